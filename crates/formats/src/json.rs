//! Errors and plumbing shared by the JSON readers and writers.

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::contour_check::ContourProblem;

/// Everything that can be wrong with a JSON input; each variant says where.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum JsonError {
    /// Not well-formed JSON (or a number beyond f64 range).
    #[error("JSON syntax error at line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's description.
        message: String,
    },
    /// Well-formed JSON that does not match the schema (missing field, wrong type, …).
    #[error("JSON schema error at {path} (line {line}, column {column}): {message}")]
    Schema {
        /// JSON path of the offending value, e.g. `Contours[2].Points[0].X`.
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A geometry point that is not 2 or 3 numbers.
    #[error("JSON point at {path} has {len} numbers; expected 2 or 3 (x, y[, bulge])")]
    BadPoint {
        /// JSON path of the point.
        path: String,
        /// How many numbers it has.
        len: usize,
    },
    /// An array the schema requires to be non-empty (or long enough) is not.
    #[error("JSON array at {path} has {len} items; at least {min} required")]
    TooShort {
        /// JSON path of the array.
        path: String,
        /// Its length.
        len: usize,
        /// The schema's minimum.
        min: usize,
    },
    /// A contour is unusable (unclosed, degenerate, self-intersecting).
    #[error("JSON contour at {path}: {problem}")]
    BadContour {
        /// JSON path of the contour's point array.
        path: String,
        /// What is wrong.
        problem: ContourProblem,
    },
    /// Values that must agree do not (indices, ranges).
    #[error("JSON value at {path} is inconsistent: {message}")]
    Inconsistent {
        /// JSON path of the value.
        path: String,
        /// What disagrees.
        message: String,
    },
}

/// What can stop a JSON writer.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum JsonWriteError {
    /// A number is NaN or infinite; JSON cannot hold it.
    #[error("cannot write a non-finite number at {path}")]
    NonFinite {
        /// JSON path of the value.
        path: String,
    },
}

/// Parses `bytes` into `T`, mapping serde errors to [`JsonError`] with path and position.
pub(crate) fn parse<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, JsonError> {
    // Windows editors save UTF-8 with a byte-order mark, which JSON forbids but every reader
    // of text accepts; the DXF and SVG readers take it too.
    let bytes = without_bom(bytes);
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        classify(inner, Some(path))
    })?;
    de.end().map_err(|e| classify(e, None))?;
    Ok(value)
}

/// `bytes` without a leading UTF-8 byte-order mark.
pub(crate) fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

fn classify(e: serde_json::Error, path: Option<String>) -> JsonError {
    let (line, column) = (e.line(), e.column());
    let message = e.to_string();
    // serde_json appends " at line L column C"; we report those separately.
    let message = match message.rfind(" at line ") {
        Some(cut) => message[..cut].to_string(),
        None => message,
    };
    match (e.classify(), path) {
        (serde_json::error::Category::Data, Some(path)) => JsonError::Schema {
            path,
            line,
            column,
            message,
        },
        _ => JsonError::Syntax {
            line,
            column,
            message,
        },
    }
}

/// Serialises `value` pretty-printed, refusing NaN/∞ (serde_json would silently write `null`).
pub(crate) fn to_pretty<T: Serialize>(value: &T) -> Result<String, JsonWriteError> {
    let tree =
        serde_json::to_value(value).map_err(|_| JsonWriteError::NonFinite { path: ".".into() })?;
    if let Some(path) = find_null(&tree, String::new()) {
        return Err(JsonWriteError::NonFinite { path });
    }
    serde_json::to_string_pretty(&tree).map_err(|_| JsonWriteError::NonFinite { path: ".".into() })
}

/// Our structs skip absent optionals, so any `null` in the tree was a non-finite float.
fn find_null(v: &serde_json::Value, path: String) -> Option<String> {
    match v {
        serde_json::Value::Null => Some(if path.is_empty() { ".".into() } else { path }),
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, x)| find_null(x, format!("{path}[{i}]"))),
        serde_json::Value::Object(map) => map.iter().find_map(|(k, x)| {
            let sep = if path.is_empty() { "" } else { "." };
            find_null(x, format!("{path}{sep}{k}"))
        }),
        _ => None,
    }
}

/// A finite number as JSON text (`0.0`, `-1.5`, shortest round-trip form).
pub(crate) fn number(v: f64) -> Option<String> {
    v.is_finite()
        .then(|| serde_json::Number::from_f64(v).map(|n| n.to_string()))
        .flatten()
}
