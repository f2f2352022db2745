//! The lattice of order ideals and the *pierce-group DP* bound.
//!
//! The assignment bounds (L1, L2) collapse on cutting instances: a contour has many pierce
//! points, and H1 lets a tour enter a contour at one point and leave from another for free.
//! This bound keeps that consistency up to a small tolerance. The pierce points of every
//! cluster are split into at most `K` groups of consecutive points (consecutive points lie next
//! to each other along the contour); the *group instance* has one node per group and the arc
//! cost `min` over the members. Every tour maps to a group tour that is no more expensive, so
//! the group instance's optimum bounds the original one. It is solved **exactly**, backwards
//! over the whole ideal lattice, with states `(ideal, group of the last cluster)`: a tour must
//! enter and leave a cluster through the same group. `K` is chosen from the lattice size (with
//! `K = |cluster|` the bound is the exact optimum).
//!
//! A node-level DP state `(J, x)` with `x` in cluster `L` completes at cost at least
//! `min_{Y, g ∈ groups(Y)} ( c(x, g) + V(J ∪ {Y}, g) )`.

use crate::instance::Instance;
use crate::keys::{with_key_width, ByWidth, Key, Keyed};
use crate::model::Model;
use crate::order::OrderError;
use std::rc::Rc;
use web_time::Instant;

const INF: f64 = f64::INFINITY;

/// One layer of the lattice (ideals with the same number of clusters).
#[derive(Default)]
struct LatticeLayer<const W: usize> {
    keys: Vec<Key<W>>,
    /// Children of ideal `i`: `child_start[i]..child_start[i + 1]`.
    child_start: Vec<u32>,
    child_cluster: Vec<u8>,
    child_index: Vec<u32>,
    /// Blocks (one per maximal cluster) of ideal `i`: `block_start[i]..block_start[i + 1]`.
    block_start: Vec<u32>,
    /// The maximal cluster of every block.
    block_cluster: Vec<u8>,
    /// Where a block's values (one per group of its cluster) begin in `values`.
    block_value_start: Vec<u32>,
    /// Completion bounds, rounded down to `f32`.
    values: Vec<f32>,
}

/// The full ideal lattice with the cluster-DP bound of every `(ideal, last cluster)`.
pub(crate) struct Lattice<const W: usize> {
    layers: Vec<LatticeLayer<W>>,
    /// Root bound: the cheapest tour in the relaxation.
    pub root_bound: f64,
    /// The pierce groups the bound was computed with.
    groups: Groups,
}

/// Pierce groups: consecutive nodes of a cluster merged into at most `K` groups.
pub(crate) struct Groups {
    /// Number of groups.
    count: usize,
    /// Groups of every cluster (a range of group ids).
    cluster_groups: Vec<std::ops::Range<usize>>,
    /// `count × count`: cheapest arc between the groups' members.
    cost: Vec<f64>,
    /// `n × count`: cheapest arc from a node into a group.
    node_to_group: Vec<f64>,
}

impl Groups {
    fn new(model: &Model, k_max: usize) -> Groups {
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut cluster_groups = Vec::with_capacity(model.m);
        for nodes in &model.cluster_nodes {
            let k = k_max.min(nodes.len()).max(1);
            let first = members.len();
            for t in 0..k {
                let from = t * nodes.len() / k;
                let to = (t + 1) * nodes.len() / k;
                members.push(nodes[from..to].to_vec());
            }
            cluster_groups.push(first..members.len());
        }
        let count = members.len();
        let n = model.n;
        let mut node_to_group = vec![INF; n * count];
        for x in 0..n {
            for (g, list) in members.iter().enumerate() {
                node_to_group[x * count + g] = list
                    .iter()
                    .map(|&y| if y == x { INF } else { model.arc(x, y) })
                    .fold(INF, f64::min);
            }
        }
        let mut cost = vec![INF; count * count];
        for (g1, list) in members.iter().enumerate() {
            for g2 in 0..count {
                cost[g1 * count + g2] = list
                    .iter()
                    .map(|&x| node_to_group[x * count + g2])
                    .fold(INF, f64::min);
            }
        }
        // Groups of one cluster are never consecutive in a tour.
        for range in &cluster_groups {
            for g1 in range.clone() {
                for g2 in range.clone() {
                    cost[g1 * count + g2] = INF;
                }
            }
        }
        Groups {
            count,
            cluster_groups,
            cost,
            node_to_group,
        }
    }
}

/// Rounds `v` down to an `f32` so the stored bound never exceeds the computed one.
fn down(v: f64) -> f32 {
    let f = v as f32;
    if f as f64 > v {
        f.next_down()
    } else {
        f
    }
}

/// Counts the order ideals of the model's precedence order by building the lattice's keys
/// layer by layer; `None` if there are more than `limit`.
fn count_ideals_width<const W: usize>(model: &Model, limit: usize) -> Option<usize> {
    let (pred, _) = masks::<W>(model);
    let mut layer = vec![Key::<W>([0; W]).with(model.depot)];
    let mut total = 1usize;
    for _ in 1..model.m {
        let mut next = Vec::new();
        for key in &layer {
            for (c, pred_c) in pred.iter().enumerate() {
                if !key.contains(c) && key.contains_all(pred_c) {
                    next.push(key.with(c));
                }
            }
            if next.len() > 4 * limit {
                return None;
            }
        }
        next.sort_unstable();
        next.dedup();
        total += next.len();
        if total > limit {
            return None;
        }
        layer = next;
    }
    Some(total)
}

fn masks<const W: usize>(model: &Model) -> (Vec<Key<W>>, Vec<Key<W>>) {
    let to_key =
        |set: &crate::order::ClusterSet| set.iter().fold(Key::<W>([0; W]), |k, c| k.with(c));
    let pred = model.order.predecessors.iter().map(to_key).collect();
    let succ = model.order.successors.iter().map(to_key).collect();
    (pred, succ)
}

/// Builds a [`Lattice`] in resumable slices of work ([`LatticeBuilder::advance`] with a
/// deadline), so the solver can report progress and honour a cancel flag during the build.
pub(crate) struct LatticeBuilder<const W: usize> {
    max_ideals: usize,
    max_bytes: usize,
    work_budget: usize,
    /// Give up when the budget affords fewer groups per cluster than this share of the
    /// average cluster size (the relaxation would be too coarse to help).
    min_group_share: f64,
    pred: Vec<Key<W>>,
    succ: Vec<Key<W>>,
    layers: Vec<LatticeLayer<W>>,
    ideal_count: usize,
    bytes: usize,
    stage: LatticeStage,
    /// `(child key, parent index, new cluster)` of the layer being generated.
    records: Vec<(Key<W>, u32, u8)>,
}

enum LatticeStage {
    /// Generating the children of layer `k` (0-based) from its ideal `next` on.
    Forward {
        k: usize,
        next: usize,
    },
    /// Backward pass over layer `k`, ideal `next` on.
    Backward {
        k: usize,
        next: usize,
        groups: Box<Groups>,
        k_max: usize,
        block_start: Vec<u32>,
        block_cluster: Vec<u8>,
        block_value_start: Vec<u32>,
        values: Vec<f32>,
    },
    Finished,
}

impl<const W: usize> LatticeBuilder<W> {
    /// Starts a build; it gives up (result `None`) beyond `max_ideals` ideals or `max_bytes`,
    /// or when it could afford fewer than `min_group_share` × the average cluster size groups.
    pub fn new(
        model: &Model,
        max_ideals: usize,
        max_bytes: usize,
        work_budget: usize,
        min_group_share: f64,
    ) -> LatticeBuilder<W> {
        let (pred, succ) = masks::<W>(model);
        let stage = if model.m > 255 || model.m > 64 * W {
            LatticeStage::Finished
        } else {
            LatticeStage::Forward { k: 0, next: 0 }
        };
        LatticeBuilder {
            max_ideals,
            max_bytes,
            work_budget,
            min_group_share,
            pred,
            succ,
            layers: vec![LatticeLayer {
                keys: vec![Key([0; W]).with(model.depot)],
                ..Default::default()
            }],
            ideal_count: 1,
            bytes: 0,
            stage,
            records: Vec::new(),
        }
    }

    /// Works until `deadline` (or the end). Returns `Some(result)` once finished: the lattice,
    /// or `None` if it does not fit the limits.
    pub fn advance(&mut self, model: &Model, deadline: Instant) -> Option<Option<Lattice<W>>> {
        let m = model.m;
        loop {
            match &mut self.stage {
                LatticeStage::Finished => return Some(None),
                LatticeStage::Forward { k, .. } if *k + 1 >= m => {
                    if !self.start_backward(model) {
                        self.stage = LatticeStage::Finished;
                        return Some(None);
                    }
                }
                LatticeStage::Forward { k, next } => {
                    let layer = &self.layers[*k];
                    while *next < layer.keys.len() {
                        let i = *next;
                        let key = layer.keys[i];
                        *next += 1;
                        for (c, pred_c) in self.pred.iter().enumerate() {
                            if !key.contains(c) && key.contains_all(pred_c) {
                                self.records.push((key.with(c), i as u32, c as u8));
                            }
                        }
                        if self.records.len() > 4 * self.max_ideals {
                            self.stage = LatticeStage::Finished;
                            return Some(None);
                        }
                        if *next % 256 == 0 && Instant::now() >= deadline {
                            return None;
                        }
                    }
                    let k = *k;
                    let mut records = std::mem::take(&mut self.records);
                    if !self.finish_forward_layer(k, &mut records) {
                        self.stage = LatticeStage::Finished;
                        return Some(None);
                    }
                    records.clear();
                    self.records = records;
                    if self.groups_affordable(model) < self.min_group_share * average_size(model) {
                        // Ideals only accumulate: the groups affordable can only shrink.
                        self.stage = LatticeStage::Finished;
                        return Some(None);
                    }
                    self.stage = LatticeStage::Forward { k: k + 1, next: 0 };
                    if Instant::now() >= deadline {
                        return None;
                    }
                }
                LatticeStage::Backward {
                    k,
                    next,
                    groups,
                    block_start,
                    block_cluster,
                    block_value_start,
                    values,
                    ..
                } => {
                    let depot_group = groups.cluster_groups[model.depot].start;
                    let mut scratch_max: Vec<usize> = Vec::new();
                    let mut child_values: Vec<(usize, f64)> = Vec::new();
                    let (lower, upper) = self.layers.split_at_mut(*k + 1);
                    let layer = &mut lower[*k];
                    let child_layer = upper.first();
                    while *next < layer.keys.len() {
                        let i = *next;
                        *next += 1;
                        let key = &layer.keys[i];
                        child_values.clear();
                        if let Some(child_layer) = child_layer {
                            for ch in
                                layer.child_start[i] as usize..layer.child_start[i + 1] as usize
                            {
                                let c = layer.child_cluster[ch] as usize;
                                let j = layer.child_index[ch] as usize;
                                let block = child_layer
                                    .block(j, c)
                                    .expect("new last cluster is maximal");
                                let offset = child_layer.block_value_start[block] as usize;
                                for (t, g) in groups.cluster_groups[c].clone().enumerate() {
                                    child_values.push((g, child_layer.values[offset + t] as f64));
                                }
                            }
                        }
                        scratch_max.clear();
                        scratch_max.extend(
                            key.ones()
                                .filter(|&b| b != model.depot && !intersects(key, &self.succ[b])),
                        );
                        for &b in &scratch_max {
                            block_cluster.push(b as u8);
                            block_value_start.push(values.len() as u32);
                            for gb in groups.cluster_groups[b].clone() {
                                let row = &groups.cost[gb * groups.count..(gb + 1) * groups.count];
                                let best = if *k == m - 1 {
                                    row[depot_group]
                                } else {
                                    let mut best = INF;
                                    for &(g, v) in &child_values {
                                        let w = row[g] + v;
                                        if w < best {
                                            best = w;
                                        }
                                    }
                                    best
                                };
                                values.push(if best.is_finite() {
                                    down(best)
                                } else {
                                    f32::INFINITY
                                });
                            }
                        }
                        block_start.push(block_cluster.len() as u32);
                        if *next % 64 == 0 && Instant::now() >= deadline {
                            return None;
                        }
                    }
                    self.bytes += values.len() * 4 + block_cluster.len() * 5 + layer.keys.len() * 4;
                    if self.bytes > self.max_bytes {
                        self.stage = LatticeStage::Finished;
                        return Some(None);
                    }
                    layer.block_start = std::mem::replace(block_start, vec![0]);
                    layer.block_cluster = std::mem::take(block_cluster);
                    layer.block_value_start = std::mem::take(block_value_start);
                    layer.values = std::mem::take(values);
                    *next = 0;
                    if *k > 1 {
                        *k -= 1;
                        continue;
                    }
                    let stage = std::mem::replace(&mut self.stage, LatticeStage::Finished);
                    let LatticeStage::Backward { groups, k_max, .. } = stage else {
                        unreachable!("in the backward stage");
                    };
                    if std::env::var_os("PCGTSP_DEBUG").is_some() {
                        eprintln!("[pcgtsp] lattice: {} ideals, K = {k_max}", self.ideal_count);
                    }
                    let mut lattice = Lattice {
                        layers: std::mem::take(&mut self.layers),
                        root_bound: 0.0,
                        groups: *groups,
                    };
                    lattice.root_bound = if m == 1 {
                        model.arc(model.start, model.start)
                    } else {
                        lattice.completion_bound(model, 1, 0, model.start)
                    };
                    return Some(Some(lattice));
                }
            }
        }
    }

    /// Sorts the records of layer `k` into the next layer's keys and `k`'s children.
    fn finish_forward_layer(&mut self, k: usize, records: &mut [(Key<W>, u32, u8)]) -> bool {
        records.sort_unstable();
        let layer = &self.layers[k];
        let mut keys: Vec<Key<W>> = Vec::new();
        let mut counts = vec![0u32; layer.keys.len() + 1];
        let mut child_of: Vec<u32> = Vec::with_capacity(records.len());
        for &(key, parent, _) in records.iter() {
            if keys.last() != Some(&key) {
                keys.push(key);
            }
            child_of.push((keys.len() - 1) as u32);
            counts[parent as usize + 1] += 1;
        }
        self.ideal_count += keys.len();
        self.bytes += keys.len() * (8 * W + 8) + records.len() * 5;
        if self.ideal_count > self.max_ideals || self.bytes > self.max_bytes {
            return false;
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut fill = counts.clone();
        let mut child_cluster = vec![0u8; records.len()];
        let mut child_index = vec![0u32; records.len()];
        for (r, &(_, parent, c)) in records.iter().enumerate() {
            let slot = fill[parent as usize] as usize;
            fill[parent as usize] += 1;
            child_cluster[slot] = c;
            child_index[slot] = child_of[r];
        }
        let layer = &mut self.layers[k];
        layer.child_start = counts;
        layer.child_cluster = child_cluster;
        layer.child_index = child_index;
        self.layers.push(LatticeLayer {
            keys,
            ..Default::default()
        });
        true
    }

    /// The pierce groups per cluster the work budget affords for the ideals generated so far
    /// (1–64): the backward pass costs about ideals × (children × K)².
    fn groups_affordable(&self, _model: &Model) -> f64 {
        let ideal_count = self.ideal_count;
        // Small lattices need few groups for strong pruning; more would only slow the build.
        let work_budget = self
            .work_budget
            .min(ideal_count.saturating_mul(3000).max(300_000_000));
        let children_total: usize = self.layers.iter().map(|l| l.child_cluster.len()).sum();
        let average_children = (children_total as f64 / ideal_count as f64).max(1.0);
        let per_ideal = average_children * average_children;
        (work_budget as f64 / (ideal_count as f64 * per_ideal))
            .sqrt()
            .floor()
            .clamp(1.0, 64.0)
    }

    /// Chooses the number of pierce groups from the work budget and starts the backward pass;
    /// `false` if the budget affords fewer groups than `min_group_share` asks for.
    fn start_backward(&mut self, model: &Model) -> bool {
        let last = self.layers.len() - 1;
        self.layers[last].child_start = vec![0; self.layers[last].keys.len() + 1];
        let ideal_count = self.ideal_count;
        let children_total: usize = self.layers.iter().map(|l| l.child_cluster.len()).sum();
        let average_children = (children_total as f64 / ideal_count as f64).max(1.0);
        let mut k_max = self.groups_affordable(model) as usize;
        // Memory: about average_children blocks of k values per ideal.
        while k_max > 1
            && ideal_count as f64 * average_children * k_max as f64 * 4.0 + self.bytes as f64
                > self.max_bytes as f64
        {
            k_max -= 1;
        }
        if (k_max as f64) < self.min_group_share * average_size(model) {
            if std::env::var_os("PCGTSP_DEBUG").is_some() {
                eprintln!(
                    "[pcgtsp] lattice: {ideal_count} ideals, K = {k_max} too coarse, skipped"
                );
            }
            return false;
        }
        self.stage = LatticeStage::Backward {
            k: self.layers.len() - 1,
            next: 0,
            groups: Box::new(Groups::new(model, k_max)),
            k_max,
            block_start: vec![0],
            block_cluster: Vec::new(),
            block_value_start: Vec::new(),
            values: Vec::new(),
        };
        true
    }
}

impl<const W: usize> Lattice<W> {
    /// Builds the lattice and the bound in one go; `None` if it would exceed `max_ideals`
    /// ideals or `max_bytes` of memory (then the solver falls back to the assignment bounds).
    pub fn build(
        model: &Model,
        max_ideals: usize,
        max_bytes: usize,
        work_budget: usize,
    ) -> Option<Lattice<W>> {
        let far = Instant::now() + std::time::Duration::from_secs(1 << 30);
        let mut builder = LatticeBuilder::<W>::new(model, max_ideals, max_bytes, work_budget, 0.0);
        loop {
            if let Some(result) = builder.advance(model, far) {
                return result;
            }
        }
    }

    /// Position of ideal `key` (of `size` clusters) in its layer.
    pub fn find(&self, key: &Key<W>, size: usize) -> Option<usize> {
        self.layers.get(size - 1)?.keys.binary_search(key).ok()
    }

    /// For ideal number `index` of `size` clusters: fills `out` with `(g, V(J ∪ {Y}, g))` for
    /// every group `g` of every cluster `Y` addable to the ideal.
    pub fn next_values(&self, size: usize, index: usize, out: &mut Vec<(usize, f64)>) {
        out.clear();
        let layer = &self.layers[size - 1];
        let Some(child_layer) = self.layers.get(size) else {
            return;
        };
        for ch in layer.child_start[index] as usize..layer.child_start[index + 1] as usize {
            let c = layer.child_cluster[ch] as usize;
            let j = layer.child_index[ch] as usize;
            let Some(block) = child_layer.block(j, c) else {
                continue;
            };
            let offset = child_layer.block_value_start[block] as usize;
            for (t, g) in self.groups.cluster_groups[c].clone().enumerate() {
                out.push((g, child_layer.values[offset + t] as f64));
            }
        }
    }

    /// The bound on the completion from node `x` after the ideal at position `index` of the
    /// layer of ideals with `size` clusters (not the full one).
    pub fn completion_bound(&self, model: &Model, size: usize, index: usize, x: usize) -> f64 {
        let mut values = Vec::new();
        self.next_values(size, index, &mut values);
        self.node_completion(model, &values, x)
    }

    /// `min_g ( c(x, g) + V_g )` over the `(g, V_g)` of [`Lattice::next_values`].
    #[inline]
    pub fn node_completion(&self, _model: &Model, values: &[(usize, f64)], x: usize) -> f64 {
        let count = self.groups.count;
        let row = &self.groups.node_to_group[x * count..(x + 1) * count];
        let mut best = INF;
        for &(g, v) in values {
            let w = row[g] + v;
            if w < best {
                best = w;
            }
        }
        best
    }
}

impl<const W: usize> LatticeLayer<W> {
    /// The block of ideal `index` whose last cluster is `last`.
    #[inline]
    fn block(&self, index: usize, last: usize) -> Option<usize> {
        (self.block_start[index] as usize..self.block_start[index + 1] as usize)
            .find(|&b| self.block_cluster[b] as usize == last)
    }
}

/// Average number of nodes of the clusters other than the depot.
fn average_size(model: &Model) -> f64 {
    let clustered: usize = (0..model.m)
        .filter(|&c| c != model.depot)
        .map(|c| model.cluster_nodes[c].len())
        .sum();
    clustered as f64 / (model.m.max(2) - 1) as f64
}

#[inline]
fn intersects<const W: usize>(a: &Key<W>, b: &Key<W>) -> bool {
    (0..W).any(|i| a.0[i] & b.0[i] != 0)
}

/// Counts the order ideals of an instance's precedence order (the DP's state space over
/// clusters), layer by layer; `Ok(None)` when there are more than `limit` (or more than 256
/// clusters).
pub fn count_ideals(instance: &Instance, limit: usize) -> Result<Option<usize>, OrderError> {
    let start = instance.clusters[instance.depot][0];
    let model = Model::new(instance, start)?;
    Ok(with_key_width!(model.m, |W| count_ideals_width::<W>(&model, limit)).flatten())
}

/// A lattice shared by the beam and exact engines of one run, at any key width.
pub(crate) struct SharedLattice;

impl ByWidth for SharedLattice {
    type At<const W: usize> = Option<Rc<Lattice<W>>>;
}

/// The lattice bound of one run, built once and shared by the beam and exact engines: at the
/// key width of the run's model (`None` inside when it was not built), or `None` for orders
/// too large for any key.
pub(crate) struct LatticeStore(pub Option<Keyed<SharedLattice>>);

impl LatticeStore {
    /// The lattice's root bound, when it was built.
    pub fn root_bound(&self) -> Option<f64> {
        let keyed = self.0.as_ref()?;
        crate::keys::on_keyed!(keyed, |lattice| lattice.as_ref().map(|l| l.root_bound))
    }
}
