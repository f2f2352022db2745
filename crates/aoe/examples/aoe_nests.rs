//! Common-edge routes on the real nests and on synthetic grids of touching rectangles:
//! plan graph size, pierces and cut length of the OE-route against cutting every contour on
//! its own (one pierce per contour, common edges cut twice).
//!
//! `cargo run -p cutroute-aoe --release --example aoe_nests` (run from the workspace root).

use std::time::Instant;

use cutroute_aoe::{check_route, oe_route, PlanGraph, PlanOptions};
use cutroute_geometry::{Contour, Nest, Part, Vertex};

fn load(relative: &str) -> Nest {
    let path = format!("../shared/data/nests/{relative}");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path} is missing: {e}"));
    if relative.ends_with(".tfnesting") {
        cutroute_cad::tflex::read_tfnesting(&bytes)
            .unwrap()
            .remove(0)
    } else {
        cutroute_formats::read_nest(&bytes).unwrap()
    }
}

fn grid(n: usize, m: usize) -> Nest {
    let mut parts = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (x, y) = (100.0 * i as f64, 50.0 * j as f64);
            parts.push(Part {
                name: String::new(),
                contours: vec![Contour::new(vec![
                    Vertex::line(x, y),
                    Vertex::line(x, y + 50.0),
                    Vertex::line(x + 100.0, y + 50.0),
                    Vertex::line(x + 100.0, y),
                ])],
            });
        }
    }
    Nest { sheet: None, parts }
}

fn main() {
    println!("| nest | contours | V | E | common edges | components | pierces (contours) | pierces (OE-route) | lower bound | cut mm (contours) | cut mm (OE-route) | graph ms | route ms |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut nests: Vec<(String, Nest)> = [
        "dbs/nested.dbs",
        "dbs/seven.dbs",
        "dbs/test0.json.dbs",
        "dbs-json/E1X_6_01.dbs.json",
        "dbs-json/test1.dbs.json",
        "tflex/Nest01.tfnesting",
        "tflex/Nest02.tfnesting",
        "tflex/Nest03.tfnesting",
    ]
    .iter()
    .map(|name| (name.rsplit('/').next().unwrap().to_string(), load(name)))
    .collect();
    for (n, m) in [(1, 5), (3, 3), (10, 10), (30, 30)] {
        nests.push((format!("grid {n}×{m}"), grid(n, m)));
    }
    for (name, nest) in nests {
        let t = Instant::now();
        let plan = PlanGraph::from_nest(&nest, &PlanOptions::default()).expect("plan graph");
        let graph_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let chains = plan.route().expect("plane components");
        let route_ms = t.elapsed().as_secs_f64() * 1e3;
        let components = plan.components().expect("plane components");
        let mut bound = 0;
        for c in &components {
            let route = oe_route(&c.embedding);
            check_route(&c.embedding, &route.chains).expect("valid OE-route");
            bound += cutroute_aoe::pierce_lower_bound(c.embedding.graph());
        }
        let g = plan.graph();
        let common = (0..g.edge_count())
            .filter(|&e| plan.edge_contours(e).len() > 1)
            .count();
        let perimeters: f64 = nest
            .parts
            .iter()
            .flat_map(|p| &p.contours)
            .map(|c| c.perimeter())
            .sum();
        let cut: f64 = chains
            .iter()
            .flat_map(|c| &c.spans)
            .map(|s| s.length())
            .sum();
        println!(
            "| {name} | {} | {} | {} | {common} | {} | {} | {} | {bound} | {perimeters:.1} | {cut:.1} | {graph_ms:.1} | {route_ms:.1} |",
            nest.contour_count(),
            g.vertex_count(),
            g.edge_count(),
            components.len(),
            nest.contour_count(),
            chains.len(),
        );
    }
}
