//! What the DXF import makes of small hand-written drawings: joining, orientation, nesting of
//! parts, coordinate systems, block inserts and curve approximation.

mod common;

use common::{area, distance_to_contour, exact_bounds, polygon};
use cutroute_cad::dxf::{read_dxf, DxfImport, DxfOptions};
use cutroute_geometry::{BoundingBox, Point};

fn drawing(entities: &str) -> String {
    format!("0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
}

fn with_blocks(blocks: &str, entities: &str) -> String {
    format!(
        "0\nSECTION\n2\nBLOCKS\n{blocks}0\nENDSEC\n{}",
        drawing(entities)
    )
}

fn line(a: (f64, f64), b: (f64, f64)) -> String {
    format!(
        "0\nLINE\n10\n{}\n20\n{}\n11\n{}\n21\n{}\n",
        a.0, a.1, b.0, b.1
    )
}

/// A square of four loose lines, drawn counter-clockwise, with the given corner and side.
fn square(x: f64, y: f64, side: f64) -> String {
    let c = [(x, y), (x + side, y), (x + side, y + side), (x, y + side)];
    (0..4).map(|i| line(c[i], c[(i + 1) % 4])).collect()
}

fn read(text: &str) -> DxfImport {
    read_dxf(text.as_bytes(), &DxfOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn loose_lines_in_any_order_and_direction_join() {
    // The square's sides shuffled and two of them reversed, with 0.01 mm gaps.
    let text = drawing(
        &[
            line((10.0, 10.0), (0.0, 10.0)),
            line((0.0, 0.0), (10.0, 0.0)),
            line((0.0, 0.01), (0.0, 10.0)),
            line((10.0, 10.0), (10.0, 0.01)),
        ]
        .concat(),
    );
    let import = read(&text);
    assert_eq!(import.nest.parts.len(), 1);
    assert_eq!(import.nest.parts[0].contours[0].vertices.len(), 4);
    assert!(import.open_chains.is_empty());
    // With a 1 µm tolerance the gaps stay open: two chains, reported, nothing closed.
    let strict = DxfOptions {
        join_tolerance: 0.001,
        ..DxfOptions::default()
    };
    assert!(read_dxf(text.as_bytes(), &strict).is_err());
}

#[test]
fn part_in_a_hole_is_a_new_part_and_orientation_is_normalised() {
    // Plate 100 with a 80 hole, a 40 part in the hole, and a 10 hole in that part.
    let text = drawing(
        &[
            square(0.0, 0.0, 100.0),
            square(10.0, 10.0, 80.0),
            square(30.0, 30.0, 40.0),
            square(45.0, 45.0, 10.0),
        ]
        .concat(),
    );
    let import = read(&text);
    assert_eq!(import.nest.parts.len(), 2);
    for part in &import.nest.parts {
        assert_eq!(part.contours.len(), 2);
        assert!(area(&polygon(&part.contours[0])) < 0.0, "outer clockwise");
        assert!(
            area(&polygon(&part.contours[1])) > 0.0,
            "hole counter-clockwise"
        );
    }
    let BoundingBox { min: lo, max: hi } = exact_bounds(&import.nest.parts[1].contours[0]);
    assert_eq!((lo, hi), (Point::new(30.0, 30.0), Point::new(70.0, 70.0)));
}

#[test]
fn duplicate_contours_are_dropped_with_a_warning() {
    let text = drawing(&[square(0.0, 0.0, 10.0), square(0.0, 0.0, 10.0)].concat());
    let import = read(&text);
    assert_eq!(import.nest.parts.len(), 1);
    assert_eq!(import.nest.parts[0].contours.len(), 1);
    // Four duplicates, after the note that the drawing declares no units.
    assert_eq!(import.warnings.len(), 5, "{:?}", import.warnings);
    assert_eq!(
        import.warnings[0].kind,
        cutroute_geometry::WarningKind::Units
    );
    assert!(import.warnings[1]
        .message
        .contains("duplicates the entity at line 5"));
}

#[test]
fn t_junction_leaves_the_branch_open() {
    let text = drawing(&[square(0.0, 0.0, 10.0), line((5.0, 0.0), (5.0, -7.0))].concat());
    let import = read(&text);
    assert_eq!(import.nest.parts.len(), 1);
    assert_eq!(import.open_chains.len(), 1);
    assert!((import.open_chains[0].length - 7.0).abs() < 1e-12);
}

#[test]
fn mirrored_ocs_arcs_land_where_they_are_drawn() {
    // Extrusion (0, 0, −1): OCS x is world −x. The half circle about OCS (−5, 0) from 0° to 180°
    // is the upper half circle about world (5, 0) from (4, 0)… drawn clockwise.
    let arc = "0\nARC\n10\n-5\n20\n0\n40\n1\n50\n0\n51\n180\n210\n0\n220\n0\n230\n-1\n";
    let text = drawing(&format!("{arc}{}", line((4.0, 0.0), (6.0, 0.0))));
    let import = read(&text);
    let outer = &import.nest.parts[0].contours[0];
    let BoundingBox { min: lo, max: hi } = exact_bounds(outer);
    assert!((lo.x - 4.0).abs() < 1e-12 && (hi.x - 6.0).abs() < 1e-12);
    assert!(lo.y.abs() < 1e-12 && (hi.y - 1.0).abs() < 1e-12);
}

#[test]
fn inserts_rotate_scale_and_nest() {
    // Block B: a 10 × 10 square with base point (5, 5). Block C inserts B turned 90° and scaled 2
    // at (100, 0); the drawing inserts C at (0, 50).
    let blocks = format!(
        "0\nBLOCK\n2\nB\n10\n5\n20\n5\n{}0\nENDBLK\n0\nBLOCK\n2\nC\n10\n0\n20\n0\n0\nINSERT\n2\nB\n10\n100\n20\n0\n41\n2\n42\n2\n50\n90\n0\nENDBLK\n",
        square(0.0, 0.0, 10.0)
    );
    let import = read(&with_blocks(&blocks, "0\nINSERT\n2\nc\n10\n0\n20\n50\n"));
    let BoundingBox { min: lo, max: hi } = exact_bounds(&import.nest.parts[0].contours[0]);
    let near = |a: Point, b: Point| (a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9;
    assert!(
        near(lo, Point::new(90.0, 40.0)) && near(hi, Point::new(110.0, 60.0)),
        "{lo:?} {hi:?}"
    );
}

#[test]
fn unevenly_scaled_circle_becomes_an_ellipse_within_tolerance() {
    let blocks = "0\nBLOCK\n2\nR\n10\n0\n20\n0\n0\nCIRCLE\n10\n0\n20\n0\n40\n10\n0\nENDBLK\n";
    let text = with_blocks(
        blocks,
        "0\nINSERT\n2\nR\n10\n0\n20\n0\n41\n3\n42\n1\n50\n30\n",
    );
    for tolerance in [0.01, 0.0005] {
        let options = DxfOptions {
            approximation_tolerance: tolerance,
            ..DxfOptions::default()
        };
        let import = read_dxf(text.as_bytes(), &options).unwrap();
        let outer = &import.nest.parts[0].contours[0];
        let (s, c) = 30f64.to_radians().sin_cos();
        for k in 0..3600 {
            let t = k as f64 / 3600.0 * std::f64::consts::TAU;
            let (x, y) = (30.0 * t.cos(), 10.0 * t.sin());
            let p = Point::new(c * x - s * y, s * x + c * y);
            let d = distance_to_contour(p, outer);
            assert!(d <= tolerance * (1.0 + 1e-6), "deviation {d} at t = {t}");
        }
    }
}

#[test]
fn ellipse_arc_entity_within_tolerance() {
    // Upper half of an ellipse with semi-axes 50 (along 45°) and 20, closed by its chord.
    let (s, c) = std::f64::consts::FRAC_PI_4.sin_cos();
    let major = (50.0 * c, 50.0 * s);
    let ellipse = format!(
        "0\nELLIPSE\n10\n0\n20\n0\n11\n{}\n21\n{}\n40\n0.4\n41\n0\n42\n{}\n",
        major.0,
        major.1,
        std::f64::consts::PI
    );
    let text = drawing(&format!("{ellipse}{}", line((-major.0, -major.1), major)));
    let import = read(&text);
    let outer = &import.nest.parts[0].contours[0];
    for k in 0..=2000 {
        let t = k as f64 / 2000.0 * std::f64::consts::PI;
        let (x, y) = (50.0 * t.cos(), 20.0 * t.sin());
        let p = Point::new(c * x - s * y, s * x + c * y);
        assert!(distance_to_contour(p, outer) <= 0.01 * (1.0 + 1e-6));
    }
}

#[test]
fn rational_spline_quarter_circles_stay_on_the_circle() {
    // Two rational quadratic Béziers (weights 1, √½, 1) form the upper half of the unit circle
    // scaled to r = 100; a line closes it.
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let spline = format!(
        "0\nSPLINE\n70\n4\n71\n2\n72\n8\n73\n5\n40\n0\n40\n0\n40\n0\n40\n1\n40\n1\n40\n2\n40\n2\n40\n2\n\
         41\n1\n41\n{w}\n41\n1\n41\n{w}\n41\n1\n\
         10\n100\n20\n0\n10\n100\n20\n100\n10\n0\n20\n100\n10\n-100\n20\n100\n10\n-100\n20\n0\n"
    );
    let text = drawing(&format!("{spline}{}", line((-100.0, 0.0), (100.0, 0.0))));
    let import = read(&text);
    let outer = &import.nest.parts[0].contours[0];
    // Each quarter is one exact arc: 2 arcs and the line.
    assert_eq!(outer.vertices.len(), 3);
    for k in 0..=1000 {
        let t = k as f64 / 1000.0 * std::f64::consts::PI;
        let p = Point::new(100.0 * t.cos(), 100.0 * t.sin());
        assert!(distance_to_contour(p, outer) <= 1e-6);
    }
}

#[test]
fn ten_thousand_loose_squares_join_quickly() {
    let mut entities = String::new();
    for i in 0..100 {
        for j in 0..100 {
            entities.push_str(&square(i as f64 * 20.0, j as f64 * 20.0, 10.0));
        }
    }
    let started = std::time::Instant::now();
    let import = read(&drawing(&entities));
    assert_eq!(import.nest.parts.len(), 10_000);
    assert!(started.elapsed().as_secs() < 30, "{:?}", started.elapsed());
}

#[test]
fn unevenly_scaled_bulge_polyline_within_tolerance() {
    // A closed LWPOLYLINE circle of radius 10 (two half-circle bulges, clockwise) scaled (2, 1).
    let circle = "0\nLWPOLYLINE\n70\n1\n10\n10\n20\n0\n42\n-1\n10\n-10\n20\n0\n42\n-1\n";
    let blocks = format!("0\nBLOCK\n2\nP\n10\n0\n20\n0\n{circle}0\nENDBLK\n");
    let import = read(&with_blocks(&blocks, "0\nINSERT\n2\nP\n41\n2\n42\n1\n"));
    let outer = &import.nest.parts[0].contours[0];
    assert!(outer.vertices.len() > 2);
    for k in 0..3600 {
        let t = k as f64 / 3600.0 * std::f64::consts::TAU;
        let p = Point::new(20.0 * t.cos(), 10.0 * t.sin());
        assert!(distance_to_contour(p, outer) <= 0.01 * (1.0 + 1e-6));
    }
    let BoundingBox { min: lo, max: hi } = exact_bounds(outer);
    assert!((lo.x + 20.0).abs() < 0.011 && (hi.y - 10.0).abs() < 0.011);
}
