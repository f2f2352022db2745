//! What a job found ([`Solution`]); how good it is, [`crate::Bounds`] in its [`crate::CostUnit`],
//! is the solvers' own type (`cutroute-anytime`).

use cutroute_geometry::{PathRoute, Route};
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
