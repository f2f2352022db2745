//! Any bytes must give a DXF import or a typed error: no panic, no hang, bounded memory.
#![no_main]

use cutroute_cad::dxf::{read_dxf, DxfOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(import) = read_dxf(data, &DxfOptions::default()) {
        // Every part has an outer contour with at least one span.
        for part in &import.nest.parts {
            assert!(!part.contours.is_empty());
            assert!(part.contours.iter().all(|c| !c.vertices.is_empty()));
        }
    }
});
