//! The command-line tool as users call it, on the real files.

mod common;

use common::{cutroute, data, json};
use cutroute_engine::open_document;
use cutroute_geometry::{ContourRef, CutStep, MachineParameters, Point, Route};
use cutroute_protocol::Problem;
use serde_json::Value;
use std::path::PathBuf;

#[test]
fn inspect_reports_the_stored_facts_of_nests() {
    let cases = [
        ("nests/dbs/nested.dbs", 57, 88, 101),
        ("nests/dbs/seven.dbs", 29, 51, 42),
        ("nests/dbs-json/E1X_6_01.dbs.json", 9, 17, 27),
        ("nests/dbs/test0.json.dbs", 15, 21, -1),
    ];
    for (file, parts, contours, arcs) in cases {
        let v = json(&["inspect", data(file).to_str().unwrap(), "--json"]);
        assert_eq!(v["parts"], parts, "{file}");
        assert_eq!(v["contours"], contours, "{file}");
        if arcs >= 0 {
            assert_eq!(v["arcs"], arcs, "{file}");
        }
        assert_eq!(v["sheet"].as_array().unwrap().len(), 4);
    }
    let nest02 = json(&[
        "inspect",
        data("nests/tflex/Nest02.tfnesting").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(nest02["parts"], 407, "406 placed parts and the sheet");
    assert_eq!(
        nest02["sheet"],
        serde_json::json!([0.0, 0.0, 6000.0, 2000.0])
    );
}

#[test]
fn inspect_reports_pcgtsp_instances() {
    let v = json(&[
        "inspect",
        data("pcgtsp/industrial/e1x_6.pcglns").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(v["format"], "PCGTSP instance");
    assert_eq!(v["nodes"], 181);
    assert_eq!(v["clusters"], 17);
}

#[test]
fn bad_input_exits_non_zero_with_the_readers_message() {
    let dir = std::env::temp_dir().join(format!("cutroute-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("broken.dbs");
    let bytes = std::fs::read(data("nests/dbs/nested.dbs")).unwrap();
    std::fs::write(&bad, &bytes[..777]).unwrap();
    let (ok, _, stderr) = cutroute(&["inspect", bad.to_str().unwrap(), "--json"]);
    assert!(!ok);
    assert!(
        stderr.contains("broken.dbs") && stderr.contains("DBS"),
        "{stderr}"
    );
}

#[test]
fn convert_round_trips_through_dbs_and_writes_svg() {
    let dir = std::env::temp_dir().join(format!("cutroute-convert-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dbs = dir.join("e1x.dbs");
    let svg = dir.join("e1x.svg");
    let source = data("nests/dbs-json/E1X_6_01.dbs.json");
    assert!(cutroute(&["convert", source.to_str().unwrap(), dbs.to_str().unwrap()]).0);
    assert!(cutroute(&["convert", dbs.to_str().unwrap(), svg.to_str().unwrap()]).0);
    let v = json(&["inspect", dbs.to_str().unwrap(), "--json"]);
    assert_eq!(
        (v["parts"].as_u64(), v["contours"].as_u64()),
        (Some(9), Some(17))
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("<svg") && text.matches("class=\"part\"").count() == 8,
        "{}",
        &text[..200.min(text.len())]
    );
}

#[test]
fn solve_exact_prints_the_documented_keys_and_a_proven_optimum() {
    let v = json(&[
        "solve",
        data("pcgtsp/industrial/e1x_6.pcglns").to_str().unwrap(),
        "--solver",
        "exact",
        "--time-limit",
        "30",
        "--json",
    ]);
    for key in [
        "solver",
        "ub",
        "lb",
        "gap",
        "proven_optimal",
        "tour",
        "elapsed_s",
        "states",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["ub"], 1513.0);
    assert_eq!(v["proven_optimal"], true);
    assert_eq!(v["tour"][0], 1, "1-based, depot first");
}

#[test]
fn solve_ccp_prints_a_checked_route() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let v = json(&[
        "solve",
        file.to_str().unwrap(),
        "--solver",
        "ccp",
        "--time-limit",
        "1",
        "--json",
    ]);
    assert_eq!(v["solver"], "ccp");
    assert_eq!(v["pierces"], 16);
    // The printed route, rebuilt and checked here: every contour once, pierce points on their
    // contours, holes first.
    let bytes = std::fs::read(&file).unwrap();
    let document = open_document("E1X_6_01.dbs.json", &bytes).unwrap();
    let Problem::Nest {
        nest,
        start,
        finish,
    } = document.problem
    else {
        panic!("a nest")
    };
    let point = |p: &Value| Point::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
    let steps: Vec<CutStep> = v["route"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let c = &s["contour"];
            let contour = ContourRef {
                part: c[0].as_u64().unwrap() as usize,
                contour: c[1].as_u64().unwrap() as usize,
            };
            CutStep::pierced(contour, point(&s["pierce"]))
        })
        .collect();
    assert_eq!(steps.len(), 16);
    let route = Route {
        start,
        steps,
        finish,
    };
    let problems = route.problems(&nest, &nest.containment_forest(), 1e-3);
    assert!(problems.is_empty(), "{problems:?}");
    // Idle, cut and time recomputed from the printed points and the nest's own contours, with
    // the default machine (no task file): what the report says must be what the route is.
    let mut at = start;
    let mut idle = 0.0;
    let mut cut = 0.0;
    for s in &route.steps {
        idle += at.distance(s.pierce_point);
        at = s.pierce_point;
        cut += nest.parts[s.contour.part].contours[s.contour.contour].perimeter();
    }
    if let Some(f) = finish {
        idle += at.distance(f);
    }
    let machine = MachineParameters::default();
    let time = cut / machine.cut_speed + idle / machine.idle_speed + 16.0 * machine.pierce_time;
    let close = |key: &str, expected: f64| {
        let got = v[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} is a number"));
        assert!(
            (got - expected).abs() <= 1e-6 * expected,
            "{key}: {got} vs {expected}"
        );
    };
    close("idle_length", idle);
    close("cut_length", cut);
    close("time_s", time);
    close("ub", idle);
    assert_eq!(v["machine"]["cut_speed"], machine.cut_speed);
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cutroute-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn convert_to_gcode_writes_the_solved_route() {
    let source = data("nests/dbs-json/E1X_6_01.dbs.json");
    let solved = json(&[
        "solve",
        source.to_str().unwrap(),
        "--solver",
        "nearest",
        "--json",
    ]);
    for (file, extra) in [
        ("e1x.nc", vec![]),
        (
            "e1x.txt",
            vec!["--to", "gcode", "--incremental", "--arcs", "r"],
        ),
    ] {
        let out = scratch(file);
        let mut args = vec![
            "convert",
            source.to_str().unwrap(),
            out.to_str().unwrap(),
            "--solver",
            "nearest",
            "--decimals",
            "6",
        ];
        args.extend(extra);
        let (ok, _, stderr) = cutroute(&args);
        assert!(ok, "{stderr}");
        let text = std::fs::read_to_string(&out).unwrap();
        // The nest's home point is the origin, where the reader starts by default.
        let program = cutroute_gcode::read_gcode(&text, &cutroute_gcode::ReadOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(
            program.pierce_count() as u64,
            solved["pierces"].as_u64().unwrap()
        );
        let idle = solved["idle_length"].as_f64().unwrap();
        let cut = solved["cut_length"].as_f64().unwrap();
        assert!(
            (program.idle_length() - idle).abs() < 1e-3,
            "{file}: idle {} vs {idle}",
            program.idle_length()
        );
        assert!(
            (program.cut_length() - cut).abs() < 1e-3,
            "{file}: cut {} vs {cut}",
            program.cut_length()
        );
        assert!(
            (program.dwell_time() - 16.0 * 7.0).abs() < 1e-9,
            "one default dwell per pierce"
        );
    }
}

#[test]
fn convert_to_html_writes_a_standalone_page() {
    let source = data("nests/dbs/nested.dbs");
    let out = scratch("nested.html");
    let (ok, _, stderr) = cutroute(&[
        "convert",
        source.to_str().unwrap(),
        out.to_str().unwrap(),
        "--solver",
        "nearest",
    ]);
    assert!(ok, "{stderr}");
    let page = std::fs::read_to_string(&out).unwrap();
    assert!(page.starts_with("<!DOCTYPE html>") && page.trim_end().ends_with("</html>"));
    assert!(!page.contains("http") && !page.contains("src="));
    // nested.dbs: 57 parts of which one is the sheet, 88 contours of which one is the sheet's.
    assert_eq!(page.matches("<circle class=\"pierce\"").count(), 87);
    assert_eq!(page.matches("<path class=\"part\"").count(), 56);
    assert!(page.contains("id=\"tool-head\""));
}

#[test]
fn convert_refuses_unknown_formats_and_solvers() {
    let source = data("nests/dbs-json/E1X_6_01.dbs.json");
    let out = scratch("e1x.gcode");
    let (ok, _, stderr) = cutroute(&[
        "convert",
        source.to_str().unwrap(),
        out.to_str().unwrap(),
        "--solver",
        "magic",
    ]);
    // Refused by the option parser, which names the option and the possible values.
    assert!(
        !ok && stderr.contains("'--solver") && stderr.contains("possible values"),
        "{stderr}"
    );
    let (ok, _, stderr) = cutroute(&[
        "convert",
        source.to_str().unwrap(),
        out.to_str().unwrap(),
        "--to",
        "pdf",
    ]);
    assert!(
        !ok && stderr.contains("'--to") && stderr.contains("possible values"),
        "{stderr}"
    );
}

/// `inspect --step` counts the candidate pierce points the discrete solvers weigh: the nodes of
/// the discretised instance but its depot (the app's candidate dots are checked against it).
#[test]
fn inspect_counts_the_discrete_candidates() {
    for (file, step) in [
        ("nests/dbs/nested.dbs", 25.0),
        ("nests/dbs-json/E1X_6_01.dbs.json", 10.0),
        ("nests/dbs/seven.dbs", 3.5),
    ] {
        let path = data(file);
        let v = json(&[
            "inspect",
            path.to_str().unwrap(),
            "--json",
            "--step",
            &step.to_string(),
        ]);
        let Problem::Nest { nest, .. } = open_document(file, &std::fs::read(&path).unwrap())
            .unwrap()
            .problem
        else {
            panic!("{file} is a nest");
        };
        let options = cutroute_ccp::DiscretisationOptions {
            step,
            ..Default::default()
        };
        let instance = cutroute_ccp::build_pcgtsp(&nest, &options)
            .unwrap()
            .instance;
        assert_eq!(
            v["candidate_points"].as_u64(),
            Some(instance.node_count as u64 - 1),
            "{file} at {step} mm"
        );
    }
    let without = json(&[
        "inspect",
        data("nests/dbs/nested.dbs").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(without.get("candidate_points"), None);
}

#[test]
fn generate_writes_a_seeded_nest() {
    let out = scratch("generated.json");
    let (ok, _, stderr) = cutroute(&[
        "generate",
        "--contours",
        "300",
        "--seed",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let v = json(&["inspect", out.to_str().unwrap(), "--json"]);
    // Geometry JSON stores the sheet as the first part: 300 contours plus the sheet's.
    assert_eq!(v["contours"], 301);
    let expected = cutroute_geometry::generate_nest(300, 5);
    assert_eq!(v["parts"].as_u64(), Some(expected.parts.len() as u64 + 1));
}

/// One door for files: the G-code `convert` writes opens again in `inspect` and `solve`, with
/// the route's pierces and lengths; path routes (AOE) are written and read back as paths.
#[test]
fn gcode_written_by_convert_opens_in_inspect_and_solve() {
    let nest = data("nests/tflex/Nest01.tfnesting");
    let solved = json(&["solve", nest.to_str().unwrap(), "--solver", "aoe", "--json"]);
    let program = scratch("nest01-aoe.nc");
    let (ok, _, stderr) = cutroute(&[
        "convert",
        nest.to_str().unwrap(),
        program.to_str().unwrap(),
        "--solver",
        "aoe",
    ]);
    assert!(ok, "{stderr}");
    let facts = json(&["inspect", program.to_str().unwrap(), "--json"]);
    assert_eq!(facts["format"], "G-code");
    assert_eq!(facts["route_pierces"], solved["pierces"]);
    for (key, expected) in [
        ("route_cut_length", "cut_length"),
        ("route_idle_length", "idle_length"),
    ] {
        let (got, want) = (
            facts[key].as_f64().unwrap(),
            solved[expected].as_f64().unwrap(),
        );
        // The program rounds coordinates to 3 decimals: 0.0005 mm per end of every move.
        assert!((got - want).abs() <= 1e-2, "{key}: {got} vs {want}");
    }

    // A contour route: the program's loops are the nest, and solving it cuts every one.
    let e1x = data("nests/dbs-json/E1X_6_01.dbs.json");
    let program = scratch("e1x-nearest.nc");
    let (ok, _, stderr) = cutroute(&[
        "convert",
        e1x.to_str().unwrap(),
        program.to_str().unwrap(),
        "--solver",
        "nearest",
    ]);
    assert!(ok, "{stderr}");
    let nearest = json(&[
        "solve",
        e1x.to_str().unwrap(),
        "--solver",
        "nearest",
        "--json",
    ]);
    let facts = json(&["inspect", program.to_str().unwrap(), "--json"]);
    assert_eq!(facts["contours"], 16);
    assert_eq!(facts["route_pierces"], 16);
    let idle = facts["route_idle_length"].as_f64().unwrap();
    let want = nearest["idle_length"].as_f64().unwrap();
    assert!((idle - want).abs() <= 1e-2, "idle {idle} vs {want}");
    let again = json(&[
        "solve",
        program.to_str().unwrap(),
        "--solver",
        "ccp",
        "--time-limit",
        "1",
        "--json",
    ]);
    assert_eq!(again["pierces"], 16);
    let cut = again["cut_length"].as_f64().unwrap();
    let want = nearest["cut_length"].as_f64().unwrap();
    assert!((cut - want).abs() <= 1e-2, "cut {cut} vs {want}");
}
