//! Plane graphs as rotation systems on half-edges (darts).
//!
//! Edge `e` owns two darts: `2e` runs from the edge's first end to its second, `2e + 1` back.
//! Every vertex keeps its darts in counter-clockwise order. Loops (both darts at one vertex) and
//! multiple edges are ordinary cases here, which the paper's edge-based representation cannot
//! express unambiguously (digest §9.2).

use thiserror::Error;

/// Index of a half-edge: dart `2e` leaves edge `e`'s first end, dart `2e + 1` its second.
pub type Dart = usize;

/// Why a rotation system does not describe a graph.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum GraphError {
    /// An edge names a vertex that does not exist.
    #[error("edge {edge} ends at vertex {vertex}, but there are only {vertex_count} vertices")]
    VertexOutOfRange {
        /// The edge.
        edge: usize,
        /// The vertex it names.
        vertex: usize,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// The rotation list has a different length than the vertex count.
    #[error("{found} rotations given for {vertex_count} vertices")]
    RotationCount {
        /// Rotations given.
        found: usize,
        /// Vertices.
        vertex_count: usize,
    },
    /// A rotation names a dart that does not exist.
    #[error(
        "the rotation of vertex {vertex} names dart {dart}, but there are only {dart_count} darts"
    )]
    DartOutOfRange {
        /// The vertex.
        vertex: usize,
        /// The dart.
        dart: Dart,
        /// Number of darts (twice the edges).
        dart_count: usize,
    },
    /// A rotation names a dart that leaves another vertex.
    #[error("the rotation of vertex {vertex} names dart {dart}, which leaves vertex {origin}")]
    DartAtWrongVertex {
        /// The vertex.
        vertex: usize,
        /// The dart.
        dart: Dart,
        /// Where the dart actually starts.
        origin: usize,
    },
    /// A dart appears twice in the rotations.
    #[error("dart {dart} appears twice in the rotation of vertex {vertex}")]
    DuplicateDart {
        /// The vertex.
        vertex: usize,
        /// The dart.
        dart: Dart,
    },
    /// A dart appears in no rotation.
    #[error("dart {dart} (edge {edge}) appears in no rotation")]
    MissingDart {
        /// The dart.
        dart: Dart,
        /// Its edge.
        edge: usize,
    },
}

/// A graph embedded in the plane (or sphere) by the counter-clockwise order of darts at each vertex.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlaneGraph {
    origin: Vec<usize>,
    next_ccw: Vec<Dart>,
    next_cw: Vec<Dart>,
    vertex_dart: Vec<Option<Dart>>,
}

impl PlaneGraph {
    /// Builds a graph from its edges (`(first end, second end)`) and, for every vertex, the darts
    /// leaving it in counter-clockwise order.
    ///
    /// ```
    /// use cutroute_aoe::PlaneGraph;
    /// // A figure-eight: one vertex, two loops; the loops do not cross (darts 0,1 then 2,3).
    /// let g = PlaneGraph::from_rotations(1, &[(0, 0), (0, 0)], &[vec![0, 1, 2, 3]])?;
    /// assert_eq!(g.degree(0), 4);
    /// assert_eq!(g.next_ccw(1), 2);
    /// # Ok::<(), cutroute_aoe::GraphError>(())
    /// ```
    pub fn from_rotations(
        vertex_count: usize,
        edges: &[(usize, usize)],
        rotations: &[Vec<Dart>],
    ) -> Result<Self, GraphError> {
        if rotations.len() != vertex_count {
            return Err(GraphError::RotationCount {
                found: rotations.len(),
                vertex_count,
            });
        }
        let dart_count = 2 * edges.len();
        let mut origin = Vec::with_capacity(dart_count);
        for (edge, &(a, b)) in edges.iter().enumerate() {
            for vertex in [a, b] {
                if vertex >= vertex_count {
                    return Err(GraphError::VertexOutOfRange {
                        edge,
                        vertex,
                        vertex_count,
                    });
                }
            }
            origin.push(a);
            origin.push(b);
        }
        let mut next_ccw = vec![usize::MAX; dart_count];
        let mut next_cw = vec![usize::MAX; dart_count];
        let mut vertex_dart = vec![None; vertex_count];
        for (vertex, rotation) in rotations.iter().enumerate() {
            for &dart in rotation {
                if dart >= dart_count {
                    return Err(GraphError::DartOutOfRange {
                        vertex,
                        dart,
                        dart_count,
                    });
                }
                if origin[dart] != vertex {
                    return Err(GraphError::DartAtWrongVertex {
                        vertex,
                        dart,
                        origin: origin[dart],
                    });
                }
                if next_ccw[dart] != usize::MAX {
                    return Err(GraphError::DuplicateDart { vertex, dart });
                }
                next_ccw[dart] = dart; // placeholder: marks the dart as seen
            }
            for (i, &dart) in rotation.iter().enumerate() {
                let next = rotation[(i + 1) % rotation.len()];
                next_ccw[dart] = next;
                next_cw[next] = dart;
            }
            vertex_dart[vertex] = rotation.first().copied();
        }
        if let Some(dart) = next_ccw.iter().position(|&d| d == usize::MAX) {
            return Err(GraphError::MissingDart {
                dart,
                edge: dart / 2,
            });
        }
        Ok(PlaneGraph {
            origin,
            next_ccw,
            next_cw,
            vertex_dart,
        })
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertex_dart.len()
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.origin.len() / 2
    }

    /// Number of darts (twice the edges).
    pub fn dart_count(&self) -> usize {
        self.origin.len()
    }

    /// The dart of `edge` leaving its first end (`end == 0`) or its second end (`end == 1`).
    pub fn dart(edge: usize, end: usize) -> Dart {
        2 * edge + (end & 1)
    }

    /// The edge a dart belongs to.
    pub fn edge(dart: Dart) -> usize {
        dart / 2
    }

    /// The opposite dart of the same edge.
    pub fn twin(dart: Dart) -> Dart {
        dart ^ 1
    }

    /// The vertex a dart leaves.
    pub fn origin(&self, dart: Dart) -> usize {
        self.origin[dart]
    }

    /// The vertex a dart enters.
    pub fn head(&self, dart: Dart) -> usize {
        self.origin[dart ^ 1]
    }

    /// The two ends of an edge.
    pub fn ends(&self, edge: usize) -> (usize, usize) {
        (self.origin[2 * edge], self.origin[2 * edge + 1])
    }

    /// The next dart counter-clockwise around the dart's origin (the paper's `l`).
    pub fn next_ccw(&self, dart: Dart) -> Dart {
        self.next_ccw[dart]
    }

    /// The next dart clockwise around the dart's origin (the paper's `r`).
    pub fn next_cw(&self, dart: Dart) -> Dart {
        self.next_cw[dart]
    }

    /// The dart after `dart` along the boundary of the face on its left: the face is traversed
    /// counter-clockwise (clockwise for the outer face of a drawing).
    pub fn next_in_face(&self, dart: Dart) -> Dart {
        self.next_cw[dart ^ 1]
    }

    /// One dart leaving `vertex`, if it has any.
    pub fn vertex_dart(&self, vertex: usize) -> Option<Dart> {
        self.vertex_dart[vertex]
    }

    /// The darts leaving `vertex`, counter-clockwise from [`PlaneGraph::vertex_dart`].
    pub fn darts_around(&self, vertex: usize) -> impl Iterator<Item = Dart> + '_ {
        let first = self.vertex_dart[vertex];
        let mut current = first;
        std::iter::from_fn(move || {
            let dart = current?;
            let next = self.next_ccw[dart];
            current = if Some(next) == first {
                None
            } else {
                Some(next)
            };
            Some(dart)
        })
    }

    /// Number of darts leaving `vertex` (a loop counts twice).
    pub fn degree(&self, vertex: usize) -> usize {
        self.darts_around(vertex).count()
    }

    /// Whether every vertex that has an edge is reachable from every other one, and isolated
    /// vertices exist only in a graph without edges.
    pub fn is_connected(&self) -> bool {
        let n = self.vertex_count();
        if n == 0 {
            return true;
        }
        let mut seen = vec![false; n];
        let mut stack = vec![0];
        seen[0] = true;
        let mut reached = 1;
        while let Some(v) = stack.pop() {
            for dart in self.darts_around(v) {
                let w = self.head(dart);
                if !seen[w] {
                    seen[w] = true;
                    reached += 1;
                    stack.push(w);
                }
            }
        }
        reached == n
    }

    /// Traces the faces: every dart gets the id of the face on its left.
    pub fn faces(&self) -> Faces {
        let mut left = vec![usize::MAX; self.dart_count()];
        let mut count = 0;
        for start in 0..self.dart_count() {
            if left[start] != usize::MAX {
                continue;
            }
            let mut dart = start;
            while left[dart] == usize::MAX {
                left[dart] = count;
                dart = self.next_in_face(dart);
            }
            count += 1;
        }
        Faces { left, count }
    }

    /// Euler's formula `V − E + F = 2` for a connected graph: the rotation system describes a
    /// sphere (plane) embedding rather than one on a surface of higher genus.
    pub fn is_planar_connected(&self) -> bool {
        self.is_connected() && self.vertex_count() + self.faces().count() == self.edge_count() + 2
    }
}

/// The faces of a [`PlaneGraph`]: for every dart, the face on its left.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Faces {
    left: Vec<usize>,
    count: usize,
}

impl Faces {
    /// Number of faces.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The face on the left of a dart (the corner counter-clockwise from it at its origin).
    pub fn left(&self, dart: Dart) -> usize {
        self.left[dart]
    }

    /// The face on the right of a dart.
    pub fn right(&self, dart: Dart) -> usize {
        self.left[dart ^ 1]
    }

    /// The topological dual: one node per face, one edge per graph edge joining the faces on
    /// its two sides (a bridge gives a loop).
    pub fn dual(&self) -> DualGraph {
        let mut adjacency = vec![Vec::new(); self.count];
        for edge in 0..self.left.len() / 2 {
            let (a, b) = (self.left[2 * edge], self.left[2 * edge + 1]);
            adjacency[a].push((b, edge));
            if a != b {
                adjacency[b].push((a, edge));
            }
        }
        DualGraph { adjacency }
    }
}

/// The dual graph: faces joined across the edges they share.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DualGraph {
    adjacency: Vec<Vec<(usize, usize)>>,
}

impl DualGraph {
    /// The faces across the edges of `face`: `(neighbour face, edge)` pairs.
    pub fn neighbours(&self, face: usize) -> &[(usize, usize)] {
        &self.adjacency[face]
    }

    /// Breadth-first distance of every face from `source` (`u32::MAX` if unreachable).
    pub fn distances_from(&self, source: usize) -> Vec<u32> {
        let mut distance = vec![u32::MAX; self.adjacency.len()];
        let mut queue = std::collections::VecDeque::new();
        distance[source] = 0;
        queue.push_back(source);
        while let Some(face) = queue.pop_front() {
            for &(next, _) in &self.adjacency[face] {
                if distance[next] == u32::MAX {
                    distance[next] = distance[face] + 1;
                    queue.push_back(next);
                }
            }
        }
        distance
    }
}
