//! The model every bound and the exact search work on: an [`Instance`] prepared for bounding
//! with the depot fixed to one start node — the precedence order, the cheapest arcs between
//! nodes and clusters, the admissible cluster arcs and the cluster graphs H1 and H2.

use crate::instance::Instance;
use crate::order::{OrderError, PrecedenceOrder};

const INF: f64 = f64::INFINITY;

/// The instance prepared for bounding, with the depot restricted to one start node.
#[derive(Clone, Debug)]
pub(crate) struct Model {
    pub n: usize,
    pub m: usize,
    pub depot: usize,
    pub start: usize,
    /// Row-major arc costs (`INF` = forbidden).
    pub cost: Vec<f64>,
    /// Nodes of every cluster; the depot cluster holds only `start`.
    pub cluster_nodes: Vec<Vec<usize>>,
    pub node_cluster: Vec<usize>,
    pub order: PrecedenceOrder,
    /// `n × m`: cheapest arc from node `x` into cluster `B` (into `start` for the depot).
    pub node_to_cluster: Vec<f64>,
    /// `m × m`: may an arc `A → B` appear in a feasible tour (relaxed precedence)?
    pub admissible: Vec<bool>,
    /// `m × m`: H1 costs, `INF` where not admissible or on the diagonal.
    pub w1: Vec<f64>,
    /// `m × m`: H2 costs through an intermediate node of a third, non-depot cluster.
    pub w2: Vec<f64>,
    /// All finite costs are integers, so tour costs are integers too.
    pub integral: bool,
    /// Per cluster `V`: an `n × |V|` matrix of the arcs from every node into `V`'s nodes, so the
    /// DP's inner loop reads contiguous memory.
    pub into_cluster: Vec<Vec<f64>>,
}

impl Model {
    pub fn new(instance: &Instance, start: usize) -> Result<Model, OrderError> {
        let order = PrecedenceOrder::new(instance)?;
        let n = instance.node_count;
        let m = instance.clusters.len();
        let depot = instance.depot;
        let mut cluster_nodes = instance.clusters.clone();
        cluster_nodes[depot] = vec![start];
        let cost = instance.cost.clone();
        let integral = cost.iter().all(|c| !c.is_finite() || c.fract() == 0.0);
        let mut admissible = vec![false; m * m];
        for a in 0..m {
            for b in 0..m {
                admissible[a * m + b] = if a == b {
                    false
                } else if b == depot {
                    order.successors[a].is_empty()
                } else {
                    !order.precedes(b, a)
                        && (!order.precedes(a, b) || order.cover_predecessors[b].contains(a))
                };
            }
        }
        let mut node_to_cluster = vec![INF; n * m];
        for x in 0..n {
            let row = &cost[x * n..(x + 1) * n];
            for (b, nodes) in cluster_nodes.iter().enumerate() {
                let mut best = INF;
                for &y in nodes {
                    if y != x {
                        best = best.min(row[y]);
                    }
                }
                node_to_cluster[x * m + b] = best;
            }
        }
        let mut w1 = vec![INF; m * m];
        for a in 0..m {
            for b in 0..m {
                if admissible[a * m + b] {
                    let mut best = INF;
                    for &x in &cluster_nodes[a] {
                        best = best.min(node_to_cluster[x * m + b]);
                    }
                    w1[a * m + b] = best;
                }
            }
        }
        // H2: half the cheapest path A → k → B with k in a third cluster Q ≠ depot.
        // from_cluster[A][k] = min_{a∈A} c(a,k) over admissible (A, cluster(k)).
        let mut from_cluster = vec![INF; m * n];
        for a in 0..m {
            for k in 0..n {
                let q = instance.node_cluster[k];
                if q == depot && k != start {
                    continue;
                }
                if admissible[a * m + q] {
                    let mut best = INF;
                    for &x in &cluster_nodes[a] {
                        best = best.min(cost[x * n + k]);
                    }
                    from_cluster[a * n + k] = best;
                }
            }
        }
        let mut w2 = vec![INF; m * m];
        // H2 costs m²·n: beyond ~10⁹ steps it is skipped (all zero, so L2 stays a valid 0).
        let h2_affordable = (m as u64) * (m as u64) * (n as u64) <= 1_000_000_000;
        if !h2_affordable {
            w2.iter_mut().for_each(|w| *w = 0.0);
        }
        for a in (0..m).filter(|_| h2_affordable) {
            for b in 0..m {
                if a == b {
                    continue;
                }
                let mut best = INF;
                for (q, nodes) in cluster_nodes.iter().enumerate() {
                    if q == a
                        || q == b
                        || q == depot
                        || !admissible[q * m + b]
                        || !admissible[a * m + q]
                    {
                        continue;
                    }
                    for &k in nodes {
                        let v = from_cluster[a * n + k] + node_to_cluster[k * m + b];
                        if v < best {
                            best = v;
                        }
                    }
                }
                w2[a * m + b] = best / 2.0;
            }
        }
        let into_cluster = cluster_nodes
            .iter()
            .map(|nodes| {
                let mut block = Vec::with_capacity(n * nodes.len());
                for u in 0..n {
                    block.extend(nodes.iter().map(|&x| cost[u * n + x]));
                }
                block
            })
            .collect();
        Ok(Model {
            into_cluster,
            n,
            m,
            depot,
            start,
            cost,
            cluster_nodes,
            node_cluster: instance.node_cluster.clone(),
            order,
            node_to_cluster,
            admissible,
            w1,
            w2,
            integral,
        })
    }

    #[inline]
    pub fn arc(&self, from: usize, to: usize) -> f64 {
        self.cost[from * self.n + to]
    }

    /// Rounds a lower bound up to the next integer when all costs are integral (with a small
    /// tolerance against floating-point noise from the dual computations).
    #[inline]
    pub fn round_bound(&self, bound: f64) -> f64 {
        if self.integral && bound.is_finite() {
            (bound - 1e-6).ceil()
        } else {
            bound
        }
    }
}

impl Model {
    /// Cheapest arc from cluster `a` into cluster `b`, ignoring admissibility.
    pub fn node_to_cluster_min(&self, a: usize, b: usize) -> f64 {
        let mut best = INF;
        for &x in &self.cluster_nodes[a] {
            best = best.min(self.node_to_cluster[x * self.m + b]);
        }
        best
    }
}
