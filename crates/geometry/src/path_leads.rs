//! Leads for routes of tool-on paths (segment cutting SCCP/GSCCP, common-edge cutting AOE): each
//! path pierces at M in G_M, runs a lead-in to its entry on an equidistant, cuts its spans (on
//! the equidistants at kerf/2: the path solvers run on [`LeadFitter::kerf_nest`]) and leaves by
//! a lead-out to M* in G_M* (dissertation §2.3, (1.5)–(1.6)).
//!
//! [`LeadFitter::attach_path`] fits the leads of one path. A path that cuts one equidistant
//! round (a whole contour, the common case on a nest whose parts are spaced wider than the
//! kerf) is fitted as a contour step is ([`LeadFitter::fit_on`]): where the asked lead has no
//! room the start moves along the equidistant, and a hole may be pierced at its centre. A path
//! that starts or ends inside a chain of edges (contours meeting on the kerf nest) keeps its
//! ends, which the rest of the route depends on: there the leads are the asked ones, shorter
//! and turned ones, on either side of the cut. A contour where none fits is reported, never
//! dropped.
//!
//! With edge piercing on ([`KerfSettings::edge_pierce`]) a path that starts on the equidistant
//! of a part's outer contour in the sheet's scrap may start with a straight edge lead-in from
//! the sheet's border, the contour steps' own (`LeadFitter::edge_lead_in`). A closed path
//! (one that ends where it starts) runs on past its start by the overcut before its lead-out,
//! over its own first spans ([`PathLeads::overcut_spans`]); an open path ends where the solver
//! ends it and gets no overcut (running on would cut past a piece the route cuts elsewhere).
//! A path that cuts a part's outer contour round (one equidistant, from its start back to it)
//! gets that contour's tabs, placed as a contour step's ([`crate::place_tabs`]); a part whose
//! outer contour is cut in pieces by several paths (chains of common edges) gets none.

use serde::{Deserialize, Serialize};

use crate::leads::{lead_in_chain, lead_out_chain, split_at_tabs, vertex, vertex_triples};
use crate::{
    chain_spans, opened_at, Contour, ContourRef, KerfSettings, LeadError, LeadFitter, LeadProblem,
    PathRoute, Point, Span, StepLeads, Tab, ToolOnPath, Vertex,
};

/// How far (mm) a point may lie from an equidistant and still count as on it: the checker's
/// entry tolerance (`LeadFitter::problems`).
const ON_EQUIDISTANT: f64 = 1e-6;

/// Pieces of a span shorter than this (mm) are dropped when an equidistant is opened at an
/// entry (as the toolpath does).
const MIN_PIECE: f64 = 1e-9;

/// The full-route elements of one tool-on path beyond its spans: the path's `pierce` is M, the
/// lead-in runs from it to `entry` (where the spans start, on an equidistant), and the
/// lead-out from the spans' end (the exit) to the switch-off point M*.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathLeads {
    /// Where the lead-in meets the equidistant; the first span starts here.
    pub entry: Point,
    /// Lead-in spans as vertices `[x, y, bulge]` from M to the entry (the last vertex is the
    /// entry); just `[entry]` without a lead.
    #[serde(with = "vertex_triples")]
    pub lead_in: Vec<Vertex>,
    /// Lead-out spans from the exit (the last span's end) to M*.
    #[serde(with = "vertex_triples")]
    pub lead_out: Vec<Vertex>,
    /// Switch-off point M*.
    pub switch_off: Point,
    /// Half the kerf: the distance of the equidistants from the contours, mm.
    pub offset: f64,
    /// d₁ the pierce point was placed under, mm.
    #[serde(default)]
    pub pierce_clearance: f64,
    /// d₂ the switch-off point was placed under, mm.
    #[serde(default)]
    pub switch_off_clearance: f64,
    /// How far a closed path runs on past its start over its own first spans before the
    /// lead-out, mm (0 on open paths).
    #[serde(default)]
    pub overcut: f64,
    /// M lies on the sheet's border (an edge pierce, see [`KerfSettings::edge_pierce`]): the
    /// checker holds it to the border instead of G_M.
    #[serde(default)]
    pub edge_pierce: bool,
    /// Micro-joints of the path's cut, in cut order, their arc lengths measured along the
    /// spans from the entry.
    #[serde(default)]
    pub tabs: Vec<Tab>,
}

impl PathLeads {
    /// Total width of the tabs' gaps, mm.
    pub fn tab_width(&self) -> f64 {
        self.tabs.iter().map(Tab::width).sum()
    }

    /// `spans` (the path's, from the entry) split at the tabs: the pieces the torch cuts
    /// between the entry, the gaps and the end (one piece without tabs).
    pub fn pieces(&self, spans: &[Span], min_piece: f64) -> Vec<Vec<Span>> {
        if self.tabs.is_empty() {
            // The spans as they are (splitting would rebuild each span from its ends).
            return vec![spans.to_vec()];
        }
        split_at_tabs(spans.to_vec(), &self.tabs, min_piece)
    }

    /// The overcut of a path whose spans (from the entry) are `spans`: its first spans up to
    /// [`PathLeads::overcut`] mm, the last one cut short. Pieces no longer than `min_piece`
    /// are dropped.
    pub fn overcut_spans(&self, spans: &[Span], min_piece: f64) -> Vec<Span> {
        let mut out = Vec::new();
        let mut left = self.overcut;
        for span in spans {
            if !(left > min_piece) {
                break;
            }
            let l = span.length();
            if l <= left {
                out.push(*span);
                left -= l;
            } else {
                out.push(span.sub_span(0.0, left / l));
                left = 0.0;
            }
        }
        out
    }

    /// Length of the lead-in, mm.
    pub fn lead_in_length(&self) -> f64 {
        chain_spans(&self.lead_in).map(|s| s.length()).sum()
    }

    /// Length of the lead-out, mm.
    pub fn lead_out_length(&self) -> f64 {
        chain_spans(&self.lead_out).map(|s| s.length()).sum()
    }

    /// Where the lead-out leaves the equidistant.
    pub fn exit(&self) -> Point {
        self.lead_out.first().map_or(self.entry, |v| v.point)
    }

    /// The rules these leads were built under (kerf, d₁, d₂), which the checker holds them to.
    pub fn rules(&self) -> KerfSettings {
        KerfSettings {
            kerf: 2.0 * self.offset,
            pierce_clearance: self.pierce_clearance,
            switch_off_clearance: self.switch_off_clearance,
            ..KerfSettings::default()
        }
    }

    /// The lead-in side as the leads of a step whose cut ends at the entry (no lead-out), for
    /// the contour checker.
    fn lead_in_side(&self) -> StepLeads {
        StepLeads {
            pierce: self.lead_in.first().map_or(self.entry, |v| v.point),
            entry: self.entry,
            lead_in: self.lead_in.clone(),
            lead_out: vec![vertex(self.entry)],
            switch_off: self.entry,
            offset: self.offset,
            overcut: 0.0,
            pierce_clearance: self.pierce_clearance,
            switch_off_clearance: self.switch_off_clearance,
            tabs: self.tabs.clone(),
            edge_pierce: self.edge_pierce,
            kerf_pierce: None,
        }
    }

    /// The lead-out side as the leads of a step entered at the exit (no lead-in).
    fn lead_out_side(&self) -> StepLeads {
        let exit = self.exit();
        StepLeads {
            pierce: exit,
            entry: exit,
            lead_in: vec![vertex(exit)],
            lead_out: self.lead_out.clone(),
            switch_off: self.switch_off,
            offset: self.offset,
            overcut: 0.0,
            pierce_clearance: self.pierce_clearance,
            switch_off_clearance: self.switch_off_clearance,
            tabs: Vec::new(),
            edge_pierce: false,
            kerf_pierce: None,
        }
    }
}

/// `chain` reflected across the line through `at` along `tangent`: the same lead on the other
/// side of the cut (a path may run either way along a contour, so the scrap may be on its
/// right).
fn mirrored(chain: &[Vertex], at: Point, tangent: Point) -> Vec<Vertex> {
    let t = tangent.normalized();
    chain
        .iter()
        .map(|v| {
            let d = v.point - at;
            let p = at + t * (2.0 * d.dot(t)) - d;
            Vertex::arc(p.x, p.y, -v.bulge)
        })
        .collect()
}

impl LeadFitter<'_> {
    /// The contours of the nest whose equidistant at kerf/2 passes through `p` (several where
    /// equidistants coincide: parts spaced by the kerf).
    pub fn contours_on_equidistant(&self, p: Point) -> Vec<ContourRef> {
        self.contours_near_equidistant(p, ON_EQUIDISTANT)
    }

    /// [`LeadFitter::contours_on_equidistant`] within `tolerance` mm.
    fn contours_near_equidistant(&self, p: Point, tolerance: f64) -> Vec<ContourRef> {
        let half = self.settings().kerf / 2.0;
        self.nest()
            .contour_refs()
            .filter(|&r| {
                self.box_of(r)
                    .is_some_and(|b| b.expanded(half + 1.0).contains_point(p))
            })
            .filter(|&r| {
                self.nest()
                    .contour(r)
                    .is_some_and(|c| (c.distance_to(p) - half).abs() <= tolerance)
            })
            .collect()
    }

    /// How far `p` lies off the equidistant of contour `r`, mm (by its distance to `r`).
    fn off_equidistant(&self, r: ContourRef, p: Point) -> f64 {
        self.nest().contour(r).map_or(f64::NAN, |c| {
            (c.distance_to(p) - self.settings().kerf / 2.0).abs()
        })
    }

    /// The nearest contour to `p` (for naming a contour where a lead found no room).
    fn nearest_contour(&self, p: Point) -> ContourRef {
        self.nest()
            .contour_refs()
            .filter_map(|r| Some((r, self.nest().contour(r)?.distance_to(p))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(
                ContourRef {
                    part: 0,
                    contour: 0,
                },
                |(r, _)| r,
            )
    }

    /// The contour whose equidistant `path` cuts once round, from its start back to it, and
    /// that equidistant: one of `candidates` (contours whose equidistant passes through the
    /// start), or a contour the path runs round itself (the kerf nest keeps a contour's own
    /// shape where its equidistant would change which contour holds which: the path is then
    /// moved onto the equidistant).
    fn whole_loop(
        &self,
        path: &ToolOnPath,
        candidates: &[ContourRef],
        tolerance: f64,
    ) -> Option<(ContourRef, Contour)> {
        let (first, last) = (path.spans.first()?, path.spans.last()?);
        if first.start.distance(last.end) > tolerance {
            return None;
        }
        let length: f64 = path.spans.iter().map(Span::length).sum();
        let runs_round = |target: &Contour| {
            let perimeter = target.perimeter();
            (length - perimeter).abs() <= 1e-6 * perimeter.max(1.0) + tolerance
                && path.spans.iter().all(|s| {
                    [s.point_at(0.5), s.end]
                        .iter()
                        .all(|&p| target.distance_to(p) <= tolerance)
                })
        };
        let on_contour = self.nest().contour_refs().filter(|&r| {
            self.box_of(r)
                .is_some_and(|b| b.expanded(tolerance).contains_point(first.start))
                && self
                    .nest()
                    .contour(r)
                    .is_some_and(|c| c.distance_to(first.start) <= tolerance)
        });
        candidates
            .iter()
            .copied()
            .find_map(|r| {
                let eq = self.equidistant(r).ok()?;
                runs_round(&eq).then_some((r, eq))
            })
            .or_else(|| {
                on_contour
                    .filter(|&r| self.nest().contour(r).is_some_and(&runs_round))
                    .find_map(|r| Some((r, self.equidistant(r).ok()?)))
            })
    }

    /// A lead-in (`lead_in`) ending at `at` where the cut leaves along `tangent`, or a lead-out
    /// starting there where the cut arrives along it, for one of `candidates`: the asked lead,
    /// its shorter and turned variants, each on the left of the cut and then on its right.
    fn fit_path_end(
        &self,
        candidates: &[ContourRef],
        at: Point,
        tangent: Point,
        lead_in: bool,
    ) -> Result<Vec<Vertex>, LeadError> {
        let spec = if lead_in {
            self.settings().lead_in
        } else {
            self.settings().lead_out
        };
        let Some(&named) = candidates.first() else {
            let contour = self.nearest_contour(at);
            return Err(LeadError::NoFit {
                contour,
                reason: LeadProblem::EntryOffEquidistant {
                    x: at.x,
                    y: at.y,
                    distance: self.off_equidistant(contour, at),
                },
            });
        };
        let mut reason = LeadProblem::Disjoint;
        for spec in self.variants(spec) {
            let chain = if lead_in {
                lead_in_chain(spec, at, tangent)
            } else {
                lead_out_chain(spec, at, tangent)
            };
            let other_side = mirrored(&chain, at, tangent);
            for chain in [chain, other_side] {
                for &r in candidates {
                    match self.chain_problem(r, &chain, lead_in) {
                        None => return Ok(chain),
                        Some(problem) => reason = problem,
                    }
                }
            }
        }
        Err(LeadError::NoFit {
            contour: named,
            reason,
        })
    }

    /// `path` (a path over [`LeadFitter::kerf_nest`], its spans on the equidistants) with
    /// leads (see the module notes). An empty path is returned as it is (the checker reports
    /// it).
    pub fn attach_path(&self, path: &ToolOnPath) -> Result<ToolOnPath, LeadError> {
        let (Some(first), Some(last)) = (path.spans.first(), path.spans.last()) else {
            return Ok(path.clone());
        };
        // The solver's points on the equidistants are exact to its own tolerance (segment
        // cutting splits spans at computed points): within the nest's check tolerance they
        // count as on an equidistant and are moved onto it.
        let snap = self.nest().check_tolerance().max(ON_EQUIDISTANT);
        let at_start = self.contours_near_equidistant(first.start, snap);
        // A closed path runs on past its start; an open one ends where the solver ends it.
        let overcut = if first.start.distance(last.end) <= snap {
            self.settings().overcut
        } else {
            0.0
        };
        if let Some((r, eq)) = self.whole_loop(path, &at_start, snap) {
            // Fitted as a contour step with the overcut: its lead-out leaves where it ends.
            let leads = self.fit_on(r, &eq, path.pierce)?;
            let spans = opened_at(&eq, leads.entry, MIN_PIECE);
            let entry = spans.first().map_or(leads.entry, |s| s.start);
            let mut lead_in = leads.lead_in.clone();
            if let Some(v) = lead_in.last_mut() {
                v.point = entry;
            }
            let mut path_leads = PathLeads {
                entry,
                lead_in,
                lead_out: leads.lead_out.clone(),
                switch_off: leads.switch_off,
                offset: leads.offset,
                pierce_clearance: leads.pierce_clearance,
                switch_off_clearance: leads.switch_off_clearance,
                overcut: leads.overcut,
                edge_pierce: leads.edge_pierce,
                tabs: leads.tabs.clone(),
            };
            let exit = path_leads
                .overcut_spans(&spans, MIN_PIECE)
                .last()
                .or(spans.last())
                .map_or(entry, |s| s.end);
            if let Some(v) = path_leads.lead_out.first_mut() {
                // The same point computed twice (frame and opening): the cut's end is exact.
                v.point = exit;
            }
            // Without a lead the chain is that one point, so M* (M) moved with it: the
            // chains' ends are the points, exactly, as the checker holds them.
            if let Some(v) = path_leads.lead_out.last() {
                path_leads.switch_off = v.point;
            }
            let pierce = path_leads.lead_in.first().map_or(leads.pierce, |v| v.point);
            return Ok(ToolOnPath {
                pierce,
                spans,
                leads: Some(path_leads),
            });
        }
        let onto = |p: Point, candidates: &[ContourRef]| {
            candidates
                .first()
                .and_then(|&r| self.equidistant(r).ok())
                .and_then(|eq| eq.nearest_point(p))
                .map_or(p, |q| q.point)
        };
        let at_end = self.contours_near_equidistant(last.end, snap);
        let mut spans = path.spans.clone();
        let start = onto(first.start, &at_start);
        let end = if overcut > 0.0 {
            start
        } else {
            onto(last.end, &at_end)
        };
        spans[0].start = start;
        let n = spans.len();
        spans[n - 1].end = end;
        let settings = self.settings();
        let mut leads = PathLeads {
            entry: start,
            lead_in: Vec::new(),
            lead_out: Vec::new(),
            switch_off: end,
            offset: settings.kerf / 2.0,
            pierce_clearance: settings.pierce_clearance,
            switch_off_clearance: settings.switch_off_clearance,
            overcut,
            edge_pierce: false,
            tabs: Vec::new(),
        };
        let edge_lead = at_start.iter().find_map(|&r| self.edge_lead_in(r, start));
        leads.edge_pierce = edge_lead.is_some();
        leads.lead_in = match edge_lead {
            Some(chain) => chain,
            None => self.fit_path_end(&at_start, start, spans[0].tangent_at(0.0), true)?,
        };
        let (exit, exit_tangent, at_exit) = match leads.overcut_spans(&spans, MIN_PIECE).last() {
            Some(s) => (
                s.end,
                s.tangent_at(1.0),
                self.contours_near_equidistant(s.end, snap),
            ),
            None => (end, spans[n - 1].tangent_at(1.0), at_end),
        };
        leads.lead_out = self.fit_path_end(&at_exit, exit, exit_tangent, false)?;
        leads.switch_off = leads.lead_out.last().map_or(exit, |v| v.point);
        Ok(ToolOnPath {
            pierce: leads.lead_in[0].point,
            spans,
            leads: Some(leads),
        })
    }

    /// `route` (over [`LeadFitter::kerf_nest`]) with leads on every path; fails with every
    /// contour where no lead fits.
    pub fn attach_paths(&self, route: &PathRoute) -> Result<PathRoute, Vec<LeadError>> {
        let mut errors = Vec::new();
        let mut paths = Vec::with_capacity(route.paths.len());
        for path in &route.paths {
            match self.attach_path(path) {
                Ok(p) => paths.push(p),
                Err(e) => errors.push(e),
            }
        }
        if errors.is_empty() {
            Ok(PathRoute {
                paths,
                ..route.clone()
            })
        } else {
            Err(errors)
        }
    }

    /// Every rule the leads of `path` break (this fitter's nest; the rules are the leads'):
    /// the chains joined to M, the entry, the exit (after the overcut) and M*; an overcut only
    /// on a closed path and no longer than it; an edge pierce's M on the sheet's border, its
    /// contour a part's outer one in the sheet's scrap; the entry and exit on the
    /// equidistant of some contour; M ∈ G_M and M* ∈ G_M* of that contour; both leads at
    /// least kerf/2 from every contour. `tolerance` is how far joined points may lie apart.
    pub fn path_lead_problems(
        &self,
        path: &ToolOnPath,
        leads: &PathLeads,
        tolerance: f64,
    ) -> Vec<LeadProblem> {
        let mut problems = Vec::new();
        let near = |a: Option<Point>, b: Point| a.is_some_and(|a| a.distance(b) <= tolerance);
        // An overcut runs on over the path's first spans: only a closed path has them after
        // its end, and only as far as the path goes.
        let overcut = leads.overcut;
        if overcut != 0.0 {
            let length: f64 = path.spans.iter().map(Span::length).sum();
            let closed = path
                .spans
                .first()
                .zip(path.spans.last())
                .is_some_and(|(a, b)| a.start.distance(b.end) <= tolerance);
            if !(overcut > 0.0 && overcut <= length + tolerance && closed) {
                problems.push(LeadProblem::OvercutMisplaced { length: overcut });
            }
        }
        // Tabs lie within the path's own cut (the contour checker places them on the
        // equidistant and away from its corners).
        let length: f64 = path.spans.iter().map(Span::length).sum();
        problems.extend(
            leads
                .tabs
                .iter()
                .filter(|t| !(t.start >= 0.0 && t.end <= length + tolerance))
                .map(|t| LeadProblem::TabMisplaced {
                    x: t.from.x,
                    y: t.from.y,
                }),
        );
        let exit = leads
            .overcut_spans(&path.spans, MIN_PIECE)
            .last()
            .map_or(path.end(), |s| s.end);
        let joined = near(leads.lead_in.first().map(|v| v.point), path.pierce)
            && near(leads.lead_in.last().map(|v| v.point), leads.entry)
            && near(leads.lead_out.first().map(|v| v.point), exit)
            && near(leads.lead_out.last().map(|v| v.point), leads.switch_off);
        if !joined {
            problems.push(LeadProblem::Disjoint);
        }
        let side = |at: Point, step: StepLeads, lead_in: bool| -> Vec<LeadProblem> {
            let candidates = self.contours_on_equidistant(at);
            let mut first: Option<Vec<LeadProblem>> = None;
            for r in candidates {
                let found = self.problems_linked(r, &step, !lead_in, lead_in);
                if found.is_empty() {
                    return found;
                }
                first.get_or_insert(found);
            }
            first.unwrap_or_else(|| {
                vec![LeadProblem::EntryOffEquidistant {
                    x: at.x,
                    y: at.y,
                    distance: self.off_equidistant(self.nearest_contour(at), at),
                }]
            })
        };
        problems.extend(side(leads.entry, leads.lead_in_side(), true));
        problems.extend(side(leads.exit(), leads.lead_out_side(), false));
        problems
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LeadShape, LeadSpec, Nest, Part, PathLeadError, PathRouteError, Route};
    use proptest::prelude::*;

    fn nest(contours: Vec<Vec<Contour>>) -> Nest {
        let mut nest = Nest {
            sheet: None,
            parts: contours
                .into_iter()
                .map(|contours| Part {
                    name: String::new(),
                    contours,
                })
                .collect(),
        };
        nest.normalize_orientation();
        nest
    }

    /// A plate 100 × 60 with a 40 × 30 hole, and a second part 50 × 50 beside it.
    fn plates() -> Nest {
        nest(vec![
            vec![
                Contour::rectangle(0.0, 0.0, 100.0, 60.0),
                Contour::rectangle(20.0, 15.0, 60.0, 45.0),
            ],
            vec![Contour::rectangle(130.0, 0.0, 180.0, 50.0)],
        ])
    }

    /// The path route of the innermost-first contour route over the kerf nest, with leads.
    fn with_leads(nest: &Nest, settings: KerfSettings) -> Result<PathRoute, Vec<LeadError>> {
        let fitter = LeadFitter::new(nest, settings);
        let kerf_nest = fitter.kerf_nest();
        let route = Route::innermost_first(&kerf_nest, Point::new(-50.0, -50.0), None);
        let paths = PathRoute::from_route(&route, &kerf_nest).expect("contours of the nest");
        fitter.attach_paths(&paths)
    }

    #[test]
    fn whole_contour_paths_get_leads_that_pass_the_checker() {
        let nest = plates();
        let route =
            with_leads(&nest, KerfSettings::plasma_reference()).expect("room for every lead");
        assert_eq!(route.paths.len(), 3);
        assert_eq!(route.problems(&nest, 1e-6), Vec::new());
        for path in &route.paths {
            let leads = path.leads.as_ref().expect("leads");
            assert!(leads.lead_in_length() > 0.0 && leads.lead_out_length() > 0.0);
            // M at least d₁ from every contour, the entry on the equidistant.
            assert!(crate::clearance(&nest, path.pierce, 100.0) >= 5.0 - 1e-6);
            assert!((crate::clearance(&nest, leads.entry, 100.0) - 1.0).abs() < 1e-6);
        }
        // Idle runs M* → next M, and the leads count as tool-on length.
        let legs: f64 = route
            .paths
            .windows(2)
            .map(|w| w[0].switch_off().distance(w[1].pierce))
            .sum::<f64>()
            + route.start.distance(route.paths[0].pierce);
        assert!((route.idle_length() - legs).abs() < 1e-9);
        let spans: f64 = route
            .paths
            .iter()
            .flat_map(|p| &p.spans)
            .map(Span::length)
            .sum();
        let leads: f64 = route.paths.iter().map(ToolOnPath::leads_length).sum();
        assert!((route.cut_length() - spans - leads).abs() < 1e-9);
    }

    #[test]
    fn json_carries_the_leads_and_reads_back() {
        let route = with_leads(&plates(), KerfSettings::plasma_reference()).expect("room");
        let json = serde_json::to_value(&route).expect("serialises");
        let leads = &json["paths"][0]["leads"];
        for field in ["entry", "lead_in", "lead_out", "switch_off"] {
            assert!(leads.get(field).is_some(), "{field} missing in {leads}");
        }
        assert_eq!(leads["lead_in"][0].as_array().map(Vec::len), Some(3));
        let back: PathRoute = serde_json::from_value(json).expect("reads back");
        assert_eq!(back, route);
        // A path route written before leads still reads.
        let plain: PathRoute = serde_json::from_str(
            r#"{"start":{"x":0,"y":0},"paths":[{"pierce":{"x":0,"y":0},"spans":[]}],"finish":null}"#,
        )
        .expect("reads");
        assert!(plain.paths[0].leads.is_none());
    }

    #[test]
    fn the_checker_catches_broken_leads() {
        let nest = plates();
        let good = with_leads(&nest, KerfSettings::plasma_reference()).expect("room");
        let first_lead = |route: &PathRoute| {
            route
                .problems(&nest, 1e-6)
                .into_iter()
                .find(|p| matches!(p, PathRouteError::Lead(_)))
        };
        // M moved onto the plate (into material): the lead-in starts there too, so it is
        // joined, but M is not in G_M.
        let mut inside = good.clone();
        let path = &mut inside.paths[2];
        let m = Point::new(40.0, 5.0);
        path.pierce = m;
        path.leads.as_mut().unwrap().lead_in = vec![
            Vertex::arc(m.x, m.y, 0.0),
            vertex(path.leads.as_ref().unwrap().entry),
        ];
        assert!(first_lead(&inside).is_some(), "a pierce in material passes");
        // M* moved next to a contour (closer than d₂ = 1).
        let mut late = good.clone();
        let leads = late.paths[0].leads.as_mut().unwrap();
        let near = Point::new(40.0, 45.0 - 0.5);
        leads.switch_off = near;
        *leads.lead_out.last_mut().unwrap() = vertex(near);
        assert!(
            first_lead(&late).is_some(),
            "a switch-off by a contour passes"
        );
        // A lead not joined to its pierce point.
        let mut loose = good.clone();
        loose.paths[1].pierce += Point::new(0.5, 0.0);
        assert!(matches!(
            first_lead(&loose),
            Some(PathRouteError::Lead(PathLeadError {
                problem: LeadProblem::Disjoint,
                ..
            }))
        ));
        // A path without leads among paths with them.
        let mut bare = good.clone();
        bare.paths[1].leads = None;
        bare.paths[1].pierce = bare.paths[1].spans[0].start;
        assert!(bare
            .problems(&nest, 1e-6)
            .contains(&PathRouteError::LeadsMismatch { path: 1 }));
        // The cut on the contours themselves, not the equidistants: their equidistants are
        // left uncut.
        let ideal = PathRoute::from_route(
            &Route::innermost_first(&nest, Point::new(-50.0, -50.0), None),
            &nest,
        )
        .unwrap();
        let mut on_contours = good.clone();
        for (path, plain) in on_contours.paths.iter_mut().zip(&ideal.paths) {
            path.spans = plain.spans.clone();
        }
        let problems = on_contours.problems(&nest, 1e-6);
        assert!(problems
            .iter()
            .any(|p| matches!(p, PathRouteError::Gap { .. })));
        assert!(problems
            .iter()
            .any(|p| matches!(p, PathRouteError::CutTooClose { .. })));
    }

    #[test]
    fn parts_closer_than_the_kerf_are_cut_too_close() {
        // Two squares 1 mm apart: their equidistants at 1 mm cross, each cut burns into the
        // other part.
        let close = nest(vec![
            vec![Contour::rectangle(0.0, 0.0, 50.0, 50.0)],
            vec![Contour::rectangle(51.0, 0.0, 101.0, 50.0)],
        ]);
        let fitter = LeadFitter::new(&close, KerfSettings::plasma_reference());
        let kerf_nest = fitter.kerf_nest();
        let route = Route::innermost_first(&kerf_nest, Point::new(-50.0, 25.0), None);
        let paths = PathRoute::from_route(&route, &kerf_nest).unwrap();
        let Ok(attached) = fitter.attach_paths(&paths) else {
            return; // no room reported: also right
        };
        assert!(attached
            .problems(&close, 1e-6)
            .iter()
            .any(|p| matches!(p, PathRouteError::CutTooClose { .. })));
    }

    #[test]
    fn open_paths_keep_their_ends_and_get_leads_on_the_scrap_side() {
        // One square's equidistant cut in two open paths, the second against the contour's
        // direction: its scrap is on the right, so its leads are the mirrored ones.
        let nest = nest(vec![vec![Contour::rectangle(0.0, 0.0, 50.0, 50.0)]]);
        let fitter = LeadFitter::new(&nest, KerfSettings::plasma_reference());
        let r = ContourRef {
            part: 0,
            contour: 0,
        };
        let eq = fitter.equidistant(r).unwrap();
        let spans: Vec<Span> = eq.spans().collect();
        let half = spans.len() / 2;
        let forward = ToolOnPath::new(spans[0].start, spans[..half].to_vec());
        let backward: Vec<Span> = spans[half..].iter().rev().map(Span::reversed).collect();
        let backward = ToolOnPath::new(backward[0].start, backward);
        let route = PathRoute {
            start: Point::new(-30.0, -30.0),
            paths: vec![forward.clone(), backward.clone()],
            finish: None,
        };
        let attached = fitter.attach_paths(&route).expect("room");
        assert_eq!(attached.problems(&nest, 1e-6), Vec::new());
        assert_eq!(attached.paths[0].spans, forward.spans);
        assert_eq!(attached.paths[1].spans, backward.spans);
        // The mirrored lead-in is needed on the backward path: the unmirrored one lies inside.
        let leads = attached.paths[1].leads.as_ref().unwrap();
        assert!(!nest.contour(r).unwrap().contains(attached.paths[1].pierce));
        assert!(leads.lead_in_length() > 0.0);
    }

    #[test]
    fn a_contour_without_room_is_reported() {
        // A 3 mm hole: with kerf 2 and d₁ 5 no pierce point fits inside it.
        let nest = nest(vec![vec![
            Contour::rectangle(0.0, 0.0, 60.0, 60.0),
            Contour::rectangle(20.0, 20.0, 23.0, 23.0),
        ]]);
        let errors =
            with_leads(&nest, KerfSettings::plasma_reference()).expect_err("no room in the hole");
        assert!(errors.iter().any(|e| match e {
            LeadError::NoFit { contour, .. } | LeadError::Offset { contour, .. } =>
                contour.contour == 1,
            LeadError::UnknownContour { .. } => false,
        }));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Grids of rectangles with holes, spaced wider than the leads need: every path
        /// route of whole contours over the kerf nest gets leads that pass the checker,
        /// plasma and laser alike.
        #[test]
        fn grids_get_leads_that_pass(
            cols in 1usize..4,
            rows in 1usize..3,
            w in 20.0f64..60.0,
            h in 20.0f64..60.0,
            gap in 14.0f64..30.0,
            laser in any::<bool>(),
        ) {
            let mut parts = Vec::new();
            for i in 0..cols {
                for j in 0..rows {
                    let (x, y) = (i as f64 * (w + gap), j as f64 * (h + gap));
                    parts.push(vec![
                        Contour::rectangle(x, y, x + w, y + h),
                        Contour::rectangle(x + w / 4.0, y + h / 4.0, x + 3.0 * w / 4.0, y + 3.0 * h / 4.0),
                    ]);
                }
            }
            let nest = nest(parts);
            let settings = if laser {
                KerfSettings {
                    kerf: 0.2,
                    pierce_clearance: 1.0,
                    switch_off_clearance: 0.5,
                    lead_in: LeadSpec::new(LeadShape::Arc, 3.0),
                    lead_out: LeadSpec::new(LeadShape::Line, 1.0),
                    ..KerfSettings::default()
                }
            } else {
                KerfSettings::plasma_reference()
            };
            let route = with_leads(&nest, settings).expect("room");
            prop_assert_eq!(route.problems(&nest, 1e-6), Vec::new());
            prop_assert_eq!(route.pierce_count(), 2 * cols * rows);
        }
    }
}
