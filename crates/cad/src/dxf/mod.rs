//! DXF import: ASCII and binary DXF drawings (R12 … 2018) → a [`Nest`](cutroute_geometry::Nest)
//! of closed parts plus a report.
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
//! attributes) is skipped with one warning per entity type, naming the first; paper-space
//! entities are read only when model space draws nothing (with a warning saying so). Comment
//! groups (`999`) may stand anywhere, and whatever follows `0 EOF` is ignored. Loose pieces are joined end to end
//! within [`DxfOptions::join_tolerance`]; what does not close is reported in
//! [`DrawingImport::open_chains`].

mod entities;
mod groups;

use cutroute_geometry::{ReadWarning, WarningKind, WarningPlace};

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

/// Something the reader skipped or changed without failing: the readers' one warning type,
/// placed at the line of the entity (its `0` group) or of the value concerned, at a byte offset
/// in a binary file, or nowhere when it concerns the whole drawing.
pub type DxfWarning = ReadWarning;

/// The result of a DXF import: the closed parts (no sheet: a drawing does not describe one),
/// the open chains of entities, and the warnings.
pub type DxfImport = DrawingImport<DxfWarning>;

/// Why a DXF file could not be imported: the CAD readers' shared [`CadError`](crate::CadError),
/// whose shared and `DXF:` variants this reader returns. Line numbers are 1-based lines of the
/// file.
pub type DxfError = crate::CadError;

/// Reads a DXF drawing (ASCII or binary) into closed parts, reporting open chains and skipped
/// entities.
///
/// Fails with a located [`DxfError`] on malformed input (a line of an ASCII file, a byte offset
/// of a binary one); never panics. Succeeds as long as at least one closed contour results, even
/// if some geometry stayed open.
pub fn read_dxf(bytes: &[u8], options: &DxfOptions) -> Result<DxfImport, DxfError> {
    let binary = groups::is_binary(bytes);
    read_groups(bytes, binary, options).map_err(|e| if binary { in_binary(e) } else { e })
}

fn read_groups(bytes: &[u8], binary: bool, options: &DxfOptions) -> Result<DxfImport, DxfError> {
    check_options(options)?;
    let groups = groups::split_groups(bytes)?;
    let mut warnings = Vec::new();
    let pieces: Vec<Piece> = entities::collect_pieces(&groups, options, &mut warnings)?;
    let limits = AssembleLimits {
        join_tolerance: options.join_tolerance,
        flatten_tolerance: options.approximation_tolerance,
    };
    let dropped = ReadWarning::from;
    // Without an open chain, the first refused entity is why nothing was drawn: its warning
    // carries the entity's place.
    let nothing_drawn = |warnings: &[DxfWarning]| {
        let first = warnings
            .iter()
            .find(|w| w.kind != WarningKind::Units)
            .or(warnings.first());
        match first {
            Some(w) => format!("nothing drawn; {w}"),
            None if binary => format!("nothing drawn in bytes 0 to {}", bytes.len()),
            None => {
                let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
                format!("nothing drawn in lines 1 to {lines}")
            }
        }
    };
    let mut import = finish_import(pieces, None, &limits, warnings, dropped, nothing_drawn)?;
    if binary {
        for w in &mut import.warnings {
            if let Some(WarningPlace::Line { line, .. }) = w.place {
                w.place = Some(WarningPlace::Byte { offset: line });
            }
        }
    }
    Ok(import)
}

/// The error of a binary file, whose "lines" are byte offsets: said as such.
fn in_binary(error: DxfError) -> DxfError {
    let offset = match &error {
        DxfError::BadGroupCode { line, .. }
        | DxfError::MissingValue { line, .. }
        | DxfError::BadNumber { line, .. }
        | DxfError::OutOfRange { line, .. }
        | DxfError::Unterminated { line, .. }
        | DxfError::MissingGroup { line, .. }
        | DxfError::InvalidSpline { line, .. }
        | DxfError::InvalidEntity { line, .. }
        | DxfError::UnknownBlock { line, .. }
        | DxfError::BlockNestingTooDeep { line, .. } => *line,
        _ => return error,
    };
    let text = error.to_string();
    let prefix = format!("line {offset}: ");
    let reason = text.strip_prefix(&prefix).unwrap_or(&text).to_owned();
    DxfError::BinaryDxf { offset, reason }
}

fn check_options(options: &DxfOptions) -> Result<(), DxfError> {
    crate::assemble::check_curve_options(
        options.approximation_tolerance,
        options.join_tolerance,
        options.max_spans,
    )
    .map_err(DxfError::InvalidOptions)
}
