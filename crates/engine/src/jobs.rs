//! The solver jobs: each wraps one resumable solver (or two that cooperate) behind [`Job`].

use cutroute_alns::{AlnsBuilder, AlnsOptions, AlnsSolver};
use cutroute_anytime::AnytimeSolver;
use cutroute_ccp::{CcpLowerBound, CcpOptions, CcpSolver, DiscreteInstance, LinkPrices};
use cutroute_chains::{ChainError, ChainOptions, Chained, Chaining};
use cutroute_geometry::{MachineParameters, Nest, Route};
use cutroute_pcgtsp::{ExactOptions, ExactSolver, Instance};
use cutroute_protocol::{Bounds, CcpStage, CostUnit, JobId, Phase, Progress, Solution};
use web_time::{Duration, Instant};

use crate::{Job, JobStatus, Refusal};

/// CCP-Relax on a nest, and beside it (when given) the certified lower bound of the interval
/// relaxation (`cutroute_ccp::CcpLowerBound`), each slice shared half and half; the bound
/// learns every improved route (its pierce points guide the refinement). When the VNS ends
/// before the time limit, the bound gets the rest of it; the job ends early when the bound
/// meets the route.
pub struct CcpJob {
    job_id: JobId,
    solver: CcpSolver,
    solver_done: bool,
    bound: Option<CcpLowerBound>,
    /// Whether the bound may still improve (false once it has nothing left to do).
    bound_running: bool,
    /// The whole job's limit, for the bound's running on alone.
    time_limit: Duration,
    offered_length: f64,
    started: Instant,
    done: bool,
}

impl CcpJob {
    /// Wrap a prepared solver.
    pub fn new(job_id: JobId, solver: CcpSolver) -> Self {
        Self {
            job_id,
            solver,
            solver_done: false,
            bound: None,
            bound_running: false,
            time_limit: Duration::ZERO,
            offered_length: f64::INFINITY,
            started: Instant::now(),
            done: false,
        }
    }

    /// Adds the lower bound of the same nest, start and finish, computed until `time_limit`
    /// (the solver's own limit) from now.
    pub fn with_lower_bound(mut self, bound: CcpLowerBound, time_limit: Duration) -> Self {
        self.bound = Some(bound);
        self.bound_running = true;
        self.time_limit = time_limit;
        self.started = Instant::now();
        self
    }

    /// The bound is within `relative` of the best route offered to it.
    fn bound_within(&self, relative: f64) -> bool {
        let lb = self.bound.as_ref().map_or(0.0, |b| b.lower_bound());
        lb > 0.0 && lb >= self.offered_length * (1.0 - relative)
    }
}

impl Job for CcpJob {
    fn stop(&mut self) {
        self.solver.cancel();
        self.done = true;
    }

    fn step(&mut self, budget: Duration) -> JobStatus {
        if self.done {
            return JobStatus::Done;
        }
        let share = if self.bound_running && !self.solver_done {
            budget / 2
        } else {
            budget
        };
        if self.bound.is_some() && self.started.elapsed() >= self.time_limit {
            // The solver counts only its own share of the slices: the job's limit is wall
            // time, so end the VNS here (its best route stays).
            self.solver.cancel();
        }
        if !self.solver_done {
            self.solver_done = self.solver.step(share).is_done();
        }
        if let Some(bound) = self.bound.as_mut().filter(|_| self.bound_running) {
            let state = self.solver.progress();
            if !state.route.steps.is_empty() && state.best_idle_length < self.offered_length {
                self.offered_length = state.best_idle_length;
                bound.offer_route(&state.route);
            }
            let left = self.time_limit.saturating_sub(self.started.elapsed());
            let slice = if self.solver_done {
                budget
            } else {
                budget - share
            };
            self.bound_running = !left.is_zero() && bound.step(slice.min(left));
        }
        // Within 10⁻⁶ nothing a user can see is left to prove (the distances carry a 10⁻⁹
        // margin): stop rather than refine pieces for the last micrometres.
        self.done = (self.solver_done && !self.bound_running) || self.bound_within(1e-6);
        if self.done {
            JobStatus::Done
        } else {
            JobStatus::Running
        }
    }

    fn progress(&self) -> Progress {
        let state = self.solver.progress();
        let has_route = !state.route.steps.is_empty();
        // Certificates cost a pass over the route: only for the final answer (done, or
        // stopped).
        let certified = if self.done && has_route {
            let by_contour: std::collections::HashMap<_, _> = self
                .solver
                .certificates()
                .into_iter()
                .map(|c| (c.contour, c.condition1))
                .collect();
            state
                .route
                .steps
                .iter()
                .map(|s| by_contour.get(&s.contour).copied().unwrap_or(false))
                .collect()
        } else {
            Vec::new()
        };
        Progress {
            job_id: self.job_id,
            elapsed_s: if self.bound.is_some() {
                self.started.elapsed().as_secs_f64()
            } else {
                state.elapsed.as_secs_f64()
            },
            bounds: Bounds::idle_mm(
                has_route.then_some(state.best_idle_length),
                self.bound.as_ref().map(|b| b.lower_bound()),
            ),
            phase: Phase::Ccp(ccp_stage(state.phase)),
            solution: has_route.then_some(Solution::Route(state.route)),
            proven_optimal: has_route && self.bound_within(1e-9),
            states: None,
            certified,
            alternatives: Vec::new(),
            ..Progress::default()
        }
    }
}

/// How a discrete job searches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiscreteMode {
    /// ALNS only: upper bounds.
    Heuristic,
    /// ALNS feeding incumbents to the exact search, which proves lower bounds.
    Exact,
}

/// A PCGTSP job: ALNS alone, or ALNS and the exact solver sharing the time (the heuristic gets
/// a quarter of each slice while the exact search runs, and every improvement it finds is
/// offered to the exact search as an incumbent).
///
/// The model is built in steps of its own, so no step runs long and the build counts against
/// the limit: the discretisation's cost matrix row by row ([`cutroute_ccp::PcgtspBuilder`]),
/// then the ALNS, then the exact solver (each solver gets the limit's rest when it is made).
///
/// On a discretised nest the exact search may run beside the continuous bound of the same nest
/// (`with_lower_bound`): every discrete tour is a continuous route with the same idle length,
/// so the continuous optimum, and any lower bound of it, is below the discrete optimum. The
/// bound then gets the exact search's part of each slice until it ends or half the limit has
/// passed (to the end where its ng-path bound is above the exact search's root bound), and
/// shares it half and half after that; its value is offered to the exact search as a proven
/// lower bound.
pub struct DiscreteJob {
    job_id: JobId,
    mode: DiscreteMode,
    seed: u64,
    /// The wall-clock end of the job (its limit counted from the request).
    deadline: Instant,
    /// A first tour is worth this much time even when the build used up the limit.
    first_tour_allowance: Duration,
    /// The discretisation under way (nest problems only).
    builder: Option<Box<cutroute_ccp::PcgtspBuilder>>,
    /// The instance of a PCGTSP problem (a nest's is in `discrete`).
    instance: Option<Instance>,
    discrete: Option<DiscreteInstance>,
    alns: Option<AlnsSolver>,
    /// The heuristic being prepared, a piece per step (seconds on a big discretisation).
    alns_builder: Option<AlnsBuilder>,
    alns_done: bool,
    /// The exact solver's copy of the instance, being made (a slice of rows per step).
    exact_instance: Option<Instance>,
    exact: Option<ExactSolver>,
    exact_done: Option<bool>,
    /// The longest single piece of the exact solver so far (its making, then its steps): a
    /// piece is not started when less time than that is left (see `step`).
    exact_piece: Duration,
    offered_cost: f64,
    /// The continuous bound of the nest the instance discretises, while it may still improve.
    bound: Option<CcpLowerBound>,
    bound_running: bool,
    offered_route_cost: f64,
    started: Instant,
    /// Why the job ended without a search.
    failure: Option<DiscreteFailure>,
    /// The nearest-neighbour tour and its cost, made when the limit came before the heuristic
    /// had a tour (the build took the time): a route to show rather than none.
    fallback: Option<(Vec<usize>, f64)>,
    fallback_tried: bool,
    /// CCP-Relax on the nest the instance discretises, run first in the heuristic's share:
    /// its route, in its order of contours at the cheapest candidates, seeds the heuristic
    /// (`with_route_seed`).
    route_seed: Option<Box<cutroute_ccp::CcpSolver>>,
    /// [`Job::stop`] ended the job.
    stopped: bool,
}

/// Why a discrete job ended without a search; its words are the phase's reason.
#[derive(Clone, Debug, thiserror::Error)]
enum DiscreteFailure {
    /// A solver refused the instance (its error, for [`DiscreteJob::new`]).
    #[error("{0}")]
    Refused(#[from] Refusal),
    /// The time limit passed while the model was built (the phase says it as
    /// [`Phase::BuildTimedOut`]).
    #[error("the time limit passed while the model was built")]
    BuildTimedOut,
}

impl DiscreteJob {
    /// A job on an instance, ended `time_limit` after `started` (the request's arrival: what
    /// was spent before counts). `discrete` maps nodes back to pierce points when the instance
    /// was built from a nest. The solvers are made here, so one that refuses the instance
    /// (infeasible, too large) is an error now.
    pub fn new(
        job_id: JobId,
        instance: Instance,
        discrete: Option<DiscreteInstance>,
        mode: DiscreteMode,
        time_limit: Duration,
        started: Instant,
        seed: u64,
    ) -> Result<Self, Refusal> {
        let mut job = Self::pending(job_id, mode, time_limit, started, seed);
        job.instance = Some(instance);
        job.discrete = discrete;
        while !job.build(Duration::MAX) {
            if let Some(DiscreteFailure::Refused(refusal)) = job.failure.take() {
                return Err(refusal);
            }
        }
        Ok(job)
    }

    /// A job on an instance like [`DiscreteJob::new`], but its solvers are made in its first
    /// steps (on a big instance that is seconds: [`DiscreteJob::new`] is one piece); a solver
    /// that refuses the instance ends the job there, its phase saying why.
    pub fn unbuilt(
        job_id: JobId,
        instance: Instance,
        mode: DiscreteMode,
        time_limit: Duration,
        started: Instant,
        seed: u64,
    ) -> Self {
        let mut job = Self::pending(job_id, mode, time_limit, started, seed);
        job.instance = Some(instance);
        job
    }

    /// A job on the discretisation `builder` is building (one step fills rows of its matrix).
    pub fn building(
        job_id: JobId,
        builder: cutroute_ccp::PcgtspBuilder,
        mode: DiscreteMode,
        time_limit: Duration,
        started: Instant,
        seed: u64,
    ) -> Self {
        let mut job = Self::pending(job_id, mode, time_limit, started, seed);
        job.builder = Some(Box::new(builder));
        job
    }

    fn pending(
        job_id: JobId,
        mode: DiscreteMode,
        time_limit: Duration,
        started: Instant,
        seed: u64,
    ) -> Self {
        Self {
            job_id,
            mode,
            seed,
            deadline: started + time_limit,
            // A tenth of the limit, at most half a second: a run whose build used up the
            // limit still gets a first tour, within the limit + 1 s promise.
            first_tour_allowance: (time_limit / 10).min(Duration::from_millis(500)),
            builder: None,
            instance: None,
            discrete: None,
            alns: None,
            alns_builder: None,
            alns_done: false,
            exact_instance: None,
            exact: None,
            exact_done: None,
            exact_piece: Duration::ZERO,
            offered_cost: f64::INFINITY,
            bound: None,
            bound_running: false,
            offered_route_cost: f64::INFINITY,
            started,
            failure: None,
            fallback: None,
            fallback_tried: false,
            route_seed: None,
            stopped: false,
        }
    }

    /// Seeds the heuristic with a continuous route of the nest this job's instance
    /// discretises: `ccp` runs first in the heuristic's share of the slices (to its own time
    /// limit), and its route, in its order of contours at the cheapest candidates
    /// ([`cutroute_ccp::DiscreteInstance::tour_in_order_of`]), is offered to the heuristic,
    /// which goes on from it when it is cheaper. Free pierce points find better orders than
    /// a search over the candidates: on nested.dbs at 25 mm, 9,558 mm against the heuristic's
    /// 9,622–9,632 in 60 s.
    pub fn with_route_seed(mut self, ccp: cutroute_ccp::CcpSolver) -> Self {
        self.route_seed = Some(Box::new(ccp));
        self
    }

    /// One slice of the heuristic's `share`: the seeding CCP-Relax while it runs (its route
    /// offered to the heuristic when it ends), then the heuristic. Whether the heuristic has
    /// finished.
    fn heuristic_step(&mut self, share: Duration) -> bool {
        // (After the heuristic's first tour: a route to show comes first.)
        let first_tour = |job: &Self| job.alns.as_ref().is_some_and(|a| a.best().is_some());
        if self.route_seed.is_some() && first_tour(self) {
            let ccp = self.route_seed.as_mut().expect("checked above");
            if !ccp.step(share).is_done() {
                return false;
            }
            let route = cutroute_anytime::AnytimeSolver::best(&**ccp);
            self.route_seed = None;
            let tour = route
                .zip(self.discrete.as_ref())
                .and_then(|(route, discrete)| discrete.tour_in_order_of(&route));
            if let (Some((tour, _)), Some(alns)) = (tour, self.alns.as_mut()) {
                alns.offer_tour(&tour);
            }
            return false;
        }
        self.alns
            .as_mut()
            .is_some_and(|alns| alns_step(alns, share))
    }

    /// Adds the continuous lower bound (`CcpLowerBound`) of the nest this job's instance
    /// discretises, with the same start and finish and unrounded costs (the caller vouches for
    /// that: the bound is then below the discrete optimum). Only for the exact mode.
    pub fn with_lower_bound(mut self, bound: CcpLowerBound) -> Self {
        if self.mode == DiscreteMode::Exact {
            self.bound = Some(bound);
            self.bound_running = true;
        }
        self
    }

    /// Runs the continuous bound for `slice` and hands its value to the exact search.
    fn step_bound(&mut self, slice: Duration) {
        let (Some(bound), Some(exact)) = (self.bound.as_mut(), self.exact.as_mut()) else {
            return;
        };
        if !self.bound_running {
            return;
        }
        let best = self.alns.as_ref().and_then(|a| a.best());
        if let (Some(discrete), Some((tour, cost))) = (&self.discrete, best) {
            if cost < self.offered_route_cost {
                if let Ok(route) = discrete.tour_to_route(tour) {
                    self.offered_route_cost = cost;
                    bound.offer_route(&route);
                }
            }
        }
        let left = self.deadline.saturating_duration_since(Instant::now());
        self.bound_running = !left.is_zero() && bound.step(slice.min(left));
        let lb = bound.lower_bound();
        if lb > 0.0 {
            exact.offer_lower_bound(lb);
        }
    }

    /// The time a solver made now may run.
    fn time_left(&self) -> Duration {
        self.deadline
            .saturating_duration_since(Instant::now())
            .max(self.first_tour_allowance)
    }

    /// Builds what is missing, one piece per call; true when everything is built.
    fn build(&mut self, budget: Duration) -> bool {
        if let Some(builder) = self.builder.as_mut() {
            let slice_end = Instant::now().checked_add(budget);
            if let Some(discrete) =
                builder.advance(&|| slice_end.is_some_and(|end| Instant::now() >= end))
            {
                // Kept once, inside `discrete`: the dense matrix of a big nest is hundreds of MB.
                self.discrete = Some(discrete);
                self.builder = None;
            }
            return false;
        }
        let Some(instance) = self
            .instance
            .as_ref()
            .or(self.discrete.as_ref().map(|d| &d.instance))
        else {
            return false;
        };
        if self.alns.is_none() {
            let builder = match self.alns_builder.take() {
                Some(builder) => Ok(builder),
                None => AlnsSolver::builder(
                    instance,
                    AlnsOptions {
                        seed: self.seed,
                        time_limit: Some(self.time_left()),
                        ..AlnsOptions::default()
                    },
                ),
            };
            match builder.and_then(|mut b| b.advance(instance, budget).map(|done| (b, done))) {
                Ok((_, Some(alns))) => self.alns = Some(alns),
                Ok((builder, None)) => self.alns_builder = Some(builder),
                Err(e) => self.refuse(e.into()),
            }
            return false;
        }
        if self.mode == DiscreteMode::Exact && self.exact.is_none() && self.exact_done.is_none() {
            if Instant::now() >= self.deadline {
                // The limit passed before the exact solver was made (its instance copy on a
                // big discretisation): the heuristic's tour is the answer.
                self.exact_instance = None;
                self.exact_done = Some(false);
                return true;
            }
            // ALNS supplies the incumbents here, so the exact solver's own beam search (which
            // ate the whole budget on nests of 50-90 contours, leaving only the root assignment
            // bound) is switched off: the time goes to the bounds.
            let options = ExactOptions {
                time_limit: Some(self.time_left()),
                heuristic: false,
                ..ExactOptions::default()
            };
            // The solver keeps its own instance, copied here a slice of rows at a time (on a
            // 7,000-node discretisation one copy was a step of 0.5 s).
            let n = instance.node_count;
            let copy = self.exact_instance.get_or_insert_with(|| Instance {
                name: instance.name.clone(),
                node_count: n,
                cost: Vec::with_capacity(n * n),
                clusters: instance.clusters.clone(),
                node_cluster: instance.node_cluster.clone(),
                precedence: instance.precedence.clone(),
                depot: instance.depot,
            });
            let copying = Instant::now();
            while copy.cost.len() < n * n {
                let row = copy.cost.len() / n;
                let end = (row + 64).min(n);
                copy.cost
                    .extend_from_slice(&instance.cost[row * n..end * n]);
                if copying.elapsed() >= budget {
                    break;
                }
            }
            if copy.cost.len() < n * n {
                return false;
            }
            let copy = self.exact_instance.take().expect("copied above");
            let made = Instant::now();
            match ExactSolver::deferred_owned(copy, options) {
                Ok(exact) => self.exact = Some(exact),
                Err(e) => self.refuse(e.into()),
            }
            self.exact_piece = made.elapsed();
            return false;
        }
        true
    }

    /// A solver refused the instance: the job ends, its phase saying why.
    fn refuse(&mut self, refusal: Refusal) {
        self.failure = Some(refusal.into());
    }

    /// The best tour: the solvers', or the nearest-neighbour one if it is cheaper or the only.
    fn best_tour(&self) -> Option<(Vec<usize>, f64)> {
        [self.solvers_tour(), self.fallback.clone()]
            .into_iter()
            .flatten()
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether the heuristic solved the instance outright (a tiny one: every order tried), so
    /// its tour is proven optimal.
    fn heuristic_proved(&self) -> bool {
        self.alns
            .as_ref()
            .is_some_and(|a| a.progress().stop_reason == Some(cutroute_alns::StopReason::Exhausted))
    }

    /// The better of the heuristic's and the exact search's best tours.
    fn solvers_tour(&self) -> Option<(Vec<usize>, f64)> {
        let heuristic = self.alns.as_ref().and_then(best_with_cost);
        let exact = self.exact.as_ref().and_then(best_with_cost);
        [heuristic, exact]
            .into_iter()
            .flatten()
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// The nearest-neighbour tour of what is built so far: from the candidate points while the
    /// matrix is being filled (no matrix needed), else from the instance's costs.
    fn nearest_neighbour_tour(&self) -> Option<(Vec<usize>, f64)> {
        if let Some(builder) = &self.builder {
            return builder.nearest_neighbour_tour();
        }
        let instance = self
            .instance
            .as_ref()
            .or(self.discrete.as_ref().map(|d| &d.instance))?;
        let &start = instance.clusters.get(instance.depot)?.first()?;
        cutroute_pcgtsp::nearest_neighbour_tour(
            start,
            instance.depot,
            &instance.clusters,
            &instance.precedence,
            &|a, b| instance.arc_cost(a, b),
        )
    }

    /// A tour's route: by the discretisation, or by its builder while the matrix is unfinished.
    fn route_of(&self, tour: &[usize]) -> Option<Route> {
        match (&self.discrete, &self.builder) {
            (Some(discrete), _) => discrete.tour_to_route(tour).ok(),
            (None, Some(builder)) => builder.tour_to_route(tour).ok(),
            (None, None) => None,
        }
    }
}

/// How long past its limit a discrete job still finishes the heuristic's preparation (its
/// first tour comes after, within the limit + 1 s promise).
const LATEST_PREPARATION: Duration = Duration::from_millis(600);

/// One slice of the heuristic; whether it has finished.
fn alns_step(alns: &mut AlnsSolver, budget: Duration) -> bool {
    alns.step(budget).is_done()
}

/// A solver's best solution with its objective (the upper bound).
fn best_with_cost<S: AnytimeSolver>(solver: &S) -> Option<(S::Solution, f64)> {
    Some((solver.best()?, solver.bounds().upper?))
}

impl Job for DiscreteJob {
    fn stop(&mut self) {
        // As the limit reached now: the solvers' best tour, or (none yet) the nearest-neighbour
        // one that a limit passing during the build gives.
        self.deadline = Instant::now();
        self.first_tour_allowance = Duration::ZERO;
        if self.solvers_tour().is_none() && !self.fallback_tried {
            self.fallback_tried = true;
            self.fallback = self.nearest_neighbour_tour();
        }
        if self.exact.is_some() && self.exact_done.is_none() {
            self.exact_done = Some(false);
        }
        self.alns_done = true;
        self.bound_running = false;
        self.stopped = true;
    }

    fn step(&mut self, budget: Duration) -> JobStatus {
        if self.stopped {
            return JobStatus::Done;
        }
        if self.failure.is_some() {
            return JobStatus::Done;
        }
        if !self.build(budget) {
            if Instant::now() >= self.deadline && self.alns.is_none() && !self.fallback_tried {
                // The limit came before the heuristic could give its first tour: the
                // nearest-neighbour one (tens of milliseconds on Nest03 at 25 mm, from the
                // points) is kept, and replaced if the heuristic's preparation still ends in time.
                self.fallback_tried = true;
                self.fallback = self.nearest_neighbour_tour();
                return JobStatus::Running;
            }
            // A build past the limit ends the job (no solver yet: the tour, if any, is the
            // nearest-neighbour one). The
            // heuristic's own preparation, once started, is finished (it is one pass over the
            // matrix, bounded, and then gives the first tour), as when it was one step ...
            let now = Instant::now();
            let over = now >= self.deadline + self.first_tour_allowance;
            // ... unless it is still under way this late: the first tour would come after the
            // limit + 1 s promise (a 25 mm discretisation of Nest02: the preparation alone
            // ran 3 s past a 5 s limit).
            let preparing = self.alns_builder.is_some() && now < self.deadline + LATEST_PREPARATION;
            return if self.failure.is_some() || (over && self.alns.is_none() && !preparing) {
                if self.failure.is_none() {
                    self.failure = Some(DiscreteFailure::BuildTimedOut);
                }
                JobStatus::Done
            } else {
                JobStatus::Running
            };
        }
        if Instant::now() >= self.deadline && self.solvers_tour().is_some() {
            // The solvers count only their own shares of the slices (and were made after the
            // build): the job's limit is wall time from the request, so it ends here.
            if self.exact.is_some() && self.exact_done.is_none() {
                self.exact_done = Some(false);
            }
            self.alns_done = true;
            return JobStatus::Done;
        }
        let alns = self.alns.as_mut().expect("built");
        if Instant::now() >= self.deadline {
            // The limit came before the first tour (a big model took the time): its rest is
            // inserted cheaply, with the whole slice, so that the tour still comes within the
            // limit + 1 s promise (Nest03 at 25 mm: the cheapest insertion ran 2.25 s past a 5 s
            // limit under load). The exact solver has nothing to add in that time.
            alns.hurry_first_tour();
            self.alns_done = alns.step(budget).is_done();
            return if self.alns_done {
                JobStatus::Done
            } else {
                JobStatus::Running
            };
        }
        if self.exact.is_none() {
            if self.alns_done || self.heuristic_step(budget) {
                self.alns_done = true;
                return JobStatus::Done;
            }
            return JobStatus::Running;
        }
        if !self.alns_done {
            let share = if self.exact_done.is_some() {
                budget
            } else {
                budget / 4
            };
            self.alns_done = self.heuristic_step(share);
            let (Some(alns), Some(exact)) = (self.alns.as_ref(), self.exact.as_mut()) else {
                return JobStatus::Running;
            };
            if let Some((tour, cost)) = alns.best() {
                if cost < self.offered_cost {
                    self.offered_cost = cost;
                    exact.offer_incumbent(tour, cost);
                }
            }
            if self.heuristic_proved() {
                // Solved outright: nothing is left for the exact search to prove.
                return JobStatus::Done;
            }
        }
        let mut exact_share = budget - budget / 4;
        if self.bound_running && self.exact_done.is_none() {
            // The bound first (solved exactly at the candidates of up to ~22 kept contours,
            // in seconds), for at most half of the limit; then the two share. The exact
            // search's bound preparation on these orders is long and weaker than the bound.
            // An ng-path bound (more kept contours) keeps the whole share while it is above
            // the exact search's root bound: that search's later bounds stay near its root
            // (nested.dbs at 25 mm: 4,549 at best against the ng-path bound's 9,000), while
            // the ng-path bound rises to the end.
            let half_limit = self.started + (self.deadline - self.started) / 2;
            let ng_leads = match (&self.bound, &self.exact) {
                // (−∞ until the search's root is built: its share would only build it.)
                (Some(bound), Some(exact)) => {
                    bound.ng_bound() > 0.0 && bound.ng_bound() > exact.root_bound()
                }
                _ => false,
            };
            let bound_share = if Instant::now() < half_limit || ng_leads {
                exact_share
            } else {
                exact_share / 2
            };
            exact_share -= bound_share;
            self.step_bound(bound_share);
            if exact_share.is_zero() {
                return JobStatus::Running;
            }
        }
        let exact = self.exact.as_mut().expect("built");
        // A piece of the exact solver is not split further (a start node's model or root
        // bound: seconds on thousands of nodes, several times the instance's copy when it was
        // made; later pieces no longer than the longest so far): none is started that would
        // run past the limit. The heuristic takes the slice instead.
        let left = self.deadline.saturating_duration_since(Instant::now());
        let piece = if exact.runs_built() {
            self.exact_piece
        } else {
            self.exact_piece * 4
        };
        if self.exact_done.is_none() && left < piece {
            if !self.alns_done {
                self.alns_done = self.heuristic_step(exact_share);
            }
            return JobStatus::Running;
        }
        if self.exact_done.is_none() {
            let began = Instant::now();
            let status = exact.step(exact_share);
            self.exact_piece = self.exact_piece.max(began.elapsed());
            if status.is_done() {
                self.exact_done = Some(status.proven_optimal());
            }
        }
        // Once the exact search has ended there is nothing left to prove: stop the heuristic too.
        if self.exact_done.is_some() {
            return JobStatus::Done;
        }
        JobStatus::Running
    }

    fn progress(&self) -> Progress {
        let best = self.best_tour();
        let exact = self.exact.as_ref().map(|e| e.progress());
        let route: Option<Route> = best.as_ref().and_then(|(tour, _)| self.route_of(tour));
        let exhausted = self.heuristic_proved();
        let proven_optimal = self.exact_done == Some(true) || exhausted;
        let phase = match (&exact, self.exact_done) {
            _ if exhausted => Phase::ProvenOptimal,
            _ if matches!(self.failure, Some(DiscreteFailure::BuildTimedOut)) => {
                Phase::BuildTimedOut
            }
            _ if self.failure.is_some() => Phase::Stopped {
                reason: self.failure.as_ref().map(ToString::to_string),
            },
            (_, Some(true)) => Phase::ProvenOptimal,
            (_, Some(false)) => Phase::Stopped { reason: None },
            (Some(p), None) => Phase::ExactLayer {
                layer: p.layer,
                states: p.live_states,
            },
            (None, _) => match (&self.builder, &self.alns) {
                (Some(b), _) => Phase::BuildingMatrix {
                    rows_done: b.rows_done(),
                    rows: b.node_count(),
                },
                (None, None) => Phase::BuildingHeuristic,
                (None, Some(_)) if self.mode == DiscreteMode::Exact => Phase::BuildingExact,
                (None, Some(alns)) => Phase::Alns {
                    iterations: alns.progress().iterations,
                },
            },
        };
        let lower_bound = exact
            .as_ref()
            .map(|p| p.lower_bound)
            .filter(|lb| lb.is_finite());
        // A discretised nest's tour is reported as its route, in idle mm; an instance's tour
        // in the instance's weights.
        let nest = self.discrete.is_some() || self.builder.is_some();
        let (solution, unit) = match nest {
            true => (route.map(Solution::Route), CostUnit::IdleMm),
            false => (
                best.as_ref().map(|(tour, _)| Solution::Tour(tour.clone())),
                CostUnit::TourCost,
            ),
        };
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            bounds: Bounds {
                upper: best.as_ref().map(|(_, cost)| *cost),
                lower: if proven_optimal {
                    best.as_ref().map(|(_, c)| *c)
                } else {
                    lower_bound
                },
                unit,
            },
            phase,
            solution,
            proven_optimal,
            states: self.exact.as_ref().map(|e| e.states_created()),
            certified: Vec::new(),
            alternatives: Vec::new(),
            ..Progress::default()
        }
    }
}

/// Options of a CCP job from the protocol's parameters.
pub fn ccp_options(
    start: cutroute_geometry::Point,
    finish: Option<cutroute_geometry::Point>,
    time_limit: Duration,
    seed: u64,
    machine: MachineParameters,
) -> CcpOptions {
    CcpOptions {
        start,
        finish,
        time_limit,
        seed,
        machine,
        ..CcpOptions::default()
    }
}

/// The certified lower bound on the idle length of every CCP route of `nest` from `start`
/// (to `finish`), planned for `budget` of its own time: the `ccp` job's, and the segment jobs'
/// where every segment is a whole contour.
pub fn continuous_lower_bound(
    nest: &Nest,
    start: cutroute_geometry::Point,
    finish: Option<cutroute_geometry::Point>,
    budget: Duration,
) -> Result<CcpLowerBound, cutroute_ccp::CcpError> {
    lower_bound_with(nest, start, finish, budget, None)
}

/// The certified lower bound on the cost of every chain-cutting route of `nest` (links and
/// pierces at `machine`'s prices) less the cut of its perimeters; planned for `budget`.
pub fn chain_lower_bound(
    nest: &Nest,
    start: cutroute_geometry::Point,
    finish: Option<cutroute_geometry::Point>,
    machine: &MachineParameters,
    budget: Duration,
) -> Result<CcpLowerBound, cutroute_ccp::CcpError> {
    let links = LinkPrices {
        idle_per_mm: machine.idle_price_per_metre * 1e-3,
        cut_per_mm: machine.cut_price_per_metre * 1e-3,
        pierce: machine.pierce_price,
    };
    lower_bound_with(nest, start, finish, budget, Some(links))
}

fn lower_bound_with(
    nest: &Nest,
    start: cutroute_geometry::Point,
    finish: Option<cutroute_geometry::Point>,
    budget: Duration,
    links: Option<LinkPrices>,
) -> Result<CcpLowerBound, cutroute_ccp::CcpError> {
    CcpLowerBound::new(
        nest,
        cutroute_ccp::LowerBoundOptions {
            start,
            finish,
            budget_seconds: budget.as_secs_f64(),
            first_stage: (budget / 10).clamp(Duration::from_millis(500), Duration::from_secs(5)),
            links,
            ..Default::default()
        },
    )
}

/// CCP-Relax, then chain cutting of its route (`cutroute-chains`): the CCP phase streams its
/// progress as a CCP job does; the chaining is set up in the step after CCP ends and tries its
/// groups in the steps after that. Its bounds are on the route's cost (formula 1.3: what
/// chaining minimises), and with [`ChainJob::with_lower_bound`] the certified bound of chain
/// cutting runs beside both phases, as long as each step's route work did, and on alone after
/// them until its first stage is done (within the limit).
pub struct ChainJob {
    ccp: CcpJob,
    nest: Nest,
    options: ChainOptions,
    /// Chain cutting under way, in slices of close-contour groups (Stop stays responsive).
    chaining: Option<Chaining>,
    chained: Option<Chained>,
    failure: Option<ChainFailure>,
    /// Whether CCP-Relax has ended (its last step, `Chaining::new` and the groups each take
    /// steps of their own: together they ran 2 s on a thousand contours).
    ccp_done: bool,
    started: Instant,
    /// The job's wall-clock end: chain cutting gives up the group under way there.
    deadline: Option<Instant>,
    /// The lower bound beside the route's search (see [`ChainJob::with_lower_bound`]).
    bound: Option<ChainBound>,
}

/// The certified bound of a [`ChainJob`].
struct ChainBound {
    /// The moves' part (`cutroute_ccp::LinkPrices`).
    moves: CcpLowerBound,
    /// Every contour's perimeter cut, at the cut price: what every route pays besides.
    perimeters: f64,
    /// Whether it may still improve.
    running: bool,
    /// The idle length of the last route offered to it.
    offered: f64,
    /// When CCP-Relax, which shares the slices with it, is stopped (its share of the limit).
    ccp_end: Instant,
}

impl ChainJob {
    /// Wrap a prepared CCP solver; `machine` prices the links.
    pub fn new(job_id: JobId, solver: CcpSolver, nest: Nest, machine: MachineParameters) -> Self {
        Self {
            ccp: CcpJob::new(job_id, solver),
            nest,
            options: ChainOptions {
                machine,
                ..ChainOptions::default()
            },
            chaining: None,
            chained: None,
            failure: None,
            ccp_done: false,
            started: Instant::now(),
            deadline: None,
            bound: None,
        }
    }

    /// Ends the job `time_limit` after `started` (CCP has its own share of it): a chain group
    /// still under way then is dropped and the route keeps the groups done before.
    pub fn with_time_limit(mut self, started: Instant, time_limit: Duration) -> Self {
        self.deadline = Some(started + time_limit);
        self
    }

    /// Adds the certified lower bound of chain cutting (`bound`, from [`chain_lower_bound`]
    /// at the job's machine) computed beside the search; CCP-Relax, whose own time no longer
    /// keeps pace with the clock, is stopped `ccp_share` after `started`.
    pub fn with_lower_bound(
        mut self,
        bound: CcpLowerBound,
        started: Instant,
        ccp_share: Duration,
    ) -> Self {
        let perimeters: f64 = self
            .nest
            .contour_refs()
            .filter_map(|r| self.nest.contour(r))
            .map(|c| c.perimeter())
            .sum();
        self.bound = Some(ChainBound {
            moves: bound,
            perimeters: perimeters * 1e-3 * self.options.machine.cut_price_per_metre,
            running: true,
            offered: f64::INFINITY,
            ccp_end: started + ccp_share,
        });
        self
    }

    /// The route's part of a step: CCP-Relax, then chaining's set-up, then its groups.
    fn step_route(&mut self, budget: Duration) -> JobStatus {
        if self.chained.is_some() || self.failure.is_some() {
            return JobStatus::Done;
        }
        if !self.ccp_done {
            if self
                .bound
                .as_ref()
                .is_some_and(|b| Instant::now() >= b.ccp_end)
            {
                self.ccp.stop();
            }
            if self.ccp.step(budget) == JobStatus::Running {
                return JobStatus::Running;
            }
            self.ccp_done = true;
            return JobStatus::Running;
        }
        if self.chaining.is_none() {
            if self.deadline.is_some_and(|end| Instant::now() >= end) {
                // CCP-Relax used up the limit (a 100,000-contour nest): chaining could not
                // finish a group, and only preparing it (the route's check, the containment
                // forest, the close groups, the report) ran 1–2 s past the limit. CCP's route
                // is the answer.
                return JobStatus::Done;
            }
            let Some(route) = self.ccp.progress().solution.and_then(Solution::into_route) else {
                self.failure = Some(ChainFailure::NoCcpRoute);
                return JobStatus::Done;
            };
            match Chaining::new(&self.nest, &route, &self.options) {
                Ok(mut chaining) => {
                    if let Some(end) = self.deadline {
                        chaining.stop_at(end);
                    }
                    self.chaining = Some(chaining);
                }
                Err(e) => {
                    self.failure = Some(e.into());
                    return JobStatus::Done;
                }
            }
            return JobStatus::Running;
        }
        let chaining = self.chaining.as_mut().expect("set above");
        if chaining.step(budget).is_running() {
            return JobStatus::Running;
        }
        let chaining = self.chaining.take().expect("set above");
        self.chained = Some(chaining.finish());
        JobStatus::Done
    }

    /// The best route so far: chained, else CCP's.
    fn best_route(&self) -> Option<Route> {
        match &self.chained {
            Some(chained) => Some(chained.route.clone()),
            None => self.ccp.progress().solution.and_then(Solution::into_route),
        }
    }

    /// The bound's part of a step: `budget` at most, and within the job's limit; true while it
    /// may still improve. Once the route is done (`route_done`) the bound works on only until
    /// its first stage is done (in short pieces, so a long slice does not run it to the
    /// limit), so that it does not depend on which of the two was faster.
    fn step_bound(&mut self, budget: Duration, route_done: bool) -> bool {
        let Some(b) = self.bound.as_mut().filter(|b| b.running) else {
            return false;
        };
        match &self.chained {
            Some(chained) if chained.route.idle_length() < b.offered => {
                b.offered = chained.route.idle_length();
                b.moves.offer_route(&chained.route);
            }
            Some(_) => {}
            None => {
                let state = self.ccp.solver.progress();
                if !state.route.steps.is_empty() && state.best_idle_length < b.offered {
                    b.offered = state.best_idle_length;
                    b.moves.offer_route(&state.route);
                }
            }
        }
        let end = Instant::now() + budget;
        let end = self.deadline.map_or(end, |limit| end.min(limit));
        let piece = if route_done {
            Duration::from_millis(50)
        } else {
            budget
        };
        loop {
            let left = end.saturating_duration_since(Instant::now());
            let wanted = !route_done || b.moves.stages() == 0;
            if !wanted || left.is_zero() {
                b.running = wanted && self.deadline.is_none_or(|limit| Instant::now() < limit);
                return b.running;
            }
            if !b.moves.step(left.min(piece)) {
                b.running = false;
                return false;
            }
            if !route_done {
                return true;
            }
        }
    }
}

impl Job for ChainJob {
    fn stop(&mut self) {
        // Stopped before chaining ended, the answer is CCP's route (the group under way is
        // given up, and a later step ends the job).
        self.ccp.stop();
        self.ccp_done = true;
        self.chaining = None;
        self.deadline = Some(Instant::now());
        if let Some(b) = &mut self.bound {
            b.running = false;
        }
    }

    fn step(&mut self, budget: Duration) -> JobStatus {
        let route_done = self.chained.is_some() || self.failure.is_some();
        if route_done || self.bound.is_none() {
            if route_done && self.step_bound(budget, true) {
                return JobStatus::Running;
            }
            return self.step_route(budget);
        }
        // The route and the bound take turns within the slice, the bound as long as the
        // route's part ran (so a slice of an hour does not hand the bound the whole limit
        // while CCP-Relax ends in seconds).
        let began = Instant::now();
        let status = self.step_route(budget / 2);
        let used = began.elapsed();
        let more = self.step_bound(used.min(budget / 2), status == JobStatus::Done);
        if status == JobStatus::Done && more {
            JobStatus::Running
        } else {
            status
        }
    }

    fn progress(&self) -> Progress {
        let mut progress = self.ccp.progress();
        // The route's cost, what chaining minimises; a CCP route is a chain route too.
        let upper = self
            .best_route()
            .map(|route| route.cost(&self.nest, &self.options.machine));
        let lower = self
            .bound
            .as_ref()
            .map(|b| b.perimeters + b.moves.lower_bound());
        progress.bounds = Bounds {
            upper,
            lower,
            unit: CostUnit::Cost,
        };
        progress.proven_optimal = matches!(
            (upper, lower),
            (Some(u), Some(l)) if l >= u * (1.0 - 1e-9)
        );
        if self.bound.is_some() {
            progress.elapsed_s = self.started.elapsed().as_secs_f64();
        }
        if let Some(chained) = &self.chained {
            let r = &chained.report;
            progress.elapsed_s = self.started.elapsed().as_secs_f64();
            progress.phase = Phase::Chained {
                saved: r.pierces_before - r.pierces_after,
                pierces: r.pierces_before,
                chains: r.chains,
                cost_before: r.cost_before,
                cost_after: r.cost_after,
            };
            progress.solution = Some(Solution::Route(chained.route.clone()));
            // CCP's certificates are about its own pierce points, which chaining moved.
            progress.certified = Vec::new();
        } else if let Some(failure) = &self.failure {
            progress.phase = Phase::ChainFailed {
                error: failure.to_string(),
            };
        } else if self.chaining.is_some() {
            progress.phase = Phase::ChainJoining;
        } else if let Phase::Ccp(stage) = progress.phase {
            progress.phase = Phase::ChainCcp(stage);
        }
        progress
    }
}

/// Why a chain job ended without chaining; its words are the phase's error.
#[derive(Debug, thiserror::Error)]
enum ChainFailure {
    /// CCP-Relax ended without a route.
    #[error("CCP found no route to chain")]
    NoCcpRoute,
    /// Chain cutting refused CCP's route.
    #[error("{0}")]
    Chaining(#[from] ChainError),
}

/// CCP-Relax's step in the protocol's words.
fn ccp_stage(phase: cutroute_ccp::CcpPhase) -> CcpStage {
    use cutroute_ccp::CcpPhase;
    match phase {
        CcpPhase::Start => CcpStage::Start,
        CcpPhase::Relaxing => CcpStage::Relaxing,
        CcpPhase::LocalSearch => CcpStage::LocalSearch,
        CcpPhase::Shaking => CcpStage::Shaking,
        CcpPhase::Done => CcpStage::Done,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_ccp::{build_pcgtsp, CcpSolver, DiscretisationOptions};
    use cutroute_geometry::{generate_nest, Point};

    /// The seeding CCP-Relax's route reaches the heuristic in the step where CCP ends
    /// (`DiscreteJob::with_route_seed`): from then on the job's best tour costs at most that
    /// route's tour in its order of contours at the cheapest candidates, before the heuristic
    /// has searched beyond its first tour. The same CCP run beside the job (its VNS ends on its
    /// own here, before its limit) gives the same route. Then the job's route passes the
    /// checker.
    #[test]
    fn the_seeding_route_reaches_the_heuristic_when_ccp_ends() {
        for seed in [13u64, 16] {
            let nest = generate_nest(30, seed);
            let b = nest.bounding_box();
            let start = Point::new(b.min.x - 10.0, b.min.y - 10.0);
            let step = (b.max.x - b.min.x).max(b.max.y - b.min.y) / 60.0;
            let discrete = build_pcgtsp(
                &nest,
                &DiscretisationOptions {
                    start,
                    step,
                    ..Default::default()
                },
            )
            .unwrap();
            let options = CcpOptions {
                max_non_improving_shakes: 40,
                restarts: 0,
                ..ccp_options(
                    start,
                    None,
                    Duration::from_secs(600),
                    seed,
                    Default::default(),
                )
            };
            let mut ccp = CcpSolver::new(&nest, options.clone()).unwrap();
            while ccp.step(Duration::from_secs(60)).is_running() {}
            let (tour, seed_cost) = discrete.tour_in_order_of(&ccp.result().route).unwrap();
            let checked = cutroute_pcgtsp::check_tour(&discrete.instance, &tour).unwrap();
            assert!((checked - seed_cost).abs() <= 1e-9 * checked);
            let mut job = DiscreteJob::new(
                1,
                discrete.instance.clone(),
                Some(discrete.clone()),
                DiscreteMode::Heuristic,
                Duration::from_secs(600),
                Instant::now(),
                seed,
            )
            .unwrap()
            .with_route_seed(CcpSolver::new(&nest, options).unwrap());
            let mut before = f64::INFINITY;
            while job.route_seed.is_some() {
                before = job.best_tour().map_or(f64::INFINITY, |(_, c)| c);
                assert_eq!(job.step(Duration::from_millis(40)), JobStatus::Running);
            }
            let (best, cost) = job.best_tour().unwrap();
            assert!(
                cost <= seed_cost + 1e-9,
                "seed {seed}: {cost} > {seed_cost} (before {before})"
            );
            let route = job.route_of(&best).unwrap();
            route.validate(&nest, 1e-6).unwrap();
            assert!((route.idle_length() - cost).abs() <= 1e-6 * cost);
        }
    }
}
