//! Chain cutting with kerf and leads: routes over the kerf nest brought back with leads, and
//! the checker's rules for chains (links kerf/2 clear of every contour, no pierce region at a
//! link's ends).

use cutroute_geometry::{
    Contour, ContourRef, CutStep, Entry, KerfSettings, LeadFitter, Nest, Part, Point, Route,
    RouteError, Vertex,
};
use proptest::prelude::*;

/// A clockwise (outer) square `size` wide with its lower left corner at (x, 0).
fn square(x: f64, size: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x, 0.0),
        Vertex::line(x, size),
        Vertex::line(x + size, size),
        Vertex::line(x + size, 0.0),
    ])
}

/// Squares of `size` in a row, the gaps between them given.
fn row(size: f64, gaps: &[f64]) -> Nest {
    let mut x = 0.0;
    let mut parts = vec![];
    for k in 0..=gaps.len() {
        parts.push(Part {
            name: format!("p{k}"),
            contours: vec![square(x, size)],
        });
        if let Some(g) = gaps.get(k) {
            x += size + g;
        }
    }
    Nest { sheet: None, parts }
}

fn r(part: usize) -> ContourRef {
    ContourRef { part, contour: 0 }
}

/// One chain over the kerf nest of `nest` (squares in a row): square k is entered on its left
/// equidistant at height `y` by a straight link from the right equidistant of square k − 1.
/// (A valid chain for two squares; beyond, the links cross the squares they leave from, and
/// the checker must catch that.)
fn chained_over_kerf_nest(nest: &Nest, half: f64, y: f64) -> Route {
    let steps = (0..nest.parts.len())
        .map(|k| {
            let c = nest.contour(r(k)).unwrap().bounding_box();
            if k == 0 {
                CutStep::pierced(r(k), Point::new(c.max.x + half, y))
            } else {
                CutStep {
                    contour: r(k),
                    pierce_point: Point::new(c.min.x - half, y),
                    entry: Entry::Link(vec![]),
                    leads: None,
                }
            }
        })
        .collect();
    Route {
        start: Point::new(-50.0, y),
        steps,
        finish: None,
    }
}

#[test]
fn a_chain_pierces_once_with_a_lead_in_and_ends_with_a_lead_out() {
    let nest = row(20.0, &[12.0]);
    let fitter = LeadFitter::new(&nest, KerfSettings::plasma_reference());
    let kerf_nest = fitter.kerf_nest();
    let route = chained_over_kerf_nest(&nest, 1.0, 10.0);
    // The hand-made chain is a valid chain of the kerf nest.
    assert_eq!(route.validate(&kerf_nest, 1e-6), Ok(()));
    let chained = fitter.attach_chained(&route, 2, 24).unwrap();
    assert_eq!(chained.broken_links, 0);
    let route = chained.route;
    assert_eq!(route.validate(&nest, 1e-6), Ok(()));
    assert_eq!(route.pierce_count(), 1);
    assert!(
        (route.link_length() - 10.0).abs() < 1e-6,
        "{}",
        route.link_length()
    );
    let leads: Vec<_> = route
        .steps
        .iter()
        .map(|s| s.leads.clone().unwrap())
        .collect();
    // The first step leads in from a pierce point d₁ off the parts; the links run between
    // the entries on the equidistants; the last step leads out.
    assert!(leads[0].lead_in_length() > 0.0 && leads[0].lead_out_length() == 0.0);
    assert!(leads[1].lead_in_length() == 0.0 && leads[1].lead_out_length() > 0.0);
    for (k, l) in leads.iter().enumerate() {
        let contour = nest.contour(r(k)).unwrap();
        assert!((contour.distance_to(l.entry) - 1.0).abs() < 1e-9);
    }
    assert!(nest.contour(r(0)).unwrap().distance_to(leads[0].pierce) >= 5.0 - 1e-9);
    // The link ends where the cut of the previous contour ends.
    assert_eq!(route.link_path(1).unwrap()[0], leads[0].switch_off);
    assert_eq!(leads[0].switch_off, leads[0].entry);
}

#[test]
fn a_chain_start_without_room_for_a_lead_in_is_pierced_apart() {
    // A 6 mm gap: no point of it is d₁ = 5 from both squares, and the chain's first entry
    // faces it, so no lead-in fits there; the link is given up for a second pierce.
    let nest = row(20.0, &[6.0]);
    let fitter = LeadFitter::new(&nest, KerfSettings::plasma_reference());
    let route = chained_over_kerf_nest(&nest, 1.0, 10.0);
    assert_eq!(route.validate(&fitter.kerf_nest(), 1e-6), Ok(()));
    let chained = fitter.attach_chained(&route, 2, 24).unwrap();
    assert_eq!(chained.broken_links, 1);
    assert_eq!(chained.route.validate(&nest, 1e-6), Ok(()));
    assert_eq!(chained.route.pierce_count(), 2);
    assert_eq!(chained.route.link_length(), 0.0);
}

#[test]
fn the_checker_holds_links_to_half_the_kerf() {
    let nest = row(20.0, &[12.0]);
    let fitter = LeadFitter::new(&nest, KerfSettings::plasma_reference());
    let mut route = fitter
        .attach_chained(&chained_over_kerf_nest(&nest, 1.0, 10.0), 0, 0)
        .unwrap()
        .route;
    assert_eq!(route.validate(&nest, 1e-6), Ok(()));
    // Corners half a millimetre below the squares' corners: in scrap and crossing nothing,
    // but the kerf would eat into the squares.
    route.steps[1].entry = Entry::Link(vec![Point::new(20.5, -0.5), Point::new(31.5, -0.5)]);
    let problems = route.problems(&nest, &nest.containment_forest(), 1e-6);
    assert!(
        problems.iter().any(
            |p| matches!(p, RouteError::LinkTooClose { step: 1, distance, .. } if *distance < 0.75)
        ),
        "{problems:?}"
    );
    assert!(problems
        .iter()
        .all(|p| matches!(p, RouteError::LinkTooClose { .. })));
}

#[test]
fn a_pierced_step_s_pierce_point_is_still_held_to_the_pierce_region() {
    // The chain start's lead-in swapped for none: its pierce point is then the entry, 1 mm
    // from the square, which only a linked step may have.
    let nest = row(20.0, &[12.0]);
    let fitter = LeadFitter::new(&nest, KerfSettings::plasma_reference());
    let mut route = fitter
        .attach_chained(&chained_over_kerf_nest(&nest, 1.0, 10.0), 0, 0)
        .unwrap()
        .route;
    let leads = route.steps[0].leads.as_mut().unwrap();
    leads.pierce = leads.entry;
    leads.lead_in = vec![Vertex::arc(leads.entry.x, leads.entry.y, 0.0)];
    let problems = route.problems(&nest, &nest.containment_forest(), 1e-6);
    assert!(
        problems
            .iter()
            .any(|p| matches!(p, RouteError::Lead { step: 0, .. })),
        "{problems:?}"
    );
    // The linked step's lead-in is the same kind of single point, and is no problem.
    assert!(problems
        .iter()
        .all(|p| !matches!(p, RouteError::Lead { step: 1, .. })));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Whatever the gaps and the height of the links, the chain comes back valid over the real
    /// nest: one pierce per chain (the links given up each add one), every link kerf/2 clear.
    /// Rows of more than two squares also try links that cross the squares they leave: those
    /// are given up, never kept.
    #[test]
    fn chains_with_leads_pass_the_checker(
        gaps in prop::collection::vec(3.0f64..30.0, 1..6),
        y in 0.5f64..19.5,
        kerf in prop::sample::select(vec![0.2, 2.0]),
    ) {
        let nest = row(20.0, &gaps);
        let settings = KerfSettings { kerf, pierce_clearance: if kerf < 1.0 { 1.0 } else { 5.0 }, ..KerfSettings::plasma_reference() };
        let fitter = LeadFitter::new(&nest, settings);
        let route = chained_over_kerf_nest(&nest, kerf / 2.0, y);
        prop_assume!(gaps.iter().all(|g| *g > kerf));
        let chained = fitter.attach_chained(&route, 1, 12).unwrap();
        prop_assert_eq!(chained.route.validate(&nest, 1e-6), Ok(()));
        prop_assert_eq!(chained.route.pierce_count(), 1 + chained.broken_links);
        prop_assert_eq!(chained.route.steps.len(), nest.parts.len());
        prop_assert!(chained.route.steps.iter().all(|s| s.leads.is_some()));
        // Two squares with room for the arc's pierce point (6.1 mm out, d₁ from the other
        // square) keep their link.
        if gaps.len() == 1 && gaps[0] >= 12.0 && (6.0..14.0).contains(&y) {
            prop_assert_eq!(chained.broken_links, 0);
        }
    }
}

/// A link turned into a pierce after the leads were fitted (as `--rules-hard` does) is fitted
/// again: the step gets a lead-in from M in G_M, the one before a lead-out.
#[test]
fn a_chain_fitted_again_after_a_link_became_a_pierce_is_valid() {
    let nest = row(20.0, &[12.0]);
    let fitter = LeadFitter::new(&nest, KerfSettings::plasma_reference());
    let mut route = fitter
        .attach_chained(&chained_over_kerf_nest(&nest, 1.0, 10.0), 0, 0)
        .unwrap()
        .route;
    route.steps[1].entry = Entry::Pierce;
    assert!(route.validate(&nest, 1e-6).is_err());
    let again = fitter.attach_chained(&route, 0, 0).unwrap();
    assert_eq!(again.broken_links, 0);
    assert_eq!(again.route.validate(&nest, 1e-6), Ok(()));
    assert_eq!(again.route.pierce_count(), 2);
    // The first contour keeps its entry.
    assert_eq!(
        again.route.steps[0].leads.as_ref().unwrap().entry,
        route.steps[0].leads.as_ref().unwrap().entry
    );
}
