//! The position-indexed completion bound (`completion.rs`): never above an optimum or a known
//! tour's cost, at the root and at every DP state along a tour; the search that uses it proves
//! the brute-force optimum; and it proves rbg048a / rbg050c, which the precedence-free bounds
//! leave at 272 / 372.

mod common;

use common::{brute_force, references, trusted_optimum};
use cutroute_pcgtsp::{position_bounds, solve, ExactOptions, ExactSolver, Instance, Status};
use std::time::Duration;

/// The instances of these tests: costs 0–39, each pair ordered with odds `1 / pair_odds`.
fn random_instance(seed: u64, m: usize, pair_odds: u64) -> Instance {
    common::random_instance(
        seed,
        m,
        common::RandomShape {
            salt: 23,
            cost_base: 0,
            cost_range: 40,
            pair_odds,
        },
    )
}

#[test]
fn position_bound_never_exceeds_brute_force_optima_at_the_root_or_along_the_optimal_tour() {
    let mut compared = 0;
    let mut above_plain_start = 0;
    for seed in 0..300u64 {
        let m = 3 + (seed % 6) as usize;
        let instance = random_instance(seed, m, 2 + seed % 4);
        let Some((opt, tour)) = brute_force(&instance) else {
            continue;
        };
        // Penalties optimised towards the optimum, towards nothing, and not at all (μ = 0):
        // the bound is valid for every μ.
        for (target, iterations) in [(opt, 200), (f64::INFINITY, 200), (opt, 0)] {
            let b = position_bounds(&instance, Some(&tour), target, iterations).unwrap();
            assert!(
                b.root <= opt + 1e-6,
                "seed {seed}: root {} > optimum {opt}",
                b.root
            );
            assert_eq!(b.along_tour.len(), m.saturating_sub(2), "seed {seed}");
            for (k, &state) in b.along_tour.iter().enumerate() {
                assert!(
                    state <= opt + 1e-6,
                    "seed {seed}: state bound {state} > optimum {opt} after {} clusters",
                    k + 2
                );
            }
        }
        // The bound at the last state before closing is the exact completion (one cluster
        // left), so it must reach the optimum there.
        let b = position_bounds(&instance, Some(&tour), opt, 0).unwrap();
        if let Some(&last) = b.along_tour.last() {
            assert!((last - opt).abs() < 1e-6, "seed {seed}: {last} vs {opt}");
            above_plain_start += 1;
        }
        compared += 1;
    }
    assert!(compared > 150, "only {compared} feasible random instances");
    assert!(above_plain_start > 100);
}

#[test]
fn position_bound_never_exceeds_known_optima_or_pcglns_tours() {
    let refs = references();
    assert_eq!(refs.len(), 59, "reference.csv rows");
    for r in &refs {
        let instance = r.load();
        // Larger instances get fewer subgradient steps (the test checks validity, not strength;
        // a pass costs about m·n² steps).
        let pass = (instance.clusters.len() * instance.node_count * instance.node_count) as f64;
        let iterations = if pass > 5e6 { 3 } else { 30 };
        let b = position_bounds(&instance, Some(&r.pcglns_tour), r.pcglns_cost, iterations)
            .unwrap_or_else(|e| panic!("{}: {e}", r.instance));
        let limit = trusted_optimum(r).unwrap_or(r.pcglns_cost);
        assert!(
            b.root <= limit + 1e-6,
            "{}: root {} > {limit}",
            r.instance,
            b.root
        );
        assert_eq!(b.along_tour.len(), r.clusters - 2, "{}", r.instance);
        for (k, &state) in b.along_tour.iter().enumerate() {
            assert!(
                state <= r.pcglns_cost + 1e-6,
                "{}: state bound {state} > tour cost {} after {} clusters",
                r.instance,
                r.pcglns_cost,
                k + 2
            );
        }
    }
}

#[test]
fn search_with_the_position_bound_matches_brute_force() {
    // Without the lattice the DP uses the position bound (and, when its root is the stronger
    // one, only it): the search must still prove the brute-force optimum.
    let mut proven = 0;
    for seed in 0..120u64 {
        let m = 4 + (seed % 5) as usize;
        let instance = random_instance(seed + 7000, m, 2 + seed % 4);
        let expected = brute_force(&instance).map(|(cost, _)| cost);
        let options = ExactOptions {
            lattice_max_ideals: 0,
            heuristic: seed % 2 == 0,
            penalty_iterations: if seed % 3 == 0 { 0 } else { 400 },
            time_limit: Some(Duration::from_secs(30)),
            ..ExactOptions::default()
        };
        let result = solve(&instance, options, &mut |p| {
            if let Some(opt) = expected {
                assert!(
                    p.lower_bound <= opt + 1e-9,
                    "seed {seed}: LB {} above the optimum {opt}",
                    p.lower_bound
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
    assert!(proven > 70, "only {proven} feasible random instances");
}

#[test]
fn position_bound_proves_rbg048a_at_the_root() {
    // Every precedence-free bound stops at 272; the optimum is 282.
    let r = references()
        .into_iter()
        .find(|r| r.instance == "rbg048a")
        .expect("rbg048a in reference.csv");
    let instance = r.load();
    let b = position_bounds(&instance, None, 282.0, 3000).unwrap();
    assert!(
        b.root > 281.0 && b.root <= 282.0 + 1e-6,
        "rbg048a root {} (optimum 282)",
        b.root
    );
}

#[test]
fn exact_solver_proves_rbg050c_from_the_published_tour() {
    // The precedence-free bounds stop at 372; with the published (optimal) tour as incumbent
    // the DP with the position bound closes the gap. No heuristic: the test is the proof.
    let r = references()
        .into_iter()
        .find(|r| r.instance == "rbg050c")
        .expect("rbg050c in reference.csv");
    let instance = r.load();
    let options = ExactOptions {
        heuristic: false,
        // A wall-clock backstop only (the machine may be loaded); the budgets are sized for 60 s.
        time_limit: Some(Duration::from_secs(600)),
        budget_seconds: Some(60.0),
        ..ExactOptions::default()
    };
    let mut solver = ExactSolver::new(&instance, options).unwrap();
    assert!(solver.offer_incumbent(&r.pcglns_tour, r.pcglns_cost));
    let mut status = Status::Running;
    while status == Status::Running {
        status = solver.step(Duration::from_millis(100));
        let p = solver.progress();
        assert!(p.lower_bound <= 378.0, "LB {} > 378", p.lower_bound);
    }
    assert_eq!(
        status,
        Status::Finished {
            proven_optimal: true
        },
        "{:?}",
        solver.progress()
    );
    assert_eq!(solver.progress().upper_bound, 378.0);
}
