//! The solver's prepared geometry: contours as [`Shape`]s of [`PreparedSpan`]s, whose arcs carry
//! their centre, radius, start angle and sweep, so that the relaxation's inner loops (millions of
//! point, nearest-point and chord-crossing evaluations) need no trigonometry to recover them.
//!
//! Everything that defines the geometry comes from `cutroute-geometry`: points and boxes are its
//! [`Point`] and [`BoundingBox`] (with the one-`sqrt` norms, [`Point::fast_norm`] and kin, in
//! the inner loops), a prepared span wraps its [`GeoSpan`], and the arc data (centre, radius and
//! sweep), exact span bounding boxes, contour signed area and perimeter are its; point-in-contour
//! and the containment forest are the geometry crate's too (see `problem.rs`). The evaluators
//! kept here work on the cached data and are tested against the geometry crate's own.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{BoundingBox, Contour, Point, Span as GeoSpan};

/// Tolerance for "lies on" decisions, in millimetres.
pub(crate) const EPS: f64 = 1e-9;

/// A span prepared for the inner loops: the geometry crate's [`GeoSpan`] and, for an arc, its
/// cached centre, radius and angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PreparedSpan {
    /// The span itself, as the contour holds it.
    pub span: GeoSpan,
    /// The arc's cached data; `None` for a segment (and for an arc too flat to have a precise
    /// centre, which the solver takes as its chord).
    pub arc: Option<ArcCache>,
}

/// What an arc's evaluators need without trigonometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ArcCache {
    pub center: Point,
    pub radius: f64,
    /// The angle of the span's start point as seen from the centre.
    pub start: f64,
    /// The signed swept angle (positive counter-clockwise).
    pub sweep: f64,
}

/// Wraps an angle to `[0, 2π)`.
fn wrap(t: f64) -> f64 {
    let r = t.rem_euclid(std::f64::consts::TAU);
    if r >= std::f64::consts::TAU {
        0.0
    } else {
        r
    }
}

impl ArcCache {
    /// The parameter of the point of the circle at angle `theta`, when that point is on the arc.
    fn param(&self, theta: f64) -> Option<f64> {
        let off = if self.sweep > 0.0 {
            wrap(theta - self.start)
        } else {
            wrap(self.start - theta)
        };
        let s = self.sweep.abs();
        if off <= s + 1e-12 {
            Some((off / s).min(1.0))
        } else if off >= std::f64::consts::TAU - 1e-12 {
            Some(0.0)
        } else {
            None
        }
    }
}

impl PreparedSpan {
    /// The span from `a` to `b` with the given bulge (`tan(φ/4)`); tiny bulges become segments.
    #[cfg(test)]
    pub fn new(a: Point, b: Point, bulge: f64) -> PreparedSpan {
        PreparedSpan::prepare(&GeoSpan::new(a, b, bulge))
    }

    /// The straight segment from `a` to `b`.
    pub fn segment(a: Point, b: Point) -> PreparedSpan {
        PreparedSpan {
            span: GeoSpan::line(a, b),
            arc: None,
        }
    }

    /// Caches a geometry span's arc data (centre, radius, sweep from `cutroute-geometry`, plus
    /// the start angle). Bulges below 1e-9 (sagitta below a nanometre per metre of chord) are
    /// taken as segments: their centres lie too far away to be precise.
    pub fn prepare(span: &GeoSpan) -> PreparedSpan {
        let a = span.start;
        let is_arc = span.bulge.abs() >= 1e-9
            && span.bulge.is_finite()
            && a.fast_distance(span.end) >= 1e-12;
        let arc = span.centre().filter(|_| is_arc).map(|center| ArcCache {
            center,
            radius: span.radius(),
            start: (a.y - center.y).atan2_libm(a.x - center.x),
            sweep: span.sweep(),
        });
        PreparedSpan { span: *span, arc }
    }

    /// Where the span starts.
    #[inline]
    pub fn a(&self) -> Point {
        self.span.start
    }
    /// Where the span ends.
    #[inline]
    pub fn b(&self) -> Point {
        self.span.end
    }
    pub fn length(&self) -> f64 {
        match self.arc {
            None => self.a().fast_distance(self.b()),
            Some(arc) => arc.radius * arc.sweep.abs(),
        }
    }
    /// The point at parameter `t ∈ [0, 1]` (proportional to arc length).
    pub fn point_at(&self, t: f64) -> Point {
        let (a, b) = (self.a(), self.b());
        match self.arc {
            None => a + (b - a) * t,
            Some(arc) => {
                if t <= 0.0 {
                    return a;
                }
                if t >= 1.0 {
                    return b;
                }
                let th = arc.start + arc.sweep * t;
                arc.center + Point::new(th.cos_libm(), th.sin_libm()) * arc.radius
            }
        }
    }
    /// The derivative of `point_at` with respect to `t`.
    pub fn derivative_at(&self, t: f64) -> Point {
        match self.arc {
            None => self.b() - self.a(),
            Some(arc) => {
                let th = arc.start + arc.sweep * t;
                Point::new(-th.sin_libm(), th.cos_libm()) * (arc.radius * arc.sweep)
            }
        }
    }
    /// The nearest point of the span to `p`: `(t, point)`.
    pub fn nearest(&self, p: Point) -> (f64, Point) {
        let (a, b) = (self.a(), self.b());
        match self.arc {
            None => {
                let u = b - a;
                let uu = u.dot(u);
                let t = if uu > 0.0 {
                    ((p - a).dot(u) / uu).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (t, a + u * t)
            }
            Some(arc) => {
                let d = p - arc.center;
                if d.fast_norm() > 0.0 {
                    let th = d.y.atan2_libm(d.x);
                    if let Some(t) = arc.param(th) {
                        return (t, self.point_at(t));
                    }
                }
                if p.fast_distance(a) <= p.fast_distance(b) {
                    (0.0, a)
                } else {
                    (1.0, b)
                }
            }
        }
    }
    /// Crossings of the segment `p q` with the span: `(λ along p q, t along the span)`.
    pub fn intersect_segment(&self, p: Point, q: Point, out: &mut Vec<(f64, f64)>) {
        let w = q - p;
        match self.arc {
            None => {
                let (a, b) = (self.a(), self.b());
                let u = b - a;
                let den = w.cross(u);
                if den.abs() < 1e-15 {
                    return; // parallel: collinear overlaps are not crossings
                }
                let lam = (a - p).cross(u) / den;
                let t = (a - p).cross(w) / den;
                if (-EPS..=1.0 + EPS).contains(&lam) && (-EPS..=1.0 + EPS).contains(&t) {
                    out.push((lam.clamp(0.0, 1.0), t.clamp(0.0, 1.0)));
                }
            }
            Some(arc) => {
                let ww = w.dot(w);
                if ww <= 0.0 {
                    return;
                }
                let f = p - arc.center;
                let bq = 2.0 * f.dot(w);
                let c = f.dot(f) - arc.radius * arc.radius;
                let disc = bq * bq - 4.0 * ww * c;
                if disc < 0.0 {
                    return;
                }
                let sq = disc.sqrt();
                for lam in [(-bq - sq) / (2.0 * ww), (-bq + sq) / (2.0 * ww)] {
                    if (-EPS..=1.0 + EPS).contains(&lam) {
                        let x = p + w * lam - arc.center;
                        if let Some(t) = arc.param(x.y.atan2_libm(x.x)) {
                            out.push((lam.clamp(0.0, 1.0), t));
                        }
                    }
                    if sq == 0.0 {
                        break;
                    }
                }
            }
        }
    }
    /// The minimum of `⟨n, X − m⟩` over the span's points `X`.
    pub fn min_dot(&self, n: Point, m: Point) -> f64 {
        let mut best = n.dot(self.a() - m).min(n.dot(self.b() - m));
        if let Some(arc) = self.arc {
            // The arc's extreme point in direction −n.
            let dir = n.fast_unit() * -1.0;
            if dir.fast_norm() > 0.0 && arc.param(dir.y.atan2_libm(dir.x)).is_some() {
                best = best.min(n.dot(arc.center + dir * arc.radius - m));
            }
        }
        best
    }
}

/// A contour prepared for the solver: cached spans, their exact boxes, perimeter, signed area.
#[derive(Clone, Debug)]
pub(crate) struct Shape {
    pub spans: Vec<PreparedSpan>,
    pub span_boxes: Vec<BoundingBox>,
    pub bbox: BoundingBox,
    pub perimeter: f64,
    /// Signed area (positive = counter-clockwise).
    pub area: f64,
}

impl Shape {
    pub fn new(contour: &Contour) -> Shape {
        let mut spans = Vec::with_capacity(contour.vertices.len());
        let mut span_boxes = Vec::with_capacity(contour.vertices.len());
        for span in contour.spans() {
            // Zero-length spans (repeated vertices) carry no points of their own.
            if span.chord_length() >= 1e-12 {
                spans.push(PreparedSpan::prepare(&span));
                span_boxes.push(span.bounding_box());
            }
        }
        if spans.is_empty() {
            let a = contour
                .vertices
                .first()
                .map(|v| v.point)
                .unwrap_or_default();
            spans.push(PreparedSpan::segment(a, a));
            span_boxes.push(BoundingBox::EMPTY.including(a));
        }
        let bbox = span_boxes
            .iter()
            .fold(BoundingBox::EMPTY, |bbox, b| bbox.union(*b));
        Shape {
            spans,
            span_boxes,
            bbox,
            perimeter: contour.perimeter(),
            area: contour.signed_area(),
        }
    }

    /// The nearest point of the contour to `p`.
    pub fn nearest(&self, p: Point) -> Point {
        let mut best = (f64::INFINITY, Point::ORIGIN);
        for (s, bb) in self.spans.iter().zip(&self.span_boxes) {
            if bb.gap_to_point(p).fast_norm() >= best.0 {
                continue;
            }
            let (_, x) = s.nearest(p);
            let d = x.fast_distance(p);
            if d < best.0 {
                best = (d, x);
            }
        }
        best.1
    }

    /// The minimum of `⟨n, X − m⟩` over the whole contour.
    pub fn min_dot(&self, n: Point, m: Point) -> f64 {
        self.spans
            .iter()
            .map(|s| s.min_dot(n, m))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether the region is convex (every turn and every arc bends the same way as the area).
    pub fn is_convex(&self) -> bool {
        let sign = self.area.signum();
        let n = self.spans.len();
        for i in 0..n {
            let s = self.spans[i];
            let nxt = self.spans[(i + 1) % n];
            if let Some(arc) = s.arc {
                if arc.sweep * sign < 0.0 {
                    return false;
                }
            }
            let t_out = s.derivative_at(1.0).fast_unit();
            let t_in = nxt.derivative_at(0.0).fast_unit();
            if t_out.cross(t_in) * sign < -1e-9 {
                return false;
            }
        }
        // Total turning of a convex simple curve is 2π: rules out self-winding stars.
        true
    }
}

/// Whether point `m` lies on the segment `p q` (within `tol`).
pub(crate) fn on_segment(p: Point, q: Point, m: Point, tol: f64) -> bool {
    let (_, x) = PreparedSpan::segment(p, q).nearest(m);
    x.fast_distance(m) <= tol
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::SplitMix64;

    /// Segments, small and large arcs of both senses, and a nearly straight arc.
    fn sample_spans() -> Vec<PreparedSpan> {
        let mut rng = SplitMix64::new(11);
        let mut out = Vec::new();
        for bulge in [0.0, 1e-4, 0.2, -0.2, 0.7, -1.0, 1.0, 2.5, -3.0] {
            for _ in 0..6 {
                let a = Point::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0));
                let b = Point::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0));
                out.push(PreparedSpan::new(a, b, bulge));
            }
        }
        out
    }

    #[test]
    fn cached_evaluators_agree_with_the_geometry_crate() {
        let mut rng = SplitMix64::new(5);
        for span in sample_spans() {
            let g = span.span;
            assert!((span.length() - g.length()).abs() < 1e-9 * (1.0 + g.length()));
            for k in 0..=10 {
                let t = k as f64 / 10.0;
                let (p, q) = (span.point_at(t), g.point_at(t));
                assert!(
                    p.fast_distance(q) < 1e-9,
                    "point_at({t}) of {span:?}: {p:?} vs {q:?}"
                );
            }
            for _ in 0..20 {
                let p = Point::new(rng.range(-80.0, 80.0), rng.range(-80.0, 80.0));
                let (_, x) = span.nearest(p);
                let own = g.nearest_point(p);
                assert!(
                    (x.fast_distance(p) - own.distance).abs() < 1e-9,
                    "nearest to {p:?} on {span:?}: {} vs {}",
                    x.fast_distance(p),
                    own.distance
                );
                let q = Point::new(rng.range(-80.0, 80.0), rng.range(-80.0, 80.0));
                let mut hits = Vec::new();
                span.intersect_segment(p, q, &mut hits);
                let theirs = g.intersect_segment(p, q);
                assert_eq!(
                    hits.len(),
                    theirs.len(),
                    "crossings of {p:?}–{q:?} with {span:?}"
                );
                for (&(lam, t), h) in hits.iter().zip(&theirs) {
                    let x = span.point_at(t);
                    assert!(x.fast_distance(p + (q - p) * lam) < 1e-7);
                    assert!(
                        theirs.iter().any(|h2| x.fast_distance(h2.point) < 1e-7),
                        "{h:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn shapes_take_boxes_area_and_perimeter_from_the_geometry_crate() {
        use cutroute_geometry::Vertex;
        // A 20 × 10 slot with round ends (two half circles), counter-clockwise.
        let slot = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::arc(20.0, 0.0, 1.0),
            Vertex::line(20.0, 10.0),
            Vertex::arc(0.0, 10.0, 1.0),
        ]);
        let shape = Shape::new(&slot);
        let circle = std::f64::consts::PI * 25.0;
        assert!((shape.area - (200.0 + circle)).abs() < 1e-9);
        assert!((shape.perimeter - (40.0 + 10.0 * std::f64::consts::PI)).abs() < 1e-9);
        assert!((shape.bbox.min.x + 5.0).abs() < 1e-9 && (shape.bbox.max.x - 25.0).abs() < 1e-9);
        assert_eq!(shape.spans.len(), 4);
    }
}
