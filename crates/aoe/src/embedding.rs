//! A connected plane graph with a chosen outer face, and the ranks of its faces and edges.

use thiserror::Error;

use crate::graph::{Dart, Faces, PlaneGraph};

/// Why a graph cannot be ranked.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum EmbeddingError {
    /// The graph has no edge.
    #[error("the graph has no edges")]
    NoEdges,
    /// Some vertex cannot be reached from vertex 0.
    #[error("the graph is not connected")]
    Disconnected,
    /// The rotation system describes a surface of higher genus, not the plane.
    #[error("the rotation system is not planar: V − E + F = {euler_characteristic}, expected 2")]
    NotPlanar {
        /// `V − E + F` of the rotation system.
        euler_characteristic: i64,
    },
    /// The dart naming the outer face does not exist.
    #[error("dart {dart} does not exist ({dart_count} darts)")]
    NoSuchDart {
        /// The dart asked for.
        dart: Dart,
        /// Number of darts.
        dart_count: usize,
    },
    /// The outer face id does not exist.
    #[error("outer face {face} does not exist ({face_count} faces)")]
    NoSuchFace {
        /// The face asked for.
        face: usize,
        /// Number of faces.
        face_count: usize,
    },
}

/// A rank-k cut point: a vertex of degree 4 whose four edge ends all have rank `k`, i.e. all
/// border the outer face of the rank-k subgraph `G_k` (Def. 12; digest §2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CutPoint {
    /// The vertex.
    pub vertex: usize,
    /// Its rank `k`.
    pub rank: u32,
}

/// A connected plane graph, its faces, an outer face `f0` and the ranks.
///
/// Face rank is the breadth-first distance from `f0` in the dual graph (Def. 11), edge rank is
/// `1 + min(rank of the faces on its two sides)`, the number of faces one must cross to reach
/// the edge from `f0` (Def. 9; equal to the literal peeling definition, digest §4.1).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Embedding {
    graph: PlaneGraph,
    faces: Faces,
    outer_face: usize,
    face_rank: Vec<u32>,
    edge_rank: Vec<u32>,
}

impl Embedding {
    /// Checks connectivity and planarity, traces faces and ranks them from `outer_face`.
    pub fn new(graph: PlaneGraph, outer_face: usize) -> Result<Self, EmbeddingError> {
        if graph.edge_count() == 0 {
            return Err(EmbeddingError::NoEdges);
        }
        if !graph.is_connected() {
            return Err(EmbeddingError::Disconnected);
        }
        let faces = graph.faces();
        let euler_characteristic =
            graph.vertex_count() as i64 - graph.edge_count() as i64 + faces.count() as i64;
        if euler_characteristic != 2 {
            return Err(EmbeddingError::NotPlanar {
                euler_characteristic,
            });
        }
        if outer_face >= faces.count() {
            return Err(EmbeddingError::NoSuchFace {
                face: outer_face,
                face_count: faces.count(),
            });
        }
        let face_rank = faces.dual().distances_from(outer_face);
        let edge_rank = (0..graph.edge_count())
            .map(|e| 1 + face_rank[faces.left(2 * e)].min(face_rank[faces.left(2 * e + 1)]))
            .collect();
        Ok(Embedding {
            graph,
            faces,
            outer_face,
            face_rank,
            edge_rank,
        })
    }

    /// Like [`Embedding::new`], with the outer face given as the face on the left of `dart`.
    pub fn with_outer_dart(graph: PlaneGraph, dart: Dart) -> Result<Self, EmbeddingError> {
        if dart >= graph.dart_count() {
            return Err(EmbeddingError::NoSuchDart {
                dart,
                dart_count: graph.dart_count(),
            });
        }
        let outer = graph.faces().left(dart);
        Embedding::new(graph, outer)
    }

    /// The graph.
    pub fn graph(&self) -> &PlaneGraph {
        &self.graph
    }

    /// The faces.
    pub fn faces(&self) -> &Faces {
        &self.faces
    }

    /// The outer face `f0`.
    pub fn outer_face(&self) -> usize {
        self.outer_face
    }

    /// Rank of a face (0 for `f0`).
    pub fn face_rank(&self, face: usize) -> u32 {
        self.face_rank[face]
    }

    /// Rank of an edge (1 for edges on `f0`).
    pub fn edge_rank(&self, edge: usize) -> u32 {
        self.edge_rank[edge]
    }

    /// Rank of the edge a dart belongs to.
    pub fn dart_rank(&self, dart: Dart) -> u32 {
        self.edge_rank[dart / 2]
    }

    /// Whether the vertex touches the outer face.
    pub fn is_on_outer_face(&self, vertex: usize) -> bool {
        self.graph
            .darts_around(vertex)
            .any(|d| self.faces.left(d) == self.outer_face)
    }

    /// The vertices on the outer face, in increasing order.
    pub fn outer_vertices(&self) -> Vec<usize> {
        (0..self.graph.vertex_count())
            .filter(|&v| self.is_on_outer_face(v))
            .collect()
    }

    /// Whether `vertex` is a rank-k cut point, and its rank.
    pub fn cut_point_rank(&self, vertex: usize) -> Option<u32> {
        let mut darts = self.graph.darts_around(vertex);
        let first = self.dart_rank(darts.next()?);
        let mut degree = 1;
        for dart in darts {
            if self.dart_rank(dart) != first {
                return None;
            }
            degree += 1;
        }
        (degree == 4).then_some(first)
    }

    /// All cut points, by vertex.
    pub fn cut_points(&self) -> Vec<CutPoint> {
        (0..self.graph.vertex_count())
            .filter_map(|vertex| {
                self.cut_point_rank(vertex)
                    .map(|rank| CutPoint { vertex, rank })
            })
            .collect()
    }
}
