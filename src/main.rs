//! cutroute's browser application: open a nest, solve it in the worker, watch the route improve,
//! review it (layers, animation, certificates), compare and export it.

mod animation;
mod app;
mod chart;
mod compare;
mod drawing;
mod export;
mod pan_zoom;
mod settings;
mod stats;
mod theme;
mod worker_client;

fn main() {
    console_error_panic_hook::set_once();
    leptos::mount::mount_to_body(app::App);
}
