//! G-code inputs: `G41 D<n>` programs read with `--compensation-radius`, and other CAM
//! programs' styles read as their pierces and cuts.

mod common;

use common::{cutroute, data, json};

#[test]
fn a_g41_register_program_reads_with_the_compensation_radius() {
    let file = data("nests/dbs-json/E1X_6_01.dbs.json");
    let file = file.to_str().unwrap();
    let leads = [
        "--kerf",
        "2",
        "--pierce-clearance",
        "3",
        "--lead-in",
        "line",
        "--lead-out",
        "line",
    ];
    let out = std::env::temp_dir().join(format!("cutroute-g41-register-{}.nc", std::process::id()));
    let out_s = out.to_str().unwrap();
    let mut args = vec![
        "convert",
        file,
        out_s,
        "--solver",
        "nearest",
        "--kerf-compensation",
        "g41:1",
    ];
    args.extend(leads);
    let (ok, _, err) = cutroute(&args);
    assert!(ok, "{err}");
    let program = std::fs::read_to_string(&out).unwrap();
    assert!(program.contains("G41 D1"));
    // Without the radius: refused, naming the line and the flag that gives it.
    let (ok, _, err) = cutroute(&["inspect", out_s, "--json"]);
    assert!(!ok);
    assert!(
        err.contains("--compensation-radius") && err.contains("line"),
        "{err}"
    );
    let read = json(&["inspect", out_s, "--json", "--compensation-radius", "1"]);
    let mut solve = vec!["solve", file, "--solver", "nearest", "--json"];
    solve.extend(leads);
    let solved = json(&solve);
    assert_eq!(read["route_pierces"], solved["pierces"]);
    let (cut, expected) = (
        read["route_cut_length"].as_f64().unwrap(),
        solved["cut_length"].as_f64().unwrap(),
    );
    assert!((cut - expected).abs() < 1e-2, "{cut} vs {expected}");
    // `solve` of the program takes the radius too.
    let (ok, _, err) = cutroute(&[
        "solve",
        out_s,
        "--solver",
        "nearest",
        "--compensation-radius",
        "1",
    ]);
    assert!(ok, "{err}");
    // A nest is not a program: the flag changes nothing there.
    let plain = json(&["inspect", file, "--json"]);
    let flagged = json(&["inspect", file, "--json", "--compensation-radius", "1"]);
    assert_eq!(plain, flagged);
    let _ = std::fs::remove_file(&out);
}

#[test]
fn third_party_programs_inspect_as_their_pierces_and_cuts() {
    use std::f64::consts::PI;
    let cases = [
        (
            "gcode-samples/dxf2gcode-plasma.ngc",
            2,
            300.0 + 20.0 * PI,
            2,
        ),
        ("gcode-samples/sheetcam-plasma.tap", 2, 120.0 + 30.0 * PI, 2),
        ("gcode-samples/lightburn-grbl.gc", 2, 108.0, 2),
    ];
    // (inkscape-gcodetools.ngc is left out: its torch stays on through the rapid between its
    // two paths, which the nest's route can only show as a cut link.)
    for (file, pierces, cut, contours) in cases {
        let v = json(&["inspect", data(file).to_str().unwrap(), "--json"]);
        assert_eq!(v["route_pierces"], pierces, "{file}");
        let read = v["route_cut_length"].as_f64().unwrap();
        assert!((read - cut).abs() < 1e-6, "{file}: {read} vs {cut}");
        assert_eq!(v["contours"], contours, "{file}");
        assert_eq!(v["route_problems"], serde_json::json!([]), "{file}");
    }
}

/// Contours drawn with runs of 2 µm lines (what real drawings carry) read as the contours they
/// are: a loop is a tool-on path that returns to its own start, not a step that ends near an
/// earlier step's start.
#[test]
fn micrometre_lines_close_no_loops_of_their_own() {
    let mut program = String::from("G21 G90\n");
    for k in 0..21 {
        let x0 = 30.0 * k as f64;
        program.push_str(&format!("G0 X{x0:.3} Y0.000\nM3\n"));
        let mut x = x0;
        for _ in 0..40 {
            x += 0.002;
            program.push_str(&format!("G1 X{x:.3} Y0.000 F1000\n"));
        }
        program.push_str(&format!("G1 X{:.3} Y0.000\n", x0 + 20.0));
        program.push_str(&format!("G1 X{:.3} Y20.000\n", x0 + 20.0));
        program.push_str(&format!("G1 X{x0:.3} Y20.000\n"));
        program.push_str(&format!("G1 X{x0:.3} Y0.006\n"));
        for y in ["0.004", "0.002", "0.000"] {
            program.push_str(&format!("G1 X{x0:.3} Y{y}\n"));
        }
        program.push_str("M5\n");
    }
    program.push_str("M2\n");
    let file = std::env::temp_dir().join(format!("cutroute-micro-{}.nc", std::process::id()));
    std::fs::write(&file, &program).unwrap();
    let v = json(&["inspect", file.to_str().unwrap(), "--json"]);
    let _ = std::fs::remove_file(&file);
    assert_eq!(v["contours"], 21, "{v}");
    assert_eq!(v["route_pierces"], 21);
}
