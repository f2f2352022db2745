//! Common-edge routes on the real nests and on synthetic grids of touching rectangles:
//! plan graph size, pierces and cut length of the OE-route against cutting every contour on
//! its own (one pierce per contour, common edges cut twice).
//!
//! A second table runs the solver behind `--solver aoe` (`solve_nest`: components ordered
//! inner-first with short idle moves) against plain CCP-Relax (`--ccp-seconds`, default 2) on
//! the same nests: pierces, idle and cut length, machine time and cost under
//! `MachineParameters::default()`; both routes from (0, 0), open; both checked.
//!
//! `cargo run -p cutroute-aoe --release --example aoe_nests [-- --ccp-seconds S]` (run from the
//! workspace root).

use std::time::{Duration, Instant};

use cutroute_aoe::{check_route, oe_route, solve_nest, AoeSolveOptions, PlanGraph, PlanOptions};
use cutroute_geometry::{Contour, MachineParameters, Nest, Part, Vertex};

fn load(relative: &str) -> Nest {
    let path = format!("data/nests/{relative}");
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
    let args: Vec<String> = std::env::args().collect();
    let ccp_seconds: f64 = args
        .iter()
        .position(|a| a == "--ccp-seconds")
        .and_then(|i| args.get(i + 1))
        .map_or(2.0, |v| v.parse().expect("--ccp-seconds S"));
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
    for (name, nest) in &nests {
        let t = Instant::now();
        let plan = PlanGraph::from_nest(nest, &PlanOptions::default()).expect("plan graph");
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
    versus_ccp(&nests, ccp_seconds);
}

/// The AOE solver against plain CCP-Relax, by the cost model.
fn versus_ccp(nests: &[(String, Nest)], ccp_seconds: f64) {
    let machine = MachineParameters::default();
    println!();
    println!(
        "AOE solver vs CCP-Relax ({ccp_seconds} s); machine: idle {} mm/s, cut {} mm/s, pierce {} s; prices idle {}/m, cut {}/m, pierce {}",
        machine.idle_speed,
        machine.cut_speed,
        machine.pierce_time,
        machine.idle_price_per_metre,
        machine.cut_price_per_metre,
        machine.pierce_price
    );
    println!();
    println!("| nest | contours | pierces CCP → AOE | idle mm CCP → AOE | cut mm CCP → AOE | time s CCP → AOE | cost CCP → AOE | cost change | AOE ms |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, nest) in nests {
        let b = nest.bounding_box();
        let scale = ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0);
        let ccp = cutroute_ccp::solve(
            nest,
            cutroute_ccp::CcpOptions {
                time_limit: Duration::from_secs_f64(ccp_seconds),
                ..cutroute_ccp::CcpOptions::default()
            },
            &mut |_| {},
        )
        .expect("CCP route")
        .route;
        ccp.validate(nest, 1e-6 * scale).expect("valid CCP route");
        let t = Instant::now();
        let options = AoeSolveOptions {
            plan: PlanOptions {
                tolerance: 1e-6 * scale,
                ..PlanOptions::default()
            },
            ..AoeSolveOptions::default()
        };
        let aoe = solve_nest(nest, &options).expect("AOE route").route;
        let aoe_ms = t.elapsed().as_secs_f64() * 1e3;
        aoe.validate(nest, 1e-5 * scale).expect("valid AOE route");
        let (ccp_cost, aoe_cost) = (ccp.cost(nest, &machine), aoe.cost(&machine));
        println!(
            "| {name} | {} | {} → {} | {:.0} → {:.0} | {:.0} → {:.0} | {:.0} → {:.0} | {:.2} → {:.2} | {:+.2} % | {aoe_ms:.1} |",
            nest.contour_count(),
            ccp.pierce_count(),
            aoe.pierce_count(),
            ccp.idle_length(),
            aoe.idle_length(),
            ccp.cut_length(nest),
            aoe.cut_length(),
            ccp.time(nest, &machine),
            aoe.time(&machine),
            ccp_cost,
            aoe_cost,
            100.0 * (aoe_cost - ccp_cost) / ccp_cost,
        );
    }
}
