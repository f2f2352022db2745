//! The drawing area: notes on the open file, the drawing, and the animation's controls; files
//! dropped on it are opened.

use leptos::prelude::*;

use crate::animation::{Animation, AnimationControls};
use crate::i18n::{tr, use_language};
use crate::import_warnings::{ImportWarnings, LeftOutShown};
use crate::nest_view::NestView;
use crate::state::{DocumentState, JobState};

/// The cutting plan.
#[component]
pub fn DrawingArea() -> impl IntoView {
    let document = expect_context::<DocumentState>();
    let animation = expect_context::<Animation>();
    // The warnings' toggle and the view's layer of left-out geometry share it.
    provide_context(LeftOutShown(RwSignal::new(false)));
    view! {
        <section
            class="view"
            aria-label=tr("Cutting plan", "Карта раскроя")
            on:dragover=move |ev: web_sys::DragEvent| ev.prevent_default()
            on:drop=move |ev: web_sys::DragEvent| {
                ev.prevent_default();
                if let Some(files) = ev.data_transfer().and_then(|d| d.files()) {
                    document.open_files(files);
                }
            }
        >
            <FileNotes />
            <NestView />
            <AnimationControls animation=animation />
        </section>
    }
}

/// Why a file did not open, the worker's restart, what the reader left out or approximated,
/// and the local file shown last time.
#[component]
fn FileNotes() -> impl IntoView {
    let document = expect_context::<DocumentState>();
    let job = expect_context::<JobState>();
    let language = use_language();
    // A local file cannot be reopened without the user: say which one it was.
    let last_file = move || {
        let shown = document.file_name();
        document.last_file.get().filter(|f| shown.as_ref() != Some(f)).map(|f| {
            view! {
                <p id="last-file" class="note">
                    {tr("Last time ", "В прошлый раз был открыт ")} <strong>{f}</strong>
                    {tr(
                        " was open: choose it again with Open files… (the sample is shown meanwhile)",
                        ": выберите его снова через «Открыть файлы…» (пока показан пример)",
                    )}
                </p>
            }
        })
    };
    view! {
        {move || document.open_error.get().map(|e| view! { <p class="error" role="alert">{e.text(language.get())}</p> })}
        {move || job.worker_notice.get().map(|n| view! { <p id="worker-notice" class="error" role="status">{n.text(language.get())}</p> })}
        <ImportWarnings />
        {last_file}
    }
}
