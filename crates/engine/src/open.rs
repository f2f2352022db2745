//! Opening files: bytes in, a solvable [`Document`] out, whatever the format.

use cutroute_cad::dxf::{read_dxf, DxfOptions};
use cutroute_cad::svg::{read_svg, SvgOptions};
use cutroute_cad::tflex::read_tfnesting_project;
use cutroute_formats::{detect, read_nest, read_result_json, Format};
use cutroute_geometry::{Nest, Point, ReadWarning, WarningKind};
use cutroute_pcgtsp::Instance;
use cutroute_protocol::{Document, Problem, SourceLocation};

use crate::located::Located;

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
        /// Where the reader stopped, as data.
        location: Option<SourceLocation>,
    },
    /// A task file lists pierce points for a nest stored elsewhere.
    #[error("{0}: a cutting task holds no geometry; open its nest (geometry JSON or DBS) first")]
    TaskWithoutGeometry(String),
    /// Nothing recognisable.
    #[error(
        "{0}: unknown format from byte 0 (expected DBS, geometry/task/result JSON, DXF, SVG, \
         T-FLEX, a PCGLNS/PCGTSPLIB instance or result, or G-code)"
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
        /// The line and column, as data.
        location: Option<SourceLocation>,
        /// What is wrong, without the location.
        detail: String,
    },
    /// The file reads but holds nothing to cut.
    #[error("{0}: the file holds no closed contours to cut")]
    NothingToCut(String),
    /// A G-code program that does not read.
    #[error("{file_name} (G-code): {message}")]
    Gcode {
        /// The file's name.
        file_name: String,
        /// The reader's error with its line and column.
        message: String,
        /// The line and column, as data.
        location: Option<SourceLocation>,
    },
    /// A G-code program that never cuts a closed contour.
    #[error("{0} (G-code): the program cuts no closed contour")]
    GcodeCutsNothing(String),
    /// A PCGLNS result opened with nothing to check its tour against.
    #[error(
        "{0}: a PCGLNS result holds only a tour; open it together with its instance \
         (.pcglns/.pcgtsp), or with its nest and task JSON"
    )]
    TourAlone(String),
    /// Two files of one kind in a batch.
    #[error("{first} and {second} are both {kind}: open one {kind} at a time")]
    TwoOfAKind {
        /// The kind, in words.
        kind: &'static str,
        /// The first file.
        first: String,
        /// The second file.
        second: String,
    },
    /// A file of a batch that is none of the kinds a batch combines.
    #[error("{0}: cannot be combined with the other files (expected a nest, a task JSON, a PCGTSP instance or a PCGLNS result)")]
    NotCombinable(String),
    /// The tour fails the independent checker.
    #[error("{file_name}: the tour is not feasible for {against}: {reason} (nodes and clusters counted from 0)")]
    InfeasibleTour {
        /// The result file.
        file_name: String,
        /// What it was checked against (the instance's or the task's file name).
        against: String,
        /// The checker's finding.
        reason: String,
    },
    /// The checked cost of the tour differs from what the result file reports.
    #[error("{file_name}: the file reports cost {reported} but the tour costs {checked:.3} on {against}")]
    CostMismatch {
        /// The result file.
        file_name: String,
        /// What it was checked against.
        against: String,
        /// The cost in the file.
        reported: f64,
        /// The cost recomputed by the checker.
        checked: f64,
    },
    /// An instance whose nodes are not the task's pierce points plus the start.
    #[error("{instance} has {nodes} nodes but {task} has {points} pierce points plus the start: they do not belong together")]
    InstanceNotOfTask {
        /// The instance file.
        instance: String,
        /// Its node count.
        nodes: usize,
        /// The task file.
        task: String,
        /// The task's pierce points.
        points: usize,
    },
    /// A task contour that lies on no contour of the nest.
    #[error("{task}: contour {index} (pierce point ({x:.3}, {y:.3})) is on no contour of {nest}: they do not belong together")]
    TaskNotOnNest {
        /// The task file.
        task: String,
        /// The task contour's 1-based `Index`.
        index: i64,
        /// Its first pierce point.
        x: f64,
        /// Its first pierce point.
        y: f64,
        /// The nest file.
        nest: String,
    },
    /// The tour, as a cutting route, fails the route checker.
    #[error("{file_name}: as a cutting route of {nest} the tour is not valid: {reason}")]
    InvalidRoute {
        /// The result file.
        file_name: String,
        /// The nest file.
        nest: String,
        /// The route checker's finding.
        reason: String,
    },
    /// A sheet the file does not have.
    #[error("{file_name}: there is no sheet {sheet} (the file has {count}; sheets count from 1)")]
    NoSuchSheet {
        /// The file's name.
        file_name: String,
        /// The sheet asked for, counted from 1.
        sheet: usize,
        /// How many sheets the file has.
        count: usize,
    },
    /// A task or a tour with no nest to draw it on, and no instance either.
    #[error("{0}: a cutting task holds no geometry; open it together with its nest (geometry JSON or DBS)")]
    TaskWithoutNest(String),
}

impl OpenError {
    /// The error as the protocol's data: kind, parameters and location for the page to word in
    /// its language, with the English text the CLI prints.
    pub fn report(&self) -> cutroute_protocol::OpenError {
        use cutroute_protocol::OpenErrorKind as Kind;
        let whole =
            |file_name: &str, kind: Kind| (file_name.to_string(), kind, None, String::new());
        let (file_name, kind, location, detail) = match self {
            OpenError::Unreadable {
                file_name,
                format,
                message,
                location,
            } => (
                file_name.clone(),
                Kind::Unreadable {
                    format: format.to_string(),
                },
                location.clone(),
                message.clone(),
            ),
            OpenError::TaskWithoutGeometry(f) => whole(f, Kind::TaskWithoutGeometry),
            OpenError::UnknownFormat(f) => whole(f, Kind::UnknownFormat),
            OpenError::MalformedJson {
                file_name,
                location,
                detail,
                ..
            } => (
                file_name.clone(),
                Kind::MalformedJson,
                location.clone(),
                detail.clone(),
            ),
            OpenError::NothingToCut(f) => whole(f, Kind::NothingToCut),
            OpenError::Gcode {
                file_name,
                message,
                location,
            } => (
                file_name.clone(),
                Kind::Gcode,
                location.clone(),
                message.clone(),
            ),
            OpenError::GcodeCutsNothing(f) => whole(f, Kind::GcodeCutsNothing),
            OpenError::TourAlone(f) => whole(f, Kind::TourAlone),
            OpenError::TwoOfAKind {
                kind,
                first,
                second,
            } => whole(
                first,
                Kind::TwoOfAKind {
                    kind: kind.to_string(),
                    second: second.clone(),
                },
            ),
            OpenError::NotCombinable(f) => whole(f, Kind::NotCombinable),
            OpenError::InfeasibleTour {
                file_name,
                against,
                reason,
            } => (
                file_name.clone(),
                Kind::InfeasibleTour {
                    against: against.clone(),
                },
                None,
                reason.clone(),
            ),
            OpenError::CostMismatch {
                file_name,
                against,
                reported,
                checked,
            } => whole(
                file_name,
                Kind::CostMismatch {
                    against: against.clone(),
                    reported: *reported,
                    checked: *checked,
                },
            ),
            OpenError::InstanceNotOfTask {
                instance,
                nodes,
                task,
                points,
            } => whole(
                instance,
                Kind::InstanceNotOfTask {
                    nodes: *nodes,
                    task: task.clone(),
                    points: *points,
                },
            ),
            OpenError::TaskNotOnNest {
                task,
                index,
                x,
                y,
                nest,
            } => whole(
                task,
                Kind::TaskNotOnNest {
                    index: *index,
                    x: *x,
                    y: *y,
                    nest: nest.clone(),
                },
            ),
            OpenError::InvalidRoute {
                file_name,
                nest,
                reason,
            } => (
                file_name.clone(),
                Kind::InvalidRoute { nest: nest.clone() },
                None,
                reason.clone(),
            ),
            OpenError::NoSuchSheet {
                file_name,
                sheet,
                count,
            } => whole(
                file_name,
                Kind::NoSuchSheet {
                    sheet: *sheet,
                    count: *count,
                },
            ),
            OpenError::TaskWithoutNest(f) => whole(f, Kind::TaskWithoutNest),
        };
        cutroute_protocol::OpenError {
            file_name,
            kind,
            location,
            detail,
            message: self.to_string(),
        }
    }
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
        Format::Svg => "SVG",
        Format::Pcglns => "PCGTSP instance",
        Format::Unknown => "unknown",
    }
}

/// Read a file of one of the model formats, recognised from its content (the name is only
/// reported); [`crate::open_document`] is the door that also opens G-code programs.
///
/// Nests come back with contours oriented by nesting depth (outer clockwise, holes
/// counter-clockwise), since some real files store every contour clockwise.
///
/// `sheet` (from 0) picks one sheet of a multi-sheet file (T-FLEX projects); files of one sheet
/// have only sheet 0.
pub(crate) fn open_model_file(
    file_name: &str,
    bytes: &[u8],
    sheet: usize,
) -> Result<Document, OpenError> {
    let format = detect(bytes);
    let no_such_sheet = |count: usize| OpenError::NoSuchSheet {
        file_name: file_name.to_string(),
        sheet: sheet + 1,
        count,
    };
    if sheet > 0 && format != Format::TflexXml && format != Format::Unknown {
        return Err(no_such_sheet(1));
    }
    let mut sheets = Vec::new();
    let unreadable = |message: String, location: Option<SourceLocation>| OpenError::Unreadable {
        file_name: file_name.to_string(),
        format: format_name(format),
        message,
        location,
    };
    let mut warnings = Vec::new();
    let mut route = None;
    let nest = match format {
        Format::DbsBinary | Format::GeometryJson => {
            read_nest(bytes).map_err(|e| unreadable(e.to_string(), e.location()))?
        }
        Format::ResultJson => {
            let result =
                read_result_json(bytes).map_err(|e| unreadable(e.to_string(), e.location()))?;
            route = Some(result.route());
            result
                .nest()
                .map_err(|e| unreadable(e.to_string(), e.location()))?
        }
        Format::Dxf => {
            let import = read_dxf(bytes, &DxfOptions::default())
                .map_err(|e| unreadable(e.to_string(), e.location()))?;
            // The open chains are among the warnings (one each, with their geometry).
            warnings.extend(import.warnings);
            import.nest
        }
        Format::Svg => {
            let import = read_svg(bytes, &SvgOptions::default())
                .map_err(|e| unreadable(e.to_string(), e.location()))?;
            warnings.extend(import.warnings);
            import.nest
        }
        Format::TflexXml => {
            let project = read_tfnesting_project(bytes)
                .map_err(|e| unreadable(e.to_string(), e.location()))?;
            let count = project.layouts.len();
            if count == 0 {
                return Err(OpenError::NothingToCut(file_name.to_string()));
            }
            if count > 1 {
                sheets = project
                    .layouts
                    .iter()
                    .map(|l| l.sheet_name.clone())
                    .collect();
                warnings.push(ReadWarning::new(
                    WarningKind::Sheets,
                    format!(
                        "the project has {count} sheets; showing sheet {} ({})",
                        sheet + 1,
                        sheets.get(sheet).map_or("", String::as_str)
                    ),
                ));
            }
            project
                .layouts
                .into_iter()
                .nth(sheet)
                .ok_or_else(|| no_such_sheet(count))?
                .nest
        }
        Format::Pcglns => {
            let text = std::str::from_utf8(bytes).map_err(|e| {
                unreadable(
                    format!("byte {}: not UTF-8 text", e.valid_up_to()),
                    e.location(),
                )
            })?;
            Instance::parse(text).map_err(|e| unreadable(e.to_string(), e.location()))?;
            return Ok(Document {
                file_name: file_name.to_string(),
                format: format_name(format).to_string(),
                problem: Problem::PcgtspText {
                    text: text.to_string(),
                },
                route: None,
                paths: None,
                task_speeds: None,
                warnings,
                sheets: Vec::new(),
                sheet: 0,
            });
        }
        Format::TaskJson => return Err(OpenError::TaskWithoutGeometry(file_name.to_string())),
        Format::Unknown => return Err(unknown_format(file_name, bytes)),
    };
    // Every reader checks its own values with a location; this catches what a reader builds
    // (DXF and T-FLEX transforms, arcs) against the same domain, located by part and contour.
    nest.check_domain()
        .map_err(|e| unreadable(e.to_string(), None))?;
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
        paths: None,
        task_speeds: None,
        warnings,
        sheets,
        sheet,
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
    let (line, column, detail) = match serde_json::from_slice::<serde::de::IgnoredAny>(bytes) {
        Err(e) => (e.line(), e.column(), format!("malformed JSON: {e}")),
        Ok(_) => (
            1,
            1,
            "a JSON object with neither `TaskData` and `Contours` (task) nor `job` and \
             `results` (result)"
                .to_string(),
        ),
    };
    OpenError::MalformedJson {
        file_name: file_name.to_string(),
        message: format!("line {line} column {column}: {detail}"),
        location: Some(SourceLocation::Line {
            line,
            column: Some(column),
        }),
        detail,
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
