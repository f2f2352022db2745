//! `cutroute`: inspect, convert and route cutting plans and PCGTSP instances from the shell.
//!
//! ```text
//! cutroute inspect FILE [--json] [--sheet N] [--step MM]  # lists a project's sheets
//! cutroute convert IN OUT [--to dbs|json|svg|gcode|html]   # default: by OUT's extension
//!                  [--sheet N] [--profile FILE.json] [--preset NAME]
//!                  [--solver NAME] [--time-limit S] [--seed N] [--step MM]   # as solve
//!                  [--cost …] [--speeds …] [--task …] [--objective …]         # as solve
//!                  [--incremental] [--arcs ij|r|lines] [--decimals N] [--line-numbers]
//!                  [--feed MM_PER_MIN] [--dwell S] [--torch-on CODE] [--torch-off CODE]
//! cutroute generate --contours N [--seed S] --out FILE   # synthetic nest as geometry JSON
//! cutroute solve FILE --solver nearest|ccp|heuristic|exact|discrete|chain|aoe|sccp|gsccp
//!                     [--time-limit S] [--seed N] [--ub N] [--step MM] [--cost C_off,C_on,C_pt]
//!                     [--speeds V_off,V_on,t_pt] [--task TASK.json] [--objective time|cost]
//!                     [--thermal-sigma MM] [--thermal-tau S] [--thermal-weight W]
//!                     [--rules part,sheet,islands] [--rules-hard] [--json] [--out FILE]
//!                     [--kerf MM] [--pierce-clearance MM] [--switch-off-clearance MM]
//!                     [--lead-in arc|line|line-arc|none] [--lead-in-length MM]
//!                     [--lead-out arc|line|line-arc|none] [--lead-out-length MM]
//!                     [--overcut MM] [--leads-after]   # also on convert
//!                     [--sheet N] [--profile FILE.json]
//! ```
//! The time and cost model (`--speeds`, `--cost`) defaults to the task file's speeds and pierce
//! time when `--task` is given, else to `MachineParameters::default()`; prices are per metre of
//! idle travel and of cut and per pierce, speeds in mm/s, the pierce time in s.
//! `sccp` cuts the multi-contour chains of the nest's plan graph (common edges once) as base
//! segments; `gsccp` also tries standard cutting and contours split at junctions and keeps
//! the best by `--objective` (`cutroute-segments`); `aoe` cuts common edges once along
//! AOE-chains (`cutroute-aoe`). The three run the job engine's path-route jobs, as the app
//! does, and report the route as tool-on paths (`PathRoute` JSON), `ub`/`lb` in the
//! objective's unit, and (sccp, gsccp) each ensemble's numbers.
//! Every nest report adds the heat load `heat` (σ = 50 mm, τ = 60 s unless given), the rule
//! violations and each step's machine time `t` (`cutroute-thermal`); `--thermal-weight` makes
//! nearest, ccp and chain minimise objective + W·H (heuristic and exact relax their final pierce
//! points on it), `--rules-hard` repairs the route until the rules hold.
//! With `--kerf`/leads on (`kerf.rs`), nearest, ccp, heuristic and discrete optimise the full
//! route (pierce points off the contours, leads, cut on the equidistants), chain links its
//! chains between the equidistants (a lead-in at each chain's start, a lead-out at its end),
//! and each route step carries `pierce` (M), `entry`, `lead_in`, `lead_out` and `switch_off`.
//! `--sheet`, `--profile` and `--preset` are described in `inputs.rs` (profile < task <
//! flags; `--preset` < the G-code flags).
//! `-` as a file name is standard input (FILE, IN) or standard output (OUT, `--out`); files are
//! written whole or not at all, and on a terminal a live line shows UB, LB and the gap
//! (`stdio.rs`).
//! Errors go to stderr with the reader's location, and the exit code is 1.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use cutroute_engine::{start_job, AoeJob, Job, NearestNeighbourJob, SegmentJob};
use cutroute_geometry::{
    ContainmentForest, Entry, MachineParameters, Nest, Objective, PathRoute, Route,
};
use cutroute_protocol::{
    CostUnit, Document, JobRequest, Problem, Progress, Solution, SolverKind, SolverParams,
};
use report::{Report, StepReport};
use serde_json::{json, Value};

mod gcode_input;
mod inputs;
mod kerf;
mod output;
mod report;
mod stdio;
mod thermal;
mod warnings;

#[derive(Parser)]
#[command(
    name = "cutroute",
    version,
    about = "Tool-path optimisation for CNC sheet cutting"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Summarise a nest or PCGTSP file (format detected from content).
    Inspect {
        /// The file to read (`-`: standard input).
        file: PathBuf,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        sheet: inputs::SheetArg,
        /// Also count the candidate pierce points of the discrete solvers at this spacing, mm
        /// (`candidate_points`: every STEP mm along each contour, and its vertices).
        #[arg(long, value_name = "MM", value_parser = step_mm)]
        step: Option<f64>,
        /// Read a G-code program in this post-processor's dialect (its torch codes, dwell unit
        /// and arc tolerance), e.g. kometa-2p32m's M71/M74.
        #[arg(long, value_enum, value_name = "NAME")]
        preset: Option<inputs::PresetArg>,
        #[command(flatten)]
        compensation: gcode_input::CompensationArg,
    },
    /// Convert a nest between formats (.dbs, .json, .svg), or route it and write the route as
    /// G-code (.nc, .gcode, .ngc, .tap) or a standalone HTML page (.html).
    Convert {
        /// The file to read (any supported nest format; `-`: standard input).
        input: PathBuf,
        /// The file to write (`-`: standard output, with --to).
        output: PathBuf,
        /// Output format (default: from the output's extension).
        #[arg(long, value_parser = ["dbs", "json", "svg", "gcode", "html"])]
        to: Option<String>,
        /// Solver of the route for gcode/html: nearest, ccp, heuristic or discrete (default: the
        /// route the file holds, else ccp).
        #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(SOLVERS))]
        solver: Option<String>,
        /// Wall-clock limit of the solver, seconds: finite and positive, or `inf` (until proven
        /// optimal or stopped by Ctrl-C).
        #[arg(long, default_value = "10", value_parser = time_limit_seconds)]
        time_limit: f64,
        /// Seed of the solver's random choices.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Spacing of candidate pierce points for the discrete solvers, mm (positive; at
        /// least the nest's perimeter / 20,000, see the error).
        #[arg(long, default_value = "50", value_parser = step_mm)]
        step: f64,
        #[command(flatten)]
        machine: MachineArgs,
        #[command(flatten)]
        gcode: GcodeArgs,
        #[command(flatten)]
        kerf: kerf::KerfArgs,
        #[command(flatten)]
        sheet: inputs::SheetArg,
        #[command(flatten)]
        profile: inputs::ProfileArg,
        #[command(flatten)]
        compensation: gcode_input::CompensationArg,
    },
    /// Write a seeded synthetic nest (geometry JSON) for tests and benchmarks.
    Generate {
        /// Number of contours, 1 to 1,000,000.
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_GENERATED_CONTOURS))]
        contours: u64,
        /// Seed of the generator.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The file to write (`-`: standard output).
        #[arg(long)]
        out: PathBuf,
    },
    /// Route a nest or solve a PCGTSP instance.
    Solve {
        /// A nest file or a PCGTSP instance (`-`: standard input).
        file: PathBuf,
        /// nearest, ccp, heuristic, exact, discrete (= heuristic on a discretised nest),
        /// chain (ccp, then chain cutting), aoe (common edges cut once along AOE-chains),
        /// sccp (segment cutting along the plan's common edges) or gsccp (the best of several
        /// segment ensembles).
        #[arg(long, default_value = "ccp", value_parser = clap::builder::PossibleValuesParser::new(SOLVERS))]
        solver: String,
        /// Wall-clock limit in seconds: finite and positive, or `inf` (until proven optimal or
        /// stopped by Ctrl-C, which keeps the best route so far).
        #[arg(long, default_value = "10", value_parser = time_limit_seconds)]
        time_limit: f64,
        /// Seed of the solver's random choices.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// A known upper bound (exact solver), finite and non-negative.
        #[arg(long, value_parser = finite_non_negative)]
        ub: Option<f64>,
        /// Spacing of candidate pierce points for the discrete solvers on nests, mm (positive;
        /// at least the nest's perimeter / 20,000, see the error).
        #[arg(long, default_value = "50", value_parser = step_mm)]
        step: f64,
        #[command(flatten)]
        machine: MachineArgs,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
        /// Write the report to this file instead of standard output (whole or not at all).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        #[command(flatten)]
        thermal: thermal::ThermalArgs,
        #[command(flatten)]
        kerf: kerf::KerfArgs,
        #[command(flatten)]
        sheet: inputs::SheetArg,
        #[command(flatten)]
        profile: inputs::ProfileArg,
        #[command(flatten)]
        compensation: gcode_input::CompensationArg,
    },
}

/// The machine's time and cost model and the objective, the same for `solve` and `convert`.
#[derive(clap::Args)]
struct MachineArgs {
    /// Prices: idle travel per metre, cut per metre, one pierce (C_off,C_on,C_pt).
    #[arg(long, value_name = "C_off,C_on,C_pt")]
    cost: Option<String>,
    /// Idle speed and cutting speed (mm/s) and pierce time (s): V_off,V_on,t_pt.
    #[arg(long, value_name = "V_off,V_on,t_pt")]
    speeds: Option<String>,
    /// A RouteManager task JSON whose speeds and pierce time are the defaults.
    #[arg(long)]
    task: Option<PathBuf>,
    /// Time of one pierce at the sheet's edge (`--edge-pierce`), s; default: the pierce time.
    #[arg(long, value_name = "S")]
    edge_pierce_time: Option<f64>,
    /// What gsccp minimises when it picks an ensemble, and the unit of the path-route
    /// solvers' (sccp, gsccp, aoe) bounds: time or cost.
    #[arg(long, default_value = "time", value_parser = ["time", "cost"])]
    objective: String,
}

impl MachineArgs {
    /// The time and cost model on top of `base` (defaults or the profile), and the objective.
    fn parse(&self, base: MachineParameters) -> Result<(MachineParameters, Objective), String> {
        let mut machine = machine_parameters(
            base,
            self.cost.as_deref(),
            self.speeds.as_deref(),
            self.task.as_deref(),
        )?;
        if let Some(time) = self.edge_pierce_time {
            if !(time.is_finite() && time >= 0.0) {
                return Err(format!(
                    "--edge-pierce-time {time}: must be finite and non-negative"
                ));
            }
            machine.edge_pierce_time = Some(time);
        }
        let objective = match self.objective.as_str() {
            "cost" => Objective::Cost,
            _ => Objective::Time,
        };
        Ok((machine, objective))
    }
}

/// The `--solver` names of `solve`.
const SOLVERS: [&str; 9] = [
    "nearest",
    "ccp",
    "heuristic",
    "exact",
    "discrete",
    "chain",
    "aoe",
    "sccp",
    "gsccp",
];

/// Most contours `generate` writes: a million contours are about 200 MB of geometry JSON.
const MAX_GENERATED_CONTOURS: u64 = 1_000_000;

/// `--time-limit`: a finite positive number of seconds, or `inf` / `infinity` (until proven
/// optimal or stopped by Ctrl-C).
fn time_limit_seconds(text: &str) -> Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|e| format!("{e}"))?;
    if value == f64::INFINITY || (value.is_finite() && value > 0.0) {
        Ok(value)
    } else {
        Err("expected a finite number of seconds above 0, or inf".into())
    }
}

/// `--step`: a finite positive length, mm (the nest bounds it from below, see `build_pcgtsp`).
fn step_mm(text: &str) -> Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|e| format!("{e}"))?;
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err("expected a finite length above 0 mm".into())
    }
}

/// A finite non-negative number.
fn finite_non_negative(text: &str) -> Result<f64, String> {
    let value: f64 = text.trim().parse().map_err(|e| format!("{e}"))?;
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err("expected a finite number of at least 0".into())
    }
}

/// Exit code of a PCGTSP instance without a feasible tour (errors are 1, usage errors 2).
const EXIT_INFEASIBLE: u8 = 3;

/// Why the CLI failed: an error (exit 1) or a proof that no tour exists (exit 3). The printed
/// message is the `Display`; a typed cause stays reachable as the error's `source`.
#[derive(Debug, thiserror::Error)]
enum Failure {
    /// The CLI's own words: a flag, a file, a checker's verdict.
    #[error("{0}")]
    Message(String),
    /// The instance has no feasible tour, or none was found in time.
    #[error("{0}")]
    Infeasible(String),
    /// A file the engine could not open.
    #[error(transparent)]
    Open(#[from] cutroute_engine::OpenError),
    /// The engine refused to start the solver's job.
    #[error("--solver {solver}: {source}")]
    Engine {
        solver: &'static str,
        #[source]
        source: cutroute_engine::EngineError,
    },
    /// Segment cutting failed.
    #[error("--solver {solver}: {source}")]
    Segments {
        solver: &'static str,
        #[source]
        source: cutroute_segments::SegmentError,
    },
    /// AOE's job failed.
    #[error("--solver {solver}: {source}")]
    Aoe {
        solver: &'static str,
        #[source]
        source: cutroute_aoe::AoeSolveError,
    },
    /// The heat model or a rule check refused the route.
    #[error(transparent)]
    Thermal(#[from] cutroute_thermal::ThermalError),
}

impl From<String> for Failure {
    fn from(message: String) -> Self {
        Failure::Message(message)
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    install_stop_handler();
    let outcome = match cli.command {
        Command::Inspect {
            file,
            json,
            sheet,
            step,
            preset,
            compensation,
        } => inspect(&file, sheet.index(), json, step, preset, &compensation),
        Command::Convert {
            input,
            output,
            to,
            solver,
            time_limit,
            seed,
            step,
            machine,
            gcode,
            kerf,
            sheet,
            profile,
            compensation,
        } => (|| -> Result<(), Failure> {
            let inputs = [Some(input.as_path()), machine.task.as_deref()];
            let inputs = inputs.into_iter().chain([profile.profile.as_deref()]);
            output::refuse_overwriting_inputs(&output, inputs.flatten())?;
            let profile = profile.load()?;
            {
                let kerf = kerf.parse()?.with_profile(profile.as_ref());
                let (machine, objective) = machine.parse(inputs::base_machine(profile.as_ref()))?;
                let params = SolverParams {
                    time_limit_s: time_limit,
                    seed,
                    discretisation_step_mm: step,
                    initial_upper_bound: None,
                    machine,
                    objective,
                    thermal: Default::default(),
                    // Set by `kerf.request` when a solver runs.
                    kerf: Default::default(),
                    leads_after: false,
                };
                let gcode = gcode.options(profile.as_ref(), &params.machine)?;
                convert(
                    (&input, sheet.index(), &compensation),
                    &output,
                    to.as_deref(),
                    solver.as_deref(),
                    params,
                    &gcode,
                    &kerf,
                )
            }
        })(),
        Command::Generate {
            contours,
            seed,
            out,
        } => generate(contours as usize, seed, &out).map_err(Failure::Message),
        Command::Solve {
            file,
            solver,
            time_limit,
            seed,
            ub,
            step,
            machine,
            json,
            out,
            thermal,
            kerf,
            sheet,
            profile,
            compensation,
        } => (|| {
            if let Some(out) = &out {
                let inputs = [Some(file.as_path()), machine.task.as_deref()];
                let inputs = inputs.into_iter().chain([profile.profile.as_deref()]);
                output::refuse_overwriting_inputs(out, inputs.flatten())?;
            }
            let profile = profile.load()?;
            let kerf = kerf.parse()?.with_profile(profile.as_ref());
            let base = inputs::base_machine(profile.as_ref());
            let (machine, objective) = machine.parse(base)?;
            let thermal = thermal.parse()?;
            let params = SolverParams {
                time_limit_s: time_limit,
                seed,
                discretisation_step_mm: step,
                initial_upper_bound: ub,
                machine,
                objective,
                thermal: thermal.engine_settings(),
                // Set by `kerf.request`.
                kerf: Default::default(),
                leads_after: false,
            };
            let input = (file.as_path(), sheet.index(), &compensation);
            let report = solve(input, &solver, params, json, &thermal, &kerf)?;
            Ok(write_report(&report, json, out.as_deref())?)
        })(),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure @ Failure::Infeasible(_)) => {
            eprintln!("cutroute: {failure}");
            ExitCode::from(EXIT_INFEASIBLE)
        }
        Err(failure) => {
            eprintln!("cutroute: {failure}");
            ExitCode::FAILURE
        }
    }
}

/// Set by the first Ctrl-C: the running solver stops and its best route so far is reported.
static STOP_REQUESTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// First Ctrl-C: ask the solver loop to stop (it prints the best route so far); a second one
/// exits at once with 130, as a shell's SIGINT would.
fn install_stop_handler() {
    use std::sync::atomic::Ordering;
    // Without a handler (e.g. no signal support) Ctrl-C simply ends the process as before.
    let _ = ctrlc::set_handler(|| {
        if STOP_REQUESTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("cutroute: stopping; Ctrl-C again to quit without a result");
    });
}

/// A job's final (or latest) state, and earlier routes kept in case it fails the checker.
#[derive(Default)]
struct JobRun {
    last: Option<Progress>,
    /// Improving routes seen while the job ran, oldest first, at most [`KEPT_ROUTES`].
    earlier_routes: Vec<Route>,
    /// Why the run ended early: `None` when the solver ended by itself.
    stopped: Option<&'static str>,
    /// The limit it ran under, s (for messages).
    time_limit_s: f64,
    /// The route a very short limit gives (the nearest solver's first route, in forest
    /// order), made before the job starts: the answer when the job has none by the limit or
    /// Ctrl-C.
    first_route: Option<Progress>,
    /// Why the report answers with `first_route` (the job made no route of its own).
    fallback: Option<String>,
}

/// How many improving routes a run keeps, at least half a second apart.
const KEPT_ROUTES: usize = 8;

/// How long past its limit a solver may take to return to the CLI before the CLI reports the
/// best state it published and exits (the promise is limit + 1 s, report included).
const GRACE: std::time::Duration = std::time::Duration::from_millis(300);

/// How long after the first Ctrl-C the CLI waits for the stopped solver's route.
const CTRL_C_GRACE: std::time::Duration = std::time::Duration::from_secs(1);

/// What the CLI's main thread and the solver's thread share.
#[derive(Default)]
struct Watch {
    /// Set by the main thread at the limit or on Ctrl-C: the solver stops at its next slice.
    stop: std::sync::atomic::AtomicBool,
    /// Why: set before `stop`.
    reason: std::sync::Mutex<Option<&'static str>>,
    /// The latest published state.
    seen: std::sync::Mutex<JobRun>,
}

impl Watch {
    /// Whether a route has been published (the solver's or the first route).
    fn has_route(&self) -> bool {
        let seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        seen.first_route.is_some() || seen.last.as_ref().is_some_and(|p| p.solution.is_some())
    }
}

/// Steps a job until it ends or the watch says stop, publishing each slice's state and, now
/// and then, an improving route (only checked if the final route fails, see
/// [`checked_route`]).
fn run_job(job: &mut dyn Job, watch: &Watch, on_progress: &mut dyn FnMut(&Progress)) -> JobRun {
    use std::sync::atomic::Ordering;
    let started = std::time::Instant::now();
    let mut kept_ub = f64::INFINITY;
    let mut kept_at = -1.0;
    loop {
        let status = job.step(cutroute_engine::DEFAULT_SLICE);
        let progress = job.progress();
        on_progress(&progress);
        let elapsed = started.elapsed().as_secs_f64();
        let mut seen = watch.seen.lock().unwrap_or_else(|e| e.into_inner());
        if let (Some(route), Some(ub)) = (progress.route(), progress.bounds.upper) {
            if ub < kept_ub && elapsed - kept_at >= 0.5 {
                if seen.earlier_routes.len() == KEPT_ROUTES {
                    seen.earlier_routes.remove(0);
                }
                seen.earlier_routes.push(route.clone());
                (kept_ub, kept_at) = (ub, elapsed);
            }
        }
        // A kerf job between its solver's end and its first route with leads: the leads are
        // part of the answer, so a stop waits for them (the main thread still reports what
        // was published at the grace's end).
        let fitting_leads = progress.solution.is_none()
            && matches!(
                progress.phase,
                cutroute_protocol::Phase::Kerf {
                    note: cutroute_protocol::KerfNote::Leads { .. },
                    ..
                }
            );
        seen.last = Some(progress);
        let stop = watch.stop.load(Ordering::SeqCst) && !fitting_leads;
        if status == cutroute_engine::JobStatus::Done || stop {
            if stop {
                seen.stopped = *watch.reason.lock().unwrap_or_else(|e| e.into_inner());
                if status != cutroute_engine::JobStatus::Done {
                    // The final answer: with what only a final answer carries (CCP's
                    // certificates), whichever of the job and the watch saw the limit first.
                    // Stopping may take a while (GSCCP checks the route of the ensemble under
                    // way): not under the lock, which the main thread takes at its grace's end
                    // to report what was published.
                    drop(seen);
                    job.stop();
                    let mut last = job.progress();
                    // A job with no route yet makes the one its limit would give (AOE checks
                    // its ordering cut short) in further steps; the main thread reports what
                    // was published if that outlasts its grace.
                    while last.solution.is_none() {
                        let status = job.step(cutroute_engine::DEFAULT_SLICE);
                        last = job.progress();
                        watch.seen.lock().unwrap_or_else(|e| e.into_inner()).last =
                            Some(last.clone());
                        if status == cutroute_engine::JobStatus::Done {
                            break;
                        }
                    }
                    seen = watch.seen.lock().unwrap_or_else(|e| e.into_inner());
                    seen.last = Some(last);
                }
            }
            // A copy, not `take`: the job is dropped after this returns, and dropping a large
            // one (the exact search's states) can outlast the grace, when the main thread
            // reports what was published; taken, that was nothing ("found no route").
            return JobRun {
                last: seen.last.clone(),
                earlier_routes: seen.earlier_routes.clone(),
                stopped: seen.stopped,
                time_limit_s: seen.time_limit_s,
                first_route: seen.first_route.clone(),
                fallback: None,
            };
        }
    }
}

/// Runs `work` (which builds and steps a solver, see [`run_job`]) on its own thread, so the
/// CLI keeps its promises whatever the solver does: at `time_limit_s` after the start, or at
/// the first Ctrl-C, the watch asks the solver to stop; if it has not returned `grace` later
/// (at least `route_wait` while it has published no route), the latest state it published is
/// taken (and the thread ends with the process).
/// Build phases (matrices, lattices, discretisations) count against the limit.
fn run_bounded<T: Send + 'static>(
    time_limit_s: f64,
    (grace, route_wait): (std::time::Duration, std::time::Duration),
    work: impl FnOnce(&Watch) -> Result<T, Failure> + Send + 'static,
) -> Result<Result<T, JobRun>, Failure> {
    use std::sync::atomic::Ordering;
    use std::sync::Arc;
    let watch = Arc::new(Watch::default());
    let (done, result) = std::sync::mpsc::channel();
    let shared = Arc::clone(&watch);
    std::thread::spawn(move || {
        let _ = done.send(work(&shared));
    });
    let started = std::time::Instant::now();
    let mut stop_at: Option<std::time::Instant> = None;
    loop {
        match result.recv_timeout(std::time::Duration::from_millis(10)) {
            Ok(outcome) => return outcome.map(Ok),
            // A panic in the solver's thread: reported as an error, not as a crash.
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(Failure::Message(
                    "the solver failed (internal error)".into(),
                ))
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
        }
        let limit_passed = started.elapsed().as_secs_f64() >= time_limit_s;
        if stop_at.is_none() && (limit_passed || STOP_REQUESTED.load(Ordering::SeqCst)) {
            *watch.reason.lock().unwrap_or_else(|e| e.into_inner()) =
                Some(if limit_passed { "time limit" } else { "Ctrl-C" });
            watch.stop.store(true, Ordering::SeqCst);
            stop_at = Some(std::time::Instant::now());
        }
        // Ctrl-C waits a little longer for the route the solver makes when stopped (a second
        // Ctrl-C quits at once); the limit keeps its limit + 1 s promise.
        let waited = if limit_passed {
            grace
        } else {
            grace.max(CTRL_C_GRACE)
        };
        let waited = if stop_at.is_some() && !watch.has_route() {
            waited.max(route_wait)
        } else {
            waited
        };
        if stop_at.is_some_and(|at| at.elapsed() >= waited) {
            let mut seen = watch.seen.lock().unwrap_or_else(|e| e.into_inner());
            let mut run = std::mem::take(&mut *seen);
            run.stopped = Some(if limit_passed {
                "time limit (the solver was still in a long step)"
            } else {
                "Ctrl-C"
            });
            return Ok(Err(run));
        }
    }
}

/// The job the CLI steps: the engine's job for the request, or, for the path-route solvers,
/// their own job kept by its type so the report can add what only it knows (GSCCP's
/// ensembles, AOE's chains).
enum SolverJob {
    Engine(Box<dyn Job>),
    Segments(Box<SegmentJob>),
    Aoe(Box<AoeJob>),
}

impl SolverJob {
    /// The request's job; the path-route solvers (sccp, gsccp, aoe) run their job as the app's
    /// worker steps it.
    fn start(request: &JobRequest) -> Result<Self, Failure> {
        let refused = |e: cutroute_engine::EngineError| Failure::Engine {
            solver: request.solver.name(),
            source: e,
        };
        Ok(match request.solver {
            // With kerf and leads every solver runs in the engine's kerf job (the page's code
            // path): a path solver over the equidistants, leads at every path's ends.
            _ if !request.params.kerf.is_idealised() => {
                SolverJob::Engine(start_job(request).map_err(refused)?)
            }
            SolverKind::Aoe => {
                SolverJob::Aoe(Box::new(AoeJob::from_request(request).map_err(refused)?))
            }
            SolverKind::Sccp | SolverKind::Gsccp => SolverJob::Segments(Box::new(
                SegmentJob::from_request(request).map_err(refused)?,
            )),
            _ => SolverJob::Engine(start_job(request).map_err(refused)?),
        })
    }

    fn job(&mut self) -> &mut dyn Job {
        match self {
            SolverJob::Engine(job) => job.as_mut(),
            SolverJob::Segments(job) => job.as_mut(),
            SolverJob::Aoe(job) => job.as_mut(),
        }
    }

    /// What the report adds for this job after its run, under `machine`: AOE's pierce bound
    /// and components; GSCCP's chosen ensemble, every ensemble's numbers and the CCP route's.
    fn report_extras(
        &self,
        solver: SolverKind,
        machine: &MachineParameters,
    ) -> Result<serde_json::Map<String, Value>, Failure> {
        let mut extra = serde_json::Map::new();
        match self {
            SolverJob::Engine(_) => {}
            SolverJob::Aoe(job) => match job.outcome() {
                Some(Ok((solution, _))) => {
                    extra.insert(
                        "pierce_lower_bound".into(),
                        json!(solution.pierce_lower_bound),
                    );
                    extra.insert("components".into(), json!(solution.components));
                }
                // AOE failed and the job answers with a checked contour route: the report's
                // `fallback` says why (from the job's rejected-route alternative).
                Some(Err(_)) if job.fallback_route().is_some() => {}
                Some(Err(e)) => {
                    return Err(Failure::Aoe {
                        solver: solver.name(),
                        source: e.clone(),
                    })
                }
                // Stopped before its route was made (the job runs in slices): no extras, and
                // the report says what the run has, or that it found no route by the limit.
                None => {}
            },
            SolverJob::Segments(job) => {
                let result = job.search().result().map_err(|e| Failure::Segments {
                    solver: solver.name(),
                    source: e,
                })?;
                extra.insert(
                    "ensemble".into(),
                    json!(result.best.map_or("ccp", |kind| kind.name())),
                );
                extra.insert(
                    "ensembles".into(),
                    json!(result
                        .reports
                        .iter()
                        .map(|r| json!({
                            "kind": r.kind.name(),
                            "segments": r.segments,
                            "pierces": r.pierces,
                            "idle_length": finite(r.idle_length),
                            "cut_length": finite(r.cut_length),
                            "recut_length": r.recut_length,
                            "time_s": finite(r.time_s),
                            "cost": finite(r.cost),
                            "failure": r.failure.as_ref().map(ToString::to_string),
                        }))
                        .collect::<Vec<_>>()),
                );
                extra.insert(
                    "ccp".into(),
                    json!({
                        "idle_length": result.ccp_route.idle_length(),
                        "cut_length": result.ccp_route.cut_length(),
                        "pierces": result.ccp_route.pierce_count(),
                        "time_s": result.ccp_route.time(machine),
                        "cost": result.ccp_route.cost(machine),
                    }),
                );
            }
        }
        Ok(extra)
    }
}

/// A finished run: its states, what the job adds to the report ([`SolverJob::report_extras`];
/// empty when the run was cut in a long step, whose `run.stopped` then says so).
struct FinishedRun {
    run: JobRun,
    extras: serde_json::Map<String, Value>,
}

/// How long the report after a job is expected to take: about 4 µs per contour (twice what
/// the check, heat and JSON of a contour route take on a quiet machine, for load); a path
/// solver's report checks and prints every span of its route, so 5 µs more a span; none on a
/// PCGTSP instance.
fn report_estimate_s(problem: &Problem, solver: SolverKind) -> f64 {
    const PER_CONTOUR_S: f64 = 4e-6;
    const PER_SPAN_S: f64 = 5e-6;
    let Problem::Nest { nest, .. } = problem else {
        return 0.0;
    };
    let contours = nest.contour_count() as f64 * PER_CONTOUR_S;
    if solver.gives_path_route() {
        let spans: usize = nest
            .parts
            .iter()
            .flat_map(|part| &part.contours)
            .map(|contour| contour.span_count())
            .sum();
        contours + spans as f64 * PER_SPAN_S
    } else {
        contours
    }
}

/// The time kept from a job's limit for the report that follows it: its estimate, at most a
/// quarter of the limit (half for a path solver, whose report is mostly its spans); none on
/// an unlimited run.
fn report_reserve_s(problem: &Problem, solver: SolverKind, time_limit_s: f64) -> f64 {
    if !time_limit_s.is_finite() {
        return 0.0;
    }
    let share = if solver.gives_path_route() { 2.0 } else { 4.0 };
    report_estimate_s(problem, solver).min(time_limit_s / share)
}

/// The run of the request's job on the solver's thread, bounded by [`run_bounded`].
fn bounded_job_run(mut request: JobRequest, as_json: bool) -> Result<FinishedRun, Failure> {
    let time_limit_s = request.params.time_limit_s;
    // The report after the job (the route checked again, its heat and JSON) is part of the
    // promise: the job ends that much earlier.
    let reserve_s = report_reserve_s(&request.problem, request.solver, time_limit_s);
    request.params.time_limit_s = time_limit_s - reserve_s;
    // A run with no route at its limit (a first route still being made on a huge nest) waits
    // for one while the report would still end within the promise: exiting without a route
    // keeps the promise and gives the user nothing.
    let route_wait = std::time::Duration::from_secs_f64(
        (1.0 + reserve_s - report_estimate_s(&request.problem, request.solver)).max(0.0),
    );
    // A kerf job keeps its leads' time inside the limit where it can (it stops its solvers
    // when the final route's leads would not be ready by then) and ends by itself at most
    // `OVERRUN_LIMIT` past it: a route whose leads are still being fitted is waited for that
    // long, and no longer (the limit + 1 s promise, report included).
    let grace = if request.params.kerf.is_idealised() {
        GRACE
    } else {
        cutroute_engine::OVERRUN_LIMIT + std::time::Duration::from_millis(50)
    };
    let display = stdio::ProgressDisplay::new(as_json);
    let mut shown = display.clone();
    let job_limit_s = request.params.time_limit_s;
    let solver = request.solver;
    let run_started = std::time::Instant::now();
    let outcome = run_bounded(job_limit_s, (grace, route_wait), move |watch| {
        let first = first_route(&request);
        watch
            .seen
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .first_route = first;
        let mut job = SolverJob::start(&request)?;
        let run = run_job(job.job(), watch, &mut |p| shown.show(p));
        let extras = job.report_extras(request.solver, &request.params.machine)?;
        Ok((run, extras))
    })?;
    drop(display);
    let (mut run, extras) = match outcome {
        Ok((run, extras)) => (run, extras),
        Err(snapshot) => (snapshot, serde_json::Map::new()),
    };
    run.time_limit_s = time_limit_s;
    let has_route = run.last.as_ref().is_some_and(|p| p.solution.is_some());
    if let (false, Some(mut first)) = (has_route, run.first_route.take()) {
        // The report's time is the run's, not the first route's own.
        first.elapsed_s = first.elapsed_s.max(run_started.elapsed().as_secs_f64());
        let why = match run.stopped {
            Some(stopped) => format!(
                "the {} solver made no route before it was stopped ({stopped}): the nearest solver's first route (forest order) instead",
                solver.name()
            ),
            None => format!(
                "the {} solver made no route: the nearest solver's first route (forest order) instead",
                solver.name()
            ),
        };
        eprintln!("cutroute: warning: {why}");
        run.fallback = Some(why);
        run.last = Some(first);
    }
    Ok(FinishedRun { run, extras })
}

/// The route a very short limit gives for `request`'s nest: the nearest solver's first step
/// (the containment forest and the forest-order route, linear in vertices). `None` for the
/// nearest solver itself (its first step is this route), a PCGTSP instance, or a kerf job
/// (whose routes carry leads).
fn first_route(request: &JobRequest) -> Option<Progress> {
    let Problem::Nest {
        nest,
        start,
        finish,
    } = &request.problem
    else {
        return None;
    };
    if request.solver == SolverKind::NearestNeighbour || !request.params.kerf.is_idealised() {
        return None;
    }
    let mut job = NearestNeighbourJob::new(request.job_id, nest.clone(), *start, *finish).ok()?;
    job.step(cutroute_engine::DEFAULT_SLICE);
    Some(job.progress()).filter(|p| p.solution.is_some())
}

/// The run's route if it passes the checker, else the newest earlier route that does (with
/// the final route's problem, reported as `final_route_rejected`): a solver's last word never
/// loses a valid route it had. An error when no route passes.
fn checked_route(
    run: &JobRun,
    nest: &Nest,
    forest: &ContainmentForest,
) -> Result<(Route, Option<String>), String> {
    let tolerance = nest.check_tolerance();
    let first_problem = |route: &Route| route.problems(nest, forest, tolerance).into_iter().next();
    let no_route = || match run.stopped {
        Some(why) => format!(
            "--time-limit {}: the solver found no route before it was stopped ({why})",
            run.time_limit_s
        ),
        None => "the solver found no route".to_string(),
    };
    let route = run
        .last
        .as_ref()
        .and_then(Progress::route)
        .ok_or_else(no_route)?;
    let problem = match first_problem(route) {
        None => return Ok((route.clone(), None)),
        Some(e) => format!("invalid route: {e}"),
    };
    run.earlier_routes
        .iter()
        .rev()
        .find(|earlier| first_problem(earlier).is_none())
        .map(|earlier| (earlier.clone(), Some(problem.clone())))
        .ok_or(problem)
}

/// The checker's containment forest of a nest, built on its own thread while the solver runs:
/// on 100,000 contours building it after the solver stopped broke the time-limit promise.
fn forest_in_background(problem: &Problem) -> Option<std::thread::JoinHandle<ContainmentForest>> {
    let Problem::Nest { nest, .. } = problem else {
        return None;
    };
    let nest = nest.clone();
    Some(std::thread::spawn(move || nest.containment_forest()))
}

/// The forest [`forest_in_background`] built (built here if its thread failed).
fn joined_forest(
    handle: Option<std::thread::JoinHandle<ContainmentForest>>,
    nest: &Nest,
) -> ContainmentForest {
    handle
        .and_then(|h| h.join().ok())
        .unwrap_or_else(|| nest.containment_forest())
}

/// Three comma-separated finite non-negative numbers.
fn triple(flag: &str, text: &str) -> Result<[f64; 3], String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("--{flag} {text:?}: {e}"))?;
    let [a, b, c] = values[..] else {
        return Err(format!(
            "--{flag} {text:?}: expected three comma-separated numbers"
        ));
    };
    if [a, b, c].iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(format!(
            "--{flag} {text:?}: values must be finite and non-negative"
        ));
    }
    Ok([a, b, c])
}

/// The time and cost model: `base` (defaults or the profile), then the task file's speeds,
/// then the flags.
fn machine_parameters(
    base: MachineParameters,
    cost: Option<&str>,
    speeds: Option<&str>,
    task: Option<&Path>,
) -> Result<MachineParameters, String> {
    let mut machine = base;
    if let Some(path) = task {
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let task = cutroute_formats::read_task_json(&bytes)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        machine.idle_speed = task.task_data.tool_idling_speed;
        machine.cut_speed = task.task_data.tool_cut_speed;
        machine.pierce_time = task.task_data.piercing_duration;
    }
    if let Some(text) = speeds {
        let [idle, cut, pierce] = triple("speeds", text)?;
        if !(idle > 0.0 && cut > 0.0) {
            return Err(format!("--speeds {text:?}: speeds must be positive"));
        }
        machine.idle_speed = idle;
        machine.cut_speed = cut;
        machine.pierce_time = pierce;
    }
    if let Some(text) = cost {
        let [idle, cut, pierce] = triple("cost", text)?;
        machine.idle_price_per_metre = idle;
        machine.cut_price_per_metre = cut;
        machine.pierce_price = pierce;
    }
    Ok(machine)
}

/// Opens sheet `sheet` (from 0) of the file; every file has sheet 0. A G-code program's
/// `G41 D<n>` takes its radius from `--compensation-radius`.
fn open(
    (path, sheet): (&Path, usize),
    compensation: &gcode_input::CompensationArg,
) -> Result<Document, Failure> {
    let (name, bytes) = stdio::read_input(path)?;
    Ok(gcode_input::open(&name, &bytes, sheet, compensation)?)
}

fn inspect(
    path: &Path,
    sheet: usize,
    as_json: bool,
    step: Option<f64>,
    preset: Option<inputs::PresetArg>,
    compensation: &gcode_input::CompensationArg,
) -> Result<(), Failure> {
    let document = match preset {
        Some(inputs::PresetArg(preset)) => {
            let (name, bytes) = stdio::read_input(path)?;
            let text = String::from_utf8(bytes).map_err(|e| format!("{name}: {e}"))?;
            let options = compensation.apply(preset.read_options());
            cutroute_engine::open_gcode_with(&name, &text, &options)?
        }
        None => open((path, sheet), compensation)?,
    };
    let summary = match &document.problem {
        Problem::Nest { nest, .. } => {
            let mut summary = nest_summary(&document.format, nest);
            // A program's own route: its tool-on paths and pierces, as the machine runs it.
            let route = (document.paths.clone()).or_else(|| {
                let route = document.route.as_ref()?;
                PathRoute::from_route(route, nest).ok()
            });
            if let (Some(route), Value::Object(fields)) = (route, &mut summary) {
                fields.insert("route_pierces".into(), json!(route.pierce_count()));
                fields.insert("route_cut_length".into(), json!(route.cut_length()));
                fields.insert("route_idle_length".into(), json!(route.idle_length()));
            }
            if let (Some(step), Value::Object(fields)) = (step, &mut summary) {
                let candidates: usize = nest
                    .parts
                    .iter()
                    .flat_map(|part| &part.contours)
                    .map(|contour| contour.candidate_points(step, true).len())
                    .sum();
                fields.insert("candidate_points".into(), json!(candidates));
            }
            // The file's own route of whole contours, through the independent checker: what
            // tests use to check a route saved elsewhere (the app's result JSON).
            if let (Some(route), Value::Object(fields)) = (&document.route, &mut summary) {
                let tolerance = nest.check_tolerance();
                let problems: Vec<String> = route
                    .problems(nest, &nest.containment_forest(), tolerance)
                    .iter()
                    .map(ToString::to_string)
                    .collect();
                fields.insert("route_problems".into(), json!(problems));
            }
            summary
        }
        Problem::PcgtspText { text } => {
            let instance = cutroute_pcgtsp::Instance::parse(text).map_err(|e| e.to_string())?;
            json!({
                "format": document.format,
                "nodes": instance.node_count,
                "clusters": instance.clusters.len(),
                "precedence_pairs": instance.precedence.len(),
            })
        }
    };
    let mut summary = summary;
    inputs::add_sheets(&mut summary, &document.sheets, document.sheet);
    // Written as one piece, so a failing standard output is an error, not a panic.
    let text = if as_json {
        warnings::add_to(&mut summary, &document.warnings);
        format!("{summary}\n")
    } else {
        let mut text = String::new();
        for (key, value) in summary.as_object().into_iter().flatten() {
            text.push_str(&format!("{key:>16}: {value}\n"));
        }
        for warning in &document.warnings {
            text.push_str(&format!("         warning: {warning}\n"));
        }
        text
    };
    Ok(stdio::write_output(Path::new("-"), text.as_bytes())?)
}

/// Counts as stored in the file: the sheet counts as a part when the file has one.
fn nest_summary(format: &str, nest: &Nest) -> Value {
    let sheet_contours = nest.sheet.as_ref().map_or(0, |s| s.contours.len());
    let sheet_arcs = nest
        .sheet
        .as_ref()
        .map_or(0, |s| s.contours.iter().map(|c| c.arc_count()).sum());
    let bounds = nest
        .sheet
        .as_ref()
        .map(|s| s.bounding_box())
        .filter(|b| b.min.is_finite())
        .unwrap_or_else(|| nest.bounding_box());
    let forest = nest.containment_forest();
    json!({
        "format": format,
        "parts": nest.parts.len() + usize::from(nest.sheet.is_some()),
        "contours": nest.contour_count() + sheet_contours,
        "arcs": nest.arc_count() + sheet_arcs,
        "sheet": [bounds.min.x, bounds.min.y, bounds.max.x, bounds.max.y],
        "depth": forest.max_depth(),
    })
}

/// G-code settings of `convert --to gcode` (see `cutroute_gcode::GcodeOptions`).
#[derive(clap::Args)]
struct GcodeArgs {
    /// Post-processor preset (G-code dialect); the flags below override it.
    #[arg(long, value_enum, value_name = "NAME")]
    preset: Option<inputs::PresetArg>,
    /// Incremental coordinates (G91) instead of absolute (G90).
    #[arg(long)]
    incremental: bool,
    /// Arcs as G02/G03 with I/J ("ij"), with R ("r"), or as G01 chords ("lines")
    /// [default: the preset's, ij].
    #[arg(long, value_parser = ["ij", "r", "lines"])]
    arcs: Option<String>,
    /// Largest chord deviation of --arcs lines, mm.
    #[arg(long, default_value_t = 0.01)]
    chord_tolerance: f64,
    /// Decimals of coordinates [default: the preset's, 3].
    #[arg(long)]
    decimals: Option<usize>,
    /// Number the lines (N10, N20, …).
    #[arg(long)]
    line_numbers: bool,
    /// Cutting feed rate, mm/min (default: the machine's cutting speed).
    #[arg(long)]
    feed: Option<f64>,
    /// Pierce dwell, seconds (default: the machine's pierce time).
    #[arg(long)]
    dwell: Option<f64>,
    /// Torch-on line [default: the preset's, M03].
    #[arg(long)]
    torch_on: Option<String>,
    /// Torch-off line [default: the preset's, M05].
    #[arg(long)]
    torch_off: Option<String>,
    /// Who offsets the tool by half the kerf: the program ("program": the tool centre on the
    /// equidistants), or the controller, the program running on the contours with
    /// "g41.1" (G41.1 D<kerf>, LinuxCNC) or "g41:N" (G41 D<N>, the kerf in tool-table entry N).
    /// The controller's needs straight leads (--lead-in line --lead-out line) and no tabs.
    #[arg(long, value_name = "WHO", default_value = "program")]
    kerf_compensation: String,
}

impl GcodeArgs {
    /// The preset's (or profile's) options for `machine`, then the flags given.
    fn options(
        &self,
        profile: Option<&cutroute_protocol::MachineProfile>,
        machine: &MachineParameters,
    ) -> Result<cutroute_gcode::GcodeOptions, String> {
        use cutroute_gcode::{ArcOutput, DistanceMode, KerfCompensation};
        let mut options = inputs::preset_options(self.preset, profile, machine)?;
        match self.arcs.as_deref() {
            None => {}
            Some("ij") => options.arcs = ArcOutput::CentreOffsets,
            Some("r") => options.arcs = ArcOutput::Radius,
            Some("lines") => {
                options.arcs = ArcOutput::Lines {
                    tolerance_mm: self.chord_tolerance,
                }
            }
            Some(other) => return Err(format!("unknown --arcs {other:?} (ij, r, lines)")),
        }
        if self.incremental {
            options.distance_mode = DistanceMode::Incremental;
        }
        if self.line_numbers {
            options.line_numbers = true;
        }
        if let Some(decimals) = self.decimals {
            options.decimals = decimals;
        }
        if let Some(feed) = self.feed {
            options.cut_feed_mm_per_min = feed;
        }
        if let Some(dwell) = self.dwell {
            options.pierce_dwell_s = dwell;
        }
        if let Some(code) = &self.torch_on {
            options.torch_on = code.clone();
        }
        if let Some(code) = &self.torch_off {
            options.torch_off = code.clone();
        }
        options.kerf_compensation = match self.kerf_compensation.as_str() {
            "program" => KerfCompensation::InProgram,
            "g41.1" => KerfCompensation::ControllerDiameter,
            other => match other.strip_prefix("g41:").map(str::parse::<u32>) {
                Some(Ok(n)) => KerfCompensation::ControllerRegister(n),
                _ => {
                    return Err(format!(
                        "--kerf-compensation {other:?}: expected program, g41.1 or g41:N"
                    ))
                }
            },
        };
        // The controller of the preset in force must have the compensation code asked for.
        let preset = self
            .preset
            .map(|p| p.0)
            .or_else(|| profile?.gcode_preset.as_deref()?.parse().ok())
            .unwrap_or(cutroute_gcode::GcodePreset::Generic);
        preset
            .check_compensation(options.kerf_compensation)
            .map_err(|e| e.to_string())?;
        Ok(options)
    }
}

fn convert(
    (input, sheet, compensation): (&Path, usize, &gcode_input::CompensationArg),
    output: &Path,
    to: Option<&str>,
    solver: Option<&str>,
    params: SolverParams,
    gcode: &cutroute_gcode::GcodeOptions,
    kerf: &kerf::Kerf,
) -> Result<(), Failure> {
    let (document, read_s) = timed_open((input, sheet), compensation)?;
    warnings::print(&document.warnings);
    // The limit counts reading the file, as `solve`'s does.
    let mut params = params;
    params.time_limit_s = limit_after_reading(params.time_limit_s, read_s);
    Ok(convert_document(
        &document, input, output, to, solver, params, gcode, kerf,
    )?)
}

/// `convert` of an opened document.
#[allow(clippy::too_many_arguments)]
fn convert_document(
    document: &Document,
    input: &Path,
    output: &Path,
    to: Option<&str>,
    solver: Option<&str>,
    params: SolverParams,
    gcode: &cutroute_gcode::GcodeOptions,
    kerf: &kerf::Kerf,
) -> Result<(), String> {
    let Problem::Nest { nest, .. } = &document.problem else {
        return Err(format!(
            "{}: line 1 starts a PCGTSP instance, not a nest; only nests can be converted",
            input.display()
        ));
    };
    let name = output.to_string_lossy().to_lowercase();
    if stdio::is_standard(output) && to.is_none() {
        return Err("writing to standard output (-) needs --to dbs|json|svg|gcode|html".into());
    }
    let format = match to {
        Some(format) => format.to_string(),
        None => [
            (".dbs", "dbs"),
            (".json", "json"),
            (".svg", "svg"),
            (".nc", "gcode"),
            (".gcode", "gcode"),
            (".ngc", "gcode"),
            (".tap", "gcode"),
            (".html", "html"),
            (".htm", "html"),
        ]
        .iter()
        .find(|(extension, _)| name.ends_with(extension))
        .map(|(_, format)| format.to_string())
        .ok_or_else(|| {
            format!(
                "{}: unknown output extension (use .dbs, .dbs.json/.json, .svg, .nc/.gcode/.ngc/.tap, .html or --to)",
                output.display()
            )
        })?,
    };
    // The route of the G-code and HTML outputs: solved when asked, else the file's own.
    let routed = || -> Result<Routed, String> {
        match (solver, &document.route, &document.paths) {
            (None, _, Some(paths)) => Ok(Routed::Paths(paths.clone())),
            // A file's own route gets its leads here; a solved one has them from the job.
            (None, Some(route), None) => Ok(Routed::Contours(kerf.attach(nest, route.clone())?)),
            (name, ..) => solved(document, name.unwrap_or("ccp"), params.clone(), kerf),
        }
        .and_then(|routed| match routed {
            // A solved path route has its leads from the job; a file's own has none.
            Routed::Paths(paths)
                if kerf.is_on() && paths.paths.iter().any(|p| p.leads.is_none()) =>
            {
                Err("a file's own path route gets no leads: solve it with --solver sccp, gsccp or aoe".into())
            }
            routed => Ok(routed),
        })
    };
    let bytes: Vec<u8> = match format.as_str() {
        // DBS names are 8 CP866 characters: longer names are cut, others written as `?`.
        "dbs" => cutroute_formats::write_dbs_with(
            nest,
            &cutroute_formats::DbsWriteOptions {
                truncate_long_names: true,
            },
        )
        .map_err(|e| e.to_string())?,
        "json" => cutroute_formats::write_geometry_json(nest)
            .map_err(|e| e.to_string())?
            .into_bytes(),
        "svg" => match &document.route {
            Some(route) => {
                cutroute_formats::route_svg(nest, route, &cutroute_formats::SvgOptions::default())
                    .map_err(|e| e.to_string())?
            }
            None => {
                cutroute_formats::nest_svg(nest, None, &cutroute_formats::SvgOptions::default())
            }
        }
        .into_bytes(),
        "gcode" => match routed()? {
            Routed::Contours(route) => cutroute_gcode::route_gcode(nest, &route, gcode),
            Routed::Paths(paths) => cutroute_gcode::path_route_gcode(&paths, gcode),
        }
        .map_err(|e| e.to_string())?
        .into_bytes(),
        "html" => {
            let options = cutroute_formats::HtmlOptions {
                title: input
                    .file_name()
                    .map_or_else(|| "route".into(), |n| n.to_string_lossy().into_owned()),
                ..Default::default()
            };
            match routed()? {
                Routed::Contours(route) => cutroute_formats::route_html(nest, &route, &options)
                    .map_err(|e| e.to_string())?,
                Routed::Paths(paths) => cutroute_formats::toolpath_html(
                    nest,
                    &cutroute_geometry::Toolpath::from_path_route(&paths),
                    &[],
                    &options,
                ),
            }
            .into_bytes()
        }
        other => {
            return Err(format!(
                "unknown output format {other:?} (dbs, json, svg, gcode, html)"
            ))
        }
    };
    stdio::write_output(output, &bytes)?;
    // A nest format read back must give the nest written; what it does not is said.
    if matches!(format.as_str(), "dbs" | "json" | "svg") {
        warnings::print(&cutroute_engine::conversion_losses(
            nest,
            &output.to_string_lossy(),
            &bytes,
        ));
    }
    Ok(())
}

/// What a G-code or HTML output draws: a route of whole contours, or tool-on paths (segment
/// and common-edge cutting, G-code programs of open paths).
enum Routed {
    Contours(Route),
    Paths(PathRoute),
}

/// Routes the document's nest with the named solver; the best route found, checked.
fn solved(
    document: &Document,
    solver_name: &str,
    params: SolverParams,
    kerf: &kerf::Kerf,
) -> Result<Routed, String> {
    let Problem::Nest { nest, .. } = &document.problem else {
        return Err("only nests are routed".into());
    };
    let solver = solver_kind(solver_name)?;
    let request = JobRequest {
        job_id: 1,
        problem: document.problem.clone(),
        solver,
        params,
    };
    let forest = forest_in_background(&document.problem);
    let request = kerf.request(request, solver_name)?;
    let run = bounded_job_run(request, true)
        .map_err(|f| f.to_string())?
        .run;
    if let Some(paths) = run.last.as_ref().and_then(Progress::path_route).cloned() {
        // As `solve` checks path routes: a contour cut twice (standard cutting of common
        // edges) is allowed, nothing else.
        let problems = paths.problems(nest, nest.check_tolerance());
        if let Some(other) = problems
            .iter()
            .find(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
        {
            return Err(format!("the {solver_name} solver: invalid route: {other}"));
        }
        return Ok(Routed::Paths(paths));
    }
    kerf.refused(run.last.as_ref())?;
    checked_route(&run, nest, &joined_forest(forest, nest))
        .map(|(route, _)| Routed::Contours(route))
        .map_err(|e| format!("the {solver_name} solver: {e}"))
}

/// The solver a CLI name selects; "discrete" is the heuristic on a discretised nest.
fn solver_kind(name: &str) -> Result<SolverKind, String> {
    match name {
        "discrete" => Ok(SolverKind::Heuristic),
        name => SolverKind::from_name(name).ok_or_else(|| {
            let known: Vec<&str> = SolverKind::ALL.iter().map(|k| k.name()).collect();
            format!("unknown solver {name:?} ({}, discrete)", known.join(", "))
        }),
    }
}

/// Writes `generate_nest(contours, seed)` as geometry JSON.
fn generate(contours: usize, seed: u64, out: &Path) -> Result<(), String> {
    let nest = cutroute_geometry::generate_nest(contours, seed);
    let text = cutroute_formats::write_geometry_json(&nest).map_err(|e| e.to_string())?;
    stdio::write_output(out, text.as_bytes())
}

/// `solve` for every solver: one job run ([`bounded_job_run`]), then the report of the
/// solution's shape (a tour, a route of whole contours, or tool-on paths), each checked again
/// by the independent checker before it is printed.
fn solve(
    input: (&Path, usize, &gcode_input::CompensationArg),
    solver_name: &str,
    params: SolverParams,
    as_json: bool,
    thermal: &thermal::Thermal,
    kerf: &kerf::Kerf,
) -> Result<Report, Failure> {
    let solver = solver_kind(solver_name)?;
    // The limit counts reading the file: the solver gets what is left of it.
    let (document, read_s) = timed_open((input.0, input.1), input.2)?;
    warnings::print(&document.warnings);
    let user_limit_s = params.time_limit_s;
    let mut params = params;
    params.time_limit_s = limit_after_reading(user_limit_s, read_s);
    if solver.gives_path_route() && matches!(document.problem, Problem::PcgtspText { .. }) {
        return Err(Failure::Message(format!(
            "--solver {solver_name}: routes nests, not PCGTSP instances"
        )));
    }
    let (machine, objective) = (params.machine, params.objective);
    let request = JobRequest {
        job_id: 1,
        problem: document.problem.clone(),
        solver,
        params,
    };
    // The checker's forest of routes of whole contours (path routes are checked without it,
    // but a path solver with no route of its own answers with a route of whole contours).
    let forest = forest_in_background(&document.problem);
    let request = kerf.request(request, solver_name)?;
    thermal.warn_unpriced(solver);
    let started = std::time::Instant::now();
    let mut finished = bounded_job_run(request, as_json)?;
    // Messages name the limit the user gave.
    finished.run.time_limit_s = user_limit_s;
    // The report follows the solution's shape.
    let path_report = match finished.run.last.as_ref().and_then(|p| p.solution.as_ref()) {
        Some(solution) => solution.path_route().is_some(),
        None => solver.gives_path_route(),
    };
    let report = match &document.problem {
        Problem::PcgtspText { text } => Report::new(tour_report(solver_name, text, &finished.run)?),
        // Tool-on paths, or none from a path solver (its report says why).
        Problem::Nest { nest, .. } if path_report => {
            let report = PathReport {
                solver,
                solver_name,
                machine: &machine,
                objective,
                thermal,
                kerf,
                started,
            };
            report.of(nest, finished)?
        }
        Problem::Nest { nest, .. } => {
            let forest = joined_forest(forest, nest);
            let run = &mut finished.run;
            kerf.refused(run.last.as_ref())?;
            // With `--rules-hard`, the route repaired until the rules hold (and its
            // certificates recomputed): the report describes the route it prints.
            if let Some(last) = run.last.as_mut() {
                if let Some(Solution::Route(route)) = last.solution.take() {
                    let enforced = thermal.enforce(nest, route.clone(), &machine, objective)?;
                    if !last.certified.is_empty() {
                        let certified = cutroute_ccp::route_certificates(nest, &enforced)
                            .map_err(|e| Failure::Message(e.to_string()))?;
                        last.certified = certified.iter().map(|c| c.condition1).collect();
                    }
                    // The job's route has its leads; a route the repair changed gets them
                    // fitted again.
                    last.solution = Some(Solution::Route(if enforced != route {
                        kerf.attach_repaired(nest, enforced)?
                    } else {
                        enforced
                    }));
                }
            }
            let (mut report, mut steps) = route_report(solver_name, nest, &machine, run, &forest)?;
            if let Some(route) = run.last.as_ref().and_then(Progress::route) {
                thermal.report(&mut report, &mut steps, nest, route, &machine, objective)?;
                kerf.report(
                    &mut report,
                    &mut steps,
                    route,
                    run.last.as_ref().map(|p| &p.phase),
                );
            }
            Report::with_steps(report, &steps)?
        }
    };
    let mut report = report;
    if let Value::Object(fields) = &mut report.fields {
        // Apart from `elapsed_s` (the solver's run): how long opening the file took.
        fields.insert("read_s".into(), json!(read_s));
    }
    warnings::add_to(&mut report.fields, &document.warnings);
    Ok(report)
}

/// The document at `input` and how long opening it took (s).
fn timed_open(
    input: (&Path, usize),
    compensation: &gcode_input::CompensationArg,
) -> Result<(Document, f64), Failure> {
    let started = std::time::Instant::now();
    let document = open(input, compensation)?;
    Ok((document, started.elapsed().as_secs_f64()))
}

/// What is left of a limit of `limit_s` for the solver after `read_s` of reading (none left:
/// the solver gives the route a zero limit gives).
fn limit_after_reading(limit_s: f64, read_s: f64) -> f64 {
    if limit_s.is_finite() {
        (limit_s - read_s).max(0.0)
    } else {
        limit_s
    }
}

/// A solve report, to standard output or `out`: one JSON object, or its keys one per line
/// without the route or tour.
fn write_report(report: &Report, as_json: bool, out: Option<&Path>) -> Result<(), String> {
    let mut text = String::new();
    if as_json {
        text = report.to_json()? + "\n";
    } else {
        for (key, value) in report.fields.as_object().into_iter().flatten() {
            if key != "route" && key != "tour" {
                text.push_str(&format!("{key:>18}: {value}\n"));
            }
        }
    }
    stdio::write_output(out.unwrap_or(Path::new("-")), text.as_bytes())
}

fn machine_json(machine: &MachineParameters) -> Value {
    json!({
        "idle_speed": machine.idle_speed,
        "cut_speed": machine.cut_speed,
        "pierce_time": machine.pierce_time,
        "idle_price_per_metre": machine.idle_price_per_metre,
        "cut_price_per_metre": machine.cut_price_per_metre,
        "pierce_price": machine.pierce_price,
    })
}

/// The PCGTSP report: tour as 1-based node ids of the instance, starting at the depot, and
/// checked by `check_tour`. No tour is a failure: infeasibility when the exact search ended
/// without one (exit 3), else "none found" within the limit (exit 3 too: no tour to report).
fn tour_report(solver: &str, text: &str, run: &JobRun) -> Result<Value, Failure> {
    let instance = cutroute_pcgtsp::Instance::parse(text).map_err(|e| e.to_string())?;
    let Some(result) = &run.last else {
        return Err(Failure::Infeasible(format!(
            "--time-limit {}: the {solver} solver found no tour before it was stopped",
            run.time_limit_s
        )));
    };
    let Some(tour) = result.tour() else {
        let why = result.missing_tour(solver, run.stopped.is_some());
        return Err(Failure::Infeasible(why.unwrap_or_default()));
    };
    let cost = cutroute_pcgtsp::check_tour(&instance, tour)
        .map_err(|e| format!("the {solver} solver's tour fails the checker: {e}"))?;
    Ok(json!({
        "solver": solver,
        "ub": result.bounds.upper,
        "lb": result.bounds.lower,
        "gap": result.gap(),
        "proven_optimal": result.proven_optimal,
        "cost": cost,
        "tour": tour.iter().map(|n| n + 1).collect::<Vec<_>>(),
        "elapsed_s": result.elapsed_s,
        "states": result.states,
        "stopped": run.stopped,
    }))
}

/// The nest report: lengths recomputed from the route itself, not taken from the solver; time
/// and cost under `machine`. Cut length includes the tool-on links of chains (also reported
/// alone as `link_length`); a linked step lists its link's corners under `link`.
fn route_report(
    solver: &str,
    nest: &Nest,
    machine: &MachineParameters,
    run: &JobRun,
    forest: &ContainmentForest,
) -> Result<(Value, Vec<StepReport>), String> {
    let (route, final_route_rejected) = checked_route(run, nest, forest)?;
    let result = run.last.as_ref().ok_or("the solver found no route")?;
    let route = &route;
    let idle_length = route.idle_length();
    let cut_length = route.cut_length(nest);
    let pierces = route.pierce_count();
    // Edge and kerf pierces (`--edge-pierce`, `--kerf-pierce`) take the machine's edge-pierce
    // time.
    let time_s = machine.time(cut_length, idle_length, 0)
        + machine.pierce_seconds(
            pierces,
            route.edge_pierce_count() + route.kerf_pierce_count(),
        );
    let fields = json!({
        "solver": solver,
        "idle_length": idle_length,
        "cut_length": cut_length,
        "link_length": route.link_length(),
        "pierces": pierces,
        "time_s": time_s,
        "cost": machine.cost(cut_length, idle_length, pierces),
        "machine": machine_json(machine),
        // The steps, written apart (`Report::with_steps`).
        "route": null,
        "certified_contours": result.certified.iter().filter(|c| **c).count(),
        // In the job's unit: idle mm, or (chain) the route's cost.
        "ub": if final_route_rejected.is_some() {
            Some(match result.bounds.unit {
                CostUnit::Cost => machine.cost(cut_length, idle_length, pierces),
                _ => idle_length,
            })
        } else {
            result.bounds.upper
        },
        "lb": result.bounds.lower,
        "unit": result.bounds.unit,
        "gap": result.gap(),
        "proven_optimal": result.proven_optimal,
        "elapsed_s": result.elapsed_s,
        "final_route_rejected": final_route_rejected,
        // A solver with no route of its own, or a path solver whose own route failed the
        // checker, answers with this contour route.
        "fallback": run.fallback.clone().or_else(|| result
            .alternatives
            .iter()
            .find(|a| a.name == cutroute_engine::REJECTED_ROUTE)
            .and_then(|a| a.failure.clone())),
        "stopped": run.stopped,
    });
    let steps = route
        .steps
        .iter()
        .map(|s| StepReport {
            contour: [s.contour.part, s.contour.contour],
            pierce: Some([s.pierce_point.x, s.pierce_point.y]),
            link: match &s.entry {
                Entry::Link(corners) => Some(corners.iter().map(|c| [c.x, c.y]).collect()),
                _ => None,
            },
            ..StepReport::default()
        })
        .collect();
    Ok((fields, steps))
}

/// The report of a path route (sccp, gsccp, aoe: the engine's path-route jobs, the app's code
/// path). Its numbers are recomputed from the route, which must pass `PathRoute::problems` but
/// for contour cut twice (standard cutting of common edges, reported as `recut_length`); `ub`
/// and `lb` are the job's bounds in the objective's unit (s or cost); `idle_lb` is its lower
/// bound on idle length (mm) and `idle_gap` the route's `idle_length` against it.
struct PathReport<'a> {
    solver: SolverKind,
    solver_name: &'a str,
    machine: &'a MachineParameters,
    objective: Objective,
    thermal: &'a thermal::Thermal,
    /// The full route's settings: the job's paths carry their leads, printed per path.
    kerf: &'a kerf::Kerf,
    /// When the run started (the report's `elapsed_s` runs to the report).
    started: std::time::Instant,
}

impl PathReport<'_> {
    fn of(&self, nest: &Nest, finished: FinishedRun) -> Result<Report, Failure> {
        let (solver, solver_name, machine, objective) =
            (self.solver, self.solver_name, self.machine, self.objective);
        // Why the run ended early (the limit, Ctrl-C), as in a route's report; stopped in a
        // long step, the latest published state, without the job's own extras.
        let stopped = finished.run.stopped;
        let time_limit_s = finished.run.time_limit_s;
        let progress = finished.run.last.ok_or_else(|| {
            format!(
                "--time-limit {time_limit_s}: the {solver_name} solver found no route before it \
                 was stopped ({})",
                stopped.unwrap_or("")
            )
        })?;
        self.kerf.refused(Some(&progress))?;
        // Stopped by the limit while it still had no route (AOE building its plan graph): the
        // limit is what to change, so the message names it.
        let solver_route = progress
            .path_route()
            .ok_or_else(|| match finished.run.stopped {
                Some(why) => format!(
                    "--time-limit {time_limit_s}: the {solver_name} solver found no route before \
                     it was stopped ({why}; {})",
                    progress.phase
                ),
                None => format!("the solver found no route ({})", progress.phase),
            })?;
        // Hard rules: a route whose contour route breaks them is replaced by that route
        // repaired (standard cutting). Its ub is its own objective; AOE's lb assumed edges cut
        // once.
        let (repaired, failed) =
            match self
                .thermal
                .enforce_paths(nest, solver_route, machine, objective)
            {
                Ok(repaired) => (repaired, None),
                Err(e) => (None, Some(e)),
            };
        if self.kerf.is_on() && repaired.is_some() {
            return Err(Failure::Message(
                "the rule repair's route (whole contours, standard cutting) gets no leads yet: \
                 solve without --kerf or without the hard rules"
                    .into(),
            ));
        }
        let route = repaired.as_ref().unwrap_or(solver_route);
        let (ub, lb, phase) = match &repaired {
            None => (
                progress.bounds.upper,
                progress.bounds.lower,
                match failed {
                    Some(e) => format!("{} · rule repair failed ({e}); route kept", progress.phase),
                    None => progress.phase.to_string(),
                },
            ),
            Some(r) => (
                Some(objective.value(machine, r.cut_length(), r.idle_length(), r.pierce_count())),
                progress.bounds.lower.filter(|_| solver != SolverKind::Aoe),
                format!(
                    "{} · rules enforced on whole contours (standard cutting)",
                    progress.phase
                ),
            ),
        };
        // Checked again here, as every route the CLI prints.
        let tolerance = nest.check_tolerance();
        let problems = route.problems(nest, tolerance);
        if let Some(other) = problems
            .iter()
            .find(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
        {
            return Err(Failure::Message(format!("invalid route: {other}")));
        }
        let recut_length = cutroute_segments::recut_length(&problems, tolerance);
        let (idle_length, cut_length, pierces) = (
            route.idle_length(),
            route.cut_length(),
            route.pierce_count(),
        );
        // Edge pierces (`--edge-pierce`) take the machine's edge-pierce time.
        let time_s = machine.time(cut_length, idle_length, 0)
            + machine.pierce_seconds(pierces, route.edge_pierce_count());
        // The spans as text (see `report`): as values they took seconds on large routes.
        let (route_value, spans) = Report::path_route(route).map_err(Failure::Message)?;
        let mut report = json!({
            "solver": solver_name,
            "idle_length": idle_length,
            "cut_length": cut_length,
            "recut_length": recut_length,
            "pierces": pierces,
            "time_s": time_s,
            "cost": machine.cost(cut_length, idle_length, pierces),
            "objective": objective.name(),
            "machine": machine_json(machine),
            "route": route_value,
            "ub": ub,
            "lb": lb,
            // The idle bound holds for any route that cuts every contour, a repaired one too;
            // the gap is that of the printed route.
            "idle_lb": progress.idle_lower_bound,
            "idle_gap": progress
                .idle_lower_bound
                .map(|lb| if idle_length > 0.0 { ((idle_length - lb) / idle_length).max(0.0) } else { 0.0 }),
            "phase": phase,
            "elapsed_s": self.started.elapsed().as_secs_f64(),
            "stopped": stopped,
        });
        if let Value::Object(fields) = &mut report {
            fields.extend(finished.extras);
        }
        self.thermal
            .report_paths(&mut report, nest, route, machine, objective)?;
        self.kerf.report_paths(&mut report, route);
        Ok(Report::with_spans(report, spans))
    }
}

/// A number for JSON: `null` when not finite (an ensemble that gave no route).
fn finite(value: f64) -> Value {
    if value.is_finite() {
        json!(value)
    } else {
        Value::Null
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, ContourRef, CutStep, Part, Point, Vertex};

    /// The report's share of the limit grows with the nest (its estimate), never past a
    /// quarter of the limit, and is nothing for instances and unlimited runs.
    #[test]
    fn the_report_reserve_follows_the_nest_size() {
        let nest = |n: usize| Problem::Nest {
            nest: cutroute_geometry::generate_nest(n, 1),
            start: Point::new(0.0, 0.0),
            finish: None,
        };
        let big = nest(20_000);
        let contours = match &big {
            Problem::Nest { nest, .. } => nest.contour_count(),
            _ => unreachable!(),
        };
        let ccp = SolverKind::Ccp;
        let estimate = report_estimate_s(&big, ccp);
        assert!(estimate > 0.0 && estimate > 0.5 * report_estimate_s(&nest(10_000), ccp));
        assert!((report_reserve_s(&big, ccp, 5.0) - estimate).abs() < 1e-12);
        assert!(contours > 0);
        let tight = 2.0 * estimate;
        assert_eq!(report_reserve_s(&big, ccp, tight), tight / 4.0);
        assert_eq!(report_reserve_s(&big, ccp, f64::INFINITY), 0.0);
        assert!(report_reserve_s(&nest(50), ccp, 5.0) < 1e-3);
        // A path solver keeps more for its spans, never past half the limit.
        let sccp = SolverKind::Sccp;
        assert!(report_reserve_s(&big, sccp, 5.0) > report_reserve_s(&big, ccp, 5.0));
        assert_eq!(report_reserve_s(&big, sccp, tight), tight / 2.0);
        let instance = Problem::PcgtspText {
            text: String::new(),
        };
        assert_eq!(report_reserve_s(&instance, SolverKind::Sccp, 5.0), 0.0);
    }

    /// A solver with no route at its limit is waited for while its first route may still
    /// come within the promise (`route_wait`), and no longer.
    #[test]
    fn a_run_without_a_route_waits_for_its_first() {
        use std::time::Duration;
        let late_first_route = |watch: &Watch| -> Result<(), Failure> {
            std::thread::sleep(Duration::from_millis(150));
            watch.seen.lock().unwrap().first_route = Some(Progress::default());
            std::thread::sleep(Duration::from_secs(5));
            Ok(())
        };
        let started = std::time::Instant::now();
        let waited = run_bounded(
            0.01,
            (Duration::from_millis(20), Duration::from_secs(2)),
            late_first_route,
        );
        let Ok(Err(run)) = waited else {
            panic!("the run was not cut at its limit")
        };
        assert!(
            run.first_route.is_some(),
            "the first route was not waited for"
        );
        assert!(
            started.elapsed() < Duration::from_secs(2),
            "waited on after the route came"
        );
        let cut = run_bounded(
            0.01,
            (Duration::from_millis(20), Duration::ZERO),
            late_first_route,
        );
        let Ok(Err(run)) = cut else {
            panic!("the run was not cut at its limit")
        };
        assert!(
            run.first_route.is_none(),
            "waited past the grace without a route wait"
        );
    }

    fn square(x: f64) -> Contour {
        Contour::new(vec![
            Vertex::line(x, 0.0),
            Vertex::line(x, 10.0),
            Vertex::line(x + 10.0, 10.0),
            Vertex::line(x + 10.0, 0.0),
        ])
    }

    fn route(parts: &[usize]) -> Route {
        Route {
            start: Point::new(0.0, 0.0),
            steps: parts
                .iter()
                .map(|&part| {
                    CutStep::pierced(
                        ContourRef { part, contour: 0 },
                        Point::new(part as f64 * 20.0, 0.0),
                    )
                })
                .collect(),
            finish: None,
        }
    }

    fn run_ending_with(last: Route, earlier: Vec<Route>) -> JobRun {
        JobRun {
            last: Some(Progress {
                solution: Some(Solution::Route(last)),
                ..Progress::default()
            }),
            earlier_routes: earlier,
            time_limit_s: 1.0,
            ..JobRun::default()
        }
    }

    /// The CLI's words stay those of the engine, and the engine's error stays the source.
    #[test]
    fn an_engine_refusal_keeps_its_words_and_its_source() {
        use cutroute_engine::{EngineError, Refusal};
        use cutroute_protocol::ThermalSettingsError;
        let refusal = || EngineError::SolverRefused {
            solver: "exact",
            reason: Refusal::ThermalSettings(ThermalSettingsError::Weight(-1.0)),
        };
        let failure = Failure::Engine {
            solver: "exact",
            source: refusal(),
        };
        assert_eq!(
            failure.to_string(),
            "--solver exact: exact: thermal weight -1: must be finite and non-negative"
        );
        let source = std::error::Error::source(&failure).expect("a source");
        assert_eq!(source.downcast_ref::<EngineError>(), Some(&refusal()));
        assert!(std::error::Error::source(source).is_some());
    }

    /// Item 13 of issue #15: a final route that fails the checker never hides a valid one.
    #[test]
    fn a_failing_final_route_gives_way_to_the_newest_valid_earlier_route() {
        let nest = Nest {
            sheet: None,
            parts: (0..2)
                .map(|i| Part {
                    name: format!("P{i}"),
                    contours: vec![square(i as f64 * 20.0)],
                })
                .collect(),
        };
        let forest = nest.containment_forest();
        let valid = route(&[0, 1]);
        let (chosen, rejected) =
            checked_route(&run_ending_with(valid.clone(), vec![]), &nest, &forest).unwrap();
        assert_eq!((chosen, rejected), (valid.clone(), None));

        let invalid = route(&[0]); // part 1 never cut
        let run = run_ending_with(invalid.clone(), vec![route(&[1]), valid.clone()]);
        let (chosen, rejected) = checked_route(&run, &nest, &forest).unwrap();
        assert_eq!(chosen, valid);
        assert!(rejected.unwrap().starts_with("invalid route"));

        // Nothing valid at all: a clear error, never the invalid route.
        let run = run_ending_with(invalid.clone(), vec![route(&[1])]);
        assert!(checked_route(&run, &nest, &forest)
            .unwrap_err()
            .starts_with("invalid route"));
    }
}
