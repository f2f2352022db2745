//! Routes of tool-on paths (segment cutting, AOE-chains) written as G-code and read back: the
//! same pierces, lengths and motion, each path numbered in a comment.

use cutroute_gcode::{path_route_gcode, read_gcode, GcodeOptions, ReadOptions};
use cutroute_geometry::{PathRoute, Point, Span, ToolOnPath, Toolpath};

/// Two paths: a square's outline run on through scrap (a link) to a half-disc cut with an arc,
/// then a lone edge after an idle move.
fn two_paths() -> PathRoute {
    let p = Point::new;
    let first = ToolOnPath {
        pierce: p(0.0, 0.0),
        spans: vec![
            Span::line(p(0.0, 0.0), p(0.0, 10.0)),
            Span::line(p(0.0, 10.0), p(10.0, 10.0)),
            Span::line(p(10.0, 10.0), p(10.0, 0.0)),
            Span::line(p(10.0, 0.0), p(0.0, 0.0)),
            // Through scrap to the half-disc, then round it.
            Span::line(p(0.0, 0.0), p(20.0, 0.0)),
            Span {
                start: p(20.0, 0.0),
                end: p(30.0, 0.0),
                bulge: -1.0,
            },
            Span::line(p(30.0, 0.0), p(20.0, 0.0)),
        ],
        leads: None,
    };
    let second = ToolOnPath {
        pierce: p(40.0, 0.0),
        spans: vec![Span::line(p(40.0, 0.0), p(40.0, 25.0))],
        leads: None,
    };
    PathRoute {
        start: p(-5.0, -5.0),
        paths: vec![first, second],
        finish: Some(p(-5.0, -5.0)),
    }
}

#[test]
fn path_routes_read_back_with_the_same_pierces_and_lengths() {
    let route = two_paths();
    let text = path_route_gcode(&route, &GcodeOptions::default()).expect("writes");
    assert!(text.contains("path 1 of 2"), "{text}");
    assert!(text.contains("path 2 of 2"), "{text}");
    // The program starts where the head stands: the route's start.
    let options = ReadOptions {
        start: route.start,
        ..ReadOptions::default()
    };
    let program = read_gcode(&text, &options).expect("reads back");
    assert_eq!(program.pierce_count(), route.pierce_count());
    assert_eq!(
        program.pierce_points(),
        vec![route.paths[0].pierce, route.paths[1].pierce]
    );
    assert!(
        (program.cut_length() - route.cut_length()).abs() < 1e-3,
        "cut {} vs {}",
        program.cut_length(),
        route.cut_length()
    );
    assert!(
        (program.idle_length() - route.idle_length()).abs() < 1e-3,
        "idle {} vs {}",
        program.idle_length(),
        route.idle_length()
    );
    // The half-disc's arc survives as an arc: the cut length counts its half circumference.
    let expected_cut = 40.0 + 20.0 + 5.0 * std::f64::consts::PI + 10.0 + 25.0;
    assert!((route.cut_length() - expected_cut).abs() < 1e-9);
    // Read back as tool-on paths: the very route written (to the program's rounding).
    let paths = program.path_route();
    assert_eq!(paths.paths.len(), 2);
    assert_eq!(paths.start, route.start);
    assert_eq!(paths.finish, route.finish);
    for (a, b) in paths.paths.iter().zip(&route.paths) {
        assert_eq!(a.spans.len(), b.spans.len());
        assert!(a.pierce.distance(b.pierce) < 1e-3);
        assert!((a.length() - b.length()).abs() < 1e-3);
    }
    assert!((paths.idle_length() - route.idle_length()).abs() < 1e-3);
    let back = program.toolpath();
    let written = Toolpath::from_path_route(&route);
    assert_eq!(back.pierce_count(), written.pierce_count());
    assert!((back.cut_length() - written.cut_length()).abs() < 1e-3);
}
