//! Fuzz target: the edge-list reader must never panic, and whatever it accepts must survive the
//! writer, and the chain construction must answer (a chain that passes the checker, or an error).
#![no_main]

use cutroute_aoe::{aoe_chain, check_chain, check_route, edge_list, oe_route, AoeOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(embedding) = edge_list::read(text) else {
        return;
    };
    let written = edge_list::write(&embedding).expect("the reader rejects loops");
    let again = edge_list::read(&written).expect("written text must read");
    assert_eq!(again.graph(), embedding.graph());
    for start in embedding.outer_vertices() {
        if let Ok(chain) = aoe_chain(&embedding, start, &AoeOptions::default()) {
            check_chain(&embedding, &chain.darts).expect("a returned chain is an AOE-chain");
        }
    }
    let route = oe_route(&embedding);
    check_route(&embedding, &route.chains).expect("an OE-route");
});
