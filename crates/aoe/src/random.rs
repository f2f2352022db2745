//! Seeded random plane graphs for tests and benchmarks.
//!
//! [`random_plane_multigraph`] grows a connected plane multigraph by two rotation-preserving
//! moves (a pendant edge at a random corner, or a chord splitting a random face between two of
//! its corners, possibly a loop); [`medial_graph`] turns any plane graph into a plane 4-regular
//! one (one vertex per edge, one edge per corner), loops and double edges included;
//! [`delete_random_edges`] removes non-bridges to make T-junctions.

use cutroute_geometry::SplitMix64;

use crate::embedding::{Embedding, EmbeddingError};
use crate::graph::{Dart, PlaneGraph};

/// How far along a face boundary a chord may reach, in darts.
const CHORD_REACH: u64 = 12;

/// A connected plane multigraph with `edge_count ≥ 1` edges; about a third of the moves add
/// a pendant edge (new vertex), the others split a face by a chord between a random corner and
/// one up to 11 corners further along the face (the same corner gives a loop). Linear time.
pub fn random_plane_multigraph(edge_count: usize, rng: &mut SplitMix64) -> PlaneGraph {
    let edge_count = edge_count.max(1);
    // Rotation as a ccw successor array, built move by move.
    let mut origin: Vec<usize> = vec![0, 1];
    let mut next_ccw: Vec<Dart> = vec![0, 1];
    let mut next_cw: Vec<Dart> = vec![0, 1];
    let mut vertex_count = 2;
    let insert_after = |next_ccw: &mut Vec<Dart>, next_cw: &mut Vec<Dart>, at: Dart, new: Dart| {
        let after = next_ccw[at];
        next_ccw[at] = new;
        next_cw[new] = at;
        next_ccw[new] = after;
        next_cw[after] = new;
    };
    while origin.len() < 2 * edge_count {
        let new = origin.len();
        let corner = rng.below(new as u64) as Dart;
        next_ccw.extend([new, new + 1]);
        next_cw.extend([new, new + 1]);
        if rng.below(3) == 0 {
            origin.extend([origin[corner], vertex_count]);
            vertex_count += 1;
            insert_after(&mut next_ccw, &mut next_cw, corner, new);
        } else {
            // Another corner of the face on the left of `corner`, a few steps along its
            // boundary (walking whole faces would make generation quadratic).
            let mut other = corner;
            for _ in 0..rng.below(CHORD_REACH) {
                other = next_cw[other ^ 1];
            }
            origin.extend([origin[corner], origin[other]]);
            insert_after(&mut next_ccw, &mut next_cw, corner, new);
            // With `other == corner` the second dart goes after the first: a loop.
            let at = if other == corner { new } else { other };
            insert_after(&mut next_ccw, &mut next_cw, at, new + 1);
        }
    }
    rotations_to_graph(vertex_count, &origin, &next_ccw)
}

fn rotations_to_graph(vertex_count: usize, origin: &[usize], next_ccw: &[Dart]) -> PlaneGraph {
    let edges: Vec<(usize, usize)> = origin.chunks(2).map(|p| (p[0], p[1])).collect();
    let mut rotations = vec![Vec::new(); vertex_count];
    let mut seen = vec![false; origin.len()];
    for start in 0..origin.len() {
        if seen[start] || !rotations[origin[start]].is_empty() {
            continue;
        }
        let mut dart = start;
        while !seen[dart] {
            seen[dart] = true;
            rotations[origin[dart]].push(dart);
            dart = next_ccw[dart];
        }
    }
    PlaneGraph::from_rotations(vertex_count, &edges, &rotations)
        .expect("moves keep a valid rotation system")
}

/// The medial graph: vertex `e` for every edge `e` of `graph`, and edge `x` for every corner
/// (dart `x` and its counter-clockwise successor at their vertex) joining the vertices of the
/// two edges that bound the corner. Plane and 4-regular.
pub fn medial_graph(graph: &PlaneGraph) -> PlaneGraph {
    let corners = graph.dart_count();
    let mut origin = Vec::with_capacity(2 * corners);
    for x in 0..corners {
        origin.push(PlaneGraph::edge(x));
        origin.push(PlaneGraph::edge(graph.next_ccw(x)));
    }
    // Corner x has medial dart 2x at the vertex of edge(x) and 2x + 1 at the vertex of
    // edge(next_ccw(x)). Around the midpoint of edge e (darts a from its first end, b from its
    // second), counter-clockwise: the corner right of b, left of a, right of a, left of b.
    let mut next_ccw = vec![0; 2 * corners];
    for e in 0..graph.edge_count() {
        let (a, b) = (2 * e, 2 * e + 1);
        let around = [
            2 * graph.next_cw(b) + 1,
            2 * a,
            2 * graph.next_cw(a) + 1,
            2 * b,
        ];
        for i in 0..4 {
            next_ccw[around[i]] = around[(i + 1) % 4];
        }
    }
    rotations_to_graph(graph.edge_count(), &origin, &next_ccw)
}

/// A random connected plane 4-regular graph with `2 × base_edges` edges and a random outer
/// face: the medial graph of [`random_plane_multigraph`].
pub fn random_four_regular(
    base_edges: usize,
    rng: &mut SplitMix64,
) -> Result<Embedding, EmbeddingError> {
    let medial = medial_graph(&random_plane_multigraph(base_edges, rng));
    let face_count = medial.faces().count();
    let outer = rng.below(face_count as u64) as usize;
    Embedding::new(medial, outer)
}

/// `graph` without up to `count` random edges, never a bridge, so it stays connected. Deleting
/// edges of a 4-regular graph leaves T-junctions (degree 3), as common-line cutting plans have.
pub fn delete_random_edges(graph: &PlaneGraph, count: usize, rng: &mut SplitMix64) -> PlaneGraph {
    let faces = graph.faces();
    let mut parent: Vec<usize> = (0..faces.count()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut deleted = vec![false; graph.edge_count()];
    let mut order: Vec<usize> = (0..graph.edge_count()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i as u64 + 1) as usize);
    }
    let mut removed = 0;
    for e in order {
        if removed == count {
            break;
        }
        // An edge is a bridge exactly when the same face lies on both sides.
        let (a, b) = (
            find(&mut parent, faces.left(2 * e)),
            find(&mut parent, faces.left(2 * e + 1)),
        );
        if a != b {
            parent[a] = b;
            deleted[e] = true;
            removed += 1;
        }
    }
    let mut new_id = vec![usize::MAX; graph.edge_count()];
    let mut edges = Vec::new();
    for e in 0..graph.edge_count() {
        if !deleted[e] {
            new_id[e] = edges.len();
            edges.push(graph.ends(e));
        }
    }
    let rotations: Vec<Vec<Dart>> = (0..graph.vertex_count())
        .map(|v| {
            graph
                .darts_around(v)
                .filter(|&d| !deleted[d / 2])
                .map(|d| 2 * new_id[d / 2] + d % 2)
                .collect()
        })
        .collect();
    PlaneGraph::from_rotations(graph.vertex_count(), &edges, &rotations)
        .expect("deleting edges keeps a valid rotation system")
}
