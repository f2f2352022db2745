//! Benchmark: the thermal targets of issue #19 for every solver on every real nest, through the
//! engine's jobs (`start_job`, the CLI's and the app's code path).
//!
//! `cargo run --release -p cutroute-bench --bin thermal_targets -- [--time-limit 2]
//! [--solvers nearest,ccp,…] [--filter NAME[,NAME…]] [--data DIR]`
//!
//! Inputs: every nest file of `data/nests` (dbs, dbs-json, dxf, svg, tflex) with at least two
//! contours (with one contour there is one pierce and H = 0 whatever the route). Per nest and
//! solver, three runs with σ = 50 mm, τ = 60 s, seed 1, `MachineParameters::default()`:
//! - **plain**: weight 0 (H reported only);
//! - **W=100**: `--thermal-sigma 50 --thermal-tau 60 --thermal-weight 100`;
//! - **hard**: `--rules part,sheet,islands --rules-hard` (weight 0).
//!
//! Prints a Markdown table: H plain and W=100 and the drop in %, idle length and machine time
//! plain → W=100, and for the hard run the violations left (part/sheet/islands, counted here
//! on the final route; "job: not in time" when the job's own final check would have run past
//! its time limit + 0.8 s and it reported none) and the
//! independent checker's verdict on the final route (`Route::problems` for contour routes,
//! `PathRoute::problems` for path routes; "ok, recut" when the only findings are pieces cut
//! twice, which standard cutting does on coincident contours and GSCCP accepts). Every H in the
//! table is recomputed here from the final route's pierces and times.
//!
//! Then a lower bound on H for the nests of one part with one hole (ring.dbs): see
//! [`one_hole_bound`].

use std::path::{Path, PathBuf};

use cutroute_engine::{check_path_rules, open_document, run_to_end, start_job};
use cutroute_geometry::{MachineParameters, Nest, PathRouteError, Point};
use cutroute_protocol::{
    JobRequest, Problem, Progress, RuleSet, SolverKind, SolverParams, ThermalSettings,
};
use cutroute_thermal::{
    check_rules, path_route_pierces, route_pierces, HeatModel, RuleCounts, RuleParams,
};

struct Input {
    name: String,
    nest: Nest,
    problem: Problem,
}

fn inputs(data: &Path, filter: &Option<Vec<String>>) -> Vec<Input> {
    let mut inputs = Vec::new();
    for (name, path) in cutroute_bench::real_nest_files(data) {
        if filter
            .as_ref()
            .is_some_and(|f| !f.iter().any(|n| name.contains(n.as_str())))
        {
            continue;
        }
        let bytes = std::fs::read(&path).expect("readable");
        if let Ok(document) = open_document(&name, &bytes) {
            if let Problem::Nest { nest, .. } = &document.problem {
                if nest.contour_count() >= 2 {
                    inputs.push(Input {
                        name,
                        nest: nest.clone(),
                        problem: document.problem,
                    });
                }
            }
        }
    }
    inputs
}

fn solve(input: &Input, solver: SolverKind, thermal: ThermalSettings, limit: f64) -> Progress {
    let request = JobRequest {
        job_id: 1,
        problem: input.problem.clone(),
        solver,
        params: SolverParams {
            time_limit_s: limit,
            seed: 1,
            thermal,
            ..SolverParams::default()
        },
    };
    match start_job(&request) {
        Ok(mut job) => run_to_end(job.as_mut(), &mut |_| {}),
        Err(e) => {
            // The table says "no route"; the reason goes to the log.
            eprintln!("{}: refused: {e}", solver.name());
            Progress::default()
        }
    }
}

/// H of the final route by the definition, every pair (no cut-off), and its idle length and
/// machine time.
fn measured(input: &Input, p: &Progress, model: &HeatModel) -> Option<(f64, f64, f64)> {
    let machine = MachineParameters::default();
    let (pierces, idle, time) = match (p.route(), p.path_route()) {
        (Some(r), _) => (
            route_pierces(r, &input.nest, &machine).ok()?,
            r.idle_length(),
            r.time(&input.nest, &machine),
        ),
        (None, Some(r)) => (
            path_route_pierces(r, &machine),
            r.idle_length(),
            r.time(&machine),
        ),
        _ => return None,
    };
    let mut h = 0.0;
    for (i, a) in pierces.iter().enumerate() {
        for b in &pierces[..i] {
            h += model.kernel((a.point - b.point).norm_squared(), a.time - b.time);
        }
    }
    if let Some(reported) = p.heat {
        assert!(
            (reported - h).abs() <= 1e-6 * h.max(1e-12),
            "{}: reported H {reported} vs {h}",
            input.name
        );
    }
    Some((h, idle, time))
}

/// The violations of the final route, counted by the rule check itself (path routes on their
/// contour route).
fn left_violations(input: &Input, p: &Progress, settings: &ThermalSettings) -> Option<RuleCounts> {
    let nest = &input.nest;
    let report = match (p.route(), p.path_route()) {
        (Some(route), _) => {
            check_rules(nest, route, settings.rules, &RuleParams::default()).ok()?
        }
        (None, Some(route)) => check_path_rules(nest, route, settings).ok()?,
        _ => return None,
    };
    Some(report.counts())
}

/// The independent checker's verdict on the final route.
fn checker(input: &Input, p: &Progress) -> String {
    let nest = &input.nest;
    if let Some(route) = p.route() {
        let problems = route.problems(nest, &nest.containment_forest(), 1e-3);
        return match problems.first() {
            None => "ok".into(),
            Some(e) => format!("FAILS: {e}"),
        };
    }
    if let Some(route) = p.path_route() {
        let problems = route.problems(nest, 10.0 * nest.check_tolerance());
        let recut = problems
            .iter()
            .any(|e| matches!(e, PathRouteError::Overlap { .. }));
        return match problems
            .iter()
            .find(|e| !matches!(e, PathRouteError::Overlap { .. }))
        {
            Some(e) => format!("FAILS: {e}"),
            None if recut => "ok, recut".into(),
            None => "ok".into(),
        };
    }
    format!("no route ({})", p.phase)
}

/// A lower bound on H over every route of whole contours of a nest of two contours, one inside
/// the other (a part with one hole): the hole is cut first, then the head moves to the outer
/// contour's pierce point, so the one pair of pierces is at most D apart in space and at most
/// pierce time + the hole's cut + D / idle speed apart in time, D the largest distance between
/// a point of the hole and one of the outer contour. D is bounded by dense samples (spacing
/// h₁, h₂ along the contours) plus (h₁ + h₂)/2. H ≥ exp(−D²/(2σ²) − Δt_max/τ).
fn one_hole_bound(nest: &Nest, model: &HeatModel) -> Option<f64> {
    let refs: Vec<_> = nest.contour_refs().collect();
    if refs.len() != 2 {
        return None;
    }
    let forest = nest.containment_forest();
    let (hole, outer) = match (forest.parent(refs[0]), forest.parent(refs[1])) {
        (Some(p), None) if p == refs[1] => (refs[0], refs[1]),
        (None, Some(p)) if p == refs[0] => (refs[1], refs[0]),
        _ => return None,
    };
    let (hole, outer) = (nest.contour(hole)?, nest.contour(outer)?);
    let samples = |c: &cutroute_geometry::Contour, n: usize| -> (Vec<Point>, f64) {
        let length = c.perimeter();
        let points = (0..n)
            .filter_map(|k| c.point_at_length(length * k as f64 / n as f64))
            .collect();
        (points, length / n as f64)
    };
    let (a, ha) = samples(hole, 2_000);
    let (b, hb) = samples(outer, 2_000);
    let mut d_max: f64 = 0.0;
    for p in &a {
        for q in &b {
            d_max = d_max.max(p.distance(*q));
        }
    }
    let d_max = d_max + 0.5 * (ha + hb);
    let machine = MachineParameters::default();
    let dt_max =
        machine.pierce_time + hole.perimeter() / machine.cut_speed + d_max / machine.idle_speed;
    Some(model.kernel(d_max * d_max, dt_max))
}

fn main() {
    let mut limit = 2.0;
    let mut solvers = vec![
        SolverKind::NearestNeighbour,
        SolverKind::Ccp,
        SolverKind::Heuristic,
        SolverKind::Exact,
        SolverKind::Chain,
        SolverKind::Sccp,
        SolverKind::Gsccp,
        SolverKind::Aoe,
    ];
    let mut filter: Option<Vec<String>> = None;
    let mut data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--time-limit" => limit = value().parse().expect("--time-limit SECONDS"),
            "--solvers" => {
                solvers = value()
                    .split(',')
                    .map(|s| {
                        SolverKind::ALL
                            .into_iter()
                            .find(|k| k.name() == s)
                            .unwrap_or_else(|| panic!("unknown solver {s}"))
                    })
                    .collect()
            }
            "--filter" => filter = Some(value().split(',').map(str::to_string).collect()),
            "--data" => data = PathBuf::from(value()),
            other => panic!("unknown argument {other}"),
        }
    }
    let model = HeatModel::new(50.0, 60.0).expect("σ and τ");
    let plain = ThermalSettings::default();
    let heated = ThermalSettings {
        weight: 100.0,
        ..plain
    };
    let hard = ThermalSettings {
        rules: RuleSet::ALL,
        hard: true,
        ..plain
    };
    let inputs = inputs(&data, &filter);
    println!(
        "| nest | contours | solver | H plain | H W=100 | drop | idle mm plain → W=100 | time s plain → W=100 | hard: left p/s/i | hard: checker |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut failures = Vec::new();
    for input in &inputs {
        for &solver in &solvers {
            let a = solve(input, solver, plain, limit);
            let b = solve(input, solver, heated, limit);
            let c = solve(input, solver, hard, limit);
            let (ma, mb) = (measured(input, &a, &model), measured(input, &b, &model));
            let cell = |m: Option<(f64, f64, f64)>, f: fn((f64, f64, f64)) -> String| {
                m.map_or("failed".to_string(), f)
            };
            let drop = match (ma, mb) {
                (Some((ha, ..)), Some((hb, ..))) if ha > 0.0 => {
                    format!("{:+.1} %", 100.0 * (hb - ha) / ha)
                }
                _ => "—".into(),
            };
            // Counted here on the final route (the job's own count is asserted equal when it
            // has one; it has none when its check would have run past the time limit).
            let counts = left_violations(input, &c, &hard);
            if let (Some(mine), Some(job)) = (counts, c.rule_counts) {
                assert_eq!(mine, job, "{} {}", input.name, solver.name());
            }
            let left = match counts {
                Some(counts) => format!(
                    "{}/{}/{}{}",
                    counts.part.unwrap_or(0),
                    counts.sheet.unwrap_or(0),
                    counts.islands.unwrap_or(0),
                    if c.rule_counts.is_none() {
                        " (job: not in time)"
                    } else {
                        ""
                    }
                ),
                None => "no route".into(),
            };
            let verdict = checker(input, &c);
            if counts.is_none_or(|counts| counts.total() > 0) || !verdict.starts_with("ok") {
                failures.push(format!(
                    "{} {}: {left}, {verdict}",
                    input.name,
                    solver.name()
                ));
            }
            println!(
                "| {} | {} | {} | {} | {} | {drop} | {} → {} | {} → {} | {left} | {verdict} |",
                input.name,
                input.nest.contour_count(),
                solver.name(),
                cell(ma, |m| format!("{:.4}", m.0)),
                cell(mb, |m| format!("{:.4}", m.0)),
                cell(ma, |m| format!("{:.0}", m.1)),
                cell(mb, |m| format!("{:.0}", m.1)),
                cell(ma, |m| format!("{:.0}", m.2)),
                cell(mb, |m| format!("{:.0}", m.2)),
            );
        }
    }
    println!();
    println!("| nest | H lower bound (every route of whole contours) |");
    println!("|---|---|");
    for input in &inputs {
        if let Some(bound) = one_hole_bound(&input.nest, &model) {
            println!("| {} | {bound:.6} |", input.name);
        }
    }
    if !failures.is_empty() {
        eprintln!("hard mode left violations or failed the checker:");
        for f in &failures {
            eprintln!("  {f}");
        }
        std::process::exit(1);
    }
}
