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
//! `H` is computed exactly over the ideals of the restricted order (states: ideal, maximal
//! cluster, node). Which clusters are dropped is chosen from the incumbent tour: those whose
//! visit costs the least detour go first, until the backward pass fits the work budget.

use crate::bounds::Model;

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

impl SubsetBound {
    /// Chooses the tracked subset from `tour` (0-based nodes starting at the start node; may be
    /// `None`) and computes the bound with about `work_budget` elementary steps.
    pub fn build(model: &Model, tour: Option<&[usize]>, work_budget: f64) -> Option<SubsetBound> {
        let m = model.m;
        if m < 2 {
            return None;
        }
        // Detour of every cluster in the tour: what skipping it would save.
        let mut detour = vec![0.0f64; m];
        if let Some(tour) = tour.filter(|t| t.len() == m) {
            for i in 1..m {
                let (a, y, b) = (tour[i - 1], tour[i], tour[(i + 1) % m]);
                detour[model.node_cluster[y]] = model.arc(a, y) + model.arc(y, b)
                    - model.arc(a, b).min(model.arc(a, y) + model.arc(y, b));
            }
        } else {
            for (c, d) in detour.iter_mut().enumerate() {
                *d = model.cluster_nodes[c].len() as f64;
            }
        }
        // Track the clusters with the largest detours first, while the backward pass fits.
        let mut candidates: Vec<usize> = (0..m).filter(|&c| c != model.depot).collect();
        candidates.sort_by(|&a, &b| detour[b].total_cmp(&detour[a]).then(a.cmp(&b)));
        let mut is_tracked = vec![false; m];
        is_tracked[model.depot] = true;
        let mut best: Option<(Vec<usize>, Vec<Vec<u64>>)> = None;
        let mut failures = 0;
        for &candidate in &candidates {
            if failures >= 3 {
                break;
            }
            let tracked_count = is_tracked.iter().filter(|&&t| t).count();
            if tracked_count >= 64 {
                break;
            }
            is_tracked[candidate] = true;
            let tracked: Vec<usize> = model
                .order
                .topological
                .iter()
                .copied()
                .filter(|&c| is_tracked[c])
                .collect();
            debug_assert_eq!(tracked[0], model.depot);
            let mut local_of = vec![u8::MAX; m];
            for (i, &c) in tracked.iter().enumerate() {
                local_of[c] = i as u8;
            }
            let pred: Vec<u64> = tracked
                .iter()
                .map(|&c| {
                    model.order.predecessors[c]
                        .iter()
                        .filter(|&p| local_of[p] != u8::MAX)
                        .fold(0u64, |mask, p| mask | 1 << local_of[p])
                })
                .collect();
            let size: Vec<usize> = tracked
                .iter()
                .map(|&c| model.cluster_nodes[c].len())
                .collect();
            match backward_work(&pred, &size, work_budget) {
                Some(layers) => best = Some((tracked, layers)),
                None => {
                    is_tracked[candidate] = false;
                    failures += 1;
                }
            }
        }
        let (tracked, layers) = best?;
        Some(Self::compute(model, tracked, layers))
    }

    fn compute(model: &Model, tracked: Vec<usize>, layers: Vec<Vec<u64>>) -> SubsetBound {
        let (n, m) = (model.n, model.m);
        let t = tracked.len();
        let mut local_of = vec![u8::MAX; m];
        for (i, &c) in tracked.iter().enumerate() {
            local_of[c] = i as u8;
        }
        let local_pred: Vec<u64> = tracked
            .iter()
            .map(|&c| {
                model.order.predecessors[c]
                    .iter()
                    .filter(|&p| local_of[p] != u8::MAX)
                    .fold(0u64, |mask, p| mask | 1 << local_of[p])
            })
            .collect();
        let mut local_succ = vec![0u64; t];
        for (c, &p) in local_pred.iter().enumerate() {
            for (d, s) in local_succ.iter_mut().enumerate() {
                if p >> d & 1 == 1 {
                    *s |= 1 << c;
                }
            }
        }
        // Penalties: a dropped cluster Y is worth λ_Y = min_{y ∈ Y} (in(y) + out(y)) / 2 (its
        // cheapest arcs in and out, over arcs between clusters). A walk through dropped nodes earns λ at each
        // one; every real completion visits each unvisited dropped cluster exactly once, so its
        // cost is at least the penalised walk plus the λ of the dropped clusters still to visit.
        // Every cycle costs at least the λ it earns, so no cycle is negative.
        let mut penalty = vec![0.0f64; m];
        for (c, nodes) in model.cluster_nodes.iter().enumerate() {
            if local_of[c] != u8::MAX {
                continue;
            }
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
        }
        // c': cheapest penalised walks with intermediate nodes in dropped clusters only.
        // Arcs inside a cluster never occur in a tour; without them every walk pays its λ.
        let mut dist = model.cost.clone();
        for nodes in &model.cluster_nodes {
            for &x in nodes {
                for &y in nodes {
                    dist[x * n + y] = INF;
                }
            }
        }
        for (c, nodes) in model.cluster_nodes.iter().enumerate() {
            if local_of[c] != u8::MAX {
                continue;
            }
            for &k in nodes {
                let row_k = dist[k * n..(k + 1) * n].to_vec();
                for i in 0..n {
                    let dik = dist[i * n + k] - penalty[c];
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
            }
        }
        let dropped: Vec<(usize, f64)> = (0..m)
            .filter(|&c| local_of[c] == u8::MAX && penalty[c] > 0.0)
            .map(|c| (c, penalty[c]))
            .collect();
        let into: Vec<Vec<f64>> = tracked
            .iter()
            .map(|&c| {
                let nodes = &model.cluster_nodes[c];
                let mut block = Vec::with_capacity(n * nodes.len());
                for x in 0..n {
                    block.extend(
                        nodes
                            .iter()
                            .map(|&y| if x == y { INF } else { dist[x * n + y] }),
                    );
                }
                block
            })
            .collect();
        let to_start: Vec<f64> = (0..n).map(|x| dist[x * n + model.start]).collect();
        let mut layer_offset = Vec::with_capacity(layers.len() + 1);
        let mut total = 0usize;
        for layer in &layers {
            layer_offset.push(total);
            total += layer.len();
        }
        layer_offset.push(total);
        let full: u64 = if t == 64 { u64::MAX } else { (1u64 << t) - 1 };
        let mut bound = SubsetBound {
            tracked,
            local_of,
            local_pred,
            into,
            to_start,
            layers,
            layer_offset,
            block_start: vec![0; total + 1],
            block_cluster: Vec::new(),
            block_value: Vec::new(),
            values: Vec::new(),
            full,
            dropped,
            root_bound: 0.0,
        };
        // Backward over layers; blocks are filled in reverse and re-indexed at the end.
        let mut rev_blocks: Vec<(u8, u32)> = Vec::new();
        let mut rev_values: Vec<f64> = Vec::new();
        // Per ideal (global index): (first block, block count) in rev_blocks.
        let mut ideal_blocks = vec![(0u32, 0u32); total];
        let mut children: Vec<(usize, usize)> = Vec::new(); // (local cluster, value offset)
        for size in (1..=bound.layers.len()).rev() {
            for (i, &key) in bound.layers[size - 1].iter().enumerate() {
                let global = bound.layer_offset[size - 1] + i;
                children.clear();
                if key != full {
                    for c in 1..t {
                        if key >> c & 1 == 0 && key & bound.local_pred[c] == bound.local_pred[c] {
                            let child = bound.locate(key | 1 << c).expect("child ideal exists");
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
                    for &x in &model.cluster_nodes[bound.tracked[l]] {
                        let value = if key == full {
                            bound.to_start[x]
                        } else {
                            bound.completion_with(&children, &rev_values, x)
                        };
                        rev_values.push(value);
                    }
                    rev_blocks.push((l as u8, offset));
                }
                ideal_blocks[global] = (first, rev_blocks.len() as u32 - first);
            }
        }
        let mut block_start = Vec::with_capacity(total + 1);
        block_start.push(0u32);
        for &(first, count) in &ideal_blocks {
            for b in first..first + count {
                bound.block_cluster.push(rev_blocks[b as usize].0);
                bound.block_value.push(rev_blocks[b as usize].1);
            }
            block_start.push(bound.block_cluster.len() as u32);
        }
        bound.block_start = block_start;
        bound.values = rev_values;
        bound.root_bound = bound.values[bound.block_value[bound.block_start[0] as usize] as usize]
            + bound.dropped.iter().map(|&(_, p)| p).sum::<f64>();
        bound
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
