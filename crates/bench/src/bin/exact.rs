//! Benchmark: exact solver (being written).
fn main() {}
