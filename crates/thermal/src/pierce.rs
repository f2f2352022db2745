//! Heat-aware pierce points: the relaxation step of a penalised search.
//!
//! CCP-Relax places each pierce point where it shortens the idle path most; with a heat
//! penalty the best place may be elsewhere on the contour, away from the pierces just before
//! and after it (a part's outer contour pierced next to its last hole heats the same spot
//! twice within seconds). This pass moves one pierce point at a time to the candidate point of
//! its contour with the least idle length to its neighbours plus the weight times its kernels
//! with the steps near it in time, and keeps the result only if the route's whole objective
//! (idle + weight · H, recomputed) fell.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{Entry, MachineParameters, Nest, Point, Route};

use crate::layout::samples;
use crate::{route_pierces, HeatModel, ThermalError};

/// Kernels below e⁻¹² are not worth summing for a local choice.
const MAX_EXPONENT: f64 = 12.0;

/// `route` with pierce points moved along their contours to lower
/// `idle length + weight_mm · H` (`passes` sweeps over the steps). Steps entered by a tool-on
/// link, and those a link leaves from, keep their points. `candidates` (per step; `None` = the
/// contour's sample points) restricts the choice, e.g. to [`crate::admissible_pierce_points`].
/// Returns the route unchanged when no move lowers the objective.
pub fn relax_pierce_points(
    nest: &Nest,
    route: &Route,
    machine: &MachineParameters,
    model: &HeatModel,
    weight_mm: f64,
    passes: usize,
    candidates: Option<&[Option<Vec<Point>>]>,
) -> Result<Route, ThermalError> {
    model.validate()?;
    let objective = |r: &Route| -> Result<f64, ThermalError> {
        Ok(r.idle_length() + weight_mm * model.load(&route_pierces(r, nest, machine)?))
    };
    let before = objective(route)?;
    let mut current = route.clone();
    let n = current.steps.len();
    let (space, time) = (0.5 / (model.sigma_mm * model.sigma_mm), 1.0 / model.tau_s);
    for _ in 0..passes {
        // Times from the pass's start (a moved point shifts later times by a few idle
        // milliseconds); points kept current, so each step sees its neighbours' new places.
        let mut pierces = route_pierces(&current, nest, machine)?;
        let mut moved = false;
        for i in 0..n {
            let linked = |k: usize| {
                current
                    .steps
                    .get(k)
                    .is_some_and(|s| matches!(s.entry, Entry::Link(_)))
            };
            if linked(i) || linked(i + 1) {
                continue;
            }
            let Some(contour) = nest.contour(current.steps[i].contour) else {
                continue;
            };
            let previous = if i == 0 {
                current.start
            } else {
                current.steps[i - 1].pierce_point
            };
            let next = match current.steps.get(i + 1) {
                Some(s) => Some(s.pierce_point),
                None => current.finish,
            };
            let t = pierces[i].time;
            let cost = |x: Point| {
                let idle = previous.distance(x) + next.map_or(0.0, |q| x.distance(q));
                let mut heat = 0.0;
                let near = pierces[..i]
                    .iter()
                    .rev()
                    .take_while(|p| (t - p.time) * time <= MAX_EXPONENT)
                    .chain(
                        pierces[i + 1..]
                            .iter()
                            .take_while(|p| (p.time - t) * time <= MAX_EXPONENT),
                    );
                for p in near {
                    let exponent = (x - p.point).norm_squared() * space + (p.time - t).abs() * time;
                    if exponent <= MAX_EXPONENT {
                        heat += (-exponent).exp_libm();
                    }
                }
                idle + weight_mm * heat
            };
            let here = cost(current.steps[i].pierce_point);
            let points = match candidates.and_then(|c| c.get(i)) {
                Some(Some(points)) => points.clone(),
                _ => samples(contour),
            };
            let best = points
                .into_iter()
                .map(|x| (cost(x), x))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((value, x)) = best {
                if value < here - 1e-9 {
                    current.steps[i].pierce_point = x;
                    pierces[i].point = x;
                    moved = true;
                }
            }
        }
        if !moved {
            break;
        }
    }
    Ok(if objective(&current)? < before {
        current
    } else {
        route.clone()
    })
}
