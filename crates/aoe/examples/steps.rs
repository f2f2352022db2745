//! Step lengths of [`AoeSolving`] on `generate_nest(n, 1)` (default 5,000 contours), stepped as
//! the web worker steps a job (40 ms slices): the longest steps by CPU time of this thread
//! (Linux: `/proc/thread-self/schedstat`), since on a loaded machine wall time is the work
//! stretched by the scheduler.
//!
//! `cargo run --release -p cutroute-aoe --example steps -- [contours]`

use cutroute_aoe::{AoeSolveOptions, AoeSolving, PlanOptions};
use std::time::{Duration, Instant};

/// CPU time of this thread, seconds.
fn cpu() -> f64 {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux schedstat");
    let ns: f64 = text.split_whitespace().next().unwrap().parse().unwrap();
    ns * 1e-9
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(5000, |a| a.parse().expect("a contour count"));
    let nest = cutroute_geometry::generate_nest(n, 1);
    let options = AoeSolveOptions {
        plan: PlanOptions {
            tolerance: nest.check_tolerance(),
            ..PlanOptions::default()
        },
        ..AoeSolveOptions::default()
    };
    let (wall, cpu_start) = (Instant::now(), cpu());
    let mut solving = AoeSolving::new(&nest, &options);
    let mut steps: Vec<(f64, String)> = Vec::new();
    loop {
        let before = solving.stage();
        let t = cpu();
        let status = solving.step(Duration::from_millis(40));
        steps.push((cpu() - t, format!("{before:?} → {:?}", solving.stage())));
        if status.is_done() {
            break;
        }
    }
    let route = &solving.outcome().unwrap().as_ref().unwrap().route;
    println!(
        "{n} contours: {} steps, wall {:.2} s, CPU {:.2} s, idle {:.1} mm, {} pierces",
        steps.len(),
        wall.elapsed().as_secs_f64(),
        cpu() - cpu_start,
        route.idle_length(),
        route.pierce_count()
    );
    steps.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("| longest steps, CPU s | stage |\n|---:|---|");
    for (seconds, stage) in steps.iter().take(5) {
        println!("| {seconds:.3} | {stage} |");
    }
}
