//! `PathRoute::problems` on contours that touch: a tangent contact is not a second cut, a
//! rounding-error crossing is covered by the edge that crosses, a real second cut is reported.

use cutroute_geometry::{
    Contour, Nest, Part, PathRoute, PathRouteError, Point, Route, Span, ToolOnPath, Vertex,
};

fn part(contours: Vec<Contour>) -> Part {
    Part {
        name: String::new(),
        contours,
    }
}

/// A half disc of radius 100 on y = 0 (its top at (0, 100)) and a rectangle resting on that
/// top: the rectangle's bottom edge is tangent to the arc at (0, 100).
fn tangent_pair() -> Nest {
    Nest {
        sheet: None,
        parts: vec![
            part(vec![Contour::new(vec![
                Vertex::arc(-100.0, 0.0, -1.0),
                Vertex::line(100.0, 0.0),
            ])]),
            part(vec![Contour::new(vec![
                Vertex::line(-50.0, 100.0),
                Vertex::line(-50.0, 150.0),
                Vertex::line(50.0, 150.0),
                Vertex::line(50.0, 100.0),
            ])]),
        ],
    }
}

fn every_contour_on_its_own(nest: &Nest) -> PathRoute {
    let steps = nest
        .contour_refs()
        .map(|r| cutroute_geometry::CutStep::pierced(r, nest.contour(r).unwrap().vertices[0].point))
        .collect();
    let route = Route {
        start: Point::new(0.0, -50.0),
        steps,
        finish: None,
    };
    PathRoute::from_route(&route, nest).unwrap()
}

#[test]
fn a_tangent_contact_is_not_a_second_cut() {
    let nest = tangent_pair();
    // With a tolerance of 0.01 mm the edge stays within it of the arc for ±1.4 mm.
    let route = every_contour_on_its_own(&nest);
    assert_eq!(route.problems(&nest, 0.01), vec![]);
}

#[test]
fn cutting_the_arc_twice_is_still_an_overlap() {
    let nest = tangent_pair();
    let mut route = every_contour_on_its_own(&nest);
    // A third path re-cuts a piece of the arc.
    let arc = route.paths[0].spans[0];
    let piece = arc.sub_span(0.25, 0.5);
    route.paths.push(ToolOnPath {
        pierce: piece.start,
        spans: vec![piece],
        leads: None,
    });
    let problems = route.problems(&nest, 0.01);
    assert!(
        problems
            .iter()
            .any(|p| matches!(p, PathRouteError::Overlap { length, .. } if (*length - piece.length()).abs() < 0.1)),
        "{problems:?}"
    );
}

#[test]
fn an_arc_bulging_a_rounding_error_across_a_line_is_covered_by_the_line() {
    // The half disc's top pokes 2e-5 mm above y = 100 (Nest02 has such a pair); a route that
    // cuts the disc but takes the line across the 0.13 mm piece above it, once, for both
    // contours, leaves no gap and no overlap.
    let nest = tangent_pair();
    let lifted = Nest {
        parts: vec![
            part(vec![Contour::new(vec![
                Vertex::arc(-100.00002, 0.0, -1.0),
                Vertex::line(100.00002, 0.0),
            ])]),
            nest.parts[1].clone(),
        ],
        ..nest
    };
    let full = every_contour_on_its_own(&lifted);
    let arc = full.paths[0].spans[0];
    // Where the arc crosses y = 100 (x = ±√(100.00002² − 100²)).
    let x = (100.00002f64.powi(2) - 100.0f64.powi(2)).sqrt();
    let t_left = arc.parameter_of(Point::new(-x, 100.0));
    let t_right = arc.parameter_of(Point::new(x, 100.0));
    let (t0, t1) = (t_left.min(t_right), t_left.max(t_right));
    let mut spans = vec![arc.sub_span(0.0, t0)];
    spans.push(Span::line(spans[0].end, arc.sub_span(t1, 1.0).start));
    spans.push(arc.sub_span(t1, 1.0));
    spans.extend(full.paths[0].spans[1..].iter().copied());
    // The rectangle without the piece of its bottom edge that the first path cut.
    let corners = [
        Point::new(-x, 100.0),
        Point::new(-50.0, 100.0),
        Point::new(-50.0, 150.0),
        Point::new(50.0, 150.0),
        Point::new(50.0, 100.0),
        Point::new(x, 100.0),
    ];
    let rest = corners.windows(2).map(|w| Span::line(w[0], w[1])).collect();
    let route = PathRoute {
        paths: vec![
            ToolOnPath {
                pierce: spans[0].start,
                spans,
                leads: None,
            },
            ToolOnPath {
                pierce: corners[0],
                spans: rest,
                leads: None,
            },
        ],
        ..full
    };
    assert_eq!(route.problems(&lifted, 1e-4), vec![]);
}
