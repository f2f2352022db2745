//! The SCCP solver: CCP-Relax generalised to a fixed set of base segments.
//!
//! A closed segment is entered and left at one point that may lie anywhere on it (the CCP
//! rule); an open segment is entered at one end and left at the other, the direction being a
//! binary choice. For a fixed order, relaxation sweeps move every closed segment's point to
//! the exact minimiser of `|X(i−1) M| + |M E(i+1)|` over the segment and flip every open
//! segment to its cheaper direction, until a sweep gains less than δ. The order is improved by
//! block re-insertion (Or-opt, blocks of 1 to `max_block` segments, at the places next to the k
//! nearest segments, single open segments in both directions, single closed ones with their
//! point relaxed at the new place) and block reversal (2-opt: open segments in the block
//! change direction, so only the two joints change length), always respecting the ensemble's
//! precedence; sweeps and moves alternate to a local optimum. Then VNS: random block moves in
//! a window shake the best order, descent follows, and the result is kept only if shorter,
//! until `max_non_improving_shakes` shakes in a row fail, the time is up or the cancel flag is
//! raised.

use std::collections::{BinaryHeap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit, Status};
use cutroute_ccp::HeatPenalty;
use cutroute_geometry::{
    nearest_groups, BoundingBox, ContourRef, MachineParameters, PathRoute, Point, Route, Span,
    SplitMix64, ToolOnPath,
};
use cutroute_thermal::path_route_pierces;
use web_time::Instant;

use crate::segment::{Ensemble, Segment};
use crate::SegmentError;

/// Settings of [`solve_sccp`].
#[derive(Clone, Debug, PartialEq)]
pub struct SccpOptions {
    /// Where the head starts.
    pub start: Point,
    /// Where it must end, if anywhere.
    pub finish: Option<Point>,
    /// Wall-clock limit of the search.
    pub time_limit: Duration,
    /// Re-insertion places tried next to this many nearest segments.
    pub neighbours: usize,
    /// Longest block of consecutive segments moved at once.
    pub max_block: usize,
    /// A relaxation sweep gaining less than this (mm) ends the relaxation.
    pub delta: f64,
    /// Most relaxation sweeps in a row.
    pub max_relaxation_sweeps: usize,
    /// Longest block reversed at once (2-opt; open segments in it change direction).
    pub max_reversal: usize,
    /// The search stops after this many shakes in a row that did not improve the best route.
    pub max_non_improving_shakes: usize,
    /// Most random block moves in one shake.
    pub max_shake_strength: usize,
    /// Seed of the shakes.
    pub seed: u64,
    /// The heat penalty (issue #19): the VNS keeps the order with the least idle + W·H
    /// rather than the least idle. `None`: idle alone.
    pub heat: Option<PathHeat>,
}

/// The heat penalty of a segment search: W·H of a route of tool-on paths, H with one source
/// per path at its pierce on the route's own machine clock (`path_route_pierces`), W in
/// objective units per unit of H.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathHeat {
    /// σ, τ, W and W's unit.
    pub penalty: HeatPenalty,
    /// The time model of the clock H runs on, and the prices that convert W to idle length.
    pub machine: MachineParameters,
}

impl PathHeat {
    /// H of `route`.
    pub fn load(&self, route: &PathRoute) -> f64 {
        self.penalty
            .model
            .load(&path_route_pierces(route, &self.machine))
    }

    /// W·H of `route` in objective units (what GSCCP adds to a route's time or cost).
    pub fn objective_penalty(&self, route: &PathRoute) -> f64 {
        if self.penalty.weight > 0.0 {
            self.penalty.weight * self.load(route)
        } else {
            0.0
        }
    }

    /// W·H of `route` in millimetres of idle travel (what the SCCP search adds to idle).
    pub fn idle_penalty(&self, route: &PathRoute) -> f64 {
        if self.penalty.weight > 0.0 {
            self.penalty.weight_mm(&self.machine) * self.load(route)
        } else {
            0.0
        }
    }
}

impl Default for SccpOptions {
    fn default() -> Self {
        SccpOptions {
            start: Point::new(0.0, 0.0),
            finish: None,
            time_limit: Duration::from_secs(10),
            neighbours: 8,
            max_block: 3,
            delta: 1e-6,
            max_relaxation_sweeps: 1000,
            max_reversal: 50,
            max_non_improving_shakes: 100,
            max_shake_strength: 4,
            seed: 1,
            heat: None,
        }
    }
}

/// A solved SCCP.
#[derive(Clone, Debug, PartialEq)]
pub struct SccpSolution {
    /// The route: one tool-on path per segment, in cutting order.
    pub route: PathRoute,
    /// The segments in cutting order.
    pub order: Vec<usize>,
    /// Idle length of the route, mm.
    pub idle_length: f64,
    /// Idle length of the first order after its first relaxation, mm.
    pub initial_idle_length: f64,
    /// Whether the search stopped at the time limit or the cancel flag rather than after
    /// `max_non_improving_shakes` fruitless shakes.
    pub interrupted: bool,
    /// Shakes tried.
    pub shakes: usize,
}

/// Where the tool enters and leaves a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Place {
    /// Closed segment: in and out at `point`, on span `span` at parameter `t`.
    Closed { span: usize, t: f64, point: Point },
    /// Open segment: in at its first point (or its last, reversed).
    Open { reversed: bool },
}

/// Where the tool enters `segment` placed at `place`.
fn entry_point(segment: &Segment, place: Place) -> Point {
    match place {
        Place::Closed { point, .. } => point,
        Place::Open { reversed: false } => segment.first_point(),
        Place::Open { reversed: true } => segment.last_point(),
    }
}

/// The point of a closed segment minimising `|a M| + |M b|` (or `|a M|` without `b`), starting
/// from the value `current` to prune spans: `(span, t, point, value)`, or `None` if no span
/// beats `current`.
fn best_point(
    segment: &Segment,
    boxes: &[BoundingBox],
    a: Point,
    b: Option<Point>,
    current: f64,
) -> Option<(usize, f64, Point, f64)> {
    let mut best: Option<(usize, f64, Point, f64)> = None;
    let mut bound = current;
    for (i, span) in segment.spans.iter().enumerate() {
        let bbox = &boxes[i];
        let lower = bbox.distance_to_point(a) + b.map_or(0.0, |b| bbox.distance_to_point(b));
        // Not `lower >= …`: a NaN bound must skip the span too.
        if lower.partial_cmp(&(bound - 1e-12)) != Some(std::cmp::Ordering::Less) {
            continue;
        }
        let (t, value) = span.detour_minimum(a, b);
        if value < bound {
            bound = value;
            best = Some((i, t, span.point_at(t), value));
        }
    }
    best
}

struct Search {
    segments: Vec<Segment>,
    /// The bounding box of every span of every segment, and of every whole segment.
    boxes: Vec<Vec<BoundingBox>>,
    whole_box: Vec<BoundingBox>,
    before: Vec<Vec<usize>>,
    after: Vec<Vec<usize>>,
    neighbours: Vec<Vec<usize>>,
    order: Vec<usize>,
    pos: Vec<usize>,
    place: Vec<Place>,
    options: SccpOptions,
}

impl Search {
    fn entry(&self, s: usize) -> Point {
        entry_point(&self.segments[s], self.place[s])
    }

    fn exit(&self, s: usize) -> Point {
        match self.place[s] {
            Place::Closed { point, .. } => point,
            Place::Open { reversed: false } => self.segments[s].last_point(),
            Place::Open { reversed: true } => self.segments[s].first_point(),
        }
    }

    /// Where the head is before position `i` (the start for 0).
    fn before_point(&self, i: usize) -> Point {
        if i == 0 {
            self.options.start
        } else {
            self.exit(self.order[i - 1])
        }
    }

    /// Where the head goes after position `i` (the finish, or nowhere, after the last).
    fn after_point(&self, i: usize) -> Option<Point> {
        match self.order.get(i + 1) {
            Some(&s) => Some(self.entry(s)),
            None => self.options.finish,
        }
    }

    fn idle_length(&self) -> f64 {
        self.idle_length_of(&self.order, &self.place)
    }

    /// What the VNS minimises: idle length, plus W·H in millimetres with a heat penalty.
    fn penalised_length(&self) -> f64 {
        let idle = self.idle_length();
        match &self.options.heat {
            Some(heat) => idle + heat.idle_penalty(&self.route()),
            None => idle,
        }
    }

    fn idle_length_of(&self, order: &[usize], place: &[Place]) -> f64 {
        let mut at = self.options.start;
        let mut total = 0.0;
        for &s in order {
            total += at.distance(entry_point(&self.segments[s], place[s]));
            at = match place[s] {
                Place::Closed { point, .. } => point,
                Place::Open { reversed: false } => self.segments[s].last_point(),
                Place::Open { reversed: true } => self.segments[s].first_point(),
            };
        }
        if let Some(f) = self.options.finish {
            total += at.distance(f);
        }
        total
    }

    /// Relaxes the place of the segment at position `i` for its current neighbours; returns
    /// the gain.
    fn relax_at(&mut self, i: usize) -> f64 {
        let s = self.order[i];
        let a = self.before_point(i);
        let b = self.after_point(i);
        let cost = |e: Point, x: Point| a.distance(e) + b.map_or(0.0, |b| x.distance(b));
        let old = cost(self.entry(s), self.exit(s));
        match self.place[s] {
            Place::Closed { .. } => {
                if let Some((span, t, point, value)) =
                    best_point(&self.segments[s], &self.boxes[s], a, b, old)
                {
                    if value < old {
                        self.place[s] = Place::Closed { span, t, point };
                        return old - value;
                    }
                }
                0.0
            }
            Place::Open { reversed } => {
                let flipped = Place::Open {
                    reversed: !reversed,
                };
                let previous = self.place[s];
                self.place[s] = flipped;
                let new = cost(self.entry(s), self.exit(s));
                if new < old {
                    old - new
                } else {
                    self.place[s] = previous;
                    0.0
                }
            }
        }
    }

    /// Can the block at positions `[i, i + len)` move to just after position `j` (before
    /// position 0 for `j = usize::MAX`)?
    fn can_move(&self, i: usize, len: usize, j: Option<usize>) -> bool {
        let block = &self.order[i..i + len];
        match j {
            Some(j) if j >= i + len => block
                .iter()
                .all(|&b| self.after[b].iter().all(|&x| self.pos[x] > j)),
            _ => {
                let limit = j.map_or(0, |j| j + 1);
                block
                    .iter()
                    .all(|&b| self.before[b].iter().all(|&x| self.pos[x] < limit))
            }
        }
    }

    /// Block re-insertion at position `i` (blocks of 1 to `max_block` segments, the first
    /// that gains is moved); returns whether a block moved.
    fn or_opt_at(&mut self, i: usize) -> bool {
        for len in 1..=self.options.max_block.min(self.order.len() - i) {
            if self.try_move_block(i, len) {
                return true;
            }
        }
        false
    }

    fn try_move_block(&mut self, i: usize, len: usize) -> bool {
        let n = self.order.len();
        let first = self.order[i];
        let last = self.order[i + len - 1];
        let p = self.before_point(i);
        let next = self.after_point(i + len - 1);
        let (e0, x0) = (self.entry(first), self.exit(last));
        let removal = p.distance(e0) + next.map_or(0.0, |q| x0.distance(q))
            - next.map_or(0.0, |q| p.distance(q));
        if removal <= 1e-9 {
            return false;
        }
        // Places: just after position j (None = before everything).
        let mut places: Vec<Option<usize>> = Vec::new();
        for &c in self.neighbours[first]
            .iter()
            .chain(self.neighbours[last].iter())
        {
            let k = self.pos[c];
            if k >= i && k < i + len {
                continue;
            }
            places.push(Some(k));
            places.push(k.checked_sub(1));
        }
        places.push(Some(n - 1));
        places.push(None);
        places.sort_unstable();
        places.dedup();
        let single = len == 1;
        let mut best: Option<(f64, Option<usize>, Place)> = None;
        for j in places {
            // Same place as now.
            if j == i.checked_sub(1) || j.is_some_and(|j| j >= i && j < i + len) {
                continue;
            }
            let u = match j {
                None => self.options.start,
                Some(j) => self.exit(self.order[j]),
            };
            let v_index = j.map_or(0, |j| j + 1);
            // `v_index == i` is the block's own place, skipped above.
            let v = if v_index < n {
                Some(self.entry(self.order[v_index]))
            } else {
                self.options.finish
            };
            let base = v.map_or(0.0, |v| u.distance(v));
            let add = |e: Point, x: Point| u.distance(e) + v.map_or(0.0, |v| x.distance(v)) - base;
            let mut candidate = (add(e0, x0), self.place[first]);
            if single {
                match self.place[first] {
                    Place::Open { reversed } => {
                        let (e, x) = (x0, e0);
                        let flipped = add(e, x);
                        if flipped < candidate.0 {
                            candidate = (
                                flipped,
                                Place::Open {
                                    reversed: !reversed,
                                },
                            );
                        }
                    }
                    Place::Closed { .. } => {
                        let bbox = &self.whole_box[first];
                        let lower = bbox.distance_to_point(u)
                            + v.map_or(0.0, |v| bbox.distance_to_point(v))
                            - base;
                        if candidate.0 >= removal && lower < removal {
                            let current = candidate.0 + base;
                            if let Some((span, t, point, value)) =
                                best_point(&self.segments[first], &self.boxes[first], u, v, current)
                            {
                                candidate = (value - base, Place::Closed { span, t, point });
                            }
                        }
                    }
                }
            }
            let delta = candidate.0 - removal;
            if delta < -1e-9 && best.is_none_or(|b| delta < b.0) && self.can_move(i, len, j) {
                best = Some((delta, j, candidate.1));
            }
        }
        let Some((_, j, place)) = best else {
            return false;
        };
        if single {
            self.place[first] = place;
        }
        let block: Vec<usize> = self.order.drain(i..i + len).collect();
        let at = match j {
            None => 0,
            Some(j) if j >= i + len => j + 1 - len,
            Some(j) => j + 1,
        };
        for (k, s) in block.into_iter().enumerate() {
            self.order.insert(at + k, s);
        }
        for (k, &s) in self.order.iter().enumerate() {
            self.pos[s] = k;
        }
        true
    }

    /// Block reversal (2-opt) from position `i`: the block from `i` to a position `j` where
    /// the segment before `i` has a near neighbour is cut backwards, open segments flipped;
    /// only the two joints change. Returns whether a reversal gained.
    fn two_opt_at(&mut self, i: usize) -> bool {
        let p = self.before_point(i);
        let first = self.order[i];
        let anchors: Vec<usize> = match i.checked_sub(1) {
            Some(k) => self.neighbours[self.order[k]].clone(),
            None => self.neighbours[first].clone(),
        };
        let mut best: Option<(f64, usize)> = None;
        for c in anchors {
            let j = self.pos[c];
            if j <= i || j - i + 1 > self.options.max_reversal {
                continue;
            }
            let last = self.order[j];
            let next = self.after_point(j);
            let old =
                p.distance(self.entry(first)) + next.map_or(0.0, |q| self.exit(last).distance(q));
            let new =
                p.distance(self.exit(last)) + next.map_or(0.0, |q| self.entry(first).distance(q));
            let delta = new - old;
            if delta < -1e-9 && best.is_none_or(|b| delta < b.0) && self.can_reverse(i, j) {
                best = Some((delta, j));
            }
        }
        match best {
            Some((_, j)) => {
                self.reverse(i, j);
                true
            }
            None => false,
        }
    }

    /// No precedence pair inside positions `[i, j]`.
    fn can_reverse(&self, i: usize, j: usize) -> bool {
        self.order[i..=j]
            .iter()
            .all(|&b| self.after[b].iter().all(|&x| self.pos[x] > j))
    }

    fn reverse(&mut self, i: usize, j: usize) {
        self.order[i..=j].reverse();
        for k in i..=j {
            let s = self.order[k];
            self.pos[s] = k;
            if let Place::Open { reversed } = self.place[s] {
                self.place[s] = Place::Open {
                    reversed: !reversed,
                };
            }
        }
    }

    /// Random block moves to valid places within a window of the order.
    fn shake(&mut self, rng: &mut SplitMix64) {
        let n = self.order.len();
        if n < 3 {
            return;
        }
        let strength = 1 + rng.below(self.options.max_shake_strength.max(1) as u64) as usize;
        for _ in 0..strength {
            let len = 1 + rng.below(self.options.max_block.clamp(1, n - 1) as u64) as usize;
            let i = rng.below((n - len + 1) as u64) as usize;
            let window = 10usize;
            let lo = i.saturating_sub(window);
            let hi = (i + len + window).min(n - 1);
            let target = lo + rng.below((hi - lo + 1) as u64) as usize;
            let j = if target == 0 && rng.below(2) == 0 {
                None
            } else {
                Some(target)
            };
            if j == i.checked_sub(1) || j.is_some_and(|j| j >= i && j < i + len) {
                continue;
            }
            if self.can_move(i, len, j) {
                let block: Vec<usize> = self.order.drain(i..i + len).collect();
                let at = match j {
                    None => 0,
                    Some(j) if j >= i + len => j + 1 - len,
                    Some(j) => j + 1,
                };
                for (k, s) in block.into_iter().enumerate() {
                    self.order.insert(at + k, s);
                }
                for (k, &s) in self.order.iter().enumerate() {
                    self.pos[s] = k;
                }
            }
        }
    }

    fn route(&self) -> PathRoute {
        self.route_of(&self.order, &self.place)
    }

    /// The route of an order with its places (the current one, or the best kept).
    fn route_of(&self, order: &[usize], place: &[Place]) -> PathRoute {
        let paths = order
            .iter()
            .map(|&s| {
                let segment = &self.segments[s];
                let spans = match place[s] {
                    Place::Closed { span, t, point } => opened(&segment.spans, span, t, point),
                    Place::Open { reversed: false } => segment.spans.clone(),
                    Place::Open { reversed: true } => {
                        segment.spans.iter().rev().map(Span::reversed).collect()
                    }
                };
                ToolOnPath {
                    pierce: entry_point(segment, place[s]),
                    spans,
                    leads: None,
                }
            })
            .collect();
        PathRoute {
            start: self.options.start,
            paths,
            finish: self.options.finish,
        }
    }
}

/// A closed chain of spans opened at `point` (on span `i` at `t`): the rest of span `i`, the
/// spans after it round the cycle, the part of span `i` before the point.
fn opened(spans: &[Span], i: usize, t: f64, point: Point) -> Vec<Span> {
    let mut out = Vec::with_capacity(spans.len() + 1);
    let mut at = point;
    let mut push = |mut s: Span| {
        if s.length() > 1e-12 {
            s.start = at;
            at = s.end;
            out.push(s);
        }
    };
    push(spans[i].sub_span(t, 1.0));
    for k in 1..spans.len() {
        push(spans[(i + k) % spans.len()]);
    }
    let mut tail = spans[i].sub_span(0.0, t);
    tail.end = point;
    push(tail);
    out
}

/// What a CCP route says about each contour: its position in the route and pierce point.
fn hints(route: &Route) -> HashMap<ContourRef, (usize, Point)> {
    route
        .steps
        .iter()
        .enumerate()
        .map(|(i, s)| (s.contour, (i, s.pierce_point)))
        .collect()
}

/// Solves one SCCP: [`SccpSearch`] stepped to its end (the cancel flag is read between
/// slices of [`SOLVE_SLICE`]; the route is then the best so far). The first order follows
/// `hint` (see [`SccpSearch::new`]); then descent and VNS (see the module notes) until the
/// shakes stop paying, `options.time_limit` passes or `cancel` is raised; the route is the best
/// order found with its relaxed points.
pub fn solve_sccp(
    ensemble: &Ensemble,
    hint: Option<&Route>,
    options: &SccpOptions,
    cancel: &AtomicBool,
) -> Result<SccpSolution, SegmentError> {
    let mut search = SccpSearch::new(ensemble, hint, options)?;
    // The flag is read before every slice, the first included: a run cancelled before it
    // starts returns the starting order (a small ensemble can finish within one slice).
    loop {
        if cancel.load(Ordering::Relaxed) {
            search.stop();
            break;
        }
        if search.step(SOLVE_SLICE).is_done() {
            break;
        }
    }
    Ok(search.solution())
}

/// The contract of every solver: the best path route so far and its idle length (mm, the
/// objective the search minimises; the heat penalty is priced inside the search); no lower
/// bound.
impl AnytimeSolver for SccpSearch {
    type Solution = PathRoute;

    fn step(&mut self, budget: Duration) -> Status {
        SccpSearch::step(self, budget)
    }

    fn best(&self) -> Option<PathRoute> {
        Some(self.best_route())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            upper: Some(self.best_idle_length()),
            lower: None,
            unit: CostUnit::IdleMm,
        }
    }
}

/// The slice [`solve_sccp`] and [`crate::solve_gsccp`] step their searches by between looks at
/// the cancel flag.
pub const SOLVE_SLICE: Duration = Duration::from_millis(20);

/// Units of work done between looks at the clock (each is one position of a pass: a few
/// dozen distance evaluations, or one block move, O(segments)).
const UNITS_PER_CLOCK_CHECK: usize = 8;

/// Where a relaxation (sweeps of [`Search::relax_at`] over every position) stands.
#[derive(Clone, Copy, Debug)]
struct Relaxation {
    sweep: usize,
    i: usize,
    gain: f64,
    total: f64,
}

impl Relaxation {
    const NEW: Relaxation = Relaxation {
        sweep: 0,
        i: 0,
        gain: 0.0,
        total: 0.0,
    };
}

/// Which pass of a descent is under way, and at which position.
#[derive(Clone, Copy, Debug)]
enum Pass {
    OrOpt { i: usize },
    TwoOpt { i: usize },
    Relax(Relaxation),
}

/// A descent to a local optimum: passes of block moves, reversals and relaxation, repeated
/// until a round changes nothing.
#[derive(Clone, Copy, Debug)]
struct Descent {
    pass: Pass,
    moved: bool,
    reversed: bool,
}

impl Descent {
    const NEW: Descent = Descent {
        pass: Pass::OrOpt { i: 0 },
        moved: false,
        reversed: false,
    };
}

#[derive(Clone, Copy, Debug)]
enum Stage {
    /// The first relaxation of the first order.
    Relaxing(Relaxation),
    /// The first descent (no best kept yet) or one after a shake.
    Descending(Descent),
    Finished,
}

/// The SCCP search as a resumable state machine: [`SccpSearch::step`] does about `budget` of
/// work and returns, and resumes exactly where it stopped, so a run stepped in slices of any
/// size takes the same path as one run in a single call (only the time limit depends on the
/// clock). A browser worker steps it between messages; [`solve_sccp`] is a loop over it.
pub struct SccpSearch {
    search: Search,
    stage: Stage,
    started: Instant,
    deadline: Instant,
    rng: SplitMix64,
    /// The best order kept by the VNS (after the first descent): idle (+ W·H with a heat
    /// penalty), order, places.
    best: Option<(f64, Vec<usize>, Vec<Place>)>,
    initial_idle_length: Option<f64>,
    shakes: usize,
    fruitless: usize,
    interrupted: bool,
}

impl SccpSearch {
    /// Prepares the search of one SCCP (neighbour lists, precedence, the first order). The
    /// first order follows `hint` (a route of the nest, e.g. CCP-Relax's: segments sorted by
    /// the earliest step that cuts one of their contours, as far as precedence allows; a
    /// closed segment that is one whole contour starts at that step's pierce point); without a
    /// hint, greedy nearest neighbour. `options.time_limit` counts from this call.
    pub fn new(
        ensemble: &Ensemble,
        hint: Option<&Route>,
        options: &SccpOptions,
    ) -> Result<Self, SegmentError> {
        let segments = &ensemble.segments;
        let n = segments.len();
        if let Some(i) = segments.iter().position(|s| s.spans.is_empty()) {
            return Err(SegmentError::EmptySegment { segment: i });
        }
        let started = Instant::now();
        let mut before = vec![Vec::new(); n];
        let mut after = vec![Vec::new(); n];
        for &(a, b) in &ensemble.precedence {
            if a >= n || b >= n {
                return Err(SegmentError::UnknownSegment {
                    segment: a.max(b),
                    count: n,
                });
            }
            after[a].push(b);
            before[b].push(a);
        }
        let boxes: Vec<Vec<BoundingBox>> = segments
            .iter()
            .map(|s| s.spans.iter().map(Span::bounding_box).collect())
            .collect();
        let whole_box: Vec<BoundingBox> = boxes
            .iter()
            .map(|bs| {
                bs.iter()
                    .fold(BoundingBox::EMPTY, |whole, b| whole.union(*b))
            })
            .collect();
        // Representative points for neighbour lists: the ends of open segments, the box centre
        // of closed ones.
        let reps: Vec<Vec<Point>> = segments
            .iter()
            .zip(&whole_box)
            .map(|(s, whole)| {
                if s.closed {
                    vec![whole.centre()]
                } else {
                    vec![s.first_point(), s.last_point()]
                }
            })
            .collect();
        let neighbours = nearest_groups(&reps, options.neighbours.min(n.saturating_sub(1)));

        // First order: by hint rank within precedence (Kahn's algorithm with a priority queue),
        // or greedy nearest neighbour.
        let hint_map = hint.map(hints);
        let mut place: Vec<Place> = segments
            .iter()
            .map(|s| {
                if s.closed {
                    Place::Closed {
                        span: 0,
                        t: 0.0,
                        point: s.first_point(),
                    }
                } else {
                    Place::Open { reversed: false }
                }
            })
            .collect();
        let mut indegree: Vec<usize> = before.iter().map(Vec::len).collect();
        let mut order = Vec::with_capacity(n);
        if let Some(map) = &hint_map {
            let key: Vec<usize> = segments
                .iter()
                .map(|s| {
                    s.contours
                        .iter()
                        .filter_map(|c| map.get(c).map(|h| h.0))
                        .min()
                        .unwrap_or(usize::MAX)
                })
                .collect();
            for (s, segment) in segments.iter().enumerate() {
                if let ([c], true) = (&segment.contours[..], segment.closed) {
                    if let Some(&(_, pierce)) = map.get(c) {
                        let best = segment
                            .spans
                            .iter()
                            .enumerate()
                            .map(|(i, sp)| (i, sp.nearest_point(pierce)))
                            .min_by(|x, y| x.1.distance.total_cmp(&y.1.distance));
                        if let Some((span, q)) = best {
                            place[s] = Place::Closed {
                                span,
                                t: q.t,
                                point: q.point,
                            };
                        }
                    }
                }
            }
            let mut ready: BinaryHeap<std::cmp::Reverse<(usize, usize)>> = (0..n)
                .filter(|&s| indegree[s] == 0)
                .map(|s| std::cmp::Reverse((key[s], s)))
                .collect();
            while let Some(std::cmp::Reverse((_, s))) = ready.pop() {
                order.push(s);
                for &t in &after[s] {
                    indegree[t] -= 1;
                    if indegree[t] == 0 {
                        ready.push(std::cmp::Reverse((key[t], t)));
                    }
                }
            }
        } else {
            let mut ready: Vec<usize> = (0..n).filter(|&s| indegree[s] == 0).collect();
            let mut at = options.start;
            while !ready.is_empty() {
                let (r, _) = ready
                    .iter()
                    .enumerate()
                    .map(|(r, &s)| {
                        let d = if segments[s].closed {
                            segments[s]
                                .spans
                                .iter()
                                .map(|sp| sp.start.distance(at))
                                .fold(f64::INFINITY, f64::min)
                        } else {
                            at.distance(segments[s].first_point())
                                .min(at.distance(segments[s].last_point()))
                        };
                        (r, d)
                    })
                    .min_by(|x, y| x.1.total_cmp(&y.1))
                    .expect("ready is not empty");
                let s = ready.swap_remove(r);
                if !segments[s].closed {
                    let reversed = at.distance(segments[s].last_point())
                        < at.distance(segments[s].first_point());
                    place[s] = Place::Open { reversed };
                }
                order.push(s);
                at = match place[s] {
                    Place::Open { reversed: false } => segments[s].last_point(),
                    Place::Open { reversed: true } => segments[s].first_point(),
                    Place::Closed { point, .. } => point,
                };
                for &t in &after[s] {
                    indegree[t] -= 1;
                    if indegree[t] == 0 {
                        ready.push(t);
                    }
                }
            }
        }
        if order.len() != n {
            return Err(SegmentError::CyclicPrecedence {
                kind: ensemble.kind,
                segment: (0..n).find(|&s| indegree[s] > 0).unwrap_or(0),
            });
        }
        let mut pos = vec![0; n];
        for (k, &s) in order.iter().enumerate() {
            pos[s] = k;
        }
        let search = Search {
            segments: segments.clone(),
            boxes,
            whole_box,
            before,
            after,
            neighbours,
            order,
            pos,
            place,
            options: options.clone(),
        };
        Ok(SccpSearch {
            search,
            stage: Stage::Relaxing(Relaxation::NEW),
            started,
            deadline: started + options.time_limit,
            rng: SplitMix64::new(options.seed),
            best: None,
            initial_idle_length: None,
            shakes: 0,
            fruitless: 0,
            interrupted: false,
        })
    }

    /// Works for about `budget` (the clock is read every few units of work, each far below a
    /// millisecond on the real nests), then returns; [`Status::Stopped`] at the time limit or
    /// after [`SccpSearch::stop`], [`Status::Finished`] when the shakes confirmed the local
    /// optimum.
    pub fn step(&mut self, budget: Duration) -> Status {
        let slice_end = Instant::now() + budget;
        loop {
            for _ in 0..UNITS_PER_CLOCK_CHECK {
                if matches!(self.stage, Stage::Finished) {
                    return self.done_status();
                }
                self.unit();
            }
            let now = Instant::now();
            if now >= self.deadline {
                self.stop();
                return self.done_status();
            }
            if now >= slice_end {
                return Status::Running;
            }
        }
    }

    /// The status once the search has ended.
    fn done_status(&self) -> Status {
        if self.interrupted {
            Status::Stopped
        } else {
            Status::Finished {
                proven_optimal: false,
            }
        }
    }

    /// Ends the search now (cancel, or the time limit): the current order is kept if it beats
    /// the best one, else the best is restored.
    pub fn stop(&mut self) {
        if matches!(self.stage, Stage::Finished) {
            return;
        }
        self.interrupted = true;
        if self.initial_idle_length.is_none() {
            self.initial_idle_length = Some(self.search.idle_length());
        }
        if let Some(best) = self.best.take() {
            if self.search.penalised_length() >= best.0 - self.search.options.delta {
                self.restore(best);
            }
        }
        self.stage = Stage::Finished;
    }

    /// Whether the search has ended.
    pub fn is_finished(&self) -> bool {
        matches!(self.stage, Stage::Finished)
    }

    /// Idle length (mm) of the best route so far (the kept best, or during the first descent
    /// the current order, which only improves).
    pub fn best_idle_length(&self) -> f64 {
        match &self.best {
            Some((_, order, place)) if !self.is_finished() => {
                self.search.idle_length_of(order, place)
            }
            _ => self.search.idle_length(),
        }
    }

    /// The best route so far (see [`SccpSearch::best_idle_length`]).
    pub fn best_route(&self) -> PathRoute {
        match &self.best {
            Some((_, order, place)) if !self.is_finished() => self.search.route_of(order, place),
            _ => self.search.route(),
        }
    }

    /// Shakes tried so far.
    pub fn shakes(&self) -> usize {
        self.shakes
    }

    /// Time since [`SccpSearch::new`].
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// The result: after the end, the final route; before it, the best so far (as if stopped).
    pub fn solution(&self) -> SccpSolution {
        let (route, order, idle_length) = match &self.best {
            Some((_, order, place)) if !self.is_finished() => (
                self.search.route_of(order, place),
                order.clone(),
                self.search.idle_length_of(order, place),
            ),
            _ => (
                self.search.route(),
                self.search.order.clone(),
                self.search.idle_length(),
            ),
        };
        SccpSolution {
            route,
            order,
            idle_length,
            initial_idle_length: self.initial_idle_length.unwrap_or(idle_length),
            interrupted: self.interrupted || !self.is_finished(),
            shakes: self.shakes,
        }
    }

    fn restore(&mut self, best: (f64, Vec<usize>, Vec<Place>)) {
        let search = &mut self.search;
        search.order = best.1;
        search.place = best.2;
        for (k, &s) in search.order.iter().enumerate() {
            search.pos[s] = k;
        }
    }

    /// One unit of work: one position of the current pass, or the end of a pass.
    fn unit(&mut self) {
        match self.stage {
            Stage::Finished => {}
            Stage::Relaxing(mut relaxation) => {
                self.stage = match self.relax_unit(&mut relaxation) {
                    None => Stage::Relaxing(relaxation),
                    Some(_) => {
                        self.initial_idle_length = Some(self.search.idle_length());
                        Stage::Descending(Descent::NEW)
                    }
                };
            }
            Stage::Descending(mut descent) => {
                let n = self.search.order.len();
                match &mut descent.pass {
                    Pass::OrOpt { i } => {
                        if *i >= n {
                            descent.pass = Pass::TwoOpt { i: 0 };
                        } else if self.search.or_opt_at(*i) {
                            // The block that moved left a new segment at `i`: try it too.
                            descent.moved = true;
                        } else {
                            *i += 1;
                        }
                    }
                    Pass::TwoOpt { i } => {
                        if *i >= n {
                            descent.pass = Pass::Relax(Relaxation::NEW);
                        } else {
                            descent.reversed |= self.search.two_opt_at(*i);
                            *i += 1;
                        }
                    }
                    Pass::Relax(relaxation) => {
                        if let Some(total) = self.relax_unit(relaxation) {
                            if !descent.moved
                                && !descent.reversed
                                && total < self.search.options.delta
                            {
                                self.descent_done();
                                return;
                            }
                            descent = Descent::NEW;
                        }
                    }
                }
                self.stage = Stage::Descending(descent);
            }
        }
    }

    /// One position of a relaxation sweep, or the end of a sweep; `Some(total gain)` when the
    /// relaxation has ended (a sweep gained less than δ, or the sweep limit).
    fn relax_unit(&mut self, relaxation: &mut Relaxation) -> Option<f64> {
        let options = &self.search.options;
        if options.max_relaxation_sweeps == 0 {
            return Some(0.0);
        }
        if relaxation.i < self.search.order.len() {
            relaxation.gain += self.search.relax_at(relaxation.i);
            relaxation.i += 1;
            return None;
        }
        relaxation.total += relaxation.gain;
        relaxation.sweep += 1;
        if relaxation.gain < options.delta || relaxation.sweep >= options.max_relaxation_sweeps {
            return Some(relaxation.total);
        }
        relaxation.i = 0;
        relaxation.gain = 0.0;
        None
    }

    /// A descent reached its local optimum: the first one becomes the best; after a shake the
    /// result is kept only if shorter (VNS; idle + W·H with a heat penalty). Then shake again,
    /// or end after `max_non_improving_shakes` fruitless shakes in a row.
    fn descent_done(&mut self) {
        let length = self.search.penalised_length();
        match self.best.take() {
            None => {
                self.best = Some((length, self.search.order.clone(), self.search.place.clone()))
            }
            Some(best) => {
                self.shakes += 1;
                if length < best.0 - self.search.options.delta {
                    self.best =
                        Some((length, self.search.order.clone(), self.search.place.clone()));
                    self.fruitless = 0;
                } else {
                    self.fruitless += 1;
                    self.restore(best.clone());
                    self.best = Some(best);
                }
            }
        }
        if self.fruitless >= self.search.options.max_non_improving_shakes {
            self.stage = Stage::Finished;
            return;
        }
        self.search.shake(&mut self.rng);
        self.stage = Stage::Descending(Descent::NEW);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, ContourRef, SplitMix64, Vertex};

    /// The relaxation's minimiser over a closed segment is never beaten by dense sampling.
    #[test]
    fn best_point_matches_dense_sampling() {
        let mut rng = SplitMix64::new(7);
        // A rounded slot: lines and semicircles; and a circle of two arcs.
        let shapes = [
            Contour::new(vec![
                Vertex::line(0.0, 0.0),
                Vertex::arc(40.0, 0.0, 1.0),
                Vertex::line(40.0, 20.0),
                Vertex::arc(0.0, 20.0, 1.0),
            ]),
            Contour::circle(Point::new(5.0, -3.0), 12.0, true),
        ];
        for shape in shapes {
            let spans: Vec<Span> = shape.spans().collect();
            let segment = Segment::new(
                spans.clone(),
                vec![ContourRef {
                    part: 0,
                    contour: 0,
                }],
                1e-9,
            );
            assert!(segment.closed);
            let boxes: Vec<BoundingBox> = spans.iter().map(Span::bounding_box).collect();
            for _ in 0..200 {
                let a = Point::new(rng.range(-60.0, 100.0), rng.range(-60.0, 80.0));
                let b = Point::new(rng.range(-60.0, 100.0), rng.range(-60.0, 80.0));
                let (_, _, m, value) =
                    best_point(&segment, &boxes, a, Some(b), f64::INFINITY).unwrap();
                assert!((a.distance(m) + m.distance(b) - value).abs() < 1e-9);
                assert!(shape.distance_to(m) < 1e-9);
                let sampled = (0..20_000)
                    .map(|k| {
                        shape
                            .point_at_length(k as f64 / 20_000.0 * shape.perimeter())
                            .unwrap()
                    })
                    .map(|q| a.distance(q) + q.distance(b))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    value <= sampled + 1e-9,
                    "{value} > {sampled} for {a:?}, {b:?}"
                );
            }
        }
    }
}
