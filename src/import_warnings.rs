//! What the reader left out or changed when the file opened: one summary line beside the
//! drawing ("223 duplicates ignored · units: none, assumed mm") that expands on demand into
//! the list, over the drawing rather than above it so the drawing never moves, and a toggle that
//! draws the left-out geometry as a layer of the nest view.

use cutroute_geometry::{ReadWarning, WarningKind};
use leptos::prelude::*;

use crate::i18n::{tr, use_language, Lang};
use crate::state::DocumentState;

/// Whether the nest view draws the geometry the reader left out.
#[derive(Clone, Copy)]
pub struct LeftOutShown(pub RwSignal<bool>);

/// The summary's words for `count` warnings of `kind`.
fn kind_summary(kind: WarningKind, count: usize, language: Lang) -> String {
    let (en, ru) = match kind {
        WarningKind::OpenChain => ("open chains left out", "незамкнутых цепочек пропущено"),
        WarningKind::Duplicate => ("duplicates ignored", "дубликатов пропущено"),
        WarningKind::ZeroArea => (
            "contours without area left out",
            "контуров без площади пропущено",
        ),
        WarningKind::SelfIntersecting => (
            "self-intersecting contours left out",
            "самопересекающихся контуров пропущено",
        ),
        WarningKind::Skipped => ("entities skipped", "объектов пропущено"),
        WarningKind::Hidden => ("hidden elements skipped", "скрытых элементов пропущено"),
        WarningKind::Units => ("units assumed", "единицы приняты по умолчанию"),
        WarningKind::PaperSpace => ("paper space used", "использовано пространство листа"),
        WarningKind::Approximated => ("curves approximated", "кривых аппроксимировано"),
        WarningKind::Sheets => ("sheets in the file", "листов в файле"),
        WarningKind::Other => ("notes", "замечаний"),
    };
    format!("{count} {}", language.pick(en, ru))
}

/// "3 open chains left out · 223 duplicates ignored · …", kinds in the order first met; a
/// units warning is quoted, as it changes every size.
fn summary(warnings: &[ReadWarning], language: Lang) -> String {
    let mut kinds: Vec<(WarningKind, usize)> = Vec::new();
    for w in warnings {
        match kinds.iter_mut().find(|(k, _)| *k == w.kind) {
            Some((_, n)) => *n += 1,
            None => kinds.push((w.kind, 1)),
        }
    }
    kinds
        .into_iter()
        .map(|(kind, count)| match (kind, count) {
            (WarningKind::Units, 1) => {
                let w = warnings.iter().find(|w| w.kind == kind).expect("counted");
                format!("{}: {}", language.pick("units", "единицы"), w.message)
            }
            _ => kind_summary(kind, count, language),
        })
        .collect::<Vec<_>>()
        .join(" · ")
}

/// The summary line and, on demand, the list of the open file's warnings.
#[component]
pub fn ImportWarnings() -> impl IntoView {
    let document = expect_context::<DocumentState>();
    let language = use_language();
    let shown = use_context::<LeftOutShown>();
    move || {
        let warnings = document
            .document
            .with(|d| d.as_ref().map(|d| d.warnings.clone()).unwrap_or_default());
        if warnings.is_empty() {
            return None;
        }
        let line = summary(&warnings, language.get());
        let any_geometry = warnings.iter().any(|w| !w.left_out.is_empty());
        let toggle = shown.filter(|_| any_geometry).map(|LeftOutShown(on)| {
            view! {
                <label class="left-out-toggle">
                    <input
                        type="checkbox"
                        prop:checked=move || on.get()
                        on:change=move |_| on.update(|v| *v = !*v)
                    />
                    {tr("draw what was left out", "показать пропущенное")}
                </label>
            }
        });
        let items = warnings
            .into_iter()
            .map(|w| view! { <li>{w.to_string()}</li> })
            .collect_view();
        Some(view! {
            <div id="open-notes" class="note import-warnings" style="position: relative">
                <details>
                    <summary>{line}</summary>
                    // Over the drawing, not above it: opening the list never moves the drawing.
                    <ul
                        aria-label=tr("Notes on the open file", "Замечания к открытому файлу")
                        style="position: absolute; z-index: 5; left: 0; right: 0; max-height: 50vh; overflow: auto; margin: 0; background: var(--background, Canvas)"
                    >
                        {items}
                    </ul>
                </details>
                {toggle}
            </div>
        })
    }
}

/// The geometry the reader left out, as polylines in the nest's coordinates (drawn inside the
/// view's y-flipped group) when the toggle is on.
#[component]
pub fn LeftOutLayer(extent: Memo<f64>) -> impl IntoView {
    let document = expect_context::<DocumentState>();
    let shown = use_context::<LeftOutShown>();
    move || {
        let on = shown.is_some_and(|LeftOutShown(s)| s.get());
        if !on {
            return None;
        }
        let width = extent.get() / 400.0;
        let paths = document.document.with(|d| {
            d.as_ref()
                .map(|d| {
                    d.warnings
                        .iter()
                        .flat_map(|w| &w.left_out)
                        .filter(|line| line.len() >= 2)
                        .map(|line| {
                            let mut path = String::new();
                            for (i, p) in line.iter().enumerate() {
                                path.push_str(if i == 0 { "M" } else { " L" });
                                path.push_str(&format!("{} {}", p.x, p.y));
                            }
                            path
                        })
                        .collect::<Vec<_>>()
                })
                .unwrap_or_default()
        });
        Some(view! {
            <g class="left-out" fill="none" stroke="#d33" stroke-dasharray=move || format!("{} {}", 4.0 * width, 2.0 * width) stroke-width=width>
                {paths.into_iter().map(|d| view! { <path d=d /> }).collect_view()}
            </g>
        })
    }
}
