//! The statistics panel: lengths, pierces, machine time and cost of the shown route, from
//! editable machine parameters.

use cutroute_geometry::{MachineParameters, Nest, Route};
use leptos::prelude::*;

/// One editable machine parameter: (id, label, unit, getter, setter).
type Field = (
    &'static str,
    &'static str,
    &'static str,
    fn(&MachineParameters) -> f64,
    fn(&mut MachineParameters, f64),
);

const FIELDS: [Field; 6] = [
    (
        "idle-speed",
        "Idle speed",
        "mm/s",
        |m| m.idle_speed,
        |m, v| m.idle_speed = v,
    ),
    (
        "cut-speed",
        "Cut speed",
        "mm/s",
        |m| m.cut_speed,
        |m, v| m.cut_speed = v,
    ),
    (
        "pierce-time",
        "Pierce time",
        "s",
        |m| m.pierce_time,
        |m, v| m.pierce_time = v,
    ),
    (
        "idle-price",
        "Idle price",
        "per m",
        |m| m.idle_price_per_metre,
        |m, v| m.idle_price_per_metre = v,
    ),
    (
        "cut-price",
        "Cut price",
        "per m",
        |m| m.cut_price_per_metre,
        |m, v| m.cut_price_per_metre = v,
    ),
    (
        "pierce-price",
        "Pierce price",
        "each",
        |m| m.pierce_price,
        |m, v| m.pierce_price = v,
    ),
];

/// Route statistics under `machine`.
#[component]
pub fn StatsPanel(
    nest: Signal<Option<Nest>>,
    route: Signal<Option<Route>>,
    machine: RwSignal<MachineParameters>,
) -> impl IntoView {
    let figures = move || {
        let route = route.get()?;
        let nest = nest.get()?;
        let m = machine.get();
        let idle = route.idle_length();
        let cut = route.cut_length(&nest);
        let pierces = route.pierce_count();
        Some((
            idle,
            cut,
            pierces,
            m.time(cut, idle, pierces),
            m.cost(cut, idle, pierces),
        ))
    };
    let cell = move |pick: fn((f64, f64, usize, f64, f64)) -> String| {
        move || figures().map(pick).unwrap_or_else(|| "—".into())
    };
    view! {
        <dl class="route-stats">
            <dt>"Idle length"</dt>
            // The shown figures are rounded; `data-mm` keeps 0.001 mm for checks by tools.
            <dd id="idle-length" data-mm=cell(|f| format!("{:.3}", f.0))>
                {cell(|f| format!("{:.1} mm", f.0))}
            </dd>
            <dt>"Cut length"</dt>
            <dd id="cut-length" data-mm=cell(|f| format!("{:.3}", f.1))>
                {cell(|f| format!("{:.1} mm", f.1))}
            </dd>
            <dt>"Pierces"</dt>
            <dd id="pierces">{cell(|f| f.2.to_string())}</dd>
            <dt>"Machine time"</dt>
            <dd id="machine-time">{cell(|f| format_duration(f.3))}</dd>
            <dt>"Cost"</dt>
            <dd id="route-cost">{cell(|f| format!("{:.2}", f.4))}</dd>
        </dl>
        <details class="machine">
            <summary>"Machine parameters"</summary>
            {FIELDS
                .into_iter()
                .map(|(id, label, unit, get, set)| {
                    view! {
                        <label class="param">
                            <span>{label}</span>
                            <input
                                id=id
                                type="number"
                                min="0"
                                step="any"
                                prop:value=move || get(&machine.get()).to_string()
                                on:change=move |ev| {
                                    if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                                        if v.is_finite() && v >= 0.0 {
                                            machine.update(|m| set(m, v));
                                        }
                                    }
                                }
                            />
                            <span class="unit">{unit}</span>
                        </label>
                    }
                })
                .collect_view()}
        </details>
    }
}

/// `h:mm:ss` for people reading machine time.
fn format_duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "—".into();
    }
    let total = seconds.round() as u64;
    format!("{}:{:02}:{:02}", total / 3600, total / 60 % 60, total % 60)
}
