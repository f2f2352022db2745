//! G-code for cutroute: a post-processor that writes a [`Toolpath`] as a program for a CNC
//! cutting machine (laser, plasma, water jet), and a reader that turns such a program back into
//! the tool's motion.
//!
//! The writer ([`write_gcode`], [`route_gcode`], [`path_route_gcode`] for routes of tool-on paths) is configured by a plain [`GcodeOptions`]:
//! absolute (`G90`) or incremental (`G91`) coordinates in millimetres (`G21`), the number of
//! decimals, optional `N` line numbers, arcs as `G02`/`G03` with `I`/`J` centre offsets, with `R`
//! (arcs split into pieces of at most 150°), or flattened into `G01` chords, rapid `G00` idle moves, the cutting feed
//! `F` (mm/min), configurable torch on/off lines (default `M03`/`M05`), a pierce dwell
//! `G04 P<seconds>`, header and footer lines, and comments naming the part and contour of every
//! pierce. Coordinates are rounded once to the last written digit and tracked as integers, so an
//! incremental program does not drift and arc centres fit the rounded start exactly.
//!
//! Named dialects ([`GcodePreset`]: GRBL laser, LinuxCNC QtPlasmaC, Mach3 plasma, Fanuc-style
//! dwell in ms, the gas cutter «Комета» with CNC 2P32M) fill these options for a machine.
//!
//! The reader ([`read_gcode`]) understands that subset and common variants (see its module
//! notes), reports errors with line and column, and never panics.
//!
//! Arc direction follows the geometry crate: a positive bulge is counter-clockwise, which is
//! `G03`.
//!
//! ```
//! use cutroute_gcode::{read_gcode, write_gcode, GcodeOptions, ReadOptions};
//! use cutroute_geometry::{Point, Span, ToolMove, Toolpath};
//!
//! // Pierce at (10, 0) and cut a half circle counter-clockwise about the origin.
//! let at = Point::new(10.0, 0.0);
//! let path = Toolpath {
//!     start: Point::new(0.0, 0.0),
//!     moves: vec![
//!         ToolMove::Idle { from: Point::new(0.0, 0.0), to: at },
//!         ToolMove::Pierce { at, step: 0 },
//!         ToolMove::Cut { step: 0, span: Span::new(at, Point::new(-10.0, 0.0), 1.0), link: false },
//!     ],
//! };
//! let options = GcodeOptions { pierce_dwell_s: 0.5, ..GcodeOptions::default() };
//! let gcode = write_gcode(&path, &options)?;
//! assert!(gcode.contains("G00 X10.000 Y0.000\nM03\nG04 P0.500\nG03 X-10.000 I-10.000 J0.000 F600\nM05\n"));
//!
//! let program = read_gcode(&gcode, &ReadOptions::default())?;
//! assert_eq!(program.pierce_count(), 1);
//! assert!((program.cut_length() - 10.0 * std::f64::consts::PI).abs() < 1e-9);
//! assert!((program.idle_length() - 10.0).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod preset;
mod read;
mod write;

#[cfg(doc)]
use cutroute_geometry::Toolpath;

pub use preset::{GcodePreset, UnknownPreset, UnsupportedCompensation};
pub use read::{
    closed_loop_start, read_gcode, CompensationModel, GcodeReadError, Motion, Program, ReadOptions,
};
pub use write::{
    path_route_gcode, route_gcode, write_gcode, ArcOutput, DistanceMode, DwellFormat, GcodeError,
    GcodeOptions, KerfCompensation,
};
