//! Benchmark of issue #17: equidistants (kerf/2 = 1 mm) of every contour of a 20,000-contour
//! generated nest. Target: ≤ 2 s natively.
//!
//! `cargo run --release -p cutroute-geometry --example offsets -- [CONTOURS]`

use cutroute_geometry::{equidistant, generate_nest};

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20_000);
    let nest = generate_nest(count, 1);
    for offset in [0.1, 1.0, 5.0] {
        let started = std::time::Instant::now();
        let mut made = 0;
        let mut spans = 0;
        for r in nest.contour_refs() {
            if let Ok(e) = equidistant(nest.contour(r).unwrap(), offset) {
                made += 1;
                spans += e.span_count();
            }
        }
        println!(
            "{count} contours, offset {offset} mm: {made} equidistants ({spans} spans) in {:.3} s",
            started.elapsed().as_secs_f64()
        );
    }
}
