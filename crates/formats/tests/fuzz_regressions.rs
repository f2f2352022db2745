//! Inputs the fuzzers (`crates/formats/fuzz`) once broke, replayed with the fuzz targets' own
//! checks so the bugs stay fixed.

use cutroute_formats::*;

fn regression(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_regressions")
        .join(name);
    std::fs::read(&path)
        .unwrap_or_else(|e| panic!("regression input {} is missing: {e}", path.display()))
}

/// The `dbs_reader` target's property: what reads is written back byte-stably. The input must
/// still read, and its rewrite must still read, so that the property is really exercised (a
/// reader that started refusing the input would otherwise pass silently).
fn assert_dbs_rewrite_is_stable(bytes: &[u8]) {
    let _ = detect(bytes);
    let _ = read_nest(bytes);
    let file = read_dbs(bytes).expect("the regression input still reads");
    let written = write_dbs(&file.nest).expect("what reads writes");
    let again = read_dbs(&written).expect("our own output reads");
    let rewritten = write_dbs(&again.nest).expect("a nest read from our own output writes");
    if rewritten != written {
        let at = rewritten.iter().zip(&written).position(|(a, b)| a != b);
        panic!(
            "rewrite differs at byte {at:?} (lengths {} vs {})",
            rewritten.len(),
            written.len()
        );
    }
}

#[test]
fn dbs_byte_stability_1() {
    assert_dbs_rewrite_is_stable(&regression("dbs-byte-stability-1.dbs"));
}
