//! The drawing: sheet, parts and the route's layers, y axis up, with pan and zoom, and the
//! animation's overlay stacked on it.

use cutroute_geometry::{Point, Viewport};
use leptos::prelude::*;

use crate::animation::{Animation, AnimationOverlay};
use crate::drawing::{
    candidate_dots, contour_path, cut_path, cut_paths_by_step, direction_arrows, idle_path,
    link_path, nest_bounds, path_route_idle_path, toolpath_bounds,
};
use crate::i18n::{tr, use_language, Lang};
use crate::order_labels::OrderLabels;
use crate::pan_zoom::{fitted_view, view_box_attribute, PanZoom};
use crate::state::{DocumentState, Shown, SolverSettings, ViewSettings};
use crate::thermal::{HeatMapLayer, ThermalView, ViolationMarks};

/// Hues the tool-on paths of a path route take in turn (`.hue-0` … `.hue-5` in `style/`).
const PATH_HUES: usize = 6;

/// The drawing: sheet, parts and the route's layers, y axis up.
#[component]
pub fn NestView() -> impl IntoView {
    let Shown { nest, route, .. } = expect_context::<Shown>();
    let hidden_layers = expect_context::<ViewSettings>().hidden_layers;
    let animation = expect_context::<Animation>();
    let thermal = expect_context::<ThermalView>();
    let fit = drawing_fit();
    // Size of the drawing: fixed-size marks (arrows, dots, numbers) scale with it.
    let extent = Memo::new(move |_| fit.get().map_or(100.0, |f| f.longer_side()));
    let pan_zoom = PanZoom::new(fit);
    // A new drawing starts fitted, with the animation rewound.
    Effect::new(move |_| {
        nest.track();
        pan_zoom.reset();
        animation.playing.set(false);
        animation.time.set(None);
    });
    let view_box = move || pan_zoom.current().map(view_box_attribute);
    let view_width = Signal::derive(move || pan_zoom.current().map_or(100.0, |v| v.longer_side()));
    // Marks are sized for the fitted view; zoomed, they are scaled back to that screen size.
    let mark_scale = move || format!("--mark-scale:{}", view_width.get() / extent.get());
    let svg = NodeRef::<leptos::svg::Svg>::new();
    let size = element_size(svg);
    let current = Signal::derive(move || pan_zoom.current());
    let px_per_unit = Signal::derive(move || {
        let (w, h) = size.get();
        match pan_zoom.current() {
            // "xMidYMid meet": the view box is fitted into the element.
            Some(v) if w > 0.0 && h > 0.0 => (w / v.width).min(h / v.height),
            // Not laid out yet: as if 1,000 pixels wide.
            _ => 1000.0 / view_width.get(),
        }
    });
    let classes = move || {
        hidden_layers.with(|hidden| {
            let mut c = String::from("nest");
            for layer in hidden {
                c.push_str(" hide-");
                c.push_str(layer.name());
            }
            c
        })
    };
    view! {
        <div class="canvas">
        <svg
            id="nest-view"
            node_ref=svg
            xmlns="http://www.w3.org/2000/svg"
            class=classes
            viewBox=view_box
            preserveAspectRatio="xMidYMid meet"
            tabindex="0"
            role="img"
            aria-label=tr(
                "Nest and route; drag to pan, wheel or + and − to zoom, 0 to fit",
                "Раскрой и маршрут; перетаскивание — сдвиг, колесо или + и − — масштаб, 0 — вписать",
            )
            on:wheel=move |ev| pan_zoom.on_wheel(ev)
            on:pointerdown=move |ev| pan_zoom.on_pointer_down(ev)
            on:pointermove=move |ev| pan_zoom.on_pointer_move(ev)
            on:pointerup=move |ev| pan_zoom.on_pointer_up(ev)
            on:pointercancel=move |ev| pan_zoom.on_pointer_up(ev)
            on:keydown=move |ev| pan_zoom.on_key(ev)
        >
            <defs><HatchPattern extent=extent /></defs>
            <g transform="scale(1,-1)" style=mark_scale>
                <NestShapes extent=extent />
                <CertificateLayer />
                <RouteLayers extent=extent />
                <ComparedRoutes />
                <crate::import_warnings::LeftOutLayer extent=extent />
                <g class="violations">
                    <ViolationMarks thermal=thermal nest=nest route=route extent=extent />
                </g>
            </g>
            <OrderLabels view=current px_per_unit=px_per_unit />
        </svg>
        // A second SVG stacked on the view: its own layer, so an animation frame repaints and
        // rasters the tool head only, not the nest (src/animation.rs).
        <AnimationOverlay scale=view_width view_box=Signal::derive(view_box) />
        </div>
    }
}

/// The size of `node`'s element in CSS pixels (its layout box, which a gesture's transform
/// does not change), kept up to date as the page's layout changes it.
fn element_size(node: NodeRef<leptos::svg::Svg>) -> ReadSignal<(f64, f64)> {
    use wasm_bindgen::{closure::Closure, JsCast};
    let (size, set_size) = signal((0.0, 0.0));
    let observer = StoredValue::new_local(None::<web_sys::ResizeObserver>);
    Effect::new(move |_| {
        let Some(svg) = node.get() else {
            return;
        };
        if observer.with_value(Option::is_some) {
            return;
        }
        let element: web_sys::Element = svg.into();
        let measure = {
            let element = element.clone();
            move || {
                set_size.set((
                    f64::from(element.client_width()),
                    f64::from(element.client_height()),
                ))
            }
        };
        measure();
        let callback = Closure::<dyn FnMut()>::new(measure);
        if let Ok(o) = web_sys::ResizeObserver::new(callback.as_ref().unchecked_ref()) {
            o.observe(&element);
            observer.set_value(Some(o));
        }
        // The observer lives as long as the page's drawing.
        callback.forget();
    });
    size
}

/// The box the drawing fits at first: the nest's; for a nest with nothing to draw (a G-code
/// program of open paths), the box of the head's moves.
fn drawing_fit() -> Signal<Option<Viewport>> {
    let Shown { nest, paths, .. } = expect_context::<Shown>();
    let animation = expect_context::<Animation>();
    let fit = Memo::new(move |_| {
        let nest_box = nest.with(|n| n.as_ref().and_then(nest_bounds));
        // Tool-on paths may leave the nest's box (a program's paths over the loops they
        // close): the view takes in their moves too.
        let paths_box = if paths.with(Option::is_some) || nest_box.is_none() {
            animation
                .timeline
                .with(|t| t.as_ref().and_then(|t| toolpath_bounds(&t.toolpath)))
        } else {
            None
        };
        match (nest_box, paths_box) {
            (Some(n), Some(p)) => Some(n.union(p)),
            (n, p) => n.or(p),
        }
        .map(fitted_view)
    });
    Signal::from(fit)
}

/// The hatch pattern of the parts, its spacing scaled with the drawing.
#[component]
fn HatchPattern(extent: Memo<f64>) -> impl IntoView {
    move || {
        let s = extent.get() / 120.0;
        view! {
            <pattern id="hatch" patternUnits="userSpaceOnUse" width=s height=s patternTransform="rotate(45)">
                <rect class="hatch-bg" width=s height=s />
                <line class="hatch-line" x1="0" y1="0" x2="0" y2=s />
            </pattern>
        }
    }
}

/// The sheet, the parts, the heat map, the cutting directions and the candidate pierce points.
#[component]
fn NestShapes(extent: Memo<f64>) -> impl IntoView {
    let nest = expect_context::<Shown>().nest;
    let hidden_layers = expect_context::<ViewSettings>().hidden_layers;
    let solver = expect_context::<SolverSettings>();
    let candidates_step = Signal::derive(move || solver.candidates_step());
    let animation = expect_context::<Animation>();
    let thermal = expect_context::<ThermalView>();
    let language = use_language();
    let parts = move || {
        nest.with(|n| {
            n.as_ref().map(|n| {
                n.parts
                    .iter()
                    .enumerate()
                    .map(|(i, part)| {
                        let mut d = String::new();
                        part.contours.iter().for_each(|c| contour_path(c, &mut d));
                        let count = part.contours.len();
                        let title = match language.get() {
                            Lang::En => format!(
                                "part {} “{}”, {count} contour{}",
                                i + 1,
                                part.name,
                                if count == 1 { "" } else { "s" }
                            ),
                            Lang::Ru => {
                                format!("деталь {} «{}», контуров: {count}", i + 1, part.name)
                            }
                        };
                        view! { <path class="part" d=d><title>{title}</title></path> }
                    })
                    .collect_view()
            })
        })
    };
    let sheet = move || {
        nest.with(|n| {
            n.as_ref().and_then(|n| n.sheet.as_ref()).map(|sheet| {
                let mut d = String::new();
                sheet.contours.iter().for_each(|c| contour_path(c, &mut d));
                d
            })
        })
    };
    let arrows = move || {
        let size = extent.get() / 60.0;
        nest.with(|n| n.as_ref().map(|n| direction_arrows(n, size)))
    };
    let candidates = move || {
        let step = candidates_step.get()?;
        nest.with(|n| n.as_ref().map(|n| candidate_dots(n, step)))
    };
    view! {
        <path class="sheet" d=sheet />
        <g class="parts">{parts}</g>
        <HeatMapLayer thermal=thermal nest=nest hidden=hidden_layers animation=animation />
        <path class="arrows" d=arrows />
        <path class="candidates" d=candidates />
    }
}

/// Certified and uncertified contours of the route (CCP's certificates).
#[component]
fn CertificateLayer() -> impl IntoView {
    let Shown {
        nest,
        route,
        certified,
        ..
    } = expect_context::<Shown>();
    // Certified and uncertified contours of the route (CCP's certificates).
    let certificates = move || {
        let flags = certified.get();
        if flags.is_empty() {
            return None;
        }
        let route = route.get()?;
        nest.with(|n| {
            let n = n.as_ref()?;
            let (mut yes, mut no) = (String::new(), String::new());
            for (step, ok) in route.steps.iter().zip(flags.iter()) {
                if let Some(c) = n.contour(step.contour) {
                    contour_path(c, if *ok { &mut yes } else { &mut no });
                }
            }
            Some((yes, no))
        })
    };
    view! {
        {move || {
            certificates()
                .map(|(yes, no)| {
                    view! {
                        <g class="certificates">
                            <path class="certified" d=yes />
                            <path class="uncertified" d=no />
                        </g>
                    }
                })
        }}
    }
}

/// The route: leads, cuts, tool-on paths, links, idle moves, pierces and its ends.
#[component]
fn RouteLayers(extent: Memo<f64>) -> impl IntoView {
    let Shown {
        nest, route, paths, ..
    } = expect_context::<Shown>();
    let animation = expect_context::<Animation>();
    // A route of whole contours: its cuts in one path. Tool-on paths: coloured in turn (six
    // hues, distinct in every theme), so where one path ends and the next begins shows; one
    // element per hue, not per path: 5,000 path elements slowed every animation frame of the
    // view (Layout and Layerize, BENCHMARKS.md). The pierce marks name each path on hover.
    let cuts = move || {
        if paths.with(Option::is_some) {
            return None;
        }
        animation
            .timeline
            .with(|t| t.as_ref().map(|t| cut_path(&t.toolpath)))
    };
    let tool_on_paths = move || {
        if paths.with(Option::is_none) {
            return None;
        }
        animation.timeline.with(|t| {
            let t = t.as_ref()?;
            let mut hues = vec![(String::new(), 0_usize); PATH_HUES];
            for (k, d) in cut_paths_by_step(&t.toolpath).into_iter().enumerate() {
                let (all, count) = &mut hues[k % PATH_HUES];
                all.push_str(&d);
                *count += 1;
            }
            Some(
                hues.into_iter()
                    .enumerate()
                    .filter(|(_, (_, count))| *count > 0)
                    .map(|(hue, (d, count))| {
                        view! {
                            <path class=format!("cut tool-on-path hue-{hue}") data-paths=count d=d />
                        }
                    })
                    .collect_view(),
            )
        })
    };
    // Tool-on moves off the contours: chain links, and a path's pieces through scrap.
    let links = move || {
        animation
            .timeline
            .with(|t| t.as_ref().map(|t| link_path(&t.toolpath)))
            .filter(|d| !d.is_empty())
    };
    let idle = move || {
        route
            .with(|r| r.as_ref().map(idle_path))
            .or_else(|| paths.with(|p| p.as_ref().map(path_route_idle_path)))
    };
    view! {
        <g class="route">
            <crate::kerf::LeadLayers nest=nest route=route paths=paths extent=Signal::from(extent) />
            <path class="cut" d=cuts />
            <g class="tool-on-paths">{tool_on_paths}</g>
            <path class="link" d=links />
            <path class="idle" d=idle />
            <g class="pierces"><ContourPierces extent=extent /><PathPierces extent=extent /></g>
            <g class="ends"><EndMarkers extent=extent /></g>
        </g>
    }
}

/// The pierce point of each step of a route of whole contours, named on hover.
#[component]
fn ContourPierces(extent: Memo<f64>) -> impl IntoView {
    let Shown { nest, route, .. } = expect_context::<Shown>();
    let language = use_language();
    let pierces = move || {
        let route = route.get()?;
        let r = extent.get() / 250.0;
        nest.with(|n| {
            let n = n.as_ref()?;
            let total = route.steps.len();
            Some(
                route
                    .steps
                    .iter()
                    .enumerate()
                    .map(|(k, s)| {
                        let part = n.parts.get(s.contour.part);
                        let name = part.map_or("", |p| p.name.as_str());
                        let title = match language.get() {
                            Lang::En => format!(
                                "cut {} of {total}: part {} “{name}”, contour {}{} — pierce at ({:.2}, {:.2})",
                                k + 1,
                                s.contour.part + 1,
                                s.contour.contour,
                                if s.contour.contour == 0 { " (outer)" } else { "" },
                                s.pierce_point.x,
                                s.pierce_point.y
                            ),
                            Lang::Ru => format!(
                                "рез {} из {total}: деталь {} «{name}», контур {}{} — врезка в ({:.2}, {:.2})",
                                k + 1,
                                s.contour.part + 1,
                                s.contour.contour,
                                if s.contour.contour == 0 { " (внешний)" } else { "" },
                                s.pierce_point.x,
                                s.pierce_point.y
                            ),
                        };
                        view! {
                            <circle class="pierce" cx=s.pierce_point.x cy=s.pierce_point.y r=r>
                                <title>{title}</title>
                            </circle>
                        }
                    })
                    .collect_view(),
            )
        })
    };
    view! {
        {pierces}
    }
}

/// The pierce point of each tool-on path, named on hover.
#[component]
fn PathPierces(extent: Memo<f64>) -> impl IntoView {
    let paths = expect_context::<Shown>().paths;
    let language = use_language();
    let path_pierces = move || {
        let paths = paths.get()?;
        let r = extent.get() / 250.0;
        let total = paths.paths.len();
        Some(
            paths
                .paths
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let title = match language.get() {
                        Lang::En => format!(
                            "path {} of {total}: pierce at ({:.2}, {:.2}), {:.1} mm tool-on, {} spans",
                            k + 1,
                            p.pierce.x,
                            p.pierce.y,
                            p.length(),
                            p.spans.len()
                        ),
                        Lang::Ru => format!(
                            "путь {} из {total}: врезка в ({:.2}, {:.2}), {:.1} мм резки, участков: {}",
                            k + 1,
                            p.pierce.x,
                            p.pierce.y,
                            p.length(),
                            p.spans.len()
                        ),
                    };
                    view! {
                        <circle class="pierce" cx=p.pierce.x cy=p.pierce.y r=r>
                            <title>{title}</title>
                        </circle>
                    }
                })
                .collect_view(),
        )
    };
    view! {
        {path_pierces}
    }
}

/// The start and finish markers.
#[component]
fn EndMarkers(extent: Memo<f64>) -> impl IntoView {
    let Shown { route, paths, .. } = expect_context::<Shown>();
    let language = use_language();
    let ends = move || {
        let (start, finish) = route
            .with(|r| r.as_ref().map(|r| (r.start, r.finish)))
            .or_else(|| paths.with(|p| p.as_ref().map(|p| (p.start, p.finish))))?;
        let r = extent.get() / 100.0;
        let lang = language.get();
        let marker = move |p: Point, class: &'static str, name: &'static str| {
            view! {
                <rect class=class x=p.x - r y=p.y - r width=2.0 * r height=2.0 * r>
                    <title>{format!("{name} ({:.2}, {:.2})", p.x, p.y)}</title>
                </rect>
            }
        };
        Some(view! {
            {marker(start, "start-marker", lang.pick("start", "старт"))}
            {finish.map(|f| marker(f, "finish-marker", lang.pick("finish", "финиш")))}
        })
    };
    view! {
        {ends}
    }
}

/// Up to two kept results' idle moves drawn over the route.
#[component]
fn ComparedRoutes() -> impl IntoView {
    let kept = expect_context::<DocumentState>().kept;
    let language = use_language();
    let compared = move || {
        kept.with(|k| {
            k.iter()
                .filter(|e| e.overlay)
                .take(2)
                .zip(["compare-a", "compare-b"])
                .map(|(e, class)| {
                    view! {
                        <path class=format!("compare {class}") d=e.idle_d.clone()>
                            <title>{format!("{} #{}: {}", language.pick("kept result", "сохранённый результат"), e.id, language.pick(e.label.0, e.label.1))}</title>
                        </path>
                    }
                })
                .collect_view()
        })
    };
    view! {
        <g class="compared">{compared}</g>
    }
}
