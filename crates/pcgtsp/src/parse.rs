//! Readers and writers for the PCGTSP text formats.
//!
//! Two instance dialects share one reader ([`Instance::parse`]):
//! - **PCGLNS** (`TYPE : PCGLNS`): `DIMENSION`, `GTSP_SETS`, an integer `EDGE_WEIGHT_SECTION`
//!   (`-1` = forbidden), `GTSP_SET_SECTION`, `GTSP_SET_ORDERING`, `START_GROUP_SECTION`.
//! - **PCGTSPLIB** (`TYPE: PCGTSP`): `GROUPS` instead of `GTSP_SETS`, `NODE_GROUP_SECTION`,
//!   real-valued weights and an optional `NODE_WEIGHT_SECTION` whose weights are folded into
//!   every arc entering the node. Such files may carry no ordering section at all (then the
//!   precedence is encoded only through forbidden arcs and `precedence` stays empty).
//!
//! The reader never trusts the header: memory grows only with the data actually present, every
//! index is range-checked, and every failure is a [`ParseError`] carrying the 1-based line.

use crate::instance::Instance;
use std::fmt::Write as _;

/// Largest `DIMENSION` the reader accepts. A full matrix of this many nodes already needs
/// 800 MB as `f64`; larger headers are hostile or mistaken.
pub const MAX_NODES: usize = 10_000;

/// Why an instance or result file could not be read. `line` is always 1-based.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParseError {
    /// The text contains no instance at all.
    #[error("empty input: no header lines found")]
    Empty,
    /// A header line that is not `KEY : value`, or a keyword this reader does not know.
    #[error("line {line}: unknown keyword `{keyword}`")]
    UnknownKeyword {
        /// Line of the keyword.
        line: usize,
        /// The keyword as written.
        keyword: String,
    },
    /// `TYPE`, `EDGE_WEIGHT_TYPE` or `EDGE_WEIGHT_FORMAT` names a variant this reader cannot handle.
    #[error("line {line}: unsupported {key} `{value}`")]
    Unsupported {
        /// Line of the header.
        line: usize,
        /// The header key.
        key: &'static str,
        /// Its value.
        value: String,
    },
    /// A required header or section never appeared (or appeared after the section needing it).
    #[error("line {line}: missing `{what}`")]
    Missing {
        /// Line where it was needed (the last line for end-of-file checks).
        line: usize,
        /// The missing header or section.
        what: &'static str,
    },
    /// A header or section appears twice.
    #[error("line {line}: `{what}` appears twice")]
    Duplicate {
        /// Line of the second occurrence.
        line: usize,
        /// The repeated header or section.
        what: &'static str,
    },
    /// A token that should be a number is not one (or is NaN / infinite).
    #[error("line {line}: `{token}` is not a valid {expected}")]
    InvalidNumber {
        /// Line of the token.
        line: usize,
        /// The token as written.
        token: String,
        /// What was expected there.
        expected: &'static str,
    },
    /// `DIMENSION` is zero or above [`MAX_NODES`].
    #[error("line {line}: DIMENSION {value} is out of range 1..={max}")]
    DimensionOutOfRange {
        /// Line of the header.
        line: usize,
        /// The declared value.
        value: u64,
        /// The largest accepted value.
        max: usize,
    },
    /// The cluster count is zero or exceeds the node count.
    #[error("line {line}: {value} clusters for {nodes} nodes")]
    ClusterCountOutOfRange {
        /// Line of the header.
        line: usize,
        /// The declared cluster count.
        value: u64,
        /// The node count.
        nodes: usize,
    },
    /// A weight other than `-1` (forbidden) is negative.
    #[error("line {line}: negative weight {value} (only -1 = forbidden is allowed)")]
    NegativeWeight {
        /// Line of the weight.
        line: usize,
        /// The weight.
        value: f64,
    },
    /// A numeric section holds fewer values than declared (truncated file).
    #[error("line {line}: {section} has {found} values, expected {expected}")]
    Truncated {
        /// Line where the section ended.
        line: usize,
        /// The section.
        section: &'static str,
        /// Values found.
        found: usize,
        /// Values expected.
        expected: usize,
    },
    /// A numeric section holds more values than declared.
    #[error("line {line}: {section} has more than {expected} values")]
    TooManyValues {
        /// Line of the first extra value.
        line: usize,
        /// The section.
        section: &'static str,
        /// Values expected.
        expected: usize,
    },
    /// A list in a set or ordering section is not terminated by `-1`.
    #[error("line {line}: list in {section} not terminated by -1")]
    Unterminated {
        /// Line where the section ended.
        line: usize,
        /// The section.
        section: &'static str,
    },
    /// A node index outside `1..=DIMENSION`.
    #[error("line {line}: node {node} is out of range 1..={max}")]
    NodeOutOfRange {
        /// Line of the index.
        line: usize,
        /// The index as written (1-based).
        node: i64,
        /// The node count.
        max: usize,
    },
    /// A cluster index outside `1..=GTSP_SETS`.
    #[error("line {line}: cluster {cluster} is out of range 1..={max}")]
    ClusterOutOfRange {
        /// Line of the index.
        line: usize,
        /// The index as written (1-based).
        cluster: i64,
        /// The cluster count.
        max: usize,
    },
    /// The same cluster is defined twice.
    #[error("line {line}: cluster {cluster} is defined twice")]
    ClusterDefinedTwice {
        /// Line of the second definition.
        line: usize,
        /// The cluster (1-based).
        cluster: usize,
    },
    /// A declared cluster has no definition line, or an empty node list.
    #[error("line {line}: cluster {cluster} has no nodes")]
    EmptyCluster {
        /// Line of the definition (or end of the section).
        line: usize,
        /// The cluster (1-based).
        cluster: usize,
    },
    /// A node is listed in two clusters (or twice in one).
    #[error("line {line}: node {node} is in cluster {first} and cluster {second}")]
    NodeInTwoClusters {
        /// Line of the second listing.
        line: usize,
        /// The node (1-based).
        node: usize,
        /// The first cluster (1-based).
        first: usize,
        /// The second cluster (1-based).
        second: usize,
    },
    /// A node belongs to no cluster.
    #[error("line {line}: node {node} is in no cluster")]
    NodeInNoCluster {
        /// Last line of the cluster section.
        line: usize,
        /// The node (1-based).
        node: usize,
    },
    /// A cluster is required to precede itself.
    #[error("line {line}: cluster {cluster} must precede itself")]
    SelfPrecedence {
        /// Line of the pair.
        line: usize,
        /// The cluster (1-based).
        cluster: usize,
    },
    /// Some cluster is required to come before the depot cluster, which is always first.
    #[error("line {line}: cluster {before} must precede the depot cluster {depot}")]
    PrecedenceBeforeDepot {
        /// Line of the pair.
        line: usize,
        /// The cluster that would precede the depot (1-based).
        before: usize,
        /// The depot cluster (1-based).
        depot: usize,
    },
    /// The precedence relation contains a cycle, so no tour exists.
    #[error("line {line}: cyclic precedence {}", display_cycle(.cycle))]
    CyclicPrecedence {
        /// Line of one pair on the cycle.
        line: usize,
        /// The clusters of the cycle (1-based), first repeated at the end.
        cycle: Vec<usize>,
    },
    /// The start group section does not hold exactly one cluster.
    #[error("line {line}: START_GROUP_SECTION must hold exactly one cluster")]
    BadStartGroup {
        /// Line of the section.
        line: usize,
    },
}

fn display_cycle(cycle: &[usize]) -> String {
    cycle
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(" -> ")
}

/// The sections of an instance file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Section {
    None,
    EdgeWeights,
    NodeWeights,
    Sets,
    Ordering,
    StartGroup,
    Eof,
}

impl Section {
    fn name(self) -> &'static str {
        match self {
            Section::None => "header",
            Section::EdgeWeights => "EDGE_WEIGHT_SECTION",
            Section::NodeWeights => "NODE_WEIGHT_SECTION",
            Section::Sets => "GTSP_SET_SECTION",
            Section::Ordering => "GTSP_SET_ORDERING",
            Section::StartGroup => "START_GROUP_SECTION",
            Section::Eof => "EOF",
        }
    }
}

/// One list (`head items… -1`) being read from a set or ordering section.
#[derive(Default)]
struct OpenList {
    head: Option<usize>,
    head_line: usize,
}

struct Reader {
    name: String,
    dimension: Option<usize>,
    cluster_count: Option<usize>,
    weights: Vec<f64>,
    node_weights: Option<Vec<f64>>,
    node_cluster: Vec<usize>,
    clusters: Vec<Option<Vec<usize>>>,
    cluster_line: Vec<usize>,
    precedence: Vec<(usize, usize)>,
    precedence_line: Vec<usize>,
    start_groups: Vec<(usize, usize)>,
    section: Section,
    seen: Vec<Section>,
    open: OpenList,
    last_line: usize,
}

const UNASSIGNED: usize = usize::MAX;

fn parse_int(token: &str, line: usize, expected: &'static str) -> Result<i64, ParseError> {
    token.parse::<i64>().map_err(|_| ParseError::InvalidNumber {
        line,
        token: token.chars().take(40).collect(),
        expected,
    })
}

/// Largest arc or node weight read: a tour of a million arcs then costs at most 1e18, so no
/// sum of weights overflows to ∞ (weights near f64::MAX made every tour cost ∞, and the
/// solvers then "proved" a tour that was not one).
pub const MAX_WEIGHT: f64 = 1e12;

fn parse_weight(token: &str, line: usize) -> Result<f64, ParseError> {
    let value = token
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v <= MAX_WEIGHT)
        .ok_or_else(|| ParseError::InvalidNumber {
            line,
            token: token.chars().take(40).collect(),
            expected: "finite weight of at most 1e12 (or -1 = forbidden)",
        })?;
    if value == -1.0 {
        return Ok(f64::INFINITY);
    }
    if value < 0.0 {
        return Err(ParseError::NegativeWeight { line, value });
    }
    Ok(value)
}

/// A keyword line starts with a letter and is not a number such as `NaN` or `inf`
/// (those are data, rejected later with a precise message).
fn is_keyword_line(trimmed: &str) -> bool {
    let first = trimmed.split_whitespace().next().unwrap_or("");
    first.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && first.parse::<f64>().is_err()
}

impl Reader {
    fn new() -> Self {
        Reader {
            name: String::new(),
            dimension: None,
            cluster_count: None,
            weights: Vec::new(),
            node_weights: None,
            node_cluster: Vec::new(),
            clusters: Vec::new(),
            cluster_line: Vec::new(),
            precedence: Vec::new(),
            precedence_line: Vec::new(),
            start_groups: Vec::new(),
            section: Section::None,
            seen: Vec::new(),
            open: OpenList::default(),
            last_line: 0,
        }
    }

    fn need_dimension(&self, line: usize) -> Result<usize, ParseError> {
        self.dimension.ok_or(ParseError::Missing {
            line,
            what: "DIMENSION",
        })
    }

    fn need_clusters(&self, line: usize) -> Result<usize, ParseError> {
        self.cluster_count.ok_or(ParseError::Missing {
            line,
            what: "GTSP_SETS",
        })
    }

    /// Checks that the section being left is complete.
    fn close_section(&mut self, line: usize) -> Result<(), ParseError> {
        match self.section {
            Section::EdgeWeights => {
                let n = self.need_dimension(line)?;
                if self.weights.len() != n * n {
                    return Err(ParseError::Truncated {
                        line,
                        section: "EDGE_WEIGHT_SECTION",
                        found: self.weights.len(),
                        expected: n * n,
                    });
                }
            }
            Section::NodeWeights => {
                let n = self.need_dimension(line)?;
                let found = self.node_weights.as_ref().map_or(0, Vec::len);
                if found != n {
                    return Err(ParseError::Truncated {
                        line,
                        section: "NODE_WEIGHT_SECTION",
                        found,
                        expected: n,
                    });
                }
            }
            Section::Sets | Section::Ordering => {
                if self.open.head.is_some() {
                    return Err(ParseError::Unterminated {
                        line,
                        section: self.section.name(),
                    });
                }
            }
            Section::StartGroup => {
                if self.start_groups.len() != 1 {
                    return Err(ParseError::BadStartGroup { line });
                }
            }
            Section::None | Section::Eof => {}
        }
        Ok(())
    }

    fn enter_section(&mut self, section: Section, line: usize) -> Result<(), ParseError> {
        self.close_section(line)?;
        if self.seen.contains(&section) {
            return Err(ParseError::Duplicate {
                line,
                what: section.name(),
            });
        }
        self.seen.push(section);
        match section {
            Section::EdgeWeights | Section::NodeWeights => {
                self.need_dimension(line)?;
            }
            Section::Sets => {
                let n = self.need_dimension(line)?;
                let m = self.need_clusters(line)?;
                self.node_cluster = vec![UNASSIGNED; n];
                self.clusters = vec![None; m];
                self.cluster_line = vec![0; m];
            }
            Section::Ordering | Section::StartGroup => {
                self.need_clusters(line)?;
            }
            Section::None | Section::Eof => {}
        }
        if section == Section::NodeWeights {
            self.node_weights = Some(Vec::new());
        }
        self.section = section;
        Ok(())
    }

    fn header(&mut self, key: &str, value: &str, line: usize) -> Result<(), ParseError> {
        let upper = key.to_ascii_uppercase();
        match upper.as_str() {
            "NAME" => self.name = value.to_string(),
            "COMMENT" => {}
            "TYPE" => accept_only(
                line,
                "TYPE",
                value,
                &["PCGLNS", "PCGTSP", "GTSP", "PCGTSPLIB"],
            )?,
            "EDGE_WEIGHT_TYPE" => accept_only(line, "EDGE_WEIGHT_TYPE", value, &["EXPLICIT"])?,
            "EDGE_WEIGHT_FORMAT" => {
                accept_only(line, "EDGE_WEIGHT_FORMAT", value, &["FULL_MATRIX"])?
            }
            "DIMENSION" => {
                if self.dimension.is_some() {
                    return Err(ParseError::Duplicate {
                        line,
                        what: "DIMENSION",
                    });
                }
                let v = parse_count(line, value, "node count")?;
                if v == 0 || v > MAX_NODES as u64 {
                    return Err(ParseError::DimensionOutOfRange {
                        line,
                        value: v,
                        max: MAX_NODES,
                    });
                }
                self.dimension = Some(v as usize);
            }
            "GTSP_SETS" | "GROUPS" => {
                if self.cluster_count.is_some() {
                    return Err(ParseError::Duplicate {
                        line,
                        what: "GTSP_SETS",
                    });
                }
                let n = self.need_dimension(line)?;
                let v = parse_count(line, value, "cluster count")?;
                if v == 0 || v > n as u64 {
                    return Err(ParseError::ClusterCountOutOfRange {
                        line,
                        value: v,
                        nodes: n,
                    });
                }
                self.cluster_count = Some(v as usize);
            }
            _ => {
                return Err(ParseError::UnknownKeyword {
                    line,
                    keyword: key.chars().take(60).collect(),
                })
            }
        }
        Ok(())
    }

    fn keyword_line(&mut self, trimmed: &str, line: usize) -> Result<(), ParseError> {
        let (key, value) = match trimmed.find(':') {
            Some(pos) => (trimmed[..pos].trim(), trimmed[pos + 1..].trim()),
            None => (trimmed, ""),
        };
        let section = match key.to_ascii_uppercase().as_str() {
            "EDGE_WEIGHT_SECTION" => Some(Section::EdgeWeights),
            "NODE_WEIGHT_SECTION" => Some(Section::NodeWeights),
            "GTSP_SET_SECTION" | "NODE_GROUP_SECTION" | "GROUP_SECTION" => Some(Section::Sets),
            "GTSP_SET_ORDERING" | "GROUP_ORDERING_SECTION" | "GROUP_ORDER_SECTION" => {
                Some(Section::Ordering)
            }
            "START_GROUP_SECTION" => Some(Section::StartGroup),
            "EOF" => Some(Section::Eof),
            _ => None,
        };
        match section {
            Some(section) => {
                self.enter_section(section, line)?;
                // Data may follow the keyword on the same line (`START_GROUP_SECTION : 1`).
                for token in value.split_whitespace() {
                    self.data_token(token, line)?;
                }
                Ok(())
            }
            None => {
                if self.section != Section::None {
                    // Headers after the data sections are not part of either format.
                    return Err(ParseError::UnknownKeyword {
                        line,
                        keyword: key.chars().take(60).collect(),
                    });
                }
                self.header(key, value, line)
            }
        }
    }

    fn data_token(&mut self, token: &str, line: usize) -> Result<(), ParseError> {
        match self.section {
            Section::None | Section::Eof => Err(ParseError::UnknownKeyword {
                line,
                keyword: token.chars().take(60).collect(),
            }),
            Section::EdgeWeights => {
                let n = self.need_dimension(line)?;
                if self.weights.len() >= n * n {
                    return Err(ParseError::TooManyValues {
                        line,
                        section: "EDGE_WEIGHT_SECTION",
                        expected: n * n,
                    });
                }
                self.weights.push(parse_weight(token, line)?);
                Ok(())
            }
            Section::NodeWeights => {
                let n = self.need_dimension(line)?;
                let weights = self.node_weights.get_or_insert_with(Vec::new);
                if weights.len() >= n {
                    return Err(ParseError::TooManyValues {
                        line,
                        section: "NODE_WEIGHT_SECTION",
                        expected: n,
                    });
                }
                let w = parse_weight(token, line)?;
                if w.is_infinite() {
                    return Err(ParseError::NegativeWeight { line, value: -1.0 });
                }
                weights.push(w);
                Ok(())
            }
            Section::Sets => self.set_token(token, line),
            Section::Ordering => self.ordering_token(token, line),
            Section::StartGroup => {
                let m = self.need_clusters(line)?;
                let v = parse_int(token, line, "cluster index")?;
                if v < 1 || v > m as i64 {
                    return Err(ParseError::ClusterOutOfRange {
                        line,
                        cluster: v,
                        max: m,
                    });
                }
                if !self.start_groups.is_empty() {
                    return Err(ParseError::BadStartGroup { line });
                }
                self.start_groups.push((v as usize - 1, line));
                Ok(())
            }
        }
    }

    fn cluster_index(&self, token: &str, line: usize) -> Result<usize, ParseError> {
        let m = self.clusters.len().max(self.cluster_count.unwrap_or(0));
        let v = parse_int(token, line, "cluster index")?;
        if v < 1 || v > m as i64 {
            return Err(ParseError::ClusterOutOfRange {
                line,
                cluster: v,
                max: m,
            });
        }
        Ok(v as usize - 1)
    }

    fn set_token(&mut self, token: &str, line: usize) -> Result<(), ParseError> {
        match self.open.head {
            None => {
                let c = self.cluster_index(token, line)?;
                if self.clusters[c].is_some() {
                    return Err(ParseError::ClusterDefinedTwice {
                        line,
                        cluster: c + 1,
                    });
                }
                self.clusters[c] = Some(Vec::new());
                self.cluster_line[c] = line;
                self.open = OpenList {
                    head: Some(c),
                    head_line: line,
                };
            }
            Some(c) => {
                let v = parse_int(token, line, "node index")?;
                if v == -1 {
                    if self.clusters[c].as_ref().is_none_or(Vec::is_empty) {
                        return Err(ParseError::EmptyCluster {
                            line,
                            cluster: c + 1,
                        });
                    }
                    self.open = OpenList::default();
                    return Ok(());
                }
                let n = self.node_cluster.len();
                if v < 1 || v > n as i64 {
                    return Err(ParseError::NodeOutOfRange {
                        line,
                        node: v,
                        max: n,
                    });
                }
                let node = v as usize - 1;
                let first = self.node_cluster[node];
                if first != UNASSIGNED {
                    return Err(ParseError::NodeInTwoClusters {
                        line,
                        node: node + 1,
                        first: first + 1,
                        second: c + 1,
                    });
                }
                self.node_cluster[node] = c;
                if let Some(list) = self.clusters[c].as_mut() {
                    list.push(node);
                }
            }
        }
        Ok(())
    }

    fn ordering_token(&mut self, token: &str, line: usize) -> Result<(), ParseError> {
        match self.open.head {
            None => {
                let c = self.cluster_index(token, line)?;
                self.open = OpenList {
                    head: Some(c),
                    head_line: line,
                };
            }
            Some(a) => {
                let v = parse_int(token, line, "cluster index")?;
                if v == -1 {
                    self.open = OpenList::default();
                    return Ok(());
                }
                let b = self.cluster_index(token, line)?;
                if a == b {
                    return Err(ParseError::SelfPrecedence {
                        line,
                        cluster: a + 1,
                    });
                }
                self.precedence.push((a, b));
                self.precedence_line.push(line.max(self.open.head_line));
            }
        }
        Ok(())
    }

    fn finish(mut self) -> Result<Instance, ParseError> {
        let line = self.last_line.max(1);
        if self.seen.is_empty() && self.dimension.is_none() {
            return Err(ParseError::Empty);
        }
        self.close_section(line)?;
        let n = self.need_dimension(line)?;
        let m = self.need_clusters(line)?;
        if !self.seen.contains(&Section::EdgeWeights) {
            return Err(ParseError::Missing {
                line,
                what: "EDGE_WEIGHT_SECTION",
            });
        }
        if !self.seen.contains(&Section::Sets) {
            return Err(ParseError::Missing {
                line,
                what: "GTSP_SET_SECTION",
            });
        }
        let mut clusters = Vec::with_capacity(m);
        for (c, list) in self.clusters.into_iter().enumerate() {
            match list {
                Some(list) if !list.is_empty() => clusters.push(list),
                _ => {
                    return Err(ParseError::EmptyCluster {
                        line: self.cluster_line[c].max(line),
                        cluster: c + 1,
                    })
                }
            }
        }
        if let Some(node) = self.node_cluster.iter().position(|&c| c == UNASSIGNED) {
            return Err(ParseError::NodeInNoCluster {
                line,
                node: node + 1,
            });
        }
        let depot = self.start_groups.first().map_or(0, |&(c, _)| c);
        for (&(a, b), &pl) in self.precedence.iter().zip(&self.precedence_line) {
            if b == depot {
                return Err(ParseError::PrecedenceBeforeDepot {
                    line: pl,
                    before: a + 1,
                    depot: depot + 1,
                });
            }
        }
        if let Some((cycle, cycle_line)) = find_cycle(m, &self.precedence, &self.precedence_line) {
            return Err(ParseError::CyclicPrecedence {
                line: cycle_line,
                cycle,
            });
        }
        let mut cost = self.weights;
        if let Some(node_weights) = &self.node_weights {
            for row in cost.chunks_mut(n) {
                for (entry, w) in row.iter_mut().zip(node_weights) {
                    *entry += w;
                }
            }
        }
        Ok(Instance {
            name: self.name,
            node_count: n,
            cost,
            clusters,
            node_cluster: self.node_cluster,
            precedence: self.precedence,
            depot,
        })
    }
}

/// Finds a cycle in the precedence digraph (iterative DFS, no recursion on hostile input).
/// Returns the cycle's clusters (1-based, closed) and the line of one of its pairs.
fn find_cycle(m: usize, pairs: &[(usize, usize)], lines: &[usize]) -> Option<(Vec<usize>, usize)> {
    let mut adjacency: Vec<Vec<(usize, usize)>> = vec![Vec::new(); m];
    for (&(a, b), &line) in pairs.iter().zip(lines) {
        adjacency[a].push((b, line));
    }
    // 0 = unvisited, 1 = on the stack, 2 = done.
    let mut state = vec![0u8; m];
    let mut parent = vec![(usize::MAX, 0usize); m];
    for root in 0..m {
        if state[root] != 0 {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        state[root] = 1;
        while let Some(&mut (v, ref mut next)) = stack.last_mut() {
            if *next < adjacency[v].len() {
                let (w, line) = adjacency[v][*next];
                *next += 1;
                match state[w] {
                    0 => {
                        state[w] = 1;
                        parent[w] = (v, line);
                        stack.push((w, 0));
                    }
                    1 => {
                        let mut cycle = vec![w + 1];
                        let mut u = v;
                        while u != w {
                            cycle.push(u + 1);
                            u = parent[u].0;
                        }
                        cycle.push(w + 1);
                        cycle.reverse();
                        return Some((cycle, line));
                    }
                    _ => {}
                }
            } else {
                state[v] = 2;
                stack.pop();
            }
        }
    }
    None
}

impl Instance {
    /// Reads an instance in the PCGLNS or the PCGTSPLIB text format (detected from the
    /// keywords). Node weights are folded into the arcs entering each node.
    ///
    /// Never panics, and allocates memory proportional to the input text only.
    pub fn parse(text: &str) -> Result<Instance, ParseError> {
        let mut reader = Reader::new();
        for (index, raw) in text.lines().enumerate() {
            let line = index + 1;
            reader.last_line = line;
            let trimmed = raw.trim();
            if trimmed.is_empty() {
                continue;
            }
            if reader.section == Section::Eof {
                // Everything after EOF is ignored, as the PCGLNS reader does.
                break;
            }
            if is_keyword_line(trimmed) {
                reader.keyword_line(trimmed, line)?;
            } else {
                for token in trimmed.split_whitespace() {
                    reader.data_token(token, line)?;
                }
            }
        }
        reader.finish()
    }

    /// Writes the instance in the PCGLNS text format. Forbidden arcs become `-1`; integral
    /// weights are written as integers, others in Rust's shortest round-trip notation, so
    /// `Instance::parse(&i.to_pcglns()) == Ok(i)`.
    pub fn to_pcglns(&self) -> String {
        let n = self.node_count;
        let mut out = String::with_capacity(n * n * 4 + 1024);
        let _ = writeln!(out, "NAME : {}", self.name);
        let _ = writeln!(out, "TYPE : PCGLNS");
        let _ = writeln!(out, "COMMENT : written by cutroute-pcgtsp");
        let _ = writeln!(out, "DIMENSION : {n}");
        let _ = writeln!(out, "GTSP_SETS : {}", self.clusters.len());
        let _ = writeln!(out, "EDGE_WEIGHT_TYPE : EXPLICIT");
        let _ = writeln!(out, "EDGE_WEIGHT_FORMAT : FULL_MATRIX");
        let _ = writeln!(out, "EDGE_WEIGHT_SECTION");
        for row in self.cost.chunks(n.max(1)) {
            let mut first = true;
            for &w in row {
                if !first {
                    out.push(' ');
                }
                first = false;
                if w.is_infinite() {
                    out.push_str("-1");
                } else if w.fract() == 0.0 && w.abs() < 1e15 {
                    let _ = write!(out, "{}", w as i64);
                } else {
                    let _ = write!(out, "{w}");
                }
            }
            out.push('\n');
        }
        let _ = writeln!(out, "GTSP_SET_SECTION");
        for (c, nodes) in self.clusters.iter().enumerate() {
            let _ = write!(out, "{}", c + 1);
            for &v in nodes {
                let _ = write!(out, " {}", v + 1);
            }
            let _ = writeln!(out, " -1");
        }
        let _ = writeln!(out, "GTSP_SET_ORDERING");
        // Consecutive pairs with the same head share a line, so the pair order round-trips.
        let mut i = 0;
        while i < self.precedence.len() {
            let head = self.precedence[i].0;
            let _ = write!(out, "{}", head + 1);
            while i < self.precedence.len() && self.precedence[i].0 == head {
                let _ = write!(out, " {}", self.precedence[i].1 + 1);
                i += 1;
            }
            let _ = writeln!(out, " -1");
        }
        let _ = writeln!(out, "START_GROUP_SECTION");
        let _ = writeln!(out, "{}", self.depot + 1);
        let _ = writeln!(out, "EOF");
        out
    }
}

/// The summary of a PCGLNS run (`*.pcglns.result.txt`).
#[derive(Clone, Debug, PartialEq)]
pub struct PcglnsResult {
    /// `Instance Name`, if present.
    pub instance_name: Option<String>,
    /// The tour cost reported in the summary (`Cost : …`).
    pub cost: f64,
    /// `Tour Ordering`, converted to 0-based node indices.
    pub tour: Vec<usize>,
    /// `Total Time` in seconds, if present.
    pub total_time_s: Option<f64>,
}

impl PcglnsResult {
    /// Reads a PCGLNS result file. Only `Cost` and `Tour Ordering` are required; progress
    /// lines (`Cost = …`) are ignored.
    pub fn parse(text: &str) -> Result<PcglnsResult, ParseError> {
        let mut instance_name = None;
        let mut cost = None;
        let mut tour = None;
        let mut total_time_s = None;
        let mut last_line = 0;
        for (index, raw) in text.lines().enumerate() {
            let line = index + 1;
            last_line = line;
            let Some(pos) = raw.find(':') else { continue };
            let key = raw[..pos].trim();
            let value = raw[pos + 1..].trim();
            match key {
                "Instance Name" => instance_name = Some(value.to_string()),
                "Cost" | "Tour Cost" => {
                    let v = value
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite() && *v >= 0.0);
                    cost = Some(v.ok_or_else(|| ParseError::InvalidNumber {
                        line,
                        token: value.chars().take(40).collect(),
                        expected: "tour cost",
                    })?);
                }
                "Total Time" => {
                    total_time_s = value.trim_end_matches("sec").trim().parse::<f64>().ok();
                }
                "Tour Ordering" => {
                    let inner = value
                        .strip_prefix('[')
                        .and_then(|v| v.strip_suffix(']'))
                        .ok_or_else(|| ParseError::InvalidNumber {
                            line,
                            token: value.chars().take(40).collect(),
                            expected: "bracketed node list",
                        })?;
                    let mut nodes = Vec::new();
                    for token in inner.split(',').map(str::trim).filter(|t| !t.is_empty()) {
                        let v = parse_int(token, line, "node index")?;
                        if v < 1 || v > MAX_NODES as i64 {
                            return Err(ParseError::NodeOutOfRange {
                                line,
                                node: v,
                                max: MAX_NODES,
                            });
                        }
                        nodes.push(v as usize - 1);
                    }
                    tour = Some(nodes);
                }
                _ => {}
            }
        }
        let line = last_line.max(1);
        Ok(PcglnsResult {
            instance_name,
            cost: cost.ok_or(ParseError::Missing { line, what: "Cost" })?,
            tour: tour.ok_or(ParseError::Missing {
                line,
                what: "Tour Ordering",
            })?,
            total_time_s,
        })
    }
}

/// A header whose value must be one of `allowed` (case-insensitive): anything else is a variant
/// of the format this reader does not support.
fn accept_only(
    line: usize,
    key: &'static str,
    value: &str,
    allowed: &[&str],
) -> Result<(), ParseError> {
    if allowed.iter().any(|a| value.eq_ignore_ascii_case(a)) {
        Ok(())
    } else {
        Err(ParseError::Unsupported {
            line,
            key,
            value: value.into(),
        })
    }
}

/// A header count (`DIMENSION`, `GTSP_SETS`): a non-negative integer, else a located error.
fn parse_count(line: usize, value: &str, expected: &'static str) -> Result<u64, ParseError> {
    value.parse::<u64>().map_err(|_| ParseError::InvalidNumber {
        line,
        token: value.chars().take(40).collect(),
        expected,
    })
}
