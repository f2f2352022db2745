//! Chain cutting's tool-on links survive the RouteManager result format and show in SVG.

use cutroute_formats::{
    read_result_json, route_svg, write_result_json, ResultExportOptions, RmResult, SvgOptions,
};
use cutroute_geometry::{Contour, ContourRef, CutStep, Entry, Nest, Part, Point, Route, Vertex};

/// A clockwise 20 × 20 square with its lower-left corner at (x, 10).
fn square(x: f64) -> Part {
    Part {
        name: format!("S{x}"),
        contours: vec![Contour::new(vec![
            Vertex::line(x, 10.0),
            Vertex::line(x, 30.0),
            Vertex::line(x + 20.0, 30.0),
            Vertex::line(x + 20.0, 10.0),
        ])],
    }
}

/// Three squares in a row on a 100 × 50 sheet, 10 mm apart.
fn row() -> Nest {
    Nest {
        sheet: Some(Part {
            name: "sheet".into(),
            contours: vec![Contour::new(vec![
                Vertex::line(0.0, 0.0),
                Vertex::line(0.0, 50.0),
                Vertex::line(100.0, 50.0),
                Vertex::line(100.0, 0.0),
            ])],
        }),
        parts: vec![square(10.0), square(40.0), square(70.0)],
    }
}

/// One pierce, then a straight link across the gap and a link with two corners over the
/// middle square.
fn chained_route() -> Route {
    let c = |part| ContourRef { part, contour: 0 };
    Route {
        start: Point::new(0.0, 0.0),
        steps: vec![
            CutStep::pierced(c(0), Point::new(30.0, 20.0)),
            CutStep {
                contour: c(1),
                pierce_point: Point::new(40.0, 20.0),
                entry: Entry::Link(vec![]),
                leads: None,
            },
            CutStep {
                contour: c(2),
                pierce_point: Point::new(70.0, 20.0),
                entry: Entry::Link(vec![Point::new(35.0, 35.0), Point::new(65.0, 35.0)]),
                leads: None,
            },
        ],
        finish: Some(Point::new(0.0, 0.0)),
    }
}

#[test]
fn links_round_trip_through_the_result_format() {
    let nest = row();
    let route = chained_route();
    route
        .validate(&nest, 1e-6)
        .expect("the hand-made chain is valid");
    let exported = RmResult::from_route(&nest, &route, &ResultExportOptions::default()).unwrap();
    let text = write_result_json(&exported).unwrap();
    let back = read_result_json(text.as_bytes()).unwrap();
    assert_eq!(
        back.route(),
        route,
        "links, corners and pierce points come back"
    );
    let results = &back.results;
    assert!((results.route_length_no_contours - route.idle_length()).abs() < 1e-9);
    // Three perimeters of 80 mm plus the links: 10 mm across the gap, 5√10 + 30 + 5√10 over.
    let link = 10.0 + 30.0 + 2.0 * 250f64.sqrt();
    assert!((route.link_length() - link).abs() < 1e-9);
    let cut = route.cut_length(&nest);
    assert!((cut - (240.0 + link)).abs() < 1e-9, "{cut}");
    assert!((results.route_length - (route.idle_length() + cut)).abs() < 1e-9);
    // The links are tool-on moves without a contour; only the first step pierces.
    let links = back
        .tool_moves()
        .iter()
        .filter(|m| m.contour.is_none() && m.kind == cutroute_formats::MoveKind::Cut)
        .count();
    assert_eq!(links, 1 + 3);
}

#[test]
fn links_are_drawn_as_links_with_one_pierce() {
    let svg = route_svg(&row(), &chained_route(), &SvgOptions::default()).unwrap();
    assert_eq!(svg.matches("class=\"link\"").count(), 2, "{svg}");
    assert_eq!(svg.matches("class=\"pierce\"").count(), 1, "{svg}");
    assert_eq!(svg.matches("class=\"idle\"").count(), 2, "{svg}");
    assert_eq!(svg.matches("class=\"cut\"").count(), 3, "{svg}");
}

#[test]
fn a_result_without_links_reads_as_pierced_steps() {
    let nest = row();
    let mut route = chained_route();
    for step in &mut route.steps {
        step.entry = Entry::Pierce;
    }
    let exported = RmResult::from_route(&nest, &route, &ResultExportOptions::default()).unwrap();
    assert_eq!(exported.route(), route);
}
