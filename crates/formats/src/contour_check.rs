//! Turning a stored point list (closing point repeated) into a [`Contour`], and the checks every
//! reader applies to it. The readers wrap a [`ContourProblem`] into their own error type together
//! with the location (byte offset or JSON path).

use cutroute_geometry::float::Libm;
use cutroute_geometry::{domain, Contour, ContourFault, DomainError, Vertex};

/// How far apart (mm) the first and last stored points may be for the contour to count as closed.
pub const DEFAULT_CLOSURE_TOLERANCE: f64 = 1e-3;

/// What is wrong with one stored contour.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContourProblem {
    /// The first and last stored points differ by more than the closure tolerance.
    #[error("contour is not closed: its first and last points are {gap} mm apart")]
    Unclosed {
        /// Distance between the first and the last stored point, mm.
        gap: f64,
    },
    /// After dropping the closing point fewer than two vertices remain.
    #[error("contour has {count} distinct vertices; a closed contour needs at least 2")]
    TooFewVertices {
        /// Vertices left after dropping the closing point.
        count: usize,
    },
    /// A coordinate or bulge is NaN or infinite.
    #[error("contour point {index} has a non-finite coordinate or bulge")]
    NonFinite {
        /// Index of the offending point in the stored list.
        index: usize,
    },
    /// A coordinate, bulge or the contour's size is outside the readers' domain
    /// (`cutroute_geometry::domain`).
    #[error("contour {0}")]
    Domain(#[from] DomainError),
    /// The contour crosses or touches itself.
    #[error("contour intersects itself: spans {first_span} and {second_span} meet at ({x}, {y})")]
    SelfIntersecting {
        /// The lower span index (span i runs from vertex i to vertex i+1).
        first_span: usize,
        /// The higher span index.
        second_span: usize,
        /// Where they meet, x.
        x: f64,
        /// Where they meet, y.
        y: f64,
    },
    /// The contour encloses no area, or less than a region one closure tolerance wide (see
    /// [`ContourFault`]).
    #[error("{0}")]
    NoArea(ContourFault),
}

/// Checks a stored point list `(x, y, bulge)` whose last point repeats the first, and returns the
/// contour without the closing point. The contour must be cuttable
/// ([`Contour::check_cuttable`] with the closure tolerance): a nest format refuses, with its
/// location, what a drawing would leave out with a warning. `check_self_intersection: false`
/// skips that whole check (the fuzz target, which exercises the parser).
pub(crate) fn closed_contour(
    points: &[[f64; 3]],
    tolerance: f64,
    check_self_intersection: bool,
) -> Result<Contour, ContourProblem> {
    if let Some(index) = points.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
        return Err(ContourProblem::NonFinite { index });
    }
    for (index, p) in points.iter().enumerate() {
        domain::check_coordinate(index, p[0])?;
        domain::check_coordinate(index, p[1])?;
        domain::check_bulge(index, p[2])?;
    }
    let (first, last) = match (points.first(), points.last()) {
        (Some(f), Some(l)) if points.len() >= 2 => (f, l),
        _ => {
            return Err(ContourProblem::TooFewVertices {
                count: points.len(),
            })
        }
    };
    let gap = (first[0] - last[0]).hypot_libm(first[1] - last[1]);
    // A NaN gap (from overflowing coordinates) must be rejected too, hence not `gap > tolerance`.
    if gap.is_nan() || gap > tolerance {
        return Err(ContourProblem::Unclosed { gap });
    }
    let vertices: Vec<Vertex> = points[..points.len() - 1]
        .iter()
        .map(|p| Vertex::arc(p[0], p[1], p[2]))
        .collect();
    if vertices.len() < 2 {
        return Err(ContourProblem::TooFewVertices {
            count: vertices.len(),
        });
    }
    let contour = Contour::new(vertices);
    domain::check_contour(&contour)?;
    if check_self_intersection {
        match contour.check_cuttable(tolerance) {
            Ok(()) => {}
            Err(ContourFault::SelfIntersecting {
                first_span,
                second_span,
                x,
                y,
            }) => {
                return Err(ContourProblem::SelfIntersecting {
                    first_span,
                    second_span,
                    x,
                    y,
                })
            }
            Err(fault) => return Err(ContourProblem::NoArea(fault)),
        }
    }
    Ok(contour)
}

/// The stored form of a contour: its vertices and the closing point again with bulge 0.
pub(crate) fn stored_points(contour: &Contour) -> Vec<[f64; 3]> {
    let mut out: Vec<[f64; 3]> = contour
        .vertices
        .iter()
        .map(|v| [v.point.x, v.point.y, v.bulge])
        .collect();
    if let Some(first) = contour.vertices.first() {
        out.push([first.point.x, first.point.y, 0.0]);
    }
    out
}
