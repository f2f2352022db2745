//! The geometry JSON of parts and nests (`dbs.json` schema, thesis Listing Г.1): an array of
//! `{partid, paths}` whose first element is the sheet; each path is a list of `[x, y, bulge]`
//! points (bulge optional) with the closing point repeated. A first element without paths
//! means the nest has no sheet (written so by [`write_geometry_json`]).

use cutroute_geometry::{Nest, Part};
use serde::{Deserialize, Serialize};

use crate::contour_check::{self, DEFAULT_CLOSURE_TOLERANCE};
use crate::json::{self, JsonError, JsonWriteError};

/// The `partid` of the element without paths that stands for "no sheet" in first place.
pub const NO_SHEET: &str = "no sheet";

/// One element of the file, as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GeometryJsonPart {
    /// Part designation (DBS record 26).
    pub partid: String,
    /// Extension seen in real files: the DBS ids of the part's contours.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pathids: Option<Vec<i64>>,
    /// Contours, outer first; each point is 2 or 3 numbers.
    pub paths: Vec<Vec<Vec<f64>>>,
    /// Optional area (DBS record 27).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<f64>,
    /// Optional perimeter (DBS record 27).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub perimeter: Option<f64>,
}

/// Options of [`read_geometry_json_with`].
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryJsonOptions {
    /// The first array element is the sheet (the format's convention).
    pub first_part_is_sheet: bool,
    /// Maximum distance (mm) between a contour's first and last point.
    pub closure_tolerance: f64,
    /// Reject contours that cross or touch themselves.
    pub check_self_intersection: bool,
}

impl Default for GeometryJsonOptions {
    fn default() -> Self {
        Self {
            first_part_is_sheet: true,
            closure_tolerance: DEFAULT_CLOSURE_TOLERANCE,
            check_self_intersection: true,
        }
    }
}

/// Parses the file into its stored form, checking only the schema.
pub fn parse_geometry_json(bytes: &[u8]) -> Result<Vec<GeometryJsonPart>, JsonError> {
    let parts: Vec<GeometryJsonPart> = json::parse(bytes)?;
    if parts.is_empty() {
        return Err(JsonError::TooShort {
            path: ".".into(),
            len: 0,
            min: 1,
        });
    }
    for (i, part) in parts.iter().enumerate() {
        for (k, path) in part.paths.iter().enumerate() {
            if path.len() < 2 {
                return Err(JsonError::TooShort {
                    path: format!("[{i}].paths[{k}]"),
                    len: path.len(),
                    min: 2,
                });
            }
            if let Some((j, p)) = path
                .iter()
                .enumerate()
                .find(|(_, p)| !(2..=3).contains(&p.len()))
            {
                return Err(JsonError::BadPoint {
                    path: format!("[{i}].paths[{k}][{j}]"),
                    len: p.len(),
                });
            }
        }
    }
    Ok(parts)
}

/// Reads a geometry JSON file into a nest with [`GeometryJsonOptions::default`].
pub fn read_geometry_json(bytes: &[u8]) -> Result<Nest, JsonError> {
    read_geometry_json_with(bytes, &GeometryJsonOptions::default())
}

/// Reads a geometry JSON file into a nest: closing points dropped, contours checked.
pub fn read_geometry_json_with(
    bytes: &[u8],
    options: &GeometryJsonOptions,
) -> Result<Nest, JsonError> {
    let stored = parse_geometry_json(bytes)?;
    let mut parts = Vec::with_capacity(stored.len());
    for (i, part) in stored.into_iter().enumerate() {
        let mut contours = Vec::with_capacity(part.paths.len());
        for (k, path) in part.paths.iter().enumerate() {
            let points: Vec<[f64; 3]> = path
                .iter()
                .map(|p| [p[0], p[1], p.get(2).copied().unwrap_or(0.0)])
                .collect();
            let contour = contour_check::closed_contour(
                &points,
                options.closure_tolerance,
                options.check_self_intersection,
            )
            .map_err(|problem| JsonError::BadContour {
                path: format!("[{i}].paths[{k}]"),
                problem,
            })?;
            contours.push(contour);
        }
        parts.push(Part {
            name: part.partid,
            contours,
        });
    }
    let mut parts = parts.into_iter();
    // A first element without paths is the writer's marker of a nest without a sheet.
    let sheet = if options.first_part_is_sheet {
        parts.next().filter(|sheet| !sheet.contours.is_empty())
    } else {
        None
    };
    Ok(Nest {
        sheet,
        parts: parts.collect(),
    })
}

/// Writes a nest as geometry JSON, one point per line. The format's first element is the
/// sheet: a nest without one gets an element without paths there ([`NO_SHEET`]), which the
/// reader takes for "no sheet", so its first part is not read back as the sheet.
pub fn write_geometry_json(nest: &Nest) -> Result<String, JsonWriteError> {
    let mut out = String::from("[");
    let no_sheet = Part {
        name: NO_SHEET.into(),
        contours: Vec::new(),
    };
    let sheet = nest.sheet.as_ref().unwrap_or(&no_sheet);
    for (i, part) in std::iter::once(sheet).chain(&nest.parts).enumerate() {
        if i > 0 {
            out.push(',');
        }
        let name = serde_json::to_string(&part.name).unwrap_or_else(|_| "\"\"".into());
        out.push_str(&format!(
            "\n  {{\n    \"partid\": {name},\n    \"paths\": ["
        ));
        for (k, contour) in part.contours.iter().enumerate() {
            out.push_str(if k > 0 { ",\n      [" } else { "\n      [" });
            for (j, p) in contour_check::stored_points(contour).iter().enumerate() {
                let nums: Option<Vec<String>> = p.iter().map(|v| json::number(*v)).collect();
                let nums = nums.ok_or_else(|| JsonWriteError::NonFinite {
                    path: format!("[{i}].paths[{k}][{j}]"),
                })?;
                out.push_str(if j > 0 { ",\n        [" } else { "\n        [" });
                out.push_str(&nums.join(", "));
                out.push(']');
            }
            out.push_str("\n      ]");
        }
        out.push_str("\n    ]\n  }");
    }
    out.push_str("\n]\n");
    Ok(out)
}
