//! Diagnostics: the whole interval relaxation's bound against the decomposition bound (the
//! sum of the spatial groups' bounds) on a nest, over time, with CCP's route guiding both.
//!
//! `cargo run --release -p cutroute-ccp --example group_bound -- data/nests/dbs/nested.dbs 16 60`
//! (nest, group size (0: no groups), seconds of the bound's own time; CCP runs 10 s first;
//! then optionally a window `x0 y0 x1 y1`: only the parts inside it). Where the whole
//! relaxation is not solved, wide groups (`LowerBoundOptions::wide_group_size`) may take over
//! from groups of a smaller size; a size of at least that runs groups of that size alone.

use std::time::Duration;

use cutroute_ccp::{solve, CcpLowerBound, CcpOptions, LowerBoundOptions};
use cutroute_geometry::Point;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("a nest file");
    let group_size: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(16);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let bytes = std::fs::read(path).expect("readable");
    let mut nest = cutroute_formats::read_nest(&bytes).expect("a nest");
    // Optional window `x0 y0 x1 y1`: only the parts whose box lies inside it (a sub-nest).
    let window: Vec<f64> = args[4.min(args.len())..]
        .iter()
        .filter_map(|s| s.parse().ok())
        .collect();
    if let [x0, y0, x1, y1] = window[..] {
        nest.sheet = None;
        nest.parts.retain(|part| {
            let b = part
                .contours
                .iter()
                .map(|c| c.bounding_box())
                .fold(cutroute_geometry::BoundingBox::default(), |a, b| a.union(b));
            b.min.x >= x0 && b.min.y >= y0 && b.max.x <= x1 && b.max.y <= y1
        });
    }
    nest.normalize_orientation();
    let start = Point::new(0.0, 0.0);
    let ccp = solve(
        &nest,
        CcpOptions {
            start,
            time_limit: Duration::from_secs(10),
            ..CcpOptions::default()
        },
        &mut |_| {},
    )
    .expect("a route");
    let ub = ccp.metrics.idle_length;
    let options = LowerBoundOptions {
        start,
        budget_seconds: seconds,
        first_stage: Duration::from_secs_f64((seconds / 10.0).clamp(0.5, 5.0)),
        group_size,
        decompose_above: 0,
        ..LowerBoundOptions::default()
    };
    let mut bound = CcpLowerBound::new(&nest, options).expect("options");
    bound.offer_route(&ccp.route);
    println!(
        "{path}: {} kept contours, {} groups, CCP idle {ub:.1}",
        bound.kept_contours(),
        bound.group_count()
    );
    let mut next_report = 0.0;
    while bound.elapsed().as_secs_f64() < seconds && bound.step(Duration::from_millis(40)) {
        let t = bound.elapsed().as_secs_f64();
        if t >= next_report {
            println!(
                "{t:6.1} s: whole {:.1}, groups {:.1}, bound {:.1} ({:.2} % gap)",
                bound.whole_bound(),
                bound.group_sum(),
                bound.lower_bound(),
                100.0 * (ub - bound.lower_bound()) / ub
            );
            next_report = t + 5.0;
        }
    }
    let lb = bound.lower_bound();
    assert!(lb <= ub + 1e-6, "bound {lb} above the route {ub}");
    println!(
        "end {:.1} s: whole {:.1}, groups {:.1}, bound {lb:.1}, gap {:.2} %",
        bound.elapsed().as_secs_f64(),
        bound.whole_bound(),
        bound.group_sum(),
        100.0 * (ub - lb) / ub
    );
}
