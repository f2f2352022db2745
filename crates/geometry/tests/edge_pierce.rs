//! Edge piercing (issue #17): a part's outer contour pierced at the sheet's border, with a
//! straight lead-in from the border; the checker accepts it only where it is true.

use cutroute_geometry::{
    Contour, ContourRef, KerfSettings, LeadFitter, LeadProblem, LeadShape, LeadSpec,
    MachineParameters, Nest, Part, Point, Route, TabSpec, Vertex,
};

/// Kerf 2, d₁ 5, d₂ 1, an 8 mm arc lead-in, a 2 mm line lead-out, edge piercing on.
fn plasma_edge() -> KerfSettings {
    KerfSettings {
        kerf: 2.0,
        pierce_clearance: 5.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 0.0,
        tabs: TabSpec::default(),
        edge_pierce: true,
        kerf_pierce: false,
    }
}

/// A 200 × 100 sheet; part 0 near the left border (4 mm from it), part 1 in the middle, part 2
/// a small square between part 3 and the left border.
fn nest() -> Nest {
    let mut nest = Nest {
        sheet: Some(Part {
            name: "sheet".into(),
            contours: vec![Contour::rectangle(0.0, 0.0, 200.0, 100.0)],
        }),
        parts: vec![
            Part {
                name: "edge".into(),
                contours: vec![Contour::rectangle(4.0, 4.0, 40.0, 30.0)],
            },
            Part {
                name: "middle".into(),
                contours: vec![Contour::rectangle(80.0, 30.0, 120.0, 70.0)],
            },
            Part {
                name: "blocker".into(),
                contours: vec![Contour::rectangle(3.0, 55.0, 9.0, 65.0)],
            },
            Part {
                name: "behind".into(),
                contours: vec![Contour::rectangle(20.0, 45.0, 50.0, 75.0)],
            },
        ],
    };
    nest.normalize_orientation();
    nest
}

fn part(i: usize) -> ContourRef {
    ContourRef {
        part: i,
        contour: 0,
    }
}

#[test]
fn a_part_near_the_border_is_pierced_at_it_and_the_checker_agrees() {
    let nest = nest();
    let fitter = LeadFitter::new(&nest, plasma_edge());
    let border = &nest.sheet.as_ref().unwrap().contours[0];
    let leads = fitter.fit(part(0), Point::new(0.0, 15.0)).expect("fits");
    assert!(leads.edge_pierce, "{leads:?}");
    assert!(border.distance_to(leads.pierce) < 1e-9);
    assert_eq!(leads.lead_in.len(), 2, "a straight lead from the border");
    assert!(leads.lead_in_length() <= plasma_edge().edge_reach() + 1e-9);
    assert!(fitter.problems(part(0), &leads).is_empty());
    // Far from every border, the usual lead: M in G_M.
    let middle = fitter.fit(part(1), Point::new(0.0, 0.0)).expect("fits");
    assert!(!middle.edge_pierce);
    assert!(fitter.problems(part(1), &middle).is_empty());
    // Off, no edge pierce anywhere.
    let off = LeadFitter::new(
        &nest,
        KerfSettings {
            edge_pierce: false,
            ..plasma_edge()
        },
    );
    let usual = off.fit(part(0), Point::new(0.0, 15.0)).expect("fits");
    assert!(!usual.edge_pierce);
    assert!(nest.parts[0].contours[0].distance_to(usual.pierce) >= 5.0 - 1e-9);
}

#[test]
fn the_checker_refuses_edge_pierces_that_are_not_true() {
    let nest = nest();
    let fitter = LeadFitter::new(&nest, plasma_edge());
    let leads = fitter.fit(part(0), Point::new(0.0, 15.0)).expect("fits");
    assert!(leads.edge_pierce);
    // M moved off the border into the sheet (the lead still joins it to the entry).
    let mut inside = leads.clone();
    inside.pierce = inside.pierce + (inside.entry - inside.pierce) * 0.5;
    inside.lead_in[0] = Vertex::arc(inside.pierce.x, inside.pierce.y, 0.0);
    assert!(fitter
        .problems(part(0), &inside)
        .iter()
        .any(|p| matches!(p, LeadProblem::EdgePierceOffBorder { .. })));
    // A middle part's usual leads marked as an edge pierce: not on the border.
    let mut middle = fitter.fit(part(1), Point::new(0.0, 0.0)).expect("fits");
    middle.edge_pierce = true;
    assert!(fitter
        .problems(part(1), &middle)
        .iter()
        .any(|p| matches!(p, LeadProblem::EdgePierceOffBorder { .. })));
    // A lead from the border through another part's kerf: part 3's left side at x = 19
    // (the equidistant), the border at x = 0, the blocker at x ∈ [3, 9], y ∈ [55, 65].
    let behind = fitter.fit(part(3), Point::new(0.0, 60.0)).expect("fits");
    let mut through = behind.clone();
    let entry = Point::new(19.0, 60.0);
    through.entry = entry;
    through.pierce = Point::new(0.0, 60.0);
    through.lead_in = vec![Vertex::line(0.0, 60.0), Vertex::line(entry.x, entry.y)];
    through.edge_pierce = true;
    let problems = fitter.problems(part(3), &through);
    assert!(
        problems
            .iter()
            .any(|p| matches!(p, LeadProblem::LeadTooClose { .. })),
        "{problems:?}"
    );
    // The fitter never makes that lead: part 3's leads keep clear of the blocker.
    assert!(fitter.problems(part(3), &behind).is_empty());
}

#[test]
fn edge_pierces_are_priced_at_the_edge_pierce_time_and_counted_on_routes() {
    let machine = MachineParameters {
        pierce_time: 7.0,
        edge_pierce_time: Some(1.0),
        ..MachineParameters::default()
    };
    assert_eq!(machine.pierce_seconds(10, 3), 7.0 * 7.0 + 3.0);
    // Without an edge-pierce time every pierce takes the pierce time.
    assert_eq!(MachineParameters::default().pierce_seconds(10, 3), 70.0);
    let nest = nest();
    let fitter = LeadFitter::new(&nest, plasma_edge());
    let origin = Point::new(0.0, 0.0);
    let route = fitter
        .attach(&Route::innermost_first(&nest, origin, None))
        .expect("leads fit");
    assert!(route
        .problems(&nest, &nest.containment_forest(), 1e-6)
        .is_empty());
    assert!(route.edge_pierce_count() >= 1);
    assert!(route.edge_pierce_count() < route.pierce_count());
}
