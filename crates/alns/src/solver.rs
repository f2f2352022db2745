//! The resumable ALNS driver: operator selection, acceptance, restarts and bookkeeping.

use cutroute_geometry::float::Libm;
use std::time::Duration;

use cutroute_pcgtsp::Instance;
use web_time::Instant;

use crate::local_search::{eps, LocalSearch};
use crate::nodes::NodeChoice;
use crate::operators::{Insertion, Operators, Removal, Selection, INSERTIONS, REMOVALS};
use crate::problem::{Problem, ProblemBuild};
use crate::{AlnsError, AlnsOptions, AlnsProgress, StopReason};
use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit, Status};
use cutroute_geometry::Xoshiro256 as Rng;

/// Adaptive weights of one family of operators (Ropke & Pisinger's segment scheme).
#[derive(Clone, Debug)]
struct Adaptive<const N: usize> {
    weight: [f64; N],
    score: [f64; N],
    uses: [u32; N],
}

impl<const N: usize> Adaptive<N> {
    fn new() -> Self {
        Adaptive {
            weight: [1.0; N],
            score: [0.0; N],
            uses: [0; N],
        }
    }

    /// Roulette-wheel choice proportional to weight.
    fn pick(&mut self, rng: &mut Rng) -> usize {
        let total: f64 = self.weight.iter().sum();
        let mut x = rng.unit() * total;
        for (i, w) in self.weight.iter().enumerate() {
            if x < *w {
                self.uses[i] += 1;
                return i;
            }
            x -= w;
        }
        self.uses[N - 1] += 1;
        N - 1
    }

    /// Ends a segment: blends the mean score of each used operator into its weight. A floor
    /// keeps every operator alive (what works changes during a run).
    fn end_segment(&mut self, reaction: f64) {
        for i in 0..N {
            if self.uses[i] > 0 {
                let mean = self.score[i] / self.uses[i] as f64;
                self.weight[i] = (1.0 - reaction) * self.weight[i] + reaction * mean;
            }
            self.score[i] = 0.0;
            self.uses[i] = 0;
        }
        let top = self.weight.iter().cloned().fold(0.0, f64::max);
        for w in &mut self.weight {
            *w = w.max(0.05 * top).max(1e-3);
        }
    }
}

/// Where the first tour's descent is: the next unit (0 2-opt, 1 or-opt, 2 reinsertion,
/// 3 block reversal when the round changed nothing, 4 the node-choice DP) and whether the
/// round's moves changed the tour.
#[derive(Clone, Copy, Debug, Default)]
struct Descent {
    unit: u8,
    changed: bool,
    /// Where the unit's move family paused.
    family: FamilyAt,
}

/// Where a move family paused at a slice's end ([`run_family`]): whether it is under way, and
/// the reinsertion's position.
#[derive(Clone, Copy, Debug, Default)]
struct FamilyAt {
    partial: bool,
    reinsert: Option<(usize, usize)>,
}

/// Runs move family `family` (0 2-opt, 1 or-opt, 2 reinsertion, 3 block reversal of segments
/// up to `max_len`) on `tour` until `pause()`, setting `changed` when it improved the tour;
/// whether it is finished. Unfinished, `at` is marked under way and the next call goes on from
/// it (with the result of one call); finished, `at` is reset for the next family.
#[allow(clippy::too_many_arguments)]
fn run_family(
    search: &mut LocalSearch,
    p: &Problem,
    tour: &mut [usize],
    family: u8,
    max_len: usize,
    at: &mut FamilyAt,
    changed: &mut bool,
    pause: &dyn Fn() -> bool,
) -> bool {
    let (better, finished) = match family {
        0 => search.two_opt_until(p, tour, pause),
        1 => search.or_opt_until(p, tour, pause),
        2 => search.reinsert_until(p, tour, &mut at.reinsert, pause),
        _ => search.block_reverse_until(p, tour, max_len, pause),
    };
    *changed |= better;
    if finished {
        *at = FamilyAt::default();
    } else {
        at.partial = true;
    }
    finished
}

/// An iteration under way ([`AlnsSolver::iterate_unit`]): its operators, its candidate and
/// the candidate's cost, and where its local search is (`None`: not gated, or done).
#[derive(Clone, Debug)]
struct Iteration {
    removal: usize,
    insertion: usize,
    candidate: Vec<usize>,
    cost: f64,
    improve: Option<Improve>,
}

/// Where an iteration's local search ([`AlnsSolver::improve`] in units) is: the next unit
/// (0 the node-choice DP it starts with, 1 2-opt, 2 or-opt, 3 reinsertion, 4 block reversal
/// when the round changed nothing, 5 the node-choice DP after the round) and whether the
/// round's moves changed the tour.
#[derive(Clone, Copy, Debug)]
struct Improve {
    deep_below: f64,
    unit: u8,
    changed: bool,
    /// Where the unit's move family paused.
    family: FamilyAt,
}

/// How the first tour is built: cheapest insertion, without noise.
const FIRST_INSERTION: Insertion = Insertion {
    selection: Selection::Cheapest,
    noisy: false,
};

/// Anytime ALNS for PCGTSP / GTSP that can be advanced in slices (see [`AlnsSolver::step`]).
///
/// The search trajectory depends only on the seed and the number of iterations: time only
/// decides where it stops, so the same seed and iteration limit always give the same tour (a
/// limit that comes before the first tour is whole also makes its rest go in the quick way,
/// [`AlnsSolver::hurry_first_tour`]).
#[derive(Clone, Debug)]
pub struct AlnsSolver {
    problem: Problem,
    options: AlnsOptions,
    rng: Rng,
    operators: Operators,
    local_search: LocalSearch,
    node_choice: NodeChoice,
    removal: Adaptive<5>,
    insertion: Adaptive<8>,
    current: Vec<usize>,
    current_cost: f64,
    candidate: Vec<usize>,
    best: Vec<usize>,
    best_cost: f64,
    /// The best tour of the current epoch (where its annealing got to).
    epoch_best: Vec<usize>,
    epoch_best_cost: f64,
    /// Whether the current epoch found a new global best.
    epoch_improved: bool,
    /// The best distinct epoch results, cheapest first: restart points after a stagnant epoch.
    elite: Vec<(Vec<usize>, f64)>,
    started: bool,
    /// The first tour under way (cheapest insertion a cluster per [`AlnsSolver::step`] unit,
    /// finished before any limit is checked, as when it was one piece: the search always has
    /// a tour once started; past the limit its rest is inserted cheaply, see `hurry`).
    first: Option<Vec<usize>>,
    /// The rest of the first tour is inserted cheaply ([`AlnsSolver::hurry_first_tour`]): the
    /// limit came before the tour, and a tour is still owed.
    hurry: bool,
    /// The first tour's descent under way, a move family per [`AlnsSolver::step`] unit (on
    /// thousands of clusters it takes seconds: one piece would block Stop that long).
    descent: Option<Descent>,
    /// The iteration under way, a destroy–repair or a move family per
    /// [`AlnsSolver::step`] unit (on thousands of nodes one iteration's local search took
    /// 0.4–0.6 s: one piece would block Stop that long).
    iteration: Option<Iteration>,
    /// A tour offered from outside ([`AlnsSolver::offer_tour`]), cheaper than the best: the
    /// search goes on from it at the next unit that starts afresh.
    offered: Option<(Vec<usize>, f64)>,
    stop: Option<StopReason>,
    iterations: u64,
    improvements: u64,
    restarts: u64,
    epoch_iteration: u64,
    epoch_length: u64,
    elapsed: Duration,
}

/// An [`AlnsSolver`] being prepared in slices ([`AlnsSolver::builder`]).
#[derive(Clone, Debug)]
pub struct AlnsBuilder {
    build: ProblemBuild,
    options: AlnsOptions,
}

impl AlnsBuilder {
    /// Prepares for about `budget` (a piece at least: a few matrix rows or one pivot of the
    /// closure); `Some(solver)` once ready, the solver [`AlnsSolver::new`] makes. Pass the
    /// instance given to [`AlnsSolver::builder`] on every call.
    pub fn advance(
        &mut self,
        instance: &Instance,
        budget: Duration,
    ) -> Result<Option<AlnsSolver>, AlnsError> {
        let started = Instant::now();
        let problem = self
            .build
            .advance(instance, &|| started.elapsed() >= budget)?;
        Ok(problem.map(|problem| AlnsSolver::from_problem(problem, self.options.clone())))
    }
}

impl AlnsSolver {
    /// Prepares a solver (validates the instance and closes its precedence relation); no search
    /// happens until [`AlnsSolver::step`].
    pub fn new(instance: &Instance, options: AlnsOptions) -> Result<Self, AlnsError> {
        let mut builder = AlnsSolver::builder(instance, options)?;
        loop {
            if let Some(solver) = builder.advance(instance, Duration::MAX)? {
                return Ok(solver);
            }
        }
    }

    /// [`AlnsSolver::new`] in slices: checks the instance's shape now, and
    /// [`AlnsBuilder::advance`] does the rest (the cost matrix and the precedence closure,
    /// seconds on a discretisation of thousands of nodes) a piece at a time.
    pub fn builder(instance: &Instance, options: AlnsOptions) -> Result<AlnsBuilder, AlnsError> {
        Ok(AlnsBuilder {
            build: ProblemBuild::new(instance)?,
            options,
        })
    }

    fn from_problem(problem: Problem, options: AlnsOptions) -> Self {
        let epoch_length = options.parameters.epoch_iterations.max(1);
        AlnsSolver {
            rng: Rng::new(options.seed),
            problem,
            options,
            operators: Operators::default(),
            local_search: LocalSearch::default(),
            node_choice: NodeChoice::default(),
            removal: Adaptive::new(),
            insertion: Adaptive::new(),
            current: Vec::new(),
            current_cost: f64::INFINITY,
            candidate: Vec::new(),
            best: Vec::new(),
            best_cost: f64::INFINITY,
            epoch_best: Vec::new(),
            epoch_best_cost: f64::INFINITY,
            epoch_improved: false,
            elite: Vec::new(),
            started: false,
            first: None,
            hurry: false,
            descent: None,
            iteration: None,
            offered: None,
            stop: None,
            iterations: 0,
            improvements: 0,
            restarts: 0,
            epoch_iteration: 0,
            epoch_length,
            elapsed: Duration::ZERO,
        }
    }

    /// Searches for about `budget` of time (at least one unit of work — a piece of the first
    /// descent or of an iteration — unless already finished) and reports whether the search
    /// can go on: once a stop condition holds, [`Status::Stopped`] for the time limit and
    /// [`AlnsSolver::cancel`], else [`Status::Finished`] (proven optimal only when the instance
    /// is too small to search).
    pub fn step(&mut self, budget: Duration) -> Status {
        self.step_with(budget, &mut |_| {})
    }

    /// Like [`AlnsSolver::step`], calling `on_improvement` after every new best tour.
    pub fn step_with(
        &mut self,
        budget: Duration,
        on_improvement: &mut dyn FnMut(&AlnsProgress),
    ) -> Status {
        let slice_start = Instant::now();
        let base = self.elapsed;
        // A move family pauses at the slice's end (and goes on in the next unit).
        let slice_end = slice_start.checked_add(budget);
        let pause = || slice_end.is_some_and(|end| Instant::now() >= end);
        loop {
            // An iteration or the first tour under way is finished first (as when it was one
            // piece), unless the search was cancelled: the limits are checked between them.
            if (self.iteration.is_none() && self.first.is_none()) || self.stop.is_some() {
                if let Some(reason) = self.stop_reason() {
                    self.stop = Some(reason);
                    return stopped_status(reason);
                }
            }
            let improved = if !self.started {
                self.start()
            } else if self.iteration.is_none() && self.first.is_none() && self.offered.is_some() {
                self.take_offered()
            } else if let Some(tour) = self.first.take() {
                if self
                    .options
                    .time_limit
                    .is_some_and(|limit| self.elapsed >= limit)
                {
                    self.hurry = true;
                }
                self.build_first(tour)
            } else if let Some(descent) = self.descent.take() {
                self.descend(descent, &pause)
            } else {
                self.iterate_unit(base + slice_start.elapsed(), &pause)
            };
            self.elapsed = base + slice_start.elapsed();
            if improved && self.best().is_some() {
                self.improvements += 1;
                on_improvement(&self.progress());
            }
            if slice_start.elapsed() >= budget {
                if self.iteration.is_some() || self.first.is_some() {
                    return Status::Running;
                }
                if let Some(reason) = self.stop_reason() {
                    self.stop = Some(reason);
                    return stopped_status(reason);
                }
                return Status::Running;
            }
        }
    }

    /// Finishes a first tour under way quickly: each remaining cluster is inserted at its
    /// cheapest feasible place in the tour as it is then, in units of one cluster, instead of
    /// the cheapest insertion that weighs every remaining cluster's best place before each
    /// one. For a caller whose limit came before the first tour (a job whose model took the
    /// time: the cheapest insertion of 460 clusters in 12,000 nodes took 0.7–2 s more); the
    /// solver does it itself when its own time limit passes during that tour. The tour is worse
    /// than the cheapest insertion's but checked the same, and the search stops after it at
    /// the limit. No effect once the first tour is complete.
    pub fn hurry_first_tour(&mut self) {
        if self.first.is_some() || !self.started {
            self.hurry = true;
        }
    }

    /// Offers a tour found elsewhere (nodes, depot first, every cluster once in an order the
    /// precedence allows, no forbidden arc), e.g. another solver's route on the same
    /// instance. When it is cheaper than the best it becomes the best at once, and the search
    /// goes on from it (its local descent first) at its next unit of work. Returns whether it
    /// was taken.
    pub fn offer_tour(&mut self, tour: &[usize]) -> bool {
        let p = &self.problem;
        if tour.len() != p.m
            || tour.iter().any(|&v| v >= p.n)
            || !p.order_is_valid(tour)
            || !p.uses_no_forbidden_arc(tour)
        {
            return false;
        }
        let cost: f64 = tour.windows(2).map(|w| p.d(w[0], w[1])).sum::<f64>()
            + p.d(tour[tour.len() - 1], tour[0]);
        // (A NaN cost is refused too.)
        if cost.is_nan() || cost >= self.best_cost - eps(p) {
            return false;
        }
        self.best = tour.to_vec();
        self.best_cost = cost;
        self.offered = Some((tour.to_vec(), cost));
        true
    }

    /// The offered tour as current, epoch best and best (unless the search found a cheaper
    /// one since), and its descent next. Returns whether the best improved.
    fn take_offered(&mut self) -> bool {
        let Some((tour, cost)) = self.offered.take() else {
            return false;
        };
        if cost > self.best_cost {
            return false;
        }
        self.publish_first(tour, cost);
        self.descent = Some(Descent::default());
        true
    }

    /// Stops the search: later calls to `step` return [`Status::Stopped`] at once.
    pub fn cancel(&mut self) {
        if self.stop.is_none() {
            self.stop = Some(StopReason::Cancelled);
        }
    }

    /// The best tour found (nodes, depot first; the closing arc back to the first node is
    /// implied) and its cost. `None` until a tour without forbidden arcs is found.
    pub fn best(&self) -> Option<(&[usize], f64)> {
        if self.best.is_empty() || !self.problem.uses_no_forbidden_arc(&self.best) {
            return None;
        }
        Some((&self.best, self.best_cost))
    }

    /// Counters of the search so far.
    pub fn progress(&self) -> AlnsProgress {
        AlnsProgress {
            elapsed: self.elapsed,
            best_cost: self.best().map(|(_, c)| c),
            current_cost: self.current_cost.is_finite().then_some(self.current_cost),
            iterations: self.iterations,
            improvements: self.improvements,
            restarts: self.restarts,
            stop_reason: self.stop,
        }
    }

    fn stop_reason(&self) -> Option<StopReason> {
        if self.stop.is_some() {
            return self.stop;
        }
        if self.started {
            if let (Some(target), Some((_, cost))) = (self.options.target_cost, self.best()) {
                if cost <= target + eps(&self.problem) {
                    return Some(StopReason::TargetReached);
                }
            }
            if self.problem.m <= 2 && self.best().is_some() {
                return Some(StopReason::Exhausted);
            }
        }
        if let Some(limit) = self.options.time_limit {
            if self.elapsed >= limit && self.started {
                return Some(StopReason::TimeLimit);
            }
        }
        if let Some(limit) = self.options.max_iterations {
            if self.iterations >= limit && self.started {
                return Some(StopReason::IterationLimit);
            }
        }
        None
    }

    /// Starts the first tour: cheapest insertion from the depot, a cluster per unit
    /// ([`AlnsSolver::build_first`]), then its descent ([`AlnsSolver::descend`], the same
    /// moves as [`AlnsSolver::improve`] with no depth gate). The tour is the best from its
    /// node-choice DP on: every unit of the descent keeps it valid. A tiny instance is solved
    /// here instead, by trying every order ([`crate::exhaustive`]).
    fn start(&mut self) -> bool {
        self.started = true;
        if let Some((tour, cost)) = crate::exhaustive::optimal_tour(
            &self.problem,
            &mut self.node_choice,
            self.options.parameters.exhaustive_up_to,
        ) {
            // Every order was tried: the search has nothing left to find.
            self.publish_first(tour, cost);
            self.stop = Some(StopReason::Exhausted);
            return true;
        }
        let p = &self.problem;
        let mut tour = Vec::with_capacity(p.m);
        self.operators.destroy_all(p, &mut tour);
        self.operators
            .begin_repair(p, &tour, FIRST_INSERTION, 0.0, &mut self.rng);
        self.first = Some(tour);
        false
    }

    /// One unit of the first tour's cheapest insertion: the next cluster inserted, or (when
    /// all are) its node-choice DP, after which the tour is the best and its descent starts
    /// ([`AlnsSolver::descend`]). Returns whether the best improved.
    fn build_first(&mut self, mut tour: Vec<usize>) -> bool {
        let p = &self.problem;
        let inserted = if self.hurry {
            self.operators
                .insert_one_quickly(p, &mut tour, &mut self.rng)
        } else {
            self.operators
                .insert_one(p, &mut tour, FIRST_INSERTION, 0.0, &mut self.rng)
        };
        if inserted {
            self.first = Some(tour);
            return false;
        }
        let cost = self.node_choice.optimise(p, &mut tour);
        self.publish_first(tour, cost);
        self.descent = Some(Descent::default());
        true
    }

    /// The first tour (or its descent so far) as current, epoch best and best.
    fn publish_first(&mut self, tour: Vec<usize>, cost: f64) {
        self.current.clone_from(&tour);
        self.current_cost = cost;
        self.epoch_best.clone_from(&tour);
        self.epoch_best_cost = cost;
        // (An offered tour may be the best already.)
        if cost <= self.best_cost || self.best.is_empty() {
            self.best = tour;
            self.best_cost = cost;
        }
    }

    /// One unit of the first tour's descent: one move family over the tour, or the
    /// node-choice DP after a round that changed it. The units run the loop of
    /// [`AlnsSolver::improve`] (with `deep_below` infinite) in the same order, so the tour it
    /// ends with does not depend on how the units fall into slices; a time limit ends it
    /// between units as it ended `improve` between rounds. Returns whether the best improved.
    fn descend(&mut self, mut descent: Descent, pause: &dyn Fn() -> bool) -> bool {
        let p = &self.problem;
        let mut tour = std::mem::take(&mut self.current);
        let mut improved = false;
        let max_len = self.options.parameters.block_reverse_length;
        match descent.unit {
            0..=3 => {
                if descent.unit == 0 && !descent.family.partial {
                    descent.changed = false;
                }
                // Block reversal (unit 3) only after a round that changed nothing (or to
                // finish it).
                if descent.unit < 3 || !descent.changed || descent.family.partial {
                    let finished = run_family(
                        &mut self.local_search,
                        p,
                        &mut tour,
                        descent.unit,
                        max_len,
                        &mut descent.family,
                        &mut descent.changed,
                        pause,
                    );
                    if !finished {
                        self.current = tour;
                        self.descent = Some(descent);
                        return false;
                    }
                    if descent.unit == 3 && !descent.changed {
                        // A local optimum: the descent is over.
                        debug_assert!(p.order_is_valid(&tour));
                        self.current = tour;
                        return false;
                    }
                }
            }
            _ => {
                let cost = self.node_choice.optimise(p, &mut tour);
                improved = cost < self.best_cost;
                self.publish_first(tour, cost);
                descent = Descent::default();
                self.descent = Some(descent);
                return improved;
            }
        }
        self.current = tour;
        descent.unit += 1;
        self.descent = Some(descent);
        improved
    }

    /// Node-choice DP followed by local search until nothing changes. The expensive block
    /// reversal only runs on tours that are about as good as the best (`deep_below`), where
    /// it is needed to escape "wrong direction of travel" local optima.
    ///
    /// The descent also ends at the time limit (checked after each round of moves; every
    /// round keeps the tour valid): on thousands of clusters the first descent alone took
    /// 25 s, so a 5 s limit gave no tour at all.
    fn improve(&mut self, tour: &mut [usize], deep_below: f64) -> f64 {
        let deadline = self
            .options
            .time_limit
            .map(|limit| Instant::now() + limit.saturating_sub(self.elapsed));
        let p = &self.problem;
        let max_len = self.options.parameters.block_reverse_length;
        let mut cost = self.node_choice.optimise(p, tour);
        // Every local-search move strictly improves and the DP never worsens, so this ends.
        loop {
            let mut changed = self.local_search.two_opt(p, tour);
            changed |= self.local_search.or_opt(p, tour);
            changed |= self.local_search.reinsert(p, tour);
            if !changed && (cost > deep_below || !self.local_search.block_reverse(p, tour, max_len))
            {
                break;
            }
            cost = self.node_choice.optimise(p, tour);
            if deadline.is_some_and(|d| Instant::now() >= d) {
                break;
            }
        }
        debug_assert!(p.order_is_valid(tour));
        cost
    }

    /// The temperature for the current point of the epoch (exponential cooling).
    fn temperature(&self) -> f64 {
        let params = &self.options.parameters;
        let reference = if self.best().is_some() {
            self.best_cost.abs()
        } else {
            self.problem.mean_arc * self.problem.m as f64
        }
        .max(self.problem.mean_arc);
        // Epochs cycle through hotter and cooler schedules: instances differ in which works,
        // and a portfolio is more robust than any single setting.
        let scale = params.temperature_cycle
            [(self.restarts as usize) % params.temperature_cycle.len().max(1)];
        let start = params.start_temperature * reference * scale;
        let end = (params.end_temperature * reference).min(start);
        let frac = self.epoch_iteration as f64 / self.epoch_length as f64;
        start * (end / start).powf_libm(frac.min(1.0))
    }

    /// One destroy–repair–improve–accept iteration in one piece; returns whether the best tour
    /// improved.
    #[cfg(test)]
    fn iterate(&mut self) -> bool {
        loop {
            let improved = self.iterate_unit(self.elapsed, &|| false);
            if self.iteration.is_none() {
                return improved;
            }
        }
    }

    /// One unit of an iteration: the destroy–repair and node-choice DP that make the
    /// candidate, one step of its local search (the loop of [`AlnsSolver::improve`], a move
    /// family or a node-choice DP per unit, in the same order, so the iteration's result does
    /// not depend on how its units fall into slices), or its acceptance. `elapsed` is the
    /// search's time so far: the local search ends at the time limit between rounds, as
    /// `improve` does. Returns whether the best tour improved.
    fn iterate_unit(&mut self, elapsed: Duration, pause: &dyn Fn() -> bool) -> bool {
        let Some(mut it) = self.iteration.take() else {
            self.begin_iteration();
            return false;
        };
        let Some(mut at) = it.improve else {
            return self.accept(it);
        };
        let p = &self.problem;
        let max_len = self.options.parameters.block_reverse_length;
        match at.unit {
            0 => it.cost = self.node_choice.optimise(p, &mut it.candidate),
            1..=3 => {
                if at.unit == 1 && !at.family.partial {
                    at.changed = false;
                }
                let finished = run_family(
                    &mut self.local_search,
                    p,
                    &mut it.candidate,
                    at.unit - 1,
                    max_len,
                    &mut at.family,
                    &mut at.changed,
                    pause,
                );
                if !finished {
                    it.improve = Some(at);
                    self.iteration = Some(it);
                    return false;
                }
            }
            4 => {
                // Block reversal only after a round that changed nothing and on a candidate
                // about as good as the best (or to finish it).
                if !at.changed || at.family.partial {
                    let gated = !at.family.partial && it.cost > at.deep_below;
                    if !gated {
                        let finished = run_family(
                            &mut self.local_search,
                            p,
                            &mut it.candidate,
                            3,
                            max_len,
                            &mut at.family,
                            &mut at.changed,
                            pause,
                        );
                        if !finished {
                            it.improve = Some(at);
                            self.iteration = Some(it);
                            return false;
                        }
                    }
                    if !at.changed {
                        debug_assert!(p.order_is_valid(&it.candidate));
                        it.improve = None;
                        self.iteration = Some(it);
                        return false;
                    }
                }
            }
            _ => {
                it.cost = self.node_choice.optimise(p, &mut it.candidate);
                if self
                    .options
                    .time_limit
                    .is_some_and(|limit| elapsed >= limit)
                {
                    it.improve = None;
                    self.iteration = Some(it);
                    return false;
                }
                at.unit = 0;
                at.changed = false;
            }
        }
        at.unit += 1;
        it.improve = Some(at);
        self.iteration = Some(it);
        false
    }

    /// The destroy–repair of an iteration and its node-choice DP; its local search follows
    /// when the candidate passes the gate.
    fn begin_iteration(&mut self) {
        self.iterations += 1;
        let params = self.options.parameters.clone();
        let p = &self.problem;
        let m = p.m;
        let removal = self.removal.pick(&mut self.rng);
        let insertion = self.insertion.pick(&mut self.rng);
        let movable = m - 1;
        let max_remove = ((params.max_removal_fraction * movable as f64).round() as usize)
            .clamp(1, params.max_removal.max(1))
            .min(movable);
        let min_remove = params.min_removal.clamp(1, max_remove);
        let count = self.rng.between(min_remove, max_remove);

        self.candidate.clone_from(&self.current);
        let mut candidate = std::mem::take(&mut self.candidate);
        if REMOVALS[removal] == Removal::Reverse && m >= 4 {
            let i = self.rng.between(1, m - 2);
            let last = (m - 1).min(i + params.block_reverse_length);
            let j = self.rng.between(i + 1, last);
            self.local_search.reverse_repaired(p, &mut candidate, i, j);
        }
        self.operators
            .destroy(p, &mut candidate, REMOVALS[removal], count, &mut self.rng);
        let arc_scale = if self.current_cost < p.penalty {
            (self.current_cost / m as f64).abs().max(p.mean_arc * 1e-3)
        } else {
            p.mean_arc
        };
        self.operators.repair(
            p,
            &mut candidate,
            INSERTIONS[insertion],
            params.noise * arc_scale,
            &mut self.rng,
        );
        let cost = self.node_choice.optimise(p, &mut candidate);
        let gate = self.current_cost + params.local_search_gate * self.current_cost.abs();
        let improve = (cost < gate || cost < self.best_cost).then(|| Improve {
            deep_below: self.best_cost + params.block_reverse_gate * self.best_cost.abs(),
            unit: 0,
            changed: false,
            family: FamilyAt::default(),
        });
        self.iteration = Some(Iteration {
            removal,
            insertion,
            candidate,
            cost,
            improve,
        });
    }

    /// The acceptance of an iteration's candidate (annealing), the operators' scores and the
    /// epoch's end; returns whether the best tour improved.
    fn accept(&mut self, it: Iteration) -> bool {
        let params = self.options.parameters.clone();
        let Iteration {
            removal,
            insertion,
            mut candidate,
            cost,
            ..
        } = it;
        let eps = eps(&self.problem);
        let delta = cost - self.current_cost;
        let temperature = self.temperature();
        let accepted = delta <= 0.0
            || (temperature > 0.0 && self.rng.unit() < (-delta / temperature).exp_libm());
        let mut score = 0.0;
        let mut new_best = false;
        if cost < self.best_cost - eps {
            score = params.score_new_best;
            new_best = true;
            self.epoch_improved = true;
            self.best.clone_from(&candidate);
            self.best_cost = cost;
        } else if delta < -eps {
            score = params.score_better;
        } else if accepted && delta > eps {
            score = params.score_accepted;
        }
        self.removal.score[removal] += score;
        self.insertion.score[insertion] += score;
        if accepted {
            if cost < self.epoch_best_cost - eps {
                self.epoch_best.clone_from(&candidate);
                self.epoch_best_cost = cost;
            }
            std::mem::swap(&mut self.current, &mut candidate);
            self.current_cost = cost;
        }
        self.candidate = candidate;

        if self
            .iterations
            .is_multiple_of(params.segment_iterations.max(1))
        {
            self.removal.end_segment(params.reaction);
            self.insertion.end_segment(params.reaction);
        }
        self.epoch_iteration += 1;
        if self.epoch_iteration >= self.epoch_length {
            self.restart();
        }
        new_best
    }

    /// Ends an epoch: reheats, cools more slowly next time, and picks the next start. After
    /// an epoch that improved the best tour the search continues from it; after a stagnant
    /// one, going back to the best would only repeat the same basin, so it starts from a kicked
    /// copy (a large random destroy, random re-insertion, local search) of a random elite tour.
    fn restart(&mut self) {
        let params = self.options.parameters.clone();
        self.restarts += 1;
        self.epoch_iteration = 0;
        self.epoch_length = ((self.epoch_length as f64) * params.epoch_growth)
            .min(params.max_epoch_iterations as f64)
            .max(1.0) as u64;
        self.remember_elite(params.elite_size);
        let movable = self.problem.m - 1;
        let kick = ((params.kick_fraction * movable as f64).round() as usize).min(movable);
        if self.epoch_improved || self.elite.is_empty() || kick == 0 {
            self.current.clone_from(&self.best);
            self.current_cost = self.best_cost;
        } else {
            let pick = self.rng.below(self.elite.len());
            let mut tour = self.elite[pick].0.clone();
            let p = &self.problem;
            let removal = if self.rng.unit() < 0.5 {
                Removal::Random
            } else {
                Removal::Segment
            };
            self.operators
                .destroy(p, &mut tour, removal, kick, &mut self.rng);
            let how = Insertion {
                selection: Selection::Random,
                noisy: false,
            };
            self.operators.repair(p, &mut tour, how, 0.0, &mut self.rng);
            let deep_below = self.best_cost + params.block_reverse_gate * self.best_cost.abs();
            let cost = self.improve(&mut tour, deep_below);
            if cost < self.best_cost - eps(&self.problem) {
                self.best.clone_from(&tour);
                self.best_cost = cost;
            }
            self.current = tour;
            self.current_cost = cost;
        }
        self.epoch_best.clone_from(&self.current);
        self.epoch_best_cost = self.current_cost;
        self.epoch_improved = false;
    }

    /// Adds the epoch's best tour to the elite unless one of the same cost is there already,
    /// keeping the `size` cheapest.
    fn remember_elite(&mut self, size: usize) {
        let eps = eps(&self.problem);
        let cost = self.epoch_best_cost;
        if size == 0 || !cost.is_finite() || self.elite.iter().any(|(_, c)| (c - cost).abs() <= eps)
        {
            return;
        }
        let at = self.elite.partition_point(|(_, c)| *c < cost);
        if at < size {
            self.elite.insert(at, (self.epoch_best.clone(), cost));
            self.elite.truncate(size);
        }
    }
}

/// The status a stop condition gives.
fn stopped_status(reason: StopReason) -> Status {
    match reason {
        StopReason::TimeLimit | StopReason::Cancelled => Status::Stopped,
        StopReason::IterationLimit | StopReason::TargetReached => Status::Finished {
            proven_optimal: false,
        },
        StopReason::Exhausted => Status::Finished {
            proven_optimal: true,
        },
    }
}

/// The contract of every solver: the best tour (nodes, depot first) and its cost; no lower
/// bound.
impl AnytimeSolver for AlnsSolver {
    type Solution = Vec<usize>;

    fn step(&mut self, budget: Duration) -> Status {
        AlnsSolver::step(self, budget)
    }

    fn best(&self) -> Option<Vec<usize>> {
        AlnsSolver::best(self).map(|(tour, _)| tour.to_vec())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            upper: AlnsSolver::best(self).map(|(_, cost)| cost),
            lower: None,
            unit: CostUnit::TourCost,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_pcgtsp::check_tour;

    fn instance(set: &str, name: &str) -> Instance {
        crate::reference_instance(set, name)
    }

    /// The first descent runs a move family per unit: stepped with no budget (one unit per
    /// call) it ends with the very tour of one long step, every tour it shows on the way is
    /// feasible and costs what the solver says, and the costs never rise.
    #[test]
    fn the_first_descent_in_units_equals_one_piece() {
        for (set, name) in [("pcgtsplib", "ry48p.1"), ("industrial", "e1x_2")] {
            let instance = instance(set, name);
            let options = AlnsOptions {
                seed: 5,
                time_limit: None,
                max_iterations: Some(1),
                ..AlnsOptions::default()
            };
            let mut whole = AlnsSolver::new(&instance, options.clone()).unwrap();
            whole.step(Duration::from_secs(3600));
            let mut units = AlnsSolver::new(&instance, options).unwrap();
            // The first tour's insertion: a cluster per unit, no tour before it is whole.
            let mut insertions = 0;
            while units.first.is_some() || !units.started {
                assert!(units.best().is_none(), "{name}: a tour before the first");
                units.step(Duration::ZERO);
                insertions += 1;
            }
            // The start, a unit per cluster but the depot's, and the node-choice DP.
            let expected = 1 + (instance.clusters.len() - 1) + 1;
            assert_eq!(insertions, expected, "{name}: a unit per cluster");
            let mut calls = 0;
            let mut last = f64::INFINITY;
            while units.descent.is_some() {
                let (tour, cost) = units.best().expect("a tour from the insertion's end");
                let checked = check_tour(&instance, tour).unwrap();
                assert!(
                    (checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()),
                    "{name}"
                );
                units.step(Duration::ZERO);
                calls += 1;
                let (tour, cost) = units.best().expect("a tour from the first unit");
                let checked = check_tour(&instance, tour).unwrap();
                assert!(
                    (checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()),
                    "{name}"
                );
                assert!(cost <= last + 1e-9, "{name}: {cost} after {last}");
                last = cost;
            }
            assert!(calls > 5, "{name}: {calls} units");
            assert_eq!(units.current, whole_first_tour(&instance, 5), "{name}");
            assert!(whole.best_cost <= last + 1e-9);
        }
    }

    /// A limit that comes before the first tour is whole (none at all, or the caller's
    /// `hurry_first_tour` half-way through) still gives a tour: its rest is inserted a cluster
    /// per unit at its cheapest feasible place, the tour passes the independent checker at the
    /// cost the solver reports, and the search stops at the limit right after it.
    #[test]
    fn a_limit_before_the_first_tour_still_gives_a_checked_tour() {
        for (set, name) in [("pcgtsplib", "ry48p.1"), ("industrial", "e1x_2")] {
            let instance = instance(set, name);
            let clusters = instance.clusters.len();
            // Its own limit passed at once: every cluster goes in the quick way.
            let mut solver = AlnsSolver::new(
                &instance,
                AlnsOptions {
                    seed: 7,
                    time_limit: Some(Duration::ZERO),
                    ..AlnsOptions::default()
                },
            )
            .unwrap();
            let mut units = 1;
            while solver.step(Duration::ZERO) == Status::Running {
                units += 1;
            }
            assert!(solver.hurry, "{name}");
            // The start, a unit per cluster but the depot's, and the node-choice DP.
            assert_eq!(units, 1 + (clusters - 1) + 1, "{name}: a unit per cluster");
            assert_eq!(solver.progress().stop_reason, Some(StopReason::TimeLimit));
            let (tour, cost) = solver.best().expect("a tour at the limit");
            let checked = check_tour(&instance, tour).unwrap();
            assert!(
                (checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()),
                "{name}"
            );

            // The caller hurries half-way through the cheapest insertion.
            let options = AlnsOptions {
                seed: 7,
                time_limit: None,
                max_iterations: Some(0),
                ..AlnsOptions::default()
            };
            let mut solver = AlnsSolver::new(&instance, options).unwrap();
            for _ in 0..clusters / 2 {
                solver.step(Duration::ZERO);
            }
            assert!(solver.first.is_some() && solver.best().is_none(), "{name}");
            solver.hurry_first_tour();
            while solver.first.is_some() {
                solver.step(Duration::ZERO);
            }
            let (tour, cost) = solver.best().expect("a tour once hurried");
            let checked = check_tour(&instance, tour).unwrap();
            assert!(
                (checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()),
                "{name}"
            );
            // Once the tour is whole, hurrying changes nothing.
            let mut whole = AlnsSolver::new(
                &instance,
                AlnsOptions {
                    seed: 7,
                    time_limit: None,
                    max_iterations: Some(0),
                    ..AlnsOptions::default()
                },
            )
            .unwrap();
            while whole.first.is_some() || !whole.started {
                whole.step(Duration::ZERO);
            }
            whole.hurry_first_tour();
            assert!(!whole.hurry, "{name}");
        }
    }

    /// Iterations run in units (a destroy–repair, a move family, a node-choice DP, the
    /// acceptance): stepped with no budget (one unit per call) the search ends with the very
    /// tour, cost and counters of one long step, on a GTSP and a PCGTSP instance, and the
    /// iterations did take several units each.
    #[test]
    fn iterations_in_units_equal_one_piece() {
        for (set, name) in [("pcgtsplib", "ry48p.2"), ("industrial", "e1x_3")] {
            let instance = instance(set, name);
            let options = AlnsOptions {
                seed: 11,
                time_limit: None,
                max_iterations: Some(400),
                ..AlnsOptions::default()
            };
            let mut whole = AlnsSolver::new(&instance, options.clone()).unwrap();
            assert_eq!(
                whole.step(Duration::from_secs(3600)),
                Status::Finished {
                    proven_optimal: false
                }
            );
            let mut units = AlnsSolver::new(&instance, options).unwrap();
            let mut calls = 0u64;
            while units.step(Duration::ZERO) == Status::Running {
                calls += 1;
                if let Some((tour, cost)) = units.best() {
                    let checked = check_tour(&instance, tour).unwrap();
                    assert!((checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()));
                }
            }
            assert_eq!(units.iterations, 400, "{name}");
            assert!(
                calls > 2 * units.iterations,
                "{name}: {calls} calls for {} iterations",
                units.iterations
            );
            assert_eq!(units.best, whole.best, "{name}");
            assert_eq!(units.best_cost, whole.best_cost, "{name}");
            assert_eq!(units.current, whole.current, "{name}");
            assert_eq!(
                (units.improvements, units.restarts),
                (whole.improvements, whole.restarts),
                "{name}"
            );
        }
    }

    /// The first tour after the descent in one piece, by the unsliced `improve` loop.
    fn whole_first_tour(instance: &Instance, seed: u64) -> Vec<usize> {
        let mut solver = AlnsSolver::new(
            instance,
            AlnsOptions {
                seed,
                time_limit: None,
                ..AlnsOptions::default()
            },
        )
        .unwrap();
        solver.started = true;
        let p = &solver.problem;
        let mut tour = Vec::with_capacity(p.m);
        solver.operators.destroy_all(p, &mut tour);
        let how = Insertion {
            selection: Selection::Cheapest,
            noisy: false,
        };
        solver
            .operators
            .repair(p, &mut tour, how, 0.0, &mut solver.rng);
        solver.improve(&mut tour, f64::INFINITY);
        tour
    }

    /// A cheaper tour from outside becomes the best at once and the search goes on from it;
    /// a dearer or invalid one is refused.
    #[test]
    fn an_offered_tour_is_taken_when_cheaper_and_valid() {
        let instance = instance("pcgtsplib", "ry48p.1");
        let mut long = AlnsSolver::new(
            &instance,
            AlnsOptions {
                seed: 1,
                time_limit: None,
                max_iterations: Some(600),
                ..AlnsOptions::default()
            },
        )
        .unwrap();
        while long.step(Duration::from_secs(3600)).is_running() {}
        let (good, good_cost) = long.best().map(|(t, c)| (t.to_vec(), c)).unwrap();
        let mut short = AlnsSolver::new(
            &instance,
            AlnsOptions {
                seed: 2,
                time_limit: None,
                max_iterations: Some(3),
                ..AlnsOptions::default()
            },
        )
        .unwrap();
        short.step(Duration::ZERO);
        // A tour that visits a cluster twice, and one with the depot elsewhere.
        let mut twice = good.clone();
        twice[2] = twice[1];
        assert!(!short.offer_tour(&twice));
        let mut rotated = good.clone();
        rotated.rotate_left(1);
        assert!(!short.offer_tour(&rotated));
        let first_cost = short.best().map(|(_, c)| c);
        let taken = short.offer_tour(&good);
        assert_eq!(taken, first_cost.is_none_or(|c| good_cost < c));
        if taken {
            assert_eq!(short.best().unwrap().0, good.as_slice());
            // Offered again: no longer cheaper than the best.
            assert!(!short.offer_tour(&good));
        }
        while short.step(Duration::from_secs(3600)).is_running() {}
        let (tour, cost) = short.best().unwrap();
        assert!(cost <= good_cost + 1e-9);
        let checked = check_tour(&instance, tour).unwrap();
        assert!((checked - cost).abs() <= 1e-6 * checked.max(1.0));
    }

    /// After a stagnant epoch the next one starts from a kicked elite tour: feasible (checked
    /// independently), costing what the solver believes, usually different from the best
    /// tour, and the elite stays sorted, distinct and bounded.
    #[test]
    fn a_stagnant_epoch_restarts_from_a_feasible_kicked_elite_tour() {
        for (set, name) in [("pcgtsplib", "ry48p.1"), ("industrial", "e1x_2")] {
            let instance = instance(set, name);
            let mut options = AlnsOptions {
                seed: 3,
                time_limit: None,
                max_iterations: Some(300),
                ..AlnsOptions::default()
            };
            options.parameters.elite_size = 3;
            let mut solver = AlnsSolver::new(&instance, options).unwrap();
            while solver.step(Duration::from_millis(50)).is_running() {}
            let mut kicked = 0;
            for _ in 0..8 {
                let restarts = solver.restarts;
                solver.epoch_improved = false;
                solver.restart();
                assert_eq!(solver.restarts, restarts + 1);
                let cost = check_tour(&instance, &solver.current)
                    .unwrap_or_else(|e| panic!("{name}: kicked tour infeasible: {e}"));
                assert!((cost - solver.current_cost).abs() <= 1e-6 * (1.0 + cost.abs()));
                assert!(solver.current_cost >= solver.best_cost);
                if solver.current != solver.best {
                    kicked += 1;
                }
                assert!(solver.elite.len() <= 3);
                assert!(solver.elite.windows(2).all(|w| w[0].1 < w[1].1));
                for (tour, cost) in &solver.elite {
                    let checked = check_tour(&instance, tour).unwrap();
                    assert!((checked - cost).abs() <= 1e-6 * (1.0 + cost.abs()));
                }
                // Anneal the kicked tour for a while, as an epoch would.
                for _ in 0..30 {
                    solver.iterate();
                }
            }
            // On e1x_2 (29 clusters) the local search often leads a kicked tour back to the
            // best one; ry48p.1's landscape is rugged enough that it must not.
            if name == "ry48p.1" {
                assert!(
                    kicked >= 6,
                    "{name}: only {kicked} of 8 restarts left the best tour"
                );
            }
            // After an improving epoch the search goes back to the best tour.
            solver.epoch_improved = true;
            solver.restart();
            assert_eq!(solver.current, solver.best);
        }
    }
}
