//! The nearest-neighbour route: the baseline every real solver must beat.

use std::collections::HashMap;

use cutroute_geometry::{ContourRef, CutStep, MachineParameters, Nest, Point, Route};
use cutroute_protocol::{JobId, Progress};
use cutroute_thermal::{HeatModel, Pierce};
use web_time::{Duration, Instant};

use crate::{EngineError, Job, JobStatus};

/// Greedy routing: from the current tool position, cut the nearest contour that may be cut now
/// (only once every contour inside it is cut), piercing at its nearest vertex. With a heat
/// penalty ([`NearestNeighbourJob::with_heat`]) "nearest" means the least idle length plus the
/// weight times the heat the pierce adds to the route's load H (`cutroute-thermal`), on the
/// machine clock of the route so far.
pub struct NearestNeighbourJob {
    job_id: JobId,
    nest: Nest,
    start: Point,
    finish: Option<Point>,
    started: Instant,
    route: Option<Route>,
    idle_length: f64,
    heat: Option<NearestHeat>,
}

/// The heat penalty of the greedy choice.
struct NearestHeat {
    model: HeatModel,
    /// Millimetres of idle per unit of H.
    weight_mm: f64,
    machine: MachineParameters,
}

/// Heat kernels below e⁻¹² are not worth summing for a greedy choice.
const HEAT_MAX_EXPONENT: f64 = 12.0;

impl NearestNeighbourJob {
    /// Prepare the job; fails on a nest with no contours.
    pub fn new(
        job_id: JobId,
        nest: Nest,
        start: Point,
        finish: Option<Point>,
    ) -> Result<Self, EngineError> {
        if nest.parts.iter().all(|part| part.contours.is_empty()) {
            return Err(EngineError::EmptyNest);
        }
        Ok(Self {
            job_id,
            nest,
            start,
            finish,
            started: Instant::now(),
            route: None,
            idle_length: 0.0,
            heat: None,
        })
    }

    /// Adds `weight_mm` millimetres of idle per unit of heat load H to each choice (time of
    /// the pierces under `machine`). A zero weight changes nothing.
    pub fn with_heat(
        mut self,
        model: HeatModel,
        weight_mm: f64,
        machine: MachineParameters,
    ) -> Self {
        self.heat = (weight_mm > 0.0).then_some(NearestHeat {
            model,
            weight_mm,
            machine,
        });
        self
    }

    fn solve(&mut self) {
        let forest = self.nest.containment_forest();
        let mut remaining: Vec<ContourRef> = self.nest.contour_refs().collect();
        // Contours still to cut inside each contour: it waits for them (inner before outer).
        let mut inner_left: HashMap<ContourRef, usize> = remaining
            .iter()
            .map(|&r| (r, forest.children(r).len()))
            .collect();
        let mut position = self.start;
        let mut steps = Vec::with_capacity(remaining.len());
        let mut idle_length = 0.0;
        // The heat sources so far and the machine clock (heat penalty only).
        let mut sources: Vec<Pierce> = Vec::new();
        let mut clock = 0.0;
        while !remaining.is_empty() {
            let mut best: Option<(usize, Point, f64)> = None;
            for (index, contour_ref) in remaining.iter().enumerate() {
                if inner_left.get(contour_ref).is_some_and(|&left| left > 0) {
                    continue;
                }
                let contour = &self.nest.parts[contour_ref.part].contours[contour_ref.contour];
                for vertex in &contour.vertices {
                    let d = distance(position, vertex.point);
                    let value = match &self.heat {
                        None => d,
                        Some(h) => {
                            let t = clock + d / h.machine.idle_speed;
                            d + h.weight_mm
                                * h.model
                                    .added_load(&sources, vertex.point, t, HEAT_MAX_EXPONENT)
                        }
                    };
                    if best.is_none_or(|(_, _, best_value)| value < best_value) {
                        best = Some((index, vertex.point, value));
                    }
                }
            }
            let Some((index, pierce_point, _)) = best else {
                break; // only contours without vertices remain
            };
            let d = distance(position, pierce_point);
            let contour_ref = remaining.swap_remove(index);
            if let Some(h) = &self.heat {
                clock += d / h.machine.idle_speed;
                sources.push(Pierce {
                    point: pierce_point,
                    time: clock,
                });
                let perimeter = self
                    .nest
                    .contour(contour_ref)
                    .map_or(0.0, |c| c.perimeter());
                clock += h.machine.pierce_time + perimeter / h.machine.cut_speed;
            }
            if let Some(left) = forest
                .parent(contour_ref)
                .and_then(|p| inner_left.get_mut(&p))
            {
                *left -= 1;
            }
            idle_length += d;
            position = pierce_point;
            steps.push(CutStep {
                contour: contour_ref,
                pierce_point,
                entry: Default::default(),
                leads: None,
            });
        }
        if let Some(finish) = self.finish {
            idle_length += distance(position, finish);
        }
        self.idle_length = idle_length;
        self.route = Some(Route {
            start: self.start,
            steps,
            finish: self.finish,
        });
    }
}

fn distance(a: Point, b: Point) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

impl Job for NearestNeighbourJob {
    fn step(&mut self, _budget: Duration) -> JobStatus {
        if self.route.is_none() {
            self.solve();
        }
        JobStatus::Done
    }

    fn progress(&self) -> Progress {
        Progress {
            job_id: self.job_id,
            elapsed_s: self.started.elapsed().as_secs_f64(),
            upper_bound: self.route.as_ref().map(|_| self.idle_length),
            lower_bound: None,
            phase: if self.route.is_some() {
                "done".into()
            } else {
                "starting".into()
            },
            route: self.route.clone(),
            tour: None,
            proven_optimal: false,
            states: None,
            certified: Vec::new(),
            path_route: None,
            alternatives: Vec::new(),
        }
    }
}
