//! LinuxCNC's standalone interpreter `rs274` as the referee of the reader's tests: it runs a
//! program and its canonical motion (with LinuxCNC's own cutter compensation) is summed up as
//! the pierces, cut length and idle length the machine would make.
//!
//! It is found at `$CUTROUTE_RS274` (the `rs274` binary of a `dpkg -x` of Debian's
//! `linuxcnc-uspace`, its libraries under the same root's `usr/lib`) or under
//! `/opt/cutroute/linuxcnc`. Missing, a test fails in CI (`CI=true`) and otherwise says so
//! and checks only the numbers derived by hand.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Stdio};

use cutroute_geometry::Point;

/// Where scripts/install-rs274.sh unpacks LinuxCNC.
pub const LINUXCNC_ROOT: &str = "/opt/cutroute/linuxcnc/root";

/// The `rs274` binary, or `None` (with a note) when it is not installed outside CI.
pub fn rs274() -> Option<PathBuf> {
    let path = std::env::var_os("CUTROUTE_RS274")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(LINUXCNC_ROOT).join("usr/bin/rs274"));
    if path.is_file() {
        return Some(path);
    }
    assert!(
        std::env::var("CI").map_or(true, |v| v != "true"),
        "rs274 missing at {}: run scripts/install-rs274.sh",
        path.display()
    );
    eprintln!(
        "rs274 missing at {}: run scripts/install-rs274.sh (checking hand-derived numbers only)",
        path.display()
    );
    None
}

/// What the controller does with a program.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Machine {
    /// Where the torch (beam) started burning, in the frame the program started in.
    pub pierces: Vec<Point>,
    /// Length of the feed moves made while burning, mm.
    pub cut: f64,
    /// Length of the rapids and of the feed moves made while not burning, mm.
    pub idle: f64,
    /// The interpreter's error, when it stopped on one.
    pub error: Option<String>,
}

/// Runs `program` through `rs274` with every tool table entry 1–9 of radius `radius_mm`.
/// `laser`: GRBL laser mode's rule for what burns (a feed move with the spindle on and a
/// speed above 0); otherwise the torch burns from spindle on to spindle off.
pub fn run(rs274: &std::path::Path, program: &str, radius_mm: f64, laser: bool) -> Machine {
    let dir = std::env::temp_dir().join(format!(
        "cutroute-rs274-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let (ngc, tbl, var) = (dir.join("p.ngc"), dir.join("t.tbl"), dir.join("p.var"));
    std::fs::write(&ngc, program).unwrap();
    // Without an INI file the interpreter's machine units are inches: so is the table.
    let table: String = (1..=9)
        .map(|n| format!("T{n} P{n} D{:.9}\n", 2.0 * radius_mm / 25.4))
        .collect();
    std::fs::write(&tbl, table).unwrap();
    std::fs::write(&var, "").unwrap();
    let root = rs274.parent().and_then(|p| p.parent()).unwrap();
    let libs = format!(
        "{}:{}",
        root.join("lib").display(),
        root.join("lib/x86_64-linux-gnu").display()
    );
    let out = Command::new(rs274)
        .env("LD_LIBRARY_PATH", libs)
        // The tool table is shared through `$HOME/.tool.mmap`: runs at the same time (other
        // tests, other users of the machine) would read each other's radii.
        .env("HOME", &dir)
        .arg("-t")
        .arg(&tbl)
        .arg("-v")
        .arg(&var)
        .arg("-g")
        .arg(&ngc)
        .stdin(Stdio::null())
        .output()
        .expect("rs274 runs");
    let _ = std::fs::remove_dir_all(&dir);
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    summarise(&text, laser)
}

fn args(call: &str) -> Vec<f64> {
    let inner = call
        .split_once('(')
        .and_then(|(_, rest)| rest.rsplit_once(')'))
        .map_or("", |(inner, _)| inner);
    inner
        .split(',')
        .filter_map(|a| a.trim().parse::<f64>().ok())
        .collect()
}

/// The machine's pierces and lengths from rs274's canonical output.
pub fn summarise(text: &str, laser: bool) -> Machine {
    let mut m = Machine::default();
    let (mut unit, mut g92, mut g5x) = (1.0, Point::new(0.0, 0.0), Point::new(0.0, 0.0));
    let mut at = Point::new(0.0, 0.0);
    let (mut spindle, mut speed, mut burning) = (false, 0.0_f64, false);
    let mut errors = Vec::new();
    for line in text.lines() {
        let trimmed = line.trim_start();
        if !trimmed.starts_with(|c: char| c.is_ascii_digit()) {
            if !trimmed.is_empty() && trimmed != "executing" {
                errors.push(trimmed.to_string());
            }
            continue;
        }
        // `   12 N..... CALL(args)`
        let call = trimmed
            .split_whitespace()
            .skip(2)
            .collect::<Vec<_>>()
            .join(" ");
        let a = args(&call);
        let frame = |x: f64, y: f64| Point::new(x * unit + g92.x + g5x.x, y * unit + g92.y + g5x.y);
        let name = call.split('(').next().unwrap_or("");
        match name {
            "USE_LENGTH_UNITS" => unit = if call.contains("INCHES") { 25.4 } else { 1.0 },
            "SET_G92_OFFSET" if a.len() >= 2 => g92 = Point::new(a[0] * unit, a[1] * unit),
            "SET_G5X_OFFSET" if a.len() >= 3 => g5x = Point::new(a[1] * unit, a[2] * unit),
            "START_SPINDLE_CLOCKWISE" | "START_SPINDLE_COUNTERCLOCKWISE" => spindle = true,
            "STOP_SPINDLE_TURNING" => spindle = false,
            "SET_SPINDLE_SPEED" if !a.is_empty() => speed = a[a.len() - 1],
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" | "ARC_FEED" if a.len() >= 2 => {
                let feed = name != "STRAIGHT_TRAVERSE";
                let burns = spindle && (!laser || (feed && speed > 0.0));
                if burns && !burning {
                    m.pierces.push(at);
                }
                burning = burns;
                let to = frame(a[0], a[1]);
                let length = if name == "ARC_FEED" {
                    let centre = frame(a[2], a[3]);
                    let turns = a[4];
                    let r = at.distance(centre);
                    let (s, e) = (at - centre, to - centre);
                    let turn = e.y.atan2(e.x) - s.y.atan2(s.x);
                    let tau = std::f64::consts::TAU;
                    let mut sweep = if turns > 0.0 {
                        turn.rem_euclid(tau)
                    } else {
                        (-turn).rem_euclid(tau)
                    };
                    if sweep < 1e-9 {
                        sweep = tau;
                    }
                    sweep += tau * (turns.abs() - 1.0);
                    r * sweep
                } else {
                    at.distance(to)
                };
                // A rapid is never a cut, whatever the spindle does.
                if burning && feed {
                    m.cut += length;
                } else {
                    m.idle += length;
                }
                at = to;
            }
            _ => {}
        }
        if !laser && spindle && !burning {
            burning = true;
            m.pierces.push(at);
        } else if !spindle {
            burning = false;
        }
    }
    if !errors.is_empty() {
        m.error = Some(errors.join("\n"));
    }
    m
}
