//! The position-indexed completion bound: a per-state lower bound that sees precedence.
//!
//! In every feasible tour (depot at position 0) cluster `c` sits at a position `p` with
//! `|pred(c)| ≤ p ≤ m − 1 − |succ(c)|` (`pred` includes the depot). Relaxing "every cluster is
//! visited exactly once" to "position `p` holds a node of a cluster whose window contains `p`"
//! leaves a shortest-walk problem over (position, node) — solved backwards in `O(m · arcs)`.
//! Two relaxations make it tight:
//!
//! - **Lagrangian cluster penalties** `μ_c` on "visited once": a visit of `y` costs
//!   `c(x, y) − μ_{cl(y)}` and the bound adds `Σ μ_c` over the clusters the walk still has to
//!   visit; valid for every `μ` (the tour's own walk visits each exactly once). `μ` is chosen by
//!   subgradient ascent on the root value (subgradient `1 − visits(c)`).
//! - **2-cycle elimination**: the walk never goes `A → B → A`; every (position, node) keeps its
//!   best completion and the best one whose next cluster differs.
//!
//! Arcs are filtered by the relaxed precedence of [`Model::admissible`] (`A → B` only if
//! neither `B ≺ A` nor some `K` with `A ≺ K ≺ B`).
//!
//! A DP state (ideal `J` of `k` clusters, last node `x` at position `k − 1`) is bounded by
//! `Σ_{c ∉ J} μ_c + min_y [c(x, y) − μ_{cl(y)} + h(k, y)]` over the nodes `y` of clusters that
//! can follow (`pred ⊆ J`, not in `J`), where `h(k, y)` is the table's completion from `y` at
//! position `k` (its second-best when the best continues into a cluster of `J`). The table is
//! built once; a state costs one pass over the candidate next nodes.

use crate::instance::Instance;
use crate::model::Model;
use crate::order::OrderError;

const INF: f64 = f64::INFINITY;
/// Marks "no next cluster" (the completion ends at the start node).
const NONE: u16 = u16::MAX;
/// Polyak steps aim this share above the incumbent's cost, and start at this scale: aiming at
/// the incumbent itself takes steps too short to leave the first plateau (rbg048a: root 278.3
/// after 1,100 iterations aiming 1 % above, 281.0 after 370 aiming 10 % above with scale 2).
const TARGET_MARGIN: f64 = 0.1;
const INITIAL_SCALE: f64 = 2.0;

/// Settings of the subgradient optimisation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PositionBoundOptions {
    /// At most this many subgradient iterations.
    pub iterations: usize,
    /// Stop once this many elementary steps (arc relaxations) are spent.
    pub work: f64,
    /// After this many steps, stop unless the bound is within 1 % of `known_bound`: where
    /// another root bound is clearly stronger, the rest of the budget would be wasted.
    pub probe_work: f64,
    /// The best root bound known from other relaxations (`-INF` if none).
    pub known_bound: f64,
}

/// The completion table and its penalties.
#[derive(Clone, Debug)]
pub(crate) struct PositionBound {
    n: usize,
    /// Penalty per cluster (0 for the depot).
    mu: Vec<f64>,
    /// Window of every cluster: first and last possible position.
    first: Vec<usize>,
    last: Vec<usize>,
    /// `m × n` (position-major): cheapest penalised completion from node `x` at position `p`
    /// (positions after `p`, then back to the start; `INF` if `x` cannot be at `p`).
    best: Vec<f64>,
    /// Cluster of the next node on that completion (`NONE` = back to the start).
    best_next: Vec<u16>,
    /// Cheapest completion whose next cluster differs from `best_next`.
    second: Vec<f64>,
    /// The root bound `Σ μ + walk(μ)` for the final `μ`.
    pub root_bound: f64,
    /// Subgradient iterations done.
    pub iterations: usize,
}

/// Scratch of one backward pass with the successors kept for tracing the root walk.
struct Pass {
    best: Vec<f64>,
    best_next: Vec<u16>,
    best_node: Vec<u32>,
    second: Vec<f64>,
    second_node: Vec<u32>,
}

/// The per-group part of a state bound ([`PositionBound::prepare`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct PositionQuery {
    /// Position of the next node.
    next_position: usize,
    /// `Σ μ` over the clusters not yet visited.
    remaining_penalty: f64,
    /// Candidate next nodes with their penalised completion `h − μ` (the arc is added per `x`).
    candidates: Vec<(u32, f64)>,
}

impl PositionQuery {
    /// Candidate next nodes of the prepared group.
    pub fn candidate_count(&self) -> usize {
        self.candidates.len()
    }
}

impl PositionBound {
    /// Elementary steps of one backward pass (for sizing the subgradient budget).
    pub fn pass_work(model: &Model) -> f64 {
        let (first, last) = windows(model);
        let m = model.m;
        let mut work = 0.0;
        for p in 1..m.saturating_sub(1) {
            let here: usize = (0..m)
                .filter(|&a| first[a] <= p && p <= last[a])
                .map(|a| model.cluster_nodes[a].len())
                .sum();
            let next: usize = (0..m)
                .filter(|&b| first[b] <= p + 1 && p < last[b])
                .map(|b| model.cluster_nodes[b].len())
                .sum();
            work += (here * next) as f64;
        }
        work.max(1.0)
    }

    /// Builds the table with penalties optimised towards `upper_bound` (a tour cost or `INF`).
    /// Returns `None` when the relaxation is infeasible (then so is the instance).
    pub fn build(
        model: &Model,
        upper_bound: f64,
        options: PositionBoundOptions,
    ) -> Option<PositionBound> {
        let mut ascent = PositionAscent::new(model, upper_bound, options)?;
        loop {
            if let Some(bound) = ascent.advance(model, &|| false) {
                return Some(bound);
            }
        }
    }

    /// Prepares the bound of the states of ideal `in_ideal` (of `size` clusters) ending in
    /// cluster `last_cluster`: the candidate next nodes and the remaining penalty.
    pub fn prepare(
        &self,
        model: &Model,
        in_ideal: impl Fn(usize) -> bool,
        size: usize,
        last_cluster: usize,
        query: &mut PositionQuery,
    ) {
        let m = model.m;
        let p = size;
        query.next_position = p;
        query.candidates.clear();
        query.remaining_penalty = (0..m).filter(|&c| !in_ideal(c)).map(|c| self.mu[c]).sum();
        if p >= m {
            return;
        }
        let row = p * self.n;
        for b in 0..m {
            if in_ideal(b)
                || self.first[b] > p
                || p > self.last[b]
                || !model.admissible[last_cluster * m + b]
                || !model.order.predecessors[b].iter().all(&in_ideal)
            {
                continue;
            }
            for &y in &model.cluster_nodes[b] {
                let next = self.best_next[row + y];
                // The best completion continues into a visited cluster: take the second best
                // (its next cluster differs, and the tour's next cluster is unvisited).
                let h = if next != NONE && in_ideal(next as usize) {
                    self.second[row + y]
                } else {
                    self.best[row + y]
                };
                if h.is_finite() {
                    query.candidates.push((y as u32, h - self.mu[b]));
                }
            }
        }
    }

    /// Lower bound on the completion (back to the start) of a state of the prepared group
    /// ending at node `x`.
    #[inline]
    pub fn bound(&self, model: &Model, query: &PositionQuery, x: usize) -> f64 {
        let row = &model.cost[x * model.n..(x + 1) * model.n];
        let mut best = INF;
        for &(y, h) in &query.candidates {
            let v = row[y as usize] + h;
            if v < best {
                best = v;
            }
        }
        best + query.remaining_penalty
    }
}

/// [`PositionBound::build`]'s subgradient ascent, resumable between iterations (on ESC25 its
/// 625 backward passes took 1.6 s in one piece). The bound does not depend on where it pauses.
pub(crate) struct PositionAscent {
    upper_bound: f64,
    options: PositionBoundOptions,
    first: Vec<usize>,
    last: Vec<usize>,
    pass: Pass,
    mu: Vec<f64>,
    visits: Vec<usize>,
    per_pass: f64,
    value: f64,
    best: (f64, Vec<f64>),
    scale: f64,
    since_improvement: usize,
    iterations: usize,
}

impl PositionAscent {
    /// The ascent from zero penalties (its first backward pass done here); `None` when the
    /// relaxation is infeasible.
    pub fn new(
        model: &Model,
        upper_bound: f64,
        options: PositionBoundOptions,
    ) -> Option<PositionAscent> {
        let (m, n) = (model.m, model.n);
        let (first, last) = windows(model);
        let mut pass = Pass {
            best: vec![INF; m * n],
            best_next: vec![NONE; m * n],
            best_node: vec![u32::MAX; m * n],
            second: vec![INF; m * n],
            second_node: vec![u32::MAX; m * n],
        };
        let mu = vec![0.0; m];
        let mut visits = vec![0usize; m];
        let per_pass = PositionBound::pass_work(model);
        let value = backward_pass(model, &first, &last, &mu, &mut pass, &mut visits);
        if !value.is_finite() {
            return None;
        }
        Some(PositionAscent {
            upper_bound,
            options,
            first,
            last,
            pass,
            best: (value, mu.clone()),
            mu,
            visits,
            per_pass,
            value,
            scale: INITIAL_SCALE,
            since_improvement: 0,
            iterations: 0,
        })
    }

    /// Runs iterations until `pause()` (asked after each, so at least one is tried); the
    /// bound once the ascent ends.
    pub fn advance(&mut self, model: &Model, pause: &dyn Fn() -> bool) -> Option<PositionBound> {
        loop {
            if !self.iteration(model) {
                return Some(self.finish(model));
            }
            if pause() {
                return None;
            }
        }
    }

    /// One iteration; whether the ascent goes on.
    fn iteration(&mut self, model: &Model) -> bool {
        let (upper_bound, options, per_pass) = (self.upper_bound, self.options, self.per_pass);
        if self.iterations >= options.iterations
            || (self.iterations as f64 + 2.0) * per_pass > options.work
        {
            return false;
        }
        let best = self.best.0;
        if upper_bound.is_finite() && model.round_bound(best) >= upper_bound {
            return false;
        }
        // Still behind the other root bounds after `probe_work`: give up. (No earlier probe:
        // on p43.3 the root climbs from 257 after 100 iterations to 3,685 after 772, and the
        // state bounds then prove it.)
        let spent = (self.iterations as f64 + 1.0) * per_pass;
        let behind = best < options.known_bound - 0.01 * options.known_bound.abs();
        if behind && spent > options.probe_work {
            return false;
        }
        let m = model.m;
        let gradient: Vec<f64> = (0..m)
            .map(|c| {
                if c == model.depot {
                    0.0
                } else {
                    1.0 - self.visits[c] as f64
                }
            })
            .collect();
        let norm: f64 = gradient.iter().map(|g| g * g).sum();
        if norm == 0.0 {
            // The walk is a tour: no penalty raises the bound further.
            return false;
        }
        let target = if upper_bound.is_finite() && upper_bound > best {
            upper_bound + TARGET_MARGIN * upper_bound.abs().max(1.0)
        } else {
            best + 0.05 * best.abs() + 1.0
        };
        let step = self.scale * (target - self.value) / norm;
        for (u, g) in self.mu.iter_mut().zip(&gradient) {
            *u += step * g;
        }
        self.value = backward_pass(
            model,
            &self.first,
            &self.last,
            &self.mu,
            &mut self.pass,
            &mut self.visits,
        );
        self.iterations += 1;
        if !self.value.is_finite() {
            return false;
        }
        if self.value > self.best.0 + 1e-9 {
            self.best = (self.value, self.mu.clone());
            self.since_improvement = 0;
        } else {
            self.since_improvement += 1;
            if self.since_improvement >= 40 {
                self.scale /= 2.0;
                self.since_improvement = 0;
                if self.scale < 1e-3 {
                    return false;
                }
            }
        }
        true
    }

    /// The table of the best penalties.
    fn finish(&mut self, model: &Model) -> PositionBound {
        let mu = std::mem::take(&mut self.best.1);
        let root_bound = backward_pass(
            model,
            &self.first,
            &self.last,
            &mu,
            &mut self.pass,
            &mut self.visits,
        );
        PositionBound {
            n: model.n,
            mu,
            first: std::mem::take(&mut self.first),
            last: std::mem::take(&mut self.last),
            best: std::mem::take(&mut self.pass.best),
            best_next: std::mem::take(&mut self.pass.best_next),
            second: std::mem::take(&mut self.pass.second),
            root_bound,
            iterations: self.iterations,
        }
    }
}

/// First and last possible position of every cluster (the depot: 0).
fn windows(model: &Model) -> (Vec<usize>, Vec<usize>) {
    let m = model.m;
    let first = (0..m).map(|c| model.order.predecessors[c].len()).collect();
    let last = (0..m)
        .map(|c| {
            if c == model.depot {
                0
            } else {
                m - 1 - model.order.successors[c].len()
            }
        })
        .collect();
    (first, last)
}

/// One backward pass under penalties `mu`: fills `pass`, returns the root bound
/// `Σ μ + walk(μ)` and the visits of the root walk in `visits`.
fn backward_pass(
    model: &Model,
    first: &[usize],
    last: &[usize],
    mu: &[f64],
    pass: &mut Pass,
    visits: &mut [usize],
) -> f64 {
    let (m, n) = (model.m, model.n);
    let depot = model.depot;
    let start = model.start;
    pass.best.iter_mut().for_each(|v| *v = INF);
    pass.second.iter_mut().for_each(|v| *v = INF);
    pass.best_next.iter_mut().for_each(|v| *v = NONE);
    visits.iter_mut().for_each(|v| *v = 0);
    if m == 1 {
        return model.arc(start, start);
    }
    for p in (0..m).rev() {
        let row = p * n;
        for a in 0..m {
            let at_p = if p == 0 {
                a == depot
            } else {
                a != depot && first[a] <= p && p <= last[a]
            };
            if !at_p {
                continue;
            }
            for &x in &model.cluster_nodes[a] {
                let (mut v1, mut c1, mut y1) = (INF, NONE, u32::MAX);
                let (mut v2, mut y2) = (INF, u32::MAX);
                if p == m - 1 {
                    if model.admissible[a * m + depot] {
                        v1 = model.arc(x, start);
                    }
                } else {
                    let next_row = (p + 1) * n;
                    let arcs = &model.cost[x * n..(x + 1) * n];
                    for b in 0..m {
                        if b == depot
                            || first[b] > p + 1
                            || p + 1 > last[b]
                            || !model.admissible[a * m + b]
                        {
                            continue;
                        }
                        let (mut vb, mut yb) = (INF, u32::MAX);
                        for &y in &model.cluster_nodes[b] {
                            let h = if pass.best_next[next_row + y] as usize == a {
                                pass.second[next_row + y]
                            } else {
                                pass.best[next_row + y]
                            };
                            let v = arcs[y] + h;
                            if v < vb {
                                vb = v;
                                yb = y as u32;
                            }
                        }
                        let vb = vb - mu[b];
                        if vb < v1 {
                            v2 = v1;
                            y2 = y1;
                            v1 = vb;
                            c1 = b as u16;
                            y1 = yb;
                        } else if vb < v2 {
                            v2 = vb;
                            y2 = yb;
                        }
                    }
                }
                pass.best[row + x] = v1;
                pass.best_next[row + x] = if p == m - 1 { NONE } else { c1 };
                pass.best_node[row + x] = y1;
                pass.second[row + x] = v2;
                pass.second_node[row + x] = y2;
            }
        }
    }
    let walk = pass.best[start];
    if !walk.is_finite() {
        return INF;
    }
    // Trace the root walk for the subgradient.
    let mut x = start;
    let mut use_best = true;
    for p in 0..m - 1 {
        let y = if use_best {
            pass.best_node[p * n + x]
        } else {
            pass.second_node[p * n + x]
        } as usize;
        visits[model.node_cluster[y]] += 1;
        use_best = pass.best_next[(p + 1) * n + y] as usize != model.node_cluster[x];
        x = y;
    }
    walk + mu.iter().sum::<f64>()
}

/// The position-indexed bound of an instance, for inspection and tests.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionBounds {
    /// The root bound: minimum over the depot's nodes.
    pub root: f64,
    /// Subgradient iterations done (summed over the depot's nodes).
    pub iterations: usize,
    /// For the `tour` given to [`position_bounds`]: the bound of every DP state along it, i.e.
    /// the cost of its first `k` nodes plus the completion bound of that prefix, for
    /// `k = 2 … m − 1`. Each is at most the tour's cost (the tour completes its own prefix).
    pub along_tour: Vec<f64>,
}

/// Computes the position-indexed completion bound of `instance` with penalties optimised for
/// at most `iterations` subgradient steps towards `upper_bound` (a tour cost, or `INF`), and,
/// if `tour` (0-based nodes starting in the depot) is given, the bounds of the DP states along
/// it. The root is `INF` when the relaxation (hence the instance) is infeasible.
pub fn position_bounds(
    instance: &Instance,
    tour: Option<&[usize]>,
    upper_bound: f64,
    iterations: usize,
) -> Result<PositionBounds, OrderError> {
    let options = PositionBoundOptions {
        iterations,
        work: f64::INFINITY,
        probe_work: f64::INFINITY,
        known_bound: -INF,
    };
    let mut result = PositionBounds {
        root: INF,
        iterations: 0,
        along_tour: Vec::new(),
    };
    for &start in &instance.clusters[instance.depot] {
        let model = Model::new(instance, start)?;
        let Some(bound) = PositionBound::build(&model, upper_bound, options) else {
            continue;
        };
        result.root = result.root.min(bound.root_bound);
        result.iterations += bound.iterations;
        let Some(tour) = tour.filter(|t| t.first() == Some(&start)) else {
            continue;
        };
        let mut query = PositionQuery::default();
        let mut in_prefix = vec![false; model.m];
        in_prefix[model.depot] = true;
        let mut cost = 0.0;
        for k in 2..model.m {
            let (x, y) = (tour[k - 2], tour[k - 1]);
            cost += model.arc(x, y);
            let last = model.node_cluster[y];
            in_prefix[last] = true;
            bound.prepare(&model, |c| in_prefix[c], k, last, &mut query);
            result
                .along_tour
                .push(cost + bound.bound(&model, &query, y));
        }
    }
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instance::Instance;

    /// Paused after every iteration, the ascent ends with the table built in one piece.
    #[test]
    fn the_ascent_in_pieces_equals_the_ascent_at_once() {
        for name in ["pcgtsplib/ESC25", "industrial/e1x_4"] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../data/pcgtsp/{name}.pcglns"));
            let instance = Instance::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
            let model = Model::new(&instance, instance.clusters[instance.depot][0]).unwrap();
            let options = PositionBoundOptions {
                iterations: 300,
                work: f64::INFINITY,
                probe_work: f64::INFINITY,
                known_bound: -INF,
            };
            let whole = PositionBound::build(&model, INF, options).expect("feasible");
            let mut ascent = PositionAscent::new(&model, INF, options).unwrap();
            let mut pieces = 0;
            let sliced = loop {
                pieces += 1;
                if let Some(bound) = ascent.advance(&model, &|| true) {
                    break bound;
                }
            };
            assert_eq!(format!("{sliced:?}"), format!("{whole:?}"), "{name}");
            assert!(
                whole.iterations > 10,
                "{name}: {} iterations",
                whole.iterations
            );
            assert_eq!(
                pieces,
                whole.iterations + 1,
                "{name}: a piece per iteration"
            );
        }
    }
}
