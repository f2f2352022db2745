//! What the thermal measures of a `ThermalJob` cost per route (issue #19): H on the machine
//! clock, and the rule check (part, sheet, islands), on generated nests of growing size, for the
//! nearest neighbour's route. A progress report measures a route only when it changed, and on
//! a route that is not the final one only after 10× the measure's own last duration: these
//! times say how often that is.
//!
//! `cargo run --release -p cutroute-engine --example thermal_measure` prints a Markdown table.

use cutroute_engine::{measure_route, run_to_end, NearestNeighbourJob};
use cutroute_geometry::{generate_nest, MachineParameters, Point};
use cutroute_protocol::{RuleSet, ThermalSettings};
use web_time::Instant;

fn main() {
    println!(
        "| contours | H ms | rules (part, sheet, islands) ms | part ms | sheet ms | islands ms |"
    );
    println!("|---|---|---|---|---|---|");
    for contours in [1_000, 10_000, 30_000] {
        let nest = generate_nest(contours, 1);
        let mut job = NearestNeighbourJob::new(1, nest.clone(), Point::new(0.0, 0.0), None)
            .expect("a nest with contours");
        let route = run_to_end(&mut job, &mut |_| {})
            .route()
            .cloned()
            .expect("a route");
        let machine = MachineParameters::default();
        let time = |settings: ThermalSettings| {
            let started = Instant::now();
            let measure = measure_route(&nest, &route, &settings, &machine).expect("measures");
            (started.elapsed().as_secs_f64() * 1e3, measure)
        };
        let (heat_ms, _) = time(ThermalSettings::default());
        let (rules_ms, measured) = time(ThermalSettings {
            rules: RuleSet::ALL,
            ..ThermalSettings::default()
        });
        eprintln!("{contours}: H {:.4}, {:?}", measured.heat, measured.counts);
        let only = |rules: RuleSet| {
            time(ThermalSettings {
                rules,
                ..ThermalSettings::default()
            })
            .0 - heat_ms
        };
        let none = RuleSet::NONE;
        let part = only(RuleSet { part: true, ..none });
        let sheet = only(RuleSet {
            sheet: true,
            ..none
        });
        let islands = only(RuleSet {
            islands: true,
            ..none
        });
        println!(
            "| {contours} | {heat_ms:.1} | {:.1} | {part:.1} | {sheet:.1} | {islands:.1} |",
            rules_ms - heat_ms
        );
    }
}
