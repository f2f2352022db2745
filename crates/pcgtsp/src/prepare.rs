//! Building the search's bounds in resumable slices: first the subset DP bound
//! ([`crate::bounds::subset`]), then — unless the subset bound is already strong — the
//! pierce-group lattice ([`crate::bounds::lattice`]). The solver advances the preparation with a deadline on every
//! `step`, so progress is reported and a cancel honoured while the bounds are being built.

use crate::bounds::lattice::{LatticeBuilder, LatticeStore};
use crate::bounds::subset::{SubsetBound, SubsetBuilder};
use crate::keys::{on_keyed, with_key_width, ByWidth, Keyed};
use crate::model::Model;
use std::rc::Rc;
use web_time::Instant;

/// A subset bound whose root is at least this share of the incumbent's cost prunes more than
/// a coarse pierce-group lattice ...
pub(crate) const STRONG_SUBSET_SHARE: f64 = 0.85;
/// ... one with fewer groups per cluster than this share of the average cluster size (on
/// large orders with big clusters the lattice affords only 2–3 groups and costs seconds; with
/// small clusters it is nearly exact and still worth building).
const COARSE_GROUP_SHARE: f64 = 0.5;

/// Limits of the pierce-group lattice build.
pub(crate) struct LatticeLimits {
    /// Most ideals.
    pub max_ideals: usize,
    /// Memory for the lattice.
    pub max_bytes: usize,
    /// Work budget of the backward pass.
    pub work: usize,
    /// Skip the lattice if it affords fewer groups than this share of the average cluster size.
    pub min_group_share: f64,
}

/// The lattice build at the key width of the model.
struct LatticeJob(Keyed<LatticeJobWidth>);

struct LatticeJobWidth;

impl ByWidth for LatticeJobWidth {
    type At<const W: usize> = LatticeBuilder<W>;
}

impl LatticeJob {
    fn new(model: &Model, limits: &LatticeLimits) -> Option<LatticeJob> {
        let (i, b, w, g) = (
            limits.max_ideals,
            limits.max_bytes,
            limits.work,
            limits.min_group_share,
        );
        with_key_width!(model.m, |W, wrap| LatticeJob(wrap(
            LatticeBuilder::<W>::new(model, i, b, w, g)
        )))
    }

    fn advance(&mut self, model: &Model, deadline: Instant) -> Option<LatticeStore> {
        let built = on_keyed!(&mut self.0, |builder, wrap| wrap(
            builder.advance(model, deadline)?.map(Rc::new)
        ));
        Some(LatticeStore(Some(built)))
    }
}

enum Stage {
    Subset(SubsetBuilder),
    Lattice(LatticeJob),
}

/// The bounds of one run being built.
pub(crate) struct Preparation {
    stage: Stage,
    limits: LatticeLimits,
    upper_bound: f64,
    /// The subset bound, once built.
    pub subset: Option<Rc<SubsetBound>>,
}

impl Preparation {
    /// Starts with the subset bound, chosen from `tour` (cost `upper_bound`).
    pub fn new(
        model: &Model,
        tour: Option<&[usize]>,
        upper_bound: f64,
        subset_work: f64,
        limits: LatticeLimits,
    ) -> Preparation {
        let tour = tour.filter(|t| t.first() == Some(&model.start));
        Preparation {
            stage: Stage::Subset(SubsetBuilder::new(model, tour, subset_work)),
            limits,
            upper_bound,
            subset: None,
        }
    }

    /// Works until `deadline`; returns the lattice store once everything is built.
    pub fn advance(&mut self, model: &Model, deadline: Instant) -> Option<LatticeStore> {
        loop {
            match &mut self.stage {
                Stage::Subset(builder) => {
                    let subset = builder.advance(model, deadline)?;
                    let mut limits = LatticeLimits { ..self.limits };
                    if let Some(subset) = &subset {
                        // Exact (every cluster tracked) or already proving the incumbent
                        // optimal: nothing left for the lattice to add.
                        let exact = subset.tracked_count() == model.m;
                        if exact || model.round_bound(subset.root_bound) >= self.upper_bound {
                            limits.max_ideals = 0;
                        } else if subset.root_bound >= STRONG_SUBSET_SHARE * self.upper_bound {
                            limits.min_group_share = COARSE_GROUP_SHARE;
                        }
                    }
                    self.subset = subset.map(Rc::new);
                    match LatticeJob::new(model, &limits) {
                        Some(job) if limits.max_ideals > 0 => self.stage = Stage::Lattice(job),
                        _ => {
                            return Some(LatticeStore(with_key_width!(model.m, |_W, wrap| wrap(
                                None
                            ))))
                        }
                    }
                    if Instant::now() >= deadline {
                        return None;
                    }
                }
                Stage::Lattice(job) => return job.advance(model, deadline),
            }
        }
    }
}
