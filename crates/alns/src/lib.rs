//! Anytime adaptive large neighbourhood search (ALNS) for the precedence-constrained generalized
//! TSP (PCGTSP) and plain GTSP: cutroute's heuristic for ordering contours and choosing pierce
//! points.
//!
//! The search works on cluster sequences with node selection, in the spirit of GLNS / PCGLNS:
//! remove some clusters (random, worst, segment, related), re-insert them at precedence-feasible
//! positions (cheapest, nearest, farthest, random; with or without noise), pick the optimal nodes
//! for the new cluster order by a shortest-cycle DP over the layered graph, polish with
//! precedence-respecting 2-opt, or-opt and cluster re-insertion, and accept by simulated
//! annealing in epochs. An epoch that improved the best tour is followed by one that starts from
//! it; after a stagnant epoch the next starts from a kicked copy (large random destroy, random
//! re-insertion, local search) of a random elite tour, so that the search leaves a basin it
//! keeps returning to. Operator weights adapt to their success.
//!
//! It is deterministic for a given seed (its own PRNG, no threads, time only decides when to
//! stop, and, when the limit comes before the first tour is whole, how its rest is inserted),
//! runs on wasm32 (`web_time`), and is resumable: [`AlnsSolver::step`] does a slice of
//! work so that a web worker or a job engine can interleave it with other work.
//!
//! ```
//! use cutroute_alns::{solve, AlnsOptions};
//! use cutroute_pcgtsp::Instance;
//!
//! // Depot {0}, clusters {1, 2} and {3}; cluster 2 ({3}) must come before cluster 1.
//! let inf = f64::INFINITY;
//! #[rustfmt::skip]
//! let cost = vec![
//!     0.0, 5.0, 1.0, 9.0,
//!     5.0, 0.0, 9.0, 2.0,
//!     1.0, 9.0, 0.0, 2.0,
//!     1.0, 3.0, 8.0, inf,
//! ];
//! let instance = Instance {
//!     name: "tiny".into(),
//!     node_count: 4,
//!     cost,
//!     clusters: vec![vec![0], vec![1, 2], vec![3]],
//!     node_cluster: vec![0, 1, 1, 2],
//!     precedence: vec![(2, 1)],
//!     depot: 0,
//! };
//! let options = AlnsOptions { max_iterations: Some(100), ..AlnsOptions::default() };
//! let result = solve(&instance, options, &mut |progress| {
//!     println!("{:?}: {:?}", progress.elapsed, progress.best_cost);
//! })
//! .unwrap();
//! // 0 → 3 → 1 → 0 costs 9 + 3 + 5 = 17; 0 → 3 → 2 → 0 costs 9 + 8 + 1 = 18.
//! assert_eq!(result.tour.as_deref(), Some(&[0, 3, 1][..]));
//! assert_eq!(result.cost, Some(17.0));
//! ```
#![deny(missing_docs)]

mod exhaustive;
mod local_search;
mod nodes;
mod operators;
mod problem;
mod solver;

use std::time::Duration;

use cutroute_pcgtsp::Instance;

pub use cutroute_anytime::{AnytimeSolver, Bounds, Status};
pub use solver::{AlnsBuilder, AlnsSolver};

/// Why an instance cannot be searched.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AlnsError {
    /// No nodes or no clusters.
    #[error("the instance has no nodes or no clusters")]
    Empty,
    /// `cost` is not `node_count × node_count`.
    #[error("cost matrix has {found} entries, expected {expected}")]
    CostMatrixSize {
        /// `node_count²`.
        expected: usize,
        /// The actual length.
        found: usize,
    },
    /// `node_cluster` is not `node_count` long.
    #[error("node_cluster has {found} entries, expected {expected}")]
    NodeClusterLength {
        /// `node_count`.
        expected: usize,
        /// The actual length.
        found: usize,
    },
    /// The depot is not a cluster index.
    #[error("depot cluster {0} does not exist")]
    DepotOutOfRange(usize),
    /// A cluster has no nodes.
    #[error("cluster {0} is empty")]
    EmptyCluster(usize),
    /// A cluster lists a node that is out of range, repeated, or assigned to another cluster.
    #[error("cluster {cluster} lists node {node}, which is out of range, repeated or not its own")]
    BadClusterNode {
        /// The cluster.
        cluster: usize,
        /// The node.
        node: usize,
    },
    /// A node belongs to no cluster.
    #[error("node {0} belongs to no cluster")]
    NodeWithoutCluster(usize),
    /// An arc cost is NaN or −∞.
    #[error("arc {from} → {to} has a NaN or −∞ cost")]
    BadCost {
        /// Tail node.
        from: usize,
        /// Head node.
        to: usize,
    },
    /// A precedence pair names a cluster that does not exist.
    #[error("precedence pair ({before}, {after}) names a missing cluster")]
    PrecedenceOutOfRange {
        /// The cluster that must come first.
        before: usize,
        /// The cluster that must come later.
        after: usize,
    },
    /// The precedence relation has a cycle through this cluster (or puts a cluster before the
    /// depot), so no tour exists.
    #[error("precedence relation is cyclic through cluster {0}")]
    PrecedenceCycle(usize),
}

/// Tuning knobs of the search. The defaults are what the benchmarks were run with.
#[derive(Clone, Debug, PartialEq)]
pub struct AlnsParameters {
    /// Fewest clusters removed per iteration.
    pub min_removal: usize,
    /// Most clusters removed per iteration, as a fraction of the non-depot clusters.
    pub max_removal_fraction: f64,
    /// Absolute cap on clusters removed per iteration.
    pub max_removal: usize,
    /// Amplitude of the insertion-cost noise of noisy operators, in mean tour arcs.
    pub noise: f64,
    /// Temperature at the start of an epoch, as a fraction of the best cost.
    pub start_temperature: f64,
    /// Factors applied to `start_temperature` in successive epochs, cyclically.
    pub temperature_cycle: Vec<f64>,
    /// Temperature at the end of an epoch, as a fraction of the best cost.
    pub end_temperature: f64,
    /// Iterations of the first annealing epoch; each epoch ends with a restart (from the best
    /// tour, or from a kicked elite tour after an epoch that did not improve it).
    pub epoch_iterations: u64,
    /// Factor by which each epoch is longer than the previous one.
    pub epoch_growth: f64,
    /// Longest epoch.
    pub max_epoch_iterations: u64,
    /// A repaired tour gets the full local search if it costs less than the current tour times
    /// `1 + local_search_gate` (or beats the best).
    pub local_search_gate: f64,
    /// Longest segment the block-reversal local search move turns around.
    pub block_reverse_length: usize,
    /// Block reversal runs on tours whose cost is within this fraction above the best.
    pub block_reverse_gate: f64,
    /// Iterations between operator-weight updates.
    pub segment_iterations: u64,
    /// Weight-update reaction factor in `[0, 1]`.
    pub reaction: f64,
    /// Score of an operator pair that found a new best tour.
    pub score_new_best: f64,
    /// Score for a tour better than the current one.
    pub score_better: f64,
    /// Score for an accepted worse tour.
    pub score_accepted: f64,
    /// How many of the best distinct epoch results are kept as restart points.
    pub elite_size: usize,
    /// Fraction of the non-depot clusters removed (and re-inserted at random) by the kick that
    /// starts an epoch after an epoch that did not improve the best tour.
    pub kick_fraction: f64,
    /// Instances of at most this many clusters besides the depot's are solved outright at the
    /// start (every order with its best nodes, when that is a few tens of milliseconds of
    /// work; at most 10) and the search stops as [`StopReason::Exhausted`]; 0: always search.
    pub exhaustive_up_to: usize,
}

impl Default for AlnsParameters {
    fn default() -> Self {
        AlnsParameters {
            min_removal: 1,
            max_removal_fraction: 0.3,
            max_removal: 50,
            noise: 0.3,
            start_temperature: 0.1,
            temperature_cycle: vec![1.0, 0.3, 0.1],
            end_temperature: 0.0005,
            epoch_iterations: 2000,
            epoch_growth: 1.5,
            max_epoch_iterations: 200_000,
            local_search_gate: 0.05,
            block_reverse_length: 40,
            block_reverse_gate: 0.001,
            segment_iterations: 50,
            reaction: 0.2,
            score_new_best: 33.0,
            score_better: 9.0,
            score_accepted: 13.0,
            elite_size: 6,
            kick_fraction: 0.3,
            exhaustive_up_to: 10,
        }
    }
}

/// What to run and when to stop.
#[derive(Clone, Debug, PartialEq)]
pub struct AlnsOptions {
    /// Seed of the solver's PRNG: the same seed and iteration count give the same tour.
    pub seed: u64,
    /// Stop after this much search time (time spent inside `step`; `None` = no limit).
    pub time_limit: Option<Duration>,
    /// Stop after this many iterations (`None` = no limit).
    pub max_iterations: Option<u64>,
    /// Stop as soon as a tour this cheap is found (e.g. a known optimum or a lower bound).
    pub target_cost: Option<f64>,
    /// Search parameters.
    pub parameters: AlnsParameters,
}

impl Default for AlnsOptions {
    fn default() -> Self {
        AlnsOptions {
            seed: 1,
            time_limit: Some(Duration::from_secs(10)),
            max_iterations: None,
            target_cost: None,
            parameters: AlnsParameters::default(),
        }
    }
}

/// Why the search stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The time limit was reached.
    TimeLimit,
    /// The iteration limit was reached.
    IterationLimit,
    /// A tour at or below the target cost was found.
    TargetReached,
    /// The instance is so small that every cluster order was tried, each with its best nodes
    /// ([`AlnsParameters::exhaustive_up_to`]), or it has at most one cluster besides the
    /// depot: the tour is optimal.
    Exhausted,
    /// [`AlnsSolver::cancel`] was called.
    Cancelled,
}

/// A snapshot of the search, streamed on every improvement.
#[derive(Clone, Debug, PartialEq)]
pub struct AlnsProgress {
    /// Search time so far (time spent inside `step`).
    pub elapsed: Duration,
    /// Cost of the best tour without forbidden arcs, if one was found.
    pub best_cost: Option<f64>,
    /// Cost of the tour the search is at (may include penalised forbidden arcs).
    pub current_cost: Option<f64>,
    /// Destroy–repair iterations done.
    pub iterations: u64,
    /// Times the best tour improved.
    pub improvements: u64,
    /// Restarts (annealing epochs completed).
    pub restarts: u64,
    /// Set once the search has stopped.
    pub stop_reason: Option<StopReason>,
}

/// The outcome of [`solve`].
#[derive(Clone, Debug, PartialEq)]
pub struct AlnsResult {
    /// The best tour (nodes, depot first, closed implicitly), if one without forbidden arcs
    /// was found.
    pub tour: Option<Vec<usize>>,
    /// Its cost.
    pub cost: Option<f64>,
    /// Final counters.
    pub progress: AlnsProgress,
}

/// Runs the search to its stop condition, calling `on_improvement` on every new best tour.
pub fn solve(
    instance: &Instance,
    options: AlnsOptions,
    on_improvement: &mut dyn FnMut(&AlnsProgress),
) -> Result<AlnsResult, AlnsError> {
    solve_until(instance, options, on_improvement, &|| false)
}

/// Like [`solve`], also stopping (with [`StopReason::Cancelled`]) when `cancelled()` returns
/// true; it is polled every few milliseconds.
pub fn solve_until(
    instance: &Instance,
    options: AlnsOptions,
    on_improvement: &mut dyn FnMut(&AlnsProgress),
    cancelled: &dyn Fn() -> bool,
) -> Result<AlnsResult, AlnsError> {
    let mut solver = AlnsSolver::new(instance, options)?;
    while solver
        .step_with(Duration::from_millis(5), on_improvement)
        .is_running()
    {
        if cancelled() {
            solver.cancel();
        }
    }
    let best = solver.best().map(|(t, c)| (t.to_vec(), c));
    Ok(AlnsResult {
        tour: best.as_ref().map(|(t, _)| t.clone()),
        cost: best.map(|(_, c)| c),
        progress: solver.progress(),
    })
}

/// A reference instance of `data/pcgtsp/<set>/<name>.pcglns` for the unit tests; panics
/// loudly when the file is missing.
#[cfg(test)]
pub(crate) fn reference_instance(set: &str, name: &str) -> cutroute_pcgtsp::Instance {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/pcgtsp")
        .join(set)
        .join(format!("{name}.pcglns"));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("missing reference instance {}: {e}", path.display()));
    cutroute_pcgtsp::Instance::parse(&text).unwrap()
}
