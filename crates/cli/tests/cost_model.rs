//! `cutroute solve` prices and times every solver's route by the cost model given on the
//! command line (or a task file's speeds), and the chain solver saves pierces.

mod common;

use common::{cutroute, json};
use serde_json::Value;

/// A file under `data/` as a command-line argument.
fn data(relative: &str) -> String {
    common::data(relative).to_string_lossy().into_owned()
}

fn number(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number {key:?} in {v}"))
}

/// `T = L_on/V_on + L_off/V_off + N·t_pt`, `F = (L_on·C_on + L_off·C_off)/1000 + N·C_pt`.
fn assert_model(v: &Value, speeds: [f64; 3], prices: [f64; 3], what: &str) {
    let (idle, cut, pierces) = (
        number(v, "idle_length"),
        number(v, "cut_length"),
        number(v, "pierces"),
    );
    let time = cut / speeds[1] + idle / speeds[0] + pierces * speeds[2];
    let cost = cut * 1e-3 * prices[1] + idle * 1e-3 * prices[0] + pierces * prices[2];
    assert!(
        (number(v, "time_s") - time).abs() <= 1e-9 * time,
        "{what}: time_s {} vs {time}",
        v["time_s"]
    );
    assert!(
        (number(v, "cost") - cost).abs() <= 1e-9 * cost,
        "{what}: cost {} vs {cost}",
        v["cost"]
    );
}

#[test]
fn every_solver_reports_time_and_cost_under_the_given_model() {
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    for solver in [
        "nearest",
        "ccp",
        "heuristic",
        "exact",
        "discrete",
        "chain",
        "aoe",
    ] {
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
        assert_model(&v, [400.0, 20.0, 2.5], [0.1, 35.0, 7.0], solver);
        for key in [
            "solver",
            "idle_length",
            "cut_length",
            "pierces",
            "route",
            "ub",
        ] {
            assert!(v.get(key).is_some(), "{solver}: no {key:?}");
        }
    }
}

#[test]
fn defaults_come_from_the_task_file_else_the_built_in_machine() {
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    let v = json(&["solve", &nest, "--solver", "nearest", "--json"]);
    // MachineParameters::default(): 500 mm/s, 10 mm/s, 7 s; prices 0.1, 1, 0.5.
    assert_model(&v, [500.0, 10.0, 7.0], [0.1, 1.0, 0.5], "defaults");

    // The real task has the default speeds; a copy with other speeds shows they are read.
    let mut task: Value =
        serde_json::from_slice(&std::fs::read(data("nests/task-json/E1X_6_01.task.json")).unwrap())
            .unwrap();
    task["TaskData"]["ToolIdlingSpeed"] = 250.0.into();
    task["TaskData"]["ToolCutSpeed"] = 12.5.into();
    task["TaskData"]["PiercingDuration"] = 3.0.into();
    let dir = std::env::temp_dir().join(format!("cutroute-cost-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let task_file = dir.join("E1X_6_01.task.json");
    std::fs::write(&task_file, task.to_string()).unwrap();
    let task_path = task_file.to_string_lossy().into_owned();
    let v = json(&[
        "solve", &nest, "--solver", "nearest", "--task", &task_path, "--json",
    ]);
    assert_model(&v, [250.0, 12.5, 3.0], [0.1, 1.0, 0.5], "task");
    // Flags override the task.
    let v = json(&[
        "solve", &nest, "--solver", "nearest", "--task", &task_path, "--speeds", "100,5,1",
        "--json",
    ]);
    assert_model(&v, [100.0, 5.0, 1.0], [0.1, 1.0, 0.5], "task + flags");
}

#[test]
fn chain_cutting_saves_pierces_and_cost_over_ccp() {
    let nest = data("nests/dbs/nested.dbs");
    let args = |solver: &'static str| {
        vec![
            "solve",
            "--solver",
            solver,
            "--time-limit",
            "2",
            "--cost",
            "0.1,35,7",
            "--json",
        ]
    };
    let mut chain_args = args("chain");
    chain_args.insert(1, &nest);
    let chain = json(&chain_args);
    let mut ccp_args = args("ccp");
    ccp_args.insert(1, &nest);
    let ccp = json(&ccp_args);
    assert_eq!(number(&ccp, "pierces"), 87.0);
    assert!(number(&chain, "pierces") < 87.0, "{}", chain["pierces"]);
    assert!(number(&chain, "link_length") > 0.0);
    assert_eq!(number(&ccp, "link_length"), 0.0);
    assert!(number(&chain, "cost") < number(&ccp, "cost"));
    let linked = chain["route"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s.get("link").is_some())
        .count();
    assert_eq!(linked as f64, 87.0 - number(&chain, "pierces"));
}

#[test]
fn aoe_cuts_common_edges_once_with_fewer_pierces_than_ccp() {
    // Nest01: five parts sharing four edges; the OE-route needs 4 pierces (8 odd vertices).
    let nest = data("nests/tflex/Nest01.tfnesting");
    let run = |solver: &str| {
        json(&[
            "solve",
            &nest,
            "--solver",
            solver,
            "--time-limit",
            "1",
            "--cost",
            "0.1,35,7",
            "--json",
        ])
    };
    let (aoe, ccp) = (run("aoe"), run("ccp"));
    assert_eq!(number(&ccp, "pierces"), 5.0);
    assert_eq!(number(&aoe, "pierces"), 4.0);
    assert_eq!(number(&aoe, "pierce_lower_bound"), 4.0);
    // The four common edges (590 mm in all) are cut once instead of twice.
    let saved = number(&ccp, "cut_length") - number(&aoe, "cut_length");
    assert!((saved - 590.0).abs() < 1.0, "saved {saved} mm");
    assert!(number(&aoe, "cost") < number(&ccp, "cost"));
    let paths = aoe["route"]["paths"].as_array().expect("route.paths");
    assert_eq!(paths.len(), 4);
    assert!(paths
        .iter()
        .all(|p| p["spans"].as_array().is_some_and(|s| !s.is_empty())));
}

#[test]
fn malformed_model_flags_are_refused() {
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    for args in [
        ["--cost", "1,2"],
        ["--cost", "1,x,3"],
        ["--speeds", "0,10,1"],
        ["--cost", "1,-2,3"],
    ] {
        let (ok, _, stderr) = cutroute(&["solve", &nest, "--solver", "nearest", args[0], args[1]]);
        assert!(!ok, "{args:?} accepted");
        assert!(stderr.contains(args[0]), "{args:?}: {stderr}");
    }
}
