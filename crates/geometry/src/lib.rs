//! Plane geometry of sheet-cutting plans: points, bulge arcs, closed contours, parts and nests.
//!
//! A contour is a closed chain of *spans*; each span runs from one vertex to the next and is a
//! straight segment (`bulge == 0`) or a circular arc whose bulge is `tan(φ/4)` of its swept
//! angle φ (positive = counter-clockwise). The closing span runs from the last vertex back to the
//! first: the duplicated closing point that files store is dropped by the readers.
//!
//! What the kernel offers, bottom up:
//! - [`Span`]: length, area, points and tangents by arc-length parameter, exact bounding box,
//!   splitting and joining, nearest point, intersections, arc through three points — stable
//!   for β → 0 and right for semicircles (β = ±1) and larger arcs (|β| > 1).
//! - [`Contour`]: closing raw file points ([`Contour::close_points`]), orientation, area,
//!   perimeter, reversal by the DBS rule, [`Transform`]s, point-in-contour with true arcs,
//!   nearest point, length parameterisation, self-intersection check, flattening; the one
//!   meaning of a contour ([`Contour::check_cuttable`]) and the one repair of drawn outlines
//!   that touch or cross themselves in a loop too small to cut ([`Contour::without_small_loops`]).
//! - [`Nest`] and [`ContainmentForest`]: which contour lies inside which, hence the cutting
//!   precedence "inner before outer".
//! - [`Route`]: idle and cut length, time and cost under [`MachineParameters`], and an
//!   independent validity check; a step may be entered by a tool-on link ([`Entry::Link`],
//!   chain cutting) instead of idle move + pierce, checked to cross no contour; [`Toolpath`] and [`ToolClock`]: the head's moves (idle, pierce,
//!   cut span by span) on the machine's time axis, for animation, G-code and exports.
//! - [`PathRoute`]: segment cutting (SCCP/GSCCP): tool-on paths of arbitrary spans, each from
//!   one pierce, with lengths, time, cost and an independent coverage/scrap/precedence check.
//! - The full cutting route (issue #17): [`equidistant`] (exact offsets at kerf/2), the pierce
//!   and switch-off regions ([`in_clear_scrap`]), lead-ins and lead-outs ([`LeadSpec`]) fitted
//!   by [`LeadFitter`] into [`StepLeads`] on a [`CutStep`]; [`KerfSettings::default`] is the
//!   idealised model; [`kerf_overlaps`]: parts closer than the kerf, where no cut keeps kerf/2
//!   off its neighbour.
//! - [`generate_nest`]: deterministic synthetic nests of up to tens of thousands of contours.
//!
//! Sign conventions: [`Contour::signed_area`] is positive for counter-clockwise contours (the
//! dissertation's Appendix Б uses the opposite sign); outer contours run clockwise and holes
//! counter-clockwise (material on the right), see [`Nest::normalize_orientation`].
//!
//! ```
//! use cutroute_geometry::{Contour, ContourRef, CutStep, Nest, Part, Point, Route, Vertex};
//! // A 10 × 10 square, clockwise as outer contours are.
//! let square = Contour::new(vec![
//!     Vertex::line(0.0, 0.0),
//!     Vertex::line(0.0, 10.0),
//!     Vertex::line(10.0, 10.0),
//!     Vertex::line(10.0, 0.0),
//! ]);
//! assert_eq!(square.vertices.len(), 4);
//! assert_eq!(square.vertices[2].point, Point::new(10.0, 10.0));
//! assert!(square.is_clockwise());
//! assert_eq!(square.signed_area(), -100.0);
//!
//! // A round hole of radius 2: two semicircles (bulge +1 = counter-clockwise).
//! let hole = Contour::circle(Point::new(5.0, 5.0), 2.0, false);
//! assert!((hole.perimeter() - 4.0 * std::f64::consts::PI).abs() < 1e-12);
//! assert!(hole.contains(Point::new(6.5, 5.0)) && !hole.contains(Point::new(6.5, 6.5)));
//!
//! // The hole must be cut before the square that contains it.
//! let nest = Nest { sheet: None, parts: vec![Part { name: "plate".into(), contours: vec![square, hole] }] };
//! let forest = nest.containment_forest();
//! let (outer, inner) = (ContourRef { part: 0, contour: 0 }, ContourRef { part: 0, contour: 1 });
//! assert_eq!(forest.parent(inner), Some(outer));
//! assert_eq!(forest.precedence_pairs(), vec![(inner, outer)]);
//!
//! let route = Route {
//!     start: Point::new(0.0, -10.0),
//!     steps: vec![
//!         CutStep::pierced(inner, Point::new(7.0, 5.0)),
//!         CutStep::pierced(outer, Point::new(10.0, 5.0)),
//!     ],
//!     finish: None,
//! };
//! assert!(route.validate(&nest, 1e-9).is_ok());
//! assert!((route.idle_length() - (7.0f64.hypot(15.0) + 3.0)).abs() < 1e-12);
//! ```
#![deny(missing_docs)]
// `!(x <= tol)` is deliberate throughout: it is true for NaN, so bad input fails checks
// instead of slipping through them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bbox;
mod chain_leads;
mod contour;
pub mod domain;
pub mod float;
mod forest;
mod generator;
mod kerf;
mod kerf_clearance;
mod leads;
mod loop_repair;
mod neighbours;
mod offset_carrier;
mod path_leads;
mod path_route;
mod point;
mod read_warning;
mod rng;
mod route;
mod span;
mod toolpath;
mod transform;
mod types;
mod viewport;

pub use bbox::BoundingBox;
pub use chain_leads::{ChainedAttach, ChainedLeads};
pub use contour::{
    flatten_spans, ClosureError, ContourError, ContourFault, ContourPosition, ContourProjection,
    SelfIntersection,
};
pub use domain::{DomainError, NestDomainError, MAX_BULGE, MAX_COORDINATE, MIN_CONTOUR_EXTENT};
pub use forest::ContainmentForest;
pub use generator::generate_nest;
pub use kerf::{clearance, equidistant, in_clear_scrap, OffsetError};
pub use kerf_clearance::{
    contours_on_one_another, kerf_overlaps, ContourSpans, KerfOverlap, PartsTooClose, TooClose,
};
pub use leads::{
    chain_spans, opened_at, place_tabs, KerfField, KerfRange, KerfRangeError, KerfSettings,
    LeadError, LeadFitter, LeadProblem, LeadShape, LeadSpec, StepLeads, Tab, TabSpec,
    MAX_KERF_LENGTH, MAX_TABS, MIN_KERF_LENGTH,
};
pub use loop_repair::{LoopReason, LoopRepair, RemovedLoop};
pub use neighbours::nearest_groups;
pub use path_leads::PathLeads;
pub use path_route::{PathLeadError, PathRoute, PathRouteError, ToolOnPath};
pub use read_warning::{ReadWarning, WarningKind, WarningPlace};
pub use rng::{SplitMix64, Xoshiro256};
pub use route::{
    in_scrap_region, is_scrap_region, ContourRef, CutStep, Entry, MachineParameters, Objective,
    Route, RouteError,
};
pub use span::{tan_half_arg, Span, SpanIntersection, SpanProjection};
pub use toolpath::{ToolClock, ToolMove, ToolState, Toolpath};
pub use transform::Transform;
pub use types::{Contour, Nest, Part, Point, Vertex};
pub use viewport::Viewport;
