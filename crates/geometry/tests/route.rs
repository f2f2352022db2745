//! Route measures and the independent route checker.

use cutroute_geometry::{
    generate_nest, Contour, ContourRef, CutStep, Entry, MachineParameters, Nest, Part, Point,
    Route, RouteError, Vertex,
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
                entry: Default::default(),
                leads: None,
            },
            CutStep {
                contour: r(0, 0),
                pierce_point: p(100.0, 50.0),
                entry: Default::default(),
                leads: None,
            },
            CutStep {
                contour: r(1, 0),
                pierce_point: p(195.0, 50.0),
                entry: Default::default(),
                leads: None,
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
    route.steps.push(route.steps[2].clone());
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
    let route = Route::innermost_first(&n, Point::ORIGIN, Some(Point::ORIGIN));
    assert_eq!(route.steps.len(), n.contour_refs().count());
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

fn square(x: f64, y: f64, side: f64, clockwise: bool) -> Contour {
    let c = Contour::new(vec![
        Vertex::line(x, y),
        Vertex::line(x, y + side),
        Vertex::line(x + side, y + side),
        Vertex::line(x + side, y),
    ]);
    if clockwise {
        c
    } else {
        c.reversed()
    }
}

/// Three squares of side 10 in a row on the sheet (x = 0, 20, 40); a plate 100..200 with two
/// square holes (110 and 150), and a small part inside the first hole.
fn chain_nest() -> Nest {
    let mut parts: Vec<Part> = (0..3)
        .map(|i| Part {
            name: format!("s{i}"),
            contours: vec![square(20.0 * i as f64, 0.0, 10.0, true)],
        })
        .collect();
    parts.push(Part {
        name: "plate".into(),
        contours: vec![
            square(100.0, 0.0, 100.0, true),
            square(110.0, 10.0, 30.0, false),
            square(150.0, 10.0, 30.0, false),
        ],
    });
    parts.push(Part {
        name: "inner".into(),
        contours: vec![square(120.0, 20.0, 5.0, true)],
    });
    Nest { sheet: None, parts }
}

fn linked(contour: ContourRef, at: Point, corners: Vec<Point>) -> CutStep {
    CutStep {
        contour,
        pierce_point: at,
        entry: Entry::Link(corners),
        leads: None,
    }
}

/// Every contour of `chain_nest`, pierced, in a valid order.
fn chain_route(steps_0_to_2: [CutStep; 3]) -> Route {
    let mut steps: Vec<CutStep> = steps_0_to_2.into();
    steps.extend([
        CutStep::pierced(r(4, 0), p(120.0, 20.0)),
        CutStep::pierced(r(3, 1), p(110.0, 10.0)),
        CutStep::pierced(r(3, 2), p(150.0, 10.0)),
        CutStep::pierced(r(3, 0), p(100.0, 0.0)),
    ]);
    Route {
        start: p(0.0, -10.0),
        steps,
        finish: None,
    }
}

#[test]
fn links_count_as_cut_length_and_save_a_pierce_each() {
    let nest = chain_nest();
    let plain = chain_route([
        CutStep::pierced(r(0, 0), p(10.0, 5.0)),
        CutStep::pierced(r(1, 0), p(20.0, 5.0)),
        CutStep::pierced(r(2, 0), p(40.0, 5.0)),
    ]);
    plain.validate(&nest, 1e-9).unwrap();
    let chained = chain_route([
        CutStep::pierced(r(0, 0), p(10.0, 5.0)),
        linked(r(1, 0), p(20.0, 5.0), vec![]),
        // Round s1 from its pierce point on its left edge, over its top.
        linked(r(2, 0), p(40.0, 5.0), vec![p(19.0, 11.0), p(39.0, 11.0)]),
    ]);
    chained.validate(&nest, 1e-9).unwrap();
    let links = 10.0 + 20.0 + 2.0 * 37f64.sqrt();
    assert_eq!(plain.pierce_count(), 7);
    assert_eq!(chained.pierce_count(), 5);
    assert!((chained.link_length() - links).abs() < 1e-12);
    assert!((chained.cut_length(&nest) - plain.cut_length(&nest) - links).abs() < 1e-9);
    // The idle moves s0 → s1 → s2 (10 + 20 mm) are gone.
    assert!((plain.idle_length() - chained.idle_length() - 30.0).abs() < 1e-9);
    let m = MachineParameters::default();
    let saved = 2.0 * m.pierce_price + 0.030 * m.idle_price_per_metre
        - links * 1e-3 * m.cut_price_per_metre;
    assert!((plain.cost(&nest, &m) - chained.cost(&nest, &m) - saved).abs() < 1e-9);
}

#[test]
fn a_link_through_a_part_is_rejected() {
    let nest = chain_nest();
    // s0 → s2 straight through s1.
    let route = chain_route([
        CutStep::pierced(r(1, 0), p(20.0, 5.0)),
        CutStep::pierced(r(0, 0), p(10.0, 5.0)),
        linked(r(2, 0), p(40.0, 5.0), vec![]),
    ]);
    assert!(matches!(
        route.validate(&nest, 1e-9),
        Err(RouteError::LinkCrossesContour { step: 2, contour, .. }) if contour == r(1, 0)
    ));
    // Round s1 instead: valid.
    let around = chain_route([
        CutStep::pierced(r(1, 0), p(20.0, 5.0)),
        CutStep::pierced(r(0, 0), p(10.0, 10.0)),
        linked(r(2, 0), p(40.0, 10.0), vec![p(20.0, 10.5), p(30.0, 10.5)]),
    ]);
    around.validate(&nest, 1e-9).unwrap();
}

#[test]
fn a_link_running_inside_the_part_it_leaves_is_rejected() {
    let nest = chain_nest();
    let route = chain_route([
        CutStep::pierced(r(0, 0), p(10.0, 5.0)),
        linked(r(1, 0), p(20.0, 5.0), vec![p(5.0, 5.0)]),
        CutStep::pierced(r(2, 0), p(40.0, 5.0)),
    ]);
    assert!(matches!(
        route.validate(&nest, 1e-9),
        Err(RouteError::LinkLeavesScrap { step: 1, .. })
    ));
}

#[test]
fn holes_of_one_part_and_a_first_step_are_never_linked() {
    let nest = chain_nest();
    let mut route = chain_route([
        CutStep::pierced(r(0, 0), p(10.0, 5.0)),
        CutStep::pierced(r(1, 0), p(20.0, 5.0)),
        CutStep::pierced(r(2, 0), p(40.0, 5.0)),
    ]);
    // Hole 110 → hole 150 of the plate: the link would cut the plate.
    route.steps[5].entry = Entry::Link(vec![]);
    route.steps[5].pierce_point = p(150.0, 25.0);
    route.steps[4].pierce_point = p(140.0, 25.0);
    assert!(matches!(
        route.validate(&nest, 1e-9),
        Err(RouteError::LinkNotBetweenSiblings { step: 5, .. })
    ));
    // The part in the hole → the hole that contains it: not siblings either.
    route.steps[5].entry = Entry::Pierce;
    route.steps[4].entry = Entry::Link(vec![]);
    assert!(matches!(
        route.validate(&nest, 1e-9),
        Err(RouteError::LinkNotBetweenSiblings { step: 4, .. })
    ));
    route.steps[4].entry = Entry::Pierce;
    route.steps[0].entry = Entry::Link(vec![]);
    assert_eq!(
        route.validate(&nest, 1e-9),
        Err(RouteError::LinkWithoutPrevious)
    );
}

#[test]
fn routes_without_entry_fields_read_as_pierced() {
    let text = r#"{"start":{"x":0.0,"y":0.0},"steps":[{"contour":{"part":0,"contour":0},"pierce_point":{"x":1.0,"y":2.0}}],"finish":null}"#;
    let route: Route = serde_json::from_str(text).unwrap();
    assert_eq!(route.steps[0].entry, Entry::Pierce);
}
