//! Progress for screen readers: a polite live region that speaks the phase, the bounds and the
//! gap, not every report (a job reports many times a second), but when the phase changes, when
//! a bound improves by more than 1 %, when the job proves optimality, and when it ends; at most
//! one announcement of improvements every few seconds.

use cutroute_protocol::{Phase, Progress};
use leptos::prelude::*;

use crate::i18n::use_language;

/// Least time between two announcements of mere bound improvements, ms.
const QUIET_MS: f64 = 3000.0;

/// What was last announced.
#[derive(Clone, Debug, Default, PartialEq)]
struct Said {
    phase: Option<Phase>,
    upper: Option<f64>,
    lower: Option<f64>,
    optimal: bool,
    ended: bool,
    at_ms: f64,
}

/// Whether `p` is worth announcing after `said` at time `now_ms`.
fn worth_saying(said: &Said, p: &Progress, ended: bool, now_ms: f64) -> bool {
    if said.phase.as_ref() != Some(&p.phase)
        || p.proven_optimal != said.optimal
        || ended != said.ended
    {
        return true;
    }
    let moved = |new: Option<f64>, old: Option<f64>| match (new, old) {
        (Some(n), Some(o)) => (n - o).abs() > 0.01 * o.abs().max(1e-9),
        (Some(_), None) => true,
        _ => false,
    };
    (moved(p.bounds.upper, said.upper) || moved(p.bounds.lower, said.lower))
        && now_ms - said.at_ms >= QUIET_MS
}

/// The live region (visually hidden) that announces `progress`; `ended` is true once the job
/// has stopped (its last state is always said).
#[component]
pub fn ProgressAnnouncer(
    progress: RwSignal<Option<Progress>>,
    ended: Signal<bool>,
) -> impl IntoView {
    let language = use_language();
    let said = StoredValue::new(Said::default());
    let text = RwSignal::new(String::new());
    Effect::new(move |_| {
        let Some(p) = progress.get() else {
            said.set_value(Said::default());
            return;
        };
        let ended = ended.get();
        let now = js_sys::Date::now();
        if !said.with_value(|s| worth_saying(s, &p, ended, now)) {
            return;
        }
        said.set_value(Said {
            phase: Some(p.phase.clone()),
            upper: p.bounds.upper,
            lower: p.bounds.lower,
            optimal: p.proven_optimal,
            ended,
            at_ms: now,
        });
        let number = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.1}"));
        let mut line = format!(
            "{}: {}. {} {}, {} {}",
            language.pick("Phase", "Этап"),
            crate::words::phase_text(language.get_untracked(), &p.phase),
            language.pick("upper bound", "верхняя оценка"),
            number(p.bounds.upper),
            language.pick("lower bound", "нижняя оценка"),
            number(p.bounds.lower),
        );
        if let Some(gap) = p.gap() {
            line.push_str(&format!(
                ", {} {:.1} %",
                language.pick("gap", "разрыв"),
                gap * 100.0
            ));
        }
        if p.proven_optimal {
            line.push_str(language.pick(". Proven optimal.", ". Оптимальность доказана."));
        }
        text.set(line);
    });
    view! {
        <p id="progress-announcer" class="visually-hidden" role="status" aria-live="polite">
            {move || text.get()}
        </p>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn progress(phase: Phase, upper: Option<f64>) -> Progress {
        Progress {
            phase,
            bounds: cutroute_protocol::Bounds {
                upper,
                ..Default::default()
            },
            ..Progress::default()
        }
    }

    #[test]
    fn only_phase_changes_and_real_improvements_are_spoken() {
        let said = Said {
            phase: Some(Phase::ChainJoining),
            upper: Some(1000.0),
            at_ms: 0.0,
            ..Said::default()
        };
        assert!(worth_saying(
            &said,
            &progress(Phase::Bound, Some(1000.0)),
            false,
            10.0
        ));
        assert!(!worth_saying(
            &said,
            &progress(Phase::ChainJoining, Some(995.0)),
            false,
            10_000.0
        ));
        assert!(!worth_saying(
            &said,
            &progress(Phase::ChainJoining, Some(900.0)),
            false,
            100.0
        ));
        assert!(worth_saying(
            &said,
            &progress(Phase::ChainJoining, Some(900.0)),
            false,
            5_000.0
        ));
        assert!(
            worth_saying(
                &said,
                &progress(Phase::ChainJoining, Some(995.0)),
                true,
                100.0
            ),
            "the end is said"
        );
    }
}
