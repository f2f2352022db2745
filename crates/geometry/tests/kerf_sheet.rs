//! Pierce points on the sheet and parts on the right side: the lead fitter keeps M and M* on
//! the sheet (at least d₁, d₂ inside its border), the route checkers refuse a pierce off it,
//! contours lying on one another are found, and the kerf settings are held to one table of
//! ranges.

use cutroute_geometry::{
    contours_on_one_another, kerf_overlaps, place_tabs, Contour, ContourRef, KerfField,
    KerfSettings, LeadFitter, LeadProblem, LeadShape, LeadSpec, Nest, Part, Point, Route,
    RouteError, TabSpec, Vertex,
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
