//! The real-world corpus of `data/realworld/`: its `expected.csv`, written by an independent
//! oracle (ezdxf, svgelements), parsed into rows a reader-level or engine-level test compares
//! against.

use std::path::PathBuf;

/// One row of `expected.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct Expected {
    /// The file, relative to `data/realworld/` (`files/…`).
    pub file: String,
    /// `DXF R2000 (AC1015)`, `SVG`, … as the oracle saw it.
    pub format: String,
    /// The program that wrote it.
    pub writer: String,
    /// Closed contours at cutroute's 0.05 mm joining; `None` when the cell is empty.
    pub contours_loose: Option<usize>,
    /// Total perimeter of those contours (mm).
    pub perimeter_mm: Option<f64>,
    /// Bounding box `[min x, min y, max x, max y]` (mm), when there are contours.
    pub bbox: Option<[f64; 4]>,
    /// Whether the oracle marks its own numbers as unsure (`yes: …`), with its reason.
    pub oracle_unsure: Option<String>,
    /// Free notes.
    pub notes: String,
}

impl Expected {
    /// Whether the file is expected to be refused (no closed contour).
    pub fn is_refusal(&self) -> bool {
        self.contours_loose.unwrap_or(0) == 0
    }

    /// The file's bytes.
    pub fn bytes(&self) -> Vec<u8> {
        let path = realworld_dir().join(&self.file);
        std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    /// The file name without its folder.
    pub fn name(&self) -> &str {
        self.file.rsplit('/').next().unwrap_or(&self.file)
    }
}

/// `data/realworld/` of the repository.
pub fn realworld_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/realworld")
}

/// Every row of `expected.csv`, in file order; panics on a malformed table (the test data are
/// broken then, not the reader).
pub fn expected_rows() -> Vec<Expected> {
    let path = realworld_dir().join("expected.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{} is missing ({e})", path.display()));
    let records = parse_csv(&text);
    let (header, rows) = records.split_first().expect("expected.csv has a header");
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("expected.csv has no column {name}"))
    };
    let (file, format, writer) = (column("file"), column("format"), column("writer"));
    let (loose, perimeter, bbox) = (
        column("contours_loose"),
        column("perimeter_mm"),
        column("bbox"),
    );
    let (unsure, notes) = (column("oracle_unsure"), column("notes"));
    rows.iter()
        .filter(|r| r.len() > 1)
        .map(|r| {
            let cell = |i: usize| r.get(i).map_or("", |s| s.trim());
            let number = |i: usize| -> Option<f64> {
                let c = cell(i);
                (!c.is_empty()).then(|| {
                    c.parse()
                        .unwrap_or_else(|_| panic!("{}: {c:?} is no number", cell(file)))
                })
            };
            let bbox = {
                let values: Vec<f64> = cell(bbox)
                    .split_whitespace()
                    .map(|v| v.parse().expect("bbox number"))
                    .collect();
                <[f64; 4]>::try_from(values).ok()
            };
            let unsure = cell(unsure);
            Expected {
                file: cell(file).to_owned(),
                format: cell(format).to_owned(),
                writer: cell(writer).to_owned(),
                contours_loose: number(loose).map(|n| n as usize),
                perimeter_mm: number(perimeter),
                bbox,
                oracle_unsure: unsure.starts_with("yes").then(|| unsure.to_owned()),
                notes: cell(notes).to_owned(),
            }
        })
        .collect()
}

/// RFC 4180 CSV: fields separated by commas, quoted with `"` (doubled inside) when they hold
/// commas, quotes or line breaks.
pub fn parse_csv(text: &str) -> Vec<Vec<String>> {
    let mut records = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        if quoted {
            match c {
                '"' if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                '"' => quoted = false,
                _ => field.push(c),
            }
            continue;
        }
        match c {
            '"' => quoted = true,
            ',' => record.push(std::mem::take(&mut field)),
            '\r' => {}
            '\n' => {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
            }
            _ => field.push(c),
        }
    }
    if !field.is_empty() || !record.is_empty() {
        record.push(field);
        records.push(record);
    }
    records
}
