//! Diagnostics: the ng-path bound (`NgPathBound`) on a nest's interval relaxation after some
//! stages, against the exact search's bound on the same instance.
//!
//! `cargo run --release -p cutroute-ccp --example ng_bound -- data/nests/dbs/nested.dbs 400 8 20 9535`
//! (nest, pieces, neighbourhood size, seconds, a known route's idle length). With `NG_DUMP=FILE`
//! the relaxed instance is also written to FILE (PCGLNS), for a heuristic to bound its optimum
//! from above: `cutroute solve FILE --solver heuristic`.

use std::time::{Duration, Instant};

use cutroute_ccp::{CcpLowerBound, LowerBoundOptions, NgPathBound};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("a nest file");
    // Pieces of the relaxation (shared by perimeter, as in the first stage).
    let pieces: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(400);
    let ng_size: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(8);
    let seconds: f64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(20.0);
    let target: f64 = args
        .get(5)
        .and_then(|s| s.parse().ok())
        .unwrap_or(f64::INFINITY);
    let bytes = std::fs::read(path).expect("readable");
    let mut nest = if path.ends_with(".tfnesting") {
        // T-FLEX files hold sheets; the first is the nest.
        cutroute_cad::tflex::read_tfnesting(&bytes)
            .expect("a T-FLEX nesting")
            .into_iter()
            .next()
            .expect("a sheet")
    } else {
        cutroute_formats::read_nest(&bytes).expect("a nest")
    };
    nest.normalize_orientation();
    let options = LowerBoundOptions {
        budget_seconds: 30.0,
        group_size: 0,
        ng_size: 0,
        initial_pieces: pieces,
        ..LowerBoundOptions::default()
    };
    let mut bound = CcpLowerBound::new(&nest, options.clone()).expect("options");
    if bound.kept_contours() > 256 {
        // Beyond the exact search's keys the relaxation is built only for the ng-path bound.
        let options = LowerBoundOptions {
            ng_size,
            ng_above: 0,
            ng_alone: true,
            ..options
        };
        bound = CcpLowerBound::new(&nest, options).expect("options");
    }
    while bound.relaxed_instance().is_none() && bound.step(Duration::from_millis(100)) {}
    println!(
        "{:.1} s: exact search's bound {:.1}",
        bound.elapsed().as_secs_f64(),
        bound.lower_bound()
    );
    let Some(instance) = bound.relaxed_instance() else {
        return;
    };
    if let Ok(dump) = std::env::var("NG_DUMP") {
        // The relaxed instance for another solver (e.g. `cutroute solve FILE --solver
        // heuristic`): how far its optimum lies above the bound.
        std::fs::write(&dump, instance.to_pcglns()).expect("writable");
        println!("wrote {dump} ({} nodes)", instance.node_count);
    }
    let began = Instant::now();
    let mut ng = NgPathBound::new(instance, ng_size, &[]).expect("a depot node");
    ng.set_upper(target);
    let mut printed = 0;
    while began.elapsed().as_secs_f64() < seconds {
        if !ng.step(Instant::now() + Duration::from_millis(40)) {
            break;
        }
        if ng.iterations() >= printed + 5 {
            printed = ng.iterations();
            println!(
                "{:.1} s: {} iterations, ng-path bound {:.1} (labels {}, pruned {}, backward {:.1} s, forward {:.1} s)",
                began.elapsed().as_secs_f64(),
                ng.iterations(),
                ng.lower_bound(),
                ng.stats().labels,
                ng.stats().pruned,
                ng.stats().backward_seconds,
                ng.stats().forward_seconds,
            );
        }
    }
    println!(
        "{} nodes, ng {ng_size}: {:.1} after {} iterations in {:.1} s (longest step overrun {:.3} s)",
        instance.node_count,
        ng.lower_bound(),
        ng.iterations(),
        began.elapsed().as_secs_f64(),
        ng.stats().longest_overrun_seconds
    );
}
