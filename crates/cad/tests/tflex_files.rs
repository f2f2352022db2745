//! The T-FLEX reference projects: counts, sheets, and the placement semantics verified by the
//! absence of overlaps.

mod common;

use common::{bounds, overlapping_pairs, polygon, shared_dir_files, shared_file, Solid};
use cutroute_cad::tflex::{read_tfnesting, read_tfnesting_project, TflexProject};
use cutroute_geometry::{BoundingBox, Contour, Point, Vertex};

const TOLERANCE: f64 = 0.05;

fn project(name: &str) -> TflexProject {
    let bytes = shared_file(&format!("nests/tflex/{name}"));
    read_tfnesting_project(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn count_named(project: &TflexProject, name: &str) -> usize {
    project.layouts[0]
        .nest
        .parts
        .iter()
        .filter(|p| p.name == name)
        .count()
}

/// Every part lies on the sheet (within the tolerance) and no two parts' materials overlap.
fn assert_valid_layout(project: &TflexProject) {
    for layout in &project.layouts {
        let sheet = layout.nest.sheet.as_ref().expect("sheet contour");
        let sheet_polygon = polygon(&sheet.contours[0]);
        let BoundingBox { min: slo, max: shi } = bounds(&sheet_polygon);
        let solids: Vec<Solid> = layout
            .nest
            .parts
            .iter()
            .map(|p| Solid::new(&p.contours))
            .collect();
        for (part, solid) in layout.nest.parts.iter().zip(&solids) {
            assert!(
                solid.bounds.min.x >= slo.x - TOLERANCE
                    && solid.bounds.min.y >= slo.y - TOLERANCE
                    && solid.bounds.max.x <= shi.x + TOLERANCE
                    && solid.bounds.max.y <= shi.y + TOLERANCE,
                "{} lies off the sheet: {:?}–{:?}",
                part.name,
                solid.bounds.min,
                solid.bounds.max
            );
        }
        let pairs = overlapping_pairs(&solids, TOLERANCE);
        assert!(
            pairs.is_empty(),
            "{} overlapping pairs, first: {:?}",
            pairs.len(),
            pairs.first().map(|&(i, j)| (
                &layout.nest.parts[i].name,
                &layout.placements[i],
                &layout.nest.parts[j].name,
                &layout.placements[j]
            ))
        );
    }
}

/// Orientation convention: outer contour clockwise, holes counter-clockwise.
fn assert_oriented(project: &TflexProject) {
    for layout in &project.layouts {
        for part in layout.nest.parts.iter().chain(layout.nest.sheet.iter()) {
            assert!(
                common::area(&polygon(&part.contours[0])) < 0.0,
                "{} outer not clockwise",
                part.name
            );
            for hole in &part.contours[1..] {
                assert!(
                    common::area(&polygon(hole)) > 0.0,
                    "{} hole not counter-clockwise",
                    part.name
                );
            }
            // The shared model's own checks: a simple closed curve, oriented by role.
            for (k, c) in part.contours.iter().enumerate() {
                c.validate()
                    .unwrap_or_else(|e| panic!("{}: contour {k}: {e}", part.name));
                assert_eq!(c.is_clockwise(), k == 0, "{}: contour {k}", part.name);
            }
        }
    }
}

#[test]
fn every_reference_project_reads() {
    let files = shared_dir_files("nests/tflex", ".tfnesting");
    assert_eq!(
        files,
        ["Nest01.tfnesting", "Nest02.tfnesting", "Nest03.tfnesting"]
    );
    for f in files {
        let nests = read_tfnesting(&shared_file(&format!("nests/tflex/{f}"))).unwrap();
        assert_eq!(nests.len(), 1, "{f}: one sheet layout");
    }
}

#[test]
fn nest01_five_rectangles_on_a_3000_by_1000_sheet() {
    let p = project("Nest01.tfnesting");
    assert_eq!(p.layouts.len(), 1);
    let layout = &p.layouts[0];
    assert_eq!(layout.sheet_name, "List1");
    let BoundingBox { min: lo, max: hi } =
        bounds(&polygon(&layout.nest.sheet.as_ref().unwrap().contours[0]));
    assert_eq!((lo, hi), (Point::new(0.0, 0.0), Point::new(3000.0, 1000.0)));
    assert_eq!(layout.nest.parts.len(), 5);
    assert_eq!(count_named(&p, "Rect12"), 2);
    assert_eq!(count_named(&p, "Rect2"), 3);
    // Rect12 has one rounded corner (R10 arc): 6 spans, one of them an arc.
    let rect12 = &layout.nest.parts[0];
    assert_eq!(rect12.contours[0].vertices.len(), 6);
    assert_eq!(
        rect12.contours[0]
            .vertices
            .iter()
            .filter(|v| v.bulge != 0.0)
            .count(),
        1
    );
    let BoundingBox { min: lo, max: hi } = bounds(&polygon(&layout.nest.parts[4].contours[0]));
    assert_eq!(
        (lo, hi),
        (Point::new(1200.0, 0.0), Point::new(1300.0, 100.0))
    );
    assert_valid_layout(&p);
    assert_oriented(&p);
}

#[test]
fn nest02_places_406_parts_without_overlap() {
    let p = project("Nest02.tfnesting");
    let layout = &p.layouts[0];
    assert_eq!(layout.nest.parts.len(), 406);
    let expected = [
        ("CIRCLE50", 27),
        ("RECT100", 21),
        ("RECT200", 64),
        ("RING100", 27),
        ("RISE100", 66),
        ("RUMB", 55),
        ("SQUARE50", 77),
        ("TRIANGLE", 42),
        ("WINDOW", 27),
    ];
    for (name, count) in expected {
        assert_eq!(count_named(&p, name), count, "{name}");
    }
    let BoundingBox { min: lo, max: hi } =
        bounds(&polygon(&layout.nest.sheet.as_ref().unwrap().contours[0]));
    assert_eq!((lo, hi), (Point::new(0.0, 0.0), Point::new(6000.0, 2000.0)));
    let mut angles: Vec<i64> = layout
        .placements
        .iter()
        .map(|pl| pl.angle_deg as i64)
        .collect();
    angles.sort();
    angles.dedup();
    assert_eq!(angles, [0, 90, 116, 135, 180, 270, 296, 315]);
    assert!(layout.placements.iter().all(|pl| !pl.mirrored));
    // Rings and windows have a hole each.
    assert!(layout
        .nest
        .parts
        .iter()
        .filter(|p| p.name == "RING100" || p.name == "WINDOW")
        .all(|p| p.contours.len() == 2));
    assert_valid_layout(&p);
    assert_oriented(&p);
}

#[test]
fn nest03_places_406_parts_with_125_mirrored_without_overlap() {
    let p = project("Nest03.tfnesting");
    let layout = &p.layouts[0];
    assert_eq!(layout.nest.parts.len(), 406);
    assert_eq!(
        layout.placements.iter().filter(|pl| pl.mirrored).count(),
        125
    );
    assert_valid_layout(&p);
    assert_oriented(&p);
}

/// Turns a placed contour about `centre` by `angle` radians: used to re-read a layout under
/// another rotation convention without the part definitions.
fn turned(contour: &Contour, centre: Point, angle: f64) -> Contour {
    let (s, c) = angle.sin_cos();
    Contour::new(
        contour
            .vertices
            .iter()
            .map(|v| {
                let (dx, dy) = (v.point.x - centre.x, v.point.y - centre.y);
                Vertex::arc(
                    centre.x + c * dx - s * dy,
                    centre.y + s * dx + c * dy,
                    v.bulge,
                )
            })
            .collect(),
    )
}

#[test]
fn the_other_readings_of_the_placements_do_overlap() {
    // Clockwise angles instead of counter-clockwise: turning each placed part by −2·angle about
    // its position gives what a clockwise reading would have produced.
    let p = project("Nest02.tfnesting");
    let layout = &p.layouts[0];
    let solids: Vec<Solid> = layout
        .nest
        .parts
        .iter()
        .zip(&layout.placements)
        .map(|(part, pl)| {
            let contours: Vec<Contour> = part
                .contours
                .iter()
                .map(|c| turned(c, pl.position, -2.0 * pl.angle_deg.to_radians()))
                .collect();
            Solid::new(&contours)
        })
        .collect();
    assert!(overlapping_pairs(&solids, TOLERANCE).len() > 10);

    // Mirroring y instead of x: for the (unturned) mirrored parts that is a half turn about the
    // position, which pushes them off the sheet or into neighbours.
    let p = project("Nest03.tfnesting");
    let layout = &p.layouts[0];
    let solids: Vec<Solid> = layout
        .nest
        .parts
        .iter()
        .zip(&layout.placements)
        .map(|(part, pl)| {
            let angle = if pl.mirrored {
                std::f64::consts::PI
            } else {
                0.0
            };
            let contours: Vec<Contour> = part
                .contours
                .iter()
                .map(|c| turned(c, pl.position, angle))
                .collect();
            Solid::new(&contours)
        })
        .collect();
    let off_sheet = solids
        .iter()
        .filter(|s| s.bounds.min.y < -TOLERANCE || s.bounds.min.x < -TOLERANCE)
        .count();
    assert!(off_sheet + overlapping_pairs(&solids, TOLERANCE).len() > 10);
}
