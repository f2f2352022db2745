//! Command-line options for what goes in and how the machine is set up: the sheet of a
//! multi-sheet file (`--sheet N`), a machine profile (`--profile FILE.json`) and a G-code
//! preset (`--preset NAME`).
//!
//! Precedence, lowest first: built-in defaults, the profile, the task file (`solve --task`),
//! then the individual flags (`--speeds`, `--cost`, `--feed`, `--dwell`, `--torch-on`, …).
//! The preset comes from `--preset`, else the profile's `gcode_preset`, else `generic`; the
//! profile's header and footer lines replace the preset's.
//!
//! ```text
//! cutroute inspect project.tfnesting            # lists the sheets
//! cutroute solve project.tfnesting --sheet 2 --profile plasma3.json
//! cutroute convert nest.dxf out.nc --preset fanuc --dwell 1.5
//! ```

use std::path::{Path, PathBuf};

use clap::builder::PossibleValue;
use cutroute_gcode::{GcodeOptions, GcodePreset};
use cutroute_geometry::MachineParameters;
use cutroute_protocol::MachineProfile;

/// `--sheet N`: which sheet of a multi-sheet file (T-FLEX project) to open.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct SheetArg {
    /// Sheet of a multi-sheet file (T-FLEX project), counted from 1; `inspect` lists them.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub sheet: Option<u64>,
}

impl SheetArg {
    /// The sheet counted from 0, as the engine counts.
    pub fn index(self) -> usize {
        self.sheet.map_or(0, |n| (n - 1) as usize)
    }
}

/// `--profile FILE.json`: a machine profile.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ProfileArg {
    /// Machine profile (JSON: name, machine speeds/pierce time/prices, G-code preset, header
    /// and footer); explicit flags override it.
    #[arg(long, value_name = "FILE.json")]
    pub profile: Option<PathBuf>,
}

impl ProfileArg {
    /// The profile read and checked, when one is given.
    pub fn load(&self) -> Result<Option<MachineProfile>, String> {
        self.profile.as_deref().map(read_profile).transpose()
    }
}

/// Reads and checks a machine profile; errors name the file and the place in it.
pub fn read_profile(path: &Path) -> Result<MachineProfile, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    // A byte-order mark, as Windows editors write, is not part of the JSON.
    let json = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let profile: MachineProfile =
        serde_json::from_str(json).map_err(|e| format!("{}: {e}", path.display()))?;
    profile
        .check()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    // The same ranges as the flags (a tab count of 4·10¹⁸ is no machine's).
    if let Some(kerf) = &profile.kerf {
        kerf.check()
            .map_err(|e| format!("{}: {}", path.display(), e.in_profile()))?;
    }
    if let Some(name) = &profile.gcode_preset {
        name.parse::<GcodePreset>()
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(profile)
}

/// The machine of the profile, else the defaults.
pub fn base_machine(profile: Option<&MachineProfile>) -> MachineParameters {
    profile.map_or_else(MachineParameters::default, |p| p.machine)
}

/// A G-code preset as a command-line choice (`--help` lists the names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PresetArg(pub GcodePreset);

impl clap::ValueEnum for PresetArg {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [PresetArg; 6] = [
            PresetArg(GcodePreset::ALL[0]),
            PresetArg(GcodePreset::ALL[1]),
            PresetArg(GcodePreset::ALL[2]),
            PresetArg(GcodePreset::ALL[3]),
            PresetArg(GcodePreset::ALL[4]),
            PresetArg(GcodePreset::ALL[5]),
        ];
        &ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.0.name()).help(self.0.description()))
    }
}

/// The preset's options for `machine`: `--preset`, else the profile's, else generic; the
/// profile's header and footer replace the preset's. The caller applies explicit flags.
pub fn preset_options(
    preset: Option<PresetArg>,
    profile: Option<&MachineProfile>,
    machine: &MachineParameters,
) -> Result<GcodeOptions, String> {
    let from_profile = profile
        .and_then(|p| p.gcode_preset.as_deref())
        .map(str::parse::<GcodePreset>)
        .transpose()
        .map_err(|e| e.to_string())?;
    let preset = preset
        .map(|p| p.0)
        .or(from_profile)
        .unwrap_or(GcodePreset::Generic);
    let mut options = preset.options(machine);
    if let Some(header) = profile.and_then(|p| p.gcode_header.clone()) {
        options.header = header;
    }
    if let Some(footer) = profile.and_then(|p| p.gcode_footer.clone()) {
        options.footer = footer;
    }
    Ok(options)
}

/// Adds the sheet list to an `inspect` summary when the file has several sheets.
pub fn add_sheets(summary: &mut serde_json::Value, sheets: &[String], sheet: usize) {
    if let (false, serde_json::Value::Object(fields)) = (sheets.is_empty(), summary) {
        fields.insert("sheets".into(), serde_json::json!(sheets));
        fields.insert("sheet".into(), serde_json::json!(sheet + 1));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_a_choice() {
        use clap::ValueEnum;
        let names: Vec<String> = PresetArg::value_variants()
            .iter()
            .filter_map(|p| p.to_possible_value())
            .map(|v| v.get_name().to_owned())
            .collect();
        let expected: Vec<&str> = GcodePreset::ALL.iter().map(|p| p.name()).collect();
        assert_eq!(names, expected);
    }

    #[test]
    fn the_profile_sets_the_dialect_and_the_flag_wins() {
        let mut profile = MachineProfile::new("t", MachineParameters::default());
        profile.gcode_preset = Some("fanuc".into());
        profile.gcode_footer = Some(vec!["M02".into()]);
        let machine = profile.machine;
        let options = preset_options(None, Some(&profile), &machine).unwrap();
        assert_eq!(
            options.dwell_format,
            cutroute_gcode::DwellFormat::PMilliseconds
        );
        assert_eq!(options.footer, ["M02"]);
        let options = preset_options(
            Some(PresetArg(GcodePreset::GrblLaser)),
            Some(&profile),
            &machine,
        )
        .unwrap();
        assert_eq!(options.torch_on, "M04 S1000");
        assert_eq!(options.footer, ["M02"]);
    }
}
