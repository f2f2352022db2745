//! Step 2 kernel: the point of a contour minimising `|P X| + |X Q|` (Algorithm 3.1, line 6).
//!
//! Segments are solved in closed form (the chord crossing or the mirror rule, clamped: the
//! objective is convex along a segment). Arcs are not convex: a chord crossing is optimal when it
//! exists; otherwise every sign change `− → +` of the derivative on a fine angular grid brackets a
//! local minimum that bisection refines, and the endpoints are candidates too.

use crate::geom::{Shape, Span, V};

/// `|P X| + |X Q|`, or `|P X|` at an open end.
#[inline]
pub(crate) fn cost(p: V, q: Option<V>, x: V) -> f64 {
    p.dist(x) + q.map_or(0.0, |q| x.dist(q))
}

/// The minimiser of `cost` over one span: `(value, point)`.
pub(crate) fn best_on_span(span: &Span, p: V, q: Option<V>) -> (f64, V) {
    let Some(q) = q else {
        let (_, x) = span.nearest(p);
        return (p.dist(x), x);
    };
    match *span {
        Span::Seg { a, b } => {
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
                let n = u.perp() * (1.0 / uu.sqrt());
                q - n * (2.0 * n.dot(q - a))
            };
            let w = q2 - p;
            let den = u.cross(w);
            let t = if den.abs() < 1e-14 * (uu.sqrt() * w.norm()).max(1e-300) {
                ((p - a).dot(u) / uu).clamp(0.0, 1.0)
            } else {
                ((p - a).cross(w) / den).clamp(0.0, 1.0)
            };
            let x = a + u * t;
            (cost(p, Some(q), x), x)
        }
        Span::Arc { a, b, .. } => {
            let mut hits = Vec::new();
            span.intersect_segment(p, q, &mut hits);
            if let Some(&(_, t)) = hits.first() {
                let x = span.point_at(t);
                return (cost(p, Some(q), x), x);
            }
            let f = |t: f64| cost(p, Some(q), span.point_at(t));
            let g = |t: f64| {
                let x = span.point_at(t);
                ((x - p).unit() + (x - q).unit()).dot(span.derivative_at(t))
            };
            let mut best = (f(0.0), a);
            let fb = f(1.0);
            if fb < best.0 {
                best = (fb, b);
            }
            let sweep = match *span {
                Span::Arc { sweep, .. } => sweep.abs(),
                _ => 0.0,
            };
            let n = ((sweep / (std::f64::consts::PI / 12.0)).ceil() as usize).max(2);
            let mut t_prev = 0.0;
            let mut g_prev = g(0.0);
            for k in 1..=n {
                let t = k as f64 / n as f64;
                let gk = g(t);
                if g_prev < 0.0 && gk > 0.0 {
                    let (mut lo, mut hi) = (t_prev, t);
                    for _ in 0..50 {
                        let mid = 0.5 * (lo + hi);
                        if g(mid) < 0.0 {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                        if hi - lo < 1e-13 {
                            break;
                        }
                    }
                    let tm = 0.5 * (lo + hi);
                    let x = span.point_at(tm);
                    let v = cost(p, Some(q), x);
                    if v < best.0 {
                        best = (v, x);
                    }
                }
                t_prev = t;
                g_prev = gk;
            }
            best
        }
    }
}

/// The minimiser of `cost` over a whole contour. `current` (the warm start) seeds the pruning
/// bound, and is returned unchanged unless a strictly better point exists, so relaxation is
/// monotone.
pub(crate) fn best_on_shape(shape: &Shape, p: V, q: Option<V>, current: Option<V>) -> (f64, V) {
    let mut best = match current {
        Some(c) => (cost(p, q, c), c),
        None => (f64::INFINITY, shape.spans[0].a()),
    };
    for (span, bb) in shape.spans.iter().zip(&shape.span_boxes) {
        // Lower bound of the span: distances to its box.
        let lb = bb.dist(p) + q.map_or(0.0, |q| bb.dist(q));
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
        let s = Span::Seg { a: V::new(0.0, 0.0), b: V::new(10.0, 0.0) };
        // Opposite sides: the chord crossing.
        let (v, x) = best_on_span(&s, V::new(2.0, 5.0), Some(V::new(6.0, -5.0)));
        assert!((x.x - 4.0).abs() < 1e-12 && x.y.abs() < 1e-12);
        assert!((v - V::new(2.0, 5.0).dist(V::new(6.0, -5.0))).abs() < 1e-12);
        // Same side: the reflection point.
        let (_, x) = best_on_span(&s, V::new(2.0, 5.0), Some(V::new(8.0, 5.0)));
        assert!((x.x - 5.0).abs() < 1e-12);
        // Clamped to an endpoint.
        let (_, x) = best_on_span(&s, V::new(20.0, 5.0), Some(V::new(30.0, 5.0)));
        assert_eq!(x, V::new(10.0, 0.0));
    }

    #[test]
    fn arc_matches_dense_sampling() {
        // A half circle of radius 10 around the origin, counter-clockwise from (10,0) to (−10,0).
        let s = Span::new(V::new(10.0, 0.0), V::new(-10.0, 0.0), 1.0);
        for (p, q) in [
            (V::new(0.0, 30.0), V::new(25.0, 20.0)),
            (V::new(-30.0, 5.0), V::new(30.0, 6.0)),
            (V::new(3.0, 15.0), V::new(-4.0, 12.0)),
        ] {
            let (v, _) = best_on_span(&s, p, Some(q));
            let dense = (0..=20000).map(|k| cost(p, Some(q), s.point_at(k as f64 / 20000.0))).fold(f64::INFINITY, f64::min);
            assert!(v <= dense + 1e-9, "{v} > {dense}");
        }
    }
}
