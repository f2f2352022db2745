//! The RouteManager cutting result (`rm-result.json`, thesis Listing Г.3): an echo of the task
//! (`job`: the sheet outline and every contour with arc angles in degrees) and the solution
//! (`results`: lengths, time and the tool path as a list of vertices, each with the mode of the
//! move that leaves it).
//!
//! Real files also use the modes `cut.in` / `cut.out` (lead-in and lead-out) and the fields
//! `partid` / `pathid`; they are accepted. Our own routes are exported in this format
//! ([`RmResult::from_route`]) so existing tools can read them, and results are turned into
//! things the UI can draw ([`RmResult::tool_moves`], [`RmResult::nest`]).
//!
//! Chain cutting's tool-on links (see [`cutroute_geometry::Entry::Link`]) are written as `cut`
//! moves without a `part.id` (the torch is on, no contour is being cut) and read back as links.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{
    chain_spans, opened_at, BoundingBox, Contour, ContourRef, CutStep, Entry, Nest, Part, Point,
    Route, Span, StepLeads, Tab, Vertex,
};
use serde::{Deserialize, Serialize};

use crate::contour_check::{self, DEFAULT_CLOSURE_TOLERANCE};
use crate::json::{self, JsonError, JsonWriteError};

/// A cutting result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RmResult {
    /// What was solved.
    pub job: Job,
    /// The solution.
    pub results: Results,
}

/// The task solved, as echoed in the result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Job {
    /// Number of contours.
    #[serde(rename = "paths.count")]
    pub paths_count: i64,
    /// Number of parts (the sheet not counted).
    #[serde(rename = "parts.count")]
    pub parts_count: i64,
    /// Number of candidate pierce points.
    #[serde(rename = "total.points.count")]
    pub total_points_count: i64,
    /// Undocumented RouteManager figure, kept as read.
    #[serde(rename = "total.address.pairs.count")]
    pub total_address_pairs_count: i64,
    /// The sheet outline: `[x, y, angle°]` points, closing point repeated.
    pub list: Vec<[f64; 3]>,
    /// Every contour of the task.
    pub paths: Vec<ResultPath>,
}

/// One contour of the task.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResultPath {
    /// 1-based part number (the sheet is not a part).
    #[serde(rename = "part.id")]
    pub part_id: i64,
    /// 0-based contour number within the part; 0 is the outer contour.
    pub id: i64,
    /// Extension: the part's designation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partid: Option<String>,
    /// Extension: the contour's id in the source DBS file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pathid: Option<i64>,
    /// `[x, y, angle°]` points, closing point repeated.
    pub points: Vec<[f64; 3]>,
}

/// The solution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Results {
    /// The objective (RouteManager reports the idle time, s).
    pub result: f64,
    /// Idle length L_off, mm.
    #[serde(rename = "route.length.no.contours")]
    pub route_length_no_contours: f64,
    /// Total length (idle + cut), mm.
    #[serde(rename = "route.length")]
    pub route_length: f64,
    /// Computation time `HH:MM:SS.mmm`.
    #[serde(rename = "count.time")]
    pub count_time: String,
    /// The tool path, vertex by vertex.
    pub toolpath: Vec<ToolpathEntry>,
}

/// What the tool does on the move that leaves a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum MoveKind {
    /// Idle (torch off).
    #[serde(rename = "air")]
    Air,
    /// Cutting a contour.
    #[serde(rename = "cut")]
    Cut,
    /// Lead-in: from the pierce point to the contour.
    #[serde(rename = "cut.in")]
    CutIn,
    /// Lead-out: leaving the contour after it is cut.
    #[serde(rename = "cut.out")]
    CutOut,
}

/// One vertex of the tool path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolpathEntry {
    /// Sequential number.
    #[serde(rename = "point.id")]
    pub point_id: i64,
    /// Mode of the move leaving this vertex.
    pub mode: MoveKind,
    /// 1-based part number of the contour being cut.
    #[serde(rename = "part.id", default, skip_serializing_if = "Option::is_none")]
    pub part_id: Option<i64>,
    /// 0-based contour number within the part.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<i64>,
    /// Extension: the part's designation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partid: Option<String>,
    /// Extension: the contour's id in the source DBS file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pathid: Option<i64>,
    /// `[x, y, angle°]`: the vertex and the arc angle of the move leaving it (0 = straight).
    pub point: [f64; 3],
}

/// One move of the tool, ready to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolMove {
    /// What the tool does.
    pub kind: MoveKind,
    /// Where the move starts.
    pub from: Point,
    /// Where it ends.
    pub to: Point,
    /// Bulge of the move (0 = straight).
    pub bulge: f64,
    /// The contour being cut, for cutting moves that name one.
    pub contour: Option<ContourRef>,
}

/// Options of [`RmResult::from_route`].
#[derive(Clone, Debug, PartialEq)]
pub struct ResultExportOptions {
    /// Idle speed, mm/s: `result` is the idle time L_off / speed, as RouteManager reports.
    pub idle_speed: f64,
    /// Value for `count.time`.
    pub count_time: String,
    /// Value for `total.points.count`; `None` writes the number of cut steps.
    pub total_points_count: Option<i64>,
    /// Value for `total.address.pairs.count`.
    pub address_pairs_count: i64,
    /// Write the `partid` extension (part names) on paths and cutting moves.
    pub part_names: bool,
}

impl Default for ResultExportOptions {
    fn default() -> Self {
        Self {
            idle_speed: 500.0,
            count_time: "00:00:00.000".into(),
            total_points_count: None,
            address_pairs_count: 0,
            part_names: true,
        }
    }
}

/// Why a route cannot be turned into moves or a result file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RouteError {
    /// A step names a contour the nest does not have.
    #[error("route step {step} cuts part {part} contour {contour}, which the nest does not have")]
    NoSuchContour {
        /// Index of the step.
        step: usize,
        /// `ContourRef::part`.
        part: usize,
        /// `ContourRef::contour`.
        contour: usize,
    },
    /// A step's contour has no vertices.
    #[error("route step {step} cuts an empty contour")]
    EmptyContour {
        /// Index of the step.
        step: usize,
    },
    /// A step with leads names an offset its contour has no equidistant at.
    #[error("route step {step}: no equidistant for its kerf ({problem})")]
    NoEquidistant {
        /// Index of the step.
        step: usize,
        /// Why the offset failed.
        #[source]
        problem: cutroute_geometry::OffsetError,
    },
}

/// Reads a result file and checks the schema's minimum lengths.
pub fn read_result_json(bytes: &[u8]) -> Result<RmResult, JsonError> {
    let result: RmResult = json::parse(bytes)?;
    let short = |path: String, len: usize| JsonError::TooShort { path, len, min: 2 };
    if result.job.list.len() < 2 {
        return Err(short("job.list".into(), result.job.list.len()));
    }
    if let Some((i, p)) = result
        .job
        .paths
        .iter()
        .enumerate()
        .find(|(_, p)| p.points.len() < 2)
    {
        return Err(short(format!("job.paths[{i}].points"), p.points.len()));
    }
    Ok(result)
}

/// Writes a result file (pretty-printed).
pub fn write_result_json(result: &RmResult) -> Result<String, JsonWriteError> {
    json::to_pretty(result)
}

/// Arc angle in degrees (signed, CCW positive) of a span with bulge `b`: how result JSON stores
/// a bulge.
fn bulge_to_degrees(b: f64) -> f64 {
    4.0 * b.atan_libm().to_degrees()
}

/// Bulge of a span whose swept angle is `deg` degrees (result JSON's angle read back).
fn degrees_to_bulge(deg: f64) -> f64 {
    (deg.to_radians() / 4.0).tan_libm()
}

/// The vertices of the full cut of `contour` from the point nearest to `pierce` round to it
/// again, as the tool path lists them: the first vertex is the pierce point and the list
/// repeats it at the end with bulge 0. Pieces without length (a pierce point on a vertex, a
/// repeated vertex) are left out. `None` for a contour without vertices.
fn cut_from(contour: &Contour, pierce: Point) -> Option<Vec<Vertex>> {
    let start = contour.nearest_point(pierce)?.point;
    let mut out: Vec<Vertex> = opened_at(contour, pierce, 0.0)
        .into_iter()
        .map(|s| Vertex {
            point: s.start,
            bulge: s.bulge,
        })
        .collect();
    if out.is_empty() {
        // Every span has zero length: the cut is the pierce point alone.
        out.push(Vertex {
            point: start,
            bulge: 0.0,
        });
    }
    out.push(Vertex {
        point: start,
        bulge: 0.0,
    });
    Some(out)
}

fn stored_degrees(contour: &Contour) -> Vec<[f64; 3]> {
    contour_check::stored_points(contour)
        .into_iter()
        .map(|[x, y, b]| [x, y, bulge_to_degrees(b)])
        .collect()
}

/// The moves of a route over a nest: idle to each pierce point (or the tool-on link of a chained
/// step, as `Cut` moves without a contour), the full contour from there (split where the pierce
/// point falls inside a span), and idle to the finish.
///
/// A step cut with leads (see [`StepLeads`]) is idle to its pierce point M, `cut.in` along the
/// lead-in to the entry, `cut` round the equidistant from the entry (and the overcut), `cut.out`
/// along the lead-out to the switch-off point M*, where the next idle move starts. The lead
/// moves name the step's contour, so a reader knows whose they are.
pub fn route_moves(nest: &Nest, route: &Route) -> Result<Vec<ToolMove>, RouteError> {
    let mut moves = Vec::new();
    let mut at = route.start;
    for (step, cut) in route.steps.iter().enumerate() {
        let contour = step_contour(nest, step, cut)?;
        let on = Some(cut.contour);
        let mut push = |kind, span: Span, contour| {
            moves.push(ToolMove {
                kind,
                from: span.start,
                to: span.end,
                bulge: span.bulge,
                contour,
            })
        };
        // Idealised: the contour's own cut, from its point nearest the pierce point round to it.
        let (switch_on, idealised) = match &cut.leads {
            Some(leads) => (leads.pierce, Vec::new()),
            None => {
                let vertices =
                    cut_from(contour, cut.pierce_point).ok_or(RouteError::EmptyContour { step })?;
                (vertices[0].point, vertices)
            }
        };
        match &cut.entry {
            Entry::Pierce => push(MoveKind::Air, Span::line(at, switch_on), None),
            Entry::Link(corners) => {
                for (from, to) in link_pieces(at, corners, switch_on) {
                    push(MoveKind::Cut, Span::line(from, to), None);
                }
            }
        }
        match &cut.leads {
            None => {
                for w in idealised.windows(2) {
                    push(
                        MoveKind::Cut,
                        Span::new(w[0].point, w[1].point, w[0].bulge),
                        on,
                    );
                }
            }
            Some(leads) => {
                chain_spans(&leads.lead_in).for_each(|s| push(MoveKind::CutIn, s, on));
                let equidistant = cutroute_geometry::equidistant(contour, leads.offset)
                    .map_err(|problem| RouteError::NoEquidistant { step, problem })?;
                // A tab's gap is an idle move that names the contour, between cut pieces.
                let pieces = leads.equidistant_pieces(&equidistant, 0.0);
                for (k, piece) in pieces.into_iter().enumerate() {
                    if let Some(tab) = k.checked_sub(1).and_then(|t| leads.tabs.get(t)) {
                        push(MoveKind::Air, Span::line(tab.from, tab.to), on);
                    }
                    for span in piece {
                        push(MoveKind::Cut, span, on);
                    }
                }
                chain_spans(&leads.lead_out).for_each(|s| push(MoveKind::CutOut, s, on));
            }
        }
        at = match &cut.leads {
            Some(leads) => leads.switch_off,
            None => switch_on,
        };
    }
    if let Some(finish) = route.finish {
        moves.push(ToolMove {
            kind: MoveKind::Air,
            from: at,
            to: finish,
            bulge: 0.0,
            contour: None,
        });
    }
    Ok(moves)
}

/// The straight pieces of a tool-on link from `from` through `corners` to `to`.
fn link_pieces(from: Point, corners: &[Point], to: Point) -> Vec<(Point, Point)> {
    let points: Vec<Point> = std::iter::once(from)
        .chain(corners.iter().copied())
        .chain(std::iter::once(to))
        .collect();
    points.windows(2).map(|w| (w[0], w[1])).collect()
}

fn step_contour<'a>(nest: &'a Nest, step: usize, cut: &CutStep) -> Result<&'a Contour, RouteError> {
    let ContourRef { part, contour } = cut.contour;
    let c = nest
        .parts
        .get(part)
        .and_then(|p| p.contours.get(contour))
        .ok_or(RouteError::NoSuchContour {
            step,
            part,
            contour,
        })?;
    if c.vertices.is_empty() {
        return Err(RouteError::EmptyContour { step });
    }
    Ok(c)
}

impl ToolMove {
    /// Length of the move, mm.
    pub fn length(&self) -> f64 {
        Span::new(self.from, self.to, self.bulge).length()
    }
}

impl RmResult {
    /// Exports a route over a nest in RouteManager's result format. Contours are cut in their
    /// own direction starting at the pierce point; lengths are computed from the geometry.
    pub fn from_route(
        nest: &Nest,
        route: &Route,
        options: &ResultExportOptions,
    ) -> Result<Self, RouteError> {
        let mut paths = Vec::new();
        for (i, part) in nest.parts.iter().enumerate() {
            for (k, contour) in part.contours.iter().enumerate() {
                paths.push(ResultPath {
                    part_id: i as i64 + 1,
                    id: k as i64,
                    partid: options.part_names.then(|| part.name.clone()),
                    pathid: None,
                    points: stored_degrees(contour),
                });
            }
        }
        let list = match nest.sheet.as_ref().and_then(|s| s.contours.first()) {
            Some(outline) => stored_degrees(outline),
            None => bounding_rectangle(nest),
        };
        let mut toolpath = Vec::new();
        let mut push = |mode, point: Point, angle: f64, contour: Option<ContourRef>| {
            toolpath.push(ToolpathEntry {
                point_id: toolpath.len() as i64,
                mode,
                part_id: contour.map(|c| c.part as i64 + 1),
                id: contour.map(|c| c.contour as i64),
                partid: contour
                    .filter(|_| options.part_names)
                    .and_then(|c| nest.parts.get(c.part))
                    .map(|p| p.name.clone()),
                pathid: None,
                point: [point.x, point.y, angle],
            });
        };
        // Each vertex carries the mode, contour and arc angle of the move that leaves it; the
        // last one ends the path as an idle vertex.
        let moves = route_moves(nest, route)?;
        let (mut idle, mut cut_len) = (0.0, 0.0);
        for m in &moves {
            let length = m.length();
            match m.kind {
                MoveKind::Air => idle += length,
                _ => cut_len += length,
            }
            push(m.kind, m.from, bulge_to_degrees(m.bulge), m.contour);
        }
        let end = moves.last().map_or(route.start, |m| m.to);
        push(MoveKind::Air, end, 0.0, None);
        Ok(RmResult {
            job: Job {
                paths_count: paths.len() as i64,
                parts_count: nest.parts.len() as i64,
                total_points_count: options
                    .total_points_count
                    .unwrap_or(route.steps.len() as i64),
                total_address_pairs_count: options.address_pairs_count,
                list,
                paths,
            },
            results: Results {
                result: idle / options.idle_speed,
                route_length_no_contours: idle,
                route_length: idle + cut_len,
                count_time: options.count_time.clone(),
                toolpath,
            },
        })
    }

    /// The tool path as drawable moves: each vertex's mode and angle describe the move to the
    /// next vertex.
    pub fn tool_moves(&self) -> Vec<ToolMove> {
        self.results
            .toolpath
            .windows(2)
            .map(|w| {
                let [x, y, angle] = w[0].point;
                let contour = match (w[0].part_id, w[0].id) {
                    (Some(p), Some(c)) if p >= 1 && c >= 0 => Some(ContourRef {
                        part: (p - 1) as usize,
                        contour: c as usize,
                    }),
                    _ => None,
                };
                ToolMove {
                    kind: w[0].mode,
                    from: Point::new(x, y),
                    to: Point::new(w[1].point[0], w[1].point[1]),
                    bulge: degrees_to_bulge(angle),
                    contour,
                }
            })
            .collect()
    }

    /// The nest echoed in `job`: the sheet from `list`, parts from `paths` grouped by `part.id`
    /// (in order of first appearance, contours sorted by `id`).
    pub fn nest(&self) -> Result<Nest, JsonError> {
        let closed = |points: &[[f64; 3]], path: String| {
            let pts: Vec<[f64; 3]> = points
                .iter()
                .map(|&[x, y, a]| [x, y, degrees_to_bulge(a)])
                .collect();
            contour_check::closed_contour(&pts, DEFAULT_CLOSURE_TOLERANCE, true)
                .map_err(|problem| JsonError::BadContour { path, problem })
        };
        let sheet = Part {
            name: "sheet".into(),
            contours: vec![closed(&self.job.list, "job.list".into())?],
        };
        let mut groups: Vec<PartGroup> = Vec::new();
        for (i, p) in self.job.paths.iter().enumerate() {
            let contour = closed(&p.points, format!("job.paths[{i}].points"))?;
            match groups.iter_mut().find(|g| g.0 == p.part_id) {
                Some(g) => g.2.push((p.id, contour)),
                None => groups.push((p.part_id, p.partid.clone(), vec![(p.id, contour)])),
            }
        }
        let parts = groups
            .into_iter()
            .map(|(part_id, name, mut contours)| {
                contours.sort_by_key(|c| c.0);
                Part {
                    name: name.unwrap_or_else(|| part_id.to_string()),
                    contours: contours.into_iter().map(|c| c.1).collect(),
                }
            })
            .collect();
        Ok(Nest {
            sheet: Some(sheet),
            parts,
        })
    }

    /// The route the tool path describes: the start, one step per cut contour (pierce point =
    /// where cutting of the contour begins, after any lead-in) and the final point as finish.
    /// A contour reached from the previous one by `cut` moves without a contour (torch on, no
    /// idle move, no lead) is a chained step: its entry is a link through those moves' corners.
    ///
    /// A step with `cut.in`/`cut.out` moves, or whose cut runs off its contour (on the kerf's
    /// equidistant), gets its [`StepLeads`] back: M where the lead-in starts, the entry where
    /// the cut starts, M* where the lead-out ends. The offset is the entry's distance from the
    /// contour and the overcut the cut's length beyond the equidistant's perimeter; the
    /// clearances d₁ and d₂ are not in the file and read as 0.
    pub fn route(&self) -> Route {
        let moves = self.tool_moves();
        let nest = self.nest().ok();
        let start = moves.first().map(|m| m.from).unwrap_or_default();
        let mut steps: Vec<CutStep> = Vec::new();
        // The contour being cut, and the ends of the link moves since it (torch still on).
        let mut current: Option<ContourRef> = None;
        let mut link_ends: Option<Vec<Point>> = None;
        // Lead-in moves since the last idle move, and the step being cut with what it had.
        let mut lead_in: Vec<ToolMove> = Vec::new();
        let mut open: Option<ReadLeads> = None;
        let close = |open: &mut Option<ReadLeads>, steps: &mut Vec<CutStep>| {
            if let (Some(read), Some(nest)) = (open.take(), nest.as_ref()) {
                read.attach(nest, steps);
            }
        };
        for m in &moves {
            match (m.kind, m.contour) {
                (MoveKind::CutIn, _) => {
                    close(&mut open, &mut steps);
                    lead_in.push(*m);
                    current = None;
                    link_ends = None;
                }
                (MoveKind::Cut, Some(contour)) if current != Some(contour) => {
                    close(&mut open, &mut steps);
                    let entry = match (current, link_ends.take()) {
                        (Some(_), Some(mut ends)) => {
                            ends.pop(); // the last end is this step's pierce point
                            Entry::Link(ends)
                        }
                        _ => Entry::Pierce,
                    };
                    steps.push(CutStep {
                        contour,
                        pierce_point: m.from,
                        entry,
                        leads: None,
                    });
                    open = Some(ReadLeads {
                        step: steps.len() - 1,
                        lead_in: std::mem::take(&mut lead_in),
                        entry: m.from,
                        cut_length: m.length(),
                        exit: m.to,
                        lead_out: Vec::new(),
                        tabs: Vec::new(),
                    });
                    current = Some(contour);
                }
                (MoveKind::Cut, Some(_)) => {
                    if let Some(read) = open.as_mut() {
                        read.cut_length += m.length();
                        read.exit = m.to;
                    }
                }
                (MoveKind::CutOut, _) => {
                    if let Some(read) = open.as_mut() {
                        read.lead_out.push(*m);
                    }
                }
                (MoveKind::Air, Some(contour)) if current == Some(contour) => {
                    if let Some(read) = open.as_mut() {
                        read.tabs.push((read.cut_length, m.from, m.to));
                    }
                }
                (MoveKind::Cut, None) if current.is_some() => {
                    link_ends.get_or_insert_with(Vec::new).push(m.to);
                }
                _ => {
                    close(&mut open, &mut steps);
                    lead_in.clear();
                    current = None;
                    link_ends = None;
                }
            }
        }
        close(&mut open, &mut steps);
        let finish = match moves.last() {
            Some(m) if m.kind == MoveKind::Air => Some(m.to),
            _ => None,
        };
        Route {
            start,
            steps,
            finish,
        }
    }
}

/// What the tool path says about one step's full-route elements, while it is read.
struct ReadLeads {
    step: usize,
    lead_in: Vec<ToolMove>,
    entry: Point,
    cut_length: f64,
    exit: Point,
    lead_out: Vec<ToolMove>,
    /// Tab gaps: the cut length before each, where the torch stops and where it starts again.
    tabs: Vec<(f64, Point, Point)>,
}

/// Entries closer to their contour than this are on it: the idealised model.
const ON_CONTOUR: f64 = 1e-9;

impl ReadLeads {
    /// Gives the step its leads, unless it was cut on its contour without any.
    fn attach(self, nest: &Nest, steps: &mut [CutStep]) {
        let Some(step) = steps.get_mut(self.step) else {
            return;
        };
        let Some(contour) = nest.contour(step.contour) else {
            return;
        };
        let Some(nearest) = contour.nearest_point(self.entry) else {
            return;
        };
        let offset = nearest.point.distance(self.entry);
        if self.lead_in.is_empty()
            && self.lead_out.is_empty()
            && self.tabs.is_empty()
            && offset < ON_CONTOUR
        {
            return;
        }
        let chain = |moves: &[ToolMove], end: Point| -> Vec<Vertex> {
            moves
                .iter()
                .map(|m| Vertex {
                    point: m.from,
                    bulge: m.bulge,
                })
                .chain(std::iter::once(Vertex {
                    point: moves.last().map_or(end, |m| m.to),
                    bulge: 0.0,
                }))
                .collect()
        };
        let lead_in = chain(&self.lead_in, self.entry);
        let lead_out = chain(&self.lead_out, self.exit);
        let equidistant =
            cutroute_geometry::equidistant(contour, offset).unwrap_or_else(|_| contour.clone());
        let perimeter = equidistant.perimeter();
        let along = |p: Point| {
            equidistant
                .nearest_point(p)
                .map_or(0.0, |q| equidistant.length_at(q.position))
        };
        // Each gap's width is its length along the equidistant; its start counts the cut
        // before it and the gaps before it.
        let mut gaps = 0.0;
        let tabs: Vec<Tab> = self
            .tabs
            .iter()
            .map(|&(cut, from, to)| {
                let width = (along(to) - along(from)).rem_euclid(perimeter.max(f64::MIN_POSITIVE));
                let start = cut + gaps;
                gaps += width;
                Tab {
                    start,
                    end: start + width,
                    from,
                    to,
                }
            })
            .collect();
        step.pierce_point = nearest.point;
        step.leads = Some(StepLeads {
            pierce: lead_in[0].point,
            entry: self.entry,
            switch_off: lead_out[lead_out.len() - 1].point,
            lead_in,
            lead_out,
            offset,
            overcut: (self.cut_length + gaps - perimeter).max(0.0),
            pierce_clearance: 0.0,
            switch_off_clearance: 0.0,
            tabs,
            // The format has no edge-pierce mark; with d₁ 0 a border pierce is in G_M anyway.
            edge_pierce: false,
            kerf_pierce: None,
        });
    }
}

/// Contours of one `part.id` collected from `job.paths`: (part.id, partid, [(id, contour)]).
type PartGroup = (i64, Option<String>, Vec<(i64, cutroute_geometry::Contour)>);

/// A clockwise rectangle around every part, used as `list` when the nest has no sheet.
fn bounding_rectangle(nest: &Nest) -> Vec<[f64; 3]> {
    let mut b = BoundingBox::from_points(
        nest.parts
            .iter()
            .flat_map(|p| &p.contours)
            .flat_map(|c| &c.vertices)
            .map(|v| v.point),
    );
    if !b.min.x.is_finite() {
        b = BoundingBox::from_corners(Point::ORIGIN, Point::ORIGIN);
    }
    let (lo, hi) = (b.min, b.max);
    vec![
        [lo.x, lo.y, 0.0],
        [lo.x, hi.y, 0.0],
        [hi.x, hi.y, 0.0],
        [hi.x, lo.y, 0.0],
        [lo.x, lo.y, 0.0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(r: f64, bulge: f64) -> Contour {
        Contour::new(vec![
            Vertex::arc(0.0, r, bulge),
            Vertex::arc(0.0, -r, bulge),
        ])
    }

    #[test]
    fn angle_conversion_round_trips() {
        assert!((bulge_to_degrees(1.0) - 180.0).abs() < 1e-12);
        assert!((degrees_to_bulge(90.0) - (2f64.sqrt() - 1.0)).abs() < 1e-12);
        assert!((degrees_to_bulge(bulge_to_degrees(-0.3)) + 0.3).abs() < 1e-12);
    }

    fn cut_length(cut: &[Vertex]) -> f64 {
        cut.windows(2)
            .map(|w| Span::new(w[0].point, w[1].point, w[0].bulge).length())
            .sum()
    }

    #[test]
    fn cut_from_mid_arc_keeps_the_length() {
        let c = circle(5.0, -1.0);
        let pierce = Point::new(5.0, 0.0);
        let cut = cut_from(&c, pierce).unwrap();
        assert_eq!(cut.first().unwrap().point, cut.last().unwrap().point);
        assert!(cut[0].point.distance(pierce) < 1e-9);
        assert_eq!(cut.len(), 4);
        assert!((cut_length(&cut) - c.perimeter()).abs() < 1e-9);
    }

    #[test]
    fn cut_from_a_vertex_adds_no_sliver() {
        let square = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, 10.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(10.0, 0.0),
        ]);
        let cut = cut_from(&square, Point::new(10.0, 10.0)).unwrap();
        let points: Vec<Point> = cut.iter().map(|v| v.point).collect();
        assert_eq!(
            points,
            [
                (10.0, 10.0),
                (10.0, 0.0),
                (0.0, 0.0),
                (0.0, 10.0),
                (10.0, 10.0)
            ]
            .map(|(x, y)| Point::new(x, y))
        );
        assert!((cut_length(&cut) - 40.0).abs() < 1e-12);
    }
}
