//! Cutting routes over a nest: which contour is cut when, and where the torch pierces.

use serde::{Deserialize, Serialize};

use crate::Point;

/// Identifies one contour of a nest: `part` indexes `Nest::parts`, `contour` that part's contours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ContourRef {
    /// Index into `Nest::parts`.
    pub part: usize,
    /// Index into `Part::contours`.
    pub contour: usize,
}

/// One cut of a route: pierce a contour at a point on it and cut it all the way round.
///
/// The cut follows the contour's own direction (outer clockwise, holes counter-clockwise) from
/// `pierce_point` back to `pierce_point`; the idle move to the next step starts there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CutStep {
    /// The contour that is cut.
    pub contour: ContourRef,
    /// Where the torch pierces; lies on the contour.
    pub pierce_point: Point,
}

/// A complete route: idle from `start` to the first pierce point, cut, idle to the next, …, and
/// finally idle to `finish` (when the machine must return somewhere).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Route {
    /// Where the tool head starts (the machine's home point).
    pub start: Point,
    /// The cuts in order.
    pub steps: Vec<CutStep>,
    /// Where the tool head ends, if the route is closed by a final idle move.
    pub finish: Option<Point>,
}
