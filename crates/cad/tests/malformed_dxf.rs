//! Hostile and broken DXF input: every failure is a typed error that says where, and nothing
//! panics, hangs or grows without bound.

use cutroute_cad::dxf::{read_dxf, DxfError, DxfOptions};

/// A drawing with the given entity groups; the first entity's `0` group is on line 5.
fn drawing(entities: &str) -> String {
    format!("0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
}

const SQUARE: &str =
    "0\nLWPOLYLINE\n70\n1\n10\n0\n20\n0\n10\n10\n20\n0\n10\n10\n20\n10\n10\n0\n20\n10\n";

fn read(text: &str) -> Result<cutroute_cad::dxf::DxfImport, DxfError> {
    read_dxf(text.as_bytes(), &DxfOptions::default())
}

#[test]
fn empty_and_binary_files() {
    assert_eq!(read(""), Err(DxfError::NoEntities));
    // A binary DXF is read: with nothing after its sentinel it has no sections at all.
    assert_eq!(
        read_dxf(b"AutoCAD Binary DXF\r\n\x1a\x00", &DxfOptions::default()),
        Err(DxfError::NoEntities)
    );
    // Cut inside a string (R12 one-byte codes: `0`, then "SECTION" without its NUL).
    let cut = read_dxf(
        b"AutoCAD Binary DXF\r\n\x1a\x00\x00SECTION",
        &DxfOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(cut, DxfError::BinaryDxf { offset: 23, .. }),
        "{cut}"
    );
    assert!(
        cut.to_string().starts_with("byte 23: binary DXF: "),
        "{cut}"
    );
}

#[test]
fn truncated_files_say_where() {
    let full = drawing(SQUARE);
    // Cut after a group code: its value is missing.
    let cut = &full[..full.find("10\n10\n20").unwrap() + 3];
    assert_eq!(
        read(cut),
        Err(DxfError::MissingValue { line: 13, code: 10 })
    );
    // Cut between groups: the section never ends.
    let cut = &full[..full.find("10\n10\n20").unwrap()];
    assert!(
        matches!(read(cut), Err(DxfError::Unterminated { line: 1, ref what }) if what == "section ENTITIES")
    );
}

#[test]
fn garbage_group_codes_and_numbers_are_located() {
    assert!(matches!(
        read("0\nSECTION\nxyz\nENTITIES\n"),
        Err(DxfError::BadGroupCode { line: 3, .. })
    ));
    assert!(matches!(
        read_dxf(b"\xff\xfe\x00\x01\n\x02", &DxfOptions::default()),
        Err(DxfError::BadGroupCode { line: 1, .. })
    ));
    // The corrupt coordinate of the second LINE is an error, not a silently dropped entity.
    let text =
        drawing("0\nLINE\n10\n0\n20\n0\n11\n5\n21\n0\n0\nLINE\n10\n5\n20\n0\n11\nxyz\n21\n5\n");
    assert_eq!(
        read(&text),
        Err(DxfError::BadNumber {
            line: 22,
            code: 11,
            text: "xyz".into()
        })
    );
    let text = drawing("0\nLINE\n10\nNaN\n20\n0\n11\n5\n21\n0\n");
    assert!(matches!(
        read(&text),
        Err(DxfError::BadNumber {
            line: 8,
            code: 10,
            ..
        })
    ));
    let text = drawing("0\nCIRCLE\n10\n0\n20\n0\n40\n1e300\n");
    assert!(matches!(
        read(&text),
        Err(DxfError::OutOfRange {
            line: 12,
            code: 40,
            ..
        })
    ));
}

#[test]
fn missing_groups_are_named() {
    let err = read(&drawing("0\nLINE\n10\n0\n20\n0\n")).unwrap_err();
    assert_eq!(
        err,
        DxfError::MissingGroup {
            line: 5,
            entity: "LINE".into(),
            code: 11,
            meaning: "end point"
        }
    );
    assert_eq!(err.to_string(), "line 5: LINE has no group 11 (end point)");
}

#[test]
fn absurd_splines_are_refused_without_allocating() {
    let declared =
        drawing("0\nSPLINE\n71\n3\n72\n1000000000\n73\n1000000000\n40\n0\n10\n0\n20\n0\n");
    let err = read(&declared).unwrap_err();
    assert!(
        matches!(err, DxfError::InvalidSpline { line: 5, ref reason } if reason.contains("1000000000 knots")),
        "{err}"
    );
    for degree in ["0", "-3", "1000000000"] {
        let text = drawing(&format!(
            "0\nSPLINE\n71\n{degree}\n40\n0\n40\n0\n40\n1\n40\n1\n10\n0\n20\n0\n10\n1\n20\n1\n"
        ));
        assert!(
            matches!(read(&text), Err(DxfError::InvalidSpline { line: 5, .. })),
            "degree {degree}"
        );
    }
    // Decreasing knots.
    let text =
        drawing("0\nSPLINE\n71\n1\n40\n0\n40\n1\n40\n0.5\n40\n1\n10\n0\n20\n0\n10\n1\n20\n1\n");
    assert!(
        matches!(read(&text), Err(DxfError::InvalidSpline { ref reason, .. }) if reason.contains("order"))
    );
}

#[test]
fn degenerate_entities_are_skipped_with_a_warning() {
    let text = drawing(&format!(
        "{SQUARE}0\nARC\n10\n5\n20\n5\n40\n0\n50\n0\n51\n90\n0\nLINE\n10\n1\n20\n1\n11\n1\n21\n1\n"
    ));
    let import = read(&text).unwrap();
    assert_eq!(import.nest.parts.len(), 1);
    // Besides the drawing-wide note that no units are declared.
    let lines: Vec<String> = import
        .warnings
        .iter()
        .filter(|w| w.kind != cutroute_geometry::WarningKind::Units)
        .map(|w| {
            w.place
                .as_ref()
                .map(ToString::to_string)
                .unwrap_or_default()
        })
        .collect();
    assert_eq!(lines, ["line 25", "line 37"], "{:?}", import.warnings);
    assert!(import.warnings[1].message.contains("radius 0"));
}

#[test]
fn nothing_closed_is_an_error_naming_the_chain() {
    let err = read(&drawing("0\nLINE\n10\n0\n20\n0\n11\n5\n21\n0\n")).unwrap_err();
    let DxfError::NothingClosed { open, first } = &err else {
        panic!("{err}")
    };
    assert_eq!(*open, 1);
    assert!(first.contains("LINE at line 5"), "{first}");
}

#[test]
fn block_errors() {
    let text = drawing("0\nINSERT\n2\nNOWHERE\n10\n0\n20\n0\n");
    assert_eq!(
        read(&text),
        Err(DxfError::UnknownBlock {
            line: 5,
            name: "NOWHERE".into()
        })
    );
    // A block that inserts itself.
    let cyclic = "0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n2\nLOOP\n10\n0\n20\n0\n0\nINSERT\n2\nLOOP\n0\nENDBLK\n0\nENDSEC\n\
                  0\nSECTION\n2\nENTITIES\n0\nINSERT\n2\nLOOP\n0\nENDSEC\n0\nEOF\n";
    assert!(matches!(
        read(cyclic),
        Err(DxfError::BlockNestingTooDeep { line: 13, .. })
    ));
    // A MINSERT array of a million by a million copies.
    let text = format!(
        "0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n2\nB\n{SQUARE}0\nENDBLK\n0\nENDSEC\n{}",
        drawing("0\nINSERT\n2\nB\n70\n1000000\n71\n1000000\n44\n20\n45\n20\n")
    );
    assert!(
        matches!(read(&text), Err(DxfError::InvalidEntity { ref entity, .. }) if entity == "INSERT")
    );
    // Unterminated block.
    assert!(matches!(
        read("0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n2\nB\n0\nENDSEC\n"),
        Err(DxfError::Unterminated { line: 5, .. })
    ));
}

#[test]
fn block_bomb_hits_the_budget() {
    // Six levels of blocks, each inserting the previous one ten times: 10^6 squares.
    let mut blocks = format!("0\nBLOCK\n2\nL0\n{SQUARE}0\nENDBLK\n");
    for level in 1..=6 {
        blocks.push_str(&format!("0\nBLOCK\n2\nL{level}\n"));
        for copy in 0..10 {
            blocks.push_str(&format!(
                "0\nINSERT\n2\nL{}\n10\n{}\n20\n0\n",
                level - 1,
                copy * 20
            ));
        }
        blocks.push_str("0\nENDBLK\n");
    }
    let text = format!(
        "0\nSECTION\n2\nBLOCKS\n{blocks}0\nENDSEC\n{}",
        drawing("0\nINSERT\n2\nL6\n")
    );
    let options = DxfOptions {
        max_spans: 10_000,
        ..DxfOptions::default()
    };
    assert_eq!(
        read_dxf(text.as_bytes(), &options).unwrap_err(),
        DxfError::TooComplex { limit: 10_000 }
    );
}

#[test]
fn tiny_tolerance_on_a_huge_ellipse_hits_the_budget() {
    let text = drawing("0\nELLIPSE\n10\n0\n20\n0\n11\n1000000\n21\n0\n40\n0.001\n");
    let options = DxfOptions {
        approximation_tolerance: 1e-6,
        max_spans: 1000,
        ..DxfOptions::default()
    };
    assert_eq!(
        read_dxf(text.as_bytes(), &options).unwrap_err(),
        DxfError::TooComplex { limit: 1000 }
    );
    // With the default tolerance the same ellipse imports as one closed part.
    let import = read(&text).unwrap();
    assert_eq!(import.nest.parts.len(), 1);
}

#[test]
fn invalid_options_are_refused() {
    for options in [
        DxfOptions {
            approximation_tolerance: f64::NAN,
            ..DxfOptions::default()
        },
        DxfOptions {
            approximation_tolerance: 0.0,
            ..DxfOptions::default()
        },
        DxfOptions {
            join_tolerance: -1.0,
            ..DxfOptions::default()
        },
        DxfOptions {
            max_spans: 0,
            ..DxfOptions::default()
        },
    ] {
        assert!(matches!(
            read_dxf(drawing(SQUARE).as_bytes(), &options),
            Err(DxfError::InvalidOptions(_))
        ));
    }
}

#[test]
fn coincident_pile_of_lines_stays_fast() {
    // 20 000 lines from one point: their starts pile up in one grid cell.
    let mut entities = String::from(SQUARE);
    for k in 0..20_000 {
        entities.push_str(&format!(
            "0\nLINE\n10\n50\n20\n50\n11\n60\n21\n{}\n",
            50.0 + k as f64 * 0.1
        ));
    }
    let started = std::time::Instant::now();
    let import = read(&drawing(&entities)).unwrap();
    assert_eq!(import.nest.parts.len(), 1);
    assert!(started.elapsed().as_secs() < 20);
}

#[test]
fn nested_scales_cannot_overflow() {
    // Each level scales by 1e5: three levels are 1e15, far past any sheet.
    let blocks = format!(
        "0\nBLOCK\n2\nA\n{SQUARE}0\nENDBLK\n0\nBLOCK\n2\nB\n0\nINSERT\n2\nA\n41\n1e5\n42\n1e5\n0\nENDBLK\n\
         0\nBLOCK\n2\nC\n0\nINSERT\n2\nB\n41\n1e5\n42\n1e5\n0\nENDBLK\n"
    );
    let text = format!(
        "0\nSECTION\n2\nBLOCKS\n{blocks}0\nENDSEC\n{}",
        drawing("0\nINSERT\n2\nC\n41\n1e5\n42\n1e5\n")
    );
    let err = read(&text).unwrap_err();
    assert!(
        matches!(err, DxfError::InvalidEntity { ref entity, .. } if entity == "INSERT"),
        "{err}"
    );
}
