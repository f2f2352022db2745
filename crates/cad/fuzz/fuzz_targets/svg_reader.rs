//! Any bytes must give an SVG nest or a typed error: no panic, no hang, bounded memory.
#![no_main]

use cutroute_cad::svg::{read_svg, SvgOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = read_svg(data, &SvgOptions::default());
});
