//! The settings panels' number field: one labelled input bound to one field of a settings
//! struct held in a signal (the machine, the material's heat model, the kerf and leads).

use leptos::prelude::*;

use crate::i18n::{tr, use_language};

/// A text as (English, Russian).
pub type Words = (&'static str, &'static str);

/// Which numbers a field takes; anything else typed is ignored (the field shows the setting).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accept {
    /// Finite, ≥ 0.
    NonNegative,
    /// Finite, > 0.
    Positive,
}

impl Accept {
    /// Whether `value` is taken.
    pub fn takes(self, value: f64) -> bool {
        value.is_finite()
            && match self {
                Accept::NonNegative => value >= 0.0,
                Accept::Positive => value > 0.0,
            }
    }
}

/// A number input labelled `label` with its `unit`, showing `get` of `settings` and writing a
/// typed value that `accept` takes through `set`; `tip` is its tooltip.
#[allow(clippy::too_many_arguments)]
pub fn setting_field<T: Send + Sync + 'static>(
    settings: RwSignal<T>,
    id: &'static str,
    label: Words,
    unit: Words,
    tip: Option<Words>,
    accept: Accept,
    get: fn(&T) -> f64,
    set: fn(&mut T, f64),
) -> impl IntoView {
    let language = use_language();
    view! {
        <label class="param" title=move || tip.map(|(en, ru)| language.pick(en, ru))>
            <span>{tr(label.0, label.1)}</span>
            <input
                id=id
                type="number"
                min="0"
                step="any"
                prop:value=move || settings.with(get).to_string()
                on:change=move |ev| {
                    if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                        if accept.takes(v) {
                            settings.update(|s| set(s, v));
                        }
                    }
                }
            />
            <span class="unit">{tr(unit.0, unit.1)}</span>
        </label>
    }
}

#[cfg(test)]
mod tests {
    use super::Accept;

    #[test]
    fn fields_take_finite_numbers_in_their_range() {
        assert!(Accept::NonNegative.takes(0.0));
        assert!(!Accept::Positive.takes(0.0));
        assert!(Accept::Positive.takes(2.5));
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(!Accept::NonNegative.takes(bad) && !Accept::Positive.takes(bad));
        }
    }
}
