//! Read times of DXF and SVG drawings, for the table "Reading real DXF and SVG files" of
//! BENCHMARKS.md (`scripts/bench-readers.sh` runs it beside ezdxf).
//!
//! `cargo bench -p cutroute-cad --bench read_speed -- [--generate PATH] [--runs N] FILE…`
//!
//! `--generate PATH` first writes the generated sheet of 1,200 closed splines (40 × 30 blobs of
//! 25 control points, about 2.4 MB, the same bytes every time) to PATH and reads it too. Each
//! file is read `--runs` times (default 5); the fastest run is reported, in wall time and in
//! the CPU time of the reading thread (Linux `schedstat`; on a machine shared with other work
//! the CPU time is the reader's own cost, the wall time includes waiting for a core). Prints
//! tab-separated rows: file, bytes, wall ms, CPU ms, and what the read gave (contours, or the
//! refusal).

#[allow(dead_code)]
#[path = "../tests/common/spline_sheet.rs"]
mod spline_sheet;

use std::time::Instant;

use cutroute_cad::dxf::{read_dxf, DxfOptions};
use cutroute_cad::svg::{read_svg, SvgOptions};

fn main() {
    let mut args = std::env::args().skip(1).filter(|a| a != "--bench");
    let mut files = Vec::new();
    let mut runs = 5usize;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--generate" => {
                let path = args.next().expect("--generate needs a path");
                std::fs::write(&path, spline_sheet::spline_sheet(40, 30, 25))
                    .expect("the generated file can be written");
                files.push(path);
            }
            "--runs" => {
                runs = args
                    .next()
                    .and_then(|n| n.parse().ok())
                    .expect("--runs needs a count");
            }
            _ => files.push(arg),
        }
    }
    for file in files {
        let bytes = std::fs::read(&file).unwrap_or_else(|e| panic!("{file}: {e}"));
        let svg = file.to_ascii_lowercase().ends_with(".svg");
        let mut best = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        let mut outcome = String::new();
        for _ in 0..runs.max(1) {
            let start = Instant::now();
            let cpu_start = thread_cpu_seconds();
            outcome = if svg {
                match read_svg(&bytes, &SvgOptions::default()) {
                    Ok(i) => contours(&i.nest),
                    Err(e) => format!("refused: {e}"),
                }
            } else {
                match read_dxf(&bytes, &DxfOptions::default()) {
                    Ok(i) => contours(&i.nest),
                    Err(e) => format!("refused: {e}"),
                }
            };
            best = best.min(start.elapsed().as_secs_f64());
            best_cpu = best_cpu.min(thread_cpu_seconds() - cpu_start);
        }
        println!(
            "{file}\t{}\t{:.1}\t{:.1}\t{outcome}",
            bytes.len(),
            best * 1000.0,
            best_cpu * 1000.0
        );
    }
}

/// CPU time this thread has run, in seconds (NaN where `/proc` does not tell).
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns / 1e9)
}

fn contours(nest: &cutroute_geometry::Nest) -> String {
    let n: usize = nest.parts.iter().map(|p| p.contours.len()).sum();
    format!("{n} contours")
}
