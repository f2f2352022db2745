//! Links: the address bar follows the page's state (`history.replaceState`, so a reload or a
//! bookmark reopens it), a Copy-link button puts that link on the clipboard, and `?file=URL`
//! names a nest hosted next to the app or anywhere CORS allows.
//!
//! The query itself is `Settings::query` (`settings.rs`), which `Settings::with_query` reads
//! back. History and the clipboard are reached through `js_sys::Reflect`: the web-sys features
//! for them would rebuild web-sys and everything above it for two calls.

use leptos::prelude::*;
use wasm_bindgen::{JsCast, JsValue};

use crate::i18n::tr;

/// The page's address with `query` in place of the current one.
pub fn page_link(query: &str) -> String {
    web_sys::window()
        .and_then(|w| {
            let l = w.location();
            Some(format!("{}{}{query}", l.origin().ok()?, l.pathname().ok()?))
        })
        .unwrap_or_else(|| query.to_string())
}

/// Puts `query` in the address bar without a reload or a history entry. Pages opened from
/// `file://` keep their address (browsers refuse to rewrite it there).
pub fn replace_address(query: &str) {
    let Some(window) = web_sys::window() else {
        return;
    };
    if window.location().protocol().ok().as_deref() == Some("file:") {
        return;
    }
    let current = window.location().search().unwrap_or_default();
    if current == query {
        return;
    }
    let Ok(history) = js_sys::Reflect::get(&window, &"history".into()) else {
        return;
    };
    let Ok(replace) = js_sys::Reflect::get(&history, &"replaceState".into()) else {
        return;
    };
    if let Some(replace) = replace.dyn_ref::<js_sys::Function>() {
        let _ = replace.call3(
            &history,
            &JsValue::NULL,
            &"".into(),
            &page_link(query).into(),
        );
    }
}

/// The file name a URL names: its last path segment, decoded (`nests/a%20b.dbs` → `a b.dbs`).
pub fn file_name_of(url: &str) -> String {
    let path = url.split(['?', '#']).next().unwrap_or(url);
    let last = path.rsplit('/').next().unwrap_or(path);
    let name = js_sys::decode_uri_component(last)
        .ok()
        .and_then(|s| s.as_string())
        .unwrap_or_else(|| last.to_string());
    if name.is_empty() {
        "nest".into()
    } else {
        name
    }
}

/// The link field's element id (also the fallback's text to select).
const LINK_FIELD: &str = "share-link";

/// A button that copies `link` to the clipboard; where the clipboard is refused (an insecure
/// origin, a denied permission), the link's text field is selected for Ctrl+C instead.
#[component]
pub fn CopyLinkButton(link: Signal<String>) -> impl IntoView {
    let status = RwSignal::new(None::<bool>);
    let language = crate::i18n::use_language();
    let copy = move |_| {
        let text = link.get_untracked();
        leptos::task::spawn_local(async move {
            let copied = write_clipboard(&text).await;
            if !copied {
                select_link_field();
            }
            status.set(Some(copied));
        });
    };
    view! {
        <button
            id="copy-link"
            type="button"
            title=tr(
                "Copy a link that reopens this nest with these settings",
                "Скопировать ссылку, которая откроет этот раскрой с этими настройками",
            )
            on:click=copy
        >
            {tr("Copy link", "Копировать ссылку")}
        </button>
        <span id="copy-link-status" class="muted" role="status" aria-live="polite">
            {move || match status.get() {
                Some(true) => language.pick("copied", "скопировано"),
                Some(false) => language.pick("press Ctrl+C to copy", "нажмите Ctrl+C, чтобы скопировать"),
                None => "",
            }}
        </span>
    }
}

/// `navigator.clipboard.writeText(text)`; false when there is no clipboard or it refused.
async fn write_clipboard(text: &str) -> bool {
    let Some(window) = web_sys::window() else {
        return false;
    };
    let navigator = window.navigator();
    let Ok(clipboard) = js_sys::Reflect::get(&navigator, &"clipboard".into()) else {
        return false;
    };
    if clipboard.is_undefined() || clipboard.is_null() {
        return false;
    }
    let Ok(write) = js_sys::Reflect::get(&clipboard, &"writeText".into()) else {
        return false;
    };
    let Some(write) = write.dyn_ref::<js_sys::Function>() else {
        return false;
    };
    let Ok(promise) = write.call1(&clipboard, &text.into()) else {
        return false;
    };
    let Ok(promise) = promise.dyn_into::<js_sys::Promise>() else {
        return false;
    };
    wasm_bindgen_futures::JsFuture::from(promise).await.is_ok()
}

fn select_link_field() {
    if let Some(input) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id(LINK_FIELD))
        .and_then(|e| e.dyn_into::<web_sys::HtmlInputElement>().ok())
    {
        let _ = input.focus();
        input.select();
    }
}
