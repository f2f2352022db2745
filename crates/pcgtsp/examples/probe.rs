//! Debug probe: solve one instance with chosen options and print the result.
use cutroute_pcgtsp::{check_tour, solve, ExactOptions, Instance};
use std::time::Duration;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = &args[1];
    let instance = Instance::parse(&std::fs::read_to_string(path).expect("read")).expect("parse");
    let mut options = ExactOptions {
        time_limit: Some(Duration::from_secs(
            args.get(2).map_or(30, |a| a.parse().expect("secs")),
        )),
        ..ExactOptions::default()
    };
    if args.iter().any(|a| a == "--no-lattice") {
        options.lattice_max_ideals = 0;
    }
    if let Some(w) = args.iter().position(|a| a == "--work") {
        options.lattice_work = args[w + 1].parse().expect("work");
    }
    let result = solve(&instance, options, &mut |_| {}).expect("solve");
    let p = &result.progress;
    let checked = p.best_tour.as_ref().map(|t| check_tour(&instance, t));
    println!(
        "UB {} LB {} proven {} root {} time {:?} states {} checked {:?}",
        p.upper_bound,
        p.lower_bound,
        result.proven_optimal(),
        result.root_bound,
        p.elapsed,
        result.states_created,
        checked
    );
    println!(
        "tour {:?}",
        p.best_tour
            .as_ref()
            .map(|t| t.iter().map(|v| v + 1).collect::<Vec<_>>())
    );
}
