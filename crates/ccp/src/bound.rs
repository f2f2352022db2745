//! A certified lower bound on the idle length of continuous cutting (CCP): the *interval
//! relaxation*, solved by `cutroute-pcgtsp`'s exact machinery and refined adaptively.
//!
//! Why it is sound, step by step (the objective is the route's idle length: start → pierce
//! points in order → finish if any, as [`crate::idle_length`] measures it):
//!
//! 1. **Only the innermost contours** (the leaves of the containment forest) are kept. Removing
//!    the other pierce points from a route's air polyline can only shorten it (triangle
//!    inequality). After the last kept contour the route still has to reach the outermost
//!    contour around it (holes before their outer contour), and the finish: that tail costs at
//!    least `max(d(piece, finish), d(piece, outermost) + d(outermost, finish))`, or
//!    `d(piece, outermost)` on an open route. Leaves have no precedence among themselves. (The
//!    relaxation loses nothing here: CCP-Relax restores outer contours at the route's last
//!    crossing with them at no extra length.)
//! 2. **Pieces**: each kept contour is split into arcs of the contour (intervals of arc
//!    length). A pierce point lies in one piece, and the tool enters and leaves the contour
//!    there, so charging each idle move by the least distance between the piece it leaves and
//!    the piece it enters ([`Span::distance_to_span`]) can only undercount. That is a PCGTSP
//!    (clusters = kept contours, nodes = pieces, depot = the start point, the return arc = the
//!    tail above) whose optimum is at most the continuous optimum, for any pieces.
//! 3. Any proven lower bound of that PCGTSP (`ExactSolver::progress().lower_bound`: assignment,
//!    Lagrangian, position and lattice bounds, the DP over ideals) is therefore a lower bound
//!    for the continuous problem. Each arc cost is lowered by a tiny margin so that rounding
//!    in the distance computations cannot lift it above the true set distance.
//!
//! **Chain cutting** ([`LinkPrices`]): where a contour may also be entered by a tool-on link
//! from a sibling, each move of the relaxation is priced as the cheapest way to make it (a
//! link, or an idle move and a pierce) instead of by its length, and the bound is on the
//! route's cost less the cut of its perimeters (no spatial groups then).
//!
//! **Fixed candidates** ([`CcpLowerBound::for_candidates`]): for routes that pierce only at
//! given points (a discretised nest's candidates), each piece is a tiny arc around one
//! candidate instead, so the relaxed PCGTSP is the discrete instance restricted to the kept
//! contours (with the tail above) and there is nothing to refine: one stage, solved until
//! it ends. Its optimum lies between the continuous relaxation's and the discrete optimum.
//! A node is then a point, entered and left at the same place, so the relaxation loses none
//! of the "enter a piece at one end, leave at the other" that caps the continuous one: with
//! more kept contours than `ng_above` the ng-path bound runs on it as below (nested.dbs at
//! 25 mm: 9,086 in 60 s against the continuous bound's ~7,950, a discrete route of 9,632).
//!
//! **Decomposition by spatial groups** (nests of more than `decompose_above` kept contours):
//! the kept contours are split into compact groups of at most `group_size` (the holes of one
//! part together), and each group's region `R_G` is the set of points nearer to its contours
//! than to any other group's (the regions partition the plane). A route's length is the sum of
//! its lengths inside the regions, and inside `R_G` it is at least the relaxation above over
//! `G`'s contours alone with every cost `c(a, b)` replaced by `min(c(a, b), e(a) + e(b))`,
//! where the *escape* `e(a)` = half the distance from piece `a` to the nearest contour of
//! another group bounds the way from `a` to the region's border (a border point `q` is no
//! nearer to `G` than to some other group `H`, so `d(a, H) ≤ d(a, q) + d(q, H) ≤ 2·d(a, q)`):
//! between two consecutive pierce points of `G` the route stays inside (`c(a, b)`) or leaves
//! and comes back (`≥ e(a) + e(b)` inside); the first is reached from the start or the border,
//! the tail after the last one runs inside or leaves. Each group is small enough to be solved
//! exactly, so the sum of the groups' bounds is a certified bound; the reported bound is the
//! larger of it and the whole relaxation's. What it loses is the travel across the group
//! borders, little where groups are separated by space, much on tightly packed sheets. Where
//! nothing solves the whole relaxation (more kept contours than the exact search's keys hold),
//! the groups are the bound; where the small groups' first sum shows that their borders lose
//! most of the route (`wide_below`: tightly packed sheets), wide groups (`wide_group_size`)
//! that run the ng-path bound below take over: fewer borders lose less than small groups
//! solved exactly gain.
//!
//! **The ng-path bound** ([`NgPathBound`], more kept contours than `ng_above`) runs on the whole
//! relaxation's instance beside its exact search, and, with `ng_alone`, alone where the exact
//! search cannot run (more kept contours than its keys hold, `exact_max_kept`); any lower bound
//! of that PCGTSP is sound by step 3. Its neighbourhoods are `ng_size` contours in the first
//! stage and `ng_refined_size` in the later ones, which start from the earlier penalties (the
//! clusters stay the same).
//!
//! **Refinement.** A stage builds the instance (row by row, in slices), then runs the exact
//! solver for a doubling time share (or a doubling share of work, `stage_work`). Then the pieces relaxed tours visit are split in order of
//! importance until the node limit: with the ng-path bound first the cheapest tours of the
//! relaxation itself ([`crate::relaxed_tours`]: an iterated local search with the pieces
//! re-chosen by a layered shortest path, run in every eighth slice; a relaxed tour that enters
//! a long piece at one end and leaves at the other is where the relaxed optimum lies below the
//! route), then the best route, the exact search's relaxed tour and the ng-path bound's walk;
//! and the next stage starts. With the ng-path bound a visited piece is cut once, halfway
//! between its points nearest to the tour's previous and next pieces (where the relaxation
//! charges the move in and the move out), else it is split in four; its neighbours along the
//! contour are halved. Finer pieces only raise the relaxed optimum; the reported bound is the
//! best over all stages.
//!
//! ```
//! use cutroute_ccp::{CcpLowerBound, LowerBoundOptions};
//! use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};
//! use web_time::Duration;
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
//! let options = LowerBoundOptions { start: Point::new(-10.0, 5.0), ..Default::default() };
//! let mut bound = CcpLowerBound::new(&nest, options).unwrap();
//! while bound.step(Duration::from_millis(50)) && bound.stages() < 4 {}
//! // The best route is 50 mm (the straight line through the squares); the bound is below it.
//! assert!(bound.lower_bound() <= 50.0 + 1e-9);
//! assert!(bound.lower_bound() >= 49.0);
//! ```

use std::collections::HashMap;
use std::sync::Arc;

use cutroute_geometry::{
    is_scrap_region, BoundingBox, Contour, ContourRef, Nest, Point, Route, Span,
};
use cutroute_pcgtsp::{AnytimeSolver, ExactOptions, ExactSolver, Instance, Status};
use web_time::{Duration, Instant};

use crate::ngpath::{NgPathBuilder, MAX_NG};
use crate::relaxed_tours::RelaxedTourSearch;
use crate::{CcpError, NgPathBound};

/// How much each relaxed arc cost is lowered so that rounding in the distance maths (true
/// distances between computed points, at most a few ulps above the exact set distance) can
/// never lift it above the true value; relative to the nest's size.
const COST_MARGIN: f64 = 1e-9;

/// Most entries of a relaxation's dense cost matrix (2²⁴ f64, 128 MiB): beyond it a stage is
/// not built and the bound keeps what it has, so a sheet of 100,000 contours cannot ask for a
/// 137 GB matrix (it did, and aborted the process) and the browser's worker stays in memory.
pub const MAX_RELAXATION_ENTRIES: usize = 1 << 24;

/// Most nodes of a relaxation whose dense matrix fits [`MAX_RELAXATION_ENTRIES`].
const MAX_RELAXATION_NODES: usize = 1 << 12;

/// First pieces of a relaxation that runs the ng-path bound.
const NG_INITIAL_PIECES: usize = 1600;

/// Most nodes of a relaxation that runs the ng-path bound without the exact search: one DP
/// pass over Nest02's 359 kept contours took ~2 s at 824 nodes, ~5 s at 1,627 and over 20 s
/// at 2,500, and the subgradient needs many passes.
const NG_ALONE_MAX_NODES: usize = 1200;

/// Passes of the ng-path bound at fixed candidates before the largest neighbourhoods
/// ([`MAX_NG`]) take over with its penalties.
const ESCALATE_PASSES: usize = 24;

/// Most groups of the decomposition bound.
const MAX_GROUPS: usize = 64;

/// Node limit of a group's relaxation with the ng-path bound (wide groups): their DP passes
/// are what limits them, not their pieces (on Nest02, groups of 90 in 60 s of the bound's own
/// time: 14,800 at 4,000 nodes, 15,357–16,074 at 2,500, 16,746–16,784 at 2,000, 16,524 at
/// 1,700).
const GROUP_NG_MAX_NODES: usize = 2000;

/// Most kept contours for which the whole relaxation's exact search runs (its keys hold at
/// most 256 clusters).
const EXACT_MAX_KEPT: usize = 256;

/// Settings of [`CcpLowerBound`].
#[derive(Clone, Debug, PartialEq)]
pub struct LowerBoundOptions {
    /// Where the route starts.
    pub start: Point,
    /// Where it ends with an idle move (`None`: open route, it ends at its last cut).
    pub finish: Option<Point>,
    /// Pieces in the first stage, shared among the kept contours by perimeter (at least 2
    /// each).
    pub initial_pieces: usize,
    /// Refinement stops adding pieces at this many PCGTSP nodes (the cost matrix is dense);
    /// relaxations that run the ng-path bound beside the exact search use `ng_max_nodes`.
    pub max_nodes: usize,
    /// Memory the exact solver of a stage may use.
    pub memory_limit_bytes: usize,
    /// Time share of the first stage's exact search; each later stage gets twice the previous.
    pub first_stage: Duration,
    /// Measure stages by work instead of `first_stage` (`None`: by time). What a stage of
    /// time finds depends on how much CPU the machine gives it; a stage of work finds the same
    /// on any machine, which is what tests of the bound's strength assert.
    pub stage_work: Option<StageWork>,
    /// Seconds the whole computation is expected to run: the exact solver sizes its bounds'
    /// work for it (the lattice of ideals is built only when there is time for it).
    pub budget_seconds: f64,
    /// Most kept contours per group of the decomposition bound (see the module
    /// documentation); with more kept contours than this the bound also runs one relaxation
    /// per group and reports the larger of the whole relaxation's bound and the groups' sum.
    /// 0: no decomposition.
    pub group_size: usize,
    /// Most kept contours per group where the whole relaxation is not solved (more kept
    /// contours than the exact search's keys hold, without `ng_alone`): the groups are then
    /// the whole bound, and groups this large run the ng-path bound, which loses far less at
    /// fewer borders than small groups solved exactly gain inside them (Nest02 in 100 s of the
    /// bound's own time: groups of 16 reached 13,501, of 60 16,944, of 90 17,471, of 130
    /// 16,643; BENCHMARKS.md). They take over from the small groups only where these lose
    /// much (`wide_below`); 0 or at most `group_size`: never.
    pub wide_group_size: usize,
    /// Where wide groups may take over: once every small group has run a short probe stage,
    /// they give way to wide ones if their sum is below this share of the best route offered.
    /// Small groups lose the travel across their borders, which on a tightly packed sheet is
    /// most of it (Nest02: 0.22 of its route after their probes, 0.36 with four
    /// times the share), and little where parts lie apart (a generated 1,000-contour sheet:
    /// 0.67 and 0.72; there wide groups, whose stages take longer, reached 18,124 in 40 s
    /// against the small ones' 22,240). The best sum of the small groups stays a bound.
    pub wide_below: f64,
    /// Decompose only with more kept contours than this: up to about 22 the whole relaxation
    /// is solved exactly stage after stage and converges on its own, and groups would only
    /// take its time.
    pub decompose_above: usize,
    /// Clusters per neighbourhood of the ng-path bound ([`crate::NgPathBound`]) run on the
    /// relaxation beside the exact search; 0: none.
    pub ng_size: usize,
    /// Clusters per neighbourhood from the second stage on (at most [`MAX_NG`]); 0: `ng_size`
    /// in every stage. The first stage's small neighbourhoods set the penalties in quick
    /// passes; on the finer pieces after it, wider ones forbid more of the short loops among
    /// neighbours that the relaxation otherwise takes (nested.dbs in 60 s: 8,524 with 8
    /// throughout, 8,650 with 10, 8,621 with 12, 8,625–8,702 with 8 then 10; BENCHMARKS.md).
    /// Wide groups keep `ng_size`: their passes are few, and 10 lowered Nest03's sum by 7 %.
    pub ng_refined_size: usize,
    /// Run the ng-path bound only on relaxations of more kept contours than this (up to about
    /// 22 the exact search solves each stage, and the ng-path bound would only take its time).
    pub ng_above: usize,
    /// Most kept contours for which the whole relaxation runs the exact search (at most 256,
    /// its keys' width); above, the whole relaxation runs the ng-path bound alone when
    /// `ng_alone` is set, or not at all. Lower values are for tests of that path.
    pub exact_max_kept: usize,
    /// Run the whole relaxation with the ng-path bound alone above `exact_max_kept` kept
    /// contours. Off by default: on Nest02/Nest03 (359 kept contours) its DP passes take
    /// seconds, it reached 3,400–4,000 in 120 s against the groups' 12,000–12,800, and the
    /// slices it took lowered the groups' sum (BENCHMARKS.md).
    pub ng_alone: bool,
    /// Chain cutting: a route may also enter a contour by a tool-on link from the previous one
    /// (see [`LinkPrices`]), and the bound is on the moves' prices instead of idle length.
    /// `None`: every move is idle, the bound is in mm.
    pub links: Option<LinkPrices>,
    /// Node limit of the refinement instead of `max_nodes` for relaxations that run the
    /// ng-path bound beside the exact search (more kept contours than `ng_above`); at most
    /// 4,096 (the dense matrix's [`MAX_RELAXATION_ENTRIES`]). Their DP passes are fast
    /// enough for more pieces than the exact search alone: on nested.dbs 4,000 raised the
    /// 60 s bound from ~8,360 to ~8,490 (BENCHMARKS.md).
    pub ng_max_nodes: usize,
}

/// The work of a first stage when stages are measured by work ([`LowerBoundOptions::stage_work`]):
/// the stage ends once each of its searches has done its share, or has ended, or does not run.
/// Each later stage gets twice the previous one's, as with time shares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StageWork {
    /// States the exact search creates.
    pub exact_states: u64,
    /// Passes of the ng-path bound's subgradient.
    pub ng_passes: usize,
}

impl StageWork {
    /// This work times `2^doublings`, divided by `divisor` (at least one state and one pass).
    fn scaled(self, doublings: usize, divisor: u64) -> StageWork {
        let times = 1u64 << doublings.min(16);
        StageWork {
            exact_states: (self.exact_states.saturating_mul(times) / divisor).max(1),
            ng_passes: ((self.ng_passes as u64).saturating_mul(times) / divisor).max(1) as usize,
        }
    }
}

/// Prices of the moves between pierce points of chain cutting (`cutroute-chains`), per mm and
/// per pierce in the unit of the route's cost. A contour is entered either by an idle move and
/// a pierce, or, from a sibling in one scrap region (children of the sheet or of one hole), by a
/// tool-on link that is at least as long as the straight distance and leaves it where it
/// entered. So a move of straight length `d` between two kept contours costs at least
/// [`LinkPrices::between_siblings`] (siblings) or [`LinkPrices::pierced`] (others: the way
/// between them has a pierce), and both prices are increasing and subadditive, so dropping the
/// outer contours from the route (step 1 of the module documentation) still only lowers it.
/// With these prices the relaxation bounds the route's cost less the cut of its perimeters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkPrices {
    /// Per mm of idle travel.
    pub idle_per_mm: f64,
    /// Per mm of cut (a link is cut).
    pub cut_per_mm: f64,
    /// Per pierce.
    pub pierce: f64,
}

impl LinkPrices {
    /// The least price of a move of straight length `d` into a sibling in one scrap region:
    /// a link, or an idle move and a pierce.
    pub fn between_siblings(&self, d: f64) -> f64 {
        (self.cut_per_mm * d).min(self.idle_per_mm * d + self.pierce)
    }

    /// The least price of a way of straight length `d` that has a pierce on it (into a
    /// contour that is no sibling, from the start, or to an outer contour of the last one).
    pub fn pierced(&self, d: f64) -> f64 {
        self.idle_per_mm.min(self.cut_per_mm) * d + self.pierce
    }

    /// The least price of `d` mm of travel (idle or linked).
    fn travel(&self, d: f64) -> f64 {
        self.idle_per_mm.min(self.cut_per_mm) * d
    }

    /// Whether the prices are finite and non-negative.
    fn valid(&self) -> bool {
        [self.idle_per_mm, self.cut_per_mm, self.pierce]
            .iter()
            .all(|p| p.is_finite() && *p >= 0.0)
    }
}

impl Default for LowerBoundOptions {
    fn default() -> Self {
        LowerBoundOptions {
            start: Point::new(0.0, 0.0),
            finish: None,
            initial_pieces: 400,
            max_nodes: 2500,
            memory_limit_bytes: 256 << 20,
            first_stage: Duration::from_millis(500),
            stage_work: None,
            budget_seconds: 10.0,
            group_size: 16,
            wide_group_size: 90,
            wide_below: 0.5,
            decompose_above: 24,
            ng_size: 8,
            ng_refined_size: 10,
            ng_above: 24,
            exact_max_kept: EXACT_MAX_KEPT,
            ng_alone: false,
            links: None,
            ng_max_nodes: 4000,
        }
    }
}

/// One kept (innermost) contour.
#[derive(Clone)]
struct Leaf {
    contour_ref: ContourRef,
    contour: Contour,
    spans: Vec<Span>,
    /// Arc length at the start of each span, and the perimeter last.
    offsets: Vec<f64>,
    /// Least tail after this contour when it is cut last, per piece (computed with the pieces).
    outermost: Option<ContourRef>,
    /// The scrap region it lies in, named by its parent (`Some(None)`: the sheet), or `None`
    /// for a hole of a part: with [`LinkPrices`], only contours of one scrap region are
    /// joined by links.
    scrap_region: Option<Option<ContourRef>>,
}

impl Leaf {
    fn perimeter(&self) -> f64 {
        *self.offsets.last().unwrap_or(&0.0)
    }

    /// The spans of the piece `[a, b]` of arc length.
    fn piece_spans(&self, a: f64, b: f64) -> Vec<Span> {
        let mut out = Vec::new();
        for (i, span) in self.spans.iter().enumerate() {
            let (s0, s1) = (self.offsets[i], self.offsets[i + 1]);
            let len = s1 - s0;
            if s1 < a || s0 > b {
                continue;
            }
            if len <= 0.0 {
                out.push(*span);
                continue;
            }
            let t0 = ((a - s0) / len).clamp(0.0, 1.0);
            let t1 = ((b - s0) / len).clamp(0.0, 1.0);
            out.push(if t0 == 0.0 && t1 == 1.0 {
                *span
            } else {
                span.sub_span(t0, t1)
            });
        }
        if out.is_empty() {
            out.push(Span::line(self.spans[0].start, self.spans[0].start));
        }
        out
    }

    /// Arc length of the point of this contour nearest to `p`.
    fn length_of(&self, p: Point) -> f64 {
        self.contour
            .nearest_point(p)
            .map_or(0.0, |q| self.contour.length_at(q.position))
    }
}

/// A piece with its geometry, for distances.
#[derive(Clone)]
struct PieceShape {
    spans: Vec<Span>,
    boxes: Vec<BoundingBox>,
    bbox: BoundingBox,
}

impl PieceShape {
    fn new(spans: Vec<Span>) -> Self {
        let boxes: Vec<BoundingBox> = spans.iter().map(|s| s.bounding_box()).collect();
        let bbox = boxes
            .iter()
            .fold(BoundingBox::default(), |acc, b| acc.union(*b));
        PieceShape { spans, boxes, bbox }
    }

    /// A single point as a shape (a span of no length).
    fn point(p: Point) -> Self {
        PieceShape::new(vec![Span::line(p, p)])
    }

    /// The arc length along the contour of this piece's point nearest to `other`, the piece
    /// beginning at arc length `start` (its spans in order along the contour).
    fn nearest_length(&self, start: f64, other: &PieceShape) -> f64 {
        let (mut best, mut at) = (f64::INFINITY, start);
        let mut offset = start;
        for (s, sb) in self.spans.iter().zip(&self.boxes) {
            let length = s.length();
            if sb.distance_to_box(&other.bbox) < best {
                for o in &other.spans {
                    let q = s.nearest_point_to_span(o);
                    if q.distance < best {
                        (best, at) = (q.distance, offset + q.t * length);
                    }
                }
            }
            offset += length;
        }
        at
    }

    fn distance_to_point(&self, p: Point) -> f64 {
        self.spans
            .iter()
            .map(|s| s.distance_to(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Least distance to another piece (or contour), skipping span pairs whose boxes are
    /// already farther than the best pair found.
    fn distance_to(&self, other: &PieceShape) -> f64 {
        let mut best = f64::INFINITY;
        for (s, sb) in self.spans.iter().zip(&self.boxes) {
            if sb.distance_to_box(&other.bbox) >= best {
                continue;
            }
            for (o, ob) in other.spans.iter().zip(&other.boxes) {
                if sb.distance_to_box(ob) < best {
                    best = best.min(s.distance_to_span(o));
                }
            }
        }
        best
    }
}

/// A stage's instance under construction (rows of the cost matrix, in slices).
struct Building {
    /// Per node (after the depot): (leaf, piece index).
    node_piece: Vec<(usize, usize)>,
    shapes: Vec<PieceShape>,
    /// Per node (after the depot), in a group's bound: half the distance from the piece to the
    /// nearest kept contour of another group (a lower bound on the length any route runs
    /// inside the group's region from the piece to the region's border); +∞ otherwise.
    escape: Vec<f64>,
    cost: Vec<f64>,
    next_row: usize,
    /// Time spent building (diagnostics).
    spent: Duration,
}

/// A stage's exact search on its instance.
struct Solving {
    node_piece: Vec<(usize, usize)>,
    instance: Instance,
    /// `None` above `exact_max_kept` kept contours: the ng-path bound runs alone.
    solver: Option<ExactSolver>,
    spent: Duration,
    share: Duration,
    /// The stage's work when stages are measured by work (then `share` is no limit).
    work: Option<StageWork>,
    /// The ng-path bound on the same instance (large relaxations only), sharing the slices,
    /// and its neighbourhoods' size.
    ng: Option<NgPathBound>,
    ng_size: usize,
    ng_running: bool,
    /// The ng-path bound being made, a stretch of rows per slice (before the incumbent is
    /// offered to it): in one piece it took 0.26 s on 4,000 nodes.
    ng_builder: Option<NgPathBuilder>,
    exact_over: bool,
    /// Slices of this stage so far (the exact search gets every eighth beside the ng-path
    /// bound, and so does the search for cheap relaxed tours).
    turns: usize,
    /// Cheap tours of this relaxation (with the ng-path bound only): where its optimum lies
    /// below the route, so where the next stage refines.
    tours: Option<RelaxedTourSearch>,
    /// Time the stage's matrix took to build (diagnostics).
    build_spent: Duration,
}

impl Solving {
    /// Whether the exact search and the ng-path bound have each done the stage's work (false
    /// when stages are measured by time). A search that ended or does not run has; the ng-path
    /// bound has not while it is being made.
    fn work_done(&self) -> (bool, bool) {
        let Some(work) = self.work else {
            return (false, false);
        };
        let exact = self
            .solver
            .as_ref()
            .is_none_or(|e| self.exact_over || e.states_created() >= work.exact_states);
        let ng = self.ng_builder.is_none()
            && (!self.ng_running
                || self
                    .ng
                    .as_ref()
                    .is_none_or(|ng| ng.iterations() >= work.ng_passes));
        (exact, ng)
    }
}

enum Stage {
    Building(Building),
    Solving(Box<Solving>),
}

/// The resumable lower-bound computation for one nest (see the module documentation).
pub struct CcpLowerBound {
    leaves: Vec<Leaf>,
    by_ref: HashMap<ContourRef, usize>,
    outermost_shapes: HashMap<ContourRef, PieceShape>,
    options: LowerBoundOptions,
    margin: f64,
    /// Per leaf: the pieces as sorted, contiguous intervals of arc length covering the contour.
    pieces: Vec<Vec<(f64, f64)>>,
    stage: Option<Stage>,
    stages_done: usize,
    best: f64,
    /// The best route's pierce points on kept contours, in route order: (leaf, arc length).
    incumbent: Vec<(usize, f64)>,
    incumbent_length: f64,
    incumbent_offered: bool,
    elapsed: Duration,
    /// Pieces are fixed candidates (no refinement; one stage).
    fixed: bool,
    /// In a group's bound: the whole kept contours of the nest (shared by the groups) and
    /// which of them are this group's (the escape distances are to the others); empty
    /// otherwise.
    others: Arc<Vec<PieceShape>>,
    own: Vec<bool>,
    /// In a group's bound: per kept contour, whether all kept contours inside its outermost
    /// contour are in this group (that contour's inside then belongs to this group's region);
    /// and the outermost contours whose insides belong to other groups.
    absorbed: Vec<bool>,
    foreign_outlines: Vec<PieceShape>,
    /// The decomposition's group bounds (empty without decomposition), and whether each may
    /// still improve.
    groups: Vec<CcpLowerBound>,
    groups_running: Vec<bool>,
    /// Whether this bound's own relaxation (of all its kept contours) may still improve.
    own_running: bool,
    /// The size of the wide groups that may take over from the small ones (0: none pending),
    /// the small groups' sum when they gave way (a bound that stays), and the last route
    /// offered (for the wide groups' refinement).
    wide_size: usize,
    floor: f64,
    last_route: Option<Route>,
    /// In a small group that wide ones may replace: its first stage is a short probe.
    probe: bool,
    /// Slices handed out so far (the own relaxation gets one of four beside the groups, three
    /// with the ng-path bound).
    turns: usize,
    /// The ng-path bound's best penalties, carried from stage to stage (same clusters).
    ng_lambda: Vec<f64>,
    /// The ng-path bound's best value over the stages (0 before any).
    ng_best: f64,
}

impl CcpLowerBound {
    /// Prepares the kept contours and the first pieces (no distances computed yet).
    pub fn new(nest: &Nest, options: LowerBoundOptions) -> Result<CcpLowerBound, CcpError> {
        let finite = |p: Point| p.x.is_finite() && p.y.is_finite();
        if !finite(options.start) || options.finish.is_some_and(|f| !finite(f)) {
            return Err(CcpError::InvalidOption(
                "start and finish must be finite".into(),
            ));
        }
        if options.initial_pieces == 0 || options.max_nodes < 2 {
            return Err(CcpError::InvalidOption(
                "initial_pieces ≥ 1 and max_nodes ≥ 2 are required".into(),
            ));
        }
        if options.links.is_some_and(|l| !l.valid()) {
            return Err(CcpError::InvalidOption(
                "link prices must be finite and non-negative".into(),
            ));
        }
        let forest = nest.containment_forest();
        let mut leaves = Vec::new();
        let mut outermost_shapes = HashMap::new();
        // With links every contour is kept: dropping one would drop the pierce or link that
        // enters it, which only a crossing of the idle route gets for free.
        let kept = if options.links.is_some() {
            (0..forest.len())
                .filter_map(|i| forest.contour_ref(i))
                .collect()
        } else {
            forest.leaves()
        };
        for r in kept {
            let Some(contour) = nest.contour(r).filter(|c| !c.vertices.is_empty()) else {
                continue;
            };
            let spans: Vec<Span> = contour.spans().collect();
            let mut offsets = vec![0.0];
            for s in &spans {
                offsets.push(offsets.last().copied().unwrap_or(0.0) + s.length());
            }
            let outermost = if options.links.is_some() {
                None
            } else {
                forest.ancestors(r).last()
            };
            if let Some(o) = outermost {
                if let Some(c) = nest.contour(o) {
                    outermost_shapes
                        .entry(o)
                        .or_insert_with(|| PieceShape::new(c.spans().collect()));
                }
            }
            let parent = forest.parent(r);
            leaves.push(Leaf {
                contour_ref: r,
                contour: contour.clone(),
                spans,
                offsets,
                outermost,
                scrap_region: is_scrap_region(&forest, parent).then_some(parent),
            });
        }
        let b = nest.bounding_box();
        let scale = b
            .max
            .x
            .abs()
            .max(b.max.y.abs())
            .max(b.min.x.abs())
            .max(b.min.y.abs())
            + options.start.x.abs().max(options.start.y.abs());
        let mut margin = COST_MARGIN * (1.0 + if scale.is_finite() { scale } else { 0.0 });
        if let Some(links) = options.links {
            // A price moves by at most the dearer price per mm as the distance does.
            margin *= links.idle_per_mm.max(links.cut_per_mm);
        }
        let group_size = options.group_size;
        let mut bound = CcpLowerBound::from_leaves(
            leaves,
            outermost_shapes,
            options,
            margin,
            Arc::new(Vec::new()),
            Vec::new(),
        );
        // Beyond MAX_GROUPS groups each would get too little time to count, and the sheets
        // that large do not fit a relaxation anyway.
        // (Not with links: a group's region argument charges lengths inside the regions, and a
        // pierce on a way that crosses a border belongs to neither side.)
        let fits = |size: usize, bound: &CcpLowerBound| {
            size > 0
                && bound.options.links.is_none()
                && bound.leaves.len() > size.max(bound.options.decompose_above)
                && bound.leaves.len() <= MAX_GROUPS * size
        };
        // Where nothing solves the whole relaxation, the groups are the bound, and wide ones
        // with the ng-path bound may take over from the small ones (`wide_below`).
        let whole_solved = bound.exact_whole() || (bound.options.ng_alone && bound.ng_active());
        let wide = bound.options.wide_group_size;
        let wide_pending = !whole_solved
            && bound.options.ng_size > 0
            && wide > group_size
            && group_size > 0
            && fits(wide, &bound);
        if fits(group_size, &bound) {
            if wide_pending {
                bound.wide_size = wide;
            }
            bound.decompose(group_size);
        } else if wide_pending {
            // Too many kept contours for small groups: wide ones from the start.
            bound.decompose(wide);
        }
        // The exact search keys hold at most 256 clusters: beyond, the whole relaxation runs
        // the ng-path bound alone (its own DP needs no keys) when asked, or not at all (its
        // first root bound was 4,676 against the groups' 9,502 on Nest02; and with nothing to
        // solve them, its stages' matrices only took time, in steps of up to 0.45 s).
        let ng_alone = bound.options.ng_alone && bound.ng_active();
        if !bound.exact_whole() && !ng_alone {
            bound.own_running = false;
        }
        Ok(bound)
    }

    /// The bound over `leaves` (the first pieces shared by perimeter); in a group's bound,
    /// `others` are all kept contours and `own` marks the group's.
    fn from_leaves(
        leaves: Vec<Leaf>,
        outermost_shapes: HashMap<ContourRef, PieceShape>,
        options: LowerBoundOptions,
        margin: f64,
        others: Arc<Vec<PieceShape>>,
        own: Vec<bool>,
    ) -> CcpLowerBound {
        let by_ref = leaves
            .iter()
            .enumerate()
            .map(|(i, l)| (l.contour_ref, i))
            .collect();
        let total: f64 = leaves.iter().map(Leaf::perimeter).sum();
        // With the ng-path bound the relaxation starts fine: coarse pieces cap its optimum far
        // below the route (6,759 at 383 pieces against 9,535 on nested.dbs), and the ng-path
        // bound gained more from 2,400 uniform pieces in 30 s (7,796) than from the doubling
        // stages in 60 s (7,211).
        // Not without the exact search (more kept contours than its keys hold): there one DP
        // pass costs ~5 s at 1,600 pieces on Nest02 (359 kept contours), and the subgradient
        // needs many passes.
        let ng_wide = options.ng_size > 0
            && leaves.len() > options.ng_above
            && leaves.len() <= options.exact_max_kept.min(EXACT_MAX_KEPT);
        let initial = if ng_wide {
            options.initial_pieces.max(NG_INITIAL_PIECES)
        } else {
            options.initial_pieces
        };
        let budget = initial.min(options.max_nodes - 1) as f64;
        let pieces = leaves
            .iter()
            .map(|l| {
                let p = l.perimeter();
                let share = if total > 0.0 { budget * p / total } else { 1.0 };
                let n = (share.round() as usize).max(2);
                (0..n)
                    .map(|k| (p * k as f64 / n as f64, p * (k + 1) as f64 / n as f64))
                    .collect()
            })
            .collect();
        CcpLowerBound {
            leaves,
            by_ref,
            outermost_shapes,
            margin,
            options,
            pieces,
            stage: None,
            stages_done: 0,
            best: 0.0,
            incumbent: Vec::new(),
            incumbent_length: f64::INFINITY,
            incumbent_offered: false,
            elapsed: Duration::ZERO,
            fixed: false,
            others,
            own,
            absorbed: Vec::new(),
            foreign_outlines: Vec::new(),
            groups: Vec::new(),
            groups_running: Vec::new(),
            own_running: true,
            wide_size: 0,
            floor: 0.0,
            last_route: None,
            probe: false,
            turns: 0,
            ng_lambda: Vec::new(),
            ng_best: 0.0,
        }
    }

    /// Splits the kept contours into spatial groups of at most `size` (the contours of one
    /// outermost contour together where they fit) and prepares one group bound per group.
    fn decompose(&mut self, size: usize) {
        let members = spatial_groups(&self.leaves, size);
        if members.len() < 2 {
            return;
        }
        let whole: Arc<Vec<PieceShape>> = Arc::new(
            self.leaves
                .iter()
                .map(|l| PieceShape::new(l.spans.clone()))
                .collect(),
        );
        let count = members.len();
        // The groups holding the kept contours inside each outermost contour.
        let mut holders: HashMap<ContourRef, Vec<usize>> = HashMap::new();
        for (g, group) in members.iter().enumerate() {
            for &i in group {
                if let Some(o) = self.leaves[i].outermost {
                    let list = holders.entry(o).or_default();
                    if !list.contains(&g) {
                        list.push(g);
                    }
                }
            }
        }
        let absorbed_by = |o: Option<ContourRef>| -> Option<usize> {
            match holders.get(&o?)?.as_slice() {
                [g] => Some(*g),
                _ => None,
            }
        };
        for (g, group) in members.iter().enumerate() {
            let mut own = vec![false; self.leaves.len()];
            for &i in group {
                own[i] = true;
            }
            let leaves: Vec<Leaf> = group.iter().map(|&i| self.leaves[i].clone()).collect();
            let outermost_shapes = leaves
                .iter()
                .filter_map(|l| {
                    let o = l.outermost?;
                    Some((o, self.outermost_shapes.get(&o)?.clone()))
                })
                .collect();
            let wide = leaves.len() > self.options.ng_above && self.options.ng_size > 0;
            let options = LowerBoundOptions {
                // Finer first pieces than the whole relaxation: a group's exact search is
                // cheap, and its bound is only as good as its pieces.
                initial_pieces: (12 * leaves.len()).min(self.options.initial_pieces),
                // Wide groups run the ng-path bound, whose passes a stage's rebuild restarts: they
                // get the whole relaxation's first share (Nest02, groups of 90, 60 s of the
                // bound's own time: 16,932 with a quarter of it, 17,858–18,079 with all of it,
                // 17,331 with twice it).
                first_stage: if wide {
                    self.options.first_stage
                } else {
                    (self.options.first_stage / 4).max(Duration::from_millis(100))
                },
                stage_work: self
                    .options
                    .stage_work
                    .map(|w| if wide { w } else { w.scaled(0, 4) }),
                budget_seconds: (2.0 * self.options.budget_seconds / count as f64).max(2.0),
                group_size: 0,
                // Groups fit the exact search's keys: the test threshold is the whole relaxation's only.
                exact_max_kept: EXACT_MAX_KEPT,
                ng_max_nodes: GROUP_NG_MAX_NODES.min(self.options.ng_max_nodes),
                ng_refined_size: 0,
                ..self.options.clone()
            };
            let absorbed: Vec<bool> = leaves
                .iter()
                .map(|l| absorbed_by(l.outermost) == Some(g))
                .collect();
            let mut foreign: Vec<(ContourRef, usize)> = holders
                .iter()
                .filter_map(|(&o, list)| match list.as_slice() {
                    [h] if *h != g => Some((o, *h)),
                    _ => None,
                })
                .collect();
            foreign.sort_by_key(|&(o, _)| (o.part, o.contour));
            let foreign_outlines = foreign
                .iter()
                .filter_map(|(o, _)| self.outermost_shapes.get(o).cloned())
                .collect();
            let mut bound = CcpLowerBound::from_leaves(
                leaves,
                outermost_shapes,
                options,
                self.margin,
                Arc::clone(&whole),
                own,
            );
            bound.absorbed = absorbed;
            bound.probe = self.wide_size > size;
            bound.foreign_outlines = foreign_outlines;
            self.groups.push(bound);
            self.groups_running.push(true);
        }
    }

    /// The bound for routes that pierce each contour only at one of `candidates` (contour,
    /// point on it): the discrete model's bound. `None` when a kept contour has no candidate
    /// or the candidates exceed `options.max_nodes`.
    pub fn for_candidates(
        nest: &Nest,
        options: LowerBoundOptions,
        candidates: &[(ContourRef, Point)],
    ) -> Result<Option<CcpLowerBound>, CcpError> {
        let mut bound = CcpLowerBound::new(nest, options)?;
        let mut at: Vec<Vec<f64>> = vec![Vec::new(); bound.leaves.len()];
        for &(r, p) in candidates {
            if let Some(&leaf) = bound.by_ref.get(&r) {
                at[leaf].push(bound.leaves[leaf].length_of(p));
            }
        }
        let total: usize = at.iter().map(Vec::len).sum();
        if at.iter().any(Vec::is_empty) || total + 1 > bound.options.max_nodes {
            return Ok(None);
        }
        for (leaf, lengths) in at.iter_mut().enumerate() {
            let perimeter = bound.leaves[leaf].perimeter();
            // Half-width of each piece: the arc around a candidate absorbs the rounding of its
            // arc length (a wider piece only lowers the distances, so any width is sound).
            let half = 1e-7 * (1.0 + perimeter);
            lengths.sort_by(f64::total_cmp);
            lengths.dedup_by(|a, b| *a - *b <= half);
            bound.pieces[leaf] = lengths
                .iter()
                .map(|&s| ((s - half).max(0.0), (s + half).min(perimeter)))
                .collect();
        }
        bound.fixed = true;
        // The candidates' instance is solved exactly in one stage: no groups beside it.
        bound.groups.clear();
        bound.groups_running.clear();
        bound.own_running = true;
        Ok(Some(bound))
    }

    /// Contours the relaxation keeps (the innermost ones: its clusters).
    pub fn kept_contours(&self) -> usize {
        self.leaves.len()
    }

    /// The best certified lower bound so far (mm of idle travel; 0 before the first stage):
    /// the whole relaxation's, or the sum of the groups' bounds (or of the small groups', when
    /// wide ones took over) when larger.
    pub fn lower_bound(&self) -> f64 {
        self.best.max(self.group_sum()).max(self.floor)
    }

    /// The decomposition's bound: the sum of the groups' bounds (0 without groups).
    pub fn group_sum(&self) -> f64 {
        self.groups.iter().map(|g| g.best).sum()
    }

    /// Groups of the decomposition bound (0: none).
    pub fn group_count(&self) -> usize {
        self.groups.len()
    }

    /// Whether wide groups may still take over from the small ones (`wide_below`).
    pub fn wide_pending(&self) -> bool {
        self.wide_size > 0
    }

    /// The best ng-path bound on the whole relaxation so far (0 when it does not run).
    pub fn ng_bound(&self) -> f64 {
        self.ng_best
    }

    /// Clusters per neighbourhood of the ng-path bound on the current stage's relaxation
    /// (before [`MAX_NG`] and the cluster count cap it); `None` while it has none.
    pub fn ng_neighbourhood(&self) -> Option<usize> {
        match &self.stage {
            Some(Stage::Solving(s)) if s.ng.is_some() || s.ng_builder.is_some() => Some(s.ng_size),
            _ => None,
        }
    }

    /// The bound of the whole relaxation alone (without the groups).
    pub fn whole_bound(&self) -> f64 {
        self.best
    }

    /// Stages (instances solved, each with finer pieces) completed so far.
    pub fn stages(&self) -> usize {
        self.stages_done
    }

    /// Stages completed by every relaxation that may still improve: the least of the whole
    /// relaxation's (while it runs) and each running group's (`usize::MAX` when none runs).
    /// With stages measured by work, running until this reaches `k` does the same work on any
    /// machine.
    pub fn least_stages(&self) -> usize {
        let own = self.own_running.then_some(self.stages_done);
        let groups = self
            .groups
            .iter()
            .zip(&self.groups_running)
            .filter(|(_, &running)| running)
            .map(|(g, _)| g.least_stages());
        own.into_iter().chain(groups).min().unwrap_or(usize::MAX)
    }

    /// Nodes (pieces + depot) of the current stage's instance.
    pub fn node_count(&self) -> usize {
        1 + self.pieces.iter().map(Vec::len).sum::<usize>()
    }

    /// The relaxed PCGTSP instance of the stage under way, once built (for inspection and
    /// experiments with other bounds on it).
    pub fn relaxed_instance(&self) -> Option<&Instance> {
        match &self.stage {
            Some(Stage::Solving(s)) => Some(&s.instance),
            _ => None,
        }
    }

    /// Time spent in `step` so far.
    pub fn elapsed(&self) -> Duration {
        self.elapsed
    }

    /// Tells the bound about a route (the solver's best): its pierce points guide refinement
    /// and its relaxed cost is the exact search's incumbent. Routes no shorter than the last
    /// one offered are ignored.
    pub fn offer_route(&mut self, route: &Route) {
        let length = route.idle_length();
        if length.is_nan() || length >= self.incumbent_length {
            return;
        }
        self.incumbent_length = length;
        self.incumbent = route
            .steps
            .iter()
            .filter_map(|s| {
                let &leaf = self.by_ref.get(&s.contour)?;
                Some((leaf, self.leaves[leaf].length_of(s.pierce_point)))
            })
            .collect();
        self.incumbent_offered = false;
        for group in &mut self.groups {
            group.offer_route(route);
        }
        if self.wide_size > 0 {
            self.last_route = Some(route.clone());
        }
    }

    /// Once every small group has run its probe: wide groups take over if the small ones' sum
    /// is below `wide_below` of the best route, else the small ones stay.
    fn maybe_widen(&mut self) {
        if self.wide_size == 0 {
            return;
        }
        let probed = self
            .groups
            .iter()
            .zip(&self.groups_running)
            .all(|(g, &running)| !g.probe || !running);
        if !probed {
            return;
        }
        let size = std::mem::take(&mut self.wide_size);
        let sum = self.group_sum();
        debug_log(|| {
            format!(
                "small groups' probes: sum {sum:.3} = {:.3} of the route",
                sum / self.incumbent_length
            )
        });
        // (Without a route the threshold is infinite: wide groups, unless `wide_below` is 0.)
        let widen = sum < self.options.wide_below * self.incumbent_length;
        if !widen {
            self.last_route = None;
            return;
        }
        self.floor = self.floor.max(sum);
        self.groups.clear();
        self.groups_running.clear();
        self.decompose(size);
        if let Some(route) = self.last_route.take() {
            for group in &mut self.groups {
                group.offer_route(&route);
            }
        }
    }

    /// Works for about `budget`; returns false when nothing is left to do (the bound is exact
    /// for the pieces' limit, or there is nothing to bound).
    pub fn step(&mut self, budget: Duration) -> bool {
        let began = Instant::now();
        let deadline = began + budget;
        let more = if self.groups.is_empty() {
            self.own_running = self.own_running && self.step_until(deadline);
            self.own_running
        } else {
            self.step_shared(deadline)
        };
        self.elapsed += began.elapsed();
        more
    }

    /// One slice of the decomposition: to the group that has had the least time so far, or to
    /// the whole relaxation (which stays the bound where groups lose much at their borders).
    fn step_shared(&mut self, deadline: Instant) -> bool {
        self.maybe_widen();
        self.turns += 1;
        // A group in the middle of a stage keeps the groups' turns until that stage ends, and
        // only then the group that has had the least time so far starts its next one: so at
        // most one group holds a stage's matrices and exact search at a time (all of them at
        // once held 1.6–2.8 GB on Nest02/Nest03). A group's stage ends by its own time share,
        // whichever slices it runs in.
        let group = (0..self.groups.len())
            .find(|&g| self.groups_running[g] && self.groups[g].stage.is_some())
            .or_else(|| {
                let running = (0..self.groups.len()).filter(|&g| self.groups_running[g]);
                if self.options.stage_work.is_some() {
                    // By work: the group with the fewest stages (a pending probe first), so
                    // that what the groups reach does not depend on the machine either.
                    running.min_by_key(|&g| {
                        let group = &self.groups[g];
                        group.stages_done + usize::from(!group.probe)
                    })
                } else {
                    running.min_by_key(|&g| self.groups[g].elapsed())
                }
            });
        // With the ng-path bound the whole relaxation is the stronger one (the groups' exact
        // optima saturate within seconds at the loss on their borders): it gets three slices
        // of four, seven of eight once its bound is above the groups' sum; without it, one.
        let own_turn = if self.ng_active() && (self.exact_whole() || self.best > self.group_sum()) {
            let every = if self.best > self.group_sum() { 8 } else { 4 };
            !self.turns.is_multiple_of(every)
        } else {
            // Without the exact search (hundreds of kept contours) the ng-path bound's passes
            // are slow and it starts far below the groups' sum: one slice of four until it is
            // above, so the groups keep most of the time.
            self.turns.is_multiple_of(4)
        };
        match group {
            Some(g) if !self.own_running || !own_turn => {
                let left = deadline.saturating_duration_since(Instant::now());
                self.groups_running[g] = self.groups[g].step(left.max(Duration::from_millis(1)));
            }
            _ => {
                self.own_running = self.own_running && self.step_until(deadline);
            }
        }
        self.own_running || self.groups_running.iter().any(|&r| r)
    }

    /// Whether this bound's own relaxation runs the exact search (few enough kept contours
    /// for its keys).
    fn exact_whole(&self) -> bool {
        self.leaves.len() <= self.options.exact_max_kept.min(EXACT_MAX_KEPT)
    }

    /// Whether this bound's own relaxation runs the ng-path bound (beside the exact search
    /// where that runs), at fixed candidates too.
    fn ng_active(&self) -> bool {
        self.options.ng_size > 0 && self.leaves.len() > self.options.ng_above
    }

    fn step_until(&mut self, deadline: Instant) -> bool {
        if self.leaves.is_empty() {
            return false;
        }
        loop {
            match self.stage.take() {
                None => {
                    let n = 1 + self.pieces.iter().map(Vec::len).sum::<usize>();
                    if n.saturating_mul(n) > MAX_RELAXATION_ENTRIES {
                        return false;
                    }
                    self.stage = Some(Stage::Building(self.start_building()));
                }
                Some(Stage::Building(mut b)) => {
                    let began = Instant::now();
                    // A complete matrix waits for the next slice when this one is used up:
                    // making the stage's solver is a long piece of work of its own.
                    let built = self.build_rows(&mut b, deadline);
                    b.spent += began.elapsed();
                    if built && Instant::now() < deadline {
                        match self.start_solving(b) {
                            Some(s) => self.stage = Some(Stage::Solving(Box::new(s))),
                            None => return false,
                        }
                    } else {
                        self.stage = Some(Stage::Building(b));
                        return true;
                    }
                }
                Some(Stage::Solving(mut s)) => {
                    let finished = self.solve_slice(&mut s, deadline);
                    if !finished {
                        self.stage = Some(Stage::Solving(s));
                        return true;
                    }
                    if std::mem::take(&mut self.probe) {
                        // A small group's probe (see `wide_below`): its bound counts, but it
                        // neither counts as a stage nor refines (the pieces it would add
                        // slowed every later stage: a generated 1,000-contour sheet's bound
                        // at 60 s fell by 2 %), so the usual stages follow as before.
                        return true;
                    }
                    self.stages_done += 1;
                    let progress = s.solver.as_ref().map(ExactSolver::progress);
                    debug_log(|| {
                        format!(
                            "stage {} ({} nodes, built in {:.2} s, {:.2} s of {:.2} s): relaxed lb {:.3} ub {:.3}, ng {:.3} ({} passes), cheapest relaxed tour {:.3} ({} local searches), best {:.3}, incumbent {:.3}",
                            self.stages_done,
                            s.instance.node_count,
                            s.build_spent.as_secs_f64(),
                            s.spent.as_secs_f64(),
                            s.share.as_secs_f64(),
                            progress.as_ref().map_or(f64::NAN, |p| p.lower_bound),
                            progress.as_ref().map_or(f64::NAN, |p| p.upper_bound),
                            s.ng.as_ref().map_or(f64::NAN, NgPathBound::lower_bound),
                            s.ng.as_ref().map_or(0, NgPathBound::iterations),
                            s.tours.as_ref().map_or(f64::NAN, RelaxedTourSearch::best_cost),
                            s.tours.as_ref().map_or(0, RelaxedTourSearch::kicks),
                            self.best,
                            self.incumbent_length
                        )
                    });
                    if self.fixed {
                        // Nothing to refine: the stage ran until its exact search ended.
                        self.stage = None;
                        return false;
                    }
                    // The pieces of the cheapest relaxed tours, of the incumbent, of the
                    // exact search's relaxed tour and of the ng-path bound's cheapest walk are
                    // where the next relaxed optimum tends to lie, in that order of priority.
                    if let (Some(tours), Some(ng)) = (s.tours.as_mut(), s.ng.as_ref()) {
                        // One more local search from the ng walk's order (a few ms).
                        tours.add_start(&s.instance, ng.last_walk());
                        tours.step(&s.instance, Instant::now());
                    }
                    let mut tours: Vec<Vec<usize>> = Vec::new();
                    if let Some(search) = &s.tours {
                        tours.extend(search.pool().iter().map(|(_, tour)| tour.clone()));
                    }
                    tours.extend(self.incumbent_tour(&s.node_piece));
                    tours.extend(progress.and_then(|p| p.best_tour));
                    if let Some(ng) = &s.ng {
                        tours.push(ng.last_walk().to_vec());
                    }
                    // With no piece left to split, the next stage reruns the same pieces
                    // with twice the time.
                    self.refine(&s.node_piece, &tours, s.tours.is_some());
                    if !self.own.is_empty() {
                        // A group's stage is over: the decomposition picks who goes next.
                        return true;
                    }
                }
            }
            if Instant::now() >= deadline {
                return true;
            }
        }
    }

    fn start_building(&self) -> Building {
        let mut node_piece = Vec::new();
        let mut shapes = Vec::new();
        for (leaf, pieces) in self.pieces.iter().enumerate() {
            for (k, &(a, b)) in pieces.iter().enumerate() {
                node_piece.push((leaf, k));
                shapes.push(PieceShape::new(self.leaves[leaf].piece_spans(a, b)));
            }
        }
        let n = 1 + node_piece.len();
        Building {
            node_piece,
            shapes,
            escape: Vec::with_capacity(if self.others.is_empty() { 0 } else { n - 1 }),
            cost: vec![f64::INFINITY; n * n],
            next_row: 0,
            spent: Duration::ZERO,
        }
    }

    /// The least tail after the last kept contour when it is cut from `piece`.
    ///
    /// With [`LinkPrices`] its price: the way to the outermost contour has a pierce (that
    /// contour is no sibling of anything inside it), the rest is travel.
    fn tail(&self, leaf: usize, piece: &PieceShape) -> f64 {
        let to_outermost = self.leaves[leaf]
            .outermost
            .and_then(|o| self.outermost_shapes.get(&o));
        let (travel, pierced): (&dyn Fn(f64) -> f64, &dyn Fn(f64) -> f64) =
            match &self.options.links {
                Some(links) => (&|d| links.travel(d), &|d| links.pierced(d)),
                None => (&|d| d, &|d| d),
            };
        match (self.options.finish, to_outermost) {
            (None, None) => 0.0,
            (None, Some(o)) => pierced(piece.distance_to(o)),
            (Some(f), None) => travel(piece.distance_to_point(f)),
            (Some(f), Some(o)) => travel(piece.distance_to_point(f))
                .max(pierced(piece.distance_to(o)) + travel(o.distance_to_point(f))),
        }
    }

    /// The least price of a move of straight length `d` from the start (`from` is `None`) or
    /// a piece of kept contour `from` to one of kept contour `to`: the length itself, or with
    /// [`LinkPrices`] a link's price between siblings and a pierced way's otherwise.
    fn move_price(&self, from: Option<usize>, to: usize, d: f64) -> f64 {
        let Some(links) = &self.options.links else {
            return d;
        };
        let region = |leaf: usize| self.leaves[leaf].scrap_region;
        match (from.and_then(region), region(to)) {
            (Some(a), Some(b)) if a == b => links.between_siblings(d),
            _ => links.pierced(d),
        }
    }

    /// How far any route runs inside this group's region from a pierce point `p` in `piece`
    /// (of kept contour `leaf`) to the region's border. The region is the points nearer to
    /// this group's kept contours than to the others', with the insides of *absorbed*
    /// outermost contours (all kept contours inside them in one group) given to that group.
    /// A border point q lies in another group H's part of the plane: either q is no nearer to
    /// this group than to H, so d(p, H) ≤ d(p, q) + d(q, H) ≤ 2·d(p, q), or q is inside or on
    /// an outermost contour absorbed by H, which `p` lies outside of. And when `leaf`'s own
    /// outermost contour is absorbed here, q is not inside it, so d(p, q) is at least the
    /// distance from `p` to that contour.
    fn escape(&self, leaf: usize, piece: &PieceShape) -> f64 {
        let mut best = f64::INFINITY;
        for (other, _) in self.others.iter().zip(&self.own).filter(|(_, &own)| !own) {
            if 0.5 * piece.bbox.distance_to_box(&other.bbox) < best {
                best = best.min(0.5 * piece.distance_to(other));
            }
        }
        for outline in &self.foreign_outlines {
            if piece.bbox.distance_to_box(&outline.bbox) < best {
                best = best.min(piece.distance_to(outline));
            }
        }
        if self.absorbed.get(leaf).copied().unwrap_or(false) {
            if let Some(own) = self.leaves[leaf]
                .outermost
                .and_then(|o| self.outermost_shapes.get(&o))
            {
                best = best.max(piece.distance_to(own));
            }
        }
        best
    }

    /// Fills rows of the cost matrix until `deadline`; true when complete.
    ///
    /// In a group's bound every cost is the least length a route runs inside the group's
    /// region: between two pierce points either the move stays inside (the piece distance)
    /// or it leaves and comes back (at least both escapes); the first pierce point is reached
    /// from the start or from the border, and after the last one the route either leaves the
    /// region or runs its tail inside it. The regions partition the plane, so the groups'
    /// bounds add up.
    fn build_rows(&self, b: &mut Building, deadline: Instant) -> bool {
        let n = 1 + b.node_piece.len();
        while !self.others.is_empty() && b.escape.len() < n - 1 {
            let v = b.escape.len();
            let e = self.escape(b.node_piece[v].0, &b.shapes[v]);
            b.escape.push(e);
            if Instant::now() >= deadline {
                return false;
            }
        }
        let escape = |v: usize| b.escape.get(v - 1).copied().unwrap_or(f64::INFINITY);
        while b.next_row < n {
            let a = b.next_row;
            for c in 0..n {
                let value = match (a, c) {
                    (0, 0) => continue,
                    (0, c) => self
                        .move_price(
                            None,
                            b.node_piece[c - 1].0,
                            b.shapes[c - 1].distance_to_point(self.options.start),
                        )
                        .min(escape(c)),
                    (a, 0) => self
                        .tail(b.node_piece[a - 1].0, &b.shapes[a - 1])
                        .min(escape(a)),
                    (a, c) if b.node_piece[a - 1].0 == b.node_piece[c - 1].0 => continue,
                    // Symmetric: the lower triangle was filled from the upper one.
                    (a, c) if c < a => b.cost[c * n + a],
                    (a, c) => self
                        .move_price(
                            Some(b.node_piece[a - 1].0),
                            b.node_piece[c - 1].0,
                            b.shapes[a - 1].distance_to(&b.shapes[c - 1]),
                        )
                        .min(escape(a) + escape(c)),
                };
                b.cost[a * n + c] = value;
            }
            b.next_row += 1;
            if Instant::now() >= deadline {
                return b.next_row >= n;
            }
        }
        true
    }

    fn start_solving(&mut self, b: Building) -> Option<Solving> {
        let n = 1 + b.node_piece.len();
        let build_spent = b.spent;
        let margin = self.margin;
        // In place: at 2,500 pieces the matrix is 50 MB, and the ng-path bound keeps its own.
        let mut cost = b.cost;
        for c in cost.iter_mut().filter(|c| c.is_finite()) {
            *c = (*c - margin).max(0.0);
        }
        let mut clusters: Vec<Vec<usize>> = vec![Vec::new(); 1 + self.leaves.len()];
        clusters[0].push(0);
        let mut node_cluster = vec![0usize; n];
        for (v, &(leaf, _)) in b.node_piece.iter().enumerate() {
            clusters[leaf + 1].push(v + 1);
            node_cluster[v + 1] = leaf + 1;
        }
        let instance = Instance {
            name: "ccp-interval-relaxation".into(),
            node_count: n,
            cost,
            clusters,
            node_cluster,
            precedence: Vec::new(),
            depot: 0,
        };
        let share = if self.fixed {
            // One stage: it runs until the exact search ends or the caller stops.
            Duration::from_secs(1 << 40)
        } else if self.probe {
            // Small groups that wide ones may replace first tell whether they should, in a
            // sixteenth of their first share (Nest02's 25 groups took 17 s with all of it,
            // ~3 s with this; the sums they tell by are lower, see `wide_below`).
            (self.options.first_stage / 16).max(Duration::from_millis(100))
        } else {
            self.options.first_stage * (1u32 << self.stages_done.min(16))
        };
        let work = match self.options.stage_work {
            Some(_) if self.fixed => None,
            Some(w) if self.probe => Some(w.scaled(0, 16)),
            Some(w) => Some(w.scaled(self.stages_done, 1)),
            None => None,
        };
        // By work, the time share is no limit (the exact search's budgets are sized for the
        // whole computation, not for a share that depends on the machine).
        let share = if work.is_some() {
            Duration::from_secs(1 << 40)
        } else {
            share
        };
        // The relaxation has no precedence, so its lattice of ideals holds all 2^m subsets of
        // its m contours. Past the lattice's cap the build always fails, and before it failed,
        // sorting one layer of 3.7 million records was one piece of 0.32 s on nested.dbs' 4,000
        // pieces (70 contours). So the lattice is not built there at all.
        let lattice_max_ideals = ExactOptions::default().lattice_max_ideals;
        let lattice_fits =
            self.leaves.len() < 40 && 1usize << self.leaves.len() <= lattice_max_ideals;
        let lattice_max_ideals = if lattice_fits { lattice_max_ideals } else { 0 };
        let options = ExactOptions {
            time_limit: Some(share),
            budget_seconds: Some(if self.fixed || work.is_some() {
                self.options.budget_seconds
            } else {
                self.options.budget_seconds.max(share.as_secs_f64())
            }),
            memory_limit_bytes: self.options.memory_limit_bytes,
            heuristic: false,
            penalty_iterations: 0,
            position_iterations: 0,
            lattice_max_ideals,
            ..ExactOptions::default()
        };
        // Deferred: the start node's model and root bound are built in the stage's first
        // slices, a piece each (`ExactSolver::new` built them here in one piece of up to
        // 0.6 s on nested.dbs, which Stop had to wait for).
        let solver = if self.exact_whole() {
            Some(ExactSolver::deferred(&instance, options).ok()?)
        } else {
            None
        };
        self.incumbent_offered = false;
        let ng_size = match self.options.ng_refined_size {
            refined if refined > 0 && self.stages_done > 0 => refined,
            _ => self.options.ng_size,
        };
        let ng_builder = self
            .ng_active()
            .then(|| NgPathBuilder::new(&instance, ng_size, &self.ng_lambda))
            .flatten();
        if solver.is_none() && ng_builder.is_none() {
            return None;
        }
        Some(Solving {
            node_piece: b.node_piece,
            instance,
            solver,
            spent: Duration::ZERO,
            share,
            work,
            ng_running: false,
            ng: None,
            ng_size,
            exact_over: false,
            turns: 0,
            build_spent,
            tours: ng_builder
                .is_some()
                .then(|| RelaxedTourSearch::new(0x5eed ^ self.stages_done as u64)),
            ng_builder,
        })
    }

    /// The incumbent route as a tour of the stage's instance (its pierce points' pieces).
    fn incumbent_tour(&self, node_piece: &[(usize, usize)]) -> Option<Vec<usize>> {
        let mut first_node = Vec::with_capacity(self.leaves.len());
        let mut next = 1;
        for pieces in &self.pieces {
            first_node.push(next);
            next += pieces.len();
        }
        if next != node_piece.len() + 1 || self.incumbent.len() != self.leaves.len() {
            return None;
        }
        let mut tour = vec![0];
        for &(leaf, s) in &self.incumbent {
            let pieces = &self.pieces[leaf];
            // The piece holding the pierce point, else (fixed candidates, which need not
            // cover the contour) the nearest one.
            let k = pieces
                .iter()
                .position(|&(a, b)| a <= s && s <= b)
                .unwrap_or_else(|| {
                    (0..pieces.len())
                        .min_by(|&i, &j| {
                            let d = |k: usize| (0.5 * (pieces[k].0 + pieces[k].1) - s).abs();
                            d(i).total_cmp(&d(j))
                        })
                        .unwrap_or(0)
                });
            tour.push(first_node[leaf] + k);
        }
        Some(tour)
    }

    /// Runs the stage's exact search until `deadline`; true when the stage is over.
    fn solve_slice(&mut self, s: &mut Solving, deadline: Instant) -> bool {
        if let Some(builder) = s.ng_builder.as_mut() {
            // Slices of its own, before the incumbent is offered to it.
            let began = Instant::now();
            if builder.step(&s.instance, deadline) {
                let builder = s.ng_builder.take().expect("made above");
                s.ng = Some(builder.finish(&s.instance));
                s.ng_running = true;
            }
            s.spent += began.elapsed();
            return false;
        }
        if !self.incumbent_offered {
            if let Some(tour) = self.incumbent_tour(&s.node_piece) {
                let cost = cutroute_pcgtsp::check_tour(&s.instance, &tour).unwrap_or(f64::INFINITY);
                if let Some(solver) = &mut s.solver {
                    solver.offer_incumbent(&tour, cost);
                }
                if let Some(ng) = &mut s.ng {
                    ng.offer_tour(&tour);
                    ng.set_upper(cost);
                }
                if let Some(tours) = &mut s.tours {
                    tours.add_start(&s.instance, &tour);
                }
            }
            self.incumbent_offered = true;
        }
        let now = Instant::now();
        let slice = deadline.saturating_duration_since(now);
        // With the ng-path bound beside it, the exact search (which cannot solve a relaxation
        // this large; its bounds stall early) gets every eighth slice while its bound is ahead.
        // Until its model and root bound are built, one piece of them per slice (a step of
        // no budget builds one and returns), whoever has the slice's turn.
        if let Some(solver) = s.solver.as_mut().filter(|e| !e.runs_built()) {
            let status = solver.step(Duration::ZERO);
            s.exact_over = status != Status::Running;
            let progress = solver.progress();
            if progress.lower_bound.is_finite() {
                self.best = self.best.max(progress.lower_bound);
            }
        }
        s.turns += 1;
        // Once the ng-path bound is above the exact search's (on nested.dbs ~7,900 against
        // ~4,600), the exact search's eighth of the slices goes to the ng-path bound too.
        let ng_ahead = match (&s.ng, &s.solver) {
            // `bounds`, not `progress`: no copy of the incumbent tour nor DP statistics per slice.
            (Some(ng), Some(solver)) => {
                ng.lower_bound() > solver.bounds().lower.unwrap_or(f64::NEG_INFINITY)
            }
            _ => false,
        };
        // By work, a search that has done its share leaves the slices to the other.
        let (exact_done, ng_done) = s.work_done();
        let exact_wants = !s.exact_over && !exact_done;
        let ng_wants = s.ng_running && !ng_done;
        let exact_turn = exact_wants && (!ng_wants || (s.turns.is_multiple_of(8) && !ng_ahead));
        let tours_turn = s.turns % 8 == 4;
        if let Some(tours) = s.tours.as_mut().filter(|t| tours_turn && t.running()) {
            // A cheaper relaxed tour bounds the ng-path DP's passes better (pruning, level).
            if tours.step(&s.instance, deadline) {
                let (cost, best) = &tours.pool()[0];
                if let Some(solver) = &mut s.solver {
                    let mut tour = vec![s.instance.clusters[s.instance.depot][0]];
                    tour.extend_from_slice(best);
                    solver.offer_incumbent(&tour, *cost);
                }
                if let Some(ng) = &mut s.ng {
                    ng.offer_tour(best);
                }
            }
        } else if let Some(solver) = s.solver.as_mut().filter(|_| exact_turn) {
            let status = solver.step(slice.max(Duration::from_millis(1)));
            s.exact_over = status != Status::Running;
            let progress = solver.progress();
            if progress.lower_bound.is_finite() {
                self.best = self.best.max(progress.lower_bound);
            }
        } else if let Some(ng) = s.ng.as_mut().filter(|_| s.ng_running) {
            s.ng_running = ng.step(deadline);
            if ng.lower_bound().is_finite() {
                self.best = self.best.max(ng.lower_bound());
                self.ng_best = self.ng_best.max(ng.lower_bound());
            }
            self.ng_lambda = ng.best_lambda().to_vec();
            // At fixed candidates the stage is the last: once the small neighbourhoods have
            // set the penalties (or converged), the largest ones take over from them. Their
            // passes cost ~5 times as much, but their walks revisit far fewer contours: on
            // nested.dbs at 25 mm the walks of ng = 8 cycled through 21–44 of 70 contours
            // (cycles of 12–15), and ng = 12 reached 9,183 in 10 passes where ng = 8 had
            // 8,563 (9,2xx converged).
            let escalate = !s.ng_running || ng.iterations() >= ESCALATE_PASSES;
            // (Not where every contour is already in every neighbourhood.)
            let wider_exists = s.ng_size < MAX_NG && self.leaves.len() > s.ng_size;
            if self.fixed && escalate && wider_exists {
                // (The arc tables are shared: no pass over the matrix.)
                let mut wider = ng.widened(MAX_NG, &self.ng_lambda);
                for walk in ng.offered_tours() {
                    wider.offer_tour(walk);
                }
                s.ng_size = MAX_NG;
                s.ng_running = true;
                *ng = wider;
            }
        }
        s.spent += now.elapsed();
        // The stage is over when the exact search ended (its bound is then the relaxation's
        // optimum), when neither search can go on, or when its time or work is up.
        let (exact_done, ng_done) = s.work_done();
        s.exact_over
            || s.spent >= s.share
            || (s.solver.is_none() && !s.ng_running)
            || (exact_done && ng_done)
    }

    /// Splits pieces where the relaxed `tours` (node sequences of the stage's instance, most
    /// important first; depot nodes are skipped) may gain, in order until the node limit; false
    /// when no piece could be split (node limit or tiny pieces).
    ///
    /// With `at_turns` (the relaxations that run the ng-path bound) a tour's visit to a piece
    /// is split once, between the points where the relaxation charges the move in and the
    /// move out ([`CcpLowerBound::cuts_at_turns`]): after the split each part holds only one
    /// of them. Without it, the visited pieces are split in four
    /// ([`CcpLowerBound::cuts_in_parts`]). Either way their neighbours along the contour are
    /// halved (the next relaxed optimum tends to move next door).
    fn refine(
        &mut self,
        node_piece: &[(usize, usize)],
        tours: &[Vec<usize>],
        at_turns: bool,
    ) -> bool {
        let max_nodes = if !self.exact_whole() {
            self.options.max_nodes.min(NG_ALONE_MAX_NODES)
        } else if self.ng_active() {
            // Past the largest dense matrix the next stage would not be built at all.
            self.options.ng_max_nodes.min(MAX_RELAXATION_NODES)
        } else {
            self.options.max_nodes
        };
        let cuts = if at_turns {
            self.cuts_at_turns(node_piece, tours, max_nodes)
        } else {
            self.cuts_in_parts(node_piece, tours, max_nodes)
        };
        let mut split_any = false;
        for (leaf, pieces) in self.pieces.iter_mut().enumerate() {
            let mut out = Vec::with_capacity(pieces.len() + 8);
            for (k, &(a, b)) in pieces.iter().enumerate() {
                let mut at = cuts[leaf][k].clone();
                at.sort_by(f64::total_cmp);
                split_any |= !at.is_empty();
                let mut from = a;
                for c in at {
                    out.push((from, c));
                    from = c;
                }
                out.push((from, b));
            }
            *pieces = out;
        }
        split_any
    }

    /// Least length of a piece's part (relative rounding of the arc lengths).
    fn min_part(&self, leaf: usize) -> f64 {
        1e-6 * (1.0 + self.leaves[leaf].perimeter())
    }

    /// Cuts (arc lengths strictly inside each piece, per leaf and piece) that split the pieces
    /// `tours` visit in four and halve their neighbours, granted in the tours' order while
    /// the node count stays within `max_nodes`, then the pieces holding the incumbent's pierce
    /// points.
    fn cuts_in_parts(
        &self,
        node_piece: &[(usize, usize)],
        tours: &[Vec<usize>],
        max_nodes: usize,
    ) -> Vec<Vec<Vec<f64>>> {
        // Parts per piece: 1 keeps it, 2 halves it, 4 quarters it; granted in the tours'
        // order, so that at the node limit the most important pieces are the split ones (not
        // the first contours').
        let mut parts: Vec<Vec<usize>> = self.pieces.iter().map(|p| vec![1; p.len()]).collect();
        let mut nodes = self.node_count();
        let mut grant = |leaf: usize, k: usize, n: usize, pieces: &[(f64, f64)]| {
            let (a, b) = pieces[k];
            let old = parts[leaf][k];
            if n > old && b - a > n as f64 * self.min_part(leaf) && nodes + n - old <= max_nodes {
                nodes += n - old;
                parts[leaf][k] = n;
            }
        };
        let incumbent_nodes: Vec<(usize, usize)> = self
            .incumbent
            .iter()
            .filter_map(|&(leaf, s)| {
                let k = self.pieces[leaf]
                    .iter()
                    .position(|&(a, b)| a <= s && s <= b)?;
                Some((leaf, k))
            })
            .collect();
        let marks = tours
            .iter()
            .flatten()
            .filter_map(|&v| v.checked_sub(1).and_then(|i| node_piece.get(i)).copied())
            .chain(incumbent_nodes);
        for (leaf, k) in marks {
            let pieces = &self.pieces[leaf];
            let n = pieces.len();
            grant(leaf, k, 4, pieces);
            for j in [(k + n - 1) % n, (k + 1) % n] {
                grant(leaf, j, 2, pieces);
            }
        }
        self.pieces
            .iter()
            .zip(&parts)
            .map(|(pieces, parts)| {
                pieces
                    .iter()
                    .zip(parts)
                    .map(|(&(a, b), &n)| {
                        (1..n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
                    })
                    .collect()
            })
            .collect()
    }

    /// Cuts (as [`CcpLowerBound::cuts_in_parts`]) where the tours turn: for each visit of a
    /// tour, in the tours' order while the node count stays within `max_nodes`, one cut at the
    /// midpoint of the stretch between the points where the visit is charged for entering and
    /// for leaving its piece ([`CcpLowerBound::turn_split`]), unless a cut already lies in the
    /// middle half of that stretch; then the piece's neighbours along the contour are halved
    /// unless already cut (with the piece split, the next relaxed optimum tends to move next
    /// door). On nested.dbs at 2,500 nodes one such cut raised the cheapest relaxed tour
    /// about twice as much per node as quartering the visited piece.
    fn cuts_at_turns(
        &self,
        node_piece: &[(usize, usize)],
        tours: &[Vec<usize>],
        max_nodes: usize,
    ) -> Vec<Vec<Vec<f64>>> {
        let mut cuts: Vec<Vec<Vec<f64>>> = self
            .pieces
            .iter()
            .map(|p| vec![Vec::new(); p.len()])
            .collect();
        let visits = |tour: &[usize]| -> Vec<usize> {
            tour.iter()
                .copied()
                .filter(|&v| v > 0 && v <= node_piece.len())
                .collect()
        };
        let mut shapes: Vec<Option<PieceShape>> = vec![None; node_piece.len()];
        for v in tours.iter().flat_map(|t| visits(t)) {
            if shapes[v - 1].is_none() {
                let (leaf, k) = node_piece[v - 1];
                let (a, b) = self.pieces[leaf][k];
                shapes[v - 1] = Some(PieceShape::new(self.leaves[leaf].piece_spans(a, b)));
            }
        }
        let start = PieceShape::point(self.options.start);
        let finish = self.options.finish.map(PieceShape::point);
        let mut nodes = self.node_count();
        for tour in tours {
            let visits = visits(tour);
            for (i, &v) in visits.iter().enumerate() {
                let (leaf, k) = node_piece[v - 1];
                let from = match i.checked_sub(1) {
                    Some(j) => shapes[visits[j] - 1].as_ref(),
                    None => Some(&start),
                };
                // After the last visit the tail goes to the outermost contour around it, else
                // to the finish; an open route without either ends in the piece (no exit).
                let to = match visits.get(i + 1) {
                    Some(&w) => shapes[w - 1].as_ref(),
                    None => self.leaves[leaf]
                        .outermost
                        .and_then(|o| self.outermost_shapes.get(&o))
                        .or(finish.as_ref()),
                };
                let (Some(from), Some(to), Some(piece)) = (from, to, shapes[v - 1].as_ref()) else {
                    continue;
                };
                let Some((entry, exit)) = self.turn_split(leaf, k, piece, from, to) else {
                    continue;
                };
                let min_part = self.min_part(leaf);
                let cut = 0.5 * (entry + exit);
                let here = &cuts[leaf][k];
                let (a, b) = self.pieces[leaf][k];
                let taken = here
                    .iter()
                    .any(|&c| (c - cut).abs() < 0.25 * (entry - exit).abs());
                let room = [a, b]
                    .iter()
                    .chain(here)
                    .all(|&c| (c - cut).abs() > min_part);
                if !taken && room && nodes < max_nodes {
                    cuts[leaf][k].push(cut);
                    nodes += 1;
                }
                let n = self.pieces[leaf].len();
                for j in [(k + n - 1) % n, (k + 1) % n] {
                    let (a, b) = self.pieces[leaf][j];
                    if cuts[leaf][j].is_empty() && b - a > 2.0 * min_part && nodes < max_nodes {
                        cuts[leaf][j].push(0.5 * (a + b));
                        nodes += 1;
                    }
                }
            }
        }
        cuts
    }

    /// The arc lengths of the points of piece `k` of kept contour `leaf` (whose shape is
    /// `piece`) nearest to `from` and to `to`: where a relaxed tour that comes from `from` and
    /// goes on to `to` is charged for entering and for leaving the piece. `None` when they are
    /// too close to be told apart by a cut.
    fn turn_split(
        &self,
        leaf: usize,
        k: usize,
        piece: &PieceShape,
        from: &PieceShape,
        to: &PieceShape,
    ) -> Option<(f64, f64)> {
        let (a, b) = self.pieces[leaf][k];
        let entry = piece.nearest_length(a, from).clamp(a, b);
        let exit = piece.nearest_length(a, to).clamp(a, b);
        ((entry - exit).abs() > 2.0 * self.min_part(leaf)).then_some((entry, exit))
    }
}

/// Per-stage numbers on stderr when `CCP_BOUND_DEBUG` is set (benchmark diagnostics).
fn debug_log(message: impl FnOnce() -> String) {
    if std::env::var_os("CCP_BOUND_DEBUG").is_some() {
        eprintln!("[ccp bound] {}", message());
    }
}

/// Splits the kept contours into groups of at most `size` that lie together: units (the kept
/// contours inside one outermost contour, or a lone contour; a unit larger than `size` is
/// split into its contours) halved recursively across the longer side of their box, at the
/// median by count. Few, compact groups keep the decomposition's loss at the group borders
/// small.
fn spatial_groups(leaves: &[Leaf], size: usize) -> Vec<Vec<usize>> {
    let mut by_outer: HashMap<ContourRef, Vec<usize>> = HashMap::new();
    let mut units: Vec<Vec<usize>> = Vec::new();
    for (i, leaf) in leaves.iter().enumerate() {
        match leaf.outermost {
            Some(o) => by_outer.entry(o).or_default().push(i),
            None => units.push(vec![i]),
        }
    }
    let mut outer: Vec<(ContourRef, Vec<usize>)> = by_outer.into_iter().collect();
    // HashMap order is not deterministic: sort so the groups are.
    outer.sort_by_key(|(_, m)| m[0]);
    for (_, members) in outer {
        if members.len() > size {
            units.extend(members.into_iter().map(|i| vec![i]));
        } else {
            units.push(members);
        }
    }
    let centre = |unit: &[usize]| {
        let b = unit
            .iter()
            .map(|&i| leaves[i].contour.bounding_box())
            .fold(BoundingBox::default(), |acc, b| acc.union(b));
        Point::new(0.5 * (b.min.x + b.max.x), 0.5 * (b.min.y + b.max.y))
    };
    let units: Vec<(Point, Vec<usize>)> = units.into_iter().map(|u| (centre(&u), u)).collect();
    let mut out = Vec::new();
    let mut todo = vec![units];
    while let Some(mut set) = todo.pop() {
        let count: usize = set.iter().map(|(_, u)| u.len()).sum();
        if count <= size || set.len() < 2 {
            out.push(set.into_iter().flat_map(|(_, u)| u).collect());
            continue;
        }
        let b = set
            .iter()
            .fold(BoundingBox::default(), |acc, (c, _)| acc.including(*c));
        if b.width() >= b.height() {
            set.sort_by(|p, q| p.0.x.total_cmp(&q.0.x).then(p.0.y.total_cmp(&q.0.y)));
        } else {
            set.sort_by(|p, q| p.0.y.total_cmp(&q.0.y).then(p.0.x.total_cmp(&q.0.x)));
        }
        // Halves of equal count, in multiples of `size` where possible (fewer groups).
        let parts = count.div_ceil(size);
        let target = parts / 2 * count / parts;
        let mut taken = 0;
        let mut cut = 0;
        while cut + 1 < set.len() && taken + set[cut].1.len() <= target.max(1) {
            taken += set[cut].1.len();
            cut += 1;
        }
        let cut = cut.max(1);
        let rest = set.split_off(cut);
        todo.push(set);
        todo.push(rest);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, Part, Vertex};

    /// Every kept contour's pieces are a partition of `[0, perimeter]` into contiguous,
    /// non-empty intervals.
    fn assert_pieces_partition(bound: &CcpLowerBound) {
        for (leaf, pieces) in bound.pieces.iter().enumerate() {
            let perimeter = bound.leaves[leaf].perimeter();
            assert_eq!(pieces[0].0, 0.0);
            assert_eq!(pieces.last().unwrap().1, perimeter);
            for w in pieces.windows(2) {
                assert_eq!(w[0].1, w[1].0, "a gap or overlap between pieces");
            }
            assert!(pieces.iter().all(|&(a, b)| a < b), "an empty piece");
        }
    }

    fn grid_nest(columns: usize, rows: usize) -> Nest {
        let square = |x: f64, y: f64| Part {
            name: format!("square at {x},{y}"),
            contours: vec![Contour::new(vec![
                Vertex::line(x, y),
                Vertex::line(x, y + 10.0),
                Vertex::line(x + 10.0, y + 10.0),
                Vertex::line(x + 10.0, y),
            ])],
        };
        let parts = (0..columns * rows)
            .map(|i| square(20.0 * (i % columns) as f64, 20.0 * (i / columns) as f64))
            .collect();
        Nest { sheet: None, parts }
    }

    /// The pieces of every kept contour stay a partition of `[0, perimeter]` into contiguous,
    /// non-empty intervals (sorted) under refinement with any marks, the node
    /// limit holds, and the first marked piece is split while there is room.
    #[test]
    fn refinement_keeps_the_pieces_a_partition_within_the_node_limit() {
        let nest = grid_nest(3, 2);
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            rng ^= rng >> 12;
            rng ^= rng << 25;
            rng ^= rng >> 27;
            rng.wrapping_mul(0x2545_F491_4F6C_DD1D) as usize
        };
        for max_nodes in [20, 60, 200] {
            let options = LowerBoundOptions {
                initial_pieces: 12,
                max_nodes,
                group_size: 0,
                ng_size: 0,
                ..LowerBoundOptions::default()
            };
            let mut bound = CcpLowerBound::new(&nest, options).unwrap();
            for _ in 0..12 {
                let node_piece: Vec<(usize, usize)> = bound
                    .pieces
                    .iter()
                    .enumerate()
                    .flat_map(|(leaf, p)| (0..p.len()).map(move |k| (leaf, k)))
                    .collect();
                let marked: Vec<usize> = (0..8).map(|_| 1 + next() % node_piece.len()).collect();
                let (leaf, k) = node_piece[marked[0] - 1];
                let first = bound.pieces[leaf][k];
                let before = bound.node_count();
                bound.refine(&node_piece, &[marked], false);
                assert!(bound.node_count() <= max_nodes.max(before));
                if before + 3 <= max_nodes {
                    assert!(
                        !bound.pieces[leaf].contains(&first),
                        "the first marked piece was not split"
                    );
                }
                assert_pieces_partition(&bound);
            }
        }
    }

    /// Splitting at the turns of relaxed tours: every visit whose entry and exit points lie
    /// apart gets a piece boundary strictly between them while there is room (so neither part
    /// holds both), the pieces stay a partition of `[0, perimeter]`, and the node limit
    /// holds; open and closed routes, outermost contours around the kept ones or not.
    #[test]
    fn splits_at_turns_separate_entry_and_exit_within_the_node_limit() {
        let framed = {
            let mut nest = grid_nest(3, 2);
            nest.parts.push(Part {
                name: "frame".into(),
                contours: vec![Contour::new(vec![
                    Vertex::line(-5.0, -5.0),
                    Vertex::line(-5.0, 35.0),
                    Vertex::line(55.0, 35.0),
                    Vertex::line(55.0, -5.0),
                ])],
            });
            nest
        };
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            rng ^= rng >> 12;
            rng ^= rng << 25;
            rng ^= rng >> 27;
            rng.wrapping_mul(0x9e37_79b9_7f4a_7c15) as usize
        };
        for (nest, finish) in [
            (grid_nest(3, 2), None),
            (grid_nest(3, 2), Some(Point::new(70.0, 50.0))),
            (framed, None),
        ] {
            for max_nodes in [10, 30, 400] {
                let options = LowerBoundOptions {
                    start: Point::new(-20.0, 7.0),
                    finish,
                    initial_pieces: 12,
                    max_nodes,
                    group_size: 0,
                    ng_size: 0,
                    ..LowerBoundOptions::default()
                };
                let mut bound = CcpLowerBound::new(&nest, options).unwrap();
                let clusters = bound.leaves.len();
                for _ in 0..6 {
                    let node_piece: Vec<(usize, usize)> = bound
                        .pieces
                        .iter()
                        .enumerate()
                        .flat_map(|(leaf, p)| (0..p.len()).map(move |k| (leaf, k)))
                        .collect();
                    let first_node: Vec<usize> = (0..clusters)
                        .map(|leaf| 1 + node_piece.iter().position(|&(l, _)| l == leaf).unwrap())
                        .collect();
                    // A random order of the contours, a random piece of each, after the depot.
                    let mut order: Vec<usize> = (0..clusters).collect();
                    for i in (1..order.len()).rev() {
                        order.swap(i, next() % (i + 1));
                    }
                    let mut tour = vec![0];
                    tour.extend(
                        order
                            .iter()
                            .map(|&leaf| first_node[leaf] + next() % bound.pieces[leaf].len()),
                    );
                    let shape = |b: &CcpLowerBound, v: usize| {
                        let (leaf, k) = node_piece[v - 1];
                        let (x, y) = b.pieces[leaf][k];
                        PieceShape::new(b.leaves[leaf].piece_spans(x, y))
                    };
                    let start = PieceShape::point(bound.options.start);
                    let mut stretches = Vec::new();
                    for i in 1..tour.len() {
                        let (leaf, k) = node_piece[tour[i] - 1];
                        let from = if i == 1 {
                            start.clone()
                        } else {
                            shape(&bound, tour[i - 1])
                        };
                        let to = match tour.get(i + 1) {
                            Some(&w) => Some(shape(&bound, w)),
                            None => bound.leaves[leaf]
                                .outermost
                                .and_then(|o| bound.outermost_shapes.get(&o).cloned())
                                .or(finish.map(PieceShape::point)),
                        };
                        let Some(to) = to else { continue };
                        let piece = shape(&bound, tour[i]);
                        if let Some((entry, exit)) = bound.turn_split(leaf, k, &piece, &from, &to) {
                            let (a, b) = bound.pieces[leaf][k];
                            assert!(a <= entry.min(exit) && entry.max(exit) <= b);
                            stretches.push((leaf, entry.min(exit), entry.max(exit)));
                        }
                    }
                    let before = bound.node_count();
                    bound.refine(&node_piece, &[tour], true);
                    assert!(bound.node_count() <= max_nodes.max(before));
                    if bound.node_count() + 1 < max_nodes {
                        // Room was left, so no visit was refused its cut.
                        for &(leaf, lo, hi) in &stretches {
                            assert!(
                                bound.pieces[leaf].iter().any(|&(a, _)| lo < a && a < hi),
                                "entry {lo} and exit {hi} still in one piece of contour {leaf}"
                            );
                        }
                    }
                    assert_pieces_partition(&bound);
                }
            }
        }
    }

    /// The decomposition runs one group's stage at a time (the memory of a stage — its cost
    /// matrix, the exact solver's model copies and DP — is held by one group only), in slices
    /// of any length, and the groups still all get stages.
    #[test]
    fn one_group_at_a_time_holds_a_stage() {
        let nest = grid_nest(4, 3);
        let options = LowerBoundOptions {
            start: Point::new(-10.0, -10.0),
            group_size: 2,
            decompose_above: 0,
            first_stage: Duration::from_millis(20),
            ..LowerBoundOptions::default()
        };
        let mut bound = CcpLowerBound::new(&nest, options).unwrap();
        assert!(bound.group_count() >= 4);
        for slice_us in [200u64, 3_000, 40_000].into_iter().cycle().take(300) {
            if !bound.step(Duration::from_micros(slice_us)) {
                break;
            }
            let holding = bound.groups.iter().filter(|g| g.stage.is_some()).count();
            assert!(holding <= 1, "{holding} groups hold a stage at once");
        }
        assert!(
            bound.groups.iter().all(|g| g.stages() >= 1),
            "a group never finished a stage: {:?}",
            bound.groups.iter().map(|g| g.stages()).collect::<Vec<_>>()
        );
        assert!(bound.group_sum() > 0.0);
    }
}
