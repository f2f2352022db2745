//! The export menu: files built in the page and handed to the browser as downloads (Blob +
//! object URL). Nest and result formats come from `cutroute-formats`' writers, so our own readers
//! parse them back; the SVG is the current view as drawn.
//!
//! The standalone HTML page comes from `cutroute-formats`' `route_html`, G-code from the
//! `cutroute-gcode` post-processor with the options chosen in the menu (and a preview of the
//! first lines).
//!
//! A route of tool-on paths (segment cutting, AOE) exports as G-code (`path_route_gcode`), as
//! the standalone page (`toolpath_html` of its toolpath, links marked) and as the SVG of the
//! view. RouteManager's result format has one entry per whole contour cut from one pierce, so
//! it cannot say "cut this common edge once, then this piece of that contour": that export is
//! disabled for such routes, with the reason shown next to it.

use cutroute_formats::{
    route_html, toolpath_html, write_dbs, write_geometry_json, write_result_json, HtmlOptions,
    ResultExportOptions, RmResult,
};
use cutroute_gcode::{
    path_route_gcode, route_gcode, ArcOutput, DistanceMode, GcodeOptions, GcodePreset,
};
use cutroute_geometry::{MachineParameters, Nest, PathRoute, Route, Toolpath};
use leptos::prelude::*;
use wasm_bindgen::JsCast;

use crate::i18n::{tr, use_language, Lang};
use crate::state::{DocumentState, MachineSettings, Shown};

/// Styles inlined into an exported SVG so it looks like the view without the page's CSS.
const SVG_STYLE: &str = ".sheet{fill:#e9e6df;stroke:#6b6b70}.part{fill:#c9d6e8;fill-rule:evenodd;stroke:#2b4a73}\
.idle{fill:none;stroke:#d55e00;stroke-dasharray:6 4}.cut{fill:none;stroke:#0072b2}\
.arrows{fill:none;stroke:#2b4a73}.pierce{fill:#009e73}.candidates{fill:none;stroke:#888;stroke-linecap:round;stroke-width:3px}\
.lead{fill:none;stroke:#e69f00;stroke-width:2.5px;stroke-linecap:round}.equidistants{fill:none;stroke:#cc79a7;stroke-dasharray:3 2}\
.pierce-m{fill:#e69f00}.switch-off-m{fill:none;stroke:#e69f00}\
path,circle{vector-effect:non-scaling-stroke}.done,.tool-head{display:none}";

/// Builds a download from the file stem, the nest and the route (if any).
type Exporter<'a> = &'a dyn Fn(&str, &Nest, Option<&Route>) -> Result<Download, String>;

/// One file to download.
pub struct Download {
    /// Suggested file name.
    pub name: String,
    /// MIME type.
    pub mime: &'static str,
    /// Content.
    pub bytes: Vec<u8>,
}

/// The base of exported file names: the opened file's name without its extensions.
pub fn stem(file_name: &str) -> String {
    let base = file_name.rsplit(['/', '\\']).next().unwrap_or(file_name);
    let stem = base.split('.').next().unwrap_or(base);
    if stem.is_empty() {
        "cutroute".into()
    } else {
        stem.into()
    }
}

/// The route in RouteManager's result format.
pub fn result_json(
    stem: &str,
    nest: &Nest,
    route: &Route,
    machine: &MachineParameters,
) -> Result<Download, String> {
    let options = ResultExportOptions {
        idle_speed: machine.idle_speed,
        ..ResultExportOptions::default()
    };
    let result = RmResult::from_route(nest, route, &options).map_err(|e| e.to_string())?;
    let text = write_result_json(&result).map_err(|e| e.to_string())?;
    Ok(Download {
        name: format!("{stem}.rm-result.json"),
        mime: "application/json",
        bytes: text.into_bytes(),
    })
}

/// The nest as geometry JSON.
pub fn geometry_json(stem: &str, nest: &Nest) -> Result<Download, String> {
    let text = write_geometry_json(nest).map_err(|e| e.to_string())?;
    Ok(Download {
        name: format!("{stem}.dbs.json"),
        mime: "application/json",
        bytes: text.into_bytes(),
    })
}

/// The nest as binary DBS.
pub fn dbs(stem: &str, nest: &Nest) -> Result<Download, String> {
    let bytes = write_dbs(nest).map_err(|e| e.to_string())?;
    Ok(Download {
        name: format!("{stem}.dbs"),
        mime: "application/octet-stream",
        bytes,
    })
}

/// A page that shows and animates the route with no server.
pub fn standalone_html(
    stem: &str,
    nest: &Nest,
    route: &Route,
    machine: &MachineParameters,
) -> Result<Download, String> {
    let options = HtmlOptions {
        title: stem.to_string(),
        machine: *machine,
        ..HtmlOptions::default()
    };
    let text = route_html(nest, route, &options).map_err(|e| e.to_string())?;
    Ok(Download {
        name: format!("{stem}.html"),
        mime: "text/html",
        bytes: text.into_bytes(),
    })
}

/// A page that shows and animates a route of tool-on paths: `toolpath` is its toolpath with the
/// pieces through scrap marked as links.
pub fn standalone_html_of_paths(
    stem: &str,
    nest: &Nest,
    paths: &PathRoute,
    toolpath: &Toolpath,
    machine: &MachineParameters,
) -> Download {
    let options = HtmlOptions {
        title: stem.to_string(),
        machine: *machine,
        ..HtmlOptions::default()
    };
    let total = paths.paths.len();
    let labels: Vec<String> = paths
        .paths
        .iter()
        .enumerate()
        .map(|(k, p)| {
            format!(
                "Path {} of {total}: {} spans, {:.1} mm tool-on",
                k + 1,
                p.spans.len(),
                p.length()
            )
        })
        .collect();
    Download {
        name: format!("{stem}.html"),
        mime: "text/html",
        bytes: toolpath_html(nest, toolpath, &labels, &options).into_bytes(),
    }
}

/// Why the result JSON export is off for routes of tool-on paths.
pub const RESULT_JSON_CANNOT_HOLD_PATHS: &str = "Result JSON is off for this route: RouteManager's format cuts each contour whole from one pierce and cannot hold tool-on paths that cut common edges once or parts of contours. Use G-code or the standalone HTML page.";
/// [`RESULT_JSON_CANNOT_HOLD_PATHS`] in Russian.
pub const RESULT_JSON_CANNOT_HOLD_PATHS_RU: &str = "JSON результата недоступен для этого маршрута: в формате RouteManager каждый контур вырезается целиком от одной врезки, и пути, режущие общие кромки один раз или части контуров, в нём не записать. Используйте G-код или отдельную HTML-страницу.";

/// What the G-code panel lets the user choose: a post-processor preset (the controller's
/// dialect: line numbers, dwell unit, decimals) and, over it, the fields the panel shows.
#[derive(Clone, Debug, PartialEq)]
pub struct GcodeChoice {
    /// The controller's dialect.
    pub preset: GcodePreset,
    /// `G91` instead of `G90`.
    pub incremental: bool,
    /// "ij", "r" or "lines".
    pub arcs: String,
    /// Torch on line.
    pub torch_on: String,
    /// Torch off line.
    pub torch_off: String,
    /// Pierce dwell, s.
    pub dwell_s: f64,
    /// Lines at the start of the program.
    pub header: Vec<String>,
    /// Lines at its end.
    pub footer: Vec<String>,
}

impl GcodeChoice {
    /// The panel filled from `preset` under `machine` (its pierce time is the dwell).
    pub fn of_preset(preset: GcodePreset, machine: &MachineParameters) -> Self {
        let o = preset.options(machine);
        GcodeChoice {
            preset,
            incremental: o.distance_mode == DistanceMode::Incremental,
            arcs: match o.arcs {
                ArcOutput::Radius => "r",
                ArcOutput::Lines { .. } => "lines",
                ArcOutput::CentreOffsets => "ij",
            }
            .into(),
            torch_on: o.torch_on,
            torch_off: o.torch_off,
            dwell_s: o.pierce_dwell_s,
            header: o.header,
            footer: o.footer,
        }
    }

    /// The post-processor's options for this choice under `machine`'s feed: the preset's, with
    /// the panel's fields over them.
    pub fn options(&self, machine: &MachineParameters) -> GcodeOptions {
        GcodeOptions {
            distance_mode: if self.incremental {
                DistanceMode::Incremental
            } else {
                DistanceMode::Absolute
            },
            arcs: match self.arcs.as_str() {
                "r" => ArcOutput::Radius,
                "lines" => ArcOutput::Lines { tolerance_mm: 0.01 },
                _ => ArcOutput::CentreOffsets,
            },
            torch_on: self.torch_on.clone(),
            torch_off: self.torch_off.clone(),
            pierce_dwell_s: self.dwell_s,
            header: self.header.clone(),
            footer: self.footer.clone(),
            ..self.preset.options(machine)
        }
    }
}

/// The route (of whole contours, or of tool-on paths when `paths` is given) as a G-code program.
pub fn gcode(
    stem: &str,
    nest: &Nest,
    route: Option<&Route>,
    paths: Option<&PathRoute>,
    options: &GcodeOptions,
) -> Result<Download, String> {
    let text = match (paths, route) {
        (Some(paths), _) => path_route_gcode(paths, options),
        (None, Some(route)) => route_gcode(nest, route, options),
        (None, None) => return Err("no route yet".into()),
    }
    .map_err(|e| e.to_string())?;
    Ok(Download {
        name: format!("{stem}.nc"),
        mime: "text/plain",
        bytes: text.into_bytes(),
    })
}

/// The SVG element with id `svg_id` as a standalone document, view box as currently shown.
pub fn current_view_svg(stem: &str, svg_id: &str) -> Result<Download, String> {
    let element = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id(svg_id))
        .ok_or("the drawing is not on the page")?;
    let markup = element.outer_html();
    // Insert the style right after the opening tag.
    let open_end = markup.find('>').ok_or("the drawing has no markup")? + 1;
    let mut text = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    text.push_str(&markup[..open_end]);
    text.push_str("<style>");
    text.push_str(SVG_STYLE);
    text.push_str("</style>");
    text.push_str(&markup[open_end..]);
    Ok(Download {
        name: format!("{stem}.svg"),
        mime: "image/svg+xml",
        bytes: text.into_bytes(),
    })
}

/// Hands a file to the browser's download machinery.
pub fn save(download: &Download) -> Result<(), String> {
    let js = |e: wasm_bindgen::JsValue| format!("{e:?}");
    let parts = js_sys::Array::new();
    parts.push(&js_sys::Uint8Array::from(download.bytes.as_slice()));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(download.mime);
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(js)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(js)?;
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let anchor: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(js)?
        .dyn_into()
        .map_err(|_| "not an anchor".to_string())?;
    anchor.set_href(&url);
    anchor.set_download(&download.name);
    anchor.click();
    // The click has started the download; the URL can go once the browser has read it.
    set_timeout(
        move || {
            let _ = web_sys::Url::revoke_object_url(&url);
        },
        std::time::Duration::from_secs(30),
    );
    Ok(())
}

/// A saved file's name, or why the export failed (in English: the writers' words).
type ExportOutcome = Result<String, String>;

/// What the export menu exports (the nest and route shown) and what it said last.
#[derive(Clone, Copy)]
struct Exports {
    file_name: Signal<Option<String>>,
    nest: Signal<Option<Nest>>,
    route: Signal<Option<Route>>,
    paths: Signal<Option<PathRoute>>,
    toolpath: Signal<Option<Toolpath>>,
    machine: RwSignal<MachineParameters>,
    /// The G-code panel's choice, shared with the machine profiles (`profiles.rs`).
    choice: RwSignal<GcodeChoice>,
    /// The last file saved, or why the export failed.
    message: RwSignal<Option<ExportOutcome>>,
    /// The first lines of the G-code.
    preview: RwSignal<String>,
}

impl Exports {
    /// The shown nest and route, from context.
    fn new() -> Self {
        let shown = expect_context::<Shown>();
        let document = expect_context::<DocumentState>();
        let machine = expect_context::<MachineSettings>();
        Self {
            file_name: Signal::derive(move || document.file_name()),
            nest: shown.nest,
            route: shown.route,
            paths: shown.paths,
            toolpath: shown.toolpath,
            machine: machine.machine,
            choice: machine.gcode,
            message: RwSignal::new(None),
            preview: RwSignal::new(String::new()),
        }
    }

    fn stem(&self) -> String {
        stem(&self.file_name.get_untracked().unwrap_or_default())
    }

    /// Saves what `make` writes of the nest and route.
    fn run(&self, make: Exporter) {
        let Some(nest) = self.nest.get_untracked() else {
            return;
        };
        let route = self.route.get_untracked();
        let outcome = make(&self.stem(), &nest, route.as_ref()).and_then(|d| {
            save(&d)?;
            Ok(d.name)
        });
        self.message.set(Some(outcome));
    }

    fn no_nest(&self) -> bool {
        self.nest.with(Option::is_none)
    }

    fn no_route(&self) -> bool {
        self.route.with(Option::is_none) && self.paths.with(Option::is_none)
    }

    fn is_paths(&self) -> bool {
        self.paths.with(Option::is_some)
    }

    /// The G-code program of the route shown, as the panel sets it.
    fn gcode(&self) -> Result<Download, String> {
        let nest = self.nest.get_untracked().ok_or("no nest")?;
        let route = self.route.get_untracked();
        let paths = self.paths.get_untracked();
        let choice = self.choice;
        let options = self
            .machine
            .with_untracked(|m| choice.with_untracked(|c| c.options(m)));
        gcode(
            &self.stem(),
            &nest,
            route.as_ref(),
            paths.as_ref(),
            &options,
        )
    }

    fn show_preview(&self, lang: Lang) {
        match self.gcode() {
            Ok(d) => self.preview.set(
                String::from_utf8_lossy(&d.bytes)
                    .lines()
                    .take(PREVIEW_LINES)
                    .collect::<Vec<_>>()
                    .join("\n"),
            ),
            Err(e) => self
                .preview
                .set(format!("{}: {e}", lang.pick("no G-code", "G-кода нет"))),
        }
    }

    /// Saves the G-code program, previewing it.
    fn save_gcode(&self, lang: Lang) {
        self.show_preview(lang);
        let outcome = self.gcode().and_then(|d| {
            save(&d)?;
            Ok(d.name)
        });
        self.message.set(Some(outcome));
    }
}

/// The export menu for the nest and route shown.
#[component]
pub fn ExportMenu() -> impl IntoView {
    let language = use_language();
    let exports = Exports::new();
    view! {
        <details class="export">
            <summary>{tr("Export", "Экспорт")}</summary>
            <FileExportButtons exports=exports />
            {move || {
                exports.is_paths()
                    .then(|| view! { <p id="export-result-note" class="note">{tr(RESULT_JSON_CANNOT_HOLD_PATHS, RESULT_JSON_CANNOT_HOLD_PATHS_RU)}</p> })
            }}
            <GcodeExport exports=exports />
            <p id="export-status" class="muted" aria-live="polite">
                {move || exports.message.get().map(|outcome| match (outcome, language.get()) {
                    (Ok(name), Lang::En) => format!("saved {name}"),
                    (Ok(name), Lang::Ru) => format!("сохранено: {name}"),
                    (Err(e), Lang::En) => format!("export failed: {e}"),
                    (Err(e), Lang::Ru) => format!("экспорт не удался: {e}"),
                })}
            </p>
        </details>
    }
}

/// The buttons that save the route or the nest as a file.
#[component]
fn FileExportButtons(exports: Exports) -> impl IntoView {
    let language = use_language();
    let Exports {
        route,
        paths,
        toolpath,
        machine,
        ..
    } = exports;
    let no_nest = move || exports.no_nest();
    view! {
        <div class="export-buttons" role="group" aria-label=tr("Export", "Экспорт")>
            <button
                id="export-result"
                title=move || {
                    if exports.is_paths() {
                        language.pick(RESULT_JSON_CANNOT_HOLD_PATHS, RESULT_JSON_CANNOT_HOLD_PATHS_RU)
                    } else {
                        language.pick(
                            "The route in RouteManager's result format (rm-result.json)",
                            "Маршрут в формате результата RouteManager (rm-result.json)",
                        )
                    }
                }
                disabled=move || route.with(Option::is_none)
                on:click=move |_| {
                    exports.run(&|stem, nest, route| {
                        let route = route.ok_or("no route yet")?;
                        machine.with_untracked(|m| result_json(stem, nest, route, m))
                    })
                }
            >
                {tr("Result JSON", "JSON результата")}
            </button>
            <button
                id="export-geometry"
                title=tr("The nest as geometry JSON (dbs.json)", "Раскрой в JSON геометрии (dbs.json)")
                disabled=no_nest
                on:click=move |_| exports.run(&|stem, nest, _| geometry_json(stem, nest))
            >
                {tr("Geometry JSON", "JSON геометрии")}
            </button>
            <button
                id="export-dbs"
                title=tr("The nest as binary DBS", "Раскрой в двоичном формате DBS")
                disabled=no_nest
                on:click=move |_| exports.run(&|stem, nest, _| dbs(stem, nest))
            >
                "DBS"
            </button>
            <button
                id="export-svg"
                title=tr("The drawing as shown (current zoom and layers)", "Чертёж как на экране (текущий масштаб и слои)")
                disabled=no_nest
                on:click=move |_| exports.run(&|stem, _, _| current_view_svg(stem, "nest-view"))
            >
                {tr("SVG of the view", "SVG вида")}
            </button>
            <button
                id="export-html"
                title=tr(
                    "A single HTML file that shows and animates the route, no server needed",
                    "Один HTML-файл, который показывает и анимирует маршрут, без сервера",
                )
                disabled=move || exports.no_route()
                on:click=move |_| {
                    exports.run(&|stem, nest, route| {
                        if let (Some(p), Some(t)) = (paths.get_untracked(), toolpath.get_untracked()) {
                            return Ok(machine.with_untracked(|m| standalone_html_of_paths(stem, nest, &p, &t, m)));
                        }
                        let route = route.ok_or("no route yet")?;
                        machine.with_untracked(|m| standalone_html(stem, nest, route, m))
                    })
                }
            >
                {tr("Standalone HTML", "Отдельная HTML-страница")}
            </button>
        </div>
    }
}

/// The G-code panel: dialect, format, preview and save.
#[component]
fn GcodeExport(exports: Exports) -> impl IntoView {
    let language = use_language();
    let Exports {
        choice, machine, ..
    } = exports;
    let no_route = move || exports.no_route();
    view! {
        <fieldset class="gcode">
            <legend>{tr("G-code", "G-код")}</legend>
            <crate::profiles::PresetPicker choice=choice machine=machine />
            <GcodeFormatFields choice=choice />
            <crate::profiles::HeaderFooterFields choice=choice />
            <button
                id="gcode-preview-button"
                disabled=no_route
                on:click=move |_| exports.show_preview(language.get_untracked())
            >
                {tr("Preview", "Просмотр")}
            </button>
            <button
                id="export-gcode"
                disabled=no_route
                on:click=move |_| exports.save_gcode(language.get_untracked())
            >
                {tr("G-code", "G-код")}
            </button>
            <pre id="gcode-preview" aria-label=tr("First lines of the G-code", "Первые строки G-кода")>{move || exports.preview.get()}</pre>
        </fieldset>
    }
}

/// How the program writes coordinates and arcs, switches the torch and dwells on a pierce.
#[component]
fn GcodeFormatFields(choice: RwSignal<GcodeChoice>) -> impl IntoView {
    let text_field = move |id: &'static str,
                           label: (&'static str, &'static str),
                           tip: (&'static str, &'static str),
                           get: fn(&GcodeChoice) -> String,
                           set: fn(&mut GcodeChoice, String)| {
        view! {
            <label title=tr(tip.0, tip.1)>
                {tr(label.0, label.1)}
                <input
                    id=id
                    type="text"
                    size="8"
                    prop:value=move || choice.with(get)
                    on:change=move |ev| {
                        let v = event_target_value(&ev);
                        choice.update(|c| set(c, v));
                    }
                />
            </label>
        }
    };
    view! {
        <GcodeFormatPickers choice=choice />
        {text_field(
            "gcode-torch-on",
            ("Torch on ", "Включение резака "),
            ("Line that switches the torch on", "Строка включения резака"),
            |c| c.torch_on.clone(),
            |c, v| c.torch_on = v,
        )}
        {text_field(
            "gcode-torch-off",
            ("Torch off ", "Выключение резака "),
            ("Line that switches the torch off", "Строка выключения резака"),
            |c| c.torch_off.clone(),
            |c, v| c.torch_off = v,
        )}
        <label title=tr(
            "Dwell after the torch is switched on (G04), seconds",
            "Выдержка после включения резака (G04), секунды",
        )>
            {tr("Pierce dwell, s ", "Выдержка на врезку, с ")}
            <input
                id="gcode-dwell"
                type="number"
                min="0"
                step="any"
                prop:value=move || choice.with(|c| c.dwell_s.to_string())
                on:change=move |ev| {
                    if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                        if v >= 0.0 && v.is_finite() {
                            choice.update(|c| c.dwell_s = v);
                        }
                    }
                }
            />
        </label>
    }
}

/// Absolute or incremental coordinates, and how arcs are written.
#[component]
fn GcodeFormatPickers(choice: RwSignal<GcodeChoice>) -> impl IntoView {
    view! {
        <label title=tr(
            "G90: positions; G91: increments from the previous point",
            "G90: абсолютные координаты; G91: приращения от предыдущей точки",
        )>
            {tr("Coordinates ", "Координаты ")}
            <select
                id="gcode-distance"
                prop:value=move || if choice.with(|c| c.incremental) { "incremental" } else { "absolute" }
                on:change=move |ev| {
                    let incremental = event_target_value(&ev) == "incremental";
                    choice.update(|c| c.incremental = incremental);
                }
            >
                <option value="absolute">{tr("absolute (G90)", "абсолютные (G90)")}</option>
                <option value="incremental">{tr("incremental (G91)", "в приращениях (G91)")}</option>
            </select>
        </label>
        <label title=tr("How arcs are written", "Как записываются дуги")>
            {tr("Arcs ", "Дуги ")}
            <select
                id="gcode-arcs"
                prop:value=move || choice.with(|c| c.arcs.clone())
                on:change=move |ev| {
                    let arcs = event_target_value(&ev);
                    choice.update(|c| c.arcs = arcs);
                }
            >
                <option value="ij">{tr("G02/G03 with I, J", "G02/G03 с I, J")}</option>
                <option value="r">{tr("G02/G03 with R", "G02/G03 с R")}</option>
                <option value="lines">{tr("G01 chords only", "только хорды G01")}</option>
            </select>
        </label>
    }
}

/// Lines of G-code shown in the preview.
const PREVIEW_LINES: usize = 12;

#[cfg(test)]
mod tests {
    use super::{stem, GcodeChoice};
    use cutroute_gcode::GcodePreset;
    use cutroute_geometry::MachineParameters;

    #[test]
    fn stems_drop_folders_and_every_extension() {
        assert_eq!(stem("E1X_6_01.dbs.json"), "E1X_6_01");
        assert_eq!(stem("C:\\nests\\seven.dbs"), "seven");
        assert_eq!(stem(""), "cutroute");
    }

    #[test]
    fn a_preset_untouched_writes_exactly_the_preset() {
        let machine = MachineParameters::default();
        for preset in GcodePreset::ALL {
            let choice = GcodeChoice::of_preset(preset, &machine);
            assert_eq!(
                choice.options(&machine),
                preset.options(&machine),
                "{preset}"
            );
        }
    }
}
