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
use crate::{Contour, CutStep, Entry, LeadError, LeadFitter, Nest, Route};

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
        let n = route.steps.len();
        let mut errors = Vec::new();
        let mut linked: Vec<bool> = route
            .steps
            .iter()
            .enumerate()
            .map(|(i, s)| i > 0 && !s.is_pierced())
            .collect();
        // Each step's equidistant and the arc length of its entry on it.
        let mut eqs: Vec<Option<(Contour, f64)>> = Vec::with_capacity(n);
        // Where each step cut on its own wants its pierce point.
        let mut near = Vec::with_capacity(n);
        for (i, step) in route.steps.iter().enumerate() {
            // A step with leads already (a route being fitted again after a change of its
            // links) keeps its entry, unless its point on the contour moved away from it.
            let (at, wanted) = match (&step.leads, self.nest().contour(step.contour)) {
                (Some(l), Some(c))
                    if c.nearest_point(l.entry).is_some_and(|p| {
                        p.point.distance(step.pierce_point) <= self.nest().check_tolerance()
                    }) =>
                {
                    (l.entry, l.pierce)
                }
                _ => (step.pierce_point, step.pierce_point),
            };
            near.push(wanted);
            match self.equidistant(step.contour) {
                Ok(eq) => {
                    let s = eq
                        .nearest_point(at)
                        .map_or(0.0, |p| eq.length_at(p.position));
                    eqs.push(Some((eq, s)));
                }
                Err(e) => {
                    errors.push(e);
                    eqs.push(None);
                    // No chain runs through a contour that cannot be cut with kerf.
                    linked[i] = false;
                    if i + 1 < n {
                        linked[i + 1] = false;
                    }
                }
            }
        }
        let mut leads: Vec<Option<crate::StepLeads>> = vec![None; n];
        let mut no_room = vec![false; n];
        let links = |linked: &[bool]| linked.iter().filter(|&&l| l).count();
        let links_given = links(&linked);
        loop {
            let mut i = 0;
            while i < n {
                let Some((eq, s)) = &eqs[i] else {
                    i += 1;
                    continue;
                };
                if leads[i].is_some() || no_room[i] {
                    i += 1;
                    continue;
                }
                let r = route.steps[i].contour;
                let (linked_in, linked_out) = (linked[i], i + 1 < n && linked[i + 1]);
                if !linked_in && !linked_out {
                    match self.fit_on(r, eq, near[i]) {
                        Ok(l) => leads[i] = Some(l),
                        Err(e) => {
                            errors.push(e);
                            no_room[i] = true;
                        }
                    }
                    i += 1;
                    continue;
                }
                match self.fit_at_linked(r, eq, *s, linked_in, linked_out) {
                    Ok(l) => {
                        leads[i] = Some(l);
                        i += 1;
                    }
                    // No lead-in at the chain's start: the next contour is pierced instead,
                    // and this one is fitted again, free.
                    Err((true, _)) => {
                        linked[i + 1] = false;
                        leads[i + 1] = None;
                    }
                    // No lead-out at the chain's end: this contour is pierced on its own, and
                    // the one before ends its chain (or stands alone) and is fitted again.
                    Err((false, _)) => {
                        linked[i] = false;
                        leads[i - 1] = None;
                        i -= 1;
                    }
                }
            }
            if !errors.is_empty() {
                return Err(errors);
            }
            let built = self.chained_route(route, &linked, &leads);
            let forest = self.forest();
            let tolerance = self.nest().check_tolerance();
            let mut changed = false;
            for i in 1..n {
                if linked[i] && !link_problems(&built, i, self.nest(), forest, tolerance).is_empty()
                {
                    linked[i] = false;
                    leads[i - 1] = None;
                    leads[i] = None;
                    changed = true;
                }
            }
            if !changed {
                return Ok(ChainedLeads {
                    route: self.relax(&built, passes, positions),
                    broken_links: links_given - links(&linked),
                });
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
