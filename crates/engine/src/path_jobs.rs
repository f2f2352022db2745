//! The jobs whose routes are tool-on paths ([`PathRoute`]): segment cutting (SCCP, GSCCP) and
//! common-edge routes (AOE). Their progress carries `path_route` (never `route`), the
//! objective's value of the best route as `upper_bound` (seconds or cost, by
//! `params.objective`), a lower bound in the same unit, and the candidates weighed as
//! `alternatives`.

use cutroute_aoe::{AoeHeat, AoeSolution, AoeSolveOptions, AoeSolving, PlanGraph, PlanOptions};
use cutroute_geometry::float::Libm;
use cutroute_geometry::{MachineParameters, Nest, Objective, PathRoute, Point};
use cutroute_protocol::{JobId, JobRequest, Problem, Progress, RouteSummary, SolverKind};
use cutroute_segments::{
    Candidate, EnsembleKind, EnsembleReport, GsccpOptions, GsccpSearch, PathHeat, SccpOptions,
    SearchStatus,
};
use web_time::{Duration, Instant};

use crate::{EngineError, Job, JobStatus};

/// What every route of a plan must at least cut and pierce, from the nest's plane graph
/// (`cutroute-aoe`'s [`PlanGraph`]: contours split at touchings and crossings, common edges
/// merged).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanBound {
    /// Total length of the plan graph's edges less their merging tolerance (mm): every
    /// contour is covered by every route, so every route cuts at least the length of their
    /// union.
    pub cut_length: f64,
    /// Connected components of the plan graph: a tool-on path of these solvers never leaves
    /// its component, so each needs a pierce.
    pub components: usize,
    /// Σ over components of max(1, odd vertices / 2): the pierces of any route that cuts every
    /// plan edge exactly once as trails (SCCP's chain segments, AOE's chains). Routes that cut
    /// edges twice (standard cutting) may pierce less.
    pub trail_pierces: usize,
    /// Idle travel no route avoids (mm): from the start to the parts' bounding box, and from it
    /// to the finish.
    pub idle_length: f64,
}

impl PlanBound {
    /// Measures the plan graph of `nest` built with `tolerance` (mm).
    pub fn new(
        nest: &Nest,
        start: Point,
        finish: Option<Point>,
        tolerance: f64,
    ) -> Result<Self, String> {
        let plan = PlanGraph::from_nest(
            nest,
            &PlanOptions {
                tolerance,
                ..PlanOptions::default()
            },
        )
        .map_err(|e| e.to_string())?;
        let graph = plan.graph();
        let edges = graph.edge_count();
        let length: f64 = (0..edges)
            .flat_map(|e| plan.edge_spans(e).iter())
            .map(|s| s.length())
            .sum();
        let components = plan.components().map_err(|e| e.to_string())?;
        let trail_pierces = components
            .iter()
            .map(|c| cutroute_aoe::pierce_lower_bound(c.embedding.graph()))
            .sum();
        let b = nest.bounding_box();
        let to_box = |p: Point| {
            let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
            let dy = (b.min.y - p.y).max(p.y - b.max.y).max(0.0);
            dx.hypot_libm(dy)
        };
        Ok(PlanBound {
            // Merged copies of a common edge agree within the tolerance at their ends.
            cut_length: (length - 4.0 * tolerance * edges as f64).max(0.0),
            components: components.len(),
            trail_pierces,
            idle_length: to_box(start) + finish.map_or(0.0, to_box),
        })
    }

    /// The objective's lower bound for routes that may cut edges twice (GSCCP's standard
    /// ensemble, the CCP route): at least one pierce per component.
    pub fn any_route(&self, objective: Objective, machine: &MachineParameters) -> f64 {
        objective.value(machine, self.cut_length, self.idle_length, self.components)
    }

    /// The objective's lower bound for routes that cut every plan edge once as trails (AOE).
    pub fn trail_route(&self, objective: Objective, machine: &MachineParameters) -> f64 {
        objective.value(
            machine,
            self.cut_length,
            self.idle_length,
            self.trail_pierces,
        )
    }
}

fn summary(name: &str, route: &PathRoute, machine: &MachineParameters) -> RouteSummary {
    RouteSummary {
        name: name.to_string(),
        pierces: route.pierce_count(),
        idle_length: route.idle_length(),
        cut_length: route.cut_length(),
        time_s: route.time(machine),
        cost: route.cost(machine),
        chosen: false,
        failure: None,
    }
}

fn report_summary(report: &EnsembleReport) -> RouteSummary {
    RouteSummary {
        name: report.kind.name().to_string(),
        pierces: report.pierces,
        idle_length: report.idle_length,
        cut_length: report.cut_length,
        time_s: report.time_s,
        cost: report.cost,
        chosen: false,
        failure: report.failure.clone(),
    }
}

/// The nest, start and finish of a nest request, or why the solver cannot take it.
fn nest_of(request: &JobRequest) -> Result<(&Nest, Point, Option<Point>), EngineError> {
    match &request.problem {
        Problem::Nest {
            nest,
            start,
            finish,
        } => {
            if nest.contour_count() == 0 {
                return Err(EngineError::EmptyNest);
            }
            Ok((nest, *start, *finish))
        }
        Problem::PcgtspText { .. } => Err(EngineError::UnsupportedProblem {
            solver: request.solver.name(),
            problem: "a PCGTSP instance",
        }),
    }
}

/// Segment cutting (`cutroute-segments`' [`GsccpSearch`]): CCP-Relax seeds the orders, then
/// each ensemble is built and searched in slices; SCCP is the chains ensemble alone, GSCCP
/// every ensemble, the best by the objective kept. The first step measures the plan graph for
/// the lower bound (at least the plan's length cut and one pierce per component).
pub struct SegmentJob {
    job_id: JobId,
    search: GsccpSearch,
    nest: Nest,
    start: Point,
    finish: Option<Point>,
    machine: MachineParameters,
    objective: Objective,
    tolerance: f64,
    bound: Option<Result<PlanBound, String>>,
    started: Instant,
}

impl SegmentJob {
    /// The job of an `sccp` or `gsccp` request on a nest.
    pub fn from_request(request: &JobRequest) -> Result<Self, EngineError> {
        let (nest, start, finish) = nest_of(request)?;
        let params = &request.params;
        let kinds = match request.solver {
            SolverKind::Sccp => vec![EnsembleKind::Chains],
            SolverKind::Gsccp => EnsembleKind::ALL.to_vec(),
            other => {
                return Err(EngineError::UnsupportedProblem {
                    solver: other.name(),
                    problem: "a nest by segment cutting",
                })
            }
        };
        let options = GsccpOptions {
            sccp: SccpOptions {
                start,
                finish,
                time_limit: Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7)),
                seed: params.seed,
                // With a heat weight the VNS and the choice between ensembles (and GSCCP's
                // CCP-Relax seed) add W·H, priced on the machine clock of `params.machine`.
                heat: params.thermal.penalised().then(|| PathHeat {
                    penalty: crate::thermal::heat_penalty(&params.thermal, params.objective),
                    machine: params.machine,
                }),
                ..SccpOptions::default()
            },
            kinds,
            machine: params.machine,
            objective: params.objective,
            seed: params.seed,
            ..GsccpOptions::default()
        };
        let search = GsccpSearch::new(nest, &options).map_err(|e| EngineError::SolverRefused {
            solver: request.solver.name(),
            message: e.to_string(),
        })?;
        Ok(SegmentJob {
            job_id: request.job_id,
            search,
            nest: nest.clone(),
            start,
            finish,
            machine: params.machine,
            objective: params.objective,
            tolerance: nest.check_tolerance(),
            bound: None,
            started: Instant::now(),
        })
    }

    /// The search behind the job (its ensembles' reports, the CCP route, the result).
    pub fn search(&self) -> &GsccpSearch {
        &self.search
    }

    /// The plan graph's bound, once the first step has measured it (`Err`: no plane graph).
    pub fn plan_bound(&self) -> Option<&Result<PlanBound, String>> {
        self.bound.as_ref()
    }
}

impl Job for SegmentJob {
    fn step(&mut self, budget: Duration) -> JobStatus {
        if self.bound.is_none() {
            // A plan graph: one piece of work, a step of its own.
            self.bound = Some(PlanBound::new(
                &self.nest,
                self.start,
                self.finish,
                self.tolerance,
            ));
            return JobStatus::Running;
        }
        match self.search.step(budget) {
            SearchStatus::Running => JobStatus::Running,
            SearchStatus::Finished => JobStatus::Done,
        }
    }

    fn progress(&self) -> Progress {
        let best = self.search.best();
        let chosen = best.map(|c: &Candidate| c.source);
        let mut alternatives = Vec::new();
        if let Some(ccp) = self.search.ccp_route() {
            let mut s = summary("ccp", ccp, &self.machine);
            s.chosen = chosen == Some(None);
            alternatives.push(s);
        }
        for report in self.search.reports() {
            let mut s = report_summary(report);
            s.chosen = report.failure.is_none() && chosen == Some(Some(report.kind));
            alternatives.push(s);
        }
        if let Some(p) = self.search.provisional() {
            // The running ensemble's route so far, or CCP-Relax's while it runs.
            let mut s = summary(
                p.source.map_or("ccp", |k| k.name()),
                &p.route,
                &self.machine,
            );
            s.chosen = chosen == Some(p.source);
            alternatives.push(s);
        }
        let lower_bound = match &self.bound {
            Some(Ok(bound)) => Some(bound.any_route(self.objective, &self.machine)),
            _ => None,
        };
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            // The route's own objective value (a candidate's value adds W·H with a heat
            // weight, which the plan bound does not bound).
            upper_bound: best.map(|c| {
                self.objective.value(
                    &self.machine,
                    c.route.cut_length(),
                    c.route.idle_length(),
                    c.route.pierce_count(),
                )
            }),
            lower_bound,
            phase: self.search.phase(),
            route: None,
            tour: None,
            proven_optimal: false,
            states: None,
            certified: Vec::new(),
            path_route: best.map(|c| c.route.clone()),
            alternatives,
            ..Progress::default()
        }
    }
}

/// Common-edge routes along AOE-chains (`cutroute-aoe`'s [`AoeSolving`]): the plan graph and
/// linear-time chains per component in the first step, the ordering of the components in
/// slices (a round of moves per piece), the plan bound in a step of its own. Its lower bound:
/// the plan's length cut once and the trail pierce bound.
pub struct AoeJob {
    job_id: JobId,
    nest: Nest,
    options: AoeSolveOptions,
    finish_bound: (Point, Option<Point>),
    machine: MachineParameters,
    objective: Objective,
    /// The ordering under way (after the first step).
    solving: Option<Box<AoeSolving>>,
    /// The route, before its plan bound is measured.
    solved: Option<AoeSolution>,
    /// The job's wall-clock end: the ordering stops there with its best so far.
    deadline: Option<Instant>,
    outcome: Option<Result<(AoeSolution, Option<PlanBound>), String>>,
    started: Instant,
}

impl AoeJob {
    /// The job of an `aoe` request on a nest.
    pub fn from_request(request: &JobRequest) -> Result<Self, EngineError> {
        let (nest, start, finish) = nest_of(request)?;
        Ok(AoeJob {
            job_id: request.job_id,
            nest: nest.clone(),
            options: AoeSolveOptions {
                plan: PlanOptions {
                    tolerance: nest.check_tolerance(),
                    ..PlanOptions::default()
                },
                start,
                finish,
                // With a heat weight the orderings compete on idle + W·H (machine clock of
                // `params.machine`), and a heat-priced greedy ordering joins them.
                heat: request.params.thermal.penalised().then(|| {
                    let penalty = crate::thermal::heat_penalty(
                        &request.params.thermal,
                        request.params.objective,
                    );
                    AoeHeat {
                        model: penalty.model,
                        weight_mm: penalty.weight_mm(&request.params.machine),
                        machine: request.params.machine,
                    }
                }),
            },
            finish_bound: (start, finish),
            machine: request.params.machine,
            objective: request.params.objective,
            solving: None,
            solved: None,
            deadline: Instant::now().checked_add(Duration::from_secs_f64(
                request.params.time_limit_s.clamp(0.0, 1.0e7),
            )),
            outcome: None,
            started: Instant::now(),
        })
    }

    /// The solution and the plan bound, once the job has run (`Err`: why it failed).
    pub fn outcome(&self) -> Option<&Result<(AoeSolution, Option<PlanBound>), String>> {
        self.outcome.as_ref()
    }
}

impl Job for AoeJob {
    fn step(&mut self, budget: Duration) -> JobStatus {
        if self.outcome.is_some() {
            return JobStatus::Done;
        }
        if let Some(solution) = self.solved.take() {
            // The plan bound builds the plan graph again: a step of its own.
            let (start, finish) = self.finish_bound;
            let bound = PlanBound::new(&self.nest, start, finish, self.options.plan.tolerance).ok();
            self.outcome = Some(Ok((solution, bound)));
            return JobStatus::Done;
        }
        let Some(solving) = self.solving.as_mut() else {
            match AoeSolving::new(&self.nest, &self.options) {
                Ok(solving) => {
                    self.solving = Some(Box::new(solving));
                    return JobStatus::Running;
                }
                Err(e) => {
                    self.outcome = Some(Err(e.to_string()));
                    return JobStatus::Done;
                }
            }
        };
        let slice_end = Instant::now().checked_add(budget);
        let advanced = if self.deadline.is_some_and(|end| Instant::now() >= end) {
            Some(solving.finish_now(&self.nest, &self.options))
        } else {
            solving.advance(&self.nest, &self.options, &|| {
                slice_end.is_some_and(|end| Instant::now() >= end)
            })
        };
        match advanced {
            None => JobStatus::Running,
            Some(Ok(solution)) => {
                self.solving = None;
                self.solved = Some(solution);
                JobStatus::Running
            }
            Some(Err(e)) => {
                self.solving = None;
                self.outcome = Some(Err(e.to_string()));
                JobStatus::Done
            }
        }
    }

    fn progress(&self) -> Progress {
        let solved = match &self.outcome {
            Some(Ok(solved)) => Some(solved),
            _ => None,
        };
        let phase = match &self.outcome {
            None if self.solved.is_some() => "common-edge routes: measuring the plan bound".into(),
            None if self.solving.is_some() => "common-edge routes: ordering the components".into(),
            None => "common-edge routes: building the plan graph".to_string(),
            Some(Ok((solution, _))) => format!(
                "common-edge routes: {} chains in {} components",
                solution.chains.len(),
                solution.components
            ),
            Some(Err(e)) => format!("common-edge routes failed: {e}"),
        };
        let route = solved.map(|(s, _)| &s.route);
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            upper_bound: route.map(|r| {
                self.objective.value(
                    &self.machine,
                    r.cut_length(),
                    r.idle_length(),
                    r.pierce_count(),
                )
            }),
            lower_bound: solved
                .and_then(|(_, b)| b.as_ref())
                .map(|b| b.trail_route(self.objective, &self.machine)),
            phase,
            route: None,
            tour: None,
            proven_optimal: false,
            states: None,
            certified: Vec::new(),
            path_route: route.cloned(),
            alternatives: route
                .map(|r| {
                    let mut s = summary("aoe", r, &self.machine);
                    s.chosen = true;
                    vec![s]
                })
                .unwrap_or_default(),
            ..Progress::default()
        }
    }
}
