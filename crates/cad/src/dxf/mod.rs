//! DXF import: ASCII DXF drawings (R12 … 2018) → a [`Nest`](cutroute_geometry::Nest) of closed parts plus a report.
//!
//! The reader is this crate's own group-code parser rather than the `dxf` crate. That crate
//! reads all eleven reference drawings, but it drops an entity whose number fails to parse
//! without telling (a `LINE` with a corrupt `11` group simply vanishes), reports a truncated file
//! without a position, and keeps no line numbers on entities; a cutting program must instead
//! refuse or report such input and say where. Only the sections that carry geometry are
//! interpreted (`HEADER` for version, code page and units; `BLOCKS`; `ENTITIES`); everything else
//! is skipped group by group.
//!
//! What becomes geometry: `LINE`, `ARC`, `CIRCLE`, `LWPOLYLINE` and `POLYLINE`/`VERTEX` (with
//! bulges), `ELLIPSE` and `SPLINE` (approximated by arcs within
//! [`DxfOptions::approximation_tolerance`]), and `INSERT` (also `MINSERT` arrays) of blocks,
//! nested blocks included. Annotation (text, dimensions, leaders, hatches, points, viewports,
//! attributes) is ignored, and so are paper-space entities. Loose pieces are joined end to end
//! within [`DxfOptions::join_tolerance`]; what does not close is reported in
//! [`DrawingImport::open_chains`].

mod entities;
mod groups;

use crate::assemble::{finish_import, AssembleLimits, DrawingImport, Piece};
pub use crate::assemble::{EntityRef, OpenChain};

/// Settings of a DXF import.
#[derive(Clone, Debug, PartialEq)]
pub struct DxfOptions {
    /// Largest distance (mm) allowed between a spline or ellipse and the arcs that replace it.
    pub approximation_tolerance: f64,
    /// Largest gap (mm) between two end points that are still joined into one contour.
    pub join_tolerance: f64,
    /// Most spans the import may produce before it gives up with [`DxfError::TooComplex`]:
    /// guards against block bombs and absurd tolerances.
    pub max_spans: usize,
}

impl Default for DxfOptions {
    fn default() -> Self {
        Self {
            approximation_tolerance: 0.01,
            join_tolerance: 0.05,
            max_spans: 500_000,
        }
    }
}

/// Something the reader skipped or changed without failing, with the line it concerns.
#[derive(Clone, Debug, PartialEq)]
pub struct DxfWarning {
    /// 1-based line of the entity (its `0` group) or of the value concerned; 0 when the warning
    /// concerns the whole drawing.
    pub line: usize,
    /// What happened, for people.
    pub message: String,
}

impl std::fmt::Display for DxfWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line > 0 {
            write!(f, "line {}: {}", self.line, self.message)
        } else {
            f.write_str(&self.message)
        }
    }
}

/// The result of a DXF import: the closed parts (no sheet: a drawing does not describe one),
/// the open chains of entities, and the warnings.
pub type DxfImport = DrawingImport<DxfWarning>;

/// Why a DXF file could not be imported. Line numbers are 1-based lines of the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DxfError {
    /// The file is a binary DXF, which this reader does not read.
    #[error("binary DXF is not supported; save the drawing as ASCII DXF")]
    BinaryDxf,
    /// A group code line does not hold an integer.
    #[error("line {line}: group code expected, found {text:?}")]
    BadGroupCode {
        /// Line of the would-be group code.
        line: usize,
        /// What stands there.
        text: String,
    },
    /// The file ends after a group code, before its value (truncated file).
    #[error("line {line}: group code {code} has no value line (file truncated?)")]
    MissingValue {
        /// Line of the group code.
        line: usize,
        /// The group code.
        code: i32,
    },
    /// A value that must be a number is not one (or is NaN or infinite).
    #[error("line {line}: group {code} must be a finite number, found {text:?}")]
    BadNumber {
        /// Line of the value.
        line: usize,
        /// Its group code.
        code: i32,
        /// What stands there.
        text: String,
    },
    /// A number is beyond ±1e9, larger than any drawing in millimetres.
    #[error("line {line}: group {code} value {value} is out of range (|value| > 1e9)")]
    OutOfRange {
        /// Line of the value.
        line: usize,
        /// Its group code.
        code: i32,
        /// The value.
        value: f64,
    },
    /// A section, block or polyline is not closed before the file ends (truncated file).
    #[error("line {line}: {what} is not terminated before the end of the file (truncated?)")]
    Unterminated {
        /// Line where the unterminated item starts.
        line: usize,
        /// What it is (`section ENTITIES`, `block X`, …).
        what: String,
    },
    /// The file has no `ENTITIES` section.
    #[error("the file has no ENTITIES section")]
    NoEntities,
    /// An entity lacks a group it cannot do without.
    #[error("line {line}: {entity} has no group {code} ({meaning})")]
    MissingGroup {
        /// Line of the entity.
        line: usize,
        /// Entity type.
        entity: String,
        /// The missing group code.
        code: i32,
        /// What the group means.
        meaning: &'static str,
    },
    /// A spline whose data are inconsistent (degree, counts, knots, weights).
    #[error("line {line}: invalid SPLINE: {reason}")]
    InvalidSpline {
        /// Line of the spline.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// Another inconsistent entity (negative counts, absurd array sizes, …).
    #[error("line {line}: invalid {entity}: {reason}")]
    InvalidEntity {
        /// Line of the entity.
        line: usize,
        /// Entity type.
        entity: String,
        /// What is wrong.
        reason: String,
    },
    /// An `INSERT` names a block the file does not define.
    #[error("line {line}: INSERT of undefined block {name:?}")]
    UnknownBlock {
        /// Line of the INSERT.
        line: usize,
        /// The block name.
        name: String,
    },
    /// Blocks insert each other deeper than the limit (or in a cycle).
    #[error("line {line}: blocks nest deeper than {limit} levels at block {name:?} (cycle?)")]
    BlockNestingTooDeep {
        /// Line of the innermost INSERT.
        line: usize,
        /// The block being inserted.
        name: String,
        /// The depth limit.
        limit: usize,
    },
    /// The drawing would produce more spans than [`DxfOptions::max_spans`].
    #[error("the drawing needs more than {limit} spans (block explosion or too fine tolerance)")]
    TooComplex {
        /// The limit that was hit.
        limit: usize,
    },
    /// The options are unusable (tolerances must be finite and positive).
    #[error("invalid options: {0}")]
    InvalidOptions(String),
    /// The drawing yields no closed contour at all.
    #[error("no closed contour in the drawing ({open} open chains, first: {first})")]
    NothingClosed {
        /// How many open chains there are.
        open: usize,
        /// The first open chain, described.
        first: String,
    },
}

/// Reads an ASCII DXF drawing into closed parts, reporting open chains and skipped entities.
///
/// Fails with a located [`DxfError`] on malformed input; never panics. Succeeds as long as at
/// least one closed contour results, even if some geometry stayed open.
pub fn read_dxf(bytes: &[u8], options: &DxfOptions) -> Result<DxfImport, DxfError> {
    check_options(options)?;
    let groups = groups::split_groups(bytes)?;
    let mut warnings = Vec::new();
    let pieces: Vec<Piece> = entities::collect_pieces(&groups, options, &mut warnings)?;
    let limits = AssembleLimits {
        join_tolerance: options.join_tolerance,
        flatten_tolerance: options.approximation_tolerance,
    };
    let dropped = |w: crate::assemble::Dropped| DxfWarning {
        line: w.line,
        message: w.message,
    };
    // Without an open chain, the first refused entity is why nothing was drawn: its warning
    // carries the entity's line.
    let nothing_drawn = |warnings: &[DxfWarning]| match warnings.first() {
        Some(w) => format!("nothing drawn; {w}"),
        None => {
            let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
            format!("nothing drawn in lines 1 to {lines}")
        }
    };
    finish_import(pieces, None, &limits, warnings, dropped, nothing_drawn).map_err(|e| {
        DxfError::NothingClosed {
            open: e.open,
            first: e.first,
        }
    })
}

fn check_options(options: &DxfOptions) -> Result<(), DxfError> {
    crate::assemble::check_curve_options(
        options.approximation_tolerance,
        options.join_tolerance,
        options.max_spans,
    )
    .map_err(DxfError::InvalidOptions)
}
