//! Results kept for comparison: several routes of the same nest side by side (numbers) and up to
//! two of them overlaid on the drawing. Routes of whole contours and routes of tool-on paths
//! (segment cutting, AOE) are compared alike, by the objective the user chooses (machine time
//! or cost).

use cutroute_geometry::{MachineParameters, Nest, Objective, PathRoute, Route};
use leptos::prelude::*;

use crate::drawing::{idle_path, path_route_idle_path};
use crate::i18n::{tr, use_language, Lang};
use crate::state::Page;
use crate::stats::{path_route_figures, route_figures, Figures};
use crate::thermal::ThermalView;

/// A kept result.
#[derive(Clone, Debug, PartialEq)]
pub struct Kept {
    /// Number shown in the list (1, 2, …).
    pub id: usize,
    /// Which solver (or "from the file"), in English and Russian.
    pub label: (&'static str, &'static str),
    /// Idle length, mm.
    pub idle_length: f64,
    /// Cut length, mm.
    pub cut_length: f64,
    /// Number of pierces.
    pub pierces: usize,
    /// Machine time, s.
    pub time_s: f64,
    /// Cost.
    pub cost: f64,
    /// Thermal load H under the panel's σ and τ when kept (`None`: the settings were invalid).
    pub heat: Option<f64>,
    /// Path data of the route's idle moves (what an overlay draws).
    pub idle_d: String,
    /// Drawn over the current route.
    pub overlay: bool,
}

impl Kept {
    fn from_figures(
        (idle_length, cut_length, pierces, time_s, cost): Figures,
        idle_d: String,
        label: (&'static str, &'static str),
        heat: Option<f64>,
    ) -> Kept {
        Kept {
            id: 0,
            label,
            idle_length,
            cut_length,
            pierces,
            time_s,
            cost,
            heat,
            idle_d,
            overlay: false,
        }
    }

    /// The figures of `route` under `machine`, with its H.
    pub fn new(
        nest: &Nest,
        route: &Route,
        machine: &MachineParameters,
        label: (&'static str, &'static str),
        heat: Option<f64>,
    ) -> Kept {
        Kept::from_figures(
            route_figures(nest, route, machine),
            idle_path(route),
            label,
            heat,
        )
    }

    /// The figures of a route of tool-on paths under `machine`, with its H.
    pub fn of_paths(
        route: &PathRoute,
        machine: &MachineParameters,
        label: (&'static str, &'static str),
        heat: Option<f64>,
    ) -> Kept {
        Kept::from_figures(
            path_route_figures(route, machine),
            path_route_idle_path(route),
            label,
            heat,
        )
    }

    /// The value of the objective the results are compared by.
    pub fn value(&self, objective: Objective) -> f64 {
        match objective {
            Objective::Time => self.time_s,
            Objective::Cost => self.cost,
        }
    }
}

/// The list of kept results with a Keep button.
#[component]
pub fn ComparePanel() -> impl IntoView {
    let page = expect_context::<Page>();
    let thermal = expect_context::<ThermalView>();
    let kept = page.document.kept;
    let objective = page.solver.objective;
    let best = Signal::derive(move || {
        let objective = objective.get();
        kept.with(|k| {
            k.iter()
                .map(|e| e.value(objective))
                .fold(f64::INFINITY, f64::min)
        })
    });
    view! {
        <section class="compare" aria-label=tr("Compare results", "Сравнение результатов")>
            <h2>{tr("Compare", "Сравнение")}</h2>
            <button
                id="keep-result"
                title=tr(
                    "Keep the route shown to compare it with later ones",
                    "Сохранить показанный маршрут, чтобы сравнить его с последующими",
                )
                disabled=move || !page.shown.has_route()
                on:click=move |_| page.keep(thermal)
            >
                {tr("Keep this result", "Сохранить результат")}
            </button>
            <button
                id="clear-kept"
                disabled=move || kept.with(Vec::is_empty)
                on:click=move |_| kept.set(Vec::new())
            >
                {tr("Clear", "Очистить")}
            </button>
            <table id="compare-table">
                <CompareHead objective=objective />
                <tbody>
                    <For
                        each=move || kept.get()
                        key=|e| (e.id, e.overlay)
                        children=move |entry: Kept| view! { <KeptRow entry=entry kept=kept objective=objective best=best /> }
                    />
                </tbody>
            </table>
        </section>
    }
}

/// The table's head; the column of excess names the objective.
#[component]
fn CompareHead(objective: RwSignal<Objective>) -> impl IntoView {
    let language = use_language();
    view! {
        <thead>
            <tr>
                <th scope="col">"#"</th>
                <th scope="col">{tr("Solver", "Решатель")}</th>
                <th scope="col">{tr("Idle, mm", "Хол. ход, мм")}</th>
                <th scope="col" id="compare-by">{move || match language.get() {
                    Lang::En => format!("vs best ({})", objective.get().name()),
                    Lang::Ru => format!(
                        "к лучшему ({})",
                        match objective.get() {
                            Objective::Time => "время",
                            Objective::Cost => "стоимость",
                        }
                    ),
                }}</th>
                <th scope="col">{tr("Time, h:mm:ss", "Время, ч:мм:сс")}</th>
                <th scope="col">{tr("Cost", "Стоимость")}</th>
                <th scope="col" title=tr("Thermal load H under the heat panel's σ and τ", "Тепловая нагрузка H при σ и τ из тепловой панели")>"H"</th>
                <th scope="col">{tr("Pierces", "Врезки")}</th>
                <th scope="col">{tr("Overlay", "Наложить")}</th>
            </tr>
        </thead>
    }
}

/// A kept result's row: its figures, how far it is above the best, and its overlay switch.
#[component]
fn KeptRow(
    entry: Kept,
    kept: RwSignal<Vec<Kept>>,
    objective: RwSignal<Objective>,
    best: Signal<f64>,
) -> impl IntoView {
    let language = use_language();
    let e = entry;
    let id = e.id;
    let (time_s, cost) = (e.time_s, e.cost);
    let value = move || match objective.get() {
        Objective::Time => time_s,
        Objective::Cost => cost,
    };
    let excess = move || {
        let b = best.get();
        if b > 0.0 {
            format!("+{:.1} %", (value() / b - 1.0) * 100.0)
        } else {
            "—".into()
        }
    };
    view! {
        <tr class="kept" data-id=id>
            <td>{id}</td>
            <td>{tr(e.label.0, e.label.1)}</td>
            <td class="kept-idle">{format!("{:.1}", e.idle_length)}</td>
            <td>{excess}</td>
            <td class="kept-time" data-s=format!("{:.3}", e.time_s)>{crate::clock::hms(e.time_s)}</td>
            <td class="kept-cost">{format!("{:.2}", e.cost)}</td>
            <td class="kept-heat">{e.heat.map_or_else(|| "—".into(), |h| format!("{h:.4}"))}</td>
            <td class="kept-pierces">{e.pierces}</td>
            <td>
                <input
                    type="checkbox"
                    class="kept-overlay"
                    aria-label=move || match language.get() {
                        Lang::En => format!("Overlay result {id} on the drawing"),
                        Lang::Ru => format!("Наложить результат {id} на чертёж"),
                    }
                    prop:checked=e.overlay
                    on:change=move |ev| {
                        let on = event_target_checked(&ev);
                        kept.update(|k| {
                            if let Some(x) = k.iter_mut().find(|x| x.id == id) {
                                x.overlay = on;
                            }
                        });
                    }
                />
            </td>
        </tr>
    }
}
