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
//! let route = result.route().unwrap();
//! assert_eq!(route.steps[0].contour.part, 1); // the nearer part is cut first
//! assert_eq!(result.bounds.upper, Some(20.0 + 80.0));
//! ```
#![deny(missing_docs)]

mod full_route;
mod jobs;
mod kerf;
mod kerf_paths;
mod located;
mod nearest;
mod open;
mod open_files;
mod path_jobs;
mod thermal;

use cutroute_protocol::{JobRequest, Problem, Progress, SolverKind};
use web_time::Duration;

pub use full_route::{build_full_route_model, FullRouteBuilder, FullRouteJob, FullRouteModel};
pub use jobs::{ccp_options, CcpJob, ChainJob, DiscreteJob, DiscreteMode};
pub use kerf::{
    fit_leads, supports_kerf, validate_kerf, KerfJob, KerfSettingsError, OVERRUN_LIMIT,
};
pub use kerf_paths::REJECTED_ROUTE;
pub use nearest::NearestNeighbourJob;
pub use open::{format_name, OpenError};
pub use open_files::{
    conversion_losses, is_pcglns_result, open_document, open_gcode, open_gcode_with, open_sheet,
    open_together, task_instance, POINT_TOLERANCE_MM,
};
pub use path_jobs::{idle_tree_bound, AoeJob, PlanBound, PlanBoundError, SegmentJob};
pub use thermal::{
    check_path_rules, enforce_thermal_rules, enforce_thermal_rules_on_paths, heat_penalty,
    measure_path_route, measure_route, path_contour_route, price_consecutive_heat, PathRepairError,
    ThermalJob, ThermalMeasure,
};

/// How long one [`Job::step`] may run before it returns, so cancel requests are seen quickly.
pub const DEFAULT_SLICE: Duration = Duration::from_millis(40);

/// The share of a chain job's time limit its CCP phase gets; chain cutting has the rest.
pub const CHAIN_CCP_SHARE: f64 = 0.6;

/// The share of a discretised nest's time limit that CCP-Relax gets (its own running time,
/// in the heuristic's share of the slices) to find the route that seeds the heuristic.
pub const ROUTE_SEED_SHARE: f64 = 1.0 / 12.0;

/// What a step left behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobStatus {
    /// More work to do: call `step` again.
    Running,
    /// The solver ended (finished its search or reached its time limit).
    Done,
}

impl From<cutroute_anytime::Status> for JobStatus {
    fn from(status: cutroute_anytime::Status) -> Self {
        if status.is_running() {
            JobStatus::Running
        } else {
            JobStatus::Done
        }
    }
}

/// A solver run that advances in slices.
pub trait Job {
    /// Work for about `budget` (solvers check the clock every few hundred operations), then return.
    fn step(&mut self, budget: Duration) -> JobStatus;
    /// The current state: bounds, best route or tour, phase.
    fn progress(&self) -> Progress;
    /// The job is stopped before it is done (Stop, Ctrl-C, or the caller's own limit): it ends
    /// as it would at its own time limit reached now. Its next [`Job::progress`] is the final
    /// answer and carries what only a final answer does (CCP's certificates, a pass over the
    /// route) and the best route so far; where there is none yet, the route a very short limit
    /// gives (the discrete jobs' nearest-neighbour tour), or, where that route still takes
    /// work (AOE's ordering cut short and checked), further [`Job::step`] calls make it and
    /// then return [`JobStatus::Done`]. Nothing to do for jobs that end in one step.
    fn stop(&mut self) {}
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
    #[error("{solver}: {reason}")]
    SolverRefused {
        /// The solver's short name.
        solver: &'static str,
        /// Its reason: the solver crate's own error, kept as the source.
        #[source]
        reason: Refusal,
    },
}

/// Why a solver refused a problem: the error of the crate that refused it, or a setting out
/// of range. The words are the refusing crate's.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum Refusal {
    /// CCP-Relax, its lower bound or the discretisation refused the nest.
    #[error("{0}")]
    Ccp(#[from] cutroute_ccp::CcpError),
    /// The PCGTSP instance does not parse.
    #[error("{0}")]
    Instance(#[from] cutroute_pcgtsp::ParseError),
    /// The exact solver refused the instance.
    #[error("{0}")]
    Exact(#[from] cutroute_pcgtsp::SolverError),
    /// The ALNS heuristic refused the instance.
    #[error("{0}")]
    Alns(#[from] cutroute_alns::AlnsError),
    /// Segment cutting refused the nest.
    #[error("{0}")]
    Segments(#[from] cutroute_segments::SegmentError),
    /// The heat model's σ or τ is out of range.
    #[error("{0}")]
    Thermal(#[from] cutroute_thermal::ThermalError),
    /// A kerf or lead length is out of range.
    #[error("{0}")]
    Kerf(#[from] kerf::KerfSettingsError),
    /// Parts sit closer than the kerf: no cut on the equidistants keeps kerf/2 off its
    /// neighbour, so the full cutting route has no admissible route (the pairs and their gaps).
    #[error("{0}")]
    PartsTooClose(#[from] cutroute_geometry::PartsTooClose),
    /// The solver has no model of the full cutting route (kerf, leads).
    #[error("does not cut with kerf and leads yet (nearest, ccp, heuristic, exact and chain do)")]
    NoFullRouteModel,
    /// The thermal settings are out of range.
    #[error("{0}")]
    ThermalSettings(#[from] cutroute_protocol::ThermalSettingsError),
    /// The discretisation step of the full-route model is not a positive number.
    #[error("discretisation step {0}: must be positive")]
    DiscretisationStep(f64),
    /// With kerf and leads, exact searches the full-route model, which has no heat terms.
    #[error(
        "with kerf and leads, exact searches the full-route model and cannot price heat or \
         repair rules; use heuristic"
    )]
    ExactWithHeat,
}

/// Most kept (innermost) contours for which the discrete exact job bounds at the
/// discretisation's candidates rather than with the refined continuous relaxation. Up to ~22
/// the candidates' instance is solved exactly; above, the ng-path bound runs on it, which on
/// nested.dbs (70 kept) reached 9,086 in 60 s where the continuous bound reached ~7,950. Much
/// larger nests keep the continuous bound: its spatial groups are the stronger bound there
/// (the ng-path bound alone on Nest02's 359 kept contours: 3,400–4,000 against 12,000).
const DISCRETE_BOUND_MAX_KEPT: usize = 100;

/// Most contours of a discretised nest for which the exact job runs without the continuous
/// bound (the exact search's own bounds prove such nests: test0, test1, E1X_6_01 in seconds).
const DISCRETE_EXACT_ALONE_CONTOURS: usize = 35;

/// Build the job a request asks for. On a nest, the job runs inside a [`ThermalJob`]: its
/// progress carries H and the rule violations of [`SolverParams::thermal`], and with `hard`
/// its final route is repaired until the rules hold; with a positive heat weight, nearest, ccp
/// and chain price H in their search, and heuristic/exact relax their final pierce points on
/// idle + W·H (see the module `thermal` for what each solver honours).
///
/// [`SolverParams::thermal`]: cutroute_protocol::SolverParams::thermal
///
/// With [`SolverParams::kerf`] not idealised, the job is a [`KerfJob`] around such jobs (its
/// progress carries the full route with leads; see the module `kerf`).
///
/// [`SolverParams::kerf`]: cutroute_protocol::SolverParams::kerf
pub fn start_job(request: &JobRequest) -> Result<Box<dyn Job>, EngineError> {
    let params = &request.params;
    let Problem::Nest { nest, .. } = &request.problem else {
        return start_solver_job(request);
    };
    if !params.kerf.is_idealised() {
        return Ok(Box::new(KerfJob::from_request(request, start_job)?));
    }
    params
        .thermal
        .validate()
        .map_err(|e| EngineError::SolverRefused {
            solver: request.solver.name(),
            reason: e.into(),
        })?;
    let inner = match heated_job(request)? {
        Some(job) => job,
        None => start_solver_job(request)?,
    };
    Ok(Box::new(ThermalJob::new(
        inner,
        request.solver,
        nest.clone(),
        params.machine,
        params.objective,
        params.thermal,
        Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7)),
    )))
}

/// The nearest, ccp or chain job that prices heat, when the request's heat weight is positive
/// (else `None`). The ccp job has no lower bound: its search minimises idle + W·H, and the
/// bound's share of each slice would change the routes a weight gives.
fn heated_job(request: &JobRequest) -> Result<Option<Box<dyn Job>>, EngineError> {
    let params = &request.params;
    let Problem::Nest {
        nest,
        start,
        finish,
    } = &request.problem
    else {
        return Ok(None);
    };
    let solver = request.solver;
    if !params.thermal.penalised()
        || !matches!(
            solver,
            SolverKind::Ccp | SolverKind::Chain | SolverKind::NearestNeighbour
        )
    {
        return Ok(None);
    }
    let refused = |reason: Refusal| EngineError::SolverRefused {
        solver: solver.name(),
        reason,
    };
    let model = params.thermal.model().map_err(|e| refused(e.into()))?;
    let penalty = thermal::heat_penalty(&params.thermal, params.objective);
    if solver == SolverKind::NearestNeighbour {
        let job = NearestNeighbourJob::new(request.job_id, nest.clone(), *start, *finish)?
            .with_heat(model, penalty.weight_mm(&params.machine), params.machine);
        return Ok(Some(Box::new(job)));
    }
    let time_limit = Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7));
    let ccp_limit = if solver == SolverKind::Chain {
        time_limit.mul_f64(CHAIN_CCP_SHARE)
    } else {
        time_limit
    };
    let mut options = jobs::ccp_options(*start, *finish, ccp_limit, params.seed, params.machine);
    options.heat = Some(penalty);
    let ccp = cutroute_ccp::CcpSolver::new(nest, options).map_err(|e| refused(e.into()))?;
    Ok(Some(if solver == SolverKind::Chain {
        Box::new(ChainJob::new(
            request.job_id,
            ccp,
            nest.clone(),
            params.machine,
        ))
    } else {
        Box::new(CcpJob::new(request.job_id, ccp))
    }))
}

/// The solver's own job, without thermal settings.
fn start_solver_job(request: &JobRequest) -> Result<Box<dyn Job>, EngineError> {
    let params = &request.params;
    let time_limit = Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7));
    // Building the problem (a discretisation's dense matrix) counts against the limit.
    let started = web_time::Instant::now();
    let solver = request.solver;
    let refused = |reason: Refusal| EngineError::SolverRefused {
        solver: solver.name(),
        reason,
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
            let ccp = cutroute_ccp::CcpSolver::new(nest, options).map_err(|e| refused(e.into()))?;
            if solver == SolverKind::Chain {
                // The bound gets about half of the slices while the route is searched.
                let bound =
                    jobs::chain_lower_bound(nest, *start, *finish, &params.machine, time_limit / 2)
                        .map_err(|e| refused(e.into()))?;
                return Ok(Box::new(
                    ChainJob::new(request.job_id, ccp, nest.clone(), params.machine)
                        .with_time_limit(started, time_limit)
                        .with_lower_bound(bound, started, ccp_limit),
                ));
            }
            let bound = jobs::continuous_lower_bound(nest, *start, *finish, time_limit)
                .map_err(|e| refused(e.into()))?;
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
            let mode = discrete_mode.unwrap_or(DiscreteMode::Heuristic);
            // With a heat weight the arcs are priced once the matrix is there: built here, in
            // one piece. Otherwise the matrix is filled in the job's first steps (seconds on
            // big nests), so no step runs long.
            let (job, candidates) = if params.thermal.penalised() {
                let mut discrete =
                    cutroute_ccp::build_pcgtsp(nest, &options).map_err(|e| refused(e.into()))?;
                let model = params.thermal.model().map_err(|e| refused(e.into()))?;
                let weight_mm = thermal::heat_penalty(&params.thermal, params.objective)
                    .weight_mm(&params.machine);
                thermal::price_consecutive_heat(
                    &mut discrete,
                    nest,
                    &model,
                    weight_mm,
                    &params.machine,
                );
                let candidates = cutroute_ccp::pierce_candidates(&discrete.nodes);
                let instance = discrete.instance.clone();
                let job = DiscreteJob::new(
                    request.job_id,
                    instance,
                    Some(discrete),
                    mode,
                    time_limit,
                    started,
                    params.seed,
                )
                .map_err(refused)?;
                (job, candidates)
            } else {
                let builder = cutroute_ccp::PcgtspBuilder::new(nest, &options)
                    .map_err(|e| refused(e.into()))?;
                let candidates = cutroute_ccp::pierce_candidates(builder.nodes());
                let job = DiscreteJob::building(
                    request.job_id,
                    builder,
                    mode,
                    time_limit,
                    started,
                    params.seed,
                );
                (job, candidates)
            };
            // On nests of up to ~35 contours (the industrial set's size) the exact search
            // builds its lattice bound and proves the discrete optimum itself: the continuous
            // bound, below that optimum, would only take its time. (Counting the order's
            // ideals to decide took 10 s on seven.dbs.)
            let exact_alone = nest.contour_count() <= DISCRETE_EXACT_ALONE_CONTOURS;
            // CCP-Relax's route seeds the heuristic (in its order of contours, at the cheapest
            // candidates), in a twelfth of the limit: 4 s of it reach 9,535 mm on nested.dbs.
            // Not where the exact search proves the optimum itself: there the heuristic's
            // share feeds it incumbents (test1 was proven in 4.7 s with the seed, 3.0 s
            // without).
            let job = if mode == DiscreteMode::Exact && exact_alone {
                job
            } else {
                let seed_options = jobs::ccp_options(
                    *start,
                    *finish,
                    time_limit.mul_f64(ROUTE_SEED_SHARE),
                    params.seed,
                    params.machine,
                );
                match cutroute_ccp::CcpSolver::new(nest, seed_options) {
                    Ok(ccp) => job.with_route_seed(ccp),
                    Err(_) => job,
                }
            };
            if mode != DiscreteMode::Exact || options.round_costs || exact_alone {
                return Ok(Box::new(job));
            }
            // The exact search's own bounds relax "a pierce point is entered and left at one
            // node" on nests of more than ~20 contours; the continuous bound of the same nest,
            // start and finish (below the discrete optimum) keeps it.
            let bound_options = cutroute_ccp::LowerBoundOptions {
                start: *start,
                finish: *finish,
                budget_seconds: time_limit.as_secs_f64() / 2.0,
                first_stage: (time_limit / 20).clamp(
                    web_time::Duration::from_millis(250),
                    web_time::Duration::from_secs(3),
                ),
                ..Default::default()
            };
            let bound = cutroute_ccp::CcpLowerBound::new(nest, bound_options.clone())
                .map_err(|e| refused(e.into()))?;
            // The bound at the discretisation's own candidates is tighter than the continuous
            // one and needs no refinement: its nodes are points, entered and left at one
            // place. Where the candidates do not fit its matrix, the continuous bound stays.
            // Its ng-path bound runs with the widest neighbourhoods from the start: on
            // nested.dbs at 25 mm (2,141 nodes) they reached 9,342 in 60 s, against 9,262
            // after starting with ng = 8 for 24 passes.
            let bound = if bound.kept_contours() <= DISCRETE_BOUND_MAX_KEPT {
                cutroute_ccp::CcpLowerBound::for_candidates(
                    nest,
                    cutroute_ccp::LowerBoundOptions {
                        max_nodes: 4000,
                        ng_size: cutroute_ccp::MAX_NG,
                        ..bound_options
                    },
                    &candidates,
                )
                .map_err(|e| refused(e.into()))?
                .unwrap_or(bound)
            } else {
                bound
            };
            Ok(Box::new(job.with_lower_bound(bound)))
        }
        (Problem::PcgtspText { text }, _) => {
            let Some(mode) = discrete_mode else {
                return Err(EngineError::UnsupportedProblem {
                    solver: solver.name(),
                    problem: "a PCGTSP instance",
                });
            };
            let instance = cutroute_pcgtsp::Instance::parse(text).map_err(|e| refused(e.into()))?;
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
