//! Chain cutting vs plain CCP on every real nest: pierces, lengths, time and cost per material
//! of Verkhoturov–Tarasenko's Table 1. Prints a Markdown table for BENCHMARKS.md.
//!
//! `cargo run --release -p cutroute-chains --example chain_bench -- [--ccp-seconds S] [--filter A,B]`

use std::time::{Duration, Instant};

use cutroute_chains::{chain_route, ChainOptions, TABLE1_MATERIALS};
use cutroute_geometry::{MachineParameters, Nest, Point};

const NESTS: [&str; 10] = [
    "dbs-json/E1X_6_01.dbs.json",
    "dbs-json/test0.dbs.json",
    "dbs-json/test1.dbs.json",
    "dbs/nested.dbs",
    "dbs/seven.dbs",
    "dbs/test0.json.dbs",
    "dbs/rounded3x4.dbs",
    "tflex/Nest01.tfnesting",
    "tflex/Nest02.tfnesting",
    "tflex/Nest03.tfnesting",
];

fn read_nest(path: &str) -> Nest {
    let full = format!(
        "{}/../../../shared/data/nests/{path}",
        env!("CARGO_MANIFEST_DIR")
    );
    let bytes = std::fs::read(&full).unwrap_or_else(|e| panic!("missing file {full}: {e}"));
    cutroute_formats::read_nest(&bytes).unwrap_or_else(|e| panic!("cannot read {full}: {e}"))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let ccp_seconds: f64 = value("--ccp-seconds").map_or(5.0, |v| v.parse().expect("seconds"));
    let filter: Option<Vec<String>> =
        value("--filter").map(|v| v.split(',').map(str::to_string).collect());
    println!("| nest | contours | material | condValue mm | pierces CCP → chain | saved | links mm | idle mm CCP → chain | cut mm CCP → chain | time s CCP → chain | cost CCP → chain | cost change | chain s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for path in NESTS {
        if filter
            .as_ref()
            .is_some_and(|f| !f.iter().any(|x| path.contains(x.as_str())))
        {
            continue;
        }
        let nest = read_nest(path);
        let ccp = cutroute_ccp::solve(
            &nest,
            cutroute_ccp::CcpOptions {
                start: Point::new(0.0, 0.0),
                time_limit: Duration::from_secs_f64(ccp_seconds),
                ..cutroute_ccp::CcpOptions::default()
            },
            &mut |_| {},
        )
        .expect("CCP solves every real nest");
        for material in TABLE1_MATERIALS {
            let machine = material.priced(&MachineParameters::default());
            let options = ChainOptions {
                machine,
                ..ChainOptions::default()
            };
            let started = Instant::now();
            let chained = chain_route(&nest, &ccp.route, &options).expect("valid CCP route");
            let seconds = started.elapsed().as_secs_f64();
            let scale = {
                let b = nest.bounding_box();
                ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0)
            };
            if let Err(e) = chained.route.validate(&nest, 1e-6 * scale) {
                panic!("{path}: chained route invalid: {e}");
            }
            let r = &chained.report;
            let cut_before = ccp.route.cut_length(&nest);
            let cut_after = chained.route.cut_length(&nest);
            println!(
                "| {} | {} | {} | {:.0} | {} → {} | {} | {:.1} | {:.0} → {:.0} | {:.0} → {:.0} | {:.0} → {:.0} | {:.2} → {:.2} | {:+.2} % | {:.2} |",
                path.rsplit('/').next().unwrap_or(path),
                nest.contour_count(),
                material.name,
                cutroute_chains::profitable_link_length(&machine),
                r.pierces_before,
                r.pierces_after,
                r.pierces_before - r.pierces_after,
                r.link_length,
                r.idle_before,
                r.idle_after,
                cut_before,
                cut_after,
                r.time_before,
                r.time_after,
                r.cost_before,
                r.cost_after,
                100.0 * (r.cost_after - r.cost_before) / r.cost_before,
                seconds,
            );
        }
    }
}
