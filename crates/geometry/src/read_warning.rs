//! What a reader leaves out or changes without refusing the file: one type for every reader
//! (DXF, SVG, JSON, DBS, T-FLEX, G-code), so the CLI, the reports and the page can list, count
//! and draw it the same way.
//!
//! **Invariant:** a reader that leaves geometry out says so with a [`ReadWarning`] whose
//! `left_out` holds that geometry (as polylines, in the nest's millimetres, y up) and whose
//! `length_mm` is its length; nothing is dropped in silence. Messages are sentences for people,
//! never `Debug` dumps.

use serde::{Deserialize, Serialize};

use crate::Point;

/// Why a reader warned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// A chain of pieces that does not close within the join tolerance: left out.
    OpenChain,
    /// A contour drawn twice (or an entity lying on another): one copy kept.
    Duplicate,
    /// A contour that encloses no area (a slit drawn out and back, a degenerate circle): left
    /// out.
    ZeroArea,
    /// A contour that crosses itself: left out (or repaired, as the message says).
    SelfIntersecting,
    /// An entity or element of a kind that is not cutting geometry (text, dimensions,
    /// hatches, images) or not understood: skipped.
    Skipped,
    /// Geometry that the drawing hides (`display:none`, a frozen or hidden layer): skipped.
    Hidden,
    /// The drawing's units are missing or unknown: a unit was assumed.
    Units,
    /// Paper space read because model space is empty.
    PaperSpace,
    /// A curve (spline, ellipse, Bézier) replaced by arcs or lines within a tolerance.
    Approximated,
    /// A file of several sheets: one of them shown.
    Sheets,
    /// Anything else the reader changed.
    Other,
}

impl WarningKind {
    /// A short lower-case name, as in JSON (`open_chain`, `duplicate`, …).
    pub fn name(self) -> &'static str {
        match self {
            Self::OpenChain => "open_chain",
            Self::Duplicate => "duplicate",
            Self::ZeroArea => "zero_area",
            Self::SelfIntersecting => "self_intersecting",
            Self::Skipped => "skipped",
            Self::Hidden => "hidden",
            Self::Units => "units",
            Self::PaperSpace => "paper_space",
            Self::Approximated => "approximated",
            Self::Sheets => "sheets",
            Self::Other => "other",
        }
    }
}

/// Where in its file a warning points: a line (from 1) with an optional column (from 1), a
/// byte offset of a binary file, or a path in a JSON document (`[1].paths[0]`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningPlace {
    /// A line, and a column when the reader knows it.
    Line {
        /// The line, from 1.
        line: usize,
        /// The column, from 1.
        column: Option<usize>,
    },
    /// A byte offset, from 0.
    Byte {
        /// The offset.
        offset: usize,
    },
    /// A place in a JSON document or a part/contour of a nest.
    Path {
        /// The path.
        path: String,
    },
}

impl std::fmt::Display for WarningPlace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Line { line, column: None } => write!(f, "line {line}"),
            Self::Line {
                line,
                column: Some(c),
            } => write!(f, "line {line} column {c}"),
            Self::Byte { offset } => write!(f, "byte {offset}"),
            Self::Path { path } => f.write_str(path),
        }
    }
}

/// Something a reader left out or changed, as data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReadWarning {
    /// Why.
    pub kind: WarningKind,
    /// Where in the file (`None`: the whole drawing).
    pub place: Option<WarningPlace>,
    /// What happened, in a sentence for people (without the place, which [`Display`]
    /// prepends).
    ///
    /// [`Display`]: std::fmt::Display
    pub message: String,
    /// Total length (mm) of the geometry left out, when geometry was left out.
    pub length_mm: Option<f64>,
    /// The geometry left out, as polylines in the nest's coordinates (arcs flattened), so a
    /// view can draw it as a layer. Empty when nothing drawable was left out. Always written:
    /// the worker's messages are bincode, which has no field names to skip a field by.
    #[serde(default)]
    pub left_out: Vec<Vec<Point>>,
}

impl ReadWarning {
    /// A warning of `kind` with a message and nothing else.
    pub fn new(kind: WarningKind, message: impl Into<String>) -> Self {
        Self {
            kind,
            place: None,
            message: message.into(),
            length_mm: None,
            left_out: Vec::new(),
        }
    }

    /// The same warning at `place`.
    pub fn at(mut self, place: WarningPlace) -> Self {
        self.place = Some(place);
        self
    }

    /// The same warning at a 1-based line (0 = no place), with a 1-based column when known.
    pub fn at_line(self, line: usize, column: Option<usize>) -> Self {
        if line == 0 {
            self
        } else {
            self.at(WarningPlace::Line { line, column })
        }
    }

    /// The same warning with the geometry it left out (its length is summed).
    pub fn leaving_out(mut self, polylines: Vec<Vec<Point>>) -> Self {
        let length: f64 = polylines
            .iter()
            .map(|p| p.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>())
            .sum();
        self.length_mm = Some(self.length_mm.unwrap_or(0.0) + length);
        self.left_out.extend(polylines);
        self
    }

    /// The same warning with `length_mm` set (when the geometry itself is not kept).
    pub fn with_length(mut self, length_mm: f64) -> Self {
        self.length_mm = Some(length_mm);
        self
    }
}

impl std::fmt::Display for ReadWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(place) = &self.place {
            write!(f, "{place}: ")?;
        }
        f.write_str(&self.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warning_reads_as_its_place_and_message_and_sums_what_it_left_out() {
        let w = ReadWarning::new(WarningKind::OpenChain, "open chain left out")
            .at_line(23, None)
            .leaving_out(vec![vec![Point::new(0.0, 0.0), Point::new(3.0, 4.0)]]);
        assert_eq!(w.to_string(), "line 23: open chain left out");
        assert_eq!(w.length_mm, Some(5.0));
        let json = serde_json::to_string(&w).unwrap();
        assert!(json.contains("\"kind\":\"open_chain\""), "{json}");
        assert_eq!(serde_json::from_str::<ReadWarning>(&json).unwrap(), w);
        assert_eq!(
            ReadWarning::new(WarningKind::Units, "no units").to_string(),
            "no units"
        );
    }
}
