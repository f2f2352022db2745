//! Micro-joints (tabs): N gaps of width w in the outer contour of every part, away from corners;
//! the torch stops at each gap and pierces after it, and every length, count and time of the
//! route says so.

use cutroute_geometry::{
    generate_nest, place_tabs, Contour, ContourRef, CutStep, KerfSettings, LeadFitter, LeadProblem,
    LeadShape, LeadSpec, MachineParameters, Nest, Point, Route, RouteError, TabSpec, ToolMove,
    Toolpath, Vertex,
};
use proptest::prelude::*;

fn settings(count: usize, width: f64) -> KerfSettings {
    KerfSettings {
        kerf: 2.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 1.0,
        tabs: TabSpec { count, width },
        edge_pierce: false,
        kerf_pierce: false,
    }
}

fn idealised_route(nest: &Nest) -> Route {
    let origin = Point::new(0.0, 0.0);
    Route::innermost_first(nest, origin, Some(origin))
}

/// The corners of `eq` as arc-length intervals from `entry`: turns of more than `deg` degrees
/// (no length), and arcs of radius at most `offset` (the rounding of an outward offset's
/// corner). Intervals that wrap past the entry are split.
fn corners(eq: &Contour, entry: Point, deg: f64, offset: f64) -> Vec<(f64, f64)> {
    let spans: Vec<_> = eq.spans().collect();
    let n = spans.len();
    let perimeter = eq.perimeter();
    let origin = eq.length_at(eq.nearest_point(entry).unwrap().position);
    let mut at = 0.0;
    let mut out = Vec::new();
    let mut add = |from: f64, length: f64| {
        let a = (from - origin).rem_euclid(perimeter);
        if a + length > perimeter {
            out.push((a, perimeter));
            out.push((0.0, a + length - perimeter));
        } else {
            out.push((a, a + length));
        }
    };
    for k in 0..n {
        let a = spans[(k + n - 1) % n].tangent_at(1.0);
        let b = spans[k].tangent_at(0.0);
        if a.cross(b).atan2(a.dot(b)).abs() > deg.to_radians() {
            add(at, 0.0);
        }
        if spans[k].bulge != 0.0 && spans[k].radius() <= offset + 1e-9 {
            add(at, spans[k].length());
        }
        at += spans[k].length();
    }
    out
}

#[test]
fn every_part_gets_its_tabs_away_from_corners_and_the_route_counts_them() {
    let machine = MachineParameters::default();
    for seed in [5, 6, 7] {
        let nest = generate_nest(40, seed);
        let forest = nest.containment_forest();
        let route = idealised_route(&nest);
        let plain = LeadFitter::new(&nest, settings(0, 0.0))
            .attach(&route)
            .unwrap();
        let fitter = LeadFitter::new(&nest, settings(3, 1.5));
        let tabbed = fitter.attach(&route).expect("every contour has room");
        assert_eq!(tabbed.problems(&nest, &forest, 1e-6), vec![], "seed {seed}");
        let mut tabs = 0;
        for (step, plain_step) in tabbed.steps.iter().zip(&plain.steps) {
            let leads = step.leads.as_ref().unwrap();
            let hole = forest.depth(step.contour).unwrap() % 2 == 1;
            if hole {
                assert!(leads.tabs.is_empty(), "holes fall out: no tabs");
                continue;
            }
            assert!(leads.tabs.len() <= 3);
            tabs += leads.tabs.len();
            let eq = fitter.equidistant(step.contour).unwrap();
            let perimeter = eq.perimeter();
            // Each gap is 1.5 mm along the cut, inside the cut, clear of the start and end
            // (lead-in, overcut, lead-out) and at least its width from every corner.
            let corners = corners(&eq, leads.entry, 20.0, leads.offset);
            for tab in &leads.tabs {
                assert!((tab.width() - 1.5).abs() < 1e-9);
                assert!(
                    tab.start >= leads.overcut + 1.5 - 1e-9 && tab.end <= perimeter - 1.5 + 1e-9
                );
                for &(c0, c1) in &corners {
                    assert!(
                        c1 < tab.start - 1.5 + 1e-6 || c0 > tab.end + 1.5 - 1e-6,
                        "corner {c0}..{c1} near {tab:?}"
                    );
                }
                assert!((eq.distance_to(tab.from)).abs() < 1e-6 && eq.distance_to(tab.to) < 1e-6);
            }
            // The gaps are taken off the step's cut.
            let contour = nest.contour(step.contour).unwrap();
            let gaps: f64 = leads.tabs.iter().map(|t| t.width()).sum();
            let same_entry = plain_step
                .leads
                .as_ref()
                .unwrap()
                .entry
                .distance(leads.entry)
                < 1e-9;
            if same_entry {
                assert!(
                    (plain_step.cut_length_on(contour) - step.cut_length_on(contour) - gaps).abs()
                        < 1e-6
                );
            }
        }
        assert!(tabs > 0, "seed {seed}: some part got tabs");
        // One more pierce per tab; the head crosses each gap with the torch off.
        assert_eq!(tabbed.pierce_count(), tabbed.steps.len() + tabs);
        let toolpath = Toolpath::new(&tabbed, &nest).unwrap();
        assert_eq!(toolpath.pierce_count(), tabbed.pierce_count());
        assert!((toolpath.cut_length() - tabbed.cut_length(&nest)).abs() < 1e-6);
        assert!((toolpath.idle_length() - tabbed.idle_length()).abs() < 1e-6);
        let by_moves = machine.time(
            toolpath.cut_length(),
            toolpath.idle_length(),
            toolpath.pierce_count(),
        );
        assert!((tabbed.time(&nest, &machine) - by_moves).abs() < 1e-9);
        // Every gap's crossing is an idle move followed by a pierce at its end.
        let gap_moves = toolpath
            .moves
            .windows(2)
            .filter(|w| matches!((w[0], w[1]), (ToolMove::Idle { to, .. }, ToolMove::Pierce { at, .. }) if to == at))
            .count();
        assert!(gap_moves >= tabs);
    }
}

#[test]
fn the_checker_rejects_tabs_over_corners_in_holes_or_off_the_cut() {
    let nest = generate_nest(20, 8);
    let forest = nest.containment_forest();
    let fitter = LeadFitter::new(&nest, settings(2, 2.0));
    let tabbed = fitter.attach(&idealised_route(&nest)).unwrap();
    assert_eq!(tabbed.problems(&nest, &forest, 1e-6), vec![]);
    let (k, step) = tabbed
        .steps
        .iter()
        .enumerate()
        .find(|(_, s)| !s.tabs().is_empty())
        .expect("a part with tabs");
    let misplaced = |route: &Route| {
        route.problems(&nest, &forest, 1e-6).iter().any(|p| {
            matches!(
                p,
                RouteError::Lead {
                    problem: LeadProblem::TabMisplaced { .. },
                    ..
                }
            )
        })
    };
    // A tab whose end points are not where its arc lengths say.
    let mut moved = tabbed.clone();
    let tab = &mut moved.steps[k].leads.as_mut().unwrap().tabs[0];
    tab.from += Point::new(0.5, 0.0);
    assert!(misplaced(&moved));
    // A gap past the end of the cut.
    let mut long = tabbed.clone();
    let eq = fitter.equidistant(step.contour).unwrap();
    long.steps[k].leads.as_mut().unwrap().tabs[0].end = eq.perimeter() + 1.0;
    assert!(misplaced(&long));
    // A tab in a hole (holes fall out as scrap and get none).
    let hole = tabbed
        .steps
        .iter()
        .position(|s| forest.depth(s.contour).unwrap() % 2 == 1)
        .expect("a hole in the generated nest");
    let mut holed = tabbed.clone();
    let copied = step.tabs()[0];
    holed.steps[hole].leads.as_mut().unwrap().tabs.push(copied);
    assert!(misplaced(&holed));
    // A gap over a corner: the square's tab moved onto its first corner.
    let square = Contour::new(vec![
        Vertex::line(0.0, 0.0),
        Vertex::line(0.0, 50.0),
        Vertex::line(50.0, 50.0),
        Vertex::line(50.0, 0.0),
    ]);
    let plate = Nest {
        sheet: None,
        parts: vec![cutroute_geometry::Part {
            name: "plate".into(),
            contours: vec![square],
        }],
    };
    let r = ContourRef {
        part: 0,
        contour: 0,
    };
    let route = Route {
        start: Point::new(-20.0, 25.0),
        steps: vec![CutStep::pierced(r, Point::new(0.0, 25.0))],
        finish: None,
    };
    let square_fitter = LeadFitter::new(&plate, settings(4, 2.0));
    let mut routed = square_fitter.attach(&route).unwrap();
    let plate_forest = plate.containment_forest();
    assert_eq!(routed.problems(&plate, &plate_forest, 1e-6), vec![]);
    let leads = routed.steps[0].leads.as_mut().unwrap();
    assert_eq!(leads.tabs.len(), 4, "one tab per side of the square");
    let eq = square_fitter.equidistant(r).unwrap();
    // The first rounded corner of the square's outward equidistant: a quarter circle.
    let (c0, c1) = corners(&eq, leads.entry, 20.0, leads.offset)[0];
    let corner = 0.5 * (c0 + c1);
    let perimeter = eq.perimeter();
    let origin = eq.length_at(eq.nearest_point(leads.entry).unwrap().position);
    let at = |s: f64| {
        let p = eq
            .position_at_length((origin + s).rem_euclid(perimeter))
            .unwrap();
        eq.span(p.span).unwrap().point_at(p.t)
    };
    leads.tabs[0] = cutroute_geometry::Tab {
        start: corner - 1.0,
        end: corner + 1.0,
        from: at(corner - 1.0),
        to: at(corner + 1.0),
    };
    leads.tabs.sort_by(|a, b| a.start.total_cmp(&b.start));
    assert!(routed
        .problems(&plate, &plate_forest, 1e-6)
        .iter()
        .any(|p| matches!(
            p,
            RouteError::Lead {
                problem: LeadProblem::TabMisplaced { .. },
                ..
            }
        )));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// On any rectangle, the tabs are inside the cut, in order, disjoint, as wide as asked and
    /// a width away from every corner; there are never more than asked.
    #[test]
    fn tabs_keep_clear_of_corners(
        w in 10.0f64..200.0,
        h in 10.0f64..200.0,
        entry in 0.0f64..1.0,
        count in 0usize..8,
        width in 0.5f64..5.0,
    ) {
        let rect = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, h),
            Vertex::line(w, h),
            Vertex::line(w, 0.0),
        ]);
        let perimeter = rect.perimeter();
        let entry_s = entry * perimeter;
        let tabs = place_tabs(&rect, 0.0, entry_s, 0.0, TabSpec { count, width });
        prop_assert!(tabs.len() <= count);
        let margin = width.max(1.0);
        let entry_point = {
            let p = rect.position_at_length(entry_s).unwrap();
            rect.span(p.span).unwrap().point_at(p.t)
        };
        let corners = corners(&rect, entry_point, 20.0, 0.0);
        let mut end = 0.0;
        for t in &tabs {
            prop_assert!(t.start >= end && (t.width() - width).abs() < 1e-9);
            prop_assert!(t.start >= margin - 1e-9 && t.end <= perimeter - margin + 1e-9);
            for &(c0, c1) in &corners {
                prop_assert!(c1 <= t.start - margin + 1e-6 || c0 >= t.end + margin - 1e-6);
            }
            end = t.end;
        }
    }
}
