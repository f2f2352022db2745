//! LinuxCNC's own interpreter (`rs274`, installed by `scripts/install-rs274.sh`) runs the
//! programs the writer makes, and its tool-centre motion must be the route's: the same pierce
//! points, cut and rapid lengths, every cut traced within 0.01 mm (plus the written resolution),
//! whatever the machine's position before the program.
//!
//! Every preset whose codes LinuxCNC knows is run as written. The «Комета» preset's torch codes
//! (`M71`/`M74 T1`) mean other things to LinuxCNC, so its programs run with `M03`/`M05` in
//! their place: the interpreter still checks its coordinates (one decimal, incremental).

#[path = "support/canon.rs"]
mod canon;

use std::path::PathBuf;

use cutroute_engine::open_document;
use cutroute_gcode::{
    route_gcode, ArcOutput, DistanceMode, GcodeOptions, GcodePreset, KerfCompensation,
};
use cutroute_geometry::{
    generate_nest, BoundingBox, KerfSettings, LeadFitter, LeadShape, LeadSpec, MachineParameters,
    Nest, Point, Route, Span, ToolMove, Toolpath,
};
use cutroute_protocol::Problem;

/// A machine position the programs must not depend on: the interpreter stands here first.
const ELSEWHERE: &str = "G21 G90 G00 X-41.3 Y27.9\n";

fn data(relative: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("missing test file {}: {e}", path.display()))
}

fn nest_of(relative: &str) -> Option<Nest> {
    let name = relative.rsplit('/').next().unwrap_or(relative);
    let document = open_document(name, &data(relative)).ok()?;
    match document.problem {
        Problem::Nest { nest, .. } if !nest.parts.is_empty() => Some(nest),
        _ => None,
    }
}

/// The baseline route from the corner of the nest's bounding box (often a contour's vertex,
/// and so the first pierce point).
fn route_of(nest: &Nest) -> Route {
    let mut bbox = BoundingBox::EMPTY;
    for contour in nest.parts.iter().flat_map(|p| &p.contours) {
        let b = contour.bounding_box();
        bbox.min = Point::new(bbox.min.x.min(b.min.x), bbox.min.y.min(b.min.y));
        bbox.max = Point::new(bbox.max.x.max(b.max.x), bbox.max.y.max(b.max.y));
    }
    let start = bbox.min;
    Route::innermost_first(nest, start, Some(start))
}

fn with_leads(nest: &Nest, route: &Route, lead_in: LeadShape) -> Option<Route> {
    let settings = KerfSettings {
        kerf: 1.0,
        pierce_clearance: 2.0,
        switch_off_clearance: 1.0,
        lead_in: LeadSpec::new(lead_in, 3.0),
        lead_out: LeadSpec::new(LeadShape::Line, 2.0),
        overcut: 0.5,
        ..KerfSettings::default()
    };
    LeadFitter::new(nest, settings).attach(route).ok()
}

/// The groups of cutting spans between torch-ons, and the rapid length after the first
/// torch-on, of the expected tool-centre path.
fn expected_groups(path: &Toolpath) -> (Vec<Point>, Vec<Vec<Span>>, f64) {
    let (mut pierces, mut groups, mut rapid) = (Vec::new(), Vec::<Vec<Span>>::new(), 0.0);
    for m in &path.moves {
        match *m {
            ToolMove::Pierce { at, .. } => {
                pierces.push(at);
                groups.push(Vec::new());
            }
            ToolMove::Idle { from, to } if !pierces.is_empty() => rapid += from.distance(to),
            ToolMove::Cut { span, .. } => {
                if let Some(g) = groups.last_mut() {
                    g.push(span);
                }
            }
            _ => {}
        }
    }
    (pierces, groups, rapid)
}

fn run_groups(run: &canon::Run) -> Result<(Vec<Vec<Span>>, f64), String> {
    let mut groups = vec![Vec::<Span>::new(); run.torch_on_at.len()];
    let mut rapid = 0.0;
    for m in &run.motions {
        if m.rapid {
            if m.tool_on {
                return Err(format!("a rapid with the torch on: {:?}", m.span));
            }
            if m.torch_ons > 0 {
                rapid += m.span.length();
            }
        } else if m.tool_on {
            groups[m.torch_ons - 1].push(m.span);
        } else if m.span.length() > 1e-9 {
            return Err(format!("a feed move with the torch off: {:?}", m.span));
        }
    }
    Ok((groups, rapid))
}

fn distance_to(spans: &[Span], p: Point) -> f64 {
    spans
        .iter()
        .map(|s| s.distance_to(p))
        .fold(f64::INFINITY, f64::min)
}

/// The largest distance from a point of `a` (sampled every `step` mm) to `b`.
fn one_sided(a: &[Span], b: &[Span], step: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for s in a {
        let n = (s.length() / step).ceil().max(1.0) as usize;
        for k in 0..=n {
            worst = worst.max(distance_to(b, s.point_at(k as f64 / n as f64)));
        }
    }
    worst
}

/// Compares the interpreter's run of a program with the expected tool-centre path.
fn agree(path: &Toolpath, run: &canon::Run, options: &GcodeOptions) -> Result<(), String> {
    let tolerance = tolerance(options);
    let (pierces, expected, rapid) = expected_groups(path);
    if run.torch_on_at.len() != pierces.len() {
        return Err(format!(
            "{} torch-ons, the route has {} pierces",
            run.torch_on_at.len(),
            pierces.len()
        ));
    }
    for (k, (a, b)) in run.torch_on_at.iter().zip(&pierces).enumerate() {
        if a.distance(*b) > tolerance {
            return Err(format!("pierce {k} at {a:?}, the route's at {b:?}"));
        }
    }
    let (groups, run_rapid) = run_groups(run)?;
    let cut = |g: &[Vec<Span>]| g.iter().flatten().map(Span::length).sum::<f64>();
    let (want, got) = (cut(&expected), cut(&groups));
    // Both ends of a written move are within half a quantum per axis of their true places,
    // so its length may change by up to √2 quanta: at one decimal (0.1 mm) the short moves of
    // small arcs and fine features add up to more than the relative slack.
    let written: usize = groups.iter().map(Vec::len).sum();
    let rounding = 2.0f64.sqrt() * quantum(options) * written as f64;
    if (want - got).abs() > 2e-3 * want + 0.05 + rounding {
        return Err(format!("cuts {got:.4} mm, the route {want:.4} mm"));
    }
    if (rapid - run_rapid).abs() > 2e-3 * rapid + 0.05 {
        return Err(format!("rapids {run_rapid:.4} mm, the route {rapid:.4} mm"));
    }
    for (k, (e, g)) in expected.iter().zip(&groups).enumerate() {
        let step = 1.0;
        let off = one_sided(g, e, step).max(one_sided(e, g, step));
        if off > tolerance {
            return Err(format!(
                "cut {k} (pierced at {:?}) leaves the route by {off:.4} mm",
                pierces[k]
            ));
        }
    }
    Ok(())
}

/// What a case is: the program's options and the route's expected tool-centre path.
struct Case {
    what: String,
    options: GcodeOptions,
    route: Route,
    tool_diameter: f64,
}

/// The last written digit, in mm.
fn quantum(options: &GcodeOptions) -> f64 {
    10f64.powi(-(options.decimals as i32))
}

/// The tolerance of the trace: 0.01 mm plus what rounding and chords may add.
fn tolerance(options: &GcodeOptions) -> f64 {
    let quantum = quantum(options);
    let chords = match options.arcs {
        ArcOutput::Lines { tolerance_mm } => tolerance_mm,
        _ => 0.0,
    };
    // A written point is within half a quantum of its true place on each axis, and an arc the
    // resolution cannot hold is written as chords within half a quantum.
    0.01 + (0.5f64.sqrt() + 0.5) * quantum + chords
}

/// Runs the cases; returns the failures (refused by the writer counts as agreeing only when it
/// says why, which every `GcodeError` does).
fn referee(nest: &Nest, cases: Vec<Case>) -> (usize, usize, Vec<String>) {
    let (accepted, refused, failures) = referee_reasons(nest, cases);
    for refusal in &refused {
        eprintln!("refused before writing: {refusal}");
    }
    (accepted, refused.len(), failures)
}

/// The preset's options as LinuxCNC can run them (see the module notes on «Комета»).
fn runnable(preset: GcodePreset) -> GcodeOptions {
    let mut options = preset.options(&MachineParameters::default());
    if preset == GcodePreset::Kometa2p32m {
        options.torch_on = "M03".into();
        options.torch_off = "M05".into();
        options.header.clear();
        options.footer = vec!["M30".into()];
    }
    options
}

fn option_variants(base: &GcodeOptions) -> Vec<(&'static str, GcodeOptions)> {
    let with = |f: &dyn Fn(&mut GcodeOptions)| {
        let mut o = base.clone();
        f(&mut o);
        o
    };
    vec![
        ("as is", base.clone()),
        ("ij", with(&|o| o.arcs = ArcOutput::CentreOffsets)),
        ("r", with(&|o| o.arcs = ArcOutput::Radius)),
        (
            "lines",
            with(&|o| o.arcs = ArcOutput::Lines { tolerance_mm: 0.01 }),
        ),
        (
            "incremental",
            with(&|o| o.distance_mode = DistanceMode::Incremental),
        ),
        (
            "absolute",
            with(&|o| o.distance_mode = DistanceMode::Absolute),
        ),
        ("line numbers", with(&|o| o.line_numbers = true)),
        ("decimals 1", with(&|o| o.decimals = 1)),
        ("decimals 4", with(&|o| o.decimals = 4)),
        (
            "decimals 1 r",
            with(&|o| {
                o.decimals = 1;
                o.arcs = ArcOutput::Radius;
            }),
        ),
    ]
}

#[test]
fn every_preset_and_option_runs_on_linuxcnc_as_reported() {
    if canon::rs274().is_none() {
        return;
    }
    let mut total = (0, 0, Vec::new());
    for relative in ["nests/dbs/nested.dbs", "nests/dxf/kompas.dxf"] {
        let nest = nest_of(relative).expect("the nest opens");
        let bare = route_of(&nest);
        let leads = with_leads(&nest, &bare, LeadShape::Arc).expect("leads fit");
        let mut cases = Vec::new();
        for preset in GcodePreset::ALL {
            for (name, options) in option_variants(&runnable(preset)) {
                cases.push(Case {
                    what: format!("{relative} {preset} {name}"),
                    options: options.clone(),
                    route: bare.clone(),
                    tool_diameter: 1.0,
                });
                cases.push(Case {
                    what: format!("{relative} {preset} {name} kerf+leads"),
                    options,
                    route: leads.clone(),
                    tool_diameter: 1.0,
                });
            }
        }
        let (a, r, f) = referee(&nest, cases);
        total.0 += a;
        total.1 += r;
        total.2.extend(f);
    }
    eprintln!(
        "rs274: {} agree, {} refused before writing, {} differ",
        total.0,
        total.1,
        total.2.len()
    );
    assert!(total.2.is_empty(), "{}", total.2.join("\n"));
}

#[test]
fn controller_compensation_runs_on_linuxcnc_as_reported_or_is_refused() {
    if canon::rs274().is_none() {
        return;
    }
    let mut total = (0, 0, Vec::new());
    let mut nests: Vec<(String, Nest)> = ["nests/dbs/nested.dbs", "nests/dbs/seven.dbs"]
        .into_iter()
        .map(|relative| {
            (
                relative.to_string(),
                nest_of(relative).expect("the nest opens"),
            )
        })
        .collect();
    // Generated parts: entries on arcs as well as on lines.
    nests.push(("generated 30/4".into(), generate_nest(30, 4)));
    for (relative, nest) in &nests {
        let nest = nest.clone();
        let bare = route_of(&nest);
        let Some(leads) = with_leads(&nest, &bare, LeadShape::Line) else {
            continue;
        };
        let mut cases = Vec::new();
        for preset in GcodePreset::ALL {
            for (name, code) in [
                ("g41.1", KerfCompensation::ControllerDiameter),
                ("g41:1", KerfCompensation::ControllerRegister(1)),
            ] {
                if let Err(e) = preset.check_compensation(code) {
                    total.1 += 1;
                    eprintln!("{relative} {preset} {name}: refused before writing: {e}");
                    continue;
                }
                let options = GcodeOptions {
                    kerf_compensation: code,
                    ..runnable(preset)
                };
                cases.push(Case {
                    what: format!("{relative} {preset} {name}"),
                    options,
                    route: leads.clone(),
                    tool_diameter: 1.0,
                });
            }
        }
        let (a, r, f) = referee(&nest, cases);
        total.0 += a;
        total.1 += r;
        total.2.extend(f);
    }
    eprintln!(
        "rs274 (compensation): {} agree, {} refused before writing, {} differ",
        total.0,
        total.1,
        total.2.len()
    );
    assert!(total.2.is_empty(), "{}", total.2.join("\n"));
}

#[test]
fn shipped_nests_and_real_world_files_run_on_linuxcnc_as_reported() {
    if canon::rs274().is_none() {
        return;
    }
    let mut files: Vec<String> = [
        "nests/dbs/seven.dbs",
        "nests/dbs/test0.json.dbs",
        "nests/dbs-json/E1X_6_01.dbs.json",
        "nests/dxf/cone.dxf",
        "nests/dxf/cross.dxf",
        "nests/dxf/planka.dxf",
        "nests/dxf/propeller.dxf",
        "nests/dxf/square.dxf",
        "nests/svg/plates.svg",
    ]
    .map(String::from)
    .to_vec();
    // Every fourth real-world file with closed contours.
    let csv = String::from_utf8(data("realworld/expected.csv")).expect("utf-8");
    let closed: Vec<String> = csv
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut f = l.split(',');
            let file = f.next()?;
            let tight: usize = f.nth(2)?.parse().ok()?;
            (tight > 0).then(|| format!("realworld/{file}"))
        })
        .collect();
    files.extend(closed.into_iter().step_by(4));
    let mut total = (0, 0, Vec::new());
    let mut opened = 0;
    for relative in &files {
        let Some(nest) = nest_of(relative) else {
            continue;
        };
        opened += 1;
        let route = route_of(&nest);
        let base = GcodeOptions::default();
        let cases = [DistanceMode::Absolute, DistanceMode::Incremental]
            .into_iter()
            .map(|distance_mode| Case {
                what: format!("{relative} {distance_mode:?}"),
                options: GcodeOptions {
                    distance_mode,
                    ..base.clone()
                },
                route: route.clone(),
                tool_diameter: 1.0,
            })
            .collect();
        let (a, r, f) = referee(&nest, cases);
        total.0 += a;
        total.1 += r;
        total.2.extend(f);
    }
    assert!(opened >= 15, "only {opened} files opened");
    eprintln!(
        "rs274 (files): {} agree, {} refused before writing, {} differ",
        total.0,
        total.1,
        total.2.len()
    );
    assert!(total.2.is_empty(), "{}", total.2.join("\n"));
}

/// The program cases of one nest: every preset × every arc format, incremental, line numbers,
/// kerf with line and with arc leads, and both controller compensations. A case the writer or
/// the lead fitter cannot make comes back as its reason.
fn matrix_cases(what: &str, nest: &Nest) -> (Vec<Case>, Vec<String>) {
    let bare = route_of(nest);
    let mut refusals = Vec::new();
    let mut lead_route = |shape: LeadShape| {
        let settings = KerfSettings {
            kerf: 1.0,
            pierce_clearance: 2.0,
            switch_off_clearance: 1.0,
            lead_in: LeadSpec::new(shape, 3.0),
            lead_out: LeadSpec::new(LeadShape::Line, 2.0),
            overcut: 0.5,
            ..KerfSettings::default()
        };
        LeadFitter::new(nest, settings)
            .attach(&bare)
            .map_err(|errors| {
                for e in errors {
                    refusals.push(format!("{what} leads: {e}"));
                }
            })
            .ok()
    };
    let line_leads = lead_route(LeadShape::Line);
    let arc_leads = lead_route(LeadShape::Arc);
    let mut cases = Vec::new();
    for preset in GcodePreset::ALL {
        let base = runnable(preset);
        let with = |f: &dyn Fn(&mut GcodeOptions)| {
            let mut o = base.clone();
            f(&mut o);
            o
        };
        let mut push = |name: &str, options: GcodeOptions, route: &Option<Route>| {
            if let Some(route) = route {
                cases.push(Case {
                    what: format!("{what} {preset} {name}"),
                    options,
                    route: route.clone(),
                    tool_diameter: 1.0,
                });
            }
        };
        let bare = Some(bare.clone());
        push("ij", with(&|o| o.arcs = ArcOutput::CentreOffsets), &bare);
        push("r", with(&|o| o.arcs = ArcOutput::Radius), &bare);
        let lines = ArcOutput::Lines { tolerance_mm: 0.01 };
        push("lines", with(&|o| o.arcs = lines), &bare);
        let incremental = DistanceMode::Incremental;
        push(
            "incremental",
            with(&|o| o.distance_mode = incremental),
            &bare,
        );
        push("line numbers", with(&|o| o.line_numbers = true), &bare);
        push("kerf+line leads", base.clone(), &line_leads);
        push("kerf+arc leads", base.clone(), &arc_leads);
        for (name, code) in [
            ("g41.1", KerfCompensation::ControllerDiameter),
            ("g41:1", KerfCompensation::ControllerRegister(1)),
        ] {
            match preset.check_compensation(code) {
                Ok(()) => push(
                    name,
                    GcodeOptions {
                        kerf_compensation: code,
                        ..base.clone()
                    },
                    &line_leads,
                ),
                Err(e) => refusals.push(format!("{preset} {name}: {e}")),
            }
        }
    }
    (cases, refusals)
}

/// What refusals say, with the numbers and names that differ between cases taken out, so
/// that the summary counts reasons rather than cases.
fn reason_of(message: &str) -> String {
    let tail = message.rsplit(": ").next().unwrap_or(message);
    let mut reason = String::new();
    let mut depth = 0;
    for c in tail.chars() {
        match c {
            '(' if depth == 0 => {
                depth += 1;
                reason.push_str("(…)");
            }
            '(' => depth += 1,
            ')' => depth -= 1,
            _ if depth > 0 => {}
            c if c.is_ascii_digit() => {
                if !reason.ends_with('#') {
                    reason.push('#');
                }
            }
            c => reason.push(c),
        }
    }
    reason
}

/// The shipped nests and a chosen part of the real-world corpus, each with its nest.
///
/// The real-world corpus is large and every file costs the whole option matrix; the part
/// chosen covers both what stresses the writer most (the files with the most contours) and
/// what differs between the programs that made the files (the first file of every generator,
/// named before `__` in the corpus).
fn matrix_files() -> Vec<(String, Nest)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let listed = |folder: &str| {
        let mut names: Vec<String> = std::fs::read_dir(root.join(folder))
            .expect("data folder")
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .map(|name| format!("{folder}/{name}"))
            .collect();
        names.sort();
        names
    };
    let mut files = Vec::new();
    for folder in ["nests/dbs", "nests/dbs-json", "nests/dxf", "nests/svg"] {
        for relative in listed(folder) {
            if let Some(nest) = nest_of(&relative) {
                files.push((relative, nest));
            }
        }
    }
    let mut corpus: Vec<(String, Nest)> = listed("realworld/files")
        .into_iter()
        .filter_map(|relative| Some((relative.clone(), nest_of(&relative)?)))
        .collect();
    let contours = |n: &Nest| n.parts.iter().map(|p| p.contours.len()).sum::<usize>();
    corpus.sort_by_key(|(_, nest)| std::cmp::Reverse(contours(nest)));
    let generator = |relative: &str| {
        let name = relative.rsplit('/').next().unwrap_or(relative);
        name.split("__").next().unwrap_or(name).to_string()
    };
    let mut seen = std::collections::BTreeSet::new();
    for (k, (relative, nest)) in corpus.into_iter().enumerate() {
        if seen.insert(generator(&relative)) | (k < 15) {
            files.push((relative, nest));
        }
    }
    files
}

/// Differences of the matrix that are known and not yet fixed, each with why: a case whose
/// name (file, preset, option) contains every pattern of an entry is counted as open, not as a
/// failure. Every entry must still match a difference, so a fix makes the test ask for its entry
/// to be removed; a difference no entry matches fails the test.
const OPEN_DIFFERENCES: &[(&[&str], &str)] = &[];

#[test]
fn the_whole_output_matrix_runs_on_linuxcnc_as_reported_or_is_refused() {
    if canon::rs274().is_none() {
        return;
    }
    let started = std::time::Instant::now();
    let files = matrix_files();
    let mut reasons = std::collections::BTreeMap::<String, usize>::new();
    let (mut agreed, mut failures) = (0, Vec::new());
    for (relative, nest) in &files {
        let (cases, refusals) = matrix_cases(relative, nest);
        for r in refusals {
            *reasons.entry(reason_of(&r)).or_default() += 1;
        }
        // Two workers: the writing and comparing of one case overlaps another's interpreter.
        let half = cases.len() / 2;
        let mut cases = cases;
        let second = cases.split_off(half);
        let results = std::thread::scope(|s| {
            let workers: Vec<_> = [cases, second]
                .into_iter()
                .map(|part| s.spawn(move || referee_reasons(nest, part)))
                .collect();
            workers
                .into_iter()
                .map(|w| w.join().expect("worker"))
                .collect::<Vec<_>>()
        });
        for (a, refused, f) in results {
            agreed += a;
            for r in refused {
                *reasons.entry(reason_of(&r)).or_default() += 1;
            }
            failures.extend(f);
        }
    }
    let refused: usize = reasons.values().sum();
    eprintln!(
        "rs274 matrix over {} files: {} programs agree, {} refused before writing, {} differ ({:.0} s)",
        files.len(),
        agreed,
        refused,
        failures.len(),
        started.elapsed().as_secs_f64()
    );
    for (reason, count) in &reasons {
        eprintln!("  refused {count:>5} × {reason}");
    }
    assert!(files.len() >= 40, "only {} files open", files.len());
    let open_entry = |failure: &str| {
        let case = failure.split(": ").next().unwrap_or(failure);
        let case = format!("{case} ");
        OPEN_DIFFERENCES
            .iter()
            .position(|(patterns, _)| patterns.iter().all(|p| case.contains(p)))
    };
    let mut open = vec![0usize; OPEN_DIFFERENCES.len()];
    let mut new_failures = Vec::new();
    for failure in &failures {
        match open_entry(failure) {
            Some(k) => {
                eprintln!("  known difference: {failure}");
                open[k] += 1
            }
            None => new_failures.push(failure.as_str()),
        }
    }
    for ((patterns, why), count) in OPEN_DIFFERENCES.iter().zip(&open) {
        eprintln!("  open  {count:>5} × {patterns:?}: {why}");
    }
    assert!(new_failures.is_empty(), "{}", new_failures.join("\n"));
    for ((patterns, _), count) in OPEN_DIFFERENCES.iter().zip(&open) {
        assert!(
            *count > 0,
            "{patterns:?} no longer differs: remove it from OPEN_DIFFERENCES"
        );
    }
}

/// Like `referee`, with the writer's refusals returned rather than counted.
fn referee_reasons(nest: &Nest, cases: Vec<Case>) -> (usize, Vec<String>, Vec<String>) {
    let rs274 = canon::rs274().expect("rs274");
    let (mut accepted, mut refused, mut failures) = (0, Vec::new(), Vec::new());
    for case in cases {
        let program = match route_gcode(nest, &case.route, &case.options) {
            Ok(p) => p,
            Err(e) => {
                refused.push(format!("{}: {e}", case.what));
                continue;
            }
        };
        let program = format!("{ELSEWHERE}{program}");
        let path = Toolpath::new(&case.route, nest).expect("toolpath");
        let result = canon::run(&rs274, &program, case.tool_diameter, &case.what)
            .and_then(|run| agree(&path, &run, &case.options));
        match result {
            Ok(()) => accepted += 1,
            Err(e) => failures.push(format!("{}: {e}", case.what)),
        }
    }
    (accepted, refused, failures)
}
