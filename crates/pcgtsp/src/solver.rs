//! The exact solver: an anytime, resumable driver around the DP over order ideals.

use cutroute_anytime::{AnytimeSolver, Bounds, CostUnit, Status};

use crate::bounds::completion::{PositionAscent, PositionBound, PositionBoundOptions};
use crate::bounds::lagrange::{ArborescenceAscent, NodePenalties, PenaltyAscent, PenaltyOptions};
use crate::bounds::lattice::LatticeStore;
use crate::bounds::residual::ResidualBounder;
use crate::bounds::subset::SubsetBound;
use crate::check::check_tour;
use crate::dp::{Dp, DpStatus, Incumbent};
use crate::heuristic;
use crate::instance::Instance;
use crate::keys::{on_keyed, ByWidth, Keyed};
use crate::model::{Model, ModelBuilder};
use crate::order::{OrderError, PrecedenceOrder};
use crate::prepare::{LatticeLimits, Preparation, STRONG_SUBSET_SHARE};
use std::rc::Rc;
use std::time::Duration;
use web_time::Instant;

const INF: f64 = f64::INFINITY;
/// Work (arc relaxations, about a second) after which the position bound's subgradient stops
/// if it is still clearly below the other root bounds (ft53.*, kro124p.*: 12 s otherwise).
const POSITION_PROBE_WORK: f64 = 1e9;

/// Settings of the exact solver.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactOptions {
    /// Stop after this much time (measured from the first `step`); `None` = no limit.
    pub time_limit: Option<Duration>,
    /// Approximate memory the DP may use. When reached, the worst-bounded states are dropped
    /// (the lower bound stays valid; optimality is then no longer proven).
    pub memory_limit_bytes: usize,
    /// Also compute the L2 bound (assignment on the two-step graph H2).
    pub use_l2: bool,
    /// Run the beam-search + local-search heuristic first for an initial upper bound.
    pub heuristic: bool,
    /// Beam widths tried by the heuristic, in order.
    pub beam_widths: Vec<usize>,
    /// Stop as soon as `(UB − LB) / UB` is at most this (0 = prove optimality).
    pub gap_tolerance: f64,
    /// Build the ideal lattice with the pierce-group DP bound when the precedence order has at
    /// most this many ideals (0 disables it; the assignment bounds are used instead). Short
    /// time limits lower it further (60 000 ideals per second of the limit).
    pub lattice_max_ideals: usize,
    /// Work budget (elementary steps) of the lattice bound's backward pass; it sets how many
    /// pierce groups per cluster the bound keeps (more = tighter and slower). 0 = automatic:
    /// 40 million steps per second of the time limit, clamped to 0.3–4 billion.
    pub lattice_work: usize,
    /// Subgradient iterations of the node penalties (a Lagrangian strengthening of the
    /// assignment bounds, see `lagrange.rs`; the arborescence bound gets 4× as many); 0
    /// disables both. Used only when the lattice bound is not built.
    pub penalty_iterations: usize,
    /// Seconds the automatic work budgets (lattice, subset and penalty bounds) are sized for;
    /// `None` = `time_limit`. Set it when the run is stopped by another clock (e.g. CPU time)
    /// and `time_limit` is only a backstop.
    pub budget_seconds: Option<f64>,
    /// Subgradient iterations of the position-indexed completion bound (`completion.rs`, a
    /// per-state bound that sees precedence); 0 disables it. Used only when the lattice bound
    /// is not built.
    pub position_iterations: usize,
}

impl ExactOptions {
    /// The seconds the automatic budgets scale with (`budget_seconds`, else `time_limit`).
    fn budget_seconds_or(&self, unlimited: f64) -> f64 {
        self.budget_seconds
            .or(self.time_limit.map(|t| t.as_secs_f64()))
            .unwrap_or(unlimited)
    }

    /// The lattice size cap after scaling with the time limit: a failed build (too many
    /// ideals) costs about a second per million ideals, so short runs try smaller lattices.
    fn effective_lattice_max_ideals(&self) -> usize {
        let seconds = self.budget_seconds_or(f64::INFINITY);
        self.lattice_max_ideals
            .min((seconds * 60_000.0).max(100_000.0) as usize)
    }

    /// Work budget (elementary steps) of the subset DP bound's backward pass.
    /// 4·10⁸ steps (a fraction of a second), less under short time limits.
    fn effective_subset_work(&self) -> f64 {
        let seconds = self.budget_seconds_or(f64::INFINITY);
        (seconds * 4e7).clamp(2e7, 4e8)
    }

    /// Work budget (elementary steps) of the node penalties' subgradient optimisation:
    /// 2·10⁷ steps per second of the time limit, at most 10⁹ (about a second).
    fn effective_penalty_work(&self) -> f64 {
        let seconds = self.budget_seconds_or(f64::INFINITY);
        (seconds * 2e7).clamp(1e7, 1e9)
    }

    /// Work budget (arc relaxations) of the position bound's subgradient optimisation:
    /// 5·10⁷ steps per second of the time limit, 10⁸–3·10⁹ (up to a few seconds).
    fn effective_position_work(&self) -> f64 {
        let seconds = self.budget_seconds_or(f64::INFINITY);
        (seconds * 5e7).clamp(1e8, 3e9)
    }

    /// The lattice work budget after resolving the automatic setting.
    fn effective_lattice_work(&self) -> usize {
        if self.lattice_work > 0 {
            return self.lattice_work;
        }
        let seconds = self.budget_seconds_or(100.0);
        (seconds * 40e6).clamp(3e8, 4e9) as usize
    }
}

impl Default for ExactOptions {
    fn default() -> Self {
        ExactOptions {
            time_limit: Some(Duration::from_secs(60)),
            memory_limit_bytes: 3 << 29,
            use_l2: true,
            heuristic: true,
            beam_widths: vec![64, 1024, 8192],
            gap_tolerance: 0.0,
            lattice_max_ideals: 8_000_000,
            lattice_work: 0,
            penalty_iterations: 400,
            budget_seconds: None,
            position_iterations: 3000,
        }
    }
}

/// Why the solver could not be created.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The precedence pairs are not a partial order with the depot first.
    #[error(transparent)]
    Order(#[from] OrderError),
    /// The instance has more nodes than the DP's 16-bit node index can hold.
    #[error("{0} nodes: the exact solver handles at most 65535")]
    TooManyNodes(usize),
}

/// A snapshot of the solver's state.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactProgress {
    /// Time spent in `step` so far.
    pub elapsed: Duration,
    /// Cost of the best tour known (`INFINITY` if none).
    pub upper_bound: f64,
    /// Proven lower bound on the optimum.
    pub lower_bound: f64,
    /// `(UB − LB) / UB` (0 when proven, `INFINITY` without a tour).
    pub gap: f64,
    /// Current DP layer (clusters in the ideals being expanded).
    pub layer: usize,
    /// DP states alive in memory.
    pub live_states: usize,
    /// The best tour (0-based nodes, starting in the depot), if any.
    pub best_tour: Option<Vec<usize>>,
}

/// The final answer of [`solve`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExactResult {
    /// The final status.
    pub status: Status,
    /// The final progress snapshot (tour, bounds, time).
    pub progress: ExactProgress,
    /// DP states created over the whole run.
    pub states_created: u64,
    /// The root lower bound (max of L1 and L2 at the root).
    pub root_bound: f64,
}

impl ExactResult {
    /// Whether the returned tour is proven optimal.
    pub fn proven_optimal(&self) -> bool {
        matches!(
            self.status,
            Status::Finished {
                proven_optimal: true
            }
        )
    }
}

/// The DP at the key width of the run's model.
struct DpWidth;

impl ByWidth for DpWidth {
    type At<const W: usize> = Dp<W>;
}

/// The DP of one run; `None` inside when there are too many clusters for the DP keys: only
/// bounds and the heuristic.
struct Engine(Option<Keyed<DpWidth>>);

impl Engine {
    fn new(
        model: &Model,
        beam: Option<usize>,
        memory: usize,
        use_l2: bool,
        store: &LatticeStore,
    ) -> Engine {
        // The lattice bound gets at most half of the memory; the DP keeps the rest.
        let dp_memory = memory - memory / 2;
        Engine(store.0.as_ref().map(|lattice| {
            on_keyed!(lattice, |l, wrap| wrap(Dp::new(
                model,
                beam,
                dp_memory,
                use_l2,
                l.clone()
            )))
        }))
    }

    fn is_unsupported(&self) -> bool {
        self.0.is_none()
    }

    fn set_subset_bound(&mut self, model: &Model, subset: Rc<SubsetBound>) {
        if let Some(dp) = &mut self.0 {
            on_keyed!(dp, |dp| dp.set_subset_bound(model, subset))
        }
    }

    fn set_penalties(&mut self, model: &Model, penalties: Rc<NodePenalties>) {
        if let Some(dp) = &mut self.0 {
            on_keyed!(dp, |dp| dp.set_penalties(model, penalties))
        }
    }

    fn set_position_bound(&mut self, model: &Model, position: Rc<PositionBound>) {
        if let Some(dp) = &mut self.0 {
            on_keyed!(dp, |dp| dp.set_position_bound(model, position))
        }
    }

    fn run(&mut self, model: &Model, incumbent: &mut Incumbent, work: u64) -> DpStatus {
        match &mut self.0 {
            Some(dp) => on_keyed!(dp, |dp| dp.run(model, incumbent, work)),
            None => DpStatus::Done,
        }
    }

    /// (layer, live states, lower bound, dropped_min, states created)
    fn stats(&self, model: &Model, ub: f64) -> (usize, usize, f64, f64, u64) {
        match &self.0 {
            Some(dp) => on_keyed!(dp, |dp| (
                dp.layer,
                dp.live_states(),
                dp.lower_bound(model, ub),
                dp.dropped_min,
                dp.states_created,
            )),
            None => (0, 0, -INF, -INF, 0),
        }
    }
}

/// One start node of the depot cluster: the DP fixes the start, so a depot with several nodes
/// gives several runs, and the answer is the best over them.
struct Run {
    model: Model,
    /// Built lazily on the first `step`s, in slices (it can take a while on large orders).
    lattice: Option<LatticeStore>,
    /// The bounds being built (until `lattice` is set).
    preparation: Option<Preparation>,
    /// The subset DP bound, once built.
    subset: Option<Rc<SubsetBound>>,
    /// Node penalties for the per-state assignment bounds (when the run has no lattice).
    penalties: Option<Rc<NodePenalties>>,
    /// The position-indexed completion bound (when the run has no lattice).
    position: Option<Rc<PositionBound>>,
    /// The prepared lattice store while the Lagrangian bounds are still to be built: the node
    /// penalties take a step of their own, the arborescence bound's ascent slices of its own
    /// (together 0.4–1.1 s on ESC78, 0.7 s on seven.dbs's full-route model), the position
    /// bound the next step.
    prepared: Option<LatticeStore>,
    /// Whether the Lagrangian bounds of `prepared` are built (the arborescence bound's ascent
    /// then runs in `arborescence`, a slice per call, before the position bound).
    penalties_built: bool,
    /// The node penalties' ascent under way (`None` inside: an infeasible root), with the
    /// incumbent's cost and the arborescence bound's options.
    penalty_ascent: Option<(Option<PenaltyAscent>, f64, PenaltyOptions)>,
    arborescence: Option<ArborescenceAscent>,
    /// Whether the position bound was considered (after the Lagrangian bounds); its ascent
    /// then runs in `position_ascent`, slices of its own.
    position_checked: bool,
    position_ascent: Option<PositionAscent>,
    root_bound: f64,
    engine: Option<Engine>,
    finished_bound: Option<f64>,
    states_created: u64,
}

impl Run {
    /// Builds the bounds until `deadline`; sets `lattice` once they are complete. The
    /// preparation runs in slices; the Lagrangian bounds and then the position bound each take
    /// a call of their own after it (the caller calls again while `lattice` is unset).
    fn build_lattice(
        &mut self,
        instance: &Instance,
        options: &ExactOptions,
        tour: Option<&[usize]>,
        upper_bound: f64,
        deadline: Instant,
    ) {
        let began = Instant::now();
        let preparation = self.preparation.get_or_insert_with(|| {
            let limits = LatticeLimits {
                max_ideals: options.effective_lattice_max_ideals(),
                max_bytes: options.memory_limit_bytes / 2,
                work: options.effective_lattice_work(),
                min_group_share: 0.0,
            };
            Preparation::new(
                &self.model,
                tour,
                upper_bound,
                options.effective_subset_work(),
                limits,
            )
        });
        debug_log(|| format!("preparation made after {:?}", began.elapsed()));
        let Some(store) = self.prepared.take() else {
            let Some(store) = preparation.advance(&self.model, deadline) else {
                debug_log(|| format!("preparation advanced after {:?}", began.elapsed()));
                return;
            };
            debug_log(|| format!("preparation done after {:?}", began.elapsed()));
            self.subset = preparation.subset.clone();
            self.prepared = Some(store);
            return;
        };
        if !self.penalties_built {
            self.penalties_built = true;
            if store.root_bound().is_none() {
                // Without the lattice the DP bounds its states by assignments: strengthen them.
                self.build_penalties(options, upper_bound);
            }
            self.prepared = Some(store);
            return;
        }
        if !self.advance_penalties(instance, deadline) || !self.advance_arborescence(deadline) {
            self.prepared = Some(store);
            return;
        }
        if !self.position_checked {
            self.position_checked = true;
            if let Some(root) = store.root_bound() {
                self.root_bound = self.root_bound.max(self.model.round_bound(root));
            }
            if let Some(subset) = &self.subset {
                self.root_bound = self
                    .root_bound
                    .max(self.model.round_bound(subset.root_bound));
            }
            let strong_subset = self.subset.as_ref().is_some_and(|s| {
                s.tracked_count() == self.model.m
                    || s.root_bound >= STRONG_SUBSET_SHARE * upper_bound
            });
            if store.root_bound().is_none() && !strong_subset && self.root_bound < upper_bound {
                // Neither the lattice nor a strong subset bound (exact, or within 15 % of the
                // incumbent, as on the industrial orders) sees precedence per state: add the
                // position bound (on e1x_4, ec_2, … its root stays 17–35 % below the subset's).
                self.build_position_bound(options, upper_bound);
            }
        }
        if !self.advance_position(deadline) {
            self.prepared = Some(store);
            return;
        }
        self.preparation = None;
        debug_log(|| {
            format!(
                "bounds built (last slice {:?}): lattice root {:?}, subset root {:?} ({} of {} clusters tracked)",
                began.elapsed(),
                store.root_bound(),
                self.subset.as_ref().map(|s| s.root_bound),
                self.subset.as_ref().map_or(0, |s| s.tracked_count()),
                self.model.m,
            )
        });
        self.lattice = Some(store);
    }

    /// The Lagrangian bounds (`lagrange.rs`): node penalties for the per-state assignment
    /// bounds, and the Held–Karp style arborescence bound at the root.
    fn build_penalties(&mut self, options: &ExactOptions, upper_bound: f64) {
        if options.penalty_iterations == 0 || self.model.m > 256 {
            return;
        }
        let work = options.effective_penalty_work();
        let ascent = PenaltyAscent::new(
            &self.model,
            upper_bound,
            PenaltyOptions {
                iterations: options.penalty_iterations,
                work,
            },
        );
        let arborescence = PenaltyOptions {
            iterations: 4 * options.penalty_iterations,
            work: 4.0 * work,
        };
        self.penalty_ascent = Some((ascent, upper_bound, arborescence));
    }

    /// Iterations of the node penalties' ascent until `deadline` (at least one), then the
    /// arborescence bound's ascent is set up from them; whether they are done (or there are
    /// none).
    fn advance_penalties(&mut self, instance: &Instance, deadline: Instant) -> bool {
        let Some((ascent, upper_bound, arborescence)) = self.penalty_ascent.as_mut() else {
            return true;
        };
        let (upper_bound, arborescence) = (*upper_bound, *arborescence);
        let penalties = match ascent {
            Some(ascent) => {
                match ascent.advance(instance, &self.model, &|| Instant::now() >= deadline) {
                    Some(penalties) => penalties.map(Rc::new),
                    None => return false,
                }
            }
            None => None,
        };
        self.penalty_ascent = None;
        if let Some(p) = &penalties {
            self.root_bound = self.root_bound.max(self.model.round_bound(p.root_bound));
            debug_log(|| {
                format!(
                    "node penalties: root L1 {} -> {} ({} iterations)",
                    p.plain_l1, p.root_bound, p.iterations
                )
            });
        }
        self.penalties = penalties;
        self.arborescence = ArborescenceAscent::new(
            &self.model,
            upper_bound,
            self.penalties.as_ref().map(|p| p.lambda.as_slice()),
            arborescence,
        );
        true
    }

    /// Iterations of the arborescence bound until `deadline` (at least one); whether it is
    /// done (or there is none).
    fn advance_arborescence(&mut self, deadline: Instant) -> bool {
        let Some(ascent) = self.arborescence.as_mut() else {
            return true;
        };
        let Some((bound, iterations)) = ascent.advance(&self.model, &|| Instant::now() >= deadline)
        else {
            return false;
        };
        self.arborescence = None;
        self.root_bound = self.root_bound.max(self.model.round_bound(bound));
        debug_log(|| format!("arborescence bound: {bound} ({iterations} iterations)"));
        true
    }

    /// The position-indexed completion bound (`completion.rs`).
    fn build_position_bound(&mut self, options: &ExactOptions, upper_bound: f64) {
        if options.position_iterations == 0 || self.model.m > 256 {
            return;
        }
        self.position_ascent = PositionAscent::new(
            &self.model,
            upper_bound,
            PositionBoundOptions {
                iterations: options.position_iterations,
                work: options.effective_position_work(),
                probe_work: POSITION_PROBE_WORK,
                known_bound: self.root_bound,
            },
        );
    }

    /// Iterations of the position bound's ascent until `deadline` (at least one); whether it
    /// is done (or there is none).
    fn advance_position(&mut self, deadline: Instant) -> bool {
        let Some(ascent) = self.position_ascent.as_mut() else {
            return true;
        };
        let Some(position) = ascent.advance(&self.model, &|| Instant::now() >= deadline) else {
            return false;
        };
        self.position_ascent = None;
        self.root_bound = self
            .root_bound
            .max(self.model.round_bound(position.root_bound));
        debug_log(|| {
            format!(
                "position bound: root {} ({} iterations)",
                position.root_bound, position.iterations
            )
        });
        self.position = Some(Rc::new(position));
        true
    }

    /// A new DP engine with every bound this run has.
    fn engine(&mut self, beam: Option<usize>, memory: usize, use_l2: bool) -> Engine {
        let store = self
            .lattice
            .as_ref()
            .expect("bounds built before the search");
        let mut engine = Engine::new(&self.model, beam, memory, use_l2, store);
        if let Some(subset) = &self.subset {
            engine.set_subset_bound(&self.model, subset.clone());
        }
        if let Some(penalties) = &self.penalties {
            engine.set_penalties(&self.model, penalties.clone());
        }
        // Only the exact search: ranking the beams by it (and without the assignments) made
        // them miss ESC47's 1063 tour (1144) in the library run.
        if let (None, Some(position)) = (beam, &self.position) {
            engine.set_position_bound(&self.model, position.clone());
        }
        engine
    }
}

enum Phase {
    Heuristic {
        beam: usize,
        engine: Option<Box<Engine>>,
    },
    Exact,
    Done(Status),
}

/// The least time the or-opt polish of a tour gets in a step, whatever the slice: on small
/// instances 20,000 evaluations take about 0.1 s and the tour they give shortens the proof; on
/// a discretised nest of 5,000 nodes they took 21 s, so the polish stops here (a step may
/// overrun a shorter slice by this much).
const POLISH_SLICE: Duration = Duration::from_millis(150);

/// The anytime exact solver: construct, then call [`ExactSolver::step`] until it stops
/// returning [`Status::Running`]; read [`ExactSolver::progress`] at any time; feed
/// tours found elsewhere with [`ExactSolver::offer_incumbent`].
pub struct ExactSolver {
    instance: Instance,
    options: ExactOptions,
    runs: Vec<Run>,
    /// Start nodes whose run is still to be built (reversed: next is last).
    unbuilt: Vec<usize>,
    /// The model being built, a piece per [`ExactSolver::build_unit`].
    building: Option<ModelBuilder>,
    /// The model built last, its root bound not yet computed (or under way in `root_bounder`).
    unbounded: Option<Model>,
    root_bounder: ResidualBounder,
    current_run: usize,
    incumbent: Incumbent,
    phase: Phase,
    elapsed: Duration,
    cancelled: bool,
    /// A lower bound proven outside the DP ([`ExactSolver::offer_lower_bound`]).
    external_bound: f64,
}

impl ExactSolver {
    /// Prepares the solver (preprocessing and root bounds; no search yet).
    pub fn new(instance: &Instance, options: ExactOptions) -> Result<ExactSolver, SolverError> {
        let mut solver = ExactSolver::deferred(instance, options)?;
        while solver.build_unit(&|| false) {}
        Ok(solver)
    }

    /// Like [`ExactSolver::new`] but cheap: the instance is checked here and each start
    /// node's model and root bound are built later, each in a [`ExactSolver::step`] of its own
    /// (on thousands of nodes each takes seconds, which a caller answering Stop between steps
    /// cannot wait for; a model is built in pieces itself, [`ModelBuilder`]). Until they are
    /// built, [`ExactSolver::root_bound`] is −∞.
    pub fn deferred(
        instance: &Instance,
        options: ExactOptions,
    ) -> Result<ExactSolver, SolverError> {
        ExactSolver::deferred_owned(instance.clone(), options)
    }

    /// [`ExactSolver::deferred`] on an instance it keeps (a caller that copied it in pieces
    /// saves the copy `deferred` makes: hundreds of MB on a big discretisation).
    pub fn deferred_owned(
        instance: Instance,
        options: ExactOptions,
    ) -> Result<ExactSolver, SolverError> {
        if instance.node_count > u16::MAX as usize {
            return Err(SolverError::TooManyNodes(instance.node_count));
        }
        // The only way a model fails: the precedence pairs are no partial order.
        PrecedenceOrder::new(&instance)?;
        let phase = if options.heuristic {
            Phase::Heuristic {
                beam: 0,
                engine: None,
            }
        } else {
            Phase::Exact
        };
        let mut unbuilt = instance.clusters[instance.depot].clone();
        unbuilt.reverse();
        Ok(ExactSolver {
            instance,
            options,
            runs: Vec::new(),
            unbuilt,
            building: None,
            unbounded: None,
            root_bounder: ResidualBounder::default(),
            current_run: 0,
            incumbent: Incumbent {
                upper_bound: INF,
                tour: None,
            },
            phase,
            elapsed: Duration::ZERO,
            cancelled: false,
            external_bound: -INF,
        })
    }

    /// Whether every start node's run (model and root bound) is built (always, but for a
    /// [`ExactSolver::deferred`] solver before its first steps).
    pub fn runs_built(&self) -> bool {
        self.unbuilt.is_empty() && self.building.is_none() && self.unbounded.is_none()
    }

    /// Builds one piece of the runs: pieces of the next start node's model until `pause()`
    /// (at least one), or rows of its root bound's assignments until `pause()` (at least one).
    /// Returns whether it did anything (false once all are built).
    fn build_unit(&mut self, pause: &dyn Fn() -> bool) -> bool {
        if let Some(model) = self.unbounded.take() {
            let depot = model.depot;
            // In pieces: on a discretisation of 1,000 clusters the assignments took 2.9 s.
            let Some(bound) = self.root_bounder.compute_until(
                &model,
                &|c| c == depot,
                depot,
                self.options.use_l2,
                pause,
            ) else {
                self.unbounded = Some(model);
                return true;
            };
            let root_bound = model.round_bound(bound);
            self.runs.push(Run {
                model,
                lattice: None,
                preparation: None,
                subset: None,
                penalties: None,
                position: None,
                prepared: None,
                penalties_built: false,
                penalty_ascent: None,
                arborescence: None,
                position_checked: false,
                position_ascent: None,
                root_bound,
                engine: None,
                finished_bound: None,
                states_created: 0,
            });
            return true;
        }
        if let Some(builder) = self.building.as_mut() {
            let t = Instant::now();
            if let Some(model) = builder.advance(&self.instance, pause) {
                let start = model.start;
                debug_log(|| {
                    format!(
                        "model of start node {start} built (last piece {:?})",
                        t.elapsed()
                    )
                });
                self.building = None;
                self.unbounded = Some(model);
            }
            return true;
        }
        let Some(start) = self.unbuilt.pop() else {
            return false;
        };
        // Checked in `deferred`: the order is a partial order, so the model builds.
        match ModelBuilder::new(&self.instance, start) {
            Ok(builder) => self.building = Some(builder),
            Err(e) => debug_log(|| format!("start node {start}: no model ({e})")),
        }
        true
    }

    /// The root lower bound (max of L1 and L2 over the empty prefix; min over start nodes);
    /// −∞ until every run is built ([`ExactSolver::deferred`]).
    pub fn root_bound(&self) -> f64 {
        if !self.runs_built() {
            return -INF;
        }
        self.runs.iter().map(|r| r.root_bound).fold(INF, f64::min)
    }

    /// Offers a tour found elsewhere (e.g. by a heuristic in the same job). It is checked with
    /// [`check_tour`]; if feasible and better, it becomes the incumbent and prunes the search.
    /// Returns whether it was accepted. The cost is recomputed; `cost` is only a hint.
    pub fn offer_incumbent(&mut self, tour: &[usize], cost: f64) -> bool {
        let Ok(checked) = check_tour(&self.instance, tour) else {
            return false;
        };
        let _ = cost;
        if checked < self.incumbent.upper_bound {
            self.incumbent.upper_bound = checked;
            self.incumbent.tour = Some(tour.to_vec());
            true
        } else {
            false
        }
    }

    /// Offers a lower bound proven elsewhere (e.g. [`crate::restricted_bound`]). The caller vouches
    /// for its validity; it raises the reported bound and ends the search once it reaches the
    /// incumbent's cost.
    pub fn offer_lower_bound(&mut self, bound: f64) {
        self.external_bound = self.external_bound.max(bound);
    }

    /// Whether a proven lower bound (external, or every run's root bound) reaches the
    /// incumbent's cost, so the incumbent is optimal without further search.
    fn bounds_meet_incumbent(&self) -> bool {
        let ub = self.incumbent.upper_bound;
        ub.is_finite()
            && (self.external_bound >= ub
                || (self.runs_built() && self.runs.iter().all(|r| r.root_bound >= ub)))
    }

    /// Stops the search at the next `step`.
    pub fn cancel(&mut self) {
        self.cancelled = true;
    }

    /// The current lower bound.
    fn lower_bound(&self) -> f64 {
        let ub = self.incumbent.upper_bound;
        // A start node without its run bounds nothing yet.
        let mut lb = if self.runs_built() { INF } else { -INF };
        for run in &self.runs {
            let run_lb = if let Some(b) = run.finished_bound {
                b
            } else {
                let dp_lb = run
                    .engine
                    .as_ref()
                    .map_or(-INF, |e| e.stats(&run.model, ub).2);
                run.root_bound.max(dp_lb)
            };
            lb = lb.min(run_lb);
        }
        let lb = lb.max(self.external_bound);
        match self.phase {
            Phase::Done(Status::Finished {
                proven_optimal: true,
            }) => ub,
            _ => lb.min(ub),
        }
    }

    /// A snapshot of the current state.
    pub fn progress(&self) -> ExactProgress {
        let ub = self.incumbent.upper_bound;
        let lb = self.lower_bound();
        let (layer, live) = match (&self.phase, self.runs.get(self.current_run)) {
            (Phase::Exact, Some(run)) => run.engine.as_ref().map_or((0, 0), |e| {
                let s = e.stats(&run.model, ub);
                (s.0, s.1)
            }),
            _ => (0, 0),
        };
        let gap = if ub.is_finite() {
            if ub > 0.0 {
                ((ub - lb) / ub).max(0.0)
            } else {
                0.0
            }
        } else {
            INF
        };
        ExactProgress {
            elapsed: self.elapsed,
            upper_bound: ub,
            lower_bound: lb,
            gap,
            layer,
            live_states: live,
            best_tour: self.incumbent.tour.clone(),
        }
    }

    /// DP states created so far.
    pub fn states_created(&self) -> u64 {
        self.runs
            .iter()
            .map(|r| r.states_created + r.engine.as_ref().map_or(0, |e| e.stats(&r.model, INF).4))
            .sum()
    }

    /// Does at most about `budget` of work and returns the status.
    pub fn step(&mut self, budget: Duration) -> Status {
        if let Phase::Done(status) = self.phase {
            return status;
        }
        let began = Instant::now();
        let mut deadline = budget;
        if let Some(limit) = self.options.time_limit {
            deadline = deadline.min(limit.saturating_sub(self.elapsed));
        }
        // Work units between clock reads: small enough to keep steps near their budget.
        const CHUNK: u64 = 200_000;
        let mut built_one = false;
        loop {
            if self.cancelled {
                return self.stop(began);
            }
            if let Some(limit) = self.options.time_limit {
                if self.elapsed + began.elapsed() >= limit {
                    return self.stop(began);
                }
            }
            // The runs of a deferred solver: one model or root bound per piece, at least one
            // per step whatever its budget (so tiny slices still advance).
            let pause = || began.elapsed() >= deadline;
            if !built_one && self.build_unit(&pause) {
                built_one = true;
                continue;
            }
            if began.elapsed() >= deadline {
                self.elapsed += began.elapsed();
                return Status::Running;
            }
            if self.build_unit(&pause) {
                continue;
            }
            if self.bounds_meet_incumbent() {
                // A bound (from outside, or a root bound) already meets the incumbent.
                self.elapsed += began.elapsed();
                let status = Status::Finished {
                    proven_optimal: true,
                };
                self.phase = Phase::Done(status);
                return status;
            }
            match &mut self.phase {
                Phase::Heuristic { beam, engine } => {
                    if self.runs[0].lattice.is_none() {
                        // A quick tour first, so an upper bound exists before the bounds are
                        // built (the subset bound also chooses its clusters from it).
                        for r in (0..self.runs.len()).filter(|_| self.runs[0].preparation.is_none())
                        {
                            if let Some(mut tour) = heuristic::greedy(&self.runs[r].model) {
                                let cost = heuristic::improve(
                                    &self.runs[r].model,
                                    &mut tour,
                                    20_000,
                                    began + deadline.max(POLISH_SLICE),
                                );
                                if cost < self.incumbent.upper_bound {
                                    if let Ok(checked) = check_tour(&self.instance, &tour) {
                                        self.incumbent.upper_bound = checked;
                                        self.incumbent.tour = Some(tour);
                                    }
                                }
                            }
                        }
                        if self.runs[0].preparation.is_none() {
                            debug_log(|| format!("greedy: UB {}", self.incumbent.upper_bound));
                        }
                        self.runs[0].build_lattice(
                            &self.instance,
                            &self.options,
                            self.incumbent.tour.as_deref(),
                            self.incumbent.upper_bound,
                            began + deadline,
                        );
                        continue;
                    }
                    let run = &mut self.runs[0];
                    if engine.is_none() {
                        // Without the lattice the beam bounds states by assignments (O(m³)
                        // per group): wide beams would eat the whole budget.
                        let has_lattice = run
                            .lattice
                            .as_ref()
                            .is_some_and(|l| l.root_bound().is_some());
                        let width = self.options.beam_widths.get(*beam).copied();
                        let width = if has_lattice {
                            width
                        } else {
                            width.filter(|&w| w <= 1024)
                        };
                        match width {
                            Some(width) => {
                                *engine = Some(Box::new(run.engine(
                                    Some(width),
                                    self.options.memory_limit_bytes,
                                    self.options.use_l2,
                                )));
                            }
                            None => {
                                self.phase = Phase::Exact;
                                continue;
                            }
                        }
                    }
                    let e = engine.as_mut().expect("engine set above");
                    // The beam must not prune with its own incumbent's rounding tricks beyond
                    // what is valid: it uses the same (valid) pruning as the exact DP.
                    if e.run(&run.model, &mut self.incumbent, CHUNK) == DpStatus::Done {
                        debug_log(|| {
                            format!(
                                "beam {} done at {:?}: UB {}",
                                *beam,
                                self.elapsed + began.elapsed(),
                                self.incumbent.upper_bound
                            )
                        });
                        *engine = None;
                        *beam += 1;
                        self.polish_incumbent(began + deadline.max(POLISH_SLICE));
                        debug_log(|| {
                            format!(
                                "polished at {:?}: UB {}",
                                self.elapsed + began.elapsed(),
                                self.incumbent.upper_bound
                            )
                        });
                    }
                }
                Phase::Exact => {
                    if self.current_run >= self.runs.len() {
                        let proven = self.runs.iter().all(|r| {
                            r.finished_bound
                                .is_some_and(|b| b >= self.incumbent.upper_bound)
                        });
                        self.elapsed += began.elapsed();
                        let status = Status::Finished {
                            proven_optimal: proven,
                        };
                        self.phase = Phase::Done(status);
                        return status;
                    }
                    let memory = self.options.memory_limit_bytes;
                    let use_l2 = self.options.use_l2;
                    let max_ideals = self.options.lattice_max_ideals;
                    let run = &mut self.runs[self.current_run];
                    if run.lattice.is_none() {
                        run.build_lattice(
                            &self.instance,
                            &self.options,
                            self.incumbent.tour.as_deref(),
                            self.incumbent.upper_bound,
                            began + deadline,
                        );
                        continue;
                    }
                    let _ = max_ideals;
                    if run.engine.is_none() {
                        let t = Instant::now();
                        run.engine = Some(run.engine(None, memory, use_l2));
                        debug_log(|| format!("engine made in {:?}", t.elapsed()));
                    }
                    let engine = run.engine.as_mut().expect("created above");
                    let layer_before = engine.stats(&run.model, INF).0;
                    let status = engine.run(&run.model, &mut self.incumbent, CHUNK);
                    let layer_changed = engine.stats(&run.model, INF).0 != layer_before;
                    if status == DpStatus::Done {
                        let (_, _, _, dropped, created) =
                            engine.stats(&run.model, self.incumbent.upper_bound);
                        let unsupported = engine.is_unsupported();
                        run.states_created += created;
                        run.finished_bound = Some(if unsupported {
                            run.root_bound
                        } else {
                            run.model.round_bound(dropped).max(run.root_bound)
                        });
                        run.engine = None;
                        self.current_run += 1;
                    }
                    let p = self.progress();
                    if p.upper_bound.is_finite() && p.lower_bound >= p.upper_bound {
                        // Every live state is bounded by the incumbent: nothing can improve.
                        self.elapsed += began.elapsed();
                        let status = Status::Finished {
                            proven_optimal: true,
                        };
                        self.phase = Phase::Done(status);
                        return status;
                    }
                    if self.options.gap_tolerance > 0.0 && p.gap <= self.options.gap_tolerance {
                        return self.stop(began);
                    }
                    if layer_changed {
                        debug_log(|| {
                            format!(
                                "layer {} at {:?}: {} live states, LB {}, UB {}",
                                p.layer,
                                self.elapsed + began.elapsed(),
                                p.live_states,
                                p.lower_bound,
                                p.upper_bound
                            )
                        });
                        // Let the caller report progress after every layer.
                        self.elapsed += began.elapsed();
                        return Status::Running;
                    }
                }
                Phase::Done(status) => {
                    let status = *status;
                    self.elapsed += began.elapsed();
                    return status;
                }
            }
        }
    }

    fn stop(&mut self, began: Instant) -> Status {
        self.elapsed += began.elapsed();
        self.phase = Phase::Done(Status::Stopped);
        Status::Stopped
    }

    /// Local search on the incumbent (for the start node it begins with), until `deadline`.
    fn polish_incumbent(&mut self, deadline: Instant) {
        let Some(tour) = self.incumbent.tour.clone() else {
            return;
        };
        let Some(run) = self.runs.iter().find(|r| r.model.start == tour[0]) else {
            return;
        };
        let mut improved = tour;
        let cost = heuristic::improve(&run.model, &mut improved, 200_000, deadline);
        if cost < self.incumbent.upper_bound {
            if let Ok(checked) = check_tour(&self.instance, &improved) {
                self.incumbent.upper_bound = checked;
                self.incumbent.tour = Some(improved);
            }
        }
    }
}

/// The contract of every solver: the best tour (0-based nodes from the depot) and its cost; the
/// lower bound is the proven one ([`Status::Finished`]'s `proven_optimal` when they meet:
/// finished without dropping states, or a bound reached the tour's cost; [`Status::Stopped`] by
/// the time limit, the gap tolerance or [`ExactSolver::cancel`]).
impl AnytimeSolver for ExactSolver {
    type Solution = Vec<usize>;

    fn step(&mut self, budget: Duration) -> Status {
        ExactSolver::step(self, budget)
    }

    fn best(&self) -> Option<Vec<usize>> {
        self.incumbent.tour.clone()
    }

    fn bounds(&self) -> Bounds {
        let ub = self.incumbent.upper_bound;
        let lb = self.lower_bound();
        Bounds {
            upper: ub.is_finite().then_some(ub),
            lower: lb.is_finite().then_some(lb),
            unit: CostUnit::TourCost,
        }
    }
}

/// Runs the exact solver to completion (or its time limit), reporting progress at least every
/// 200 ms and after every DP layer.
pub fn solve(
    instance: &Instance,
    options: ExactOptions,
    on_progress: &mut dyn FnMut(&ExactProgress),
) -> Result<ExactResult, SolverError> {
    let mut solver = ExactSolver::new(instance, options)?;
    loop {
        // `step` also returns after every finished layer, so this reports per layer too.
        let status = solver.step(Duration::from_millis(100));
        let progress = solver.progress();
        on_progress(&progress);
        if status != Status::Running {
            return Ok(ExactResult {
                status,
                progress,
                states_created: solver.states_created(),
                root_bound: solver.root_bound(),
            });
        }
    }
}

/// Debug tracing to stderr when `PCGTSP_DEBUG` is set (never in wasm, where `env::var` fails).
fn debug_log(message: impl FnOnce() -> String) {
    if std::env::var_os("PCGTSP_DEBUG").is_some() {
        eprintln!("[pcgtsp] {}", message());
    }
}
