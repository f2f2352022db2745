//! Chain cutting on hand-made nests with known optima and on the real nests, every result
//! checked by the geometry crate's independent route checker (links cross no contour and stay
//! in their scrap region, precedence holds, every contour is cut once).

use std::time::Duration;

use cutroute_chains::{chain_route, profitable_link_length, ChainOptions, TABLE1_MATERIALS};
use cutroute_geometry::{
    Contour, ContourRef, CutStep, Entry, MachineParameters, Nest, Part, Point, Route, Vertex,
};

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

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x0, y0),
        Vertex::line(x0, y1),
        Vertex::line(x1, y1),
        Vertex::line(x1, y0),
    ])
}

fn part(name: &str, contours: Vec<Contour>) -> Part {
    Part {
        name: name.into(),
        contours,
    }
}

/// Every contour pierced at its first vertex, inner contours first (by depth, deepest first).
fn plain_route(nest: &Nest, start: Point) -> Route {
    let forest = nest.containment_forest();
    let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
    refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r).unwrap()));
    Route {
        start,
        steps: refs
            .into_iter()
            .map(|r| CutStep::pierced(r, nest.contour(r).unwrap().vertices[0].point))
            .collect(),
        finish: None,
    }
}

fn check(nest: &Nest, route: &Route) {
    route
        .validate(nest, 1e-6)
        .unwrap_or_else(|e| panic!("invalid chained route: {e}"));
}

#[test]
fn a_row_of_squares_is_one_chain_of_near_minimal_link_length() {
    // k squares of side s, gap g: one pierce; the links must cover the span from the leftmost
    // to the rightmost pierce point, at least (k−1)(s+g) − s, which corner pierce points reach.
    let (k, s, g) = (5, 10.0, 5.0);
    let nest = Nest {
        sheet: None,
        parts: (0..k)
            .map(|i| part("sq", vec![square(i as f64 * (s + g), 0.0, s, true)]))
            .collect(),
    };
    let route = plain_route(&nest, Point::new(-20.0, 5.0));
    for machine in [MachineParameters::default()].into_iter().chain(
        TABLE1_MATERIALS
            .iter()
            .map(|m| m.priced(&MachineParameters::default())),
    ) {
        let options = ChainOptions {
            machine,
            ..ChainOptions::default()
        };
        let chained = chain_route(&nest, &route, &options).unwrap();
        check(&nest, &chained.route);
        assert_eq!(chained.route.pierce_count(), 1);
        assert_eq!(chained.report.pierces_before, k);
        assert_eq!(chained.report.chains, 1);
        let lower = (k - 1) as f64 * (s + g) - s;
        let links = chained.route.link_length();
        assert!(links >= lower - 1e-9, "{links} < lower bound {lower}");
        assert!(
            links <= lower + 1.0,
            "{links}: more than 1 mm above {lower}"
        );
        assert!(chained.report.cost_after < chained.report.cost_before);
        let recomputed = chained.route.cost(&nest, &machine);
        assert!((recomputed - chained.report.cost_after).abs() < 1e-9);
    }
}

#[test]
fn contours_farther_apart_than_the_threshold_are_never_chained() {
    let machine = TABLE1_MATERIALS[0].priced(&MachineParameters::default());
    let threshold = profitable_link_length(&machine);
    assert!((threshold - 5000.0 / 29.9).abs() < 1e-9, "paper: 0.1672 m");
    let nest = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 10.0, true)]),
            part("b", vec![square(10.0 + threshold + 1.0, 0.0, 10.0, true)]),
        ],
    };
    let route = plain_route(&nest, Point::new(-5.0, 0.0));
    let options = ChainOptions {
        machine,
        ..ChainOptions::default()
    };
    let chained = chain_route(&nest, &route, &options).unwrap();
    assert_eq!(chained.route.pierce_count(), 2);
    assert_eq!(chained.report.cost_after, chained.report.cost_before);
    // Just under the threshold a straight link pays.
    let nest = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 10.0, true)]),
            part("b", vec![square(10.0 + threshold - 1.0, 0.0, 10.0, true)]),
        ],
    };
    let route = plain_route(&nest, Point::new(-5.0, 0.0));
    let chained = chain_route(&nest, &route, &options).unwrap();
    check(&nest, &chained.route);
    assert_eq!(chained.route.pierce_count(), 1);
    assert!((chained.route.link_length() - (threshold - 1.0)).abs() < 1e-6);
}

#[test]
fn a_part_in_a_hole_in_a_part_chains_only_within_its_scrap_region() {
    // Plate 0..200 × 0..100 with a big hole 10..110 × 10..90 and two small holes close
    // together at x 150 and 165; in the big hole two small parts 5 mm apart, one of which has
    // a hole of its own; beside the plate on the sheet, a square 5 mm away.
    let plate = part(
        "plate",
        vec![
            rect(0.0, 0.0, 200.0, 100.0),
            rect(10.0, 10.0, 110.0, 90.0).reversed(),
            square(150.0, 40.0, 10.0, false),
            square(165.0, 40.0, 10.0, false),
        ],
    );
    let inner_a = part(
        "inner a",
        vec![rect(20.0, 20.0, 50.0, 80.0), square(30.0, 40.0, 5.0, false)],
    );
    let inner_b = part("inner b", vec![rect(55.0, 20.0, 85.0, 80.0)]);
    let beside = part("beside", vec![rect(205.0, 0.0, 215.0, 100.0)]);
    let nest = Nest {
        sheet: None,
        parts: vec![plate, inner_a, inner_b, beside],
    };
    let route = plain_route(&nest, Point::new(0.0, -20.0));
    check(&nest, &route);
    let chained = chain_route(&nest, &route, &ChainOptions::default()).unwrap();
    check(&nest, &chained.route);
    // Optimum: inner a + inner b in one chain (in the big hole), plate + beside in one chain
    // (on the sheet); the plate's small holes and inner a's hole lie in material: pierced.
    assert_eq!(chained.route.pierce_count(), route.pierce_count() - 2);
    let r = |part, contour| ContourRef { part, contour };
    for step in &chained.route.steps {
        if !step.is_pierced() {
            assert!(
                [r(1, 0), r(2, 0), r(0, 0), r(3, 0)].contains(&step.contour),
                "{:?} was linked",
                step.contour
            );
        }
    }
    // The two inner parts are 5 mm apart: their link is the 5 mm gap (to within the golden
    // section's and the corner clearance's precision).
    let inner_link = chained
        .route
        .steps
        .iter()
        .enumerate()
        .find(|(_, s)| !s.is_pierced() && [r(1, 0), r(2, 0)].contains(&s.contour))
        .map(|(i, _)| i)
        .unwrap();
    let path = chained.route.link_path(inner_link).unwrap();
    let length: f64 = path.windows(2).map(|w| w[0].distance(w[1])).sum();
    assert!((5.0 - 1e-9..5.01).contains(&length), "{length}");
}

#[test]
fn links_go_round_a_wall_between_two_parts() {
    // Two small squares at y 0..10, x 0..10 and 30..40, a wall 15..25 × −50..60 between:
    // the straight link is blocked; the shortest way runs over the wall's top corners.
    let nest = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 10.0, true)]),
            part("wall", vec![rect(15.0, -50.0, 25.0, 60.0)]),
            part("b", vec![square(30.0, 0.0, 10.0, true)]),
        ],
    };
    let mut route = plain_route(&nest, Point::new(-10.0, 100.0));
    route.steps.sort_by_key(|s| s.contour.part);
    let machine = MachineParameters {
        pierce_price: 1000.0, // any link pays
        ..MachineParameters::default()
    };
    let options = ChainOptions {
        machine,
        ..ChainOptions::default()
    };
    let chained = chain_route(&nest, &route, &options).unwrap();
    check(&nest, &chained.route);
    assert_eq!(chained.route.pierce_count(), 1);
    // a and b are chained across the wall (directly or through it as the middle member):
    // any a ↔ b link rounds the wall's top or bottom, at least 5 + 50 + 10 + 50 + 5 − … long;
    // the checker above already rejected any link through it. Every link is at least as
    // long as its straight chord, and one of them bends.
    let mut bends = 0;
    for (i, s) in chained.route.steps.iter().enumerate() {
        if let Entry::Link(corners) = &s.entry {
            let path = chained.route.link_path(i).unwrap();
            let length: f64 = path.windows(2).map(|w| w[0].distance(w[1])).sum();
            assert!(length >= path[0].distance(*path.last().unwrap()) - 1e-12);
            bends += usize::from(!corners.is_empty());
        }
    }
    assert!(bends >= 1, "some link must go round the wall");
    let toolpath = cutroute_geometry::Toolpath::new(&chained.route, &nest).unwrap();
    assert!((toolpath.cut_length() - chained.route.cut_length(&nest)).abs() < 1e-9);
    assert_eq!(toolpath.pierce_count(), 1);
}

fn read_nest(path: &str) -> Nest {
    let full = format!("{}/../../data/nests/{path}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&full).unwrap_or_else(|e| panic!("missing test file {full}: {e}"));
    cutroute_formats::read_nest(&bytes).unwrap_or_else(|e| panic!("cannot read {full}: {e}"))
}

#[test]
fn ccp_routes_of_real_nests_chain_validly_and_never_cost_more() {
    let mut links_seen = 0;
    for path in [
        "dbs-json/E1X_6_01.dbs.json",
        "dbs/nested.dbs",
        "dbs-json/test1.dbs.json",
        "dbs/seven.dbs",
    ] {
        let nest = read_nest(path);
        let ccp = cutroute_ccp::solve(
            &nest,
            cutroute_ccp::CcpOptions {
                time_limit: Duration::from_millis(500),
                ..cutroute_ccp::CcpOptions::default()
            },
            &mut |_| {},
        )
        .unwrap();
        for material in TABLE1_MATERIALS {
            let options = ChainOptions {
                machine: material.priced(&MachineParameters::default()),
                ..ChainOptions::default()
            };
            let chained = chain_route(&nest, &ccp.route, &options).unwrap();
            let scale = 1e-6 * 1e4;
            chained
                .route
                .validate(&nest, scale)
                .unwrap_or_else(|e| panic!("{path}, {}: {e}", material.name));
            // The result format keeps the links: same steps, same entries, still valid.
            let exported = cutroute_formats::RmResult::from_route(
                &nest,
                &chained.route,
                &cutroute_formats::ResultExportOptions::default(),
            )
            .unwrap();
            let back = exported.route();
            links_seen += back.steps.iter().filter(|s| !s.is_pierced()).count();
            assert_eq!(back.steps.len(), chained.route.steps.len(), "{path}");
            for (ours, read) in chained.route.steps.iter().zip(&back.steps) {
                assert_eq!(ours.contour, read.contour, "{path}");
                assert!(
                    ours.pierce_point.distance(read.pierce_point) < 1e-6,
                    "{path}"
                );
                assert_eq!(ours.is_pierced(), read.is_pierced(), "{path}");
            }
            back.validate(&nest, scale)
                .unwrap_or_else(|e| panic!("{path}, read back: {e}"));
            let r = &chained.report;
            assert!(r.cost_after <= r.cost_before, "{path}: {r:?}");
            assert_eq!(r.pierces_before, nest.contour_count());
            assert!(r.pierces_after <= r.pierces_before);
        }
    }
    assert!(
        links_seen > 0,
        "no real nest was chained: the round trip saw no link"
    );
}

#[test]
fn tflex_nests_with_touching_parts_chain_validly() {
    // 406 parts, many touching: links start at points where neighbours touch, the case that
    // once let a link through a neighbour within the region's old end tolerance.
    for file in ["Nest02.tfnesting", "Nest03.tfnesting"] {
        let full = format!(
            "{}/../../data/nests/tflex/{file}",
            env!("CARGO_MANIFEST_DIR")
        );
        let bytes =
            std::fs::read(&full).unwrap_or_else(|e| panic!("missing test file {full}: {e}"));
        let document = cutroute_engine::open_document(&full, &bytes).unwrap();
        let cutroute_protocol::Problem::Nest {
            nest,
            start,
            finish,
        } = &document.problem
        else {
            panic!("{file} is a nest")
        };
        let request = cutroute_protocol::JobRequest {
            job_id: 1,
            problem: document.problem.clone(),
            solver: cutroute_protocol::SolverKind::NearestNeighbour,
            params: cutroute_protocol::SolverParams::default(),
        };
        let mut job = cutroute_engine::start_job(&request).unwrap();
        let route = cutroute_engine::run_to_end(job.as_mut(), &mut |_| {})
            .route()
            .cloned()
            .unwrap();
        assert_eq!((route.start, route.finish), (*start, *finish));
        for material in TABLE1_MATERIALS {
            let options = ChainOptions {
                machine: material.priced(&MachineParameters::default()),
                ..ChainOptions::default()
            };
            let chained = chain_route(nest, &route, &options).unwrap();
            chained
                .route
                .validate(nest, 1e-6 * 8000.0)
                .unwrap_or_else(|e| panic!("{file}, {}: {e}", material.name));
            assert!(chained.report.pierces_after < chained.report.pierces_before);
            assert!(chained.report.cost_after < chained.report.cost_before);
        }
    }
}

#[test]
fn chaining_in_slices_of_one_piece_gives_the_same_route() {
    for path in ["dbs/nested.dbs", "dbs/seven.dbs", "dbs-json/test1.dbs.json"] {
        let nest = read_nest(path);
        let route = plain_route(&nest, Point::new(0.0, 0.0));
        let options = ChainOptions {
            machine: TABLE1_MATERIALS[1].priced(&MachineParameters::default()),
            ..ChainOptions::default()
        };
        let whole = chain_route(&nest, &route, &options).unwrap();
        let mut chaining = cutroute_chains::Chaining::new(&nest, &route, &options).unwrap();
        let mut slices = 1;
        // Stop after every piece: each call does one piece of a group of close contours (a
        // row of its distances, its order, one contour's refinement or one link), and the
        // next call resumes the group there.
        while chaining.step(Duration::ZERO).is_running() {
            slices += 1;
        }
        let sliced = chaining.finish();
        assert_eq!(sliced.route, whole.route, "{path}");
        assert_eq!(sliced.report, whole.report, "{path}");
        // Far more slices than groups: every group of n contours takes about 4n pieces.
        let grouped = sliced.report.pierces_before - sliced.report.pierces_after;
        assert!(
            slices > 3 * grouped,
            "{path}: {slices} slices, {grouped} links"
        );
        check(&nest, &sliced.route);
    }
}
