//! The reader: the tool motion of a G-code program, as a controller runs it.
//!
//! It understands what [`crate::write_gcode`] writes and the common variants of hand-written and
//! other post-processors' programs (DXF2GCODE, SheetCam, LightBurn, Inkscape's gcodetools):
//! `G00`–`G03` (arcs by `I`/`J` or `R`, full circles), `G04` dwell (`P` or `X` seconds),
//! `G20`/`G21` (inches are converted to mm), `G90`/`G91`, `G90.1`/`G91.1` (absolute or
//! incremental arc centres), `G92` (the head's position gets new coordinates: an offset of the
//! program's frame; the motion is reported in the frame the program started in, so the head's
//! path stays continuous), `G92.1` (offset cancelled and forgotten), `G92.2` (cancelled, kept),
//! `G92.3` (the kept one restored), `G53` (a `G0`/`G1` move in machine coordinates: the frame
//! the program started in, the work offsets being zero as in rs274), `N` line numbers, `O` program numbers, `( )` comments
//! (`(MSG,…)` among them) and `;` comments, spaces anywhere (LinuxCNC ignores them), `%` tape
//! marks, block delete `/` (the block is executed), modal motion (a line of bare coordinates
//! continues the last motion). Harmless
//! modal codes (`G17`, `G43`/`G43.1`/`G43.2`, `G49`, `G54`–`G59`, `G61`, `G64`, `G80`, `G94`, `G96`/`G97` spindle speed
//! modes) are accepted; codes that would change the meaning of the motion (other planes, canned
//! cycles, homing, probing, …) are refused with their location. LinuxCNC's polar coordinates
//! (`@` distance, `^` angle) are read on straight moves. Z
//! and the rotary axes are ignored: the motion is the head's path in the sheet's plane.
//!
//! LinuxCNC's language is read as its interpreter (rs274) runs it:
//! - parameters (`#1`, `#<local>`, `#<_global>`), expressions (`[ … ]`, operators, functions)
//!   and what a program may read back of the machine: see the `expr` module; `#n = …`
//!   assignments take effect after their whole line is read;
//! - O-word control flow (subroutines in the file, `if`, `while`, `do`, `repeat`, `break`,
//!   `continue`, `return`): see the `flow` module; `M2`/`M30` end the program there. A call of
//!   a subroutine not in the file, a loop that runs more than a million lines, recursion
//!   deeper than 100 calls are refused where they stand.
//! - Values only a running machine has are refused, naming the item and what it would need:
//!   `#<_hal[…]>` (rs274 refuses it too), `#<_ini[…]>`, tool data `#5400`–`#5413` (rs274
//!   answers from its own tool table, the reader has none), positions of Z and rotary axes.
//! - M codes: user M codes `M100`–`M199` (QtPlasmaC's `M190` material change among them) run a
//!   program the controller finds in its USER_M_PATH: refused, as rs274 refuses them without
//!   it. Digital and analog outputs (`M62`–`M65`, `M67`, `M68`), waiting on an input (`M66`;
//!   `#5399` keeps its value, 0 unless set, as in rs274), adaptive feed and feed hold (`M52`, `M53`) and the other
//!   M codes besides the torch's change no motion: accepted. A tool change `M6` switches the
//!   torch off, as LinuxCNC stops the spindle for it, and is refused under compensation. A program without `M2`/`M30`
//!   (which rs274 requires) is read to its last line.
//!
//! The torch burns from its on code to its off code. In GRBL laser mode
//! ([`ReadOptions::laser_mode`], or from a program's `M04`, dynamic power, which only laser
//! mode has) the beam burns only on feed moves with a power `S` above 0: a rapid or an `S0`
//! move is travel with the beam off, and the next burning move is a new pierce.
//!
//! Cutter (kerf) compensation: `G41`/`G42` take their radius from the controller's tool table,
//! which the reader is given as [`ReadOptions::compensation_radius`]; `G41.1`/`G42.1
//! D<diameter>` carry it. [`ReadOptions::compensation_model`] says how the stretch from the
//! start-up move to `G40` (or the program's end) becomes the tool centre's path (see
//! [`CompensationModel`]). As in LinuxCNC, the tool stays at that path's end until the next
//! move, which must be straight and runs from there to its programmed point; a torch switch
//! under compensation happens where the compensated move before it ends.

mod expr;
mod flow;
mod linuxcnc;
mod loops;
use linuxcnc::Side;
pub use loops::closed_loop_start;

use cutroute_geometry::float::Libm;
use std::f64::consts::{PI, TAU};

use cutroute_geometry::{
    equidistant, opened_at, Contour, PathRoute, Point, Span, ToolMove, ToolOnPath, Toolpath, Vertex,
};
use thiserror::Error;

/// Settings of [`read_gcode`].
#[derive(Clone, Debug, PartialEq)]
pub struct ReadOptions {
    /// Where the head stands when the program begins (incremental programs start from here).
    pub start: Point,
    /// M numbers that switch the torch on (`M03` = 3).
    pub torch_on: Vec<u32>,
    /// M numbers that switch it off.
    pub torch_off: Vec<u32>,
    /// Largest difference between an arc's start radius and end radius, mm (arcs written with
    /// rounded coordinates never match exactly).
    pub arc_tolerance_mm: f64,
    /// `G04 P` counts milliseconds (Fanuc-style controllers), not seconds; `G04 X` stays
    /// seconds.
    pub dwell_p_milliseconds: bool,
    /// Half the kerf, mm, for `G41 D<n>`/`G42 D<n>` (the controller's tool table holds it;
    /// `G41.1 D<kerf>` carries it in the program).
    pub compensation_radius: Option<f64>,
    /// GRBL laser mode (`$32=1`) from the first line: the beam burns only on `G01`–`G03` moves
    /// with a power `S` above 0; a rapid or an `S0` move is travel with the beam off. A
    /// program's `M04` (dynamic power, which only laser mode has) switches it on as well.
    pub laser_mode: bool,
    /// How a `G41`/`G42` … `G40` stretch becomes the tool centre's path.
    pub compensation_model: CompensationModel,
}

/// How the reader turns a cutter-compensated stretch into the tool centre's path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CompensationModel {
    /// As cutroute's post-processor intends it: the closed contour programmed after the
    /// start-up move, offset whole by the radius, entered from where the head stood and left
    /// to the cancel move's end.
    ClosedContour,
    /// As LinuxCNC's interpreter runs it, move by move: a straight start-up move ends offset
    /// perpendicular to itself, convex corners get arcs about the programmed corner, concave
    /// ones end at the offsets' intersection (or are refused where the tool would gouge), and
    /// the move after `G40` is straight from where the tool stands. The default: a program is read
    /// as the controller the writer's compensated programs are checked against runs it.
    #[default]
    LinuxCnc,
}

impl Default for ReadOptions {
    /// Starts at the origin; `M03`/`M04` torch on, `M05` off; arcs tolerate 0.01 mm.
    fn default() -> Self {
        ReadOptions {
            start: Point::new(0.0, 0.0),
            torch_on: vec![3, 4],
            torch_off: vec![5],
            arc_tolerance_mm: 0.01,
            dwell_p_milliseconds: false,
            compensation_radius: None,
            laser_mode: false,
            compensation_model: CompensationModel::default(),
        }
    }
}

/// One thing the machine does, with the (1-based) line it comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// `G00`: a rapid straight move.
    Rapid {
        /// Where it starts.
        from: Point,
        /// Where it ends.
        to: Point,
        /// Line of the program.
        line: usize,
    },
    /// `G01`/`G02`/`G03`: a move at feed rate, straight or along an arc (an arc of more than
    /// 180° is given as two spans).
    Feed {
        /// The path (bulge > 0 for `G03`, counter-clockwise).
        span: Span,
        /// The torch was on.
        tool_on: bool,
        /// Feed rate in force, mm/min, if one was set.
        feed: Option<f64>,
        /// Line of the program.
        line: usize,
    },
    /// The torch switched on (a pierce).
    TorchOn {
        /// Where the head stands.
        at: Point,
        /// Line of the program.
        line: usize,
    },
    /// The torch switched off.
    TorchOff {
        /// Where the head stands.
        at: Point,
        /// Line of the program.
        line: usize,
    },
    /// `G04`: the head waits.
    Dwell {
        /// For how long, seconds.
        seconds: f64,
        /// Line of the program.
        line: usize,
    },
}

/// The tool motion of a program.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Program {
    /// Where the head starts.
    pub start: Point,
    /// What the machine does, in order.
    pub motions: Vec<Motion>,
    /// Where the head ends.
    pub end: Point,
}

impl Program {
    /// Length of the moves with the torch off (rapids and feed moves), mm.
    pub fn idle_length(&self) -> f64 {
        self.motions
            .iter()
            .map(|m| match m {
                Motion::Rapid { from, to, .. } => from.distance(*to),
                Motion::Feed {
                    span,
                    tool_on: false,
                    ..
                } => span.length(),
                _ => 0.0,
            })
            .sum()
    }

    /// Length cut with the torch on, mm.
    pub fn cut_length(&self) -> f64 {
        self.motions
            .iter()
            .map(|m| match m {
                Motion::Feed {
                    span,
                    tool_on: true,
                    ..
                } => span.length(),
                _ => 0.0,
            })
            .sum()
    }

    /// Where the torch was switched on, in order.
    pub fn pierce_points(&self) -> Vec<Point> {
        self.motions
            .iter()
            .filter_map(|m| match m {
                Motion::TorchOn { at, .. } => Some(*at),
                _ => None,
            })
            .collect()
    }

    /// Number of times the torch was switched on.
    pub fn pierce_count(&self) -> usize {
        self.pierce_points().len()
    }

    /// Total dwell time, seconds.
    pub fn dwell_time(&self) -> f64 {
        self.motions
            .iter()
            .map(|m| match m {
                Motion::Dwell { seconds, .. } => *seconds,
                _ => 0.0,
            })
            .sum()
    }

    /// The program as a [`Toolpath`] (for animation and statistics): rapids and torch-off feed
    /// moves become idle moves (a torch-off arc becomes its chord), each torch-on a pierce that
    /// starts a new step, torch-on feed moves its cuts. Cuts before the first pierce cannot
    /// happen: the torch is off then.
    pub fn toolpath(&self) -> Toolpath {
        let mut moves = Vec::with_capacity(self.motions.len());
        let mut step = 0usize;
        for m in &self.motions {
            match *m {
                Motion::Rapid { from, to, .. } => moves.push(ToolMove::Idle { from, to }),
                Motion::Feed {
                    span,
                    tool_on: false,
                    ..
                } => moves.push(ToolMove::Idle {
                    from: span.start,
                    to: span.end,
                }),
                // A feed move cannot tell a contour's cut from a chain's tool-on link: both
                // count as cut length, which is all a read-back check needs.
                Motion::Feed { span, .. } => moves.push(ToolMove::Cut {
                    step: step.saturating_sub(1),
                    span,
                    link: false,
                }),
                Motion::TorchOn { at, .. } => {
                    moves.push(ToolMove::Pierce { at, step });
                    step += 1;
                }
                Motion::TorchOff { .. } | Motion::Dwell { .. } => {}
            }
        }
        Toolpath {
            start: self.start,
            moves,
        }
    }
}

impl Program {
    /// The program as a route of tool-on paths (what segment cutting and AOE-chains write): each
    /// torch-on starts a path at the head's position, and the torch-on feed moves until the next
    /// torch-on are its spans, whether they close contours or not. The route finishes where the
    /// program ends when the head moves on after the last cut. Idle travel between paths is
    /// taken as the straight move a [`PathRoute`] implies, so a program whose idle motion bends
    /// (several rapids between two pierces) reads back with less idle length than
    /// [`Program::idle_length`].
    pub fn path_route(&self) -> PathRoute {
        let mut paths: Vec<ToolOnPath> = Vec::new();
        for m in &self.motions {
            match *m {
                Motion::TorchOn { at, .. } => paths.push(ToolOnPath {
                    pierce: at,
                    spans: Vec::new(),
                    leads: None,
                }),
                Motion::Feed {
                    span,
                    tool_on: true,
                    ..
                } => {
                    if let Some(path) = paths.last_mut() {
                        path.spans.push(span);
                    }
                }
                _ => {}
            }
        }
        let last_exit = paths.last().map_or(self.start, ToolOnPath::end);
        PathRoute {
            start: self.start,
            paths,
            finish: (last_exit != self.end).then_some(self.end),
        }
    }
}

/// What is wrong with a program, and where (1-based line and column).
#[derive(Clone, Debug, PartialEq, Error)]
pub enum GcodeReadError {
    /// A character that starts no word.
    #[error("line {line}, column {column}: unexpected character {found:?}")]
    UnexpectedCharacter {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The character.
        found: char,
    },
    /// A letter without a number after it.
    #[error("line {line}, column {column}: {letter} has no number")]
    MissingNumber {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The word's letter.
        letter: char,
    },
    /// A number too large for a machine (above 10⁹ in magnitude).
    #[error("line {line}, column {column}: the value of {letter} is out of range")]
    NumberOutOfRange {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The word's letter.
        letter: char,
    },
    /// A `(` comment that does not close on its line.
    #[error("line {line}, column {column}: comment not closed")]
    UnclosedComment {
        /// Line.
        line: usize,
        /// Column of the `(`.
        column: usize,
    },
    /// The same letter twice in one block (e.g. two X words).
    #[error("line {line}, column {column}: {letter} appears twice in the block")]
    DuplicateWord {
        /// Line.
        line: usize,
        /// Column of the second word.
        column: usize,
        /// The letter.
        letter: char,
    },
    /// Two codes of one modal group in one block (e.g. `G00 G01`), or a dwell with axis words.
    #[error("line {line}, column {column}: {second} conflicts with {first} in the same block")]
    ConflictingCodes {
        /// Line.
        line: usize,
        /// Column of the second code.
        column: usize,
        /// The first code.
        first: String,
        /// The second code.
        second: String,
    },
    /// A G code outside the supported subset.
    #[error("line {line}, column {column}: {code} is not supported")]
    UnsupportedCode {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The code as read (e.g. `G18`).
        code: String,
    },
    /// Coordinates before any motion code (`G00`–`G03`) was given.
    #[error("line {line}, column {column}: coordinates without a motion mode (G00–G03)")]
    MotionWithoutMode {
        /// Line.
        line: usize,
        /// Column of the first coordinate.
        column: usize,
    },
    /// A feed move (`G01`–`G03`) with no feed rate set, or a zero one: the controller refuses
    /// it rather than guess a speed.
    #[error(
        "line {line}, column {column}: a feed move (G01–G03) without a feed rate: give F before it"
    )]
    FeedMoveWithoutFeed {
        /// Line.
        line: usize,
        /// Column of the motion code or first coordinate.
        column: usize,
    },
    /// A `G02`/`G03` move with neither `I`/`J` nor `R`.
    #[error("line {line}, column {column}: arc without centre (I/J) or radius (R)")]
    ArcWithoutCentre {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
    },
    /// The centre is not equally far from both ends of the arc.
    #[error("line {line}, column {column}: arc radius {start_radius} at the start but {end_radius} at the end")]
    ArcRadiusMismatch {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// Distance from the centre to the start.
        start_radius: f64,
        /// Distance from the centre to the end.
        end_radius: f64,
    },
    /// The radius is too small to reach from the start to the end (or zero).
    #[error(
        "line {line}, column {column}: arc radius {radius} cannot span half-chord {half_chord}"
    )]
    ArcRadiusTooSmall {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The radius.
        radius: f64,
        /// Half the distance between the ends.
        half_chord: f64,
    },
    /// An `R` arc whose ends coincide (its circle is undetermined).
    #[error("line {line}, column {column}: R arc with coinciding ends")]
    ZeroLengthRadiusArc {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
    },
    /// `G04` without `P` or `X`, or with a negative time.
    #[error("line {line}, column {column}: dwell without a non-negative time (P or X seconds)")]
    InvalidDwell {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
    },
    /// Cutter (kerf) compensation that this reader cannot follow.
    #[error("line {line}, column {column}: cutter compensation: {problem}")]
    Compensation {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What is wrong.
        problem: &'static str,
    },
    /// A parameter or expression without a value (undefined, division by zero, bad syntax).
    #[error("line {line}, column {column}: {problem}")]
    Expression {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What is wrong.
        problem: String,
    },
    /// A value only the running machine knows (a HAL pin, the INI file, the tool table).
    #[error(
        "line {line}, column {column}: {item} cannot be known from the program: it needs {needs}"
    )]
    UnknownValue {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The parameter (e.g. `#<_hal[plasmac.cut-feed-rate]>`).
        item: String,
        /// What would give it a value.
        needs: &'static str,
    },
    /// O-word control flow that does not fit together, or calls what is not in the program.
    #[error("line {line}, column {column}: {problem}")]
    ControlFlow {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What is wrong.
        problem: String,
    },
    /// The program runs more lines than any real one (a loop that never ends).
    #[error("line {line}, column {column}: the program runs more than {limit} lines (a loop that never ends?)")]
    RunsTooLong {
        /// Line where the limit was reached.
        line: usize,
        /// Column.
        column: usize,
        /// The limit.
        limit: usize,
    },
}

impl GcodeReadError {
    /// The (line, column) of the error, both 1-based.
    pub fn location(&self) -> (usize, usize) {
        use GcodeReadError::*;
        match *self {
            UnexpectedCharacter { line, column, .. }
            | MissingNumber { line, column, .. }
            | NumberOutOfRange { line, column, .. }
            | UnclosedComment { line, column }
            | DuplicateWord { line, column, .. }
            | ConflictingCodes { line, column, .. }
            | UnsupportedCode { line, column, .. }
            | MotionWithoutMode { line, column }
            | FeedMoveWithoutFeed { line, column }
            | ArcWithoutCentre { line, column }
            | ArcRadiusMismatch { line, column, .. }
            | ArcRadiusTooSmall { line, column, .. }
            | ZeroLengthRadiusArc { line, column }
            | InvalidDwell { line, column }
            | Compensation { line, column, .. }
            | Expression { line, column, .. }
            | UnknownValue { line, column, .. }
            | ControlFlow { line, column, .. }
            | RunsTooLong { line, column, .. } => (line, column),
        }
    }
}

/// Largest magnitude of any number in a program.
const MAX_VALUE: f64 = 1e9;
/// Ends closer than this (mm) make a full circle of an `I`/`J` arc.
const SAME_POINT: f64 = 1e-9;

#[derive(Clone, Copy)]
struct Word {
    letter: char,
    value: f64,
    column: usize,
}

/// Reads the tool motion of a G-code program; never panics.
pub fn read_gcode(text: &str, options: &ReadOptions) -> Result<Program, GcodeReadError> {
    let mut state = State {
        options,
        at: options.start,
        motion: None,
        incremental: false,
        incremental_centres: true,
        inches: false,
        tool_on: false,
        feed: None,
        motions: Vec::new(),
        compensation: None,
        tool_at: None,
        after_cancel: false,
        offset: Point::new(0.0, 0.0),
        saved_offset: Point::new(0.0, 0.0),
        laser: options.laser_mode,
        enabled: false,
        power_zero: false,
    };
    let lines = flow::run(text, &mut state)?;
    // LinuxCNC's program end flushes compensation as G40 does (rs274 wants M2 or M30; the
    // reader takes the last line for it).
    state.finish_compensation(lines)?;
    let end = state.head();
    Ok(Program {
        start: options.start,
        motions: state.motions,
        end,
    })
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum MotionMode {
    Rapid,
    Linear,
    Clockwise,
    CounterClockwise,
}

struct State<'a> {
    options: &'a ReadOptions,
    at: Point,
    motion: Option<MotionMode>,
    incremental: bool,
    incremental_centres: bool,
    inches: bool,
    tool_on: bool,
    feed: Option<f64>,
    motions: Vec<Motion>,
    /// Cutter compensation under way, from `G41`/`G42` to `G40`.
    compensation: Option<Compensated>,
    /// Where the head stands when that is not the programmed point `at`: after `G40`, at the
    /// end of the compensated path, until the next move in the plane (LinuxCNC reckons that
    /// move from the programmed point, and the machine runs it from where the tool stands).
    tool_at: Option<Point>,
    /// Compensation has just ended: LinuxCNC refuses an arc before a straight move (the head
    /// may stand off the programmed point, `tool_at`, only while this holds).
    after_cancel: bool,
    /// The `G92` offset: a programmed coordinate plus this is where the head goes, in the
    /// frame the program started in (the head's own motion stays continuous through a `G92`).
    offset: Point,
    /// The offset `G92.3` restores (LinuxCNC keeps it in parameters 5211–5212).
    saved_offset: Point,
    /// GRBL laser mode: the beam burns only on feed moves with a power above 0.
    laser: bool,
    /// The torch or beam is switched on (`M03`/`M04` and no `M05` since).
    enabled: bool,
    /// The last `S` was 0 (in laser mode: no beam).
    power_zero: bool,
}

/// `G92` and its companions, as LinuxCNC defines them.
#[derive(Clone, Copy, PartialEq, Eq)]
enum OffsetCode {
    /// `G92`: the head's position gets the coordinates of the axis words.
    Set,
    /// `G92.1`: no offset, and none kept for `G92.3`.
    Cancel,
    /// `G92.2`: no offset; the kept one stays for `G92.3`.
    Suspend,
    /// `G92.3`: the kept offset again.
    Restore,
}

/// A stretch of program under cutter compensation (`G41`/`G42` … `G40`), gathered whole: the
/// tool path can only be known once the stretch ends (LinuxCNC moves a move's end when it
/// sees the next one), at `G40` or the program's end.
struct Compensated {
    side: Side,
    radius: f64,
    /// Where the stretch starts: the programmed point the interpreter reckons from and where
    /// the head stands (they differ right after a `G40`), with the start-up move's line.
    from: Option<(Point, Point, usize)>,
    /// How many of `steps` the start-up move made (an arc of more than half a turn makes two).
    startup: usize,
    /// The programmed moves, the start-up move's first.
    steps: Vec<linuxcnc::Step>,
    /// Torch switches in the stretch: after how many of `steps`, on or off, and the line.
    /// LinuxCNC queues them behind the move before them, so they happen where its tool path
    /// ends.
    switches: Vec<(usize, bool, usize)>,
    /// The torch when the stretch began.
    tool_on: bool,
}

impl Compensated {
    /// The tool path of the stretch as cutroute's post-processor intends it: the start-up
    /// move from where the head stood to the contour's offset, the offset contour once round,
    /// and on along it as far as the programmed overcut goes, where the tool stays. `None`
    /// when the programmed moves do not close a contour or it has no offset.
    fn closed_contour_path(&self) -> Option<Vec<(Span, usize)>> {
        let (_, start, start_line) = self.from?;
        let first = self.steps.first()?.span.end;
        let spans: Vec<(Span, usize)> = self.steps[1..].iter().map(|s| (s.span, s.line)).collect();
        let spans = &spans;
        let k = spans
            .iter()
            .position(|(span, _)| span.end.distance(first) <= CLOSED)?;
        let (round, overcut) = (&spans[..=k], &spans[k + 1..]);
        let contour = Contour::new(
            round
                .iter()
                .map(|(s, _)| Vertex::arc(s.start.x, s.start.y, s.bulge))
                .collect(),
        );
        // Only a simple closed contour has an offset; anything else is refused before the
        // offset library sees it (it must never panic in the browser's worker).
        contour.validate().ok()?;
        let r = self.radius;
        let offset = match self.side {
            Side::Left => equidistant(&contour, r).ok()?,
            Side::Right => equidistant(&contour.reversed(), r).ok()?.reversed(),
        };
        let normal = |t: Point| match self.side {
            Side::Left => t.rotated_quarter(),
            Side::Right => -t.rotated_quarter(),
        };
        let on_offset = |p: Point| offset.nearest_point(p);
        let entry = on_offset(first + normal(spans[0].0.tangent_at(0.0)) * r)?;
        let cut = opened_at(&offset, entry.point, 1e-9);
        let round_line = spans[0].1;
        let mut path = vec![(Span::line(start, entry.point), start_line)];
        path.extend(cut.iter().map(|&span| (span, round_line)));
        if let Some((last, last_line)) = overcut.last() {
            let exit = on_offset(last.end + normal(last.tangent_at(1.0)) * r)?;
            let mut left = (offset.length_at(exit.position) - offset.length_at(entry.position))
                .rem_euclid(offset.perimeter());
            for span in cut {
                let l = span.length();
                if left <= 1e-9 || l <= 0.0 {
                    break;
                }
                path.push((span.sub_span(0.0, (left / l).min(1.0)), *last_line));
                left -= l;
            }
        }
        Some(path)
    }
}

/// Programmed points closer than this (mm) are one point: where a compensated contour closes.
const CLOSED: f64 = 1e-6;

/// The compensation code of a block: on to a side (with `.1`: the diameter in `D`), or off.
#[derive(Clone, Copy, PartialEq, Eq)]
enum CompensationCode {
    Off,
    On { side: Side, dynamic: bool },
}

/// The G codes of one block, sorted by what they change.
#[derive(Default)]
struct Codes {
    offset: Option<(OffsetCode, usize, String)>,
    compensation: Option<(CompensationCode, usize, String)>,
    motion: Option<(MotionMode, usize, String)>,
    dwell: Option<usize>,
    /// `G53`: this block's move is in machine coordinates (column of the code).
    machine: Option<usize>,
    /// `G80` was in the block.
    cycle_off: bool,
    distance: Option<(bool, usize, String)>,
    centres: Option<(bool, usize, String)>,
    units: Option<(bool, usize, String)>,
}

fn set<T>(
    slot: &mut Option<(T, usize, String)>,
    value: T,
    word: &Word,
    name: String,
    line: usize,
) -> Result<(), GcodeReadError> {
    if let Some((_, _, first)) = slot {
        return Err(GcodeReadError::ConflictingCodes {
            line,
            column: word.column,
            first: first.clone(),
            second: name,
        });
    }
    *slot = Some((value, word.column, name));
    Ok(())
}

impl State<'_> {
    /// What a program can read back of the machine through parameters.
    fn machine(&self) -> expr::Machine {
        let unit = if self.inches { 25.4 } else { 1.0 };
        expr::Machine {
            x: (self.at.x - self.offset.x) / unit,
            y: (self.at.y - self.offset.y) / unit,
            g92_x: self.offset.x / unit,
            g92_y: self.offset.y / unit,
            metric: !self.inches,
            absolute: !self.incremental,
        }
    }

    fn block(&mut self, words: &[Word], line: usize) -> Result<(), GcodeReadError> {
        if words.is_empty() {
            return Ok(());
        }
        let mut codes = Codes::default();
        let mut values: [Option<Word>; 26] = [None; 26];
        let mut m_codes = Vec::new();
        // LinuxCNC's polar coordinates: `@` distance and `^` angle (degrees) from the origin.
        let mut polar: [Option<Word>; 2] = [None; 2];
        for word in words {
            match word.letter {
                'G' => self.g_code(word, &mut codes, line)?,
                'M' => m_codes.push((word.value, word.column)),
                '$' => {}
                '@' | '^' => {
                    let slot = &mut polar[usize::from(word.letter == '^')];
                    if slot.is_some() {
                        return Err(GcodeReadError::DuplicateWord {
                            line,
                            column: word.column,
                            letter: word.letter,
                        });
                    }
                    *slot = Some(*word);
                }
                letter => {
                    let slot = &mut values[(letter as u8 - b'A') as usize];
                    if slot.is_some() {
                        return Err(GcodeReadError::DuplicateWord {
                            line,
                            column: word.column,
                            letter,
                        });
                    }
                    *slot = Some(*word);
                }
            }
        }
        let get = |letter: char| values[(letter as u8 - b'A') as usize];
        // Execution order of RS274/NGC: feed, spindle (torch), dwell, units, distance, motion.
        if let Some((inches, _, _)) = codes.units {
            self.inches = inches;
        }
        let unit = if self.inches { 25.4 } else { 1.0 };
        if let Some(f) = get('F') {
            self.feed = Some(f.value * unit);
        }
        if let Some(s) = get('S') {
            self.power_zero = s.value == 0.0;
        }
        for (m, column) in m_codes {
            let number = m.round();
            if (100.0..=199.0).contains(&number) {
                return Err(GcodeReadError::UnsupportedCode {
                    line,
                    column,
                    code: format!(
                        "M{number} (a user M code: the controller runs the program of that name in its USER_M_PATH)"
                    ),
                });
            }
            if number != m || number < 0.0 {
                continue;
            }
            let number = number as u32;
            // LinuxCNC's tool change stops the spindle first, and cannot happen while
            // compensation is on (it would change the radius).
            let tool_change = number == 6 && !self.options.torch_on.contains(&number);
            if tool_change && self.compensation.is_some() {
                return Err(GcodeReadError::Compensation {
                    line,
                    column,
                    problem: "a tool change (M6) while compensation is on",
                });
            }
            // After it the interpreter reads the head's position back from the machine: where
            // compensation left the tool becomes the programmed point.
            if tool_change {
                self.at = self.head();
                self.tool_at = None;
            }
            let (on, off) = (
                self.options.torch_on.contains(&number),
                self.options.torch_off.contains(&number) || tool_change,
            );
            // Dynamic power exists only in laser mode.
            self.laser |= on && number == 4;
            if on {
                self.enabled = true;
            } else if off {
                self.enabled = false;
            }
            if self.laser {
                // The beam follows the moves (on at a feed move, off at a rapid); off at once
                // on M05.
                if off {
                    self.switch(false, line)?;
                }
                continue;
            }
            if off {
                self.switch(false, line)?;
            } else if on {
                self.switch(true, line)?;
            }
        }
        if self.laser && (!self.enabled || self.power_zero) {
            self.switch(false, line)?;
        }
        let cartesian = ['X', 'Y'].into_iter().filter_map(get).next();
        let polar_word = polar.iter().flatten().next().copied();
        if let (Some(x), Some(p)) = (cartesian, polar_word) {
            return Err(GcodeReadError::ConflictingCodes {
                line,
                column: p.column,
                first: x.letter.to_string(),
                second: p.letter.to_string(),
            });
        }
        let axis = cartesian.or(polar_word);
        if let Some(column) = codes.dwell {
            // `G04 P… G00 X… Y…`: LinuxCNC dwells, then moves (the axis words are the move's).
            let then_moves = codes.motion.is_some() && get('P').is_some();
            let axis_words = axis.filter(|w| w.letter == 'Y' && !then_moves);
            if let Some(word) = axis_words.or(get('I')).or(get('R')) {
                return Err(GcodeReadError::ConflictingCodes {
                    line,
                    column: word.column,
                    first: "G04".into(),
                    second: word.letter.to_string(),
                });
            }
            // Fanuc-style `G04 X<seconds>` is the X word of a dwell block.
            let p_scale = if self.options.dwell_p_milliseconds {
                1e-3
            } else {
                1.0
            };
            let seconds = get('P')
                .map(|w| w.value * p_scale)
                .or(get('X').map(|w| w.value));
            match seconds {
                Some(s) if s >= 0.0 => self.motions.push(Motion::Dwell { seconds: s, line }),
                _ => return Err(GcodeReadError::InvalidDwell { line, column }),
            }
            if !then_moves {
                return Ok(());
            }
        }
        if let Some((incremental, _, _)) = codes.distance {
            self.incremental = incremental;
        }
        if let Some((incremental, _, _)) = codes.centres {
            self.incremental_centres = incremental;
        }
        if let Some((mode, _, _)) = codes.motion {
            self.motion = Some(mode);
        }
        if let Some((code, column, name)) = codes.offset {
            if let Some((_, _, motion)) = codes.motion {
                return Err(GcodeReadError::ConflictingCodes {
                    line,
                    column,
                    first: motion,
                    second: name,
                });
            }
            return self.offset_code(code, [get('X'), get('Y'), get('Z')], unit, line, column);
        }
        if let Some((code, column, _)) = codes.compensation {
            self.compensation_code(code, get('D'), unit, line, column)?;
        }
        if let Some(column) = codes.machine {
            // As rs274: a G53 block moves by G0 or G1, in absolute machine coordinates.
            let moves = axis.is_some() || get('Z').is_some();
            let straight = matches!(self.motion, Some(MotionMode::Rapid | MotionMode::Linear));
            let problem = if !moves && !codes.cycle_off {
                Some("G53 without a G0 or G1 move")
            } else if moves && !straight {
                Some("G53 with a motion other than G0 or G1")
            } else if axis.is_some() && (self.incremental || polar_word.is_some()) {
                Some("G53 with incremental or polar coordinates")
            } else if axis.is_some() && self.compensation.is_some() {
                Some("G53 under cutter compensation")
            } else {
                None
            };
            if let Some(problem) = problem {
                return Err(GcodeReadError::UnsupportedCode {
                    line,
                    column,
                    code: problem.into(),
                });
            }
        }
        let arc_words = ['I', 'J', 'R'].into_iter().filter_map(get).next();
        let straight = matches!(self.motion, Some(MotionMode::Rapid | MotionMode::Linear));
        if let (None, None, Some(z), true) = (axis, arc_words, get('Z'), straight) {
            // A move along Z alone is a straight move to LinuxCNC: as a start-up move it has
            // no length in the plane; after G40 it allows an arc again, and takes the head
            // from where compensation left it to the programmed point, which the interpreter
            // reckons as where it stands.
            if self
                .compensation
                .as_ref()
                .is_some_and(|c| c.steps.is_empty())
            {
                return Err(GcodeReadError::Compensation {
                    line,
                    column: z.column,
                    problem: "the start-up move is not longer than the tool radius",
                });
            }
            self.after_cancel = false;
            if let Some(from) = self.tool_at.take() {
                if self.motion == Some(MotionMode::Rapid) {
                    self.motions.push(Motion::Rapid {
                        from,
                        to: self.at,
                        line,
                    });
                } else {
                    self.feed_span(Span::line(from, self.at), line);
                }
            }
        }
        let Some(first) = axis.or(arc_words) else {
            return Ok(());
        };
        let Some(mode) = self.motion else {
            return Err(GcodeReadError::MotionWithoutMode {
                line,
                column: first.column,
            });
        };
        // Machine coordinates (G53) are the frame the program started in, less no offset.
        let offset = if codes.machine.is_some() {
            Point::new(0.0, 0.0)
        } else {
            self.offset
        };
        let coordinate = |letter: char, current: f64, offset: f64| match get(letter) {
            Some(w) if self.incremental => current + w.value * unit,
            Some(w) => w.value * unit + offset,
            None => current,
        };
        let to = if polar_word.is_some() {
            if !matches!(mode, MotionMode::Rapid | MotionMode::Linear) {
                return Err(GcodeReadError::UnsupportedCode {
                    line,
                    column: first.column,
                    code: "polar coordinates (@, ^) on an arc".into(),
                });
            }
            self.polar_point(polar, unit)
        } else {
            Point::new(
                coordinate('X', self.at.x, offset.x),
                coordinate('Y', self.at.y, offset.y),
            )
        };
        if self.laser {
            let burns = self.enabled && !self.power_zero && mode != MotionMode::Rapid;
            self.switch(burns, line)?;
        }
        let column = codes.motion.as_ref().map_or(first.column, |m| m.1);
        if mode != MotionMode::Rapid && !self.feed.is_some_and(|f| f > 0.0) {
            return Err(GcodeReadError::FeedMoveWithoutFeed { line, column });
        }
        match mode {
            MotionMode::Rapid if self.compensation.is_some() => {
                self.compensated_step(Span::line(self.at, to), line, true);
            }
            MotionMode::Rapid => {
                self.motions.push(Motion::Rapid {
                    from: self.head(),
                    to,
                    line,
                });
            }
            MotionMode::Linear => self.feed_span(Span::line(self.head(), to), line),
            MotionMode::Clockwise | MotionMode::CounterClockwise => {
                if self.after_cancel {
                    return Err(GcodeReadError::Compensation {
                        line,
                        column,
                        problem: "the move after G40 must be straight, not an arc",
                    });
                }
                let ccw = mode == MotionMode::CounterClockwise;
                let (sweep, centre) = if let Some(r) = get('R') {
                    (
                        self.radius_sweep(to, r.value * unit, ccw, line, column)?,
                        None,
                    )
                } else if get('I').is_some() || get('J').is_some() {
                    let centre_word = |letter: char, current: f64, offset: f64| match get(letter) {
                        Some(w) if self.incremental_centres => current + w.value * unit,
                        Some(w) => w.value * unit + offset,
                        None => current,
                    };
                    let centre = Point::new(
                        centre_word('I', self.at.x, offset.x),
                        centre_word('J', self.at.y, offset.y),
                    );
                    (
                        self.centre_sweep(to, centre, ccw, line, column)?,
                        Some(centre),
                    )
                } else {
                    return Err(GcodeReadError::ArcWithoutCentre { line, column });
                };
                self.arc(to, sweep, centre, line);
            }
        }
        if let Some(c) = self.compensation.as_mut() {
            if c.startup == 0 {
                c.startup = c.steps.len();
            }
        }
        self.after_cancel &= !matches!(mode, MotionMode::Rapid | MotionMode::Linear);
        self.at = to;
        self.tool_at = None;
        Ok(())
    }

    /// Where `@` (distance) and `^` (angle) take the head: about the program's origin, from
    /// the head's own distance and angle when one is missing; in `G91` both add to the head's.
    fn polar_point(&self, [distance, angle]: [Option<Word>; 2], unit: f64) -> Point {
        let here = (self.at - self.offset) * (1.0 / unit);
        let r0 = here.x.hypot_libm(here.y);
        let a0 = here.y.atan2_libm(here.x).to_degrees();
        let (r, a) = if self.incremental {
            (
                r0 + distance.map_or(0.0, |w| w.value),
                a0 + angle.map_or(0.0, |w| w.value),
            )
        } else {
            (
                distance.map_or(r0, |w| w.value),
                angle.map_or(a0, |w| w.value),
            )
        };
        let (sin, cos) = a.to_radians().sin_cos_libm();
        self.offset + Point::new(r * cos, r * sin) * unit
    }

    fn g_code(&self, word: &Word, codes: &mut Codes, line: usize) -> Result<(), GcodeReadError> {
        let tenths = (word.value * 10.0).round();
        let name = if tenths % 10.0 == 0.0 {
            format!("G{:02}", (tenths / 10.0) as i64)
        } else {
            format!("G{}", tenths / 10.0)
        };
        if (word.value * 10.0 - tenths).abs() > 1e-6 {
            return Err(GcodeReadError::UnsupportedCode {
                line,
                column: word.column,
                code: format!("G{}", word.value),
            });
        }
        use MotionMode::*;
        match tenths as i64 {
            0 => set(&mut codes.motion, Rapid, word, name, line),
            10 => set(&mut codes.motion, Linear, word, name, line),
            20 => set(&mut codes.motion, Clockwise, word, name, line),
            30 => set(&mut codes.motion, CounterClockwise, word, name, line),
            40 => {
                if codes.dwell.is_some() {
                    return Err(GcodeReadError::ConflictingCodes {
                        line,
                        column: word.column,
                        first: "G04".into(),
                        second: name,
                    });
                }
                codes.dwell = Some(word.column);
                Ok(())
            }
            200 => set(&mut codes.units, true, word, name, line),
            920 => set(&mut codes.offset, OffsetCode::Set, word, name, line),
            921 => set(&mut codes.offset, OffsetCode::Cancel, word, name, line),
            922 => set(&mut codes.offset, OffsetCode::Suspend, word, name, line),
            923 => set(&mut codes.offset, OffsetCode::Restore, word, name, line),
            210 => set(&mut codes.units, false, word, name, line),
            900 => set(&mut codes.distance, false, word, name, line),
            910 => set(&mut codes.distance, true, word, name, line),
            901 => set(&mut codes.centres, false, word, name, line),
            911 => set(&mut codes.centres, true, word, name, line),
            400 => set(
                &mut codes.compensation,
                CompensationCode::Off,
                word,
                name,
                line,
            ),
            410 | 411 | 420 | 421 => {
                let side = if tenths as i64 / 10 == 41 {
                    Side::Left
                } else {
                    Side::Right
                };
                let dynamic = tenths as i64 % 10 == 1;
                set(
                    &mut codes.compensation,
                    CompensationCode::On { side, dynamic },
                    word,
                    name,
                    line,
                )
            }
            // Plane XY, tool length offsets (on or off: they move Z only), work offsets, path
            // control, canned cycle off, feed per minute, spindle speed modes: nothing changes
            // for the head's XY path.
            530 => {
                codes.machine = Some(word.column);
                Ok(())
            }
            800 => {
                codes.cycle_off = true;
                Ok(())
            }
            170 | 430 | 431 | 432 | 490 | 540..=590 | 610 | 640 | 940 | 960 | 970 => Ok(()),
            _ => Err(GcodeReadError::UnsupportedCode {
                line,
                column: word.column,
                code: name,
            }),
        }
    }

    /// The torch (beam) switches on or off where the head stands, if it is not so already.
    fn switch(&mut self, on: bool, line: usize) -> Result<(), GcodeReadError> {
        if on == self.tool_on {
            return Ok(());
        }
        self.tool_on = on;
        if let Some(c) = self.compensation.as_mut() {
            c.switches.push((c.steps.len(), on, line));
            return Ok(());
        }
        let at = self.head();
        self.motions.push(if on {
            Motion::TorchOn { at, line }
        } else {
            Motion::TorchOff { at, line }
        });
        Ok(())
    }

    /// `G92` with its axis words (`X`, `Y`, `Z`), `G92.1`, `G92.2` or `G92.3`.
    fn offset_code(
        &mut self,
        code: OffsetCode,
        [x, y, z]: [Option<Word>; 3],
        unit: f64,
        line: usize,
        column: usize,
    ) -> Result<(), GcodeReadError> {
        match code {
            OffsetCode::Set => {
                if x.is_none() && y.is_none() && z.is_none() {
                    return Err(GcodeReadError::UnsupportedCode {
                        line,
                        column,
                        code: "G92 without axis words".into(),
                    });
                }
                if let Some(x) = x {
                    self.offset.x = self.at.x - x.value * unit;
                }
                if let Some(y) = y {
                    self.offset.y = self.at.y - y.value * unit;
                }
                self.saved_offset = self.offset;
            }
            OffsetCode::Cancel => {
                self.offset = Point::new(0.0, 0.0);
                self.saved_offset = self.offset;
            }
            OffsetCode::Suspend => self.offset = Point::new(0.0, 0.0),
            OffsetCode::Restore => self.offset = self.saved_offset,
        }
        Ok(())
    }

    fn feed_span(&mut self, span: Span, line: usize) {
        if self.compensation.is_some() {
            self.compensated_step(span, line, false);
            return;
        }
        self.motions.push(Motion::Feed {
            span,
            tool_on: self.tool_on,
            feed: self.feed,
            line,
        });
    }

    /// `G40`, `G41`/`G42` (radius from the options) or `G41.1`/`G42.1` (diameter in `D`).
    fn compensation_code(
        &mut self,
        code: CompensationCode,
        d: Option<Word>,
        unit: f64,
        line: usize,
        column: usize,
    ) -> Result<(), GcodeReadError> {
        let problem = |problem| GcodeReadError::Compensation {
            line,
            column,
            problem,
        };
        match code {
            // Already off, G40 is harmless.
            CompensationCode::Off => self.finish_compensation(line)?,
            CompensationCode::On { side, dynamic } => {
                if self.compensation.is_some() {
                    return Err(problem("compensation switched on twice without G40"));
                }
                let radius = if dynamic {
                    d.map(|w| 0.5 * w.value * unit)
                        .ok_or_else(|| problem("G41.1/G42.1 without the diameter D"))?
                } else {
                    self.options.compensation_radius.ok_or_else(|| {
                        problem(
                            "G41/G42 take the radius from the controller's tool table: give it (--compensation-radius MM)",
                        )
                    })?
                };
                if !(radius.is_finite() && radius >= 0.0) {
                    return Err(problem("negative compensation"));
                }
                self.compensation = Some(Compensated {
                    side,
                    radius,
                    from: None,
                    startup: 0,
                    steps: Vec::new(),
                    switches: Vec::new(),
                    tool_on: self.tool_on,
                });
            }
        }
        Ok(())
    }

    /// Where the head stands.
    fn head(&self) -> Point {
        self.tool_at.unwrap_or(self.at)
    }

    /// A programmed move under compensation, gathered into the stretch.
    fn compensated_step(&mut self, span: Span, line: usize, rapid: bool) {
        let (at, head) = (self.at, self.head());
        let c = self.compensation.as_mut().expect("compensation on");
        if c.steps.is_empty() {
            c.from = Some((at, head, line));
        }
        c.steps.push(linuxcnc::Step { span, line, rapid });
    }

    /// Compensation ends (`G40`, or the program's end, on `line`): the stretch becomes the
    /// tool centre's path, and the tool stays at its end, off the programmed point, until
    /// the next move. Compensation switched on without a move since ends with no motion.
    fn finish_compensation(&mut self, line: usize) -> Result<(), GcodeReadError> {
        let Some(c) = self.compensation.take() else {
            return Ok(());
        };
        let problem = |problem| GcodeReadError::Compensation {
            line,
            column: 1,
            problem,
        };
        let path: Vec<linuxcnc::ToolSpan> = match (c.from, self.options.compensation_model) {
            (None, _) => Vec::new(),
            (Some(_), CompensationModel::ClosedContour) => {
                let straight = c.startup == 1 && c.steps[0].span.bulge == 0.0;
                if !straight {
                    return Err(problem("the start-up move must be straight"));
                }
                if c.steps.iter().any(|s| s.rapid) {
                    return Err(problem("a rapid move while compensation is on"));
                }
                if !c.switches.is_empty() {
                    return Err(problem("the torch switches while compensation is on"));
                }
                c.closed_contour_path()
                    .ok_or_else(|| {
                        problem("the compensated moves do not close a contour that can be offset")
                    })?
                    .into_iter()
                    .map(|(span, line)| linuxcnc::ToolSpan {
                        span,
                        line,
                        rapid: false,
                        step: 0,
                    })
                    .collect()
            }
            (Some((origin, start, _)), CompensationModel::LinuxCnc) => {
                linuxcnc::tool_path(c.side, c.radius, (origin, start), &c.steps, c.startup, line)
                    .map_err(|(problem, line)| GcodeReadError::Compensation {
                        line,
                        column: 1,
                        problem,
                    })?
            }
        };
        let mut at = c.from.map_or(self.head(), |(_, head, _)| head);
        let mut tool_on = c.tool_on;
        let switch = |on: bool, at: Point, line: usize| {
            if on {
                Motion::TorchOn { at, line }
            } else {
                Motion::TorchOff { at, line }
            }
        };
        let mut switches = c.switches.iter().peekable();
        for piece in path {
            while let Some(&(_, on, switch_line)) = switches.next_if(|s| s.0 <= piece.step) {
                if on != tool_on {
                    tool_on = on;
                    self.motions.push(switch(on, at, switch_line));
                }
            }
            self.motions.push(if piece.rapid {
                Motion::Rapid {
                    from: piece.span.start,
                    to: piece.span.end,
                    line: piece.line,
                }
            } else {
                Motion::Feed {
                    span: piece.span,
                    tool_on,
                    feed: self.feed,
                    line: piece.line,
                }
            });
            at = piece.span.end;
        }
        for &(_, on, switch_line) in switches {
            if on != tool_on {
                tool_on = on;
                self.motions.push(switch(on, at, switch_line));
            }
        }
        // Compensation switched off without a move since leaves LinuxCNC's ban on an arc as
        // it was.
        self.after_cancel |= c.from.is_some();
        self.tool_at = (at.distance(self.at) > 0.0).then_some(at);
        Ok(())
    }

    /// Signed sweep of the arc to `to` about `centre`.
    fn centre_sweep(
        &self,
        to: Point,
        centre: Point,
        ccw: bool,
        line: usize,
        column: usize,
    ) -> Result<f64, GcodeReadError> {
        let (r0, r1) = (self.at.distance(centre), to.distance(centre));
        if (r0 - r1).abs() > self.options.arc_tolerance_mm {
            return Err(GcodeReadError::ArcRadiusMismatch {
                line,
                column,
                start_radius: r0,
                end_radius: r1,
            });
        }
        if r0 <= SAME_POINT {
            return Err(GcodeReadError::ArcRadiusTooSmall {
                line,
                column,
                radius: r0,
                half_chord: 0.5 * self.at.distance(to),
            });
        }
        let (a, b) = (self.at - centre, to - centre);
        let turn = b.y.atan2_libm(b.x) - a.y.atan2_libm(a.x);
        let sweep = if self.at.distance(to) <= SAME_POINT {
            TAU
        } else if ccw {
            turn.rem_euclid(TAU)
        } else {
            (-turn).rem_euclid(TAU)
        };
        Ok(if ccw { sweep } else { -sweep })
    }

    /// Signed sweep of the arc of radius `r` to `to` (negative `r`: the longer arc).
    fn radius_sweep(
        &self,
        to: Point,
        r: f64,
        ccw: bool,
        line: usize,
        column: usize,
    ) -> Result<f64, GcodeReadError> {
        let half_chord = 0.5 * self.at.distance(to);
        if half_chord <= SAME_POINT {
            return Err(GcodeReadError::ZeroLengthRadiusArc { line, column });
        }
        if r.abs() < half_chord - self.options.arc_tolerance_mm || r == 0.0 {
            return Err(GcodeReadError::ArcRadiusTooSmall {
                line,
                column,
                radius: r.abs(),
                half_chord,
            });
        }
        let short = 2.0 * (half_chord / r.abs()).min(1.0).asin_libm();
        let sweep = if r < 0.0 { TAU - short } else { short };
        Ok(if ccw { sweep } else { -sweep })
    }

    /// Appends the arc from the current point to `to`; arcs of more than half a turn are split
    /// at their middle so no bulge gets large (a full circle would have an infinite one).
    fn arc(&mut self, to: Point, sweep: f64, centre: Option<Point>, line: usize) {
        let from = self.at;
        if sweep.abs() <= PI {
            self.feed_span(Span::new(from, to, (sweep / 4.0).tan_libm()), line);
            return;
        }
        let middle = match centre {
            // Turning about the centre also works for a full circle, whose ends coincide.
            Some(c) => c + (from - c).rotated(0.5 * sweep),
            // An R arc: the midpoint is the zenith of the whole span.
            None => Span::new(from, to, (sweep / 4.0).tan_libm()).midpoint(),
        };
        let half_bulge = (sweep / 8.0).tan_libm();
        self.feed_span(Span::new(from, middle, half_bulge), line);
        self.feed_span(Span::new(middle, to, half_bulge), line);
    }
}
