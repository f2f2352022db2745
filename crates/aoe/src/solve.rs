//! The AOE solver: a nest in, a checked [`PathRoute`] out.
//!
//! [`PlanGraph::route`] fixes *what* each pierce cuts (the OE-route of every component of the
//! plan graph); this module decides *in which order* the components are visited, so the idle
//! travel between them is short, and turns the chains into tool-on paths. A component's own
//! chains keep their OE order (reordering them could enclose an uncut edge); only a component
//! that is one simple closed curve may start anywhere on it. Between components
//! the only rule is containment: a component holding a contour that lies inside a contour of
//! another component is cut first (the part it frees would otherwise fall with uncut edges).

use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit, Status};
use cutroute_geometry::float::Libm;
use cutroute_geometry::{
    BoundingBox, MachineParameters, Nest, PathRoute, PathRouteError, Point, Span, ToolOnPath,
};
use cutroute_thermal::{path_route_pierces, HeatModel};
use thiserror::Error;
use web_time::{Duration, Instant};

use crate::plan::PlanBuild;
use crate::{CheckError, CutChain, EmbeddingError, PlanError, PlanGraph, PlanOptions};

/// Options of [`solve_nest`].
#[derive(Clone, Debug, PartialEq)]
pub struct AoeSolveOptions {
    /// How the plan graph is built from the nest.
    pub plan: PlanOptions,
    /// Where the head starts.
    pub start: Point,
    /// Where the head must return at the end, if anywhere.
    pub finish: Option<Point>,
    /// The heat penalty (issue #19): the orderings compete on idle + W·H, and one more
    /// ordering picks the next ready component by its idle move + W·(the H its pierces add).
    /// `None`: idle alone.
    pub heat: Option<AoeHeat>,
}

/// W·H in millimetres of idle travel, H on the machine clock of `machine` with one source per
/// tool-on path at its pierce.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AoeHeat {
    /// σ and τ.
    pub model: HeatModel,
    /// Millimetres of idle travel per unit of H.
    pub weight_mm: f64,
    /// Speeds and pierce time of the clock H runs on.
    pub machine: MachineParameters,
}

impl Default for AoeSolveOptions {
    fn default() -> Self {
        AoeSolveOptions {
            plan: PlanOptions::default(),
            start: Point::new(0.0, 0.0),
            finish: None,
            heat: None,
        }
    }
}

/// A solved nest.
#[derive(Clone, Debug, PartialEq)]
pub struct AoeSolution {
    /// The route, accepted by [`PathRoute::problems`].
    pub route: PathRoute,
    /// The chains in cutting order, accepted by [`PlanGraph::check_route`]. A component that
    /// is one simple closed curve is cut from the point the ordering chose: its path in
    /// `route` is its chain's spans opened there.
    pub chains: Vec<CutChain>,
    /// Connected components of the plan graph.
    pub components: usize,
    /// No route of the plan graph pierces fewer times ([`crate::pierce_lower_bound`] summed
    /// over components).
    pub pierce_lower_bound: usize,
    /// Idle length of the components in the plain inner-first (area) order, before ordering.
    pub unordered_idle_length: f64,
}

/// Why [`solve_nest`] failed.
#[derive(Clone, Debug, Error)]
pub enum AoeSolveError {
    /// The plan graph could not be built.
    #[error("cannot build the plan graph: {0}")]
    Plan(#[from] PlanError),
    /// A component could not be embedded.
    #[error("cannot embed the plan graph: {0}")]
    Embedding(#[from] EmbeddingError),
    /// The chains failed the plan-graph checker (a bug: reported, never returned as a route).
    #[error("the AOE chains fail the plan checker: {0}")]
    Chains(#[from] CheckError),
    /// The route failed the nest's independent checker (a bug: reported, never returned).
    #[error("the AOE route fails the nest checker: {0}")]
    Route(PathRouteError),
}

/// One component's part of the route: its chains, where it is entered and left, and the idle
/// travel between its own chains (fixed by its OE-route).
#[derive(Clone)]
struct Visit {
    chains: Vec<CutChain>,
    entry: Point,
    exit: Point,
    inner_idle: f64,
    /// For a component that is one simple closed curve (every vertex of degree 2, one chain):
    /// where the curve is opened. Such a chain may start anywhere on it — no pass can cross,
    /// and nothing is enclosed before the curve closes — so `entry = exit` is chosen as for
    /// CCP-Relax's contours.
    opening: Option<Opening>,
}

/// Where a closed chain is opened: on span `span` of its spans, at parameter `t`.
#[derive(Clone, Copy)]
struct Opening {
    span: usize,
    t: f64,
}

/// Cuts every contour of `nest` along AOE-chains: common edges once, each component of the plan
/// graph by its OE-route, components ordered inner-first and then by short idle moves (nearest
/// ready component, improved by moving single components while precedence allows); a
/// component that is one simple closed curve (a part with no common edge) is pierced at the
/// point that shortens the idle travel, as CCP-Relax places its pierce points.
///
/// ```
/// use cutroute_aoe::{solve_nest, AoeSolveOptions};
/// use cutroute_geometry::{Contour, Nest, Part, Vertex};
/// let rect = |x: f64| Part {
///     name: String::new(),
///     contours: vec![Contour::new(vec![
///         Vertex::line(x, 0.0), Vertex::line(x, 5.0), Vertex::line(x + 10.0, 5.0), Vertex::line(x + 10.0, 0.0),
///     ])],
/// };
/// // Three rectangles in a row share two edges: one pierce cuts them all.
/// let nest = Nest { sheet: None, parts: vec![rect(0.0), rect(10.0), rect(20.0)] };
/// let solution = solve_nest(&nest, &AoeSolveOptions::default())?;
/// assert_eq!(solution.route.pierce_count(), 2); // two odd vertices pairs: the lower bound
/// assert_eq!(solution.pierce_lower_bound, 2);
/// assert!((solution.route.cut_length() - (2.0 * 30.0 + 4.0 * 5.0)).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn solve_nest(nest: &Nest, options: &AoeSolveOptions) -> Result<AoeSolution, AoeSolveError> {
    let mut solving = AoeSolving::new(nest, options);
    while !solving.advance(&|| false) {}
    solving
        .outcome
        .take()
        .expect("advance ended with an outcome")
}

/// [`solve_nest`] in resumable slices ([`AnytimeSolver`]), for callers that must stay
/// responsive (the app's worker answers Stop between slices). A 5,000-part sheet once took 12 s
/// in one step, and its ordering rounds were single pieces of seconds, so every stage is cut
/// into small units of work with a look at the clock between them: the plan graph, its components, each
/// component's chains, each pick of the nearest-ready ordering, each move tried and each closed
/// curve relaxed, and the two checks of the final route. The route does not depend on where the
/// slices end. [`AoeSolving::stop_at`] ends the ordering at a deadline with its best so far (the
/// plain inner-first area order at worst); the build and the checks always run to their end.
pub struct AoeSolving {
    nest: Nest,
    options: AoeSolveOptions,
    deadline: Option<Instant>,
    stage: Stage,
    /// Whether the deadline cut the ordering short.
    stopped: bool,
    outcome: Option<Result<AoeSolution, AoeSolveError>>,
}

/// Where [`AoeSolving`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AoeStage {
    /// Building the plan graph, its components and their chains.
    Building,
    /// Ordering the components.
    Ordering,
    /// Checking the route of the best ordering.
    Checking,
    /// Done: [`AoeSolving::outcome`] holds the solution or the error.
    Done,
}

enum Stage {
    Plan,
    Sweep(Box<PlanBuild>),
    Components(Box<PlanGraph>),
    Chains(Box<Chaining>),
    Ordering(Box<Orderings>),
    /// The route's chains, checked by the plan's checker; then the route by the nest's.
    Check(Box<Orderings>, Option<(Vec<CutChain>, PathRoute)>),
    /// The plan graph stays for [`AoeSolving::plan`] (none after a failure).
    Done(Option<Box<PlanGraph>>),
}

/// The components' chains, one component per unit of work.
struct Chaining {
    plan: PlanGraph,
    components: Vec<crate::PlanComponent>,
    visits: Vec<Visit>,
    contours_of: Vec<Vec<cutroute_geometry::ContourRef>>,
    pierce_lower_bound: usize,
}

/// The orderings of the components and the best so far.
struct Orderings {
    plan: PlanGraph,
    n: usize,
    visits: Vec<Visit>,
    before: Vec<Vec<usize>>,
    after: Vec<Vec<usize>>,
    pierce_lower_bound: usize,
    unordered_idle_length: f64,
    /// The best ordering so far: its value (idle length, + W·H with a heat penalty), visits
    /// (closed curves placed), order.
    best: (f64, Vec<Visit>, Vec<usize>),
    /// Whether the heat-priced ordering is still to try (with a heat penalty only).
    heated_start: bool,
    /// The starts of the ordering still to try (`choose_points` of each), next last.
    starts: Vec<bool>,
    /// The start under way.
    ordering: Option<Ordering>,
}

/// One start of the ordering: the nearest-ready order, then rounds of single-component moves
/// and relaxation of the closed curves' points while they gain.
struct Ordering {
    placed: Vec<Visit>,
    order: Vec<usize>,
    rounds: usize,
    work: OrderWork,
}

enum OrderWork {
    Greedy(NearestReady),
    Moves(Moves),
    Relax(Relax),
}

/// Units of work between looks at `stop` (a unit is one pick, one move tried, one curve
/// relaxed or one component's chains).
const UNITS_PER_LOOK: usize = 16;

impl AoeSolving {
    /// Prepares the solve (no work yet: the plan graph is built by the first steps).
    pub fn new(nest: &Nest, options: &AoeSolveOptions) -> Self {
        AoeSolving {
            nest: nest.clone(),
            options: options.clone(),
            deadline: None,
            stage: Stage::Plan,
            stopped: false,
            outcome: None,
        }
    }

    /// Ends the ordering at `deadline` with its best order so far (a time limit).
    pub fn stop_at(&mut self, deadline: Instant) {
        self.deadline = Some(deadline);
    }

    /// The stage under way.
    pub fn stage(&self) -> AoeStage {
        match self.stage {
            Stage::Plan | Stage::Sweep(_) | Stage::Components(_) | Stage::Chains(_) => {
                AoeStage::Building
            }
            Stage::Ordering(_) => AoeStage::Ordering,
            Stage::Check(..) => AoeStage::Checking,
            Stage::Done(_) => AoeStage::Done,
        }
    }

    /// The plan graph the route was made on, once done (for bounds measured on it).
    pub fn plan(&self) -> Option<&PlanGraph> {
        match &self.stage {
            Stage::Done(plan) => plan.as_deref(),
            _ => None,
        }
    }

    /// The solution (checked by both checkers) or why there is none, once done.
    pub fn outcome(&self) -> Option<&Result<AoeSolution, AoeSolveError>> {
        self.outcome.as_ref()
    }

    /// Works for about `budget`: [`Status::Finished`] once the route is made and checked (or
    /// failed: see [`AoeSolving::outcome`]), [`Status::Stopped`] when the deadline of
    /// [`AoeSolving::stop_at`] cut the ordering short.
    pub fn step(&mut self, budget: Duration) -> Status {
        let slice_end = Instant::now().checked_add(budget);
        let done = self.advance(&|| slice_end.is_some_and(|end| Instant::now() >= end));
        if !done {
            Status::Running
        } else if self.stopped {
            Status::Stopped
        } else {
            Status::Finished {
                proven_optimal: false,
            }
        }
    }

    /// Works unit by unit until `stop()` says so (`false`: call again) or the outcome is set
    /// (`true`).
    fn advance(&mut self, stop: &dyn Fn() -> bool) -> bool {
        loop {
            if self.outcome.is_some() {
                return true;
            }
            let stage = std::mem::replace(&mut self.stage, Stage::Done(None));
            self.stage = match self.advance_stage(stage, stop) {
                Ok(stage) => stage,
                Err(e) => {
                    self.outcome = Some(Err(e));
                    return true;
                }
            };
            if self.outcome.is_none() && stop() {
                return false;
            }
        }
    }

    /// One piece of `stage` (a piece may stop early when `stop()` says so); the stage after it.
    fn advance_stage(
        &mut self,
        stage: Stage,
        stop: &dyn Fn() -> bool,
    ) -> Result<Stage, AoeSolveError> {
        let (nest, options) = (&self.nest, &self.options);
        Ok(match stage {
            Stage::Plan => Stage::Sweep(Box::new(PlanBuild::new(nest, &options.plan)?)),
            Stage::Sweep(mut build) => {
                if build.run(stop) {
                    Stage::Components(Box::new(build.finish()?))
                } else {
                    Stage::Sweep(build)
                }
            }
            Stage::Components(plan) => {
                let components = plan.components()?;
                Stage::Chains(Box::new(Chaining {
                    plan: *plan,
                    visits: Vec::with_capacity(components.len()),
                    contours_of: Vec::with_capacity(components.len()),
                    components,
                    pierce_lower_bound: 0,
                }))
            }
            Stage::Chains(mut chaining) => {
                let mut units = 0usize;
                while chaining.visits.len() < chaining.components.len() {
                    chaining.add_next(options.start);
                    units += 1;
                    if units.is_multiple_of(UNITS_PER_LOOK) && stop() {
                        return Ok(Stage::Chains(chaining));
                    }
                }
                Stage::Ordering(Box::new(Orderings::new(*chaining, nest, options)))
            }
            Stage::Ordering(mut orderings) => {
                let over = self.deadline.is_some_and(|end| Instant::now() >= end);
                if over {
                    self.stopped = orderings.cut_short(options);
                    Stage::Check(orderings, None)
                } else if orderings.advance(options, &|| {
                    stop() || self.deadline.is_some_and(|end| Instant::now() >= end)
                }) {
                    Stage::Check(orderings, None)
                } else {
                    Stage::Ordering(orderings)
                }
            }
            Stage::Check(mut orderings, None) => {
                let (start, finish) = (options.start, options.finish);
                let (_, visits, order) = std::mem::take(&mut orderings.best);
                let chains: Vec<CutChain> = order
                    .iter()
                    .flat_map(|&c| visits[c].chains.iter().cloned())
                    .collect();
                orderings.plan.check_route(&chains)?;
                let route = route_of(&visits, &order, start, finish);
                Stage::Check(orderings, Some((chains, route)))
            }
            Stage::Check(orderings, Some((chains, route))) => {
                // Ten times the plan's tolerance: merged copies of a common edge agree within
                // it (ends snapped within the tolerance, midpoints within eight times it).
                let tolerance = (options.plan.tolerance * 10.0).max(1e-6);
                let (overlaps, others): (Vec<_>, Vec<_>) = route
                    .problems(nest, tolerance)
                    .into_iter()
                    .partition(|p| matches!(p, PathRouteError::Overlap { .. }));
                if let Some(problem) = others.into_iter().next() {
                    return Err(AoeSolveError::Route(problem));
                }
                // But two cuts that far apart are not one piece cut twice: the plan kept them
                // apart, as it keeps the equidistants of parts spaced a little wider than the
                // kerf. A piece is cut twice when the cuts agree within the plan's tolerance.
                if !overlaps.is_empty() {
                    let close = options.plan.tolerance.max(1e-6);
                    if let Some(problem) = route
                        .problems(nest, close)
                        .into_iter()
                        .find(|p| matches!(p, PathRouteError::Overlap { .. }))
                    {
                        return Err(AoeSolveError::Route(problem));
                    }
                }
                self.outcome = Some(Ok(AoeSolution {
                    route,
                    chains,
                    components: orderings.n,
                    pierce_lower_bound: orderings.pierce_lower_bound,
                    unordered_idle_length: orderings.unordered_idle_length,
                }));
                Stage::Done(Some(Box::new(orderings.plan)))
            }
            Stage::Done(plan) => Stage::Done(plan),
        })
    }
}

/// The contract of every solver: the checked route once made (the orderings compete on an
/// unchecked route, so none is offered before), its idle length (+ W·H with a heat penalty,
/// the value the orderings minimise); no lower bound (the engine's `PlanBound` gives one).
impl AnytimeSolver for AoeSolving {
    type Solution = PathRoute;

    fn step(&mut self, budget: Duration) -> Status {
        AoeSolving::step(self, budget)
    }

    fn best(&self) -> Option<PathRoute> {
        match &self.outcome {
            Some(Ok(solution)) => Some(solution.route.clone()),
            _ => None,
        }
    }

    fn bounds(&self) -> Bounds {
        let upper = match (&self.outcome, &self.stage) {
            (Some(Ok(solution)), _) => {
                let route = &solution.route;
                Some(match self.options.heat {
                    Some(heat) if heat.weight_mm > 0.0 => {
                        route.idle_length()
                            + heat.weight_mm
                                * heat.model.load(&path_route_pierces(route, &heat.machine))
                    }
                    _ => route.idle_length(),
                })
            }
            _ => None,
        };
        Bounds {
            upper,
            lower: None,
            unit: CostUnit::IdleMm,
        }
    }
}

impl Chaining {
    /// The chains and the entry and exit of the next component.
    fn add_next(&mut self, start: Point) {
        let (plan, component) = (&self.plan, &self.components[self.visits.len()]);
        self.pierce_lower_bound += crate::pierce_lower_bound(component.embedding.graph());
        let chains = plan.component_chains(component);
        let entry = chains
            .first()
            .and_then(|c| c.spans.first())
            .map_or(start, |s| s.start);
        let exit = chains
            .last()
            .and_then(|c| c.spans.last())
            .map_or(entry, |s| s.end);
        let inner_idle = chains
            .windows(2)
            .filter_map(|w| Some(w[0].spans.last()?.end.distance(w[1].spans.first()?.start)))
            .sum();
        let simple_cycle = chains.len() == 1
            && (0..component.embedding.graph().vertex_count())
                .all(|v| component.embedding.graph().degree(v) == 2);
        self.visits.push(Visit {
            chains,
            entry,
            exit,
            inner_idle,
            opening: simple_cycle.then_some(Opening { span: 0, t: 0.0 }),
        });
        let mut contours: Vec<_> = component
            .edges
            .iter()
            .flat_map(|&e| plan.edge_contours(e).iter().copied())
            .collect();
        contours.sort();
        contours.dedup();
        self.contours_of.push(contours);
    }
}

impl Orderings {
    /// The precedence between components and the plain inner-first (area) order.
    fn new(chaining: Chaining, nest: &Nest, options: &AoeSolveOptions) -> Self {
        let Chaining {
            plan,
            components,
            visits,
            contours_of,
            pierce_lower_bound,
        } = chaining;
        let forest = nest.containment_forest();
        // before[b] lists the components that must be cut before b: those holding a contour
        // that lies inside one of b's contours (and is not itself b's).
        let n = components.len();
        let mut before: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut owner = std::collections::HashMap::new();
        for (c, contours) in contours_of.iter().enumerate() {
            for &r in contours {
                owner.entry(r).or_insert_with(Vec::new).push(c);
            }
        }
        for (a, contours) in contours_of.iter().enumerate() {
            for &r in contours {
                for outer in forest.ancestors(r) {
                    for &b in owner.get(&outer).map_or(&[][..], |v| &v[..]) {
                        if b != a && !before[b].contains(&a) {
                            before[b].push(a);
                        }
                    }
                }
            }
        }
        let area_order = {
            let enclosed: Vec<f64> = components.iter().map(|c| plan.enclosed_area(c)).collect();
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| enclosed[a].total_cmp(&enclosed[b]));
            order
        };
        let unordered_idle_length =
            idle_length(&visits, &area_order, options.start, options.finish);
        let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (b, list) in before.iter().enumerate() {
            for &a in list {
                after[a].push(b);
            }
        }
        let area_value = penalised(&visits, &area_order, options);
        Orderings {
            plan,
            n,
            best: (area_value, visits.clone(), area_order),
            heated_start: options.heat.is_some_and(|h| h.weight_mm > 0.0),
            visits,
            before,
            after,
            pierce_lower_bound,
            unordered_idle_length,
            // Tried in the order true, then false.
            starts: vec![false, true],
            ordering: None,
        }
    }

    /// Works on the orderings until `stop()` says so (`false`) or every start is done (`true`).
    fn advance(&mut self, options: &AoeSolveOptions, stop: &dyn Fn() -> bool) -> bool {
        let (start, finish) = (options.start, options.finish);
        // Nearest ready component (closed curves entered at their nearest point), then rounds
        // of single-component moves and relaxation of the closed curves' points, while they
        // gain. Two starts — closed curves entered at their nearest point, or at their chain's
        // start — each improved; the shorter wins, and the plain area order if both are longer.
        loop {
            if self.heated_start {
                // Heat-priced greedy, not improved by the idle moves (they would undo it).
                self.heated_start = false;
                if let Some(heat) = options.heat {
                    let mut placed = self.visits.clone();
                    if let Some(order) =
                        heated_ready_order(&mut placed, &self.before, &self.after, start, &heat)
                    {
                        let value = penalised(&placed, &order, options);
                        if value < self.best.0 {
                            self.best = (value, placed, order);
                        }
                    }
                }
                if stop() {
                    return false;
                }
                continue;
            }
            let Some(mut ordering) = self.ordering.take() else {
                let Some(choose_points) = self.starts.pop() else {
                    return true;
                };
                let placed = self.visits.clone();
                let greedy = NearestReady::new(&placed, &self.before, start, choose_points);
                self.ordering = Some(Ordering {
                    placed,
                    order: Vec::new(),
                    rounds: 0,
                    work: OrderWork::Greedy(greedy),
                });
                continue;
            };
            let Ordering {
                placed,
                order,
                rounds,
                work,
            } = &mut ordering;
            match work {
                OrderWork::Greedy(greedy) => match greedy.run(placed, &self.after, stop) {
                    // A containment cycle cannot come from a valid nest; the area order stays
                    // then.
                    None => continue,
                    Some(false) => {
                        self.ordering = Some(ordering);
                        return false;
                    }
                    Some(true) => {
                        *order = std::mem::take(&mut greedy.order);
                        *work = OrderWork::Moves(Moves::new(order, placed));
                    }
                },
                OrderWork::Moves(moves) => {
                    let context = (&self.before[..], &self.after[..], start, finish);
                    if !moves.run(order, context, placed, stop) {
                        self.ordering = Some(ordering);
                        return false;
                    }
                    *work = OrderWork::Relax(Relax::default());
                }
                OrderWork::Relax(relax) => {
                    let Some(gain) = relax.run(placed, order, start, finish, stop) else {
                        self.ordering = Some(ordering);
                        return false;
                    };
                    if gain < 1e-6 || *rounds + 1 >= ORDER_ROUNDS {
                        let value = penalised(placed, order, options);
                        if value < self.best.0 {
                            self.best = (value, std::mem::take(placed), std::mem::take(order));
                        }
                        if stop() {
                            return false;
                        }
                        continue;
                    }
                    *rounds += 1;
                    *work = OrderWork::Moves(Moves::new(order, placed));
                }
            }
            self.ordering = Some(ordering);
            if stop() {
                return false;
            }
        }
    }

    /// Ends the ordering now: the start under way competes with its order so far if it has a
    /// whole one (its moves and relaxations keep every order whole). Whether anything was cut
    /// short.
    fn cut_short(&mut self, options: &AoeSolveOptions) -> bool {
        let cut = self.ordering.is_some() || !self.starts.is_empty() || self.heated_start;
        if let Some(ordering) = self.ordering.take() {
            if !matches!(ordering.work, OrderWork::Greedy(_)) {
                let value = penalised(&ordering.placed, &ordering.order, options);
                if value < self.best.0 {
                    self.best = (value, ordering.placed, ordering.order);
                }
            }
        }
        self.starts.clear();
        self.heated_start = false;
        cut
    }
}

/// The tool-on paths of visiting the components in `order`.
fn route_of(visits: &[Visit], order: &[usize], start: Point, finish: Option<Point>) -> PathRoute {
    let mut paths = Vec::with_capacity(order.len());
    for &c in order {
        let visit = &visits[c];
        match visit.opening {
            Some(opening) => {
                let spans = &visit.chains[0].spans;
                paths.push(ToolOnPath {
                    pierce: visit.entry,
                    spans: opened(spans, opening, visit.entry),
                    leads: None,
                });
            }
            None => paths.extend(
                visit
                    .chains
                    .iter()
                    .filter(|c| !c.spans.is_empty())
                    .map(|c| ToolOnPath {
                        pierce: c.spans[0].start,
                        spans: c.spans.clone(),
                        leads: None,
                    }),
            ),
        }
    }
    PathRoute {
        start,
        paths,
        finish,
    }
}

/// What the orderings compete on: idle length, + W·H (mm) with a heat penalty.
fn penalised(visits: &[Visit], order: &[usize], options: &AoeSolveOptions) -> f64 {
    let idle = idle_length(visits, order, options.start, options.finish);
    match options.heat {
        Some(heat) if heat.weight_mm > 0.0 => {
            let route = route_of(visits, order, options.start, options.finish);
            idle + heat.weight_mm * heat.model.load(&path_route_pierces(&route, &heat.machine))
        }
        _ => idle,
    }
}

/// Kernels below e⁻¹² are left out of the greedy's heat increments.
const HEAT_CUTOFF: f64 = 12.0;

/// Next the ready component of least idle move + W·ΔH, ΔH the heat its pierces add given
/// the pierces before them on the machine clock (closed curves entered at their chain's
/// start); `None` when the precedence has a cycle.
fn heated_ready_order(
    visits: &mut [Visit],
    before: &[Vec<usize>],
    after: &[Vec<usize>],
    start: Point,
    heat: &AoeHeat,
) -> Option<Vec<usize>> {
    let n = visits.len();
    let m = &heat.machine;
    let mut waiting: Vec<usize> = before.iter().map(Vec::len).collect();
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let (mut at, mut clock) = (start, 0.0);
    // (point, time) of every pierce so far, in time order.
    let mut history: Vec<(Point, f64)> = Vec::new();
    // A component's pierces relative to its entry time: (point, offset), and its duration.
    let timeline = |v: &Visit| {
        let mut t = 0.0;
        let mut here = v.entry;
        let mut pierces = Vec::new();
        for chain in v.chains.iter().filter(|c| !c.spans.is_empty()) {
            let p = chain.spans[0].start;
            t += here.distance(p) / m.idle_speed;
            pierces.push((p, t));
            let length: f64 = chain.spans.iter().map(|s| s.length()).sum();
            t += m.pierce_time + length / m.cut_speed;
            here = chain.spans[chain.spans.len() - 1].end;
        }
        (pierces, t)
    };
    let timelines: Vec<(Vec<(Point, f64)>, f64)> = visits.iter().map(timeline).collect();
    let horizon = HEAT_CUTOFF * heat.model.tau_s;
    while order.len() < n {
        let mut best: Option<(f64, usize)> = None;
        for c in (0..n).filter(|&c| !done[c] && waiting[c] == 0) {
            let idle = at.distance(visits[c].entry);
            let arrive = clock + idle / m.idle_speed;
            let mut added = 0.0;
            for &(p, offset) in &timelines[c].0 {
                let t = arrive + offset;
                for &(q, tq) in history.iter().rev() {
                    if t - tq > horizon {
                        break;
                    }
                    added += heat.model.kernel((p - q).norm_squared(), t - tq);
                }
            }
            let value = idle + heat.weight_mm * added;
            if best.is_none_or(|b| value < b.0) {
                best = Some((value, c));
            }
        }
        let (_, next) = best?;
        let arrive = clock + at.distance(visits[next].entry) / m.idle_speed;
        history.extend(timelines[next].0.iter().map(|&(p, o)| (p, arrive + o)));
        clock = arrive + timelines[next].1;
        done[next] = true;
        order.push(next);
        at = visits[next].exit;
        for &b in &after[next] {
            waiting[b] -= 1;
        }
    }
    Some(order)
}

/// Idle length of visiting the components in `order`: start → entry, exit → next entry, …,
/// last exit → finish; plus the idle moves inside each component between its chains.
fn idle_length(visits: &[Visit], order: &[usize], start: Point, finish: Option<Point>) -> f64 {
    let mut at = start;
    let mut total = 0.0;
    for &c in order {
        total += at.distance(visits[c].entry) + visits[c].inner_idle;
        at = visits[c].exit;
    }
    if let Some(f) = finish {
        total += at.distance(f);
    }
    total
}

/// Where a closed curve is opened, and the point there.
type Placed = (Opening, Point);

/// Most rounds of component moves and relaxation of the closed curves' points.
const ORDER_ROUNDS: usize = 8;

/// Nearest ready component first (with `choose_points`, a closed curve is measured to, and
/// entered at, its nearest point; else at its chain's start), one pick per unit of work.
struct NearestReady {
    waiting: Vec<usize>,
    done: Vec<bool>,
    order: Vec<usize>,
    at: Point,
    /// A closed curve's distance is at least its box's: the exact nearest point is needed only
    /// for curves whose box is nearer than the best so far.
    boxes: Vec<BoundingBox>,
    choose_points: bool,
}

impl NearestReady {
    fn new(visits: &[Visit], before: &[Vec<usize>], start: Point, choose_points: bool) -> Self {
        let n = visits.len();
        NearestReady {
            waiting: before.iter().map(Vec::len).collect(),
            done: vec![false; n],
            order: Vec::with_capacity(n),
            at: start,
            boxes: visits
                .iter()
                .map(|v| {
                    v.chains[0]
                        .spans
                        .iter()
                        .fold(BoundingBox::EMPTY, |b, s| b.union(s.bounding_box()))
                })
                .collect(),
            choose_points,
        }
    }

    /// Picks until the order is whole (`Some(true)`) or `stop()` says so (`Some(false)`);
    /// `None` when the precedence has a cycle.
    fn run(
        &mut self,
        visits: &mut [Visit],
        after: &[Vec<usize>],
        stop: &dyn Fn() -> bool,
    ) -> Option<bool> {
        let n = visits.len();
        while self.order.len() < n {
            self.pick(visits, after)?;
            if self.order.len().is_multiple_of(UNITS_PER_LOOK) && self.order.len() < n && stop() {
                return Some(false);
            }
        }
        Some(true)
    }

    /// The next component; `None` when none is ready.
    fn pick(&mut self, visits: &mut [Visit], after: &[Vec<usize>]) -> Option<()> {
        let (at, choose_points) = (self.at, self.choose_points);
        let mut ready: Vec<(f64, usize)> = (0..visits.len())
            .filter(|&c| !self.done[c] && self.waiting[c] == 0)
            .map(|c| match visits[c].opening {
                Some(_) if choose_points => (box_distance(&self.boxes[c], at), c),
                _ => (at.distance(visits[c].entry), c),
            })
            .collect();
        ready.sort_by(|a, b| a.0.total_cmp(&b.0));
        // (distance, component, where a closed curve is entered)
        let mut best: Option<(f64, usize, Option<Placed>)> = None;
        for (lower, c) in ready {
            if best.as_ref().is_some_and(|b| lower >= b.0) {
                break;
            }
            let bound = best.as_ref().map_or(f64::INFINITY, |b| b.0);
            let candidate = match visits[c].opening {
                Some(_) if choose_points => {
                    match best_point(&visits[c].chains[0].spans, at, None, bound) {
                        Some((span, t, point, distance)) => {
                            (distance, c, Some((Opening { span, t }, point)))
                        }
                        None => continue,
                    }
                }
                _ => (lower, c, None),
            };
            if best.as_ref().is_none_or(|b| candidate.0 < b.0) {
                best = Some(candidate);
            }
        }
        let (_, next, place) = best?;
        if let Some((opening, point)) = place {
            let visit = &mut visits[next];
            (visit.opening, visit.entry, visit.exit) = (Some(opening), point, point);
        }
        self.done[next] = true;
        self.order.push(next);
        self.at = visits[next].exit;
        for &b in &after[next] {
            self.waiting[b] -= 1;
        }
        Some(())
    }
}

/// Or-opt with segments of one: move a component to the place that shortens the idle travel
/// most (evaluated by the four joints that change), among the places after all its
/// predecessors and before all its successors; passes until no move helps. Up to
/// [`FULL_SCAN_COMPONENTS`] components every place is tried (O(n²) per pass); beyond, only the
/// places next to the component's [`NEIGHBOURS`] nearest components, the order's ends
/// included (O(n·k) per pass: a 5,000-part sheet took minutes with the full scan). One move
/// tried per unit of work.
struct Moves {
    near: Option<NearestComponents>,
    pos: Vec<usize>,
    places: Vec<usize>,
    pass: usize,
    /// The position whose move is tried next.
    i: usize,
    improved: bool,
}

/// Precedence (before, after), start and finish.
type MoveContext<'a> = (&'a [Vec<usize>], &'a [Vec<usize>], Point, Option<Point>);

impl Moves {
    fn new(order: &[usize], visits: &[Visit]) -> Self {
        let n = order.len();
        let mut pos = vec![0; n];
        for (k, &x) in order.iter().enumerate() {
            pos[x] = k;
        }
        Moves {
            near: (n > FULL_SCAN_COMPONENTS).then(|| nearest_components(visits, NEIGHBOURS)),
            pos,
            places: Vec::new(),
            pass: 0,
            i: 0,
            improved: false,
        }
    }

    /// Tries moves until no pass helps or [`MAX_MOVE_PASSES`] are done (`true`), or `stop()`
    /// says so (`false`).
    fn run(
        &mut self,
        order: &mut Vec<usize>,
        context: MoveContext,
        visits: &[Visit],
        stop: &dyn Fn() -> bool,
    ) -> bool {
        let n = order.len();
        let mut units = 0usize;
        loop {
            if self.i == n {
                if !self.improved || self.pass + 1 >= MAX_MOVE_PASSES {
                    return true;
                }
                (self.pass, self.i, self.improved) = (self.pass + 1, 0, false);
            }
            self.try_move(order, context, visits);
            self.i += 1;
            units += 1;
            if units.is_multiple_of(UNITS_PER_LOOK) && stop() {
                return false;
            }
        }
    }

    /// Moves the component at position `i` to its best place, if that shortens the route.
    fn try_move(&mut self, order: &mut Vec<usize>, context: MoveContext, visits: &[Visit]) {
        let (before, after, start, finish) = context;
        let (n, i, pos) = (order.len(), self.i, &mut self.pos);
        let (entry, exit) = (|c: usize| visits[c].entry, |c: usize| visits[c].exit);
        // The cost of putting `c` between `u` (an exit) and `v` (the next entry, if any).
        let joint = |u: Point, c: usize, v: Option<Point>| {
            u.distance(entry(c)) + v.map_or(0.0, |v| exit(c).distance(v) - u.distance(v))
        };
        let c = order[i];
        let p = if i == 0 { start } else { exit(order[i - 1]) };
        let q = if i + 1 < n {
            Some(entry(order[i + 1]))
        } else {
            finish
        };
        let saving = joint(p, c, q);
        if saving <= 1e-9 {
            return;
        }
        // Positions in the order without `c`.
        let rest = |k: usize| if k < i { order[k] } else { order[k + 1] };
        let rest_pos = |x: usize| if pos[x] < i { pos[x] } else { pos[x] - 1 };
        let lo = before[c]
            .iter()
            .map(|&a| rest_pos(a) + 1)
            .max()
            .unwrap_or(0);
        let hi = after[c]
            .iter()
            .map(|&b| rest_pos(b))
            .min()
            .unwrap_or(n - 1)
            .min(n - 1);
        let places = &mut self.places;
        places.clear();
        match &self.near {
            None => places.extend(lo..=hi),
            Some(near) => {
                places.extend([lo, hi]);
                // After a component whose exit is near c's entry, before one whose entry
                // is near c's exit.
                places.extend(near.entry_to_exits[c].iter().map(|&x| rest_pos(x) + 1));
                places.extend(near.exit_to_entries[c].iter().map(|&x| rest_pos(x)));
                places.retain(|&k| (lo..=hi).contains(&k));
            }
        }
        let mut best = (saving - 1e-9, None);
        for &k in places.iter() {
            if k == i {
                continue;
            }
            let u = if k == 0 { start } else { exit(rest(k - 1)) };
            let v = if k < n - 1 {
                Some(entry(rest(k)))
            } else {
                finish
            };
            let cost = joint(u, c, v);
            if cost < best.0 {
                best = (cost, Some(k));
            }
        }
        if let (_, Some(k)) = best {
            order.remove(i);
            order.insert(k, c);
            for (j, &x) in order.iter().enumerate().take(i.max(k) + 1).skip(i.min(k)) {
                pos[x] = j;
            }
            self.improved = true;
        }
    }
}

/// Orders of up to this many components are improved by trying every place for every move.
const FULL_SCAN_COMPONENTS: usize = 400;

/// Places tried for a move in larger orders: next to this many nearest components each way.
const NEIGHBOURS: usize = 10;

/// For every component, the components whose exit is nearest to its entry and those whose
/// entry is nearest to its exit (itself excluded).
struct NearestComponents {
    entry_to_exits: Vec<Vec<usize>>,
    exit_to_entries: Vec<Vec<usize>>,
}

fn nearest_components(visits: &[Visit], k: usize) -> NearestComponents {
    use rstar::primitives::GeomWithData;
    use rstar::RTree;
    let tree = |point: fn(&Visit) -> Point| {
        RTree::bulk_load(
            visits
                .iter()
                .enumerate()
                .map(|(c, v)| GeomWithData::new([point(v).x, point(v).y], c))
                .collect(),
        )
    };
    let (exits, entries) = (tree(|v| v.exit), tree(|v| v.entry));
    let query = |tree: &RTree<GeomWithData<[f64; 2], usize>>, c: usize, at: Point| {
        tree.nearest_neighbor_iter(&[at.x, at.y])
            .map(|g| g.data)
            .filter(|&x| x != c)
            .take(k)
            .collect::<Vec<_>>()
    };
    NearestComponents {
        entry_to_exits: (0..visits.len())
            .map(|c| query(&exits, c, visits[c].entry))
            .collect(),
        exit_to_entries: (0..visits.len())
            .map(|c| query(&entries, c, visits[c].exit))
            .collect(),
    }
}

/// Most passes of [`improve_by_moves`].
const MAX_MOVE_PASSES: usize = 50;

/// Sweeps over the order moving each closed curve's point to the minimiser of
/// `|previous exit, M| + |M, next entry|` on the curve, until a sweep gains less than 10⁻⁶ mm;
/// one curve per unit of work.
#[derive(Default)]
struct Relax {
    sweep: usize,
    /// The position relaxed next.
    i: usize,
    /// The gain of the sweep under way, and of the sweeps before it.
    gain: f64,
    total: f64,
}

impl Relax {
    /// Relaxes until done (`Some(total gain)`) or `stop()` says so (`None`).
    fn run(
        &mut self,
        visits: &mut [Visit],
        order: &[usize],
        start: Point,
        finish: Option<Point>,
        stop: &dyn Fn() -> bool,
    ) -> Option<f64> {
        let mut units = 0usize;
        while self.sweep < MAX_RELAXATION_SWEEPS {
            if self.i == order.len() {
                self.total += self.gain;
                if self.gain < 1e-6 {
                    break;
                }
                (self.sweep, self.i, self.gain) = (self.sweep + 1, 0, 0.0);
                continue;
            }
            let i = self.i;
            self.i += 1;
            let c = order[i];
            if visits[c].opening.is_none() {
                continue;
            }
            let a = if i == 0 {
                start
            } else {
                visits[order[i - 1]].exit
            };
            let b = order.get(i + 1).map(|&d| visits[d].entry).or(finish);
            let visit = &visits[c];
            let old = a.distance(visit.entry) + b.map_or(0.0, |b| visit.exit.distance(b));
            if let Some((span, t, point, value)) = best_point(&visit.chains[0].spans, a, b, old) {
                if value < old - 1e-12 {
                    let visit = &mut visits[c];
                    (visit.opening, visit.entry, visit.exit) =
                        (Some(Opening { span, t }), point, point);
                    self.gain += old - value;
                }
            }
            units += 1;
            if units.is_multiple_of(UNITS_PER_LOOK) && stop() {
                return None;
            }
        }
        Some(self.total)
    }
}

const MAX_RELAXATION_SWEEPS: usize = 50;

/// The point `M` of a closed chain of spans minimising `|a M| + |M b|` (`|a M|` without `b`):
/// `(span, t, M, value)`, or `None` if no point beats `bound`; per span
/// [`Span::detour_minimum`]. Spans whose box is already farther than the best value (at first
/// `bound`) are skipped.
fn best_point(
    spans: &[Span],
    a: Point,
    b: Option<Point>,
    bound: f64,
) -> Option<(usize, f64, Point, f64)> {
    let mut best = (0, 0.0, spans.first()?.start, bound);
    let mut found = false;
    for (i, span) in spans.iter().enumerate() {
        let bb = span.bounding_box();
        let to_box = |p: Point| box_distance(&bb, p);
        if to_box(a) + b.map_or(0.0, to_box) >= best.3 {
            continue;
        }
        let (t, value) = span.detour_minimum(a, b);
        if value < best.3 {
            best = (i, t, span.point_at(t), value);
            found = true;
        }
    }
    found.then_some(best)
}

/// Distance from `p` to a box (0 inside).
fn box_distance(b: &BoundingBox, p: Point) -> f64 {
    let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
    let dy = (b.min.y - p.y).max(p.y - b.max.y).max(0.0);
    dx.hypot_libm(dy)
}

/// A closed chain of spans opened at `point` (on span `opening.span` at `opening.t`): the rest
/// of that span, the spans after it round the cycle, the part of that span before the point.
fn opened(spans: &[Span], opening: Opening, point: Point) -> Vec<Span> {
    let i = opening.span;
    let mut out = Vec::with_capacity(spans.len() + 1);
    let mut at = point;
    let mut push = |mut s: Span| {
        if s.length() > 1e-12 {
            s.start = at;
            at = s.end;
            out.push(s);
        }
    };
    push(spans[i].sub_span(opening.t, 1.0));
    for k in 1..spans.len() {
        push(spans[(i + k) % spans.len()]);
    }
    let mut tail = spans[i].sub_span(0.0, opening.t);
    tail.end = point;
    push(tail);
    out
}
