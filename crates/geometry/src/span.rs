//! One span of a contour: a straight segment or a circular arc given by its ends and bulge.
//!
//! The formulas follow Appendix Б of the dissertation (complex-plane arc geometry): with chord
//! `d = Z − A`, length `L = |d|` and bulge `β = tan(φ/4)`, the arc length is
//! `L·(1 + β²)·atan(β)/β`, the radius `L·(1 + β²)/(4|β|)`, and so on. Wherever a formula would
//! divide by β, a series or a form without the division is used, so nearly straight arcs
//! (β → 0) lose no precision and β = 0 needs no special case in the callers.
//!
//! Points on a span are addressed by `t ∈ [0, 1]`, proportional to arc length (not the τ of
//! formula Б.2, whose speed varies along the arc).

use crate::float::Libm;
use serde::{Deserialize, Serialize};

use crate::{BoundingBox, Point, Transform};

/// Below this |β| the nearest-point search refines a projection instead of going through the
/// centre, which lies ~L/(4β) away and would cost that many ulps of precision.
const NEAR_STRAIGHT_BULGE: f64 = 1e-3;

/// Below this |β| a point's parameter is taken from its projection onto the chord: the relative
/// error is O(β²), far below anything measurable.
const PROJECTION_PARAMETER_BULGE: f64 = 1e-6;

/// A segment or circular arc from `start` to `end`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Span {
    /// Where the span starts (A).
    pub start: Point,
    /// Where the span ends (Z).
    pub end: Point,
    /// `tan(φ/4)` of the swept angle φ; 0 for a segment, positive for counter-clockwise.
    pub bulge: f64,
}

/// The point of a span nearest to some query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpanProjection {
    /// Arc-length parameter of the nearest point, in `[0, 1]`.
    pub t: f64,
    /// The nearest point.
    pub point: Point,
    /// Its distance to the query point.
    pub distance: f64,
}

/// A point where two spans meet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpanIntersection {
    /// The common point.
    pub point: Point,
    /// Its arc-length parameter on the first span (the receiver).
    pub t_self: f64,
    /// Its arc-length parameter on the second span (the argument).
    pub t_other: f64,
}

/// `tan(arg(z)/2)` without trigonometry (formula Б.6); `z` is given as `(re, im)`.
///
/// Returns `None` for `z = 0` and for the negative real axis, where the result is infinite.
pub fn tan_half_arg(re: f64, im: f64) -> Option<f64> {
    let r = re.hypot_libm(im);
    let value = if re < 0.0 {
        if im == 0.0 {
            return None;
        }
        (r - re) / im
    } else {
        if r == 0.0 {
            return None;
        }
        im / (r + re)
    };
    value.is_finite().then_some(value)
}

/// `sin(t·x)/sin(x)` for `|x| < π`, stable as `x → 0` (where it tends to `t`).
fn sin_ratio(t: f64, x: f64) -> f64 {
    if x.abs() < 1e-4 {
        // sin(tx)/sin(x) = t·(1 + (1 − t²)·x²/6 + O(x⁴))
        t * (1.0 + (1.0 - t * t) * x * x / 6.0)
    } else {
        (t * x).sin_libm() / x.sin_libm()
    }
}

/// `atan(β)/β`, stable as `β → 0`.
fn atan_over(beta: f64) -> f64 {
    let b2 = beta * beta;
    if beta.abs() < 1e-2 {
        // 1 − β²/3 + β⁴/5 − β⁶/7 + β⁸/9 − …; the next term is below 1e-20.
        1.0 - b2 * (1.0 / 3.0 - b2 * (1.0 / 5.0 - b2 * (1.0 / 7.0 - b2 / 9.0)))
    } else {
        beta.atan_libm() / beta
    }
}

/// Circular-segment area factor: signed area between chord and arc divided by `L²`
/// (positive for β > 0, i.e. when the arc bulges to the right of the chord).
fn segment_area_factor(beta: f64) -> f64 {
    let b2 = beta * beta;
    if beta.abs() < 1e-2 {
        // Series of Б.4 with the sign flipped to the counter-clockwise-positive convention.
        beta * (1.0 / 3.0
            + b2 * (1.0 / 15.0 - b2 * (1.0 / 105.0 - b2 * (1.0 / 315.0 - b2 / 693.0))))
    } else {
        ((1.0 + b2) * (1.0 + b2) * beta.atan_libm() - (1.0 - b2) * beta) / (8.0 * b2)
    }
}

/// A cycle (circle or line) `a·|q|² + g·q + h = 0` in coordinates relative to some origin.
#[derive(Clone, Copy, Debug)]
struct Cycle {
    a: f64,
    g: Point,
    h: f64,
}

impl Cycle {
    fn value(&self, q: Point) -> f64 {
        self.a * q.norm_squared() + self.g.dot(q) + self.h
    }
}

/// Real roots of `a·s² + b·s + c = 0`, robust for `a → 0` (then one root runs off to infinity,
/// to be rejected by the caller) and for a slightly negative discriminant (a tangent touch blurred by rounding).
fn quadratic_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if !(scale > 0.0) || !scale.is_finite() {
        return Vec::new();
    }
    let (a, b, c) = (a / scale, b / scale, c / scale);
    // Even a tiny `a` is kept: the small root c/q below stays exact, while dropping a·s²
    // would cost precision when s is large (nearly straight arcs).
    if a == 0.0 {
        if b == 0.0 {
            return Vec::new();
        }
        return vec![-c / b];
    }
    let mut disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        if disc > -1e-12 * (b * b + (4.0 * a * c).abs()) {
            disc = 0.0;
        } else {
            return Vec::new();
        }
    }
    if disc == 0.0 {
        return vec![-b / (2.0 * a)];
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let q = if q == 0.0 { -0.5 * disc.sqrt() } else { q };
    vec![q / a, c / q]
}

/// Golden-section search for the least value of `f` on `[lo, hi]`, where it is unimodal; the
/// bracket's ends are tried too (a monotone `f` is least there): `(t, f(t))`.
/// Value of the polynomial `c[0] + c[1]·x + … + c[n]·xⁿ` (Horner).
fn polynomial_value(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * x + k)
}

/// The real roots in `[lo, hi]` of the polynomial `c[0] + c[1]·x + … ` and the roots of each
/// of its derivatives there (its turning points and theirs), unsorted. By induction on the
/// degree: the derivative's roots cut `[lo, hi]` into pieces on which the polynomial is
/// monotone, so each piece holds at most one root, found by bisection where the sign changes.
/// A double root shows as a root of the derivative, which is why those are returned too.
/// Leading coefficients below `1e-13` of the largest count as zero.
fn polynomial_roots_and_turns(c: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let largest = c.iter().fold(0.0f64, |m, &k| m.max(k.abs()));
    let degree = c.iter().rposition(|&k| k.abs() > 1e-13 * largest);
    let Some(degree) = degree.filter(|&d| d > 0) else {
        return Vec::new();
    };
    let c = &c[..=degree];
    let derivative: Vec<f64> = (1..=degree).map(|k| k as f64 * c[k]).collect();
    let mut turns = polynomial_roots_and_turns(&derivative, lo, hi);
    let mut cuts: Vec<f64> = turns
        .iter()
        .copied()
        .filter(|x| (lo..=hi).contains(x))
        .collect();
    cuts.extend([lo, hi]);
    cuts.sort_by(f64::total_cmp);
    let mut roots = Vec::new();
    for piece in cuts.windows(2) {
        let (mut a, mut b) = (piece[0], piece[1]);
        let (fa, fb) = (polynomial_value(c, a), polynomial_value(c, b));
        if fa == 0.0 {
            roots.push(a);
            continue;
        }
        if fa.signum() == fb.signum() {
            continue;
        }
        // Bisection to the last bit: ≤ ~64 halvings of a finite interval.
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                break;
            }
            if polynomial_value(c, mid).signum() == fa.signum() {
                a = mid;
            } else {
                b = mid;
            }
        }
        roots.push(0.5 * (a + b));
    }
    turns.extend(roots);
    turns
}

fn golden_section(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_8;
    let (first, last) = (lo, hi);
    let (mut x1, mut x2) = (hi - R * (hi - lo), lo + R * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..60 {
        if hi - lo < 1e-12 {
            break;
        }
        if f1 <= f2 {
            (hi, x2, f2) = (x2, x1, f1);
            x1 = hi - R * (hi - lo);
            f1 = f(x1);
        } else {
            (lo, x1, f1) = (x1, x2, f2);
            x2 = lo + R * (hi - lo);
            f2 = f(x2);
        }
    }
    let mid = 0.5 * (lo + hi);
    [first, last]
        .into_iter()
        .map(|t| (t, f(t)))
        .fold((mid, f(mid)), |best, x| if x.1 < best.1 { x } else { best })
}

impl Span {
    /// A span from `start` to `end` with the given bulge.
    pub const fn new(start: Point, end: Point, bulge: f64) -> Self {
        Span { start, end, bulge }
    }

    /// A straight segment.
    pub const fn line(start: Point, end: Point) -> Self {
        Span {
            start,
            end,
            bulge: 0.0,
        }
    }

    /// The arc from `start` to `end` passing through `via` (section 5.5): its bulge is
    /// `tan(arg(conj(via − start)·(end − via))/2)`.
    ///
    /// `None` when `via` coincides with an end, or lies on the chord's line outside the chord
    /// (no finite arc passes through it); a `via` on the chord gives a straight segment.
    pub fn through_points(start: Point, via: Point, end: Point) -> Option<Span> {
        let u = via - start;
        let v = end - via;
        if u.norm_squared() == 0.0 || v.norm_squared() == 0.0 {
            return None;
        }
        // conj(u)·v = (u.x − i·u.y)(v.x + i·v.y)
        let re = u.dot(v);
        let im = u.cross(v);
        tan_half_arg(re, im).map(|bulge| Span::new(start, end, bulge))
    }

    /// True for a straight segment (`bulge == 0`).
    pub fn is_line(&self) -> bool {
        self.bulge == 0.0
    }

    /// The chord vector `end − start`.
    pub fn chord(&self) -> Point {
        self.end - self.start
    }

    /// Length of the chord.
    pub fn chord_length(&self) -> f64 {
        self.chord().norm()
    }

    /// Signed swept angle φ = 4·atan(β), in `(−2π, 2π)`; positive counter-clockwise.
    pub fn sweep(&self) -> f64 {
        4.0 * self.bulge.atan_libm()
    }

    /// Radius `L·(1 + β²)/(4|β|)`; infinite for a segment.
    pub fn radius(&self) -> f64 {
        if self.is_line() {
            return f64::INFINITY;
        }
        self.chord_length() * (1.0 + self.bulge * self.bulge) / (4.0 * self.bulge.abs())
    }

    /// Signed curvature `1/R` (positive for counter-clockwise arcs, 0 for segments), finite
    /// for every finite bulge and non-degenerate chord.
    pub fn curvature(&self) -> f64 {
        let l = self.chord_length();
        if l == 0.0 {
            return 0.0;
        }
        4.0 * self.bulge / (l * (1.0 + self.bulge * self.bulge))
    }

    /// Centre of the arc: the chord midpoint plus `i·d·(1 − β²)/(4β)`; `None` for a segment.
    ///
    /// For tiny β the centre is far away and imprecise in absolute terms; the other methods
    /// avoid it for that reason.
    pub fn centre(&self) -> Option<Point> {
        if self.is_line() {
            return None;
        }
        let b = self.bulge;
        let c = self.start.midpoint(self.end)
            + self.chord().rotated_quarter() * ((1.0 - b * b) / (4.0 * b));
        c.is_finite().then_some(c)
    }

    /// The arc's midpoint, the "zenith" `(A + Z)/2 − i·d·β/2`.
    pub fn midpoint(&self) -> Point {
        self.start.midpoint(self.end) - self.chord().rotated_quarter() * (0.5 * self.bulge)
    }

    /// Arc length `(1 + β²)·atan(β)/β·L` (formula Б.3, series near β = 0).
    pub fn length(&self) -> f64 {
        let b = self.bulge;
        (1.0 + b * b) * atan_over(b) * self.chord_length()
    }

    /// Signed area between the chord and the arc, positive when it adds to the area of a
    /// counter-clockwise contour (β > 0). Formula Б.4 with the opposite (CCW-positive) sign.
    pub fn segment_area(&self) -> f64 {
        segment_area_factor(self.bulge) * self.chord().norm_squared()
    }

    /// This span's contribution to the signed area of a closed contour, taken about `origin`:
    /// the shoelace triangle (origin, A, Z) plus the circular segment. Summing it over a
    /// contour's spans gives the contour's area, positive for counter-clockwise contours.
    /// Passing a point near the contour as `origin` avoids cancellation far from (0, 0).
    pub fn area_term(&self, origin: Point) -> f64 {
        0.5 * (self.start - origin).cross(self.end - origin) + self.segment_area()
    }

    /// The point at arc-length fraction `t` (0 = start, 1 = end); `t` outside `[0, 1]` walks on
    /// along the circle (or line).
    ///
    /// Computed as `A + d·sin(tφ/2)/sin(φ/2)` turned by `(t − 1)·φ/2`: no centre involved, so it
    /// is exact for segments and stable for nearly straight arcs.
    pub fn point_at(&self, t: f64) -> Point {
        if t == 0.0 {
            return self.start;
        }
        if t == 1.0 {
            return self.end;
        }
        let d = self.chord();
        if self.is_line() {
            return self.start + d * t;
        }
        let half = 0.5 * self.sweep();
        self.start + d.rotated((t - 1.0) * half) * sin_ratio(t, half)
    }

    /// Unit tangent (direction of travel) at arc-length fraction `t`; zero for a zero-length span.
    pub fn tangent_at(&self, t: f64) -> Point {
        let d = self.chord().normalized();
        if self.is_line() {
            return d;
        }
        d.rotated((2.0 * t - 1.0) * 0.5 * self.sweep())
    }

    /// The same span run backwards (ends swapped, bulge negated).
    pub fn reversed(&self) -> Span {
        Span::new(self.end, self.start, -self.bulge)
    }

    /// The span mapped by `transform`; a reflection negates the bulge.
    pub fn transformed(&self, transform: &Transform) -> Span {
        let bulge = if transform.is_reflection() {
            -self.bulge
        } else {
            self.bulge
        };
        Span::new(
            transform.apply(self.start),
            transform.apply(self.end),
            bulge,
        )
    }

    /// Exact bounding box: the ends plus every axis extreme (leftmost, topmost, …) of the
    /// circle that lies inside the sweep.
    pub fn bounding_box(&self) -> BoundingBox {
        let mut bbox = BoundingBox::from_corners(self.start, self.end);
        if self.is_line() {
            return bbox;
        }
        let b = self.bulge;
        if b.abs() >= 1e-4 && b.abs() <= 1e4 {
            // The circle's extreme point in an axis direction lies on the arc when it is on
            // the arc's side of the chord (the right for a counter-clockwise arc). No angle is
            // needed; near β = 0 or ∞ the centre is far from the chord or near an end, and the
            // angles below are the accurate way.
            let d = self.chord();
            let centre =
                self.start.midpoint(self.end) + d.rotated_quarter() * ((1.0 - b * b) / (4.0 * b));
            let radius = d.norm() * (1.0 + b * b) / (4.0 * b.abs());
            if centre.is_finite() && radius.is_finite() {
                for u in [
                    Point::new(1.0, 0.0),
                    Point::new(0.0, 1.0),
                    Point::new(-1.0, 0.0),
                    Point::new(0.0, -1.0),
                ] {
                    let extreme = centre + u * radius;
                    if d.cross(extreme - self.start) * b < 0.0 {
                        bbox = bbox.including(extreme);
                    }
                }
                return bbox;
            }
        }
        let phi = self.sweep();
        let d = self.chord();
        if d.norm_squared() == 0.0 || !phi.is_finite() {
            return bbox;
        }
        let theta = d.y.atan2_libm(d.x);
        let tau = std::f64::consts::TAU;
        // The outward radius at fraction t points at θ + (2t − 1)φ/2 ∓ π/2 (− for CCW arcs,
        // whose centre is on the left); it points along axis direction α when
        // t·φ ≡ α − θ + φ/2 ± π/2 (mod 2π).
        let side = if phi > 0.0 {
            std::f64::consts::FRAC_PI_2
        } else {
            -std::f64::consts::FRAC_PI_2
        };
        for k in 0..4 {
            let alpha = k as f64 * std::f64::consts::FRAC_PI_2;
            let delta = (alpha - theta + 0.5 * phi + side).rem_euclid(tau);
            let delta = if phi < 0.0 && delta > 0.0 {
                delta - tau
            } else {
                delta
            };
            let t = delta / phi;
            if (0.0..=1.0).contains(&t) {
                bbox = bbox.including(self.point_at(t));
            }
        }
        bbox
    }

    /// The two spans `start → point_at(t)` and `point_at(t) → end`, with bulges
    /// `tan(tφ/4)` and `tan((1 − t)φ/4)`. `t` is clamped to `[0, 1]`.
    pub fn split_at(&self, t: f64) -> (Span, Span) {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let p = self.point_at(t);
        if self.is_line() {
            return (Span::line(self.start, p), Span::line(p, self.end));
        }
        let phi = self.sweep();
        let first = Span::new(self.start, p, (0.25 * t * phi).tan_libm());
        let second = Span::new(p, self.end, (0.25 * (1.0 - t) * phi).tan_libm());
        (first, second)
    }

    /// The two halves `start → midpoint()` and `midpoint() → end`, each with bulge
    /// `β / (1 + √(1 + β²))` = `tan(φ/8)` (Appendix Б): [`split_at`](Self::split_at)`(0.5)`
    /// without trigonometry. Halves of an arc of 180° or more are below 180° each, so they can
    /// be written where an arc must be less than a half turn (an SVG `A` without the large-arc
    /// flag).
    pub fn halved(&self) -> (Span, Span) {
        let b = self.bulge;
        let half = b / (1.0 + (1.0 + b * b).sqrt());
        let m = self.midpoint();
        (Span::new(self.start, m, half), Span::new(m, self.end, half))
    }

    /// The sub-span between arc-length fractions `t0` and `t1` (`t0 ≤ t1` not required: a
    /// reversed range gives the reversed piece).
    pub fn sub_span(&self, t0: f64, t1: f64) -> Span {
        let a = self.point_at(t0);
        let b = self.point_at(t1);
        if self.is_line() {
            return Span::line(a, b);
        }
        Span::new(a, b, (0.25 * (t1 - t0) * self.sweep()).tan_libm())
    }

    /// Merges `self` with the following span `next` into one span when they are pieces of the
    /// same line or circle meeting end to start; the bulge is `tan((φ₁ + φ₂)/4)`, i.e.
    /// `(β₁ + β₂)/(1 − β₁β₂)`. `None` when they do not continue each other within
    /// `tolerance` (a length), or when the union would sweep a full circle or more.
    pub fn joined(&self, next: &Span, tolerance: f64) -> Option<Span> {
        if !(self.end.distance(next.start) <= tolerance) {
            return None;
        }
        let total = self.sweep() + next.sweep();
        if !(total.abs() < std::f64::consts::TAU) {
            return None;
        }
        let merged = if self.is_line() && next.is_line() {
            Span::line(self.start, next.end)
        } else {
            Span::new(self.start, next.end, (0.25 * total).tan_libm())
        };
        // Both pieces must lie on the merged span: test each one's midpoint.
        let on = |s: &Span| merged.nearest_point(s.midpoint()).distance <= tolerance;
        let turns_consistently = self.sweep().signum() * next.sweep().signum() >= 0.0;
        (turns_consistently && on(self) && on(next)).then_some(merged)
    }

    /// The arc-length parameter of a point lying on (or very near) the span's line or circle;
    /// not clamped: points of the line or circle outside the span map outside `[0, 1]`.
    pub fn parameter_of(&self, p: Point) -> f64 {
        let d = self.chord();
        let l2 = d.norm_squared();
        if l2 == 0.0 {
            return 0.0;
        }
        if self.bulge.abs() < PROJECTION_PARAMETER_BULGE {
            return (p - self.start).dot(d) / l2;
        }
        let phi = self.sweep();
        let tangent = d.rotated(-0.5 * phi);
        let v = p - self.start;
        if phi.abs() < 1.0 {
            // Chord ratio: |P − A| = L·sin(tφ/2)/sin(φ/2), monotone here. Going through the
            // angle instead would multiply its rounding error by 2/φ.
            let ratio = (v.norm() / l2.sqrt() * (0.5 * phi.abs()).sin_libm()).min(1.0);
            let t = 2.0 * ratio.asin_libm() / phi.abs();
            return if tangent.dot(v) < 0.0 { -t } else { t };
        }
        if let Some(c) = self.centre() {
            // Central angle from A to P. With |φ| ≥ 1 the radius is at most ~1.05·L, so the
            // centre is precise; the tangent–chord angle is not used here because, for a point
            // just past A, it lives in P's offset across the tangent (second order in the
            // distance), which rounding of P's coordinates erases.
            let (u, w) = (self.start - c, p - c);
            let angle = u.cross(w).atan2_libm(u.dot(w));
            // Take the turn of that angle nearest the arc's middle (φ/2), so a point a rounding
            // error before A (or past Z) maps just outside [0, 1], not a full turn away.
            let from_middle = angle - 0.5 * phi;
            let from_middle = from_middle.sin_libm().atan2_libm(from_middle.cos_libm());
            return (0.5 * phi + from_middle) / phi;
        }
        // Tangent–chord angle: the chord A→P makes half of its arc's angle with the start tangent.
        let psi = tangent.cross(v).atan2_libm(tangent.dot(v));
        let psi = if phi > 0.0 && psi < 0.0 {
            psi + std::f64::consts::TAU
        } else if phi < 0.0 && psi > 0.0 {
            psi - std::f64::consts::TAU
        } else {
            psi
        };
        2.0 * psi / phi
    }

    /// The point of the span nearest to `p`, its parameter and distance.
    ///
    /// A NaN input gives a NaN distance (never a panic).
    pub fn nearest_point(&self, p: Point) -> SpanProjection {
        let at = |t: f64| {
            let point = self.point_at(t);
            SpanProjection {
                t,
                point,
                distance: point.distance(p),
            }
        };
        let better =
            |a: SpanProjection, b: SpanProjection| if b.distance < a.distance { b } else { a };
        let ends = better(at(0.0), at(1.0));
        let d = self.chord();
        let l2 = d.norm_squared();
        if l2 == 0.0 {
            return at(0.0);
        }
        let projection_t = ((p - self.start).dot(d) / l2).clamp(0.0, 1.0);
        if self.is_line() {
            return if projection_t.is_nan() {
                ends
            } else {
                at(projection_t)
            };
        }
        let radius = self.radius();
        let far = p.distance(self.start.midpoint(self.end)) > 0.25 * radius;
        if self.bulge.abs() >= NEAR_STRAIGHT_BULGE || far {
            // Radial projection onto the circle; the centre is precise enough here.
            let Some(c) = self.centre() else { return ends };
            let v = p - c;
            let n = v.norm();
            if !(n > 1e-12 * radius) {
                return ends; // p at the centre: every point is equally near
            }
            let x = c + v * (radius / n);
            // On the arc iff on the zenith side of the chord (cross(d, x − A)·β ≤ 0).
            if d.cross(x - self.start) * self.bulge <= 0.0 {
                let t = self.parameter_of(x).clamp(0.0, 1.0);
                return better(ends, at(t));
            }
            return ends;
        }
        // Nearly straight and p nearby: Newton on t from the chord projection. The true second
        // derivative differs from length² by a factor (1 ± κ·dist) with κ·dist < 1/4 here, so
        // the iteration contracts.
        let length = self.length();
        let mut t = projection_t;
        for _ in 0..60 {
            let q = self.point_at(t);
            let g = (q - p).dot(self.tangent_at(t)) * length;
            let next = (t - g / (length * length)).clamp(0.0, 1.0);
            let step = (next - t).abs();
            t = next;
            if !(step > 1e-15) {
                break;
            }
        }
        if t.is_nan() {
            return ends;
        }
        better(ends, at(t))
    }

    /// Distance from `p` to the span.
    pub fn distance_to(&self, p: Point) -> f64 {
        self.nearest_point(p).distance
    }

    /// The point of the span where a detour from `a` to `b` is shortest: `(t, value)` with
    /// `value = |a s(t)| + |s(t) b|` least over `t ∈ [0, 1]` (`|a s(t)|` alone without `b`):
    /// where a pierce point on this span costs the least idle travel between the previous exit
    /// `a` and the next entry `b`. A span crossing the segment `ab` gives `|ab|` at the
    /// crossing; otherwise the sum is convex along a line (golden-section search) and, on an
    /// arc, is least at one of its stationary points or an end, all of which are found
    /// (a sextic's roots); nearly straight arcs (bulge below 10⁻³) are searched around the
    /// best of samples every π/8 at most.
    pub fn detour_minimum(&self, a: Point, b: Option<Point>) -> (f64, f64) {
        let Some(b) = b else {
            let q = self.nearest_point(a);
            return (q.t, q.distance);
        };
        if let Some(x) = self.intersect_segment(a, b).first() {
            return (x.t_self, a.distance(x.point) + x.point.distance(b));
        }
        let f = |t: f64| {
            let m = self.point_at(t);
            a.distance(m) + m.distance(b)
        };
        if self.is_line() {
            return golden_section(&f, 0.0, 1.0);
        }
        if let Some(best) = self.arc_detour_stationary(a, b) {
            return best;
        }
        let n = 8 + (self.sweep().abs() / (std::f64::consts::PI / 8.0)).ceil() as usize;
        let k = (0..=n)
            .min_by(|&x, &y| f(x as f64 / n as f64).total_cmp(&f(y as f64 / n as f64)))
            .unwrap_or(0);
        golden_section(
            &f,
            k.saturating_sub(1) as f64 / n as f64,
            (k + 1).min(n) as f64 / n as f64,
        )
    }

    /// [`Span::detour_minimum`] on an arc of bulge ≥ 10⁻³ from its stationary points, which
    /// are all found: `f = |a m| + |m b|` can have two local minima on an arc (a sampled
    /// search picked the wrong one, 1 mm above the least), so no search in one basin is
    /// enough. With the centre at the origin, the arc's midpoint on the x axis and
    /// `m = R·(cos θ, sin θ)`, `f′(θ) = 0` is `cross(A, m)/|m − A| = −cross(B, m)/|m − B|`;
    /// squared and with `t = tan(θ/2)` (the arc is `|t| ≤ |β|`, as `θ ≤ sweep/2 = 2·atan β`)
    /// it is the sextic `p_A²·q_B − p_B²·q_A = 0` with the quadratics
    /// `p_X = cross(X, m)·(1 + t²)/R` and `q_X = |m − X|²·(1 + t²)`. Its roots, the roots of
    /// its derivatives and the two ends are the candidates; the least true `f` among them is
    /// returned. `None` for nearly straight arcs (their centre is too far for the sextic to be
    /// well conditioned), left to the sampled search.
    fn arc_detour_stationary(&self, a: Point, b: Point) -> Option<(f64, f64)> {
        if self.bulge.abs() < 1e-3 {
            return None;
        }
        let centre = self.centre()?;
        let radius = self.radius();
        let axis = (self.midpoint() - centre) * (1.0 / radius);
        if !(radius.is_finite() && axis.is_finite()) {
            return None;
        }
        // Coordinates in the frame (axis, axis rotated a quarter), in units of the radius.
        let local = |p: Point| {
            let v = (p - centre) * (1.0 / radius);
            (v.dot(axis), axis.cross(v))
        };
        let quadratics = |(x, y): (f64, f64)| {
            // cross(X, u)·(1 + t²) with u = ((1 − t²), 2t)/(1 + t²): x·2t − y·(1 − t²).
            let p = [-y, 2.0 * x, y];
            // |u − X|²·(1 + t²) = (1 + |X|²)(1 + t²) − 2(x(1 − t²) + 2y·t).
            let r = 1.0 + x * x + y * y;
            let q = [r - 2.0 * x, -4.0 * y, r + 2.0 * x];
            (p, q)
        };
        let multiply = |u: &[f64], v: &[f64]| {
            let mut w = vec![0.0; u.len() + v.len() - 1];
            for (i, &x) in u.iter().enumerate() {
                for (j, &y) in v.iter().enumerate() {
                    w[i + j] += x * y;
                }
            }
            w
        };
        let (pa, qa) = quadratics(local(a));
        let (pb, qb) = quadratics(local(b));
        let left = multiply(&multiply(&pa, &pa), &qb);
        let right = multiply(&multiply(&pb, &pb), &qa);
        let sextic: Vec<f64> = left.iter().zip(&right).map(|(l, r)| l - r).collect();
        if !sextic.iter().all(|k| k.is_finite()) {
            return None;
        }
        let reach = self.bulge.abs();
        let sweep = self.sweep();
        let f = |t: f64| {
            let m = self.point_at(t);
            a.distance(m) + m.distance(b)
        };
        polynomial_roots_and_turns(&sextic, -reach, reach)
            .into_iter()
            .filter(|t| t.is_finite())
            // θ = 2·atan t from the midpoint; the span's parameter is 1/2 + θ/sweep.
            .map(|t| (0.5 + 2.0 * t.atan() / sweep).clamp(0.0, 1.0))
            .chain([0.0, 1.0])
            .map(|t| (t, f(t)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
    }

    /// The least distance between a point of this span and a point of `other`: 0 when they
    /// meet, else attained at an end of one span (its nearest point on the other), or at
    /// interior points of both where the connecting line is normal to both: on an arc that
    /// line passes through the centre, so the candidates are the arc's points in the direction
    /// of the other arc's centre or of the other segment's normal. Each candidate is a true
    /// point of the span, so the result is a true distance; parallel segments and concentric
    /// arcs reach their minimum at an end too. This is the set distance of the interval
    /// relaxation behind CCP's lower bound (pieces of contours as PCGTSP nodes).
    pub fn distance_to_span(&self, other: &Span) -> f64 {
        if !self.intersections(other).is_empty() {
            return 0.0;
        }
        let mut best = [self.start, self.end]
            .iter()
            .map(|&p| other.distance_to(p))
            .chain(
                [other.start, other.end]
                    .iter()
                    .map(|&p| self.distance_to(p)),
            )
            .fold(f64::INFINITY, f64::min);
        for (on, to) in [(self, other), (other, self)] {
            for p in on.normal_candidates(to) {
                best = best.min(to.distance_to(p));
            }
        }
        best
    }

    /// The point of this span nearest to `other`, with its parameter and its distance to
    /// `other` (the set distance of [`Span::distance_to_span`], to rounding): where an idle
    /// move from or to `other` reaches this span at its shortest. A meeting point when they
    /// meet; else the best of the candidates the set distance is attained at (this span's
    /// ends, its points nearest to the other's ends, and its points where a line normal to
    /// both can meet it, from either side). Which point among several equally near ones is
    /// unspecified.
    pub fn nearest_point_to_span(&self, other: &Span) -> SpanProjection {
        if let Some(x) = self.intersections(other).first() {
            return SpanProjection {
                t: x.t_self,
                point: x.point,
                distance: 0.0,
            };
        }
        let at = |t: f64| {
            let point = self.point_at(t);
            SpanProjection {
                t,
                point,
                distance: other.distance_to(point),
            }
        };
        // The other's points where the least distance can be attained, carried onto this span
        // by their nearest points.
        let from_other = [other.start, other.end]
            .into_iter()
            .chain(other.normal_candidates(self))
            .map(|p| self.nearest_point(p).t);
        let own = self
            .normal_candidates(other)
            .into_iter()
            .map(|p| self.parameter_of(p).clamp(0.0, 1.0));
        [0.0, 1.0]
            .into_iter()
            .chain(from_other)
            .chain(own)
            .map(at)
            .min_by(|a, b| a.distance.total_cmp(&b.distance))
            .unwrap_or_else(|| at(0.0))
    }

    /// Points of this arc (none for a segment) where a line normal to it can also be normal to
    /// `other`: the arc's points in the direction (±) of the other's centre, or of the other
    /// segment's normal.
    fn normal_candidates(&self, other: &Span) -> Vec<Point> {
        let (Some(c), r) = (self.centre(), self.radius()) else {
            return Vec::new();
        };
        let direction = match other.centre() {
            Some(oc) => oc - c,
            None => other.chord().rotated_quarter(),
        };
        let n = direction.norm();
        if !(n > 0.0 && r.is_finite()) {
            return Vec::new();
        }
        let u = direction * (1.0 / n);
        [c + u * r, c - u * r]
            .into_iter()
            .map(|p| self.point_at(self.parameter_of(p).clamp(0.0, 1.0)))
            .collect()
    }

    /// The span's circle (or line) as `a·|q|² + g·q + h = 0` with `q = p − origin`.
    ///
    /// From `|q' − c|² = R²` around the chord midpoint, multiplied by β so that nothing is
    /// divided by β: `β(|q'|² − L²/4) − ((1 − β²)/2)·cross(d, q') = 0`. At β = 0 it is the line.
    fn cycle(&self, origin: Point) -> Cycle {
        let b = self.bulge;
        let d = self.chord();
        let m = self.start.midpoint(self.end) - origin;
        let k = 0.5 * (1.0 - b * b);
        let l2 = d.norm_squared();
        let normal = d.rotated_quarter(); // cross(d, q) = normal · q
        Cycle {
            a: b,
            g: m * (-2.0 * b) - normal * k,
            h: b * (m.norm_squared() - 0.25 * l2) + k * d.cross(m),
        }
    }

    /// The arc-length parameter of `p` if it lies on the span within `tolerance`.
    fn locate(&self, p: Point, tolerance: f64) -> Option<f64> {
        if self.start.distance(p) <= tolerance {
            return Some(0.0);
        }
        if self.end.distance(p) <= tolerance {
            return Some(1.0);
        }
        let t = self.parameter_of(p);
        if !(-1e-9..=1.0 + 1e-9).contains(&t) {
            return None;
        }
        let t = t.clamp(0.0, 1.0);
        (self.point_at(t).distance(p) <= tolerance).then_some(t)
    }

    /// Tolerance for deciding that a computed point lies on both spans: relative to the size
    /// and position of the pair, so that it survives the rounding of the cycle coefficients.
    fn pair_tolerance(&self, other: &Span) -> f64 {
        let magnitude = [self.start, self.end, other.start, other.end]
            .iter()
            .map(|p| p.x.abs().max(p.y.abs()))
            .fold(0.0, f64::max);
        1e-9 * (1.0 + magnitude + self.chord_length() + other.chord_length())
    }

    /// All points where this span meets `other` (at most two, except for overlapping pieces of
    /// the same line or circle, where the overlap's end points are reported).
    pub fn intersections(&self, other: &Span) -> Vec<SpanIntersection> {
        let tolerance = self.pair_tolerance(other);
        if !tolerance.is_finite()
            || !self
                .bounding_box()
                .expanded(tolerance)
                .intersects(&other.bounding_box())
        {
            return Vec::new();
        }
        let mut candidates: Vec<Point> = Vec::new();
        let zero_self = self.chord().norm_squared() == 0.0;
        let zero_other = other.chord().norm_squared() == 0.0;
        if zero_self || zero_other {
            candidates.push(if zero_self { self.start } else { other.start });
        } else if self.is_line() && other.is_line() {
            candidates.extend(segment_segment(self, other, tolerance));
        } else {
            let origin = self.start.midpoint(self.end);
            let c1 = self.cycle(origin);
            let c2 = other.cycle(origin);
            // Radical line: a₂·(cycle 1) − a₁·(cycle 2), linear in q.
            let normal = c1.g * c2.a - c2.g * c1.a;
            let offset = c2.a * c1.h - c1.a * c2.h;
            let scale = (c1.g * c2.a).norm() + (c2.g * c1.a).norm();
            if normal.norm() <= 1e-12 * scale {
                // Same centre: either disjoint circles or the same circle (overlap).
                candidates.extend([self.start, self.end, other.start, other.end]);
            } else {
                let n2 = normal.norm_squared();
                let q0 = normal * (-offset / n2);
                let dir = normal.rotated_quarter();
                let c = if c1.a.abs() >= c2.a.abs() { c1 } else { c2 };
                let roots = quadratic_roots(
                    c.a * dir.norm_squared(),
                    2.0 * c.a * q0.dot(dir) + c.g.dot(dir),
                    c.value(q0),
                );
                candidates.extend(roots.into_iter().map(|s| origin + q0 + dir * s));
            }
        }
        let mut found: Vec<SpanIntersection> = Vec::new();
        for point in candidates {
            let (Some(t_self), Some(t_other)) = (
                self.locate(point, tolerance),
                other.locate(point, tolerance),
            ) else {
                continue;
            };
            if found.iter().any(|f| f.point.distance(point) <= tolerance) {
                continue;
            }
            found.push(SpanIntersection {
                point,
                t_self,
                t_other,
            });
        }
        found.sort_by(|a, b| a.t_self.total_cmp(&b.t_self));
        found
    }

    /// Where the straight segment `a → b` meets this span.
    pub fn intersect_segment(&self, a: Point, b: Point) -> Vec<SpanIntersection> {
        self.intersections(&Span::line(a, b))
    }
}

/// Candidate meeting points of two straight segments: the crossing, or for collinear
/// overlapping segments all four end points (filtered by the caller).
fn segment_segment(s: &Span, o: &Span, tolerance: f64) -> Vec<Point> {
    let r = s.chord();
    let q = o.chord();
    let denom = r.cross(q);
    let w = o.start - s.start;
    if denom.abs() > 1e-12 * r.norm() * q.norm() {
        let t = w.cross(q) / denom;
        return vec![s.start + r * t];
    }
    // Parallel: collinear only if o.start is on s's line.
    if (r.cross(w)).abs() <= tolerance * r.norm() {
        vec![s.start, s.end, o.start, o.end]
    } else {
        Vec::new()
    }
}
