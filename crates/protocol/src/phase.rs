//! What a job is doing, typed: the engine says which phase and its numbers, the CLI prints the
//! English words ([`Phase`]'s `Display`, the text scripts have always read in `phase`), and the
//! page words it in its own language.

use serde::{Deserialize, Serialize};
use std::fmt;

/// The step of CCP-Relax (the continuous solver).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CcpStage {
    /// Not started.
    #[default]
    Start,
    /// Relaxation: pierce points moved to their optimum for the order.
    Relaxing,
    /// Local search over the order.
    LocalSearch,
    /// Shaking (the VNS restarts).
    Shaking,
    /// Ended.
    Done,
}

impl CcpStage {
    fn word(self) -> &'static str {
        match self {
            CcpStage::Start => "start",
            CcpStage::Relaxing => "relaxing",
            CcpStage::LocalSearch => "localsearch",
            CcpStage::Shaking => "shaking",
            CcpStage::Done => "done",
        }
    }
}

/// A segment-cutting ensemble (the way base segments are made).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Ensemble {
    /// One segment per contour.
    Standard,
    /// Chains of neighbouring contours.
    Chains,
    /// Segments split at junctions of common edges.
    Junctions,
}

impl Ensemble {
    /// The lower-case name the CLI prints.
    pub fn name(self) -> &'static str {
        match self {
            Ensemble::Standard => "standard",
            Ensemble::Chains => "chains",
            Ensemble::Junctions => "junctions",
        }
    }
}

/// What a thermal job did to the route of the solver it wraps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ThermalNote {
    /// The heat rules were enforced on the route.
    RulesEnforced,
    /// Pierce points were relaxed on idle length + W·H.
    Relaxed,
    /// The rules could not be repaired; the route is kept.
    RepairFailed {
        /// Why, in English.
        error: String,
    },
    /// A path route broke a rule and was replaced by its contours cut whole (standard cutting)
    /// with the rules enforced.
    RulesEnforcedOnWholeContours,
    /// The final rule check was left out: it would have passed the time limit.
    RulesNotChecked,
}

/// Which candidate route a kerf job kept (its optimised route is never longer than the
/// idealised order with leads attached and relaxed: both are evaluated, the shorter is kept).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum KerfSource {
    /// The solver's route over the pierce curves, leads fitted and moved along the equidistants.
    PierceCurves,
    /// The exact solver's route over the discretised full-route model: candidate entries with
    /// their leads fitted, idle legs from M* to the next M; its bounds are about that model.
    FullRoute,
    /// The solver's idealised route with leads attached (and, unless asked for the plain
    /// "after" route, moved along the equidistants).
    Idealised,
    /// The chain solver's route over the equidistants: a lead-in at each chain's start and a
    /// lead-out at its end; `links_broken` of its links gave way to pierces where no lead
    /// fitted at their ends or they came closer than kerf/2 to a contour.
    Chains {
        /// Links of the solver's route that became pierces.
        links_broken: usize,
    },
    /// A path solver's route (sccp, gsccp, aoe) over the equidistants: a lead-in at each
    /// path's start and a lead-out at its end.
    Paths,
}

/// What a kerf job (the full cutting route: kerf, leads, tabs) did to the route of the solver
/// it wraps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum KerfNote {
    /// Leads are attached to every pierced step; the route came from `source`.
    Leads {
        /// Which candidate route was kept.
        source: KerfSource,
    },
    /// Some contours have no room for a lead-in/lead-out pair: no full route exists under the
    /// settings, so the progress carries no route.
    NoRoom {
        /// The contours without room, as (part, contour) indices.
        contours: Vec<(usize, usize)>,
        /// Why, per contour, in English (`LeadError`'s words).
        errors: Vec<String>,
    },
}

/// What a job is doing, with its numbers.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum Phase {
    /// The job is about to start.
    #[default]
    Starting,
    /// The job has ended (solvers without a phase of their own).
    Done,
    /// The job was cancelled.
    Cancelled,
    /// A lower bound is being computed (CLI `bound`).
    Bound,
    /// CCP-Relax at this step.
    Ccp(CcpStage),
    /// CCP-Relax at this step, before chain cutting.
    ChainCcp(CcpStage),
    /// Chain cutting joins close contours.
    ChainJoining,
    /// Chain cutting has ended.
    Chained {
        /// Pierces saved.
        saved: usize,
        /// Pierces before.
        pierces: usize,
        /// Chains made.
        chains: usize,
        /// Cost before, mm.
        cost_before: f64,
        /// Cost after, mm.
        cost_after: f64,
    },
    /// Chain cutting failed; the CCP route is kept.
    ChainFailed {
        /// Why, in English.
        error: String,
    },
    /// The discrete model's cost matrix is built row by row.
    BuildingMatrix {
        /// Rows built.
        rows_done: usize,
        /// Rows in all.
        rows: usize,
    },
    /// The model is built: the heuristic is being set up.
    BuildingHeuristic,
    /// The model is built: the exact search is being set up.
    BuildingExact,
    /// ALNS, the heuristic.
    Alns {
        /// Iterations so far.
        iterations: u64,
    },
    /// The exact search, layer by layer of the order ideals.
    ExactLayer {
        /// The layer.
        layer: usize,
        /// Live states of the layer.
        states: usize,
    },
    /// The exact search proved the best tour optimal.
    ProvenOptimal,
    /// The time limit passed while the model was built: no tour, or on a discretised nest the
    /// nearest-neighbour one over its candidate points.
    BuildTimedOut,
    /// The search stopped, for this reason if any.
    Stopped {
        /// Why, in English.
        reason: Option<String>,
    },
    /// Segment cutting: CCP-Relax seeds the orders.
    SegmentsCcp,
    /// Segment cutting builds an ensemble.
    SegmentsBuilding {
        /// Which.
        ensemble: Option<Ensemble>,
    },
    /// Segment cutting searches an ensemble.
    SegmentsSearch {
        /// Which.
        ensemble: Ensemble,
        /// Its base segments.
        segments: usize,
        /// Shakes so far.
        shakes: usize,
    },
    /// Segment cutting has ended; the best route comes from this ensemble (`None`: CCP).
    SegmentsDone {
        /// The source of the best route.
        best: Option<Ensemble>,
    },
    /// Segment cutting failed.
    SegmentsFailed {
        /// Why, in English.
        error: String,
    },
    /// Segment cutting ended with no valid route.
    SegmentsNoRoute,
    /// Common-edge routes: the plan graph is built.
    CommonEdgeGraph,
    /// Common-edge routes: the components are ordered.
    CommonEdgeOrdering,
    /// Common-edge routes: the plan bound is measured.
    CommonEdgeBound,
    /// Common-edge routes have ended.
    CommonEdgeDone {
        /// Chains of the route.
        chains: usize,
        /// Components of the plan graph.
        components: usize,
    },
    /// Common-edge routes failed.
    CommonEdgeFailed {
        /// Why, in English.
        error: String,
    },
    /// A thermal job's note on the phase of the solver it wraps.
    Thermal {
        /// The wrapped solver's phase.
        base: Box<Phase>,
        /// What the thermal pass did.
        note: ThermalNote,
    },
    /// A kerf job's note on the phase of the solver it wraps.
    Kerf {
        /// The wrapped solver's phase.
        base: Box<Phase>,
        /// What the kerf job did.
        note: KerfNote,
    },
}

impl Phase {
    /// Progress within the phase as (done, total), when the phase counts towards a total.
    pub fn fraction(&self) -> Option<(usize, usize)> {
        match self {
            Phase::BuildingMatrix { rows_done, rows } => Some((*rows_done, *rows)),
            Phase::Thermal { base, .. } | Phase::Kerf { base, .. } => base.fraction(),
            _ => None,
        }
    }
}

impl fmt::Display for Phase {
    /// The English words, as the CLI's `phase` has always read.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Phase::Starting => write!(f, "starting"),
            Phase::Done => write!(f, "done"),
            Phase::Cancelled => write!(f, "cancelled"),
            Phase::Bound => write!(f, "bound"),
            Phase::Ccp(stage) => write!(f, "{}", stage.word()),
            Phase::ChainCcp(stage) => write!(f, "ccp: {}", stage.word()),
            Phase::ChainJoining => write!(f, "chain cutting: joining close contours"),
            Phase::Chained {
                saved,
                pierces,
                chains,
                cost_before,
                cost_after,
            } => write!(
                f,
                "chained: {saved} of {pierces} pierces saved, {chains} chains, cost \
                 {cost_before:.2} → {cost_after:.2}"
            ),
            Phase::ChainFailed { error } => {
                write!(f, "chain cutting failed: {error}; CCP route kept")
            }
            Phase::BuildingMatrix { rows_done, rows } => write!(
                f,
                "building the model: {rows_done} of {rows} rows of the cost matrix"
            ),
            Phase::BuildingHeuristic => write!(f, "building the model: the heuristic"),
            Phase::BuildingExact => write!(f, "building the model: the exact search"),
            Phase::Alns { iterations } => write!(f, "ALNS · {iterations} iterations"),
            Phase::ExactLayer { layer, states } => write!(f, "layer {layer} · {states} states"),
            Phase::ProvenOptimal => write!(f, "proven optimal"),
            Phase::BuildTimedOut => {
                write!(
                    f,
                    "stopped: the time limit passed while the model was built"
                )
            }
            Phase::Stopped { reason: None } => write!(f, "stopped"),
            Phase::Stopped {
                reason: Some(reason),
            } => write!(f, "stopped: {reason}"),
            Phase::SegmentsCcp => write!(f, "segment cutting: CCP-Relax seeds the orders"),
            Phase::SegmentsBuilding {
                ensemble: Some(ensemble),
            } => write!(
                f,
                "segment cutting: building the {} ensemble",
                ensemble.name()
            ),
            // Between ensembles (the last one built, the searches not started).
            Phase::SegmentsBuilding { ensemble: None } => {
                write!(f, "segment cutting: building the ensembles")
            }
            Phase::SegmentsSearch {
                ensemble,
                segments,
                shakes,
            } => write!(
                f,
                "segment cutting: {} ensemble ({segments} segments, {shakes} shakes)",
                ensemble.name()
            ),
            Phase::SegmentsDone { best } => write!(
                f,
                "segment cutting: done, best {}",
                best.map_or("ccp", Ensemble::name)
            ),
            Phase::SegmentsFailed { error } => write!(f, "segment cutting failed: {error}"),
            Phase::SegmentsNoRoute => {
                write!(f, "segment cutting: no ensemble gave a valid route")
            }
            Phase::CommonEdgeGraph => write!(f, "common-edge routes: building the plan graph"),
            Phase::CommonEdgeOrdering => {
                write!(f, "common-edge routes: ordering the components")
            }
            Phase::CommonEdgeBound => write!(f, "common-edge routes: measuring the plan bound"),
            Phase::CommonEdgeDone { chains, components } => write!(
                f,
                "common-edge routes: {chains} chains in {components} components"
            ),
            Phase::CommonEdgeFailed { error } => write!(f, "common-edge routes failed: {error}"),
            Phase::Thermal { base, note } => match note {
                ThermalNote::RulesEnforced => write!(f, "{base} · rules enforced"),
                ThermalNote::Relaxed => {
                    write!(f, "{base} · pierce points relaxed on idle + W·H")
                }
                ThermalNote::RepairFailed { error } => {
                    write!(f, "{base} · rule repair failed ({error}); route kept")
                }
                ThermalNote::RulesEnforcedOnWholeContours => {
                    write!(
                        f,
                        "{base} · rules enforced on whole contours (standard cutting)"
                    )
                }
                ThermalNote::RulesNotChecked => write!(
                    f,
                    "{base} · rules not checked: the check would pass the time limit"
                ),
            },
            Phase::Kerf { base, note } => match note {
                KerfNote::Leads {
                    source: KerfSource::PierceCurves,
                } => write!(f, "{base} · leads optimised over the pierce curves"),
                KerfNote::Leads {
                    source: KerfSource::FullRoute,
                } => write!(
                    f,
                    "{base} · leads chosen among the full-route model's candidates"
                ),
                KerfNote::Leads {
                    source: KerfSource::Idealised,
                } => write!(f, "{base} · leads attached to the idealised order"),
                KerfNote::Leads {
                    source: KerfSource::Chains { links_broken },
                } => write!(
                    f,
                    "{base} · leads at the chains' ends, {links_broken} link(s) broken into pierces"
                ),
                KerfNote::Leads {
                    source: KerfSource::Paths,
                } => write!(
                    f,
                    "{base} · leads at the paths' ends, cut on the equidistants"
                ),
                KerfNote::NoRoom { errors, .. } => write!(
                    f,
                    "{base} · {} contour(s) without room for the leads: {}",
                    errors.len(),
                    errors.join("; ")
                ),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_english_words_are_the_cli_phase_texts() {
        assert_eq!(
            Phase::BuildingMatrix {
                rows_done: 3,
                rows: 40
            }
            .to_string(),
            "building the model: 3 of 40 rows of the cost matrix"
        );
        assert_eq!(Phase::Ccp(CcpStage::LocalSearch).to_string(), "localsearch");
        // Between two ensembles no name is left blank.
        assert_eq!(
            Phase::SegmentsBuilding { ensemble: None }.to_string(),
            "segment cutting: building the ensembles"
        );
        assert_eq!(
            Phase::SegmentsBuilding {
                ensemble: Some(Ensemble::Chains)
            }
            .to_string(),
            "segment cutting: building the chains ensemble"
        );
        assert_eq!(
            Phase::ChainCcp(CcpStage::Relaxing).to_string(),
            "ccp: relaxing"
        );
        assert_eq!(
            Phase::ExactLayer {
                layer: 3,
                states: 12
            }
            .to_string(),
            "layer 3 · 12 states"
        );
        assert_eq!(
            Phase::Thermal {
                base: Box::new(Phase::Ccp(CcpStage::Done)),
                note: ThermalNote::RulesEnforced
            }
            .to_string(),
            "done · rules enforced"
        );
        assert_eq!(
            Phase::SegmentsDone { best: None }.to_string(),
            "segment cutting: done, best ccp"
        );
    }

    #[test]
    fn the_fraction_is_the_matrix_rows_through_a_thermal_note() {
        let building = Phase::BuildingMatrix {
            rows_done: 5,
            rows: 9,
        };
        assert_eq!(building.fraction(), Some((5, 9)));
        let wrapped = Phase::Thermal {
            base: Box::new(building),
            note: ThermalNote::Relaxed,
        };
        assert_eq!(wrapped.fraction(), Some((5, 9)));
        assert_eq!(Phase::Alns { iterations: 4 }.fraction(), None);
    }
}
