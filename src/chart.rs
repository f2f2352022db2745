//! The bounds chart: upper and lower bound over time, as SVG, with a log-time option.

use leptos::prelude::*;

use crate::i18n::{tr, use_language, Lang};

/// One sample of a job's bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundSample {
    /// Seconds since the job started.
    pub elapsed_s: f64,
    /// Best solution's cost.
    pub upper_bound: Option<f64>,
    /// Proven lower bound.
    pub lower_bound: Option<f64>,
}

const WIDTH: f64 = 260.0;
const HEIGHT: f64 = 140.0;
const PAD: f64 = 6.0;

/// Path data of one bound as a step line (bounds hold until the next report).
fn step_path(
    samples: &[BoundSample],
    pick: impl Fn(&BoundSample) -> Option<f64>,
    x: impl Fn(f64) -> f64,
    y: impl Fn(f64) -> f64,
) -> String {
    use std::fmt::Write;
    let mut d = String::new();
    let mut last_y: Option<f64> = None;
    for s in samples {
        let Some(v) = pick(s).filter(|v| v.is_finite()) else {
            continue;
        };
        let (px, py) = (x(s.elapsed_s), y(v));
        match last_y {
            None => {
                let _ = write!(d, "M{px:.1} {py:.1}");
            }
            Some(prev) => {
                let _ = write!(d, "L{px:.1} {prev:.1}L{px:.1} {py:.1}");
            }
        }
        last_y = Some(py);
    }
    d
}

/// The chart of `samples`; `log_time` spaces the time axis logarithmically; `unit` names what the
/// bounds measure (the y axis): idle length in mm for most solvers, the objective's seconds or
/// cost for the solvers that minimise time or cost.
#[component]
pub fn BoundsChart(
    samples: RwSignal<Vec<BoundSample>>,
    log_time: RwSignal<bool>,
    unit: Signal<&'static str>,
) -> impl IntoView {
    let language = use_language();
    let paths = move || {
        samples.with(|samples| {
            let values: Vec<f64> = samples
                .iter()
                .flat_map(|s| [s.upper_bound, s.lower_bound])
                .flatten()
                .filter(|v| v.is_finite())
                .collect();
            if values.is_empty() {
                return (String::new(), String::new(), String::new());
            }
            let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let span = (hi - lo).max(hi.abs() * 1e-9).max(1e-9);
            let t_max = samples.iter().map(|s| s.elapsed_s).fold(1e-3, f64::max);
            let log = log_time.get();
            // Log axis from 1 ms; linear from 0.
            let tx = move |t: f64| {
                let f = if log {
                    ((t.max(1e-3) / 1e-3).ln() / (t_max.max(2e-3) / 1e-3).ln()).clamp(0.0, 1.0)
                } else {
                    t / t_max
                };
                PAD + f * (WIDTH - 2.0 * PAD)
            };
            let vy = move |v: f64| HEIGHT - PAD - (v - lo) / span * (HEIGHT - 2.0 * PAD);
            let label = match language.get() {
                Lang::En => format!("{lo:.1} – {hi:.1} {} over {t_max:.2} s", unit.get()),
                Lang::Ru => format!("{lo:.1} – {hi:.1} {} за {t_max:.2} с", unit.get()),
            };
            (
                step_path(samples, |s| s.upper_bound, tx, vy),
                step_path(samples, |s| s.lower_bound, tx, vy),
                label,
            )
        })
    };
    view! {
        <figure class="chart">
            <svg id="bounds-chart" viewBox=format!("0 0 {WIDTH} {HEIGHT}") role="img" aria-label=tr("Upper and lower bound over time", "Верхняя и нижняя оценки во времени")>
                <rect class="chart-frame" x="0" y="0" width=WIDTH height=HEIGHT />
                <path class="chart-ub" d=move || paths().0 />
                <path class="chart-lb" d=move || paths().1 />
                <text id="chart-y-label" class="chart-axis" x=PAD y=PAD + 10.0>{move || unit.get()}</text>
            </svg>
            <figcaption>
                <span class="legend-ub">{tr("upper bound", "верхняя оценка")}</span>
                " · "
                <span class="legend-lb">{tr("lower bound", "нижняя оценка")}</span>
                " · "
                <span id="chart-range">{move || paths().2}</span>
                <label>
                    <input type="checkbox" id="log-time" prop:checked=move || log_time.get() on:change=move |ev| log_time.set(event_target_checked(&ev)) />
                    {tr(" log time", " логарифмическая шкала времени")}
                </label>
            </figcaption>
        </figure>
    }
}
