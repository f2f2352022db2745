//! The native peer of `tests/wasm_bench.rs`: the same benchmark subset, timed natively.
//! `cargo bench -p cutroute-engine --bench wasm_peer` (see `scripts/bench-wasm.sh`).

#[path = "../tests/bench_subset/mod.rs"]
mod bench_subset;

fn main() {
    bench_subset::run(&|line| println!("{line}"));
}
