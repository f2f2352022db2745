//! The AOE solver: a nest in, a checked [`PathRoute`] out.
//!
//! [`PlanGraph::route`] fixes *what* each pierce cuts (the OE-route of every component of the
//! plan graph); this module decides *in which order* the components are visited, so the idle
//! travel between them is short, and turns the chains into tool-on paths. A component's own
//! chains keep their OE order (reordering them could enclose an uncut edge). Between components
//! the only rule is containment: a component holding a contour that lies inside a contour of
//! another component is cut first (the part it frees would otherwise fall with uncut edges).

use cutroute_geometry::{Nest, PathRoute, PathRouteError, Point, ToolOnPath};
use thiserror::Error;

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
}

impl Default for AoeSolveOptions {
    fn default() -> Self {
        AoeSolveOptions {
            plan: PlanOptions::default(),
            start: Point::new(0.0, 0.0),
            finish: None,
        }
    }
}

/// A solved nest.
#[derive(Clone, Debug, PartialEq)]
pub struct AoeSolution {
    /// The route, accepted by [`PathRoute::problems`].
    pub route: PathRoute,
    /// The chains in cutting order, accepted by [`PlanGraph::check_route`].
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
#[derive(Debug, Error)]
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
struct Visit {
    chains: Vec<CutChain>,
    entry: Point,
    exit: Point,
    inner_idle: f64,
}

/// Cuts every contour of `nest` along AOE-chains: common edges once, each component of the plan
/// graph by its OE-route, components ordered inner-first and then by short idle moves (nearest
/// ready component, improved by moving single components while precedence allows).
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
    let plan = PlanGraph::from_nest(nest, &options.plan)?;
    let components = plan.components()?;
    let forest = nest.containment_forest();
    let mut visits = Vec::with_capacity(components.len());
    let mut pierce_lower_bound = 0;
    let mut contours_of = Vec::with_capacity(components.len());
    for component in &components {
        pierce_lower_bound += crate::pierce_lower_bound(component.embedding.graph());
        let chains = plan.component_chains(component);
        let entry = chains
            .first()
            .and_then(|c| c.spans.first())
            .map_or(options.start, |s| s.start);
        let exit = chains
            .last()
            .and_then(|c| c.spans.last())
            .map_or(entry, |s| s.end);
        let inner_idle = chains
            .windows(2)
            .filter_map(|w| Some(w[0].spans.last()?.end.distance(w[1].spans.first()?.start)))
            .sum();
        visits.push(Visit {
            chains,
            entry,
            exit,
            inner_idle,
        });
        let mut contours: Vec<_> = component
            .edges
            .iter()
            .flat_map(|&e| plan.edge_contours(e).iter().copied())
            .collect();
        contours.sort();
        contours.dedup();
        contours_of.push(contours);
    }
    // before[b] lists the components that must be cut before b: those holding a contour that
    // lies inside one of b's contours (and is not itself b's).
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
    let idle = |order: &[usize]| idle_length(&visits, order, options.start, options.finish);
    let unordered_idle_length = idle(&area_order);
    let order = match nearest_ready_order(&visits, &before, options.start) {
        // A containment cycle cannot come from a valid nest; keep the area order then.
        Some(greedy) if idle(&greedy) < unordered_idle_length => greedy,
        _ => area_order,
    };
    let order = improve_by_moves(order, &before, |o| idle(o));

    let chains: Vec<CutChain> = order
        .iter()
        .flat_map(|&c| visits[c].chains.iter().cloned())
        .collect();
    plan.check_route(&chains)?;
    let route = PathRoute {
        start: options.start,
        paths: chains
            .iter()
            .filter(|c| !c.spans.is_empty())
            .map(|c| ToolOnPath {
                pierce: c.spans[0].start,
                spans: c.spans.clone(),
            })
            .collect(),
        finish: options.finish,
    };
    let tolerance = (options.plan.tolerance * 10.0).max(1e-6);
    if let Some(problem) = route.problems(nest, tolerance).into_iter().next() {
        return Err(AoeSolveError::Route(problem));
    }
    Ok(AoeSolution {
        route,
        chains,
        components: n,
        pierce_lower_bound,
        unordered_idle_length,
    })
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

/// Nearest ready component first; `None` when the precedence has a cycle.
fn nearest_ready_order(
    visits: &[Visit],
    before: &[Vec<usize>],
    start: Point,
) -> Option<Vec<usize>> {
    let n = visits.len();
    let mut waiting: Vec<usize> = before.iter().map(Vec::len).collect();
    let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (b, list) in before.iter().enumerate() {
        for &a in list {
            after[a].push(b);
        }
    }
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut at = start;
    while order.len() < n {
        let next = (0..n)
            .filter(|&c| !done[c] && waiting[c] == 0)
            .min_by(|&a, &b| {
                at.distance(visits[a].entry)
                    .total_cmp(&at.distance(visits[b].entry))
            })?;
        done[next] = true;
        order.push(next);
        at = visits[next].exit;
        for &b in &after[next] {
            waiting[b] -= 1;
        }
    }
    Some(order)
}

/// Or-opt with segments of one: move a component to the position that shortens the idle
/// length most, among the positions after all its predecessors and before all its
/// successors; repeat until no move helps.
fn improve_by_moves(
    mut order: Vec<usize>,
    before: &[Vec<usize>],
    idle: impl Fn(&[usize]) -> f64,
) -> Vec<usize> {
    let n = order.len();
    let mut best = idle(&order);
    // Each pass is O(n²) evaluations of O(n): bound the work on big plans.
    let passes = if n <= 200 { 20 } else { 2 };
    for _ in 0..passes {
        let mut improved = false;
        for i in 0..n {
            let c = order[i];
            let mut rest = order.clone();
            rest.remove(i);
            let position: Vec<usize> = {
                let mut p = vec![0; n];
                for (k, &x) in rest.iter().enumerate() {
                    p[x] = k;
                }
                p
            };
            let lo = before[c]
                .iter()
                .map(|&a| position[a] + 1)
                .max()
                .unwrap_or(0);
            let hi = (0..n)
                .filter(|&b| b != c && before[b].contains(&c))
                .map(|b| position[b])
                .min()
                .unwrap_or(rest.len());
            for k in lo..=hi.min(rest.len()) {
                if k == i {
                    continue;
                }
                let mut candidate = rest.clone();
                candidate.insert(k, c);
                let value = idle(&candidate);
                if value < best - 1e-9 {
                    best = value;
                    order = candidate;
                    improved = true;
                    break;
                }
            }
        }
        if !improved {
            break;
        }
    }
    order
}
