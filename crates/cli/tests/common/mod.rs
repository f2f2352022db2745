//! Shared helpers of the CLI tests: the real data files (missing ones fail loudly) and the
//! binary run as users run it.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

use serde_json::Value;

/// A file under `data/`; panics naming the file when it is missing.
pub fn data(relative: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    assert!(path.exists(), "missing test file {}", path.display());
    path
}

/// Runs `cutroute ARGS`: (success, stdout, stderr).
pub fn cutroute(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(args)
        .output()
        .expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// Runs `cutroute ARGS`, which must succeed and print one JSON value.
pub fn json(args: &[&str]) -> Value {
    let (ok, stdout, stderr) = cutroute(args);
    assert!(ok, "cutroute {args:?} failed: {stderr}");
    serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("not JSON ({e}): {stdout}"))
}
