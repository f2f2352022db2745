//! The toolbar: what to open (a sample, local files, another sheet, a lecture), exports, the
//! theme, the language and presentation mode.

use leptos::prelude::*;

use crate::app::SAMPLES;
use crate::export::ExportMenu;
use crate::i18n::tr;
use crate::state::{DocumentState, Page, ViewSettings};

/// The page's header.
#[component]
pub fn Toolbar(initial_sample: String, lecture_url: String) -> impl IntoView {
    let page = expect_context::<Page>();
    let document = page.document;
    view! {
        <header class="toolbar">
            <h1>"cutroute"</h1>
            <SamplePicker initial_sample=initial_sample />
            <OpenFilesButton />
            <crate::sheets::SheetPicker
                document=document.document
                open=Callback::new(move |sheet| document.open_sheet(sheet))
            />
            <ExportMenu />
            <crate::gallery::LectureGallery
                list_url=lecture_url
                pick=Callback::new(move |(url, query): (String, String)| page.pick_lecture(url, &query))
            />
            <crate::theme::ThemePicker />
            <crate::i18n::LanguagePicker />
            <PresentButton />
        </header>
    }
}

/// The bundled samples.
#[component]
fn SamplePicker(initial_sample: String) -> impl IntoView {
    let document = expect_context::<DocumentState>();
    view! {
        <label>
            {tr("Sample ", "Пример ")}
            <select
                id="sample"
                aria-label=tr("Sample nest", "Пример раскроя")
                prop:value=move || document.sample.get()
                on:change=move |ev| {
                    document.last_file.set(None);
                    document.open_sample(event_target_value(&ev));
                }
            >
                {SAMPLES
                    .iter()
                    .map(|(file, en, ru)| {
                        view! {
                            <option value=*file selected=*file == initial_sample>
                                {tr(en, ru)}
                            </option>
                        }
                    })
                    .collect_view()}
            </select>
        </label>
    }
}

/// Local files, one or several together (a nest with its task and result).
#[component]
fn OpenFilesButton() -> impl IntoView {
    let document = expect_context::<DocumentState>();
    view! {
        <label class="file-button">
            {tr("Open files… ", "Открыть файлы… ")}
            <input
                id="file-input"
                type="file"
                multiple
                aria-label=tr("Open nest or instance files", "Открыть файлы раскроя или задачи")
                on:change=move |ev| {
                    let input: web_sys::HtmlInputElement = event_target(&ev);
                    if let Some(files) = input.files() {
                        document.open_files(files);
                    }
                    input.set_value("");
                }
            />
        </label>
    }
}

/// Presentation mode on and off (also the F key).
#[component]
fn PresentButton() -> impl IntoView {
    let settings = expect_context::<ViewSettings>();
    view! {
        <button
            id="present"
            aria-pressed=move || settings.presentation.get().to_string()
            title=tr(
                "Presentation mode: large fonts, full screen (key F)",
                "Режим показа: крупный шрифт, полный экран (клавиша F)",
            )
            on:click=move |_| settings.toggle_presentation()
        >
            {tr("Present", "Показ")}
        </button>
    }
}
