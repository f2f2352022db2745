//! The independent tour checker and the precedence order preprocessing.

mod common;

use common::reference;
use cutroute_pcgtsp::{check_tour, Instance, PrecedenceOrder, TourError};

fn tiny() -> Instance {
    // Clusters: {0} depot, {1, 2}, {3}, {4}; 1 before 2 (clusters), arc 3 -> 4 forbidden.
    Instance::parse(
        "NAME : t\nTYPE : PCGLNS\nDIMENSION : 5\nGTSP_SETS : 4\nEDGE_WEIGHT_TYPE : EXPLICIT\n\
         EDGE_WEIGHT_FORMAT : FULL_MATRIX\nEDGE_WEIGHT_SECTION\n\
         0 1 2 3 4\n1 0 1 1 1\n2 1 0 1 1\n3 1 1 0 -1\n4 1 1 1 0\n\
         GTSP_SET_SECTION\n1 1 -1\n2 2 3 -1\n3 4 -1\n4 5 -1\nGTSP_SET_ORDERING\n2 3 -1\n\
         START_GROUP_SECTION\n1\nEOF\n",
    )
    .unwrap()
}

#[test]
fn checker_accepts_feasible_tours_and_recomputes_cost() {
    let instance = tiny();
    assert_eq!(
        check_tour(&instance, &[0, 1, 4, 3]),
        Ok(1.0 + 1.0 + 1.0 + 3.0)
    );
    assert_eq!(
        check_tour(&instance, &[0, 4, 2, 3]),
        Ok(4.0 + 1.0 + 1.0 + 3.0)
    );
}

#[test]
fn checker_rejects_every_kind_of_infeasibility() {
    let instance = tiny();
    assert_eq!(
        check_tour(&instance, &[0, 1, 3]),
        Err(TourError::WrongLength {
            found: 3,
            expected: 4
        })
    );
    assert_eq!(
        check_tour(&instance, &[0, 1, 3, 9]),
        Err(TourError::NodeOutOfRange {
            position: 3,
            node: 9
        })
    );
    assert_eq!(
        check_tour(&instance, &[1, 0, 3, 4]),
        Err(TourError::NotStartingAtDepot {
            node: 1,
            cluster: 1,
            depot: 0
        })
    );
    assert_eq!(
        check_tour(&instance, &[0, 1, 2, 4]),
        Err(TourError::ClusterVisitedTwice {
            cluster: 1,
            first: 1,
            second: 2
        })
    );
    assert_eq!(
        check_tour(&instance, &[0, 3, 1, 4]),
        Err(TourError::PrecedenceViolated {
            before: 1,
            after: 2
        })
    );
    // The forbidden arc 3 -> 4 (0-based), a forbidden closing arc, a forbidden inner arc.
    assert_eq!(
        check_tour(&instance, &[0, 1, 3, 4]),
        Err(TourError::ForbiddenArc { from: 3, to: 4 })
    );
    let mut closing = tiny();
    closing.cost[3 * 5] = f64::INFINITY;
    assert_eq!(
        check_tour(&closing, &[0, 1, 4, 3]),
        Err(TourError::ForbiddenArc { from: 3, to: 0 })
    );
    let mut inner = tiny();
    inner.cost[5 + 4] = f64::INFINITY;
    assert_eq!(
        check_tour(&inner, &[0, 1, 4, 3]),
        Err(TourError::ForbiddenArc { from: 1, to: 4 })
    );
}

#[test]
fn closure_and_reduction() {
    let instance = tiny();
    let order = PrecedenceOrder::new(&instance).unwrap();
    // Depot precedes all; 1 precedes 2.
    assert!(order.precedes(0, 1) && order.precedes(0, 2) && order.precedes(0, 3));
    assert!(order.precedes(1, 2) && !order.precedes(2, 1) && !order.precedes(1, 3));
    // Reduction: depot -> 2 is implied through 1.
    assert!(order.cover_predecessors[2].contains(1));
    assert!(!order.cover_predecessors[2].contains(0));
    assert!(order.cover_predecessors[3].contains(0));
    assert_eq!(order.topological[0], 0);
    // Ideals containing the depot: {0}, +1, +3, +1+2, +1+3, +1+2+3 with 3 free → 2 * 3 = 6.
    assert_eq!(order.count_ideals(100), Some(6));
    assert_eq!(order.count_ideals(5), None);
}

#[test]
fn closure_of_a_real_instance_matches_the_file() {
    // The file's ordering lists are already transitively closed: closure adds only depot pairs.
    let instance = reference("ESC07").load();
    let order = PrecedenceOrder::new(&instance).unwrap();
    let m = instance.clusters.len();
    let closure_pairs: usize = (0..m).map(|b| order.predecessors[b].len()).sum();
    assert_eq!(closure_pairs, instance.precedence.len() + (m - 1));
    for &(a, b) in &instance.precedence {
        assert!(order.precedes(a, b));
    }
}

#[test]
fn reader_regressions_never_panic() {
    // Inputs in the spirit of what the fuzzer explores (no crash was found in 2.85 M runs).
    let nasty = [
        "DIMENSION : 10000\nGTSP_SETS : 1\nEDGE_WEIGHT_SECTION\n",
        "DIMENSION : 2\nGTSP_SETS : 1\nEDGE_WEIGHT_SECTION\n0 0 0 0\nGTSP_SET_SECTION\n1 1 2\n",
        "DIMENSION : 1\nGTSP_SETS : 1\nEDGE_WEIGHT_SECTION\n0\nGTSP_SET_SECTION\n1 1 -1\nGTSP_SET_ORDERING\n1 -1\n",
        "DIMENSION : 1\nGTSP_SETS : 1\nEDGE_WEIGHT_SECTION\n0\nGTSP_SET_SECTION\n1 1 -1\nSTART_GROUP_SECTION\n1 1\n",
        "DIMENSION : 1\nDIMENSION : 1\n",
        "EOF\n",
        "DIMENSION : 18446744073709551615\n",
        "DIMENSION : 1\nGTSP_SETS : 1\nEDGE_WEIGHT_SECTION\n1e308\nGTSP_SET_SECTION\n1 1 -1\n",
    ];
    for text in nasty {
        let _ = Instance::parse(text);
    }
    let one = Instance::parse(
        "DIMENSION : 1\nGTSP_SETS : 1\nEDGE_WEIGHT_SECTION\n0\nGTSP_SET_SECTION\n1 1 -1\n",
    )
    .unwrap();
    assert_eq!(check_tour(&one, &[0]), Ok(0.0));
}
