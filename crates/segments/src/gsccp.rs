//! GSCCP: several ensembles of one nest, each solved as an SCCP, the best kept by time or cost.

use std::sync::atomic::AtomicBool;
use std::time::Duration;

use cutroute_ccp::{CcpOptions, CcpSolver, SolverStatus};
use cutroute_geometry::{MachineParameters, Nest, Objective, PathRoute, PathRouteError, Route};
use serde::{Deserialize, Serialize};
use web_time::Instant;

use crate::segment::{Ensemble, EnsembleKind};
use crate::solver::{solve_sccp, SccpOptions};
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

/// The numbers of one ensemble's route.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    pub failure: Option<String>,
}

/// The outcome of [`solve_gsccp`].
#[derive(Clone, Debug, PartialEq)]
pub struct GsccpResult {
    /// The best route by the objective; [`PathRoute::problems`] finds nothing wrong with it
    /// but pieces of contour cut twice (see [`EnsembleReport::recut_length`]).
    pub route: PathRoute,
    /// Which ensemble it came from.
    pub best: EnsembleKind,
    /// Every ensemble's numbers, in the order of the options' kinds.
    pub reports: Vec<EnsembleReport>,
    /// The CCP-Relax route that seeded the orders, as a path route.
    pub ccp_route: PathRoute,
}

fn nest_scale(nest: &Nest) -> f64 {
    let b = nest.bounding_box();
    ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0)
}

/// Runs CCP-Relax for its share of the time, then builds and solves every ensemble of
/// `options.kinds` seeded by its route, checks each route independently and returns the best
/// by the objective with every ensemble's numbers. A route may compete if the check finds
/// nothing but contour cut twice (standard cutting of parts with common edges); gaps, cuts
/// through material and precedence violations disqualify it.
pub fn solve_gsccp(
    nest: &Nest,
    options: &GsccpOptions,
    cancel: &AtomicBool,
) -> Result<GsccpResult, SegmentError> {
    if !(options.ccp_share > 0.0 && options.ccp_share < 1.0) {
        return Err(SegmentError::InvalidOption(format!(
            "ccp_share {} must lie strictly between 0 and 1",
            options.ccp_share
        )));
    }
    let started = Instant::now();
    let limit = options.sccp.time_limit;
    let ccp = run_ccp(
        nest,
        CcpOptions {
            start: options.sccp.start,
            finish: options.sccp.finish,
            time_limit: limit.mul_f64(options.ccp_share),
            seed: options.seed,
            machine: options.machine,
            ..CcpOptions::default()
        },
        cancel,
    )?;
    let ccp_route =
        PathRoute::from_route(&ccp, nest).map_err(|e| SegmentError::Ccp(e.to_string()))?;
    let tolerance = options
        .check_tolerance
        .unwrap_or_else(|| 1e-6 * nest_scale(nest));
    let machine = &options.machine;
    let mut reports = Vec::new();
    let mut best: Option<(f64, EnsembleKind, PathRoute)> = None;
    // Standard cutting starts from CCP-Relax's own local optimum: it needs the least time.
    let weight = |kind: EnsembleKind| match kind {
        EnsembleKind::Standard => 1.0,
        EnsembleKind::Chains => 3.0,
        EnsembleKind::Junctions => 2.0,
    };
    for (k, &kind) in options.kinds.iter().enumerate() {
        let left = limit.saturating_sub(started.elapsed());
        let remaining: f64 = options.kinds[k..].iter().map(|&x| weight(x)).sum();
        let share = left.mul_f64(weight(kind) / remaining);
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
        let outcome = Ensemble::build(nest, kind, options.plan_tolerance.unwrap_or(tolerance))
            .and_then(|ensemble| {
                report.segments = ensemble.segments.len();
                let sccp = SccpOptions {
                    time_limit: share.max(Duration::from_millis(1)),
                    ..options.sccp.clone()
                };
                solve_sccp(&ensemble, Some(&ccp), &sccp, cancel)
            });
        match outcome {
            Err(e) => report.failure = Some(e.to_string()),
            Ok(solution) => {
                let route = solution.route;
                report.pierces = route.pierce_count();
                report.idle_length = route.idle_length();
                report.cut_length = route.cut_length();
                report.time_s = route.time(machine);
                report.cost = route.cost(machine);
                // Cutting a piece of contour twice wastes time but harms nothing: such
                // routes compete with their true cost. Anything else disqualifies.
                let mut problems = route.problems(nest, tolerance);
                report.recut_length = recut_length(&problems, tolerance);
                problems.retain(|p| !matches!(p, PathRouteError::Overlap { .. }));
                match problems.first() {
                    Some(problem) => {
                        report.failure = Some(format!("the route fails the check: {problem}"))
                    }
                    None => {
                        let value = match options.objective {
                            Objective::Time => report.time_s,
                            Objective::Cost => report.cost,
                        };
                        if best.as_ref().is_none_or(|b| value < b.0) {
                            best = Some((value, kind, route));
                        }
                    }
                }
            }
        }
        reports.push(report);
    }
    let Some((_, kind, route)) = best else {
        let reasons: Vec<String> = reports
            .iter()
            .map(|r| {
                format!(
                    "{}: {}",
                    r.kind.name(),
                    r.failure.clone().unwrap_or_default()
                )
            })
            .collect();
        return Err(SegmentError::NoRoute(reasons.join("; ")));
    };
    Ok(GsccpResult {
        route,
        best: kind,
        reports,
        ccp_route,
    })
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
        let near = |a: f64, b: f64, c: f64, d: f64| (a - c).hypot(b - d) <= tolerance;
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

fn run_ccp(nest: &Nest, options: CcpOptions, cancel: &AtomicBool) -> Result<Route, SegmentError> {
    let mut solver = CcpSolver::new(nest, options).map_err(|e| SegmentError::Ccp(e.to_string()))?;
    loop {
        if cancel.load(std::sync::atomic::Ordering::Relaxed) {
            solver.cancel();
        }
        if solver.step(Duration::from_millis(50)) == SolverStatus::Finished {
            return Ok(solver.result().route);
        }
    }
}
