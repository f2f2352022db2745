//! Colour themes: CSS files in `style/` keyed by `data-theme` on the root element; the choice is
//! remembered in local storage.

use leptos::prelude::*;

use crate::i18n::tr;

/// The themes, as (value of `data-theme`, English label, Russian label).
pub const THEMES: [(&str, &str, &str); 4] = [
    ("light", "Light", "Светлая"),
    ("dark", "Dark", "Тёмная"),
    ("high-contrast", "High contrast", "Контрастная"),
    ("print", "Print", "Для печати"),
];

const STORAGE_KEY: &str = "cutroute.theme";

fn storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok()?
}

/// The remembered theme, or light.
pub fn remembered() -> String {
    storage()
        .and_then(|s| s.get_item(STORAGE_KEY).ok().flatten())
        .filter(|t| THEMES.iter().any(|(value, ..)| value == t))
        .unwrap_or_else(|| THEMES[0].0.to_string())
}

/// Show and remember a theme.
pub fn apply(theme: &str) {
    if let Some(root) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.document_element())
    {
        let _ = root.set_attribute("data-theme", theme);
    }
    if let Some(storage) = storage() {
        let _ = storage.set_item(STORAGE_KEY, theme);
    }
}

/// The theme picker.
#[component]
pub fn ThemePicker() -> impl IntoView {
    let theme = RwSignal::new(remembered());
    Effect::new(move |_| apply(&theme.get()));
    view! {
        <label>
            {tr("Theme ", "Тема ")}
            <select
                id="theme"
                aria-label=tr("Colour theme", "Цветовая тема")
                prop:value=move || theme.get()
                on:change=move |ev| theme.set(event_target_value(&ev))
            >
                {THEMES
                    .iter()
                    .map(|(value, en, ru)| view! { <option value=*value>{tr(en, ru)}</option> })
                    .collect_view()}
            </select>
        </label>
    }
}
