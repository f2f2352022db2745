//! Benchmark of issue #17's kerf check: how long the test "does any cut on an equidistant come
//! closer than kerf/2 to another contour" takes on large generated nests, both as the kerf
//! job's up-front `kerf_overlaps` (every contour's equidistant against every contour) and
//! inside `Route::problems` (`Route::kerf_overlap_problems` on a route with leads on every step,
//! and all the checker's checks for comparison; pass `--no-full` to skip the latter, which are
//! quadratic in the nest's size).
//!
//! `cargo run --release -p cutroute-geometry --example kerf_overlaps -- [CONTOURS…]`

use cutroute_geometry::{
    generate_nest, kerf_overlaps, KerfSettings, LeadFitter, Point, Route, RouteError,
};

fn main() {
    let full = !std::env::args().any(|a| a == "--no-full");
    let counts: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let counts = if counts.is_empty() {
        vec![460, 5_000, 20_000]
    } else {
        counts
    };
    println!("| contours | kerf mm | kerf_overlaps s | pairs | kerf_overlap_problems s | problems | Route::problems s |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for count in counts {
        let nest = generate_nest(count, 1);
        let tolerance = nest.check_tolerance();
        for kerf in [0.2, 2.0] {
            let started = std::time::Instant::now();
            let pairs = kerf_overlaps(&nest, kerf / 2.0, tolerance);
            let overlaps_s = started.elapsed().as_secs_f64();
            // The idealised settings but the kerf: a pierce on the equidistant fits anywhere.
            let settings = KerfSettings {
                kerf,
                ..KerfSettings::default()
            };
            let fitter = LeadFitter::new(&nest, settings);
            let route = Route::innermost_first(&nest, Point::new(0.0, 0.0), None);
            let cells = match fitter.attach(&route) {
                Ok(route) => {
                    let started = std::time::Instant::now();
                    let overlaps = route.kerf_overlap_problems(&nest, tolerance);
                    let seconds = started.elapsed().as_secs_f64();
                    let all = if full {
                        let forest = nest.containment_forest();
                        let started = std::time::Instant::now();
                        let problems = route.problems(&nest, &forest, tolerance);
                        assert_eq!(
                            problems
                                .iter()
                                .filter(|p| matches!(p, RouteError::KerfOverlap { .. }))
                                .count(),
                            overlaps.len()
                        );
                        format!("{:.3}", started.elapsed().as_secs_f64())
                    } else {
                        "—".into()
                    };
                    format!("{seconds:.3} | {} | {all}", overlaps.len())
                }
                Err(errors) => format!("no leads: {} contours | — | —", errors.len()),
            };
            println!(
                "| {count} | {kerf} | {overlaps_s:.3} | {} | {cells} |",
                pairs.len()
            );
        }
    }
}
