//! SVG nests, T-FLEX sheet choice, machine profiles and G-code presets on the command line.

mod common;

use common::{cutroute, data, json};
use cutroute_gcode::{read_gcode, GcodePreset, ReadOptions};

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cutroute-inputs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn s(path: &std::path::Path) -> &str {
    path.to_str().unwrap()
}

/// `convert` writes the project's SVG of a real nest, and `inspect` reads it back with the same
/// contours: the SVG reader proved on real data through the CLI.
#[test]
fn converted_svg_reads_back_with_the_same_contours() {
    let nest = data("nests/dbs/nested.dbs");
    let svg = temp("nested.svg");
    let (ok, _, stderr) = cutroute(&["convert", s(&nest), s(&svg)]);
    assert!(ok, "{stderr}");
    let before = json(&["inspect", s(&nest), "--json"]);
    let after = json(&["inspect", s(&svg), "--json"]);
    assert_eq!(after["format"], "SVG");
    assert_eq!(after["contours"], before["contours"]);
    assert_eq!(after["parts"], before["parts"]);
    // The SVG routes like the original: one pierce per contour.
    let pierces =
        |file: &str| json(&["solve", file, "--solver", "nearest", "--json"])["pierces"].clone();
    assert_eq!(pierces(s(&svg)), pierces(s(&nest)));
}

#[test]
fn inspect_lists_the_sheets_and_sheet_picks_one() {
    let project = data("nests/tflex-multi/two-sheets.tfnesting");
    let first = json(&["inspect", s(&project), "--json"]);
    assert_eq!(first["sheets"].as_array().unwrap().len(), 2);
    assert_eq!(first["sheet"], 1);
    let second = json(&["inspect", s(&project), "--sheet", "2", "--json"]);
    assert_eq!(second["sheet"], 2);
    assert!(second["parts"].as_u64() < first["parts"].as_u64());
    let solved = json(&[
        "solve",
        s(&project),
        "--sheet",
        "2",
        "--solver",
        "nearest",
        "--json",
    ]);
    assert!(solved["pierces"].as_u64().unwrap() >= 1);
    let (ok, _, stderr) = cutroute(&["inspect", s(&project), "--sheet", "3"]);
    assert!(!ok && stderr.contains("no sheet 3"), "{stderr}");
    let (ok, _, stderr) = cutroute(&["inspect", s(&project), "--sheet", "0"]);
    assert!(!ok && stderr.contains("--sheet"), "{stderr}");
}

#[test]
fn a_profile_sets_the_machine_and_flags_override_it() {
    let profile = data("profiles/kometa-2p32m.json");
    let nest = data("nests/dbs/nested.dbs");
    let report = json(&[
        "solve",
        s(&nest),
        "--solver",
        "nearest",
        "--profile",
        s(&profile),
        "--json",
    ]);
    assert_eq!(report["machine"]["idle_speed"], 100.0);
    assert_eq!(report["machine"]["cut_speed"], 7.666);
    let report = json(&[
        "solve",
        s(&nest),
        "--solver",
        "nearest",
        "--profile",
        s(&profile),
        "--speeds",
        "200,5,1",
        "--json",
    ]);
    assert_eq!(report["machine"]["idle_speed"], 200.0);
    assert_eq!(report["machine"]["cut_price_per_metre"], 1.0);

    // The profile's preset writes the Kometa dialect, its feed from the profile's speed.
    let program = temp("kometa.nc");
    let (ok, _, stderr) = cutroute(&[
        "convert",
        s(&nest),
        s(&program),
        "--solver",
        "nearest",
        "--profile",
        s(&profile),
    ]);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&program).unwrap();
    assert!(
        text.contains("M71 T1") && text.contains("G91") && text.contains("F460"),
        "{text}"
    );
    let read = read_gcode(&text, &GcodePreset::Kometa2p32m.read_options()).unwrap();
    assert!(read.pierce_count() > 0);

    let broken = temp("broken.json");
    std::fs::write(&broken, r#"{"name": "x", "machine": {"idle_speed": 1}}"#).unwrap();
    let (ok, _, stderr) = cutroute(&["solve", s(&nest), "--profile", s(&broken)]);
    assert!(
        !ok && stderr.contains("broken.json") && stderr.contains("line"),
        "{stderr}"
    );
}

#[test]
fn inspect_reads_a_program_in_its_presets_dialect() {
    let nest = data("nests/dbs/nested.dbs");
    let mut pierces = Vec::new();
    for preset in ["generic", "kometa-2p32m"] {
        let program = temp(&format!("inspect-{preset}.nc"));
        let (ok, _, stderr) = cutroute(&[
            "convert",
            s(&nest),
            s(&program),
            "--solver",
            "nearest",
            "--preset",
            preset,
        ]);
        assert!(ok, "{stderr}");
        let report = json(&["inspect", s(&program), "--json", "--preset", preset]);
        assert_eq!(report["route_problems"], serde_json::json!([]), "{preset}");
        pierces.push(report["route_pierces"].as_u64().unwrap());
    }
    assert!(pierces[0] > 0);
    assert_eq!(pierces[0], pierces[1], "the same route in both dialects");
}

#[test]
fn presets_write_their_dialect_and_flags_override() {
    let nest = data("nests/dbs/nested.dbs");
    let program = temp("fanuc.nc");
    let (ok, _, stderr) = cutroute(&[
        "convert",
        s(&nest),
        s(&program),
        "--solver",
        "nearest",
        "--preset",
        "fanuc",
        "--dwell",
        "1.5",
    ]);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&program).unwrap();
    assert!(
        text.contains("G04 P1500") && text.contains("N10 "),
        "{text}"
    );
    let read = ReadOptions {
        dwell_p_milliseconds: true,
        ..ReadOptions::default()
    };
    let back = read_gcode(&text, &read).unwrap();
    assert!((back.dwell_time() - 1.5 * back.pierce_count() as f64).abs() < 1e-9);
    let (ok, _, stderr) = cutroute(&["convert", s(&nest), s(&program), "--preset", "haas"]);
    assert!(!ok && stderr.contains("grbl-laser"), "{stderr}");
}
