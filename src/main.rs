//! cutroute's browser application: open a nest, solve it in the worker, watch the route improve.

mod app;
mod chart;
mod drawing;
mod pan_zoom;
mod stats;
mod theme;
mod worker_client;

fn main() {
    console_error_panic_hook::set_once();
    leptos::mount::mount_to_body(app::App);
}
