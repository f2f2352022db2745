//! Kerf geometry: the equidistant that the tool centre runs on, and the pierce and switch-off
//! regions G_M (1.5) and G_M* (1.6) of the dissertation's model.
//!
//! The tool burns a kerf of width `k`, so its centre runs on the *equidistant* at `k/2` from a
//! contour on the scrap side: outward for outer contours, inward for holes. After
//! [`Nest::normalize_orientation`] outer contours run clockwise and holes counter-clockwise,
//! so the scrap is always on the left of the direction of travel and one rule ("offset to the
//! left") serves both.
//!
//! Offsets are exact for lines and arcs: they are computed by `cavalier_contours`
//! (bulge polylines, the same encoding as [`Contour`]), converted in this module only.
//!
//! ```
//! use cutroute_geometry::{equidistant, Contour, Point};
//! // A clockwise (outer) circle of radius 10: its equidistant at 1 is the circle of radius 11.
//! let circle = Contour::circle(Point::new(0.0, 0.0), 10.0, true);
//! let offset = equidistant(&circle, 1.0).unwrap();
//! assert!((offset.perimeter() - 2.0 * std::f64::consts::PI * 11.0).abs() < 1e-9);
//! assert!(offset.is_clockwise());
//! // A counter-clockwise hole of radius 10 shrinks to radius 9.
//! let hole = Contour::circle(Point::new(0.0, 0.0), 10.0, false);
//! let inner = equidistant(&hole, 1.0).unwrap();
//! assert!((inner.perimeter() - 2.0 * std::f64::consts::PI * 9.0).abs() < 1e-9);
//! ```

use cavalier_contours::polyline::{
    PlineCreation, PlineSource, PlineSourceMut, PlineVertex, Polyline,
};
use thiserror::Error;

use crate::{offset_carrier, Contour, ContourRef, Nest, Point, Vertex};

/// Why a contour has no single equidistant at the asked distance.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum OffsetError {
    /// The distance is negative or not finite.
    #[error("offset distance {distance} is not a finite non-negative number")]
    BadDistance {
        /// The distance asked.
        distance: f64,
    },
    /// The contour closes up at that distance (a hole narrower than twice the distance).
    #[error("the contour vanishes when offset by {distance} mm")]
    Vanishes {
        /// The distance asked.
        distance: f64,
    },
    /// The offset library failed on this contour (degenerate geometry).
    #[error("the offset by {distance} mm failed on degenerate geometry")]
    Failed {
        /// The distance asked.
        distance: f64,
    },
    /// The contour turns back on itself at a vertex (its two spans leave it in opposite
    /// directions, a spike of no width), and the offset library finds no equidistant outward
    /// (it sees the spans cross again micrometres from the vertex).
    #[error(
        "the contour turns back on itself at ({x:.6}, {y:.6}) (a cusp): no equidistant at {distance} mm"
    )]
    Cusp {
        /// The distance asked.
        distance: f64,
        /// The cusp vertex.
        x: f64,
        /// The cusp vertex.
        y: f64,
    },
    /// An inward offset falls apart into several closed loops (a hole with a narrow waist),
    /// so one cut cannot follow it. (Outward, the loop round the outside is the equidistant.)
    #[error("the contour splits into {pieces} loops when offset by {distance} mm")]
    Splits {
        /// The distance asked.
        distance: f64,
        /// Number of loops.
        pieces: usize,
    },
}

/// The one conversion from a [`Contour`] to cavalier's closed bulge polyline.
fn to_polyline(contour: &Contour) -> Polyline<f64> {
    let mut pline = Polyline::with_capacity(contour.vertices.len(), true);
    for v in &contour.vertices {
        pline.add_vertex(PlineVertex::new(v.point.x, v.point.y, v.bulge));
    }
    pline
}

/// The one conversion back from cavalier's polyline to a [`Contour`].
fn from_polyline(pline: &Polyline<f64>) -> Contour {
    Contour::new(
        pline
            .iter_vertexes()
            .map(|v| Vertex::arc(v.x, v.y, v.bulge))
            .collect(),
    )
}

/// The equidistant of `contour` at `distance` on its left side (the scrap side of an
/// oriented contour): a closed contour in the same direction, with exact arcs. Distance 0
/// returns the contour itself. Outward (clockwise contours), notches narrower than twice the
/// distance close, and the loop round the outside is returned.
pub fn equidistant(contour: &Contour, distance: f64) -> Result<Contour, OffsetError> {
    if !(distance >= 0.0) || !distance.is_finite() {
        return Err(OffsetError::BadDistance { distance });
    }
    if distance == 0.0 {
        return Ok(contour.clone());
    }
    // Repeated and collinear vertices (files have them) trip cavalier's internal asserts:
    // drop them first, within an epsilon relative to the contour's size, and retry with a
    // coarser one if the library still fails.
    let pline = to_polyline(&offset_carrier::flattened(contour));
    let scale = (contour.bounding_box().width() + contour.bounding_box().height()).max(1.0);
    let mut loops = None;
    for relative_eps in [1e-9, 1e-6, 1e-4] {
        let cleaned = pline
            .remove_redundant(relative_eps * scale)
            .unwrap_or_else(|| pline.clone());
        // A guard where unwinding exists (native): a panic inside the library is an error
        // of this contour, not a crash of the caller.
        if let Ok(result) = std::panic::catch_unwind(|| cleaned.parallel_offset(distance)) {
            loops = Some(result);
            break;
        }
    }
    let loops = loops.ok_or(OffsetError::Failed { distance })?;
    // The library's vertices can be micrometres off beside nearly straight arcs (and the arcs
    // it was given as chords are not yet arcs): the loop that is returned gets exact vertices
    // and bulges from the contour itself.
    let exact = |l: &Polyline<f64>| offset_carrier::refine(contour, &from_polyline(l), distance);
    // Corners drawn as runs of tiny segments can leave degenerate loops of zero area beside
    // the real one (a 17 mm slot of seven.dbs came back in three pieces at 1 mm: the slot and
    // two 2-vertex loops); they enclose nothing and are no part of the tool's path.
    let degenerate = 1e-12 * scale * scale;
    let mut loops: Vec<Polyline<f64>> = loops
        .into_iter()
        .filter(|l| from_polyline(l).area().abs() > degenerate)
        .collect();
    match loops.len() {
        // Outward a contour never vanishes: the library failed, at a cusp where it has seen one.
        0 if contour.is_clockwise() => Err(match cusp(contour) {
            Some(p) => OffsetError::Cusp {
                distance,
                x: p.x,
                y: p.y,
            },
            None => OffsetError::Failed { distance },
        }),
        0 => Err(OffsetError::Vanishes { distance }),
        1 => Ok(exact(&loops.remove(0))),
        // Outward (a clockwise contour's left): a notch narrower than twice the distance
        // closes and leaves an enclosed loop the tool never reaches; the path is the loop
        // round the outside, the largest.
        _ if contour.is_clockwise() => {
            let outside = loops
                .iter()
                .max_by(|a, b| from_polyline(a).area().total_cmp(&from_polyline(b).area()))
                .expect("several loops");
            Ok(exact(outside))
        }
        pieces => Err(OffsetError::Splits { distance, pieces }),
    }
}

/// The first vertex where the contour turns back on itself: the span into it ends in the
/// direction opposite to where the span out of it starts (within 1.4·10⁻³ rad).
fn cusp(contour: &Contour) -> Option<Point> {
    let spans: Vec<_> = contour.spans().collect();
    (0..spans.len()).find_map(|k| {
        let into = &spans[(k + spans.len() - 1) % spans.len()];
        let out = &spans[k];
        (into.tangent_at(1.0).dot(out.tangent_at(0.0)) < -1.0 + 1e-6).then_some(out.start)
    })
}

/// The least distance from `p` to any contour of the nest, searching only contours whose
/// boxes come within `limit` of `p`; `f64::INFINITY` when none does.
pub fn clearance(nest: &Nest, p: Point, limit: f64) -> f64 {
    nest.contour_refs()
        .filter_map(|r| nest.contour(r))
        .filter(|c| c.bounding_box().expanded(limit).contains_point(p))
        .map(|c| c.distance_to(p))
        .fold(f64::INFINITY, f64::min)
}

/// Whether `p` lies in the region of points at least `distance` from every contour and in the
/// scrap on the cut side of `contour` (outside it and its siblings, inside the hole that holds
/// it; inside it and outside its islands for a hole) — G_M for d₁, G_M* for d₂, restricted to
/// the scrap region the contour's leads live in, and on the sheet at least `distance` from its
/// border where the nest has a sheet.
pub fn in_clear_scrap(
    nest: &Nest,
    forest: &crate::ContainmentForest,
    contour: ContourRef,
    p: Point,
    distance: f64,
) -> bool {
    if nest.contour(contour).is_none() {
        return false;
    }
    // Outer contours (even depth) lead in from their parent's scrap region; holes from their own.
    let is_hole = forest.depth(contour).is_some_and(|d| d % 2 == 1);
    let region = if is_hole {
        Some(contour)
    } else {
        forest.parent(contour)
    };
    p.is_finite()
        && crate::leads::on_sheet(nest, p, distance)
        && crate::in_scrap_region(nest, forest, region, p)
        && !(clearance(nest, p, distance) < distance)
}
