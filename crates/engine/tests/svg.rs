//! SVG nests through the engine's one door for files: hand-written drawings of known geometry,
//! and the project's own SVG export of real nests read back.

use std::f64::consts::PI;
use std::path::PathBuf;

use cutroute_engine::open_document;
use cutroute_formats::{nest_svg, read_nest, SvgOptions};
use cutroute_geometry::Nest;
use cutroute_protocol::{Document, Problem};

fn data(relative: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn nest_of(document: &Document) -> &Nest {
    match &document.problem {
        Problem::Nest { nest, .. } => nest,
        other => panic!("not a nest: {other:?}"),
    }
}

/// Area of a part: outer contour minus holes.
fn part_area(nest: &Nest, k: usize) -> f64 {
    let part = &nest.parts[k];
    part.contours[0].area() - part.contours[1..].iter().map(|c| c.area()).sum::<f64>()
}

#[test]
fn hand_written_plates_have_their_known_geometry() {
    let document = open_document("plates.svg", &data("nests/svg/plates.svg")).unwrap();
    assert_eq!(document.format, "SVG");
    let nest = nest_of(&document);
    let sheet = nest
        .sheet
        .as_ref()
        .expect("the rect of class sheet is the sheet");
    assert!((sheet.contours[0].area() - 60_000.0).abs() < 1e-6);
    assert_eq!(nest.parts.len(), 4);
    let counts: Vec<usize> = nest.parts.iter().map(|p| p.contours.len()).collect();
    assert_eq!(counts, [3, 1, 1, 1]);
    let expected = [
        5000.0 - 100.0 * PI - 100.0,
        225.0 * PI,
        800.0 - (4.0 - PI) * 25.0,
        450.0,
    ];
    for (k, area) in expected.into_iter().enumerate() {
        assert!(
            (part_area(nest, k) - area).abs() < 1e-6,
            "part {k}: {} vs {area}",
            part_area(nest, k)
        );
    }
    // y turned up: the plate (SVG y 10…60) lies at model y −60…−10.
    let plate = nest.parts[0].contours[0].bounding_box();
    assert!((plate.min.y + 60.0).abs() < 1e-9 && (plate.max.y + 10.0).abs() < 1e-9);
    // The rounded rectangle turned 90° about its centre is 20 wide and 40 high.
    let rounded = nest.parts[2].contours[0].bounding_box();
    assert!((rounded.max.x - rounded.min.x - 20.0).abs() < 1e-9);
    assert!((rounded.max.y - rounded.min.y - 40.0).abs() < 1e-9);
    // Circular arcs stay exact arcs: the disc is two spans.
    assert_eq!(nest.parts[1].contours[0].span_count(), 2);
}

#[test]
fn deepnest_style_inches_and_cubics_read_in_millimetres() {
    let document = open_document("deepnest.svg", &data("nests/svg/deepnest-style.svg")).unwrap();
    let nest = nest_of(&document);
    assert!(nest.sheet.is_none());
    assert_eq!(nest.parts.len(), 3);
    let plate = 50.8 * 25.4 - PI * 6.35 * 6.35;
    let unit = 25.4 / 72.0;
    let slot = (10_000.0 + PI * 2500.0) * unit * unit;
    for (k, area, tolerance) in [(0, plate, 1e-6), (1, plate, 1e-6), (2, slot, 1e-3 * slot)] {
        assert!(
            (part_area(nest, k) - area).abs() < tolerance,
            "part {k}: {} vs {area}",
            part_area(nest, k)
        );
    }
    assert_eq!(nest.parts[0].contours.len(), 2);
    assert_eq!(nest.parts[1].contours.len(), 2);
}

/// The project's SVG export of every real DBS nest reads back with the same contours: the
/// reader proved on real data (arcs split at their zenith, evenodd holes, the flipped group).
#[test]
fn own_export_of_real_nests_reads_back() {
    for name in ["nested.dbs", "circle.dbs", "rectangle.dbs", "Graph_5x7.DBS"] {
        let original = read_nest(&data(&format!("nests/dbs/{name}"))).unwrap();
        let svg = nest_svg(&original, None, &SvgOptions::default());
        let document = open_document("export.svg", svg.as_bytes()).unwrap();
        let back = nest_of(&document);
        assert_eq!(
            back.contour_count(),
            original.contour_count(),
            "{name}: contour count"
        );
        let mut before: Vec<f64> = original
            .parts
            .iter()
            .flat_map(|p| p.contours.iter().map(|c| c.perimeter()))
            .collect();
        let mut after: Vec<f64> = back
            .parts
            .iter()
            .flat_map(|p| p.contours.iter().map(|c| c.perimeter()))
            .collect();
        before.sort_by(f64::total_cmp);
        after.sort_by(f64::total_cmp);
        for (a, b) in before.iter().zip(&after) {
            assert!(
                (a - b).abs() < 1e-6 * a.max(1.0),
                "{name}: perimeter {a} vs {b}"
            );
        }
        assert_eq!(
            back.sheet.is_some(),
            original.sheet.is_some(),
            "{name}: sheet"
        );
    }
}

#[test]
fn broken_svg_is_refused_with_a_location() {
    let e = open_document(
        "bad.svg",
        b"<svg xmlns=\"http://www.w3.org/2000/svg\">\n<path d=\"M0 0 Q\"/></svg>",
    )
    .unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("bad.svg (SVG)") && message.contains("2:1"),
        "{message}"
    );
}
