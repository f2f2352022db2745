//! GSCCP: several ensembles of one nest, each solved as an SCCP, the best kept by time or cost.

use cutroute_geometry::float::Libm;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use cutroute_anytime::{AnytimeSolver, Bounds, Status};
use cutroute_ccp::{CcpOptions, CcpSolver};
use cutroute_geometry::{MachineParameters, Nest, Objective, PathRoute, PathRouteError, Route};
use web_time::Instant;

use crate::segment::{Ensemble, EnsembleKind};
use crate::solver::{SccpOptions, SccpSearch, SOLVE_SLICE};
use crate::SegmentError;

/// Settings of [`solve_gsccp`].
#[derive(Clone, Debug, PartialEq)]
pub struct GsccpOptions {
    /// Start, finish, time limit (for everything: the CCP run that seeds the orders, then the
    /// ensembles in turn, sharing what is left 1 : 3 : 2 for standard, chains and junctions)
    /// and search settings.
    pub sccp: SccpOptions,
    /// The ensembles to build and solve.
    pub kinds: Vec<EnsembleKind>,
    /// Speeds and prices of the time and cost model.
    pub machine: MachineParameters,
    /// What picks the best route.
    pub objective: Objective,
    /// Fraction of the time limit given to the CCP-Relax run whose route seeds every order.
    pub ccp_share: f64,
    /// Seed of CCP-Relax.
    pub seed: u64,
    /// Points closer than this (mm) are one vertex of the plan graph; `None`: the check
    /// tolerance (pieces the check sees on one contour must be one edge of the plan).
    pub plan_tolerance: Option<f64>,
    /// Tolerance (mm) of the independent check every route passes before it may be chosen;
    /// `None`: 10⁻⁶ of the nest's width plus height (at least 10⁻⁶ mm).
    pub check_tolerance: Option<f64>,
}

impl Default for GsccpOptions {
    fn default() -> Self {
        GsccpOptions {
            sccp: SccpOptions::default(),
            kinds: EnsembleKind::ALL.to_vec(),
            machine: MachineParameters::default(),
            objective: Objective::Time,
            ccp_share: 0.5,
            seed: 1,
            plan_tolerance: None,
            check_tolerance: None,
        }
    }
}

/// The numbers of one ensemble's route. (Not serialised: its failure is a typed error; the
/// engine's `RouteSummary` carries the numbers and the failure's words to the page.)
#[derive(Clone, Debug, PartialEq)]
pub struct EnsembleReport {
    /// Which ensemble.
    pub kind: EnsembleKind,
    /// Number of base segments (0 when the ensemble could not be built).
    pub segments: usize,
    /// Pierces of the route.
    pub pierces: usize,
    /// Idle length, mm.
    pub idle_length: f64,
    /// Cut length, mm.
    pub cut_length: f64,
    /// Machining time, s.
    pub time_s: f64,
    /// Cost.
    pub cost: f64,
    /// Length of contour cut more than once, mm: common edges that standard cutting cuts from
    /// both sides (counted in `cut_length`, time and cost alike).
    pub recut_length: f64,
    /// Why the ensemble gave no route (could not be built, or its route failed the check).
    pub failure: Option<EnsembleFailure>,
}

/// Why an ensemble gave no route.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EnsembleFailure {
    /// The ensemble or its search could not be built.
    #[error("{0}")]
    Build(#[from] SegmentError),
    /// Its route failed the independent check (other than by cutting an edge twice).
    #[error("the route fails the check: {0}")]
    FailsCheck(#[source] PathRouteError),
    /// The run was stopped before the ensemble's turn.
    #[error("not run: the run was stopped first")]
    NotRun,
}

/// The outcome of [`solve_gsccp`].
#[derive(Clone, Debug, PartialEq)]
pub struct GsccpResult {
    /// The best route by the objective; [`PathRoute::problems`] finds nothing wrong with it
    /// but pieces of contour cut twice (see [`EnsembleReport::recut_length`]).
    pub route: PathRoute,
    /// Which ensemble it came from; `None`: the CCP-Relax route itself (no ensemble did
    /// better, or the run was cancelled before any ensemble had a route).
    pub best: Option<EnsembleKind>,
    /// Every ensemble's numbers, in the order of the options' kinds.
    pub reports: Vec<EnsembleReport>,
    /// The CCP-Relax route that seeded the orders, as a path route.
    pub ccp_route: PathRoute,
}

/// The contract of every solver: the best checked path route so far and its value (time or
/// cost by the options' objective); no lower bound.
impl AnytimeSolver for GsccpSearch {
    type Solution = PathRoute;

    fn step(&mut self, budget: Duration) -> Status {
        GsccpSearch::step(self, budget)
    }

    fn best(&self) -> Option<PathRoute> {
        GsccpSearch::best(self).map(|c| c.route.clone())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            upper: GsccpSearch::best(self).map(|c| c.value),
            lower: None,
            unit: self.options.objective.unit(),
        }
    }
}

/// Runs [`GsccpSearch`] to its end (the cancel flag is read between slices): CCP-Relax for its
/// share of the time, then every ensemble of `options.kinds` seeded by its route, each route
/// checked independently; returns the best by the objective with every ensemble's numbers. A
/// route may compete if the check finds nothing but contour cut twice (standard cutting of
/// parts with common edges); gaps, cuts through material and precedence violations
/// disqualify it. After a cancel, the ensembles not yet started are reported as not run.
pub fn solve_gsccp(
    nest: &Nest,
    options: &GsccpOptions,
    cancel: &AtomicBool,
) -> Result<GsccpResult, SegmentError> {
    let mut search = GsccpSearch::new(nest, options)?;
    while search.step(SOLVE_SLICE).is_running() {
        if cancel.load(Ordering::Relaxed) {
            search.stop();
        }
    }
    search.result()
}

/// A route GSCCP may return, checked: where it came from and its objective value.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// The ensemble it solves; `None`: the CCP-Relax route that seeds the orders.
    pub source: Option<EnsembleKind>,
    /// The route (passed [`PathRoute::problems`] but for contour cut twice).
    pub route: PathRoute,
    /// Its time (s) or cost under the options' machine, by the options' objective.
    pub value: f64,
}

impl Candidate {
    /// Whether `self` should replace `other` as the best: a lower value, or an equal one from
    /// an ensemble against the CCP route (the ensembles exist to improve on it).
    fn beats(&self, other: &Candidate) -> bool {
        self.value < other.value
            || (other.source.is_none() && self.source.is_some() && self.value <= other.value)
    }
}

/// How long a running ensemble's improving route waits at least between two checks (a check
/// is a pass over the whole nest; see [`GsccpSearch::step`]).
const SNAPSHOT_INTERVAL: Duration = Duration::from_millis(300);

enum Stage {
    Ccp(Box<CcpSolver>),
    /// The ensemble at this index of the kinds is to be built next.
    Build(usize),
    /// The ensemble at this index is being searched.
    Search(usize, Box<SccpSearch>, EnsembleReport),
    Finished,
}

/// What a [`GsccpSearch`] is doing ([`GsccpSearch::stage`]).
#[derive(Clone, Debug, PartialEq)]
pub enum GsccpStage<'a> {
    /// CCP-Relax seeds the orders.
    Ccp,
    /// An ensemble of this kind is built next.
    Building(Option<EnsembleKind>),
    /// An ensemble is searched.
    Searching {
        /// Which.
        kind: EnsembleKind,
        /// Its base segments.
        segments: usize,
        /// Shakes so far.
        shakes: usize,
    },
    /// The run failed.
    Failed(&'a SegmentError),
    /// The run ended; the best route comes from this ensemble (`None`: CCP-Relax).
    Done(Option<EnsembleKind>),
    /// The run ended with no ensemble giving a valid route.
    NoValidRoute,
}

/// GSCCP as a resumable state machine: CCP-Relax (stepped as [`CcpSolver`] steps), then per
/// ensemble one step that builds it and steps of its [`SccpSearch`]. Each [`step`](Self::step)
/// returns after about its budget, but for building an ensemble (one plan-graph construction,
/// which cannot be cut) and the check of each finished route. [`solve_gsccp`] is a loop over
/// it; the job engine steps it between the browser worker's messages.
pub struct GsccpSearch {
    nest: Nest,
    options: GsccpOptions,
    tolerance: f64,
    started: Instant,
    stage: Stage,
    ccp_route: Option<Route>,
    /// CCP-Relax's best route so far (its snapshots while it runs, then its end route) and
    /// its idle length.
    ccp_best: Option<(Route, f64)>,
    ccp_path: Option<PathRoute>,
    reports: Vec<EnsembleReport>,
    best: Option<Candidate>,
    /// A checked snapshot of the running ensemble's best route so far.
    provisional: Option<Candidate>,
    next_snapshot: Instant,
    snapshot_idle: f64,
    failure: Option<SegmentError>,
    /// [`GsccpSearch::stop`] ended the run before its end.
    stopped: bool,
    /// How long checking CCP-Relax's route took: an ensemble's search leaves that much of its
    /// share for the check of its own route, which follows it.
    route_check: Duration,
}

impl GsccpSearch {
    /// Checks the options and prepares CCP-Relax (no search yet).
    pub fn new(nest: &Nest, options: &GsccpOptions) -> Result<Self, SegmentError> {
        if !(options.ccp_share > 0.0 && options.ccp_share < 1.0) {
            return Err(SegmentError::InvalidOption(format!(
                "ccp_share {} must lie strictly between 0 and 1",
                options.ccp_share
            )));
        }
        let started = Instant::now();
        let ccp = CcpSolver::new(
            nest,
            CcpOptions {
                start: options.sccp.start,
                finish: options.sccp.finish,
                time_limit: options.sccp.time_limit.mul_f64(options.ccp_share),
                seed: options.seed,
                machine: options.machine,
                heat: options.sccp.heat.map(|h| h.penalty),
                ..CcpOptions::default()
            },
        )?;
        Ok(GsccpSearch {
            nest: nest.clone(),
            options: options.clone(),
            tolerance: options
                .check_tolerance
                .unwrap_or_else(|| nest.check_tolerance()),
            started,
            stage: Stage::Ccp(Box::new(ccp)),
            ccp_route: None,
            ccp_best: None,
            ccp_path: None,
            reports: Vec::new(),
            best: None,
            provisional: None,
            next_snapshot: started,
            snapshot_idle: f64::INFINITY,
            failure: None,
            stopped: false,
            route_check: Duration::ZERO,
        })
    }

    /// Works for about `budget`, then returns. Building an ensemble and checking a finished
    /// route are single pieces of work that may overrun the budget (measured on the real nests
    /// in `BENCHMARKS.md`); a step that does one returns right after it. While an ensemble's search improves, its best route is checked at
    /// most every 300 ms (and at most a tenth of the time) so [`GsccpSearch::best`] follows it.
    pub fn step(&mut self, budget: Duration) -> Status {
        let slice_end = Instant::now() + budget;
        loop {
            let now = Instant::now();
            if matches!(self.stage, Stage::Finished) {
                return self.status();
            }
            if now >= slice_end {
                return Status::Running;
            }
            let left = slice_end - now;
            match std::mem::replace(&mut self.stage, Stage::Finished) {
                Stage::Finished => {}
                // Ending a phase (a check over the whole nest) and building an ensemble (a
                // plan graph) cannot be cut: each ends the step, so a step holds at most one.
                Stage::Ccp(mut solver) => {
                    // CCP-Relax counts its own time; its share of the limit is wall time here,
                    // as the ensembles' shares are, so a caller that steps the search in part
                    // of each slice (the segment job with its bound) still ends on time.
                    let ccp_limit = self.options.sccp.time_limit.mul_f64(self.options.ccp_share);
                    if now >= self.started + ccp_limit {
                        solver.cancel();
                    }
                    if solver.step(left).is_done() {
                        self.ccp_done(&solver);
                        return self.status();
                    }
                    self.ccp_snapshot(&solver);
                    self.stage = Stage::Ccp(solver);
                }
                Stage::Build(k) => {
                    self.build(k);
                    return self.status();
                }
                Stage::Search(k, mut search, report) => {
                    if search.step(left).is_done() {
                        self.ensemble_done(k, &search, report);
                        return self.status();
                    }
                    self.snapshot(&search, report.kind);
                    self.stage = Stage::Search(k, search, report);
                }
            }
        }
    }

    /// Ends the run now with the best so far: CCP-Relax is cancelled (its route kept), a
    /// running ensemble keeps its best route (checked), the ensembles not started are reported
    /// as not run.
    pub fn stop(&mut self) {
        if !self.is_finished() {
            self.stopped = true;
        }
        match std::mem::replace(&mut self.stage, Stage::Finished) {
            Stage::Finished => {}
            Stage::Ccp(mut solver) => {
                solver.cancel();
                while solver.step(Duration::from_millis(10)).is_running() {}
                self.ccp_done(&solver);
                self.stage = Stage::Finished;
                if self.failure.is_none() {
                    self.not_run(0);
                }
            }
            Stage::Build(k) => self.not_run(k),
            Stage::Search(k, mut search, report) => {
                search.stop();
                self.ensemble_done(k, &search, report);
                self.stage = Stage::Finished;
                self.not_run(k + 1);
            }
        }
    }

    fn status(&self) -> Status {
        if !self.is_finished() {
            Status::Running
        } else if self.stopped {
            Status::Stopped
        } else {
            Status::Finished {
                proven_optimal: false,
            }
        }
    }

    /// Whether the run has ended.
    pub fn is_finished(&self) -> bool {
        matches!(self.stage, Stage::Finished)
    }

    /// The best checked route so far (CCP-Relax's until an ensemble beats it, a running
    /// ensemble's latest checked snapshot included); `None` before CCP-Relax has a route.
    pub fn best(&self) -> Option<&Candidate> {
        match (&self.best, &self.provisional) {
            (Some(best), Some(p)) => Some(if p.beats(best) { p } else { best }),
            (best, p) => best.as_ref().or(p.as_ref()),
        }
    }

    /// The numbers of every finished ensemble, in the order of the options' kinds.
    pub fn reports(&self) -> &[EnsembleReport] {
        &self.reports
    }

    /// The ensemble being built or searched, if any.
    pub fn running(&self) -> Option<EnsembleKind> {
        match &self.stage {
            Stage::Build(k) => self.options.kinds.get(*k).copied(),
            Stage::Search(_, _, report) => Some(report.kind),
            _ => None,
        }
    }

    /// The checked snapshot of the running ensemble's best route, or during CCP-Relax of its
    /// route so far (see [`GsccpSearch::step`]), if any.
    pub fn provisional(&self) -> Option<&Candidate> {
        self.provisional.as_ref()
    }

    /// The CCP-Relax route that seeds the orders, once CCP-Relax has ended.
    pub fn ccp_route(&self) -> Option<&PathRoute> {
        self.ccp_path.as_ref()
    }

    /// CCP-Relax's best route so far as pierce points per contour (a CCP [`Route`]), with its
    /// idle length: taken at the snapshots while it runs (see [`GsccpSearch::step`]), then its
    /// route.
    pub fn ccp_cutting_route(&self) -> Option<(&Route, f64)> {
        self.ccp_best.as_ref().map(|(route, idle)| (route, *idle))
    }

    /// Why the run failed, if it did (CCP-Relax gave no usable route).
    pub fn failure(&self) -> Option<&SegmentError> {
        self.failure.as_ref()
    }

    /// What the run is doing, typed, for callers that word it in their own language.
    pub fn stage(&self) -> GsccpStage<'_> {
        match &self.stage {
            Stage::Ccp(_) => GsccpStage::Ccp,
            Stage::Build(k) => GsccpStage::Building(self.options.kinds.get(*k).copied()),
            Stage::Search(_, search, report) => GsccpStage::Searching {
                kind: report.kind,
                segments: report.segments,
                shakes: search.shakes(),
            },
            Stage::Finished => match (&self.failure, self.best()) {
                (Some(e), _) => GsccpStage::Failed(e),
                (None, Some(best)) => GsccpStage::Done(best.source),
                (None, None) => GsccpStage::NoValidRoute,
            },
        }
    }

    /// The outcome (after the end; before it, what there is so far).
    pub fn result(&self) -> Result<GsccpResult, SegmentError> {
        if let Some(e) = &self.failure {
            return Err(e.clone());
        }
        let (Some(best), Some(ccp_route)) = (self.best(), &self.ccp_path) else {
            let reasons: Vec<String> = self
                .reports
                .iter()
                .map(|r| {
                    format!(
                        "{}: {}",
                        r.kind.name(),
                        r.failure
                            .as_ref()
                            .map(ToString::to_string)
                            .unwrap_or_default()
                    )
                })
                .collect();
            return Err(SegmentError::NoRoute(reasons.join("; ")));
        };
        Ok(GsccpResult {
            route: best.route.clone(),
            best: best.source,
            reports: self.reports.clone(),
            ccp_route: ccp_route.clone(),
        })
    }

    /// The objective's value of a route (+ W·H with a heat penalty), if it passes the check
    /// (contour cut twice allowed), with the length cut twice; else the first problem.
    fn checked(&self, route: &PathRoute) -> Result<(f64, f64), PathRouteError> {
        let mut problems = route.problems(&self.nest, self.tolerance);
        let recut = recut_length(&problems, self.tolerance);
        problems.retain(|p| !matches!(p, PathRouteError::Overlap { .. }));
        match problems.into_iter().next() {
            Some(problem) => Err(problem),
            None => Ok((
                self.options.objective.value(
                    &self.options.machine,
                    route.cut_length(),
                    route.idle_length(),
                    route.pierce_count(),
                ) + self
                    .options
                    .sccp
                    .heat
                    .map_or(0.0, |heat| heat.objective_penalty(route)),
                recut,
            )),
        }
    }

    fn offer(&mut self, candidate: Candidate) {
        if self.best.as_ref().is_none_or(|b| candidate.beats(b)) {
            self.best = Some(candidate);
        }
    }

    fn ccp_done(&mut self, solver: &CcpSolver) {
        self.provisional = None;
        let route = solver.result().route;
        match PathRoute::from_route(&route, &self.nest) {
            Err(e) => {
                self.failure = Some(SegmentError::CcpRoute(Box::new(e)));
                self.stage = Stage::Finished;
            }
            Ok(path) => {
                let began = Instant::now();
                let checked = self.checked(&path);
                self.route_check = began.elapsed();
                if let Ok((value, _)) = checked {
                    self.offer(Candidate {
                        source: None,
                        route: path.clone(),
                        value,
                    });
                }
                self.ccp_best = Some((route.clone(), route.idle_length()));
                self.ccp_route = Some(route);
                self.ccp_path = Some(path);
                self.stage = Stage::Build(0);
            }
        }
    }

    /// Builds the ensemble at `k` and prepares its search with its share of the time left.
    fn build(&mut self, k: usize) {
        let Some(&kind) = self.options.kinds.get(k) else {
            self.stage = Stage::Finished;
            return;
        };
        // Standard cutting starts from CCP-Relax's own local optimum: it needs the least time.
        let weight = |kind: EnsembleKind| match kind {
            EnsembleKind::Standard => 1.0,
            EnsembleKind::Chains => 3.0,
            EnsembleKind::Junctions => 2.0,
        };
        let left = self
            .options
            .sccp
            .time_limit
            .saturating_sub(self.started.elapsed());
        if left.is_zero() {
            // The limit has passed: building the ensemble (a plan graph of the whole nest,
            // seconds on 10,000 contours) would only run past it.
            self.not_run(k);
            self.stage = Stage::Finished;
            return;
        }
        let remaining: f64 = self.options.kinds[k..].iter().map(|&x| weight(x)).sum();
        let mut report = EnsembleReport {
            kind,
            segments: 0,
            pierces: 0,
            idle_length: f64::NAN,
            cut_length: f64::NAN,
            time_s: f64::NAN,
            cost: f64::NAN,
            recut_length: 0.0,
            failure: None,
        };
        let plan_tolerance = self.options.plan_tolerance.unwrap_or(self.tolerance);
        let ensemble = match Ensemble::build(&self.nest, kind, plan_tolerance) {
            Ok(ensemble) => ensemble,
            Err(e) => {
                report.failure = Some(e.into());
                self.reports.push(report);
                self.stage = Stage::Build(k + 1);
                return;
            }
        };
        report.segments = ensemble.segments.len();
        // A share of what the build left (it took 0.36 s of a 1 s limit on 10,000 contours,
        // and the search then ran its whole share past the limit), less the check of the
        // search's route after it (0.19 s there). Nothing left: the search and its check
        // would only run past the limit.
        let left = self
            .options
            .sccp
            .time_limit
            .saturating_sub(self.started.elapsed() + self.route_check);
        if left.is_zero() {
            self.not_run(k);
            self.stage = Stage::Finished;
            return;
        }
        let sccp = SccpOptions {
            time_limit: left
                .mul_f64(weight(kind) / remaining)
                .max(Duration::from_millis(1)),
            ..self.options.sccp.clone()
        };
        let search = SccpSearch::new(&ensemble, self.ccp_route.as_ref(), &sccp);
        match search {
            Err(e) => {
                report.failure = Some(e.into());
                self.reports.push(report);
                self.stage = Stage::Build(k + 1);
            }
            Ok(search) => {
                self.provisional = None;
                self.snapshot_idle = f64::INFINITY;
                self.next_snapshot = Instant::now() + SNAPSHOT_INTERVAL;
                self.stage = Stage::Search(k, Box::new(search), report);
            }
        }
    }

    /// Checks the running search's best route if it improved and the time has come.
    fn snapshot(&mut self, search: &SccpSearch, kind: EnsembleKind) {
        let now = Instant::now();
        let idle = search.best_idle_length();
        if now < self.next_snapshot || idle >= self.snapshot_idle - self.options.sccp.delta {
            return;
        }
        let route = search.best_route();
        let checked = self.checked(&route);
        let took = now.elapsed();
        self.next_snapshot = Instant::now() + SNAPSHOT_INTERVAL.max(took * 10);
        self.snapshot_idle = idle;
        if let Ok((value, _)) = checked {
            self.provisional = Some(Candidate {
                source: Some(kind),
                route,
                value,
            });
        }
    }

    /// Checks CCP-Relax's route so far if it improved and the time has come.
    fn ccp_snapshot(&mut self, solver: &CcpSolver) {
        let now = Instant::now();
        if now < self.next_snapshot {
            return;
        }
        let progress = solver.progress();
        if progress.route.steps.is_empty()
            || progress.best_idle_length >= self.snapshot_idle - self.options.sccp.delta
        {
            return;
        }
        let checked = PathRoute::from_route(&progress.route, &self.nest)
            .ok()
            .and_then(|route| Some((self.checked(&route).ok()?.0, route)));
        self.next_snapshot = Instant::now() + SNAPSHOT_INTERVAL.max(now.elapsed() * 10);
        self.snapshot_idle = progress.best_idle_length;
        self.ccp_best = Some((progress.route.clone(), progress.best_idle_length));
        if let Some((value, route)) = checked {
            self.provisional = Some(Candidate {
                source: None,
                route,
                value,
            });
        }
    }

    fn ensemble_done(&mut self, k: usize, search: &SccpSearch, mut report: EnsembleReport) {
        self.provisional = None;
        let route = search.solution().route;
        let machine = &self.options.machine;
        report.pierces = route.pierce_count();
        report.idle_length = route.idle_length();
        report.cut_length = route.cut_length();
        report.time_s = route.time(machine);
        report.cost = route.cost(machine);
        // Cutting a piece of contour twice wastes time but harms nothing: such routes compete
        // with their true cost. Anything else disqualifies.
        match self.checked(&route) {
            Err(problem) => report.failure = Some(EnsembleFailure::FailsCheck(problem)),
            Ok((value, recut)) => {
                report.recut_length = recut;
                self.offer(Candidate {
                    source: Some(report.kind),
                    route,
                    value,
                });
            }
        }
        self.reports.push(report);
        self.stage = Stage::Build(k + 1);
    }

    /// Reports the ensembles from index `k` on as not run.
    fn not_run(&mut self, k: usize) {
        for &kind in self.options.kinds.iter().skip(k) {
            self.reports.push(EnsembleReport {
                kind,
                segments: 0,
                pierces: 0,
                idle_length: f64::NAN,
                cut_length: f64::NAN,
                time_s: f64::NAN,
                cost: f64::NAN,
                recut_length: 0.0,
                failure: Some(EnsembleFailure::NotRun),
            });
        }
    }
}

/// Length cut more than once among `problems` (their [`PathRouteError::Overlap`]s), each
/// piece once: a common edge cut twice is reported on both its contours (same ends, perhaps
/// swapped, within `tolerance`) and counted once.
pub fn recut_length(problems: &[PathRouteError], tolerance: f64) -> f64 {
    let mut seen: Vec<(f64, f64, f64, f64)> = Vec::new();
    let mut total = 0.0;
    for p in problems {
        let PathRouteError::Overlap {
            x,
            y,
            to_x,
            to_y,
            length,
            ..
        } = *p
        else {
            continue;
        };
        let near = |a: f64, b: f64, c: f64, d: f64| (a - c).hypot_libm(b - d) <= tolerance;
        let repeated = seen.iter().any(|&(sx, sy, tx, ty)| {
            (near(x, y, sx, sy) && near(to_x, to_y, tx, ty))
                || (near(x, y, tx, ty) && near(to_x, to_y, sx, sy))
        });
        if !repeated {
            seen.push((x, y, to_x, to_y));
            total += length;
        }
    }
    total
}
