//! Private plane geometry of the solver: vectors, spans (segments and bulge arcs), contour shapes
//! with bounding boxes, nearest points, segment intersections and point-in-contour tests.
//!
//! These belong in `cutroute-geometry` eventually; they live here so the solver does not depend
//! on a crate that is being extended concurrently (see the crate docs, "Geometry to merge").

use cutroute_geometry::{Contour, Point};

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
    pub fn contains_box(&self, o: &BBox) -> bool {
        self.min.x <= o.min.x
            && self.min.y <= o.min.y
            && self.max.x >= o.max.x
            && self.max.y >= o.max.y
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
    pub fn new(a: V, b: V, bulge: f64) -> Span {
        let chord = b - a;
        let d = chord.norm();
        if bulge.abs() < 1e-9 || d < 1e-12 || !bulge.is_finite() {
            return Span::Seg { a, b };
        }
        let sweep = 4.0 * bulge.atan();
        // The centre lies on the chord's bisector, (1 − b²)/(4b)·d to the left of the chord.
        let offset = d * (1.0 - bulge * bulge) / (4.0 * bulge);
        let center = (a + b) * 0.5 + chord.unit().perp() * offset;
        let radius = d * (1.0 + bulge * bulge) / (4.0 * bulge.abs());
        let start = (a.y - center.y).atan2(a.x - center.x);
        Span::Arc {
            a,
            b,
            center,
            radius,
            start,
            sweep,
        }
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
                center + V::new(th.cos(), th.sin()) * radius
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
                V::new(-th.sin(), th.cos()) * (radius * sweep)
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
    /// The bounding box (exact for arcs: endpoints plus the axis extremes the arc passes).
    pub fn bbox(&self) -> BBox {
        let mut bb = BBox::empty();
        bb.add(self.a());
        bb.add(self.b());
        if let Span::Arc {
            center,
            radius,
            start,
            sweep,
            ..
        } = *self
        {
            for k in 0..4 {
                let th = k as f64 * std::f64::consts::FRAC_PI_2;
                if Self::arc_param(start, sweep, th).is_some() {
                    bb.add(center + V::new(th.cos(), th.sin()) * radius);
                }
            }
        }
        bb
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
                    let th = d.y.atan2(d.x);
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
                        if let Some(t) = Self::arc_param(start, sweep, x.y.atan2(x.x)) {
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
            if dir.norm() > 0.0 && Self::arc_param(start, sweep, dir.y.atan2(dir.x)).is_some() {
                best = best.min(n.dot(center + dir * radius - m));
            }
        }
        best
    }
}

/// A contour prepared for the solver: spans, bounding box, perimeter, signed area.
#[derive(Clone, Debug)]
pub(crate) struct Shape {
    pub spans: Vec<Span>,
    pub span_boxes: Vec<BBox>,
    pub bbox: BBox,
    pub perimeter: f64,
    /// Signed area (positive = counter-clockwise).
    pub area: f64,
    /// A fine polygonal approximation used for point-in-contour tests.
    pub polygon: Vec<V>,
}

impl Shape {
    pub fn new(contour: &Contour) -> Shape {
        let n = contour.vertices.len();
        let mut spans = Vec::with_capacity(n);
        for i in 0..n {
            let v = contour.vertices[i];
            let w = contour.vertices[(i + 1) % n];
            let a = V::from(v.point);
            let b = V::from(w.point);
            if n == 1 || a.dist(b) < 1e-12 {
                if n == 1 {
                    spans.push(Span::Seg { a, b });
                }
                continue;
            }
            spans.push(Span::new(a, b, v.bulge));
        }
        if spans.is_empty() {
            let a = contour
                .vertices
                .first()
                .map(|v| V::from(v.point))
                .unwrap_or_default();
            spans.push(Span::Seg { a, b: a });
        }
        let span_boxes: Vec<BBox> = spans.iter().map(Span::bbox).collect();
        let mut bbox = BBox::empty();
        for b in &span_boxes {
            bbox.union(b);
        }
        let perimeter = spans.iter().map(Span::length).sum();
        let mut area = 0.0;
        let mut polygon = Vec::new();
        for s in &spans {
            area += 0.5 * s.a().cross(s.b());
            match *s {
                Span::Seg { a, .. } => polygon.push(a),
                Span::Arc {
                    a, radius, sweep, ..
                } => {
                    // Circular-segment area between chord and arc.
                    area += 0.5 * radius * radius * (sweep - sweep.sin());
                    // Sagitta tolerance ≈ 1e-3·r keeps containment tests exact for disjoint contours.
                    let steps = ((sweep.abs() / 0.05).ceil() as usize).clamp(2, 256);
                    polygon.push(a);
                    for k in 1..steps {
                        polygon.push(s.point_at(k as f64 / steps as f64));
                    }
                }
            }
        }
        Shape {
            spans,
            span_boxes,
            bbox,
            perimeter,
            area,
            polygon,
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

    /// Whether `p` lies inside the region the contour bounds (even-odd on the fine polygon).
    pub fn contains_point(&self, p: V) -> bool {
        if p.x < self.bbox.min.x
            || p.x > self.bbox.max.x
            || p.y < self.bbox.min.y
            || p.y > self.bbox.max.y
        {
            return false;
        }
        let poly = &self.polygon;
        let n = poly.len();
        let mut inside = false;
        let mut j = n - 1;
        for i in 0..n {
            let (a, b) = (poly[i], poly[j]);
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if p.x < x {
                    inside = !inside;
                }
            }
            j = i;
        }
        inside
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
