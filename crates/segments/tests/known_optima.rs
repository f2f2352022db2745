//! Segment cutting on plans whose optimum is known, and on every real nest: every route passes
//! the independent check of `PathRoute::problems`.

use std::sync::atomic::AtomicBool;
use std::time::Duration;

use cutroute_geometry::{
    Contour, ContourRef, MachineParameters, Nest, Part, PathRoute, PathRouteError, Point, Vertex,
};
use cutroute_protocol::Problem;
use cutroute_segments::{
    rectangle_grid, solve_gsccp, solve_sccp, Ensemble, EnsembleKind, GsccpOptions, Objective,
    SccpOptions,
};

const TOL: f64 = 1e-7;

fn sccp(ensemble: &Ensemble, start: Point) -> PathRoute {
    let options = SccpOptions {
        start,
        time_limit: Duration::from_secs(2),
        ..SccpOptions::default()
    };
    solve_sccp(ensemble, None, &options, &AtomicBool::new(false))
        .unwrap()
        .route
}

fn overlap_length(problems: &[PathRouteError]) -> f64 {
    problems
        .iter()
        .map(|p| match p {
            PathRouteError::Overlap { length, .. } => *length,
            other => panic!("unexpected problem: {other}"),
        })
        .sum()
}

#[test]
fn a_row_of_touching_rectangles_cuts_each_common_edge_once_from_k_minus_one_pierces() {
    for k in 1..=7usize {
        let (w, h) = (50.0, 30.0);
        let nest = rectangle_grid(k, 1, w, h);
        // Common edges once: two long sides and k + 1 posts. The k − 1 inner posts end in
        // 2(k − 1) T-junctions of odd degree, so no cover by trails has fewer than k − 1.
        let chains = Ensemble::build(&nest, EnsembleKind::Chains, 1e-6).unwrap();
        let route = sccp(&chains, Point::new(-10.0, -10.0));
        assert_eq!(route.problems(&nest, TOL), vec![], "k = {k}");
        assert!((route.cut_length() - (2.0 * k as f64 * w + (k + 1) as f64 * h)).abs() < 1e-9);
        assert_eq!(route.pierce_count(), (k - 1).max(1), "k = {k}");
        // Standard cutting: every rectangle whole, each common edge twice.
        let standard = Ensemble::build(&nest, EnsembleKind::Standard, 1e-6).unwrap();
        let route = sccp(&standard, Point::new(-10.0, -10.0));
        assert_eq!(route.pierce_count(), k);
        assert!((route.cut_length() - k as f64 * 2.0 * (w + h)).abs() < 1e-9);
        // Each doubled edge is reported on both its contours.
        let problems = route.problems(&nest, TOL);
        let doubled = overlap_length(&problems);
        assert!(
            (doubled - 2.0 * (k - 1) as f64 * h).abs() < 1e-6,
            "k = {k}: {doubled}"
        );
        // Counted once per piece, that is the k − 1 common edges.
        let recut = cutroute_segments::recut_length(&problems, TOL);
        assert!(
            (recut - (k - 1) as f64 * h).abs() < 1e-6,
            "k = {k}: {recut}"
        );
        // Junctions: every plan edge one segment, still every common edge once.
        let junctions = Ensemble::build(&nest, EnsembleKind::Junctions, 1e-6).unwrap();
        let route = sccp(&junctions, Point::new(-10.0, -10.0));
        assert_eq!(route.problems(&nest, TOL), vec![], "k = {k}");
        assert!((route.cut_length() - (2.0 * k as f64 * w + (k + 1) as f64 * h)).abs() < 1e-9);
        assert_eq!(
            route.pierce_count(),
            // Two end arcs, k − 1 posts, k − 2 middle pieces on each long side.
            if k == 1 { 1 } else { 3 * k - 3 }
        );
    }
}

#[test]
fn a_grid_of_rectangles_is_cut_along_every_line_once_with_the_fewest_trails() {
    for (columns, rows) in [(2, 2), (3, 2), (3, 4), (5, 5), (8, 3)] {
        let (w, h) = (40.0, 25.0);
        let nest = rectangle_grid(columns, rows, w, h);
        let expected_cut =
            (rows + 1) as f64 * columns as f64 * w + (columns + 1) as f64 * rows as f64 * h;
        // Odd vertices: the T-junctions on the border, 2(columns − 1) + 2(rows − 1).
        let expected_pierces = (columns - 1) + (rows - 1);
        let options = GsccpOptions {
            sccp: SccpOptions {
                start: Point::new(-5.0, -5.0),
                time_limit: Duration::from_secs(2),
                ..SccpOptions::default()
            },
            ..GsccpOptions::default()
        };
        let result = solve_gsccp(&nest, &options, &AtomicBool::new(false)).unwrap();
        assert_eq!(result.best, Some(EnsembleKind::Chains), "{columns}×{rows}");
        assert_eq!(result.route.problems(&nest, TOL), vec![]);
        assert!((result.route.cut_length() - expected_cut).abs() < 1e-9);
        assert_eq!(result.route.pierce_count(), expected_pierces);
        let standard = &result.reports[0];
        assert_eq!(standard.kind, EnsembleKind::Standard);
        assert_eq!(standard.pierces, columns * rows);
        // Every inner line is a common edge, cut twice by standard cutting.
        let inner = (rows - 1) as f64 * columns as f64 * w + (columns - 1) as f64 * rows as f64 * h;
        assert!((standard.recut_length - inner).abs() < 1e-6, "{standard:?}");
        assert!((standard.cut_length - expected_cut - inner).abs() < 1e-6);
        for r in &result.reports {
            assert!(r.failure.is_none(), "{r:?}");
        }
    }
}

/// Clockwise rectangle.
fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x0, y0),
        Vertex::line(x0, y1),
        Vertex::line(x1, y1),
        Vertex::line(x1, y0),
    ])
}

#[test]
fn a_part_in_a_hole_in_a_part_is_cut_inside_out_by_every_ensemble() {
    let plate = Part {
        name: "plate".into(),
        contours: vec![
            rect(0.0, 0.0, 100.0, 100.0),
            rect(20.0, 20.0, 80.0, 80.0).reversed(),
        ],
    };
    let inner = Part {
        name: "inner".into(),
        contours: vec![rect(40.0, 40.0, 60.0, 60.0)],
    };
    // The inner part first in the file, and a start next to the plate's corner: a greedy
    // order would cut the plate first.
    let nest = Nest {
        sheet: None,
        parts: vec![plate, inner],
    };
    let (outer, hole, part) = (
        ContourRef {
            part: 0,
            contour: 0,
        },
        ContourRef {
            part: 0,
            contour: 1,
        },
        ContourRef {
            part: 1,
            contour: 0,
        },
    );
    for kind in EnsembleKind::ALL {
        let ensemble = Ensemble::build(&nest, kind, 1e-6).unwrap();
        assert_eq!(ensemble.segments.len(), 3);
        let index = |c: ContourRef| {
            ensemble
                .segments
                .iter()
                .position(|s| s.contours == vec![c])
                .unwrap()
        };
        let (o, h, p) = (index(outer), index(hole), index(part));
        for pair in [(p, h), (p, o), (h, o)] {
            assert!(ensemble.precedence.contains(&pair), "{kind:?}: {pair:?}");
        }
        let route = sccp(&ensemble, Point::new(-1.0, -1.0));
        assert_eq!(route.problems(&nest, TOL), vec![], "{kind:?}");
        // The part, then the hole, then the plate.
        let first_x: Vec<f64> = route.paths.iter().map(|p| p.pierce.x).collect();
        assert!(first_x[0] >= 40.0 && first_x[0] <= 60.0, "{first_x:?}");
        assert!(first_x[1] >= 20.0 && first_x[1] <= 80.0, "{first_x:?}");
        // The same paths in reverse fail the check.
        let mut reversed = route.clone();
        reversed.paths.reverse();
        let problems = reversed.problems(&nest, TOL);
        assert!(
            problems
                .iter()
                .any(|e| matches!(e, PathRouteError::PrecedenceViolated { inner, outer: o, .. } if *inner == part && *o == hole)),
            "{problems:?}"
        );
        // Idle: the distances between the nested squares are lower bounds, reached by
        // (40, 40) on the part, (40, 20) or (20, 40) on the hole, the plate straight below or
        // beside: 41√2 + 20 + 20.
        let optimum = 41.0 * 2f64.sqrt() + 40.0;
        assert!(
            (route.idle_length() - optimum).abs() < 1e-6,
            "{kind:?}: {}",
            route.idle_length()
        );
    }
}

#[test]
fn a_raised_cancel_flag_still_returns_a_valid_route() {
    let nest = rectangle_grid(6, 6, 10.0, 10.0);
    let ensemble = Ensemble::build(&nest, EnsembleKind::Junctions, 1e-6).unwrap();
    let solution = solve_sccp(
        &ensemble,
        None,
        &SccpOptions::default(),
        &AtomicBool::new(true),
    )
    .unwrap();
    assert!(solution.interrupted);
    assert_eq!(solution.route.problems(&nest, TOL), vec![]);
    assert!(solution.idle_length <= solution.initial_idle_length + 1e-9);
}

#[test]
fn the_objective_decides_between_ensembles() {
    // Free pierces: the many-pierce junction ensemble may compete; whichever objective is
    // chosen, the kept route is the best of all ensembles by that objective.
    let nest = rectangle_grid(4, 1, 50.0, 30.0);
    let cheap_pierces = MachineParameters {
        pierce_price: 0.0,
        pierce_time: 0.0,
        ..MachineParameters::default()
    };
    for objective in [Objective::Time, Objective::Cost] {
        let options = GsccpOptions {
            machine: cheap_pierces,
            objective,
            sccp: SccpOptions {
                time_limit: Duration::from_secs(1),
                ..SccpOptions::default()
            },
            ..GsccpOptions::default()
        };
        let result = solve_gsccp(&nest, &options, &AtomicBool::new(false)).unwrap();
        let value = |r: &cutroute_segments::EnsembleReport| match objective {
            Objective::Time => r.time_s,
            Objective::Cost => r.cost,
        };
        let best = result
            .reports
            .iter()
            .find(|r| Some(r.kind) == result.best)
            .unwrap();
        for r in &result.reports {
            assert!(value(best) <= value(r), "{objective:?}: {best:?} vs {r:?}");
        }
        let m = &options.machine;
        let chosen = match objective {
            Objective::Time => result.route.time(m),
            Objective::Cost => result.route.cost(m),
        };
        assert!((chosen - value(best)).abs() < 1e-9);
    }
}

/// Every nest file of the shared data, opened as the app and the CLI open it.
fn real_nests() -> Vec<(String, Nest, Point, Option<Point>)> {
    let root = format!("{}/../../data/nests", env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for dir in ["dbs-json", "dbs", "tflex"] {
        let mut names: Vec<String> = std::fs::read_dir(format!("{root}/{dir}"))
            .unwrap_or_else(|e| panic!("missing data folder {root}/{dir}: {e}"))
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert!(!names.is_empty(), "no nests in {root}/{dir}");
        for name in names {
            let path = format!("{root}/{dir}/{name}");
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            let document = cutroute_engine::open_document(&path, &bytes)
                .unwrap_or_else(|e| panic!("{path}: {e}"));
            let Problem::Nest {
                nest,
                start,
                finish,
            } = document.problem
            else {
                panic!("{path} is not a nest");
            };
            out.push((name, nest, start, finish));
        }
    }
    out
}

#[test]
fn every_real_nest_gets_a_checked_route_no_worse_than_ccp() {
    let nests = real_nests();
    assert!(nests.len() >= 20, "only {} nests found", nests.len());
    for (name, nest, start, finish) in nests {
        let options = GsccpOptions {
            sccp: SccpOptions {
                start,
                finish,
                // Ended by work (a few fruitless shakes), not by the clock: under load a
                // short limit stopped the run before the standard ensemble ran. The limit is
                // a safety net only.
                time_limit: Duration::from_secs(120),
                max_non_improving_shakes: 3,
                ..SccpOptions::default()
            },
            ..GsccpOptions::default()
        };
        let result = solve_gsccp(&nest, &options, &AtomicBool::new(false))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let b = nest.bounding_box();
        let tolerance = 1e-6 * ((b.max.x - b.min.x) + (b.max.y - b.min.y)).max(1.0);
        let problems = result.route.problems(&nest, tolerance);
        assert!(
            problems
                .iter()
                .all(|p| matches!(p, PathRouteError::Overlap { .. })),
            "{name}: {problems:?}"
        );
        let m = &options.machine;
        let ccp = &result.ccp_route;
        // Standard cutting starts from CCP-Relax's route and only improves it.
        let standard = &result.reports[0];
        assert_eq!(standard.kind, EnsembleKind::Standard);
        assert!(standard.failure.is_none(), "{name}: {standard:?}");
        assert_eq!(standard.pierces, nest.contour_count(), "{name}");
        assert!(
            standard.idle_length <= ccp.idle_length() + 1e-6,
            "{name}: {} > {}",
            standard.idle_length,
            ccp.idle_length()
        );
        assert!((standard.cut_length - ccp.cut_length()).abs() < 1e-6 * ccp.cut_length().max(1.0));
        // The chosen route is never slower than CCP's.
        assert!(result.route.time(m) <= ccp.time(m) + 1e-6, "{name}");
        assert!(result.route.pierce_count() <= ccp.pierce_count(), "{name}");
    }
}
