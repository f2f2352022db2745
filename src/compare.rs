//! Results kept for comparison: several routes of the same nest side by side (numbers) and up to
//! two of them overlaid on the drawing.

use cutroute_geometry::{MachineParameters, Nest, Route};
use leptos::prelude::*;

/// A kept result.
#[derive(Clone, Debug, PartialEq)]
pub struct Kept {
    /// Number shown in the list (1, 2, …).
    pub id: usize,
    /// Which solver (or "from the file").
    pub label: &'static str,
    /// Idle length, mm.
    pub idle_length: f64,
    /// Cut length, mm.
    pub cut_length: f64,
    /// Number of pierces.
    pub pierces: usize,
    /// Machine time, s.
    pub time_s: f64,
    /// The route.
    pub route: Route,
    /// Drawn over the current route.
    pub overlay: bool,
}

impl Kept {
    /// The figures of `route` under `machine`.
    pub fn new(
        nest: &Nest,
        route: Route,
        machine: &MachineParameters,
        label: &'static str,
    ) -> Kept {
        let idle_length = route.idle_length();
        let cut_length = route.cut_length(nest);
        let pierces = route.pierce_count();
        Kept {
            id: 0,
            label,
            idle_length,
            cut_length,
            pierces,
            time_s: machine.time(cut_length, idle_length, pierces),
            route,
            overlay: false,
        }
    }
}

/// The list of kept results with a Keep button.
#[component]
pub fn ComparePanel(
    kept: RwSignal<Vec<Kept>>,
    keep: impl Fn(web_sys::MouseEvent) + 'static,
    can_keep: Signal<bool>,
) -> impl IntoView {
    let best = move || {
        kept.with(|k| {
            k.iter()
                .map(|e| e.idle_length)
                .fold(f64::INFINITY, f64::min)
        })
    };
    view! {
        <section class="compare" aria-label="Compare results">
            <h2>"Compare"</h2>
            <button
                id="keep-result"
                title="Keep the route shown to compare it with later ones"
                disabled=move || !can_keep.get()
                on:click=keep
            >
                "Keep this result"
            </button>
            <button
                id="clear-kept"
                disabled=move || kept.with(Vec::is_empty)
                on:click=move |_| kept.set(Vec::new())
            >
                "Clear"
            </button>
            <table id="compare-table">
                <thead>
                    <tr>
                        <th scope="col">"#"</th>
                        <th scope="col">"Solver"</th>
                        <th scope="col">"Idle, mm"</th>
                        <th scope="col">"vs best"</th>
                        <th scope="col">"Time, s"</th>
                        <th scope="col">"Overlay"</th>
                    </tr>
                </thead>
                <tbody>
                    <For
                        each=move || kept.get()
                        key=|e| (e.id, e.overlay)
                        children=move |e: Kept| {
                            let id = e.id;
                            let excess = move || {
                                let b = best();
                                if b > 0.0 {
                                    format!("+{:.1} %", (e.idle_length / b - 1.0) * 100.0)
                                } else {
                                    "—".into()
                                }
                            };
                            view! {
                                <tr class="kept" data-id=id>
                                    <td>{id}</td>
                                    <td>{e.label}</td>
                                    <td class="kept-idle">{format!("{:.1}", e.idle_length)}</td>
                                    <td>{excess}</td>
                                    <td>{format!("{:.1}", e.time_s)}</td>
                                    <td>
                                        <input
                                            type="checkbox"
                                            class="kept-overlay"
                                            aria-label=format!("Overlay result {id} on the drawing")
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
                    />
                </tbody>
            </table>
        </section>
    }
}
