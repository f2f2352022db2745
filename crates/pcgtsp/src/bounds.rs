//! Lower bounds on the residual problem (§6.3.1 of the spec).
//!
//! A DP state is a path from the start node through the clusters of an order ideal `J`, ending
//! in cluster `L` (maximal in `J`). Its completion visits the remaining clusters `R` and returns
//! to the start. The *residual problem* closes that completion into a cycle on `R ∪ {L, depot}`
//! with a zero arc `depot → L`; any relaxation of it bounds the completion cost:
//!
//! - **L1**: assignment (cycle cover) on the cluster graph H1 (cheapest arc between clusters),
//!   with arcs filtered by the relaxed precedence (rules a–c of the spec) and by the residual:
//!   the arc out of `L` must enter a cluster whose predecessors are all in `J`.
//! - **L2**: assignment on H2, where the cost of `(A, B)` is the cheapest two-arc path
//!   `A → k → B` halved; summing over a cycle counts every arc twice.
//! - **Node refinement**: the L1 duals bound the completion from a specific end node `x ∈ L`
//!   by replacing `L`'s row with `x`'s own arcs (dual feasibility is kept by lowering `u_L`).
//!
//! All bounds are valid for every feasible completion; tests check them against known optima.

use crate::assignment::Assignment;
use crate::instance::Instance;
use crate::order::{OrderError, PrecedenceOrder};

const INF: f64 = f64::INFINITY;

/// Largest residual problem (clusters) the assignment bounds are computed for.
const MAX_ASSIGNMENT: usize = 1500;

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

/// Scratch space and the last solution of a residual bound, for node refinement.
#[derive(Clone, Debug, Default)]
pub(crate) struct ResidualBounder {
    assignment: Assignment,
    clusters: Vec<usize>,
    matrix: Vec<f64>,
    /// Columns reachable from the last cluster's row: (cluster, column potential).
    last_row: Vec<(usize, f64)>,
    /// Dual sum minus the last cluster's row potential.
    base_without_last: f64,
    /// The L1 value.
    pub l1: f64,
    /// The L2 value (`-INF` when not computed).
    pub l2: f64,
    /// The last problem was too large for the assignment: every bound is 0.
    skipped: bool,
}

impl ResidualBounder {
    /// Computes L1 (and L2 if `with_l2`) for the residual problem of ideal `in_ideal` ending in
    /// `last`. `in_ideal(c)` tells whether cluster `c` is visited. Returns `max(L1, L2)`
    /// (`INF` when the residual problem is infeasible).
    pub fn compute(
        &mut self,
        model: &Model,
        in_ideal: &dyn Fn(usize) -> bool,
        last: usize,
        with_l2: bool,
    ) -> f64 {
        let m = model.m;
        let depot = model.depot;
        self.clusters.clear();
        self.clusters.push(last);
        for c in 0..m {
            if !in_ideal(c) {
                self.clusters.push(c);
            }
        }
        let remaining = self.clusters.len() - 1;
        let root = last == depot;
        // The O(k³) assignment is skipped on very large residual problems (bound 0 is valid).
        self.skipped = remaining > MAX_ASSIGNMENT;
        if self.skipped {
            self.l1 = 0.0;
            self.l2 = -INF;
            self.last_row.clear();
            self.base_without_last = 0.0;
            return 0.0;
        }
        if !root {
            self.clusters.push(depot);
        }
        let k = self.clusters.len();
        // Clusters whose predecessors are all visited: the only possible next clusters.
        let addable = |c: usize| model.order.predecessors[c].iter().all(in_ideal);
        self.matrix.clear();
        self.matrix.resize(k * k, INF);
        for (i, &a) in self.clusters.iter().enumerate() {
            for (j, &b) in self.clusters.iter().enumerate() {
                if i == j {
                    continue;
                }
                let w = if a == depot && !root {
                    if b == last {
                        0.0
                    } else {
                        INF
                    }
                } else if b == last && !root {
                    INF
                } else if a == last {
                    if b == depot {
                        // Back to the start only when nothing remains.
                        if remaining == 0 {
                            model.w1[a * m + b]
                        } else {
                            INF
                        }
                    } else if addable(b) {
                        model.w1[a * m + b]
                    } else {
                        INF
                    }
                } else {
                    model.w1[a * m + b]
                };
                self.matrix[i * k + j] = w;
            }
        }
        if root && k == 1 {
            self.l1 = 0.0;
            self.l2 = -INF;
            self.last_row.clear();
            self.base_without_last = 0.0;
            return 0.0;
        }
        let l1 = self.assignment.solve(k, &self.matrix);
        self.l1 = l1;
        self.last_row.clear();
        if l1.is_finite() {
            let mut dual_sum = 0.0;
            for i in 0..k {
                dual_sum += self.assignment.row_potential(i) + self.assignment.column_potential(i);
            }
            self.base_without_last = dual_sum - self.assignment.row_potential(0);
            for j in 1..k {
                if self.matrix[j].is_finite() {
                    self.last_row
                        .push((self.clusters[j], self.assignment.column_potential(j)));
                }
            }
        }
        self.l2 = -INF;
        if with_l2 && l1.is_finite() && k >= 3 {
            self.l2 = self.compute_l2(model, &addable, last, root);
        }
        l1.max(self.l2)
    }

    fn compute_l2(
        &mut self,
        model: &Model,
        addable: &dyn Fn(usize) -> bool,
        last: usize,
        root: bool,
    ) -> f64 {
        let m = model.m;
        let depot = model.depot;
        let k = self.clusters.len();
        let start = model.start;
        for i in 0..k {
            let a = self.clusters[i];
            for j in 0..k {
                let b = self.clusters[j];
                let w = if i == j {
                    INF
                } else if root {
                    // Cycle depot, X1, …, Xr. Middle depot: (Xr, X1) via the start node.
                    // (depot, B): the middle X1 is admissible after the depot, i.e. addable;
                    // (A, depot): the middle is final; both are rules of `admissible` in w2.
                    let mut w = model.w2[a * m + b];
                    if a != depot && b != depot && model.admissible[a * m + depot] && addable(b) {
                        let via = model.node_to_cluster_min(a, depot)
                            + model.node_to_cluster[start * m + b];
                        w = w.min(via / 2.0);
                    }
                    w
                } else if a == depot {
                    // Middle L: (depot, B) = (0 + c(l, b)) / 2, B the first cluster after L.
                    if b != last && addable(b) {
                        model.w1[last * m + b] / 2.0
                    } else {
                        INF
                    }
                } else if b == last {
                    // Middle depot: (A, L) = (c(a, start) + 0) / 2, A the final cluster.
                    if model.admissible[a * m + depot] {
                        model.w1[a * m + depot] / 2.0
                    } else {
                        INF
                    }
                } else {
                    // Middle in R (the global w2 allows any third cluster: weaker, still valid).
                    model.w2[a * m + b]
                };
                self.matrix[i * k + j] = w;
            }
        }
        self.assignment.solve(k, &self.matrix)
    }

    /// The L1 bound for a completion starting at node `x` of the last cluster, from the duals of
    /// the last [`ResidualBounder::compute`] (≥ L1). `INF` if `x` has no usable arc.
    #[inline]
    pub fn node_bound(&self, model: &Model, x: usize) -> f64 {
        if self.skipped {
            return 0.0;
        }
        let row = &model.node_to_cluster[x * model.m..(x + 1) * model.m];
        let mut best = INF;
        for &(b, v) in &self.last_row {
            let r = row[b] - v;
            if r < best {
                best = r;
            }
        }
        self.base_without_last + best
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

/// The root lower bounds of an instance (the residual problem of the empty prefix).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootBounds {
    /// Assignment on the cluster graph H1.
    pub l1: f64,
    /// Assignment on the two-step graph H2.
    pub l2: f64,
    /// The pierce-consistent cluster DP over the ideal lattice (`None` when the order has
    /// more ideals than allowed, or more than 256 clusters).
    pub cluster_dp: Option<f64>,
    /// `max(L1, L2)` on costs with node penalties (Lagrangian multipliers of "a tour leaves
    /// every node it enters") chosen by subgradient ascent on L1.
    pub node_penalty: f64,
    /// The Held–Karp style bound: a spanning arborescence of the clusters rooted at the depot
    /// plus an arc back, with out-degrees and node consistency relaxed by subgradient ascent
    /// (`None` with fewer than 3 clusters).
    pub arborescence: Option<f64>,
}

impl RootBounds {
    /// The best of the bounds.
    pub fn best(&self) -> f64 {
        self.l1
            .max(self.l2)
            .max(self.cluster_dp.unwrap_or(-INF))
            .max(self.node_penalty)
            .max(self.arborescence.unwrap_or(-INF))
    }
}

/// Computes the root bounds (minimum over the start nodes of the depot cluster). The cluster DP
/// is built only when the precedence order has at most `max_ideals` order ideals.
pub fn root_bounds(instance: &Instance, max_ideals: usize) -> Result<RootBounds, OrderError> {
    use crate::lagrange::{arborescence_bound, optimise, PenaltyOptions};
    use crate::lattice::Lattice;
    const LATTICE_WORK: usize = 300_000_000;
    let mut result = RootBounds {
        l1: INF,
        l2: INF,
        cluster_dp: Some(INF),
        node_penalty: INF,
        arborescence: Some(INF),
    };
    let mut bounder = ResidualBounder::default();
    for &start in &instance.clusters[instance.depot] {
        let model = Model::new(instance, start)?;
        let depot = model.depot;
        bounder.compute(&model, &|c| c == depot, depot, true);
        result.l1 = result.l1.min(bounder.l1);
        result.l2 = result.l2.min(bounder.l2);
        let memory = 1 << 30;
        let dp =
            match model.m {
                0..=64 => Lattice::<1>::build(&model, max_ideals, memory, LATTICE_WORK)
                    .map(|l| l.root_bound),
                65..=128 => Lattice::<2>::build(&model, max_ideals, memory, LATTICE_WORK)
                    .map(|l| l.root_bound),
                129..=256 => Lattice::<4>::build(&model, max_ideals, memory, LATTICE_WORK)
                    .map(|l| l.root_bound),
                _ => None,
            };
        let penalty_options = PenaltyOptions {
            iterations: 400,
            work: 1e9,
        };
        let penalised = optimise(instance, &model, INF, penalty_options);
        result.node_penalty = result
            .node_penalty
            .min(penalised.as_ref().map_or(INF, |p| p.root_bound));
        let lambda = penalised.as_ref().map(|p| p.lambda.as_slice());
        let arborescence = arborescence_bound(&model, INF, lambda, penalty_options).map(|(b, _)| b);
        result.arborescence = match (result.arborescence, arborescence) {
            (Some(a), Some(b)) => Some(a.min(b)),
            _ => None,
        };
        result.cluster_dp = match (result.cluster_dp, dp) {
            (Some(a), Some(b)) => Some(a.min(b)),
            _ => None,
        };
    }
    Ok(result)
}
