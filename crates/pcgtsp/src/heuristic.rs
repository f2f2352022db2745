//! A simple improvement heuristic for initial upper bounds: for a precedence-feasible cluster
//! order, choose the best node of every cluster (exact, by a DP along the cycle), and move
//! clusters or short cluster chains to better precedence-feasible positions (or-opt).

use crate::model::Model;
use crate::order::ClusterSet;
use web_time::Instant;

const INF: f64 = f64::INFINITY;

/// Best node choice for a fixed cluster order (first cluster = depot with the model's start
/// node). Returns the nodes and the closed-tour cost (`INF` if every choice hits a forbidden arc).
pub(crate) fn best_nodes(model: &Model, clusters: &[usize]) -> (Vec<usize>, f64) {
    let m = clusters.len();
    let start = model.start;
    let mut layers: Vec<Vec<(f64, usize)>> = Vec::with_capacity(m);
    layers.push(vec![(0.0, usize::MAX)]);
    let mut prev_nodes: &[usize] = std::slice::from_ref(&model.start);
    for &c in &clusters[1..] {
        let nodes = &model.cluster_nodes[c];
        let prev = layers.last().expect("non-empty");
        let mut layer = Vec::with_capacity(nodes.len());
        for &x in nodes {
            let mut best = (INF, usize::MAX);
            for (i, &u) in prev_nodes.iter().enumerate() {
                let v = prev[i].0 + model.arc(u, x);
                if v < best.0 {
                    best = (v, i);
                }
            }
            layer.push(best);
        }
        layers.push(layer);
        prev_nodes = nodes;
    }
    let last = layers.last().expect("non-empty");
    let mut best = (INF, usize::MAX);
    for (i, &u) in prev_nodes.iter().enumerate() {
        let v = last[i].0 + model.arc(u, start);
        if v < best.0 {
            best = (v, i);
        }
    }
    if !best.0.is_finite() {
        return (Vec::new(), INF);
    }
    let mut nodes = vec![0; m];
    let mut index = best.1;
    for pos in (0..m).rev() {
        nodes[pos] = if pos == 0 {
            start
        } else {
            model.cluster_nodes[clusters[pos]][index]
        };
        index = layers[pos][index].1;
    }
    (nodes, best.0)
}

/// Improves a feasible node tour in place by or-opt cluster-chain moves (with node re-selection
/// after every accepted move) until no move helps, `budget_moves` evaluations are used or the
/// clock passes `deadline` (each evaluation is a DP over every cluster's nodes: on a
/// discretised nest of 5,000 nodes 20,000 of them take 20 s, so the caller's slice must bound
/// them too). The tour is the best found either way.
pub(crate) fn improve(
    model: &Model,
    tour: &mut Vec<usize>,
    budget_moves: usize,
    deadline: Instant,
) -> f64 {
    let m = tour.len();
    let mut clusters: Vec<usize> = tour.iter().map(|&v| model.node_cluster[v]).collect();
    let (mut nodes, mut cost) = best_nodes(model, &clusters);
    if !cost.is_finite() {
        return INF;
    }
    let mut evaluations = 0usize;
    let mut improved = true;
    while improved && evaluations < budget_moves && Instant::now() < deadline {
        improved = false;
        'moves: for len in 1..=3usize {
            for i in 1..m {
                if i + len > m {
                    break;
                }
                // Chain clusters[i..i+len] moved to after position j (in the remaining order).
                for j in 0..m {
                    if j + 1 >= i && j < i + len {
                        continue;
                    }
                    evaluations += 1;
                    let candidate = moved(&clusters, i, len, j);
                    if !feasible(model, &candidate) {
                        continue;
                    }
                    let (cand_nodes, cand_cost) = best_nodes(model, &candidate);
                    if cand_cost < cost - 1e-9 {
                        clusters = candidate;
                        nodes = cand_nodes;
                        cost = cand_cost;
                        improved = true;
                        break 'moves;
                    }
                    if evaluations >= budget_moves || Instant::now() >= deadline {
                        break 'moves;
                    }
                }
            }
        }
    }
    *tour = nodes;
    cost
}

fn moved(clusters: &[usize], i: usize, len: usize, j: usize) -> Vec<usize> {
    let chain = &clusters[i..i + len];
    let mut rest: Vec<usize> = clusters[..i]
        .iter()
        .chain(&clusters[i + len..])
        .copied()
        .collect();
    let insert_at = if j < i { j + 1 } else { j + 1 - len };
    let tail = rest.split_off(insert_at);
    rest.extend_from_slice(chain);
    rest.extend(tail);
    rest
}

fn feasible(model: &Model, clusters: &[usize]) -> bool {
    let mut seen = crate::order::ClusterSet::new(model.m);
    for &c in clusters {
        if !model.order.predecessors[c].is_subset(&seen) {
            return false;
        }
        seen.insert(c);
    }
    true
}

/// Nearest-neighbour construction on the prepared model (see [`nearest_neighbour_tour`]).
pub(crate) fn greedy(model: &Model) -> Option<Vec<usize>> {
    greedy_tour(
        model.start,
        model.depot,
        &model.cluster_nodes,
        &|c, visited| model.order.predecessors[c].is_subset(visited),
        &|a, b| model.arc(a, b),
    )
}

/// Nearest-neighbour construction: from node `start` (of cluster `start_cluster`), repeatedly
/// move to the cheapest node of any cluster whose predecessors (the `precedence` pairs
/// `(before, after)`) are all visited, and close the tour back to `start`. Returns the tour and
/// its cost, `None` if it gets stuck on forbidden (infinite) arcs. `arc` need not be a stored
/// matrix: a discretised nest's first tour is made this way from its points when the time
/// limit comes before its matrix is built.
///
/// ```
/// use cutroute_pcgtsp::nearest_neighbour_tour;
///
/// // Depot node 0, then clusters {1, 2} and {3}; cluster 1 must come before cluster 2.
/// let clusters = vec![vec![0], vec![1, 2], vec![3]];
/// let x: [f64; 4] = [0.0, 5.0, 1.0, 2.0];
/// let arc = |a: usize, b: usize| (x[a] - x[b]).abs();
/// let (tour, cost) = nearest_neighbour_tour(0, 0, &clusters, &[(1, 2)], &arc).unwrap();
/// assert_eq!(tour, vec![0, 2, 3]);
/// assert_eq!(cost, 1.0 + 1.0 + 2.0);
/// ```
pub fn nearest_neighbour_tour(
    start: usize,
    start_cluster: usize,
    cluster_nodes: &[Vec<usize>],
    precedence: &[(usize, usize)],
    arc: &dyn Fn(usize, usize) -> f64,
) -> Option<(Vec<usize>, f64)> {
    let mut predecessors = vec![Vec::new(); cluster_nodes.len()];
    for &(before, after) in precedence {
        predecessors.get_mut(after)?.push(before);
    }
    let tour = greedy_tour(
        start,
        start_cluster,
        cluster_nodes,
        &|c, visited| predecessors[c].iter().all(|&p| visited.contains(p)),
        arc,
    )?;
    let cost = tour
        .iter()
        .zip(tour.iter().cycle().skip(1))
        .map(|(&a, &b)| arc(a, b))
        .sum();
    Some((tour, cost))
}

/// The nearest-neighbour tour with `ready(c, visited)` saying whether cluster `c` may come next.
fn greedy_tour(
    start: usize,
    start_cluster: usize,
    cluster_nodes: &[Vec<usize>],
    ready: &dyn Fn(usize, &ClusterSet) -> bool,
    arc: &dyn Fn(usize, usize) -> f64,
) -> Option<Vec<usize>> {
    let m = cluster_nodes.len();
    let mut visited = ClusterSet::new(m);
    visited.insert(start_cluster);
    let mut tour = vec![start];
    let mut current = start;
    for _ in 1..m {
        let mut best = (INF, usize::MAX, usize::MAX);
        for (c, nodes) in cluster_nodes.iter().enumerate() {
            if visited.contains(c) || !ready(c, &visited) {
                continue;
            }
            for &x in nodes {
                let w = arc(current, x);
                if w < best.0 {
                    best = (w, c, x);
                }
            }
        }
        if best.1 == usize::MAX {
            return None;
        }
        visited.insert(best.1);
        tour.push(best.2);
        current = best.2;
    }
    arc(current, start).is_finite().then_some(tour)
}
