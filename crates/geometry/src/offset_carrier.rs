//! Exact vertices for the equidistants `cavalier_contours` computes.
//!
//! Every span of an equidistant runs on a *carrier*: the offset of one source span (a line, or
//! a circle concentric with the source arc), or the round corner of radius d about a source
//! vertex. Its vertices are where consecutive carriers meet. The library finds those points
//! through the circles' centres, and a nearly straight arc's centre lies hundreds of metres
//! away: a bulge of 1e-5 on a 15 mm chord has its centre 600 m off, and the circle–circle
//! intersection then loses micrometres to cancellation (R² − a² with R² ≈ 4·10¹¹ mm²). Here
//! each span's carrier is recognised among the source's, each vertex is moved to the meeting
//! point of its two carriers by Newton's method in a form with no centre, and each bulge is
//! recomputed from its carrier, so the equidistant is as exact as the source allows.

use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use crate::{tan_half_arg, BoundingBox, Contour, Point, Span, Vertex};

/// How far (mm, plus a relative part for large coordinates) an output span's ends and midpoint
/// may lie from a carrier to be taken as running on it. The library's error grows with the
/// square of a nearly straight arc's radius (3 µm at bulge 1e-5 on a 15 mm chord, 60 µm at
/// 2e-6, 2.4 mm at 5e-7), so this is loose; the best fitting carrier is taken, and
/// [`refine`] keeps the library's loop if the refined one is not closer to the distance.
const ON_CARRIER: f64 = 1e-2;

/// How far a vertex may move to the meeting point of its carriers. Where they cross at a
/// shallow angle the meeting point slides along them by the residual over the angle's sine,
/// so this is above [`ON_CARRIER`]; a longer move means a misread carrier, and the vertex is
/// left where it is.
const MAX_MOVE: f64 = 5e-2;

/// Below this |bulge| (and [`FLAT_SAGITTA`]) an arc goes to the library as its chord: between
/// bulges of about 1e-8 and 1e-6 the library's results are not just imprecise but wrong (whole
/// loops lost, vertices millimetres off), while its chord's offset has the same topology and
/// lies within the sagitta of the arc's, close enough for [`refine`] to recognise the arc's
/// own carrier and put the vertices back on it.
const FLAT_BULGE: f64 = 1e-4;

/// The largest sagitta (mm) of an arc sent as its chord: a tenth of [`ON_CARRIER`].
const FLAT_SAGITTA: f64 = 1e-3;

/// `contour` with its nearly straight arcs made straight, for the library (see [`FLAT_BULGE`]).
pub(crate) fn flattened(contour: &Contour) -> Contour {
    let mut flat = contour.clone();
    for (v, span) in flat.vertices.iter_mut().zip(contour.spans()) {
        let sagitta = 0.5 * span.bulge.abs() * span.chord_length();
        if span.bulge.abs() < FLAT_BULGE && sagitta <= FLAT_SAGITTA {
            v.bulge = 0.0;
        }
    }
    flat
}

/// A line or circle given locally: a point on it, the unit tangent (direction of travel)
/// there, and the signed curvature (positive counter-clockwise, 0 for a line). No centre, so a
/// nearly straight carrier keeps full precision.
#[derive(Clone, Copy, Debug)]
struct Carrier {
    origin: Point,
    tangent: Point,
    curvature: f64,
}

impl Carrier {
    /// The offset of `span` by `distance` to its left; `None` for a zero-length span or an arc
    /// that collapses (radius not above the distance, on its inner side).
    fn offset(span: &Span, distance: f64) -> Option<Carrier> {
        let tangent = span.tangent_at(0.0);
        let shrink = 1.0 - span.curvature() * distance;
        (tangent.norm_squared() > 0.0 && shrink > 0.0).then(|| Carrier {
            origin: span.start + tangent.rotated_quarter() * distance,
            tangent,
            curvature: span.curvature() / shrink,
        })
    }

    /// The round corner about `vertex` at `distance`, reached along `tangent` (the end tangent
    /// of the span before it): the vertex is on the right, so the corner turns clockwise.
    fn round_corner(vertex: Point, tangent: Point, distance: f64) -> Carrier {
        Carrier {
            origin: vertex + tangent.rotated_quarter() * distance,
            tangent,
            curvature: -1.0 / distance,
        }
    }

    /// `F(p) = κ|q|²/2 − q·n` with `q = p − origin` and `n` the left normal: zero on the
    /// carrier, where its gradient has unit length, so it is the signed distance (positive on
    /// the right) to first order.
    fn value(&self, p: Point) -> f64 {
        let q = p - self.origin;
        0.5 * self.curvature * q.norm_squared() - q.dot(self.tangent.rotated_quarter())
    }

    fn gradient(&self, p: Point) -> Point {
        (p - self.origin) * self.curvature - self.tangent.rotated_quarter()
    }

    /// The direction of travel at (or nearest) `p`.
    fn tangent_at(&self, p: Point) -> Point {
        self.gradient(p).rotated_quarter().normalized()
    }

    /// `p` moved onto the carrier along the gradient.
    fn project(&self, mut p: Point) -> Point {
        for _ in 0..3 {
            let g = self.gradient(p);
            p = p - g * (self.value(p) / g.norm_squared());
        }
        p
    }

    /// The bulge of the carrier's piece from `a` to `b` (both on it): the chord makes half the
    /// sweep with the tangent at `a`. `fallback` when the chord is empty or a full turn.
    fn bulge(&self, a: Point, b: Point, fallback: f64) -> f64 {
        if self.curvature == 0.0 {
            return 0.0;
        }
        let t = self.tangent_at(a);
        let chord = b - a;
        tan_half_arg(t.dot(chord), t.cross(chord)).unwrap_or(fallback)
    }

    /// How far (to first order) the span lies off the carrier, or `None` if it runs the other
    /// way.
    fn misfit(&self, span: &Span) -> Option<f64> {
        let mid = span.midpoint();
        if span.tangent_at(0.5).dot(self.tangent_at(mid)) < 0.5 {
            return None;
        }
        Some(
            [span.start, mid, span.end]
                .iter()
                .map(|&p| self.value(p).abs())
                .fold(0.0, f64::max),
        )
    }
}

/// Where carriers `a` and `b` meet nearest `p`: Newton's method on `F_a = F_b = 0`, or for
/// (nearly) tangent carriers, where the meeting point slides along the common tangent, `p`
/// moved along the common normal until both residuals balance.
fn meet(a: &Carrier, b: &Carrier, p: Point, limit: f64) -> Point {
    let mut q = p;
    for _ in 0..8 {
        let (fa, fb) = (a.value(q), b.value(q));
        let (ga, gb) = (a.gradient(q), b.gradient(q));
        let det = ga.cross(gb);
        if !(det.abs() > 1e-12) {
            break;
        }
        let step = Point::new(-fa * gb.y + fb * ga.y, -fb * ga.x + fa * gb.x) * (1.0 / det);
        q += step;
        if !(step.norm() > 1e-15 * (1.0 + q.norm())) {
            break;
        }
    }
    let converged = (a.value(q).abs() + b.value(q).abs()) <= 1e-12 * (1.0 + q.norm());
    if q.is_finite() && converged && q.distance(p) <= limit {
        return q;
    }
    let g = (a.gradient(p) + b.gradient(p)) * 0.5;
    let balanced = p - g * (0.5 * (a.value(p) + b.value(p)) / g.norm_squared());
    if balanced.is_finite() && balanced.distance(p) <= limit {
        balanced
    } else {
        p
    }
}

fn envelope(b: &BoundingBox) -> AABB<[f64; 2]> {
    AABB::from_corners([b.min.x, b.min.y], [b.max.x, b.max.y])
}

/// `offset`, computed by the library as the equidistant of `source` at `distance` to the
/// left, with each vertex moved to the exact meeting point of its spans' carriers and each
/// bulge recomputed from its carrier. Spans whose carrier is not recognised keep their
/// geometry, and so do the vertices at their ends.
pub(crate) fn refine(source: &Contour, offset: &Contour, distance: f64) -> Contour {
    let n = offset.vertices.len();
    if n < 2 || source.vertices.len() < 2 {
        return offset.clone();
    }
    let magnitude = source
        .vertices
        .iter()
        .map(|v| v.point.x.abs().max(v.point.y.abs()))
        .fold(0.0, f64::max);
    let tolerance = ON_CARRIER + 1e-9 * magnitude;
    let max_move = MAX_MOVE + 1e-9 * magnitude;
    let reach = distance + tolerance;

    let spans: Vec<Span> = source.spans().collect();
    // Each carrier with the source spans it comes from (a corner: the spans either side).
    let mut carriers: Vec<(Carrier, [usize; 2])> = Vec::new();
    let mut entries = Vec::new();
    for (i, span) in spans.iter().enumerate() {
        if let Some(c) = Carrier::offset(span, distance) {
            entries.push(GeomWithData::new(
                Rectangle::from_aabb(envelope(&span.bounding_box().expanded(reach))),
                carriers.len(),
            ));
            carriers.push((c, [i, i]));
        }
        let previous = (i + spans.len() - 1) % spans.len();
        let before = spans[previous].tangent_at(1.0);
        if before.norm_squared() > 0.0 {
            let corner = BoundingBox::from_corners(span.start, span.start).expanded(reach);
            entries.push(GeomWithData::new(
                Rectangle::from_aabb(envelope(&corner)),
                carriers.len(),
            ));
            carriers.push((
                Carrier::round_corner(span.start, before, distance),
                [previous, i],
            ));
        }
    }
    let tree = RTree::bulk_load(entries);
    // The test the result must pass: how far points of a loop stray from the distance (the
    // source spans near a point are those of the carriers whose boxes hold it).
    let stray = |contour: &Contour| {
        contour
            .spans()
            .flat_map(|s| (0..4).map(move |i| s.point_at(i as f64 / 4.0)))
            .map(|p| {
                let nearest = tree
                    .locate_all_at_point(&[p.x, p.y])
                    .flat_map(|e| carriers[e.data].1)
                    .map(|i| spans[i].distance_to(p))
                    .fold(f64::INFINITY, f64::min);
                (nearest - distance).abs()
            })
            .fold(0.0, f64::max)
    };

    let out: Vec<Span> = offset.spans().collect();
    let on: Vec<Option<usize>> = out
        .iter()
        .map(|s| {
            let mid = s.midpoint();
            tree.locate_all_at_point(&[mid.x, mid.y])
                .filter_map(|e| carriers[e.data].0.misfit(s).map(|m| (m, e.data)))
                .filter(|&(m, _)| m <= tolerance)
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .map(|(_, c)| c)
        })
        .collect();

    let points: Vec<Point> = (0..n)
        .map(|i| {
            let p = out[i].start;
            match (on[(i + n - 1) % n], on[i]) {
                (Some(a), Some(b)) if a == b => {
                    let q = carriers[a].0.project(p);
                    if q.is_finite() && q.distance(p) <= tolerance {
                        q
                    } else {
                        p
                    }
                }
                (Some(a), Some(b)) => meet(&carriers[a].0, &carriers[b].0, p, max_move),
                _ => p,
            }
        })
        .collect();
    // A vertex must not pass the other end of a span (a tiny one beside a shallow crossing):
    // where a chord would turn round, both its ends stay where the library put them.
    let mut points = points;
    for i in 0..n {
        let j = (i + 1) % n;
        if (points[j] - points[i]).dot(out[i].chord()) <= 0.0 && out[i].chord().norm_squared() > 0.0
        {
            points[i] = out[i].start;
            points[j] = out[i].end;
        }
    }
    let refined = Contour::new(
        (0..n)
            .map(|i| {
                let (a, b) = (points[i], points[(i + 1) % n]);
                let bulge = on[i].map_or(out[i].bulge, |c| carriers[c].0.bulge(a, b, out[i].bulge));
                Vertex::arc(a.x, a.y, bulge)
            })
            .collect(),
    );
    if stray(&refined) <= stray(offset) {
        refined
    } else {
        offset.clone()
    }
}
