//! Benchmark: every solver with kerf and leads (issue #17) on every real nest, through the
//! engine's `start_job` (the CLI's and the page's code path: `KerfJob`).
//!
//! `cargo run -p cutroute-bench --bin kerf_solvers -- [--time-limit 2] [--filter NAME[,NAME…]]
//! [--solvers NAME[,NAME…]] [--data DIR]`
//!
//! Inputs: every nest file of `data/nests` (dbs, dbs-json, dxf, svg, tflex) with at least two
//! contours (the RouteManager tasks of task-json hold no geometry: their nests are dbs-json's). Per nest and machine — *plasma* (kerf 2, d₁ 5, d₂ 1, arc lead-in 8 mm, line
//! lead-out 2 mm) and *laser* (kerf 0.2, d₁ 1, d₂ 0.5, arc lead-in 3 mm, line lead-out 1 mm) —
//! every solver (nearest, ccp, heuristic, exact, chain, sccp, gsccp, aoe; seed 1, default
//! machine) runs once. Per run: whether the route passes the independent checker on the real
//! nest (`Route::problems`, or `PathRoute::problems` for sccp/gsccp/aoe, where a contour cut
//! twice — standard cutting of a common edge — is allowed as the CLI allows it), its idle
//! length (mm), the leads' length (lead-ins plus lead-outs, mm), the contours without room for
//! a lead (the job then gives no route and names them), the pairs of contours closer than the
//! kerf (the job then refuses the nest up front: "refused: parts closer than kerf", with the
//! pairs' count and least gap), and the wall time (s). A solver the engine refuses with kerf for
//! another reason prints "refused".

use std::path::{Path, PathBuf};
use std::time::Instant;

use cutroute_engine::{open_document, run_to_end, start_job, EngineError, Refusal};
use cutroute_geometry::{KerfSettings, LeadShape, LeadSpec, Nest, PathRouteError};
use cutroute_protocol::{JobRequest, KerfNote, Phase, Problem, SolverKind, SolverParams};

const SOLVERS: [SolverKind; 8] = [
    SolverKind::NearestNeighbour,
    SolverKind::Ccp,
    SolverKind::Heuristic,
    SolverKind::Exact,
    SolverKind::Chain,
    SolverKind::Sccp,
    SolverKind::Gsccp,
    SolverKind::Aoe,
];

fn settings(kerf: f64, d1: f64, d2: f64, lead_in: f64, lead_out: f64) -> KerfSettings {
    KerfSettings {
        kerf,
        pierce_clearance: d1,
        switch_off_clearance: d2,
        lead_in: LeadSpec::new(LeadShape::Arc, lead_in),
        lead_out: LeadSpec::new(LeadShape::Line, lead_out),
        ..KerfSettings::default()
    }
}

/// What one run gave.
struct Run {
    /// "yes", "no (first problem)", "refused", "no room", "no route".
    checker: String,
    idle: Option<f64>,
    leads: Option<f64>,
    no_room: usize,
    /// The pairs of contours closer than the kerf and their least gap, mm, when the job
    /// refused the nest for them.
    too_close: Option<(usize, f64)>,
    seconds: f64,
}

/// The checker cell of a job refused because parts sit closer than the kerf.
const PARTS_TOO_CLOSE: &str = "refused: parts closer than kerf";

fn run(problem: &Problem, nest: &Nest, solver: SolverKind, kerf: KerfSettings, limit: f64) -> Run {
    let request = JobRequest {
        job_id: 1,
        problem: problem.clone(),
        solver,
        params: SolverParams {
            time_limit_s: limit,
            seed: 1,
            kerf,
            ..SolverParams::default()
        },
    };
    let clock = Instant::now();
    let mut job = match start_job(&request) {
        Ok(job) => job,
        Err(e) => {
            let too_close = match &e {
                EngineError::SolverRefused {
                    reason: Refusal::PartsTooClose(p),
                    ..
                } => Some((
                    p.pairs.len(),
                    p.pairs.iter().map(|o| o.gap).fold(f64::INFINITY, f64::min),
                )),
                _ => None,
            };
            return Run {
                checker: if too_close.is_some() {
                    PARTS_TOO_CLOSE
                } else {
                    "refused"
                }
                .into(),
                idle: None,
                leads: None,
                no_room: 0,
                too_close,
                seconds: clock.elapsed().as_secs_f64(),
            };
        }
    };
    let progress = run_to_end(job.as_mut(), &mut |_| {});
    let seconds = clock.elapsed().as_secs_f64();
    let no_room = match &progress.phase {
        Phase::Kerf {
            note: KerfNote::NoRoom { contours, .. },
            ..
        } => contours.len(),
        _ => 0,
    };
    let tolerance = nest.check_tolerance();
    let verdict = |first: Option<String>, count: usize| match first {
        None => "yes".to_string(),
        Some(p) => format!("no ({count}: {p})"),
    };
    if let Some(route) = progress.route() {
        let problems = route.problems(nest, &nest.containment_forest(), tolerance);
        let leads = route
            .steps
            .iter()
            .filter_map(|s| s.leads.as_ref())
            .map(|l| l.lead_in_length() + l.lead_out_length())
            .sum();
        return Run {
            checker: verdict(problems.first().map(|p| p.to_string()), problems.len()),
            idle: Some(route.idle_length()),
            leads: Some(leads),
            no_room,
            too_close: None,
            seconds,
        };
    }
    if let Some(route) = progress.path_route() {
        let problems: Vec<PathRouteError> = route
            .problems(nest, tolerance)
            .into_iter()
            .filter(|p| !matches!(p, PathRouteError::Overlap { .. }))
            .collect();
        let leads = route.paths.iter().map(|p| p.leads_length()).sum();
        return Run {
            checker: verdict(problems.first().map(|p| p.to_string()), problems.len()),
            idle: Some(route.idle_length()),
            leads: Some(leads),
            no_room,
            too_close: None,
            seconds,
        };
    }
    // Why, on stderr: the table has no room for the reasons.
    eprintln!("{} {}: {}", solver.name(), kerf.kerf, progress.phase);
    Run {
        checker: if no_room > 0 { "no room" } else { "no route" }.into(),
        idle: None,
        leads: None,
        no_room,
        too_close: None,
        seconds,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let limit: f64 = value("--time-limit").map_or(2.0, |v| v.parse().expect("seconds"));
    let filter: Option<Vec<String>> =
        value("--filter").map(|f| f.split(',').map(str::to_string).collect());
    let solvers: Vec<SolverKind> = value("--solvers").map_or(SOLVERS.to_vec(), |names| {
        names
            .split(',')
            .map(|n| {
                *SOLVERS
                    .iter()
                    .find(|s| s.name() == n)
                    .unwrap_or_else(|| panic!("unknown solver {n}"))
            })
            .collect()
    });
    let data = value("--data").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data"),
        PathBuf::from,
    );
    let machines = [
        ("plasma", settings(2.0, 5.0, 1.0, 8.0, 2.0)),
        ("laser", settings(0.2, 1.0, 0.5, 3.0, 1.0)),
    ];
    println!("| nest | contours | machine | solver | passes checker | idle mm | leads mm | no room | closer than kerf: pairs, least gap mm | wall s |");
    println!("|---|---:|---|---|---|---:|---:|---:|---|---:|");
    // Per solver and machine: runs, passed, no room, refused for parts closer than the kerf,
    // refused otherwise.
    let mut totals = vec![[0usize; 5]; solvers.len() * machines.len()];
    for (name, path) in cutroute_bench::real_nest_files(Path::new(&data)) {
        if filter
            .as_ref()
            .is_some_and(|f| !f.iter().any(|n| name.contains(n.as_str())))
        {
            continue;
        }
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        let Ok(document) = open_document(&name, &bytes) else {
            continue;
        };
        let Problem::Nest { nest, .. } = &document.problem else {
            continue;
        };
        if nest.contour_count() < 2 {
            continue;
        }
        for (m, (machine, kerf)) in machines.iter().enumerate() {
            for (s, &solver) in solvers.iter().enumerate() {
                let r = run(&document.problem, nest, solver, *kerf, limit);
                let total = &mut totals[m * solvers.len() + s];
                total[0] += 1;
                total[1] += usize::from(r.checker == "yes");
                total[2] += usize::from(r.no_room > 0);
                total[3] += usize::from(r.too_close.is_some());
                total[4] += usize::from(r.checker == "refused");
                let mm = |v: Option<f64>| v.map_or("—".into(), |v| format!("{v:.0}"));
                let too_close = r
                    .too_close
                    .map_or("—".into(), |(pairs, gap)| format!("{pairs}, {gap:.3}"));
                println!(
                    "| {name} | {} | {machine} | {} | {} | {} | {} | {} | {too_close} | {:.2} |",
                    nest.contour_count(),
                    solver.name(),
                    r.checker,
                    mm(r.idle),
                    mm(r.leads),
                    r.no_room,
                    r.seconds
                );
            }
        }
    }
    println!();
    println!("| machine | solver | nests | pass | no room | refused: parts closer than kerf | refused otherwise |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    for (m, (machine, _)) in machines.iter().enumerate() {
        for (s, solver) in solvers.iter().enumerate() {
            let [runs, pass, no_room, too_close, refused] = totals[m * solvers.len() + s];
            println!(
                "| {machine} | {} | {runs} | {pass} | {no_room} | {too_close} | {refused} |",
                solver.name()
            );
        }
    }
}
