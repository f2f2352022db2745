//! The job protocol: every message that crosses the boundary between the UI, the solver worker
//! and the command-line tool.
//!
//! The UI sends [`ToWorker`] messages; the worker answers with [`FromWorker`] messages. A job is
//! started with a [`JobRequest`], reports [`Progress`] while it runs (the improving route, the
//! upper and lower bounds, the gap), and ends with exactly one of `Finished`, `Cancelled` or
//! `Failed`. The same types serialise to JSON for the CLI.
//!
//! The worker transport (gloo-worker) encodes messages with bincode, which has no self-describing
//! format: keep these types plain (no untagged enums, no skipped fields).
//!
//! ```
//! use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams, ToWorker};
//! use cutroute_geometry::{Nest, Point};
//!
//! let request = ToWorker::Start(JobRequest {
//!     job_id: 1,
//!     problem: Problem::Nest { nest: Nest::default(), start: Point::new(0.0, 0.0), finish: None },
//!     solver: SolverKind::NearestNeighbour,
//!     params: SolverParams::default(),
//! });
//! assert!(matches!(request, ToWorker::Start(ref job) if job.job_id == 1));
//! ```
#![deny(missing_docs)]

use cutroute_geometry::{
    KerfSettings, MachineParameters, Nest, Objective, PathRoute, Point, ReadWarning, Route,
};
use serde::{Deserialize, Serialize};

mod open_error;
mod phase;
mod profile;
mod solution;
mod thermal;

pub use cutroute_anytime::{Bounds, CostUnit};
pub use open_error::{OpenError, OpenErrorKind, SourceLocation};
pub use phase::{CcpStage, Ensemble, KerfNote, KerfSource, Phase, ThermalNote};
pub use profile::{MachineProfile, ProfileError};
pub use solution::Solution;
pub use thermal::{ThermalSettings, ThermalSettingsError};
// The thermal types a `Progress` carries, so the UI needs no second import path.
pub use cutroute_thermal::{HeatModel, RuleCounts, RuleSet, Violation};

/// Identifies one job for the lifetime of a worker; chosen by the sender, echoed in every answer.
pub type JobId = u64;

/// A message to the solver worker.
// `Start` is large (a request carries every setting) but one message is built per job, never
// in bulk: boxing it would change every sender for nothing measurable.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ToWorker {
    /// Start a job. A job already running keeps running: jobs are independent.
    Start(JobRequest),
    /// Stop a job as soon as possible; the worker answers `Cancelled` with the best result so far.
    Cancel {
        /// The job to stop.
        job_id: JobId,
    },
    /// Read one file, or several as one document (a nest with its task and a PCGLNS result, an
    /// instance with its result), through `cutroute_engine::open_together`; parsed in the
    /// worker, off the UI thread. Answered by `Opened` or `OpenFailed` with the same
    /// `request_id`.
    Open {
        /// Chosen by the sender; echoed in the answer.
        request_id: u64,
        /// Each file's name (its extension is only a hint: formats are detected from the
        /// content) and bytes.
        files: Vec<(String, Vec<u8>)>,
    },
    /// Read sheet `sheet` (from 0) of a multi-sheet file (`Document::sheets`) through
    /// `cutroute_engine::open_sheet`; answered as `Open` is.
    OpenSheet {
        /// Chosen by the sender; echoed in the answer.
        request_id: u64,
        /// The file's name and bytes.
        file: (String, Vec<u8>),
        /// Which sheet.
        sheet: usize,
    },
}

/// A file the worker has read.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Document {
    /// The file's name.
    pub file_name: String,
    /// The detected format, in words (e.g. "DBS binary").
    pub format: String,
    /// What the file describes, ready to be solved.
    pub problem: Problem,
    /// A route the file already holds (result files), to show or compare.
    pub route: Option<Route>,
    /// A G-code program's own tool-on paths, when they are more than the closed loops `route`
    /// makes of them (open paths of segment or common-edge cutting): the page shows these.
    #[serde(default)]
    pub paths: Option<PathRoute>,
    /// The speeds and pierce time a task file of the batch sets for the machine.
    #[serde(default)]
    pub task_speeds: Option<TaskSpeeds>,
    /// What the reader left out, skipped, approximated or assumed, as data: kind, place in the
    /// file, a sentence, the length and the geometry left out (for the page to draw as a
    /// layer). In JSON each is an object `{"kind": "open_chain", "place": …, "message": …,
    /// "length_mm": …, "left_out": [[{x, y}, …], …]}`.
    pub warnings: Vec<ReadWarning>,
    /// The names of the file's sheets when it holds several (T-FLEX projects), in file order;
    /// empty for files of one sheet. The engine's `open_sheet` opens any of them.
    #[serde(default)]
    pub sheets: Vec<String>,
    /// Which of `sheets` the problem is, counted from 0 (0 when `sheets` is empty).
    #[serde(default)]
    pub sheet: usize,
}

/// The machine settings a RouteManager task file carries (its prices are not the file's).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TaskSpeeds {
    /// Idle (air-move) speed, mm/s.
    pub idle_speed: f64,
    /// Cutting speed, mm/s.
    pub cut_speed: f64,
    /// Time of one pierce, s.
    pub pierce_time: f64,
}

impl TaskSpeeds {
    /// `machine` with these speeds and pierce time, its prices kept.
    pub fn applied_to(&self, machine: MachineParameters) -> MachineParameters {
        MachineParameters {
            idle_speed: self.idle_speed,
            cut_speed: self.cut_speed,
            pierce_time: self.pierce_time,
            ..machine
        }
    }
}

/// A message from the solver worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FromWorker {
    /// The job is running; sent after every improvement and at least every few hundred ms.
    Progress(Progress),
    /// The job ran to its end (solver finished or time limit reached).
    Finished(Progress),
    /// The job was cancelled; the progress is the best state reached.
    Cancelled(Progress),
    /// A file was read.
    Opened {
        /// The `request_id` of the `Open` message.
        request_id: u64,
        /// What was read.
        document: Document,
    },
    /// A file could not be read.
    OpenFailed {
        /// The `request_id` of the `Open` message.
        request_id: u64,
        /// What is wrong and where.
        error: OpenError,
    },
    /// The job could not run.
    Failed {
        /// The job that failed.
        job_id: JobId,
        /// What went wrong, in plain words.
        message: String,
        /// When the job was refused because parts sit closer than the kerf: the pairs, so
        /// the page can word them in its language. (Always written, even as `null`: the
        /// worker's binary codec cannot skip fields.)
        #[serde(default)]
        parts_too_close: Option<cutroute_geometry::PartsTooClose>,
    },
}

/// What to solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Problem {
    /// A cutting plan: route the tool over every contour of the nest.
    Nest {
        /// The parts to cut.
        nest: Nest,
        /// The machine's home point, where the tool head starts.
        start: Point,
        /// Where the tool head must end, if anywhere.
        finish: Option<Point>,
    },
    /// A PCGTSP instance in PCGLNS or PCGTSPLIB text format.
    PcgtspText {
        /// The file's text.
        text: String,
    },
}

/// The solvers a job can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SolverKind {
    /// Greedy: cut the nearest contour whose inner contours are done, pierce at its nearest vertex.
    NearestNeighbour,
    /// CCP-Relax: pierce points anywhere on the contours, VNS over the order.
    Ccp,
    /// Discretised pierce points, adaptive large neighbourhood search (upper bounds only).
    Heuristic,
    /// Discretised pierce points, exact dynamic programming with lower bounds.
    Exact,
    /// CCP-Relax, then chain cutting: neighbouring contours of one scrap region cut from one
    /// pierce, joined by tool-on links that pay under the machine's prices.
    Chain,
    /// Segment cutting (SCCP): the multi-contour chains of the nest's plan graph (parts
    /// sharing edges cut along them once) as base segments; reports a [`Solution::PathRoute`].
    Sccp,
    /// Generalised segment cutting (GSCCP): standard, chain and junction-split ensembles, the
    /// best by the chosen [`Objective`]; reports a [`Solution::PathRoute`].
    Gsccp,
    /// Common-edge routes along AOE-chains of the nest's plane graph (each edge cut once, no
    /// self-crossing, nothing enclosed before it is cut); reports a [`Solution::PathRoute`].
    Aoe,
}

impl SolverKind {
    /// Every solver, in the order the UI lists them.
    pub const ALL: [SolverKind; 8] = [
        SolverKind::NearestNeighbour,
        SolverKind::Ccp,
        SolverKind::Heuristic,
        SolverKind::Exact,
        SolverKind::Chain,
        SolverKind::Sccp,
        SolverKind::Gsccp,
        SolverKind::Aoe,
    ];

    /// Whether the solver's result is a [`PathRoute`] (tool-on paths that may cut parts of
    /// several contours) rather than a [`Route`] of whole contours.
    pub fn gives_path_route(self) -> bool {
        matches!(self, SolverKind::Sccp | SolverKind::Gsccp | SolverKind::Aoe)
    }

    /// Whether the solver has a full-route model (kerf, pierce regions, leads, tabs): nearest,
    /// ccp and heuristic route whole contours through pierce points, which the pierce curves
    /// carry over, and chain runs over the equidistants with leads at its chains' ends. Exact
    /// searches the discretised full-route model (candidate entries with their leads, idle
    /// legs from M* to the next M), so its bounds are about that model. The path solvers
    /// (sccp, gsccp, aoe) run over the equidistants at kerf/2, with a lead-in at each path's
    /// start and a lead-out at its end. Every solver has one; the match makes a new solver
    /// decide.
    pub fn cuts_with_kerf(self) -> bool {
        match self {
            SolverKind::NearestNeighbour
            | SolverKind::Ccp
            | SolverKind::Heuristic
            | SolverKind::Exact
            | SolverKind::Chain
            | SolverKind::Sccp
            | SolverKind::Gsccp
            | SolverKind::Aoe => true,
        }
    }

    /// The short name used on the command line and in links.
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::NearestNeighbour => "nearest",
            SolverKind::Ccp => "ccp",
            SolverKind::Heuristic => "heuristic",
            SolverKind::Exact => "exact",
            SolverKind::Chain => "chain",
            SolverKind::Sccp => "sccp",
            SolverKind::Gsccp => "gsccp",
            SolverKind::Aoe => "aoe",
        }
    }

    /// What the UI shows for the solver.
    pub fn label(self) -> &'static str {
        match self {
            SolverKind::NearestNeighbour => "Nearest neighbour (baseline)",
            SolverKind::Ccp => "Continuous CCP-Relax",
            SolverKind::Heuristic => "Discrete heuristic (ALNS)",
            SolverKind::Exact => "Discrete exact with lower bound",
            SolverKind::Chain => "Chain cutting (CCP-Relax + chains)",
            SolverKind::Sccp => "Segment cutting (SCCP, common edges once)",
            SolverKind::Gsccp => "Generalised segment cutting (GSCCP)",
            SolverKind::Aoe => "Common-edge AOE-chains",
        }
    }

    /// The solver with the given short name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|kind| kind.name() == name)
    }
}

/// Solver settings; every field has a sensible default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverParams {
    /// Wall-clock limit in seconds.
    pub time_limit_s: f64,
    /// Seed of the solver's random choices (runs with one seed are repeatable).
    pub seed: u64,
    /// Spacing of candidate pierce points along contours for the discrete solvers, in mm.
    pub discretisation_step_mm: f64,
    /// An upper bound known in advance (the exact solver prunes with it).
    pub initial_upper_bound: Option<f64>,
    /// Speeds, pierce time and prices of the time and cost model (chain cutting links
    /// contours when the link costs less than the pierce it saves).
    #[serde(default)]
    pub machine: MachineParameters,
    /// What the solvers that choose between routes (GSCCP's ensembles) minimise, and what the
    /// UI compares routes by.
    #[serde(default)]
    pub objective: Objective,
    /// The material's heat model, the heat weight and the shop rules (issue #19); off by
    /// default (weight 0, no rules), so requests without it run as before.
    #[serde(default)]
    pub thermal: ThermalSettings,
    /// The full cutting route (issue #17): kerf, the pierce and switch-off clearances d₁ and
    /// d₂, lead-in, lead-out, overcut and tabs. The default is the idealised model (requests
    /// and links without it run as before); otherwise the engine's kerf job optimises the route
    /// with its leads (nearest, ccp, heuristic).
    #[serde(default)]
    pub kerf: KerfSettings,
    /// With kerf on: solve the idealised route, then attach leads (no optimisation with them;
    /// the comparison of the benchmark, the CLI's `--leads-after`).
    #[serde(default)]
    pub leads_after: bool,
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            time_limit_s: 10.0,
            seed: 1,
            discretisation_step_mm: 50.0,
            initial_upper_bound: None,
            machine: MachineParameters::default(),
            objective: Objective::default(),
            thermal: ThermalSettings::default(),
            kerf: KerfSettings::default(),
            leads_after: false,
        }
    }
}

/// Start a job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobRequest {
    /// Chosen by the sender; echoed in every answer.
    pub job_id: JobId,
    /// What to solve.
    pub problem: Problem,
    /// Which solver.
    pub solver: SolverKind,
    /// Its settings.
    pub params: SolverParams,
}

/// The state of a running (or ended) job.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// The job this is about.
    pub job_id: JobId,
    /// Seconds since the job started.
    pub elapsed_s: f64,
    /// The cost of the best solution so far and a proven lower bound on the optimum (if the
    /// solver computes one), in the unit the job states: idle mm for routes of whole contours,
    /// the value of [`SolverParams::objective`] under [`SolverParams::machine`] for path routes
    /// (sccp, gsccp, aoe: the plan's length cut, the pierces every route needs and the idle
    /// travel to and from the parts), the instance's weights for tours.
    pub bounds: Bounds,
    /// What the solver is doing, with its numbers (`Display`: the English words).
    pub phase: Phase,
    /// The best solution so far: a route of whole contours, tool-on paths or a tour.
    pub solution: Option<Solution>,
    /// Whether the best solution is proven optimal.
    pub proven_optimal: bool,
    /// States the exact search has created so far (exact solver only).
    pub states: Option<u64>,
    /// Per step of the route: whether its pierce point is certified optimal for the order
    /// (CCP's Condition 1); empty when the solver does not certify.
    pub certified: Vec<bool>,
    /// The candidates the solver weighed (GSCCP: each ensemble and the CCP route that seeded
    /// them), with their numbers under the machine's model; empty for other solvers.
    #[serde(default)]
    pub alternatives: Vec<RouteSummary>,
    /// The thermal load H of the best route (or path route) under
    /// [`SolverParams::thermal`]'s σ and τ, on the route's machine clock
    /// (`cutroute_thermal::HeatModel::load`); `None` without a route.
    #[serde(default)]
    pub heat: Option<f64>,
    /// Violations per rule group of the rules [`SolverParams::thermal`] selects (`None` for a
    /// group not checked, and for path routes: the rules are defined on contour routes).
    #[serde(default)]
    pub rule_counts: Option<RuleCounts>,
    /// Every violation behind `rule_counts`, by rule group then step.
    #[serde(default)]
    pub violations: Vec<Violation>,
    /// A proven lower bound (mm) on the idle length of every route the solver can return, for
    /// the solvers that give a path route (sccp, gsccp, aoe): their `bounds` are machine
    /// time or cost, where the fixed cutting time hides how far the idle travel may still
    /// shrink. `None` for the other solvers and before the bound is measured.
    #[serde(default)]
    pub idle_lower_bound: Option<f64>,
}

/// One candidate route a solver weighed, in numbers (lengths in mm, time in s).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RouteSummary {
    /// What the candidate is, e.g. "chains" or "standard".
    pub name: String,
    /// Pierces of its route.
    pub pierces: usize,
    /// Idle length.
    pub idle_length: f64,
    /// Cut length (common edges cut twice counted twice).
    pub cut_length: f64,
    /// Machining time.
    pub time_s: f64,
    /// Cost.
    pub cost: f64,
    /// Whether this is the route the solver returned.
    pub chosen: bool,
    /// Why the candidate gave no route, if it did not, in words. A message, not the solver's
    /// error type: the summary crosses to the page (postMessage) and the CLI's JSON, where only
    /// the words are shown; the typed error with its source stays in the solver crate
    /// (`cutroute_segments::EnsembleFailure`).
    pub failure: Option<String>,
    /// The solver's proven lower bound on the idle length (mm) of every route it can return
    /// ([`Progress::idle_lower_bound`]), on the chosen candidate; `None` elsewhere.
    #[serde(default)]
    pub idle_lower_bound: Option<f64>,
}

impl RouteSummary {
    /// The summary of a route that was made, from its cut and idle lengths and pierces, its time
    /// and cost under `machine` (not chosen, no failure, no bound).
    pub fn measured(
        name: &str,
        (cut, idle, pierces): (f64, f64, usize),
        machine: &MachineParameters,
    ) -> Self {
        RouteSummary {
            name: name.to_string(),
            pierces,
            idle_length: idle,
            cut_length: cut,
            time_s: machine.time(cut, idle, pierces),
            cost: machine.cost(cut, idle, pierces),
            ..RouteSummary::default()
        }
    }

    /// The relative gap `(idle − idle LB) / idle` of this candidate's idle length, when the
    /// bound is known.
    pub fn idle_gap(&self) -> Option<f64> {
        relative_gap(self.idle_length, self.idle_lower_bound?)
    }
}

/// `(ub − lb) / ub`, clamped at 0; 0 when `ub` is 0.
fn relative_gap(ub: f64, lb: f64) -> Option<f64> {
    if !(ub.is_finite() && lb.is_finite()) {
        return None;
    }
    Some(if ub > 0.0 {
        ((ub - lb) / ub).max(0.0)
    } else {
        0.0
    })
}

impl Progress {
    /// The best route of whole contours so far, if the solution is one.
    pub fn route(&self) -> Option<&Route> {
        self.solution.as_ref().and_then(Solution::route)
    }

    /// The best tool-on paths so far, if the solution is a path route.
    pub fn path_route(&self) -> Option<&PathRoute> {
        self.solution.as_ref().and_then(Solution::path_route)
    }

    /// The best tour so far, if the solution is a PCGTSP tour.
    pub fn tour(&self) -> Option<&[usize]> {
        self.solution.as_ref().and_then(Solution::tour)
    }

    /// The idle length (mm) of the best path route: the upper bound the idle gap is measured
    /// against.
    pub fn idle_upper_bound(&self) -> Option<f64> {
        self.path_route().map(|r| r.idle_length())
    }

    /// The relative gap `(idle UB − idle LB) / idle UB` in idle length (path-route solvers),
    /// when both are known.
    pub fn idle_gap(&self) -> Option<f64> {
        relative_gap(self.idle_upper_bound()?, self.idle_lower_bound?)
    }

    /// The relative gap `(UB − LB) / UB`, when both bounds are known.
    pub fn gap(&self) -> Option<f64> {
        self.bounds.gap()
    }

    /// Why a PCGTSP job that ended holds no tour, in the words the CLI and the page both use;
    /// `None` when it holds one. Only a search that ran to its end (`stopped_early` false)
    /// and proved its result proves infeasibility; otherwise nothing is proved.
    /// `solver` is the solver's name ([`SolverKind::name`]).
    pub fn missing_tour(&self, solver: &str, stopped_early: bool) -> Option<String> {
        if self.tour().is_some() {
            return None;
        }
        Some(if self.proven_optimal && !stopped_early {
            format!("the {solver} solver proved that the instance has no feasible tour")
        } else {
            format!(
                "the {solver} solver found no feasible tour in {:.1} s (not a proof that none exists)",
                self.elapsed_s
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{ContourRef, CutStep, Vertex};

    fn sample_request() -> ToWorker {
        let nest = Nest {
            sheet: None,
            parts: vec![cutroute_geometry::Part {
                name: "A".into(),
                contours: vec![cutroute_geometry::Contour::new(vec![
                    Vertex::line(0.0, 0.0),
                    Vertex::arc(1.0, 0.0, 0.5),
                ])],
            }],
        };
        ToWorker::Start(JobRequest {
            job_id: 7,
            problem: Problem::Nest {
                nest,
                start: Point::new(1.0, 2.0),
                finish: Some(Point::default()),
            },
            solver: SolverKind::Ccp,
            params: SolverParams {
                initial_upper_bound: Some(3.5),
                ..SolverParams::default()
            },
        })
    }

    #[test]
    fn idle_gap_is_measured_against_the_path_routes_idle_length() {
        let route = cutroute_geometry::PathRoute {
            start: Point::default(),
            paths: vec![cutroute_geometry::ToolOnPath {
                pierce: Point::new(30.0, 40.0),
                spans: vec![cutroute_geometry::Span {
                    start: Point::new(30.0, 40.0),
                    end: Point::new(40.0, 40.0),
                    bulge: 0.0,
                }],
                leads: None,
            }],
            finish: None,
        };
        let mut progress = Progress {
            solution: Some(Solution::PathRoute(route)),
            ..Progress::default()
        };
        assert_eq!(progress.idle_upper_bound(), Some(50.0));
        assert_eq!(progress.idle_gap(), None);
        progress.idle_lower_bound = Some(40.0);
        assert!((progress.idle_gap().unwrap() - 0.2).abs() < 1e-12);
        progress.idle_lower_bound = Some(60.0);
        assert_eq!(progress.idle_gap(), Some(0.0));
        let summary = RouteSummary {
            idle_length: 0.0,
            idle_lower_bound: Some(0.0),
            ..RouteSummary::default()
        };
        assert_eq!(summary.idle_gap(), Some(0.0));
    }

    /// One solution of each shape, as the jobs report them.
    fn every_solution_kind() -> Vec<(Solution, CostUnit)> {
        vec![
            (
                Solution::Route(Route {
                    start: Point::default(),
                    steps: vec![CutStep {
                        contour: ContourRef {
                            part: 0,
                            contour: 0,
                        },
                        pierce_point: Point::new(0.0, 0.0),
                        entry: Default::default(),
                        leads: None,
                    }],
                    finish: None,
                }),
                CostUnit::IdleMm,
            ),
            (Solution::Tour(vec![0, 3, 2]), CostUnit::TourCost),
            (
                Solution::PathRoute(cutroute_geometry::PathRoute {
                    start: Point::default(),
                    paths: vec![cutroute_geometry::ToolOnPath {
                        pierce: Point::new(0.0, 0.0),
                        spans: vec![cutroute_geometry::Span {
                            start: Point::new(0.0, 0.0),
                            end: Point::new(10.0, 0.0),
                            bulge: 0.5,
                        }],
                        leads: None,
                    }],
                    finish: Some(Point::new(1.0, 1.0)),
                }),
                CostUnit::Seconds,
            ),
        ]
    }

    fn progress_with(solution: Solution, unit: CostUnit) -> Progress {
        Progress {
            job_id: 7,
            elapsed_s: 0.25,
            bounds: Bounds {
                upper: Some(10.0),
                lower: Some(8.0),
                unit,
            },
            phase: Phase::ExactLayer {
                layer: 3,
                states: 12,
            },
            solution: Some(solution),
            proven_optimal: false,
            states: Some(12),
            certified: vec![true],
            alternatives: vec![RouteSummary {
                name: "chains".into(),
                pierces: 1,
                idle_length: 2.0,
                cut_length: 10.0,
                time_s: 3.0,
                cost: 4.0,
                chosen: true,
                failure: None,
                idle_lower_bound: Some(1.5),
            }],
            heat: Some(0.75),
            rule_counts: Some(RuleCounts {
                part: Some(1),
                sheet: None,
                islands: Some(0),
            }),
            violations: vec![Violation::Island {
                step: 0,
                part: ContourRef {
                    part: 0,
                    contour: 0,
                },
            }],
            idle_lower_bound: Some(1.5),
        }
    }

    #[test]
    fn progress_of_every_solution_kind_survives_both_codecs() {
        for (solution, unit) in every_solution_kind() {
            let progress = progress_with(solution.clone(), unit);
            for message in [
                FromWorker::Progress(progress.clone()),
                FromWorker::Finished(progress.clone()),
            ] {
                let bytes = bincode::serialize(&message).unwrap();
                assert_eq!(bincode::deserialize::<FromWorker>(&bytes).unwrap(), message);
                let text = serde_json::to_string(&message).unwrap();
                assert_eq!(serde_json::from_str::<FromWorker>(&text).unwrap(), message);
            }
            // Each shape answers only to its own accessor, and the bounds keep their unit.
            assert_eq!(progress.route().is_some(), solution.route().is_some());
            assert_eq!(
                progress.path_route().is_some(),
                solution.path_route().is_some()
            );
            assert_eq!(progress.tour().is_some(), solution.tour().is_some());
            let shapes = [
                progress.route().is_some(),
                progress.path_route().is_some(),
                progress.tour().is_some(),
            ];
            assert_eq!(shapes.iter().filter(|s| **s).count(), 1, "{solution:?}");
            assert_eq!(progress.bounds.unit, unit);
        }
    }

    #[test]
    fn the_objective_names_the_unit_of_path_route_bounds() {
        assert_eq!(Objective::Time.unit(), CostUnit::Seconds);
        assert_eq!(Objective::Cost.unit(), CostUnit::Cost);
        assert_eq!(Bounds::default().unit, CostUnit::IdleMm);
        assert_eq!(Bounds::idle_mm(Some(4.0), Some(3.0)).gap(), Some(0.25));
        assert_eq!(Bounds::unknown(CostUnit::Cost).gap(), None);
    }

    #[test]
    fn routes_with_leads_survive_the_worker_codec() {
        use cutroute_geometry::{ContourRef, CutStep, Route, StepLeads, Vertex};
        let mut step = CutStep::pierced(
            ContourRef {
                part: 0,
                contour: 0,
            },
            Point::new(1.0, 0.0),
        );
        step.leads = Some(StepLeads {
            pierce: Point::new(-4.0, 0.0),
            entry: Point::new(0.0, 0.0),
            lead_in: vec![Vertex::arc(-4.0, 0.0, 0.4), Vertex::line(0.0, 0.0)],
            lead_out: vec![Vertex::line(0.0, 0.0), Vertex::line(-2.0, 0.0)],
            switch_off: Point::new(-2.0, 0.0),
            offset: 1.0,
            overcut: 0.5,
            pierce_clearance: 5.0,
            switch_off_clearance: 1.0,
            tabs: vec![cutroute_geometry::Tab {
                start: 3.0,
                end: 4.5,
                from: Point::new(0.0, 3.0),
                to: Point::new(0.0, 4.5),
            }],
            edge_pierce: true,
            kerf_pierce: Some(ContourRef {
                part: 1,
                contour: 0,
            }),
        });
        let route = Route {
            start: Point::default(),
            steps: vec![
                step,
                CutStep::pierced(
                    ContourRef {
                        part: 1,
                        contour: 0,
                    },
                    Point::new(9.0, 9.0),
                ),
            ],
            finish: None,
        };
        let bytes = bincode::serialize(&route).unwrap();
        assert_eq!(bincode::deserialize::<Route>(&bytes).unwrap(), route);
    }

    /// The reader's warnings cross to the page in the worker's codec, with and without the
    /// geometry they left out, and in JSON.
    #[test]
    fn read_warnings_survive_both_codecs() {
        use cutroute_geometry::{ReadWarning, WarningKind, WarningPlace};
        let warnings = vec![
            ReadWarning::new(WarningKind::Units, "no units; millimetres assumed"),
            ReadWarning::new(WarningKind::OpenChain, "open chain left out")
                .at_line(12, Some(3))
                .leaving_out(vec![vec![Point::new(0.0, 0.0), Point::new(3.0, 4.0)]]),
            ReadWarning::new(WarningKind::Duplicate, "drawn twice")
                .at(WarningPlace::Byte { offset: 7 }),
        ];
        let bytes = bincode::serialize(&warnings).unwrap();
        assert_eq!(
            bincode::deserialize::<Vec<ReadWarning>>(&bytes).unwrap(),
            warnings
        );
        let json = serde_json::to_string(&warnings).unwrap();
        assert_eq!(
            serde_json::from_str::<Vec<ReadWarning>>(&json).unwrap(),
            warnings
        );
    }

    #[test]
    fn kerf_settings_and_notes_survive_both_codecs_and_old_requests_stay_idealised() {
        use cutroute_geometry::{KerfSettings, LeadShape, LeadSpec, TabSpec};
        let mut request = match sample_request() {
            ToWorker::Start(request) => request,
            other => panic!("{other:?}"),
        };
        request.params.kerf = KerfSettings {
            kerf: 2.0,
            pierce_clearance: 5.0,
            switch_off_clearance: 1.0,
            lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
            lead_out: LeadSpec::new(LeadShape::LineArc, 2.0),
            overcut: 0.5,
            tabs: TabSpec {
                count: 2,
                width: 1.5,
            },
            edge_pierce: true,
            kerf_pierce: true,
        };
        request.params.leads_after = true;
        let message = ToWorker::Start(request.clone());
        let bytes = bincode::serialize(&message).unwrap();
        assert_eq!(bincode::deserialize::<ToWorker>(&bytes).unwrap(), message);
        let text = serde_json::to_string(&message).unwrap();
        assert_eq!(serde_json::from_str::<ToWorker>(&text).unwrap(), message);
        // A request written before kerf existed (links, scripts) reads as idealised.
        let mut old: serde_json::Value = serde_json::to_value(&request).unwrap();
        let params = old["params"].as_object_mut().unwrap();
        params.remove("kerf");
        params.remove("leads_after");
        let read: JobRequest = serde_json::from_value(old).unwrap();
        assert!(read.params.kerf.is_idealised());
        assert!(!read.params.leads_after);
        let phase = Phase::Kerf {
            base: Box::new(Phase::Done),
            note: KerfNote::NoRoom {
                contours: vec![(1, 0)],
                errors: vec!["no lead fits".into()],
            },
        };
        let bytes = bincode::serialize(&phase).unwrap();
        assert_eq!(bincode::deserialize::<Phase>(&bytes).unwrap(), phase);
        assert_eq!(
            phase.to_string(),
            "done · 1 contour(s) without room for the leads: no lead fits"
        );
    }

    #[test]
    fn messages_survive_json() {
        let request = sample_request();
        let text = serde_json::to_string(&request).unwrap();
        assert_eq!(serde_json::from_str::<ToWorker>(&text).unwrap(), request);
    }

    #[test]
    fn gap_is_relative_to_the_upper_bound() {
        let p = Progress {
            bounds: Bounds::idle_mm(Some(200.0), Some(150.0)),
            ..Progress::default()
        };
        assert_eq!(p.gap(), Some(0.25));
        assert_eq!(Progress::default().gap(), None);
    }

    #[test]
    fn a_missing_tour_is_proved_infeasible_only_by_a_finished_proof() {
        let with_tour = Progress {
            solution: Some(Solution::Tour(vec![0, 1])),
            proven_optimal: true,
            ..Progress::default()
        };
        assert_eq!(with_tour.missing_tour("exact", false), None);
        let proved = Progress {
            proven_optimal: true,
            ..Progress::default()
        };
        assert_eq!(
            proved.missing_tour("exact", false).as_deref(),
            Some("the exact solver proved that the instance has no feasible tour")
        );
        let stopped = proved.missing_tour("exact", true).unwrap();
        assert!(stopped.contains("not a proof"), "{stopped}");
        let heuristic = Progress {
            elapsed_s: 1.04,
            ..Progress::default()
        };
        assert_eq!(
            heuristic.missing_tour("heuristic", false).as_deref(),
            Some("the heuristic solver found no feasible tour in 1.0 s (not a proof that none exists)")
        );
    }

    #[test]
    fn solver_names_round_trip() {
        for kind in SolverKind::ALL {
            assert_eq!(SolverKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(SolverKind::from_name("magic"), None);
    }
}
