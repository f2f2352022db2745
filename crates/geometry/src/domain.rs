//! The numeric domain of every reader: what a coordinate, a bulge and a contour may be.
//!
//! Every nest reader (geometry JSON, DBS, RouteManager task JSON, DXF, T-FLEX) checks what it
//! reads against these rules, so a solver never sees a value that only one format let through:
//! - coordinates are finite and within ±[`MAX_COORDINATE`] mm (a kilometre-scale sheet is
//!   1e6 mm; 1e9 leaves room for transforms, and every length, area and sum of lengths of a
//!   route stays finite and far from overflow);
//! - bulges (tan(φ/4) of an arc's sweep) are finite and within ±[`MAX_BULGE`]: a sweep of at
//!   most 4·atan(1e4) ≈ 359.98°, beyond which an arc is a numerically degenerate full circle
//!   (files store circles as two arcs);
//! - a contour spans at least [`MIN_CONTOUR_EXTENT`] mm along x or y (its exact bounding box,
//!   arcs included): smaller contours are points to any cutting machine (kerfs are 0.1 mm and
//!   more), and the plane graph of the common-edge solvers (sccp, gsccp, aoe) snaps points
//!   within 0.001 mm, which left circles of up to 0.01 mm uncut (found by fuzzing); 0.05 mm
//!   keeps a factor of 50 from that snap.
//!
//! Readers report a [`DomainError`] with their own location (line, JSON path, byte offset).

use crate::{Contour, Nest, Vertex};

/// Largest absolute coordinate a reader accepts, mm.
pub const MAX_COORDINATE: f64 = 1e9;

/// Largest absolute bulge a reader accepts.
pub const MAX_BULGE: f64 = 1e4;

/// Smallest extent (the larger side of a contour's bounding box) a reader accepts, mm.
pub const MIN_CONTOUR_EXTENT: f64 = 0.05;

/// A value outside the domain of [`MAX_COORDINATE`], [`MAX_BULGE`] and [`MIN_CONTOUR_EXTENT`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DomainError {
    /// A coordinate is NaN, infinite or beyond ±[`MAX_COORDINATE`].
    #[error("vertex {index}: coordinate {value:e} is not a finite number within ±1e9 mm")]
    Coordinate {
        /// The vertex's index in its contour.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A bulge is NaN, infinite or beyond ±[`MAX_BULGE`].
    #[error("vertex {index}: bulge {value:e} is not a finite number within ±1e4")]
    Bulge {
        /// The vertex's index in its contour.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The contour is smaller than [`MIN_CONTOUR_EXTENT`] along both axes.
    #[error("spans {extent:e} mm, below the 0.05 mm a contour must span")]
    TooSmall {
        /// The larger side of its bounding box, mm.
        extent: f64,
    },
}

/// Whether `value` is a coordinate a reader accepts.
pub fn is_valid_coordinate(value: f64) -> bool {
    value.is_finite() && value.abs() <= MAX_COORDINATE
}

/// Checks one coordinate (of vertex `index`).
pub fn check_coordinate(index: usize, value: f64) -> Result<(), DomainError> {
    if is_valid_coordinate(value) {
        Ok(())
    } else {
        Err(DomainError::Coordinate { index, value })
    }
}

/// Checks one bulge (of vertex `index`).
pub fn check_bulge(index: usize, value: f64) -> Result<(), DomainError> {
    if value.is_finite() && value.abs() <= MAX_BULGE {
        Ok(())
    } else {
        Err(DomainError::Bulge { index, value })
    }
}

/// Checks every coordinate and bulge of a vertex list.
pub fn check_vertices(vertices: &[Vertex]) -> Result<(), DomainError> {
    for (index, v) in vertices.iter().enumerate() {
        check_coordinate(index, v.point.x)?;
        check_coordinate(index, v.point.y)?;
        check_bulge(index, v.bulge)?;
    }
    Ok(())
}

/// Checks a contour: its values, then its extent.
pub fn check_contour(contour: &Contour) -> Result<(), DomainError> {
    check_vertices(&contour.vertices)?;
    let b = contour.bounding_box();
    let extent = (b.max.x - b.min.x).max(b.max.y - b.min.y);
    // `!(a >= b)` also refuses a NaN extent.
    if !(extent >= MIN_CONTOUR_EXTENT) {
        return Err(DomainError::TooSmall { extent });
    }
    Ok(())
}

/// Where in a nest a contour breaks the domain, and how.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{} contour {contour}: {error}", part.map_or_else(|| "sheet".to_string(), |p| format!("part {p}")))]
pub struct NestDomainError {
    /// The part's index in `Nest::parts`, `None` for the sheet.
    pub part: Option<usize>,
    /// The contour's index in its part.
    pub contour: usize,
    /// What is wrong.
    pub error: DomainError,
}

impl Nest {
    /// The first contour of the sheet or a part outside the readers' domain ([`check_contour`]).
    pub fn check_domain(&self) -> Result<(), NestDomainError> {
        let sheet = self.sheet.iter().map(|s| (None, s));
        let parts = self.parts.iter().enumerate().map(|(i, p)| (Some(i), p));
        for (part, p) in sheet.chain(parts) {
            for (contour, c) in p.contours.iter().enumerate() {
                check_contour(c).map_err(|error| NestDomainError {
                    part,
                    contour,
                    error,
                })?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Point;

    fn square(side: f64) -> Contour {
        Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, side),
            Vertex::line(side, side),
            Vertex::line(side, 0.0),
        ])
    }

    #[test]
    fn limits_are_inclusive_and_refuse_non_finite_values() {
        assert!(check_coordinate(0, MAX_COORDINATE).is_ok());
        assert!(check_coordinate(0, -MAX_COORDINATE).is_ok());
        for bad in [f64::NAN, f64::INFINITY, 1.0e9 + 1.0, -1e308] {
            assert!(check_coordinate(3, bad).is_err(), "{bad}");
        }
        assert!(check_bulge(0, MAX_BULGE).is_ok());
        for bad in [f64::NAN, f64::NEG_INFINITY, 1e300] {
            assert!(check_bulge(0, bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn points_and_microscopic_contours_are_refused() {
        assert!(check_contour(&square(1.0)).is_ok());
        assert!(check_contour(&square(MIN_CONTOUR_EXTENT)).is_ok());
        assert!(matches!(
            check_contour(&square(1e-6)),
            Err(DomainError::TooSmall { .. })
        ));
        assert!(check_contour(&square(0.0)).is_err());
        let dot = Contour::circle(Point::new(5.0, 5.0), 1e-9, false);
        assert!(check_contour(&dot).is_err());
    }
}
