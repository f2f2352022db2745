//! Precedence-respecting local search on a node tour with fixed nodes (2-opt, or-opt) and
//! cluster re-insertion with node re-selection.
//!
//! Costs are asymmetric in general: reversing a segment changes the cost of every arc inside it,
//! so 2-opt evaluates the reversed segment with prefix sums of backward arc costs.

use crate::problem::{Problem, ABSENT};

/// Positions [`LocalSearch::reinsert_until`] visits between questions to its `pause`.
const REINSERT_PAUSE_EVERY: usize = 16;

/// Reusable buffers of the local search. Every move family also runs in pieces
/// (`*_until`, paused by the caller's clock) with the result of one call: on the 7,000-node
/// discretisations of Nest02/Nest03 one family took 0.2–0.7 s.
#[derive(Default, Clone, Debug)]
pub(crate) struct LocalSearch {
    forward: Vec<f64>,
    backward: Vec<f64>,
    last_pred: Vec<usize>,
    pos: Vec<usize>,
    buffer: Vec<usize>,
    waiting: Vec<usize>,
    inside_preds: Vec<u32>,
    count: Vec<u32>,
}

/// Smallest improvement that counts (guards against float noise cycling).
pub(crate) fn eps(p: &Problem) -> f64 {
    1e-9 * (1.0 + p.mean_arc)
}

impl LocalSearch {
    fn prefix_sums(&mut self, p: &Problem, t: &[usize]) {
        let m = t.len();
        self.forward.clear();
        self.backward.clear();
        self.forward.push(0.0);
        self.backward.push(0.0);
        let (mut f, mut b) = (0.0, 0.0);
        for k in 0..m - 1 {
            f += p.d(t[k], t[k + 1]);
            b += p.d(t[k + 1], t[k]);
            self.forward.push(f);
            self.backward.push(b);
        }
    }

    fn positions(&mut self, p: &Problem, t: &[usize]) {
        self.pos.clear();
        self.pos.resize(p.m, ABSENT);
        for (i, &v) in t.iter().enumerate() {
            self.pos[p.cl(v)] = i;
        }
    }

    /// Asymmetric 2-opt: reverses `t[i..=j]` when that is cheaper and no precedence pair lies
    /// inside the segment. Returns whether the tour improved.
    pub(crate) fn two_opt(&mut self, p: &Problem, t: &mut [usize]) -> bool {
        self.two_opt_until(p, t, &|| false).0
    }

    /// [`LocalSearch::two_opt`] until `pause()` (asked after every improving move): whether
    /// the tour improved, and whether the family is finished (called again on the same tour,
    /// it goes on where it paused: every pass starts from the tour as it is).
    #[inline(never)]
    pub(crate) fn two_opt_until(
        &mut self,
        p: &Problem,
        t: &mut [usize],
        pause: &dyn Fn() -> bool,
    ) -> (bool, bool) {
        let m = t.len();
        if m < 4 {
            return (false, true);
        }
        let eps = eps(p);
        let mut improved_any = false;
        loop {
            let mut improved = false;
            self.prefix_sums(p, t);
            // last_pred[k]: largest position of a predecessor of the cluster at k.
            self.positions(p, t);
            self.last_pred.clear();
            for &v in t.iter() {
                let c = p.cl(v);
                let lp = p.preds[c].iter().map(|&a| self.pos[a]).max().unwrap_or(0);
                self.last_pred.push(lp);
            }
            for i in 1..m - 1 {
                let a = t[i - 1];
                let b = t[i];
                let mut best = -eps;
                let mut best_j = 0;
                for j in i + 1..m {
                    if self.last_pred[j] >= i {
                        break; // a predecessor of t[j] is inside: every longer segment too
                    }
                    let c = t[j];
                    let d = t[(j + 1) % m];
                    let delta = p.d(a, c) + p.d(b, d) - p.d(a, b) - p.d(c, d)
                        + (self.backward[j] - self.backward[i])
                        - (self.forward[j] - self.forward[i]);
                    if delta < best {
                        best = delta;
                        best_j = j;
                    }
                }
                if best_j > 0 {
                    t[i..=best_j].reverse();
                    improved = true;
                    break;
                }
            }
            if !improved {
                return (improved_any, true);
            }
            improved_any = true;
            if pause() {
                return (true, false);
            }
        }
    }

    /// Or-opt: moves a segment of 2–3 clusters (possibly reversed) elsewhere, passing only
    /// clusters it is not ordered with. Returns whether the tour improved.
    pub(crate) fn or_opt(&mut self, p: &Problem, t: &mut [usize]) -> bool {
        self.or_opt_until(p, t, &|| false).0
    }

    /// [`LocalSearch::or_opt`] until `pause()` (asked after every sweep that moved a segment),
    /// as [`LocalSearch::two_opt_until`].
    #[inline(never)]
    pub(crate) fn or_opt_until(
        &mut self,
        p: &Problem,
        t: &mut [usize],
        pause: &dyn Fn() -> bool,
    ) -> (bool, bool) {
        let m = t.len();
        if m < 3 {
            return (false, true);
        }
        let eps = eps(p);
        let mut improved_any = false;
        // Single segments are covered by `reinsert` (which also re-picks the node).
        loop {
            let mut improved = false;
            for len in 2..=3usize.min(m - 2) {
                for i in 1..=m - len {
                    let first = t[i];
                    let last = t[i + len - 1];
                    let prev = t[i - 1];
                    let next = t[(i + len) % m];
                    let gain = p.d(prev, first) + p.d(last, next) - p.d(prev, next);
                    let seg = &t[i..i + len];
                    let mut inner_fwd = 0.0;
                    let mut inner_bwd = 0.0;
                    let mut reversible = len > 1;
                    for k in 0..len - 1 {
                        inner_fwd += p.d(seg[k], seg[k + 1]);
                        inner_bwd += p.d(seg[k + 1], seg[k]);
                        for l in k + 1..len {
                            if p.related(p.cl(seg[k]), p.cl(seg[l])) {
                                reversible = false;
                            }
                        }
                    }
                    let rev_extra = inner_bwd - inner_fwd;
                    // (delta, insert-after position in the original tour, reversed)
                    let mut best = (-eps, ABSENT, false);
                    // Forward: insert between t[k] and t[k+1], k = i+len..m-1.
                    for k in i + len..m {
                        let ck = p.cl(t[k]);
                        if seg.iter().any(|&x| p.precedes(p.cl(x), ck)) {
                            break;
                        }
                        let (x, y) = (t[k], t[(k + 1) % m]);
                        let base = p.d(x, y);
                        let delta = p.d(x, first) + p.d(last, y) - base - gain;
                        if delta < best.0 {
                            best = (delta, k, false);
                        }
                        if reversible {
                            let delta = p.d(x, last) + p.d(first, y) - base - gain + rev_extra;
                            if delta < best.0 {
                                best = (delta, k, true);
                            }
                        }
                    }
                    // Backward: insert between t[k-1] and t[k], k = i-1 down to 1.
                    for k in (1..i).rev() {
                        let ck = p.cl(t[k]);
                        if seg.iter().any(|&x| p.precedes(ck, p.cl(x))) {
                            break;
                        }
                        let (x, y) = (t[k - 1], t[k]);
                        let base = p.d(x, y);
                        let delta = p.d(x, first) + p.d(last, y) - base - gain;
                        if delta < best.0 {
                            best = (delta, k - 1, false);
                        }
                        if reversible {
                            let delta = p.d(x, last) + p.d(first, y) - base - gain + rev_extra;
                            if delta < best.0 {
                                best = (delta, k - 1, true);
                            }
                        }
                    }
                    if best.1 != ABSENT {
                        self.move_segment(t, i, len, best.1, best.2);
                        improved = true;
                    }
                }
            }
            if !improved {
                return (improved_any, true);
            }
            improved_any = true;
            if pause() {
                return (true, false);
            }
        }
    }

    /// Moves `t[i..i+len]` to just after the element now at `after` (an index outside the
    /// segment, in the original tour), reversing it if asked.
    fn move_segment(&mut self, t: &mut [usize], i: usize, len: usize, after: usize, rev: bool) {
        self.buffer.clear();
        self.buffer.extend_from_slice(&t[i..i + len]);
        if rev {
            self.buffer.reverse();
        }
        if after > i {
            // Shift t[i+len..=after] left by len, then place the segment.
            t.copy_within(i + len..=after, i);
            let start = after + 1 - len;
            t[start..start + len].copy_from_slice(&self.buffer);
        } else {
            // Shift t[after+1..i] right by len.
            t.copy_within(after + 1..i, after + 1 + len);
            t[after + 1..after + 1 + len].copy_from_slice(&self.buffer);
        }
    }

    /// Re-inserts each cluster at its best feasible position with its best node (GLNS's
    /// "move opt"). Returns whether the tour improved.
    pub(crate) fn reinsert(&mut self, p: &Problem, t: &mut [usize]) -> bool {
        self.reinsert_until(p, t, &mut None, &|| false).0
    }

    /// [`LocalSearch::reinsert`] until `pause()` (asked every [`REINSERT_PAUSE_EVERY`]
    /// positions), as [`LocalSearch::two_opt_until`]; `at` keeps where it paused (the next
    /// position and the positions since the last improvement; `None` to begin).
    #[inline(never)]
    pub(crate) fn reinsert_until(
        &mut self,
        p: &Problem,
        t: &mut [usize],
        at: &mut Option<(usize, usize)>,
        pause: &dyn Fn() -> bool,
    ) -> (bool, bool) {
        let m = t.len();
        if m < 3 {
            return (false, true);
        }
        let eps = eps(p);
        let mut improved_any = false;
        let (mut i, mut since_improvement) = at.take().unwrap_or((1, 0));
        let mut visited = 0;
        self.positions(p, t);
        // Cycle through positions until a full round brings nothing.
        while since_improvement < m - 1 {
            visited += 1;
            if visited % REINSERT_PAUSE_EVERY == 0 && pause() {
                *at = Some((i, since_improvement));
                return (improved_any, false);
            }
            let v = t[i];
            let c = p.cl(v);
            let prev = t[i - 1];
            let next = t[(i + 1) % m];
            let gain = p.d(prev, v) + p.d(v, next) - p.d(prev, next);
            let lo = p.preds[c].iter().map(|&a| self.pos[a]).max().unwrap_or(0);
            let hi = p.succs[c].iter().map(|&b| self.pos[b]).min().unwrap_or(m);
            // Candidate arcs (t[k], t[k+1]) for k in lo..hi, with the removed node bridged.
            let mut best = (gain - eps, ABSENT, v);
            for k in lo..hi {
                if k == i {
                    continue; // arc (v, next) disappears with v
                }
                let x = if k == i - 1 { prev } else { t[k] };
                let y = if k == i - 1 { next } else { t[(k + 1) % m] };
                let base = p.d(x, y);
                for &u in &p.clusters[c] {
                    let delta = p.d(x, u) + p.d(u, y) - base;
                    if delta < best.0 {
                        best = (delta, k, u);
                    }
                }
            }
            if best.1 != ABSENT {
                let k = best.1;
                t[i] = best.2;
                if k != i - 1 {
                    self.move_segment(t, i, 1, k, false);
                    self.positions(p, t);
                }
                improved_any = true;
                since_improvement = 0;
            } else {
                since_improvement += 1;
            }
            i = if i + 1 >= m { 1 } else { i + 1 };
        }
        (improved_any, true)
    }

    /// Block reversal: reverses `t[i..=j]` where the segment holds precedence pairs, then
    /// restores precedence with the stable topological order closest to the reversed one (a
    /// cluster waits only for its own predecessors). On cutting plans this turns the direction
    /// of travel of a run of "hole, then its outer contour" pairs around, which no plain 2-opt
    /// or or-opt move can do. Segments are at most `max_len` long. Returns whether it improved.
    pub(crate) fn block_reverse(&mut self, p: &Problem, t: &mut [usize], max_len: usize) -> bool {
        self.block_reverse_until(p, t, max_len, &|| false).0
    }

    /// [`LocalSearch::block_reverse`] until `pause()` (asked after every improving
    /// reversal), as [`LocalSearch::two_opt_until`].
    #[inline(never)]
    pub(crate) fn block_reverse_until(
        &mut self,
        p: &Problem,
        t: &mut [usize],
        max_len: usize,
        pause: &dyn Fn() -> bool,
    ) -> (bool, bool) {
        let m = t.len();
        if m < 4 || !p.has_precedence {
            return (false, true);
        }
        let eps = eps(p);
        let mut improved_any = false;
        'restart: loop {
            self.prefix_sums(p, t);
            self.positions(p, t);
            self.last_pred.clear();
            for &v in t.iter() {
                let c = p.cl(v);
                let lp = p.preds[c].iter().map(|&a| self.pos[a]).max().unwrap_or(0);
                self.last_pred.push(lp);
            }
            self.inside_preds.resize(m, 0);
            self.count.resize(m, 0);
            for i in 1..m - 1 {
                let a = t[i - 1];
                self.inside_preds[i] = 0;
                let mut internal = false;
                for j in i + 1..m.min(i + max_len) {
                    // Predecessors of t[j] inside t[i..j]: independent of where the segment ends.
                    let cj = p.cl(t[j]);
                    self.inside_preds[j] = if self.last_pred[j] >= i {
                        internal = true;
                        t[i..j].iter().filter(|&&x| p.precedes(p.cl(x), cj)).count() as u32
                    } else {
                        0
                    };
                    if !internal {
                        continue; // plain 2-opt territory
                    }
                    self.repaired_reversal(p, t, i, j);
                    let r = &self.buffer;
                    let d_next = t[(j + 1) % m];
                    let mut new = p.d(a, r[0]) + p.d(r[r.len() - 1], d_next);
                    for w in r.windows(2) {
                        new += p.d(w[0], w[1]);
                    }
                    let old =
                        p.d(a, t[i]) + (self.forward[j] - self.forward[i]) + p.d(t[j], d_next);
                    if new < old - eps {
                        t[i..=j].copy_from_slice(&self.buffer);
                        improved_any = true;
                        if pause() {
                            return (true, false);
                        }
                        continue 'restart;
                    }
                }
            }
            return (improved_any, true);
        }
    }

    /// Reverses `t[i..=j]` in place with precedence repaired as in [`Self::block_reverse`].
    pub(crate) fn reverse_repaired(&mut self, p: &Problem, t: &mut [usize], i: usize, j: usize) {
        self.inside_preds.resize(t.len(), 0);
        self.count.resize(t.len(), 0);
        for k in i..=j {
            let ck = p.cl(t[k]);
            self.inside_preds[k] =
                t[i..k].iter().filter(|&&x| p.precedes(p.cl(x), ck)).count() as u32;
        }
        self.repaired_reversal(p, t, i, j);
        t[i..=j].copy_from_slice(&self.buffer);
    }

    /// Writes into `buffer` the reversal of `t[i..=j]` (a precedence-feasible run) in which
    /// every cluster is delayed just enough to follow its predecessors inside the segment:
    /// Kahn's algorithm that always takes the earliest available cluster of the reversed order.
    fn repaired_reversal(&mut self, p: &Problem, t: &[usize], i: usize, j: usize) {
        self.buffer.clear();
        self.waiting.clear(); // positions, in reversed order (earliest first)
        for k in (i..=j).rev() {
            self.count[k] = self.inside_preds[k];
        }
        for k in (i..=j).rev() {
            if self.count[k] > 0 {
                self.waiting.push(k);
                continue;
            }
            self.place(p, t, k);
            // Placing may free waiting clusters; take the earliest free one each time.
            while let Some(w) = self.waiting.iter().position(|&x| self.count[x] == 0) {
                let x = self.waiting.remove(w);
                self.place(p, t, x);
            }
        }
        debug_assert!(self.waiting.is_empty());
    }

    /// Appends `t[k]` to the reversal under construction and releases its successors.
    fn place(&mut self, p: &Problem, t: &[usize], k: usize) {
        self.buffer.push(t[k]);
        let ck = p.cl(t[k]);
        for &x in &self.waiting {
            if p.precedes(ck, p.cl(t[x])) {
                self.count[x] -= 1;
            }
        }
    }
}
