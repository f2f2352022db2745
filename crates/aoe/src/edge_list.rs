//! The paper's edge-list text format (Makarovskikh 2019, Sect. 3; digest §5 and §6).
//!
//! Line 1 holds the number of edges; then one line per edge with nine numbers
//! `v1 v2 l1 l2 r1 r2 f1 f2 rank`: its two vertices, the edges next counter-clockwise (`l`) and
//! clockwise (`r`) around each end, the face on the right when moving from `v_k` to the other
//! end, and the edge's rank. Vertices and edges are numbered from 1; face ids are arbitrary
//! non-negative numbers and face `0` is the outer face. An edge line may start with a label
//! `n:` equal to its edge number, as in the digest's fixtures. Blank lines are ignored.
//!
//! The format cannot say which end of a loop a neighbour pointer means, so loops are rejected
//! by the reader and the writer (digest §9.2); [`PlaneGraph`] itself handles loops.
//!
//! ```
//! use cutroute_aoe::{edge_list, Embedding, PlaneGraph};
//! // Two vertices joined by four parallel edges drawn as nested lenses, edge 0 on top.
//! let graph = PlaneGraph::from_rotations(
//!     2,
//!     &[(0, 1), (0, 1), (0, 1), (0, 1)],
//!     &[vec![6, 4, 2, 0], vec![1, 3, 5, 7]],
//! )?;
//! let embedding = Embedding::with_outer_dart(graph, 0)?; // above edge 0 is outside
//! let text = edge_list::write(&embedding)?;
//! assert_eq!(text.lines().nth(1), Some("1 2 4 2 2 4 1 0 1"));
//! let again = edge_list::read(&text)?;
//! assert_eq!((0..4).map(|e| again.edge_rank(e)).collect::<Vec<_>>(), [1, 2, 2, 1]);
//! assert_eq!(edge_list::write(&again)?, text);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use thiserror::Error;

use crate::embedding::{Embedding, EmbeddingError};
use crate::graph::{Dart, PlaneGraph};

const FIELDS: [&str; 9] = ["v1", "v2", "l1", "l2", "r1", "r2", "f1", "f2", "rank"];

/// Why an edge-list text was rejected. Lines are numbered from 1.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum ReadError {
    /// No edge count line.
    #[error("the text is empty: expected the number of edges on line 1")]
    Empty,
    /// The first line is not a positive integer.
    #[error("line {line}: expected the number of edges, found {found:?}")]
    BadEdgeCount {
        /// Line number.
        line: usize,
        /// What was there.
        found: String,
    },
    /// An edge line does not have nine numbers.
    #[error("line {line}: expected 9 numbers (v1 v2 l1 l2 r1 r2 f1 f2 rank), found {found}")]
    FieldCount {
        /// Line number.
        line: usize,
        /// Numbers found.
        found: usize,
    },
    /// A field is not a non-negative integer.
    #[error("line {line}, field {field}: {found:?} is not a non-negative integer")]
    BadNumber {
        /// Line number.
        line: usize,
        /// Field name (`v1` … `rank`, or `label`).
        field: &'static str,
        /// What was there.
        found: String,
    },
    /// The label `n:` in front of an edge line is not the edge's number.
    #[error("line {line}: label {found} but this is edge {expected}")]
    WrongLabel {
        /// Line number.
        line: usize,
        /// Label written.
        found: usize,
        /// The edge's number.
        expected: usize,
    },
    /// Fewer edge lines than announced.
    #[error("{expected} edges announced but only {found} given")]
    MissingEdges {
        /// Announced.
        expected: usize,
        /// Given.
        found: usize,
    },
    /// Text after the last announced edge.
    #[error("line {line}: more edge lines than the {expected} announced")]
    ExtraLine {
        /// Line number.
        line: usize,
        /// Announced edges.
        expected: usize,
    },
    /// A vertex number is 0 (numbering starts at 1).
    #[error("line {line}, field {field}: vertex 0 does not exist (vertices are numbered from 1)")]
    VertexZero {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
    },
    /// A vertex number exceeds twice the number of edges, so some vertex would have no edge.
    #[error(
        "line {line}, field {field}: vertex {vertex} cannot exist with at most {limit} edge ends"
    )]
    VertexOutOfRange {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
        /// The vertex written.
        vertex: usize,
        /// Twice the number of edges.
        limit: usize,
    },
    /// Vertex numbers skip a vertex, which then has no edges.
    #[error(
        "vertex {vertex} has no edges (vertices must be numbered 1..={vertex_count} without gaps)"
    )]
    IsolatedVertex {
        /// The vertex (1-based).
        vertex: usize,
        /// Highest vertex number.
        vertex_count: usize,
    },
    /// A neighbour field names an edge that does not exist.
    #[error("line {line}, field {field}: edge {edge} does not exist")]
    NoSuchEdge {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
        /// The edge named (1-based).
        edge: usize,
    },
    /// A neighbour field names an edge that does not touch the vertex at that end.
    #[error("line {line}, field {field}: edge {edge} does not end at vertex {vertex}")]
    NotIncident {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
        /// The edge named (1-based).
        edge: usize,
        /// The vertex (1-based).
        vertex: usize,
    },
    /// A loop, whose two ends the format cannot tell apart.
    #[error("line {line}, field {field}: edge {edge} is a loop, which this format cannot represent unambiguously")]
    Loop {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
        /// The loop (1-based).
        edge: usize,
    },
    /// The clockwise neighbours are not the inverse of the counter-clockwise ones.
    #[error("line {line}, field {field}: left and right neighbours disagree at vertex {vertex}")]
    LeftRightMismatch {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
        /// The vertex (1-based).
        vertex: usize,
    },
    /// The counter-clockwise neighbours at a vertex form more than one cycle.
    #[error("vertex {vertex}: the left neighbours do not form one cyclic order")]
    NotOneCycle {
        /// The vertex (1-based).
        vertex: usize,
    },
    /// A face id disagrees with the faces traced from the rotation.
    #[error("line {line}, field {field}: face {face} does not match the faces traced from the neighbours")]
    FaceMismatch {
        /// Line number.
        line: usize,
        /// Field name.
        field: &'static str,
        /// The face id written.
        face: usize,
    },
    /// No face has id 0, the outer face.
    #[error("no face has id 0 (the outer face)")]
    NoOuterFace,
    /// The graph is not a connected plane graph.
    #[error("{0}")]
    Embedding(#[from] EmbeddingError),
    /// The rank field differs from the rank computed from the faces.
    #[error("line {line}: rank {found} written, but the edge's rank is {computed}")]
    RankMismatch {
        /// Line number.
        line: usize,
        /// Rank written.
        found: usize,
        /// Rank computed.
        computed: u32,
    },
}

/// Why a graph cannot be written.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum WriteError {
    /// The format cannot represent loops.
    #[error("edge {edge} is a loop, which the edge-list format cannot represent")]
    Loop {
        /// The loop (1-based).
        edge: usize,
    },
}

struct EdgeLine {
    line: usize,
    fields: [usize; 9],
}

/// Reads the format; never panics.
pub fn read(text: &str) -> Result<Embedding, ReadError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let (count_line, count_text) = lines.next().ok_or(ReadError::Empty)?;
    let edge_count: usize = match count_text.parse() {
        Ok(n) if n > 0 => n,
        _ => {
            return Err(ReadError::BadEdgeCount {
                line: count_line,
                found: count_text.into(),
            })
        }
    };
    let mut edges: Vec<EdgeLine> = Vec::new();
    for (line, content) in lines {
        if edges.len() == edge_count {
            return Err(ReadError::ExtraLine {
                line,
                expected: edge_count,
            });
        }
        let mut rest = content;
        if let Some((label, after)) = content.split_once(':') {
            let found: usize = label.trim().parse().map_err(|_| ReadError::BadNumber {
                line,
                field: "label",
                found: label.trim().into(),
            })?;
            if found != edges.len() + 1 {
                return Err(ReadError::WrongLabel {
                    line,
                    found,
                    expected: edges.len() + 1,
                });
            }
            rest = after;
        }
        let tokens: Vec<&str> = rest.split_whitespace().collect();
        if tokens.len() != 9 {
            return Err(ReadError::FieldCount {
                line,
                found: tokens.len(),
            });
        }
        let mut fields = [0usize; 9];
        for (i, token) in tokens.iter().enumerate() {
            fields[i] = token.parse().map_err(|_| ReadError::BadNumber {
                line,
                field: FIELDS[i],
                found: (*token).into(),
            })?;
        }
        edges.push(EdgeLine { line, fields });
    }
    if edges.len() < edge_count {
        return Err(ReadError::MissingEdges {
            expected: edge_count,
            found: edges.len(),
        });
    }
    build(&edges)
}

fn build(edges: &[EdgeLine]) -> Result<Embedding, ReadError> {
    let mut vertex_count = 0;
    for edge in edges {
        for (&vertex, &field) in edge.fields[..2].iter().zip(&FIELDS) {
            if vertex == 0 {
                return Err(ReadError::VertexZero {
                    line: edge.line,
                    field,
                });
            }
            // Without isolated vertices there are at most two per edge; larger numbers would
            // also make the reader allocate for vertices that cannot exist.
            if vertex > 2 * edges.len() {
                let (line, limit) = (edge.line, 2 * edges.len());
                return Err(ReadError::VertexOutOfRange {
                    line,
                    field,
                    vertex,
                    limit,
                });
            }
            vertex_count = vertex_count.max(vertex);
        }
    }
    let ends: Vec<(usize, usize)> = edges
        .iter()
        .map(|e| (e.fields[0] - 1, e.fields[1] - 1))
        .collect();
    let mut has_edge = vec![false; vertex_count];
    for &(a, b) in &ends {
        has_edge[a] = true;
        has_edge[b] = true;
    }
    if let Some(v) = has_edge.iter().position(|&h| !h) {
        return Err(ReadError::IsolatedVertex {
            vertex: v + 1,
            vertex_count,
        });
    }
    // The dart of a neighbour edge at `vertex`, checked.
    let dart_at = |line: usize, field: &'static str, number: usize, vertex: usize| {
        if number == 0 || number > edges.len() {
            return Err(ReadError::NoSuchEdge {
                line,
                field,
                edge: number,
            });
        }
        let (a, b) = ends[number - 1];
        if a == b {
            return Err(ReadError::Loop {
                line,
                field,
                edge: number,
            });
        }
        if a == vertex {
            Ok(2 * (number - 1))
        } else if b == vertex {
            Ok(2 * (number - 1) + 1)
        } else {
            Err(ReadError::NotIncident {
                line,
                field,
                edge: number,
                vertex: vertex + 1,
            })
        }
    };
    let dart_count = 2 * edges.len();
    let mut next_ccw = vec![0; dart_count];
    let mut next_cw = vec![0; dart_count];
    for (e, edge) in edges.iter().enumerate() {
        if ends[e].0 == ends[e].1 {
            return Err(ReadError::Loop {
                line: edge.line,
                field: "v2",
                edge: e + 1,
            });
        }
        for k in 0..2 {
            let vertex = if k == 0 { ends[e].0 } else { ends[e].1 };
            next_ccw[2 * e + k] = dart_at(edge.line, FIELDS[2 + k], edge.fields[2 + k], vertex)?;
            next_cw[2 * e + k] = dart_at(edge.line, FIELDS[4 + k], edge.fields[4 + k], vertex)?;
        }
    }
    // Left neighbours first, so that an error points at the line whose `l` field is wrong.
    for (pointers, inverse, field_offset) in [(&next_ccw, &next_cw, 2), (&next_cw, &next_ccw, 4)] {
        for d in 0..dart_count {
            if inverse[pointers[d]] != d {
                let vertex = if d % 2 == 0 {
                    ends[d / 2].0
                } else {
                    ends[d / 2].1
                } + 1;
                let (line, field) = (edges[d / 2].line, FIELDS[field_offset + d % 2]);
                return Err(ReadError::LeftRightMismatch {
                    line,
                    field,
                    vertex,
                });
            }
        }
    }
    let mut rotations: Vec<Vec<Dart>> = vec![Vec::new(); vertex_count];
    let mut degree = vec![0usize; vertex_count];
    for d in 0..dart_count {
        degree[if d % 2 == 0 {
            ends[d / 2].0
        } else {
            ends[d / 2].1
        }] += 1;
    }
    for d in 0..dart_count {
        let vertex = if d % 2 == 0 {
            ends[d / 2].0
        } else {
            ends[d / 2].1
        };
        if !rotations[vertex].is_empty() {
            continue;
        }
        let mut dart = d;
        loop {
            rotations[vertex].push(dart);
            dart = next_ccw[dart];
            if dart == d || rotations[vertex].len() > degree[vertex] {
                break;
            }
        }
        if rotations[vertex].len() != degree[vertex] {
            return Err(ReadError::NotOneCycle { vertex: vertex + 1 });
        }
    }
    let graph = PlaneGraph::from_rotations(vertex_count, &ends, &rotations)
        .expect("rotations checked above");
    // File face f_k(e) is on the right of the dart leaving end k, i.e. left of its twin.
    let faces = graph.faces();
    let mut traced_of_id = std::collections::HashMap::new();
    let mut id_of_traced = vec![usize::MAX; faces.count()];
    for (e, edge) in edges.iter().enumerate() {
        for k in 0..2 {
            let id = edge.fields[6 + k];
            let traced = faces.right(2 * e + k);
            let known = *traced_of_id.entry(id).or_insert(traced);
            if known != traced || (id_of_traced[traced] != usize::MAX && id_of_traced[traced] != id)
            {
                return Err(ReadError::FaceMismatch {
                    line: edge.line,
                    field: FIELDS[6 + k],
                    face: id,
                });
            }
            id_of_traced[traced] = id;
        }
    }
    let outer = *traced_of_id.get(&0).ok_or(ReadError::NoOuterFace)?;
    let embedding = Embedding::new(graph, outer)?;
    for (e, edge) in edges.iter().enumerate() {
        let computed = embedding.edge_rank(e);
        if edge.fields[8] != computed as usize {
            return Err(ReadError::RankMismatch {
                line: edge.line,
                found: edge.fields[8],
                computed,
            });
        }
    }
    Ok(embedding)
}

/// Writes the format: faces are numbered 0 (outer) and then 1, 2, … in order of first use.
pub fn write(embedding: &Embedding) -> Result<String, WriteError> {
    let graph = embedding.graph();
    let faces = embedding.faces();
    let mut id = vec![usize::MAX; faces.count()];
    id[embedding.outer_face()] = 0;
    let mut next_id = 1;
    let mut out = format!("{}\n", graph.edge_count());
    for e in 0..graph.edge_count() {
        let (a, b) = graph.ends(e);
        if a == b {
            return Err(WriteError::Loop { edge: e + 1 });
        }
        let mut face_ids = [0; 2];
        for (k, slot) in face_ids.iter_mut().enumerate() {
            let face = faces.right(2 * e + k);
            if id[face] == usize::MAX {
                id[face] = next_id;
                next_id += 1;
            }
            *slot = id[face];
        }
        let n = |d: Dart| d / 2 + 1;
        out += &format!(
            "{} {} {} {} {} {} {} {} {}\n",
            a + 1,
            b + 1,
            n(graph.next_ccw(2 * e)),
            n(graph.next_ccw(2 * e + 1)),
            n(graph.next_cw(2 * e)),
            n(graph.next_cw(2 * e + 1)),
            face_ids[0],
            face_ids[1],
            embedding.edge_rank(e)
        );
    }
    Ok(out)
}
