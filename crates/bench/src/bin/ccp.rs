//! Benchmark of the CCP-Relax solver (`cargo run --release -p cutroute-bench --bin ccp`).
//!
//! Prints Markdown tables:
//! 1. real nests, open routes from the sheet origin: CCP-Relax against the crates.io peer
//!    `u-nesting-cutting` (arcs flattened at 8 segments per radian, `pierce_candidates = 1`),
//!    both measured by the same metric (Euclidean idle length of the route they return);
//!    with a lower bound on every open route from the origin (the distance to the farthest
//!    contour: the air path must reach each contour's pierce point);
//!    and, on nests of at most 6 innermost contours, an exact lower bound over every order;
//! 2. real nests, CCP against the discrete model (PCGTSP at ε = 25, 50 and 100 mm solved by
//!    cutroute's ALNS, 10 s each, dense cost matrix), same start point and metric;
//! 3. `E1X_6_01` closed at (0, 0) against the proven discrete optimum 1513;
//! 4. synthetic nests of 100 … 20,000 contours: time to the first VNS local optimum, idle
//!    length, and the peer.
//!
//! Arguments: `--quick` skips the 20,000-contour nest; `--real-only` skips the synthetic nests; `--vns-seconds S` sets CCP's budget
//! after the local optimum (default 5); `--synthetic N` runs CCP on one synthetic nest only, `--peer-synthetic N` runs only the peer on one synthetic nest, `--nest PATH` CCP on one real nest (path under
//! `data/nests`), `--discrete-nest PATH` the discrete model alone on one real nest.

use std::time::{Duration, Instant};

use cutroute_ccp::{build_pcgtsp, solve, CcpOptions, CcpResult, DiscretisationOptions};
use cutroute_geometry::{generate_nest, Nest, Point, Route};

const SHARED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/nests");

/// Any nest format, read as the app and the CLI read it (orientation normalised).
fn read(path: &str) -> Nest {
    let full = format!("{SHARED}/{path}");
    let bytes = std::fs::read(&full).unwrap_or_else(|e| panic!("cannot read {full}: {e}"));
    match cutroute_engine::open_document(path, &bytes) {
        Ok(cutroute_protocol::Document {
            problem: cutroute_protocol::Problem::Nest { nest, .. },
            ..
        }) => nest,
        Ok(_) => panic!("{full} is not a nest"),
        Err(e) => panic!("cannot parse {full}: {e}"),
    }
}

fn ccp(nest: &Nest, finish: Option<Point>, time_limit: Duration) -> (CcpResult, Duration) {
    let options = CcpOptions {
        start: Point::new(0.0, 0.0),
        finish,
        time_limit,
        best_improvement: std::env::args().any(|a| a == "--best-improvement"),
        ..CcpOptions::default()
    };
    let t = Instant::now();
    let r = solve(nest, options, &mut |_| {}).expect("ccp solves");
    let route_check = r.route.validate(nest, 1e-6);
    assert!(route_check.is_ok(), "invalid CCP route: {route_check:?}");
    (r, t.elapsed())
}

/// The peer on the same geometry: each part becomes a polygon with holes (arcs flattened at 8
/// segments per radian), placed where it is; returns (idle length recomputed by our metric,
/// the peer's own figure, time).
fn peer(nest: &Nest) -> Option<(f64, f64, Duration)> {
    use u_nesting_core::{Placement, SolveResult};
    use u_nesting_d2::Geometry2D;
    let flatten = |c: &cutroute_geometry::Contour| -> Vec<(f64, f64)> {
        let mut pts = Vec::new();
        for span in c.spans() {
            let sweep = 4.0 * span.bulge.atan();
            let n = ((sweep.abs() * 8.0).ceil() as usize).max(1);
            for k in 0..n {
                let p = span.point_at(k as f64 / n as f64);
                pts.push((p.x, p.y));
            }
        }
        pts
    };
    let mut geometries = Vec::new();
    let mut result = SolveResult::<f64>::new();
    for (i, part) in nest.parts.iter().enumerate() {
        if part.contours.is_empty() {
            continue;
        }
        let id = format!("p{i}");
        let mut g = Geometry2D::new(id.clone()).with_polygon(flatten(&part.contours[0]));
        for hole in &part.contours[1..] {
            g = g.with_hole(flatten(hole));
        }
        geometries.push(g);
        result
            .placements
            .push(Placement::new_2d(id, 0, 0.0, 0.0, 0.0));
    }
    let config = u_nesting_cutting::CuttingConfig {
        pierce_candidates: 1,
        home_position: (0.0, 0.0),
        time_limit_ms: 60_000,
        ..u_nesting_cutting::CuttingConfig::default()
    };
    let t = Instant::now();
    let out = match u_nesting_cutting::optimize_cutting_path(&result, &geometries, &config) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("u-nesting-cutting failed: {e}");
            return None;
        }
    };
    let elapsed = t.elapsed();
    let mut cur = (0.0f64, 0.0f64);
    let mut idle = 0.0;
    for st in &out.sequence {
        idle += (st.pierce_point.0 - cur.0).hypot(st.pierce_point.1 - cur.1);
        cur = st.pierce_point;
    }
    Some((idle, out.total_rapid_distance, elapsed))
}

/// A lower bound on the idle length of every open route from `start`: the air path reaches a
/// pierce point on every contour, so it is at least as long as the distance to the farthest.
fn farthest_contour(nest: &Nest, start: Point) -> f64 {
    nest.parts
        .iter()
        .flat_map(|p| &p.contours)
        .filter(|c| !c.vertices.is_empty())
        .map(|c| c.distance_to(start))
        .fold(0.0, f64::max)
}

/// A certified lower bound on the idle length of every open route from `start` over a nest with
/// at most `max_kept` innermost contours (`None` above): over every order of the innermost
/// contours, the shortest path from `start` through one sample point of each (samples at most
/// `h` apart along the contour), plus the distance from the last one to its outermost enclosing
/// contour, which must still be cut after it. Outer contours are otherwise left out, which can
/// only shorten a path (triangle inequality). Moving a pierce point to its nearest sample
/// changes the path by at most `h` per contour, so `k·h` is subtracted. Returns (bound, h).
fn small_nest_lower_bound(nest: &Nest, start: Point, max_kept: usize) -> Option<(f64, f64)> {
    let forest = nest.containment_forest();
    let kept: Vec<cutroute_geometry::ContourRef> = forest
        .leaves()
        .into_iter()
        .filter(|&r| nest.contour(r).is_some_and(|c| !c.vertices.is_empty()))
        .collect();
    let k = kept.len();
    if k == 0 || k > max_kept {
        return None;
    }
    let longest = kept
        .iter()
        .map(|&r| nest.contour(r).map_or(0.0, |c| c.perimeter()))
        .fold(0.0, f64::max);
    // About 1,500 samples on the longest contour (the pairwise layers cost n² per order); one
    // contour has no pairs and gets 100 times more.
    let per_contour = if k == 1 { 150_000.0 } else { 1500.0 };
    let h = (longest / per_contour).max(1e-4);
    let mut samples: Vec<Vec<Point>> = Vec::with_capacity(k);
    let mut exit: Vec<Vec<f64>> = Vec::with_capacity(k);
    for &r in &kept {
        let c = nest.contour(r)?;
        let per = c.perimeter();
        let n = ((per / h).ceil() as usize).max(1);
        let pts: Vec<Point> = (0..n)
            .map(|i| c.point_at_length(per * i as f64 / n as f64))
            .collect::<Option<_>>()?;
        let outermost = forest.ancestors(r).last().and_then(|a| nest.contour(a));
        exit.push(
            pts.iter()
                .map(|&p| outermost.map_or(0.0, |o| o.distance_to(p)))
                .collect(),
        );
        samples.push(pts);
    }
    let mut best = f64::INFINITY;
    let mut cur: Vec<f64> = Vec::new();
    let mut next: Vec<f64> = Vec::new();
    let mut order: Vec<usize> = (0..k).collect();
    for_each_permutation(&mut order, 0, &mut |order| {
        cur.clear();
        cur.extend(samples[order[0]].iter().map(|p| p.distance(start)));
        for w in 1..k {
            let (from, to) = (&samples[order[w - 1]], &samples[order[w]]);
            next.clear();
            next.extend(to.iter().map(|q| {
                from.iter()
                    .zip(&cur)
                    .map(|(p, d)| d + p.distance(*q))
                    .fold(f64::INFINITY, f64::min)
            }));
            std::mem::swap(&mut cur, &mut next);
        }
        let value = cur
            .iter()
            .zip(&exit[order[k - 1]])
            .map(|(d, e)| d + e)
            .fold(f64::INFINITY, f64::min);
        best = best.min(value);
    });
    // The farthest contour bound holds too; keep the better.
    Some(((best - k as f64 * h).max(farthest_contour(nest, start)), h))
}

/// Calls `f` with every permutation of `v[from..]` (prefix fixed).
fn for_each_permutation(v: &mut [usize], from: usize, f: &mut dyn FnMut(&[usize])) {
    if from + 1 >= v.len() {
        f(v);
        return;
    }
    for i in from..v.len() {
        v.swap(from, i);
        for_each_permutation(v, from + 1, f);
        v.swap(from, i);
    }
}

/// Best discrete route at step ε found by cutroute's ALNS in `budget`: (idle length, nodes).
fn discrete(
    nest: &Nest,
    finish: Option<Point>,
    step: f64,
    budget: Duration,
) -> Option<(f64, usize)> {
    let opts = DiscretisationOptions {
        start: Point::new(0.0, 0.0),
        finish,
        step,
        ..DiscretisationOptions::default()
    };
    let inst = build_pcgtsp(nest, &opts).ok()?;
    let options = cutroute_alns::AlnsOptions {
        time_limit: Some(budget),
        ..cutroute_alns::AlnsOptions::default()
    };
    let r = cutroute_alns::solve(&inst.instance, options, &mut |_| {}).ok()?;
    let route: Route = inst.tour_to_route(r.tour.as_ref()?).ok()?;
    Some((route.idle_length(), inst.instance.node_count))
}

/// The nests of the `--bound` table: every real multi-contour nest of at most 100 contours
/// (then Nest02 and Nest03, 460 contours, with their own budget).
const BOUND_NESTS: [(&str, &str); 13] = [
    ("nested.dbs", "dbs/nested.dbs"),
    ("seven.dbs", "dbs/seven.dbs"),
    ("test0", "dbs-json/test0.dbs.json"),
    ("test1", "dbs-json/test1.dbs.json"),
    ("E1X_6_01", "dbs-json/E1X_6_01.dbs.json"),
    ("propeller.dxf", "dxf/propeller.dxf"),
    ("cross.dxf", "dxf/cross.dxf"),
    ("planka.dxf", "dxf/planka.dxf"),
    ("kompas.dxf", "dxf/kompas.dxf"),
    ("f26.dxf", "dxf/f26.dxf"),
    ("cone.dxf", "dxf/cone.dxf"),
    ("Nest02", "tflex/Nest02.tfnesting"),
    ("Nest03", "tflex/Nest03.tfnesting"),
];

/// `--bound [S] [S_BIG]`: the engine's CCP job (the CLI's and the app's code path: CCP-Relax
/// and the interval relaxation's lower bound sharing each slice) on every nest of
/// `BOUND_NESTS`, `S` seconds for nests of at most 100 contours, `S_BIG` for larger ones;
/// open routes from the origin. Prints UB, LB, gap, the small nests' k!-orders bound and
/// the wall time.
fn print_bound_table(small_seconds: f64, big_seconds: f64, only: Option<&String>) {
    use cutroute_protocol::{JobRequest, SolverKind, SolverParams};
    println!("| nest | contours | kept | time limit s | UB (CCP idle) | LB | gap | k!-orders bound | wall s | longest slice s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, path) in BOUND_NESTS {
        if only.is_some_and(|o| o != name) {
            continue;
        }
        let nest = read(path);
        let contours = nest.contour_count();
        if contours < 2 {
            continue;
        }
        let seconds = if contours <= 100 {
            small_seconds
        } else {
            big_seconds
        };
        let request = JobRequest {
            job_id: 1,
            problem: cutroute_protocol::Problem::Nest {
                nest: nest.clone(),
                start: Point::new(0.0, 0.0),
                finish: None,
            },
            solver: SolverKind::Ccp,
            params: SolverParams {
                time_limit_s: seconds,
                ..SolverParams::default()
            },
        };
        let t = Instant::now();
        let mut job = cutroute_engine::start_job(&request).expect("a CCP job");
        // The engine's loop, timing each slice (Stop is answered between slices).
        let mut longest = Duration::ZERO;
        loop {
            let slice = Instant::now();
            let status = job.step(cutroute_engine::DEFAULT_SLICE);
            longest = longest.max(slice.elapsed());
            if status == cutroute_engine::JobStatus::Done {
                break;
            }
        }
        let progress = job.progress();
        let wall = t.elapsed().as_secs_f64();
        let route = progress.route().expect("a route");
        assert!(route.validate(&nest, 1e-6).is_ok(), "invalid CCP route");
        let (ub, lb) = (
            progress.bounds.upper.unwrap_or(f64::NAN),
            progress.bounds.lower.unwrap_or(f64::NAN),
        );
        assert!(lb <= ub + 1e-6, "{name}: bound {lb} above the route {ub}");
        let exact = small_nest_lower_bound(&nest, Point::new(0.0, 0.0), 6)
            .map_or("—".to_string(), |(b, _)| format!("{b:.1}"));
        println!(
            "| {name} | {contours} | {} | {seconds:.0} | {ub:.1} | {lb:.1} | {:.2} % | {exact} | {wall:.1} | {:.2} |",
            nest.containment_forest().leaves().len(),
            100.0 * (ub - lb) / ub,
            longest.as_secs_f64(),
        );
    }
}

/// Every multi-contour nest of data/nests: (name, path).
const REAL: [(&str, &str); 13] = [
    ("nested.dbs", "dbs/nested.dbs"),
    ("seven.dbs", "dbs/seven.dbs"),
    ("test0", "dbs-json/test0.dbs.json"),
    ("test1", "dbs-json/test1.dbs.json"),
    ("E1X_6_01", "dbs-json/E1X_6_01.dbs.json"),
    ("Nest01", "tflex/Nest01.tfnesting"),
    ("Nest02", "tflex/Nest02.tfnesting"),
    ("Nest03", "tflex/Nest03.tfnesting"),
    ("Graph_9x15", "dbs/Graph_9x15.DBS"),
    ("seven_3717", "dbs/seven_3717.dbs"),
    ("propeller.dxf", "dxf/propeller.dxf"),
    ("cross.dxf", "dxf/cross.dxf"),
    ("planka.dxf", "dxf/planka.dxf"),
];

/// The lower-bound table: (name, nest, CCP idle, peer idle) per nest.
fn print_lower_bounds<'a>(rows: impl Iterator<Item = (&'a str, &'a Nest, f64, f64)>) {
    println!("\n## Exact lower bounds on the small real nests (every order of the innermost contours, sampled pierce points, certified margin)\n");
    println!("| nest | kept | lower bound | sample step h | CCP idle | CCP / bound | 0.9 × peer |");
    println!("|---|---|---|---|---|---|---|");
    for (name, nest, len, pl) in rows {
        if let Some((lb, h)) = small_nest_lower_bound(nest, Point::new(0.0, 0.0), 6) {
            let kept = nest.containment_forest().leaves().len();
            println!(
                "| {name} | {kept} | {lb:.2} | {h:.3} | {len:.2} | {:.4} | {:.1} |",
                len / lb,
                0.9 * pl
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let vns_seconds: f64 = args
        .iter()
        .position(|a| a == "--vns-seconds")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(5.0);
    let budget = Duration::from_secs_f64(vns_seconds);
    let only: Option<usize> = args
        .iter()
        .position(|a| a == "--synthetic")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok());
    if let Some(path) = args
        .iter()
        .position(|a| a == "--discrete-nest")
        .and_then(|i| args.get(i + 1))
    {
        let nest = read(path);
        for step in [100.0, 50.0, 25.0] {
            let t = Instant::now();
            let d = discrete(&nest, None, step, Duration::from_secs(10));
            println!(
                "{path} ε = {step}: {d:?} in {:.1} s",
                t.elapsed().as_secs_f64()
            );
        }
        return;
    }
    if let Some(path) = args
        .iter()
        .position(|a| a == "--nest")
        .and_then(|i| args.get(i + 1))
    {
        let nest = read(path);
        let (r, t) = ccp(&nest, None, budget);
        println!(
            "{path}: initial {:.1}, local optimum {:.1} at {:.3} s, final {:.1} in {:.2} s, {} shakes",
            r.progress.initial_length.unwrap_or(f64::NAN),
            r.progress.local_optimum_length.unwrap_or(f64::NAN),
            r.progress.local_optimum_time.unwrap_or_default().as_secs_f64(),
            r.metrics.idle_length,
            t.as_secs_f64(),
            r.progress.shakes
        );
        return;
    }
    if let Some(n) = args
        .iter()
        .position(|a| a == "--peer-synthetic")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse::<usize>().ok())
    {
        let nest = generate_nest(n, 1);
        match peer(&nest) {
            Some((l, own, t)) => println!(
                "peer on {n} contours: idle {l:.0} (its own figure {own:.0}) in {:.1} s",
                t.as_secs_f64()
            ),
            None => println!("peer on {n} contours failed"),
        }
        return;
    }
    if let Some(n) = only {
        let nest = generate_nest(n, 1);
        let (r, t) = ccp(&nest, None, budget);
        println!(
            "{n} contours: initial {:.0}, local optimum {:.0} at {:.2} s, final {:.0} in {:.2} s, {} evaluations, {} exact checks, {} moves, {} shakes",
            r.progress.initial_length.unwrap_or(f64::NAN),
            r.progress.local_optimum_length.unwrap_or(f64::NAN),
            r.progress.local_optimum_time.unwrap_or_default().as_secs_f64(),
            r.metrics.idle_length,
            t.as_secs_f64(),
            r.progress.evaluations,
            r.progress.exact_checks,
            r.progress.accepted_moves,
            r.progress.shakes
        );
        return;
    }
    let real = REAL;
    if let Some(i) = args.iter().position(|a| a == "--bound") {
        let seconds = |at: usize, default: f64| {
            args.get(at)
                .and_then(|s| s.parse::<f64>().ok())
                .unwrap_or(default)
        };
        let only = args
            .iter()
            .position(|a| a == "--only")
            .and_then(|i| args.get(i + 1));
        print_bound_table(seconds(i + 1, 60.0), seconds(i + 2, 120.0), only);
        return;
    }
    if args.iter().any(|a| a == "--lower-bounds") {
        let mut rows = Vec::new();
        for (name, path) in real {
            let nest = read(path);
            if small_nest_lower_bound(&nest, Point::new(0.0, 0.0), 6).is_some() {
                let (r, _) = ccp(&nest, None, budget);
                let pl = peer(&nest).map_or(f64::NAN, |p| p.0);
                rows.push((name, nest, r.metrics.idle_length, pl));
            }
        }
        print_lower_bounds(rows.iter().map(|(n, nest, l, p)| (*n, nest, *l, *p)));
        return;
    }

    println!("## CCP-Relax vs u-nesting-cutting (open routes from the sheet origin, idle mm)\n");
    println!("| nest | contours | kept | CCP idle | CCP time s | local opt. s | certified | peer idle | peer time s | CCP / peer | lower bound |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut open_results = Vec::new();
    for (name, path) in real {
        let nest = read(path);
        let (r, t) = ccp(&nest, None, budget);
        let p = peer(&nest);
        let (pl, pt) = p.map_or((f64::NAN, f64::NAN), |(l, _, t)| (l, t.as_secs_f64()));
        println!(
            "| {name} | {} | {} | {:.1} | {:.2} | {:.3} | {}/{} | {:.1} | {:.2} | {:.3} | {:.1} |",
            r.route.steps.len(),
            r.progress.kept_contours,
            r.metrics.idle_length,
            t.as_secs_f64(),
            r.progress
                .local_optimum_time
                .unwrap_or_default()
                .as_secs_f64(),
            r.certificates.iter().filter(|c| c.condition1).count(),
            r.certificates.len(),
            pl,
            pt,
            r.metrics.idle_length / pl,
            farthest_contour(&nest, Point::new(0.0, 0.0)),
        );
        open_results.push((name, nest, r.metrics.idle_length, pl));
    }

    print_lower_bounds(
        open_results
            .iter()
            .map(|(n, nest, l, p)| (*n, nest, *l, *p)),
    );

    println!("\n## CCP-Relax vs the discrete model (PCGTSP solved by cutroute-alns, 10 s each; open routes, idle mm)\n");
    println!("| nest | CCP | ε = 25 mm (nodes, s) | ε = 50 mm (nodes, s) | ε = 100 mm (nodes, s) | CCP / d25 | CCP / d50 | CCP / d100 |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, nest, len, _) in &open_results {
        let run = |step: f64| {
            let t = Instant::now();
            discrete(nest, None, step, Duration::from_secs(10))
                .map(|(l, n)| (l, n, t.elapsed().as_secs_f64()))
        };
        let (d25, d50, d100) = (run(25.0), run(50.0), run(100.0));
        let f = |d: Option<(f64, usize, f64)>| {
            d.map_or("n/a".to_string(), |(l, n, t)| {
                format!("{l:.1} ({n}, {t:.1})")
            })
        };
        let ratio = |d: Option<(f64, usize, f64)>| {
            d.map_or("n/a".to_string(), |(l, _, _)| format!("{:.4}", len / l))
        };
        println!(
            "| {name} | {len:.1} | {} | {} | {} | {} | {} | {} |",
            f(d25),
            f(d50),
            f(d100),
            ratio(d25),
            ratio(d50),
            ratio(d100)
        );
    }

    println!("\n## E1X_6_01 closed at (0, 0) (the PCGTSP instance e1x_6: proven discrete optimum 1513)\n");
    let nest = read("dbs-json/E1X_6_01.dbs.json");
    let (r, t) = ccp(&nest, Some(Point::new(0.0, 0.0)), budget);
    println!("| CCP idle | time s | certified | discrete optimum | CCP / optimum |");
    println!("|---|---|---|---|---|");
    println!(
        "| {:.2} | {:.2} | {} | 1513 | {:.4} |",
        r.metrics.idle_length,
        t.as_secs_f64(),
        r.certified_optimal_for_order,
        r.metrics.idle_length / 1513.0
    );

    if args.iter().any(|a| a == "--real-only") {
        return;
    }
    println!("\n## Synthetic nests (`generate_nest(n, 1)`, open routes from the origin)\n");
    println!("| contours | kept | initial (NN) | local optimum | time to local opt. s | after VNS | total s | peer idle | peer s | CCP / peer |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let sizes: &[usize] = if quick {
        &[100, 1000, 5000]
    } else {
        &[100, 1000, 5000, 20000]
    };
    for &n in sizes {
        let nest = generate_nest(n, 1);
        // Budget of the whole run (first local optimum, then VNS): 10 s per 1,000 contours,
        // at least 10 s and at most 120 s.
        let limit = Duration::from_secs_f64((n as f64 / 100.0).clamp(10.0, 120.0));
        let (r, t) = ccp(&nest, None, limit);
        let p = if n <= 5000 { peer(&nest) } else { None };
        let (pl, pt) = p.map_or((f64::NAN, f64::NAN), |(l, _, t)| (l, t.as_secs_f64()));
        println!(
            "| {n} | {} | {:.0} | {:.0} | {:.2} | {:.0} | {:.1} | {:.0} | {:.2} | {:.3} |",
            r.progress.kept_contours,
            r.progress.initial_length.unwrap_or(f64::NAN),
            r.progress.local_optimum_length.unwrap_or(f64::NAN),
            r.progress
                .local_optimum_time
                .unwrap_or_default()
                .as_secs_f64(),
            r.metrics.idle_length,
            t.as_secs_f64(),
            pl,
            pt,
            r.metrics.idle_length / pl,
        );
    }
}
