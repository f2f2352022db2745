//! The resumable anytime solver: `CcpSolver::step` runs for a time budget and can be called again
//! (the web worker runs solvers in time slices); `solve` runs it to the end.

use std::time::Duration;

use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit, Status};
use cutroute_geometry::{MachineParameters, Nest, Objective, Point, Route};
use cutroute_thermal::HeatModel;
use serde::{Deserialize, Serialize};
use web_time::Instant;

use crate::problem::Problem;
use crate::route::{
    assemble_route, idle_length, route_certificates, route_metrics, ContourCertificate,
    RouteMetrics,
};
use crate::search::{Move, Search, SearchParams};
use crate::CcpError;

/// Options of a CCP-Relax run. Plain data: build with `..Default::default()`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CcpOptions {
    /// Where the tool head starts (outside all contours).
    pub start: Point,
    /// Where it must end (`TerminalMotion`); `None` for an open route ending at the last cut.
    pub finish: Option<Point>,
    /// Relaxation stops when a full sweep shortens the route by at most this (mm).
    pub delta: f64,
    /// Relaxation also stops after this many sweeps. Coordinate-wise relaxation can creep: two
    /// neighbouring pierce points sliding together along parallel edges gain a few µm per sweep
    /// for tens of thousands of sweeps (Nest02 from the origin), so δ alone does not end it.
    pub max_relaxation_sweeps: usize,
    /// Wall-clock budget of the whole run (summed over `step` calls).
    pub time_limit: Duration,
    /// Seed of the solver's own PRNG (shaking, restarts).
    pub seed: u64,
    /// Size k of each contour's candidate list (k nearest contours).
    pub neighbours: usize,
    /// Largest distance in the order between contours of a 3- or 4-cycle.
    pub cycle_window: usize,
    /// Longest block moved by block shift and block exchange.
    pub max_block: usize,
    /// Longest block of the optimal re-insertion neighbourhood.
    pub reinsert_block: usize,
    /// VNS stops (or restarts) after this many shakes in a row without improvement.
    pub max_non_improving_shakes: usize,
    /// How many times the search restarts from a new randomised construction.
    pub restarts: usize,
    /// Largest shaking strength (number of random moves).
    pub max_shake_strength: usize,
    /// Apply the best move of a neighbourhood (by estimated gain) instead of the first
    /// improving one.
    pub best_improvement: bool,
    /// Machine speeds and pierce time of the time model.
    pub machine: MachineParameters,
    /// The heat penalty of issue #19 (`None`: plain CCP-Relax, unchanged).
    #[serde(default)]
    pub heat: Option<HeatPenalty>,
}

/// Minimise the objective plus `weight · H` (H: the thermal load of `cutroute-thermal` on the
/// machine clock of `CcpOptions::machine`).
///
/// CCP-Relax cuts every contour once with one pierce each, so time and cost differ from the
/// idle length only by a constant and a factor: the penalty enters the search as
/// `weight · H` converted to millimetres of idle travel (× V_off for time, ÷ C_off per mm for
/// cost). The search's H runs over the innermost contours in order, each outer contour counted
/// right after the last contour inside it (where step 4 restores it, near the route's last
/// crossing); pairs whose kernel is below e⁻¹² are skipped. The reported H is recomputed on the
/// final route.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeatPenalty {
    /// σ and τ.
    pub model: HeatModel,
    /// Objective units per unit of H (s for time, price units for cost).
    pub weight: f64,
    /// What the weight's unit is.
    pub objective: Objective,
}

impl HeatPenalty {
    /// The weight in millimetres of idle travel per unit of H under `machine`.
    pub fn weight_mm(&self, machine: &MachineParameters) -> f64 {
        match self.objective {
            Objective::Time => self.weight * machine.idle_speed,
            Objective::Cost => self.weight / (machine.idle_price_per_metre * 1e-3),
        }
    }
}

impl Default for CcpOptions {
    fn default() -> Self {
        CcpOptions {
            start: Point::new(0.0, 0.0),
            finish: None,
            delta: 1e-6,
            max_relaxation_sweeps: 1000,
            time_limit: Duration::from_secs(30),
            seed: 1,
            neighbours: 8,
            cycle_window: 5,
            max_block: 3,
            reinsert_block: 10,
            max_non_improving_shakes: 300,
            restarts: 1,
            max_shake_strength: 5,
            best_improvement: false,
            machine: MachineParameters::default(),
            heat: None,
        }
    }
}

/// Where the solver is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum CcpPhase {
    /// Nothing computed yet.
    Start,
    /// Relaxing the pierce points of the nearest-neighbour order (sweeps until δ).
    Relaxing,
    /// Descending to the first VNS local optimum.
    LocalSearch,
    /// Shaking and descending again (VNS proper).
    Shaking,
    /// Finished.
    Done,
}

/// A snapshot of the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CcpProgress {
    /// Computing time used so far.
    pub elapsed: Duration,
    /// Idle length of the best route so far (mm).
    pub best_idle_length: f64,
    /// The best route so far, all contours restored.
    pub route: Route,
    /// The current phase.
    pub phase: CcpPhase,
    /// Time at which the first VNS local optimum was reached.
    pub local_optimum_time: Option<Duration>,
    /// Idle length at the first local optimum.
    pub local_optimum_length: Option<f64>,
    /// Idle length of the initial (nearest-neighbour, relaxed) route.
    pub initial_length: Option<f64>,
    /// Moves evaluated.
    pub evaluations: u64,
    /// Moves checked exactly (applied, relaxed, then kept or undone).
    pub exact_checks: u64,
    /// Moves accepted.
    pub accepted_moves: u64,
    /// VNS shakes done.
    pub shakes: u64,
    /// Contours kept by step 1 (innermost).
    pub kept_contours: usize,
    /// Contours removed by step 1 and restored in step 4.
    pub removed_contours: usize,
}

/// The outcome of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CcpResult {
    /// The route over all contours.
    pub route: Route,
    /// Its lengths, pierce count and time.
    pub metrics: RouteMetrics,
    /// Conditions 1 and 2 per step of the route.
    pub certificates: Vec<ContourCertificate>,
    /// Condition 1 holds at every pierce point: optimal for this order (Proposition 2).
    pub certified_optimal_for_order: bool,
    /// The final progress snapshot.
    pub progress: CcpProgress,
}

/// CCP-Relax as a resumable anytime solver.
pub struct CcpSolver {
    nest: Nest,
    options: CcpOptions,
    search: Search,
    phase: CcpPhase,
    elapsed: Duration,
    best: Option<(Vec<u32>, Vec<Point>, f64)>,
    route: Route,
    route_length: f64,
    local_optimum_time: Option<Duration>,
    local_optimum_length: Option<f64>,
    initial_length: Option<f64>,
    fails: usize,
    strength: usize,
    restarts_left: usize,
    shakes: u64,
    relaxation_sweeps: usize,
    /// Sweeps done by the full relaxation that ends a local search, while it runs: it may take
    /// up to `max_relaxation_sweeps` sweeps (over a second on Nest02), so it runs one sweep
    /// per iteration of the step loop, across slices.
    full_relaxation_sweeps: Option<usize>,
    cancelled: bool,
    /// The run ended at its time limit or by [`CcpSolver::cancel`], not at the VNS's end.
    stopped: bool,
    /// The final route's pierce points were relaxed under the heat penalty.
    heat_relaxed: bool,
}

impl CcpSolver {
    /// Prepares a run: step 1 (containment forest, outer contours removed) and candidate lists.
    pub fn new(nest: &Nest, options: CcpOptions) -> Result<CcpSolver, CcpError> {
        let finite = |p: Point| p.x.is_finite() && p.y.is_finite();
        if !finite(options.start) || options.finish.is_some_and(|f| !finite(f)) {
            return Err(CcpError::InvalidOption(
                "start and finish must be finite".into(),
            ));
        }
        if !(options.delta > 0.0 && options.delta.is_finite()) {
            return Err(CcpError::InvalidOption("delta must be positive".into()));
        }
        if options.max_relaxation_sweeps == 0 {
            return Err(CcpError::InvalidOption(
                "max_relaxation_sweeps must be at least 1".into(),
            ));
        }
        if options.neighbours == 0
            || options.max_block == 0
            || options.max_block > 5
            || options.cycle_window > 14
        {
            return Err(CcpError::InvalidOption(
                "neighbours ≥ 1, 1 ≤ max_block ≤ 5 and cycle_window ≤ 14 are required".into(),
            ));
        }
        if let Some(heat) = &options.heat {
            heat.model
                .validate()
                .map_err(|e| CcpError::InvalidOption(e.to_string()))?;
            let weight = heat.weight_mm(&options.machine);
            let m = &options.machine;
            let valid = weight >= 0.0
                && weight.is_finite()
                && m.idle_speed > 0.0
                && m.cut_speed > 0.0
                && m.pierce_time >= 0.0;
            if !valid {
                return Err(CcpError::InvalidOption(
                    "the heat weight must be finite and non-negative (and the idle price positive \
                     for cost), speeds positive"
                        .into(),
                ));
            }
        }
        let t0 = Instant::now();
        let start = options.start;
        let finish = options.finish;
        let prob = Problem::new(nest, start, finish);
        let params = SearchParams {
            delta: options.delta,
            max_relaxation_sweeps: options.max_relaxation_sweeps,
            neighbours: options.neighbours,
            cycle_window: options.cycle_window,
            max_block: options.max_block,
            reinsert_block: options.reinsert_block,
        };
        let mut search = Search::new(prob, start, finish, params, options.seed);
        search.best_improvement = options.best_improvement;
        if let Some(heat) = options.heat.filter(|h| h.weight > 0.0) {
            search.set_heat(
                nest,
                heat.model,
                heat.weight_mm(&options.machine),
                &options.machine,
            );
        }
        let restarts_left = options.restarts;
        Ok(CcpSolver {
            nest: nest.clone(),
            route: Route {
                start: options.start,
                steps: Vec::new(),
                finish: options.finish,
            },
            options,
            search,
            phase: CcpPhase::Start,
            elapsed: t0.elapsed(),
            best: None,
            route_length: 0.0,
            local_optimum_time: None,
            local_optimum_length: None,
            initial_length: None,
            fails: 0,
            strength: 1,
            restarts_left,
            shakes: 0,
            relaxation_sweeps: 0,
            full_relaxation_sweeps: None,
            cancelled: false,
            stopped: false,
            heat_relaxed: false,
        })
    }

    /// Stops the run: the next `step` returns [`Status::Stopped`] and the best route stays
    /// available.
    pub fn cancel(&mut self) {
        self.cancelled = true;
    }

    /// Runs for about `budget` (checked between moves) and reports whether more is to be done:
    /// [`Status::Finished`] when the VNS ended (never proven optimal), [`Status::Stopped`] at
    /// the time limit or after [`CcpSolver::cancel`].
    pub fn step(&mut self, budget: Duration) -> Status {
        let t0 = Instant::now();
        let result = self.step_inner(t0, budget);
        if !matches!(self.phase, CcpPhase::Start | CcpPhase::Relaxing)
            || self.route.steps.is_empty()
        {
            self.refresh_route();
        }
        if self.phase == CcpPhase::Done {
            self.relax_heat();
        }
        self.elapsed += t0.elapsed();
        result
    }

    fn out_of_time(&self, t0: Instant, budget: Duration) -> bool {
        t0.elapsed() >= budget || self.time_is_up(t0)
    }

    /// The whole run's limit (not just this slice's budget) is used up.
    fn time_is_up(&self, t0: Instant) -> bool {
        self.elapsed + t0.elapsed() >= self.options.time_limit
    }

    /// Ends the slice: `Stopped` when the run's time limit is reached (in any phase), else
    /// `Running`.
    fn end_slice(&mut self, t0: Instant) -> Status {
        if self.time_is_up(t0) {
            self.stopped = true;
            self.finish_run();
            Status::Stopped
        } else {
            Status::Running
        }
    }

    /// The status of a run whose phase is `Done`.
    fn done_status(&self) -> Status {
        if self.stopped {
            Status::Stopped
        } else {
            Status::Finished {
                proven_optimal: false,
            }
        }
    }

    fn step_inner(&mut self, t0: Instant, budget: Duration) -> Status {
        if self.cancelled && self.phase != CcpPhase::Done {
            if self.phase == CcpPhase::Start {
                // Even a run cancelled at once reports a complete route.
                self.search.construct(false);
            }
            self.stopped = true;
            self.finish_run();
        }
        loop {
            match self.phase {
                CcpPhase::Done => return self.done_status(),
                CcpPhase::Start => {
                    self.search.construct(false);
                    self.phase = CcpPhase::Relaxing;
                    if self.out_of_time(t0, budget) {
                        return self.end_slice(t0);
                    }
                }
                CcpPhase::Relaxing => {
                    // One sweep per iteration so that long relaxations respect time slices.
                    let gain = self.search.sweep();
                    self.relaxation_sweeps += 1;
                    if gain <= self.options.delta
                        || self.relaxation_sweeps >= self.options.max_relaxation_sweeps
                    {
                        self.initial_length = Some(self.search.total);
                        self.search.queue_all();
                        self.phase = CcpPhase::LocalSearch;
                    }
                    if self.out_of_time(t0, budget) {
                        return self.end_slice(t0);
                    }
                }
                CcpPhase::LocalSearch | CcpPhase::Shaking => {
                    if self.full_relaxation_sweeps.is_none() && !self.descend(t0, budget) {
                        return self.end_slice(t0);
                    }
                    // The queue is empty: a local optimum of every neighbourhood. A full
                    // relaxation (`Search::relax_full`, a sweep at a time) queues the contours
                    // whose pierce points still moved. (After a shake only the neighbourhood
                    // of the shake moved: the local relaxation of the moves already covers it.)
                    if self.phase == CcpPhase::LocalSearch {
                        let sweeps = self.full_relaxation_sweeps.unwrap_or(0) + 1;
                        let gain = self.search.sweep();
                        let params = &self.search.params;
                        if gain > params.delta && sweeps < params.max_relaxation_sweeps {
                            self.full_relaxation_sweeps = Some(sweeps);
                            if self.out_of_time(t0, budget) {
                                return self.end_slice(t0);
                            }
                            continue;
                        }
                        self.full_relaxation_sweeps = None;
                        if !self.search.queue.is_empty() {
                            continue;
                        }
                    }
                    if self.phase == CcpPhase::LocalSearch {
                        self.local_optimum_time = Some(self.elapsed + t0.elapsed());
                        self.local_optimum_length = Some(self.search.total);
                        self.phase = CcpPhase::Shaking;
                        self.best = Some(self.search.snapshot());
                    } else {
                        self.after_shake();
                    }
                    if self.phase == CcpPhase::Done {
                        return self.done_status();
                    }
                    // Shake before the time check: a slice that ended here would otherwise
                    // resume with an empty queue and judge the same state twice, so the run
                    // would depend on where the slices fall.
                    self.shake();
                    if self.out_of_time(t0, budget) {
                        return self.end_slice(t0);
                    }
                }
            }
        }
    }

    /// Runs the queue-driven VND; true when the queue emptied, false when time ran out.
    fn descend(&mut self, t0: Instant, budget: Duration) -> bool {
        while let Some(c) = self.search.pop() {
            for nb in 0..Search::NEIGHBOURHOODS {
                if self.search.explore(nb, c) {
                    self.search.push(c);
                    break;
                }
            }
            // After every contour: on 460 contours 32 explorations took up to 1.7 s, far
            // past a 40 ms slice, and a clock read is nothing beside one exploration.
            if self.out_of_time(t0, budget) {
                return false;
            }
        }
        true
    }

    /// Compares the descended shake with the best; keeps or reverts; restarts or stops.
    fn after_shake(&mut self) {
        let best_len = self.best.as_ref().map_or(f64::INFINITY, |b| b.2);
        if self.search.objective() < best_len - 1e-6 {
            self.best = Some(self.search.snapshot());
            self.fails = 0;
            self.strength = 1;
        } else {
            if let Some(b) = &self.best {
                self.search.restore(b);
            }
            self.fails += 1;
            self.strength = self.strength % self.options.max_shake_strength.max(1) + 1;
        }
        if self.fails >= self.options.max_non_improving_shakes {
            if self.restarts_left > 0 {
                self.restarts_left -= 1;
                self.fails = 0;
                self.search.construct(true);
                self.search.relax_full();
                self.search.queue_all();
                // The restart descends in the shaking phase and is compared with the best.
            } else {
                self.finish_run();
            }
        }
    }

    /// VNS shaking: `strength` random moves in a window of the order around a random position.
    fn shake(&mut self) {
        self.shakes += 1;
        let n = self.search.len();
        if n < 4 {
            self.fails = self.options.max_non_improving_shakes;
            return;
        }
        if self.strength == self.options.max_shake_strength && n >= 8 {
            // The strongest shake exchanges two blocks anywhere in the order (a double bridge).
            let len1 = 1 + self.search.rng.index_below(3);
            let len2 = 1 + self.search.rng.index_below(3);
            let i = self.search.rng.index_below(n - len1 - len2 - 1);
            let k = i + len1 + 1 + self.search.rng.index_below(n - i - len1 - len2);
            let m = Move::Exchange {
                i,
                j: i + len1 - 1,
                k,
                l: k + len2 - 1,
            };
            self.search.force_move(&m);
            return;
        }
        let centre = self.search.rng.index_below(n);
        let span = 8 + 4 * self.strength;
        for _ in 0..self.strength {
            if let Some(m) = self.search.random_move(centre, span) {
                self.search.force_move(&m);
            }
        }
    }

    fn finish_run(&mut self) {
        if let Some(b) = &self.best {
            if b.2 < self.search.objective() {
                self.search.restore(b);
            }
        }
        self.phase = CcpPhase::Done;
    }

    /// Rebuilds the cached route from the best state when it changed.
    fn refresh_route(&mut self) {
        let (len, use_best) = match &self.best {
            Some(b) if b.2 <= self.search.objective() => (b.2, true),
            _ => (self.search.objective(), false),
        };
        if !self.route.steps.is_empty() && (len - self.route_length).abs() < 1e-9 {
            return;
        }
        let route = match (&self.best, use_best) {
            (Some(b), true) => assemble_route(&self.search, &b.0, &b.1),
            _ => assemble_route(&self.search, &self.search.order, &self.search.pts),
        };
        self.route_length = len;
        self.route = route;
        self.heat_relaxed = false;
    }

    /// With a heat penalty, the final route's pierce points (outer contours restored by step 4
    /// included) move along their contours where idle + weight · H falls
    /// (`cutroute_thermal::relax_pierce_points`); the search's relaxation minimises idle only.
    fn relax_heat(&mut self) {
        let Some(heat) = self.options.heat.filter(|h| h.weight > 0.0) else {
            return;
        };
        if self.heat_relaxed {
            return;
        }
        let weight_mm = heat.weight_mm(&self.options.machine);
        if let Ok(route) = cutroute_thermal::relax_pierce_points(
            &self.nest,
            &self.route,
            &self.options.machine,
            &heat.model,
            weight_mm,
            3,
            None,
        ) {
            self.route = route;
        }
        self.heat_relaxed = true;
    }

    /// The current snapshot.
    pub fn progress(&self) -> CcpProgress {
        CcpProgress {
            elapsed: self.elapsed,
            best_idle_length: idle_length(&self.route),
            route: self.route.clone(),
            phase: self.phase,
            local_optimum_time: self.local_optimum_time,
            local_optimum_length: self.local_optimum_length,
            initial_length: self.initial_length,
            evaluations: self.search.evaluations,
            exact_checks: self.search.exact_checks,
            accepted_moves: self.search.accepted,
            shakes: self.shakes,
            kept_contours: self.search.prob.kept.len(),
            removed_contours: self.search.prob.removed.len(),
        }
    }

    /// Conditions 1 and 2 at every pierce point of the best route.
    pub fn certificates(&self) -> Vec<ContourCertificate> {
        route_certificates(&self.nest, &self.route).unwrap_or_default()
    }

    /// The result for the best route so far.
    pub fn result(&self) -> CcpResult {
        let certificates = self.certificates();
        let metrics =
            route_metrics(&self.nest, &self.route, &self.options.machine).unwrap_or_default();
        CcpResult {
            route: self.route.clone(),
            metrics,
            certified_optimal_for_order: certificates.iter().all(|c| c.condition1),
            certificates,
            progress: self.progress(),
        }
    }
}

/// The contract of every solver: the route with every contour restored, its idle length (the
/// objective CCP-Relax minimises; the heat penalty is priced in the search, not in this bound).
impl AnytimeSolver for CcpSolver {
    type Solution = Route;

    fn step(&mut self, budget: Duration) -> Status {
        CcpSolver::step(self, budget)
    }

    fn best(&self) -> Option<Route> {
        (!self.route.steps.is_empty()).then(|| self.route.clone())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            upper: (!self.route.steps.is_empty()).then(|| idle_length(&self.route)),
            lower: None,
            unit: CostUnit::IdleMm,
        }
    }
}

/// Runs CCP-Relax to the end (VNS finished or time limit), reporting progress after each slice.
pub fn solve(
    nest: &Nest,
    options: CcpOptions,
    on_progress: &mut dyn FnMut(&CcpProgress),
) -> Result<CcpResult, CcpError> {
    solve_with_cancel(nest, options, on_progress, &|| false)
}

/// Like [`solve`], polling `cancelled` between slices.
pub fn solve_with_cancel(
    nest: &Nest,
    options: CcpOptions,
    on_progress: &mut dyn FnMut(&CcpProgress),
    cancelled: &dyn Fn() -> bool,
) -> Result<CcpResult, CcpError> {
    let mut solver = CcpSolver::new(nest, options)?;
    loop {
        if cancelled() {
            solver.cancel();
        }
        let status = solver.step(Duration::from_millis(100));
        on_progress(&solver.progress());
        if status.is_done() {
            return Ok(solver.result());
        }
    }
}
