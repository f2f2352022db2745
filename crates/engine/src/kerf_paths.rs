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

use cutroute_geometry::{
    ContainmentForest, KerfSettings, LeadError, LeadFitter, LeadProblem, MachineParameters, Nest,
    Objective, PathRoute, PathRouteError, ToolOnPath,
};
use cutroute_protocol::{Bounds, KerfNote, KerfSource, Phase, Progress, Solution};
use web_time::{Duration, Instant};

use crate::{Job, JobStatus};

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
}

impl PathLeadsRun {
    /// `job` is the solver's job over `LeadFitter::kerf_nest` of `nest`.
    pub(crate) fn new(
        nest: Nest,
        forest: ContainmentForest,
        settings: KerfSettings,
        machine: MachineParameters,
        objective: Objective,
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
        }
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
        progress.phase = Phase::Kerf {
            base: Box::new(std::mem::take(&mut progress.phase)),
            note,
        };
        progress
    }
}
