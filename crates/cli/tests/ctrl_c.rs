//! Ctrl-C keeps the best route for every solver: the first SIGINT stops the solver as its
//! limit reached then would, and the CLI prints the best route so far, checked again here by
//! the independent checkers; before any route exists, the route a very short limit gives.

#![cfg(target_os = "linux")]

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{data, SOLVERS};
use cutroute_protocol::Problem;
use serde_json::Value;

/// Longest a stopped run may take to end (a debug build on a loaded machine; the CLI waits at
/// most a second for the stopped solver's route).
const AFTER_CTRL_C: Duration = Duration::from_secs(20);

/// Whether `pid` has installed its SIGINT handler (Linux: bit 2 of `SigCgt`), so a SIGINT is
/// the Ctrl-C the CLI handles and not the default end of a process still starting.
fn catches_sigint(pid: u32) -> bool {
    let Ok(status) = std::fs::read_to_string(format!("/proc/{pid}/status")) else {
        return false;
    };
    status
        .lines()
        .find_map(|l| l.strip_prefix("SigCgt:"))
        .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
        .is_some_and(|mask| mask & 0b10 != 0)
}

/// Spawns `cutroute ARGS`, sends SIGINT `after` its handler is installed, and returns its exit
/// code, stdout, stderr and whether the SIGINT was sent (false: the run had ended before).
fn interrupted(args: &[&str], after: Duration) -> (Option<i32>, String, String, bool) {
    let mut child: Child = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    let pid = child.id();
    let waiting = Instant::now();
    while !catches_sigint(pid) {
        assert!(
            waiting.elapsed() < Duration::from_secs(20),
            "{args:?}: no SIGINT handler after 20 s"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
    std::thread::sleep(after);
    // (A run that has ended is not signalled: its pid may be gone.)
    let ended = child.try_wait().expect("waits").is_some();
    let sent = !ended
        && Command::new("kill")
            .args(["-INT", &pid.to_string()])
            .status()
            .expect("kill runs")
            .success();
    let stopped = Instant::now();
    let out = child.wait_with_output().expect("waits");
    assert!(
        stopped.elapsed() < AFTER_CTRL_C,
        "{args:?}: {:.1} s after Ctrl-C",
        stopped.elapsed().as_secs_f64()
    );
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
        sent,
    )
}

/// The route of a `solve --json` report on `input`, checked by the geometry's checkers (path
/// routes may cut a piece of contour twice, nothing else).
fn assert_checked_route(what: &str, input: &Path, report: &Value) {
    let bytes = std::fs::read(input).unwrap();
    let document = cutroute_engine::open_document("input", &bytes).unwrap();
    let Problem::Nest { nest, start, .. } = &document.problem else {
        panic!("a nest");
    };
    common::assert_report_route(what, nest, *start, report);
}

fn solve_interrupted(solver: &str, after: Duration) {
    solve_interrupted_on(&data("nests/dbs/nested.dbs"), solver, after);
}

fn solve_interrupted_on(nest: &Path, solver: &str, after: Duration) {
    let args = [
        "solve",
        nest.to_str().unwrap(),
        "--solver",
        solver,
        "--time-limit",
        "inf",
        "--json",
    ];
    let what = format!("{solver}, Ctrl-C after {after:?}");
    let (code, stdout, stderr, sent) = interrupted(&args, after);
    assert_eq!(code, Some(0), "{what}: {stderr}");
    let report: Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("{what}: not JSON ({e}): {stdout}"));
    if sent {
        // (Unless the SIGINT came as the solver ended by itself.)
        assert!(
            report["stopped"] == "Ctrl-C" || report["stopped"].is_null(),
            "{what}: {report}"
        );
    }
    assert_checked_route(&what, nest, &report);
}

#[test]
fn ctrl_c_after_50_ms_gives_every_solver_s_first_route() {
    for solver in SOLVERS {
        solve_interrupted(solver, Duration::from_millis(50));
    }
}

#[test]
fn ctrl_c_after_1_s_keeps_every_solver_s_best_route() {
    for solver in SOLVERS {
        solve_interrupted(solver, Duration::from_secs(1));
    }
}

/// On a generated nest of thousands of contours, Ctrl-C comes before the path solvers and
/// chain have a route of their own: each answers with the first route (the one a very short
/// limit gives), checked. (The solvers of a dense cost matrix, heuristic, exact and discrete,
/// refuse a nest this big before they start: a refusal, not a run to stop.)
#[test]
fn ctrl_c_on_a_big_nest_gives_every_solver_a_checked_route() {
    let dir = std::env::temp_dir().join(format!("cutroute-ctrl-c-big-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let nest = dir.join("big.json");
    let out = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(["generate", "--contours", "5000", "--seed", "1", "--out"])
        .arg(&nest)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dense = ["heuristic", "exact", "discrete"];
    for solver in SOLVERS.iter().filter(|s| !dense.contains(s)) {
        solve_interrupted_on(&nest, solver, Duration::from_millis(50));
    }
}

/// `convert` stopped by Ctrl-C still writes the program of the best route so far.
#[test]
fn a_convert_stopped_by_ctrl_c_writes_its_program() {
    let nest = data("nests/dbs/nested.dbs");
    let dir = std::env::temp_dir().join(format!("cutroute-ctrl-c-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for solver in ["gsccp", "exact"] {
        let out = dir.join(format!("{solver}.nc"));
        let _ = std::fs::remove_file(&out);
        let args = [
            "convert",
            nest.to_str().unwrap(),
            out.to_str().unwrap(),
            "--solver",
            solver,
            "--time-limit",
            "inf",
        ];
        let (code, _, stderr, _) = interrupted(&args, Duration::from_secs(1));
        assert_eq!(code, Some(0), "convert --solver {solver}: {stderr}");
        let program = std::fs::read_to_string(&out).unwrap_or_default();
        assert!(
            program.contains("G1") || program.contains("G01"),
            "convert --solver {solver} wrote no cutting moves: {program:.200}"
        );
    }
}
