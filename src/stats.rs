//! The statistics panel: lengths, pierces, machine time and cost of the shown route (of whole
//! contours or of tool-on paths), from editable machine parameters; and the table of the
//! candidates a solver weighed (GSCCP's ensembles).

use cutroute_geometry::{MachineParameters, Nest, PathRoute, Route};
use cutroute_protocol::RouteSummary;
use leptos::prelude::*;

use crate::fields::{setting_field, Accept};
use crate::i18n::{tr, use_language, Lang};

/// One editable machine parameter: (id, (label, Russian label), (unit, Russian unit), getter,
/// setter).
type Field = (
    &'static str,
    (&'static str, &'static str),
    (&'static str, &'static str),
    fn(&MachineParameters) -> f64,
    fn(&mut MachineParameters, f64),
);

const FIELDS: [Field; 6] = [
    (
        "idle-speed",
        ("Idle speed", "Скорость холостого хода"),
        ("mm/s", "мм/с"),
        |m| m.idle_speed,
        |m, v| m.idle_speed = v,
    ),
    (
        "cut-speed",
        ("Cut speed", "Скорость резки"),
        ("mm/s", "мм/с"),
        |m| m.cut_speed,
        |m, v| m.cut_speed = v,
    ),
    (
        "pierce-time",
        ("Pierce time", "Время врезки"),
        ("s", "с"),
        |m| m.pierce_time,
        |m, v| m.pierce_time = v,
    ),
    (
        "idle-price",
        ("Idle price", "Цена холостого хода"),
        ("per m", "за м"),
        |m| m.idle_price_per_metre,
        |m, v| m.idle_price_per_metre = v,
    ),
    (
        "cut-price",
        ("Cut price", "Цена резки"),
        ("per m", "за м"),
        |m| m.cut_price_per_metre,
        |m, v| m.cut_price_per_metre = v,
    ),
    (
        "pierce-price",
        ("Pierce price", "Цена врезки"),
        ("each", "за врезку"),
        |m| m.pierce_price,
        |m, v| m.pierce_price = v,
    ),
];

/// The numbers of a route under a machine: (idle mm, cut mm, pierces, time s, cost).
pub type Figures = (f64, f64, usize, f64, f64);

/// The figures of a route of whole contours over `nest`.
pub fn route_figures(nest: &Nest, route: &Route, m: &MachineParameters) -> Figures {
    let idle = route.idle_length();
    let cut = route.cut_length(nest);
    let pierces = route.pierce_count();
    (
        idle,
        cut,
        pierces,
        m.time(cut, idle, pierces),
        m.cost(cut, idle, pierces),
    )
}

/// The figures of a route of tool-on paths (links through scrap count as cut length).
pub fn path_route_figures(route: &PathRoute, m: &MachineParameters) -> Figures {
    (
        route.idle_length(),
        route.cut_length(),
        route.pierce_count(),
        route.time(m),
        route.cost(m),
    )
}

/// Route statistics under `machine`: of `paths` when there is one, else of `route`.
#[component]
pub fn StatsPanel(
    nest: Signal<Option<Nest>>,
    route: Signal<Option<Route>>,
    paths: Signal<Option<PathRoute>>,
    machine: RwSignal<MachineParameters>,
) -> impl IntoView {
    let figures = move || {
        let m = machine.get();
        if let Some(paths) = paths.get() {
            return Some(path_route_figures(&paths, &m));
        }
        let route = route.get()?;
        let nest = nest.get()?;
        Some(route_figures(&nest, &route, &m))
    };
    let cell = move |pick: fn(Figures) -> String| {
        move || figures().map(pick).unwrap_or_else(|| "—".into())
    };
    let language = use_language();
    let mm = move |pick: fn(Figures) -> f64| {
        move || {
            figures()
                .map(|f| format!("{:.1} {}", pick(f), language.pick("mm", "мм")))
                .unwrap_or_else(|| "—".into())
        }
    };
    view! {
        <dl class="route-stats">
            <dt>{tr("Idle length", "Длина холостого хода")}</dt>
            // The shown figures are rounded; `data-mm` keeps 0.001 mm for checks by tools.
            <dd id="idle-length" data-mm=cell(|f| format!("{:.3}", f.0))>
                {mm(|f| f.0)}
            </dd>
            <dt>{tr("Cut length", "Длина резки")}</dt>
            <dd id="cut-length" data-mm=cell(|f| format!("{:.3}", f.1))>
                {mm(|f| f.1)}
            </dd>
            <dt>{tr("Pierces", "Врезки")}</dt>
            <dd id="pierces">{cell(|f| f.2.to_string())}</dd>
            <dt>{tr("Machine time", "Время работы станка")}</dt>
            // `data-s` / `data-value` keep the unrounded figures for checks by tools.
            <dd id="machine-time" data-s=cell(|f| format!("{:.3}", f.3))>{cell(|f| crate::clock::hms(f.3))}</dd>
            <dt>{tr("Cost", "Стоимость")}</dt>
            <dd id="route-cost" data-value=cell(|f| format!("{:.3}", f.4))>{cell(|f| format!("{:.2}", f.4))}</dd>
        </dl>
        <details class="machine">
            <summary>{tr("Machine parameters", "Параметры станка")}</summary>
            {FIELDS
                .into_iter()
                .map(|(id, label, unit, get, set)| {
                    setting_field(machine, id, label, unit, None, Accept::NonNegative, get, set)
                })
                .collect_view()}
        </details>
    }
}

/// The candidates a solver weighed (GSCCP: each segment ensemble and the CCP route that seeded
/// them), the one it returned marked; nothing when the solver weighed none.
#[component]
pub fn AlternativesTable(alternatives: Signal<Vec<RouteSummary>>) -> impl IntoView {
    let language = use_language();
    move || {
        let lang = language.get();
        let rows = alternatives.get();
        let idle_gap = rows
            .iter()
            .find(|r| r.chosen)
            .and_then(|r| Some((r.idle_lower_bound?, r.idle_gap()?)));
        (!rows.is_empty()).then(|| {
            view! {
                // Scrolls sideways in the narrow panel rather than clipping columns.
                <div class="table-scroll">
                <table id="alternatives" aria-label=lang.pick("Candidates the solver weighed", "Варианты, рассмотренные решателем")>
                    <caption>{lang.pick("Candidates weighed", "Рассмотренные варианты")}</caption>
                    <thead>
                        <tr>
                            <th scope="col">{lang.pick("Route", "Маршрут")}</th>
                            <th scope="col" title=lang.pick("Pierces", "Врезки")>{lang.pick("Pierc.", "Врез.")}</th>
                            <th scope="col" title=lang.pick("Idle length, mm", "Длина холостого хода, мм")>{lang.pick("Idle", "Хол.")}</th>
                            <th scope="col" title=lang.pick("Cut length, mm", "Длина резки, мм")>{lang.pick("Cut", "Рез")}</th>
                            <th scope="col" title=lang.pick("Machine time, h:mm:ss", "Время работы станка, ч:мм:сс")>{lang.pick("Time", "Время")}</th>
                            <th scope="col">{lang.pick("Cost", "Стоим.")}</th>
                        </tr>
                    </thead>
                    <tbody>
                        {rows
                            .into_iter()
                            .map(|r| {
                                let class = if r.chosen { "alternative chosen" } else { "alternative" };
                                let mark = r.chosen.then_some("✓ ");
                                let said = r.chosen.then(|| view! { <span class="visually-hidden">{lang.pick(" (chosen)", " (выбран)")}</span> });
                                let name = view! { {mark} {candidate_name(&r.name, lang)} {said} };
                                match r.failure {
                                    Some(why) => view! {
                                        <tr class=class data-name=r.name.clone() data-chosen=r.chosen.to_string()>
                                            <td>{name}</td>
                                            <td colspan="5" class="failure">{format!("{}: {why}", lang.pick("no route", "нет маршрута"))}</td>
                                        </tr>
                                    }
                                    .into_any(),
                                    None => view! {
                                        <tr class=class data-name=r.name.clone() data-chosen=r.chosen.to_string()>
                                            <td>{name}</td>
                                            <td class="alt-pierces">{r.pierces}</td>
                                            <td class="alt-idle">{format!("{:.1}", r.idle_length)}</td>
                                            <td class="alt-cut">{format!("{:.1}", r.cut_length)}</td>
                                            <td class="alt-time" data-s=format!("{:.3}", r.time_s)>{crate::clock::hms(r.time_s)}</td>
                                            <td class="alt-cost" data-value=format!("{:.3}", r.cost)>{format!("{:.2}", r.cost)}</td>
                                        </tr>
                                    }
                                    .into_any(),
                                }
                            })
                            .collect_view()}
                    </tbody>
                </table>
                // The idle part of the gap: cutting time is fixed, so the time gap hides it.
                {idle_gap.map(|(lb, gap)| view! { <p id="idle-gap" data-mm=format!("{lb:.3}")>{crate::i18n::tr("Idle gap", "Разрыв по холостому ходу")}{format!(": {:.1} % (≥ {lb:.1} mm)", gap * 100.0)}</p> })}
                </div>
            }
        })
    }
}

/// A candidate's name (a segment ensemble, or `ccp`, a solver id) in the page's language.
fn candidate_name(name: &str, lang: Lang) -> String {
    match (lang, name) {
        (Lang::Ru, "standard") => "стандартный".into(),
        (Lang::Ru, "chains") => "цепочки".into(),
        (Lang::Ru, "junctions") => "стыки".into(),
        _ => name.to_string(),
    }
}
