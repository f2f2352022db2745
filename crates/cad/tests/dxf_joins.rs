//! Pieces that share edges or branch: the joiner reads such a group as the faces of its plane
//! graph, each bounded face a contour, and says what bounds no face.

use cutroute_cad::dxf::{read_dxf, DxfImport, DxfOptions};
use cutroute_geometry::WarningKind;

fn drawing(entities: &str) -> String {
    format!("0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
}

fn line(a: (f64, f64), b: (f64, f64)) -> String {
    format!(
        "0\nLINE\n10\n{}\n20\n{}\n11\n{}\n21\n{}\n",
        a.0, a.1, b.0, b.1
    )
}

/// A line from its start to its end.
type Segment = ((f64, f64), (f64, f64));

fn lines(points: &[Segment]) -> String {
    points.iter().map(|&(a, b)| line(a, b)).collect()
}

fn read(text: &str) -> DxfImport {
    read_dxf(text.as_bytes(), &DxfOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// (perimeter, area) of every contour, sorted.
fn measures(import: &DxfImport) -> Vec<(f64, f64)> {
    let mut m: Vec<(f64, f64)> = import
        .nest
        .parts
        .iter()
        .flat_map(|p| &p.contours)
        .map(|c| (c.perimeter(), c.area()))
        .collect();
    m.sort_by(|a, b| a.0.total_cmp(&b.0));
    m
}

#[test]
fn three_squares_sharing_edges_are_three_parts() {
    // A 30 × 10 strip split by two inner lines: nodes of degree 3 at the splits.
    let text = drawing(&lines(&[
        ((0.0, 0.0), (30.0, 0.0)),
        ((30.0, 0.0), (30.0, 10.0)),
        ((30.0, 10.0), (0.0, 10.0)),
        ((0.0, 10.0), (0.0, 0.0)),
        ((10.0, 0.0), (10.0, 10.0)),
        ((20.0, 10.0), (20.0, 0.0)),
    ]));
    // The long sides are cut at the splits so that the ends meet there.
    let text = text.replace(
        &line((0.0, 0.0), (30.0, 0.0)),
        &lines(&[
            ((0.0, 0.0), (10.0, 0.0)),
            ((10.0, 0.0), (20.0, 0.0)),
            ((20.0, 0.0), (30.0, 0.0)),
        ]),
    );
    let text = text.replace(
        &line((30.0, 10.0), (0.0, 10.0)),
        &lines(&[
            ((30.0, 10.0), (20.0, 10.0)),
            ((20.0, 10.0), (10.0, 10.0)),
            ((10.0, 10.0), (0.0, 10.0)),
        ]),
    );
    let import = read(&text);
    assert_eq!(import.nest.parts.len(), 3);
    for (perimeter, area) in measures(&import) {
        assert!((perimeter - 40.0).abs() < 1e-9, "{perimeter}");
        assert!((area - 100.0).abs() < 1e-9, "{area}");
    }
    assert!(import.open_chains.is_empty());
}

#[test]
fn a_loop_with_a_tail_is_one_contour_and_the_tail_an_open_chain() {
    let text = drawing(&lines(&[
        ((0.0, 0.0), (10.0, 0.0)),
        ((10.0, 0.0), (10.0, 10.0)),
        ((10.0, 10.0), (0.0, 10.0)),
        ((0.0, 10.0), (0.0, 0.0)),
        ((10.0, 10.0), (25.0, 20.0)),
    ]));
    let import = read(&text);
    let m = measures(&import);
    assert_eq!(m.len(), 1);
    assert!((m[0].0 - 40.0).abs() < 1e-9);
    assert_eq!(import.open_chains.len(), 1);
    assert!((import.open_chains[0].length - 325f64.sqrt()).abs() < 1e-9);
    assert!(import
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::OpenChain && w.left_out.len() == 1));
}

#[test]
fn a_bridge_between_two_squares_bounds_no_face() {
    let square = |x: f64| {
        lines(&[
            ((x, 0.0), (x + 10.0, 0.0)),
            ((x + 10.0, 0.0), (x + 10.0, 10.0)),
            ((x + 10.0, 10.0), (x, 10.0)),
            ((x, 10.0), (x, 0.0)),
        ])
    };
    let text = drawing(&format!(
        "{}{}{}",
        square(0.0),
        square(20.0),
        line((10.0, 0.0), (20.0, 0.0))
    ));
    let import = read(&text);
    let m = measures(&import);
    assert_eq!(m.len(), 2, "{m:?}");
    assert!(m
        .iter()
        .all(|&(p, a)| (p - 40.0).abs() < 1e-9 && (a - 100.0).abs() < 1e-9));
    assert_eq!(import.open_chains.len(), 1);
    assert!((import.open_chains[0].length - 10.0).abs() < 1e-9);
}

#[test]
fn an_edge_drawn_again_within_the_tolerance_is_a_duplicate_not_a_sliver() {
    // A triangle whose top edge is drawn a second time 0.03 mm lower, ending 0.03 mm from the
    // corners: the same two nodes, a sliver narrower than the 0.05 mm join tolerance.
    let text = drawing(&lines(&[
        ((0.0, 10.0), (10.0, 10.0)),
        ((10.0, 10.0), (5.0, 0.0)),
        ((5.0, 0.0), (0.0, 10.0)),
        ((0.0, 9.97), (10.0, 9.97)),
    ]));
    let import = read(&text);
    let m = measures(&import);
    assert_eq!(m.len(), 1);
    assert!(
        (m[0].0 - (10.0 + 2.0 * 125f64.sqrt())).abs() < 1e-9,
        "{m:?}"
    );
    assert!(import
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::Duplicate));
}

#[test]
fn a_group_with_a_t_junction_inside_a_piece_stays_open_and_says_so() {
    // A square with a cross bar ending on the middle of the right side (not at an end): the
    // plane graph needs that side split, which the joiner does not do; nothing is made up.
    let text = drawing(&lines(&[
        ((0.0, 0.0), (10.0, 0.0)),
        ((10.0, 0.0), (10.0, 10.0)),
        ((10.0, 10.0), (0.0, 10.0)),
        ((0.0, 10.0), (0.0, 5.0)),
        ((0.0, 5.0), (0.0, 0.0)),
        ((0.0, 5.0), (10.0, 5.0)),
        ((20.0, 0.0), (30.0, 0.0)),
        ((30.0, 0.0), (30.0, 10.0)),
        ((30.0, 10.0), (20.0, 0.0)),
    ]));
    let import = read(&text);
    assert_eq!(measures(&import).len(), 1, "only the separate triangle");
    let left: f64 = import.open_chains.iter().map(|c| c.length).sum();
    assert!((left - 50.0).abs() < 1e-9, "{left}");
}
