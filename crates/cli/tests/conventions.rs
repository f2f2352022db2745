//! Shell conventions: `-` for standard input and output, `--out` for the report, files written
//! whole, the enumerated choices refused by the parser.

mod common;

use std::io::Write;
use std::process::{Command, Stdio};

use common::{cutroute, data, json};
use serde_json::Value;

/// Runs `cutroute ARGS` with `input` on standard input: (success, stdout bytes, stderr).
fn piped(args: &[&str], input: &[u8]) -> (bool, Vec<u8>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(input).unwrap();
    drop(stdin);
    let out = child.wait_with_output().unwrap();
    (
        out.status.success(),
        out.stdout,
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cutroute-conventions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn standard_input_reads_like_the_file() {
    for file in [
        "nests/dbs/nested.dbs",
        "nests/dbs-json/E1X_6_01.dbs.json",
        "nests/dxf/propeller.dxf",
        "nests/tflex/Nest01.tfnesting",
    ] {
        let path = data(file);
        let bytes = std::fs::read(&path).unwrap();
        let (ok, stdout, stderr) = piped(&["inspect", "-", "--json"], &bytes);
        assert!(ok, "{file}: {stderr}");
        let from_stdin: Value = serde_json::from_slice(&stdout).unwrap();
        assert_eq!(
            from_stdin,
            json(&["inspect", path.to_str().unwrap(), "--json"]),
            "{file}"
        );
    }
    // A solve from standard input is the solve of the file (nearest is deterministic).
    let path = data("nests/dbs/seven.dbs");
    let (ok, stdout, stderr) = piped(
        &["solve", "-", "--solver", "nearest", "--json"],
        &std::fs::read(&path).unwrap(),
    );
    assert!(ok, "{stderr}");
    let mut from_stdin: Value = serde_json::from_slice(&stdout).unwrap();
    let mut from_file = json(&[
        "solve",
        path.to_str().unwrap(),
        "--solver",
        "nearest",
        "--json",
    ]);
    for report in [&mut from_stdin, &mut from_file] {
        // The run's own timings differ from run to run.
        for timing in ["elapsed_s", "read_s"] {
            report.as_object_mut().unwrap().remove(timing);
        }
    }
    assert_eq!(from_stdin, from_file);
    // Broken input on the stream is located like a broken file.
    let (ok, _, stderr) = piped(&["inspect", "-"], b"{\"results\": [1, 2,");
    assert!(!ok);
    assert!(stderr.contains("stdin"), "{stderr}");
}

#[test]
fn standard_output_writes_what_the_file_gets() {
    let nest = data("nests/dbs/seven.dbs");
    let nest = nest.to_str().unwrap();
    for (to, extension) in [("svg", "svg"), ("dbs", "dbs"), ("json", "dbs.json")] {
        let file = scratch(&format!("seven.{extension}"));
        let (ok, _, stderr) = cutroute(&["convert", nest, file.to_str().unwrap()]);
        assert!(ok, "{stderr}");
        let (ok, stdout, stderr) = piped(&["convert", nest, "-", "--to", to], b"");
        assert!(ok, "{to}: {stderr}");
        assert_eq!(stdout, std::fs::read(&file).unwrap(), "{to}");
    }
    // G-code through a pipe: the same program as the file (nearest is deterministic).
    let file = scratch("seven.nc");
    let args = ["--solver", "nearest"];
    let (ok, _, stderr) =
        cutroute(&[&["convert", nest, file.to_str().unwrap()][..], &args].concat());
    assert!(ok, "{stderr}");
    let (ok, stdout, stderr) = piped(
        &[&["convert", nest, "-", "--to", "gcode"][..], &args].concat(),
        b"",
    );
    assert!(ok, "{stderr}");
    assert_eq!(stdout, std::fs::read(&file).unwrap());
    // Without --to there is no extension to go by.
    let (ok, _, stderr) = piped(&["convert", nest, "-"], b"");
    assert!(!ok && stderr.contains("needs --to"), "{stderr}");
    // generate --out -.
    let file = scratch("generated.json");
    let (ok, _, stderr) = cutroute(&[
        "generate",
        "--contours",
        "40",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let (ok, stdout, _) = piped(&["generate", "--contours", "40", "--out", "-"], b"");
    assert!(ok);
    assert_eq!(stdout, std::fs::read(&file).unwrap());
}

#[test]
fn solve_writes_its_report_to_out() {
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    let report = scratch("report.json");
    let (ok, stdout, stderr) = cutroute(&[
        "solve",
        nest.to_str().unwrap(),
        "--solver",
        "nearest",
        "--json",
        "--out",
        report.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert_eq!(
        stdout, "",
        "the report goes to the file, not to standard output"
    );
    let mut written: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let mut printed = json(&[
        "solve",
        nest.to_str().unwrap(),
        "--solver",
        "nearest",
        "--json",
    ]);
    for r in [&mut written, &mut printed] {
        for timing in ["elapsed_s", "read_s"] {
            r.as_object_mut().unwrap().remove(timing);
        }
    }
    assert_eq!(written, printed);
    // Text reports too; a failing solve leaves the old report in place.
    let (ok, _, _) = cutroute(&[
        "solve",
        nest.to_str().unwrap(),
        "--solver",
        "nearest",
        "--out",
        report.to_str().unwrap(),
    ]);
    assert!(ok);
    let text = std::fs::read_to_string(&report).unwrap();
    assert!(
        text.lines()
            .any(|l| l.trim_start().starts_with("idle_length:")),
        "{text}"
    );
    let broken = scratch("broken.json");
    std::fs::write(&broken, "{").unwrap();
    let (ok, _, _) = cutroute(&[
        "solve",
        broken.to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_eq!(std::fs::read_to_string(&report).unwrap(), text);
}

/// `convert` takes the machine options of `solve`: the pierce time of `--speeds` is the dwell
/// of every pierce in the program.
#[test]
fn convert_takes_the_machine_options_of_solve() {
    let nest = data("nests/dbs/seven.dbs");
    for (speeds, dwell) in [(None, "G04 P7.000"), (Some("500,10,3"), "G04 P3.000")] {
        let mut args = vec!["convert", nest.to_str().unwrap(), "-", "--to", "gcode"];
        args.extend(["--solver", "nearest"]);
        if let Some(speeds) = speeds {
            args.extend(["--speeds", speeds]);
        }
        let (ok, stdout, stderr) = piped(&args, b"");
        assert!(ok, "{stderr}");
        let program = String::from_utf8(stdout).unwrap();
        let dwells: Vec<&str> = program.lines().filter(|l| l.starts_with("G04")).collect();
        assert_eq!(dwells.len(), 50, "one dwell per pierce of seven.dbs");
        assert!(dwells.iter().all(|l| *l == dwell), "{speeds:?}: {dwells:?}");
    }
}

#[test]
fn enumerated_choices_are_checked_by_the_parser() {
    let nest = data("nests/dbs/seven.dbs");
    for args in [
        vec!["convert", nest.to_str().unwrap(), "x.out", "--to", "pdf"],
        vec![
            "convert",
            nest.to_str().unwrap(),
            "x.nc",
            "--arcs",
            "spline",
        ],
        vec!["solve", nest.to_str().unwrap(), "--solver", "fastest"],
    ] {
        let (ok, _, stderr) = cutroute(&args);
        assert!(!ok);
        assert!(stderr.contains("possible values"), "{args:?}: {stderr}");
    }
}
