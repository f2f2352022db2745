//! The benchmark subset shared by the wasm run (`tests/wasm_bench.rs`, in headless Chromium) and
//! the native run (`benches/wasm_peer.rs`): the same code, the same inputs, one line per case.

use cutroute_engine::{run_to_end, start_job};
use cutroute_geometry::{generate_nest, Point};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

macro_rules! instance {
    ($name:literal) => {
        (
            $name,
            include_str!(concat!(
                "../../../../data/pcgtsp/industrial/",
                $name,
                ".pcglns"
            )),
        )
    };
}

/// Industrial instances whose order has at most 300,000 ideals (2,048 to 295,245).
const EXACT_SUBSET: [(&str, &str); 7] = [
    instance!("e1x_6"),
    instance!("e1x_10"),
    instance!("e3x_1"),
    instance!("e1x_9"),
    instance!("ec_5"),
    instance!("e1x_1"),
    instance!("e1x_13"),
];

/// Runs every case and reports `BENCH <case> <seconds> <value> <proven>` lines through `log`.
pub fn run(log: &dyn Fn(String)) {
    for (name, text) in EXACT_SUBSET {
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
        log(format!(
            "BENCH exact:{name} {:.3} {} {}",
            result.elapsed_s,
            result.bounds.upper.unwrap_or(f64::NAN),
            result.proven_optimal
        ));
    }
    // CCP on synthetic nests: seconds to the first VNS local optimum.
    for contours in [1_000, 5_000] {
        let nest = generate_nest(contours, 1);
        let options = cutroute_ccp::CcpOptions {
            start: Point::new(0.0, 0.0),
            time_limit: web_time::Duration::from_secs(600),
            restarts: 0,
            max_non_improving_shakes: 0,
            ..cutroute_ccp::CcpOptions::default()
        };
        let result = cutroute_ccp::solve(&nest, options, &mut |_| {}).expect("solves");
        let seconds = result
            .progress
            .local_optimum_time
            .map_or(f64::NAN, |t| t.as_secs_f64());
        log(format!(
            "BENCH ccp:{contours} {seconds:.3} {:.1} -",
            result.metrics.idle_length
        ));
    }
}
