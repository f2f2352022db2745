//! The application shell: creates the page's state (`crate::state`), shares it by context and
//! lays out the components: toolbar, solver panel, drawing area and side panels.

use leptos::prelude::*;

use crate::animation::Animation;
use crate::drawing_area::DrawingArea;
use crate::settings::Settings;
use crate::side_panels::SidePanels;
use crate::solver_panel::SolverPanel;
use crate::state::Page;
use crate::thermal::ThermalView;
use crate::toolbar::Toolbar;

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

/// The whole page.
#[component]
pub fn App() -> impl IntoView {
    provide_context(crate::i18n::Language::new());
    let query = web_sys::window()
        .and_then(|w| w.location().search().ok())
        .unwrap_or_default();
    let initial = Settings::load().with_query(&query);
    let lecture_url = crate::gallery::list_url(&query);

    let page = Page::new(&initial, &lecture_url);
    page.provide();
    page.remember();
    let (shown, machine) = (page.shown, page.machine);
    provide_context(ThermalView::new(
        machine.thermal,
        shown.nest,
        shown.route,
        shown.paths,
        machine.machine,
        page.job.progress,
    ));
    provide_context(Animation::new(
        shown.toolpath,
        machine.machine,
        Signal::derive(move || shown.piece()),
    ));
    page.document.open_initial(&initial);

    view! {
        <Toolbar initial_sample=initial.sample.clone() lecture_url=lecture_url />
        <SolverPanel initial_solver=initial.solver.clone() initial_objective=initial.objective.clone() />
        <main class="workspace">
            <DrawingArea />
            <SidePanels />
        </main>
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
