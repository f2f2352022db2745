//! Fuzz target: the G-code reader must never panic, every error must point into the text, and
//! whatever it reads must be finite motion that the writer can write again.
#![no_main]

use cutroute_gcode::{read_gcode, write_gcode, GcodeOptions, ReadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match read_gcode(text, &ReadOptions::default()) {
        Err(e) => {
            let (line, column) = e.location();
            assert!(line >= 1 && column >= 1);
            assert!(line <= text.lines().count().max(1));
        }
        Ok(program) => {
            assert!(program.end.is_finite());
            assert!(program.idle_length().is_finite() && program.cut_length().is_finite());
            // Torch-off arcs become chords, so only the write must succeed, not a round trip.
            let _ = write_gcode(&program.toolpath(), &GcodeOptions::default());
        }
    }
});
