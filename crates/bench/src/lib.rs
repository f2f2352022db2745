//! Shared helpers of the benchmark commands in `src/bin/` (each prints a Markdown table for
//! `BENCHMARKS.md`): reading `reference.csv`, and CPU clocks for shared machines.
//!
//! ```
//! assert_eq!(cutroute_bench::csv_fields(r#"a,"1,2",b"#), ["a", "1,2", "b"]);
//! ```
#![deny(missing_docs)]

/// Splits a CSV line, honouring double quotes (the tour column of `reference.csv` holds commas).
pub fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            _ => field.push(ch),
        }
    }
    fields.push(field);
    fields
}

/// CPU time (user + system) in seconds of a `/proc` stat file (`NaN` where there is none):
/// benchmark machines are often shared, so CPU time is reported beside wall time.
fn proc_cpu_seconds(stat_path: &str) -> f64 {
    std::fs::read_to_string(stat_path)
        .ok()
        .and_then(|stat| {
            // Fields 14 and 15 of stat(5), counted after the parenthesised name.
            let after = stat.rsplit_once(')')?.1;
            let fields: Vec<&str> = after.split_whitespace().collect();
            let user: f64 = fields.get(11)?.parse().ok()?;
            let system: f64 = fields.get(12)?.parse().ok()?;
            Some((user + system) / 100.0)
        })
        .unwrap_or(f64::NAN)
}

/// CPU seconds used by this process so far.
pub fn process_cpu_seconds() -> f64 {
    proc_cpu_seconds("/proc/self/stat")
}

/// CPU seconds used by the calling thread so far.
pub fn thread_cpu_seconds() -> f64 {
    proc_cpu_seconds("/proc/thread-self/stat")
}

/// The best tour of a heuristic run as it stood at one time limit.
#[derive(Clone, Debug, PartialEq)]
pub struct HeuristicSnapshot {
    /// The limit (in the run's clock units, seconds in the benchmarks).
    pub limit: f64,
    /// Best tour found by the first clock reading at or after `limit` (depot first).
    pub tour: Vec<usize>,
    /// Its cost.
    pub cost: f64,
    /// Iterations done by then.
    pub iterations: u64,
}

/// What [`run_heuristic_with_snapshots`] saw.
#[derive(Clone, Debug, PartialEq)]
pub struct HeuristicRun {
    /// One snapshot per limit, in the order of the limits.
    pub snapshots: Vec<HeuristicSnapshot>,
    /// Clock reading at the first improvement to a cost ≤ `reach_cost`, if any.
    pub time_to_reach: Option<f64>,
    /// Whether the solver stopped by itself (target cost reached or instance exhausted) before
    /// the largest limit; later snapshots then hold its final tour, which could not improve.
    pub finished_early: bool,
    /// Clock reading when the run ended.
    pub seconds: f64,
}

/// Runs `solver` until `clock` reaches the largest of `limits` (or the solver stops), in slices
/// of `slice`, and records the best tour at every limit: one long run yields the results of
/// all shorter limits, because the ALNS trajectory depends only on its seed and iteration
/// count (the clock only decides where to stop). A run with limits `[L]` ends at exactly the
/// point where a longer run takes its snapshot for `L`, for the same clock readings.
///
/// `clock` is read after every slice and at every improvement; the benchmarks pass the
/// solver thread's CPU time, tests a deterministic clock made from the iteration count. The
/// solver's own `time_limit` and `max_iterations` should be unset (it would stop early and
/// the later snapshots would then hold its final tour).
pub fn run_heuristic_with_snapshots(
    solver: &mut cutroute_alns::AlnsSolver,
    limits: &[f64],
    reach_cost: f64,
    slice: std::time::Duration,
    clock: &mut dyn FnMut(&cutroute_alns::AlnsProgress) -> f64,
) -> HeuristicRun {
    let mut order: Vec<usize> = (0..limits.len()).collect();
    order.sort_by(|&a, &b| limits[a].total_cmp(&limits[b]));
    let mut snapshots: Vec<Option<HeuristicSnapshot>> = vec![None; limits.len()];
    let mut next = 0;
    let mut time_to_reach = None;
    let mut finished_early = false;
    let mut now = 0.0;
    while next < order.len() {
        let status = solver.step_with(slice, &mut |progress| {
            if time_to_reach.is_none() && progress.best_cost.is_some_and(|c| c <= reach_cost) {
                time_to_reach = Some(clock(progress));
            }
        });
        let progress = solver.progress();
        now = clock(&progress);
        let finished = status.is_done();
        while next < order.len() && (finished || now >= limits[order[next]]) {
            let (tour, cost) = solver
                .best()
                .map(|(t, c)| (t.to_vec(), c))
                .unwrap_or((Vec::new(), f64::INFINITY));
            snapshots[order[next]] = Some(HeuristicSnapshot {
                limit: limits[order[next]],
                tour,
                cost,
                iterations: progress.iterations,
            });
            if now < limits[order[next]] {
                finished_early = true;
            }
            next += 1;
        }
    }
    HeuristicRun {
        snapshots: snapshots
            .into_iter()
            .map(|s| s.expect("every limit"))
            .collect(),
        time_to_reach,
        finished_early,
        seconds: now,
    }
}

/// The real nest files under `data/nests/{dbs,dbs-json,dxf,svg,tflex}`, each folder in name
/// order, with their file names: the nests the benchmarks run on.
pub fn real_nest_files(data: &std::path::Path) -> Vec<(String, std::path::PathBuf)> {
    let mut files = Vec::new();
    for dir in ["dbs", "dbs-json", "dxf", "svg", "tflex"] {
        let Ok(entries) = std::fs::read_dir(data.join("nests").join(dir)) else {
            continue;
        };
        let mut paths: Vec<std::path::PathBuf> =
            entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        files.extend(paths.into_iter().filter_map(|path| {
            let name = path.file_name()?.to_string_lossy().to_string();
            Some((name, path))
        }));
    }
    files
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_alns::{AlnsOptions, AlnsSolver};
    use cutroute_pcgtsp::{check_tour, Instance};
    use std::time::Duration;

    fn load(set: &str, name: &str) -> Instance {
        let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/pcgtsp")
            .join(set)
            .join(format!("{name}.pcglns"));
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("missing reference instance {}: {e}", path.display()));
        Instance::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    /// A deterministic stand-in for the CPU clock: one "second" per 1000 iterations.
    fn iteration_clock(progress: &cutroute_alns::AlnsProgress) -> f64 {
        progress.iterations as f64 / 1000.0
    }

    fn run(instance: &Instance, seed: u64, limits: &[f64]) -> HeuristicRun {
        let options = AlnsOptions {
            seed,
            time_limit: None,
            ..AlnsOptions::default()
        };
        let mut solver = AlnsSolver::new(instance, options).unwrap();
        // A zero slice is one iteration per step: the clock is read after every iteration.
        run_heuristic_with_snapshots(
            &mut solver,
            limits,
            f64::NEG_INFINITY,
            Duration::ZERO,
            &mut iteration_clock,
        )
    }

    #[test]
    fn a_short_run_equals_the_snapshot_of_a_longer_run() {
        // ft53.2 is still improving after 1000 iterations, so the snapshots differ.
        let instance = load("pcgtsplib", "ft53.2");
        let long = run(&instance, 5, &[1.0, 2.0, 4.0]);
        let short = run(&instance, 5, &[1.0]);
        assert_eq!(short.snapshots[0], long.snapshots[0]);
        assert_eq!(short.snapshots[0].iterations, 1000);
        assert_eq!(long.snapshots[2].iterations, 4000);
        assert!(long.snapshots[2].cost <= long.snapshots[0].cost);
        assert!(!long.finished_early);
        for snapshot in long.snapshots.iter().chain(&short.snapshots) {
            let checked = check_tour(&instance, &snapshot.tour).expect("feasible tour");
            assert_eq!(checked, snapshot.cost);
        }
    }

    #[test]
    fn later_snapshots_of_a_run_stopped_at_its_target_hold_the_final_tour() {
        let instance = load("pcgtsplib", "ESC12");
        let options = AlnsOptions {
            seed: 2,
            time_limit: None,
            target_cost: Some(1390.0),
            ..AlnsOptions::default()
        };
        let mut solver = AlnsSolver::new(&instance, options).unwrap();
        let run = run_heuristic_with_snapshots(
            &mut solver,
            &[30.0, 1000.0],
            1390.0,
            Duration::ZERO,
            &mut iteration_clock,
        );
        assert!(run.finished_early);
        assert!(run.time_to_reach.is_some_and(|t| t <= run.seconds));
        for snapshot in &run.snapshots {
            assert_eq!(snapshot.cost, 1390.0);
            assert_eq!(check_tour(&instance, &snapshot.tour).unwrap(), 1390.0);
        }
    }
}
