//! cutroute's browser application: open a nest, solve it in the worker, watch the route improve,
//! review it (layers, animation, certificates), compare and export it.

mod animation;
mod announce;
mod app;
mod chart;
mod clock;
mod compare;
mod drawing;
mod drawing_area;
mod embedded;
mod export;
mod fields;
mod gallery;
mod i18n;
mod import_warnings;
mod job_status;
mod kerf;
mod legend;
mod links;
mod nest_view;
mod order_labels;
mod pan_zoom;
mod profiles;
mod settings;
mod sheets;
mod side_panels;
mod solver_panel;
mod state;
mod stats;
mod theme;
mod thermal;
mod toolbar;
mod words;
mod worker_client;

fn main() {
    console_error_panic_hook::set_once();
    leptos::mount::mount_to_body(app::App);
    // The page's own "loading" line stood in while the wasm loaded: the app is here now.
    if let Some(loading) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id("loading"))
    {
        loading.remove();
    }
}
