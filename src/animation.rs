//! The animation of the tool along the route, on the machine's time axis.
//!
//! State is the machine time shown; every frame (requestAnimationFrame) advances it by the real
//! time elapsed times the speed factor, and the drawing asks [`ToolClock::state_at`] where the
//! head is. The already-travelled route is one path revealed by a dash whose length is the
//! distance travelled, so a frame changes a handful of attributes whatever the nest's size.
//!
//! Contract with the app benchmark (keep): play button `#anim-play` (aria-label "Play" /
//! "Pause"), slider `#anim-scrub`, speed select `#anim-speed`, the head `<circle id="tool-head">`
//! with `data-machine-time` (seconds, updated each frame), and the clock `#anim-clock`.

use cutroute_geometry::{MachineParameters, Nest, Route, ToolClock, ToolMove, ToolState, Toolpath};
use leptos::prelude::*;

use crate::drawing::travel_path;

/// Speed factors offered: machine seconds per real second.
pub const SPEEDS: [u32; 7] = [1, 2, 5, 10, 20, 50, 100];
/// The speed selected at first.
const DEFAULT_SPEED: u32 = 10;

/// A route laid out in time and space, ready to animate.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// The head's moves.
    pub toolpath: Toolpath,
    /// When each move starts.
    pub clock: ToolClock,
    /// The whole toolpath as one continuous SVG subpath.
    pub travel: String,
    /// Distance along `travel` at which each move starts (one more entry for the end).
    pub travel_starts: Vec<f64>,
    /// Indices of the pierce moves: where each contour begins.
    pub pierces: Vec<usize>,
}

impl Timeline {
    /// The timeline of `route` over `nest` under `machine`; `None` if the route names contours
    /// the nest lacks.
    pub fn new(nest: &Nest, route: &Route, machine: &MachineParameters) -> Option<Timeline> {
        let toolpath = Toolpath::new(route, nest).ok()?;
        let clock = ToolClock::new(&toolpath, machine);
        let (travel, travel_starts) = travel_path(&toolpath);
        let pierces = toolpath
            .moves
            .iter()
            .enumerate()
            .filter(|(_, m)| matches!(m, ToolMove::Pierce { .. }))
            .map(|(i, _)| i)
            .collect();
        Some(Timeline {
            toolpath,
            clock,
            travel,
            travel_starts,
            pierces,
        })
    }

    /// Machine time of the whole route, s.
    pub fn total(&self) -> f64 {
        self.clock.total()
    }

    /// The head at machine time `t`.
    pub fn state_at(&self, t: f64) -> ToolState {
        self.clock.state_at(&self.toolpath, t)
    }

    /// Distance travelled along `travel` at machine time `t`.
    pub fn travelled_at(&self, t: f64) -> f64 {
        let state = self.state_at(t);
        match state.move_index {
            None => 0.0,
            Some(i) => {
                let (a, b) = (self.travel_starts[i], self.travel_starts[i + 1]);
                a + (b - a) * state.fraction
            }
        }
    }

    /// Length of `travel`.
    pub fn travel_length(&self) -> f64 {
        self.travel_starts.last().copied().unwrap_or(0.0)
    }

    /// Start time of the first contour beginning after `t` (the end when there is none).
    pub fn next_contour(&self, t: f64) -> f64 {
        self.pierces
            .iter()
            .filter_map(|&i| self.clock.start_of(i))
            .find(|&s| s > t + 1e-9)
            .unwrap_or_else(|| self.total())
    }

    /// Start time of the last contour beginning before `t` (0 when there is none).
    pub fn previous_contour(&self, t: f64) -> f64 {
        self.pierces
            .iter()
            .filter_map(|&i| self.clock.start_of(i))
            .rfind(|&s| s < t - 1e-9)
            .unwrap_or(0.0)
    }

    /// Number of contours begun by machine time `t` (pierce included).
    pub fn contours_begun(&self, t: f64) -> usize {
        self.pierces
            .iter()
            .filter_map(|&i| self.clock.start_of(i))
            .filter(|&s| s <= t)
            .count()
    }
}

/// The animation's state, shared by the controls and the drawing.
#[derive(Clone, Copy)]
pub struct Animation {
    /// What to animate.
    pub timeline: Memo<Option<Timeline>>,
    /// Machine time shown; `None` until the animation is first used (the route is then drawn
    /// plainly, without the travelled overlay).
    pub time: RwSignal<Option<f64>>,
    /// Whether frames advance the time.
    pub playing: RwSignal<bool>,
    /// Machine seconds per real second.
    pub speed: RwSignal<u32>,
}

impl Animation {
    /// State for the route shown.
    pub fn new(
        nest: Signal<Option<Nest>>,
        route: Signal<Option<Route>>,
        machine: RwSignal<MachineParameters>,
    ) -> Self {
        let timeline = Memo::new(move |_| {
            nest.with(|nest| {
                route.with(|route| {
                    machine.with(|m| Timeline::new(nest.as_ref()?, route.as_ref()?, m))
                })
            })
        });
        Self {
            timeline,
            time: RwSignal::new(None),
            playing: RwSignal::new(false),
            speed: RwSignal::new(DEFAULT_SPEED),
        }
    }

    fn total_untracked(&self) -> f64 {
        self.timeline
            .with_untracked(|t| t.as_ref().map_or(0.0, Timeline::total))
    }

    /// Play from the current time (from the start when at the end); pause if playing.
    pub fn toggle(&self) {
        if self.playing.get_untracked() {
            self.playing.set(false);
            return;
        }
        let total = self.total_untracked();
        if self.timeline.with_untracked(Option::is_none) {
            return;
        }
        let t = self.time.get_untracked().unwrap_or(0.0);
        self.time.set(Some(if t >= total { 0.0 } else { t }));
        self.playing.set(true);
        run_frames(*self, now_ms());
    }

    /// Jump to machine time `t` and pause.
    pub fn seek(&self, t: f64) {
        self.playing.set(false);
        self.time.set(Some(t.clamp(0.0, self.total_untracked())));
    }
}

fn now_ms() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or_else(js_sys::Date::now, |p| p.now())
}

/// One frame: advance the machine time by the real time since the last frame.
fn run_frames(animation: Animation, last_ms: f64) {
    request_animation_frame(move || {
        if !animation.playing.get_untracked() {
            return;
        }
        let now = now_ms();
        let real_s = (now - last_ms).max(0.0) / 1000.0;
        let total = animation.total_untracked();
        let t = animation.time.get_untracked().unwrap_or(0.0)
            + real_s * f64::from(animation.speed.get_untracked());
        if t >= total {
            animation.time.set(Some(total));
            animation.playing.set(false);
            return;
        }
        animation.time.set(Some(t));
        run_frames(animation, now);
    });
}

/// Seconds as `m:ss.s`.
pub fn format_clock(seconds: f64) -> String {
    let tenths = (seconds.max(0.0) * 10.0).round() as u64;
    format!("{}:{:02}.{}", tenths / 600, tenths / 10 % 60, tenths % 10)
}

/// Play/pause, contour steps, scrub slider, speed and clock.
#[component]
pub fn AnimationControls(animation: Animation) -> impl IntoView {
    let Animation {
        timeline,
        time,
        playing,
        speed,
    } = animation;
    let total = move || timeline.with(|t| t.as_ref().map_or(0.0, Timeline::total));
    let shown = move || time.get().unwrap_or(0.0);
    let absent = move || timeline.with(Option::is_none);
    let step = move |forward: bool| {
        let t = time.get_untracked().unwrap_or(0.0);
        let target = timeline.with_untracked(|tl| {
            tl.as_ref().map(|tl| {
                if forward {
                    tl.next_contour(t)
                } else {
                    tl.previous_contour(t)
                }
            })
        });
        if let Some(target) = target {
            animation.seek(target);
        }
    };
    let contour_text = move || {
        let t = time.get()?;
        timeline.with(|tl| {
            tl.as_ref()
                .map(|tl| format!("contour {} of {}", tl.contours_begun(t), tl.pierces.len()))
        })
    };
    view! {
        <div class="animation" role="group" aria-label="Animation of the route">
            <button
                id="anim-prev"
                title="Previous contour"
                aria-label="Previous contour"
                disabled=absent
                on:click=move |_| step(false)
            >
                "‹ Prev"
            </button>
            <button
                id="anim-play"
                aria-label=move || if playing.get() { "Pause" } else { "Play" }
                title=move || if playing.get() { "Pause" } else { "Play" }
                disabled=absent
                on:click=move |_| animation.toggle()
            >
                {move || if playing.get() { "Pause" } else { "Play" }}
            </button>
            <button
                id="anim-next"
                title="Next contour"
                aria-label="Next contour"
                disabled=absent
                on:click=move |_| step(true)
            >
                "Next ›"
            </button>
            <label class="scrub">
                <span class="visually-hidden">"Machine time"</span>
                <input
                    id="anim-scrub"
                    type="range"
                    min="0"
                    step="any"
                    aria-label="Machine time"
                    disabled=absent
                    max=move || total().to_string()
                    prop:value=move || shown().to_string()
                    on:input=move |ev| {
                        if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                            animation.seek(v);
                        }
                    }
                />
            </label>
            <label>
                "Speed "
                <select
                    id="anim-speed"
                    aria-label="Animation speed (machine time)"
                    prop:value=move || speed.get().to_string()
                    on:change=move |ev| {
                        if let Ok(v) = event_target_value(&ev).parse::<u32>() {
                            speed.set(v);
                        }
                    }
                >
                    {SPEEDS
                        .iter()
                        .map(|s| {
                            view! {
                                <option value=s.to_string() selected=*s == DEFAULT_SPEED>
                                    {format!("×{s}")}
                                </option>
                            }
                        })
                        .collect_view()}
                </select>
            </label>
            <output
                id="anim-clock"
                aria-label="Machine time"
                data-time=move || format!("{:.3}", shown())
                data-total=move || format!("{:.3}", total())
            >
                {move || format!("{} / {}", format_clock(shown()), format_clock(total()))}
            </output>
            <span id="anim-contour" class="muted">{contour_text}</span>
        </div>
    }
}

/// The travelled route and the tool head, drawn inside the view's y-up group. `scale` is the
/// current view's width in drawing units (sizes follow the zoom).
#[component]
pub fn AnimationOverlay(animation: Animation, scale: Signal<f64>) -> impl IntoView {
    let Animation { timeline, time, .. } = animation;
    let travelled = move || {
        let t = time.get()?;
        timeline.with(|tl| tl.as_ref().map(|tl| tl.travelled_at(t)))
    };
    // One memo for the head: a frame then only updates the circle's attributes (the element
    // stays; re-creating it every frame would be DOM work for nothing).
    let head = Memo::new(move |_| {
        let t = time.get().unwrap_or(0.0);
        timeline.with(|tl| tl.as_ref().map(|tl| (tl.state_at(t), t)))
    });
    let head_shown = Memo::new(move |_| head.with(Option::is_some));
    view! {
        {move || {
            timeline
                .with(|tl| tl.as_ref().map(|tl| (tl.travel.clone(), tl.travel_length())))
                .map(|(d, length)| {
                    view! {
                        <path
                            id="anim-done"
                            class="done"
                            d=d
                            pathLength=length
                            stroke-width=move || scale.get() / 250.0
                            stroke-dasharray=move || {
                                format!("{} {}", travelled().unwrap_or(0.0), length * 2.0 + 1.0)
                            }
                            visibility=move || if time.get().is_some() { "visible" } else { "hidden" }
                        />
                    }
                })
        }}
        {move || {
            head_shown.get().then(|| {
                let state = move || head.get().map(|(state, _)| state);
                view! {
                    <circle
                        id="tool-head"
                        class=move || {
                            if state().is_some_and(|s| s.tool_on) {
                                "tool-head on"
                            } else {
                                "tool-head"
                            }
                        }
                        cx=move || state().map_or(0.0, |s| s.position.x)
                        cy=move || state().map_or(0.0, |s| s.position.y)
                        r=move || scale.get() / 120.0
                        data-machine-time=move || {
                            format!("{:.3}", head.get().map_or(0.0, |(_, t)| t))
                        }
                    />
                }
            })
        }}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, ContourRef, CutStep, Part, Point, Vertex};

    fn two_squares() -> (Nest, Route) {
        let square = |x: f64| {
            Contour::new(vec![
                Vertex::line(x, 0.0),
                Vertex::line(x + 10.0, 0.0),
                Vertex::line(x + 10.0, 10.0),
                Vertex::line(x, 10.0),
            ])
        };
        let nest = Nest {
            sheet: None,
            parts: vec![
                Part {
                    name: "a".into(),
                    contours: vec![square(0.0)],
                },
                Part {
                    name: "b".into(),
                    contours: vec![square(20.0)],
                },
            ],
        };
        let step = |part, x| CutStep::pierced(ContourRef { part, contour: 0 }, Point::new(x, 0.0));
        let route = Route {
            start: Point::new(0.0, -10.0),
            steps: vec![step(0, 0.0), step(1, 20.0)],
            finish: None,
        };
        (nest, route)
    }

    #[test]
    fn contour_steps_land_on_pierces_and_the_travel_grows() {
        let (nest, route) = two_squares();
        let tl = Timeline::new(&nest, &route, &MachineParameters::default()).unwrap();
        assert_eq!(tl.pierces.len(), 2);
        let first = tl.next_contour(0.0);
        let second = tl.next_contour(first);
        assert!(first > 0.0 && second > first);
        assert_eq!(tl.next_contour(second), tl.total());
        assert_eq!(tl.previous_contour(second), first);
        assert_eq!(tl.previous_contour(first), 0.0);
        assert_eq!(tl.contours_begun(second), 2);
        // Idle 10 in + 40 round the first square + idle 20 across + 40 round the second.
        assert!((tl.travel_length() - 110.0).abs() < 1e-9);
        assert!((tl.travelled_at(tl.total()) - 110.0).abs() < 1e-9);
        let mut last = 0.0;
        for k in 0..=50 {
            let d = tl.travelled_at(tl.total() * f64::from(k) / 50.0);
            assert!(d >= last);
            last = d;
        }
    }

    #[test]
    fn the_clock_reads_minutes_seconds_tenths() {
        assert_eq!(format_clock(0.0), "0:00.0");
        assert_eq!(format_clock(75.34), "1:15.3");
    }
}
