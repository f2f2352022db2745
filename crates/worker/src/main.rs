//! The solver worker: a Web Worker binary that receives [`ToWorker`] messages, runs jobs through
//! `cutroute-engine` in short slices, and streams [`FromWorker`] messages back to the page.
//!
//! Between two slices the worker awaits a zero-delay timer, which hands control back to the
//! browser's event loop: that is how a Cancel message reaches a job that is still running.
//!
//! Files are opened here too, off the UI thread, through the engine's one door
//! (`cutroute_engine::open_together`).

#[cfg(target_arch = "wasm32")]
mod web {
    use std::collections::HashMap;

    use cutroute_engine::{
        open_sheet, open_together, start_job, EngineError, Job, JobStatus, OpenError, Refusal,
        DEFAULT_SLICE,
    };
    use cutroute_protocol::{Document, FromWorker, JobId, ToWorker};
    use gloo_worker::{HandlerId, Worker, WorkerScope};
    use web_time::{Duration, Instant};

    fn opened(request_id: u64, result: Result<Document, OpenError>) -> FromWorker {
        match result {
            Ok(document) => FromWorker::Opened {
                request_id,
                document,
            },
            Err(error) => FromWorker::OpenFailed {
                request_id,
                error: error.report(),
            },
        }
    }

    /// Progress is sent at most this often while a job improves (the page redraws on each one).
    const PROGRESS_INTERVAL: Duration = Duration::from_millis(150);

    struct RunningJob {
        job: Box<dyn Job>,
        requester: HandlerId,
        last_report: Option<Instant>,
        last_upper_bound: Option<f64>,
        last_lower_bound: Option<f64>,
    }

    /// Internal messages: "run the next slice of this job".
    pub enum Tick {
        Run(JobId),
    }

    /// The worker's state: the jobs that are running.
    pub struct SolverWorker {
        jobs: HashMap<JobId, RunningJob>,
    }

    fn schedule(scope: &WorkerScope<SolverWorker>, job_id: JobId) {
        scope.send_future(async move {
            // A macrotask boundary: lets queued messages (Cancel) in before the next slice.
            gloo_timers::future::TimeoutFuture::new(0).await;
            Tick::Run(job_id)
        });
    }

    impl Worker for SolverWorker {
        type Message = Tick;
        type Input = ToWorker;
        type Output = FromWorker;

        fn create(_scope: &WorkerScope<Self>) -> Self {
            Self {
                jobs: HashMap::new(),
            }
        }

        fn update(&mut self, scope: &WorkerScope<Self>, msg: Self::Message) {
            let Tick::Run(job_id) = msg;
            let Some(running) = self.jobs.get_mut(&job_id) else {
                return; // cancelled meanwhile
            };
            let status = running.job.step(DEFAULT_SLICE);
            let progress = running.job.progress();
            if status == JobStatus::Done {
                let requester = running.requester;
                self.jobs.remove(&job_id);
                scope.respond(requester, FromWorker::Finished(progress));
                return;
            }
            let bounds_changed = progress.bounds.upper != running.last_upper_bound
                || progress.bounds.lower != running.last_lower_bound;
            let due = running
                .last_report
                .is_none_or(|at| at.elapsed() >= PROGRESS_INTERVAL);
            if due
                || (bounds_changed
                    && running
                        .last_report
                        .is_none_or(|at| at.elapsed() >= PROGRESS_INTERVAL / 3))
            {
                running.last_report = Some(Instant::now());
                running.last_upper_bound = progress.bounds.upper;
                running.last_lower_bound = progress.bounds.lower;
                scope.respond(running.requester, FromWorker::Progress(progress));
            }
            schedule(scope, job_id);
        }

        fn received(&mut self, scope: &WorkerScope<Self>, msg: Self::Input, requester: HandlerId) {
            match msg {
                ToWorker::Start(request) => match start_job(&request) {
                    Ok(job) => {
                        let job_id = request.job_id;
                        scope.respond(requester, FromWorker::Progress(job.progress()));
                        self.jobs.insert(
                            job_id,
                            RunningJob {
                                job,
                                requester,
                                last_report: None,
                                last_upper_bound: None,
                                last_lower_bound: None,
                            },
                        );
                        schedule(scope, job_id);
                    }
                    Err(error) => scope.respond(
                        requester,
                        FromWorker::Failed {
                            job_id: request.job_id,
                            message: error.to_string(),
                            parts_too_close: match error {
                                EngineError::SolverRefused {
                                    reason: Refusal::PartsTooClose(pairs),
                                    ..
                                } => Some(pairs),
                                _ => None,
                            },
                        },
                    ),
                },
                ToWorker::Open { request_id, files } => {
                    scope.respond(requester, opened(request_id, open_together(&files)));
                }
                ToWorker::OpenSheet {
                    request_id,
                    file: (name, bytes),
                    sheet,
                } => {
                    scope.respond(
                        requester,
                        opened(request_id, open_sheet(&name, &bytes, sheet)),
                    );
                }
                ToWorker::Cancel { job_id } => {
                    if let Some(mut running) = self.jobs.remove(&job_id) {
                        running.job.stop();
                        let mut progress = running.job.progress();
                        progress.phase = cutroute_protocol::Phase::Cancelled;
                        scope.respond(running.requester, FromWorker::Cancelled(progress));
                    }
                }
            }
        }
    }
}

#[cfg(target_arch = "wasm32")]
fn main() {
    use gloo_worker::Registrable;
    console_error_panic_hook::set_once();
    web::SolverWorker::registrar().register();
}

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    eprintln!("cutroute-worker is a Web Worker: build it for wasm32 with trunk (see README).");
    std::process::exit(2);
}
