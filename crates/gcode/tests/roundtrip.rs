//! Real nests routed by the engine, written as G-code and read back: the same motion.

use std::path::PathBuf;

use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_gcode::{
    read_gcode, route_gcode, write_gcode, ArcOutput, DistanceMode, GcodeOptions, Program,
    ReadOptions,
};
use cutroute_geometry::{Nest, Point, Route, ToolMove, Toolpath};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

const NESTS: [&str; 5] = [
    "nests/dbs/nested.dbs",
    "nests/dbs/seven.dbs",
    "nests/dbs/test0.json.dbs",
    "nests/dbs-json/E1X_6_01.dbs.json",
    "nests/tflex/Nest02.tfnesting",
];

fn data(relative: &str) -> (String, Vec<u8>) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    let bytes = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("missing test file {}: {e}", path.display()));
    (relative.to_string(), bytes)
}

/// The nest of `relative` and a checked route over it by `solver`.
fn routed(relative: &str, solver: SolverKind, time_limit_s: f64) -> (Nest, Route) {
    let (name, bytes) = data(relative);
    let document = open_document(&name, &bytes).expect("opens");
    let Problem::Nest { nest, .. } = &document.problem else {
        panic!("{relative} is not a nest");
    };
    let request = JobRequest {
        job_id: 1,
        problem: document.problem.clone(),
        solver,
        params: SolverParams {
            time_limit_s,
            ..SolverParams::default()
        },
    };
    let mut job = start_job(&request).expect("starts");
    let route = run_to_end(job.as_mut(), &mut |_| {})
        .route()
        .cloned()
        .expect("a route");
    route.validate(nest, 1e-6 * 10_000.0).expect("valid route");
    (nest.clone(), route)
}

fn pierce_points(path: &Toolpath) -> Vec<Point> {
    path.moves
        .iter()
        .filter_map(|m| match m {
            ToolMove::Pierce { at, .. } => Some(*at),
            _ => None,
        })
        .collect()
}

/// The program read back moves as the toolpath does, within `tolerance` mm for each total.
fn assert_same_motion(path: &Toolpath, program: &Program, tolerance: f64, what: &str) {
    let (idle, cut) = (program.idle_length(), program.cut_length());
    assert!(
        (idle - path.idle_length()).abs() <= tolerance,
        "{what}: idle {idle} vs {}",
        path.idle_length()
    );
    assert!(
        (cut - path.cut_length()).abs() <= tolerance,
        "{what}: cut {cut} vs {}",
        path.cut_length()
    );
    let expected = pierce_points(path);
    let read = program.pierce_points();
    assert_eq!(read.len(), expected.len(), "{what}: pierces");
    for (k, (a, b)) in read.iter().zip(&expected).enumerate() {
        assert!(
            a.distance(*b) <= 1e-3,
            "{what}: pierce {k} at {a:?}, expected {b:?}"
        );
    }
    assert!(
        program.end.distance(path.end()) <= 1e-3,
        "{what}: ends at {:?}, expected {:?}",
        program.end,
        path.end()
    );
}

fn arc_cut_count(path: &Toolpath) -> usize {
    path.moves
        .iter()
        .filter(|m| matches!(m, ToolMove::Cut { span, .. } if !span.is_line()))
        .count()
}

#[test]
fn nearest_neighbour_routes_survive_every_output_mode() {
    let mut arcs_seen = 0;
    for relative in NESTS {
        let (nest, route) = routed(relative, SolverKind::NearestNeighbour, 10.0);
        let path = Toolpath::new(&route, &nest).unwrap();
        arcs_seen += arc_cut_count(&path);
        let read = ReadOptions {
            start: path.start,
            ..ReadOptions::default()
        };
        for distance_mode in [DistanceMode::Absolute, DistanceMode::Incremental] {
            for arcs in [ArcOutput::CentreOffsets, ArcOutput::Radius] {
                let options = GcodeOptions {
                    distance_mode,
                    arcs,
                    decimals: 6,
                    line_numbers: true,
                    ..GcodeOptions::default()
                };
                let what = format!("{relative} {distance_mode:?} {arcs:?}");
                let text = route_gcode(&nest, &route, &options).unwrap();
                let program = read_gcode(&text, &read).unwrap_or_else(|e| panic!("{what}: {e}"));
                assert_same_motion(&path, &program, 1e-3, &what);
                // The default three decimals: each written point moves by at most 0.0007 mm.
                let coarse = GcodeOptions {
                    decimals: 3,
                    ..options
                };
                let text = route_gcode(&nest, &route, &coarse).unwrap();
                let program = read_gcode(&text, &read).unwrap_or_else(|e| panic!("{what}: {e}"));
                let tolerance = 2e-3 * path.moves.len() as f64;
                assert_same_motion(&path, &program, tolerance, &format!("{what} 3 decimals"));
            }
        }
    }
    assert!(
        arcs_seen > 100,
        "the nests must exercise arcs ({arcs_seen})"
    );
}

#[test]
fn ccp_routes_round_trip() {
    for relative in ["nests/dbs-json/E1X_6_01.dbs.json", "nests/dbs/nested.dbs"] {
        let (nest, route) = routed(relative, SolverKind::Ccp, 2.0);
        let path = Toolpath::new(&route, &nest).unwrap();
        let options = GcodeOptions {
            decimals: 6,
            ..GcodeOptions::default()
        };
        let text = route_gcode(&nest, &route, &options).unwrap();
        let read = ReadOptions {
            start: path.start,
            ..ReadOptions::default()
        };
        let program = read_gcode(&text, &read).unwrap();
        assert_same_motion(&path, &program, 1e-3, relative);
        // Every step is named in a comment before its pierce.
        let first = route.steps[0].contour;
        let name = &nest.parts[first.part].name;
        assert!(
            text.contains(&format!("({first} [{name}])")),
            "{first} named"
        );
        // The read-back toolpath is continuous and pierces where the route does.
        let back = program.toolpath();
        assert_eq!(pierce_points(&back).len(), route.steps.len());
        let mut at = back.start;
        for m in &back.moves {
            assert!(m.point_at(0.0).distance(at) < 1e-9);
            at = m.end();
        }
    }
}

#[test]
fn flattened_arcs_stay_within_the_tolerance() {
    let (nest, route) = routed("nests/dbs/nested.dbs", SolverKind::NearestNeighbour, 10.0);
    let path = Toolpath::new(&route, &nest).unwrap();
    let tolerance_mm = 0.01;
    let options = GcodeOptions {
        arcs: ArcOutput::Lines { tolerance_mm },
        decimals: 6,
        ..GcodeOptions::default()
    };
    let text = write_gcode(&path, &options).unwrap();
    assert!(!text.contains("G02") && !text.contains("G03"));
    let read = ReadOptions {
        start: path.start,
        ..ReadOptions::default()
    };
    let program = read_gcode(&text, &read).unwrap();
    assert_eq!(program.pierce_count(), path.pierce_count());
    assert!(program.end.distance(path.end()) < 1e-3);
    // Chords are shorter than their arcs, but not by much.
    let (chords, arcs) = (program.cut_length(), path.cut_length());
    assert!(
        chords <= arcs + 1e-3 && chords > 0.995 * arcs,
        "{chords} vs {arcs}"
    );
    // Every chord end lies on the contour it cuts (within rounding).
    let cut_points: Vec<Point> = program
        .toolpath()
        .moves
        .iter()
        .filter_map(|m| match m {
            ToolMove::Cut { span, .. } => Some(span.end),
            _ => None,
        })
        .collect();
    let contours: Vec<_> = nest.parts.iter().flat_map(|p| &p.contours).collect();
    for p in cut_points.iter().step_by(7) {
        let d = contours
            .iter()
            .filter_map(|c| c.nearest_point(*p))
            .map(|n| n.point.distance(*p))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-4, "chord end {p:?} is {d} mm off the contours");
    }
}
