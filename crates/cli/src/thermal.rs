//! `cutroute solve`'s thermal options (issue #19): the heat penalty of CCP-Relax, the shop
//! rules as a check or as a hard repair, and the report's `heat`, `rule_violations` and
//! per-step `t`.

use cutroute_engine::{enforce_thermal_rules, PathRepairError};
use cutroute_geometry::{MachineParameters, Nest, Objective, Route};
use cutroute_protocol::{SolverKind, ThermalSettings};
use cutroute_thermal::{check_rules, route_pierces, HeatModel, RuleParams, RuleSet, ThermalError};
use serde_json::{json, Value};

use crate::report::StepReport;

/// The thermal flags of `solve`.
#[derive(clap::Args, Clone, Debug)]
pub struct ThermalArgs {
    /// Heat-affected radius σ of the heat model, mm (H is reported for every solver).
    #[arg(long, value_name = "MM", default_value_t = 50.0)]
    thermal_sigma: f64,
    /// Cooling time τ of the heat model, s.
    #[arg(long, value_name = "S", default_value_t = 60.0)]
    thermal_tau: f64,
    /// nearest, ccp, chain, sccp, gsccp and aoe minimise their objective + W·H (W in objective
    /// units per unit of H; 0: H only reported); heuristic and exact price H's consecutive
    /// terms on their arcs and relax their final pierce points on it.
    #[arg(long, value_name = "W", default_value_t = 0.0)]
    thermal_weight: f64,
    /// The rules checked and reported (and enforced with --rules-hard): a list of
    /// part,sheet,islands. None unless given (all three with --rules-hard). Path routes
    /// (sccp, gsccp, aoe) are judged by their contour route: a contour is done when its last
    /// piece is cut and starts where its first piece does.
    #[arg(long, value_name = "LIST")]
    rules: Option<String>,
    /// Repair the solver's route until the rules hold (whole parts reordered, pierce points
    /// moved; a path route that breaks them becomes its contour route repaired, as standard
    /// cutting); bounds and certificates stay those of the problem without rules.
    #[arg(long)]
    rules_hard: bool,
}

/// The parsed thermal settings.
#[derive(Clone)]
pub struct Thermal {
    model: HeatModel,
    weight: f64,
    rules: RuleSet,
    hard: bool,
}

impl ThermalArgs {
    pub fn parse(&self) -> Result<Thermal, String> {
        let model = HeatModel::new(self.thermal_sigma, self.thermal_tau)
            .map_err(|e| format!("--thermal-sigma/--thermal-tau: {e}"))?;
        if !(self.thermal_weight >= 0.0 && self.thermal_weight.is_finite()) {
            return Err(format!(
                "--thermal-weight {}: must be finite and non-negative",
                self.thermal_weight
            ));
        }
        let rules = match (&self.rules, self.rules_hard) {
            (Some(list), _) => RuleSet::parse(list).map_err(|e| format!("--rules: {e}"))?,
            (None, true) => RuleSet::ALL,
            (None, false) => RuleSet::parse("").map_err(|e| format!("--rules: {e}"))?,
        };
        Ok(Thermal {
            model,
            weight: self.thermal_weight,
            rules,
            hard: self.rules_hard,
        })
    }
}

impl Thermal {
    /// The settings the engine runs the job with: σ, τ and the weight (nearest, ccp and chain
    /// price H in their search). Rules and their repair stay with the CLI, which applies them
    /// after bringing a kerf route back onto the real contours ([`Thermal::enforce`]), and
    /// checks them once, on the route it prints ([`Thermal::report`]).
    pub fn engine_settings(&self) -> ThermalSettings {
        ThermalSettings {
            sigma_mm: self.model.sigma_mm,
            tau_s: self.model.tau_s,
            weight: self.weight,
            rules: RuleSet::NONE,
            hard: false,
        }
    }

    /// Says on stderr when a heat weight is given to a solver that prices only part of H.
    pub fn warn_unpriced(&self, solver: SolverKind) {
        if self.weight <= 0.0 {
            return;
        }
        match solver {
            SolverKind::Ccp
            | SolverKind::Chain
            | SolverKind::NearestNeighbour
            | SolverKind::Sccp
            | SolverKind::Gsccp
            | SolverKind::Aoe => {}
            SolverKind::Heuristic | SolverKind::Exact => eprintln!(
                "cutroute: {}'s order search prices only H's terms between consecutive pierces; \
                 --thermal-weight also relaxes its final pierce points on objective + W·H (and \
                 drops the discrete lb)",
                solver.name()
            ),
        }
    }

    /// With `--rules-hard`, the route repaired until the rules hold (what is left is reported
    /// by [`Thermal::report`]), then, with a heat weight, its pierce points relaxed on
    /// objective + W·H among those the part rule admits (the engine's
    /// `enforce_thermal_rules`, as the app's hard mode); else the route as it is.
    pub fn enforce(
        &self,
        nest: &Nest,
        route: Route,
        machine: &MachineParameters,
        objective: Objective,
    ) -> Result<Route, ThermalError> {
        if !self.hard {
            return Ok(route);
        }
        let settings = ThermalSettings {
            rules: self.rules,
            hard: true,
            ..self.engine_settings()
        };
        enforce_thermal_rules(nest, route, &settings, machine, objective)
    }

    /// With `--rules-hard`, a path route whose contour route breaks the rules becomes that
    /// contour route repaired, cut as standard cutting (`Some`); `None`: the route stays.
    pub fn enforce_paths(
        &self,
        nest: &Nest,
        route: &cutroute_geometry::PathRoute,
        machine: &MachineParameters,
        objective: Objective,
    ) -> Result<Option<cutroute_geometry::PathRoute>, PathRepairError> {
        if !self.hard {
            return Ok(None);
        }
        let settings = ThermalSettings {
            rules: self.rules,
            hard: true,
            ..self.engine_settings()
        };
        cutroute_engine::enforce_thermal_rules_on_paths(nest, route, &settings, machine, objective)
    }

    /// Adds `heat` (one source per tool-on path), `thermal`, `rule_violations` (on the route's
    /// contour route) and each path's `t` to a path-route report.
    pub fn report_paths(
        &self,
        report: &mut Value,
        nest: &Nest,
        route: &cutroute_geometry::PathRoute,
        machine: &MachineParameters,
        objective: Objective,
    ) -> Result<(), ThermalError> {
        let pierces = cutroute_thermal::path_route_pierces(route, machine);
        let settings = ThermalSettings {
            rules: self.rules,
            ..self.engine_settings()
        };
        let counts = cutroute_engine::check_path_rules(nest, route, &settings)?.counts();
        report["heat"] = json!(self.model.load(&pierces));
        report["thermal"] = json!({
            "sigma_mm": self.model.sigma_mm,
            "tau_s": self.model.tau_s,
            "weight": self.weight,
            "weight_unit": format!("{} per unit of H", objective.name()),
            "rules_hard": self.hard,
        });
        report["rule_violations"] = json!({
            "part": counts.part,
            "sheet": counts.sheet,
            "islands": counts.islands,
        });
        if let Some(paths) = report["route"]["paths"].as_array_mut() {
            for (path, pierce) in paths.iter_mut().zip(&pierces) {
                path["t"] = json!(pierce.time);
            }
        }
        Ok(())
    }

    /// Adds `heat`, `thermal` and `rule_violations` to a route report, and each step's `t`.
    pub fn report(
        &self,
        report: &mut Value,
        steps: &mut [StepReport],
        nest: &Nest,
        route: &Route,
        machine: &MachineParameters,
        objective: Objective,
    ) -> Result<(), ThermalError> {
        let pierces = route_pierces(route, nest, machine)?;
        let counts = check_rules(nest, route, self.rules, &RuleParams::default())?.counts();
        report["heat"] = json!(self.model.load(&pierces));
        report["thermal"] = json!({
            "sigma_mm": self.model.sigma_mm,
            "tau_s": self.model.tau_s,
            "weight": self.weight,
            "weight_unit": format!("{} per unit of H", objective.name()),
            "rules_hard": self.hard,
        });
        if self.hard {
            report["thermal"]["bounds"] =
                json!("lb and certificates are those of the problem without the rules");
        }
        report["rule_violations"] = json!({
            "part": counts.part,
            "sheet": counts.sheet,
            "islands": counts.islands,
        });
        for (step, pierce) in steps.iter_mut().zip(&pierces) {
            step.t = Some(pierce.time);
        }
        Ok(())
    }
}
