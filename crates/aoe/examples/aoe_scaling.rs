//! Linear-time evidence for the AOE pipeline: random plane 4-regular graphs of growing size,
//! time per edge for ranking, chain construction and the independent check; then OE-routes on
//! the same graphs with a quarter of the edges deleted (T-junctions): pierces against the
//! lower bound max(1, odd vertices / 2).
//!
//! `cargo run -p cutroute-aoe --release --example aoe_scaling [graphs per size]`

use std::time::Instant;

use cutroute_aoe::random::{delete_random_edges, medial_graph, random_plane_multigraph};
use cutroute_aoe::{
    aoe_chain, check_chain, check_route, oe_route, pierce_lower_bound, AoeOptions, Dart, Embedding,
    PlaneGraph,
};
use cutroute_geometry::SplitMix64;

/// The same graph with vertices and edges renumbered in breadth-first order, so that darts
/// that are neighbours in the graph are mostly neighbours in memory.
fn relabelled(graph: &PlaneGraph) -> (PlaneGraph, Vec<usize>) {
    let n = graph.vertex_count();
    let mut vertex_id = vec![usize::MAX; n];
    let mut order = vec![0];
    vertex_id[0] = 0;
    let mut edge_id = vec![usize::MAX; graph.edge_count()];
    let mut edges = Vec::with_capacity(graph.edge_count());
    let mut i = 0;
    while i < order.len() {
        let v = order[i];
        for d in graph.darts_around(v) {
            let w = graph.head(d);
            if vertex_id[w] == usize::MAX {
                vertex_id[w] = order.len();
                order.push(w);
            }
            if edge_id[d / 2] == usize::MAX {
                edge_id[d / 2] = edges.len();
                edges.push(d / 2);
            }
        }
        i += 1;
    }
    let ends: Vec<(usize, usize)> = edges
        .iter()
        .map(|&e| (vertex_id[graph.ends(e).0], vertex_id[graph.ends(e).1]))
        .collect();
    let rotations: Vec<Vec<Dart>> = order
        .iter()
        .map(|&v| {
            graph
                .darts_around(v)
                .map(|d| 2 * edge_id[d / 2] + d % 2)
                .collect()
        })
        .collect();
    let relabelled =
        PlaneGraph::from_rotations(n, &ends, &rotations).expect("a relabelling of a valid graph");
    (relabelled, edge_id)
}

fn main() {
    let graphs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    println!("| edges | graphs | cut points / graph | rank ns/edge | chain ns/edge | check ns/edge | total ms / graph | BFS-numbered: rank / chain / check ns/edge |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---|");
    let mut rng = SplitMix64::new(2019);
    for base_edges in [500, 5_000, 50_000, 500_000] {
        let (mut rank_s, mut chain_s, mut check_s) = (0.0, 0.0, 0.0);
        let mut local = [0.0; 3];
        let (mut edges, mut cut_points) = (0, 0);
        for _ in 0..graphs {
            let medial = medial_graph(&random_plane_multigraph(base_edges, &mut rng));
            let outer = rng.below(medial.faces().count() as u64) as usize;
            // The BFS-numbered copy; its outer face is left of the image of a dart on `outer`.
            let (local_graph, edge_id) = relabelled(&medial);
            let faces = medial.faces();
            let dart = (0..medial.dart_count())
                .find(|&d| faces.left(d) == outer)
                .expect("a dart");
            let local_outer = local_graph.faces().left(2 * edge_id[dart / 2] + dart % 2);
            let t = Instant::now();
            let local_embedding = Embedding::new(local_graph, local_outer).expect("plane");
            local[0] += t.elapsed().as_secs_f64();
            let start = local_embedding.outer_vertices()[0];
            let t = Instant::now();
            let chain =
                aoe_chain(&local_embedding, start, &AoeOptions::default()).expect("a chain");
            local[1] += t.elapsed().as_secs_f64();
            let t = Instant::now();
            check_chain(&local_embedding, &chain.darts).expect("valid");
            local[2] += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let embedding = Embedding::new(medial, outer).expect("plane and connected");
            rank_s += t.elapsed().as_secs_f64();
            let start = embedding.outer_vertices()[0];
            let t = Instant::now();
            let chain = aoe_chain(&embedding, start, &AoeOptions::default()).expect("a chain");
            chain_s += t.elapsed().as_secs_f64();
            let t = Instant::now();
            check_chain(&embedding, &chain.darts).expect("valid");
            check_s += t.elapsed().as_secs_f64();
            edges = embedding.graph().edge_count();
            cut_points += chain.split_vertices.len();
        }
        let per_edge = |s: f64| s * 1e9 / (graphs * edges) as f64;
        println!(
            "| {edges} | {graphs} | {:.0} | {:.0} | {:.0} | {:.0} | {:.1} | {:.0} / {:.0} / {:.0} |",
            cut_points as f64 / graphs as f64,
            per_edge(rank_s),
            per_edge(chain_s),
            per_edge(check_s),
            (rank_s + chain_s + check_s) * 1e3 / graphs as f64,
            per_edge(local[0]),
            per_edge(local[1]),
            per_edge(local[2])
        );
    }

    println!();
    println!("| edges (T-junction graphs) | graphs | pierces | lower bound | route ns/edge | check ns/edge |");
    println!("|---:|---:|---:|---:|---:|---:|");
    for base_edges in [500, 5_000, 50_000] {
        let (mut route_s, mut check_s, mut pierces, mut bound, mut edges) = (0.0, 0.0, 0, 0, 0);
        for _ in 0..graphs {
            let medial = medial_graph(&random_plane_multigraph(base_edges, &mut rng));
            let g = delete_random_edges(&medial, medial.edge_count() / 4, &mut rng);
            let outer = rng.below(g.faces().count() as u64) as usize;
            let embedding = Embedding::new(g, outer).expect("plane and connected");
            let t = Instant::now();
            let route = oe_route(&embedding);
            route_s += t.elapsed().as_secs_f64();
            let t = Instant::now();
            check_route(&embedding, &route.chains).expect("valid");
            check_s += t.elapsed().as_secs_f64();
            pierces += route.pierces();
            bound += pierce_lower_bound(embedding.graph());
            edges += embedding.graph().edge_count();
        }
        println!(
            "| {} | {graphs} | {pierces} | {bound} | {:.0} | {:.0} |",
            edges / graphs,
            route_s * 1e9 / edges as f64,
            check_s * 1e9 / edges as f64
        );
    }
}
