//! The page's language: English or Russian, chosen from the browser and remembered once switched.
//!
//! Every text the page shows is written at its place of use in both languages, `tr("Stop",
//! "Стоп")`, so a component reads as it renders and no key table drifts out of step with the
//! markup. The science's own Russian terms are used: врезка (pierce), холостой ход (idle move),
//! эквидистанта (equidistant), нижняя оценка (lower bound), разрыв (gap).
//!
//! The language lives in a [`Language`] shared by context; [`tr`] gives a reactive text that
//! follows it, [`Language::pick`] a text for the current language inside a closure that is
//! already reactive.

use leptos::prelude::*;

/// A UI language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lang {
    En,
    Ru,
}

const STORAGE_KEY: &str = "cutroute.lang";

impl Lang {
    /// The value of `<html lang>` and of the stored choice.
    pub fn code(self) -> &'static str {
        match self {
            Lang::En => "en",
            Lang::Ru => "ru",
        }
    }

    /// A language from its code (`ru`, `ru-RU`, `en-GB`, …); other languages are not offered.
    pub fn from_code(code: &str) -> Option<Lang> {
        let primary = code.split(['-', '_']).next()?.to_ascii_lowercase();
        match primary.as_str() {
            "ru" => Some(Lang::Ru),
            "en" => Some(Lang::En),
            _ => None,
        }
    }

    /// The remembered choice, else the first of the browser's preferred languages the page
    /// speaks, else English.
    pub fn initial() -> Lang {
        let remembered = storage()
            .and_then(|s| s.get_item(STORAGE_KEY).ok().flatten())
            .and_then(|code| Lang::from_code(&code));
        remembered
            .or_else(|| browser_languages().iter().find_map(|c| Lang::from_code(c)))
            .unwrap_or(Lang::En)
    }

    /// The text for this language.
    pub fn pick(self, en: &'static str, ru: &'static str) -> &'static str {
        match self {
            Lang::En => en,
            Lang::Ru => ru,
        }
    }
}

/// The page's language, shared by context (`provide_context` in the app shell).
#[derive(Clone, Copy, Debug)]
pub struct Language(RwSignal<Lang>);

impl Language {
    /// The language at start; keeps `<html lang>` and the page title in step with the choice.
    pub fn new() -> Self {
        let language = Language(RwSignal::new(Lang::initial()));
        Effect::new(move |_| {
            let lang = language.get();
            let Some(document) = web_sys::window().and_then(|w| w.document()) else {
                return;
            };
            if let Some(root) = document.document_element() {
                let _ = root.set_attribute("lang", lang.code());
            }
            document.set_title(lang.pick(
                "cutroute — tool paths for CNC sheet cutting",
                "cutroute — маршруты резки листа на станках с ЧПУ",
            ));
        });
        language
    }

    /// The current language (tracked).
    pub fn get(self) -> Lang {
        self.0.get()
    }

    /// The current language, not tracked (event handlers).
    pub fn get_untracked(self) -> Lang {
        self.0.get_untracked()
    }

    /// Switch and remember the choice.
    pub fn set(self, lang: Lang) {
        if let Some(storage) = storage() {
            let _ = storage.set_item(STORAGE_KEY, lang.code());
        }
        self.0.set(lang);
    }

    /// The text for the current language (tracked).
    pub fn pick(self, en: &'static str, ru: &'static str) -> &'static str {
        self.get().pick(en, ru)
    }
}

impl Default for Language {
    fn default() -> Self {
        Self::new()
    }
}

/// The page's language from context; English outside the app (unit tests of components).
pub fn use_language() -> Language {
    use_context::<Language>().unwrap_or_else(|| Language(RwSignal::new(Lang::En)))
}

/// A text in both languages that follows the page's language: use it as a child or an attribute
/// value, `<button title=tr("Stop the job", "Остановить задачу")>{tr("Stop", "Стоп")}</button>`.
pub fn tr(en: &'static str, ru: &'static str) -> impl Fn() -> &'static str + Copy + Send + Sync {
    let language = use_language();
    move || language.pick(en, ru)
}

/// The language switch (English · Русский), remembered across visits.
#[component]
pub fn LanguagePicker() -> impl IntoView {
    let language = use_language();
    view! {
        <label>
            {tr("Language ", "Язык ")}
            <select
                id="language"
                aria-label=tr("Interface language", "Язык интерфейса")
                prop:value=move || language.get().code()
                on:change=move |ev| {
                    if let Some(lang) = Lang::from_code(&event_target_value(&ev)) {
                        language.set(lang);
                    }
                }
            >
                <option value="en">"English"</option>
                <option value="ru">"Русский"</option>
            </select>
        </label>
    }
}

fn browser_languages() -> Vec<String> {
    let Some(navigator) = web_sys::window().map(|w| w.navigator()) else {
        return Vec::new();
    };
    let mut codes: Vec<String> = navigator
        .languages()
        .iter()
        .filter_map(|v| v.as_string())
        .collect();
    if let Some(code) = navigator.language() {
        codes.push(code);
    }
    codes
}

fn storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok()?
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_name_the_two_languages_and_nothing_else() {
        assert_eq!(Lang::from_code("ru-RU"), Some(Lang::Ru));
        assert_eq!(Lang::from_code("RU"), Some(Lang::Ru));
        assert_eq!(Lang::from_code("en_GB"), Some(Lang::En));
        assert_eq!(Lang::from_code("de"), None);
        assert_eq!(Lang::from_code(""), None);
        for lang in [Lang::En, Lang::Ru] {
            assert_eq!(Lang::from_code(lang.code()), Some(lang));
        }
        assert_eq!(Lang::Ru.pick("gap", "разрыв"), "разрыв");
    }
}
