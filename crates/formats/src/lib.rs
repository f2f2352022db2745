//! Readers and writers of the sheet-cutting world's file formats, all speaking the shared model
//! of `cutroute-geometry` ([`Nest`], [`Part`], [`Contour`], [`Route`]).
//!
//! | format | read | write |
//! |---|---|---|
//! | legacy binary DBS (thesis App. В) | [`read_dbs`] → [`DbsFile`] | [`write_dbs`] |
//! | geometry JSON (`dbs.json`, App. Г.1) | [`read_geometry_json`] | [`write_geometry_json`] |
//! | RouteManager task (`rm-task.json`, Г.2) | [`read_task_json`] → [`RmTask`] | [`write_task_json`] |
//! | RouteManager result (`rm-result.json`, Г.3) | [`read_result_json`] → [`RmResult`] | [`write_result_json`], [`RmResult::from_route`] |
//! | SVG | — | [`nest_svg`] |
//! | standalone HTML (animated route) | — | [`route_html`], [`toolpath_html`] |
//!
//! [`detect`] recognises a format from content and [`read_nest`] reads a nest from whichever
//! format holds one. Every reader returns a typed error saying what is wrong and where (byte
//! offset for DBS, JSON path or line/column for JSON); none panics, loops or allocates without
//! bound on hostile input (the crate's `fuzz/` project exercises this).
//!
//! ```
//! use cutroute_formats::{detect, read_geometry_json, write_dbs, read_dbs, nest_svg, Format, SvgOptions};
//!
//! // Listing 4.1 of the thesis: a 700 × 500 sheet and one ring (radii 200 and 100).
//! let json = br#"[{"partid": "LIST", "paths": [[[0,0,0],[0,500,0],[700,500,0],[700,0,0],[0,0,0]]]},
//!                {"partid": "RING", "paths": [[[205,405,-1],[205,5,-1],[205,405,0]],
//!                                             [[205,305,1],[205,105,1],[205,305,0]]]}]"#;
//! assert_eq!(detect(json), Format::GeometryJson);
//! let nest = read_geometry_json(json)?;
//! assert_eq!(nest.sheet.as_ref().unwrap().name, "LIST");
//! assert_eq!(nest.parts[0].contours.len(), 2);
//!
//! // Through DBS and back: same nest, and the file knows the ring's area in dm².
//! let bytes = write_dbs(&nest)?;
//! assert_eq!(detect(&bytes), Format::DbsBinary);
//! let file = read_dbs(&bytes)?;
//! assert_eq!(file.nest, nest);
//! let ring_area = std::f64::consts::PI * (200.0f64.powi(2) - 100.0f64.powi(2)) * 1e-4;
//! assert!((f64::from(file.part_records[1].area_dm2.unwrap()) - ring_area).abs() < 1e-3);
//!
//! let svg = nest_svg(&nest, None, &SvgOptions::default());
//! assert!(svg.contains("class=\"sheet\""));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod contour_check;
mod dbs;
mod detect;
mod geometry_json;
mod html_export;
mod json;
mod path_data;
mod result_json;
mod svg_export;
mod task_json;

#[cfg(doc)]
use cutroute_geometry::{Contour, Part};
use cutroute_geometry::{Nest, Route};

pub use contour_check::{ContourProblem, DEFAULT_CLOSURE_TOLERANCE};
pub use dbs::{
    read_dbs, read_dbs_with, write_dbs, write_dbs_with, DbsError, DbsFile, DbsPartRecord,
    DbsReadOptions, DbsWriteError, DbsWriteOptions, SheetDetection,
};
pub use detect::{detect, read_nest, Format, ReadError};
pub use geometry_json::{
    parse_geometry_json, read_geometry_json, read_geometry_json_with, write_geometry_json,
    GeometryJsonOptions, GeometryJsonPart,
};
pub use html_export::{route_html, toolpath_html, HtmlExportError, HtmlOptions};
pub use json::{JsonError, JsonWriteError};
pub use result_json::{
    read_result_json, route_moves, write_result_json, Job, MoveKind, ResultExportOptions,
    ResultPath, Results, RmResult, RouteError, ToolMove, ToolpathEntry,
};
pub use svg_export::{nest_svg, SvgOptions, DEFAULT_STYLE};
pub use task_json::{
    read_task_json, write_task_json, FlatTaskContour, PiercePoint, RmTask, TaskContour, TaskData,
};

/// Area (mm², outer contour minus holes) of a part, as DBS record 27 stores it (in dm²):
/// [`Part::area`](cutroute_geometry::Part::area).
pub fn part_area(part: &cutroute_geometry::Part) -> f64 {
    part.area()
}

/// Perimeter (mm, all contours) of a part, as DBS record 27 stores it (in dm):
/// [`Part::perimeter`](cutroute_geometry::Part::perimeter).
pub fn part_perimeter(part: &cutroute_geometry::Part) -> f64 {
    part.perimeter()
}

/// Renders a nest with a route over it (convenience over [`route_moves`] + [`nest_svg`]).
pub fn route_svg(nest: &Nest, route: &Route, options: &SvgOptions) -> Result<String, RouteError> {
    let moves = route_moves(nest, route)?;
    Ok(nest_svg(nest, Some(&moves), options))
}
