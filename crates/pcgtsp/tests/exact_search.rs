//! The exact search against brute force on random small instances, and the resumable bound
//! build on a large order.

mod common;

use common::{brute_force, references};
use cutroute_pcgtsp::{
    check_tour, root_bounds, solve, ExactOptions, ExactSolver, Instance, Status,
};
use std::time::Duration;

/// The instances of these tests: costs 5–64, a quarter of the pairs ordered.
fn random_instance(seed: u64, m: usize) -> Instance {
    common::random_instance(
        seed,
        m,
        common::RandomShape {
            salt: 17,
            cost_base: 5,
            cost_range: 60,
            pair_odds: 4,
        },
    )
}

#[test]
fn proven_optimum_equals_brute_force_on_random_instances() {
    let mut feasible = 0;
    for seed in 0..120u64 {
        let m = 3 + (seed % 6) as usize;
        let instance = random_instance(seed, m);
        let expected = brute_force(&instance).map(|(cost, _)| cost);
        for heuristic in [true, false] {
            let options = ExactOptions {
                heuristic,
                time_limit: Some(Duration::from_secs(30)),
                ..ExactOptions::default()
            };
            let result = solve(&instance, options, &mut |p| {
                if let Some(opt) = expected {
                    assert!(
                        p.lower_bound <= opt + 1e-9,
                        "seed {seed}: LB above the optimum"
                    );
                }
            })
            .expect("valid instance");
            let p = &result.progress;
            match expected {
                Some(opt) => {
                    assert!(result.proven_optimal(), "seed {seed}: not proven");
                    assert_eq!(p.upper_bound, opt, "seed {seed} (heuristic {heuristic})");
                    let tour = p.best_tour.as_ref().expect("a tour");
                    assert_eq!(check_tour(&instance, tour).expect("feasible"), opt);
                }
                None => assert!(p.best_tour.is_none(), "seed {seed}: tour for infeasible"),
            }
        }
        feasible += usize::from(expected.is_some());
    }
    assert!(
        feasible > 80,
        "only {feasible} random instances were feasible"
    );
}

#[test]
fn bounds_are_built_in_slices_and_the_build_can_be_cancelled() {
    let reference = references()
        .into_iter()
        .find(|r| r.instance == "e1x_4")
        .expect("e1x_4 in reference.csv");
    let instance = reference.load();
    let options = ExactOptions {
        heuristic: false,
        ..ExactOptions::default()
    };
    // With 1 ms slices the build (about a second of work) must span many steps.
    let mut solver = ExactSolver::new(&instance, options.clone()).unwrap();
    assert!(solver.offer_incumbent(&reference.pcglns_tour, reference.pcglns_cost));
    let mut steps = 0;
    while solver.step(Duration::from_millis(1)) == Status::Running {
        steps += 1;
        assert!(solver.progress().lower_bound <= 3258.0);
    }
    assert!(
        steps > 20,
        "only {steps} steps: the bounds were built in one block"
    );
    assert!(solver.progress().gap == 0.0);

    // Cancelled in the middle of the build: stops with a valid bound.
    let mut cancelled = ExactSolver::new(&instance, options).unwrap();
    for _ in 0..3 {
        assert_eq!(cancelled.step(Duration::from_millis(1)), Status::Running);
    }
    cancelled.cancel();
    assert_eq!(cancelled.step(Duration::from_secs(60)), Status::Stopped);
    assert!(cancelled.progress().lower_bound <= 3258.0);
}

#[test]
fn lagrangian_root_bounds_never_exceed_brute_force_optima() {
    let mut compared = 0;
    for seed in 0..200u64 {
        let m = 3 + (seed % 6) as usize;
        let instance = random_instance(seed + 1000, m);
        let Some((opt, _)) = brute_force(&instance) else {
            continue;
        };
        let b = root_bounds(&instance, 0).expect("valid instance");
        assert!(
            b.node_penalty <= opt + 1e-6,
            "seed {seed}: node-penalty bound {} > optimum {opt}",
            b.node_penalty
        );
        let arborescence = b.arborescence.expect("at least 3 clusters");
        assert!(
            arborescence <= opt + 1e-6,
            "seed {seed}: arborescence bound {arborescence} > optimum {opt}"
        );
        compared += 1;
    }
    assert!(compared > 120, "only {compared} feasible random instances");
}

#[test]
fn search_with_penalised_assignment_bounds_matches_brute_force() {
    // Without the lattice the DP bounds states by assignments on penalised costs and starts
    // from the arborescence bound: both must keep the optimum.
    let mut proven = 0;
    for seed in 0..80u64 {
        let m = 4 + (seed % 5) as usize;
        let instance = random_instance(seed + 5000, m);
        let expected = brute_force(&instance).map(|(cost, _)| cost);
        let options = ExactOptions {
            lattice_max_ideals: 0,
            heuristic: seed % 2 == 0,
            time_limit: Some(Duration::from_secs(30)),
            ..ExactOptions::default()
        };
        let result = solve(&instance, options, &mut |p| {
            if let Some(opt) = expected {
                assert!(
                    p.lower_bound <= opt + 1e-9,
                    "seed {seed}: LB above the optimum"
                );
            }
        })
        .expect("valid instance");
        if let Some(opt) = expected {
            assert!(result.proven_optimal(), "seed {seed}: not proven");
            assert!(result.root_bound <= opt + 1e-9, "seed {seed}: root bound");
            assert_eq!(result.progress.upper_bound, opt, "seed {seed}");
            proven += 1;
        }
    }
    assert!(proven > 50, "only {proven} feasible random instances");
}
