//! Equidistants of the real nests' contours: every contour with room offsets to one loop at
//! the kerf's half-widths a plasma and a laser use, each vertex at the offset's distance
//! within 1 µm (the cleanup of near-collinear vertices moves it by up to 0.1 µm here). A
//! slot of `seven.dbs` (17 mm wide, corners of tiny segments) once split in three at 1 mm in
//! release builds, so those nests reported no room for leads.

mod common;

use cutroute_geometry::{equidistant, OffsetError};
use cutroute_protocol::Problem;

#[test]
fn the_real_nests_contours_offset_to_one_loop_each() {
    for file in [
        "nests/dbs/seven.dbs",
        "nests/dbs/seven_3717.dbs",
        "nests/dbs/nested.dbs",
        "nests/dbs/test0.json.dbs",
        "nests/tflex/Nest02.tfnesting",
    ] {
        let (name, bytes) = common::data(file);
        let document = cutroute_engine::open_document(&name, &bytes).expect("opens");
        let Problem::Nest { nest, .. } = document.problem else {
            panic!("{file}: not a nest")
        };
        for (p, part) in nest.parts.iter().enumerate() {
            for (c, contour) in part.contours.iter().enumerate() {
                for distance in [0.1, 1.0] {
                    match equidistant(contour, distance) {
                        Ok(offset) => {
                            for v in &offset.vertices {
                                let gap = contour.distance_to(v.point);
                                assert!(
                                    (gap - distance).abs() < 1e-3,
                                    "{file} part {p} contour {c} at {distance}: vertex {:?} is {gap} away",
                                    v.point
                                );
                            }
                        }
                        // A hole narrower than the kerf closes: that is no room, not an error.
                        Err(OffsetError::Vanishes { .. }) if !contour.is_clockwise() => {}
                        Err(e) => panic!("{file} part {p} contour {c} at {distance}: {e}"),
                    }
                }
            }
        }
    }
}
