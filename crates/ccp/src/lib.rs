//! CCP-Relax: the continuous cutting problem solver of cutroute.
//!
//! Each contour of a nest is cut whole from a pierce point that may lie **anywhere** on it; the
//! solver chooses the order of the contours and the pierce points to minimise the idle (air)
//! length of the route. It follows Ukolov (2021), Chapter 3:
//!
//! 1. remove the "outer" contours (those containing others): every order of the remaining
//!    innermost contours is feasible;
//! 2. for a fixed order, move one pierce point at a time to the minimiser of
//!    `|M(i−1) M| + |M M(i+1)|` over its contour (exact on segments and arcs) until a sweep gains
//!    less than δ;
//! 3. optimise the order by variable neighbourhood search (block shift, block reversal, swaps,
//!    block exchange, 3- and 4-cycles in a window, rotation of equal blocks, optimal block
//!    re-insertion; candidate lists from the k nearest contours; shaking and restarts);
//! 4. restore the removed contours at the route's last crossing with each of them, which keeps
//!    "inner before outer" and adds no length (where the route only touches a contour, within
//!    10⁻³ mm, at its last contact: at most 2e-3 mm more).
//!
//! The route is then certified per pierce point by Conditions 1 and 2 (sufficient conditions for
//! the global optimum of the pierce points for the order). [`CcpSolver`] is a resumable anytime
//! solver for time-sliced callers; [`solve`] runs it to the end. [`build_pcgtsp`] builds the
//! discrete (PCGTSP) alternative of a nest.
//!
//! ```
//! use cutroute_ccp::{solve, CcpOptions};
//! use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};
//!
//! let square = |x: f64| Part {
//!     name: format!("square at {x}"),
//!     contours: vec![Contour::new(vec![
//!         Vertex::line(x, 0.0),
//!         Vertex::line(x, 10.0),
//!         Vertex::line(x + 10.0, 10.0),
//!         Vertex::line(x + 10.0, 0.0),
//!     ])],
//! };
//! let nest = Nest { sheet: None, parts: vec![square(40.0), square(0.0), square(20.0)] };
//! let options = CcpOptions { start: Point::new(-10.0, 5.0), ..CcpOptions::default() };
//! let result = solve(&nest, options, &mut |_| {}).unwrap();
//! // The straight line from the start through the squares: 10 + 20 + 20 mm.
//! assert!((result.metrics.idle_length - 50.0).abs() < 1e-6);
//! assert!(result.certified_optimal_for_order);
//! ```
//!
//! # Open routes
//! Without a finish point the route ends at its last cut. If that contour lies inside outer
//! contours (a hole, or a part in a hole), the route must still leave them to cut them after it:
//! it exits through the nearest point of each enclosing contour in turn, and the search counts
//! that exit as part of the idle length.
//!
//! # Search details
//! A move's *fixed-point* delta (pierce points held) is exact in O(1); relaxation can only
//! shorten, so a negative one is a sure improvement. Otherwise a bound and a one-point relaxation
//! estimate per junction decide whether to check the move exactly: apply, relax the junctions
//! with propagation, keep or undo. The VND is driven by a queue of contours whose surroundings
//! changed (every contour at first), each anchoring all neighbourhoods in turn; a run reaches its
//! first local optimum, then shakes (random moves in a window of the order, the strongest a
//! double bridge), descends again and keeps the result only if shorter, and restarts from a
//! randomised nearest-neighbour order after `max_non_improving_shakes` failures.
//!
//! # Heat penalty
//! With [`CcpOptions::heat`] set ([`HeatPenalty`], issue #19) the search minimises the idle
//! length plus the weight times the thermal load H of `cutroute-thermal`, converted to
//! millimetres of idle: H depends on the whole partial route (each pierce's time is the sum of
//! everything before it), so it is a *dynamic* penalty and no fixed-point delta bounds it. Every
//! move is therefore checked exactly (apply, relax, recompute H, keep or undo) and shakes and
//! restarts compare the penalised objective; the pierce point relaxation itself stays the
//! exact idle-length minimiser. Without the option (or with weight 0) nothing changes: same
//! moves, same screens, same route. The Conditions 1 and 2 certificates speak of the idle
//! length only.
//!
//! # Geometry
//! Arc data (centre, radius, sweep), exact span boxes, contour area and perimeter,
//! point-in-contour and the containment forest all come from `cutroute-geometry`. The solver
//! only caches each arc's centre, radius and start angle (module `geom`) so that its inner
//! loops evaluate points, nearest points and chord crossings without trigonometry; those
//! evaluators are tested against the geometry crate's. The uniform box grid with k-nearest
//! queries (module `problem`) is the solver's own.
#![deny(missing_docs)]

mod bound;
mod discrete;
mod geom;
mod ngpath;
mod problem;
mod relax;
mod relaxed_tours;
mod route;
mod search;
mod solver;

pub use bound::{CcpLowerBound, LinkPrices, LowerBoundOptions, StageWork, MAX_RELAXATION_ENTRIES};
pub use cutroute_anytime::{AnytimeSolver, Bounds, Status};
pub use discrete::{
    build_pcgtsp, pierce_candidates, DiscreteInstance, DiscreteNode, DiscretisationOptions,
    PcgtspBuilder, MAX_DISCRETE_NODES,
};
pub use ngpath::{NgPathBound, NgStats, MAX_NG};
pub use route::{idle_length, route_certificates, route_metrics, ContourCertificate, RouteMetrics};
pub use solver::{
    solve, solve_with_cancel, CcpOptions, CcpPhase, CcpProgress, CcpResult, CcpSolver, HeatPenalty,
};

use cutroute_geometry::{ContourRef, Nest};

/// What can go wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CcpError {
    /// An option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// A route names a contour the nest does not have.
    #[error("the nest has no contour {contour} in part {part}")]
    UnknownContour {
        /// Part index.
        part: usize,
        /// Contour index within the part.
        contour: usize,
    },
    /// A PCGTSP node tour does not describe a route.
    #[error("invalid tour: {0}")]
    InvalidTour(String),
}

/// The containment forest of a nest's contours: pairs `(inner, outer)` for every contour lying
/// inside another (transitively closed), in "inner before outer" precedence form.
pub fn containment_pairs(nest: &Nest) -> Vec<(ContourRef, ContourRef)> {
    let prob = problem::Problem::new(nest, cutroute_geometry::Point::ORIGIN, None);
    prob.precedence_pairs()
        .into_iter()
        .map(|(a, b)| (prob.refs[a], prob.refs[b]))
        .collect()
}
