//! Shell conventions: `-` names standard input (for what is read) or standard output (for what
//! is written); files are written whole or not at all, and never over an input or a device
//! (`output.rs`); a long run shows its progress on a terminal.

use std::io::{IsTerminal, Read};
use std::path::Path;

use cutroute_protocol::Progress;

/// Whether `path` is `-`, the standard stream.
pub fn is_standard(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The name and bytes of `path`, or of standard input for `-`. The name is what errors and
/// format detection see (`stdin` for the stream: formats are told apart by their content).
pub fn read_input(path: &Path) -> Result<(String, Vec<u8>), String> {
    if is_standard(path) {
        let mut bytes = Vec::new();
        std::io::stdin()
            .lock()
            .read_to_end(&mut bytes)
            .map_err(|e| format!("standard input: {e}"))?;
        return Ok(("stdin".into(), bytes));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((path.display().to_string(), bytes))
}

/// Writes `bytes` to `path`, or to standard output for `-`, destroying nothing (`output.rs`).
pub use crate::output::write_output;

/// A solver's progress on standard error: a live line with the upper and lower bound and the
/// gap when standard error is a terminal, else (text reports only) one line a second, which
/// logs keep readable. Nothing for a JSON report written to a pipe. Clones share the live line
/// (the solver's thread shows, the main thread clears it when it reports).
#[derive(Clone)]
pub struct ProgressDisplay {
    bar: Option<indicatif::ProgressBar>,
    lines: bool,
    last_line_s: f64,
}

impl ProgressDisplay {
    pub fn new(as_json: bool) -> ProgressDisplay {
        let terminal = std::io::stderr().is_terminal();
        let bar = terminal.then(|| {
            let bar = indicatif::ProgressBar::new_spinner();
            let style = indicatif::ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner());
            bar.set_style(style);
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            bar
        });
        ProgressDisplay {
            bar,
            lines: !terminal && !as_json,
            last_line_s: -1.0,
        }
    }

    /// Shows the state a slice published.
    pub fn show(&mut self, progress: &Progress) {
        if let Some(bar) = &self.bar {
            if !bar.is_finished() {
                bar.set_message(summary(progress));
            }
        } else if self.lines && progress.elapsed_s - self.last_line_s >= 1.0 {
            self.last_line_s = progress.elapsed_s;
            eprintln!("{:8.2} s  {}", progress.elapsed_s, summary(progress));
        }
    }
}

impl Drop for ProgressDisplay {
    /// The live line is cleared: the report follows on standard output.
    fn drop(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// `ub …  lb …  gap …  phase`.
fn summary(progress: &Progress) -> String {
    let number = |v: Option<f64>| v.map_or_else(|| "—".to_string(), |v| format!("{v:.3}"));
    let bounds = &progress.bounds;
    let gap = match (bounds.upper, bounds.lower) {
        (Some(ub), Some(lb)) if ub > 0.0 => format!("{:.2} %", 100.0 * (ub - lb).max(0.0) / ub),
        _ => "—".into(),
    };
    format!(
        "ub {:>12}  lb {:>12}  gap {:>8}  {}",
        number(bounds.upper),
        number(bounds.lower),
        gap,
        progress.phase
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_shows_the_gap() {
        let progress = Progress {
            bounds: cutroute_protocol::Bounds::idle_mm(Some(200.0), Some(150.0)),
            phase: cutroute_protocol::Phase::Bound,
            ..Progress::default()
        };
        assert_eq!(
            summary(&progress),
            "ub      200.000  lb      150.000  gap  25.00 %  bound"
        );
    }
}
