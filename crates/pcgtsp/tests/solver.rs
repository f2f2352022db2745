//! Bounds soundness and exact optimality on the real instances; the anytime API.

mod common;

use common::{reference, references, trusted_optimum, Reference};
use cutroute_pcgtsp::{
    check_tour, root_bounds, solve, ExactOptions, ExactProgress, ExactSolver, Instance, Status,
};
use std::time::Duration;

/// Asserts everything a progress report claims: a feasible tour of the reported cost, and a
/// lower bound not above the known optimum.
fn check_progress(instance: &Instance, r: &Reference, p: &ExactProgress) {
    if let Some(tour) = &p.best_tour {
        let cost = check_tour(instance, tour)
            .unwrap_or_else(|e| panic!("{}: infeasible tour: {e}", r.instance));
        assert_eq!(cost, p.upper_bound, "{}: reported cost", r.instance);
    }
    assert!(
        p.lower_bound <= p.upper_bound,
        "{}: LB {} > UB {}",
        r.instance,
        p.lower_bound,
        p.upper_bound
    );
    if let Some(opt) = trusted_optimum(r) {
        assert!(
            p.lower_bound <= opt,
            "{}: LB {} above the optimum {opt}",
            r.instance,
            p.lower_bound
        );
        assert!(
            p.upper_bound >= opt,
            "{}: tour {} below the optimum {opt}",
            r.instance,
            p.upper_bound
        );
    }
}

#[test]
fn root_bounds_never_exceed_known_optima() {
    let mut checked = 0;
    for r in references().iter().filter(|r| r.known_optimum.is_some()) {
        let instance = r.load();
        let opt = trusted_optimum(r).unwrap();
        // The cluster DP only where the lattice is small enough for a quick test.
        let b = root_bounds(&instance, 200_000).unwrap();
        assert!(b.l1 <= opt, "{}: L1 {} > {opt}", r.instance, b.l1);
        assert!(b.l2 <= opt, "{}: L2 {} > {opt}", r.instance, b.l2);
        if let Some(dp) = b.cluster_dp {
            assert!(dp <= opt, "{}: cluster DP {dp} > {opt}", r.instance);
        }
        assert!(
            b.node_penalty <= opt,
            "{}: node-penalty bound {} > {opt}",
            r.instance,
            b.node_penalty
        );
        let arborescence = b.arborescence.expect("every instance has ≥ 3 clusters");
        assert!(
            arborescence <= opt,
            "{}: arborescence bound {arborescence} > {opt}",
            r.instance
        );
        assert!(
            b.best() > 0.0 || opt == 0.0 || r.instance.starts_with("br17"),
            "{}: trivial bound",
            r.instance
        );
        checked += 1;
    }
    assert_eq!(checked, 33, "instances with a known optimum");
}

#[test]
fn every_reported_bound_is_sound_on_instances_with_known_optima() {
    // A short run on each: all progress reports are checked, including the final one.
    for r in references().iter().filter(|r| r.known_optimum.is_some()) {
        let instance = r.load();
        let options = ExactOptions {
            time_limit: Some(Duration::from_millis(300)),
            lattice_max_ideals: 100_000,
            beam_widths: vec![16],
            ..ExactOptions::default()
        };
        let result = solve(&instance, options, &mut |p| check_progress(&instance, r, p)).unwrap();
        check_progress(&instance, r, &result.progress);
        assert!(
            result.root_bound <= trusted_optimum(r).unwrap(),
            "{}: root bound",
            r.instance
        );
        if result.proven_optimal() {
            assert_eq!(
                result.progress.upper_bound,
                trusted_optimum(r).unwrap(),
                "{}",
                r.instance
            );
        }
    }
}

fn prove(name: &str, options: ExactOptions) {
    let r = reference(name);
    let instance = r.load();
    let mut reports = 0;
    let result = solve(&instance, options, &mut |p| {
        reports += 1;
        check_progress(&instance, &r, p);
    })
    .unwrap();
    assert!(reports > 0);
    assert!(
        result.proven_optimal(),
        "{name}: not proven: {:?}",
        result.progress
    );
    assert_eq!(
        result.progress.upper_bound,
        r.known_optimum.unwrap(),
        "{name}"
    );
    assert_eq!(
        result.progress.lower_bound,
        r.known_optimum.unwrap(),
        "{name}"
    );
    assert_eq!(result.progress.gap, 0.0);
    let tour = result.progress.best_tour.as_ref().expect("tour");
    assert_eq!(
        check_tour(&instance, tour).unwrap(),
        r.known_optimum.unwrap()
    );
}

#[test]
fn exact_optimum_on_quick_industrial_instances() {
    for name in ["e1x_6", "e1x_10", "e1x_12"] {
        prove(
            name,
            ExactOptions {
                time_limit: Some(Duration::from_secs(30)),
                ..ExactOptions::default()
            },
        );
    }
}

#[test]
fn exact_optimum_on_small_library_instances() {
    for name in ["ESC07", "ESC12", "br17.12"] {
        prove(
            name,
            ExactOptions {
                time_limit: Some(Duration::from_secs(30)),
                ..ExactOptions::default()
            },
        );
    }
}

#[test]
fn exact_optimum_with_assignment_bounds_only_and_no_heuristic() {
    // The path without the lattice bound and without an initial incumbent.
    let options = ExactOptions {
        time_limit: Some(Duration::from_secs(30)),
        heuristic: false,
        lattice_max_ideals: 0,
        ..ExactOptions::default()
    };
    prove("ESC07", options.clone());
    prove("e1x_6", options);
}

#[test]
fn anytime_api_steps_accepts_incumbents_and_cancels() {
    let r = reference("e1x_6");
    let instance = r.load();
    let mut solver = ExactSolver::new(
        &instance,
        ExactOptions {
            heuristic: false,
            ..ExactOptions::default()
        },
    )
    .unwrap();
    assert_eq!(solver.progress().upper_bound, f64::INFINITY);
    // A bad tour is refused, the PCGLNS tour accepted.
    assert!(!solver.offer_incumbent(&[0, 1, 2], 1.0));
    assert!(solver.offer_incumbent(&r.pcglns_tour, r.pcglns_cost));
    assert_eq!(solver.progress().upper_bound, r.pcglns_cost);
    let mut steps = 0;
    let status = loop {
        let status = solver.step(Duration::from_millis(5));
        steps += 1;
        check_progress(&instance, &r, &solver.progress());
        if status != Status::Running {
            break status;
        }
    };
    assert!(steps > 1, "work must be split over several steps");
    assert_eq!(
        status,
        Status::Finished {
            proven_optimal: true
        }
    );
    assert_eq!(solver.progress().upper_bound, 1513.0);
    // Finished stays finished.
    assert_eq!(solver.step(Duration::from_millis(5)), status);

    let mut cancelled = ExactSolver::new(&instance, ExactOptions::default()).unwrap();
    cancelled.cancel();
    assert_eq!(cancelled.step(Duration::from_secs(1)), Status::Stopped);
    check_progress(&instance, &r, &cancelled.progress());
}

#[test]
fn memory_cap_degrades_gracefully_with_a_valid_bound() {
    let r = reference("e1x_13");
    let instance = r.load();
    let options = ExactOptions {
        time_limit: Some(Duration::from_secs(20)),
        memory_limit_bytes: 1 << 20,
        lattice_max_ideals: 0,
        heuristic: false,
        ..ExactOptions::default()
    };
    let result = solve(&instance, options, &mut |p| {
        check_progress(&instance, &r, p)
    })
    .unwrap();
    check_progress(&instance, &r, &result.progress);
    assert!(
        result.progress.best_tour.is_some(),
        "the capped DP still finds a tour"
    );
    assert!(!result.proven_optimal() || result.progress.upper_bound == 2168.0);
}

#[test]
fn bfs_branch_and_bound_variant_proves_small_optima() {
    use cutroute_pcgtsp::{solve_bnb, BnbOptions};
    for name in ["ESC07", "e1x_6"] {
        let r = reference(name);
        let instance = r.load();
        let options = BnbOptions {
            initial_tour: Some(r.pcglns_tour.clone()),
            ..BnbOptions::default()
        };
        let result = solve_bnb(&instance, &options).unwrap();
        check_progress(&instance, &r, &result.progress);
        assert!(result.proven_optimal(), "{name}: {:?}", result.progress);
        assert_eq!(result.progress.upper_bound, r.known_optimum.unwrap());
    }
}

#[test]
fn p43_4_optimum_is_66848_not_the_published_bound_66846() {
    let r = reference("p43.4");
    let instance = r.load();
    let result = solve(&instance, ExactOptions::default(), &mut |p| {
        check_progress(&instance, &r, p)
    })
    .unwrap();
    assert!(result.proven_optimal());
    assert_eq!(result.progress.upper_bound, common::P43_4_OPTIMUM);
    // Consistent with the published lower bound.
    assert!(result.progress.lower_bound >= r.known_optimum.unwrap());
}

#[test]
fn lagrangian_bounds_lift_the_assignment_bound_on_ft70_2() {
    // ft70.2 (> 6 M ideals, no lattice): L1 = 30994; the node penalties and the arborescence
    // bound lift it to ~31460 and ~32070 (best published bound 31787, best tour 33374).
    let r = reference("ft70.2");
    let instance = r.load();
    let b = root_bounds(&instance, 0).unwrap();
    assert!(b.node_penalty >= b.l1 + 300.0, "node penalties: {b:?}");
    let arborescence = b.arborescence.expect("70 clusters");
    assert!(arborescence >= 31900.0, "arborescence: {b:?}");
    assert!(arborescence <= 33374.0, "above a known tour: {b:?}");
}

/// A deferred solver builds its runs in steps of their own: before they are built its root
/// bound is −∞ and every lower bound it reports stays below the optimum; after, it has the root
/// bound of `new` and proves the same optima.
#[test]
fn a_deferred_solver_builds_its_runs_in_steps_and_proves_what_new_proves() {
    for name in ["ESC12", "br17.12", "e1x_8"] {
        let r = reference(name);
        let instance = r.load();
        let options = ExactOptions {
            heuristic: false,
            ..ExactOptions::default()
        };
        let whole = ExactSolver::new(&instance, options.clone()).unwrap();
        let mut deferred = ExactSolver::deferred(&instance, options).unwrap();
        assert_eq!(deferred.root_bound(), f64::NEG_INFINITY, "{name}");
        let opt = trusted_optimum(&r).unwrap();
        let mut calls = 0;
        loop {
            let status = deferred.step(Duration::ZERO);
            calls += 1;
            let p = deferred.progress();
            assert!(p.lower_bound <= opt, "{name}: LB {} > {opt}", p.lower_bound);
            if deferred.root_bound() > f64::NEG_INFINITY {
                break;
            }
            assert_eq!(status, Status::Running, "{name}");
            assert!(calls < 100, "{name}: runs never built");
        }
        assert!(calls >= 2, "{name}: model and root bound in separate steps");
        assert_eq!(deferred.root_bound(), whole.root_bound(), "{name}");
        while deferred.step(Duration::from_millis(200)) == Status::Running {}
        let p = deferred.progress();
        check_progress(&instance, &r, &p);
        assert_eq!(p.upper_bound, opt, "{name}");
        assert_eq!(p.lower_bound, opt, "{name}: proven");
    }
}
