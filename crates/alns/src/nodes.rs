//! Optimal node choice for a fixed cluster order: a shortest cycle through the layered graph.

use crate::problem::Problem;

/// Reusable buffers of the layered-graph DP.
#[derive(Default, Clone, Debug)]
pub(crate) struct NodeChoice {
    dist: Vec<f64>,
    parent: Vec<u32>,
    offset: Vec<usize>,
    rotated: Vec<usize>,
    path: Vec<usize>,
}

impl NodeChoice {
    /// Rewrites the nodes of the closed tour `t` (depot first) to the cheapest choice for its
    /// cluster order and returns the new penalised cost.
    ///
    /// The cycle is closed, so the DP may start in any layer: it starts in the smallest cluster
    /// and tries each of its nodes as the fixed start (the trick GLNS uses), which costs
    /// `min |V_i| · Σ |V_i||V_i+1|`.
    pub(crate) fn optimise(&mut self, p: &Problem, t: &mut [usize]) -> f64 {
        let m = t.len();
        if m == 1 {
            let best = *p.clusters[p.cl(t[0])]
                .iter()
                .min_by(|&&a, &&b| p.d(a, a).total_cmp(&p.d(b, b)))
                .expect("clusters are non-empty");
            t[0] = best;
            return p.d(best, best);
        }
        let start = (0..m)
            .min_by_key(|&k| p.clusters[p.cl(t[k])].len())
            .expect("tour is non-empty");
        self.rotated.clear();
        self.rotated
            .extend((0..m).map(|k| p.cl(t[(start + k) % m])));
        self.offset.clear();
        let mut total = 0;
        for &c in &self.rotated {
            self.offset.push(total);
            total += p.clusters[c].len();
        }
        self.offset.push(total);
        self.dist.resize(total, 0.0);
        self.parent.resize(total, 0);
        self.path.resize(m, 0);

        let mut best_total = f64::INFINITY;
        let first = &p.clusters[self.rotated[0]];
        for (si, &s) in first.iter().enumerate() {
            // Layer 1 from the fixed start.
            let row = p.row(s);
            let l1 = self.rotated[1];
            for (j, &v) in p.clusters[l1].iter().enumerate() {
                self.dist[self.offset[1] + j] = row[v];
                self.parent[self.offset[1] + j] = si as u32;
            }
            for k in 2..m {
                let (prev_off, cur_off) = (self.offset[k - 1], self.offset[k]);
                let prev = &p.clusters[self.rotated[k - 1]];
                let cur = &p.clusters[self.rotated[k]];
                for j in 0..cur.len() {
                    self.dist[cur_off + j] = f64::INFINITY;
                }
                for (i, &u) in prev.iter().enumerate() {
                    let du = self.dist[prev_off + i];
                    let row = p.row(u);
                    for (j, &v) in cur.iter().enumerate() {
                        let cand = du + row[v];
                        if cand < self.dist[cur_off + j] {
                            self.dist[cur_off + j] = cand;
                            self.parent[cur_off + j] = i as u32;
                        }
                    }
                }
            }
            let last = &p.clusters[self.rotated[m - 1]];
            let last_off = self.offset[m - 1];
            let mut close = f64::INFINITY;
            let mut close_at = 0;
            for (i, &u) in last.iter().enumerate() {
                let cand = self.dist[last_off + i] + p.d(u, s);
                if cand < close {
                    close = cand;
                    close_at = i;
                }
            }
            if close < best_total {
                best_total = close;
                let mut idx = close_at;
                for k in (1..m).rev() {
                    self.path[k] = p.clusters[self.rotated[k]][idx];
                    idx = self.parent[self.offset[k] + idx] as usize;
                }
                self.path[0] = s;
            }
        }
        for k in 0..m {
            t[(start + k) % m] = self.path[k];
        }
        best_total
    }
}
