//! The restricted bound: solve a smaller PCGTSP exactly and use its optimum as a lower bound.
//!
//! Keep only a subset `S` of the clusters (always with the depot), ordered by the precedence
//! relation restricted to `S`, and replace the arc costs by shortest-path distances `d_S` whose
//! intermediate nodes lie in clusters outside `S ∪ {depot}`. Any feasible tour of the full
//! instance, read only at the clusters of `S`, is a feasible tour of this *restricted*
//! instance: it visits one node per cluster of `S`, in an order that respects every precedence
//! between them, and each of its arcs `x → y` replaces a segment of the full tour that passes
//! only through clusters outside `S` (each cluster is visited once, the depot only at the ends),
//! so the segment costs at least `d_S(x, y)`. Hence the restricted optimum, and any lower bound
//! proven for it, is a lower bound of the full instance. With `S` = all clusters, `d_S` is the
//! original cost and the bound is the optimum.
//!
//! The bound is strong where the assignment bounds collapse (lightly constrained instances whose
//! cost lies in the precedences), as long as `S` holds the clusters that make tours expensive.
//! `S` is chosen by farthest insertion along a guide tour (usually the incumbent) under a cap
//! on the number of order ideals of the restricted order, and grows in rounds while time
//! remains; every round runs the exact solver on the restricted instance.

use crate::check::check_tour;
use crate::instance::Instance;
use crate::order::{OrderError, PrecedenceOrder};
use crate::solver::{ExactOptions, ExactSolver};
use cutroute_anytime::Status;
use std::time::Duration;
use web_time::Instant;

const INF: f64 = f64::INFINITY;

/// Settings of [`restricted_bound`].
#[derive(Clone, Debug, PartialEq)]
pub struct RestrictedBoundOptions {
    /// Total time for all rounds.
    pub time_limit: Duration,
    /// Clusters (besides the depot) in the first round.
    pub first_size: usize,
    /// Clusters added per round.
    pub growth: usize,
    /// Largest number of order ideals a restricted order may have.
    pub max_ideals: u64,
    /// Memory for each restricted exact solve.
    pub memory_limit_bytes: usize,
    /// A bound already known by other means (e.g. the root assignment bound). When the subset
    /// bound is still below 80 % of it after two rounds, growing the subset is unlikely to beat
    /// it in time and the rounds stop.
    pub known_bound: f64,
}

impl Default for RestrictedBoundOptions {
    fn default() -> Self {
        RestrictedBoundOptions {
            time_limit: Duration::from_secs(10),
            first_size: 12,
            growth: 4,
            max_ideals: 400_000,
            memory_limit_bytes: 1 << 29,
            known_bound: 0.0,
        }
    }
}

/// Why the restricted bound could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RestrictedBoundError {
    /// The precedence pairs are not a partial order with the depot first.
    #[error(transparent)]
    Order(#[from] OrderError),
    /// The guide tour is not a feasible tour of the instance.
    #[error("the guide tour is infeasible: {0}")]
    InfeasibleGuide(String),
}

/// The outcome of [`restricted_bound`].
#[derive(Clone, Debug, PartialEq)]
pub struct RestrictedBound {
    /// The best lower bound over the rounds (rounded up for integral costs).
    pub lower_bound: f64,
    /// Clusters (besides the depot) of the round that gave it.
    pub clusters: usize,
    /// Whether that round proved the restricted optimum.
    pub proven: bool,
    /// Rounds run.
    pub rounds: usize,
}

/// Shortest-path distances between all nodes whose intermediate nodes all satisfy
/// `via(node)` (Floyd–Warshall over the allowed intermediates; `INF` where unreachable).
pub(crate) fn metric_closure(instance: &Instance, via: &dyn Fn(usize) -> bool) -> Vec<f64> {
    let n = instance.node_count;
    let mut d = instance.cost.clone();
    for x in 0..n {
        d[x * n + x] = 0.0;
    }
    for k in (0..n).filter(|&k| via(k)) {
        let row_k: Vec<f64> = d[k * n..(k + 1) * n].to_vec();
        for i in 0..n {
            let dik = d[i * n + k];
            if !dik.is_finite() {
                continue;
            }
            let row_i = &mut d[i * n..(i + 1) * n];
            for (dij, &dkj) in row_i.iter_mut().zip(&row_k) {
                let via = dik + dkj;
                if via < *dij {
                    *dij = via;
                }
            }
        }
    }
    d
}

/// The instance restricted to the depot and `chosen` (cluster ids of `instance`), with metric
/// costs `d`. Returns it with the map from its nodes to the original nodes.
fn restrict(
    instance: &Instance,
    order: &PrecedenceOrder,
    d: &[f64],
    chosen: &[usize],
) -> (Instance, Vec<usize>) {
    let n = instance.node_count;
    let mut clusters_kept = vec![instance.depot];
    clusters_kept.extend(chosen.iter().copied().filter(|&c| c != instance.depot));
    let mut original_node = Vec::new();
    let mut clusters = Vec::new();
    let mut node_cluster = Vec::new();
    for (new_c, &c) in clusters_kept.iter().enumerate() {
        let mut nodes = Vec::new();
        for &x in &instance.clusters[c] {
            nodes.push(original_node.len());
            node_cluster.push(new_c);
            original_node.push(x);
        }
        clusters.push(nodes);
    }
    let k = original_node.len();
    let mut cost = vec![INF; k * k];
    for (i, &x) in original_node.iter().enumerate() {
        for (j, &y) in original_node.iter().enumerate() {
            if node_cluster[i] != node_cluster[j] {
                cost[i * k + j] = d[x * n + y];
            }
        }
    }
    let mut precedence = Vec::new();
    for (i, &a) in clusters_kept.iter().enumerate().skip(1) {
        for (j, &b) in clusters_kept.iter().enumerate().skip(1) {
            if order.precedes(a, b) {
                precedence.push((i, j));
            }
        }
    }
    let restricted = Instance {
        name: format!("{} (subset of {})", instance.name, chosen.len()),
        node_count: k,
        cost,
        clusters,
        node_cluster,
        precedence,
        depot: 0,
    };
    (restricted, original_node)
}

/// Orders `count` clusters (besides the depot) by farthest insertion along the guide tour:
/// each step adds the cluster whose cheapest node raises the metric length of the guide tour
/// restricted to the chosen clusters the most. Clusters that would push the restricted order
/// over `max_ideals` ideals are skipped.
fn farthest_insertion(
    instance: &Instance,
    order: &PrecedenceOrder,
    d: &[f64],
    guide: &[usize],
    count: usize,
    max_ideals: u64,
) -> Vec<usize> {
    let n = instance.node_count;
    let m = instance.clusters.len();
    // Position of every cluster in the guide tour.
    let mut position = vec![0usize; m];
    for (p, &x) in guide.iter().enumerate() {
        position[instance.node_cluster[x]] = p;
    }
    let mut in_subset = vec![false; m];
    in_subset[instance.depot] = true;
    let mut rejected = vec![false; m];
    let mut chosen: Vec<usize> = Vec::new();
    while chosen.len() < count {
        // Guide nodes of the subset, in tour order (the tour is closed at guide[0]).
        let mut best: Option<((f64, f64), usize)> = None;
        for c in 0..m {
            if in_subset[c] || rejected[c] {
                continue;
            }
            let p = position[c];
            let before = (0..p)
                .rev()
                .map(|q| guide[q])
                .find(|&x| in_subset[instance.node_cluster[x]])
                .unwrap_or(guide[0]);
            let after = (p + 1..guide.len())
                .map(|q| guide[q])
                .find(|&x| in_subset[instance.node_cluster[x]])
                .unwrap_or(guide[0]);
            let mut increase = INF;
            for &x in &instance.clusters[c] {
                increase =
                    increase.min(d[before * n + x] + d[x * n + after] - d[before * n + after]);
            }
            // Ties (common where many arcs cost 0) go to the cluster with the most precedence
            // relations: on heavily constrained instances those carry the cost.
            let relations = (order.predecessors[c].len() + order.successors[c].len()) as f64;
            let score = (increase, relations);
            if best.is_none_or(|(b, _)| score > b) {
                best = Some((score, c));
            }
        }
        let Some((_, c)) = best else {
            break;
        };
        in_subset[c] = true;
        chosen.push(c);
        let (sub, _) = restrict(instance, order, d, &chosen);
        let fits = PrecedenceOrder::new(&sub)
            .ok()
            .and_then(|o| o.count_ideals(max_ideals))
            .is_some();
        if !fits {
            chosen.pop();
            in_subset[c] = false;
            rejected[c] = true;
        }
    }
    chosen
}

/// Computes the restricted bound within `options.time_limit`, choosing subsets along `guide` (a
/// feasible tour, 0-based nodes starting in the depot; the incumbent is a good choice).
/// `stop_at` ends the rounds early once a bound this large is found (e.g. the incumbent's cost).
pub fn restricted_bound(
    instance: &Instance,
    guide: &[usize],
    stop_at: f64,
    options: &RestrictedBoundOptions,
) -> Result<RestrictedBound, RestrictedBoundError> {
    let began = Instant::now();
    check_tour(instance, guide)
        .map_err(|e| RestrictedBoundError::InfeasibleGuide(e.to_string()))?;
    let order = PrecedenceOrder::new(instance)?;
    // For choosing subsets: distances through any node.
    let d = metric_closure(instance, &|_| true);
    let integral = instance
        .cost
        .iter()
        .all(|c| !c.is_finite() || c.fract() == 0.0);
    let m = instance.clusters.len();
    let mut result = RestrictedBound {
        lower_bound: 0.0,
        clusters: 0,
        proven: false,
        rounds: 0,
    };
    let mut size = options.first_size.min(m - 1);
    let mut last_size = usize::MAX;
    while size > 0 && size != last_size {
        let remaining = options.time_limit.saturating_sub(began.elapsed());
        if remaining < Duration::from_millis(50) || result.lower_bound >= stop_at {
            break;
        }
        let chosen = farthest_insertion(instance, &order, &d, guide, size, options.max_ideals);
        if chosen.len() == last_size {
            break;
        }
        last_size = chosen.len();
        // The segment of a tour between two consecutive clusters of the subset only passes
        // through clusters outside it (never the depot): those are the allowed intermediates.
        let mut outside = vec![true; m];
        outside[instance.depot] = false;
        for &c in &chosen {
            outside[c] = false;
        }
        let d_outside = metric_closure(instance, &|x| outside[instance.node_cluster[x]]);
        let (sub, original_node) = restrict(instance, &order, &d_outside, &chosen);
        let sub_options = ExactOptions {
            time_limit: Some(remaining),
            memory_limit_bytes: options.memory_limit_bytes,
            heuristic: false,
            ..ExactOptions::default()
        };
        let Ok(mut solver) = ExactSolver::new(&sub, sub_options) else {
            break;
        };
        // The guide tour read at the chosen clusters is a tour of the restricted instance.
        let mut new_node = vec![usize::MAX; instance.node_count];
        for (i, &x) in original_node.iter().enumerate() {
            new_node[x] = i;
        }
        let sub_guide: Vec<usize> = guide
            .iter()
            .map(|&x| new_node[x])
            .filter(|&x| x != usize::MAX)
            .collect();
        solver.offer_incumbent(&sub_guide, INF);
        let status = loop {
            let status = solver.step(Duration::from_millis(100));
            if status != Status::Running {
                break status;
            }
        };
        result.rounds += 1;
        let mut lb = solver.progress().lower_bound;
        if integral && lb.is_finite() {
            lb = (lb - 1e-6).ceil();
        }
        let improved = lb > result.lower_bound;
        if improved {
            result.lower_bound = lb;
            result.clusters = chosen.len();
            result.proven = matches!(
                status,
                Status::Finished {
                    proven_optimal: true
                }
            );
        }
        // Stop when the restricted solve ran out of time, or when growing the subset stopped
        // paying (heavily constrained instances with many zero-cost arcs: the metric closure
        // erases their cost, and the time is better left to the exact search).
        let hopeless = result.rounds >= 2 && result.lower_bound < 0.8 * options.known_bound;
        if !matches!(status, Status::Finished { .. })
            || (!improved && result.rounds >= 2)
            || hopeless
        {
            break;
        }
        size = (size + options.growth).min(m - 1);
    }
    Ok(result)
}
