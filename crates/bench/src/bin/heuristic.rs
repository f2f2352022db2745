//! Benchmark of the ALNS heuristic (`cutroute-alns`) on the 59 PCGTSP instances of
//! `../shared/data/pcgtsp`, next to PCGLNS and the known optima of `reference.csv`.
//!
//! ```text
//! cargo run --release -p cutroute-bench --bin heuristic -- [--seeds 5] [--limits 1,5,30|pcglns]
//!     [--filter NAME[,NAME…]] [--no-target] [--scale F]
//! ```
//!
//! `--limits` takes seconds; `pcglns` means "each instance's own `pcglns_time_s`" (the main
//! target: beat PCGLNS in the time it took). Each tour is checked by `cutroute_pcgtsp::check_tour`.
//! Runs stop early at the known optimum (a proven optimum cannot be beaten) unless `--no-target`.
//! `--scale F` multiplies every limit. Limits and times are CPU seconds of the solver's thread
//! (from `/proc/thread-self/stat`, 10 ms resolution) so that a loaded shared machine does not
//! distort the comparison; `--wall` uses wall-clock time instead.

use std::path::PathBuf;
use std::time::Duration;

use cutroute_alns::{AlnsOptions, AlnsSolver, SolverStatus};
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
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/pcgtsp")
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

#[derive(Clone, Copy)]
enum Limit {
    Seconds(f64),
    Pcglns,
}

struct Args {
    seeds: u64,
    limits: Vec<Limit>,
    filter: Vec<String>,
    target: bool,
    scale: f64,
    wall: bool,
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
        limits: vec![
            Limit::Seconds(1.0),
            Limit::Seconds(5.0),
            Limit::Seconds(30.0),
        ],
        filter: Vec::new(),
        target: true,
        scale: 1.0,
        wall: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--seeds" => args.seeds = value().parse().expect("--seeds N"),
            "--limits" => {
                args.limits = value()
                    .split(',')
                    .map(|s| match s.trim() {
                        "pcglns" => Limit::Pcglns,
                        x => Limit::Seconds(x.parse().expect("--limits 1,5,30 or pcglns")),
                    })
                    .collect()
            }
            "--filter" => args.filter = value().split(',').map(str::to_owned).collect(),
            "--no-target" => args.target = false,
            "--scale" => args.scale = value().parse().expect("--scale F"),
            "--wall" => args.wall = true,
            other => panic!("unknown argument {other}"),
        }
    }
    args
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

fn main() {
    let args = parse_args();
    let references = read_reference();
    let selected: Vec<&Reference> = references
        .iter()
        .filter(|r| args.filter.is_empty() || args.filter.iter().any(|f| r.instance.contains(f)))
        .collect();
    for &limit in &args.limits {
        let title = match limit {
            Limit::Seconds(s) => format!("{s} s"),
            Limit::Pcglns => "pcglns_time_s".to_owned(),
        };
        println!(
            "\n### ALNS, time limit {title} × {} ({}), {} seeds\n",
            args.scale,
            if args.wall {
                "wall clock"
            } else {
                "CPU time of the solver thread"
            },
            args.seeds
        );
        println!("| instance | n | m | PCGLNS cost | PCGLNS s | known opt | ALNS best | ALNS median | ≤ PCGLNS (seeds) | median s to PCGLNS cost | median s to final best | at opt (seeds) | median iterations |");
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        let mut median_ok = 0;
        let mut optimum_instances = 0;
        let mut optimum_reached = 0;
        for r in &selected {
            let path = data_dir()
                .join(&r.set)
                .join(format!("{}.pcglns", r.instance));
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
            let instance = Instance::parse(&text).expect("instance parses");
            let seconds = match limit {
                Limit::Seconds(s) => s,
                Limit::Pcglns => r.pcglns_time_s,
            } * args.scale;
            let mut costs = Vec::new();
            let mut times_to_pcglns = Vec::new();
            let mut iterations = Vec::new();
            let mut times_to_best = Vec::new();
            let mut at_optimum = 0;
            for seed in 1..=args.seeds {
                let options = AlnsOptions {
                    seed,
                    time_limit: None,
                    target_cost: if args.target { r.known_optimum } else { None },
                    ..AlnsOptions::default()
                };
                let mut reached: Option<f64> = None;
                let mut last_improvement = 0.0;
                let mut solver =
                    AlnsSolver::new(&instance, options).expect("solver accepts the instance");
                let clock = Clock::start(args.wall);
                loop {
                    let status = solver.step_with(Duration::from_millis(10), &mut |progress| {
                        last_improvement = clock.seconds();
                        if reached.is_none()
                            && progress
                                .best_cost
                                .is_some_and(|c| c <= r.pcglns_cost + 1e-6)
                        {
                            reached = Some(clock.seconds());
                        }
                    });
                    if status == SolverStatus::Finished || clock.seconds() >= seconds {
                        break;
                    }
                }
                let result = solver.best().map(|(t, c)| (t.to_vec(), c));
                let (tour, cost) = result.expect("a feasible tour");
                let checked = check_tour(&instance, &tour).expect("tour passes the checker");
                assert!((checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()));
                costs.push(cost);
                times_to_pcglns.push(reached.unwrap_or(f64::INFINITY));
                iterations.push(solver.progress().iterations as f64);
                times_to_best.push(last_improvement);
                if r.known_optimum.is_some_and(|o| cost <= o + 1e-6) {
                    at_optimum += 1;
                }
            }
            let best = costs.iter().cloned().fold(f64::INFINITY, f64::min);
            let med = median(&mut costs.clone());
            let beat = costs.iter().filter(|&&c| c <= r.pcglns_cost + 1e-6).count();
            let med_time = median(&mut times_to_pcglns);
            if med <= r.pcglns_cost + 1e-6 {
                median_ok += 1;
            }
            if r.known_optimum.is_some() {
                optimum_instances += 1;
                if at_optimum > 0 {
                    optimum_reached += 1;
                }
            }
            println!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {}/{} | {} | {:.2} | {} | {} |",
                r.instance,
                r.nodes,
                r.clusters,
                r.pcglns_cost,
                r.pcglns_time_s,
                r.known_optimum.map_or("–".to_owned(), |o| o.to_string()),
                best,
                med,
                beat,
                args.seeds,
                if med_time.is_finite() {
                    format!("{med_time:.2}")
                } else {
                    "–".to_owned()
                },
                median(&mut times_to_best),
                if r.known_optimum.is_some() {
                    format!("{at_optimum}/{}", args.seeds)
                } else {
                    "–".to_owned()
                },
                median(&mut iterations),
            );
        }
        println!(
            "\nMedian ≤ PCGLNS cost on {median_ok}/{} instances; known optimum reached (≥ 1 seed) on \
             {optimum_reached}/{optimum_instances}.",
            selected.len()
        );
    }
}
