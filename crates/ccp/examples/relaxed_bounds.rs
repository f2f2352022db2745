//! Diagnostics: the interval relaxation of a nest after a few stages, and what the pcgtsp
//! crate's position-indexed bound reaches on it with many subgradient iterations.
//!
//! `cargo run --release -p cutroute-ccp --example relaxed_bounds -- data/nests/dbs/nested.dbs 2 300 9535`
//! (nest, stages to run first, position-bound iterations, the length the subgradient aims at).

use std::time::{Duration, Instant};

use cutroute_ccp::{CcpLowerBound, LowerBoundOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("a nest file");
    let stages: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let iterations: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(300);
    // The subgradient steps aim at a known route's length (e.g. CCP's).
    let target: f64 = args
        .get(4)
        .and_then(|s| s.parse().ok())
        .unwrap_or(f64::INFINITY);
    let bytes = std::fs::read(path).expect("readable");
    let mut nest = cutroute_formats::read_nest(&bytes).expect("a nest");
    nest.normalize_orientation();
    let options = LowerBoundOptions {
        budget_seconds: 30.0,
        ..LowerBoundOptions::default()
    };
    let mut bound = CcpLowerBound::new(&nest, options).expect("options");
    while bound.stages() < stages && bound.step(Duration::from_millis(100)) {}
    while bound.relaxed_instance().is_none() && bound.step(Duration::from_millis(100)) {}
    println!(
        "after {} stages ({:.1} s): bound {:.1}",
        bound.stages(),
        bound.elapsed().as_secs_f64(),
        bound.lower_bound()
    );
    let Some(instance) = bound.relaxed_instance() else {
        return;
    };
    let t = Instant::now();
    let position =
        cutroute_pcgtsp::position_bounds(instance, None, target, iterations).expect("an order");
    println!(
        "{} nodes: position bound {:.1} after {} iterations in {:.1} s",
        instance.node_count,
        position.root,
        position.iterations,
        t.elapsed().as_secs_f64()
    );
    let roots = cutroute_pcgtsp::root_bounds(instance, 0).expect("an order");
    println!("root bounds: {roots:?}");
}
