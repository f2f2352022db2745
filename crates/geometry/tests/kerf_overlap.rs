//! The kerf of one part must not eat into a neighbour: the cut on a contour's equidistant keeps
//! kerf/2 from every other contour. Checked on nests whose gaps are known by construction, by
//! `kerf_overlaps` (the kerf job's up-front test), `Route::problems` (each step's cut) and
//! `PathRoute::problems` (each tool-on span), which must agree.

use cutroute_geometry::{
    kerf_overlaps, Contour, ContourRef, KerfSettings, LeadFitter, LeadShape, LeadSpec, Nest, Part,
    PathLeads, PathRoute, PathRouteError, Point, Route, RouteError, ToolOnPath, Vertex,
};
use proptest::prelude::*;

/// A clockwise (outer) square with its lower left corner at (x, y).
fn square(x: f64, y: f64, size: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x, y),
        Vertex::line(x, y + size),
        Vertex::line(x + size, y + size),
        Vertex::line(x + size, y),
    ])
}

fn nest(parts: Vec<Vec<Contour>>) -> Nest {
    let mut nest = Nest {
        sheet: None,
        parts: parts
            .into_iter()
            .enumerate()
            .map(|(i, contours)| Part {
                name: format!("p{i}"),
                contours,
            })
            .collect(),
    };
    nest.normalize_orientation();
    nest
}

fn r(part: usize, contour: usize) -> ContourRef {
    ContourRef { part, contour }
}

/// The innermost-first route of `nest` with leads fitted under `settings`.
fn with_leads(nest: &Nest, settings: KerfSettings) -> Route {
    let fitter = LeadFitter::new(nest, settings);
    let route = Route::innermost_first(nest, Point::new(-100.0, -100.0), None);
    fitter.attach(&route).expect("leads fit")
}

fn kerf_overlaps_of(route: &Route, nest: &Nest) -> Vec<RouteError> {
    route
        .problems(nest, &nest.containment_forest(), nest.check_tolerance())
        .into_iter()
        .filter(|p| matches!(p, RouteError::KerfOverlap { .. }))
        .collect()
}

/// The same cuts as tool-on paths: each step's equidistant from its entry round, its leads.
fn as_paths(route: &Route, nest: &Nest) -> PathRoute {
    let paths = route
        .steps
        .iter()
        .map(|s| {
            let leads = s.leads.as_ref().expect("leads");
            let eq = cutroute_geometry::equidistant(nest.contour(s.contour).unwrap(), leads.offset)
                .unwrap();
            ToolOnPath {
                pierce: leads.pierce,
                spans: leads.equidistant_cut(&eq, 1e-9),
                leads: Some(PathLeads {
                    entry: leads.entry,
                    lead_in: leads.lead_in.clone(),
                    lead_out: leads.lead_out.clone(),
                    switch_off: leads.switch_off,
                    offset: leads.offset,
                    pierce_clearance: leads.pierce_clearance,
                    switch_off_clearance: leads.switch_off_clearance,
                    // The spans are the step's whole cut already.
                    overcut: 0.0,
                    edge_pierce: leads.edge_pierce,
                    tabs: Vec::new(),
                }),
            }
        })
        .collect();
    PathRoute {
        start: route.start,
        paths,
        finish: route.finish,
    }
}

fn cut_too_close(route: &PathRoute, nest: &Nest) -> usize {
    route
        .problems(nest, nest.check_tolerance())
        .iter()
        .filter(|p| matches!(p, PathRouteError::CutTooClose { .. }))
        .count()
}

#[test]
fn two_squares_1_mm_apart_fail_with_kerf_2_once_per_pair() {
    let nest = nest(vec![
        vec![square(0.0, 0.0, 50.0)],
        vec![square(51.0, 0.0, 50.0)],
    ]);
    let pairs = kerf_overlaps(&nest, 1.0, nest.check_tolerance());
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    let p = pairs[0];
    assert_eq!((p.contour, p.other), (r(0, 0), r(1, 0)));
    assert!((p.gap - 1.0).abs() < 1e-9, "{p:?}");
    assert!(p.distance < 1e-9 && p.required == 1.0, "{p:?}");
    assert!((50.0..=51.0).contains(&p.at.x), "{p:?}");

    let route = with_leads(&nest, KerfSettings::plasma_reference());
    let overlaps = kerf_overlaps_of(&route, &nest);
    // Both cuts eat into the other part; the pair is reported once.
    assert_eq!(overlaps.len(), 1, "{overlaps:?}");
    let RouteError::KerfOverlap {
        contour,
        other,
        gap,
        required,
        ..
    } = overlaps[0]
    else {
        unreachable!()
    };
    let mut pair = [contour, other];
    pair.sort();
    assert_eq!(pair, [r(0, 0), r(1, 0)]);
    assert!((gap - 1.0).abs() < 1e-9 && required == 1.0);
    assert!(overlaps[0].to_string().contains("closer than kerf/2"));
    // The path checker refuses the same cuts.
    assert!(cut_too_close(&as_paths(&route, &nest), &nest) > 0);
}

#[test]
fn two_squares_3_mm_apart_pass_and_exactly_the_kerf_apart_pass() {
    for gap in [3.0, 2.0] {
        let nest = nest(vec![
            vec![square(0.0, 0.0, 50.0)],
            vec![square(50.0 + gap, 0.0, 50.0)],
        ]);
        assert!(kerf_overlaps(&nest, 1.0, nest.check_tolerance()).is_empty());
        let route = with_leads(&nest, KerfSettings::plasma_reference());
        let problems = route.problems(&nest, &nest.containment_forest(), nest.check_tolerance());
        assert!(problems.is_empty(), "gap {gap}: {problems:?}");
        assert_eq!(cut_too_close(&as_paths(&route, &nest), &nest), 0);
    }
}

#[test]
fn three_squares_in_a_row_make_two_pairs() {
    let nest = nest(vec![
        vec![square(0.0, 0.0, 50.0)],
        vec![square(50.5, 0.0, 50.0)],
        vec![square(101.0, 0.0, 50.0)],
    ]);
    let pairs = kerf_overlaps(&nest, 1.0, nest.check_tolerance());
    let named: Vec<(ContourRef, ContourRef)> = pairs.iter().map(|p| (p.contour, p.other)).collect();
    assert_eq!(named, vec![(r(0, 0), r(1, 0)), (r(1, 0), r(2, 0))]);
    let route = with_leads(&nest, KerfSettings::plasma_reference());
    assert_eq!(kerf_overlaps_of(&route, &nest).len(), 2);
}

#[test]
fn a_part_in_a_hole_closer_than_the_kerf_to_the_hole_fails() {
    // A 100 mm plate with a 40 mm hole; a 20 mm part in the hole, 0.5 mm from its left side.
    let plate = square(0.0, 0.0, 100.0);
    let hole = square(30.0, 30.0, 40.0).reversed();
    let close = nest(vec![
        vec![plate.clone(), hole.clone()],
        vec![square(30.5, 40.0, 20.0)],
    ]);
    let pairs = kerf_overlaps(&close, 1.0, close.check_tolerance());
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    let mut pair = [pairs[0].contour, pairs[0].other];
    pair.sort();
    assert_eq!(pair, [r(0, 1), r(1, 0)]);
    assert!((pairs[0].gap - 0.5).abs() < 1e-9);
    // Laser leads fit in the hole; the cut of the part (or the hole) still eats into the other.
    let laser = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 1.0,
        switch_off_clearance: 0.5,
        lead_in: LeadSpec::new(LeadShape::Arc, 2.0),
        lead_out: LeadSpec::new(LeadShape::Line, 1.0),
        ..KerfSettings::default()
    };
    let route = with_leads(&close, laser);
    assert_eq!(kerf_overlaps_of(&route, &close).len(), 1);
    assert!(cut_too_close(&as_paths(&route, &close), &close) > 0);

    // Centred, 10 mm from every side of the hole: room for the kerf.
    let roomy = nest(vec![vec![plate, hole], vec![square(40.0, 40.0, 20.0)]]);
    assert!(kerf_overlaps(&roomy, 1.0, roomy.check_tolerance()).is_empty());
    let route = with_leads(&roomy, laser);
    assert!(kerf_overlaps_of(&route, &roomy).is_empty());
}

#[test]
fn a_wall_thinner_than_the_kerf_between_a_hole_and_its_outer_contour_is_no_overlap() {
    // The hole is 0.5 mm from the plate's edge: the outer cut's kerf lies outside the plate,
    // the hole's inside the hole, and the wall between them stays (thin, but not eaten).
    let plate = nest(vec![vec![
        square(0.0, 0.0, 100.0),
        square(0.5, 30.0, 40.0).reversed(),
    ]]);
    assert!(kerf_overlaps(&plate, 1.0, plate.check_tolerance()).is_empty());
}

#[test]
fn circles_overlap_by_their_arcs_exactly_when_closer_than_the_kerf() {
    for (gap, overlap) in [(1.5, true), (2.5, false)] {
        let nest = nest(vec![
            vec![Contour::circle(Point::new(0.0, 0.0), 10.0, true)],
            vec![Contour::circle(Point::new(20.0 + gap, 0.0), 10.0, true)],
        ]);
        let pairs = kerf_overlaps(&nest, 1.0, nest.check_tolerance());
        assert_eq!(pairs.len(), usize::from(overlap), "gap {gap}: {pairs:?}");
        if overlap {
            assert!((pairs[0].gap - gap).abs() < 1e-9, "{pairs:?}");
            // The cut (radius 11) reaches to 0.5 mm inside the other circle's 1 mm: 0.5 from it.
            assert!((pairs[0].distance - (gap - 1.0)).abs() < 1e-9, "{pairs:?}");
        }
        let route = with_leads(&nest, KerfSettings::plasma_reference());
        assert_eq!(kerf_overlaps_of(&route, &nest).len(), usize::from(overlap));
    }
}

#[test]
fn the_parts_too_close_message_names_the_pairs_and_their_gap() {
    let nest = nest(vec![
        vec![square(0.0, 0.0, 50.0)],
        vec![square(50.75, 0.0, 50.0)],
    ]);
    let refusal = cutroute_geometry::PartsTooClose {
        kerf: 2.0,
        pairs: kerf_overlaps(&nest, 1.0, nest.check_tolerance()),
    };
    let words = refusal.to_string();
    assert!(words.contains("closer than the kerf of 2 mm"), "{words}");
    assert!(
        words.contains("part 1 contour 0 and part 2 contour 0 0.750 mm apart"),
        "{words}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Two circles `gap` apart under a kerf: the nest test and the route checker both find the
    /// pair exactly when the gap is less than the kerf, and agree with the path checker.
    #[test]
    fn circles_overlap_iff_the_gap_is_less_than_the_kerf(
        r1 in 3.0f64..30.0,
        r2 in 3.0f64..30.0,
        gap in 0.05f64..4.0,
        kerf in 0.2f64..3.0,
        angle in 0.0f64..std::f64::consts::TAU,
    ) {
        prop_assume!((gap - kerf).abs() > 1e-3);
        let d = r1 + r2 + gap;
        let nest = nest(vec![
            vec![Contour::circle(Point::new(0.0, 0.0), r1, true)],
            vec![Contour::circle(Point::new(d * angle.cos(), d * angle.sin()), r2, true)],
        ]);
        let expected = usize::from(gap < kerf);
        let pairs = kerf_overlaps(&nest, kerf / 2.0, nest.check_tolerance());
        prop_assert_eq!(pairs.len(), expected);
        if let Some(p) = pairs.first() {
            prop_assert!((p.gap - gap).abs() < 1e-6, "{:?}", p);
        }
        // No leads: the pierce is on the equidistant, so the only elements are the cuts.
        let settings = KerfSettings { kerf, ..KerfSettings::default() };
        let fitter = LeadFitter::new(&nest, settings);
        let route = Route::innermost_first(&nest, Point::new(-100.0, -100.0), None);
        let route = fitter.attach(&route).expect("a pierce on the equidistant always fits");
        prop_assert_eq!(kerf_overlaps_of(&route, &nest).len(), expected);
        prop_assert_eq!(cut_too_close(&as_paths(&route, &nest), &nest) > 0, gap < kerf);
    }
}
