//! The paper's Tables 1 and 2 on the graphs the digest reconstructs (digest §6.1, §6.2).

mod common;

use common::{read, row, FIG4_ANTIPRISM, FIG5A};
use cutroute_aoe::{aoe_chain, check_chain, AoeError, AoeOptions, SplitRule};

fn chain_edges(text: &str, start_1based: usize, rule: SplitRule) -> Vec<usize> {
    let embedding = read(text);
    let options = AoeOptions { split_rule: rule };
    let chain = aoe_chain(&embedding, start_1based - 1, &options)
        .unwrap_or_else(|e| panic!("start {start_1based}: {e}"));
    check_chain(&embedding, &chain.darts).unwrap_or_else(|e| panic!("start {start_1based}: {e}"));
    chain.edges()
}

#[test]
fn antiprism_ranks_and_no_cut_points() {
    let embedding = read(FIG4_ANTIPRISM);
    assert!(embedding.cut_points().is_empty());
    assert_eq!(embedding.outer_vertices(), vec![0, 1, 2, 3]);
    let ranks: Vec<u32> = (0..16).map(|e| embedding.edge_rank(e)).collect();
    assert_eq!(ranks, [1, 2, 2, 1, 2, 2, 1, 2, 2, 1, 2, 2, 3, 3, 3, 3]);
}

#[test]
fn table_1_fig_4() {
    // Row 1 without the duplicated "7" (digest §6.1); rows 2–4 verbatim.
    let table = [
        (
            1,
            "2 - 13 - 14 - 15 - 16 - 12 - 11 - 9 - 8 - 6 - 5 - 3 - 4 - 7 - 10 - 1",
        ),
        (
            2,
            "11 - 16 - 13 - 14 - 15 - 9 - 8 - 6 - 5 - 3 - 2 - 12 - 1 - 4 - 7 - 10",
        ),
        (
            3,
            "8 - 15 - 16 - 13 - 14 - 6 - 5 - 3 - 2 - 12 - 11 - 9 - 10 - 1 - 4 - 7",
        ),
        (
            4,
            "5 - 14 - 15 - 16 - 13 - 3 - 2 - 12 - 11 - 9 - 8 - 6 - 7 - 10 - 1 - 4",
        ),
    ];
    for rule in [SplitRule::Corrected, SplitRule::Paper] {
        for (start, expected) in table {
            assert_eq!(
                chain_edges(FIG4_ANTIPRISM, start, rule),
                row(expected),
                "start {start}"
            );
        }
    }
}

#[test]
fn fig_5a_has_one_ambiguous_cut_point() {
    let embedding = read(FIG5A);
    let cut_points = embedding.cut_points();
    assert_eq!(cut_points.len(), 1);
    assert_eq!((cut_points[0].vertex, cut_points[0].rank), (4, 2));
    // Its two rank-1 corners are different faces of G (the case the printed test misjudges).
    let graph = embedding.graph();
    let outer_corners: Vec<usize> = graph
        .darts_around(4)
        .map(|d| embedding.faces().left(d))
        .filter(|&f| embedding.face_rank(f) == 1)
        .collect();
    assert_eq!(outer_corners.len(), 2);
    assert_ne!(outer_corners[0], outer_corners[1]);
}

#[test]
fn table_2_fig_5a_with_the_printed_split_rule() {
    let table = [
        (1, "2 - 4 - 3 - 9 - 8 - 5 - 7 - 10 - 6 - 1"),
        (2, "2 - 3 - 4 - 6 - 5 - 8 - 7 - 10 - 9 - 1"),
        (3, "5 - 8 - 7 - 10 - 9 - 3 - 4 - 2 - 1 - 6"),
        (4, "7 - 5 - 8 - 9 - 3 - 4 - 2 - 1 - 6 - 10"),
    ];
    for (start, expected) in table {
        assert_eq!(
            chain_edges(FIG5A, start, SplitRule::Paper),
            row(expected),
            "start {start}"
        );
    }
}

#[test]
fn fig_5a_with_the_corrected_split_rule() {
    // The digest's chains for the corrected rule (§6.2), different from Table 2 but also valid.
    let expected = [
        (1, "2-4-5-7-8-3-9-10-6-1"),
        (2, "2-3-8-7-5-4-6-10-9-1"),
        (3, "5-4-2-3-8-7-10-9-1-6"),
        (4, "7-5-4-2-3-8-9-1-6-10"),
    ];
    for (start, chain) in expected {
        assert_eq!(
            chain_edges(FIG5A, start, SplitRule::Corrected),
            row(chain),
            "start {start}"
        );
    }
}

#[test]
fn the_paper_table_rows_pass_the_checker_as_given() {
    // The checker must accept the printed chains as they are; it needs the orientation of
    // every edge, which follows from the start vertex and the trail.
    let embedding = read(FIG5A);
    let graph = embedding.graph();
    let darts = |start: usize, edges: &[usize]| {
        let mut at = start;
        edges
            .iter()
            .map(|&e| {
                let dart = if graph.ends(e).0 == at {
                    2 * e
                } else {
                    2 * e + 1
                };
                at = graph.head(dart);
                dart
            })
            .collect::<Vec<_>>()
    };
    let good = darts(0, &row("2 - 4 - 3 - 9 - 8 - 5 - 7 - 10 - 6 - 1"));
    check_chain(&embedding, &good).expect("the paper's row 1 is an AOE-chain");
}

#[test]
fn start_vertex_off_the_outer_face_is_an_error() {
    let embedding = read(FIG4_ANTIPRISM);
    for start in 4..8 {
        assert_eq!(
            aoe_chain(&embedding, start, &AoeOptions::default()),
            Err(AoeError::StartNotOnOuterFace { vertex: start })
        );
    }
    assert!(matches!(
        aoe_chain(&embedding, 8, &AoeOptions::default()),
        Err(AoeError::NoSuchVertex {
            vertex: 8,
            vertex_count: 8
        })
    ));
}
