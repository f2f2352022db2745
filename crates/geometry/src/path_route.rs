//! Routes made of tool-on paths (segment cutting, SCCP/GSCCP): each path is pierced once and then
//! cuts an arbitrary chain of spans end to end — a whole contour, part of one, several
//! contours joined along their common edges, or pieces through scrap between them.
//!
//! A [`Route`] can only say "cut this whole contour from this pierce point"; a [`PathRoute`]
//! says exactly where the torch goes. [`PathRoute::problems`] checks one against a nest without
//! trusting whoever built it: paths are contiguous, every contour's boundary is covered exactly
//! once by measure (a span on a common edge covers both contours), tool-on pieces off every
//! contour stay in scrap and cross no contour, and a contour's boundary is completed only after
//! the boundaries of all contours inside it.

use rstar::{RTree, RTreeObject, AABB};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::{
    BoundingBox, ContainmentForest, ContourRef, ContourSpans, LeadFitter, LeadProblem,
    MachineParameters, Nest, PathLeads, Point, Route, RouteError, Span,
};

/// One pierce's worth of cutting: the torch pierces at `pierce` and cuts `spans` in order.
/// With [`PathLeads`] (the full cutting route: kerf, pierce regions, leads) the torch pierces at
/// `pierce` = M, runs the lead-in to the entry where the spans start (on an equidistant), cuts
/// them, and runs the lead-out to the switch-off point M*.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ToolOnPath {
    /// Where the torch pierces; without leads the first span starts here.
    pub pierce: Point,
    /// The spans in cutting direction, each starting where the previous one ends.
    pub spans: Vec<Span>,
    /// The lead-in, the entry, the lead-out and the switch-off point, when the route is the
    /// full cutting route. (Always written, even as `null`, and never flattened: the worker's
    /// binary codec needs every field in place.)
    #[serde(default)]
    pub leads: Option<PathLeads>,
}

impl ToolOnPath {
    /// The path's spans from `pierce`, without leads.
    pub fn new(pierce: Point, spans: Vec<Span>) -> ToolOnPath {
        ToolOnPath {
            pierce,
            spans,
            leads: None,
        }
    }

    /// Where the cut of the spans starts: the entry with leads, else the pierce point.
    pub fn cut_start(&self) -> Point {
        self.leads.as_ref().map_or(self.pierce, |l| l.entry)
    }

    /// Where the spans end: the exit with leads, the switch-off point without (the pierce
    /// point if empty).
    pub fn end(&self) -> Point {
        self.spans.last().map_or(self.cut_start(), |s| s.end)
    }

    /// Where the torch switches off: M* with leads, else the end of the spans.
    pub fn switch_off(&self) -> Point {
        self.leads.as_ref().map_or(self.end(), |l| l.switch_off)
    }

    /// Length of the lead-in and lead-out, mm (0 without leads).
    pub fn leads_length(&self) -> f64 {
        self.leads
            .as_ref()
            .map_or(0.0, |l| l.lead_in_length() + l.lead_out_length())
    }

    /// The overcut's spans: the path's first spans again, as far as its leads' overcut (none
    /// without leads or overcut).
    pub fn overcut_spans(&self) -> Vec<Span> {
        self.leads
            .as_ref()
            .map_or_else(Vec::new, |l| l.overcut_spans(&self.spans, 0.0))
    }

    /// The path's tabs (micro-joints), none without leads.
    pub fn tabs(&self) -> &[crate::Tab] {
        self.leads.as_ref().map_or(&[], |l| l.tabs.as_slice())
    }

    /// Tool-on length of the path, leads and overcut included, the tabs' gaps left out, mm.
    pub fn length(&self) -> f64 {
        self.spans.iter().map(|s| s.length()).sum::<f64>()
            + self.overcut_spans().iter().map(Span::length).sum::<f64>()
            + self.leads_length()
            - self.leads.as_ref().map_or(0.0, PathLeads::tab_width)
    }
}

/// A route of tool-on paths: idle from `start` to the first pierce, cut the path, idle to the
/// next pierce, …, and finally idle to `finish` if the machine must return somewhere.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PathRoute {
    /// Where the head starts.
    pub start: Point,
    /// The tool-on paths in order.
    pub paths: Vec<ToolOnPath>,
    /// Where the head ends, if the route is closed by a final idle move.
    pub finish: Option<Point>,
}

/// One way a [`PathRoute`] fails to cut a nest.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PathRouteError {
    /// A path pierces but cuts nothing.
    #[error("path {path} pierces at ({x}, {y}) but cuts nothing")]
    EmptyPath {
        /// Index of the path.
        path: usize,
        /// Pierce point, x.
        x: f64,
        /// Pierce point, y.
        y: f64,
    },
    /// A span has a non-finite coordinate or bulge.
    #[error("span {span} of path {path} has a non-finite coordinate or bulge")]
    NonFinite {
        /// Index of the path.
        path: usize,
        /// Index of the span in the path.
        span: usize,
    },
    /// A span does not start where the previous one (or the pierce, for the first) ends.
    #[error("span {span} of path {path} starts {distance} mm away from where the torch is, at ({x}, {y})")]
    NotContiguous {
        /// Index of the path.
        path: usize,
        /// Index of the span in the path.
        span: usize,
        /// How far the span's start is from the torch.
        distance: f64,
        /// Where the torch is, x.
        x: f64,
        /// Where the torch is, y.
        y: f64,
    },
    /// Part of a contour's boundary is never cut.
    #[error("{length} mm of {contour} from ({x}, {y}) are never cut")]
    Gap {
        /// The contour.
        contour: ContourRef,
        /// Where the uncut piece starts, x.
        x: f64,
        /// Its y.
        y: f64,
        /// Its length along the contour, mm.
        length: f64,
    },
    /// Part of a contour's boundary is cut more than once. A common edge cut twice is reported
    /// on both its contours, with the ends swapped when they run opposite ways.
    #[error("{length} mm of {contour} from ({x}, {y}) to ({to_x}, {to_y}) are cut more than once")]
    Overlap {
        /// The contour.
        contour: ContourRef,
        /// Where the doubly cut piece starts (in the contour's direction), x.
        x: f64,
        /// Its y.
        y: f64,
        /// Where it ends, x.
        to_x: f64,
        /// Its y.
        to_y: f64,
        /// Its length along the contour, mm.
        length: f64,
    },
    /// A tool-on piece off every contour crosses a contour: it cuts into a part or across a
    /// scrap boundary.
    #[error("span {span} of path {path} crosses {contour} at ({x}, {y}) away from every contour it follows")]
    CrossesContour {
        /// Index of the path.
        path: usize,
        /// Index of the span in the path.
        span: usize,
        /// The contour crossed.
        contour: ContourRef,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
    },
    /// A tool-on piece off every contour runs through material (inside a part).
    #[error("span {span} of path {path} cuts through material near ({x}, {y})")]
    ThroughMaterial {
        /// Index of the path.
        path: usize,
        /// Index of the span in the path.
        span: usize,
        /// A point of the piece inside a part, x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// With leads: a lead of a path breaks a rule of the model (M ∉ G_M, M* ∉ G_M*, a lead
    /// closer than kerf/2 to a contour, an entry or exit off the equidistants, chains not
    /// joined).
    #[error(transparent)]
    Lead(#[from] PathLeadError),
    /// With leads on other paths: this path has none, or was fitted under other kerf or
    /// clearances.
    #[error("path {path} has no leads, or leads under other kerf rules than the route's first")]
    LeadsMismatch {
        /// Index of the path.
        path: usize,
    },
    /// With leads: the contour has no equidistant at kerf/2, so no cut keeps the kerf off it.
    #[error("{contour} has no equidistant at half the kerf")]
    NoEquidistant {
        /// The contour.
        contour: ContourRef,
    },
    /// With leads: a tool-on span comes closer than kerf/2 to a contour, so the kerf burns
    /// into it (parts spaced narrower than the kerf, or a cut off the equidistants).
    #[error("span {span} of path {path} comes {distance} mm from {contour} at ({x}, {y}), closer than half the kerf")]
    CutTooClose {
        /// Index of the path.
        path: usize,
        /// The contour it comes too close to.
        contour: ContourRef,
        /// Index of the span in the path.
        span: usize,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
        /// The distance, mm.
        distance: f64,
    },
    /// A contour's boundary is completed before that of a contour inside it: the outer piece
    /// would drop (or move) before the inner one is cut out.
    #[error(
        "{outer} is completed (path {outer_path}) before {inner} inside it (path {inner_path})"
    )]
    PrecedenceViolated {
        /// The contained contour.
        inner: ContourRef,
        /// Path that completes it.
        inner_path: usize,
        /// The containing contour.
        outer: ContourRef,
        /// Path that completes it.
        outer_path: usize,
    },
}

/// With leads (the full cutting route): a path's lead breaks a rule of the model.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("path {path}: {problem}")]
pub struct PathLeadError {
    /// Index of the path.
    pub path: usize,
    /// The rule broken.
    pub problem: LeadProblem,
}

/// R-tree entry: the box of one span of a contour.
struct SpanEntry {
    envelope: AABB<[f64; 2]>,
    contour: usize,
    span: usize,
}

impl RTreeObject for SpanEntry {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

fn aabb(b: &BoundingBox) -> AABB<[f64; 2]> {
    AABB::from_corners([b.min.x, b.min.y], [b.max.x, b.max.y])
}

/// Where a route span lies on a contour span: `[a, b]` on the contour span, `[ra, rb]` (sorted)
/// on the route span.
struct Overlap {
    a: f64,
    b: f64,
    ra: f64,
    rb: f64,
    /// How the route span lies on the piece.
    contact: Contact,
}

/// How a cut lies on a piece of contour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Contact {
    /// It runs along the piece ([`same_carrier`]): a second such cut is an overlap.
    Along,
    /// It touches the piece within the tolerance over the piece's length (a tangent touch, or
    /// an arc bulging a rounding error across a line): the piece is cut, and a second cut of
    /// it is not reported.
    Touch,
    /// The piece is no longer than the tolerance, so which way it runs cannot be told, but it
    /// lies within the tolerance of the cut: it counts as cut (finely discretised contours,
    /// such as offsets near corners, have runs of such spans, and a run longer than the
    /// tolerance would otherwise be a gap although the cut runs along it), and neither as a
    /// second cut nor as the moment its contour completes.
    Within,
}

/// Sub-intervals of `on` that lie on `other` within `tolerance`, each with whether it is longer
/// than `tolerance`: the candidates are the ends of `on` and the projections of `other`'s ends;
/// a piece between candidates lies on `other` when its ends and three interior points do (two
/// distinct circles or lines share at most two points). A piece no longer than `tolerance` is
/// kept apart: next to `other`'s end, every point of a piece up to 4/3 of `tolerance` long is
/// within `tolerance` of `other` although the piece need not run along it.
fn pieces_on(on: &Span, other: &Span, tolerance: f64) -> Vec<(f64, f64, bool)> {
    let mut cuts = vec![0.0, 1.0];
    for p in [other.start, other.end] {
        let q = on.nearest_point(p);
        if q.distance <= tolerance {
            cuts.push(q.t);
        }
    }
    cuts.sort_by(f64::total_cmp);
    let length = on.length();
    let mut pieces: Vec<(f64, f64, bool)> = Vec::new();
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if !((b - a) * length > 0.0) {
            continue;
        }
        let long = (b - a) * length > tolerance;
        let lies = [0.0, 0.25, 0.5, 0.75, 1.0]
            .iter()
            .all(|f| other.distance_to(on.point_at(a + (b - a) * f)) <= tolerance);
        if lies {
            match pieces.last_mut() {
                Some(last) if last.1 >= a && last.2 == long => last.1 = b,
                _ => pieces.push((a, b, long)),
            }
        }
    }
    pieces
}

/// Whether two spans run along each other: both straight (a span whose sagitta is within
/// `tolerance` counts as straight), or both arcs of one circle. Distance alone cannot tell: a
/// line tangent to an arc of radius R stays within `tolerance` of it for √(2·R·tol) either side
/// of the touching point, far longer than `tolerance`. Such contact still covers the contour
/// (an arc bulging a rounding error across a line is cut by the line), but two cuts of one
/// piece are reported as an overlap only when both run along it: a tangent touch between two
/// edges that must both be cut is not a second cut of either.
///
/// An arc so short that its sagitta is within `tolerance` counts as straight beside a line,
/// but beside an arc of its own radius it runs along that arc: a pierce a micrometre before a
/// circle's vertex makes such a piece of the circle, and cutting it twice is an overlap. Its
/// centre lies far off in absolute terms, so the radius alone (precise relative to itself)
/// tells, the pieces being within `tolerance` of each other already.
fn same_carrier(a: &Span, b: &Span, tolerance: f64) -> bool {
    let straight = |s: &Span| s.is_line() || 0.5 * s.chord_length() * s.bulge.abs() <= tolerance;
    let same_radius = |short: &Span, arc: &Span| {
        !short.is_line() && (short.radius() - arc.radius()).abs() <= tolerance + 1e-6 * arc.radius()
    };
    match (straight(a), straight(b)) {
        (true, true) => true,
        (false, false) => match (a.centre(), b.centre()) {
            (Some(ca), Some(cb)) => {
                ca.distance(cb) <= tolerance && (a.radius() - b.radius()).abs() <= tolerance
            }
            _ => false,
        },
        (true, false) => same_radius(a, b),
        (false, true) => same_radius(b, a),
    }
}

fn overlaps(contour_span: &Span, route_span: &Span, tolerance: f64) -> Vec<Overlap> {
    let along = same_carrier(contour_span, route_span, tolerance);
    pieces_on(contour_span, route_span, tolerance)
        .into_iter()
        .map(|(a, b, long)| {
            // The nearest point's parameter (clamped, compared with the span's ends), not
            // `Span::parameter_of`: that one once wrapped a point at an arc's start to 2π/φ.
            let ta = route_span.nearest_point(contour_span.point_at(a)).t;
            let tb = route_span.nearest_point(contour_span.point_at(b)).t;
            Overlap {
                a,
                b,
                ra: ta.min(tb),
                rb: ta.max(tb),
                contact: match (long, along) {
                    (false, _) => Contact::Within,
                    (true, true) => Contact::Along,
                    (true, false) => Contact::Touch,
                },
            }
        })
        .collect()
}

/// A piece `(a, b)` of a contour span cut at a moment, and how the cut lies on it.
type Coverage = (f64, f64, Moment, Contact);

/// When a piece of contour is cut: path, span within the path, and parameter on that span.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Moment {
    path: usize,
    span: usize,
    t: f64,
}

impl Moment {
    fn is_after(&self, other: &Moment) -> bool {
        (self.path, self.span) > (other.path, other.span)
            || ((self.path, self.span) == (other.path, other.span) && self.t > other.t + 1e-9)
    }
}

impl PathRoute {
    /// The route of the same cuts as `route`: each step's contour opened at its pierce point
    /// and cut round in its own direction; a step entered by a tool-on link continues the
    /// previous path with the link's straight pieces instead of starting a new one.
    ///
    /// Fails when a step names a contour the nest does not have.
    pub fn from_route(route: &Route, nest: &Nest) -> Result<PathRoute, RouteError> {
        let mut paths: Vec<ToolOnPath> = Vec::new();
        for (step, cut) in route.steps.iter().enumerate() {
            let contour = nest
                .contour(cut.contour)
                .ok_or(RouteError::UnknownContour {
                    step,
                    contour: cut.contour,
                })?;
            let linked = match (route.link_path(step), paths.last_mut()) {
                (Some(link), Some(path)) => {
                    for w in link.windows(2) {
                        if w[0] != w[1] {
                            path.spans.push(Span::line(w[0], w[1]));
                        }
                    }
                    true
                }
                _ => false,
            };
            if !linked {
                paths.push(ToolOnPath::new(cut.pierce_point, Vec::new()));
            }
            let path = paths.last_mut().expect("a path was just ensured");
            let Some(entry) = contour.nearest_point(cut.pierce_point) else {
                continue;
            };
            let spans: Vec<Span> = contour.spans().collect();
            let (i, t) = (entry.position.span, entry.position.t);
            // The contour opened at the entry, which is the pierce point itself for a valid
            // route; pieces of zero length at a vertex are dropped.
            let mut opened = vec![spans[i].sub_span(t, 1.0)];
            opened.extend((1..spans.len()).map(|k| spans[(i + k) % spans.len()]));
            opened.push(spans[i].sub_span(0.0, t));
            let mut at = path.end();
            for mut s in opened {
                if s.length() <= 1e-12 {
                    continue;
                }
                s.start = at; // exact contiguity: the split point is computed twice
                at = s.end;
                path.spans.push(s);
            }
        }
        Ok(PathRoute {
            start: route.start,
            paths,
            finish: route.finish,
        })
    }

    /// The straight idle moves `(from, to)`: start → first pierce, the crossings of each
    /// path's tabs, each path's end → next pierce, last end → finish.
    pub fn idle_moves(&self) -> Vec<(Point, Point)> {
        let mut moves = Vec::with_capacity(self.paths.len() + 1);
        let mut at = self.start;
        for p in &self.paths {
            moves.push((at, p.pierce));
            // The head crosses each tab's gap with the torch off.
            moves.extend(p.tabs().iter().map(|tab| (tab.from, tab.to)));
            at = p.switch_off();
        }
        if let Some(finish) = self.finish {
            moves.push((at, finish));
        }
        moves
    }

    /// Total idle length, mm.
    pub fn idle_length(&self) -> f64 {
        self.idle_moves().iter().map(|(a, b)| a.distance(*b)).sum()
    }

    /// Total tool-on length (contours, pieces through scrap and leads alike), mm.
    pub fn cut_length(&self) -> f64 {
        self.paths.iter().map(|p| p.length()).sum()
    }

    /// Number of pierces: one per path, and one after every tab.
    pub fn pierce_count(&self) -> usize {
        self.paths.len() + self.paths.iter().map(|p| p.tabs().len()).sum::<usize>()
    }

    /// The pierces of [`PathRoute::pierce_count`] made at the sheet's edge (edge-pierced
    /// paths, priced at the machine's edge-pierce time).
    pub fn edge_pierce_count(&self) -> usize {
        self.paths
            .iter()
            .filter(|p| p.leads.as_ref().is_some_and(|l| l.edge_pierce))
            .count()
    }

    /// Machining time, seconds (formula 1.2).
    pub fn time(&self, machine: &MachineParameters) -> f64 {
        machine.time(self.cut_length(), self.idle_length(), self.pierce_count())
    }

    /// Cost (formula 1.3).
    pub fn cost(&self, machine: &MachineParameters) -> f64 {
        machine.cost(self.cut_length(), self.idle_length(), self.pierce_count())
    }

    /// Every way the route fails to cut `nest` (empty when it is valid), with `tolerance` mm
    /// for points to coincide and for pieces to count:
    /// - every path cuts something, its spans finite and end to end from the pierce point;
    /// - every contour's boundary covered exactly once by measure: gaps and overlaps longer
    ///   than `tolerance` are reported with the contour and where they start;
    /// - every tool-on piece that lies on no contour crosses no contour and lies in scrap (an
    ///   even number of part contours around it: outside every part, or in a hole);
    /// - when a contour's boundary is completed, every contour inside it is already complete.
    ///
    /// With leads on its paths (the full cutting route) the cut is checked against the nest of
    /// equidistants at kerf/2 ([`LeadFitter::kerf_nest`]: every contour's equidistant covered
    /// exactly once, precedence, pieces through scrap) and every path's leads against the
    /// nest ([`LeadFitter::path_lead_problems`]: M ∈ G_M, M* ∈ G_M*, leads at least kerf/2
    /// from every contour, entry and exit on the equidistants); every tool-on span keeps
    /// kerf/2 from every contour; every contour has an equidistant; every path has leads under
    /// the same rules.
    pub fn problems(&self, nest: &Nest, tolerance: f64) -> Vec<PathRouteError> {
        let Some(rules) = self
            .paths
            .iter()
            .find_map(|p| p.leads.as_ref())
            .map(PathLeads::rules)
        else {
            return self.cut_problems(nest, tolerance);
        };
        let forest = nest.containment_forest();
        let fitter = LeadFitter::with_forest(nest, &forest, rules);
        let mut problems: Vec<PathRouteError> = nest
            .contour_refs()
            .filter(|&r| fitter.equidistant(r).is_err())
            .map(|contour| PathRouteError::NoEquidistant { contour })
            .collect();
        problems.extend(self.cut_problems(&fitter.kerf_nest(), tolerance));
        for (p, path) in self.paths.iter().enumerate() {
            match &path.leads {
                Some(leads) if leads.rules() == rules => problems.extend(
                    fitter
                        .path_lead_problems(path, leads, tolerance)
                        .into_iter()
                        .map(|problem| PathLeadError { path: p, problem }.into()),
                ),
                _ => problems.push(PathRouteError::LeadsMismatch { path: p }),
            }
        }
        problems.extend(self.clearance_problems(nest, rules.kerf / 2.0, tolerance));
        problems
    }

    /// Every tool-on span (leads aside: their checker samples them) closer than `half` less
    /// `tolerance` to a contour of `nest`, one per path: a cut whose kerf burns into a part.
    /// The same test as [`Route::problems`]'s on each step's cut ([`ContourSpans::too_close`]).
    pub fn clearance_problems(
        &self,
        nest: &Nest,
        half: f64,
        tolerance: f64,
    ) -> Vec<PathRouteError> {
        let index = ContourSpans::new(nest);
        let mut problems = Vec::new();
        for (p, path) in self.paths.iter().enumerate() {
            let first = path.spans.iter().enumerate().find_map(|(s, span)| {
                index
                    .too_close(span, half, tolerance)
                    .next()
                    .map(|hit| (s, hit))
            });
            if let Some((s, hit)) = first {
                problems.push(PathRouteError::CutTooClose {
                    path: p,
                    contour: hit.contour,
                    span: s,
                    x: hit.at.x,
                    y: hit.at.y,
                    distance: hit.distance,
                });
            }
        }
        problems
    }

    /// The checks of [`PathRoute::problems`] on the cut itself (the spans against `nest`'s
    /// contours: contiguity, coverage, pieces through scrap, precedence).
    fn cut_problems(&self, nest: &Nest, tolerance: f64) -> Vec<PathRouteError> {
        let mut problems = Vec::new();
        let refs: Vec<ContourRef> = nest.contour_refs().collect();
        let contours: Vec<Vec<Span>> = refs
            .iter()
            .map(|&r| nest.contour(r).map_or(Vec::new(), |c| c.spans().collect()))
            .collect();
        let mut entries = Vec::new();
        for (c, spans) in contours.iter().enumerate() {
            for (s, span) in spans.iter().enumerate() {
                entries.push(SpanEntry {
                    envelope: aabb(&span.bounding_box().expanded(tolerance)),
                    contour: c,
                    span: s,
                });
            }
        }
        let span_tree = RTree::bulk_load(entries);
        // Per contour and span: covered intervals on the contour span with their moment.
        let mut covered: Vec<Vec<Vec<Coverage>>> = contours
            .iter()
            .map(|spans| vec![Vec::new(); spans.len()])
            .collect();

        for (p, path) in self.paths.iter().enumerate() {
            if path.spans.is_empty() {
                problems.push(PathRouteError::EmptyPath {
                    path: p,
                    x: path.pierce.x,
                    y: path.pierce.y,
                });
                continue;
            }
            let mut at = path.cut_start();
            for (s, span) in path.spans.iter().enumerate() {
                if !(span.start.is_finite() && span.end.is_finite() && span.bulge.is_finite()) {
                    problems.push(PathRouteError::NonFinite { path: p, span: s });
                    at = span.end;
                    continue;
                }
                let distance = at.distance(span.start);
                if !(distance <= tolerance) {
                    problems.push(PathRouteError::NotContiguous {
                        path: p,
                        span: s,
                        distance,
                        x: at.x,
                        y: at.y,
                    });
                }
                at = span.end;
                let reach = aabb(&span.bounding_box().expanded(tolerance));
                let mut on_route: Vec<(f64, f64)> = Vec::new();
                for e in span_tree.locate_in_envelope_intersecting(&reach) {
                    let contour_span = &contours[e.contour][e.span];
                    for o in overlaps(contour_span, span, tolerance) {
                        covered[e.contour][e.span].push((
                            o.a,
                            o.b,
                            Moment {
                                path: p,
                                span: s,
                                t: o.rb,
                            },
                            o.contact,
                        ));
                        on_route.push((o.ra, o.rb));
                    }
                }
                self.check_off_contour(
                    nest,
                    &refs,
                    &span_tree,
                    &contours,
                    p,
                    s,
                    span,
                    on_route,
                    tolerance,
                    &mut problems,
                );
            }
        }

        let mut completed: Vec<Option<Moment>> = vec![None; refs.len()];
        for (c, spans) in contours.iter().enumerate() {
            let lengths: Vec<f64> = spans.iter().map(|s| s.length()).collect();
            let mut intervals: Vec<(f64, f64, Moment, Point, Contact)> = Vec::new();
            let mut offset = 0.0;
            for (s, pieces) in covered[c].iter().enumerate() {
                for &(a, b, m, contact) in pieces {
                    intervals.push((
                        offset + a * lengths[s],
                        offset + b * lengths[s],
                        m,
                        spans[s].point_at(a),
                        contact,
                    ));
                }
                offset += lengths[s];
            }
            let perimeter = offset;
            intervals.sort_by(|x, y| x.0.total_cmp(&y.0));
            let point_at_length = |l: f64| {
                nest.contour(refs[c])
                    .and_then(|k| k.point_at_length(l))
                    .unwrap_or_default()
            };
            let (mut reach, mut along_reach) = (0.0, 0.0);
            let mut last: Option<Moment> = None;
            for &(a, b, m, pa, contact) in &intervals {
                if a - reach > tolerance {
                    let p = point_at_length(reach);
                    problems.push(PathRouteError::Gap {
                        contour: refs[c],
                        x: p.x,
                        y: p.y,
                        length: a - reach,
                    });
                }
                if contact == Contact::Along {
                    if along_reach - a > tolerance {
                        let to = point_at_length(f64::min(along_reach, b));
                        problems.push(PathRouteError::Overlap {
                            contour: refs[c],
                            x: pa.x,
                            y: pa.y,
                            to_x: to.x,
                            to_y: to.y,
                            length: f64::min(along_reach, b) - a,
                        });
                    }
                    along_reach = f64::max(along_reach, b);
                }
                reach = f64::max(reach, b);
                if contact != Contact::Within && last.is_none_or(|l| m.is_after(&l)) {
                    last = Some(m);
                }
            }
            if perimeter - reach > tolerance {
                let p = point_at_length(reach);
                problems.push(PathRouteError::Gap {
                    contour: refs[c],
                    x: p.x,
                    y: p.y,
                    length: perimeter - reach,
                });
            }
            completed[c] = last;
        }

        let forest = ContainmentForest::new(nest);
        for (inner, outer) in forest.all_precedence_pairs() {
            let (Some(i), Some(o)) = (forest.index_of(inner), forest.index_of(outer)) else {
                continue;
            };
            if let (Some(mi), Some(mo)) = (completed[i], completed[o]) {
                if mi.is_after(&mo) {
                    problems.push(PathRouteError::PrecedenceViolated {
                        inner,
                        inner_path: mi.path,
                        outer,
                        outer_path: mo.path,
                    });
                }
            }
        }
        problems
    }

    /// The pieces of `span` outside `on_route` (the parts lying on contours) must cross no
    /// contour and lie in scrap.
    #[allow(clippy::too_many_arguments)]
    fn check_off_contour(
        &self,
        nest: &Nest,
        refs: &[ContourRef],
        span_tree: &RTree<SpanEntry>,
        contours: &[Vec<Span>],
        path: usize,
        s: usize,
        span: &Span,
        mut on_route: Vec<(f64, f64)>,
        tolerance: f64,
        problems: &mut Vec<PathRouteError>,
    ) {
        on_route.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut free = Vec::new();
        let mut reach = 0.0;
        for (a, b) in on_route {
            if a > reach {
                free.push((reach, a));
            }
            reach = f64::max(reach, b);
        }
        if reach < 1.0 {
            free.push((reach, 1.0));
        }
        let length = span.length();
        for (a, b) in free {
            if !((b - a) * length > tolerance) {
                continue;
            }
            let piece = span.sub_span(a, b);
            let (first, last) = (piece.start, piece.end);
            let reach = aabb(&piece.bounding_box().expanded(tolerance));
            for e in span_tree.locate_in_envelope_intersecting(&reach) {
                let crossing = contours[e.contour][e.span]
                    .intersections(&piece)
                    .into_iter()
                    .find(|x| {
                        x.point.distance(first) > tolerance && x.point.distance(last) > tolerance
                    });
                if let Some(x) = crossing {
                    problems.push(PathRouteError::CrossesContour {
                        path,
                        span: s,
                        contour: refs[e.contour],
                        x: x.point.x,
                        y: x.point.y,
                    });
                    return;
                }
            }
            // No crossing inside the piece: one interior point tells on which side of every
            // contour the whole piece lies.
            let probe = piece.point_at(0.5);
            let around = refs
                .iter()
                .filter(|&&r| nest.contour(r).is_some_and(|c| c.contains(probe)))
                .count();
            if around % 2 == 1 {
                problems.push(PathRouteError::ThroughMaterial {
                    path,
                    span: s,
                    x: probe.x,
                    y: probe.y,
                });
                return;
            }
        }
    }

    /// Checks the route against the nest (see [`PathRoute::problems`]) and reports the first
    /// failure.
    pub fn validate(&self, nest: &Nest, tolerance: f64) -> Result<(), PathRouteError> {
        match self.problems(nest, tolerance).into_iter().next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Contour, CutStep, Entry, Part, Toolpath, Vertex};
    use proptest::prelude::*;

    const TOL: f64 = 1e-7;

    fn part(contours: Vec<Contour>) -> Part {
        Part {
            name: String::new(),
            contours,
        }
    }

    fn p(x: f64, y: f64) -> Point {
        Point::new(x, y)
    }

    /// The step that pierces contour `contour` of part `part` at `at`.
    fn step(part: usize, contour: usize, at: Point) -> CutStep {
        CutStep::pierced(ContourRef { part, contour }, at)
    }

    fn polyline(points: &[(f64, f64)]) -> ToolOnPath {
        ToolOnPath {
            pierce: p(points[0].0, points[0].1),
            spans: points
                .windows(2)
                .map(|w| Span::line(p(w[0].0, w[0].1), p(w[1].0, w[1].1)))
                .collect(),
            leads: None,
        }
    }

    /// Two 10 × 10 squares sharing the edge x = 10.
    fn pair() -> Nest {
        Nest {
            sheet: None,
            parts: vec![
                part(vec![Contour::rectangle(0.0, 0.0, 10.0, 10.0)]),
                part(vec![Contour::rectangle(10.0, 0.0, 20.0, 10.0)]),
            ],
        }
    }

    /// A 100 × 100 plate with a 60 × 60 hole holding a 20 × 20 part.
    fn nested() -> Nest {
        Nest {
            sheet: None,
            parts: vec![
                part(vec![
                    Contour::rectangle(0.0, 0.0, 100.0, 100.0),
                    Contour::rectangle(20.0, 20.0, 80.0, 80.0).reversed(),
                ]),
                part(vec![Contour::rectangle(40.0, 40.0, 60.0, 60.0)]),
            ],
        }
    }

    #[test]
    fn a_route_converts_to_a_valid_path_route_with_the_same_numbers() {
        let nest = nested();
        let (plate, hole, inner) = (
            ContourRef {
                part: 0,
                contour: 0,
            },
            ContourRef {
                part: 0,
                contour: 1,
            },
            ContourRef {
                part: 1,
                contour: 0,
            },
        );
        let route = Route {
            start: p(-10.0, -10.0),
            steps: vec![
                CutStep::pierced(inner, p(45.0, 40.0)),
                CutStep::pierced(hole, p(20.0, 33.0)),
                CutStep::pierced(plate, p(0.0, 0.0)),
            ],
            finish: Some(p(-10.0, -10.0)),
        };
        route.validate(&nest, TOL).unwrap();
        let paths = PathRoute::from_route(&route, &nest).unwrap();
        assert_eq!(paths.problems(&nest, TOL), vec![]);
        assert_eq!(paths.pierce_count(), 3);
        assert!((paths.cut_length() - route.cut_length(&nest)).abs() < 1e-9);
        assert!((paths.idle_length() - route.idle_length()).abs() < 1e-9);
        let machine = MachineParameters::default();
        assert!((paths.time(&machine) - route.time(&nest, &machine)).abs() < 1e-9);
        assert!((paths.cost(&machine) - route.cost(&nest, &machine)).abs() < 1e-12);
        let toolpath = Toolpath::from_path_route(&paths);
        assert!((toolpath.cut_length() - paths.cut_length()).abs() < 1e-9);
        assert!((toolpath.idle_length() - paths.idle_length()).abs() < 1e-9);
        assert_eq!(toolpath.pierce_count(), 3);
        let text = serde_json::to_string(&paths).unwrap();
        assert_eq!(serde_json::from_str::<PathRoute>(&text).unwrap(), paths);
    }

    #[test]
    fn precedence_is_checked_when_a_boundary_completes() {
        let nest = nested();
        let route = Route {
            start: p(0.0, 0.0),
            steps: vec![
                step(1, 0, p(40.0, 40.0)),
                step(0, 0, p(0.0, 0.0)),
                step(0, 1, p(20.0, 20.0)),
            ],
            finish: None,
        };
        let paths = PathRoute::from_route(&route, &nest).unwrap();
        let problems = paths.problems(&nest, TOL);
        assert_eq!(
            problems,
            vec![PathRouteError::PrecedenceViolated {
                inner: ContourRef {
                    part: 0,
                    contour: 1
                },
                inner_path: 2,
                outer: ContourRef {
                    part: 0,
                    contour: 0
                },
                outer_path: 1,
            }]
        );
        // Starting the plate before the hole is fine as long as it is completed after it:
        // cut three sides of the plate, then the hole, then the last side in a new path.
        let mut good = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![polyline(&[
                (40.0, 40.0),
                (40.0, 60.0),
                (60.0, 60.0),
                (60.0, 40.0),
                (40.0, 40.0),
            ])],
            finish: None,
        };
        good.paths.push(polyline(&[
            (0.0, 0.0),
            (0.0, 100.0),
            (100.0, 100.0),
            (100.0, 0.0),
        ]));
        good.paths.push(polyline(&[
            (20.0, 20.0),
            (80.0, 20.0),
            (80.0, 80.0),
            (20.0, 80.0),
            (20.0, 20.0),
        ]));
        good.paths.push(polyline(&[(100.0, 0.0), (0.0, 0.0)]));
        assert_eq!(good.problems(&nest, TOL), vec![]);
        assert_eq!(good.pierce_count(), 4);
    }

    #[test]
    fn a_contour_opened_just_past_a_vertex_is_cut_once() {
        // The last piece (vertex → pierce) is 1.3 tolerances long: its interior lies within
        // the tolerance of the first span's line extension, yet it is not cut twice.
        let tolerance = 0.01;
        let nest = Nest {
            sheet: None,
            parts: vec![part(vec![Contour::rectangle(0.0, 0.0, 10.0, 10.0)])],
        };
        let pierce = 1.3 * tolerance;
        let route = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![polyline(&[
                (pierce, 10.0),
                (10.0, 10.0),
                (10.0, 0.0),
                (0.0, 0.0),
                (0.0, 10.0),
                (pierce, 10.0),
            ])],
            finish: None,
        };
        assert_eq!(route.problems(&nest, tolerance), vec![]);
        // Cutting that short piece a second time is still an overlap.
        let mut twice = route.clone();
        twice.paths[0]
            .spans
            .push(Span::line(p(pierce, 10.0), p(0.0, 10.0)));
        twice.paths[0]
            .spans
            .push(Span::line(p(0.0, 10.0), p(pierce, 10.0)));
        assert!(twice
            .problems(&nest, tolerance)
            .iter()
            .any(|e| matches!(e, PathRouteError::Overlap { .. })));
    }

    #[test]
    fn a_common_edge_is_cut_once_and_cutting_it_twice_is_an_overlap() {
        let nest = pair();
        // One path: the outline of both squares, then the common edge.
        let once = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![polyline(&[
                (10.0, 0.0),
                (0.0, 0.0),
                (0.0, 10.0),
                (20.0, 10.0),
                (20.0, 0.0),
                (10.0, 0.0),
                (10.0, 10.0),
            ])],
            finish: None,
        };
        assert_eq!(once.problems(&nest, TOL), vec![]);
        assert!((once.cut_length() - 70.0).abs() < 1e-12);
        // Each square cut whole: the common edge twice.
        let route = Route {
            start: p(0.0, 0.0),
            steps: vec![step(0, 0, p(0.0, 0.0)), step(1, 0, p(10.0, 0.0))],
            finish: None,
        };
        let twice = PathRoute::from_route(&route, &nest).unwrap();
        let problems = twice.problems(&nest, TOL);
        assert_eq!(problems.len(), 2, "{problems:?}"); // the edge is doubled on both contours
        for e in &problems {
            let PathRouteError::Overlap { length, x, .. } = e else {
                panic!("expected an overlap, got {e}");
            };
            assert!((length - 10.0).abs() < 1e-9 && (x - 10.0).abs() < 1e-9);
        }
    }

    /// A clockwise 10 × 10 square whose top edge starts with a run of `n` collinear spans of
    /// `step` mm each (finely discretised geometry: offsets give such runs near corners).
    fn square_with_fine_run(n: usize, step: f64) -> Nest {
        let mut vertices = vec![Vertex::line(0.0, 0.0)];
        vertices.extend((0..n).map(|i| Vertex::line(i as f64 * step, 10.0)));
        vertices.push(Vertex::line(10.0, 10.0));
        vertices.push(Vertex::line(10.0, 0.0));
        Nest {
            sheet: None,
            parts: vec![part(vec![Contour::new(vertices)])],
        }
    }

    #[test]
    fn runs_of_spans_shorter_than_the_tolerance_are_covered_by_the_cut_along_them() {
        // 0.004 mm of spans of 0.0004 mm each, checked at 0.001 mm: no single span is long
        // enough to tell its direction, but every one lies on the cut. The contour cut as
        // itself, and cut with the run as one straight span, cut it exactly once.
        let tolerance = 1e-3;
        let nest = square_with_fine_run(11, 4e-4);
        let itself = PathRoute::from_route(
            &Route {
                start: p(0.0, 0.0),
                steps: vec![step(0, 0, p(0.0, 0.0))],
                finish: None,
            },
            &nest,
        )
        .unwrap();
        assert_eq!(itself.problems(&nest, tolerance), vec![]);
        let merged = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![polyline(&[
                (0.0, 0.0),
                (0.0, 10.0),
                (0.004, 10.0),
                (10.0, 10.0),
                (10.0, 0.0),
                (0.0, 0.0),
            ])],
            finish: None,
        };
        assert_eq!(merged.problems(&nest, tolerance), vec![]);
    }

    #[test]
    fn a_run_of_short_spans_left_uncut_is_a_gap() {
        // The same run, with the cut stopping before it and starting again after it: the
        // uncut 0.004 mm (less what lies within the tolerance of the two cut ends) is a gap.
        let tolerance = 1e-3;
        let nest = square_with_fine_run(11, 4e-4);
        let route = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![polyline(&[
                (0.004, 10.0),
                (10.0, 10.0),
                (10.0, 0.0),
                (0.0, 0.0),
                (0.0, 10.0),
            ])],
            finish: None,
        };
        // One path from the run's end round to its start: the run itself is never cut.
        let problems = route.problems(&nest, tolerance);
        assert!(
            problems.iter().any(|e| matches!(e, PathRouteError::Gap { length, .. } if *length >= 0.004 - 2.0 * tolerance - 1e-9)),
            "{problems:?}"
        );
    }

    #[test]
    fn gaps_breaks_and_empty_paths_are_reported() {
        let nest = pair();
        let route = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![
                polyline(&[
                    (10.0, 0.0),
                    (0.0, 0.0),
                    (0.0, 10.0),
                    (20.0, 10.0),
                    (20.0, 0.0),
                ]),
                ToolOnPath {
                    pierce: p(10.0, 0.0),
                    // starts 1 mm off the pierce point
                    spans: vec![
                        Span::line(p(11.0, 0.0), p(10.0, 0.0)),
                        Span::line(p(10.0, 0.0), p(10.0, 10.0)),
                    ],
                    leads: None,
                },
                ToolOnPath {
                    pierce: p(5.0, 5.0),
                    spans: vec![],
                    leads: None,
                },
            ],
            finish: None,
        };
        let problems = route.problems(&nest, TOL);
        assert!(problems.contains(&PathRouteError::EmptyPath {
            path: 2,
            x: 5.0,
            y: 5.0
        }));
        assert!(problems.iter().any(|e| matches!(e, PathRouteError::NotContiguous { path: 1, span: 0, distance, .. } if (distance - 1.0).abs() < 1e-12)));
        // 9 mm of the bottom of the right square are never cut.
        assert!(problems.iter().any(|e| matches!(e, PathRouteError::Gap { contour: ContourRef { part: 1, contour: 0 }, length, .. } if (length - 9.0).abs() < 1e-9)));
    }

    #[test]
    fn tool_on_pieces_must_stay_in_scrap() {
        let nest = pair();
        let whole = |c: usize, pierce: Point| {
            PathRoute::from_route(
                &Route {
                    start: p(0.0, 0.0),
                    steps: vec![CutStep::pierced(
                        ContourRef {
                            part: c,
                            contour: 0,
                        },
                        pierce,
                    )],
                    finish: None,
                },
                &nest,
            )
            .unwrap()
            .paths
            .remove(0)
        };
        // Left square, then a piece through the sheet around to the right square: fine.
        let mut through_scrap = whole(0, p(0.0, 0.0));
        through_scrap
            .spans
            .push(Span::line(p(0.0, 0.0), p(0.0, -5.0)));
        through_scrap
            .spans
            .push(Span::line(p(0.0, -5.0), p(20.0, -5.0)));
        through_scrap
            .spans
            .push(Span::line(p(20.0, -5.0), p(20.0, 0.0)));
        let right: Vec<Span> = vec![
            Span::line(p(20.0, 0.0), p(20.0, 10.0)),
            Span::line(p(20.0, 10.0), p(10.0, 10.0)),
            Span::line(p(10.0, 0.0), p(20.0, 0.0)),
        ];
        through_scrap.spans.extend(right.iter().take(2));
        let mut route = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![through_scrap, polyline(&[(10.0, 0.0), (20.0, 0.0)])],
            finish: None,
        };
        assert_eq!(route.problems(&nest, TOL), vec![]);
        // A piece through the left square.
        route.paths[1] = polyline(&[(5.0, 0.0), (5.0, 5.0), (10.0, 5.0)]);
        let problems = route.problems(&nest, TOL);
        assert!(
            problems
                .iter()
                .any(|e| matches!(e, PathRouteError::ThroughMaterial { path: 1, .. })),
            "{problems:?}"
        );
        // A piece across the right square's boundary.
        route.paths[1] = polyline(&[(10.0, 0.0), (20.0, 0.0), (25.0, 5.0), (15.0, 5.0)]);
        let problems = route.problems(&nest, TOL);
        assert!(
            problems.iter().any(|e| matches!(
                e,
                PathRouteError::CrossesContour {
                    path: 1,
                    span: 2,
                    ..
                }
            )),
            "{problems:?}"
        );
        // Chain-cutting links become tool-on pieces of the previous path.
        let linked = Route {
            start: p(0.0, 0.0),
            steps: vec![
                step(0, 0, p(0.0, 0.0)),
                CutStep {
                    contour: ContourRef {
                        part: 1,
                        contour: 0,
                    },
                    pierce_point: p(20.0, 0.0),
                    entry: Entry::Link(vec![p(0.0, -5.0), p(20.0, -5.0)]),
                    leads: None,
                },
            ],
            finish: None,
        };
        let paths = PathRoute::from_route(&linked, &nest).unwrap();
        assert_eq!(paths.pierce_count(), 1);
        assert!((paths.cut_length() - linked.cut_length(&nest)).abs() < 1e-9);
        // Both squares whole: the common edge is cut twice, and nothing else is wrong.
        let problems = paths.problems(&nest, TOL);
        assert!(
            problems
                .iter()
                .all(|e| matches!(e, PathRouteError::Overlap { .. })),
            "{problems:?}"
        );
    }

    #[test]
    fn arcs_are_covered_by_measure() {
        // A round part cut in two halves from two pierces, the second half in reverse.
        let nest = Nest {
            sheet: None,
            parts: vec![part(vec![Contour::circle(p(0.0, 0.0), 5.0, true)])],
        };
        let c = nest.parts[0].contours[0].clone();
        let spans: Vec<Span> = c.spans().collect();
        assert_eq!(spans.len(), 2);
        let (first, second) = spans[0].split_at(0.3);
        let route = PathRoute {
            start: p(0.0, 0.0),
            paths: vec![
                ToolOnPath {
                    pierce: spans[0].start,
                    spans: vec![first],
                    leads: None,
                },
                ToolOnPath {
                    pierce: spans[1].end,
                    spans: vec![spans[1].reversed(), second.reversed()],
                    leads: None,
                },
            ],
            finish: None,
        };
        assert_eq!(route.problems(&nest, TOL), vec![]);
        assert!((route.cut_length() - c.perimeter()).abs() < 1e-9);
        // Dropping the first path leaves 30 % of a semicircle uncut.
        let mut short = route.clone();
        short.paths.remove(0);
        let problems = short.problems(&nest, TOL);
        assert!(
            matches!(problems[..], [PathRouteError::Gap { length, .. }] if (length - first.length()).abs() < 1e-6),
            "{problems:?}"
        );
    }

    /// A ring (plate with a round hole) opened anywhere: the pieces of the semicircles that
    /// start mid-arc sweep more than a radian, where mapping a point at an arc's start back to
    /// its parameter once wrapped round to 2π/φ and made covered arc look uncovered.
    #[test]
    fn contours_of_arcs_opened_anywhere_are_covered() {
        let nest = Nest {
            sheet: None,
            parts: vec![part(vec![
                Contour::circle(p(0.0, 0.0), 63.0, true),
                Contour::circle(p(5.0, 0.0), 20.0, false),
            ])],
        };
        for k in 1..100 {
            let f = k as f64 / 100.0;
            let steps = [(1, f), (0, 1.0 - f)]
                .iter()
                .map(|&(c, f)| {
                    let r = ContourRef {
                        part: 0,
                        contour: c,
                    };
                    let contour = nest.contour(r).unwrap();
                    CutStep::pierced(r, contour.point_at_length(f * contour.perimeter()).unwrap())
                })
                .collect();
            let route = Route {
                start: p(0.0, -100.0),
                steps,
                finish: None,
            };
            let paths = PathRoute::from_route(&route, &nest).unwrap();
            assert_eq!(paths.problems(&nest, 1e-7), vec![], "f = {f}");
        }
    }

    /// The property below's case (`fraction = 0.99997694…`, path 5): a pierce 1.45 µm before a
    /// circle's closing vertex makes the path's first span a 1.45 µm arc of the circle, whose
    /// sagitta is below the tolerance. Cut again as its own path, it must be an overlap.
    #[test]
    fn a_tiny_arc_of_a_circle_cut_twice_is_an_overlap() {
        let nest = Nest {
            sheet: None,
            parts: vec![part(vec![Contour::circle(p(60.0, 0.0), 10.0, true)])],
        };
        let r = ContourRef {
            part: 0,
            contour: 0,
        };
        let c = nest.contour(r).unwrap();
        let pierce = c
            .point_at_length(0.9999769492703391 * c.perimeter())
            .unwrap();
        let route = Route {
            start: p(0.0, -50.0),
            steps: vec![CutStep::pierced(r, pierce)],
            finish: None,
        };
        let route = PathRoute::from_route(&route, &nest).unwrap();
        assert_eq!(route.problems(&nest, TOL), vec![]);
        let victim = route.paths[0].spans[0];
        assert!(
            victim.length() > 1e-3 && victim.length() < 2e-3,
            "{victim:?}"
        );
        let mut repeated = route.clone();
        repeated.paths.insert(
            0,
            ToolOnPath {
                pierce: victim.start,
                spans: vec![victim],
                leads: None,
            },
        );
        let problems = repeated.problems(&nest, TOL);
        let doubled: f64 = problems
            .iter()
            .map(|e| match e {
                PathRouteError::Overlap { length, .. } => *length,
                _ => f64::NAN,
            })
            .sum();
        assert!((doubled - victim.length()).abs() < 1e-6, "{problems:?}");
    }

    proptest! {
        /// Damage to a valid route never goes unnoticed: a span left out leaves a gap (or
        /// breaks its path), a span cut again from a new pierce is an overlap. Half of the
        /// pierces lie within 0.01 % of the perimeter of a contour's closing vertex, where the
        /// path's first or last span is tiny.
        #[test]
        fn dropped_or_repeated_spans_are_found(path in 0..6usize, pick in 0.0..1.0f64, fraction in prop_oneof![2 => 0.0..1.0f64, 1 => 0.9999..1.0f64, 1 => 0.0..0.0001f64]) {
            let nest = Nest {
                sheet: None,
                parts: (0..6).map(|i| part(vec![Contour::circle(p(i as f64 * 30.0, 0.0), 10.0, true), Contour::rectangle(i as f64 * 30.0 - 5.0, -5.0, i as f64 * 30.0 + 5.0, 3.0).reversed()])).collect(),
            };
            let steps = (0..6).flat_map(|i| {
                let hole = ContourRef { part: i, contour: 1 };
                let outer = ContourRef { part: i, contour: 0 };
                [hole, outer].map(|r| {
                    let c = nest.contour(r).unwrap();
                    CutStep::pierced(r, c.point_at_length(fraction * c.perimeter()).unwrap())
                })
            }).collect();
            let route = PathRoute::from_route(&Route { start: p(0.0, -50.0), steps, finish: None }, &nest).unwrap();
            prop_assert_eq!(route.problems(&nest, TOL), vec![]);
            let spans = &route.paths[path].spans;
            let k = ((pick * spans.len() as f64) as usize).min(spans.len() - 1);
            let victim = spans[k];
            prop_assume!(victim.length() > 1e-3);
            let mut dropped = route.clone();
            dropped.paths[path].spans.remove(k);
            let problems = dropped.problems(&nest, TOL);
            prop_assert!(problems.iter().any(|e| matches!(e, PathRouteError::Gap { length, .. } if (length - victim.length()).abs() < 1e-6)), "{:?}", problems);
            let mut repeated = route.clone();
            // First, so that no contour's completion moves.
            repeated.paths.insert(0, ToolOnPath { pierce: victim.start, spans: vec![victim], leads: None });
            let problems = repeated.problems(&nest, TOL);
            prop_assert!(problems.iter().all(|e| matches!(e, PathRouteError::Overlap { .. })), "{:?}", problems);
            let doubled: f64 = problems.iter().map(|e| match e { PathRouteError::Overlap { length, .. } => *length, _ => 0.0 }).sum();
            prop_assert!((doubled - victim.length()).abs() < 1e-6, "{}", doubled);
        }

        /// Squares in a row cut whole in any order from any pierce points: valid, and the
        /// numbers agree with the route's.
        #[test]
        fn whole_contour_routes_stay_valid(order in Just((0..6usize).collect::<Vec<_>>()).prop_shuffle(), fractions in prop::collection::vec(0.0..1.0f64, 6)) {
            let nest = Nest {
                sheet: None,
                parts: (0..6).map(|i| part(vec![Contour::rectangle(i as f64 * 15.0, 0.0, i as f64 * 15.0 + 10.0, 7.0)])).collect(),
            };
            let steps = order.iter().map(|&i| {
                let r = ContourRef { part: i, contour: 0 };
                let c = nest.contour(r).unwrap();
                CutStep::pierced(r, c.point_at_length(fractions[i] * c.perimeter()).unwrap())
            }).collect();
            let route = Route { start: p(-5.0, -5.0), steps, finish: None };
            let paths = PathRoute::from_route(&route, &nest).unwrap();
            prop_assert_eq!(paths.problems(&nest, TOL), vec![]);
            prop_assert!((paths.cut_length() - route.cut_length(&nest)).abs() < 1e-9);
            prop_assert!((paths.idle_length() - route.idle_length()).abs() < 1e-9);
        }
    }
}
