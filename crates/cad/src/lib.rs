//! Import of CAD drawings and nesting projects into cutroute's shared nest model.
//!
//! A cutting route is planned over a [`Nest`](cutroute_geometry::Nest): closed contours grouped
//! into parts (outer contour clockwise, holes counter-clockwise, millimetres). Designers deliver
//! parts as CAD drawings, where a part is a loose heap of lines, arcs and splines, and nesting
//! programs deliver finished layouts. This crate turns both into nests:
//!
//! - [`dxf::read_dxf`] reads an ASCII DXF drawing: it approximates splines and ellipses by arcs
//!   within a tolerance, expands block inserts, joins loose entities into closed contours, orients
//!   them, groups them into parts by containment, and reports what stayed open.
//! - [`svg::read_svg`] reads an SVG nest (DeepNest, SVGnest, cutroute's export): paths,
//!   basic shapes and transforms, curves approximated by arcs as for DXF, y turned up.
//! - [`tflex::read_tfnesting`] reads a T-FLEX nesting project (`.tfnesting` XML) and places every
//!   part on its sheet, one nest per sheet layout.
//!
//! Both readers take untrusted bytes: malformed input yields a typed error that says what is
//! wrong and where (DXF line, XML element and position), never a panic or unbounded work.
//!
//! ```
//! use cutroute_cad::dxf::{read_dxf, DxfOptions};
//!
//! // A 40 × 20 rectangle drawn as four loose lines, and a Ø10 hole in it.
//! let drawing = "0\nSECTION\n2\nENTITIES\n\
//!     0\nLINE\n8\nPLATE\n10\n0\n20\n0\n11\n40\n21\n0\n\
//!     0\nLINE\n8\nPLATE\n10\n40\n20\n0\n11\n40\n21\n20\n\
//!     0\nLINE\n8\nPLATE\n10\n0\n20\n20\n11\n40\n21\n20\n\
//!     0\nLINE\n8\nPLATE\n10\n0\n20\n0\n11\n0\n21\n20\n\
//!     0\nCIRCLE\n8\nPLATE\n10\n20\n20\n10\n40\n5\n\
//!     0\nENDSEC\n0\nEOF\n";
//! let import = read_dxf(drawing.as_bytes(), &DxfOptions::default()).unwrap();
//! assert_eq!(import.nest.parts.len(), 1);
//! let part = &import.nest.parts[0];
//! assert_eq!(part.contours.len(), 2); // the outline, then the hole
//! assert_eq!(part.contours[0].vertices.len(), 4);
//! assert!(import.open_chains.is_empty());
//! ```
#![deny(missing_docs)]

mod assemble;
mod curves;
pub mod dxf;
mod error;
pub mod svg;
pub mod tflex;

pub use assemble::{DrawingImport, EntityRef, OpenChain};
pub use error::CadError;
