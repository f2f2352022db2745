//! Diagnostics: the bound of a discretised nest at its candidates (`for_candidates`) against
//! the continuous bound, printed as they go.
//!
//! `cargo run --release -p cutroute-ccp --example candidate_bound -- data/nests/dbs/nested.dbs 25 30`
//! (nest, step mm, seconds, `candidates` or `continuous`, ng neighbourhood size).
//! With `NG_DUMP=FILE` the relaxed instance is written to FILE (PCGLNS).

use std::time::{Duration, Instant};

use cutroute_ccp::{
    build_pcgtsp, pierce_candidates, CcpLowerBound, DiscretisationOptions, LowerBoundOptions,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("a nest file");
    let step: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(25.0);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(30.0);
    let mode = args.get(4).cloned().unwrap_or_else(|| "candidates".into());
    let ng_size: usize = args.get(5).and_then(|s| s.parse().ok()).unwrap_or(8);
    let bytes = std::fs::read(path).expect("readable");
    let mut nest = cutroute_formats::read_nest(&bytes).expect("a nest");
    nest.normalize_orientation();
    let discrete = build_pcgtsp(
        &nest,
        &DiscretisationOptions {
            step,
            ..DiscretisationOptions::default()
        },
    )
    .expect("an instance");
    let candidates: Vec<_> = pierce_candidates(&discrete.nodes);
    let options = LowerBoundOptions {
        budget_seconds: seconds,
        first_stage: Duration::from_secs_f64((seconds / 10.0).clamp(0.25, 3.0)),
        max_nodes: 4000,
        ng_size,
        ..LowerBoundOptions::default()
    };
    let mut bound = if mode == "candidates" {
        CcpLowerBound::for_candidates(&nest, options, &candidates)
            .expect("options")
            .expect("candidates fit")
    } else {
        CcpLowerBound::new(&nest, options).expect("options")
    };
    println!(
        "{} kept contours, {} nodes",
        bound.kept_contours(),
        bound.node_count()
    );
    let t = Instant::now();
    let mut last = 0.0;
    let mut dumped = false;
    while t.elapsed().as_secs_f64() < seconds && bound.step(Duration::from_millis(100)) {
        if let (false, Ok(dump), Some(instance)) =
            (dumped, std::env::var("NG_DUMP"), bound.relaxed_instance())
        {
            // The relaxed instance for a heuristic: how far its optimum lies above the bound.
            std::fs::write(&dump, instance.to_pcglns()).expect("writable");
            println!("wrote {dump} ({} nodes)", instance.node_count);
            dumped = true;
        }
        let now = t.elapsed().as_secs_f64();
        if now - last >= 2.0 {
            last = now;
            println!(
                "{now:6.1} s  lb {:.1}  ng {:.1}",
                bound.lower_bound(),
                bound.ng_bound()
            );
        }
    }
    println!(
        "{:6.1} s  lb {:.1}  ng {:.1}",
        t.elapsed().as_secs_f64(),
        bound.lower_bound(),
        bound.ng_bound()
    );
}
