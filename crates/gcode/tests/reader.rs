//! The reader on hand-written programs, the arc direction, located errors, and garbage.

use std::f64::consts::PI;

use cutroute_gcode::{
    read_gcode, write_gcode, ArcOutput, DistanceMode, GcodeError, GcodeOptions, GcodeReadError,
    Motion, ReadOptions,
};
use cutroute_geometry::{Point, Span, ToolMove, Toolpath};
use proptest::prelude::*;

fn read(text: &str) -> cutroute_gcode::Program {
    read_gcode(text, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn spans(text: &str) -> Vec<Span> {
    read(text)
        .motions
        .iter()
        .filter_map(|m| match m {
            Motion::Feed { span, .. } => Some(*span),
            _ => None,
        })
        .collect()
}

/// A quarter circle of radius 10 about the origin from (10, 0) to (0, 10): counter-clockwise.
fn quarter(bulge_sign: f64) -> Toolpath {
    let a = Point::new(10.0, 0.0);
    let z = Point::new(0.0, 10.0);
    let bulge = bulge_sign * (PI / 8.0).tan();
    Toolpath {
        start: a,
        moves: vec![
            ToolMove::Pierce { at: a, step: 0 },
            ToolMove::Cut {
                step: 0,
                span: Span::new(a, z, bulge),
                link: false,
            },
        ],
    }
}

#[test]
fn positive_bulge_is_g03_negative_is_g02() {
    let ccw = write_gcode(&quarter(1.0), &GcodeOptions::default()).unwrap();
    // Counter-clockwise about (0, 0): centre offset (-10, 0) from the start.
    assert!(ccw.contains("G03 X0.000 Y10.000 I-10.000 J0.000"), "{ccw}");
    // The clockwise arc between the same ends turns about (10, 10).
    let cw = write_gcode(&quarter(-1.0), &GcodeOptions::default()).unwrap();
    assert!(cw.contains("G02 X0.000 Y10.000 I0.000 J10.000"), "{cw}");
    // And back: the reader gives the bulge of the geometry crate.
    let read_options = ReadOptions {
        start: Point::new(10.0, 0.0),
        ..ReadOptions::default()
    };
    for (text, sign) in [(ccw, 1.0), (cw, -1.0)] {
        let program = read_gcode(&text, &read_options).unwrap();
        let feed = program
            .motions
            .iter()
            .find(|m| matches!(m, Motion::Feed { .. }));
        let Some(Motion::Feed { span, tool_on, .. }) = feed else {
            panic!("{:?}", program.motions)
        };
        assert!(tool_on);
        assert!((span.bulge - sign * (PI / 8.0).tan()).abs() < 1e-9);
        assert!((span.length() - 5.0 * PI).abs() < 1e-9);
    }
}

#[test]
fn r_arcs_full_circles_and_long_arcs() {
    // R > 0: the short arc; R < 0: the long one.
    let short = spans("G90 G01 X10 Y0 F100\nG03 X0 Y10 R10");
    let total: f64 = short[1..].iter().map(Span::length).sum();
    assert!((total - 5.0 * PI).abs() < 1e-9);
    let long = spans("G90 G01 X10 Y0 F100\nG03 X0 Y10 R-10");
    let total: f64 = long[1..].iter().map(Span::length).sum();
    assert!((total - 15.0 * PI).abs() < 1e-9, "{total}");
    assert!(long[1..].iter().all(|s| s.bulge > 0.0));
    // A full circle by I/J: ends coincide, two half-circles.
    let circle = spans("G0 X5 Y0\nG2 X5 Y0 I-5 J0 F100");
    // The G0 to (5, 0) is not a feed move; the circle is two half circles.
    assert_eq!(circle.len(), 2, "{circle:?}");
    let arc_length: f64 = circle.iter().map(Span::length).sum();
    assert!((arc_length - 10.0 * PI).abs() < 1e-9);
    assert!(circle[0].end.distance(Point::new(-5.0, 0.0)) < 1e-9);
    assert!(circle.iter().all(|s| s.bulge < 0.0), "clockwise");
}

#[test]
fn modes_units_comments_and_line_numbers() {
    let text = "%\n\
        N10 (a comment) G21 G90 G17 G54\n\
        N20 G00 X10 Y10 ; to the pierce point\n\
        N30 M03 $0 S1\n\
        N40 G04 P1.5\n\
        N50 G91 G01 X5 F1200\n\
        N60 Y5\n\
        n70 g1 x-5 y-5\n\
        N80 M05\n\
        /N90 G20 G90 G00 X1 Y1\n\
        N100 M30\n%\n";
    let program = read(text);
    assert_eq!(program.pierce_count(), 1);
    assert_eq!(program.pierce_points()[0], Point::new(10.0, 10.0));
    assert!((program.dwell_time() - 1.5).abs() < 1e-12);
    assert!((program.cut_length() - (10.0 + 50f64.sqrt())).abs() < 1e-9);
    // The last move is in inches: (1, 1) in = (25.4, 25.4) mm.
    assert_eq!(program.end, Point::new(25.4, 25.4));
    let idle = 200f64.sqrt() + (2.0 * 15.4f64 * 15.4).sqrt();
    assert!((program.idle_length() - idle).abs() < 1e-9);
    let feeds: Vec<_> = program
        .motions
        .iter()
        .filter_map(|m| match m {
            Motion::Feed { feed, .. } => *feed,
            _ => None,
        })
        .collect();
    assert_eq!(feeds, vec![1200.0; 3]);
}

#[test]
fn errors_say_where() {
    let cases: [(&str, (usize, usize)); 11] = [
        ("G00 X1\nG01 X2 #", (2, 8)),
        ("G00 X\n", (1, 5)),
        ("G01 X1 F100\n(open comment", (2, 1)),
        ("G01 X1 X2", (1, 8)),
        ("G00 G01 X1", (1, 5)),
        ("G18\n", (1, 1)),
        ("X10 Y10", (1, 1)),
        ("G01 X1 F100\nG02 X3 Y1", (2, 1)),
        ("G01 X10 Y0 F100\nG03 X0 Y10 I-10 J1", (2, 1)),
        ("G00 X1\nG04\n", (2, 1)),
        // No feed rate for a feed move: the controller refuses it rather than guess one.
        ("G00 X1\nG01 X2", (2, 1)),
    ];
    for (text, location) in cases {
        match read_gcode(text, &ReadOptions::default()) {
            Ok(p) => panic!("{text:?} read as {p:?}"),
            Err(e) => {
                assert_eq!(e.location(), location, "{text:?}: {e}");
                assert!(e
                    .to_string()
                    .starts_with(&format!("line {}, column {}", location.0, location.1)));
            }
        }
    }
    assert!(matches!(
        read_gcode("G00 X1\nG03 X3 R0.5 F100", &ReadOptions::default()),
        Err(GcodeReadError::ArcRadiusTooSmall { line: 2, .. })
    ));
    assert!(matches!(
        read_gcode("G02 X0 Y0 R5 F100", &ReadOptions::default()),
        Err(GcodeReadError::ZeroLengthRadiusArc { line: 1, .. })
    ));
    // No exponents in G-code: `X1e5` is X1 and an E5 word (an extruder axis, ignored).
    assert_eq!(read("G00 X1e5").end, Point::new(1.0, 0.0));
    assert!(matches!(
        read_gcode("G00 X99999999999", &ReadOptions::default()),
        Err(GcodeReadError::NumberOutOfRange { letter: 'X', .. })
    ));
}

#[test]
fn writer_options_show_in_the_program() {
    let path = quarter(1.0);
    let options = GcodeOptions {
        distance_mode: DistanceMode::Incremental,
        line_numbers: true,
        line_number_step: 5,
        arcs: ArcOutput::Radius,
        decimals: 2,
        torch_on: "M04 S1000".into(),
        torch_off: "M05".into(),
        pierce_dwell_s: 0.25,
        header: vec!["G64 P0.05".into()],
        footer: vec!["G00 X0 Y0".into(), "M02".into()],
        comments: false,
        ..GcodeOptions::default()
    };
    let text = write_gcode(&path, &options).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines,
        [
            "N5 G21",
            "N10 G90",
            "N15 G17",
            "N20 G64 P0.05",
            // Incremental moves start from a known position, not from where the head stands.
            "N25 G00 X10.00 Y0.00",
            "N30 G91",
            "N35 M04 S1000",
            "N40 G04 P0.250",
            "N45 G03 X-10.00 Y10.00 R10.00 F600",
            "N50 M05",
            "N55 G00 X0 Y0",
            "N60 M02",
        ]
    );
    // Lines only: no arc codes.
    let flat = GcodeOptions {
        arcs: ArcOutput::Lines { tolerance_mm: 0.1 },
        ..GcodeOptions::default()
    };
    let text = write_gcode(&path, &flat).unwrap();
    assert!(!text.contains("G03") && text.matches("G01").count() >= 3);
    // A long arc with a 180° limit becomes two.
    let a = Point::new(10.0, 0.0);
    let long = Toolpath {
        start: a,
        moves: vec![
            ToolMove::Pierce { at: a, step: 0 },
            ToolMove::Cut {
                step: 0,
                span: Span::new(a, Point::new(0.0, -10.0), (3.0 * PI / 8.0).tan()),
                link: false,
            },
        ],
    };
    let split = GcodeOptions {
        max_arc_sweep_deg: 180.0,
        ..GcodeOptions::default()
    };
    assert_eq!(
        write_gcode(&long, &split).unwrap().matches("G03").count(),
        2
    );
    assert_eq!(
        write_gcode(&long, &GcodeOptions::default())
            .unwrap()
            .matches("G03")
            .count(),
        1
    );
}

#[test]
fn writer_refuses_bad_options_and_moves() {
    let path = quarter(1.0);
    let bad = |options: GcodeOptions| write_gcode(&path, &options).unwrap_err();
    assert!(matches!(
        bad(GcodeOptions {
            decimals: 12,
            ..GcodeOptions::default()
        }),
        GcodeError::TooManyDecimals { decimals: 12 }
    ));
    assert!(matches!(
        bad(GcodeOptions {
            cut_feed_mm_per_min: 0.0,
            ..GcodeOptions::default()
        }),
        GcodeError::InvalidFeed { .. }
    ));
    assert!(matches!(
        bad(GcodeOptions {
            pierce_dwell_s: f64::NAN,
            ..GcodeOptions::default()
        }),
        GcodeError::InvalidDwell { .. }
    ));
    assert!(matches!(
        bad(GcodeOptions {
            arcs: ArcOutput::Lines { tolerance_mm: -1.0 },
            ..GcodeOptions::default()
        }),
        GcodeError::InvalidTolerance { .. }
    ));
    assert!(matches!(
        bad(GcodeOptions {
            max_arc_sweep_deg: 0.0,
            ..GcodeOptions::default()
        }),
        GcodeError::InvalidMaxSweep { .. }
    ));
    assert!(matches!(
        bad(GcodeOptions {
            torch_on: "M03\nG00 X0".into(),
            ..GcodeOptions::default()
        }),
        GcodeError::LineBreakInCode {
            field: "torch_on",
            ..
        }
    ));
    let mut no_pierce = quarter(1.0);
    no_pierce.moves.remove(0);
    assert!(matches!(
        write_gcode(&no_pierce, &GcodeOptions::default()),
        Err(GcodeError::CutWithoutPierce { move_index: 0 })
    ));
    let mut far = quarter(1.0);
    far.moves.push(ToolMove::Idle {
        from: Point::new(0.0, 10.0),
        to: Point::new(f64::INFINITY, 0.0),
    });
    assert!(matches!(
        write_gcode(&far, &GcodeOptions::default()),
        Err(GcodeError::CoordinateOutOfRange { move_index: 2, .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn garbage_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = read_gcode(&text, &ReadOptions::default());
    }

    #[test]
    fn gcode_like_garbage_never_panics(
        words in proptest::collection::vec(
            (prop::sample::select(vec!["G", "M", "X", "Y", "I", "J", "R", "P", "F", "N", "(", ")", ";", "\n", " ", "%", "/", "G9", "G2", "G3", "-", "."]),
             -1.0e3f64..1.0e3),
            0..60)
    ) {
        let text: String = words.iter().map(|(w, v)| format!("{w}{v:.3}")).collect();
        let _ = read_gcode(&text, &ReadOptions::default());
    }
}

/// A continuous toolpath: idle to the first point, pierce, then cut spans of the given bulges
/// through the given points.
fn random_path(points: &[(f64, f64)], bulges: &[f64]) -> Toolpath {
    let start = Point::new(0.0, 0.0);
    let first = Point::new(points[0].0, points[0].1);
    let mut moves = vec![
        ToolMove::Idle {
            from: start,
            to: first,
        },
        ToolMove::Pierce { at: first, step: 0 },
    ];
    for (w, b) in points.windows(2).zip(bulges) {
        let (a, z) = (Point::new(w[0].0, w[0].1), Point::new(w[1].0, w[1].1));
        moves.push(ToolMove::Cut {
            step: 0,
            span: Span::new(a, z, *b),
            link: false,
        });
    }
    Toolpath { start, moves }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_paths_round_trip_in_every_mode(
        points in proptest::collection::vec((-500.0f64..500.0, -500.0f64..500.0), 2..12),
        bulges in proptest::collection::vec(-3.0f64..3.0, 11),
        mode in 0usize..4,
    ) {
        // Skip spans too short to be meaningful at six decimals.
        prop_assume!(points.windows(2).all(|w| (w[0].0 - w[1].0).hypot(w[0].1 - w[1].1) > 1e-2));
        let path = random_path(&points, &bulges);
        let options = GcodeOptions {
            decimals: 6,
            distance_mode: if mode % 2 == 0 { DistanceMode::Absolute } else { DistanceMode::Incremental },
            arcs: if mode < 2 { ArcOutput::CentreOffsets } else { ArcOutput::Radius },
            ..GcodeOptions::default()
        };
        let text = write_gcode(&path, &options).unwrap();
        let program = read_gcode(&text, &ReadOptions::default()).unwrap();
        prop_assert!((program.cut_length() - path.cut_length()).abs() < 1e-3,
            "cut {} vs {}", program.cut_length(), path.cut_length());
        prop_assert!((program.idle_length() - path.idle_length()).abs() < 1e-5);
        prop_assert_eq!(program.pierce_count(), 1);
        prop_assert!(program.end.distance(path.end()) < 1e-5);
    }
}
