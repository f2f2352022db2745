//! The made DXF corpus (`data/made/dxf-matrix/`, written and measured by ezdxf through
//! `scripts/make-dxf-matrix.py`): every drawing case a cutting program meets — loose lines and
//! arcs, polylines with bulges and widths, ellipses, splines (rational too), block inserts
//! rotated, scaled, mirrored, scaled unevenly, nested and arrayed, planes seen from below,
//! text and hatches beside the parts, inch drawings — in every DXF version from R12 to R2018.
//! Each must read as ezdxf measures it: the contours the case draws, their total perimeter
//! and box (exactly where the drawing is lines and arcs, within 0.1 % where the reader
//! approximates), and the warnings say what was left out.

mod common;

use common::realworld::parse_csv;
use cutroute_cad::dxf::{read_dxf, DxfOptions};
use cutroute_geometry::{BoundingBox, WarningKind};
use std::path::PathBuf;

/// Relative tolerance of lines, arcs and circles: exact geometry on both sides, but for the
/// oracle's flattening (chords within 1e-5 mm).
const EXACT: f64 = 1e-6;

/// Relative tolerance where the reader approximates (ellipses, splines, circles scaled
/// unevenly), as the real-world corpus is held.
const APPROXIMATED: f64 = 1e-3;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/made/dxf-matrix")
}

#[test]
fn every_case_in_every_version_reads_as_ezdxf_measures_it() {
    let text = std::fs::read_to_string(dir().join("expected.csv")).expect("expected.csv");
    let records = parse_csv(&text);
    let (header, rows) = records.split_first().expect("a header");
    assert_eq!(
        header,
        &["file", "version", "contours", "perimeter_mm", "bbox"]
    );
    assert!(rows.len() >= 80, "only {} cases", rows.len());
    let mut failures = Vec::new();
    for row in rows {
        let file = &row[0];
        let number = |s: &str| -> f64 { s.parse().unwrap_or_else(|_| panic!("{file}: {s}")) };
        let contours: usize = row[2].parse().unwrap();
        let perimeter = number(&row[3]);
        let bbox: Vec<f64> = row[4].split_whitespace().map(number).collect();
        let curved = ["ellipses", "splines", "nonuniform"]
            .iter()
            .any(|c| file.contains(c));
        let tolerance = if curved { APPROXIMATED } else { EXACT };
        let bytes = std::fs::read(dir().join(file)).unwrap();
        let import = match read_dxf(&bytes, &DxfOptions::default()) {
            Ok(import) => import,
            Err(e) => {
                failures.push(format!("{file}: refused: {e}"));
                continue;
            }
        };
        let ours: Vec<_> = import.nest.parts.iter().flat_map(|p| &p.contours).collect();
        let mut problems = Vec::new();
        if ours.len() != contours {
            problems.push(format!("{} contours, expected {contours}", ours.len()));
        }
        let length: f64 = ours.iter().map(|c| c.perimeter()).sum();
        if (length - perimeter).abs() > tolerance * perimeter {
            problems.push(format!("perimeter {length:.6}, expected {perimeter:.6}"));
        }
        let b = ours
            .iter()
            .fold(BoundingBox::EMPTY, |b, c| b.union(c.bounding_box()));
        let size = (bbox[2] - bbox[0]).max(bbox[3] - bbox[1]);
        let got = [b.min.x, b.min.y, b.max.x, b.max.y];
        if got
            .iter()
            .zip(&bbox)
            .any(|(g, e)| (g - e).abs() > tolerance * size)
        {
            problems.push(format!("box {got:.4?}, expected {bbox:.4?}"));
        }
        // Text, points and hatches beside the parts are said to be left out.
        if file.contains("leftovers")
            && !import
                .warnings
                .iter()
                .any(|w| w.kind == WarningKind::Skipped && w.message.contains("TEXT"))
        {
            problems.push(format!(
                "no warning for the TEXT left out: {:?}",
                import
                    .warnings
                    .iter()
                    .map(|w| &w.message)
                    .collect::<Vec<_>>()
            ));
        }
        // An inch drawing says what it was scaled from; a millimetre one says nothing of units.
        let units = import.warnings.iter().any(|w| w.kind == WarningKind::Units);
        if file.contains("inches") != units && !file.starts_with("R12") {
            problems.push(format!("units warning: {units}"));
        }
        if !problems.is_empty() {
            failures.push(format!("{file}: {}", problems.join("; ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases differ from ezdxf:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}
