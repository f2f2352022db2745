//! Cutting routes over a nest: which contour is cut when, and where the torch pierces.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::kerf_clearance::{cut_overlaps, touching};
use crate::{
    ContainmentForest, Contour, ContourSpans, LeadFitter, LeadProblem, Nest, Point, Span, StepLeads,
};

/// Identifies one contour of a nest: `part` indexes `Nest::parts`, `contour` that part's contours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ContourRef {
    /// Index into `Nest::parts`.
    pub part: usize,
    /// Index into `Part::contours`.
    pub contour: usize,
}

/// How every message names a contour: parts from 1, as the page lists them, and contours from
/// 0, the outer contour first.
impl std::fmt::Display for ContourRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "part {} contour {}", self.part + 1, self.contour)
    }
}

/// How the tool reaches the contour of a step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum Entry {
    /// Idle move from where the previous step ended (or the start), then a pierce.
    #[default]
    Pierce,
    /// Chain cutting: the torch stays on and cuts a *link* from the previous step's exit point
    /// (its pierce point, since contours are closed) to this step's pierce point, through these
    /// intermediate corners (empty for a straight link). No idle move and no pierce: the link
    /// is cut length. Valid only between siblings of one scrap region (see [`Route::problems`]).
    Link(Vec<Point>),
}

/// One cut of a route: reach a contour at a point on it (idle + pierce, or a tool-on link) and
/// cut it all the way round.
///
/// The cut follows the contour's own direction (outer clockwise, holes counter-clockwise) from
/// `pierce_point` back to `pierce_point`; the move to the next step starts there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CutStep {
    /// The contour that is cut.
    pub contour: ContourRef,
    /// Where the cut of the contour starts and ends (where the torch pierces, unless the step
    /// is entered by a link); lies on the contour.
    pub pierce_point: Point,
    /// How the tool gets there; routes written before chain cutting have no such field and
    /// read as [`Entry::Pierce`].
    #[serde(default)]
    pub entry: Entry,
    /// The full-route elements (pierce point M off the contour, leads, the cut on the
    /// equidistant, switch-off point M*) when the route is cut with kerf and leads; `None` in
    /// the idealised model, where the tool pierces and switches off at `pierce_point` on the
    /// contour. With leads, `pierce_point` is the contour point the entry lies over. Routes
    /// written before leads have no such field. (Always written, even as `null`: the worker's
    /// bincode transport is not self-describing and cannot skip fields.)
    #[serde(default)]
    pub leads: Option<StepLeads>,
}

impl CutStep {
    /// A step entered the usual way: idle move, then a pierce at `pierce_point`.
    pub fn pierced(contour: ContourRef, pierce_point: Point) -> CutStep {
        CutStep {
            contour,
            pierce_point,
            entry: Entry::Pierce,
            leads: None,
        }
    }

    /// Whether the torch pierces at this step (it does unless the step is entered by a link).
    pub fn is_pierced(&self) -> bool {
        matches!(self.entry, Entry::Pierce)
    }

    /// Where the tool is switched on for this step: the pierce point M of its leads, or
    /// `pierce_point` on the contour in the idealised model.
    pub fn switch_on_point(&self) -> Point {
        self.leads.as_ref().map_or(self.pierce_point, |l| l.pierce)
    }

    /// Where the tool leaves this step: the switch-off point M* of its leads, or
    /// `pierce_point` (where a closed contour's cut ends) in the idealised model.
    pub fn switch_off_point(&self) -> Point {
        self.leads
            .as_ref()
            .map_or(self.pierce_point, |l| l.switch_off)
    }

    /// The micro-joints of this step (none in the idealised model).
    pub fn tabs(&self) -> &[crate::Tab] {
        self.leads.as_ref().map_or(&[], |l| l.tabs.as_slice())
    }

    /// Tool-on length of this step on `contour` (its own contour): the perimeter, or with
    /// leads the lead-in, the equidistant, the overcut and the lead-out.
    pub fn cut_length_on(&self, contour: &Contour) -> f64 {
        match &self.leads {
            None => contour.perimeter(),
            Some(leads) => match crate::equidistant(contour, leads.offset) {
                Ok(eq) => leads.cut_length(&eq),
                Err(_) => f64::NAN,
            },
        }
    }
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
    /// Time of one pierce at the sheet's edge, s (`None`: the pierce time, so runs without
    /// edge piercing, and old profiles, are unchanged).
    #[serde(default)]
    pub edge_pierce_time: Option<f64>,
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
            edge_pierce_time: None,
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

    /// Time of one pierce at the sheet's edge, s: `edge_pierce_time`, else the pierce time.
    pub fn edge_pierce_seconds(&self) -> f64 {
        self.edge_pierce_time.unwrap_or(self.pierce_time)
    }

    /// Time of `pierces` pierces of which `edge` are at the sheet's edge, s.
    pub fn pierce_seconds(&self, pierces: usize, edge: usize) -> f64 {
        let edge = edge.min(pierces);
        (pierces - edge) as f64 * self.pierce_time + edge as f64 * self.edge_pierce_seconds()
    }

    /// Cost `F = L_on·C_on + L_off·C_off + N·C_pt`, lengths in millimetres (prices per metre).
    pub fn cost(&self, cut_length: f64, idle_length: f64, pierces: usize) -> f64 {
        cut_length * 1e-3 * self.cut_price_per_metre
            + idle_length * 1e-3 * self.idle_price_per_metre
            + pierces as f64 * self.pierce_price
    }
}

/// What a solver minimises, or what routes are compared by, under the machine's model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Objective {
    /// Machining time (formula 1.2).
    #[default]
    Time,
    /// Cost (formula 1.3).
    Cost,
}

impl Objective {
    /// The unit of this objective's value (bounds on it say so).
    pub fn unit(self) -> cutroute_anytime::CostUnit {
        match self {
            Objective::Time => cutroute_anytime::CostUnit::Seconds,
            Objective::Cost => cutroute_anytime::CostUnit::Cost,
        }
    }

    /// The objective's value for a route of these lengths (mm) and pierces.
    pub fn value(
        self,
        machine: &MachineParameters,
        cut_length: f64,
        idle_length: f64,
        pierces: usize,
    ) -> f64 {
        match self {
            Objective::Time => machine.time(cut_length, idle_length, pierces),
            Objective::Cost => machine.cost(cut_length, idle_length, pierces),
        }
    }

    /// The short name used on the command line: `time` or `cost`.
    pub fn name(self) -> &'static str {
        match self {
            Objective::Time => "time",
            Objective::Cost => "cost",
        }
    }
}

/// One way a route fails to be a valid continuous cutting route of a nest.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum RouteError {
    /// A step names a contour the nest does not have.
    #[error("step {step} cuts {contour}, which the nest does not have")]
    UnknownContour {
        /// Index of the step.
        step: usize,
        /// The reference.
        contour: ContourRef,
    },
    /// A contour is cut more than once.
    #[error("{contour} is cut twice: at steps {first_step} and {second_step}")]
    CutTwice {
        /// The contour.
        contour: ContourRef,
        /// Its first cut.
        first_step: usize,
        /// Its repeated cut.
        second_step: usize,
    },
    /// A contour is never cut.
    #[error("{contour} is never cut")]
    NotCut {
        /// The contour.
        contour: ContourRef,
    },
    /// A pierce point is off its contour.
    #[error("step {step} pierces {contour} {distance} mm away from it (tolerance {tolerance} mm)")]
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
    /// A step is pierced in the kerf of a contour that is not cut before it (or not cut with
    /// leads).
    #[error(
        "step {step} on {contour} is pierced in the kerf of {kerf_of}, which is not cut before it"
    )]
    KerfPierceBeforeCut {
        /// Index of the step.
        step: usize,
        /// Its contour.
        contour: ContourRef,
        /// The contour whose kerf it names.
        kerf_of: ContourRef,
    },
    /// A contour is cut after a contour that contains it.
    #[error(
        "{inner} (step {inner_step}) lies inside {outer} (step {outer_step}) but is cut after it"
    )]
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
    /// A step's full-route elements break the model (M ∉ G_M, M* ∉ G_M*, a lead closer than
    /// kerf/2 to a contour, the entry off the equidistant).
    #[error("step {step} on {contour}: {problem}")]
    Lead {
        /// Index of the step.
        step: usize,
        /// Its contour.
        contour: ContourRef,
        /// What is wrong.
        problem: LeadProblem,
    },
    /// The cut of a step on its equidistant (the overcut included, the tabs' gaps not) comes
    /// closer than kerf/2 to a contour: the kerf eats into that contour's part (parts closer
    /// than the kerf). Reported once per pair of contours, at the first step that cuts one of
    /// them.
    #[error("the cut of {contour} (step {step}) comes {distance} mm from {other} near ({x}, {y}), closer than kerf/2 = {required} mm (the contours are {gap} mm apart)")]
    KerfOverlap {
        /// Index of the step.
        step: usize,
        /// The contour it cuts.
        contour: ContourRef,
        /// The contour its kerf eats into.
        other: ContourRef,
        /// The least distance from the cut to `other`, mm.
        distance: f64,
        /// kerf/2, mm.
        required: f64,
        /// The gap between the two contours themselves, mm.
        gap: f64,
        /// A point of the cut near where it comes closest, x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// With a kerf, the contour of a step and another contour touch or lie on one another (a
    /// part in a hole of its own shape, stacked parts), which [`RouteError::KerfOverlap`] does
    /// not see where the cut keeps kerf/2 on the other's far side: one of the two comes out a
    /// kerf off its line. Reported once per pair of contours, at the first step that cuts one.
    #[error(
        "{contour} (step {step}) and {other} {} near ({x}, {y}): with a kerf one of them is cut off its line",
        if *on_one_another { "lie on one another" } else { "touch" }
    )]
    ContoursTouch {
        /// Index of the step.
        step: usize,
        /// The contour it cuts.
        contour: ContourRef,
        /// The contour it touches or lies on.
        other: ContourRef,
        /// Whether the two lie wholly on one another (else they touch).
        on_one_another: bool,
        /// A point of the step's contour near where they touch, x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// The first step is entered by a link, but there is no previous cut to link from.
    #[error("step 0 is entered by a tool-on link, but no contour was cut before it")]
    LinkWithoutPrevious,
    /// A link joins two contours that are not siblings in one scrap region (the sheet or a
    /// hole): it would cut through a part.
    #[error(
        "step {step} links {from:?} to {to:?}, which do not lie side by side in one scrap region"
    )]
    LinkNotBetweenSiblings {
        /// Index of the linked step.
        step: usize,
        /// The contour the link leaves.
        from: ContourRef,
        /// The contour the link enters.
        to: ContourRef,
    },
    /// A link crosses a contour (a part or scrap boundary) away from its two end points.
    #[error("the link into step {step} crosses {contour} at ({x}, {y})")]
    LinkCrossesContour {
        /// Index of the linked step.
        step: usize,
        /// The contour crossed.
        contour: ContourRef,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
    },
    /// A link of a route cut with kerf comes closer than kerf/2 to a contour: the kerf it
    /// burns would eat into that contour.
    #[error("the link into step {step} comes {distance} mm from a contour near ({x}, {y}), closer than kerf/2")]
    LinkTooClose {
        /// Index of the linked step.
        step: usize,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
        /// Its distance to the nearest contour.
        distance: f64,
    },
    /// A piece of a link lies outside the scrap region of the contours it joins (inside a
    /// part, or outside the hole they sit in).
    #[error("the link into step {step} leaves its scrap region near ({x}, {y})")]
    LinkLeavesScrap {
        /// Index of the linked step.
        step: usize,
        /// A point of the link outside the region, x.
        x: f64,
        /// Its y.
        y: f64,
    },
}

impl Route {
    /// A feasible route that needs no solver: every contour pierced at its first vertex, the
    /// deepest contours first (so every hole before the part around it, every part in a hole
    /// before that hole). A baseline for comparisons and a starting point for tests.
    pub fn innermost_first(nest: &Nest, start: Point, finish: Option<Point>) -> Route {
        let forest = nest.containment_forest();
        let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
        refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r)));
        Route {
            start,
            steps: refs
                .into_iter()
                .filter_map(|r| {
                    let first = nest.contour(r)?.vertices.first()?.point;
                    Some(CutStep::pierced(r, first))
                })
                .collect(),
            finish,
        }
    }

    /// The points the head passes between contours: start, every step's pierce point (where
    /// its cut starts), finish (if any). Consecutive points are joined by idle moves except
    /// where a step is entered by a link (see [`Route::idle_moves`]).
    pub fn idle_points(&self) -> impl Iterator<Item = Point> + '_ {
        std::iter::once(self.start)
            .chain(self.steps.iter().map(|s| s.switch_on_point()))
            .chain(self.finish)
    }

    /// The straight idle moves `(from, to)`: to every pierced step from where the head stands
    /// (the start, or the previous step's pierce point, where its cut ends), and to the finish.
    pub fn idle_moves(&self) -> Vec<(Point, Point)> {
        let mut moves = Vec::with_capacity(self.steps.len() + 1);
        let mut at = self.start;
        for s in &self.steps {
            if s.is_pierced() {
                moves.push((at, s.switch_on_point()));
            }
            // The head crosses each tab's gap with the torch off.
            moves.extend(s.tabs().iter().map(|tab| (tab.from, tab.to)));
            at = s.switch_off_point();
        }
        if let Some(finish) = self.finish {
            moves.push((at, finish));
        }
        moves
    }

    /// Total length of the straight idle moves, mm.
    pub fn idle_length(&self) -> f64 {
        self.idle_moves().iter().map(|(a, b)| a.distance(*b)).sum()
    }

    /// The whole polyline of the link into step `step`: the previous step's pierce point, the
    /// link's corners, this step's pierce point. `None` when the step is pierced, does not
    /// exist, or is the first step.
    pub fn link_path(&self, step: usize) -> Option<Vec<Point>> {
        let s = self.steps.get(step)?;
        let Entry::Link(corners) = &s.entry else {
            return None;
        };
        let previous = self.steps.get(step.checked_sub(1)?)?;
        let mut path = Vec::with_capacity(corners.len() + 2);
        path.push(previous.switch_off_point());
        path.extend_from_slice(corners);
        path.push(s.switch_on_point());
        Some(path)
    }

    /// Total length of the tool-on links between chained contours, mm.
    pub fn link_length(&self) -> f64 {
        (0..self.steps.len())
            .filter_map(|i| self.link_path(i))
            .map(|p| p.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>())
            .sum()
    }

    /// Number of pierces: one per step not entered by a link, and one after every tab.
    pub fn pierce_count(&self) -> usize {
        self.steps.iter().filter(|s| s.is_pierced()).count()
            + self.steps.iter().map(|s| s.tabs().len()).sum::<usize>()
    }

    /// The pierces of [`Route::pierce_count`] made at the sheet's edge (edge-pierced steps;
    /// the pierces after tabs are in the sheet).
    pub fn edge_pierce_count(&self) -> usize {
        self.steps
            .iter()
            .filter(|s| s.is_pierced() && s.leads.as_ref().is_some_and(|l| l.edge_pierce))
            .count()
    }

    /// The pierces of [`Route::pierce_count`] made in the open kerf of a contour cut earlier
    /// (kerf-pierced steps; priced like edge pierces).
    pub fn kerf_pierce_count(&self) -> usize {
        self.steps
            .iter()
            .filter(|s| s.is_pierced() && s.leads.as_ref().is_some_and(|l| l.kerf_pierce.is_some()))
            .count()
    }

    /// Total cut length: the perimeters of the contours cut (with leads: the equidistants,
    /// overcuts and leads) plus the tool-on links, mm. Unknown contours count 0 (see
    /// [`Route::validate`]).
    pub fn cut_length(&self, nest: &Nest) -> f64 {
        self.steps
            .iter()
            .filter_map(|s| Some(s.cut_length_on(nest.contour(s.contour)?)))
            .sum::<f64>()
            + self.link_length()
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
    /// each pierce point within `tolerance` mm of its contour, inner contours cut before
    /// every contour containing them, and every tool-on link joining two siblings of one scrap
    /// region (children of the sheet or of one hole) without crossing any contour or leaving
    /// that region. With leads, each step's elements are checked by
    /// [`LeadFitter::problems_linked`], and its cut on the equidistant keeps kerf/2 (less
    /// `tolerance`) from every other contour ([`RouteError::KerfOverlap`], the test
    /// [`PathRoute::problems`](crate::PathRoute::problems) holds every tool-on span to).
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
            if let Some(leads) = &s.leads {
                let fitter = LeadFitter::with_forest(nest, forest, leads.rules());
                // In a chain the link's ends are no pierce or switch-off: the link itself is
                // checked below (kerf/2 from every contour included).
                let linked_in = !s.is_pierced();
                let linked_out = self.steps.get(step + 1).is_some_and(|n| !n.is_pierced());
                problems.extend(
                    fitter
                        .problems_linked(s.contour, leads, linked_in, linked_out)
                        .into_iter()
                        .map(|problem| RouteError::Lead {
                            step,
                            contour: s.contour,
                            problem,
                        }),
                );
                // A kerf pierce needs its kerf cut before: the contours cut so far are those
                // with a step already.
                if let Some(kerf_of) = leads.kerf_pierce.filter(|_| !linked_in) {
                    let cut_at = forest
                        .index_of(kerf_of)
                        .and_then(|k| step_of[k])
                        .filter(|&j| j < step);
                    let cut = cut_at.and_then(|j| self.steps[j].leads.as_ref());
                    match cut {
                        None => problems.push(RouteError::KerfPierceBeforeCut {
                            step,
                            contour: s.contour,
                            kerf_of,
                        }),
                        Some(cut) => problems.extend(
                            fitter
                                .kerf_pierce_problem(kerf_of, cut, leads.pierce)
                                .map(|problem| RouteError::Lead {
                                    step,
                                    contour: s.contour,
                                    problem,
                                }),
                        ),
                    }
                }
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
        for step in 0..self.steps.len() {
            if let Entry::Link(_) = self.steps[step].entry {
                check_link(self, step, nest, forest, tolerance, &mut problems);
            }
        }
        problems.extend(self.kerf_overlap_problems(nest, tolerance));
        problems
    }

    /// The steps whose cut on the equidistant comes closer than kerf/2 (less `tolerance`) to
    /// another contour, once per pair of contours (see [`RouteError::KerfOverlap`]), and those
    /// whose contour touches or lies on another ([`RouteError::ContoursTouch`]). Steps without
    /// leads (the idealised model: no kerf) and contours without an equidistant (reported as
    /// the entry off the equidistant) are not checked here. Part of [`Route::problems`].
    pub fn kerf_overlap_problems(&self, nest: &Nest, tolerance: f64) -> Vec<RouteError> {
        let mut index: Option<ContourSpans> = None;
        let mut seen = std::collections::BTreeSet::new();
        let mut problems = Vec::new();
        for (step, s) in self.steps.iter().enumerate() {
            let Some(leads) = s.leads.as_ref().filter(|l| l.offset > 0.0) else {
                continue;
            };
            let Some(eq) = nest
                .contour(s.contour)
                .and_then(|c| crate::equidistant(c, leads.offset).ok())
            else {
                continue;
            };
            let cut: Vec<Span> = leads
                .equidistant_pieces(&eq, 0.0)
                .into_iter()
                .flatten()
                .collect();
            let index = index.get_or_insert_with(|| ContourSpans::new(nest));
            // Its own contour is kept kerf/2 off by the offset itself (to the offset's
            // precision, which can be 1e-4 mm on files' runs of tiny segments, where the
            // offset's cleanup moves vertices): the pairs here are neighbours.
            seen.insert((s.contour, s.contour));
            problems.extend(
                cut_overlaps(index, s.contour, &cut, leads.offset, tolerance, &mut seen)
                    .into_iter()
                    .map(|o| RouteError::KerfOverlap {
                        step,
                        contour: o.contour,
                        other: o.other,
                        distance: o.distance,
                        required: o.required,
                        gap: o.gap,
                        x: o.at.x,
                        y: o.at.y,
                    }),
            );
            // Contours on one another escape the test above (the cut keeps kerf/2 on the
            // other's far side).
            let own: Vec<Span> = nest
                .contour(s.contour)
                .map_or(Vec::new(), |c| c.spans().collect());
            problems.extend(
                touching(index, s.contour, &own, leads.offset, tolerance, &mut seen)
                    .into_iter()
                    .map(|o| RouteError::ContoursTouch {
                        step,
                        contour: o.contour,
                        other: o.other,
                        on_one_another: o.on_one_another,
                        x: o.at.x,
                        y: o.at.y,
                    }),
            );
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

/// Whether the children of `parent` lie in scrap: children of the sheet (`None`) and of holes
/// (odd depth: a part's outer contour has even depth, its holes odd). Children of a part's
/// outer contour are its holes, which lie in material.
pub fn is_scrap_region(forest: &ContainmentForest, parent: Option<ContourRef>) -> bool {
    match parent {
        None => true,
        Some(p) => forest.depth(p).is_some_and(|d| d % 2 == 1),
    }
}

/// Whether `p` lies in the scrap region of `parent` (see [`is_scrap_region`]): inside the
/// parent (or anywhere for the sheet) and outside every child of the parent.
pub fn in_scrap_region(
    nest: &Nest,
    forest: &ContainmentForest,
    parent: Option<ContourRef>,
    p: Point,
) -> bool {
    let inside_parent = match parent {
        None => true,
        Some(r) => nest.contour(r).is_some_and(|c| c.contains(p)),
    };
    let children: &[ContourRef] = match parent {
        None => forest.roots(),
        Some(r) => forest.children(r),
    };
    inside_parent
        && !children
            .iter()
            .any(|&c| nest.contour(c).is_some_and(|c| c.contains(p)))
}

/// The problems of the link into step `step` (see [`Route::problems`]); none for a pierced
/// step.
pub(crate) fn link_problems(
    route: &Route,
    step: usize,
    nest: &Nest,
    forest: &ContainmentForest,
    tolerance: f64,
) -> Vec<RouteError> {
    let mut problems = Vec::new();
    if route.steps.get(step).is_some_and(|s| !s.is_pierced()) {
        check_link(route, step, nest, forest, tolerance, &mut problems);
    }
    problems
}

/// The checks of one link (see [`Route::problems`]). Independent of how links are built: it
/// tests the polyline against every contour of the nest; with kerf (the steps it joins carry
/// leads) it also keeps kerf/2 from every contour.
fn check_link(
    route: &Route,
    step: usize,
    nest: &Nest,
    forest: &ContainmentForest,
    tolerance: f64,
    problems: &mut Vec<RouteError>,
) {
    let Some(path) = route.link_path(step) else {
        problems.push(RouteError::LinkWithoutPrevious);
        return;
    };
    let (from, to) = (route.steps[step - 1].contour, route.steps[step].contour);
    let (Some(_), Some(_)) = (forest.index_of(from), forest.index_of(to)) else {
        return; // reported as an unknown contour
    };
    let parent = forest.parent(to);
    if forest.parent(from) != parent || from == to || !is_scrap_region(forest, parent) {
        problems.push(RouteError::LinkNotBetweenSiblings { step, from, to });
        return;
    }
    let half_kerf = [&route.steps[step - 1], &route.steps[step]]
        .iter()
        .filter_map(|s| s.leads.as_ref().map(|l| l.offset))
        .fold(0.0, f64::max);
    let (first, last) = (path[0], path[path.len() - 1]);
    let at_an_end = |x: Point| x.distance(first) <= tolerance || x.distance(last) <= tolerance;
    for w in path.windows(2) {
        let (a, b) = (w[0], w[1]);
        if !(a.is_finite() && b.is_finite()) {
            problems.push(RouteError::LinkLeavesScrap {
                step,
                x: b.x,
                y: b.y,
            });
            return;
        }
        let reach = crate::BoundingBox::from_corners(a, b).expanded(tolerance);
        for r in nest.contour_refs() {
            let Some(c) = nest.contour(r) else { continue };
            if !c.bounding_box().intersects(&reach) {
                continue;
            }
            if let Some(x) = c
                .segment_crossings(a, b)
                .into_iter()
                .find(|x| !at_an_end(x.point))
            {
                problems.push(RouteError::LinkCrossesContour {
                    step,
                    contour: r,
                    x: x.point.x,
                    y: x.point.y,
                });
                return;
            }
        }
        // No crossing inside the piece, so one interior point tells on which side of every
        // contour the whole piece lies.
        let probe = a.midpoint(b);
        if a.distance(b) > tolerance && !in_scrap_region(nest, forest, parent, probe) {
            problems.push(RouteError::LinkLeavesScrap {
                step,
                x: probe.x,
                y: probe.y,
            });
            return;
        }
        if half_kerf > 0.0 {
            // The exact distance from the piece to every span near it.
            let piece = crate::Span::line(a, b);
            let near = crate::BoundingBox::from_corners(a, b).expanded(half_kerf);
            for r in nest.contour_refs() {
                let Some(c) = nest.contour(r) else { continue };
                if !c.bounding_box().intersects(&near) {
                    continue;
                }
                for span in c.spans() {
                    let distance = piece.distance_to_span(&span);
                    if distance < half_kerf - tolerance {
                        let at = span.nearest_point(piece.nearest_point(span.start).point);
                        let x = piece.nearest_point(at.point).point;
                        problems.push(RouteError::LinkTooClose {
                            step,
                            x: x.x,
                            y: x.y,
                            distance,
                        });
                        return;
                    }
                }
            }
        }
    }
}
