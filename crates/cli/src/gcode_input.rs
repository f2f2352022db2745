//! How a G-code input is read: `--compensation-radius` gives the radius of `G41`/`G42 D<n>`
//! (the controller's tool table holds it, the program only names the entry), `--preset` the
//! dialect's torch codes and dwell unit.

use cutroute_gcode::ReadOptions;
use cutroute_protocol::Document;

/// `--compensation-radius MM` of `inspect`, `solve` and `convert`.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct CompensationArg {
    /// Cutter compensation radius of a G-code input's `G41`/`G42 D<n>`, mm (half the kerf:
    /// the radius the controller's tool table gives entry N). `G41.1`/`G42.1` carry theirs.
    #[arg(long, value_name = "MM", value_parser = radius_mm)]
    pub compensation_radius: Option<f64>,
}

fn radius_mm(text: &str) -> Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|e| format!("{e}"))?;
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err("expected a finite radius of at least 0 mm".into())
    }
}

impl CompensationArg {
    /// `options` with the radius given, if one was.
    pub fn apply(&self, mut options: ReadOptions) -> ReadOptions {
        if self.compensation_radius.is_some() {
            options.compensation_radius = self.compensation_radius;
        }
        options
    }
}

/// Opens sheet `sheet` of the named bytes; a G-code program (as the format detection finds
/// it) is read with the radius given.
pub fn open(
    name: &str,
    bytes: &[u8],
    sheet: usize,
    compensation: &CompensationArg,
) -> Result<Document, cutroute_engine::OpenError> {
    let opened = cutroute_engine::open_sheet(name, bytes, sheet);
    if compensation.compensation_radius.is_none() {
        return opened;
    }
    let is_program = match &opened {
        Ok(document) => document.format == "G-code",
        Err(cutroute_engine::OpenError::Gcode { .. }) => true,
        Err(_) => false,
    };
    match std::str::from_utf8(bytes) {
        Ok(text) if is_program => cutroute_engine::open_gcode_with(
            name,
            text,
            &compensation.apply(ReadOptions::default()),
        ),
        _ => opened,
    }
}
