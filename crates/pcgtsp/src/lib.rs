//! Precedence-constrained generalized TSP (PCGTSP): the discrete model of cutting routes.
#![deny(missing_docs)]

mod check;
mod instance;
mod parse;

pub use check::{check_tour, TourError};
pub use instance::Instance;
pub use parse::{ParseError, PcglnsResult, MAX_NODES};
