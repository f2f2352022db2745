//! What the reader left out or changed, as the CLI shows it: one `warning: …` line each on
//! standard error, and a `warnings` array in JSON reports.

use cutroute_geometry::ReadWarning;
use serde_json::{json, Value};

/// Most warnings printed one per line; the rest are counted.
const MAX_PRINTED: usize = 20;

/// Prints the warnings on standard error, one line each (at most [`MAX_PRINTED`], then a
/// count of the others).
pub fn print(warnings: &[ReadWarning]) {
    for warning in warnings.iter().take(MAX_PRINTED) {
        eprintln!("warning: {warning}");
    }
    if warnings.len() > MAX_PRINTED {
        eprintln!(
            "warning: {} warnings in all ({} more not shown; `inspect --json` lists them)",
            warnings.len(),
            warnings.len() - MAX_PRINTED
        );
    }
}

/// The warnings as JSON objects `{kind, place, message, length_mm}`, without the geometry
/// left out (the page draws that; the CLI reports what and where).
pub fn to_json(warnings: &[ReadWarning]) -> Value {
    Value::Array(
        warnings
            .iter()
            .map(|w| {
                json!({
                    "kind": w.kind.name(),
                    "place": w.place.as_ref().map(ToString::to_string),
                    "message": w.message,
                    "length_mm": w.length_mm,
                })
            })
            .collect(),
    )
}

/// Adds the `warnings` array to a JSON report object.
pub fn add_to(report: &mut Value, warnings: &[ReadWarning]) {
    if let Value::Object(fields) = report {
        fields.insert("warnings".into(), to_json(warnings));
    }
}
