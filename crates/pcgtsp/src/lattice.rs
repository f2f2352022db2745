//! The lattice of order ideals and the *pierce-consistent cluster DP* bound.
//!
//! The assignment bounds (L1, L2) collapse on cutting instances: a contour has many pierce
//! points, and H1 lets a tour enter a contour at one point and leave from another for free.
//! This bound keeps the consistency where it matters. Split every arc's cost half to its tail
//! and half to its head; the node `y` of a cluster then carries `(c(prev, y) + c(y, next)) / 2`,
//! which is at least
//!
//! `τ(A, B, C) = min_{b ∈ B} ( min_{a ∈ A} c(a, b) + min_{c ∈ C} c(b, c) ) / 2`
//!
//! for the clusters `A, B, C` visited around it: entry and exit share the pierce point `b`.
//! Minimising the sum of these terms over all precedence-feasible cluster sequences is a DP on
//! the ideal lattice with cluster-level states `(ideal, last cluster)` (the previous cluster is
//! enumerated on the fly), orders of magnitude cheaper than the node-level DP and solved
//! exactly, backwards from the full ideal. Its value at a state bounds every completion, and it
//! dominates the exact H1 relaxation (`τ(A,B,C) ≥ (d(A,B) + d(B,C)) / 2`).
//!
//! For a node-level DP state `(J, x)` with `x ∈ L`, the completion `x → y1 → … → start` costs
//! at least `min_{Y1} ( c(x, Y1) / 2 + V(J ∪ {Y1}, Y1 | prev = L) )`: the first arc's tail half
//! is exact, everything else is charged by `τ`, and the last arc's head half goes to the start.

use crate::bounds::Model;
use crate::dp::Key;

const INF: f64 = f64::INFINITY;

/// One layer of the lattice (ideals with the same number of clusters).
#[derive(Default)]
struct LatticeLayer<const W: usize> {
    keys: Vec<Key<W>>,
    /// Children of ideal `i`: `child_start[i]..child_start[i + 1]`.
    child_start: Vec<u32>,
    child_cluster: Vec<u8>,
    child_index: Vec<u32>,
    /// Bound values of ideal `i`'s states: `state_start[i]..state_start[i + 1]`.
    state_start: Vec<u32>,
    /// The last cluster of every state.
    state_last: Vec<u8>,
    /// Bound on the completion from the state, rounded down to `f32`.
    state_value: Vec<f32>,
}

/// The full ideal lattice with the cluster-DP bound of every `(ideal, last cluster)`.
pub(crate) struct Lattice<const W: usize> {
    layers: Vec<LatticeLayer<W>>,
    /// Root bound: the cheapest tour in the relaxation.
    pub root_bound: f64,
    /// Number of ideals.
    pub ideal_count: usize,
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
pub(crate) fn count_ideals<const W: usize>(model: &Model, limit: usize) -> Option<usize> {
    let (pred, _) = masks::<W>(model);
    let mut layer = vec![Key::<W>([0; W]).with(model.depot)];
    let mut total = 1usize;
    for _ in 1..model.m {
        let mut next = Vec::new();
        for key in &layer {
            for c in 0..model.m {
                if !key.contains(c) && key.contains_all(&pred[c]) {
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

impl<const W: usize> Lattice<W> {
    /// Builds the lattice and the bound; `None` if it would exceed `max_ideals` ideals or
    /// `max_bytes` of memory (then the solver falls back to the assignment bounds).
    pub fn build(model: &Model, max_ideals: usize, max_bytes: usize) -> Option<Lattice<W>> {
        let m = model.m;
        if m > 255 || m > 64 * W {
            return None;
        }
        let (pred, succ) = masks::<W>(model);
        // Forward: keys and children, layer by layer.
        let mut layers: Vec<LatticeLayer<W>> = Vec::with_capacity(m);
        layers.push(LatticeLayer {
            keys: vec![Key([0; W]).with(model.depot)],
            ..Default::default()
        });
        let mut ideal_count = 1usize;
        let mut bytes = 0usize;
        for k in 0..m - 1 {
            let mut records: Vec<(Key<W>, u32, u8)> = Vec::new();
            let layer = &layers[k];
            for (i, key) in layer.keys.iter().enumerate() {
                for c in 0..m {
                    if !key.contains(c) && key.contains_all(&pred[c]) {
                        records.push((key.with(c), i as u32, c as u8));
                    }
                }
                if records.len() > 4 * max_ideals {
                    return None;
                }
            }
            records.sort_unstable();
            let mut keys: Vec<Key<W>> = Vec::new();
            let mut counts = vec![0u32; layer.keys.len() + 1];
            let mut child_of: Vec<u32> = Vec::with_capacity(records.len());
            for &(key, parent, _) in &records {
                if keys.last() != Some(&key) {
                    keys.push(key);
                }
                child_of.push((keys.len() - 1) as u32);
                counts[parent as usize + 1] += 1;
            }
            ideal_count += keys.len();
            bytes += keys.len() * (8 * W + 8) + records.len() * 5;
            if ideal_count > max_ideals || bytes > max_bytes {
                return None;
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
            let layer = &mut layers[k];
            layer.child_start = counts;
            layer.child_cluster = child_cluster;
            layer.child_index = child_index;
            layers.push(LatticeLayer {
                keys,
                ..Default::default()
            });
        }
        let forward_done = web_time::Instant::now();
        let last = layers.len() - 1;
        layers[last].child_start = vec![0; layers[last].keys.len() + 1];
        // τ(A, B, C) over clusters; C = depot means "then back to the start".
        let tau = tau_table(model);
        let end: Vec<f64> = (0..m)
            .map(|b| {
                model.cluster_nodes[b]
                    .iter()
                    .map(|&y| model.arc(y, model.start))
                    .fold(INF, f64::min)
                    / 2.0
            })
            .collect();
        // Backward: state values, from the full ideal down to layer 2.
        let mut scratch_max: Vec<usize> = Vec::new();
        let mut scratch_prev: Vec<usize> = Vec::new();
        let mut child_values: Vec<(usize, f64)> = Vec::new();
        for k in (1..layers.len()).rev() {
            let (lower, upper) = layers.split_at_mut(k + 1);
            let layer = &mut lower[k];
            let child_layer = upper.first();
            let mut state_start = Vec::with_capacity(layer.keys.len() + 1);
            let mut state_last = Vec::new();
            let mut state_value = Vec::new();
            state_start.push(0u32);
            for (i, key) in layer.keys.iter().enumerate() {
                // V(J ∪ {C}, C) of every child, looked up once per ideal.
                child_values.clear();
                if let Some(child_layer) = child_layer {
                    for ch in layer.child_start[i] as usize..layer.child_start[i + 1] as usize {
                        let c = layer.child_cluster[ch] as usize;
                        child_values
                            .push((c, child_layer.value(layer.child_index[ch] as usize, c)));
                    }
                }
                scratch_max.clear();
                scratch_max.extend((0..m).filter(|&b| {
                    b != model.depot && key.contains(b) && !intersects(key, &succ[b])
                }));
                for &b in &scratch_max {
                    let without = key.without(b);
                    scratch_prev.clear();
                    if without == Key([0; W]).with(model.depot) {
                        scratch_prev.push(model.depot);
                    } else {
                        scratch_prev.extend((0..m).filter(|&a| {
                            a != model.depot
                                && without.contains(a)
                                && !intersects(&without, &succ[a])
                        }));
                    }
                    let mut best = INF;
                    for &a in &scratch_prev {
                        let row = &tau[(a * m + b) * m..(a * m + b + 1) * m];
                        if k == m - 1 {
                            best = best.min(row[model.depot] + end[b]);
                        } else {
                            for &(c, v) in &child_values {
                                let w = row[c] + v;
                                if w < best {
                                    best = w;
                                }
                            }
                        }
                    }
                    state_last.push(b as u8);
                    state_value.push(if best.is_finite() {
                        down(best)
                    } else {
                        f32::INFINITY
                    });
                }
                state_start.push(state_last.len() as u32);
            }
            bytes += state_last.len() * 5 + layer.keys.len() * 4;
            if bytes > max_bytes {
                return None;
            }
            layer.state_start = state_start;
            layer.state_last = state_last;
            layer.state_value = state_value;
        }
        if std::env::var_os("PCGTSP_DEBUG").is_some() {
            eprintln!(
                "[pcgtsp] lattice backward pass {:?}",
                forward_done.elapsed()
            );
        }
        let mut lattice = Lattice {
            layers,
            root_bound: 0.0,
            ideal_count,
        };
        lattice.root_bound = if m == 1 {
            model.arc(model.start, model.start)
        } else {
            lattice.completion_bound(model, 1, 0, model.start)
        };
        Some(lattice)
    }

    /// Position of ideal `key` (of `size` clusters) in its layer.
    pub fn find(&self, key: &Key<W>, size: usize) -> Option<usize> {
        self.layers.get(size - 1)?.keys.binary_search(key).ok()
    }

    /// For ideal number `index` of `size` clusters: fills `out` with `(Y, V(J ∪ {Y}, Y))` for
    /// every cluster `Y` addable to the ideal.
    pub fn next_values(&self, size: usize, index: usize, out: &mut Vec<(usize, f64)>) {
        out.clear();
        let layer = &self.layers[size - 1];
        let Some(child_layer) = self.layers.get(size) else {
            return;
        };
        for ch in layer.child_start[index] as usize..layer.child_start[index + 1] as usize {
            let c = layer.child_cluster[ch] as usize;
            let j = layer.child_index[ch] as usize;
            out.push((c, child_layer.value(j, c)));
        }
    }

    /// The bound on the completion from node `x` after the ideal at position `index` of the
    /// layer of ideals with `size` clusters (not the full one).
    pub fn completion_bound(&self, model: &Model, size: usize, index: usize, x: usize) -> f64 {
        let mut values = Vec::new();
        self.next_values(size, index, &mut values);
        node_completion(model, &values, x)
    }
}

/// `min_Y ( c(x, Y) / 2 + V_Y )` over the `(Y, V_Y)` of [`Lattice::next_values`].
#[inline]
pub(crate) fn node_completion(model: &Model, values: &[(usize, f64)], x: usize) -> f64 {
    let row = &model.node_to_cluster[x * model.m..(x + 1) * model.m];
    let mut best = INF;
    for &(c, v) in values {
        let w = row[c] / 2.0 + v;
        if w < best {
            best = w;
        }
    }
    best
}

impl<const W: usize> LatticeLayer<W> {
    /// The stored bound of ideal `index` with last cluster `last` (`INF` if absent).
    #[inline]
    fn value(&self, index: usize, last: usize) -> f64 {
        let s0 = self.state_start[index] as usize;
        let s1 = self.state_start[index + 1] as usize;
        for s in s0..s1 {
            if self.state_last[s] as usize == last {
                return self.state_value[s] as f64;
            }
        }
        INF
    }
}

#[inline]
fn intersects<const W: usize>(a: &Key<W>, b: &Key<W>) -> bool {
    (0..W).any(|i| a.0[i] & b.0[i] != 0)
}

/// `τ(A, B, C)` for all clusters (`m³`, row-major in A, B, C); `C = depot` closes at the start.
fn tau_table(model: &Model) -> Vec<f64> {
    let m = model.m;
    let n = model.n;
    // into[A][y] = cheapest arc from cluster A into node y.
    let mut into = vec![INF; m * n];
    for (a, nodes) in model.cluster_nodes.iter().enumerate() {
        for y in 0..n {
            into[a * n + y] = nodes
                .iter()
                .map(|&x| if x == y { INF } else { model.arc(x, y) })
                .fold(INF, f64::min);
        }
    }
    let mut tau = vec![INF; m * m * m];
    for a in 0..m {
        for b in 0..m {
            if a == b {
                continue;
            }
            for c in 0..m {
                if c == b || (c == a && c != model.depot) {
                    continue;
                }
                let mut best = INF;
                for &y in &model.cluster_nodes[b] {
                    let v = into[a * n + y] + model.node_to_cluster[y * m + c];
                    if v < best {
                        best = v;
                    }
                }
                tau[(a * m + b) * m + c] = best / 2.0;
            }
        }
    }
    tau
}
