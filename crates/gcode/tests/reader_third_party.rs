//! Other CAM programs' G-code (data/gcode-samples/): each style reads as the pierces and cut
//! length that LinuxCNC's interpreter computes for it, and as the numbers derived by hand from
//! its geometry.

mod reader_rs274;

use cutroute_gcode::{read_gcode, ReadOptions};
use std::f64::consts::PI;

fn sample(name: &str) -> String {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/gcode-samples")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// (file, GRBL laser mode, pierces, cut length by hand or `None` where only rs274 can tell).
const SAMPLES: [(&str, bool, usize, Option<f64>); 6] = [
    // G92 X0 Y0 first; a hole of radius 10 in two G2 halves, then a 100 × 50 rectangle.
    ("dxf2gcode-plasma.ngc", false, 2, Some(300.0 + 20.0 * PI)),
    // A hole of radius 5, then a half circle of radius 20 on a 40 × 40 outline (120 mm of lines).
    (
        "sheetcam-plasma.tap",
        false,
        2,
        Some(120.0 + 20.0 * PI + 10.0 * PI),
    ),
    // M4 once: a 20 × 20 square, a rapid (beam off), a 7 × 7 square, a 10 mm S0 move.
    ("lightburn-grbl.gc", true, 2, Some(80.0 + 28.0)),
    // M3 in the header: one pierce; a circle of radius 10 and a 30 × 30 square, Z ignored.
    ("inkscape-gcodetools.ngc", false, 1, Some(20.0 * PI + 120.0)),
    // LinuxCNC's own shipped plasma test (SheetCam's EMC post): 404 lines of letters.
    ("linuxcnc-plasmatest.ngc", false, 15, None),
    // LinuxCNC's parameters, a subroutine and loops: six holes of radius 5, a 120 × 80 outline.
    (
        "linuxcnc-parametric-plasma.ngc",
        false,
        7,
        Some(400.0 + 60.0 * PI),
    ),
];

#[test]
fn third_party_programs_read_as_the_controller_runs_them() {
    let rs274 = reader_rs274::rs274();
    for (name, laser, pierces, by_hand) in SAMPLES {
        let text = sample(name);
        let program =
            read_gcode(&text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(program.pierce_count(), pierces, "{name}");
        if let Some(cut) = by_hand {
            assert!(
                (program.cut_length() - cut).abs() < 1e-6,
                "{name}: {} vs {cut} by hand",
                program.cut_length()
            );
        }
        let Some(rs274) = &rs274 else { continue };
        let machine = reader_rs274::run(rs274, &text, 1.0, laser);
        assert_eq!(machine.error, None, "{name}");
        assert_eq!(machine.pierces.len(), program.pierce_count(), "{name}");
        for (a, b) in machine.pierces.iter().zip(program.pierce_points()) {
            assert!(a.distance(b) < 1e-3, "{name}: pierce {a:?} vs {b:?}");
        }
        // rs274 prints four decimals: a few 1e-5 mm per move.
        let tolerance = 1e-4 * program.motions.len() as f64;
        assert!(
            (machine.cut - program.cut_length()).abs() < tolerance,
            "{name}: cut {} by rs274, {} read",
            machine.cut,
            program.cut_length()
        );
        assert!(
            (machine.idle - program.idle_length()).abs() < tolerance,
            "{name}: idle {} by rs274, {} read",
            machine.idle,
            program.idle_length()
        );
    }
}

/// GRBL laser mode from the options: an `M03` program whose rapids switch the beam off.
#[test]
fn laser_mode_from_the_options_makes_every_rapid_a_new_pierce() {
    let text =
        "G21 G90\nM3 S500\nG0 X0 Y0\nG1 X10 F600\nG0 X20\nG1 X30\nG1 X40 S0\nG1 X50 S500\nM5\n";
    let plasma = read_gcode(text, &ReadOptions::default()).unwrap();
    assert_eq!(plasma.pierce_count(), 1);
    assert!(
        (plasma.cut_length() - 40.0).abs() < 1e-9,
        "S is ignored on a torch"
    );
    let laser = ReadOptions {
        laser_mode: true,
        ..ReadOptions::default()
    };
    let program = read_gcode(text, &laser).unwrap();
    assert_eq!(program.pierce_count(), 3);
    assert!((program.cut_length() - 30.0).abs() < 1e-9);
    let points = program.pierce_points();
    assert_eq!(points[1], cutroute_geometry::Point::new(20.0, 0.0));
    assert_eq!(points[2], cutroute_geometry::Point::new(40.0, 0.0));
}
