//! The exact solver over the discretised full cutting route (issue #17, "discrete/exact:
//! candidates in G_M, distances switch-off → pierce").
//!
//! The model is a PCGTSP instance ([`FullRouteModel`]): cluster 0 is the start; cluster
//! `1 + i` is the `i`-th contour of the nest (part/contour order). A node of a contour is one
//! complete set of its full-route elements ([`StepLeads`]): an entry on the equidistant at one
//! of evenly spaced arc lengths (about one per discretisation step, at least
//! [`MIN_POSITIONS`]), the lead-in and lead-out that [`LeadFitter::fit_at`] fits there (the
//! asked leads or their shortened and turned variants), so its pierce point M lies in G_M and
//! its switch-off point M* in G_M*. A hole where no position fits gets the fitter's own choice
//! (a centre pierce). The arc from node a to node b costs |M*ₐ → M_b|, the idle leg of the
//! full route; from the start, |start → M_b|; back to the start, |M*ₐ → finish| (0 for an open
//! route). Precedence is inner before outer, as in the idealised model. Every tour is
//! therefore a full route with leads whose idle length is the tour's cost, and the leads'
//! lengths and shapes enter through where each candidate puts M and M*.
//!
//! **What the bound proves.** The exact search's lower bound is a bound on this instance: no
//! full route whose every contour is entered at one of these candidates (with these leads) has
//! a shorter idle length, and "proven optimal" means the route is the best of those. It says
//! nothing about entries between the candidates, or other leads at the same entry: it is a
//! bound for the discretised full-route problem at that step, as the idealised exact solver's
//! is for the discretised idealised problem. (The route is therefore not relaxed along the
//! equidistants afterwards: a relaxed route leaves the candidates, and the bound would no
//! longer be about it.)

use cutroute_geometry::{
    ContainmentForest, ContourRef, CutStep, KerfSettings, LeadError, LeadFitter, Nest, Point,
    Route, StepLeads,
};
use cutroute_pcgtsp::Instance;
use cutroute_protocol::{CostUnit, Phase, Progress, Solution};
use web_time::{Duration, Instant};

use crate::{DiscreteJob, DiscreteMode, Job, JobStatus, Refusal};

/// Fewest entry positions tried round each equidistant (small contours get this many even
/// when their perimeter is shorter than the step).
pub const MIN_POSITIONS: usize = 4;

/// The full-route PCGTSP instance of a nest and what its nodes stand for.
#[derive(Clone, Debug)]
pub struct FullRouteModel {
    /// Cluster 0: the start (node 0); cluster `1 + i`: the `i`-th contour's candidates.
    pub instance: Instance,
    /// Node `v` ↦ its contour and full-route elements (`None` for the start node).
    pub nodes: Vec<Option<(ContourRef, StepLeads)>>,
    /// Where the tool starts.
    pub start: Point,
    /// Where it ends, if the route is closed by an idle move.
    pub finish: Option<Point>,
}

impl FullRouteModel {
    /// The route of a closed node tour (any rotation, the start node once, one node of every
    /// cluster); `None` when the tour is not one.
    pub fn tour_to_route(&self, nest: &Nest, tour: &[usize]) -> Option<Route> {
        let at = tour.iter().position(|&v| v == 0)?;
        let mut seen = vec![false; self.instance.clusters.len()];
        let mut steps = Vec::with_capacity(tour.len().saturating_sub(1));
        for k in 0..tour.len() {
            let v = tour[(at + k) % tour.len()];
            let cluster = *self.instance.node_cluster.get(v)?;
            if std::mem::replace(&mut seen[cluster], true) {
                return None;
            }
            if let Some((contour, leads)) = &self.nodes[v] {
                // The step's pierce point on the contour is the point under the entry (as
                // `LeadFitter::attach_to_step` places it).
                let on_contour = nest.contour(*contour)?.nearest_point(leads.entry)?.point;
                steps.push(CutStep {
                    contour: *contour,
                    pierce_point: on_contour,
                    entry: Default::default(),
                    leads: Some(leads.clone()),
                });
            }
        }
        seen.iter().all(|&s| s).then_some(Route {
            start: self.start,
            steps,
            finish: self.finish,
        })
    }
}

/// Builds a [`FullRouteModel`] in slices: the leads of one contour's candidates at a time
/// until [`FullRouteBuilder::advance`]'s time is up, then the cost matrix a row at a time (on
/// Nest02 its 5,000 × 5,000 legs were a piece of seconds, longer than Stop may wait).
pub struct FullRouteBuilder {
    nest: Nest,
    forest: ContainmentForest,
    settings: KerfSettings,
    step: f64,
    start: Point,
    finish: Option<Point>,
    refs: Vec<ContourRef>,
    /// The candidates of `refs[..candidates.len()]`.
    candidates: Vec<Vec<StepLeads>>,
    errors: Vec<LeadError>,
    /// The matrix under way, once every candidate is placed.
    matrix: Option<Matrix>,
}

/// The full-route instance's nodes and clusters, and its cost matrix's rows so far.
struct Matrix {
    nodes: Vec<Option<(ContourRef, StepLeads)>>,
    clusters: Vec<Vec<usize>>,
    node_cluster: Vec<usize>,
    cost: Vec<f64>,
}

impl FullRouteBuilder {
    /// A builder for `nest` under `settings`, entries about `step` mm apart round each
    /// equidistant.
    pub fn new(
        nest: &Nest,
        settings: KerfSettings,
        step: f64,
        start: Point,
        finish: Option<Point>,
    ) -> Result<FullRouteBuilder, Refusal> {
        if !(step > 0.0 && step.is_finite()) {
            return Err(Refusal::DiscretisationStep(step));
        }
        Ok(FullRouteBuilder {
            forest: nest.containment_forest(),
            refs: nest.contour_refs().collect(),
            nest: nest.clone(),
            settings,
            step,
            start,
            finish,
            candidates: Vec::new(),
            errors: Vec::new(),
            matrix: None,
        })
    }

    /// Contours whose candidates are placed, of all.
    pub fn progress(&self) -> (usize, usize) {
        (self.candidates.len() + self.errors.len(), self.refs.len())
    }

    /// Places candidates, then fills the matrix, until `until` (at least a contour or a row
    /// per call); the model (or every contour where no lead fits) once all is built.
    pub fn advance(&mut self, until: Instant) -> Option<Result<FullRouteModel, Vec<LeadError>>> {
        if self.matrix.is_none() {
            let fitter = LeadFitter::with_forest(&self.nest, &self.forest, self.settings);
            loop {
                let done = self.candidates.len() + self.errors.len();
                let Some(&r) = self.refs.get(done) else {
                    break;
                };
                match self.candidates_of(&fitter, r) {
                    Ok(c) => self.candidates.push(c),
                    Err(e) => {
                        // Keeps `candidates` aligned with `refs` while errors are collected.
                        self.candidates.push(Vec::new());
                        self.errors.push(e);
                    }
                }
                if Instant::now() >= until && done + 1 < self.refs.len() {
                    return None;
                }
            }
            if !self.errors.is_empty() {
                return Some(Err(std::mem::take(&mut self.errors)));
            }
            self.matrix = Some(self.nodes());
            if Instant::now() >= until {
                return None;
            }
        }
        let matrix = self.matrix.as_mut().expect("set above");
        let n = matrix.nodes.len();
        loop {
            let a = matrix.cost.len() / n;
            if a == n {
                break;
            }
            let from = matrix.nodes[a]
                .as_ref()
                .map_or(self.start, |(_, l)| l.switch_off);
            for b in 0..n {
                matrix
                    .cost
                    .push(if matrix.node_cluster[a] == matrix.node_cluster[b] {
                        f64::INFINITY
                    } else {
                        match &matrix.nodes[b] {
                            Some((_, l)) => from.distance(l.pierce),
                            None => self.finish.map_or(0.0, |f| from.distance(f)),
                        }
                    });
            }
            if a + 1 < n && Instant::now() >= until {
                return None;
            }
        }
        Some(Ok(self.model()))
    }

    fn candidates_of(
        &self,
        fitter: &LeadFitter<'_>,
        r: ContourRef,
    ) -> Result<Vec<StepLeads>, LeadError> {
        let eq = fitter.equidistant(r)?;
        let perimeter = eq.perimeter();
        let positions = ((perimeter / self.step).ceil() as usize).max(MIN_POSITIONS);
        let mut found: Vec<StepLeads> = (0..positions)
            .filter_map(|k| {
                fitter
                    .fit_at(r, &eq, perimeter * k as f64 / positions as f64)
                    .ok()
            })
            .collect();
        // The same leads at two positions (a fitter fallback) are one candidate.
        found.dedup();
        if found.is_empty() {
            // The fitter's own search: more positions, and a centre pierce in a hole.
            let centre = self
                .nest
                .contour(r)
                .map_or(self.start, |c| c.bounding_box().centre());
            found.push(fitter.fit_on(r, &eq, centre)?);
        }
        Ok(found)
    }

    /// The instance's nodes (the start, then every contour's candidates) and clusters.
    fn nodes(&mut self) -> Matrix {
        let mut nodes: Vec<Option<(ContourRef, StepLeads)>> = vec![None];
        let mut clusters = vec![vec![0usize]];
        let mut node_cluster = vec![0usize];
        for (i, (r, candidates)) in self
            .refs
            .iter()
            .zip(std::mem::take(&mut self.candidates))
            .enumerate()
        {
            let mut cluster = Vec::with_capacity(candidates.len());
            for leads in candidates {
                cluster.push(nodes.len());
                node_cluster.push(i + 1);
                nodes.push(Some((*r, leads)));
            }
            clusters.push(cluster);
        }
        let n = nodes.len();
        Matrix {
            nodes,
            clusters,
            node_cluster,
            cost: Vec::with_capacity(n * n),
        }
    }

    /// The model of the complete matrix.
    fn model(&mut self) -> FullRouteModel {
        let Matrix {
            nodes,
            clusters,
            node_cluster,
            cost,
        } = self.matrix.take().expect("the matrix is complete");
        let n = nodes.len();
        let index: std::collections::HashMap<ContourRef, usize> = self
            .refs
            .iter()
            .enumerate()
            .map(|(i, &r)| (r, i + 1))
            .collect();
        let precedence = self
            .forest
            .all_precedence_pairs()
            .into_iter()
            .filter_map(|(inner, outer)| Some((*index.get(&inner)?, *index.get(&outer)?)))
            .collect();
        FullRouteModel {
            instance: Instance {
                name: "full-route-discretised".into(),
                node_count: n,
                cost,
                clusters,
                node_cluster,
                precedence,
                depot: 0,
            },
            nodes,
            start: self.start,
            finish: self.finish,
        }
    }
}

/// [`FullRouteBuilder`] run to its end in one go.
pub fn build_full_route_model(
    nest: &Nest,
    settings: KerfSettings,
    step: f64,
    start: Point,
    finish: Option<Point>,
) -> Result<Result<FullRouteModel, Vec<LeadError>>, Refusal> {
    let mut builder = FullRouteBuilder::new(nest, settings, step, start, finish)?;
    loop {
        if let Some(model) = builder.advance(Instant::now()) {
            return Ok(model);
        }
    }
}

/// The exact search (ALNS incumbents, exact bounds: [`DiscreteJob`] in its exact mode) over a
/// [`FullRouteModel`]: its routes carry their leads, its bounds are the instance's.
pub struct FullRouteJob {
    nest: Nest,
    model: FullRouteModel,
    search: DiscreteJob,
}

impl FullRouteJob {
    /// The exact job on `model` of `nest`, ended `time_limit` after `started`. Its solvers are
    /// made in its first steps (made here, they were one piece of seconds on Nest02); one that
    /// refuses the instance ends the job without a route, its phase saying why.
    pub fn new(
        job_id: u64,
        nest: Nest,
        mut model: FullRouteModel,
        time_limit: Duration,
        started: Instant,
        seed: u64,
    ) -> FullRouteJob {
        // The search takes the cost matrix (hundreds of MB on a big nest: no copy); the model
        // keeps the clusters its routes are read with.
        let instance = Instance {
            cost: std::mem::take(&mut model.instance.cost),
            ..model.instance.clone()
        };
        let search = DiscreteJob::unbuilt(
            job_id,
            instance,
            DiscreteMode::Exact,
            time_limit,
            started,
            seed,
        );
        FullRouteJob {
            nest,
            model,
            search,
        }
    }
}

impl Job for FullRouteJob {
    fn step(&mut self, budget: Duration) -> JobStatus {
        self.search.step(budget)
    }

    fn progress(&self) -> Progress {
        let mut progress = self.search.progress();
        // The tour's cost is the route's idle length (but for rounding): the model's arcs are
        // the legs M* → next M.
        let route = progress
            .tour()
            .and_then(|tour| self.model.tour_to_route(&self.nest, tour));
        progress.solution = route.map(Solution::Route);
        progress.bounds = progress.bounds.in_unit(CostUnit::IdleMm);
        progress
    }
}

/// The kerf job's stand-in for the exact job while its model is built (the phase says so).
pub(crate) struct Modelling {
    pub(crate) job_id: u64,
}

impl Job for Modelling {
    fn step(&mut self, _budget: Duration) -> JobStatus {
        JobStatus::Running
    }

    fn progress(&self) -> Progress {
        Progress {
            job_id: self.job_id,
            phase: Phase::BuildingExact,
            ..Progress::default()
        }
    }
}
