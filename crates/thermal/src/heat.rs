//! Heat accumulation on the machine clock.
//!
//! Each step of a route is a heat source at its entry point `M_i` (where the cut of its contour
//! starts), switched on at the machine time `t_i` the head gets there: the start of its pierce,
//! or, for a step entered by a tool-on link (chain cutting), the end of that link. A chained
//! contour is cut all the same, so it heats the sheet all the same: only where and when matter.
//! Times come from the route's own time model ([`Toolpath`] on the [`ToolClock`] of
//! [`MachineParameters`]), never re-derived here.
//!
//! The route's thermal load is
//! `H = Σ_i Σ_{j<i} exp(−|M_i − M_j|² / (2σ²)) · exp(−(t_i − t_j) / τ)`:
//! a pierce close in space and time to earlier ones scores close to 1 per neighbour; a pierce far
//! away (≫ σ) or late (≫ τ) scores nothing.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{
    MachineParameters, Nest, PathRoute, Point, Route, ToolClock, ToolMove, Toolpath,
};
use serde::{Deserialize, Serialize};

use crate::ThermalError;

/// Pairs further apart in time than this many τ are skipped: each would add less than
/// e⁻⁴⁰ ≈ 4·10⁻¹⁸, far below the 1e-6 relative accuracy promised for H.
const TIME_CUTOFF_TAUS: f64 = 40.0;

/// The material's heat parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeatModel {
    /// Heat-affected radius σ, mm.
    pub sigma_mm: f64,
    /// Cooling time τ, s.
    pub tau_s: f64,
}

impl Default for HeatModel {
    /// σ = 50 mm, τ = 60 s: the defaults of the CLI and the benchmark.
    fn default() -> Self {
        HeatModel {
            sigma_mm: 50.0,
            tau_s: 60.0,
        }
    }
}

/// One heat source: where and when the torch starts on a contour.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pierce {
    /// The entry point `M_i`, mm.
    pub point: Point,
    /// Machine time `t_i`, s.
    pub time: f64,
}

impl HeatModel {
    /// A model with validated parameters (both finite and positive).
    pub fn new(sigma_mm: f64, tau_s: f64) -> Result<HeatModel, ThermalError> {
        let model = HeatModel { sigma_mm, tau_s };
        model.validate()?;
        Ok(model)
    }

    /// Checks that σ and τ are finite and positive.
    pub fn validate(&self) -> Result<(), ThermalError> {
        for (name, value) in [("sigma", self.sigma_mm), ("tau", self.tau_s)] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(ThermalError::InvalidParameter {
                    name,
                    value,
                    expected: "finite and positive",
                });
            }
        }
        Ok(())
    }

    /// What an earlier source at squared distance `distance_squared` (mm²), switched on `dt`
    /// seconds before, contributes.
    #[inline]
    pub fn kernel(&self, distance_squared: f64, dt: f64) -> f64 {
        (-distance_squared / (2.0 * self.sigma_mm * self.sigma_mm) - dt / self.tau_s).exp_libm()
    }

    /// The thermal load H of sources in time order (times non-decreasing; pairs more than 40 τ
    /// apart are skipped, which needs that order).
    pub fn load(&self, pierces: &[Pierce]) -> f64 {
        self.load_truncated(pierces, TIME_CUTOFF_TAUS)
    }

    /// H without the pairs whose kernel exponent `d²/(2σ²) + Δt/τ` exceeds `max_exponent`
    /// (each would add less than `exp(−max_exponent)`): what a search evaluating H thousands
    /// of times a second can afford. Times must be non-decreasing.
    pub fn load_truncated(&self, pierces: &[Pierce], max_exponent: f64) -> f64 {
        pierces
            .iter()
            .enumerate()
            .map(|(i, a)| self.added_load(&pierces[..i], a.point, a.time, max_exponent))
            .sum()
    }

    /// What a source at `p` switched on at time `t` adds to H after the `earlier` ones (in
    /// time order, all at or before `t`), without kernels below `exp(−max_exponent)`. Greedy
    /// solvers price their next pierce with it.
    pub fn added_load(&self, earlier: &[Pierce], p: Point, t: f64, max_exponent: f64) -> f64 {
        let (space, time) = (0.5 / (self.sigma_mm * self.sigma_mm), 1.0 / self.tau_s);
        let mut total = 0.0;
        for b in earlier.iter().rev() {
            let dt = (t - b.time) * time;
            if dt > max_exponent {
                break;
            }
            let exponent = (p - b.point).norm_squared() * space + dt;
            if exponent <= max_exponent {
                total += (-exponent).exp_libm();
            }
        }
        total
    }

    /// The thermal load of `route` over `nest` under `machine`'s time model.
    pub fn route_load(
        &self,
        route: &Route,
        nest: &Nest,
        machine: &MachineParameters,
    ) -> Result<f64, ThermalError> {
        Ok(self.load(&route_pierces(route, nest, machine)?))
    }

    /// The temperature field of the sources (in time order) at point `p` and time `t` (same
    /// units as H: the sum of the kernels of the sources switched on at or before `t`). This is
    /// what a heat-map layer draws, frame by frame.
    pub fn temperature_at(&self, pierces: &[Pierce], p: Point, t: f64) -> f64 {
        let switched_on = pierces.partition_point(|s| s.time <= t);
        self.added_load(&pierces[..switched_on], p, t, TIME_CUTOFF_TAUS)
    }
}

/// The heat sources of a route: per step, where the torch goes on (the pierce point M of its
/// leads, else its point on the contour) and the machine time the head gets there (pierce
/// start, or end of the step's tool-on link). Fails on an unknown contour.
pub fn route_pierces(
    route: &Route,
    nest: &Nest,
    machine: &MachineParameters,
) -> Result<Vec<Pierce>, ThermalError> {
    let toolpath = Toolpath::new(route, nest).map_err(|e| ThermalError::Route(Box::new(e)))?;
    Ok(step_times(&toolpath, machine, route.steps.len())
        .into_iter()
        .zip(&route.steps)
        .map(|(time, step)| Pierce {
            point: step.switch_on_point(),
            time,
        })
        .collect())
}

/// The heat sources of a route of tool-on paths: one per path, at its pierce.
pub fn path_route_pierces(route: &PathRoute, machine: &MachineParameters) -> Vec<Pierce> {
    let toolpath = Toolpath::from_path_route(route);
    step_times(&toolpath, machine, route.paths.len())
        .into_iter()
        .zip(&route.paths)
        .map(|(time, path)| Pierce {
            point: path.pierce,
            time,
        })
        .collect()
}

/// Per step, the start time of its first move that is not a link piece: the pierce, or the
/// first cut of the contour after a link. A step without such moves (an empty contour) takes
/// the time its predecessor's moves end.
fn step_times(toolpath: &Toolpath, machine: &MachineParameters, steps: usize) -> Vec<f64> {
    let clock = ToolClock::new(toolpath, machine);
    let mut times: Vec<Option<f64>> = vec![None; steps];
    for (index, m) in toolpath.moves.iter().enumerate() {
        let step = match *m {
            ToolMove::Pierce { step, .. }
            | ToolMove::Cut {
                step, link: false, ..
            } => step,
            _ => continue,
        };
        if let Some(slot) = times.get_mut(step) {
            if slot.is_none() {
                *slot = clock.start_of(index);
            }
        }
    }
    let mut last = 0.0;
    times
        .into_iter()
        .map(|t| {
            last = t.unwrap_or(last);
            last
        })
        .collect()
}
