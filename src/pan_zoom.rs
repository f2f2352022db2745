//! Pan and zoom of the SVG view, written for this app: wheel zoom around the cursor, drag to
//! pan (mouse, pen or one finger), pinch with two fingers, and the keyboard (+ − arrows, 0 = fit).
//!
//! The state is the SVG `viewBox` in the drawing's outer coordinates; `None` means "fit the
//! sheet". Screen → drawing conversion uses the element's screen transformation matrix, so the
//! point under the cursor stays put while zooming.

use std::collections::HashMap;

use leptos::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{KeyboardEvent, PointerEvent, SvgGraphicsElement, WheelEvent};

/// A view box `[x, y, width, height]`.
pub type ViewBox = [f64; 4];

/// Zoom factor of one key press.
const KEY_ZOOM: f64 = 1.25;
/// Fraction of the view one arrow key pans.
const KEY_PAN: f64 = 0.1;

/// Scale `view` by `factor` (> 1 zooms out) keeping the drawing point `(ux, uy)` fixed.
pub fn zoom_about(view: ViewBox, factor: f64, ux: f64, uy: f64) -> ViewBox {
    let [x, y, w, h] = view;
    let factor = factor.clamp(1e-3, 1e3);
    [
        ux - (ux - x) * factor,
        uy - (uy - y) * factor,
        w * factor,
        h * factor,
    ]
}

/// The drawing point under a screen point, through the element's screen matrix.
fn to_drawing(svg: &SvgGraphicsElement, client_x: f64, client_y: f64) -> Option<(f64, f64, f64)> {
    let m = svg.get_screen_ctm()?;
    let (a, e, d, f) = (
        f64::from(m.a()),
        f64::from(m.e()),
        f64::from(m.d()),
        f64::from(m.f()),
    );
    if a == 0.0 || d == 0.0 {
        return None;
    }
    Some(((client_x - e) / a, (client_y - f) / d, a))
}

/// Handlers that drive `view` (the current view box, `None` = fit) given the fitted box.
#[derive(Clone, Copy)]
pub struct PanZoom {
    /// The view box shown, `None` = fit the whole drawing.
    pub view: RwSignal<Option<ViewBox>>,
    /// The fitted view box, used when `view` is `None`.
    pub fit: Signal<Option<ViewBox>>,
    pointers: StoredValue<HashMap<i32, (f64, f64)>, LocalStorage>,
}

impl PanZoom {
    /// State for one view.
    pub fn new(fit: Signal<Option<ViewBox>>) -> Self {
        Self {
            view: RwSignal::new(None),
            fit,
            pointers: StoredValue::new_local(HashMap::new()),
        }
    }

    /// The view box to render.
    pub fn current(&self) -> Option<ViewBox> {
        self.view.get().or_else(|| self.fit.get())
    }

    fn current_untracked(&self) -> Option<ViewBox> {
        self.view
            .get_untracked()
            .or_else(|| self.fit.get_untracked())
    }

    /// Back to "fit the sheet".
    pub fn reset(&self) {
        self.view.set(None);
    }

    /// Wheel: zoom around the cursor.
    pub fn on_wheel(&self, ev: WheelEvent) {
        ev.prevent_default();
        let Some(view) = self.current_untracked() else {
            return;
        };
        let Some(svg) = target_svg(&ev) else { return };
        let Some((ux, uy, _)) =
            to_drawing(&svg, f64::from(ev.client_x()), f64::from(ev.client_y()))
        else {
            return;
        };
        // deltaMode 1 = lines: scale them to pixels so mice and touchpads feel alike.
        let delta = ev.delta_y() * if ev.delta_mode() == 1 { 16.0 } else { 1.0 };
        self.view
            .set(Some(zoom_about(view, (delta * 0.0015).exp(), ux, uy)));
    }

    /// Pointer down: start a drag (or a pinch with the second finger).
    pub fn on_pointer_down(&self, ev: PointerEvent) {
        if let Some(target) = ev
            .current_target()
            .and_then(|t| t.dyn_into::<web_sys::Element>().ok())
        {
            let _ = target.set_pointer_capture(ev.pointer_id());
        }
        self.pointers.update_value(|p| {
            p.insert(
                ev.pointer_id(),
                (f64::from(ev.client_x()), f64::from(ev.client_y())),
            );
        });
    }

    /// Pointer move: pan by the drag, or pinch-zoom with two pointers.
    pub fn on_pointer_move(&self, ev: PointerEvent) {
        let id = ev.pointer_id();
        let now = (f64::from(ev.client_x()), f64::from(ev.client_y()));
        let Some(before) = self.pointers.with_value(|p| p.get(&id).copied()) else {
            return;
        };
        let Some(view) = self.current_untracked() else {
            return;
        };
        let Some(svg) = target_svg(&ev) else { return };
        let Some((_, _, scale)) = to_drawing(&svg, now.0, now.1) else {
            return;
        };
        let others: Vec<(f64, f64)> = self.pointers.with_value(|p| {
            p.iter()
                .filter(|(k, _)| **k != id)
                .map(|(_, v)| *v)
                .collect()
        });
        let next = if let [other] = others[..] {
            // Pinch: the distance ratio between the two pointers is the zoom factor, about
            // their midpoint.
            let d_before = (before.0 - other.0).hypot(before.1 - other.1);
            let d_now = (now.0 - other.0).hypot(now.1 - other.1);
            if d_before < 1.0 || d_now < 1.0 {
                view
            } else {
                let mid = ((now.0 + other.0) / 2.0, (now.1 + other.1) / 2.0);
                match to_drawing(&svg, mid.0, mid.1) {
                    Some((ux, uy, _)) => zoom_about(view, d_before / d_now, ux, uy),
                    None => view,
                }
            }
        } else {
            let [x, y, w, h] = view;
            [
                x - (now.0 - before.0) / scale,
                y - (now.1 - before.1) / scale,
                w,
                h,
            ]
        };
        self.pointers.update_value(|p| {
            p.insert(id, now);
        });
        self.view.set(Some(next));
    }

    /// Pointer up or cancelled: that pointer no longer drags.
    pub fn on_pointer_up(&self, ev: PointerEvent) {
        self.pointers.update_value(|p| {
            p.remove(&ev.pointer_id());
        });
    }

    /// Keyboard: `+`/`=` zoom in, `-` zoom out, arrows pan, `0` fits the sheet.
    pub fn on_key(&self, ev: KeyboardEvent) {
        let Some(view) = self.current_untracked() else {
            return;
        };
        let [x, y, w, h] = view;
        let (cx, cy) = (x + w / 2.0, y + h / 2.0);
        let next = match ev.key().as_str() {
            "+" | "=" => Some(zoom_about(view, 1.0 / KEY_ZOOM, cx, cy)),
            "-" | "_" => Some(zoom_about(view, KEY_ZOOM, cx, cy)),
            "ArrowLeft" => Some([x - w * KEY_PAN, y, w, h]),
            "ArrowRight" => Some([x + w * KEY_PAN, y, w, h]),
            "ArrowUp" => Some([x, y - h * KEY_PAN, w, h]),
            "ArrowDown" => Some([x, y + h * KEY_PAN, w, h]),
            "0" => {
                ev.prevent_default();
                self.reset();
                return;
            }
            _ => None,
        };
        if let Some(next) = next {
            ev.prevent_default();
            self.view.set(Some(next));
        }
    }
}

fn target_svg<E: AsRef<web_sys::Event>>(ev: &E) -> Option<SvgGraphicsElement> {
    ev.as_ref()
        .current_target()?
        .dyn_into::<SvgGraphicsElement>()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::zoom_about;

    #[test]
    fn zoom_keeps_the_anchor_point_fixed() {
        let view = [0.0, 0.0, 100.0, 50.0];
        let zoomed = zoom_about(view, 0.5, 20.0, 10.0);
        assert_eq!(zoomed, [10.0, 5.0, 50.0, 25.0]);
        // The anchor sits at the same relative place in both boxes.
        let rel = |v: [f64; 4]| ((20.0 - v[0]) / v[2], (10.0 - v[1]) / v[3]);
        assert_eq!(rel(view), rel(zoomed));
    }
}
