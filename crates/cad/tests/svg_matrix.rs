//! The made SVG corpus (`data/made/svg-matrix/`, written by `scripts/make-svg-matrix.py` and
//! measured by svgelements): units (mm, px, in, pt), transforms, path syntax as minifiers
//! write it, subpaths as holes, rounded rectangles, hidden and unused geometry beside a
//! `<use>`, a nested viewport, Inkscape layers. Each must read as svgelements measures it:
//! the closed contours the drawing has, their total length and their box (x range and
//! height: SVG's y runs down) within 0.01 %.

mod common;

use common::realworld::parse_csv;
use cutroute_cad::svg::{read_svg, SvgOptions};
use std::path::PathBuf;

/// Relative tolerance: the oracle's unit factor is good to 5e-7, and the reader approximates
/// Béziers and ellipses.
const TOLERANCE: f64 = 1e-4;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/made/svg-matrix")
}

#[test]
fn every_case_reads_as_svgelements_measures_it() {
    let text = std::fs::read_to_string(dir().join("expected.csv")).expect("expected.csv");
    let records = parse_csv(&text);
    let (header, rows) = records.split_first().expect("a header");
    assert_eq!(
        header,
        &["file", "contours", "perimeter_mm", "x_range_and_height_mm"]
    );
    assert!(rows.len() >= 11, "only {} cases", rows.len());
    let mut failures = Vec::new();
    for row in rows {
        let file = &row[0];
        let number = |s: &str| -> f64 { s.parse().unwrap_or_else(|_| panic!("{file}: {s}")) };
        let contours: usize = row[1].parse().unwrap();
        let perimeter = number(&row[2]);
        let extent: Vec<f64> = row[3].split_whitespace().map(number).collect();
        let bytes = std::fs::read(dir().join(file)).unwrap();
        let import = match read_svg(&bytes, &SvgOptions::default()) {
            Ok(import) => import,
            Err(e) => {
                failures.push(format!("{file}: refused: {e}"));
                continue;
            }
        };
        let ours: Vec<_> = import
            .nest
            .parts
            .iter()
            .chain(import.nest.sheet.iter())
            .flat_map(|p| &p.contours)
            .collect();
        let mut problems = Vec::new();
        if ours.len() != contours {
            problems.push(format!("{} contours, expected {contours}", ours.len()));
        }
        let length: f64 = ours.iter().map(|c| c.perimeter()).sum();
        if (length - perimeter).abs() > TOLERANCE * perimeter {
            problems.push(format!("perimeter {length:.6}, expected {perimeter:.6}"));
        }
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for c in &ours {
            let b = c.bounding_box();
            (x0, x1) = (x0.min(b.min.x), x1.max(b.max.x));
            (y0, y1) = (y0.min(b.min.y), y1.max(b.max.y));
        }
        let got = [x0, x1, y1 - y0];
        let size = (extent[1] - extent[0]).max(extent[2]);
        if got
            .iter()
            .zip(&extent)
            .any(|(g, e)| (g - e).abs() > TOLERANCE * size)
        {
            problems.push(format!(
                "x range and height {got:.4?}, expected {extent:.4?}"
            ));
        }
        if !problems.is_empty() {
            failures.push(format!("{file}: {}", problems.join("; ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases differ from svgelements:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}
