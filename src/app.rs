//! The application shell: sample picker, solver controls, live bounds, and the route drawing.

use cutroute_geometry::{MachineParameters, Nest, Point};
use cutroute_protocol::{
    Document, FromWorker, JobId, JobRequest, Problem, Progress, SolverKind, SolverParams, ToWorker,
};
use gloo_worker::WorkerBridge;
use leptos::prelude::*;

use crate::chart::{BoundSample, BoundsChart};
use crate::drawing::{contour_path, idle_path, nest_bounds};
use crate::pan_zoom::PanZoom;
use crate::stats::StatsPanel;
use crate::worker_client::{spawn, SolverWorker};

/// Bundled sample nests (files under `assets/samples/`), the first is opened on start.
pub const SAMPLES: [(&str, &str); 4] = [
    ("E1X_6_01.dbs.json", "E1X_6_01 — 9 parts with arcs"),
    ("test1.dbs.json", "test1 — 40 contours"),
    ("nested.dbs", "nested — parts inside holes"),
    ("seven.dbs", "seven — 29 parts, 5,000 points"),
];

/// What the page shows about the current job.
#[derive(Clone, Debug, PartialEq)]
enum JobState {
    Idle,
    Running(JobId),
    Finished,
    Cancelled,
    Failed(String),
}

impl JobState {
    fn label(&self) -> String {
        match self {
            JobState::Idle => "idle".into(),
            JobState::Running(_) => "running".into(),
            JobState::Finished => "finished".into(),
            JobState::Cancelled => "cancelled".into(),
            JobState::Failed(message) => format!("failed: {message}"),
        }
    }
}

/// The whole page.
#[component]
pub fn App() -> impl IntoView {
    let document = RwSignal::new(None::<Document>);
    let open_error = RwSignal::new(None::<String>);
    let progress = RwSignal::new(None::<Progress>);
    let samples = RwSignal::new(Vec::<BoundSample>::new());
    let log_time = RwSignal::new(false);
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
    let job_state = RwSignal::new(JobState::Idle);
    let solver = RwSignal::new(SolverKind::NearestNeighbour);
    let time_limit = RwSignal::new(10.0_f64);
    let next_id = StoredValue::new(1_u64);

    let bridge: StoredValue<WorkerBridge<SolverWorker>, LocalStorage> =
        StoredValue::new_local(spawn(move |message| match message {
            FromWorker::Opened {
                document: opened, ..
            } => {
                open_error.set(None);
                progress.set(None);
                document.set(Some(opened));
            }
            FromWorker::OpenFailed { message, .. } => open_error.set(Some(message)),
            FromWorker::Progress(update) => {
                if job_state.get_untracked() == JobState::Running(update.job_id) {
                    record(&update);
                    progress.set(Some(update));
                }
            }
            FromWorker::Finished(last) => {
                if job_state.get_untracked() == JobState::Running(last.job_id) {
                    record(&last);
                    progress.set(Some(last));
                    job_state.set(JobState::Finished);
                }
            }
            FromWorker::Cancelled(last) => {
                if job_state.get_untracked() == JobState::Running(last.job_id) {
                    progress.set(Some(last));
                    job_state.set(JobState::Cancelled);
                }
            }
            FromWorker::Failed { job_id, message } => {
                if job_state.get_untracked() == JobState::Running(job_id) {
                    job_state.set(JobState::Failed(message));
                }
            }
        }));

    let machine = RwSignal::new(MachineParameters::default());
    let shown_nest = Signal::derive(move || {
        document.with(|d| match d.as_ref().map(|d| &d.problem) {
            Some(Problem::Nest { nest, .. }) => Some(nest.clone()),
            _ => None,
        })
    });
    let shown_route =
        Signal::derive(move || progress.with(|p| p.as_ref().and_then(|p| p.route.clone())));

    let take_id = move || {
        let id = next_id.get_value();
        next_id.set_value(id + 1);
        id
    };

    let open_sample = move |file_name: String| {
        let request_id = take_id();
        leptos::task::spawn_local(async move {
            let url = format!("./assets/samples/{file_name}");
            match fetch_bytes(&url).await {
                Ok(bytes) => bridge.with_value(|b| {
                    b.send(ToWorker::Open {
                        request_id,
                        file_name,
                        bytes,
                    })
                }),
                Err(message) => open_error.set(Some(format!("{url}: {message}"))),
            }
        });
    };
    open_sample(SAMPLES[0].0.to_string());

    // Local files (picker or drag and drop) go to the worker as bytes: parsing happens there.
    let open_files = move |files: web_sys::FileList| {
        for index in 0..files.length() {
            let Some(file) = files.item(index) else {
                continue;
            };
            let request_id = take_id();
            leptos::task::spawn_local(async move {
                match read_file(&file).await {
                    Ok(bytes) => bridge.with_value(|b| {
                        b.send(ToWorker::Open {
                            request_id,
                            file_name: file.name(),
                            bytes,
                        })
                    }),
                    Err(message) => open_error.set(Some(format!("{}: {message}", file.name()))),
                }
            });
        }
    };

    let start = move |_| {
        let Some(Document { problem, .. }) = document.get_untracked() else {
            return;
        };
        let job_id = take_id();
        let params = SolverParams {
            time_limit_s: time_limit.get_untracked(),
            ..SolverParams::default()
        };
        progress.set(None);
        samples.set(Vec::new());
        job_state.set(JobState::Running(job_id));
        let request = JobRequest {
            job_id,
            problem,
            solver: solver.get_untracked(),
            params,
        };
        bridge.with_value(|b| b.send(ToWorker::Start(request)));
    };
    let stop = move |_| {
        if let JobState::Running(job_id) = job_state.get_untracked() {
            bridge.with_value(|b| b.send(ToWorker::Cancel { job_id }));
        }
    };
    let running = move || matches!(job_state.get(), JobState::Running(_));

    view! {
        <header class="toolbar">
            <h1>"cutroute"</h1>
            <label>
                "Sample "
                <select
                    id="sample"
                    aria-label="Sample nest"
                    on:change=move |ev| open_sample(event_target_value(&ev))
                >
                    {SAMPLES
                        .iter()
                        .map(|(file, label)| view! { <option value=*file>{*label}</option> })
                        .collect_view()}
                </select>
            </label>
            <label class="file-button">
                "Open file… "
                <input
                    id="file-input"
                    type="file"
                    multiple
                    aria-label="Open nest or instance files"
                    on:change=move |ev| {
                        let input: web_sys::HtmlInputElement = event_target(&ev);
                        if let Some(files) = input.files() {
                            open_files(files);
                        }
                        input.set_value("");
                    }
                />
            </label>
            <label>
                "Solver "
                <select
                    id="solver"
                    aria-label="Solver"
                    on:change=move |ev| {
                        if let Some(kind) = SolverKind::from_name(&event_target_value(&ev)) {
                            solver.set(kind);
                        }
                    }
                >
                    {SolverKind::ALL
                        .iter()
                        .map(|kind| view! { <option value=kind.name()>{solver_label(*kind)}</option> })
                        .collect_view()}
                </select>
            </label>
            <label>
                "Time limit, s "
                <input
                    id="time-limit"
                    type="number"
                    min="0.1"
                    step="1"
                    prop:value=move || time_limit.get().to_string()
                    on:change=move |ev| {
                        if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                            if v > 0.0 {
                                time_limit.set(v);
                            }
                        }
                    }
                />
            </label>
            <crate::theme::ThemePicker />
            <button id="start" on:click=start disabled=move || running() || document.get().is_none()>
                "Start"
            </button>
            <button id="stop" on:click=stop disabled=move || !running()>
                "Stop"
            </button>
        </header>
        <main class="workspace">
            <section
                class="view"
                aria-label="Cutting plan"
                on:dragover=move |ev: web_sys::DragEvent| ev.prevent_default()
                on:drop=move |ev: web_sys::DragEvent| {
                    ev.prevent_default();
                    if let Some(files) = ev.data_transfer().and_then(|d| d.files()) {
                        open_files(files);
                    }
                }
            >
                {move || open_error.get().map(|e| view! { <p class="error" role="alert">{e}</p> })}
                <NestView document=document progress=progress />
            </section>
            <aside class="stats" aria-label="Job status">
                <dl>
                    <dt>"File"</dt>
                    <dd id="file-name">
                        {move || document.get().map(|d| format!("{} ({})", d.file_name, d.format)).unwrap_or_default()}
                    </dd>
                    <dt>"Job"</dt>
                    <dd id="job-status">{move || job_state.get().label()}</dd>
                    <dt>"Phase"</dt>
                    <dd id="phase">{move || progress.get().map(|p| p.phase).unwrap_or_default()}</dd>
                    <dt>"Upper bound"</dt>
                    <dd id="upper-bound">{move || format_bound(progress.get().and_then(|p| p.upper_bound))}</dd>
                    <dt>"Lower bound"</dt>
                    <dd id="lower-bound">{move || format_bound(progress.get().and_then(|p| p.lower_bound))}</dd>
                    <dt>"Gap"</dt>
                    <dd id="gap">
                        {move || progress.get().and_then(|p| p.gap()).map(|g| format!("{:.2} %", g * 100.0)).unwrap_or_else(|| "—".into())}
                    </dd>
                    <dt>"Elapsed"</dt>
                    <dd id="elapsed">{move || progress.get().map(|p| format!("{:.2} s", p.elapsed_s)).unwrap_or_default()}</dd>
                </dl>
                <StatsPanel nest=shown_nest route=shown_route machine=machine />
                <BoundsChart samples=samples log_time=log_time />
            </aside>
        </main>
    }
}

fn solver_label(kind: SolverKind) -> &'static str {
    match kind {
        SolverKind::NearestNeighbour => "Nearest neighbour (baseline)",
        SolverKind::Ccp => "Continuous CCP-Relax",
        SolverKind::Heuristic => "Discrete heuristic (ALNS)",
        SolverKind::Exact => "Discrete exact with lower bound",
    }
}

fn format_bound(value: Option<f64>) -> String {
    value
        .map(|v| format!("{v:.1}"))
        .unwrap_or_else(|| "—".into())
}

async fn read_file(file: &web_sys::File) -> Result<Vec<u8>, String> {
    let buffer = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
        .await
        .map_err(|e| format!("{e:?}"))?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}

async fn fetch_bytes(url: &str) -> Result<Vec<u8>, String> {
    let response = gloo_net::http::Request::get(url)
        .send()
        .await
        .map_err(|e| e.to_string())?;
    if !response.ok() {
        return Err(format!("HTTP {}", response.status()));
    }
    response.binary().await.map_err(|e| e.to_string())
}

/// The drawing: sheet, parts, idle moves and pierce points, y axis up.
#[component]
fn NestView(
    document: RwSignal<Option<Document>>,
    progress: RwSignal<Option<Progress>>,
) -> impl IntoView {
    let nest = Memo::new(move |_| {
        document.with(|d| match d.as_ref().map(|d| &d.problem) {
            Some(Problem::Nest { nest, .. }) => Some(nest.clone()),
            _ => None,
        })
    });
    let fit = Signal::derive(move || {
        nest.with(|n| n.as_ref().and_then(nest_bounds))
            .map(|[x0, y0, x1, y1]| {
                let margin = ((x1 - x0).max(y1 - y0) * 0.03).max(1.0);
                // The group below flips y, so the box spans [-y1, -y0] vertically.
                [
                    x0 - margin,
                    -y1 - margin,
                    x1 - x0 + 2.0 * margin,
                    y1 - y0 + 2.0 * margin,
                ]
            })
    });
    let pan_zoom = PanZoom::new(fit);
    // A new drawing starts fitted.
    Effect::new(move |_| {
        nest.track();
        pan_zoom.reset();
    });
    let view_box = move || {
        pan_zoom
            .current()
            .map(|[x, y, w, h]| format!("{x} {y} {w} {h}"))
    };
    let parts = move || nest.with(|n| n.as_ref().map(part_paths).unwrap_or_default());
    let sheet = move || {
        nest.with(|n| {
            n.as_ref().and_then(|n| n.sheet.as_ref()).map(|sheet| {
                let mut d = String::new();
                sheet.contours.iter().for_each(|c| contour_path(c, &mut d));
                d
            })
        })
    };
    let route = move || progress.with(|p| p.as_ref().and_then(|p| p.route.clone()));
    view! {
        <svg
            id="nest-view"
            class="nest"
            viewBox=view_box
            preserveAspectRatio="xMidYMid meet"
            tabindex="0"
            role="img"
            aria-label="Nest and route; drag to pan, wheel or + and − to zoom, 0 to fit"
            on:wheel=move |ev| pan_zoom.on_wheel(ev)
            on:pointerdown=move |ev| pan_zoom.on_pointer_down(ev)
            on:pointermove=move |ev| pan_zoom.on_pointer_move(ev)
            on:pointerup=move |ev| pan_zoom.on_pointer_up(ev)
            on:pointercancel=move |ev| pan_zoom.on_pointer_up(ev)
            on:keydown=move |ev| pan_zoom.on_key(ev)
        >
            <g transform="scale(1,-1)">
                <path class="sheet" d=sheet />
                {move || {
                    parts()
                        .into_iter()
                        .map(|(name, d)| view! { <path class="part" d=d><title>{name}</title></path> })
                        .collect_view()
                }}
                {move || {
                    route()
                        .map(|route| {
                            let pierces = route
                                .steps
                                .iter()
                                .map(|s| pierce_marker(s.pierce_point))
                                .collect_view();
                            view! {
                                <g class="route">
                                    <path class="idle" d=idle_path(&route) />
                                    {pierces}
                                </g>
                            }
                        })
                }}
            </g>
        </svg>
    }
}

fn pierce_marker(p: Point) -> impl IntoView {
    view! { <circle class="pierce" cx=p.x cy=p.y r="1" /> }
}

fn part_paths(nest: &Nest) -> Vec<(String, String)> {
    nest.parts
        .iter()
        .map(|part| {
            let mut d = String::new();
            part.contours.iter().for_each(|c| contour_path(c, &mut d));
            (part.name.clone(), d)
        })
        .collect()
}
