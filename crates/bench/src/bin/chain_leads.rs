//! Benchmark: chain cutting with kerf and leads (issue #17) on every real nest, through the
//! engine's chain job (`start_job`, the CLI's code path).
//!
//! `cargo run -p cutroute-bench --bin chain_leads -- [--time-limit 2] [--filter NAME[,NAME…]]
//! [--data DIR]`
//!
//! Inputs: every nest file of `data/nests` (dbs, dbs-json, dxf, svg, tflex) with at least two
//! contours. Per nest, the chain job (CCP, then chain cutting; seed 1, default machine) runs
//! three times: on the nest (*ideal*, the idealised route), and on `LeadFitter::kerf_nest` for
//! *plasma* (kerf 2, d₁ 5, d₂ 1, arc lead-in 8 mm, line lead-out 2 mm) and *laser* (kerf 0.2,
//! d₁ 1, d₂ 0.5, arc lead-in 3 mm, line lead-out 1 mm), whose routes get their leads from
//! `LeadFitter::attach_chained` (2 relax passes of 24 positions). Per run: idle length (mm),
//! pierces, the leads' length (lead-ins plus lead-outs, mm), links given up for a pierce,
//! the independent checker's verdict (`Route::problems` on the real nest) and the contours
//! without room for a lead (the route is then refused and those contours named).

use std::path::{Path, PathBuf};
use std::time::Instant;

use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_geometry::{KerfSettings, LeadFitter, LeadShape, LeadSpec, Nest, Route, StepLeads};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

/// The chain job's route of `problem` (a nest problem) with its nest replaced by `nest`.
fn chain(problem: &Problem, nest: &Nest, limit: f64) -> Option<Route> {
    let mut problem = problem.clone();
    if let Problem::Nest { nest: n, .. } = &mut problem {
        *n = nest.clone();
    }
    let request = JobRequest {
        job_id: 1,
        problem,
        solver: SolverKind::Chain,
        params: SolverParams {
            time_limit_s: limit,
            seed: 1,
            ..SolverParams::default()
        },
    };
    let mut job = start_job(&request).ok()?;
    run_to_end(job.as_mut(), &mut |_| {}).route().cloned()
}

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

/// The cells of one run with leads: idle, pierces, leads mm, broken links, checker, no room,
/// seconds of `attach_chained`.
fn with_leads(problem: &Problem, nest: &Nest, settings: KerfSettings, limit: f64) -> [String; 7] {
    let fitter = LeadFitter::new(nest, settings);
    let Some(route) = chain(problem, &fitter.kerf_nest(), limit) else {
        return [
            "no route".into(),
            "".into(),
            "".into(),
            "".into(),
            "".into(),
            "".into(),
            "".into(),
        ];
    };
    let clock = Instant::now();
    let attached = fitter.attach_chained(&route, 2, 24);
    let seconds = format!("{:.1}", clock.elapsed().as_secs_f64());
    match attached {
        Ok(chained) => {
            let r = chained.route;
            let leads: f64 = r
                .steps
                .iter()
                .filter_map(|s| s.leads.as_ref())
                .map(|l: &StepLeads| l.lead_in_length() + l.lead_out_length())
                .sum();
            let problems = r.problems(nest, &nest.containment_forest(), nest.check_tolerance());
            let verdict = match problems.first() {
                None => "ok".to_string(),
                Some(p) => format!("{} problems, first: {p}", problems.len()),
            };
            [
                format!("{:.0}", r.idle_length()),
                r.pierce_count().to_string(),
                format!("{leads:.0}"),
                chained.broken_links.to_string(),
                verdict,
                "0".into(),
                seconds,
            ]
        }
        Err(errors) => [
            "—".into(),
            "—".into(),
            "—".into(),
            "—".into(),
            "refused".into(),
            errors.len().to_string(),
            seconds,
        ],
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
    let data = value("--data").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data"),
        PathBuf::from,
    );
    let plasma = settings(2.0, 5.0, 1.0, 8.0, 2.0);
    let laser = settings(0.2, 1.0, 0.5, 3.0, 1.0);
    println!(
        "| nest | contours | ideal idle | ideal pierces | plasma idle | pierces | leads mm | links broken | checker | no room | attach s | laser idle | pierces | leads mm | links broken | checker | no room | attach s |"
    );
    println!(
        "|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"
    );
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
        let ideal = chain(&document.problem, nest, limit);
        let (idle, pierces) = ideal.as_ref().map_or(("no route".into(), "".into()), |r| {
            (
                format!("{:.0}", r.idle_length()),
                r.pierce_count().to_string(),
            )
        });
        let p = with_leads(&document.problem, nest, plasma, limit);
        let l = with_leads(&document.problem, nest, laser, limit);
        println!(
            "| {name} | {} | {idle} | {pierces} | {} | {} |",
            nest.contour_count(),
            p.join(" | "),
            l.join(" | ")
        );
    }
}
