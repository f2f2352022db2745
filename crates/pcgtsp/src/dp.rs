//! The layer-by-layer DP over order ideals with node-level states (Algorithm 2.4), as a
//! resumable engine: `run` does a bounded amount of work and returns.
//!
//! Layer `k` holds states `(J, x)`: `J` an order ideal of `k` clusters (bitset key), `x` a node
//! of a maximal cluster `V` of `J`, with the cheapest path cost from the start node through
//! exactly the clusters of `J` ending at `x`. A state of `(J, V)` has a single predecessor ideal
//! `J \ {V}`, so the next layer is built by sorting the child records `(J ∪ {V}, V, parent)`
//! and taking, for every node of `V`, the minimum over the parent ideal's states.
//!
//! Layers are flat arrays sorted by key (no hash maps); earlier layers keep only the node and
//! parent index of every state, for reconstruction.

use crate::bounds::completion::{PositionBound, PositionQuery};
use crate::bounds::lagrange::NodePenalties;
use crate::bounds::lattice::Lattice;
use crate::bounds::residual::ResidualBounder;
use crate::bounds::subset::{SubsetBound, SubsetQuery};
use crate::keys::Key;
use crate::model::Model;
use std::rc::Rc;

const INF: f64 = f64::INFINITY;

/// One layer: ideals → groups (ideal, last cluster) → states, all as flat sorted arrays.
#[derive(Default)]
struct Layer<const W: usize> {
    ideals: Vec<Key<W>>,
    /// Groups of ideal `i`: `ideal_groups[i]..ideal_groups[i + 1]`.
    ideal_groups: Vec<u32>,
    group_last: Vec<u16>,
    /// States of group `g`: `group_states[g]..group_states[g + 1]`.
    group_states: Vec<u32>,
    node: Vec<u16>,
    cost: Vec<f64>,
    lb: Vec<f64>,
    parent: Vec<u32>,
}

impl<const W: usize> Layer<W> {
    fn new() -> Self {
        Layer {
            ideal_groups: vec![0],
            group_states: vec![0],
            ..Default::default()
        }
    }

    fn state_count(&self) -> usize {
        self.node.len()
    }

    /// The state range of ideal `i`.
    fn ideal_states(&self, i: usize) -> std::ops::Range<usize> {
        let g0 = self.ideal_groups[i] as usize;
        let g1 = self.ideal_groups[i + 1] as usize;
        self.group_states[g0] as usize..self.group_states[g1] as usize
    }

    /// Keeps only the states for which `keep(index)` holds, dropping empty groups and ideals.
    fn retain(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mut out = Layer::<W>::new();
        for i in 0..self.ideals.len() {
            let groups_before = out.group_last.len();
            for g in self.ideal_groups[i] as usize..self.ideal_groups[i + 1] as usize {
                let states_before = out.node.len();
                for s in self.group_states[g] as usize..self.group_states[g + 1] as usize {
                    if keep(s) {
                        out.node.push(self.node[s]);
                        out.cost.push(self.cost[s]);
                        out.lb.push(self.lb[s]);
                        out.parent.push(self.parent[s]);
                    }
                }
                if out.node.len() > states_before {
                    out.group_last.push(self.group_last[g]);
                    out.group_states.push(out.node.len() as u32);
                }
            }
            if out.group_last.len() > groups_before {
                out.ideals.push(self.ideals[i]);
                out.ideal_groups.push(out.group_last.len() as u32);
            }
        }
        *self = out;
    }
}

/// Shared solver state the DP reads and updates.
pub(crate) struct Incumbent {
    /// Best known tour cost (`INF` if none).
    pub upper_bound: f64,
    /// Best known tour (0-based nodes), if any.
    pub tour: Option<Vec<usize>>,
}

/// What one call of [`Dp::run`] ended with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DpStatus {
    /// More work remains.
    Running,
    /// The last layer is done (or no state survived).
    Done,
}

/// Width-generic DP engine.
pub(crate) struct Dp<const W: usize> {
    pred_mask: Vec<Key<W>>,
    /// Clusters of the current layer's ideals.
    pub layer: usize,
    current: Layer<W>,
    past_nodes: Vec<Vec<u16>>,
    past_parents: Vec<Vec<u32>>,
    past_bytes: usize,
    records: Vec<(Key<W>, u16, u32)>,
    next_record: usize,
    next: Layer<W>,
    next_min_lb: f64,
    /// The smallest bound in the current layer.
    current_min_lb: f64,
    /// Keep at most this many states per layer (beam search; `None` = exact).
    beam_width: Option<usize>,
    memory_limit: usize,
    /// The smallest bound of any state dropped for memory or beam width (`INF` if none).
    pub dropped_min: f64,
    /// `max` over finished layers of their smallest state bound.
    pub layer_bound: f64,
    bounder: ResidualBounder,
    use_l2: bool,
    costs: Vec<f64>,
    parents: Vec<u32>,
    /// States created so far (all layers).
    pub states_created: u64,
    /// Upper bound used when the current layer was pruned last.
    pruned_with: f64,
    done: bool,
    /// The cluster-DP bound over the whole ideal lattice, when it fits in memory.
    lattice: Option<Rc<Lattice<W>>>,
    next_values: Vec<(usize, f64)>,
    /// The subset DP bound (exact node-level completion over tracked clusters), if built.
    subset: Option<Rc<SubsetBound>>,
    subset_query: SubsetQuery,
    /// Node penalties: when set, the assignment bounds are computed on the penalised costs.
    penalties: Option<Rc<NodePenalties>>,
    /// The position-indexed completion bound (precedence-aware, O(candidates) per state).
    position: Option<Rc<PositionBound>>,
    position_query: PositionQuery,
    /// Position bound of every node of the group being expanded.
    position_lbs: Vec<f64>,
    /// The position bound's root is at least the penalised assignment root: skip assignments.
    position_replaces_assignment: bool,
}

impl<const W: usize> Dp<W> {
    pub fn new(
        model: &Model,
        beam_width: Option<usize>,
        memory_limit: usize,
        use_l2: bool,
        lattice: Option<Rc<Lattice<W>>>,
    ) -> Self {
        let m = model.m;
        assert!(m <= 64 * W, "cluster count exceeds key width");
        let pred_mask = (0..m)
            .map(|c| {
                model.order.predecessors[c]
                    .iter()
                    .fold(Key::<W>::empty(), |k, p| k.with(p))
            })
            .collect();
        let mut current = Layer::<W>::new();
        current.ideals.push(Key::empty().with(model.depot));
        current.ideal_groups.push(1);
        current.group_last.push(model.depot as u16);
        current.node.push(model.start as u16);
        current.cost.push(0.0);
        // With a single cluster the start node alone is the tour (closed by its self-arc).
        current.lb.push(if m == 1 {
            model.arc(model.start, model.start)
        } else {
            0.0
        });
        current.parent.push(u32::MAX);
        current.group_states.push(1);
        let layer_bound = lattice
            .as_ref()
            .map_or(0.0, |l| model.round_bound(l.root_bound));
        Dp {
            pred_mask,
            layer: 1,
            current,
            past_nodes: Vec::new(),
            past_parents: Vec::new(),
            past_bytes: 0,
            records: Vec::new(),
            next_record: 0,
            next: Layer::new(),
            next_min_lb: INF,
            current_min_lb: 0.0,
            beam_width,
            memory_limit,
            dropped_min: INF,
            layer_bound,
            bounder: ResidualBounder::default(),
            use_l2,
            costs: Vec::new(),
            parents: Vec::new(),
            states_created: 1,
            pruned_with: INF,
            done: false,
            lattice,
            next_values: Vec::new(),
            subset: None,
            subset_query: SubsetQuery::default(),
            penalties: None,
            position: None,
            position_query: PositionQuery::default(),
            position_lbs: Vec::new(),
            position_replaces_assignment: false,
        }
    }

    /// Adds the position-indexed completion bound: every state created from now on is
    /// bounded by it too, and groups it prunes entirely skip the assignment bounds.
    pub fn set_position_bound(&mut self, model: &Model, position: Rc<PositionBound>) {
        self.layer_bound = self.layer_bound.max(model.round_bound(position.root_bound));
        self.position_replaces_assignment = self
            .penalties
            .as_ref()
            .is_some_and(|p| position.root_bound >= p.root_bound);
        self.position = Some(position);
    }

    /// Computes the per-state assignment bounds on penalised costs from now on.
    pub fn set_penalties(&mut self, model: &Model, penalties: Rc<NodePenalties>) {
        self.layer_bound = self
            .layer_bound
            .max(model.round_bound(penalties.root_bound));
        self.penalties = Some(penalties);
    }

    /// Adds the subset DP bound: every state created from now on is bounded by it too.
    pub fn set_subset_bound(&mut self, model: &Model, subset: Rc<SubsetBound>) {
        self.layer_bound = self.layer_bound.max(model.round_bound(subset.root_bound));
        self.subset = Some(subset);
    }

    /// States in the current layer plus the one being built.
    pub fn live_states(&self) -> usize {
        self.current.state_count() + self.next.state_count()
    }

    /// A valid lower bound on every tour better than the incumbent that this DP still represents.
    pub fn lower_bound(&self, model: &Model, upper_bound: f64) -> f64 {
        if self.done {
            return model.round_bound(self.dropped_min).min(upper_bound);
        }
        // Every improving tour passes through a state of the current layer, or one of the layer
        // being built, or was dropped (pruned states cannot improve on the incumbent).
        let live = self
            .dropped_min
            .min(self.current_min_lb)
            .min(self.next_min_lb);
        model
            .round_bound(live)
            .min(upper_bound)
            .max(self.layer_bound.min(upper_bound))
    }

    #[inline]
    fn prunable(model: &Model, lb: f64, upper_bound: f64) -> bool {
        // With integral costs an improving tour costs at most UB - 1.
        model.round_bound(lb) >= upper_bound
    }

    /// Does about `work_limit` units of work (one unit ≈ one state transition) and returns.
    pub fn run(&mut self, model: &Model, incumbent: &mut Incumbent, work_limit: u64) -> DpStatus {
        if self.done {
            return DpStatus::Done;
        }
        let mut work = 0u64;
        while work < work_limit {
            if self.layer == model.m {
                self.close_tours(model, incumbent);
                self.done = true;
                return DpStatus::Done;
            }
            if self.records.is_empty() && self.next_record == 0 {
                work += self.generate_records(model, incumbent.upper_bound);
                if self.records.is_empty() {
                    // Nothing survives: the incumbent is optimal (up to dropped states).
                    self.done = true;
                    return DpStatus::Done;
                }
                continue;
            }
            if self.next_record < self.records.len() {
                work += self.expand_record(model, incumbent.upper_bound);
                self.next_record += 1;
                continue;
            }
            self.finish_layer(model);
            if self.done {
                return DpStatus::Done;
            }
        }
        DpStatus::Running
    }

    fn generate_records(&mut self, model: &Model, upper_bound: f64) -> u64 {
        if upper_bound < self.pruned_with {
            // The incumbent improved since this layer was built: drop what it now prunes.
            let lbs = std::mem::take(&mut self.current.lb);
            self.current.lb = lbs.clone();
            self.current
                .retain(|s| !Self::prunable(model, lbs[s], upper_bound));
            self.pruned_with = upper_bound;
        }
        let m = model.m;
        self.records.clear();
        for (i, ideal) in self.current.ideals.iter().enumerate() {
            for v in 0..m {
                if !ideal.contains(v) && ideal.contains_all(&self.pred_mask[v]) {
                    self.records.push((ideal.with(v), v as u16, i as u32));
                }
            }
        }
        self.records.sort_unstable();
        self.next_record = 0;
        self.next = Layer::new();
        self.next_min_lb = INF;
        (self.current.ideals.len() * m / 8 + self.records.len()) as u64
    }

    fn expand_record(&mut self, model: &Model, upper_bound: f64) -> u64 {
        let (ideal, v, source) = self.records[self.next_record];
        let v = v as usize;
        let sources = self.current.ideal_states(source as usize);
        let nodes = &model.cluster_nodes[v];
        let width = nodes.len();
        let block = &model.into_cluster[v];
        self.costs.clear();
        self.costs.resize(width, INF);
        self.parents.clear();
        self.parents.resize(width, u32::MAX);
        {
            // Local slices keep the hot loop free of reloads through `self`.
            let costs = &mut self.costs[..width];
            let parents = &mut self.parents[..width];
            let source_cost = &self.current.cost[sources.clone()];
            let source_node = &self.current.node[sources.clone()];
            for (offset, (&g, &u)) in source_cost.iter().zip(source_node).enumerate() {
                let u = u as usize;
                let row = &block[u * width..(u + 1) * width];
                let s = (sources.start + offset) as u32;
                for ((cost, parent), &arc) in costs.iter_mut().zip(parents.iter_mut()).zip(row) {
                    let c = g + arc;
                    if c < *cost {
                        *cost = c;
                        *parent = s;
                    }
                }
            }
        }
        let work = (sources.len() * width) as u64 + 1;
        let g_min = self.costs.iter().copied().fold(INF, f64::min);
        if Self::prunable(model, g_min, upper_bound) {
            return work;
        }
        let complete = self.layer + 1 == model.m;
        self.position_lbs.clear();
        if let (false, Some(position)) = (complete, self.position.clone()) {
            // The cheap precedence-aware bound first: a group it prunes needs no assignment.
            position.prepare(
                model,
                |c| ideal.contains(c),
                self.layer + 1,
                v,
                &mut self.position_query,
            );
            let mut survivors = false;
            for (&x, &g) in nodes.iter().zip(&self.costs) {
                let lb = if g.is_finite() {
                    g + position.bound(model, &self.position_query, x)
                } else {
                    INF
                };
                survivors |= !Self::prunable(model, lb, upper_bound);
                self.position_lbs.push(lb);
            }
            let probe = (self.position_query.candidate_count() * width) as u64;
            if !survivors {
                return work + probe;
            }
        }
        let group_bound;
        let mut use_lattice = false;
        let mut cheap = false;
        if complete {
            group_bound = 0.0;
            self.bounder.l2 = -INF;
        } else if let Some(lattice) = &self.lattice {
            let index = lattice
                .find(&ideal, self.layer + 1)
                .expect("every ideal is in the lattice");
            lattice.next_values(self.layer + 1, index, &mut self.next_values);
            use_lattice = true;
            group_bound = 0.0;
            self.bounder.l2 = -INF;
        } else if self.beam_width.is_some() && model.m > 60 {
            // A beam without the lattice on many clusters ranks by path cost alone: assignments
            // per group (O(m³)) would make the heuristic slower than the search it seeds.
            cheap = true;
            group_bound = 0.0;
            self.bounder.l2 = -INF;
        } else if self.position_replaces_assignment && !self.position_lbs.is_empty() {
            // The position bound is the stronger one (at the root) and far cheaper: the
            // O(m³) assignments per group would cost more than the states they prune.
            cheap = true;
            group_bound = 0.0;
            self.bounder.l2 = -INF;
        } else if let Some(penalties) = &self.penalties {
            // Bounds in penalised costs: a completion from `x` costs its penalised cost plus
            // `λ_x − λ_start`.
            group_bound =
                self.bounder
                    .compute(&penalties.model, &|c| ideal.contains(c), v, self.use_l2);
            let shifted_min = nodes
                .iter()
                .zip(&self.costs)
                .map(|(&x, &g)| g + penalties.shift(x))
                .fold(INF, f64::min);
            if Self::prunable(model, shifted_min + group_bound, upper_bound) {
                return work + (model.m * model.m) as u64;
            }
        } else {
            group_bound = self
                .bounder
                .compute(model, &|c| ideal.contains(c), v, self.use_l2);
            if Self::prunable(model, g_min + group_bound, upper_bound) {
                return work + (model.m * model.m) as u64;
            }
        }
        let l2 = self.bounder.l2;
        let subset = if complete {
            None
        } else {
            self.subset.as_deref()
        };
        if let Some(subset) = subset {
            subset.prepare(|c| ideal.contains(c), v, &mut self.subset_query);
        }
        let states_before = self.next.node.len();
        for (j, &x) in nodes.iter().enumerate() {
            let g = self.costs[j];
            if !g.is_finite() {
                continue;
            }
            let lb = if complete {
                g + model.arc(x, model.start)
            } else if cheap {
                g
            } else if let (true, Some(lattice)) = (use_lattice, &self.lattice) {
                g + lattice.node_completion(model, &self.next_values, x)
            } else if let Some(penalties) = &self.penalties {
                g + self
                    .bounder
                    .node_bound(&penalties.model, x)
                    .max(l2)
                    .max(group_bound)
                    + penalties.shift(x)
            } else {
                g + self.bounder.node_bound(model, x).max(l2).max(group_bound)
            };
            let lb = match subset {
                Some(subset) => lb.max(g + subset.bound(&self.subset_query, j, x)),
                None => lb,
            };
            let lb = match self.position_lbs.get(j) {
                Some(&position) => lb.max(position),
                None => lb,
            };
            if Self::prunable(model, lb, upper_bound) {
                continue;
            }
            self.next.node.push(x as u16);
            self.next.cost.push(g);
            self.next.lb.push(lb);
            self.next.parent.push(self.parents[j]);
            self.next_min_lb = self.next_min_lb.min(lb);
        }
        if self.next.node.len() > states_before {
            if self.next.ideals.last() != Some(&ideal) {
                self.next.ideals.push(ideal);
                self.next
                    .ideal_groups
                    .push(self.next.group_last.len() as u32);
            }
            self.next.group_last.push(v as u16);
            self.next.group_states.push(self.next.node.len() as u32);
            let last = self.next.ideal_groups.len() - 1;
            self.next.ideal_groups[last] = self.next.group_last.len() as u32;
            self.states_created += (self.next.node.len() - states_before) as u64;
        }
        let cap = self.layer_cap();
        if self.next.state_count() > cap {
            self.cut_next(cap / 2);
        }
        work + (model.m * model.m) as u64
    }

    /// The most states the layer being built may hold.
    fn layer_cap(&self) -> usize {
        let by_memory = self
            .memory_limit
            .saturating_sub(self.past_bytes + self.records.len() * (8 * W + 8))
            / 40;
        let by_memory = by_memory.max(1024);
        match self.beam_width {
            Some(w) => by_memory.min(2 * w.max(1)),
            None => by_memory,
        }
    }

    /// Keeps the `keep` best-bounded states of the layer being built; records what was dropped.
    fn cut_next(&mut self, keep: usize) {
        if self.next.state_count() <= keep {
            return;
        }
        let mut lbs = self.next.lb.clone();
        let (_, &mut threshold, _) = lbs.select_nth_unstable_by(keep, f64::total_cmp);
        self.dropped_min = self.dropped_min.min(threshold);
        let lb = std::mem::take(&mut self.next.lb);
        self.next.lb = lb.clone();
        self.next.retain(|s| lb[s] < threshold);
        self.next_min_lb = self.next.lb.iter().copied().fold(INF, f64::min);
    }

    fn finish_layer(&mut self, model: &Model) {
        if let Some(width) = self.beam_width {
            self.cut_next(width);
        }
        if self.next.state_count() == 0 {
            self.done = true;
            self.records = Vec::new();
            return;
        }
        let layer_min = model.round_bound(self.next_min_lb.min(self.dropped_min));
        self.layer_bound = self.layer_bound.max(layer_min);
        let finished = std::mem::replace(&mut self.current, std::mem::take(&mut self.next));
        self.current_min_lb = self.next_min_lb;
        self.past_bytes += finished.node.len() * 6;
        self.past_nodes.push(finished.node);
        self.past_parents.push(finished.parent);
        self.records = Vec::new();
        self.next_record = 0;
        self.next = Layer::new();
        self.next_min_lb = INF;
        self.layer += 1;
        self.pruned_with = INF;
    }

    /// The last layer holds complete paths; their bounds are the closed-tour costs.
    fn close_tours(&mut self, model: &Model, incumbent: &mut Incumbent) {
        let mut best = (INF, usize::MAX);
        for (s, &lb) in self.current.lb.iter().enumerate() {
            if lb < best.0 {
                best = (lb, s);
            }
        }
        if best.1 == usize::MAX || best.0 >= incumbent.upper_bound {
            return;
        }
        let m = model.m;
        let mut tour = vec![0usize; m];
        tour[m - 1] = self.current.node[best.1] as usize;
        let mut parent = self.current.parent[best.1];
        for k in (0..m - 1).rev() {
            let p = parent as usize;
            tour[k] = self.past_nodes[k][p] as usize;
            parent = self.past_parents[k][p];
        }
        incumbent.upper_bound = best.0;
        incumbent.tour = Some(tour);
    }
}
