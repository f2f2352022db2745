//! Free-form curves of CAD files (NURBS splines, elliptical arcs) and their approximation by
//! circular arcs within a tolerance.
//!
//! The approximation splits the curve at its knots (where it may lose smoothness) and then
//! bisects each piece until the circular arc through the piece's start, middle and end points
//! stays within the tolerance of the curve at 15 evenly spread samples. The result is a G0 chain
//! of arcs (straight spans where the three points are collinear); far fewer spans than chords
//! would need for the same tolerance, which keeps the route optimizer's input small.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{Point, Span};

/// Highest spline degree accepted (AutoCAD allows up to 11); each evaluation costs degree².
pub(crate) const MAX_SPLINE_DEGREE: usize = 11;
/// Bisection depth limit per piece: 2^-40 of a knot interval is far below any tolerance.
const MAX_DEPTH: u32 = 40;
/// Samples checked against each candidate arc.
const CHECK_SAMPLES: usize = 16;

/// Why a curve could not be approximated.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ApproxFailure {
    /// More spans would be produced than the caller's budget allows.
    BudgetExceeded,
}

/// A NURBS curve in the plane, validated on construction.
#[derive(Debug, Clone)]
pub(crate) struct Nurbs {
    degree: usize,
    knots: Vec<f64>,
    /// Control points in homogeneous form `(w·x, w·y, w)`.
    control: Vec<[f64; 3]>,
}

impl Nurbs {
    /// Checks counts, ordering and weights; the message says what is wrong.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: &[Point],
        weights: &[f64],
    ) -> Result<Self, String> {
        if degree == 0 || degree > MAX_SPLINE_DEGREE {
            return Err(format!(
                "degree {degree} is outside 1..={MAX_SPLINE_DEGREE}"
            ));
        }
        if points.len() < degree + 1 {
            return Err(format!(
                "{} control points are too few for degree {degree}",
                points.len()
            ));
        }
        if knots.len() != points.len() + degree + 1 {
            return Err(format!(
                "{} knots do not match {} control points of degree {degree} (expected {})",
                knots.len(),
                points.len(),
                points.len() + degree + 1
            ));
        }
        if knots.windows(2).any(|w| w[1] < w[0]) {
            return Err("knots are not in non-decreasing order".into());
        }
        if !weights.is_empty() && weights.len() != points.len() {
            return Err(format!(
                "{} weights do not match {} control points",
                weights.len(),
                points.len()
            ));
        }
        // Values are finite (the readers check), so `<= 0` catches every non-positive weight.
        if weights.iter().any(|&w| w <= 0.0) {
            return Err("a weight is not positive".into());
        }
        let n = points.len();
        if knots[degree] >= knots[n] {
            return Err("the knot vector spans an empty parameter range".into());
        }
        let control = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let w = weights.get(i).copied().unwrap_or(1.0);
                [p.x * w, p.y * w, w]
            })
            .collect();
        Ok(Self {
            degree,
            knots,
            control,
        })
    }

    /// Parameter range over which the curve is defined.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.control.len()])
    }

    /// Distinct knots strictly inside the domain: the curve is only piecewise smooth across them.
    pub fn breaks(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out: Vec<f64> = Vec::new();
        for &k in &self.knots {
            if k > a && k < b && out.last().is_none_or(|&l| k > l) {
                out.push(k);
            }
        }
        out
    }

    /// The curve point at `t` by de Boor's algorithm (in homogeneous coordinates).
    pub fn point_at(&self, t: f64) -> Point {
        let p = self.degree;
        let n = self.control.len();
        let (a, b) = self.domain();
        let t = t.clamp(a, b);
        // The knot span k with knots[k] ≤ t < knots[k+1], kept inside [p, n-1].
        let k = (self.knots.partition_point(|&u| u <= t).saturating_sub(1)).clamp(p, n - 1);
        // On the stack: this runs for every sample of every span of every spline.
        let mut d = [[0.0; 3]; MAX_SPLINE_DEGREE + 1];
        d[..=p].copy_from_slice(&self.control[k - p..=k]);
        for r in 1..=p {
            for j in (r..=p).rev() {
                let lo = self.knots[j + k - p];
                let hi = self.knots[j + 1 + k - r];
                let alpha = if hi > lo { (t - lo) / (hi - lo) } else { 0.0 };
                let previous = d[j - 1];
                for (value, prev) in d[j].iter_mut().zip(previous) {
                    *value = (1.0 - alpha) * prev + alpha * *value;
                }
            }
        }
        let [x, y, w] = d[p];
        Point::new(x / w, y / w)
    }
}

/// An elliptical arc `center + u·cos t + v·sin t` for `t` from `t0` to `t1` (either direction).
///
/// Circular arcs are the special case `|u| = |v|`, `u ⊥ v`; an affine image of either is again
/// of this form, which is how block inserts with uneven scales are handled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EllipticArc {
    pub center: Point,
    pub u: Point,
    pub v: Point,
    pub t0: f64,
    pub t1: f64,
}

impl EllipticArc {
    pub fn point_at(&self, t: f64) -> Point {
        let (s, c) = t.sin_cos_libm();
        Point::new(
            self.center.x + self.u.x * c + self.v.x * s,
            self.center.y + self.u.y * c + self.v.y * s,
        )
    }

    /// The arc as exact circular spans when it is circular, `None` otherwise.
    pub fn as_circular_spans(&self) -> Option<Vec<Span>> {
        let ru = self.u.x.hypot_libm(self.u.y);
        let rv = self.v.x.hypot_libm(self.v.y);
        let dot = self.u.x * self.v.x + self.u.y * self.v.y;
        let scale = ru.max(rv);
        if scale == 0.0 || (ru - rv).abs() > 1e-9 * scale || dot.abs() > 1e-9 * scale * scale {
            return None;
        }
        // Increasing t runs counter-clockwise when v is u turned left.
        let orientation = (self.u.x * self.v.y - self.u.y * self.v.x).signum();
        let sweep = (self.t1 - self.t0) * orientation;
        // At most a half turn per span keeps |bulge| ≤ 1, far from the ill-conditioned ∞.
        let pieces = ((sweep.abs() / std::f64::consts::PI).ceil() as usize).max(1);
        let bulge = (sweep / pieces as f64 / 4.0).tan_libm();
        Some(
            (0..pieces)
                .map(|i| {
                    let ta = self.t0 + (self.t1 - self.t0) * i as f64 / pieces as f64;
                    let tb = self.t0 + (self.t1 - self.t0) * (i + 1) as f64 / pieces as f64;
                    Span::new(self.point_at(ta), self.point_at(tb), bulge)
                })
                .collect(),
        )
    }
}

/// Below this |bulge| a span is taken as straight: the arc through three points of a spline's
/// straight stretch stays a line (no G2/G3 of astronomic radius, no bulge of rounding noise),
/// and a DXF arc this flat is not turned into an ellipse around its far-away centre.
pub(crate) const STRAIGHT_BULGE: f64 = 1e-12;

/// The circular arc through `a`, `m`, `b` (in that order) as a span from `a` to `b`; a straight
/// span when the three points are (nearly) collinear or `m` repeats an end.
pub(crate) fn arc_through(a: Point, m: Point, b: Point) -> Span {
    Span::through_points(a, m, b)
        .filter(|s| s.bulge.abs() >= STRAIGHT_BULGE)
        .unwrap_or(Span::line(a, b))
}

/// The distance from points to one span, with the span's centre and radius worked out once:
/// the approximation measures 15 samples against every candidate arc, and the general
/// [`Span::distance_to`] spends trigonometry on each.
enum SpanDistance {
    /// An arc of less than a half turn: its centre, radius, ends and turning sense.
    Arc {
        span: Span,
        centre: Point,
        radius: f64,
        sense: f64,
    },
    /// A line, or an arc this shortcut does not cover.
    General(Span),
}

impl SpanDistance {
    fn new(span: &Span) -> Self {
        match span.centre() {
            Some(centre) if span.bulge != 0.0 && span.bulge.abs() < 1.0 => Self::Arc {
                span: *span,
                centre,
                radius: span.radius(),
                sense: span.bulge.signum(),
            },
            _ => Self::General(*span),
        }
    }

    fn to(&self, p: Point) -> f64 {
        match self {
            Self::General(span) => span.distance_to(p),
            Self::Arc {
                span,
                centre,
                radius,
                sense,
            } => {
                let cross = |u: Point, v: Point| {
                    (u.x - centre.x) * (v.y - centre.y) - (u.y - centre.y) * (v.x - centre.x)
                };
                // Within the arc's sector (less than a half turn, so two half-planes bound it)
                // the nearest point of the arc is on the ray from the centre; outside, an end.
                if cross(span.start, p) * sense >= 0.0 && cross(p, span.end) * sense >= 0.0 {
                    (p.distance(*centre) - radius).abs()
                } else {
                    p.distance(span.start).min(p.distance(span.end))
                }
            }
        }
    }
}

/// Approximates `curve` on `[t0, t1]` by arcs within `tolerance`, splitting first at `breaks`.
///
/// `budget` is the number of spans the caller still allows; it is decreased by the spans made.
pub(crate) fn approximate(
    curve: &dyn Fn(f64) -> Point,
    t0: f64,
    t1: f64,
    breaks: &[f64],
    tolerance: f64,
    budget: &mut usize,
) -> Result<Vec<Span>, ApproxFailure> {
    let mut cuts: Vec<f64> = Vec::with_capacity(breaks.len() + 2);
    cuts.push(t0);
    cuts.extend(breaks.iter().copied().filter(|&k| k > t0 && k < t1));
    cuts.push(t1);
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        // Bisection without recursion: `a` is where the next span starts, `pending` holds the
        // right ends still to reach (innermost last), so spans come out in curve order.
        let mut a = w[0];
        let mut pending: Vec<(f64, u32)> = vec![(w[1], 0)];
        while let Some(&(b, depth)) = pending.last() {
            let m = (a + b) / 2.0;
            let pa = curve(a);
            let pb = curve(b);
            let span = arc_through(pa, curve(m), pb);
            let distance = SpanDistance::new(&span);
            let fits = depth >= MAX_DEPTH
                || (1..CHECK_SAMPLES).all(|k| {
                    let t = a + (b - a) * k as f64 / CHECK_SAMPLES as f64;
                    distance.to(curve(t)) <= tolerance
                });
            if fits {
                if *budget == 0 {
                    return Err(ApproxFailure::BudgetExceeded);
                }
                *budget -= 1;
                out.push(span);
                pending.pop();
                a = b;
            } else {
                pending.push((m, depth + 1));
            }
        }
    }
    Ok(out)
}

/// An elliptic arc (already in world coordinates) as arcs: exact circular spans when it is
/// circular, otherwise the approximation within `tolerance`, split in eighths of its sweep so
/// each piece is free of inflections in curvature direction.
///
/// `budget` is the number of spans the caller still allows; only the approximation draws on it
/// (exact spans are at most a handful per arc).
pub(crate) fn elliptic_spans(
    arc: &EllipticArc,
    tolerance: f64,
    budget: &mut usize,
) -> Result<Vec<Span>, ApproxFailure> {
    if let Some(spans) = arc.as_circular_spans() {
        return Ok(spans);
    }
    approximate_elliptic(arc, tolerance, budget)
}

/// The approximation half of [`elliptic_spans`], also used for arcs that an uneven scale made
/// elliptic even though their circular form is known.
pub(crate) fn approximate_elliptic(
    arc: &EllipticArc,
    tolerance: f64,
    budget: &mut usize,
) -> Result<Vec<Span>, ApproxFailure> {
    let breaks: Vec<f64> = (1..8)
        .map(|k| arc.t0 + (arc.t1 - arc.t0) * k as f64 / 8.0)
        .collect();
    approximate(
        &|t| arc.point_at(t),
        arc.t0,
        arc.t1,
        &breaks,
        tolerance,
        budget,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_through_three_points_of_a_circle() {
        let s = arc_through(
            Point::new(1.0, 0.0),
            Point::new(0.0, 1.0),
            Point::new(-1.0, 0.0),
        );
        assert!((s.bulge - 1.0).abs() < 1e-12);
        let s = arc_through(
            Point::new(-1.0, 0.0),
            Point::new(0.0, 1.0),
            Point::new(1.0, 0.0),
        );
        assert!((s.bulge + 1.0).abs() < 1e-12);
        let s = arc_through(
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(2.0, 0.0),
        );
        assert_eq!(s.bulge, 0.0);
    }

    #[test]
    fn clamped_quadratic_bezier_is_a_parabola() {
        let pts = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 2.0),
            Point::new(2.0, 0.0),
        ];
        let n = Nurbs::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], &pts, &[]).unwrap();
        let p = n.point_at(0.5);
        assert!((p.x - 1.0).abs() < 1e-12 && (p.y - 1.0).abs() < 1e-12);
        assert_eq!(n.point_at(1.0), Point::new(2.0, 0.0));
    }

    #[test]
    fn rational_quadratic_is_an_exact_quarter_circle() {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let pts = [
            Point::new(1.0, 0.0),
            Point::new(1.0, 1.0),
            Point::new(0.0, 1.0),
        ];
        let n = Nurbs::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], &pts, &[1.0, w, 1.0]).unwrap();
        for k in 0..=10 {
            let p = n.point_at(k as f64 / 10.0);
            assert!((p.x.hypot_libm(p.y) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn invalid_splines_are_refused() {
        let pts = [Point::new(0.0, 0.0), Point::new(1.0, 0.0)];
        assert!(Nurbs::new(0, vec![0.0, 1.0, 2.0], &pts, &[]).is_err());
        assert!(Nurbs::new(1, vec![0.0, 0.0, 1.0], &pts, &[]).is_err());
        assert!(Nurbs::new(1, vec![0.0, 1.0, 0.5, 1.0], &pts, &[]).is_err());
        assert!(Nurbs::new(1, vec![0.0, 0.0, 1.0, 1.0], &pts, &[1.0, -1.0]).is_err());
        assert!(Nurbs::new(1, vec![1.0, 1.0, 1.0, 1.0], &pts, &[]).is_err());
    }

    #[test]
    fn approximation_of_an_ellipse_stays_within_tolerance() {
        let e = EllipticArc {
            center: Point::new(5.0, -3.0),
            u: Point::new(100.0, 20.0),
            v: Point::new(-6.0, 30.0),
            t0: 0.3,
            t1: 5.0,
        };
        let tol = 0.01;
        let mut budget = 10_000;
        let spans = approximate(&|t| e.point_at(t), e.t0, e.t1, &[], tol, &mut budget).unwrap();
        assert!(spans.len() < 200, "{} spans", spans.len());
        for i in 0..=2000 {
            let t = e.t0 + (e.t1 - e.t0) * i as f64 / 2000.0;
            let p = e.point_at(t);
            let d = spans
                .iter()
                .map(|s| s.distance_to(p))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= tol * 1.01, "deviation {d} at t = {t}");
        }
    }

    #[test]
    fn the_shortcut_distance_to_an_arc_is_the_general_one() {
        let mut seed = 7u64;
        let mut random = move || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0
        };
        for _ in 0..200 {
            let a = Point::new(random(), random());
            let b = Point::new(random(), random());
            let span = Span::new(a, b, random() / 10.5);
            let fast = SpanDistance::new(&span);
            assert!(matches!(fast, SpanDistance::Arc { .. }) || span.bulge == 0.0);
            for _ in 0..20 {
                let p = Point::new(random(), random());
                let (f, g) = (fast.to(p), span.distance_to(p));
                assert!(
                    (f - g).abs() <= 1e-9 * (1.0 + g),
                    "{span:?} {p:?}: {f} vs {g}"
                );
            }
        }
    }

    #[test]
    fn budget_stops_runaway_approximation() {
        let e = EllipticArc {
            center: Point::new(0.0, 0.0),
            u: Point::new(1e6, 0.0),
            v: Point::new(0.0, 1.0),
            t0: 0.0,
            t1: 6.0,
        };
        let mut budget = 5;
        let r = approximate(&|t| e.point_at(t), e.t0, e.t1, &[], 1e-6, &mut budget);
        assert_eq!(r, Err(ApproxFailure::BudgetExceeded));
    }
}
