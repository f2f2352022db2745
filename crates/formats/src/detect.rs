//! Recognising a file's format from its content, and reading a nest from any format this crate
//! owns.

use cutroute_geometry::Nest;

use crate::dbs::{self, DbsError};
use crate::geometry_json;
use crate::json::JsonError;
use crate::result_json;

/// The formats of the cutting world, as far as content tells them apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Legacy binary DBS.
    DbsBinary,
    /// Geometry JSON (`dbs.json`): an array of `{partid, paths}`.
    GeometryJson,
    /// RouteManager task JSON (`TaskData` + `Contours`).
    TaskJson,
    /// RouteManager result JSON (`job` + `results`).
    ResultJson,
    /// DXF drawing (read by the CAD crate).
    Dxf,
    /// T-FLEX nesting project, XML (read by the CAD crate).
    TflexXml,
    /// SVG drawing of a nest (read by the CAD crate).
    Svg,
    /// PCGLNS / PCGTSPLIB text instance (read by the PCGTSP crate).
    Pcglns,
    /// None of the above.
    Unknown,
}

/// Why [`read_nest`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// A DBS file that does not read.
    #[error(transparent)]
    Dbs(#[from] DbsError),
    /// A JSON file that does not read.
    #[error(transparent)]
    Json(#[from] JsonError),
    /// The format holds no nest geometry (a task lists pierce points only).
    #[error("a {0:?} file holds no nest geometry")]
    NoGeometry(Format),
    /// The format is read by another crate (or not at all).
    #[error("{0:?} is not read by cutroute-formats")]
    Unsupported(Format),
}

/// Guesses the format from the content (never from a file name).
///
/// Cheap for text formats (only the start is inspected, plus the top-level keys of JSON
/// objects); a DBS file is recognised by a consistent first record header.
pub fn detect(bytes: &[u8]) -> Format {
    let text_start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace() && *b != 0xEF && *b != 0xBB && *b != 0xBF)
        .map_or(&[][..], |i| &bytes[i..]);
    match text_start.first() {
        Some(b'[') => return Format::GeometryJson,
        Some(b'{') => return json_object_kind(bytes),
        Some(b'<') => {
            // A T-FLEX project cut before its first `Nest` still starts as a `Project`: its
            // reader, not "unknown format", says where it breaks.
            return if root_is_svg(text_start) {
                Format::Svg
            } else if contains(bytes, b"Nest")
                || contains(bytes, b"<Project")
                || contains(bytes, b"TFlex")
                || contains(bytes, b"tfnesting")
            {
                Format::TflexXml
            } else {
                Format::Unknown
            };
        }
        _ => {}
    }
    // The binary DXF sentinel comes first: its bytes are no DBS record header either.
    if bytes.starts_with(b"AutoCAD Binary DXF\r\n\x1a\0") {
        return Format::Dxf;
    }
    if looks_like_dbs(bytes) {
        return Format::DbsBinary;
    }
    if looks_like_ascii_dxf(text_start) {
        return Format::Dxf;
    }
    let head = &bytes[..bytes.len().min(4096)];
    if text_start.starts_with(b"NAME")
        && (contains(head, b"GTSP_SETS") || contains(head, b"PCGLNS") || contains(head, b"GROUPS"))
    {
        return Format::Pcglns;
    }
    Format::Unknown
}

/// Whether a text starts as an ASCII DXF does: group-code/value line pairs whose first group
/// (after any `999` comment groups, as LibreCAD, QCAD, OpenSCAD, Inkscape and CloudCompare
/// write them, and blank lines) is `0 SECTION`.
fn looks_like_ascii_dxf(text: &[u8]) -> bool {
    let head = &text[..text.len().min(1 << 16)];
    // Blank lines may stand where a code is due (as the reader allows); a value line is the
    // line after its code, blank or not (an empty comment).
    let mut lines = head.split(|&b| b == b'\n').map(<[u8]>::trim_ascii);
    while let Some(code) = lines.next() {
        if code.is_empty() {
            continue;
        }
        let value = lines.next().unwrap_or_default();
        match code {
            b"999" => continue,
            b"0" => return value.eq_ignore_ascii_case(b"SECTION"),
            _ => return false,
        }
    }
    false
}

/// Whether the first element of an XML text is `<svg>` (after the declaration, comments,
/// processing instructions and a DOCTYPE): an HTML page with inline SVG is not an SVG file.
fn root_is_svg(text: &[u8]) -> bool {
    let mut rest = &text[..text.len().min(1 << 16)];
    loop {
        let skip = |rest: &[u8], end: &[u8]| {
            rest.windows(end.len())
                .position(|w| w == end)
                .map(|i| i + end.len())
        };
        let next = if rest.starts_with(b"<?") {
            skip(rest, b"?>")
        } else if rest.starts_with(b"<!--") {
            skip(rest, b"-->")
        } else if rest.starts_with(b"<!") {
            // A DOCTYPE, with an internal subset in brackets when one comes before its `>`.
            let bracket = rest.iter().position(|&b| b == b'[');
            let close = rest.iter().position(|&b| b == b'>');
            match (bracket, close) {
                (Some(b), Some(c)) if b < c => skip(rest, b"]>"),
                _ => close.map(|c| c + 1),
            }
        } else {
            return rest.starts_with(b"<svg") || rest.starts_with(b"<svg:svg");
        };
        let Some(next) = next else { return false };
        rest = &rest[next..];
        let start = rest.iter().position(|b| !b.is_ascii_whitespace());
        rest = start.map_or(&[][..], |i| &rest[i..]);
    }
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

fn json_object_kind(bytes: &[u8]) -> Format {
    // Only the top-level keys matter; deserialising into a map of ignored values is cheap.
    let Ok(map) = serde_json::from_slice::<std::collections::HashMap<String, serde::de::IgnoredAny>>(
        crate::json::without_bom(bytes),
    ) else {
        return Format::Unknown;
    };
    if map.contains_key("TaskData") && map.contains_key("Contours") {
        Format::TaskJson
    } else if map.contains_key("job") && map.contains_key("results") {
        Format::ResultJson
    } else {
        Format::Unknown
    }
}

/// A DBS file starts with a record header whose `size` equals `size'`, or is just the end
/// marker.
fn looks_like_dbs(bytes: &[u8]) -> bool {
    let i16_at = |at: usize| i16::from_le_bytes([bytes[at], bytes[at + 1]]);
    if bytes.len() >= 2 && bytes.len() <= 4 && i16_at(0) < 0 {
        return true;
    }
    if bytes.len() < 16 {
        return false;
    }
    let (size, size_copy, record_type) = (i16_at(0), i16_at(4), i16_at(8));
    size >= 3 && size == size_copy && (1..=255).contains(&record_type) && bytes[6..8] == [0, 0]
}

/// Reads a nest from DBS, geometry JSON or result JSON (its `job` echo), detected by content.
pub fn read_nest(bytes: &[u8]) -> Result<Nest, ReadError> {
    match detect(bytes) {
        Format::DbsBinary => Ok(dbs::read_dbs(bytes)?.nest),
        Format::GeometryJson => Ok(geometry_json::read_geometry_json(bytes)?),
        Format::ResultJson => Ok(result_json::read_result_json(bytes)?.nest()?),
        Format::TaskJson => Err(ReadError::NoGeometry(Format::TaskJson)),
        other => Err(ReadError::Unsupported(other)),
    }
}

#[cfg(test)]
mod dxf_detection {
    use super::*;

    #[test]
    fn dxf_files_as_cad_programs_write_them_are_recognised() {
        assert_eq!(detect(b"0\nSECTION\n2\nHEADER\n"), Format::Dxf);
        assert_eq!(
            detect(b"999\ndxflib 2.0.4.8\n  0\nSECTION\n  2\nHEADER\n"),
            Format::Dxf
        );
        assert_eq!(
            detect(b"\xEF\xBB\xBF\r\n999\r\nInkscape\r\n999\r\n\r\n0\r\nSECTION\r\n"),
            Format::Dxf
        );
        assert_eq!(
            detect(b"AutoCAD Binary DXF\r\n\x1a\0\0SECTION\0"),
            Format::Dxf
        );
        // A comment alone, or a first group that is not `0 SECTION`, is no drawing.
        assert_eq!(detect(b"999\nhello\n"), Format::Unknown);
        assert_eq!(detect(b"999\nhello\n5\nSECTION\n"), Format::Unknown);
    }
}

#[cfg(test)]
mod svg_detection {
    use super::*;

    #[test]
    fn svg_files_are_recognised_and_html_pages_are_not() {
        let svg = b"<?xml version=\"1.0\"?>\n<!-- made by hand -->\n<!DOCTYPE svg PUBLIC \"-//W3C//DTD SVG 1.1//EN\" \"x.dtd\" [<!ENTITY a \"b\">]>\n<svg xmlns=\"http://www.w3.org/2000/svg\"/>";
        assert_eq!(detect(svg), Format::Svg);
        assert_eq!(detect(b"<svg/>"), Format::Svg);
        assert_eq!(
            detect(b"<!DOCTYPE html><html><body><svg></svg></body></html>"),
            Format::Unknown
        );
        assert_eq!(detect(b"<?xml version=\"1.0\"?>"), Format::Unknown);
    }
}
