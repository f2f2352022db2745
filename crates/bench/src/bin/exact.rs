//! Benchmark: the exact PCGTSP solver on every instance of `data/pcgtsp`.
//!
//! `cargo run --release -p cutroute-bench --bin exact -- [--time-limit 60] [--filter NAME[,NAME…]]
//! [--skip NAME] [--set industrial|pcgtsplib] [--no-l2] [--no-heuristic] [--memory-mb 2048] [--data DIR]
//! [--alns-seconds 0] [--restricted-seconds 0] [--cpu-limit]`
//!
//! With `--cpu-limit`, every limit (the instance's, the ALNS phase's) counts the benchmark
//! thread's CPU time instead of wall time, so other processes on the machine do not shorten
//! the run; the restricted bound's own sub-limit stays wall time (its CPU counts against the
//! instance's limit).
//!
//! Within each instance's time limit, optionally runs first the ALNS heuristic
//! (`--alns-seconds`, its tour seeds the exact search) and then the restricted bound
//! (`--restricted-seconds`, guided by the best tour so far); the exact search gets the rest.
//!
//! Prints a Markdown table: instance size, number of order ideals, our upper and lower bounds,
//! gap, proven optimality and time, next to the reference values of `reference.csv`.

use cutroute_alns::{AlnsOptions, AlnsSolver};
use cutroute_pcgtsp::{
    check_tour, count_ideals, restricted_bound, ExactOptions, ExactSolver, Instance,
    RestrictedBoundOptions, Status,
};
use std::path::PathBuf;
use std::time::{Duration, Instant};

struct Row {
    set: String,
    instance: String,
    pcglns_cost: String,
    best_lb: String,
    known_optimum: String,
}

pub fn main() {
    let mut time_limit = 60.0f64;
    let mut filter: Option<String> = None;
    let mut skip: Vec<String> = Vec::new();
    let mut only_set: Option<String> = None;
    let mut options = ExactOptions::default();
    let mut data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/pcgtsp");
    let mut alns_seconds = 0.0f64;
    let mut restricted_seconds = 0.0f64;
    let mut cpu_limit = false;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--time-limit" => {
                time_limit = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--time-limit SECONDS")
            }
            "--filter" => filter = args.next(),
            "--skip" => skip.push(args.next().expect("--skip NAME")),
            "--set" => only_set = args.next(),
            "--no-l2" => options.use_l2 = false,
            "--no-heuristic" => options.heuristic = false,
            "--memory-mb" => {
                options.memory_limit_bytes = args
                    .next()
                    .and_then(|v| v.parse::<usize>().ok())
                    .expect("--memory-mb MB")
                    << 20
            }
            "--alns-seconds" => {
                alns_seconds = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--alns-seconds SECONDS")
            }
            "--restricted-seconds" => {
                restricted_seconds = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--restricted-seconds SECONDS")
            }
            "--cpu-limit" => cpu_limit = true,
            "--data" => data = PathBuf::from(args.next().expect("--data DIR")),
            other => panic!("unknown argument {other}"),
        }
    }
    let reference = std::fs::read_to_string(data.join("reference.csv"))
        .unwrap_or_else(|e| panic!("{}: {e}", data.join("reference.csv").display()));
    let mut lines = reference.lines();
    let header = cutroute_bench::csv_fields(lines.next().expect("header"));
    let col = |name: &str| header.iter().position(|h| h == name).expect(name);
    let rows: Vec<Row> = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f = cutroute_bench::csv_fields(l);
            Row {
                set: f[col("set")].clone(),
                instance: f[col("instance")].clone(),
                pcglns_cost: f[col("pcglns_cost")].clone(),
                best_lb: f[col("best_lb")].clone(),
                known_optimum: f[col("known_optimum")].clone(),
            }
        })
        .collect();
    println!("| set | instance | nodes | clusters | ideals | UB | LB | gap % | proven | time s | cpu s | states | restricted LB (clusters) | pcglns | best_lb | known_opt |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for row in rows {
        if let Some(f) = &filter {
            if !f.split(',').any(|f| row.instance.contains(f)) {
                continue;
            }
        }
        if skip.contains(&row.instance) || only_set.as_ref().is_some_and(|s| *s != row.set) {
            continue;
        }
        let path = data.join(&row.set).join(format!("{}.pcglns", row.instance));
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let instance = Instance::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let ideals = count_ideals(&instance, 6_000_000)
            .ok()
            .flatten()
            .map_or(">6e6".to_string(), |c| c.to_string());
        let limit = if row.instance == "e1x_2" {
            time_limit.max(600.0)
        } else {
            time_limit
        };
        let began = Instant::now();
        let cpu_before = cutroute_bench::process_cpu_seconds();
        let (p, proven, states, restricted_lb) = run(
            &instance,
            &options,
            limit,
            alns_seconds.min(limit),
            restricted_seconds,
            cpu_limit,
        );
        let wall = began.elapsed().as_secs_f64();
        let cpu = cutroute_bench::process_cpu_seconds() - cpu_before;
        if let Some(tour) = &p.best_tour {
            let cost = check_tour(&instance, tour).expect("solver returned an infeasible tour");
            assert!(
                (cost - p.upper_bound).abs() < 1e-6,
                "reported cost differs from checked cost"
            );
        }
        // A bound above a published optimum is flagged, not fatal: the published value may be
        // a rounded bound (p43.4: 66846 is the dissertation's lower bound; the optimum is 66848).
        let flag = match row.known_optimum.parse::<f64>() {
            Ok(opt) if p.lower_bound > opt + 1e-6 => " (LB > known_opt!)",
            _ => "",
        };
        println!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.2} | {} | {:.2} | {:.2} | {} | {} | {} | {} | {}{} |",
            row.set,
            row.instance,
            instance.node_count,
            instance.clusters.len(),
            ideals,
            p.upper_bound,
            p.lower_bound,
            p.gap * 100.0,
            if proven { "yes" } else { "no" },
            wall,
            cpu,
            states,
            restricted_lb.unwrap_or_else(|| "–".to_string()),
            row.pcglns_cost,
            row.best_lb,
            row.known_optimum,
            flag,
        );
    }
}

/// One instance within `limit` seconds: ALNS first, then the restricted bound, then the exact
/// search seeded with both. Returns the final progress, proven optimality, DP states created and
/// the restricted bound (if run).
fn run(
    instance: &Instance,
    options: &ExactOptions,
    limit: f64,
    alns_seconds: f64,
    restricted_seconds: f64,
    cpu_limit: bool,
) -> (cutroute_pcgtsp::ExactProgress, bool, u64, Option<String>) {
    // The clock every limit is measured on: wall time, or this thread's CPU time.
    let wall_began = Instant::now();
    let cpu_began = cutroute_bench::thread_cpu_seconds();
    let clock = || {
        if cpu_limit {
            cutroute_bench::thread_cpu_seconds() - cpu_began
        } else {
            wall_began.elapsed().as_secs_f64()
        }
    };
    let mut best: Option<(Vec<usize>, f64)> = None;
    if alns_seconds > 0.0 {
        let alns_options = AlnsOptions {
            // On the CPU clock the wall limit is only a backstop.
            time_limit: Some(Duration::from_secs_f64(if cpu_limit {
                alns_seconds * 20.0
            } else {
                alns_seconds
            })),
            ..AlnsOptions::default()
        };
        let mut alns = AlnsSolver::new(instance, alns_options).expect("ALNS accepts the instance");
        while clock() < alns_seconds
            && alns.step(Duration::from_millis(50)) == cutroute_alns::Status::Running
        {}
        best = alns.best().map(|(t, c)| (t.to_vec(), c));
    }
    // The solver's own beam search still runs after ALNS (unless `--no-heuristic`): with a
    // short ALNS budget it sometimes finds the better tour (ESC47), and its tours prune the DP.
    let mut opts = options.clone();
    let remaining = || (limit - clock()).max(0.0);
    let budget = remaining();
    opts.budget_seconds = Some(budget);
    opts.time_limit = Some(Duration::from_secs_f64(if cpu_limit {
        budget * 20.0
    } else {
        budget
    }));
    let mut solver = ExactSolver::new(instance, opts.clone()).expect("solver");
    if let Some((tour, cost)) = &best {
        solver.offer_incumbent(tour, *cost);
    }
    let mut restricted_lb = None;
    if restricted_seconds > 0.0 {
        // The restricted bound needs a guide tour: the ALNS tour, or the solver's first one.
        if best.is_none() {
            solver.step(Duration::from_millis(1));
        }
        if let Some(guide) = solver.progress().best_tour {
            let ub = solver.progress().upper_bound;
            let seconds = restricted_seconds.min(remaining());
            let bound = restricted_bound(
                instance,
                &guide,
                ub,
                &RestrictedBoundOptions {
                    time_limit: Duration::from_secs_f64(seconds),
                    known_bound: solver.root_bound(),
                    ..RestrictedBoundOptions::default()
                },
            )
            .expect("subset bound");
            solver.offer_lower_bound(bound.lower_bound);
            restricted_lb = Some(format!("{} ({})", bound.lower_bound, bound.clusters));
        }
    }
    let mut status = Status::Running;
    while status == Status::Running && clock() < limit {
        status = solver.step(Duration::from_millis(100));
    }
    let proven = matches!(
        status,
        Status::Finished {
            proven_optimal: true
        }
    );
    (
        solver.progress(),
        proven,
        solver.states_created(),
        restricted_lb,
    )
}
