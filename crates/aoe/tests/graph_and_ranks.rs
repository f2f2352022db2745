//! Plane graph basics: faces, Euler's formula, the dual, ranks against the literal definition.

mod common;

use cutroute_aoe::random::{medial_graph, random_four_regular, random_plane_multigraph};
use cutroute_aoe::{Embedding, EmbeddingError, GraphError, PlaneGraph};
use cutroute_geometry::SplitMix64;

/// Def. 9 applied literally: peel the edges on the outer face of what remains, again and
/// again. The outer region of `G_k` is the union of the faces of `G` joined to `f0` across
/// already-peeled edges.
fn ranks_by_peeling(embedding: &Embedding) -> Vec<u32> {
    let graph = embedding.graph();
    let faces = embedding.faces();
    let mut region: Vec<usize> = (0..faces.count()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            x = p[x];
        }
        x
    }
    let mut rank = vec![0u32; graph.edge_count()];
    let mut k = 0;
    while rank.contains(&0) {
        k += 1;
        let outer = find(&mut region, embedding.outer_face());
        let peel: Vec<usize> = (0..graph.edge_count())
            .filter(|&e| rank[e] == 0)
            .filter(|&e| {
                find(&mut region, faces.left(2 * e)) == outer
                    || find(&mut region, faces.left(2 * e + 1)) == outer
            })
            .collect();
        assert!(!peel.is_empty(), "peeling made no progress");
        for e in peel {
            rank[e] = k;
            let (a, b) = (
                find(&mut region, faces.left(2 * e)),
                find(&mut region, faces.left(2 * e + 1)),
            );
            region[a] = b;
        }
    }
    rank
}

#[test]
fn figure_eight_and_its_faces() {
    let g = PlaneGraph::from_rotations(1, &[(0, 0), (0, 0)], &[vec![0, 1, 2, 3]]).unwrap();
    assert_eq!(g.faces().count(), 3);
    assert!(g.is_planar_connected());
    // Crossing the loops (darts 0,2,1,3) is a torus embedding, not a plane one.
    let torus = PlaneGraph::from_rotations(1, &[(0, 0), (0, 0)], &[vec![0, 2, 1, 3]]).unwrap();
    assert!(!torus.is_planar_connected());
    assert!(matches!(
        Embedding::new(torus, 0),
        Err(EmbeddingError::NotPlanar {
            euler_characteristic: 0
        })
    ));
    let e = Embedding::with_outer_dart(g, 1).unwrap();
    assert_eq!((e.edge_rank(0), e.edge_rank(1)), (1, 1));
    assert_eq!(e.cut_points().len(), 1);
    let dual = e.faces().dual();
    assert_eq!(dual.neighbours(e.outer_face()).len(), 2);
}

#[test]
fn bad_rotations_are_rejected() {
    let edges = [(0, 1)];
    assert_eq!(
        PlaneGraph::from_rotations(2, &edges, &[vec![0], vec![]]),
        Err(GraphError::MissingDart { dart: 1, edge: 0 })
    );
    assert_eq!(
        PlaneGraph::from_rotations(2, &edges, &[vec![1], vec![0]]),
        Err(GraphError::DartAtWrongVertex {
            vertex: 0,
            dart: 1,
            origin: 1
        })
    );
    assert_eq!(
        PlaneGraph::from_rotations(2, &edges, &[vec![0, 0], vec![1]]),
        Err(GraphError::DuplicateDart { vertex: 0, dart: 0 })
    );
    assert_eq!(
        PlaneGraph::from_rotations(2, &[(0, 2)], &[vec![0], vec![1]]),
        Err(GraphError::VertexOutOfRange {
            edge: 0,
            vertex: 2,
            vertex_count: 2
        })
    );
    assert!(matches!(
        PlaneGraph::from_rotations(2, &edges, &[vec![0, 5], vec![1]]),
        Err(GraphError::DartOutOfRange { dart: 5, .. })
    ));
    let two =
        PlaneGraph::from_rotations(4, &[(0, 1), (2, 3)], &[vec![0], vec![1], vec![2], vec![3]])
            .unwrap();
    assert!(matches!(
        Embedding::new(two, 0),
        Err(EmbeddingError::Disconnected)
    ));
}

#[test]
fn random_multigraphs_and_medial_graphs_are_plane() {
    let mut rng = SplitMix64::new(7);
    for size in 1..200 {
        let g = random_plane_multigraph(size, &mut rng);
        assert_eq!(g.edge_count(), size);
        assert!(g.is_planar_connected(), "size {size}");
        let m = medial_graph(&g);
        assert!(m.is_planar_connected(), "medial of size {size}");
        assert_eq!(m.vertex_count(), g.edge_count());
        assert!((0..m.vertex_count()).all(|v| m.degree(v) == 4));
        // Faces of the medial graph = vertices + faces of the base graph.
        assert_eq!(m.faces().count(), g.vertex_count() + g.faces().count());
    }
}

#[test]
fn ranks_equal_the_literal_definition_and_differ_by_one_across_edges() {
    let mut rng = SplitMix64::new(11);
    for round in 0..500 {
        let embedding = random_four_regular(2 + round % 80, &mut rng).unwrap();
        assert_eq!(
            (0..embedding.graph().edge_count())
                .map(|e| embedding.edge_rank(e))
                .collect::<Vec<_>>(),
            ranks_by_peeling(&embedding),
            "round {round}"
        );
        let faces = embedding.faces();
        for e in 0..embedding.graph().edge_count() {
            let (a, b) = (
                embedding.face_rank(faces.left(2 * e)),
                embedding.face_rank(faces.left(2 * e + 1)),
            );
            assert_eq!(
                a.abs_diff(b),
                1,
                "faces of a 4-regular plane graph are 2-colourable"
            );
        }
        // Around every vertex: ranks (k,k,k+1,k+1) cyclically, or all k at a cut point.
        let graph = embedding.graph();
        for v in 0..graph.vertex_count() {
            let r: Vec<u32> = graph
                .darts_around(v)
                .map(|d| embedding.dart_rank(d))
                .collect();
            let k = *r.iter().min().unwrap();
            let high = r.iter().filter(|&&x| x == k + 1).count();
            assert!(r.iter().all(|&x| x == k || x == k + 1));
            assert!(high == 0 || high == 2, "{r:?}");
            assert_eq!(embedding.cut_point_rank(v).is_some(), high == 0);
        }
    }
}

#[test]
fn non_eulerian_ranks_equal_the_literal_definition() {
    let mut rng = SplitMix64::new(5);
    for round in 0..300 {
        let g = random_plane_multigraph(1 + round % 60, &mut rng);
        let faces = g.faces().count();
        let outer = rng.below(faces as u64) as usize;
        let embedding = Embedding::new(g, outer).unwrap();
        let expected = ranks_by_peeling(&embedding);
        let ranks: Vec<u32> = (0..embedding.graph().edge_count())
            .map(|e| embedding.edge_rank(e))
            .collect();
        assert_eq!(ranks, expected, "round {round}");
    }
}
