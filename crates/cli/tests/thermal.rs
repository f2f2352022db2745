//! `cutroute solve`'s thermal report: H recomputed from the report's own pierce points and
//! times, the penalty lowering it, hard rules leaving no violation, and flag errors.

mod common;

use common::{cutroute, json};
use serde_json::Value;

fn data(relative: &str) -> String {
    common::data(relative).to_string_lossy().into_owned()
}

/// H by a plain double loop over the report's steps (`pierce`, `t`).
fn heat_from_report(report: &Value, sigma: f64, tau: f64) -> f64 {
    let steps: Vec<(f64, f64, f64)> = report["route"]
        .as_array()
        .expect("route")
        .iter()
        .map(|s| {
            (
                s["pierce"][0].as_f64().unwrap(),
                s["pierce"][1].as_f64().unwrap(),
                s["t"].as_f64().expect("t per step"),
            )
        })
        .collect();
    let mut h = 0.0;
    for i in 0..steps.len() {
        for j in 0..i {
            let d2 = (steps[i].0 - steps[j].0).powi(2) + (steps[i].1 - steps[j].1).powi(2);
            h += (-d2 / (2.0 * sigma * sigma)).exp() * (-(steps[i].2 - steps[j].2) / tau).exp();
        }
    }
    h
}

#[test]
fn heat_matches_an_independent_recomputation_for_every_route_solver() {
    let file = data("nests/dbs/nested.dbs");
    for (solver, extra) in [
        ("nearest", vec![]),
        ("ccp", vec![]),
        ("ccp", vec!["--thermal-sigma", "30", "--thermal-tau", "20"]),
    ] {
        let mut args = vec![
            "solve",
            &file,
            "--solver",
            solver,
            "--time-limit",
            "2",
            "--json",
            "--rules",
            "part,sheet,islands",
        ];
        args.extend(extra.iter().copied());
        let report = json(&args);
        let (sigma, tau) = if extra.is_empty() {
            (50.0, 60.0)
        } else {
            (30.0, 20.0)
        };
        let h = report["heat"].as_f64().expect("heat");
        let reference = heat_from_report(&report, sigma, tau);
        assert!(reference > 0.0);
        assert!(
            (h - reference).abs() <= 1e-6 * reference,
            "{solver}: {h} vs {reference}"
        );
        for group in ["part", "sheet", "islands"] {
            assert!(report["rule_violations"][group].is_u64(), "{report}");
        }
    }
}

#[test]
fn the_weight_lowers_heat_and_hard_rules_leave_no_violation() {
    let file = data("nests/dbs-json/test1.dbs.json");
    let base = [
        "solve",
        &file,
        "--solver",
        "ccp",
        "--time-limit",
        "3",
        "--json",
    ];
    let plain = json(&base);
    let mut heated_args = base.to_vec();
    heated_args.extend(["--thermal-weight", "100"]);
    let heated = json(&heated_args);
    let (h0, h1) = (
        plain["heat"].as_f64().unwrap(),
        heated["heat"].as_f64().unwrap(),
    );
    assert!(h1 <= 0.7 * h0, "H {h1} with the penalty vs {h0}");
    heated_args.push("--rules-hard");
    let hard = json(&heated_args);
    for group in ["part", "sheet", "islands"] {
        assert_eq!(
            hard["rule_violations"][group], 0,
            "{}",
            hard["rule_violations"]
        );
    }
    assert_eq!(hard["thermal"]["rules_hard"], true);
}

#[test]
fn nearest_honours_the_weight_and_weight_zero_changes_nothing() {
    let file = data("nests/dbs/nested.dbs");
    let base = ["solve", &file, "--solver", "nearest", "--json"];
    let plain = json(&base);
    let mut zero = base.to_vec();
    zero.extend(["--thermal-weight", "0"]);
    assert_eq!(json(&zero)["route"], plain["route"]);
    let mut heated = base.to_vec();
    heated.extend(["--thermal-weight", "100"]);
    let heated = json(&heated);
    let (h0, h1) = (
        plain["heat"].as_f64().unwrap(),
        heated["heat"].as_f64().unwrap(),
    );
    assert!(h1 <= 0.7 * h0, "H {h1} with the penalty vs {h0}");
}

#[test]
fn bad_thermal_flags_are_refused() {
    let file = data("nests/dbs-json/test1.dbs.json");
    for bad in [
        vec!["--rules", "part,heat"],
        vec!["--thermal-sigma", "0"],
        vec!["--thermal-tau", "-1"],
        vec!["--thermal-weight", "-5"],
    ] {
        let mut args = vec!["solve", file.as_str(), "--solver", "nearest"];
        args.extend(bad.iter().copied());
        let (ok, _, stderr) = cutroute(&args);
        assert!(!ok && stderr.contains("--"), "{bad:?}: {stderr}");
    }
}

/// H by a plain double loop over a path report's paths (`pierce` {x, y}, `t`).
fn heat_from_path_report(report: &Value, sigma: f64, tau: f64) -> f64 {
    let paths: Vec<(f64, f64, f64)> = report["route"]["paths"]
        .as_array()
        .expect("paths")
        .iter()
        .map(|p| {
            (
                p["pierce"]["x"].as_f64().unwrap(),
                p["pierce"]["y"].as_f64().unwrap(),
                p["t"].as_f64().expect("t per path"),
            )
        })
        .collect();
    let mut h = 0.0;
    for i in 0..paths.len() {
        for j in 0..i {
            let d2 = (paths[i].0 - paths[j].0).powi(2) + (paths[i].1 - paths[j].1).powi(2);
            h += (-d2 / (2.0 * sigma * sigma)).exp() * (-(paths[i].2 - paths[j].2) / tau).exp();
        }
    }
    h
}

#[test]
fn path_solvers_report_rules_honour_them_hard_and_their_heat_is_recomputed() {
    let file = data("nests/dbs-json/test0.dbs.json");
    for solver in ["sccp", "gsccp", "aoe"] {
        let base = [
            "solve",
            &file,
            "--solver",
            solver,
            "--time-limit",
            "2",
            "--json",
        ];
        let mut checked = base.to_vec();
        checked.extend(["--rules", "part,sheet,islands"]);
        let plain = json(&checked);
        let counts = &plain["rule_violations"];
        let total: u64 = ["part", "sheet", "islands"]
            .iter()
            .map(|g| counts[g].as_u64().expect("counted on the contour route"))
            .sum();
        assert!(
            total > 0,
            "{solver}: test0's plain route breaks rules ({counts})"
        );

        let mut hard_args = base.to_vec();
        hard_args.push("--rules-hard");
        let hard = json(&hard_args);
        for group in ["part", "sheet", "islands"] {
            assert_eq!(hard["rule_violations"][group], 0, "{solver}: {hard}");
        }
        for report in [&plain, &hard] {
            let h = report["heat"].as_f64().expect("heat");
            let reference = heat_from_path_report(report, 50.0, 60.0);
            assert!(reference > 0.0);
            assert!(
                (h - reference).abs() <= 1e-6 * reference,
                "{solver}: {h} vs {reference}"
            );
        }
        // ub is the printed route's objective (time), never below lb.
        let ub = hard["ub"].as_f64().unwrap();
        assert!((ub - hard["time_s"].as_f64().unwrap()).abs() <= 1e-6 * ub);
        if let Some(lb) = hard["lb"].as_f64() {
            assert!(lb <= ub + 1e-6, "{solver}: lb {lb} > ub {ub}");
        }
    }
}
