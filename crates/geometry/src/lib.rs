//! Plane geometry of sheet-cutting plans: points, bulge arcs, closed contours, parts and nests.
//!
//! A contour is a closed chain of *spans*; each span runs from one vertex to the next and is a
//! straight segment (`bulge == 0`) or a circular arc whose bulge is `tan(φ/4)` of its swept
//! angle φ (positive = counter-clockwise). The closing span runs from the last vertex back to the
//! first: the duplicated closing point that files store is dropped by the readers.
//!
//! ```
//! use cutroute_geometry::{Contour, Point, Vertex};
//! // A 10 × 10 square, clockwise as outer contours are.
//! let square = Contour::new(vec![
//!     Vertex::line(0.0, 0.0),
//!     Vertex::line(0.0, 10.0),
//!     Vertex::line(10.0, 10.0),
//!     Vertex::line(10.0, 0.0),
//! ]);
//! assert_eq!(square.vertices.len(), 4);
//! assert_eq!(square.vertices[2].point, Point::new(10.0, 10.0));
//! ```
#![deny(missing_docs)]

mod route;
mod types;

pub use route::{ContourRef, CutStep, Route};
pub use types::{Contour, Nest, Part, Point, Vertex};
