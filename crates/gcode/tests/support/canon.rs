//! LinuxCNC's standalone interpreter `rs274` as a referee: runs a program and parses its
//! canonical machining calls into the tool centre's motion (its own cutter compensation
//! included), with the torch taken to be the spindle.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use cutroute_geometry::{Point, Span};

/// Where `scripts/install-rs274.sh` puts the interpreter's wrapper.
const DEFAULT_RS274: &str = "/opt/cutroute/linuxcnc/rs274";

/// The interpreter, from `CUTROUTE_RS274` or the install script's fixed path. `None` (with a
/// message) when it is missing on a developer's machine; in CI (`CI` set) a missing
/// interpreter fails the test instead of skipping it.
pub fn rs274() -> Option<PathBuf> {
    let path = std::env::var_os("CUTROUTE_RS274")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(DEFAULT_RS274));
    if path.is_file() {
        return Some(path);
    }
    let message = format!(
        "rs274 missing at {}: run scripts/install-rs274.sh",
        path.display()
    );
    if std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false") {
        panic!("{message}");
    }
    eprintln!("{message}");
    None
}

/// One motion of the tool centre.
#[derive(Clone, Copy, Debug)]
pub struct Motion {
    /// `STRAIGHT_TRAVERSE` (a rapid).
    pub rapid: bool,
    /// The torch was on during it.
    pub tool_on: bool,
    /// How many torch-ons came before it.
    pub torch_ons: usize,
    pub span: Span,
}

/// What the interpreter made of a program.
#[derive(Clone, Debug, Default)]
pub struct Run {
    pub motions: Vec<Motion>,
    /// Where the head stood at each torch-on.
    pub torch_on_at: Vec<Point>,
}

/// Runs `program` through `rs274` with a tool table whose tool 1 has diameter `tool_diameter`
/// (for `G41 D1`); `Err` carries the interpreter's message.
pub fn run(rs274: &PathBuf, program: &str, tool_diameter: f64, name: &str) -> Result<Run, String> {
    let stem: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    // The interpreter writes its parameter file into its working folder: one folder per run
    // (numbered: two tests may run a case of the same name at once, and one would remove the
    // other's folder), so that runs in parallel tests do not share it.
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir()
        .join(format!("cutroute-rs274-{}", std::process::id()))
        .join(format!("{}-{stem}", RUNS.fetch_add(1, Ordering::Relaxed)));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let tool = dir.join(format!("{stem}.tbl"));
    let file = dir.join(format!("{stem}.ngc"));
    // Without an INI file the interpreter's machine unit is the inch, the tool table's too.
    let inches = tool_diameter / 25.4;
    std::fs::write(&tool, format!("T1 P1 D{inches:.9} ;\n")).map_err(|e| e.to_string())?;
    std::fs::write(&file, program).map_err(|e| e.to_string())?;
    // Interpreters running at once share memory and one of them now and then dies of a bus
    // error: the runs of this process take turns, and a run killed by a signal (another
    // process's interpreter may collide with it) is run again; a refusal is never retried.
    static TURNS: Mutex<()> = Mutex::new(());
    let _turn = TURNS.lock().unwrap_or_else(|e| e.into_inner());
    let mut attempts = 0;
    let out = loop {
        let out = Command::new(rs274)
            .arg("-g")
            .arg("-t")
            .arg(&tool)
            .arg(&file)
            .current_dir(&dir)
            // Its own HOME too: the interpreter keeps files there that runs of other test
            // processes would otherwise share (a run then found another's tool table).
            .env("HOME", &dir)
            .stdin(Stdio::null())
            .output()
            .map_err(|e| format!("cannot run {}: {e}", rs274.display()))?;
        attempts += 1;
        if out.status.code().is_some() || attempts == 3 {
            break out;
        }
    };
    if std::env::var_os("CUTROUTE_RS274_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        let message: Vec<&str> = stderr.lines().filter(|l| *l != "executing").collect();
        let last = stdout.lines().last().unwrap_or("");
        return Err(format!(
            "rs274 refused ({}): {} (last call: {last})",
            out.status,
            message.join(" | ")
        ));
    }
    parse(&stdout)
}

/// The text after `call(` when the line is that call. Lines are `  <count> N<line number>
/// CALL(…)`, the line number field padded to six characters and run into the call's name
/// when it is longer.
fn call<'a>(line: &'a str, call: &str) -> Option<&'a str> {
    let at = line.find(&format!("{call}("))?;
    let before = line[..at].chars().next_back();
    if before.is_some_and(|c| c.is_ascii_alphabetic() || c == '_') {
        return None;
    }
    Some(&line[at + call.len() + 1..])
}

fn arguments(line: &str, name: &str) -> Option<Vec<f64>> {
    let rest = call(line, name)?;
    let inner = &rest[..rest.find(')')?];
    inner
        .split(',')
        .map(|a| a.trim().parse::<f64>().ok())
        .collect()
}

/// The motion of the canonical calls (`rs274`'s output), from the origin where it starts.
pub fn parse(canonical: &str) -> Result<Run, String> {
    let mut run = Run::default();
    let mut at = Point::new(0.0, 0.0);
    let mut on = false;
    for line in canonical.lines() {
        if call(line, "START_SPINDLE_CLOCKWISE").is_some()
            || call(line, "START_SPINDLE_COUNTERCLOCKWISE").is_some()
        {
            on = true;
            run.torch_on_at.push(at);
        } else if call(line, "STOP_SPINDLE_TURNING").is_some() {
            on = false;
        } else if let Some(a) = arguments(line, "STRAIGHT_TRAVERSE") {
            let to = Point::new(a[0], a[1]);
            run.motions.push(Motion {
                rapid: true,
                tool_on: on,
                torch_ons: run.torch_on_at.len(),
                span: Span::line(at, to),
            });
            at = to;
        } else if let Some(a) = arguments(line, "STRAIGHT_FEED") {
            let to = Point::new(a[0], a[1]);
            run.motions.push(Motion {
                rapid: false,
                tool_on: on,
                torch_ons: run.torch_on_at.len(),
                span: Span::line(at, to),
            });
            at = to;
        } else if let Some(a) = arguments(line, "ARC_FEED") {
            // ARC_FEED(end x, end y, centre x, centre y, rotation, z, …): rotation > 0 is
            // counter-clockwise, |rotation| - 1 extra full turns.
            let (to, centre, rotation) = (Point::new(a[0], a[1]), Point::new(a[2], a[3]), a[4]);
            let angle = |p: Point| (p.y - centre.y).atan2(p.x - centre.x);
            let mut sweep = angle(to) - angle(at);
            let turn = 2.0 * std::f64::consts::PI;
            if rotation > 0.0 {
                while sweep <= 1e-12 {
                    sweep += turn;
                }
            } else {
                while sweep >= -1e-12 {
                    sweep -= turn;
                }
            }
            if rotation.abs() > 1.0 {
                return Err(format!("arc of more than one turn: {line}"));
            }
            let span = Span::new(at, to, (sweep / 4.0).tan());
            run.motions.push(Motion {
                rapid: false,
                tool_on: on,
                torch_ons: run.torch_on_at.len(),
                span,
            });
            at = to;
        }
    }
    Ok(run)
}
