//! What the engine's test binaries share: the real data files and the independent check of a
//! nest job's answer.
#![allow(dead_code)]

use std::path::PathBuf;

use cutroute_geometry::{KerfSettings, MachineParameters, Nest};
use cutroute_protocol::{CostUnit, Problem, Progress};

/// The name and bytes of a file under `data/`; panics naming the file when it is missing.
pub fn data(relative: &str) -> (String, Vec<u8>) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    let bytes = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("missing test file {}: {e}", path.display()));
    (relative.to_string(), bytes)
}

/// The route of a nest job's result, through the independent checker; its idle length. The
/// reported upper bound must be the route's value in the job's unit: its idle length, or
/// (chain cutting) its cost at the default machine's prices.
pub fn check_route(problem: &Problem, result: &Progress) -> f64 {
    check_route_at(problem, result, &MachineParameters::default())
}

/// [`check_route`] for a job run at `machine`'s prices.
pub fn check_route_at(problem: &Problem, result: &Progress, machine: &MachineParameters) -> f64 {
    let Problem::Nest { nest, .. } = problem else {
        panic!("a nest")
    };
    let route = result.route().expect("a route");
    route
        .validate(nest, 1e-3)
        .expect("the route passes the independent checker");
    let idle = route.idle_length();
    let value = match result.bounds.unit {
        CostUnit::Cost => route.cost(nest, machine),
        _ => idle,
    };
    let reported = result.bounds.upper.expect("an upper bound");
    assert!(
        (value - reported).abs() <= 1e-6 * value.max(1.0),
        "reported {reported} vs recomputed {value} ({:?})",
        result.bounds.unit
    );
    idle
}

/// The problem of a nest file under `data/`, opened by the engine.
pub fn nest_problem(relative: &str) -> Problem {
    let (name, bytes) = data(relative);
    cutroute_engine::open_document(&name, &bytes)
        .expect("opens")
        .problem
}

/// The nest of a nest problem.
pub fn nest_of(problem: &Problem) -> &Nest {
    match problem {
        Problem::Nest { nest, .. } => nest,
        Problem::PcgtspText { .. } => panic!("a nest"),
    }
}

/// Kerf 2, d₁ 5, d₂ 1, an 8 mm arc lead-in and a 2 mm line lead-out (issue #17's plasma).
pub fn plasma() -> KerfSettings {
    KerfSettings::plasma_reference()
}
