//! Shared helpers for the integration tests: real data files, read loudly.
#![allow(dead_code)]

use cutroute_geometry::SplitMix64;
use cutroute_pcgtsp::Instance;
use std::path::PathBuf;

/// `data/` beside the checkout.
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// Reads a file under `data/`, panicking with the path if it is missing.
pub fn read_data(relative: &str) -> String {
    let path = data_dir().join(relative);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("required test data {} is missing: {e}", path.display()))
}

/// One row of `pcgtsp/reference.csv`.
#[derive(Clone, Debug)]
pub struct Reference {
    pub set: String,
    pub instance: String,
    pub nodes: usize,
    pub clusters: usize,
    pub pcglns_cost: f64,
    pub pcglns_tour: Vec<usize>,
    pub best_lb: Option<f64>,
    pub known_optimum: Option<f64>,
}

impl Reference {
    /// Path relative to `data/`.
    pub fn relative_path(&self) -> String {
        format!("pcgtsp/{}/{}.pcglns", self.set, self.instance)
    }

    pub fn load(&self) -> Instance {
        Instance::parse(&read_data(&self.relative_path()))
            .unwrap_or_else(|e| panic!("{}: {e}", self.instance))
    }
}

fn split_csv(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut current = String::new();
    let mut quoted = false;
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut current)),
            _ => current.push(ch),
        }
    }
    fields.push(current);
    fields
}

/// All rows of `pcgtsp/reference.csv`.
pub fn references() -> Vec<Reference> {
    let text = read_data("pcgtsp/reference.csv");
    let mut lines = text.lines();
    let header = split_csv(lines.next().expect("reference.csv is empty"));
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("column {name}"))
    };
    let (set, instance, nodes, clusters) =
        (col("set"), col("instance"), col("nodes"), col("clusters"));
    let (cost, tour, best_lb, optimum) = (
        col("pcglns_cost"),
        col("pcglns_tour"),
        col("best_lb"),
        col("known_optimum"),
    );
    let opt = |s: &str| {
        if s.trim().is_empty() {
            None
        } else {
            Some(s.trim().parse::<f64>().unwrap())
        }
    };
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f = split_csv(l);
            Reference {
                set: f[set].clone(),
                instance: f[instance].clone(),
                nodes: f[nodes].parse().unwrap(),
                clusters: f[clusters].parse().unwrap(),
                pcglns_cost: f[cost].parse().unwrap(),
                pcglns_tour: f[tour]
                    .split(',')
                    .map(|t| t.trim().parse::<usize>().unwrap() - 1)
                    .collect(),
                best_lb: opt(&f[best_lb]),
                known_optimum: opt(&f[optimum]),
            }
        })
        .collect()
}

/// p43.4: `reference.csv` lists 66846, which is the dissertation's *lower bound* (Table 2.3,
/// gap printed as 0.00 % although 66848 vs 66846 is 0.003 %). Salman et al. (2017) prove
/// 66848.40 on the real-valued twin, and our exact DP proves 66848 with a checked tour of that
/// cost, confirmed by the pierce-group DP with one group per node (= the exact problem). So the
/// tests use 66848 as the optimum and still check that we never go below the published bound.
pub const P43_4_OPTIMUM: f64 = 66848.0;

/// The optimum the tests trust (see [`P43_4_OPTIMUM`]).
pub fn trusted_optimum(r: &Reference) -> Option<f64> {
    if r.instance == "p43.4" {
        assert_eq!(
            r.known_optimum,
            Some(66846.0),
            "reference.csv changed: revisit P43_4_OPTIMUM"
        );
        return Some(P43_4_OPTIMUM);
    }
    r.known_optimum
}

/// The reference row of one instance.
pub fn reference(name: &str) -> Reference {
    references()
        .into_iter()
        .find(|r| r.instance == name)
        .unwrap_or_else(|| panic!("{name} not in reference.csv"))
}

/// Brute force over cluster orders and node choices: the optimum and an optimal tour.
pub fn brute_force(instance: &Instance) -> Option<(f64, Vec<usize>)> {
    fn extend(
        instance: &Instance,
        tour: &mut Vec<usize>,
        visited: &mut Vec<bool>,
        cost: f64,
        best: &mut Option<(f64, Vec<usize>)>,
    ) {
        let m = instance.clusters.len();
        let last = *tour.last().expect("tour starts at the depot");
        if tour.len() == m {
            let total = cost + instance.arc_cost(last, tour[0]);
            if total.is_finite() && best.as_ref().is_none_or(|(b, _)| total < *b) {
                *best = Some((total, tour.clone()));
            }
            return;
        }
        for c in 0..m {
            let ready = !visited[c]
                && instance
                    .precedence
                    .iter()
                    .all(|&(a, b)| b != c || visited[a]);
            if !ready {
                continue;
            }
            visited[c] = true;
            for &x in &instance.clusters[c] {
                let arc = instance.arc_cost(last, x);
                if arc.is_finite() {
                    tour.push(x);
                    extend(instance, tour, visited, cost + arc, best);
                    tour.pop();
                }
            }
            visited[c] = false;
        }
    }
    let mut best = None;
    for &start in &instance.clusters[instance.depot] {
        let mut visited = vec![false; instance.clusters.len()];
        visited[instance.depot] = true;
        extend(instance, &mut vec![start], &mut visited, 0.0, &mut best);
    }
    best
}

/// How [`random_instance`] draws: its stream's salt, the arc costs `cost_base + [0, cost_range)`,
/// and each precedence pair's odds `1 / pair_odds`.
#[derive(Clone, Copy)]
pub struct RandomShape {
    pub salt: u64,
    pub cost_base: u64,
    pub cost_range: u64,
    pub pair_odds: u64,
}

/// `m` clusters of 1–4 nodes (the depot has 1 or 2), integer asymmetric costs with about one
/// arc in eight forbidden, and random precedence pairs consistent with a random order.
pub fn random_instance(seed: u64, m: usize, shape: RandomShape) -> Instance {
    let mut rng = SplitMix64::new(seed.wrapping_mul(7919).wrapping_add(shape.salt));
    let mut clusters = Vec::new();
    let mut node_cluster = Vec::new();
    for c in 0..m {
        let size = if c == 0 {
            1 + rng.below(2) as usize
        } else {
            1 + rng.below(4) as usize
        };
        let nodes: Vec<usize> = (node_cluster.len()..node_cluster.len() + size).collect();
        node_cluster.extend(std::iter::repeat_n(c, size));
        clusters.push(nodes);
    }
    let n = node_cluster.len();
    let mut cost = vec![f64::INFINITY; n * n];
    for a in 0..n {
        for b in 0..n {
            if a != b && rng.below(8) != 0 {
                cost[a * n + b] = (shape.cost_base + rng.below(shape.cost_range)) as f64;
            }
        }
    }
    let mut order: Vec<usize> = (1..m).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i as u64 + 1) as usize);
    }
    let mut precedence = Vec::new();
    for i in 0..order.len() {
        for j in i + 1..order.len() {
            if rng.below(shape.pair_odds) == 0 {
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
