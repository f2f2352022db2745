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
//! or a tour) and bounds in the solver's own objective; the job engine turns those into the
//! protocol's progress, with their units.
//!
//! ```
//! use std::time::Duration;
//! use cutroute_anytime::{AnytimeSolver, Bounds, Status};
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
//!         Bounds { upper: Some(f64::from(self.n - self.at)), lower: Some(0.0) }
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

/// The bounds so far, in the solver's own objective (idle millimetres, seconds or cost, as the
/// solver minimises). `None`: no bound known yet.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bounds {
    /// The objective of the best solution so far.
    pub upper: Option<f64>,
    /// A proven lower bound on the optimum, if the solver computes one.
    pub lower: Option<f64>,
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
