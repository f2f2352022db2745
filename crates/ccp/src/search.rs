//! Steps 2 and 3 on the kept contours: the route state (order, pierce points, idle length),
//! relaxation sweeps, the VNS neighbourhoods and move evaluation.
//!
//! A move is described by the route edges it removes and adds. Its *fixed-point delta* (pierce
//! points held) is exact and O(1); since relaxation can only shorten, a negative fixed-point delta
//! is a guaranteed improvement. Otherwise a cheap bound and a one-point-per-junction relaxation
//! estimate decide whether the move is worth an exact check: apply it, relax the junctions with
//! propagation, keep it if the length fell, undo it otherwise.

use std::collections::VecDeque;

use cutroute_geometry::{MachineParameters, Nest, Point};
use cutroute_thermal::{HeatModel, Pierce};

use crate::geom::Shape;
use crate::problem::{nearest_lists, nearest_neighbour_order, Problem};
use crate::relax::{best_on_shape, cost};
use cutroute_geometry::SplitMix64;

/// The start pseudo-node.
pub(crate) const START: i64 = -1;
/// The end pseudo-node (finish point, exit chain, or nothing).
pub(crate) const END: i64 = -2;
/// An improvement must beat this (mm) to count: guards against float noise cycling.
const IMPROVE: f64 = 1e-7;
/// The search's H skips pairs whose kernel is below e⁻¹² (≈ 6·10⁻⁶ each).
const HEAT_MAX_EXPONENT: f64 = 12.0;

/// The heat penalty term of the objective (issue #19): `weight_mm · H` over the route's
/// sources in order (see `HeatPenalty` in the solver).
pub(crate) struct HeatTerm {
    model: HeatModel,
    /// Millimetres of idle per unit of H.
    weight_mm: f64,
    idle_speed: f64,
    /// Per problem contour: the seconds its pierce and cut take.
    busy: Vec<f64>,
    /// Per problem contour: nesting depth among the removed contours (inner ones restored first).
    depth: Vec<usize>,
    /// The current penalty, mm.
    value: f64,
    /// Scratch: per problem contour, the last position of a kept contour inside it.
    last: Vec<i64>,
    events: Vec<(u32, std::cmp::Reverse<usize>, u32)>,
    sources: Vec<Pierce>,
}

/// Tuning of the search (a subset of the public options).
#[derive(Clone, Debug)]
pub(crate) struct SearchParams {
    pub delta: f64,
    pub max_relaxation_sweeps: usize,
    pub neighbours: usize,
    pub cycle_window: usize,
    pub max_block: usize,
    pub reinsert_block: usize,
}

/// A VNS move on positions of the order.
#[derive(Clone, Debug)]
pub(crate) enum Move {
    /// Reverse positions `i..=j`.
    Reverse { i: usize, j: usize },
    /// Move block `i..=j` to after position `k` (`k = -1`: to the front), reversed if `rev`.
    Relocate {
        i: usize,
        j: usize,
        k: isize,
        rev: bool,
    },
    /// Swap the contours at positions `i < j`.
    Swap { i: usize, j: usize },
    /// Exchange the non-adjacent blocks `i..=j` and `k..=l` (`j + 1 < k`).
    Exchange {
        i: usize,
        j: usize,
        k: usize,
        l: usize,
    },
    /// Rewrite the short window starting at `lo` with `new` (cycles, block rotations).
    Window {
        lo: usize,
        len: usize,
        new: [u32; 16],
    },
}

#[derive(Default)]
struct Edges {
    rem: [(i64, i64); 16],
    nr: usize,
    add: [(i64, i64); 16],
    na: usize,
}

impl Edges {
    fn rem(&mut self, a: i64, b: i64) {
        self.rem[self.nr] = (a, b);
        self.nr += 1;
    }
    fn add(&mut self, a: i64, b: i64) {
        self.add[self.na] = (a, b);
        self.na += 1;
    }
}

/// The search state over the kept contours.
pub(crate) struct Search {
    pub prob: Problem,
    pub start: Point,
    pub finish: Option<Point>,
    pub params: SearchParams,
    /// Per kept contour: the removed contours enclosing it, innermost first (open routes exit them).
    pub ancestors: Vec<Vec<usize>>,
    pub knn: Vec<Vec<u32>>,
    pub order: Vec<u32>,
    pub pos: Vec<u32>,
    pub pts: Vec<Point>,
    pub total: f64,
    pub queue: VecDeque<u32>,
    queued: Vec<bool>,
    pub rng: SplitMix64,
    recording: bool,
    saved_pts: Vec<(u32, Point)>,
    saved_slice: Vec<u32>,
    relax_queue: Vec<usize>,
    /// Moves evaluated (fixed-point deltas computed).
    pub evaluations: u64,
    /// Moves checked exactly (applied, relaxed, kept or undone).
    pub exact_checks: u64,
    /// Moves accepted.
    pub accepted: u64,
    /// Best-improvement mode: `try_move` only collects promising moves with their estimate.
    collecting: Option<Vec<(f64, Move)>>,
    /// Explore each neighbourhood fully and apply its best move (instead of the first).
    pub best_improvement: bool,
    /// The heat penalty, when the objective has one (`None`: plain idle length).
    heat: Option<HeatTerm>,
}

impl Search {
    pub fn new(
        prob: Problem,
        start: Point,
        finish: Option<Point>,
        params: SearchParams,
        seed: u64,
    ) -> Search {
        let k = prob.kept.len();
        let mut ancestors = vec![Vec::new(); k];
        for (ki, &c) in prob.kept.iter().enumerate() {
            let mut p = prob.parent[c];
            while let Some(a) = p {
                ancestors[ki].push(a);
                p = prob.parent[a];
            }
        }
        let boxes: Vec<_> = prob.kept.iter().map(|&c| prob.shapes[c].bbox).collect();
        let knn = nearest_lists(&boxes, prob.bounds, params.neighbours);
        Search {
            prob,
            start,
            finish,
            params,
            ancestors,
            knn,
            order: Vec::new(),
            pos: vec![0; k],
            pts: vec![Point::ORIGIN; k],
            total: 0.0,
            queue: VecDeque::new(),
            queued: vec![false; k],
            // CCP-Relax has always started its stream one golden-ratio step off the seed.
            rng: SplitMix64::new(seed ^ 0x9E37_79B9_7F4A_7C15),
            recording: false,
            saved_pts: Vec::new(),
            saved_slice: Vec::new(),
            relax_queue: Vec::new(),
            evaluations: 0,
            exact_checks: 0,
            accepted: 0,
            collecting: None,
            best_improvement: false,
            heat: None,
        }
    }

    /// Adds `weight_mm · H` to the objective.
    pub fn set_heat(
        &mut self,
        nest: &Nest,
        model: HeatModel,
        weight_mm: f64,
        machine: &MachineParameters,
    ) {
        let busy = self
            .prob
            .refs
            .iter()
            .map(|&r| {
                machine.pierce_time
                    + nest.contour(r).map_or(0.0, |c| c.perimeter()) / machine.cut_speed
            })
            .collect();
        let mut depth = vec![0; self.prob.refs.len()];
        for (c, d) in depth.iter_mut().enumerate() {
            let mut p = self.prob.parent[c];
            while let Some(a) = p {
                *d += 1;
                p = self.prob.parent[a];
            }
        }
        self.heat = Some(HeatTerm {
            model,
            weight_mm,
            idle_speed: machine.idle_speed,
            busy,
            depth,
            value: 0.0,
            last: vec![-1; self.prob.refs.len()],
            events: Vec::new(),
            sources: Vec::new(),
        });
        self.refresh_heat();
    }

    /// What the search minimises: the idle length, plus the heat penalty if any.
    #[inline]
    pub fn objective(&self) -> f64 {
        match &self.heat {
            None => self.total,
            Some(h) => self.total + h.value,
        }
    }

    /// Recomputes the heat penalty of the current order and points; returns it (0 without).
    fn refresh_heat(&mut self) -> f64 {
        let Some(mut h) = self.heat.take() else {
            return 0.0;
        };
        // Outer contours come back right after the last kept contour inside them.
        for &r in &self.prob.removed {
            h.last[r] = -1;
        }
        for (p, &k) in self.order.iter().enumerate() {
            for &a in &self.ancestors[k as usize] {
                h.last[a] = p as i64;
            }
        }
        h.events.clear();
        for &r in &self.prob.removed {
            if h.last[r] >= 0 {
                h.events
                    .push((h.last[r] as u32, std::cmp::Reverse(h.depth[r]), r as u32));
            }
        }
        h.events.sort_unstable();
        h.sources.clear();
        let (mut t, mut at, mut e) = (0.0, self.start, 0);
        let visit = |x: Point, c: usize, t: &mut f64, at: &mut Point, sources: &mut Vec<Pierce>| {
            *t += at.fast_distance(x) / h.idle_speed;
            sources.push(Pierce {
                point: Point::new(x.x, x.y),
                time: *t,
            });
            *t += h.busy[c];
            *at = x;
        };
        for (p, &k) in self.order.iter().enumerate() {
            let x = self.pts[k as usize];
            visit(
                x,
                self.prob.kept[k as usize],
                &mut t,
                &mut at,
                &mut h.sources,
            );
            while e < h.events.len() && h.events[e].0 as usize == p {
                let r = h.events[e].2 as usize;
                let y = self.prob.shapes[r].nearest(at);
                visit(y, r, &mut t, &mut at, &mut h.sources);
                e += 1;
            }
        }
        h.value = h.weight_mm * h.model.load_truncated(&h.sources, HEAT_MAX_EXPONENT);
        let value = h.value;
        self.heat = Some(h);
        value
    }

    pub fn len(&self) -> usize {
        self.prob.kept.len()
    }

    #[inline]
    pub fn shape(&self, k: usize) -> &Shape {
        &self.prob.shapes[self.prob.kept[k]]
    }

    /// Builds the initial order by nearest neighbour (randomised when `randomise`).
    pub fn construct(&mut self, randomise: bool) {
        let shapes: Vec<&Shape> = self
            .prob
            .kept
            .iter()
            .map(|&c| &self.prob.shapes[c])
            .collect();
        let mut rng = self.rng.clone();
        let (order, pts) = nearest_neighbour_order(
            &shapes,
            self.prob.bounds,
            self.start,
            if randomise { Some(&mut rng) } else { None },
        );
        self.rng = rng;
        self.order = order;
        self.pts = pts;
        self.reindex(0, self.order.len());
        self.total = self.recompute_total();
        self.refresh_heat();
    }

    fn reindex(&mut self, lo: usize, hi: usize) {
        for p in lo..hi {
            self.pos[self.order[p] as usize] = p as u32;
        }
    }

    #[inline]
    fn node(&self, p: isize) -> i64 {
        if p < 0 {
            START
        } else if p as usize >= self.order.len() {
            END
        } else {
            self.order[p as usize] as i64
        }
    }

    /// The exit chain of kept contour `k` leaving point `x` (open routes only): the nearest point
    /// on each enclosing removed contour in turn. Returns its length.
    pub fn exit_chain(&self, k: usize, x: Point, mut out: Option<&mut Vec<Point>>) -> f64 {
        let mut cur = x;
        let mut len = 0.0;
        for &a in &self.ancestors[k] {
            let y = self.prob.shapes[a].nearest(cur);
            len += cur.fast_distance(y);
            if let Some(o) = out.as_deref_mut() {
                o.push(y);
            }
            cur = y;
        }
        len
    }

    /// The cost of ending the route at kept contour `k` pierced at `x`.
    #[inline]
    pub fn end_cost(&self, k: usize, x: Point) -> f64 {
        match self.finish {
            Some(f) => x.fast_distance(f),
            None if self.ancestors[k].is_empty() => 0.0,
            None => self.exit_chain(k, x, None),
        }
    }

    /// What follows the last contour's point, for the relaxation: the finish, the first exit
    /// point, or nothing.
    fn end_target(&self, k: usize, x: Point) -> Option<Point> {
        match self.finish {
            Some(f) => Some(f),
            None => self.ancestors[k]
                .first()
                .map(|&a| self.prob.shapes[a].nearest(x)),
        }
    }

    #[inline]
    fn w(&self, a: i64, b: i64) -> f64 {
        match (a, b) {
            (START, END) | (END, START) => self.finish.map_or(0.0, |f| self.start.fast_distance(f)),
            (START, k) | (k, START) => self.start.fast_distance(self.pts[k as usize]),
            (k, END) | (END, k) => self.end_cost(k as usize, self.pts[k as usize]),
            (a, b) => self.pts[a as usize].fast_distance(self.pts[b as usize]),
        }
    }

    pub fn recompute_total(&self) -> f64 {
        let n = self.order.len() as isize;
        (-1..n)
            .map(|p| self.w(self.node(p), self.node(p + 1)))
            .sum()
    }

    /// Moves the pierce point at position `i` to its best place; returns how far it moved.
    fn relax_at(&mut self, i: usize) -> f64 {
        let k = self.order[i] as usize;
        let p = if i == 0 {
            self.start
        } else {
            self.pts[self.order[i - 1] as usize]
        };
        let cur = self.pts[k];
        let (old, new, x) = if i + 1 < self.order.len() {
            let q = self.pts[self.order[i + 1] as usize];
            let (v, x) = best_on_shape(self.shape(k), p, Some(q), Some(cur));
            (cost(p, Some(q), cur), v, x)
        } else {
            let q = self.end_target(k, cur);
            let (_, x) = best_on_shape(self.shape(k), p, q, Some(cur));
            (
                p.fast_distance(cur) + self.end_cost(k, cur),
                p.fast_distance(x) + self.end_cost(k, x),
                x,
            )
        };
        if new < old - 1e-12 {
            if self.recording {
                self.saved_pts.push((k as u32, cur));
            }
            self.pts[k] = x;
            self.total -= old - new;
            cur.fast_distance(x)
        } else {
            0.0
        }
    }

    /// One relaxation sweep over the whole order (Algorithm 3.1, lines 5–9); returns the gain.
    /// Contours whose pierce point moved noticeably are queued for the order search.
    pub fn sweep(&mut self) -> f64 {
        let before = self.total;
        for i in 0..self.order.len() {
            if self.relax_at(i) > 1e-3 {
                let k = self.order[i];
                self.push(k);
            }
        }
        self.refresh_heat();
        before - self.total
    }

    /// Sweeps until one sweep gains at most δ (Algorithm 3.1); returns the number of sweeps.
    pub fn relax_full(&mut self) -> usize {
        let mut sweeps = 0;
        loop {
            sweeps += 1;
            let gain = self.sweep();
            if gain <= self.params.delta || sweeps >= self.params.max_relaxation_sweeps {
                return sweeps;
            }
        }
    }

    /// Relaxes the given positions, propagating to neighbours of points that moved.
    fn relax_local(&mut self, seeds: &[usize]) {
        let mut q = std::mem::take(&mut self.relax_queue);
        q.clear();
        q.extend_from_slice(seeds);
        let mut ops = 0;
        let cap = 16 + 8 * seeds.len();
        while let Some(i) = q.pop() {
            ops += 1;
            if ops > cap {
                break;
            }
            let moved = self.relax_at(i);
            if moved > 1e-7 {
                if i > 0 {
                    q.push(i - 1);
                }
                if i + 1 < self.order.len() {
                    q.push(i + 1);
                }
            }
        }
        self.relax_queue = q;
    }

    pub fn push(&mut self, k: u32) {
        if !self.queued[k as usize] {
            self.queued[k as usize] = true;
            self.queue.push_back(k);
        }
    }

    pub fn pop(&mut self) -> Option<u32> {
        let k = self.queue.pop_front()?;
        self.queued[k as usize] = false;
        Some(k)
    }

    pub fn queue_all(&mut self) {
        for p in 0..self.order.len() {
            let k = self.order[p];
            self.push(k);
        }
    }

    fn edges(&self, m: &Move) -> Option<Edges> {
        let n = |p: isize| self.node(p);
        let mut e = Edges::default();
        match *m {
            Move::Reverse { i, j } => {
                if i >= j {
                    return None;
                }
                let (i, j) = (i as isize, j as isize);
                e.rem(n(i - 1), n(i));
                e.rem(n(j), n(j + 1));
                e.add(n(i - 1), n(j));
                e.add(n(i), n(j + 1));
            }
            Move::Relocate { i, j, k, rev } => {
                if i > j || (k >= i as isize - 1 && k <= j as isize) {
                    return None;
                }
                let (i, j) = (i as isize, j as isize);
                let (f, l) = if rev { (n(j), n(i)) } else { (n(i), n(j)) };
                e.rem(n(i - 1), n(i));
                e.rem(n(j), n(j + 1));
                e.rem(n(k), n(k + 1));
                e.add(n(i - 1), n(j + 1));
                e.add(n(k), f);
                e.add(l, n(k + 1));
            }
            Move::Swap { i, j } => {
                if i >= j {
                    return None;
                }
                let (i, j) = (i as isize, j as isize);
                if j == i + 1 {
                    e.rem(n(i - 1), n(i));
                    e.rem(n(i), n(j));
                    e.rem(n(j), n(j + 1));
                    e.add(n(i - 1), n(j));
                    e.add(n(j), n(i));
                    e.add(n(i), n(j + 1));
                } else {
                    e.rem(n(i - 1), n(i));
                    e.rem(n(i), n(i + 1));
                    e.rem(n(j - 1), n(j));
                    e.rem(n(j), n(j + 1));
                    e.add(n(i - 1), n(j));
                    e.add(n(j), n(i + 1));
                    e.add(n(j - 1), n(i));
                    e.add(n(i), n(j + 1));
                }
            }
            Move::Exchange { i, j, k, l } => {
                if !(i <= j && j + 1 < k && k <= l) {
                    return None;
                }
                let (i, j, k, l) = (i as isize, j as isize, k as isize, l as isize);
                e.rem(n(i - 1), n(i));
                e.rem(n(j), n(j + 1));
                e.rem(n(k - 1), n(k));
                e.rem(n(l), n(l + 1));
                e.add(n(i - 1), n(k));
                e.add(n(l), n(j + 1));
                e.add(n(k - 1), n(i));
                e.add(n(j), n(l + 1));
            }
            Move::Window { lo, len, ref new } => {
                let lo_i = lo as isize;
                let old_at = |t: isize| n(lo_i + t);
                let new_at = |t: isize| {
                    if t < 0 || t >= len as isize {
                        n(lo_i + t)
                    } else {
                        new[t as usize] as i64
                    }
                };
                let same = |a: (i64, i64), b: (i64, i64)| a == b || (a.0 == b.1 && a.1 == b.0);
                let mut olds = [(0i64, 0i64); 17];
                let mut news = [(0i64, 0i64); 17];
                for t in -1..len as isize {
                    olds[(t + 1) as usize] = (old_at(t), old_at(t + 1));
                    news[(t + 1) as usize] = (new_at(t), new_at(t + 1));
                }
                let cnt = len + 1;
                for a in 0..cnt {
                    if !news[..cnt].iter().any(|&b| same(olds[a], b)) {
                        e.rem(olds[a].0, olds[a].1);
                    }
                    if !olds[..cnt].iter().any(|&b| same(news[a], b)) {
                        e.add(news[a].0, news[a].1);
                    }
                }
                if e.na == 0 {
                    return None;
                }
            }
        }
        Some(e)
    }

    fn range(&self, m: &Move) -> (usize, usize) {
        match *m {
            Move::Reverse { i, j } | Move::Swap { i, j } => (i, j),
            Move::Relocate { i, j, k, .. } => {
                if k > j as isize {
                    (i, k as usize)
                } else {
                    ((k + 1) as usize, j)
                }
            }
            Move::Exchange { i, l, .. } => (i, l),
            Move::Window { lo, len, .. } => (lo, lo + len - 1),
        }
    }

    fn apply_order(&mut self, m: &Move) {
        match *m {
            Move::Reverse { i, j } => self.order[i..=j].reverse(),
            Move::Relocate { i, j, k, rev } => {
                let len = j - i + 1;
                if k > j as isize {
                    let k = k as usize;
                    self.order[i..=k].rotate_left(len);
                    if rev {
                        self.order[k + 1 - len..=k].reverse();
                    }
                } else {
                    let s = (k + 1) as usize;
                    self.order[s..=j].rotate_right(len);
                    if rev {
                        self.order[s..s + len].reverse();
                    }
                }
            }
            Move::Swap { i, j } => self.order.swap(i, j),
            Move::Exchange { i, j, k, l } => {
                let mut tmp = Vec::with_capacity(l - i + 1);
                tmp.extend_from_slice(&self.order[k..=l]);
                tmp.extend_from_slice(&self.order[j + 1..k]);
                tmp.extend_from_slice(&self.order[i..=j]);
                self.order[i..=l].copy_from_slice(&tmp);
            }
            Move::Window { lo, len, ref new } => {
                self.order[lo..lo + len].copy_from_slice(&new[..len])
            }
        }
        let (lo, hi) = self.range(m);
        self.reindex(lo, hi + 1);
    }

    /// New neighbours of contour `c` under the edge change `e`.
    fn new_neighbours(&self, c: i64, e: &Edges) -> (Option<i64>, Option<i64>) {
        let p = self.pos[c as usize] as isize;
        let mut nb: [Option<i64>; 4] = [Some(self.node(p - 1)), Some(self.node(p + 1)), None, None];
        for &(a, b) in &e.rem[..e.nr] {
            let other = if a == c {
                b
            } else if b == c {
                a
            } else {
                continue;
            };
            if let Some(s) = nb.iter_mut().find(|s| **s == Some(other)) {
                *s = None;
            }
        }
        for &(a, b) in &e.add[..e.na] {
            let other = if a == c {
                b
            } else if b == c {
                a
            } else {
                continue;
            };
            if let Some(s) = nb.iter_mut().find(|s| s.is_none()) {
                *s = Some(other);
            }
        }
        let mut it = nb.into_iter().flatten();
        (it.next(), it.next())
    }

    /// Evaluates a move; applies it when it shortens the route (after local relaxation).
    pub fn try_move(&mut self, m: &Move) -> bool {
        let Some(e) = self.edges(m) else { return false };
        self.evaluations += 1;
        let d0: f64 = e.add[..e.na]
            .iter()
            .map(|&(a, b)| self.w(a, b))
            .sum::<f64>()
            - e.rem[..e.nr]
                .iter()
                .map(|&(a, b)| self.w(a, b))
                .sum::<f64>();
        let mut junctions = [0i64; 12];
        let mut nj = 0;
        for &(a, b) in &e.add[..e.na] {
            for x in [a, b] {
                if x >= 0 && !junctions[..nj].contains(&x) {
                    junctions[nj] = x;
                    nj += 1;
                }
            }
        }
        let mut estimate = d0;
        // With a heat penalty a longer route may still be better: every move is checked.
        if d0 >= -IMPROVE && self.heat.is_none() {
            // Estimate what relaxing each junction could win against its new neighbours.
            let mut targets = [(Point::ORIGIN, None::<Point>, 0usize); 12];
            let mut ub = 0.0;
            for (t, &c) in junctions[..nj].iter().enumerate() {
                let (a, b) = self.new_neighbours(c, &e);
                let cur = self.pts[c as usize];
                let at = |x: Option<i64>| -> Option<Point> {
                    match x {
                        Some(START) => Some(self.start),
                        Some(END) | None => self.end_target(c as usize, cur),
                        Some(k) => Some(self.pts[k as usize]),
                    }
                };
                let (p, q) = match (a, b) {
                    (Some(END), other) | (other, Some(END)) => {
                        (at(other).unwrap_or(cur), at(Some(END)))
                    }
                    (a, b) => (at(a).unwrap_or(cur), at(b)),
                };
                let here = cost(p, q, cur);
                // Nothing on the contour beats the distances to its bounding box, nor |PQ|.
                let bb = &self.shape(c as usize).bbox;
                let lower = match q {
                    Some(q) => p
                        .fast_distance(q)
                        .max(bb.gap_to_point(p).fast_norm() + bb.gap_to_point(q).fast_norm()),
                    None => bb.gap_to_point(p).fast_norm(),
                };
                ub += here - lower;
                targets[t] = (p, q, c as usize);
            }
            if d0 - ub >= -IMPROVE {
                return false;
            }
            let mut gain = 0.0;
            for &(p, q, c) in &targets[..nj] {
                let cur = self.pts[c];
                let (v, _) = best_on_shape(self.shape(c), p, q, Some(cur));
                gain += cost(p, q, cur) - v;
            }
            if d0 - gain >= -IMPROVE {
                return false;
            }
            estimate = d0 - gain;
        }
        if let Some(list) = self.collecting.as_mut() {
            list.push((estimate, m.clone()));
            return false;
        }
        // Exact check: apply, relax the junctions, keep or undo.
        self.exact_checks += 1;
        let before = self.total;
        let before_objective = self.objective();
        let heat_before = self.heat.as_ref().map(|h| h.value);
        let (lo, hi) = self.range(m);
        self.saved_slice.clear();
        self.saved_slice.extend_from_slice(&self.order[lo..=hi]);
        self.saved_pts.clear();
        self.recording = true;
        self.apply_order(m);
        self.total += d0;
        let mut seeds = [0usize; 12];
        for t in 0..nj {
            seeds[t] = self.pos[junctions[t] as usize] as usize;
        }
        self.relax_local(&seeds[..nj]);
        self.recording = false;
        let improved = if self.heat.is_some() {
            self.total + self.refresh_heat() < before_objective - IMPROVE
        } else {
            self.total < before - IMPROVE
        };
        if improved {
            self.accepted += 1;
            for &c in &junctions[..nj] {
                let p = self.pos[c as usize] as isize;
                self.push(c as u32);
                for q in [p - 1, p + 1] {
                    let nq = self.node(q);
                    if nq >= 0 {
                        self.push(nq as u32);
                    }
                }
            }
            true
        } else {
            self.order[lo..=hi].copy_from_slice(&self.saved_slice);
            self.reindex(lo, hi + 1);
            while let Some((k, x)) = self.saved_pts.pop() {
                self.pts[k as usize] = x;
            }
            self.total = before;
            if let (Some(h), Some(value)) = (self.heat.as_mut(), heat_before) {
                h.value = value;
            }
            false
        }
    }

    /// Applies a move unconditionally (for shaking): the length may grow.
    pub fn force_move(&mut self, m: &Move) -> bool {
        let Some(e) = self.edges(m) else { return false };
        let d0: f64 = e.add[..e.na]
            .iter()
            .map(|&(a, b)| self.w(a, b))
            .sum::<f64>()
            - e.rem[..e.nr]
                .iter()
                .map(|&(a, b)| self.w(a, b))
                .sum::<f64>();
        self.apply_order(m);
        self.total += d0;
        let mut seeds = Vec::new();
        for &(a, b) in &e.add[..e.na] {
            for x in [a, b] {
                if x >= 0 {
                    seeds.push(self.pos[x as usize] as usize);
                    self.push(x as u32);
                }
            }
        }
        self.relax_local(&seeds);
        self.refresh_heat();
        true
    }

    /// Number of neighbourhoods.
    pub const NEIGHBOURHOODS: usize = 8;

    /// Tries neighbourhood `nb` anchored at contour `c`; true when a move was accepted.
    pub fn explore(&mut self, nb: usize, c: u32) -> bool {
        let n = self.order.len();
        let i = self.pos[c as usize] as usize;
        let knn = std::mem::take(&mut self.knn[c as usize]);
        if self.best_improvement {
            self.collecting = Some(Vec::new());
        }
        let found = match nb {
            0 => self.nb_relocate(i, &knn, n),
            1 => self.nb_two_opt(i, &knn),
            2 => self.nb_swap(i, &knn, n),
            3 => self.nb_exchange(i, &knn, n),
            4 => self.nb_cycle3(i, n),
            5 => self.nb_cycle4(i, n),
            6 => self.nb_rotate_blocks(i, n),
            _ => self.nb_reinsert(i, n),
        };
        self.knn[c as usize] = knn;
        if let Some(mut list) = self.collecting.take() {
            // Best improvement: the most promising moves by estimate, checked exactly.
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            return list.iter().take(3).any(|(_, m)| self.try_move(m));
        }
        found
    }

    /// Block shift: move a block of 1..=max_block contours holding position `i` next to a
    /// spatial neighbour of one of its ends, in either orientation.
    fn nb_relocate(&mut self, i: usize, _knn: &[u32], n: usize) -> bool {
        for len in 1..=self.params.max_block.min(n) {
            for (bi, bj) in [(i, i + len - 1), (i.saturating_sub(len - 1), i)] {
                if bj >= n || bj + 1 - bi != len {
                    continue;
                }
                for end in [bi, bj] {
                    let e = self.order[end] as usize;
                    for t in 0..self.knn[e].len() {
                        let b = self.knn[e][t] as usize;
                        let pb = self.pos[b] as isize;
                        if pb >= bi as isize && pb <= bj as isize {
                            continue;
                        }
                        for k in [pb, pb - 1] {
                            for rev in [false, true] {
                                if len == 1 && rev {
                                    continue;
                                }
                                if self.try_move(&Move::Relocate {
                                    i: bi,
                                    j: bj,
                                    k,
                                    rev,
                                }) {
                                    return true;
                                }
                            }
                        }
                    }
                }
                if len == 1 {
                    break;
                }
            }
        }
        false
    }

    /// Block reversal (2-opt): make contour `i` adjacent to a spatial neighbour.
    fn nb_two_opt(&mut self, i: usize, knn: &[u32]) -> bool {
        for &b in knn {
            let j = self.pos[b as usize] as usize;
            let cands = if i < j {
                [(i + 1, j), (i, j - 1)]
            } else {
                [(j + 1, i), (j, i.wrapping_sub(1))]
            };
            for (x, y) in cands {
                if x < y && y < self.order.len() && self.try_move(&Move::Reverse { i: x, j: y }) {
                    return true;
                }
            }
        }
        // Reversing the tail lets an open route end elsewhere.
        let n = self.order.len();
        if self.finish.is_none()
            && i + 1 < n
            && self.try_move(&Move::Reverse { i: i + 1, j: n - 1 })
        {
            return true;
        }
        false
    }

    /// Pairwise exchange: put contour `i` next to a spatial neighbour by swapping.
    fn nb_swap(&mut self, i: usize, knn: &[u32], n: usize) -> bool {
        for &b in knn {
            let j = self.pos[b as usize] as usize;
            for t in [j.wrapping_sub(1), j + 1] {
                if t < n
                    && t != i
                    && self.try_move(&Move::Swap {
                        i: i.min(t),
                        j: i.max(t),
                    })
                {
                    return true;
                }
            }
        }
        false
    }

    /// Exchange of two non-adjacent blocks; the second block is chosen so that contour `i`'s
    /// block lands next to one of its spatial neighbours.
    fn nb_exchange(&mut self, i: usize, knn: &[u32], n: usize) -> bool {
        let maxb = self.params.max_block;
        for l1 in 1..=maxb {
            let j = i + l1 - 1;
            if j >= n {
                break;
            }
            for &b in knn {
                let pb = self.pos[b as usize] as usize;
                // Block 2 starts right after b, so block 1 follows b after the exchange.
                let k = pb + 1;
                for l2 in 1..=maxb {
                    let l = k + l2 - 1;
                    if k > j + 1 && l < n && self.try_move(&Move::Exchange { i, j, k, l }) {
                        return true;
                    }
                    // Or block 2 lies before block 1 and starts right after b.
                    let (k2, l2e) = (pb + 1, pb + l2);
                    if l2e + 1 < i
                        && self.try_move(&Move::Exchange {
                            i: k2,
                            j: l2e,
                            k: i,
                            l: j,
                        })
                    {
                        return true;
                    }
                }
            }
        }
        false
    }

    fn window_move(&self, lo: usize, content: &[u32]) -> Move {
        let mut new = [0u32; 16];
        new[..content.len()].copy_from_slice(content);
        Move::Window {
            lo,
            len: content.len(),
            new,
        }
    }

    /// Cyclic permutations of 3 contours at most `cycle_window` apart in the order.
    fn nb_cycle3(&mut self, i: usize, n: usize) -> bool {
        let w = self.params.cycle_window;
        for j in i + 1..=(i + w).min(n - 1) {
            for l in j + 1..=(i + w).min(n - 1) {
                let (a, b, c) = (self.order[i], self.order[j], self.order[l]);
                for (x, y, z) in [(b, c, a), (c, a, b)] {
                    let mut content: Vec<u32> = self.order[i..=l].to_vec();
                    content[0] = x;
                    content[j - i] = y;
                    content[l - i] = z;
                    let m = self.window_move(i, &content);
                    if self.try_move(&m) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Cyclic permutations of 4 contours at most `cycle_window` apart in the order.
    fn nb_cycle4(&mut self, i: usize, n: usize) -> bool {
        let w = self.params.cycle_window;
        const CYCLES: [[usize; 4]; 6] = [
            [1, 2, 3, 0],
            [3, 0, 1, 2],
            [1, 3, 0, 2],
            [2, 0, 3, 1],
            [2, 3, 1, 0],
            [3, 2, 0, 1],
        ];
        let hi = (i + w).min(n - 1);
        for j in i + 1..=hi {
            for l in j + 1..=hi {
                for m in l + 1..=hi {
                    let ps = [i, j, l, m];
                    let els = ps.map(|p| self.order[p]);
                    for cyc in CYCLES {
                        let mut content: Vec<u32> = self.order[i..=m].to_vec();
                        for t in 0..4 {
                            content[ps[t] - i] = els[cyc[t]];
                        }
                        let mv = self.window_move(i, &content);
                        if self.try_move(&mv) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }

    /// Cyclic rotation of three consecutive blocks of equal length (1..=4) starting at `i`.
    fn nb_rotate_blocks(&mut self, i: usize, n: usize) -> bool {
        for len in 1..=4 {
            if i + 3 * len > n {
                break;
            }
            let s = &self.order[i..i + 3 * len];
            let (b1, b2, b3) = (&s[..len], &s[len..2 * len], &s[2 * len..]);
            let r1: Vec<u32> = [b2, b3, b1].concat();
            let r2: Vec<u32> = [b3, b1, b2].concat();
            for content in [r1, r2] {
                let m = self.window_move(i, &content);
                if self.try_move(&m) {
                    return true;
                }
            }
        }
        false
    }

    /// Optimal re-insertion of a longer block starting at `i`: the best of all candidate places
    /// (next to spatial neighbours of its ends, both orientations) by fixed-point delta.
    fn nb_reinsert(&mut self, i: usize, n: usize) -> bool {
        let lo = self.params.max_block + 1;
        for len in lo..=self.params.reinsert_block {
            let j = i + len - 1;
            if j >= n {
                break;
            }
            let mut best: Option<(f64, Move)> = None;
            for end in [i, j] {
                let e = self.order[end] as usize;
                for t in 0..self.knn[e].len() {
                    let pb = self.pos[self.knn[e][t] as usize] as isize;
                    if pb >= i as isize && pb <= j as isize {
                        continue;
                    }
                    for k in [pb, pb - 1] {
                        for rev in [false, true] {
                            let m = Move::Relocate { i, j, k, rev };
                            if let Some(ed) = self.edges(&m) {
                                let d0: f64 = ed.add[..ed.na]
                                    .iter()
                                    .map(|&(a, b)| self.w(a, b))
                                    .sum::<f64>()
                                    - ed.rem[..ed.nr]
                                        .iter()
                                        .map(|&(a, b)| self.w(a, b))
                                        .sum::<f64>();
                                if best.as_ref().is_none_or(|b| d0 < b.0) {
                                    best = Some((d0, m));
                                }
                            }
                        }
                    }
                }
            }
            if let Some((_, m)) = best {
                if self.try_move(&m) {
                    return true;
                }
            }
        }
        false
    }

    /// A random move inside a window of the order around `centre` (VNS shaking).
    pub fn random_move(&mut self, centre: usize, span: usize) -> Option<Move> {
        let n = self.order.len();
        if n < 4 {
            return None;
        }
        let lo = centre.saturating_sub(span / 2).min(n - 1);
        let hi = (lo + span).min(n - 1);
        if hi <= lo + 2 {
            return None;
        }
        let width = hi - lo + 1;
        let a = lo + self.rng.index_below(width);
        let b = lo + self.rng.index_below(width);
        let (x, y) = (a.min(b), a.max(b));
        if x == y {
            return None;
        }
        Some(match self.rng.index_below(3) {
            0 => Move::Reverse { i: x, j: y },
            1 => {
                let len = 1 + self.rng.index_below(3).min(y - x - 1);
                Move::Relocate {
                    i: x,
                    j: x + len - 1,
                    k: y as isize,
                    rev: self.rng.index_below(2) == 1,
                }
            }
            _ => {
                let l1 = 1 + self.rng.index_below(2);
                if x + l1 + 1 > y {
                    return None;
                }
                Move::Exchange {
                    i: x,
                    j: x + l1 - 1,
                    k: y,
                    l: y,
                }
            }
        })
    }

    /// A copy of the route state; its third element is the objective (the idle length when
    /// there is no heat penalty).
    pub fn snapshot(&self) -> (Vec<u32>, Vec<Point>, f64) {
        (self.order.clone(), self.pts.clone(), self.objective())
    }

    /// Restores a copy made by `snapshot`.
    pub fn restore(&mut self, snap: &(Vec<u32>, Vec<Point>, f64)) {
        self.order.clone_from(&snap.0);
        self.pts.clone_from(&snap.1);
        self.reindex(0, self.order.len());
        if self.heat.is_some() {
            self.total = self.recompute_total();
            self.refresh_heat();
        } else {
            self.total = snap.2;
        }
        while self.pop().is_some() {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relaxation_never_increases_length() {
        let nest = cutroute_geometry::generate_nest(150, 11);
        for finish in [None, Some(Point::new(0.0, 0.0))] {
            let prob = Problem::new(&nest, Point::ORIGIN, finish);
            let params = SearchParams {
                delta: 1e-9,
                max_relaxation_sweeps: 1000,
                neighbours: 6,
                cycle_window: 4,
                max_block: 3,
                reinsert_block: 6,
            };
            let mut s = Search::new(prob, Point::ORIGIN, finish, params, 3);
            let n = s.len();
            // A random order and arbitrary pierce points (first vertices).
            let mut order: Vec<u32> = (0..n as u32).collect();
            for i in (1..n).rev() {
                let j = s.rng.index_below(i + 1);
                order.swap(i, j);
            }
            s.order = order;
            s.pts = (0..n).map(|k| s.shape(k).spans[0].a()).collect();
            s.reindex(0, n);
            s.total = s.recompute_total();
            for _ in 0..3000 {
                let i = s.rng.index_below(n);
                let before = s.total;
                s.relax_at(i);
                assert!(s.total <= before + 1e-12);
            }
            assert!((s.total - s.recompute_total()).abs() < 1e-6);
            let before = s.total;
            s.relax_full();
            assert!(s.total <= before + 1e-12);
            assert!((s.total - s.recompute_total()).abs() < 1e-6);
            // Every pierce point lies on its contour.
            for k in 0..n {
                let x = s.pts[k];
                assert!(s.shape(k).nearest(x).fast_distance(x) < 1e-7);
            }
        }
    }

    #[test]
    fn accepted_moves_keep_the_running_length_exact() {
        let nest = cutroute_geometry::generate_nest(120, 4);
        let prob = Problem::new(&nest, Point::ORIGIN, None);
        let params = SearchParams {
            delta: 1e-9,
            max_relaxation_sweeps: 1000,
            neighbours: 6,
            cycle_window: 4,
            max_block: 3,
            reinsert_block: 6,
        };
        let mut s = Search::new(prob, Point::ORIGIN, None, params, 5);
        s.construct(false);
        s.relax_full();
        s.queue_all();
        while let Some(c) = s.pop() {
            for nb in 0..Search::NEIGHBOURHOODS {
                if s.explore(nb, c) {
                    s.push(c);
                    break;
                }
            }
        }
        assert!(s.accepted > 0);
        assert!(
            (s.total - s.recompute_total()).abs() < 1e-6,
            "{} vs {}",
            s.total,
            s.recompute_total()
        );
        let mut seen = s.order.clone();
        seen.sort();
        assert_eq!(seen, (0..s.len() as u32).collect::<Vec<_>>());
        assert!(s
            .order
            .iter()
            .enumerate()
            .all(|(p, &k)| s.pos[k as usize] as usize == p));
    }
}
