//! Cutting routes over a nest: which contour is cut when, and where the torch pierces.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::{ContainmentForest, Nest, Point};

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

/// Machine speeds, pierce time and prices, for the time (1.2) and cost (1.3) objectives.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MachineParameters {
    /// Idle (air-move) speed V_off, mm/s.
    pub idle_speed: f64,
    /// Cutting speed V_on, mm/s.
    pub cut_speed: f64,
    /// Time of one pierce t_pt, s.
    pub pierce_time: f64,
    /// Price of one metre of idle move C_off.
    pub idle_price_per_metre: f64,
    /// Price of one metre of cut C_on.
    pub cut_price_per_metre: f64,
    /// Price of one pierce C_pt.
    pub pierce_price: f64,
}

impl Default for MachineParameters {
    /// Speeds and pierce time of the `E1X_6_01` cutting task (idle 500 mm/s, cut 10 mm/s,
    /// pierce 7 s); prices in arbitrary units, idle moves ten times cheaper than cutting.
    fn default() -> Self {
        MachineParameters {
            idle_speed: 500.0,
            cut_speed: 10.0,
            pierce_time: 7.0,
            idle_price_per_metre: 0.1,
            cut_price_per_metre: 1.0,
            pierce_price: 0.5,
        }
    }
}

impl MachineParameters {
    /// Time `T = L_on/V_on + L_off/V_off + N·t_pt`, seconds, for lengths in millimetres.
    pub fn time(&self, cut_length: f64, idle_length: f64, pierces: usize) -> f64 {
        cut_length / self.cut_speed
            + idle_length / self.idle_speed
            + pierces as f64 * self.pierce_time
    }

    /// Cost `F = L_on·C_on + L_off·C_off + N·C_pt`, lengths in millimetres (prices per metre).
    pub fn cost(&self, cut_length: f64, idle_length: f64, pierces: usize) -> f64 {
        cut_length * 1e-3 * self.cut_price_per_metre
            + idle_length * 1e-3 * self.idle_price_per_metre
            + pierces as f64 * self.pierce_price
    }
}

/// One way a route fails to be a valid continuous cutting route of a nest.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum RouteError {
    /// A step names a contour the nest does not have.
    #[error("step {step} cuts contour {contour:?}, which the nest does not have")]
    UnknownContour {
        /// Index of the step.
        step: usize,
        /// The reference.
        contour: ContourRef,
    },
    /// A contour is cut more than once.
    #[error("contour {contour:?} is cut twice: at steps {first_step} and {second_step}")]
    CutTwice {
        /// The contour.
        contour: ContourRef,
        /// Its first cut.
        first_step: usize,
        /// Its repeated cut.
        second_step: usize,
    },
    /// A contour is never cut.
    #[error("contour {contour:?} is never cut")]
    NotCut {
        /// The contour.
        contour: ContourRef,
    },
    /// A pierce point is off its contour.
    #[error("step {step} pierces contour {contour:?} {distance} mm away from it (tolerance {tolerance} mm)")]
    PierceOffContour {
        /// Index of the step.
        step: usize,
        /// The contour.
        contour: ContourRef,
        /// Distance from the pierce point to the contour (NaN for a non-finite point).
        distance: f64,
        /// The tolerance exceeded.
        tolerance: f64,
    },
    /// A contour is cut after a contour that contains it.
    #[error("contour {inner:?} (step {inner_step}) lies inside {outer:?} (step {outer_step}) but is cut after it")]
    PrecedenceViolated {
        /// The contained contour.
        inner: ContourRef,
        /// Step at which it is cut.
        inner_step: usize,
        /// The containing contour.
        outer: ContourRef,
        /// Step at which that is cut.
        outer_step: usize,
    },
}

impl Route {
    /// The points the tool head idles through: start, every pierce point, finish (if any).
    pub fn idle_points(&self) -> impl Iterator<Item = Point> + '_ {
        std::iter::once(self.start)
            .chain(self.steps.iter().map(|s| s.pierce_point))
            .chain(self.finish)
    }

    /// Total length of the straight idle moves start → pierce → … → pierce → finish, mm.
    pub fn idle_length(&self) -> f64 {
        let points: Vec<Point> = self.idle_points().collect();
        points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }

    /// Number of pierces (one per step).
    pub fn pierce_count(&self) -> usize {
        self.steps.len()
    }

    /// Total cut length: the perimeters of the contours cut, mm. Unknown contours count 0
    /// (see [`Route::validate`]).
    pub fn cut_length(&self, nest: &Nest) -> f64 {
        self.steps
            .iter()
            .filter_map(|s| nest.contour(s.contour))
            .map(|c| c.perimeter())
            .sum()
    }

    /// Machining time of the route, seconds (formula 1.2).
    pub fn time(&self, nest: &Nest, machine: &MachineParameters) -> f64 {
        machine.time(
            self.cut_length(nest),
            self.idle_length(),
            self.pierce_count(),
        )
    }

    /// Cost of the route (formula 1.3).
    pub fn cost(&self, nest: &Nest, machine: &MachineParameters) -> f64 {
        machine.cost(
            self.cut_length(nest),
            self.idle_length(),
            self.pierce_count(),
        )
    }

    /// Every way the route fails the nest (empty when valid): each contour cut exactly once,
    /// each pierce point within `tolerance` mm of its contour, and inner contours cut before
    /// every contour containing them.
    pub fn problems(
        &self,
        nest: &Nest,
        forest: &ContainmentForest,
        tolerance: f64,
    ) -> Vec<RouteError> {
        let mut problems = Vec::new();
        let mut step_of: Vec<Option<usize>> = vec![None; forest.len()];
        for (step, s) in self.steps.iter().enumerate() {
            let (Some(index), Some(contour)) =
                (forest.index_of(s.contour), nest.contour(s.contour))
            else {
                problems.push(RouteError::UnknownContour {
                    step,
                    contour: s.contour,
                });
                continue;
            };
            match step_of[index] {
                Some(first_step) => problems.push(RouteError::CutTwice {
                    contour: s.contour,
                    first_step,
                    second_step: step,
                }),
                None => step_of[index] = Some(step),
            }
            let distance = contour.distance_to(s.pierce_point);
            if !(distance <= tolerance) {
                problems.push(RouteError::PierceOffContour {
                    step,
                    contour: s.contour,
                    distance,
                    tolerance,
                });
            }
        }
        for (index, step) in step_of.iter().enumerate() {
            let Some(contour) = forest.contour_ref(index) else {
                continue;
            };
            if step.is_none() {
                problems.push(RouteError::NotCut { contour });
            }
        }
        // All ancestors, not just parents: a contour left uncut must not hide a violation
        // between its child and its parent.
        for (inner, outer) in forest.all_precedence_pairs() {
            let (Some(i), Some(o)) = (forest.index_of(inner), forest.index_of(outer)) else {
                continue;
            };
            if let (Some(inner_step), Some(outer_step)) = (step_of[i], step_of[o]) {
                if inner_step > outer_step {
                    problems.push(RouteError::PrecedenceViolated {
                        inner,
                        inner_step,
                        outer,
                        outer_step,
                    });
                }
            }
        }
        problems
    }

    /// Checks the route against the nest (see [`Route::problems`]) and reports the first
    /// failure. Builds the containment forest; use [`Route::problems`] to reuse one.
    pub fn validate(&self, nest: &Nest, tolerance: f64) -> Result<(), RouteError> {
        let forest = nest.containment_forest();
        match self.problems(nest, &forest, tolerance).into_iter().next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}
