//! The order of a chain: an open-path TSP from the point before the chain to the point after it.

/// The cheapest order of `n` members for a path `before → m₁ → … → mₙ → after` with
/// `enter[i]` the cost of starting at member i, `leave[i]` of ending at it, `between[i][j]` of
/// going from i to j. Exact (Held–Karp dynamic programming) for up to `exact_limit` members,
/// otherwise nearest neighbour improved by 2-opt and Or-opt moves until no move gains.
pub(crate) fn open_path_order(
    enter: &[f64],
    leave: &[f64],
    between: &[Vec<f64>],
    exact_limit: usize,
) -> Vec<usize> {
    let n = enter.len();
    if n <= 1 {
        return (0..n).collect();
    }
    if n <= exact_limit.min(16) {
        return held_karp(enter, leave, between);
    }
    let mut order = nearest_neighbour(enter, between);
    if n <= SMALL_CHAIN {
        improve(&mut order, enter, leave, between);
    } else {
        two_opt_symmetric(&mut order, enter, leave, between);
    }
    order
}

/// Up to this many members the heuristic evaluates every 2-opt and Or-opt move on the whole
/// order (O(n³) per pass); longer chains use 2-opt with O(1) gains.
const SMALL_CHAIN: usize = 60;

/// 2-opt for long chains, first improvement until no gain; `between` must be symmetric (it is
/// for contour-to-contour distances), so a reversal changes only its two boundary costs.
fn two_opt_symmetric(order: &mut [usize], enter: &[f64], leave: &[f64], between: &[Vec<f64>]) {
    let n = order.len();
    let mut improved = true;
    let mut passes = 0;
    while improved && passes < 100 {
        improved = false;
        passes += 1;
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (order[i], order[j]);
                let (left_old, left_new) = if i == 0 {
                    (enter[a], enter[b])
                } else {
                    (between[order[i - 1]][a], between[order[i - 1]][b])
                };
                let (right_old, right_new) = if j + 1 == n {
                    (leave[b], leave[a])
                } else {
                    (between[b][order[j + 1]], between[a][order[j + 1]])
                };
                if left_new + right_new < left_old + right_old - 1e-12 {
                    order[i..=j].reverse();
                    improved = true;
                }
            }
        }
    }
}

/// Cost of a whole order.
pub(crate) fn order_cost(
    order: &[usize],
    enter: &[f64],
    leave: &[f64],
    between: &[Vec<f64>],
) -> f64 {
    let (Some(&first), Some(&last)) = (order.first(), order.last()) else {
        return 0.0;
    };
    enter[first] + leave[last] + order.windows(2).map(|w| between[w[0]][w[1]]).sum::<f64>()
}

fn held_karp(enter: &[f64], leave: &[f64], between: &[Vec<f64>]) -> Vec<usize> {
    let n = enter.len();
    let full = 1usize << n;
    // cost[set][last]: cheapest path from `before` through `set`, ending at `last` ∈ set.
    let mut cost = vec![f64::INFINITY; full * n];
    let mut parent = vec![usize::MAX; full * n];
    for i in 0..n {
        cost[(1 << i) * n + i] = enter[i];
    }
    for set in 1..full {
        for last in 0..n {
            let here = cost[set * n + last];
            if set & (1 << last) == 0 || !here.is_finite() {
                continue;
            }
            for next in 0..n {
                if set & (1 << next) != 0 {
                    continue;
                }
                let grown = set | (1 << next);
                let c = here + between[last][next];
                if c < cost[grown * n + next] {
                    cost[grown * n + next] = c;
                    parent[grown * n + next] = last;
                }
            }
        }
    }
    let all = full - 1;
    let mut last = (0..n)
        .min_by(|&a, &b| (cost[all * n + a] + leave[a]).total_cmp(&(cost[all * n + b] + leave[b])))
        .unwrap_or(0);
    let mut set = all;
    let mut order = Vec::with_capacity(n);
    while last != usize::MAX {
        order.push(last);
        let previous = parent[set * n + last];
        set &= !(1 << last);
        last = previous;
    }
    order.reverse();
    order
}

fn nearest_neighbour(enter: &[f64], between: &[Vec<f64>]) -> Vec<usize> {
    let n = enter.len();
    let mut used = vec![false; n];
    let mut at = (0..n)
        .min_by(|&a, &b| enter[a].total_cmp(&enter[b]))
        .unwrap_or(0);
    let mut order = vec![at];
    used[at] = true;
    while order.len() < n {
        let next = (0..n)
            .filter(|&j| !used[j])
            .min_by(|&a, &b| between[at][a].total_cmp(&between[at][b]))
            .unwrap_or(0);
        used[next] = true;
        order.push(next);
        at = next;
    }
    order
}

/// 2-opt (reverse a stretch) and Or-opt (move a stretch of 1–3 members) on the open path, first
/// improvement, until a full pass gains nothing. Costs may be asymmetric, so every move is
/// evaluated on the whole order.
fn improve(order: &mut Vec<usize>, enter: &[f64], leave: &[f64], between: &[Vec<f64>]) {
    let n = order.len();
    let mut current = order_cost(order, enter, leave, between);
    let mut improved = true;
    let mut passes = 0;
    while improved && passes < 50 {
        improved = false;
        passes += 1;
        for i in 0..n {
            for j in i + 1..n {
                let mut candidate = order.clone();
                candidate[i..=j].reverse();
                let c = order_cost(&candidate, enter, leave, between);
                if c < current - 1e-12 {
                    *order = candidate;
                    current = c;
                    improved = true;
                }
            }
        }
        for len in 1..=3.min(n - 1) {
            for i in 0..=n - len {
                for k in 0..=n - len {
                    if k == i {
                        continue;
                    }
                    let mut candidate = order.clone();
                    let moved: Vec<usize> = candidate.drain(i..i + len).collect();
                    let at = k.min(candidate.len());
                    candidate.splice(at..at, moved);
                    let c = order_cost(&candidate, enter, leave, between);
                    if c < current - 1e-12 {
                        *order = candidate;
                        current = c;
                        improved = true;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over all permutations.
    fn brute(enter: &[f64], leave: &[f64], between: &[Vec<f64>]) -> f64 {
        fn rec(
            order: &mut Vec<usize>,
            used: &mut Vec<bool>,
            e: &[f64],
            l: &[f64],
            b: &[Vec<f64>],
            best: &mut f64,
        ) {
            if order.len() == e.len() {
                *best = best.min(order_cost(order, e, l, b));
                return;
            }
            for i in 0..e.len() {
                if !used[i] {
                    used[i] = true;
                    order.push(i);
                    rec(order, used, e, l, b, best);
                    order.pop();
                    used[i] = false;
                }
            }
        }
        let mut best = f64::INFINITY;
        rec(
            &mut Vec::new(),
            &mut vec![false; enter.len()],
            enter,
            leave,
            between,
            &mut best,
        );
        best
    }

    #[test]
    fn held_karp_matches_brute_force_and_the_heuristic_is_never_better() {
        let mut rng = cutroute_geometry::SplitMix64::new(12345);
        let mut rnd = || rng.next_f64();
        for n in 1..=7 {
            for _ in 0..20 {
                let pts: Vec<(f64, f64)> = (0..n).map(|_| (rnd() * 100.0, rnd() * 100.0)).collect();
                let d = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
                let enter: Vec<f64> = pts.iter().map(|&p| 0.1 * d(p, (0.0, 0.0))).collect();
                let leave: Vec<f64> = pts.iter().map(|&p| 0.1 * d(p, (100.0, 0.0))).collect();
                let between: Vec<Vec<f64>> = pts
                    .iter()
                    .map(|&a| pts.iter().map(|&b| d(a, b)).collect())
                    .collect();
                let exact = open_path_order(&enter, &leave, &between, 12);
                let mut sorted = exact.clone();
                sorted.sort();
                assert_eq!(sorted, (0..n).collect::<Vec<_>>());
                let optimum = brute(&enter, &leave, &between);
                assert!((order_cost(&exact, &enter, &leave, &between) - optimum).abs() < 1e-9);
                let heuristic = open_path_order(&enter, &leave, &between, 0);
                assert!(order_cost(&heuristic, &enter, &leave, &between) >= optimum - 1e-9);
                let mut long = nearest_neighbour(&enter, &between);
                let before = order_cost(&long, &enter, &leave, &between);
                two_opt_symmetric(&mut long, &enter, &leave, &between);
                let after = order_cost(&long, &enter, &leave, &between);
                assert!(after <= before + 1e-9 && after >= optimum - 1e-9);
            }
        }
    }
}
