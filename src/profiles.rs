//! Machine profiles in the page: the machine's speeds, pierce time and prices with its G-code
//! dialect (preset, header and footer lines) kept under a name, remembered in local storage,
//! exported and imported as JSON in exactly the CLI's `--profile` format
//! (`cutroute_protocol::MachineProfile`), so a profile made in the page drives the CLI and the
//! other way round. Also the export menu's preset picker and header and footer fields.

use cutroute_gcode::GcodePreset;
use cutroute_geometry::{KerfSettings, MachineParameters};
use cutroute_protocol::MachineProfile;
use leptos::prelude::*;

use crate::export::{save, Download, GcodeChoice};
use crate::i18n::{tr, use_language, Lang};
use crate::state::MachineSettings;

/// Local-storage key of the saved profiles.
const STORAGE_KEY: &str = "cutroute.profiles";

/// The saved profiles (none when nothing or something unreadable is stored).
pub fn stored() -> Vec<MachineProfile> {
    storage()
        .and_then(|s| s.get_item(STORAGE_KEY).ok().flatten())
        .and_then(|text| serde_json::from_str(&text).ok())
        .unwrap_or_default()
}

fn store(profiles: &[MachineProfile]) {
    if let (Some(storage), Ok(text)) = (storage(), serde_json::to_string(profiles)) {
        let _ = storage.set_item(STORAGE_KEY, &text);
    }
}

fn storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok()?
}

/// The profile of the page's machine, full-route settings and G-code choice. Header and
/// footer are written only when they differ from the preset's (the CLI then takes the
/// preset's own); the kerf only when the route is not idealised.
pub fn profile_of(
    name: &str,
    machine: &MachineParameters,
    kerf: &KerfSettings,
    choice: &GcodeChoice,
) -> MachineProfile {
    let preset = choice.preset.options(machine);
    MachineProfile {
        kerf: (!kerf.is_idealised()).then_some(*kerf),
        name: name.to_string(),
        machine: *machine,
        gcode_preset: Some(choice.preset.name().to_string()),
        gcode_header: (choice.header != preset.header).then(|| choice.header.clone()),
        gcode_footer: (choice.footer != preset.footer).then(|| choice.footer.clone()),
    }
}

/// The machine, full-route settings (the page's idealised ones when the profile has none) and
/// G-code choice a profile sets, after the same checks as the CLI's.
pub fn from_profile(
    profile: &MachineProfile,
) -> Result<(MachineParameters, KerfSettings, GcodeChoice), String> {
    profile.check().map_err(|e| e.to_string())?;
    let preset = match &profile.gcode_preset {
        Some(name) => name.parse::<GcodePreset>().map_err(|e| e.to_string())?,
        None => GcodePreset::Generic,
    };
    let mut choice = GcodeChoice::of_preset(preset, &profile.machine);
    if let Some(header) = &profile.gcode_header {
        choice.header = header.clone();
    }
    if let Some(footer) = &profile.gcode_footer {
        choice.footer = footer.clone();
    }
    let kerf = profile.kerf.unwrap_or_else(crate::settings::default_kerf);
    Ok((profile.machine, kerf, choice))
}

/// Reads a profile file as the CLI does (unknown fields refused, numbers checked).
pub fn parse_profile(text: &str) -> Result<MachineProfile, String> {
    // A byte-order mark, as Windows editors write, is not part of the JSON.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let profile: MachineProfile = serde_json::from_str(text).map_err(|e| e.to_string())?;
    from_profile(&profile)?;
    Ok(profile)
}

/// The stored profiles, the one named in the panel, and what the panel said last.
#[derive(Clone, Copy)]
struct Profiles {
    all: RwSignal<Vec<MachineProfile>>,
    /// The profile's name in the panel.
    name: RwSignal<String>,
    status: RwSignal<String>,
    machine: MachineSettings,
}

impl Profiles {
    /// The profiles stored in the browser; the first is named.
    fn new(machine: MachineSettings) -> Self {
        let all = RwSignal::new(stored());
        let name = RwSignal::new(
            all.with_untracked(|p| p.first().map(|p| p.name.clone()).unwrap_or_default()),
        );
        Self {
            all,
            name,
            status: RwSignal::new(String::new()),
            machine,
        }
    }

    /// Sets the machine, kerf and G-code settings from `profile`; false (and said) when it
    /// holds values the page refuses.
    fn apply(&self, profile: &MachineProfile) -> bool {
        match from_profile(profile) {
            Ok((m, k, c)) => {
                self.machine.machine.set(m);
                self.machine.kerf.set(k);
                self.machine.gcode.set(c);
                self.name.set(profile.name.clone());
                true
            }
            Err(e) => {
                self.status.set(e);
                false
            }
        }
    }

    /// The panel's settings as a profile of the name given.
    fn current(&self) -> MachineProfile {
        let n = self.name.get_untracked();
        let n = if n.trim().is_empty() {
            "machine".to_string()
        } else {
            n.trim().to_string()
        };
        let MachineSettings {
            machine,
            kerf,
            gcode,
            ..
        } = self.machine;
        machine.with_untracked(|m| {
            kerf.with_untracked(|k| gcode.with_untracked(|c| profile_of(&n, m, k, c)))
        })
    }

    /// Stores `profile`, replacing one of its name.
    fn keep(&self, profile: MachineProfile) {
        self.all.update(|all| {
            all.retain(|p| p.name != profile.name);
            all.push(profile);
            all.sort_by(|a, b| a.name.cmp(&b.name));
        });
        self.all.with_untracked(|all| store(all));
    }

    fn save(&self, lang: Lang) {
        let profile = self.current();
        let saved = profile.name.clone();
        self.keep(profile);
        self.name.set(saved.clone());
        self.status
            .set(format!("{} {saved}", lang.pick("saved", "сохранён")));
    }

    fn delete(&self, lang: Lang) {
        let n = self.name.get_untracked();
        self.all.update(|all| all.retain(|p| p.name != n));
        self.all.with_untracked(|all| store(all));
        self.status
            .set(format!("{} {n}", lang.pick("deleted", "удалён")));
    }

    /// Downloads the panel's settings as a profile file.
    fn export(&self, lang: Lang) {
        let profile = self.current();
        let outcome = serde_json::to_string_pretty(&profile)
            .map_err(|e| e.to_string())
            .and_then(|text| {
                let download = Download {
                    name: format!("{}.profile.json", crate::export::stem(&profile.name)),
                    mime: "application/json",
                    bytes: text.into_bytes(),
                };
                save(&download)?;
                Ok(download.name)
            });
        self.status.set(match outcome {
            Ok(file) => format!("{} {file}", lang.pick("saved", "сохранён")),
            Err(e) => e,
        });
    }

    /// Reads a profile file: applied, then stored.
    fn import(&self, file: web_sys::File, lang: Lang) {
        let this = *self;
        leptos::task::spawn_local(async move {
            let text = crate::app::read_file(&file)
                .await
                .and_then(|bytes| String::from_utf8(bytes).map_err(|e| e.to_string()));
            match text.and_then(|t| parse_profile(&t)) {
                Ok(profile) => {
                    if this.apply(&profile) {
                        this.status.set(format!(
                            "{} {}",
                            lang.pick("imported", "загружен"),
                            profile.name
                        ));
                        this.keep(profile);
                    }
                }
                Err(e) => this.status.set(format!("{}: {e}", file.name())),
            }
        });
    }
}

/// The panel of named machine profiles, beside the machine parameters.
#[component]
pub fn ProfilesPanel() -> impl IntoView {
    let profiles = Profiles::new(expect_context::<MachineSettings>());
    let Profiles {
        all, name, status, ..
    } = profiles;
    view! {
        <details id="profiles" class="profiles">
            <summary>{tr("Machine profiles", "Профили станков")}</summary>
            <label class="param">
                <span>{tr("Profile", "Профиль")}</span>
                <select
                    id="profile-select"
                    prop:value=move || name.get()
                    on:change=move |ev| {
                        let chosen = event_target_value(&ev);
                        if let Some(p) = all.with_untracked(|all| all.iter().find(|p| p.name == chosen).cloned()) {
                            profiles.apply(&p);
                        }
                    }
                >
                    <option value="">"—"</option>
                    {move || {
                        all
                            .get()
                            .into_iter()
                            .map(|p| view! { <option value=p.name.clone()>{p.name.clone()}</option> })
                            .collect_view()
                    }}
                </select>
            </label>
            <label class="param">
                <span>{tr("Name", "Название")}</span>
                <input
                    id="profile-name"
                    type="text"
                    prop:value=move || name.get()
                    on:change=move |ev| name.set(event_target_value(&ev))
                />
            </label>
            <ProfileButtons profiles=profiles />
            <p id="profile-status" class="muted" role="status" aria-live="polite">
                {move || status.get()}
            </p>
        </details>
    }
}

/// Save, delete, export and import a profile.
#[component]
fn ProfileButtons(profiles: Profiles) -> impl IntoView {
    let language = use_language();
    let import = move |ev: leptos::ev::Event| {
        let input: web_sys::HtmlInputElement = event_target(&ev);
        let Some(file) = input.files().and_then(|f| f.item(0)) else {
            return;
        };
        input.set_value("");
        profiles.import(file, language.get_untracked());
    };
    view! {
        <div class="profile-buttons">
            <button
                id="profile-save"
                type="button"
                title=tr(
                    "Remember the machine parameters and G-code settings under this name",
                    "Запомнить параметры станка и настройки G-кода под этим названием",
                )
                on:click=move |_| profiles.save(language.get_untracked())
            >
                {tr("Save", "Сохранить")}
            </button>
            <button id="profile-delete" type="button" on:click=move |_| profiles.delete(language.get_untracked())>
                {tr("Delete", "Удалить")}
            </button>
            <button
                id="profile-export"
                type="button"
                title=tr(
                    "Download the profile as JSON (the CLI reads it: cutroute solve --profile FILE)",
                    "Скачать профиль в JSON (его читает и программа командной строки cutroute, ключ --profile)",
                )
                on:click=move |_| profiles.export(language.get_untracked())
            >
                {tr("Export JSON", "Экспорт JSON")}
            </button>
            <label class="file-button">
                {tr("Import JSON… ", "Импорт JSON… ")}
                <input
                    id="profile-import"
                    type="file"
                    accept=".json,application/json"
                    on:change=import
                />
            </label>
        </div>
    }
}

/// The export menu's post-processor preset: choosing one fills the panel's fields from it.
#[component]
pub fn PresetPicker(
    choice: RwSignal<GcodeChoice>,
    machine: RwSignal<MachineParameters>,
) -> impl IntoView {
    view! {
        <label title=tr(
            "The controller's G-code dialect; the fields below start from it",
            "Диалект G-кода стойки ЧПУ; поля ниже заполняются по нему",
        )>
            {tr("Post-processor ", "Постпроцессор ")}
            <select
                id="gcode-preset"
                prop:value=move || choice.with(|c| c.preset.name())
                on:change=move |ev| {
                    if let Ok(preset) = event_target_value(&ev).parse::<GcodePreset>() {
                        choice.set(machine.with_untracked(|m| GcodeChoice::of_preset(preset, m)));
                    }
                }
            >
                {GcodePreset::ALL
                    .into_iter()
                    .map(|p| {
                        let language = crate::i18n::use_language();
                        let text = move || crate::words::preset_text(language.get(), p);
                        view! {
                            <option value=p.name() title=text>
                                {text}
                            </option>
                        }
                    })
                    .collect_view()}
            </select>
        </label>
    }
}

/// Header and footer lines of the program, one per line.
#[component]
pub fn HeaderFooterFields(choice: RwSignal<GcodeChoice>) -> impl IntoView {
    let lines = |text: String| -> Vec<String> {
        text.lines()
            .map(str::trim_end)
            .filter(|l| !l.is_empty())
            .map(str::to_string)
            .collect()
    };
    view! {
        <label class="gcode-lines">
            {tr("Header", "Начало программы")}
            <textarea
                id="gcode-header"
                rows="3"
                prop:value=move || choice.with(|c| c.header.join("\n"))
                on:change=move |ev| {
                    let v = lines(event_target_value(&ev));
                    choice.update(|c| c.header = v);
                }
            />
        </label>
        <label class="gcode-lines">
            {tr("Footer", "Конец программы")}
            <textarea
                id="gcode-footer"
                rows="3"
                prop:value=move || choice.with(|c| c.footer.join("\n"))
                on:change=move |ev| {
                    let v = lines(event_target_value(&ev));
                    choice.update(|c| c.footer = v);
                }
            />
        </label>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_profile_round_trips_through_the_page_and_the_cli_format() {
        let machine = MachineParameters {
            cut_speed: 25.0,
            pierce_time: 0.8,
            ..MachineParameters::default()
        };
        let mut choice = GcodeChoice::of_preset(GcodePreset::QtPlasmac, &machine);
        choice.footer = vec!["M30".into(), "%".into()];
        let kerf = KerfSettings {
            kerf: 2.0,
            pierce_clearance: 5.0,
            switch_off_clearance: 1.0,
            lead_in: cutroute_geometry::LeadSpec::new(cutroute_geometry::LeadShape::Arc, 8.0),
            ..crate::settings::default_kerf()
        };
        let profile = profile_of("Plasma 3", &machine, &kerf, &choice);
        assert_eq!(
            profile.gcode_header, None,
            "the preset's header stays the preset's"
        );
        let text = serde_json::to_string_pretty(&profile).unwrap();
        let back = parse_profile(&text).unwrap();
        let (m, k, c) = from_profile(&back).unwrap();
        assert_eq!(m, machine);
        assert_eq!(k, kerf);
        let idealised = profile_of("Laser", &machine, &crate::settings::default_kerf(), &choice);
        assert!(
            !serde_json::to_string(&idealised).unwrap().contains("kerf"),
            "idealised profiles stay as they were"
        );
        assert_eq!(c, choice);
        assert!(parse_profile(r#"{"name": "x", "machine": {}}"#).is_err());
        let bad = MachineProfile {
            gcode_preset: Some("haas".into()),
            ..MachineProfile::new("x", machine)
        };
        assert!(from_profile(&bad).is_err());
    }
}
