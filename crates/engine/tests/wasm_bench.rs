//! Benchmark (not a test of speed): the exact solver compiled to wasm32 in headless Chromium on
//! industrial instances, timed with the browser's clock. `scripts/bench-wasm.sh` runs it in
//! release mode with the output shown, next to the native run of the same instances, and prints
//! the wasm/native ratio table for BENCHMARKS.md.
#![cfg(target_arch = "wasm32")]

use cutroute_engine::{run_to_end, start_job};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};
use wasm_bindgen_test::{console_log, wasm_bindgen_test, wasm_bindgen_test_configure};

wasm_bindgen_test_configure!(run_in_browser);

macro_rules! instance {
    ($name:literal) => {
        (
            $name,
            include_str!(concat!(
                "../../../../shared/data/pcgtsp/industrial/",
                $name,
                ".pcglns"
            )),
        )
    };
}

/// The subset: instances whose order has at most 300,000 ideals, small to large.
const SUBSET: [(&str, &str); 6] = [
    instance!("e1x_6"),
    instance!("e1x_1"),
    instance!("e1x_10"),
    instance!("34"),
    instance!("e3x_1"),
    instance!("ec_1"),
];

#[wasm_bindgen_test]
fn exact_solver_in_the_browser() {
    for (name, text) in SUBSET {
        let request = JobRequest {
            job_id: 1,
            problem: Problem::PcgtspText {
                text: text.to_string(),
            },
            solver: SolverKind::Exact,
            params: SolverParams {
                time_limit_s: 120.0,
                ..SolverParams::default()
            },
        };
        let mut job = start_job(&request).expect("starts");
        let result = run_to_end(job.as_mut(), &mut |_| {});
        console_log!(
            "WASM-BENCH {name} ub={} lb={} proven={} elapsed_s={:.3}",
            result.upper_bound.unwrap_or(f64::NAN),
            result.lower_bound.unwrap_or(f64::NAN),
            result.proven_optimal,
            result.elapsed_s
        );
        assert!(result.upper_bound.is_some());
    }
}
