//! The drawing's legend: what each colour and mark of the route means, in the theme's colours
//! (the same CSS variables the drawing uses), so a printout or a projected slide explains itself.

use leptos::prelude::*;

use crate::i18n::tr;

/// The legend of the route's marks.
#[component]
pub fn DrawingLegend() -> impl IntoView {
    let item = |class: &'static str, en: &'static str, ru: &'static str| {
        view! {
            <li>
                <svg class="legend-mark" viewBox="0 0 24 12" width="24" height="12" aria-hidden="true">
                    {match class {
                        "pierce" => view! { <circle class="pierce" cx="12" cy="6" r="4" /> }.into_any(),
                        "start-marker" | "finish-marker" => {
                            view! { <rect class=class x="7" y="1" width="10" height="10" /> }.into_any()
                        }
                        _ => view! { <path class=class d="M1 6H23" /> }.into_any(),
                    }}
                </svg>
                " "
                {tr(en, ru)}
            </li>
        }
    };
    view! {
        <figure id="drawing-legend" class="legend">
            <figcaption>{tr("Legend", "Условные обозначения")}</figcaption>
            <ul>
                {item("cut", "cut (tool on)", "рабочий ход (резка)")}
                {item("idle", "idle move (tool off)", "холостой ход")}
                {item("link", "tool-on link", "перемычка (без выключения)")}
                {item("pierce", "pierce point", "точка врезки")}
                {item("lead", "lead-in and lead-out", "подвод и отвод")}
                {item("equidistants", "equidistant (kerf/2)", "эквидистанта (половина ширины реза)")}
                {item("region-pierce", "pierce region G_M (d₁)", "область врезки G_M (d₁)")}
                {item("region-switch-off", "switch-off region G_M* (d₂)", "область выключения G_M* (d₂)")}
                {item("start-marker", "start", "начало")}
                {item("finish-marker", "finish", "конец")}
            </ul>
        </figure>
    }
}
