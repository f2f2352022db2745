//! The one door for files: [`open_document`] opens any single file the app or the CLI can open
//! (every nest format, PCGTSP instances, and G-code programs, shown as the nest their cuts trace
//! with the program's own route), and [`open_together`] several files opened as one document —
//! a nest with its task JSON and a PCGLNS result, or a PCGTSP instance with a PCGLNS result.
//! Tours are checked by the independent checker (`cutroute_pcgtsp::check_tour`) and routes by
//! `Route::problems` before anything is shown.

use crate::located::Located;
use crate::open::{format_name, open_model_file, OpenError};
use cutroute_formats::{detect, read_task_json, Format, RmTask};
use cutroute_gcode::{read_gcode, Motion, ReadOptions};
use cutroute_geometry::{
    flatten_spans, Contour, ContourFault, ContourRef, CutStep, Entry, Nest, Part, PathRoute, Point,
    ReadWarning, Route, RouteError, Span, Toolpath, Vertex, WarningKind,
};
use cutroute_pcgtsp::{check_tour, Instance, PcglnsResult};
use cutroute_protocol::{Document, Problem, TaskSpeeds};

/// Pierce points of a task and the end points of G-code moves count as "the same point" within
/// this distance, mm (files round coordinates to a few decimals).
pub const POINT_TOLERANCE_MM: f64 = 0.01;

/// Chord tolerance (mm) of the left-out geometry a warning carries: it is only drawn.
const LEFT_OUT_FLATTENING_MM: f64 = 0.01;

/// Whether the text is a PCGLNS run summary (`*.pcglns.result.txt`).
pub fn is_pcglns_result(bytes: &[u8]) -> bool {
    detect(bytes) == Format::Unknown
        && std::str::from_utf8(bytes).is_ok_and(|t| t.contains("Tour Ordering"))
}

/// Opens one file: what the engine reads, else a G-code program, else a PCGLNS result (which
/// needs company, so it is an error alone).
pub fn open_document(file_name: &str, bytes: &[u8]) -> Result<Document, OpenError> {
    open_sheet(file_name, bytes, 0)
}

/// What a conversion to a nest format loses: `written` (the bytes of `nest` in DBS, geometry
/// JSON or SVG, to be saved as `file_name`) read back through [`open_document`] and compared
/// with `nest`: the number of contours, the total perimeter (within 1e-6 relative) and the
/// bounding box (within 1e-6 of its size). Each difference is a warning of kind
/// [`WarningKind::Other`] saying what changed; none when the file reads back as written.
pub fn conversion_losses(nest: &Nest, file_name: &str, written: &[u8]) -> Vec<ReadWarning> {
    let lost = |message: String| vec![ReadWarning::new(WarningKind::Other, message)];
    let back = match open_document(file_name, written) {
        Ok(Document {
            problem: Problem::Nest { nest, .. },
            ..
        }) => nest,
        Ok(_) => return lost(format!("{file_name} reads back as no nest")),
        Err(e) => return lost(format!("{file_name} cannot be read back: {e}")),
    };
    let mut out = Vec::new();
    let (before, after) = (NestShape::of(nest), NestShape::of(&back));
    if before.contours != after.contours {
        out.push(format!(
            "{file_name} reads back with {} of its {} contours (the sheet included)",
            after.contours, before.contours
        ));
    }
    let relative = (after.perimeter - before.perimeter).abs() / before.perimeter.max(1e-300);
    if relative.is_nan() || relative > 1e-6 {
        out.push(format!(
            "{file_name} reads back with a total perimeter of {:.6} mm instead of {:.6} mm ({:+.4} %)",
            after.perimeter,
            before.perimeter,
            100.0 * (after.perimeter - before.perimeter) / before.perimeter.max(1e-300)
        ));
    }
    let size = (before.bbox.max.x - before.bbox.min.x)
        .max(before.bbox.max.y - before.bbox.min.y)
        .max(1e-9);
    let moved = [
        before.bbox.min.x - after.bbox.min.x,
        before.bbox.min.y - after.bbox.min.y,
        before.bbox.max.x - after.bbox.max.x,
        before.bbox.max.y - after.bbox.max.y,
    ]
    .iter()
    .fold(0.0f64, |m, d| m.max(d.abs()));
    if moved.is_nan() || moved > 1e-6 * size {
        out.push(format!(
            "{file_name} reads back with a bounding box ({:.6}, {:.6})–({:.6}, {:.6}) instead of ({:.6}, {:.6})–({:.6}, {:.6})",
            after.bbox.min.x, after.bbox.min.y, after.bbox.max.x, after.bbox.max.y,
            before.bbox.min.x, before.bbox.min.y, before.bbox.max.x, before.bbox.max.y
        ));
    }
    out.into_iter()
        .map(|m| ReadWarning::new(WarningKind::Other, m))
        .collect()
}

/// The measures of a nest that a conversion must keep, the sheet included.
struct NestShape {
    contours: usize,
    perimeter: f64,
    bbox: cutroute_geometry::BoundingBox,
}

impl NestShape {
    fn of(nest: &Nest) -> Self {
        let all = || nest.sheet.iter().chain(&nest.parts);
        Self {
            contours: all().map(|p| p.contours.len()).sum(),
            perimeter: all().map(Part::perimeter).sum(),
            bbox: all().fold(cutroute_geometry::BoundingBox::EMPTY, |b, p| {
                b.union(p.bounding_box())
            }),
        }
    }
}

/// [`open_document`] for sheet `sheet` (from 0) of a multi-sheet file (T-FLEX projects list
/// their sheets in [`Document::sheets`]); every other file has only sheet 0.
pub fn open_sheet(file_name: &str, bytes: &[u8], sheet: usize) -> Result<Document, OpenError> {
    match open_model_file(file_name, bytes, sheet) {
        Err(OpenError::UnknownFormat(name)) => {
            if is_pcglns_result(bytes) {
                return Err(OpenError::TourAlone(name));
            }
            match std::str::from_utf8(bytes) {
                Ok(_) if sheet > 0 => Err(OpenError::NoSuchSheet {
                    file_name: name,
                    sheet: sheet + 1,
                    count: 1,
                }),
                Ok(text) if looks_like_gcode(text) => open_gcode(file_name, text),
                _ => Err(OpenError::UnknownFormat(name)),
            }
        }
        other => other,
    }
}

/// A cheap look at the first words: G-code programs start with `%`, a comment, a line number
/// or a G/M/T word.
fn looks_like_gcode(text: &str) -> bool {
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .and_then(|l| l.chars().next())
        .is_some_and(|c| {
            matches!(
                c.to_ascii_uppercase(),
                '%' | '(' | ';' | 'N' | 'G' | 'M' | 'T' | 'O'
            )
        })
}

/// A G-code program as the nest its cuts trace and the route it takes: every closed tool-on
/// loop is a contour (loops inside loops become holes of their part), every torch-on a pierce,
/// a tool-on path from one loop to the next in the same torch-on run a chain link. The cut
/// direction is the program's own. Tool-on paths that close no loop are left out with a
/// warning.
pub fn open_gcode(file_name: &str, text: &str) -> Result<Document, OpenError> {
    open_gcode_with(file_name, text, &ReadOptions::default())
}

/// [`open_gcode`] in a named dialect (`GcodePreset::read_options`: its torch codes, dwell unit
/// and arc tolerance), for programs whose torch codes are not `M03`/`M04`/`M05`.
pub fn open_gcode_with(
    file_name: &str,
    text: &str,
    options: &ReadOptions,
) -> Result<Document, OpenError> {
    let program = read_gcode(text, options).map_err(|e| OpenError::Gcode {
        file_name: file_name.to_string(),
        message: e.to_string(),
        location: Located::location(&e),
    })?;
    let mut warnings = Vec::new();
    // (loop, entry) in cutting order.
    let mut loops: Vec<(Contour, Entry)> = Vec::new();
    // Tool-on length of the loops' crossings removed by the repair: told, not a lost path.
    let mut repaired_mm = 0.0;
    let mut run: Option<RunState> = None;
    let finish_run = |run: Option<RunState>, warnings: &mut Vec<ReadWarning>| {
        if let Some(r) = run {
            if !r.pending.is_empty() {
                let length = r.pending.iter().map(Span::length).sum::<f64>();
                warnings.push(
                    ReadWarning::new(
                        WarningKind::OpenChain,
                        format!(
                            "a tool-on path of {length:.3} mm closes no contour and is not drawn"
                        ),
                    )
                    .at_line(r.pending_line, None)
                    .leaving_out(vec![flatten_spans(&r.pending, LEFT_OUT_FLATTENING_MM)]),
                );
            }
        }
    };
    for motion in &program.motions {
        match *motion {
            Motion::TorchOn { .. } => {
                finish_run(run.take(), &mut warnings);
                run = Some(RunState::default());
            }
            Motion::TorchOff { .. } => finish_run(run.take(), &mut warnings),
            Motion::Feed {
                span,
                tool_on: true,
                line,
                ..
            } => {
                let Some(r) = run.as_mut() else { continue };
                if r.pending.is_empty() {
                    r.pending_line = line;
                }
                r.pending.push(span);
                // Does this span close a loop that began at one of the pending spans?
                let closes = cutroute_gcode::closed_loop_start(&r.pending, POINT_TOLERANCE_MM);
                if let Some(j) = closes {
                    let lead: Vec<Span> = r.pending.drain(..j).collect();
                    let vertices: Vec<Vertex> = r
                        .pending
                        .drain(..)
                        .map(|s| Vertex {
                            point: s.start,
                            bulge: s.bulge,
                        })
                        .collect();
                    let entry = if r.loops_cut == 0 {
                        if !lead.is_empty() {
                            let length = lead.iter().map(Span::length).sum::<f64>();
                            warnings.push(
                                ReadWarning::new(
                                    WarningKind::Skipped,
                                    format!(
                                        "a lead-in of {length:.3} mm before the contour is not drawn"
                                    ),
                                )
                                .at_line(r.pending_line, None)
                                .leaving_out(vec![flatten_spans(&lead, LEFT_OUT_FLATTENING_MM)]),
                            );
                        }
                        Entry::Pierce
                    } else {
                        // The link's corners: where its pieces meet.
                        Entry::Link(lead.iter().skip(1).map(|s| s.start).collect())
                    };
                    r.loops_cut += 1;
                    let contour = Contour::new(vertices);
                    // The one meaning of a contour every reader applies, after the one repair
                    // (loops too small to cut where it crosses itself removed, said): a loop that
                    // is no cuttable contour (a slit, a bow-tie) is left out, as a drawing's is.
                    match contour.without_small_loops(POINT_TOLERANCE_MM) {
                        Ok(repair) => {
                            if let Some(what) = repair.describe() {
                                repaired_mm += repair.removed_length();
                                warnings.push(
                                    ReadWarning::new(
                                        repair.warning_kind(),
                                        format!("a tool-on loop: {what}"),
                                    )
                                    .at_line(r.pending_line, None)
                                    .leaving_out(repair.left_out(LEFT_OUT_FLATTENING_MM)),
                                );
                            }
                            loops.push((repair.contour, entry));
                        }
                        Err(fault) => warnings.push(
                            ReadWarning::new(
                                match fault {
                                    ContourFault::SelfIntersecting { .. } => {
                                        WarningKind::SelfIntersecting
                                    }
                                    _ if fault.is_zero_area() => WarningKind::ZeroArea,
                                    _ => WarningKind::Other,
                                },
                                format!("a tool-on loop is left out: {fault}"),
                            )
                            .at_line(r.pending_line, None)
                            .leaving_out(vec![flatten_spans(
                                &contour.spans().collect::<Vec<_>>(),
                                LEFT_OUT_FLATTENING_MM,
                            )]),
                        ),
                    }
                }
            }
            Motion::Feed { .. } | Motion::Rapid { .. } | Motion::Dwell { .. } => {}
        }
    }
    finish_run(run.take(), &mut warnings);
    let program_paths = program.path_route();
    if loops.is_empty() {
        if program_paths.paths.is_empty() {
            return Err(OpenError::GcodeCutsNothing(file_name.to_string()));
        }
        // No closed contour to make a nest of: the program's paths alone, to review.
        warnings.push(ReadWarning::new(
            WarningKind::Other,
            format!(
                "the program cuts no closed contour: shown as its {} tool-on paths (open paths: segment or common-edge cutting); there is no nest to solve",
                program_paths.paths.len()
            ),
        ));
        return Ok(Document {
            file_name: file_name.to_string(),
            format: GCODE.to_string(),
            problem: Problem::Nest {
                nest: Nest::default(),
                start: program_paths.start,
                finish: program_paths.finish,
            },
            route: None,
            paths: Some(program_paths),
            task_speeds: None,
            warnings,
            sheets: Vec::new(),
            sheet: 0,
        });
    }
    let (nest, refs) = nest_of_loops(loops.iter().map(|(c, _)| c.clone()).collect());
    let steps: Vec<CutStep> = loops
        .into_iter()
        .zip(refs)
        .map(|((contour, entry), r)| CutStep {
            contour: r,
            pierce_point: contour.vertices[0].point,
            entry,
            leads: None,
        })
        .collect();
    let last_exit = steps.last().map(|s| s.pierce_point);
    let finish = (last_exit.is_some_and(|p| p.distance(program.end) > POINT_TOLERANCE_MM))
        .then_some(program.end);
    let route = Route {
        start: program.start,
        steps,
        finish,
    };
    // A program that cuts open paths: the nest holds only the loops they close, so the
    // program's own tool-on paths are what to show.
    let paths = open_paths_note(&nest, &route, &program_paths, repaired_mm).map(|note| {
        warnings.push(ReadWarning::new(WarningKind::Other, note));
        program_paths
    });
    Ok(Document {
        file_name: file_name.to_string(),
        format: GCODE.to_string(),
        problem: Problem::Nest {
            nest,
            start: program.start,
            finish,
        },
        route: Some(route),
        paths,
        task_speeds: None,
        warnings,
        sheets: Vec::new(),
        sheet: 0,
    })
}

/// The format's name for people.
const GCODE: &str = "G-code";

/// Differences of tool-on length (mm) between a program's closed loops and its own paths that
/// are rounding, not a lost path.
const PROGRAM_LENGTH_NOISE_MM: f64 = 0.05;

/// When the loops of a program (as contours, the rest left out) lose tool-on length or pierces
/// that the program's own paths have, a note saying the paths are shown instead; `None` when
/// the loops' route is the whole program. `repaired_mm` of crossing loops removed (and said so)
/// by the repair of a contour is no lost path.
fn open_paths_note(
    nest: &Nest,
    route: &Route,
    paths: &PathRoute,
    repaired_mm: f64,
) -> Option<String> {
    let (cut, pierces) = Toolpath::new(route, nest)
        .ok()
        .map_or((0.0, 0), |t| (t.cut_length(), t.pierce_count()));
    // Loops closed within the point tolerance may differ from the program's spans by
    // rounding; what is left out is at least a whole span or path.
    let lost = paths.cut_length() - cut - repaired_mm;
    let noise = PROGRAM_LENGTH_NOISE_MM.max(1e-6 * cut);
    (lost > noise || pierces != paths.pierce_count()).then(|| {
        format!(
            "the program cuts open tool-on paths (segment or common-edge cutting): shown as its {} paths ({:.1} mm tool-on); as contours it would keep {:.1} mm in {} pierces",
            paths.paths.len(),
            paths.cut_length(),
            cut,
            pierces
        )
    })
}

#[derive(Default)]
struct RunState {
    /// Tool-on spans since the last closed loop.
    pending: Vec<Span>,
    /// Line of the first pending span.
    pending_line: usize,
    /// Loops closed in this run so far.
    loops_cut: usize,
}

/// Groups loops into parts by containment (a loop at odd depth is a hole of its parent);
/// returns the nest and where each loop went.
fn nest_of_loops(loops: Vec<Contour>) -> (Nest, Vec<ContourRef>) {
    let flat = Nest {
        sheet: None,
        parts: loops
            .iter()
            .map(|c| Part {
                name: String::new(),
                contours: vec![c.clone()],
            })
            .collect(),
    };
    let forest = flat.containment_forest();
    let at = |i: usize| ContourRef {
        part: i,
        contour: 0,
    };
    let depth = |i: usize| forest.depth(at(i)).unwrap_or(0);
    let mut part_of_loop = vec![usize::MAX; loops.len()];
    let mut refs = vec![at(0); loops.len()];
    let mut parts: Vec<Part> = Vec::new();
    for i in (0..loops.len()).filter(|&i| depth(i) % 2 == 0) {
        part_of_loop[i] = parts.len();
        refs[i] = ContourRef {
            part: parts.len(),
            contour: 0,
        };
        parts.push(Part {
            name: format!("cut {}", i + 1),
            contours: vec![loops[i].clone()],
        });
    }
    for i in (0..loops.len()).filter(|&i| depth(i) % 2 == 1) {
        let parent = forest.parent(at(i)).map(|p| p.part).unwrap_or(i);
        let part = part_of_loop[parent];
        refs[i] = ContourRef {
            part,
            contour: parts[part].contours.len(),
        };
        parts[part].contours.push(loops[i].clone());
    }
    (Nest { sheet: None, parts }, refs)
}

/// One file of a batch, as recognised from its content.
enum Piece {
    /// Boxed: a document is far larger than the other pieces.
    Nest(Box<Document>),
    Task(RmTask),
    Instance(Instance, String),
    Tour(PcglnsResult),
}

/// Opens several files as one document: a nest (any nest format) with its task JSON (start,
/// finish) and optionally a PCGLNS result whose tour becomes the shown route; or a PCGTSP
/// instance with a PCGLNS result (the tour is checked and reported; with a nest and task too,
/// it is also drawn). One file alone opens as [`open_document`] does.
pub fn open_together(files: &[(String, Vec<u8>)]) -> Result<Document, OpenError> {
    if let [(name, bytes)] = files {
        return open_document(name, bytes);
    }
    let mut nest: Option<(String, Document)> = None;
    let mut task: Option<(String, RmTask)> = None;
    let mut instance: Option<(String, Instance, String)> = None;
    let mut tour: Option<(String, PcglnsResult)> = None;
    let mut labels = Vec::new();
    for (name, bytes) in files {
        let format = detect(bytes);
        let unreadable = |message: String, location| OpenError::Unreadable {
            file_name: name.clone(),
            format: format_name(format),
            message,
            location,
        };
        let piece = match format {
            Format::TaskJson => Piece::Task(
                read_task_json(bytes).map_err(|e| unreadable(e.to_string(), e.location()))?,
            ),
            Format::Pcglns => {
                let text = std::str::from_utf8(bytes)
                    .map_err(|e| unreadable(e.to_string(), e.location()))?;
                let parsed =
                    Instance::parse(text).map_err(|e| unreadable(e.to_string(), e.location()))?;
                Piece::Instance(parsed, text.to_string())
            }
            Format::Unknown if is_pcglns_result(bytes) => {
                let text = std::str::from_utf8(bytes).unwrap_or_default();
                Piece::Tour(
                    PcglnsResult::parse(text).map_err(|e| OpenError::Unreadable {
                        file_name: name.clone(),
                        format: "PCGLNS result",
                        message: e.to_string(),
                        location: e.location(),
                    })?,
                )
            }
            _ => match open_document(name, bytes)? {
                d if matches!(d.problem, Problem::Nest { .. }) => Piece::Nest(Box::new(d)),
                _ => return Err(OpenError::NotCombinable(name.clone())),
            },
        };
        let kind = match &piece {
            Piece::Nest(d) => d.format.clone(),
            Piece::Task(_) => "task JSON".to_string(),
            Piece::Instance(..) => "PCGTSP instance".to_string(),
            Piece::Tour(_) => "PCGLNS result".to_string(),
        };
        labels.push((name.clone(), kind));
        let two = |kind: &'static str, first: &str| OpenError::TwoOfAKind {
            kind,
            first: first.to_string(),
            second: name.clone(),
        };
        match piece {
            Piece::Nest(d) => match &nest {
                Some((first, _)) => return Err(two("nests", first)),
                None => nest = Some((name.clone(), *d)),
            },
            Piece::Task(t) => match &task {
                Some((first, _)) => return Err(two("task files", first)),
                None => task = Some((name.clone(), t)),
            },
            Piece::Instance(i, text) => match &instance {
                Some((first, ..)) => return Err(two("PCGTSP instances", first)),
                None => instance = Some((name.clone(), i, text)),
            },
            Piece::Tour(r) => match &tour {
                Some((first, _)) => return Err(two("PCGLNS results", first)),
                None => tour = Some((name.clone(), r)),
            },
        }
    }
    let file_name = labels
        .iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(" + ");
    let format = labels
        .iter()
        .map(|(_, k)| k.as_str())
        .collect::<Vec<_>>()
        .join(" + ");
    let mut notes = Vec::new();
    // The tour first: checked against the instance when there is one, else against the
    // instance the task defines (rounded idle lengths between pierce points, as PCGLNS needs).
    let checked_tour = match (&tour, &instance, &task) {
        (Some((tour_name, result)), Some((instance_name, inst, _)), _) => {
            if let Some((task_name, t)) = &task {
                let points = t.pierce_point_count();
                if inst.node_count != points + 1 {
                    return Err(OpenError::InstanceNotOfTask {
                        instance: instance_name.clone(),
                        nodes: inst.node_count,
                        task: task_name.clone(),
                        points,
                    });
                }
            }
            let cost = checked(tour_name, instance_name, inst, result)?;
            notes.push(tour_note(tour_name, instance_name, result, cost));
            Some(result.tour.clone())
        }
        (Some((tour_name, result)), None, Some((task_name, t))) => {
            let inst = task_instance(t);
            let cost = checked(tour_name, task_name, &inst, result)?;
            notes.push(tour_note(tour_name, task_name, result, cost));
            Some(result.tour.clone())
        }
        (Some((tour_name, _)), None, None) => return Err(OpenError::TourAlone(tour_name.clone())),
        (None, ..) => None,
    };
    let Some((nest_name, mut document)) = nest else {
        if let Some((_, _, text)) = instance {
            return Ok(Document {
                file_name,
                format,
                problem: Problem::PcgtspText { text },
                route: None,
                paths: None,
                task_speeds: None,
                warnings: notes_as_warnings(notes),
                sheets: Vec::new(),
                sheet: 0,
            });
        }
        let (task_name, _) = task.expect("a batch of two or more files has a piece");
        return Err(OpenError::TaskWithoutNest(task_name));
    };
    if let Some((task_name, t)) = &task {
        if let Problem::Nest { start, finish, .. } = &mut document.problem {
            *start = t.task_data.start();
            *finish = t.task_data.finish();
        }
        let data = &t.task_data;
        document.task_speeds = Some(TaskSpeeds {
            idle_speed: data.tool_idling_speed,
            cut_speed: data.tool_cut_speed,
            pierce_time: data.piercing_duration,
        });
        if let (Some(tour_nodes), Some((tour_name, _))) = (&checked_tour, &tour) {
            let Problem::Nest {
                nest,
                start,
                finish,
            } = &document.problem
            else {
                unreachable!("matched above")
            };
            let (route, listed) =
                tour_route(t, task_name, nest, &nest_name, *start, *finish, tour_nodes)?;
            // Contours the task leaves out (files repeat a hole as a part of its own) are not
            // cut; everything else is checked.
            let forest = nest.containment_forest();
            let mut left_out = Vec::new();
            for problem in route.problems(nest, &forest, POINT_TOLERANCE_MM) {
                match problem {
                    RouteError::NotCut { contour } if !listed.contains(&contour) => {
                        left_out.push(contour)
                    }
                    other => {
                        return Err(OpenError::InvalidRoute {
                            file_name: tour_name.clone(),
                            nest: nest_name.clone(),
                            reason: other.to_string(),
                        })
                    }
                }
            }
            notes.push(format!(
                "{tour_name}: drawn as a cutting route of {nest_name} (route checked: every contour of the task once, on its contour, inner before outer)"
            ));
            if !left_out.is_empty() {
                let names: Vec<String> = left_out.iter().map(|r| r.to_string()).collect();
                notes.push(format!(
                    "{task_name} does not list {} of {nest_name}: not cut",
                    names.join(", ")
                ));
            }
            document.route = Some(route);
        }
    } else if let Some((tour_name, _)) = &tour {
        notes.push(format!(
            "{tour_name}: not drawn: open the nest's task JSON too to place its nodes on the contours"
        ));
    }
    document.file_name = file_name;
    document.format = format;
    document.warnings.extend(notes_as_warnings(notes));
    Ok(document)
}

/// What a batch's checks found, as warnings of kind [`WarningKind::Other`].
fn notes_as_warnings(notes: Vec<String>) -> Vec<ReadWarning> {
    notes
        .into_iter()
        .map(|n| ReadWarning::new(WarningKind::Other, n))
        .collect()
}

/// The independent check of a result's tour, and of the cost it reports.
fn checked(
    tour_name: &str,
    against: &str,
    instance: &Instance,
    result: &PcglnsResult,
) -> Result<f64, OpenError> {
    let cost = check_tour(instance, &result.tour).map_err(|e| OpenError::InfeasibleTour {
        file_name: tour_name.to_string(),
        against: against.to_string(),
        reason: e.to_string(),
    })?;
    // PCGLNS works on integers: a tour over real weights may differ by rounding, half a unit
    // per arc at most.
    let slack = 0.5 * result.tour.len() as f64 + 1e-6;
    if (cost - result.cost).abs() > slack {
        return Err(OpenError::CostMismatch {
            file_name: tour_name.to_string(),
            against: against.to_string(),
            reported: result.cost,
            checked: cost,
        });
    }
    Ok(cost)
}

fn tour_note(tour_name: &str, against: &str, result: &PcglnsResult, cost: f64) -> String {
    let nodes: Vec<String> = result.tour.iter().map(|n| (n + 1).to_string()).collect();
    format!(
        "{tour_name}: tour checked against {against}: feasible, cost {cost:.3} (the file reports {}); nodes {}",
        result.cost,
        nodes.join(" ")
    )
}

/// The PCGTSP instance a task defines: node 0 is the start (the depot cluster), node `1 + g`
/// the pierce point with 0-based global index `g`; one cluster per task contour; a contour
/// nested in another is cut before it; arcs cost the idle length rounded to whole millimetres
/// (as the instances built from these tasks for PCGLNS do), closing back to the finish.
pub fn task_instance(task: &RmTask) -> Instance {
    let flat = task.flat_contours();
    let point_count = task.pierce_point_count();
    let node_count = point_count + 1;
    let mut position = vec![task.task_data.start(); node_count];
    let mut node_cluster = vec![0; node_count];
    let mut clusters = vec![vec![0]];
    for (i, c) in flat.iter().enumerate() {
        let mut nodes = Vec::new();
        for p in &c.contour.points {
            let node = 1 + usize::try_from(p.zero_based_global_index).unwrap_or(usize::MAX);
            if node < node_count {
                position[node] = p.point();
                node_cluster[node] = i + 1;
                nodes.push(node);
            }
        }
        clusters.push(nodes);
    }
    let mut precedence = Vec::new();
    for (i, c) in flat.iter().enumerate() {
        let mut ancestor = c.parent;
        while let Some(a) = ancestor {
            precedence.push((i + 1, a + 1));
            ancestor = flat[a].parent;
        }
    }
    let finish = task.task_data.finish();
    let mut cost = vec![0.0; node_count * node_count];
    for from in 0..node_count {
        for to in 0..node_count {
            let target = if to == 0 { finish } else { Some(position[to]) };
            cost[from * node_count + to] = match target {
                Some(t) if from != to => position[from].distance(t).round(),
                _ => 0.0,
            };
        }
    }
    Instance {
        name: "task".to_string(),
        node_count,
        cost,
        clusters,
        node_cluster,
        precedence,
        depot: 0,
    }
}

/// The tour's nodes placed on the nest: each task contour is matched to the nest contour its
/// pierce points lie on, and each node after the start becomes a pierce there.
fn tour_route(
    task: &RmTask,
    task_name: &str,
    nest: &Nest,
    nest_name: &str,
    start: Point,
    finish: Option<Point>,
    tour: &[usize],
) -> Result<(Route, Vec<ContourRef>), OpenError> {
    let refs: Vec<ContourRef> = nest.contour_refs().collect();
    // Global index → (pierce point on the nest, nest contour).
    let mut placed: Vec<Option<(Point, ContourRef)>> = vec![None; task.pierce_point_count()];
    let mut listed = Vec::new();
    for c in task.flat_contours() {
        let points: Vec<Point> = c.contour.points.iter().map(on_contour_point).collect();
        let best = refs
            .iter()
            .filter_map(|&r| {
                let contour = nest.contour(r)?;
                let worst = points
                    .iter()
                    .map(|p| contour.distance_to(*p))
                    .fold(0.0_f64, f64::max);
                Some((worst, r))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((_, r)) = best.filter(|(d, _)| *d <= POINT_TOLERANCE_MM) else {
            let first = points.first().copied().unwrap_or(Point::new(0.0, 0.0));
            return Err(OpenError::TaskNotOnNest {
                task: task_name.to_string(),
                index: c.contour.index,
                x: first.x,
                y: first.y,
                nest: nest_name.to_string(),
            });
        };
        listed.push(r);
        let contour = nest.contour(r).expect("found above");
        for (p, point) in c.contour.points.iter().zip(&points) {
            let on = contour.nearest_point(*point).map_or(*point, |n| n.point);
            if let Some(slot) = usize::try_from(p.zero_based_global_index)
                .ok()
                .and_then(|g| placed.get_mut(g))
            {
                *slot = Some((on, r));
            }
        }
    }
    let steps = tour
        .iter()
        .filter(|&&node| node != 0)
        .filter_map(|&node| placed.get(node - 1).copied().flatten())
        .map(|(point, r)| CutStep::pierced(r, point))
        .collect();
    Ok((
        Route {
            start,
            steps,
            finish,
        },
        listed,
    ))
}

/// Where a task's pierce point meets its contour: the circuit point when the task cuts a lead-in
/// to it, else the pierce point itself.
fn on_contour_point(p: &cutroute_formats::PiercePoint) -> Point {
    match (
        p.use_circuit_and_finish_cut_point,
        p.circuit_point_x,
        p.circuit_point_y,
    ) {
        (true, Some(x), Some(y)) => Point::new(x, y),
        _ => p.point(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A file under `data/nests/`; panics naming the file when it is missing.
    fn nests_file(relative: &str) -> (String, Vec<u8>) {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/nests")
            .join(relative);
        let bytes = std::fs::read(&path).unwrap_or_else(|e| {
            panic!(
                "reference file {} is missing or unreadable ({e}); the tests need data/ of the repository",
                path.display()
            )
        });
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        (name, bytes)
    }

    fn route_of(document: &Document) -> &Route {
        document.route.as_ref().expect("a route")
    }

    #[test]
    fn instance_and_result_check_the_tour() {
        let files = [
            nests_file("pcgtsp/E1X_6_01.pcgtsp"),
            nests_file("pcgtsp/E1X_6_01.pcglns.result.txt"),
        ];
        let document = open_together(&files).unwrap();
        assert!(matches!(document.problem, Problem::PcgtspText { .. }));
        assert_eq!(document.format, "PCGTSP instance + PCGLNS result");
        assert!(
            document.warnings[0].message.contains("feasible"),
            "{:?}",
            document.warnings
        );
        assert!(
            document.warnings[0].message.contains("reports 1514"),
            "{:?}",
            document.warnings
        );
    }

    #[test]
    fn an_infeasible_tour_is_refused_in_plain_words() {
        let (name, bytes) = nests_file("pcgtsp/E1X_6_01.pcglns.result.txt");
        // Cut the outer contour 2 (nodes 25..28 are its hole, cluster 3) before its hole.
        let text = String::from_utf8(bytes).unwrap().replace(
            "[1, 161, 138, 80, 67, 27, 14,",
            "[1, 161, 138, 80, 67, 14, 27,",
        );
        assert!(
            text.contains("[1, 161, 138, 80, 67, 14, 27,"),
            "the edit applies"
        );
        let files = [
            nests_file("pcgtsp/E1X_6_01.pcgtsp"),
            (name, text.into_bytes()),
        ];
        let error = open_together(&files).unwrap_err();
        assert!(matches!(error, OpenError::InfeasibleTour { .. }), "{error}");
        // Arcs that break the order are forbidden in the matrix: that is what the checker meets.
        assert!(error.to_string().contains("is forbidden"), "{error}");
    }

    #[test]
    fn a_tour_alone_asks_for_its_instance() {
        let (name, bytes) = nests_file("pcgtsp/test1.pcglns.result.txt");
        let error = open_document(&name, &bytes).unwrap_err();
        assert_eq!(error, OpenError::TourAlone(name));
    }

    #[test]
    fn nest_task_instance_and_result_become_a_checked_route() {
        let files = [
            nests_file("dbs-json/E1X_6_01.dbs.json"),
            nests_file("task-json/E1X_6_01.task.json"),
            nests_file("pcgtsp/E1X_6_01.pcgtsp"),
            nests_file("pcgtsp/E1X_6_01.pcglns.result.txt"),
        ];
        let document = open_together(&files).unwrap();
        let Problem::Nest { nest, .. } = &document.problem else {
            panic!("a nest")
        };
        let route = route_of(&document);
        assert_eq!(route.steps.len(), 16);
        route.validate(nest, POINT_TOLERANCE_MM).unwrap();
        // The instance's weights are the exact idle lengths: the route's idle length is the
        // tour's cost (1514 rounded in the file).
        // The instance's weights are the exact idle lengths between pierce points (PCGLNS
        // rounds them: it reports 1514), so the drawn route's idle length is the tour's cost.
        let (_, instance) = nests_file("pcgtsp/E1X_6_01.pcgtsp");
        let instance = Instance::parse(std::str::from_utf8(&instance).unwrap()).unwrap();
        let tour = [
            1, 161, 138, 80, 67, 27, 14, 92, 90, 181, 177, 112, 108, 47, 41, 133, 124,
        ];
        let tour: Vec<usize> = tour.iter().map(|n| n - 1).collect();
        let cost = check_tour(&instance, &tour).unwrap();
        assert!(
            (route.idle_length() - cost).abs() < 1e-6,
            "{} vs {cost}",
            route.idle_length()
        );
        assert!(document.warnings[0]
            .message
            .contains(&format!("feasible, cost {cost:.3}")));
        assert!(
            (cost - 1514.0).abs() < 0.5 * 17.0,
            "rounding explains the file's cost"
        );
    }

    #[test]
    fn test1_nest_task_and_result_become_a_checked_route() {
        let files = [
            nests_file("dbs-json/test1.dbs.json"),
            nests_file("task-json/test1.task.json"),
            nests_file("pcgtsp/test1.pcglns.result.txt"),
        ];
        let document = open_together(&files).unwrap();
        let Problem::Nest { nest, .. } = &document.problem else {
            panic!("a nest")
        };
        let route = route_of(&document);
        assert_eq!(route.steps.len(), 23);
        // Parts 16 and 18 coincide with the holes they fill (a common edge): the task lists each
        // such edge once, so those two contours are all the route checker finds uncut.
        let problems = route.problems(nest, &nest.containment_forest(), POINT_TOLERANCE_MM);
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(
            problems
                .iter()
                .all(|p| matches!(p, RouteError::NotCut { .. })),
            "{problems:?}"
        );
        assert!(
            document.warnings[0]
                .message
                .contains("feasible, cost 4662.000"),
            "{:?}",
            document.warnings
        );
        // The task repeats two holes as parts of their own only once: those are not cut.
        assert!(
            document.warnings[2]
                .message
                .contains("does not list part 16 contour 0, part 18 contour 0 of"),
            "{:?}",
            document.warnings
        );
        assert_eq!(document.warnings.len(), 3, "{:?}", document.warnings);
    }

    #[test]
    fn the_e1x_task_instance_agrees_with_the_shipped_instance() {
        let (_, task) = nests_file("task-json/E1X_6_01.task.json");
        let (_, shipped) = nests_file("pcgtsp/E1X_6_01.pcgtsp");
        let built = task_instance(&read_task_json(&task).unwrap());
        let shipped = Instance::parse(std::str::from_utf8(&shipped).unwrap()).unwrap();
        assert_eq!(built.node_count, shipped.node_count);
        assert_eq!(built.clusters, shipped.clusters);
        for from in 0..built.node_count {
            for to in 0..built.node_count {
                let (a, b) = (built.arc_cost(from, to), shipped.arc_cost(from, to));
                if from != to && built.node_cluster[from] != built.node_cluster[to] && b.is_finite()
                {
                    assert!((a - b).abs() <= 0.5 + 1e-9, "arc {from}->{to}: {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn gcode_reads_back_as_the_route_it_was_written_from() {
        let (name, bytes) = nests_file("dbs-json/E1X_6_01.dbs.json");
        let Problem::Nest { nest, start, .. } = open_document(&name, &bytes).unwrap().problem
        else {
            panic!("a nest")
        };
        let request = cutroute_protocol::JobRequest {
            job_id: 1,
            problem: Problem::Nest {
                nest: nest.clone(),
                start,
                finish: None,
            },
            solver: cutroute_protocol::SolverKind::NearestNeighbour,
            params: Default::default(),
        };
        let mut job = crate::start_job(&request).unwrap();
        let route = crate::run_to_end(job.as_mut(), &mut |_| {})
            .route()
            .cloned()
            .unwrap();
        let program =
            cutroute_gcode::route_gcode(&nest, &route, &cutroute_gcode::GcodeOptions::default())
                .unwrap();
        let document = open_document("E1X_6_01.nc", program.as_bytes()).unwrap();
        assert_eq!(document.format, "G-code");
        let Problem::Nest { nest: read, .. } = &document.problem else {
            panic!("a nest")
        };
        let back = route_of(&document);
        assert_eq!(read.parts.len(), 8, "parts by containment");
        assert_eq!(back.pierce_count(), route.pierce_count());
        assert!((back.idle_length() - route.idle_length()).abs() < 0.01);
        assert!((back.cut_length(read) - route.cut_length(&nest)).abs() < 0.01);
        back.validate(read, POINT_TOLERANCE_MM).unwrap();
        assert!(document.warnings.is_empty(), "{:?}", document.warnings);
    }

    #[test]
    fn a_gcode_loop_crossing_itself_in_a_loop_too_small_to_cut_is_repaired_and_said() {
        // A square whose right edge overshoots the corner by 5 µm and comes back across it.
        let program = "G90 G21\nG00 X0 Y0\nM03\nG01 X10 Y0 F1000\nG01 X10 Y10.005\n\
                       G01 X10.005 Y10\nG01 X0 Y10\nG01 X0 Y0\nM05\n";
        let document = open_document("corner.nc", program.as_bytes()).unwrap();
        let Problem::Nest { nest, .. } = &document.problem else {
            panic!("a nest")
        };
        assert_eq!(nest.parts.len(), 1);
        let contour = &nest.parts[0].contours[0];
        assert_eq!(contour.check_cuttable(POINT_TOLERANCE_MM), Ok(()));
        assert!((contour.area() - 100.0).abs() < 1e-6, "{}", contour.area());
        let [warning] = &document.warnings[..] else {
            panic!("one warning: {:?}", document.warnings)
        };
        assert_eq!(warning.kind, WarningKind::SelfIntersecting);
        assert!(warning.message.contains("removed"), "{}", warning.message);
        assert_eq!(warning.left_out.len(), 1);
        assert!(document.paths.is_none(), "the loops are the whole program");
        route_of(&document)
            .validate(nest, POINT_TOLERANCE_MM)
            .unwrap();

        // A bow-tie's lobes are no such loop: left out, as before.
        let bow_tie = "G90 G21\nG00 X0 Y0\nM03\nG01 X10 Y10 F1000\nG01 X10 Y0\n\
                       G01 X0 Y10\nG01 X0 Y0\nM05\n";
        let document = open_document("bow.nc", bow_tie.as_bytes()).unwrap();
        assert!(
            document
                .warnings
                .iter()
                .any(|w| w.kind == WarningKind::SelfIntersecting && w.message.contains("left out")),
            "{:?}",
            document.warnings
        );
    }

    #[test]
    fn unknown_files_list_what_is_understood() {
        let error = open_document("notes.txt", b"just some words").unwrap_err();
        assert_eq!(error, OpenError::UnknownFormat("notes.txt".into()));
        assert!(error.to_string().contains("G-code"), "{error}");
    }

    #[test]
    fn broken_gcode_names_its_line() {
        let error = open_document("bad.nc", b"G90\nG01 X10 Y\n").unwrap_err();
        assert!(
            error.to_string().starts_with("bad.nc (G-code): "),
            "{error}"
        );
        assert!(error.to_string().contains("line 2"), "{error}");
    }
}
