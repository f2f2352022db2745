//! The sheet picker of multi-sheet files (T-FLEX nesting projects): the worker opens the chosen
//! sheet of the same file (`ToWorker::OpenSheet`, `cutroute_engine::open_sheet`), as the CLI's
//! `--sheet N` does.

use cutroute_protocol::Document;
use leptos::prelude::*;

use crate::i18n::tr;

/// A select of the open file's sheets, shown when it has more than one; `open` gets the chosen
/// sheet's index (from 0).
#[component]
pub fn SheetPicker(document: RwSignal<Option<Document>>, open: Callback<usize>) -> impl IntoView {
    let sheets = move || {
        document.with(|d| {
            d.as_ref()
                .filter(|d| d.sheets.len() > 1)
                .map(|d| (d.sheets.clone(), d.sheet))
        })
    };
    move || {
        sheets().map(|(names, current)| {
            view! {
                <label title=tr(
                    "Which sheet of the nesting project is shown and solved",
                    "Какой лист проекта раскроя показан и решается",
                )>
                    {tr("Sheet ", "Лист ")}
                    <select
                        id="sheet"
                        prop:value=current.to_string()
                        on:change=move |ev| {
                            if let Ok(k) = event_target_value(&ev).parse::<usize>() {
                                open.run(k);
                            }
                        }
                    >
                        {names
                            .into_iter()
                            .enumerate()
                            .map(|(k, name)| {
                                view! {
                                    <option value=k.to_string() selected=k == current>
                                        {format!("{} — {name}", k + 1)}
                                    </option>
                                }
                            })
                            .collect_view()}
                    </select>
                </label>
            }
        })
    }
}
