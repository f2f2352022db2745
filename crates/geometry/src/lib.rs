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
// `!(x <= tol)` is deliberate throughout: it is true for NaN, so bad input fails checks
// instead of slipping through them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bbox;
mod contour;
mod forest;
mod generator;
mod point;
mod route;
mod span;
mod transform;
mod types;

pub use bbox::BoundingBox;
pub use contour::{
    ClosureError, ContourError, ContourPosition, ContourProjection, SelfIntersection,
};
pub use forest::ContainmentForest;
pub use generator::{generate_nest, SplitMix64};
pub use route::{ContourRef, CutStep, MachineParameters, Route, RouteError};
pub use span::{tan_half_arg, Span, SpanIntersection, SpanProjection};
pub use transform::Transform;
pub use types::{Contour, Nest, Part, Point, Vertex};
