//! The solver job: starting it, its reports, stopping it, how it ended, and the worker dying
//! under it.

use cutroute_geometry::{PathRoute, Route};
use cutroute_protocol::{
    Bounds, CostUnit, FromWorker, JobId, JobRequest, Progress, SolverParams, ToWorker,
};
use leptos::prelude::*;

use crate::chart::BoundSample;
use crate::i18n::Lang;
use crate::state::{DocumentState, MachineSettings, SolverSettings, WorkerLink};
use crate::words::{JobFailure, PageError};
use crate::worker_client::{DeathReason, WorkerDeath};

/// How long Stop waits for the job to stop itself before its worker is replaced.
const STOP_GRACE: std::time::Duration = std::time::Duration::from_millis(150);

/// Where the current job is in its life.
#[derive(Clone, Debug, PartialEq)]
pub enum JobStatus {
    Idle,
    Running(JobId),
    Finished,
    Cancelled,
    Failed(JobFailure),
}

impl JobStatus {
    /// The status in words.
    pub fn label(&self, lang: Lang) -> String {
        match (self, lang) {
            (JobStatus::Idle, Lang::En) => "idle".into(),
            (JobStatus::Idle, Lang::Ru) => "ожидание".into(),
            (JobStatus::Running(_), Lang::En) => "running".into(),
            (JobStatus::Running(_), Lang::Ru) => "выполняется".into(),
            (JobStatus::Finished, Lang::En) => "finished".into(),
            (JobStatus::Finished, Lang::Ru) => "завершено".into(),
            (JobStatus::Cancelled, Lang::En) => "cancelled".into(),
            (JobStatus::Cancelled, Lang::Ru) => "отменено".into(),
            (JobStatus::Failed(failure), Lang::En) => format!("failed: {}", failure.text(lang)),
            (JobStatus::Failed(failure), Lang::Ru) => format!("ошибка: {}", failure.text(lang)),
        }
    }
}

/// The job and what it reported. One job runs at a time; a report naming another job (a late
/// answer of one stopped or replaced) is ignored.
#[derive(Clone, Copy)]
pub struct JobState {
    pub status: RwSignal<JobStatus>,
    /// The last report, merged with the run a Continue started from.
    pub progress: RwSignal<Option<Progress>>,
    /// The best route of whole contours reported.
    pub best_route: RwSignal<Option<Route>>,
    /// The best route of tool-on paths reported (segment cutting, AOE).
    pub best_paths: RwSignal<Option<PathRoute>>,
    /// Every report's bounds, for the chart.
    pub chart_samples: RwSignal<Vec<BoundSample>>,
    /// Said after the worker died and was replaced; stays until the next job starts.
    pub worker_notice: RwSignal<Option<WorkerNotice>>,
    /// The result a Continue started from.
    continued_from: StoredValue<Option<Progress>>,
    /// How many runs the current result took (each continued run explores with another seed).
    runs: StoredValue<u64>,
    worker: WorkerLink,
    document: DocumentState,
    solver: SolverSettings,
    machine: MachineSettings,
}

impl JobState {
    /// No job yet.
    pub fn new(
        worker: WorkerLink,
        document: DocumentState,
        solver: SolverSettings,
        machine: MachineSettings,
    ) -> Self {
        let job = Self {
            status: RwSignal::new(JobStatus::Idle),
            progress: RwSignal::new(None),
            best_route: RwSignal::new(None),
            best_paths: RwSignal::new(None),
            chart_samples: RwSignal::new(Vec::new()),
            worker_notice: RwSignal::new(None),
            continued_from: StoredValue::new(None),
            runs: StoredValue::new(0),
            worker,
            document,
            solver,
            machine,
        };
        Effect::new(move |_| {
            if job.is_running() {
                job.worker_notice.set(None);
            }
        });
        job
    }

    /// Whether a job runs (tracked).
    pub fn is_running(&self) -> bool {
        matches!(self.status.get(), JobStatus::Running(_))
    }

    /// Whether Continue can run again from the result: a job gave one, and it is not proven
    /// optimal.
    pub fn can_continue(&self) -> bool {
        !self.is_running()
            && self
                .progress
                .with(|p| p.as_ref().is_some_and(|p| p.bounds.upper.is_some()))
            && !self
                .progress
                .with(|p| p.as_ref().is_some_and(|p| p.proven_optimal))
    }

    /// Forgets the result shown (a new document opened).
    pub fn clear(&self) {
        self.apply(None);
        self.chart_samples.set(Vec::new());
        self.continued_from.set_value(None);
    }

    /// Starts a job on the document with the panels' settings.
    pub fn start(&self) {
        self.launch(None);
    }

    /// Runs again from the best result so far, with another seed, pruned by its cost.
    pub fn continue_run(&self) {
        self.launch(self.progress.get_untracked());
    }

    fn launch(&self, from: Option<Progress>) {
        let Some(problem) = self.document.problem_untracked() else {
            return;
        };
        let job_id = self.worker.take_id();
        let run = if from.is_some() {
            self.runs.get_value() + 1
        } else {
            0
        };
        self.runs.set_value(run);
        let params = SolverParams {
            time_limit_s: self.solver.time_limit_s.get_untracked(),
            // A continued run explores with another seed, pruned by the best cost found.
            seed: self.solver.seed.get_untracked().wrapping_add(run),
            discretisation_step_mm: self.solver.step_mm.get_untracked(),
            initial_upper_bound: from.as_ref().and_then(|p| p.bounds.upper),
            // The stats panel's speeds and prices: chain cutting decides by this cost model.
            machine: self.machine.machine.get_untracked(),
            objective: self.solver.objective.get_untracked(),
            thermal: self.machine.thermal.get_untracked(),
            // The full cutting route: the engine's kerf job fits and optimises the leads.
            kerf: self.machine.kerf.get_untracked(),
            leads_after: false,
        };
        let solver = self.solver.kind.get_untracked();
        // Refused here, in the page's words (the engine's refusal is English), and before the
        // shown result is cleared.
        if !params.kerf.is_idealised() && !solver.cuts_with_kerf() {
            self.status.set(JobStatus::Failed(JobFailure::NoKerfModel {
                solver: solver.name(),
            }));
            return;
        }
        if from.is_none() {
            self.apply(None);
            self.chart_samples.set(Vec::new());
        }
        self.continued_from.set_value(from);
        self.status.set(JobStatus::Running(job_id));
        self.worker.send(ToWorker::Start(JobRequest {
            job_id,
            problem,
            solver,
            params,
        }));
    }

    /// Asks the running job to stop.
    pub fn stop(&self) {
        let JobStatus::Running(job_id) = self.status.get_untracked() else {
            return;
        };
        self.worker.send(ToWorker::Cancel { job_id });
        // The worker answers between solver steps, which the jobs keep short (their long
        // phases run in slices), so the job stops itself. A step that still runs long (the
        // few single pieces listed in BENCHMARKS.md, "Time limits in the engine") would hold
        // Stop up: as a safety net, after 150 ms the job is dropped with the best result
        // already received and a fresh worker takes over (the old one is told to close, and
        // its late messages name a job that is no longer running), so Stop takes effect
        // within the promised 200 ms, page updates included. The net firing is logged and
        // marked on the page (`data-stop-fallback` = the job's id), so tests can tell a job
        // that stopped itself from one that was replaced.
        let this = *self;
        set_timeout(
            move || {
                if this.status.get_untracked() == JobStatus::Running(job_id) {
                    leptos::logging::warn!(
                        "Stop: job {job_id} did not stop itself within 150 ms; its worker was \
                         replaced"
                    );
                    if let Some(root) = web_sys::window()
                        .and_then(|w| w.document())
                        .and_then(|d| d.document_element())
                    {
                        let _ = root.set_attribute("data-stop-fallback", &job_id.to_string());
                    }
                    this.worker.replace();
                    this.status.set(JobStatus::Cancelled);
                }
            },
            STOP_GRACE,
        );
    }

    /// A message of the worker about a job.
    pub fn hear(&self, message: FromWorker) {
        match message {
            FromWorker::Progress(update) if self.runs_job(update.job_id) => {
                let update = self.merged(update);
                self.chart(&update);
                self.apply(Some(update));
            }
            FromWorker::Finished(last) if self.runs_job(last.job_id) => {
                let last = self.merged(last);
                self.chart(&last);
                let missing = self.missing_tour(&last);
                self.apply(Some(last));
                self.status
                    .set(missing.map_or(JobStatus::Finished, JobStatus::Failed));
            }
            FromWorker::Cancelled(last) if self.runs_job(last.job_id) => {
                self.apply(Some(self.merged(last)));
                self.status.set(JobStatus::Cancelled);
            }
            FromWorker::Failed {
                job_id,
                message,
                parts_too_close,
            } if self.runs_job(job_id) => {
                self.status.set(JobStatus::Failed(match parts_too_close {
                    Some(refusal) => JobFailure::PartsTooClose(refusal),
                    None => JobFailure::Engine(message),
                }));
            }
            _ => {}
        }
    }

    fn runs_job(&self, job_id: JobId) -> bool {
        self.status.get_untracked() == JobStatus::Running(job_id)
    }

    /// A report made the page's own: the one place that reads a report's result (the route,
    /// the tool-on paths), so the shown result follows `Progress`'s shape from here.
    fn apply(&self, report: Option<Progress>) {
        self.best_route
            .set(report.as_ref().and_then(|p| p.route().cloned()));
        self.best_paths
            .set(report.as_ref().and_then(|p| p.path_route().cloned()));
        self.progress.set(report);
    }

    /// A PCGTSP job that ended without a tour failed: proved infeasible, or none found (the
    /// CLI's words, exit 3 there); `Progress::missing_tour`'s cases, as data the page words
    /// itself.
    fn missing_tour(&self, last: &Progress) -> Option<JobFailure> {
        if !self.document.is_instance_untracked() || last.tour().is_some() {
            return None;
        }
        let solver = self.solver.kind.get_untracked().name();
        Some(if last.proven_optimal {
            JobFailure::NoTourExists { solver }
        } else {
            JobFailure::NoTourFound {
                solver,
                seconds: last.elapsed_s,
            }
        })
    }

    /// What the bounds measure, as the job reports it (nothing before a job reports; tracked).
    pub fn bound_unit(&self, lang: Lang) -> &'static str {
        let unit = self.progress.with(|p| p.as_ref().map(|p| p.bounds.unit));
        unit.map_or("", |unit| unit_words(unit, lang))
    }

    /// Every report of the running job is a point of the bounds chart.
    fn chart(&self, p: &Progress) {
        self.chart_samples.update(|s| {
            s.push(BoundSample {
                elapsed_s: p.elapsed_s,
                upper_bound: p.bounds.upper,
                lower_bound: p.bounds.lower,
            })
        });
    }

    fn merged(&self, update: Progress) -> Progress {
        match self.continued_from.get_value() {
            Some(from) => continued(&from, update),
            None => update,
        }
    }

    /// After the worker died and a fresh one took over (`src/worker_client.rs`): what was
    /// lost is said, and nothing else changes. The document stays open (every job request
    /// carries its problem, so the fresh worker needs nothing re-sent) and so does the best
    /// route received from the job, which Continue can start from. An open in flight is not
    /// retried: the file may be what killed the worker.
    pub fn after_worker_death(&self, death: &WorkerDeath) {
        let job_lost = matches!(
            self.status.get_untracked(),
            JobStatus::Running(id) if death.jobs.contains(&id)
        );
        if job_lost {
            self.status
                .set(JobStatus::Failed(JobFailure::WorkerStopped));
        }
        if !death.opening.is_empty() {
            self.document
                .open_error
                .set(Some(PageError::WorkerDiedOpening {
                    files: death.opening.join(" + "),
                    reason: death.reason.clone(),
                }));
        }
        self.worker_notice.set(Some(WorkerNotice {
            reason: death.reason.clone(),
            job_lost,
        }));
    }
}

/// What bounds in `unit` measure, in words (the chart and the bounds show it).
fn unit_words(unit: CostUnit, lang: Lang) -> &'static str {
    match unit {
        CostUnit::IdleMm => lang.pick("mm idle", "мм холостого хода"),
        CostUnit::Seconds => lang.pick("s (machine time)", "с (время работы станка)"),
        CostUnit::Cost => lang.pick("cost", "стоимость"),
        CostUnit::TourCost => lang.pick("tour cost", "стоимость обхода"),
    }
}

/// A continued job reports on its own run; the page shows the better of that and the result it
/// continued from, with the time of both runs added up.
fn continued(from: &Progress, update: Progress) -> Progress {
    let improved = match (update.bounds.upper, from.bounds.upper) {
        (Some(new), Some(old)) => new < old - 1e-9,
        (Some(_), None) => true,
        (None, _) => false,
    };
    let lower_bound = match (update.bounds.lower, from.bounds.lower) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    let elapsed_s = from.elapsed_s + update.elapsed_s;
    if improved {
        Progress {
            elapsed_s,
            bounds: Bounds {
                lower: lower_bound,
                ..update.bounds
            },
            ..update
        }
    } else {
        Progress {
            job_id: update.job_id,
            elapsed_s,
            bounds: Bounds {
                lower: lower_bound,
                ..from.bounds
            },
            phase: update.phase,
            states: update.states,
            ..from.clone()
        }
    }
}

/// The notice after the worker died and was restarted.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkerNotice {
    reason: DeathReason,
    job_lost: bool,
}

impl WorkerNotice {
    /// The notice in words.
    pub fn text(&self, lang: Lang) -> String {
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
