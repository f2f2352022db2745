//! Benchmark: time limits and step lengths of every solver, driven through the engine exactly
//! as the web worker drives it (`start_job`, then `step(40 ms)` until done).
//!
//! `cargo run --release -p cutroute-bench --bin time_limits -- [--time-limit 5] [--slice-ms 40]
//! [--step 50] [--solvers ccp,exact,…] [--filter NAME[,NAME…]] [--set nests|pcgtsp|all]
//! [--generated 1000,10000] [--data DIR] [--trace] [--phases] [--rules-hard] [--kerf]
//! [--cli BIN --cli-input FILE[,FILE…] --cli-limit S]`
//!
//! `--rules-hard` runs every job with `--rules part,sheet,islands --rules-hard` (the repair and
//! the rule check after the solver are steps of the job too).
//!
//! `--kerf` runs every nest job on the full cutting route (issue #17's plasma: kerf 2, d₁ 5,
//! d₂ 1, an 8 mm arc lead-in, a 2 mm line lead-out): the kerf job with exact over the
//! full-route model, the chain attach of leads, and the others.
//!
//! `--trace` prints every call longer than its slice + 50 ms to stderr, with the job's phase
//! before and after it. `--phases` prints every change of the job's phase to stderr with the
//! wall time it was first seen at (where a job spends the time past its limit).
//!
//! Inputs: every real nest of `data/nests` (dbs, dbs-json, dxf, svg, tflex), every PCGTSP
//! instance of `data/pcgtsp` (industrial, pcgtsplib) and `data/nests/pcgtsp` and generated nests of the given sizes
//! (`generate_nest(n, 1)`; their discretisations are the 1,000-cluster PCGTSP instances).
//!
//! Prints a Markdown table: solver, input, limit, wall (start + steps), wall − limit, `start_job`'s own time
//! (the model is built there), the longest `step` call, the 99th percentile of the step calls
//! (nearest rank), the number of steps, and what ended the
//! job: "limit" when the wall reached the limit, "finished" when the solver ended before it
//! ("no solution" added when the job ended without a route or tour).
//! A row is marked **over** when the wall exceeds limit + 1 s (the promise), and "long step"
//! when one call (start or step) exceeds its slice by more than 50 ms (Stop waits for it). A
//! job still running at limit + 60 s is abandoned ("abandoned"). After the table: per solver,
//! the longest single call, the worst wall − limit, the walls over limit + 1 s and the runs
//! with a call over 0.2 s.
//!
//! `--cli BIN` also runs the command-line tool (`BIN solve FILE --solver S --time-limit S
//! --json`, the release binary `target/release/cutroute`) on each `--cli-input` file with every
//! solver that takes it (heuristic and exact for PCGTSP instances), and prints its wall time
//! (process start to exit, reading included) and wall − limit against `--cli-limit` (default
//! 120 s).

use cutroute_engine::{open_document, start_job, JobStatus};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};
use std::path::PathBuf;
use std::time::{Duration, Instant};

struct Input {
    name: String,
    problem: Problem,
}

fn nest_inputs(data: &std::path::Path, generated: &[usize]) -> Vec<Input> {
    let mut inputs = Vec::new();
    for (name, path) in cutroute_bench::real_nest_files(data) {
        let bytes = std::fs::read(&path).expect("readable");
        match open_document(&name, &bytes) {
            Ok(document) if matches!(document.problem, Problem::Nest { .. }) => {
                inputs.push(Input {
                    name,
                    problem: document.problem,
                })
            }
            Ok(_) => {}
            Err(e) => eprintln!("{name}: not opened ({e})"),
        }
    }
    for &n in generated {
        inputs.push(Input {
            name: format!("generated-{n}"),
            problem: Problem::Nest {
                nest: cutroute_geometry::generate_nest(n, 1),
                start: cutroute_geometry::Point::new(0.0, 0.0),
                finish: None,
            },
        });
    }
    inputs
}

fn pcgtsp_inputs(data: &std::path::Path) -> Vec<Input> {
    let mut inputs = Vec::new();
    for dir in ["pcgtsp/industrial", "pcgtsp/pcgtsplib", "nests/pcgtsp"] {
        let Ok(entries) = std::fs::read_dir(data.join(dir)) else {
            continue;
        };
        // Beside the instances, `nests/pcgtsp` holds their result files (`.txt`).
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension()
                    .is_some_and(|x| x == "pcglns" || x == "pcgtsp")
            })
            .collect();
        paths.sort();
        for path in paths {
            inputs.push(Input {
                name: path.file_name().unwrap().to_string_lossy().to_string(),
                problem: Problem::PcgtspText {
                    text: std::fs::read_to_string(&path).expect("readable"),
                },
            });
        }
    }
    inputs
}

/// Issue #17's plasma settings: kerf 2, d₁ 5, d₂ 1, an 8 mm arc lead-in, a 2 mm line lead-out
/// (the engine tests' `plasma`).
fn plasma() -> cutroute_geometry::KerfSettings {
    cutroute_geometry::KerfSettings::plasma_reference()
}

/// The nearest-rank `q` quantile of `times` (0 when empty); sorts them.
fn percentile(times: &mut [f64], q: f64) -> f64 {
    if times.is_empty() {
        return 0.0;
    }
    times.sort_by(f64::total_cmp);
    let rank = ((q * times.len() as f64).ceil() as usize).clamp(1, times.len());
    times[rank - 1]
}

pub fn main() {
    let mut limit = 5.0f64;
    let mut slice = Duration::from_millis(40);
    let mut step_mm = SolverParams::default().discretisation_step_mm;
    let mut solvers: Vec<SolverKind> = SolverKind::ALL.to_vec();
    let mut filter: Option<Vec<String>> = None;
    let mut set = "all".to_string();
    let mut generated: Vec<usize> = vec![1000];
    let mut data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let mut trace = false;
    let mut phases = false;
    let mut thermal = cutroute_protocol::ThermalSettings::default();
    let mut kerf = false;
    let mut cli: Option<PathBuf> = None;
    let mut cli_inputs: Vec<PathBuf> = Vec::new();
    let mut cli_limit = 120.0f64;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--time-limit" => limit = value().parse().expect("--time-limit SECONDS"),
            "--slice-ms" => {
                slice = Duration::from_millis(value().parse().expect("--slice-ms MILLISECONDS"))
            }
            "--step" => step_mm = value().parse().expect("--step MM"),
            "--solvers" => {
                let names = value();
                solvers = names
                    .split(',')
                    .map(|n| {
                        *SolverKind::ALL
                            .iter()
                            .find(|k| k.name() == n)
                            .unwrap_or_else(|| panic!("unknown solver {n}"))
                    })
                    .collect()
            }
            "--filter" => filter = Some(value().split(',').map(str::to_string).collect()),
            "--set" => set = value(),
            "--generated" => {
                let sizes = value();
                generated = if sizes.is_empty() {
                    Vec::new()
                } else {
                    sizes
                        .split(',')
                        .map(|s| s.parse().expect("--generated N[,N…]"))
                        .collect()
                }
            }
            "--data" => data = PathBuf::from(value()),
            "--trace" => trace = true,
            "--phases" => phases = true,
            "--kerf" => kerf = true,
            "--rules-hard" => {
                thermal = cutroute_protocol::ThermalSettings {
                    rules: cutroute_protocol::RuleSet::ALL,
                    hard: true,
                    ..thermal
                }
            }
            "--cli" => cli = Some(PathBuf::from(value())),
            "--cli-input" => cli_inputs = value().split(',').map(PathBuf::from).collect(),
            "--cli-limit" => cli_limit = value().parse().expect("--cli-limit SECONDS"),
            other => panic!("unknown option {other}"),
        }
    }
    let mut inputs = Vec::new();
    if set == "all" || set == "nests" {
        inputs.extend(nest_inputs(&data, &generated));
    }
    if set == "all" || set == "pcgtsp" {
        inputs.extend(pcgtsp_inputs(&data));
    }
    if let Some(names) = &filter {
        inputs.retain(|i| names.iter().any(|n| i.name.contains(n.as_str())));
    }
    println!(
        "| solver | input | limit s | wall s | wall − limit s | start s | longest step s | p99 step s | steps | ended by | |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut worst_step = 0.0f64;
    let mut worst_over = f64::NEG_INFINITY;
    let mut wall_overs = 0;
    let mut long_rows = 0;
    // Per solver: (longest call s, worst wall − limit s, walls over limit + 1 s, runs, runs
    // with a call > 0.2 s).
    let mut per_solver: Vec<(SolverKind, f64, f64, usize, usize, usize)> = solvers
        .iter()
        .map(|&k| (k, 0.0, f64::NEG_INFINITY, 0, 0, 0))
        .collect();
    for input in &inputs {
        for &solver in &solvers {
            let is_pcgtsp = matches!(input.problem, Problem::PcgtspText { .. });
            if is_pcgtsp && !matches!(solver, SolverKind::Heuristic | SolverKind::Exact) {
                continue;
            }
            let request = JobRequest {
                job_id: 1,
                problem: input.problem.clone(),
                solver,
                params: SolverParams {
                    time_limit_s: limit,
                    discretisation_step_mm: step_mm,
                    thermal,
                    kerf: if kerf && !is_pcgtsp {
                        plasma()
                    } else {
                        cutroute_geometry::KerfSettings::default()
                    },
                    ..SolverParams::default()
                },
            };
            let started = Instant::now();
            let job = start_job(&request);
            let start_s = started.elapsed().as_secs_f64();
            let mut longest = 0.0f64;
            let mut step_times: Vec<f64> = Vec::new();
            let mut steps = 0usize;
            let mut last_phase = String::new();
            let ended_by = match job {
                Err(e) => format!("refused: {e}"),
                Ok(mut job) => loop {
                    if phases {
                        let phase = job.progress().phase.to_string();
                        if phase != last_phase {
                            eprintln!(
                                "{} {}: {:.3} s \"{phase}\"",
                                solver.name(),
                                input.name,
                                started.elapsed().as_secs_f64()
                            );
                            last_phase = phase;
                        }
                    }
                    let phase = if trace {
                        job.progress().phase.to_string()
                    } else {
                        String::new()
                    };
                    let t = Instant::now();
                    let status = job.step(slice);
                    let took = t.elapsed().as_secs_f64();
                    longest = longest.max(took);
                    step_times.push(took);
                    if trace && took > slice.as_secs_f64() + 0.05 {
                        eprintln!(
                            "{} {}: step {steps} took {took:.3} s from phase \"{phase}\" to \"{}\"",
                            solver.name(),
                            input.name,
                            job.progress().phase
                        );
                    }
                    steps += 1;
                    let wall = started.elapsed().as_secs_f64();
                    if status == JobStatus::Done {
                        let ended = if wall >= limit - 0.05 {
                            "limit"
                        } else {
                            "finished"
                        };
                        break match job.progress().solution {
                            Some(_) => ended.to_string(),
                            None => format!("{ended}, no solution"),
                        };
                    }
                    if wall > limit + 60.0 {
                        break "abandoned".to_string();
                    }
                },
            };
            let wall = started.elapsed().as_secs_f64();
            let p99 = percentile(&mut step_times, 0.99);
            let call = longest.max(start_s);
            worst_step = worst_step.max(call);
            let wall_over = wall > limit + 1.0;
            let long_call = call > slice.as_secs_f64() + 0.05;
            wall_overs += usize::from(wall_over);
            long_rows += usize::from(long_call);
            worst_over = worst_over.max(wall - limit);
            if let Some(row) = per_solver.iter_mut().find(|r| r.0 == solver) {
                row.1 = row.1.max(call);
                row.2 = row.2.max(wall - limit);
                row.3 += usize::from(wall_over);
                row.4 += 1;
                row.5 += usize::from(call > 0.2);
            }
            println!(
                "| {} | {} | {limit} | {wall:.2} | {:+.2} | {start_s:.3} | {longest:.3} | {p99:.3} | {steps} | {ended_by} | {} |",
                solver.name(),
                input.name,
                wall - limit,
                match (wall_over, long_call) {
                    (true, _) => "**over**",
                    (false, true) => "long step",
                    _ => "",
                }
            );
        }
    }
    println!();
    println!(
        "{} inputs, {} runs; {wall_overs} walls over limit + 1 s (**over**); worst wall − limit \
         {worst_over:+.2} s; longest single call (start or step) {worst_step:.3} s; {long_rows} \
         runs with a call > slice + 50 ms (long step)",
        inputs.len(),
        per_solver.iter().map(|r| r.4).sum::<usize>()
    );
    println!();
    println!(
        "| solver | runs | longest call s | worst wall − limit s | walls > limit + 1 s | runs with a call > 0.2 s |"
    );
    println!("|---|---|---|---|---|---|");
    for (solver, call, over_by, over_rows, rows, long) in per_solver.iter().filter(|r| r.4 > 0) {
        println!(
            "| {} | {rows} | {call:.3} | {over_by:+.2} | {over_rows} | {long} |",
            solver.name()
        );
    }
    if let Some(bin) = cli {
        println!();
        println!("| CLI: solver | input | limit s | wall s | wall − limit s | exit | |");
        println!("|---|---|---|---|---|---|---|");
        for input in &cli_inputs {
            let text = std::fs::read_to_string(input).unwrap_or_default();
            let is_pcgtsp = text.contains("GTSP_SETS");
            let names: Vec<&str> = if is_pcgtsp {
                vec!["heuristic", "exact"]
            } else {
                solvers.iter().map(|k| k.name()).collect()
            };
            for name in names {
                let started = Instant::now();
                let status = std::process::Command::new(&bin)
                    .arg("solve")
                    .arg(input)
                    .args([
                        "--solver",
                        name,
                        "--time-limit",
                        &cli_limit.to_string(),
                        "--json",
                    ])
                    .stdout(std::process::Stdio::null())
                    .stderr(std::process::Stdio::null())
                    .status();
                let wall = started.elapsed().as_secs_f64();
                let exit = status.map_or_else(
                    |e| e.to_string(),
                    |s| s.code().map_or("signal".to_string(), |c| c.to_string()),
                );
                println!(
                    "| {name} | {} | {cli_limit} | {wall:.2} | {:+.2} | {exit} | {} |",
                    input.file_name().unwrap_or_default().to_string_lossy(),
                    wall - cli_limit,
                    if wall > cli_limit + 1.0 {
                        "**over**"
                    } else {
                        ""
                    }
                );
            }
        }
    }
}
