//! Unit tests of contour operations.

use std::f64::consts::PI;

use cutroute_geometry::{
    ClosureError, Contour, ContourError, ContourPosition, Part, Point, Transform, Vertex,
};

fn p(x: f64, y: f64) -> Point {
    Point::new(x, y)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// 10 × 10 square, clockwise.
fn square_cw() -> Contour {
    Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(0.0, 10.0),
        Vertex::line(10.0, 10.0),
        Vertex::line(10.0, 0.0),
    ])
}

/// A "stadium": 20 × 10 rectangle with semicircular ends, counter-clockwise.
fn stadium_ccw() -> Contour {
    Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::arc(20.0, 0.0, 1.0),
        Vertex::line(20.0, 10.0),
        Vertex::arc(0.0, 10.0, 1.0),
    ])
}

#[test]
fn close_points_drops_the_repeated_point() {
    let raw = [
        Vertex::arc(0.0, 0.0, 0.0),
        Vertex::arc(1.0, 0.0, 1.0),
        Vertex::arc(0.0, 0.0, 7.0),
    ];
    let c = Contour::close_points(&raw, 0.0).unwrap();
    assert_eq!(c.vertices.len(), 2);
    assert_eq!(c.vertices[1].bulge, 1.0);
    let open = [
        Vertex::line(0.0, 0.0),
        Vertex::line(1.0, 0.0),
        Vertex::line(1.0, 1.0),
        Vertex::line(0.0, 0.002),
    ];
    match Contour::close_points(&open, 1e-3) {
        Err(ClosureError::Open { gap, .. }) => assert!(close(gap, 0.002, 1e-12)),
        other => panic!("{other:?}"),
    }
    let msg = Contour::close_points(&open, 1e-3).unwrap_err().to_string();
    assert!(msg.contains("open"), "{msg}");
    assert!(Contour::close_points(&open, 1e-2).is_ok());
    assert!(matches!(
        Contour::close_points(&[], 1.0),
        Err(ClosureError::TooFewPoints { .. })
    ));
    assert!(matches!(
        Contour::close_points(&[Vertex::line(0.0, 0.0), Vertex::line(0.0, 0.0)], 1.0),
        Err(ClosureError::TooFewPoints { .. })
    ));
    let nan = [
        Vertex::line(0.0, 0.0),
        Vertex::line(f64::NAN, 0.0),
        Vertex::line(0.0, 0.0),
    ];
    assert!(matches!(
        Contour::close_points(&nan, 1.0),
        Err(ClosureError::NonFinite { index: 1 })
    ));
}

#[test]
fn orientation_area_perimeter() {
    let sq = square_cw();
    assert!(sq.is_clockwise());
    assert_eq!(sq.signed_area(), -100.0);
    assert_eq!(sq.perimeter(), 40.0);
    let st = stadium_ccw();
    assert!(!st.is_clockwise());
    assert!(close(st.signed_area(), 200.0 + PI * 25.0, 1e-9));
    assert!(close(st.perimeter(), 40.0 + 10.0 * PI, 1e-9));
    let b = st.bounding_box();
    assert!(b.min.distance(p(-5.0, 0.0)) < 1e-12 && b.max.distance(p(25.0, 10.0)) < 1e-12);
    let disc = Contour::circle(p(3.0, 4.0), 2.0, true);
    assert!(disc.is_clockwise());
    assert!(close(disc.signed_area(), -4.0 * PI, 1e-12));
    assert_eq!(disc.arc_count(), 2);
}

#[test]
fn reverse_follows_the_dbs_rule() {
    let st = stadium_ccw();
    let r = st.reversed();
    // Points reversed; new bulge = −(bulge of the point preceding it originally).
    let expected = vec![
        Vertex::arc(0.0, 10.0, -0.0),
        Vertex::arc(20.0, 10.0, -1.0),
        Vertex::arc(20.0, 0.0, -0.0),
        Vertex::arc(0.0, 0.0, -1.0),
    ];
    assert_eq!(r.vertices, expected);
    assert!(r.is_clockwise());
    assert!(close(r.signed_area(), -st.signed_area(), 1e-9));
    assert_eq!(r.reversed(), st);
}

#[test]
fn reflection_flips_bulges_and_orientation() {
    let st = stadium_ccw();
    let m = st.transformed(&Transform::mirror_x());
    assert!(m.is_clockwise());
    assert!(m
        .vertices
        .iter()
        .zip(&st.vertices)
        .all(|(a, b)| a.bulge == -b.bulge));
    assert!(close(m.signed_area(), -st.signed_area(), 1e-9));
    let rot = st.transformed(&Transform::rotation(0.7).then(&Transform::translation(5.0, -3.0)));
    assert!(close(rot.signed_area(), st.signed_area(), 1e-9));
    let dbs = Transform::from_dbs(0.0, 1.0, -1.0, 0.0, 10.0, 0.0); // 90° rotation + shift
    assert!(dbs.apply(p(1.0, 0.0)).distance(p(10.0, 1.0)) < 1e-12);
}

#[test]
fn point_in_contour_with_arcs() {
    let st = stadium_ccw();
    assert!(st.contains(p(10.0, 5.0)));
    assert!(
        st.contains(p(-4.0, 5.0)),
        "inside the left cap, outside the chord polygon"
    );
    assert!(st.contains(p(24.0, 5.0)));
    assert!(
        !st.contains(p(-4.0, 9.0)),
        "inside the box, outside the cap"
    );
    assert!(!st.contains(p(30.0, 5.0)));
    assert_eq!(st.winding_number(p(10.0, 5.0)), 1);
    assert_eq!(st.reversed().winding_number(p(-4.0, 5.0)), -1);
    let disc = Contour::circle(p(0.0, 0.0), 1.0, true);
    assert!(
        disc.contains(p(0.0, 0.99))
            && !disc.contains(p(0.0, 1.01))
            && !disc.contains(p(0.72, 0.72))
    );
    assert!(!disc.contains(p(f64::NAN, 0.0)));
    // Points on the chords of the two semicircles (the diameter) are inside.
    for x in [-0.9, -0.5, 0.0, 0.5, 0.9] {
        assert!(disc.contains(p(x, 0.0)), "{x}");
        assert!(disc.contains(p(0.0, x)), "{x}");
    }
    assert!(
        st.contains(p(0.0, 5.0)) && st.contains(p(20.0, 5.0)),
        "on the caps' chords"
    );
    assert!(
        !st.contains(p(-6.0, 0.0)) && !st.contains(p(-6.0, 5.0)) && !st.contains(p(26.0, 10.0))
    );
}

#[test]
fn nearest_point_and_length_parameterisation() {
    let st = stadium_ccw();
    let n = st.nearest_point(p(-10.0, 5.0)).unwrap();
    assert!(n.point.distance(p(-5.0, 5.0)) < 1e-12 && close(n.distance, 5.0, 1e-12));
    assert_eq!(n.position.span, 3);
    assert!(close(n.position.t, 0.5, 1e-12));
    let s = st.length_at(n.position);
    assert!(close(s, 20.0 + 5.0 * PI + 20.0 + 2.5 * PI, 1e-9));
    assert!(st.point_at_length(s).unwrap().distance(n.point) < 1e-9);
    assert!(
        st.point_at_length(s + st.perimeter())
            .unwrap()
            .distance(n.point)
            < 1e-9
    );
    assert!(
        st.point_at_length(-2.0)
            .unwrap()
            .distance(p(0.0, 0.0) + (p(-5.0, 5.0) - p(0.0, 0.0)) * 0.0)
            > 0.0
    );
    assert!(st.point_at_length(10.0).unwrap().distance(p(10.0, 0.0)) < 1e-12);
    assert_eq!(
        st.position_at_length(f64::NAN),
        Some(ContourPosition { span: 0, t: 0.0 })
    );
    assert!(Contour::default().point_at_length(1.0).is_none());
}

#[test]
fn self_intersections() {
    assert!(stadium_ccw().validate().is_ok());
    assert!(square_cw().first_self_intersection().is_none());
    assert!(Contour::circle(p(0.0, 0.0), 1.0, false).validate().is_ok());
    // Bow-tie: spans 0 and 2 cross at (5, 5).
    let bow = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(10.0, 10.0),
        Vertex::line(10.0, 0.0),
        Vertex::line(0.0, 10.0),
    ]);
    let x = bow.first_self_intersection().unwrap();
    assert_eq!((x.first_span, x.second_span), (0, 2));
    assert!(x.point.distance(p(5.0, 5.0)) < 1e-12);
    assert!(matches!(
        bow.validate(),
        Err(ContourError::SelfIntersecting {
            first_span: 0,
            second_span: 2,
            ..
        })
    ));
    // An arc that bulges across the opposite edge.
    let bad = Contour::new(vec![
        Vertex::arc(0.0, 0.0, -0.5),
        Vertex::line(10.0, 0.0),
        Vertex::line(10.0, 1.0),
        Vertex::line(0.0, 1.0),
    ]);
    let x = bad.first_self_intersection().unwrap();
    assert_eq!((x.first_span, x.second_span), (0, 2));
    // β = −2 makes a big arc round the outside of the thin rectangle: simple after all.
    let big = Contour::new(vec![
        Vertex::arc(0.0, 0.0, -2.0),
        Vertex::line(10.0, 0.0),
        Vertex::line(10.0, 1.0),
        Vertex::line(0.0, 1.0),
    ]);
    assert!(big.first_self_intersection().is_none());
    // A spike folding back on itself: adjacent collinear spans overlap.
    let spike = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(10.0, 0.0),
        Vertex::line(5.0, 0.0),
        Vertex::line(5.0, 5.0),
    ]);
    assert!(spike.first_self_intersection().is_some());
    assert!(matches!(
        Contour::new(vec![Vertex::line(0.0, 0.0)]).validate(),
        Err(ContourError::TooFewVertices { count: 1 })
    ));
    let dup = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(0.0, 0.0),
        Vertex::line(1.0, 1.0),
    ]);
    assert!(matches!(
        dup.validate(),
        Err(ContourError::ZeroLengthSpan { span: 0 })
    ));
}

#[test]
fn flattening_stays_within_tolerance() {
    let st = stadium_ccw();
    for tol in [1.0, 0.1, 0.01, 0.001] {
        let poly = st.flatten(tol);
        // Every polyline vertex is on the contour, and every chord midpoint within tol.
        for (i, &a) in poly.iter().enumerate() {
            let b = poly[(i + 1) % poly.len()];
            assert!(st.distance_to(a) < 1e-9);
            assert!(st.distance_to(a.midpoint(b)) <= tol + 1e-12, "tol {tol}");
        }
    }
    assert_eq!(square_cw().flatten(0.1).len(), 4);
    assert!(stadium_ccw().flatten(f64::NAN).len() <= 4 + 2 * 1024);
}

#[test]
fn tangent_arcs_are_not_self_intersections() {
    // Rounded rectangles (lines tangent to quarter arcs) far from the origin, rotated.
    let q = (PI / 8.0).tan();
    for k in 0..200 {
        let (w, h, r) = (
            10.0 + k as f64 * 7.3,
            5.0 + k as f64 * 3.1,
            0.5 + (k % 7) as f64,
        );
        let c = Contour::new(vec![
            Vertex::line(r, 0.0),
            Vertex::arc(w - r, 0.0, q),
            Vertex::line(w, r),
            Vertex::arc(w, h - r, q),
            Vertex::line(w - r, h),
            Vertex::arc(r, h, q),
            Vertex::line(0.0, h - r),
            Vertex::arc(0.0, r, q),
        ]);
        let t = Transform::rotation(k as f64 * 0.37).then(&Transform::translation(
            6000.0 - k as f64,
            2000.0 + k as f64,
        ));
        let c = c.transformed(&t);
        assert_eq!(c.validate(), Ok(()), "{k}");
        assert_eq!(c.reversed().validate(), Ok(()), "{k}");
    }
}

#[test]
fn nan_contours_do_not_panic() {
    let bad = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::arc(f64::NAN, 1.0, 0.5),
        Vertex::arc(1.0, 0.0, f64::NAN),
    ]);
    let _ = (
        bad.perimeter(),
        bad.signed_area(),
        bad.is_clockwise(),
        bad.bounding_box(),
    );
    let _ = (
        bad.contains(p(0.5, 0.5)),
        bad.nearest_point(p(0.0, 1.0)),
        bad.point_at_length(1.0),
    );
    let _ = (
        bad.first_self_intersection(),
        bad.flatten(0.1),
        bad.reversed(),
        bad.length_at(ContourPosition { span: 1, t: 0.5 }),
    );
    assert!(matches!(
        bad.validate(),
        Err(ContourError::NonFinite { index: 1 })
    ));
    let nest = cutroute_geometry::Nest {
        sheet: None,
        parts: vec![
            cutroute_geometry::Part {
                name: "bad".into(),
                contours: vec![bad],
            },
            cutroute_geometry::Part {
                name: "disc".into(),
                contours: vec![Contour::circle(p(0.0, 0.0), 5.0, true)],
            },
        ],
    };
    let forest = nest.containment_forest();
    assert_eq!(forest.roots().len(), 2);
    let _ = nest.bounding_box();
    let _ = nest.clone().normalize_orientation();
    let _ = cutroute_geometry::generate_nest(3, u64::MAX);
}

#[test]
fn segment_crossings_in_order() {
    let st = stadium_ccw();
    // A horizontal line through the middle crosses both caps.
    let x = st.segment_crossings(p(-10.0, 5.0), p(30.0, 5.0));
    assert_eq!(x.len(), 2);
    assert!(x[0].point.distance(p(-5.0, 5.0)) < 1e-12 && x[1].point.distance(p(25.0, 5.0)) < 1e-12);
    assert!(x[0].segment_t < x[1].segment_t);
    assert_eq!((x[0].position.span, x[1].position.span), (3, 1));
    // Through a vertex: reported once.
    let x = st.segment_crossings(p(0.0, -5.0), p(0.0, 5.0));
    assert_eq!(x.len(), 1, "{x:?}");
    assert!(x[0].point.distance(p(0.0, 0.0)) < 1e-12);
    // Along an edge: its ends.
    assert_eq!(st.segment_crossings(p(-1.0, 0.0), p(30.0, 0.0)).len(), 2);
    assert!(st
        .segment_crossings(p(100.0, 0.0), p(200.0, 0.0))
        .is_empty());
}

#[test]
fn closed_vertices_lose_repeats() {
    let raw = [
        Vertex::line(0.0, 0.0),
        Vertex::line(10.0, 0.0),
        Vertex::arc(10.0, 0.0, 0.5),
        Vertex::line(10.0, 10.0),
        Vertex::line(0.0, 10.0),
        Vertex::line(0.0, 0.0),
    ];
    let c = Contour::from_closed_vertices(&raw, 1e-9).unwrap();
    assert_eq!(
        c.vertices,
        vec![
            Vertex::line(0.0, 0.0),
            Vertex::arc(10.0, 0.0, 0.5),
            Vertex::line(10.0, 10.0),
            Vertex::line(0.0, 10.0)
        ]
    );
    assert_eq!(Contour::from_closed_vertices(&raw[..5], 1e-9).unwrap(), c);
    assert!(c.validate().is_ok());
    assert!(matches!(
        Contour::from_closed_vertices(&[Vertex::line(1.0, 1.0), Vertex::line(1.0, 1.0)], 0.0),
        Err(ClosureError::TooFewPoints { count: 1 })
    ));
}

#[test]
fn part_area_subtracts_holes_in_either_orientation() {
    let circle = |r: f64, bulge: f64| {
        Contour::new(vec![
            Vertex::arc(0.0, r, bulge),
            Vertex::arc(0.0, -r, bulge),
        ])
    };
    let ring = |hole_bulge| Part {
        name: "R".into(),
        contours: vec![circle(2.0, -1.0), circle(1.0, hole_bulge)],
    };
    let expected = PI * 3.0;
    assert!((ring(1.0).area() - expected).abs() < 1e-9);
    assert!((ring(-1.0).area() - expected).abs() < 1e-9);
    assert!((ring(1.0).perimeter() - 6.0 * PI).abs() < 1e-9);
}

/// The one meaning of a contour: a slit, a sliver narrower than the tolerance and a bow-tie of
/// either shape are not cuttable; a square, a circle and a thin but wide-enough strip are.
#[test]
fn check_cuttable_refuses_slits_slivers_and_bow_ties() {
    use cutroute_geometry::ContourFault;
    let tolerance = 0.05;
    assert_eq!(square_cw().check_cuttable(tolerance), Ok(()));
    assert_eq!(
        Contour::circle(p(0.0, 0.0), 1.0, true).check_cuttable(tolerance),
        Ok(())
    );
    let slit = Contour::new(vec![Vertex::line(0.0, 0.0), Vertex::line(10.0, 0.0)]);
    assert_eq!(slit.check_cuttable(tolerance), Err(ContourFault::Slit));
    // A strip 0.01 wide (area 1, perimeter 200.02): below the 0.05 tolerance, above 0.001.
    let strip = Contour::rectangle(0.0, 0.0, 100.0, 0.01);
    assert!(matches!(
        strip.check_cuttable(tolerance),
        Err(ContourFault::TooThin { .. })
    ));
    assert!(strip.check_cuttable(tolerance).unwrap_err().is_zero_area());
    assert_eq!(strip.check_cuttable(0.001), Ok(()));
    let symmetric = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(10.0, 10.0),
        Vertex::line(10.0, 0.0),
        Vertex::line(0.0, 10.0),
    ]);
    let unequal = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(10.0, 10.0),
        Vertex::line(10.0, 0.0),
        Vertex::line(0.0, 4.0),
    ]);
    for bow_tie in [symmetric, unequal] {
        assert!(matches!(
            bow_tie.check_cuttable(tolerance),
            Err(ContourFault::SelfIntersecting { .. })
        ));
    }
    // A zero-area "circle" of radius below the tolerance is a point.
    assert!(Contour::circle(p(0.0, 0.0), 0.01, true)
        .check_cuttable(tolerance)
        .unwrap_err()
        .is_zero_area());
}
