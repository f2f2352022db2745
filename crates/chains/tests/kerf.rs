//! Chain cutting with kerf and leads: chains solved over the nest of equidistants and brought
//! back with `LeadFitter::attach_chained` pass the route checker on the real nest, or name every
//! contour without room.

use cutroute_chains::{chain_route, ChainOptions};
use cutroute_geometry::{
    generate_nest, KerfSettings, LeadFitter, LeadShape, LeadSpec, Nest, Point, Route,
};

fn settings(kerf: f64, d1: f64, d2: f64, lead_in: f64) -> KerfSettings {
    KerfSettings {
        kerf,
        pierce_clearance: d1,
        switch_off_clearance: d2,
        lead_in: LeadSpec::new(LeadShape::Arc, lead_in),
        lead_out: LeadSpec::new(LeadShape::Line, 1.0),
        ..KerfSettings::default()
    }
}

/// The nest's lead fitter and a chained route over its kerf nest (innermost first from the
/// origin, back to it).
fn chained_over_kerf_nest(nest: &Nest, s: KerfSettings) -> (LeadFitter<'_>, Route) {
    let fitter = LeadFitter::new(nest, s);
    let kerf_nest = fitter.kerf_nest();
    let origin = Point::new(0.0, 0.0);
    let route = Route::innermost_first(&kerf_nest, origin, Some(origin));
    let chained = chain_route(&kerf_nest, &route, &ChainOptions::default())
        .unwrap()
        .route;
    (fitter, chained)
}

#[test]
fn chains_over_the_kerf_nest_come_back_valid_with_leads() {
    let mut chained_somewhere = false;
    for seed in 1..=6 {
        let nest = generate_nest(30, seed);
        for s in [settings(2.0, 5.0, 1.0, 8.0), settings(0.2, 1.0, 0.5, 3.0)] {
            let (fitter, chained) = chained_over_kerf_nest(&nest, s);
            match fitter.attach_chained(&chained, 1, 12) {
                Ok(with_leads) => {
                    let r = with_leads.route;
                    assert_eq!(
                        r.validate(&nest, 1e-6),
                        Ok(()),
                        "seed {seed}, kerf {}",
                        s.kerf
                    );
                    assert_eq!(r.steps.len(), nest.contour_count());
                    assert!(r.steps.iter().all(|s| s.leads.is_some()));
                    let links = chained.steps.iter().filter(|s| !s.is_pierced()).count();
                    assert_eq!(
                        r.pierce_count(),
                        chained.pierce_count() + with_leads.broken_links,
                        "{links} links"
                    );
                    chained_somewhere |= r.link_length() > 0.0;
                }
                // Only a contour the rules leave no room on may refuse the route, and each is
                // named.
                Err(errors) => {
                    assert!(!errors.is_empty());
                    for e in errors {
                        let text = e.to_string();
                        assert!(text.contains(" part ") && text.contains(" contour "), "{e}");
                    }
                }
            }
        }
    }
    assert!(chained_somewhere, "no chain survived anywhere");
}

/// Leads attached in pieces (`ChainedAttach`, paused after every piece, as the kerf job runs
/// it between slices) give the very result of `attach_chained` in one call, broken links and
/// errors included, on chained routes of nested.dbs and of generated nests.
#[test]
fn leads_attached_in_pieces_equal_leads_attached_at_once() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/nests/dbs/nested.dbs");
    let nested = cutroute_formats::read_nest(&std::fs::read(path).unwrap()).unwrap();
    let mut nests = vec![nested];
    nests.extend((1..=3).map(|seed| generate_nest(30, seed)));
    let mut linked = 0;
    for nest in &nests {
        for s in [settings(2.0, 5.0, 1.0, 8.0), settings(0.2, 1.0, 0.5, 3.0)] {
            let (fitter, chained) = chained_over_kerf_nest(nest, s);
            linked += chained.steps.iter().filter(|s| !s.is_pierced()).count();
            for (passes, positions) in [(0, 0), (1, 12)] {
                let whole = fitter.attach_chained(&chained, passes, positions);
                let mut work = cutroute_geometry::ChainedAttach::new(&chained, passes, positions);
                let mut pieces = 1;
                let sliced = loop {
                    match work.advance(&fitter, &chained, &|| true) {
                        Some(result) => break result,
                        None => pieces += 1,
                    }
                };
                assert_eq!(sliced, whole);
                assert!(pieces >= chained.steps.len(), "{pieces} pieces");
            }
        }
    }
    assert!(linked > 0, "no links to attach");
}
