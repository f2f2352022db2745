//! Opening files: bytes in, a solvable [`Document`] out, whatever the format.

use cutroute_cad::dxf::{read_dxf, DxfOptions};
use cutroute_cad::tflex::read_tfnesting_project;
use cutroute_formats::{detect, read_nest, read_result_json, Format};
use cutroute_geometry::{Nest, Point};
use cutroute_pcgtsp::Instance;
use cutroute_protocol::{Document, Problem};

/// Why a file could not be opened; the message names the file and the place in it.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OpenError {
    /// The reader of the detected format refused the file.
    #[error("{file_name} ({format}): {message}")]
    Unreadable {
        /// The file's name.
        file_name: String,
        /// The detected format.
        format: &'static str,
        /// The reader's error, with its location.
        message: String,
    },
    /// A task file lists pierce points for a nest stored elsewhere.
    #[error("{0}: a cutting task holds no geometry; open its nest (geometry JSON or DBS) first")]
    TaskWithoutGeometry(String),
    /// Nothing recognisable.
    #[error(
        "{0}: unknown format from byte 0 (expected DBS, geometry/task/result JSON, DXF, T-FLEX or PCGLNS)"
    )]
    UnknownFormat(String),
    /// A JSON object that does not parse, or parses as none of the JSON formats: the message
    /// gives the line and column.
    #[error("{file_name} (JSON): {message}")]
    MalformedJson {
        /// The file's name.
        file_name: String,
        /// What is wrong, with line and column.
        message: String,
    },
    /// The file reads but holds nothing to cut.
    #[error("{0}: the file holds no closed contours to cut")]
    NothingToCut(String),
}

/// The format's name for people.
pub fn format_name(format: Format) -> &'static str {
    match format {
        Format::DbsBinary => "DBS binary",
        Format::GeometryJson => "geometry JSON",
        Format::TaskJson => "task JSON",
        Format::ResultJson => "result JSON",
        Format::Dxf => "DXF",
        Format::TflexXml => "T-FLEX nesting",
        Format::Pcglns => "PCGTSP instance",
        Format::Unknown => "unknown",
    }
}

/// Read a file whose format is recognised from its content (the name is only reported).
///
/// Nests come back with contours oriented by nesting depth (outer clockwise, holes
/// counter-clockwise), since some real files store every contour clockwise.
pub fn open_document(file_name: &str, bytes: &[u8]) -> Result<Document, OpenError> {
    let format = detect(bytes);
    let unreadable = |message: String| OpenError::Unreadable {
        file_name: file_name.to_string(),
        format: format_name(format),
        message,
    };
    let mut warnings = Vec::new();
    let mut route = None;
    let nest = match format {
        Format::DbsBinary | Format::GeometryJson => {
            read_nest(bytes).map_err(|e| unreadable(e.to_string()))?
        }
        Format::ResultJson => {
            let result = read_result_json(bytes).map_err(|e| unreadable(e.to_string()))?;
            route = Some(result.route());
            result.nest().map_err(|e| unreadable(e.to_string()))?
        }
        Format::Dxf => {
            let import =
                read_dxf(bytes, &DxfOptions::default()).map_err(|e| unreadable(e.to_string()))?;
            warnings.extend(import.warnings.iter().map(ToString::to_string));
            warnings.extend(
                import
                    .open_chains
                    .iter()
                    .map(|chain| format!("open chain left out: {chain:?}")),
            );
            import.nest
        }
        Format::TflexXml => {
            let project = read_tfnesting_project(bytes).map_err(|e| unreadable(e.to_string()))?;
            let count = project.layouts.len();
            let mut layouts = project.layouts.into_iter();
            let first = layouts
                .next()
                .ok_or_else(|| OpenError::NothingToCut(file_name.to_string()))?;
            if count > 1 {
                warnings.push(format!(
                    "the project has {count} sheets; showing the first ({})",
                    first.sheet_name
                ));
            }
            first.nest
        }
        Format::Pcglns => {
            let text = std::str::from_utf8(bytes)
                .map_err(|e| unreadable(format!("byte {}: not UTF-8 text", e.valid_up_to())))?;
            Instance::parse(text).map_err(|e| unreadable(e.to_string()))?;
            return Ok(Document {
                file_name: file_name.to_string(),
                format: format_name(format).to_string(),
                problem: Problem::PcgtspText {
                    text: text.to_string(),
                },
                route: None,
                warnings,
            });
        }
        Format::TaskJson => return Err(OpenError::TaskWithoutGeometry(file_name.to_string())),
        Format::Unknown => return Err(unknown_format(file_name, bytes)),
    };
    // Every reader checks its own values with a location; this catches what a reader builds
    // (DXF and T-FLEX transforms, arcs) against the same domain, located by part and contour.
    nest.check_domain().map_err(|e| unreadable(e.to_string()))?;
    let nest = oriented(nest);
    if nest.contour_count() == 0 {
        return Err(OpenError::NothingToCut(file_name.to_string()));
    }
    let start = default_start(&nest);
    Ok(Document {
        file_name: file_name.to_string(),
        format: format_name(format).to_string(),
        problem: Problem::Nest {
            nest,
            start,
            finish: None,
        },
        route,
        warnings,
    })
}

/// Why a file is of no known format, located: a JSON object that does not parse gets serde's
/// line and column, one that parses gets the keys it lacks; anything else is unknown from
/// byte 0.
fn unknown_format(file_name: &str, bytes: &[u8]) -> OpenError {
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    if first != Some(&b'{') {
        return OpenError::UnknownFormat(file_name.to_string());
    }
    let message = match serde_json::from_slice::<serde::de::IgnoredAny>(bytes) {
        Err(e) => format!(
            "line {} column {}: malformed JSON: {e}",
            e.line(),
            e.column()
        ),
        Ok(_) => "line 1 column 1: a JSON object with neither `TaskData` and `Contours` (task) \
                  nor `job` and `results` (result)"
            .to_string(),
    };
    OpenError::MalformedJson {
        file_name: file_name.to_string(),
        message,
    }
}

fn oriented(mut nest: Nest) -> Nest {
    nest.normalize_orientation();
    nest
}

/// The machine's home point when the file names none: the sheet's lower-left corner (the
/// origin of the parts' box when there is no sheet).
fn default_start(nest: &Nest) -> Point {
    let sheet_box = nest.sheet.as_ref().map(|s| s.bounding_box());
    match sheet_box.filter(|b| b.min.is_finite()) {
        Some(b) => b.min,
        None => {
            let b = nest.bounding_box();
            if b.min.is_finite() {
                b.min
            } else {
                Point::new(0.0, 0.0)
            }
        }
    }
}
