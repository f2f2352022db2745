//! Nest geometry to plane graph on hand-made plans whose graph is known.

mod common;

use common::{part, rect};
use cutroute_aoe::{aoe_chain, check_chain, AoeOptions, PlanGraph, PlanOptions};
use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};

fn nest(parts: Vec<Part>) -> Nest {
    Nest { sheet: None, parts }
}

fn keep_corners() -> PlanOptions {
    PlanOptions {
        dissolve_degree_two: false,
        ..PlanOptions::default()
    }
}

fn degrees(plan: &PlanGraph) -> Vec<usize> {
    let g = plan.graph();
    let mut d: Vec<usize> = (0..g.vertex_count()).map(|v| g.degree(v)).collect();
    d.sort_unstable();
    d
}

#[test]
fn row_of_touching_rectangles() {
    for n in 1..=6 {
        let parts = (0..n)
            .map(|i| part(vec![rect(10.0 * i as f64, 0.0, 10.0 * (i + 1) as f64, 5.0)]))
            .collect();
        let nest = nest(parts);
        let plan = PlanGraph::from_nest(&nest, &keep_corners()).unwrap();
        let g = plan.graph();
        assert_eq!(
            (g.vertex_count(), g.edge_count()),
            (2 * (n + 1), 3 * n + 1),
            "n = {n}"
        );
        let e = plan.embedding().unwrap();
        assert_eq!(e.faces().count(), n + 1);
        let common = (0..g.edge_count())
            .filter(|&x| plan.edge_contours(x).len() == 2)
            .count();
        assert_eq!(common, n - 1);
        // T-junctions have degree 3, the four row corners degree 2.
        let mut expected = vec![2; 4];
        expected.extend(vec![3; 2 * (n - 1)]);
        assert_eq!(degrees(&plan), expected);
        // The outline has rank 1, the common edges between two cells rank 2.
        for x in 0..g.edge_count() {
            assert_eq!(e.edge_rank(x) as usize, plan.edge_contours(x).len());
        }
        if n >= 2 {
            let dissolved = PlanGraph::from_nest(&nest, &PlanOptions::default()).unwrap();
            let g = dissolved.graph();
            assert_eq!(
                (g.vertex_count(), g.edge_count()),
                (2 * (n - 1), 3 * (n - 1))
            );
            let length: f64 = (0..g.edge_count())
                .flat_map(|x| dissolved.edge_spans(x).iter().map(|s| s.length()))
                .sum();
            // Cut length: the outline plus the n − 1 common edges, each once.
            assert!((length - (2.0 * (10.0 * n as f64 + 5.0) + 5.0 * (n - 1) as f64)).abs() < 1e-9);
        }
    }
}

#[test]
fn grid_of_rectangles_sharing_edges() {
    for (n, m) in [(1, 1), (2, 3), (4, 4), (5, 2)] {
        let mut parts = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (x, y) = (20.0 * i as f64, 10.0 * j as f64);
                parts.push(part(vec![rect(x, y, x + 20.0, y + 10.0)]));
            }
        }
        let plan = PlanGraph::from_nest(&nest(parts), &keep_corners()).unwrap();
        let g = plan.graph();
        assert_eq!(g.vertex_count(), (n + 1) * (m + 1));
        assert_eq!(g.edge_count(), n * (m + 1) + m * (n + 1));
        let e = plan.embedding().unwrap();
        assert_eq!(e.faces().count(), n * m + 1);
        let inner = (n - 1) * m + (m - 1) * n;
        let common = (0..g.edge_count())
            .filter(|&x| plan.edge_contours(x).len() == 2)
            .count();
        assert_eq!(common, inner);
        // Interior grid points are crossings of degree 4, each face a rectangle of area 200.
        let fours = (0..g.vertex_count()).filter(|&v| g.degree(v) == 4).count();
        assert_eq!(fours, (n - 1) * (m - 1));
        let areas = plan.face_areas(e.faces());
        for (f, &a) in areas.iter().enumerate() {
            if f == e.outer_face() {
                assert!((a + 200.0 * (n * m) as f64).abs() < 1e-6);
            } else {
                assert!((a - 200.0).abs() < 1e-6, "face area {a}");
            }
        }
        // Ranks grow towards the middle: a cell's rank is 1 + its distance to the border, an
        // edge between two cells has rank 1 + the smaller one.
        let cell = |i: usize, j: usize| 1 + i.min(j).min(n - 1 - i).min(m - 1 - j);
        let mut expected = 1;
        for i in 0..n {
            for j in 0..m {
                if i + 1 < n {
                    expected = expected.max(1 + cell(i, j).min(cell(i + 1, j)));
                }
                if j + 1 < m {
                    expected = expected.max(1 + cell(i, j).min(cell(i, j + 1)));
                }
            }
        }
        let max_rank = (0..g.edge_count()).map(|x| e.edge_rank(x)).max().unwrap();
        assert_eq!(max_rank as usize, expected);
    }
}

#[test]
fn two_crossing_circles_make_a_four_regular_graph_with_an_aoe_chain() {
    let nest = nest(vec![
        part(vec![Contour::circle(Point::new(0.0, 0.0), 10.0, true)]),
        part(vec![Contour::circle(Point::new(12.0, 0.0), 10.0, true)]),
    ]);
    let plan = PlanGraph::from_nest(&nest, &PlanOptions::default()).unwrap();
    let g = plan.graph();
    assert_eq!((g.vertex_count(), g.edge_count()), (2, 4));
    for v in 0..2 {
        let p = plan.point(v);
        assert!((p.x - 6.0).abs() < 1e-9 && (p.y.abs() - 8.0).abs() < 1e-9);
    }
    let e = plan.embedding().unwrap();
    let mut ranks: Vec<u32> = (0..4).map(|x| e.edge_rank(x)).collect();
    ranks.sort_unstable();
    assert_eq!(ranks, [1, 1, 2, 2]);
    for start in 0..2 {
        let chain = aoe_chain(&e, start, &AoeOptions::default()).unwrap();
        check_chain(&e, &chain.darts).unwrap();
        // The lens (rank 2) is cut before the outline closes.
        assert_eq!(e.dart_rank(chain.darts[0]), 2);
    }
}

#[test]
fn two_crossing_rings_make_a_four_regular_graph_with_an_aoe_chain() {
    let ring = |x: f64| {
        part(vec![
            Contour::circle(Point::new(x, 0.0), 10.0, true),
            Contour::circle(Point::new(x, 0.0), 6.0, false),
        ])
    };
    let plan =
        PlanGraph::from_nest(&nest(vec![ring(0.0), ring(10.0)]), &PlanOptions::default()).unwrap();
    let g = plan.graph();
    assert_eq!((g.vertex_count(), g.edge_count()), (8, 16));
    assert!((0..8).all(|v| g.degree(v) == 4));
    let e = plan.embedding().unwrap();
    assert_eq!(e.faces().count(), 10);
    for start in e.outer_vertices() {
        let chain = aoe_chain(&e, start, &AoeOptions::default()).unwrap();
        check_chain(&e, &chain.darts).unwrap();
    }
}

#[test]
fn partly_overlapping_edges_are_merged_and_split() {
    // Two rectangles sharing the piece 5 ≤ x ≤ 10 of the line y = 5.
    let plan = PlanGraph::from_nest(
        &nest(vec![
            part(vec![rect(0.0, 0.0, 10.0, 5.0)]),
            part(vec![rect(5.0, 5.0, 15.0, 10.0)]),
        ]),
        &keep_corners(),
    )
    .unwrap();
    let g = plan.graph();
    // Corners 4 + 4, of which (5,5) and (10,5) are T-junctions on the other rectangle.
    assert_eq!(g.vertex_count(), 8);
    assert_eq!(g.edge_count(), 9);
    let common: Vec<usize> = (0..g.edge_count())
        .filter(|&x| plan.edge_contours(x).len() == 2)
        .collect();
    assert_eq!(common.len(), 1);
    let s = plan.edge_spans(common[0]);
    assert_eq!(s.len(), 1);
    assert!((s[0].length() - 5.0).abs() < 1e-9);
    assert_eq!(degrees(&plan), vec![2, 2, 2, 2, 2, 2, 3, 3]);
}

#[test]
fn co_circular_arcs_are_merged_and_a_part_in_a_hole_is_its_own_component() {
    // A ring (hole radius 5) and a disc of radius 5 filling the hole, its spans rotated by 90°.
    let hole = Contour::new(vec![
        Vertex::arc(5.0, 0.0, 1.0),
        Vertex::arc(-5.0, 0.0, 1.0),
    ]);
    let disc = Contour::new(vec![
        Vertex::arc(0.0, 5.0, -1.0),
        Vertex::arc(0.0, -5.0, -1.0),
    ]);
    let nest = nest(vec![
        part(vec![
            Contour::circle(Point::new(0.0, 0.0), 10.0, true),
            hole,
        ]),
        part(vec![disc]),
    ]);
    let plan = PlanGraph::from_nest(&nest, &keep_corners()).unwrap();
    let g = plan.graph();
    // Outer circle: 2 vertices, 2 arcs. Shared circle: 4 vertices, 4 quarter arcs, 2 contours each.
    assert_eq!((g.vertex_count(), g.edge_count()), (6, 6));
    let shared = (0..6).filter(|&x| plan.edge_contours(x).len() == 2).count();
    assert_eq!(shared, 4);
    let components = plan.components().unwrap();
    assert_eq!(components.len(), 2);
    let dissolved = PlanGraph::from_nest(&nest, &PlanOptions::default()).unwrap();
    let g = dissolved.graph();
    assert_eq!((g.vertex_count(), g.edge_count()), (2, 2));
    let lengths: Vec<f64> = (0..2)
        .map(|x| dissolved.edge_spans(x).iter().map(|s| s.length()).sum())
        .collect();
    let expected = [20.0 * std::f64::consts::PI, 10.0 * std::f64::consts::PI];
    assert!(
        lengths
            .iter()
            .all(|l| expected.iter().any(|x| (x - l).abs() < 1e-9)),
        "{lengths:?}"
    );
}

#[test]
fn tangent_circles_touch_in_one_vertex_ordered_by_curvature() {
    // A circle of radius 5 inside one of radius 10, touching at (10, 0): tangents agree there,
    // so the rotation comes from curvature.
    let nest = nest(vec![
        part(vec![Contour::circle(Point::new(0.0, 0.0), 10.0, true)]),
        part(vec![Contour::circle(Point::new(5.0, 0.0), 5.0, true)]),
    ]);
    let plan = PlanGraph::from_nest(&nest, &PlanOptions::default()).unwrap();
    let g = plan.graph();
    assert_eq!((g.vertex_count(), g.edge_count()), (1, 2));
    let e = plan.embedding().unwrap();
    // Plane (Euler's formula holds) with three faces: outside, between the circles, inside.
    assert_eq!(e.faces().count(), 3);
    let ranks: Vec<u32> = (0..2).map(|x| e.edge_rank(x)).collect();
    assert!(ranks.contains(&1) && ranks.contains(&2), "{ranks:?}");
}
