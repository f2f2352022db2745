//! The machine and material: speeds and prices, the kerf and leads of the full cutting route,
//! the heat model and shop rules, and the G-code export's dialect.

use cutroute_gcode::GcodePreset;
use cutroute_geometry::{KerfSettings, MachineParameters};
use cutroute_protocol::{Document, ThermalSettings};
use leptos::prelude::*;

use crate::export::GcodeChoice;
use crate::settings::Settings;

/// The machine, kerf and thermal settings, shared by their panels, the job and the exports.
#[derive(Clone, Copy)]
pub struct MachineSettings {
    /// Speeds, pierce time and prices.
    pub machine: RwSignal<MachineParameters>,
    /// The full cutting route: kerf, clearances, leads, overcut, tabs.
    pub kerf: RwSignal<KerfSettings>,
    /// The material's heat model, heat weight and shop rules.
    pub thermal: RwSignal<ThermalSettings>,
    /// The G-code export's dialect and lines.
    pub gcode: RwSignal<GcodeChoice>,
}

impl MachineSettings {
    /// The settings remembered or linked; G-code starts from the generic dialect.
    pub fn new(settings: &Settings) -> Self {
        Self {
            machine: RwSignal::new(settings.machine),
            kerf: RwSignal::new(settings.kerf),
            thermal: RwSignal::new(settings.thermal),
            gcode: RwSignal::new(GcodeChoice::of_preset(
                GcodePreset::Generic,
                &settings.machine,
            )),
        }
    }

    /// Takes the settings of `settings` (a lecture card's).
    pub fn restore(&self, settings: &Settings) {
        self.thermal.set(settings.thermal);
        self.kerf.set(settings.kerf);
        self.machine.set(settings.machine);
    }

    /// Writes the settings into `settings` (tracked).
    pub fn remember(&self, settings: &mut Settings) {
        settings.machine = self.machine.get();
        settings.thermal = self.thermal.get();
        settings.kerf = self.kerf.get();
    }

    /// A task file in an opened batch brings the machine's speeds (its start and finish are
    /// already the document's).
    pub fn take_task_speeds(&self, opened: &Document) {
        if let Some(speeds) = opened.task_speeds {
            self.machine.update(|m| *m = speeds.applied_to(*m));
        }
    }
}
