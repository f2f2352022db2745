//! Step 2 kernel: the point of a contour minimising `|P X| + |X Q|` (Algorithm 3.1, line 6).
//!
//! Segments are solved in closed form (the chord crossing or the mirror rule, clamped: the
//! objective is convex along a segment). Arcs are not convex: a chord crossing is optimal when it
//! exists; otherwise every sign change `− → +` of the derivative on a fine angular grid brackets a
//! local minimum that bisection refines, and the endpoints are candidates too.

use crate::geom::{ArcCache, PreparedSpan, Shape};
use cutroute_geometry::float::Libm;
use cutroute_geometry::Point;

/// `|P X| + |X Q|`, or `|P X|` at an open end.
#[inline]
pub(crate) fn cost(p: Point, q: Option<Point>, x: Point) -> f64 {
    p.fast_distance(x) + q.map_or(0.0, |q| x.fast_distance(q))
}

/// The minimiser of `cost` over one span: `(value, point)`.
pub(crate) fn best_on_span(span: &PreparedSpan, p: Point, q: Option<Point>) -> (f64, Point) {
    let Some(q) = q else {
        let (_, x) = span.nearest(p);
        return (p.fast_distance(x), x);
    };
    let (a, b) = (span.a(), span.b());
    match span.arc {
        None => {
            let u = b - a;
            let uu = u.dot(u);
            if uu <= 0.0 {
                return (cost(p, Some(q), a), a);
            }
            let sp = u.cross(p - a);
            let sq = u.cross(q - a);
            // Same side (or touching): mirror Q in the line (Fermat's principle).
            let q2 = if sp * sq < 0.0 {
                q
            } else {
                let n = u.rotated_quarter() * (1.0 / uu.sqrt());
                q - n * (2.0 * n.dot(q - a))
            };
            let w = q2 - p;
            let den = u.cross(w);
            let t = if den.abs() < 1e-14 * (uu.sqrt() * w.fast_norm()).max(1e-300) {
                ((p - a).dot(u) / uu).clamp(0.0, 1.0)
            } else {
                ((p - a).cross(w) / den).clamp(0.0, 1.0)
            };
            let x = a + u * t;
            (cost(p, Some(q), x), x)
        }
        Some(ArcCache {
            center,
            radius,
            sweep,
            ..
        }) => {
            let mut hits = Vec::new();
            span.intersect_segment(p, q, &mut hits);
            if let Some(&(_, t)) = hits.first() {
                let x = span.point_at(t);
                return (cost(p, Some(q), x), x);
            }
            let mut best = (cost(p, Some(q), a), a);
            let fb = cost(p, Some(q), b);
            if fb < best.0 {
                best = (fb, b);
            }
            // Derivative of f along the arc (up to the positive factor r·|φ|), from the unit
            // radius vector u: tangent = ±perp(u).
            let dir = sweep.signum();
            let g_of = |u: Point| {
                let x = center + u * radius;
                ((x - p).fast_unit() + (x - q).fast_unit()).dot(u.rotated_quarter() * dir)
            };
            let n = ((sweep.abs() / (std::f64::consts::PI / 10.0)).ceil() as usize).max(2);
            let step = sweep / n as f64;
            let (sd, cd) = step.sin_cos_libm();
            let rot = |u: Point| Point::new(u.x * cd - u.y * sd, u.x * sd + u.y * cd);
            let u0 = (a - center) * (1.0 / radius);
            let mut u_prev = u0;
            let mut g_prev = g_of(u0);
            for k in 1..=n {
                // Samples by rotation (no trigonometry per sample); the last is the endpoint.
                let u = if k == n {
                    (b - center) * (1.0 / radius)
                } else {
                    rot(u_prev)
                };
                let gk = g_of(u);
                if g_prev < 0.0 && gk > 0.0 {
                    // Bisect the angle inside this sample interval (less than π wide), halving
                    // by normalised vector sums rather than trigonometry.
                    let (mut lo, mut hi) = (u_prev, u);
                    for _ in 0..30 {
                        let mid = (lo + hi).fast_unit();
                        if g_of(mid) < 0.0 {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    let um = (lo + hi).fast_unit();
                    let x = center + um * radius;
                    let v = cost(p, Some(q), x);
                    if v < best.0 {
                        best = (v, x);
                    }
                }
                u_prev = u;
                g_prev = gk;
            }
            best
        }
    }
}

/// The minimiser of `cost` over a whole contour. `current` (the warm start) seeds the pruning
/// bound, and is returned unchanged unless a strictly better point exists, so relaxation is
/// monotone.
pub(crate) fn best_on_shape(
    shape: &Shape,
    p: Point,
    q: Option<Point>,
    current: Option<Point>,
) -> (f64, Point) {
    let mut best = match current {
        Some(c) => (cost(p, q, c), c),
        None => (f64::INFINITY, shape.spans[0].a()),
    };
    for (span, bb) in shape.spans.iter().zip(&shape.span_boxes) {
        // Lower bound of the span: distances to its box.
        let lb = bb.gap_to_point(p).fast_norm() + q.map_or(0.0, |q| bb.gap_to_point(q).fast_norm());
        if lb >= best.0 {
            continue;
        }
        let (v, x) = best_on_span(span, p, q);
        if v < best.0 - 1e-12 {
            best = (v, x);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_mirror_and_crossing() {
        let s = PreparedSpan::segment(Point::new(0.0, 0.0), Point::new(10.0, 0.0));
        // Opposite sides: the chord crossing.
        let (v, x) = best_on_span(&s, Point::new(2.0, 5.0), Some(Point::new(6.0, -5.0)));
        assert!((x.x - 4.0).abs() < 1e-12 && x.y.abs() < 1e-12);
        assert!((v - Point::new(2.0, 5.0).fast_distance(Point::new(6.0, -5.0))).abs() < 1e-12);
        // Same side: the reflection point.
        let (_, x) = best_on_span(&s, Point::new(2.0, 5.0), Some(Point::new(8.0, 5.0)));
        assert!((x.x - 5.0).abs() < 1e-12);
        // Clamped to an endpoint.
        let (_, x) = best_on_span(&s, Point::new(20.0, 5.0), Some(Point::new(30.0, 5.0)));
        assert_eq!(x, Point::new(10.0, 0.0));
    }

    #[test]
    fn arc_matches_dense_sampling() {
        // A half circle of radius 10 around the origin, counter-clockwise from (10,0) to (−10,0).
        let s = PreparedSpan::new(Point::new(10.0, 0.0), Point::new(-10.0, 0.0), 1.0);
        for (p, q) in [
            (Point::new(0.0, 30.0), Point::new(25.0, 20.0)),
            (Point::new(-30.0, 5.0), Point::new(30.0, 6.0)),
            (Point::new(3.0, 15.0), Point::new(-4.0, 12.0)),
        ] {
            let (v, _) = best_on_span(&s, p, Some(q));
            let dense = (0..=20000)
                .map(|k| cost(p, Some(q), s.point_at(k as f64 / 20000.0)))
                .fold(f64::INFINITY, f64::min);
            assert!(v <= dense + 1e-9, "{v} > {dense}");
        }
    }
}
