//! The reader as a controller reads: small programs with the codes that change the motion's
//! meaning (`G92` and its companions, inches, incremental moves and arc centres, `R` arcs,
//! cutter compensation as LinuxCNC models it), each checked against numbers derived by hand
//! and, where it is installed, against LinuxCNC's interpreter `rs274`.

mod reader_rs274;

use cutroute_gcode::{read_gcode, CompensationModel, Motion, Program, ReadOptions};
use cutroute_geometry::Point;
use std::f64::consts::PI;

const SQRT2: f64 = std::f64::consts::SQRT_2;

fn linuxcnc(radius: f64) -> ReadOptions {
    ReadOptions {
        compensation_radius: Some(radius),
        compensation_model: CompensationModel::LinuxCnc,
        ..ReadOptions::default()
    }
}

/// The reader's program agrees with rs274's canonical motion, when rs274 is installed.
fn agrees_with_rs274(name: &str, text: &str, program: &Program, radius: f64) {
    let Some(rs274) = reader_rs274::rs274() else {
        return;
    };
    let machine = reader_rs274::run(&rs274, text, radius, false);
    assert_eq!(machine.error, None, "{name}");
    assert_eq!(machine.pierces.len(), program.pierce_count(), "{name}");
    for (a, b) in machine.pierces.iter().zip(program.pierce_points()) {
        assert!(a.distance(b) < 1e-3, "{name}: pierce {a:?} vs {b:?}");
    }
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

/// rs274 refuses the program, when it is installed.
fn refused_by_rs274(name: &str, text: &str, radius: f64) {
    let Some(rs274) = reader_rs274::rs274() else {
        return;
    };
    let machine = reader_rs274::run(&rs274, text, radius, false);
    assert!(machine.error.is_some(), "{name}: rs274 accepts it");
}

#[test]
fn g92_offsets_the_coordinates_and_the_head_moves_on_continuously() {
    let text = "\
G21 G90
G0 X10 Y10
G92 X0 Y0
M3
G1 X5 F100
G1 Y5
M5
G92.2
G0 X0 Y0
G92.3
G0 X1 Y1
G92.1
G0 X2 Y2
M2
";
    let program = read_gcode(text, &ReadOptions::default()).unwrap();
    assert_eq!(program.pierce_points(), vec![Point::new(10.0, 10.0)]);
    assert!((program.cut_length() - 10.0).abs() < 1e-9);
    // 0 → (10, 10); (15, 15) → (0, 0) with no offset; → (11, 11) restored; → (2, 2) cancelled.
    let idle = 10.0 * SQRT2 + 15.0 * SQRT2 + 11.0 * SQRT2 + 9.0 * SQRT2;
    assert!((program.idle_length() - idle).abs() < 1e-9);
    assert_eq!(program.end, Point::new(2.0, 2.0));
    agrees_with_rs274("g92", text, &program, 1.0);
    // The common first line of DXF2GCODE and Inkscape's plasma programs reads as no offset.
    let dxf2gcode = "G21 G90\nG92 X0 Y0\nG0 X10 Y0\nM3\nG1 X20 F100\nM5\n";
    let program = read_gcode(dxf2gcode, &ReadOptions::default()).unwrap();
    assert_eq!(program.pierce_points(), vec![Point::new(10.0, 0.0)]);
    // G92 needs an axis, and cannot share its block with a motion.
    for (bad, column) in [("G92\nM2\n", 1), ("G0 G92 X0\nM2\n", 4)] {
        let error = read_gcode(bad, &ReadOptions::default()).unwrap_err();
        assert_eq!(error.location(), (1, column), "{bad}: {error}");
        refused_by_rs274(bad, bad, 1.0);
    }
}

#[test]
fn inches_incremental_moves_and_absolute_centres() {
    let text = "\
G20 G91 G90.1
G0 X1 Y0
M3
G2 X1 Y-1 I1 J-1 F10
G1 X-1
M5
G90 G91.1
G0 X0 Y0
M3
G3 X0 Y0 I0.5 J0
M5
M2
";
    let program = read_gcode(text, &ReadOptions::default()).unwrap();
    let inch = 25.4;
    // A quarter of radius 1 in, a line of 1 in, then a full circle of radius 0.5 in.
    let cut = inch * (PI / 2.0 + 1.0 + PI);
    assert!(
        (program.cut_length() - cut).abs() < 1e-9,
        "{}",
        program.cut_length()
    );
    assert_eq!(program.pierce_count(), 2);
    agrees_with_rs274("inches", text, &program, 1.0);
}

#[test]
fn radius_arcs_short_and_long() {
    let text = "G21 G90\nG0 X0 Y0\nM3\nG2 X10 Y0 R5 F100\nG3 X0 Y0 R-5\nM5\nM2\n";
    let program = read_gcode(text, &ReadOptions::default()).unwrap();
    // Half a turn each way (R 5 over a chord of 10 is a half circle whichever sign).
    assert!((program.cut_length() - 10.0 * PI).abs() < 1e-9);
    agrees_with_rs274("r arcs", text, &program, 1.0);
}

/// A programmed outline with a convex start, concave and convex corners, an arc the tool runs
/// inside, and a straight cancel move.
const COMPENSATED: &str = "\
G21 G90
G0 X-5 Y-5
M3
G41 D1 G1 X0 Y0 F100
G1 X10 Y0
G1 X10 Y10
G1 X5 Y5
G1 X0 Y10
G3 X0 Y0 I0 J-5
G40 G1 X-5 Y-5
M5
M2
";

#[test]
fn compensation_runs_as_linuxcnc_runs_it() {
    let program = read_gcode(COMPENSATED, &linuxcnc(1.0)).unwrap();
    let ends: Vec<Point> = program
        .motions
        .iter()
        .filter_map(|m| match m {
            Motion::Feed { span, .. } => Some(span.end),
            _ => None,
        })
        .collect();
    // The start-up move ends perpendicular to itself; an arc about (0, 0) joins the bottom
    // edge's offset; the concave corner at (10, 0) is the offsets' intersection (9, 1).
    let h = 0.5 * SQRT2;
    let expected_first = [
        Point::new(-h, h),
        Point::new(0.0, 1.0),
        Point::new(9.0, 1.0),
    ];
    for (e, p) in expected_first.iter().zip(&ends) {
        assert!(e.distance(*p) < 1e-9, "{ends:?}");
    }
    assert!(ends.last().unwrap().distance(Point::new(-5.0, -5.0)) < 1e-9);
    agrees_with_rs274("compensated", COMPENSATED, &program, 1.0);
    // To the right, and with the diameter in the program (G42.1 D2): the tool runs outside.
    let right = COMPENSATED.replace("G41 D1", "G42.1 D2");
    let program = read_gcode(&right, &linuxcnc(0.0)).unwrap();
    agrees_with_rs274("right", &right, &program, 1.0);
}

#[test]
fn compensation_refuses_what_linuxcnc_refuses() {
    // The start-up move no longer than the radius.
    let short = COMPENSATED.replace("G0 X-5 Y-5", "G0 X-0.5 Y-0.5");
    let error = read_gcode(&short, &linuxcnc(1.0)).unwrap_err();
    assert!(error.to_string().contains("start-up"), "{error}");
    refused_by_rs274("short entry", &short, 1.0);
    // A slot narrower than the tool: its concave corners cannot be reached.
    let notch = "\
G21 G90
G0 X-5 Y-5
M3
G41 D1 G1 X0 Y0 F100
G1 X10 Y0
G1 X10 Y10
G1 X5.5 Y10
G1 X5.5 Y15
G1 X5 Y15
G1 X5 Y10
G1 X0 Y10
G1 X0 Y0
G40 G1 X-5 Y-5
M5
";
    let error = read_gcode(notch, &linuxcnc(1.0)).unwrap_err();
    assert!(error.to_string().contains("gouging"), "{error}");
    refused_by_rs274("notch", notch, 1.0);
    // An arc the tool cannot run inside: a hole of radius 2 for a tool of radius 3.
    let hole =
        "G21 G90\nG0 X0 Y0\nM3\nG41 D1 G1 X10 Y0 F100\nG3 X10 Y0 I-2 J0\nG40 G1 X0 Y0\nM5\nM2\n";
    let error = read_gcode(hole, &linuxcnc(3.0)).unwrap_err();
    assert!(error.to_string().contains("arc"), "{error}");
    refused_by_rs274("hole", hole, 3.0);
    // A move shorter than its concave corner's retreat runs backwards; the convex corner
    // after it needs its end again.
    let backwards = "\
G21 G90
G0 X-1040 Y100
M3
G41.1 D1 G1 X-1050 Y115 F1000
G2 X-1072.435 Y118.363 I0.107 J77.239
G1 X-1072.436
G1 X-1072.911 Y118.509
G40 G1 X-1073.651 Y116.121
M5
M2
";
    let error = read_gcode(backwards, &linuxcnc(0.0)).unwrap_err();
    assert!(error.to_string().contains("line 7"), "{error}");
    refused_by_rs274("backwards, then a corner", backwards, 0.5);
    // Followed by a turn within LinuxCNC's tolerance instead, it stands: the tool backs up.
    let backs_up = "\
G21 G90
G0 X0 Y10
M3
G41.1 D1 G1 X0 Y0 F1000
G1 X10 Y0
G1 X20 Y-0.7
G1 X20.014
G1 X20.514 Y-0.709
G40 G1 X21 Y5
M5
M2
";
    let program = read_gcode(backs_up, &linuxcnc(0.0)).unwrap();
    agrees_with_rs274("backwards, then straight on", backs_up, &program, 0.5);
    // Without a radius for G41 D1, the error says where to give it.
    let error = read_gcode(COMPENSATED, &ReadOptions::default()).unwrap_err();
    assert!(
        error.to_string().contains("--compensation-radius"),
        "{error}"
    );
}

/// Compensation ends where LinuxCNC flushes it: at `G40` (the tool stays at its offset end
/// until the next move, which the interpreter reckons from the programmed point) or at the
/// program's end. Rapids are compensated as straight moves (a convex corner before one is a
/// straight traverse), a start-up move may be an arc, and a torch switch waits for the move
/// before it.
const FLUSHED: &str = "\
G21 G90
G0 X-5 Y-5
M3
G41.1 D2
G0 X0 Y0
F100
G1 X10 Y0
G0 X10 Y10
G1 X0 Y10
G1 X0.5 Y5.025
G1 X0 Y0
M5
G40
G0 Z5
G0 X-5 Y-5
G42.1 D2
G3 X10 Y0 I7.5 J2.5
G2 X20 Y0 I5 J0
G1 X20 Y-5
M3
G1 X25 Y-5
M2
";

#[test]
fn compensation_ends_where_linuxcnc_flushes_it() {
    let program = read_gcode(FLUSHED, &linuxcnc(0.0)).unwrap();
    // The torch goes off where the last compensated move ends, and the move along Z alone
    // after G40 takes the head from there to the programmed point.
    let off = program
        .motions
        .iter()
        .find_map(|m| match m {
            Motion::TorchOff { at, line: 12 } => Some(*at),
            _ => None,
        })
        .unwrap();
    let back = program
        .motions
        .iter()
        .find_map(|m| match m {
            Motion::Rapid { from, to, line: 14 } => Some((*from, *to)),
            _ => None,
        })
        .unwrap();
    assert!(back.0.distance(off) < 1e-9 && back.1.distance(Point::new(0.0, 0.0)) < 1e-9);
    assert!(off.distance(Point::new(0.0, 0.0)) > 0.9, "{off:?}");
    // The rapid up the right edge is offset like a feed: from the bottom edge's end (10, 1)
    // after the concave corner trimmed it, to (9, 9).
    assert!(rapid_targets(&program)
        .iter()
        .any(|p| p.distance(Point::new(9.0, 9.0)) < 1e-9));
    assert_eq!(program.pierce_count(), 2);
    agrees_with_rs274("flushed", FLUSHED, &program, 1.0);
}

#[test]
fn turns_within_linuxcncs_tolerance_are_no_corners() {
    // A concave turn of 0.03 rad: LinuxCNC neither trims the moves to their intersection nor
    // rounds the convex one after it; each move runs on from where the last one ended.
    let text = "\
G21 G90
G0 X0 Y-10
M3
G41.1 D2 G1 X0 Y0 F1000
G1 X10 Y0
G1 X20 Y0.3
G1 X30 Y0.3
G40 G1 X30 Y-10
M5
M2
";
    let program = read_gcode(text, &linuxcnc(0.0)).unwrap();
    let ends: Vec<Point> = program
        .motions
        .iter()
        .filter_map(|m| match m {
            Motion::Feed { span, line: 5, .. } => Some(span.end),
            _ => None,
        })
        .collect();
    assert!(
        ends.last().unwrap().distance(Point::new(10.0, 1.0)) < 1e-9,
        "{ends:?}"
    );
    agrees_with_rs274("small turns", text, &program, 1.0);
}

#[test]
fn about_a_half_turn_back_linuxcnc_decides_the_corner_by_its_own_rules() {
    let stretch = |side: &str, from: &str, moves: &str| {
        format!("G21 G90\nG0 {from}\nM3\n{side} G1 {moves}\nG40 G1 X-10 Y-10\nM5\nM2\n")
    };
    let cases = [
        // A spike back within LinuxCNC's tolerance of a half turn, to the concave side: it
        // goes round the tip as a convex corner.
        stretch(
            "G41.1 D2",
            "X-5 Y-5",
            "X0 Y0 F100\nG1 X10 Y0\nG1 X0 Y0.3\nG1 X-5 Y10",
        ),
        // Atop an "m": arc to arc, the tool outside both, is a concave corner.
        stretch(
            "G41.1 D2",
            "X-5 Y-5",
            "X0 Y0 F100\nG2 X10 Y0 I5 J0\nG2 X20 Y0 I5 J0\nG1 X20 Y-5",
        ),
        // An "h": over the round part, the tool outside it, then back up beside the stem.
        stretch(
            "G42.1 D2",
            "X15 Y-5",
            "X10 Y0 F100\nG3 X0 Y0 I-5 J0\nG1 X0 Y10\nG1 X-5 Y10",
        ),
        stretch(
            "G41.1 D2",
            "X-5 Y15",
            "X0 Y10 F100\nG1 X0 Y0\nG2 X10 Y0 I5 J0\nG1 X10 Y-5",
        ),
    ];
    for text in &cases {
        let program = read_gcode(text, &linuxcnc(0.0)).unwrap_or_else(|e| panic!("{text}: {e}"));
        agrees_with_rs274(text, text, &program, 1.0);
    }
    // The tip of the spike is rounded about the programmed corner (10, 0).
    let program = read_gcode(&cases[0], &linuxcnc(0.0)).unwrap();
    assert!(program.motions.iter().any(|m| matches!(
        m,
        Motion::Feed { span, line: 6, .. } if span.bulge != 0.0 && span.start.distance(Point::new(10.0, 1.0)) < 1e-9
    )));
}

#[test]
fn a_tool_change_stops_the_torch_and_takes_the_head_where_it_stands() {
    // LinuxCNC stops the spindle for M6 and reads the position back: the rapid after it runs
    // from where compensation left the tool, and the torch pierces again.
    let text = "\
G21 G90
G0 X0 Y-10
M3
G41.1 D2 G1 X0 Y0 F100
G1 X10 Y0
G40
T1 M6
G0 X20 Y0
M3
G1 X30 Y0
M5
M2
";
    let program = read_gcode(text, &linuxcnc(0.0)).unwrap();
    assert_eq!(program.pierce_count(), 2);
    assert!(program.motions.iter().any(|m| matches!(
        m,
        Motion::Rapid { from, line: 8, .. } if from.distance(Point::new(10.0, 1.0)) < 1e-9
    )));
    agrees_with_rs274("tool change", text, &program, 1.0);
}

#[test]
fn compensation_refuses_what_linuxcnc_refuses_when_it_ends() {
    let stretch = "G21 G90\nG0 X0 Y-10\nM3\nG41.1 D2 G1 X0 Y0 F100\nG1 X10 Y0\n";
    let cases = [
        // G40 flushes the last move with its end checked: one that runs backwards (shorter
        // than its concave corner's retreat) is refused there.
        (
            "G21 G90\nG0 X0 Y10\nM3\nG41.1 D1 G1 X0 Y0 F1000\nG1 X10 Y0\nG1 X20 Y-0.7\nG1 X20.014\nG40 G1 X21 Y5\nM5\nM2\n".to_string(),
            "line 8",
            0.5,
        ),
        (format!("{stretch}G40\nG2 X20 Y0 I5 J0\nM5\nM2\n"), "not an arc", 1.0),
        (format!("{stretch}T1 M6\nG40\nM5\nM2\n"), "tool change", 1.0),
        (
            "G21 G90\nG0 X0 Y0\nF100\nG41.1 D2\nG1 Z-1\nG1 X10 Y0\nG40\nM2\n".to_string(),
            "start-up",
            1.0,
        ),
    ];
    for (text, says, radius) in &cases {
        let error = read_gcode(text, &linuxcnc(0.0)).unwrap_err();
        assert!(error.to_string().contains(says), "{text}: {error}");
        refused_by_rs274(says, text, *radius);
    }
    // Switched on and off without a move, compensation does nothing.
    let idle = format!("{stretch}G40\nG41.1 D2\nG40\nG1 X20 Y0\nM5\nM2\n");
    let program = read_gcode(&idle, &linuxcnc(0.0)).unwrap();
    agrees_with_rs274("on and off", &idle, &program, 1.0);
}

#[test]
fn headers_comments_and_what_the_reader_leaves_to_the_controller() {
    // A Fanuc program number, `%` tape marks, `(MSG,…)`, `;` comments, N words.
    let text = "%\nO1234 (bracket)\n(MSG, load the sheet)\nN10 G21 G90 ; metric\nN20 G0 X1 Y1\nN30 M3\nN40 G1 X2 F100\nN50 M5\n%\n";
    let program = read_gcode(text, &ReadOptions::default()).unwrap();
    assert_eq!(program.pierce_count(), 1);
    assert!((program.cut_length() - 1.0).abs() < 1e-9);
}

/// LinuxCNC's parameters, expressions and O-word control flow: a program that uses every kind
/// reads as rs274 runs it and as worked out by hand.
#[test]
fn parameters_expressions_and_o_words_run_as_linuxcnc_runs_them() {
    let text = "\
G21 G90
#<side> = 10
#<_count> = 0
o100 sub
  G0 X#2 Y0 (a square of side #1 at X #2)
  M3
  G1 X[#2 + #1] F100
  G1 Y#1
  G1 X#2
  G1 Y0
  M5
  #<_count> = [#<_count> + 1]
o100 endsub
o101 repeat [3]
  o100 call [#<side>] [#<_count> * 20]
o101 endrepeat
#1 = 0
o102 while [#1 LT 4]
  #1 = [#1 + 1]
  o103 if [#1 EQ 2]
    o102 continue
  o103 elseif [#1 EQ 4]
    o102 break
  o103 else
    G0 X[100 + #1 * 10] Y50
    M3
    G1 Y[50 + SQRT[25]]
    M5
  o103 endif
o102 endwhile
o104 do
  #1 = [#1 - 1]
o104 while [#1 GT 0]
#3 = 7 G0 X[#3 + 200] Y#1 (the assignment takes effect after the line)
G0 X[#3 + 200] Y[2 ** 3 ** 2 / 64]
M2
G0 X999 (after the program's end)
";
    let program = read_gcode(text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    // Three squares of 40 mm (at X 0, 20, 40: the global counts the calls), and the while
    // loop's two 5 mm cuts (#1 = 1 and 3; 2 continues, 4 breaks).
    assert_eq!(
        program.pierce_points(),
        [
            (0.0, 0.0),
            (20.0, 0.0),
            (40.0, 0.0),
            (110.0, 50.0),
            (130.0, 50.0)
        ]
        .map(|(x, y)| Point::new(x, y))
    );
    assert!((program.cut_length() - 130.0).abs() < 1e-9);
    // The do-while runs once (#1 from 4 to 3): after a `break`, LinuxCNC's next do-while end
    // does not loop back. `#3 = 7` is not seen on its own line.
    let rapids = rapid_targets(&program);
    assert_eq!(
        rapids[rapids.len() - 2..],
        [Point::new(200.0, 3.0), Point::new(207.0, 1.0)]
    );
    assert_eq!(program.end, Point::new(207.0, 1.0));
    agrees_with_rs274("o-words", text, &program, 1.0);
}

/// `G04 P… G00 X… Y…`: the dwell, then the move, in one block.
#[test]
fn a_dwell_and_a_move_share_a_block() {
    let text = "G21 G90\nG04 P0.5 G0 X3 Y4\nM2\n";
    let program = read_gcode(text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(program.dwell_time(), 0.5);
    assert_eq!(program.end, Point::new(3.0, 4.0));
    assert!((program.idle_length() - 5.0).abs() < 1e-12);
    agrees_with_rs274("dwell and move", text, &program, 1.0);
}

/// `G53`: one G0/G1 move in machine coordinates, past the G92 offset.
#[test]
fn g53_moves_in_machine_coordinates() {
    let text = "G21 G90\nG92 X10 Y10\nG53 G0 X5 Y5\nG0 X1 Y1\nG53 Z0\nM2\n";
    let program = read_gcode(text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let rapids = rapid_targets(&program);
    // The G92 offset is -10 on both axes: X1 Y1 is (-9, -9) where the program started.
    assert_eq!(rapids, [Point::new(5.0, 5.0), Point::new(-9.0, -9.0)]);
    agrees_with_rs274("g53", text, &program, 1.0);
    for (bad, location) in [("G53\n", (1, 1)), ("G0 X0\nG53 G2 X5 Y5 R5\n", (2, 1))] {
        let error = read_gcode(bad, &ReadOptions::default()).unwrap_err();
        assert_eq!(error.location(), location, "{bad}: {error}");
        assert!(error.to_string().contains("G53"), "{bad}: {error}");
        refused_by_rs274(bad, &format!("{bad}M2\n"), 1.0);
    }
}

/// LinuxCNC's polar coordinates: `@` distance and `^` angle from the origin; in `G91` both add
/// to the head's own.
#[test]
fn polar_coordinates_turn_about_the_origin() {
    let text = "G21 G90\nM3\nF100 G1 @5 ^90\nG91 ^90\n^90\n^90\n^90\nG90 G0 X0 Y0\nM5\nM2\n";
    let program = read_gcode(text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    // Up the Y axis to (0, 5), then round a square of corners on the axes.
    assert!((program.cut_length() - (5.0 + 20.0 * SQRT2)).abs() < 1e-9);
    assert!(program.end.distance(Point::new(0.0, 0.0)) < 1e-12);
    agrees_with_rs274("polar", text, &program, 1.0);
    for (bad, column) in [("G1 X1 @2\n", 7), ("G2 @1 ^90 R1\n", 4)] {
        let error = read_gcode(bad, &ReadOptions::default()).unwrap_err();
        assert_eq!(error.location(), (1, column), "{bad}: {error}");
    }
}

/// What the reader cannot know or run is refused where it stands, as rs274 refuses it.
#[test]
fn what_only_the_machine_knows_and_what_never_ends_are_refused_where_they_stand() {
    for (bad, location, says) in [
        (
            "F#<_hal[plasmac.cut-feed-rate]>\n",
            (1, 2),
            "#<_hal[plasmac.cut-feed-rate]>",
        ),
        ("G0 X#<_ini[axis_x]max_limit>\n", (1, 5), "INI file"),
        ("G0 X#<undefined>\n", (1, 5), "not defined"),
        ("G0 X[1 / 0]\n", (1, 8), "division by zero"),
        ("o<touchoff> call [1]\n", (1, 1), "o<touchoff> call"),
        ("G0 X1\no100 if [0]\nG0 X2\n", (2, 1), "never closed"),
        ("o100 if [1]\no101 endif\n", (2, 1), "o101 endif"),
        ("M3\nM190 P1\n", (2, 1), "USER_M_PATH"),
    ] {
        let error = read_gcode(bad, &ReadOptions::default()).unwrap_err();
        assert_eq!(error.location(), location, "{bad}: {error}");
        assert!(error.to_string().contains(says), "{bad}: {error}");
        refused_by_rs274(bad, &format!("{bad}M2\n"), 1.0);
    }
    // A loop that never ends: rs274 would run it forever; the reader stops and says where.
    let error = read_gcode(
        "G21\n#1 = 0\no1 while [1]\n#1 = [#1 + 1]\no1 endwhile\nM2\n",
        &ReadOptions::default(),
    )
    .unwrap_err();
    assert!(error.to_string().contains("never ends"), "{error}");
    assert!((3..=5).contains(&error.location().0), "{error}");
    // So does recursion without end.
    let error = read_gcode(
        "o1 sub\no1 call\no1 endsub\no1 call\nM2\n",
        &ReadOptions::default(),
    )
    .unwrap_err();
    assert_eq!(error.location(), (2, 1), "{error}");
    // G96/G97 (spindle speed modes) and QtPlasmaC's output and feed codes change no motion.
    let text = "G21 G97 S100\nG96 S10 D100\nM66 P0 L0\nM67 E0 Q5\nM68 E0 Q3\nM62 P1\nM63 P1\nM64 P1\nM65 P1\nM52 P1\nM53 P1\nG0 X#5399 Y1\nM3\nG1 X10 F100\nM5\nM2\n";
    let program = read_gcode(text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(program.pierce_points(), [Point::new(0.0, 1.0)]);
    agrees_with_rs274("harmless codes", text, &program, 1.0);
    // Tool data depends on the machine's tool table, which the reader does not have (rs274
    // answers from its own): refused.
    let error = read_gcode("G0 X#5400\n", &ReadOptions::default()).unwrap_err();
    assert_eq!(error.location(), (1, 5), "{error}");
    assert!(error.to_string().contains("tool table"), "{error}");
}

/// Programs the post-processor writes with `G41.1 D<kerf>` and `G41 D1`: the reader's LinuxCNC
/// model and rs274 accept and refuse the same ones, and agree on what the accepted ones cut.
#[test]
fn written_compensated_programs_read_as_rs274_runs_them() {
    use cutroute_gcode::{route_gcode, GcodeOptions, KerfCompensation};
    use cutroute_geometry::{generate_nest, KerfSettings, LeadFitter, LeadShape, LeadSpec, Route};
    let Some(rs274) = reader_rs274::rs274() else {
        return;
    };
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 3.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Line, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 1.0,
        ..KerfSettings::default()
    };
    let mut compared = 0;
    for seed in [4, 7] {
        let nest = generate_nest(12, seed);
        let origin = Point::new(0.0, 0.0);
        let route = Route::innermost_first(&nest, origin, Some(origin));
        let route = LeadFitter::new(&nest, settings).attach(&route).unwrap();
        for compensation in [
            KerfCompensation::ControllerDiameter,
            KerfCompensation::ControllerRegister(1),
        ] {
            let options = GcodeOptions {
                kerf_compensation: compensation,
                ..GcodeOptions::default()
            };
            let text = route_gcode(&nest, &route, &options).unwrap();
            let name = format!("seed {seed} {compensation:?}");
            let machine = reader_rs274::run(&rs274, &text, 1.0, false);
            let read = read_gcode(&text, &linuxcnc(1.0));
            match (&machine.error, &read) {
                (None, Ok(program)) => {
                    agrees_with_rs274(&name, &text, program, 1.0);
                    compared += 1;
                }
                (Some(_), Err(_)) => {}
                (e, r) => panic!("{name}: rs274 {e:?}, reader {:?}", r.as_ref().err()),
            }
        }
    }
    assert!(compared > 0, "no program was accepted by both");
}

/// Where each rapid of a program goes, in order.
fn rapid_targets(program: &Program) -> Vec<Point> {
    program
        .motions
        .iter()
        .filter_map(|m| match m {
            Motion::Rapid { to, .. } => Some(*to),
            _ => None,
        })
        .collect()
}
