//! `cutroute solve`/`convert` with kerf and leads: every step carries its full-route elements,
//! checked here independently of the library; the defaults change nothing.

mod common;

use common::{cutroute, json};
use serde_json::Value;

fn data(relative: &str) -> String {
    common::data(relative).to_string_lossy().into_owned()
}

const PLASMA: [&str; 12] = [
    "--kerf",
    "2",
    "--pierce-clearance",
    "5",
    "--switch-off-clearance",
    "1",
    "--lead-in",
    "arc",
    "--lead-in-length",
    "8",
    "--lead-out",
    "line",
];

/// Laser settings of the issue: kerf 0.2, d₁ 1, d₂ 0.5, arc lead-ins of 3 mm.
const LASER: [&str; 14] = [
    "--kerf",
    "0.2",
    "--pierce-clearance",
    "1",
    "--switch-off-clearance",
    "0.5",
    "--lead-in",
    "arc",
    "--lead-in-length",
    "3",
    "--lead-out",
    "line",
    "--lead-out-length",
    "1",
];

fn point(v: &Value) -> (f64, f64) {
    (v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

/// The report's idle legs recomputed from its points: start → M₁, every M*ᵢ → Mᵢ₊₁, and
/// M*ₙ → finish.
fn legs(report: &Value) -> f64 {
    let distance = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0).hypot(b.1 - a.1);
    let mut at = point(&report["start"]);
    let mut legs = 0.0;
    for step in report["route"].as_array().unwrap() {
        legs += distance(at, point(&step["pierce"]));
        at = point(&step["switch_off"]);
    }
    if let Some(finish) = report.get("finish").filter(|f| !f.is_null()) {
        legs += distance(at, point(finish));
    }
    legs
}

/// test1 (a 2000 × 1000 sheet with parts near its border) less the parts lying in a hole of
/// their own shape, which no kerf cuts right (the kerf refusal names each such pair, the part
/// in the hole second), written as DBS JSON into a folder of `test`'s own.
fn test1_without_parts_in_their_holes(test: &str) -> String {
    let file = data("nests/dbs-json/test1.dbs.json");
    let mut args = vec!["solve", &file, "--solver", "nearest"];
    args.extend(PLASMA);
    let (ok, _, err) = cutroute(&args);
    assert!(!ok, "test1 is refused with a kerf");
    let mut in_holes: Vec<usize> = err
        .split("; ")
        .filter_map(|pair| {
            let pair = pair.split(": ").last()?;
            let (_, second) = pair.split_once(" and part ")?;
            let (part, rest) = second.split_once(' ')?;
            rest.contains("lie on one another")
                .then(|| part.parse().ok())?
        })
        .collect();
    assert_eq!(in_holes.len(), 2, "{err}");
    let mut parts: Vec<Value> =
        serde_json::from_slice(&std::fs::read(&file).unwrap()).expect("DBS JSON");
    // Entry 0 is the sheet; parts are numbered from 1.
    in_holes.sort_unstable();
    for &k in in_holes.iter().rev() {
        assert_eq!(parts[k]["paths"].as_array().unwrap().len(), 1, "part {k}");
        parts.remove(k);
    }
    let dir = std::env::temp_dir().join(format!("cutroute-kerf-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("test1-fit.dbs.json");
    std::fs::write(&out, serde_json::to_vec(&parts).unwrap()).unwrap();
    out.to_string_lossy().into_owned()
}

#[test]
fn with_leads_every_step_carries_pierce_entry_leads_and_switch_off() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    for solver in ["nearest", "ccp"] {
        let mut args = vec![
            "solve",
            &file,
            "--solver",
            solver,
            "--time-limit",
            "1",
            "--json",
        ];
        args.extend(PLASMA);
        let report = json(&args);
        let steps = report["route"].as_array().unwrap();
        assert!(!steps.is_empty());
        for step in steps {
            let m = point(&step["pierce"]);
            let lead_in = step["lead_in"].as_array().unwrap();
            assert_eq!(point(&lead_in[0]), m, "{solver}: the lead-in starts at M");
            assert_eq!(point(lead_in.last().unwrap()), point(&step["entry"]));
            let lead_out = step["lead_out"].as_array().unwrap();
            assert_eq!(point(lead_out.last().unwrap()), point(&step["switch_off"]));
            // M is off the contour, at least d₁ = 5 from the point of the contour it serves.
            let c = point(&step["contour_point"]);
            assert!(
                (m.0 - c.0).hypot(m.1 - c.1) >= 5.0 - 1e-6,
                "{solver}: {m:?} vs {c:?}"
            );
        }
        // idle_length is the start leg plus every switch-off → next pierce leg.
        let idle = legs(&report);
        let reported = report["idle_length"].as_f64().unwrap();
        assert!(
            (idle - reported).abs() < 1e-6,
            "{solver}: {idle} vs {reported}"
        );
        assert!(report["lead_in_length"].as_f64().unwrap() > 0.0);
    }
}

/// Chain cutting with leads: one pierce per chain at M with a lead-in, links from the exit of
/// one contour's equidistant to the entry of the next (no `pierce` or `switch_off` at a link's
/// ends), a lead-out at each chain's end; the idle legs run M* → next M.
#[test]
fn chains_pierce_once_with_a_lead_in_and_end_with_a_lead_out() {
    for (file, settings) in [
        ("nests/dbs-json/E1X_6_01.dbs.json", &PLASMA[..]),
        // Not test0: its part lying in a hole of its own shape is refused with any kerf.
        ("nests/svg/plates.svg", &LASER[..]),
    ] {
        let file = data(file);
        let mut args = vec![
            "solve",
            &file,
            "--solver",
            "chain",
            "--time-limit",
            "2",
            "--json",
        ];
        args.extend(settings);
        let report = json(&args);
        let steps = report["route"].as_array().unwrap();
        let linked = |k: usize| steps.get(k).is_some_and(|s| s.get("link").is_some());
        assert!((1..steps.len()).any(linked), "{file}: no chain");
        let distance = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0).hypot(b.1 - a.1);
        let (mut at, mut idle, mut pierces) = (point(&report["start"]), 0.0, 0);
        for (k, step) in steps.iter().enumerate() {
            let lead_in = step["lead_in"].as_array().unwrap();
            let lead_out = step["lead_out"].as_array().unwrap();
            assert_eq!(point(lead_in.last().unwrap()), point(&step["entry"]));
            if linked(k) {
                assert!(step.get("pierce").is_none(), "{file}: step {k}");
                assert_eq!(lead_in.len(), 1, "{file}: no lead-in after a link");
            } else {
                let m = point(&step["pierce"]);
                assert_eq!(point(&lead_in[0]), m);
                idle += distance(at, m);
                pierces += 1;
            }
            if linked(k + 1) {
                assert!(step.get("switch_off").is_none(), "{file}: step {k}");
                assert_eq!(lead_out.len(), 1, "{file}: no lead-out before a link");
            } else {
                at = point(&step["switch_off"]);
                assert_eq!(point(lead_out.last().unwrap()), at);
            }
        }
        if let Some(finish) = report.get("finish").filter(|f| !f.is_null()) {
            idle += distance(at, point(finish));
        }
        assert_eq!(report["pierces"].as_u64(), Some(pierces));
        let reported = report["idle_length"].as_f64().unwrap();
        assert!(
            (idle - reported).abs() < 1e-6,
            "{file}: {idle} vs {reported}"
        );
        assert!(report["link_length"].as_f64().unwrap() > 0.0);
        assert!(report["chain_links_broken"].as_u64().is_some());
    }
}

/// `--rules-hard` turns chain links that break a rule into pierces after the leads were fitted:
/// those steps get leads of their own (a lead-in from M), and the route printed is the one
/// repaired, not an earlier one.
#[test]
fn chains_repaired_by_hard_rules_keep_their_leads() {
    // Not test0: its part lying in a hole of its own shape is refused with any kerf. plates.svg
    // chains with these leads, and its links break the rules.
    let file = data("nests/svg/plates.svg");
    let mut free = vec![
        "solve",
        &file,
        "--solver",
        "chain",
        "--time-limit",
        "3",
        "--json",
    ];
    free.extend(PLASMA);
    let chained = json(&free);
    let linked = |r: &Value| {
        r["route"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s.get("link").is_some())
            .count()
    };
    assert!(linked(&chained) > 0, "{chained}");
    let mut args = vec![
        "solve",
        &file,
        "--solver",
        "chain",
        "--time-limit",
        "3",
        "--rules",
        "part,sheet,islands",
        "--rules-hard",
        "--json",
    ];
    args.extend(PLASMA);
    let report = json(&args);
    assert!(report["final_route_rejected"].is_null(), "{report}");
    let steps = report["route"].as_array().unwrap();
    for (k, step) in steps.iter().enumerate() {
        assert!(step.get("lead_in").is_some(), "step {k} has no leads");
        if step.get("link").is_none() {
            let lead_in = step["lead_in"].as_array().unwrap();
            assert_eq!(point(&lead_in[0]), point(&step["pierce"]));
            assert!(lead_in.len() > 1, "step {k}: a pierce without a lead-in");
        }
    }
    for rule in ["part", "sheet", "islands"] {
        assert_eq!(report["rule_violations"][rule], 0, "{rule}");
    }
    // The repair turned links into pierces.
    assert!(linked(&report) < linked(&chained), "{report}");
}

#[test]
fn the_defaults_keep_the_idealised_report() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let report = json(&["solve", &file, "--solver", "nearest", "--json"]);
    assert!(report.get("kerf").is_none());
    assert!(report["route"][0].get("lead_in").is_none());
}

#[test]
fn path_solvers_print_leads_per_path_and_bad_flags_are_refused() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    for solver in ["sccp", "aoe"] {
        let mut args = vec!["solve", &file, "--solver", solver, "--json"];
        args.extend(PLASMA);
        let report = json(&args);
        assert!(report.get("kerf").is_some(), "{solver}");
        let paths = report["route"]["paths"].as_array().expect("paths");
        assert_eq!(paths.len() as f64, report["pierces"].as_f64().unwrap());
        for path in paths {
            for field in ["pierce", "entry", "lead_in", "lead_out", "switch_off"] {
                assert!(path.get(field).is_some(), "{solver}: {field} in {path}");
            }
            let lead_in = path["lead_in"].as_array().unwrap();
            assert_eq!(point(&lead_in[0]), point(&path["pierce"]), "{solver}");
            assert_eq!(
                point(&lead_in[lead_in.len() - 1]),
                point(&path["entry"]),
                "{solver}"
            );
            let lead_out = path["lead_out"].as_array().unwrap();
            assert_eq!(
                point(&lead_out[lead_out.len() - 1]),
                point(&path["switch_off"]),
                "{solver}"
            );
        }
        assert!(report["lead_in_length"].as_f64().unwrap() > 0.0, "{solver}");
    }
    let (ok, _, err) = cutroute(&["solve", &file, "--lead-in", "spiral"]);
    assert!(!ok && err.contains("--lead-in"), "{err}");
    let (ok, _, err) = cutroute(&["solve", &file, "--kerf=-1"]);
    assert!(!ok && err.contains("--kerf"), "{err}");
}

#[test]
fn convert_writes_gcode_with_leads_that_reads_back() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let out = std::env::temp_dir().join(format!("cutroute-kerf-{}.nc", std::process::id()));
    let out_s = out.to_string_lossy().into_owned();
    let mut args = vec!["convert", &file, &out_s, "--solver", "nearest"];
    args.extend(PLASMA);
    let (ok, _, err) = cutroute(&args);
    assert!(ok, "{err}");
    let report = json(&["inspect", &out_s, "--json"]);
    let solved = {
        let mut a = vec!["solve", &file, "--solver", "nearest", "--json"];
        a.extend(PLASMA);
        json(&a)
    };
    let _ = std::fs::remove_file(&out);
    assert_eq!(report["route_pierces"], solved["pierces"]);
    let (read, cut) = (
        report["route_cut_length"].as_f64().unwrap(),
        solved["cut_length"].as_f64().unwrap(),
    );
    assert!((read - cut).abs() < 1e-2, "{read} vs {cut}");
}

/// The target: on every real nest the routes with kerf 2, d₁ 5, d₂ 1 and arc
/// lead-ins (and the laser's kerf 0.2, d₁ 1) pass the checker (the CLI checks every route before printing it); a nest with no
/// room for the kerf (`ring.dbs`, a 4 mm ring) names the contour instead.
#[test]
fn every_real_nest_routes_with_plasma_leads_or_names_the_contour_without_room() {
    let root = common::data("nests");
    let mut files: Vec<std::path::PathBuf> = ["dbs", "dbs-json"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for path in files {
        let file = path.to_string_lossy().into_owned();
        for solver in ["nearest", "ccp", "chain"] {
            let mut args = vec!["solve", &file, "--solver", solver, "--time-limit", "0.3"];
            args.extend(PLASMA);
            let (ok, _, err) = cutroute(&args);
            // test0 and test1 have a part lying in a hole of its own shape: refused with any
            // kerf, the pairs named.
            let in_its_hole = file.contains("test0") || file.contains("test1");
            let refused_in_its_hole = |err: &str| {
                err.contains("parts closer than the kerf of")
                    && err.contains("lie on one another near (")
            };
            if file.ends_with("ring.dbs") {
                assert!(
                    !ok && err.contains("part 1 contour 1 has no equidistant"),
                    "{file}: {err}"
                );
            } else if in_its_hole {
                assert!(!ok && refused_in_its_hole(&err), "{file} {solver}: {err}");
            } else {
                assert!(ok, "{file} {solver}: {err}");
            }
            // Laser: a 0.2 mm kerf and d₁ 1 leave room on every nest, the 4 mm ring included.
            let mut args = vec!["solve", &file, "--solver", solver, "--time-limit", "0.3"];
            args.extend(LASER);
            let (ok, _, err) = cutroute(&args);
            if in_its_hole {
                assert!(!ok && refused_in_its_hole(&err), "{file} {solver}: {err}");
            } else {
                assert!(ok, "{file} {solver} (laser): {err}");
            }
        }
    }
}

/// `--tabs N:WIDTH`: each part's outer contour gets up to N gaps (holes none); each gap is a
/// torch-off crossing and one more pierce, in the report and in the G-code read back.
#[test]
fn tabs_add_a_pierce_and_an_idle_crossing_per_gap() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let solve = |extra: &[&str]| {
        let mut args = vec![
            "solve",
            &file,
            "--solver",
            "ccp",
            "--time-limit",
            "1",
            "--json",
        ];
        args.extend(PLASMA);
        args.extend(extra);
        json(&args)
    };
    let report = solve(&["--tabs", "2:1.5"]);
    let steps = report["route"].as_array().unwrap();
    let mut gaps = 0;
    let mut crossing = 0.0;
    for step in steps {
        if let Some(tabs) = step.get("tabs").and_then(Value::as_array) {
            assert!(tabs.len() <= 2);
            for tab in tabs {
                let (a, b) = (point(&tab["from"]), point(&tab["to"]));
                crossing += (b.0 - a.0).hypot(b.1 - a.1);
                gaps += 1;
            }
        }
    }
    assert!(gaps > 0, "{report}");
    assert_eq!(
        report["pierces"].as_u64().unwrap() as usize,
        steps.len() + gaps
    );
    // idle = the legs between steps plus the crossings of the gaps.
    let legs = legs(&report);
    let idle = report["idle_length"].as_f64().unwrap();
    assert!(
        (legs + crossing - idle).abs() < 1e-6,
        "{legs} + {crossing} vs {idle}"
    );
    // The program written with tabs reads back with the same pierces and cut.
    let out = std::env::temp_dir().join(format!("cutroute-tabs-{}.nc", std::process::id()));
    let out_s = out.to_string_lossy().into_owned();
    let mut args = vec![
        "convert",
        &file,
        &out_s,
        "--solver",
        "ccp",
        "--time-limit",
        "1",
        "--tabs",
        "2:1.5",
    ];
    args.extend(PLASMA);
    let (ok, _, err) = cutroute(&args);
    assert!(ok, "{err}");
    let read = json(&["inspect", &out_s, "--json"]);
    let _ = std::fs::remove_file(&out);
    let pierces = read["route_pierces"].as_u64().unwrap() as usize;
    let contours = steps.len();
    assert!(
        pierces > contours,
        "the gaps' pierces are in the program: {pierces}"
    );
    let (ok, _, err) = cutroute(&["solve", &file, "--tabs", "two:1"]);
    assert!(!ok && err.contains("--tabs"), "{err}");
}

/// `--kerf-compensation g41.1`: the program runs on the contours and the controller offsets
/// it; read back (the reader offsets it too) it has the route's pierces and cut.
#[test]
fn controller_compensation_writes_a_program_that_reads_back_as_the_route() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let line_leads = [
        "--kerf",
        "2",
        "--pierce-clearance",
        "3",
        "--lead-in",
        "line",
        "--lead-out",
        "line",
        "--overcut",
        "1",
    ];
    let out = std::env::temp_dir().join(format!("cutroute-g41-{}.nc", std::process::id()));
    let out_s = out.to_string_lossy().into_owned();
    let mut args = vec![
        "convert",
        &file,
        &out_s,
        "--solver",
        "nearest",
        "--kerf-compensation",
        "g41.1",
    ];
    args.extend(line_leads);
    let (ok, _, err) = cutroute(&args);
    assert!(ok, "{err}");
    let program = std::fs::read_to_string(&out).unwrap();
    let read = json(&["inspect", &out_s, "--json"]);
    let _ = std::fs::remove_file(&out);
    let mut solve = vec!["solve", &file, "--solver", "nearest", "--json"];
    solve.extend(line_leads);
    let solved = json(&solve);
    let steps = solved["route"].as_array().unwrap().len();
    assert_eq!(program.matches("G41.1 D2.000").count(), steps);
    assert_eq!(read["route_pierces"], solved["pierces"]);
    let (cut, expected) = (
        read["route_cut_length"].as_f64().unwrap(),
        solved["cut_length"].as_f64().unwrap(),
    );
    assert!((cut - expected).abs() < 1e-2, "{cut} vs {expected}");
    // Arc leads cannot be the controller's start-up move.
    let mut args = vec![
        "convert",
        &file,
        &out_s,
        "--solver",
        "nearest",
        "--kerf-compensation",
        "g41.1",
    ];
    args.extend(PLASMA);
    let (ok, _, err) = cutroute(&args);
    assert!(!ok && err.contains("straight lead"), "{err}");
    let (ok, _, err) = cutroute(&["convert", &file, &out_s, "--kerf-compensation", "g42"]);
    assert!(!ok && err.contains("--kerf-compensation"), "{err}");
}

#[test]
fn exact_with_leads_reports_its_model_bound_below_its_route() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let mut args = vec![
        "solve",
        &file,
        "--solver",
        "exact",
        "--time-limit",
        "10",
        "--json",
    ];
    args.extend(PLASMA);
    let report = json(&args);
    let idle = report["idle_length"].as_f64().unwrap();
    assert!((legs(&report) - idle).abs() < 1e-6 * idle.max(1.0));
    for step in report["route"].as_array().unwrap() {
        assert!(step.get("lead_in").is_some() && step.get("switch_off").is_some());
    }
    let lb = report["lb"]
        .as_f64()
        .expect("a bound of the full-route model");
    assert!(lb > 0.0 && lb <= idle, "bound {lb} vs route {idle}");
}

#[test]
fn edge_pierces_sit_on_the_sheet_border_and_take_the_edge_pierce_time() {
    // test1's 2000 × 1000 sheet (less its parts lying in their holes, refused with a kerf).
    let file = test1_without_parts_in_their_holes("edge-pierces");
    let mut args = vec![
        "solve",
        &file,
        "--solver",
        "nearest",
        "--json",
        "--edge-pierce",
        "--edge-pierce-time",
        "2",
    ];
    args.extend(PLASMA);
    let report = json(&args);
    let edge: Vec<&Value> = report["route"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s.get("edge_pierce").is_some())
        .collect();
    assert_eq!(
        report["edge_pierces"].as_u64().unwrap() as usize,
        edge.len()
    );
    // Nearest is deterministic: one part of test1 lies within the edge reach of the border.
    assert!(!edge.is_empty());
    for step in &edge {
        let (x, y) = point(&step["pierce"]);
        let to_border = x
            .abs()
            .min((x - 2000.0).abs())
            .min(y.abs())
            .min((y - 1000.0).abs());
        assert!(to_border < 1e-6, "edge pierce ({x}, {y}) off the border");
        assert_eq!(
            step["lead_in"].as_array().unwrap().len(),
            2,
            "a straight lead"
        );
    }
    // Time: cut at 10 mm/s, idle at 500 mm/s, 7 s a pierce in the sheet, 2 s at its edge.
    let (cut, idle) = (
        report["cut_length"].as_f64().unwrap(),
        report["idle_length"].as_f64().unwrap(),
    );
    let pierces = report["pierces"].as_u64().unwrap() as f64;
    let expected =
        cut / 10.0 + idle / 500.0 + 7.0 * (pierces - edge.len() as f64) + 2.0 * edge.len() as f64;
    let time = report["time_s"].as_f64().unwrap();
    assert!(
        (time - expected).abs() < 1e-6 * expected,
        "{time} vs {expected}"
    );
}

#[test]
fn kerf_pierces_sit_in_a_kerf_cut_before_and_save_time() {
    // nested.dbs with nearest (deterministic): the same order with and without kerf piercing.
    let file = data("nests/dbs/nested.dbs");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "solve",
            &file,
            "--solver",
            "nearest",
            "--json",
            "--edge-pierce-time",
            "2",
        ];
        args.extend(PLASMA);
        args.extend(extra);
        json(&args)
    };
    let plain = run(&[]);
    let report = run(&["--kerf-pierce"]);
    assert!(
        report["final_route_rejected"].is_null(),
        "the checker passed it"
    );
    assert!(plain.get("kerf_pierces").is_none());
    let route = report["route"].as_array().unwrap();
    let kerf: Vec<(usize, &Value)> = route
        .iter()
        .enumerate()
        .filter(|(_, s)| s.get("kerf_pierce").is_some())
        .collect();
    assert_eq!(
        report["kerf_pierces"].as_u64().unwrap() as usize,
        kerf.len()
    );
    assert!(
        kerf.len() >= 5,
        "nested.dbs packs parts within reach: {}",
        kerf.len()
    );
    let cut_before = |k: usize, of: &Value| route[..k].iter().any(|s| s["contour"] == *of);
    for &(k, step) in &kerf {
        assert!(cut_before(k, &step["kerf_pierce"]), "step {k}: {step}");
        assert_eq!(
            step["lead_in"].as_array().unwrap().len(),
            2,
            "a straight lead"
        );
    }
    // The order is nearest's either way; the quick pierces save more than the idle they add.
    let order = |steps: &[Value]| {
        steps
            .iter()
            .map(|s| s["contour"].clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(order(route), order(plain["route"].as_array().unwrap()));
    let time = |r: &Value| r["time_s"].as_f64().unwrap();
    assert!(
        time(&report) < time(&plain) - 4.0 * kerf.len() as f64,
        "{} vs {}",
        time(&report),
        time(&plain)
    );
    // Time: cut at 10 mm/s, idle at 500 mm/s, 7 s a pierce in the sheet, 2 s in a kerf.
    let (cut, idle) = (
        report["cut_length"].as_f64().unwrap(),
        report["idle_length"].as_f64().unwrap(),
    );
    let pierces = report["pierces"].as_u64().unwrap() as f64;
    let expected =
        cut / 10.0 + idle / 500.0 + 7.0 * (pierces - kerf.len() as f64) + 2.0 * kerf.len() as f64;
    assert!((time(&report) - expected).abs() < 1e-6 * expected);
}

/// T-FLEX Nest01's five parts touch in a row: with any kerf no cut on the equidistants keeps
/// kerf/2 off its neighbour, so `solve` refuses up front (exit 1, no route printed), naming
/// each touching pair and where — for plasma and laser alike.
#[test]
fn parts_closer_than_the_kerf_are_refused_naming_the_pairs() {
    let file = data("nests/tflex/Nest01.tfnesting");
    for solver in ["nearest", "ccp", "chain"] {
        for machine in [&PLASMA[..], &LASER[..]] {
            let mut args = vec!["solve", &file, "--solver", solver, "--time-limit", "0.3"];
            args.extend(machine);
            let (ok, out, err) = cutroute(&args);
            assert!(!ok && out.is_empty(), "{solver}: {out}");
            assert!(err.contains("parts closer than the kerf of"), "{err}");
            assert!(err.contains("4 pair(s) of contours"), "{err}");
            assert!(
                err.contains("part 1 contour 0 and part 2 contour 0 touch near ("),
                "{err}"
            );
        }
    }
    // Without kerf the same nest is cut as ever.
    let (ok, _, err) = cutroute(&["solve", &file, "--solver", "ccp", "--time-limit", "0.3"]);
    assert!(ok, "{err}");
}

/// test0 has a part lying exactly in a hole of its own shape (part 4's contour 2 and part 13):
/// with a kerf either the hole or the part would come out a kerf off its line. Every way a
/// kerf reaches a program refuses it as parts closer than the kerf, naming both parts:
/// `solve` (text and --json), `convert` to G-code with the offsets in the program and with the
/// controller's compensation (G41.1 and G41 D<n>), for a solved route and for the file's own
/// (test0's result), and no program is written. Without a kerf it converts as ever.
#[test]
fn contours_on_one_another_are_refused_with_a_kerf_naming_both_parts() {
    let nest = data("nests/dbs-json/test0.dbs.json");
    let own_route = data("nests/result-json/test0.result.json");
    let refused = |args: &[&str]| {
        let (ok, out, err) = cutroute(args);
        assert!(!ok && out.is_empty(), "{args:?}: {out}");
        let last = err.trim().lines().last().unwrap_or_default().to_string();
        assert!(
            last.contains("parts closer than the kerf of"),
            "{args:?}: {err}"
        );
        assert!(last.contains("1 pair(s) of contours"), "{args:?}: {err}");
        // The pair by part (from 1) and contour, both parts named.
        let pair = last
            .split("1 pair(s) of contours: ")
            .nth(1)
            .unwrap_or_default();
        assert!(
            pair.starts_with("part ")
                && pair.contains(" and part ")
                && pair.contains(" lie on one another near ("),
            "{args:?}: {err}"
        );
        let parts: Vec<&str> = pair
            .split("part ")
            .skip(1)
            .filter_map(|p| p.split(' ').next())
            .collect();
        assert_eq!(parts.len(), 2, "{pair}");
        assert_ne!(parts[0], parts[1], "{pair}");
    };
    for machine in [&PLASMA[..], &LASER[..]] {
        for solver in ["nearest", "ccp", "chain", "sccp"] {
            for json in [false, true] {
                let mut args = vec!["solve", &nest, "--solver", solver, "--time-limit", "0.3"];
                if json {
                    args.push("--json");
                }
                args.extend(machine);
                refused(&args);
            }
        }
    }
    let dir = std::env::temp_dir().join(format!(
        "cutroute-kerf-on-one-another-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("test0.nc");
    let out_s = out.to_string_lossy().into_owned();
    // The controller's compensation needs straight leads.
    let straight = [
        "--kerf",
        "2",
        "--pierce-clearance",
        "5",
        "--switch-off-clearance",
        "1",
        "--lead-in",
        "line",
        "--lead-out",
        "line",
    ];
    for input in [&nest, &own_route] {
        for compensation in ["program", "g41.1", "g41:1"] {
            let mut args = vec![
                "convert",
                input,
                &out_s,
                "--kerf-compensation",
                compensation,
            ];
            if input == &nest {
                args.extend(["--solver", "nearest"]);
            }
            args.extend(straight);
            refused(&args);
            assert!(
                !out.exists(),
                "{input} {compensation}: a program was written"
            );
        }
    }
    let (ok, _, err) = cutroute(&["convert", &own_route, &out_s]);
    assert!(ok && out.exists(), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn path_solvers_pierce_at_the_sheet_border_overcut_and_tab_and_take_the_edge_pierce_time() {
    // test1's 2000 × 1000 sheet (less its parts lying in their holes, refused with a kerf).
    let file = test1_without_parts_in_their_holes("path-edge-pierces");
    for solver in ["sccp", "aoe"] {
        let mut args = vec![
            "solve",
            &file,
            "--solver",
            solver,
            "--json",
            "--edge-pierce",
            "--edge-pierce-time",
            "2",
            "--overcut",
            "1.5",
            "--tabs",
            "2:1.5",
        ];
        args.extend(PLASMA);
        let report = json(&args);
        let paths = report["route"]["paths"].as_array().expect("paths");
        // A pierce per path and one after each tab's gap.
        let tabs: usize = paths
            .iter()
            .filter_map(|p| p.get("tabs"))
            .map(|t| t.as_array().unwrap().len())
            .sum();
        assert!(tabs > 0, "{solver}");
        assert_eq!(
            report["pierces"].as_u64().unwrap() as usize,
            paths.len() + tabs,
            "{solver}"
        );
        let edge: Vec<&Value> = paths
            .iter()
            .filter(|p| p.get("edge_pierce").is_some())
            .collect();
        assert_eq!(
            report["edge_pierces"].as_u64().unwrap() as usize,
            edge.len(),
            "{solver}"
        );
        // Whether a path starts within the edge reach of the border depends on the solver's
        // route (its run under load): the geometry tests pin edge pierces down; here every one
        // made is checked.
        for path in &edge {
            let (x, y) = point(&path["pierce"]);
            let to_border = x
                .abs()
                .min((x - 2000.0).abs())
                .min(y.abs())
                .min((y - 1000.0).abs());
            assert!(
                to_border < 1e-6,
                "{solver}: edge pierce ({x}, {y}) off the border"
            );
        }
        assert!(paths.iter().any(|p| p.get("overcut").is_some()), "{solver}");
        // Time: cut at 10 mm/s, idle at 500 mm/s, 7 s a pierce in the sheet, 2 s at its edge.
        let (cut, idle) = (
            report["cut_length"].as_f64().unwrap(),
            report["idle_length"].as_f64().unwrap(),
        );
        let pierces = report["pierces"].as_u64().unwrap() as f64;
        let n = edge.len() as f64;
        let expected = cut / 10.0 + idle / 500.0 + 7.0 * (pierces - n) + 2.0 * n;
        let time = report["time_s"].as_f64().unwrap();
        assert!(
            (time - expected).abs() < 1e-6 * expected,
            "{solver}: {time} vs {expected}"
        );
    }
}
