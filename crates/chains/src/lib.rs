//! Chain cutting (Verkhoturov–Tarasenko): post-optimise a cutting route so that sibling
//! contours lying in one scrap region are cut from a single pierce, joined by tool-on links.
//!
//! A pierce costs as much as tens of metres of idle travel; a short tool-on link between two
//! neighbouring contours costs less than the pierce it saves. A link from contour A to contour
//! B pays when `C_on·n < C_pt + C_off·d` (n the link's length, d the straight idle distance it
//! replaces); for a straight link this is the paper's `n < C_pt / (C_on − C_off)`
//! ([`profitable_link_length`]).
//!
//! What [`chain_route`] does, per scrap region (the sheet, or a hole of a part: never the holes
//! of one part, which lie in material):
//! 1. groups the region's contours whose straight distance is below the threshold (connected
//!    components of the "close" graph; the paper's *SelectProfitable*),
//! 2. orders each group by an open-path TSP from the point the tool comes from to the point it
//!    goes to next (exact Held–Karp up to [`ChainOptions::exact_order_limit`] members, 2-opt and
//!    Or-opt beyond), weighing links at `C_on` and the idle moves at its ends at `C_off`,
//! 3. places the pierce points to minimise that weighted length (the paper's midpoint rule as a
//!    start, then coordinate descent, each point the exact minimiser on its contour's spans),
//!    then refines them against the true link costs (a chain leaves a contour where it entered
//!    it, so the contour itself is often the obstacle: corners are tried),
//! 4. routes every link on the shortest path inside the region that crosses no contour
//!    (visibility graph over the obstacles' corners and arc tangent points), keeping a link only
//!    when it pays and cutting the chain otherwise,
//! 5. moves the chain to where its last member stood (every member's inner contours are cut
//!    earlier there, and the parent still after) or, if cheaper, to the place in the window
//!    between the members' inner contours and their parent where the chain is the smallest
//!    idle detour, and keeps the change only if the route's cost drops.
//!
//! The printed pseudo-code's defects (`docs/science/chain-cutting-and-ccp-paper.md` §A.6.3)
//! are avoided by construction: the route is rebuilt from scratch for each group (no growing
//! `resultPath`), groups are processed once each instead of by a moving index, the link test
//! uses the obstacle-avoiding length between consecutive chain members only, the tool comes from
//! the last non-member before the chain, and only children of the sheet or of a hole are chained.
//!
//! ```
//! use cutroute_chains::{chain_route, ChainOptions};
//! use cutroute_geometry::{Contour, ContourRef, CutStep, Nest, Part, Point, Route, Vertex};
//! // Three 10 mm squares 5 mm apart on the sheet, each pierced on its own.
//! let square = |x: f64| Contour::new(vec![
//!     Vertex::line(x, 0.0), Vertex::line(x, 10.0), Vertex::line(x + 10.0, 10.0), Vertex::line(x + 10.0, 0.0),
//! ]);
//! let nest = Nest { sheet: None, parts: (0..3).map(|i| Part {
//!     name: format!("p{i}"), contours: vec![square(15.0 * i as f64)] }).collect() };
//! let route = Route {
//!     start: Point::new(-10.0, 5.0),
//!     steps: (0..3).map(|i| CutStep::pierced(
//!         ContourRef { part: i, contour: 0 }, Point::new(15.0 * i as f64, 5.0))).collect(),
//!     finish: None,
//! };
//! let chained = chain_route(&nest, &route, &ChainOptions::default()).unwrap();
//! assert_eq!(chained.route.pierce_count(), 1);
//! // 5 mm from the first square to a corner of the middle one, then over its top to the
//! // third: about 5 + 15 mm (the middle square is left where it was entered).
//! assert!((chained.route.link_length() - 20.0).abs() < 0.5);
//! chained.route.validate(&nest, 1e-6).unwrap();
//! assert!(chained.report.cost_after < chained.report.cost_before);
//! ```
#![deny(missing_docs)]

mod order;
mod region;

use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit};
use cutroute_geometry::float::Libm;
use cutroute_geometry::{
    is_scrap_region, BoundingBox, ContainmentForest, Contour, ContourRef, CutStep, Entry,
    MachineParameters, Nest, Point, Route, RouteError,
};
use thiserror::Error;
use web_time::{Duration, Instant};

pub use cutroute_anytime::Status;

use region::Region;

/// Settings of [`chain_route`].
#[derive(Clone, Debug, PartialEq)]
pub struct ChainOptions {
    /// Prices (and speeds, for the reported time) of the cost model; links pay by these.
    pub machine: MachineParameters,
    /// Chains of up to this many contours are ordered exactly (Held–Karp, at most 16).
    pub exact_order_limit: usize,
    /// How far (mm) link corners keep from the contours they bend round.
    pub clearance_mm: f64,
    /// Rounds of pierce-point coordinate descent per chain (straight-line lengths).
    pub descent_rounds: usize,
    /// Rounds of refinement against true (obstacle-avoiding) link lengths, trying contour
    /// corners as pierce points; 0 skips it.
    pub refinement_rounds: usize,
}

/// Corners of a contour tried per refinement round (those nearest its chain neighbours).
const REFINEMENT_CANDIDATES: usize = 12;

impl Default for ChainOptions {
    fn default() -> Self {
        ChainOptions {
            machine: MachineParameters::default(),
            exact_order_limit: 10,
            clearance_mm: 0.05,
            descent_rounds: 4,
            refinement_rounds: 2,
        }
    }
}

/// Why a route cannot be chained.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ChainError {
    /// The route given is not a valid route of the nest.
    #[error("the route to chain is invalid: {0}")]
    InvalidRoute(RouteError),
    /// A price is negative or not a number.
    #[error("prices must be finite and non-negative (idle {idle}, cut {cut}, pierce {pierce})")]
    InvalidPrices {
        /// Price per metre of idle travel.
        idle: f64,
        /// Price per metre of cut.
        cut: f64,
        /// Price per pierce.
        pierce: f64,
    },
}

/// What chaining changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChainReport {
    /// Pierces of the route given.
    pub pierces_before: usize,
    /// Pierces of the chained route.
    pub pierces_after: usize,
    /// Chains of two or more contours in the result.
    pub chains: usize,
    /// Total length of the tool-on links, mm.
    pub link_length: f64,
    /// Idle length before and after, mm.
    pub idle_before: f64,
    /// Idle length after, mm.
    pub idle_after: f64,
    /// Cost of the route given (formula 1.3, perimeters included).
    pub cost_before: f64,
    /// Cost of the chained route.
    pub cost_after: f64,
    /// Machine time of the route given, s.
    pub time_before: f64,
    /// Machine time of the chained route, s.
    pub time_after: f64,
}

/// The chained route and what changed.
#[derive(Clone, Debug, PartialEq)]
pub struct Chained {
    /// The route: chains are runs of steps entered by [`Entry::Link`].
    pub route: Route,
    /// Pierces saved, cost and time before and after.
    pub report: ChainReport,
}

/// The paper's condValue in mm: a straight tool-on link shorter than this costs less than the
/// pierce plus idle move it replaces, `C_pt / (C_on − C_off)` with prices per metre. Infinite
/// when cutting is no dearer than idling.
pub fn profitable_link_length(machine: &MachineParameters) -> f64 {
    let extra = machine.cut_price_per_metre - machine.idle_price_per_metre;
    if extra > 0.0 {
        1000.0 * machine.pierce_price / extra
    } else {
        f64::INFINITY
    }
}

/// One material of the paper's Table 1 (waterjet prices): name and prices per metre / pierce.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Name and thickness.
    pub name: &'static str,
    /// Idle travel, per metre (C_off).
    pub idle_price_per_metre: f64,
    /// Cut, per metre (C_on).
    pub cut_price_per_metre: f64,
    /// Pierce (C_pt).
    pub pierce_price: f64,
}

impl Material {
    /// `machine` with this material's prices.
    pub fn priced(&self, machine: &MachineParameters) -> MachineParameters {
        MachineParameters {
            idle_price_per_metre: self.idle_price_per_metre,
            cut_price_per_metre: self.cut_price_per_metre,
            pierce_price: self.pierce_price,
            ..*machine
        }
    }
}

/// The three materials of Table 1 of Verkhoturov–Tarasenko.
pub const TABLE1_MATERIALS: [Material; 3] = [
    Material {
        name: "granite 30 mm",
        idle_price_per_metre: 0.1,
        cut_price_per_metre: 30.0,
        pierce_price: 5.0,
    },
    Material {
        name: "steel 20 mm",
        idle_price_per_metre: 0.1,
        cut_price_per_metre: 35.0,
        pierce_price: 7.0,
    },
    Material {
        name: "marble 30 mm",
        idle_price_per_metre: 0.1,
        cut_price_per_metre: 20.0,
        pierce_price: 5.0,
    },
];

/// Chain the contours of `route` (any valid route of `nest`; links it already has are
/// dropped and rebuilt). The result is valid whenever the input is, and never costs more.
pub fn chain_route(
    nest: &Nest,
    route: &Route,
    options: &ChainOptions,
) -> Result<Chained, ChainError> {
    let mut groups = Groups::new(nest, route, options)?;
    while !groups.step_within(nest, options, &|| false, &|| false) {}
    Ok(groups.finish(nest, options))
}

/// [`chain_route`] in resumable slices, so a caller that must stay responsive (the app's
/// worker answers Stop between slices) can interleave: [`Chaining::new`], then
/// [`Chaining::step`] (the [`AnytimeSolver`] contract) until it is done, then
/// [`Chaining::finish`]. A slice ends between pieces of a group of close contours (a row of its
/// distances, its order, one contour's refinement or link) and the next step resumes it: where
/// slices end does not change the route. One group of a big scrap region can take seconds
/// (seven.dbs: 20 s), so with [`Chaining::stop_at`] the group under way at that instant is
/// given up ([`Status::Stopped`]) and the route keeps every group done before.
pub struct Chaining {
    nest: Nest,
    options: ChainOptions,
    deadline: Option<Instant>,
    groups: Groups,
    /// Set once the work is done: finished, or stopped at the deadline.
    status: Status,
}

impl Chaining {
    /// Checks the prices and the route (as [`chain_route`] does) and plans the work.
    pub fn new(nest: &Nest, route: &Route, options: &ChainOptions) -> Result<Self, ChainError> {
        Ok(Chaining {
            groups: Groups::new(nest, route, options)?,
            nest: nest.clone(),
            options: options.clone(),
            deadline: None,
            status: Status::Running,
        })
    }

    /// Gives up the group under way at `deadline` (a caller's time limit).
    pub fn stop_at(&mut self, deadline: Instant) {
        self.deadline = Some(deadline);
    }

    /// Tries groups of close contours for about `budget` (a slice ends between pieces of a
    /// group): [`Status::Finished`] when every group is tried, [`Status::Stopped`] when the
    /// deadline of [`Chaining::stop_at`] gave one up.
    pub fn step(&mut self, budget: Duration) -> Status {
        if self.status.is_done() {
            return self.status;
        }
        let slice_end = Instant::now().checked_add(budget);
        let deadline = self.deadline;
        let aborted = std::cell::Cell::new(false);
        let done = self.groups.step_within(
            &self.nest,
            &self.options,
            &|| slice_end.is_some_and(|end| Instant::now() >= end),
            &|| {
                let over = deadline.is_some_and(|end| Instant::now() >= end);
                aborted.set(aborted.get() || over);
                over
            },
        );
        if done {
            self.status = if aborted.get() {
                Status::Stopped
            } else {
                Status::Finished {
                    proven_optimal: false,
                }
            };
        }
        if done {
            self.status
        } else {
            Status::Running
        }
    }

    /// The chained route and its report (all groups tried or not: the route is valid after
    /// every group).
    pub fn finish(self) -> Chained {
        self.groups.finish(&self.nest, &self.options)
    }
}

/// The contract of every solver: the route chained so far (valid after every group) and its
/// cost at the options' prices; no lower bound.
impl AnytimeSolver for Chaining {
    type Solution = Route;

    fn step(&mut self, budget: Duration) -> Status {
        Chaining::step(self, budget)
    }

    fn best(&self) -> Option<Route> {
        Some(self.groups.current.clone())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            upper: Some(self.groups.current_cost),
            lower: None,
            unit: CostUnit::Cost,
        }
    }
}

/// The work of [`Chaining`] on a nest and options held by the caller.
struct Groups {
    original: Route,
    current: Route,
    current_cost: f64,
    forest: ContainmentForest,
    scale: f64,
    regions: Vec<(Option<ContourRef>, Vec<ContourRef>)>,
    /// The region being worked on and its groups still to try (reversed: next is last).
    region: usize,
    groups: Option<Vec<Vec<ContourRef>>>,
    /// The region's close groups being found, when a slice ended inside the sweep.
    grouping: Option<CloseGroups>,
    /// The group under way, when a slice ended inside it.
    work: Option<GroupWork>,
}

impl Groups {
    /// Checks the prices and the route (as [`chain_route`] does) and plans the work.
    fn new(nest: &Nest, route: &Route, options: &ChainOptions) -> Result<Self, ChainError> {
        let m = &options.machine;
        let prices = [
            m.idle_price_per_metre,
            m.cut_price_per_metre,
            m.pierce_price,
        ];
        if prices.iter().any(|p| !(p.is_finite() && *p >= 0.0)) {
            return Err(ChainError::InvalidPrices {
                idle: prices[0],
                cut: prices[1],
                pierce: prices[2],
            });
        }
        let forest = nest.containment_forest();
        let scale = nest.scale();
        let tolerance = 1e-6 * scale;
        if let Some(e) = route.problems(nest, &forest, tolerance).into_iter().next() {
            return Err(ChainError::InvalidRoute(e));
        }
        let current = Route {
            steps: route
                .steps
                .iter()
                .map(|s| CutStep::pierced(s.contour, s.pierce_point))
                .collect(),
            ..route.clone()
        };
        let current_cost = current.cost(nest, m);
        let regions = scrap_regions(nest, &forest);
        Ok(Groups {
            original: route.clone(),
            current,
            current_cost,
            forest,
            scale,
            regions,
            region: 0,
            groups: None,
            grouping: None,
            work: None,
        })
    }

    /// Tries groups of close contours until all are done (`true`) or `stop()` says so after a
    /// piece of a group (`false`: call again; the group goes on from there), or `abort()` says
    /// so, inside a group too (between its contours): the group under way is left as it was,
    /// chaining ends (`true`) and the route keeps every group done before.
    fn step_within(
        &mut self,
        nest: &Nest,
        options: &ChainOptions,
        stop: &dyn Fn() -> bool,
        abort: &dyn Fn() -> bool,
    ) -> bool {
        let m = &options.machine;
        let context = Context {
            nest,
            forest: &self.forest,
            machine: m,
            options,
            threshold: profitable_link_length(m),
            scale: self.scale,
        };
        while self.region < self.regions.len() {
            let (parent, siblings) = &self.regions[self.region];
            if siblings.len() < 2 {
                self.region += 1;
                continue;
            }
            if self.groups.is_none() {
                // The close groups a piece of the sweep at a time: over the 31,400 top-level
                // contours of a 100,000-contour nest the sweep took 0.8 s.
                if abort() {
                    self.region = self.regions.len();
                    self.grouping = None;
                    return true;
                }
                let grouping = self
                    .grouping
                    .get_or_insert_with(|| CloseGroups::new(nest, siblings));
                match grouping.advance(nest, siblings, context.threshold, &|| stop() || abort()) {
                    Some(found) => {
                        let mut groups: Vec<_> =
                            found.into_iter().filter(|g| g.len() >= 2).collect();
                        groups.reverse();
                        self.groups = Some(groups);
                        self.grouping = None;
                    }
                    None => {
                        if abort() {
                            self.region = self.regions.len();
                            self.grouping = None;
                            return true;
                        }
                        return false;
                    }
                }
            }
            let groups = self.groups.as_mut().expect("set above");
            let mut work = match self.work.take() {
                Some(work) => work,
                None => {
                    let Some(group) = groups.pop() else {
                        self.groups = None;
                        self.region += 1;
                        continue;
                    };
                    context.start_group(&self.current, group)
                }
            };
            // Far stricter than the checker's tolerance, so every link the region accepts
            // passes `Route::validate` (a crossing near but not at a link's end is a crossing).
            // Rebuilt per slice: cheap (boxes of the siblings), and it borrows the nest.
            let region = Region::new(
                nest,
                *parent,
                siblings,
                options.clearance_mm,
                1e-9 * self.scale,
            );
            let candidate =
                match context.advance_group(&self.current, &mut work, &region, stop, abort) {
                    GroupStatus::Done(candidate) => candidate,
                    GroupStatus::Paused => {
                        self.work = Some(work);
                        return false;
                    }
                    GroupStatus::Aborted => {
                        self.region = self.regions.len();
                        self.groups = None;
                        return true;
                    }
                };
            let cost = candidate.cost(nest, m);
            if cost < self.current_cost - 1e-12 * self.current_cost.abs().max(1.0) {
                self.current = candidate;
                self.current_cost = cost;
            }
            if stop() {
                return self.region >= self.regions.len();
            }
        }
        true
    }

    /// The chained route and its report.
    fn finish(self, nest: &Nest, options: &ChainOptions) -> Chained {
        let m = &options.machine;
        let (route, current) = (self.original, self.current);
        let chains = current
            .steps
            .windows(2)
            .filter(|w| w[0].is_pierced() && !w[1].is_pierced())
            .count();
        let report = ChainReport {
            pierces_before: route.pierce_count(),
            pierces_after: current.pierce_count(),
            chains,
            link_length: current.link_length(),
            idle_before: route.idle_length(),
            idle_after: current.idle_length(),
            cost_before: route.cost(nest, m),
            cost_after: self.current_cost,
            time_before: route.time(nest, m),
            time_after: current.time(nest, m),
        };
        Chained {
            route: current,
            report,
        }
    }
}

/// The scrap regions with their contours: the sheet with the top-level contours, and every
/// hole with the parts placed in it.
fn scrap_regions(
    nest: &Nest,
    forest: &ContainmentForest,
) -> Vec<(Option<ContourRef>, Vec<ContourRef>)> {
    let mut regions = vec![(None, forest.roots().to_vec())];
    for r in nest.contour_refs() {
        if is_scrap_region(forest, Some(r)) && !forest.children(r).is_empty() {
            regions.push((Some(r), forest.children(r).to_vec()));
        }
    }
    regions
}

/// Connected components of the graph joining contours closer than `threshold` (straight
/// distance: a link is never shorter, so farther pairs can never pay), found by a sweep over
/// the members by left edge that pauses between members ([`CloseGroups::advance`]).
#[derive(Clone, Debug)]
struct CloseGroups {
    boxes: Vec<BoundingBox>,
    parent: Vec<usize>,
    /// Members with a box, by left edge.
    by_left: Vec<usize>,
    /// The sweep's next position in `by_left`.
    next: usize,
}

/// Members of a sweep between two looks at the clock.
const SWEEP_PIECE: usize = 64;

impl CloseGroups {
    fn new(nest: &Nest, members: &[ContourRef]) -> Self {
        let boxes: Vec<BoundingBox> = members
            .iter()
            .map(|&r| {
                nest.contour(r)
                    .map_or(BoundingBox::EMPTY, |c| c.bounding_box())
            })
            .collect();
        // Sweep by left edge so only boxes overlapping in x (within the threshold) are compared.
        let mut by_left: Vec<usize> = (0..members.len())
            .filter(|&i| !boxes[i].is_empty())
            .collect();
        by_left.sort_by(|&a, &b| boxes[a].min.x.total_cmp(&boxes[b].min.x));
        CloseGroups {
            parent: (0..members.len()).collect(),
            boxes,
            by_left,
            next: 0,
        }
    }

    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }

    /// Sweeps on until done (the groups, in the order of their roots) or `stop()` says so
    /// between pieces (`None`: call again with the same members). Where it pauses does not
    /// change the groups.
    fn advance(
        &mut self,
        nest: &Nest,
        members: &[ContourRef],
        threshold: f64,
        stop: &dyn Fn() -> bool,
    ) -> Option<Vec<Vec<ContourRef>>> {
        let (boxes, parent, by_left) = (&self.boxes, &mut self.parent, &self.by_left);
        while self.next < by_left.len() {
            let end = (self.next + SWEEP_PIECE).min(by_left.len());
            for k in self.next..end {
                let i = by_left[k];
                for &j in &by_left[k + 1..] {
                    if boxes[j].min.x - boxes[i].max.x >= threshold {
                        break;
                    }
                    if box_distance(&boxes[i], &boxes[j]) >= threshold
                        || Self::find(parent, i) == Self::find(parent, j)
                    {
                        continue;
                    }
                    let (Some(a), Some(b)) = (nest.contour(members[i]), nest.contour(members[j]))
                    else {
                        continue;
                    };
                    if contour_distance(a, b) < threshold {
                        let (ri, rj) = (Self::find(parent, i), Self::find(parent, j));
                        parent[ri] = rj;
                    }
                }
            }
            self.next = end;
            if self.next < by_left.len() && stop() {
                return None;
            }
        }
        let mut groups: std::collections::BTreeMap<usize, Vec<ContourRef>> = Default::default();
        for (i, &member) in members.iter().enumerate() {
            let root = Self::find(parent, i);
            groups.entry(root).or_default().push(member);
        }
        Some(groups.into_values().collect())
    }
}

fn box_distance(a: &BoundingBox, b: &BoundingBox) -> f64 {
    let dx = (a.min.x - b.max.x).max(b.min.x - a.max.x).max(0.0);
    let dy = (a.min.y - b.max.y).max(b.min.y - a.max.y).max(0.0);
    dx.hypot_libm(dy)
}

/// Distance between two disjoint contours: from every vertex and span middle of each to the
/// other. Exact for straight spans (two segments are nearest at an end point of one of them),
/// within the arcs' sagitta between samples otherwise. Spans whose box is farther than the best
/// distance so far are skipped.
fn contour_distance(a: &Contour, b: &Contour) -> f64 {
    let boxed = |c: &Contour| -> Vec<(cutroute_geometry::Span, BoundingBox)> {
        c.spans().map(|s| (s, s.bounding_box())).collect()
    };
    let (spans_a, spans_b) = (boxed(a), boxed(b));
    let mut best = f64::INFINITY;
    for (from, to) in [(&spans_a, &spans_b), (&spans_b, &spans_a)] {
        for (s, _) in from.iter() {
            for p in [s.start, s.point_at(0.5)] {
                for (t, bbox) in to.iter() {
                    if point_box_distance(p, bbox) < best {
                        best = best.min(t.distance_to(p));
                    }
                }
            }
        }
    }
    best
}

fn point_box_distance(p: Point, b: &BoundingBox) -> f64 {
    let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
    let dy = (b.min.y - p.y).max(p.y - b.max.y).max(0.0);
    dx.hypot_libm(dy)
}

/// What every group needs.
struct Context<'a> {
    nest: &'a Nest,
    forest: &'a ContainmentForest,
    machine: &'a MachineParameters,
    options: &'a ChainOptions,
    /// [`profitable_link_length`], mm.
    threshold: f64,
    scale: f64,
}

impl Context<'_> {
    /// Price of a mm of cut and of idle travel.
    fn per_mm(&self) -> (f64, f64) {
        (
            self.machine.cut_price_per_metre * 1e-3,
            self.machine.idle_price_per_metre * 1e-3,
        )
    }

    /// Longest link (mm) that pays instead of a pierce plus an idle move of `straight` mm.
    fn link_reach(&self, straight: f64) -> f64 {
        let (on, off) = self.per_mm();
        let reach = if on > 0.0 {
            (self.machine.pierce_price + off * straight) / on
        } else {
            f64::INFINITY
        };
        // Beyond the nest's size a detour is never the shortest way round anything.
        reach.min(straight + 2.0 * self.scale)
    }

    /// The work of chaining `group` in `current`: the places to try. The chain goes where its
    /// last member stood (the paper's place) and, when another is feasible and cheaper in idle
    /// detour, there too; the cheaper result wins.
    fn start_group(&self, current: &Route, group: Vec<ContourRef>) -> GroupWork {
        // A set, not `group.contains`: the scan below asks it for every step's ancestors, and
        // the sheet of a 100,000-contour nest is one group of 31,400 (1.5 s in one piece).
        let members: std::collections::HashSet<ContourRef> = group.iter().copied().collect();
        let is_member = |c: ContourRef| members.contains(&c);
        let last = current
            .steps
            .iter()
            .rposition(|s| is_member(s.contour))
            .unwrap_or(0);
        let rest: Vec<CutStep> = current
            .steps
            .iter()
            .filter(|s| !is_member(s.contour))
            .cloned()
            .collect();
        // The paper puts the chain where its last member stood ...
        let paper_at = current.steps[..last]
            .iter()
            .filter(|s| !is_member(s.contour))
            .count();
        // ... but any place after every member's inner contours and before their parent is
        // feasible: also try the one where the chain's box is the smallest idle detour.
        let after_inner = rest
            .iter()
            .rposition(|s| self.forest.ancestors(s.contour).any(is_member))
            .map_or(0, |i| i + 1);
        let parent = self.forest.parent(group[0]);
        let before_parent = parent
            .and_then(|p| rest.iter().position(|s| s.contour == p))
            .unwrap_or(rest.len());
        let area = group
            .iter()
            .filter_map(|&r| self.nest.contour(r))
            .fold(BoundingBox::EMPTY, |b, c| b.union(c.bounding_box()));
        let detour = |k: usize| {
            let a = if k > 0 {
                rest[k - 1].pierce_point
            } else {
                current.start
            };
            match rest.get(k).map(|s| s.pierce_point).or(current.finish) {
                Some(b) => {
                    point_box_distance(a, &area) + point_box_distance(b, &area) - a.distance(b)
                }
                None => point_box_distance(a, &area),
            }
        };
        let nearest_at = (after_inner..=before_parent.max(after_inner))
            .min_by(|&a, &b| detour(a).total_cmp(&detour(b)))
            .unwrap_or(paper_at);
        // Tried last to first.
        let mut places = Vec::with_capacity(2);
        if nearest_at != paper_at {
            places.push(nearest_at);
        }
        places.push(paper_at);
        GroupWork {
            group,
            rest,
            places,
            best: None,
            at: None,
        }
    }

    /// Works on `work` (a group of `current`) a piece at a time until it is done (`current`
    /// with the group cut as one chain at its best place), `stop()` says so after a piece
    /// (`Paused`: call again with the same `current`), or `abort()` does (`Aborted`: asked per
    /// contour of the group).
    fn advance_group(
        &self,
        current: &Route,
        work: &mut GroupWork,
        region: &Region,
        stop: &dyn Fn() -> bool,
        abort: &dyn Fn() -> bool,
    ) -> GroupStatus {
        loop {
            if work.at.is_none() {
                let Some(insert_at) = work.places.pop() else {
                    let best = work.best.take();
                    return GroupStatus::Done(best.map_or_else(|| current.clone(), |(_, r)| r));
                };
                work.at = Some(self.start_chain(current, &work.group, &work.rest, insert_at));
            }
            let at = work.at.as_mut().expect("set above");
            match self.advance_chain(current, &work.group, &work.rest, at, region, abort) {
                None => return GroupStatus::Aborted,
                Some(Some(route)) => {
                    work.at = None;
                    let cost = route.cost(self.nest, self.machine);
                    if work.best.as_ref().is_none_or(|(c, _)| cost < *c) {
                        work.best = Some((cost, route));
                    }
                }
                Some(None) => {}
            }
            if stop() {
                return GroupStatus::Paused;
            }
        }
    }

    /// The chain of `group` to be inserted into `rest` (the other steps) at `insert_at`.
    fn start_chain(
        &self,
        current: &Route,
        group: &[ContourRef],
        rest: &[CutStep],
        insert_at: usize,
    ) -> ChainAt {
        let before = if insert_at > 0 {
            rest[insert_at - 1].pierce_point
        } else {
            current.start
        };
        let after = rest
            .get(insert_at)
            .map(|s| s.pierce_point)
            .or(current.finish);
        let n = group.len();
        ChainAt {
            insert_at,
            before,
            after,
            stage: ChainStage::Between {
                i: 0,
                between: Vec::with_capacity(n),
            },
        }
    }

    /// One piece of the chain `at`: a row of the member-to-member costs, the order with the
    /// pierce points' descent, one contour's refinement or one link. `Some(Some(route))`:
    /// `current` with the chain inserted; `Some(None)`: more pieces to go; `None`: `abort()`
    /// said so.
    fn advance_chain(
        &self,
        current: &Route,
        group: &[ContourRef],
        rest: &[CutStep],
        at: &mut ChainAt,
        region: &Region,
        abort: &dyn Fn() -> bool,
    ) -> Option<Option<Route>> {
        let (before, after) = (at.before, at.after);
        let contours: Vec<&Contour> = group
            .iter()
            .map(|&r| self.nest.contour(r).expect("validated route"))
            .collect();
        let (on, off) = self.per_mm();
        let pierce = self.machine.pierce_price;
        let n = group.len();
        let stage = std::mem::replace(&mut at.stage, ChainStage::Taken);
        at.stage = match stage {
            ChainStage::Between { i, mut between } if i < n => {
                // Order: open-path TSP over contour-to-contour distances, a row at a time.
                if abort() {
                    return None;
                }
                let boxes: Vec<BoundingBox> = contours.iter().map(|c| c.bounding_box()).collect();
                // Row i is made here, its first i entries from the rows before (the costs are
                // symmetric): the whole matrix at once was n² zeroes in one piece, 7.9 GB and
                // 7.5 s for the 31,400 contours of a 100,000-contour nest's sheet.
                let mut row: Vec<f64> = between.iter().map(|earlier| earlier[i]).collect();
                row.resize(n, 0.0);
                for j in i + 1..n {
                    let near = box_distance(&boxes[i], &boxes[j]);
                    let d = if near < self.threshold {
                        contour_distance(contours[i], contours[j])
                    } else {
                        near.max(boxes[i].centre().distance(boxes[j].centre()) * 0.5)
                    };
                    row[j] = (on * d).min(pierce + off * d);
                }
                between.push(row);
                ChainStage::Between { i: i + 1, between }
            }
            ChainStage::Between { between, .. } => {
                let enter: Vec<f64> = contours
                    .iter()
                    .map(|c| off * c.distance_to(before))
                    .collect();
                let leave: Vec<f64> = contours
                    .iter()
                    .map(|c| after.map_or(0.0, |a| off * c.distance_to(a)))
                    .collect();
                let order = order::open_path_order(
                    &enter,
                    &leave,
                    &between,
                    self.options.exact_order_limit,
                );
                let chain: Vec<&Contour> = order.iter().map(|&i| contours[i]).collect();

                // Pierce points: the paper's rule (nearest to the middle of before–after) as a
                // start, then coordinate descent on the weighted link + end-idle length.
                let middle = match after {
                    Some(a) => before.midpoint(a),
                    None => before,
                };
                let mut points: Vec<Point> = chain
                    .iter()
                    .map(|c| c.nearest_point(middle).map_or(middle, |p| p.point))
                    .collect();
                for _ in 0..self.options.descent_rounds {
                    for k in 0..n {
                        let mut terms = Vec::with_capacity(2);
                        terms.push(if k == 0 {
                            (before, off)
                        } else {
                            (points[k - 1], on)
                        });
                        if k + 1 < n {
                            terms.push((points[k + 1], on));
                        } else if let Some(a) = after {
                            terms.push((a, off));
                        }
                        points[k] = best_point(chain[k], &terms);
                    }
                }
                ChainStage::Refine {
                    order,
                    points,
                    round: 0,
                    k: 0,
                    trial: None,
                }
            }
            ChainStage::Refine {
                order,
                mut points,
                round,
                k,
                trial,
            } if round < self.options.refinement_rounds => {
                if abort() {
                    return None;
                }
                let ends = (before, after);
                // Point k's refinement a candidate per piece: each costs two obstacle-avoiding
                // links, and a contour of a big scrap region took up to a second in one piece.
                let trial = match trial {
                    None => {
                        let candidates =
                            self.refine_candidates(contours[order[k]], &points, k, ends);
                        let here = self.refine_cost(points[k], &points, k, ends, region);
                        Some(Trial {
                            candidates,
                            next: 0,
                            best: (here, points[k]),
                        })
                    }
                    Some(mut trial) if trial.next < trial.candidates.len() => {
                        let x = trial.candidates[trial.next];
                        trial.next += 1;
                        // Links are never shorter than straight: a candidate whose
                        // straight-line cost is no better than the best true cost so far
                        // cannot win.
                        if self.refine_lower_bound(x, &points, k, ends) < trial.best.0 {
                            let c = self.refine_cost(x, &points, k, ends, region);
                            if c < trial.best.0 - 1e-12 {
                                trial.best = (c, x);
                            }
                        }
                        Some(trial)
                    }
                    Some(trial) => {
                        points[k] = trial.best.1;
                        None
                    }
                };
                let (round, k) = match (&trial, k + 1 < n) {
                    (Some(_), _) => (round, k),
                    (None, true) => (round, k + 1),
                    (None, false) => (round + 1, 0),
                };
                ChainStage::Refine {
                    order,
                    points,
                    round,
                    k,
                    trial,
                }
            }
            ChainStage::Refine { order, points, .. } => ChainStage::Links {
                order,
                points,
                steps: Vec::with_capacity(n),
            },
            ChainStage::Links {
                order,
                points,
                mut steps,
            } if steps.len() < n => {
                // Links that pay, on obstacle-avoiding paths; elsewhere the chain is cut.
                if abort() {
                    return None;
                }
                let k = steps.len();
                let contour = group[order[k]];
                let entry = if k == 0 {
                    Entry::Pierce
                } else {
                    let straight = points[k - 1].distance(points[k]);
                    let reach = self.link_reach(straight);
                    match region.shortest_link(points[k - 1], points[k], reach) {
                        Some((corners, length))
                            if on * length < pierce + off * straight - 1e-12 =>
                        {
                            Entry::Link(corners)
                        }
                        _ => Entry::Pierce,
                    }
                };
                steps.push(CutStep {
                    contour,
                    pierce_point: points[k],
                    entry,
                    leads: None,
                });
                ChainStage::Links {
                    order,
                    points,
                    steps,
                }
            }
            ChainStage::Links { steps, .. } => {
                let mut new_steps = rest.to_vec();
                new_steps.splice(at.insert_at..at.insert_at, steps);
                return Some(Some(Route {
                    steps: new_steps,
                    ..current.clone()
                }));
            }
            ChainStage::Taken => unreachable!("a chain's stage is put back after every piece"),
        };
        Some(None)
    }

    /// The true cost of chain point `k` at `x`: the links (or pierces) into and out of it,
    /// on obstacle-avoiding paths, and the idle moves at the chain's ends (`ends`: where the
    /// tool comes from and goes to). The straight-line model of the descent misses that a
    /// contour blocks the way out of itself (a chain leaves a contour where it entered it).
    fn refine_cost(
        &self,
        x: Point,
        points: &[Point],
        k: usize,
        (before, after): (Point, Option<Point>),
        region: &Region,
    ) -> f64 {
        let (on, off) = self.per_mm();
        let pierce = self.machine.pierce_price;
        let n = points.len();
        let transition = |a: Point, b: Point| -> f64 {
            let straight = a.distance(b);
            let idle = pierce + off * straight;
            match region.shortest_link(a, b, self.link_reach(straight)) {
                Some((_, length)) => (on * length).min(idle),
                None => idle,
            }
        };
        let entering = if k == 0 {
            off * before.distance(x)
        } else {
            transition(points[k - 1], x)
        };
        let leaving = if k + 1 < n {
            transition(x, points[k + 1])
        } else {
            after.map_or(0.0, |a| off * x.distance(a))
        };
        entering + leaving
    }

    /// A lower bound on [`Context::refine_cost`] from straight distances.
    fn refine_lower_bound(
        &self,
        x: Point,
        points: &[Point],
        k: usize,
        (before, after): (Point, Option<Point>),
    ) -> f64 {
        let (on, off) = self.per_mm();
        let pierce = self.machine.pierce_price;
        let n = points.len();
        let at_least = |a: Point, b: Point, end_price: Option<f64>| {
            let d = a.distance(b);
            match end_price {
                Some(price) => price * d,
                None => (on * d).min(pierce + off * d),
            }
        };
        let entering = if k == 0 {
            at_least(before, x, Some(off))
        } else {
            at_least(points[k - 1], x, None)
        };
        let leaving = if k + 1 < n {
            at_least(x, points[k + 1], None)
        } else {
            after.map_or(0.0, |a| at_least(x, a, Some(off)))
        };
        entering + leaving
    }

    /// The corners of `contour` tried for chain point `k`: the `REFINEMENT_CANDIDATES`
    /// nearest its neighbours in straight line, where the way round the contour starts
    /// shortest.
    fn refine_candidates(
        &self,
        contour: &Contour,
        points: &[Point],
        k: usize,
        (before, _): (Point, Option<Point>),
    ) -> Vec<Point> {
        let n = points.len();
        let straight_cost = |x: Point| {
            let prev = if k == 0 { before } else { points[k - 1] };
            x.distance(prev)
                + (if k + 1 < n {
                    x.distance(points[k + 1])
                } else {
                    0.0
                })
        };
        let mut candidates: Vec<Point> = contour.spans().map(|s| s.start).collect();
        candidates.sort_by(|a, b| straight_cost(*a).total_cmp(&straight_cost(*b)));
        candidates.truncate(REFINEMENT_CANDIDATES);
        candidates
    }
}

/// A group being chained ([`Context::advance_group`]).
struct GroupWork {
    group: Vec<ContourRef>,
    /// The route's steps that are not members, in order.
    rest: Vec<CutStep>,
    /// Where in `rest` the chain is still to be tried (next last).
    places: Vec<usize>,
    /// The cheapest route so far, with its cost.
    best: Option<(f64, Route)>,
    /// The chain under way at one place.
    at: Option<ChainAt>,
}

/// The refinement of one chain point: its candidate corners, the next to try, and the best
/// (true cost, point) so far (the current point first).
struct Trial {
    candidates: Vec<Point>,
    next: usize,
    best: (f64, Point),
}

/// What a call of [`Context::advance_group`] ended with.
enum GroupStatus {
    Done(Route),
    Paused,
    Aborted,
}

/// The chain of a group at one place, under way.
struct ChainAt {
    insert_at: usize,
    /// Where the tool comes from (the step before the place, or the route's start).
    before: Point,
    /// Where it goes next (the step at the place, or the route's finish).
    after: Option<Point>,
    stage: ChainStage,
}

enum ChainStage {
    /// The member-to-member costs, row `i` next (the rows made so far).
    Between { i: usize, between: Vec<Vec<f64>> },
    /// Pierce point `k` of refinement round `round` under way (members in chain `order`).
    Refine {
        order: Vec<usize>,
        points: Vec<Point>,
        round: usize,
        k: usize,
        /// Its candidates being tried (`None`: not started).
        trial: Option<Trial>,
    },
    /// The steps of the chain, one link decided per piece.
    Links {
        order: Vec<usize>,
        points: Vec<Point>,
        steps: Vec<CutStep>,
    },
    /// Only while a piece runs.
    Taken,
}

/// The point of `contour` minimising `Σ w·|x − a|` over `terms`: every span is sampled, the
/// best span and its neighbours are searched by golden section (exact on straight spans, where
/// the sum is convex), and the nearest points to each `a` are candidates too.
fn best_point(contour: &Contour, terms: &[(Point, f64)]) -> Point {
    let f = |x: Point| terms.iter().map(|(a, w)| w * x.distance(*a)).sum::<f64>();
    let spans: Vec<_> = contour.spans().collect();
    if spans.is_empty() {
        return terms.first().map_or(Point::default(), |t| t.0);
    }
    let mut best = (f64::INFINITY, spans[0].start, 0usize);
    let consider = |x: Point, span: usize, best: &mut (f64, Point, usize)| {
        let v = f(x);
        if v < best.0 {
            *best = (v, x, span);
        }
    };
    for (i, s) in spans.iter().enumerate() {
        for t in [0.0, 0.25, 0.5, 0.75] {
            consider(s.point_at(t), i, &mut best);
        }
    }
    for (a, _) in terms {
        if let Some(p) = contour.nearest_point(*a) {
            consider(p.point, p.position.span, &mut best);
        }
    }
    let n = spans.len();
    let around = best.2;
    for i in [around, (around + 1) % n, (around + n - 1) % n] {
        let s = spans[i];
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let g = |t: f64| f(s.point_at(t));
        let ratio = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..60 {
            let m1 = hi - ratio * (hi - lo);
            let m2 = lo + ratio * (hi - lo);
            if g(m1) < g(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        consider(s.point_at(0.5 * (lo + hi)), i, &mut best);
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The close-group sweep paused after every piece finds the groups of the sweep in one
    /// piece, over the top-level contours of a generated nest (hundreds of them: many pieces).
    #[test]
    fn the_close_group_sweep_in_pieces_finds_the_one_piece_groups() {
        let nest = cutroute_geometry::generate_nest(3000, 1);
        let forest = nest.containment_forest();
        let threshold =
            profitable_link_length(&TABLE1_MATERIALS[1].priced(&MachineParameters::default()));
        let mut most_pieces = 0;
        for (_, members) in scrap_regions(&nest, &forest) {
            let whole = CloseGroups::new(&nest, &members)
                .advance(&nest, &members, threshold, &|| false)
                .expect("done without a pause");
            let mut sweep = CloseGroups::new(&nest, &members);
            let mut pieces = 1;
            let sliced = loop {
                match sweep.advance(&nest, &members, threshold, &|| true) {
                    Some(groups) => break groups,
                    None => pieces += 1,
                }
            };
            assert_eq!(sliced, whole);
            assert_eq!(pieces, members.len().div_ceil(SWEEP_PIECE).max(1));
            most_pieces = most_pieces.max(pieces);
        }
        assert!(most_pieces > 5, "the sweep paused only {most_pieces} times");
    }
}
