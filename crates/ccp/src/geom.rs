//! The solver's prepared geometry: contours as [`Shape`]s whose arcs carry their centre, radius,
//! start angle and sweep, so that the relaxation's inner loops (millions of point, nearest-point
//! and chord-crossing evaluations) need no trigonometry to recover them.
//!
//! Everything that defines the geometry comes from `cutroute-geometry`: the arc data
//! ([`cutroute_geometry::Span`]'s centre, radius and sweep), exact span bounding boxes, contour
//! signed area and perimeter; point-in-contour and the containment forest are the geometry
//! crate's too (see `problem.rs`). The evaluators kept here work on the cached data and are
//! tested against the geometry crate's own.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{BoundingBox, Contour, Point, Span as GeoSpan};

/// Tolerance for "lies on" decisions, in millimetres.
pub(crate) const EPS: f64 = 1e-9;

/// A plane vector with the arithmetic the solver needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct V {
    pub x: f64,
    pub y: f64,
}

impl V {
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }
    pub fn dot(self, o: V) -> f64 {
        self.x * o.x + self.y * o.y
    }
    pub fn cross(self, o: V) -> f64 {
        self.x * o.y - self.y * o.x
    }
    pub fn norm(self) -> f64 {
        // sqrt, not hypot: libm's hypot is several times slower and coordinates are small.
        (self.x * self.x + self.y * self.y).sqrt()
    }
    pub fn dist(self, o: V) -> f64 {
        let (dx, dy) = (self.x - o.x, self.y - o.y);
        (dx * dx + dy * dy).sqrt()
    }
    /// The unit vector, or zero for the zero vector.
    pub fn unit(self) -> V {
        let n = self.norm();
        if n > 0.0 {
            V::new(self.x / n, self.y / n)
        } else {
            V::default()
        }
    }
    /// Rotated by +90°.
    pub fn perp(self) -> V {
        V::new(-self.y, self.x)
    }
}

impl std::ops::Add for V {
    type Output = V;
    fn add(self, o: V) -> V {
        V::new(self.x + o.x, self.y + o.y)
    }
}
impl std::ops::Sub for V {
    type Output = V;
    fn sub(self, o: V) -> V {
        V::new(self.x - o.x, self.y - o.y)
    }
}
impl std::ops::Mul<f64> for V {
    type Output = V;
    fn mul(self, s: f64) -> V {
        V::new(self.x * s, self.y * s)
    }
}

impl From<Point> for V {
    fn from(p: Point) -> V {
        V::new(p.x, p.y)
    }
}
impl From<V> for Point {
    fn from(v: V) -> Point {
        Point::new(v.x, v.y)
    }
}

impl From<BoundingBox> for BBox {
    fn from(b: BoundingBox) -> BBox {
        BBox {
            min: b.min.into(),
            max: b.max.into(),
        }
    }
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BBox {
    pub min: V,
    pub max: V,
}

impl BBox {
    pub fn empty() -> Self {
        BBox {
            min: V::new(f64::INFINITY, f64::INFINITY),
            max: V::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        }
    }
    pub fn add(&mut self, p: V) {
        self.min.x = self.min.x.min(p.x);
        self.min.y = self.min.y.min(p.y);
        self.max.x = self.max.x.max(p.x);
        self.max.y = self.max.y.max(p.y);
    }
    pub fn union(&mut self, o: &BBox) {
        self.add(o.min);
        self.add(o.max);
    }
    /// Distance from a point to the box (0 inside).
    pub fn dist(&self, p: V) -> f64 {
        let dx = (self.min.x - p.x).max(0.0).max(p.x - self.max.x);
        let dy = (self.min.y - p.y).max(0.0).max(p.y - self.max.y);
        (dx * dx + dy * dy).sqrt()
    }
    /// Gap between two boxes (0 when they overlap).
    pub fn gap(&self, o: &BBox) -> f64 {
        let dx = (self.min.x - o.max.x).max(0.0).max(o.min.x - self.max.x);
        let dy = (self.min.y - o.max.y).max(0.0).max(o.min.y - self.max.y);
        (dx * dx + dy * dy).sqrt()
    }
    pub fn center(&self) -> V {
        (self.min + self.max) * 0.5
    }
    /// Whether the segment `a b` may touch the box (a cheap conservative test).
    pub fn overlaps_segment(&self, a: V, b: V) -> bool {
        a.x.min(b.x) <= self.max.x
            && a.x.max(b.x) >= self.min.x
            && a.y.min(b.y) <= self.max.y
            && a.y.max(b.y) >= self.min.y
    }
}

/// One span of a contour: a straight segment or a circular arc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Span {
    /// From `a` to `b`.
    Seg { a: V, b: V },
    /// From `a` to `b` around `center`: `start` is the angle of `a`, `sweep` the signed swept angle.
    Arc {
        a: V,
        b: V,
        center: V,
        radius: f64,
        start: f64,
        sweep: f64,
    },
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

impl Span {
    /// The span from `a` to `b` with the given bulge (`tan(φ/4)`); tiny bulges become segments.
    #[cfg(test)]
    pub fn new(a: V, b: V, bulge: f64) -> Span {
        Span::prepare(&GeoSpan::new(a.into(), b.into(), bulge))
    }

    /// Caches a geometry span's arc data (centre, radius, sweep from `cutroute-geometry`, plus
    /// the start angle). Bulges below 1e-9 (sagitta below a nanometre per metre of chord) are
    /// taken as segments: their centres lie too far away to be precise.
    pub fn prepare(span: &GeoSpan) -> Span {
        let (a, b) = (V::from(span.start), V::from(span.end));
        let arc = span.bulge.abs() >= 1e-9 && span.bulge.is_finite() && a.dist(b) >= 1e-12;
        match span.centre().filter(|_| arc) {
            None => Span::Seg { a, b },
            Some(c) => {
                let center = V::from(c);
                Span::Arc {
                    a,
                    b,
                    center,
                    radius: span.radius(),
                    start: (a.y - center.y).atan2_libm(a.x - center.x),
                    sweep: span.sweep(),
                }
            }
        }
    }

    /// The same span in `cutroute-geometry`'s form.
    #[cfg(test)]
    pub fn to_geometry(self) -> GeoSpan {
        let bulge = match self {
            Span::Seg { .. } => 0.0,
            Span::Arc { sweep, .. } => (sweep / 4.0).tan_libm(),
        };
        GeoSpan::new(self.a().into(), self.b().into(), bulge)
    }
    pub fn a(&self) -> V {
        match *self {
            Span::Seg { a, .. } | Span::Arc { a, .. } => a,
        }
    }
    pub fn b(&self) -> V {
        match *self {
            Span::Seg { b, .. } | Span::Arc { b, .. } => b,
        }
    }
    pub fn length(&self) -> f64 {
        match *self {
            Span::Seg { a, b } => a.dist(b),
            Span::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }
    /// The point at parameter `t ∈ [0, 1]` (proportional to arc length).
    pub fn point_at(&self, t: f64) -> V {
        match *self {
            Span::Seg { a, b } => a + (b - a) * t,
            Span::Arc {
                a,
                b,
                center,
                radius,
                start,
                sweep,
            } => {
                if t <= 0.0 {
                    return a;
                }
                if t >= 1.0 {
                    return b;
                }
                let th = start + sweep * t;
                center + V::new(th.cos_libm(), th.sin_libm()) * radius
            }
        }
    }
    /// The derivative of `point_at` with respect to `t`.
    pub fn derivative_at(&self, t: f64) -> V {
        match *self {
            Span::Seg { a, b } => b - a,
            Span::Arc {
                radius,
                start,
                sweep,
                ..
            } => {
                let th = start + sweep * t;
                V::new(-th.sin_libm(), th.cos_libm()) * (radius * sweep)
            }
        }
    }
    /// The parameter of the point of the circle at angle `theta`, when that point is on the arc.
    fn arc_param(start: f64, sweep: f64, theta: f64) -> Option<f64> {
        let off = if sweep > 0.0 {
            wrap(theta - start)
        } else {
            wrap(start - theta)
        };
        let s = sweep.abs();
        if off <= s + 1e-12 {
            Some((off / s).min(1.0))
        } else if off >= std::f64::consts::TAU - 1e-12 {
            Some(0.0)
        } else {
            None
        }
    }
    /// The nearest point of the span to `p`: `(t, point)`.
    pub fn nearest(&self, p: V) -> (f64, V) {
        match *self {
            Span::Seg { a, b } => {
                let u = b - a;
                let uu = u.dot(u);
                let t = if uu > 0.0 {
                    ((p - a).dot(u) / uu).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (t, a + u * t)
            }
            Span::Arc {
                a,
                b,
                center,
                start,
                sweep,
                ..
            } => {
                let d = p - center;
                if d.norm() > 0.0 {
                    let th = d.y.atan2_libm(d.x);
                    if let Some(t) = Self::arc_param(start, sweep, th) {
                        return (t, self.point_at(t));
                    }
                }
                if p.dist(a) <= p.dist(b) {
                    (0.0, a)
                } else {
                    (1.0, b)
                }
            }
        }
    }
    /// Crossings of the segment `p q` with the span: `(λ along p q, t along the span)`.
    pub fn intersect_segment(&self, p: V, q: V, out: &mut Vec<(f64, f64)>) {
        let w = q - p;
        match *self {
            Span::Seg { a, b } => {
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
            Span::Arc {
                center,
                radius,
                start,
                sweep,
                ..
            } => {
                let ww = w.dot(w);
                if ww <= 0.0 {
                    return;
                }
                let f = p - center;
                let bq = 2.0 * f.dot(w);
                let c = f.dot(f) - radius * radius;
                let disc = bq * bq - 4.0 * ww * c;
                if disc < 0.0 {
                    return;
                }
                let sq = disc.sqrt();
                for lam in [(-bq - sq) / (2.0 * ww), (-bq + sq) / (2.0 * ww)] {
                    if (-EPS..=1.0 + EPS).contains(&lam) {
                        let x = p + w * lam - center;
                        if let Some(t) = Self::arc_param(start, sweep, x.y.atan2_libm(x.x)) {
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
    pub fn min_dot(&self, n: V, m: V) -> f64 {
        let mut best = n.dot(self.a() - m).min(n.dot(self.b() - m));
        if let Span::Arc {
            center,
            radius,
            start,
            sweep,
            ..
        } = *self
        {
            // The arc's extreme point in direction −n.
            let dir = n.unit() * -1.0;
            if dir.norm() > 0.0 && Self::arc_param(start, sweep, dir.y.atan2_libm(dir.x)).is_some()
            {
                best = best.min(n.dot(center + dir * radius - m));
            }
        }
        best
    }
}

/// A contour prepared for the solver: cached spans, their exact boxes, perimeter, signed area.
#[derive(Clone, Debug)]
pub(crate) struct Shape {
    pub spans: Vec<Span>,
    pub span_boxes: Vec<BBox>,
    pub bbox: BBox,
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
                spans.push(Span::prepare(&span));
                span_boxes.push(BBox::from(span.bounding_box()));
            }
        }
        if spans.is_empty() {
            let a = contour
                .vertices
                .first()
                .map(|v| V::from(v.point))
                .unwrap_or_default();
            spans.push(Span::Seg { a, b: a });
            let mut bb = BBox::empty();
            bb.add(a);
            span_boxes.push(bb);
        }
        let mut bbox = BBox::empty();
        for b in &span_boxes {
            bbox.union(b);
        }
        Shape {
            spans,
            span_boxes,
            bbox,
            perimeter: contour.perimeter(),
            area: contour.signed_area(),
        }
    }

    /// The nearest point of the contour to `p`.
    pub fn nearest(&self, p: V) -> V {
        let mut best = (f64::INFINITY, V::default());
        for (s, bb) in self.spans.iter().zip(&self.span_boxes) {
            if bb.dist(p) >= best.0 {
                continue;
            }
            let (_, x) = s.nearest(p);
            let d = x.dist(p);
            if d < best.0 {
                best = (d, x);
            }
        }
        best.1
    }

    /// The minimum of `⟨n, X − m⟩` over the whole contour.
    pub fn min_dot(&self, n: V, m: V) -> f64 {
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
            if let Span::Arc { sweep, .. } = s {
                if sweep * sign < 0.0 {
                    return false;
                }
            }
            let t_out = s.derivative_at(1.0).unit();
            let t_in = nxt.derivative_at(0.0).unit();
            if t_out.cross(t_in) * sign < -1e-9 {
                return false;
            }
        }
        // Total turning of a convex simple curve is 2π: rules out self-winding stars.
        true
    }
}

/// Whether point `m` lies on the segment `p q` (within `tol`).
pub(crate) fn on_segment(p: V, q: V, m: V, tol: f64) -> bool {
    let (_, x) = Span::Seg { a: p, b: q }.nearest(m);
    x.dist(m) <= tol
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::SplitMix64;

    /// Segments, small and large arcs of both senses, and a nearly straight arc.
    fn sample_spans() -> Vec<Span> {
        let mut rng = SplitMix64::new(11);
        let mut out = Vec::new();
        for bulge in [0.0, 1e-4, 0.2, -0.2, 0.7, -1.0, 1.0, 2.5, -3.0] {
            for _ in 0..6 {
                let a = V::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0));
                let b = V::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0));
                out.push(Span::new(a, b, bulge));
            }
        }
        out
    }

    #[test]
    fn cached_evaluators_agree_with_the_geometry_crate() {
        let mut rng = SplitMix64::new(5);
        for span in sample_spans() {
            let g = span.to_geometry();
            assert!((span.length() - g.length()).abs() < 1e-9 * (1.0 + g.length()));
            for k in 0..=10 {
                let t = k as f64 / 10.0;
                let (p, q) = (span.point_at(t), V::from(g.point_at(t)));
                assert!(
                    p.dist(q) < 1e-9,
                    "point_at({t}) of {span:?}: {p:?} vs {q:?}"
                );
            }
            for _ in 0..20 {
                let p = V::new(rng.range(-80.0, 80.0), rng.range(-80.0, 80.0));
                let (_, x) = span.nearest(p);
                let own = g.nearest_point(p.into());
                assert!(
                    (x.dist(p) - own.distance).abs() < 1e-9,
                    "nearest to {p:?} on {span:?}: {} vs {}",
                    x.dist(p),
                    own.distance
                );
                let q = V::new(rng.range(-80.0, 80.0), rng.range(-80.0, 80.0));
                let mut hits = Vec::new();
                span.intersect_segment(p, q, &mut hits);
                let theirs = g.intersect_segment(p.into(), q.into());
                assert_eq!(
                    hits.len(),
                    theirs.len(),
                    "crossings of {p:?}–{q:?} with {span:?}"
                );
                for (&(lam, t), h) in hits.iter().zip(&theirs) {
                    let x = span.point_at(t);
                    assert!(x.dist(p + (q - p) * lam) < 1e-7);
                    assert!(
                        theirs.iter().any(|h2| x.dist(h2.point.into()) < 1e-7),
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
