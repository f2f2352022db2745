//! Kerf options that used to end in an internal "invalid route" or a panic: ranges checked up
//! front by the one table the flags and profiles share, path-route leads that join, hard rules
//! that hold with leads, and the tabs actually placed in the report.

mod common;

use std::path::PathBuf;

use common::{cutroute, json};

fn data(relative: &str) -> String {
    common::data(relative).to_string_lossy().into_owned()
}

/// A file of this test's own under the system's temporary directory.
fn scratch(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cutroute-kerf-ranges-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn refused(args: &[&str]) -> String {
    let (ok, _, stderr) = cutroute(args);
    assert!(!ok, "cutroute {args:?} succeeded");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!stderr.contains("invalid route"), "{stderr}");
    stderr
}

#[test]
fn flags_out_of_range_are_refused_by_name() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    for (args, words) in [
        (vec!["--kerf", "1e-300"], "--kerf 1e-300: must be 0 or from"),
        (vec!["--tabs", "3:1e-300"], "--tabs width 1e-300"),
        (
            vec!["--lead-in", "line", "--lead-in-length", "0"],
            "--lead-in-length 0: must be from",
        ),
        (vec!["--tabs", "1001:1"], "--tabs"),
    ] {
        let mut all = vec!["solve", &file, "--solver", "ccp", "--time-limit", "1"];
        all.extend(args.iter().copied());
        let stderr = refused(&all);
        assert!(stderr.contains(words), "{args:?}: {stderr}");
    }
}

#[test]
fn profile_values_are_held_to_the_flags_ranges() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    for (count, words) in [
        ("4000000000000000000", "kerf.tabs.count 4e18"),
        ("100000000", "kerf.tabs.count 100000000"),
    ] {
        let profile = scratch(
            &format!("tabs-{count}.json"),
            &format!(
                r#"{{"name": "t", "machine": {{"idle_speed": 100.0, "cut_speed": 10.0,
                "pierce_time": 1.0, "idle_price_per_metre": 0.1, "cut_price_per_metre": 1.0,
                "pierce_price": 0.5}},
                "kerf": {{"kerf": 2.0, "pierce_clearance": 5.0, "switch_off_clearance": 1.0,
                "lead_in": {{"shape": "arc", "length": 8.0, "angle": 0.0, "radius": 0.0}},
                "lead_out": {{"shape": "line", "length": 2.0, "angle": 0.0, "radius": 0.0}},
                "overcut": 0.0, "tabs": {{"count": {count}, "width": 1.0}}}}}}"#
            ),
        );
        let profile = profile.to_string_lossy().into_owned();
        let stderr = refused(&["solve", &file, "--time-limit", "1", "--profile", &profile]);
        assert!(stderr.contains(words), "{stderr}");
    }
}

/// Path solvers' leads join their paths (whole loops without a lead-out gave M* off the
/// lead-out's one point), and hard rules hold with leads.
#[test]
fn path_routes_with_leads_pass_their_checker() {
    let ring = data("nests/dbs/ring.dbs");
    let e1x = data("nests/dbs-json/E1X_6_01.dbs.json");
    let runs: [Vec<&str>; 4] = [
        vec![&ring, "--solver", "sccp", "--kerf", "1", "--lead-in", "arc"],
        vec![&ring, "--solver", "aoe", "--kerf", "1", "--lead-in", "arc"],
        vec![
            &e1x,
            "--solver",
            "sccp",
            "--kerf",
            "2",
            "--tabs",
            "3:1.5",
            "--lead-in",
            "line",
        ],
        vec![&e1x, "--solver", "aoe", "--rules-hard", "--kerf", "1"],
    ];
    for run in runs {
        let mut args = vec!["solve"];
        args.extend(run.iter().copied());
        args.extend(["--time-limit", "2", "--json"]);
        let report = json(&args);
        assert!(report["route"]["paths"].is_array(), "{run:?}");
    }
}

#[test]
fn hard_rules_hold_with_leads_on_contour_routes() {
    let e1x = data("nests/dbs-json/E1X_6_01.dbs.json");
    let report = json(&[
        "solve",
        &e1x,
        "--solver",
        "ccp",
        "--rules-hard",
        "--kerf",
        "1",
        "--time-limit",
        "2",
        "--json",
    ]);
    for rule in ["part", "sheet", "islands"] {
        assert_eq!(report["rule_violations"][rule], 0, "{rule}: {report}");
    }
}

/// `--tabs 4:5` on a 10 × 10 square (no side long enough for a gap away from its corners) and
/// a Ø10 circle (room for two): the report says what was placed, not only what was asked.
#[test]
fn the_report_counts_the_tabs_placed() {
    let nest = scratch(
        "small.dbs.json",
        r#"[{"partid": "sheet", "paths": [[[0,0,0],[0,100,0],[100,100,0],[100,0,0],[0,0,0]]]},
        {"partid": "square", "paths": [[[20,20,0],[20,30,0],[30,30,0],[30,20,0],[20,20,0]]]},
        {"partid": "circle", "paths": [[[50,25,1],[60,25,1],[50,25,0]]]}]"#,
    );
    let nest = nest.to_string_lossy().into_owned();
    let report = json(&[
        "solve",
        &nest,
        "--solver",
        "nearest",
        "--kerf",
        "1",
        "--lead-in",
        "line",
        "--tabs",
        "4:5",
        "--time-limit",
        "1",
        "--json",
    ]);
    let tabs = &report["kerf"]["tabs"];
    assert_eq!(tabs["per_part"], 4);
    let placed: usize = report["route"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.get("tabs").and_then(|t| t.as_array()).map_or(0, Vec::len))
        .sum();
    assert_eq!(tabs["placed"].as_u64(), Some(placed as u64), "{tabs}");
    assert!(placed < 8, "{tabs}");
    assert_eq!(tabs["parts_with_fewer"], 2, "{tabs}");
}
