//! Routes with kerf and leads written as G-code and read back: the program cuts on the
//! equidistants with the leads, and reads back with the same lengths and pierces.

use cutroute_gcode::{
    path_route_gcode, read_gcode, route_gcode, ArcOutput, DistanceMode, GcodeOptions, ReadOptions,
};
use cutroute_geometry::{
    chain_spans, generate_nest, Contour, KerfSettings, LeadFitter, LeadShape, LeadSpec, Nest, Part,
    PathRoute, Point, Route, TabSpec, Toolpath, Vertex,
};

/// A generated nest and its baseline route (innermost first) with leads fitted under `settings`,
/// checked.
fn routed(contours: usize, seed: u64, settings: KerfSettings) -> (Nest, Route) {
    let nest = generate_nest(contours, seed);
    let origin = Point::new(0.0, 0.0);
    let route = Route::innermost_first(&nest, origin, Some(origin));
    let route = LeadFitter::new(&nest, settings).attach(&route).unwrap();
    route.validate(&nest, 1e-6).unwrap();
    (nest, route)
}

#[test]
fn a_route_with_leads_reads_back_with_the_same_lengths_and_pierces() {
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 0.5,
        ..KerfSettings::default()
    };
    let (nest, route) = routed(40, 11, settings);
    let path = Toolpath::new(&route, &nest).unwrap();
    for distance_mode in [DistanceMode::Absolute, DistanceMode::Incremental] {
        for arcs in [ArcOutput::CentreOffsets, ArcOutput::Radius] {
            let options = GcodeOptions {
                distance_mode,
                arcs,
                decimals: 6,
                ..GcodeOptions::default()
            };
            let text = route_gcode(&nest, &route, &options).unwrap();
            let program = read_gcode(&text, &ReadOptions::default()).unwrap();
            let what = format!("{distance_mode:?} {arcs:?}");
            assert!(
                (program.cut_length() - route.cut_length(&nest)).abs() < 1e-3,
                "{what}"
            );
            assert!(
                (program.idle_length() - route.idle_length()).abs() < 1e-3,
                "{what}"
            );
            assert!(
                (program.cut_length() - path.cut_length()).abs() < 1e-3,
                "{what}"
            );
            assert_eq!(program.pierce_count(), route.pierce_count(), "{what}");
            // The torch goes on at the pierce points M, off the contours.
            for (read, step) in program.pierce_points().iter().zip(&route.steps) {
                let m = step.leads.as_ref().unwrap().pierce;
                assert!(read.distance(m) < 1e-4, "{what}: {read:?} vs {m:?}");
            }
        }
    }
}

/// A chained route with leads (the chains solved over the kerf nest, leads attached with
/// `attach_chained`) reads back with the same lengths, links included, and one pierce per
/// chain at its M.
#[test]
fn a_chained_route_with_leads_reads_back_with_the_same_lengths_and_pierces() {
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 5.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        ..KerfSettings::default()
    };
    let nest = generate_nest(60, 5);
    let fitter = LeadFitter::new(&nest, settings);
    let kerf_nest = fitter.kerf_nest();
    let origin = Point::new(0.0, 0.0);
    let route = Route::innermost_first(&kerf_nest, origin, Some(origin));
    let chained = cutroute_chains::chain_route(
        &kerf_nest,
        &route,
        &cutroute_chains::ChainOptions::default(),
    )
    .unwrap()
    .route;
    let route = fitter.attach_chained(&chained, 1, 12).unwrap().route;
    route.validate(&nest, 1e-6).unwrap();
    assert!(route.link_length() > 0.0 && route.pierce_count() < route.steps.len());
    let options = GcodeOptions {
        decimals: 6,
        ..GcodeOptions::default()
    };
    let text = route_gcode(&nest, &route, &options).unwrap();
    let program = read_gcode(&text, &ReadOptions::default()).unwrap();
    let (read, cut) = (program.cut_length(), route.cut_length(&nest));
    assert!((read - cut).abs() < 1e-3, "{read} vs {cut}");
    assert!((program.idle_length() - route.idle_length()).abs() < 1e-3);
    assert_eq!(program.pierce_count(), route.pierce_count());
    let pierced = route.steps.iter().filter(|s| s.is_pierced());
    for (read, step) in program.pierce_points().iter().zip(pierced) {
        let m = step.leads.as_ref().unwrap().pierce;
        assert!(read.distance(m) < 1e-3, "{read:?} vs {m:?}");
    }
}

#[test]
fn tabs_read_back_as_pierces_and_idle_gaps() {
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        tabs: TabSpec {
            count: 3,
            width: 1.5,
        },
        ..KerfSettings::default()
    };
    let (nest, route) = routed(40, 7, settings);
    let tabs: usize = route.steps.iter().map(|s| s.tabs().len()).sum();
    assert!(tabs > 0);
    let options = GcodeOptions {
        decimals: 6,
        ..GcodeOptions::default()
    };
    let text = route_gcode(&nest, &route, &options).unwrap();
    let program = read_gcode(&text, &ReadOptions::default()).unwrap();
    // The torch goes on once per step and once after every gap; the gaps are crossed idle.
    assert_eq!(program.pierce_count(), route.steps.len() + tabs);
    assert_eq!(program.pierce_count(), route.pierce_count());
    assert!((program.cut_length() - route.cut_length(&nest)).abs() < 1e-3);
    assert!((program.idle_length() - route.idle_length()).abs() < 1e-3);
}

/// Kerf compensation by the controller: the program runs on the contours with `G41.1 D<kerf>`
/// (or `G41 D<n>` and the tool table's radius) and straight leads as its start-up and cancel
/// moves; the reader offsets it back and finds the route's own tool path.
#[test]
fn controller_compensation_reads_back_as_the_route() {
    use cutroute_gcode::KerfCompensation;
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 3.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Line, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 1.0,
        ..KerfSettings::default()
    };
    let (nest, route) = routed(30, 4, settings);
    for (compensation, read) in [
        (KerfCompensation::ControllerDiameter, ReadOptions::default()),
        (
            KerfCompensation::ControllerRegister(1),
            ReadOptions {
                compensation_radius: Some(1.0),
                ..ReadOptions::default()
            },
        ),
    ] {
        let options = GcodeOptions {
            decimals: 6,
            kerf_compensation: compensation,
            ..GcodeOptions::default()
        };
        let text = route_gcode(&nest, &route, &options).unwrap();
        let on = match compensation {
            KerfCompensation::ControllerRegister(_) => "G41 D1",
            _ => "G41.1 D2.000000",
        };
        assert_eq!(
            text.matches(on).count(),
            route.steps.len(),
            "{compensation:?}"
        );
        assert_eq!(text.matches("G40").count(), route.steps.len());
        // The programmed cut is the contours' (shorter outside, longer in the holes) …
        let programmed = read_gcode(&text, &ReadOptions::default());
        assert!(
            programmed.is_err() == matches!(compensation, KerfCompensation::ControllerRegister(_))
        );
        // … and the compensated read-back is the route's tool path.
        let program = read_gcode(&text, &read).unwrap();
        let what = format!("{compensation:?}");
        assert_eq!(program.pierce_count(), route.pierce_count(), "{what}");
        assert!(
            (program.cut_length() - route.cut_length(&nest)).abs() < 1e-3,
            "{what}: {} vs {}",
            program.cut_length(),
            route.cut_length(&nest)
        );
        assert!(
            (program.idle_length() - route.idle_length()).abs() < 1e-3,
            "{what}"
        );
        for (read, step) in program.pierce_points().iter().zip(&route.steps) {
            assert!(
                read.distance(step.leads.as_ref().unwrap().pierce) < 1e-4,
                "{what}"
            );
        }
    }
}

/// Arc lead-ins cannot be a controller's start-up move: refused, naming the step.
#[test]
fn controller_compensation_refuses_arc_lead_ins() {
    use cutroute_gcode::KerfCompensation;
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 3.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Line, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 1.0,
        ..KerfSettings::default()
    };
    let (nest, route) = routed(30, 4, settings);
    let arcs = KerfSettings {
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        ..settings
    };
    let with_arcs = LeadFitter::new(&nest, arcs).attach(&route).unwrap();
    let options = GcodeOptions {
        kerf_compensation: KerfCompensation::ControllerDiameter,
        ..GcodeOptions::default()
    };
    assert!(matches!(
        route_gcode(&nest, &with_arcs, &options),
        Err(cutroute_gcode::GcodeError::CompensationNeedsLineLeads { .. })
    ));
}

/// A path route (segment cutting's form) over the kerf nest of a generated nest, with leads
/// at every path's ends, checked.
fn path_routed(contours: usize, seed: u64, settings: KerfSettings) -> (Nest, PathRoute) {
    let nest = generate_nest(contours, seed);
    let fitter = LeadFitter::new(&nest, settings);
    let kerf_nest = fitter.kerf_nest();
    let origin = Point::new(0.0, 0.0);
    let route = Route::innermost_first(&kerf_nest, origin, Some(origin));
    let paths = PathRoute::from_route(&route, &kerf_nest).unwrap();
    let paths = fitter.attach_paths(&paths).unwrap();
    assert_eq!(paths.problems(&nest, 1e-6), Vec::new());
    (nest, paths)
}

#[test]
fn a_path_route_with_leads_reads_back_with_the_same_lengths_pierces_and_leads() {
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        ..KerfSettings::default()
    };
    let (_, route) = path_routed(40, 11, settings);
    for arcs in [ArcOutput::CentreOffsets, ArcOutput::Radius] {
        let options = GcodeOptions {
            arcs,
            decimals: 6,
            ..GcodeOptions::default()
        };
        let text = path_route_gcode(&route, &options).unwrap();
        let program = read_gcode(
            &text,
            &ReadOptions {
                start: route.start,
                ..ReadOptions::default()
            },
        )
        .unwrap();
        let what = format!("{arcs:?}");
        assert_eq!(program.pierce_count(), route.pierce_count(), "{what}");
        assert!(
            (program.cut_length() - route.cut_length()).abs() < 1e-3,
            "{what}: cut {} vs {}",
            program.cut_length(),
            route.cut_length()
        );
        assert!(
            (program.idle_length() - route.idle_length()).abs() < 1e-3,
            "{what}"
        );
        // Read back as paths: each pierces at M, starts with the lead-in's spans (the same
        // lengths), ends with the lead-out's at M*.
        let back = program.path_route();
        assert_eq!(back.paths.len(), route.paths.len(), "{what}");
        for (read, written) in back.paths.iter().zip(&route.paths) {
            let leads = written.leads.as_ref().unwrap();
            assert!(read.pierce.distance(written.pierce) < 1e-5, "{what}");
            assert!(read.end().distance(leads.switch_off) < 1e-5, "{what}");
            let lead_in: Vec<f64> = chain_spans(&leads.lead_in).map(|s| s.length()).collect();
            let lead_out: Vec<f64> = chain_spans(&leads.lead_out)
                .map(|s| s.length())
                .filter(|&l| l > 1e-9)
                .collect();
            assert!(!lead_in.is_empty() && !lead_out.is_empty(), "{what}");
            for (span, length) in read.spans.iter().zip(&lead_in) {
                assert!((span.length() - length).abs() < 1e-4, "{what}: lead-in");
            }
            for (span, length) in read.spans.iter().rev().zip(lead_out.iter().rev()) {
                assert!((span.length() - length).abs() < 1e-4, "{what}: lead-out");
            }
            assert!((read.length() - written.length()).abs() < 1e-3, "{what}");
        }
    }
}

#[test]
fn a_path_route_with_edge_pierces_overcut_and_tabs_reads_back_with_the_same_lengths_and_pierces() {
    // The generated nest on a sheet 4 mm round its parts: the parts at its border can be
    // pierced there.
    let mut nest = generate_nest(40, 11);
    let b = nest.bounding_box().expanded(4.0);
    nest.sheet = Some(Part {
        name: "sheet".into(),
        contours: vec![Contour::new(vec![
            Vertex::line(b.min.x, b.min.y),
            Vertex::line(b.min.x, b.max.y),
            Vertex::line(b.max.x, b.max.y),
            Vertex::line(b.max.x, b.min.y),
        ])],
    });
    let settings = KerfSettings {
        kerf: 2.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 1.5,
        edge_pierce: true,
        tabs: TabSpec {
            count: 2,
            width: 1.5,
        },
        ..KerfSettings::default()
    };
    let fitter = LeadFitter::new(&nest, settings);
    let kerf_nest = fitter.kerf_nest();
    let origin = Point::new(0.0, 0.0);
    let route = Route::innermost_first(&kerf_nest, origin, Some(origin));
    let paths = PathRoute::from_route(&route, &kerf_nest).unwrap();
    let route = fitter.attach_paths(&paths).unwrap();
    assert_eq!(route.problems(&nest, 1e-6), Vec::new());
    assert!(route.edge_pierce_count() > 0);
    // Pierces after the tabs' gaps too.
    assert!(route.pierce_count() > route.paths.len());
    assert!(route
        .paths
        .iter()
        .all(|p| p.leads.as_ref().unwrap().overcut == 1.5));
    let overcut: f64 = route
        .paths
        .iter()
        .flat_map(|p| p.overcut_spans())
        .map(|s| s.length())
        .sum();
    assert!((overcut - 1.5 * route.paths.len() as f64).abs() < 1e-6);
    let options = GcodeOptions {
        decimals: 6,
        ..GcodeOptions::default()
    };
    let text = path_route_gcode(&route, &options).unwrap();
    let program = read_gcode(
        &text,
        &ReadOptions {
            start: route.start,
            ..ReadOptions::default()
        },
    )
    .unwrap();
    assert_eq!(program.pierce_count(), route.pierce_count());
    assert!(
        (program.cut_length() - route.cut_length()).abs() < 1e-3,
        "cut {} vs {}",
        program.cut_length(),
        route.cut_length()
    );
    assert!((program.idle_length() - route.idle_length()).abs() < 1e-3);
    // Each path read back pierces at M (on the border where edge-pierced) and switches off
    // at M*, its tool-on length the spans, the overcut and the leads less the tabs' gaps
    // (A tab's gap splits a path in two where read back.)
    let back = program.path_route();
    assert_eq!(back.paths.len(), route.pierce_count());
    let mut read = back.paths.iter();
    for written in &route.paths {
        let leads = written.leads.as_ref().unwrap();
        let pieces: Vec<_> = read.by_ref().take(1 + written.tabs().len()).collect();
        assert!(pieces[0].pierce.distance(written.pierce) < 1e-5);
        assert!(pieces.last().unwrap().end().distance(leads.switch_off) < 1e-5);
        let length: f64 = pieces.iter().map(|p| p.length()).sum();
        assert!((length - written.length()).abs() < 1e-3);
    }
}

/// A slot narrower than the kerf: the controller's compensation cannot reach its concave
/// corners (LinuxCNC stops there), so the program is refused before it is written, naming the
/// contour; compensated in the program, the same route is written.
#[test]
fn controller_compensation_refuses_a_slot_narrower_than_the_kerf() {
    use cutroute_gcode::{GcodeError, KerfCompensation};
    let outline = [
        (0.0, 0.0),
        (0.0, 20.0),
        (9.75, 20.0),
        (9.75, 10.0),
        (10.25, 10.0),
        (10.25, 20.0),
        (20.0, 20.0),
        (20.0, 0.0),
    ];
    let nest = Nest {
        sheet: None,
        parts: vec![Part {
            name: "slotted".into(),
            contours: vec![Contour::new(
                outline.iter().map(|&(x, y)| Vertex::line(x, y)).collect(),
            )],
        }],
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
    let origin = Point::new(5.0, -10.0);
    let mut route = Route::innermost_first(&nest, origin, Some(origin));
    // Entered in the middle of the bottom edge, away from the slot and every corner.
    route.steps[0].pierce_point = Point::new(5.0, 0.0);
    let route = LeadFitter::new(&nest, settings).attach(&route).unwrap();
    route_gcode(&nest, &route, &GcodeOptions::default()).unwrap();
    let options = GcodeOptions {
        kerf_compensation: KerfCompensation::ControllerDiameter,
        ..GcodeOptions::default()
    };
    let error = route_gcode(&nest, &route, &options).unwrap_err();
    assert!(
        matches!(error, GcodeError::CompensationGouge { step: 0, .. }),
        "{error}"
    );
    let message = error.to_string();
    assert!(
        message.contains("part 1 contour 0") && message.contains("gouging"),
        "{message}"
    );
}
