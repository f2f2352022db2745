//! The exact job on a discretised nest with the interval bound of the nest beside it. Its own
//! test binary: these runs are CPU-heavy, and beside the timed checks of `jobs.rs` (a bound
//! within a 1 s CCP run) they would compete for the same cores.

mod common;

use common::{check_route, data};
use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_protocol::{JobRequest, SolverKind, SolverParams};
use web_time::Duration;

/// The exact job with the interval bound of the nest beside it (`DiscreteJob::with_lower_bound`,
/// as `start_job` builds it for nests above 35 contours): never above the discrete optimum,
/// proven here by the exact solver alone on small random nests (5–7 contours, coarse steps),
/// with and without a finish point, for the refined continuous bound, the same with the
/// decomposition by spatial groups forced on (groups of one and two kept contours), and the
/// bound at the discretisation's candidates (with and without the ng-path bound).
#[test]
fn discrete_exact_job_bound_never_exceeds_the_discrete_optimum() {
    use cutroute_ccp::{pierce_candidates, CcpLowerBound, LowerBoundOptions};
    use cutroute_engine::{DiscreteJob, DiscreteMode};
    use cutroute_geometry::{generate_nest, Point};
    for seed in 1..=6u64 {
        let nest = generate_nest(5 + (seed as usize % 3), seed);
        let b = nest.bounding_box();
        let start = Point::new(b.min.x - 10.0, b.min.y - 5.0);
        let finish = (seed % 2 == 0).then(|| Point::new(b.max.x + 3.0, b.min.y));
        let step = (b.max.x - b.min.x).max(b.max.y - b.min.y) / 6.0;
        let discrete = cutroute_ccp::build_pcgtsp(
            &nest,
            &cutroute_ccp::DiscretisationOptions {
                start,
                finish,
                step,
                ..Default::default()
            },
        )
        .unwrap();
        let alone = cutroute_pcgtsp::solve(
            &discrete.instance,
            cutroute_pcgtsp::ExactOptions {
                time_limit: None,
                ..Default::default()
            },
            &mut |_| {},
        )
        .unwrap();
        assert!(alone.proven_optimal(), "seed {seed}: not proven");
        let optimum = alone.progress.upper_bound;
        let candidates: Vec<_> = pierce_candidates(&discrete.nodes);
        // (at the candidates, group size, ng-path bound forced on the whole relaxation)
        for (at_candidates, group_size, ng) in [
            (false, 0, false),
            (false, 1, false),
            (false, 2, false),
            (true, 0, false),
            (true, 0, true),
            (false, 0, true),
            (false, 2, true),
        ] {
            let options = LowerBoundOptions {
                start,
                finish,
                budget_seconds: 1.0,
                group_size,
                decompose_above: 0,
                ng_above: if ng { 0 } else { usize::MAX },
                ..Default::default()
            };
            let bound = if at_candidates {
                CcpLowerBound::for_candidates(&nest, options, &candidates)
                    .unwrap()
                    .expect("candidates on every kept contour")
            } else {
                CcpLowerBound::new(&nest, options).unwrap()
            };
            let mut job = DiscreteJob::new(
                3,
                discrete.instance.clone(),
                Some(discrete.clone()),
                DiscreteMode::Exact,
                Duration::from_secs(2),
                web_time::Instant::now(),
                seed,
            )
            .unwrap()
            .with_lower_bound(bound);
            let result = run_to_end(&mut job, &mut |_| {});
            let lb = result.bounds.lower.expect("a lower bound");
            assert!(
                lb <= optimum * (1.0 + 1e-9) + 1e-9,
                "seed {seed} ({at_candidates}, groups of {group_size}, ng {ng}): job bound {lb} above the discrete optimum {optimum}"
            );
            let ub = result.bounds.upper.expect("a tour");
            assert!(ub >= optimum - 1e-6 * optimum.max(1.0), "seed {seed}");
            // A bound offered above the optimum would end the search with a worse tour "proven".
            if result.proven_optimal {
                assert!(
                    (ub - optimum).abs() <= 1e-6 * optimum.max(1.0),
                    "seed {seed}: proven {ub} vs optimum {optimum}"
                );
            }
        }
    }
}

/// On nested.dbs (87 contours, 70 innermost: the bound runs the ng-path bound at the
/// discretisation's candidates) the job's bound stays below its own route.
#[test]
fn discrete_exact_job_on_nested_reports_a_bound_below_its_route() {
    let (name, bytes) = data("nests/dbs/nested.dbs");
    let document = open_document(&name, &bytes).expect("opens");
    let request = JobRequest {
        job_id: 5,
        problem: document.problem.clone(),
        solver: SolverKind::Exact,
        params: SolverParams {
            time_limit_s: 4.0,
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
