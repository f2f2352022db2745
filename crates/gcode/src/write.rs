//! The post-processor: a [`Toolpath`] as a G-code program.

use cutroute_geometry::float::Libm;
use std::f64::consts::PI;
use std::fmt::Write as _;

use cutroute_geometry::{
    ContourRef, MachineParameters, Nest, PathRoute, Point, Route, RouteError, Span, ToolMove,
    Toolpath,
};
use thiserror::Error;

use crate::read::{read_gcode, CompensationModel, GcodeReadError, ReadOptions};

/// How coordinates are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DistanceMode {
    /// `G90`: every X/Y is a position on the machine's coordinate system.
    #[default]
    Absolute,
    /// `G91`: every X/Y is the increment from the previous position. So that the first move
    /// does not depend on where the machine stands, the program first moves to the toolpath's
    /// start in absolute coordinates (`G90`, `G00 X… Y…`) and then switches to `G91`.
    Incremental,
}

/// How arcs are written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ArcOutput {
    /// `G02`/`G03` with `I`/`J`: the centre as an offset from the arc's start (the usual
    /// incremental-centre convention, `G91.1`, in both distance modes).
    CentreOffsets,
    /// `G02`/`G03` with `R`: arcs are split into pieces of at most 150°, so `R` is always
    /// positive (many controllers do not accept the negative `R` of a long arc) and never close
    /// to half the chord, where rounding `R` in its last digit would change the sweep by far
    /// more than the rounding (at 180° a change of 0.5 µm in a 10 mm radius turns the end
    /// tangent by 0.03°).
    Radius,
    /// `G01` chords for machines without circular interpolation: no chord leaves the arc by
    /// more than `tolerance_mm`.
    Lines {
        /// Largest distance between a chord and its arc, mm (> 0).
        tolerance_mm: f64,
    },
}

/// How the pierce dwell is written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DwellFormat {
    /// `G04 P<seconds>` with three decimals (LinuxCNC, GRBL, Mach3 by default).
    #[default]
    PSeconds,
    /// `G04 X<seconds>` with three decimals (Fanuc-style controllers accept it as seconds).
    XSeconds,
    /// `G04 P<milliseconds>`, an integer (Fanuc-style controllers, Mach3 set to ms); read it
    /// back with [`crate::ReadOptions::dwell_p_milliseconds`].
    PMilliseconds,
    /// No dwell line: the controller times the pierce itself (its torch-on code pierces).
    Omitted,
}

/// Who moves the tool off the contour by half the kerf, for routes cut with kerf.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KerfCompensation {
    /// The program runs the tool centre on the equidistants: any controller.
    #[default]
    InProgram,
    /// The program runs on the contours and the controller keeps the tool left of the cut (on
    /// the scrap side) by half the kerf: `G41.1 D<kerf>` switches it on with the kerf written
    /// in the program (LinuxCNC), `G40` off. The operator can then trim the kerf at the machine.
    ControllerDiameter,
    /// As [`KerfCompensation::ControllerDiameter`] with `G41 D<n>`: the kerf is entry `n` of the
    /// controller's tool table (Fanuc-style, Mach3).
    ControllerRegister(u32),
}

/// Settings of the post-processor. The defaults suit a LinuxCNC/Mach3-style plasma or laser
/// controller with the machine parameters of [`MachineParameters::default`].
///
/// Torch codes differ between machines; common choices:
///
/// | controller | `torch_on` | `torch_off` |
/// |---|---|---|
/// | generic, Mach3 plasma, LinuxCNC | `M03` | `M05` |
/// | LinuxCNC QtPlasmaC | `M03 $0 S1` | `M05 $0` |
/// | GRBL in laser mode (power follows speed) | `M04 S1000` | `M05` |
///
/// The reader ([`crate::read_gcode`]) recognises the torch by its M number, so a custom
/// `torch_on` must start with an M word listed in [`crate::ReadOptions::torch_on`].
#[derive(Clone, Debug, PartialEq)]
pub struct GcodeOptions {
    /// Absolute (`G90`) or incremental (`G91`) coordinates.
    pub distance_mode: DistanceMode,
    /// Digits after the decimal point of coordinates, 0..=9 (3 = micrometres).
    pub decimals: usize,
    /// Prefix every line with `N<number>`.
    pub line_numbers: bool,
    /// Increment of the line numbers (usually 1, 5 or 10).
    pub line_number_step: u32,
    /// How arcs are written.
    pub arcs: ArcOutput,
    /// Arcs sweeping more than this many degrees are split into equal pieces (180 for
    /// controllers that reject longer arcs; at most 350 is used so that an arc never has nearly
    /// coincident ends, which a controller would read as a full circle).
    pub max_arc_sweep_deg: f64,
    /// Feed rate of cutting moves, mm/min (`F`).
    pub cut_feed_mm_per_min: f64,
    /// Line that switches the torch (laser, plasma arc) on.
    pub torch_on: String,
    /// Line that switches it off.
    pub torch_off: String,
    /// Dwell after switching the torch on, seconds (`G04 P<seconds>`; 0 writes no dwell).
    /// Fanuc-style controllers read `P` in milliseconds: set this in their unit if needed.
    pub pierce_dwell_s: f64,
    /// How the dwell is written.
    pub dwell_format: DwellFormat,
    /// Lines after the units and distance-mode lines (e.g. work offset, torch height).
    pub header: Vec<String>,
    /// Lines at the end, after the torch is off.
    pub footer: Vec<String>,
    /// Write comments: a summary at the top and the part/contour of every pierce.
    pub comments: bool,
    /// Kerf compensation in the program or by the controller (`G41`/`G40`); the controller's
    /// needs straight lead-ins and lead-outs (its start-up and cancel moves) and no tabs.
    pub kerf_compensation: KerfCompensation,
}

impl GcodeOptions {
    /// Defaults with the feed rate and pierce dwell of `machine` (its speeds are mm/s).
    pub fn for_machine(machine: &MachineParameters) -> GcodeOptions {
        GcodeOptions {
            cut_feed_mm_per_min: machine.cut_speed * 60.0,
            pierce_dwell_s: machine.pierce_time,
            ..GcodeOptions::base()
        }
    }

    fn base() -> GcodeOptions {
        GcodeOptions {
            distance_mode: DistanceMode::Absolute,
            decimals: 3,
            line_numbers: false,
            line_number_step: 10,
            arcs: ArcOutput::CentreOffsets,
            max_arc_sweep_deg: 360.0,
            cut_feed_mm_per_min: 600.0,
            torch_on: "M03".into(),
            torch_off: "M05".into(),
            pierce_dwell_s: 0.0,
            dwell_format: DwellFormat::PSeconds,
            header: Vec::new(),
            footer: vec!["M30".into()],
            comments: true,
            kerf_compensation: KerfCompensation::InProgram,
        }
    }
}

impl Default for GcodeOptions {
    /// [`GcodeOptions::for_machine`] of [`MachineParameters::default`]: absolute, mm, three
    /// decimals, `G02`/`G03` with `I`/`J`, `M03`/`M05`, no line numbers, comments on.
    fn default() -> Self {
        GcodeOptions::for_machine(&MachineParameters::default())
    }
}

/// Why a program could not be written.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum GcodeError {
    /// `decimals` is above 9 (coordinates would exceed the exact range of the writer's integers).
    #[error("{decimals} decimals requested; at most 9 are supported")]
    TooManyDecimals {
        /// The value given.
        decimals: usize,
    },
    /// The cutting feed rate is not a positive number.
    #[error("cutting feed rate {feed} mm/min is not a positive number")]
    InvalidFeed {
        /// The value given.
        feed: f64,
    },
    /// The pierce dwell is negative or not a number.
    #[error("pierce dwell {seconds} s is not a non-negative number")]
    InvalidDwell {
        /// The value given.
        seconds: f64,
    },
    /// The chord tolerance of [`ArcOutput::Lines`] is not a positive number.
    #[error("arc flattening tolerance {tolerance} mm is not a positive number")]
    InvalidTolerance {
        /// The value given.
        tolerance: f64,
    },
    /// The largest arc sweep is not a positive number of degrees.
    #[error("largest arc sweep {degrees}° is not a positive number")]
    InvalidMaxSweep {
        /// The value given.
        degrees: f64,
    },
    /// A configured line (torch code, header, footer) spans several lines.
    #[error("the {field} line {text:?} contains a line break")]
    LineBreakInCode {
        /// Which option.
        field: &'static str,
        /// Its text.
        text: String,
    },
    /// A coordinate is not finite or too large to write with the requested decimals.
    #[error("move {move_index}: coordinate {value} cannot be written")]
    CoordinateOutOfRange {
        /// Index of the move in the toolpath.
        move_index: usize,
        /// The coordinate.
        value: f64,
    },
    /// A cutting move comes while the torch is off (no pierce before it).
    #[error("move {move_index} cuts with the torch off (no pierce before it)")]
    CutWithoutPierce {
        /// Index of the move in the toolpath.
        move_index: usize,
    },
    /// The route does not fit the nest.
    #[error("the route does not fit the nest: {0}")]
    Route(#[from] RouteError),
    /// Kerf compensation by the controller switches on and off on straight moves only, and a
    /// torch that stops at a tab would leave it on across the gap.
    #[error("route step {step}: kerf compensation by the controller needs straight lead-ins and lead-outs (its start-up and cancel moves) and no tabs")]
    CompensationNeedsLineLeads {
        /// Index of the route step.
        step: usize,
    },
    /// The controller's start-up move cannot bring the compensated tool onto the route's
    /// lead-in and equidistant (the pierce point is too close to the contour, or the entry is
    /// not on the scrap side, left of the cut).
    #[error("route step {step}: kerf compensation by the controller cannot start on the route's lead-in here (the pierce is too close to the contour); compensate in the program instead")]
    CompensationEntry {
        /// Index of the route step.
        step: usize,
    },
    /// The controller would refuse the compensated moves of a step, as LinuxCNC does: a
    /// concave feature of the contour is tighter than the compensation radius (a corner its
    /// offsets cannot meet in without gouging, or an inside arc of a smaller radius).
    #[error("route step {step}, {contour}: kerf compensation by the controller (radius {radius} mm) cannot follow this contour: {problem}, where a concave feature is tighter than the radius; compensate in the program instead")]
    CompensationGouge {
        /// Index of the route step.
        step: usize,
        /// The contour cut by the step.
        contour: ContourRef,
        /// The compensation radius (half the kerf).
        radius: f64,
        /// What the controller would refuse.
        problem: &'static str,
    },
}

/// Writes `toolpath` as a G-code program.
pub fn write_gcode(toolpath: &Toolpath, options: &GcodeOptions) -> Result<String, GcodeError> {
    write_labelled(toolpath, toolpath, &|_| None, &[], options)
}

/// Writes the route's toolpath over `nest`, with a comment naming the part and contour before
/// every pierce (when [`GcodeOptions::comments`] is on).
pub fn route_gcode(
    nest: &Nest,
    route: &Route,
    options: &GcodeOptions,
) -> Result<String, GcodeError> {
    let label = |step: usize| {
        let contour = route.steps.get(step)?.contour;
        let part = nest.parts.get(contour.part)?;
        Some(format!("{contour} ({})", part.name))
    };
    match options.kerf_compensation {
        KerfCompensation::InProgram => {
            let toolpath = Toolpath::new(route, nest)?;
            write_labelled(&toolpath, &toolpath, &label, &[], options)
        }
        code => {
            let (toolpath, codes) = compensated_toolpath(nest, route, code, options.decimals)?;
            // The header states what the controller runs: the tool centre's path.
            let centre = Toolpath::new(route, nest)?;
            // Controllers compensate arcs of up to half a turn (full circles are split).
            let options = GcodeOptions {
                max_arc_sweep_deg: options.max_arc_sweep_deg.min(180.0),
                ..options.clone()
            };
            let (text, line_moves) = write_moves(&toolpath, &centre, &label, &codes, &options)?;
            refuse_what_the_controller_refuses(&text, &line_moves, &toolpath, route)?;
            Ok(text)
        }
    }
}

/// Reads a compensated program back as LinuxCNC runs it (move by move, see
/// [`CompensationModel::LinuxCnc`]) and refuses it where the controller would stop: a concave
/// feature of the programmed contour tighter than the compensation radius. The written program
/// is read, not the route, because rounding and the merging of moves below the resolution
/// decide which corners the controller sees.
fn refuse_what_the_controller_refuses(
    text: &str,
    line_moves: &[usize],
    toolpath: &Toolpath,
    route: &Route,
) -> Result<(), GcodeError> {
    let Some(radius) = route
        .steps
        .iter()
        .filter_map(|s| s.leads.as_ref())
        .map(|l| l.offset)
        .find(|&r| r > 0.0)
    else {
        return Ok(());
    };
    let options = ReadOptions {
        start: toolpath.start,
        compensation_radius: Some(radius),
        compensation_model: CompensationModel::LinuxCnc,
        ..ReadOptions::default()
    };
    let Err(GcodeReadError::Compensation { line, problem, .. }) = read_gcode(text, &options) else {
        return Ok(());
    };
    // The step of the line's move, or of the last move before it that has one (a code line
    // goes with the move after it, which may be an idle move).
    let moves_so_far = line
        .checked_sub(1)
        .and_then(|l| line_moves.get(l))
        .map_or(0, |&m| m + 1)
        .min(toolpath.moves.len());
    let step = toolpath.moves[..moves_so_far]
        .iter()
        .rev()
        .find_map(|m| match *m {
            ToolMove::Cut { step, .. } | ToolMove::Pierce { step, .. } => Some(step),
            ToolMove::Idle { .. } => None,
        })
        .unwrap_or(0);
    let contour = route
        .steps
        .get(step)
        .map_or(route.steps[0].contour, |s| s.contour);
    Err(GcodeError::CompensationGouge {
        step,
        contour,
        radius,
        problem,
    })
}

/// The programmed path of a route whose kerf the controller compensates: each step with kerf
/// runs on its contour, from the contour point under its entry round and on to the point under
/// its exit (the overcut); the straight lead-in from M to the contour is the controller's
/// start-up move (`G41…` before it) and the straight lead-out to M* its cancel move (`G40`
/// before it). The controller's offset to the left by kerf/2 turns this back into the route's
/// equidistant cut. Also returns the code lines, each with the move it goes before.
fn compensated_toolpath(
    nest: &Nest,
    route: &Route,
    code: KerfCompensation,
    decimals: usize,
) -> Result<(Toolpath, Vec<(usize, String)>), GcodeError> {
    let actual = Toolpath::new(route, nest)?;
    let mut moves = Vec::with_capacity(actual.moves.len());
    let mut codes = Vec::new();
    let mut replaced = vec![false; route.steps.len()];
    for m in &actual.moves {
        let step = match *m {
            ToolMove::Cut {
                step, link: false, ..
            } => step,
            _ => {
                moves.push(*m);
                continue;
            }
        };
        let cut = &route.steps[step];
        let Some(leads) = cut.leads.as_ref().filter(|l| l.offset > 0.0) else {
            moves.push(*m);
            continue;
        };
        if std::mem::replace(&mut replaced[step], true) {
            continue; // the step's programmed moves are already in
        }
        let straight = |chain: &[cutroute_geometry::Vertex]| {
            chain.len() == 2 && chain[0].bulge == 0.0 && chain[0].point != chain[1].point
        };
        if !(straight(&leads.lead_in) && straight(&leads.lead_out) && leads.tabs.is_empty()) {
            return Err(GcodeError::CompensationNeedsLineLeads { step });
        }
        let contour = nest
            .contour(cut.contour)
            .ok_or(RouteError::UnknownContour {
                step,
                contour: cut.contour,
            })?;
        let on_contour = |p: Point| contour.nearest_point(p).map_or(p, |q| q.point);
        let (start, exit) = (on_contour(leads.entry), on_contour(leads.exit()));
        let push = |moves: &mut Vec<ToolMove>, span: Span| {
            if span.length() > 1e-9 {
                moves.push(ToolMove::Cut {
                    step,
                    span,
                    link: false,
                });
            }
        };
        let on = match code {
            KerfCompensation::ControllerRegister(n) => format!("G41 D{n}"),
            _ => format!("G41.1 D{:.*}", decimals, 2.0 * leads.offset),
        };
        let round = cutroute_geometry::opened_at(contour, start, 1e-9);
        let entry = round
            .first()
            .and_then(|first| controller_entry(leads.pierce, leads.entry, *first, leads.offset))
            .ok_or(GcodeError::CompensationEntry { step })?;
        codes.push((moves.len(), on));
        push(&mut moves, Span::line(leads.pierce, entry.0));
        push(&mut moves, entry.1);
        round[1..].iter().for_each(|&span| push(&mut moves, span));
        if leads.overcut > 0.0 {
            // On along the contour to the point under the exit.
            let along = |p: Point| {
                contour
                    .nearest_point(p)
                    .map_or(0.0, |q| contour.length_at(q.position))
            };
            let mut left = (along(exit) - along(start)).rem_euclid(contour.perimeter());
            for span in round {
                let l = span.length();
                if left <= 1e-9 || l <= 0.0 {
                    break;
                }
                push(&mut moves, span.sub_span(0.0, (left / l).min(1.0)));
                left -= l;
            }
        }
        codes.push((moves.len(), "G40".into()));
        push(&mut moves, Span::line(exit, leads.switch_off));
    }
    Ok((
        Toolpath {
            start: actual.start,
            moves,
        },
        codes,
    ))
}

/// The programmed start-up move's end and the first span that follows it, for a controller
/// that compensates the kerf, such that the compensated tool runs straight from `pierce` to the
/// route's `entry` (`radius` left of the contour's `first` span, at its start) and on along the
/// equidistant.
///
/// LinuxCNC keeps the tool `radius` left of each programmed move, and where the start-up move
/// meets the next move in a concave corner the tool turns where their offsets cross. So the
/// start-up move ends on the first span extended back before its start (its line, or its
/// circle), at the point whose start-up line's offset passes through `entry`, and the first
/// span is programmed from there. `None` when `entry` is not left of the span's start or the
/// pierce is too close to the contour for such a point.
fn controller_entry(
    pierce: Point,
    entry: Point,
    first: Span,
    radius: f64,
) -> Option<(Point, Span)> {
    let c = first.start;
    let t = first.tangent_at(0.0);
    let norm = t.x.hypot_libm(t.y);
    if radius <= 0.0 || norm <= 0.0 || first.length() <= 0.0 {
        return None;
    }
    let u = (t.x / norm, t.y / norm);
    let left = Point::new(c.x - radius * u.1, c.y + radius * u.0);
    if left.distance(entry) > 1e-6 {
        return None;
    }
    // The point `b` mm back along the first span's own line or circle, and the span from it.
    let back = |b: f64| -> (Point, Span) {
        match first.centre() {
            None => {
                let p = Point::new(c.x - b * u.0, c.y - b * u.1);
                (p, Span::line(p, first.end))
            }
            Some(o) => {
                let r = first.radius();
                let turn = if first.bulge > 0.0 { -b / r } else { b / r };
                let (dx, dy) = (c.x - o.x, c.y - o.y);
                let (sin, cos) = turn.sin_cos_libm();
                let p = Point::new(o.x + dx * cos - dy * sin, o.y + dx * sin + dy * cos);
                let sweep = first.sweep() - turn;
                (p, Span::new(p, first.end, (sweep / 4.0).tan_libm()))
            }
        }
    };
    // Signed distance of the entry left of the start-up line to `back(b)`, less the radius.
    let miss = |b: f64| {
        let (p, _) = back(b);
        let (dx, dy) = (p.x - pierce.x, p.y - pierce.y);
        let d = dx.hypot_libm(dy);
        if d <= 2.0 * radius {
            return f64::NAN;
        }
        (dx * (entry.y - p.y) - dy * (entry.x - p.x)) / d - radius
    };
    let at_start = miss(0.0);
    if at_start.is_nan() || at_start > 0.0 {
        return None;
    }
    // Along a circle, at most a quarter of it back; along a line, as far as needed.
    let limit = first.centre().map_or(1e6, |_| 0.5 * PI * first.radius());
    let (mut lo, mut hi) = (0.0, radius.min(limit));
    loop {
        let m = miss(hi);
        if m > 0.0 {
            break;
        }
        if m.is_nan() || hi >= limit {
            return None;
        }
        lo = hi;
        hi = (2.0 * hi).min(limit);
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if miss(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(back(0.5 * (lo + hi)))
}

/// Writes a route of tool-on paths (segment cutting, AOE-chains), with a comment numbering
/// each path before its pierce (when [`GcodeOptions::comments`] is on).
pub fn path_route_gcode(route: &PathRoute, options: &GcodeOptions) -> Result<String, GcodeError> {
    let toolpath = Toolpath::from_path_route(route);
    let total = route.paths.len();
    let label = |step: usize| {
        let path = route.paths.get(step)?;
        Some(format!(
            "path {} of {total}: {} spans, {:.3} mm tool-on",
            step + 1,
            path.spans.len(),
            path.length()
        ))
    };
    write_labelled(&toolpath, &toolpath, &label, &[], options)
}

/// Arcs whose sagitta is below this many quanta (units of the last written digit) are written
/// as straight moves: their centre would be far away and rounding would move it by more than
/// the arc deviates from its chord.
const FLAT_ARC_QUANTA: f64 = 0.5;
/// How far beyond the rounding of its points (half a quantum per axis) and of its chords (half
/// a quantum) a written arc may run from the route's arc, in mm; an arc that would run further
/// (a few quanta of radius, where moving the centre to equalise the rounded radii moves the
/// whole arc) is written as chords instead.
const TRACE_SLACK_MM: f64 = 0.005;
/// Upper bound on the chords one arc is flattened into, whatever the tolerance.
const MAX_CHORDS_PER_ARC: f64 = 100_000.0;
/// No `R` arc longer than this is written in one move (see [`ArcOutput::Radius`]).
const LONGEST_RADIUS_ARC_DEG: f64 = 150.0;
/// No arc longer than this is written in one move (see [`GcodeOptions::max_arc_sweep_deg`]).
const LONGEST_ARC_DEG: f64 = 350.0;
/// Written arcs keep their start and end radii (from the written centre to the written ends)
/// within this many mm, or within [`ARC_RADIUS_TOLERANCE_REL`] of the radius. LinuxCNC refuses
/// an arc only when both its absolute and its relative (0.1 %) differences are too large, and
/// its absolute limit is looser than this one, so this rule is a safe subset for it and for
/// stricter controllers.
const ARC_RADIUS_TOLERANCE_MM: f64 = 0.002;
/// See [`ARC_RADIUS_TOLERANCE_MM`].
const ARC_RADIUS_TOLERANCE_REL: f64 = 0.001;

/// Writes the moves; `codes` are extra lines, each before the move of its index (in order).
/// `centre` is the tool centre's path the controller will run (the toolpath itself unless the
/// controller compensates the kerf), which the header comment summarises.
fn write_labelled(
    toolpath: &Toolpath,
    centre: &Toolpath,
    label: &dyn Fn(usize) -> Option<String>,
    codes: &[(usize, String)],
    options: &GcodeOptions,
) -> Result<String, GcodeError> {
    write_moves(toolpath, centre, label, codes, options).map(|(text, _)| text)
}

/// [`write_labelled`], with the index of the move each written line belongs to.
fn write_moves(
    toolpath: &Toolpath,
    centre: &Toolpath,
    label: &dyn Fn(usize) -> Option<String>,
    codes: &[(usize, String)],
    options: &GcodeOptions,
) -> Result<(String, Vec<usize>), GcodeError> {
    check(options)?;
    let mut w = Writer::new(options, toolpath.start)?;
    if options.comments {
        w.comment(&format!(
            "cutroute: {} pierces, tool centre cuts {:.1} mm, idle {:.1} mm",
            centre.pierce_count(),
            centre.cut_length(),
            centre.idle_length()
        ));
    }
    w.line("G21".into());
    w.line("G90".into());
    w.line("G17".into());
    for line in &options.header {
        w.line(line.clone());
    }
    if options.distance_mode == DistanceMode::Incremental {
        // The increments start from a known position, not from wherever the head stands.
        let start = w.full_position(w.at);
        w.line(format!("G00{start}"));
        w.line("G91".into());
    }
    let mut codes = codes.iter().peekable();
    for (index, m) in toolpath.moves.iter().enumerate() {
        w.move_index = index;
        while let Some((_, code)) = codes.next_if(|(at, _)| *at == index) {
            w.line(code.clone());
        }
        match *m {
            ToolMove::Idle { to, .. } => {
                w.torch_off();
                w.straight("G00", to, false)?;
            }
            ToolMove::Pierce { step, .. } => {
                w.torch_off();
                if options.distance_mode == DistanceMode::Absolute && !w.positioned {
                    // The torch fires where the program put the head, never where it stood.
                    let here = w.full_position(w.at);
                    w.line(format!("G00{here}"));
                }
                w.positioned = false;
                if options.comments {
                    if let Some(text) = label(step) {
                        w.comment(&text);
                    }
                }
                w.line(options.torch_on.clone());
                w.tool_on = true;
                w.feed_written = false;
                let dwell = options.pierce_dwell_s;
                if dwell > 0.0 {
                    match options.dwell_format {
                        DwellFormat::PSeconds => w.line(format!("G04 P{dwell:.3}")),
                        DwellFormat::XSeconds => w.line(format!("G04 X{dwell:.3}")),
                        DwellFormat::PMilliseconds => w.line(format!("G04 P{:.0}", dwell * 1000.0)),
                        DwellFormat::Omitted => {}
                    }
                }
            }
            ToolMove::Cut { span, .. } => {
                if !w.tool_on {
                    return Err(GcodeError::CutWithoutPierce { move_index: index });
                }
                w.span(span)?;
            }
        }
    }
    w.torch_off();
    for line in &options.footer {
        w.line(line.clone());
    }
    Ok((w.out, w.line_moves))
}

fn check(options: &GcodeOptions) -> Result<(), GcodeError> {
    if options.decimals > 9 {
        return Err(GcodeError::TooManyDecimals {
            decimals: options.decimals,
        });
    }
    let feed = options.cut_feed_mm_per_min;
    if !(feed.is_finite() && feed > 0.0) {
        return Err(GcodeError::InvalidFeed { feed });
    }
    let dwell = options.pierce_dwell_s;
    if !(dwell.is_finite() && dwell >= 0.0) {
        return Err(GcodeError::InvalidDwell { seconds: dwell });
    }
    if let ArcOutput::Lines { tolerance_mm } = options.arcs {
        if !(tolerance_mm.is_finite() && tolerance_mm > 0.0) {
            return Err(GcodeError::InvalidTolerance {
                tolerance: tolerance_mm,
            });
        }
    }
    let sweep = options.max_arc_sweep_deg;
    if !(sweep.is_finite() && sweep > 0.0) {
        return Err(GcodeError::InvalidMaxSweep { degrees: sweep });
    }
    let fields = [
        ("torch_on", &options.torch_on),
        ("torch_off", &options.torch_off),
    ];
    let extra = options
        .header
        .iter()
        .map(|l| ("header", l))
        .chain(options.footer.iter().map(|l| ("footer", l)));
    for (field, text) in fields.into_iter().chain(extra) {
        if text.contains(['\n', '\r']) {
            return Err(GcodeError::LineBreakInCode {
                field,
                text: text.clone(),
            });
        }
    }
    Ok(())
}

/// Positions are tracked as integers of the last written digit, so incremental programs do not
/// drift and the centre offsets refer to the start point exactly as written.
struct Writer<'a> {
    options: &'a GcodeOptions,
    out: String,
    scale: f64,
    /// Where the head is, in quanta, as written so far.
    at: (i64, i64),
    tool_on: bool,
    /// A `G00` with every axis has put the head where it is since the last torch-on.
    positioned: bool,
    feed_written: bool,
    line_number: u64,
    move_index: usize,
    /// The move each written line belongs to.
    line_moves: Vec<usize>,
}

impl<'a> Writer<'a> {
    fn new(options: &'a GcodeOptions, start: Point) -> Result<Writer<'a>, GcodeError> {
        let scale = 10f64.powi(options.decimals as i32);
        let mut w = Writer {
            options,
            out: String::new(),
            scale,
            at: (0, 0),
            tool_on: false,
            positioned: false,
            feed_written: false,
            line_number: 0,
            move_index: 0,
            line_moves: Vec::new(),
        };
        w.at = w.quantize_point(start)?;
        Ok(w)
    }

    fn quantize(&self, value: f64) -> Result<i64, GcodeError> {
        let q = (value * self.scale).round();
        // Beyond 2^53 integers are no longer exact in f64.
        if q.is_finite() && q.abs() < 9.0e15 {
            Ok(q as i64)
        } else {
            Err(GcodeError::CoordinateOutOfRange {
                move_index: self.move_index,
                value,
            })
        }
    }

    fn quantize_point(&self, p: Point) -> Result<(i64, i64), GcodeError> {
        Ok((self.quantize(p.x)?, self.quantize(p.y)?))
    }

    fn number(&self, q: i64) -> String {
        let decimals = self.options.decimals;
        let sign = if q < 0 { "-" } else { "" };
        let magnitude = q.unsigned_abs();
        if decimals == 0 {
            return format!("{sign}{magnitude}");
        }
        let unit = 10u64.pow(decimals as u32);
        format!(
            "{sign}{}.{:0width$}",
            magnitude / unit,
            magnitude % unit,
            width = decimals
        )
    }

    fn line(&mut self, text: String) {
        if self.options.line_numbers {
            self.line_number += u64::from(self.options.line_number_step.max(1));
            let _ = write!(self.out, "N{} ", self.line_number);
        }
        self.out.push_str(&text);
        self.out.push('\n');
        self.line_moves.push(self.move_index);
    }

    fn comment(&mut self, text: &str) {
        // Parentheses cannot nest in G-code comments.
        let clean: String = text
            .chars()
            .map(|c| match c {
                '(' => '[',
                ')' => ']',
                '\n' | '\r' => ' ',
                c => c,
            })
            .collect();
        self.line(format!("({clean})"));
    }

    fn torch_off(&mut self) {
        if self.tool_on {
            self.line(self.options.torch_off.clone());
            self.tool_on = false;
        }
    }

    /// The absolute X/Y words of `target` (quanta), both axes.
    fn full_position(&self, target: (i64, i64)) -> String {
        format!(" X{} Y{}", self.number(target.0), self.number(target.1))
    }

    /// The X/Y words of a move to `target` (quanta), or `None` when the head does not move.
    fn axis_words(&self, target: (i64, i64)) -> Option<String> {
        if target == self.at {
            return None;
        }
        let mut words = String::new();
        let (dx, dy) = (target.0 - self.at.0, target.1 - self.at.1);
        let (x, y) = match self.options.distance_mode {
            DistanceMode::Absolute => (target.0, target.1),
            DistanceMode::Incremental => (dx, dy),
        };
        if dx != 0 {
            let _ = write!(words, " X{}", self.number(x));
        }
        if dy != 0 {
            let _ = write!(words, " Y{}", self.number(y));
        }
        Some(words)
    }

    fn feed_word(&mut self) -> String {
        if self.feed_written {
            return String::new();
        }
        self.feed_written = true;
        let feed = self.options.cut_feed_mm_per_min;
        let text = format!("{feed:.1}");
        format!(" F{}", text.trim_end_matches('0').trim_end_matches('.'))
    }

    fn straight(&mut self, code: &str, to: Point, feed: bool) -> Result<(), GcodeError> {
        let target = self.quantize_point(to)?;
        let rapid = !feed && self.options.distance_mode == DistanceMode::Absolute;
        if rapid && target != self.at {
            // Rapids write every axis: the move before a pierce never depends on the last one.
            let words = self.full_position(target);
            self.line(format!("{code}{words}"));
            self.at = target;
            self.positioned = true;
            return Ok(());
        }
        if let Some(words) = self.axis_words(target) {
            let f = if feed {
                self.feed_word()
            } else {
                String::new()
            };
            self.line(format!("{code}{words}{f}"));
            self.at = target;
        }
        Ok(())
    }

    fn span(&mut self, span: Span) -> Result<(), GcodeError> {
        if span.is_line() {
            return self.straight("G01", span.end, true);
        }
        let sweep = span.sweep().abs();
        let sagitta = 0.5 * span.chord_length() * (sweep / 4.0).tan_libm().abs();
        if sweep < PI && sagitta * self.scale < FLAT_ARC_QUANTA {
            return self.straight("G01", span.end, true);
        }
        let max_sweep = match self.options.arcs {
            ArcOutput::Radius => self.options.max_arc_sweep_deg.min(LONGEST_RADIUS_ARC_DEG),
            _ => self.options.max_arc_sweep_deg,
        }
        .min(LONGEST_ARC_DEG)
        .to_radians();
        let pieces = (sweep / max_sweep).ceil().max(1.0) as usize;
        for k in 0..pieces {
            let piece = if pieces == 1 {
                span
            } else {
                span.sub_span(k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64)
            };
            self.arc(piece)?;
        }
        Ok(())
    }

    /// `span` as `G01` chords, none leaving the arc by more than `tolerance_mm`.
    fn chords(&mut self, span: Span, tolerance_mm: f64) -> Result<(), GcodeError> {
        let r = span.radius();
        let step = if tolerance_mm < r {
            2.0 * (1.0 - tolerance_mm / r).acos_libm()
        } else {
            2.0 * PI / 3.0
        };
        let chords = (span.sweep().abs() / step)
            .ceil()
            .clamp(1.0, MAX_CHORDS_PER_ARC) as usize;
        for k in 1..=chords {
            let p = span.point_at(k as f64 / chords as f64);
            self.straight("G01", p, true)?;
        }
        Ok(())
    }

    /// Chord tolerance of arcs the written resolution cannot hold as arcs: half the last
    /// digit, below the rounding every written point already carries.
    fn rounding_chord_tolerance(&self) -> f64 {
        0.5 / self.scale
    }

    /// The centre (quanta) to write for an arc from the head to `end`: the rounded centre, or
    /// the grid point next to it that best equalises the two radii, provided the radii then
    /// agree within [`ARC_RADIUS_TOLERANCE_MM`] or [`ARC_RADIUS_TOLERANCE_REL`]; `None` when
    /// no such point exists.
    fn written_centre(&self, rounded: (i64, i64), end: (i64, i64)) -> Option<(i64, i64)> {
        let radius =
            |p: (i64, i64), c: (i64, i64)| ((p.0 - c.0) as f64).hypot_libm((p.1 - c.1) as f64);
        let mismatch = |c: (i64, i64)| {
            let (r1, r2) = (radius(self.at, c), radius(end, c));
            let d = (r1 - r2).abs() / self.scale;
            let ok = d <= ARC_RADIUS_TOLERANCE_MM
                || d <= ARC_RADIUS_TOLERANCE_REL * r1.max(r2) / self.scale;
            ok.then_some(d)
        };
        if mismatch(rounded).is_some_and(|d| d <= ARC_RADIUS_TOLERANCE_MM) {
            return Some(rounded);
        }
        let mut best: Option<((i64, i64), f64)> = mismatch(rounded).map(|d| (rounded, d));
        for dx in -1..=1 {
            for dy in -1..=1 {
                let c = (rounded.0 + dx, rounded.1 + dy);
                if let Some(d) = mismatch(c) {
                    if best.is_none_or(|(_, b)| d < b) {
                        best = Some((c, d));
                    }
                }
            }
        }
        best.map(|(c, _)| c)
    }

    /// Whether the arc the controller runs from the head to `end` (quanta) about `centre`
    /// (quanta, on the grid or, for `R` arcs, where the controller puts it) stays as close to `span` as its chords would (see
    /// [`Writer::rounding_chord_tolerance`]): every written point is off by up to half a
    /// quantum per axis, and moving the centre to equalise the radii may add more.
    fn traces(&self, span: Span, centre: (f64, f64), end: (i64, i64)) -> bool {
        let Some(true_centre) = span.centre() else {
            return false;
        };
        let scaled = |p: (f64, f64)| Point::new(p.0 / self.scale, p.1 / self.scale);
        let grid = |q: (i64, i64)| scaled((q.0 as f64, q.1 as f64));
        let c = scaled(centre);
        let r = span.radius();
        let drift = |p: Point| (p.distance(c) - r).abs();
        // Every point of the traced arc (or spiral, between its end radii) is within this of
        // the true circle.
        let off = c.distance(true_centre) + drift(grid(self.at)).max(drift(grid(end)));
        off <= TRACE_SLACK_MM + (0.5f64.sqrt() + 0.5) / self.scale
    }

    fn arc(&mut self, span: Span) -> Result<(), GcodeError> {
        let code = if span.bulge > 0.0 { "G03" } else { "G02" };
        match self.options.arcs {
            ArcOutput::Lines { tolerance_mm } => self.chords(span, tolerance_mm),
            ArcOutput::CentreOffsets => {
                let Some(centre) = span.centre() else {
                    return self.straight("G01", span.end, true);
                };
                let target = self.quantize_point(span.end)?;
                // Ends that round to one point would read as a full circle: the piece is
                // below the resolution (at most 350° pieces, so its radius is a few quanta).
                let Some(words) = self.axis_words(target) else {
                    return Ok(());
                };
                let rounded = self.quantize_point(centre)?;
                let Some(c) = self.written_centre(rounded, target) else {
                    // No centre on the grid of written values gives equal radii at both
                    // rounded ends: the controller would refuse the arc.
                    return self.chords(span, self.rounding_chord_tolerance());
                };
                if !self.traces(span, (c.0 as f64, c.1 as f64), target) {
                    return self.chords(span, self.rounding_chord_tolerance());
                }
                let (i, j) = (c.0 - self.at.0, c.1 - self.at.1);
                let f = self.feed_word();
                let centre_words = format!(" I{} J{}", self.number(i), self.number(j));
                self.line(format!("{code}{words}{centre_words}{f}"));
                self.at = target;
                Ok(())
            }
            ArcOutput::Radius => {
                let target = self.quantize_point(span.end)?;
                let Some(words) = self.axis_words(target) else {
                    // A radius arc needs distinct ends; this piece is below the resolution.
                    return Ok(());
                };
                let r = self.quantize(span.radius())?;
                let (dx, dy) = (target.0 - self.at.0, target.1 - self.at.1);
                let half_chord = 0.5 * (dx as f64).hypot_libm(dy as f64);
                if half_chord >= r as f64 {
                    // The rounded radius cannot reach between the rounded ends.
                    return self.chords(span, self.rounding_chord_tolerance());
                }
                // The controller puts the centre on the side of the chord the arc turns to
                // (`R` positive: never more than half a turn).
                let h = (r as f64 * r as f64 - half_chord * half_chord).sqrt();
                let (ux, uy) = (
                    dx as f64 / (2.0 * half_chord),
                    dy as f64 / (2.0 * half_chord),
                );
                let side = if span.bulge > 0.0 { 1.0 } else { -1.0 };
                let centre = (
                    0.5 * (self.at.0 + target.0) as f64 - side * h * uy,
                    0.5 * (self.at.1 + target.1) as f64 + side * h * ux,
                );
                if !self.traces(span, centre, target) {
                    return self.chords(span, self.rounding_chord_tolerance());
                }
                let f = self.feed_word();
                self.line(format!("{code}{words} R{}{f}", self.number(r)));
                self.at = target;
                Ok(())
            }
        }
    }
}
