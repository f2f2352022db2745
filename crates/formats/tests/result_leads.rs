//! Routes with kerf and leads in RouteManager's result format: the leads travel in the
//! format's own `cut.in` / `cut.out` moves, the cut on the equidistant, and read back as the
//! same full route.

use cutroute_formats::ResultExportOptions;
use cutroute_formats::{read_result_json, route_moves, write_result_json, MoveKind, RmResult};
use cutroute_geometry::{
    generate_nest, CutStep, KerfSettings, LeadFitter, LeadShape, LeadSpec, Nest, Point, Route,
    TabSpec,
};

fn route_with_leads(nest: &Nest, settings: KerfSettings) -> Route {
    let origin = Point::new(0.0, 0.0);
    let route = Route::innermost_first(nest, origin, Some(origin));
    let route = LeadFitter::new(nest, settings).attach(&route).unwrap();
    route.validate(nest, 1e-6).unwrap();
    route
}

fn plasma() -> KerfSettings {
    KerfSettings {
        kerf: 2.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 0.5,
        ..KerfSettings::default()
    }
}

#[test]
fn leads_round_trip_through_the_result_format() {
    for (seed, settings) in [
        (11, plasma()),
        (
            12,
            KerfSettings {
                lead_out: LeadSpec::new(LeadShape::None, 0.0),
                overcut: 0.0,
                ..plasma()
            },
        ),
        (
            13,
            KerfSettings {
                tabs: TabSpec {
                    count: 3,
                    width: 1.5,
                },
                ..plasma()
            },
        ),
    ] {
        let nest = generate_nest(30, seed);
        let route = route_with_leads(&nest, settings);
        let result = RmResult::from_route(&nest, &route, &ResultExportOptions::default()).unwrap();

        // The lengths in the file are those of the full route.
        let idle = route.idle_length();
        let total = idle + route.cut_length(&nest);
        assert!((result.results.route_length_no_contours - idle).abs() < 1e-6);
        assert!((result.results.route_length - total).abs() < 1e-6);
        // Every step writes its lead-in (and lead-out where there is one) in the format's modes.
        let modes = |kind| {
            result
                .results
                .toolpath
                .iter()
                .filter(|e| e.mode == kind)
                .count()
        };
        assert!(modes(MoveKind::CutIn) >= route.steps.len());
        if settings.lead_out.shape != LeadShape::None {
            assert!(modes(MoveKind::CutOut) >= route.steps.len());
        }

        let text = write_result_json(&result).unwrap();
        let back = read_result_json(text.as_bytes()).unwrap().route();
        assert_eq!(back.steps.len(), route.steps.len());
        assert!(back.start.distance(route.start) < 1e-9);
        assert_eq!(back.finish.is_some(), route.finish.is_some());
        for (read, wrote) in back.steps.iter().zip(&route.steps) {
            assert_eq!(read.contour, wrote.contour);
            let (r, w) = (read.leads.as_ref().unwrap(), wrote.leads.as_ref().unwrap());
            let close = |a: Point, b: Point| a.distance(b) < 1e-6;
            assert!(close(r.pierce, w.pierce), "{:?} {:?}", r.pierce, w.pierce);
            assert!(close(r.entry, w.entry));
            assert!(close(r.switch_off, w.switch_off));
            assert!(close(read.pierce_point, wrote.pierce_point));
            assert!(
                (r.offset - w.offset).abs() < 1e-6,
                "{} {}",
                r.offset,
                w.offset
            );
            assert!(
                (r.overcut - w.overcut).abs() < 1e-6,
                "{} {}",
                r.overcut,
                w.overcut
            );
            assert!((r.lead_in_length() - w.lead_in_length()).abs() < 1e-6);
            assert!((r.lead_out_length() - w.lead_out_length()).abs() < 1e-6);
            assert_eq!(r.tabs.len(), w.tabs.len());
            for (a, b) in r.tabs.iter().zip(&w.tabs) {
                assert!((a.start - b.start).abs() < 1e-6 && (a.end - b.end).abs() < 1e-6);
                assert!(close(a.from, b.from) && close(a.to, b.to));
            }
        }
        // The route read back is a full route the checker accepts, with the same lengths.
        back.validate(&nest, 1e-6).unwrap();
        assert!((back.idle_length() - idle).abs() < 1e-6);
        assert!((back.cut_length(&nest) - route.cut_length(&nest)).abs() < 1e-6);
        assert_eq!(back.pierce_count(), route.pierce_count());
        // The drawn moves are the route's: idle ends at pierce points M, not on the contours.
        let moves = route_moves(&nest, &route).unwrap();
        let pierces: Vec<Point> = moves
            .windows(2)
            .filter(|w| w[0].kind == MoveKind::Air && w[1].kind == MoveKind::CutIn)
            .map(|w| w[0].to)
            .collect();
        assert_eq!(pierces.len(), route.steps.len());
        for (m, step) in pierces.iter().zip(&route.steps) {
            assert!(m.distance(step.leads.as_ref().unwrap().pierce) < 1e-9);
        }
    }
}

#[test]
fn routes_without_leads_read_back_without_leads() {
    let nest = generate_nest(20, 3);
    let route = Route {
        start: Point::new(0.0, 0.0),
        steps: nest
            .contour_refs()
            .map(|r| CutStep::pierced(r, nest.contour(r).unwrap().vertices[0].point))
            .collect(),
        finish: None,
    };
    let result = RmResult::from_route(&nest, &route, &ResultExportOptions::default()).unwrap();
    let back = result.route();
    assert!(back.steps.iter().all(|s| s.leads.is_none()));
    assert!((back.idle_length() - route.idle_length()).abs() < 1e-9);
}
