//! Linear-time evidence for the AOE pipeline: random plane 4-regular graphs of growing size,
//! time per edge for ranking, chain construction and the independent check; then OE-routes on
//! the same graphs with a quarter of the edges deleted (T-junctions): pierces against the
//! lower bound max(1, odd vertices / 2).
//!
//! `cargo run -p cutroute-aoe --release --example aoe_scaling [graphs per size]`

use std::time::Instant;

use cutroute_aoe::random::{delete_random_edges, medial_graph, random_plane_multigraph};
use cutroute_aoe::{
    aoe_chain, check_chain, check_route, oe_route, pierce_lower_bound, AoeOptions, Embedding,
};
use cutroute_geometry::SplitMix64;

fn main() {
    let graphs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    println!("| edges | graphs | cut points / graph | rank ns/edge | chain ns/edge | check ns/edge | total ms / graph |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    let mut rng = SplitMix64::new(2019);
    for base_edges in [500, 5_000, 50_000, 500_000] {
        let (mut rank_s, mut chain_s, mut check_s) = (0.0, 0.0, 0.0);
        let (mut edges, mut cut_points) = (0, 0);
        for _ in 0..graphs {
            let medial = medial_graph(&random_plane_multigraph(base_edges, &mut rng));
            let outer = rng.below(medial.faces().count() as u64) as usize;
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
            "| {edges} | {graphs} | {:.0} | {:.0} | {:.0} | {:.0} | {:.1} |",
            cut_points as f64 / graphs as f64,
            per_edge(rank_s),
            per_edge(chain_s),
            per_edge(check_s),
            (rank_s + chain_s + check_s) * 1e3 / graphs as f64
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
