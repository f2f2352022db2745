//! Bad input for every reader: each failure is a typed error naming what is wrong and where.
//! DBS files are assembled record by record here so each defect is exactly one change.

use cutroute_formats::*;
use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};

// ---------------------------------------------------------------- DBS record builders

const IDENTITY: [f32; 6] = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0];

fn slot(v: i16) -> [u8; 4] {
    let b = v.to_le_bytes();
    [b[0], b[1], 0, 0]
}

fn header(payload: usize, record_type: i16, id: i16) -> Vec<u8> {
    let size = ((16 + payload - 4) / 4) as i16;
    let mut out = Vec::new();
    out.extend_from_slice(&size.to_le_bytes());
    out.extend_from_slice(&id.to_le_bytes());
    out.extend_from_slice(&slot(size));
    out.extend_from_slice(&slot(record_type));
    out.extend_from_slice(&slot(id));
    out
}

fn contour_record(
    record_type: i16,
    id: i16,
    part: i16,
    original: i16,
    rev: i16,
    m: [f32; 6],
    points: &[[f32; 3]],
) -> Vec<u8> {
    let mut out = header(48 + 12 * points.len(), record_type, id);
    for v in [1, 0, 0, part, original, rev] {
        out.extend_from_slice(&slot(v));
    }
    for v in m {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for p in points {
        for v in p {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

fn geometry(id: i16, part: i16, points: &[[f32; 3]]) -> Vec<u8> {
    contour_record(1, id, part, id, 0, IDENTITY, points)
}

fn copy(id: i16, part: i16, original: i16, rev: i16, m: [f32; 6]) -> Vec<u8> {
    contour_record(2, id, part, original, rev, m, &[])
}

fn part(id: i16, contours: &[i16]) -> Vec<u8> {
    let mut out = header(4 * contours.len(), 8, id);
    for &c in contours {
        out.extend_from_slice(&slot(c));
    }
    out
}

fn name(id: i16, text: &str) -> Vec<u8> {
    let mut plain = [b' '; 8];
    plain[..text.len()].copy_from_slice(text.as_bytes());
    let mut out = header(8, 26, id);
    out.extend((0..8).map(|i| plain[i ^ 1]));
    out
}

const END: [u8; 4] = [0xFF; 4];

fn file(records: &[Vec<u8>]) -> Vec<u8> {
    let mut out: Vec<u8> = records.concat();
    out.extend_from_slice(&END);
    out
}

/// A clockwise 10 × 10 square stored with its closing point; the arc-free basis of most cases.
fn square(x: f32, y: f32) -> Vec<[f32; 3]> {
    vec![
        [x, y, 0.0],
        [x, y + 10.0, 0.0],
        [x + 10.0, y + 10.0, 0.0],
        [x + 10.0, y, 0.0],
        [x, y, 0.0],
    ]
}

/// A half-disc: straight diameter then a clockwise half circle back.
fn half_disc() -> Vec<[f32; 3]> {
    vec![[0.0, 0.0, 0.0], [0.0, 10.0, -1.0], [0.0, 0.0, 0.0]]
}

fn dbs_err(bytes: &[u8]) -> DbsError {
    match read_dbs(bytes) {
        Ok(f) => panic!("expected an error, read {f:?}"),
        Err(e) => e,
    }
}

// ---------------------------------------------------------------- DBS: valid edge cases

#[test]
fn forward_references_resolve() {
    // The part record comes first and names contours written after it.
    let bytes = file(&[
        part(3, &[1, 2]),
        name(3, "FWD"),
        geometry(1, -3, &square(0.0, 0.0)),
        geometry(
            2,
            3,
            &square(2.0, 2.0)[..]
                .iter()
                .rev()
                .copied()
                .collect::<Vec<_>>(),
        ),
    ]);
    let f = read_dbs(&bytes).unwrap();
    assert_eq!(f.nest.parts.len(), 1);
    assert_eq!(f.nest.parts[0].name, "FWD");
    assert_eq!(f.nest.parts[0].contours.len(), 2);
}

#[test]
fn copies_apply_matrix_offset_mirror_and_reversal() {
    let base = half_disc();
    // Rotation by 90° plus offset; a mirror in x; a reversed plain translation.
    let rotate = [0.0, 1.0, -1.0, 0.0, 100.0, 0.0];
    let mirror = [-1.0, 0.0, 0.0, 1.0, 0.0, 50.0];
    let shift = [1.0, 0.0, 0.0, 1.0, 20.0, 0.0];
    let bytes = file(&[
        geometry(1, -2, &base),
        part(2, &[1]),
        copy(3, -4, 1, 0, rotate),
        part(4, &[3]),
        copy(5, -6, 1, 0, mirror),
        part(6, &[5]),
        copy(7, -8, 1, 1, shift),
        part(8, &[7]),
    ]);
    let f = read_dbs_with(
        &bytes,
        &DbsReadOptions {
            sheet: SheetDetection::None,
            ..Default::default()
        },
    )
    .unwrap();
    let parts = &f.nest.parts;
    assert_eq!(parts.len(), 4);
    let v = |p: usize| parts[p].contours[0].vertices.clone();
    assert_eq!(
        v(0),
        vec![Vertex::arc(0.0, 0.0, 0.0), Vertex::arc(0.0, 10.0, -1.0)]
    );
    // (x, y) → (−y + 100, x): bulges keep their sign (determinant +1).
    assert_eq!(
        v(1),
        vec![Vertex::arc(100.0, 0.0, 0.0), Vertex::arc(90.0, 0.0, -1.0)]
    );
    // (x, y) → (−x, y + 50): a mirror flips bulges.
    assert_eq!(v(2)[1], Vertex::arc(0.0, 60.0, 1.0));
    assert_eq!(v(2)[0].point, Point::new(0.0, 50.0));
    // Reversed after the shift: start at the old first point, run the half circle backwards.
    assert_eq!(
        v(3),
        vec![Vertex::arc(20.0, 0.0, 1.0), Vertex::arc(20.0, 10.0, 0.0)]
    );
    // The area is that of the half disc in every copy.
    let half = std::f64::consts::PI * 25.0 / 2.0;
    for p in parts {
        assert!((part_area(p) - half).abs() < 1e-9);
    }
}

#[test]
fn a_copy_of_a_copy_composes_the_maps() {
    let shift = [1.0, 0.0, 0.0, 1.0, 5.0, 0.0];
    let bytes = file(&[
        geometry(1, -2, &square(0.0, 0.0)),
        part(2, &[1]),
        copy(3, -5, 4, 0, shift),
        copy(4, -6, 1, 0, shift),
        part(5, &[3]),
        part(6, &[4]),
    ]);
    let f = read_dbs_with(
        &bytes,
        &DbsReadOptions {
            sheet: SheetDetection::None,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(
        f.nest.parts[1].contours[0].vertices[0].point,
        Point::new(10.0, 0.0)
    );
    assert_eq!(
        f.nest.parts[2].contours[0].vertices[0].point,
        Point::new(5.0, 0.0)
    );
}

#[test]
fn unknown_record_types_are_skipped_by_size() {
    let mut note = header(20, 28, 2);
    note.extend_from_slice(&[b'x'; 20]);
    let bytes = file(&[geometry(1, -2, &square(0.0, 0.0)), note, part(2, &[1])]);
    let f = read_dbs(&bytes).unwrap();
    assert_eq!(f.skipped_records, 1);
    assert_eq!(f.nest.parts.len(), 1);
}

#[test]
fn an_empty_file_is_an_empty_nest() {
    let f = read_dbs(&END).unwrap();
    assert_eq!(f.nest, Nest::default());
}

// ---------------------------------------------------------------- DBS: each defect

#[test]
fn size_copy_mismatch_is_reported_at_the_record() {
    let mut bytes = file(&[geometry(1, -2, &square(0.0, 0.0)), part(2, &[1])]);
    let second = 16 + 48 + 12 * 5;
    bytes[second + 4] = 9;
    assert_eq!(
        dbs_err(&bytes),
        DbsError::SizeMismatch {
            offset: second,
            size: 4,
            size_copy: 9
        }
    );
}

#[test]
fn a_huge_size_is_an_overrun_not_an_allocation() {
    let mut bytes = file(&[geometry(1, -2, &square(0.0, 0.0)), part(2, &[1])]);
    bytes[0..2].copy_from_slice(&i16::MAX.to_le_bytes());
    bytes[4..6].copy_from_slice(&i16::MAX.to_le_bytes());
    let e = dbs_err(&bytes);
    assert_eq!(
        e,
        DbsError::RecordOverrun {
            offset: 0,
            claimed: 131072,
            available: bytes.len()
        }
    );
    assert!(e.to_string().contains("byte 0"));
}

#[test]
fn every_truncation_is_an_error() {
    let bytes = file(&[
        geometry(1, -3, &half_disc()),
        geometry(2, 3, &square(1.0, 1.0)),
        part(3, &[1, 2]),
        name(3, "T"),
    ]);
    assert!(read_dbs(&bytes).is_ok());
    // The end record needs only its first int16 (bit 0x8000), so cutting the marker to two bytes
    // still reads; anything shorter does not.
    for cut in 0..bytes.len() - 2 {
        let e = read_dbs(&bytes[..cut]).expect_err("a truncated file must not read");
        assert!(
            matches!(
                e,
                DbsError::Truncated { .. } | DbsError::RecordOverrun { .. }
            ),
            "cut at {cut}: {e}"
        );
    }
    assert_eq!(
        dbs_err(&bytes[..bytes.len() - 4]),
        DbsError::Truncated {
            offset: bytes.len() - 4,
            expected: "a record header or the end record"
        }
    );
}

#[test]
fn non_finite_coordinates_are_reported_with_their_offset() {
    let mut pts = square(0.0, 0.0);
    pts[2][1] = f32::NAN;
    let bytes = file(&[geometry(1, -2, &pts), part(2, &[1])]);
    assert_eq!(
        dbs_err(&bytes),
        DbsError::NonFinite {
            offset: 64 + 2 * 12 + 4,
            what: "point y"
        }
    );
    pts[2][1] = 1.0;
    pts[3][2] = f32::INFINITY;
    let bytes = file(&[geometry(1, -2, &pts), part(2, &[1])]);
    assert_eq!(
        dbs_err(&bytes),
        DbsError::NonFinite {
            offset: 64 + 3 * 12 + 8,
            what: "point bulge"
        }
    );
    let bytes = file(&[
        geometry(1, -2, &square(0.0, 0.0)),
        copy(3, -4, 1, 0, [1.0, 0.0, 0.0, f32::NAN, 0.0, 0.0]),
        part(4, &[3]),
    ]);
    assert_eq!(
        dbs_err(&bytes),
        DbsError::NonFinite {
            offset: 124 + 52,
            what: "transformation matrix"
        }
    );
}

#[test]
fn an_unclosed_contour_is_rejected() {
    let mut pts = square(0.0, 0.0);
    pts[4] = [0.0, 0.01, 0.0];
    let e = dbs_err(&file(&[geometry(1, -2, &pts), part(2, &[1])]));
    match e {
        DbsError::BadContour {
            offset: 0,
            id: 1,
            problem: ContourProblem::Unclosed { gap },
        } => assert!((gap - 0.01).abs() < 1e-6),
        other => panic!("{other}"),
    }
    // Within 1e-3 mm it counts as closed.
    pts[4] = [0.0, 0.0005, 0.0];
    assert!(read_dbs(&file(&[geometry(1, -2, &pts), part(2, &[1])])).is_ok());
}

#[test]
fn a_self_intersecting_contour_is_rejected() {
    let bow = vec![
        [0.0, 0.0, 0.0],
        [10.0, 10.0, 0.0],
        [10.0, 0.0, 0.0],
        [0.0, 10.0, 0.0],
        [0.0, 0.0, 0.0],
    ];
    let e = dbs_err(&file(&[geometry(1, -2, &bow), part(2, &[1])]));
    assert_eq!(
        e,
        DbsError::BadContour {
            offset: 0,
            id: 1,
            problem: ContourProblem::SelfIntersecting {
                first_span: 0,
                second_span: 2,
                x: 5.0,
                y: 5.0
            }
        }
    );
    assert!(e.to_string().contains("intersects itself"));
    // The check can be switched off.
    let lenient = DbsReadOptions {
        check_self_intersection: false,
        ..Default::default()
    };
    assert!(read_dbs_with(&file(&[geometry(1, -2, &bow), part(2, &[1])]), &lenient).is_ok());
}

#[test]
fn a_degenerate_contour_is_rejected() {
    let e = dbs_err(&file(&[
        geometry(1, -2, &[[1.0, 1.0, 0.0], [1.0, 1.0, 0.0]]),
        part(2, &[1]),
    ]));
    assert_eq!(
        e,
        DbsError::BadContour {
            offset: 0,
            id: 1,
            problem: ContourProblem::TooFewVertices { count: 1 }
        }
    );
}

#[test]
fn a_reference_to_a_missing_record_is_rejected() {
    let sq = geometry(1, -2, &square(0.0, 0.0));
    let part_offset = sq.len();
    assert_eq!(
        dbs_err(&file(&[sq.clone(), part(2, &[1, 7])])),
        DbsError::MissingContour {
            offset: part_offset,
            id: 7
        }
    );
    let c = copy(3, -4, 9, 0, IDENTITY);
    assert_eq!(
        dbs_err(&file(&[sq, c, part(4, &[3])])),
        DbsError::MissingContour {
            offset: part_offset,
            id: 9
        }
    );
}

#[test]
fn a_cyclic_chain_of_copies_is_rejected() {
    let bytes = file(&[
        copy(1, -3, 2, 0, IDENTITY),
        copy(2, 3, 1, 0, IDENTITY),
        part(3, &[1]),
    ]);
    assert!(matches!(dbs_err(&bytes), DbsError::CyclicReference { .. }));
    let selfref = file(&[copy(1, -2, 1, 0, IDENTITY), part(2, &[1])]);
    assert_eq!(
        dbs_err(&selfref),
        DbsError::CyclicReference { offset: 0, id: 1 }
    );
}

#[test]
fn a_copy_with_the_wrong_matrix_count_is_rejected() {
    // Five numbers only (size 14) and seven numbers (size 16).
    let mut short = copy(3, -4, 1, 0, IDENTITY);
    short.truncate(60);
    short[0] = 14;
    short[4] = 14;
    let sq = geometry(1, -2, &square(0.0, 0.0));
    let offset = sq.len();
    assert_eq!(
        dbs_err(&file(&[sq.clone(), short, part(4, &[3])])),
        DbsError::RecordTooShort {
            offset,
            record_type: 2,
            len: 60,
            needed: 64
        }
    );
    let mut long = copy(3, -4, 1, 0, IDENTITY);
    long.extend_from_slice(&1f32.to_le_bytes());
    long[0] = 16;
    long[4] = 16;
    assert_eq!(
        dbs_err(&file(&[sq, long, part(4, &[3])])),
        DbsError::CopyMatrixSize { offset, size: 16 }
    );
}

#[test]
fn copies_scaling_past_f64_range_are_rejected() {
    // Each copy scales its original by 1e38; nine levels overflow f64 (max ≈ 1.8e308).
    let big = [1e38, 0.0, 0.0, 1e38, 0.0, 0.0];
    let mut records = vec![geometry(1, -2, &square(1.0, 1.0)), part(2, &[1])];
    for id in 3..12 {
        records.push(copy(id, -20, id - 1 - i16::from(id == 3), 0, big));
    }
    let offset = records[..records.len() - 1]
        .iter()
        .map(Vec::len)
        .sum::<usize>();
    records.push(part(20, &[11]));
    let e = dbs_err(&file(&records));
    assert_eq!(
        e,
        DbsError::NonFinite {
            offset,
            what: "contour point after the copy transformation"
        }
    );
}

#[test]
fn a_singular_matrix_is_rejected() {
    let sq = geometry(1, -2, &square(0.0, 0.0));
    let offset = sq.len();
    let flat = copy(3, -4, 1, 0, [1.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
    assert_eq!(
        dbs_err(&file(&[sq, flat, part(4, &[3])])),
        DbsError::SingularMatrix { offset }
    );
}

#[test]
fn ids_must_be_unique_and_non_negative() {
    let sq = geometry(1, -2, &square(0.0, 0.0));
    let len = sq.len();
    assert_eq!(
        dbs_err(&file(&[sq.clone(), sq.clone(), part(2, &[1])])),
        DbsError::DuplicateId {
            offset: len,
            id: 1,
            other: "another contour record"
        }
    );
    assert_eq!(
        dbs_err(&file(&[sq.clone(), part(1, &[1])])),
        DbsError::DuplicateId {
            offset: len,
            id: 1,
            other: "a contour record"
        }
    );
    assert_eq!(
        dbs_err(&file(&[sq.clone(), part(2, &[-1])])),
        DbsError::NegativeId {
            offset: len + 16,
            id: -1
        }
    );
    assert_eq!(
        dbs_err(&file(&[sq, part(2, &[])])),
        DbsError::EmptyPart { offset: len, id: 2 }
    );
}

#[test]
fn copies_cannot_blow_up_the_nest() {
    // 200 copies of one contour in one part, against a budget of 500 vertices.
    let mut records = vec![geometry(1, -2, &square(0.0, 0.0))];
    let ids: Vec<i16> = (0..200).map(|k| 10 + k).collect();
    for &id in &ids {
        records.push(copy(id, 2, 1, 0, IDENTITY));
    }
    records.push(part(2, &ids));
    let options = DbsReadOptions {
        max_vertices: 500,
        check_self_intersection: false,
        ..Default::default()
    };
    assert!(matches!(
        read_dbs_with(&file(&records), &options),
        Err(DbsError::TooManyVertices { limit: 500, .. })
    ));
}

#[test]
fn flipping_any_byte_of_a_real_file_never_panics() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/nests/dbs/ring.dbs");
    let bytes = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("required data file {} is missing: {e}", path.display()));
    for at in 0..bytes.len() {
        for mask in [0x01u8, 0x80, 0xFF] {
            let mut b = bytes.clone();
            b[at] ^= mask;
            let _ = read_dbs(&b);
        }
    }
}

// ---------------------------------------------------------------- DBS writer

#[test]
fn the_writer_refuses_what_dbs_cannot_hold() {
    let square = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(0.0, 1.0),
        Vertex::line(1.0, 1.0),
        Vertex::line(1.0, 0.0),
    ]);
    let nest = |name: &str, c: Contour| Nest {
        sheet: None,
        parts: vec![Part {
            name: name.into(),
            contours: vec![c],
        }],
    };
    assert_eq!(
        write_dbs(&nest("NINECHARS", square.clone())),
        Err(DbsWriteError::NameNotRepresentable {
            part: 0,
            name: "NINECHARS".into()
        })
    );
    let cut = write_dbs_with(
        &nest("NINECHARS", square.clone()),
        &DbsWriteOptions {
            truncate_long_names: true,
        },
    )
    .unwrap();
    assert_eq!(read_dbs(&cut).unwrap().nest.parts[0].name, "NINECHAR");
    let mut bad = square.clone();
    bad.vertices[1].point.y = f64::NAN;
    assert_eq!(
        write_dbs(&nest("X", bad)),
        Err(DbsWriteError::NotRepresentable {
            part: 0,
            contour: 0,
            vertex: 1
        })
    );
    assert_eq!(
        write_dbs(&Nest {
            sheet: None,
            parts: vec![Part::default()]
        }),
        Err(DbsWriteError::EmptyPart { part: 0 })
    );
}

// ---------------------------------------------------------------- JSON readers

#[test]
fn geometry_json_syntax_errors_give_line_and_column() {
    let e = read_geometry_json(b"[{\"partid\": \"A\",\n  \"paths\": [[[0, 0, 0] [1, 1]]]}]")
        .unwrap_err();
    match e {
        JsonError::Syntax {
            line: 2, column, ..
        } => assert!(column > 10),
        other => panic!("{other}"),
    }
}

#[test]
fn geometry_json_schema_errors_give_the_path() {
    let e = read_geometry_json(br#"[{"partid": "A", "paths": [[[0, 0], [1, "x"]]]}]"#).unwrap_err();
    match &e {
        JsonError::Schema { path, .. } => assert_eq!(path, "[0].paths[0][1][1]"),
        other => panic!("{other}"),
    }
    let e = read_geometry_json(br#"[{"paths": []}]"#).unwrap_err();
    assert!(
        matches!(&e, JsonError::Schema { message, .. } if message.contains("partid")),
        "{e}"
    );
    assert_eq!(
        read_geometry_json(b"[]").unwrap_err(),
        JsonError::TooShort {
            path: ".".into(),
            len: 0,
            min: 1
        }
    );
    assert_eq!(
        read_geometry_json(br#"[{"partid": "A", "paths": [[[0, 0], [1, 1, 0, 9], [0, 0]]]}]"#)
            .unwrap_err(),
        JsonError::BadPoint {
            path: "[0].paths[0][1]".into(),
            len: 4
        }
    );
    assert_eq!(
        read_geometry_json(br#"[{"partid": "A", "paths": [[[0, 0]]]}]"#).unwrap_err(),
        JsonError::TooShort {
            path: "[0].paths[0]".into(),
            len: 1,
            min: 2
        }
    );
}

#[test]
fn geometry_json_numbers_out_of_range_are_errors() {
    let e = read_geometry_json(br#"[{"partid": "A", "paths": [[[0, 1e999], [1, 1], [0, 0]]]}]"#)
        .unwrap_err();
    assert!(
        matches!(
            e,
            JsonError::Syntax { line: 1, .. } | JsonError::Schema { .. }
        ),
        "{e}"
    );
}

#[test]
fn geometry_json_bad_contours_give_their_path() {
    let unclosed = br#"[{"partid": "S", "paths": [[[0,0],[0,9],[9,9],[9,0],[0,0]]]},
                        {"partid": "A", "paths": [[[0,0],[0,1],[1,1],[1,0],[0.5,0]]]}]"#;
    match read_geometry_json(unclosed).unwrap_err() {
        JsonError::BadContour {
            path,
            problem: ContourProblem::Unclosed { gap },
        } => {
            assert_eq!(path, "[1].paths[0]");
            assert!((gap - 0.5).abs() < 1e-12);
        }
        other => panic!("{other}"),
    }
    let bow = br#"[{"partid": "A", "paths": [[[0,0],[10,10],[10,0],[0,10],[0,0]]]}]"#;
    assert_eq!(
        read_geometry_json(bow).unwrap_err(),
        JsonError::BadContour {
            path: "[0].paths[0]".into(),
            problem: ContourProblem::SelfIntersecting {
                first_span: 0,
                second_span: 2,
                x: 5.0,
                y: 5.0
            }
        }
    );
}

fn task_json(point_extra: &str, contour_index: i64) -> String {
    format!(
        r#"{{"TaskData": {{"StartX": 0, "StartY": 0, "TerminalMotion": true, "FinishX": 0, "FinishY": 0,
            "SheetMinX": 0, "SheetMaxX": 10, "SheetMinY": 0, "SheetMaxY": 10,
            "ToolIdlingSpeed": 500, "ToolCutSpeed": 10, "PiercingDuration": 7}},
          "Contours": [{{"Index": {contour_index}, "ZeroBasedIndex": 0, "Points": [
            {{"Index": 1, "ZeroBasedIndex": 0, "GlobalIndex": 1, "ZeroBasedGlobalIndex": 0,
              "X": 1, "Y": 2, "UseCircuitAndFinishCutPoint": false{point_extra}}}]}}]}}"#
    )
}

#[test]
fn task_json_errors_name_the_path() {
    assert!(read_task_json(task_json("", 1).as_bytes()).is_ok());
    let ext = ", \"CircuitPointX\": 1, \"CircuitPointY\": 2, \"FinishCutX\": 1, \"FinishCutY\": 2";
    assert_eq!(
        read_task_json(task_json(ext, 1).as_bytes())
            .unwrap()
            .contours[0]
            .points[0]
            .finish_cut_y,
        Some(2.0)
    );
    match read_task_json(task_json(", \"Z\": 3", 1).as_bytes()).unwrap_err() {
        JsonError::Schema { path, message, .. } => {
            assert_eq!(path, "Contours[0].Points[0].Z");
            assert!(message.contains("unknown field `Z`"), "{message}");
        }
        other => panic!("{other}"),
    }
    match read_task_json(task_json("", 5).as_bytes()).unwrap_err() {
        JsonError::Inconsistent { path, .. } => assert_eq!(path, "Contours[0].Index"),
        other => panic!("{other}"),
    }
    let missing = task_json("", 1).replace("\"ToolCutSpeed\": 10,", "");
    assert!(
        matches!(read_task_json(missing.as_bytes()).unwrap_err(), JsonError::Schema { path, .. } if path == "TaskData")
    );
    let empty = r#"{"TaskData": {"StartX": 0, "StartY": 0, "TerminalMotion": false, "FinishX": 0, "FinishY": 0,
        "SheetMinX": 0, "SheetMaxX": 1, "SheetMinY": 0, "SheetMaxY": 1, "ToolIdlingSpeed": 1, "ToolCutSpeed": 1,
        "PiercingDuration": 0}, "Contours": []}"#;
    assert_eq!(
        read_task_json(empty.as_bytes()).unwrap_err(),
        JsonError::TooShort {
            path: "Contours".into(),
            len: 0,
            min: 1
        }
    );
}

#[test]
fn deeply_nested_json_is_an_error_not_a_stack_overflow() {
    let mut deep = String::new();
    for _ in 0..100_000 {
        deep.push_str("{\"NestedContours\": [");
    }
    assert!(read_task_json(deep.as_bytes()).is_err());
    let brackets = "[".repeat(100_000);
    assert!(matches!(
        read_geometry_json(brackets.as_bytes()).unwrap_err(),
        JsonError::Syntax { .. } | JsonError::Schema { .. }
    ));
}

fn result_json(mode: &str) -> String {
    format!(
        r#"{{"job": {{"paths.count": 1, "parts.count": 1, "total.points.count": 1, "total.address.pairs.count": 0,
              "list": [[0,0,0],[0,9,0],[9,9,0],[9,0,0],[0,0,0]],
              "paths": [{{"part.id": 1, "id": 0, "points": [[1,1,0],[1,2,0],[2,2,0],[2,1,0],[1,1,0]]}}]}},
           "results": {{"result": 1, "route.length.no.contours": 2, "route.length": 6, "count.time": "00:00:00.000",
              "toolpath": [{{"point.id": 0, "mode": "air", "point": [0,0,0]}},
                           {{"point.id": 1, "mode": "{mode}", "part.id": 1, "id": 0, "point": [1,1,0]}},
                           {{"point.id": 2, "mode": "air", "point": [1,2,0]}}]}}}}"#
    )
}

#[test]
fn result_json_errors_name_the_path() {
    assert!(read_result_json(result_json("cut").as_bytes()).is_ok());
    assert!(read_result_json(result_json("cut.in").as_bytes()).is_ok());
    match read_result_json(result_json("fly").as_bytes()).unwrap_err() {
        JsonError::Schema { path, message, .. } => {
            assert_eq!(path, "results.toolpath[1].mode");
            assert!(message.contains("fly"), "{message}");
        }
        other => panic!("{other}"),
    }
    let two_numbers = result_json("cut").replace("\"point\": [1,2,0]", "\"point\": [1,2]");
    assert!(
        matches!(read_result_json(two_numbers.as_bytes()).unwrap_err(), JsonError::Schema { path, .. } if path == "results.toolpath[2].point")
    );
    let short =
        result_json("cut").replace("[[1,1,0],[1,2,0],[2,2,0],[2,1,0],[1,1,0]]", "[[1,1,0]]");
    assert_eq!(
        read_result_json(short.as_bytes()).unwrap_err(),
        JsonError::TooShort {
            path: "job.paths[0].points".into(),
            len: 1,
            min: 2
        }
    );
    let unclosed = result_json("cut").replace("[2,1,0],[1,1,0]]", "[2,1,0],[1,1.5,0]]");
    let parsed = read_result_json(unclosed.as_bytes()).unwrap();
    assert!(
        matches!(parsed.nest().unwrap_err(), JsonError::BadContour { path, .. } if path == "job.paths[0].points")
    );
}

#[test]
fn route_errors_name_the_step() {
    let nest = read_geometry_json(br#"[{"partid": "S", "paths": [[[0,0],[0,9],[9,9],[9,0],[0,0]]]},
                                      {"partid": "A", "paths": [[[1,1],[1,2],[2,2],[2,1],[1,1]]]}]"#)
    .unwrap();
    let route = cutroute_geometry::Route {
        start: Point::default(),
        steps: vec![cutroute_geometry::CutStep {
            contour: cutroute_geometry::ContourRef {
                part: 0,
                contour: 3,
            },
            pierce_point: Point::new(1.0, 1.5),
            entry: Default::default(),
            leads: None,
        }],
        finish: None,
    };
    assert_eq!(
        route_moves(&nest, &route),
        Err(RouteError::NoSuchContour {
            step: 0,
            part: 0,
            contour: 3
        })
    );
}

#[test]
fn read_nest_reports_formats_it_does_not_own() {
    assert_eq!(
        read_nest(b"  0\nSECTION\n  2\nENTITIES\n"),
        Err(ReadError::Unsupported(Format::Dxf))
    );
    assert_eq!(
        read_nest(b"hello"),
        Err(ReadError::Unsupported(Format::Unknown))
    );
    assert_eq!(read_nest(b""), Err(ReadError::Unsupported(Format::Unknown)));
    assert!(matches!(
        read_nest(b"[{\"partid\": 1}]"),
        Err(ReadError::Json(JsonError::Schema { .. }))
    ));
    let mut dbs = file(&[geometry(1, -2, &square(0.0, 0.0)), part(2, &[1])]);
    dbs.truncate(30);
    assert!(matches!(
        read_nest(&dbs),
        Err(ReadError::Dbs(DbsError::RecordOverrun { offset: 0, .. }))
    ));
}

#[test]
fn json_has_no_nan_or_infinity() {
    for bad in ["NaN", "Infinity", "-Infinity", "nan"] {
        let text = format!(r#"[{{"partid": "A", "paths": [[[0, {bad}], [1, 1], [0, 0]]]}}]"#);
        assert!(
            matches!(
                read_geometry_json(text.as_bytes()).unwrap_err(),
                JsonError::Syntax { line: 1, .. }
            ),
            "{bad}"
        );
    }
}

#[test]
fn two_number_points_default_the_bulge_to_zero() {
    let nest = read_geometry_json(
        br#"[{"partid": "S", "paths": [[[0, 0], [0, 9, 0], [9, 9], [9, 0], [0, 0]]]}]"#,
    )
    .unwrap();
    let sheet = nest.sheet.unwrap();
    assert_eq!(sheet.contours[0].vertices.len(), 4);
    assert!(sheet.contours[0].vertices.iter().all(|v| v.bulge == 0.0));
    assert!(nest.parts.is_empty());
}

/// A nest format refuses what is not a cuttable contour, located: a slit drawn out and back
/// and a bow-tie; a byte-order mark is not an error.
#[test]
fn geometry_json_refuses_slits_and_bow_ties_and_accepts_a_bom() {
    let sheet = "[[0,0,0],[0,500,0],[700,500,0],[700,0,0],[0,0,0]]";
    let file = |contour: &str| {
        format!(r#"[{{"partid":"LIST","paths":[{sheet}]}},{{"partid":"P","paths":[{contour}]}}]"#)
    };
    let slit = file("[[10,10,0],[20,10,0],[10,10,0]]");
    let e = cutroute_formats::read_geometry_json(slit.as_bytes()).unwrap_err();
    assert!(e.to_string().contains("[1].paths[0]"), "{e}");
    assert!(e.to_string().contains("slit"), "{e}");
    let bow_tie = file("[[0,0,0],[10,10,0],[10,0,0],[0,4,0],[0,0,0]]");
    let e = cutroute_formats::read_geometry_json(bow_tie.as_bytes()).unwrap_err();
    assert!(e.to_string().contains("intersects itself"), "{e}");
    let square = file("[[10,10,0],[10,20,0],[20,20,0],[20,10,0],[10,10,0]]");
    let with_bom = [b"\xEF\xBB\xBF".as_slice(), square.as_bytes()].concat();
    assert_eq!(
        cutroute_formats::detect(&with_bom),
        cutroute_formats::Format::GeometryJson
    );
    let nest = cutroute_formats::read_geometry_json(&with_bom).unwrap();
    assert_eq!(nest.parts.len(), 1);
}

/// Writers keep what they write: a bulge of 9999 survives DBS within 1e-6 of its perimeter,
/// and a bulge of 1e-13 becomes an SVG line instead of a radius no reader accepts.
#[test]
fn extreme_bulges_survive_dbs_and_svg() {
    use cutroute_geometry::{Contour, Nest, Part, Vertex};
    let part = |contour: Contour| Nest {
        sheet: None,
        parts: vec![Part {
            name: "P".into(),
            contours: vec![contour],
        }],
    };
    let nearly_full = part(Contour::new(vec![
        Vertex::arc(100.0, 100.0, 9999.0),
        Vertex::line(100.01, 100.0),
    ]));
    let back = cutroute_formats::read_dbs(&cutroute_formats::write_dbs(&nearly_full).unwrap())
        .unwrap()
        .nest;
    let (before, after) = (nearly_full.parts[0].perimeter(), back.parts[0].perimeter());
    assert!(
        (after - before).abs() <= 1e-6 * before,
        "{before} → {after}"
    );
    let flat = part(Contour::new(vec![
        Vertex::arc(0.0, 0.0, 1e-13),
        Vertex::line(0.0, 10.0),
        Vertex::line(10.0, 10.0),
    ]));
    let svg = cutroute_formats::nest_svg(&flat, None, &cutroute_formats::SvgOptions::default());
    assert!(!svg.contains(" A"), "{svg}");
}
