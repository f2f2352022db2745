//! Benchmark of the ALNS heuristic (`cutroute-alns`) on the 59 PCGTSP instances of
//! `data/pcgtsp`, next to PCGLNS and the known optima of `reference.csv`.
//!
//! ```text
//! cargo run --release -p cutroute-bench --bin heuristic -- [--seeds 5] [--limits 1,5,30]
//!     [--filter NAME[,NAME…]] [--no-target] [--cap-unknown S] [--wall]
//! cargo run --release -p cutroute-bench --bin heuristic -- --iterations N [--seeds K] [--filter …]
//! ```
//!
//! One run per instance and seed, to the largest limit; the result at every smaller limit is
//! the best tour at that time of the same run (the search's trajectory depends only on the seed
//! and the iteration count, so this is what a run with the smaller limit returns). The run also
//! takes a snapshot at `min(pcglns_time_s, largest limit)`: the main target is a median cost ≤
//! PCGLNS's in no more time than PCGLNS took. Runs stop early at the known optimum (a proven
//! optimum cannot be beaten; later limits then show that tour) unless `--no-target`.
//! `--cap-unknown S` ends the runs on instances without a known optimum at
//! `max(S, min(pcglns_time_s, largest limit))` to save CPU time (their larger-limit columns
//! then show "–"). Limits and times are CPU seconds of the solver's thread (from
//! `/proc/thread-self/stat`, 10 ms resolution) so that a loaded shared machine does not distort
//! the comparison; `--wall` uses wall-clock time instead. Each tour is checked by
//! `cutroute_pcgtsp::check_tour`.
//!
//! `--iterations N` measures throughput instead: N iterations per seed (no target), printing
//! iterations per CPU second and the final cost (equal costs before and after a speed-up show
//! that it left the search unchanged).

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use cutroute_alns::{AlnsOptions, AlnsSolver};
use cutroute_bench::{run_heuristic_with_snapshots, HeuristicSnapshot};
use cutroute_pcgtsp::{check_tour, Instance};

/// One row of `reference.csv`.
struct Reference {
    set: String,
    instance: String,
    nodes: usize,
    clusters: usize,
    pcglns_cost: f64,
    pcglns_time_s: f64,
    known_optimum: Option<f64>,
}

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/pcgtsp")
}

fn read_reference() -> Vec<Reference> {
    let path = data_dir().join("reference.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut lines = text.lines();
    let header = cutroute_bench::csv_fields(lines.next().expect("reference.csv is empty"));
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("reference.csv has no column {name}"))
    };
    let (set, instance, nodes, clusters) = (
        column("set"),
        column("instance"),
        column("nodes"),
        column("clusters"),
    );
    let (cost, time, optimum) = (
        column("pcglns_cost"),
        column("pcglns_time_s"),
        column("known_optimum"),
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let f = cutroute_bench::csv_fields(line);
            Reference {
                set: f[set].clone(),
                instance: f[instance].clone(),
                nodes: f[nodes].parse().expect("nodes"),
                clusters: f[clusters].parse().expect("clusters"),
                pcglns_cost: f[cost].parse().expect("pcglns_cost"),
                pcglns_time_s: f[time].parse().expect("pcglns_time_s"),
                known_optimum: f[optimum].trim().parse().ok(),
            }
        })
        .collect()
}

struct Args {
    seeds: u64,
    limits: Vec<f64>,
    filter: Vec<String>,
    target: bool,
    cap_unknown: Option<f64>,
    wall: bool,
    iterations: Option<u64>,
}

/// A clock that measures either the thread's CPU time or wall-clock time.
struct Clock {
    wall: bool,
    cpu_start: f64,
    wall_start: std::time::Instant,
}

impl Clock {
    fn start(wall: bool) -> Self {
        Clock {
            wall,
            cpu_start: cutroute_bench::thread_cpu_seconds(),
            wall_start: std::time::Instant::now(),
        }
    }

    fn seconds(&self) -> f64 {
        if self.wall {
            self.wall_start.elapsed().as_secs_f64()
        } else {
            cutroute_bench::thread_cpu_seconds() - self.cpu_start
        }
    }
}

fn parse_args() -> Args {
    let mut args = Args {
        seeds: 5,
        limits: vec![1.0, 5.0, 30.0],
        filter: Vec::new(),
        target: true,
        cap_unknown: None,
        wall: false,
        iterations: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--seeds" => args.seeds = value().parse().expect("--seeds N"),
            "--limits" => {
                args.limits = value()
                    .split(',')
                    .map(|s| s.trim().parse().expect("--limits 1,5,30"))
                    .collect();
                args.limits.sort_by(f64::total_cmp);
            }
            "--filter" => args.filter = value().split(',').map(str::to_owned).collect(),
            "--no-target" => args.target = false,
            "--cap-unknown" => args.cap_unknown = Some(value().parse().expect("--cap-unknown S")),
            "--wall" => args.wall = true,
            "--iterations" => args.iterations = Some(value().parse().expect("--iterations N")),
            other => panic!("unknown argument {other}"),
        }
    }
    args
}

fn median(values: &[f64]) -> f64 {
    let mut values = values.to_vec();
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

fn load(r: &Reference) -> Instance {
    let path = data_dir()
        .join(&r.set)
        .join(format!("{}.pcglns", r.instance));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    Instance::parse(&text).expect("instance parses")
}

/// Checks a tour with the independent checker and that it costs what the solver said.
fn check(instance: &Instance, tour: &[usize], cost: f64) {
    let checked = check_tour(instance, tour)
        .unwrap_or_else(|e| panic!("{}: infeasible tour: {e}", instance.name));
    assert!(
        (checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()),
        "{}: solver says {cost}, checker {checked}",
        instance.name
    );
}

/// `--iterations N`: iterations per CPU second and final cost for a fixed iteration count.
fn throughput(args: &Args, selected: &[&Reference], iterations: u64) {
    println!("| instance | m | seeds × iterations | CPU s | iterations / CPU s | final costs |");
    println!("|---|---|---|---|---|---|");
    let mut total_iterations = 0.0;
    let mut total_seconds = 0.0;
    for r in selected {
        let instance = load(r);
        let clock = Clock::start(args.wall);
        let mut costs = Vec::new();
        for seed in 1..=args.seeds {
            let options = AlnsOptions {
                seed,
                time_limit: None,
                max_iterations: Some(iterations),
                ..AlnsOptions::default()
            };
            let result = cutroute_alns::solve(&instance, options, &mut |_| {}).expect("solves");
            let tour = result.tour.expect("a feasible tour");
            check(&instance, &tour, result.cost.unwrap());
            costs.push(result.cost.unwrap().to_string());
        }
        let seconds = clock.seconds();
        let done = (iterations * args.seeds) as f64;
        total_iterations += done;
        total_seconds += seconds;
        println!(
            "| {} | {} | {} × {iterations} | {seconds:.2} | {:.0} | {} |",
            r.instance,
            r.clusters,
            args.seeds,
            done / seconds,
            costs.join(" ")
        );
    }
    println!(
        "\nAll: {total_iterations} iterations in {total_seconds:.2} CPU s ({:.0} / s).",
        total_iterations / total_seconds
    );
}

fn cell(values: Option<(f64, f64)>) -> String {
    values.map_or("–".to_owned(), |(best, med)| format!("{best} / {med}"))
}

/// One seed's run, kept alive so that a capped run can be continued.
struct SeedRun {
    solver: AlnsSolver,
    /// Snapshots at every limit reached so far.
    snapshots: Vec<HeuristicSnapshot>,
    time_to_reach: Option<f64>,
    time_to_optimum: Option<f64>,
    seconds: f64,
    finished_early: bool,
}

/// All seeds of one instance.
struct InstanceRuns<'a> {
    reference: &'a Reference,
    instance: Instance,
    /// `min(pcglns_time_s, largest limit)`: where the main target is checked.
    target_time: f64,
    /// How far the first pass ran.
    run_to: f64,
    seeds: Vec<SeedRun>,
}

/// Advances every seed of `runs` to `limits` (clock readings continue from where each seed
/// stopped), checking every snapshot's tour with the independent checker.
fn advance(runs: &mut InstanceRuns, limits: &[f64], wall: bool) {
    let pcglns_cost = runs.reference.pcglns_cost + 1e-6;
    let optimum = runs
        .reference
        .known_optimum
        .map_or(f64::NEG_INFINITY, |o| o + 1e-6);
    for seed in &mut runs.seeds {
        let offset = seed.seconds;
        let clock = Clock::start(wall);
        let mut to_optimum = seed.time_to_optimum;
        let run = run_heuristic_with_snapshots(
            &mut seed.solver,
            limits,
            pcglns_cost,
            Duration::from_millis(2),
            &mut |progress| {
                let now = offset + clock.seconds();
                if to_optimum.is_none() && progress.best_cost.is_some_and(|c| c <= optimum) {
                    to_optimum = Some(now);
                }
                now
            },
        );
        for snapshot in &run.snapshots {
            check(&runs.instance, &snapshot.tour, snapshot.cost);
        }
        seed.time_to_reach = seed.time_to_reach.or(run.time_to_reach);
        seed.time_to_optimum = to_optimum;
        seed.seconds = seed.seconds.max(run.seconds);
        seed.finished_early |= run.finished_early;
        seed.snapshots.extend(run.snapshots);
    }
}

/// Costs of all seeds at `limit`, if every seed has a snapshot there (or stopped before it:
/// a run stopped at the optimum keeps its tour).
fn costs_at(runs: &InstanceRuns, limit: f64) -> Option<Vec<f64>> {
    runs.seeds
        .iter()
        .map(|seed| {
            seed.snapshots
                .iter()
                .find(|s| s.limit == limit)
                .or_else(|| {
                    seed.finished_early
                        .then(|| {
                            seed.snapshots
                                .iter()
                                .max_by(|a, b| a.limit.total_cmp(&b.limit))
                        })
                        .flatten()
                })
                .map(|s| s.cost)
        })
        .collect()
}

fn summary(costs: &[f64]) -> (f64, f64) {
    let best = costs.iter().cloned().fold(f64::INFINITY, f64::min);
    (best, median(costs))
}

fn fmt_time(t: f64) -> String {
    if t.is_finite() {
        format!("{t:.2}")
    } else {
        "–".to_owned()
    }
}

fn print_header(args: &Args) {
    let limit_headers: Vec<String> = args
        .limits
        .iter()
        .map(|l| format!("{l} s best / median"))
        .collect();
    println!(
        "| instance | n | m | PCGLNS cost | PCGLNS s | known opt | {} | at PCGLNS s: median | ≤ PCGLNS (seeds) | median s to PCGLNS cost | at opt (seeds) | median s to opt | run s (max) | median iterations |",
        limit_headers.join(" | ")
    );
    println!(
        "|---|---|---|---|---|---|{}---|---|---|---|---|---|---|---|",
        "---|".repeat(args.limits.len())
    );
}

/// Totals for the summary lines.
#[derive(Default)]
struct Tally {
    instances: usize,
    median_fails: Vec<String>,
    optimum_instances: usize,
    optimum_reached: usize,
    optimum_missed: Vec<String>,
}

fn print_row(args: &Args, runs: &InstanceRuns, tally: &mut Tally) {
    let r = runs.reference;
    let limit_cells: Vec<String> = args
        .limits
        .iter()
        .map(|&l| costs_at(runs, l).map(|c| summary(&c)))
        .map(cell)
        .collect();
    let target_costs = costs_at(runs, runs.target_time).expect("target snapshot");
    let target_median = median(&target_costs);
    let beat = target_costs
        .iter()
        .filter(|&&c| c <= r.pcglns_cost + 1e-6)
        .count();
    tally.instances += 1;
    if target_median > r.pcglns_cost + 1e-6 {
        tally.median_fails.push(format!(
            "{} (median {target_median} > {} at {} s)",
            r.instance, r.pcglns_cost, runs.target_time
        ));
    }
    let reach: Vec<f64> = runs
        .seeds
        .iter()
        .map(|s| s.time_to_reach.unwrap_or(f64::INFINITY))
        .collect();
    let to_optimum: Vec<f64> = runs
        .seeds
        .iter()
        .map(|s| s.time_to_optimum.unwrap_or(f64::INFINITY))
        .collect();
    let at_optimum = to_optimum.iter().filter(|t| t.is_finite()).count();
    if let Some(optimum) = r.known_optimum {
        tally.optimum_instances += 1;
        if at_optimum > 0 {
            tally.optimum_reached += 1;
        } else {
            let best = runs
                .seeds
                .iter()
                .flat_map(|s| s.snapshots.iter().map(|x| x.cost))
                .fold(f64::INFINITY, f64::min);
            tally
                .optimum_missed
                .push(format!("{} (best {best}, optimum {optimum})", r.instance));
        }
    }
    let iterations: Vec<f64> = runs
        .seeds
        .iter()
        .map(|s| s.snapshots.iter().map(|x| x.iterations).max().unwrap_or(0) as f64)
        .collect();
    let run_seconds = runs.seeds.iter().map(|s| s.seconds).fold(0.0, f64::max);
    let with_optimum = |text: String| {
        if r.known_optimum.is_some() {
            text
        } else {
            "–".to_owned()
        }
    };
    println!(
        "| {} | {} | {} | {} | {} | {} | {} | {} | {beat}/{} | {} | {} | {} | {run_seconds:.1} | {} |",
        r.instance,
        r.nodes,
        r.clusters,
        r.pcglns_cost,
        r.pcglns_time_s,
        r.known_optimum.map_or("–".to_owned(), |o| o.to_string()),
        limit_cells.join(" | "),
        target_median,
        args.seeds,
        fmt_time(median(&reach)),
        with_optimum(format!("{at_optimum}/{}", args.seeds)),
        with_optimum(fmt_time(median(&to_optimum))),
        median(&iterations),
    );
    std::io::stdout().flush().ok();
}

fn print_tally(tally: &Tally, largest: f64) {
    println!(
        "\nMedian ≤ PCGLNS cost at min(pcglns_time_s, {largest} s): {}/{} instances{}.",
        tally.instances - tally.median_fails.len(),
        tally.instances,
        if tally.median_fails.is_empty() {
            String::new()
        } else {
            format!("; not on {}", tally.median_fails.join(", "))
        }
    );
    println!(
        "Known optimum reached (≥ 1 seed) within the run: {}/{}{}.",
        tally.optimum_reached,
        tally.optimum_instances,
        if tally.optimum_missed.is_empty() {
            String::new()
        } else {
            format!("; not on {}", tally.optimum_missed.join(", "))
        }
    );
}

fn main() {
    let args = parse_args();
    let references = read_reference();
    let selected: Vec<&Reference> = references
        .iter()
        .filter(|r| args.filter.is_empty() || args.filter.contains(&r.instance))
        .collect();
    if let Some(iterations) = args.iterations {
        throughput(&args, &selected, iterations);
        return;
    }
    let largest = *args.limits.last().expect("at least one limit");
    let clock_name = if args.wall {
        "wall clock"
    } else {
        "CPU time of the solver thread"
    };
    println!(
        "\n### ALNS, limits {:?} s ({clock_name}), {} seeds{}; `at PCGLNS s` = at min(pcglns_time_s, {largest} s)\n",
        args.limits,
        args.seeds,
        args.cap_unknown.map_or(String::new(), |c| format!(
            "; first pass: instances without a known optimum to max({c} s, min(pcglns_time_s, {largest} s))"
        )),
    );
    print_header(&args);
    let mut all = Vec::new();
    let mut tally = Tally::default();
    for r in &selected {
        let instance = load(r);
        let target_time = r.pcglns_time_s.min(largest);
        let run_to = match (args.cap_unknown, r.known_optimum) {
            (Some(cap), None) => cap.max(target_time).min(largest),
            _ => largest,
        };
        let mut limits: Vec<f64> = args
            .limits
            .iter()
            .copied()
            .filter(|&l| l <= run_to)
            .collect();
        limits.push(target_time);
        limits.push(run_to);
        let seeds = (1..=args.seeds)
            .map(|seed| {
                let options = AlnsOptions {
                    seed,
                    time_limit: None,
                    target_cost: if args.target { r.known_optimum } else { None },
                    ..AlnsOptions::default()
                };
                SeedRun {
                    solver: AlnsSolver::new(&instance, options)
                        .expect("solver accepts the instance"),
                    snapshots: Vec::new(),
                    time_to_reach: None,
                    time_to_optimum: None,
                    seconds: 0.0,
                    finished_early: false,
                }
            })
            .collect();
        let mut runs = InstanceRuns {
            reference: r,
            instance,
            target_time,
            run_to,
            seeds,
        };
        advance(&mut runs, &limits, args.wall);
        print_row(&args, &runs, &mut tally);
        if run_to < largest {
            all.push(runs);
        }
    }
    print_tally(&tally, largest);
    if all.is_empty() {
        return;
    }
    // Second pass: continue the capped runs to the largest limit (same solvers, clocks go on).
    println!("\n### Second pass: capped runs continued to {largest} s\n");
    print_header(&args);
    let mut tally = Tally::default();
    for runs in &mut all {
        let limits: Vec<f64> = args
            .limits
            .iter()
            .copied()
            .filter(|&l| l > runs.run_to)
            .collect();
        advance(runs, &limits, args.wall);
        print_row(&args, runs, &mut tally);
    }
    print_tally(&tally, largest);
}
