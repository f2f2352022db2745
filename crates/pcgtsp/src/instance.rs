//! The PCGTSP instance every discrete solver works on.

/// A PCGTSP instance, 0-based throughout (files are 1-based).
///
/// Clusters partition the nodes; cluster `depot` holds the start. A tour is closed: it starts at a
/// node of the depot cluster, visits exactly one node of every cluster, and returns to its start.
/// `precedence` holds pairs `(a, b)`: cluster `a` must be visited before cluster `b` (the depot
/// is first and never constrained by this).
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// The instance name (`NAME` line).
    pub name: String,
    /// Number of nodes.
    pub node_count: usize,
    /// Row-major `node_count × node_count` arc costs; `f64::INFINITY` marks a forbidden arc.
    /// Node weights of PCGTSPLIB files are folded into the cost of every arc entering the node.
    pub cost: Vec<f64>,
    /// The node lists of the clusters.
    pub clusters: Vec<Vec<usize>>,
    /// The cluster of every node.
    pub node_cluster: Vec<usize>,
    /// Precedence pairs `(a, b)`: cluster `a` before cluster `b`, as stored in the file.
    pub precedence: Vec<(usize, usize)>,
    /// The start (depot) cluster.
    pub depot: usize,
}

impl Instance {
    /// The cost of the arc `from → to` (`f64::INFINITY` when forbidden).
    #[inline]
    pub fn arc_cost(&self, from: usize, to: usize) -> f64 {
        self.cost[from * self.node_count + to]
    }
}
