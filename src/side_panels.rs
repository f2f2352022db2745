//! The side panel: the job's status and figures, the machine, kerf and thermal settings, the
//! chart, the layers, the legend and the comparison of kept results.

use leptos::prelude::*;

use crate::chart::BoundsChart;
use crate::compare::ComparePanel;
use crate::i18n::{tr, use_language};
use crate::job_status::JobStatusList;
use crate::settings::Layer;
use crate::state::{Page, ViewSettings};
use crate::stats::{AlternativesTable, StatsPanel};
use crate::thermal::{ThermalPanel, ThermalStats};

/// The aside beside the drawing.
#[component]
pub fn SidePanels() -> impl IntoView {
    let page = expect_context::<Page>();
    let (job, shown, machine) = (page.job, page.shown, page.machine);
    let language = use_language();
    let alternatives = Signal::derive(move || {
        job.progress.with(|p| {
            p.as_ref()
                .map(|p| p.alternatives.clone())
                .unwrap_or_default()
        })
    });
    view! {
        <aside class="stats" aria-label=tr("Job status", "Состояние задачи")>
            <crate::announce::ProgressAnnouncer progress=job.progress ended=Signal::derive(move || !job.is_running()) />
            <JobStatusList />
            <StatsPanel nest=shown.nest route=shown.route paths=shown.paths machine=machine.machine />
            <crate::kerf::LeadStats route=shown.route />
            <crate::profiles::ProfilesPanel />
            <crate::kerf::KerfPanel />
            <ThermalPanel />
            <ThermalStats />
            <AlternativesTable alternatives=alternatives />
            <BoundsChart
                samples=job.chart_samples
                log_time=page.view.log_time
                unit=Signal::derive(move || job.bound_unit(language.get()))
            />
            <LayerPanel />
            <crate::legend::DrawingLegend />
            <ComparePanel />
        </aside>
    }
}

/// A checkbox per drawing layer.
#[component]
fn LayerPanel() -> impl IntoView {
    let hidden = expect_context::<ViewSettings>().hidden_layers;
    let language = use_language();
    view! {
        <fieldset class="layers">
            <legend>{tr("Layers", "Слои")}</legend>
            {Layer::ALL
                .into_iter()
                .map(|layer| {
                    view! {
                        <label>
                            <input
                                type="checkbox"
                                id=format!("layer-{}", layer.name())
                                prop:checked=move || hidden.with(|h| !h.contains(&layer))
                                on:change=move |ev| {
                                    let show = event_target_checked(&ev);
                                    hidden.update(|h| {
                                        h.retain(|l| *l != layer);
                                        if !show {
                                            h.push(layer);
                                        }
                                    });
                                }
                            />
                            " "
                            {move || layer.label(language.get())}
                        </label>
                    }
                })
                .collect_view()}
        </fieldset>
    }
}
