//! Private span maths the readers and writers need (areas for DBS record 27, arc angles for
//! result JSON, splitting a contour at a pierce point, the self-intersection check).
//!
//! The geometry crate is growing the same functions; this module is deliberately small and
//! private so it can be replaced by `cutroute_geometry` calls once they land. Formulas follow
//! Appendix Б of the thesis (complex-plane arc maths on the bulge β = tan(φ/4)).

use cutroute_geometry::{Contour, Part, Point, Vertex};

/// Below this |β| an arc is treated by its Taylor series (or as a segment) to avoid 0/0.
const SMALL_BULGE: f64 = 1e-4;

/// A minimal complex number: points of the plane as `x + iy`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn of(p: Point) -> Self {
        Self::new(p.x, p.y)
    }
    fn point(self) -> Point {
        Point::new(self.re, self.im)
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn scale(self, k: f64) -> C {
        C::new(self.re * k, self.im * k)
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// tan(½·arg z) without transcendental functions (formula Б.6).
fn tan_half_arg(z: C) -> f64 {
    let r = z.abs();
    if z.re < 0.0 {
        (r - z.re) / z.im
    } else if r + z.re == 0.0 {
        0.0
    } else {
        z.im / (r + z.re)
    }
}

/// Euclidean distance between two points.
pub(crate) fn dist(a: Point, b: Point) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// Arc angle in degrees (signed, CCW positive) of a span with bulge `b`; result JSON stores this.
pub(crate) fn bulge_to_degrees(b: f64) -> f64 {
    4.0 * b.atan().to_degrees()
}

/// Bulge of a span whose swept angle is `deg` degrees.
pub(crate) fn degrees_to_bulge(deg: f64) -> f64 {
    (deg.to_radians() / 4.0).tan()
}

/// Length of the span from `a` to `z` with bulge `b` (formula Б.3).
pub(crate) fn span_length(a: Point, z: Point, b: f64) -> f64 {
    let chord = dist(a, z);
    if b.abs() < SMALL_BULGE {
        let b2 = b * b;
        (1.0 + b2 * (2.0 / 3.0 - b2 * 2.0 / 15.0)) * chord
    } else {
        (1.0 + b * b) * b.atan() / b * chord
    }
}

/// Signed area contribution of the span (triangle with the origin plus circular segment;
/// formulas Б.4–Б.5). Summed over a closed contour it gives the enclosed area, positive for
/// clockwise (outer) contours and negative for counter-clockwise ones (holes).
pub(crate) fn span_area(a: Point, z: Point, b: f64) -> f64 {
    let triangle = (z.x * a.y - z.y * a.x) / 2.0;
    let chord2 = (z.x - a.x).powi(2) + (z.y - a.y).powi(2);
    let segment = if b.abs() < SMALL_BULGE {
        let b2 = b * b;
        (-b / 3.0 - b * b2 / 15.0 + b * b2 * b2 / 105.0) * chord2
    } else {
        ((1.0 - b * b) * b - (1.0 + b * b).powi(2) * b.atan()) / (8.0 * b * b) * chord2
    };
    triangle + segment
}

/// The spans of a closed contour as `(start, end, bulge)`, the closing span included.
pub(crate) fn spans(contour: &Contour) -> impl Iterator<Item = (Point, Point, f64)> + '_ {
    let v = &contour.vertices;
    (0..v.len()).map(move |i| (v[i].point, v[(i + 1) % v.len()].point, v[i].bulge))
}

/// Signed area of a closed contour (clockwise positive), mm².
pub(crate) fn contour_area(contour: &Contour) -> f64 {
    spans(contour).map(|(a, z, b)| span_area(a, z, b)).sum()
}

/// Perimeter of a closed contour, mm.
pub(crate) fn contour_perimeter(contour: &Contour) -> f64 {
    spans(contour).map(|(a, z, b)| span_length(a, z, b)).sum()
}

/// Material area of a part: outer contour minus its holes, whatever their stored orientation.
pub(crate) fn part_area(part: &Part) -> f64 {
    let mut contours = part.contours.iter();
    let outer = contours.next().map_or(0.0, |c| contour_area(c).abs());
    outer - contours.map(|c| contour_area(c).abs()).sum::<f64>()
}

/// Total cut length of a part: every contour's perimeter.
pub(crate) fn part_perimeter(part: &Part) -> f64 {
    part.contours.iter().map(contour_perimeter).sum()
}

/// The point x(τ), τ ∈ [−1, 1], of the span (formula Б.2).
pub(crate) fn point_on_span(a: Point, z: Point, b: f64, tau: f64) -> Point {
    let (a, z) = (C::of(a), C::of(z));
    let mid = a.add(z).scale(0.5);
    let half = z.sub(a).scale(0.5);
    let f = C::new(tau, -b).div(C::new(1.0, -b * tau));
    mid.add(half.mul(f)).point()
}

/// The zenith (midpoint) of the span.
pub(crate) fn span_midpoint(a: Point, z: Point, b: f64) -> Point {
    point_on_span(a, z, b, 0.0)
}

/// Bulge of each half when a span is halved at its zenith.
pub(crate) fn half_bulge(b: f64) -> f64 {
    b / (1.0 + (1.0 + b * b).sqrt())
}

/// Radius of the arc of the span (infinite for a straight one).
pub(crate) fn arc_radius(a: Point, z: Point, b: f64) -> f64 {
    if b == 0.0 {
        f64::INFINITY
    } else {
        (b + 1.0 / b).abs() * dist(a, z) / 4.0
    }
}

/// The parameter τ of a point known to lie on the span (formula of §5.5).
fn tau_of(a: Point, z: Point, p: Point) -> f64 {
    let (da, dz) = (dist(a, p), dist(z, p));
    if da + dz == 0.0 {
        0.0
    } else {
        (da - dz) / (da + dz)
    }
}

/// Bulges of the two pieces when a span is split at parameter τ: (A→x(τ), x(τ)→Z) (§5.4).
pub(crate) fn split_bulges(b: f64, tau: f64) -> (f64, f64) {
    let one_ib = C::new(1.0, b);
    let left = tan_half_arg(one_ib.mul(C::new(1.0, b * tau)));
    let right = tan_half_arg(one_ib.mul(C::new(1.0, -b * tau)));
    (left, right)
}

/// Distance from `p` to the span, and the span parameter τ of the nearest point.
pub(crate) fn nearest_on_span(a: Point, z: Point, b: f64, p: Point) -> (f64, f64) {
    let endpoints = || {
        let (da, dz) = (dist(a, p), dist(z, p));
        if da <= dz {
            (da, -1.0)
        } else {
            (dz, 1.0)
        }
    };
    let chord = dist(a, z);
    if chord == 0.0 {
        return endpoints();
    }
    if b.abs() < 1e-12 {
        let (dx, dy) = (z.x - a.x, z.y - a.y);
        let t = (((p.x - a.x) * dx + (p.y - a.y) * dy) / (chord * chord)).clamp(0.0, 1.0);
        let q = Point::new(a.x + t * dx, a.y + t * dy);
        return (dist(p, q), 2.0 * t - 1.0);
    }
    // Centre C = (1+iβ)²/(4iβ)·A − (1−iβ)²/(4iβ)·Z.
    let (ca, cz) = (C::of(a), C::of(z));
    let four_ib = C::new(0.0, 4.0 * b);
    let centre = C::new(1.0, b)
        .mul(C::new(1.0, b))
        .div(four_ib)
        .mul(ca)
        .sub(C::new(1.0, -b).mul(C::new(1.0, -b)).div(four_ib).mul(cz));
    let radius = arc_radius(a, z, b);
    let to_p = C::of(p).sub(centre);
    let r = to_p.abs();
    if r == 0.0 {
        return endpoints();
    }
    let x = centre.add(to_p.scale(radius / r)).point();
    // x lies on the arc iff it is on the zenith's side of the chord.
    let m = span_midpoint(a, z, b);
    let side = |q: Point| (z.x - a.x) * (q.y - a.y) - (z.y - a.y) * (q.x - a.x);
    if side(x) * side(m) > 0.0 {
        ((r - radius).abs(), tau_of(a, z, x))
    } else {
        endpoints()
    }
}

/// Splits a closed contour at the point nearest to `pierce`, returning the vertex sequence of
/// the full cut from the pierce point back to it: the first vertex is the pierce point, the
/// returned list repeats it at the end with bulge 0. Returns `None` for an empty contour.
pub(crate) fn cut_from(contour: &Contour, pierce: Point) -> Option<Vec<Vertex>> {
    let v = &contour.vertices;
    if v.is_empty() {
        return None;
    }
    let (mut best, mut best_d, mut best_tau) = (0, f64::INFINITY, -1.0);
    for (i, (a, z, b)) in spans(contour).enumerate() {
        let (d, tau) = nearest_on_span(a, z, b, pierce);
        if d < best_d {
            (best, best_d, best_tau) = (i, d, tau);
        }
    }
    let n = v.len();
    let (a, z, b) = (v[best].point, v[(best + 1) % n].point, v[best].bulge);
    // Snap to the exact vertex at the ends so no sliver span is produced.
    let p = if best_tau <= -1.0 {
        a
    } else if best_tau >= 1.0 {
        z
    } else {
        point_on_span(a, z, b, best_tau)
    };
    let (left, right) = split_bulges(b, best_tau);
    let mut out = Vec::with_capacity(n + 2);
    out.push(Vertex {
        point: p,
        bulge: right,
    });
    for k in 1..=n {
        let i = (best + k) % n;
        let bulge = if k == n { left } else { v[i].bulge };
        out.push(Vertex {
            point: v[i].point,
            bulge,
        });
    }
    out.push(Vertex {
        point: p,
        bulge: 0.0,
    });
    // Drop zero-length pieces created when the pierce point is a vertex.
    out.dedup_by(|later, earlier| {
        later.point == earlier.point && {
            earlier.bulge = if earlier.bulge == 0.0 {
                later.bulge
            } else {
                earlier.bulge
            };
            true
        }
    });
    if out.len() == 1 {
        out.push(Vertex {
            point: p,
            bulge: 0.0,
        });
    }
    if let Some(last) = out.last_mut() {
        last.bulge = 0.0;
    }
    Some(out)
}

/// True when the closed contour crosses or touches itself (arcs are flattened to chords first).
///
/// A sort-and-sweep over the chords' bounding boxes keeps the usual case near-linear; the
/// worst case is quadratic in the number of chords, which the callers bound.
pub(crate) fn is_self_intersecting(contour: &Contour) -> bool {
    let pts = flatten(contour);
    let m = pts.len();
    if m < 3 {
        return false;
    }
    let seg = |i: usize| (pts[i], pts[(i + 1) % m]);
    let scale = pts
        .iter()
        .fold(0.0f64, |s, p| s.max(p.x.abs()).max(p.y.abs()))
        .max(1.0);
    let eps = 1e-12 * scale * scale;
    let adjacent = |i: usize, j: usize| j == (i + 1) % m || i == (j + 1) % m;
    // Adjacent chords may only meet at their shared point: folding back onto each other is an
    // overlap.
    for i in 0..m {
        let (a, b) = seg(i);
        let (_, c) = seg((i + 1) % m);
        let cross = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
        let dot = (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y);
        if cross.abs() <= eps && dot < 0.0 && m > 3 {
            return true;
        }
    }
    let mut order: Vec<usize> = (0..m).collect();
    let min_x = |i: usize| seg(i).0.x.min(seg(i).1.x);
    let max_x = |i: usize| seg(i).0.x.max(seg(i).1.x);
    order.sort_by(|&i, &j| min_x(i).total_cmp(&min_x(j)));
    for (k, &i) in order.iter().enumerate() {
        let (a, b) = seg(i);
        let hi = max_x(i);
        for &j in &order[k + 1..] {
            if min_x(j) > hi {
                break;
            }
            if adjacent(i, j) {
                continue;
            }
            let (c, d) = seg(j);
            if a.y.max(b.y) < c.y.min(d.y) || c.y.max(d.y) < a.y.min(b.y) {
                continue;
            }
            if segments_meet(a, b, c, d, eps) {
                return true;
            }
        }
    }
    false
}

fn orient(a: Point, b: Point, c: Point) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

fn within_box(a: Point, b: Point, p: Point) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Closed-segment intersection test (touching counts), with a small collinearity tolerance.
fn segments_meet(a: Point, b: Point, c: Point, d: Point, eps: f64) -> bool {
    let sgn = |v: f64| {
        if v > eps {
            1
        } else if v < -eps {
            -1
        } else {
            0
        }
    };
    let (o1, o2) = (sgn(orient(a, b, c)), sgn(orient(a, b, d)));
    let (o3, o4) = (sgn(orient(c, d, a)), sgn(orient(c, d, b)));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    (o1 == 0 && within_box(a, b, c))
        || (o2 == 0 && within_box(a, b, d))
        || (o3 == 0 && within_box(c, d, a))
        || (o4 == 0 && within_box(c, d, b))
}

/// The contour as a closed polyline: arcs become up to 16 chords (one per 22.5°).
fn flatten(contour: &Contour) -> Vec<Point> {
    let mut out = Vec::with_capacity(contour.vertices.len());
    for (a, z, b) in spans(contour) {
        out.push(a);
        if b != 0.0 && a != z {
            let sweep = 4.0 * b.atan().abs();
            let pieces = ((sweep / (std::f64::consts::PI / 8.0)).ceil() as usize).clamp(2, 16);
            for k in 1..pieces {
                let tau = -1.0 + 2.0 * k as f64 / pieces as f64;
                out.push(point_on_span(a, z, b, tau));
            }
        }
    }
    // Repeated points would make zero-length chords that "touch" their neighbours' neighbours.
    out.dedup();
    if out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_cw() -> Contour {
        Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, 10.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(10.0, 0.0),
        ])
    }

    fn circle(r: f64, bulge: f64) -> Contour {
        Contour::new(vec![
            Vertex::arc(0.0, r, bulge),
            Vertex::arc(0.0, -r, bulge),
        ])
    }

    #[test]
    fn clockwise_square_has_positive_area() {
        assert!((contour_area(&square_cw()) - 100.0).abs() < 1e-12);
        assert!((contour_perimeter(&square_cw()) - 40.0).abs() < 1e-12);
    }

    #[test]
    fn circles_have_textbook_area_and_length() {
        let cw = circle(2.0, -1.0);
        assert!((contour_area(&cw) - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        assert!((contour_perimeter(&cw) - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        assert!((contour_area(&circle(2.0, 1.0)) + 4.0 * std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn small_bulge_series_matches_closed_form() {
        let (a, z) = (Point::new(1.0, 2.0), Point::new(5.0, -1.0));
        for b in [2e-4f64, -3e-4] {
            let closed = ((1.0 - b * b) * b - (1.0 + b * b).powi(2) * b.atan()) / (8.0 * b * b);
            let series = -b / 3.0 - b * b * b / 15.0;
            assert!((closed - series).abs() < 1e-9);
            assert!(span_length(a, z, b) > dist(a, z));
        }
    }

    #[test]
    fn angle_conversion_round_trips() {
        assert!((bulge_to_degrees(1.0) - 180.0).abs() < 1e-12);
        assert!((degrees_to_bulge(90.0) - (2f64.sqrt() - 1.0)).abs() < 1e-12);
    }

    #[test]
    fn split_bulges_recombine() {
        let b = 0.7;
        let (l, r) = split_bulges(b, 0.3);
        assert!(((l + r) / (1.0 - l * r) - b).abs() < 1e-12);
        assert!((split_bulges(b, 0.0).0 - half_bulge(b)).abs() < 1e-12);
    }

    #[test]
    fn cut_from_mid_arc_keeps_length() {
        let c = circle(5.0, -1.0);
        let pierce = Point::new(5.0, 0.0);
        let cut = cut_from(&c, pierce).unwrap();
        assert_eq!(cut.first().unwrap().point, cut.last().unwrap().point);
        assert!(dist(cut[0].point, pierce) < 1e-9);
        let len: f64 = cut
            .windows(2)
            .map(|w| span_length(w[0].point, w[1].point, w[0].bulge))
            .sum();
        assert!((len - contour_perimeter(&c)).abs() < 1e-9);
    }

    #[test]
    fn bow_tie_is_self_intersecting_square_is_not() {
        assert!(!is_self_intersecting(&square_cw()));
        assert!(!is_self_intersecting(&circle(3.0, 1.0)));
        let bow = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(10.0, 0.0),
            Vertex::line(0.0, 10.0),
        ]);
        assert!(is_self_intersecting(&bow));
    }
}
