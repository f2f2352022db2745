//! Chain cutting with kerf and leads: a chain pierces once at M in G_M, runs a lead-in to the
//! first contour's entry on its equidistant, cuts it round, follows a tool-on link *between
//! equidistants* to the next contour's entry, …, and leaves the last contour by a lead-out to
//! M* in G_M*.
//!
//! The chain solver runs over [`LeadFitter::kerf_nest`] (every contour replaced by its
//! equidistant at kerf/2), so the pierce points it places are entries on the equidistants and
//! the links it routes round the equidistants keep kerf/2 from every contour.
//! [`LeadFitter::attach_chained`] brings such a route back onto the nest: the ends of every
//! link stay where the solver put them, the chain's first contour gets a lead-in there and its
//! last a lead-out, and contours cut on their own get freely fitted leads. Where a lead finds
//! no room at a link's end, or a link comes closer than kerf/2 to a contour the kerf nest did
//! not offset, the link is broken (one more pierce, with its own leads); a contour where no
//! lead fits at all is reported, never dropped.

use crate::route::link_problems;
use crate::{Contour, CutStep, Entry, LeadError, LeadFitter, Nest, Point, Route};

/// A chained route with leads, and how many of the solver's links gave way to pierces.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainedLeads {
    /// The route over the nest: every step carries leads; linked steps keep their links.
    pub route: Route,
    /// Links of the solver's route broken because a lead had no room at their ends or they
    /// came closer than kerf/2 to a contour.
    pub broken_links: usize,
}

impl LeadFitter<'_> {
    /// The nest of equidistants: every contour replaced by its equidistant at kerf/2 on its
    /// scrap side, where the tool centre runs. Chain links routed round these keep kerf/2 from
    /// the contours. Contours without an equidistant, or whose equidistant would change which
    /// contour holds which, keep their own shape (so the precedence is the nest's).
    pub fn kerf_nest(&self) -> Nest {
        self.offset_nest(self.settings().kerf / 2.0)
    }

    /// `route`, a route over [`LeadFitter::kerf_nest`] (its pierce points on the
    /// equidistants, chains as steps entered by [`Entry::Link`]), with leads on every step over
    /// this fitter's nest (see the module notes). A route over the nest whose steps carry leads
    /// already (whose links were changed since) is fitted again from its entries. Steps cut on their own are then moved along
    /// their equidistants to shorten the idle legs ([`LeadFitter::relax`], `passes` sweeps of
    /// `positions` entries). Fails with every contour where no lead fits.
    pub fn attach_chained(
        &self,
        route: &Route,
        passes: usize,
        positions: usize,
    ) -> Result<ChainedLeads, Vec<LeadError>> {
        let mut work = ChainedAttach::new(route, passes, positions);
        loop {
            if let Some(result) = work.advance(self, route, &|| false) {
                return result;
            }
        }
    }

    /// The route of `route`'s contours with `leads` (one for every step) and the links still
    /// `linked`.
    fn chained_route(
        &self,
        route: &Route,
        linked: &[bool],
        leads: &[Option<crate::StepLeads>],
    ) -> Route {
        let steps = route
            .steps
            .iter()
            .zip(leads)
            .enumerate()
            .filter_map(|(i, (step, leads))| {
                let leads = leads.clone()?;
                let contour = self.nest().contour(step.contour)?;
                let pierce_point = contour
                    .nearest_point(leads.entry)
                    .map_or(step.pierce_point, |p| p.point);
                let entry = match (&step.entry, linked[i]) {
                    (Entry::Link(corners), true) => Entry::Link(corners.clone()),
                    _ => Entry::Pierce,
                };
                Some(CutStep {
                    contour: step.contour,
                    pierce_point,
                    entry,
                    leads: Some(leads),
                })
            })
            .collect();
        Route {
            steps,
            ..route.clone()
        }
    }
}

/// [`LeadFitter::attach_chained`] in pieces, for a job that answers Stop between slices (on
/// seven.dbs one call took 0.35–0.5 s, each chained route of the search fitted anew): a piece
/// is one step's equidistant, one step's lead fit, or the links' check of a fitted route.
/// [`ChainedAttach::advance`] with the same fitter and route until it returns gives what
/// `attach_chained` gives, wherever the pieces fall.
#[derive(Clone, Debug)]
pub struct ChainedAttach {
    passes: usize,
    positions: usize,
    /// Per step: entered by a link that still stands.
    linked: Vec<bool>,
    /// Each step's equidistant and the arc length of its entry on it (made so far).
    eqs: Vec<Option<(Contour, f64)>>,
    /// Where each step cut on its own wants its pierce point.
    near: Vec<Point>,
    errors: Vec<LeadError>,
    leads: Vec<Option<crate::StepLeads>>,
    no_room: Vec<bool>,
    links_given: usize,
    /// The step the fitting pass is at.
    at: usize,
}

impl ChainedAttach {
    /// The work of attaching leads to `route` (see [`LeadFitter::attach_chained`]).
    pub fn new(route: &Route, passes: usize, positions: usize) -> ChainedAttach {
        let n = route.steps.len();
        let linked: Vec<bool> = route
            .steps
            .iter()
            .enumerate()
            .map(|(i, s)| i > 0 && !s.is_pierced())
            .collect();
        ChainedAttach {
            passes,
            positions,
            // Counted before the equidistants (`attach_chained` counted after them): a link
            // lost to a contour without an equidistant ends in an error either way.
            links_given: linked.iter().filter(|&&l| l).count(),
            linked,
            eqs: Vec::with_capacity(n),
            near: Vec::with_capacity(n),
            errors: Vec::new(),
            leads: vec![None; n],
            no_room: vec![false; n],
            at: 0,
        }
    }

    /// Works until done (the chained route with leads, or every contour where no lead fits)
    /// or `pause()` says so after a piece (`None`: call again with the same fitter and route).
    pub fn advance(
        &mut self,
        fitter: &LeadFitter<'_>,
        route: &Route,
        pause: &dyn Fn() -> bool,
    ) -> Option<Result<ChainedLeads, Vec<LeadError>>> {
        let n = route.steps.len();
        while self.eqs.len() < n {
            let i = self.eqs.len();
            let step = &route.steps[i];
            // A step with leads already (a route being fitted again after a change of its
            // links) keeps its entry, unless its point on the contour moved away from it.
            let (at, wanted) = match (&step.leads, fitter.nest().contour(step.contour)) {
                (Some(l), Some(c))
                    if c.nearest_point(l.entry).is_some_and(|p| {
                        p.point.distance(step.pierce_point) <= fitter.nest().check_tolerance()
                    }) =>
                {
                    (l.entry, l.pierce)
                }
                _ => (step.pierce_point, step.pierce_point),
            };
            self.near.push(wanted);
            match fitter.equidistant(step.contour) {
                Ok(eq) => {
                    let s = eq
                        .nearest_point(at)
                        .map_or(0.0, |p| eq.length_at(p.position));
                    self.eqs.push(Some((eq, s)));
                }
                Err(e) => {
                    self.errors.push(e);
                    self.eqs.push(None);
                    // No chain runs through a contour that cannot be cut with kerf.
                    self.linked[i] = false;
                    if i + 1 < n {
                        self.linked[i + 1] = false;
                    }
                }
            }
            if pause() {
                return None;
            }
        }
        loop {
            while self.at < n {
                let i = self.at;
                let Some((eq, s)) = &self.eqs[i] else {
                    self.at += 1;
                    continue;
                };
                if self.leads[i].is_some() || self.no_room[i] {
                    self.at += 1;
                    continue;
                }
                let r = route.steps[i].contour;
                let (linked_in, linked_out) = (self.linked[i], i + 1 < n && self.linked[i + 1]);
                if !linked_in && !linked_out {
                    match fitter.fit_on(r, eq, self.near[i]) {
                        Ok(l) => self.leads[i] = Some(l),
                        Err(e) => {
                            self.errors.push(e);
                            self.no_room[i] = true;
                        }
                    }
                    self.at += 1;
                } else {
                    match fitter.fit_at_linked(r, eq, *s, linked_in, linked_out) {
                        Ok(l) => {
                            self.leads[i] = Some(l);
                            self.at += 1;
                        }
                        // No lead-in at the chain's start: the next contour is pierced
                        // instead, and this one is fitted again, free.
                        Err((true, _)) => {
                            self.linked[i + 1] = false;
                            self.leads[i + 1] = None;
                        }
                        // No lead-out at the chain's end: this contour is pierced on its own,
                        // and the one before ends its chain (or stands alone) and is fitted
                        // again.
                        Err((false, _)) => {
                            self.linked[i] = false;
                            self.leads[i - 1] = None;
                            self.at -= 1;
                        }
                    }
                }
                if pause() {
                    return None;
                }
            }
            if !self.errors.is_empty() {
                return Some(Err(std::mem::take(&mut self.errors)));
            }
            let built = fitter.chained_route(route, &self.linked, &self.leads);
            let forest = fitter.forest();
            let tolerance = fitter.nest().check_tolerance();
            let mut changed = false;
            for i in 1..n {
                if self.linked[i]
                    && !link_problems(&built, i, fitter.nest(), forest, tolerance).is_empty()
                {
                    self.linked[i] = false;
                    self.leads[i - 1] = None;
                    self.leads[i] = None;
                    changed = true;
                }
            }
            if !changed {
                let links = self.linked.iter().filter(|&&l| l).count();
                return Some(Ok(ChainedLeads {
                    route: fitter.relax(&built, self.passes, self.positions),
                    broken_links: self.links_given - links,
                }));
            }
            // The fitting pass again, from the first step (the broken links' ends).
            self.at = 0;
            if pause() {
                return None;
            }
        }
    }
}
