//! The path-route jobs (sccp, gsccp, aoe) through the engine on real nests: every route shown
//! passes the independent checker, the progress's numbers are the route's, the lower bound
//! holds (and is tight where the optimum is known), cancel keeps the best so far, stepping in
//! tiny slices changes nothing.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use cutroute_aoe::{PlanGraph, PlanOptions};
use cutroute_engine::{
    idle_tree_bound, open_document, run_to_end, start_job, JobStatus, PlanBound,
};
use cutroute_geometry::{
    Contour, MachineParameters, Nest, Objective, Part, PathRoute, PathRouteError, Point, Span,
    SplitMix64,
};
use cutroute_protocol::{JobRequest, Problem, Progress, Solution, SolverKind, SolverParams};
use web_time::{Duration, Instant};

const NEST01: &str = "nests/tflex/Nest01.tfnesting";
const NEST02: &str = "nests/tflex/Nest02.tfnesting";
const NESTED: &str = "nests/dbs/nested.dbs";
const TEST1: &str = "nests/dbs-json/test1.dbs.json";

fn problem(relative: &str) -> Problem {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    let bytes = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("missing test file {}: {e}", path.display()));
    open_document(relative, &bytes).expect("opens").problem
}

fn nest_of(problem: &Problem) -> (&Nest, Point, Option<Point>) {
    match problem {
        Problem::Nest {
            nest,
            start,
            finish,
        } => (nest, *start, *finish),
        Problem::PcgtspText { .. } => panic!("a nest"),
    }
}

fn request(problem: &Problem, solver: SolverKind, params: SolverParams) -> JobRequest {
    JobRequest {
        job_id: 5,
        problem: problem.clone(),
        solver,
        params,
    }
}

fn params(time_limit_s: f64, objective: Objective) -> SolverParams {
    SolverParams {
        time_limit_s,
        objective,
        ..SolverParams::default()
    }
}

fn value(objective: Objective, machine: &MachineParameters, route: &PathRoute) -> f64 {
    objective.value(
        machine,
        route.cut_length(),
        route.idle_length(),
        route.pierce_count(),
    )
}

/// Checks a progress report against its own route: the route passes `PathRoute::problems`
/// (contour cut twice allowed only for routes of whole contours: "ccp", "standard"), the upper
/// bound is the objective's value of the route, the lower bound does not exceed it, and exactly
/// one alternative is chosen, with the route's numbers.
fn check_progress(
    what: &str,
    problem: &Problem,
    params: &SolverParams,
    progress: &Progress,
) -> PathRoute {
    let (nest, start, finish) = nest_of(problem);
    assert!(progress.route().is_none(), "{what}: a path route only");
    let route = progress.path_route().cloned().expect("a path route");
    assert_eq!((route.start, route.finish), (start, finish), "{what}");
    let chosen: Vec<_> = progress.alternatives.iter().filter(|a| a.chosen).collect();
    assert_eq!(chosen.len(), 1, "{what}: {:?}", progress.alternatives);
    let chosen = chosen[0];
    let overlaps_allowed = matches!(chosen.name.as_str(), "ccp" | "standard");
    // The solvers' own check tolerance: 10⁻⁶ of the nest's width plus height.
    let b = nest.bounding_box();
    let tolerance = 1e-6 * ((b.max.x - b.min.x) + (b.max.y - b.min.y)).max(1.0);
    let problems = route.problems(nest, tolerance);
    assert!(
        problems
            .iter()
            .all(|p| overlaps_allowed && matches!(p, PathRouteError::Overlap { .. })),
        "{what}: {problems:?}"
    );
    let machine = &params.machine;
    let expected = value(params.objective, machine, &route);
    let ub = progress.bounds.upper.expect("an upper bound");
    assert!(
        (ub - expected).abs() <= 1e-9 * expected,
        "{what}: {ub} vs {expected}"
    );
    let lb = progress.bounds.lower.expect("a lower bound");
    assert!(lb > 0.0 && lb <= ub, "{what}: lb {lb} ub {ub}");
    assert_eq!(
        progress.bounds.unit,
        params.objective.unit(),
        "{what}: the bounds are in the objective's unit"
    );
    // The idle bound (mm) holds for the route, and the chosen candidate carries it.
    let idle_lb = progress.idle_lower_bound.expect("an idle lower bound");
    assert!(
        idle_lb >= 0.0 && idle_lb <= route.idle_length() + 1e-9,
        "{what}: idle lb {idle_lb} idle {}",
        route.idle_length()
    );
    assert_eq!(chosen.idle_lower_bound, Some(idle_lb), "{what}");
    assert_eq!(progress.idle_upper_bound(), Some(route.idle_length()));
    assert_eq!(chosen.pierces, route.pierce_count(), "{what}");
    assert!((chosen.idle_length - route.idle_length()).abs() < 1e-6);
    assert!((chosen.cut_length - route.cut_length()).abs() < 1e-6);
    assert!((chosen.time_s - route.time(machine)).abs() < 1e-9 * chosen.time_s.max(1.0));
    assert!((chosen.cost - route.cost(machine)).abs() < 1e-9 * chosen.cost.max(1.0));
    route
}

#[test]
fn every_path_solver_returns_a_checked_route_with_its_numbers() {
    for file in [NEST01, NEST02, NESTED, TEST1] {
        let problem = problem(file);
        for (solver, names) in [
            (SolverKind::Sccp, &["ccp", "chains"][..]),
            (
                SolverKind::Gsccp,
                &["ccp", "standard", "chains", "junctions"][..],
            ),
            (SolverKind::Aoe, &["aoe"][..]),
        ] {
            for objective in [Objective::Time, Objective::Cost] {
                let params = params(1.0, objective);
                let what = format!("{file} {} {}", solver.name(), objective.name());
                let mut job = start_job(&request(&problem, solver, params.clone())).unwrap();
                let mut reports = 0;
                let result = run_to_end(job.as_mut(), &mut |p| {
                    reports += 1;
                    if p.path_route().is_some() {
                        check_progress(&what, &problem, &params, p);
                    }
                });
                check_progress(&what, &problem, &params, &result);
                let listed: Vec<&str> = result
                    .alternatives
                    .iter()
                    .map(|a| a.name.as_str())
                    .collect();
                assert_eq!(listed, names, "{what}");
                assert!(
                    result.phase.to_string().contains(' ')
                        && !result.phase.to_string().contains("failed"),
                    "{what}: {}",
                    result.phase
                );
                if solver == SolverKind::Gsccp {
                    // The chosen route is the best of the checked candidates by the objective.
                    let key = |a: &cutroute_protocol::RouteSummary| match objective {
                        Objective::Time => a.time_s,
                        Objective::Cost => a.cost,
                    };
                    let chosen = result.alternatives.iter().find(|a| a.chosen).unwrap();
                    for a in result.alternatives.iter().filter(|a| a.failure.is_none()) {
                        assert!(key(chosen) <= key(a) + 1e-9, "{what}: {a:?}");
                    }
                }
            }
        }
    }
}

#[test]
fn common_edges_are_cut_once_on_nest01() {
    let problem = problem(NEST01);
    let (nest, ..) = nest_of(&problem);
    // The plan graph merges the edges two parts share; every piece of such a common edge must be
    // under exactly one tool-on span of the route (twice would be the standard cut of both
    // contours, zero an uncut edge).
    let plan = PlanGraph::from_nest(nest, &PlanOptions::default()).expect("a plan graph");
    let common_edges: Vec<usize> = (0..plan.graph().edge_count())
        .filter(|&e| plan.edge_contours(e).len() == 2)
        .collect();
    // Five parts in a row, each touching the next along y = 0.
    assert_eq!(common_edges.len(), 4, "Nest01's common edges");
    let common: Vec<Point> = common_edges
        .iter()
        .flat_map(|&e| plan.edge_spans(e))
        .flat_map(|s| [0.1, 0.3, 0.5, 0.7, 0.9].map(|t| s.point_at(t)))
        .collect();
    let near = 1e-2;
    for solver in [SolverKind::Sccp, SolverKind::Gsccp, SolverKind::Aoe] {
        let params = params(1.0, Objective::Time);
        let mut job = start_job(&request(&problem, solver, params)).unwrap();
        let result = run_to_end(job.as_mut(), &mut |_| {});
        let route = result.solution.and_then(Solution::into_path_route).unwrap();
        let spans: Vec<&Span> = route.paths.iter().flat_map(|p| &p.spans).collect();
        for (i, &m) in common.iter().enumerate() {
            let cuts = spans.iter().filter(|s| s.distance_to(m) <= near).count();
            assert_eq!(
                cuts, 1,
                "{solver:?}: common piece {i} at {m:?} cut {cuts} times"
            );
        }
    }
}

/// AOE's lower bound on grids of touching rectangles, whose optimal cut length and pierces are
/// known: every edge once ((rows + 1)·columns·w + (columns + 1)·rows·h) and one trail per pair
/// of odd T-junctions ((columns − 1) + (rows − 1)); the bound is exactly that plus the idle
/// travel to the plan, and the route reaches its pierces and cut.
#[test]
fn the_aoe_lower_bound_is_the_known_optimum_of_cut_and_pierces_on_grids() {
    let machine = MachineParameters::default();
    for (columns, rows) in [(2, 1), (3, 3), (5, 4), (10, 10)] {
        let (w, h) = (50.0, 30.0);
        let nest = cutroute_segments::rectangle_grid(columns, rows, w, h);
        let start = Point::new(0.0, -20.0);
        let problem = Problem::Nest {
            nest,
            start,
            finish: None,
        };
        let cut = (rows + 1) as f64 * columns as f64 * w + (columns + 1) as f64 * rows as f64 * h;
        let pierces = (columns - 1) + (rows - 1);
        for objective in [Objective::Time, Objective::Cost] {
            let params = params(1.0, objective);
            let mut job = start_job(&request(&problem, SolverKind::Aoe, params.clone())).unwrap();
            let result = run_to_end(job.as_mut(), &mut |_| {});
            let route = check_progress("grid", &problem, &params, &result);
            assert_eq!(route.pierce_count(), pierces.max(1));
            assert!((route.cut_length() - cut).abs() < 1e-6);
            let known = objective.value(&machine, cut, 20.0, pierces.max(1));
            let lb = result.bounds.lower.unwrap();
            // Equal but for the slack the bound leaves for the plan's merging tolerance (four
            // tolerances, here 10⁻⁶ of the grid's width plus height, per plan edge).
            assert!(
                lb <= known && known - lb <= 1e-4 * known,
                "{columns}×{rows}: {lb} vs {known}"
            );
            // Segment cutting: the weaker bound (routes may cut edges twice) stays below.
            let mut job = start_job(&request(&problem, SolverKind::Gsccp, params.clone())).unwrap();
            let result = run_to_end(job.as_mut(), &mut |_| {});
            check_progress("grid gsccp", &problem, &params, &result);
        }
    }
}

#[test]
fn cancel_mid_run_keeps_the_best_route_so_far() {
    let problem = problem(NEST02);
    let params = params(6.0, Objective::Cost);
    for solver in [SolverKind::Gsccp, SolverKind::Sccp] {
        let mut job = start_job(&request(&problem, solver, params.clone())).unwrap();
        let started = Instant::now();
        // Step until an ensemble is running (past CCP-Relax), as the worker does, then "cancel":
        // the worker sends the job's progress without another step.
        let mut during_ccp = false;
        loop {
            assert_eq!(job.step(Duration::from_millis(40)), JobStatus::Running);
            let progress = job.progress();
            if progress.phase.to_string().contains("CCP") && progress.path_route().is_some() {
                // The best so far while CCP-Relax runs is its own route, checked.
                check_progress("during ccp", &problem, &params, &progress);
                during_ccp = true;
            }
            if progress.phase.to_string().contains("ensemble (")
                && started.elapsed().as_secs_f64() > 1.0
            {
                break;
            }
            assert!(started.elapsed().as_secs() < 50, "{}", progress.phase);
        }
        assert!(during_ccp, "CCP-Relax's route is shown while it runs");
        let cancelled = job.progress();
        let route = check_progress("cancelled", &problem, &params, &cancelled);
        let (nest, ..) = nest_of(&problem);
        assert!(route.pierce_count() <= nest.contour_count());
    }
}

/// Where the run is deterministic (searches that end by their own rules long before the time
/// limit), the job stepped in 1 ms slices gives exactly `solve_gsccp`'s / `solve_nest`'s route.
#[test]
fn stepped_runs_equal_one_shot_runs() {
    for file in [NEST01, "nests/dbs-json/E1X_6_01.dbs.json"] {
        let problem = problem(file);
        let (nest, start, finish) = nest_of(&problem);
        for solver in [SolverKind::Sccp, SolverKind::Gsccp] {
            let params = params(120.0, Objective::Time);
            let mut job = start_job(&request(&problem, solver, params.clone())).unwrap();
            while job.step(Duration::from_millis(1)) == JobStatus::Running {}
            let stepped = job.progress();
            assert!(stepped.elapsed_s < 60.0, "ended by its own rules");
            let options = cutroute_segments::GsccpOptions {
                sccp: cutroute_segments::SccpOptions {
                    start,
                    finish,
                    time_limit: Duration::from_secs(120),
                    seed: params.seed,
                    ..Default::default()
                },
                kinds: if solver == SolverKind::Sccp {
                    vec![cutroute_segments::EnsembleKind::Chains]
                } else {
                    cutroute_segments::EnsembleKind::ALL.to_vec()
                },
                machine: params.machine,
                objective: params.objective,
                seed: params.seed,
                ..Default::default()
            };
            let one_shot =
                cutroute_segments::solve_gsccp(nest, &options, &AtomicBool::new(false)).unwrap();
            assert_eq!(
                stepped.path_route(),
                Some(&one_shot.route),
                "{file} {solver:?}"
            );
        }
        let params = params(1.0, Objective::Time);
        let mut job = start_job(&request(&problem, SolverKind::Aoe, params)).unwrap();
        while job.step(Duration::from_millis(1)) == JobStatus::Running {}
        let options = cutroute_aoe::AoeSolveOptions {
            plan: cutroute_aoe::PlanOptions {
                tolerance: {
                    let b = nest.bounding_box();
                    1e-6 * ((b.max.x - b.min.x) + (b.max.y - b.min.y)).max(1.0)
                },
                ..Default::default()
            },
            start,
            finish,
            heat: None,
        };
        let one_shot = cutroute_aoe::solve_nest(nest, &options).unwrap();
        assert_eq!(
            job.progress().solution.and_then(Solution::into_path_route),
            Some(one_shot.route),
            "{file} aoe"
        );
    }
}

#[test]
fn runs_in_one_millisecond_slices_stay_valid() {
    for file in [NESTED, NEST01] {
        let problem = problem(file);
        for solver in [SolverKind::Sccp, SolverKind::Gsccp] {
            let params = params(1.0, Objective::Time);
            let mut job = start_job(&request(&problem, solver, params.clone())).unwrap();
            let mut steps = 0;
            while job.step(Duration::from_millis(1)) == JobStatus::Running {
                steps += 1;
                if steps % 97 == 0 {
                    let p = job.progress();
                    if p.path_route().is_some() {
                        check_progress("1 ms", &problem, &params, &p);
                    }
                }
            }
            assert!(steps > 10, "{file}: {steps} steps");
            check_progress("1 ms end", &problem, &params, &job.progress());
        }
    }
}

#[test]
fn path_solvers_refuse_pcgtsp_instances() {
    let problem = problem("pcgtsp/industrial/e1x_6.pcglns");
    for solver in [SolverKind::Sccp, SolverKind::Gsccp, SolverKind::Aoe] {
        let error = start_job(&request(&problem, solver, SolverParams::default()))
            .err()
            .expect("refused");
        assert!(error.to_string().contains("PCGTSP"), "{error}");
    }
}

/// One rectangle with the head straight below its lower edge: the optimum is known (its
/// perimeter, one pierce, the 7 mm up to the edge), and every path solver's lower bound and
/// route both reach it.
#[test]
fn bounds_meet_at_the_known_optimum_of_one_rectangle() {
    let machine = MachineParameters::default();
    let problem = Problem::Nest {
        nest: cutroute_segments::rectangle_grid(1, 1, 50.0, 30.0),
        start: Point::new(20.0, -7.0),
        finish: None,
    };
    for solver in [SolverKind::Sccp, SolverKind::Gsccp, SolverKind::Aoe] {
        for objective in [Objective::Time, Objective::Cost] {
            let params = params(1.0, objective);
            let mut job = start_job(&request(&problem, solver, params.clone())).unwrap();
            let result = run_to_end(job.as_mut(), &mut |_| {});
            check_progress("rectangle", &problem, &params, &result);
            let optimum = objective.value(&machine, 160.0, 7.0, 1);
            let (lb, ub) = (result.bounds.lower.unwrap(), result.bounds.upper.unwrap());
            assert!((ub - optimum).abs() <= 1e-9 * optimum, "{solver:?}: {ub}");
            // Equal but for the slack the bound leaves for the plan's merging tolerance.
            assert!(
                lb <= optimum && optimum - lb <= 1e-5 * optimum,
                "{solver:?}: {lb}"
            );
        }
    }
}

/// Every order of `0..n`, by Heap's algorithm.
fn permutations(n: usize) -> Vec<Vec<usize>> {
    fn heap(k: usize, items: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if k <= 1 {
            out.push(items.clone());
            return;
        }
        for i in 0..k {
            heap(k - 1, items, out);
            let j = if k.is_multiple_of(2) { i } else { 0 };
            items.swap(j, k - 1);
        }
    }
    let mut out = Vec::new();
    heap(n, &mut (0..n).collect(), &mut out);
    out
}

/// The idle bound against brute force on nests of separate circles, cut whole from one
/// pierce each (standard cutting, every path solver's CCP seed): the optimum over orders and
/// pierce points, enumerated with `N` pierce candidates per circle, is at most the true optimum
/// plus one candidate spacing per circle (snapping a pierce point to its nearest candidate moves
/// it by half a spacing, and it ends two idle moves), so the bound must stay below the
/// enumerated optimum less those spacings. It must also stay below the set-distance path (the
/// same enumeration with circles as sets), and be no trivial 0.
#[test]
fn the_idle_bound_is_below_brute_force_on_separate_circles() {
    const N: usize = 48;
    let mut rng = SplitMix64::new(20261124);
    for trial in 0..30 {
        let k = 3 + trial % 3;
        let mut circles: Vec<(Point, f64)> = Vec::new();
        while circles.len() < k {
            let c = Point::new(rng.range(0.0, 200.0), rng.range(0.0, 200.0));
            let r = rng.range(2.0, 15.0);
            if circles.iter().all(|&(d, s)| c.distance(d) > r + s + 1.0) {
                circles.push((c, r));
            }
        }
        let start = Point::new(rng.range(-50.0, 250.0), rng.range(-50.0, 250.0));
        let finish = (trial % 2 == 0).then(|| Point::new(rng.range(-50.0, 250.0), -60.0));
        let nest = Nest {
            sheet: None,
            parts: circles
                .iter()
                .map(|&(c, r)| Part {
                    name: "circle".into(),
                    contours: vec![Contour::circle(c, r, false)],
                })
                .collect(),
        };
        let candidates: Vec<Vec<Point>> = circles
            .iter()
            .map(|&(c, r)| {
                (0..N)
                    .map(|i| {
                        let a = i as f64 * std::f64::consts::TAU / N as f64;
                        Point::new(c.x + r * a.cos(), c.y + r * a.sin())
                    })
                    .collect()
            })
            .collect();
        let mut enumerated = f64::INFINITY;
        let mut set_path = f64::INFINITY;
        for order in permutations(k) {
            // Shortest idle over pierce candidates along this order (DP over the candidates).
            let mut best: Vec<f64> = candidates[order[0]]
                .iter()
                .map(|p| start.distance(*p))
                .collect();
            for w in order.windows(2) {
                best = candidates[w[1]]
                    .iter()
                    .map(|q| {
                        candidates[w[0]]
                            .iter()
                            .zip(&best)
                            .map(|(p, b)| b + p.distance(*q))
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect();
            }
            let last = &candidates[order[k - 1]];
            let total = last
                .iter()
                .zip(&best)
                .map(|(p, b)| b + finish.map_or(0.0, |f| p.distance(f)))
                .fold(f64::INFINITY, f64::min);
            enumerated = enumerated.min(total);
            let to = |p: Point, i: usize| (p.distance(circles[i].0) - circles[i].1).max(0.0);
            let mut set = to(start, order[0]) + finish.map_or(0.0, |f| to(f, order[k - 1]));
            for w in order.windows(2) {
                let ((a, ra), (b, rb)) = (circles[w[0]], circles[w[1]]);
                set += (a.distance(b) - ra - rb).max(0.0);
            }
            set_path = set_path.min(set);
        }
        let spacings: f64 = circles
            .iter()
            .map(|&(_, r)| std::f64::consts::TAU * r / N as f64)
            .sum();
        let spans: Vec<Vec<Span>> = nest
            .parts
            .iter()
            .map(|p| p.contours[0].spans().collect())
            .collect();
        let tree = idle_tree_bound(&spans, start, finish, 0.0);
        let plan = PlanBound::new(&nest, start, finish, nest.check_tolerance()).unwrap();
        assert_eq!(plan.components, k, "trial {trial}");
        for (what, lb) in [("tree", tree), ("plan", plan.idle_length)] {
            assert!(
                lb <= enumerated - spacings + 1e-9,
                "trial {trial} {what}: {lb} > {enumerated} − {spacings}"
            );
            assert!(
                lb <= set_path + 1e-9,
                "trial {trial} {what}: {lb} > {set_path}"
            );
        }
        // Not trivial: a spanning tree is at least half of the shortest path through the
        // circles' sets when they are small against their distances.
        assert!(
            tree >= 0.3 * set_path,
            "trial {trial}: {tree} vs {set_path}"
        );
        // The plan's tree is the same less the merging tolerance on each of its k + 1 edges.
        let slack = 2.0 * nest.check_tolerance() * (k + 1) as f64;
        assert!(plan.idle_length >= tree - slack - 1e-9, "trial {trial}");
        assert!(plan.whole_contours, "trial {trial}: no circles touch");

        // The sccp job adds the continuous bound of CCP (every route of its cuts each circle
        // whole). Its objective bound holds for the enumerated route, its idle bound for every
        // route at least as good as its own, and it is no weaker than the tree.
        let problem = Problem::Nest {
            nest: nest.clone(),
            start,
            finish,
        };
        let params = params(2.0, Objective::Time);
        let mut job = start_job(&request(&problem, SolverKind::Sccp, params.clone())).unwrap();
        let progress = run_to_end(job.as_mut(), &mut |_| {});
        let route = check_progress(&format!("trial {trial}"), &problem, &params, &progress);
        let (ub, lb) = (
            progress.bounds.upper.unwrap(),
            progress.bounds.lower.unwrap(),
        );
        let idle_lb = progress.idle_lower_bound.unwrap();
        let enumerated_value =
            Objective::Time.value(&params.machine, route.cut_length(), enumerated, k);
        assert!(
            lb <= enumerated_value + 1e-9,
            "trial {trial}: lb {lb} > {enumerated_value}"
        );
        if enumerated_value <= ub {
            assert!(
                idle_lb <= enumerated + 1e-9,
                "trial {trial}: idle lb {idle_lb} > {enumerated}"
            );
        }
        assert!(idle_lb >= plan.idle_length, "trial {trial}");
        // Close: the tree alone is 3–30 % below the enumerated optimum on these nests.
        assert!(
            idle_lb >= 0.97 * (enumerated - spacings),
            "trial {trial}: idle lb {idle_lb} against {enumerated} − {spacings} (tree {tree})"
        );
    }
}

/// [`PlanBound::any_route_with_ccp`] and [`PlanBound::idle_at_most`] against their definition,
/// minimised by brute force over whole numbers of extra pierces `e` and a fine grid of lengths
/// `r` cut twice: a route idles at least `max(tree, ccp − 2D·e − r)` and is worth
/// `value(plan cut + r, idle, n + e)`. The objective bound must equal that minimum (up to the
/// grid), and the idle bound must not exceed the least idle of a route worth at most `upper`.
#[test]
fn the_bounds_from_ccp_are_the_minimum_over_extra_pierces_and_recut() {
    let mut rng = SplitMix64::new(20261125);
    for trial in 0..300 {
        let machine = MachineParameters {
            idle_speed: rng.range(50.0, 1000.0),
            cut_speed: rng.range(1.0, 100.0),
            pierce_time: rng.range(0.0, 10.0),
            idle_price_per_metre: rng.range(0.1, 5.0),
            cut_price_per_metre: rng.range(0.1, 5.0),
            pierce_price: rng.range(0.0, 3.0),
            ..MachineParameters::default()
        };
        let objective = if trial % 2 == 0 {
            Objective::Time
        } else {
            Objective::Cost
        };
        let tree = rng.range(0.0, 500.0);
        let ccp = tree + rng.range(0.0, 2000.0);
        let plan = PlanBound {
            cut_length: rng.range(100.0, 5000.0),
            components: 1 + (trial % 7),
            trail_pierces: 1 + (trial % 7),
            idle_length: tree,
            whole_contours: true,
            diameter: rng.range(5.0, 3000.0),
            overlap: 0.0,
        };
        let n = plan.components;
        let value = |r: f64, idle: f64, e: usize| {
            objective.value(&machine, plan.cut_length + r, idle, n + e)
        };
        let idle_of = |e: usize, r: f64| tree.max(ccp - 2.0 * plan.diameter * e as f64 - r);
        let grid: Vec<f64> = (0..=400).map(|i| ccp * i as f64 / 400.0).collect();
        let mut least = f64::INFINITY;
        for e in 0..=400usize {
            for &r in &grid {
                least = least.min(value(r, idle_of(e, r), e));
            }
        }
        let bound = plan.any_route_with_ccp(ccp, objective, &machine);
        // Below by at most the grid's step and a pierce (the bound lets `e` be fractional).
        let zero = objective.value(&machine, 0.0, 0.0, 0);
        let per_mm = (objective.value(&machine, 1.0, 0.0, 0) - zero)
            .max(objective.value(&machine, 0.0, 1.0, 0) - zero);
        let slack = ccp / 400.0 * per_mm + (objective.value(&machine, 0.0, 0.0, 1) - zero);
        assert!(
            bound <= least + 1e-9 * least,
            "trial {trial}: {bound} > {least}"
        );
        assert!(
            bound >= least - slack - 1e-9 * least,
            "trial {trial}: {bound} ≪ {least}"
        );
        // Routes worth at most `upper` (a route at e = 0, r = 0 idling a little over ccp).
        let upper = value(0.0, ccp + rng.range(0.0, 300.0), 0);
        let mut least_idle = f64::INFINITY;
        for e in 0..=400usize {
            for &r in &grid {
                let idle = idle_of(e, r);
                if value(r, idle, e) <= upper {
                    least_idle = least_idle.min(idle);
                }
            }
        }
        let idle_bound = plan.idle_at_most(ccp, Some(upper), objective, &machine);
        assert!(
            idle_bound <= least_idle + 1e-9 * least_idle.max(1.0),
            "trial {trial}: {idle_bound} > {least_idle}"
        );
        assert!(idle_bound >= tree, "trial {trial}");
        // Where contours touch, nothing carries over.
        let touching = PlanBound {
            whole_contours: false,
            ..plan
        };
        assert_eq!(
            touching.any_route_with_ccp(ccp, objective, &machine),
            touching.any_route(objective, &machine)
        );
        assert_eq!(
            touching.idle_at_most(ccp, Some(upper), objective, &machine),
            tree
        );
    }
}

/// No components give 0; one gives its distance from the start, and to the finish as well: the
/// tool never idles from the start straight to the finish, so that edge is not in the tree.
#[test]
fn the_idle_tree_of_no_components_is_zero_and_of_one_is_the_start_distance() {
    let start = Point::new(0.0, 0.0);
    assert_eq!(idle_tree_bound(&[], start, None, 0.0), 0.0);
    let ring: Vec<Span> = Contour::circle(Point::new(30.0, 40.0), 10.0, false)
        .spans()
        .collect();
    let one = idle_tree_bound(std::slice::from_ref(&ring), start, None, 0.0);
    assert!((one - 40.0).abs() < 1e-9, "{one}");
    let back = idle_tree_bound(&[ring], start, Some(start), 0.0);
    assert!((back - 80.0).abs() < 1e-9, "{back}");
}
