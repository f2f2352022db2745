//! `cutroute solve` and `convert`'s full-route options (issue #17): kerf, the pierce and
//! switch-off clearances d₁ and d₂, lead-ins, lead-outs, overcut and micro-joints (tabs). The defaults are the
//! idealised model, under which nothing here changes a route or a report.
//!
//! With leads on, the contour solvers (nearest, ccp, heuristic, discrete, exact) and chain
//! cutting optimise the full route in the engine's kerf job (`cutroute_engine::KerfJob`, the app's
//! code path): the settings travel in the request, and the job's routes come with their leads
//! (chains with a lead-in at each chain's start and a lead-out at its end).
//! `--leads-after` instead solves the idealised route and attaches leads to it (the
//! comparison of the benchmark). This module parses the flags and writes the report.

use cutroute_geometry::{
    KerfSettings, LeadError, LeadShape, LeadSpec, Nest, PathLeads, PathRoute, Point, Route,
    StepLeads, TabSpec, Vertex,
};
use cutroute_protocol::{JobRequest, KerfNote, KerfSource, Phase, Progress};
use serde_json::{json, Value};

use crate::report::{StepReport, TabGap};

/// The full-route flags.
#[derive(clap::Args, Clone, Debug)]
pub struct KerfArgs {
    /// Kerf width, mm: the tool runs on the equidistant at kerf/2 (0: on the contours).
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    kerf: f64,
    /// d₁: least distance from every contour to a pierce point, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    pierce_clearance: f64,
    /// d₂: least distance from every contour to a switch-off point, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    switch_off_clearance: f64,
    /// Lead-in shape: arc (tangent), line, line-arc or none.
    #[arg(long, value_name = "SHAPE", default_value = "none")]
    lead_in: String,
    /// Lead-in length, mm.
    #[arg(long, value_name = "MM", default_value_t = 5.0)]
    lead_in_length: f64,
    /// Lead-out shape: arc, line, line-arc or none.
    #[arg(long, value_name = "SHAPE", default_value = "none")]
    lead_out: String,
    /// Lead-out length, mm.
    #[arg(long, value_name = "MM", default_value_t = 2.0)]
    lead_out_length: f64,
    /// How far the cut runs on past the entry before the lead-out, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    overcut: f64,
    /// Micro-joints: N uncut gaps of WIDTH mm in the outer contour of every part, away from
    /// corners (the torch switches off over each gap and pierces after it).
    #[arg(long, value_name = "N:WIDTH")]
    tabs: Option<String>,
    /// Solve the idealised route, then attach leads (instead of optimising with them).
    #[arg(long)]
    leads_after: bool,
    /// Pierce parts' outer contours at the sheet's border where the border is within the
    /// lead-in's reach plus d₁ of the entry and a straight lead from it keeps kerf/2 from every
    /// contour (the pierce takes `--edge-pierce-time`). Needs a nest with a sheet.
    #[arg(long)]
    edge_pierce: bool,
    /// Pierce in the open kerf of a contour cut earlier, where the entry is within the same
    /// reach of it and that saves time (the pierce takes `--edge-pierce-time`): for machines
    /// and materials that allow it.
    #[arg(long)]
    kerf_pierce: bool,
}

/// The parsed full-route settings.
pub struct Kerf {
    settings: KerfSettings,
    after: bool,
    /// Chain links given up for pierces where a lead found no room when a route the job did
    /// not make (a rule repair's) was fitted again (see `attach`).
    broken_links: std::cell::Cell<usize>,
}

fn shape(flag: &str, text: &str) -> Result<LeadShape, String> {
    match text {
        "none" => Ok(LeadShape::None),
        "line" => Ok(LeadShape::Line),
        "arc" => Ok(LeadShape::Arc),
        "line-arc" => Ok(LeadShape::LineArc),
        other => Err(format!(
            "--{flag} {other:?}: expected arc, line, line-arc or none"
        )),
    }
}

fn tabs(text: Option<&str>) -> Result<TabSpec, String> {
    let Some(text) = text else {
        return Ok(TabSpec::default());
    };
    let bad =
        || format!("--tabs {text:?}: expected N:WIDTH, e.g. 3:1.5 (N gaps of WIDTH mm per part)");
    let (count, width) = text.split_once(':').ok_or_else(bad)?;
    let count: usize = count.trim().parse().map_err(|_| bad())?;
    let width: f64 = width.trim().parse().map_err(|_| bad())?;
    if !(width.is_finite() && width > 0.0) || count > cutroute_geometry::MAX_TABS {
        return Err(bad());
    }
    Ok(TabSpec { count, width })
}

fn length(flag: &str, value: f64) -> Result<f64, String> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(format!("--{flag} {value}: must be finite and non-negative"))
    }
}

impl KerfArgs {
    pub fn parse(&self) -> Result<Kerf, String> {
        let settings = KerfSettings {
            kerf: length("kerf", self.kerf)?,
            pierce_clearance: length("pierce-clearance", self.pierce_clearance)?,
            switch_off_clearance: length("switch-off-clearance", self.switch_off_clearance)?,
            lead_in: LeadSpec::new(
                shape("lead-in", &self.lead_in)?,
                length("lead-in-length", self.lead_in_length)?,
            ),
            lead_out: LeadSpec::new(
                shape("lead-out", &self.lead_out)?,
                length("lead-out-length", self.lead_out_length)?,
            ),
            overcut: length("overcut", self.overcut)?,
            tabs: tabs(self.tabs.as_deref())?,
            edge_pierce: self.edge_pierce,
            kerf_pierce: self.kerf_pierce,
        };
        // The ranges profiles and the engine hold the settings to, named by flag.
        settings.check().map_err(|e| e.for_flag())?;
        Ok(Kerf {
            settings,
            after: self.leads_after,
            broken_links: Default::default(),
        })
    }
}

impl Kerf {
    /// These settings, or when the flags leave the route idealised, a profile's (`--profile`
    /// files carry the machine's kerf and leads as the page's profiles do).
    pub fn with_profile(self, profile: Option<&cutroute_protocol::MachineProfile>) -> Kerf {
        match profile.and_then(|p| p.kerf) {
            Some(settings) if !self.is_on() => Kerf { settings, ..self },
            _ => self,
        }
    }

    /// Whether the full route is on (anything but the idealised model).
    pub fn is_on(&self) -> bool {
        !self.settings.is_idealised()
    }

    /// The request with the full-route settings: the engine's kerf job then optimises the
    /// route with its leads (or, with `--leads-after`, attaches them to the idealised route).
    pub fn request(&self, mut request: JobRequest, solver: &str) -> Result<JobRequest, String> {
        if !self.is_on() {
            return Ok(request);
        }
        // The engine's word on which solvers have a full-route model (today: every one).
        if !request.solver.cuts_with_kerf() {
            return Err(format!(
                "--solver {solver} does not cut with kerf and leads yet"
            ));
        }
        request.params.kerf = self.settings;
        request.params.leads_after = self.after;
        Ok(request)
    }

    /// A route the job did not make (a file's own, or one the thermal repair changed) with
    /// leads fitted as the engine's kerf job fits them; every contour without room is named.
    pub fn attach(&self, nest: &Nest, route: Route) -> Result<Route, String> {
        if !self.is_on() {
            return Ok(route);
        }
        // The kerf job refuses such nests up front; a file's own route is held to the same.
        if let Some(too_close) =
            cutroute_geometry::PartsTooClose::of(nest, self.settings.kerf, nest.check_tolerance())
        {
            return Err(too_close.to_string());
        }
        let forest = nest.containment_forest();
        let links = |r: &Route| r.steps.iter().filter(|s| !s.is_pierced()).count();
        let fitted = cutroute_engine::fit_leads(nest, &forest, self.settings, &route, !self.after)
            .map_err(|errors| {
                no_room(&errors.iter().map(LeadError::to_string).collect::<Vec<_>>())
            })?;
        let broken = links(&route).saturating_sub(links(&fitted));
        self.broken_links.set(self.broken_links.get() + broken);
        Ok(fitted)
    }

    /// A route the hard-rule repair changed, with leads fitted as [`Kerf::attach`] fits them
    /// but never moved along the equidistants afterwards: the repair chose its pierce points
    /// for the rules, and moving them to shorten the idle legs would break the rules again.
    pub fn attach_repaired(&self, nest: &Nest, route: Route) -> Result<Route, String> {
        let fixed = Kerf {
            after: true,
            broken_links: Default::default(),
            ..*self
        };
        let fitted = fixed.attach(nest, route);
        self.broken_links
            .set(self.broken_links.get() + fixed.broken_links.get());
        fitted
    }

    /// The kerf job's word that some contours have no room for their leads, as an error.
    pub fn refused(&self, progress: Option<&Progress>) -> Result<(), String> {
        match progress.map(|p| &p.phase) {
            Some(Phase::Kerf {
                note: KerfNote::NoRoom { errors, .. },
                ..
            }) => Err(no_room(errors)),
            _ => Ok(()),
        }
    }

    /// The fields every report states, `start` and `finish` (where there is one); whether
    /// the full-route fields follow (a kerf or leads are on).
    fn report_head(&self, report: &mut Value, start: Point, finish: Option<Point>) -> bool {
        report["start"] = json!([start.x, start.y]);
        if let Some(finish) = finish {
            report["finish"] = json!([finish.x, finish.y]);
        }
        self.is_on()
    }

    /// Adds the full-route fields to a nest report: `start`, `finish`, the settings, the lead
    /// lengths, and per step `pierce` (M), `entry`, `lead_in`, `lead_out`, `switch_off`.
    /// `phase` is the job's last phase: its kerf note counts the chain links the job broke.
    pub fn report(
        &self,
        report: &mut Value,
        steps: &mut [StepReport],
        route: &Route,
        phase: Option<&Phase>,
    ) {
        if !self.report_head(report, route.start, route.finish) {
            return;
        }
        let s = &self.settings;
        report["kerf"] = json!({
            "kerf": s.kerf,
            "pierce_clearance": s.pierce_clearance,
            "switch_off_clearance": s.switch_off_clearance,
            "overcut": s.overcut,
            "tabs": tabs_placed(s.tabs, route),
            "optimised_with_leads": !self.after,
            "edge_pierce": s.edge_pierce,
            "kerf_pierce": s.kerf_pierce,
        });
        if s.edge_pierce {
            report["edge_pierces"] = json!(route.edge_pierce_count());
        }
        if s.kerf_pierce {
            report["kerf_pierces"] = json!(route.kerf_pierce_count());
        }
        let leads = || route.steps.iter().filter_map(|s| s.leads.as_ref());
        let by_job = match phase {
            Some(Phase::Kerf {
                note:
                    KerfNote::Leads {
                        source: KerfSource::Chains { links_broken },
                    },
                ..
            }) => Some(*links_broken),
            _ => None,
        };
        if by_job.is_some() || self.broken_links.get() > 0 {
            report["chain_links_broken"] = json!(by_job.unwrap_or(0) + self.broken_links.get());
        }
        report["lead_in_length"] = json!(leads().map(StepLeads::lead_in_length).sum::<f64>());
        report["lead_out_length"] = json!(leads().map(StepLeads::lead_out_length).sum::<f64>());
        for (k, (step, cut)) in steps.iter_mut().zip(&route.steps).enumerate() {
            let Some(l) = &cut.leads else { continue };
            // In a chain, a step entered by a link is not pierced and one left by a link is
            // not switched off: those points are the link's ends, not M or M*.
            let linked_out = route.steps.get(k + 1).is_some_and(|n| !n.is_pierced());
            let triples = |chain: &[Vertex]| {
                chain
                    .iter()
                    .map(|v| [v.point.x, v.point.y, v.bulge])
                    .collect::<Vec<_>>()
            };
            step.contour_point = Some([cut.pierce_point.x, cut.pierce_point.y]);
            step.pierce = cut.is_pierced().then_some([l.pierce.x, l.pierce.y]);
            step.entry = Some([l.entry.x, l.entry.y]);
            step.edge_pierce = l.edge_pierce && cut.is_pierced();
            // In the open kerf of this contour, cut before: [part, contour].
            step.kerf_pierce = l
                .kerf_pierce
                .filter(|_| cut.is_pierced())
                .map(|c| [c.part, c.contour]);
            step.lead_in = Some(triples(&l.lead_in));
            step.lead_out = Some(triples(&l.lead_out));
            step.switch_off = (!linked_out).then_some([l.switch_off.x, l.switch_off.y]);
            if !l.tabs.is_empty() {
                // Each gap: where the torch stops and where it pierces again.
                step.tabs = Some(
                    l.tabs
                        .iter()
                        .map(|t| TabGap {
                            from: [t.from.x, t.from.y],
                            to: [t.to.x, t.to.y],
                        })
                        .collect(),
                );
            }
        }
    }
}

impl Kerf {
    /// Adds the full-route fields to a path report: `start`, `finish`, the settings and the
    /// lead lengths (and `edge_pierces` with edge piercing on); each path of the report's
    /// `route` carries its `pierce` (M), `entry` and `switch_off` as [x, y], `lead_in` and
    /// `lead_out` as [x, y, bulge] vertices, `edge_pierce` when pierced at the sheet's border
    /// `overcut` (mm) when it runs on past its start, and `tabs` (each gap's `from` and `to`).
    pub fn report_paths(&self, report: &mut Value, route: &PathRoute) {
        if !self.report_head(report, route.start, route.finish) {
            return;
        }
        let s = &self.settings;
        report["kerf"] = json!({
            "kerf": s.kerf,
            "pierce_clearance": s.pierce_clearance,
            "switch_off_clearance": s.switch_off_clearance,
            // Closed paths only: an open path ends where the solver ends it.
            "overcut": s.overcut,
            "tabs": {
                "per_part": s.tabs.count,
                "width": s.tabs.width,
                // A gap goes only where the cut has room away from corners and leads.
                "placed": route
                    .paths
                    .iter()
                    .filter_map(|p| p.leads.as_ref())
                    .map(|l| l.tabs.len())
                    .sum::<usize>(),
            },
            "optimised_with_leads": true,
            "edge_pierce": s.edge_pierce,
        });
        if s.edge_pierce {
            report["edge_pierces"] = json!(route.edge_pierce_count());
        }
        let leads = || route.paths.iter().filter_map(|p| p.leads.as_ref());
        // The form: points as [x, y] (the route's serde form is {x, y}).
        if let Some(paths) = report["route"]["paths"].as_array_mut() {
            for (path, p) in paths.iter_mut().zip(&route.paths) {
                let Some(l) = &p.leads else { continue };
                let triples = |chain: &[Vertex]| {
                    chain
                        .iter()
                        .map(|v| [v.point.x, v.point.y, v.bulge])
                        .collect::<Vec<_>>()
                };
                path["pierce"] = json!([p.pierce.x, p.pierce.y]);
                path["entry"] = json!([l.entry.x, l.entry.y]);
                if l.edge_pierce {
                    path["edge_pierce"] = json!(true);
                }
                if l.overcut > 0.0 {
                    path["overcut"] = json!(l.overcut);
                }
                path["lead_in"] = json!(triples(&l.lead_in));
                path["lead_out"] = json!(triples(&l.lead_out));
                path["switch_off"] = json!([l.switch_off.x, l.switch_off.y]);
                if !l.tabs.is_empty() {
                    // Each gap: where the torch stops and where it pierces again.
                    path["tabs"] = json!(l
                        .tabs
                        .iter()
                        .map(|t| json!({ "from": [t.from.x, t.from.y], "to": [t.to.x, t.to.y] }))
                        .collect::<Vec<_>>());
                }
                if let Some(fields) = path.as_object_mut() {
                    fields.remove("leads");
                }
            }
        }
        report["lead_in_length"] = json!(leads().map(PathLeads::lead_in_length).sum::<f64>());
        report["lead_out_length"] = json!(leads().map(PathLeads::lead_out_length).sum::<f64>());
    }
}

/// The report's `tabs`: the asked gaps per part and width, how many were placed, and how many
/// parts got fewer than asked (a gap goes only where the cut has room for it away from the
/// corners and the leads, so a small or many-cornered part can get fewer, or none).
fn tabs_placed(asked: TabSpec, route: &Route) -> Value {
    let mut per_part: std::collections::BTreeMap<usize, usize> = Default::default();
    for step in &route.steps {
        let placed = step.leads.as_ref().map_or(0, |l| l.tabs.len());
        *per_part.entry(step.contour.part).or_default() += placed;
    }
    json!({
        "per_part": asked.count,
        "width": asked.width,
        "placed": per_part.values().sum::<usize>(),
        "parts_with_fewer": per_part.values().filter(|&&n| n < asked.count).count(),
    })
}

/// The error of contours without room for their leads, from `LeadError`'s words.
fn no_room(errors: &[String]) -> String {
    format!(
        "{} contour(s) without room for the leads: {}",
        errors.len(),
        errors.join("; ")
    )
}
