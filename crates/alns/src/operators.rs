//! Destroy (removal) and repair (insertion) operators on node tours.
//!
//! A tour is a `Vec<usize>` of nodes with the depot cluster's node first. Removing clusters from a
//! precedence-feasible tour keeps it feasible; inserting a cluster anywhere between its last
//! present predecessor and its first present successor keeps it feasible, and that interval is
//! never empty because the closure orders every predecessor before every successor.

use crate::problem::Problem;
use cutroute_geometry::Xoshiro256 as Rng;

/// How clusters are chosen for removal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Removal {
    /// Uniformly random clusters.
    Random,
    /// Clusters whose removal saves most (randomised order).
    Worst,
    /// A contiguous run of the tour.
    Segment,
    /// Shaw removal: clusters whose chosen nodes are close to already removed ones.
    Related,
    /// A precedence-repaired reversal of a random run (done by the solver), then random removal.
    Reverse,
}

/// All removal operators, in weight-vector order.
pub(crate) const REMOVALS: [Removal; 5] = [
    Removal::Random,
    Removal::Worst,
    Removal::Segment,
    Removal::Related,
    Removal::Reverse,
];

/// Which pending cluster is inserted next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Selection {
    /// The cluster with the cheapest best insertion.
    Cheapest,
    /// The cluster nearest to the partial tour.
    Nearest,
    /// The cluster whose best insertion is most expensive (farthest insertion).
    Farthest,
    /// A random cluster.
    Random,
}

/// A repair operator: a selection rule with or without noise on insertion costs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Insertion {
    /// The selection rule.
    pub selection: Selection,
    /// Whether insertion costs are perturbed.
    pub noisy: bool,
}

/// All insertion operators, in weight-vector order.
pub(crate) const INSERTIONS: [Insertion; 8] = [
    Insertion {
        selection: Selection::Cheapest,
        noisy: false,
    },
    Insertion {
        selection: Selection::Cheapest,
        noisy: true,
    },
    Insertion {
        selection: Selection::Nearest,
        noisy: false,
    },
    Insertion {
        selection: Selection::Nearest,
        noisy: true,
    },
    Insertion {
        selection: Selection::Farthest,
        noisy: false,
    },
    Insertion {
        selection: Selection::Farthest,
        noisy: true,
    },
    Insertion {
        selection: Selection::Random,
        noisy: false,
    },
    Insertion {
        selection: Selection::Random,
        noisy: true,
    },
];

/// The best known insertion of a pending cluster into the partial tour.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    /// Cost increase (noise included when the operator is noisy).
    delta: f64,
    /// The node of the cluster to insert.
    node: usize,
    /// Insert before index `edge` (between `tour[edge-1]` and `tour[edge % len]`).
    edge: usize,
    /// The feasible edge interval `lo..=hi`.
    lo: usize,
    hi: usize,
}

const NO_CANDIDATE: Candidate = Candidate {
    delta: f64::INFINITY,
    node: 0,
    edge: 1,
    lo: 1,
    hi: 1,
};

/// Reusable buffers of the destroy / repair operators.
#[derive(Default, Clone, Debug)]
pub(crate) struct Operators {
    pending: Vec<usize>,
    /// Pending clusters whose lower (first `words` words) / upper bound is not yet set.
    unbounded: Vec<u64>,
    candidate: Vec<Candidate>,
    nearest: Vec<f64>,
    removed: Vec<bool>,
    scratch: Vec<(f64, usize)>,
    indices: Vec<usize>,
}

impl Operators {
    /// Removes `count` non-depot clusters from `t` with operator `how`; the removed clusters are
    /// remembered for the next [`Operators::repair`].
    pub(crate) fn destroy(
        &mut self,
        p: &Problem,
        t: &mut Vec<usize>,
        how: Removal,
        count: usize,
        rng: &mut Rng,
    ) {
        let len = t.len();
        let count = count.min(len - 1);
        self.removed.clear();
        self.removed.resize(len, false);
        match how {
            Removal::Random | Removal::Reverse => {
                self.indices.clear();
                self.indices.extend(1..len);
                for k in 0..count {
                    let j = rng.between(k, self.indices.len() - 1);
                    self.indices.swap(k, j);
                    self.removed[self.indices[k]] = true;
                }
            }
            Removal::Worst => {
                self.scratch.clear();
                for i in 1..len {
                    let (a, v, b) = (t[i - 1], t[i], t[(i + 1) % len]);
                    let gain = p.d(a, v) + p.d(v, b) - p.d(a, b);
                    self.scratch.push((gain, i));
                }
                self.scratch.sort_by(|x, y| y.0.total_cmp(&x.0));
                for _ in 0..count {
                    // Randomised: strongly biased towards the front of the sorted list.
                    let u = rng.unit();
                    let k = ((u * u * u) * self.scratch.len() as f64) as usize;
                    let (_, i) = self.scratch.remove(k.min(self.scratch.len() - 1));
                    self.removed[i] = true;
                }
            }
            Removal::Segment => {
                let start = rng.between(1, len - count);
                for r in &mut self.removed[start..start + count] {
                    *r = true;
                }
            }
            Removal::Related => {
                self.indices.clear();
                self.indices.extend(1..len);
                let seed = rng.below(self.indices.len());
                let first = self.indices.swap_remove(seed);
                self.removed[first] = true;
                let mut taken = vec![first];
                while taken.len() < count {
                    let reference = t[taken[rng.below(taken.len())]];
                    self.scratch.clear();
                    for &i in &self.indices {
                        let v = t[i];
                        let relatedness = p.d(reference, v).min(p.d(v, reference));
                        self.scratch.push((relatedness, i));
                    }
                    self.scratch.sort_by(|x, y| x.0.total_cmp(&y.0));
                    let u = rng.unit();
                    let k = ((u * u * u) * self.scratch.len() as f64) as usize;
                    let i = self.scratch[k.min(self.scratch.len() - 1)].1;
                    self.removed[i] = true;
                    taken.push(i);
                    self.indices.retain(|&x| x != i);
                }
            }
        }
        self.pending.clear();
        let mut w = 0;
        for r in 0..len {
            if self.removed[r] {
                self.pending.push(p.cl(t[r]));
            } else {
                t[w] = t[r];
                w += 1;
            }
        }
        t.truncate(w);
    }

    /// Prepares a repair that inserts every non-depot cluster into the tour `[depot node]`.
    pub(crate) fn destroy_all(&mut self, p: &Problem, t: &mut Vec<usize>) {
        t.clear();
        t.push(p.clusters[p.depot][0]);
        self.pending.clear();
        self.pending.extend((0..p.m).filter(|&c| c != p.depot));
    }

    /// Inserts every pending cluster back into `t` with operator `how`; `noise` is the
    /// amplitude of the additive noise of noisy operators.
    pub(crate) fn repair(
        &mut self,
        p: &Problem,
        t: &mut Vec<usize>,
        how: Insertion,
        noise: f64,
        rng: &mut Rng,
    ) {
        self.begin_repair(p, t, how, noise, rng);
        while self.insert_one(p, t, how, noise, rng) {}
    }

    /// The first part of [`Operators::repair`]: every pending cluster's best insertion. Then
    /// [`Operators::insert_one`] inserts them one at a time (a repair in resumable units: the
    /// first tour of Nest03's 460 clusters took 0.6–1.5 s in one piece).
    pub(crate) fn begin_repair(
        &mut self,
        p: &Problem,
        t: &[usize],
        how: Insertion,
        noise: f64,
        rng: &mut Rng,
    ) {
        let noise = if how.noisy { noise } else { 0.0 };
        self.candidate.clear();
        self.candidate.resize(p.m, NO_CANDIDATE);
        if how.selection == Selection::Random {
            rng.shuffle(&mut self.pending);
        }
        let pending = std::mem::take(&mut self.pending);
        self.initial_intervals(p, t, &pending);
        for &c in &pending {
            let (lo, hi) = (self.candidate[c].lo, self.candidate[c].hi);
            self.candidate[c] = full_candidate(p, t, c, lo, hi, noise, rng);
        }
        if how.selection == Selection::Nearest {
            self.nearest.clear();
            self.nearest.resize(p.m, f64::INFINITY);
            for &c in &pending {
                let mut best = f64::INFINITY;
                for &u in &p.clusters[c] {
                    for &v in t.iter() {
                        best = best.min(p.d(u, v)).min(p.d(v, u));
                    }
                }
                self.nearest[c] = best;
            }
        }
        self.pending = pending;
    }

    /// Inserts the next pending cluster of a repair begun by [`Operators::begin_repair`] (with
    /// the same `how` and `noise`); whether one was left to insert.
    pub(crate) fn insert_one(
        &mut self,
        p: &Problem,
        t: &mut Vec<usize>,
        how: Insertion,
        noise: f64,
        rng: &mut Rng,
    ) -> bool {
        let noise = if how.noisy { noise } else { 0.0 };
        let mut pending = std::mem::take(&mut self.pending);
        if pending.is_empty() {
            return false;
        }
        {
            let pick = match how.selection {
                Selection::Random => pending.len() - 1,
                Selection::Cheapest => arg_best(&pending, |c| -self.candidate[c].delta),
                Selection::Farthest => arg_best(&pending, |c| self.candidate[c].delta),
                Selection::Nearest => arg_best(&pending, |c| -self.nearest[c]),
            };
            let c = pending.swap_remove(pick);
            let Candidate {
                node: v, edge: e, ..
            } = self.candidate[c];
            t.insert(e, v);
            let (a, b) = (t[e - 1], t[(e + 1) % t.len()]);
            for &c2 in &pending {
                let old = self.candidate[c2];
                // The interval in O(1): indices at or after `e` moved up by one, and `c` (now
                // at `e`) bounds it if it is a predecessor or successor of `c2`.
                let mut lo = if old.lo > e { old.lo + 1 } else { old.lo };
                let mut hi = if old.hi >= e { old.hi + 1 } else { old.hi };
                let c_before = p.precedes(c, c2);
                let c_after = p.precedes(c2, c);
                if c_before {
                    lo = lo.max(e + 1);
                }
                if c_after {
                    hi = hi.min(e);
                }
                if cfg!(any(test, debug_assertions)) {
                    assert_eq!((lo, hi), interval_by_scan(p, t, c2), "interval of {c2}");
                }
                if c_before || c_after || old.edge == e {
                    self.candidate[c2] = full_candidate(p, t, c2, lo, hi, noise, rng);
                } else {
                    // Unrelated to the inserted cluster: only indices shift and the split edge
                    // (a, b) became (a, v), (v, b).
                    let mut cand = old;
                    if cand.edge > e {
                        cand.edge += 1;
                    }
                    cand.lo = lo;
                    cand.hi = hi;
                    if old.lo <= e && e <= old.hi {
                        for &u in &p.clusters[c2] {
                            let d1 = p.d(a, u) + p.d(u, v) - p.d(a, v) + jitter(noise, rng);
                            if d1 < cand.delta {
                                cand.delta = d1;
                                cand.node = u;
                                cand.edge = e;
                            }
                            let d2 = p.d(v, u) + p.d(u, b) - p.d(v, b) + jitter(noise, rng);
                            if d2 < cand.delta {
                                cand.delta = d2;
                                cand.node = u;
                                cand.edge = e + 1;
                            }
                        }
                    }
                    self.candidate[c2] = cand;
                }
                if how.selection == Selection::Nearest {
                    let mut best = self.nearest[c2];
                    for &u in &p.clusters[c2] {
                        best = best.min(p.d(u, v)).min(p.d(v, u));
                    }
                    self.nearest[c2] = best;
                }
            }
        }
        self.pending = pending;
        true
    }

    /// Inserts the next pending cluster of a repair begun by [`Operators::begin_repair`] at its
    /// cheapest feasible place in `t` as it is now, without looking at the other pending
    /// clusters; whether one was left to insert. A repair that has to end soon (a first tour
    /// whose time limit came first) finishes this way: one cluster costs a scan of `t` and of
    /// its feasible edges, where [`Operators::insert_one`] updates the best insertion of every
    /// pending cluster (0.7 s on Nest03 at 25 mm, 2 s under load, for the clusters left).
    /// Any pending cluster has a feasible place: the clusters of `t` keep the precedence, so
    /// its present predecessors all come before its present successors.
    pub(crate) fn insert_one_quickly(
        &mut self,
        p: &Problem,
        t: &mut Vec<usize>,
        rng: &mut Rng,
    ) -> bool {
        let Some(c) = self.pending.pop() else {
            return false;
        };
        let (lo, hi) = interval_by_scan(p, t, c);
        let Candidate {
            node: v, edge: e, ..
        } = full_candidate(p, t, c, lo, hi, 0.0, rng);
        t.insert(e, v);
        true
    }

    /// Sets `candidate[c].lo ..= candidate[c].hi` of every pending cluster `c` to its feasible
    /// insertion interval in the partial tour `t`: after its last present predecessor, up to
    /// its first present successor. The prefixes of a feasible tour are ideals of the order, so
    /// that interval is never empty. Two sweeps over `t`, each word-parallel over the pending
    /// set and assigning every bound once (the first hit from the far side is the binding
    /// one): `O(len · ⌈m / 64⌉ + k)` for `k` pending clusters, the cost of the destroy's own
    /// compaction for up to 64 clusters; insertions then update intervals in O(1).
    fn initial_intervals(&mut self, p: &Problem, t: &[usize], pending: &[usize]) {
        let len = t.len();
        let words = p.words;
        self.unbounded.clear();
        self.unbounded.resize(2 * words, 0);
        for &c in pending {
            self.candidate[c].lo = 1;
            self.candidate[c].hi = len;
            if p.has_precedence {
                self.unbounded[c / 64] |= 1 << (c % 64);
                self.unbounded[words + c / 64] |= 1 << (c % 64);
            }
        }
        if !p.has_precedence {
            return;
        }
        let (without_lo, without_hi) = self.unbounded.split_at_mut(words);
        // Lower bounds: the last present predecessor is the first one met from the end.
        let mut left = pending.len();
        for i in (1..len).rev() {
            if left == 0 {
                break;
            }
            let successors = p.successor_bits(p.cl(t[i]));
            for (w, (open, &row)) in without_lo.iter_mut().zip(successors).enumerate() {
                let mut hit = *open & row;
                *open &= !row;
                while hit != 0 {
                    let c = w * 64 + hit.trailing_zeros() as usize;
                    hit &= hit - 1;
                    self.candidate[c].lo = i + 1;
                    left -= 1;
                }
            }
        }
        // Upper bounds: the first present successor is the first one met from the front.
        let mut left = pending.len();
        for (i, &v) in t.iter().enumerate().skip(1) {
            if left == 0 {
                break;
            }
            let predecessors = p.predecessor_bits(p.cl(v));
            for (w, (open, &row)) in without_hi.iter_mut().zip(predecessors).enumerate() {
                let mut hit = *open & row;
                *open &= !row;
                while hit != 0 {
                    let c = w * 64 + hit.trailing_zeros() as usize;
                    hit &= hit - 1;
                    self.candidate[c].hi = i;
                    left -= 1;
                }
            }
        }
        if cfg!(any(test, debug_assertions)) {
            for &c in pending {
                let interval = (self.candidate[c].lo, self.candidate[c].hi);
                assert_eq!(interval, interval_by_scan(p, t, c), "interval of {c}");
            }
        }
    }
}

/// Best insertion of cluster `c` over its feasible edge interval `lo..=hi`.
fn full_candidate(
    p: &Problem,
    t: &[usize],
    c: usize,
    lo: usize,
    hi: usize,
    noise: f64,
    rng: &mut Rng,
) -> Candidate {
    let len = t.len();
    debug_assert!(lo <= hi, "precedence interval empty");
    let mut best = Candidate {
        delta: f64::INFINITY,
        node: p.clusters[c][0],
        edge: lo,
        lo,
        hi,
    };
    for e in lo..=hi {
        let (a, b) = (t[e - 1], t[e % len]);
        let base = p.d(a, b);
        for &u in &p.clusters[c] {
            let delta = p.d(a, u) + p.d(u, b) - base + jitter(noise, rng);
            if delta < best.delta {
                best.delta = delta;
                best.node = u;
                best.edge = e;
            }
        }
    }
    best
}

/// The feasible insertion interval of cluster `c` in `t` by scanning the whole tour: the
/// reference the incremental bounds are checked against in tests and debug builds, and the
/// interval of [`Operators::insert_one_quickly`].
fn interval_by_scan(p: &Problem, t: &[usize], c: usize) -> (usize, usize) {
    let mut lo = 1;
    let mut hi = t.len();
    for (i, &v) in t.iter().enumerate().skip(1) {
        let d = p.cl(v);
        if p.precedes(d, c) {
            lo = i + 1;
        }
        if p.precedes(c, d) && hi == t.len() {
            hi = i;
        }
    }
    (lo, hi)
}

/// Symmetric additive noise of amplitude `noise` (no random draw when the operator is exact).
#[inline]
fn jitter(noise: f64, rng: &mut Rng) -> f64 {
    if noise == 0.0 {
        0.0
    } else {
        noise * (2.0 * rng.unit() - 1.0)
    }
}

/// Index in `items` of the cluster with the largest `key` (first one on ties).
#[inline]
fn arg_best(items: &[usize], key: impl Fn(usize) -> f64) -> usize {
    let mut best = 0;
    let mut best_key = f64::NEG_INFINITY;
    for (i, &c) in items.iter().enumerate() {
        let k = key(c);
        if k > best_key {
            best_key = k;
            best = i;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(set: &str, name: &str) -> Problem {
        Problem::new(&crate::reference_instance(set, name)).unwrap()
    }

    /// Many destroy–repair cycles with every operator. `repair` asserts (under `cfg(test)`)
    /// after every insertion that each incrementally maintained interval equals a full scan;
    /// here every repaired order must also respect the precedence relation.
    #[test]
    fn incremental_intervals_match_a_scan_and_repairs_stay_feasible() {
        for (set, name) in [
            ("pcgtsplib", "ft53.2"),
            ("pcgtsplib", "ESC47"),
            ("pcgtsplib", "rbg109a"),
            ("industrial", "e1x_2"),
        ] {
            let p = problem(set, name);
            let mut ops = Operators::default();
            let mut rng = Rng::new(17);
            let mut t = Vec::new();
            ops.destroy_all(&p, &mut t);
            ops.repair(&p, &mut t, INSERTIONS[0], 0.0, &mut rng);
            assert!(p.order_is_valid(&t), "{name}: initial tour");
            for round in 0..400 {
                let how = REMOVALS[round % REMOVALS.len()];
                let count = rng.between(1, (p.m - 1).min(40));
                ops.destroy(&p, &mut t, how, count, &mut rng);
                assert_eq!(t.len(), p.m - count);
                let insertion = INSERTIONS[rng.below(INSERTIONS.len())];
                ops.repair(&p, &mut t, insertion, p.mean_arc, &mut rng);
                assert!(p.order_is_valid(&t), "{name}: round {round} ({how:?})");
            }
        }
    }
}
