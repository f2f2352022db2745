//! Fuzzed small nests into every solver (issue #15): the bytes pick a solver and place up to
//! 12 shapes (rectangles, circles, bulged quadrilaterals, tiny to large, some nested: a hole
//! of the part before, or a part in that hole) on a grid, so contours never cross. A nest
//! outside the readers' domain is refused as the readers refuse it; any other nest must
//! give, within 100 ms of stepping (plus the longest single step), a route that passes the
//! independent checker, or a clean error: never a panic, a hang or an invalid route.
#![no_main]

use cutroute_engine::{start_job, JobStatus, DEFAULT_SLICE};
use cutroute_geometry::{Contour, Nest, Part, PathRouteError, Point, Vertex};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};
use libfuzzer_sys::fuzz_target;
use std::time::{Duration, Instant};

/// A shape of one record within the box (x0, y0)–(x0 + size, y0 + size), clockwise.
fn shape(kind: u8, x0: f64, y0: f64, size: f64, skew: u8) -> Contour {
    match kind % 3 {
        0 => Contour::new(vec![
            Vertex::line(x0, y0),
            Vertex::line(x0, y0 + size),
            Vertex::line(x0 + size, y0 + size * (0.5 + f64::from(skew) / 510.0)),
            Vertex::line(x0 + size, y0),
        ]),
        1 => Contour::circle(
            Point::new(x0 + size / 2.0, y0 + size / 2.0),
            size / 2.0,
            true,
        ),
        _ => {
            // A quadrilateral with one bulged side, the bulge within (−1, 1): stays in its box
            // up to the arc's sagitta (at most half the side), so holes stay inside.
            let bulge = (f64::from(skew) - 127.5) / 256.0;
            Contour::new(vec![
                Vertex::line(x0 + size * 0.25, y0 + size * 0.25),
                Vertex::line(x0 + size * 0.25, y0 + size * 0.75),
                Vertex::arc(x0 + size * 0.75, y0 + size * 0.75, bulge),
                Vertex::line(x0 + size * 0.75, y0 + size * 0.25),
            ])
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, records)) = data.split_first() else {
        return;
    };
    let solver = match pick % 9 {
        8 => SolverKind::Heuristic, // "discrete" in the CLI: the heuristic on a discretised nest
        k => SolverKind::ALL[usize::from(k) % SolverKind::ALL.len()],
    };
    let mut parts: Vec<Part> = Vec::new();
    for (i, r) in records.chunks_exact(4).take(12).enumerate() {
        let (kind, scale, skew, hole) = (r[0], r[1], r[2], r[3]);
        // 1e-6 mm to 90 mm: below the domain's 0.05 mm the nest is refused like a file.
        let size = 90.0 * 10f64.powf(-f64::from(scale % 64) / 8.0);
        if hole % 4 == 0 && !parts.is_empty() {
            // Inside the innermost contour so far, centred and smaller: a hole of the last
            // part, or, when that part has its hole already, a part in that hole.
            let last = parts.last().unwrap();
            let inner = last.contours.last().unwrap().bounding_box();
            let side = (inner.max.x - inner.min.x).min(inner.max.y - inner.min.y) * 0.3;
            let (cx, cy) = (
                (inner.min.x + inner.max.x) / 2.0,
                (inner.min.y + inner.max.y) / 2.0,
            );
            let contour = shape(kind, cx - side / 2.0, cy - side / 2.0, side, skew);
            if last.contours.len() == 1 {
                parts.last_mut().unwrap().contours.push(contour.reversed());
            } else {
                parts.push(Part {
                    name: format!("P{i}"),
                    contours: vec![contour],
                });
            }
            continue;
        }
        let (x0, y0) = ((i % 4) as f64 * 100.0, (i / 4) as f64 * 100.0);
        parts.push(Part {
            name: format!("P{i}"),
            contours: vec![shape(kind, x0, y0, size, skew)],
        });
    }
    let mut nest = Nest {
        sheet: None,
        parts,
    };
    if nest.contour_count() == 0 || nest.check_domain().is_err() {
        return; // what every reader refuses
    }
    nest.normalize_orientation();
    let request = JobRequest {
        job_id: 1,
        problem: Problem::Nest {
            nest: nest.clone(),
            start: Point::new(0.0, 0.0),
            finish: None,
        },
        solver,
        params: SolverParams {
            time_limit_s: 0.1,
            discretisation_step_mm: 5.0 + f64::from(pick),
            ..SolverParams::default()
        },
    };
    let started = Instant::now();
    let Ok(mut job) = start_job(&request) else {
        return; // a clean refusal
    };
    // Stepped as the CLI steps it: stop at the limit even if the job would go on.
    while job.step(DEFAULT_SLICE) == JobStatus::Running
        && started.elapsed() < Duration::from_millis(100)
    {}
    let progress = job.progress();
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "{solver:?} took {:?} on a 0.1 s limit",
        started.elapsed()
    );
    let tolerance = 1e-6 * 400.0;
    if let Some(route) = &progress.route {
        if let Err(e) = route.validate(&nest, tolerance) {
            panic!("{solver:?}: invalid route: {e}");
        }
    }
    if let Some(path_route) = &progress.path_route {
        let problems: Vec<_> = path_route
            .problems(&nest, tolerance)
            .into_iter()
            .filter(|p| !matches!(p, PathRouteError::Overlap { .. }))
            .collect();
        assert!(problems.is_empty(), "{solver:?}: invalid path route: {problems:?}");
    }
});
