//! Small plane-geometry helpers the importers need: spans between two points, signed areas of
//! bulge contours, flattening to polygons and point-in-polygon.
//!
//! They are kept private to this crate on purpose: the shared model crate grows its own span maths
//! concurrently, and the importers only need these few, tolerance-aware operations.

use cutroute_geometry::{Contour, Point, Vertex};

/// One straight (`bulge == 0`) or circular span from `start` to `end`, in drawing coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Span {
    pub start: Point,
    pub end: Point,
    /// `tan(φ/4)` of the swept angle, positive = counter-clockwise.
    pub bulge: f64,
}

impl Span {
    pub fn line(start: Point, end: Point) -> Self {
        Self {
            start,
            end,
            bulge: 0.0,
        }
    }

    /// The same span run backwards.
    pub fn reversed(self) -> Self {
        Self {
            start: self.end,
            end: self.start,
            bulge: -self.bulge,
        }
    }

    /// The arc's centre and signed radius-independent data, or `None` for a straight span.
    pub fn arc_center(&self) -> Option<(Point, f64)> {
        if self.bulge.abs() < 1e-12 {
            return None;
        }
        let chord = dist(self.start, self.end);
        if chord < 1e-15 {
            return None;
        }
        let b = self.bulge;
        // Offset of the centre from the chord midpoint, along the chord's left normal:
        // d = chord·(1 − b²)/(4b).
        let mid = mid(self.start, self.end);
        let ux = (self.end.x - self.start.x) / chord;
        let uy = (self.end.y - self.start.y) / chord;
        let d = chord * (1.0 - b * b) / (4.0 * b);
        let center = Point::new(mid.x - uy * d, mid.y + ux * d);
        let radius = chord * (1.0 + b * b) / (4.0 * b.abs());
        Some((center, radius))
    }

    /// The point at parameter `t ∈ [0, 1]` along the span (by angle for arcs).
    pub fn point_at(&self, t: f64) -> Point {
        match self.arc_center() {
            None => Point::new(
                self.start.x + (self.end.x - self.start.x) * t,
                self.start.y + (self.end.y - self.start.y) * t,
            ),
            Some((c, r)) => {
                let sweep = 4.0 * self.bulge.atan();
                let a0 = (self.start.y - c.y).atan2(self.start.x - c.x);
                let a = a0 + sweep * t;
                Point::new(c.x + r * a.cos(), c.y + r * a.sin())
            }
        }
    }

    /// Signed area between the chord and the arc (added to the polygon area of the chords).
    pub fn segment_area(&self) -> f64 {
        if self.bulge == 0.0 {
            return 0.0;
        }
        let c2 = dist2(self.start, self.end);
        let phi = 4.0 * self.bulge.atan();
        let s = (phi / 2.0).sin();
        if s.abs() < 1e-300 {
            return 0.0;
        }
        c2 * (phi - phi.sin()) / (8.0 * s * s)
    }

    /// Bounding box corners (min, max) including the arc's extreme points.
    pub fn bounds(&self) -> (Point, Point) {
        let mut lo = Point::new(self.start.x.min(self.end.x), self.start.y.min(self.end.y));
        let mut hi = Point::new(self.start.x.max(self.end.x), self.start.y.max(self.end.y));
        if let Some((c, r)) = self.arc_center() {
            let sweep = 4.0 * self.bulge.atan();
            let a0 = (self.start.y - c.y).atan2(self.start.x - c.x);
            for k in 0..4 {
                let axis = k as f64 * std::f64::consts::FRAC_PI_2;
                if angle_in_sweep(axis, a0, sweep) {
                    let p = Point::new(c.x + r * axis.cos(), c.y + r * axis.sin());
                    lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
                    hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
                }
            }
        }
        (lo, hi)
    }

    /// Appends points along the span (excluding `end`) so that the chords deviate from the arc
    /// by at most `max_deviation`; at most `max_pieces` chords per span.
    pub fn flatten_into(&self, max_deviation: f64, max_pieces: usize, out: &mut Vec<Point>) {
        out.push(self.start);
        if let Some((_, r)) = self.arc_center() {
            let sweep = (4.0 * self.bulge.atan()).abs();
            // A chord of angle θ deviates r(1 − cos(θ/2)) from its arc.
            let ratio = (1.0 - max_deviation / r).clamp(-1.0, 1.0);
            let step = 2.0 * ratio.acos();
            let pieces = if step > 1e-9 {
                (sweep / step).ceil() as usize
            } else {
                max_pieces
            };
            let pieces = pieces.clamp(2, max_pieces.max(2));
            for k in 1..pieces {
                out.push(self.point_at(k as f64 / pieces as f64));
            }
        }
    }
}

/// Whether angle `a` lies on the arc that starts at `a0` and sweeps `sweep` radians (signed).
pub(crate) fn angle_in_sweep(a: f64, a0: f64, sweep: f64) -> bool {
    let tau = std::f64::consts::TAU;
    let rel = if sweep >= 0.0 {
        (a - a0).rem_euclid(tau)
    } else {
        (a0 - a).rem_euclid(tau)
    };
    rel <= sweep.abs()
}

pub(crate) fn dist(a: Point, b: Point) -> f64 {
    dist2(a, b).sqrt()
}

pub(crate) fn dist2(a: Point, b: Point) -> f64 {
    let dx = a.x - b.x;
    let dy = a.y - b.y;
    dx * dx + dy * dy
}

pub(crate) fn mid(a: Point, b: Point) -> Point {
    Point::new((a.x + b.x) / 2.0, (a.y + b.y) / 2.0)
}

/// The spans of a closed contour, the closing one included.
pub(crate) fn contour_spans(contour: &Contour) -> impl Iterator<Item = Span> + '_ {
    let n = contour.vertices.len();
    (0..n).map(move |i| {
        let v = contour.vertices[i];
        let w = contour.vertices[(i + 1) % n];
        Span {
            start: v.point,
            end: w.point,
            bulge: v.bulge,
        }
    })
}

/// Signed area of a closed bulge contour: positive when counter-clockwise.
pub(crate) fn signed_area(contour: &Contour) -> f64 {
    contour_spans(contour)
        .map(|s| (s.start.x * s.end.y - s.end.x * s.start.y) / 2.0 + s.segment_area())
        .sum()
}

/// The contour run the other way round (arcs keep their shape: bulges change sign).
pub(crate) fn reversed(contour: &Contour) -> Contour {
    let n = contour.vertices.len();
    let vertices = (0..n)
        .map(|j| {
            let point = contour.vertices[n - 1 - j].point;
            let bulge = -contour.vertices[(2 * n - 2 - j) % n].bulge;
            Vertex { point, bulge }
        })
        .collect();
    Contour::new(vertices)
}

/// Bounding box of a contour, arcs included.
pub(crate) fn contour_bounds(contour: &Contour) -> (Point, Point) {
    let mut lo = Point::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for s in contour_spans(contour) {
        let (a, b) = s.bounds();
        lo = Point::new(lo.x.min(a.x), lo.y.min(a.y));
        hi = Point::new(hi.x.max(b.x), hi.y.max(b.y));
    }
    (lo, hi)
}

/// The contour as a polygon whose chords stay within `max_deviation` of the arcs.
pub(crate) fn flatten(contour: &Contour, max_deviation: f64) -> Vec<Point> {
    let mut out = Vec::with_capacity(contour.vertices.len());
    for s in contour_spans(contour) {
        s.flatten_into(max_deviation, 512, &mut out);
    }
    out
}

/// Even-odd point-in-polygon test (the polygon is closed implicitly).
pub(crate) fn point_in_polygon(p: Point, polygon: &[Point]) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for i in 0..n {
        let a = polygon[i];
        let b = polygon[(i + n - 1) % n];
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Distance from `p` to the polygon's boundary.
pub(crate) fn distance_to_polygon(p: Point, polygon: &[Point]) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|i| distance_to_segment(p, polygon[i], polygon[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min)
}

pub(crate) fn distance_to_segment(p: Point, a: Point, b: Point) -> f64 {
    let l2 = dist2(a, b);
    if l2 == 0.0 {
        return dist(p, a);
    }
    let t = (((p.x - a.x) * (b.x - a.x) + (p.y - a.y) * (b.y - a.y)) / l2).clamp(0.0, 1.0);
    dist(p, Point::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_circle() -> Contour {
        Contour::new(vec![
            Vertex::arc(1.0, 0.0, 1.0),
            Vertex::arc(-1.0, 0.0, 1.0),
        ])
    }

    #[test]
    fn circle_area_and_bounds() {
        let c = unit_circle();
        assert!((signed_area(&c) - std::f64::consts::PI).abs() < 1e-12);
        assert!((signed_area(&reversed(&c)) + std::f64::consts::PI).abs() < 1e-12);
        let (lo, hi) = contour_bounds(&c);
        assert!((lo.x + 1.0).abs() < 1e-12 && (lo.y + 1.0).abs() < 1e-12);
        assert!((hi.x - 1.0).abs() < 1e-12 && (hi.y - 1.0).abs() < 1e-12);
    }

    #[test]
    fn arc_center_of_ccw_half_circle() {
        let s = Span {
            start: Point::new(1.0, 0.0),
            end: Point::new(-1.0, 0.0),
            bulge: 1.0,
        };
        let (c, r) = s.arc_center().unwrap();
        assert!(dist(c, Point::new(0.0, 0.0)) < 1e-12 && (r - 1.0).abs() < 1e-12);
        let top = s.point_at(0.5);
        assert!(dist(top, Point::new(0.0, 1.0)) < 1e-12);
    }

    #[test]
    fn reversing_keeps_shape() {
        let c = Contour::new(vec![
            Vertex::arc(0.0, 0.0, 0.3),
            Vertex::line(10.0, 0.0),
            Vertex::arc(10.0, 10.0, -0.2),
        ]);
        let r = reversed(&c);
        assert!((signed_area(&c) + signed_area(&r)).abs() < 1e-9);
        assert_eq!(reversed(&r), c);
    }
}
