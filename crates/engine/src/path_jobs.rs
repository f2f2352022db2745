//! The jobs whose routes are tool-on paths ([`PathRoute`]): segment cutting (SCCP, GSCCP) and
//! common-edge routes (AOE). Their progress carries `path_route` (never `route`), the
//! objective's value of the best route as `upper_bound` (seconds or cost, by
//! `params.objective`), a lower bound in the same unit, and the candidates weighed as
//! `alternatives`.

use cutroute_aoe::{
    AoeHeat, AoeSolution, AoeSolveError, AoeSolveOptions, AoeSolving, AoeStage, EmbeddingError,
    PlanError, PlanGraph, PlanOptions,
};
use cutroute_ccp::CcpLowerBound;
use cutroute_geometry::float::Libm;
use cutroute_geometry::{
    BoundingBox, MachineParameters, Nest, Objective, PathRoute, Point, Route, Span,
};
use cutroute_protocol::{
    Bounds, Ensemble, JobId, JobRequest, Phase, Problem, Progress, RouteSummary, Solution,
    SolverKind,
};
use cutroute_segments::{
    Candidate, EnsembleKind, EnsembleReport, GsccpOptions, GsccpSearch, GsccpStage, PathHeat,
    SccpOptions,
};
use std::cmp::Ordering;
use std::collections::HashMap;
use web_time::{Duration, Instant};

use crate::jobs::continuous_lower_bound;
use crate::{EngineError, Job, JobStatus, NearestNeighbourJob};

/// Why a [`PlanBound`] could not be measured: the nest gives no plane graph.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanBoundError {
    /// The plan graph could not be built.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// A component of the plan graph could not be embedded.
    #[error(transparent)]
    Embedding(#[from] EmbeddingError),
    /// The job was stopped before the plan graph was measured.
    #[error("stopped before the plan graph was measured")]
    Stopped,
}

/// What every route of a plan must at least cut and pierce, from the nest's plane graph
/// (`cutroute-aoe`'s [`PlanGraph`]: contours split at touchings and crossings, common edges
/// merged).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanBound {
    /// Total length of the plan graph's edges less their merging tolerance (mm): every
    /// contour is covered by every route, so every route cuts at least the length of their
    /// union.
    pub cut_length: f64,
    /// Connected components of the plan graph: a tool-on path of these solvers never leaves
    /// its component, so each needs a pierce.
    pub components: usize,
    /// Σ over components of max(1, odd vertices / 2): the pierces of any route that cuts every
    /// plan edge exactly once as trails (SCCP's chain segments, AOE's chains). Routes that cut
    /// edges twice (standard cutting) may pierce less.
    pub trail_pierces: usize,
    /// Idle travel no route of these solvers avoids (mm): the larger of [`idle_tree_bound`]
    /// over the plan's components and the travel from the start to the parts' bounding box and
    /// from it to the finish.
    pub idle_length: f64,
    /// Whether every component is one contour (no two contours touch): then every tool-on path
    /// runs along one contour, and a bound on CCP routes carries over
    /// ([`PlanBound::any_route_with_ccp`]).
    pub whole_contours: bool,
    /// The largest bounding-box diagonal of a contour (mm): at least its diameter.
    pub diameter: f64,
    /// How much longer the contours are than the plan graph (mm, at least 0): what a contour
    /// traces twice over itself (a zero-area contour, a slit), which a CCP route cuts twice
    /// and a route of the plan may cut once, ending away from its pierce point.
    pub overlap: f64,
}

/// The work [`idle_tree_bound`] may spend on exact component distances (span pairs measured);
/// the pairs left then count by their boxes' distance. A count, not a clock, so the bound does
/// not depend on the machine.
const EXACT_SPAN_PAIRS: usize = 400_000;

/// Nearest components (by box distance) whose exact distance [`idle_tree_bound`] measures;
/// the other pairs count by their boxes' distance.
const EXACT_NEIGHBOURS: usize = 8;

/// Above this many components the O(n²) spanning tree is not built (a single step must stay
/// short) and [`idle_tree_bound`] returns 0.
const TREE_COMPONENTS: usize = 3_000;

/// A lower bound (mm) on the idle length of every route that cuts `components` (each a set of
/// spans) with tool-on paths that never leave a component, from `start` (to `finish`): the
/// weight of a minimum spanning tree over the start, the components and the finish, each edge
/// weighted by a lower bound on the distance between its two sets, less `tolerance` (the
/// plan graph merges common edges, moving them by up to that much).
///
/// Why it is sound: a route's tool runs start → pierce → … → finish; tool-on paths stay inside
/// one component, so every change of component is an idle move from a point of one set to a
/// point of the other, at least their set distance long. The idle moves between different
/// nodes, taken in the route's order, form a walk through every node (every component is cut,
/// so visited), hence a connected spanning subgraph, whose weight is at least the minimum
/// spanning tree's. The walk never steps from the start straight to the finish (it reaches the
/// finish from the last component), so that edge is left out of the graph. Idle moves inside a component only add. Edge weights below the true set
/// distance (box distances, exact distances less the tolerance) can only lower the tree.
pub fn idle_tree_bound(
    components: &[Vec<Span>],
    start: Point,
    finish: Option<Point>,
    tolerance: f64,
) -> f64 {
    let k = components.len();
    if k == 0 || k > TREE_COMPONENTS {
        return 0.0;
    }
    let boxes: Vec<BoundingBox> = components
        .iter()
        .map(|spans| {
            spans
                .iter()
                .fold(BoundingBox::EMPTY, |b, s| b.union(s.bounding_box()))
        })
        .collect();
    let span_boxes: Vec<Vec<BoundingBox>> = components
        .iter()
        .map(|spans| spans.iter().map(|s| s.bounding_box()).collect())
        .collect();
    let to_point = |c: usize, p: Point| -> f64 {
        components[c]
            .iter()
            .map(|s| s.distance_to(p))
            .fold(f64::INFINITY, f64::min)
    };
    // Exact distances to each component's nearest neighbours by box, within the work budget.
    let mut exact: HashMap<(usize, usize), f64> = HashMap::new();
    let mut work = 0usize;
    for a in 0..k {
        let mut near: Vec<(f64, usize)> = (0..k)
            .filter(|&b| b != a)
            .map(|b| (boxes[a].distance_to_box(&boxes[b]), b))
            .collect();
        let n = near.len().min(EXACT_NEIGHBOURS);
        if n == 0 {
            continue;
        }
        near.select_nth_unstable_by(n - 1, |x, y| x.0.total_cmp(&y.0));
        for &(_, b) in &near[..n] {
            let key = (a.min(b), a.max(b));
            if exact.contains_key(&key) {
                continue;
            }
            let pairs = components[a].len() * components[b].len();
            if work + pairs > EXACT_SPAN_PAIRS {
                continue;
            }
            work += pairs;
            let mut best = f64::INFINITY;
            for (sa, ba) in components[a].iter().zip(&span_boxes[a]) {
                if ba.distance_to_box(&boxes[b]) >= best {
                    continue;
                }
                for (sb, bb) in components[b].iter().zip(&span_boxes[b]) {
                    if ba.distance_to_box(bb) < best {
                        best = best.min(sa.distance_to_span(sb));
                    }
                }
            }
            exact.insert(key, best);
        }
    }
    // Nodes: 0 the start, 1..=k the components, k + 1 the finish (if any).
    let n = k + 1 + usize::from(finish.is_some());
    let weight = |i: usize, j: usize| -> f64 {
        let (i, j) = (i.min(j), i.max(j));
        let raw = if i == 0 && j == k + 1 {
            // The walk reaches the finish from a component, never from the start (k ≥ 1).
            f64::INFINITY
        } else if i == 0 {
            to_point(j - 1, start)
        } else if j == k + 1 {
            to_point(i - 1, finish.expect("the finish node"))
        } else {
            let (a, b) = (i - 1, j - 1);
            exact
                .get(&(a, b))
                .copied()
                .unwrap_or_else(|| boxes[a].distance_to_box(&boxes[b]))
        };
        (raw - 2.0 * tolerance).max(0.0)
    };
    // Prim's algorithm on the complete graph: O(n²), no edge list.
    let mut in_tree = vec![false; n];
    let mut key = vec![f64::INFINITY; n];
    key[0] = 0.0;
    let mut total = 0.0;
    for _ in 0..n {
        let mut u = usize::MAX;
        for v in 0..n {
            if !in_tree[v] && (u == usize::MAX || key[v] < key[u]) {
                u = v;
            }
        }
        in_tree[u] = true;
        total += key[u];
        for v in 0..n {
            if !in_tree[v] {
                let w = weight(u, v);
                if w < key[v] {
                    key[v] = w;
                }
            }
        }
    }
    if total.is_finite() {
        total
    } else {
        0.0
    }
}

impl PlanBound {
    /// Measures the plan graph of `nest` built with `tolerance` (mm).
    pub fn new(
        nest: &Nest,
        start: Point,
        finish: Option<Point>,
        tolerance: f64,
    ) -> Result<Self, PlanBoundError> {
        let plan = PlanGraph::from_nest(
            nest,
            &PlanOptions {
                tolerance,
                ..PlanOptions::default()
            },
        )?;
        Self::from_plan(&plan, nest, start, finish, tolerance)
    }

    /// Measures `plan`, the plan graph of `nest` built with `tolerance` (mm).
    pub fn from_plan(
        plan: &PlanGraph,
        nest: &Nest,
        start: Point,
        finish: Option<Point>,
        tolerance: f64,
    ) -> Result<Self, PlanBoundError> {
        let graph = plan.graph();
        let edges = graph.edge_count();
        let length: f64 = (0..edges)
            .flat_map(|e| plan.edge_spans(e).iter())
            .map(|s| s.length())
            .sum();
        let components = plan.components()?;
        let trail_pierces = components
            .iter()
            .map(|c| cutroute_aoe::pierce_lower_bound(c.embedding.graph()))
            .sum();
        let component_spans: Vec<Vec<Span>> = components
            .iter()
            .map(|c| {
                c.edges
                    .iter()
                    .flat_map(|&e| plan.edge_spans(e).iter().copied())
                    .collect()
            })
            .collect();
        let tree = idle_tree_bound(&component_spans, start, finish, tolerance);
        let b = nest.bounding_box();
        let to_box = |p: Point| {
            let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
            let dy = (b.min.y - p.y).max(p.y - b.max.y).max(0.0);
            dx.hypot_libm(dy)
        };
        let contours = nest.parts.iter().flat_map(|p| &p.contours);
        let perimeters: f64 = nest
            .parts
            .iter()
            .flat_map(|p| &p.contours)
            .map(|c| c.perimeter())
            .sum();
        // One contour per component: each component's edges belong to one contour alone (a
        // contour the plan left out, e.g. one of zero size, would make the counts agree by
        // chance otherwise).
        let one_contour_each = components.iter().all(|c| {
            let mut owners = c.edges.iter().flat_map(|&e| plan.edge_contours(e));
            owners
                .next()
                .is_some_and(|first| owners.all(|other| other == first))
        });
        Ok(PlanBound {
            // Merged copies of a common edge agree within the tolerance at their ends.
            cut_length: (length - 4.0 * tolerance * edges as f64).max(0.0),
            components: components.len(),
            trail_pierces,
            idle_length: tree.max(to_box(start) + finish.map_or(0.0, to_box)),
            // A contour is connected, so it lies in one component and each component holds
            // one at least: as many components as contours means one contour each.
            whole_contours: one_contour_each && components.len() == nest.contour_count(),
            diameter: contours
                .map(|c| {
                    let b = c.bounding_box();
                    (b.max.x - b.min.x).hypot_libm(b.max.y - b.min.y)
                })
                .fold(0.0, f64::max),
            // The plan's edges may lie up to the tolerance short of their contours at each end.
            overlap: (perimeters - length + 4.0 * tolerance * edges as f64).max(0.0),
        })
    }

    /// The objective's lower bound for every route of the plan model (see below), given
    /// `ccp_idle`: a certified lower bound on the idle length of every CCP route from the same
    /// start (and to the same finish; `cutroute-ccp`'s `CcpLowerBound`). Where contours touch it is
    /// [`PlanBound::any_route`].
    ///
    /// Why it holds when every component is one contour (so every tool-on path runs along one
    /// contour): take a route with `n + e` pierces (`n` contours) that cuts `r` mm more than
    /// the plan. Cut each contour whole at the time of its last path, from that path's start
    /// round to it, and drop its other paths. That is a CCP route: each contour is cut after
    /// every contour inside it, as the route's precedence already had it. Its idle length
    /// grows by at most a diameter `D` per path of a contour cut in several (at most `2D` per
    /// extra pierce), and where one path both cuts a contour whole and ends at `q` away from
    /// its start `p`, by `|pq|`, which is at most the part cut twice plus the contour's own
    /// overlap ([`PlanBound::overlap`]): on the plan's edges, those the path runs an odd
    /// number of times join `p` to `q`, those the contour runs an odd number of times form
    /// cycles, so their symmetric difference still joins `p` to `q`, and each of its edges is
    /// run twice by the path (the part cut twice) or twice by the contour (the overlap). So
    /// the route idles at least `max(tree, ccp_idle − Ω − 2D·e − r)` (`Ω` the overlap), and
    /// with the prices `a` (per mm cut), `b` (per mm idle) and `c` (per pierce), its value is
    /// at least `any_route + (ccp_idle − Ω − tree)⁺ · min(a, b, c / 2D)`: a pierce saves at
    /// most `2D` mm of idle travel, a millimetre cut twice at most one.
    ///
    /// The routes bounded are those of the plan model: every tool-on path runs along the
    /// contours, and between paths the tool is off (an idle move, then a pierce). A `chain`
    /// route's tool-on links through the scrap leave that model and may be worth less.
    pub fn any_route_with_ccp(
        &self,
        ccp_idle: f64,
        objective: Objective,
        machine: &MachineParameters,
    ) -> f64 {
        let plain = self.any_route(objective, machine);
        let ccp_idle = ccp_idle - self.overlap;
        // (A NaN bound tells nothing either.)
        if !self.whole_contours
            || ccp_idle.partial_cmp(&self.idle_length) != Some(Ordering::Greater)
        {
            return plain;
        }
        let (a, b, c) = prices(objective, machine);
        let per_pierce = if self.diameter > 0.0 {
            c / (2.0 * self.diameter)
        } else {
            f64::INFINITY
        };
        plain + (ccp_idle - self.idle_length) * a.min(b).min(per_pierce).max(0.0)
    }

    /// A lower bound on the idle length (mm) of every route whose objective value is at most
    /// `upper` (the best route's: every route at least as good idles at least this much),
    /// given `ccp_idle` as in [`PlanBound::any_route_with_ccp`]. Where contours touch, or
    /// without `upper`, it is [`PlanBound::idle_length`].
    ///
    /// A route with `e` extra pierces and `r` mm cut twice idles `x ≥ ccp_idle − Ω − 2D·e − r`
    /// (see [`PlanBound::any_route_with_ccp`]), and being at least as good it has
    /// `c·e + a·r + b·x ≤ S = upper − value(plan cut, no idle, n pierces)`. Extra pierces
    /// need `c ≤ S`; then `2D·e + r ≤ k·(S − b·x)` with `k = max(2D / c, 1 / a)` (else
    /// `k = 1 / a`), so `x ≥ (ccp_idle − Ω − k·S) / (1 − k·b)` when `k·b < 1`.
    pub fn idle_at_most(
        &self,
        ccp_idle: f64,
        upper: Option<f64>,
        objective: Objective,
        machine: &MachineParameters,
    ) -> f64 {
        let ccp_idle = ccp_idle - self.overlap;
        let Some(upper) = upper.filter(|_| self.whole_contours && ccp_idle > self.idle_length)
        else {
            return self.idle_length;
        };
        let (a, b, c) = prices(objective, machine);
        let slack =
            (upper - objective.value(machine, self.cut_length, 0.0, self.components)).max(0.0);
        let per_recut = if a > 0.0 { 1.0 / a } else { f64::INFINITY };
        let k = if c > slack {
            per_recut
        } else if c > 0.0 {
            (2.0 * self.diameter / c).max(per_recut)
        } else {
            f64::INFINITY
        };
        if (k * b).partial_cmp(&1.0) != Some(Ordering::Less) {
            return self.idle_length;
        }
        self.idle_length.max((ccp_idle - k * slack) / (1.0 - k * b))
    }

    /// The objective's lower bound for routes that may cut edges twice (GSCCP's standard
    /// ensemble, the CCP route): at least one pierce per component.
    pub fn any_route(&self, objective: Objective, machine: &MachineParameters) -> f64 {
        objective.value(machine, self.cut_length, self.idle_length, self.components)
    }

    /// The objective's lower bound for routes that cut every plan edge once as trails (AOE).
    pub fn trail_route(&self, objective: Objective, machine: &MachineParameters) -> f64 {
        objective.value(
            machine,
            self.cut_length,
            self.idle_length,
            self.trail_pierces,
        )
    }
}

/// An objective's prices: per mm cut, per mm of idle travel, per pierce (it is linear in
/// each).
fn prices(objective: Objective, machine: &MachineParameters) -> (f64, f64, f64) {
    let zero = objective.value(machine, 0.0, 0.0, 0);
    (
        objective.value(machine, 1.0, 0.0, 0) - zero,
        objective.value(machine, 0.0, 1.0, 0) - zero,
        objective.value(machine, 0.0, 0.0, 1) - zero,
    )
}

fn summary(name: &str, route: &PathRoute, machine: &MachineParameters) -> RouteSummary {
    RouteSummary {
        name: name.to_string(),
        pierces: route.pierce_count(),
        idle_length: route.idle_length(),
        cut_length: route.cut_length(),
        time_s: route.time(machine),
        cost: route.cost(machine),
        chosen: false,
        failure: None,
        idle_lower_bound: None,
    }
}

fn report_summary(report: &EnsembleReport) -> RouteSummary {
    RouteSummary {
        name: report.kind.name().to_string(),
        pierces: report.pierces,
        idle_length: report.idle_length,
        cut_length: report.cut_length,
        time_s: report.time_s,
        cost: report.cost,
        chosen: false,
        failure: report.failure.as_ref().map(ToString::to_string),
        idle_lower_bound: None,
    }
}

/// The nest, start and finish of a nest request, or why the solver cannot take it.
fn nest_of(request: &JobRequest) -> Result<(&Nest, Point, Option<Point>), EngineError> {
    match &request.problem {
        Problem::Nest {
            nest,
            start,
            finish,
        } => {
            if nest.contour_count() == 0 {
                return Err(EngineError::EmptyNest);
            }
            Ok((nest, *start, *finish))
        }
        Problem::PcgtspText { .. } => Err(EngineError::UnsupportedProblem {
            solver: request.solver.name(),
            problem: "a PCGTSP instance",
        }),
    }
}

/// Segment cutting (`cutroute-segments`' [`GsccpSearch`]): CCP-Relax seeds the orders, then
/// each ensemble is built and searched in slices; SCCP is the chains ensemble alone, GSCCP
/// every ensemble, the best by the objective kept. The first step measures the plan graph for
/// the lower bound (at least the plan's length cut and one pierce per component). Where no two
/// contours touch, the next makes the continuous bound of CCP, which then gets half of each
/// slice while the search runs and tightens the bound ([`PlanBound::any_route_with_ccp`]);
/// the job ends with the search, once the bound's first stage is done (within the limit).
pub struct SegmentJob {
    job_id: JobId,
    search: GsccpSearch,
    nest: Nest,
    start: Point,
    finish: Option<Point>,
    machine: MachineParameters,
    objective: Objective,
    tolerance: f64,
    bound: Option<Result<PlanBound, PlanBoundError>>,
    ccp_bound: CcpBound,
    time_limit: Duration,
    started: Instant,
}

/// The continuous bound of CCP inside a [`SegmentJob`].
enum CcpBound {
    /// Waiting for the plan graph: it tells whether the bound carries over.
    Undecided,
    /// Contours touch (a path may leave a contour along a common edge), there is no plane
    /// graph, or the bound could not be made.
    Inapplicable,
    /// Computed beside the search; `running` is false once it has nothing left to do.
    Computing {
        bound: Box<CcpLowerBound>,
        running: bool,
        /// The idle length of the last CCP-Relax route offered to it (its pierce points
        /// guide the refinement).
        offered: f64,
    },
}

impl CcpBound {
    fn value(&self) -> Option<f64> {
        match self {
            CcpBound::Computing { bound, .. } => Some(bound.lower_bound()),
            _ => None,
        }
    }

    fn is_running(&self) -> bool {
        matches!(self, CcpBound::Computing { running: true, .. })
    }
}

impl SegmentJob {
    /// The job of an `sccp` or `gsccp` request on a nest.
    pub fn from_request(request: &JobRequest) -> Result<Self, EngineError> {
        let (nest, start, finish) = nest_of(request)?;
        let params = &request.params;
        let kinds = match request.solver {
            SolverKind::Sccp => vec![EnsembleKind::Chains],
            SolverKind::Gsccp => EnsembleKind::ALL.to_vec(),
            other => {
                return Err(EngineError::UnsupportedProblem {
                    solver: other.name(),
                    problem: "a nest by segment cutting",
                })
            }
        };
        let options = GsccpOptions {
            sccp: SccpOptions {
                start,
                finish,
                time_limit: Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7)),
                seed: params.seed,
                // With a heat weight the VNS and the choice between ensembles (and GSCCP's
                // CCP-Relax seed) add W·H, priced on the machine clock of `params.machine`.
                heat: params.thermal.penalised().then(|| PathHeat {
                    penalty: crate::thermal::heat_penalty(&params.thermal, params.objective),
                    machine: params.machine,
                }),
                ..SccpOptions::default()
            },
            kinds,
            machine: params.machine,
            objective: params.objective,
            seed: params.seed,
            ..GsccpOptions::default()
        };
        let search = GsccpSearch::new(nest, &options).map_err(|e| EngineError::SolverRefused {
            solver: request.solver.name(),
            reason: e.into(),
        })?;
        Ok(SegmentJob {
            job_id: request.job_id,
            search,
            nest: nest.clone(),
            start,
            finish,
            machine: params.machine,
            objective: params.objective,
            tolerance: nest.check_tolerance(),
            bound: None,
            ccp_bound: CcpBound::Undecided,
            time_limit: Duration::from_secs_f64(params.time_limit_s.clamp(0.0, 1.0e7)),
            started: Instant::now(),
        })
    }

    /// The search behind the job (its ensembles' reports, the CCP route, the result).
    pub fn search(&self) -> &GsccpSearch {
        &self.search
    }

    /// The plan graph's bound, once the first step has measured it (`Err`: no plane graph).
    pub fn plan_bound(&self) -> Option<&Result<PlanBound, PlanBoundError>> {
        self.bound.as_ref()
    }
}

impl Job for SegmentJob {
    fn stop(&mut self) {
        // The search ends with its best checked route (CCP-Relax's at worst, its run cut
        // short), the bound with what it has.
        self.search.stop();
        if let CcpBound::Computing { running, .. } = &mut self.ccp_bound {
            *running = false;
        } else {
            self.ccp_bound = CcpBound::Inapplicable;
        }
        if self.bound.is_none() {
            // No plan graph yet: the report goes without the bound rather than wait for one.
            self.bound = Some(Err(PlanBoundError::Stopped));
        }
    }

    fn step(&mut self, budget: Duration) -> JobStatus {
        if self.bound.is_none() {
            // A plan graph: one piece of work, a step of its own.
            self.bound = Some(PlanBound::new(
                &self.nest,
                self.start,
                self.finish,
                self.tolerance,
            ));
            return JobStatus::Running;
        }
        if matches!(self.ccp_bound, CcpBound::Undecided) {
            // Making the bound (the nest's pieces and first relaxation) is a step of its own.
            let carries_over = matches!(&self.bound, Some(Ok(plan)) if plan.whole_contours);
            self.ccp_bound = match carries_over.then(|| {
                // It gets half of the search's slices.
                continuous_lower_bound(&self.nest, self.start, self.finish, self.time_limit / 2)
            }) {
                Some(Ok(bound)) => CcpBound::Computing {
                    bound: Box::new(bound),
                    running: true,
                    offered: f64::INFINITY,
                },
                _ => CcpBound::Inapplicable,
            };
            return JobStatus::Running;
        }
        let searching = !self.search.is_finished();
        let share = match (searching, self.ccp_bound.is_running()) {
            (true, true) => budget / 2,
            (true, false) => budget,
            (false, _) => Duration::ZERO,
        };
        // (A finished search returns its status at once.)
        let status = self.search.step(share);
        if let CcpBound::Computing {
            bound,
            running: running @ true,
            offered,
        } = &mut self.ccp_bound
        {
            if let Some((route, idle)) = self.search.ccp_cutting_route() {
                if idle < *offered {
                    bound.offer_route(route);
                    *offered = idle;
                }
            }
            let left = self.time_limit.saturating_sub(self.started.elapsed());
            // A search that ends first (small nests end in a second) still waits for the
            // bound's first stage, so the bound does not depend on which of the two was faster.
            let wanted = status.is_running() || bound.stages() == 0;
            *running = wanted && !left.is_zero() && bound.step((budget - share).min(left));
            if !status.is_running() && *running {
                return JobStatus::Running;
            }
        }
        status.into()
    }

    fn progress(&self) -> Progress {
        let best = self.search.best();
        let chosen = best.map(|c: &Candidate| c.source);
        let mut alternatives = Vec::new();
        if let Some(ccp) = self.search.ccp_route() {
            let mut s = summary("ccp", ccp, &self.machine);
            s.chosen = chosen == Some(None);
            alternatives.push(s);
        }
        for report in self.search.reports() {
            let mut s = report_summary(report);
            s.chosen = report.failure.is_none() && chosen == Some(Some(report.kind));
            alternatives.push(s);
        }
        if let Some(p) = self.search.provisional() {
            // The running ensemble's route so far, or CCP-Relax's while it runs.
            let mut s = summary(
                p.source.map_or("ccp", |k| k.name()),
                &p.route,
                &self.machine,
            );
            s.chosen = chosen == Some(p.source);
            alternatives.push(s);
        }
        let bound = match &self.bound {
            Some(Ok(bound)) => Some(bound),
            _ => None,
        };
        // The route's own objective value (a candidate's value adds W·H with a heat weight,
        // which the plan bound does not bound).
        let upper = best.map(|c| {
            self.objective.value(
                &self.machine,
                c.route.cut_length(),
                c.route.idle_length(),
                c.route.pierce_count(),
            )
        });
        let ccp_idle = self.ccp_bound.value().unwrap_or(0.0);
        let lower_bound =
            bound.map(|b| b.any_route_with_ccp(ccp_idle, self.objective, &self.machine));
        let idle_lower_bound =
            bound.map(|b| b.idle_at_most(ccp_idle, upper, self.objective, &self.machine));
        for s in alternatives.iter_mut().filter(|s| s.chosen) {
            s.idle_lower_bound = idle_lower_bound;
        }
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            bounds: Bounds {
                upper,
                lower: lower_bound,
                unit: self.objective.unit(),
            },
            phase: segments_phase(&self.search),
            solution: best.map(|c| Solution::PathRoute(c.route.clone())),
            proven_optimal: false,
            states: None,
            certified: Vec::new(),
            alternatives,
            idle_lower_bound,
            ..Progress::default()
        }
    }
}

/// Common-edge routes along AOE-chains (`cutroute-aoe`'s [`AoeSolving`], stepped in slices
/// and stopped at the job's limit), then the plan bound on the solver's plan graph in a step of
/// its own. Its lower bound: the plan's length cut once and the trail pierce bound.
pub struct AoeJob {
    job_id: JobId,
    nest: Nest,
    options: AoeSolveOptions,
    finish_bound: (Point, Option<Point>),
    machine: MachineParameters,
    objective: Objective,
    solving: AoeSolving,
    outcome: Option<Result<(AoeSolution, Option<PlanBound>), AoeSolveError>>,
    /// When AOE made no checked route: the contour route it answers with instead.
    fallback: Option<ContourFallback>,
    /// The job's limit, or when it was stopped.
    deadline: Option<Instant>,
    started: Instant,
}

/// The answer of an AOE job whose own route failed (a nest its plan graph cannot take, or a
/// route a checker rejected): the nearest solver's contour route, stepped like any job and
/// taken once it passes the route checker. Every pierce then cuts one whole contour, and no
/// common edge is shared.
struct ContourFallback {
    job: NearestNeighbourJob,
    checked: Option<Route>,
    done: bool,
}

impl ContourFallback {
    fn new(nest: &Nest, (start, finish): (Point, Option<Point>)) -> Option<Self> {
        Some(ContourFallback {
            job: NearestNeighbourJob::new(0, nest.clone(), start, finish).ok()?,
            checked: None,
            done: false,
        })
    }

    /// One slice of the contour route; at `deadline` its route so far is taken (the first
    /// step makes one), checked against `nest`.
    fn step(&mut self, budget: Duration, deadline: Option<Instant>, nest: &Nest) -> JobStatus {
        if self.done {
            return JobStatus::Done;
        }
        let finished = self.job.step(budget) == JobStatus::Done;
        let over = deadline.is_some_and(|end| Instant::now() >= end);
        let progress = self.job.progress();
        let Some(route) = progress.route().filter(|_| finished || over) else {
            return JobStatus::Running;
        };
        let forest = nest.containment_forest();
        self.checked = route
            .problems(nest, &forest, nest.check_tolerance())
            .is_empty()
            .then(|| route.clone());
        self.done = true;
        JobStatus::Done
    }
}

impl AoeJob {
    /// The job of an `aoe` request on a nest.
    pub fn from_request(request: &JobRequest) -> Result<Self, EngineError> {
        let (nest, start, finish) = nest_of(request)?;
        let options = AoeSolveOptions {
            plan: PlanOptions {
                tolerance: nest.check_tolerance(),
                ..PlanOptions::default()
            },
            start,
            finish,
            // With a heat weight the orderings compete on idle + W·H (machine clock of
            // `params.machine`), and a heat-priced greedy ordering joins them.
            heat: request.params.thermal.penalised().then(|| {
                let penalty =
                    crate::thermal::heat_penalty(&request.params.thermal, request.params.objective);
                AoeHeat {
                    model: penalty.model,
                    weight_mm: penalty.weight_mm(&request.params.machine),
                    machine: request.params.machine,
                }
            }),
        };
        let mut solving = AoeSolving::new(nest, &options);
        // The job's wall-clock end: the ordering stops there with its best so far.
        let deadline = Instant::now().checked_add(Duration::from_secs_f64(
            request.params.time_limit_s.clamp(0.0, 1.0e7),
        ));
        if let Some(end) = deadline {
            solving.stop_at(end);
        }
        Ok(AoeJob {
            job_id: request.job_id,
            nest: nest.clone(),
            options,
            finish_bound: (start, finish),
            machine: request.params.machine,
            objective: request.params.objective,
            solving,
            outcome: None,
            fallback: None,
            deadline,
            started: Instant::now(),
        })
    }

    /// The solution and the plan bound, once the job has run (`Err`: why it failed).
    pub fn outcome(&self) -> Option<&Result<(AoeSolution, Option<PlanBound>), AoeSolveError>> {
        self.outcome.as_ref()
    }

    /// The checked contour route the job answers with, when AOE's own route failed.
    pub fn fallback_route(&self) -> Option<&Route> {
        self.fallback.as_ref()?.checked.as_ref()
    }

    /// What the job does once AOE has failed with `error`: it makes the contour route.
    fn failed(&mut self, error: AoeSolveError) -> JobStatus {
        self.outcome = Some(Err(error));
        self.fallback = ContourFallback::new(&self.nest, self.finish_bound);
        match self.fallback {
            Some(_) => JobStatus::Running,
            None => JobStatus::Done,
        }
    }
}

impl Job for AoeJob {
    fn stop(&mut self) {
        // As the limit reached now: the ordering ends with its best so far, and the next steps
        // check its route (the build, if under way, still runs to its end).
        self.solving.stop_at(Instant::now());
        self.deadline = Some(Instant::now());
    }

    fn step(&mut self, budget: Duration) -> JobStatus {
        if let Some(fallback) = self.fallback.as_mut() {
            return fallback.step(budget, self.deadline, &self.nest);
        }
        if self.outcome.is_some() {
            return JobStatus::Done;
        }
        match self.solving.outcome() {
            None => {
                // The route is made and checked in steps; the plan bound gets one of its own.
                self.solving.step(budget);
                JobStatus::Running
            }
            Some(Ok(solution)) => {
                let (start, finish) = self.finish_bound;
                let tolerance = self.options.plan.tolerance;
                let bound = self.solving.plan().and_then(|plan| {
                    PlanBound::from_plan(plan, &self.nest, start, finish, tolerance).ok()
                });
                self.outcome = Some(Ok((solution.clone(), bound)));
                JobStatus::Done
            }
            Some(Err(e)) => {
                let e = e.clone();
                self.failed(e)
            }
        }
    }

    fn progress(&self) -> Progress {
        if let (Some(Err(error)), Some(route)) = (&self.outcome, self.fallback_route()) {
            return self.answer_with_contours(error, route);
        }
        let solved = match &self.outcome {
            Some(Ok(solved)) => Some(solved),
            _ => None,
        };
        // A checked route waiting for its plan bound is shown, so a job stopped in that step
        // (a long one on large plans) keeps it, with the part of the bound that costs nothing:
        // the plan's length cut once and the trail pierces, no idle travel.
        let waiting = match (&self.outcome, self.solving.outcome()) {
            (None, Some(Ok(solution))) => Some(solution),
            _ => None,
        };
        let interim = waiting.and_then(|solution| {
            let plan = self.solving.plan()?;
            let edges = plan.graph().edge_count();
            let length: f64 = (0..edges)
                .flat_map(|e| plan.edge_spans(e).iter())
                .map(|s| s.length())
                .sum();
            let tolerance = self.options.plan.tolerance;
            let cut = (length - 4.0 * tolerance * edges as f64).max(0.0);
            Some(
                self.objective
                    .value(&self.machine, cut, 0.0, solution.pierce_lower_bound),
            )
        });
        let phase = match &self.outcome {
            None => match self.solving.stage() {
                AoeStage::Building => Phase::CommonEdgeGraph,
                AoeStage::Ordering | AoeStage::Checking => Phase::CommonEdgeOrdering,
                AoeStage::Done => Phase::CommonEdgeBound,
            },
            Some(Ok((solution, _))) => Phase::CommonEdgeDone {
                chains: solution.chains.len(),
                components: solution.components,
            },
            Some(Err(e)) => Phase::CommonEdgeFailed {
                error: e.to_string(),
            },
        };
        let route = solved.map(|(s, _)| &s.route).or(waiting.map(|s| &s.route));
        let idle_lower_bound = solved
            .and_then(|(_, b)| b.as_ref())
            .map(|b| b.idle_length)
            .or(interim.map(|_| 0.0));
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            bounds: Bounds {
                upper: route.map(|r| {
                    self.objective.value(
                        &self.machine,
                        r.cut_length(),
                        r.idle_length(),
                        r.pierce_count(),
                    )
                }),
                lower: solved
                    .and_then(|(_, b)| b.as_ref())
                    .map(|b| b.trail_route(self.objective, &self.machine))
                    .or(interim),
                unit: self.objective.unit(),
            },
            phase,
            solution: route.cloned().map(Solution::PathRoute),
            proven_optimal: false,
            states: None,
            certified: Vec::new(),
            alternatives: route
                .map(|r| {
                    let mut s = summary("aoe", r, &self.machine);
                    s.chosen = true;
                    s.idle_lower_bound = idle_lower_bound;
                    vec![s]
                })
                .unwrap_or_default(),
            idle_lower_bound,
            ..Progress::default()
        }
    }
}

impl AoeJob {
    /// The progress of a job answering with the contour `route` because AOE failed with
    /// `error`: the failure stated as the alternative [`crate::REJECTED_ROUTE`], no lower
    /// bound (the plan bound belongs to AOE's plan graph, which the job no longer has).
    fn answer_with_contours(&self, error: &AoeSolveError, route: &Route) -> Progress {
        let (cut, idle, pierces) = (
            route.cut_length(&self.nest),
            route.idle_length(),
            route.pierce_count(),
        );
        let rejected = RouteSummary {
            name: crate::REJECTED_ROUTE.to_string(),
            pierces: 0,
            idle_length: 0.0,
            cut_length: 0.0,
            time_s: 0.0,
            cost: 0.0,
            chosen: false,
            failure: Some(format!(
                "the AOE route failed ({error}); the contour route is reported instead"
            )),
            idle_lower_bound: None,
        };
        let contours = RouteSummary {
            chosen: true,
            ..RouteSummary::measured("contour route", (cut, idle, pierces), &self.machine)
        };
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            bounds: Bounds {
                upper: Some(self.objective.value(&self.machine, cut, idle, pierces)),
                lower: None,
                unit: self.objective.unit(),
            },
            phase: Phase::CommonEdgeFailed {
                error: error.to_string(),
            },
            solution: Some(Solution::Route(route.clone())),
            proven_optimal: false,
            states: None,
            certified: Vec::new(),
            alternatives: vec![rejected, contours],
            ..Progress::default()
        }
    }
}

/// Segment cutting's stage in the protocol's words.
fn segments_phase(search: &GsccpSearch) -> Phase {
    let ensemble = |kind: EnsembleKind| match kind {
        EnsembleKind::Standard => Ensemble::Standard,
        EnsembleKind::Chains => Ensemble::Chains,
        EnsembleKind::Junctions => Ensemble::Junctions,
    };
    match search.stage() {
        GsccpStage::Ccp => Phase::SegmentsCcp,
        GsccpStage::Building(kind) => Phase::SegmentsBuilding {
            ensemble: kind.map(ensemble),
        },
        GsccpStage::Searching {
            kind,
            segments,
            shakes,
        } => Phase::SegmentsSearch {
            ensemble: ensemble(kind),
            segments,
            shakes,
        },
        GsccpStage::Failed(e) => Phase::SegmentsFailed {
            error: e.to_string(),
        },
        GsccpStage::Done(best) => Phase::SegmentsDone {
            best: best.map(ensemble),
        },
        GsccpStage::NoValidRoute => Phase::SegmentsNoRoute,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, Part};
    use cutroute_protocol::SolverParams;

    /// When AOE fails (here: its route rejected by a checker, as a bug would have it), the
    /// job answers with the nearest solver's contour route, checked, and states the failure.
    #[test]
    fn a_failed_aoe_route_gives_way_to_a_checked_contour_route() {
        let part = |name: &str, x: f64| Part {
            name: name.to_string(),
            contours: vec![
                Contour::rectangle(x, 0.0, x + 40.0, 40.0),
                Contour::rectangle(x + 10.0, 10.0, x + 20.0, 20.0),
            ],
        };
        let nest = Nest {
            sheet: None,
            parts: vec![part("a", 0.0), part("b", 60.0)],
        };
        let request = JobRequest {
            job_id: 7,
            problem: Problem::Nest {
                nest: nest.clone(),
                start: Point::new(0.0, 0.0),
                finish: None,
            },
            solver: SolverKind::Aoe,
            params: SolverParams::default(),
        };
        let mut job = AoeJob::from_request(&request).expect("aoe starts");
        let rejected = cutroute_geometry::PathRouteError::EmptyPath {
            path: 0,
            x: 1.0,
            y: 2.0,
        };
        assert_eq!(
            job.failed(AoeSolveError::Route(rejected)),
            JobStatus::Running
        );
        let mut steps = 0;
        while job.step(Duration::from_millis(50)) == JobStatus::Running {
            steps += 1;
            assert!(steps < 1000, "the job ends");
        }
        let progress = job.progress();
        let Some(Solution::Route(route)) = &progress.solution else {
            panic!("a contour route, not {:?}", progress.solution);
        };
        let forest = nest.containment_forest();
        assert_eq!(
            route.problems(&nest, &forest, nest.check_tolerance()),
            Vec::new()
        );
        assert_eq!(route.pierce_count(), 4);
        assert_eq!(progress.bounds.lower, None, "no bound of AOE's plan");
        assert!(progress.bounds.upper.is_some());
        assert_eq!(progress.job_id, 7);
        let failure = progress.alternatives[0].failure.as_deref().expect("stated");
        assert_eq!(progress.alternatives[0].name, crate::REJECTED_ROUTE);
        assert!(
            failure.contains("pierces at (1, 2) but cuts nothing"),
            "{failure}"
        );
        assert!(
            failure.contains("contour route is reported instead"),
            "{failure}"
        );
        assert!(progress.alternatives[1].chosen);
        assert!(matches!(progress.phase, Phase::CommonEdgeFailed { .. }));
    }
}
