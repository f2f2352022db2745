//! Hostile bytes into the three JSON readers (and the detector, writers and conversions fed by
//! what they accept): errors are fine, panics and hangs are not.
#![no_main]

use cutroute_formats::{
    detect, nest_svg, read_geometry_json, read_nest, read_result_json, read_task_json, route_moves,
    write_geometry_json, write_result_json, write_task_json, ResultExportOptions, RmResult,
    SvgOptions,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = detect(data);
    let _ = read_nest(data);
    if let Ok(nest) = read_geometry_json(data) {
        let text = write_geometry_json(&nest).expect("finite nest writes");
        let again = read_geometry_json(text.as_bytes());
        // Our own output must read back: numbers are written in shortest round-trip form, so
        // the re-read contours are identical and pass the same checks.
        assert!(
            again.is_ok(),
            "geometry JSON written by us does not read back: {again:?}"
        );
        let _ = nest_svg(&nest, None, &SvgOptions::default());
    }
    if let Ok(task) = read_task_json(data) {
        let _ = task.flat_contours();
        let _ = task.pierce_point_count();
        if let Ok(text) = write_task_json(&task) {
            assert_eq!(read_task_json(text.as_bytes()).ok(), Some(task));
        }
    }
    if let Ok(result) = read_result_json(data) {
        let moves = result.tool_moves();
        let route = result.route();
        if let Ok(nest) = result.nest() {
            let _ = nest_svg(&nest, Some(&moves), &SvgOptions::default());
            if let Ok(ours) = RmResult::from_route(&nest, &route, &ResultExportOptions::default()) {
                let _ = write_result_json(&ours);
            }
            let _ = route_moves(&nest, &route);
        }
        let _ = write_result_json(&result);
    }
});
