//! The *subset DP* bound: an exact node-level DP, run backwards, over the clusters of a subset.
//!
//! The pierce-group bound of [`crate::lattice`] relaxes where a tour enters and leaves a cluster;
//! on cutting instances that relaxation is weak (a contour's pierce points lie far apart). This
//! bound keeps node-level consistency exactly and relaxes the *set* instead: a subset `T` of the
//! clusters (always with the depot) is **tracked**, the others are **dropped**. The relaxed
//! problem visits only the tracked clusters, in an order allowed by the precedence order
//! restricted to `T`, with arc costs `c'(a, b)` = the cheapest path from `a` to `b` whose
//! intermediate nodes all lie in dropped clusters (Floyd–Warshall restricted to those nodes).
//! Any real completion, read on the tracked clusters only, is such a relaxed path and costs no
//! less, because the pieces between tracked visits pass only through dropped nodes. Hence
//! `H(J ∩ T, x)` — the cheapest relaxed completion from node `x` — bounds every completion of a
//! DP state `(J, x)`. With `T` = every cluster it is the exact completion cost.
//!
//! Dropped clusters are not free: each carries a penalty `λ_Y ≥ 0` (Lagrangian style). A walk
//! through dropped nodes earns `λ` at every node it passes, and the bound adds back the `λ` of
//! every dropped cluster the state has not visited. A real completion visits each of those
//! exactly once, so its relaxed value is exactly its cost: the bound is valid for *any* `λ ≥ 0`;
//! `λ_Y = min_{y ∈ Y} (in(y) + out(y)) / 2` is the largest choice that keeps every cycle
//! non-negative (so the restricted Floyd–Warshall stays finite). On e1x_4 (15 of 24 clusters
//! tracked) it lifts the root bound from 64 % to 96 % of the optimum.
//!
//! `H` is computed exactly over the ideals of the restricted order (states: ideal, maximal
//! cluster, node). Which clusters are dropped is chosen from the incumbent tour: those whose
//! visit costs the least detour go first, until the backward pass fits the work budget.

use crate::model::Model;
use web_time::Instant;

const INF: f64 = f64::INFINITY;

/// The completion bounds of one tracked subset.
pub(crate) struct SubsetBound {
    /// Tracked clusters by local index (local index 0 is the depot).
    tracked: Vec<usize>,
    /// Local index of every cluster, `u8::MAX` if dropped.
    local_of: Vec<u8>,
    /// Local predecessor masks (restricted order).
    local_pred: Vec<u64>,
    /// Per tracked cluster (local): `n × |cluster|` relaxed costs `c'(x, y)`.
    into: Vec<Vec<f64>>,
    /// `c'(x, start)` for every node `x`.
    to_start: Vec<f64>,
    /// Ideals (local bitmasks) of every size, sorted.
    layers: Vec<Vec<u64>>,
    /// Global index of the first ideal of every layer.
    layer_offset: Vec<usize>,
    /// Blocks of global ideal `i`: `block_start[i]..block_start[i + 1]`.
    block_start: Vec<u32>,
    /// Local maximal cluster of every block.
    block_cluster: Vec<u8>,
    /// Where a block's values (one per node of its cluster) begin.
    block_value: Vec<u32>,
    /// `H(ideal, x)` for the nodes `x` of the block's cluster.
    values: Vec<f64>,
    /// The full tracked mask.
    full: u64,
    /// Dropped clusters with a positive penalty `λ` (what visiting them costs at least).
    dropped: Vec<(usize, f64)>,
    /// `H` at the root: a lower bound on the optimum.
    pub root_bound: f64,
}

/// What a forward DP record needs to bound its states: the tracked ideal `J ∩ T` and, for a
/// dropped last cluster, the `(cluster, values)` of every tracked cluster that may come next.
pub(crate) struct SubsetQuery {
    /// Global index of `J ∩ T`, `None` if it is not an ideal of the restricted order (cannot
    /// happen for real ideals; then no bound is used).
    ideal: Option<usize>,
    mask: u64,
    /// Local cluster and values offset of every child block (for dropped last clusters).
    children: Vec<(u8, u32)>,
    /// The record's last cluster is tracked: its block's values offset.
    own_block: Option<u32>,
    /// The penalties of the dropped clusters the record's ideal has not visited.
    unvisited_penalty: f64,
}

impl Default for SubsetQuery {
    fn default() -> Self {
        SubsetQuery {
            ideal: None,
            mask: 0,
            children: Vec::new(),
            own_block: None,
            unvisited_penalty: 0.0,
        }
    }
}

/// Counts the work of the backward pass over the ideals of the order restricted to `tracked`
/// (local predecessor masks `pred`, cluster sizes `size`); `None` once it exceeds `limit`.
fn backward_work(pred: &[u64], size: &[usize], limit: f64) -> Option<Vec<Vec<u64>>> {
    let t = pred.len();
    let mut succ = vec![0u64; t];
    for (c, &p) in pred.iter().enumerate() {
        for (d, s) in succ.iter_mut().enumerate() {
            if p >> d & 1 == 1 {
                *s |= 1 << c;
            }
        }
    }
    let mut layers = vec![vec![1u64]];
    // Every ideal costs at least `t` steps (children and blocks), on top of the node pairs.
    let mut work = t as f64;
    for _ in 1..t {
        let mut next = Vec::new();
        for &key in layers.last().expect("root layer") {
            for (c, &p) in pred.iter().enumerate() {
                if key >> c & 1 == 0 && key & p == p {
                    next.push(key | 1 << c);
                }
            }
            if work + (next.len() * t) as f64 > 2.0 * limit {
                return None;
            }
        }
        next.sort_unstable();
        next.dedup();
        for &key in &next {
            let (mut last, mut add) = (0usize, 0usize);
            for c in 1..t {
                if key >> c & 1 == 1 {
                    if key & succ[c] == 0 {
                        last += size[c];
                    }
                } else if key & pred[c] == pred[c] {
                    add += size[c];
                }
            }
            work += (last * add.max(1) + t) as f64;
        }
        if work > limit {
            return None;
        }
        layers.push(next);
    }
    Some(layers)
}

/// Builds a [`SubsetBound`] in resumable slices of work, so a caller can report progress and
/// honour a cancel flag while it runs (the solver calls [`SubsetBuilder::advance`] with a
/// deadline; every slice is a few milliseconds).
pub(crate) struct SubsetBuilder {
    stage: Stage,
    work_budget: f64,
    detour_order: Vec<usize>,
}

enum Stage {
    /// Trying to track `detour_order[next]` next; `best` is the largest subset that fitted.
    Choose {
        next: usize,
        failures: usize,
        is_tracked: Vec<bool>,
        best: Option<(Vec<usize>, Vec<Vec<u64>>)>,
    },
    /// The penalties of the dropped clusters from `next_cluster` on, then the rows of the
    /// distance table from `dist.len() / n` on, are still to be made (each an n² pass: 0.9 s
    /// in one piece on seven.dbs at 25 mm).
    Penalties {
        bound: Box<SubsetBound>,
        dist: Vec<f64>,
        penalty: Vec<f64>,
        dropped_nodes: Vec<usize>,
        next_cluster: usize,
    },
    /// Restricted Floyd–Warshall: `dropped_nodes[next..]` are still to be relaxed through.
    Distances {
        bound: Box<SubsetBound>,
        dist: Vec<f64>,
        penalty: Vec<f64>,
        dropped_nodes: Vec<usize>,
        next: usize,
    },
    /// Backward pass: ideals of `size` clusters from position `next` on are still to be done.
    Backward {
        bound: Box<SubsetBound>,
        local_succ: Vec<u64>,
        size: usize,
        next: usize,
        rev_blocks: Vec<(u8, u32)>,
        rev_values: Vec<f64>,
        ideal_blocks: Vec<(u32, u32)>,
    },
    Finished,
}

impl SubsetBuilder {
    /// Starts a build that chooses the tracked subset from `tour` (0-based nodes from the start
    /// node; may be `None`) and spends about `work_budget` elementary steps on the backward pass.
    pub fn new(model: &Model, tour: Option<&[usize]>, work_budget: f64) -> SubsetBuilder {
        let m = model.m;
        // Detour of every cluster in the tour: what skipping it would save.
        let mut detour = vec![0.0f64; m];
        if let Some(tour) = tour.filter(|t| t.len() == m) {
            for i in 1..m {
                let (a, y, b) = (tour[i - 1], tour[i], tour[(i + 1) % m]);
                let through = model.arc(a, y) + model.arc(y, b);
                detour[model.node_cluster[y]] = through - model.arc(a, b).min(through);
            }
        } else {
            for (c, d) in detour.iter_mut().enumerate() {
                *d = model.cluster_nodes[c].len() as f64;
            }
        }
        // Track the clusters with the largest detours first, while the backward pass fits.
        let mut detour_order: Vec<usize> = (0..m).filter(|&c| c != model.depot).collect();
        detour_order.sort_by(|&a, &b| detour[b].total_cmp(&detour[a]).then(a.cmp(&b)));
        let mut is_tracked = vec![false; m];
        is_tracked[model.depot] = true;
        SubsetBuilder {
            stage: Stage::Choose {
                next: 0,
                failures: 0,
                is_tracked,
                best: None,
            },
            work_budget,
            detour_order,
        }
    }

    /// Works until `deadline` (or the end). Returns `Some(result)` once finished: the bound, or
    /// `None` if not even one cluster besides the depot fits the budget.
    pub fn advance(&mut self, model: &Model, deadline: Instant) -> Option<Option<SubsetBound>> {
        loop {
            match &mut self.stage {
                Stage::Choose {
                    next,
                    failures,
                    is_tracked,
                    best,
                } => {
                    let tracked_count = is_tracked.iter().filter(|&&t| t).count();
                    if *next >= self.detour_order.len() || *failures >= 3 || tracked_count >= 64 {
                        let Some((tracked, layers)) = best.take() else {
                            self.stage = Stage::Finished;
                            return Some(None);
                        };
                        self.stage = SubsetBound::start_distances(model, tracked, layers);
                        continue;
                    }
                    let candidate = self.detour_order[*next];
                    *next += 1;
                    is_tracked[candidate] = true;
                    let tracked: Vec<usize> = model
                        .order
                        .topological
                        .iter()
                        .copied()
                        .filter(|&c| is_tracked[c])
                        .collect();
                    let local_of = local_indices(model.m, &tracked);
                    let pred = local_predecessors(model, &tracked, &local_of);
                    let size: Vec<usize> = tracked
                        .iter()
                        .map(|&c| model.cluster_nodes[c].len())
                        .collect();
                    match backward_work(&pred, &size, self.work_budget) {
                        Some(layers) => *best = Some((tracked, layers)),
                        None => {
                            is_tracked[candidate] = false;
                            *failures += 1;
                        }
                    }
                    // One candidate at a time: on thousands of nodes each is a pass over the
                    // order, and the choice resumes where it stopped (the same subset).
                    if Instant::now() >= deadline {
                        return None;
                    }
                }
                Stage::Penalties {
                    bound,
                    dist,
                    penalty,
                    dropped_nodes,
                    next_cluster,
                } => {
                    let (n, m) = (model.n, model.m);
                    // Penalties (see the module doc): λ_Y = min_{y ∈ Y} (in(y) + out(y)) / 2
                    // over arcs between clusters. A cycle pays each arc half to its tail's
                    // `out` and half to its head's `in`, so it costs at least the λ it earns:
                    // no cycle is negative. One cluster at a time.
                    while *next_cluster < m {
                        let c = *next_cluster;
                        *next_cluster += 1;
                        if bound.local_of[c] != u8::MAX {
                            continue;
                        }
                        let nodes = &model.cluster_nodes[c];
                        dropped_nodes.extend_from_slice(nodes);
                        let mut best = INF;
                        for &y in nodes {
                            let (mut min_in, mut min_out) = (INF, INF);
                            for z in (0..n).filter(|&z| model.node_cluster[z] != c) {
                                min_in = min_in.min(model.arc(z, y));
                                min_out = min_out.min(model.arc(y, z));
                            }
                            best = best.min((min_in + min_out) / 2.0);
                        }
                        penalty[c] = if best.is_finite() { best.max(0.0) } else { 0.0 };
                        if Instant::now() >= deadline {
                            return None;
                        }
                    }
                    // The costs without the arcs inside a cluster (they never occur in a
                    // tour; without them every walk pays its λ), 64 rows at a time.
                    while dist.len() < n * n {
                        let row = dist.len() / n;
                        let end = (row + 64).min(n);
                        dist.extend_from_slice(&model.cost[row * n..end * n]);
                        for x in row..end {
                            for &y in &model.cluster_nodes[model.node_cluster[x]] {
                                dist[x * n + y] = INF;
                            }
                        }
                        if Instant::now() >= deadline {
                            return None;
                        }
                    }
                    bound.dropped = (0..m)
                        .filter(|&c| bound.local_of[c] == u8::MAX && penalty[c] > 0.0)
                        .map(|c| (c, penalty[c]))
                        .collect();
                    self.stage = Stage::Distances {
                        bound: std::mem::replace(bound, Box::new(SubsetBound::empty())),
                        dist: std::mem::take(dist),
                        penalty: std::mem::take(penalty),
                        dropped_nodes: std::mem::take(dropped_nodes),
                        next: 0,
                    };
                }
                Stage::Distances {
                    bound,
                    dist,
                    penalty,
                    dropped_nodes,
                    next,
                } => {
                    let n = model.n;
                    while *next < dropped_nodes.len() {
                        let k = dropped_nodes[*next];
                        *next += 1;
                        let pk = penalty[model.node_cluster[k]];
                        let row_k = dist[k * n..(k + 1) * n].to_vec();
                        for i in 0..n {
                            let dik = dist[i * n + k] - pk;
                            if !dik.is_finite() {
                                continue;
                            }
                            let row_i = &mut dist[i * n..(i + 1) * n];
                            for (d, &dk) in row_i.iter_mut().zip(&row_k) {
                                let via = dik + dk;
                                if via < *d {
                                    *d = via;
                                }
                            }
                        }
                        if Instant::now() >= deadline {
                            return None;
                        }
                    }
                    let mut bound = std::mem::replace(bound, Box::new(SubsetBound::empty()));
                    bound.finish_distances(model, dist);
                    let t = bound.tracked.len();
                    let mut local_succ = vec![0u64; t];
                    for (c, &p) in bound.local_pred.iter().enumerate() {
                        for (d, s) in local_succ.iter_mut().enumerate() {
                            if p >> d & 1 == 1 {
                                *s |= 1 << c;
                            }
                        }
                    }
                    let total = bound.ideal_count();
                    self.stage = Stage::Backward {
                        size: bound.layers.len(),
                        bound,
                        local_succ,
                        next: 0,
                        rev_blocks: Vec::new(),
                        rev_values: Vec::new(),
                        ideal_blocks: vec![(0, 0); total],
                    };
                }
                Stage::Backward {
                    bound,
                    local_succ,
                    size,
                    next,
                    rev_blocks,
                    rev_values,
                    ideal_blocks,
                } => {
                    let mut children: Vec<(usize, usize)> = Vec::new();
                    while *size >= 1 {
                        let layer_len = bound.layers[*size - 1].len();
                        while *next < layer_len {
                            let key = bound.layers[*size - 1][*next];
                            *next += 1;
                            bound.backward_ideal(
                                model,
                                key,
                                local_succ,
                                &mut children,
                                rev_blocks,
                                rev_values,
                                ideal_blocks,
                            );
                            if *next % 32 == 0 && Instant::now() >= deadline {
                                return None;
                            }
                        }
                        *size -= 1;
                        *next = 0;
                    }
                    let mut bound = std::mem::replace(bound, Box::new(SubsetBound::empty()));
                    bound.finish_backward(rev_blocks, std::mem::take(rev_values), ideal_blocks);
                    self.stage = Stage::Finished;
                    return Some(Some(*bound));
                }
                Stage::Finished => return Some(None),
            }
        }
    }
}

fn local_indices(m: usize, tracked: &[usize]) -> Vec<u8> {
    let mut local_of = vec![u8::MAX; m];
    for (i, &c) in tracked.iter().enumerate() {
        local_of[c] = i as u8;
    }
    local_of
}

fn local_predecessors(model: &Model, tracked: &[usize], local_of: &[u8]) -> Vec<u64> {
    tracked
        .iter()
        .map(|&c| {
            model.order.predecessors[c]
                .iter()
                .filter(|&p| local_of[p] != u8::MAX)
                .fold(0u64, |mask, p| mask | 1 << local_of[p])
        })
        .collect()
}

impl SubsetBound {
    /// Builds the bound in one go (see [`SubsetBuilder`]).
    #[cfg(test)]
    pub fn build(model: &Model, tour: Option<&[usize]>, work_budget: f64) -> Option<SubsetBound> {
        let far = Instant::now() + std::time::Duration::from_secs(1 << 30);
        let mut builder = SubsetBuilder::new(model, tour, work_budget);
        loop {
            if let Some(result) = builder.advance(model, far) {
                return result;
            }
        }
    }

    fn empty() -> SubsetBound {
        SubsetBound {
            tracked: Vec::new(),
            local_of: Vec::new(),
            local_pred: Vec::new(),
            into: Vec::new(),
            to_start: Vec::new(),
            layers: Vec::new(),
            layer_offset: vec![0],
            block_start: Vec::new(),
            block_cluster: Vec::new(),
            block_value: Vec::new(),
            values: Vec::new(),
            full: 0,
            dropped: Vec::new(),
            root_bound: 0.0,
        }
    }

    /// The bound's frame; its penalties and distances are made in the next stages' slices.
    fn start_distances(model: &Model, tracked: Vec<usize>, layers: Vec<Vec<u64>>) -> Stage {
        let (n, m) = (model.n, model.m);
        let t = tracked.len();
        let local_of = local_indices(m, &tracked);
        let local_pred = local_predecessors(model, &tracked, &local_of);
        let mut layer_offset = Vec::with_capacity(layers.len() + 1);
        let mut total = 0usize;
        for layer in &layers {
            layer_offset.push(total);
            total += layer.len();
        }
        layer_offset.push(total);
        let full: u64 = if t == 64 { u64::MAX } else { (1u64 << t) - 1 };
        let bound = SubsetBound {
            tracked,
            local_of,
            local_pred,
            into: Vec::new(),
            to_start: Vec::new(),
            layers,
            layer_offset,
            block_start: Vec::new(),
            block_cluster: Vec::new(),
            block_value: Vec::new(),
            values: Vec::new(),
            full,
            dropped: Vec::new(),
            root_bound: 0.0,
        };
        Stage::Penalties {
            bound: Box::new(bound),
            dist: Vec::with_capacity(n * n),
            penalty: vec![0.0; m],
            dropped_nodes: Vec::new(),
            next_cluster: 0,
        }
    }

    /// Copies the relaxed costs into per-cluster blocks.
    fn finish_distances(&mut self, model: &Model, dist: &[f64]) {
        let n = model.n;
        self.into = self
            .tracked
            .iter()
            .map(|&c| {
                let nodes = &model.cluster_nodes[c];
                let mut block = Vec::with_capacity(n * nodes.len());
                for x in 0..n {
                    block.extend(nodes.iter().map(|&y| dist[x * n + y]));
                }
                block
            })
            .collect();
        self.to_start = (0..n).map(|x| dist[x * n + model.start]).collect();
    }

    /// Computes `H` for every maximal cluster and node of the ideal `key` (all its children
    /// are done, in `rev_blocks` / `rev_values`).
    #[allow(clippy::too_many_arguments)]
    fn backward_ideal(
        &self,
        model: &Model,
        key: u64,
        local_succ: &[u64],
        children: &mut Vec<(usize, usize)>,
        rev_blocks: &mut Vec<(u8, u32)>,
        rev_values: &mut Vec<f64>,
        ideal_blocks: &mut [(u32, u32)],
    ) {
        let t = self.tracked.len();
        let full = self.full;
        children.clear();
        if key != full {
            for c in 1..t {
                if key >> c & 1 == 0 && key & self.local_pred[c] == self.local_pred[c] {
                    let child = self.locate(key | 1 << c).expect("child ideal exists");
                    let (first, count) = ideal_blocks[child];
                    let block = (first..first + count)
                        .find(|&b| rev_blocks[b as usize].0 as usize == c)
                        .expect("new cluster is maximal in the child");
                    children.push((c, rev_blocks[block as usize].1 as usize));
                }
            }
        }
        let first = rev_blocks.len() as u32;
        for (l, &succ) in local_succ.iter().enumerate() {
            // Blocks for maximal clusters (the depot only in the root ideal).
            if key >> l & 1 == 0 || key & succ != 0 || (l == 0 && key != 1) {
                continue;
            }
            let offset = rev_values.len() as u32;
            for &x in &model.cluster_nodes[self.tracked[l]] {
                let value = if key == full {
                    self.to_start[x]
                } else {
                    self.completion_with(children, rev_values, x)
                };
                rev_values.push(value);
            }
            rev_blocks.push((l as u8, offset));
        }
        let global = self.locate(key).expect("ideal exists");
        ideal_blocks[global] = (first, rev_blocks.len() as u32 - first);
    }

    /// Re-indexes the blocks by ideal and sets the root bound.
    fn finish_backward(
        &mut self,
        rev_blocks: &[(u8, u32)],
        values: Vec<f64>,
        ideal_blocks: &[(u32, u32)],
    ) {
        let mut block_start = Vec::with_capacity(ideal_blocks.len() + 1);
        block_start.push(0u32);
        for &(first, count) in ideal_blocks {
            for b in first..first + count {
                self.block_cluster.push(rev_blocks[b as usize].0);
                self.block_value.push(rev_blocks[b as usize].1);
            }
            block_start.push(self.block_cluster.len() as u32);
        }
        self.block_start = block_start;
        self.values = values;
        self.root_bound = self.values[self.block_value[self.block_start[0] as usize] as usize]
            + self.dropped.iter().map(|&(_, p)| p).sum::<f64>();
    }

    /// `min` over the listed children `(Y, offset)` and nodes `y ∈ Y` of `c'(x, y) + H(child, y)`.
    #[inline]
    fn completion_with(&self, children: &[(usize, usize)], values: &[f64], x: usize) -> f64 {
        let mut best = INF;
        for &(c, offset) in children {
            let width = self.into[c].len() / self.to_start.len();
            let row = &self.into[c][x * width..(x + 1) * width];
            for (&arc, &v) in row.iter().zip(&values[offset..offset + width]) {
                let w = arc + v;
                if w < best {
                    best = w;
                }
            }
        }
        best
    }

    /// Global index of the ideal with local mask `key`.
    fn locate(&self, key: u64) -> Option<usize> {
        let size = key.count_ones() as usize;
        let layer = self.layers.get(size.checked_sub(1)?)?;
        layer
            .binary_search(&key)
            .ok()
            .map(|i| self.layer_offset[size - 1] + i)
    }

    /// Prepares `query` for the forward record whose ideal contains the clusters for which
    /// `contains` holds and whose last cluster is `last`.
    pub fn prepare(&self, contains: impl Fn(usize) -> bool, last: usize, query: &mut SubsetQuery) {
        let mut mask = 0u64;
        for (i, &c) in self.tracked.iter().enumerate() {
            if contains(c) {
                mask |= 1 << i;
            }
        }
        query.mask = mask;
        query.ideal = self.locate(mask);
        query.unvisited_penalty = self
            .dropped
            .iter()
            .filter(|&&(c, _)| !contains(c))
            .map(|&(_, p)| p)
            .sum();
        query.children.clear();
        query.own_block = None;
        let Some(ideal) = query.ideal else {
            return;
        };
        let blocks = self.block_start[ideal] as usize..self.block_start[ideal + 1] as usize;
        let local = self.local_of[last];
        if local != u8::MAX {
            query.own_block = blocks
                .clone()
                .find(|&b| self.block_cluster[b] == local)
                .map(|b| self.block_value[b]);
            return;
        }
        if mask == self.full {
            return;
        }
        for c in 1..self.tracked.len() {
            if mask >> c & 1 == 0 && mask & self.local_pred[c] == self.local_pred[c] {
                let Some(child) = self.locate(mask | 1 << c) else {
                    continue;
                };
                let found = (self.block_start[child] as usize
                    ..self.block_start[child + 1] as usize)
                    .find(|&b| self.block_cluster[b] as usize == c);
                if let Some(b) = found {
                    query.children.push((c as u8, self.block_value[b]));
                }
            }
        }
    }

    /// The completion bound of node `x` (the `j`-th node of the record's last cluster).
    #[inline]
    pub fn bound(&self, query: &SubsetQuery, j: usize, x: usize) -> f64 {
        if query.ideal.is_none() {
            return 0.0;
        }
        if let Some(offset) = query.own_block {
            return self.values[offset as usize + j] + query.unvisited_penalty;
        }
        if query.mask == self.full {
            return self.to_start[x] + query.unvisited_penalty;
        }
        let n = self.to_start.len();
        let mut best = INF;
        for &(c, offset) in &query.children {
            let into = &self.into[c as usize];
            let width = into.len() / n;
            let row = &into[x * width..(x + 1) * width];
            let offset = offset as usize;
            for (&arc, &v) in row.iter().zip(&self.values[offset..offset + width]) {
                let w = arc + v;
                if w < best {
                    best = w;
                }
            }
        }
        best + query.unvisited_penalty
    }

    /// Number of tracked clusters (with the depot).
    pub fn tracked_count(&self) -> usize {
        self.tracked.len()
    }

    /// Number of ideals of the restricted order.
    pub fn ideal_count(&self) -> usize {
        *self.layer_offset.last().unwrap_or(&0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instance::Instance;
    use cutroute_geometry::SplitMix64;

    /// A random instance: `m` clusters of 1–3 nodes, asymmetric costs (some forbidden), random
    /// precedence pairs from a random topological order.
    fn random_instance(seed: u64, m: usize) -> Instance {
        let mut rng = SplitMix64::new(seed);
        let mut clusters = vec![vec![0usize]];
        let mut node_cluster = vec![0usize];
        for c in 1..m {
            let size = 1 + rng.below(3) as usize;
            let mut nodes = Vec::new();
            for _ in 0..size {
                nodes.push(node_cluster.len());
                node_cluster.push(c);
            }
            clusters.push(nodes);
        }
        let n = node_cluster.len();
        let mut cost = vec![0.0; n * n];
        for a in 0..n {
            for b in 0..n {
                cost[a * n + b] = if a == b || rng.below(10) == 0 {
                    f64::INFINITY
                } else {
                    (30 + rng.below(40)) as f64
                };
            }
        }
        let mut order: Vec<usize> = (1..m).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, rng.below(i as u64 + 1) as usize);
        }
        let mut precedence = Vec::new();
        for i in 0..order.len() {
            for j in i + 1..order.len() {
                if rng.below(5) == 0 {
                    precedence.push((order[i], order[j]));
                }
            }
        }
        Instance {
            name: format!("random-{seed}"),
            node_count: n,
            cost,
            clusters,
            node_cluster,
            precedence,
            depot: 0,
        }
    }

    /// Calls `visit(tour, cost)` for every feasible tour of the model (start node first).
    fn every_tour(model: &Model, visit: &mut dyn FnMut(&[usize], f64)) {
        fn extend(
            model: &Model,
            tour: &mut Vec<usize>,
            visited: &mut Vec<bool>,
            cost: f64,
            visit: &mut dyn FnMut(&[usize], f64),
        ) {
            let last = *tour.last().expect("start");
            if tour.len() == model.m {
                let total = cost + model.arc(last, model.start);
                if total.is_finite() {
                    visit(tour, total);
                }
                return;
            }
            for c in 0..model.m {
                if visited[c] || model.order.predecessors[c].iter().any(|p| !visited[p]) {
                    continue;
                }
                visited[c] = true;
                for &x in &model.cluster_nodes[c] {
                    let arc = model.arc(last, x);
                    if arc.is_finite() {
                        tour.push(x);
                        extend(model, tour, visited, cost + arc, visit);
                        tour.pop();
                    }
                }
                visited[c] = false;
            }
        }
        let mut visited = vec![false; model.m];
        visited[model.depot] = true;
        extend(model, &mut vec![model.start], &mut visited, 0.0, visit);
    }

    /// For every prefix of `tour`: prefix cost + bound ≤ the tour's cost.
    fn check_prefixes(model: &Model, bound: &SubsetBound, tour: &[usize], total: f64) {
        let mut query = SubsetQuery::default();
        let mut visited = vec![false; model.m];
        visited[model.depot] = true;
        let mut prefix = 0.0;
        assert!(bound.root_bound <= total + 1e-9, "root bound above a tour");
        for k in 1..model.m {
            prefix += model.arc(tour[k - 1], tour[k]);
            let x = tour[k];
            let last = model.node_cluster[x];
            visited[last] = true;
            bound.prepare(|c| visited[c], last, &mut query);
            let j = model.cluster_nodes[last]
                .iter()
                .position(|&y| y == x)
                .expect("node of its cluster");
            let completion = bound.bound(&query, j, x);
            assert!(
                prefix + completion <= total + 1e-9,
                "state after {k} clusters: {prefix} + {completion} > tour {total}"
            );
        }
    }

    #[test]
    fn bound_never_exceeds_any_tour_on_random_instances() {
        let mut exact_roots = 0;
        for seed in 0..60u64 {
            let m = 3 + (seed % 5) as usize;
            let instance = random_instance(seed, m);
            let model = Model::new(&instance, 0).expect("acyclic by construction");
            let mut tours = Vec::new();
            every_tour(&model, &mut |t, c| tours.push((t.to_vec(), c)));
            let optimum = tours.iter().map(|t| t.1).fold(INF, f64::min);
            // Tiny budgets drop clusters (penalised walks); a large one tracks them all.
            for budget in [1.0, 30.0, 300.0, 1e9] {
                let guide = tours.first().map(|t| t.0.as_slice());
                let Some(bound) = SubsetBound::build(&model, guide, budget) else {
                    continue;
                };
                for (tour, total) in &tours {
                    check_prefixes(&model, &bound, tour, *total);
                }
                if bound.tracked_count() == m && optimum.is_finite() {
                    // Tracking every cluster, the bound is the exact optimum.
                    assert_eq!(bound.root_bound, optimum, "seed {seed}");
                    exact_roots += 1;
                }
            }
        }
        assert!(
            exact_roots > 30,
            "the exact case was exercised {exact_roots} times"
        );
    }

    /// Built a smallest piece at a time (every deadline already past: the penalties one
    /// cluster, the distance table 64 rows per call), the bound is the one built in one go.
    #[test]
    fn built_in_the_smallest_slices_it_is_the_same_bound() {
        let mut compared = 0;
        for seed in 0..40u64 {
            let m = 3 + (seed % 6) as usize;
            let instance = random_instance(seed, m);
            let model = Model::new(&instance, 0).expect("acyclic by construction");
            for budget in [1.0, 30.0, 1e9] {
                let whole = SubsetBound::build(&model, None, budget);
                let mut builder = SubsetBuilder::new(&model, None, budget);
                let mut calls = 0;
                let sliced = loop {
                    calls += 1;
                    if let Some(result) = builder.advance(&model, Instant::now()) {
                        break result;
                    }
                };
                match (whole, sliced) {
                    (Some(a), Some(b)) => {
                        assert_eq!(a.root_bound, b.root_bound, "seed {seed}, budget {budget}");
                        assert_eq!(a.dropped, b.dropped, "seed {seed}, budget {budget}");
                        assert_eq!(a.values, b.values, "seed {seed}, budget {budget}");
                        assert!(calls > 1, "seed {seed}: built in one call");
                        compared += 1;
                    }
                    (None, None) => {}
                    _ => panic!("seed {seed}, budget {budget}: one build fitted, the other not"),
                }
            }
        }
        assert!(compared > 60, "only {compared} bounds compared");
    }

    fn reference_rows() -> Vec<(String, String, Vec<usize>, f64)> {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../data/pcgtsp/reference.csv"
        );
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("required test data {path} is missing: {e}"));
        let mut rows = Vec::new();
        for line in text.lines().skip(1).filter(|l| !l.trim().is_empty()) {
            let mut fields = Vec::new();
            let (mut field, mut quoted) = (String::new(), false);
            for ch in line.chars() {
                match ch {
                    '"' => quoted = !quoted,
                    ',' if !quoted => fields.push(std::mem::take(&mut field)),
                    _ => field.push(ch),
                }
            }
            fields.push(field);
            let tour = fields[6]
                .split(',')
                .map(|v| v.trim().parse::<usize>().expect("1-based node") - 1)
                .collect();
            let cost = fields[4].parse().expect("pcglns cost");
            rows.push((fields[0].clone(), fields[1].clone(), tour, cost));
        }
        rows
    }

    #[test]
    fn bound_never_exceeds_the_reference_tours_on_industrial_instances() {
        let rows = reference_rows();
        let industrial: Vec<_> = rows.iter().filter(|r| r.0 == "industrial").collect();
        assert_eq!(industrial.len(), 25);
        for (set, name, tour, _) in industrial {
            let path = format!(
                "{}/../../data/pcgtsp/{set}/{name}.pcglns",
                env!("CARGO_MANIFEST_DIR")
            );
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("required test data {path} is missing: {e}"));
            let instance = Instance::parse(&text).expect("parses");
            let model = Model::new(&instance, tour[0]).expect("valid order");
            let total = crate::check::check_tour(&instance, tour).expect("feasible");
            // A small budget (many dropped clusters) and the solver's budget.
            for budget in [2e6, 4e8] {
                let bound = SubsetBound::build(&model, Some(tour), budget).expect("fits");
                check_prefixes(&model, &bound, tour, total);
            }
        }
    }
}
