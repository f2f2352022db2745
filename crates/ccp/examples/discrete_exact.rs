//! Diagnostics for the discrete exact bound on a nest (issue #14, part 2): the nest discretised
//! every `step` mm, solved by `cutroute-pcgtsp`'s exact solver with or without its own beam-search
//! heuristic, printing the lower bound as it goes (`PCGTSP_DEBUG=1` shows the bound phases).
//!
//! `cargo run --release -p cutroute-ccp --example discrete_exact -- data/nests/dbs/nested.dbs 25 60 no-beam`

use std::time::{Duration, Instant};

use cutroute_ccp::{build_pcgtsp, DiscretisationOptions};
use cutroute_pcgtsp::{ExactOptions, ExactSolver, Status};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("a nest file");
    let step: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(25.0);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let beam = args.get(4).is_none_or(|s| s != "no-beam");
    let bytes = std::fs::read(path).expect("readable");
    let mut nest = cutroute_formats::read_nest(&bytes).expect("a nest");
    nest.normalize_orientation();
    let t = Instant::now();
    let discrete = build_pcgtsp(
        &nest,
        &DiscretisationOptions {
            step,
            ..DiscretisationOptions::default()
        },
    )
    .expect("an instance");
    let instance = &discrete.instance;
    println!(
        "{} nodes, {} clusters, {} precedence pairs, built in {:.1} s",
        instance.node_count,
        instance.clusters.len(),
        instance.precedence.len(),
        t.elapsed().as_secs_f64()
    );
    let limit = Duration::from_secs_f64(seconds);
    let options = ExactOptions {
        time_limit: Some(limit),
        heuristic: beam,
        ..ExactOptions::default()
    };
    let mut solver = ExactSolver::new(instance, options).expect("a solver");
    println!(
        "root bound {:.1} at {:.1} s",
        solver.root_bound(),
        t.elapsed().as_secs_f64()
    );
    let mut last_print = 0.0;
    loop {
        let status = solver.step(Duration::from_millis(100));
        let p = solver.progress();
        let now = t.elapsed().as_secs_f64();
        if now - last_print >= 5.0 || status != Status::Running {
            last_print = now;
            println!(
                "{now:6.1} s  lb {:.1}  ub {:.1}  layer {}  states {}",
                p.lower_bound, p.upper_bound, p.layer, p.live_states
            );
        }
        if status != Status::Running || now > seconds + 30.0 {
            break;
        }
    }
}
