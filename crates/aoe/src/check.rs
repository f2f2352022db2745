//! Independent checks of chains and routes: Euler (every edge once), A-condition or
//! non-crossing, and ordered enclosing (OE). Shares nothing with the construction but the
//! graph's rotation: faces are traced here again.

use thiserror::Error;

use crate::embedding::Embedding;
use crate::graph::{Dart, PlaneGraph};

/// What is wrong with a chain or route.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum CheckError {
    /// A chain has no edges.
    #[error("chain {chain} is empty")]
    EmptyChain {
        /// Index of the chain in the route.
        chain: usize,
    },
    /// A dart number does not exist.
    #[error("position {position}: dart {dart} does not exist")]
    NoSuchDart {
        /// Position in the route (over all chains).
        position: usize,
        /// The dart.
        dart: Dart,
    },
    /// Two consecutive darts of a chain do not meet.
    #[error("position {position}: dart {dart} does not start where the previous dart ends")]
    NotATrail {
        /// Position in the route.
        position: usize,
        /// The dart.
        dart: Dart,
    },
    /// An edge is cut twice.
    #[error("edge {edge} is cut twice (positions {first} and {second})")]
    EdgeRepeated {
        /// The edge.
        edge: usize,
        /// First position.
        first: usize,
        /// Second position.
        second: usize,
    },
    /// An edge is never cut.
    #[error("edge {edge} is never cut")]
    EdgeMissing {
        /// The edge.
        edge: usize,
    },
    /// A closed chain does not end where it starts.
    #[error("the chain ends at vertex {end}, not at its start vertex {start}")]
    NotClosed {
        /// Start vertex.
        start: usize,
        /// End vertex.
        end: usize,
    },
    /// Consecutive edges are not neighbours around their common vertex (A-condition).
    #[error("position {position}: at vertex {vertex} the chain goes from dart {from} to dart {to}, which are not neighbours")]
    NotNeighbours {
        /// Position of the second dart (the closing transition has position = chain length).
        position: usize,
        /// The vertex.
        vertex: usize,
        /// Dart leaving the vertex backwards along the previous edge.
        from: Dart,
        /// Dart leaving the vertex along the next edge.
        to: Dart,
    },
    /// Two passes through a vertex cross each other.
    #[error("at vertex {vertex} the pass {first:?} crosses the pass {second:?}")]
    Crossing {
        /// The vertex.
        vertex: usize,
        /// Darts of one pass (both leave the vertex).
        first: (Dart, Dart),
        /// Darts of the other pass.
        second: (Dart, Dart),
    },
    /// A chain of a plan route has no edges or names an edge that does not exist.
    #[error("chain {chain} of the plan route is empty or names a missing edge")]
    BadPlanChain {
        /// Index of the chain.
        chain: usize,
    },
    /// After a chain, a part of the plan not yet cut lies in a region already cut free.
    #[error("after chain {chain} the plan vertex {vertex}, not cut yet, lies in a region already cut free")]
    EnclosesComponent {
        /// Index of the chain.
        chain: usize,
        /// A plan vertex of the enclosed component.
        vertex: usize,
    },
    /// A prefix encloses an edge that is not cut yet (ordered enclosing fails).
    #[error("after {prefix} edges the cut encloses edge {edge}, which is still uncut")]
    Encloses {
        /// Length of the offending prefix.
        prefix: usize,
        /// An enclosed uncut edge.
        edge: usize,
    },
}

/// Checks a closed AOE-chain: it is a closed trail covering every edge exactly once, every
/// transition (the closing one too) joins rotation neighbours, and no prefix encloses an uncut
/// edge.
pub fn check_chain(embedding: &Embedding, darts: &[Dart]) -> Result<(), CheckError> {
    let graph = embedding.graph();
    check_cover(graph, &[darts])?;
    let (start, end) = (graph.origin(darts[0]), graph.head(darts[darts.len() - 1]));
    if start != end {
        return Err(CheckError::NotClosed { start, end });
    }
    for position in 1..=darts.len() {
        let from = PlaneGraph::twin(darts[position - 1]);
        let to = darts[position % darts.len()];
        if graph.next_ccw(from) != to && graph.next_cw(from) != to {
            return Err(CheckError::NotNeighbours {
                position,
                vertex: graph.origin(to),
                from,
                to,
            });
        }
    }
    check_ordered_enclosing(embedding, darts)
}

/// Checks an OE-route: chains (open or closed trails) that together cut every edge exactly
/// once; no two passes through a vertex cross (a chain's start and end are points, not passes,
/// so they cannot cross anything) (passes of one chain or of different chains);
/// and no prefix of the whole route, across chains, encloses an uncut edge. The last test is
/// the union form of Def. 6: a region cut off by several chains together counts too.
pub fn check_route(embedding: &Embedding, chains: &[Vec<Dart>]) -> Result<(), CheckError> {
    let graph = embedding.graph();
    let slices: Vec<&[Dart]> = chains.iter().map(Vec::as_slice).collect();
    check_cover(graph, &slices)?;
    // Passes: (vertex, dart in, dart out) with both darts leaving the vertex.
    let mut passes: Vec<Vec<(Dart, Dart)>> = vec![Vec::new(); graph.vertex_count()];
    for chain in chains {
        for pair in chain.windows(2) {
            let from = PlaneGraph::twin(pair[0]);
            passes[graph.origin(from)].push((from, pair[1]));
        }
    }
    // Position of every dart around its own vertex.
    let mut position = vec![usize::MAX; graph.dart_count()];
    for vertex in 0..graph.vertex_count() {
        for (i, dart) in graph.darts_around(vertex).enumerate() {
            position[dart] = i;
        }
    }
    for (vertex, vertex_passes) in passes.iter().enumerate() {
        for (i, &a) in vertex_passes.iter().enumerate() {
            for &b in &vertex_passes[i + 1..] {
                if interleave(
                    (position[a.0], position[a.1]),
                    (position[b.0], position[b.1]),
                ) {
                    return Err(CheckError::Crossing {
                        vertex,
                        first: a,
                        second: b,
                    });
                }
            }
        }
    }
    let all: Vec<Dart> = chains.iter().flatten().copied().collect();
    check_ordered_enclosing(embedding, &all)
}

/// Whether chords (a0, a1) and (b0, b1) between positions on a circle cross.
fn interleave(a: (usize, usize), b: (usize, usize)) -> bool {
    let (lo, hi) = (a.0.min(a.1), a.0.max(a.1));
    let inside = |x: usize| lo < x && x < hi;
    let ends_shared = b.0 == a.0 || b.0 == a.1 || b.1 == a.0 || b.1 == a.1;
    !ends_shared && inside(b.0) != inside(b.1)
}

/// Darts exist, chains are trails, every edge is cut exactly once.
pub(crate) fn check_cover(graph: &PlaneGraph, chains: &[&[Dart]]) -> Result<(), CheckError> {
    let mut cut_at = vec![usize::MAX; graph.edge_count()];
    let mut position = 0;
    for (index, chain) in chains.iter().enumerate() {
        if chain.is_empty() {
            return Err(CheckError::EmptyChain { chain: index });
        }
        for (i, &dart) in chain.iter().enumerate() {
            if dart >= graph.dart_count() {
                return Err(CheckError::NoSuchDart { position, dart });
            }
            if i > 0 && graph.head(chain[i - 1]) != graph.origin(dart) {
                return Err(CheckError::NotATrail { position, dart });
            }
            let edge = PlaneGraph::edge(dart);
            if cut_at[edge] != usize::MAX {
                return Err(CheckError::EdgeRepeated {
                    edge,
                    first: cut_at[edge],
                    second: position,
                });
            }
            cut_at[edge] = position;
            position += 1;
        }
    }
    if let Some(edge) = cut_at.iter().position(|&p| p == usize::MAX) {
        return Err(CheckError::EdgeMissing { edge });
    }
    Ok(())
}

/// Ordered enclosing by the digest's linear-time test (§4.5): walking the cut sequence
/// backwards, un-cut each edge by joining the faces on its two sides; the edge is enclosed by
/// the prefix before it unless its region is the outer one. Checking only that edge suffices:
/// regions only grow as the walk goes back, so later edges found outside stay outside.
fn check_ordered_enclosing(embedding: &Embedding, darts: &[Dart]) -> Result<(), CheckError> {
    let graph = embedding.graph();
    // Faces traced afresh: face_left[d] for every dart.
    let mut face_left = vec![usize::MAX; graph.dart_count()];
    let mut face_count = 0;
    for start in 0..graph.dart_count() {
        if face_left[start] != usize::MAX {
            continue;
        }
        let mut dart = start;
        while face_left[dart] == usize::MAX {
            face_left[dart] = face_count;
            dart = graph.next_cw(PlaneGraph::twin(dart));
        }
        face_count += 1;
    }
    let outer_dart = (0..graph.dart_count())
        .find(|&d| embedding.faces().left(d) == embedding.outer_face())
        .expect("the outer face has a dart");
    let outer = face_left[outer_dart];
    let mut parent: Vec<usize> = (0..face_count).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    // Keep scanning to report the shortest offending prefix.
    let mut shortest = None;
    let total = darts.len();
    for (back, &dart) in darts.iter().rev().enumerate() {
        let (a, b) = (
            find(&mut parent, face_left[dart]),
            find(&mut parent, face_left[dart ^ 1]),
        );
        parent[a] = b;
        if find(&mut parent, b) != find(&mut parent, outer) {
            shortest = Some(CheckError::Encloses {
                prefix: total - 1 - back,
                edge: dart / 2,
            });
        }
    }
    shortest.map_or(Ok(()), Err)
}
