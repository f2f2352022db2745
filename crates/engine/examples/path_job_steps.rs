//! How long one step of the path-route jobs (sccp, gsccp, aoe) takes on every real nest: the
//! worker can only see a Cancel message between steps, so the longest step is the app's
//! worst response time. Each job is stepped with the worker's slice (`DEFAULT_SLICE`, 40 ms)
//! to its end; the table shows `start_job`'s own time, the number of steps, the longest step
//! and the phase the job reported before it, the longest step after CCP-Relax (the segment
//! searches and ensemble builds of `cutroute-segments`; CCP-Relax's own steps are
//! `cutroute-ccp`'s), and the final bounds (objective: time, s).
//!
//! `cargo run --release -p cutroute-engine --example path_job_steps -- [--seconds S]
//! [--filter A,B]` (from the workspace root).

use cutroute_engine::{start_job, JobStatus, DEFAULT_SLICE};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};
use web_time::Instant;

#[path = "../../chains/examples/support/nest_files.rs"]
mod nest_files;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let seconds: f64 = value("--seconds").map_or(2.0, |v| v.parse().expect("seconds"));
    let filter: Option<Vec<String>> =
        value("--filter").map(|f| f.split(',').map(String::from).collect());
    println!("Time limit {seconds} s per job, slice {DEFAULT_SLICE:?}, objective time.\n");
    println!("| nest | contours | solver | start_job ms | steps | longest step ms | phase before it | longest after CCP ms | wall s | pierces | UB s | LB s |");
    println!("|---|---:|---|---:|---:|---:|---|---:|---:|---:|---:|---:|");
    for path in nest_files::nest_files() {
        let name = path.rsplit('/').next().unwrap_or(&path).to_string();
        if let Some(f) = &filter {
            if !f.iter().any(|x| name.contains(x.as_str())) {
                continue;
            }
        }
        let (nest, start, finish) = nest_files::read_nest(&path);
        let contours = nest.contour_count();
        let problem = Problem::Nest {
            nest,
            start,
            finish,
        };
        for solver in [SolverKind::Sccp, SolverKind::Gsccp, SolverKind::Aoe] {
            let request = JobRequest {
                job_id: 1,
                problem: problem.clone(),
                solver,
                params: SolverParams {
                    time_limit_s: seconds,
                    ..SolverParams::default()
                },
            };
            let clock = Instant::now();
            let mut job = match start_job(&request) {
                Ok(job) => job,
                Err(e) => {
                    println!(
                        "| {name} | {contours} | {} | failed: {e} | | | | | | | |",
                        solver.name()
                    );
                    continue;
                }
            };
            let start_ms = clock.elapsed().as_secs_f64() * 1e3;
            let (mut steps, mut longest, mut longest_phase) = (0, 0.0f64, String::new());
            let mut longest_after_ccp = 0.0f64;
            loop {
                let phase = job.progress().phase;
                let t = Instant::now();
                let status = job.step(DEFAULT_SLICE);
                let ms = t.elapsed().as_secs_f64() * 1e3;
                steps += 1;
                if !phase.contains("CCP") {
                    longest_after_ccp = longest_after_ccp.max(ms);
                }
                if ms > longest {
                    longest = ms;
                    longest_phase = phase;
                }
                if status == JobStatus::Done {
                    break;
                }
            }
            let wall = clock.elapsed().as_secs_f64();
            let p = job.progress();
            let pierces = p
                .path_route
                .as_ref()
                .map_or(String::from("—"), |r| r.pierce_count().to_string());
            let f = |v: Option<f64>| v.map_or(String::from("—"), |v| format!("{v:.1}"));
            println!(
                "| {name} | {contours} | {} | {start_ms:.1} | {steps} | {longest:.1} | {} | {longest_after_ccp:.1} | {wall:.1} | {pierces} | {} | {} |",
                solver.name(),
                longest_phase.trim_start_matches("segment cutting: ").trim_start_matches("common-edge routes: "),
                f(p.upper_bound),
                f(p.lower_bound),
            );
        }
    }
}
