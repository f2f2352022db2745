//! Thermal rules for cutting routes: heat accumulation on the machine clock, and the shop rules
//! of part rigidity, sheet rigidity and islands as counted violations (issue #19).
//!
//! Why: every solver minimises time or cost, but a route that pierces again and again in one
//! spot, or that leaves a part held by a thin strip of hot sheet, warps the parts. The
//! dissertation (§1.3.3; digest `docs/science/model-and-pcgtsp.md` §4.3) lists the rules of
//! Krotov and Gurtovenko (Uralkhimmash) as *dynamic* constraints, depending on the route so
//! far, and leaves their formalisation open. This crate gives them a precise form:
//!
//! - [`HeatModel`]: each step is a heat source at its entry point and pierce time on the
//!   route's own [`cutroute_geometry::ToolClock`]; the thermal load is
//!   `H = Σ_i Σ_{j<i} exp(−|M_i − M_j|²/(2σ²)) · exp(−(t_i − t_j)/τ)`
//!   ([`HeatModel::load`], [`HeatModel::route_load`]), and [`HeatModel::temperature_at`] is the
//!   field a heat map draws.
//! - [`check_rules`]: part rigidity, sheet rigidity 1–3 and islands/strips (sheet rule 4) as
//!   [`Violation`]s with counts per group ([`RuleReport::counts`]); the module `rules` documents
//!   the precise definition chosen for each vague phrase and why.
//! - [`relax_pierce_points`]: pierce points moved along their contours to lower idle + weight·H
//!   (the relaxation step of a penalised search).
//! - [`enforce_rules`]: hard-rule mode as a repair of a finished route (whole parts reordered,
//!   pierce points moved), reporting what is left; [`RuleRepair`] is the same repair in
//!   resumable pieces.
//! - [`contour_route_of_paths`]: the rules on routes of tool-on paths (segment and common-edge
//!   cutting), through the contour route they imply.
//!
//! Web-free: it depends on `cutroute-geometry` only, so solvers (CCP-Relax's penalty) and the
//! app can share it.
//!
//! ```
//! use cutroute_geometry::{Contour, ContourRef, CutStep, MachineParameters, Nest, Part, Point, Route};
//! use cutroute_thermal::{check_rules, HeatModel, RuleParams, RuleSet};
//!
//! // Two 10 mm squares 20 mm apart, cut one after the other.
//! let square = |x: f64| Part {
//!     name: format!("at {x}"),
//!     contours: vec![Contour::new(vec![
//!         cutroute_geometry::Vertex::line(x, 0.0),
//!         cutroute_geometry::Vertex::line(x, 10.0),
//!         cutroute_geometry::Vertex::line(x + 10.0, 10.0),
//!         cutroute_geometry::Vertex::line(x + 10.0, 0.0),
//!     ])],
//! };
//! let nest = Nest { sheet: None, parts: vec![square(0.0), square(30.0)] };
//! let route = Route {
//!     start: Point::new(0.0, 0.0),
//!     steps: vec![
//!         CutStep::pierced(ContourRef { part: 0, contour: 0 }, Point::new(0.0, 0.0)),
//!         CutStep::pierced(ContourRef { part: 1, contour: 0 }, Point::new(30.0, 0.0)),
//!     ],
//!     finish: None,
//! };
//! let machine = MachineParameters::default(); // cut 10 mm/s, pierce 7 s, idle 500 mm/s
//! let model = HeatModel::new(50.0, 60.0).unwrap();
//! // Second pierce: 7 s pierce + 4 s cut + 30 mm idle (0.06 s) after the first, 30 mm away.
//! let dt: f64 = 7.0 + 4.0 + 30.0 / 500.0;
//! let expected = (-(30.0f64 * 30.0) / (2.0 * 50.0 * 50.0) - dt / 60.0).exp();
//! let h = model.route_load(&route, &nest, &machine).unwrap();
//! assert!((h - expected).abs() < 1e-12);
//!
//! let report = check_rules(&nest, &route, RuleSet::ALL, &RuleParams::default()).unwrap();
//! assert_eq!(report.counts().islands, Some(0));
//! ```
#![deny(missing_docs)]
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod heat;
mod islands;
mod layout;
mod paths;
mod pierce;
pub mod rules;

pub use heat::{path_route_pierces, route_pierces, HeatModel, Pierce};
pub use paths::contour_route_of_paths;
pub use pierce::relax_pierce_points;
pub use rules::{
    admissible_pierce_points, check_rules, enforce_rules, Enforced, RuleCheck, RuleCounts,
    RuleParams, RuleRepair, RuleReport, RuleSet, Side, Violation,
};

/// What can go wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ThermalError {
    /// A parameter is out of range.
    #[error("invalid {name} = {value}: expected {expected}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A rule name other than part, sheet, islands.
    #[error("unknown rule {0:?} (part, sheet, islands)")]
    UnknownRule(String),
    /// The route does not fit the nest.
    #[error(transparent)]
    Route(Box<cutroute_geometry::RouteError>),
    /// [`RuleRepair::advance`] was called again after it returned its result.
    #[error("the rule repair has already returned its result")]
    RepairFinished,
}
