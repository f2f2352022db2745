//! Any bytes must give T-FLEX nests or a typed error: no panic, no hang, bounded memory.
#![no_main]

use cutroute_cad::tflex::read_tfnesting;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = read_tfnesting(data);
});
