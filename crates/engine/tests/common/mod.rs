//! What the engine's test binaries share: the real data files and the independent check of a
//! nest job's answer.
#![allow(dead_code)]

use std::path::PathBuf;

use cutroute_protocol::{Problem, Progress};

/// The name and bytes of a file under `data/`; panics naming the file when it is missing.
pub fn data(relative: &str) -> (String, Vec<u8>) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    let bytes = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("missing test file {}: {e}", path.display()));
    (relative.to_string(), bytes)
}

/// The route of a nest job's result, through the independent checker; its idle length, which
/// must be the reported upper bound.
pub fn check_route(problem: &Problem, result: &Progress) -> f64 {
    let Problem::Nest { nest, .. } = problem else {
        panic!("a nest")
    };
    let route = result.route().expect("a route");
    route
        .validate(nest, 1e-3)
        .expect("the route passes the independent checker");
    let idle = route.idle_length();
    let reported = result.bounds.upper.expect("an upper bound");
    assert!(
        (idle - reported).abs() <= 1e-6 * idle.max(1.0),
        "reported {reported} vs recomputed {idle}"
    );
    idle
}
