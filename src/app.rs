//! The application shell: sample picker, solver panel, live bounds, the route drawing with its
//! layers, the animation, exports, and the comparison of kept results.

use cutroute_geometry::{Nest, Objective, PathRoute, Point, Route, Toolpath};
use cutroute_protocol::{
    Document, FromWorker, JobId, JobRequest, Problem, Progress, SolverKind, SolverParams, ToWorker,
};
use leptos::prelude::*;
use wasm_bindgen::JsCast;

use crate::animation::{Animation, AnimationControls, AnimationOverlay};
use crate::chart::{BoundSample, BoundsChart};
use crate::compare::{ComparePanel, Kept};
use crate::drawing::{
    candidate_dots, contour_path, cut_path, cut_paths_by_step, direction_arrows, idle_path,
    link_path, nest_bounds, path_route_idle_path, path_route_toolpath, toolpath_bounds,
};
use crate::export::ExportMenu;
use crate::i18n::{tr, use_language, Lang};
use crate::pan_zoom::{fitted_view, PanZoom, ViewBox};
use crate::settings::{objective_from_name, Layer, Settings};
use crate::stats::{AlternativesTable, StatsPanel};
use crate::thermal::{HeatMapLayer, ThermalPanel, ThermalStats, ThermalView, ViolationMarks};
use crate::words::{format_text, phase_text, solver_label, JobFailure, PageError};
use crate::worker_client::{spawn, DeathReason, SolverWorker, WorkerDeath};

/// Bundled sample nests (files under `assets/samples/`, English and Russian label), the first
/// is opened on start.
pub const SAMPLES: [(&str, &str, &str); 4] = [
    (
        "E1X_6_01.dbs.json",
        "E1X_6_01 — 9 parts with arcs",
        "E1X_6_01 — 9 деталей с дугами",
    ),
    (
        "test1.dbs.json",
        "test1 — 40 contours",
        "test1 — 40 контуров",
    ),
    (
        "nested.dbs",
        "nested — parts inside holes",
        "nested — детали в отверстиях",
    ),
    (
        "seven.dbs",
        "seven — 29 parts, 5,000 points",
        "seven — 29 деталей, 5 000 точек",
    ),
];

/// What the page shows about the current job.
#[derive(Clone, Debug, PartialEq)]
enum JobState {
    Idle,
    Running(JobId),
    Finished,
    Cancelled,
    Failed(JobFailure),
}

impl JobState {
    fn label(&self, lang: Lang) -> String {
        match (self, lang) {
            (JobState::Idle, Lang::En) => "idle".into(),
            (JobState::Idle, Lang::Ru) => "ожидание".into(),
            (JobState::Running(_), Lang::En) => "running".into(),
            (JobState::Running(_), Lang::Ru) => "выполняется".into(),
            (JobState::Finished, Lang::En) => "finished".into(),
            (JobState::Finished, Lang::Ru) => "завершено".into(),
            (JobState::Cancelled, Lang::En) => "cancelled".into(),
            (JobState::Cancelled, Lang::Ru) => "отменено".into(),
            (JobState::Failed(failure), Lang::En) => format!("failed: {}", failure.text(lang)),
            (JobState::Failed(failure), Lang::Ru) => format!("ошибка: {}", failure.text(lang)),
        }
    }
}

/// A continued job reports on its own run; the page shows the better of that and the result it
/// continued from, with the time of both runs added up.
fn continued(from: &Progress, update: Progress) -> Progress {
    let improved = match (update.upper_bound, from.upper_bound) {
        (Some(new), Some(old)) => new < old - 1e-9,
        (Some(_), None) => true,
        (None, _) => false,
    };
    let lower_bound = match (update.lower_bound, from.lower_bound) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    let elapsed_s = from.elapsed_s + update.elapsed_s;
    if improved {
        Progress {
            elapsed_s,
            lower_bound,
            ..update
        }
    } else {
        Progress {
            job_id: update.job_id,
            elapsed_s,
            lower_bound,
            phase: update.phase,
            states: update.states,
            ..from.clone()
        }
    }
}

/// The whole page.
#[component]
pub fn App() -> impl IntoView {
    provide_context(crate::i18n::Language::new());
    let language = use_language();
    let query = web_sys::window()
        .and_then(|w| w.location().search().ok())
        .unwrap_or_default();
    let initial = Settings::load().with_query(&query);
    let lecture_url = crate::gallery::list_url(&query);

    let document = RwSignal::new(None::<Document>);
    let open_error = RwSignal::new(None::<PageError>);
    let progress = RwSignal::new(None::<Progress>);
    let samples = RwSignal::new(Vec::<BoundSample>::new());
    let log_time = RwSignal::new(false);
    let job_state = RwSignal::new(JobState::Idle);
    let solver = RwSignal::new(
        SolverKind::from_name(&initial.solver).unwrap_or(SolverKind::NearestNeighbour),
    );
    let time_limit = RwSignal::new(initial.time_limit_s);
    let seed = RwSignal::new(initial.seed);
    let step_mm = RwSignal::new(initial.step_mm);
    let sample = RwSignal::new(initial.sample.clone());
    let last_file = RwSignal::new(initial.last_file.clone());
    let hidden_layers = RwSignal::new(initial.hidden_layers.clone());
    let next_id = StoredValue::new(1_u64);
    // The result a Continue started from, and how many runs the current result took.
    let continued_from = StoredValue::new(None::<Progress>);
    let runs = StoredValue::new(0_u64);
    let kept = RwSignal::new(Vec::<Kept>::new());
    let machine = RwSignal::new(initial.machine);
    let file_url = RwSignal::new(initial.file_url.clone());
    let gcode_choice = RwSignal::new(crate::export::GcodeChoice::of_preset(
        cutroute_gcode::GcodePreset::Generic,
        &initial.machine,
    ));
    let objective = RwSignal::new(objective_from_name(&initial.objective).unwrap_or_default());
    let thermal_settings = RwSignal::new(initial.thermal);
    let kerf_settings = RwSignal::new(initial.kerf);
    // The tool-on paths a G-code file holds when they are not whole contours.
    let file_paths = RwSignal::new(None::<PathRoute>);
    let presentation = RwSignal::new(false);

    // The page's state, as remembered and as linked.
    let current_settings = move || Settings {
        sample: sample.get(),
        last_file: last_file.get(),
        solver: solver.get().name().to_string(),
        time_limit_s: time_limit.get(),
        seed: seed.get(),
        step_mm: step_mm.get(),
        hidden_layers: hidden_layers.get(),
        objective: objective.get().name().to_string(),
        thermal: thermal_settings.get(),
        file_url: file_url.get(),
        machine: machine.get(),
        sheet: document.with(|d| d.as_ref().map_or(0, |d| d.sheet)),
        kerf: kerf_settings.get(),
    };
    // The link of the page's state; a lecture list other than the bundled one rides along.
    let lecture_query = StoredValue::new(crate::gallery::lecture_query(&lecture_url));
    let link_query =
        move |settings: &Settings| format!("{}{}", settings.query(), lecture_query.get_value());
    // Everything remembered is saved whenever it changes, and the address bar follows it.
    Effect::new(move |_| {
        let settings = current_settings();
        settings.save();
        crate::links::replace_address(&link_query(&settings));
    });

    // Every report of the running job is a point of the bounds chart.
    let record = move |p: &Progress| {
        samples.update(|s| {
            s.push(BoundSample {
                elapsed_s: p.elapsed_s,
                upper_bound: p.upper_bound,
                lower_bound: p.lower_bound,
            })
        })
    };
    let merged = move |update: Progress| match continued_from.get_value() {
        Some(from) => continued(&from, update),
        None => update,
    };

    // Kept so a worker stuck in a long step can be replaced (see `stop`).
    let on_message: StoredValue<std::rc::Rc<dyn Fn(FromWorker)>, LocalStorage> =
        StoredValue::new_local(std::rc::Rc::new(move |message: FromWorker| match message {
            FromWorker::Opened {
                document: mut opened,
                ..
            } => {
                // A task file in the batch brings the machine's speeds (its start and finish
                // are already the document's).
                if let Some(speeds) = opened.task_speeds {
                    machine.update(|m| *m = speeds.applied_to(*m));
                }
                open_error.set(None);
                progress.set(None);
                samples.set(Vec::new());
                continued_from.set_value(None);
                let same_nest = document
                    .with_untracked(|d| d.as_ref().map(|d| &d.problem) == Some(&opened.problem));
                if !same_nest {
                    kept.set(Vec::new());
                }
                file_paths.set(opened.paths.take());
                document.set(Some(opened));
            }
            FromWorker::OpenFailed { error, .. } => open_error.set(Some(PageError::Open(error))),
            FromWorker::Progress(update) => {
                if job_state.get_untracked() == JobState::Running(update.job_id) {
                    let update = merged(update);
                    record(&update);
                    progress.set(Some(update));
                }
            }
            FromWorker::Finished(last) => {
                if job_state.get_untracked() == JobState::Running(last.job_id) {
                    let last = merged(last);
                    record(&last);
                    let missing = missing_tour(&last, document, solver);
                    progress.set(Some(last));
                    job_state.set(missing.map_or(JobState::Finished, JobState::Failed));
                }
            }
            FromWorker::Cancelled(last) => {
                if job_state.get_untracked() == JobState::Running(last.job_id) {
                    progress.set(Some(merged(last)));
                    job_state.set(JobState::Cancelled);
                }
            }
            FromWorker::Failed { job_id, message } => {
                if job_state.get_untracked() == JobState::Running(job_id) {
                    job_state.set(JobState::Failed(JobFailure::Engine(message)));
                }
            }
        }));
    // What to do when the worker dies: set below, once the worker it replaces exists.
    let on_death: StoredValue<std::rc::Rc<dyn Fn(WorkerDeath)>, LocalStorage> =
        StoredValue::new_local(std::rc::Rc::new(|_| {}));
    let spawn_worker = move || {
        let on_message = on_message.get_value();
        spawn(
            move |message| on_message(message),
            move |death| on_death.get_value()(death),
        )
    };
    let bridge: StoredValue<SolverWorker, LocalStorage> = StoredValue::new_local(spawn_worker());
    let worker_notice = RwSignal::new(None::<WorkerNotice>);
    on_death.set_value(std::rc::Rc::new(move |death: WorkerDeath| {
        bridge.set_value(spawn_worker());
        after_worker_death(&death, job_state, open_error, worker_notice);
    }));
    // The notice stays until the next job starts.
    Effect::new(move |_| {
        if matches!(job_state.get(), JobState::Running(_)) {
            worker_notice.set(None);
        }
    });

    let shown_nest = Memo::new(move |_| {
        document.with(|d| match d.as_ref().map(|d| &d.problem) {
            Some(Problem::Nest { nest, .. }) => Some(nest.clone()),
            _ => None,
        })
    });
    let shown_nest = Signal::from(shown_nest);
    // The solver's best route of tool-on paths (segment cutting, AOE), or else the tool-on
    // paths of a G-code file that cuts open paths.
    let shown_paths =
        Memo::new(
            move |_| match progress.with(|p| p.as_ref().map(|p| p.path_route.clone())) {
                Some(paths) => paths,
                None => file_paths.get(),
            },
        );
    let shown_paths = Signal::from(shown_paths);
    // The solver's best route, or else the route the file holds (result files); none while
    // tool-on paths are shown.
    let shown_route = Memo::new(move |_| {
        if shown_paths.with(Option::is_some) {
            return None;
        }
        progress
            .with(|p| p.as_ref().and_then(|p| p.route.clone()))
            .or_else(|| document.with(|d| d.as_ref().and_then(|d| d.route.clone())))
    });
    let shown_route = Signal::from(shown_route);
    // The head's moves of what is shown: drawn, animated and exported.
    let shown_toolpath = Memo::new(move |_| {
        shown_nest.with(|nest: &Option<Nest>| {
            let nest = nest.as_ref()?;
            match shown_route.get() {
                Some(route) => Toolpath::new(&route, nest).ok(),
                None => shown_paths.with(|p| p.as_ref().map(|p| path_route_toolpath(p, nest))),
            }
        })
    });
    let shown_toolpath = Signal::from(shown_toolpath);
    let alternatives = Signal::derive(move || {
        progress.with(|p| {
            p.as_ref()
                .map(|p| p.alternatives.clone())
                .unwrap_or_default()
        })
    });
    // What the bounds measure: the objective for the solvers that minimise it, else idle mm.
    let bound_unit = Signal::derive(move || {
        let instance = document.with(|d| {
            d.as_ref()
                .is_some_and(|d| matches!(d.problem, Problem::PcgtspText { .. }))
        });
        let lang = language.get();
        if instance {
            lang.pick("tour cost", "стоимость обхода")
        } else if solver.get().gives_path_route() {
            objective_unit(objective.get(), lang)
        } else {
            lang.pick("mm idle", "мм холостого хода")
        }
    });
    let certified = Memo::new(move |_| {
        progress.with(|p| p.as_ref().map(|p| p.certified.clone()).unwrap_or_default())
    });
    let thermal_view = ThermalView::new(
        thermal_settings,
        shown_nest,
        shown_route,
        shown_paths,
        machine,
        progress,
    );
    let animation = Animation::new(
        shown_toolpath,
        machine,
        Signal::derive(move || {
            if shown_paths.with(Option::is_some) {
                "path"
            } else {
                "contour"
            }
        }),
    );
    let file_name =
        Signal::derive(move || document.with(|d| d.as_ref().map(|d| d.file_name.clone())));

    let take_id = move || {
        let id = next_id.get_value();
        next_id.set_value(id + 1);
        id
    };

    // The single file shown last, kept so another of its sheets can be opened.
    let opened_file: StoredValue<Option<(String, Vec<u8>)>> = StoredValue::new(None);
    let open_sample = move |file_name: String| {
        let request_id = take_id();
        sample.set(file_name.clone());
        file_url.set(None);
        leptos::task::spawn_local(async move {
            let url = format!("./assets/samples/{file_name}");
            match fetch_bytes(&url).await {
                Ok(bytes) => {
                    opened_file.set_value(Some((file_name.clone(), bytes.clone())));
                    bridge.with_value(|b| {
                        b.send(ToWorker::Open {
                            request_id,
                            files: vec![(file_name, bytes)],
                        })
                    })
                }
                Err(message) => open_error.set(Some(PageError::Fetch { url, message })),
            }
        });
    };
    // A hosted nest (`?file=URL`, `&sheet=N` of a multi-sheet one): fetched here, opened by the
    // worker like a dropped file.
    let open_url = move |url: String, sheet: usize| {
        let request_id = take_id();
        file_url.set(Some(url.clone()));
        last_file.set(None);
        leptos::task::spawn_local(async move {
            match fetch_bytes(&url).await {
                Ok(bytes) => {
                    let name = crate::links::file_name_of(&url);
                    opened_file.set_value(Some((name.clone(), bytes.clone())));
                    bridge.with_value(|b| {
                        b.send(if sheet > 0 {
                            ToWorker::OpenSheet {
                                request_id,
                                file: (name, bytes),
                                sheet,
                            }
                        } else {
                            ToWorker::Open {
                                request_id,
                                files: vec![(name, bytes)],
                            }
                        })
                    })
                }
                Err(message) => open_error.set(Some(PageError::Fetch { url, message })),
            }
        });
    };
    match initial.file_url.clone() {
        Some(url) => open_url(url, initial.sheet),
        None => open_sample(initial.sample.clone()),
    }
    // Another sheet of the multi-sheet file shown.
    let open_sheet = Callback::new(move |sheet: usize| {
        if let Some(file) = opened_file.get_value() {
            let request_id = take_id();
            bridge.with_value(|b| {
                b.send(ToWorker::OpenSheet {
                    request_id,
                    file,
                    sheet,
                })
            });
        }
    });
    // A lecture card: its settings as a link would set them, then its nest.
    let pick_lecture = Callback::new(move |(url, query): (String, String)| {
        // A card's file starts at its first sheet unless the card names another.
        let s = Settings {
            sheet: 0,
            ..current_settings()
        }
        .with_query(&query);
        if let Some(kind) = SolverKind::from_name(&s.solver) {
            solver.set(kind);
        }
        time_limit.set(s.time_limit_s);
        seed.set(s.seed);
        step_mm.set(s.step_mm);
        objective.set(objective_from_name(&s.objective).unwrap_or_default());
        thermal_settings.set(s.thermal);
        kerf_settings.set(s.kerf);
        machine.set(s.machine);
        hidden_layers.set(s.hidden_layers);
        last_file.set(None);
        match crate::gallery::bundled_sample(&url) {
            Some(name) => open_sample(name),
            None => open_url(url, s.sheet),
        }
    });

    // Local files (picker or drag and drop) go to the worker as bytes, all in one request: the
    // engine's one door decides what they are and how they combine (a nest with its task and
    // a PCGLNS result, an instance with its result), off the UI thread.
    let open_files = move |files: web_sys::FileList| {
        let files: Vec<web_sys::File> = (0..files.length()).filter_map(|i| files.item(i)).collect();
        leptos::task::spawn_local(async move {
            let mut batch = Vec::new();
            for file in files {
                match read_file(&file).await {
                    Ok(bytes) => batch.push((file.name(), bytes)),
                    Err(message) => open_error.set(Some(PageError::Read {
                        file_name: file.name(),
                        message,
                    })),
                }
            }
            if batch.is_empty() {
                return;
            }
            let names: Vec<String> = batch.iter().map(|(n, _)| n.clone()).collect();
            last_file.set(Some(names.join(" + ")));
            file_url.set(None);
            opened_file.set_value((batch.len() == 1).then(|| batch[0].clone()));
            let request_id = take_id();
            bridge.with_value(|b| {
                b.send(ToWorker::Open {
                    request_id,
                    files: batch,
                })
            });
        });
    };

    // Start a job; `from` is the result a Continue restarts from.
    let launch = move |from: Option<Progress>| {
        let Some(Document { problem, .. }) = document.get_untracked() else {
            return;
        };
        let job_id = take_id();
        let run = if from.is_some() {
            runs.get_value() + 1
        } else {
            0
        };
        runs.set_value(run);
        let params = SolverParams {
            time_limit_s: time_limit.get_untracked(),
            // A continued run explores with another seed, pruned by the best cost found.
            seed: seed.get_untracked().wrapping_add(run),
            discretisation_step_mm: step_mm.get_untracked(),
            initial_upper_bound: from.as_ref().and_then(|p| p.upper_bound),
            // The stats panel's speeds and prices: chain cutting decides by this cost model.
            machine: machine.get_untracked(),
            objective: objective.get_untracked(),
            thermal: thermal_settings.get_untracked(),
            // The full cutting route: the engine's kerf job fits and optimises the leads.
            kerf: kerf_settings.get_untracked(),
            leads_after: false,
        };
        let solver_kind = solver.get_untracked();
        // Refused here, in the page's words (the engine's refusal is English), and before the
        // shown result is cleared.
        if !params.kerf.is_idealised() && !solver_kind.cuts_with_kerf() {
            job_state.set(JobState::Failed(JobFailure::NoKerfModel {
                solver: solver_kind.name(),
            }));
            return;
        }
        if from.is_none() {
            progress.set(None);
            samples.set(Vec::new());
        }
        continued_from.set_value(from);
        job_state.set(JobState::Running(job_id));
        let request = JobRequest {
            job_id,
            problem,
            solver: solver_kind,
            params,
        };
        bridge.with_value(|b| b.send(ToWorker::Start(request)));
    };
    let stop = move |_| {
        if let JobState::Running(job_id) = job_state.get_untracked() {
            bridge.with_value(|b| b.send(ToWorker::Cancel { job_id }));
            // The worker answers between solver steps, which the jobs keep short (their long
            // phases run in slices), so the job stops itself. A step that still runs long (the
            // few single pieces listed in BENCHMARKS.md, "Time limits in the engine") would
            // hold Stop up: as a safety net, after 150 ms the job is dropped with the best
            // result already received and a fresh worker takes over (the old one is told to
            // close, and its late messages name a job that is no longer running), so Stop
            // takes effect within the promised 200 ms, page updates included. The net firing
            // is logged and marked on the page (`data-stop-fallback` = the job's id), so tests
            // can tell a job that stopped itself from one that was replaced.
            set_timeout(
                move || {
                    if job_state.get_untracked() == JobState::Running(job_id) {
                        leptos::logging::warn!(
                            "Stop: job {job_id} did not stop itself within 150 ms; its worker \
                             was replaced"
                        );
                        if let Some(root) = web_sys::window()
                            .and_then(|w| w.document())
                            .and_then(|d| d.document_element())
                        {
                            let _ = root.set_attribute("data-stop-fallback", &job_id.to_string());
                        }
                        bridge.set_value(spawn_worker());
                        job_state.set(JobState::Cancelled);
                    }
                },
                std::time::Duration::from_millis(150),
            );
        }
    };
    let running = move || matches!(job_state.get(), JobState::Running(_));
    let can_continue = move || {
        !running()
            && progress.with(|p| p.as_ref().is_some_and(|p| p.upper_bound.is_some()))
            && !progress.with(|p| p.as_ref().is_some_and(|p| p.proven_optimal))
    };

    // Presentation mode: large fonts and the whole screen (F toggles it outside text fields).
    // While a request for full screen is pending, a "left full screen" event is the late echo
    // of an earlier exit (F pressed twice quickly), not the user pressing Esc.
    let entering_fullscreen = StoredValue::new(false);
    Effect::new(move |_| {
        let on = presentation.get();
        let Some(doc) = web_sys::window().and_then(|w| w.document()) else {
            return;
        };
        if let Some(root) = doc.document_element() {
            let _ = if on {
                root.set_attribute("data-presentation", "on")
            } else {
                root.remove_attribute("data-presentation")
            };
            if on && doc.fullscreen_element().is_none() {
                entering_fullscreen.set_value(true);
                request_fullscreen(&root, move || entering_fullscreen.set_value(false));
            } else if !on && doc.fullscreen_element().is_some() {
                doc.exit_fullscreen();
            }
        }
    });
    let keys = window_event_listener(leptos::ev::keydown, move |ev| {
        let typing = ev
            .target()
            .and_then(|t| t.dyn_into::<web_sys::Element>().ok())
            .is_some_and(|e| matches!(e.tag_name().as_str(), "INPUT" | "SELECT" | "TEXTAREA"));
        if typing || ev.ctrl_key() || ev.meta_key() || ev.alt_key() {
            return;
        }
        if ev.key() == "f" || ev.key() == "F" {
            ev.prevent_default();
            presentation.update(|p| *p = !*p);
        }
    });
    on_cleanup(move || keys.remove());
    // Leaving full screen with Esc leaves presentation mode too.
    let fullscreen = window_event_listener_untyped("fullscreenchange", move |_| {
        let full = web_sys::window()
            .and_then(|w| w.document())
            .is_some_and(|d| d.fullscreen_element().is_some());
        if !full && presentation.get_untracked() && !entering_fullscreen.get_value() {
            presentation.set(false);
        }
    });
    on_cleanup(move || fullscreen.remove());

    let share_link = move || crate::links::page_link(&link_query(&current_settings()));

    // H of the shown route under the panel's σ and τ, for the comparison table.
    let shown_heat = move || {
        let model = thermal_settings.with_untracked(|s| s.model().ok())?;
        Some(thermal_view.sources.with_untracked(|s| model.load(s)))
    };
    let keep = move |_| {
        let label = progress
            .with_untracked(|p| {
                p.as_ref().map(|_| {
                    let kind = solver.get_untracked();
                    (solver_label(Lang::En, kind), solver_label(Lang::Ru, kind))
                })
            })
            .unwrap_or(("from the file", "из файла"));
        let entry = if let Some(paths) = shown_paths.get_untracked() {
            machine.with_untracked(|m| Kept::of_paths(&paths, m, label, shown_heat()))
        } else {
            let (Some(nest), Some(route)) =
                (shown_nest.get_untracked(), shown_route.get_untracked())
            else {
                return;
            };
            machine.with_untracked(|m| Kept::new(&nest, &route, m, label, shown_heat()))
        };
        kept.update(|k| {
            let id = k.iter().map(|e| e.id).max().unwrap_or(0) + 1;
            k.push(Kept { id, ..entry });
        });
    };

    view! {
        <header class="toolbar">
            <h1>"cutroute"</h1>
            <label>
                {tr("Sample ", "Пример ")}
                <select
                    id="sample"
                    aria-label=tr("Sample nest", "Пример раскроя")
                    prop:value=move || sample.get()
                    on:change=move |ev| {
                        last_file.set(None);
                        open_sample(event_target_value(&ev));
                    }
                >
                    {SAMPLES
                        .iter()
                        .map(|(file, en, ru)| {
                            view! {
                                <option value=*file selected=*file == initial.sample>
                                    {tr(en, ru)}
                                </option>
                            }
                        })
                        .collect_view()}
                </select>
            </label>
            <label class="file-button">
                {tr("Open files… ", "Открыть файлы… ")}
                <input
                    id="file-input"
                    type="file"
                    multiple
                    aria-label=tr("Open nest or instance files", "Открыть файлы раскроя или задачи")
                    on:change=move |ev| {
                        let input: web_sys::HtmlInputElement = event_target(&ev);
                        if let Some(files) = input.files() {
                            open_files(files);
                        }
                        input.set_value("");
                    }
                />
            </label>
            <crate::sheets::SheetPicker document=document open=open_sheet />
            <ExportMenu
                file_name=file_name
                nest=shown_nest
                route=shown_route
                paths=shown_paths
                toolpath=shown_toolpath
                machine=machine
                choice=gcode_choice
            />
            <crate::gallery::LectureGallery list_url=lecture_url pick=pick_lecture />
            <crate::theme::ThemePicker />
            <crate::i18n::LanguagePicker />
            <button
                id="present"
                aria-pressed=move || presentation.get().to_string()
                title=tr(
                    "Presentation mode: large fonts, full screen (key F)",
                    "Режим показа: крупный шрифт, полный экран (клавиша F)",
                )
                on:click=move |_| presentation.update(|p| *p = !*p)
            >
                {tr("Present", "Показ")}
            </button>
        </header>
        <section class="solver-panel" aria-label=tr("Solver", "Решатель")>
            <label title=tr("Which algorithm routes the tool", "Какой алгоритм строит маршрут инструмента")>
                {tr("Solver ", "Решатель ")}
                <select
                    id="solver"
                    aria-label=tr("Solver", "Решатель")
                    prop:value=move || solver.get().name()
                    on:change=move |ev| {
                        if let Some(kind) = SolverKind::from_name(&event_target_value(&ev)) {
                            solver.set(kind);
                        }
                    }
                >
                    {SolverKind::ALL
                        .iter()
                        .map(|kind| {
                            view! {
                                <option value=kind.name() selected=kind.name() == initial.solver>
                                    {move || solver_label(language.get(), *kind)}
                                </option>
                            }
                        })
                        .collect_view()}
                </select>
            </label>
            <label title=tr(
                "What routes are compared by, and what GSCCP picks its ensemble by (machine parameters in the stats panel)",
                "По какому критерию сравниваются маршруты и GSCCP выбирает ансамбль (параметры станка — в панели показателей)",
            )>
                {tr("Objective ", "Критерий ")}
                <select
                    id="objective"
                    aria-label=tr("Objective", "Критерий")
                    prop:value=move || objective.get().name()
                    on:change=move |ev| {
                        if let Some(o) = objective_from_name(&event_target_value(&ev)) {
                            objective.set(o);
                        }
                    }
                >
                    <option value="time" selected=initial.objective == "time">{tr("machine time", "время работы станка")}</option>
                    <option value="cost" selected=initial.objective == "cost">{tr("cost", "стоимость")}</option>
                </select>
            </label>
            <NumberField
                id="time-limit"
                label=("Time limit, s", "Лимит времени, с")
                tip=(
                    "Wall-clock time the solver may run; it stops earlier when it proves optimality",
                    "Сколько времени может работать решатель; он останавливается раньше, если доказал оптимальность",
                )
                min="0.1"
                value=time_limit
            />
            <label title=tr(
                "Seed of the solver's random choices: the same seed repeats a run",
                "Зерно случайного выбора решателя: с тем же зерном запуск повторяется",
            )>
                {tr("Seed ", "Зерно ")}
                <input
                    id="seed"
                    type="number"
                    min="0"
                    step="1"
                    prop:value=move || seed.get().to_string()
                    on:change=move |ev| {
                        if let Ok(v) = event_target_value(&ev).parse::<u64>() {
                            seed.set(v);
                        }
                    }
                />
            </label>
            <NumberField
                id="step"
                label=("Pierce step, mm", "Шаг точек врезки, мм")
                tip=(
                    "Discrete solvers: spacing of candidate pierce points along each contour (smaller = finer, slower)",
                    "Дискретные решатели: шаг точек врезки-кандидатов вдоль каждого контура (меньше — точнее, но дольше)",
                )
                min="0.1"
                value=step_mm
            />
            <button id="start" on:click=move |_| launch(None) disabled=move || running() || document.get().is_none()>
                {tr("Start", "Пуск")}
            </button>
            <button id="stop" on:click=stop disabled=move || !running()>
                {tr("Stop", "Стоп")}
            </button>
            <button
                id="continue"
                title=tr(
                    "Run again from the best result so far (another seed, pruned by its cost)",
                    "Запустить снова от лучшего результата (другое зерно, отсечение по его стоимости)",
                )
                disabled=move || !can_continue()
                on:click=move |_| launch(progress.get_untracked())
            >
                {tr("Continue", "Продолжить")}
            </button>
            <label class="share" title=tr(
                "A link that opens this sample with these solver settings",
                "Ссылка, открывающая этот пример с этими настройками решателя",
            )>
                {tr("Link ", "Ссылка ")}
                <input id="share-link" type="text" readonly prop:value=share_link />
            </label>
            <crate::links::CopyLinkButton link=Signal::derive(share_link) />
            <p id="solver-uses" class="note">{move || solver_uses(solver.get(), language.get())}</p>
        </section>
        <main class="workspace">
            <section
                class="view"
                aria-label=tr("Cutting plan", "Карта раскроя")
                on:dragover=move |ev: web_sys::DragEvent| ev.prevent_default()
                on:drop=move |ev: web_sys::DragEvent| {
                    ev.prevent_default();
                    if let Some(files) = ev.data_transfer().and_then(|d| d.files()) {
                        open_files(files);
                    }
                }
            >
                {move || open_error.get().map(|e| view! { <p class="error" role="alert">{e.text(language.get())}</p> })}
                {move || worker_notice.get().map(|n| view! { <p id="worker-notice" class="error" role="status">{n.text(language.get())}</p> })}
                // What the reader left out or approximated, and what was checked on opening.
                {move || {
                    let notes = document.with(|d| d.as_ref().map(|d| d.warnings.clone()).unwrap_or_default());
                    (!notes.is_empty()).then(|| {
                        view! {
                            <ul id="open-notes" class="note" aria-label=tr("Notes on the open file", "Замечания к открытому файлу")>
                                {notes.into_iter().map(|n| view! { <li>{n}</li> }).collect_view()}
                            </ul>
                        }
                    })
                }}
                // A local file cannot be reopened without the user: say which one it was.
                {move || {
                    last_file
                        .get()
                        .filter(|f| file_name.with(|shown| shown.as_ref() != Some(f)))
                        .map(|f| {
                            view! {
                                <p id="last-file" class="note">
                                    {tr("Last time ", "В прошлый раз был открыт ")} <strong>{f}</strong>
                                    {tr(
                                        " was open: choose it again with Open files… (the sample is shown meanwhile)",
                                        ": выберите его снова через «Открыть файлы…» (пока показан пример)",
                                    )}
                                </p>
                            }
                        })
                }}
                <NestView
                    nest=shown_nest
                    route=shown_route
                    paths=shown_paths
                    certified=certified
                    hidden_layers=hidden_layers
                    candidates_step=Signal::derive(move || {
                        matches!(solver.get(), SolverKind::Heuristic | SolverKind::Exact)
                            .then(|| step_mm.get())
                    })
                    kept=kept
                    animation=animation
                    thermal=thermal_view
                />
                <AnimationControls animation=animation />
            </section>
            <aside class="stats" aria-label=tr("Job status", "Состояние задачи")>
                <crate::announce::ProgressAnnouncer progress=progress ended=Signal::derive(move || !running()) />
                <dl>
                    <dt>{tr("File", "Файл")}</dt>
                    <dd id="file-name">
                        {move || document.get().map(|d| format!("{} ({})", d.file_name, format_text(language.get(), &d.format))).unwrap_or_default()}
                    </dd>
                    <dt>{tr("Job", "Задача")}</dt>
                    <dd id="job-status">{move || job_state.get().label(language.get())}</dd>
                    <dt>{tr("Phase", "Этап")}</dt>
                    <dd id="phase">
                        {move || progress.with(|p| p.as_ref().map(|p| phase_text(language.get(), &p.phase))).unwrap_or_default()}
                        // Phases that count towards a total (the exact model's matrix rows)
                        // show how far they are.
                        {move || progress.with(|p| p.as_ref().and_then(|p| p.phase.fraction())).map(|(done, total)| {
                            view! {
                                <progress
                                    id="phase-progress"
                                    max=total.max(1)
                                    value=done
                                    aria-label=tr("Phase progress", "Ход этапа")
                                ></progress>
                            }
                        })}
                    </dd>
                    <dt>{tr("Upper bound", "Верхняя оценка")}</dt>
                    <dd id="upper-bound" data-unit=move || bound_unit.get()>{move || format_bound(progress.get().and_then(|p| p.upper_bound))}</dd>
                    <dt>{tr("Lower bound", "Нижняя оценка")}</dt>
                    <dd id="lower-bound">{move || format_bound(progress.get().and_then(|p| p.lower_bound))}</dd>
                    <dt>{tr("Gap", "Разрыв")}</dt>
                    <dd id="gap">
                        {move || progress.get().and_then(|p| {
                            let gap = format!("{:.2} %", p.gap()? * 100.0);
                            let proven = language.pick("proven optimal", "оптимальность доказана");
                            Some(if p.proven_optimal { format!("{gap} · {proven}") } else { gap })
                        }).unwrap_or_else(|| "—".into())}
                    </dd>
                    <dt>{tr("Elapsed", "Прошло")}</dt>
                    <dd id="elapsed">{move || progress.get().map(|p| format!("{:.2} {}", p.elapsed_s, language.pick("s", "с"))).unwrap_or_default()}</dd>
                    <dt>{tr("Certified", "Подтверждено")}</dt>
                    <dd id="certified-count">
                        {move || certified.with(|c| {
                            if c.is_empty() {
                                "—".to_string()
                            } else {
                                let of = language.pick("of", "из");
                                format!("{} {of} {}", c.iter().filter(|x| **x).count(), c.len())
                            }
                        })}
                    </dd>
                </dl>
                <StatsPanel nest=shown_nest route=shown_route paths=shown_paths machine=machine />
                <crate::kerf::LeadStats route=shown_route />
                <crate::profiles::ProfilesPanel machine=machine kerf=kerf_settings choice=gcode_choice />
                <crate::kerf::KerfPanel settings=kerf_settings />
                <ThermalPanel settings=thermal_settings />
                <ThermalStats progress=progress />
                <AlternativesTable alternatives=alternatives />
                <BoundsChart samples=samples log_time=log_time unit=bound_unit />
                <LayerPanel hidden=hidden_layers />
                <crate::legend::DrawingLegend />
                <ComparePanel
                    kept=kept
                    keep=keep
                    can_keep=Signal::derive(move || shown_route.with(Option::is_some) || shown_paths.with(Option::is_some))
                    objective=Signal::from(objective)
                />
            </aside>
        </main>
    }
}

/// A PCGTSP job that ended without a tour failed: proved infeasible, or none found (the CLI's
/// words, exit 3 there).
fn missing_tour(
    last: &Progress,
    document: RwSignal<Option<Document>>,
    solver: RwSignal<SolverKind>,
) -> Option<JobFailure> {
    let instance = document.with_untracked(|d| {
        d.as_ref()
            .is_some_and(|d| matches!(d.problem, Problem::PcgtspText { .. }))
    });
    if !instance {
        return None;
    }
    // `Progress::missing_tour`'s cases (the CLI's words), as data the page words itself.
    let solver = solver.get_untracked().name();
    if last.tour.is_some() {
        None
    } else if last.proven_optimal {
        Some(JobFailure::NoTourExists { solver })
    } else {
        Some(JobFailure::NoTourFound {
            solver,
            seconds: last.elapsed_s,
        })
    }
}

/// The notice after the worker died and was restarted.
#[derive(Clone, Debug, PartialEq)]
struct WorkerNotice {
    reason: DeathReason,
    job_lost: bool,
}

impl WorkerNotice {
    fn text(&self, lang: Lang) -> String {
        let reason = self.reason.text(lang);
        match (lang, self.job_lost) {
            (Lang::En, lost) => format!(
                "The solver stopped unexpectedly ({reason}) and was restarted; {}",
                if lost {
                    "the best route received before is kept: Start or Continue runs the job again."
                } else {
                    "nothing was lost."
                }
            ),
            (Lang::Ru, lost) => format!(
                "Решатель неожиданно остановился ({reason}) и перезапущен; {}",
                if lost {
                    "полученный ранее лучший маршрут сохранён: «Пуск» или «Продолжить» \
                     запускают задачу снова."
                } else {
                    "ничего не потеряно."
                }
            ),
        }
    }
}

/// After the worker died and a fresh one took over (`src/worker_client.rs`): what was lost is
/// said, and nothing else changes. The document stays open (every job request carries its
/// problem, so the fresh worker needs nothing re-sent) and so does the best route received
/// from the job, which Continue can start from. An open in flight is not retried: the file
/// may be what killed the worker.
fn after_worker_death(
    death: &WorkerDeath,
    job_state: RwSignal<JobState>,
    open_error: RwSignal<Option<PageError>>,
    worker_notice: RwSignal<Option<WorkerNotice>>,
) {
    let job_lost =
        matches!(job_state.get_untracked(), JobState::Running(id) if death.jobs.contains(&id));
    if job_lost {
        job_state.set(JobState::Failed(JobFailure::WorkerStopped));
    }
    if !death.opening.is_empty() {
        open_error.set(Some(PageError::WorkerDiedOpening {
            files: death.opening.join(" + "),
            reason: death.reason.clone(),
        }));
    }
    worker_notice.set(Some(WorkerNotice {
        reason: death.reason.clone(),
        job_lost,
    }));
}

/// Hues the tool-on paths of a path route take in turn (`.hue-0` … `.hue-5` in `style/`).
const PATH_HUES: usize = 6;

/// A labelled positive number input with a tooltip (label and tip in English and Russian).
#[component]
fn NumberField(
    id: &'static str,
    label: (&'static str, &'static str),
    tip: (&'static str, &'static str),
    min: &'static str,
    value: RwSignal<f64>,
) -> impl IntoView {
    view! {
        <label title=tr(tip.0, tip.1)>
            {tr(label.0, label.1)} " "
            <input
                id=id
                type="number"
                min=min
                step="any"
                prop:value=move || value.get().to_string()
                on:change=move |ev| {
                    if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                        if v > 0.0 && v.is_finite() {
                            value.set(v);
                        }
                    }
                }
            />
        </label>
    }
}

/// A checkbox per drawing layer.
#[component]
fn LayerPanel(hidden: RwSignal<Vec<Layer>>) -> impl IntoView {
    let language = use_language();
    view! {
        <fieldset class="layers">
            <legend>{tr("Layers", "Слои")}</legend>
            {Layer::ALL
                .into_iter()
                .map(|layer| {
                    view! {
                        <label>
                            <input
                                type="checkbox"
                                id=format!("layer-{}", layer.name())
                                prop:checked=move || hidden.with(|h| !h.contains(&layer))
                                on:change=move |ev| {
                                    let show = event_target_checked(&ev);
                                    hidden.update(|h| {
                                        h.retain(|l| *l != layer);
                                        if !show {
                                            h.push(layer);
                                        }
                                    });
                                }
                            />
                            " "
                            {move || layer.label(language.get())}
                        </label>
                    }
                })
                .collect_view()}
        </fieldset>
    }
}

/// The unit of an objective's values, as the chart and bounds show it.
fn objective_unit(objective: Objective, lang: Lang) -> &'static str {
    match objective {
        Objective::Time => lang.pick("s (machine time)", "с (время работы станка)"),
        Objective::Cost => lang.pick("cost", "стоимость"),
    }
}

/// Which of the panel's parameters a solver uses, in words.
fn solver_uses(kind: SolverKind, lang: Lang) -> &'static str {
    if lang == Lang::Ru {
        return match kind {
            SolverKind::NearestNeighbour => "Использует: только раскрой (жадный алгоритм, один проход); оценка — длина холостого хода, мм.",
            SolverKind::Ccp => "Использует: лимит времени, зерно; оценка — длина холостого хода, мм.",
            SolverKind::Heuristic => "Использует: лимит времени, зерно, шаг точек врезки; оценка — длина холостого хода, мм.",
            SolverKind::Exact => "Использует: лимит времени, зерно, шаг точек врезки; оценки — длина холостого хода, мм.",
            SolverKind::Chain => "Использует: лимит времени, зерно, цены станка (переход с включённым инструментом заменяет врезку, если дешевле); оценка — длина холостого хода, мм.",
            SolverKind::Sccp => "Использует: лимит времени, зерно, критерий, скорости и цены станка; оценка — значение критерия.",
            SolverKind::Gsccp => "Использует: лимит времени, зерно, критерий (по нему выбирается лучший ансамбль), скорости и цены станка; оценка — значение критерия.",
            SolverKind::Aoe => "Использует: критерий, скорости и цены станка (общие кромки режутся один раз); оценка — значение критерия.",
        };
    }
    match kind {
        SolverKind::NearestNeighbour => "Uses: the nest only (greedy, one pass); bound = idle length, mm.",
        SolverKind::Ccp => "Uses: time limit, seed; bound = idle length, mm.",
        SolverKind::Heuristic => "Uses: time limit, seed, pierce step; bound = idle length, mm.",
        SolverKind::Exact => "Uses: time limit, seed, pierce step; bounds = idle length, mm.",
        SolverKind::Chain => "Uses: time limit, seed, machine prices (a link replaces a pierce when it costs less); bound = idle length, mm.",
        SolverKind::Sccp => "Uses: time limit, seed, objective, machine speeds and prices; bound = the objective's value.",
        SolverKind::Gsccp => "Uses: time limit, seed, objective (picks the best ensemble), machine speeds and prices; bound = the objective's value.",
        SolverKind::Aoe => "Uses: objective, machine speeds and prices (common edges cut once); bound = the objective's value.",
    }
}

fn format_bound(value: Option<f64>) -> String {
    value
        .map(|v| format!("{v:.1}"))
        .unwrap_or_else(|| "—".into())
}

/// Asks for full screen and calls `settled` once the request is granted or refused; a
/// refusal (no user gesture, a browser without it) is ignored, so it never surfaces as an
/// unhandled rejection: large fonts still apply.
fn request_fullscreen(element: &web_sys::Element, settled: impl FnOnce() + 'static) {
    let Ok(method) = js_sys::Reflect::get(element, &"requestFullscreen".into()) else {
        return settled();
    };
    let Some(method) = method.dyn_ref::<js_sys::Function>() else {
        return settled();
    };
    match method
        .call0(element)
        .ok()
        .and_then(|answer| answer.dyn_into::<js_sys::Promise>().ok())
    {
        Some(promise) => leptos::task::spawn_local(async move {
            let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
            settled();
        }),
        None => settled(),
    }
}

pub(crate) async fn read_file(file: &web_sys::File) -> Result<Vec<u8>, String> {
    let buffer = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
        .await
        .map_err(|e| format!("{e:?}"))?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}

pub(crate) async fn fetch_bytes(url: &str) -> Result<Vec<u8>, String> {
    if let Some(bytes) = crate::embedded::file(url) {
        return Ok(bytes);
    }
    let response = gloo_net::http::Request::get(url)
        .send()
        .await
        .map_err(|e| e.to_string())?;
    if !response.ok() {
        return Err(format!("HTTP {}", response.status()));
    }
    response.binary().await.map_err(|e| e.to_string())
}

/// The drawing: sheet, parts and the route's layers, y axis up.
#[component]
fn NestView(
    nest: Signal<Option<Nest>>,
    route: Signal<Option<Route>>,
    paths: Signal<Option<PathRoute>>,
    certified: Memo<Vec<bool>>,
    hidden_layers: RwSignal<Vec<Layer>>,
    candidates_step: Signal<Option<f64>>,
    kept: RwSignal<Vec<Kept>>,
    animation: Animation,
    thermal: ThermalView,
) -> impl IntoView {
    let language = use_language();
    // The nest's box; for a nest with nothing to draw (a G-code program of open paths), the
    // box of the head's moves.
    let fit = Memo::new(move |_| {
        let nest_box = nest.with(|n| n.as_ref().and_then(nest_bounds));
        // Tool-on paths may leave the nest's box (a program's paths over the loops they
        // close): the view takes in their moves too.
        let paths_box = if paths.with(Option::is_some) || nest_box.is_none() {
            animation
                .timeline
                .with(|t| t.as_ref().and_then(|t| toolpath_bounds(&t.toolpath)))
        } else {
            None
        };
        match (nest_box, paths_box) {
            (Some(n), Some(p)) => Some(n.union(p)),
            (n, p) => n.or(p),
        }
        .map(fitted_view)
    });
    let fit: Signal<Option<ViewBox>> = Signal::from(fit);
    // Size of the drawing: fixed-size marks (arrows, dots, numbers) scale with it.
    let extent = Memo::new(move |_| fit.get().map_or(100.0, |f| f[2].max(f[3])));
    let pan_zoom = PanZoom::new(fit);
    // A new drawing starts fitted, with the animation rewound.
    Effect::new(move |_| {
        nest.track();
        pan_zoom.reset();
        animation.playing.set(false);
        animation.time.set(None);
    });
    let view_box = move || {
        pan_zoom
            .current()
            .map(|[x, y, w, h]| format!("{x} {y} {w} {h}"))
    };
    let view_width =
        Signal::derive(move || pan_zoom.current().map_or(100.0, |[_, _, w, h]| w.max(h)));
    let classes = move || {
        hidden_layers.with(|hidden| {
            let mut c = String::from("nest");
            for layer in hidden {
                c.push_str(" hide-");
                c.push_str(layer.name());
            }
            c
        })
    };
    let parts = move || {
        nest.with(|n| {
            n.as_ref().map(|n| {
                n.parts
                    .iter()
                    .enumerate()
                    .map(|(i, part)| {
                        let mut d = String::new();
                        part.contours.iter().for_each(|c| contour_path(c, &mut d));
                        let count = part.contours.len();
                        let title = match language.get() {
                            Lang::En => format!(
                                "part {} “{}”, {count} contour{}",
                                i + 1,
                                part.name,
                                if count == 1 { "" } else { "s" }
                            ),
                            Lang::Ru => {
                                format!("деталь {} «{}», контуров: {count}", i + 1, part.name)
                            }
                        };
                        view! { <path class="part" d=d><title>{title}</title></path> }
                    })
                    .collect_view()
            })
        })
    };
    let sheet = move || {
        nest.with(|n| {
            n.as_ref().and_then(|n| n.sheet.as_ref()).map(|sheet| {
                let mut d = String::new();
                sheet.contours.iter().for_each(|c| contour_path(c, &mut d));
                d
            })
        })
    };
    let arrows = move || {
        let size = extent.get() / 60.0;
        nest.with(|n| n.as_ref().map(|n| direction_arrows(n, size)))
    };
    let candidates = move || {
        let step = candidates_step.get()?;
        nest.with(|n| n.as_ref().map(|n| candidate_dots(n, step)))
    };
    // A route of whole contours: its cuts in one path. Tool-on paths: coloured in turn (six
    // hues, distinct in every theme), so where one path ends and the next begins shows; one
    // element per hue, not per path: 5,000 path elements slowed every animation frame of the
    // view (Layout and Layerize, BENCHMARKS.md). The pierce marks name each path on hover.
    let cuts = move || {
        if paths.with(Option::is_some) {
            return None;
        }
        animation
            .timeline
            .with(|t| t.as_ref().map(|t| cut_path(&t.toolpath)))
    };
    let tool_on_paths = move || {
        if paths.with(Option::is_none) {
            return None;
        }
        animation.timeline.with(|t| {
            let t = t.as_ref()?;
            let mut hues = vec![(String::new(), 0_usize); PATH_HUES];
            for (k, d) in cut_paths_by_step(&t.toolpath).into_iter().enumerate() {
                let (all, count) = &mut hues[k % PATH_HUES];
                all.push_str(&d);
                *count += 1;
            }
            Some(
                hues.into_iter()
                    .enumerate()
                    .filter(|(_, (_, count))| *count > 0)
                    .map(|(hue, (d, count))| {
                        view! {
                            <path class=format!("cut tool-on-path hue-{hue}") data-paths=count d=d />
                        }
                    })
                    .collect_view(),
            )
        })
    };
    // Tool-on moves off the contours: chain links, and a path's pieces through scrap.
    let links = move || {
        animation
            .timeline
            .with(|t| t.as_ref().map(|t| link_path(&t.toolpath)))
            .filter(|d| !d.is_empty())
    };
    let idle = move || {
        route
            .with(|r| r.as_ref().map(idle_path))
            .or_else(|| paths.with(|p| p.as_ref().map(path_route_idle_path)))
    };
    // Certified and uncertified contours of the route (CCP's certificates).
    let certificates = move || {
        let flags = certified.get();
        if flags.is_empty() {
            return None;
        }
        let route = route.get()?;
        nest.with(|n| {
            let n = n.as_ref()?;
            let (mut yes, mut no) = (String::new(), String::new());
            for (step, ok) in route.steps.iter().zip(flags.iter()) {
                if let Some(c) = n.contour(step.contour) {
                    contour_path(c, if *ok { &mut yes } else { &mut no });
                }
            }
            Some((yes, no))
        })
    };
    let path_pierces = move || {
        let paths = paths.get()?;
        let r = extent.get() / 250.0;
        let total = paths.paths.len();
        Some(
            paths
                .paths
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let title = match language.get() {
                        Lang::En => format!(
                            "path {} of {total}: pierce at ({:.2}, {:.2}), {:.1} mm tool-on, {} spans",
                            k + 1,
                            p.pierce.x,
                            p.pierce.y,
                            p.length(),
                            p.spans.len()
                        ),
                        Lang::Ru => format!(
                            "путь {} из {total}: врезка в ({:.2}, {:.2}), {:.1} мм резки, участков: {}",
                            k + 1,
                            p.pierce.x,
                            p.pierce.y,
                            p.length(),
                            p.spans.len()
                        ),
                    };
                    view! {
                        <circle class="pierce" cx=p.pierce.x cy=p.pierce.y r=r>
                            <title>{title}</title>
                        </circle>
                    }
                })
                .collect_view(),
        )
    };
    let pierces = move || {
        let route = route.get()?;
        let r = extent.get() / 250.0;
        nest.with(|n| {
            let n = n.as_ref()?;
            let total = route.steps.len();
            Some(
                route
                    .steps
                    .iter()
                    .enumerate()
                    .map(|(k, s)| {
                        let part = n.parts.get(s.contour.part);
                        let name = part.map_or("", |p| p.name.as_str());
                        let title = match language.get() {
                            Lang::En => format!(
                                "cut {} of {total}: part {} “{name}”, contour {}{} — pierce at ({:.2}, {:.2})",
                                k + 1,
                                s.contour.part + 1,
                                s.contour.contour,
                                if s.contour.contour == 0 { " (outer)" } else { "" },
                                s.pierce_point.x,
                                s.pierce_point.y
                            ),
                            Lang::Ru => format!(
                                "рез {} из {total}: деталь {} «{name}», контур {}{} — врезка в ({:.2}, {:.2})",
                                k + 1,
                                s.contour.part + 1,
                                s.contour.contour,
                                if s.contour.contour == 0 { " (внешний)" } else { "" },
                                s.pierce_point.x,
                                s.pierce_point.y
                            ),
                        };
                        view! {
                            <circle class="pierce" cx=s.pierce_point.x cy=s.pierce_point.y r=r>
                                <title>{title}</title>
                            </circle>
                        }
                    })
                    .collect_view(),
            )
        })
    };
    let ends = move || {
        let (start, finish) = route
            .with(|r| r.as_ref().map(|r| (r.start, r.finish)))
            .or_else(|| paths.with(|p| p.as_ref().map(|p| (p.start, p.finish))))?;
        let r = extent.get() / 100.0;
        let lang = language.get();
        let marker = move |p: Point, class: &'static str, name: &'static str| {
            view! {
                <rect class=class x=p.x - r y=p.y - r width=2.0 * r height=2.0 * r>
                    <title>{format!("{name} ({:.2}, {:.2})", p.x, p.y)}</title>
                </rect>
            }
        };
        Some(view! {
            {marker(start, "start-marker", lang.pick("start", "старт"))}
            {finish.map(|f| marker(f, "finish-marker", lang.pick("finish", "финиш")))}
        })
    };
    // Order numbers live outside the flipped group (text must not be mirrored): (x, −y).
    // Numbered by step (contour) or by tool-on path.
    let order_labels = move || {
        let points: Vec<Point> = route
            .with(|r| {
                r.as_ref()
                    .map(|r| r.steps.iter().map(|s| s.pierce_point).collect())
            })
            .or_else(|| {
                paths.with(|p| {
                    p.as_ref()
                        .map(|p| p.paths.iter().map(|p| p.pierce).collect())
                })
            })?;
        Some(
            points
                .into_iter()
                .enumerate()
                .map(|(k, p)| {
                    view! {
                        <text x=p.x y=-p.y dx="0.4em" dy="-0.3em">
                            {(k + 1).to_string()}
                        </text>
                    }
                })
                .collect_view(),
        )
    };
    let compared = move || {
        kept.with(|k| {
            k.iter()
                .filter(|e| e.overlay)
                .take(2)
                .zip(["compare-a", "compare-b"])
                .map(|(e, class)| {
                    view! {
                        <path class=format!("compare {class}") d=e.idle_d.clone()>
                            <title>{format!("{} #{}: {}", language.pick("kept result", "сохранённый результат"), e.id, language.pick(e.label.0, e.label.1))}</title>
                        </path>
                    }
                })
                .collect_view()
        })
    };
    let hatch = move || {
        let s = extent.get() / 120.0;
        view! {
            <pattern id="hatch" patternUnits="userSpaceOnUse" width=s height=s patternTransform="rotate(45)">
                <rect class="hatch-bg" width=s height=s />
                <line class="hatch-line" x1="0" y1="0" x2="0" y2=s />
            </pattern>
        }
    };
    view! {
        <div class="canvas">
        <svg
            id="nest-view"
            xmlns="http://www.w3.org/2000/svg"
            class=classes
            viewBox=view_box
            preserveAspectRatio="xMidYMid meet"
            tabindex="0"
            role="img"
            aria-label=tr(
                "Nest and route; drag to pan, wheel or + and − to zoom, 0 to fit",
                "Раскрой и маршрут; перетаскивание — сдвиг, колесо или + и − — масштаб, 0 — вписать",
            )
            on:wheel=move |ev| pan_zoom.on_wheel(ev)
            on:pointerdown=move |ev| pan_zoom.on_pointer_down(ev)
            on:pointermove=move |ev| pan_zoom.on_pointer_move(ev)
            on:pointerup=move |ev| pan_zoom.on_pointer_up(ev)
            on:pointercancel=move |ev| pan_zoom.on_pointer_up(ev)
            on:keydown=move |ev| pan_zoom.on_key(ev)
        >
            <defs>{hatch}</defs>
            <g transform="scale(1,-1)">
                <path class="sheet" d=sheet />
                <g class="parts">{parts}</g>
                <HeatMapLayer thermal=thermal nest=nest hidden=hidden_layers animation=animation />
                <path class="arrows" d=arrows />
                <path class="candidates" d=candidates />
                {move || {
                    certificates()
                        .map(|(yes, no)| {
                            view! {
                                <g class="certificates">
                                    <path class="certified" d=yes />
                                    <path class="uncertified" d=no />
                                </g>
                            }
                        })
                }}
                <g class="route">
                    <crate::kerf::LeadLayers nest=nest route=route paths=paths extent=Signal::from(extent) />
                    <path class="cut" d=cuts />
                    <g class="tool-on-paths">{tool_on_paths}</g>
                    <path class="link" d=links />
                    <path class="idle" d=idle />
                    <g class="pierces">{pierces}{path_pierces}</g>
                    <g class="ends">{ends}</g>
                </g>
                <g class="compared">{compared}</g>
                <g class="violations">
                    <ViolationMarks thermal=thermal nest=nest route=route extent=extent />
                </g>
            </g>
            <g class="order" font-size=move || view_width.get() / 70.0>{order_labels}</g>
        </svg>
        // A second SVG stacked on the view: its own layer, so an animation frame repaints and
        // rasters the tool head only, not the nest (src/animation.rs).
        <AnimationOverlay animation=animation scale=view_width view_box=Signal::derive(view_box) />
        </div>
    }
}
