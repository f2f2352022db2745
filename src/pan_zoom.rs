//! Pan and zoom of the SVG view, written for this app: wheel zoom around the cursor, drag to
//! pan (mouse, pen or one finger), pinch with two fingers, and the keyboard (+ − arrows, 0 = fit).
//!
//! The state is the SVG `viewBox` in the drawing's outer coordinates; `None` means "fit the
//! sheet". Screen → drawing conversion uses the element's screen transformation matrix, so the
//! point under the cursor stays put while zooming.
//!
//! Gestures are cheap: changing the `viewBox` makes the browser lay out, paint and raster every
//! path again (tens of milliseconds per frame at 5,000 contours), so while a wheel, drag or
//! pinch gesture is under way only the *live* view changes, shown by a CSS transform of the
//! `<svg>` element — its own composited layer (`will-change: transform` in the style sheet), so
//! the compositor moves and scales the picture already rastered. (A transform on a `<g>` inside
//! would not do: Chromium lays out and paints SVG content again for that.) The `viewBox` — the
//! *committed* view, which also sizes strokes, marks and labels — follows when the gesture
//! ends: on the last pointer up, or [`WHEEL_SETTLE_MS`] after the last wheel event. Keys commit
//! at once. Elements stacked on the view with the same box (the animation's overlay, marked
//! `data-follows-gesture`) get the same transform.

use std::collections::HashMap;
use std::time::Duration;

use cutroute_geometry::{BoundingBox, Point, Transform, Viewport};
use leptos::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{KeyboardEvent, PointerEvent, SvgGraphicsElement, WheelEvent};

/// The view box that shows `bounds` (model coordinates, y up) with a margin of 3 % of its longer
/// side (at least 1 mm). The SVG `viewBox` is in the drawing's flipped frame (y down: the
/// drawing's group flips y), so the box spans [−max.y, −min.y].
pub fn fitted_view(bounds: BoundingBox) -> Viewport {
    let margin = (bounds.width().max(bounds.height()) * 0.03).max(1.0);
    let flipped = BoundingBox::from_corners(
        Point::new(bounds.min.x, -bounds.max.y),
        Point::new(bounds.max.x, -bounds.min.y),
    );
    Viewport::fitting(&flipped, margin)
}

/// The `viewBox` attribute of a view.
pub fn view_box_attribute(view: Viewport) -> String {
    format!("{} {} {} {}", view.x, view.y, view.width, view.height)
}

/// Zoom factor of one key press.
const KEY_ZOOM: f64 = 1.25;
/// Fraction of the view one arrow key pans.
const KEY_PAN: f64 = 0.1;
/// A wheel gesture ends when no wheel event came for this long; the view box is then committed.
pub const WHEEL_SETTLE_MS: u64 = 150;

/// The CSS transform of the `<svg>` element (origin at its centre) that makes the picture drawn
/// for the `committed` view box look as the `live` one would: `(tx, ty, k)` for
/// `translate(tx px, ty px) scale(k)`. `a` is the committed view's screen pixels per drawing
/// unit. Both boxes have the same aspect ratio (zooms scale both sides alike, pans keep them)
/// and `preserveAspectRatio="xMidYMid meet"` puts each box's centre at the element's centre `O`,
/// so a drawing point `p` shown at `O + a (p − c₀)` must move to `O + a k (p − c)` (`c₀`, `c` the
/// boxes' centres, `k = committed width / live width`): that is `t = a k (c₀ − c)`.
pub fn gesture_transform(a: f64, committed: Viewport, live: Viewport) -> (f64, f64, f64) {
    let k = committed.width / live.width;
    let (c0, c) = (committed.centre(), live.centre());
    (a * k * (c0.x - c.x), a * k * (c0.y - c.y), k)
}

/// Screen → drawing mapping of a live view box, from the screen matrix of the committed one:
/// a similarity (scale about the screen centre of the view, then a move to the live view's
/// centre), in geometry's `Transform` like every other affine map of the project.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LiveMapping {
    to_drawing: Transform,
}

impl LiveMapping {
    /// The mapping, given the committed view's screen matrix `screen = a · user + (e, f)`.
    fn new(a: f64, e: f64, f: f64, committed: Viewport, live: Viewport) -> Self {
        let centre = committed.centre();
        // Screen pixels per drawing unit in the live view.
        let scale = a * committed.width / live.width;
        // The committed view's centre on screen is the live view's centre.
        let screen_centre = Point::new(a * centre.x + e, a * centre.y + f);
        let live_centre = live.centre();
        Self {
            to_drawing: Transform::translation(-screen_centre.x, -screen_centre.y)
                .then(&Transform::scaling(1.0 / scale))
                .then(&Transform::translation(live_centre.x, live_centre.y)),
        }
    }

    /// The drawing point under a screen point.
    fn drawing_at(self, client_x: f64, client_y: f64) -> Point {
        self.to_drawing.apply(Point::new(client_x, client_y))
    }

    /// The drawing vector of a screen move.
    fn drawing_vector(self, dx: f64, dy: f64) -> Point {
        self.to_drawing.apply_vector(Point::new(dx, dy))
    }
}

/// A gesture under way: the element it moves, the committed view's screen matrix taken when
/// it began (the element's own CSS transform must not enter it), and the live view.
struct Gesture {
    svg: SvgGraphicsElement,
    /// Siblings drawn over the view that must move with it (`data-follows-gesture`: the
    /// animation's overlay).
    followers: Vec<web_sys::Element>,
    /// `screen = a · user + (e, f)` for the committed view box.
    ctm: (f64, f64, f64),
    committed: Viewport,
    live: Viewport,
}

impl Gesture {
    fn mapping(&self) -> LiveMapping {
        let (a, e, f) = self.ctm;
        LiveMapping::new(a, e, f, self.committed, self.live)
    }
}

/// Handlers that drive `view` (the current view box, `None` = fit) given the fitted box.
#[derive(Clone, Copy)]
pub struct PanZoom {
    /// The committed view box (the SVG `viewBox`), `None` = fit the whole drawing.
    pub view: RwSignal<Option<Viewport>>,
    /// The fitted view box, used when `view` is `None`.
    pub fit: Signal<Option<Viewport>>,
    gesture: StoredValue<Option<Gesture>, LocalStorage>,
    /// Commits the view when the wheel has been quiet for [`WHEEL_SETTLE_MS`].
    wheel_timer: StoredValue<Option<TimeoutHandle>>,
    pointers: StoredValue<HashMap<i32, (f64, f64)>, LocalStorage>,
}

impl PanZoom {
    /// State for one view.
    pub fn new(fit: Signal<Option<Viewport>>) -> Self {
        Self {
            view: RwSignal::new(None),
            fit,
            gesture: StoredValue::new_local(None),
            wheel_timer: StoredValue::new(None),
            pointers: StoredValue::new_local(HashMap::new()),
        }
    }

    /// The committed view box to render.
    pub fn current(&self) -> Option<Viewport> {
        self.view.get().or_else(|| self.fit.get())
    }

    fn committed_untracked(&self) -> Option<Viewport> {
        self.view
            .get_untracked()
            .or_else(|| self.fit.get_untracked())
    }

    /// Back to "fit the sheet" (ends any gesture without committing it).
    pub fn reset(&self) {
        self.end_gesture();
        self.view.set(None);
    }

    /// The live view and its screen mapping, starting a gesture on `ev`'s `<svg>` if none is
    /// under way.
    fn gesture_view<E: AsRef<web_sys::Event>>(&self, ev: &E) -> Option<(Viewport, LiveMapping)> {
        let running = self
            .gesture
            .with_value(|g| g.as_ref().map(|g| (g.live, g.mapping())));
        if running.is_some() {
            return running;
        }
        let committed = self.committed_untracked()?;
        let svg = target_svg(ev)?;
        let m = svg.get_screen_ctm()?;
        let (a, e, f) = (f64::from(m.a()), f64::from(m.e()), f64::from(m.f()));
        if a == 0.0 || !a.is_finite() || committed.width == 0.0 {
            return None;
        }
        // Hit-testing thousands of paths on every move is wasted work mid-gesture.
        let _ = svg.set_attribute("data-gesture", "");
        let followers =
            std::iter::successors(svg.next_element_sibling(), |e| e.next_element_sibling())
                .filter(|e| e.has_attribute("data-follows-gesture"))
                .collect();
        let gesture = Gesture {
            svg,
            followers,
            ctm: (a, e, f),
            committed,
            live: committed,
        };
        let result = (gesture.live, gesture.mapping());
        self.gesture.set_value(Some(gesture));
        Some(result)
    }

    /// Shows `live` during a gesture: a transform of the `<svg>`, no `viewBox` change.
    fn show_live(&self, live: Viewport) {
        self.gesture.update_value(|g| {
            if let Some(g) = g {
                g.live = live;
                let (tx, ty, k) = gesture_transform(g.ctm.0, g.committed, live);
                let style = format!("transform:translate({tx}px,{ty}px) scale({k})");
                let _ = g.svg.set_attribute("style", &style);
                for follower in &g.followers {
                    let _ = follower.set_attribute("style", &style);
                }
            }
        });
    }

    /// Ends the gesture under way, if any, undoing its transform; returns its live view.
    fn end_gesture(&self) -> Option<Viewport> {
        if let Some(timer) = self.wheel_timer.try_update_value(Option::take).flatten() {
            timer.clear();
        }
        let gesture = self.gesture.try_update_value(Option::take).flatten()?;
        let _ = gesture.svg.remove_attribute("style");
        for follower in &gesture.followers {
            let _ = follower.remove_attribute("style");
        }
        let _ = gesture.svg.remove_attribute("data-gesture");
        Some(gesture.live)
    }

    /// Ends the gesture under way, making its view box the `viewBox`.
    pub fn commit(&self) {
        if let Some(live) = self.end_gesture() {
            self.view.set(Some(live));
        }
    }

    /// Wheel: zoom around the cursor.
    pub fn on_wheel(&self, ev: WheelEvent) {
        ev.prevent_default();
        let Some((live, mapping)) = self.gesture_view(&ev) else {
            return;
        };
        let anchor = mapping.drawing_at(f64::from(ev.client_x()), f64::from(ev.client_y()));
        // deltaMode 1 = lines: scale them to pixels so mice and touchpads feel alike.
        let delta = ev.delta_y() * if ev.delta_mode() == 1 { 16.0 } else { 1.0 };
        self.show_live(live.zoomed_about((delta * 0.0015).exp(), anchor));
        let this = *self;
        let timer = set_timeout_with_handle(
            move || this.commit(),
            Duration::from_millis(WHEEL_SETTLE_MS),
        )
        .ok();
        if let Some(old) = self
            .wheel_timer
            .try_update_value(|t| std::mem::replace(t, timer))
        {
            old.iter().for_each(TimeoutHandle::clear);
        }
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
        let Some((view, mapping)) = self.gesture_view(&ev) else {
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
                view.zoomed_about(d_before / d_now, mapping.drawing_at(mid.0, mid.1))
            }
        } else {
            view.panned(-mapping.drawing_vector(now.0 - before.0, now.1 - before.1))
        };
        self.pointers.update_value(|p| {
            p.insert(id, now);
        });
        self.show_live(next);
    }

    /// Pointer up or cancelled: that pointer no longer drags; the last one commits the view.
    pub fn on_pointer_up(&self, ev: PointerEvent) {
        let none_left = self
            .pointers
            .try_update_value(|p| {
                p.remove(&ev.pointer_id());
                p.is_empty()
            })
            .unwrap_or(true);
        if none_left {
            self.commit();
        }
    }

    /// Keyboard: `+`/`=` zoom in, `-` zoom out, arrows pan, `0` fits the sheet.
    pub fn on_key(&self, ev: KeyboardEvent) {
        // A key press is a whole gesture: it ends any other one (keeping where it got to) and
        // commits at once.
        self.commit();
        let Some(view) = self.committed_untracked() else {
            return;
        };
        let (w, h) = (view.width, view.height);
        let next = match ev.key().as_str() {
            "+" | "=" => Some(view.zoomed_about(1.0 / KEY_ZOOM, view.centre())),
            "-" | "_" => Some(view.zoomed_about(KEY_ZOOM, view.centre())),
            "ArrowLeft" => Some(view.panned(Point::new(-w * KEY_PAN, 0.0))),
            "ArrowRight" => Some(view.panned(Point::new(w * KEY_PAN, 0.0))),
            "ArrowUp" => Some(view.panned(Point::new(0.0, -h * KEY_PAN))),
            "ArrowDown" => Some(view.panned(Point::new(0.0, h * KEY_PAN))),
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
    use super::{fitted_view, gesture_transform, view_box_attribute, LiveMapping, Viewport};
    use cutroute_geometry::{BoundingBox, Point};

    #[test]
    fn the_fitted_view_flips_y_and_keeps_a_margin() {
        // A 100 × 50 box whose top edge is at y = 60: 3 mm margin, y flipped.
        let bounds = BoundingBox::from_corners(Point::new(10.0, 10.0), Point::new(110.0, 60.0));
        assert_eq!(fitted_view(bounds), Viewport::new(7.0, -63.0, 106.0, 56.0));
        // A tiny box still gets a 1 mm margin.
        let dot = BoundingBox::from_corners(Point::new(0.0, 0.0), Point::new(2.0, 1.0));
        let view: Viewport = fitted_view(dot);
        assert_eq!(view, Viewport::new(-1.0, -2.0, 4.0, 3.0));
        assert_eq!(view_box_attribute(view), "-1 -2 4 3");
    }

    #[test]
    fn zoom_keeps_the_anchor_point_fixed() {
        let view = Viewport::new(0.0, 0.0, 100.0, 50.0);
        let zoomed = view.zoomed_about(0.5, Point::new(20.0, 10.0));
        assert_eq!(zoomed, Viewport::new(10.0, 5.0, 50.0, 25.0));
        // The anchor sits at the same relative place in both boxes.
        let rel = |v: Viewport| ((20.0 - v.x) / v.width, (10.0 - v.y) / v.height);
        assert_eq!(rel(view), rel(zoomed));
    }

    /// Screen point of drawing point `p` when `view` is the viewBox of an 800 × 500 px viewport
    /// at (40, 60), `xMidYMid meet` (what the browser does).
    fn screen(view: Viewport, p: (f64, f64)) -> (f64, f64) {
        let (vw, vh) = (800.0, 500.0);
        let a = (vw / view.width).min(vh / view.height);
        let e = 40.0 + (vw - a * view.width) / 2.0 - a * view.x;
        let f = 60.0 + (vh - a * view.height) / 2.0 - a * view.y;
        (a * p.0 + e, a * p.1 + f)
    }

    fn close(a: (f64, f64), b: (f64, f64)) -> bool {
        (a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6
    }

    #[test]
    fn the_gesture_transform_shows_the_live_view() {
        // Committed box taller than the viewport's aspect, so "meet" letterboxes it.
        let committed = Viewport::new(-20.0, -310.0, 400.0, 300.0);
        let a = screen(committed, (1.0, 0.0)).0 - screen(committed, (0.0, 0.0)).0;
        // The element's centre, the CSS transform origin.
        let origin = (40.0 + 400.0, 60.0 + 250.0);
        let lives = [
            committed.zoomed_about(0.37, Point::new(55.0, -120.0)),
            committed.zoomed_about(2.5, Point::new(300.0, -20.0)),
            Viewport::new(committed.x + 33.0, committed.y - 71.0, 400.0, 300.0),
        ];
        for live in lives {
            let (tx, ty, k) = gesture_transform(a, committed, live);
            for p in [(0.0, 0.0), (123.0, -45.0), (-300.0, 80.0)] {
                let (sx, sy) = screen(committed, p);
                let moved = (
                    origin.0 + tx + k * (sx - origin.0),
                    origin.1 + ty + k * (sy - origin.1),
                );
                assert!(close(moved, screen(live, p)), "{live:?} {p:?}");
            }
        }
    }

    #[test]
    fn the_live_mapping_inverts_the_live_view_and_zoom_stays_under_the_cursor() {
        let committed = Viewport::new(-20.0, -310.0, 400.0, 300.0);
        // The committed view's screen matrix, as getScreenCTM reports it.
        let (e, f) = screen(committed, (0.0, 0.0));
        let a = screen(committed, (1.0, 0.0)).0 - e;
        let mut live = committed;
        let cursor = (500.0, 200.0);
        for step in 0..20 {
            let mapping = LiveMapping::new(a, e, f, committed, live);
            let anchor = mapping.drawing_at(cursor.0, cursor.1);
            let (ux, uy) = (anchor.x, anchor.y);
            assert!(close(screen(live, (ux, uy)), cursor), "step {step}");
            let factor = if step < 10 { 0.8 } else { 1.3 };
            live = live.zoomed_about(factor, anchor);
            // The drawing point under the cursor is the same after the zoom.
            assert!(close(screen(live, (ux, uy)), cursor), "step {step}");
        }
    }
}
