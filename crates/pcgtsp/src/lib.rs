//! Precedence-constrained generalized TSP (PCGTSP): the discrete model of cutting routes.
//!
//! A cutting plan becomes a PCGTSP instance: clusters are contours, nodes are candidate pierce
//! points, arc costs are idle moves, and the precedence order says which contours must be cut
//! before others (holes before their outer contour). This crate holds
//!
//! - the model ([`Instance`]) and its text formats: PCGLNS and PCGTSPLIB readers, a PCGLNS
//!   writer, and the PCGLNS result reader ([`PcglnsResult`]), all with typed, line-numbered
//!   errors ([`ParseError`]);
//! - the precedence order's transitive closure and reduction ([`PrecedenceOrder`]);
//! - an independent tour checker ([`check_tour`]) that every solver result goes through;
//! - lower bounds: assignment bounds L1 / L2 on the residual problem, the pierce-group DP
//!   over the lattice of order ideals ([`root_bounds`]), the subset DP (an exact
//!   node-level backward DP over a subset of the clusters, with penalised walks through the
//!   others) that bounds every search state's completion, and the restricted bound: an exact
//!   solve of a subset of the clusters under restricted shortest-path costs ([`restricted_bound`]);
//!   and two Lagrangian bounds for orders too large for the lattice: node penalties (relaxing
//!   "a tour leaves every node it enters") that strengthen the per-state assignment bounds, and
//!   a Held–Karp style spanning-arborescence bound on the cluster graph with out-degrees
//!   relaxed, both optimised by subgradient ascent ([`RootBounds`]); and a position-indexed
//!   completion bound that sees precedence (every cluster confined to the tour positions its
//!   order allows, cluster penalties by subgradient ascent) for every search state
//!   ([`position_bounds`]);
//! - the exact solver: a DP over order ideals with node-level states, per-state bounding
//!   against the incumbent, a memory cap and an anytime, resumable API ([`ExactSolver`],
//!   [`solve`]); and the breadth-first branch-and-bound variant ([`solve_bnb`]).
//!
//! ```
//! use cutroute_pcgtsp::{check_tour, solve, ExactOptions, Instance};
//!
//! // Depot {1}, clusters {2, 3} and {4}; cluster 2 must be cut before cluster 3.
//! let text = "NAME : tiny\nTYPE : PCGLNS\nDIMENSION : 4\nGTSP_SETS : 3\n\
//!             EDGE_WEIGHT_TYPE : EXPLICIT\nEDGE_WEIGHT_FORMAT : FULL_MATRIX\n\
//!             EDGE_WEIGHT_SECTION\n0 5 1 9\n5 0 -1 2\n1 -1 0 4\n9 2 4 0\n\
//!             GTSP_SET_SECTION\n1 1 -1\n2 2 3 -1\n3 4 -1\n\
//!             GTSP_SET_ORDERING\n2 3 -1\nSTART_GROUP_SECTION\n1\nEOF\n";
//! let instance = Instance::parse(text)?;
//! let result = solve(&instance, ExactOptions::default(), &mut |_progress| {})?;
//! assert!(result.proven_optimal());
//! let tour = result.progress.best_tour.as_ref().expect("a tour");
//! // Start at node 0, pierce node 2 (cluster 2), then node 3 (cluster 3), and return.
//! assert_eq!(tour, &vec![0, 2, 3]);
//! assert_eq!(check_tour(&instance, tour)?, 1.0 + 4.0 + 9.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod assignment;
mod bnb;
mod bounds;
mod check;
mod dp;
mod heuristic;
mod instance;
mod keys;
mod model;
mod order;
mod parse;
mod prepare;
mod restricted;
mod solver;

pub use assignment::Assignment;
pub use bnb::{solve_bnb, BnbOptions};
pub use bounds::completion::{position_bounds, PositionBounds};
pub use bounds::lattice::count_ideals;
pub use bounds::{root_bounds, RootBounds};
pub use check::{check_tour, TourError};
pub use cutroute_anytime::{AnytimeSolver, Bounds, Status};
pub use heuristic::nearest_neighbour_tour;
pub use instance::Instance;
pub use order::{ClusterSet, OrderError, PrecedenceOrder};
pub use parse::{ParseError, PcglnsResult, MAX_NODES, MAX_WEIGHT};
pub use restricted::{
    restricted_bound, RestrictedBound, RestrictedBoundError, RestrictedBoundOptions,
};
pub use solver::{solve, ExactOptions, ExactProgress, ExactResult, ExactSolver, SolverError};
