//! Parameter exploration on one instance file (not a benchmark; see `cutroute-bench`).
//!
//! `cargo run --release -p cutroute-alns --example tune -- FILE SECONDS SEEDS [key=value …]`
//! with keys `start`, `end`, `epoch`, `growth`, `noise`, `frac`, `gate`, `maxrem`,
//! `block`, `bgate`, `cycle`, `elite`, `kick`, `target`.

use std::time::Duration;

use cutroute_alns::{AlnsOptions, AlnsSolver, Status};
use cutroute_pcgtsp::{check_tour, Instance};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).expect("readable instance file");
    let instance = Instance::parse(&text).expect("instance parses");
    let seconds: f64 = args[2].parse().expect("seconds");
    let seeds: u64 = args[3].parse().expect("seeds");
    let mut options = AlnsOptions {
        time_limit: None,
        ..AlnsOptions::default()
    };
    for kv in &args[4..] {
        let (k, v) = kv.split_once('=').expect("key=value");
        let p = &mut options.parameters;
        match k {
            "start" => p.start_temperature = v.parse().unwrap(),
            "end" => p.end_temperature = v.parse().unwrap(),
            "epoch" => p.epoch_iterations = v.parse().unwrap(),
            "growth" => p.epoch_growth = v.parse().unwrap(),
            "noise" => p.noise = v.parse().unwrap(),
            "frac" => p.max_removal_fraction = v.parse().unwrap(),
            "gate" => p.local_search_gate = v.parse().unwrap(),
            "maxrem" => p.max_removal = v.parse().unwrap(),
            "block" => p.block_reverse_length = v.parse().unwrap(),
            "bgate" => p.block_reverse_gate = v.parse().unwrap(),
            "cycle" => p.temperature_cycle = v.split(',').map(|x| x.parse().unwrap()).collect(),
            "elite" => p.elite_size = v.parse().unwrap(),
            "kick" => p.kick_fraction = v.parse().unwrap(),
            "target" => options.target_cost = Some(v.parse().unwrap()),
            _ => panic!("unknown key {k}"),
        }
    }
    for seed in 1..=seeds {
        options.seed = seed;
        let mut last = String::new();
        let mut solver = AlnsSolver::new(&instance, options.clone()).unwrap();
        let start = cpu_seconds();
        while solver.step_with(Duration::from_millis(10), &mut |p| {
            last = format!(
                "{:.3}s {:?} it {}",
                cpu_seconds() - start,
                p.best_cost,
                p.iterations
            );
        }) == Status::Running
            && cpu_seconds() - start < seconds
        {}
        let (tour, cost) = solver.best().map(|(t, c)| (t.to_vec(), c)).unwrap();
        let progress = solver.progress();
        struct R {
            cost: Option<f64>,
            progress: cutroute_alns::AlnsProgress,
        }
        let result = R {
            cost: Some(cost),
            progress,
        };
        check_tour(&instance, &tour).unwrap();
        if std::env::var("SHOW_TOUR").is_ok() {
            println!("{:?}", tour.iter().map(|v| v + 1).collect::<Vec<_>>());
        }
        println!(
            "seed {seed}: cost {:?} iterations {} restarts {} last improvement {last}",
            result.cost, result.progress.iterations, result.progress.restarts
        );
    }
}

/// CPU seconds of this thread (the machine is shared: wall time would mislead comparisons).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap();
    let rest = &stat[stat.rfind(')').unwrap() + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}
