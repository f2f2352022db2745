//! The interval relaxation's lower bound (`CcpLowerBound`) is sound and converges: never above
//! a brute-force route (every feasible order × finely sampled pierce points) on random small
//! nests, within a few percent of it after a few stages, and never above CCP-Relax's route on
//! the real nests.

use std::collections::BTreeSet;
use std::time::Duration;

use cutroute_ccp::{
    containment_pairs, solve, CcpLowerBound, CcpOptions, CcpResult, LinkPrices, LowerBoundOptions,
    StageWork,
};
use cutroute_geometry::{
    is_scrap_region, Contour, ContourRef, Nest, Part, Point, SplitMix64, Vertex,
};

/// A convex polygon of `n` corners around `centre` (some sides bulged outwards), clockwise as
/// outer contours are after opening; `hole` gives the counter-clockwise orientation of holes.
fn polygon(rng: &mut SplitMix64, centre: Point, radius: f64, n: usize, hole: bool) -> Contour {
    let turn = rng.range(0.0, std::f64::consts::TAU);
    let mut vertices: Vec<Vertex> = (0..n)
        .map(|k| {
            let a = turn - std::f64::consts::TAU * k as f64 / n as f64;
            // Clockwise sides bulge outwards with a negative bulge.
            let bulge = if rng.next_f64() < 0.4 {
                -rng.range(0.05, 0.4)
            } else {
                0.0
            };
            Vertex::arc(
                centre.x + radius * a.cos(),
                centre.y + radius * a.sin(),
                bulge,
            )
        })
        .collect();
    if hole {
        vertices = Contour::new(vertices).reversed().vertices;
    }
    Contour::new(vertices)
}

/// 2–4 parts in separate cells of a grid; sometimes one has a hole with a small part in it.
fn random_nest(seed: u64) -> Nest {
    let mut rng = SplitMix64::new(seed);
    let count = 2 + (rng.next_f64() * 3.0) as usize;
    let mut parts = Vec::new();
    for i in 0..count {
        let centre = Point::new(
            60.0 * (i % 2) as f64 + rng.range(-8.0, 8.0),
            60.0 * (i / 2) as f64 + rng.range(-8.0, 8.0) + 20.0,
        );
        let corners = 3 + (rng.next_f64() * 4.0) as usize;
        let radius = rng.range(10.0, 20.0);
        let mut contours = vec![polygon(&mut rng, centre, radius, corners, false)];
        if i == 0 && rng.next_f64() < 0.6 {
            contours.push(polygon(&mut rng, centre, 0.5 * radius, 5, true));
            parts.push(Part {
                name: "inner".into(),
                contours: vec![polygon(&mut rng, centre, 0.2 * radius, 4, false)],
            });
        }
        parts.push(Part {
            name: format!("part {i}"),
            contours,
        });
    }
    Nest { sheet: None, parts }
}

/// The shortest route over every order of the contours that cuts inner contours first, with
/// pierce points sampled every `h` mm: a feasible route, so no lower bound may exceed it.
fn brute_force(nest: &Nest, start: Point, finish: Option<Point>, h: f64) -> f64 {
    brute_force_priced(nest, start, finish, h, &|_, _, d| d, &|d| d)
}

/// [`brute_force`] with each move priced by `move_price(from, to, d)` (contour indices in
/// `nest.contour_refs()` order, `from` `None` for the start; `d` the straight length) and the
/// way to the finish by `finish_price(d)`.
fn brute_force_priced(
    nest: &Nest,
    start: Point,
    finish: Option<Point>,
    h: f64,
    move_price: &dyn Fn(Option<usize>, usize, f64) -> f64,
    finish_price: &dyn Fn(f64) -> f64,
) -> f64 {
    let refs: Vec<ContourRef> = nest.contour_refs().collect();
    let samples: Vec<Vec<Point>> = refs
        .iter()
        .map(|&r| {
            let c = nest.contour(r).unwrap();
            let n = (c.perimeter() / h).ceil() as usize;
            (0..n)
                .map(|k| {
                    c.point_at_length(c.perimeter() * k as f64 / n as f64)
                        .unwrap()
                })
                .collect()
        })
        .collect();
    let pairs: Vec<(usize, usize)> = containment_pairs(nest)
        .into_iter()
        .map(|(a, b)| {
            (
                refs.iter().position(|&r| r == a).unwrap(),
                refs.iter().position(|&r| r == b).unwrap(),
            )
        })
        .collect();
    let mut best = f64::INFINITY;
    let mut order: Vec<usize> = (0..refs.len()).collect();
    permute(&mut order, 0, &mut |order| {
        let at = |c: usize| order.iter().position(|&o| o == c).unwrap();
        if pairs.iter().any(|&(inner, outer)| at(inner) > at(outer)) {
            return;
        }
        let mut cur: Vec<f64> = samples[order[0]]
            .iter()
            .map(|p| move_price(None, order[0], p.distance(start)))
            .collect();
        for w in order.windows(2) {
            let (from, to) = (&samples[w[0]], &samples[w[1]]);
            cur = to
                .iter()
                .map(|q| {
                    from.iter()
                        .zip(&cur)
                        .map(|(p, d)| d + move_price(Some(w[0]), w[1], p.distance(*q)))
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
        }
        let last = &samples[*order.last().unwrap()];
        let value = cur
            .iter()
            .zip(last)
            .map(|(d, p)| d + finish.map_or(0.0, |f| finish_price(p.distance(f))))
            .fold(f64::INFINITY, f64::min);
        best = best.min(value);
    });
    best
}

fn permute(v: &mut [usize], k: usize, f: &mut dyn FnMut(&[usize])) {
    if k == v.len() {
        f(v);
        return;
    }
    for i in k..v.len() {
        v.swap(k, i);
        permute(v, k + 1, f);
        v.swap(k, i);
    }
}

/// CCP-Relax's route of `nest` within `limit` (the route that guides the bound, as in the
/// engine's job).
fn ccp_route(nest: &Nest, start: Point, finish: Option<Point>, limit: Duration) -> CcpResult {
    let options = CcpOptions {
        start,
        finish,
        time_limit: limit,
        ..CcpOptions::default()
    };
    solve(nest, options, &mut |_| {}).unwrap()
}

/// The first stage's work in these tests: what the bound reaches after some stages is then
/// the same on a quiet machine and on a loaded one (a stage of time buys what the machine
/// gives it: under load, two seconds once ended before the ng-path bound's first pass).
const WORK: StageWork = StageWork {
    exact_states: 20_000,
    ng_passes: 8,
};

/// Options measuring stages by [`WORK`].
fn by_work(options: LowerBoundOptions) -> LowerBoundOptions {
    LowerBoundOptions {
        stage_work: Some(WORK),
        ..options
    }
}

/// Runs the bound until every relaxation that still runs has done `stages` stages, or it has
/// nothing left to do; a run past ten minutes of its own time fails as a hang.
fn run_bound(bound: &mut CcpLowerBound, stages: usize) -> f64 {
    run_bound_watched(bound, stages, |_| {})
}

/// Runs the bound until the whole relaxation has done `stages` stages (the groups beside it
/// get the slices they get), or it has nothing left to do; fails as a hang past ten minutes.
fn run_whole_stages(bound: &mut CcpLowerBound, stages: usize) -> f64 {
    run_until(bound, |b| b.stages() >= stages, |_| {})
}

/// [`run_bound`], showing the bound to `watch` after every step.
fn run_bound_watched(
    bound: &mut CcpLowerBound,
    stages: usize,
    watch: impl FnMut(&CcpLowerBound),
) -> f64 {
    run_until(bound, |b| b.least_stages() >= stages, watch)
}

/// Steps the bound until `done` holds or it has nothing left to do, showing it to `watch`
/// after every step; a run past ten minutes of its own time fails as a hang.
fn run_until(
    bound: &mut CcpLowerBound,
    done: impl Fn(&CcpLowerBound) -> bool,
    mut watch: impl FnMut(&CcpLowerBound),
) -> f64 {
    while !done(bound) && bound.step(Duration::from_millis(50)) {
        watch(bound);
        assert!(
            bound.elapsed() < Duration::from_secs(600),
            "the bound ran 10 minutes"
        );
    }
    bound.lower_bound()
}

#[test]
fn never_above_brute_force_and_close_to_it_on_random_small_nests() {
    for seed in 1..=12u64 {
        let nest = random_nest(seed);
        let start = Point::new(-30.0, -10.0);
        let finish = (seed % 3 == 0).then_some(Point::new(150.0, -20.0));
        let brute = brute_force(&nest, start, finish, 0.25);
        let options = LowerBoundOptions {
            start,
            finish,
            budget_seconds: 2.0,
            ..by_work(LowerBoundOptions::default())
        };
        let mut bound = CcpLowerBound::new(&nest, options).unwrap();
        // The best CCP route guides the refinement, as in the engine's job.
        let ccp = ccp_route(&nest, start, finish, Duration::from_secs(1));
        bound.offer_route(&ccp.route);
        let lb = run_bound(&mut bound, 8);
        assert!(
            lb <= brute + 1e-9,
            "seed {seed}: bound {lb} above the brute-force route {brute}"
        );
        assert!(
            lb <= ccp.metrics.idle_length + 1e-9,
            "seed {seed}: bound {lb} above CCP's route {}",
            ccp.metrics.idle_length
        );
        assert!(
            lb >= 0.97 * brute,
            "seed {seed}: bound {lb} more than 3 % below the brute-force route {brute} after {} stages",
            bound.stages()
        );
    }
}

/// With link prices (chain cutting) the bound is never above the cheapest route that may
/// enter a contour by a straight tool-on link from a sibling in one scrap region (every order
/// that cuts inner contours first × pierce points every mm × link or pierce per move; real
/// links bend round obstacles, so they cost no less), less the cut of the perimeters, and
/// close to it. Prices vary from seed to seed so that links pay over some moves and not over
/// others; some nests have a hole with nothing in it (never linked).
#[test]
fn with_link_prices_never_above_brute_force_chain_routes() {
    let mut ratios = Vec::new();
    for seed in 1..=12u64 {
        let mut nest = random_nest(seed);
        let mut rng = SplitMix64::new(seed ^ 0xC4A1);
        if seed % 2 == 1 {
            let part = nest.parts.last_mut().unwrap();
            // The outline's corners lie evenly round its centre: their mean is the centre,
            // and a regular polygon of radius ≥ 10 holds a circle of radius 5.
            let corners = &part.contours[0].vertices;
            let (x, y) = corners
                .iter()
                .fold((0.0, 0.0), |(x, y), v| (x + v.point.x, y + v.point.y));
            let centre = Point::new(x / corners.len() as f64, y / corners.len() as f64);
            part.contours.push(polygon(&mut rng, centre, 4.0, 4, true));
        }
        let links = LinkPrices {
            idle_per_mm: rng.range(0.0, 2e-4),
            cut_per_mm: rng.range(5e-4, 2e-3),
            pierce: rng.range(0.0, 0.06),
        };
        let start = Point::new(-30.0, -10.0);
        let finish = (seed % 3 == 0).then_some(Point::new(150.0, -20.0));
        let forest = nest.containment_forest();
        let refs: Vec<ContourRef> = nest.contour_refs().collect();
        let region = |c: usize| {
            let parent = forest.parent(refs[c]);
            is_scrap_region(&forest, parent).then_some(parent)
        };
        let move_price = |from: Option<usize>, to: usize, d: f64| match from {
            Some(a) if region(a).is_some() && region(a) == region(to) => {
                (links.cut_per_mm * d).min(links.idle_per_mm * d + links.pierce)
            }
            _ => links.idle_per_mm * d + links.pierce,
        };
        let brute = brute_force_priced(&nest, start, finish, 1.0, &move_price, &|d| {
            links.idle_per_mm * d
        });
        let options = LowerBoundOptions {
            start,
            finish,
            budget_seconds: 2.0,
            links: Some(links),
            ..by_work(LowerBoundOptions::default())
        };
        let mut bound = CcpLowerBound::new(&nest, options).unwrap();
        let lb = run_bound(&mut bound, 8);
        assert!(
            lb <= brute + 1e-9,
            "seed {seed} {links:?}: bound {lb} above the brute-force chain route {brute}"
        );
        ratios.push(lb / brute);
    }
    eprintln!("bound / brute-force chain route: {ratios:?}");
    let least = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(least >= 0.9, "bound / brute-force chain route: {ratios:?}");
}

fn read_nest(path: &str) -> Nest {
    let full = format!("{}/../../data/nests/{path}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&full).unwrap_or_else(|e| panic!("missing test file {full}: {e}"));
    let mut nest =
        cutroute_formats::read_nest(&bytes).unwrap_or_else(|e| panic!("cannot read {full}: {e}"));
    nest.normalize_orientation();
    nest
}

#[test]
fn never_above_the_ccp_route_on_the_real_nests() {
    for path in [
        "dbs/nested.dbs",
        "dbs/seven.dbs",
        "dbs-json/test0.dbs.json",
        "dbs-json/test1.dbs.json",
        "dbs-json/E1X_6_01.dbs.json",
        "dbs/seven_3717.dbs",
        "dbs/Graph_5x7.DBS",
    ] {
        let nest = read_nest(path);
        let start = Point::new(0.0, 0.0);
        for finish in [None, Some(start)] {
            let ccp = ccp_route(&nest, start, finish, Duration::from_secs(2));
            let options = LowerBoundOptions {
                start,
                finish,
                budget_seconds: 2.0,
                ..by_work(LowerBoundOptions::default())
            };
            let mut bound = CcpLowerBound::new(&nest, options).unwrap();
            bound.offer_route(&ccp.route);
            let lb = run_bound(&mut bound, 1);
            let ub = ccp.metrics.idle_length;
            assert!(lb > 0.0, "{path}: no bound");
            assert!(
                lb <= ub + 1e-9,
                "{path} {finish:?}: bound {lb} above CCP's {ub}"
            );
        }
    }
}

#[test]
fn a_nest_without_contours_has_nothing_to_bound() {
    let mut bound = CcpLowerBound::new(&Nest::default(), LowerBoundOptions::default()).unwrap();
    assert!(!bound.step(Duration::from_millis(10)));
    assert_eq!(bound.lower_bound(), 0.0);
    let refused = CcpLowerBound::new(
        &Nest::default(),
        LowerBoundOptions {
            start: Point::new(f64::NAN, 0.0),
            ..LowerBoundOptions::default()
        },
    );
    assert!(refused.is_err());
}

/// A sheet too large for a dense relaxation (40,000 generated contours: far more pieces than
/// `MAX_RELAXATION_ENTRIES` allows) gives up at once with the trivial bound 0, instead of
/// asking for a matrix of tens of gigabytes.
#[test]
fn a_sheet_too_large_for_the_relaxation_keeps_the_trivial_bound() {
    let nest = cutroute_geometry::generate_nest(40_000, 1);
    let mut bound = CcpLowerBound::new(&nest, LowerBoundOptions::default()).unwrap();
    let started = std::time::Instant::now();
    assert!(!bound.step(Duration::from_millis(40)), "nothing to do");
    assert!(started.elapsed() < std::time::Duration::from_secs(5));
    assert_eq!(bound.lower_bound(), 0.0);
}

/// The optimum of `nest` discretised every `step` mm (proven by the exact solver alone) and the
/// discretisation's candidate pierce points.
fn discrete_optimum(
    nest: &Nest,
    start: Point,
    finish: Option<Point>,
    step: f64,
) -> (f64, Vec<(ContourRef, Point)>) {
    use cutroute_ccp::{build_pcgtsp, pierce_candidates, DiscretisationOptions};
    let discrete = build_pcgtsp(
        nest,
        &DiscretisationOptions {
            start,
            finish,
            step,
            ..DiscretisationOptions::default()
        },
    )
    .unwrap();
    let solved = cutroute_pcgtsp::solve(
        &discrete.instance,
        cutroute_pcgtsp::ExactOptions {
            time_limit: None,
            ..Default::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert!(
        solved.proven_optimal(),
        "the discrete optimum is not proven"
    );
    (
        solved.progress.upper_bound,
        pierce_candidates(&discrete.nodes),
    )
}

/// The bound at fixed candidates (a discretisation's pierce points) is never above the discrete
/// optimum (proven by the exact solver alone), with the exact search, the ng-path bound beside
/// it, or the ng-path bound alone; and where every contour is kept (no holes, so nothing is
/// relaxed but the pieces' micrometre widths) the exact search's equals that optimum.
#[test]
fn at_fixed_candidates_never_above_the_discrete_optimum_and_exact_without_holes() {
    let mut without_holes = 0;
    let mut ng_alone = Vec::new();
    for seed in 1..=12u64 {
        let nest = random_nest(seed);
        let start = Point::new(-30.0, -10.0);
        let finish = (seed % 3 == 0).then_some(Point::new(150.0, -20.0));
        let (optimum, candidates) = discrete_optimum(&nest, start, finish, 9.0);
        // The exact search alone (as on nests of up to ~22 kept contours), the ng-path bound
        // beside it (as on larger ones), and the ng-path bound alone. Its neighbourhoods start
        // at two contours, so that the widest ones take over on these small nests too.
        for (ng_above, exact_max_kept) in [(usize::MAX, usize::MAX), (0, usize::MAX), (0, 0)] {
            let options = LowerBoundOptions {
                start,
                finish,
                budget_seconds: 2.0,
                ng_above,
                ng_size: 2,
                exact_max_kept,
                ..LowerBoundOptions::default()
            };
            let mut bound = CcpLowerBound::for_candidates(&nest, options, &candidates)
                .unwrap()
                .expect("every kept contour has candidates");
            while bound.step(Duration::from_millis(50)) {}
            assert_eq!(
                bound.stages(),
                1,
                "seed {seed}: one stage, nothing to refine"
            );
            let lb = bound.lower_bound();
            assert!(
                lb <= optimum + 1e-9,
                "seed {seed} (ng above {ng_above}, exact up to {exact_max_kept}): bound {lb} \
                 above the discrete optimum {optimum}"
            );
            if exact_max_kept == 0 {
                ng_alone.push(lb / optimum);
            } else if bound.kept_contours() == nest.contour_count() {
                without_holes += 1;
                assert!(
                    lb >= optimum - 1e-4,
                    "seed {seed}: bound {lb} vs discrete optimum {optimum} with every contour kept"
                );
            }
        }
    }
    assert!(without_holes > 0, "no nest without holes was tried");
    // The ng-path bound alone is a bound of its own, not a stand-in: close to the optimum on
    // most of these small nests (its widest neighbourhoods hold every contour).
    eprintln!("ng-path bound alone / discrete optimum: {ng_alone:?}");
    let close = ng_alone.iter().filter(|&&r| r >= 0.9).count();
    assert!(
        4 * close >= 3 * ng_alone.len(),
        "the ng-path bound alone at the candidates: ratios to the optimum {ng_alone:?}"
    );
}

/// At fixed candidates the widest neighbourhoods take over from small ones: started with
/// ng = 1 (only immediate returns forbidden, far below the optimum on packed sheets), the
/// ng-path bound alone ends where every contour is in every neighbourhood, so at the optimum
/// of the candidates' relaxation, and never above the discrete optimum.
#[test]
fn at_fixed_candidates_the_widest_neighbourhoods_take_over() {
    let mut ratios = Vec::new();
    for seed in 1..=6u64 {
        let nest = packed_nest(seed);
        let start = Point::new(-30.0, -10.0);
        let (optimum, candidates) = discrete_optimum(&nest, start, None, 6.0);
        let options = LowerBoundOptions {
            start,
            budget_seconds: 2.0,
            ng_above: 0,
            ng_size: 1,
            exact_max_kept: 0,
            ..LowerBoundOptions::default()
        };
        let mut bound = CcpLowerBound::for_candidates(&nest, options, &candidates)
            .unwrap()
            .expect("every kept contour has candidates");
        assert!(bound.kept_contours() > 1, "seed {seed}: nothing to widen");
        while bound.step(Duration::from_millis(50)) {}
        let lb = bound.lower_bound();
        assert!(
            lb <= optimum + 1e-9,
            "seed {seed}: bound {lb} above the discrete optimum {optimum}"
        );
        ratios.push(lb / optimum);
    }
    let least = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(least >= 0.97, "bound / discrete optimum: {ratios:?}");
}

/// Six parts packed on a 3 × 2 grid (gaps of a few mm, as on real sheets), the first with a
/// hole holding a small part: more contours than the random nests, so groups of one or two
/// kept contours border each other closely.
fn packed_nest(seed: u64) -> Nest {
    let mut rng = SplitMix64::new(seed ^ 0x2545_F491_4F6C_DD1D);
    let mut parts = Vec::new();
    for i in 0..6 {
        let centre = Point::new(
            28.0 * (i % 3) as f64 + rng.range(-2.0, 2.0),
            28.0 * (i / 3) as f64 + rng.range(-2.0, 2.0) + 15.0,
        );
        let corners = 3 + (rng.next_f64() * 4.0) as usize;
        let radius = rng.range(9.0, 12.0);
        let mut contours = vec![polygon(&mut rng, centre, radius, corners, false)];
        if i == 0 {
            contours.push(polygon(&mut rng, centre, 0.5 * radius, 5, true));
            parts.push(Part {
                name: "inner".into(),
                contours: vec![polygon(&mut rng, centre, 0.2 * radius, 4, false)],
            });
        }
        parts.push(Part {
            name: format!("part {i}"),
            contours,
        });
    }
    Nest { sheet: None, parts }
}

/// The small nests the bounds are tried on against brute force: per seed 1–8 a random nest
/// (brute force's step 0.25 mm) and a packed one (1 mm), from one start, open or (every third
/// seed) closed.
fn small_cases() -> Vec<(u64, Nest, f64, Point, Option<Point>)> {
    (1..=8u64)
        .flat_map(|seed| {
            let start = Point::new(-30.0, -10.0);
            let finish = (seed % 3 == 0).then_some(Point::new(150.0, -20.0));
            [(random_nest(seed), 0.25), (packed_nest(seed), 1.0)]
                .into_iter()
                .map(move |(nest, h)| (seed, nest, h, start, finish))
        })
        .collect()
}

/// The decomposition bound (the sum of the spatial groups' bounds, each group charged only
/// for the length a route runs inside its region) is never above a brute-force route, with
/// groups of one and two kept contours (the most borders), on random and packed nests, open
/// and closed; and it is not trivially zero.
#[test]
fn the_groups_sum_never_above_brute_force() {
    let mut positive = 0;
    let mut cases = 0;
    for (seed, nest, h, start, finish) in small_cases() {
        let brute = brute_force(&nest, start, finish, h);
        for group_size in [1, 2] {
            let options = LowerBoundOptions {
                start,
                finish,
                budget_seconds: 2.0,
                group_size,
                decompose_above: 0,
                ..by_work(LowerBoundOptions::default())
            };
            let mut bound = CcpLowerBound::new(&nest, options).unwrap();
            if bound.kept_contours() <= group_size {
                assert_eq!(bound.group_count(), 0);
                continue;
            }
            assert!(bound.group_count() >= 2, "seed {seed}: no groups");
            let ccp = ccp_route(&nest, start, finish, Duration::from_millis(300));
            bound.offer_route(&ccp.route);
            let lb = run_bound(&mut bound, 3);
            let sum = bound.group_sum();
            cases += 1;
            positive += usize::from(sum > 0.05 * brute);
            assert!(
                sum <= brute + 1e-9,
                "seed {seed}, groups of {group_size}: sum {sum} above brute force {brute}"
            );
            assert!(lb <= brute + 1e-9, "seed {seed}: bound {lb} above {brute}");
            assert!(lb >= sum && lb >= bound.whole_bound());
        }
    }
    assert!(cases >= 16, "only {cases} cases had groups");
    assert!(
        positive * 2 >= cases,
        "the groups' sum was trivial in {} of {cases} cases",
        cases - positive
    );
}

/// Where nothing solves the whole relaxation (more kept contours than the exact search's keys,
/// forced to 1 here, and no `ng_alone`), groups of `wide_group_size` that run the ng-path bound
/// beside their exact search take over from the small groups once these have made their first
/// stages, if their sum is below `wide_below` of the route (always here; never with 0): the
/// bound is never above a brute-force route, on random and packed nests, open and closed, and
/// it is not trivial.
#[test]
fn wide_groups_with_the_ng_path_bound_never_above_brute_force() {
    let mut positive = 0;
    let mut cases = 0;
    for (seed, nest, h, start, finish) in small_cases() {
        let options = LowerBoundOptions {
            start,
            finish,
            budget_seconds: 2.0,
            group_size: 1,
            wide_group_size: 2,
            wide_below: f64::INFINITY,
            decompose_above: 0,
            ng_size: 8,
            ng_above: 0,
            exact_max_kept: 1,
            ..by_work(LowerBoundOptions::default())
        };
        let mut stays_small = CcpLowerBound::new(
            &nest,
            LowerBoundOptions {
                wide_below: 0.0,
                ..options.clone()
            },
        )
        .unwrap();
        let mut bound = CcpLowerBound::new(&nest, options).unwrap();
        let kept = bound.kept_contours();
        if kept <= 2 {
            // No wide groups of two: the small groups of one stay.
            assert!(!bound.wide_pending(), "seed {seed}");
            continue;
        }
        assert!(bound.wide_pending(), "seed {seed}: no wide groups pending");
        assert_eq!(
            bound.group_count(),
            kept,
            "seed {seed}: groups of one first"
        );
        let brute = brute_force(&nest, start, finish, h);
        let ccp = ccp_route(&nest, start, finish, Duration::from_millis(300));
        bound.offer_route(&ccp.route);
        // One stage of every wide group (their ng-path bounds' passes on a group's fine
        // pieces are the slow part of this test).
        let lb = run_bound(&mut bound, 1);
        let sum = bound.group_sum();
        assert!(
            !bound.wide_pending() && bound.group_count() >= 2 && bound.group_count() < kept,
            "seed {seed}: {} groups of {kept} kept contours, not groups of two",
            bound.group_count()
        );
        stays_small.offer_route(&ccp.route);
        let small = run_bound(&mut stays_small, 2);
        assert_eq!(stays_small.group_count(), kept, "seed {seed}: widened");
        assert!(
            small <= brute + 1e-9,
            "seed {seed}: small groups {small} above {brute}"
        );
        cases += 1;
        positive += usize::from(sum > 0.05 * brute);
        assert_eq!(
            bound.whole_bound(),
            0.0,
            "seed {seed}: the whole relaxation ran"
        );
        assert!(
            sum <= brute + 1e-9 && lb <= brute + 1e-9,
            "seed {seed}: groups' sum {sum}, bound {lb}, brute force {brute}"
        );
        assert!(lb <= ccp.metrics.idle_length + 1e-9);
    }
    assert!(cases >= 8, "only {cases} cases had groups");
    assert!(
        positive * 2 >= cases,
        "the groups' sum was trivial in {} of {cases} cases",
        cases - positive
    );
}

/// The ng-path bound on the whole relaxation (forced on small nests, neighbourhoods of 2 and 8
/// contours, and of 2 widened to 5 after the first stage) is never above a brute-force route,
/// on random and packed nests, open and closed; it is not trivial; and the stages after the
/// first use the refined neighbourhoods.
#[test]
fn the_ng_path_bound_never_above_brute_force() {
    let mut strong = 0;
    let mut cases = 0;
    let mut refined_stages = 0;
    for (seed, nest, h, start, finish) in small_cases() {
        let brute = brute_force(&nest, start, finish, h);
        let ccp = ccp_route(&nest, start, finish, Duration::from_millis(300));
        // Neighbourhoods of the first stage and of the later ones (0: the same), the later
        // ones starting from the first's penalties.
        for (ng_size, ng_refined_size) in [(2, 0), (8, 0), (2, 5)] {
            let options = LowerBoundOptions {
                start,
                finish,
                budget_seconds: 2.0,
                group_size: 0,
                ng_size,
                ng_refined_size,
                ng_above: 0,
                ..by_work(LowerBoundOptions::default())
            };
            let mut bound = CcpLowerBound::new(&nest, options).unwrap();
            bound.offer_route(&ccp.route);
            let mut later = BTreeSet::new();
            let mut watch = |b: &CcpLowerBound| {
                if b.stages() > 0 {
                    later.extend(b.ng_neighbourhood());
                }
            };
            let lb = run_bound_watched(&mut bound, 2, &mut watch);
            let ng = bound.ng_bound();
            cases += 1;
            strong += usize::from(ng >= 0.8 * brute);
            assert!(
                ng <= brute + 1e-9 && lb <= brute + 1e-9,
                "seed {seed}, ng {ng_size} then {ng_refined_size}: ng-path bound {ng}, bound \
                 {lb}, brute force {brute}"
            );
            assert!(lb <= ccp.metrics.idle_length + 1e-9);
            let expected = if ng_refined_size > 0 {
                ng_refined_size
            } else {
                ng_size
            };
            assert!(
                later.iter().all(|&k| k == expected),
                "seed {seed}: neighbourhoods {later:?} after the first stage, not {expected}"
            );
            refined_stages += usize::from(ng_refined_size > 0 && !later.is_empty());
        }
    }
    assert!(
        strong * 4 >= cases * 3,
        "the ng-path bound was below 80 % of the optimum in {} of {cases} cases",
        cases - strong
    );
    assert!(
        refined_stages > 0,
        "no case reached a stage with the refined neighbourhoods"
    );
}

/// Above `exact_max_kept` kept contours (256 on real nests, forced to 1 here) the whole
/// relaxation runs the ng-path bound alone, beside the spatial groups: the reported bound (the
/// larger of the groups' sum and the ng-path bound) is never above a brute-force route or
/// CCP's route, on random and packed nests, open and closed; and the ng-path bound is not
/// trivial.
#[test]
fn the_ng_path_bound_without_the_exact_search_never_above_brute_force() {
    let mut strong = 0;
    let mut cases = 0;
    for (seed, nest, h, start, finish) in small_cases() {
        let brute = brute_force(&nest, start, finish, h);
        let ccp = ccp_route(&nest, start, finish, Duration::from_millis(300));
        let options = LowerBoundOptions {
            start,
            finish,
            budget_seconds: 2.0,
            group_size: 2,
            decompose_above: 0,
            ng_size: 8,
            ng_above: 0,
            exact_max_kept: 1,
            ng_alone: true,
            ..by_work(LowerBoundOptions::default())
        };
        let mut bound = CcpLowerBound::new(&nest, options).unwrap();
        if bound.kept_contours() <= 2 {
            continue;
        }
        assert!(bound.group_count() >= 2, "seed {seed}: no groups");
        bound.offer_route(&ccp.route);
        let lb = run_whole_stages(&mut bound, 2);
        let ng = bound.ng_bound();
        cases += 1;
        strong += usize::from(ng >= 0.8 * brute);
        // Without the exact search only the ng-path bound raises the whole relaxation's.
        assert_eq!(bound.whole_bound(), ng, "seed {seed}: the exact search ran");
        assert!(ng > 0.0, "seed {seed}: the ng-path bound did not run");
        assert!(
            ng <= brute + 1e-9 && lb <= brute + 1e-9,
            "seed {seed}: ng-path bound {ng}, bound {lb}, brute force {brute}"
        );
        assert!(lb <= ccp.metrics.idle_length + 1e-9);
        assert!(lb >= bound.group_sum() && lb >= ng);
    }
    assert!(cases >= 12, "only {cases} cases had groups");
    assert!(
        strong * 4 >= cases * 3,
        "the ng-path bound was below 80 % of the optimum in {} of {cases} cases",
        cases - strong
    );
}
