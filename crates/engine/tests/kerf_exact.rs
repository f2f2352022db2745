//! The exact solver with kerf and leads (issue #17): it searches the discretised full-route
//! model, its routes pass the independent checker, and its lower bound is below the route it
//! reports and below the brute-force optimum of that model.

mod common;

use common::{nest_of, nest_problem, plasma};

use cutroute_engine::{build_full_route_model, run_to_end, start_job};
use cutroute_geometry::{Contour, Nest, Part, Point, Route};
use cutroute_pcgtsp::Instance;
use cutroute_protocol::{
    JobRequest, KerfNote, KerfSource, Phase, Problem, Progress, SolverKind, SolverParams,
};

fn exact_request(problem: &Problem, step: f64, limit: f64) -> JobRequest {
    JobRequest {
        job_id: 3,
        problem: problem.clone(),
        solver: SolverKind::Exact,
        params: SolverParams {
            time_limit_s: limit,
            kerf: plasma(),
            discretisation_step_mm: step,
            ..SolverParams::default()
        },
    }
}

/// Runs the job; every progress with a route has leads on each step, an upper bound equal to
/// its idle length and no lower bound above it.
fn run(request: &JobRequest) -> Progress {
    let mut job = start_job(request).expect("starts");
    run_to_end(job.as_mut(), &mut |p| {
        if let Some(route) = p.route() {
            assert!(route.steps.iter().all(|s| s.leads.is_some()));
            assert_eq!(p.bounds.upper, Some(route.idle_length()));
        }
        if let (Some(lower), Some(upper)) = (p.bounds.lower, p.bounds.upper) {
            assert!(lower <= upper, "lower bound {lower} > route {upper}");
        }
        assert!(matches!(p.phase, Phase::Kerf { .. }), "{:?}", p.phase);
    })
}

fn checked(problem: &Problem, progress: &Progress) -> Route {
    let nest = nest_of(problem);
    let route = progress.route().cloned().expect("a route");
    let problems = route.problems(nest, &nest.containment_forest(), 1e-6);
    assert!(problems.is_empty(), "{:?}", problems.first());
    assert!(route.steps.iter().all(|s| s.leads.is_some()));
    route
}

fn square(x: f64, y: f64, side: f64) -> Contour {
    Contour::rectangle(x, y, x + side, y + side)
}

/// Four contours: a plate with a square hole (the hole first), a square and a disc.
fn tiny_nest() -> Nest {
    let mut nest = Nest {
        sheet: None,
        parts: vec![
            Part {
                name: "plate".into(),
                contours: vec![square(0.0, 0.0, 80.0), square(25.0, 25.0, 30.0)],
            },
            Part {
                name: "square".into(),
                contours: vec![square(110.0, 0.0, 40.0)],
            },
            Part {
                name: "disc".into(),
                contours: vec![Contour::circle(Point::new(130.0, 90.0), 15.0, true)],
            },
        ],
    };
    nest.normalize_orientation();
    nest
}

/// The optimum of a PCGTSP instance by dynamic programming over the sets of visited clusters
/// (Held–Karp with precedence), independent of the solver's code.
fn brute_force(instance: &Instance) -> f64 {
    let clusters = instance.clusters.len() - 1; // cluster 0 is the depot
    let bit = |c: usize| 1usize << (c - 1);
    let mut before = vec![0usize; clusters + 1];
    for &(a, b) in &instance.precedence {
        before[b] |= bit(a);
    }
    let n = instance.node_count;
    let full = (1usize << clusters) - 1;
    let mut dp = vec![vec![f64::INFINITY; n]; full + 1];
    for c in 1..=clusters {
        if before[c] == 0 {
            for &v in &instance.clusters[c] {
                dp[bit(c)][v] = instance.arc_cost(0, v);
            }
        }
    }
    for mask in 1..=full {
        for c in 1..=clusters {
            if mask & bit(c) == 0 {
                continue;
            }
            for &v in &instance.clusters[c] {
                let here = dp[mask][v];
                if !here.is_finite() {
                    continue;
                }
                for d in 1..=clusters {
                    if mask & bit(d) != 0 || before[d] & !mask != 0 {
                        continue;
                    }
                    for &w in &instance.clusters[d] {
                        let next = here + instance.arc_cost(v, w);
                        let slot = &mut dp[mask | bit(d)][w];
                        if next < *slot {
                            *slot = next;
                        }
                    }
                }
            }
        }
    }
    (0..n)
        .map(|v| dp[full][v] + instance.arc_cost(v, 0))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn exact_with_leads_is_bounded_by_the_brute_force_optimum_of_its_model() {
    let nest = tiny_nest();
    let problem = Problem::Nest {
        nest: nest.clone(),
        start: Point::new(-10.0, -10.0),
        finish: None,
    };
    let step = 40.0;
    let model = build_full_route_model(&nest, plasma(), step, Point::new(-10.0, -10.0), None)
        .expect("a valid step")
        .expect("every contour has room");
    assert!(
        model.instance.node_count > 4 * 4,
        "several candidates per contour"
    );
    // The hole before its plate.
    assert!(!model.instance.precedence.is_empty());
    let optimum = brute_force(&model.instance);
    assert!(optimum.is_finite());
    let progress = run(&exact_request(&problem, step, 10.0));
    let route = checked(&problem, &progress);
    let lower = progress.bounds.lower.expect("a lower bound");
    // The route is a tour of the model: never below its optimum; the bound never above it.
    assert!(route.idle_length() >= optimum - 1e-6);
    assert!(lower <= optimum + 1e-9, "bound {lower} > optimum {optimum}");
    assert!(lower <= route.idle_length());
    // Four contours are proven within the limit, and then the route is the optimum.
    assert!(progress.proven_optimal, "{:?}", progress.phase);
    assert!((route.idle_length() - optimum).abs() < 1e-6);
    assert!(matches!(
        progress.phase,
        Phase::Kerf {
            note: KerfNote::Leads {
                source: KerfSource::FullRoute
            },
            ..
        }
    ));
}

#[test]
fn exact_with_leads_gives_checked_routes_on_small_nests() {
    for file in ["nests/dbs-json/E1X_6_01.dbs.json", "nests/dbs/seven.dbs"] {
        let problem = nest_problem(file);
        // Time for a bound on a loaded machine (the exact search's share of the slices).
        let progress = run(&exact_request(&problem, 50.0, 10.0));
        let route = checked(&problem, &progress);
        assert_eq!(
            route.steps.len(),
            nest_of(&problem).contour_count(),
            "{file}"
        );
        let lower = progress.bounds.lower.expect("a lower bound");
        assert!(lower <= route.idle_length(), "{file}");
    }
}

#[test]
fn exact_with_leads_names_contours_without_room() {
    // ring.dbs: a 4 mm ring, no room inside for an 8 mm lead-in at kerf 2 and d₁ 5.
    let problem = nest_problem("nests/dbs/ring.dbs");
    let progress = run(&exact_request(&problem, 50.0, 2.0));
    assert!(progress.route().is_none());
    assert!(
        matches!(
            &progress.phase,
            Phase::Kerf {
                note: KerfNote::NoRoom { contours, .. },
                ..
            } if !contours.is_empty()
        ),
        "{:?}",
        progress.phase
    );
}

#[test]
fn exact_with_leads_refuses_a_heat_penalty() {
    let problem = nest_problem("nests/dbs-json/E1X_6_01.dbs.json");
    let mut request = exact_request(&problem, 50.0, 1.0);
    request.params.thermal.weight = 1.0;
    assert!(start_job(&request).is_err());
}

/// The full-route model built a contour or a matrix row per call (each call's time already
/// up) is the model built in one call, on a real nest.
#[test]
fn the_full_route_model_in_pieces_equals_the_model_in_one_piece() {
    let problem = nest_problem("nests/dbs/seven.dbs");
    let nest = nest_of(&problem);
    let start = Point::new(0.0, 0.0);
    let mut whole = cutroute_engine::FullRouteBuilder::new(nest, plasma(), 50.0, start, None)
        .expect("a positive step");
    let far = web_time::Instant::now() + std::time::Duration::from_secs(3600);
    let whole = whole
        .advance(far)
        .expect("built in one call")
        .expect("leads fit on seven.dbs");
    let mut pieces = 0;
    let mut builder = cutroute_engine::FullRouteBuilder::new(nest, plasma(), 50.0, start, None)
        .expect("a positive step");
    let sliced = loop {
        pieces += 1;
        if let Some(model) = builder.advance(web_time::Instant::now()) {
            break model.expect("leads fit on seven.dbs");
        }
    };
    assert_eq!(sliced.instance, whole.instance);
    assert_eq!(sliced.nodes, whole.nodes);
    let n = whole.instance.node_count;
    assert!(pieces > n, "{pieces} calls for {n} nodes: a row per call");
}
