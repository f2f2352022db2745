//! Benchmark of issue #17: the engine's kerf job optimising with leads (`KerfJob`: CCP-Relax
//! over the pierce curves and over the nest, each route fitted with leads and relaxed along
//! the equidistants, the shorter kept) against "CCP then attach leads" (the same job with
//! `leads_after`), on the real nests of `data/nests` and the app's `nested.dbs` sample, with
//! kerf 2, d₁ 5, d₂ 1, arc lead-ins of 8 mm and line lead-outs of 2 mm. The column
//! "after + relax" moves the attached leads of the after route along the equidistants
//! (`LeadFitter::relax`, the order kept). Every route is checked by `Route::problems`
//! (M ∈ G_M, M* ∈ G_M*, leads clear, entries on the equidistants).
//!
//! `cargo run -p cutroute-engine --example leads -- [TIME_LIMIT_S]` prints a Markdown table.

use std::path::PathBuf;

use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_geometry::{KerfSettings, LeadFitter, MachineParameters, Route};
use cutroute_protocol::{
    JobRequest, KerfNote, KerfSource, Phase, Problem, Progress, SolverKind, SolverParams,
};

fn ccp(problem: &Problem, time_limit_s: f64, kerf: KerfSettings, after: bool) -> Progress {
    let request = JobRequest {
        job_id: 1,
        problem: problem.clone(),
        solver: SolverKind::Ccp,
        params: SolverParams {
            time_limit_s,
            kerf,
            leads_after: after,
            ..SolverParams::default()
        },
    };
    let mut job = start_job(&request).expect("ccp starts");
    run_to_end(job.as_mut(), &mut |_| {})
}

fn main() {
    let time_limit: f64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2.0);
    let settings = KerfSettings::plasma_reference();
    let machine = MachineParameters::default();
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let root = here.join("../../data/nests");
    let mut files: Vec<PathBuf> = ["dbs", "dbs-json"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    // An optional second argument keeps the files whose names contain it.
    if let Some(filter) = std::env::args().nth(2) {
        files.retain(|f| f.to_string_lossy().contains(&filter));
    }
    println!("| nest | contours | idle ideal | idle after | idle optimised | idle after + relax | leads mm | Δ idle % (optimised vs after) | optimised ≤ after | kept | job s | time after s | time optimised s | no room |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|:-:|---|---:|---:|---:|---:|");
    let (mut total_after, mut total_optimised) = (0.0, 0.0);
    let (mut idle_after, mut idle_optimised) = (0.0, 0.0);
    let mut misses = 0;
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = std::fs::read(&path).unwrap();
        let Ok(document) = open_document(&name, &bytes) else {
            continue;
        };
        let Problem::Nest { nest, .. } = &document.problem else {
            continue;
        };
        let forest = nest.containment_forest();
        let ideal = ccp(
            &document.problem,
            time_limit,
            KerfSettings::default(),
            false,
        );
        let ideal_idle = ideal.route().map_or(f64::NAN, Route::idle_length);
        let after = ccp(&document.problem, time_limit, settings, true);
        let started = std::time::Instant::now();
        let optimised = ccp(&document.problem, time_limit, settings, false);
        let job_s = started.elapsed().as_secs_f64();
        let (Some(after_route), Some(optimised_route)) = (after.route(), optimised.route()) else {
            let no_room = [&after.phase, &optimised.phase]
                .iter()
                .filter_map(|phase| match phase {
                    Phase::Kerf {
                        note: KerfNote::NoRoom { errors, .. },
                        ..
                    } => Some(errors.len()),
                    _ => None,
                })
                .max()
                .unwrap_or(0);
            for phase in [&after.phase, &optimised.phase] {
                eprintln!("{name}: {phase}");
            }
            println!(
                "| {name} | {} | {ideal_idle:.0} | — | — | — | — | — | — | — | {job_s:.2} | — | — | {no_room} |",
                nest.contour_count(),
            );
            continue;
        };
        for route in [after_route, optimised_route] {
            let problems = route.problems(nest, &forest, 1e-6);
            assert!(problems.is_empty(), "{name}: {:?}", problems.first());
        }
        let kept = match &optimised.phase {
            Phase::Kerf {
                note:
                    KerfNote::Leads {
                        source: KerfSource::PierceCurves,
                    },
                ..
            } => "curves",
            _ => "idealised",
        };
        let leads: f64 = after_route
            .steps
            .iter()
            .filter_map(|s| s.leads.as_ref())
            .map(|l| l.lead_in_length() + l.lead_out_length())
            .sum();
        let relaxed = LeadFitter::with_forest(nest, &forest, settings).relax(after_route, 2, 24);
        let (a, o) = (after_route.idle_length(), optimised_route.idle_length());
        let (t_after, t_opt) = (
            after_route.time(nest, &machine),
            optimised_route.time(nest, &machine),
        );
        let holds = o <= a + 1e-9;
        if !holds {
            misses += 1;
        }
        total_after += t_after;
        total_optimised += t_opt;
        idle_after += a;
        idle_optimised += o;
        println!(
            "| {name} | {} | {ideal_idle:.0} | {a:.0} | {o:.0} | {:.0} | {leads:.0} | {:+.1} | {} | {kept} | {job_s:.2} | {t_after:.1} | {t_opt:.1} | 0 |",
            nest.contour_count(),
            relaxed.idle_length(),
            100.0 * (o - a) / a.max(1e-9),
            if holds { "yes" } else { "**no**" },
        );
    }
    println!(
        "\nTotal idle: after {idle_after:.0} mm, optimised {idle_optimised:.0} mm ({:+.2} %); \
         total machine time: after {total_after:.1} s, optimised {total_optimised:.1} s ({:+.2} %); \
         nests where optimised > after: {misses}.",
        100.0 * (idle_optimised - idle_after) / idle_after,
        100.0 * (total_optimised - total_after) / total_after
    );
}
