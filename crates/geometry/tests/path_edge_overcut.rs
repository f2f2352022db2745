//! Edge piercing and overcut on path routes (issue #17): a path starting on a part's outer
//! contour near the sheet's border may be pierced at the border; a closed path runs on past
//! its start by the overcut, an open one does not. The checker accepts each only where true.

use cutroute_geometry::{
    Contour, ContourRef, KerfSettings, LeadFitter, LeadProblem, LeadShape, LeadSpec, Nest, Part,
    PathLeadError, PathRoute, PathRouteError, Point, Route, Span, TabSpec, ToolOnPath, Toolpath,
    Vertex,
};

/// Kerf 2, d₁ 5, d₂ 1, an 8 mm arc lead-in, a 2 mm line lead-out, 3 mm overcut, edge
/// piercing on.
fn plasma() -> KerfSettings {
    KerfSettings {
        kerf: 2.0,
        pierce_clearance: 5.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 3.0,
        edge_pierce: true,
        ..KerfSettings::default()
    }
}

/// A 200 × 100 sheet; part 0 4 mm from the left border, part 1 (with a hole) in the middle.
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
                contours: vec![
                    Contour::rectangle(80.0, 30.0, 140.0, 70.0),
                    Contour::rectangle(95.0, 40.0, 125.0, 60.0),
                ],
            },
        ],
    };
    nest.normalize_orientation();
    nest
}

/// The innermost-first route over the kerf nest as paths (one closed path per contour),
/// started by the left border, with leads.
fn whole_contours(nest: &Nest, settings: KerfSettings) -> PathRoute {
    let fitter = LeadFitter::new(nest, settings);
    let kerf_nest = fitter.kerf_nest();
    let route = Route::innermost_first(&kerf_nest, Point::new(0.0, 15.0), None);
    let paths = PathRoute::from_route(&route, &kerf_nest).expect("contours of the nest");
    fitter.attach_paths(&paths).expect("room for every lead")
}

fn lead_problems(route: &PathRoute, nest: &Nest) -> Vec<LeadProblem> {
    route
        .problems(nest, 1e-6)
        .into_iter()
        .filter_map(|p| match p {
            PathRouteError::Lead(PathLeadError { problem, .. }) => Some(problem),
            _ => None,
        })
        .collect()
}

fn path_of(route: &PathRoute, nest: &Nest, part: usize) -> usize {
    let contour = &nest.parts[part].contours[0];
    route
        .paths
        .iter()
        .position(|p| (contour.distance_to(p.spans[0].start) - 1.0).abs() < 1e-6)
        .expect("a path on the part")
}

#[test]
fn a_path_by_the_border_is_edge_pierced_and_the_checker_agrees() {
    let nest = nest();
    let route = whole_contours(&nest, plasma());
    assert_eq!(route.problems(&nest, 1e-6), Vec::new());
    let border = &nest.sheet.as_ref().unwrap().contours[0];
    let edge = &route.paths[path_of(&route, &nest, 0)];
    let leads = edge.leads.as_ref().unwrap();
    assert!(leads.edge_pierce, "{leads:?}");
    assert!(border.distance_to(edge.pierce) < 1e-9);
    assert_eq!(leads.lead_in.len(), 2, "a straight lead from the border");
    assert!(leads.lead_in_length() <= plasma().edge_reach() + 1e-9);
    // Only part 0 is near enough to the border; holes never are.
    assert_eq!(route.edge_pierce_count(), 1);
    // Off: no edge pierce, M in G_M.
    let off = whole_contours(
        &nest,
        KerfSettings {
            edge_pierce: false,
            ..plasma()
        },
    );
    assert_eq!(off.problems(&nest, 1e-6), Vec::new());
    assert_eq!(off.edge_pierce_count(), 0);
    let usual = &off.paths[path_of(&off, &nest, 0)];
    assert!(nest.parts[0].contours[0].distance_to(usual.pierce) >= 5.0 - 1e-9);
}

#[test]
fn the_checker_refuses_a_false_edge_pierce() {
    let nest = nest();
    let good = whole_contours(&nest, plasma());
    let k = path_of(&good, &nest, 0);
    // M moved off the border into the sheet, the lead still joined to it.
    let mut inside = good.clone();
    let path = &mut inside.paths[k];
    let leads = path.leads.as_mut().unwrap();
    let m = path.pierce + (leads.entry - path.pierce) * 0.5;
    path.pierce = m;
    leads.lead_in[0] = Vertex::arc(m.x, m.y, 0.0);
    assert!(lead_problems(&inside, &nest)
        .iter()
        .any(|p| matches!(p, LeadProblem::EdgePierceOffBorder { .. })));
    // The middle part's usual leads marked as an edge pierce.
    let mut middle = good.clone();
    let m = path_of(&middle, &nest, 1);
    middle.paths[m].leads.as_mut().unwrap().edge_pierce = true;
    assert!(lead_problems(&middle, &nest)
        .iter()
        .any(|p| matches!(p, LeadProblem::EdgePierceOffBorder { .. })));
    // An edge lead through part 0's material: from the border straight to the entry of
    // part 0's far side.
    let mut through = good.clone();
    let path = &mut through.paths[k];
    let far = Point::new(41.0, 15.0);
    let border_point = Point::new(0.0, 15.0);
    path.pierce = border_point;
    let leads = path.leads.as_mut().unwrap();
    leads.lead_in = vec![
        Vertex::arc(border_point.x, border_point.y, 0.0),
        Vertex::arc(far.x, far.y, 0.0),
    ];
    leads.entry = far;
    assert!(!lead_problems(&through, &nest).is_empty());
}

#[test]
fn closed_paths_run_on_by_the_overcut_and_count_it() {
    let nest = nest();
    let route = whole_contours(&nest, plasma());
    let plain = whole_contours(
        &nest,
        KerfSettings {
            overcut: 0.0,
            ..plasma()
        },
    );
    for path in &route.paths {
        let leads = path.leads.as_ref().unwrap();
        assert_eq!(leads.overcut, 3.0);
        let overcut = path.overcut_spans();
        let run_on: f64 = overcut.iter().map(Span::length).sum();
        assert!((run_on - 3.0).abs() < 1e-9, "{run_on}");
        // The overcut retraces the path from its start; the lead-out leaves at its end.
        assert!(overcut[0].start.distance(path.spans[0].start) < 1e-12);
        assert!(leads.exit().distance(overcut.last().unwrap().end) < 1e-9);
        let spans: f64 = path.spans.iter().map(Span::length).sum();
        assert!((path.length() - spans - 3.0 - path.leads_length()).abs() < 1e-9);
    }
    // The toolpath (what the G-code writes) cuts the overcut too.
    let toolpath = Toolpath::from_path_route(&route);
    assert!((toolpath.cut_length() - route.cut_length()).abs() < 1e-9);
    assert_eq!(toolpath.pierce_count(), route.pierce_count());
    assert_eq!(plain.paths.len(), route.paths.len());
    for path in &plain.paths {
        assert!(path.overcut_spans().is_empty());
    }
}

#[test]
fn the_checker_refuses_a_wrong_overcut() {
    let nest = nest();
    let good = whole_contours(&nest, plasma());
    // A longer overcut than the lead-out starts after: the lead-out is not joined to it.
    let mut longer = good.clone();
    longer.paths[0].leads.as_mut().unwrap().overcut = 6.0;
    assert!(lead_problems(&longer, &nest).contains(&LeadProblem::Disjoint));
    // A negative overcut.
    let mut negative = good.clone();
    negative.paths[0].leads.as_mut().unwrap().overcut = -1.0;
    assert!(lead_problems(&negative, &nest)
        .iter()
        .any(|p| matches!(p, LeadProblem::OvercutMisplaced { .. })));
}

#[test]
fn open_paths_get_no_overcut_and_an_overcut_on_one_is_refused() {
    // One square's equidistant cut in two open paths.
    let nest = nest();
    let fitter = LeadFitter::new(&nest, plasma());
    let r = ContourRef {
        part: 1,
        contour: 0,
    };
    let eq = fitter.equidistant(r).unwrap();
    let spans: Vec<Span> = eq.spans().collect();
    let half = spans.len() / 2;
    let route = PathRoute {
        start: Point::new(60.0, 50.0),
        paths: vec![
            ToolOnPath::new(spans[0].start, spans[..half].to_vec()),
            ToolOnPath::new(spans[half].start, spans[half..].to_vec()),
        ],
        finish: None,
    };
    // The hole first (precedence): as a whole contour.
    let hole = ContourRef {
        part: 1,
        contour: 1,
    };
    let hole_eq = fitter.equidistant(hole).unwrap();
    let mut route = route;
    route.paths.insert(
        0,
        ToolOnPath::new(hole_eq.vertices[0].point, hole_eq.spans().collect()),
    );
    // Part 0 as a whole contour too.
    let part0_eq = fitter
        .equidistant(ContourRef {
            part: 0,
            contour: 0,
        })
        .unwrap();
    route.paths.push(ToolOnPath::new(
        part0_eq.vertices[0].point,
        part0_eq.spans().collect(),
    ));
    let attached = fitter.attach_paths(&route).expect("room");
    assert_eq!(attached.problems(&nest, 1e-6), Vec::new());
    assert_eq!(attached.paths[0].leads.as_ref().unwrap().overcut, 3.0);
    for open in &attached.paths[1..3] {
        assert_eq!(open.leads.as_ref().unwrap().overcut, 0.0);
        assert!(open.overcut_spans().is_empty());
    }
    // An overcut written onto an open path (its lead-out moved to where it would end) is
    // refused.
    let mut wrong = attached.clone();
    let path = &mut wrong.paths[1];
    path.leads.as_mut().unwrap().overcut = 1.0;
    let end = path.overcut_spans().last().unwrap().end;
    path.leads.as_mut().unwrap().lead_out[0] = Vertex::arc(end.x, end.y, 0.0);
    assert!(lead_problems(&wrong, &nest)
        .iter()
        .any(|p| matches!(p, LeadProblem::OvercutMisplaced { .. })));
}

#[test]
fn whole_outer_contours_get_tabs_that_count_as_pierces_and_idle_gaps() {
    let nest = nest();
    let settings = KerfSettings {
        tabs: TabSpec {
            count: 2,
            width: 1.5,
        },
        ..plasma()
    };
    let route = whole_contours(&nest, settings);
    assert_eq!(route.problems(&nest, 1e-6), Vec::new());
    let tabs: usize = route.paths.iter().map(|p| p.tabs().len()).sum();
    // Two per part's outer contour, none in the hole.
    assert_eq!(tabs, 4);
    assert_eq!(route.pierce_count(), route.paths.len() + 4);
    let plain = whole_contours(&nest, plasma());
    let cut = |r: &PathRoute| r.cut_length();
    assert!((cut(&plain) - cut(&route) - 4.0 * 1.5).abs() < 1e-6);
    // The toolpath (what the G-code writes) stops at every gap and pierces after it.
    let toolpath = Toolpath::from_path_route(&route);
    assert_eq!(toolpath.pierce_count(), route.pierce_count());
    assert!((toolpath.cut_length() - route.cut_length()).abs() < 1e-9);
    assert!((toolpath.idle_length() - route.idle_length()).abs() < 1e-9);
    // A tab moved past the end of its path's cut is refused.
    let mut late = route.clone();
    let path = late
        .paths
        .iter_mut()
        .find(|p| !p.tabs().is_empty())
        .unwrap();
    let length: f64 = path.spans.iter().map(Span::length).sum();
    let tab = &mut path.leads.as_mut().unwrap().tabs[0];
    tab.start = length + 1.0;
    tab.end = length + 2.5;
    assert!(lead_problems(&late, &nest)
        .iter()
        .any(|p| matches!(p, LeadProblem::TabMisplaced { .. })));
    // A tab slid onto a corner of the equidistant (its ends moved with it) is refused.
    let mut corner = route.clone();
    let path = corner
        .paths
        .iter_mut()
        .find(|p| !p.tabs().is_empty())
        .unwrap();
    let first = path.spans[0];
    let to_corner = first.length();
    let spans = path.spans.clone();
    let at = |s: f64| {
        let mut left = s;
        for span in &spans {
            let l = span.length();
            if left <= l {
                return span.point_at(left / l);
            }
            left -= l;
        }
        spans.last().unwrap().end
    };
    let tab = &mut path.leads.as_mut().unwrap().tabs[0];
    tab.start = to_corner - 0.5;
    tab.end = to_corner + 1.0;
    tab.from = at(tab.start);
    tab.to = at(tab.end);
    assert!(lead_problems(&corner, &nest)
        .iter()
        .any(|p| matches!(p, LeadProblem::TabMisplaced { .. })));
}
