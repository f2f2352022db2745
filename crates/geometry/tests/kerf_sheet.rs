//! Pierce points on the sheet and parts on the right side: the lead fitter keeps M and M* on
//! the sheet (at least d₁, d₂ inside its border), the route checkers refuse a pierce off it,
//! contours lying on one another are found, and the kerf settings are held to one table of
//! ranges.

use cutroute_geometry::{
    contours_on_one_another, kerf_overlaps, place_tabs, Contour, ContourRef, KerfField,
    KerfSettings, LeadFitter, LeadProblem, LeadShape, LeadSpec, Nest, Part, PartsTooClose, Point,
    Route, RouteError, TabSpec, Vertex,
};

/// A clockwise (outer) square with its lower left corner at (x, y).
fn square(x: f64, y: f64, size: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x, y),
        Vertex::line(x, y + size),
        Vertex::line(x + size, y + size),
        Vertex::line(x + size, y),
    ])
}

fn part(name: &str, contours: Vec<Contour>) -> Part {
    Part {
        name: name.into(),
        contours,
    }
}

/// A 300 × 300 sheet with the given parts, oriented.
fn on_sheet(parts: Vec<Part>) -> Nest {
    let mut nest = Nest {
        sheet: Some(part("sheet", vec![square(0.0, 0.0, 300.0)])),
        parts,
    };
    nest.normalize_orientation();
    nest
}

fn line_lead() -> KerfSettings {
    KerfSettings {
        lead_in: LeadSpec::new(LeadShape::Line, 5.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        ..KerfSettings::default()
    }
}

/// A 20 mm square 3 mm from the sheet's right edge, approached from beyond that edge: the
/// asked 5 mm line would pierce at x = 302; the fitter finds M on the sheet, and the checker
/// passes the route.
#[test]
fn a_lead_beside_the_sheets_edge_stays_on_the_sheet() {
    for (settings, d1) in [
        (line_lead(), 0.0),
        (
            KerfSettings {
                kerf: 1.0,
                pierce_clearance: 2.0,
                lead_in: LeadSpec::new(LeadShape::Arc, 5.0),
                ..KerfSettings::default()
            },
            2.0,
        ),
        (KerfSettings::plasma_reference(), 5.0),
    ] {
        let nest = on_sheet(vec![part("edge", vec![square(277.0, 100.0, 20.0)])]);
        let fitter = LeadFitter::new(&nest, settings);
        let r = ContourRef {
            part: 0,
            contour: 0,
        };
        let leads = fitter
            .fit(r, Point::new(400.0, 110.0))
            .expect("a lead fits");
        assert!(leads.pierce.x <= 300.0 - d1 + 1e-6, "{:?}", leads.pierce);
        assert!(fitter.on_sheet(leads.pierce, d1 - 1e-6));
        assert!(fitter.on_sheet(leads.switch_off, 0.0));
        assert!(fitter.problems(r, &leads).is_empty());
        let route = Route::innermost_first(&nest, Point::new(400.0, 110.0), None);
        let route = fitter.attach(&route).expect("leads fit");
        let problems = route.problems(&nest, &nest.containment_forest(), 1e-6);
        assert!(problems.is_empty(), "{problems:?}");
    }
}

/// The same leads fitted without a sheet pierce off it; on the nest with the sheet the
/// checker refuses them by name.
#[test]
fn the_route_checker_refuses_a_pierce_off_the_sheet() {
    let square_3mm = || square(277.0, 100.0, 20.0);
    let mut bare = Nest {
        sheet: None,
        parts: vec![part("edge", vec![square_3mm()])],
    };
    bare.normalize_orientation();
    let start = Point::new(400.0, 110.0);
    let mut route = Route::innermost_first(&bare, start, None);
    // Entered from the right-hand side, the one facing the edge.
    route.steps[0].pierce_point = Point::new(297.0, 110.0);
    let route = LeadFitter::new(&bare, line_lead())
        .attach(&route)
        .expect("leads fit");
    let pierce = route.steps[0].leads.as_ref().unwrap().pierce;
    assert!(
        pierce.x > 300.0,
        "the test needs a pierce off the sheet: {pierce:?}"
    );
    assert!(route
        .problems(&bare, &bare.containment_forest(), 1e-6)
        .is_empty());
    let nest = on_sheet(vec![part("edge", vec![square_3mm()])]);
    let problems = route.problems(&nest, &nest.containment_forest(), 1e-6);
    assert!(
        problems.iter().any(|p| matches!(
            p,
            RouteError::Lead {
                problem: LeadProblem::PierceOffSheet { .. },
                ..
            }
        )),
        "{problems:?}"
    );
    let words = route.validate(&nest, 1e-6).unwrap_err().to_string();
    assert!(words.contains("off the sheet"), "{words}");
}

/// A part touching the sheet's edge (0 mm): its cut runs off the plate, but M and M* do not.
#[test]
fn a_part_on_the_sheets_edge_is_pierced_on_the_sheet() {
    let nest = on_sheet(vec![part("touching", vec![square(280.0, 0.0, 20.0)])]);
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 3.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::LineArc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        ..KerfSettings::default()
    };
    let fitter = LeadFitter::new(&nest, settings);
    for near in [
        Point::new(310.0, 10.0),
        Point::new(290.0, -10.0),
        Point::new(0.0, 0.0),
    ] {
        let leads = fitter
            .fit(
                ContourRef {
                    part: 0,
                    contour: 0,
                },
                near,
            )
            .expect("a lead fits on the sheet side");
        assert!(
            fitter.on_sheet(leads.pierce, 3.0 - 1e-6),
            "{:?}",
            leads.pierce
        );
        assert!(
            fitter.on_sheet(leads.switch_off, 1.0 - 1e-6),
            "{:?}",
            leads.switch_off
        );
    }
}

/// A part lying exactly in a hole of its own shape, and two identical parts on top of each
/// other: the cut round one runs kerf/2 from the other on its far side, which the kerf's own
/// test does not see; `contours_on_one_another` finds both pairs.
#[test]
fn coincident_contours_are_found() {
    let plate = part(
        "plate",
        vec![square(0.0, 0.0, 100.0), square(30.0, 30.0, 20.0)],
    );
    let slug = part("slug", vec![square(30.0, 30.0, 20.0)]);
    let mut in_its_hole = Nest {
        sheet: None,
        parts: vec![plate, slug],
    };
    in_its_hole.normalize_orientation();
    // The kerf's own test does not see it (the cut keeps kerf/2 on the far side).
    assert!(kerf_overlaps(&in_its_hole, 1.0, in_its_hole.check_tolerance()).is_empty());
    let pairs = contours_on_one_another(&in_its_hole, 1.0, in_its_hole.check_tolerance());
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    let parts = [pairs[0].contour.part, pairs[0].other.part];
    assert!(parts.contains(&0) && parts.contains(&1), "{pairs:?}");
    assert!(pairs[0].gap < 1e-6);

    let mut stacked = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 20.0)]),
            part("b", vec![square(0.0, 0.0, 20.0)]),
        ],
    };
    stacked.normalize_orientation();
    let pairs = contours_on_one_another(&stacked, 1.0, stacked.check_tolerance());
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    // Apart, nothing is reported.
    let mut apart = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 20.0)]),
            part("b", vec![square(22.5, 0.0, 20.0)]),
        ],
    };
    apart.normalize_orientation();
    assert!(kerf_overlaps(&apart, 1.0, apart.check_tolerance()).is_empty());
    assert!(contours_on_one_another(&apart, 1.0, apart.check_tolerance()).is_empty());
}

/// A 100 mm plate with a 20 mm hole, and a 20 mm part lying exactly in that hole.
fn part_in_its_hole() -> Nest {
    let mut nest = Nest {
        sheet: None,
        parts: vec![
            part(
                "plate",
                vec![square(0.0, 0.0, 100.0), square(30.0, 30.0, 20.0)],
            ),
            part("slug", vec![square(30.0, 30.0, 20.0)]),
        ],
    };
    nest.normalize_orientation();
    nest
}

/// Contours lying on one another are refused with a kerf as parts closer than the kerf are,
/// the pair named by part (from 1) and contour and said to lie on one another; parts that
/// merely touch are said to touch; without a kerf nothing is refused.
#[test]
fn contours_on_one_another_are_refused_with_a_kerf_naming_both_parts() {
    let nest = part_in_its_hole();
    let tolerance = nest.check_tolerance();
    let refusal = PartsTooClose::of(&nest, 2.0, tolerance).expect("refused");
    assert_eq!(refusal.kerf, 2.0);
    assert_eq!(refusal.pairs.len(), 1, "{refusal:?}");
    let pair = refusal.pairs[0];
    assert!(pair.on_one_another && pair.gap < 1e-6, "{pair:?}");
    let mut named = [pair.contour, pair.other];
    named.sort();
    assert_eq!(
        named,
        [
            ContourRef {
                part: 0,
                contour: 1
            },
            ContourRef {
                part: 1,
                contour: 0
            }
        ]
    );
    let message = refusal.to_string();
    assert!(
        message.starts_with("parts closer than the kerf of 2 mm")
            && message.contains("1 pair(s) of contours: ")
            && message.contains(" lie on one another near ("),
        "{message}"
    );
    assert!(
        message.contains("part 1 contour 1") && message.contains("part 2 contour 0"),
        "{message}"
    );
    // Any kerf, a laser's too; none without.
    assert!(PartsTooClose::of(&nest, 0.2, tolerance).is_some());
    assert!(PartsTooClose::of(&nest, 0.0, tolerance).is_none());

    // Two identical parts stacked, however each is split into spans.
    let split = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(0.0, 10.0),
        Vertex::line(0.0, 20.0),
        Vertex::line(20.0, 20.0),
        Vertex::line(20.0, 0.0),
    ]);
    let mut stacked = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 20.0)]),
            part("b", vec![split]),
        ],
    };
    stacked.normalize_orientation();
    let refusal = PartsTooClose::of(&stacked, 2.0, stacked.check_tolerance()).expect("refused");
    assert_eq!(refusal.pairs.len(), 1, "{refusal:?}");
    assert!(refusal.pairs[0].on_one_another);
    assert!(
        refusal
            .to_string()
            .contains("part 1 contour 0 and part 2 contour 0 lie on one another near ("),
        "{refusal}"
    );

    // Side by side along an edge, and a smaller part against the wall of a hole: they touch.
    let mut touching = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 20.0)]),
            part("b", vec![square(20.0, 0.0, 20.0)]),
            part(
                "plate",
                vec![square(100.0, 0.0, 100.0), square(130.0, 30.0, 20.0)],
            ),
            part("small", vec![square(130.0, 30.0, 10.0)]),
        ],
    };
    touching.normalize_orientation();
    let refusal = PartsTooClose::of(&touching, 2.0, touching.check_tolerance()).expect("refused");
    assert_eq!(refusal.pairs.len(), 2, "{refusal:?}");
    assert!(
        refusal.pairs.iter().all(|p| !p.on_one_another),
        "{refusal:?}"
    );
    let message = refusal.to_string();
    assert!(
        message.contains("part 1 contour 0 and part 2 contour 0 touch near (")
            && !message.contains("lie on one another"),
        "{message}"
    );
    // Apart by more than the kerf: nothing.
    let mut apart = Nest {
        sheet: None,
        parts: vec![
            part("a", vec![square(0.0, 0.0, 20.0)]),
            part("b", vec![square(22.5, 0.0, 20.0)]),
        ],
    };
    apart.normalize_orientation();
    assert!(PartsTooClose::of(&apart, 2.0, apart.check_tolerance()).is_none());
}

/// The route checker rejects a route with a kerf over a part lying in a hole of its own shape
/// (and over stacked parts), naming both contours, though each cut keeps kerf/2 off the other;
/// without a kerf the same order passes.
#[test]
fn the_route_checker_rejects_a_kerf_cut_over_contours_on_one_another() {
    let settings = KerfSettings {
        kerf: 2.0,
        ..line_lead()
    };
    let stacked = {
        let mut nest = Nest {
            sheet: None,
            parts: vec![
                part("a", vec![square(0.0, 0.0, 20.0)]),
                part("b", vec![square(0.0, 0.0, 20.0)]),
            ],
        };
        nest.normalize_orientation();
        nest
    };
    for nest in [part_in_its_hole(), stacked] {
        let forest = nest.containment_forest();
        let tolerance = nest.check_tolerance();
        let order = Route::innermost_first(&nest, Point::new(-50.0, -50.0), None);
        assert!(order.problems(&nest, &forest, tolerance).is_empty());
        let route = LeadFitter::new(&nest, settings)
            .attach(&order)
            .expect("leads fit");
        let problems = route.problems(&nest, &forest, tolerance);
        // The kerf's own clearance test does not see it: the cuts keep kerf/2 off each other.
        assert!(
            !problems
                .iter()
                .any(|p| matches!(p, RouteError::KerfOverlap { .. })),
            "{problems:?}"
        );
        let touching: Vec<&RouteError> = problems
            .iter()
            .filter(|p| matches!(p, RouteError::ContoursTouch { .. }))
            .collect();
        assert_eq!(touching.len(), 1, "{problems:?}");
        let RouteError::ContoursTouch {
            contour,
            other,
            on_one_another,
            ..
        } = *touching[0]
        else {
            unreachable!()
        };
        assert!(on_one_another);
        assert_ne!(contour.part, other.part);
        let message = touching[0].to_string();
        assert!(
            message.contains(&format!("{contour} (step "))
                && message.contains(&format!(") and {other} lie on one another near (")),
            "{message}"
        );
    }
}

#[test]
fn kerf_settings_out_of_range_are_named() {
    let with = |f: &dyn Fn(&mut KerfSettings)| {
        let mut s = KerfSettings::plasma_reference();
        f(&mut s);
        s.check()
            .err()
            .map(|e| (e.field, e.for_flag(), e.in_profile()))
    };
    assert_eq!(with(&|_| {}), None);
    let (field, flag, _) = with(&|s| s.kerf = 1e-300).unwrap();
    assert_eq!(field, KerfField::Kerf);
    assert!(
        flag.starts_with("--kerf 1e-300: must be 0 or from"),
        "{flag}"
    );
    let (field, _, profile) = with(&|s| {
        s.tabs = TabSpec {
            count: 4_000_000_000_000_000_000,
            width: 1.0,
        }
    })
    .unwrap();
    assert_eq!(field, KerfField::TabCount);
    assert!(profile.starts_with("kerf.tabs.count 4e18"), "{profile}");
    let (field, flag, _) = with(&|s| {
        s.tabs = TabSpec {
            count: 3,
            width: 1e-300,
        }
    })
    .unwrap();
    assert_eq!(field, KerfField::TabWidth);
    assert!(flag.starts_with("--tabs width 1e-300"), "{flag}");
    let (field, flag, _) = with(&|s| s.lead_in.length = 0.0).unwrap();
    assert_eq!(field, KerfField::LeadInLength);
    assert!(
        flag.starts_with("--lead-in-length 0: must be from"),
        "{flag}"
    );
    assert_eq!(with(&|s| s.kerf = f64::NAN).unwrap().0, KerfField::Kerf);
    assert_eq!(
        with(&|s| s.lead_out.angle = 90.0).unwrap().0,
        KerfField::LeadOutAngle
    );
    // No lead: its length is not a lead's (the CLI's default length with shape none).
    assert_eq!(
        with(&|s| {
            s.lead_in = LeadSpec::new(LeadShape::None, 0.0);
        }),
        None
    );
}

/// However many tabs are asked, no more are placed than the cut has room for, and asking
/// for an absurd number neither panics nor allocates for it.
#[test]
fn tabs_beyond_the_room_are_not_placed() {
    let eq = square(0.0, 0.0, 100.0);
    for count in [4, 40, 400, usize::MAX] {
        let tabs = place_tabs(&eq, 1.0, 0.0, 0.0, TabSpec { count, width: 2.0 });
        assert!(
            tabs.len() <= count && tabs.len() <= 400 / 3,
            "{count}: {}",
            tabs.len()
        );
        for pair in tabs.windows(2) {
            assert!(pair[0].end < pair[1].start);
        }
    }
    // A 10 × 10 square has no side long enough for a 5 mm gap a margin from its corners.
    let small = square(0.0, 0.0, 10.0);
    assert!(place_tabs(
        &small,
        1.0,
        0.0,
        0.0,
        TabSpec {
            count: 4,
            width: 5.0
        }
    )
    .is_empty());
}
