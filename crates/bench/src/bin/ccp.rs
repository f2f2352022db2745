//! Benchmark: ccp solver (being written).
fn main() {}
