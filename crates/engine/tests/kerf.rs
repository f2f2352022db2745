//! The full cutting route through the engine (issue #17): the kerf job's every progress carries
//! its route with leads, every final route passes the independent checker, its route is never
//! longer than the idealised order with leads attached, and contours without room are named.

mod common;

use common::{nest_of, nest_problem, plasma};

use cutroute_engine::{
    run_to_end, start_job, validate_kerf, EngineError, KerfSettingsError, Refusal,
};
use cutroute_geometry::{KerfSettings, LeadSpec, Route, TabSpec};
use cutroute_protocol::{
    JobRequest, KerfNote, KerfSource, Phase, Problem, Progress, Solution, SolverKind, SolverParams,
};

fn request(problem: &Problem, solver: SolverKind, kerf: KerfSettings, after: bool) -> JobRequest {
    JobRequest {
        job_id: 7,
        problem: problem.clone(),
        solver,
        params: SolverParams {
            time_limit_s: 1.0,
            kerf,
            leads_after: after,
            ..SolverParams::default()
        },
    }
}

/// Runs the job to its end; every progress with a route must have leads on each pierced step.
fn run(request: &JobRequest) -> Progress {
    let mut job = start_job(request).expect("starts");
    run_to_end(job.as_mut(), &mut |p| {
        if let Some(route) = p.route() {
            assert_leads_everywhere(route);
            assert_eq!(p.bounds.upper, Some(route.idle_length()));
            assert!(p.bounds.lower.is_none());
        }
        assert!(matches!(p.phase, Phase::Kerf { .. }), "{:?}", p.phase);
    })
}

fn assert_leads_everywhere(route: &Route) {
    for step in &route.steps {
        if step.is_pierced() {
            assert!(step.leads.is_some(), "a pierced step without leads");
        }
    }
}

fn checked(problem: &Problem, progress: &Progress) -> Route {
    let nest = nest_of(problem);
    let route = progress.route().cloned().expect("a route");
    let problems = route.problems(nest, &nest.containment_forest(), 1e-6);
    assert!(problems.is_empty(), "{:?}", problems.first());
    assert_leads_everywhere(&route);
    route
}

#[test]
fn nearest_with_leads_is_never_longer_than_nearest_then_leads() {
    // Nearest is deterministic: the kerf job's idealised candidate is exactly the route the
    // "after" job attaches leads to, so the comparison is exact.
    for file in [
        "nests/dbs-json/E1X_6_01.dbs.json",
        "nests/dbs/seven.dbs",
        "nests/dbs/seven_3717.dbs",
        // Parts in holes; not test1, whose part lying in a hole of its own shape no kerf cuts
        // right (the job refuses it).
        "nests/dbs/nested.dbs",
    ] {
        let problem = nest_problem(file);
        let mut job_request = request(&problem, SolverKind::NearestNeighbour, plasma(), false);
        // Time for every relaxation to run to its end.
        job_request.params.time_limit_s = 60.0;
        let optimised = checked(&problem, &run(&job_request));
        let after = checked(
            &problem,
            &run(&request(
                &problem,
                SolverKind::NearestNeighbour,
                plasma(),
                true,
            )),
        );
        assert!(
            optimised.idle_length() <= after.idle_length() + 1e-9,
            "{file}: optimised {} > after {}",
            optimised.idle_length(),
            after.idle_length()
        );
    }
}

#[test]
fn ccp_and_heuristic_give_checked_routes_with_leads() {
    let problem = nest_problem("nests/dbs-json/E1X_6_01.dbs.json");
    for solver in [SolverKind::Ccp, SolverKind::Heuristic] {
        let progress = run(&request(&problem, solver, plasma(), false));
        checked(&problem, &progress);
        assert!(
            matches!(
                progress.phase,
                Phase::Kerf {
                    note: KerfNote::Leads { .. },
                    ..
                }
            ),
            "{solver:?}: {:?}",
            progress.phase
        );
    }
}

#[test]
fn a_contour_without_room_is_named_not_dropped() {
    // ring.dbs: a 4 mm ring, no room inside for an 8 mm lead-in at kerf 2 and d₁ 5.
    let problem = nest_problem("nests/dbs/ring.dbs");
    let progress = run(&request(
        &problem,
        SolverKind::NearestNeighbour,
        plasma(),
        false,
    ));
    assert!(progress.route().is_none());
    let Phase::Kerf {
        note: KerfNote::NoRoom { contours, errors },
        ..
    } = &progress.phase
    else {
        panic!("{:?}", progress.phase);
    };
    assert!(!contours.is_empty());
    assert_eq!(contours.len(), errors.len());
    assert!(progress.phase.to_string().contains("without room"));
}

/// Chain cutting in the kerf job: it chains over the equidistants, its links survive the
/// leads (a lead-in at each chain's start, a lead-out at its end), and the route passes the
/// checker, which holds every link kerf/2 from every contour.
#[test]
fn chain_gives_a_checked_chained_route_with_leads() {
    let problem = nest_problem("nests/dbs-json/E1X_6_01.dbs.json");
    let mut job_request = request(&problem, SolverKind::Chain, plasma(), false);
    job_request.params.time_limit_s = 4.0;
    let progress = run(&job_request);
    let route = checked(&problem, &progress);
    let links = route.steps.iter().filter(|s| !s.is_pierced()).count();
    assert!(links > 0, "no chain");
    let Phase::Kerf {
        note: KerfNote::Leads {
            source: KerfSource::Chains { links_broken },
        },
        ..
    } = progress.phase
    else {
        panic!("{:?}", progress.phase);
    };
    // Every link the solver made is either in the route or counted as broken.
    assert!(links_broken <= links + links_broken);
    for (i, step) in route.steps.iter().enumerate() {
        let next_linked = route.steps.get(i + 1).is_some_and(|s| !s.is_pierced());
        let leads = step.leads.as_ref().expect("leads on every step");
        // A chain's inner ends have no lead: the link runs from the exit to the next entry.
        assert_eq!(leads.lead_in.len() > 1, step.is_pierced(), "step {i}");
        assert_eq!(leads.lead_out.len() > 1, !next_linked, "step {i}");
    }
}

#[test]
fn path_solvers_give_checked_path_routes_with_leads() {
    for file in ["nests/dbs-json/E1X_6_01.dbs.json", "nests/dbs/nested.dbs"] {
        let problem = nest_problem(file);
        let nest = nest_of(&problem);
        for solver in [SolverKind::Sccp, SolverKind::Gsccp, SolverKind::Aoe] {
            let mut job = start_job(&request(&problem, solver, plasma(), false)).expect("starts");
            let progress = run_to_end(job.as_mut(), &mut |p| {
                // Every route a progress shows is a full route: leads on every path.
                if let Some(route) = p.path_route() {
                    assert!(route.paths.iter().all(|p| p.leads.is_some()));
                }
            });
            assert!(
                matches!(
                    &progress.phase,
                    Phase::Kerf {
                        note: KerfNote::Leads {
                            source: KerfSource::Paths
                        },
                        ..
                    }
                ),
                "{file} {solver:?}: {}",
                progress.phase
            );
            let route = progress.path_route().cloned().expect("a route");
            assert_eq!(
                route.pierce_count(),
                nest.contour_count(),
                "{file} {solver:?}"
            );
            let problems: Vec<_> = route
                .problems(nest, nest.check_tolerance())
                .into_iter()
                .filter(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
                .collect();
            assert_eq!(problems, Vec::new(), "{file} {solver:?}");
            // The reported objective counts the leads as cut.
            let machine = cutroute_geometry::MachineParameters::default();
            let leads: f64 = route.paths.iter().map(|p| p.leads_length()).sum();
            assert!(leads > 0.0);
            assert!(
                (progress.bounds.upper.unwrap()
                    - machine.time(
                        route.cut_length(),
                        route.idle_length(),
                        route.pierce_count()
                    ))
                .abs()
                    < 1e-6
            );
        }
    }
}

#[test]
fn a_path_solver_names_the_contour_without_room() {
    // ring.dbs: a 4 mm ring whose hole has no room for kerf 2 and d₁ 5.
    let problem = nest_problem("nests/dbs/ring.dbs");
    for solver in [SolverKind::Sccp, SolverKind::Aoe] {
        let progress = run_to_end(
            start_job(&request(&problem, solver, plasma(), false))
                .expect("starts")
                .as_mut(),
            &mut |_| {},
        );
        assert!(progress.path_route().is_none(), "{solver:?}");
        assert!(
            matches!(
                &progress.phase,
                Phase::Kerf { note: KerfNote::NoRoom { contours, .. }, .. } if !contours.is_empty()
            ),
            "{solver:?}: {}",
            progress.phase
        );
    }
}

#[test]
fn aoe_cuts_seven_on_the_equidistants_with_plasma_settings() {
    // seven.dbs's equidistants at kerf 2 have runs of spans of 0.002-0.02 mm near corners, and
    // aoe's own check once refused its route there (a cut along such a run was taken for a cut
    // through material).
    let problem = nest_problem("nests/dbs/seven.dbs");
    let nest = nest_of(&problem);
    let mut job = start_job(&request(&problem, SolverKind::Aoe, plasma(), false)).expect("starts");
    let progress = run_to_end(job.as_mut(), &mut |_| {});
    let route = progress
        .path_route()
        .unwrap_or_else(|| panic!("no route: {}", progress.phase));
    assert!(route.paths.iter().all(|p| p.leads.is_some()));
    // Every problem, overlaps included: aoe cuts each piece of an equidistant once.
    assert_eq!(route.problems(nest, nest.check_tolerance()), Vec::new());
    assert!(route.pierce_count() <= nest.contour_count());
}

#[test]
fn every_solver_starts_with_kerf_and_bad_settings_are_refused() {
    let problem = nest_problem("nests/dbs-json/E1X_6_01.dbs.json");
    // Every solver has a full-route model now; one without would be refused here.
    for solver in SolverKind::ALL {
        let started = start_job(&request(&problem, solver, plasma(), false));
        assert_eq!(
            started.is_ok(),
            solver.cuts_with_kerf(),
            "{solver:?}: {:?}",
            started.err()
        );
        assert!(solver.cuts_with_kerf(), "{solver:?}");
    }
    let bad = KerfSettings {
        kerf: f64::NAN,
        ..plasma()
    };
    assert!(start_job(&request(&problem, SolverKind::Ccp, bad, false)).is_err());
}

#[test]
fn idealised_settings_leave_the_job_as_it_was() {
    let problem = nest_problem("nests/dbs-json/E1X_6_01.dbs.json");
    let plain = request(
        &problem,
        SolverKind::NearestNeighbour,
        KerfSettings::default(),
        false,
    );
    let mut job = start_job(&plain).expect("starts");
    let progress = run_to_end(job.as_mut(), &mut |_| {});
    assert!(!matches!(progress.phase, Phase::Kerf { .. }));
    let route = progress
        .solution
        .and_then(Solution::into_route)
        .expect("a route");
    assert!(route.steps.iter().all(|s| s.leads.is_none()));
}

#[test]
fn out_of_range_kerf_settings_are_refused_by_name() {
    let negative = KerfSettings {
        lead_in: LeadSpec {
            length: -1.0,
            ..plasma().lead_in
        },
        ..plasma()
    };
    assert_eq!(
        validate_kerf(&negative),
        Err(KerfSettingsError::BadLength {
            name: "lead-in length",
            value: -1.0
        })
    );
    let no_width = KerfSettings {
        tabs: TabSpec {
            count: 2,
            width: 0.0,
        },
        ..plasma()
    };
    assert_eq!(validate_kerf(&no_width), Err(KerfSettingsError::TabWidth));
    assert_eq!(validate_kerf(&plasma()), Ok(()));
    // The job's refusal keeps the typed reason and the same words.
    let problem = nest_problem("nests/dbs-json/E1X_6_01.dbs.json");
    let refused = start_job(&request(&problem, SolverKind::Ccp, negative, false))
        .err()
        .expect("refused");
    assert_eq!(
        refused,
        EngineError::SolverRefused {
            solver: "ccp",
            reason: Refusal::Kerf(KerfSettingsError::BadLength {
                name: "lead-in length",
                value: -1.0
            }),
        }
    );
    assert_eq!(
        refused.to_string(),
        "ccp: lead-in length -1: must be finite and non-negative"
    );
}

/// The least distance between two contours, span against span (independent of the kerf
/// check's index).
fn brute_gap(a: &cutroute_geometry::Contour, b: &cutroute_geometry::Contour) -> f64 {
    a.spans()
        .flat_map(|x| b.spans().map(move |y| x.distance_to_span(&y)))
        .fold(f64::INFINITY, f64::min)
}

/// T-FLEX Nest01's parts touch: no cut on the equidistants keeps kerf/2 off its neighbour (the
/// checkers reject every such route), so every solver's kerf job is refused up front, with
/// the pairs of contours and their gaps, under plasma and laser alike.
#[test]
fn parts_closer_than_the_kerf_are_refused_up_front_naming_the_pairs() {
    let problem = nest_problem("nests/tflex/Nest01.tfnesting");
    let nest = nest_of(&problem);
    let laser = KerfSettings {
        kerf: 0.2,
        pierce_clearance: 1.0,
        switch_off_clearance: 0.5,
        ..plasma()
    };
    for kerf in [plasma(), laser] {
        for solver in SolverKind::ALL {
            let started = start_job(&request(&problem, solver, kerf, false));
            let Err(EngineError::SolverRefused {
                reason: Refusal::PartsTooClose(refusal),
                ..
            }) = started
            else {
                panic!("{solver:?} kerf {}: {:?}", kerf.kerf, started.err());
            };
            assert_eq!(refusal.kerf, kerf.kerf);
            assert!(!refusal.pairs.is_empty());
            for pair in &refusal.pairs {
                assert_ne!(pair.contour, pair.other);
                let (a, b) = (
                    nest.contour(pair.contour).unwrap(),
                    nest.contour(pair.other).unwrap(),
                );
                let gap = brute_gap(a, b);
                assert!((gap - pair.gap).abs() < 1e-9, "{pair:?} vs {gap}");
                assert!(gap < kerf.kerf, "{pair:?}");
            }
            let words = refusal.to_string();
            // Each pair is named by part and contour, the first one first.
            let first = &refusal.pairs[0];
            let named = format!(
                "part {} contour {} and part {} contour {}",
                first.contour.part + 1,
                first.contour.contour,
                first.other.part + 1,
                first.other.contour
            );
            assert!(
                words.contains("parts closer than the kerf") && words.contains(&named),
                "{words}"
            );
        }
    }
}

/// test0 and test1 each have a part lying exactly in a hole of its own shape: each cut keeps
/// kerf/2 off the other contour (on its far side), yet one of the two comes out a kerf off its
/// line. Every solver's kerf job refuses them up front as parts closer than the kerf, each
/// pair of contours found lying on one another (checked here vertex by vertex), of two
/// different parts, both named; without a kerf the same nests are cut.
#[test]
fn contours_on_one_another_are_refused_up_front_naming_both_parts() {
    let laser = KerfSettings {
        kerf: 0.2,
        pierce_clearance: 1.0,
        switch_off_clearance: 0.5,
        ..plasma()
    };
    for (file, pairs) in [
        ("nests/dbs-json/test0.dbs.json", 1),
        ("nests/dbs/test0.json.dbs", 1),
        ("nests/dbs-json/test1.dbs.json", 2),
    ] {
        let problem = nest_problem(file);
        let nest = nest_of(&problem);
        for kerf in [plasma(), laser] {
            for solver in SolverKind::ALL {
                let started = start_job(&request(&problem, solver, kerf, false));
                let Err(EngineError::SolverRefused {
                    reason: Refusal::PartsTooClose(refusal),
                    ..
                }) = started
                else {
                    panic!("{file} {solver:?} kerf {}: {:?}", kerf.kerf, started.err());
                };
                assert_eq!(refusal.kerf, kerf.kerf);
                assert_eq!(refusal.pairs.len(), pairs, "{file}: {refusal}");
                let words = refusal.to_string();
                for pair in &refusal.pairs {
                    assert!(pair.on_one_another, "{file}: {pair:?}");
                    assert_ne!(pair.contour.part, pair.other.part, "{file}: {pair:?}");
                    let (a, b) = (
                        nest.contour(pair.contour).unwrap(),
                        nest.contour(pair.other).unwrap(),
                    );
                    let on = |x: &cutroute_geometry::Contour, y: &cutroute_geometry::Contour| {
                        x.spans().all(|s| {
                            y.distance_to(s.start) < 1e-6 && y.distance_to(s.point_at(0.5)) < 1e-6
                        })
                    };
                    assert!(on(a, b) && on(b, a), "{file}: {pair:?}");
                    assert!(brute_gap(a, b) < 1e-9, "{file}: {pair:?}");
                    let named = format!(
                        "{} and {} lie on one another near (",
                        pair.contour, pair.other
                    );
                    assert!(words.contains(&named), "{file}: {words}");
                }
            }
        }
        // Without a kerf a shared line is cut once per contour: the nest is routed.
        let progress = run_to_end(
            start_job(&request(
                &problem,
                SolverKind::NearestNeighbour,
                KerfSettings::default(),
                false,
            ))
            .expect("starts")
            .as_mut(),
            &mut |_| {},
        );
        assert!(progress.route().is_some(), "{file}: {}", progress.phase);
    }
}

/// A nest whose parts are 1 mm apart is refused with kerf 2 and cut with kerf 0.2; the route
/// cut then passes the checker, which holds each cut kerf/2 from every contour.
#[test]
fn a_nest_is_refused_only_where_its_gaps_are_narrower_than_the_kerf() {
    use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};
    let square = |x: f64| Part {
        name: format!("at {x}"),
        contours: vec![Contour::new(vec![
            Vertex::line(x, 0.0),
            Vertex::line(x, 40.0),
            Vertex::line(x + 40.0, 40.0),
            Vertex::line(x + 40.0, 0.0),
        ])],
    };
    let problem = Problem::Nest {
        nest: Nest {
            sheet: None,
            parts: vec![square(0.0), square(41.0), square(90.0)],
        },
        start: Point::new(-50.0, -50.0),
        finish: None,
    };
    for solver in [
        SolverKind::NearestNeighbour,
        SolverKind::Ccp,
        SolverKind::Chain,
    ] {
        let refused = start_job(&request(&problem, solver, plasma(), false)).err();
        let Some(EngineError::SolverRefused {
            reason: Refusal::PartsTooClose(refusal),
            ..
        }) = refused
        else {
            panic!("{solver:?}: {refused:?}");
        };
        // Only the first two sit closer than 2 mm; the third is 9 mm away.
        assert_eq!(refusal.pairs.len(), 1, "{refusal}");
        assert!((refusal.pairs[0].gap - 1.0).abs() < 1e-9);
        let laser = KerfSettings {
            kerf: 0.2,
            pierce_clearance: 1.0,
            switch_off_clearance: 0.5,
            ..plasma()
        };
        let progress = run(&request(&problem, solver, laser, false));
        checked(&problem, &progress);
    }
}

#[test]
fn path_solvers_pierce_at_the_edge_overcut_closed_paths_and_tab_whole_contours() {
    // nested.dbs: a sheet with parts 10 mm from its border, within the edge reach (not test1,
    // whose part lying in a hole of its own shape no kerf cuts right: the job refuses it).
    let problem = nest_problem("nests/dbs/nested.dbs");
    let nest = nest_of(&problem);
    let settings = KerfSettings {
        overcut: 1.5,
        edge_pierce: true,
        tabs: TabSpec {
            count: 2,
            width: 1.5,
        },
        ..plasma()
    };
    for solver in [SolverKind::Sccp, SolverKind::Aoe] {
        let progress = run_to_end(
            start_job(&request(&problem, solver, settings, false))
                .expect("starts")
                .as_mut(),
            &mut |_| {},
        );
        let route = progress
            .path_route()
            .unwrap_or_else(|| panic!("{solver:?}: no route: {}", progress.phase));
        let problems: Vec<_> = route
            .problems(nest, nest.check_tolerance())
            .into_iter()
            .filter(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
            .collect();
        assert_eq!(problems, Vec::new(), "{solver:?}");
        // Whether a path starts within the edge reach of the border depends on the solver's
        // route (anytime, under load): the geometry tests pin edge pierces down; here every
        // one made is checked (the checker, and M on the border).
        let border = &nest.sheet.as_ref().expect("a sheet").contours[0];
        let mut overcut = 0.0;
        for path in &route.paths {
            let leads = path.leads.as_ref().expect("leads");
            if leads.edge_pierce {
                assert!(border.distance_to(path.pierce) < 1e-6, "{solver:?}");
            }
            let closed = path.spans[0].start.distance(path.spans.last().unwrap().end) < 1e-9;
            assert_eq!(leads.overcut, if closed { 1.5 } else { 0.0 }, "{solver:?}");
            overcut += leads.overcut;
        }
        assert!(overcut > 0.0, "{solver:?}");
        assert!(
            route.paths.iter().any(|p| !p.tabs().is_empty()),
            "{solver:?}"
        );
        let tabs: usize = route.paths.iter().map(|p| p.tabs().len()).sum();
        assert_eq!(route.pierce_count(), route.paths.len() + tabs, "{solver:?}");
        let gaps: f64 = route
            .paths
            .iter()
            .flat_map(|p| p.tabs())
            .map(|t| t.width())
            .sum();
        // The cut length counts the overcut, less the tabs' gaps.
        let spans: f64 = route
            .paths
            .iter()
            .flat_map(|p| &p.spans)
            .map(|s| s.length())
            .sum();
        let leads: f64 = route.paths.iter().map(|p| p.leads_length()).sum();
        assert!(
            (route.cut_length() - spans - leads - overcut + gaps).abs() < 1e-6,
            "{solver:?}"
        );
    }
}
