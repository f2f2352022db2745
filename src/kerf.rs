//! The full cutting route in the page (issue #17): the machine panel's kerf, clearances d₁
//! and d₂, lead shapes and lengths, overcut and tabs (sent in every job request as
//! `SolverParams::kerf`; the engine's kerf job returns the route with its leads), and the
//! drawing's layers of it: one lead path per step (lead-in and lead-out), the equidistants the
//! tool centre runs on, the pierce (M) and switch-off (M*) points, and the outlines of the
//! pierce and switch-off regions G_M and G_M* (each contour's offsets at d₁ and d₂ on its
//! scrap side, where M and M* may lie beyond). The cuts themselves
//! (along the equidistants, tabs left as gaps) and the animation come from the route's
//! `Toolpath`, which follows lead-in → contour → lead-out.

use std::fmt::Write;

use cutroute_geometry::{
    chain_spans, equidistant, KerfSettings, LeadShape, Nest, PathRoute, Route, Vertex,
};
use leptos::prelude::*;

use crate::drawing::{contour_path, push_span};
use crate::fields::{setting_field, Accept, Words};
use crate::i18n::tr;
use crate::settings::{parse_tabs, shape_from_name, shape_name};
use crate::state::MachineSettings;

/// Path data of a lead-in and a lead-out, the lead-out as a second subpath.
fn leads_d(lead_in: &[Vertex], lead_out: &[Vertex]) -> String {
    let mut d = String::new();
    for chain in [lead_in, lead_out] {
        let Some(first) = chain.first() else { continue };
        let _ = write!(d, "M{:.3} {:.3}", first.point.x, first.point.y);
        chain_spans(chain).for_each(|span| push_span(&span, &mut d));
    }
    d
}

/// Path data of each step's leads (lead-in, then lead-out as a second subpath), one entry per
/// step that has leads.
pub fn lead_paths(route: &Route) -> Vec<String> {
    route
        .steps
        .iter()
        .filter_map(|s| s.leads.as_ref())
        .map(|leads| leads_d(&leads.lead_in, &leads.lead_out))
        .collect()
}

/// Path data of each tool-on path's leads (sccp, gsccp, aoe with kerf), one entry per path
/// that has leads.
pub fn path_lead_paths(route: &PathRoute) -> Vec<String> {
    route
        .paths
        .iter()
        .filter_map(|p| p.leads.as_ref())
        .map(|leads| leads_d(&leads.lead_in, &leads.lead_out))
        .collect()
}

/// Path data of the equidistants of the route's contours (kerf/2 off each, on its scrap side).
pub fn equidistants_path(nest: &Nest, route: &Route) -> String {
    let mut d = String::new();
    for step in &route.steps {
        let (Some(leads), Some(contour)) = (&step.leads, nest.contour(step.contour)) else {
            continue;
        };
        if let Ok(eq) = equidistant(contour, leads.offset) {
            contour_path(&eq, &mut d);
        }
    }
    d
}

/// Path data of the outlines of the pierce region G_M and the switch-off region G_M*: for each
/// step with leads, its contour's offsets at the d₁ and d₂ the leads were placed under, on the
/// contour's scrap side (a clearance of 0, or an offset that closes up, draws nothing).
pub fn region_paths(nest: &Nest, route: &Route) -> (String, String) {
    let (mut pierce, mut switch_off) = (String::new(), String::new());
    for step in &route.steps {
        let (Some(leads), Some(contour)) = (&step.leads, nest.contour(step.contour)) else {
            continue;
        };
        for (distance, d) in [
            (leads.pierce_clearance, &mut pierce),
            (leads.switch_off_clearance, &mut switch_off),
        ] {
            if distance > 0.0 {
                if let Ok(outline) = equidistant(contour, distance) {
                    contour_path(&outline, d);
                }
            }
        }
    }
    (pierce, switch_off)
}

/// Lead-in and lead-out lengths of a route, mm (0 without leads).
pub fn lead_lengths(route: &Route) -> (f64, f64) {
    route
        .steps
        .iter()
        .filter_map(|s| s.leads.as_ref())
        .fold((0.0, 0.0), |(i, o), l| {
            (i + l.lead_in_length(), o + l.lead_out_length())
        })
}

/// The lead layers of the drawing: leads, equidistants, pierce and switch-off points, of a
/// contour route or of a path route (whose cuts are the equidistants themselves).
#[component]
pub fn LeadLayers(
    nest: Signal<Option<Nest>>,
    route: Signal<Option<Route>>,
    paths: Signal<Option<PathRoute>>,
    extent: Signal<f64>,
) -> impl IntoView {
    let leads = move || {
        let mut ds = route.with(|r| r.as_ref().map(lead_paths).unwrap_or_default());
        ds.extend(paths.with(|p| p.as_ref().map(path_lead_paths).unwrap_or_default()));
        ds.into_iter()
            .map(|d| view! { <path class="lead" d=d /> })
            .collect_view()
    };
    let equidistants = move || {
        route.with(|r| {
            let r = r.as_ref()?;
            nest.with(|n| n.as_ref().map(|n| equidistants_path(n, r)))
        })
    };
    let regions = Memo::new(move |_| {
        route.with(|r| {
            let r = r.as_ref()?;
            nest.with(|n| n.as_ref().map(|n| region_paths(n, r)))
        })
    });
    let marks = move || {
        let size = extent.get() / 300.0;
        // M and M* of every step (contour route) or path (path route) with leads.
        let mut points: Vec<_> = route.with(|r| {
            r.iter()
                .flat_map(|r| r.steps.iter().filter_map(|s| s.leads.as_ref()))
                .map(|l| (l.pierce, l.switch_off))
                .collect()
        });
        paths.with(|p| {
            points.extend(p.iter().flat_map(|p| {
                p.paths
                    .iter()
                    .filter_map(|path| Some((path.pierce, path.leads.as_ref()?.switch_off)))
            }))
        });
        points
            .into_iter()
            .map(|(m, off)| {
                view! {
                    <circle class="pierce-m" cx=m.x cy=m.y r=size />
                    <rect
                        class="switch-off-m"
                        x=off.x - size
                        y=off.y - size
                        width=2.0 * size
                        height=2.0 * size
                    />
                }
            })
            .collect_view()
    };
    view! {
        <path class="equidistants" d=equidistants />
        <g class="leads">{leads}</g>
        <g class="pierce-regions">{marks}</g>
        <g class="regions">
            <path class="region-pierce" d=move || regions.get().map(|r| r.0) />
            <path class="region-switch-off" d=move || regions.get().map(|r| r.1) />
        </g>
    }
}

/// The full-route settings, beside the machine parameters.
#[component]
pub fn KerfPanel() -> impl IntoView {
    let settings = expect_context::<MachineSettings>().kerf;
    let number = |id, label, tip, get, set| length_field(settings, id, label, tip, get, set);
    let shape = |id, label, get, set| {
        view! { <LeadShapeSelect settings=settings id=id label=label get=get set=set /> }
    };
    view! {
        <details class="machine kerf">
            <summary>{tr("Kerf and leads", "Ширина реза и подводы")}</summary>
            {number("kerf-width", ("Kerf", "Ширина реза"), ("Kerf width: the tool centre runs kerf/2 off each contour; 0 cuts on the contours", "Ширина реза: центр инструмента идёт на половине ширины реза от контура; 0 — по контурам"), |k| k.kerf, |k, v| k.kerf = v)}
            {number("kerf-d1", ("Pierce clearance d₁", "Зазор врезки d₁"), ("Least distance from every contour to a pierce point", "Наименьшее расстояние от любого контура до точки врезки"), |k| k.pierce_clearance, |k, v| k.pierce_clearance = v)}
            {number("kerf-d2", ("Switch-off clearance d₂", "Зазор выключения d₂"), ("Least distance from every contour to a switch-off point", "Наименьшее расстояние от любого контура до точки выключения"), |k| k.switch_off_clearance, |k, v| k.switch_off_clearance = v)}
            {shape("lead-in-shape", ("Lead-in", "Подвод"), |k| k.lead_in.shape, |k, s| k.lead_in.shape = s)}
            {number("lead-in-length", ("Lead-in length", "Длина подвода"), ("Length of the lead-in from the pierce point to the contour", "Длина подвода от точки врезки до контура"), |k| k.lead_in.length, |k, v| k.lead_in.length = v)}
            {shape("lead-out-shape", ("Lead-out", "Отвод"), |k| k.lead_out.shape, |k, s| k.lead_out.shape = s)}
            {number("lead-out-length", ("Lead-out length", "Длина отвода"), ("Length of the lead-out from the contour to the switch-off point", "Длина отвода от контура до точки выключения"), |k| k.lead_out.length, |k, v| k.lead_out.length = v)}
            {number("kerf-overcut", ("Overcut", "Перебег"), ("How far the cut runs on past the entry before the lead-out", "На сколько рез заходит за точку входа перед отводом"), |k| k.overcut, |k, v| k.overcut = v)}
            <TabsField settings=settings />
            {switch_field(settings, "kerf-edge-pierce", ("Edge piercing", "Врезка с кромки листа"), ("Pierce parts' outer contours at the sheet's border where a straight lead from it reaches the contour (the nest needs a sheet)", "Врезка внешних контуров деталей с кромки листа, где прямой подвод от неё доходит до контура (нужен лист)"), |k| k.edge_pierce, |k, on| k.edge_pierce = on)}
            {switch_field(settings, "kerf-kerf-pierce", ("Kerf piercing", "Врезка в прорезь"), ("Pierce in the open kerf of a contour cut earlier, where a straight lead from it reaches the contour and that saves time (for machines and materials that allow it; priced at the edge-pierce time)", "Врезка в открытую прорезь ранее вырезанного контура, где прямой подвод от неё доходит до контура и это экономит время (если станок и материал позволяют; время — как врезки с кромки)"), |k| k.kerf_pierce, |k, on| k.kerf_pierce = on)}
        </details>
    }
}

/// A length of the kerf settings in mm (non-negative), with its tip.
fn length_field(
    settings: RwSignal<KerfSettings>,
    id: &'static str,
    label: Words,
    tip: Words,
    get: fn(&KerfSettings) -> f64,
    set: fn(&mut KerfSettings, f64),
) -> impl IntoView {
    let unit = ("mm", "мм");
    setting_field(
        settings,
        id,
        label,
        unit,
        Some(tip),
        Accept::NonNegative,
        get,
        set,
    )
}

/// The shape of a lead-in or lead-out.
#[component]
fn LeadShapeSelect(
    settings: RwSignal<KerfSettings>,
    id: &'static str,
    label: Words,
    get: fn(&KerfSettings) -> LeadShape,
    set: fn(&mut KerfSettings, LeadShape),
) -> impl IntoView {
    let options: [(LeadShape, Words); 4] = [
        (LeadShape::None, ("none", "нет")),
        (LeadShape::Line, ("line", "прямая")),
        (LeadShape::Arc, ("arc", "дуга")),
        (LeadShape::LineArc, ("line + arc", "прямая + дуга")),
    ];
    let option = move |(s, words): (LeadShape, Words)| {
        view! {
            <option value=shape_name(s) selected=move || get(&settings.get()) == s>
                {tr(words.0, words.1)}
            </option>
        }
    };
    view! {
        <label class="param">
            <span>{tr(label.0, label.1)}</span>
            <select
                id=id
                prop:value=move || shape_name(get(&settings.get()))
                on:change=move |ev| {
                    if let Some(s) = shape_from_name(&event_target_value(&ev)) {
                        settings.update(|k| set(k, s));
                    }
                }
            >
                {options.into_iter().map(option).collect_view()}
            </select>
        </label>
    }
}

/// Micro-joints as "N:width".
#[component]
fn TabsField(settings: RwSignal<KerfSettings>) -> impl IntoView {
    view! {
        <label class="param" title=tr("Micro-joints: N uncut gaps of WIDTH mm in the outer contour of every part (0:0 for none)", "Микроперемычки: N непрорезанных промежутков шириной W мм во внешнем контуре каждой детали (0:0 — нет)")>
            <span>{tr("Tabs N:width", "Перемычки N:ширина")}</span>
            <input
                id="kerf-tabs"
                type="text"
                inputmode="decimal"
                prop:value=move || settings.with(|k| format!("{}:{}", k.tabs.count, k.tabs.width))
                on:change=move |ev| {
                    if let Some(tabs) = parse_tabs(&event_target_value(&ev)) {
                        settings.update(|k| k.tabs = tabs);
                    }
                }
            />
        </label>
    }
}

/// A yes/no setting of the full route (edge piercing, kerf piercing).
fn switch_field(
    settings: RwSignal<KerfSettings>,
    id: &'static str,
    label: Words,
    tip: Words,
    get: fn(&KerfSettings) -> bool,
    set: fn(&mut KerfSettings, bool),
) -> impl IntoView {
    view! {
        <label class="param" title=tr(tip.0, tip.1)>
            <span>{tr(label.0, label.1)}</span>
            <input
                id=id
                type="checkbox"
                prop:checked=move || settings.with(get)
                on:change=move |ev| {
                    let on = event_target_checked(&ev);
                    settings.update(|k| set(k, on));
                }
            />
        </label>
    }
}

/// The lead lengths of the shown route, for the statistics.
#[component]
pub fn LeadStats(route: Signal<Option<Route>>) -> impl IntoView {
    let language = crate::i18n::use_language();
    let lengths = move || route.with(|r| r.as_ref().map(lead_lengths));
    let mm = move || language.pick("mm", "мм");
    // Pierces at the sheet's edge and in a cut kerf: quicker ones (`--edge-pierce-time`).
    let edge = move || route.with(|r| r.as_ref().map_or(0, Route::edge_pierce_count));
    let kerf = move || route.with(|r| r.as_ref().map_or(0, Route::kerf_pierce_count));
    let has_leads = move || {
        route.with(|r| {
            r.as_ref()
                .is_some_and(|r| r.steps.iter().any(|s| s.leads.is_some()))
        })
    };
    view! {
        <Show when=has_leads>
            <dl class="lead-stats">
                <dt>{tr("Lead-ins", "Подводы")}</dt>
                <dd id="lead-in-length" data-mm=move || lengths().map(|l| format!("{:.3}", l.0))>
                    {move || lengths().map(|l| format!("{:.1} {}", l.0, mm())).unwrap_or_default()}
                </dd>
                <dt>{tr("Lead-outs", "Отводы")}</dt>
                <dd id="lead-out-length" data-mm=move || lengths().map(|l| format!("{:.3}", l.1))>
                    {move || lengths().map(|l| format!("{:.1} {}", l.1, mm())).unwrap_or_default()}
                </dd>
                <dt>{tr("Edge / kerf pierces", "Врезки с кромки / в прорезь")}</dt>
                <dd id="quick-pierces">
                    <span id="edge-pierces">{edge}</span>
                    " / "
                    <span id="kerf-pierces">{kerf}</span>
                </dd>
            </dl>
        </Show>
    }
}
