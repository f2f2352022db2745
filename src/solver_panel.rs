//! The solver panel: the solver and its parameters, Start, Stop and Continue, and the link of
//! the page's state.

use cutroute_protocol::SolverKind;
use leptos::prelude::*;

use crate::i18n::{tr, use_language, Lang};
use crate::settings::objective_from_name;
use crate::state::{DocumentState, JobState, Page, SolverSettings};
use crate::words::solver_label;

/// The panel; `initial_solver` and `initial_objective` are the names selected at first.
#[component]
pub fn SolverPanel(initial_solver: String, initial_objective: String) -> impl IntoView {
    let solver = expect_context::<SolverSettings>();
    let language = use_language();
    view! {
        <section class="solver-panel" aria-label=tr("Solver", "Решатель")>
            <SolverPicker initial=initial_solver />
            <ObjectivePicker initial=initial_objective />
            <NumberField
                id="time-limit"
                label=("Time limit, s", "Лимит времени, с")
                tip=(
                    "Wall-clock time the solver may run; it stops earlier when it proves optimality",
                    "Сколько времени может работать решатель; он останавливается раньше, если доказал оптимальность",
                )
                min="0.1"
                value=solver.time_limit_s
            />
            <SeedField />
            <NumberField
                id="step"
                label=("Pierce step, mm", "Шаг точек врезки, мм")
                tip=(
                    "Discrete solvers: spacing of candidate pierce points along each contour (smaller = finer, slower)",
                    "Дискретные решатели: шаг точек врезки-кандидатов вдоль каждого контура (меньше — точнее, но дольше)",
                )
                min="0.1"
                value=solver.step_mm
            />
            <JobButtons />
            <ShareLink />
            <p id="solver-uses" class="note">{move || solver_uses(solver.kind.get(), language.get())}</p>
        </section>
    }
}

/// Which solver runs.
#[component]
fn SolverPicker(initial: String) -> impl IntoView {
    let solver = expect_context::<SolverSettings>();
    let language = use_language();
    view! {
        <label title=tr("Which algorithm routes the tool", "Какой алгоритм строит маршрут инструмента")>
            {tr("Solver ", "Решатель ")}
            <select
                id="solver"
                aria-label=tr("Solver", "Решатель")
                prop:value=move || solver.kind.get().name()
                on:change=move |ev| {
                    if let Some(kind) = SolverKind::from_name(&event_target_value(&ev)) {
                        solver.kind.set(kind);
                    }
                }
            >
                {SolverKind::ALL
                    .iter()
                    .map(|kind| {
                        view! {
                            <option value=kind.name() selected=kind.name() == initial>
                                {move || solver_label(language.get(), *kind)}
                            </option>
                        }
                    })
                    .collect_view()}
            </select>
        </label>
    }
}

/// What routes are compared by.
#[component]
fn ObjectivePicker(initial: String) -> impl IntoView {
    let solver = expect_context::<SolverSettings>();
    view! {
        <label title=tr(
            "What routes are compared by, and what GSCCP picks its ensemble by (machine parameters in the stats panel)",
            "По какому критерию сравниваются маршруты и GSCCP выбирает ансамбль (параметры станка — в панели показателей)",
        )>
            {tr("Objective ", "Критерий ")}
            <select
                id="objective"
                aria-label=tr("Objective", "Критерий")
                prop:value=move || solver.objective.get().name()
                on:change=move |ev| {
                    if let Some(o) = objective_from_name(&event_target_value(&ev)) {
                        solver.objective.set(o);
                    }
                }
            >
                <option value="time" selected=initial == "time">{tr("machine time", "время работы станка")}</option>
                <option value="cost" selected=initial == "cost">{tr("cost", "стоимость")}</option>
            </select>
        </label>
    }
}

/// The seed of the solver's random choices.
#[component]
fn SeedField() -> impl IntoView {
    let solver = expect_context::<SolverSettings>();
    view! {
        <label title=tr(
            "Seed of the solver's random choices: the same seed repeats a run",
            "Зерно случайного выбора решателя: с тем же зерном запуск повторяется",
        )>
            {tr("Seed ", "Зерно ")}
            <input
                id="seed"
                type="number"
                min="0"
                step="1"
                prop:value=move || solver.seed.get().to_string()
                on:change=move |ev| {
                    if let Ok(v) = event_target_value(&ev).parse::<u64>() {
                        solver.seed.set(v);
                    }
                }
            />
        </label>
    }
}

/// A labelled positive number input with a tooltip (label and tip in English and Russian).
#[component]
fn NumberField(
    id: &'static str,
    label: (&'static str, &'static str),
    tip: (&'static str, &'static str),
    min: &'static str,
    value: RwSignal<f64>,
) -> impl IntoView {
    view! {
        <label title=tr(tip.0, tip.1)>
            {tr(label.0, label.1)} " "
            <input
                id=id
                type="number"
                min=min
                step="any"
                prop:value=move || value.get().to_string()
                on:change=move |ev| {
                    if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                        if v > 0.0 && v.is_finite() {
                            value.set(v);
                        }
                    }
                }
            />
        </label>
    }
}

/// Start, Stop and Continue.
#[component]
fn JobButtons() -> impl IntoView {
    let job = expect_context::<JobState>();
    let document = expect_context::<DocumentState>();
    view! {
        <button
            id="start"
            on:click=move |_| job.start()
            disabled=move || job.is_running() || document.document.with(Option::is_none)
        >
            {tr("Start", "Пуск")}
        </button>
        <button id="stop" on:click=move |_| job.stop() disabled=move || !job.is_running()>
            {tr("Stop", "Стоп")}
        </button>
        <button
            id="continue"
            title=tr(
                "Run again from the best result so far (another seed, pruned by its cost)",
                "Запустить снова от лучшего результата (другое зерно, отсечение по его стоимости)",
            )
            disabled=move || !job.can_continue()
            on:click=move |_| job.continue_run()
        >
            {tr("Continue", "Продолжить")}
        </button>
    }
}

/// The link of the page's state, and a button that copies it.
#[component]
fn ShareLink() -> impl IntoView {
    let page = expect_context::<Page>();
    view! {
        <label class="share" title=tr(
            "A link that opens this sample with these solver settings",
            "Ссылка, открывающая этот пример с этими настройками решателя",
        )>
            {tr("Link ", "Ссылка ")}
            <input id="share-link" type="text" readonly prop:value=move || page.share_link() />
        </label>
        <crate::links::CopyLinkButton link=Signal::derive(move || page.share_link()) />
    }
}

/// Which of the panel's parameters a solver uses, in words.
fn solver_uses(kind: SolverKind, lang: Lang) -> &'static str {
    if lang == Lang::Ru {
        return match kind {
            SolverKind::NearestNeighbour => "Использует: только раскрой (жадный алгоритм, один проход); оценка — длина холостого хода, мм.",
            SolverKind::Ccp => "Использует: лимит времени, зерно; оценка — длина холостого хода, мм.",
            SolverKind::Heuristic => "Использует: лимит времени, зерно, шаг точек врезки; оценка — длина холостого хода, мм.",
            SolverKind::Exact => "Использует: лимит времени, зерно, шаг точек врезки; оценки — длина холостого хода, мм.",
            SolverKind::Chain => "Использует: лимит времени, зерно, цены станка (переход с включённым инструментом заменяет врезку, если дешевле); оценки — стоимость маршрута по ценам станка.",
            SolverKind::Sccp => "Использует: лимит времени, зерно, критерий, скорости и цены станка; оценка — значение критерия.",
            SolverKind::Gsccp => "Использует: лимит времени, зерно, критерий (по нему выбирается лучший ансамбль), скорости и цены станка; оценка — значение критерия.",
            SolverKind::Aoe => "Использует: критерий, скорости и цены станка (общие кромки режутся один раз); оценка — значение критерия.",
        };
    }
    match kind {
        SolverKind::NearestNeighbour => "Uses: the nest only (greedy, one pass); bound = idle length, mm.",
        SolverKind::Ccp => "Uses: time limit, seed; bound = idle length, mm.",
        SolverKind::Heuristic => "Uses: time limit, seed, pierce step; bound = idle length, mm.",
        SolverKind::Exact => "Uses: time limit, seed, pierce step; bounds = idle length, mm.",
        SolverKind::Chain => "Uses: time limit, seed, machine prices (a link replaces a pierce when it costs less); bounds = the route's cost at the machine's prices.",
        SolverKind::Sccp => "Uses: time limit, seed, objective, machine speeds and prices; bound = the objective's value.",
        SolverKind::Gsccp => "Uses: time limit, seed, objective (picks the best ensemble), machine speeds and prices; bound = the objective's value.",
        SolverKind::Aoe => "Uses: objective, machine speeds and prices (common edges cut once); bound = the objective's value.",
    }
}
