//! Kerf piercing (issue #17, edge piercing's second form): a step pierced in the open kerf of
//! a contour cut earlier, by a straight lead-in from that kerf; the checker accepts it only
//! where the kerf is really open when the tool gets there.

use cutroute_geometry::{
    generate_nest, Contour, ContourRef, CutStep, KerfSettings, LeadFitter, LeadProblem, LeadShape,
    LeadSpec, MachineParameters, Nest, Part, Point, Route, RouteError, StepLeads, TabSpec, Vertex,
};

/// Kerf 2, d₁ 5, d₂ 1, an 8 mm line lead-in, a 2 mm line lead-out, kerf piercing on.
fn plasma() -> KerfSettings {
    KerfSettings {
        kerf: 2.0,
        pierce_clearance: 5.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Line, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 0.0,
        tabs: TabSpec::default(),
        edge_pierce: false,
        kerf_pierce: true,
    }
}

/// A quick pierce at an edge: 1 s against 7 s.
fn machine() -> MachineParameters {
    MachineParameters {
        pierce_time: 7.0,
        edge_pierce_time: Some(1.0),
        ..MachineParameters::default()
    }
}

/// A 300 × 200 sheet; parts 0 and 1 side by side 8 mm apart, far from the border; part 2 far
/// from both.
fn nest() -> Nest {
    let part = |name: &str, c: Contour| Part {
        name: name.into(),
        contours: vec![c],
    };
    let mut nest = Nest {
        sheet: Some(part("sheet", Contour::rectangle(0.0, 0.0, 300.0, 200.0))),
        parts: vec![
            part("first", Contour::rectangle(60.0, 60.0, 100.0, 100.0)),
            part("beside", Contour::rectangle(108.0, 60.0, 148.0, 100.0)),
            part("far", Contour::rectangle(220.0, 140.0, 260.0, 180.0)),
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

/// Part 0 pierced on its left side, part 1 on the side facing part 0, then part 2.
fn route(fitter: &LeadFitter) -> Route {
    let idealised = Route {
        start: Point::new(0.0, 0.0),
        steps: vec![
            CutStep::pierced(part(0), Point::new(60.0, 80.0)),
            CutStep::pierced(part(1), Point::new(108.0, 80.0)),
            CutStep::pierced(part(2), Point::new(220.0, 160.0)),
        ],
        finish: None,
    };
    fitter.attach(&idealised).expect("leads fit")
}

#[test]
fn a_part_beside_a_cut_one_is_pierced_in_its_kerf_and_the_checker_agrees() {
    let nest = nest();
    let forest = nest.containment_forest();
    let fitter = LeadFitter::new(&nest, plasma());
    let mut route = route(&fitter);
    let seconds = |route: &Route| {
        route.time(&nest, &machine()) - route.pierce_count() as f64 * 7.0
            + machine().pierce_seconds(route.pierce_count(), route.kerf_pierce_count())
    };
    let before = seconds(&route);
    assert_eq!(fitter.pierce_into_kerfs(&mut route, &machine()), 1);
    let leads = route.steps[1].leads.as_ref().unwrap();
    assert_eq!(leads.kerf_pierce, Some(part(0)));
    // M on part 0's equidistant (x = 101, between the parts) and a straight lead to the entry.
    let eq0 = fitter.equidistant(part(0)).unwrap();
    assert!(eq0.distance_to(leads.pierce) < 1e-9, "{:?}", leads.pierce);
    assert_eq!(leads.lead_in.len(), 2);
    assert!(leads.lead_in_length() <= plasma().edge_reach() + 1e-9);
    assert!(
        route.problems(&nest, &forest, 1e-6).is_empty(),
        "{:?}",
        route.problems(&nest, &forest, 1e-6)
    );
    assert_eq!(route.edge_pierce_count(), 0);
    assert_eq!(route.kerf_pierce_count(), 1);
    // The quick pierce is what the move buys.
    let after = seconds(&route);
    assert!(after < before - 5.0, "{after} vs {before}");
    // Part 2 is far from every kerf: pierced as usual.
    assert_eq!(route.steps[2].leads.as_ref().unwrap().kerf_pierce, None);
}

#[test]
fn no_kerf_pierce_when_off_without_a_kerf_or_without_a_gain() {
    let nest = nest();
    for settings in [
        KerfSettings {
            kerf_pierce: false,
            ..plasma()
        },
        KerfSettings {
            kerf: 0.0,
            ..plasma()
        },
    ] {
        let fitter = LeadFitter::new(&nest, settings);
        let mut route = route(&fitter);
        assert_eq!(fitter.pierce_into_kerfs(&mut route, &machine()), 0);
    }
    // An edge pierce as slow as a pierce gains nothing here (M moves away from the tool).
    let fitter = LeadFitter::new(&nest, plasma());
    let mut route = route(&fitter);
    let slow = MachineParameters {
        edge_pierce_time: None,
        ..machine()
    };
    let idle = route.idle_length();
    let moved = fitter.pierce_into_kerfs(&mut route, &slow);
    assert!(moved == 0 || route.idle_length() < idle, "{moved}");
}

#[test]
fn the_checker_refuses_kerf_pierces_that_are_not_true() {
    let nest = nest();
    let forest = nest.containment_forest();
    let fitter = LeadFitter::new(&nest, plasma());
    let mut route = route(&fitter);
    fitter.pierce_into_kerfs(&mut route, &machine());
    assert!(route.problems(&nest, &forest, 1e-6).is_empty());

    // The kerf is cut after the step pierced in it.
    let mut swapped = route.clone();
    swapped.steps.swap(0, 1);
    let problems = swapped.problems(&nest, &forest, 1e-6);
    assert!(
        problems.iter().any(|p| matches!(
            p,
            RouteError::KerfPierceBeforeCut { kerf_of, .. } if *kerf_of == part(0)
        )),
        "{problems:?}"
    );

    // M off the kerf, 1 mm into the gap (the lead still joins it to the entry).
    let mut off = route.clone();
    let leads = off.steps[1].leads.as_mut().unwrap();
    leads.pierce += Point::new(1.0, 0.0);
    leads.lead_in[0] = Vertex::line(leads.pierce.x, leads.pierce.y);
    let problems = off.problems(&nest, &forest, 1e-6);
    assert!(
        problems.iter().any(|p| matches!(
            p,
            RouteError::Lead {
                problem: LeadProblem::KerfPierceOffKerf { .. },
                ..
            }
        )),
        "{problems:?}"
    );

    // The kerf of a contour far away named instead.
    let mut wrong = route.clone();
    wrong.steps.swap(0, 2);
    wrong.steps[1].leads.as_mut().unwrap().kerf_pierce = Some(part(2));
    let problems = wrong.problems(&nest, &forest, 1e-6);
    assert!(
        problems.iter().any(|p| matches!(
            p,
            RouteError::Lead {
                problem: LeadProblem::KerfPierceOffKerf { .. },
                ..
            }
        )),
        "{problems:?}"
    );
}

#[test]
fn a_tab_is_material_no_kerf_pierce_lands_in_its_gap() {
    let nest = nest();
    let forest = nest.containment_forest();
    let fitter = LeadFitter::new(&nest, plasma());
    let mut route = route(&fitter);
    fitter.pierce_into_kerfs(&mut route, &machine());
    let m = route.steps[1].leads.as_ref().unwrap().pierce;
    // A tab in part 0's cut right where M lies.
    let eq0 = fitter.equidistant(part(0)).unwrap();
    let cut = route.steps[0].leads.as_mut().unwrap();
    let position = |p: Point| eq0.length_at(eq0.nearest_point(p).unwrap().position);
    let along = (position(m) - position(cut.entry)).rem_euclid(eq0.perimeter());
    let at = |s: f64| {
        eq0.point_at_length((position(cut.entry) + s).rem_euclid(eq0.perimeter()))
            .unwrap()
    };
    cut.tabs = vec![cutroute_geometry::Tab {
        start: along - 1.0,
        end: along + 1.0,
        from: at(along - 1.0),
        to: at(along + 1.0),
    }];
    let problems = route.problems(&nest, &forest, 1e-6);
    assert!(
        problems.iter().any(|p| matches!(
            p,
            RouteError::Lead {
                step: 1,
                problem: LeadProblem::KerfPierceOffKerf { .. },
                ..
            }
        )),
        "{problems:?}"
    );
    // The pass does not pierce there: with the tab in place it leaves step 1 as fitted.
    let mut again = route.clone();
    let fresh = fitter.attach_to_step(&CutStep::pierced(part(1), Point::new(108.0, 80.0)));
    again.steps[1] = fresh.unwrap();
    fitter.pierce_into_kerfs(&mut again, &machine());
    let moved_to = again.steps[1].leads.as_ref().unwrap();
    assert!(
        moved_to.kerf_pierce.is_none() || moved_to.pierce.distance(m) > 1.0,
        "{moved_to:?}"
    );
}

/// The kerf-piercing pass as first written, through the public API: every step tested against
/// the boxes of all the steps before it (quadratic in the route's length). The pass looks the
/// earlier cuts up in an R-tree instead and must pierce exactly where this does.
// `!(distance <= reach)` as in the pass: a NaN distance is not within reach.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn pierce_into_kerfs_by_scanning(
    fitter: &LeadFitter,
    route: &mut Route,
    machine: &MachineParameters,
) -> usize {
    let settings = fitter.settings();
    if !settings.kerf_pierce || settings.kerf <= 0.0 {
        return 0;
    }
    let reach = settings.edge_reach();
    let half = settings.kerf / 2.0;
    let mut moved = 0;
    for i in 0..route.steps.len() {
        let step = &route.steps[i];
        let Some(leads) = step.leads.as_ref().filter(|_| step.is_pierced()) else {
            continue;
        };
        if leads.edge_pierce || leads.kerf_pierce.is_some() {
            continue;
        }
        let before = if i == 0 {
            route.start
        } else {
            route.steps[i - 1].switch_off_point()
        };
        let seconds = |m: Point, pierce: f64| before.distance(m) / machine.idle_speed + pierce;
        let mut best: (f64, Option<StepLeads>) = (seconds(leads.pierce, machine.pierce_time), None);
        for earlier in &route.steps[..i] {
            let (kerf_of, Some(cut)) = (earlier.contour, earlier.leads.as_ref()) else {
                continue;
            };
            let near = fitter.nest().contour(kerf_of).is_some_and(|c| {
                c.bounding_box()
                    .expanded(half + reach)
                    .contains_point(leads.entry)
            });
            if kerf_of == step.contour || !near {
                continue;
            }
            let Ok(eq) = fitter.equidistant(kerf_of) else {
                continue;
            };
            let Some(at) = eq.nearest_point(leads.entry).map(|n| n.point) else {
                continue;
            };
            let time = seconds(at, machine.edge_pierce_seconds());
            if !(at.distance(leads.entry) <= reach) || time >= best.0 - 1e-9 {
                continue;
            }
            let pierced = StepLeads {
                pierce: at,
                lead_in: vec![
                    Vertex::line(at.x, at.y),
                    Vertex::line(leads.entry.x, leads.entry.y),
                ],
                kerf_pierce: Some(kerf_of),
                ..leads.clone()
            };
            // The step's other leads passed the checker before, so the whole set passes
            // (entered without a pierce in G_M) exactly when the new lead-in does.
            if fitter.kerf_pierce_problem(kerf_of, cut, at).is_none()
                && fitter
                    .problems_linked(step.contour, &pierced, true, false)
                    .is_empty()
            {
                best = (time, Some(pierced));
            }
        }
        if let (_, Some(pierced)) = best {
            route.steps[i].leads = Some(pierced);
            moved += 1;
        }
    }
    moved
}

/// Every contour of `nest` in a route that cuts the deepest contours first (so every contour
/// after those inside it), each pierced near its first vertex (contours with no room for the
/// leads left out), with leads attached.
fn route_with_leads(fitter: &LeadFitter, nest: &Nest) -> Route {
    let forest = nest.containment_forest();
    let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
    refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r)));
    let steps = refs
        .into_iter()
        .filter_map(|r| {
            let near = nest.contour(r)?.vertices[0].point;
            fitter.attach_to_step(&CutStep::pierced(r, near)).ok()
        })
        .collect();
    Route {
        start: Point::new(0.0, 0.0),
        steps,
        finish: None,
    }
}

/// `nest` without the contours that have no room for the leads (a part whose outer contour
/// has none goes whole): the generator's smallest holes are narrower than d₁ = 5.
fn with_room(nest: Nest, settings: KerfSettings) -> Nest {
    let fitter = LeadFitter::new(&nest, settings);
    let fits = |part: usize, contour: usize| {
        let r = ContourRef { part, contour };
        let near = nest.contour(r).unwrap().vertices[0].point;
        fitter.attach_to_step(&CutStep::pierced(r, near)).is_ok()
    };
    let parts = (0..nest.parts.len())
        .filter(|&p| fits(p, 0))
        .map(|p| Part {
            name: nest.parts[p].name.clone(),
            contours: (0..nest.parts[p].contours.len())
                .filter(|&c| c == 0 || fits(p, c))
                .map(|c| nest.parts[p].contours[c].clone())
                .collect(),
        })
        .collect();
    Nest {
        sheet: nest.sheet.clone(),
        parts,
    }
}

/// The R-tree pass and the scanning one pierce the same steps the same way, on the nests of
/// the benchmark and generated ones, and every route still passes the checker.
#[test]
fn the_indexed_pass_pierces_exactly_where_scanning_every_earlier_cut_does() {
    let read = |name: &str| {
        let path = format!("{}/../../data/nests/{name}", env!("CARGO_MANIFEST_DIR"));
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
        let mut nest = cutroute_formats::read_nest(&bytes).expect("a nest");
        nest.normalize_orientation();
        nest
    };
    let settings = KerfSettings {
        lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        ..plasma()
    };
    let nests = [
        ("nested.dbs", read("dbs/nested.dbs")),
        // Not test1: one of its parts lies in a hole of its own shape, which no kerf cuts right
        // (the checker rejects every route over it with a kerf).
        ("E1X_6_01.dbs.json", read("dbs-json/E1X_6_01.dbs.json")),
        (
            "generated 400, seed 1",
            with_room(generate_nest(400, 1), settings),
        ),
        (
            "generated 400, seed 2",
            with_room(generate_nest(400, 2), settings),
        ),
    ];
    let mut pierced_somewhere = 0;
    for (name, nest) in &nests {
        let forest = nest.containment_forest();
        let fitter = LeadFitter::new(nest, settings);
        let route = route_with_leads(&fitter, nest);
        let problems = route.problems(nest, &forest, 1e-6);
        assert!(problems.is_empty(), "{name}: {problems:?}");
        let (mut indexed, mut scanned) = (route.clone(), route);
        let moved = fitter.pierce_into_kerfs(&mut indexed, &machine());
        let moved_by_scanning = pierce_into_kerfs_by_scanning(&fitter, &mut scanned, &machine());
        assert_eq!(moved, moved_by_scanning, "{name}");
        assert_eq!(indexed, scanned, "{name}");
        let problems = indexed.problems(nest, &forest, 1e-6);
        assert!(problems.is_empty(), "{name}: {problems:?}");
        pierced_somewhere += usize::from(moved > 0);
    }
    assert_eq!(pierced_somewhere, nests.len());
}
