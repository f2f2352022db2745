//! The precedence order on clusters: transitive closure and reduction as bitsets.

use crate::instance::Instance;

/// A set of clusters as a dense bitset (any number of clusters).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct ClusterSet {
    words: Vec<u64>,
}

impl ClusterSet {
    /// The empty set over `len` clusters.
    pub fn new(len: usize) -> Self {
        ClusterSet {
            words: vec![0; len.div_ceil(64)],
        }
    }

    /// Adds cluster `c`.
    #[inline]
    pub fn insert(&mut self, c: usize) {
        self.words[c / 64] |= 1 << (c % 64);
    }

    /// Removes cluster `c`.
    #[inline]
    pub fn remove(&mut self, c: usize) {
        self.words[c / 64] &= !(1 << (c % 64));
    }

    /// Whether cluster `c` is in the set.
    #[inline]
    pub fn contains(&self, c: usize) -> bool {
        self.words
            .get(c / 64)
            .is_some_and(|w| w >> (c % 64) & 1 == 1)
    }

    /// Adds every cluster of `other`.
    pub fn union_with(&mut self, other: &ClusterSet) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a |= b;
        }
    }

    /// Whether every cluster of `self` is in `other`.
    pub fn is_subset(&self, other: &ClusterSet) -> bool {
        self.words
            .iter()
            .zip(&other.words)
            .all(|(a, b)| a & !b == 0)
    }

    /// Whether the two sets share a cluster.
    pub fn intersects(&self, other: &ClusterSet) -> bool {
        self.words.iter().zip(&other.words).any(|(a, b)| a & b != 0)
    }

    /// Number of clusters in the set.
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|&w| w == 0)
    }

    /// The clusters in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        set_bits(&self.words)
    }

    /// The raw 64-bit words (cluster `c` is bit `c % 64` of word `c / 64`).
    pub fn words(&self) -> &[u64] {
        &self.words
    }
}

/// The set bits of a bitset of 64-bit words (bit `c % 64` of word `c / 64` is `c`), in
/// increasing order: the members of a [`ClusterSet`] or of an ideal key.
#[inline]
pub(crate) fn set_bits(words: &[u64]) -> impl Iterator<Item = usize> + '_ {
    words.iter().enumerate().flat_map(|(i, &word)| {
        let mut w = word;
        std::iter::from_fn(move || {
            if w == 0 {
                return None;
            }
            let bit = w.trailing_zeros() as usize;
            w &= w - 1;
            Some(i * 64 + bit)
        })
    })
}

/// Why the precedence pairs of an instance do not form a partial order with the depot first.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OrderError {
    /// A pair names a cluster that does not exist.
    #[error("precedence pair ({before}, {after}) names a cluster out of range")]
    ClusterOutOfRange {
        /// First cluster of the pair.
        before: usize,
        /// Second cluster of the pair.
        after: usize,
    },
    /// The pairs contain a cycle (a cluster would precede itself).
    #[error("cyclic precedence through cluster {cluster}")]
    Cyclic {
        /// A cluster on the cycle.
        cluster: usize,
    },
    /// Some cluster is required before the depot, which is always first.
    #[error("cluster {before} must precede the depot")]
    BeforeDepot {
        /// The offending cluster.
        before: usize,
    },
}

/// The precedence order of an instance: the depot precedes every cluster, plus the file's pairs,
/// transitively closed; and its transitive reduction (the cover relation).
#[derive(Clone, Debug)]
pub struct PrecedenceOrder {
    /// Strict predecessors of every cluster (closure; the depot is a predecessor of all others).
    pub predecessors: Vec<ClusterSet>,
    /// Strict successors of every cluster (closure).
    pub successors: Vec<ClusterSet>,
    /// Immediate predecessors (transitive reduction).
    pub cover_predecessors: Vec<ClusterSet>,
    /// Immediate successors (transitive reduction).
    pub cover_successors: Vec<ClusterSet>,
    /// A topological order of the clusters (depot first).
    pub topological: Vec<usize>,
}

impl PrecedenceOrder {
    /// Builds closure and reduction. Fails on cycles and on pairs ending at the depot.
    pub fn new(instance: &Instance) -> Result<Self, OrderError> {
        let m = instance.clusters.len();
        let depot = instance.depot;
        let mut direct: Vec<Vec<usize>> = vec![Vec::new(); m];
        let mut indegree = vec![0usize; m];
        let mut add = |a: usize, b: usize, direct: &mut Vec<Vec<usize>>| {
            direct[a].push(b);
            indegree[b] += 1;
        };
        for &(a, b) in &instance.precedence {
            if a >= m || b >= m {
                return Err(OrderError::ClusterOutOfRange {
                    before: a,
                    after: b,
                });
            }
            if b == depot {
                return Err(OrderError::BeforeDepot { before: a });
            }
            add(a, b, &mut direct);
        }
        for b in 0..m {
            if b != depot {
                add(depot, b, &mut direct);
            }
        }
        // Kahn's algorithm; the depot has no incoming pairs, so it comes first.
        let mut topological = Vec::with_capacity(m);
        let mut ready: Vec<usize> = (0..m).filter(|&c| indegree[c] == 0).collect();
        ready.sort_unstable_by_key(|&c| std::cmp::Reverse((c == depot, c)));
        while let Some(c) = ready.pop() {
            topological.push(c);
            for &b in &direct[c] {
                indegree[b] -= 1;
                if indegree[b] == 0 {
                    ready.push(b);
                }
            }
        }
        if topological.len() != m {
            let cluster = (0..m).find(|&c| indegree[c] > 0).unwrap_or(0);
            return Err(OrderError::Cyclic { cluster });
        }
        let mut predecessors = vec![ClusterSet::new(m); m];
        for &a in &topological {
            for &b in &direct[a] {
                let mut add_set = predecessors[a].clone();
                add_set.insert(a);
                predecessors[b].union_with(&add_set);
            }
        }
        let mut successors = vec![ClusterSet::new(m); m];
        for (b, preds) in predecessors.iter().enumerate() {
            for a in preds.iter() {
                successors[a].insert(b);
            }
        }
        // (a, b) is a cover pair iff nothing lies strictly between a and b.
        let mut cover_predecessors = vec![ClusterSet::new(m); m];
        let mut cover_successors = vec![ClusterSet::new(m); m];
        for b in 0..m {
            for a in predecessors[b].iter() {
                if !successors[a].intersects(&predecessors[b]) {
                    cover_predecessors[b].insert(a);
                    cover_successors[a].insert(b);
                }
            }
        }
        Ok(PrecedenceOrder {
            predecessors,
            successors,
            cover_predecessors,
            cover_successors,
            topological,
        })
    }

    /// Number of clusters.
    pub fn cluster_count(&self) -> usize {
        self.predecessors.len()
    }

    /// Whether cluster `a` must be visited before cluster `b`.
    #[inline]
    pub fn precedes(&self, a: usize, b: usize) -> bool {
        self.predecessors[b].contains(a)
    }

    /// Counts the order ideals containing the depot (the DP's state space), giving up at `limit`.
    /// Returns `None` when there are more than `limit`.
    pub fn count_ideals(&self, limit: u64) -> Option<u64> {
        // Layer by layer over explicit ideals would be exponential in memory; instead count by
        // recursion over the topological order with memoisation-free branching, bounded by limit.
        let m = self.cluster_count();
        let order: Vec<usize> = self.topological.iter().copied().skip(1).collect();
        let mut count = 0u64;
        // Iterative enumeration of antichains would be faster; ideals are enumerated as
        // "include / exclude in topological order", pruning excluded clusters' successors.
        let mut stack: Vec<(usize, ClusterSet)> = vec![(0, ClusterSet::new(m))];
        while let Some((pos, excluded)) = stack.pop() {
            if pos == order.len() {
                count += 1;
                if count > limit {
                    return None;
                }
                continue;
            }
            let c = order[pos];
            if excluded.contains(c) {
                stack.push((pos + 1, excluded));
                continue;
            }
            let mut without = excluded.clone();
            without.insert(c);
            without.union_with(&self.successors[c]);
            stack.push((pos + 1, without));
            stack.push((pos + 1, excluded));
        }
        Some(count)
    }
}
