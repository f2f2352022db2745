//! The job engine: turns a [`JobRequest`] into a running solver and advances it in time slices.
//!
//! A browser worker has one thread: a solver that ran to its end in one call would block the
//! worker's message loop, so a Cancel message could not arrive until it finished. Every job is
//! therefore a [`Job`] that does a bounded slice of work per [`Job::step`] call; the worker yields
//! to its event loop between slices, and the CLI simply loops.
//!
//! ```
//! use cutroute_engine::{run_to_end, start_job};
//! use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};
//! use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};
//!
//! let square = |x: f64| Contour::new(vec![
//!     Vertex::line(x, 0.0), Vertex::line(x, 10.0), Vertex::line(x + 10.0, 10.0), Vertex::line(x + 10.0, 0.0),
//! ]);
//! let nest = Nest { sheet: None, parts: vec![
//!     Part { name: "far".into(), contours: vec![square(100.0)] },
//!     Part { name: "near".into(), contours: vec![square(20.0)] },
//! ]};
//! let request = JobRequest {
//!     job_id: 1,
//!     problem: Problem::Nest { nest, start: Point::new(0.0, 0.0), finish: None },
//!     solver: SolverKind::NearestNeighbour,
//!     params: SolverParams::default(),
//! };
//! let mut job = start_job(&request).unwrap();
//! let result = run_to_end(job.as_mut(), &mut |_| {});
//! let route = result.route.unwrap();
//! assert_eq!(route.steps[0].contour.part, 1); // the nearer part is cut first
//! assert_eq!(result.upper_bound, Some(20.0 + 80.0));
//! ```
#![deny(missing_docs)]

mod jobs;
mod nearest;
mod open;
mod open_files;
mod path_jobs;

use cutroute_protocol::{JobRequest, Problem, Progress, SolverKind};
use web_time::Duration;

pub use jobs::{ccp_options, CcpJob, ChainJob, DiscreteJob, DiscreteMode};
pub use nearest::NearestNeighbourJob;
pub use open::{format_name, OpenError};
pub use open_files::{
    is_pcglns_result, open_document, open_gcode, open_sheet, open_together, task_instance,
    POINT_TOLERANCE_MM,
};
pub use path_jobs::{AoeJob, PlanBound, SegmentJob};

/// How long one [`Job::step`] may run before it returns, so cancel requests are seen quickly.
pub const DEFAULT_SLICE: Duration = Duration::from_millis(40);

/// The share of a chain job's time limit its CCP phase gets; chain cutting has the rest.
pub const CHAIN_CCP_SHARE: f64 = 0.6;

/// What a step left behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobStatus {
    /// More work to do: call `step` again.
    Running,
    /// The solver ended (finished its search or reached its time limit).
    Done,
}

/// A solver run that advances in slices.
pub trait Job {
    /// Work for about `budget` (solvers check the clock every few hundred operations), then return.
    fn step(&mut self, budget: Duration) -> JobStatus;
    /// The current state: bounds, best route or tour, phase.
    fn progress(&self) -> Progress;
}

/// Why a job could not start.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EngineError {
    /// The solver does not accept this kind of problem.
    #[error("the {solver} solver cannot solve {problem}")]
    UnsupportedProblem {
        /// The solver's short name.
        solver: &'static str,
        /// What the problem was, in words.
        problem: &'static str,
    },
    /// The problem has nothing to cut.
    #[error("the nest has no contours to cut")]
    EmptyNest,
    /// The solver refused the problem (bad instance, no feasible tour, …).
    #[error("{solver}: {message}")]
    SolverRefused {
        /// The solver's short name.
        solver: &'static str,
        /// Its reason.
        message: String,
    },
}

/// Build the job a request asks for.
pub fn start_job(request: &JobRequest) -> Result<Box<dyn Job>, EngineError> {
    let params = &request.params;
    let time_limit = Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7));
    // Building the problem (a discretisation's dense matrix) counts against the limit.
    let started = web_time::Instant::now();
    let solver = request.solver;
    let refused = |message: String| EngineError::SolverRefused {
        solver: solver.name(),
        message,
    };
    let discrete_mode = match solver {
        SolverKind::Heuristic => Some(DiscreteMode::Heuristic),
        SolverKind::Exact => Some(DiscreteMode::Exact),
        _ => None,
    };
    let discrete_job = |instance, mode| -> Result<Box<dyn Job>, EngineError> {
        let job = DiscreteJob::new(
            request.job_id,
            instance,
            None,
            mode,
            time_limit,
            started,
            params.seed,
        )
        .map_err(refused)?;
        Ok(Box::new(job))
    };
    match (&request.problem, solver) {
        (
            Problem::Nest {
                nest,
                start,
                finish,
            },
            SolverKind::NearestNeighbour,
        ) => Ok(Box::new(NearestNeighbourJob::new(
            request.job_id,
            nest.clone(),
            *start,
            *finish,
        )?)),
        (
            Problem::Nest {
                nest,
                start,
                finish,
            },
            SolverKind::Ccp | SolverKind::Chain,
        ) => {
            // Chain cutting runs after CCP within the same limit: CCP gets its share of it.
            let ccp_limit = if solver == SolverKind::Chain {
                time_limit.mul_f64(CHAIN_CCP_SHARE)
            } else {
                time_limit
            };
            let options =
                jobs::ccp_options(*start, *finish, ccp_limit, params.seed, params.machine);
            let ccp =
                cutroute_ccp::CcpSolver::new(nest, options).map_err(|e| refused(e.to_string()))?;
            if solver == SolverKind::Chain {
                return Ok(Box::new(
                    ChainJob::new(request.job_id, ccp, nest.clone(), params.machine)
                        .with_time_limit(started, time_limit),
                ));
            }
            let bound = cutroute_ccp::CcpLowerBound::new(
                nest,
                cutroute_ccp::LowerBoundOptions {
                    start: *start,
                    finish: *finish,
                    budget_seconds: time_limit.as_secs_f64(),
                    first_stage: (time_limit / 10).clamp(
                        web_time::Duration::from_millis(500),
                        web_time::Duration::from_secs(5),
                    ),
                    ..Default::default()
                },
            )
            .map_err(|e| refused(e.to_string()))?;
            Ok(Box::new(
                CcpJob::new(request.job_id, ccp).with_lower_bound(bound, time_limit),
            ))
        }
        (Problem::Nest { .. }, SolverKind::Sccp | SolverKind::Gsccp) => {
            Ok(Box::new(SegmentJob::from_request(request)?))
        }
        (Problem::Nest { .. }, SolverKind::Aoe) => Ok(Box::new(AoeJob::from_request(request)?)),
        (
            Problem::Nest {
                nest,
                start,
                finish,
            },
            SolverKind::Heuristic | SolverKind::Exact,
        ) => {
            let options = cutroute_ccp::DiscretisationOptions {
                start: *start,
                finish: *finish,
                step: params.discretisation_step_mm,
                ..cutroute_ccp::DiscretisationOptions::default()
            };
            // The matrix is filled in the job's first steps (seconds on big nests).
            let builder = cutroute_ccp::PcgtspBuilder::new(nest, &options)
                .map_err(|e| refused(e.to_string()))?;
            Ok(Box::new(DiscreteJob::building(
                request.job_id,
                builder,
                discrete_mode.unwrap_or(DiscreteMode::Heuristic),
                time_limit,
                started,
                params.seed,
            )))
        }
        (Problem::PcgtspText { text }, _) => {
            let Some(mode) = discrete_mode else {
                return Err(EngineError::UnsupportedProblem {
                    solver: solver.name(),
                    problem: "a PCGTSP instance",
                });
            };
            let instance =
                cutroute_pcgtsp::Instance::parse(text).map_err(|e| refused(e.to_string()))?;
            discrete_job(instance, mode)
        }
    }
}

/// Step a job until it is done, reporting progress after every slice; returns the final state.
pub fn run_to_end(job: &mut dyn Job, on_progress: &mut dyn FnMut(&Progress)) -> Progress {
    while job.step(DEFAULT_SLICE) == JobStatus::Running {
        on_progress(&job.progress());
    }
    job.progress()
}
