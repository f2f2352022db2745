//! The full cutting route in every contour job (issue #17): kerf, the pierce and switch-off
//! clearances d₁ and d₂, lead-ins, lead-outs, overcut and tabs ([`KerfSettings`]). The one
//! place where a solver's idealised route becomes a route with leads; the CLI and the page
//! both get their full routes from [`KerfJob`].
//!
//! Optimising with leads: the solver runs over the nest of *pierce curves*
//! ([`LeadFitter::pierce_curve_nest`]), so the idle legs it prices run between pierce points
//! off the contours; its route is projected back onto the nest, leads are fitted to every step
//! and moved along the equidistants where that shortens the M* → next M legs
//! ([`LeadFitter::relax`]). The curve model prices M = M*, which the real leads break (the
//! lead-out ends elsewhere than the lead-in starts), so on some nests the idealised order with
//! leads attached and relaxed is shorter. The job therefore also runs the solver on the nest
//! itself, within the same time limit (the two share every slice), and keeps the shorter of the
//! two full routes: its route is never longer than the idealised order with leads attached and
//! relaxed, and so never longer than that order with leads attached.
//!
//! The exact solver is the exception: it searches the discretised full-route model itself
//! ([`crate::FullRouteModel`]: candidate entries with their leads fitted, idle legs from M* to
//! the next M), and the job keeps its route as found, with its lower bound and optimality
//! proof, which are about that model (see the module `full_route`). Neither the idealised run
//! nor the relaxation is added: either could give a route off the candidates, below the
//! discretised optimum, and the bound would then no longer be below the route reported.
//!
//! With `leads_after` the job runs the solver on the nest only and attaches leads (no
//! relaxation): the "solve, then attach leads" route of the benchmark.
//!
//! The path solvers (sccp, gsccp, aoe) run on the nest of equidistants instead, with leads at
//! their paths' ends (module `kerf_paths`).

use cutroute_geometry::{
    ChainedAttach, ContainmentForest, CutStep, KerfSettings, LeadError, LeadFitter,
    MachineParameters, Nest, PartsTooClose, Route,
};
use cutroute_protocol::{
    Bounds, JobRequest, KerfNote, KerfSource, Phase, Problem, Progress, Solution, SolverKind,
};
use web_time::{Duration, Instant};

use crate::full_route::{FullRouteBuilder, FullRouteJob, Modelling};
use crate::kerf_paths::PathLeadsRun;
use crate::thermal::ThermalJob;
use crate::{EngineError, Job, JobStatus, Refusal};

/// Sweeps of [`LeadFitter::relax`] over a finished route, and the entries it tries round each
/// equidistant (as the CLI always did).
const RELAX_PASSES: usize = 2;
const RELAX_POSITIONS: usize = 24;

/// The share of the request's time limit kept for fitting and relaxing the leads of the
/// finished routes (at most [`FIT_RESERVE_MAX_S`]): the inner solvers end that much earlier,
/// so the final full route is there by the limit (the CLI stops a job at it).
const FIT_RESERVE_SHARE: f64 = 0.25;
const FIT_RESERVE_MAX_S: f64 = 2.0;

/// How long past the request's limit the job may run to give its solvers' last routes their
/// leads (the CLI's promise is the limit + 1 s, its report included): then it ends with what
/// it has.
pub const OVERRUN_LIMIT: Duration = Duration::from_millis(700);

/// A solver is stopped this much earlier than the time its final route's leads are expected
/// to take (from the leads attached so far) would allow, for the estimate's noise.
const ATTACH_MARGIN: f64 = 1.5;

/// Whether the kerf job can wrap `solver`'s job ([`SolverKind::cuts_with_kerf`], which the page
/// asks before it sends a job).
pub fn supports_kerf(solver: SolverKind) -> bool {
    solver.cuts_with_kerf()
}

/// A kerf setting [`validate_kerf`] refuses.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KerfSettingsError {
    /// A length is negative, infinite or NaN.
    #[error("{name} {value}: must be finite and non-negative")]
    BadLength {
        /// The setting, in words.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// Tabs are asked for with no width.
    #[error("tabs need a positive width")]
    TabWidth,
    /// A setting outside its range ([`KerfSettings::check`], the table the CLI's flags and
    /// profiles share).
    #[error("{0}")]
    OutOfRange(#[from] cutroute_geometry::KerfRangeError),
}

/// Checks the settings a request carries: every length finite and non-negative, tabs with a
/// width, then every setting in its range ([`KerfSettings::check`]).
pub fn validate_kerf(settings: &KerfSettings) -> Result<(), KerfSettingsError> {
    let lengths = [
        ("kerf", settings.kerf),
        ("pierce clearance", settings.pierce_clearance),
        ("switch-off clearance", settings.switch_off_clearance),
        ("lead-in length", settings.lead_in.length),
        ("lead-out length", settings.lead_out.length),
        ("overcut", settings.overcut),
        ("tab width", settings.tabs.width),
    ];
    for (name, value) in lengths {
        if !(value.is_finite() && value >= 0.0) {
            return Err(KerfSettingsError::BadLength { name, value });
        }
    }
    if settings.tabs.count > 0 && settings.tabs.width <= 0.0 {
        return Err(KerfSettingsError::TabWidth);
    }
    settings.check()?;
    Ok(())
}

/// `route` with leads fitted to every pierced step under `settings` on `nest` (every contour
/// without room named), then, with `relax`, moved along the equidistants to shorten the idle
/// legs (the order kept). Used by [`KerfJob`] and for routes a file already holds.
pub fn fit_leads(
    nest: &Nest,
    forest: &ContainmentForest,
    settings: KerfSettings,
    route: &Route,
    relax: bool,
) -> Result<Route, Vec<LeadError>> {
    let fitter = LeadFitter::with_forest(nest, forest, settings);
    // A chained route keeps its links (refitted where they changed, as after a rule repair);
    // no relaxation, so pierce points a repair placed stay.
    if route.steps.iter().any(|s| !s.is_pierced()) {
        return fitter
            .attach_chained(route, 0, 0)
            .map(|chained| chained.route);
    }
    // A route that is not over this nest's contours (the curve nest's) is brought back first.
    let attached = fitter.attach(&fitter.project(route))?;
    Ok(if relax {
        fitter.relax(&attached, RELAX_PASSES, RELAX_POSITIONS)
    } else {
        attached
    })
}

/// One solver run whose routes the kerf job fits with leads.
struct Candidate {
    source: KerfSource,
    job: Box<dyn Job>,
    stage: Stage,
    /// The last route of the running solver whose leads are fitted, and what the fit gave.
    fitted: Option<(Route, Result<Route, Vec<LeadError>>)>,
    /// A newer route of the running solver whose leads are being fitted step by step.
    pending: Option<Attach>,
    /// Whether its finished route has had its kerf pierces placed (once).
    kerf_pierced: bool,
}

/// Where a candidate is: its solver runs, then its final route gets leads step by step, then
/// they are relaxed step by step (every stage in slices, so a cancel is seen and no step runs
/// long).
enum Stage {
    /// The exact solver's full-route model is built (its candidates' leads fitted).
    Modelling(Box<ExactModelling>),
    Solving,
    Attaching(Attach),
    Relaxing {
        route: Route,
        pass: usize,
        next: usize,
        /// Steps whose neighbours moved since they were last relaxed: a step whose idle legs
        /// are unchanged would not move again (it holds the best of its positions), so only
        /// these are tried (the same route as `LeadFitter::relax`, fewer fits).
        dirty: Vec<bool>,
    },
    Finished(Option<Result<Route, Vec<LeadError>>>),
}

/// The full-route model under construction and the request its exact job will run.
struct ExactModelling {
    builder: FullRouteBuilder,
    /// The idealised request (its time limit shortened like every inner job's).
    request: JobRequest,
    /// When the request arrived: the build counts against the limit.
    started: Instant,
}

/// Leads attached to a solver's route, one step at a time (a chained route all at once: its
/// links tie neighbouring steps' leads together).
struct Attach {
    /// The solver's route.
    from: Route,
    /// Whether `from` is a chain solver's route over the equidistants.
    chained: bool,
    /// It projected onto the nest.
    route: Route,
    steps: Vec<CutStep>,
    errors: Vec<LeadError>,
    /// Time spent attaching so far.
    spent: Duration,
    /// Steps of a chained route once its leads are attached.
    chained_done: usize,
    /// A chained route's leads being attached, a step at a time (on seven.dbs one
    /// `attach_chained` call was a step of 0.35–0.5 s).
    chained_work: Option<Box<ChainedAttach>>,
}

impl Attach {
    fn new(fitter: &LeadFitter<'_>, from: Route, chained: bool) -> Attach {
        Attach {
            chained,
            // A chained route stays over the equidistants until `attach_chained`.
            route: if chained {
                from.clone()
            } else {
                fitter.project(&from)
            },
            steps: Vec::with_capacity(from.steps.len()),
            errors: Vec::new(),
            spent: Duration::ZERO,
            chained_done: 0,
            chained_work: None,
            from,
        }
    }

    /// Attaches steps until `until`; the route with leads (or every contour without room)
    /// once every step is done.
    fn advance(
        &mut self,
        fitter: &LeadFitter<'_>,
        until: Instant,
    ) -> Option<Result<Route, Vec<LeadError>>> {
        let began = Instant::now();
        let result = self.advance_until(fitter, until);
        self.spent += began.elapsed();
        if self.chained && result.is_some() {
            self.chained_done = self.from.steps.len();
        }
        result
    }

    /// The time per step attached so far (`None` before a few steps are done).
    fn step_cost(&self) -> Option<Duration> {
        let done = (self.steps.len() + self.errors.len()).max(self.chained_done) as u32;
        (done >= 8).then(|| self.spent / done)
    }

    fn advance_until(
        &mut self,
        fitter: &LeadFitter<'_>,
        until: Instant,
    ) -> Option<Result<Route, Vec<LeadError>>> {
        if self.chained {
            let work = self
                .chained_work
                .get_or_insert_with(|| Box::new(ChainedAttach::new(&self.from, 0, 0)));
            let result = work.advance(fitter, &self.from, &|| Instant::now() >= until)?;
            self.chained_work = None;
            return Some(result.map(|chained| chained.route));
        }
        loop {
            let done = self.steps.len() + self.errors.len();
            let Some(step) = self.route.steps.get(done) else {
                let steps = std::mem::take(&mut self.steps);
                return Some(if self.errors.is_empty() {
                    Ok(Route {
                        steps,
                        ..self.route.clone()
                    })
                } else {
                    Err(std::mem::take(&mut self.errors))
                });
            };
            if !step.is_pierced() {
                self.steps.push(step.clone());
            } else {
                match fitter.attach_to_step(step) {
                    Ok(step) => self.steps.push(step),
                    Err(e) => self.errors.push(e),
                }
            }
            if Instant::now() >= until {
                return None;
            }
        }
    }
}

/// A contour job (nearest, ccp, heuristic) under [`KerfSettings`]: every [`Progress`] carries
/// the best route found with its leads (pierce M, lead-in, entry on the equidistant, lead-out,
/// switch-off M*, tabs), its idle length as the upper bound, and a [`Phase::Kerf`] note. When a
/// contour has no room for its leads the progress carries no route and the note lists the
/// contours ([`KerfNote::NoRoom`]).
pub struct KerfJob {
    nest: Nest,
    forest: ContainmentForest,
    settings: KerfSettings,
    /// Whether finished routes are relaxed (not in the "attach after" mode).
    relax: bool,
    /// Whether the solver is chain cutting (its routes are over the equidistants).
    chained: bool,
    candidates: Vec<Candidate>,
    /// Which candidate the next slice starts with (they take turns).
    turn: usize,
    /// The request's time limit from the job's start: relaxing stops there (every relaxed
    /// route is valid; attaching, which validity needs, goes on until a route has its leads,
    /// for at most [`OVERRUN_LIMIT`] more).
    deadline: Option<Instant>,
    /// The time one step's leads took to attach, as measured on the routes attached so far: a
    /// solver is stopped when its final route's leads would not be ready by the deadline.
    step_cost: Option<Duration>,
    /// A path solver's run over the equidistants (sccp, gsccp, aoe): the job is that run.
    paths: Option<PathLeadsRun>,
    /// The machine: whether a kerf pierce pays off is a matter of its pierce times.
    machine: MachineParameters,
}

impl KerfJob {
    /// The kerf job of `request` (a nest, settings not idealised, a solver that
    /// [`supports_kerf`]); its inner jobs are built by `start` (the engine's `start_job`, so
    /// each runs inside its thermal job).
    pub fn from_request(
        request: &JobRequest,
        start: impl Fn(&JobRequest) -> Result<Box<dyn Job>, EngineError>,
    ) -> Result<KerfJob, EngineError> {
        let started = Instant::now();
        let solver = request.solver;
        let refused = |reason: Refusal| EngineError::SolverRefused {
            solver: solver.name(),
            reason,
        };
        let Problem::Nest {
            nest,
            start: route_start,
            finish: route_finish,
        } = &request.problem
        else {
            return Err(EngineError::UnsupportedProblem {
                solver: solver.name(),
                problem: "a PCGTSP instance with kerf and leads",
            });
        };
        if !supports_kerf(solver) {
            return Err(refused(Refusal::NoFullRouteModel));
        }
        let settings = request.params.kerf;
        validate_kerf(&settings).map_err(|e| refused(e.into()))?;
        // Parts closer than the kerf: every solver's cut there would eat into a neighbour, and
        // the route checkers reject it; say so now, with the pairs, rather than after a search.
        // So are contours lying on one another (a part in a hole of its own shape, stacked
        // parts), where the cuts keep kerf/2 off each other yet one part comes out a kerf off.
        if let Some(too_close) = PartsTooClose::of(nest, settings.kerf, nest.check_tolerance()) {
            return Err(refused(too_close.into()));
        }
        let forest = nest.containment_forest();
        // The inner requests are idealised: the kerf is this job's.
        let mut idealised = request.clone();
        idealised.params.kerf = KerfSettings::default();
        idealised.params.leads_after = false;
        let limit = request.params.time_limit_s;
        if limit.is_finite() && limit > 0.0 {
            idealised.params.time_limit_s =
                limit - (limit * FIT_RESERVE_SHARE).min(FIT_RESERVE_MAX_S);
        }
        if solver.gives_path_route() {
            // Cut on the equidistants: the solver's paths are the tool centre's; leads at
            // their ends (`leads_after` changes nothing: nothing is relaxed).
            let equidistants = LeadFitter::with_forest(nest, &forest, settings).kerf_nest();
            let mut over_equidistants = idealised.clone();
            if let Problem::Nest { nest, .. } = &mut over_equidistants.problem {
                *nest = equidistants;
            }
            let run = PathLeadsRun::new(
                nest.clone(),
                forest.clone(),
                settings,
                request.params.machine,
                request.params.objective,
                (*route_start, *route_finish),
                start(&over_equidistants)?,
            );
            return Ok(KerfJob {
                nest: nest.clone(),
                forest,
                settings,
                relax: false,
                chained: false,
                candidates: Vec::new(),
                turn: 0,
                deadline: None,
                step_cost: None,
                paths: Some(run),
                machine: request.params.machine,
            });
        }
        let mut candidates = Vec::new();
        let after = request.params.leads_after;
        let chained = solver == SolverKind::Chain;
        let exact = solver == SolverKind::Exact && !after;
        if exact {
            // A heat penalty or a rule repair changes the route after the search: the bound
            // would no longer be about it.
            if request.params.thermal.penalised() || request.params.thermal.hard {
                return Err(refused(Refusal::ExactWithHeat));
            }
            let builder = FullRouteBuilder::new(
                nest,
                settings,
                request.params.discretisation_step_mm,
                *route_start,
                *route_finish,
            )
            .map_err(refused)?;
            candidates.push(Candidate::new(
                KerfSource::FullRoute,
                Box::new(Modelling {
                    job_id: request.job_id,
                }),
            ));
            candidates[0].stage = Stage::Modelling(Box::new(ExactModelling {
                builder,
                request: idealised.clone(),
                started,
            }));
        } else if chained {
            // Links routed round the equidistants keep kerf/2 from every contour.
            let equidistants = LeadFitter::with_forest(nest, &forest, settings).kerf_nest();
            let mut over_equidistants = idealised.clone();
            if let Problem::Nest { nest, .. } = &mut over_equidistants.problem {
                *nest = equidistants;
            }
            candidates.push(Candidate::new(
                KerfSource::Chains { links_broken: 0 },
                start(&over_equidistants)?,
            ));
        } else if !after {
            let curves = LeadFitter::with_forest(nest, &forest, settings).pierce_curve_nest();
            let mut over_curves = idealised.clone();
            if let Problem::Nest { nest, .. } = &mut over_curves.problem {
                *nest = curves;
            }
            candidates.push(Candidate::new(
                KerfSource::PierceCurves,
                start(&over_curves)?,
            ));
        }
        if !chained && !exact {
            candidates.push(Candidate::new(KerfSource::Idealised, start(&idealised)?));
        }
        Ok(KerfJob {
            nest: nest.clone(),
            forest,
            settings,
            relax: !after,
            chained,
            candidates,
            turn: 0,
            deadline: started.checked_add(Duration::from_secs_f64(limit.clamp(0.0, 1.0e7))),
            step_cost: None,
            paths: None,
            machine: request.params.machine,
        })
    }

    fn done(&self) -> bool {
        self.candidates
            .iter()
            .all(|c| matches!(c.stage, Stage::Finished(_)))
    }

    /// Advances candidate `i` for about `budget`.
    fn advance(&mut self, i: usize, budget: Duration) {
        let started = Instant::now();
        let until = started + budget;
        let fitter = LeadFitter::with_forest(&self.nest, &self.forest, self.settings);
        let relax = self.relax;
        let chained = self.chained;
        let deadline = self.deadline;
        let relaxing = |route: Route| Stage::Relaxing {
            dirty: vec![true; route.steps.len()],
            route,
            pass: 0,
            next: 0,
        };
        // The time the final route's leads are expected to take: the solver stops that much
        // before the deadline, so its route has them by the limit. Not chain cutting: its
        // route before the chaining has no links, so it runs to the deadline.
        let reserve = match self.step_cost {
            Some(cost) if !chained => {
                (cost * self.nest.contour_count() as u32).mul_f64(ATTACH_MARGIN)
            }
            _ => Duration::ZERO,
        };
        let cut_solver = deadline.is_some_and(|end| Instant::now() + reserve >= end);
        let mut step_cost = self.step_cost;
        let candidate = &mut self.candidates[i];
        loop {
            let stage = std::mem::replace(&mut candidate.stage, Stage::Finished(None));
            candidate.stage = match stage {
                Stage::Modelling(mut modelling) => match modelling.builder.advance(until) {
                    None => Stage::Modelling(modelling),
                    Some(Err(errors)) => Stage::Finished(Some(Err(errors))),
                    Some(Ok(model)) => {
                        candidate.job = exact_job(&self.nest, model, &modelling);
                        Stage::Solving
                    }
                },
                // The exact solver's routes carry their leads already.
                Stage::Solving if candidate.source == KerfSource::FullRoute => {
                    let status = candidate.job.step(budget);
                    if let Some(route) = candidate
                        .job
                        .progress()
                        .solution
                        .and_then(Solution::into_route)
                    {
                        candidate.fitted = Some((route.clone(), Ok(route)));
                    }
                    if status == JobStatus::Done {
                        Stage::Finished(candidate.fitted.take().map(|(_, fitted)| fitted))
                    } else {
                        candidate.stage = Stage::Solving;
                        return;
                    }
                }
                Stage::Solving => {
                    // Past the point where the leads would still be attached by the deadline,
                    // the solver's route so far is its last (when it has one).
                    let status = if cut_solver && candidate.job.progress().route().is_some() {
                        JobStatus::Done
                    } else {
                        candidate.job.step(budget)
                    };
                    let route = candidate
                        .job
                        .progress()
                        .solution
                        .and_then(Solution::into_route);
                    let fitted_from = candidate.fitted.as_ref().map(|(from, _)| from);
                    let pending_from = candidate.pending.as_ref().map(|a| &a.from);
                    if status == JobStatus::Done {
                        match route {
                            None => Stage::Finished(None),
                            // Its leads were fitted already for a report: attached, they are.
                            Some(route) if fitted_from == Some(&route) => {
                                match candidate.fitted.as_ref().map(|(_, r)| r.clone()) {
                                    Some(Ok(route)) if relax => relaxing(route),
                                    other => Stage::Finished(other),
                                }
                            }
                            Some(route) if pending_from == Some(&route) => Stage::Attaching(
                                candidate.pending.take().expect("the pending attachment"),
                            ),
                            Some(route) => Stage::Attaching(Attach::new(&fitter, route, chained)),
                        }
                    } else {
                        // The solver's newer route gets its leads in a quarter more of the
                        // slice, the first one in as much again as the solver had (one at a
                        // time: a report shows the last fitted one meanwhile).
                        if let Some(route) = route {
                            if candidate.pending.is_none() && fitted_from != Some(&route) {
                                candidate.pending = Some(Attach::new(&fitter, route, chained));
                            }
                        }
                        let spare = if candidate.fitted.is_some() {
                            budget / 4
                        } else {
                            budget
                        };
                        if let Some(pending) = candidate.pending.as_mut() {
                            let result = pending.advance(&fitter, Instant::now() + spare);
                            step_cost = pending.step_cost().or(step_cost);
                            if let Some(result) = result {
                                let from = candidate.pending.take().expect("pending").from;
                                candidate.fitted = Some((from, result));
                            }
                        }
                        candidate.stage = Stage::Solving;
                        self.step_cost = step_cost;
                        return;
                    }
                }
                Stage::Attaching(mut attach) => {
                    let result = attach.advance(&fitter, until);
                    step_cost = attach.step_cost().or(step_cost);
                    match result {
                        None => Stage::Attaching(attach),
                        Some(Ok(route)) if relax => relaxing(route),
                        Some(result) => Stage::Finished(Some(result)),
                    }
                }
                Stage::Relaxing {
                    mut route,
                    mut pass,
                    mut next,
                    mut dirty,
                } => {
                    if deadline.is_some_and(|end| Instant::now() >= end) {
                        Stage::Finished(Some(Ok(route)))
                    } else {
                        if dirty[next] {
                            dirty[next] = false;
                            if fitter.relax_step(&mut route, next, RELAX_POSITIONS) {
                                if let Some(before) = next.checked_sub(1) {
                                    dirty[before] = true;
                                }
                                if let Some(after) = dirty.get_mut(next + 1) {
                                    *after = true;
                                }
                            }
                        }
                        next += 1;
                        if next >= route.steps.len() {
                            (pass, next) = (pass + 1, 0);
                        }
                        if pass >= RELAX_PASSES {
                            Stage::Finished(Some(Ok(route)))
                        } else {
                            Stage::Relaxing {
                                route,
                                pass,
                                next,
                                dirty,
                            }
                        }
                    }
                }
                finished @ Stage::Finished(_) => finished,
            };
            // A finished full route gets its kerf pierces once (with edge piercing on): the
            // order and the leads are final, and each move only saves time.
            if let Stage::Finished(Some(Ok(route))) = &mut candidate.stage {
                if !candidate.kerf_pierced {
                    candidate.kerf_pierced = true;
                    fitter.pierce_into_kerfs(route, &self.machine);
                }
            }
            let working = matches!(
                candidate.stage,
                Stage::Attaching(_) | Stage::Relaxing { .. }
            );
            if !working || Instant::now() >= until {
                self.step_cost = step_cost;
                return;
            }
        }
    }
}

impl Candidate {
    fn new(source: KerfSource, job: Box<dyn Job>) -> Candidate {
        Candidate {
            source,
            job,
            stage: Stage::Solving,
            fitted: None,
            pending: None,
            kerf_pierced: false,
        }
    }
}

impl KerfJob {
    /// [`OVERRUN_LIMIT`] past the deadline every unfinished candidate ends with the full route
    /// it has (relaxed as far as it got); whether that time has come. (At the deadline the
    /// solvers are cut and their last routes get their leads; relaxing stops.)
    fn end_at_deadline(&mut self) -> bool {
        let Some(deadline) = self.deadline else {
            return false;
        };
        if Instant::now() < deadline + OVERRUN_LIMIT {
            return false;
        }
        for c in &mut self.candidates {
            let last = match std::mem::replace(&mut c.stage, Stage::Finished(None)) {
                Stage::Relaxing { route, .. } => Some(Ok(route)),
                Stage::Finished(last) => last,
                Stage::Modelling(_) => None,
                Stage::Solving | Stage::Attaching(_) => c.fitted.as_ref().map(|(_, r)| r.clone()),
            };
            c.stage = Stage::Finished(last);
        }
        true
    }
}

impl Job for KerfJob {
    fn step(&mut self, budget: Duration) -> JobStatus {
        if let Some(paths) = self.paths.as_mut() {
            return paths.step(budget);
        }
        if self.end_at_deadline() {
            return JobStatus::Done;
        }
        let solving: Vec<usize> = (0..self.candidates.len())
            .filter(|&i| {
                matches!(
                    self.candidates[i].stage,
                    Stage::Solving | Stage::Modelling(_)
                )
            })
            .collect();
        // Leads are finished one candidate at a time, every attachment before any relaxation,
        // so the first full route is there as soon as one solver has ended (a stop at the
        // limit then still has one); then the shortest route is relaxed first, so a
        // relaxation cut at the limit has spent its time on the route that is kept.
        let finishing = (0..self.candidates.len())
            .find(|&i| matches!(self.candidates[i].stage, Stage::Attaching(_)))
            .or_else(|| {
                (0..self.candidates.len())
                    .filter_map(|i| match &self.candidates[i].stage {
                        Stage::Relaxing { route, .. } => Some((i, route.idle_length())),
                        _ => None,
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(i, _)| i)
            });
        let mut turns = solving.clone();
        turns.extend(finishing);
        if turns.is_empty() {
            return JobStatus::Done;
        }
        // The solvers (and the finishing) share the slice, in turns, so each solver gets its
        // share of the time limit's processor time and all end at the request's limit.
        let share = budget / turns.len() as u32;
        let first = self.turn % turns.len();
        self.turn += 1;
        for k in 0..turns.len() {
            self.advance(turns[(first + k) % turns.len()], share);
        }
        if self.done() {
            JobStatus::Done
        } else {
            JobStatus::Running
        }
    }

    fn progress(&self) -> Progress {
        if let Some(paths) = &self.paths {
            return paths.progress();
        }
        let done = self.done();
        let mut inner: Vec<Progress> = self.candidates.iter().map(|c| c.job.progress()).collect();
        // Each candidate's full route: the finished one, the one being relaxed, or the last
        // route of its solver whose leads are fitted.
        let fitted: Vec<Option<Result<Route, Vec<LeadError>>>> = self
            .candidates
            .iter()
            .map(|c| match &c.stage {
                Stage::Finished(last) => last.clone(),
                Stage::Relaxing { route, .. } => Some(Ok(route.clone())),
                Stage::Solving | Stage::Attaching(_) => c.fitted.as_ref().map(|(_, r)| r.clone()),
                Stage::Modelling(_) => None,
            })
            .collect();
        // The shorter full route (the first candidate, the curves', on a tie).
        let best = fitted
            .iter()
            .enumerate()
            .filter_map(|(i, f)| match f {
                Some(Ok(route)) => Some((i, route)),
                _ => None,
            })
            .min_by(|a, b| {
                a.1.idle_length()
                    .total_cmp(&b.1.idle_length())
                    .then(a.0.cmp(&b.0))
            });
        let (index, note, route) = match best {
            Some((i, route)) => (
                i,
                KerfNote::Leads {
                    source: match self.candidates[i].source {
                        // The links the solver made that the full route lost to pierces.
                        KerfSource::Chains { .. } => KerfSource::Chains {
                            links_broken: inner[i]
                                .route()
                                .map_or(0, links)
                                .saturating_sub(links(route)),
                        },
                        source => source,
                    },
                },
                Some(route.clone()),
            ),
            None => match fitted
                .iter()
                .enumerate()
                .find_map(|(i, f)| f.as_ref().and_then(|f| f.as_ref().err()).map(|e| (i, e)))
            {
                Some((i, errors)) => (i, no_room(errors), None),
                None => (
                    0,
                    KerfNote::Leads {
                        source: self.candidates[0].source,
                    },
                    None,
                ),
            },
        };
        let slowest = inner.iter().map(|p| p.elapsed_s).fold(0.0, f64::max);
        let mut progress = inner.swap_remove(index);
        // The inner bounds, certificates and optimality proof are about the idealised (or the
        // curve) nest, not the full route: none of them is reported for it. The exact
        // solver's are about the discretised full route, whose tour the route is: they stay
        // (the bound no higher than the route's idle length, which the tour's cost equals but
        // for rounding).
        let full_route = self.candidates[index].source == KerfSource::FullRoute;
        let upper = route.as_ref().map(Route::idle_length);
        let lower = match (full_route, progress.bounds.lower, upper) {
            (true, Some(lower), Some(upper)) => Some(lower.min(upper)),
            _ => None,
        };
        progress.bounds = Bounds::idle_mm(upper, lower);
        progress.proven_optimal = full_route && route.is_some() && progress.proven_optimal;
        progress.certified = Vec::new();
        progress.solution = route.map(Solution::Route);
        if done {
            // The slower candidate's clock is the job's.
            progress.elapsed_s = slowest;
        }
        progress.phase = Phase::Kerf {
            base: Box::new(std::mem::take(&mut progress.phase)),
            note,
        };
        progress
    }
}

/// The exact job over a built full-route model, inside its thermal job (which reports H and
/// checks the rules; penalties and repairs are refused with leads). A search that refuses
/// the instance ends in its first steps without a route.
fn exact_job(
    nest: &Nest,
    model: crate::FullRouteModel,
    modelling: &ExactModelling,
) -> Box<dyn Job> {
    let params = &modelling.request.params;
    let limit = Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7));
    let job = FullRouteJob::new(
        modelling.request.job_id,
        nest.clone(),
        model,
        limit,
        modelling.started,
        params.seed,
    );
    Box::new(ThermalJob::new(
        Box::new(job),
        SolverKind::Exact,
        nest.clone(),
        params.machine,
        params.objective,
        params.thermal,
        limit,
    ))
}

/// The tool-on links of a route (steps entered without a pierce).
fn links(route: &Route) -> usize {
    route.steps.iter().filter(|s| !s.is_pierced()).count()
}

pub(crate) fn no_room(errors: &[LeadError]) -> KerfNote {
    let contours = errors
        .iter()
        .map(|e| match e {
            LeadError::UnknownContour { contour }
            | LeadError::Offset { contour, .. }
            | LeadError::NoFit { contour, .. } => (contour.part, contour.contour),
        })
        .collect();
    KerfNote::NoRoom {
        contours,
        errors: errors.iter().map(LeadError::to_string).collect(),
    }
}
