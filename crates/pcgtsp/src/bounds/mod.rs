//! The lower bounds on a tour's cost, every one valid for every feasible completion of a
//! search state (tests check them against known and brute-force optima):
//!
//! - [`residual`]: the assignment bounds L1 / L2 on the residual problem, with node refinement;
//! - [`lagrange`]: node penalties and the Held–Karp style arborescence bound (subgradient ascent);
//! - [`lattice`]: the pierce-group DP over the lattice of order ideals;
//! - [`subset`]: the exact node-level DP over a subset of the clusters;
//! - [`completion`]: the position-indexed completion bound;
//! - here, [`root_bounds`]: all of them at the root, for reports and tests.

pub(crate) mod completion;
pub(crate) mod lagrange;
pub(crate) mod lattice;
pub(crate) mod residual;
pub(crate) mod subset;

use crate::instance::Instance;
use crate::keys::with_key_width;
use crate::model::Model;
use crate::order::OrderError;
use lagrange::{arborescence_bound, optimise, PenaltyOptions};
use lattice::Lattice;
use residual::ResidualBounder;

const INF: f64 = f64::INFINITY;

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
        let dp = with_key_width!(model.m, |W| {
            Lattice::<W>::build(&model, max_ideals, memory, LATTICE_WORK).map(|l| l.root_bound)
        })
        .flatten();
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
