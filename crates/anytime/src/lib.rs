//! The contract every cutroute solver keeps: [`AnytimeSolver`].
//!
//! The app runs its solvers in a browser worker, which has one thread. A solver that ran to its
//! end in one call would block the worker's message loop, so the user's Stop could not arrive
//! until it finished. Every solver therefore works in resumable slices: [`AnytimeSolver::step`]
//! does about `budget` of work and returns, the caller reads the best solution and the bounds
//! so far between slices, and stops calling when it wants to. That is what the two promises
//! rest on: **Stop within 200 ms** (no slice runs much longer than its budget) and **a time
//! limit kept within 1 s** (the caller checks its clock between slices, and every solver keeps
//! a checked best solution it can hand over at any time).
//!
//! The trait is deliberately small: a solution in the solver's own type (a route, a path route
//! or a tour) and [`Bounds`] in the solver's own objective, which say their [`CostUnit`]; the
//! job engine turns those into the protocol's progress.
//!
//! ```
//! use std::time::Duration;
//! use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit, Status};
//!
//! /// Counts to `n`, one number per unit of work; the best is the largest number reached.
//! struct Count { n: u32, at: u32 }
//!
//! impl AnytimeSolver for Count {
//!     type Solution = u32;
//!     fn step(&mut self, _budget: Duration) -> Status {
//!         if self.at == self.n {
//!             return Status::Finished { proven_optimal: true };
//!         }
//!         self.at += 1; // one unit of work per slice
//!         Status::Running
//!     }
//!     fn best(&self) -> Option<u32> {
//!         Some(self.at)
//!     }
//!     fn bounds(&self) -> Bounds {
//!         Bounds { upper: Some(f64::from(self.n - self.at)), lower: Some(0.0), unit: CostUnit::TourCost }
//!     }
//! }
//!
//! let mut solver = Count { n: 3, at: 0 };
//! let status = cutroute_anytime::run_to_end(&mut solver, Duration::from_millis(40));
//! assert_eq!(status, Status::Finished { proven_optimal: true });
//! assert!(status.is_done() && status.proven_optimal());
//! assert_eq!(solver.best(), Some(3));
//! ```
#![deny(missing_docs)]
#![no_std]

use core::time::Duration;
use serde::{Deserialize, Serialize};

/// What a call of [`AnytimeSolver::step`] left behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// Work remains: call `step` again to improve the best solution or its bounds.
    Running,
    /// The search ran to its end. `proven_optimal`: the best solution is proven optimal (the
    /// lower bound meets it); heuristics say `false`.
    Finished {
        /// Whether the best solution is proven optimal.
        proven_optimal: bool,
    },
    /// The search was stopped before its end (time limit, gap tolerance, cancel): the best
    /// solution so far stands, not proven optimal.
    Stopped,
}

impl Status {
    /// Whether more work remains ([`Status::Running`]).
    pub fn is_running(self) -> bool {
        self == Status::Running
    }

    /// Whether the solver is done, finished or stopped: further steps do nothing.
    pub fn is_done(self) -> bool {
        !self.is_running()
    }

    /// Whether the search finished with its best solution proven optimal.
    pub fn proven_optimal(self) -> bool {
        self == Status::Finished {
            proven_optimal: true,
        }
    }
}

/// What a solver's bounds measure. The solver that computes a bound says its unit, so no reader
/// (the engine, the CLI, the page's chart) has to work it out from the solver or the problem.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum CostUnit {
    /// Idle (tool-off) travel, mm: the solvers of routes of whole contours (with a heat weight,
    /// idle plus the weighted heat load, in mm).
    #[default]
    IdleMm,
    /// Machining time, s, under the machine's model (formula 1.2).
    Seconds,
    /// Cost under the machine's prices (formula 1.3).
    Cost,
    /// The arc weights of a PCGTSP instance (a tour's cost, in the instance's own unit).
    TourCost,
}

/// The bounds so far: the cost of the best solution and a proven lower bound on the optimum,
/// both in `unit`. `None`: not known yet.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// The cost of the best solution so far, if any.
    pub upper: Option<f64>,
    /// A proven lower bound on the optimal cost, if the solver computes one.
    pub lower: Option<f64>,
    /// What both measure.
    pub unit: CostUnit,
}

impl Bounds {
    /// No bound yet, in `unit`.
    pub fn unknown(unit: CostUnit) -> Self {
        Self {
            upper: None,
            lower: None,
            unit,
        }
    }

    /// Bounds on idle length, mm.
    pub fn idle_mm(upper: Option<f64>, lower: Option<f64>) -> Self {
        Self {
            upper,
            lower,
            unit: CostUnit::IdleMm,
        }
    }

    /// The same values in another unit: for a caller that knows the solver's objective means
    /// something else to its user (a discretised nest's tour cost is idle length).
    pub fn in_unit(self, unit: CostUnit) -> Self {
        Self { unit, ..self }
    }

    /// The relative gap `(upper − lower) / upper`, clamped at 0 (0 when `upper` is 0), when
    /// both are known.
    pub fn gap(&self) -> Option<f64> {
        match (self.upper, self.lower) {
            (Some(ub), Some(lb)) if ub > 0.0 => Some(((ub - lb) / ub).max(0.0)),
            (Some(_), Some(_)) => Some(0.0),
            _ => None,
        }
    }
}

/// A solver that works in resumable slices and has a best solution at any time.
pub trait AnytimeSolver {
    /// The best solution's type, the solver's own: a route, a path route or a tour.
    type Solution;

    /// Works for about `budget` (solvers look at the clock every few hundred operations), then
    /// returns. Once it returned a done status, further calls return it again at once.
    fn step(&mut self, budget: Duration) -> Status;

    /// The best solution so far, if any.
    fn best(&self) -> Option<Self::Solution>;

    /// The bounds so far.
    fn bounds(&self) -> Bounds;
}

/// Steps `solver` by `slice` until it is done; returns the final status.
pub fn run_to_end<S: AnytimeSolver + ?Sized>(solver: &mut S, slice: Duration) -> Status {
    loop {
        let status = solver.step(slice);
        if status.is_done() {
            return status;
        }
    }
}
