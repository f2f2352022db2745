//! The workspace benchmark `cutroute-bench --bin exact`, built from this crate alone (so it runs
//! while sibling crates are mid-edit): `cargo run --release -p cutroute-pcgtsp --example exact_bench -- …`.

#[path = "../../bench/src/bin/exact.rs"]
mod exact;

fn main() {
    exact::main();
}
