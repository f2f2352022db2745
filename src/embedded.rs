//! What the single-file build (`dist/cutroute.html`, `scripts/single-file.py`) carries inside the
//! page: a loader script for the solver worker (a Blob URL with the worker's wasm inlined) and the
//! bundled samples, so the page works when double-clicked (`file://`), where nothing beside it can
//! be fetched. A hosted build defines neither, and the app fetches as usual.

use wasm_bindgen::{JsCast, JsValue};

/// A global the single-file page sets before the app starts.
fn global(name: &str) -> Option<JsValue> {
    js_sys::Reflect::get(&js_sys::global(), &JsValue::from_str(name))
        .ok()
        .filter(|v| !v.is_undefined() && !v.is_null())
}

/// The Blob URL of the worker's loader script, when the page carries the worker inside.
pub fn worker_loader() -> Option<String> {
    global("cutrouteWorkerLoader")?.as_string()
}

/// The bytes the page carries for `url` (a relative URL as the app fetches it, e.g.
/// `./assets/samples/nested.dbs`).
pub fn file(url: &str) -> Option<Vec<u8>> {
    let files = global("cutrouteFiles")?;
    let bytes = js_sys::Reflect::get(&files, &JsValue::from_str(url)).ok()?;
    bytes
        .is_instance_of::<js_sys::Uint8Array>()
        .then(|| js_sys::Uint8Array::new(&bytes).to_vec())
}
