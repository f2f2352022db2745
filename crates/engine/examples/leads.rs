//! Benchmark of issue #17: "CCP optimising with leads" (CCP-Relax over the pierce curves, then
//! leads fitted and moved along the equidistants to shorten the idle legs, `LeadFitter::relax`) against "CCP then attach leads" (the idealised route, then leads), on the real
//! nests of `data/nests`, with kerf 2, d₁ 5, d₂ 1, arc lead-ins of 8 mm and line lead-outs of
//! 2 mm; the column "after + relax" moves the attached leads of the idealised order along the
//! equidistants (`LeadFitter::relax`, no new order). Every route is checked by `Route::problems` (M ∈ G_M, M* ∈ G_M*, leads clear).
//!
//! `cargo run -p cutroute-engine --example leads -- [TIME_LIMIT_S]` prints a Markdown table.

use std::path::PathBuf;

use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_geometry::{
    KerfSettings, LeadFitter, LeadShape, LeadSpec, MachineParameters, Nest, Route,
};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

fn ccp(problem: Problem, time_limit_s: f64) -> Option<Route> {
    let request = JobRequest {
        job_id: 1,
        problem,
        solver: SolverKind::Ccp,
        params: SolverParams {
            time_limit_s,
            ..SolverParams::default()
        },
    };
    let mut job = start_job(&request).ok()?;
    run_to_end(job.as_mut(), &mut |_| {}).route
}

fn with_nest(problem: &Problem, nest: Nest) -> Problem {
    match problem {
        Problem::Nest { start, finish, .. } => Problem::Nest {
            nest,
            start: *start,
            finish: *finish,
        },
        other => other.clone(),
    }
}

fn main() {
    let time_limit: f64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2.0);
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 5.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 0.0,
    };
    let machine = MachineParameters::default();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/nests");
    let mut files: Vec<PathBuf> = ["dbs", "dbs-json"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    println!("| nest | contours | idle ideal | idle after | idle optimised | idle after + relax | leads mm | Δ idle % | time after s | time optimised s | no room |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let (mut total_after, mut total_optimised) = (0.0, 0.0);
    let (mut idle_after, mut idle_optimised) = (0.0, 0.0);
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = std::fs::read(&path).unwrap();
        let Ok(document) = open_document(&name, &bytes) else {
            continue;
        };
        let Problem::Nest { nest, .. } = &document.problem else {
            continue;
        };
        let fitter = LeadFitter::new(nest, settings);
        let forest = nest.containment_forest();
        // CCP, then attach leads.
        let Some(ideal) = ccp(document.problem.clone(), time_limit) else {
            continue;
        };
        let after = fitter.attach(&ideal);
        // CCP over the pierce curves, brought back and fitted.
        let curves = with_nest(&document.problem, fitter.pierce_curve_nest());
        let optimised = ccp(curves, time_limit).map(|r| {
            fitter
                .attach(&fitter.project(&r))
                .map(|r| fitter.relax(&r, 2, 24))
        });
        let (Ok(after), Some(Ok(optimised))) = (after, optimised) else {
            let no_room = fitter.attach(&ideal).err().map_or(0, |e| e.len());
            println!(
                "| {name} | {} | {:.0} | — | — | — | — | — | — | — | {no_room} |",
                nest.contour_count(),
                ideal.idle_length()
            );
            continue;
        };
        for route in [&after, &optimised] {
            let problems = route.problems(nest, &forest, 1e-6);
            assert!(problems.is_empty(), "{name}: {:?}", problems.first());
        }
        let leads: f64 = after
            .steps
            .iter()
            .filter_map(|s| s.leads.as_ref())
            .map(|l| l.lead_in_length() + l.lead_out_length())
            .sum();
        let (t_after, t_opt) = (after.time(nest, &machine), optimised.time(nest, &machine));
        total_after += t_after;
        total_optimised += t_opt;
        println!(
            "| {name} | {} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:+.1} | {:.1} | {:.1} | 0 |",
            nest.contour_count(),
            ideal.idle_length(),
            after.idle_length(),
            optimised.idle_length(),
            fitter.relax(&after, 2, 24).idle_length(),
            leads,
            100.0 * (optimised.idle_length() - after.idle_length()) / after.idle_length().max(1e-9),
            t_after,
            t_opt,
        );
        idle_after += after.idle_length();
        idle_optimised += optimised.idle_length();
    }
    println!(
        "\nTotal machine time: after {total_after:.1} s, optimised {total_optimised:.1} s ({:+.2} %).",
        100.0 * (total_optimised - total_after) / total_after
    );
    println!(
        "Total idle: after {idle_after:.0} mm, optimised {idle_optimised:.0} mm ({:+.2} %).",
        100.0 * (idle_optimised - idle_after) / idle_after
    );
}
