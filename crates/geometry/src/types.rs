//! The shared data model: every crate of cutroute speaks these types.

use serde::{Deserialize, Serialize};

/// A point (or vector) in the sheet plane, in millimetres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// Horizontal coordinate.
    pub x: f64,
    /// Vertical coordinate (y grows upwards, as in CAD files).
    pub y: f64,
}

impl Point {
    /// A point from its coordinates.
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }
}

/// A contour vertex and the shape of the span that leaves it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vertex {
    /// Where the span starts.
    pub point: Point,
    /// `tan(φ/4)` of the arc from this vertex to the next one; 0 for a straight segment.
    pub bulge: f64,
}

impl Vertex {
    /// A vertex followed by a straight segment.
    pub const fn line(x: f64, y: f64) -> Self {
        Self {
            point: Point::new(x, y),
            bulge: 0.0,
        }
    }

    /// A vertex followed by an arc of the given bulge.
    pub const fn arc(x: f64, y: f64, bulge: f64) -> Self {
        Self {
            point: Point::new(x, y),
            bulge,
        }
    }
}

/// A closed contour: spans run from each vertex to the next and from the last back to the first.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Contour {
    /// The vertices in cutting direction; the closing point is not repeated.
    pub vertices: Vec<Vertex>,
}

impl Contour {
    /// A contour from its vertices (closing point not repeated).
    pub fn new(vertices: Vec<Vertex>) -> Self {
        Self { vertices }
    }

    /// The axis-parallel rectangle with corners (x0, y0) and (x1, y1), its vertices in the
    /// order (x0, y0), (x0, y1), (x1, y1), (x1, y0): clockwise when x0 < x1 and y0 < y1, the
    /// direction outer contours run in.
    ///
    /// ```
    /// use cutroute_geometry::Contour;
    /// let square = Contour::rectangle(0.0, 0.0, 10.0, 10.0);
    /// assert_eq!(square.vertices.len(), 4);
    /// assert!((square.perimeter() - 40.0).abs() < 1e-12);
    /// ```
    pub fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Self::new(vec![
            Vertex::line(x0, y0),
            Vertex::line(x0, y1),
            Vertex::line(x1, y1),
            Vertex::line(x1, y0),
        ])
    }
}

/// A part: its outer contour first, then its holes.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Part {
    /// The part's designation as stored in the file (DBS record 26, JSON `partid`).
    pub name: String,
    /// Outer contour first, then the holes, in file order.
    pub contours: Vec<Contour>,
}

/// A cutting plan: the sheet (when the file has one) and the parts placed on it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Nest {
    /// The sheet, when the file describes one (geometry JSON: its first part).
    pub sheet: Option<Part>,
    /// The placed parts, in file order.
    pub parts: Vec<Part>,
}
