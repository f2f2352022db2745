//! Equidistants and leads, checked by their defining properties.

use cutroute_geometry::{
    chain_spans, equidistant, generate_nest, Contour, ContourRef, KerfSettings, LeadError,
    LeadFitter, LeadProblem, LeadShape, LeadSpec, MachineParameters, Nest, OffsetError, Part,
    Point, Route, RouteError, Toolpath, Vertex,
};
use proptest::prelude::*;

/// A star-shaped polygon round `centre` with these radii at equal angles, some edges bulged;
/// clockwise (an outer contour) unless `hole`.
fn star(centre: Point, radii: &[f64], bulges: &[f64], hole: bool) -> Contour {
    let n = radii.len();
    let mut vertices: Vec<Vertex> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let p = centre + Point::new(a.cos(), a.sin()) * radii[i];
            Vertex::arc(p.x, p.y, bulges[i % bulges.len()])
        })
        .collect();
    // Counter-clockwise as built; an outer contour is reversed to run clockwise.
    let ccw = Contour::new(std::mem::take(&mut vertices));
    if hole {
        ccw
    } else {
        ccw.reversed()
    }
}

fn samples(contour: &Contour) -> impl Iterator<Item = Point> + '_ {
    contour
        .spans()
        .flat_map(|s| (0..8).map(move |i| s.point_at(i as f64 / 8.0)))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Every point of an equidistant is at exactly the offset from the contour, on the scrap
    /// side (outside an outer contour, inside a hole), and the direction is kept.
    #[test]
    fn an_offset_lies_at_its_distance_on_the_scrap_side(
        radii in prop::collection::vec(20.0f64..40.0, 3..12),
        bulges in prop::collection::vec(-0.3f64..0.3, 1..4),
        hole in any::<bool>(),
        d in 0.05f64..4.0,
    ) {
        let contour = star(Point::new(0.0, 0.0), &radii, &bulges, hole);
        prop_assume!(contour.validate().is_ok());
        match equidistant(&contour, d) {
            Ok(offset) => {
                prop_assert_eq!(offset.is_clockwise(), contour.is_clockwise());
                for p in samples(&offset) {
                    prop_assert!((contour.distance_to(p) - d).abs() < 1e-6,
                        "distance {} for offset {}", contour.distance_to(p), d);
                    prop_assert_eq!(contour.contains(p), hole);
                }
            }
            // Only a hole (inward) can close up or fall apart.
            Err(OffsetError::Vanishes { .. } | OffsetError::Splits { .. }) => prop_assert!(hole),
            // A cusp is named only where the contour does turn back on itself there.
            Err(OffsetError::Cusp { x, y, .. }) => {
                let spans: Vec<_> = contour.spans().collect();
                let k = spans.iter().position(|s| s.start == Point::new(x, y));
                prop_assert!(k.is_some(), "no vertex at ({}, {})", x, y);
                let k = k.unwrap();
                let into = spans[(k + spans.len() - 1) % spans.len()].tangent_at(1.0);
                prop_assert!(into.dot(spans[k].tangent_at(0.0)) < -0.999, "no cusp at ({}, {})", x, y);
            }
            Err(e) => prop_assert!(false, "{}", e),
        }
    }
}

/// A case the property above once failed on (3.3e-6 where 1e-6 is allowed), with the values
/// it printed rounded to radii [20, 20, 20, 38.2998, 20, 37.7025, 20, 20, 20, 20], bulges
/// [−0.25049, −9.73e-6, 0], outer, d 0.05; these are full-precision values within that
/// rounding that fail the same way. The nearly straight arc (bulge ~1e-5, radius ~600 m) meets
/// a bulged one, and the library's circle–circle intersection through the far centre lost
/// micrometres.
#[test]
fn an_offset_beside_a_nearly_straight_arc_lies_at_its_distance() {
    let radii = [
        20.0,
        20.0,
        20.0,
        38.29981553711461,
        20.0,
        37.70247019188024,
        20.0,
        20.0,
        20.0,
        20.0,
    ];
    let bulges = [-0.2504928454279584, -9.726328829126471e-6, 0.0];
    let d = 0.05;
    let contour = star(Point::new(0.0, 0.0), &radii, &bulges, false);
    assert!(contour.validate().is_ok());
    let offset = equidistant(&contour, d).unwrap();
    assert!(offset.is_clockwise());
    for p in samples(&offset) {
        let error = (contour.distance_to(p) - d).abs();
        assert!(error < 1e-6, "{p:?} is {error:e} off the distance {d}");
        assert!(!contour.contains(p));
    }
}

/// Arcs from nearly straight (bulge 1e-4) down to straight in all but name (1e-10), beside
/// bulged ones, outward and inward: between bulges of about 1e-8 and 1e-6 the offset library
/// lost whole loops or put vertices millimetres off (704 of 20,000 such random stars failed
/// the property above before the nearly straight arcs went to it as chords).
#[test]
fn offsets_beside_nearly_straight_arcs_lie_at_their_distance() {
    let radii = [
        25.63, 20.91, 34.17, 25.92, 38.42, 20.45, 21.30, 35.59, 36.54, 37.19,
    ];
    for exponent in 4..=10 {
        for mantissa in [1.0, 5.2] {
            let flat = mantissa * 10f64.powi(-exponent);
            for (bulges, hole, d) in [
                ([flat, -0.216], true, 2.62),
                ([-flat, 0.25], false, 0.05),
                ([flat, -0.12], false, 3.06),
                ([-flat, 0.2], true, 0.9),
            ] {
                let contour = star(Point::new(0.0, 0.0), &radii, &bulges, hole);
                assert!(contour.validate().is_ok());
                let offset = equidistant(&contour, d).unwrap();
                assert_eq!(offset.is_clockwise(), contour.is_clockwise());
                for p in samples(&offset) {
                    let error = (contour.distance_to(p) - d).abs();
                    assert!(
                        error < 1e-6,
                        "bulge {flat:e}, hole {hole}, d {d}: {error:e} off"
                    );
                    assert_eq!(contour.contains(p), hole);
                }
            }
        }
    }
}

/// The settings of the benchmark: kerf 2, d₁ 5, d₂ 1, arc lead-ins.
fn plasma() -> KerfSettings {
    KerfSettings {
        kerf: 2.0,
        pierce_clearance: 5.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 1.0,
        ..KerfSettings::default()
    }
}

/// Brute-force checks that do not use the fitter: every sampled point of every lead is at
/// least kerf/2 from every contour and outside every part's material.
fn assert_leads_clear(nest: &Nest, settings: &KerfSettings, r: ContourRef, near: Point) -> bool {
    let fitter = LeadFitter::new(nest, *settings);
    let leads = match fitter.fit(r, near) {
        Ok(leads) => leads,
        // A contour with no room is reported, which is allowed; it must say which.
        Err(LeadError::NoFit { contour, .. }) => {
            assert_eq!(contour, r);
            return false;
        }
        Err(e) => panic!("{e}"),
    };
    assert!(fitter.problems(r, &leads).is_empty());
    let material = |p: Point| {
        nest.parts.iter().any(|part| {
            part.contours[0].contains(p) && !part.contours[1..].iter().any(|h| h.contains(p))
        })
    };
    for chain in [&leads.lead_in, &leads.lead_out] {
        for span in chain_spans(chain) {
            for i in 0..=64 {
                let p = span.point_at(i as f64 / 64.0);
                for other in nest.contour_refs() {
                    let d = nest.contour(other).unwrap().distance_to(p);
                    assert!(
                        d >= settings.kerf / 2.0 - 1e-6,
                        "{r:?}: {p:?} is {d} from {other:?}"
                    );
                }
                assert!(!material(p), "{r:?}: {p:?} in material");
            }
        }
    }
    for other in nest.contour_refs() {
        let c = nest.contour(other).unwrap();
        assert!(c.distance_to(leads.pierce) >= settings.pierce_clearance - 1e-6);
        assert!(c.distance_to(leads.switch_off) >= settings.switch_off_clearance - 1e-6);
    }
    true
}

#[test]
fn leads_on_a_generated_nest_keep_clear_of_every_contour_and_out_of_material() {
    let nest = generate_nest(60, 3);
    let mut fitted = 0;
    for r in nest.contour_refs() {
        let c = nest.contour(r).unwrap();
        let near = c.bounding_box().centre() + Point::new(500.0, 0.0);
        fitted += usize::from(assert_leads_clear(&nest, &plasma(), r, near));
    }
    // The generator's smallest holes have no room for d₁ = 5; every other contour has leads.
    assert!(
        fitted * 10 >= nest.contour_count() * 8,
        "{fitted} of {}",
        nest.contour_count()
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Leads fitted towards any point, with any asked shape and length, keep clear.
    #[test]
    fn fitted_leads_never_touch_a_contour_nor_enter_material(
        seed in 0u64..1000,
        x in -100.0f64..400.0,
        y in -100.0f64..400.0,
        shape in prop::sample::select(vec![LeadShape::Line, LeadShape::Arc, LeadShape::LineArc]),
        length in 1.0f64..30.0,
    ) {
        let nest = generate_nest(12, seed);
        let settings = KerfSettings { lead_in: LeadSpec::new(shape, length), ..plasma() };
        for r in nest.contour_refs() {
            assert_leads_clear(&nest, &settings, r, Point::new(x, y));
        }
    }
}

#[test]
fn a_hole_too_small_for_the_kerf_is_reported_not_dropped() {
    let plate = Contour::circle(Point::new(0.0, 0.0), 50.0, true);
    let pin_hole = Contour::circle(Point::new(0.0, 0.0), 0.8, false);
    let nest = Nest {
        sheet: None,
        parts: vec![Part {
            name: "plate".into(),
            contours: vec![plate, pin_hole],
        }],
    };
    let fitter = LeadFitter::new(&nest, plasma());
    let hole = ContourRef {
        part: 0,
        contour: 1,
    };
    assert!(matches!(
        fitter.fit(hole, Point::new(0.0, 0.0)),
        Err(LeadError::Offset { contour, .. }) if contour == hole
    ));
    // Room for the kerf but not for d₁: no lead fits, and the hole is named.
    let small = Nest {
        sheet: None,
        parts: vec![Part {
            name: "plate".into(),
            contours: vec![
                Contour::circle(Point::new(0.0, 0.0), 50.0, true),
                Contour::circle(Point::new(0.0, 0.0), 4.0, false),
            ],
        }],
    };
    let fitter = LeadFitter::new(&small, plasma());
    assert!(matches!(
        fitter.fit(hole, Point::new(0.0, 0.0)),
        Err(LeadError::NoFit { contour, .. }) if contour == hole
    ));
}

#[test]
fn a_hole_with_room_is_pierced_at_its_centre_when_a_side_lead_does_not_fit() {
    // Radius 7.5: the equidistant has radius 6.5, the centre is 7.5 from the hole (≥ d₁ 5), but
    // an arc lead of 20 mm cannot fit beside the wall.
    let nest = Nest {
        sheet: None,
        parts: vec![Part {
            name: "plate".into(),
            contours: vec![
                Contour::circle(Point::new(0.0, 0.0), 50.0, true),
                Contour::circle(Point::new(0.0, 0.0), 7.5, false),
            ],
        }],
    };
    let settings = KerfSettings {
        lead_in: LeadSpec::new(LeadShape::Arc, 40.0),
        ..plasma()
    };
    let fitter = LeadFitter::new(&nest, settings);
    let hole = ContourRef {
        part: 0,
        contour: 1,
    };
    let leads = fitter.fit(hole, Point::new(100.0, 0.0)).unwrap();
    assert!(fitter.problems(hole, &leads).is_empty());
    assert!(leads.pierce.distance(Point::new(0.0, 0.0)) < 1e-9);
}

#[test]
fn leads_read_and_write_as_vertex_triples() {
    let nest = generate_nest(4, 1);
    let fitter = LeadFitter::new(&nest, plasma());
    let r = nest.contour_refs().next().unwrap();
    let leads = fitter.fit(r, Point::new(-50.0, -50.0)).unwrap();
    let json = serde_json::to_value(&leads).unwrap();
    assert!(json["lead_in"][0].as_array().unwrap().len() == 3);
    let back: cutroute_geometry::StepLeads = serde_json::from_value(json).unwrap();
    assert!(back.pierce.distance(leads.pierce) < 1e-9 && back.lead_in.len() == leads.lead_in.len());
}

/// A valid idealised route over `nest`: holes (deeper contours) first.
fn idealised_route(nest: &Nest) -> Route {
    Route::innermost_first(nest, Point::new(0.0, 0.0), None)
}

#[test]
fn a_route_with_leads_passes_the_checker_and_its_toolpath_agrees() {
    // Holes of the generator that are too small for d₁ are left out: this test is about routes.
    let settings = KerfSettings {
        pierce_clearance: 2.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        ..plasma()
    };
    let nest = generate_nest(40, 5);
    let route = idealised_route(&nest);
    let fitter = LeadFitter::new(&nest, settings);
    let with_leads = fitter.attach(&route).expect("every contour has room");
    let forest = nest.containment_forest();
    assert_eq!(with_leads.problems(&nest, &forest, 1e-6), vec![]);
    // Idle moves run from each M* to the next M; tool-on length counts leads and overcut.
    let toolpath = Toolpath::new(&with_leads, &nest).unwrap();
    assert!((toolpath.idle_length() - with_leads.idle_length()).abs() < 1e-6);
    assert!((toolpath.cut_length() - with_leads.cut_length(&nest)).abs() < 1e-6);
    assert_eq!(toolpath.pierce_count(), with_leads.pierce_count());
    let leads: f64 = with_leads
        .steps
        .iter()
        .map(|s| s.leads.as_ref().unwrap())
        .map(|l| l.lead_in_length() + l.lead_out_length() + l.overcut)
        .sum();
    assert!(leads > 0.0);
    let machine = MachineParameters::default();
    // Time counts the leads: it is the toolpath's, move by move.
    let by_moves = machine.time(
        toolpath.cut_length(),
        toolpath.idle_length(),
        toolpath.pierce_count(),
    );
    assert!((with_leads.time(&nest, &machine) - by_moves).abs() < 1e-9);
    // Old routes (no leads field) still read; routes with leads round-trip through JSON.
    let json = serde_json::to_string(&with_leads).unwrap();
    let back: Route = serde_json::from_str(&json).unwrap();
    assert_eq!(back.steps.len(), with_leads.steps.len());
    assert!(back.steps.iter().all(|s| s.leads.is_some()));
    assert!((back.cut_length(&nest) - with_leads.cut_length(&nest)).abs() < 1e-6);
    let mut old = serde_json::to_value(&route).unwrap();
    for step in old["steps"].as_array_mut().unwrap() {
        step.as_object_mut().unwrap().remove("leads");
    }
    let read: Route = serde_json::from_value(old).unwrap();
    assert!(read.steps.iter().all(|s| s.leads.is_none()));
}

#[test]
fn the_checker_rejects_a_pierce_point_in_material_or_too_near_a_part() {
    let nest = generate_nest(10, 2);
    let fitter = LeadFitter::new(&nest, plasma());
    let route = fitter.attach(&idealised_route(&nest)).unwrap();
    let forest = nest.containment_forest();
    let mut bad = route.clone();
    let step = &mut bad.steps[0];
    let leads = step.leads.as_mut().unwrap();
    // Pierce at the entry itself: 1 mm (kerf/2) from the contour, closer than d₁ = 5.
    leads.pierce = leads.entry;
    leads.lead_in = vec![Vertex::arc(leads.entry.x, leads.entry.y, 0.0)];
    let problems = bad.problems(&nest, &forest, 1e-6);
    assert!(
        problems.iter().any(|p| matches!(
            p,
            RouteError::Lead {
                step: 0,
                problem: LeadProblem::PierceOutsideRegion { .. },
                ..
            }
        )),
        "{problems:?}"
    );
    // An entry moved off the equidistant.
    let mut off = route.clone();
    let leads = off.steps[1].leads.as_mut().unwrap();
    leads.entry += Point::new(0.5, 0.5);
    leads.lead_in.last_mut().unwrap().point = leads.entry;
    assert!(off.problems(&nest, &forest, 1e-6).iter().any(|p| matches!(
        p,
        RouteError::Lead {
            step: 1,
            problem: LeadProblem::EntryOffEquidistant { .. },
            ..
        }
    )));
}

#[test]
fn the_pierce_curve_nest_keeps_the_precedence_and_lies_at_the_pierce_distance() {
    let nest = generate_nest(200, 9);
    let fitter = LeadFitter::new(&nest, plasma());
    let curves = fitter.pierce_curve_nest();
    let (forest, curve_forest) = (nest.containment_forest(), curves.containment_forest());
    for r in nest.contour_refs() {
        assert_eq!(forest.parent(r), curve_forest.parent(r), "{r:?}");
    }
    // Most contours have their curve: kerf/2 + the quarter arc's radius 16/π ≥ d₁ = 5.
    let reach = 1.0 + 16.0 / std::f64::consts::PI;
    let moved = nest
        .contour_refs()
        .filter(|&r| {
            let p = curves.contour(r).unwrap().vertices[0].point;
            (nest.contour(r).unwrap().distance_to(p) - reach).abs() < 1e-6
        })
        .count();
    assert!(moved * 10 >= nest.contour_count() * 7, "{moved}");
    // Routes over the curves come back onto the contours.
    let projected = fitter.project(&idealised_route(&curves));
    assert_eq!(projected.problems(&nest, &forest, 1e-6), vec![]);
}

#[test]
fn relaxing_the_leads_never_lengthens_the_idle_and_keeps_the_route_valid() {
    let nest = generate_nest(40, 5);
    let settings = KerfSettings {
        pierce_clearance: 2.0,
        lead_in: LeadSpec::new(LeadShape::Arc, 4.0),
        ..plasma()
    };
    let fitter = LeadFitter::new(&nest, settings);
    let route = fitter.attach(&idealised_route(&nest)).unwrap();
    let relaxed = fitter.relax(&route, 2, 16);
    assert!(relaxed.idle_length() <= route.idle_length() + 1e-9);
    assert!(relaxed.idle_length() < route.idle_length() - 1.0);
    assert_eq!(
        relaxed.problems(&nest, &nest.containment_forest(), 1e-6),
        vec![]
    );
}

#[test]
fn an_outward_offset_closes_a_narrow_notch_and_follows_the_outside() {
    // A clockwise 20 × 20 square with a notch 1 mm wide and 10 mm deep from the top.
    let notched = Contour::new(
        [
            (0.0, 0.0),
            (0.0, 20.0),
            (9.5, 20.0),
            (9.5, 10.0),
            (10.5, 10.0),
            (10.5, 20.0),
            (20.0, 20.0),
            (20.0, 0.0),
        ]
        .iter()
        .map(|&(x, y)| Vertex::line(x, y))
        .collect(),
    );
    assert!(notched.is_clockwise());
    let offset = equidistant(&notched, 1.0).unwrap();
    assert!(offset.is_clockwise());
    for p in samples(&offset) {
        assert!((notched.distance_to(p) - 1.0).abs() < 1e-6);
        assert!(!notched.contains(p));
    }
    // Round the outside: the rounded 22 × 22 square (4·20 + 2π) but for a shallow dip where
    // the arcs round the notch's two top corners meet above it.
    let rounded_square = 80.0 + std::f64::consts::TAU;
    assert!(offset.perimeter() > rounded_square - 1.0 && offset.perimeter() < rounded_square + 1.0);
    assert!(offset.bounding_box().height() > 21.9);
}

/// A star whose three concave arcs make one vertex turn back on itself by 180° (to 5·10⁻⁶ rad),
/// so the spans cross again 0.4 µm from it: the offset library builds no outward equidistant,
/// and the error says where (a proptest case, reported as "vanishes" before).
#[test]
fn a_cusp_is_named_where_no_outward_equidistant_is_built() {
    let contour = star(
        Point::new(0.0, 0.0),
        &[34.840447109320436, 39.67430069497756, 21.56448585148291],
        &[-0.2133152152693176],
        false,
    );
    assert!(contour.validate().is_ok());
    match equidistant(&contour, 0.05) {
        Err(OffsetError::Cusp { x, y, .. }) => {
            assert!(
                Point::new(x, y).distance(Point::new(-19.837150347488773, 34.35895227923318))
                    < 1e-9
            );
        }
        // Should the library learn to offset it, the equidistant must hold its distance.
        Ok(offset) => {
            for p in samples(&offset) {
                assert!((contour.distance_to(p) - 0.05).abs() < 1e-6);
            }
        }
        Err(e) => panic!("{e}"),
    }
}
