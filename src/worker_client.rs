//! The page's end of the solver worker: starts `worker.js`, routes its answers to a callback,
//! and notices when it dies.
//!
//! A worker dies in three ways, and each one is reported once through `on_death`:
//! - an uncaught exception in the worker (a wasm trap such as a panic, a script error): the
//!   `Worker`'s `error` event;
//! - a message that cannot be read (`messageerror`, or bytes that do not decode);
//! - silence: a request (an open, a running job) and no message for [`SILENCE_LIMIT`] — a
//!   worker stuck in a loop, or one that closed itself. A running job reports at least every
//!   150 ms, so this is far beyond any healthy pause.
//!
//! A dead worker is terminated at once (its thread is stopped, whatever it was doing); the
//! page then starts a fresh one. Dropping a [`SolverWorker`] terminates it too, so a worker
//! that is replaced (Stop's fallback, a restart) never keeps computing in the background.
//!
//! The worker itself is `crates/worker`, registered with gloo-worker 0.6. The page speaks that
//! registrar's wire format here (bincode of the two enums below) instead of using gloo's
//! `WorkerBridge`, because the bridge hides the native `Worker`: without it there is no
//! `error` event to listen to and no way to terminate a worker that stopped answering.

use std::cell::{Cell, RefCell};
use std::collections::{BTreeMap, BTreeSet};
use std::rc::{Rc, Weak};
use std::time::Duration;

use cutroute_protocol::{FromWorker, JobId, ToWorker};
use leptos::prelude::{set_interval_with_handle, set_timeout, IntervalHandle};
use serde::{Deserialize, Serialize};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::{JsCast, UnwrapThrowExt};

/// How long a busy worker may stay silent before it is taken for dead.
pub const SILENCE_LIMIT: Duration = Duration::from_secs(30);

/// gloo-worker 0.6's message to a worker (`gloo_worker::actor::messages::ToWorker`): the
/// variants in the same order, bincode-encoded as gloo does. The handler id is gloo's
/// `HandlerId(usize)`.
#[derive(Serialize)]
enum WireToWorker<'a> {
    Connected(usize),
    ProcessInput(usize, &'a ToWorker),
    #[allow(dead_code)] // part of the format; the page never disconnects, it terminates
    Disconnected(usize),
    #[allow(dead_code)]
    Destroy,
}

/// gloo-worker 0.6's message from a worker (`gloo_worker::actor::messages::FromWorker`). A box
/// decodes as its content does.
#[derive(Deserialize)]
enum WireFromWorker {
    WorkerLoaded,
    ProcessOutput(usize, Box<FromWorker>),
}

/// The one handler id this page uses on each worker.
const HANDLER: usize = 0;

/// Why a worker was given up.
#[derive(Clone, Debug, PartialEq)]
pub enum DeathReason {
    /// It sent a message the page cannot read (the decoder's words).
    Unreadable(String),
    /// It did not answer for this many seconds.
    Silent(u64),
    /// Its error event's message (the browser's or the wasm's words).
    Error(String),
    /// A message could not be read (`messageerror`).
    MessageError,
    /// An error event without a message: it could not start or failed.
    Failed,
}

impl DeathReason {
    /// The reason in the page's language (messages from the browser stay as they are).
    pub fn text(&self, lang: crate::i18n::Lang) -> String {
        use crate::i18n::Lang;
        match (self, lang) {
            (DeathReason::Unreadable(e), Lang::En) => {
                format!("it sent a message the page cannot read ({e})")
            }
            (DeathReason::Unreadable(e), Lang::Ru) => {
                format!("он прислал сообщение, которое страница не может прочитать ({e})")
            }
            (DeathReason::Silent(s), Lang::En) => format!("it did not answer for {s} s"),
            (DeathReason::Silent(s), Lang::Ru) => format!("он не отвечал {s} с"),
            (DeathReason::Error(message), _) => message.clone(),
            (DeathReason::MessageError, Lang::En) => "a message could not be read".into(),
            (DeathReason::MessageError, Lang::Ru) => "сообщение не удалось прочитать".into(),
            (DeathReason::Failed, Lang::En) => "it could not start or failed".into(),
            (DeathReason::Failed, Lang::Ru) => "он не запустился или завершился с ошибкой".into(),
        }
    }
}

/// What was lost when a worker died.
#[derive(Clone, Debug)]
pub struct WorkerDeath {
    /// What happened (the worker's error message, or the silence).
    pub reason: DeathReason,
    /// Names of the files of opens that had not been answered.
    pub opening: Vec<String>,
    /// Jobs that were running.
    pub jobs: Vec<JobId>,
}

/// Requests sent and not yet answered.
#[derive(Default)]
struct InFlight {
    opens: BTreeMap<u64, Vec<String>>,
    jobs: BTreeSet<JobId>,
}

impl InFlight {
    fn busy(&self) -> bool {
        !self.opens.is_empty() || !self.jobs.is_empty()
    }
}

struct Shared {
    worker: web_sys::Worker,
    /// Encoded messages held until the worker has loaded its wasm (`WorkerLoaded`).
    queue: RefCell<Option<Vec<Vec<u8>>>>,
    in_flight: RefCell<InFlight>,
    /// `performance.now()` of the last message from the worker, or of the request that made
    /// an idle worker busy.
    last_heard_ms: Cell<f64>,
    dead: Cell<bool>,
    on_message: Box<dyn Fn(FromWorker)>,
    on_death: Rc<dyn Fn(WorkerDeath)>,
}

/// A running worker; dropping it terminates the worker.
pub struct SolverWorker {
    shared: Rc<Shared>,
    watch: Option<IntervalHandle>,
    _on_message: Closure<dyn Fn(web_sys::MessageEvent)>,
    _on_error: Closure<dyn Fn(web_sys::Event)>,
}

fn now_ms() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or(0.0, |p| p.now())
}

impl Shared {
    fn post(&self, message: &WireToWorker) {
        let Ok(bytes) = bincode::serialize(message) else {
            return; // the protocol's types always encode
        };
        if let Some(queue) = self.queue.borrow_mut().as_mut() {
            queue.push(bytes);
            return;
        }
        // Posting to a terminated worker is a no-op, not an error.
        let _ = self
            .worker
            .post_message(&js_sys::Uint8Array::from(bytes.as_slice()));
    }

    fn received(self: &Rc<Self>, data: wasm_bindgen::JsValue) {
        if self.dead.get() {
            return;
        }
        self.last_heard_ms.set(now_ms());
        let bytes = js_sys::Uint8Array::new(&data).to_vec();
        match bincode::deserialize::<WireFromWorker>(&bytes) {
            Ok(WireFromWorker::WorkerLoaded) => {
                let queued = self.queue.borrow_mut().take().unwrap_or_default();
                for bytes in queued {
                    let _ = self
                        .worker
                        .post_message(&js_sys::Uint8Array::from(bytes.as_slice()));
                }
            }
            Ok(WireFromWorker::ProcessOutput(handler, message)) => {
                if handler == HANDLER {
                    self.answered(&message);
                    (self.on_message)(*message);
                }
            }
            Err(error) => self.die(DeathReason::Unreadable(error.to_string())),
        }
    }

    /// Crosses off the request a message answers.
    fn answered(&self, message: &FromWorker) {
        let mut in_flight = self.in_flight.borrow_mut();
        match message {
            FromWorker::Opened { request_id, .. } | FromWorker::OpenFailed { request_id, .. } => {
                in_flight.opens.remove(request_id);
            }
            FromWorker::Finished(p) | FromWorker::Cancelled(p) => {
                in_flight.jobs.remove(&p.job_id);
            }
            FromWorker::Failed { job_id, .. } => {
                in_flight.jobs.remove(job_id);
            }
            FromWorker::Progress(_) => {}
        }
    }

    /// Terminates the worker and reports what it was doing, once. The report comes from a
    /// fresh task: the page replaces (drops) this worker in it, which must not happen inside
    /// one of the worker's own event handlers.
    fn die(&self, reason: DeathReason) {
        if self.dead.replace(true) {
            return;
        }
        self.worker.terminate();
        let in_flight = std::mem::take(&mut *self.in_flight.borrow_mut());
        let death = WorkerDeath {
            reason,
            opening: in_flight.opens.into_values().flatten().collect(),
            jobs: in_flight.jobs.into_iter().collect(),
        };
        let on_death = self.on_death.clone();
        set_timeout(move || on_death(death), Duration::ZERO);
    }

    /// The silence check, run every second.
    fn check_silence(&self) {
        if self.dead.get() || !self.in_flight.borrow().busy() {
            return;
        }
        let silent_ms = now_ms() - self.last_heard_ms.get();
        if silent_ms > SILENCE_LIMIT.as_secs_f64() * 1000.0 {
            self.die(DeathReason::Silent(SILENCE_LIMIT.as_secs()));
        }
    }
}

impl SolverWorker {
    /// Sends a message; held until the worker has loaded.
    pub fn send(&self, message: ToWorker) {
        if self.shared.dead.get() {
            return;
        }
        {
            let mut in_flight = self.shared.in_flight.borrow_mut();
            if !in_flight.busy() {
                self.shared.last_heard_ms.set(now_ms());
            }
            match &message {
                ToWorker::Start(request) => {
                    in_flight.jobs.insert(request.job_id);
                }
                ToWorker::Open { request_id, files } => {
                    let names = files.iter().map(|(name, _)| name.clone()).collect();
                    in_flight.opens.insert(*request_id, names);
                }
                ToWorker::OpenSheet {
                    request_id, file, ..
                } => {
                    in_flight.opens.insert(*request_id, vec![file.0.clone()]);
                }
                ToWorker::Cancel { .. } => {}
            }
        }
        self.shared
            .post(&WireToWorker::ProcessInput(HANDLER, &message));
    }
}

impl Drop for SolverWorker {
    fn drop(&mut self) {
        self.shared.dead.set(true);
        if let Some(watch) = self.watch.take() {
            watch.clear();
        }
        self.shared.worker.set_onmessage(None);
        self.shared.worker.set_onerror(None);
        self.shared.worker.set_onmessageerror(None);
        self.shared.worker.terminate();
    }
}

/// Starts the worker next to the page (relative URL: works from any sub-path of a static
/// host). `on_message` gets its answers; `on_death` is called once if it dies (never after
/// the returned worker is dropped).
pub fn spawn(
    on_message: impl Fn(FromWorker) + 'static,
    on_death: impl Fn(WorkerDeath) + 'static,
) -> SolverWorker {
    let worker = create_worker("./worker.js");
    let shared = Rc::new(Shared {
        worker,
        queue: RefCell::new(Some(Vec::new())),
        in_flight: RefCell::new(InFlight::default()),
        last_heard_ms: Cell::new(now_ms()),
        dead: Cell::new(false),
        on_message: Box::new(on_message),
        on_death: Rc::new(on_death),
    });

    let weak: Weak<Shared> = Rc::downgrade(&shared);
    let on_message =
        Closure::<dyn Fn(web_sys::MessageEvent)>::new(move |event: web_sys::MessageEvent| {
            if let Some(shared) = weak.upgrade() {
                shared.received(event.data());
            }
        });
    let weak: Weak<Shared> = Rc::downgrade(&shared);
    let on_error = Closure::<dyn Fn(web_sys::Event)>::new(move |event: web_sys::Event| {
        // Handled here: not reported again as an uncaught error of the page.
        event.prevent_default();
        let Some(shared) = weak.upgrade() else {
            return;
        };
        // An `ErrorEvent`'s message, read by name: web-sys's `ErrorEvent` type is not enabled.
        let message = js_sys::Reflect::get(&event, &"message".into())
            .ok()
            .and_then(|m| m.as_string())
            .filter(|m| !m.is_empty());
        let reason = match message {
            Some(message) => DeathReason::Error(message),
            None if event.type_() == "messageerror" => DeathReason::MessageError,
            None => DeathReason::Failed,
        };
        shared.die(reason);
    });
    shared
        .worker
        .set_onmessage(Some(on_message.as_ref().unchecked_ref()));
    shared
        .worker
        .set_onerror(Some(on_error.as_ref().unchecked_ref()));
    shared
        .worker
        .set_onmessageerror(Some(on_error.as_ref().unchecked_ref()));

    let weak: Weak<Shared> = Rc::downgrade(&shared);
    let watch = set_interval_with_handle(
        move || {
            if let Some(shared) = weak.upgrade() {
                shared.check_silence();
            }
        },
        Duration::from_secs(1),
    )
    .ok();

    shared.post(&WireToWorker::Connected(HANDLER));
    SolverWorker {
        shared,
        watch,
        _on_message: on_message,
        _on_error: on_error,
    }
}

/// A classic (non-module) worker, as trunk builds `crates/worker` (`--target no-modules`): a
/// small script from a blob URL imports the bindings and loads the wasm beside them.
fn create_worker(path: &str) -> web_sys::Worker {
    // The single-file page carries the worker's script and wasm behind a loader of its own.
    if let Some(loader) = crate::embedded::worker_loader() {
        return web_sys::Worker::new(&loader)
            .expect_throw("the solver worker could not be started");
    }
    let href = web_sys::window()
        .and_then(|w| w.location().href().ok())
        .unwrap_or_default();
    let script = web_sys::Url::new_with_base(path, &href)
        .map(|u| u.href())
        .unwrap_or_else(|_| path.to_string());
    let wasm = script.replace(".js", "_bg.wasm");
    let shim = format!(r#"importScripts("{script}");wasm_bindgen("{wasm}");"#);
    let parts = js_sys::Array::of1(&shim.into());
    let options = web_sys::BlobPropertyBag::new();
    options.set_type("application/javascript");
    let url = web_sys::Blob::new_with_str_sequence_and_options(&parts, &options)
        .and_then(|blob| web_sys::Url::create_object_url_with_blob(&blob))
        .expect_throw("the solver worker's start script could not be made");
    web_sys::Worker::new(&url).expect_throw("the solver worker could not be started")
}
