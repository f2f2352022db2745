//! Named post-processor presets: the G-code dialects of common cutting controllers.
//!
//! A preset is a [`GcodeOptions`] (header and footer lines, torch codes, dwell format, arcs,
//! decimals) filled with a machine's feed rate and pierce time, plus the [`ReadOptions`] that
//! read its programs back, so every preset is checked by the project's own reader.
//!
//! ```
//! use cutroute_gcode::{GcodePreset, read_gcode, write_gcode};
//! use cutroute_geometry::{MachineParameters, Point, Span, ToolMove, Toolpath};
//!
//! let at = Point::new(10.0, 0.0);
//! let path = Toolpath {
//!     start: Point::new(0.0, 0.0),
//!     moves: vec![
//!         ToolMove::Idle { from: Point::new(0.0, 0.0), to: at },
//!         ToolMove::Pierce { at, step: 0 },
//!         ToolMove::Cut { step: 0, span: Span::new(at, Point::new(20.0, 0.0), 0.0), link: false },
//!     ],
//! };
//! let preset: GcodePreset = "fanuc".parse()?;
//! let options = preset.options(&MachineParameters::default());
//! let program = write_gcode(&path, &options)?;
//! assert!(program.contains("G04 P7000")); // the default 7 s pierce, in milliseconds
//! let back = read_gcode(&program, &preset.read_options())?;
//! assert_eq!(back.pierce_count(), 1);
//! assert!((back.dwell_time() - 7.0).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use cutroute_geometry::MachineParameters;

use crate::read::ReadOptions;
use crate::write::{ArcOutput, DistanceMode, DwellFormat, GcodeOptions, KerfCompensation};

/// A named G-code dialect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GcodePreset {
    /// cutroute's own default: `M03`/`M05`, `G04 P<s>`, I/J arcs, absolute, `M30`.
    Generic,
    /// GRBL 1.1 in laser mode (`$32=1`, a machine setting, not part of the program): `M04`
    /// dynamic power (the beam dims as the head slows in corners) with `S1000` full power,
    /// `G04 P<s>`, I/J arcs.
    GrblLaser,
    /// LinuxCNC with QtPlasmaC: `M03 $0 S1` / `M05 $0` (spindle 0 is the plasma torch), the
    /// harmless modal codes QtPlasmaC's own post writes (`G17 G40 G49 G80 G94`, `G91.1` for
    /// incremental arc centres); QtPlasmaC times the pierce from its material table, and the
    /// `G04 P<s>` kept here only adds to it.
    QtPlasmac,
    /// Mach3 plasma: `M03`/`M05`, `G91.1` (Mach3's incremental I/J mode made explicit),
    /// `G04 P<s>` (Mach3's default dwell unit is seconds), line numbers.
    Mach3Plasma,
    /// Fanuc-style controller: `G04 P<ms>` as an integer number of milliseconds, line numbers
    /// N10, N20, …, `M03`/`M05`, I/J arcs (always incremental on Fanuc, so no `G91.1`).
    Fanuc,
    /// The gas cutting machine «Комета» with CNC 2P32M (the dissertation's Fig. 1.5, see
    /// `docs/science/model-and-pcgtsp.md`). Known from the printed fragment: incremental
    /// coordinates (`G91`), line numbers N1, N2, …, `M71 T1` before each cut and `M74 T1`
    /// after it, `M70 T1` at the start, `M75 T1` and `M02` at the end, I/J arcs, no dwell (the
    /// controller times the pierce after `M71`). Unknown, chosen conservatively: the fragment's
    /// integer coordinates seem to be 0.1 mm units, but nothing states it, so this preset
    /// writes millimetres with one decimal under an explicit `G21`, which a controller that
    /// does not know `G21` refuses rather than misreads; check the unit on the machine.
    ///
    /// One decimal cannot hold most arcs: rounded to 0.1 mm, an arc's end is up to 0.14 mm
    /// off its circle, beyond what controllers accept (0.002 mm or 0.1 % of the radius, which
    /// the writer keeps to). Such arcs are written as `G01` chords within 0.05 mm of the arc
    /// (half the last digit); arcs whose rounded ends still fit a written centre stay arcs
    /// when the arc so written stays as close to the true one as the chords would (small
    /// arcs, whose centre must move by a quantum to fit, become chords). What the controller
    /// cuts is then within 0.13 mm of the route, and its length differs from the route's by up
    /// to 0.14 mm a move: the 0.1 mm grid is the machine's resolution.
    ///
    /// Like every incremental program, it starts with an absolute `G90 G00 X… Y…` to the
    /// route's start before `G91`, so the first move does not depend on where the head stands.
    Kometa2p32m,
}

impl GcodePreset {
    /// Every preset, in the order the CLI lists them.
    pub const ALL: [GcodePreset; 6] = [
        GcodePreset::Generic,
        GcodePreset::GrblLaser,
        GcodePreset::QtPlasmac,
        GcodePreset::Mach3Plasma,
        GcodePreset::Fanuc,
        GcodePreset::Kometa2p32m,
    ];

    /// The preset's name on the command line and in machine profiles.
    pub fn name(self) -> &'static str {
        match self {
            GcodePreset::Generic => "generic",
            GcodePreset::GrblLaser => "grbl-laser",
            GcodePreset::QtPlasmac => "qtplasmac",
            GcodePreset::Mach3Plasma => "mach3-plasma",
            GcodePreset::Fanuc => "fanuc",
            GcodePreset::Kometa2p32m => "kometa-2p32m",
        }
    }

    /// One line saying what the preset is for.
    pub fn description(self) -> &'static str {
        match self {
            GcodePreset::Generic => "M03/M05, G04 P seconds, I/J arcs (cutroute's default)",
            GcodePreset::GrblLaser => "GRBL 1.1 laser mode: M04 S1000 dynamic power, G04 P seconds",
            GcodePreset::QtPlasmac => "LinuxCNC QtPlasmaC: M03 $0 S1 / M05 $0",
            GcodePreset::Mach3Plasma => "Mach3 plasma: M03/M05, G91.1, line numbers",
            GcodePreset::Fanuc => "Fanuc-style: G04 P in milliseconds, N10 line numbers",
            GcodePreset::Kometa2p32m => {
                "gas cutter «Комета», CNC 2P32M: G91, M71/M74 T1, no dwell (mm, see docs)"
            }
        }
    }

    /// The dialect with `machine`'s cutting feed and pierce time.
    pub fn options(self, machine: &MachineParameters) -> GcodeOptions {
        let base = GcodeOptions::for_machine(machine);
        let lines = |items: &[&str]| items.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        match self {
            GcodePreset::Generic => base,
            GcodePreset::GrblLaser => GcodeOptions {
                torch_on: "M04 S1000".into(),
                torch_off: "M05".into(),
                header: lines(&["G17", "G94"]),
                footer: lines(&["M02"]),
                ..base
            },
            GcodePreset::QtPlasmac => GcodeOptions {
                torch_on: "M03 $0 S1".into(),
                torch_off: "M05 $0".into(),
                header: lines(&["G17 G40 G49 G80 G94", "G91.1", "G64"]),
                footer: lines(&["M30"]),
                ..base
            },
            GcodePreset::Mach3Plasma => GcodeOptions {
                line_numbers: true,
                line_number_step: 10,
                header: lines(&["G17 G40 G49 G80", "G91.1"]),
                footer: lines(&["M30"]),
                ..base
            },
            GcodePreset::Fanuc => GcodeOptions {
                line_numbers: true,
                line_number_step: 10,
                dwell_format: DwellFormat::PMilliseconds,
                header: lines(&["G17 G40 G49 G80"]),
                footer: lines(&["M30"]),
                ..base
            },
            GcodePreset::Kometa2p32m => GcodeOptions {
                distance_mode: DistanceMode::Incremental,
                decimals: 1,
                line_numbers: true,
                line_number_step: 1,
                arcs: ArcOutput::CentreOffsets,
                torch_on: "M71 T1".into(),
                torch_off: "M74 T1".into(),
                dwell_format: DwellFormat::Omitted,
                header: lines(&["M70 T1"]),
                footer: lines(&["M75 T1", "M02"]),
                // The controller's character set and comment syntax are unknown.
                comments: false,
                ..base
            },
        }
    }

    /// The cutter compensation codes the preset's controller has, as written in a program:
    ///
    /// | preset | codes | why |
    /// |---|---|---|
    /// | generic, qtplasmac | `G41`/`G42 D<n>`, `G41.1`/`G42.1 D<diameter>` | LinuxCNC's |
    /// | mach3-plasma | `G41`/`G42 D<n>` | Mach3 has no `G41.1` |
    /// | fanuc | `G41`/`G42 D<n>` | `G41.1` is normal-direction control there, no offset |
    /// | grbl-laser | none | GRBL 1.1 has no cutter compensation |
    /// | kometa-2p32m | none | nothing known of the 2P32M's compensation |
    ///
    /// The writer uses the left-hand codes (`G41`, `G41.1`): the scrap is left of the cut.
    pub fn compensation_codes(self) -> &'static [&'static str] {
        match self {
            GcodePreset::Generic | GcodePreset::QtPlasmac => &["G41", "G42", "G41.1", "G42.1"],
            GcodePreset::Mach3Plasma | GcodePreset::Fanuc => &["G41", "G42"],
            GcodePreset::GrblLaser | GcodePreset::Kometa2p32m => &[],
        }
    }

    /// `Ok` when the preset's controller has the code `compensation` writes, else the refusal
    /// naming the preset.
    pub fn check_compensation(
        self,
        compensation: KerfCompensation,
    ) -> Result<(), UnsupportedCompensation> {
        let code = match compensation {
            KerfCompensation::InProgram => return Ok(()),
            KerfCompensation::ControllerDiameter => "G41.1",
            KerfCompensation::ControllerRegister(_) => "G41",
        };
        if self.compensation_codes().contains(&code) {
            Ok(())
        } else {
            Err(UnsupportedCompensation { preset: self, code })
        }
    }

    /// How the project's reader reads this dialect back (torch codes, dwell unit).
    pub fn read_options(self) -> ReadOptions {
        let defaults = ReadOptions::default();
        match self {
            GcodePreset::Fanuc => ReadOptions {
                dwell_p_milliseconds: true,
                ..defaults
            },
            GcodePreset::Kometa2p32m => ReadOptions {
                torch_on: vec![71],
                torch_off: vec![74],
                // One decimal: a rounded arc end may leave the radius by up to 0.07 mm.
                arc_tolerance_mm: 0.1,
                ..defaults
            },
            _ => defaults,
        }
    }
}

impl std::fmt::Display for GcodePreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Controller compensation asked of a preset whose controller lacks its code.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the {preset} preset's controller has no {code} cutter compensation ({}); compensate the kerf in the program instead", available(*.preset))]
pub struct UnsupportedCompensation {
    /// The preset.
    pub preset: GcodePreset,
    /// The code the compensation would write.
    pub code: &'static str,
}

fn available(preset: GcodePreset) -> String {
    match preset.compensation_codes() {
        [] => "it has none".into(),
        codes => format!("it has {}", codes.join(", ")),
    }
}

/// A preset name that is none of [`GcodePreset::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown G-code preset {0:?} (generic, grbl-laser, qtplasmac, mach3-plasma, fanuc, kometa-2p32m)")]
pub struct UnknownPreset(pub String);

impl std::str::FromStr for GcodePreset {
    type Err = UnknownPreset;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        GcodePreset::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| UnknownPreset(name.to_owned()))
    }
}
