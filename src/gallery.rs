//! The lecture gallery: a JSON list of nests, each with a title, its file and the solver and
//! settings to show it with, picked from cards. The bundled samples are the first such list
//! (`assets/lectures.json`); `?lecture=URL` loads another one, hosted anywhere CORS allows.
//!
//! ```json
//! { "title": "Cutting paths",
//!   "lectures": [ { "title": "Parts inside holes", "file": "samples/nested.dbs",
//!                   "solver": "ccp", "settings": { "time": 2, "hide": "hatch" } } ] }
//! ```
//!
//! Titles and descriptions are a string, or one per language: `{"en": "Holes", "ru": "Отверстия"}`.
//! `file` is relative to the list's own address; `settings` are the keys of a link's query
//! (`Settings::with_query`: `time`, `seed`, `step`, `objective`, machine and thermal keys,
//! `hide`), so a card sets exactly what a link can.

use leptos::prelude::*;
use serde::Deserialize;

use crate::i18n::{tr, use_language, Lang};

/// The bundled list, under the app.
pub const BUNDLED: &str = "./assets/lectures.json";

/// A text of a list: one string for every language, or `{"en": "…", "ru": "…"}` (a missing
/// language falls back to the other).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum ListText {
    /// The same in every language.
    Plain(String),
    /// Per language.
    PerLanguage {
        /// English.
        #[serde(default)]
        en: Option<String>,
        /// Russian.
        #[serde(default)]
        ru: Option<String>,
    },
}

impl ListText {
    /// The text in `lang`.
    pub fn pick(&self, lang: Lang) -> String {
        match self {
            ListText::Plain(text) => text.clone(),
            ListText::PerLanguage { en, ru } => {
                let (wanted, other) = match lang {
                    Lang::En => (en, ru),
                    Lang::Ru => (ru, en),
                };
                wanted.clone().or_else(|| other.clone()).unwrap_or_default()
            }
        }
    }
}

impl std::fmt::Display for ListText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.pick(Lang::En))
    }
}

/// A list of lectures.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LectureList {
    /// The list's title.
    pub title: ListText,
    /// Its entries, in the order shown.
    pub lectures: Vec<Lecture>,
}

/// One nest to show.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lecture {
    /// What the card says.
    pub title: ListText,
    /// A line under the title.
    #[serde(default)]
    pub description: Option<ListText>,
    /// The nest's file, relative to the list's address (or absolute).
    pub file: String,
    /// The solver's short name (`SolverKind::name`).
    #[serde(default)]
    pub solver: Option<String>,
    /// Query keys of a link and their values.
    #[serde(default)]
    pub settings: serde_json::Map<String, serde_json::Value>,
}

impl LectureList {
    /// Reads a list; errors say what is wrong and where.
    pub fn parse(text: &str) -> Result<Self, String> {
        serde_json::from_str(text).map_err(|e| e.to_string())
    }
}

impl Lecture {
    /// The settings as a link's query (`solver=…&time=…`), read by `Settings::with_query`.
    pub fn query(&self) -> String {
        let mut pairs: Vec<String> = Vec::new();
        if let Some(solver) = &self.solver {
            pairs.push(format!("solver={solver}"));
        }
        for (key, value) in &self.settings {
            let value = match value {
                serde_json::Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            pairs.push(format!("{key}={value}"));
        }
        pairs.join("&")
    }

    /// The file's address: `file` as given when absolute, else beside the list.
    pub fn file_url(&self, list_url: &str) -> String {
        resolve(list_url, &self.file)
    }
}

/// `file` relative to `base`'s folder; absolute addresses (a scheme, or a leading `/`) as given.
/// Relative bases stay relative (`./assets/samples/…`), which is how the single-file page finds
/// the samples it carries.
pub fn resolve(base: &str, file: &str) -> String {
    if file.contains("://") || file.starts_with('/') || file.starts_with("data:") {
        return file.to_string();
    }
    let folder = match base.rfind('/') {
        Some(i) => &base[..=i],
        None => "",
    };
    format!("{folder}{file}")
}

/// The list a page opens: `?lecture=URL`, else the bundled one.
pub fn list_url(query: &str) -> String {
    query
        .trim_start_matches('?')
        .split('&')
        .filter_map(|pair| pair.split_once('='))
        .find(|(key, value)| *key == "lecture" && !value.is_empty())
        .map(|(_, value)| {
            js_sys::decode_uri_component(value)
                .ok()
                .and_then(|s| s.as_string())
                .unwrap_or_else(|| value.to_string())
        })
        .unwrap_or_else(|| BUNDLED.to_string())
}

/// What a link adds for the list at `url`: nothing for the bundled one.
pub fn lecture_query(url: &str) -> String {
    if url == BUNDLED {
        String::new()
    } else {
        format!(
            "&lecture={}",
            String::from(js_sys::encode_uri_component(url))
        )
    }
}

/// The bundled sample a resolved address names (`./assets/samples/NAME`), opened as a sample
/// (so the single-file page, which carries the samples, opens it too).
pub fn bundled_sample(url: &str) -> Option<String> {
    let name = url.strip_prefix("./assets/samples/")?;
    crate::app::SAMPLES
        .iter()
        .any(|(f, ..)| *f == name)
        .then(|| name.to_string())
}

/// The gallery of the list at `list_url`, fetched once.
#[component]
pub fn LectureGallery(list_url: String, pick: Callback<(String, String)>) -> impl IntoView {
    let list = RwSignal::new(None::<Result<LectureList, String>>);
    let url = list_url.clone();
    leptos::task::spawn_local(async move {
        let loaded = crate::app::fetch_bytes(&url)
            .await
            .and_then(|bytes| String::from_utf8(bytes).map_err(|e| e.to_string()))
            .and_then(|text| LectureList::parse(&text));
        list.set(Some(loaded));
    });
    view! {
        <Gallery list_url=Signal::stored(list_url) list=Signal::from(list) pick=pick />
    }
}

/// The gallery: cards of the list, each opening its nest with its settings through `pick`
/// (the file's address and the query of its settings).
#[component]
pub fn Gallery(
    list_url: Signal<String>,
    list: Signal<Option<Result<LectureList, String>>>,
    pick: Callback<(String, String)>,
) -> impl IntoView {
    let language = use_language();
    view! {
        <details id="gallery" class="gallery">
            <summary>{tr("Lectures", "Лекции")}</summary>
            <div class="gallery-panel">
            {move || match list.get() {
                None => view! { <p class="muted">{tr("loading…", "загрузка…")}</p> }.into_any(),
                Some(Err(e)) => {
                    view! {
                        <p class="error" role="alert">{format!("{}: {e}", list_url.get())}</p>
                    }
                        .into_any()
                }
                Some(Ok(list)) => {
                    let base = list_url.get();
                    view! {
                        <h2 id="gallery-title">{
                            let title = list.title.clone();
                            move || title.pick(language.get())
                        }</h2>
                        <ul class="gallery-cards">
                            {list
                                .lectures
                                .into_iter()
                                .enumerate()
                                .map(|(k, lecture)| {
                                    let url = lecture.file_url(&base);
                                    let query = lecture.query();
                                    let solver = lecture.solver.clone().unwrap_or_default();
                                    view! {
                                        <li>
                                            <button
                                                type="button"
                                                class="lecture"
                                                id=format!("lecture-{k}")
                                                data-file=url.clone()
                                                on:click=move |_| pick.run((url.clone(), query.clone()))
                                            >
                                                <strong>{
                                                    let title = lecture.title.clone();
                                                    move || title.pick(language.get())
                                                }</strong>
                                                <span class="muted">
                                                    {
                                                        let description = lecture.description.clone();
                                                        move || description.as_ref().map(|d| d.pick(language.get())).unwrap_or_default()
                                                    }
                                                    " · "
                                                    {solver}
                                                </span>
                                            </button>
                                        </li>
                                    }
                                })
                                .collect_view()}
                        </ul>
                    }
                        .into_any()
                }
            }}
            </div>
        </details>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bundled_list_reads_and_names_the_bundled_samples() {
        let text = include_str!("../assets/lectures.json");
        let list = LectureList::parse(text).unwrap();
        assert!(!list.lectures.is_empty());
        for lecture in &list.lectures {
            let url = lecture.file_url(BUNDLED);
            let name = url.strip_prefix("./assets/samples/").unwrap();
            assert!(
                crate::app::SAMPLES.iter().any(|(f, ..)| *f == name),
                "{url} is not a bundled sample"
            );
            let settings = crate::settings::Settings::default().with_query(&lecture.query());
            assert_eq!(
                Some(settings.solver.as_str()),
                lecture.solver.as_deref(),
                "{}: the solver is a known one",
                lecture.title
            );
        }
        // The first cards are the samples, in the picker's order.
        let first: Vec<String> = list.lectures[..crate::app::SAMPLES.len()]
            .iter()
            .map(|l| l.file_url(BUNDLED))
            .collect();
        let samples: Vec<String> = crate::app::SAMPLES
            .iter()
            .map(|(f, ..)| format!("./assets/samples/{f}"))
            .collect();
        assert_eq!(first, samples);
    }

    #[test]
    fn files_resolve_beside_the_list_and_settings_become_a_query() {
        assert_eq!(
            resolve("https://x.org/l/list.json", "a/b.dbs"),
            "https://x.org/l/a/b.dbs"
        );
        assert_eq!(resolve("list.json", "b.dbs"), "b.dbs");
        assert_eq!(
            resolve("https://x.org/l/list.json", "https://y.org/c.dxf"),
            "https://y.org/c.dxf"
        );
        let lecture: Lecture = serde_json::from_str(
            r#"{"title": "t", "file": "f.dbs", "solver": "ccp", "settings": {"time": 2.5, "hide": "hatch"}}"#,
        )
        .unwrap();
        let s = crate::settings::Settings::default().with_query(&lecture.query());
        assert_eq!(s.time_limit_s, 2.5);
        assert_eq!(s.solver, "ccp");
        assert_eq!(s.hidden_layers, vec![crate::settings::Layer::Hatch]);
        assert!(LectureList::parse(r#"{"title": "t", "lectures": [{"titel": "x"}]}"#).is_err());
    }
}
