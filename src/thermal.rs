//! Thermal rules in the page (issue #19): the material's heat settings and the shop rules in a
//! panel beside the machine parameters, H and the rule violations of the job's route, the
//! heat-map layer (the temperature field of `cutroute_thermal::HeatModel` at the animation's
//! clock time) and the violations marked on the drawing.
//!
//! H and the violations shown are the worker's (the engine's `ThermalJob` measures every
//! route it reports); the heat map recomputes the field from the shown route's heat sources on
//! the same machine clock (`cutroute_thermal::route_pierces`), frame by frame.

use cutroute_geometry::{MachineParameters, Nest, PathRoute, Route};
use cutroute_protocol::{Progress, ThermalSettings, Violation};
use cutroute_thermal::{path_route_pierces, route_pierces, Pierce};
use leptos::prelude::*;

use crate::animation::Animation;
use crate::drawing::{contour_path, heat_frame, nest_bounds};
use crate::fields::{setting_field, Accept};
use crate::i18n::{tr, use_language, Lang};
use crate::settings::Layer;
use crate::state::{JobState, MachineSettings};

/// Cells of the heat map along the drawing's longer side: fine enough to show each source's
/// σ-wide spot on a sheet of a few metres, coarse enough to redraw every animation frame.
const HEAT_CELLS_ACROSS: usize = 48;

/// What the drawing needs to show heat and violations.
#[derive(Clone, Copy)]
pub struct ThermalView {
    /// The panel's settings (the heat map's σ and τ).
    pub settings: RwSignal<ThermalSettings>,
    /// The shown route's heat sources, in time order.
    pub sources: Memo<Vec<Pierce>>,
    /// The violations of the job's route.
    pub violations: Memo<Vec<Violation>>,
}

impl ThermalView {
    /// The heat sources of the shown route (or tool-on paths) under `machine`, and the
    /// violations the job reported.
    pub fn new(
        settings: RwSignal<ThermalSettings>,
        nest: Signal<Option<Nest>>,
        route: Signal<Option<Route>>,
        paths: Signal<Option<PathRoute>>,
        machine: RwSignal<MachineParameters>,
        progress: RwSignal<Option<Progress>>,
    ) -> ThermalView {
        let sources = Memo::new(move |_| {
            let m = machine.get();
            if let Some(paths) = paths.get() {
                return path_route_pierces(&paths, &m);
            }
            match (nest.get(), route.get()) {
                (Some(nest), Some(route)) => route_pierces(&route, &nest, &m).unwrap_or_default(),
                _ => Vec::new(),
            }
        });
        let violations = Memo::new(move |_| {
            progress.with(|p| p.as_ref().map(|p| p.violations.clone()).unwrap_or_default())
        });
        ThermalView {
            settings,
            sources,
            violations,
        }
    }
}

/// The material's heat model and the shop rules, beside the machine parameters.
#[component]
pub fn ThermalPanel() -> impl IntoView {
    let settings = expect_context::<MachineSettings>().thermal;
    // Labels, units and tips as (English, Russian).
    use crate::fields::Words;
    let number = move |id: &'static str,
                       label: Words,
                       unit: Words,
                       tip: Words,
                       get: fn(&ThermalSettings) -> f64,
                       set: fn(&mut ThermalSettings, f64),
                       min_exclusive: bool| {
        let accept = if min_exclusive {
            Accept::Positive
        } else {
            Accept::NonNegative
        };
        setting_field(settings, id, label, unit, Some(tip), accept, get, set)
    };
    let rule = move |id: &'static str,
                     label: Words,
                     tip: Words,
                     get: fn(&ThermalSettings) -> bool,
                     set: fn(&mut ThermalSettings, bool)| {
        view! {
            <label class="rule" title=tr(tip.0, tip.1)>
                <input
                    id=id
                    type="checkbox"
                    prop:checked=move || get(&settings.get())
                    on:change=move |ev| {
                        let on = event_target_checked(&ev);
                        settings.update(|s| set(s, on));
                    }
                />
                {tr(label.0, label.1)}
            </label>
        }
    };
    view! {
        <details class="machine thermal">
            <summary>{tr("Heat and shop rules", "Нагрев и технологические правила")}</summary>
            {number("thermal-sigma", ("Heat radius σ", "Радиус нагрева σ"), ("mm", "мм"), ("Heat-affected radius of one pierce (material)", "Радиус зоны нагрева одной врезки (материал)"), |s| s.sigma_mm, |s, v| s.sigma_mm = v, true)}
            {number("thermal-tau", ("Cooling time τ", "Время остывания τ"), ("s", "с"), ("Time for the sheet to cool by a factor e (material)", "Время, за которое лист остывает в e раз (материал)"), |s| s.tau_s, |s, v| s.tau_s = v, true)}
            {number("thermal-weight", ("Heat weight", "Вес нагрева"), ("per H", "на ед. H"), ("Objective units (s or cost) per unit of H that nearest, ccp and chain add to their objective; 0: ignore heat", "Единицы критерия (с или стоимость) на единицу H, которые nearest, ccp и chain добавляют к критерию; 0 — нагрев не учитывается"), |s| s.weight, |s, v| s.weight = v, false)}
            {rule("rule-part", ("Part rigidity", "Жёсткость детали"), ("Pierce each part next to the free edge (sheet border or parts cut before)", "Врезка в каждую деталь у свободного края (кромка листа или уже вырезанные детали)"), |s| s.rules.part, |s, v| s.rules.part = v)}
            {rule("rule-sheet", ("Sheet rigidity", "Жёсткость листа"), ("Long parts at a narrow border first; start on the side of the large scrap's opposite, else of the most heat", "Длинные детали у узкой кромки — первыми; начинать со стороны, противоположной крупному отходу, иначе — со стороны наибольшего нагрева"), |s| s.rules.sheet, |s, v| s.rules.sheet = v)}
            {rule("rule-islands", ("No islands", "Без островов"), ("Never leave uncut parts held by less than a 20 mm strip", "Не оставлять невырезанные детали на перемычке уже 20 мм"), |s| s.rules.islands, |s, v| s.rules.islands = v)}
            {rule("rules-hard", ("Enforce (hard)", "Соблюдать строго"), ("Repair the final route until the checked rules hold (nearest, ccp, heuristic, exact, chain)", "Исправлять итоговый маршрут, пока проверяемые правила не выполнены (nearest, ccp, heuristic, exact, chain)"), |s| s.hard, |s, v| s.hard = v)}
        </details>
    }
}

/// Short name of a violation's rule group (the CLI's `rule_violations` keys).
pub fn violation_kind(v: &Violation) -> &'static str {
    match v {
        Violation::PartRigidity { .. } => "part",
        Violation::LongPartLate { .. } | Violation::WrongStartSide { .. } => "sheet",
        Violation::Island { .. } => "islands",
    }
}

/// The step and contour a violation is about.
fn violation_place(v: &Violation) -> (usize, cutroute_geometry::ContourRef) {
    match v {
        Violation::PartRigidity { step, contour, .. } => (*step, *contour),
        Violation::LongPartLate { step, part }
        | Violation::WrongStartSide { step, part, .. }
        | Violation::Island { step, part } => (*step, *part),
    }
}

fn violation_text(v: &Violation, lang: Lang) -> String {
    match (v, lang) {
        (Violation::PartRigidity { excess_mm, .. }, Lang::En) => {
            format!("pierced {excess_mm:.1} mm farther from the free edge than allowed")
        }
        (Violation::PartRigidity { excess_mm, .. }, Lang::Ru) => {
            format!("врезка на {excess_mm:.1} мм дальше от свободного края, чем допустимо")
        }
        (Violation::LongPartLate { .. }, Lang::En) => {
            "long part at a narrow border cut late".into()
        }
        (Violation::LongPartLate { .. }, Lang::Ru) => {
            "длинная деталь у узкой кромки вырезана поздно".into()
        }
        (Violation::WrongStartSide { required, rule, .. }, Lang::En) => format!(
            "start on the wrong side (rule {rule}: the {} side)",
            match required {
                cutroute_thermal::Side::Low => "low",
                cutroute_thermal::Side::High => "high",
            }
        ),
        (Violation::WrongStartSide { required, rule, .. }, Lang::Ru) => format!(
            "начало не с той стороны (правило {rule}: со стороны {})",
            match required {
                cutroute_thermal::Side::Low => "меньших координат",
                cutroute_thermal::Side::High => "больших координат",
            }
        ),
        (Violation::Island { .. }, Lang::En) => "left as an island by this cut".into(),
        (Violation::Island { .. }, Lang::Ru) => "после этого реза остаётся островом".into(),
    }
}

/// A rule group's name (`part`, `sheet`, `islands`) in the page's language.
fn kind_word(kind: &'static str, lang: Lang) -> &'static str {
    match (lang, kind) {
        (Lang::Ru, "part") => "деталь",
        (Lang::Ru, "sheet") => "лист",
        (Lang::Ru, "islands") => "острова",
        _ => kind,
    }
}

/// H and the rule violations of the job's route.
#[component]
pub fn ThermalStats() -> impl IntoView {
    let progress = expect_context::<JobState>().progress;
    view! {
        <dl class="thermal-stats">
            <HeatFigure progress=progress />
            <RuleCounts progress=progress />
        </dl>
        <ViolationList progress=progress />
    }
}

/// H, rounded; `data-value` keeps it unrounded for checks by tools.
#[component]
fn HeatFigure(progress: RwSignal<Option<Progress>>) -> impl IntoView {
    let heat = move || progress.with(|p| p.as_ref().and_then(|p| p.heat));
    view! {
        <dt title=tr(
            "Thermal load: Σ over pairs of pierces of exp(−d²/2σ²)·exp(−Δt/τ) on the machine clock",
            "Тепловая нагрузка: Σ по парам врезок exp(−d²/2σ²)·exp(−Δt/τ) по часам станка",
        )>{tr("Heat H", "Нагрев H")}</dt>
        <dd id="heat" data-value=move || heat().map(|h| format!("{h:e}")).unwrap_or_default()>
            {move || heat().map(|h| format!("{h:.4}")).unwrap_or_else(|| "—".into())}
        </dd>
    }
}

/// How many violations of each checked rule the route has.
#[component]
fn RuleCounts(progress: RwSignal<Option<Progress>>) -> impl IntoView {
    let language = use_language();
    let counts = move || progress.with(|p| p.as_ref().and_then(|p| p.rule_counts));
    let count = move |pick: fn(&cutroute_protocol::RuleCounts) -> Option<usize>| {
        move || {
            counts()
                .and_then(|c| pick(&c))
                .map(|n| n.to_string())
                .unwrap_or_default()
        }
    };
    let text = move || match counts() {
        None => language
            .pick("— (no rule checked)", "— (правила не проверялись)")
            .to_string(),
        Some(c) => [("part", c.part), ("sheet", c.sheet), ("islands", c.islands)]
            .into_iter()
            .filter_map(|(name, n)| n.map(|n| format!("{} {n}", kind_word(name, language.get()))))
            .collect::<Vec<_>>()
            .join(" · "),
    };
    view! {
        <dt>{tr("Rule violations", "Нарушения правил")}</dt>
        <dd
            id="rule-counts"
            data-part=count(|c| c.part)
            data-sheet=count(|c| c.sheet)
            data-islands=count(|c| c.islands)
        >
            {text}
        </dd>
    }
}

/// Each violation, with the cut and the contour it is at.
#[component]
fn ViolationList(progress: RwSignal<Option<Progress>>) -> impl IntoView {
    let language = use_language();
    let item = move |v: &Violation| {
        let (step, contour) = violation_place(v);
        let kind = violation_kind(v);
        view! {
            <li
                class=format!("violation-item {kind}")
                data-kind=kind
                data-step=step
                data-part=contour.part
                data-contour=contour.contour
            >
                {violation_line(v, language.get())}
            </li>
        }
    };
    let items = move || {
        progress.with(|p| {
            p.as_ref()
                .map(|p| p.violations.iter().map(item).collect_view())
        })
    };
    view! {
        <ol id="violations" class="violations" aria-label=tr("Rule violations", "Нарушения правил")>
            {items}
        </ol>
    }
}

/// One violation in words: its kind, the cut, the contour, and what is wrong.
fn violation_line(v: &Violation, lang: Lang) -> String {
    let (step, contour) = violation_place(v);
    let kind = violation_kind(v);
    match lang {
        Lang::En => format!(
            "{kind}: cut {}, part {} contour {} — {}",
            step + 1,
            contour.part + 1,
            contour.contour,
            violation_text(v, Lang::En)
        ),
        Lang::Ru => format!(
            "{}: рез {}, деталь {} контур {} — {}",
            kind_word(kind, Lang::Ru),
            step + 1,
            contour.part + 1,
            contour.contour,
            violation_text(v, Lang::Ru)
        ),
    }
}

/// The heat map: the temperature field at the animation's clock time (at the route's end when
/// the animation is not started), one path per colour level.
#[component]
pub fn HeatMapLayer(
    thermal: ThermalView,
    nest: Signal<Option<Nest>>,
    hidden: RwSignal<Vec<Layer>>,
    animation: Animation,
) -> impl IntoView {
    let bounds = Memo::new(move |_| nest.with(|n| n.as_ref().and_then(nest_bounds)));
    move || {
        if hidden.with(|h| h.contains(&Layer::Heat)) {
            return None;
        }
        let bounds = bounds.get()?;
        let model = thermal.settings.with(|s| s.model().ok())?;
        let t = animation.time.get().unwrap_or_else(|| {
            animation
                .timeline
                .with(|t| t.as_ref().map_or(0.0, |t| t.total()))
        });
        let frame = thermal
            .sources
            .with(|sources| heat_frame(&model, sources, bounds, t, HEAT_CELLS_ACROSS));
        Some(view! {
            <g
                id="heat-map"
                class="heat-map"
                // What a test needs to recompute the field: the exact clock time, the sampled
                // rectangle and its cells across, and the colour levels' thresholds.
                data-time=format!("{t}")
                data-grid=format!(
                    "{} {} {} {} {HEAT_CELLS_ACROSS}",
                    bounds.min.x, bounds.min.y, bounds.max.x, bounds.max.y
                )
                data-levels=crate::drawing::HEAT_LEVELS.map(|l| l.to_string()).join(" ")
                data-max=format!("{:.6}", frame.max)
                data-sum=format!("{:.6}", frame.sum)
            >
                {frame
                    .levels
                    .into_iter()
                    .map(|(level, d, cells)| {
                        view! { <path class=format!("heat heat-{level}") data-cells=cells d=d /> }
                    })
                    .collect_view()}
            </g>
        })
    }
}

/// The violations on the drawing: a ring at the pierce point that breaks part rigidity, the
/// outline of each part a sheet rule or the island rule is about.
#[component]
pub fn ViolationMarks(
    thermal: ThermalView,
    nest: Signal<Option<Nest>>,
    route: Signal<Option<Route>>,
    extent: Memo<f64>,
) -> impl IntoView {
    let language = use_language();
    move || {
        let lang = language.get();
        let violations = thermal.violations.get();
        if violations.is_empty() {
            return None;
        }
        let r = extent.get() / 120.0;
        let route = route.get()?;
        nest.with(|n| {
            let n = n.as_ref()?;
            Some(
                violations
                    .iter()
                    .filter_map(|v| {
                        let (step, contour) = violation_place(v);
                        let kind = violation_kind(v);
                        let title = match lang {
                            Lang::En => {
                                format!("{kind}: cut {} — {}", step + 1, violation_text(v, lang))
                            }
                            Lang::Ru => format!(
                                "{}: рез {} — {}",
                                kind_word(kind, lang),
                                step + 1,
                                violation_text(v, lang)
                            ),
                        };
                        if let Violation::PartRigidity { .. } = v {
                            let p = route.steps.get(step)?.pierce_point;
                            Some(
                                view! {
                                    <circle class="violation part" cx=p.x cy=p.y r=r data-step=step>
                                        <title>{title}</title>
                                    </circle>
                                }
                                .into_any(),
                            )
                        } else {
                            let mut d = String::new();
                            contour_path(n.contour(contour)?, &mut d);
                            Some(
                                view! {
                                    <path class=format!("violation {kind}") d=d data-step=step>
                                        <title>{title}</title>
                                    </path>
                                }
                                .into_any(),
                            )
                        }
                    })
                    .collect_view(),
            )
        })
    }
}
