//! The checker rejects what it must: every failure kind on hand-made and mutated chains.

mod common;

use common::{read, FIG4_ANTIPRISM, FIG5A};
use cutroute_aoe::random::random_four_regular;
use cutroute_aoe::{
    aoe_chain, check_chain, check_route, AoeOptions, CheckError, Embedding, PlaneGraph,
};
use cutroute_geometry::SplitMix64;

/// Two vertices, four parallel edges drawn as nested lenses, edge 0 on top.
fn lenses() -> Embedding {
    let graph = PlaneGraph::from_rotations(
        2,
        &[(0, 1), (0, 1), (0, 1), (0, 1)],
        &[vec![6, 4, 2, 0], vec![1, 3, 5, 7]],
    )
    .unwrap();
    Embedding::with_outer_dart(graph, 0).unwrap()
}

#[test]
fn lenses_good_chain_and_a_crossing_one() {
    let e = lenses();
    // Inner lens first (edges 1, 2), then the outer one (3, 0): A and OE.
    check_chain(&e, &[2, 5, 6, 1]).unwrap();
    // Outer lens first encloses the inner edges (no crossing, but not an A-chain either).
    assert_eq!(
        check_route(&e, &[vec![0, 7, 2, 5]]),
        Err(CheckError::Encloses { prefix: 2, edge: 1 })
    );
    assert!(matches!(
        check_chain(&e, &[0, 7, 2, 5]),
        Err(CheckError::NotNeighbours { position: 2, .. })
    ));
    // Edge 0 then straight across to edge 2: not rotation neighbours, and a crossing.
    assert_eq!(
        check_chain(&e, &[0, 5, 2, 7]),
        Err(CheckError::NotNeighbours {
            position: 1,
            vertex: 1,
            from: 1,
            to: 5
        })
    );
    assert!(matches!(
        check_route(&e, &[vec![0, 5, 2, 7]]),
        Err(CheckError::Crossing { vertex: 1, .. })
    ));
}

#[test]
fn cover_errors() {
    let e = lenses();
    assert_eq!(
        check_chain(&e, &[2, 5, 6]),
        Err(CheckError::EdgeMissing { edge: 0 })
    );
    assert_eq!(
        check_chain(&e, &[2, 5, 2, 5]),
        Err(CheckError::EdgeRepeated {
            edge: 1,
            first: 0,
            second: 2
        })
    );
    assert_eq!(
        check_chain(&e, &[2, 6, 5, 1]),
        Err(CheckError::NotATrail {
            position: 1,
            dart: 6
        })
    );
    assert_eq!(
        check_chain(&e, &[2, 5, 9, 1]),
        Err(CheckError::NoSuchDart {
            position: 2,
            dart: 9
        })
    );
    assert_eq!(
        check_route(&e, &[vec![2, 5], vec![]]),
        Err(CheckError::EmptyChain { chain: 1 })
    );
    // An open route of two chains, inner lens first: valid; outer first: encloses.
    check_route(&e, &[vec![2, 5], vec![6, 1]]).unwrap();
    assert!(matches!(
        check_route(&e, &[vec![0, 7], vec![2, 5]]),
        Err(CheckError::Encloses { .. })
    ));
}

#[test]
fn not_closed_is_reported() {
    let e = read(FIG5A);
    // All ten edges once, as an open trail ending away from the start (two chains joined).
    let chain = aoe_chain(&e, 0, &AoeOptions::default()).unwrap();
    let mut open = chain.darts.clone();
    open.rotate_left(1);
    // A rotation of a closed trail is still closed; the failure must come from OE instead.
    assert!(check_chain(&e, &open).is_err());
    let graph = e.graph();
    let reversed: Vec<usize> = chain
        .darts
        .iter()
        .rev()
        .map(|&d| PlaneGraph::twin(d))
        .collect();
    assert_eq!(graph.origin(reversed[0]), graph.head(reversed[9]));
}

#[test]
fn rotating_a_chain_to_end_on_an_inner_edge_breaks_ordered_enclosing() {
    let mut rng = SplitMix64::new(99);
    let mut broken = 0;
    for _ in 0..300 {
        let e = random_four_regular(20, &mut rng).unwrap();
        let start = e.outer_vertices()[0];
        let chain = aoe_chain(&e, start, &AoeOptions::default()).unwrap();
        let n = chain.darts.len();
        for shift in 1..n {
            let mut rotated = chain.darts.clone();
            rotated.rotate_left(shift);
            let last = rotated[n - 1];
            if e.dart_rank(last) > 1 {
                assert!(
                    matches!(check_chain(&e, &rotated), Err(CheckError::Encloses { .. })),
                    "a chain ending on an edge of rank > 1 encloses it"
                );
                broken += 1;
            }
        }
    }
    assert!(broken > 1000);
}

#[test]
fn antiprism_table_row_with_the_duplicate_seven_is_rejected() {
    let e = read(FIG4_ANTIPRISM);
    let graph = e.graph();
    // The printed row 1 has 17 entries: it is not even a trail.
    let printed = [2, 13, 14, 15, 16, 12, 11, 9, 8, 7, 6, 5, 3, 4, 7, 10, 1];
    let mut at = 0;
    let mut darts = Vec::new();
    for &edge in &printed {
        let e0 = edge - 1;
        let dart = if graph.ends(e0).0 == at {
            2 * e0
        } else {
            2 * e0 + 1
        };
        at = graph.head(dart);
        darts.push(dart);
    }
    assert!(check_chain(&e, &darts).is_err());
}

#[test]
fn nested_lenses_and_figure_eight_get_aoe_chains() {
    let e = lenses();
    // Two ranks, both vertices on the outer face, both cut points of no rank (ranks 1,2,2,1).
    assert!(e.cut_points().is_empty());
    for start in 0..2 {
        let chain = aoe_chain(&e, start, &AoeOptions::default()).unwrap();
        check_chain(&e, &chain.darts).unwrap();
        // The inner lens (edges 1, 2) is cut before the outline closes.
        assert!([1, 2].contains(&(chain.darts[0] / 2)));
    }
    let figure_eight =
        PlaneGraph::from_rotations(1, &[(0, 0), (0, 0)], &[vec![0, 1, 2, 3]]).unwrap();
    let e = Embedding::with_outer_dart(figure_eight, 1).unwrap();
    let chain = aoe_chain(&e, 0, &AoeOptions::default()).unwrap();
    check_chain(&e, &chain.darts).unwrap();
    assert_eq!(chain.split_vertices, vec![0]);
}
