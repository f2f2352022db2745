//! `cutroute`: inspect, convert and route cutting plans and PCGTSP instances from the shell.
//!
//! ```text
//! cutroute inspect FILE [--json]
//! cutroute convert IN OUT [--to dbs|json|svg|gcode|html]   # default: by OUT's extension
//!                  [--solver nearest|ccp|heuristic|discrete] [--time-limit S] [--seed N] [--step MM]
//!                  [--incremental] [--arcs ij|r|lines] [--decimals N] [--line-numbers]
//!                  [--feed MM_PER_MIN] [--dwell S] [--torch-on CODE] [--torch-off CODE]
//! cutroute generate --contours N [--seed S] --out FILE   # synthetic nest as geometry JSON
//! cutroute solve FILE --solver nearest|ccp|heuristic|exact|discrete|chain|aoe|sccp|gsccp
//!                     [--time-limit S] [--seed N] [--ub N] [--step MM] [--cost C_off,C_on,C_pt]
//!                     [--speeds V_off,V_on,t_pt] [--task TASK.json] [--objective time|cost]
//!                     [--thermal-sigma MM] [--thermal-tau S] [--thermal-weight W]
//!                     [--rules part,sheet,islands] [--rules-hard] [--json]
//!                     [--kerf MM] [--pierce-clearance MM] [--switch-off-clearance MM]
//!                     [--lead-in arc|line|line-arc|none] [--lead-in-length MM]
//!                     [--lead-out arc|line|line-arc|none] [--lead-out-length MM]
//!                     [--overcut MM] [--leads-after]   # also on convert
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
//! nearest, ccp and chain minimise objective + W·H, `--rules-hard` repairs the route until the rules hold.
//! With `--kerf`/leads on (`kerf.rs`), nearest, ccp, heuristic and discrete optimise the full
//! route (pierce points off the contours, leads, cut on the equidistants) and each route step
//! carries `pierce` (M), `entry`, `lead_in`, `lead_out` and `switch_off`.
//! Errors go to stderr with the reader's location, and the exit code is 1.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use cutroute_engine::{open_document, run_to_end, start_job, AoeJob, SegmentJob};
use cutroute_geometry::{Entry, MachineParameters, Nest, Objective, PathRoute, Route};
use cutroute_protocol::{Document, JobRequest, Problem, Progress, SolverKind, SolverParams};
use serde_json::{json, Value};

mod kerf;
mod thermal;

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
        /// The file to read.
        file: PathBuf,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Convert a nest between formats (.dbs, .json, .svg), or route it and write the route as
    /// G-code (.nc, .gcode, .ngc, .tap) or a standalone HTML page (.html).
    Convert {
        /// The file to read (any supported nest format).
        input: PathBuf,
        /// The file to write.
        output: PathBuf,
        /// Output format: dbs, json, svg, gcode or html (default: from the output's extension).
        #[arg(long)]
        to: Option<String>,
        /// Solver of the route for gcode/html: nearest, ccp, heuristic or discrete (default: the
        /// route the file holds, else ccp).
        #[arg(long)]
        solver: Option<String>,
        /// Wall-clock limit of the solver, seconds.
        #[arg(long, default_value_t = 10.0)]
        time_limit: f64,
        /// Seed of the solver's random choices.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Spacing of candidate pierce points for the discrete solvers, mm.
        #[arg(long, default_value_t = 50.0)]
        step: f64,
        #[command(flatten)]
        gcode: GcodeArgs,
        #[command(flatten)]
        kerf: kerf::KerfArgs,
    },
    /// Write a seeded synthetic nest (geometry JSON) for tests and benchmarks.
    Generate {
        /// Number of contours.
        #[arg(long)]
        contours: usize,
        /// Seed of the generator.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The file to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Route a nest or solve a PCGTSP instance.
    Solve {
        /// A nest file or a PCGTSP instance.
        file: PathBuf,
        /// nearest, ccp, heuristic, exact, discrete (= heuristic on a discretised nest),
        /// chain (ccp, then chain cutting), aoe (common edges cut once along AOE-chains),
        /// sccp (segment cutting along the plan's common edges) or gsccp (the best of several
        /// segment ensembles).
        #[arg(long, default_value = "ccp")]
        solver: String,
        /// Wall-clock limit in seconds.
        #[arg(long, default_value_t = 10.0)]
        time_limit: f64,
        /// Seed of the solver's random choices.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// A known upper bound (exact solver).
        #[arg(long)]
        ub: Option<f64>,
        /// Spacing of candidate pierce points for the discrete solvers on nests, mm.
        #[arg(long, default_value_t = 50.0)]
        step: f64,
        /// Prices: idle travel per metre, cut per metre, one pierce (C_off,C_on,C_pt).
        #[arg(long, value_name = "C_off,C_on,C_pt")]
        cost: Option<String>,
        /// Idle speed and cutting speed (mm/s) and pierce time (s): V_off,V_on,t_pt.
        #[arg(long, value_name = "V_off,V_on,t_pt")]
        speeds: Option<String>,
        /// A RouteManager task JSON whose speeds and pierce time are the defaults.
        #[arg(long)]
        task: Option<PathBuf>,
        /// What gsccp minimises when it picks an ensemble, and the unit of the path-route
        /// solvers' (sccp, gsccp, aoe) bounds: time or cost.
        #[arg(long, default_value = "time")]
        objective: String,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        thermal: thermal::ThermalArgs,
        #[command(flatten)]
        kerf: kerf::KerfArgs,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Inspect { file, json } => inspect(&file, json),
        Command::Convert {
            input,
            output,
            to,
            solver,
            time_limit,
            seed,
            step,
            gcode,
            kerf,
        } => kerf.parse().and_then(|kerf| {
            let params = SolverParams {
                time_limit_s: time_limit,
                seed,
                discretisation_step_mm: step,
                initial_upper_bound: None,
                machine: Default::default(),
                objective: Default::default(),
            };
            convert(
                &input,
                &output,
                to.as_deref(),
                solver.as_deref(),
                params,
                &gcode,
                &kerf,
            )
        }),
        Command::Generate {
            contours,
            seed,
            out,
        } => generate(contours, seed, &out),
        Command::Solve {
            file,
            solver,
            time_limit,
            seed,
            ub,
            step,
            cost,
            speeds,
            task,
            objective,
            json,
            thermal,
            kerf,
        } => machine_parameters(cost.as_deref(), speeds.as_deref(), task.as_deref()).and_then(
            |machine| {
                let thermal = thermal.parse()?;
                let kerf = kerf.parse()?;
                let objective = match objective.as_str() {
                    "time" => Objective::Time,
                    "cost" => Objective::Cost,
                    other => return Err(format!("--objective {other:?}: expected time or cost")),
                };
                let params = SolverParams {
                    time_limit_s: time_limit,
                    seed,
                    discretisation_step_mm: step,
                    initial_upper_bound: ub,
                    machine,
                    objective,
                };
                match solver.as_str() {
                    "sccp" | "gsccp" | "aoe" if kerf.is_on() => Err(format!(
                        "--solver {solver} does not cut with kerf and leads yet"
                    )),
                    "sccp" | "gsccp" | "aoe" => solve_path(&file, &solver, params, json, &thermal),
                    _ => solve(&file, &solver, params, json, &thermal, &kerf),
                }
            },
        ),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("cutroute: {message}");
            ExitCode::FAILURE
        }
    }
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

/// The time and cost model: defaults, then the task file's speeds, then the flags.
fn machine_parameters(
    cost: Option<&str>,
    speeds: Option<&str>,
    task: Option<&Path>,
) -> Result<MachineParameters, String> {
    let mut machine = MachineParameters::default();
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

fn open(path: &Path) -> Result<Document, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path.display().to_string();
    open_document(&name, &bytes).map_err(|e| e.to_string())
}

fn inspect(path: &Path, as_json: bool) -> Result<(), String> {
    let document = open(path)?;
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
    if as_json {
        println!("{summary}");
    } else {
        for (key, value) in summary.as_object().into_iter().flatten() {
            println!("{key:>16}: {value}");
        }
        for warning in &document.warnings {
            println!("         warning: {warning}");
        }
    }
    Ok(())
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
    /// Incremental coordinates (G91) instead of absolute (G90).
    #[arg(long)]
    incremental: bool,
    /// Arcs as G02/G03 with I/J ("ij"), with R ("r"), or as G01 chords ("lines").
    #[arg(long, default_value = "ij")]
    arcs: String,
    /// Largest chord deviation of --arcs lines, mm.
    #[arg(long, default_value_t = 0.01)]
    chord_tolerance: f64,
    /// Decimals of coordinates.
    #[arg(long, default_value_t = 3)]
    decimals: usize,
    /// Number the lines (N10, N20, …).
    #[arg(long)]
    line_numbers: bool,
    /// Cutting feed rate, mm/min (default: the machine's cutting speed).
    #[arg(long)]
    feed: Option<f64>,
    /// Pierce dwell, seconds (default: the machine's pierce time).
    #[arg(long)]
    dwell: Option<f64>,
    /// Torch-on line.
    #[arg(long, default_value = "M03")]
    torch_on: String,
    /// Torch-off line.
    #[arg(long, default_value = "M05")]
    torch_off: String,
}

impl GcodeArgs {
    fn options(&self) -> Result<cutroute_gcode::GcodeOptions, String> {
        use cutroute_gcode::{ArcOutput, DistanceMode, GcodeOptions};
        let defaults = GcodeOptions::default();
        let arcs = match self.arcs.as_str() {
            "ij" => ArcOutput::CentreOffsets,
            "r" => ArcOutput::Radius,
            "lines" => ArcOutput::Lines {
                tolerance_mm: self.chord_tolerance,
            },
            other => return Err(format!("unknown --arcs {other:?} (ij, r, lines)")),
        };
        Ok(GcodeOptions {
            distance_mode: if self.incremental {
                DistanceMode::Incremental
            } else {
                DistanceMode::Absolute
            },
            arcs,
            decimals: self.decimals,
            line_numbers: self.line_numbers,
            cut_feed_mm_per_min: self.feed.unwrap_or(defaults.cut_feed_mm_per_min),
            pierce_dwell_s: self.dwell.unwrap_or(defaults.pierce_dwell_s),
            torch_on: self.torch_on.clone(),
            torch_off: self.torch_off.clone(),
            ..defaults
        })
    }
}

fn convert(
    input: &Path,
    output: &Path,
    to: Option<&str>,
    solver: Option<&str>,
    params: SolverParams,
    gcode: &GcodeArgs,
    kerf: &kerf::Kerf,
) -> Result<(), String> {
    let document = open(input)?;
    let Problem::Nest { nest, .. } = &document.problem else {
        return Err(format!(
            "{}: not a nest; only nests can be converted",
            input.display()
        ));
    };
    let name = output.to_string_lossy().to_lowercase();
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
            (None, Some(route), None) => Ok(Routed::Contours(route.clone())),
            (name, ..) => solved(&document, name.unwrap_or("ccp"), params.clone(), kerf),
        }
        .and_then(|routed| match routed {
            Routed::Contours(route) if kerf.is_on() => Ok(Routed::Contours(
                kerf.attach(nest, kerf.project(nest, route))?,
            )),
            Routed::Paths(_) if kerf.is_on() => {
                Err("path routes (sccp, gsccp, aoe) do not cut with kerf and leads yet".into())
            }
            routed => Ok(routed),
        })
    };
    let bytes: Vec<u8> = match format.as_str() {
        "dbs" => cutroute_formats::write_dbs(nest).map_err(|e| e.to_string())?,
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
        "gcode" => {
            let options = gcode.options()?;
            match routed()? {
                Routed::Contours(route) => cutroute_gcode::route_gcode(nest, &route, &options),
                Routed::Paths(paths) => cutroute_gcode::path_route_gcode(&paths, &options),
            }
            .map_err(|e| e.to_string())?
            .into_bytes()
        }
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
    std::fs::write(output, bytes).map_err(|e| format!("{}: {e}", output.display()))
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
    let request = kerf.request(request, solver_name)?;
    let mut job = start_job(&request).map_err(|e| e.to_string())?;
    let progress = run_to_end(job.as_mut(), &mut |_| {});
    let tolerance = 1e-6 * nest_scale(nest);
    match (progress.route, progress.path_route) {
        (Some(route), _) => {
            let route = kerf.project(nest, route);
            route
                .validate(nest, tolerance)
                .map_err(|e| format!("invalid route: {e}"))?;
            Ok(Routed::Contours(route))
        }
        (None, Some(paths)) => {
            // As `solve` checks path routes: a contour cut twice (standard cutting of common
            // edges) is allowed, nothing else.
            let problems = paths.problems(nest, tolerance);
            if let Some(other) = problems
                .iter()
                .find(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
            {
                return Err(format!("invalid route: {other}"));
            }
            Ok(Routed::Paths(paths))
        }
        (None, None) => Err(format!("the {solver_name} solver found no route")),
    }
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
    std::fs::write(out, text).map_err(|e| format!("{}: {e}", out.display()))
}

fn solve(
    path: &Path,
    solver_name: &str,
    params: SolverParams,
    as_json: bool,
    thermal: &thermal::Thermal,
    kerf: &kerf::Kerf,
) -> Result<(), String> {
    let document = open(path)?;
    let solver = solver_kind(solver_name)?;
    let (machine, objective) = (params.machine, params.objective);
    let request = JobRequest {
        job_id: 1,
        problem: document.problem.clone(),
        solver,
        params,
    };
    let request = kerf.request(request, solver_name)?;
    let mut job = match thermal.heated_job(&request)? {
        Some(job) => job,
        None => start_job(&request).map_err(|e| e.to_string())?,
    };
    let mut result = run_to_end(job.as_mut(), &mut progress_printer(as_json));
    let report = match &document.problem {
        Problem::PcgtspText { .. } => tour_report(solver_name, &result),
        Problem::Nest { nest, .. } => {
            if let Some(route) = result.route.take() {
                let route = kerf.project(nest, route);
                let route = thermal.enforce(nest, route, &machine, objective)?;
                if !result.certified.is_empty() {
                    // Certificates of the route reported, not of the one before the repair.
                    let certified = cutroute_ccp::route_certificates(nest, &route)
                        .map_err(|e| e.to_string())?;
                    result.certified = certified.iter().map(|c| c.condition1).collect();
                }
                result.route = Some(kerf.attach(nest, route)?);
            }
            let mut report = route_report(solver_name, nest, &machine, &result)?;
            if let Some(route) = &result.route {
                thermal.report(&mut report, nest, route, &machine, objective)?;
                kerf.report(&mut report, route);
            }
            report
        }
    };
    print_report(&report, as_json);
    Ok(())
}

/// A solve report: one JSON object, or its keys one per line without the route or tour.
fn print_report(report: &Value, as_json: bool) {
    if as_json {
        println!("{report}");
    } else {
        for (key, value) in report.as_object().into_iter().flatten() {
            if key != "route" && key != "tour" {
                println!("{key:>18}: {value}");
            }
        }
    }
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

fn fmt(value: Option<f64>) -> String {
    value
        .map(|v| format!("{v:.1}"))
        .unwrap_or_else(|| "—".into())
}

/// The PCGTSP report: tour as 1-based node ids of the instance, starting at the depot.
fn tour_report(solver: &str, result: &Progress) -> Value {
    json!({
        "solver": solver,
        "ub": result.upper_bound,
        "lb": result.lower_bound,
        "gap": result.gap(),
        "proven_optimal": result.proven_optimal,
        "tour": result.tour.as_ref().map(|t| t.iter().map(|n| n + 1).collect::<Vec<_>>()),
        "elapsed_s": result.elapsed_s,
        "states": result.states,
    })
}

/// The nest report: lengths recomputed from the route itself, not taken from the solver; time
/// and cost under `machine`. Cut length includes the tool-on links of chains (also reported
/// alone as `link_length`); a linked step lists its link's corners under `link`.
fn route_report(
    solver: &str,
    nest: &Nest,
    machine: &MachineParameters,
    result: &Progress,
) -> Result<Value, String> {
    let route: &Route = result.route.as_ref().ok_or("the solver found no route")?;
    route
        .validate(nest, 1e-6 * nest_scale(nest))
        .map_err(|e| format!("invalid route: {e}"))?;
    let idle_length = route.idle_length();
    let cut_length = route.cut_length(nest);
    let pierces = route.pierce_count();
    Ok(json!({
        "solver": solver,
        "idle_length": idle_length,
        "cut_length": cut_length,
        "link_length": route.link_length(),
        "pierces": pierces,
        "time_s": machine.time(cut_length, idle_length, pierces),
        "cost": machine.cost(cut_length, idle_length, pierces),
        "machine": machine_json(machine),
        "route": route.steps.iter().map(|s| {
            let mut step = json!({
                "contour": [s.contour.part, s.contour.contour],
                "pierce": [s.pierce_point.x, s.pierce_point.y],
            });
            if let Entry::Link(corners) = &s.entry {
                step["link"] = json!(corners.iter().map(|c| [c.x, c.y]).collect::<Vec<_>>());
            }
            step
        }).collect::<Vec<_>>(),
        "certified_contours": result.certified.iter().filter(|c| **c).count(),
        "ub": result.upper_bound,
        "lb": result.lower_bound,
        "gap": result.gap(),
        "proven_optimal": result.proven_optimal,
        "elapsed_s": result.elapsed_s,
    }))
}

fn nest_scale(nest: &Nest) -> f64 {
    let b = nest.bounding_box();
    ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0)
}

/// Prints a progress line to stderr about once a second (text mode only).
fn progress_printer(as_json: bool) -> impl FnMut(&Progress) {
    let mut last_report = -1.0;
    move |progress: &Progress| {
        if !as_json && progress.elapsed_s - last_report >= 1.0 {
            last_report = progress.elapsed_s;
            eprintln!(
                "{:8.2} s  ub {:>12}  lb {:>12}  {}",
                progress.elapsed_s,
                fmt(progress.upper_bound),
                fmt(progress.lower_bound),
                progress.phase
            );
        }
    }
}

/// `--solver sccp|gsccp|aoe`: the engine's path-route jobs (the app's code path), stepped to
/// their end. sccp solves the multi-contour chain ensemble alone, gsccp every ensemble,
/// keeping the best by `--objective`; aoe cuts common edges once along AOE-chains. The
/// report's numbers are recomputed from the route, which must pass `PathRoute::problems` but
/// for contour cut twice (standard cutting of common edges, reported as `recut_length`);
/// `ub` and `lb` are the job's bounds in the objective's unit (s or cost).
fn solve_path(
    path: &Path,
    solver_name: &str,
    params: SolverParams,
    as_json: bool,
    thermal: &thermal::Thermal,
) -> Result<(), String> {
    let document = open(path)?;
    let Problem::Nest { nest, .. } = &document.problem else {
        return Err(format!(
            "the {solver_name} solver routes nests, not PCGTSP instances"
        ));
    };
    let solver = solver_kind(solver_name)?;
    if solver != SolverKind::Aoe && !(params.time_limit_s.is_finite() && params.time_limit_s > 0.0)
    {
        return Err(format!(
            "--time-limit {}: must be a positive number of seconds",
            params.time_limit_s
        ));
    }
    let machine = params.machine;
    let objective = params.objective;
    let request = JobRequest {
        job_id: 1,
        problem: document.problem.clone(),
        solver,
        params,
    };
    let started = std::time::Instant::now();
    let mut on_progress = progress_printer(as_json);
    let mut extra = serde_json::Map::new();
    let progress = if solver == SolverKind::Aoe {
        let mut job = AoeJob::from_request(&request).map_err(|e| e.to_string())?;
        let progress = run_to_end(&mut job, &mut on_progress);
        let (solution, _) = match job.outcome() {
            Some(Ok(solved)) => solved,
            Some(Err(e)) => return Err(e.clone()),
            None => return Err("the aoe job did not run".into()),
        };
        extra.insert(
            "pierce_lower_bound".into(),
            json!(solution.pierce_lower_bound),
        );
        extra.insert("components".into(), json!(solution.components));
        progress
    } else {
        let mut job = SegmentJob::from_request(&request).map_err(|e| e.to_string())?;
        let progress = run_to_end(&mut job, &mut on_progress);
        let result = job.search().result().map_err(|e| e.to_string())?;
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
                    "failure": r.failure,
                }))
                .collect::<Vec<_>>()),
        );
        extra.insert(
            "ccp".into(),
            json!({
                "idle_length": result.ccp_route.idle_length(),
                "cut_length": result.ccp_route.cut_length(),
                "pierces": result.ccp_route.pierce_count(),
                "time_s": result.ccp_route.time(&machine),
                "cost": result.ccp_route.cost(&machine),
            }),
        );
        progress
    };
    let route = progress
        .path_route
        .as_ref()
        .ok_or_else(|| format!("the solver found no route ({})", progress.phase))?;
    // Checked again here, as every route the CLI prints.
    let tolerance = 1e-6 * nest_scale(nest);
    let problems = route.problems(nest, tolerance);
    if let Some(other) = problems
        .iter()
        .find(|p| !matches!(p, cutroute_geometry::PathRouteError::Overlap { .. }))
    {
        return Err(format!("invalid route: {other}"));
    }
    let recut_length = cutroute_segments::recut_length(&problems, tolerance);
    let (idle_length, cut_length, pierces) = (
        route.idle_length(),
        route.cut_length(),
        route.pierce_count(),
    );
    let mut report = json!({
        "solver": solver_name,
        "idle_length": idle_length,
        "cut_length": cut_length,
        "recut_length": recut_length,
        "pierces": pierces,
        "time_s": machine.time(cut_length, idle_length, pierces),
        "cost": machine.cost(cut_length, idle_length, pierces),
        "objective": objective.name(),
        "machine": machine_json(&machine),
        "route": serde_json::to_value(route).map_err(|e| e.to_string())?,
        "ub": progress.upper_bound,
        "lb": progress.lower_bound,
        "phase": progress.phase,
        "elapsed_s": started.elapsed().as_secs_f64(),
    });
    if let Value::Object(fields) = &mut report {
        fields.extend(extra);
    }
    thermal.report_paths(&mut report, route, &machine);
    print_report(&report, as_json);
    Ok(())
}

/// A number for JSON: `null` when not finite (an ensemble that gave no route).
fn finite(value: f64) -> Value {
    if value.is_finite() {
        json!(value)
    } else {
        Value::Null
    }
}
