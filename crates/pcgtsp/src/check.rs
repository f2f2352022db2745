//! The independent tour checker: everything a solver returns goes through here.

use crate::instance::Instance;

/// Why a tour is not a feasible PCGTSP tour.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TourError {
    /// The tour has the wrong number of nodes (one per cluster).
    #[error("tour has {found} nodes, expected one per cluster ({expected})")]
    WrongLength {
        /// Nodes in the tour.
        found: usize,
        /// Number of clusters.
        expected: usize,
    },
    /// A node index is not a node of the instance.
    #[error("position {position}: node {node} does not exist")]
    NodeOutOfRange {
        /// Position in the tour.
        position: usize,
        /// The node (0-based).
        node: usize,
    },
    /// The first node is not in the depot cluster.
    #[error("tour starts at node {node} of cluster {cluster}, not in the depot cluster {depot}")]
    NotStartingAtDepot {
        /// The first node (0-based).
        node: usize,
        /// Its cluster (0-based).
        cluster: usize,
        /// The depot cluster (0-based).
        depot: usize,
    },
    /// A cluster is visited twice.
    #[error("cluster {cluster} visited twice (positions {first} and {second})")]
    ClusterVisitedTwice {
        /// The cluster (0-based).
        cluster: usize,
        /// First position.
        first: usize,
        /// Second position.
        second: usize,
    },
    /// An arc of the tour (the closing arc included) is forbidden.
    #[error("arc {from} -> {to} is forbidden")]
    ForbiddenArc {
        /// Tail node (0-based).
        from: usize,
        /// Head node (0-based).
        to: usize,
    },
    /// Cluster `after` is visited before cluster `before`, which must come first.
    #[error("cluster {after} visited before cluster {before}, which must precede it")]
    PrecedenceViolated {
        /// The cluster that must come first (0-based).
        before: usize,
        /// The cluster visited too early (0-based).
        after: usize,
    },
}

/// Checks `tour` (0-based nodes, one per cluster, starting in the depot cluster, closed back to
/// its first node) against the instance and recomputes its cost from the matrix.
pub fn check_tour(instance: &Instance, tour: &[usize]) -> Result<f64, TourError> {
    let m = instance.clusters.len();
    if tour.len() != m {
        return Err(TourError::WrongLength {
            found: tour.len(),
            expected: m,
        });
    }
    let mut position_of_cluster = vec![usize::MAX; m];
    for (position, &node) in tour.iter().enumerate() {
        if node >= instance.node_count {
            return Err(TourError::NodeOutOfRange { position, node });
        }
        let cluster = instance.node_cluster[node];
        if position_of_cluster[cluster] != usize::MAX {
            return Err(TourError::ClusterVisitedTwice {
                cluster,
                first: position_of_cluster[cluster],
                second: position,
            });
        }
        position_of_cluster[cluster] = position;
    }
    let first_cluster = instance.node_cluster[tour[0]];
    if first_cluster != instance.depot {
        return Err(TourError::NotStartingAtDepot {
            node: tour[0],
            cluster: first_cluster,
            depot: instance.depot,
        });
    }
    for &(before, after) in &instance.precedence {
        if position_of_cluster[before] > position_of_cluster[after] {
            return Err(TourError::PrecedenceViolated { before, after });
        }
    }
    let mut cost = 0.0;
    for (i, &from) in tour.iter().enumerate() {
        let to = tour[(i + 1) % m];
        let arc = instance.arc_cost(from, to);
        if !arc.is_finite() {
            return Err(TourError::ForbiddenArc { from, to });
        }
        cost += arc;
    }
    Ok(cost)
}
