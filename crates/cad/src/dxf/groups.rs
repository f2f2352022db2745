//! The layer below entities: a file is a sequence of (group code, value) pairs, written as line
//! pairs (ASCII DXF) or as typed binary records (binary DXF).

use super::DxfError;

/// Largest magnitude accepted for any real value: a kilometre-sized sheet is 1e6 mm, and staying
/// far below f64's range means no later sum or product can overflow to infinity.
pub(crate) const MAX_MAGNITUDE: f64 = cutroute_geometry::MAX_COORDINATE;

/// The first bytes of every binary DXF file.
pub(crate) const BINARY_SENTINEL: &[u8] = b"AutoCAD Binary DXF\r\n\x1a\0";

/// The comment group: any writer may put it anywhere, and it carries nothing.
const COMMENT: i32 = 999;

/// One group: its code, its value and where it stands.
///
/// In an ASCII file `value` is the value line's text (trimmed) and `line` the 1-based line of
/// the code. In a binary file `value` is the string of a string group (empty for numbers, whose
/// value is in `number`), and `line` is the byte offset of the code: the places a reader of a
/// binary file can point at.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Group<'a> {
    pub code: i32,
    pub value: &'a [u8],
    pub line: usize,
    /// Where the value stands: the next line (ASCII) or the byte after the code (binary).
    pub value_at: usize,
    /// The value of a numeric group of a binary file.
    pub number: Option<f64>,
}

impl Group<'_> {
    /// Whether this group is `0 NAME` (case-insensitive, as AutoCAD reads it).
    pub fn is(&self, code: i32, name: &str) -> bool {
        self.code == code && self.value.eq_ignore_ascii_case(name.as_bytes())
    }

    /// The value as a finite real of sane magnitude.
    pub fn real(&self) -> Result<f64, DxfError> {
        let v = match self.number {
            Some(v) => v,
            None => {
                let text = std::str::from_utf8(self.value).map_err(|_| self.bad_number())?;
                text.parse().map_err(|_| self.bad_number())?
            }
        };
        if !v.is_finite() {
            return Err(self.bad_number());
        }
        if v.abs() > MAX_MAGNITUDE {
            return Err(DxfError::OutOfRange {
                line: self.value_at,
                code: self.code,
                value: v,
            });
        }
        Ok(v)
    }

    /// The value as an integer.
    pub fn int(&self) -> Result<i64, DxfError> {
        if let Some(v) = self.number {
            return if v.is_finite() && v.fract() == 0.0 && v.abs() < 1e15 {
                Ok(v as i64)
            } else {
                Err(self.bad_number())
            };
        }
        let text = std::str::from_utf8(self.value).map_err(|_| self.bad_number())?;
        // Some writers put "1.0" or "  70" in integer groups; accept integral reals too.
        if let Ok(v) = text.parse::<i64>() {
            return Ok(v);
        }
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() && v.fract() == 0.0 && v.abs() < 1e15 => Ok(v as i64),
            _ => Err(self.bad_number()),
        }
    }

    fn bad_number(&self) -> DxfError {
        DxfError::BadNumber {
            line: self.value_at,
            code: self.code,
            text: match self.number {
                Some(v) => v.to_string(),
                None => decode_text(self.value, Codepage::Utf8OrAnsi1251),
            },
        }
    }
}

/// Whether the bytes are a binary DXF file.
pub(crate) fn is_binary(bytes: &[u8]) -> bool {
    bytes.starts_with(BINARY_SENTINEL)
}

/// Splits the file into groups, ASCII or binary, up to its `0 EOF` (what follows it, such as a
/// DOS end-of-file byte or text, is not part of the drawing) and without comment groups. Fails
/// on a code that is not an integer or a code without its value (a truncated file).
pub(crate) fn split_groups(bytes: &[u8]) -> Result<Vec<Group<'_>>, DxfError> {
    if is_binary(bytes) {
        return split_binary(bytes);
    }
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    // The newline that ends the last line does not start another (empty) line: without this a
    // file cut right after a group code would pair the code with a phantom empty value.
    let bytes = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    let mut lines = bytes.split(|&b| b == b'\n').enumerate();
    let mut groups = Vec::new();
    while let Some((index, code_line)) = lines.next() {
        let code_text = trim(code_line);
        if code_text.is_empty() {
            // A final newline leaves one empty line; blank lines elsewhere are tolerated too.
            continue;
        }
        let code = std::str::from_utf8(code_text)
            .ok()
            .and_then(|t| t.parse::<i32>().ok())
            .ok_or_else(|| DxfError::BadGroupCode {
                line: index + 1,
                text: decode_text(code_text, Codepage::Utf8OrAnsi1251),
            })?;
        let Some((_, value_line)) = lines.next() else {
            return Err(DxfError::MissingValue {
                line: index + 1,
                code,
            });
        };
        if code == COMMENT {
            continue;
        }
        let group = Group {
            code,
            value: trim(value_line),
            line: index + 1,
            value_at: index + 2,
            number: None,
        };
        groups.push(group);
        if group.is(0, "EOF") {
            break;
        }
    }
    Ok(groups)
}

/// How a binary group's value is stored, by its code's range (the DXF reference's group code
/// value types; binary DXF writes each type in its natural binary form).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BinaryValue {
    /// NUL-terminated string.
    Text,
    /// Little-endian IEEE double.
    Double,
    /// Little-endian signed integer of this many bytes.
    Int(usize),
    /// One byte (booleans, 290–299).
    Byte,
    /// A length byte and that many bytes (binary chunks).
    Chunk,
}

fn binary_value(code: i32) -> BinaryValue {
    match code {
        10..=59 | 110..=149 | 210..=239 | 460..=469 | 1010..=1059 => BinaryValue::Double,
        60..=79 | 170..=179 | 270..=289 | 370..=389 | 400..=409 | 1060..=1070 => {
            BinaryValue::Int(2)
        }
        90..=99 | 420..=459 | 1071 => BinaryValue::Int(4),
        160..=169 => BinaryValue::Int(8),
        290..=299 => BinaryValue::Byte,
        310..=319 | 1004 => BinaryValue::Chunk,
        _ => BinaryValue::Text,
    }
}

/// The groups of a binary DXF. Group codes are one byte (255 escapes to a 16-bit code) in R12
/// files and always 16 bits from R13 on; the first group of every file is `0 SECTION`, whose
/// second byte tells the two apart (`S` after a one-byte code, 0 after a two-byte one).
fn split_binary(bytes: &[u8]) -> Result<Vec<Group<'_>>, DxfError> {
    let start = BINARY_SENTINEL.len();
    let wide_codes = bytes.get(start + 1) == Some(&0);
    let truncated = |at: usize, code: i32| DxfError::BinaryDxf {
        offset: at,
        reason: format!("the value of group {code} is cut off by the end of the file (truncated?)"),
    };
    let mut groups = Vec::new();
    let mut at = start;
    while at < bytes.len() {
        let code_at = at;
        let code = if wide_codes {
            let b = bytes.get(at..at + 2).ok_or_else(|| DxfError::BinaryDxf {
                offset: at,
                reason: "the file ends inside a group code (truncated?)".into(),
            })?;
            at += 2;
            i32::from(i16::from_le_bytes([b[0], b[1]]))
        } else if bytes[at] == 255 {
            let b = bytes
                .get(at + 1..at + 3)
                .ok_or_else(|| DxfError::BinaryDxf {
                    offset: at,
                    reason: "the file ends inside a group code (truncated?)".into(),
                })?;
            at += 3;
            i32::from(i16::from_le_bytes([b[0], b[1]]))
        } else {
            at += 1;
            i32::from(bytes[code_at])
        };
        let value_at = at;
        let fixed = |at: usize, n: usize| bytes.get(at..at + n).ok_or_else(|| truncated(at, code));
        let (value, number, next): (&[u8], Option<f64>, usize) = match binary_value(code) {
            BinaryValue::Text => {
                let len = bytes[at..]
                    .iter()
                    .position(|&b| b == 0)
                    .ok_or_else(|| truncated(at, code))?;
                (&bytes[at..at + len], None, at + len + 1)
            }
            BinaryValue::Double => {
                let b = fixed(at, 8)?;
                let v = f64::from_le_bytes(b.try_into().expect("8 bytes"));
                (&[], Some(v), at + 8)
            }
            BinaryValue::Int(n) => {
                let b = fixed(at, n)?;
                let v = match n {
                    2 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                    4 => f64::from(i32::from_le_bytes(b.try_into().expect("4 bytes"))),
                    // 64-bit groups are handles and counters, never coordinates: rounding
                    // beyond 2^53 changes nothing the reader uses.
                    _ => i64::from_le_bytes(b.try_into().expect("8 bytes")) as f64,
                };
                (&[], Some(v), at + n)
            }
            BinaryValue::Byte => {
                let b = fixed(at, 1)?;
                (&[], Some(f64::from(b[0])), at + 1)
            }
            BinaryValue::Chunk => {
                let len = usize::from(*fixed(at, 1)?.first().expect("1 byte"));
                let b = fixed(at + 1, len)?;
                (b, None, at + 1 + len)
            }
        };
        at = next;
        if code == COMMENT {
            continue;
        }
        let group = Group {
            code,
            value,
            line: code_at,
            value_at,
            number,
        };
        groups.push(group);
        if group.is(0, "EOF") {
            break;
        }
    }
    Ok(groups)
}

fn trim(line: &[u8]) -> &[u8] {
    line.trim_ascii()
}

/// How the file's strings are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Codepage {
    /// AutoCAD 2007+ (AC1021 and later) writes UTF-8.
    Utf8,
    /// Older files in `ANSI_1251` (Cyrillic Windows), as KOMPAS and Russian AutoCAD write.
    Ansi1251,
    /// Unknown: UTF-8 when the bytes are valid UTF-8, else ANSI 1251.
    Utf8OrAnsi1251,
}

/// Decodes a DXF string for display (layer names, messages). Unmappable bytes become U+FFFD.
pub(crate) fn decode_text(bytes: &[u8], codepage: Codepage) -> String {
    match codepage {
        Codepage::Utf8 => String::from_utf8_lossy(bytes).into_owned(),
        Codepage::Utf8OrAnsi1251 => match std::str::from_utf8(bytes) {
            Ok(s) => s.to_owned(),
            Err(_) => decode_1251(bytes),
        },
        Codepage::Ansi1251 => decode_1251(bytes),
    }
}

fn decode_1251(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|&b| match b {
            0x00..=0x7F => b as char,
            // А..я are contiguous in both Windows-1251 and Unicode.
            0xC0..=0xFF => char::from_u32(0x0410 + (b as u32 - 0xC0)).unwrap_or('\u{FFFD}'),
            0xA8 => 'Ё',
            0xB8 => 'ё',
            0xB9 => '№',
            0xA0 => '\u{A0}',
            _ => '\u{FFFD}',
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_pairs_with_crlf_and_blank_tail() {
        let g = split_groups(b"  0\r\nSECTION\r\n  2\r\nENTITIES\r\n").unwrap();
        assert_eq!(g.len(), 2);
        assert!(g[0].is(0, "section"));
        assert_eq!(g[1].line, 3);
    }

    #[test]
    fn truncated_and_garbage_codes_are_located() {
        assert!(matches!(
            split_groups(b"0\nSECTION\n2"),
            Err(DxfError::MissingValue { line: 3, code: 2 })
        ));
        assert!(matches!(
            split_groups(b"0\nSECTION\nxx\nA"),
            Err(DxfError::BadGroupCode { line: 3, .. })
        ));
    }

    #[test]
    fn numbers_are_checked() {
        let g = split_groups(b"10\nNaN\n10\n1e300\n10\n-2.5\n70\n 8").unwrap();
        assert!(matches!(
            g[0].real(),
            Err(DxfError::BadNumber {
                line: 2,
                code: 10,
                ..
            })
        ));
        assert!(matches!(
            g[1].real(),
            Err(DxfError::OutOfRange { line: 4, .. })
        ));
        assert_eq!(g[2].real().unwrap(), -2.5);
        assert_eq!(g[3].int().unwrap(), 8);
    }

    #[test]
    fn cyrillic_in_both_encodings() {
        assert_eq!(
            decode_text(&[0xCA, 0xCE, 0xCD, 0xD3, 0xD1], Codepage::Ansi1251),
            "КОНУС"
        );
        assert_eq!(
            decode_text("КОНУС".as_bytes(), Codepage::Utf8OrAnsi1251),
            "КОНУС"
        );
    }
}
