//! The model every bound and the exact search work on: an [`Instance`] prepared for bounding
//! with the depot fixed to one start node — the precedence order, the cheapest arcs between
//! nodes and clusters, the admissible cluster arcs and the cluster graphs H1 and H2.

use crate::instance::Instance;
use crate::order::{OrderError, PrecedenceOrder};

const INF: f64 = f64::INFINITY;

/// The work (matrix entries read) of one piece of a [`ModelBuilder`]: about a millisecond, so
/// the clock is read rarely and a small model is one piece.
const PIECE_WORK: usize = 1 << 20;

/// Where a [`ModelBuilder`] is: each stage fills one of the model's tables, a row or a
/// cluster per unit of work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Copying the cost matrix (next row).
    Cost(usize),
    Admissible,
    /// `node_to_cluster` (next node).
    NodeToCluster(usize),
    W1,
    /// `from_cluster` (next cluster).
    FromCluster(usize),
    /// `w2` (next cluster).
    W2(usize),
    /// `into_cluster` (next cluster).
    IntoCluster(usize),
}

/// A [`Model`] built in resumable pieces: on a discretised nest of thousands of nodes its
/// tables are several passes over an n × n matrix (a piece of 0.72 s in the exact job on
/// nested.dbs at 25 mm), longer than the page may wait for Stop. [`ModelBuilder::advance`]
/// works until asked to pause, always doing at least one piece; the model is the one
/// [`Model::new`] builds, however the pieces fall.
#[derive(Clone, Debug)]
pub(crate) struct ModelBuilder {
    stage: Stage,
    /// The model being filled (taken when complete).
    model: Option<Model>,
    from_cluster: Vec<f64>,
    h2_affordable: bool,
}

impl ModelBuilder {
    /// Starts the model of `instance` with its depot fixed to `start`; fails when the
    /// precedence pairs are no partial order.
    pub fn new(instance: &Instance, start: usize) -> Result<ModelBuilder, OrderError> {
        let order = PrecedenceOrder::new(instance)?;
        let n = instance.node_count;
        let m = instance.clusters.len();
        let depot = instance.depot;
        let mut cluster_nodes = instance.clusters.clone();
        cluster_nodes[depot] = vec![start];
        Ok(ModelBuilder {
            stage: Stage::Cost(0),
            model: Some(Model {
                n,
                m,
                depot,
                start,
                cost: Vec::with_capacity(n * n),
                cluster_nodes,
                node_cluster: instance.node_cluster.clone(),
                order,
                node_to_cluster: vec![INF; n * m],
                admissible: vec![false; m * m],
                w1: vec![INF; m * m],
                w2: vec![INF; m * m],
                integral: true,
                into_cluster: Vec::with_capacity(m),
            }),
            from_cluster: Vec::new(),
            // H2 costs m²·n: beyond ~10⁹ steps it is skipped (all zero, so L2 stays a valid 0).
            h2_affordable: (m as u64) * (m as u64) * (n as u64) <= 1_000_000_000,
        })
    }

    /// Builds pieces (of about [`PIECE_WORK`]) until `pause()` says so (asked after every
    /// piece, so at least one is done); the model once every table is filled (not to be
    /// called again after that).
    pub fn advance(&mut self, instance: &Instance, pause: &dyn Fn() -> bool) -> Option<Model> {
        let mut work = 0;
        loop {
            let (complete, done) = self.unit(instance);
            if complete {
                return self.model.take();
            }
            work += done;
            if work >= PIECE_WORK {
                if pause() {
                    return None;
                }
                work = 0;
            }
        }
    }

    /// One row or cluster of a table: whether the model is complete, and the work done.
    fn unit(&mut self, instance: &Instance) -> (bool, usize) {
        let model = self
            .model
            .as_mut()
            .expect("advanced after the model was complete");
        let (n, m, depot, start) = (model.n, model.m, model.depot, model.start);
        match self.stage {
            Stage::Cost(row) => {
                let end = (row + 1).min(n);
                let rows = &instance.cost[row * n..end * n];
                model.integral &= rows.iter().all(|c| !c.is_finite() || c.fract() == 0.0);
                model.cost.extend_from_slice(rows);
                self.stage = if end == n {
                    Stage::Admissible
                } else {
                    Stage::Cost(end)
                };
                (false, n)
            }
            Stage::Admissible => {
                let order = &model.order;
                for a in 0..m {
                    for b in 0..m {
                        model.admissible[a * m + b] = if a == b {
                            false
                        } else if b == depot {
                            order.successors[a].is_empty()
                        } else {
                            !order.precedes(b, a)
                                && (!order.precedes(a, b)
                                    || order.cover_predecessors[b].contains(a))
                        };
                    }
                }
                self.stage = Stage::NodeToCluster(0);
                (false, m * m)
            }
            Stage::NodeToCluster(first) => {
                let end = (first + 1).min(n);
                for x in first..end {
                    let row = &model.cost[x * n..(x + 1) * n];
                    for (b, nodes) in model.cluster_nodes.iter().enumerate() {
                        let mut best = INF;
                        for &y in nodes {
                            if y != x {
                                best = best.min(row[y]);
                            }
                        }
                        model.node_to_cluster[x * m + b] = best;
                    }
                }
                self.stage = if end == n {
                    Stage::W1
                } else {
                    Stage::NodeToCluster(end)
                };
                (false, n)
            }
            Stage::W1 => {
                for a in 0..m {
                    for b in 0..m {
                        if model.admissible[a * m + b] {
                            let mut best = INF;
                            for &x in &model.cluster_nodes[a] {
                                best = best.min(model.node_to_cluster[x * m + b]);
                            }
                            model.w1[a * m + b] = best;
                        }
                    }
                }
                // H2: half the cheapest path A → k → B with k in a third cluster Q ≠ depot;
                // from_cluster[A][k] = min_{a∈A} c(a,k) over admissible (A, cluster(k)).
                self.stage = if self.h2_affordable {
                    self.from_cluster = vec![INF; m * n];
                    Stage::FromCluster(0)
                } else {
                    model.w2.iter_mut().for_each(|w| *w = 0.0);
                    Stage::IntoCluster(0)
                };
                (false, n * m)
            }
            Stage::FromCluster(a) => {
                if a < m {
                    for k in 0..n {
                        let q = instance.node_cluster[k];
                        if q == depot && k != start {
                            continue;
                        }
                        if model.admissible[a * m + q] {
                            let mut best = INF;
                            for &x in &model.cluster_nodes[a] {
                                best = best.min(model.cost[x * n + k]);
                            }
                            self.from_cluster[a * n + k] = best;
                        }
                    }
                }
                self.stage = if a + 1 >= m {
                    Stage::W2(0)
                } else {
                    Stage::FromCluster(a + 1)
                };
                (false, n * model.cluster_nodes.get(a).map_or(1, Vec::len))
            }
            Stage::W2(a) => {
                if a < m {
                    for b in 0..m {
                        if a == b {
                            continue;
                        }
                        let mut best = INF;
                        for (q, nodes) in model.cluster_nodes.iter().enumerate() {
                            if q == a
                                || q == b
                                || q == depot
                                || !model.admissible[q * m + b]
                                || !model.admissible[a * m + q]
                            {
                                continue;
                            }
                            for &k in nodes {
                                let v =
                                    self.from_cluster[a * n + k] + model.node_to_cluster[k * m + b];
                                if v < best {
                                    best = v;
                                }
                            }
                        }
                        model.w2[a * m + b] = best / 2.0;
                    }
                }
                self.stage = if a + 1 >= m {
                    self.from_cluster = Vec::new();
                    Stage::IntoCluster(0)
                } else {
                    Stage::W2(a + 1)
                };
                (false, m * n)
            }
            Stage::IntoCluster(c) => {
                if let Some(nodes) = model.cluster_nodes.get(c) {
                    let mut block = Vec::with_capacity(n * nodes.len());
                    for u in 0..n {
                        block.extend(nodes.iter().map(|&x| model.cost[u * n + x]));
                    }
                    model.into_cluster.push(block);
                }
                let work = n * model.cluster_nodes.get(c).map_or(1, Vec::len);
                if c + 1 >= m {
                    return (true, work);
                }
                self.stage = Stage::IntoCluster(c + 1);
                (false, work)
            }
        }
    }
}

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
        let mut builder = ModelBuilder::new(instance, start)?;
        loop {
            if let Some(model) = builder.advance(instance, &|| false) {
                return Ok(model);
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    fn instance(relative: &str) -> Instance {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data")
            .join(relative);
        let text = std::fs::read_to_string(&path).expect("instance file");
        Instance::parse(&text).expect("parses")
    }

    /// Built a piece per `advance` (paused after every piece), the model is the one built in
    /// one call, table for table (compared through `Debug`, which prints every float exactly).
    #[test]
    fn a_model_built_in_pieces_equals_the_model_built_at_once() {
        for name in [
            "pcgtsp/industrial/e1x_4.pcglns",
            "pcgtsp/pcgtsplib/kro124p.1.pcglns",
            "pcgtsp/pcgtsplib/ESC47.pcglns",
        ] {
            let instance = instance(name);
            let start = instance.clusters[instance.depot][0];
            let whole = Model::new(&instance, start).expect("a partial order");
            let mut builder = ModelBuilder::new(&instance, start).expect("a partial order");
            let pauses = Cell::new(0usize);
            let pause = || {
                pauses.set(pauses.get() + 1);
                true
            };
            let pieces = loop {
                if let Some(model) = builder.advance(&instance, &pause) {
                    assert_eq!(format!("{model:?}"), format!("{whole:?}"), "{name}");
                    break pauses.get() + 1;
                }
            };
            let n = instance.node_count;
            assert!(
                pieces >= 3 * n * n / PIECE_WORK,
                "{name}: {pieces} pieces for {n} nodes"
            );
        }
    }
}
