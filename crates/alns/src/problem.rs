//! The solver's own preprocessed copy of an instance: penalised cost matrix and the transitive
//! closure of the precedence relation (with per-cluster predecessor / successor lists).

use cutroute_pcgtsp::Instance;

use crate::AlnsError;

/// Marks "cluster not in the partial tour" in position arrays.
pub(crate) const ABSENT: usize = usize::MAX;

/// Preprocessed instance. Owns its data so that a solver has no lifetime tied to the instance
/// (the web worker keeps solvers across messages).
#[derive(Clone, Debug)]
pub(crate) struct Problem {
    /// Number of nodes.
    pub n: usize,
    /// Number of clusters.
    pub m: usize,
    /// The depot cluster (always first in a tour).
    pub depot: usize,
    /// Row-major arc costs; forbidden arcs carry exactly `penalty`.
    pub cost: Vec<f64>,
    /// The cost given to a forbidden arc: larger than the spread of any tour without one, so
    /// that the search can pass through infeasible tours but always prefers feasible ones.
    pub penalty: f64,
    /// Node lists of the clusters.
    pub clusters: Vec<Vec<usize>>,
    /// Cluster of every node.
    pub node_cluster: Vec<usize>,
    /// Transitively closed precedence, `words` u64 per row: bit `b` of row `a` = a before b.
    before: Vec<u64>,
    /// The transpose of `before`: bit `a` of row `b` = a before b.
    after: Vec<u64>,
    /// u64 words per bit row (`⌈m / 64⌉`).
    pub words: usize,
    /// Clusters that must come before each cluster (closure, depot excluded).
    pub preds: Vec<Vec<usize>>,
    /// Clusters that must come after each cluster (closure, depot excluded).
    pub succs: Vec<Vec<usize>>,
    /// Mean finite arc cost between different clusters: the scale of insertion noise.
    pub mean_arc: f64,
    /// Whether any precedence pair exists (plain GTSP otherwise).
    pub has_precedence: bool,
}

impl Problem {
    /// Validates `instance` and builds the closure of its precedence relation (in one piece:
    /// [`ProblemBuild`] is the same work in slices).
    #[cfg(test)]
    pub(crate) fn new(instance: &Instance) -> Result<Self, AlnsError> {
        let mut build = ProblemBuild::new(instance)?;
        loop {
            if let Some(problem) = build.advance(instance, &|| false)? {
                return Ok(problem);
            }
        }
    }

    /// Penalised cost of the arc `a → b`.
    #[inline(always)]
    pub(crate) fn d(&self, a: usize, b: usize) -> f64 {
        // SAFETY-free fast path: indices come from node lists validated in `new`.
        self.cost[a * self.n + b]
    }

    /// The row of arc costs leaving `a`.
    #[inline(always)]
    pub(crate) fn row(&self, a: usize) -> &[f64] {
        &self.cost[a * self.n..(a + 1) * self.n]
    }

    /// Whether cluster `a` must be visited before cluster `b`.
    #[inline(always)]
    pub(crate) fn precedes(&self, a: usize, b: usize) -> bool {
        self.before[a * self.words + b / 64] >> (b % 64) & 1 == 1
    }

    /// The clusters that must come after cluster `a`, as a bit row of `words` words.
    #[inline(always)]
    pub(crate) fn successor_bits(&self, a: usize) -> &[u64] {
        &self.before[a * self.words..(a + 1) * self.words]
    }

    /// The clusters that must come before cluster `b`, as a bit row of `words` words.
    #[inline(always)]
    pub(crate) fn predecessor_bits(&self, b: usize) -> &[u64] {
        &self.after[b * self.words..(b + 1) * self.words]
    }

    /// Whether clusters `a` and `b` are ordered by the precedence relation either way.
    #[inline(always)]
    pub(crate) fn related(&self, a: usize, b: usize) -> bool {
        self.precedes(a, b) || self.precedes(b, a)
    }

    /// Cluster of node `v`.
    #[inline(always)]
    pub(crate) fn cl(&self, v: usize) -> usize {
        self.node_cluster[v]
    }

    /// Whether the closed tour uses no forbidden arc.
    pub(crate) fn uses_no_forbidden_arc(&self, t: &[usize]) -> bool {
        let last = t.len() - 1;
        t.windows(2).all(|w| self.d(w[0], w[1]) < self.penalty)
            && self.d(t[last], t[0]) < self.penalty
    }

    /// Whether the cluster order of `t` respects the precedence relation and visits every
    /// cluster once with the depot first (a debug aid and a guard before reporting a tour).
    pub(crate) fn order_is_valid(&self, t: &[usize]) -> bool {
        if t.len() != self.m || self.cl(t[0]) != self.depot {
            return false;
        }
        let mut pos = vec![ABSENT; self.m];
        for (i, &v) in t.iter().enumerate() {
            let c = self.cl(v);
            if pos[c] != ABSENT {
                return false;
            }
            pos[c] = i;
        }
        (0..self.m).all(|b| self.preds[b].iter().all(|&a| pos[a] < pos[b]))
    }
}

/// Rows of the cost matrix per piece of [`ProblemBuild`] between two looks at the clock (a row
/// of a 7,000-node discretisation is 56 kB).
const ROWS_PER_LOOK: usize = 16;

/// [`Problem`]'s construction in pieces, so that a job answers Stop while a big instance is
/// prepared (the dense matrix of Nest03's discretisation, 47 M arcs, took 2.2 s in one piece):
/// the structure is checked at once, then the cost matrix is scanned and copied a few rows at a
/// time, the precedence closure a pivot at a time, then the lists are made. Every call gets
/// the same instance; the result is the one-piece build's.
#[derive(Clone, Debug)]
pub(crate) struct ProblemBuild {
    stage: BuildStage,
    max_abs: f64,
    sum: f64,
    count: usize,
    penalty: f64,
    cost: Vec<f64>,
    before: Vec<u64>,
    words: usize,
}

#[derive(Clone, Copy, Debug)]
enum BuildStage {
    /// Scanning the costs for bad values, their largest magnitude and mean (next row).
    Scan(usize),
    /// Copying the costs with forbidden arcs penalised (next row).
    Copy(usize),
    /// Reading the precedence pairs.
    Precedence,
    /// Warshall's closure (next pivot).
    Close(usize),
    /// The transposed rows and per-cluster lists.
    Lists,
}

impl ProblemBuild {
    /// Checks the instance's shape (sizes, clusters, depot); the costs and precedence are
    /// checked by [`ProblemBuild::advance`].
    pub(crate) fn new(instance: &Instance) -> Result<Self, AlnsError> {
        let n = instance.node_count;
        let m = instance.clusters.len();
        if n == 0 || m == 0 {
            return Err(AlnsError::Empty);
        }
        if instance.cost.len() != n * n {
            return Err(AlnsError::CostMatrixSize {
                expected: n * n,
                found: instance.cost.len(),
            });
        }
        if instance.node_cluster.len() != n {
            return Err(AlnsError::NodeClusterLength {
                expected: n,
                found: instance.node_cluster.len(),
            });
        }
        if instance.depot >= m {
            return Err(AlnsError::DepotOutOfRange(instance.depot));
        }
        let mut seen = vec![false; n];
        for (c, nodes) in instance.clusters.iter().enumerate() {
            if nodes.is_empty() {
                return Err(AlnsError::EmptyCluster(c));
            }
            for &v in nodes {
                if v >= n || seen[v] || instance.node_cluster[v] != c {
                    return Err(AlnsError::BadClusterNode {
                        cluster: c,
                        node: v,
                    });
                }
                seen[v] = true;
            }
        }
        if let Some(v) = seen.iter().position(|&s| !s) {
            return Err(AlnsError::NodeWithoutCluster(v));
        }
        Ok(ProblemBuild {
            stage: BuildStage::Scan(0),
            max_abs: 0.0,
            sum: 0.0,
            count: 0,
            penalty: 0.0,
            cost: Vec::new(),
            before: Vec::new(),
            words: m.div_ceil(64),
        })
    }

    /// Works on the build until it is done (`Some`) or `stop()` says so between pieces
    /// (`None`: call again with the same instance).
    pub(crate) fn advance(
        &mut self,
        instance: &Instance,
        stop: &dyn Fn() -> bool,
    ) -> Result<Option<Problem>, AlnsError> {
        let n = instance.node_count;
        let m = instance.clusters.len();
        let words = self.words;
        loop {
            match self.stage {
                BuildStage::Scan(row) if row < n => {
                    let to = (row + ROWS_PER_LOOK).min(n);
                    for i in row * n..to * n {
                        let c = instance.cost[i];
                        if c.is_nan() || c == f64::NEG_INFINITY {
                            return Err(AlnsError::BadCost {
                                from: i / n,
                                to: i % n,
                            });
                        }
                        if c.is_finite() {
                            self.max_abs = self.max_abs.max(c.abs());
                            if instance.node_cluster[i / n] != instance.node_cluster[i % n] {
                                self.sum += c;
                                self.count += 1;
                            }
                        }
                    }
                    self.stage = BuildStage::Scan(to);
                }
                BuildStage::Scan(_) => {
                    // Any tour has m arcs: a tour with one penalty arc costs at least
                    // penalty − (m − 1)·max_abs, a tour without one at most m·max_abs.
                    self.penalty = (2.0 * m as f64 + 2.0) * (self.max_abs + 1.0);
                    self.cost = Vec::with_capacity(n * n);
                    self.stage = BuildStage::Copy(0);
                }
                BuildStage::Copy(row) if row < n => {
                    let to = (row + ROWS_PER_LOOK).min(n);
                    let penalty = self.penalty;
                    self.cost
                        .extend(instance.cost[row * n..to * n].iter().map(|&c| {
                            if c.is_finite() {
                                c
                            } else {
                                penalty
                            }
                        }));
                    self.stage = BuildStage::Copy(to);
                }
                BuildStage::Copy(_) => self.stage = BuildStage::Precedence,
                BuildStage::Precedence => {
                    let mut before = vec![0u64; m * words];
                    let depot = instance.depot;
                    for &(a, b) in &instance.precedence {
                        if a >= m || b >= m {
                            return Err(AlnsError::PrecedenceOutOfRange {
                                before: a,
                                after: b,
                            });
                        }
                        if b == depot && a != depot {
                            return Err(AlnsError::PrecedenceCycle(depot));
                        }
                        if a == depot || b == depot {
                            continue; // the depot precedes everything anyway
                        }
                        if a == b {
                            return Err(AlnsError::PrecedenceCycle(a));
                        }
                        before[a * words + b / 64] |= 1 << (b % 64);
                    }
                    self.before = before;
                    self.stage = BuildStage::Close(0);
                }
                BuildStage::Close(k) if k < m => {
                    // Warshall on bit rows: if i before k then everything after k is after i.
                    let before = &mut self.before;
                    for i in 0..m {
                        if before[i * words + k / 64] >> (k % 64) & 1 == 1 {
                            for w in 0..words {
                                let bits = before[k * words + w];
                                before[i * words + w] |= bits;
                            }
                        }
                    }
                    self.stage = BuildStage::Close(k + 1);
                }
                BuildStage::Close(_) => self.stage = BuildStage::Lists,
                BuildStage::Lists => return self.finish(instance).map(Some),
            }
            if stop() {
                return Ok(None);
            }
        }
    }

    /// The transposed closure, the per-cluster lists and the problem.
    fn finish(&mut self, instance: &Instance) -> Result<Problem, AlnsError> {
        let n = instance.node_count;
        let m = instance.clusters.len();
        let words = self.words;
        let before = std::mem::take(&mut self.before);
        let mut after = vec![0u64; m * words];
        let mut preds = vec![Vec::new(); m];
        let mut succs = vec![Vec::new(); m];
        let mut has_precedence = false;
        for a in 0..m {
            for b in 0..m {
                if before[a * words + b / 64] >> (b % 64) & 1 == 1 {
                    if a == b {
                        return Err(AlnsError::PrecedenceCycle(a));
                    }
                    preds[b].push(a);
                    succs[a].push(b);
                    after[b * words + a / 64] |= 1 << (a % 64);
                    has_precedence = true;
                }
            }
        }
        let mean_arc = if self.count > 0 {
            (self.sum / self.count as f64).abs().max(1e-9)
        } else {
            1.0
        };
        Ok(Problem {
            n,
            m,
            depot: instance.depot,
            cost: std::mem::take(&mut self.cost),
            penalty: self.penalty,
            clusters: instance.clusters.clone(),
            node_cluster: instance.node_cluster.clone(),
            before,
            after,
            words,
            preds,
            succs,
            mean_arc,
            has_precedence,
        })
    }
}
