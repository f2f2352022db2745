//! Route measures and the independent route checker.

use cutroute_geometry::{
    generate_nest, Contour, ContourRef, CutStep, MachineParameters, Nest, Part, Point, Route,
    RouteError, Vertex,
};

fn p(x: f64, y: f64) -> Point {
    Point::new(x, y)
}

fn r(part: usize, contour: usize) -> ContourRef {
    ContourRef { part, contour }
}

/// Plate 0..100 square with a round hole at (50, 50) r 10; a disc r 5 at (200, 50).
fn nest() -> Nest {
    let plate = Part {
        name: "plate".into(),
        contours: vec![
            Contour::new(vec![
                Vertex::line(0.0, 0.0),
                Vertex::line(0.0, 100.0),
                Vertex::line(100.0, 100.0),
                Vertex::line(100.0, 0.0),
            ]),
            Contour::circle(p(50.0, 50.0), 10.0, false),
        ],
    };
    let disc = Part {
        name: "disc".into(),
        contours: vec![Contour::circle(p(200.0, 50.0), 5.0, true)],
    };
    Nest {
        sheet: None,
        parts: vec![plate, disc],
    }
}

fn good_route() -> Route {
    Route {
        start: p(0.0, -100.0),
        steps: vec![
            CutStep {
                contour: r(0, 1),
                pierce_point: p(60.0, 50.0),
            },
            CutStep {
                contour: r(0, 0),
                pierce_point: p(100.0, 50.0),
            },
            CutStep {
                contour: r(1, 0),
                pierce_point: p(195.0, 50.0),
            },
        ],
        finish: Some(p(0.0, -100.0)),
    }
}

#[test]
fn measures() {
    let route = good_route();
    let n = nest();
    let idle = 60.0f64.hypot(150.0) + 40.0 + 95.0 + 195.0f64.hypot(150.0);
    assert!((route.idle_length() - idle).abs() < 1e-9);
    let cut = 400.0 + 20.0 * std::f64::consts::PI + 10.0 * std::f64::consts::PI;
    assert!((route.cut_length(&n) - cut).abs() < 1e-9);
    assert_eq!(route.pierce_count(), 3);
    let m = MachineParameters::default();
    let t = cut / m.cut_speed + idle / m.idle_speed + 3.0 * m.pierce_time;
    assert!((route.time(&n, &m) - t).abs() < 1e-9);
    let f = cut / 1000.0 * m.cut_price_per_metre
        + idle / 1000.0 * m.idle_price_per_metre
        + 3.0 * m.pierce_price;
    assert!((route.cost(&n, &m) - f).abs() < 1e-12);
    let open = Route {
        finish: None,
        ..route
    };
    assert!((open.idle_length() - (idle - 195.0f64.hypot(150.0))).abs() < 1e-9);
    assert_eq!(Route::default().idle_length(), 0.0);
}

#[test]
fn valid_route_passes() {
    assert_eq!(good_route().validate(&nest(), 1e-6), Ok(()));
}

#[test]
fn every_failure_is_reported() {
    let n = nest();
    let forest = n.containment_forest();
    let mut route = good_route();
    route.steps.swap(0, 1);
    assert_eq!(
        route.validate(&n, 1e-6),
        Err(RouteError::PrecedenceViolated {
            inner: r(0, 1),
            inner_step: 1,
            outer: r(0, 0),
            outer_step: 0
        })
    );
    let mut route = good_route();
    route.steps[2].pierce_point = p(196.0, 50.0);
    match route.validate(&n, 1e-6) {
        Err(RouteError::PierceOffContour {
            step: 2, distance, ..
        }) => assert!((distance - 1.0).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    route.steps[2].pierce_point = p(f64::NAN, 50.0);
    assert!(matches!(
        route.validate(&n, 1e-6),
        Err(RouteError::PierceOffContour { step: 2, .. })
    ));
    let mut route = good_route();
    route.steps.pop();
    assert_eq!(
        route.validate(&n, 1e-6),
        Err(RouteError::NotCut { contour: r(1, 0) })
    );
    let mut route = good_route();
    route.steps.push(route.steps[2]);
    assert_eq!(
        route.validate(&n, 1e-6),
        Err(RouteError::CutTwice {
            contour: r(1, 0),
            first_step: 2,
            second_step: 3
        })
    );
    let mut route = good_route();
    route.steps[2].contour = r(5, 0);
    let problems = route.problems(&n, &forest, 1e-6);
    assert_eq!(
        problems[0],
        RouteError::UnknownContour {
            step: 2,
            contour: r(5, 0)
        }
    );
    assert!(problems.contains(&RouteError::NotCut { contour: r(1, 0) }));
    assert!(problems[0].to_string().contains("does not have"));
}

#[test]
fn inner_first_route_on_a_generated_nest_is_valid() {
    let n = generate_nest(300, 3);
    let forest = n.containment_forest();
    // Cut deepest first: sorting by decreasing depth respects every precedence pair.
    let mut refs: Vec<ContourRef> = n.contour_refs().collect();
    refs.sort_by_key(|&c| std::cmp::Reverse(forest.depth(c)));
    let steps = refs
        .iter()
        .map(|&c| CutStep {
            contour: c,
            pierce_point: n.contour(c).unwrap().vertices[0].point,
        })
        .collect();
    let route = Route {
        start: Point::ORIGIN,
        steps,
        finish: Some(Point::ORIGIN),
    };
    assert!(route.problems(&n, &forest, 1e-9).is_empty());
    let mut backwards = route.clone();
    backwards.steps.reverse();
    assert!(backwards
        .problems(&n, &forest, 1e-9)
        .iter()
        .all(|e| matches!(e, RouteError::PrecedenceViolated { .. })));
    assert_eq!(
        backwards.problems(&n, &forest, 1e-9).len(),
        forest.all_precedence_pairs().len()
    );
    // Leaving out a hole that holds an inlay still reports the inlay cut after the frame.
    let frame = n
        .parts
        .iter()
        .position(|p| p.name.starts_with("frame"))
        .expect("a frame");
    let (frame_outer, frame_hole) = (r(frame, 0), r(frame, 1));
    let mut skipping = route.clone();
    skipping.steps.retain(|s| s.contour != frame_hole);
    let outer_step = skipping
        .steps
        .iter()
        .position(|s| s.contour == frame_outer)
        .unwrap();
    let inlay = skipping
        .steps
        .iter()
        .position(|s| forest.parent(s.contour) == Some(frame_hole))
        .unwrap();
    let moved = skipping.steps.remove(inlay);
    skipping.steps.insert(outer_step, moved); // now just after the frame's outer contour
    let problems = skipping.problems(&n, &forest, 1e-9);
    assert!(problems.contains(&RouteError::NotCut {
        contour: frame_hole
    }));
    assert!(problems.iter().any(
        |e| matches!(e, RouteError::PrecedenceViolated { outer, .. } if *outer == frame_outer)
    ));
}
