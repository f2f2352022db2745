//! The breadth-first branch-and-bound variant (Algorithms 2.1–2.3 of the spec).
//!
//! A search node is a prefix σ (a cluster sequence from the depot) with the vector
//! `D(σ)[x]` = cheapest path from the start along σ ending at node `x` of its last cluster.
//! Prefixes are pruned by dominance within their class `(set of clusters, last cluster)`
//! (element-wise `D ≥` the class minimum, the first prefix of a class kept) and by
//! `min_x D[x] + LB(P(σ)) ≥ UB`, with `LB = max(L1, L2)` cached per class. Children are queued
//! fewest-children first. It shares the bound code with the DP, which is usually faster; this
//! variant exists for comparison and for the record of the dissertation's two algorithms.

use crate::bounds::residual::ResidualBounder;
use crate::check::check_tour;
use crate::heuristic::best_nodes;
use crate::instance::Instance;
use crate::model::Model;
use crate::order::ClusterSet;
use crate::solver::{ExactProgress, ExactResult, SolverError};
use cutroute_anytime::Status;
use std::collections::{HashMap, VecDeque};
use std::time::Duration;
use web_time::Instant;

const INF: f64 = f64::INFINITY;

/// Settings of [`solve_bnb`].
#[derive(Clone, Debug, PartialEq)]
pub struct BnbOptions {
    /// Stop after this much time; `None` = no limit.
    pub time_limit: Option<Duration>,
    /// Most prefixes kept in the queue; beyond it the worst-bounded are dropped (the reported
    /// lower bound stays valid, optimality is then not proven).
    pub max_queue: usize,
    /// Also compute L2.
    pub use_l2: bool,
    /// A feasible tour to start from (checked; ignored if infeasible).
    pub initial_tour: Option<Vec<usize>>,
}

impl Default for BnbOptions {
    fn default() -> Self {
        BnbOptions {
            time_limit: Some(Duration::from_secs(60)),
            max_queue: 2_000_000,
            use_l2: true,
            initial_tour: None,
        }
    }
}

struct Prefix {
    set: ClusterSet,
    last: usize,
    /// Path costs to the nodes of `last`.
    costs: Vec<f64>,
    /// Index of the parent in `arena` (for the cluster sequence).
    arena: usize,
    bound: f64,
}

/// Runs the BFS branch-and-bound (one pass per start node of the depot cluster).
pub fn solve_bnb(instance: &Instance, options: &BnbOptions) -> Result<ExactResult, SolverError> {
    let began = Instant::now();
    let mut upper_bound = INF;
    let mut best_tour: Option<Vec<usize>> = None;
    if let Some(tour) = &options.initial_tour {
        if let Ok(cost) = check_tour(instance, tour) {
            upper_bound = cost;
            best_tour = Some(tour.clone());
        }
    }
    let mut lower_bound = INF;
    let mut root_bound = INF;
    let mut stopped = false;
    let mut dropped_min = INF;
    let mut created = 0u64;
    for &start in &instance.clusters[instance.depot] {
        let model = Model::new(instance, start)?;
        let m = model.m;
        let mut bounder = ResidualBounder::default();
        let depot = model.depot;
        let root =
            model.round_bound(bounder.compute(&model, &|c| c == depot, depot, options.use_l2));
        root_bound = root_bound.min(root);
        let mut run_bound = root;
        let mut cache: HashMap<(ClusterSet, usize), f64> = HashMap::new();
        let mut dominance: HashMap<(ClusterSet, usize), Vec<f64>> = HashMap::new();
        // arena[i] = (parent, cluster)
        let mut arena: Vec<(usize, usize)> = vec![(usize::MAX, depot)];
        let mut root_set = ClusterSet::new(m);
        root_set.insert(depot);
        let mut queue: VecDeque<Prefix> = VecDeque::new();
        queue.push_back(Prefix {
            set: root_set,
            last: depot,
            costs: vec![0.0],
            arena: 0,
            bound: root,
        });
        let mut layer_size = 1;
        let mut layer_min = INF;
        let mut run_dropped = INF;
        while let Some(prefix) = queue.pop_front() {
            created += 1;
            if created.is_multiple_of(1024)
                && options.time_limit.is_some_and(|t| began.elapsed() >= t)
            {
                stopped = true;
                // Every improving tour extends a queued prefix (or this one, or a dropped one).
                let queued = queue.iter().map(|p| p.bound).fold(prefix.bound, f64::min);
                run_bound = run_bound.max(queued.min(run_dropped));
                break;
            }
            let size = prefix.set.len();
            if size > layer_size {
                // Layer finished: (2.10)–(2.11).
                run_bound = run_bound.max(layer_min.min(run_dropped));
                layer_size = size;
                layer_min = INF;
                if queue.len() + 1 > options.max_queue {
                    let mut bounds: Vec<f64> = queue.iter().map(|p| p.bound).collect();
                    let keep = options.max_queue / 2;
                    let (_, &mut threshold, _) =
                        bounds.select_nth_unstable_by(keep, f64::total_cmp);
                    run_dropped = run_dropped.min(threshold);
                    queue.retain(|p| p.bound < threshold);
                }
            }
            if Model::round_bound(&model, prefix.bound) >= upper_bound {
                continue;
            }
            layer_min = layer_min.min(prefix.bound);
            let nodes_last = &model.cluster_nodes[prefix.last];
            if size == m {
                let mut best = INF;
                for (i, &x) in nodes_last.iter().enumerate() {
                    best = best.min(prefix.costs[i] + model.arc(x, start));
                }
                if best < upper_bound {
                    let mut clusters = Vec::with_capacity(m);
                    let mut a = prefix.arena;
                    while a != usize::MAX {
                        clusters.push(arena[a].1);
                        a = arena[a].0;
                    }
                    clusters.reverse();
                    let (tour, cost) = best_nodes(&model, &clusters);
                    if cost < upper_bound {
                        upper_bound = cost;
                        best_tour = Some(tour);
                    }
                }
                continue;
            }
            // Branch: clusters whose predecessors are all in the prefix.
            let mut children: Vec<(usize, Prefix)> = Vec::new();
            for v in 0..m {
                if prefix.set.contains(v) || !model.order.predecessors[v].is_subset(&prefix.set) {
                    continue;
                }
                let nodes = &model.cluster_nodes[v];
                let mut costs = vec![INF; nodes.len()];
                for (i, &u) in nodes_last.iter().enumerate() {
                    let g = prefix.costs[i];
                    for (j, &x) in nodes.iter().enumerate() {
                        costs[j] = costs[j].min(g + model.arc(u, x));
                    }
                }
                let mut set = prefix.set.clone();
                set.insert(v);
                // Dominance within the class (set, v).
                let key = (set.clone(), v);
                match dominance.get_mut(&key) {
                    Some(best) => {
                        if costs.iter().zip(best.iter()).all(|(c, b)| c >= b) {
                            continue;
                        }
                        for (b, c) in best.iter_mut().zip(&costs) {
                            *b = b.min(*c);
                        }
                    }
                    None => {
                        dominance.insert(key.clone(), costs.clone());
                    }
                }
                let c_min = costs.iter().copied().fold(INF, f64::min);
                let residual = if set.len() == m {
                    // The closing arc is exact at the leaf.
                    0.0
                } else {
                    *cache.entry(key).or_insert_with(|| {
                        bounder.compute(&model, &|c| set.contains(c), v, options.use_l2)
                    })
                };
                let bound = c_min + residual;
                if model.round_bound(bound) >= upper_bound {
                    continue;
                }
                let fanout = (0..m)
                    .filter(|&w| !set.contains(w) && model.order.predecessors[w].is_subset(&set))
                    .count();
                arena.push((prefix.arena, v));
                children.push((
                    fanout,
                    Prefix {
                        set,
                        last: v,
                        costs,
                        arena: arena.len() - 1,
                        bound,
                    },
                ));
            }
            children.sort_by_key(|(fanout, _)| *fanout);
            queue.extend(children.into_iter().map(|(_, p)| p));
        }
        if !stopped {
            run_bound = run_dropped;
        }
        dropped_min = dropped_min.min(run_dropped);
        lower_bound = lower_bound.min(model.round_bound(run_bound));
        if stopped {
            break;
        }
    }
    let proven = !stopped && dropped_min >= upper_bound;
    let lower_bound = if proven {
        upper_bound
    } else {
        lower_bound.min(upper_bound)
    };
    let gap = if upper_bound.is_finite() && upper_bound > 0.0 {
        (upper_bound - lower_bound) / upper_bound
    } else if upper_bound.is_finite() {
        0.0
    } else {
        INF
    };
    Ok(ExactResult {
        status: if stopped {
            Status::Stopped
        } else {
            Status::Finished {
                proven_optimal: proven,
            }
        },
        progress: ExactProgress {
            elapsed: began.elapsed(),
            upper_bound,
            lower_bound,
            gap,
            layer: 0,
            live_states: 0,
            best_tour,
        },
        states_created: created,
        root_bound,
    })
}
