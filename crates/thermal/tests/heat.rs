//! The heat model against independent recomputations.

use cutroute_geometry::{
    generate_nest, ContourRef, CutStep, Entry, MachineParameters, Nest, Point, Route,
};
use cutroute_thermal::{route_pierces, HeatModel, ThermalError};

/// A valid route over every contour: deepest first (inner before outer), pierced at each
/// contour's first vertex.
fn deep_first_route(nest: &Nest) -> Route {
    let forest = nest.containment_forest();
    let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
    refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r).unwrap_or(0)));
    Route {
        start: Point::new(-10.0, -10.0),
        steps: refs
            .into_iter()
            .map(|r| CutStep::pierced(r, nest.contour(r).unwrap().vertices[0].point))
            .collect(),
        finish: None,
    }
}

/// Times of the pierces from the route alone: each step starts after the idle move to it,
/// and occupies the pierce time plus its perimeter at cutting speed.
fn independent_times(route: &Route, nest: &Nest, m: &MachineParameters) -> Vec<f64> {
    let mut t = 0.0;
    let mut at = route.start;
    let mut times = Vec::new();
    for s in &route.steps {
        t += at.distance(s.pierce_point) / m.idle_speed;
        times.push(t);
        t += m.pierce_time + nest.contour(s.contour).unwrap().perimeter() / m.cut_speed;
        at = s.pierce_point;
    }
    times
}

fn double_loop(points: &[Point], times: &[f64], sigma: f64, tau: f64) -> f64 {
    let mut h = 0.0;
    for i in 0..points.len() {
        for j in 0..i {
            let d2 = (points[i].x - points[j].x).powi(2) + (points[i].y - points[j].y).powi(2);
            h += (-d2 / (2.0 * sigma * sigma)).exp() * (-(times[i] - times[j]) / tau).exp();
        }
    }
    h
}

#[test]
fn load_matches_an_independent_double_loop() {
    for (contours, seed) in [(60, 1), (200, 7), (400, 3)] {
        let nest = generate_nest(contours, seed);
        let route = deep_first_route(&nest);
        assert!(route.validate(&nest, 1e-6).is_ok());
        for machine in [
            MachineParameters::default(),
            MachineParameters {
                idle_speed: 100.0,
                cut_speed: 50.0,
                pierce_time: 1.5,
                ..MachineParameters::default()
            },
        ] {
            let pierces = route_pierces(&route, &nest, &machine).unwrap();
            let times = independent_times(&route, &nest, &machine);
            for (p, t) in pierces.iter().zip(&times) {
                assert!((p.time - t).abs() <= 1e-9 * t.max(1.0), "{} vs {t}", p.time);
            }
            let points: Vec<Point> = route.steps.iter().map(|s| s.pierce_point).collect();
            for (sigma, tau) in [(50.0, 60.0), (200.0, 600.0), (5.0, 3.0)] {
                let model = HeatModel::new(sigma, tau).unwrap();
                let h = model.route_load(&route, &nest, &machine).unwrap();
                let reference = double_loop(&points, &times, sigma, tau);
                assert!(reference > 0.0);
                assert!(
                    (h - reference).abs() <= 1e-6 * reference,
                    "σ {sigma} τ {tau}: {h} vs {reference}"
                );
            }
        }
    }
}

#[test]
fn temperature_field_sums_to_the_load() {
    // Just before each pierce, the field at its point is what it adds to H.
    let nest = generate_nest(80, 5);
    let route = deep_first_route(&nest);
    let machine = MachineParameters::default();
    let model = HeatModel::default();
    let pierces = route_pierces(&route, &nest, &machine).unwrap();
    let h = model.load(&pierces);
    let from_field: f64 = pierces
        .iter()
        .enumerate()
        .map(|(i, p)| model.temperature_at(&pierces[..i], p.point, p.time))
        .sum();
    assert!((h - from_field).abs() <= 1e-9 * h);
    // The field cools: later, less.
    let last = pierces.last().unwrap();
    let now = model.temperature_at(&pierces, last.point, last.time);
    let later = model.temperature_at(&pierces, last.point, last.time + 100.0);
    assert!(later < now && later > 0.0);
}

#[test]
fn a_linked_step_starts_where_its_link_ends() {
    // Two squares side by side; the second is entered by a 10 mm tool-on link.
    let square = |x: f64| cutroute_geometry::Part {
        name: String::new(),
        contours: vec![cutroute_geometry::Contour::new(vec![
            cutroute_geometry::Vertex::line(x, 0.0),
            cutroute_geometry::Vertex::line(x, 10.0),
            cutroute_geometry::Vertex::line(x + 10.0, 10.0),
            cutroute_geometry::Vertex::line(x + 10.0, 0.0),
        ])],
    };
    let nest = Nest {
        sheet: None,
        parts: vec![square(0.0), square(20.0)],
    };
    let mut route = Route {
        start: Point::new(0.0, 0.0),
        steps: vec![
            CutStep::pierced(
                ContourRef {
                    part: 0,
                    contour: 0,
                },
                Point::new(10.0, 0.0),
            ),
            CutStep::pierced(
                ContourRef {
                    part: 1,
                    contour: 0,
                },
                Point::new(20.0, 0.0),
            ),
        ],
        finish: None,
    };
    route.steps[1].entry = Entry::Link(Vec::new());
    let m = MachineParameters::default();
    let pierces = route_pierces(&route, &nest, &m).unwrap();
    // Idle 10 mm, pierce 7 s, 40 mm of square, 10 mm of link, all on the clock.
    let expected = 10.0 / m.idle_speed + m.pierce_time + 40.0 / m.cut_speed + 10.0 / m.cut_speed;
    assert!((pierces[1].time - expected).abs() < 1e-12);
    let h = HeatModel::default().load(&pierces);
    let reference = (-(100.0f64) / 5000.0 - (expected - pierces[0].time) / 60.0).exp();
    assert!((h - reference).abs() < 1e-12);
}

#[test]
fn bad_parameters_and_routes_are_typed_errors() {
    assert!(matches!(
        HeatModel::new(0.0, 60.0),
        Err(ThermalError::InvalidParameter { name: "sigma", .. })
    ));
    assert!(matches!(
        HeatModel::new(50.0, f64::NAN),
        Err(ThermalError::InvalidParameter { name: "tau", .. })
    ));
    let nest = generate_nest(5, 1);
    let route = Route {
        start: Point::default(),
        steps: vec![CutStep::pierced(
            ContourRef {
                part: 99,
                contour: 0,
            },
            Point::default(),
        )],
        finish: None,
    };
    assert!(matches!(
        route_pierces(&route, &nest, &MachineParameters::default()),
        Err(ThermalError::Route(_))
    ));
}

#[test]
fn relaxed_pierce_points_lower_the_penalised_objective() {
    use cutroute_thermal::relax_pierce_points;
    // A 200 mm plate with a small hole near its left edge: cut the hole, then the plate,
    // pierced right next to the hole.
    let plate = cutroute_geometry::Contour::new(vec![
        cutroute_geometry::Vertex::line(0.0, 0.0),
        cutroute_geometry::Vertex::line(0.0, 200.0),
        cutroute_geometry::Vertex::line(200.0, 200.0),
        cutroute_geometry::Vertex::line(200.0, 0.0),
    ]);
    let hole = cutroute_geometry::Contour::circle(Point::new(20.0, 100.0), 5.0, false);
    let nest = Nest {
        sheet: None,
        parts: vec![cutroute_geometry::Part {
            name: String::new(),
            contours: vec![plate, hole],
        }],
    };
    let route = Route {
        start: Point::new(-50.0, 100.0),
        steps: vec![
            CutStep::pierced(
                ContourRef {
                    part: 0,
                    contour: 1,
                },
                Point::new(15.0, 100.0),
            ),
            CutStep::pierced(
                ContourRef {
                    part: 0,
                    contour: 0,
                },
                Point::new(0.0, 100.0),
            ),
        ],
        finish: None,
    };
    let machine = MachineParameters::default();
    let model = HeatModel::default();
    let weight_mm = 100.0 * machine.idle_speed;
    let objective =
        |r: &Route| r.idle_length() + weight_mm * model.route_load(r, &nest, &machine).unwrap();
    let relaxed = relax_pierce_points(&nest, &route, &machine, &model, weight_mm, 3, None).unwrap();
    relaxed.validate(&nest, 1e-6).unwrap();
    let (h0, h1) = (
        model.route_load(&route, &nest, &machine).unwrap(),
        model.route_load(&relaxed, &nest, &machine).unwrap(),
    );
    assert!(h1 < 0.1 * h0, "{h1} vs {h0}");
    assert!(objective(&relaxed) < objective(&route));
    // Without weight nothing pays for a longer idle path: the route stays as short.
    let unweighted = relax_pierce_points(&nest, &route, &machine, &model, 0.0, 3, None).unwrap();
    assert!(unweighted.idle_length() <= route.idle_length() + 1e-9);
}
