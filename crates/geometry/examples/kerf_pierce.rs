//! Benchmark of the kerf-piercing pass (`LeadFitter::pierce_into_kerfs`) on a generated nest:
//! issue #17's plasma settings with kerf piercing on and a 2 s pierce at an edge, every
//! contour with room for its leads in one route (the deepest contours first, each pierced near
//! its first vertex, leads attached), then the pass over that route.
//!
//! `cargo run --release -p cutroute-geometry --example kerf_pierce -- [CONTOURS]`

use std::time::Instant;

use cutroute_geometry::{
    generate_nest, ContourRef, CutStep, KerfSettings, LeadFitter, MachineParameters, Point, Route,
};

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20_000);
    let settings = KerfSettings {
        kerf_pierce: true,
        ..KerfSettings::plasma_reference()
    };
    let machine = MachineParameters {
        edge_pierce_time: Some(2.0),
        ..MachineParameters::default()
    };
    let started = Instant::now();
    let nest = generate_nest(count, 1);
    let forest = nest.containment_forest();
    let fitter = LeadFitter::new(&nest, settings);
    let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
    refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r)));
    let steps: Vec<CutStep> = refs
        .into_iter()
        .filter_map(|r| {
            let near = nest.contour(r)?.vertices[0].point;
            // The generator's smallest holes have no room for d₁: they are left out.
            fitter.attach_to_step(&CutStep::pierced(r, near)).ok()
        })
        .collect();
    let mut route = Route {
        start: Point::new(0.0, 0.0),
        steps,
        finish: None,
    };
    println!(
        "{count} contours generated, {} with room, route with leads in {:.2} s",
        route.steps.len(),
        started.elapsed().as_secs_f64()
    );
    let started = Instant::now();
    let moved = fitter.pierce_into_kerfs(&mut route, &machine);
    println!(
        "pierce_into_kerfs: {moved} kerf pierces of {} steps in {:.3} s",
        route.steps.len(),
        started.elapsed().as_secs_f64()
    );
}
