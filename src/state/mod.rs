//! The page's state: structs of named signals with methods for what the page does, shared with
//! the components by context (`provide_context` in [`crate::app::App`], `expect_context` where
//! used). Each struct is `Copy` (signal handles), so a method captures it whole.
//!
//! - [`DocumentState`] — the open file, its sheets, and how files are opened.
//! - [`JobState`] — the solver job: start, reports, stop, end, the worker dying under it.
//! - [`SolverSettings`] — the solver panel's choices.
//! - [`MachineSettings`] — machine, kerf, thermal and G-code settings.
//! - [`ViewSettings`] — layers, the chart's axis, presentation mode and full screen.
//! - [`Shown`] — the nest, route and toolpath on show, derived from the document and the job.
//! - [`Page`] — what spans them: remembered settings, links, lecture cards, kept results.

mod document;
mod job;
mod machine;
mod shown;
mod solver;
mod view;
mod worker;

pub use document::DocumentState;
pub use job::JobState;
pub use machine::MachineSettings;
pub use shown::Shown;
pub use solver::SolverSettings;
pub use view::ViewSettings;
pub use worker::WorkerLink;

use cutroute_protocol::FromWorker;
use leptos::prelude::*;

use crate::compare::Kept;
use crate::i18n::Lang;
use crate::settings::Settings;
use crate::thermal::ThermalView;
use crate::words::solver_label;

/// The whole page's state, and the operations that touch several of its parts.
#[derive(Clone, Copy)]
pub struct Page {
    pub document: DocumentState,
    pub job: JobState,
    pub solver: SolverSettings,
    pub machine: MachineSettings,
    pub view: ViewSettings,
    pub shown: Shown,
    /// The lecture list a link carries (empty for the bundled one).
    lecture_query: StoredValue<String>,
}

impl Page {
    /// The state from what was remembered and what the link says; the worker's answers are
    /// routed to the document and the job.
    pub fn new(initial: &Settings, lecture_url: &str) -> Self {
        let worker = WorkerLink::new();
        let document = DocumentState::new(worker, initial);
        let solver = SolverSettings::new(initial);
        let machine = MachineSettings::new(initial);
        let view = ViewSettings::new(initial);
        let job = JobState::new(worker, document, solver, machine);
        let shown = Shown::new(document, job);
        worker.listen(
            move |message| match message {
                FromWorker::Opened {
                    document: opened, ..
                } => {
                    machine.take_task_speeds(&opened);
                    job.clear();
                    document.show(opened);
                }
                FromWorker::OpenFailed { error, .. } => document.refuse(error),
                about_job => job.hear(about_job),
            },
            move |death| job.after_worker_death(&death),
        );
        Self {
            document,
            job,
            solver,
            machine,
            view,
            shown,
            lecture_query: StoredValue::new(crate::gallery::lecture_query(lecture_url)),
        }
    }

    /// Shares every part by context.
    pub fn provide(&self) {
        provide_context(*self);
        provide_context(self.document);
        provide_context(self.job);
        provide_context(self.solver);
        provide_context(self.machine);
        provide_context(self.view);
        provide_context(self.shown);
    }

    /// The page's state as remembered and as linked (tracked).
    pub fn settings(&self) -> Settings {
        let mut settings = Settings::default();
        self.document.remember(&mut settings);
        self.solver.remember(&mut settings);
        self.machine.remember(&mut settings);
        self.view.remember(&mut settings);
        settings
    }

    /// Everything remembered is saved whenever it changes, and the address bar follows it.
    pub fn remember(&self) {
        let this = *self;
        Effect::new(move |_| {
            let settings = this.settings();
            settings.save();
            crate::links::replace_address(&this.link_query(&settings));
        });
    }

    /// The link's query of `settings`; a lecture list other than the bundled one rides along.
    fn link_query(&self, settings: &Settings) -> String {
        format!("{}{}", settings.query(), self.lecture_query.get_value())
    }

    /// The link of the page's state (tracked).
    pub fn share_link(&self) -> String {
        crate::links::page_link(&self.link_query(&self.settings()))
    }

    /// A lecture card: its settings as a link would set them, then its nest.
    pub fn pick_lecture(&self, url: String, query: &str) {
        // A card's file starts at its first sheet unless the card names another.
        let settings = Settings {
            sheet: 0,
            ..self.settings()
        }
        .with_query(query);
        self.solver.restore(&settings);
        self.machine.restore(&settings);
        self.view.restore(&settings);
        self.document.last_file.set(None);
        match crate::gallery::bundled_sample(&url) {
            Some(name) => self.document.open_sample(name),
            None => self.document.open_url(url, settings.sheet),
        }
    }

    /// Keeps the shown result for comparison, with its H under the panel's σ and τ.
    pub fn keep(&self, thermal: ThermalView) {
        let label = self
            .job
            .progress
            .with_untracked(|p| {
                p.as_ref().map(|_| {
                    let kind = self.solver.kind.get_untracked();
                    (solver_label(Lang::En, kind), solver_label(Lang::Ru, kind))
                })
            })
            .unwrap_or(("from the file", "из файла"));
        let heat = self
            .machine
            .thermal
            .with_untracked(|s| s.model().ok())
            .map(|model| thermal.sources.with_untracked(|s| model.load(s)));
        let machine = self.machine.machine;
        let entry = if let Some(paths) = self.shown.paths.get_untracked() {
            machine.with_untracked(|m| Kept::of_paths(&paths, m, label, heat))
        } else {
            let (Some(nest), Some(route)) = (
                self.shown.nest.get_untracked(),
                self.shown.route.get_untracked(),
            ) else {
                return;
            };
            machine.with_untracked(|m| Kept::new(&nest, &route, m, label, heat))
        };
        self.document.kept.update(|k| {
            let id = k.iter().map(|e| e.id).max().unwrap_or(0) + 1;
            k.push(Kept { id, ..entry });
        });
    }
}
