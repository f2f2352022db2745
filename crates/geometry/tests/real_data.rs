//! Checks on the real nests of `data/nests/dbs-json` (geometry JSON: an array of
//! `{partid, paths: [[[x, y, bulge], …]]}`, the first part being the sheet).

use std::path::PathBuf;

use cutroute_geometry::{Contour, Nest, Part, Vertex};

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/nests/dbs-json")
}

/// Reads a geometry JSON nest; panics (fails the test) when the file is missing.
fn load(name: &str) -> Nest {
    let path = data_dir().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let json: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let mut parts: Vec<Part> = json
        .as_array()
        .expect("an array of parts")
        .iter()
        .map(|part| {
            let name = part["partid"].as_str().unwrap_or_default().to_string();
            let contours = part["paths"]
                .as_array()
                .expect("paths")
                .iter()
                .map(|path| {
                    let raw: Vec<Vertex> = path
                        .as_array()
                        .expect("points")
                        .iter()
                        .map(|p| {
                            let v: Vec<f64> = p
                                .as_array()
                                .expect("[x, y, bulge]")
                                .iter()
                                .map(|x| x.as_f64().unwrap_or(f64::NAN))
                                .collect();
                            Vertex::arc(v[0], v[1], v.get(2).copied().unwrap_or(0.0))
                        })
                        .collect();
                    Contour::close_points(&raw, 1e-3).expect("closed contour")
                })
                .collect();
            Part { name, contours }
        })
        .collect();
    let sheet = parts.remove(0);
    Nest {
        sheet: Some(sheet),
        parts,
    }
}

#[test]
fn real_nests_are_valid_and_nest_as_expected() {
    // Counts taken from the files themselves (arcs: non-zero bulges except on closing points).
    for (file, parts, contours, arcs) in [
        ("E1X_6_01.dbs.json", 8, 16, 27),
        ("test0.dbs.json", 14, 20, 12),
        ("test1.dbs.json", 21, 25, 10),
    ] {
        let mut nest = load(file);
        // E1X follows the convention; test0 and test1 store every contour clockwise, so every
        // odd-depth contour (a hole) gets reversed.
        let odd = {
            let forest = nest.containment_forest();
            nest.contour_refs()
                .filter(|&r| forest.depth(r).is_some_and(|d| d % 2 == 1))
                .count()
        };
        let expected_fixes = if file.starts_with("E1X") { 0 } else { odd };
        assert!(odd > 0, "{file}");
        assert_eq!(
            nest.clone().normalize_orientation(),
            expected_fixes,
            "{file}"
        );
        let part_fixes: usize = nest
            .parts
            .clone()
            .iter_mut()
            .map(|p| p.normalize_orientation())
            .sum();
        assert_eq!(
            part_fixes, expected_fixes,
            "{file}: no part lies in another part's hole"
        );
        let area_before: f64 = nest
            .parts
            .iter()
            .flat_map(|p| &p.contours)
            .map(|c| c.area())
            .sum();
        nest.normalize_orientation();
        let area_after: f64 = nest
            .parts
            .iter()
            .flat_map(|p| &p.contours)
            .map(|c| c.area())
            .sum();
        assert!((area_before - area_after).abs() < 1e-6 * area_before);
        assert_eq!(nest.parts.len(), parts, "{file}");
        assert_eq!(nest.contour_count(), contours, "{file}");
        assert_eq!(nest.arc_count(), arcs, "{file}");
        let sheet_box = nest.sheet.as_ref().unwrap().bounding_box();
        assert!(
            sheet_box.contains_box(&nest.bounding_box()),
            "{file}: parts on the sheet"
        );
        let forest = nest.containment_forest();
        assert_eq!(
            forest,
            cutroute_geometry::ContainmentForest::brute_force(&nest),
            "{file}"
        );
        for (pi, part) in nest.parts.iter().enumerate() {
            for (ci, c) in part.contours.iter().enumerate() {
                let r = cutroute_geometry::ContourRef {
                    part: pi,
                    contour: ci,
                };
                assert_eq!(c.validate(), Ok(()), "{file} {r:?}");
                // Material on the right: even depth clockwise, odd depth counter-clockwise.
                let depth = forest.depth(r).unwrap();
                assert_eq!(c.is_clockwise(), depth.is_multiple_of(2), "{file} {r:?}");
                if ci > 0 {
                    // Usually the outer contour is the parent; test0 has a hole in a hole.
                    assert!(
                        forest.must_precede(
                            r,
                            cutroute_geometry::ContourRef {
                                part: pi,
                                contour: 0
                            }
                        ),
                        "{file}"
                    );
                }
            }
        }
    }
}
