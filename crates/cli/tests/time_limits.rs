//! Time limits are promises (issues #14, #15): every solver, on a big generated nest and on a
//! PCGTSP library instance, returns within its limit + 1 s of wall time. A timed test, allowed
//! here because it tests a promise, not a speed. Reading the file is not the solver's time:
//! the allowance adds the wall of `inspect` on the same file.

mod common;

use std::process::Command;
use std::time::Instant;

use common::data;

/// Wall seconds and exit code of `cutroute ARGS`.
fn timed(args: &[&str]) -> (f64, Option<i32>, String) {
    let started = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(args)
        .output()
        .expect("runs");
    (
        started.elapsed().as_secs_f64(),
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn assert_promise_kept(file: &str, solvers: &[&str]) {
    let (read, code, stderr) = timed(&["inspect", file]);
    assert_eq!(code, Some(0), "{stderr}");
    for solver in solvers {
        let (wall, code, stderr) = timed(&[
            "solve",
            file,
            "--solver",
            solver,
            "--time-limit",
            "1",
            "--json",
        ]);
        // 0: a checked result; 1: a clean "no route before the limit"; 3: no tour.
        assert!(
            matches!(code, Some(0 | 1 | 3)),
            "{solver}: exit {code:?}: {stderr}"
        );
        assert!(
            wall <= 2.0 + read,
            "{solver} on {file}: {wall:.2} s on a 1 s limit (reading takes {read:.2} s)"
        );
    }
}

#[test]
fn every_solver_returns_within_its_limit_plus_one_second() {
    let dir = std::env::temp_dir().join(format!("cutroute-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let nest = dir.join("big.json");
    let nest = nest.to_str().unwrap();
    let (_, code, stderr) = timed(&["generate", "--contours", "10000", "--out", nest]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_promise_kept(nest, &common::SOLVERS);
    let instance = data("pcgtsp/pcgtsplib/kro124p.1.pcglns");
    assert_promise_kept(instance.to_str().unwrap(), &["heuristic", "exact"]);
}
