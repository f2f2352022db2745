//! Node penalties: a Lagrangian strengthening of the assignment bounds.
//!
//! The cluster graph H1 prices the arc `A → B` by the cheapest node pair, so the L1 cycle cover
//! may enter a cluster at one node and leave it from another. A tour enters and leaves every
//! node it visits equally often: `in(x) − out(x) = 0`. Relaxing these equations with a
//! multiplier `λ_x` per node gives the arc costs `c'(x, y) = c(x, y) + λ_y − λ_x`. On every
//! closed tour the penalties telescope (`Σ c' = Σ c`), so every bound computed from `c'` (L1,
//! L2, their node refinement) bounds the true tour cost for *any* `λ`; `λ = 0` is plain L1/L2.
//! A path from `x` to the start costs `Σ c = Σ c' + λ_x − λ_start`, which is how a DP state
//! ending at `x` turns a residual bound in `c'` back into a bound in `c`.
//!
//! `λ` is chosen by subgradient optimisation of the root L1: the subgradient of the assignment
//! value at `λ` is `in(x) − out(x)` of the node arcs realising the optimal cycle cover.

use crate::assignment::Assignment;
use crate::bounds::residual::ResidualBounder;
use crate::instance::Instance;
use crate::model::Model;

const INF: f64 = f64::INFINITY;

/// Settings of the subgradient optimisation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PenaltyOptions {
    /// At most this many subgradient iterations.
    pub iterations: usize,
    /// Stop once this many elementary steps (about `n² + m³` per iteration) are spent.
    pub work: f64,
}

/// Node penalties and the cost model they induce.
#[derive(Clone, Debug)]
pub(crate) struct NodePenalties {
    /// `λ_x` for every node.
    pub lambda: Vec<f64>,
    /// The model with the penalised costs `c(x, y) + λ_y − λ_x` (same clusters and order).
    pub model: Model,
    /// `max(L1, L2)` of the root residual problem under the penalised costs.
    pub root_bound: f64,
    /// The plain root L1 (`λ = 0`), for reporting.
    pub plain_l1: f64,
    /// Subgradient iterations done.
    pub iterations: usize,
}

impl NodePenalties {
    /// `λ_x − λ_start`: what a penalised bound on the completion from `x` must be shifted by.
    #[inline]
    pub fn shift(&self, x: usize) -> f64 {
        self.lambda[x] - self.lambda[self.model.start]
    }
}

/// The root L1 under penalties `lambda`, and its subgradient (`in(x) − out(x)`) in `gradient`.
/// Returns `INF` when the cycle cover is infeasible.
struct RootL1 {
    /// `n × m`: the cheapest penalised arc from node `x` into cluster `B`, and its head.
    into: Vec<(f64, u32)>,
    /// `m × m` cluster matrix and the tail / head realising each entry.
    matrix: Vec<f64>,
    arg: Vec<(u32, u32)>,
    assignment: Assignment,
}

impl RootL1 {
    fn evaluate(&mut self, model: &Model, lambda: &[f64], gradient: &mut [f64]) -> f64 {
        let (n, m) = (model.n, model.m);
        self.into.clear();
        self.into.resize(n * m, (INF, u32::MAX));
        for x in 0..n {
            let row = &model.cost[x * n..(x + 1) * n];
            let out = &mut self.into[x * m..(x + 1) * m];
            for (b, nodes) in model.cluster_nodes.iter().enumerate() {
                let mut best = (INF, u32::MAX);
                for &y in nodes {
                    if y != x {
                        let v = row[y] + lambda[y];
                        if v < best.0 {
                            best = (v, y as u32);
                        }
                    }
                }
                out[b] = best;
            }
        }
        // The root residual: a cycle cover of all clusters; from the depot only to clusters
        // without other predecessors (the same matrix as `ResidualBounder` at the root).
        let depot = model.depot;
        self.matrix.clear();
        self.matrix.resize(m * m, INF);
        self.arg.clear();
        self.arg.resize(m * m, (u32::MAX, u32::MAX));
        for a in 0..m {
            for b in 0..m {
                if !model.admissible[a * m + b] {
                    continue;
                }
                if a == depot && !model.order.predecessors[b].iter().all(|p| p == depot) {
                    continue;
                }
                let mut best = (INF, (u32::MAX, u32::MAX));
                for &x in &model.cluster_nodes[a] {
                    let (v, y) = self.into[x * m + b];
                    let v = v - lambda[x];
                    if v < best.0 {
                        best = (v, (x as u32, y));
                    }
                }
                self.matrix[a * m + b] = best.0;
                self.arg[a * m + b] = best.1;
            }
        }
        let value = self.assignment.solve(m, &self.matrix);
        gradient.iter_mut().for_each(|g| *g = 0.0);
        if value.is_finite() {
            for b in 0..m {
                let a = self.assignment.row_of_column(b);
                let (x, y) = self.arg[a * m + b];
                gradient[y as usize] += 1.0;
                gradient[x as usize] -= 1.0;
            }
        }
        value
    }
}

/// Optimises node penalties for `model` (built from `instance` with the same start node) by
/// subgradient ascent on the root L1. `upper_bound` (a tour cost, or `INF`) sets the step
/// lengths. Returns `None` when the root problem is infeasible.
pub(crate) fn optimise(
    instance: &Instance,
    model: &Model,
    upper_bound: f64,
    options: PenaltyOptions,
) -> Option<NodePenalties> {
    let mut ascent = PenaltyAscent::new(model, upper_bound, options)?;
    loop {
        if let Some(penalties) = ascent.advance(instance, model, &|| false) {
            return penalties;
        }
    }
}

/// [`optimise`]'s subgradient ascent, resumable between iterations (on seven.dbs's full-route
/// model its 170 iterations took 0.2–0.26 s in one piece). The penalties do not depend on
/// where it pauses.
pub(crate) struct PenaltyAscent {
    upper_bound: f64,
    options: PenaltyOptions,
    eval: RootL1,
    lambda: Vec<f64>,
    gradient: Vec<f64>,
    plain_l1: f64,
    best: (f64, Vec<f64>),
    value: f64,
    scale: f64,
    since_improvement: usize,
    per_iteration: f64,
    iterations: usize,
}

impl PenaltyAscent {
    /// The ascent from `λ = 0` (its first evaluation done here); `None` when the root problem
    /// is infeasible.
    pub fn new(model: &Model, upper_bound: f64, options: PenaltyOptions) -> Option<PenaltyAscent> {
        let (n, m) = (model.n, model.m);
        let mut eval = RootL1 {
            into: Vec::new(),
            matrix: Vec::new(),
            arg: Vec::new(),
            assignment: Assignment::default(),
        };
        let lambda = vec![0.0; n];
        let mut gradient = vec![0.0; n];
        let plain_l1 = eval.evaluate(model, &lambda, &mut gradient);
        if !plain_l1.is_finite() {
            return None;
        }
        Some(PenaltyAscent {
            upper_bound,
            options,
            eval,
            best: (plain_l1, lambda.clone()),
            lambda,
            gradient,
            plain_l1,
            value: plain_l1,
            scale: 2.0,
            since_improvement: 0,
            per_iteration: (n * n + m * m * m) as f64,
            iterations: 0,
        })
    }

    /// Runs iterations until `pause()` (asked after each, so at least one is done); once the
    /// ascent ends, the penalties (`None` inside when the penalised model fails).
    pub fn advance(
        &mut self,
        instance: &Instance,
        model: &Model,
        pause: &dyn Fn() -> bool,
    ) -> Option<Option<NodePenalties>> {
        loop {
            if !self.iteration(model) {
                return Some(self.finish(instance, model));
            }
            if pause() {
                return None;
            }
        }
    }

    /// One iteration; whether the ascent goes on.
    fn iteration(&mut self, model: &Model) -> bool {
        let (upper_bound, options) = (self.upper_bound, self.options);
        if self.iterations >= options.iterations
            || (self.iterations as f64 + 1.0) * self.per_iteration > options.work
        {
            return false;
        }
        let norm: f64 = self.gradient.iter().map(|g| g * g).sum();
        if norm == 0.0 {
            // A node-consistent cycle cover: no multiplier can raise this bound.
            return false;
        }
        let best = self.best.0;
        // Polyak steps towards the incumbent (or a little above the bound without one).
        let target = if upper_bound.is_finite() && upper_bound > best {
            upper_bound
        } else {
            best + 0.05 * best.abs() + 1.0
        };
        let step = self.scale * (target - self.value) / norm;
        for (l, g) in self.lambda.iter_mut().zip(&self.gradient) {
            *l += step * g;
        }
        self.value = self.eval.evaluate(model, &self.lambda, &mut self.gradient);
        self.iterations += 1;
        if !self.value.is_finite() {
            return false;
        }
        if self.value > self.best.0 + 1e-9 {
            self.best = (self.value, self.lambda.clone());
            self.since_improvement = 0;
        } else {
            self.since_improvement += 1;
            if self.since_improvement >= 20 {
                self.scale /= 2.0;
                self.since_improvement = 0;
                if self.scale < 1e-3 {
                    return false;
                }
            }
        }
        !(upper_bound.is_finite() && model.round_bound(self.best.0) >= upper_bound)
    }

    /// The penalised model of the best penalties and its root bound.
    fn finish(&mut self, instance: &Instance, model: &Model) -> Option<NodePenalties> {
        let n = model.n;
        let (best, lambda) = std::mem::take(&mut self.best);
        let mut penalised = instance.clone();
        for x in 0..n {
            for y in 0..n {
                let c = &mut penalised.cost[x * n + y];
                if c.is_finite() {
                    *c += lambda[y] - lambda[x];
                }
            }
        }
        let penalised_model = Model::new(&penalised, model.start).ok()?;
        let depot = penalised_model.depot;
        let mut bounder = ResidualBounder::default();
        let root_bound = bounder.compute(&penalised_model, &|c| c == depot, depot, true);
        Some(NodePenalties {
            lambda,
            model: penalised_model,
            root_bound: root_bound.max(best),
            plain_l1: self.plain_l1,
            iterations: self.iterations,
        })
    }
}

/// A minimum spanning arborescence (Chu–Liu / Edmonds, dense `O(k³)` per contraction) of the
/// `k × k` matrix `w` (row = tail, `INF` = no arc), rooted at `root`. Returns its cost and the
/// parent of every vertex (`usize::MAX` for the root), or `None` if some vertex is unreachable.
pub(crate) fn min_arborescence(k: usize, root: usize, w: &[f64]) -> Option<(f64, Vec<usize>)> {
    debug_assert_eq!(w.len(), k * k);
    // Cheapest in-arc of every vertex.
    let mut parent = vec![usize::MAX; k];
    for v in (0..k).filter(|&v| v != root) {
        let mut best = (INF, usize::MAX);
        for u in (0..k).filter(|&u| u != v) {
            if w[u * k + v] < best.0 {
                best = (w[u * k + v], u);
            }
        }
        if best.1 == usize::MAX {
            return None;
        }
        parent[v] = best.1;
    }
    // Find one cycle of the parent graph.
    let mut mark = vec![usize::MAX; k];
    let mut cycle: Vec<usize> = Vec::new();
    for s in 0..k {
        let mut v = s;
        while v != root && mark[v] == usize::MAX {
            mark[v] = s;
            v = parent[v];
        }
        if v != root && mark[v] == s {
            // `v` lies on a cycle found from `s`.
            let mut c = v;
            loop {
                cycle.push(c);
                c = parent[c];
                if c == v {
                    break;
                }
            }
            break;
        }
    }
    if cycle.is_empty() {
        let cost = (0..k)
            .filter(|&v| v != root)
            .map(|v| w[parent[v] * k + v])
            .sum();
        return Some((cost, parent));
    }
    // Contract the cycle into one vertex (the last index of the smaller problem).
    let mut on_cycle = vec![false; k];
    for &c in &cycle {
        on_cycle[c] = true;
    }
    let outside: Vec<usize> = (0..k).filter(|&v| !on_cycle[v]).collect();
    let kk = outside.len() + 1;
    let c_index = kk - 1;
    let mut index = vec![usize::MAX; k];
    for (i, &v) in outside.iter().enumerate() {
        index[v] = i;
    }
    let mut ww = vec![INF; kk * kk];
    // For arcs into the cycle: the cycle vertex entered; for arcs out of it: the tail used.
    let mut enter = vec![usize::MAX; kk];
    let mut leave = vec![usize::MAX; kk];
    for (i, &u) in outside.iter().enumerate() {
        for (j, &v) in outside.iter().enumerate() {
            if i != j {
                ww[i * kk + j] = w[u * k + v];
            }
        }
        let mut best = (INF, usize::MAX);
        for &v in &cycle {
            let r = w[u * k + v] - w[parent[v] * k + v];
            if r < best.0 {
                best = (r, v);
            }
        }
        ww[i * kk + c_index] = best.0;
        enter[i] = best.1;
        let mut best = (INF, usize::MAX);
        for &c in &cycle {
            if w[c * k + u] < best.0 {
                best = (w[c * k + u], c);
            }
        }
        ww[c_index * kk + i] = best.0;
        leave[i] = best.1;
    }
    let root_index = index[root];
    let (_, sub_parent) = min_arborescence(kk, root_index, &ww)?;
    let mut result = vec![usize::MAX; k];
    for (j, &v) in outside.iter().enumerate() {
        if v == root {
            continue;
        }
        let p = sub_parent[j];
        result[v] = if p == c_index { leave[j] } else { outside[p] };
    }
    for &c in &cycle {
        result[c] = parent[c];
    }
    let p = sub_parent[c_index];
    result[enter[p]] = outside[p];
    let cost = (0..k)
        .filter(|&v| v != root)
        .map(|v| w[result[v] * k + v])
        .sum();
    Some((cost, result))
}

/// The Held–Karp style bound: a tour is a spanning arborescence of the clusters rooted at the
/// depot (the path) plus one arc back into the depot, with out-degree 1 at every cluster.
/// Relaxing the out-degrees with cluster multipliers `μ` (and node consistency with `λ`, as
/// above) and optimising both by subgradient ascent bounds the tour cost from below.
/// `initial_lambda` (node penalties, e.g. those of [`optimise`]) is the starting point.
/// Returns the best bound and the iterations done (`INF` when no tour exists), or `None` with
/// fewer than 3 clusters.
pub(crate) fn arborescence_bound(
    model: &Model,
    upper_bound: f64,
    initial_lambda: Option<&[f64]>,
    options: PenaltyOptions,
) -> Option<(f64, usize)> {
    let mut ascent = ArborescenceAscent::new(model, upper_bound, initial_lambda, options)?;
    loop {
        if let Some(result) = ascent.advance(model, &|| false) {
            return Some(result);
        }
    }
}

/// [`arborescence_bound`]'s subgradient ascent, resumable between iterations (on 50 clusters
/// of 3,000 nodes its 500 iterations took 0.5 s: one piece would block Stop that long). The
/// bound and the iterations do not depend on where it pauses.
pub(crate) struct ArborescenceAscent {
    upper_bound: f64,
    options: PenaltyOptions,
    lambda: Vec<f64>,
    mu: Vec<f64>,
    into: Vec<(f64, u32)>,
    base: Vec<f64>,
    arg: Vec<(u32, u32)>,
    matrix: Vec<f64>,
    g_lambda: Vec<f64>,
    g_mu: Vec<f64>,
    best: f64,
    scale: f64,
    since_improvement: usize,
    per_iteration: f64,
    iterations: usize,
}

impl ArborescenceAscent {
    /// The ascent from `initial_lambda` (zero without); `None` with fewer than 3 clusters.
    pub fn new(
        model: &Model,
        upper_bound: f64,
        initial_lambda: Option<&[f64]>,
        options: PenaltyOptions,
    ) -> Option<ArborescenceAscent> {
        let (n, m) = (model.n, model.m);
        if m < 3 {
            return None;
        }
        Some(ArborescenceAscent {
            upper_bound,
            options,
            // Any start is valid; the node penalties of the assignment bound are a good one.
            lambda: initial_lambda.map_or_else(|| vec![0.0; n], <[f64]>::to_vec),
            mu: vec![0.0; m],
            into: vec![(INF, u32::MAX); n * m],
            base: vec![INF; m * m],
            arg: vec![(u32::MAX, u32::MAX); m * m],
            matrix: vec![INF; m * m],
            g_lambda: vec![0.0; n],
            g_mu: vec![0.0; m],
            best: -INF,
            scale: 2.0,
            since_improvement: 0,
            per_iteration: (n * n + 2 * m * m * m) as f64,
            iterations: 0,
        })
    }

    /// Runs iterations until `pause()` (asked after each, so at least one is done); the best
    /// bound and the iterations done once the ascent ends.
    pub fn advance(&mut self, model: &Model, pause: &dyn Fn() -> bool) -> Option<(f64, usize)> {
        loop {
            if let Some(result) = self.iteration(model) {
                return Some(result);
            }
            if pause() {
                return None;
            }
        }
    }

    /// One iteration; the result when the ascent ends with it.
    fn iteration(&mut self, model: &Model) -> Option<(f64, usize)> {
        let (n, m) = (model.n, model.m);
        let depot = model.depot;
        let ArborescenceAscent {
            upper_bound,
            options,
            lambda,
            mu,
            into,
            base,
            arg,
            matrix,
            g_lambda,
            g_mu,
            best,
            scale,
            since_improvement,
            per_iteration,
            iterations,
        } = self;
        let (upper_bound, options, per_iteration) = (*upper_bound, *options, *per_iteration);
        // Penalised cluster arcs.
        for x in 0..n {
            let row = &model.cost[x * n..(x + 1) * n];
            for (b, nodes) in model.cluster_nodes.iter().enumerate() {
                let mut bestv = (INF, u32::MAX);
                for &y in nodes {
                    if y != x {
                        let v = row[y] + lambda[y];
                        if v < bestv.0 {
                            bestv = (v, y as u32);
                        }
                    }
                }
                into[x * m + b] = bestv;
            }
        }
        for (a, &out_penalty) in mu.iter().enumerate() {
            for b in 0..m {
                let i = a * m + b;
                base[i] = INF;
                if !model.admissible[i]
                    || (a == depot && !model.order.predecessors[b].iter().all(|p| p == depot))
                {
                    continue;
                }
                for &x in &model.cluster_nodes[a] {
                    let (v, y) = into[x * m + b];
                    let v = v - lambda[x];
                    if v < base[i] {
                        base[i] = v;
                        arg[i] = (x as u32, y);
                    }
                }
                matrix[i] = base[i] + out_penalty;
            }
        }
        // Arcs into the depot only close the tour: not part of the arborescence.
        let mut arb = matrix.clone();
        for a in 0..m {
            arb[a * m + depot] = INF;
        }
        let Some((tree_cost, parent)) = min_arborescence(m, depot, &arb) else {
            // Some cluster cannot be reached at all (penalties never forbid an arc): no tour.
            return Some((INF, *iterations));
        };
        let mut close = (INF, usize::MAX);
        for a in (0..m).filter(|&a| a != depot) {
            if matrix[a * m + depot] < close.0 {
                close = (matrix[a * m + depot], a);
            }
        }
        if close.1 == usize::MAX {
            return Some((INF, *iterations));
        }
        let value = tree_cost + close.0 - mu.iter().sum::<f64>();
        g_lambda.iter_mut().for_each(|g| *g = 0.0);
        g_mu.iter_mut().for_each(|g| *g = -1.0);
        let arcs = (0..m)
            .filter(|&v| v != depot)
            .map(|v| (parent[v], v))
            .chain(std::iter::once((close.1, depot)));
        for (a, b) in arcs {
            let (x, y) = arg[a * m + b];
            g_lambda[y as usize] += 1.0;
            g_lambda[x as usize] -= 1.0;
            g_mu[a] += 1.0;
        }
        if value > *best + 1e-9 {
            *best = value;
            *since_improvement = 0;
        } else {
            *since_improvement += 1;
            if *since_improvement >= 20 {
                *scale /= 2.0;
                *since_improvement = 0;
            }
        }
        *iterations += 1;
        let norm: f64 = g_lambda.iter().chain(g_mu.iter()).map(|g| g * g).sum();
        if norm == 0.0
            || *scale < 1e-3
            || *iterations >= options.iterations
            || (*iterations as f64 + 1.0) * per_iteration > options.work
            || (upper_bound.is_finite() && model.round_bound(*best) >= upper_bound)
        {
            return Some((*best, *iterations));
        }
        let target = if upper_bound.is_finite() && upper_bound > *best {
            upper_bound
        } else {
            *best + 0.05 * best.abs() + 1.0
        };
        let step = *scale * (target - value) / norm;
        for (l, g) in lambda.iter_mut().zip(g_lambda.iter()) {
            *l += step * g;
        }
        for (u, g) in mu.iter_mut().zip(g_mu.iter()) {
            *u += step * g;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every parent function without cycles, by enumeration.
    fn brute(k: usize, root: usize, w: &[f64]) -> Option<f64> {
        let others: Vec<usize> = (0..k).filter(|&v| v != root).collect();
        let mut best: Option<f64> = None;
        let total = k.pow(others.len() as u32);
        for code in 0..total {
            let mut parent = vec![usize::MAX; k];
            let mut c = code;
            for &v in &others {
                parent[v] = c % k;
                c /= k;
            }
            let acyclic = others.iter().all(|&v| {
                let mut u = v;
                for _ in 0..k {
                    if u == root {
                        return true;
                    }
                    u = parent[u];
                }
                false
            });
            if !acyclic || others.iter().any(|&v| parent[v] == v) {
                continue;
            }
            let cost: f64 = others.iter().map(|&v| w[parent[v] * k + v]).sum();
            if cost.is_finite() && best.is_none_or(|b| cost < b) {
                best = Some(cost);
            }
        }
        best
    }

    #[test]
    fn min_arborescence_matches_enumeration() {
        let mut rng = cutroute_geometry::SplitMix64::new(12345);
        let mut next = |bound: u64| rng.below(bound);
        for case in 0..400 {
            let k = 2 + case % 5;
            let root = next(k as u64) as usize;
            let w: Vec<f64> = (0..k * k)
                .map(|i| {
                    if i / k == i % k || next(5) == 0 {
                        INF
                    } else {
                        next(20) as f64 - 5.0
                    }
                })
                .collect();
            let expected = brute(k, root, &w);
            let got = min_arborescence(k, root, &w);
            match (expected, got) {
                (None, None) => {}
                (Some(e), Some((c, parent))) => {
                    assert!((e - c).abs() < 1e-9, "case {case}: {c} vs {e}");
                    let sum: f64 = (0..k)
                        .filter(|&v| v != root)
                        .map(|v| w[parent[v] * k + v])
                        .sum();
                    assert!((sum - c).abs() < 1e-9, "case {case}: parents do not add up");
                }
                (e, g) => panic!("case {case}: expected {e:?}, got {g:?}"),
            }
        }
    }

    /// Paused after every iteration, both ascents end with what they give in one piece: the
    /// same penalties, bounds and iterations.
    #[test]
    fn the_ascents_in_pieces_equal_the_ascents_at_once() {
        for name in ["ft70.2", "ESC47"] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../data/pcgtsp/pcgtsplib/{name}.pcglns"));
            let instance = Instance::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
            let model = Model::new(&instance, instance.clusters[instance.depot][0]).unwrap();
            let options = PenaltyOptions {
                iterations: 150,
                work: f64::INFINITY,
            };
            let whole = optimise(&instance, &model, INF, options).expect("a feasible root");
            let mut ascent = PenaltyAscent::new(&model, INF, options).unwrap();
            let mut pieces = 0;
            let sliced = loop {
                pieces += 1;
                if let Some(p) = ascent.advance(&instance, &model, &|| true) {
                    break p.expect("a penalised model");
                }
            };
            assert_eq!(sliced.lambda, whole.lambda, "{name}");
            assert_eq!(sliced.root_bound, whole.root_bound, "{name}");
            assert_eq!(sliced.iterations, whole.iterations, "{name}");
            assert!(pieces > 10, "{name}: {pieces} pieces");
            let lambda = Some(whole.lambda.as_slice());
            let whole = arborescence_bound(&model, INF, lambda, options).unwrap();
            let mut ascent = ArborescenceAscent::new(&model, INF, lambda, options).unwrap();
            let sliced = loop {
                if let Some(result) = ascent.advance(&model, &|| true) {
                    break result;
                }
            };
            assert_eq!(sliced, whole, "{name}");
            assert!(whole.1 > 10, "{name}: {} iterations", whole.1);
        }
    }
}
