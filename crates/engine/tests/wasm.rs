//! The engine compiled to wasm32 and run in headless Chromium (`scripts/test.sh` runs these with
//! wasm-bindgen-test-runner): the code paths the worker uses, including the clock, which must
//! not be `std::time` in a browser.
#![cfg(target_arch = "wasm32")]

use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_protocol::{JobRequest, Problem, Solution, SolverKind, SolverParams};
use wasm_bindgen_test::{wasm_bindgen_test, wasm_bindgen_test_configure};

wasm_bindgen_test_configure!(run_in_browser);

const SAMPLE: &[u8] = include_bytes!("../../../data/nests/dbs-json/E1X_6_01.dbs.json");

#[wasm_bindgen_test]
fn opens_a_sample_and_routes_it_in_the_browser() {
    let document = open_document("E1X_6_01.dbs.json", SAMPLE).expect("sample opens");
    let Problem::Nest { nest, .. } = &document.problem else {
        panic!("the sample is a nest")
    };
    let nest = nest.clone();
    let request = JobRequest {
        job_id: 1,
        problem: document.problem,
        solver: SolverKind::NearestNeighbour,
        params: SolverParams::default(),
    };
    let mut job = start_job(&request).expect("job starts");
    let result = run_to_end(job.as_mut(), &mut |_| {});
    let route = result
        .solution
        .and_then(Solution::into_route)
        .expect("a route");
    assert_eq!(route.steps.len(), 16);
    // The route computed in the browser passes the same independent checker as natively, and
    // the bound the page would show is its idle length.
    let problems = route.problems(&nest, &nest.containment_forest(), 1e-3);
    assert!(problems.is_empty(), "{problems:?}");
    let idle = route.idle_length();
    let reported = result.bounds.upper.expect("an upper bound");
    assert!(
        (reported - idle).abs() <= 1e-6 * idle,
        "{reported} vs {idle}"
    );
    assert!(result.elapsed_s >= 0.0);
}
