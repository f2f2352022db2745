//! Hostile bytes into the DBS reader: it must return, never panic, loop or over-allocate; what
//! it accepts must survive the writer, and the writer's output must be a fixed point.
#![no_main]

use cutroute_formats::{
    detect, read_dbs, read_dbs_with, read_nest, write_dbs, DbsReadOptions, SheetDetection,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = detect(data);
    let _ = read_nest(data);
    let lenient = DbsReadOptions {
        sheet: SheetDetection::FirstPart,
        check_self_intersection: false,
        closure_tolerance: 1.0,
        max_vertices: 100_000,
    };
    let _ = read_dbs_with(data, &lenient);
    if let Ok(file) = read_dbs(data) {
        if let Ok(bytes) = write_dbs(&file.nest) {
            // Rounding to float32 may legitimately make a rewritten contour invalid, but a file
            // the reader accepts must be written back byte for byte.
            if let Ok(again) = read_dbs(&bytes) {
                let rewritten =
                    write_dbs(&again.nest).expect("a nest read from our own output writes");
                assert!(
                    rewritten == bytes,
                    "write(read(write(read(f)))) != write(read(f))"
                );
            }
        }
    }
});
