//! The job's status list: file, job, phase, bounds, gap, time and certificates.

use leptos::prelude::*;

use crate::i18n::{tr, use_language};
use crate::state::{DocumentState, JobState, Shown};
use crate::words::{format_text, phase_text};

/// The status list of the side panel.
#[component]
pub fn JobStatusList() -> impl IntoView {
    let document = expect_context::<DocumentState>();
    let job = expect_context::<JobState>();
    let language = use_language();
    let progress = job.progress;
    view! {
        <dl>
            <dt>{tr("File", "Файл")}</dt>
            <dd id="file-name">
                {move || document.document.get().map(|d| format!("{} ({})", d.file_name, format_text(language.get(), &d.format))).unwrap_or_default()}
            </dd>
            <dt>{tr("Job", "Задача")}</dt>
            <dd id="job-status">{move || job.status.get().label(language.get())}</dd>
            <dt>{tr("Phase", "Этап")}</dt>
            <dd id="phase">
                {move || progress.with(|p| p.as_ref().map(|p| phase_text(language.get(), &p.phase))).unwrap_or_default()}
                // Phases that count towards a total (the exact model's matrix rows) show how
                // far they are.
                {move || progress.with(|p| p.as_ref().and_then(|p| p.phase.fraction())).map(|(done, total)| {
                    view! {
                        <progress
                            id="phase-progress"
                            max=total.max(1)
                            value=done
                            aria-label=tr("Phase progress", "Ход этапа")
                        ></progress>
                    }
                })}
            </dd>
            <BoundRows />
            <dt>{tr("Elapsed", "Прошло")}</dt>
            <dd id="elapsed">{move || progress.get().map(|p| format!("{:.2} {}", p.elapsed_s, language.pick("s", "с"))).unwrap_or_default()}</dd>
            <CertifiedRow />
        </dl>
    }
}

/// The upper and lower bounds and the gap between them.
#[component]
fn BoundRows() -> impl IntoView {
    let job = expect_context::<JobState>();
    let language = use_language();
    let progress = job.progress;
    view! {
        <dt>{tr("Upper bound", "Верхняя оценка")}</dt>
        <dd id="upper-bound" data-unit=move || job.bound_unit(language.get())>{move || format_bound(progress.get().and_then(|p| p.bounds.upper))}</dd>
        <dt>{tr("Lower bound", "Нижняя оценка")}</dt>
        <dd id="lower-bound">{move || format_bound(progress.get().and_then(|p| p.bounds.lower))}</dd>
        <dt>{tr("Gap", "Разрыв")}</dt>
        <dd id="gap">
            {move || progress.get().and_then(|p| {
                let gap = format!("{:.2} %", p.gap()? * 100.0);
                let proven = language.pick("proven optimal", "оптимальность доказана");
                Some(if p.proven_optimal { format!("{gap} · {proven}") } else { gap })
            }).unwrap_or_else(|| "—".into())}
        </dd>
    }
}

/// How many contours of the route CCP certified optimal.
#[component]
fn CertifiedRow() -> impl IntoView {
    let certified = expect_context::<Shown>().certified;
    let language = use_language();
    view! {
        <dt>{tr("Certified", "Подтверждено")}</dt>
        <dd id="certified-count">
            {move || certified.with(|c| {
                if c.is_empty() {
                    "—".to_string()
                } else {
                    let of = language.pick("of", "из");
                    format!("{} {of} {}", c.iter().filter(|x| **x).count(), c.len())
                }
            })}
        </dd>
    }
}

fn format_bound(value: Option<f64>) -> String {
    value
        .map(|v| format!("{v:.1}"))
        .unwrap_or_else(|| "—".into())
}
