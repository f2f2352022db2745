//! The thermal settings of a job (issue #19): what the machine/material panel and the CLI's
//! `--thermal-*` and `--rules` flags set.

use cutroute_thermal::{HeatModel, RuleSet};
use serde::{Deserialize, Serialize};

/// The material's heat model, the heat penalty's weight and the shop rules.
///
/// The default is "off": weight 0 (no solver prices heat) and no rule checked or enforced; H is
/// still reported under σ = 50 mm, τ = 60 s, the CLI's defaults.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ThermalSettings {
    /// Heat-affected radius σ, mm.
    pub sigma_mm: f64,
    /// Cooling time τ, s.
    pub tau_s: f64,
    /// The penalty's weight in objective units (s for time, price units for cost) per unit of
    /// H; nearest, ccp, chain, sccp, gsccp and aoe minimise objective + weight·H when it is
    /// positive (heuristic and exact price its consecutive terms).
    pub weight: f64,
    /// The rules checked (and reported as violations).
    pub rules: RuleSet,
    /// Whether the final route is repaired until the selected rules hold
    /// (`cutroute_thermal::enforce_rules`; a path route through its contour route).
    pub hard: bool,
}

impl Default for ThermalSettings {
    fn default() -> Self {
        let model = HeatModel::default();
        ThermalSettings {
            sigma_mm: model.sigma_mm,
            tau_s: model.tau_s,
            weight: 0.0,
            rules: RuleSet::NONE,
            hard: false,
        }
    }
}

/// A thermal setting out of range, named in plain words.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ThermalSettingsError {
    /// σ or τ is not finite and positive: the heat model's own error.
    #[error("thermal σ/τ: {0}")]
    Model(#[from] cutroute_thermal::ThermalError),
    /// The heat penalty's weight is negative or not finite.
    #[error("thermal weight {0}: must be finite and non-negative")]
    Weight(f64),
}

impl ThermalSettings {
    /// The heat model, checked (σ and τ finite and positive).
    pub fn model(&self) -> Result<HeatModel, cutroute_thermal::ThermalError> {
        HeatModel::new(self.sigma_mm, self.tau_s)
    }

    /// Checks every setting: σ, τ as [`ThermalSettings::model`], the weight finite and
    /// non-negative. An error names the setting in plain words.
    pub fn validate(&self) -> Result<(), ThermalSettingsError> {
        self.model()?;
        if !(self.weight >= 0.0 && self.weight.is_finite()) {
            return Err(ThermalSettingsError::Weight(self.weight));
        }
        Ok(())
    }

    /// Whether a solver prices heat.
    pub fn penalised(&self) -> bool {
        self.weight > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SolverParams;

    #[test]
    fn requests_without_thermal_settings_read_as_off() {
        let mut json = serde_json::to_value(SolverParams::default()).unwrap();
        json.as_object_mut().unwrap().remove("thermal");
        let params: SolverParams = serde_json::from_value(json).unwrap();
        assert_eq!(params.thermal, ThermalSettings::default());
        assert!(!params.thermal.penalised());
        assert_eq!(params.thermal.rules, RuleSet::NONE);
    }

    #[test]
    fn partial_thermal_settings_keep_the_other_defaults() {
        let settings: ThermalSettings = serde_json::from_str(r#"{"weight": 100}"#).unwrap();
        assert_eq!(settings.weight, 100.0);
        assert_eq!(settings.sigma_mm, 50.0);
        assert!(settings.validate().is_ok());
        let bad = ThermalSettings {
            tau_s: 0.0,
            ..settings
        };
        assert!(bad.validate().is_err());
        let negative = ThermalSettings {
            weight: -1.0,
            ..settings
        };
        assert!(negative.validate().is_err());
    }

    #[test]
    fn settings_errors_name_the_setting_and_keep_the_model_error_as_source() {
        use std::error::Error;
        let bad = ThermalSettings {
            tau_s: 0.0,
            ..ThermalSettings::default()
        };
        let err = bad.validate().unwrap_err();
        assert!(matches!(err, ThermalSettingsError::Model(_)), "{err:?}");
        assert!(err.to_string().starts_with("thermal σ/τ: invalid"), "{err}");
        assert!(err.source().is_some());
        let negative = ThermalSettings {
            weight: -1.0,
            ..ThermalSettings::default()
        };
        assert_eq!(
            negative.validate().unwrap_err().to_string(),
            "thermal weight -1: must be finite and non-negative"
        );
    }
}
