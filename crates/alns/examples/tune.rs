//! Parameter exploration on one instance file (not a benchmark; see `cutroute-bench`).
//!
//! `cargo run --release -p cutroute-alns --example tune -- FILE SECONDS SEEDS [key=value …]`
//! with keys `start`, `end`, `epoch`, `growth`, `noise`, `frac`, `gate`, `maxrem`.

use std::time::Duration;

use cutroute_alns::{solve, AlnsOptions};
use cutroute_pcgtsp::{check_tour, Instance};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).expect("readable instance file");
    let instance = Instance::parse(&text).expect("instance parses");
    let seconds: f64 = args[2].parse().expect("seconds");
    let seeds: u64 = args[3].parse().expect("seeds");
    let mut options = AlnsOptions {
        time_limit: Some(Duration::from_secs_f64(seconds)),
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
            "target" => options.target_cost = Some(v.parse().unwrap()),
            _ => panic!("unknown key {k}"),
        }
    }
    for seed in 1..=seeds {
        options.seed = seed;
        let mut last = String::new();
        let result = solve(&instance, options.clone(), &mut |p| {
            last = format!(
                "{:.3}s {:?} it {}",
                p.elapsed.as_secs_f64(),
                p.best_cost,
                p.iterations
            );
        })
        .unwrap();
        let tour = result.tour.unwrap();
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
