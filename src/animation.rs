//! The animation of the tool along the route, on the machine's time axis.
//!
//! What is animated is a [`Toolpath`]: the head's moves, whether they come from a route of
//! whole contours (`Toolpath::new`) or from a route of tool-on paths (segment cutting, AOE:
//! [`crate::drawing::path_route_toolpath`]); the clock is the toolpath's machine time.
//!
//! State is the machine time shown; every frame (requestAnimationFrame) advances it by the real
//! time elapsed times the speed factor, and the drawing asks [`Timeline::frame_at`] where the
//! head is. The route is cut once into chunks of a few dozen moves, each small on the drawing
//! ([`crate::drawing::travel_chunks`]). The part travelled is drawn by two paths: the whole
//! route revealed by a dash up to the last chunk fully travelled (`#anim-done`, changed only
//! when the head leaves a chunk), and the chunk under the head revealed up to the head
//! (`#anim-current`). The head moves by a transform. A frame thus changes a handful of
//! attributes of two small elements, whatever the nest's size, in an overlay `<svg>` of its
//! own (see [`AnimationOverlay`]).
//!
//! Contract with the tests and the app benchmark (keep): play button `#anim-play` (aria-label
//! "Play" / "Pause"), slider `#anim-scrub`, speed select `#anim-speed`, the head
//! `<circle id="tool-head">` with `data-machine-time` (seconds, updated each frame), the clock
//! `#anim-clock`, and `#anim-done` whose `pathLength` is the route's length and whose
//! `stroke-dasharray` starts with the length of the chunks fully travelled.

use cutroute_geometry::{BoundingBox, MachineParameters, ToolClock, ToolMove, ToolState, Toolpath};
use leptos::prelude::*;

use crate::clock::hms_tenths;
use crate::drawing::{travel_chunks, ChunkLimits, Travel};
use crate::i18n::{tr, use_language, Lang};

/// Speed factors offered: machine seconds per real second.
pub const SPEEDS: [u32; 7] = [1, 2, 5, 10, 20, 50, 100];
/// The speed selected at first.
const DEFAULT_SPEED: u32 = 10;

/// Chunks of the travelled route are at most this fraction of the route's extent wide or high:
/// it bounds the area a frame repaints.
const CHUNK_SIDE_FRACTION: f64 = 1.0 / 12.0;
/// Most moves in one chunk.
const CHUNK_MOVES: usize = 128;

/// A route laid out in time and space, ready to animate.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// The head's moves.
    pub toolpath: Toolpath,
    /// When each move starts.
    pub clock: ToolClock,
    /// The toolpath as path data in chunks, with the distance at which each move starts.
    pub travel: Travel,
    /// Indices of the pierce moves: where each contour (each tool-on path) begins.
    pub pierces: Vec<usize>,
    /// Machine time at which each pierce starts (non-decreasing).
    pierce_times: Vec<f64>,
}

/// What one animation frame shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Machine time, s.
    pub time: f64,
    /// The head.
    pub state: ToolState,
    /// Index of the chunk under the head (`None` for an empty route).
    pub chunk: Option<usize>,
    /// Distance travelled within that chunk.
    pub chunk_travelled: f64,
}

impl Timeline {
    /// The timeline of `toolpath` under `machine`.
    pub fn new(toolpath: Toolpath, machine: &MachineParameters) -> Timeline {
        let clock = ToolClock::new(&toolpath, machine);
        let extent = toolpath_extent(&toolpath);
        let travel = travel_chunks(
            &toolpath,
            ChunkLimits {
                max_moves: CHUNK_MOVES,
                max_side: extent * CHUNK_SIDE_FRACTION,
            },
        );
        let pierces: Vec<usize> = toolpath
            .moves
            .iter()
            .enumerate()
            .filter(|(_, m)| matches!(m, ToolMove::Pierce { .. }))
            .map(|(i, _)| i)
            .collect();
        let pierce_times = pierces.iter().filter_map(|&i| clock.start_of(i)).collect();
        Timeline {
            toolpath,
            clock,
            travel,
            pierces,
            pierce_times,
        }
    }

    /// Machine time of the whole route, s.
    pub fn total(&self) -> f64 {
        self.clock.total()
    }

    /// The head at machine time `t`.
    pub fn state_at(&self, t: f64) -> ToolState {
        self.clock.state_at(&self.toolpath, t)
    }

    /// Distance travelled along the route at machine time `t` (the tests' measure of progress;
    /// the drawing uses [`Timeline::frame_at`]).
    #[cfg(test)]
    pub fn travelled_at(&self, t: f64) -> f64 {
        self.travelled(&self.state_at(t))
    }

    fn travelled(&self, state: &ToolState) -> f64 {
        match state.move_index {
            None => 0.0,
            Some(i) => {
                let starts = &self.travel.move_starts;
                let (a, b) = (starts[i], starts[i + 1]);
                a + (b - a) * state.fraction
            }
        }
    }

    /// Everything a frame at machine time `t` draws.
    pub fn frame_at(&self, t: f64) -> Frame {
        let state = self.state_at(t);
        let chunk = state.move_index.and_then(|i| self.travel.chunk_of_move(i));
        let chunk_travelled = chunk.map_or(0.0, |k| {
            let c = &self.travel.chunks[k];
            (self.travelled(&state) - c.start).clamp(0.0, c.length)
        });
        Frame {
            time: t,
            state,
            chunk,
            chunk_travelled,
        }
    }

    /// Length of the route, idle and cut moves.
    #[cfg(test)]
    pub fn travel_length(&self) -> f64 {
        self.travel.length()
    }

    /// Start time of the first contour beginning after `t` (the end when there is none).
    pub fn next_contour(&self, t: f64) -> f64 {
        let after = self.pierce_times.partition_point(|&s| s <= t + 1e-9);
        self.pierce_times
            .get(after)
            .copied()
            .unwrap_or_else(|| self.total())
    }

    /// Start time of the last contour beginning before `t` (0 when there is none).
    pub fn previous_contour(&self, t: f64) -> f64 {
        let before = self.pierce_times.partition_point(|&s| s < t - 1e-9);
        before.checked_sub(1).map_or(0.0, |k| self.pierce_times[k])
    }

    /// Number of contours begun by machine time `t` (pierce included).
    pub fn contours_begun(&self, t: f64) -> usize {
        self.pierce_times.partition_point(|&s| s <= t)
    }
}

/// Largest side of the box of everything the toolpath draws (0 for an empty toolpath).
fn toolpath_extent(toolpath: &Toolpath) -> f64 {
    let mut bounds = BoundingBox::from_corners(toolpath.start, toolpath.start);
    for m in &toolpath.moves {
        bounds = match m {
            ToolMove::Cut { span, .. } => bounds.union(span.bounding_box()),
            other => bounds.including(other.end()),
        };
    }
    bounds.width().max(bounds.height())
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
    /// What one pierce starts, for the step buttons and the counter: "contour" for routes of
    /// whole contours, "path" for routes of tool-on paths.
    pub piece: Signal<&'static str>,
}

impl Animation {
    /// State for the toolpath shown.
    pub fn new(
        toolpath: Signal<Option<Toolpath>>,
        machine: RwSignal<MachineParameters>,
        piece: Signal<&'static str>,
    ) -> Self {
        let timeline = Memo::new(move |_| {
            toolpath.with(|toolpath| {
                let toolpath = toolpath.as_ref()?.clone();
                machine.with(|m| Some(Timeline::new(toolpath, m)))
            })
        });
        Self {
            timeline,
            time: RwSignal::new(None),
            playing: RwSignal::new(false),
            speed: RwSignal::new(DEFAULT_SPEED),
            piece,
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

/// Play/pause, contour steps, scrub slider, speed and clock.
#[component]
pub fn AnimationControls(animation: Animation) -> impl IntoView {
    let Animation {
        timeline, playing, ..
    } = animation;
    let absent = move || timeline.with(Option::is_none);
    let language = use_language();
    let play_pause = move || {
        if playing.get() {
            language.pick("Pause", "Пауза")
        } else {
            language.pick("Play", "Пуск анимации")
        }
    };
    view! {
        <div class="animation" role="group" aria-label=tr("Animation of the route", "Анимация маршрута")>
            <StepButton animation=animation forward=false />
            <button
                id="anim-play"
                aria-label=play_pause
                title=play_pause
                disabled=absent
                on:click=move |_| animation.toggle()
            >
                {play_pause}
            </button>
            <StepButton animation=animation forward=true />
            <TimeControls animation=animation />
            <ContourCounter animation=animation />
        </div>
    }
}

/// The piece ("contour" or "path") in the page's language; both are masculine in Russian.
fn piece_word(lang: Lang, piece: &'static str) -> &'static str {
    match (lang, piece) {
        (Lang::En, p) => p,
        (Lang::Ru, "path") => "путь",
        (Lang::Ru, _) => "контур",
    }
}

/// The button to the previous or the next pierce.
#[component]
fn StepButton(animation: Animation, forward: bool) -> impl IntoView {
    let Animation {
        timeline,
        time,
        piece,
        ..
    } = animation;
    let language = use_language();
    let step = move || {
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
    let name = move || match (language.get(), forward) {
        (Lang::En, false) => format!("Previous {}", piece.get()),
        (Lang::En, true) => format!("Next {}", piece.get()),
        (Lang::Ru, false) => format!("Предыдущий {}", piece_word(Lang::Ru, piece.get())),
        (Lang::Ru, true) => format!("Следующий {}", piece_word(Lang::Ru, piece.get())),
    };
    let (id, text) = if forward {
        ("anim-next", tr("Next ›", "Вперёд ›"))
    } else {
        ("anim-prev", tr("‹ Prev", "‹ Назад"))
    };
    view! {
        <button
            id=id
            title=name
            aria-label=name
            disabled=move || timeline.with(Option::is_none)
            on:click=move |_| step()
        >
            {text}
        </button>
    }
}

/// The machine-time slider, the speed and the clock.
#[component]
fn TimeControls(animation: Animation) -> impl IntoView {
    let Animation {
        timeline,
        time,
        speed,
        ..
    } = animation;
    let total = move || timeline.with(|t| t.as_ref().map_or(0.0, Timeline::total));
    let shown = move || time.get().unwrap_or(0.0);
    view! {
        <label class="scrub">
            <span class="visually-hidden">{tr("Machine time", "Время работы станка")}</span>
            <input
                id="anim-scrub"
                type="range"
                min="0"
                step="any"
                aria-label=tr("Machine time", "Время работы станка")
                disabled=move || timeline.with(Option::is_none)
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
            {tr("Speed ", "Скорость ")}
            <select
                id="anim-speed"
                aria-label=tr("Animation speed (machine time)", "Скорость анимации (по времени станка)")
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
            aria-label=tr("Machine time", "Время работы станка")
            data-time=move || format!("{:.3}", shown())
            data-total=move || format!("{:.3}", total())
        >
            {move || format!("{} / {}", hms_tenths(shown()), hms_tenths(total()))}
        </output>
    }
}

/// Which contour (or tool-on path) the head is at, of how many.
#[component]
fn ContourCounter(animation: Animation) -> impl IntoView {
    let Animation {
        timeline,
        time,
        piece,
        ..
    } = animation;
    let language = use_language();
    let contour_text = move || {
        let t = time.get()?;
        let lang = language.get();
        let of = lang.pick("of", "из");
        timeline.with(|tl| {
            tl.as_ref().map(|tl| {
                format!(
                    "{} {} {of} {}",
                    piece_word(lang, piece.get()),
                    tl.contours_begun(t),
                    tl.pierces.len()
                )
            })
        })
    };
    view! { <span id="anim-contour" class="muted">{contour_text}</span> }
}

/// The travelled route and the tool head, in an `<svg>` of their own stacked on the view (same
/// `view_box`, y up). `scale` is the current view's width in drawing units (sizes follow the
/// zoom).
///
/// The paths are created once per route; per frame only the dash of `#anim-current` and the
/// head's transform change; `#anim-done`'s dash and `#anim-current`'s path data change when the
/// head leaves a chunk. Nothing here re-renders the route as the time advances. Being a
/// separate element (its own paint layer and compositing layer, `style/base.css`), a frame
/// repaints and rasters only this overlay: inside the view's SVG the same change made Chromium
/// repaint thousands of labels and pierce marks and re-raster the route's single big paths
/// under the head, ~50–130 ms a frame at 5,000 contours. Pan/zoom gestures move it with the
/// view (`data-follows-gesture`, `src/pan_zoom.rs`).
#[component]
pub fn AnimationOverlay(scale: Signal<f64>, view_box: Signal<Option<String>>) -> impl IntoView {
    let animation = expect_context::<Animation>();
    let timeline = animation.timeline;
    let frame = OverlayFrame::new(animation);
    view! {
        <svg
            id="anim-overlay"
            class="nest-overlay"
            xmlns="http://www.w3.org/2000/svg"
            viewBox=move || view_box.get()
            preserveAspectRatio="xMidYMid meet"
            aria-hidden="true"
            data-follows-gesture=""
            data-chunks=move || timeline.with(|tl| tl.as_ref().map(|tl| tl.travel.chunks.len()))
        >
            <g transform="scale(1,-1)">
                <TravelledRoute timeline=timeline frame=frame scale=scale />
                <ToolHead frame=frame.frame scale=scale />
            </g>
        </svg>
    }
}

/// What the overlay shows at the animation's time, each part a memo computed once per frame
/// and read by every attribute that needs it. Only `frame` changes every frame; the chunk
/// under the head and the length travelled in whole chunks change a few times a second.
#[derive(Clone, Copy)]
struct OverlayFrame {
    /// The head and the chunk under it (at the route's start before the animation is used).
    frame: Memo<Option<Frame>>,
    /// The chunk under the head while the travelled route is shown.
    current: Memo<Option<usize>>,
    /// The route length of the chunks fully travelled.
    finished: Memo<Option<f64>>,
    /// The whole route's length, when positive.
    route_length: Memo<Option<f64>>,
    /// The chunk under the head, unless already drawn whole by `#anim-done`. A chunk of a
    /// lone pierce has no length: not drawn (a zero pathLength is invalid).
    partial: Memo<Option<usize>>,
    /// That chunk's length.
    partial_length: Memo<Option<f64>>,
}

impl OverlayFrame {
    fn new(animation: Animation) -> Self {
        let Animation { timeline, time, .. } = animation;
        let frame = Memo::new(move |_| {
            let t = time.get().unwrap_or(0.0);
            timeline.with(|tl| tl.as_ref().map(|tl| tl.frame_at(t)))
        });
        let revealed = Memo::new(move |_| time.get().is_some());
        let current = Memo::new(move |_| {
            revealed
                .get()
                .then(|| frame.with(|f| f.and_then(|f| f.chunk)))
                .flatten()
        });
        // A chunk's start along the route and its length.
        let chunk = move |k: usize| {
            timeline.with(|tl| {
                tl.as_ref()?
                    .travel
                    .chunks
                    .get(k)
                    .map(|c| (c.start, c.length))
            })
        };
        let finished = Memo::new(move |_| {
            let (k, travelled) =
                frame.with(|f| f.and_then(|f| Some((f.chunk?, f.chunk_travelled))))?;
            let (start, length) = chunk(k)?;
            Some(if travelled >= length {
                start + length
            } else {
                start
            })
        });
        let route_length = Memo::new(move |_| {
            timeline.with(|tl| {
                tl.as_ref()
                    .map(|tl| tl.travel.length())
                    .filter(|&l| l > 0.0)
            })
        });
        let partial = Memo::new(move |_| {
            let (k, done) = (current.get()?, finished.get()?);
            let (start, length) = chunk(k)?;
            (length > 0.0 && done <= start).then_some(k)
        });
        let partial_length = Memo::new(move |_| chunk(partial.get()?).map(|(_, length)| length));
        Self {
            frame,
            current,
            finished,
            route_length,
            partial,
            partial_length,
        }
    }
}

/// The route travelled so far: the chunks fully travelled (the whole route revealed by a dash
/// that changes only when the head leaves a chunk), and the travelled part of the chunk under
/// the head (the only path a frame changes).
#[component]
fn TravelledRoute(
    timeline: Memo<Option<Timeline>>,
    frame: OverlayFrame,
    scale: Signal<f64>,
) -> impl IntoView {
    let OverlayFrame {
        current,
        finished,
        route_length,
        partial,
        partial_length,
        ..
    } = frame;
    let route_d = move || timeline.with(|tl| tl.as_ref().map(|tl| tl.travel.d.clone()));
    let partial_d = move || {
        let k = partial.get()?;
        timeline.with(|tl| tl.as_ref()?.travel.chunks.get(k).map(|c| c.d.clone()))
    };
    // A dash of `done` along a path of `length` (the gap longer than the path).
    let dash = |done: f64, length: f64| format!("{done} {}", length * 2.0 + 1.0);
    // (`#anim-done` is hidden before the first chunk is done: a dash of length 0 shows as a dot.)
    let done_shown = move || current.get().is_some() && finished.get().is_some_and(|d| d > 0.0);
    view! {
        <g class="travelled" stroke-width=move || scale.get() / 250.0>
            <path
                id="anim-done"
                class="done"
                d=route_d
                pathLength=move || route_length.get()
                stroke-dasharray=move || {
                    let length = route_length.get()?;
                    Some(dash(finished.get()?, length))
                }
                visibility=move || if done_shown() { "visible" } else { "hidden" }
            />
            <path
                id="anim-current"
                class="done"
                d=partial_d
                pathLength=move || partial_length.get()
                // (The frame is read only while a chunk is partly travelled: no work per
                // frame otherwise.)
                stroke-dasharray=move || {
                    let length = partial_length.get()?;
                    Some(dash(frame.frame.get()?.chunk_travelled, length))
                }
                visibility=move || if partial.get().is_some() { "visible" } else { "hidden" }
            />
        </g>
    }
}

/// The tool head at the frame's position, lit while the tool is on; `data-machine-time` is
/// the frame's clock time for checks by tools.
#[component]
fn ToolHead(frame: Memo<Option<Frame>>, scale: Signal<f64>) -> impl IntoView {
    let head_shown = Memo::new(move |_| frame.with(Option::is_some));
    let head_state = move || frame.get().map(|f| f.state);
    move || {
        head_shown.get().then(|| {
            view! {
                <circle
                    id="tool-head"
                    class=move || {
                        if head_state().is_some_and(|s| s.tool_on) { "tool-head on" } else { "tool-head" }
                    }
                    r=move || scale.get() / 120.0
                    transform=move || {
                        head_state().map(|s| format!("translate({} {})", s.position.x, s.position.y))
                    }
                    data-machine-time=move || format!("{:.3}", frame.get().map_or(0.0, |f| f.time))
                />
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, ContourRef, CutStep, Nest, Part, Point, Route, Vertex};

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
        let tl = Timeline::new(
            Toolpath::new(&route, &nest).unwrap(),
            &MachineParameters::default(),
        );
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
    fn a_frame_is_the_finished_chunks_plus_the_part_of_the_current_one() {
        let (nest, route) = two_squares();
        let tl = Timeline::new(
            Toolpath::new(&route, &nest).unwrap(),
            &MachineParameters::default(),
        );
        // The route spans 30 mm: chunks are at most 2.5 mm wide, so nearly every move is one.
        assert!(
            tl.travel.chunks.len() > 4,
            "{} chunks",
            tl.travel.chunks.len()
        );
        let mut last_chunk = 0;
        for k in 0..=200 {
            let t = tl.total() * f64::from(k) / 200.0;
            let frame = tl.frame_at(t);
            let chunk = frame.chunk.unwrap();
            assert!(chunk >= last_chunk, "the head never goes back");
            last_chunk = chunk;
            let c = &tl.travel.chunks[chunk];
            assert!((0.0..=c.length).contains(&frame.chunk_travelled));
            let finished: f64 = tl.travel.chunks[..chunk].iter().map(|c| c.length).sum();
            assert!((finished + frame.chunk_travelled - tl.travelled_at(t)).abs() < 1e-9);
            assert_eq!(frame.state, tl.state_at(t));
        }
        let end = tl.frame_at(tl.total());
        assert_eq!(end.chunk, Some(tl.travel.chunks.len() - 1));
        let last = tl.travel.chunks.last().unwrap();
        assert!((end.chunk_travelled - last.length).abs() < 1e-9);
    }

    #[test]
    fn a_path_route_plays_to_its_machine_time() {
        use cutroute_geometry::{PathRoute, Span, ToolOnPath};
        let p = Point::new;
        let route = PathRoute {
            start: p(0.0, -10.0),
            paths: vec![
                ToolOnPath {
                    pierce: p(0.0, 0.0),
                    spans: vec![Span::line(p(0.0, 0.0), p(10.0, 0.0))],
                    leads: None,
                },
                ToolOnPath {
                    pierce: p(20.0, 0.0),
                    spans: vec![
                        Span::line(p(20.0, 0.0), p(20.0, 10.0)),
                        Span::line(p(20.0, 10.0), p(30.0, 10.0)),
                    ],
                    leads: None,
                },
            ],
            finish: None,
        };
        let machine = MachineParameters::default();
        let tl = Timeline::new(Toolpath::from_path_route(&route), &machine);
        assert!((tl.total() - route.time(&machine)).abs() < 1e-9);
        assert_eq!(tl.pierces.len(), 2);
        assert_eq!(tl.contours_begun(tl.total()), 2);
        // Idle 10 + cut 10 + idle 10 + cut 20.
        assert!((tl.travel_length() - 50.0).abs() < 1e-9);
        let end = tl.state_at(tl.total());
        assert_eq!(end.position, p(30.0, 10.0));
    }
}
