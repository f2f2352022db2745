//! `cutroute solve --solver sccp|gsccp`: segment cutting priced and timed by the command line's
//! model, the route (tool-on paths) checked independently against the nest.

mod common;

use common::{cutroute, json};
use cutroute_geometry::{PathRoute, PathRouteError};
use cutroute_protocol::Problem;
use serde_json::Value;

fn data(relative: &str) -> String {
    common::data(relative).to_string_lossy().into_owned()
}

fn number(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number {key:?} in {v}"))
}

/// Reads the route of a report and checks it against the nest of `file`: nothing wrong but
/// (for standard cutting) contour cut twice; the report's numbers are the route's.
fn check_route(file: &str, report: &Value) -> PathRoute {
    let route: PathRoute = serde_json::from_value(report["route"].clone()).unwrap();
    let bytes = std::fs::read(file).unwrap();
    let document = cutroute_engine::open_document(file, &bytes).unwrap();
    let Problem::Nest { nest, .. } = document.problem else {
        panic!("{file} is not a nest");
    };
    let problems = route.problems(&nest, 1e-2);
    assert!(
        problems
            .iter()
            .all(|p| matches!(p, PathRouteError::Overlap { .. })),
        "{problems:?}"
    );
    assert_eq!(route.pierce_count() as f64, number(report, "pierces"));
    assert!((route.cut_length() - number(report, "cut_length")).abs() < 1e-6);
    assert!((route.idle_length() - number(report, "idle_length")).abs() < 1e-6);
    route
}

#[test]
fn segment_solvers_report_the_model_and_a_checked_route() {
    // Nest01: five parts, several sharing edges.
    let nest = data("nests/tflex/Nest01.tfnesting");
    for solver in ["sccp", "gsccp"] {
        let v = json(&[
            "solve",
            &nest,
            "--solver",
            solver,
            "--time-limit",
            "1",
            "--cost",
            "0.1,35,7",
            "--speeds",
            "400,20,2.5",
            "--json",
        ]);
        let (idle, cut, pierces) = (
            number(&v, "idle_length"),
            number(&v, "cut_length"),
            number(&v, "pierces"),
        );
        let time = cut / 20.0 + idle / 400.0 + pierces * 2.5;
        let cost = cut * 1e-3 * 35.0 + idle * 1e-3 * 0.1 + pierces * 7.0;
        assert!(
            (number(&v, "time_s") - time).abs() <= 1e-9 * time,
            "{solver}"
        );
        assert!((number(&v, "cost") - cost).abs() <= 1e-9 * cost, "{solver}");
        check_route(&nest, &v);
        // Common edges cut once: less cut and fewer pierces than CCP.
        assert!(
            cut < number(&v["ccp"], "cut_length") - 100.0,
            "{solver}: {v}"
        );
        assert!(pierces < number(&v["ccp"], "pierces"), "{solver}");
        assert_eq!(number(&v, "recut_length"), 0.0);
        let ensembles = v["ensembles"].as_array().unwrap();
        assert_eq!(ensembles.len(), if solver == "sccp" { 1 } else { 3 });
    }
}

#[test]
fn gsccp_picks_by_the_chosen_objective() {
    let nest = data("nests/dbs-json/test1.dbs.json");
    for objective in ["time", "cost"] {
        let v = json(&[
            "solve",
            &nest,
            "--solver",
            "gsccp",
            "--time-limit",
            "1",
            "--objective",
            objective,
            "--json",
        ]);
        check_route(&nest, &v);
        let key = if objective == "time" {
            "time_s"
        } else {
            "cost"
        };
        let chosen = number(&v, key);
        for e in v["ensembles"].as_array().unwrap() {
            if let Some(value) = e[key].as_f64() {
                if e["failure"].is_null() {
                    assert!(chosen <= value + 1e-9, "{objective}: {chosen} > {e}");
                }
            }
        }
        assert!(chosen <= number(&v["ccp"], key) + 1e-9);
    }
}

#[test]
fn segment_solvers_refuse_what_they_cannot_route() {
    let instance = data("pcgtsp/industrial/e1x_1.pcglns");
    let (ok, _, stderr) = cutroute(&["solve", &instance, "--solver", "sccp", "--json"]);
    assert!(!ok && stderr.contains("routes nests"), "{stderr}");
    let nest = data("nests/dbs/ring.dbs");
    let (ok, _, stderr) = cutroute(&["solve", &nest, "--solver", "gsccp", "--objective", "speed"]);
    assert!(!ok && stderr.contains("--objective"), "{stderr}");
    let (ok, _, stderr) = cutroute(&["solve", &nest, "--solver", "gsccp", "--time-limit", "0"]);
    assert!(!ok && stderr.contains("--time-limit"), "{stderr}");
}

#[test]
fn path_solvers_report_bounds_in_the_objectives_unit() {
    // The engine's path-route jobs: `ub` is the route's time (s) or cost, `lb` bounds it.
    let nest = data("nests/tflex/Nest01.tfnesting");
    for solver in ["sccp", "gsccp", "aoe"] {
        for (objective, key) in [("time", "time_s"), ("cost", "cost")] {
            let v = json(&[
                "solve",
                &nest,
                "--solver",
                solver,
                "--time-limit",
                "1",
                "--objective",
                objective,
                "--json",
            ]);
            check_route(&nest, &v);
            let (ub, lb) = (number(&v, "ub"), number(&v, "lb"));
            assert!(
                (ub - number(&v, key)).abs() <= 1e-9 * ub,
                "{solver} {objective}"
            );
            assert!(lb > 0.0 && lb <= ub, "{solver} {objective}: {lb} > {ub}");
            assert_eq!(v["objective"], objective);
            // The idle bound (mm) holds for the printed route, and the gap is measured on it.
            let (idle, idle_lb) = (number(&v, "idle_length"), number(&v, "idle_lb"));
            assert!(
                idle_lb >= 0.0 && idle_lb <= idle + 1e-9,
                "{solver}: idle lb {idle_lb} > idle {idle}"
            );
            let gap = number(&v, "idle_gap");
            assert!(
                (gap - (idle - idle_lb) / idle).abs() < 1e-9,
                "{solver}: idle gap {gap}"
            );
        }
    }
}
