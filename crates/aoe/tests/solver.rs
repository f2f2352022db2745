//! `solve_nest`: checked routes with the fewest pierces on hand-made plans with known optima and
//! on every real nest; idle travel never worse than the plain inner-first order.

mod common;

use common::{hole, load_nest, part, rect, REAL_NESTS};
use std::time::{Duration, Instant};

use cutroute_aoe::{
    solve_nest, AoeSolveOptions, AoeSolving, PlanGraph, PlanOptions, PlaneGraph, Status,
};
use cutroute_geometry::{Nest, Point};

/// `n × m` rectangles of `w × h` sharing their edges.
fn grid(n: usize, m: usize, w: f64, h: f64) -> Nest {
    let mut parts = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (x, y) = (w * i as f64, h * j as f64);
            parts.push(part(vec![rect(x, y, x + w, y + h)]));
        }
    }
    Nest { sheet: None, parts }
}

fn check(nest: &Nest, options: &AoeSolveOptions) -> cutroute_aoe::AoeSolution {
    let solution = solve_nest(nest, options).unwrap_or_else(|e| panic!("{e}"));
    // Both checkers again, independently of the solver's own final check.
    solution
        .route
        .validate(nest, 1e-6)
        .unwrap_or_else(|e| panic!("{e}"));
    let plan = PlanGraph::from_nest(nest, &options.plan).unwrap();
    plan.check_route(&solution.chains).unwrap();
    assert_eq!(solution.route.paths.len(), solution.chains.len());
    assert!(solution.route.idle_length() <= solution.unordered_idle_length + 1e-9);
    solution
}

#[test]
fn grids_cut_every_common_edge_once_with_the_fewest_pierces() {
    for (n, m) in [(1, 1), (1, 5), (2, 2), (3, 3), (4, 7), (10, 10)] {
        let (w, h) = (100.0, 50.0);
        let solution = check(&grid(n, m, w, h), &AoeSolveOptions::default());
        // Every grid line once: m + 1 horizontal lines of n·w, n + 1 vertical ones of m·h.
        let lines = (m + 1) as f64 * n as f64 * w + (n + 1) as f64 * m as f64 * h;
        assert!(
            (solution.route.cut_length() - lines).abs() < 1e-6,
            "{n}×{m}: {} vs {lines}",
            solution.route.cut_length()
        );
        // Odd vertices: the T-junctions on the boundary, 2(n − 1) + 2(m − 1); one trail per pair.
        let odd = 2 * (n - 1) + 2 * (m - 1);
        assert_eq!(solution.pierce_lower_bound, (odd / 2).max(1), "{n}×{m}");
        assert_eq!(solution.route.pierce_count(), (odd / 2).max(1), "{n}×{m}");
    }
}

#[test]
fn a_part_in_a_hole_in_a_part_is_cut_inside_out() {
    // A plate with a hole, a smaller plate with a hole inside that hole, a square in the
    // smallest hole: three levels, six closed curves, no common edges.
    let nest = Nest {
        sheet: None,
        parts: vec![
            part(vec![
                rect(0.0, 0.0, 100.0, 100.0),
                hole(10.0, 10.0, 90.0, 90.0),
            ]),
            part(vec![
                rect(20.0, 20.0, 80.0, 80.0),
                hole(30.0, 30.0, 70.0, 70.0),
            ]),
            part(vec![rect(40.0, 40.0, 60.0, 60.0)]),
        ],
    };
    // Start far outside: the nearest curve is the outermost, which must still come last.
    let options = AoeSolveOptions {
        start: Point::new(-500.0, -500.0),
        ..AoeSolveOptions::default()
    };
    let solution = check(&nest, &options);
    assert_eq!(solution.route.pierce_count(), 5);
    let first = solution.route.paths[0].pierce;
    assert!(first.x >= 40.0 && first.x <= 60.0 && first.y >= 40.0 && first.y <= 60.0);
    let last = solution.route.paths[4].pierce;
    assert!(
        last.x == 0.0 || last.x == 100.0 || last.y == 0.0 || last.y == 100.0,
        "{last:?}"
    );
}

#[test]
fn ordering_beats_the_inner_first_area_order_on_scattered_parts() {
    // Squares on a diagonal, smaller the farther from the start: the area order (smallest
    // first) goes out to the far end and back.
    let parts = (0..8)
        .map(|k| {
            let x = 100.0 * k as f64;
            let side = 45.0 - 5.0 * k as f64;
            part(vec![rect(x, x, x + side, x + side)])
        })
        .collect();
    let nest = Nest { sheet: None, parts };
    let solution = check(&nest, &AoeSolveOptions::default());
    assert!(
        solution.route.idle_length() < 0.6 * solution.unordered_idle_length,
        "{} vs {}",
        solution.route.idle_length(),
        solution.unordered_idle_length
    );
}

#[test]
fn every_real_nest_gets_a_checked_route_at_the_pierce_lower_bound() {
    for name in REAL_NESTS {
        let nest = load_nest(name);
        let scale = {
            let b = nest.bounding_box();
            (b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()
        };
        let options = AoeSolveOptions {
            plan: PlanOptions {
                tolerance: 1e-6 * scale.max(1.0),
                ..PlanOptions::default()
            },
            ..AoeSolveOptions::default()
        };
        let solution = solve_nest(&nest, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
        solution
            .route
            .validate(&nest, 1e-5 * scale.max(1.0))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        // The fewest pierces of any route, counted here from the plan graph alone: per
        // connected component (found by union-find over the edge ends, not by the solver's
        // own components), half its odd-degree vertices, and at least one.
        let plan = PlanGraph::from_nest(&nest, &options.plan).unwrap();
        let fewest = fewest_pierces(plan.graph());
        assert_eq!(solution.route.pierce_count(), fewest, "{name}");
        assert_eq!(solution.pierce_lower_bound, fewest, "{name}");
        assert!(
            solution.route.pierce_count() <= nest.contour_count(),
            "{name}"
        );
        assert!(
            solution.route.idle_length() <= solution.unordered_idle_length + 1e-9,
            "{name}"
        );
    }
}

/// A part with no common edge is one closed curve: it may be pierced anywhere, and the solver
/// places the point as CCP-Relax would. Two 10 × 10 squares 10 mm apart, the head below the
/// first: the optimum goes up to the first square, pierces at its lower right corner (the
/// minimiser of |S M| + |M N|) and crosses the 10 mm gap: √74 + 10 mm.
#[test]
fn closed_curves_are_pierced_where_the_idle_travel_is_shortest() {
    let nest = Nest {
        sheet: None,
        parts: vec![
            part(vec![rect(0.0, 0.0, 10.0, 10.0)]),
            part(vec![rect(20.0, 0.0, 30.0, 10.0)]),
        ],
    };
    let options = AoeSolveOptions {
        start: Point::new(5.0, -7.0),
        ..AoeSolveOptions::default()
    };
    let solution = check(&nest, &options);
    assert_eq!(solution.route.pierce_count(), 2);
    let idle = solution.route.idle_length();
    assert!((idle - (74f64.sqrt() + 10.0)).abs() < 1e-6, "idle {idle}");
    // One square alone: straight up to its nearest point.
    let one = Nest {
        sheet: None,
        parts: vec![part(vec![rect(0.0, 0.0, 10.0, 10.0)])],
    };
    let solution = check(&one, &options);
    assert!((solution.route.idle_length() - 7.0).abs() < 1e-9);
    assert!(
        solution.route.paths[0]
            .pierce
            .distance(Point::new(5.0, 0.0))
            < 1e-9
    );
}

#[test]
fn a_thousand_contour_sheet_gets_a_checked_route() {
    // Over 400 components the order is improved through nearest-neighbour places, and the
    // cross-component check finds holders through an R-tree; the tolerance is the engine's
    // (10⁻⁶ of width plus height), where pierce points relaxed a few hundredths of a millimetre
    // past a vertex once read as cut twice.
    let nest = cutroute_geometry::generate_nest(1000, 1);
    let b = nest.bounding_box();
    let tolerance = 1e-6 * ((b.max.x - b.min.x) + (b.max.y - b.min.y));
    let options = AoeSolveOptions {
        plan: PlanOptions {
            tolerance,
            ..PlanOptions::default()
        },
        start: b.min,
        finish: None,
        heat: None,
    };
    let solution = solve_nest(&nest, &options).unwrap_or_else(|e| panic!("{e}"));
    solution
        .route
        .validate(&nest, 10.0 * tolerance)
        .unwrap_or_else(|e| panic!("{e}"));
    let plan = PlanGraph::from_nest(&nest, &options.plan).unwrap();
    plan.check_route(&solution.chains).unwrap();
    assert!(solution.components > 400);
    assert!(solution.route.idle_length() <= solution.unordered_idle_length + 1e-9);
}

/// The engine's options for `nest`: the tolerance 10⁻⁶ of its width plus height.
fn engine_options(nest: &Nest) -> AoeSolveOptions {
    let b = nest.bounding_box();
    let scale = (b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs();
    AoeSolveOptions {
        plan: PlanOptions {
            tolerance: 1e-6 * scale.max(1.0),
            ..PlanOptions::default()
        },
        ..AoeSolveOptions::default()
    }
}

/// Stepped with a zero budget (a look at the clock after every few units of work: a pick, a
/// move tried, a curve relaxed, a component's chains), the solver gives the route of one
/// uninterrupted call: where the slices end changes nothing.
#[test]
fn slices_give_the_route_of_one_call() {
    let mut nests: Vec<(String, Nest)> = REAL_NESTS
        .iter()
        .map(|name| (name.to_string(), load_nest(name)))
        .collect();
    nests.push(("grid".into(), grid(6, 4, 10.0, 5.0)));
    nests.push((
        "generated-1000".into(),
        cutroute_geometry::generate_nest(1000, 1),
    ));
    for (name, nest) in nests {
        let options = engine_options(&nest);
        let whole = solve_nest(&nest, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut solving = AoeSolving::new(&nest, &options);
        let mut steps = 1;
        let status = loop {
            let status = solving.step(Duration::ZERO);
            if status.is_done() {
                break status;
            }
            steps += 1;
        };
        assert_eq!(
            status,
            Status::Finished {
                proven_optimal: false
            },
            "{name}"
        );
        let sliced = solving.outcome().unwrap().as_ref().unwrap();
        assert_eq!(sliced.route, whole.route, "{name}");
        assert_eq!(sliced.chains, whole.chains, "{name}");
        // Every stage in pieces: at least a step per 16 components' chains.
        assert!(steps > sliced.components / 16 + 3, "{name}: {steps} steps");
    }
}

/// A deadline already past ends the ordering at once: the route of the plain inner-first
/// order at worst, still checked, and the status says it was stopped.
#[test]
fn a_past_deadline_stops_the_ordering_with_a_checked_route() {
    let nest = cutroute_geometry::generate_nest(1000, 1);
    let options = engine_options(&nest);
    let mut solving = AoeSolving::new(&nest, &options);
    solving.stop_at(Instant::now());
    let status = cutroute_aoe::run_to_end(&mut solving, Duration::from_millis(40));
    assert_eq!(status, Status::Stopped);
    let solution = solving.outcome().unwrap().as_ref().unwrap();
    let b = nest.bounding_box();
    let tolerance = 1e-6 * ((b.max.x - b.min.x) + (b.max.y - b.min.y));
    solution
        .route
        .validate(&nest, 10.0 * tolerance)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(solution.route.idle_length() <= solution.unordered_idle_length + 1e-9);
}

/// Half the odd-degree vertices of each connected component (at least one per component with
/// an edge): an Euler trail decomposition's pierce count, the minimum of any route.
fn fewest_pierces(graph: &PlaneGraph) -> usize {
    let n = graph.vertex_count();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    let mut degree = vec![0usize; n];
    for e in 0..graph.edge_count() {
        let (a, b) = graph.ends(e);
        degree[a] += 1;
        degree[b] += 1;
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra] = rb;
    }
    let mut odd = std::collections::HashMap::<usize, usize>::new();
    for v in (0..n).filter(|&v| degree[v] > 0) {
        *odd.entry(root(&mut parent, v)).or_default() += degree[v] % 2;
    }
    odd.values().map(|&k| (k / 2).max(1)).sum()
}

#[test]
fn parts_spaced_a_little_more_than_the_tolerance_are_cut_apart() {
    // Two squares 0.005 mm apart, planned at 0.001 mm: their facing edges are two edges of the
    // plan, two cuts 0.005 mm apart (as parts spaced by the kerf plus a small margin give on
    // the nest of equidistants). Neither is cut twice.
    let nest = Nest {
        sheet: None,
        parts: vec![
            part(vec![rect(0.0, 0.0, 10.0, 10.0)]),
            part(vec![rect(10.005, 0.0, 20.005, 10.0)]),
        ],
    };
    let solution = check(&nest, &AoeSolveOptions::default());
    assert!((solution.route.cut_length() - 80.0).abs() < 1e-6);
}
