//! Benchmark (not a test of speed): the subset in `bench_subset` compiled to wasm32 and run in
//! headless Chromium. `scripts/bench-wasm.sh` runs it next to `benches/wasm_peer.rs` (the same
//! code natively) and prints the wasm/native ratio table for BENCHMARKS.md.
#![cfg(target_arch = "wasm32")]

mod bench_subset;

use wasm_bindgen_test::{console_log, wasm_bindgen_test, wasm_bindgen_test_configure};

wasm_bindgen_test_configure!(run_in_browser);

#[wasm_bindgen_test]
fn solver_subset_in_the_browser() {
    bench_subset::run(&|line| console_log!("{line}"));
}
