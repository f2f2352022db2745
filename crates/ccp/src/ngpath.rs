//! A lower bound for a PCGTSP without precedence (the interval relaxation's instances): the
//! *ng-path relaxation* with Lagrangian penalties on cluster visits.
//!
//! Why it is needed: the bounds of the exact machinery either drop clusters (the subset DP
//! beyond ~20 tracked clusters) or relax the node-level consistency of a visit (assignment,
//! 1-tree: a contour "entered at one piece, left at another"). On tightly packed sheets both
//! lose the short back-and-forth between neighbouring contours that no real route can make.
//!
//! The relaxation: walks from the depot that make exactly `m` cluster visits (m = the number of
//! clusters besides the depot's) and return, each visit entering and leaving at *one* node, with
//! a memory: each cluster `c` has a neighbourhood `ng(c)` (itself and its nearest clusters), the
//! walk remembers `M ⊆ ng(current)` and may not enter a remembered cluster; entering `d` makes
//! the memory `(M ∩ ng(d)) ∪ {d}`. So a cluster cannot be revisited before the walk has been
//! away from its neighbourhood, which forbids the short loops among neighbours. Every tour
//! (each cluster once) is such a walk. With penalties λ per visit of each cluster,
//!
//! `L(λ) = min over walks W of [cost(W) − Σ_visits λ_cluster] + Σ_c λ_c ≤ cost(any tour)`,
//!
//! for every real λ (a tour visits each cluster once, so both sums cancel), hence `L(λ)` is a
//! certified lower bound of the PCGTSP optimum, and with it of the continuous route (the module
//! `bound`). The minimum is a dynamic programme over (visits so far, node, memory); subgradient
//! steps on λ (visits − 1 per cluster) raise the bound. Labels whose memory is a superset of
//! another label's at no lower value are dropped (the other allows every extension it does).
//!
//! Pruning (the minimum stays exact): before each pass a backward DP without memory gives, per
//! node and number of visits left, a lower bound on the reduced cost of any completion (every
//! ng-walk's tail is such a q-path). Known ng-walks (the last passes' walks, offered tours),
//! repriced under the pass's λ, bound the pass's minimum from above. A label whose value plus
//! its completion bound exceeds that cannot lead to a walk below it, so it is dropped; the
//! pass's minimum is the DP's minimum or, if nothing beat it, the repriced known walk.

use std::sync::Arc;

use cutroute_pcgtsp::Instance;
use web_time::{Duration, Instant};

/// One label of a layer: a walk with `k` visits ending at `node` with memory `mask` (bits over
/// the positions of `ng(cluster(node))`) and reduced cost `value`. The label it came from is
/// not kept (the DP's inner loop is leaner without it): the cheapest walk is traced back by
/// value (`cheapest_walk`).
#[derive(Clone, Copy, Debug)]
struct Label {
    node: u32,
    mask: u32,
    value: f64,
}

/// The previous layer's labels as sources of the next: per node its run of labels in the
/// layer `(node, start, end)` and its cheapest label's value; per cluster its runs and their
/// cheapest value.
struct Sources {
    runs: Vec<(usize, usize, usize)>,
    run_best: Vec<f64>,
    cluster_runs: Vec<Vec<usize>>,
    cluster_best: Vec<f64>,
}

/// A layer under way: its sources, the labels and pruned floors so far, and the next target
/// cluster.
struct LayerWork {
    sources: Sources,
    next: Vec<Label>,
    floor: Vec<f64>,
    pruned: u64,
    d: usize,
}

/// The candidate entries of one target cluster's nodes, per memory on entering it: a compact
/// table (memories in order of appearance, times targets) rather than a dense one over all
/// `2^(ng − 1)` memories, which at ng = 12 took megabytes to clear per target cluster.
struct Entries {
    /// Per memory (`mask >> 1`): its slot, `u32::MAX` when not seen for this cluster.
    slot_of: Vec<u32>,
    /// Per slot: its memory.
    masks: Vec<u32>,
    /// `values[slot * targets + t]`: the least arrival at target `t` with that memory (before
    /// the penalty).
    values: Vec<f64>,
    targets: usize,
}

impl Entries {
    fn new(width: usize) -> Entries {
        Entries {
            slot_of: vec![u32::MAX; width],
            masks: Vec::new(),
            values: Vec::new(),
            targets: 0,
        }
    }

    /// Empties the table for a cluster of `targets` nodes; slot 0 is the memory {d} alone.
    fn reset(&mut self, targets: usize) {
        for &mask in &self.masks {
            self.slot_of[(mask >> 1) as usize] = u32::MAX;
        }
        self.masks.clear();
        self.values.clear();
        self.targets = targets;
        self.slot(1);
    }

    /// The slot of memory `mask`, made on first sight.
    #[inline]
    fn slot(&mut self, mask: u32) -> usize {
        let e = &mut self.slot_of[(mask >> 1) as usize];
        if *e == u32::MAX {
            *e = self.masks.len() as u32;
            self.masks.push(mask);
            self.values
                .resize(self.values.len() + self.targets, f64::INFINITY);
        }
        *e as usize
    }

    /// Offers the arrivals `value + arcs[t]` to the targets' entries with the memory of
    /// `slot`.
    #[inline]
    fn relax(&mut self, slot: usize, value: f64, arcs: &[f32]) {
        let values = &mut self.values[slot * self.targets..(slot + 1) * self.targets];
        for (e, &arc) in values.iter_mut().zip(arcs) {
            let total = value + f64::from(arc);
            // (A select, not a branch: the loop vectorises.)
            *e = if total < *e { total } else { *e };
        }
    }

    /// The largest entry of the memory {d} over the targets.
    fn alone_max(&self) -> f64 {
        self.values[..self.targets]
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// One source node's labels as they enter a target cluster (`NgPathBound::project`): their
/// memories there and their values; `seen[mask >> 1] == round`
/// marks a memory already projected for this source (a later label with it is no cheaper).
struct Projection {
    masks: Vec<u32>,
    values: Vec<f64>,
    seen: Vec<u32>,
    round: u32,
}

/// How the memories of a cluster `c`'s labels become memories on entering `d`: by lookup in
/// two halves of the mask (an ng neighbourhood has at most 12 clusters), or `None` when the
/// memory holds `d`.
struct MemoryMap {
    forbidden: u32,
    low: [u32; 64],
    high: [u32; 64],
}

impl MemoryMap {
    #[inline]
    fn enter(&self, mask: u32) -> Option<u32> {
        (mask & self.forbidden == 0)
            .then(|| 1 | self.low[(mask & 63) as usize] | self.high[(mask >> 6) as usize & 63])
    }
}

/// Whether some memory of `masks` is a subset of `mask` (a label with it, kept before, is no
/// dearer: the new one is dominated). Chunks of 16 are tested whole, without a branch per
/// memory, so the test vectorises: it is the DP's dominance test, run for most labels, and
/// most of those it lets through are tested against every memory.
#[inline]
fn holds_subset_of(masks: &[u32], mask: u32) -> bool {
    let outside = !mask;
    let mut chunks = masks.chunks_exact(16);
    for chunk in &mut chunks {
        if chunk
            .iter()
            .fold(0, |any, &m| any | u32::from(m & outside == 0))
            != 0
        {
            return true;
        }
    }
    chunks.remainder().iter().any(|&m| m & outside == 0)
}

/// A key whose integer order is the order of the (non-NaN) values: the sign bit flipped for
/// positive values, all bits for negative ones.
#[inline]
fn order_key(value: f64) -> u64 {
    let bits = value.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

/// The value of an `order_key`.
#[inline]
fn from_order_key(key: u64) -> f64 {
    f64::from_bits(if key >> 63 == 1 {
        key & !(1 << 63)
    } else {
        !key
    })
}

/// An arc cost as the DP reads it: the nearest `f32` at or below it. Half the memory of `f64`,
/// and the DP is bound by reading the arcs (on nested.dbs at 25 mm, 2,141 nodes: 37 MB as
/// `f64`). No walk costs more than it did, so a bound of the rounded instance bounds the
/// instance.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x {
        f.next_down()
    } else {
        f
    }
}

/// The arc costs between non-depot nodes as the DP reads them (rounded down, `round_down`),
/// laid out by target cluster: for each cluster `d`, a block of `n` rows holding the arcs
/// from every node into `d`'s nodes (in member order). A layer of the DP takes one target
/// cluster at a time and reads, for each source node, the arcs into it: in the row-major
/// matrix each was a jump to another row, waiting on memory; here a source cluster's nodes
/// read one stretch of a block small enough for the cache (a pass on nested.dbs' 2,141
/// nodes: ~8 % faster).
struct ArcTable {
    /// Per non-depot cluster: where its block starts.
    block_start: Vec<usize>,
    /// Per node: its position in its cluster's member list (0 for the depot).
    slot: Vec<u32>,
    /// Per non-depot cluster: its size.
    sizes: Vec<usize>,
    arcs: Vec<f32>,
}

impl ArcTable {
    /// An unfilled table over `n` nodes into the non-depot nodes of `members` (rows are
    /// filled by [`ArcTable::fill_row`]).
    fn empty(n: usize, members: &[Vec<usize>]) -> ArcTable {
        let mut slot = vec![0u32; n];
        for nodes in members {
            for (k, &w) in nodes.iter().enumerate() {
                slot[w] = k as u32;
            }
        }
        let sizes: Vec<usize> = members.iter().map(Vec::len).collect();
        let mut block_start = Vec::with_capacity(members.len());
        let mut total = 0;
        for &size in &sizes {
            block_start.push(total);
            total += n * size;
        }
        ArcTable {
            block_start,
            slot,
            sizes,
            arcs: vec![0.0; total],
        }
    }

    /// Fills source `v`'s arcs `arc(w)` into every non-depot node `w` of `members` (a row of
    /// the matrix at a time, as it is read best).
    fn fill_row(&mut self, members: &[Vec<usize>], v: usize, arc: impl Fn(usize) -> f32) {
        for (nodes, &start) in members.iter().zip(&self.block_start) {
            let row = start + v * nodes.len();
            for (slot, &w) in self.arcs[row..row + nodes.len()].iter_mut().zip(nodes) {
                *slot = arc(w);
            }
        }
    }

    /// The arcs from node `v` into cluster `d`'s nodes, in member order.
    #[inline]
    fn arcs_into(&self, v: usize, d: usize) -> &[f32] {
        let size = self.sizes[d];
        let start = self.block_start[d] + v * size;
        &self.arcs[start..start + size]
    }

    /// The arc from `v` to the node `w` of cluster `d`.
    #[inline]
    fn get(&self, v: usize, w: usize, d: usize) -> f32 {
        self.arcs_into(v, d)[self.slot[w] as usize]
    }
}

/// The resumable subgradient search of the ng-path bound on one instance.
pub struct NgPathBound {
    n: usize,
    /// The arc costs between non-depot nodes, by target cluster (shared with the backward DP
    /// when the arcs are symmetric).
    arcs: Arc<ArcTable>,
    /// Arc costs from and to the depot (the backward DP swaps them).
    from_depot: Vec<f64>,
    to_depot: Vec<f64>,
    /// Per node: its cluster's index among the non-depot clusters (`usize::MAX` for the depot).
    cluster: Vec<usize>,
    /// Per non-depot cluster: its nodes.
    members: Vec<Vec<usize>>,
    /// Per cluster: `ng(c)`, `c` first.
    ng: Vec<Vec<usize>>,
    /// `position[c * m + x]`: position of cluster `x` in `ng(c)`, or -1.
    position: Vec<i8>,
    /// `related[c * m + d]`: whether entering `d` from `c` can depend on the memory (d in
    /// ng(c), or ng(c) and ng(d) share a cluster).
    related: Vec<bool>,
    /// `gap[c * m + d]`: the least arc cost between clusters `c` and `d` (either way).
    gap: Vec<f64>,
    /// Penalty per cluster visit.
    lambda: Vec<f64>,
    /// Layers of the DP under way (index k = k + 1 visits), each grouped by node with a
    /// node's labels cheapest first, and the layer being built.
    layers: Vec<Vec<Label>>,
    work: Option<LayerWork>,
    best: f64,
    best_lambda: Vec<f64>,
    /// Nodes of the walk of the last completed pass (for refinement), and its `L(λ)`.
    last_walk: Vec<usize>,
    last_value: f64,
    /// Subgradient step factor: the level's distance δ relative to its start (the search
    /// has converged when it is negligible).
    mu: f64,
    since_improvement: usize,
    /// The last step's direction (the deflected subgradient; empty after a restart).
    direction: Vec<f64>,
    iterations: usize,
    /// An upper bound on the instance's optimum (a known tour's cost), for the step size.
    upper: f64,
    /// `rest[k * n + v]`: a lower bound on the reduced cost of finishing a walk at node `v`
    /// with `k` more visits and the return, under this pass's λ (from the other direction's
    /// last pass); valid when `rest_ready`.
    rest: Vec<f64>,
    rest_ready: bool,
    /// `prefix_min[k * n + v]`: a lower bound (the least label, or the pruning limit where
    /// labels were pruned) on the reduced cost of reaching `v` with `k + 1` visits in this
    /// DP's last pass, under the penalties `prefix_lambda`.
    prefix_min: Vec<f64>,
    prefix_lambda: Vec<f64>,
    /// Per node, at the last layer built: a lower bound on the value of walks that went
    /// through a pruned label (+∞ where none can have).
    floor: Vec<f64>,
    /// A pass is under way, and it runs on the reversed arcs (`backward`).
    in_pass: bool,
    pass_backward: bool,
    /// Known ng-walks (node lists with their arc cost): the last passes' walks (a ring of
    /// `POOL_SIZE`) and offered tours (kept).
    pool: Vec<(f64, Vec<usize>)>,
    tours: Vec<(f64, Vec<usize>)>,
    pool_next: usize,
    /// The pass's upper bound on its minimum reduced cost (the best repriced known walk) and
    /// that walk; `f64::INFINITY` and empty when none is known (no pruning).
    pass_upper: f64,
    pass_upper_walk: Vec<usize>,
    /// Slack on the pruning test: it absorbs the rounding of the ~2m terms on either side.
    pass_margin: f64,
    /// Whether labels are pruned against the completion bound, which needs the passes to
    /// alternate between the directions (always, except in tests that compare against the
    /// plain DP).
    pruning: bool,
    /// The level's distance above the best bound (NaN before the first pass), its start, and
    /// the passes since the bound last rose or δ was halved.
    delta: f64,
    delta0: f64,
    stall: usize,
    /// The same DP on the reversed arcs (every other pass runs there): its walks are the
    /// ng-walks reversed, at the same cost (a walk may not re-enter `c` iff `c` lies in the
    /// neighbourhood of every cluster visited in between, a condition that does not depend
    /// on the direction). So each direction's labels bound the other's completions.
    backward: Option<Box<NgPathBound>>,
    /// Diagnostics: labels kept and pruned, and the time of the backward and forward DPs.
    stats: NgStats,
}

/// Counters of the ng-path DP (diagnostics, e.g. `CCP_BOUND_DEBUG`).
#[derive(Clone, Debug, Default)]
pub struct NgStats {
    /// Labels kept, over all passes.
    pub labels: u64,
    /// Labels dropped by the completion bound (not counting those never generated because a
    /// whole source cluster could not beat it).
    pub pruned: u64,
    /// Time in the passes on the reversed arcs.
    pub backward_seconds: f64,
    /// Time in the forward passes.
    pub forward_seconds: f64,
    /// How long after its deadline a step returned, at most, in seconds (the work between
    /// deadline checks: one target cluster of a layer, or a pass's closing).
    pub longest_overrun_seconds: f64,
}

/// Passes without a better bound after which the level's distance δ is halved.
const LEVEL_STALLS: usize = 6;

/// What the level's distance δ is multiplied by when a pass's value falls below the last
/// one's (the step overshot). With δ fixed until a stall, the passes after a new best kept
/// overshooting, and the bound stood still for up to 8 passes (at 25 s of ~1.7 s passes). On
/// nested.dbs' candidates at 22–35 mm, 30 passes reached 9,438–9,465 against 9,419–9,459.
const LEVEL_SHRINK: f64 = 0.9;

/// How much of the last direction a step keeps where the subgradient turns against it (1.5,
/// the value Camerini, Fratta and Maffioli recommend).
const DEFLECTION: f64 = 1.5;

/// Walks of the last passes kept for repricing (the pass's upper bound).
const POOL_SIZE: usize = 16;

/// Most clusters in a neighbourhood (the DP keeps a dense table over the memories).
pub const MAX_NG: usize = 12;
// `MemoryMap` looks a memory up in two halves of six bits.
const _: () = assert!(MAX_NG <= 12);

/// The ng-path bound being made, a stretch of the matrix's rows at a time: one piece over
/// the 4,000 nodes of nested.dbs' last stages took 0.26 s (three passes over a 128 MB
/// matrix), longer than Stop may wait. Rows give the clusters' least arcs (the
/// neighbourhoods), the starting penalties and the arc table; bands of rows then check
/// whether the arcs are symmetric, and a reversed table is filled only if they are not.
pub(crate) struct NgPathBuilder {
    n: usize,
    depot: usize,
    ng_size: usize,
    cluster: Vec<usize>,
    members: Vec<Vec<usize>>,
    /// `near[c * m + d]`: the least arc from cluster `c` into `d` so far.
    near: Vec<f64>,
    /// The given penalties, or empty: then made from `into` and `out` (per node, its
    /// cheapest arc in and out).
    lambda: Vec<f64>,
    into: Vec<f64>,
    out: Vec<f64>,
    arcs: ArcTable,
    next_row: usize,
    /// The symmetry check's next band of rows, and its verdict so far.
    next_band: usize,
    symmetric: bool,
    /// The reversed arcs' table when they are not symmetric, and its next row.
    reversed: Option<ArcTable>,
    next_reversed_row: usize,
}

/// Rows of the symmetry check compared at a time (tiles of this size, so that the columns
/// come from the cache).
const TILE: usize = 64;

impl NgPathBuilder {
    /// Prepares the making of [`NgPathBound::new`]'s bound (its arguments, and `None` in the
    /// same cases); nothing of the matrix is read yet.
    pub(crate) fn new(
        instance: &Instance,
        ng_size: usize,
        lambda: &[f64],
    ) -> Option<NgPathBuilder> {
        let n = instance.node_count;
        let depot_nodes = instance.clusters.get(instance.depot)?;
        let &[depot] = depot_nodes.as_slice() else {
            return None;
        };
        let mut members = Vec::new();
        for (c, nodes) in instance.clusters.iter().enumerate() {
            if c != instance.depot && !nodes.is_empty() {
                members.push(nodes.clone());
            }
        }
        let m = members.len();
        if m == 0 {
            return None;
        }
        let mut cluster = vec![usize::MAX; n];
        for (c, nodes) in members.iter().enumerate() {
            for &v in nodes {
                cluster[v] = c;
            }
        }
        let given = lambda.len() == m;
        Some(NgPathBuilder {
            n,
            depot,
            ng_size,
            arcs: ArcTable::empty(n, &members),
            cluster,
            members,
            near: vec![f64::INFINITY; m * m],
            lambda: if given { lambda.to_vec() } else { Vec::new() },
            into: if given {
                Vec::new()
            } else {
                vec![f64::INFINITY; n]
            },
            out: if given {
                Vec::new()
            } else {
                vec![f64::INFINITY; n]
            },
            next_row: 0,
            next_band: 0,
            symmetric: true,
            reversed: None,
            next_reversed_row: 0,
        })
    }

    /// Reads the matrix of `instance` (the one given to [`NgPathBuilder::new`]) until
    /// `deadline`, a row or a band at a time; true when everything is read.
    pub(crate) fn step(&mut self, instance: &Instance, deadline: Instant) -> bool {
        let (n, m) = (self.n, self.members.len());
        let cost = &instance.cost;
        while self.next_row < n {
            let v = self.next_row;
            let row = &cost[v * n..(v + 1) * n];
            let cv = self.cluster[v];
            // Least arc cost between clusters: the neighbourhoods are the nearest ones.
            if cv != usize::MAX {
                let near_row = &mut self.near[cv * m..(cv + 1) * m];
                for (&arc, &cw) in row.iter().zip(&self.cluster) {
                    if cw != usize::MAX && cw != cv && arc < near_row[cw] {
                        near_row[cw] = arc;
                    }
                }
            }
            if self.lambda.is_empty() {
                let mut least_out = f64::INFINITY;
                for (w, &arc) in row.iter().enumerate() {
                    if w != v {
                        self.into[w] = if arc < self.into[w] {
                            arc
                        } else {
                            self.into[w]
                        };
                        least_out = if arc < least_out { arc } else { least_out };
                    }
                }
                self.out[v] = least_out;
            }
            self.arcs.fill_row(&self.members, v, |w| round_down(row[w]));
            self.next_row += 1;
            if Instant::now() >= deadline {
                return false;
            }
        }
        // Every other pass runs backwards: on the reversed arcs (the same table when the
        // arcs between clusters are symmetric, as the interval relaxation's are).
        let depot = self.depot;
        while self.symmetric && self.next_band < n {
            let a0 = self.next_band;
            let tile = |start: usize| start..(start + TILE).min(n);
            self.symmetric = (0..=a0).step_by(TILE).all(|b0| {
                tile(a0).all(|a| {
                    tile(b0).all(|b| {
                        b >= a
                            || a == depot
                            || b == depot
                            || round_down(cost[a * n + b]) == round_down(cost[b * n + a])
                    })
                })
            });
            self.next_band += TILE;
            if Instant::now() >= deadline {
                return false;
            }
        }
        if !self.symmetric {
            let members = &self.members;
            let reversed = self
                .reversed
                .get_or_insert_with(|| ArcTable::empty(n, members));
            while self.next_reversed_row < n {
                let v = self.next_reversed_row;
                reversed.fill_row(members, v, |w| round_down(cost[w * n + v]));
                self.next_reversed_row += 1;
                if Instant::now() >= deadline {
                    return false;
                }
            }
        }
        true
    }

    /// The bound, once [`NgPathBuilder::step`] has read everything (`instance` as there).
    pub(crate) fn finish(self, instance: &Instance) -> NgPathBound {
        let (n, m, depot) = (self.n, self.members.len(), self.depot);
        let cost = &instance.cost;
        let mut near = self.near;
        // (Rounded as the DP's arcs are, once: rounding down keeps the order.)
        for x in &mut near {
            *x = f64::from(round_down(*x));
        }
        for c in 0..m {
            for d in 0..c {
                let least = near[c * m + d].min(near[d * m + c]);
                near[c * m + d] = least;
                near[d * m + c] = least;
            }
        }
        let lambda = if self.lambda.is_empty() {
            // A start near the node-penalty bound: each visit is worth half its cheapest way
            // in plus half its cheapest way out through the same node.
            self.members
                .iter()
                .map(|nodes| {
                    nodes
                        .iter()
                        .map(|&w| 0.5 * (self.into[w] + self.out[w]))
                        .fold(f64::INFINITY, f64::min)
                })
                .map(|x| if x.is_finite() { x } else { 0.0 })
                .collect()
        } else {
            self.lambda
        };
        let from_depot: Vec<f64> = (0..n)
            .map(|w| f64::from(round_down(cost[depot * n + w])))
            .collect();
        let to_depot: Vec<f64> = (0..n)
            .map(|v| f64::from(round_down(cost[v * n + depot])))
            .collect();
        let arcs = Arc::new(self.arcs);
        let reversed = match self.reversed {
            Some(table) => Arc::new(table),
            None => Arc::clone(&arcs),
        };
        let backward = NgPathBound::from_parts(
            n,
            reversed,
            to_depot.clone(),
            from_depot.clone(),
            self.cluster.clone(),
            self.members.clone(),
            near.clone(),
            self.ng_size,
            lambda.clone(),
            None,
        );
        NgPathBound::from_parts(
            n,
            arcs,
            from_depot,
            to_depot,
            self.cluster,
            self.members,
            near,
            self.ng_size,
            lambda,
            Some(Box::new(backward)),
        )
    }
}

impl NgPathBound {
    /// Prepares the bound with neighbourhoods of `ng_size` clusters (nearest by least arc cost)
    /// and initial penalties `lambda` (one per non-depot cluster, in the instance's cluster
    /// order without the depot's; when the length does not match, half of each cluster's
    /// cheapest way in and out through one node). `None` when the depot's cluster does not
    /// hold exactly one node or there is no other cluster. Made in one piece; the bound of
    /// the interval relaxation makes it in slices (`NgPathBuilder`).
    pub fn new(instance: &Instance, ng_size: usize, lambda: &[f64]) -> Option<NgPathBound> {
        let mut builder = NgPathBuilder::new(instance, ng_size, lambda)?;
        while !builder.step(instance, Instant::now() + Duration::from_secs(3600)) {}
        Some(builder.finish(instance))
    }

    /// The same bound with neighbourhoods of `ng_size` clusters from penalties `lambda`
    /// (the current best ones when the length does not match): the arc tables are shared,
    /// so this costs only the neighbourhoods, not a pass over the matrix.
    pub fn widened(&self, ng_size: usize, lambda: &[f64]) -> NgPathBound {
        let lambda = if lambda.len() == self.members.len() {
            lambda.to_vec()
        } else {
            self.best_lambda.clone()
        };
        let remake = |bound: &NgPathBound, backward: Option<Box<NgPathBound>>| {
            NgPathBound::from_parts(
                bound.n,
                Arc::clone(&bound.arcs),
                bound.from_depot.clone(),
                bound.to_depot.clone(),
                bound.cluster.clone(),
                bound.members.clone(),
                bound.gap.clone(),
                ng_size,
                lambda.clone(),
                backward,
            )
        };
        let backward = self.backward.as_ref().map(|b| Box::new(remake(b, None)));
        remake(self, backward)
    }

    /// The bound on prepared parts: neighbourhoods of `ng_size` nearest clusters by `near`,
    /// penalties `lambda`, and the completion bound's backward DP (`None` for that DP itself).
    #[allow(clippy::too_many_arguments)]
    fn from_parts(
        n: usize,
        arcs: Arc<ArcTable>,
        from_depot: Vec<f64>,
        to_depot: Vec<f64>,
        cluster: Vec<usize>,
        members: Vec<Vec<usize>>,
        near: Vec<f64>,
        ng_size: usize,
        lambda: Vec<f64>,
        backward: Option<Box<NgPathBound>>,
    ) -> NgPathBound {
        let m = members.len();
        let size = ng_size.clamp(1, MAX_NG).min(m);
        let mut ng = Vec::with_capacity(m);
        let mut position = vec![-1i8; m * m];
        for c in 0..m {
            let mut others: Vec<usize> = (0..m).filter(|&x| x != c).collect();
            others.sort_by(|&x, &y| near[c * m + x].total_cmp(&near[c * m + y]).then(x.cmp(&y)));
            let mut list = vec![c];
            list.extend(others.into_iter().take(size - 1));
            for (p, &x) in list.iter().enumerate() {
                position[c * m + x] = p as i8;
            }
            ng.push(list);
        }
        let mut related = vec![false; m * m];
        for c in 0..m {
            for d in 0..m {
                related[c * m + d] =
                    position[c * m + d] >= 0 || ng[c].iter().any(|&x| position[d * m + x] >= 0);
            }
        }
        NgPathBound {
            n,
            arcs,
            from_depot,
            to_depot,
            cluster,
            members,
            ng,
            position,
            related,
            gap: near,
            best_lambda: lambda.clone(),
            lambda,
            layers: Vec::new(),
            work: None,
            best: f64::NEG_INFINITY,
            last_walk: Vec::new(),
            last_value: f64::NEG_INFINITY,
            mu: 1.0,
            since_improvement: 0,
            direction: Vec::new(),
            iterations: 0,
            upper: f64::INFINITY,
            rest: Vec::new(),
            rest_ready: false,
            prefix_min: Vec::new(),
            prefix_lambda: Vec::new(),
            floor: Vec::new(),
            in_pass: false,
            pass_backward: false,
            pool: Vec::new(),
            tours: Vec::new(),
            pool_next: 0,
            pass_upper: f64::INFINITY,
            pass_upper_walk: Vec::new(),
            pass_margin: 0.0,
            pruning: true,
            delta: f64::NAN,
            delta0: 1.0,
            stall: 0,
            backward,
            stats: NgStats::default(),
        }
    }

    /// Offers a tour of the instance (node list, with or without the depot first, one node per
    /// non-depot cluster): every tour is an ng-walk, so repriced under λ it bounds each pass's
    /// minimum from above (labels that cannot beat it are pruned) and its cost the optimum
    /// (the step). Ignored unless it visits each cluster once.
    pub fn offer_tour(&mut self, tour: &[usize]) {
        let m = self.members.len();
        let tour = match tour.split_first() {
            Some((&first, rest)) if self.cluster.get(first) == Some(&usize::MAX) => rest,
            _ => tour,
        };
        let mut seen = vec![false; m];
        for &v in tour {
            let Some(&c) = self.cluster.get(v) else {
                return;
            };
            if c == usize::MAX || seen[c] {
                return;
            }
            seen[c] = true;
        }
        if tour.len() != m {
            return;
        }
        let cost = self.walk_cost(tour);
        if cost.is_finite() {
            self.set_upper(cost);
            self.tours.push((cost, tour.to_vec()));
        }
    }

    /// The tours offered so far (each cluster once, without the depot), for a successor on
    /// the same instance.
    pub fn offered_tours(&self) -> impl Iterator<Item = &[usize]> {
        self.tours.iter().map(|(_, tour)| tour.as_slice())
    }

    /// The arc cost of a walk from the depot through `walk` and back.
    fn walk_cost(&self, walk: &[usize]) -> f64 {
        let (Some(&first), Some(&last)) = (walk.first(), walk.last()) else {
            return f64::INFINITY;
        };
        let inner: f64 = walk
            .windows(2)
            .map(|p| f64::from(self.arcs.get(p[0], p[1], self.cluster[p[1]])))
            .sum();
        self.from_depot[first] + inner + self.to_depot[last]
    }

    /// Tells the step size about a tour's cost (an upper bound of the optimum).
    pub fn set_upper(&mut self, upper: f64) {
        if upper < self.upper {
            self.upper = upper;
        }
    }

    /// The best certified bound so far (−∞ before the first pass ends).
    pub fn lower_bound(&self) -> f64 {
        self.best
    }

    /// The penalties of the best bound (to warm-start a finer instance with the same clusters).
    pub fn best_lambda(&self) -> &[f64] {
        &self.best_lambda
    }

    /// Nodes of the cheapest walk of the last pass (pieces worth refining).
    pub fn last_walk(&self) -> &[usize] {
        &self.last_walk
    }

    /// Counters of both directions' DPs.
    pub fn stats(&self) -> NgStats {
        let mut stats = self.stats.clone();
        if let Some(back) = &self.backward {
            stats.labels += back.stats.labels;
            stats.pruned += back.stats.pruned;
        }
        stats
    }

    /// Subgradient iterations completed.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Works until `deadline` (at least one layer of the DP); false when the search has
    /// converged (the step factor is negligible) or the bound meets the upper bound.
    pub fn step(&mut self, deadline: Instant) -> bool {
        loop {
            if self.mu < 1e-4 || self.best >= self.upper - 1e-9 * self.upper.abs() {
                return false;
            }
            if !self.in_pass {
                self.begin_pass();
            }
            let began = Instant::now();
            let m = self.members.len();
            let done = match self.backward.as_mut().filter(|_| self.pass_backward) {
                Some(back) => {
                    let complete = back.extend_layer(deadline);
                    self.stats.backward_seconds += began.elapsed().as_secs_f64();
                    complete && back.layers.len() == m
                }
                None => {
                    let complete = self.extend_layer(deadline);
                    self.stats.forward_seconds += began.elapsed().as_secs_f64();
                    complete && self.layers.len() == m
                }
            };
            if done {
                self.finish_pass();
            }
            let now = Instant::now();
            if now >= deadline {
                let overrun = now.duration_since(deadline).as_secs_f64();
                self.stats.longest_overrun_seconds =
                    self.stats.longest_overrun_seconds.max(overrun);
                return true;
            }
        }
    }

    /// Prices the known walks under this pass's λ (the pass's upper bound), picks the
    /// direction (alternating, so the other direction's last pass bounds the completions) and
    /// prepares that direction's DP.
    fn begin_pass(&mut self) {
        self.pass_upper = f64::INFINITY;
        self.pass_upper_walk.clear();
        let mut best: Option<&Vec<usize>> = None;
        for (cost, walk) in self.pool.iter().chain(&self.tours) {
            let reduced = cost
                - walk
                    .iter()
                    .map(|&v| self.lambda[self.cluster[v]])
                    .sum::<f64>();
            if reduced < self.pass_upper {
                self.pass_upper = reduced;
                best = Some(walk);
            }
        }
        if let Some(walk) = best {
            self.pass_upper_walk = walk.clone();
        }
        self.pass_margin =
            1e-9 * (self.pass_upper.abs() + self.lambda.iter().map(|l| l.abs()).sum::<f64>() + 1.0);
        self.in_pass = true;
        self.pass_backward = self.pruning && self.backward.is_some() && self.iterations % 2 == 1;
        let Some(mut back) = self.backward.take() else {
            let (lambda, upper, margin) = (self.lambda.clone(), self.pass_upper, self.pass_margin);
            self.prepare(&lambda, upper, margin, None);
            return;
        };
        let (lambda, upper, margin) = (self.lambda.clone(), self.pass_upper, self.pass_margin);
        if self.pass_backward {
            back.prepare(&lambda, upper, margin, Some(&*self));
        } else {
            self.prepare(&lambda, upper, margin, Some(&back));
        }
        self.backward = Some(back);
    }

    /// Sets this DP up for a pass under `lambda` with the upper bound `upper` on its minimum:
    /// the completion bound from `other` (the opposite direction's DP) when it has run a pass.
    fn prepare(&mut self, lambda: &[f64], upper: f64, margin: f64, other: Option<&NgPathBound>) {
        let n = self.n;
        let m = self.members.len();
        self.lambda.clear();
        self.lambda.extend_from_slice(lambda);
        self.layers.clear();
        self.work = None;
        self.pass_upper = upper;
        self.pass_margin = margin;
        self.rest_ready = false;
        if let Some(other) =
            other.filter(|o| self.pruning && upper.is_finite() && o.prefix_min.len() == m * n)
        {
            // A completion with k visits costs, under the new penalties, at least its cost
            // under the old ones less k times the largest rise of a penalty (each visit's
            // penalty rose by at most that).
            let rise = lambda
                .iter()
                .zip(&other.prefix_lambda)
                .map(|(new, old)| new - old)
                .fold(0.0, f64::max);
            self.rest.resize(m * n, f64::INFINITY);
            for k in 0..m {
                for v in 0..n {
                    let c = self.cluster[v];
                    self.rest[k * n + v] = if c == usize::MAX {
                        f64::INFINITY
                    } else {
                        // The other direction's label at v includes v's own penalty.
                        other.prefix_min[k * n + v] + other.prefix_lambda[c] - k as f64 * rise
                    };
                }
            }
            self.rest_ready = true;
        }
        self.prefix_min.clear();
        self.prefix_min.resize(m * n, f64::INFINITY);
        self.prefix_lambda.clear();
        self.prefix_lambda.extend_from_slice(lambda);
    }

    /// The largest label value at `node` with `left` visits to go that can still lead to a
    /// walk below the pass's upper bound (+∞ without pruning).
    #[inline]
    fn value_limit(&self, node: usize, left: usize) -> f64 {
        if !self.rest_ready {
            return f64::INFINITY;
        }
        self.pass_upper - self.rest[left * self.n + node] + self.pass_margin
    }

    /// Records, per node, a lower bound on every walk's value at the layer being added,
    /// pruned or not (the other direction's completion bound): the least kept label, or a
    /// walk through a pruned label, whose value is at least that label's value (`floor` holds
    /// the least pruned value per node of this layer) plus the least memoryless way on from
    /// there (carried layer to layer).
    fn record_prefix(&mut self, next: &[Label], mut floor: Vec<f64>) {
        let n = self.n;
        let k = self.layers.len();
        if self.prefix_min.len() < (k + 1) * n {
            return;
        }
        if k > 0 && self.floor.iter().any(|f| f.is_finite()) {
            // Per node: the least way in from the previous layer's floors over the source
            // clusters, the best and the second best by distinct clusters (a way in from the
            // node's own cluster does not count). One target cluster at a time (a sweep over
            // its block of arcs), one source cluster's nodes at a time within it, so the inner
            // loop is a plain min-plus over a short row (vectorised).
            let sources: Vec<(usize, &Vec<usize>)> = self
                .members
                .iter()
                .enumerate()
                .filter(|(_, nodes)| nodes.iter().any(|&u| self.floor[u].is_finite()))
                .collect();
            let mut from_cluster: Vec<f64> = Vec::new();
            let mut first: Vec<(f64, usize)> = Vec::new();
            let mut second: Vec<f64> = Vec::new();
            for (d, targets) in self.members.iter().enumerate() {
                let size = targets.len();
                first.clear();
                first.resize(size, (f64::INFINITY, usize::MAX));
                second.clear();
                second.resize(size, f64::INFINITY);
                for &(c, nodes) in &sources {
                    from_cluster.clear();
                    from_cluster.resize(size, f64::INFINITY);
                    for &u in nodes {
                        let from = self.floor[u];
                        if !from.is_finite() {
                            continue;
                        }
                        let arcs = self.arcs.arcs_into(u, d);
                        for (slot, &arc) in from_cluster.iter_mut().zip(arcs) {
                            let total = from + f64::from(arc);
                            *slot = if total < *slot { total } else { *slot };
                        }
                    }
                    for ((&x, best), next) in from_cluster.iter().zip(&mut first).zip(&mut second) {
                        if x < best.0 {
                            *next = best.0;
                            *best = (x, c);
                        } else if x < *next {
                            *next = x;
                        }
                    }
                }
                for (t, &v) in targets.iter().enumerate() {
                    let way_in = if first[t].1 == d {
                        second[t]
                    } else {
                        first[t].0
                    };
                    let total = way_in - self.lambda[d];
                    if total < floor[v] {
                        floor[v] = total;
                    }
                }
            }
        }
        let layer = &mut self.prefix_min[k * n..(k + 1) * n];
        layer.fill(f64::INFINITY);
        for l in next {
            let e = &mut layer[l.node as usize];
            if l.value < *e {
                *e = l.value;
            }
        }
        for (e, &f) in layer.iter_mut().zip(&floor) {
            *e = e.min(f);
        }
        self.floor = floor;
    }

    /// The memory after entering cluster `d` from a label at cluster `c`, as a lookup table
    /// over the label's memory (bits over the positions of `ng(c)`).
    fn memory_map(&self, c: usize, d: usize) -> MemoryMap {
        let m = self.members.len();
        let p = self.position[c * m + d];
        // Position `p` of ng(c), as a bit of the memory in ng(d).
        let bit = |p: usize| -> u32 {
            match self.ng[c].get(p) {
                Some(&x) if self.position[d * m + x] >= 0 => 1 << self.position[d * m + x],
                _ => 0,
            }
        };
        let mut map = MemoryMap {
            forbidden: if p >= 0 { 1 << p } else { 0 },
            low: [0; 64],
            high: [0; 64],
        };
        for i in 1..64usize {
            let lowest = i.trailing_zeros() as usize;
            map.low[i] = map.low[i & (i - 1)] | bit(lowest);
            map.high[i] = map.high[i & (i - 1)] | bit(lowest + 6);
        }
        map
    }

    /// Works on the next layer of the DP until `deadline` (at least one target cluster); true
    /// when the layer is complete.
    fn extend_layer(&mut self, deadline: Instant) -> bool {
        let n = self.n;
        let m = self.members.len();
        let mut next: Vec<Label> = Vec::new();
        // Visits still to make after the layer being built.
        let left = m - self.layers.len() - 1;
        // Per node: the least value of a label pruned there (or a lower bound on it).
        let mut floor = vec![f64::INFINITY; n];
        if self.layers.is_empty() {
            for (d, nodes) in self.members.iter().enumerate() {
                for &w in nodes {
                    let c = self.from_depot[w];
                    if c - self.lambda[d] > self.value_limit(w, left) {
                        self.stats.pruned += 1;
                        floor[w] = c - self.lambda[d];
                        continue;
                    }
                    if c.is_finite() {
                        next.push(Label {
                            node: w as u32,
                            mask: 1,
                            value: c - self.lambda[d],
                        });
                    }
                }
            }
            self.stats.labels += next.len() as u64;
            self.record_prefix(&next, floor);
            self.layers.push(next);
            return true;
        }
        let LayerWork {
            sources,
            mut next,
            mut floor,
            mut pruned,
            d: first,
        } = match self.work.take() {
            Some(work) => work,
            None => LayerWork {
                sources: self.sources(),
                next,
                floor,
                pruned: 0,
                d: 0,
            },
        };
        let Sources {
            runs,
            run_best,
            cluster_runs,
            cluster_best,
        } = &sources;
        let prev = self.layers.last().expect("a layer");
        // Candidates per target node of one cluster, per memory on entering it (bit 0, the
        // cluster itself, is always set).
        let width = 1usize << (self.ng[0].len() - 1);
        let mut entries = Entries::new(width);
        let mut projected = Projection {
            masks: Vec::new(),
            values: Vec::new(),
            seen: vec![0; width],
            round: 0,
        };
        let mut list: Vec<(u64, u32)> = Vec::new();
        let mut kept: Vec<u32> = Vec::new();
        for d in first..m {
            if d > first && Instant::now() >= deadline {
                self.work = Some(LayerWork {
                    sources,
                    next,
                    floor,
                    pruned,
                    d,
                });
                return false;
            }

            let targets = &self.members[d];
            let penalty = self.lambda[d];
            // Per target: the largest entry (before the penalty) that survives the pruning.
            let limits: Vec<f64> = targets
                .iter()
                .map(|&w| self.value_limit(w, left) + penalty)
                .collect();
            let cap = limits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            entries.reset(targets.len());
            // The source clusters by their least possible arrival (cheapest label plus least
            // arc to d). A cluster whose arrival is no lower than every target's entry with
            // the memory {d} cannot improve any entry (that one dominates all it would add,
            // whatever their memories), nor can the clusters after it.
            let mut order: Vec<(f64, usize)> = (0..m)
                .filter(|&c| c != d && !cluster_runs[c].is_empty())
                .map(|c| (cluster_best[c] + self.gap[c * m + d], c))
                .collect();
            order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            let mut threshold = f64::INFINITY;
            for &(key, c) in &order {
                // Beyond the cap every entry it makes would be pruned.
                if key >= threshold {
                    break;
                }
                if key > cap {
                    // What this cluster and the later ones would add lies at `key` or above.
                    for &w in targets {
                        floor[w] = floor[w].min(key - penalty);
                    }
                    break;
                }
                let map = self.related[c * m + d].then(|| self.memory_map(c, d));
                for &r in &cluster_runs[c] {
                    let (v, start, end) = runs[r];
                    let arcs = self.arcs.arcs_into(v, d);
                    match &map {
                        // The memory matters: every label not dominated as it enters d.
                        Some(map) => {
                            // A label at or above this enters no target below its entry
                            // with the memory {d} alone (which dominates it there).
                            let least =
                                f64::from(arcs.iter().copied().fold(f32::INFINITY, f32::min));
                            let ceiling = entries.alone_max() - least;
                            let labels = &prev[start..end];
                            Self::project(map, labels, ceiling, &mut projected);
                            let pairs = projected.masks.iter().zip(&projected.values);
                            for (&mask, &value) in pairs {
                                let slot = entries.slot(mask);
                                entries.relax(slot, value, arcs);
                            }
                        }
                        // No cluster of ng(c) is in ng(d), nor d in ng(c): every label enters
                        // with the memory {d}, so only the cheapest counts.
                        None => {
                            entries.relax(0, run_best[r], arcs);
                        }
                    }
                }
                threshold = entries.alone_max();
            }
            let slots = entries.masks.len();
            for (t, &w) in targets.iter().enumerate() {
                list.clear();
                // The entry with the memory {d} alone (slot 0) dominates every other that is
                // no cheaper: those are dropped before the sort.
                let alone = entries.values[t];
                for slot in 0..slots {
                    let k = slot * targets.len() + t;
                    let value = entries.values[k];
                    if value == f64::INFINITY || (slot > 0 && value >= alone) {
                        // No arrival with this memory, or a dominated one.
                        continue;
                    }
                    if value > limits[t] {
                        pruned += 1;
                        floor[w] = floor[w].min(value - penalty);
                    } else {
                        list.push((order_key(value), entries.masks[slot]));
                    }
                }
                // Cheapest first: a label is dropped when one kept before it (no dearer) has
                // a subset of its memory. (By integer keys: sorting by `total_cmp` was ~9 % of
                // the DP. Of equal values the smaller memory comes first, so a subset is kept
                // before its supersets.)
                list.sort_unstable();
                kept.clear();
                for &(key, mask) in list.iter() {
                    let value = from_order_key(key);
                    if holds_subset_of(&kept, mask) {
                        continue;
                    }
                    kept.push(mask);
                    next.push(Label {
                        node: w as u32,
                        mask,
                        value: value - penalty,
                    });
                }
            }
        }
        // Made target by target, each target's labels cheapest first: the layer is grouped
        // by node, each node's labels cheapest first (`sources` and `project` rely on it).
        self.stats.labels += next.len() as u64;
        self.stats.pruned += pruned;
        self.record_prefix(&next, floor);
        self.layers.push(next);
        true
    }

    /// The previous layer's labels grouped for the next layer: per node, per cluster.
    fn sources(&self) -> Sources {
        let m = self.members.len();
        let prev = self.layers.last().expect("a layer");
        // Per source node: its labels (a contiguous run of `prev`) and its cheapest one.
        let mut runs: Vec<(usize, usize, usize)> = Vec::new(); // (node, start, end)
        let mut i = 0;
        while i < prev.len() {
            let v = prev[i].node as usize;
            let mut j = i;
            while j < prev.len() && prev[j].node as usize == v {
                j += 1;
            }
            runs.push((v, i, j));
            i = j;
        }
        // Per run: its cheapest label; per cluster: its runs and their cheapest label.
        // (A node's labels come cheapest first.)
        let run_best: Vec<f64> = runs
            .iter()
            .map(|&(_, start, _)| prev[start].value)
            .collect();
        let mut cluster_runs: Vec<Vec<usize>> = vec![Vec::new(); m];
        let mut cluster_best = vec![f64::INFINITY; m];
        for (r, &(v, _, _)) in runs.iter().enumerate() {
            let c = self.cluster[v];
            cluster_runs[c].push(r);
            cluster_best[c] = cluster_best[c].min(run_best[r]);
        }
        Sources {
            runs,
            run_best,
            cluster_runs,
            cluster_best,
        }
    }

    /// The memories of one source node's labels `labels` (cheapest first) below `ceiling` as
    /// they enter the target cluster, by `map`: into `projected` (memories and values), those
    /// dropped that a cheaper one with a subset of the memory dominates.
    fn project(map: &MemoryMap, labels: &[Label], ceiling: f64, projected: &mut Projection) {
        let Projection {
            masks,
            values,
            seen,
            round,
        } = projected;
        masks.clear();
        values.clear();
        *round = round.wrapping_add(1);
        if *round == 0 {
            seen.fill(0);
            *round = 1;
        }
        for label in labels {
            if label.value >= ceiling {
                break;
            }
            if let Some(mask) = map.enter(label.mask) {
                // The labels come cheapest first: one kept before is no dearer. (Most
                // repeat a memory already projected: that test first.)
                let stamp = &mut seen[(mask >> 1) as usize];
                if *stamp == *round || holds_subset_of(masks, mask) {
                    continue;
                }
                *stamp = *round;
                masks.push(mask);
                values.push(label.value);
            }
        }
    }

    /// The least reduced cost of this DP's pass (its last layer closed by the return arc) and
    /// its walk (empty when no walk survived); the layers are dropped.
    fn cheapest_walk(&mut self) -> (f64, Vec<usize>) {
        let mut best = (f64::INFINITY, usize::MAX);
        if let Some(last) = self.layers.last() {
            for (i, l) in last.iter().enumerate() {
                let total = l.value + self.to_depot[l.node as usize];
                if total < best.0 {
                    best = (total, i);
                }
            }
        }
        let mut walk = Vec::with_capacity(self.members.len());
        if best.1 != usize::MAX {
            let mut label = self.layers[self.layers.len() - 1][best.1];
            walk.push(label.node as usize);
            for layer in self.layers.iter().rev().skip(1) {
                let Some(before) = self.predecessor(layer, label) else {
                    // (Cannot happen; the caller then takes a known walk for the step.)
                    walk.clear();
                    break;
                };
                label = before;
                walk.push(label.node as usize);
            }
            walk.reverse();
        }
        self.layers.clear();
        (best.0, walk)
    }

    /// A label of `layer` (the one before `label`'s) that `label` extends: its value plus the
    /// arc, less the penalty, is `label`'s value to the bit (the DP's own sums), and its memory
    /// on entering `label`'s cluster is within `label`'s. Some label was extended into it, so
    /// one is found; the walk traced this way is an ng-walk of the minimum's cost.
    fn predecessor(&self, layer: &[Label], label: Label) -> Option<Label> {
        let w = label.node as usize;
        let d = self.cluster[w];
        let penalty = self.lambda[d];
        layer
            .iter()
            .find(|p| {
                let c = self.cluster[p.node as usize];
                // (The memory's table is made only for the few labels of the right value.)
                c != d
                    && p.value + f64::from(self.arcs.get(p.node as usize, w, d)) - penalty
                        == label.value
                    && self
                        .memory_map(c, d)
                        .enter(p.mask)
                        .is_some_and(|mask| mask & !label.mask == 0)
            })
            .copied()
    }

    /// Closes the walks (return arc), records the bound and takes a subgradient step.
    fn finish_pass(&mut self) {
        let m = self.members.len();
        let (mut best, mut walk) = match self.backward.as_mut().filter(|_| self.pass_backward) {
            Some(back) => {
                let (value, mut walk) = back.cheapest_walk();
                // The reversed arcs' walk, read forwards.
                walk.reverse();
                (value, walk)
            }
            None => self.cheapest_walk(),
        };
        self.in_pass = false;
        if best <= self.pass_upper && walk.len() == m {
            let cost = self.walk_cost(&walk);
            if self.pool.len() < POOL_SIZE {
                self.pool.push((cost, walk.clone()));
            } else {
                self.pool[self.pool_next] = (cost, walk.clone());
                self.pool_next = (self.pool_next + 1) % POOL_SIZE;
            }
        } else if self.pass_upper.is_finite() {
            // Nothing beat the known walk (every label that could was pruned): it is the
            // minimum. (Or the walk could not be traced: its value stands, the known walk
            // gives the step.)
            best = best.min(self.pass_upper);
            walk = self.pass_upper_walk.clone();
        }
        self.iterations += 1;
        let sum: f64 = self.lambda.iter().sum();
        let value = best + sum;
        let previous_value = self.last_value;
        self.last_value = value;
        // The DP adds ~2m terms; this margin absorbs their rounding.
        let scale: f64 = self.lambda.iter().map(|l| l.abs()).sum::<f64>() + best.abs() + 1.0;
        let certified = value - 1e-10 * scale * (m as f64 + 1.0);
        if !certified.is_finite() {
            self.mu = 0.0;
            return;
        }
        if self.best == f64::NEG_INFINITY || certified > self.best + 1e-9 * self.best.abs().max(1.0)
        {
            self.best = certified;
            self.best_lambda = self.lambda.clone();
            self.since_improvement = 0;
        } else {
            self.since_improvement += 1;
            if self.since_improvement >= 8 {
                self.since_improvement = 0;
                // Restart from the best penalties: the walk has drifted.
                self.lambda = self.best_lambda.clone();
                self.direction.clear();
            }
        }
        let mut visits = vec![0i64; m];
        for &v in &walk {
            visits[self.cluster[v]] += 1;
        }
        // The subgradient (1 − visits per cluster), deflected (Camerini, Fratta and Maffioli)
        // where it turns back against the last direction: the plain steps zig-zag, the pass's
        // value falling every other pass. On nested.dbs' 2,141 candidates at ng = 12, 20
        // passes reached 9,416 against 9,317 (0.2 s more per pass: 9,386 against 9,317 at 35
        // s); on a 1,600-piece relaxation at ng = 8, level at equal time.
        let mut direction: Vec<f64> = visits.iter().map(|&k| (1 - k) as f64).collect();
        if self.direction.len() == m {
            let turn: f64 = direction
                .iter()
                .zip(&self.direction)
                .map(|(g, d)| g * d)
                .sum();
            let length: f64 = self.direction.iter().map(|d| d * d).sum();
            if turn < 0.0 && length > 0.0 {
                let beta = -DEFLECTION * turn / length;
                for (g, d) in direction.iter_mut().zip(&self.direction) {
                    *g += beta * d;
                }
            }
        }
        let norm: f64 = direction.iter().map(|g| g * g).sum();
        self.last_walk = walk;
        if norm == 0.0 {
            // The walk is a tour: the bound is its cost, the optimum.
            self.mu = 0.0;
            return;
        }
        // Polyak steps towards a level `best + δ` rather than the upper bound: the upper bound
        // (the incumbent's relaxed cost) lies far above `max L(λ)` when the relaxation has a
        // duality gap, and steps aimed at it overshoot. δ starts at a quarter of the gap to the
        // upper bound, shrinks by `LEVEL_SHRINK` after each pass whose value fell, and halves
        // after `LEVEL_STALLS` passes without a better bound; the step
        // factor `mu` (δ relative to its start) tells when the search has converged. (On a
        // fixed 1,600-piece relaxation of nested.dbs: 7,316 after 10 passes and 7,732 after
        // 25, against 6,972 and 7,533 aiming at the upper bound.)
        if self.delta.is_nan() {
            self.delta = if self.upper.is_finite() {
                0.25 * (self.upper - self.best).max(1e-3 * value.abs().max(1.0))
            } else {
                0.05 * value.abs().max(1.0)
            };
            self.delta0 = self.delta;
        }
        if self.iterations > 1 && value < previous_value {
            // The step overshot: the level was too far above `max L(λ)`.
            self.delta *= LEVEL_SHRINK;
        }
        if self.since_improvement == 0 && self.iterations > 1 {
            self.stall = 0;
        } else {
            self.stall += 1;
            if self.stall >= LEVEL_STALLS {
                self.delta *= 0.5;
                self.stall = 0;
            }
        }
        self.mu = self.delta / self.delta0;
        let target = (self.best + self.delta).min(self.upper);
        let t = (target - value).max(1e-3 * self.delta) / norm;
        for (l, &g) in self.lambda.iter_mut().zip(&direction) {
            *l += t * g;
        }
        self.direction = direction;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::SplitMix64;
    use web_time::Duration;

    /// A random instance: points in clusters (each cluster's nodes near one centre, like the
    /// pieces of a contour), Euclidean costs, an asymmetric return arc (the tail).
    fn random_instance(seed: u64, clusters: usize, per: usize) -> Instance {
        random_instance_skewed(seed, clusters, per, 0.0)
    }

    /// As `random_instance`, each arc between clusters stretched by up to `skew` (relative,
    /// drawn per direction: asymmetric arcs when positive).
    fn random_instance_skewed(seed: u64, clusters: usize, per: usize, skew: f64) -> Instance {
        let mut rng = SplitMix64::new(seed);
        let mut points = vec![(0.0, 0.0)];
        let mut node_cluster = vec![0];
        let mut list = vec![vec![0]];
        for c in 1..=clusters {
            let (cx, cy) = (rng.next_f64() * 100.0, rng.next_f64() * 100.0);
            let mut nodes = Vec::new();
            for _ in 0..1 + (rng.next_f64() * per as f64) as usize {
                nodes.push(points.len());
                node_cluster.push(c);
                points.push((cx + rng.next_f64() * 15.0, cy + rng.next_f64() * 15.0));
            }
            list.push(nodes);
        }
        let n = points.len();
        let mut cost = vec![f64::INFINITY; n * n];
        for a in 0..n {
            for b in 0..n {
                if node_cluster[a] == node_cluster[b] {
                    continue;
                }
                let (p, q) = (points[a], points[b]);
                let d = ((p.0 - q.0).powi(2) + (p.1 - q.1).powi(2)).sqrt();
                // The return arc: a tail cheaper than the straight way back.
                cost[a * n + b] = if b == 0 {
                    0.3 * d
                } else {
                    d * (1.0 + skew * rng.next_f64())
                };
            }
        }
        Instance {
            name: "random".into(),
            node_count: n,
            cost,
            clusters: list,
            node_cluster,
            precedence: Vec::new(),
            depot: 0,
        }
    }

    /// The optimum by enumeration of cluster orders and nodes (DP over subsets).
    fn brute_force(instance: &Instance) -> f64 {
        let n = instance.node_count;
        let m = instance.clusters.len() - 1;
        let full = (1usize << m) - 1;
        let mut f = vec![f64::INFINITY; (1 << m) * n];
        for c in 1..=m {
            for &w in &instance.clusters[c] {
                f[(1 << (c - 1)) * n + w] = instance.cost[w];
            }
        }
        for set in 1..=full {
            for v in 1..n {
                let value = f[set * n + v];
                if !value.is_finite() {
                    continue;
                }
                for d in 1..=m {
                    if set & (1 << (d - 1)) != 0 {
                        continue;
                    }
                    for &w in &instance.clusters[d] {
                        let next = set | (1 << (d - 1));
                        let total = value + instance.cost[v * n + w];
                        if total < f[next * n + w] {
                            f[next * n + w] = total;
                        }
                    }
                }
            }
        }
        (1..n)
            .map(|v| f[full * n + v] + instance.cost[v * n])
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn the_arc_table_holds_every_arc_by_target_cluster() {
        // Clusters whose nodes interleave (not consecutive), and a depot (node 0) outside them.
        let n = 23;
        let members: Vec<Vec<usize>> = (0..4)
            .map(|c| (1..n).filter(|v| v % 4 == c).collect())
            .collect();
        let arc = |v: usize, w: usize| (v * 31 + w * 7) as f32 + 0.25;
        let mut table = ArcTable::empty(n, &members);
        for v in 0..n {
            table.fill_row(&members, v, |w| arc(v, w));
        }
        for v in 0..n {
            for (d, nodes) in members.iter().enumerate() {
                let into = table.arcs_into(v, d);
                assert_eq!(into.len(), nodes.len());
                for (&w, &a) in nodes.iter().zip(into) {
                    assert_eq!(a, arc(v, w), "{v} -> {w} in the block of cluster {d}");
                    assert_eq!(table.get(v, w, d), arc(v, w));
                }
            }
        }
    }

    #[test]
    fn arcs_are_rounded_down_to_the_nearest_f32() {
        let mut rng = SplitMix64::new(7);
        for i in 0..100_000i32 {
            // Lengths over many scales, exact f32 values among them.
            let x = match i % 4 {
                0 => rng.next_f64() * 10f64.powi(i % 13 - 3),
                1 => f64::from((rng.next_f64() * 1e4) as f32),
                2 => -rng.next_f64() * 100.0,
                _ => rng.next_f64(),
            };
            let r = f64::from(round_down(x));
            assert!(r <= x, "{x} rounded up to {r}");
            // The nearest below: the next f32 up is above x.
            assert!(
                f64::from(round_down(x).next_up()) > x,
                "{x} rounded to {r}, too low"
            );
        }
        assert_eq!(round_down(f64::INFINITY), f32::INFINITY);
        assert_eq!(round_down(0.0), 0.0);
    }

    #[test]
    fn never_above_the_optimum_and_close_to_it_with_full_memory() {
        let mut closed_at_least_once = 0;
        for seed in 0..40u64 {
            let clusters = 3 + (seed % 6) as usize;
            let instance = random_instance(seed, clusters, 3);
            let optimum = brute_force(&instance);
            for ng_size in [1, 2, 4, clusters] {
                let mut bound = NgPathBound::new(&instance, ng_size, &[]).unwrap();
                bound.set_upper(optimum);
                let mut iterations = 0;
                while iterations < 300 {
                    // Every pass's bound is checked, not only the last one.
                    let more = bound.step(Instant::now() + Duration::from_micros(1));
                    let lb = bound.lower_bound();
                    assert!(
                        lb <= optimum + 1e-9,
                        "seed {seed}, ng {ng_size}: bound {lb} above the optimum {optimum}"
                    );
                    if !more {
                        break;
                    }
                    iterations = bound.iterations();
                }
                if ng_size == clusters && bound.lower_bound() >= optimum - 1e-6 * optimum {
                    closed_at_least_once += 1;
                }
                // With the whole instance as memory the walks are tours; the bound without
                // penalties is then the optimum itself.
                if ng_size == clusters {
                    let mut plain = NgPathBound::new(&instance, ng_size, &[]).unwrap();
                    while plain.iterations() == 0 {
                        plain.step(Instant::now());
                    }
                    assert!(plain.lower_bound() <= optimum + 1e-9);
                    assert!(
                        plain.lower_bound() >= optimum - 1e-6 * optimum,
                        "seed {seed}: full memory gives {} for {optimum}",
                        plain.lower_bound()
                    );
                }
            }
        }
        assert!(closed_at_least_once >= 30, "{closed_at_least_once}");
    }

    /// The walk of `bound`'s last pass (under the penalties `lambda`) is an ng-walk (each
    /// cluster entered only when not remembered) whose value is the pass's value: the walk
    /// traced back from the minimum is the minimum's.
    fn assert_walk_of_the_pass(bound: &NgPathBound, lambda: &[f64], context: &str) {
        let walk = bound.last_walk();
        assert_eq!(walk.len(), bound.members.len(), "{context}");
        let mut memory: Vec<usize> = Vec::new();
        for &v in walk {
            let d = bound.cluster[v];
            assert!(!memory.contains(&d), "{context}: {walk:?} re-enters {d}");
            memory.retain(|x| bound.ng[d].contains(x));
            memory.push(d);
        }
        let reduced =
            bound.walk_cost(walk) - walk.iter().map(|&v| lambda[bound.cluster[v]]).sum::<f64>();
        let value = reduced + lambda.iter().sum::<f64>();
        let scale = 1e-9 * (value.abs() + lambda.iter().map(|l| l.abs()).sum::<f64>() + 1.0);
        assert!(
            (value - bound.last_value).abs() <= scale,
            "{context}: walk {value} against the pass's {}",
            bound.last_value
        );
    }

    /// Runs `bound` until its pass under way (or the next one) ends.
    fn one_pass(bound: &mut NgPathBound) {
        let done = bound.iterations();
        while bound.iterations() == done {
            bound.step(Instant::now());
        }
    }

    #[test]
    fn pruning_and_alternating_directions_keep_each_pass_minimum_exact() {
        let mut pruned_some = 0;
        for seed in 0..48u64 {
            let clusters = 3 + (seed % 7) as usize;
            // Every third instance has asymmetric arcs (the backward DP on a transposed copy).
            let skew = if seed % 3 == 0 { 0.4 } else { 0.0 };
            let instance = random_instance_skewed(seed, clusters, 4, skew);
            let optimum = brute_force(&instance);
            let ng_size = [2, 3, 4][(seed % 3) as usize];
            let mut fast = NgPathBound::new(&instance, ng_size, &[]).unwrap();
            if seed % 2 == 0 {
                // A tour to reprice from the first pass on: clusters in order, first nodes.
                let tour: Vec<usize> = instance.clusters[1..].iter().map(|c| c[0]).collect();
                fast.offer_tour(&tour);
            }
            let mut plain = NgPathBound::new(&instance, ng_size, &[]).unwrap();
            plain.pruning = false;
            for pass in 0..40 {
                if fast.mu < 1e-4 {
                    break;
                }
                let lambda = fast.lambda.clone();
                one_pass(&mut fast);
                assert_walk_of_the_pass(&fast, &lambda, &format!("seed {seed}, pass {pass}"));
                // The same penalties, the plain DP (forwards, nothing pruned).
                plain.lambda.clone_from(&lambda);
                plain.mu = 1.0;
                one_pass(&mut plain);
                assert_walk_of_the_pass(&plain, &lambda, &format!("seed {seed}, plain {pass}"));
                let scale = 1e-9 * (plain.last_value.abs() + 1.0);
                assert!(
                    (fast.last_value - plain.last_value).abs() <= scale,
                    "seed {seed}, pass {pass}: pruned {} against plain {}",
                    fast.last_value,
                    plain.last_value
                );
                assert!(fast.lower_bound() <= optimum + 1e-9, "seed {seed}");
            }
            if fast.stats().pruned > 0 {
                pruned_some += 1;
            }
        }
        // The test exercises the pruning, not only the plain DP.
        assert!(pruned_some >= 16, "{pruned_some}");
    }

    /// The bound's fields that its making sets (arcs, the depot's ways, neighbourhoods,
    /// penalties), of it and of its backward DP.
    fn made_parts(bound: &NgPathBound) -> Vec<String> {
        let mut parts = Vec::new();
        let mut b = Some(bound);
        while let Some(x) = b {
            parts.push(format!(
                "{:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?}",
                x.arcs.arcs, x.from_depot, x.to_depot, x.cluster, x.ng, x.gap, x.lambda, x.related
            ));
            b = x.backward.as_deref();
        }
        parts
    }

    /// Runs both bounds pass by pass (up to 4, or until they end) and checks that each pass
    /// gives both the same value.
    fn assert_same_passes(a: &mut NgPathBound, b: &mut NgPathBound, context: &str) {
        for pass in 0..4 {
            let done = a.iterations();
            let mut running = (true, true);
            while a.iterations() == done && running.0 {
                running.0 = a.step(Instant::now());
            }
            while b.iterations() == done && running.1 {
                running.1 = b.step(Instant::now());
            }
            assert_eq!(a.iterations(), b.iterations(), "{context}, pass {pass}");
            assert_eq!(a.last_value, b.last_value, "{context}, pass {pass}");
            assert_eq!(a.lower_bound(), b.lower_bound(), "{context}, pass {pass}");
            if !running.0 || !running.1 {
                assert_eq!(running.0, running.1, "{context}, pass {pass}");
                return;
            }
        }
    }

    /// Checks the made bound's fields against `instance` directly: every arc (and the
    /// backward DP's reversed one) rounded down, the depot's ways, the least arc between
    /// clusters either way, and the penalties (`lambda`, or half the cheapest way in and out).
    fn assert_made_from(bound: &NgPathBound, instance: &Instance, lambda: &[f64], context: &str) {
        let n = instance.node_count;
        let cost = |v: usize, w: usize| instance.cost[v * n + w];
        let backward = bound.backward.as_deref().expect("a backward DP");
        let m = bound.members.len();
        let mut gap = vec![f64::INFINITY; m * m];
        for (d, nodes) in bound.members.iter().enumerate() {
            for v in 0..n {
                for &w in nodes {
                    assert_eq!(bound.arcs.get(v, w, d), round_down(cost(v, w)), "{context}");
                    // (The depot's ways are `from_depot` and `to_depot`, swapped backwards.)
                    if v != 0 {
                        let reversed = backward.arcs.get(v, w, d);
                        assert_eq!(reversed, round_down(cost(w, v)), "{context}");
                    }
                    let c = bound.cluster[v];
                    if c != usize::MAX && c != d {
                        let least = f64::from(round_down(cost(v, w).min(cost(w, v))));
                        gap[c * m + d] = gap[c * m + d].min(least);
                        gap[d * m + c] = gap[d * m + c].min(least);
                    }
                }
            }
        }
        assert_eq!(bound.gap, gap, "{context}");
        for v in 0..n {
            assert_eq!(
                bound.from_depot[v],
                f64::from(round_down(cost(0, v))),
                "{context}"
            );
            assert_eq!(
                bound.to_depot[v],
                f64::from(round_down(cost(v, 0))),
                "{context}"
            );
        }
        let expected: Vec<f64> = if lambda.len() == m {
            lambda.to_vec()
        } else {
            let least = |w: usize, into: bool| {
                (0..n)
                    .filter(|&u| u != w)
                    .map(|u| if into { cost(u, w) } else { cost(w, u) })
                    .fold(f64::INFINITY, f64::min)
            };
            bound
                .members
                .iter()
                .map(|nodes| {
                    nodes
                        .iter()
                        .map(|&w| 0.5 * (least(w, true) + least(w, false)))
                        .fold(f64::INFINITY, f64::min)
                })
                .map(|x| if x.is_finite() { x } else { 0.0 })
                .collect()
        };
        assert_eq!(bound.lambda, expected, "{context}");
    }

    #[test]
    fn made_a_row_at_a_time_it_equals_the_bound_made_at_once() {
        for seed in 0..12u64 {
            // Every other instance has asymmetric arcs (a reversed table of its own); one in
            // three gets penalties to start from, the others make theirs.
            let skew = if seed % 2 == 0 { 0.4 } else { 0.0 };
            // (Past 128 nodes for the later seeds: the symmetry check takes several bands.)
            let per = if seed < 6 { 12 } else { 60 };
            let mut instance = random_instance_skewed(seed, 4 + (seed % 5) as usize, per, skew);
            // Symmetric but for one arc between the last two clusters, far past the first
            // band of the check (odd seeds from 7).
            let one_asymmetric = seed >= 7 && skew == 0.0;
            if one_asymmetric {
                let n = instance.node_count;
                let last = instance.clusters.len() - 1;
                let (a, b) = (n - 1, *instance.clusters[last - 1].last().unwrap());
                assert!(b >= 2 * TILE && instance.node_cluster[a] != instance.node_cluster[b]);
                instance.cost[a * n + b] += 1.0;
            }
            let m = instance.clusters.len() - 1;
            let lambda: Vec<f64> = if seed % 3 == 0 {
                (0..m).map(|c| c as f64 * 0.5).collect()
            } else {
                Vec::new()
            };
            let at_once = NgPathBound::new(&instance, 3, &lambda).unwrap();
            let mut builder = NgPathBuilder::new(&instance, 3, &lambda).unwrap();
            // A deadline already past: one row (or one band of the check) per step.
            let mut steps = 1;
            while !builder.step(&instance, Instant::now()) {
                steps += 1;
            }
            assert!(
                steps >= instance.node_count,
                "seed {seed}: {steps} steps for {} rows",
                instance.node_count
            );
            let mut in_pieces = builder.finish(&instance);
            assert_eq!(made_parts(&in_pieces), made_parts(&at_once), "seed {seed}");
            assert_made_from(&in_pieces, &instance, &lambda, &format!("seed {seed}"));
            assert_eq!(
                Arc::ptr_eq(&in_pieces.arcs, &in_pieces.backward.as_ref().unwrap().arcs),
                skew == 0.0 && !one_asymmetric,
                "seed {seed}: the reversed table is shared exactly when the arcs are symmetric"
            );
            let mut at_once = at_once;
            assert_same_passes(&mut in_pieces, &mut at_once, &format!("seed {seed}"));
        }
    }

    #[test]
    fn widened_equals_the_wider_bound_made_anew() {
        for seed in 0..8u64 {
            let skew = if seed % 2 == 0 { 0.4 } else { 0.0 };
            let instance = random_instance_skewed(seed, 6, 4, skew);
            let mut narrow = NgPathBound::new(&instance, 2, &[]).unwrap();
            for _ in 0..2 {
                let done = narrow.iterations();
                while narrow.iterations() == done && narrow.step(Instant::now()) {}
            }
            let lambda = narrow.best_lambda().to_vec();
            let mut widened = narrow.widened(5, &lambda);
            let mut anew = NgPathBound::new(&instance, 5, &lambda).unwrap();
            assert_eq!(made_parts(&widened), made_parts(&anew), "seed {seed}");
            assert_same_passes(&mut widened, &mut anew, &format!("seed {seed}"));
        }
    }

    #[test]
    fn a_depot_cluster_of_several_nodes_is_refused() {
        let mut instance = random_instance(1, 3, 2);
        instance.clusters[0].push(1);
        assert!(NgPathBound::new(&instance, 4, &[]).is_none());
    }
}
