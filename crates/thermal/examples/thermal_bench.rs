//! The heat penalty and the hard rules on every real nest of `data/nests`: CCP-Relax with
//! σ, τ and weight W against plain CCP (weight 0, H reported with the same σ, τ), and the
//! heated route repaired by `enforce_rules` and relaxed among the admissible pierce points (as
//! `--rules-hard` does). Prints a Markdown table for BENCHMARKS.md.
//!
//! `cargo run --release -p cutroute-thermal --example thermal_bench -- [--seconds S]
//! [--sigma MM] [--tau S] [--weight W] [--filter A,B]`

use std::time::Duration;

use cutroute_ccp::{CcpSolver, HeatPenalty};
use cutroute_engine::{ccp_options, run_to_end, start_job, CcpJob};
use cutroute_geometry::{MachineParameters, Nest, Objective, Route};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};
use cutroute_thermal::{
    admissible_pierce_points, check_rules, enforce_rules, relax_pierce_points, HeatModel,
    RuleParams, RuleSet,
};

#[path = "../../chains/examples/support/nest_files.rs"]
mod nest_files;

use nest_files::{nest_files, read_nest};

/// The DXF drawings of `data/nests/dxf` (the other folders come from `nest_files`).
fn dxf_files() -> Vec<String> {
    let root = format!("{}/../../data/nests/dxf", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<String> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("missing data folder {root}: {e}"))
        .map(|e| {
            format!(
                "{root}/{}",
                e.expect("readable").file_name().to_string_lossy()
            )
        })
        .collect();
    names.sort();
    names
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let number = |flag: &str, default: f64| value(flag).map_or(default, |v| v.parse().expect(flag));
    let seconds = number("--seconds", 3.0);
    let model = HeatModel::new(number("--sigma", 50.0), number("--tau", 60.0)).expect("σ, τ");
    let weight = number("--weight", 100.0);
    let filter: Option<Vec<String>> =
        value("--filter").map(|v| v.split(',').map(str::to_string).collect());
    let machine = MachineParameters::default();
    let rules = RuleParams::default();
    println!("| nest | contours | H plain | H heated | H change | idle mm plain → heated | time s plain → heated | violations plain p/s/i | hard: H | hard: idle mm | hard: time s | hard: left p/s/i | hard: checker |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut files = nest_files();
    files.extend(dxf_files());
    for path in files {
        if filter
            .as_ref()
            .is_some_and(|f| !f.iter().any(|x| path.contains(x.as_str())))
        {
            continue;
        }
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        // DXF drawings that do not close into contours are not nests.
        if cutroute_engine::open_document(&path, &bytes).is_err() {
            continue;
        }
        let (nest, start, finish) = read_nest(&path);
        // H needs two pierces.
        if nest.contour_count() < 2 {
            continue;
        }
        let problem = Problem::Nest {
            nest: nest.clone(),
            start,
            finish,
        };
        let params = SolverParams {
            time_limit_s: seconds,
            ..SolverParams::default()
        };
        let plain = solve(&problem, &params, None);
        let options = ccp_options(
            start,
            finish,
            Duration::from_secs_f64(seconds),
            params.seed,
            params.machine,
        );
        let heat = HeatPenalty {
            model,
            weight,
            objective: Objective::Time,
        };
        let heated = solve(&problem, &params, Some((options, heat)));
        // What `--rules-hard` does: repair, then relax the pierce points on the penalised
        // objective among those the part rule admits.
        let repaired = enforce_rules(&nest, &heated, RuleSet::ALL, &rules)
            .expect("valid route")
            .route;
        let admissible = admissible_pierce_points(&nest, &repaired, &rules).expect("valid route");
        let hard = relax_pierce_points(
            &nest,
            &repaired,
            &machine,
            &model,
            heat.weight_mm(&machine),
            3,
            Some(&admissible),
        )
        .expect("valid route");
        let load = |r: &Route| model.route_load(r, &nest, &machine).expect("valid route");
        let time = |r: &Route| r.time(&nest, &machine);
        let counts = |r: &Route| {
            let c = check_rules(&nest, r, RuleSet::ALL, &rules)
                .expect("valid route")
                .counts();
            format!(
                "{}/{}/{}",
                c.part.unwrap_or(0),
                c.sheet.unwrap_or(0),
                c.islands.unwrap_or(0)
            )
        };
        let forest = nest.containment_forest();
        let problems = hard.problems(&nest, &forest, 1e-6 * scale(&nest)).len();
        let (h0, h1) = (load(&plain), load(&heated));
        println!(
            "| {} | {} | {:.4} | {:.4} | {} | {:.0} → {:.0} | {:.0} → {:.0} ({:+.2} %) | {} | {:.4} | {:.0} | {:.0} | {} | {} |",
            path.rsplit('/').next().unwrap_or(&path),
            nest.contour_count(),
            h0,
            h1,
            if h0 > 0.0 {
                format!("{:+.1} %", 100.0 * (h1 - h0) / h0)
            } else {
                "—".into()
            },
            plain.idle_length(),
            heated.idle_length(),
            time(&plain),
            time(&heated),
            100.0 * (time(&heated) - time(&plain)) / time(&plain),
            counts(&plain),
            load(&hard),
            hard.idle_length(),
            time(&hard),
            counts(&hard),
            if problems == 0 { "ok" } else { "FAILS" },
        );
    }
}

/// CCP-Relax through the engine's slices: plain (the engine's own job) or with the penalty.
fn solve(
    problem: &Problem,
    params: &SolverParams,
    heated: Option<(cutroute_ccp::CcpOptions, HeatPenalty)>,
) -> Route {
    let Problem::Nest { nest, .. } = problem else {
        unreachable!("nests only")
    };
    let mut job: Box<dyn cutroute_engine::Job> = match heated {
        None => start_job(&JobRequest {
            job_id: 1,
            problem: problem.clone(),
            solver: SolverKind::Ccp,
            params: params.clone(),
        })
        .expect("CCP starts"),
        Some((mut options, heat)) => {
            options.heat = Some(heat);
            Box::new(CcpJob::new(
                1,
                CcpSolver::new(nest, options).expect("valid options"),
            ))
        }
    };
    let route = run_to_end(job.as_mut(), &mut |_| {})
        .route()
        .cloned()
        .expect("CCP found a route");
    route
        .validate(nest, 1e-6 * scale(nest))
        .expect("CCP's route is valid");
    route
}

fn scale(nest: &Nest) -> f64 {
    let b = nest.bounding_box();
    ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0)
}
