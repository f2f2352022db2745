//! `cutroute solve` and `convert`'s full-route options (issue #17): kerf, the pierce and
//! switch-off clearances d₁ and d₂, lead-ins, lead-outs, overcut and micro-joints (tabs). The defaults are the
//! idealised model, under which nothing here changes a route or a report.
//!
//! With leads on, the contour solvers (nearest, ccp, heuristic, discrete) optimise the full
//! route: they run over the nest of pierce curves (`LeadFitter::pierce_curve_nest`), so the
//! idle legs they price run between pierce points off the contours; the route is brought back
//! onto the nest, every step gets its fitted leads, and the leads are moved along the
//! equidistants where that shortens the idle legs from M* to the next M. `--leads-after` instead solves the
//! idealised route and attaches leads to it (the comparison of the benchmark).
//!
//! Chain cutting runs over the nest of equidistants (`LeadFitter::kerf_nest`): its links run
//! between entries on the equidistants, and `LeadFitter::attach_chained` gives each chain a
//! lead-in at its first contour and a lead-out at its last (`--leads-after`: without moving
//! the free leads afterwards).

use cutroute_geometry::{
    KerfSettings, LeadError, LeadFitter, LeadShape, LeadSpec, Nest, Route, StepLeads, TabSpec,
    Vertex,
};
use cutroute_protocol::{JobRequest, Problem};
use serde_json::{json, Value};

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
}

/// The parsed full-route settings.
pub struct Kerf {
    settings: KerfSettings,
    after: bool,
    /// Chain links given up for pierces where a lead found no room (see `project`).
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
    if !(width.is_finite() && width > 0.0) || count > 1000 {
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
        };
        Ok(Kerf {
            settings,
            after: self.leads_after,
            broken_links: Default::default(),
        })
    }
}

impl Kerf {
    /// Whether the full route is on (anything but the idealised model).
    pub fn is_on(&self) -> bool {
        !self.settings.is_idealised()
    }

    /// The request the solver runs: over the pierce curves when it optimises with leads.
    pub fn request(&self, mut request: JobRequest, solver: &str) -> Result<JobRequest, String> {
        if !self.is_on() {
            return Ok(request);
        }
        if !matches!(
            solver,
            "nearest" | "ccp" | "heuristic" | "discrete" | "chain"
        ) {
            return Err(format!(
                "--solver {solver} does not cut with kerf and leads yet (nearest, ccp, heuristic, discrete and chain do)"
            ));
        }
        if solver == "chain" {
            if let Problem::Nest { nest, .. } = &mut request.problem {
                *nest = LeadFitter::new(nest, self.settings).kerf_nest();
            }
            return Ok(request);
        }
        if self.after {
            return Ok(request);
        }
        if let Problem::Nest { nest, .. } = &mut request.problem {
            *nest = LeadFitter::new(nest, self.settings).pierce_curve_nest();
        }
        Ok(request)
    }

    /// The solver's route brought onto `nest` (pierce points on its contours). A chained
    /// route (over the kerf nest) comes back with its leads; every contour without room is
    /// named.
    pub fn project(&self, nest: &Nest, route: Route) -> Result<Route, String> {
        if !self.is_on() {
            return Ok(route);
        }
        let fitter = LeadFitter::new(nest, self.settings);
        if route.steps.iter().any(|s| !s.is_pierced()) {
            let passes = if self.after { 0 } else { 2 };
            return fitter
                .attach_chained(&route, passes, 24)
                .map(|chained| {
                    self.broken_links.set(chained.broken_links);
                    chained.route
                })
                .map_err(no_room);
        }
        Ok(fitter.project(&route))
    }

    /// `route` with leads on every step; every contour without room is named. A route that
    /// has its leads already (a chained route, see `project`) is kept, or fitted again where
    /// its links changed since (`--rules-hard` turns links that break a rule into pierces).
    pub fn attach(&self, nest: &Nest, route: Route) -> Result<Route, String> {
        if !self.is_on() {
            return Ok(route);
        }
        let fitter = LeadFitter::new(nest, self.settings);
        if route.steps.iter().any(|s| s.leads.is_some()) {
            let forest = nest.containment_forest();
            if route
                .problems(nest, &forest, nest.check_tolerance())
                .is_empty()
            {
                return Ok(route);
            }
            // No relaxing: the pierce points stay where the rules repair put them.
            return fitter
                .attach_chained(&route, 0, 0)
                .map(|chained| {
                    let broken = self.broken_links.get() + chained.broken_links;
                    self.broken_links.set(broken);
                    chained.route
                })
                .map_err(no_room);
        }
        fitter
            .attach(&route)
            .map(|route| {
                if self.after {
                    route
                } else {
                    fitter.relax(&route, 2, 24)
                }
            })
            .map_err(no_room)
    }

    /// Adds the full-route fields to a nest report: `start`, `finish`, the settings, the lead
    /// lengths, and per step `pierce` (M), `entry`, `lead_in`, `lead_out`, `switch_off`.
    pub fn report(&self, report: &mut Value, route: &Route) {
        report["start"] = json!([route.start.x, route.start.y]);
        if let Some(finish) = route.finish {
            report["finish"] = json!([finish.x, finish.y]);
        }
        if !self.is_on() {
            return;
        }
        let s = &self.settings;
        report["kerf"] = json!({
            "kerf": s.kerf,
            "pierce_clearance": s.pierce_clearance,
            "switch_off_clearance": s.switch_off_clearance,
            "overcut": s.overcut,
            "tabs": { "per_part": s.tabs.count, "width": s.tabs.width },
            "optimised_with_leads": !self.after,
        });
        let leads = || route.steps.iter().filter_map(|s| s.leads.as_ref());
        if route.steps.iter().any(|s| !s.is_pierced()) || self.broken_links.get() > 0 {
            report["chain_links_broken"] = json!(self.broken_links.get());
        }
        report["lead_in_length"] = json!(leads().map(StepLeads::lead_in_length).sum::<f64>());
        report["lead_out_length"] = json!(leads().map(StepLeads::lead_out_length).sum::<f64>());
        let Some(steps) = report["route"].as_array_mut() else {
            return;
        };
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
            step["contour_point"] = json!([cut.pierce_point.x, cut.pierce_point.y]);
            if cut.is_pierced() {
                step["pierce"] = json!([l.pierce.x, l.pierce.y]);
            } else if let Some(fields) = step.as_object_mut() {
                fields.remove("pierce");
            }
            step["entry"] = json!([l.entry.x, l.entry.y]);
            step["lead_in"] = json!(triples(&l.lead_in));
            step["lead_out"] = json!(triples(&l.lead_out));
            if !linked_out {
                step["switch_off"] = json!([l.switch_off.x, l.switch_off.y]);
            }
            if !l.tabs.is_empty() {
                // Each gap: where the torch stops and where it pierces again.
                step["tabs"] = json!(l
                    .tabs
                    .iter()
                    .map(|t| json!({ "from": [t.from.x, t.from.y], "to": [t.to.x, t.to.y] }))
                    .collect::<Vec<_>>());
            }
        }
    }
}

/// The error of contours where no lead fits, each named.
fn no_room(errors: Vec<LeadError>) -> String {
    let list: Vec<String> = errors.iter().map(LeadError::to_string).collect();
    format!(
        "{} contour(s) without room for the leads: {}",
        errors.len(),
        list.join("; ")
    )
}
