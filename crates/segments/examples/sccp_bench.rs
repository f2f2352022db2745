//! Segment cutting vs plain CCP on every real nest and on synthetic grids of touching
//! rectangles. Prints a Markdown table for BENCHMARKS.md: per nest CCP-Relax's route, the
//! SCCP route (the multi-contour chain ensemble, what `--solver sccp` returns) and the route
//! GSCCP keeps (`--solver gsccp`); with `--full`, every ensemble's row.
//!
//! `cargo run --release -p cutroute-segments --example sccp_bench -- [--seconds S]
//! [--filter A,B] [--objective time|cost] [--full]`

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use cutroute_geometry::{Nest, Point};
use cutroute_segments::{
    rectangle_grid, solve_gsccp, EnsembleKind, GsccpOptions, Objective, SccpOptions,
};

#[path = "../../chains/examples/support/nest_files.rs"]
mod nest_files;

use nest_files::{nest_files, read_nest};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let seconds: f64 = value("--seconds").map_or(4.0, |v| v.parse().expect("seconds"));
    let filter: Option<Vec<String>> =
        value("--filter").map(|f| f.split(',').map(String::from).collect());
    let objective = match value("--objective").as_deref() {
        None | Some("time") => Objective::Time,
        Some("cost") => Objective::Cost,
        Some(other) => panic!("unknown objective {other}"),
    };
    let mut cases: Vec<(String, Nest, Point, Option<Point>)> = nest_files()
        .into_iter()
        .map(|path| {
            let (nest, start, finish) = read_nest(&path);
            let name = path.rsplit('/').next().unwrap_or(&path).to_string();
            (name, nest, start, finish)
        })
        .collect();
    for (c, r) in [(1, 6), (6, 1), (3, 3), (5, 4), (10, 10), (20, 10)] {
        cases.push((
            format!("grid {c}×{r}"),
            rectangle_grid(c, r, 50.0, 30.0),
            Point::new(0.0, -20.0),
            None,
        ));
    }
    println!("GSCCP time limit {seconds} s per nest (half for the CCP-Relax run that seeds every order), objective {objective:?}, default machine parameters.\n");
    let full = args.iter().any(|a| a == "--full");
    if full {
        println!("| nest | contours | ensemble | segments | pierces | cut mm | recut mm | idle mm | time s | cost | |");
        println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|");
    } else {
        println!("| nest | contours | CCP pierces / cut / idle mm | CCP time s / cost | SCCP pierces / cut / idle mm | SCCP time s / cost | GSCCP best | GSCCP pierces / cut / idle mm | GSCCP time s / cost | Δ time | Δ cost | wall s |");
        println!("|---|---:|---|---|---|---|---|---|---|---:|---:|---:|");
    }
    for (name, nest, start, finish) in cases {
        if let Some(f) = &filter {
            if !f.iter().any(|x| name.contains(x.as_str())) {
                continue;
            }
        }
        let options = GsccpOptions {
            sccp: SccpOptions {
                start,
                finish,
                time_limit: Duration::from_secs_f64(seconds),
                ..SccpOptions::default()
            },
            objective,
            ..GsccpOptions::default()
        };
        let clock = Instant::now();
        let result = match solve_gsccp(&nest, &options, &AtomicBool::new(false)) {
            Ok(r) => r,
            Err(e) => {
                println!(
                    "| {name} | {} | — | | | | | | | | failed: {e} |",
                    nest.contour_count()
                );
                continue;
            }
        };
        let wall = clock.elapsed().as_secs_f64();
        let m = &options.machine;
        let ccp = &result.ccp_route;
        if !full {
            let chains = result
                .reports
                .iter()
                .find(|r| r.kind == EnsembleKind::Chains)
                .expect("every kind is reported");
            // The route GSCCP keeps: the best ensemble's, or CCP-Relax's when none beat it.
            let best = &result.route;
            let best_name = result.best.map_or("ccp", |kind| kind.name());
            let sccp = match &chains.failure {
                Some(f) => (format!("failed: {f}"), String::new()),
                None => (
                    format!(
                        "{} / {:.0} / {:.0}",
                        chains.pierces, chains.cut_length, chains.idle_length
                    ),
                    format!("{:.1} / {:.3}", chains.time_s, chains.cost),
                ),
            };
            println!(
                "| {name} | {} | {} / {:.0} / {:.0} | {:.1} / {:.3} | {} | {} | {} | {} / {:.0} / {:.0} | {:.1} / {:.3} | {:+.1} % | {:+.1} % | {wall:.1} |",
                nest.contour_count(),
                ccp.pierce_count(),
                ccp.cut_length(),
                ccp.idle_length(),
                ccp.time(m),
                ccp.cost(m),
                sccp.0,
                sccp.1,
                best_name,
                best.pierce_count(),
                best.cut_length(),
                best.idle_length(),
                best.time(m),
                best.cost(m),
                100.0 * (best.time(m) / ccp.time(m) - 1.0),
                100.0 * (best.cost(m) / ccp.cost(m) - 1.0),
            );
            continue;
        }
        println!(
            "| {name} | {} | ccp | {} | {} | {:.1} | | {:.1} | {:.1} | {:.3} | |",
            nest.contour_count(),
            ccp.pierce_count(),
            ccp.pierce_count(),
            ccp.cut_length(),
            ccp.idle_length(),
            ccp.time(m),
            ccp.cost(m)
        );
        for r in &result.reports {
            let note = match &r.failure {
                Some(f) => f.to_string(),
                None if Some(r.kind) == result.best => format!("**best** ({wall:.1} s wall)"),
                None => String::new(),
            };
            println!(
                "| | | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.3} | {note} |",
                r.kind.name(),
                r.segments,
                r.pierces,
                r.cut_length,
                r.recut_length,
                r.idle_length,
                r.time_s,
                r.cost
            );
        }
    }
}
