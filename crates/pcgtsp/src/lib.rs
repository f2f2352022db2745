//! Precedence-constrained generalized TSP (PCGTSP): the discrete model of cutting routes.
#![deny(missing_docs)]

mod assignment;
mod bounds;
mod check;
mod dp;
mod heuristic;
mod instance;
mod lattice;
mod order;
mod parse;
mod solver;

pub use assignment::Assignment;
pub use bounds::{root_bounds, RootBounds};
pub use check::{check_tour, TourError};
pub use instance::Instance;
pub use order::{ClusterSet, OrderError, PrecedenceOrder};
pub use parse::{ParseError, PcglnsResult, MAX_NODES};
pub use solver::{
    solve, ExactOptions, ExactProgress, ExactResult, ExactSolver, SolverError, SolverStatus,
};
