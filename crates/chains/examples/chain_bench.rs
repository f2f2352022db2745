//! Chain cutting vs plain CCP on every real nest: pierces, lengths, time and cost per material
//! of Verkhoturov–Tarasenko's Table 1. Prints a Markdown table for BENCHMARKS.md.
//!
//! `cargo run --release -p cutroute-chains --example chain_bench -- [--ccp-seconds S] [--filter A,B]
//! [--base ccp|nearest]`

use std::time::Instant;

use cutroute_chains::{chain_route, ChainOptions, TABLE1_MATERIALS};
use cutroute_geometry::MachineParameters;
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

#[path = "support/nest_files.rs"]
mod nest_files;

use nest_files::{nest_files, read_nest};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let ccp_seconds: f64 = value("--ccp-seconds").map_or(5.0, |v| v.parse().expect("seconds"));
    // The route to chain: CCP-Relax (default) or the nearest-neighbour baseline (for nests on
    // which CCP overruns its time limit).
    let base = match value("--base").as_deref() {
        None | Some("ccp") => SolverKind::Ccp,
        Some("nearest") => SolverKind::NearestNeighbour,
        Some(other) => panic!("--base {other}: ccp or nearest"),
    };
    let filter: Option<Vec<String>> =
        value("--filter").map(|v| v.split(',').map(str::to_string).collect());
    println!("| nest | contours | material | condValue mm | pierces CCP → chain | saved | links mm | idle mm CCP → chain | cut mm CCP → chain | time s CCP → chain | cost CCP → chain | cost change | chain s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for path in nest_files() {
        let path = path.as_str();
        if filter
            .as_ref()
            .is_some_and(|f| !f.iter().any(|x| path.contains(x.as_str())))
        {
            continue;
        }
        let (nest, start, finish) = read_nest(path);
        // Single contours have nothing to chain.
        if nest.contour_count() < 2 {
            continue;
        }
        // CCP through the engine's 40 ms slices, as the app and CLI run it (one large budget
        // overruns on Nest02, see the CCP section).
        let request = JobRequest {
            job_id: 1,
            problem: Problem::Nest {
                nest: nest.clone(),
                start,
                finish,
            },
            solver: base,
            params: SolverParams {
                time_limit_s: ccp_seconds,
                ..SolverParams::default()
            },
        };
        let mut job = cutroute_engine::start_job(&request)
            .unwrap_or_else(|e| panic!("{path}: CCP refused: {e}"));
        let ccp_route = cutroute_engine::run_to_end(job.as_mut(), &mut |_| {})
            .route()
            .cloned()
            .unwrap_or_else(|| panic!("{path}: CCP found no route"));
        for material in TABLE1_MATERIALS {
            let machine = material.priced(&MachineParameters::default());
            let options = ChainOptions {
                machine,
                ..ChainOptions::default()
            };
            let started = Instant::now();
            let chained = chain_route(&nest, &ccp_route, &options).expect("valid CCP route");
            let seconds = started.elapsed().as_secs_f64();
            let scale = {
                let b = nest.bounding_box();
                ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0)
            };
            if let Err(e) = chained.route.validate(&nest, 1e-6 * scale) {
                panic!("{path}: chained route invalid: {e}");
            }
            let r = &chained.report;
            let cut_before = ccp_route.cut_length(&nest);
            let cut_after = chained.route.cut_length(&nest);
            println!(
                "| {} | {} | {} | {:.0} | {} → {} | {} | {:.1} | {:.0} → {:.0} | {:.0} → {:.0} | {:.0} → {:.0} | {:.2} → {:.2} | {:+.2} % | {:.2} |",
                path.rsplit('/').next().unwrap_or(path),
                nest.contour_count(),
                material.name,
                cutroute_chains::profitable_link_length(&machine),
                r.pierces_before,
                r.pierces_after,
                r.pierces_before - r.pierces_after,
                r.link_length + 0.0, // no "-0.0"
                r.idle_before,
                r.idle_after,
                cut_before,
                cut_after,
                r.time_before,
                r.time_after,
                r.cost_before,
                r.cost_after,
                100.0 * (r.cost_after - r.cost_before) / r.cost_before,
                seconds,
            );
        }
    }
}
