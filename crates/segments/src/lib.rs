//! Segment cutting: SCCP and GSCCP (Petunin, Polishchuk, Ukolov, CCP-Relax paper section 4;
//! Ukolov 2021, §3.4).
//!
//! A *base segment* is what one pierce cuts: a whole contour, part of one, or several contours
//! and pieces of contours joined end to end (neighbouring parts along their common edges). A
//! segment has no direction of its own: an open one is cut from either end, a closed one from
//! any point round (the CCP rule). The crate holds
//! - [`Segment`], [`Ensemble`] and [`EnsembleKind`]: the base segments of a nest — standard
//!   (every contour closed, the CCP), multi-contour chains (the chains of an OE-route of the
//!   plan graph from `cutroute-aoe`: common edges cut once, few pierces) and contours split at
//!   junctions (every plan edge a segment) — with their precedence: segments touching
//!   contours inside a contour C before every segment touching C, plus the ensemble's own
//!   order rules;
//! - [`solve_sccp`]: CCP-Relax generalised to a fixed set of base segments (relaxation of
//!   closed segments' points, direction choice of open ones, block re-insertion under
//!   precedence), time limit and cancel flag;
//! - [`solve_gsccp`]: CCP-Relax seeds every ensemble's order, each is solved and checked by
//!   [`PathRoute::problems`](cutroute_geometry::PathRoute::problems), and the best by time or
//!   cost ([`Objective`]) is kept, with every ensemble's numbers.
//!
//! The searches give no lower bound of their own; the job engine's bound for `sccp` and `gsccp`
//! (`PlanBound` in `cutroute-engine`) bounds the routes of the plan model: tool-on paths
//! only along the contours, an idle move and a pierce between paths. A `chain` route's
//! tool-on links through the scrap are outside that model (the README's solver table says
//! which routes every solver's `lb` bounds).
//!
//! ```
//! use std::sync::atomic::AtomicBool;
//! use cutroute_geometry::{Contour, Nest, Part, Vertex};
//! use cutroute_segments::{solve_gsccp, EnsembleKind, GsccpOptions};
//!
//! // Three 10 × 10 squares in a row, touching: two 30 mm sides and four 10 mm posts.
//! let square = |x: f64| Part {
//!     name: String::new(),
//!     contours: vec![Contour::new(vec![
//!         Vertex::line(x, 0.0), Vertex::line(x, 10.0), Vertex::line(x + 10.0, 10.0), Vertex::line(x + 10.0, 0.0),
//!     ])],
//! };
//! let nest = Nest { sheet: None, parts: vec![square(0.0), square(10.0), square(20.0)] };
//! let options = GsccpOptions {
//!     sccp: cutroute_segments::SccpOptions { time_limit: std::time::Duration::from_millis(200), ..Default::default() },
//!     ..GsccpOptions::default()
//! };
//! let result = solve_gsccp(&nest, &options, &AtomicBool::new(false))?;
//! // Standard cutting: 3 pierces, 120 mm; common edges cut once: 100 mm in 2 pierces.
//! let standard = &result.reports[0];
//! assert_eq!((standard.pierces, standard.cut_length.round()), (3, 120.0));
//! assert_eq!(result.best, Some(EnsembleKind::Chains));
//! assert_eq!(result.route.pierce_count(), 2);
//! assert!((result.route.cut_length() - 100.0).abs() < 1e-9);
//! assert!(result.route.problems(&nest, 1e-7).is_empty());
//! # Ok::<(), cutroute_segments::SegmentError>(())
//! ```
#![deny(missing_docs)]

mod gsccp;
mod segment;
mod solver;

pub use cutroute_anytime::{AnytimeSolver, Bounds, Status};
pub use cutroute_geometry::Objective;
pub use gsccp::{
    recut_length, solve_gsccp, Candidate, EnsembleFailure, EnsembleReport, GsccpOptions,
    GsccpResult, GsccpSearch, GsccpStage,
};
pub use segment::{Ensemble, EnsembleKind, Segment};
pub use solver::{solve_sccp, PathHeat, SccpOptions, SccpSearch, SccpSolution, SOLVE_SLICE};

use cutroute_geometry::{Contour, Nest, Part, Vertex};
use thiserror::Error;

/// A synthetic plan for tests and benchmarks: `columns × rows` parts, each a `width × height`
/// rectangle (clockwise), touching their neighbours along whole edges; the lower left corner
/// at the origin. Cut along common edges once it takes `(rows + 1)·columns·width +
/// (columns + 1)·rows·height` mm.
pub fn rectangle_grid(columns: usize, rows: usize, width: f64, height: f64) -> Nest {
    let mut parts = Vec::with_capacity(columns * rows);
    for row in 0..rows {
        for column in 0..columns {
            let (x0, y0) = (column as f64 * width, row as f64 * height);
            let (x1, y1) = (x0 + width, y0 + height);
            parts.push(Part {
                name: format!("r{row}c{column}"),
                contours: vec![Contour::new(vec![
                    Vertex::line(x0, y0),
                    Vertex::line(x0, y1),
                    Vertex::line(x1, y1),
                    Vertex::line(x1, y0),
                ])],
            });
        }
    }
    Nest { sheet: None, parts }
}

/// Why segment cutting gave no route.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum SegmentError {
    /// The nest gives no plane graph (needed by the chain and junction ensembles).
    #[error("the nest gives no plane graph: {0}")]
    Plan(#[from] cutroute_aoe::PlanError),
    /// The plane graph cannot be ranked into chains or components.
    #[error("the nest gives no plane graph: {0}")]
    Embedding(#[from] cutroute_aoe::EmbeddingError),
    /// The precedence rules of an ensemble contradict each other.
    #[error("the {} ensemble's precedence has a cycle through segment {segment}", kind.name())]
    CyclicPrecedence {
        /// Which ensemble.
        kind: EnsembleKind,
        /// A segment on or behind the cycle.
        segment: usize,
    },
    /// A segment has no spans.
    #[error("segment {segment} has no spans")]
    EmptySegment {
        /// Which segment.
        segment: usize,
    },
    /// A precedence pair names a segment the ensemble does not have.
    #[error("precedence names segment {segment}, but the ensemble has {count}")]
    UnknownSegment {
        /// The index named.
        segment: usize,
        /// How many segments there are.
        count: usize,
    },
    /// CCP-Relax, which seeds the orders, failed.
    #[error("CCP-Relax failed: {0}")]
    Ccp(#[from] cutroute_ccp::CcpError),
    /// CCP-Relax's route is not a valid route of the nest (boxed: a route error is large and
    /// this one is rare).
    #[error("CCP-Relax failed: {0}")]
    CcpRoute(#[source] Box<cutroute_geometry::RouteError>),
    /// An option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// No ensemble gave a route that passed the check.
    #[error("no ensemble gave a valid route ({0})")]
    NoRoute(String),
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{ContourRef, RouteError};
    use std::error::Error as _;

    /// The words stay those of the string the variants once held; the failing crate's error
    /// is kept as the source.
    #[test]
    fn segment_errors_keep_their_words_and_their_source() {
        let route = RouteError::NotCut {
            contour: ContourRef {
                part: 0,
                contour: 1,
            },
        };
        let error = SegmentError::CcpRoute(Box::new(route.clone()));
        assert_eq!(error.to_string(), format!("CCP-Relax failed: {route}"));
        let source = error.source().expect("a source");
        assert_eq!(
            source.downcast_ref::<Box<RouteError>>().map(|b| &**b),
            Some(&route)
        );
        let failure = EnsembleFailure::FailsCheck(cutroute_geometry::PathRouteError::EmptyPath {
            path: 2,
            x: 1.0,
            y: 0.5,
        });
        assert!(failure
            .to_string()
            .starts_with("the route fails the check: "));
        assert!(failure.source().is_some());
        let from_build = EnsembleFailure::from(error.clone());
        assert_eq!(from_build.to_string(), error.to_string());
        assert_eq!(
            EnsembleFailure::NotRun.to_string(),
            "not run: the run was stopped first"
        );
    }
}
