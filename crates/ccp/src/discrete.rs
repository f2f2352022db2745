//! The discrete alternative: a PCGTSP instance whose nodes are candidate pierce points every ε mm
//! along each contour (plus its vertices), and the way back from a node tour to a `Route`.

use cutroute_geometry::{ContourRef, CutStep, Nest, Point, Route};
use cutroute_pcgtsp::Instance;

use crate::problem::Problem;
use crate::CcpError;

/// How the contours are discretised.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscretisationOptions {
    /// Where the tool starts: the depot cluster's only node.
    pub start: Point,
    /// Where the closed tour's last arc goes instead of the depot (`None`: an open route, the
    /// return arc costs nothing).
    pub finish: Option<Point>,
    /// Step ε between candidate pierce points along a contour, mm.
    pub step: f64,
    /// Add every contour vertex as a candidate too.
    pub include_vertices: bool,
    /// Round costs to integers (as PCGTSPLIB files do).
    pub round_costs: bool,
}

impl Default for DiscretisationOptions {
    fn default() -> Self {
        DiscretisationOptions {
            start: Point::new(0.0, 0.0),
            finish: None,
            step: 25.0,
            include_vertices: true,
            round_costs: false,
        }
    }
}

/// What one node of the instance stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DiscreteNode {
    /// The start point (depot cluster).
    Depot(Point),
    /// A candidate pierce point on a contour.
    Pierce {
        /// The contour.
        contour: ContourRef,
        /// The point on it.
        point: Point,
    },
}

/// The candidate pierce points among `nodes` (contour, point), in node order: what
/// [`crate::CcpLowerBound::for_candidates`] bounds.
pub fn pierce_candidates(nodes: &[DiscreteNode]) -> Vec<(ContourRef, Point)> {
    nodes
        .iter()
        .filter_map(|n| match *n {
            DiscreteNode::Pierce { contour, point } => Some((contour, point)),
            DiscreteNode::Depot(_) => None,
        })
        .collect()
}

/// A PCGTSP instance built from a nest, with the meaning of its nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscreteInstance {
    /// The instance: cluster 0 is the depot, cluster `1 + i` the `i`-th contour of the nest in
    /// part/contour order.
    pub instance: Instance,
    /// Node `v` ↦ what it stands for.
    pub nodes: Vec<DiscreteNode>,
    /// The start point.
    pub start: Point,
    /// The finish point, if the route is closed by an idle move.
    pub finish: Option<Point>,
}

/// Most nodes (candidate points + depot) of a discretisation: its dense cost matrix is n² f64,
/// 3.2 GB at this size.
pub const MAX_DISCRETE_NODES: usize = 20_000;

/// Builds the PCGTSP instance of a nest: clusters are the contours plus the depot, costs are
/// Euclidean idle distances, precedence is "inner before outer" for every containment pair.
/// The cost matrix is dense (n² f64): Nest02/Nest03 at ε = 25 mm give 12,288 nodes, 1.2 GB;
/// above 20,000 nodes (3.2 GB) the build is refused.
pub fn build_pcgtsp(
    nest: &Nest,
    options: &DiscretisationOptions,
) -> Result<DiscreteInstance, CcpError> {
    let mut builder = PcgtspBuilder::new(nest, options)?;
    loop {
        if let Some(instance) = builder.advance(&|| false) {
            return Ok(instance);
        }
    }
}

/// [`build_pcgtsp`] in slices: [`PcgtspBuilder::new`] sizes the instance and places the
/// candidate points (cheap), [`PcgtspBuilder::advance`] fills the dense cost matrix row by row
/// until its `stop` says so. The matrix of a big nest takes seconds (Nest02 at 50 mm: 6,835
/// rows, 0.7 s), and a worker that must answer Stop within 200 ms cannot wait for it.
pub struct PcgtspBuilder {
    nodes: Vec<DiscreteNode>,
    points: Vec<Point>,
    clusters: Vec<Vec<usize>>,
    node_cluster: Vec<usize>,
    precedence: Vec<(usize, usize)>,
    finish: Option<Point>,
    round_costs: bool,
    start_point: Point,
    finish_point: Option<Point>,
    /// The rows filled so far (row `a` is the costs from node `a`).
    cost: Vec<f64>,
}

impl PcgtspBuilder {
    /// Checks the step, sizes the matrix (refusing more than [`MAX_DISCRETE_NODES`] nodes) and
    /// places the candidate points; the matrix is not allocated yet.
    pub fn new(nest: &Nest, options: &DiscretisationOptions) -> Result<Self, CcpError> {
        if !(options.step > 0.0 && options.step.is_finite()) {
            return Err(CcpError::InvalidOption("step must be positive".into()));
        }
        let start = options.start;
        let finish = options.finish;
        let prob = Problem::new(nest, start, finish);
        // Sized before anything is allocated: a contour gives at most one point per step of its
        // perimeter, one more, and (with vertices) one per span.
        let perimeter: f64 = prob
            .shapes
            .iter()
            .flat_map(|shape| shape.spans.iter().map(|span| span.length()))
            .sum();
        let fixed: usize = prob.shapes.iter().map(|shape| shape.spans.len() + 2).sum();
        let bound = perimeter / options.step + fixed as f64 + 1.0;
        if fixed + 1 >= MAX_DISCRETE_NODES {
            let contours = prob.shapes.len();
            let spans = fixed - 2 * contours;
            let what = if contours == 1 {
                format!("a contour of {spans} spans needs")
            } else {
                format!("{contours} contours of {spans} spans need")
            };
            return Err(CcpError::InvalidOption(format!(
                "{what} more than the {MAX_DISCRETE_NODES} candidate points of a dense cost \
                 matrix at any step (the ccp, chain, nearest and path solvers route any size)"
            )));
        }
        if bound.is_nan() || bound > MAX_DISCRETE_NODES as f64 {
            let smallest = perimeter / (MAX_DISCRETE_NODES - fixed - 1) as f64;
            return Err(CcpError::InvalidOption(format!(
                "step {} mm gives up to {bound:.0} candidate points, above the {MAX_DISCRETE_NODES} \
                 of a dense cost matrix; use a step of at least {smallest:.3} mm for this nest",
                options.step
            )));
        }
        let mut nodes = vec![DiscreteNode::Depot(options.start)];
        let mut points = vec![start];
        let mut clusters = vec![vec![0usize]];
        let mut node_cluster = vec![0usize];
        for (i, contour_ref) in prob.refs.iter().enumerate() {
            let contour = &nest.parts[contour_ref.part].contours[contour_ref.contour];
            let mut cl = Vec::new();
            for x in contour
                .candidate_points(options.step, options.include_vertices)
                .into_iter()
            {
                cl.push(points.len());
                node_cluster.push(i + 1);
                points.push(x);
                nodes.push(DiscreteNode::Pierce {
                    contour: prob.refs[i],
                    point: x,
                });
            }
            clusters.push(cl);
        }
        let n = points.len();
        if n > MAX_DISCRETE_NODES {
            return Err(CcpError::InvalidOption(format!(
                "{n} candidate points: the dense cost matrix is too large"
            )));
        }
        let precedence = prob
            .precedence_pairs()
            .into_iter()
            .map(|(inner, outer)| (inner + 1, outer + 1))
            .collect();
        Ok(PcgtspBuilder {
            nodes,
            points,
            clusters,
            node_cluster,
            precedence,
            finish,
            round_costs: options.round_costs,
            start_point: options.start,
            finish_point: options.finish,
            cost: Vec::new(),
        })
    }

    /// Nodes of the instance (candidate points and the depot).
    pub fn node_count(&self) -> usize {
        self.points.len()
    }

    /// What each node stands for (placed by [`PcgtspBuilder::new`], before any row is filled).
    pub fn nodes(&self) -> &[DiscreteNode] {
        &self.nodes
    }

    /// Rows of the cost matrix filled so far.
    pub fn rows_done(&self) -> usize {
        self.cost.len() / self.points.len().max(1)
    }

    /// The cost of the arc `a → b` as the matrix holds it: the idle distance (to the finish
    /// on the way back to the depot, nothing on an open route), rounded when asked; infinite
    /// within a cluster.
    fn arc_cost(&self, a: usize, b: usize) -> f64 {
        let d = if self.node_cluster[a] == self.node_cluster[b] {
            f64::INFINITY
        } else if b == 0 {
            self.finish.map_or(0.0, |f| self.points[a].fast_distance(f))
        } else {
            self.points[a].fast_distance(self.points[b])
        };
        if self.round_costs && d.is_finite() {
            d.round()
        } else {
            d
        }
    }

    /// A tour without the matrix, for when the time limit comes before the matrix is built: the
    /// nearest-neighbour tour over the candidate points (each step pierces, among the contours
    /// whose inner contours are all cut, at the candidate nearest to the last pierce), with
    /// its cost as the matrix prices it. One pass over the points per contour: 5 million
    /// distances on Nest03 at 25 mm, against the matrix's 150 million.
    pub fn nearest_neighbour_tour(&self) -> Option<(Vec<usize>, f64)> {
        let arc = |a: usize, b: usize| self.arc_cost(a, b);
        cutroute_pcgtsp::nearest_neighbour_tour(0, 0, &self.clusters, &self.precedence, &arc)
    }

    /// The route of a tour of this instance (see [`DiscreteInstance::tour_to_route`]).
    pub fn tour_to_route(&self, tour: &[usize]) -> Result<Route, CcpError> {
        tour_route(
            tour,
            &self.nodes,
            &self.node_cluster,
            self.clusters.len(),
            self.start_point,
            self.finish_point,
        )
    }

    /// Fills rows of the cost matrix, asking `stop` after each row; returns the instance once
    /// every row is filled (`None`: call again).
    pub fn advance(&mut self, stop: &dyn Fn() -> bool) -> Option<DiscreteInstance> {
        let n = self.points.len();
        if self.cost.capacity() < n * n {
            self.cost.reserve_exact(n * n - self.cost.len());
        }
        while self.rows_done() < n {
            let a = self.rows_done();
            for b in 0..n {
                let d = self.arc_cost(a, b);
                self.cost.push(d);
            }
            if self.rows_done() < n && stop() {
                return None;
            }
        }
        let instance = Instance {
            name: "ccp-discretised".into(),
            node_count: n,
            cost: std::mem::take(&mut self.cost),
            clusters: std::mem::take(&mut self.clusters),
            node_cluster: std::mem::take(&mut self.node_cluster),
            precedence: std::mem::take(&mut self.precedence),
            depot: 0,
        };
        Some(DiscreteInstance {
            instance,
            nodes: std::mem::take(&mut self.nodes),
            start: self.start_point,
            finish: self.finish_point,
        })
    }
}

impl DiscreteInstance {
    /// Turns a closed node tour (any rotation; it must contain the depot node once and one node
    /// of every cluster) into a route.
    pub fn tour_to_route(&self, tour: &[usize]) -> Result<Route, CcpError> {
        tour_route(
            tour,
            &self.nodes,
            &self.instance.node_cluster,
            self.instance.clusters.len(),
            self.start,
            self.finish,
        )
    }

    /// The cheapest node tour (depot first) that visits the contours in `route`'s order, and
    /// its cost: each contour's candidate chosen by a shortest path through the clusters in
    /// that order. So a route of the continuous solver, whose pierce points lie anywhere on
    /// the contours, gives a discrete tour of the same order at the nearest cost the
    /// candidates allow (nested.dbs at 25 mm: CCP's 9,535 mm gives 9,558 mm, where the
    /// heuristic alone reached 9,622–9,632 in 60 s). `None` when the route does not visit
    /// every contour of the instance once.
    pub fn tour_in_order_of(&self, route: &Route) -> Option<(Vec<usize>, f64)> {
        let mut cluster_of = std::collections::HashMap::new();
        for (v, node) in self.nodes.iter().enumerate() {
            if let DiscreteNode::Pierce { contour, .. } = node {
                cluster_of.insert(*contour, self.instance.node_cluster[v]);
            }
        }
        let mut seen = vec![false; self.instance.clusters.len()];
        let mut order = Vec::with_capacity(route.steps.len());
        for step in &route.steps {
            let &c = cluster_of.get(&step.contour)?;
            if std::mem::replace(&mut seen[c], true) {
                return None;
            }
            order.push(c);
        }
        if order.len() + 1 != self.instance.clusters.len() {
            return None;
        }
        let (nodes, cost) = crate::relaxed_tours::cheapest_pieces(&self.instance, &order)?;
        let mut tour = Vec::with_capacity(nodes.len() + 1);
        tour.push(*self.instance.clusters[self.instance.depot].first()?);
        tour.extend(nodes);
        Some((tour, cost))
    }
}

/// A closed node tour (any rotation; the depot node once and one node of every cluster) as a
/// route: the pierce points in the tour's order from the depot.
fn tour_route(
    tour: &[usize],
    nodes: &[DiscreteNode],
    node_cluster: &[usize],
    cluster_count: usize,
    start: Point,
    finish: Option<Point>,
) -> Result<Route, CcpError> {
    let depot_at = tour
        .iter()
        .position(|&v| v == 0)
        .ok_or(CcpError::InvalidTour("the tour misses the depot".into()))?;
    let mut seen = vec![false; cluster_count];
    let mut steps = Vec::with_capacity(tour.len().saturating_sub(1));
    for t in 0..tour.len() {
        let v = tour[(depot_at + t) % tour.len()];
        let cl = *node_cluster
            .get(v)
            .ok_or(CcpError::InvalidTour(format!("node {v} does not exist")))?;
        if std::mem::replace(&mut seen[cl], true) {
            return Err(CcpError::InvalidTour(format!("cluster {cl} visited twice")));
        }
        if let DiscreteNode::Pierce { contour, point } = nodes[v] {
            steps.push(CutStep {
                contour,
                pierce_point: point,
                entry: Default::default(),
                leads: None,
            });
        }
    }
    if let Some(cl) = seen.iter().position(|s| !s) {
        return Err(CcpError::InvalidTour(format!("cluster {cl} not visited")));
    }
    Ok(Route {
        start,
        steps,
        finish,
    })
}
