//! AOE-chains in plane connected 4-regular graphs: cut-point splitting (the paper's Algorithm 1)
//! and the greedy construction (Algorithms 2–3), with the digest's corrections (§4.5).

use thiserror::Error;

use crate::embedding::Embedding;
use crate::graph::{Dart, PlaneGraph};

/// How a rank-k cut point is split into two degree-2 vertices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SplitRule {
    /// Keep together the two edges that bound a corner of rank `k − 1` (a piece of the outer
    /// face of `G_k`); the two rank-k corners merge. Never got stuck in the digest's tests and
    /// in ours (digest §4.2, fix 3).
    #[default]
    Corrected,
    /// The printed Algorithm 1: `point(v)` is the highest-numbered incident edge `e`; if `e`
    /// and its counter-clockwise neighbour see the same unordered pair of faces of `G`, pair
    /// `e` with its clockwise neighbour, else with its counter-clockwise one. Undecided when the
    /// two outer corners are different faces of `G` and then gets stuck on some graphs; kept
    /// to reproduce the paper's Table 2.
    Paper,
}

/// Settings of [`aoe_chain`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AoeOptions {
    /// How cut points are split.
    pub split_rule: SplitRule,
}

/// Why no AOE-chain was produced.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum AoeError {
    /// The start vertex does not exist.
    #[error("start vertex {vertex} does not exist ({vertex_count} vertices)")]
    NoSuchVertex {
        /// The vertex asked for.
        vertex: usize,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// The algorithm needs every vertex to have degree 4.
    #[error("vertex {vertex} has degree {degree}; AOE-chain construction needs a 4-regular graph")]
    NotFourRegular {
        /// The first offending vertex.
        vertex: usize,
        /// Its degree.
        degree: usize,
    },
    /// Starting off the outer face always fails: the prefix without the last edge would
    /// enclose it (digest §2.1).
    #[error("start vertex {vertex} is not on the outer face")]
    StartNotOnOuterFace {
        /// The vertex asked for.
        vertex: usize,
    },
    /// Both candidate edges were already cut before all edges were (the paper's "the problem
    /// has no solution"; with the corrected split rule this was never observed).
    #[error("stuck at vertex {vertex} after {traversed} of {edge_count} edges")]
    Stuck {
        /// Where the walk stopped.
        vertex: usize,
        /// Edges traversed so far.
        traversed: usize,
        /// All edges.
        edge_count: usize,
    },
}

/// An AOE-chain: a closed trail given by its darts in cutting order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AoeChain {
    /// The darts in order; dart `d` cuts edge `d / 2` from its origin to its head.
    pub darts: Vec<Dart>,
    /// The vertices split as cut points before the walk, in increasing order.
    pub split_vertices: Vec<usize>,
}

impl AoeChain {
    /// The edge numbers in cutting order (0-based).
    pub fn edges(&self) -> Vec<usize> {
        self.darts.iter().map(|&d| d / 2).collect()
    }
}

/// The transitions available at every dart after cut-point splitting: for an outgoing dart
/// `x`, `left[x]` and `right[x]` are the darts the walk may leave by after arriving along
/// `twin(x)` (the counter-clockwise and clockwise neighbours, or twice the partner at a split
/// vertex).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Transitions {
    /// Counter-clockwise neighbour (the paper's `l`), or the partner at a split vertex.
    pub left: Vec<Dart>,
    /// Clockwise neighbour (the paper's `r`), or the partner at a split vertex.
    pub right: Vec<Dart>,
    /// The vertices that were split.
    pub split_vertices: Vec<usize>,
}

/// Algorithm 1 (CUT-POINT-SPLITTING): pairs the darts of every rank-k cut point so that the
/// vertex becomes two degree-2 vertices. Ranks do not change: a split only merges two faces of
/// equal rank. `O(|E|)`.
pub fn split_cut_points(embedding: &Embedding, rule: SplitRule) -> Transitions {
    let graph = embedding.graph();
    let faces = embedding.faces();
    let mut left: Vec<Dart> = (0..graph.dart_count()).map(|d| graph.next_ccw(d)).collect();
    let mut right: Vec<Dart> = (0..graph.dart_count()).map(|d| graph.next_cw(d)).collect();
    let mut split_vertices = Vec::new();
    for vertex in 0..graph.vertex_count() {
        let Some(rank) = embedding.cut_point_rank(vertex) else {
            continue;
        };
        let d0 = match rule {
            SplitRule::Corrected => graph.vertex_dart(vertex).expect("a cut point has darts"),
            // point(v) = the last edge written in the scan over edges, i.e. the highest number;
            // for a loop the scan's test `v = v1(e)` picks the first end.
            SplitRule::Paper => graph
                .darts_around(vertex)
                .max_by_key(|&d| (d / 2, std::cmp::Reverse(d)))
                .expect("a cut point has darts"),
        };
        let d1 = graph.next_ccw(d0);
        let d2 = graph.next_ccw(d1);
        let d3 = graph.next_ccw(d2);
        let pair_around_corner_0 = match rule {
            SplitRule::Corrected => embedding.face_rank(faces.left(d0)) < rank,
            SplitRule::Paper => {
                let pair = |d: Dart| {
                    let (a, b) = (faces.left(d), faces.right(d));
                    (a.min(b), a.max(b))
                };
                // Line 29: equal face pairs → then-branch, which pairs (d3, d0) and (d1, d2).
                pair(d0) != pair(d1)
            }
        };
        let pairs = if pair_around_corner_0 {
            [(d0, d1), (d2, d3)]
        } else {
            [(d1, d2), (d3, d0)]
        };
        for (a, b) in pairs {
            left[a] = b;
            right[a] = b;
            left[b] = a;
            right[b] = a;
        }
        split_vertices.push(vertex);
    }
    Transitions {
        left,
        right,
        split_vertices,
    }
}

/// Builds an AOE-chain of a plane connected 4-regular graph starting at `start` (a vertex on
/// the outer face): split the cut points, leave `start` along its edge of maximal rank (ties:
/// lowest edge number), then repeatedly take the untraversed counter-clockwise or clockwise
/// neighbour, preferring the higher rank (ties: counter-clockwise). Stops after |E| edges.
/// `O(|E|)`.
pub fn aoe_chain(
    embedding: &Embedding,
    start: usize,
    options: &AoeOptions,
) -> Result<AoeChain, AoeError> {
    let graph = embedding.graph();
    let vertex_count = graph.vertex_count();
    if start >= vertex_count {
        return Err(AoeError::NoSuchVertex {
            vertex: start,
            vertex_count,
        });
    }
    for vertex in 0..vertex_count {
        let degree = graph.degree(vertex);
        if degree != 4 {
            return Err(AoeError::NotFourRegular { vertex, degree });
        }
    }
    if !embedding.is_on_outer_face(start) {
        return Err(AoeError::StartNotOnOuterFace { vertex: start });
    }
    let transitions = split_cut_points(embedding, options.split_rule);
    let edge_count = graph.edge_count();
    let mut dart = graph
        .darts_around(start)
        .max_by_key(|&d| (embedding.dart_rank(d), std::cmp::Reverse(d)))
        .expect("degree 4");
    let mut used = vec![false; edge_count];
    let mut darts = Vec::with_capacity(edge_count);
    loop {
        let edge = PlaneGraph::edge(dart);
        if used[edge] {
            return Err(AoeError::Stuck {
                vertex: graph.origin(dart),
                traversed: darts.len(),
                edge_count,
            });
        }
        used[edge] = true;
        darts.push(dart);
        if darts.len() == edge_count {
            break;
        }
        let arrived = PlaneGraph::twin(dart);
        let (l, r) = (transitions.left[arrived], transitions.right[arrived]);
        let (preferred, other) = if embedding.dart_rank(r) > embedding.dart_rank(l) {
            (r, l)
        } else {
            (l, r)
        };
        dart = if used[PlaneGraph::edge(preferred)] {
            other
        } else {
            preferred
        };
    }
    Ok(AoeChain {
        darts,
        split_vertices: transitions.split_vertices,
    })
}
