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

/// Why a DXF file could not be imported: the CAD readers' shared [`CadError`](crate::CadError),
/// whose shared and `DXF:` variants this reader returns. Line numbers are 1-based lines of the
/// file.
pub type DxfError = crate::CadError;

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
    finish_import(pieces, None, &limits, warnings, dropped, nothing_drawn)
}

fn check_options(options: &DxfOptions) -> Result<(), DxfError> {
    crate::assemble::check_curve_options(
        options.approximation_tolerance,
        options.join_tolerance,
        options.max_spans,
    )
    .map_err(DxfError::InvalidOptions)
}
