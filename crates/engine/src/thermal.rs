//! Thermal rules in every nest job (issue #19): the heat-penalised jobs (nearest, ccp, chain),
//! the hard-rule repair of a finished route, and H with the rule violations in every
//! [`Progress`].
//!
//! What each solver honours (README "Thermal rules" has the table):
//! - nearest, ccp, chain: the heat penalty (objective + W·H) in their search, then the repair;
//! - heuristic, exact: H is dynamic (it depends on the times of every earlier pierce), but its
//!   terms between *consecutive* pierces are static: from pierce u to the next pierce v the
//!   machine spends the pierce, the cut of u's contour and the idle move u → v, all known per
//!   arc. With a heat weight those terms are priced on the PCGTSP's arcs
//!   ([`price_consecutive_heat`]), then the final route's pierce points are relaxed on
//!   idle + W·H (all terms) along their contours; with hard rules the route is repaired first.
//!   The reported upper bound is the final route's idle length, and the discrete lower bound
//!   (about penalised arcs through candidate points) is not reported then;
//! - sccp, gsccp, aoe: H has one source per tool-on path. With a heat weight, SCCP's VNS keeps
//!   the order of least idle + W·H and GSCCP picks its ensemble (and seeds its orders with
//!   CCP-Relax) on objective + W·H (`cutroute_segments::PathHeat`); AOE keeps, among its
//!   orderings, the one of least idle + W·H. The rules are checked on the route's contour route
//!   (`contour_route_of_paths`: a contour is done when its last piece is cut, and starts where
//!   its first piece is). Hard rules: a path route that breaks them is replaced by its contour
//!   route repaired like a contour route (whole contours, so common edges are cut twice), which
//!   then obeys them; its lower bound is the plan's bound for any route (SCCP, GSCCP) or none
//!   (AOE's trail bound assumes edges cut once).

use std::cell::RefCell;

use cutroute_ccp::HeatPenalty;
use cutroute_geometry::{
    MachineParameters, Nest, Objective, PathRoute, PathRouteError, Route, RouteError,
};
use cutroute_protocol::{
    CostUnit, Phase, Progress, Solution, SolverKind, ThermalNote, ThermalSettings,
};
use cutroute_thermal::{
    admissible_pierce_points, check_rules, contour_route_of_paths, enforce_rules,
    path_route_pierces, relax_pierce_points, route_pierces, HeatModel, RuleCheck, RuleCounts,
    RuleParams, RuleRepair, ThermalError, Violation,
};
use web_time::{Duration, Instant};

use crate::{Job, JobStatus};

/// Passes of the heat-aware pierce relaxation after a repair (as the CLI always did).
const RELAX_PASSES: usize = 3;

/// Rules are checked on routes that are not the final one only on nests of at most this many
/// contours, where one check is a short piece of a report (92 ms on 1,000 generated contours;
/// 0.37 s on 10,000 and 1.1 s on 30,000, `thermal_measure` example, BENCHMARKS.md). The final
/// route is always checked, in slices of `step`.
const LIVE_RULES_MAX_CONTOURS: usize = 1_000;

/// How long after its time limit a job may still be checking its final route's rules: the
/// promise is limit + 1 s, and the inner job ends at its limit.
pub const FINAL_CHECK_GRACE: Duration = Duration::from_millis(800);

/// Why a path route's hard-rule repair failed: the thermal crate refused, or the repaired
/// contour route could not be cut as standard cutting.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathRepairError {
    /// The rule check, the repair or the heat relaxation refused.
    #[error(transparent)]
    Thermal(#[from] ThermalError),
    /// The repaired contour route does not fit the nest as tool-on paths.
    #[error(transparent)]
    Route(#[from] RouteError),
    /// The repaired route, as tool-on paths, fails the path checker.
    #[error("the repaired route fails the checker: {0}")]
    FailsChecker(#[source] PathRouteError),
}

/// The final route's rule check: the check, the route it checks (a path route's contour
/// route), and the progress's (route, path route) it reports on.
type FinalCheck = (RuleCheck, Route, (Option<Route>, Option<PathRoute>));

/// The hard-rule repair of a finished route, in pieces.
enum RepairWork {
    /// A path route's contour route being checked: a path route obeying the rules is kept.
    PathCheck { contours: Route, check: RuleCheck },
    /// The repair of a contour route; `path`: it is the contour route of a path route, and the
    /// repaired route is cut as standard cutting.
    Rules { repair: RuleRepair, path: bool },
    /// The repair could not start (reported as the repair's failure).
    Failed(ThermalError),
}

/// A measure (H, or the rule check) of a route that is not the final one runs only when at
/// least this many times its own last duration has passed since it ran: the island check
/// replays the route on a raster, and H lays out the route on the machine clock, which on a
/// large nest improving every slice would otherwise eat the solver's slices. Until then the
/// progress carries `None` for it rather than a figure of an earlier route.
const MEASURE_SPACING: u32 = 10;

/// The route repaired until `settings.rules` hold (whole parts reordered, pierce points moved;
/// what is left is what [`check_rules`] then reports), then, with a heat weight, its pierce
/// points relaxed on idle + W·H among those the part rule admits. A route already obeying the
/// rules comes back with its order unchanged.
pub fn enforce_thermal_rules(
    nest: &Nest,
    route: Route,
    settings: &ThermalSettings,
    machine: &MachineParameters,
    objective: Objective,
) -> Result<Route, ThermalError> {
    let route = enforce_rules(nest, &route, settings.rules, &RuleParams::default())?.route;
    relax_repaired(nest, route, settings, machine, objective)
}

/// The end of [`enforce_thermal_rules`] after the rule repair: with a heat weight, the
/// repaired route's pierce points relaxed on idle + W·H among those the part rule admits.
fn relax_repaired(
    nest: &Nest,
    route: Route,
    settings: &ThermalSettings,
    machine: &MachineParameters,
    objective: Objective,
) -> Result<Route, ThermalError> {
    if !settings.penalised() {
        return Ok(route);
    }
    let model = settings.model()?;
    let params = RuleParams::default();
    let candidates = if settings.rules.part {
        Some(admissible_pierce_points(nest, &route, &params)?)
    } else {
        None
    };
    let weight_mm = heat_penalty(settings, objective).weight_mm(machine);
    relax_pierce_points(
        nest,
        &route,
        machine,
        &model,
        weight_mm,
        RELAX_PASSES,
        candidates.as_deref(),
    )
}

/// Hard rules on a route of tool-on paths: `Ok(None)` when its contour route
/// ([`path_contour_route`]) obeys `settings.rules`; else that contour route repaired by
/// [`enforce_thermal_rules`] and cut as standard cutting (whole contours: common edges are cut
/// twice), which obeys them; `Err` when that route fails the path checker (the solver's route
/// is then kept, with its violations).
pub fn enforce_thermal_rules_on_paths(
    nest: &Nest,
    path_route: &PathRoute,
    settings: &ThermalSettings,
    machine: &MachineParameters,
    objective: Objective,
) -> Result<Option<PathRoute>, PathRepairError> {
    let contours = path_contour_route(nest, path_route);
    let report = check_rules(nest, &contours, settings.rules, &RuleParams::default())?;
    if report.violations.is_empty() {
        return Ok(None);
    }
    let route = enforce_thermal_rules(nest, contours, settings, machine, objective)?;
    cut_as_standard(nest, &route).map(Some)
}

/// A repaired contour route as a route of tool-on paths (standard cutting: whole contours,
/// common edges cut twice), or why it fails the path checker.
fn cut_as_standard(nest: &Nest, route: &Route) -> Result<PathRoute, PathRepairError> {
    let paths = PathRoute::from_route(route, nest)?;
    // The repaired route must pass the path checker as the solver's did (pieces cut twice
    // allowed); when it does not, the repair fails and the caller keeps the solver's route.
    if let Some(problem) = paths
        .problems(nest, nest.check_tolerance())
        .into_iter()
        .find(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
    {
        return Err(PathRepairError::FailsChecker(problem));
    }
    Ok(paths)
}

/// The rule check of a route of tool-on paths, on its contour route.
pub fn check_path_rules(
    nest: &Nest,
    path_route: &PathRoute,
    settings: &ThermalSettings,
) -> Result<cutroute_thermal::RuleReport, ThermalError> {
    check_rules(
        nest,
        &path_contour_route(nest, path_route),
        settings.rules,
        &RuleParams::default(),
    )
}

/// Adds to every arc between two candidate pierce points of `discrete` the heat term H would
/// get from that pair being consecutive, `weight_mm · exp(−d²/(2σ²) − Δt/τ)`, with d the
/// points' distance and Δt = pierce time + the first contour's cut + the idle move (the arc's
/// own cost, mm) under `machine`. Arcs from the depot and forbidden arcs are left alone.
pub fn price_consecutive_heat(
    discrete: &mut cutroute_ccp::DiscreteInstance,
    nest: &Nest,
    model: &HeatModel,
    weight_mm: f64,
    machine: &MachineParameters,
) {
    use cutroute_ccp::DiscreteNode;
    let n = discrete.instance.node_count;
    let pierce_of = |v: usize| match discrete.nodes.get(v) {
        Some(DiscreteNode::Pierce { contour, point }) => Some((*contour, *point)),
        _ => None,
    };
    let nodes: Vec<_> = (0..n)
        .map(|v| {
            pierce_of(v).map(|(contour, point)| {
                let cut = nest.contour(contour).map_or(0.0, |c| c.perimeter());
                (point, machine.pierce_time + cut / machine.cut_speed)
            })
        })
        .collect();
    for (u, from) in nodes.iter().enumerate() {
        let Some((pu, busy)) = from else { continue };
        for (v, to) in nodes.iter().enumerate() {
            let Some((pv, _)) = to else { continue };
            let cost = &mut discrete.instance.cost[u * n + v];
            if u == v || !cost.is_finite() {
                continue;
            }
            let dt = busy + *cost / machine.idle_speed;
            *cost += weight_mm * model.kernel((*pu - *pv).norm_squared(), dt);
        }
    }
}

/// CCP-Relax's penalty for the settings and objective.
pub fn heat_penalty(settings: &ThermalSettings, objective: Objective) -> HeatPenalty {
    HeatPenalty {
        model: HeatModel {
            sigma_mm: settings.sigma_mm,
            tau_s: settings.tau_s,
        },
        weight: settings.weight,
        objective,
    }
}

/// What the thermal model says about one route.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThermalMeasure {
    /// H on the route's machine clock.
    pub heat: f64,
    /// Violations per checked group (`None` when no rule is selected).
    pub counts: Option<RuleCounts>,
    /// Every violation.
    pub violations: Vec<Violation>,
}

/// H and the selected rules' violations of a contour route.
pub fn measure_route(
    nest: &Nest,
    route: &Route,
    settings: &ThermalSettings,
    machine: &MachineParameters,
) -> Result<ThermalMeasure, ThermalError> {
    let heat = measure_heat(nest, route, settings, machine)?;
    let (counts, violations) = if settings.rules.any() {
        let report = check_rules(nest, route, settings.rules, &RuleParams::default())?;
        (Some(report.counts()), report.violations)
    } else {
        (None, Vec::new())
    };
    Ok(ThermalMeasure {
        heat,
        counts,
        violations,
    })
}

fn measure_heat(
    nest: &Nest,
    route: &Route,
    settings: &ThermalSettings,
    machine: &MachineParameters,
) -> Result<f64, ThermalError> {
    let model = settings.model()?;
    let pierces = route_pierces(route, nest, machine)?;
    Ok(model.load(&pierces))
}

/// H of a route of tool-on paths (one source per path, at its pierce).
pub fn measure_path_route(
    route: &PathRoute,
    settings: &ThermalSettings,
    machine: &MachineParameters,
) -> Result<f64, ThermalError> {
    let model = settings.model()?;
    Ok(model.load(&path_route_pierces(route, machine)))
}

/// The contour route of a path route, by which the rules judge it (spans within 10× the
/// nest's check tolerance of a contour lie on it, as AOE's own check allows).
pub fn path_contour_route(nest: &Nest, route: &PathRoute) -> Route {
    contour_route_of_paths(nest, route, 10.0 * nest.check_tolerance())
}

/// The last measured route, so a progress report of an unchanged route costs a comparison.
#[derive(Default)]
struct Measured {
    route: Option<Route>,
    path_route: Option<PathRoute>,
    heat: Option<f64>,
    rules: Option<(Option<RuleCounts>, Vec<Violation>)>,
    /// When H was last measured, and how long that took.
    heat_measured: Option<(Instant, Duration)>,
    /// When the rules were last checked, and how long that took.
    rules_checked: Option<(Instant, Duration)>,
}

/// Whether a measure last run at `last` (start, duration) may run again.
fn due(last: Option<(Instant, Duration)>, done: bool) -> bool {
    match last {
        None => true,
        Some((at, took)) => done || at.elapsed() >= took * MEASURE_SPACING,
    }
}

/// Any nest job with the thermal settings applied around it: H and the rule violations in
/// every [`Progress`], and with `hard` the final route repaired by
/// [`enforce_thermal_rules`] (contour routes only).
pub struct ThermalJob {
    inner: Box<dyn Job>,
    solver: SolverKind,
    nest: Nest,
    /// Contours of the nest.
    contours: usize,
    machine: MachineParameters,
    objective: Objective,
    settings: ThermalSettings,
    done: bool,
    /// The repaired final route, or why the repair failed (the solver's route is then kept).
    repaired: Option<Result<Route, ThermalError>>,
    /// The same for a path route: its contour route repaired, as standard cutting.
    repaired_path: Option<Result<PathRoute, PathRepairError>>,
    /// The hard-rule repair under way, a piece per step (about a second on Nest02/03).
    repair_work: Option<RepairWork>,
    /// The final route's rule check under way: the check, the (contour) route it checks, and
    /// the progress's route and path route it belongs to.
    final_check: Option<FinalCheck>,
    /// The final check was given up at the deadline (or failed): no counts are reported.
    final_check_cut: bool,
    /// The request's time limit + [`FINAL_CHECK_GRACE`] from the job's start.
    deadline: Option<Instant>,
    measured: RefCell<Measured>,
}

impl ThermalJob {
    /// Wraps `inner`, a job of `solver` on `nest` with `time_limit` (the final rule check
    /// ends by then + [`FINAL_CHECK_GRACE`]).
    pub fn new(
        inner: Box<dyn Job>,
        solver: SolverKind,
        nest: Nest,
        machine: MachineParameters,
        objective: Objective,
        settings: ThermalSettings,
        time_limit: Duration,
    ) -> Self {
        ThermalJob {
            inner,
            solver,
            contours: nest.parts.iter().map(|p| p.contours.len()).sum(),
            nest,
            machine,
            objective,
            settings,
            done: false,
            repaired: None,
            repaired_path: None,
            repair_work: None,
            final_check: None,
            final_check_cut: false,
            deadline: Instant::now().checked_add(time_limit + FINAL_CHECK_GRACE),
            measured: RefCell::default(),
        }
    }

    /// The discrete solvers, whose order search does not price H.
    fn discrete(&self) -> bool {
        matches!(self.solver, SolverKind::Heuristic | SolverKind::Exact)
    }

    fn repair(&mut self) {
        let hard = self.settings.hard && self.settings.rules.any();
        let relax = self.settings.penalised() && self.discrete();
        if !(hard || relax) {
            return;
        }
        let progress = self.inner.progress();
        if let (true, Some(path_route)) = (hard, progress.path_route()) {
            let contours = path_contour_route(&self.nest, path_route);
            self.repair_work = Some(
                match RuleCheck::new(self.settings.rules, RuleParams::default()) {
                    Ok(check) => RepairWork::PathCheck { contours, check },
                    Err(e) => RepairWork::Failed(e),
                },
            );
            return;
        }
        let Some(route) = progress.solution.and_then(Solution::into_route) else {
            return;
        };
        if hard {
            self.repair_work = Some(
                match RuleRepair::new(&route, self.settings.rules, RuleParams::default()) {
                    Ok(repair) => RepairWork::Rules {
                        repair,
                        path: false,
                    },
                    Err(e) => RepairWork::Failed(e),
                },
            );
            return;
        }
        // Not hard: the discrete solvers' pierce points relaxed on the heat weight.
        self.repaired = Some(self.settings.model().and_then(|model| {
            let weight_mm = heat_penalty(&self.settings, self.objective).weight_mm(&self.machine);
            relax_pierce_points(
                &self.nest,
                &route,
                &self.machine,
                &model,
                weight_mm,
                RELAX_PASSES,
                None,
            )
        }));
    }

    /// Works on the repair under way for about `budget`; true when it is over (its result is
    /// in `repaired` or `repaired_path`).
    fn advance_repair(&mut self, budget: Duration) -> bool {
        let Some(work) = self.repair_work.take() else {
            return true;
        };
        let nest = &self.nest;
        let next = match work {
            RepairWork::PathCheck {
                contours,
                mut check,
            } => match check.advance(nest, &contours, budget) {
                Ok(None) => RepairWork::PathCheck { contours, check },
                // A path route whose contour route obeys the rules is kept as it is.
                Ok(Some(report)) if report.violations.is_empty() => return true,
                Ok(Some(_)) => {
                    match RuleRepair::new(&contours, self.settings.rules, RuleParams::default()) {
                        Ok(repair) => RepairWork::Rules { repair, path: true },
                        Err(e) => RepairWork::Failed(e),
                    }
                }
                Err(e) => RepairWork::Failed(e),
            },
            RepairWork::Rules { mut repair, path } => match repair.advance(nest, budget) {
                Ok(None) => RepairWork::Rules { repair, path },
                Ok(Some(enforced)) => {
                    let route = relax_repaired(
                        nest,
                        enforced.route,
                        &self.settings,
                        &self.machine,
                        self.objective,
                    );
                    if path {
                        self.repaired_path = Some(
                            route
                                .map_err(PathRepairError::from)
                                .and_then(|route| cut_as_standard(nest, &route)),
                        );
                    } else {
                        self.repaired = Some(route);
                    }
                    return true;
                }
                Err(e) => RepairWork::Failed(e),
            },
            RepairWork::Failed(e) => {
                if self.base_is_path() {
                    self.repaired_path = Some(Err(e.into()));
                } else {
                    self.repaired = Some(Err(e));
                }
                return true;
            }
        };
        self.repair_work = Some(next);
        false
    }

    /// Whether the inner job's result is a route of tool-on paths.
    fn base_is_path(&self) -> bool {
        self.inner.progress().path_route().is_some()
    }

    /// Whether a report checks the rules of a route that is not the final one (the final one
    /// is checked in slices by `step`): on small nests only, and spaced out.
    fn live_check_due(&self, measured: &Measured) -> bool {
        self.settings.rules.any()
            && measured.rules.is_none()
            && !self.done
            && self.contours <= LIVE_RULES_MAX_CONTOURS
            && due(measured.rules_checked, false)
    }

    /// Fills `progress`'s thermal fields from its route, measuring only what changed.
    fn measure(&self, progress: &mut Progress) {
        let mut measured = self.measured.borrow_mut();
        if let Some(route) = progress.route() {
            if measured.route.as_ref() != Some(route) {
                *measured = Measured {
                    route: Some(route.clone()),
                    heat_measured: measured.heat_measured,
                    rules_checked: measured.rules_checked,
                    ..Measured::default()
                };
            }
            if measured.heat.is_none() && due(measured.heat_measured, self.done) {
                let started = Instant::now();
                measured.heat = measure_heat(&self.nest, route, &self.settings, &self.machine).ok();
                measured.heat_measured = Some((started, started.elapsed()));
            }
            if self.live_check_due(&measured) {
                let started = Instant::now();
                if let Ok(report) = check_rules(
                    &self.nest,
                    route,
                    self.settings.rules,
                    &RuleParams::default(),
                ) {
                    measured.rules = Some((Some(report.counts()), report.violations));
                }
                measured.rules_checked = Some((started, started.elapsed()));
            }
            progress.heat = measured.heat;
            if let Some((counts, violations)) = &measured.rules {
                progress.rule_counts = *counts;
                progress.violations = violations.clone();
            }
        } else if let Some(path_route) = progress.path_route() {
            if measured.path_route.as_ref() != Some(path_route) {
                *measured = Measured {
                    heat: measure_path_route(path_route, &self.settings, &self.machine).ok(),
                    path_route: Some(path_route.clone()),
                    rules_checked: measured.rules_checked,
                    ..Measured::default()
                };
            }
            if measured.heat.is_none() {
                // The final check's record starts without H.
                measured.heat = measure_path_route(path_route, &self.settings, &self.machine).ok();
            }
            if self.live_check_due(&measured) {
                let started = Instant::now();
                let contours = path_contour_route(&self.nest, path_route);
                if let Ok(report) = check_rules(
                    &self.nest,
                    &contours,
                    self.settings.rules,
                    &RuleParams::default(),
                ) {
                    measured.rules = Some((Some(report.counts()), report.violations));
                }
                measured.rules_checked = Some((started, started.elapsed()));
            }
            progress.heat = measured.heat;
            if let Some((counts, violations)) = &measured.rules {
                progress.rule_counts = *counts;
                progress.violations = violations.clone();
            }
        }
    }
}

impl Job for ThermalJob {
    fn stop(&mut self) {
        self.inner.stop();
    }

    fn step(&mut self, budget: Duration) -> JobStatus {
        if self.done {
            return JobStatus::Done;
        }
        if let Some(check) = self.final_check.as_mut() {
            if self.deadline.is_some_and(|end| Instant::now() >= end) {
                // The check would break the time limit: the final report says "not checked"
                // (`None`) rather than block.
                self.final_check = None;
                self.final_check_cut = true;
                self.done = true;
                return JobStatus::Done;
            }
            let (check, route, key) = check;
            let started = Instant::now();
            match check.advance(&self.nest, route, budget) {
                Ok(None) => return JobStatus::Running,
                Ok(Some(report)) => {
                    let (route, path_route) = std::mem::take(key);
                    let mut measured = self.measured.borrow_mut();
                    *measured = Measured {
                        route,
                        path_route,
                        rules: Some((Some(report.counts()), report.violations)),
                        rules_checked: Some((started, started.elapsed())),
                        ..Measured::default()
                    };
                }
                Err(_) => self.final_check_cut = true,
            }
            self.final_check = None;
            self.done = true;
            return JobStatus::Done;
        }
        if self.repair_work.is_some() {
            if !self.advance_repair(budget) {
                return JobStatus::Running;
            }
        } else {
            if self.inner.step(budget) == JobStatus::Running {
                return JobStatus::Running;
            }
            self.repair();
            if self.repair_work.is_some() {
                return JobStatus::Running;
            }
        }
        if !self.settings.rules.any() {
            self.done = true;
            return JobStatus::Done;
        }
        // The final route's rule check, in slices from the next step on (on 30,000 contours
        // it takes about a second).
        let progress = self.base_progress();
        let checked = match &progress.solution {
            Some(Solution::Route(route)) => Some(route.clone()),
            Some(Solution::PathRoute(path_route)) => {
                Some(path_contour_route(&self.nest, path_route))
            }
            Some(Solution::Tour(_)) | None => None,
        };
        match (
            checked,
            RuleCheck::new(self.settings.rules, RuleParams::default()),
        ) {
            (Some(route), Ok(check)) => {
                let key = (progress.route().cloned(), progress.path_route().cloned());
                self.final_check = Some((check, route, key));
                JobStatus::Running
            }
            _ => {
                self.done = true;
                JobStatus::Done
            }
        }
    }

    fn progress(&self) -> Progress {
        let mut progress = self.base_progress();
        if self.final_check_cut {
            progress.phase = thermal_phase(
                std::mem::take(&mut progress.phase),
                ThermalNote::RulesNotChecked,
            );
        }
        self.measure(&mut progress);
        progress
    }
}

impl ThermalJob {
    /// The inner job's progress with the repaired route, before the thermal measures.
    fn base_progress(&self) -> Progress {
        let mut progress = self.inner.progress();
        if let Some(repaired) = &self.repaired_path {
            match repaired {
                Ok(route) => {
                    progress.bounds.upper = Some(self.objective.value(
                        &self.machine,
                        route.cut_length(),
                        route.idle_length(),
                        route.pierce_count(),
                    ));
                    // SCCP's and GSCCP's plan bound holds for any route; AOE's assumes
                    // every edge cut once, which standard cutting does not.
                    if self.solver == SolverKind::Aoe {
                        progress.bounds.lower = None;
                    }
                    progress.phase = thermal_phase(
                        std::mem::take(&mut progress.phase),
                        ThermalNote::RulesEnforcedOnWholeContours,
                    );
                    progress.solution = Some(Solution::PathRoute(route.clone()));
                }
                Err(e) => {
                    progress.phase = thermal_phase(
                        std::mem::take(&mut progress.phase),
                        ThermalNote::RepairFailed {
                            error: e.to_string(),
                        },
                    )
                }
            }
        }
        match &self.repaired {
            Some(Ok(route)) if progress.route() != Some(route) => {
                // The solver's bounds are those of the problem without rules: a lower bound on
                // every route stays sound (the rules only remove routes); the discrete one is
                // about routes through its candidate points, which the changed route leaves.
                // The optimality proof and the tour do not describe the changed route.
                progress.bounds.upper = Some(match progress.bounds.unit {
                    // Chain cutting's bounds are on the route's cost.
                    CostUnit::Cost => route.cost(&self.nest, &self.machine),
                    CostUnit::Seconds => route.time(&self.nest, &self.machine),
                    CostUnit::IdleMm | CostUnit::TourCost => route.idle_length(),
                });
                if self.discrete() {
                    progress.bounds.lower = None;
                }
                progress.proven_optimal = false;
                if !progress.certified.is_empty() {
                    progress.certified = cutroute_ccp::route_certificates(&self.nest, route)
                        .map(|c| c.iter().map(|c| c.condition1).collect())
                        .unwrap_or_default();
                }
                progress.phase = Phase::Thermal {
                    base: Box::new(std::mem::take(&mut progress.phase)),
                    note: if self.settings.hard {
                        ThermalNote::RulesEnforced
                    } else {
                        ThermalNote::Relaxed
                    },
                };
                progress.solution = Some(Solution::Route(route.clone()));
            }
            _ if self.discrete() && self.settings.penalised() => {
                // The tour's cost includes the arcs' heat terms: report the route's idle
                // length, and no discrete bound (it bounds the penalised arcs).
                if let Some(route) = progress.route() {
                    progress.bounds.upper = Some(route.idle_length());
                }
                progress.bounds.lower = None;
                progress.proven_optimal = false;
            }
            Some(Err(e)) => {
                progress.phase = Phase::Thermal {
                    base: Box::new(std::mem::take(&mut progress.phase)),
                    note: ThermalNote::RepairFailed {
                        error: e.to_string(),
                    },
                }
            }
            _ => {}
        }
        progress
    }
}

/// `base` with a thermal job's note on it.
fn thermal_phase(base: Phase, note: ThermalNote) -> Phase {
    Phase::Thermal {
        base: Box::new(base),
        note,
    }
}
