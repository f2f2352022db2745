//! What a job found ([`Solution`]) and how good it is ([`Bounds`], in its [`CostUnit`]).

use cutroute_geometry::{Objective, PathRoute, Route};
use serde::{Deserialize, Serialize};

/// The best result of a job, of whichever shape its solver gives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Solution {
    /// A PCGTSP tour as 0-based node ids, depot first (PCGTSP problems).
    Tour(Vec<usize>),
    /// A route of whole contours, each cut from one pierce point (nest problems).
    Route(Route),
    /// Tool-on paths that may cut parts of several contours in one path (segment and
    /// common-edge cutting; see [`crate::SolverKind::gives_path_route`]).
    PathRoute(PathRoute),
}

impl Solution {
    /// The route of whole contours, if that is the shape.
    pub fn route(&self) -> Option<&Route> {
        match self {
            Solution::Route(route) => Some(route),
            _ => None,
        }
    }

    /// The tool-on paths, if that is the shape.
    pub fn path_route(&self) -> Option<&PathRoute> {
        match self {
            Solution::PathRoute(route) => Some(route),
            _ => None,
        }
    }

    /// The PCGTSP tour, if that is the shape.
    pub fn tour(&self) -> Option<&[usize]> {
        match self {
            Solution::Tour(tour) => Some(tour),
            _ => None,
        }
    }

    /// The route of whole contours, taken out.
    pub fn into_route(self) -> Option<Route> {
        match self {
            Solution::Route(route) => Some(route),
            _ => None,
        }
    }

    /// The tool-on paths, taken out.
    pub fn into_path_route(self) -> Option<PathRoute> {
        match self {
            Solution::PathRoute(route) => Some(route),
            _ => None,
        }
    }
}

/// What a job's bounds measure. The job that computes a bound says its unit, so no reader has
/// to work it out from the solver or the problem.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum CostUnit {
    /// Idle (tool-off) travel, mm: the solvers of routes of whole contours.
    #[default]
    IdleMm,
    /// Machining time, s, under the request's machine: the path-route solvers with
    /// [`Objective::Time`].
    Seconds,
    /// Cost under the machine's prices: the path-route solvers with [`Objective::Cost`].
    Cost,
    /// The arc weights of a PCGTSP instance (a tour's cost, in the instance's own unit).
    TourCost,
}

impl CostUnit {
    /// The unit of the value of `objective`.
    pub fn of_objective(objective: Objective) -> Self {
        match objective {
            Objective::Time => CostUnit::Seconds,
            Objective::Cost => CostUnit::Cost,
        }
    }
}

/// The cost of the best solution so far and a proven lower bound on the optimum, both in
/// `unit`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// The cost of the best solution so far, if any.
    pub upper: Option<f64>,
    /// A proven lower bound on the optimal cost, if the solver computes one.
    pub lower: Option<f64>,
    /// What both measure.
    pub unit: CostUnit,
}

impl Bounds {
    /// No bound yet, in `unit`.
    pub fn unknown(unit: CostUnit) -> Self {
        Self {
            upper: None,
            lower: None,
            unit,
        }
    }

    /// Bounds on idle length, mm.
    pub fn idle_mm(upper: Option<f64>, lower: Option<f64>) -> Self {
        Self {
            upper,
            lower,
            unit: CostUnit::IdleMm,
        }
    }

    /// The relative gap `(upper − lower) / upper`, clamped at 0 (0 when `upper` is 0), when
    /// both are known.
    pub fn gap(&self) -> Option<f64> {
        match (self.upper, self.lower) {
            (Some(ub), Some(lb)) if ub > 0.0 => Some(((ub - lb) / ub).max(0.0)),
            (Some(_), Some(_)) => Some(0.0),
            _ => None,
        }
    }
}
