//! The DXF reference drawings: every file imports, and what it holds was checked by reading the
//! files (entity lists, coordinates) independently of the reader.

mod common;

use common::{area, distance_to_contour, exact_bounds, polygon, shared_dir_files, shared_file};
use cutroute_cad::dxf::{read_dxf, DxfImport, DxfOptions};
use cutroute_geometry::{BoundingBox, Contour, Point};

fn import(name: &str) -> DxfImport {
    let bytes = shared_file(&format!("nests/dxf/{name}"));
    read_dxf(&bytes, &DxfOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn arcs(contour: &Contour) -> usize {
    contour.vertices.iter().filter(|v| v.bulge != 0.0).count()
}

fn assert_box(contour: &Contour, lo: (f64, f64), hi: (f64, f64)) {
    let BoundingBox { min: a, max: b } = exact_bounds(contour);
    let ok = (a.x - lo.0).abs() < 1e-3
        && (a.y - lo.1).abs() < 1e-3
        && (b.x - hi.0).abs() < 1e-3
        && (b.y - hi.1).abs() < 1e-3;
    assert!(ok, "bounding box {a:?}–{b:?}, expected {lo:?}–{hi:?}");
}

/// Outer contours clockwise, holes counter-clockwise, no zero-length span anywhere.
fn assert_well_formed(import: &DxfImport) {
    for part in &import.nest.parts {
        assert!(
            area(&polygon(&part.contours[0])) < 0.0,
            "{}: outer contour not clockwise",
            part.name
        );
        for hole in &part.contours[1..] {
            assert!(
                area(&polygon(hole)) > 0.0,
                "{}: hole not counter-clockwise",
                part.name
            );
        }
        for (k, c) in part.contours.iter().enumerate() {
            // The shared model's own checks: a simple closed curve, oriented by role.
            c.validate()
                .unwrap_or_else(|e| panic!("{}: contour {k}: {e}", part.name));
            assert_eq!(
                c.is_clockwise(),
                k == 0,
                "{}: contour {k} orientation",
                part.name
            );
            let n = c.vertices.len();
            for i in 0..n {
                let (a, b) = (c.vertices[i].point, c.vertices[(i + 1) % n].point);
                assert!(
                    (a.x - b.x).hypot(a.y - b.y) > 1e-9,
                    "{}: zero-length span",
                    part.name
                );
            }
        }
    }
}

#[test]
fn every_reference_drawing_imports_well_formed() {
    let files = shared_dir_files("nests/dxf", ".dxf");
    assert_eq!(files.len(), 11, "{files:?}");
    for name in files {
        let imported = import(&name);
        assert_eq!(
            imported.nest.parts.len(),
            1,
            "{name}: each drawing is one part"
        );
        assert!(imported.nest.sheet.is_none());
        assert_well_formed(&imported);
    }
}

#[test]
fn square_r12_polyline() {
    let i = import("square.dxf");
    let outer = &i.nest.parts[0].contours[0];
    assert_eq!(outer.vertices.len(), 4);
    assert_eq!(arcs(outer), 0);
    assert_box(outer, (0.0, 0.0), (100.0, 100.0));
    assert!((area(&polygon(outer)) + 10_000.0).abs() < 1e-9);
    assert!(i.open_chains.is_empty());
    // The file declares no units: the only warning says millimetres were assumed.
    assert_eq!(i.warnings.len(), 1, "{:?}", i.warnings);
    assert_eq!(i.warnings[0].kind, cutroute_geometry::WarningKind::Units);
    assert!(i.warnings[0].message.contains("millimetres assumed"));
}

#[test]
fn poly_polyline_with_two_bulged_corners() {
    let i = import("poly.dxf");
    let outer = &i.nest.parts[0].contours[0];
    assert_eq!(outer.vertices.len(), 8);
    assert_eq!(arcs(outer), 2);
    // Bulge 0.414214 = tan(22.5°): quarter circles; the reader keeps the sign convention.
    assert!(outer
        .vertices
        .iter()
        .all(|v| v.bulge == 0.0 || (v.bulge.abs() - 0.414214).abs() < 1e-12));
    assert_box(outer, (0.0, 0.0), (180.0, 598.0));
}

#[test]
fn lwpoly_loose_lines_and_arc_join_across_a_micrometre_gap() {
    let i = import("lwpoly.dxf");
    let outer = &i.nest.parts[0].contours[0];
    assert_eq!((outer.vertices.len(), arcs(outer)), (6, 1));
    assert_box(outer, (0.0, 0.0), (260.0, 488.0));
    // The ARC ends at (1.0180011, 8.1e-7) while the LINE starts at (1.018001, 0): a 1.1 µm gap,
    // bridged by the default tolerance but not by 0.1 µm.
    let bytes = shared_file("nests/dxf/lwpoly.dxf");
    let strict = DxfOptions {
        join_tolerance: 1e-7,
        ..DxfOptions::default()
    };
    let err = read_dxf(&bytes, &strict).unwrap_err().to_string();
    assert!(
        err.contains("no closed contour") && err.contains("6 entities"),
        "{err}"
    );
}

#[test]
fn non_closed_reports_the_arc_that_crosses_the_part() {
    let i = import("non-closed.dxf");
    let part = &i.nest.parts[0];
    assert_eq!(part.contours.len(), 1);
    assert_eq!(
        (part.contours[0].vertices.len(), arcs(&part.contours[0])),
        (10, 1)
    );
    assert_box(&part.contours[0], (0.0, 0.0), (580.0, 340.0));
    assert_eq!(i.open_chains.len(), 1);
    let chain = &i.open_chains[0];
    assert_eq!(chain.entities.len(), 1);
    assert_eq!(
        (chain.entities[0].entity.as_str(), chain.entities[0].line),
        ("ARC", 1313)
    );
    // R295 arc about (290, 350) from 190.563965° to 349.436035°: it ends on the part's sides.
    let ends = [chain.start, chain.end];
    assert!(ends
        .iter()
        .any(|p| p.x.abs() < 1e-6 && (p.y - 295.9167).abs() < 1e-3));
    assert!(ends
        .iter()
        .any(|p| (p.x - 580.0).abs() < 1e-6 && (p.y - 295.9167).abs() < 1e-3));
    assert!((chain.length - 295.0 * (349.436035f64 - 190.563965).to_radians()).abs() < 1e-6);
    let report = chain.to_string();
    assert!(report.contains("ARC at line 1313"), "{report}");
}

#[test]
fn propeller_outline_with_a_circular_hole() {
    let i = import("propeller.dxf");
    let part = &i.nest.parts[0];
    assert_eq!(part.name, "Ш33-ХД4-03_02_16#1");
    assert_eq!(part.contours.len(), 2);
    assert_eq!(
        (part.contours[0].vertices.len(), arcs(&part.contours[0])),
        (8, 4)
    );
    assert_box(
        &part.contours[0],
        (27.518646, 46.856462),
        (359.518646, 179.856462),
    );
    // CIRCLE r = 47.5 about (193.518646, 113.356462).
    assert_eq!(
        (part.contours[1].vertices.len(), arcs(&part.contours[1])),
        (2, 2)
    );
    assert_box(
        &part.contours[1],
        (146.018646, 65.856462),
        (241.018646, 160.856462),
    );
}

#[test]
fn f26_and_kompas_report_their_centre_lines_as_open() {
    let i = import("f26.dxf");
    let outer = &i.nest.parts[0].contours[0];
    assert_eq!((outer.vertices.len(), arcs(outer)), (16, 1));
    assert_box(outer, (69.163148, 202.306782), (149.163148, 232.306782));
    assert_eq!(i.open_chains.len(), 1);
    assert!((i.open_chains[0].length - 95.0).abs() < 1e-9);
    assert_eq!(i.open_chains[0].entities[0].line, 3039);

    let k = import("kompas.dxf");
    let part = &k.nest.parts[0];
    assert_eq!(
        part.name, "Системный слой (1)#1",
        "UTF-8 layer name of an AC1032 file"
    );
    assert_eq!(
        (part.contours[0].vertices.len(), arcs(&part.contours[0])),
        (10, 1)
    );
    assert_box(
        &part.contours[0],
        (84.332730, 54.605948),
        (103.332730, 104.605948),
    );
    assert_eq!(k.open_chains.len(), 1);
    assert!((k.open_chains[0].length - 54.0).abs() < 1e-9);
}

#[test]
fn cross_is_drawn_in_paper_space() {
    let i = import("cross.dxf");
    assert!(i.warnings.iter().any(|w| w.message.contains("paper-space")));
    let part = &i.nest.parts[0];
    assert_eq!(part.contours.len(), 2);
    // An octagon 150 × 150 with 10 mm chamfers…
    assert_eq!(
        (part.contours[0].vertices.len(), arcs(&part.contours[0])),
        (8, 0)
    );
    assert!((area(&polygon(&part.contours[0])) + 22_300.0).abs() < 1e-6);
    assert_box(&part.contours[0], (1147.0, 3966.0), (1297.0, 4116.0));
    // …with a cross-shaped hole of 12 lines and 12 R10 arcs.
    assert_eq!(
        (part.contours[1].vertices.len(), arcs(&part.contours[1])),
        (24, 12)
    );
    assert_box(&part.contours[1], (1157.0, 3976.0), (1287.0, 4106.0));
}

#[test]
fn planka_block_insert_with_four_holes() {
    let i = import("planka.dxf");
    let part = &i.nest.parts[0];
    assert_eq!(
        part.name, "ПЛАНКА_ДЛИННАЯ#1",
        "ANSI_1251 layer name decoded"
    );
    assert_eq!(part.contours.len(), 5);
    // Block SE inserted at (−606.7734672114897, −60.09083083082791): a 330 × 40 chamfered bar.
    assert_eq!(
        (part.contours[0].vertices.len(), arcs(&part.contours[0])),
        (8, 0)
    );
    assert_box(
        &part.contours[0],
        (11.019390, 61.334192),
        (341.019390, 101.334192),
    );
    for hole in &part.contours[1..] {
        assert_eq!((hole.vertices.len(), arcs(hole)), (2, 2));
        let BoundingBox { min: lo, max: hi } = exact_bounds(hole);
        assert!((hi.x - lo.x - 6.5).abs() < 1e-9 && (hi.y - lo.y - 6.5).abs() < 1e-9);
    }
}

#[test]
fn cone_fillets_of_several_arcs() {
    let i = import("cone.dxf");
    let part = &i.nest.parts[0];
    assert_eq!(part.name, "КОНУС#1");
    assert_eq!(part.contours.len(), 1);
    assert_eq!(
        (part.contours[0].vertices.len(), arcs(&part.contours[0])),
        (16, 12)
    );
    assert_box(
        &part.contours[0],
        (-181.825657, 50.613107),
        (259.822153, 482.293539),
    );
}

/// A non-rational B-spline as the file stores it.
struct FileSpline {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<Point>,
}

/// The two SPLINEs of splines.dxf, read straight from the file, and the offset of their block.
fn splines_of_the_file() -> (Vec<FileSpline>, Point) {
    let text = String::from_utf8_lossy(&shared_file("nests/dxf/splines.dxf")).replace('\r', "");
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let pairs: Vec<(i32, &str)> = lines
        .chunks(2)
        .map(|c| (c[0].parse().unwrap(), c[1]))
        .collect();
    let mut splines = Vec::new();
    let mut offset = None;
    for (k, &(code, value)) in pairs.iter().enumerate() {
        if code != 0 {
            continue;
        }
        let body: Vec<(i32, &str)> = pairs[k + 1..]
            .iter()
            .take_while(|p| p.0 != 0)
            .copied()
            .collect();
        let real = |c: i32| {
            body.iter()
                .filter(|p| p.0 == c)
                .map(|p| p.1.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        };
        if value == "SPLINE" {
            let degree = body.iter().find(|p| p.0 == 71).unwrap().1.parse().unwrap();
            let points = real(10)
                .into_iter()
                .zip(real(20))
                .map(|(x, y)| Point::new(x, y))
                .collect();
            splines.push(FileSpline {
                degree,
                knots: real(40),
                points,
            });
        }
        if value == "INSERT" && body.iter().any(|p| p.0 == 2 && p.1 == "SE") {
            offset = Some(Point::new(real(10)[0], real(20)[0]));
        }
    }
    (splines, offset.expect("INSERT of block SE"))
}

/// B-spline point by the Cox–de Boor basis recursion (not the reader's de Boor scheme).
fn basis_point(degree: usize, knots: &[f64], points: &[Point], t: f64) -> Point {
    fn basis(i: usize, p: usize, knots: &[f64], t: f64, last: bool) -> f64 {
        if p == 0 {
            let inside = knots[i] <= t && t < knots[i + 1];
            let at_end = last && t == knots[i + 1] && knots[i] < knots[i + 1];
            return if inside || at_end { 1.0 } else { 0.0 };
        }
        let mut v = 0.0;
        if knots[i + p] > knots[i] {
            v += (t - knots[i]) / (knots[i + p] - knots[i]) * basis(i, p - 1, knots, t, last);
        }
        if knots[i + p + 1] > knots[i + 1] {
            v += (knots[i + p + 1] - t) / (knots[i + p + 1] - knots[i + 1])
                * basis(i + 1, p - 1, knots, t, last);
        }
        v
    }
    let end = knots[points.len()];
    let mut q = Point::new(0.0, 0.0);
    for (i, p) in points.iter().enumerate() {
        let last = t == end && knots[i + 1] == end;
        let b = basis(i, degree, knots, t, last || t == end);
        q = Point::new(q.x + b * p.x, q.y + b * p.y);
    }
    q
}

#[test]
fn splines_are_approximated_within_the_tolerance() {
    let (splines, offset) = splines_of_the_file();
    assert_eq!(splines.len(), 2);
    let bytes = shared_file("nests/dxf/splines.dxf");
    for tolerance in [0.01, 0.001, 0.00001] {
        let options = DxfOptions {
            approximation_tolerance: tolerance,
            ..DxfOptions::default()
        };
        let imported = read_dxf(&bytes, &options).unwrap();
        assert_eq!(imported.nest.parts.len(), 1);
        let outer = &imported.nest.parts[0].contours[0];
        for FileSpline {
            degree,
            knots,
            points,
        } in &splines
        {
            assert_eq!((*degree, knots.len(), points.len()), (3, 15, 11));
            let (t0, t1) = (knots[*degree], knots[points.len()]);
            let mut worst: f64 = 0.0;
            for k in 0..=4000 {
                let t = t0 + (t1 - t0) * k as f64 / 4000.0;
                let p = basis_point(*degree, knots, points, t);
                let p = Point::new(p.x + offset.x, p.y + offset.y);
                worst = worst.max(distance_to_contour(p, outer));
            }
            assert!(
                worst <= tolerance * (1.0 + 1e-6),
                "deviation {worst} > {tolerance}"
            );
        }
    }
    // 16 lines and 4 arcs, plus one arc per knot interval of each spline (8 each) at 0.01 mm;
    // a much finer tolerance needs more arcs.
    let coarse = read_dxf(&bytes, &DxfOptions::default()).unwrap();
    let fine = read_dxf(
        &bytes,
        &DxfOptions {
            approximation_tolerance: 0.00001,
            ..DxfOptions::default()
        },
    )
    .unwrap();
    let spans = |i: &DxfImport| i.nest.parts[0].contours[0].vertices.len();
    assert_eq!(spans(&coarse), 36);
    assert!(
        spans(&fine) > spans(&coarse),
        "{} spans at 1e-5 mm",
        spans(&fine)
    );
}
