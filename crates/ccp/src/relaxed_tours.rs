//! Cheap tours of an interval relaxation (a PCGTSP without precedence whose depot is the start
//! and whose return arcs are the tails), to find where its optimum lies below the route.
//!
//! A relaxed tour can enter a piece at one end and leave it at the other, gaining up to the
//! piece's length per visit; the relaxed optimum exploits that slack where the pieces are long
//! next to short idle moves. Refining the pieces of the cheapest relaxed tours known raises
//! exactly those tours' costs, so the relaxation's optimum rises where it is lowest. These tours
//! only steer the refinement (and give the ng-path bound upper bounds): they prove nothing.
//!
//! The search: for a fixed cluster order the cheapest choice of pieces is a layered shortest
//! path ([`cheapest_pieces`]); a local search moves clusters and short chains (or-opt, the moved
//! single cluster's piece re-chosen for its new neighbours) and reverses segments (2-opt), then
//! re-chooses all pieces along the order, until no move helps; an iterated local search kicks
//! the best tour (a double bridge) and keeps the few cheapest distinct tours.

use cutroute_geometry::SplitMix64;
use cutroute_pcgtsp::Instance;
use web_time::Instant;

/// Cheapest distinct tours kept (their pieces are refined).
pub(crate) const POOL_SIZE: usize = 6;

/// Kicks in a row without a new tour in the pool after which the search stops.
const STALL_KICKS: usize = 150;

/// The cheapest nodes, one per cluster of `order` (non-depot clusters, each once), for a tour
/// depot → `order` → depot, and its cost: a shortest path through the layers of the clusters'
/// nodes, `O(Σ |A_i|·|A_{i+1}|)`. `None` when every choice meets an infinite arc.
pub(crate) fn cheapest_pieces(instance: &Instance, order: &[usize]) -> Option<(Vec<usize>, f64)> {
    let n = instance.node_count;
    let cost = &instance.cost;
    let depot = *instance.clusters[instance.depot].first()?;
    // Per layer: (cost so far, index of the predecessor in the previous layer).
    let mut layers: Vec<Vec<(f64, usize)>> = Vec::with_capacity(order.len());
    let mut prev_nodes: &[usize] = std::slice::from_ref(&depot);
    let mut prev: Vec<(f64, usize)> = vec![(0.0, usize::MAX)];
    for &c in order {
        let nodes = &instance.clusters[c];
        let mut layer = Vec::with_capacity(nodes.len());
        for &x in nodes {
            let mut best = (f64::INFINITY, usize::MAX);
            for (i, &u) in prev_nodes.iter().enumerate() {
                let value = prev[i].0 + cost[u * n + x];
                if value < best.0 {
                    best = (value, i);
                }
            }
            layer.push(best);
        }
        layers.push(layer.clone());
        prev = layer;
        prev_nodes = nodes;
    }
    let mut best = (f64::INFINITY, usize::MAX);
    for (i, &u) in prev_nodes.iter().enumerate() {
        let value = prev[i].0 + cost[u * n + depot];
        if value < best.0 {
            best = (value, i);
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let mut nodes = vec![0; order.len()];
    let mut index = best.1;
    for pos in (0..order.len()).rev() {
        nodes[pos] = instance.clusters[order[pos]][index];
        index = layers[pos][index].1;
    }
    Some((nodes, best.0))
}

/// The cost of the tour depot → `nodes` → depot.
pub(crate) fn tour_cost(instance: &Instance, nodes: &[usize]) -> f64 {
    let n = instance.node_count;
    let depot = instance.clusters[instance.depot][0];
    let mut total = 0.0;
    let mut at = depot;
    for &v in nodes.iter().chain(std::iter::once(&depot)) {
        total += instance.cost[at * n + v];
        at = v;
    }
    total
}

/// Improves `nodes` (one node per non-depot cluster) by 2-opt, or-opt (chains of 1–3, either
/// direction) and a re-choice of every piece along the order, until no move helps; returns
/// the cost. Each sweep is `O(m²)` moves (`O(m²·k)` with a single cluster's piece re-chosen).
pub(crate) fn local_search(instance: &Instance, nodes: &mut Vec<usize>) -> f64 {
    let n = instance.node_count;
    let depot = instance.clusters[instance.depot][0];
    let arc = |a: usize, b: usize| instance.cost[a * n + b];
    let mut current = tour_cost(instance, nodes);
    loop {
        let mut improved = false;
        // Sweeps of single moves with the pieces fixed (a moved single cluster re-chooses its
        // own piece), first improvement.
        'sweep: loop {
            let m = nodes.len();
            // ext[i]: the tour with the depot at both ends.
            let ext: Vec<usize> = std::iter::once(depot)
                .chain(nodes.iter().copied())
                .chain(std::iter::once(depot))
                .collect();
            // Prefix sums of the inner arcs forwards and backwards (reversed segments).
            let mut fwd = vec![0.0; m + 2];
            let mut bwd = vec![0.0; m + 2];
            for i in 1..m + 2 {
                fwd[i] = fwd[i - 1] + arc(ext[i - 1], ext[i]);
                bwd[i] = bwd[i - 1] + arc(ext[i], ext[i - 1]);
            }
            let eps = 1e-9 * (1.0 + current.abs());
            // 2-opt: reverse ext[i..=j] (1 ≤ i < j ≤ m).
            for i in 1..m {
                for j in i + 1..=m {
                    let before = fwd[j + 1] - fwd[i - 1];
                    let after =
                        arc(ext[i - 1], ext[j]) + (bwd[j] - bwd[i]) + arc(ext[i], ext[j + 1]);
                    if after < before - eps {
                        nodes[i - 1..j].reverse();
                        current += after - before;
                        improved = true;
                        continue 'sweep;
                    }
                }
            }
            // Or-opt: move ext[i..i+len) between ext[p] and ext[p+1] (outside the chain).
            for len in 1..=3.min(m) {
                for i in 1..=m + 1 - len {
                    let j = i + len - 1;
                    let (a, b) = (ext[i - 1], ext[j + 1]);
                    let removed = arc(a, ext[i]) + (fwd[j] - fwd[i]) + arc(ext[j], b) - arc(a, b);
                    let cluster = instance.node_cluster[ext[i]];
                    for p in 0..=m {
                        if p + 1 >= i && p <= j {
                            continue;
                        }
                        let (u, w) = (ext[p], ext[p + 1]);
                        let base = arc(u, w);
                        // The chain forwards, backwards, or (one cluster) at its best piece.
                        let forwards = arc(u, ext[i]) + (fwd[j] - fwd[i]) + arc(ext[j], w) - base;
                        let backwards = arc(u, ext[j]) + (bwd[j] - bwd[i]) + arc(ext[i], w) - base;
                        let mut best = (forwards, ext[i], false);
                        if backwards < best.0 {
                            best = (backwards, ext[i], true);
                        }
                        if len == 1 {
                            for &x in &instance.clusters[cluster] {
                                let value = arc(u, x) + arc(x, w) - base;
                                if value < best.0 {
                                    best = (value, x, false);
                                }
                            }
                        }
                        if best.0 < removed - eps {
                            let mut chain: Vec<usize> = ext[i..=j].to_vec();
                            if len == 1 {
                                chain[0] = best.1;
                            } else if best.2 {
                                chain.reverse();
                            }
                            // Positions in `nodes` are ext's minus one.
                            let mut rest: Vec<usize> = Vec::with_capacity(m);
                            for (q, &v) in ext.iter().enumerate().take(m + 1).skip(1) {
                                if q < i || q > j {
                                    rest.push(v);
                                }
                                if q == p {
                                    rest.extend_from_slice(&chain);
                                }
                            }
                            if p == 0 {
                                rest.splice(0..0, chain.iter().copied());
                            }
                            *nodes = rest;
                            current += best.0 - removed;
                            improved = true;
                            continue 'sweep;
                        }
                    }
                }
            }
            break;
        }
        // Every piece re-chosen for the order found.
        let order: Vec<usize> = nodes.iter().map(|&v| instance.node_cluster[v]).collect();
        if let Some((best, cost)) = cheapest_pieces(instance, &order) {
            if cost < current - 1e-9 * (1.0 + current.abs()) {
                *nodes = best;
                current = cost;
                improved = true;
            }
        }
        if !improved {
            // Recomputed: the deltas summed above carry rounding.
            return tour_cost(instance, nodes);
        }
    }
}

/// An iterated local search for cheap tours of one relaxed instance, resumable between slices
/// (the instance is passed to each call; it must be the same).
pub(crate) struct RelaxedTourSearch {
    /// Cluster orders still to start from (the incumbent's, the ng walk's).
    starts: Vec<Vec<usize>>,
    /// The cheapest distinct tours found (cost, nodes without the depot), cheapest first.
    pool: Vec<(f64, Vec<usize>)>,
    rng: SplitMix64,
    stalled: usize,
    kicks: usize,
}

impl RelaxedTourSearch {
    pub(crate) fn new(seed: u64) -> Self {
        RelaxedTourSearch {
            starts: Vec::new(),
            pool: Vec::new(),
            rng: SplitMix64::new(seed),
            stalled: 0,
            kicks: 0,
        }
    }

    /// Adds a start: a node or cluster sequence (the depot and repeated clusters are skipped;
    /// clusters it misses are inserted where they cost least).
    pub(crate) fn add_start(&mut self, instance: &Instance, walk: &[usize]) {
        let mut seen = vec![false; instance.clusters.len()];
        seen[instance.depot] = true;
        let mut order = Vec::new();
        for &v in walk {
            let Some(&c) = instance.node_cluster.get(v) else {
                continue;
            };
            if !seen[c] {
                seen[c] = true;
                order.push(c);
            }
        }
        // Missing clusters at their cheapest place between the nearest pieces of their
        // neighbours (their nodes are re-chosen by the layered path afterwards).
        let n = instance.node_count;
        let depot = instance.clusters[instance.depot][0];
        let near = |a: usize, c: usize| {
            let from: &[usize] = if a == instance.depot {
                std::slice::from_ref(&depot)
            } else {
                &instance.clusters[a]
            };
            let mut best = f64::INFINITY;
            for &u in from {
                for &x in &instance.clusters[c] {
                    best = best.min(instance.cost[u * n + x]);
                }
            }
            best
        };
        let missing: Vec<usize> = (0..instance.clusters.len())
            .filter(|&c| !seen[c] && !instance.clusters[c].is_empty())
            .collect();
        for c in missing {
            let mut best = (f64::INFINITY, order.len());
            for p in 0..=order.len() {
                let before = if p == 0 { instance.depot } else { order[p - 1] };
                let value = near(before, c) + order.get(p).map_or(0.0, |&next| near(c, next));
                if value < best.0 {
                    best = (value, p);
                }
            }
            order.insert(best.1, c);
        }
        self.starts.push(order);
    }

    /// The cheapest tours found (cost, nodes without the depot), cheapest first.
    pub(crate) fn pool(&self) -> &[(f64, Vec<usize>)] {
        &self.pool
    }

    /// The cheapest tour's cost (+∞ before any).
    pub(crate) fn best_cost(&self) -> f64 {
        self.pool.first().map_or(f64::INFINITY, |t| t.0)
    }

    /// Local searches (starts first, then kicks of the pool's tours) completed.
    pub(crate) fn kicks(&self) -> usize {
        self.kicks
    }

    /// Whether the search may still find cheaper tours.
    pub(crate) fn running(&self) -> bool {
        !self.starts.is_empty() || (!self.pool.is_empty() && self.stalled < STALL_KICKS)
    }

    /// Runs local searches until `deadline` (at least one); returns true when the pool's
    /// cheapest tour improved.
    pub(crate) fn step(&mut self, instance: &Instance, deadline: Instant) -> bool {
        let before = self.best_cost();
        loop {
            if !self.running() {
                break;
            }
            let start = if let Some(order) = self.starts.pop() {
                cheapest_pieces(instance, &order).map(|(nodes, _)| nodes)
            } else {
                // A double bridge on one of the pool's tours (the best one twice as often).
                let pick = self.rng.index_below(self.pool.len() + 1);
                let mut order: Vec<usize> = self.pool[pick.saturating_sub(1)]
                    .1
                    .iter()
                    .map(|&v| instance.node_cluster[v])
                    .collect();
                let m = order.len();
                if m >= 8 {
                    let mut cut: Vec<usize> =
                        (0..3).map(|_| 1 + self.rng.index_below(m - 1)).collect();
                    cut.sort_unstable();
                    let (a, b, c) = (cut[0], cut[1], cut[2]);
                    let mut kicked = order[..a].to_vec();
                    kicked.extend_from_slice(&order[b..c]);
                    kicked.extend_from_slice(&order[a..b]);
                    kicked.extend_from_slice(&order[c..]);
                    order = kicked;
                } else if m >= 2 {
                    let i = self.rng.index_below(m);
                    let j = self.rng.index_below(m);
                    order.swap(i, j);
                }
                cheapest_pieces(instance, &order).map(|(nodes, _)| nodes)
            };
            self.kicks += 1;
            if let Some(mut nodes) = start {
                let cost = local_search(instance, &mut nodes);
                if self.insert(cost, nodes) {
                    self.stalled = 0;
                } else {
                    self.stalled += 1;
                }
            } else {
                self.stalled += 1;
            }
            if Instant::now() >= deadline {
                break;
            }
        }
        self.best_cost() < before
    }

    /// Keeps the tour if it is among the `POOL_SIZE` cheapest distinct ones; whether it was.
    fn insert(&mut self, cost: f64, nodes: Vec<usize>) -> bool {
        if !cost.is_finite() || self.pool.iter().any(|(_, t)| *t == nodes) {
            return false;
        }
        if self.pool.len() >= POOL_SIZE && cost >= self.pool[POOL_SIZE - 1].0 {
            return false;
        }
        let at = self.pool.partition_point(|(c, _)| *c <= cost);
        self.pool.insert(at, (cost, nodes));
        self.pool.truncate(POOL_SIZE);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random instance: a depot and `m` clusters of 1–`k` nodes at random points, costs the
    /// distances (asymmetric when `skew`), the return arcs half the distance (a tail).
    fn random_instance(seed: u64, m: usize, k: usize, skew: bool) -> Instance {
        let mut rng = SplitMix64::new(seed);
        let mut next = move || rng.next_f64();
        let mut points = vec![(0.0, 0.0)];
        let mut clusters = vec![vec![0]];
        let mut node_cluster = vec![0];
        for c in 1..=m {
            let size = 1 + (next() * k as f64) as usize % k;
            let (cx, cy) = (next() * 100.0, next() * 100.0);
            let mut nodes = Vec::new();
            for _ in 0..size {
                nodes.push(points.len());
                node_cluster.push(c);
                points.push((cx + next() * 10.0, cy + next() * 10.0));
            }
            clusters.push(nodes);
        }
        let n = points.len();
        let mut cost = vec![f64::INFINITY; n * n];
        for a in 0..n {
            for b in 0..n {
                if a == b || (node_cluster[a] == node_cluster[b] && a != 0) {
                    continue;
                }
                let d = ((points[a].0 - points[b].0).powi(2) + (points[a].1 - points[b].1).powi(2))
                    .sqrt();
                cost[a * n + b] = if b == 0 {
                    0.5 * d
                } else if skew {
                    d * (1.0 + 0.3 * next())
                } else {
                    d
                };
            }
        }
        Instance {
            name: "random".into(),
            node_count: n,
            cost,
            clusters,
            node_cluster,
            precedence: Vec::new(),
            depot: 0,
        }
    }

    /// Every choice of one node per cluster along `order`, cheapest.
    fn brute_force_pieces(instance: &Instance, order: &[usize]) -> f64 {
        let mut best = f64::INFINITY;
        let mut index = vec![0usize; order.len()];
        loop {
            let nodes: Vec<usize> = order
                .iter()
                .zip(&index)
                .map(|(&c, &i)| instance.clusters[c][i])
                .collect();
            best = best.min(tour_cost(instance, &nodes));
            let mut pos = 0;
            loop {
                if pos == order.len() {
                    return best;
                }
                index[pos] += 1;
                if index[pos] < instance.clusters[order[pos]].len() {
                    break;
                }
                index[pos] = 0;
                pos += 1;
            }
        }
    }

    #[test]
    fn the_layered_path_equals_brute_force_over_piece_choices() {
        for seed in 1..40u64 {
            let instance = random_instance(seed, 5, 4, seed % 2 == 0);
            let mut order: Vec<usize> = (1..=5).collect();
            // A few orders per instance.
            for shift in 0..3 {
                order.rotate_left(shift);
                let (nodes, cost) = cheapest_pieces(&instance, &order).unwrap();
                let expected = brute_force_pieces(&instance, &order);
                assert!(
                    (cost - expected).abs() <= 1e-9 * (1.0 + expected),
                    "seed {seed}: layered {cost}, brute force {expected}"
                );
                assert!((tour_cost(&instance, &nodes) - cost).abs() <= 1e-9 * (1.0 + cost));
                let clusters: Vec<usize> =
                    nodes.iter().map(|&v| instance.node_cluster[v]).collect();
                assert_eq!(clusters, order);
            }
        }
    }

    /// Tours of a small instance by brute force over orders and pieces.
    fn brute_force_optimum(instance: &Instance) -> f64 {
        fn permute(k: usize, order: &mut Vec<usize>, instance: &Instance, best: &mut f64) {
            if k == order.len() {
                *best = best.min(brute_force_pieces(instance, order));
                return;
            }
            for i in k..order.len() {
                order.swap(k, i);
                permute(k + 1, order, instance, best);
                order.swap(k, i);
            }
        }
        let mut order: Vec<usize> = (1..instance.clusters.len()).collect();
        let mut best = f64::INFINITY;
        permute(0, &mut order, instance, &mut best);
        best
    }

    #[test]
    fn the_search_keeps_valid_tours_with_their_true_costs_and_finds_small_optima() {
        let mut optimal = 0;
        for seed in 1..30u64 {
            let instance = random_instance(seed, 6, 3, seed % 3 == 0);
            let mut search = RelaxedTourSearch::new(seed);
            search.add_start(&instance, &[0, 1]);
            while search.running() {
                search.step(&instance, Instant::now());
            }
            assert!(!search.pool().is_empty() && search.pool().len() <= POOL_SIZE);
            for window in search.pool().windows(2) {
                assert!(window[0].0 <= window[1].0);
            }
            for (cost, nodes) in search.pool() {
                let mut clusters: Vec<usize> =
                    nodes.iter().map(|&v| instance.node_cluster[v]).collect();
                clusters.sort_unstable();
                assert_eq!(clusters, (1..=6).collect::<Vec<_>>(), "seed {seed}");
                let true_cost = tour_cost(&instance, nodes);
                assert!((cost - true_cost).abs() <= 1e-9 * (1.0 + true_cost));
            }
            let optimum = brute_force_optimum(&instance);
            assert!(search.best_cost() >= optimum - 1e-9 * (1.0 + optimum));
            if search.best_cost() <= optimum + 1e-9 * (1.0 + optimum) {
                optimal += 1;
            }
        }
        // An iterated local search on 6 clusters finds the optimum nearly always.
        assert!(optimal >= 25, "optimal in {optimal} of 29");
    }

    #[test]
    fn local_search_never_raises_a_tour_cost() {
        for seed in 1..30u64 {
            let instance = random_instance(seed, 12, 4, seed % 2 == 1);
            let order: Vec<usize> = (1..=12).collect();
            let mut nodes: Vec<usize> = order.iter().map(|&c| instance.clusters[c][0]).collect();
            let before = tour_cost(&instance, &nodes);
            let after = local_search(&instance, &mut nodes);
            assert!(after <= before + 1e-9 * (1.0 + before));
            assert!((after - tour_cost(&instance, &nodes)).abs() <= 1e-9 * (1.0 + after));
            let mut clusters: Vec<usize> =
                nodes.iter().map(|&v| instance.node_cluster[v]).collect();
            clusters.sort_unstable();
            assert_eq!(clusters, order);
        }
    }
}
