//! How the page shows things: the drawing's layers, the chart's time axis, presentation mode
//! and full screen.

use leptos::prelude::*;
use wasm_bindgen::JsCast;

use crate::settings::{Layer, Settings};

/// The view's settings.
#[derive(Clone, Copy)]
pub struct ViewSettings {
    /// Drawing layers switched off.
    pub hidden_layers: RwSignal<Vec<Layer>>,
    /// Whether the chart's time axis is logarithmic.
    pub log_time: RwSignal<bool>,
    /// Presentation mode: large fonts and the whole screen.
    pub presentation: RwSignal<bool>,
}

impl ViewSettings {
    /// The layers remembered or linked; presentation mode follows the full-screen state of the
    /// window from here on (see [`ViewSettings::follow_full_screen`]).
    pub fn new(settings: &Settings) -> Self {
        let view = Self {
            hidden_layers: RwSignal::new(settings.hidden_layers.clone()),
            log_time: RwSignal::new(false),
            presentation: RwSignal::new(false),
        };
        view.follow_full_screen();
        view
    }

    /// Takes the layers of `settings` (a lecture card's).
    pub fn restore(&self, settings: &Settings) {
        self.hidden_layers.set(settings.hidden_layers.clone());
    }

    /// Writes the layers into `settings` (tracked).
    pub fn remember(&self, settings: &mut Settings) {
        settings.hidden_layers = self.hidden_layers.get();
    }

    /// Presentation mode on or off.
    pub fn toggle_presentation(&self) {
        self.presentation.update(|p| *p = !*p);
    }

    /// Presentation mode marks the page (`data-presentation`) and asks for full screen; F
    /// toggles it outside text fields, and leaving full screen with Esc leaves it too.
    fn follow_full_screen(&self) {
        let presentation = self.presentation;
        // While a request for full screen is pending, a "left full screen" event is the late
        // echo of an earlier exit (F pressed twice quickly), not the user pressing Esc.
        let entering_fullscreen = StoredValue::new(false);
        Effect::new(move |_| {
            let on = presentation.get();
            let Some(doc) = web_sys::window().and_then(|w| w.document()) else {
                return;
            };
            if let Some(root) = doc.document_element() {
                let _ = if on {
                    root.set_attribute("data-presentation", "on")
                } else {
                    root.remove_attribute("data-presentation")
                };
                if on && doc.fullscreen_element().is_none() {
                    entering_fullscreen.set_value(true);
                    request_fullscreen(&root, move || entering_fullscreen.set_value(false));
                } else if !on && doc.fullscreen_element().is_some() {
                    doc.exit_fullscreen();
                }
            }
        });
        let this = *self;
        let keys = window_event_listener(leptos::ev::keydown, move |ev| {
            let typing = ev
                .target()
                .and_then(|t| t.dyn_into::<web_sys::Element>().ok())
                .is_some_and(|e| matches!(e.tag_name().as_str(), "INPUT" | "SELECT" | "TEXTAREA"));
            if typing || ev.ctrl_key() || ev.meta_key() || ev.alt_key() {
                return;
            }
            if ev.key() == "f" || ev.key() == "F" {
                ev.prevent_default();
                this.toggle_presentation();
            }
        });
        on_cleanup(move || keys.remove());
        let fullscreen = window_event_listener_untyped("fullscreenchange", move |_| {
            let full = web_sys::window()
                .and_then(|w| w.document())
                .is_some_and(|d| d.fullscreen_element().is_some());
            if !full && presentation.get_untracked() && !entering_fullscreen.get_value() {
                presentation.set(false);
            }
        });
        on_cleanup(move || fullscreen.remove());
    }
}

/// Asks for full screen and calls `settled` once the request is granted or refused; a
/// refusal (no user gesture, a browser without it) is ignored, so it never surfaces as an
/// unhandled rejection: large fonts still apply.
fn request_fullscreen(element: &web_sys::Element, settled: impl FnOnce() + 'static) {
    let Ok(method) = js_sys::Reflect::get(element, &"requestFullscreen".into()) else {
        return settled();
    };
    let Some(method) = method.dyn_ref::<js_sys::Function>() else {
        return settled();
    };
    match method
        .call0(element)
        .ok()
        .and_then(|answer| answer.dyn_into::<js_sys::Promise>().ok())
    {
        Some(promise) => leptos::task::spawn_local(async move {
            let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
            settled();
        }),
        None => settled(),
    }
}
