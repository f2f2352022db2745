//! Tiny instances solved outright: every precedence-feasible cluster order, each with its
//! optimal node choice (the layered-graph DP of [`NodeChoice`]), so the best is the optimum.
//!
//! Why: the destroy–repair search prices an insertion with its neighbours' nodes fixed, so on
//! a handful of clusters it can settle where the optimum needs a cluster moved *and* its
//! neighbours' nodes changed; 22 of 595 random instances of 3–8 clusters (forbidden arcs,
//! precedence, two-node depots) ended above their brute-force optimum after 3,000 iterations,
//! one of them with 4 clusters. At most 8! orders, each a DP of a few hundred operations,
//! take milliseconds.

use crate::nodes::NodeChoice;
use crate::problem::Problem;

/// Most orders × DP work tried (a few tens of milliseconds).
const MAX_WORK: f64 = 2e7;

/// Most clusters besides the depot's (the order set below is a `u32` mask; 10! orders are
/// beyond the work limit anyway).
const MAX_CLUSTERS: usize = 10;

/// The optimal tour (depot first) and its penalised cost, when the instance has at most
/// `up_to` clusters besides the depot's, is small enough to try every order, and has a tour
/// without forbidden arcs; `None` otherwise.
pub(crate) fn optimal_tour(
    p: &Problem,
    dp: &mut NodeChoice,
    up_to: usize,
) -> Option<(Vec<usize>, f64)> {
    let others: Vec<usize> = (0..p.m).filter(|&c| c != p.depot).collect();
    if others.is_empty() || others.len() > up_to.min(MAX_CLUSTERS) {
        return None;
    }
    let sizes = p.clusters.iter().map(|c| c.len() as f64);
    let largest = sizes.clone().fold(0.0, f64::max);
    let smallest = sizes.fold(f64::INFINITY, f64::min);
    // The DP's cost: min |V| · Σ |V_i||V_i+1| ≤ min |V| · m · max |V|².
    let per_order = smallest * p.m as f64 * largest * largest;
    let orders: f64 = (1..=others.len()).map(|k| k as f64).product();
    if orders * per_order > MAX_WORK {
        return None;
    }
    let mut search = Search {
        p,
        dp,
        others: &others,
        order: Vec::with_capacity(p.m),
        best: None,
    };
    search.extend(0);
    search.best
}

struct Search<'a> {
    p: &'a Problem,
    dp: &'a mut NodeChoice,
    others: &'a [usize],
    order: Vec<usize>,
    best: Option<(Vec<usize>, f64)>,
}

impl Search<'_> {
    /// Places each cluster whose predecessors are all placed (`placed`: bits over `others`)
    /// next, down to complete orders.
    fn extend(&mut self, placed: u32) {
        let p = self.p;
        if self.order.len() == self.others.len() {
            let mut tour = Vec::with_capacity(p.m);
            tour.push(p.clusters[p.depot][0]);
            tour.extend(self.order.iter().map(|&c| p.clusters[c][0]));
            let cost = self.dp.optimise(p, &mut tour);
            if p.uses_no_forbidden_arc(&tour) && self.best.as_ref().is_none_or(|b| cost < b.1) {
                self.best = Some((tour, cost));
            }
            return;
        }
        for (i, &c) in self.others.iter().enumerate() {
            if placed & (1 << i) != 0 {
                continue;
            }
            let ready = p.preds[c].iter().all(|a| {
                self.others
                    .iter()
                    .position(|o| o == a)
                    .is_none_or(|j| placed & (1 << j) != 0)
            });
            if ready {
                self.order.push(c);
                self.extend(placed | (1 << i));
                self.order.pop();
            }
        }
    }
}
