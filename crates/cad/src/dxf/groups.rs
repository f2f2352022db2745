//! The ASCII DXF layer below entities: a file is a sequence of (group code, value) line pairs.

use super::DxfError;

/// Largest magnitude accepted for any real value: a kilometre-sized sheet is 1e6 mm, and staying
/// far below f64's range means no later sum or product can overflow to infinity.
pub(crate) const MAX_MAGNITUDE: f64 = cutroute_geometry::MAX_COORDINATE;

/// One group: its code, its value's text (trimmed) and the 1-based line of the code.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Group<'a> {
    pub code: i32,
    pub value: &'a [u8],
    pub line: usize,
}

impl Group<'_> {
    /// Whether this group is `0 NAME` (case-insensitive, as AutoCAD reads it).
    pub fn is(&self, code: i32, name: &str) -> bool {
        self.code == code && self.value.eq_ignore_ascii_case(name.as_bytes())
    }

    /// The value as a finite real of sane magnitude.
    pub fn real(&self) -> Result<f64, DxfError> {
        let text = std::str::from_utf8(self.value).map_err(|_| self.bad_number())?;
        let v: f64 = text.parse().map_err(|_| self.bad_number())?;
        if !v.is_finite() {
            return Err(self.bad_number());
        }
        if v.abs() > MAX_MAGNITUDE {
            return Err(DxfError::OutOfRange {
                line: self.line + 1,
                code: self.code,
                value: v,
            });
        }
        Ok(v)
    }

    /// The value as an integer.
    pub fn int(&self) -> Result<i64, DxfError> {
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
            line: self.line + 1,
            code: self.code,
            text: decode_text(self.value, Codepage::Utf8OrAnsi1251),
        }
    }
}

/// Splits the file into groups. Fails on a binary DXF, a code line that is not an integer, or a
/// code without its value line (a truncated file).
pub(crate) fn split_groups(bytes: &[u8]) -> Result<Vec<Group<'_>>, DxfError> {
    if bytes.starts_with(b"AutoCAD Binary DXF") {
        return Err(DxfError::BinaryDxf);
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
        groups.push(Group {
            code,
            value: trim(value_line),
            line: index + 1,
        });
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
