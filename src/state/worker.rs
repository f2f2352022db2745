//! The page's end of the solver worker: one handle that sends requests, numbers them, and puts
//! a fresh worker in place of one that died or ignored Stop.

use std::rc::Rc;

use cutroute_protocol::{FromWorker, ToWorker};
use leptos::prelude::*;

use crate::worker_client::{spawn, SolverWorker, WorkerDeath};

type MessageHandler = Rc<dyn Fn(FromWorker)>;
type DeathHandler = Rc<dyn Fn(WorkerDeath)>;

/// The worker, shared by the document (opening files) and the job (running solvers).
#[derive(Clone, Copy)]
pub struct WorkerLink {
    worker: StoredValue<SolverWorker, LocalStorage>,
    /// The id of the next request or job: answers name it, so a late answer to an old request
    /// is told apart.
    next_id: StoredValue<u64>,
    // Kept apart from the worker so a replacement answers to the same handlers.
    on_message: StoredValue<MessageHandler, LocalStorage>,
    on_death: StoredValue<DeathHandler, LocalStorage>,
}

impl WorkerLink {
    /// Starts the worker; its answers are dropped until [`WorkerLink::listen`] names where they
    /// go (none arrives before the page's setup returns to the event loop).
    pub fn new() -> Self {
        let on_message: StoredValue<MessageHandler, LocalStorage> =
            StoredValue::new_local(Rc::new(|_| {}));
        let on_death: StoredValue<DeathHandler, LocalStorage> =
            StoredValue::new_local(Rc::new(|_| {}));
        let worker = StoredValue::new_local(spawn_with(on_message, on_death));
        Self {
            worker,
            next_id: StoredValue::new(1),
            on_message,
            on_death,
        }
    }

    /// Where the worker's answers go, and what to do once a dead worker has been replaced.
    pub fn listen(
        &self,
        on_message: impl Fn(FromWorker) + 'static,
        after_death: impl Fn(WorkerDeath) + 'static,
    ) {
        let link = *self;
        self.on_message.set_value(Rc::new(on_message));
        self.on_death.set_value(Rc::new(move |death| {
            link.replace();
            after_death(death);
        }));
    }

    /// Sends a request; held until the worker has loaded.
    pub fn send(&self, message: ToWorker) {
        self.worker.with_value(|w| w.send(message));
    }

    /// A fresh id for a request or a job.
    pub fn take_id(&self) -> u64 {
        let id = self.next_id.get_value();
        self.next_id.set_value(id + 1);
        id
    }

    /// A fresh worker takes over; the old one is told to close, and its late answers name
    /// requests that are no longer awaited.
    pub fn replace(&self) {
        self.worker
            .set_value(spawn_with(self.on_message, self.on_death));
    }
}

fn spawn_with(
    on_message: StoredValue<MessageHandler, LocalStorage>,
    on_death: StoredValue<DeathHandler, LocalStorage>,
) -> SolverWorker {
    spawn(
        move |message| on_message.get_value()(message),
        move |death| on_death.get_value()(death),
    )
}
