//! The open document and the ways a file reaches it: a bundled sample, a hosted file
//! (`?file=URL`), local files (picker or drop), another sheet of the file shown.

use cutroute_geometry::{Nest, PathRoute};
use cutroute_protocol::{Document, Problem, ToWorker};
use leptos::prelude::*;

use crate::app::{fetch_bytes, read_file};
use crate::compare::Kept;
use crate::settings::Settings;
use crate::state::WorkerLink;
use crate::words::PageError;

/// The file shown and where it came from. The worker opens every file (the engine's one door);
/// the page fetches or reads the bytes and shows what comes back.
#[derive(Clone, Copy)]
pub struct DocumentState {
    /// What the worker opened last.
    pub document: RwSignal<Option<Document>>,
    /// Why the last file could not be fetched, read or opened.
    pub open_error: RwSignal<Option<PageError>>,
    /// The tool-on paths a G-code file holds when they are not whole contours.
    pub file_paths: RwSignal<Option<PathRoute>>,
    /// The bundled sample chosen.
    pub sample: RwSignal<String>,
    /// The name of the last local files opened (they cannot be reopened without the user).
    pub last_file: RwSignal<Option<String>>,
    /// The hosted file shown (`?file=URL`).
    pub file_url: RwSignal<Option<String>>,
    /// Results kept for comparison; a different nest clears them.
    pub kept: RwSignal<Vec<Kept>>,
    /// The single file shown last, kept so another of its sheets can be opened.
    opened_file: StoredValue<Option<(String, Vec<u8>)>>,
    /// The local files sent to the worker and not yet shown: they become `last_file` once
    /// shown, never when refused.
    pending_local: StoredValue<Option<String>>,
    worker: WorkerLink,
}

impl DocumentState {
    /// Nothing open yet; `settings` names the sample, hosted file and local file last shown.
    pub fn new(worker: WorkerLink, settings: &Settings) -> Self {
        Self {
            document: RwSignal::new(None),
            open_error: RwSignal::new(None),
            file_paths: RwSignal::new(None),
            sample: RwSignal::new(settings.sample.clone()),
            last_file: RwSignal::new(settings.last_file.clone()),
            file_url: RwSignal::new(settings.file_url.clone()),
            kept: RwSignal::new(Vec::new()),
            opened_file: StoredValue::new(None),
            pending_local: StoredValue::new(None),
            worker,
        }
    }

    /// Opens what the page starts with: the hosted file of a link, else the sample.
    pub fn open_initial(&self, settings: &Settings) {
        match settings.file_url.clone() {
            Some(url) => self.open_url(url, settings.sheet),
            None => self.open_sample(settings.sample.clone()),
        }
    }

    /// Writes what is open into `settings` (tracked).
    pub fn remember(&self, settings: &mut Settings) {
        settings.sample = self.sample.get();
        settings.last_file = self.last_file.get();
        settings.file_url = self.file_url.get();
        settings.sheet = self.document.with(|d| d.as_ref().map_or(0, |d| d.sheet));
    }

    /// A bundled sample, fetched here and opened by the worker.
    pub fn open_sample(&self, file_name: String) {
        let this = *self;
        let request_id = self.worker.take_id();
        self.sample.set(file_name.clone());
        self.file_url.set(None);
        self.pending_local.set_value(None);
        leptos::task::spawn_local(async move {
            let url = format!("./assets/samples/{file_name}");
            match fetch_bytes(&url).await {
                Ok(bytes) => {
                    this.opened_file
                        .set_value(Some((file_name.clone(), bytes.clone())));
                    this.worker.send(ToWorker::Open {
                        request_id,
                        files: vec![(file_name, bytes)],
                    });
                }
                Err(message) => this.open_error.set(Some(PageError::Fetch { url, message })),
            }
        });
    }

    /// A hosted nest (`?file=URL`, `&sheet=N` of a multi-sheet one): fetched here, opened by
    /// the worker like a dropped file.
    pub fn open_url(&self, url: String, sheet: usize) {
        let this = *self;
        let request_id = self.worker.take_id();
        self.file_url.set(Some(url.clone()));
        self.last_file.set(None);
        self.pending_local.set_value(None);
        leptos::task::spawn_local(async move {
            match fetch_bytes(&url).await {
                Ok(bytes) => {
                    let name = crate::links::file_name_of(&url);
                    this.opened_file
                        .set_value(Some((name.clone(), bytes.clone())));
                    this.worker.send(if sheet > 0 {
                        ToWorker::OpenSheet {
                            request_id,
                            file: (name, bytes),
                            sheet,
                        }
                    } else {
                        ToWorker::Open {
                            request_id,
                            files: vec![(name, bytes)],
                        }
                    });
                }
                Err(message) => this.open_error.set(Some(PageError::Fetch { url, message })),
            }
        });
    }

    /// Local files (picker or drag and drop) go to the worker as bytes, all in one request:
    /// the engine's one door decides what they are and how they combine (a nest with its task
    /// and a PCGLNS result, an instance with its result), off the UI thread.
    pub fn open_files(&self, files: web_sys::FileList) {
        let this = *self;
        let files: Vec<web_sys::File> = (0..files.length()).filter_map(|i| files.item(i)).collect();
        leptos::task::spawn_local(async move {
            let mut batch = Vec::new();
            for file in files {
                match read_file(&file).await {
                    Ok(bytes) => batch.push((file.name(), bytes)),
                    Err(message) => this.open_error.set(Some(PageError::Read {
                        file_name: file.name(),
                        message,
                    })),
                }
            }
            if batch.is_empty() {
                return;
            }
            let names: Vec<String> = batch.iter().map(|(n, _)| n.clone()).collect();
            this.pending_local.set_value(Some(names.join(" + ")));
            this.opened_file
                .set_value((batch.len() == 1).then(|| batch[0].clone()));
            let request_id = this.worker.take_id();
            this.worker.send(ToWorker::Open {
                request_id,
                files: batch,
            });
        });
    }

    /// Another sheet of the multi-sheet file shown.
    pub fn open_sheet(&self, sheet: usize) {
        if let Some(file) = self.opened_file.get_value() {
            let request_id = self.worker.take_id();
            self.worker.send(ToWorker::OpenSheet {
                request_id,
                file,
                sheet,
            });
        }
    }

    /// The worker refused the files sent: the page says why and keeps what it showed (the
    /// refused files are not "the last file open").
    pub fn refuse(&self, error: cutroute_protocol::OpenError) {
        self.pending_local.set_value(None);
        self.open_error.set(Some(PageError::Open(error)));
    }

    /// Shows what the worker opened. Kept results stay only while the nest is the same one.
    pub fn show(&self, mut opened: Document) {
        self.open_error.set(None);
        if let Some(names) = self.pending_local.try_update_value(Option::take).flatten() {
            self.last_file.set(Some(names));
            self.file_url.set(None);
        }
        let same_nest = self
            .document
            .with_untracked(|d| d.as_ref().map(|d| &d.problem) == Some(&opened.problem));
        if !same_nest {
            self.kept.set(Vec::new());
        }
        self.file_paths.set(opened.paths.take());
        self.document.set(Some(opened));
    }

    /// The nest open, if the document is one (not a PCGTSP instance).
    pub fn nest(&self) -> Option<Nest> {
        self.document
            .with(|d| match d.as_ref().map(|d| &d.problem) {
                Some(Problem::Nest { nest, .. }) => Some(nest.clone()),
                _ => None,
            })
    }

    /// Whether the document is a PCGTSP instance, read without tracking.
    pub fn is_instance_untracked(&self) -> bool {
        self.document.with_untracked(|d| {
            d.as_ref()
                .is_some_and(|d| matches!(d.problem, Problem::PcgtspText { .. }))
        })
    }

    /// The problem to solve, read without tracking.
    pub fn problem_untracked(&self) -> Option<Problem> {
        self.document
            .with_untracked(|d| d.as_ref().map(|d| d.problem.clone()))
    }

    /// The name of the file shown.
    pub fn file_name(&self) -> Option<String> {
        self.document
            .with(|d| d.as_ref().map(|d| d.file_name.clone()))
    }
}
