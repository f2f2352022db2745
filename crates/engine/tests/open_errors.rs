//! Open errors as the protocol's data: the kind, the location from the reader's typed error and
//! the English text the CLI prints, for one file of each reader.

use std::path::PathBuf;

use cutroute_engine::open_document;
use cutroute_protocol::{OpenErrorKind, SourceLocation};

fn data(relative: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn refused(name: &str, bytes: &[u8]) -> cutroute_protocol::OpenError {
    let error = open_document(name, bytes).expect_err("the file is refused");
    let report = error.report();
    assert_eq!(
        report.message,
        error.to_string(),
        "the CLI's words ride along"
    );
    assert_eq!(report.file_name, name);
    report
}

#[test]
fn a_truncated_dbs_is_located_by_byte() {
    let bytes = data("nests/dbs/nested.dbs");
    let report = refused("cut.dbs", &bytes[..700]);
    assert_eq!(
        report.kind,
        OpenErrorKind::Unreadable {
            format: "DBS binary".into()
        }
    );
    assert_eq!(report.location, Some(SourceLocation::Byte { offset: 696 }));
    assert!(
        report.detail.starts_with("DBS truncated at byte 696"),
        "{}",
        report.detail
    );
}

#[test]
fn malformed_json_is_located_by_line_and_column() {
    let report = refused("broken.json", b"{\n  \"a\": [1, 2,\n");
    assert_eq!(report.kind, OpenErrorKind::MalformedJson);
    assert!(
        matches!(
            report.location,
            Some(SourceLocation::Line {
                line: 3,
                column: Some(_)
            })
        ),
        "{:?}",
        report.location
    );
    assert!(
        report.detail.starts_with("malformed JSON: "),
        "{}",
        report.detail
    );
    assert!(report
        .message
        .starts_with("broken.json (JSON): line 3 column "));
}

#[test]
fn xml_json_path_and_text_readers_give_their_places() {
    let tflex = refused(
        "t.tfnesting",
        &data("hostile/tflex_truncated_location_1_1.tfnesting"),
    );
    assert_eq!(
        tflex.location,
        Some(SourceLocation::Line {
            line: 349,
            column: Some(10)
        })
    );
    let json = refused(
        "g.dbs.json",
        &data("hostile/huge_coords_null_lengths.dbs.json"),
    );
    assert_eq!(
        json.location,
        Some(SourceLocation::JsonPath {
            path: "[1].paths[0]".into()
        })
    );
    let pcgtsp = refused(
        "w.pcglns",
        &data("hostile/pcgtsp_weights_1e308_bad_tour.pcglns"),
    );
    assert_eq!(
        pcgtsp.location,
        Some(SourceLocation::Line {
            line: 8,
            column: None
        })
    );
    let gcode = refused("p.nc", b"G90\nG01 X1 Y1 Q\n");
    assert_eq!(gcode.kind, OpenErrorKind::Gcode);
    assert!(
        matches!(
            gcode.location,
            Some(SourceLocation::Line {
                line: 2,
                column: Some(_)
            })
        ),
        "{gcode:?}"
    );
}

#[test]
fn errors_without_a_place_have_none() {
    let report = refused("notes.txt", b"just some words");
    assert_eq!(report.kind, OpenErrorKind::UnknownFormat);
    assert_eq!(report.location, None);
    assert!(report.detail.is_empty());
}
