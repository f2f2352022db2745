//! Colour themes: CSS files in `style/` keyed by `data-theme` on the root element; the choice is
//! remembered in local storage.

use leptos::prelude::*;

/// The themes, as (value of `data-theme`, label).
pub const THEMES: [(&str, &str); 4] = [
    ("light", "Light"),
    ("dark", "Dark"),
    ("high-contrast", "High contrast"),
    ("print", "Print"),
];

const STORAGE_KEY: &str = "cutroute.theme";

fn storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok()?
}

/// The remembered theme, or light.
pub fn remembered() -> String {
    storage()
        .and_then(|s| s.get_item(STORAGE_KEY).ok().flatten())
        .filter(|t| THEMES.iter().any(|(value, _)| value == t))
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
            "Theme "
            <select
                id="theme"
                aria-label="Colour theme"
                prop:value=move || theme.get()
                on:change=move |ev| theme.set(event_target_value(&ev))
            >
                {THEMES
                    .iter()
                    .map(|(value, label)| view! { <option value=*value>{*label}</option> })
                    .collect_view()}
            </select>
        </label>
    }
}
