//! Benchmark: heuristic solver (being written).
fn main() {}
