//! Shared helpers of the CLI tests: the real data files (missing ones fail loudly) and the
//! binary run as users run it.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

use cutroute_geometry::{
    ContourRef, CutStep, Entry, Nest, PathRoute, PathRouteError, Point, Route,
};
use serde_json::Value;

/// Every `--solver` of `solve`, as a user names them.
pub const SOLVERS: [&str; 9] = [
    "nearest",
    "ccp",
    "heuristic",
    "exact",
    "discrete",
    "chain",
    "sccp",
    "gsccp",
    "aoe",
];

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

/// The route of a `solve --json` report on `nest` (from `start`), checked by the geometry's
/// own checkers, independently of the CLI: a path route may cut a piece of contour twice,
/// nothing else; a contour route must be valid. `what` names the run in the panic.
pub fn assert_report_route(what: &str, nest: &Nest, start: Point, report: &Value) {
    let tolerance = nest.check_tolerance();
    if report.get("objective").is_some() {
        let route: PathRoute = serde_json::from_value(report["route"].clone())
            .unwrap_or_else(|e| panic!("{what}: no path route ({e}): {report}"));
        let real: Vec<_> = route
            .problems(nest, tolerance)
            .into_iter()
            .filter(|p| !matches!(p, PathRouteError::Overlap { .. }))
            .collect();
        assert!(real.is_empty(), "{what}: {real:?}");
        return;
    }
    let point = |v: &Value| Point::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
    let steps = report["route"]
        .as_array()
        .unwrap_or_else(|| panic!("{what}: no route: {report}"))
        .iter()
        .map(|s| CutStep {
            contour: ContourRef {
                part: s["contour"][0].as_u64().unwrap() as usize,
                contour: s["contour"][1].as_u64().unwrap() as usize,
            },
            pierce_point: point(&s["pierce"]),
            entry: match s.get("link").and_then(Value::as_array) {
                Some(corners) => Entry::Link(corners.iter().map(point).collect()),
                None => Entry::Pierce,
            },
            leads: None,
        })
        .collect();
    let route = Route {
        start,
        steps,
        finish: None,
    };
    route
        .validate(nest, tolerance)
        .unwrap_or_else(|e| panic!("{what}: invalid route: {e}"));
}
