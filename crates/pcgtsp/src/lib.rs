//! Precedence-constrained generalized TSP (PCGTSP): the discrete model of cutting routes.
//! (Being written: model, readers, checker, lower bounds and the exact solver.)
#![deny(missing_docs)]

mod instance;

pub use instance::Instance;
