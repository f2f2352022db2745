//! The full cutting route for the path solvers (sccp, gsccp, aoe), inside [`crate::KerfJob`].
//!
//! The solver runs on [`LeadFitter::kerf_nest`] (every contour replaced by its equidistant at
//! kerf/2), so its tool-on paths are the tool centre's paths and the idle legs it prices run
//! between points of the equidistants. Each route it reports gets a lead-in at every path's
//! start and a lead-out at its end ([`LeadFitter::attach_path`], one path at a time so no
//! step runs long); a path that cuts one equidistant round moves its start along it where the
//! lead has no room. Contours where no lead fits are named (`KerfNote::NoRoom`), never dropped.
//!
//! Common edges (aoe; sccp's chains) exist on the kerf nest only where equidistants coincide:
//! parts spaced by exactly the kerf. Parts spaced closer (touching parts among them) have
//! equidistants that cross each other: no cut keeps kerf/2 from both, since every route must
//! cut every equidistant whole. [`crate::KerfJob`] refuses such a nest before any solver runs
//! (`Refusal::PartsTooClose`). Each route the solver gives is still checked against the nest
//! once its leads are fitted (a cut within the tolerance of an equidistant may come a little
//! closer than the equidistant itself): the contours it would burn into are named as contours
//! without room (the checker reports such cuts as `PathRouteError::CutTooClose`).
//!
//! A route with leads that fails the path checker is never the answer: the last one that
//! passed is kept, and until one has, a contour route (nearest neighbour on the nest, its
//! leads fitted as for the contour solvers) that passes the route checker. The rejected
//! route's problem is stated as an alternative named [`REJECTED_ROUTE`].

use cutroute_geometry::{
    ContainmentForest, KerfSettings, LeadError, LeadFitter, LeadProblem, MachineParameters, Nest,
    Objective, PathRoute, PathRouteError, Point, Route, ToolOnPath,
};
use cutroute_protocol::{Bounds, KerfNote, KerfSource, Phase, Progress, RouteSummary, Solution};
use web_time::{Duration, Instant};

use crate::{Job, JobStatus, NearestNeighbourJob};

/// The name of the alternative that states why a path solver's route with leads was set
/// aside for a checked one (its `failure` says what the checker found).
pub const REJECTED_ROUTE: &str = "rejected route";

/// The route a path job answers with when its own route with leads fails the checker.
enum Fallback {
    /// A route with leads of the solver that passed the checker.
    Paths(PathRoute),
    /// A contour route with leads that passed the route checker.
    Contours(Route),
}

/// Leads attached to a solver's path route, one path at a time.
struct Attach {
    from: PathRoute,
    paths: Vec<ToolOnPath>,
    errors: Vec<LeadError>,
}

impl Attach {
    fn new(from: PathRoute) -> Attach {
        Attach {
            paths: Vec::with_capacity(from.paths.len()),
            errors: Vec::new(),
            from,
        }
    }

    /// Attaches paths until `until`; the route with leads (or every contour without room)
    /// once every path is done.
    fn advance(
        &mut self,
        fitter: &LeadFitter<'_>,
        until: Instant,
    ) -> Option<Result<PathRoute, Vec<LeadError>>> {
        loop {
            let done = self.paths.len() + self.errors.len();
            let Some(path) = self.from.paths.get(done) else {
                return Some(if self.errors.is_empty() {
                    Ok(PathRoute {
                        paths: std::mem::take(&mut self.paths),
                        ..self.from.clone()
                    })
                } else {
                    Err(std::mem::take(&mut self.errors))
                });
            };
            match fitter.attach_path(path) {
                Ok(p) => self.paths.push(p),
                Err(e) => self.errors.push(e),
            }
            if Instant::now() >= until {
                return None;
            }
        }
    }
}

/// A path solver's job over the kerf nest and the leads of its routes.
pub(crate) struct PathLeadsRun {
    nest: Nest,
    forest: ContainmentForest,
    settings: KerfSettings,
    machine: MachineParameters,
    objective: Objective,
    job: Box<dyn Job>,
    solving: bool,
    /// The last solver route whose leads are fitted, and what the fit gave.
    fitted: Option<(PathRoute, Result<PathRoute, Vec<LeadError>>)>,
    /// A newer solver route whose leads are being fitted.
    pending: Option<Attach>,
    start: Point,
    finish: Option<Point>,
    /// The last checked route, once a route with leads has failed the checker (`None` inside
    /// when no checked route could be made).
    fallback: Option<Option<Fallback>>,
    /// The last route with leads that passed the path checker.
    checked: Option<PathRoute>,
    /// What the checker found in the last rejected route with leads.
    failure: Option<String>,
}

impl PathLeadsRun {
    /// `job` is the solver's job over `LeadFitter::kerf_nest` of `nest`.
    pub(crate) fn new(
        nest: Nest,
        forest: ContainmentForest,
        settings: KerfSettings,
        machine: MachineParameters,
        objective: Objective,
        (start, finish): (Point, Option<Point>),
        job: Box<dyn Job>,
    ) -> PathLeadsRun {
        PathLeadsRun {
            nest,
            forest,
            settings,
            machine,
            objective,
            job,
            solving: true,
            fitted: None,
            pending: None,
            start,
            finish,
            fallback: None,
            checked: None,
            failure: None,
        }
    }

    /// Records a fitted route's check: a passing one is kept; a failing one is set aside for
    /// the last passing route, or (none yet) a checked contour route.
    fn check(&mut self, route: &PathRoute) {
        let problems = route.problems(&self.nest, self.nest.check_tolerance());
        // Common edges cut twice are standard cutting, as the CLI allows.
        let failure = problems
            .iter()
            .find(|p| !matches!(p, PathRouteError::Overlap { .. }));
        match failure {
            None => {
                self.checked = Some(route.clone());
                if self.fallback.is_some() {
                    self.fallback = Some(Some(Fallback::Paths(route.clone())));
                }
            }
            Some(p) => {
                self.failure = Some(format!("the route with leads fails the checker: {p}"));
                let fallback = match &self.checked {
                    Some(c) => Some(Fallback::Paths(c.clone())),
                    None => match self.fallback.take() {
                        Some(Some(f)) => Some(f),
                        _ => self.contour_route().map(Fallback::Contours),
                    },
                };
                self.fallback = Some(fallback);
            }
        }
    }

    /// A nearest-neighbour contour route of the nest with its leads, if it passes the route
    /// checker.
    fn contour_route(&self) -> Option<Route> {
        let mut job =
            NearestNeighbourJob::new(0, self.nest.clone(), self.start, self.finish).ok()?;
        while job.step(Duration::from_millis(50)) == JobStatus::Running {}
        let route = job.progress().route()?.clone();
        let fitted =
            crate::kerf::fit_leads(&self.nest, &self.forest, self.settings, &route, false).ok()?;
        fitted
            .problems(&self.nest, &self.forest, self.nest.check_tolerance())
            .is_empty()
            .then_some(fitted)
    }

    pub(crate) fn step(&mut self, budget: Duration) -> JobStatus {
        let started = Instant::now();
        let fitter = LeadFitter::with_forest(&self.nest, &self.forest, self.settings);
        if self.solving {
            // The solver gets most of the slice; its newer routes get their leads in the rest.
            let status = self.job.step(budget * 3 / 4);
            if status == JobStatus::Done {
                self.solving = false;
            }
        }
        let latest = self
            .job
            .progress()
            .solution
            .and_then(Solution::into_path_route);
        let fitted_from = self.fitted.as_ref().map(|(from, _)| from);
        let pending_from = self.pending.as_ref().map(|a| &a.from);
        if let Some(route) = latest {
            if fitted_from != Some(&route) && pending_from != Some(&route) {
                // A route the solver has since replaced is not finished: the newest one is.
                if self.pending.is_none() || !self.solving {
                    self.pending = Some(Attach::new(route));
                }
            }
        }
        let until = started + budget;
        if let Some(pending) = self.pending.as_mut() {
            if let Some(result) = pending.advance(&fitter, until.max(Instant::now())) {
                let from = self.pending.take().expect("pending").from;
                let result = result.and_then(|route| self.clear_of_parts(route));
                if let Ok(route) = &result {
                    self.check(route);
                }
                self.fitted = Some((from, result));
            }
        }
        if self.solving || self.pending.is_some() {
            JobStatus::Running
        } else {
            JobStatus::Done
        }
    }

    /// `route` if its cuts keep kerf/2 from every contour; else the contours its kerf would
    /// burn into (parts spaced closer than the kerf, touching ones among them), as contours
    /// without room.
    fn clear_of_parts(&self, route: PathRoute) -> Result<PathRoute, Vec<LeadError>> {
        let close = self.too_close(&route, self.nest.check_tolerance());
        if close.is_empty() {
            Ok(route)
        } else {
            Err(close)
        }
    }

    /// The contours that `cuts` come closer to than kerf/2 less `tolerance`, each once, as
    /// contours without room.
    fn too_close(&self, cuts: &PathRoute, tolerance: f64) -> Vec<LeadError> {
        let mut named = std::collections::HashSet::new();
        cuts.clearance_problems(&self.nest, self.settings.kerf / 2.0, tolerance)
            .into_iter()
            .filter_map(|p| match p {
                PathRouteError::CutTooClose {
                    contour,
                    x,
                    y,
                    distance,
                    ..
                } => named.insert(contour).then_some(LeadError::NoFit {
                    contour,
                    reason: LeadProblem::LeadTooClose { x, y, distance },
                }),
                _ => None,
            })
            .collect()
    }

    pub(crate) fn progress(&self) -> Progress {
        let mut progress = self.job.progress();
        let fitted = self.fitted.as_ref().map(|(_, r)| r.as_ref());
        let (note, route) = match fitted {
            Some(Ok(route)) => (
                KerfNote::Leads {
                    source: KerfSource::Paths,
                },
                Some(route.clone()),
            ),
            Some(Err(errors)) => (crate::kerf::no_room(errors), None),
            None => (
                KerfNote::Leads {
                    source: KerfSource::Paths,
                },
                None,
            ),
        };
        // The solver's bounds and alternatives are about the kerf nest without leads.
        let upper = route.as_ref().map(|r| {
            self.objective.value(
                &self.machine,
                r.cut_length(),
                r.idle_length(),
                r.pierce_count(),
            )
        });
        progress.bounds = Bounds {
            upper,
            lower: None,
            unit: self.objective.unit(),
        };
        progress.idle_lower_bound = None;
        progress.proven_optimal = false;
        progress.alternatives = Vec::new();
        progress.solution = route.map(Solution::PathRoute);
        if let (Some(Some(fallback)), Some(Ok(rejected))) = (&self.fallback, fitted) {
            if Some(rejected) != self.checked.as_ref() {
                self.answer_with(&mut progress, fallback, rejected);
            }
        }
        progress.phase = Phase::Kerf {
            base: Box::new(std::mem::take(&mut progress.phase)),
            note,
        };
        progress
    }

    /// `progress` answering with `fallback` in place of the `rejected` route with leads, the
    /// checker's finding stated as the alternative [`REJECTED_ROUTE`].
    fn answer_with(&self, progress: &mut Progress, fallback: &Fallback, rejected: &PathRoute) {
        let value = |cut: f64, idle: f64, pierces: usize| {
            self.objective.value(&self.machine, cut, idle, pierces)
        };
        let (solution, name, cut, idle, pierces) = match fallback {
            Fallback::Paths(r) => (
                Solution::PathRoute(r.clone()),
                "checked route with leads",
                r.cut_length(),
                r.idle_length(),
                r.pierce_count(),
            ),
            Fallback::Contours(r) => (
                Solution::Route(r.clone()),
                "contour route",
                r.cut_length(&self.nest),
                r.idle_length(),
                r.pierce_count(),
            ),
        };
        progress.bounds.upper = Some(value(cut, idle, pierces));
        progress.solution = Some(solution);
        progress.alternatives = vec![
            RouteSummary {
                name: REJECTED_ROUTE.to_string(),
                pierces: rejected.pierce_count(),
                idle_length: rejected.idle_length(),
                cut_length: rejected.cut_length(),
                time_s: rejected.time(&self.machine),
                cost: rejected.cost(&self.machine),
                chosen: false,
                failure: self
                    .failure
                    .as_ref()
                    .map(|f| format!("{f}; the {name} is reported instead")),
                idle_lower_bound: None,
            },
            RouteSummary {
                chosen: true,
                ..RouteSummary::measured(name, (cut, idle, pierces), &self.machine)
            },
        ];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, LeadShape, LeadSpec, Part};
    use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

    /// A solver job that answers with a fixed path route.
    struct Fixed(PathRoute);

    impl Job for Fixed {
        fn step(&mut self, _: Duration) -> JobStatus {
            JobStatus::Done
        }

        fn progress(&self) -> Progress {
            Progress {
                solution: Some(Solution::PathRoute(self.0.clone())),
                ..Progress::default()
            }
        }
    }

    fn square(x: f64, y: f64, side: f64) -> Contour {
        Contour::rectangle(x, y, x + side, y + side)
    }

    /// A route with leads the checker rejects (it leaves a contour uncut) gives way to a
    /// checked contour route, and the rejection is stated.
    #[test]
    fn a_rejected_route_with_leads_gives_way_to_a_checked_contour_route() {
        let part = |name: &str, x: f64| Part {
            name: name.to_string(),
            contours: vec![square(x, 20.0, 30.0)],
        };
        let nest = Nest {
            sheet: None,
            parts: vec![part("a", 20.0), part("b", 100.0)],
        };
        let forest = nest.containment_forest();
        let settings = KerfSettings {
            kerf: 1.0,
            lead_in: LeadSpec::new(LeadShape::Line, 4.0),
            ..KerfSettings::default()
        };
        let start = Point::new(0.0, 0.0);
        // The solver's own route over the equidistants, less its last path.
        let equidistants = LeadFitter::with_forest(&nest, &forest, settings).kerf_nest();
        let request = JobRequest {
            job_id: 1,
            problem: Problem::Nest {
                nest: equidistants,
                start,
                finish: None,
            },
            solver: SolverKind::Sccp,
            params: SolverParams::default(),
        };
        let mut solver = crate::start_job(&request).expect("sccp starts");
        while solver.step(Duration::from_millis(50)) == JobStatus::Running {}
        let mut partial = solver
            .progress()
            .solution
            .and_then(Solution::into_path_route)
            .expect("a route");
        assert_eq!(partial.paths.len(), 2);
        partial.paths.pop();
        let machine = MachineParameters::default();
        let mut run = PathLeadsRun::new(
            nest.clone(),
            forest.clone(),
            settings,
            machine,
            Objective::Time,
            (start, None),
            Box::new(Fixed(partial)),
        );
        let mut steps = 0;
        while run.step(Duration::from_millis(50)) == JobStatus::Running {
            steps += 1;
            assert!(steps < 1000, "the run ends");
        }
        let progress = run.progress();
        let Some(Solution::Route(route)) = &progress.solution else {
            panic!("a contour route, not {:?}", progress.solution);
        };
        assert_eq!(
            route.problems(&nest, &forest, nest.check_tolerance()),
            Vec::new()
        );
        assert!(route.steps.iter().all(|s| s.leads.is_some()));
        let rejected = &progress.alternatives[0];
        assert_eq!(rejected.name, REJECTED_ROUTE);
        assert!(!rejected.chosen);
        let failure = rejected.failure.as_deref().expect("the failure stated");
        assert!(failure.contains("fails the checker"), "{failure}");
        assert!(progress.alternatives[1].chosen);
        assert!(progress.bounds.upper.is_some());
    }
}
