//! Each preset's controller has its own cutter compensation codes; asking for one it lacks is
//! refused with the preset's name.

use cutroute_gcode::{GcodePreset, KerfCompensation};

#[test]
fn presets_refuse_the_compensation_codes_their_controllers_lack() {
    let diameter = KerfCompensation::ControllerDiameter;
    let register = KerfCompensation::ControllerRegister(1);
    for preset in GcodePreset::ALL {
        assert!(preset
            .check_compensation(KerfCompensation::InProgram)
            .is_ok());
        let (g41_1, g41) = match preset {
            GcodePreset::Generic | GcodePreset::QtPlasmac => (true, true),
            GcodePreset::Mach3Plasma | GcodePreset::Fanuc => (false, true),
            GcodePreset::GrblLaser | GcodePreset::Kometa2p32m => (false, false),
        };
        assert_eq!(
            preset.check_compensation(diameter).is_ok(),
            g41_1,
            "{preset}"
        );
        assert_eq!(preset.check_compensation(register).is_ok(), g41, "{preset}");
    }
    let refusal = GcodePreset::Fanuc
        .check_compensation(diameter)
        .unwrap_err()
        .to_string();
    assert!(
        refusal.contains("fanuc") && refusal.contains("G41.1"),
        "{refusal}"
    );
    let refusal = GcodePreset::GrblLaser
        .check_compensation(register)
        .unwrap_err()
        .to_string();
    assert!(
        refusal.contains("grbl-laser") && refusal.contains("has none"),
        "{refusal}"
    );
}
