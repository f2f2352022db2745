//! Shell conventions: `-` names standard input (for what is read) or standard output (for what
//! is written); files are written whole or not at all; a long run shows its progress on a
//! terminal.

use std::io::{IsTerminal, Read, Write};
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

/// Writes `bytes` to `path`, or to standard output for `-`. A file is written beside its
/// destination and renamed over it only when complete, so a failed write (a full disk, Ctrl-C)
/// never leaves half a file or destroys the one that was there.
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<(), String> {
    if is_standard(path) {
        let mut out = std::io::stdout().lock();
        return match out.write_all(bytes).and_then(|()| out.flush()) {
            // The reader has had enough (`| head`): not an error of ours.
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
            written => written.map_err(|e| format!("standard output: {e}")),
        };
    }
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", path.display()))?;
    let mut partial = name.to_os_string();
    partial.push(format!(".cutroute-{}.part", std::process::id()));
    let partial = path.with_file_name(partial);
    let written = std::fs::write(&partial, bytes).and_then(|()| std::fs::rename(&partial, path));
    written.map_err(|e| {
        let _ = std::fs::remove_file(&partial);
        format!("{}: {e}", path.display())
    })
}

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
    fn a_failed_write_keeps_the_old_file() {
        let dir = std::env::temp_dir().join(format!("cutroute-stdio-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("kept.json");
        write_output(&file, b"first").unwrap();
        write_output(&file, b"second").unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"second");
        // A destination that cannot be replaced (a directory): an error, and no part file left.
        let blocked = dir.join("blocked");
        std::fs::create_dir_all(blocked.join("inside")).unwrap();
        assert!(write_output(&blocked, b"x").is_err());
        assert!(blocked.join("inside").is_dir());
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".part"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
