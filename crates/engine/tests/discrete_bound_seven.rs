//! The exact job on seven.dbs with the interval bound beside it, in a test binary of its own:
//! the bound has half of the limit, and beside the other discrete-bound runs (nested.dbs is
//! the heaviest of them) on two cores it got too little of it to report anything. The limit is
//! 6 s: with 3 s this unoptimised build still ended without a bound once, at a load average
//! near 4 with a workspace build beside it.

mod common;

use common::{check_route, data};
use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_protocol::{JobRequest, SolverKind, SolverParams};

/// On seven.dbs (50 contours) the job's bound stays below its own route.
#[test]
fn discrete_exact_job_on_seven_reports_a_bound_below_its_route() {
    let (name, bytes) = data("nests/dbs/seven.dbs");
    let document = open_document(&name, &bytes).expect("opens");
    let request = JobRequest {
        job_id: 4,
        problem: document.problem.clone(),
        solver: SolverKind::Exact,
        params: SolverParams {
            time_limit_s: 6.0,
            discretisation_step_mm: 25.0,
            ..SolverParams::default()
        },
    };
    let mut job = start_job(&request).expect("starts");
    let result = run_to_end(job.as_mut(), &mut |_| {});
    let idle = check_route(&document.problem, &result);
    let lb = result.bounds.lower.expect("a lower bound");
    assert!(lb > 0.0 && lb <= idle, "bound {lb} vs route {idle}");
}
