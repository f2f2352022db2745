//! `solve --time-limit` counts reading the file, and every report says how long the reading
//! took (`read_s`) apart from the solver's run (`elapsed_s`).

mod common;

use common::{data, json};

#[test]
fn every_report_says_how_long_reading_took_apart_from_the_run() {
    let nest = data("nests/dbs/nested.dbs");
    let instance = data("pcgtsp/pcgtsplib/kro124p.1.pcglns");
    for (file, solver) in [
        (&nest, "ccp"),
        (&nest, "sccp"),
        (&nest, "aoe"),
        (&instance, "heuristic"),
    ] {
        let report = json(&[
            "solve",
            file.to_str().unwrap(),
            "--solver",
            solver,
            "--time-limit",
            "0.5",
            "--json",
        ]);
        let read_s = report["read_s"]
            .as_f64()
            .unwrap_or_else(|| panic!("{solver}: no read_s: {report}"));
        assert!((0.0..60.0).contains(&read_s), "{solver}: read_s {read_s}");
        assert!(
            report["elapsed_s"].is_number(),
            "{solver}: elapsed_s kept: {report}"
        );
    }
}
