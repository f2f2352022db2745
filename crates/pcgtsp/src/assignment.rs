//! The linear assignment problem (Hungarian method with potentials, O(k³)), written for
//! repeated small solves: buffers are reused, forbidden entries are `f64::INFINITY`.

/// A reusable assignment solver.
#[derive(Clone, Debug, Default)]
pub struct Assignment {
    u: Vec<f64>,
    v: Vec<f64>,
    p: Vec<usize>,
    way: Vec<usize>,
    minv: Vec<f64>,
    used: Vec<bool>,
    /// The next row to assign (1-based) of a solve in pieces.
    next_row: usize,
}

impl Assignment {
    /// Solves the `k × k` problem `cost` (row-major; rows are tails, columns heads).
    /// Afterwards [`Assignment::row_potential`] and [`Assignment::column_potential`] give
    /// feasible duals (`u_i + v_j ≤ cost_ij`) whose sum is the optimum.
    pub fn solve(&mut self, k: usize, cost: &[f64]) -> f64 {
        self.begin(k);
        self.solve_until(k, cost, &|| false)
            .expect("runs to the end without a pause")
    }

    /// Starts [`Assignment::solve`] in pieces: [`Assignment::solve_until`] then adds a row at a
    /// time (one shortest augmenting path, O(k²)): at k = 1,000 the whole solve is seconds.
    pub fn begin(&mut self, k: usize) {
        self.u.clear();
        self.u.resize(k + 1, 0.0);
        self.v.clear();
        self.v.resize(k + 1, 0.0);
        self.p.clear();
        self.p.resize(k + 1, 0);
        self.way.clear();
        self.way.resize(k + 1, 0);
        self.next_row = 1;
    }

    /// Goes on with the solve [`Assignment::begin`] started (the same `k` and `cost` on every
    /// call): rows until all are assigned (the optimum, as [`Assignment::solve`] gives it) or
    /// `pause()` says so after one (`None`: call again).
    pub fn solve_until(&mut self, k: usize, cost: &[f64], pause: &dyn Fn() -> bool) -> Option<f64> {
        debug_assert_eq!(cost.len(), k * k);
        let inf = f64::INFINITY;
        while self.next_row <= k {
            let i = self.next_row;
            self.next_row += 1;
            self.p[0] = i;
            let mut j0 = 0usize;
            self.minv.clear();
            self.minv.resize(k + 1, inf);
            self.used.clear();
            self.used.resize(k + 1, false);
            loop {
                self.used[j0] = true;
                let i0 = self.p[j0];
                let row = &cost[(i0 - 1) * k..i0 * k];
                let ui0 = self.u[i0];
                let mut delta = inf;
                let mut j1 = 0usize;
                for j in 1..=k {
                    if self.used[j] {
                        continue;
                    }
                    let cur = row[j - 1] - ui0 - self.v[j];
                    if cur < self.minv[j] {
                        self.minv[j] = cur;
                        self.way[j] = j0;
                    }
                    if self.minv[j] < delta {
                        delta = self.minv[j];
                        j1 = j;
                    }
                }
                if delta == inf {
                    self.next_row = k + 1;
                    return Some(inf);
                }
                for j in 0..=k {
                    if self.used[j] {
                        let pj = self.p[j];
                        self.u[pj] += delta;
                        self.v[j] -= delta;
                    } else {
                        self.minv[j] -= delta;
                    }
                }
                j0 = j1;
                if self.p[j0] == 0 {
                    break;
                }
            }
            loop {
                let j1 = self.way[j0];
                self.p[j0] = self.p[j1];
                j0 = j1;
                if j0 == 0 {
                    break;
                }
            }
            if self.next_row <= k && pause() {
                return None;
            }
        }
        let mut total = 0.0;
        for j in 1..=k {
            total += cost[(self.p[j] - 1) * k + (j - 1)];
        }
        Some(total)
    }

    /// Dual potential of row `i` (0-based) after [`Assignment::solve`].
    #[inline]
    pub fn row_potential(&self, i: usize) -> f64 {
        self.u[i + 1]
    }

    /// Dual potential of column `j` (0-based) after [`Assignment::solve`].
    #[inline]
    pub fn column_potential(&self, j: usize) -> f64 {
        self.v[j + 1]
    }

    /// The row assigned to column `j` (0-based) after a feasible [`Assignment::solve`].
    #[inline]
    pub fn row_of_column(&self, j: usize) -> usize {
        self.p[j + 1] - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(k: usize, cost: &[f64]) -> f64 {
        let mut perm: Vec<usize> = (0..k).collect();
        let mut best = f64::INFINITY;
        fn rec(i: usize, perm: &mut Vec<usize>, k: usize, cost: &[f64], acc: f64, best: &mut f64) {
            if i == k {
                *best = best.min(acc);
                return;
            }
            for j in i..k {
                perm.swap(i, j);
                rec(i + 1, perm, k, cost, acc + cost[i * k + perm[i]], best);
                perm.swap(i, j);
            }
        }
        rec(0, &mut perm, k, cost, 0.0, &mut best);
        best
    }

    #[test]
    fn matches_brute_force_and_duals_are_feasible() {
        let mut rng = cutroute_geometry::SplitMix64::new(12345);
        let mut next = || rng.next_u64();
        let mut solver = Assignment::default();
        for round in 0..300 {
            let k = 1 + (round % 7);
            let cost: Vec<f64> = (0..k * k)
                .map(|_| {
                    let r = next();
                    if r % 5 == 0 {
                        f64::INFINITY
                    } else {
                        (r % 100) as f64
                    }
                })
                .collect();
            let got = solver.solve(k, &cost);
            let want = brute(k, &cost);
            assert_eq!(got, want, "k={k} cost={cost:?}");
            if got.is_finite() {
                let mut dual = 0.0;
                for i in 0..k {
                    dual += solver.row_potential(i) + solver.column_potential(i);
                    for j in 0..k {
                        let slack =
                            cost[i * k + j] - solver.row_potential(i) - solver.column_potential(j);
                        assert!(slack >= -1e-9, "dual infeasible");
                    }
                }
                assert!((dual - got).abs() < 1e-9);
            }
        }
    }

    /// The solve in pieces (a pause after every row) gives the one-piece solve's optimum and
    /// duals, on random matrices with forbidden entries.
    #[test]
    fn a_solve_in_pieces_equals_the_solve_in_one() {
        let mut rng = cutroute_geometry::SplitMix64::new(777);
        let mut next = || rng.next_u64();
        for round in 0..100 {
            let k = 1 + (round % 30);
            let cost: Vec<f64> = (0..k * k)
                .map(|_| {
                    let r = next();
                    if r % 9 == 0 {
                        f64::INFINITY
                    } else {
                        (r % 1000) as f64 / 7.0
                    }
                })
                .collect();
            let mut whole = Assignment::default();
            let want = whole.solve(k, &cost);
            let mut pieces = Assignment::default();
            pieces.begin(k);
            let mut calls = 1;
            let got = loop {
                match pieces.solve_until(k, &cost, &|| true) {
                    Some(value) => break value,
                    None => calls += 1,
                }
            };
            assert_eq!(got.to_bits(), want.to_bits(), "k={k}");
            if want.is_finite() {
                assert_eq!(calls, k, "a row per call");
                for i in 0..k {
                    assert_eq!(pieces.row_potential(i), whole.row_potential(i));
                    assert_eq!(pieces.column_potential(i), whole.column_potential(i));
                }
            }
        }
    }
}
