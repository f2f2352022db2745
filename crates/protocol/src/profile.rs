//! Machine profiles: a named machine's speeds, pierce time, prices and G-code dialect, kept as
//! JSON so a shop keeps one file per machine and hands it to the CLI (`--profile FILE.json`)
//! or, later, to the app.
//!
//! The time and cost model is [`MachineParameters`] itself (not a copy of its fields); the
//! G-code dialect is a preset name of `cutroute-gcode` (`GcodePreset`, e.g. `"fanuc"`) with
//! optional header and footer lines that replace the preset's. Every field but `name` and
//! `machine` may be left out. Unknown fields are refused, so a misspelt field is not silently
//! ignored.
//!
//! ```
//! use cutroute_protocol::MachineProfile;
//!
//! let json = r#"{
//!   "name": "Plasma table 3",
//!   "machine": { "idle_speed": 400, "cut_speed": 25, "pierce_time": 0.8,
//!                "idle_price_per_metre": 0.05, "cut_price_per_metre": 1.2, "pierce_price": 0.3 },
//!   "gcode_preset": "qtplasmac",
//!   "gcode_footer": ["M30"]
//! }"#;
//! let profile: MachineProfile = serde_json::from_str(json).unwrap();
//! profile.check().unwrap();
//! assert_eq!(profile.machine.cut_speed, 25.0);
//! assert_eq!(profile.gcode_header, None); // the preset's header stays
//! ```

use cutroute_geometry::{KerfSettings, MachineParameters};
use serde::{Deserialize, Serialize};

/// A named machine: its time and cost model and its G-code dialect.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineProfile {
    /// The machine's name, for people.
    pub name: String,
    /// Speeds (mm/s), pierce time (s) and prices (per metre, per pierce).
    pub machine: MachineParameters,
    /// The G-code preset's name (`generic`, `grbl-laser`, `qtplasmac`, `mach3-plasma`, `fanuc`,
    /// `kometa-2p32m`); `None` keeps the generic dialect.
    #[serde(default)]
    pub gcode_preset: Option<String>,
    /// Header lines replacing the preset's, when given.
    #[serde(default)]
    pub gcode_header: Option<Vec<String>>,
    /// Footer lines replacing the preset's, when given.
    #[serde(default)]
    pub gcode_footer: Option<Vec<String>>,
    /// The full cutting route of the machine and material: kerf, clearances d₁ and d₂, leads,
    /// overcut, tabs (the CLI's `--kerf` … flags, which win when they turn kerf on); `None`
    /// keeps the idealised route.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kerf: Option<KerfSettings>,
}

/// A profile whose numbers cannot be a machine's.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProfileError {
    /// A speed that is not a positive finite number.
    #[error("{field} = {value}: a speed must be a positive number (mm/s)")]
    BadSpeed {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A time or price that is negative or not finite.
    #[error("{field} = {value}: must be a finite non-negative number")]
    Negative {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A header or footer line with a line break (it would become two blocks).
    #[error("{field}: line {text:?} contains a line break")]
    LineBreak {
        /// `gcode_header` or `gcode_footer`.
        field: &'static str,
        /// The line.
        text: String,
    },
}

impl MachineProfile {
    /// The profile of `machine` under `name`, with the generic G-code dialect.
    pub fn new(name: impl Into<String>, machine: MachineParameters) -> Self {
        Self {
            name: name.into(),
            machine,
            gcode_preset: None,
            gcode_header: None,
            gcode_footer: None,
            kerf: None,
        }
    }

    /// Checks that the numbers can be a machine's (serde checks only the types).
    pub fn check(&self) -> Result<(), ProfileError> {
        let m = &self.machine;
        for (field, value) in [("idle_speed", m.idle_speed), ("cut_speed", m.cut_speed)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ProfileError::BadSpeed { field, value });
            }
        }
        for (field, value) in [
            ("pierce_time", m.pierce_time),
            ("idle_price_per_metre", m.idle_price_per_metre),
            ("cut_price_per_metre", m.cut_price_per_metre),
            ("pierce_price", m.pierce_price),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ProfileError::Negative { field, value });
            }
        }
        if let Some(k) = &self.kerf {
            for (field, value) in [
                ("kerf.kerf", k.kerf),
                ("kerf.pierce_clearance", k.pierce_clearance),
                ("kerf.switch_off_clearance", k.switch_off_clearance),
                ("kerf.lead_in.length", k.lead_in.length),
                ("kerf.lead_out.length", k.lead_out.length),
                ("kerf.overcut", k.overcut),
                ("kerf.tabs.width", k.tabs.width),
            ] {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(ProfileError::Negative { field, value });
                }
            }
        }
        for (field, lines) in [
            ("gcode_header", &self.gcode_header),
            ("gcode_footer", &self.gcode_footer),
        ] {
            if let Some(text) = lines.iter().flatten().find(|l| l.contains(['\n', '\r'])) {
                return Err(ProfileError::LineBreak {
                    field,
                    text: text.clone(),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_profile_survives_a_json_round_trip() {
        let profile = MachineProfile {
            gcode_preset: Some("fanuc".into()),
            gcode_header: Some(vec!["G54".into()]),
            kerf: Some(KerfSettings {
                kerf: 2.0,
                pierce_clearance: 5.0,
                lead_in: cutroute_geometry::LeadSpec::new(cutroute_geometry::LeadShape::Arc, 8.0),
                ..KerfSettings::default()
            }),
            ..MachineProfile::new("Kometa", MachineParameters::default())
        };
        let json = serde_json::to_string_pretty(&profile).unwrap();
        let back: MachineProfile = serde_json::from_str(&json).unwrap();
        assert_eq!(back, profile);
        back.check().unwrap();
    }

    #[test]
    fn misspelt_fields_and_impossible_numbers_are_refused() {
        let json = r#"{"name": "x", "machine": {"idle_speed": 1, "cut_speed": 1,
            "pierce_time": 0, "idle_price_per_metre": 0, "cut_price_per_metre": 0,
            "pierce_price": 0}, "gcode_presset": "fanuc"}"#;
        let e = serde_json::from_str::<MachineProfile>(json).unwrap_err();
        assert!(e.to_string().contains("gcode_presset"), "{e}");
        let mut profile = MachineProfile::new("x", MachineParameters::default());
        profile.machine.cut_speed = 0.0;
        assert!(matches!(
            profile.check(),
            Err(ProfileError::BadSpeed {
                field: "cut_speed",
                ..
            })
        ));
        profile.machine.cut_speed = 1.0;
        profile.kerf = Some(KerfSettings {
            kerf: -1.0,
            ..KerfSettings::default()
        });
        assert!(matches!(
            profile.check(),
            Err(ProfileError::Negative {
                field: "kerf.kerf",
                ..
            })
        ));
        profile.kerf = None;
        profile.gcode_footer = Some(vec!["M30\nG00 X0".into()]);
        assert!(matches!(
            profile.check(),
            Err(ProfileError::LineBreak { .. })
        ));
    }
}
