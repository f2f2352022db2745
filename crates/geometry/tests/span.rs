//! Unit tests of span maths: special bulges, near-straight arcs, intersections.

use std::f64::consts::{FRAC_PI_2, PI};

use cutroute_geometry::{Point, Span};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn p(x: f64, y: f64) -> Point {
    Point::new(x, y)
}

#[test]
fn semicircle_ccw_beta_one() {
    // From (1,0) to (-1,0) counter-clockwise: the upper half of the unit circle.
    let s = Span::new(p(1.0, 0.0), p(-1.0, 0.0), 1.0);
    assert!(close(s.length(), PI, 1e-12));
    assert!(close(s.radius(), 1.0, 1e-12));
    let c = s.centre().unwrap();
    assert!(c.distance(Point::ORIGIN) < 1e-12);
    assert!(s.midpoint().distance(p(0.0, 1.0)) < 1e-12);
    assert!(s.point_at(0.5).distance(p(0.0, 1.0)) < 1e-12);
    assert!(
        s.point_at(0.25).distance(p(
            FRAC_PI_2.cos() * 0.0 + (PI / 4.0).cos(),
            (PI / 4.0).sin()
        )) < 1e-12
    );
    // Segment area: half the disc; positive (β > 0).
    assert!(close(s.segment_area(), PI / 2.0, 1e-12));
    let b = s.bounding_box();
    assert!(b.min.distance(p(-1.0, 0.0)) < 1e-12 && b.max.distance(p(1.0, 1.0)) < 1e-12);
    assert!(s.tangent_at(0.0).distance(p(0.0, 1.0)) < 1e-12);
    assert!(s.tangent_at(0.5).distance(p(-1.0, 0.0)) < 1e-12);
}

#[test]
fn semicircle_cw_beta_minus_one() {
    // From (1,0) to (-1,0) clockwise: the lower half.
    let s = Span::new(p(1.0, 0.0), p(-1.0, 0.0), -1.0);
    assert!(close(s.length(), PI, 1e-12));
    assert!(s.point_at(0.5).distance(p(0.0, -1.0)) < 1e-12);
    assert!(close(s.segment_area(), -PI / 2.0, 1e-12));
    let b = s.bounding_box();
    assert!(b.min.distance(p(-1.0, -1.0)) < 1e-12 && b.max.distance(p(1.0, 0.0)) < 1e-12);
}

#[test]
fn more_than_half_circle() {
    // Three quarters of the unit circle, counter-clockwise from (1,0) to (0,-1).
    let beta = (3.0 * PI / 8.0).tan();
    let s = Span::new(p(1.0, 0.0), p(0.0, -1.0), beta);
    assert!(close(s.sweep(), 1.5 * PI, 1e-12));
    assert!(close(s.radius(), 1.0, 1e-12));
    assert!(s.centre().unwrap().distance(Point::ORIGIN) < 1e-12);
    assert!(close(s.length(), 1.5 * PI, 1e-12));
    assert!(s.point_at(1.0 / 3.0).distance(p(0.0, 1.0)) < 1e-12);
    assert!(s.point_at(2.0 / 3.0).distance(p(-1.0, 0.0)) < 1e-12);
    let b = s.bounding_box();
    assert!(b.min.distance(p(-1.0, -1.0)) < 1e-12 && b.max.distance(p(1.0, 1.0)) < 1e-12);
    // Area between chord and arc: 3/4 disc + the triangle (O, A, Z) of area 1/2.
    assert!(close(s.segment_area(), 0.75 * PI + 0.5, 1e-12));
    // The nearest point to a point beyond the gap is an end.
    let n = s.nearest_point(p(2.0, -2.0));
    assert!(n.t == 0.0 || n.t == 1.0);
    let n = s.nearest_point(p(-3.0, 0.0));
    assert!(n.point.distance(p(-1.0, 0.0)) < 1e-12 && close(n.t, 2.0 / 3.0, 1e-12));
    assert!(close(s.parameter_of(p(0.0, 1.0)), 1.0 / 3.0, 1e-12));
}

#[test]
fn near_straight_arcs_are_stable() {
    let a = p(0.0, 0.0);
    let z = p(1000.0, 0.0);
    for &beta in &[1e-3, 1e-5, 1e-8, 1e-12, 1e-15, -1e-9] {
        let s = Span::new(a, z, beta);
        // Arc length ≈ L(1 + 2/3 β²), area ≈ β/3·L².
        assert!(
            close(s.length(), 1000.0 * (1.0 + 2.0 / 3.0 * beta * beta), 1e-9),
            "{beta}"
        );
        assert!(
            close(
                s.segment_area(),
                beta / 3.0 * 1e6 * (1.0 + beta * beta / 5.0),
                1e-9
            ),
            "{beta}"
        );
        // The zenith is L·β/2 off the chord, to the right for β > 0.
        let m = s.point_at(0.5);
        assert!(m.distance(p(500.0, -500.0 * beta)) < 1e-9, "{beta}: {m:?}");
        for q in [
            p(300.0, 10.0),
            p(300.0, -10.0),
            p(-5.0, 1.0),
            p(700.0, 1e-7),
        ] {
            let n = s.nearest_point(q);
            let sampled = (0..=20_000)
                .map(|k| s.point_at(k as f64 / 20_000.0).distance(q))
                .fold(f64::INFINITY, f64::min);
            assert!(
                n.distance <= sampled + 1e-9 && n.distance >= sampled - 1e-3,
                "{beta}: {n:?} vs {sampled}"
            );
            assert!(close(s.point_at(n.t).distance(q), n.distance, 1e-9));
        }
        let (l, r) = s.split_at(0.3);
        assert!(l.end.distance(s.point_at(0.3)) < 1e-12);
        assert!(close(l.length() + r.length(), s.length(), 1e-9));
        let x = s.intersect_segment(p(250.0, -5.0), p(250.0, 5.0));
        assert_eq!(x.len(), 1, "{beta}");
        assert!(
            close(x[0].point.x, 250.0, 1e-9) && close(x[0].t_self, 0.25, 1e-6),
            "{beta}: {x:?}"
        );
        assert!(
            s.point_at(x[0].t_self).distance(x[0].point) < 1e-9,
            "{beta}: {x:?}"
        );
        assert!(s.bounding_box().max.x == 1000.0);
    }
    let line = Span::line(a, z);
    assert_eq!(line.length(), 1000.0);
    assert_eq!(line.segment_area(), 0.0);
    assert!(line.centre().is_none());
    assert!(line.radius().is_infinite());
}

#[test]
fn quarter_circle_through_three_points() {
    let s =
        Span::through_points(p(1.0, 0.0), p(0.5f64.sqrt(), 0.5f64.sqrt()), p(0.0, 1.0)).unwrap();
    assert!(close(s.bulge, 2f64.sqrt() - 1.0, 1e-12));
    let s = Span::through_points(p(-1.0, 0.0), p(0.0, -1.0), p(1.0, 0.0)).unwrap();
    assert!(close(s.bulge, 1.0, 1e-12));
    assert!(Span::through_points(p(0.0, 0.0), p(2.0, 0.0), p(1.0, 0.0)).is_none());
    assert_eq!(
        Span::through_points(p(0.0, 0.0), p(0.5, 0.0), p(1.0, 0.0))
            .unwrap()
            .bulge,
        0.0
    );
}

#[test]
fn intersections_of_arcs_and_lines() {
    let upper = Span::new(p(1.0, 0.0), p(-1.0, 0.0), 1.0);
    // A vertical line through x = 0.5 meets the upper semicircle once.
    let x = upper.intersect_segment(p(0.5, -2.0), p(0.5, 2.0));
    assert_eq!(x.len(), 1);
    assert!(x[0].point.distance(p(0.5, 0.75f64.sqrt())) < 1e-12);
    assert!(close(x[0].t_other, (2.0 + 0.75f64.sqrt()) / 4.0, 1e-12));
    // A horizontal line at y = 0.5 meets it twice.
    assert_eq!(upper.intersect_segment(p(-2.0, 0.5), p(2.0, 0.5)).len(), 2);
    // Circle of radius 1 around (1, 0), upper half: meets at (0.5, √0.75).
    let other = Span::new(p(2.0, 0.0), p(0.0, 0.0), 1.0);
    let x = upper.intersections(&other);
    assert_eq!(x.len(), 1, "{x:?}"); // (0.5, √0.75); the lower crossing is on neither half
    let lower = Span::new(p(1.0, 0.0), p(-1.0, 0.0), -1.0);
    // Same circle, other half: meet only at both ends.
    let x = upper.intersections(&lower);
    assert_eq!(x.len(), 2, "{x:?}");
    // Tangent line touches once.
    let x = upper.intersect_segment(p(-2.0, 1.0), p(2.0, 1.0));
    assert_eq!(x.len(), 1, "{x:?}");
    assert!(x[0].point.distance(p(0.0, 1.0)) < 1e-6);
    // Disjoint.
    assert!(upper
        .intersect_segment(p(-2.0, 1.5), p(2.0, 1.5))
        .is_empty());
    // Crossing segments.
    let x = Span::line(p(0.0, 0.0), p(2.0, 2.0)).intersect_segment(p(0.0, 2.0), p(2.0, 0.0));
    assert_eq!(x.len(), 1);
    assert!(x[0].point.distance(p(1.0, 1.0)) < 1e-12);
    // Collinear overlap reports the overlap's ends.
    let x = Span::line(p(0.0, 0.0), p(2.0, 0.0)).intersect_segment(p(1.0, 0.0), p(3.0, 0.0));
    assert_eq!(x.len(), 2);
}

#[test]
fn nan_does_not_panic() {
    let s = Span::new(p(f64::NAN, 0.0), p(1.0, 1.0), 0.5);
    let _ = s.length();
    let _ = s.bounding_box();
    let _ = s.nearest_point(p(0.0, 0.0));
    let _ = s.intersections(&Span::line(p(0.0, 0.0), p(1.0, 0.0)));
    let _ = s.split_at(f64::NAN);
    let s = Span::new(p(0.0, 0.0), p(1.0, 1.0), f64::NAN);
    let _ = s.nearest_point(p(0.0, 0.0));
    let _ = s.bounding_box();
    let _ = Span::new(p(0.0, 0.0), p(1.0, 1.0), 0.3).nearest_point(p(f64::NAN, 0.0));
}

#[test]
fn points_just_past_the_start_of_a_wide_arc_keep_their_parameter() {
    // A half circle of radius 100 (Nest03, part 197) and the point of it δ = 1.0155e-8 rad past
    // its start: x moves by 100·δ ≈ 1e-6, y by 50·δ² ≈ 5e-15, below the ulp of 1300. The point
    // is on the arc to within rounding, so its distance must be ~0, not its 1e-6 offset from A.
    let s = Span::new(
        p(1100.0002, 1300.0),
        p(1100.0002, 1500.0),
        -0.9999999999999999,
    );
    let delta: f64 = 1.0155e-8;
    let q = p(
        1100.0002 - 100.0 * delta.sin(),
        1400.0 - 100.0 * delta.cos(),
    );
    assert_eq!(
        q.y, 1300.0,
        "the offset across the tangent is lost to rounding"
    );
    let t = s.parameter_of(q);
    assert!(close(t, delta / PI, 1e-12), "t = {t}");
    let n = s.nearest_point(q);
    assert!(n.distance < 1e-9, "distance {}", n.distance);
    // Points of the circle outside the arc still map outside [0, 1], on their own side: a
    // point δ before A just below 0 (not a full turn away, past Z).
    let before = p(1100.0002 + 100.0 * delta.sin(), 1300.0);
    let t = s.parameter_of(before);
    assert!(t < 0.0 && t > -1e-6, "t = {t}");
}

#[test]
fn every_point_of_an_arc_maps_to_its_own_parameter_even_at_the_ends() {
    // Nest02: an arc of 144° traversed clockwise (common edge of a hole and a round part); its
    // start once mapped to t = 2.5 because the angle from A came out as +1e-16 instead of 0.
    let s = Span::new(
        p(2219.9999928000047, 109.9999903999997),
        p(2249.99998, 200.0),
        -0.7207593416156713,
    );
    assert!(s.parameter_of(s.start).abs() < 1e-12);
    assert!((s.parameter_of(s.end) - 1.0).abs() < 1e-12);
    for k in 0..=64 {
        let t = k as f64 / 64.0;
        for sp in [s, s.reversed(), Span::new(s.start, s.end, 1.0 / s.bulge)] {
            assert!(
                (sp.parameter_of(sp.point_at(t)) - t).abs() < 1e-9,
                "{sp:?} at {t}"
            );
        }
    }
}

#[test]
fn half_bulges_recombine() {
    let b = 0.7;
    let (first, second) = Span::new(p(0.0, 0.0), p(3.0, 1.0), b).halved();
    for h in [first.bulge, second.bulge] {
        assert!((2.0 * h / (1.0 - h * h) - b).abs() < 1e-12);
    }
}

/// f = |a m| + |m b| has two local minima on this arc; the better of the sampled search's
/// brackets held the other one, 192.57 against a least value below 191.62 (a proptest case).
#[test]
fn the_detour_minimum_is_found_when_the_arc_holds_two_local_minima() {
    let arc = Span::new(
        Point::new(64.33468337245407, 49.3502017348437),
        Point::new(-51.647170579616684, -5.068487445678068),
        1.193528076114086,
    );
    let (a, b) = (
        Point::new(-29.51977187672266, 79.8792481752956),
        Point::new(5.96412638157747, -92.60131367470302),
    );
    let f = |t: f64| a.distance(arc.point_at(t)) + arc.point_at(t).distance(b);
    let sampled = (0..=100_000)
        .map(|k| f(k as f64 / 100_000.0))
        .fold(f64::INFINITY, f64::min);
    let (t, value) = arc.detour_minimum(a, Some(b));
    assert!((f(t) - value).abs() < 1e-9);
    assert!(value <= sampled + 1e-9, "{value} against {sampled}");
    assert!(value < 191.62, "{value}");
}
