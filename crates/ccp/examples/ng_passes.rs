//! Diagnostics: the ng-path bound (`NgPathBound`) pass by pass on a PCGTSP instance file, e.g.
//! the candidates' relaxation that `candidate_bound` dumps, printed as a Markdown table.
//!
//! `cargo run --release -p cutroute-ccp --example ng_passes -- /tmp/cand.pcglns 12 60 [TOUR.json]`
//! (instance, neighbourhood size, seconds, and optionally the JSON of `cutroute solve FILE
//! --json` whose tour is offered first: what the bound's pruning and step size start from).
//!
//! The bound's values depend only on the passes made, not on their timing, so two builds
//! compare pass by pass (same bound column) and by time (the seconds columns).

use std::time::{Duration, Instant};

use cutroute_ccp::NgPathBound;
use cutroute_pcgtsp::Instance;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("a PCGTSP instance file");
    let ng_size: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(12);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let text = std::fs::read_to_string(path).expect("readable");
    let instance = Instance::parse(&text).expect("an instance");
    let began = Instant::now();
    let mut ng = NgPathBound::new(&instance, ng_size, &[]).expect("a depot of one node");
    if let Some(tour_file) = args.get(4) {
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(tour_file).expect("readable"))
                .expect("JSON");
        // The CLI's tours are 1-based.
        let tour: Vec<usize> = json["tour"]
            .as_array()
            .expect("a tour")
            .iter()
            .filter_map(|v| v.as_u64().and_then(|k| k.checked_sub(1)))
            .map(|k| k as usize)
            .collect();
        ng.offer_tour(&tour);
    }
    println!(
        "{} nodes, {} clusters, ng = {ng_size}\n",
        instance.node_count,
        instance.clusters.len()
    );
    println!("| pass | s | pass s | bound | labels | pruned |");
    println!("|---|---|---|---|---|---|");
    let (mut passes, mut last) = (0, 0.0);
    while began.elapsed().as_secs_f64() < seconds {
        if !ng.step(Instant::now() + Duration::from_millis(40)) {
            break;
        }
        if ng.iterations() > passes {
            passes = ng.iterations();
            let now = began.elapsed().as_secs_f64();
            let stats = ng.stats();
            println!(
                "| {passes} | {now:.1} | {:.2} | {:.1} | {} | {} |",
                now - last,
                ng.lower_bound(),
                stats.labels,
                stats.pruned
            );
            last = now;
        }
    }
}
