//! The real-world import corpus (data/realworld: DXF and SVG files written by CAD and nesting
//! programs, with an independent oracle's expected.csv) through `open_document`, the door the
//! CLI and the page use: every file opens with the expected contours, or is refused with a
//! located message; what is left out is in the warnings; and every file that opens converts to
//! each nest format and back with the same contours, or the conversion says what it lost.
//!
//! Both tests print a table of every mismatch and fail listing them.

use std::path::{Path, PathBuf};

use cutroute_engine::{conversion_losses, open_document};
use cutroute_geometry::{BoundingBox, Nest, Part};
use cutroute_protocol::{Document, Problem};

/// Relative tolerance of perimeters and bounding boxes against the oracle, as the corpus
/// README states it.
const ORACLE_TOLERANCE: f64 = 1e-3;

/// Files where this test believes expected.csv is wrong, with the reason. None yet: the rows
/// marked `oracle_unsure` are listed in the mismatch table with that mark, for a person to
/// decide with a second opinion (ezdxf, svgelements).
const ORACLE_DISPUTED: &[(&str, &str)] = &[];

/// Files whose verdict against the oracle lives with their reader's own corpus test, with the
/// reason written there: the oracle corrected (`crates/cad/tests/dxf_realworld.rs`
/// `CORRECTIONS`, `crates/cad/tests/svg_realworld.rs` `expect`) or not yet read as drawn (the
/// DXF test's `NOT_YET`). Here `open_document` must open each
/// exactly as its reader reads it: the door adds nothing and loses nothing.
const READER_OWNED: &[&str] = &[
    // DXF: the oracle corrected.
    "ezdxf__AC1003_LINE_Example.dxf",
    "ezdxf__POLI-ALL210_12.DXF",
    "ezdxf__text_in_viewports.dxf",
    "openscad__nothing-decimal-comma-separated.dxf",
    "openscad__polygon-self-intersect.dxf",
    "openscad__example009.dxf",
    // DXF: the oracle corrected (shared edges and branches read as the plane graph's faces,
    // periodic splines, full ellipses whose 2π is rounded).
    "librecad__tux.dxf",
    "bjnortier-dxf__issue52.dxf",
    "bjnortier-dxf__entities.dxf",
    "bjnortier-dxf__supported_entities.dxf",
    "openscad__polygon-mesh.dxf",
    "librecad__Complete-Lib-E.dxf",
    "librecad__ga9.dxf",
    "librecad__d3.dxf",
    // SVG: the oracle corrected (user units, Inkscape 0.48's 90 px/in, a square drawn twice,
    // a text frame counted, Boxes.py's zero-burn corner loops removed as too small to cut).
    "ezdxf__gear.svg",
    "openscad__box-w-holes.svg",
    "openscad__size-percent-1.svg",
    "visicut__circle-20mm-red.svg",
    "visicut__inkscape_0.48.svg",
    "visicut__test.svg",
    "boxes__ABox.svg",
    "boxes__FlexBox.svg",
    "boxes__GearBox.svg",
    "boxes__Matrix.svg",
];

/// What the DXF or SVG reader alone makes of `bytes`: contours and perimeter, or its refusal.
fn reader_alone(file: &str, bytes: &[u8]) -> Result<(usize, f64), String> {
    let nest = if file.ends_with(".svg") {
        cutroute_cad::svg::read_svg(bytes, &Default::default()).map(|i| i.nest)
    } else {
        cutroute_cad::dxf::read_dxf(bytes, &Default::default()).map(|i| i.nest)
    }
    .map_err(|e| e.to_string())?;
    let (count, perimeter, _) = measures(&nest);
    Ok((count, perimeter))
}

/// Where `open_document` and the reader alone disagree.
fn check_reader_owned(
    file: &str,
    bytes: &[u8],
    outcome: &Result<Document, cutroute_engine::OpenError>,
) -> Vec<String> {
    let door = outcome
        .as_ref()
        .map_err(|e| e.to_string())
        .map(|d| nest_of(d).map(measures));
    match (reader_alone(file, bytes), door) {
        (Err(_), Err(_)) => Vec::new(),
        (Ok((count, perimeter)), Ok(Some((c, p, _))))
            if c == count && within(p, perimeter, 1e-9) =>
        {
            Vec::new()
        }
        (reader, door) => vec![format!(
            "the reader gives {reader:?}, open_document {:?}",
            door.map(|m| m.map(|(c, p, _)| (c, p)))
        )],
    }
}

struct Row {
    file: String,
    contours: Option<usize>,
    perimeter: f64,
    bbox: Option<[f64; 4]>,
    unsure: bool,
    notes: String,
}

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/realworld")
}

/// The fields of one CSV record (RFC 4180 quoting: `"` around a field, `""` inside it).
fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            (c, _) => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

fn rows() -> Vec<Row> {
    let text = std::fs::read_to_string(corpus().join("expected.csv")).unwrap();
    let mut lines = text.lines();
    let header = csv_fields(lines.next().unwrap());
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (file, loose, perimeter, bbox, unsure, notes) = (
        column("file"),
        column("contours_loose"),
        column("perimeter_mm"),
        column("bbox"),
        column("oracle_unsure"),
        column("notes"),
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let f = csv_fields(line);
            let numbers: Vec<f64> = f[bbox]
                .split_whitespace()
                .filter_map(|v| v.parse().ok())
                .collect();
            Row {
                file: f[file].clone(),
                contours: f[loose].trim().parse().ok(),
                perimeter: f[perimeter].trim().parse().unwrap_or(0.0),
                bbox: (numbers.len() == 4)
                    .then(|| [numbers[0], numbers[1], numbers[2], numbers[3]]),
                unsure: f[unsure].starts_with("yes"),
                notes: f[notes].clone(),
            }
        })
        .collect()
}

/// Every contour of the nest, the sheet's included (a drawing's sheet outline is one of its
/// contours to the oracle).
fn all_parts(nest: &Nest) -> impl Iterator<Item = &Part> {
    nest.sheet.iter().chain(&nest.parts)
}

fn measures(nest: &Nest) -> (usize, f64, BoundingBox) {
    let count = all_parts(nest).map(|p| p.contours.len()).sum();
    let perimeter = all_parts(nest).map(Part::perimeter).sum();
    let bbox = all_parts(nest).fold(BoundingBox::EMPTY, |b, p| b.union(p.bounding_box()));
    (count, perimeter, bbox)
}

/// `a` and `b` differ by at most `tolerance` (false for NaN).
fn within(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance
}

fn nest_of(document: &Document) -> Option<&Nest> {
    match &document.problem {
        Problem::Nest { nest, .. } => Some(nest),
        Problem::PcgtspText { .. } => None,
    }
}

/// What is wrong with the file's opening against its row; empty when it matches.
fn check_row(row: &Row, outcome: &Result<Document, cutroute_engine::OpenError>) -> Vec<String> {
    let mut wrong = Vec::new();
    let name = Path::new(&row.file).file_name().unwrap().to_string_lossy();
    let expect_refusal = row.contours.is_none_or(|c| c == 0);
    match outcome {
        Err(e) if expect_refusal => {
            // A refusal names the file and says where or why.
            let report = e.report();
            let message = e.to_string();
            let located = report.location.is_some()
                || message.contains("line ")
                || message.contains("byte ")
                || message.contains("no closed contour")
                || message.contains("nothing drawn");
            if !message.contains(name.as_ref()) || !located {
                wrong.push(format!("refused without a location: {message}"));
            }
        }
        Err(e) => wrong.push(format!(
            "refused, expected {} contours: {e}",
            row.contours.unwrap_or(0)
        )),
        Ok(document) => {
            let Some(nest) = nest_of(document) else {
                wrong.push("opens as no nest".into());
                return wrong;
            };
            let (count, perimeter, bbox) = measures(nest);
            if expect_refusal {
                wrong.push(format!(
                    "opens with {count} contours (perimeter {perimeter:.4}), expected a refusal"
                ));
                return wrong;
            }
            let expected = row.contours.unwrap_or(0);
            if count != expected {
                wrong.push(format!("{count} contours, expected {expected}"));
            }
            if !within(perimeter, row.perimeter, ORACLE_TOLERANCE * row.perimeter) {
                wrong.push(format!(
                    "perimeter {perimeter:.4}, expected {:.4}",
                    row.perimeter
                ));
            }
            if let Some([x0, y0, x1, y1]) = row.bbox {
                let size = (x1 - x0).max(y1 - y0);
                let svg = row.file.to_lowercase().ends_with(".svg");
                // SVG boxes are y-down: the oracle's y range is mirrored, its height is not.
                let pairs = if svg {
                    vec![
                        (bbox.min.x, x0),
                        (bbox.max.x, x1),
                        (bbox.max.y - bbox.min.y, y1 - y0),
                    ]
                } else {
                    vec![
                        (bbox.min.x, x0),
                        (bbox.min.y, y0),
                        (bbox.max.x, x1),
                        (bbox.max.y, y1),
                    ]
                };
                if pairs
                    .iter()
                    .any(|&(ours, theirs)| !within(ours, theirs, ORACLE_TOLERANCE * size))
                {
                    wrong.push(format!(
                        "bbox {:.4} {:.4} {:.4} {:.4}, expected {x0:.4} {y0:.4} {x1:.4} {y1:.4}",
                        bbox.min.x, bbox.min.y, bbox.max.x, bbox.max.y
                    ));
                }
            }
            // What the oracle found open must be among the warnings, with its length.
            if row.notes.contains("open chain(s) besides the contours") {
                let told = document.warnings.iter().any(|w| {
                    w.message.to_lowercase().contains("open chain")
                        || w.kind == cutroute_geometry::WarningKind::OpenChain
                });
                if !told {
                    wrong.push("open chains left out without a warning".into());
                }
            }
            if let Some(w) = document.warnings.iter().find(|w| w.message.contains(":?}")) {
                wrong.push(format!("a warning is a Debug dump: {w}"));
            }
        }
    }
    wrong
}

fn table(title: &str, mismatches: &[(String, bool, Vec<String>)]) -> String {
    let mut out = format!("{title}: {} mismatches\n", mismatches.len());
    for (file, unsure, wrong) in mismatches {
        let mark = if *unsure { " [oracle unsure]" } else { "" };
        let disputed = ORACLE_DISPUTED
            .iter()
            .find(|(f, _)| file.ends_with(f))
            .map_or(String::new(), |(_, why)| {
                format!(" [oracle disputed: {why}]")
            });
        out.push_str(&format!("  {file}{mark}{disputed}\n"));
        for w in wrong {
            out.push_str(&format!("      {w}\n"));
        }
    }
    out
}

#[test]
fn every_corpus_file_opens_as_the_oracle_reads_it_or_is_refused_with_a_location() {
    let rows = rows();
    assert!(rows.len() >= 79, "expected.csv lists {} files", rows.len());
    let mut mismatches = Vec::new();
    for row in &rows {
        let path = corpus().join(&row.file);
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let outcome = open_document(&name, &bytes);
        let wrong = if READER_OWNED.iter().any(|f| row.file.ends_with(f)) {
            check_reader_owned(&row.file, &bytes, &outcome)
        } else {
            check_row(row, &outcome)
        };
        if !wrong.is_empty() {
            mismatches.push((row.file.clone(), row.unsure, wrong));
        }
    }
    let report = table("corpus against expected.csv", &mismatches);
    println!("{report}");
    assert!(mismatches.is_empty(), "{report}");
}

#[test]
fn every_corpus_file_that_opens_converts_to_each_nest_format_and_back_or_says_what_it_lost() {
    let mut mismatches = Vec::new();
    for row in rows() {
        let path = corpus().join(&row.file);
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Ok(document) = open_document(&name, &bytes) else {
            continue;
        };
        let Some(nest) = nest_of(&document) else {
            continue;
        };
        let mut wrong = Vec::new();
        let written: [(&str, Result<Vec<u8>, String>); 3] = [
            (
                "out.dbs",
                cutroute_formats::write_dbs_with(
                    nest,
                    &cutroute_formats::DbsWriteOptions {
                        truncate_long_names: true,
                    },
                )
                .map_err(|e| e.to_string()),
            ),
            (
                "out.dbs.json",
                cutroute_formats::write_geometry_json(nest)
                    .map(String::into_bytes)
                    .map_err(|e| e.to_string()),
            ),
            (
                "out.svg",
                Ok(cutroute_formats::nest_svg(
                    nest,
                    None,
                    &cutroute_formats::SvgOptions::default(),
                )
                .into_bytes()),
            ),
        ];
        for (out_name, bytes) in written {
            let bytes = match bytes {
                Ok(b) => b,
                // A writer that refuses says why: that is a report, not a silent loss.
                Err(e) if !e.is_empty() => continue,
                Err(_) => {
                    wrong.push(format!("{out_name}: refused without a reason"));
                    continue;
                }
            };
            let losses = conversion_losses(nest, out_name, &bytes);
            let (count, perimeter, bbox) = measures(nest);
            let back = open_document(out_name, &bytes)
                .ok()
                .and_then(|d| nest_of(&d).map(measures));
            let same = back.is_some_and(|(c, p, b)| {
                let size = (bbox.max.x - bbox.min.x).max(bbox.max.y - bbox.min.y);
                c == count
                    && (p - perimeter).abs() <= 1e-6 * perimeter
                    && [
                        b.min.x - bbox.min.x,
                        b.min.y - bbox.min.y,
                        b.max.x - bbox.max.x,
                        b.max.y - bbox.max.y,
                    ]
                    .iter()
                    .all(|d| d.abs() <= 1e-6 * size)
            });
            // Either the same contours, or the conversion's report says what differs.
            if same != losses.is_empty() {
                wrong.push(format!(
                    "{out_name}: read back {}, but the conversion reports {:?}",
                    if same { "the same" } else { "differently" },
                    losses.iter().map(ToString::to_string).collect::<Vec<_>>()
                ));
            }
            if !same {
                // Listed for the table: a loss that is reported, still a loss.
                wrong.push(format!(
                    "{out_name}: reported loss: {}",
                    losses
                        .iter()
                        .map(ToString::to_string)
                        .collect::<Vec<_>>()
                        .join("; ")
                ));
            }
        }
        // Only unreported losses fail; reported ones are printed.
        if !wrong.is_empty() {
            mismatches.push((row.file.clone(), row.unsure, wrong));
        }
    }
    let report = table("round trips through dbs, dbs.json and svg", &mismatches);
    println!("{report}");
    let unreported: Vec<&(String, bool, Vec<String>)> = mismatches
        .iter()
        .filter(|(_, _, w)| w.iter().any(|m| m.contains("but the conversion reports")))
        .collect();
    assert!(unreported.is_empty(), "{report}");
}
