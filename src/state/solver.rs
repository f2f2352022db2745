//! The solver panel's choices: which solver, and how long and how it runs.

use cutroute_geometry::Objective;
use cutroute_protocol::SolverKind;
use leptos::prelude::*;

use crate::settings::{objective_from_name, Settings};

/// The solver and its parameters, as the solver panel sets them.
#[derive(Clone, Copy)]
pub struct SolverSettings {
    pub kind: RwSignal<SolverKind>,
    pub time_limit_s: RwSignal<f64>,
    /// Seed of the solver's random choices.
    pub seed: RwSignal<u64>,
    /// Spacing of the discrete solvers' candidate pierce points, mm.
    pub step_mm: RwSignal<f64>,
    /// What routes are compared by, and what the solvers that weigh routes minimise.
    pub objective: RwSignal<Objective>,
}

impl SolverSettings {
    /// The choices remembered or linked.
    pub fn new(settings: &Settings) -> Self {
        let this = Self {
            kind: RwSignal::new(SolverKind::NearestNeighbour),
            time_limit_s: RwSignal::new(0.0),
            seed: RwSignal::new(0),
            step_mm: RwSignal::new(0.0),
            objective: RwSignal::new(Objective::default()),
        };
        this.restore(settings);
        this
    }

    /// Takes the choices of `settings` (a linked solver name the page does not know leaves the
    /// solver as it is).
    pub fn restore(&self, settings: &Settings) {
        if let Some(kind) = SolverKind::from_name(&settings.solver) {
            self.kind.set(kind);
        }
        self.time_limit_s.set(settings.time_limit_s);
        self.seed.set(settings.seed);
        self.step_mm.set(settings.step_mm);
        self.objective
            .set(objective_from_name(&settings.objective).unwrap_or_default());
    }

    /// Writes the choices into `settings` (tracked: an effect calling this follows them).
    pub fn remember(&self, settings: &mut Settings) {
        settings.solver = self.kind.get().name().to_string();
        settings.time_limit_s = self.time_limit_s.get();
        settings.seed = self.seed.get();
        settings.step_mm = self.step_mm.get();
        settings.objective = self.objective.get().name().to_string();
    }

    /// The spacing of candidate pierce points to draw: only the discrete solvers place them.
    pub fn candidates_step(&self) -> Option<f64> {
        matches!(self.kind.get(), SolverKind::Heuristic | SolverKind::Exact)
            .then(|| self.step_mm.get())
    }
}
