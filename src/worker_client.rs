//! The page's end of the solver worker: spawns `worker.js` and routes its answers to callbacks.

use cutroute_protocol::{FromWorker, ToWorker};
use gloo_worker::{Spawnable, WorkerBridge};

/// The worker type, named only for its message types; its code lives in `crates/worker`.
pub struct SolverWorker;

impl gloo_worker::Worker for SolverWorker {
    type Message = ();
    type Input = ToWorker;
    type Output = FromWorker;

    fn create(_scope: &gloo_worker::WorkerScope<Self>) -> Self {
        SolverWorker
    }
    fn update(&mut self, _scope: &gloo_worker::WorkerScope<Self>, _msg: ()) {}
    fn received(
        &mut self,
        _scope: &gloo_worker::WorkerScope<Self>,
        _msg: ToWorker,
        _id: gloo_worker::HandlerId,
    ) {
    }
}

/// Spawn the worker next to the page (relative URL: works from any sub-path of a static host),
/// or from the loader the single-file page carries (`crate::embedded`).
pub fn spawn(on_message: impl Fn(FromWorker) + 'static) -> WorkerBridge<SolverWorker> {
    let mut spawner = SolverWorker::spawner();
    spawner.callback(on_message).as_module(false);
    match crate::embedded::worker_loader() {
        Some(loader) => spawner.with_loader(true).spawn(&loader),
        None => spawner.spawn("./worker.js"),
    }
}
