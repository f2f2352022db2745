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
use crate::model::Model;

const INF: f64 = f64::INFINITY;

/// Largest residual problem (clusters) the assignment bounds are computed for.
const MAX_ASSIGNMENT: usize = 1500;

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
    /// Where a bound in pieces is ([`ResidualBounder::compute_until`]).
    stage: ResidualStage,
}

/// The part of a residual bound under way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum ResidualStage {
    /// Nothing under way: the next call sets up the problem.
    #[default]
    Start,
    /// The L1 assignment.
    L1,
    /// The L2 assignment.
    L2,
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
        self.stage = ResidualStage::Start;
        self.compute_until(model, in_ideal, last, with_l2, &|| false)
            .expect("runs to the end without a pause")
    }

    /// [`ResidualBounder::compute`] in pieces: the matrices at once (O(k²)), the assignments
    /// a row at a time, until `pause()` says so after one (`None`: call again with the same
    /// arguments; the last call gives what `compute` gives). The root bound of a
    /// discretisation of 1,000 clusters took 2.9 s in one piece.
    pub fn compute_until(
        &mut self,
        model: &Model,
        in_ideal: &dyn Fn(usize) -> bool,
        last: usize,
        with_l2: bool,
        pause: &dyn Fn() -> bool,
    ) -> Option<f64> {
        let depot = model.depot;
        let root = last == depot;
        // Clusters whose predecessors are all visited: the only possible next clusters.
        let addable = |c: usize| model.order.predecessors[c].iter().all(in_ideal);
        if self.stage == ResidualStage::Start {
            if let Some(done) = self.start_l1(model, in_ideal, last) {
                return Some(done);
            }
            self.assignment.begin(self.clusters.len());
            self.stage = ResidualStage::L1;
        }
        let k = self.clusters.len();
        if self.stage == ResidualStage::L1 {
            let l1 = self.assignment.solve_until(k, &self.matrix, pause)?;
            self.l1 = l1;
            self.last_row.clear();
            if l1.is_finite() {
                let mut dual_sum = 0.0;
                for i in 0..k {
                    dual_sum +=
                        self.assignment.row_potential(i) + self.assignment.column_potential(i);
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
            if !(with_l2 && l1.is_finite() && k >= 3) {
                self.stage = ResidualStage::Start;
                return Some(l1.max(self.l2));
            }
            self.fill_l2(model, &addable, last, root);
            self.assignment.begin(k);
            self.stage = ResidualStage::L2;
            if pause() {
                return None;
            }
        }
        self.l2 = self.assignment.solve_until(k, &self.matrix, pause)?;
        self.stage = ResidualStage::Start;
        Some(self.l1.max(self.l2))
    }

    /// The clusters and the L1 matrix of the residual problem; `Some(bound)` when no
    /// assignment is needed (too large: 0; the root with nothing left: 0).
    fn start_l1(
        &mut self,
        model: &Model,
        in_ideal: &dyn Fn(usize) -> bool,
        last: usize,
    ) -> Option<f64> {
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
            return Some(0.0);
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
            return Some(0.0);
        }
        None
    }

    /// The L2 matrix (H2 halved) of the residual problem [`ResidualBounder::start_l1`] set up.
    fn fill_l2(&mut self, model: &Model, addable: &dyn Fn(usize) -> bool, last: usize, root: bool) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instance::Instance;

    /// The root bound in pieces (paused after every assignment row) is the one-piece bound,
    /// L1, L2 and the node refinement's duals alike, with and without L2, on real instances.
    #[test]
    fn the_root_bound_in_pieces_equals_the_bound_at_once() {
        for name in ["industrial/e1x_4", "pcgtsplib/kro124p.1", "pcgtsplib/ESC47"] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../data/pcgtsp/{name}.pcglns"));
            let instance = Instance::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
            let model = Model::new(&instance, instance.clusters[instance.depot][0]).unwrap();
            let depot = model.depot;
            for with_l2 in [false, true] {
                let mut whole = ResidualBounder::default();
                let want = whole.compute(&model, &|c| c == depot, depot, with_l2);
                let mut pieces = ResidualBounder::default();
                let mut calls = 1;
                let got = loop {
                    match pieces.compute_until(&model, &|c| c == depot, depot, with_l2, &|| true) {
                        Some(bound) => break bound,
                        None => calls += 1,
                    }
                };
                assert_eq!(got.to_bits(), want.to_bits(), "{name}");
                assert_eq!(pieces.l1.to_bits(), whole.l1.to_bits(), "{name}");
                assert_eq!(pieces.l2.to_bits(), whole.l2.to_bits(), "{name}");
                for x in 0..model.n {
                    let (a, b) = (pieces.node_bound(&model, x), whole.node_bound(&model, x));
                    assert_eq!(a.to_bits(), b.to_bits(), "{name}: node {x}");
                }
                assert!(
                    calls >= model.m - 1,
                    "{name}: {calls} calls for {} clusters",
                    model.m
                );
            }
        }
    }
}
