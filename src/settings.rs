//! What survives a reload (local storage) and what a link can set (`?sample=…&solver=…&time=…`,
//! or `?file=URL` for a hosted nest): the chosen sample, hosted file or local file name, solver
//! settings (objective included), machine speeds and prices, thermal settings and drawing
//! layers. The address bar follows these (`links.rs`). The theme keeps its own key (see `theme`).

use cutroute_geometry::{KerfSettings, LeadShape, LeadSpec, MachineParameters, Objective, TabSpec};
use cutroute_protocol::{RuleSet, ThermalSettings};
use serde::{Deserialize, Serialize};

/// Local-storage key of [`Settings`].
const STORAGE_KEY: &str = "cutroute.settings";

/// The drawing layers, each toggled by a checkbox.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Layer {
    /// Hatched fill of the parts.
    Hatch,
    /// Chevrons along each contour showing its cutting direction.
    Arrows,
    /// Candidate pierce points of the discrete solvers.
    Candidates,
    /// The chosen pierce points.
    Pierces,
    /// Tool-on moves.
    Cuts,
    /// Tool-off moves.
    Idle,
    /// The position of each contour in the cutting order.
    Order,
    /// Start and finish markers.
    Ends,
    /// CCP's per-contour optimality certificates.
    Certificates,
    /// The temperature field of the heat model at the animation's clock time.
    Heat,
    /// The shop rules' violations.
    Violations,
    /// Lead-ins and lead-outs of the full cutting route.
    Leads,
    /// The kerf offsets (equidistants) the tool centre runs on.
    Equidistants,
    /// Pierce points M and switch-off points M* of the full cutting route.
    PierceRegions,
    /// The outlines of the pierce region G_M and the switch-off region G_M*: each contour's
    /// offsets at d₁ and d₂ on its scrap side.
    Regions,
}

impl Layer {
    /// Every layer, in the order the panel lists them.
    pub const ALL: [Layer; 15] = [
        Layer::Hatch,
        Layer::Arrows,
        Layer::Candidates,
        Layer::Pierces,
        Layer::Cuts,
        Layer::Idle,
        Layer::Order,
        Layer::Ends,
        Layer::Certificates,
        Layer::Heat,
        Layer::Violations,
        Layer::Leads,
        Layer::Equidistants,
        Layer::PierceRegions,
        Layer::Regions,
    ];

    /// Stable short name (element ids, CSS classes).
    pub fn name(self) -> &'static str {
        match self {
            Layer::Hatch => "hatch",
            Layer::Arrows => "arrows",
            Layer::Candidates => "candidates",
            Layer::Pierces => "pierces",
            Layer::Cuts => "cuts",
            Layer::Idle => "idle",
            Layer::Order => "order",
            Layer::Ends => "ends",
            Layer::Certificates => "certificates",
            Layer::Heat => "heat",
            Layer::Violations => "violations",
            Layer::Leads => "leads",
            Layer::Equidistants => "equidistants",
            Layer::PierceRegions => "pierce-regions",
            Layer::Regions => "regions",
        }
    }

    /// What the layer panel shows.
    pub fn label(self, lang: crate::i18n::Lang) -> &'static str {
        let (en, ru) = match self {
            Layer::Hatch => ("Hatched parts", "Штриховка деталей"),
            Layer::Arrows => ("Contour direction", "Направление обхода контуров"),
            Layer::Candidates => ("Candidate pierce points", "Точки врезки-кандидаты"),
            Layer::Pierces => ("Pierce points", "Точки врезки"),
            Layer::Cuts => ("Cut moves", "Рабочий ход (резка)"),
            Layer::Idle => ("Idle moves", "Холостой ход"),
            Layer::Order => ("Cutting order", "Порядок резки"),
            Layer::Ends => ("Start and finish", "Старт и финиш"),
            Layer::Certificates => ("Optimality certificates", "Сертификаты оптимальности"),
            Layer::Heat => ("Heat map", "Тепловая карта"),
            Layer::Violations => ("Rule violations", "Нарушения правил"),
            Layer::Leads => ("Lead-ins and lead-outs", "Подводы и отводы"),
            Layer::Equidistants => ("Equidistants (kerf)", "Эквидистанты (ширина реза)"),
            Layer::PierceRegions => ("Pierce and switch-off points", "Точки врезки и выключения"),
            Layer::Regions => (
                "Pierce and switch-off regions",
                "Области врезки и выключения",
            ),
        };
        lang.pick(en, ru)
    }
}

/// Everything remembered between visits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// The bundled sample shown last (file name under `assets/samples/`).
    pub sample: String,
    /// Name of the last local file opened (it cannot be reopened without the user).
    pub last_file: Option<String>,
    /// Solver short name (`SolverKind::name`).
    pub solver: String,
    /// Time limit, s.
    pub time_limit_s: f64,
    /// Random seed.
    pub seed: u64,
    /// Spacing of candidate pierce points of the discrete solvers, mm.
    pub step_mm: f64,
    /// Layers switched off (everything else is shown).
    pub hidden_layers: Vec<Layer>,
    /// What routes are compared by and what the solvers that weigh routes minimise:
    /// `Objective::name`, "time" or "cost".
    pub objective: String,
    /// The material's heat model, heat weight and shop rules (off by default).
    pub thermal: ThermalSettings,
    /// A nest hosted next to the app or anywhere CORS allows (`?file=URL`), opened instead of
    /// the sample.
    pub file_url: Option<String>,
    /// Machine speeds, pierce time and prices (the stats panel's, and a profile's).
    pub machine: MachineParameters,
    /// The sheet shown of a multi-sheet file, from 0 (`sheet=N` in a link counts from 1, as the
    /// CLI's `--sheet`).
    pub sheet: usize,
    /// The full cutting route: kerf, clearances d₁ and d₂, leads, overcut, tabs (idealised by
    /// default).
    pub kerf: KerfSettings,
}

/// The full-route settings a link carries (query key, getter, setter); lengths in mm. The
/// shapes and tabs have keys of their own (`lead_in`, `lead_out`, `tabs`).
type KerfKey = (
    &'static str,
    fn(&KerfSettings) -> f64,
    fn(&mut KerfSettings, f64),
);

const KERF_KEYS: [KerfKey; 6] = [
    ("kerf", |k| k.kerf, |k, v| k.kerf = v),
    ("d1", |k| k.pierce_clearance, |k, v| k.pierce_clearance = v),
    (
        "d2",
        |k| k.switch_off_clearance,
        |k, v| k.switch_off_clearance = v,
    ),
    (
        "lead_in_length",
        |k| k.lead_in.length,
        |k, v| k.lead_in.length = v,
    ),
    (
        "lead_out_length",
        |k| k.lead_out.length,
        |k, v| k.lead_out.length = v,
    ),
    ("overcut", |k| k.overcut, |k, v| k.overcut = v),
];

/// A lead shape's short name (the CLI's `--lead-in` values).
pub fn shape_name(shape: LeadShape) -> &'static str {
    match shape {
        LeadShape::None => "none",
        LeadShape::Line => "line",
        LeadShape::Arc => "arc",
        LeadShape::LineArc => "line-arc",
    }
}

/// The lead shape of a short name.
pub fn shape_from_name(name: &str) -> Option<LeadShape> {
    [
        LeadShape::None,
        LeadShape::Line,
        LeadShape::Arc,
        LeadShape::LineArc,
    ]
    .into_iter()
    .find(|s| shape_name(*s) == name)
}

/// The page's full-route settings when nothing is set: idealised, with the CLI's default lead
/// lengths ready for when a shape is chosen (5 mm in, 2 mm out).
pub fn default_kerf() -> KerfSettings {
    KerfSettings {
        lead_in: LeadSpec::new(LeadShape::None, 5.0),
        lead_out: LeadSpec::new(LeadShape::None, 2.0),
        tabs: TabSpec::default(),
        ..KerfSettings::default()
    }
}

/// `N:WIDTH` of the CLI's `--tabs`.
pub fn parse_tabs(text: &str) -> Option<TabSpec> {
    let (count, width) = text.split_once(':')?;
    let count: usize = count.trim().parse().ok()?;
    let width: f64 = width.trim().parse().ok()?;
    (count <= 1000 && width.is_finite() && (width > 0.0 || count == 0))
        .then_some(TabSpec { count, width })
}

/// The machine parameters a link carries: (query key, getter, setter).
type MachineKey = (
    &'static str,
    fn(&MachineParameters) -> f64,
    fn(&mut MachineParameters, f64),
);

const MACHINE_KEYS: [MachineKey; 6] = [
    ("idle_speed", |m| m.idle_speed, |m, v| m.idle_speed = v),
    ("cut_speed", |m| m.cut_speed, |m, v| m.cut_speed = v),
    ("pierce_time", |m| m.pierce_time, |m, v| m.pierce_time = v),
    (
        "idle_price",
        |m| m.idle_price_per_metre,
        |m, v| m.idle_price_per_metre = v,
    ),
    (
        "cut_price",
        |m| m.cut_price_per_metre,
        |m, v| m.cut_price_per_metre = v,
    ),
    (
        "pierce_price",
        |m| m.pierce_price,
        |m, v| m.pierce_price = v,
    ),
];

impl Default for Settings {
    fn default() -> Self {
        let params = cutroute_protocol::SolverParams::default();
        Self {
            sample: crate::app::SAMPLES[0].0.to_string(),
            last_file: None,
            solver: cutroute_protocol::SolverKind::NearestNeighbour
                .name()
                .to_string(),
            time_limit_s: params.time_limit_s,
            seed: params.seed,
            step_mm: params.discretisation_step_mm,
            // The heat map costs a field per animation frame: shown when asked for.
            hidden_layers: vec![Layer::Heat],
            objective: params.objective.name().to_string(),
            thermal: params.thermal,
            file_url: None,
            machine: MachineParameters::default(),
            sheet: 0,
            kerf: default_kerf(),
        }
    }
}

impl Settings {
    /// Applies the query of a link: `sample` or `file`, `solver`, `time`, `seed`, `step`,
    /// `objective`, the thermal and machine settings, `hide` (layers); unknown or malformed values
    /// are ignored.
    pub fn with_query(mut self, query: &str) -> Self {
        for pair in query.trim_start_matches('?').split('&') {
            let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
            let value = js_decode(value);
            if let Some((_, _, set)) = MACHINE_KEYS.iter().find(|(k, _, _)| *k == key) {
                // Speeds must be positive; times and prices may be zero.
                let speed = key.ends_with("_speed");
                if let Some(v) = value
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && (*v > 0.0 || (!speed && *v == 0.0)))
                {
                    set(&mut self.machine, v);
                }
                continue;
            }
            if let Some((_, _, set)) = KERF_KEYS.iter().find(|(k, _, _)| *k == key) {
                if let Some(v) = value
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && *v >= 0.0)
                {
                    set(&mut self.kerf, v);
                }
                continue;
            }
            match key {
                "lead_in" => {
                    if let Some(shape) = shape_from_name(&value) {
                        self.kerf.lead_in.shape = shape;
                    }
                }
                "lead_out" => {
                    if let Some(shape) = shape_from_name(&value) {
                        self.kerf.lead_out.shape = shape;
                    }
                }
                "tabs" => {
                    if let Some(tabs) = parse_tabs(&value) {
                        self.kerf.tabs = tabs;
                    }
                }
                "edge_pierce" => self.kerf.edge_pierce = value == "1",
                "kerf_pierce" => self.kerf.kerf_pierce = value == "1",
                "sample" if crate::app::SAMPLES.iter().any(|(f, ..)| *f == value) => {
                    // The address bar follows the page, so a reload brings the query of the
                    // sample shown beside a remembered local file: that keeps the reminder;
                    // a link to another sample forgets it.
                    if value != self.sample {
                        self.last_file = None;
                    }
                    self.sample = value;
                    self.file_url = None;
                }
                "file" if !value.is_empty() => {
                    self.file_url = Some(value);
                    self.last_file = None;
                }
                "sheet" => {
                    if let Some(n) = value.parse::<usize>().ok().filter(|n| *n >= 1) {
                        self.sheet = n - 1;
                    }
                }
                "hide" => {
                    self.hidden_layers = value
                        .split(',')
                        .filter_map(|name| Layer::ALL.into_iter().find(|l| l.name() == name))
                        .collect();
                }
                "solver" if cutroute_protocol::SolverKind::from_name(&value).is_some() => {
                    self.solver = value
                }
                "time" => {
                    if let Some(v) = positive(&value) {
                        self.time_limit_s = v;
                    }
                }
                "step" => {
                    if let Some(v) = positive(&value) {
                        self.step_mm = v;
                    }
                }
                "objective" if objective_from_name(&value).is_some() => self.objective = value,
                "seed" => {
                    if let Ok(v) = value.parse() {
                        self.seed = v;
                    }
                }
                "sigma" => {
                    if let Some(v) = positive(&value) {
                        self.thermal.sigma_mm = v;
                    }
                }
                "tau" => {
                    if let Some(v) = positive(&value) {
                        self.thermal.tau_s = v;
                    }
                }
                "heat_weight" => {
                    if let Some(v) = value
                        .parse::<f64>()
                        .ok()
                        .filter(|v| *v >= 0.0 && v.is_finite())
                    {
                        self.thermal.weight = v;
                    }
                }
                "rules" => {
                    if let Ok(rules) = RuleSet::parse(&value) {
                        self.thermal.rules = rules;
                    }
                }
                "hard" => self.thermal.hard = value == "1",
                _ => {}
            }
        }
        self
    }

    /// The query of a link that reopens this sample (or hosted file) with these solver
    /// settings; the thermal and machine settings only when they differ from the defaults (old
    /// links stay short and the same). Layers are read from a link (`hide=`, as lecture lists
    /// set them) but not written: a link's form is pinned by the e2e tests, and the layers a
    /// viewer switches are their own.
    pub fn query(&self) -> String {
        let opened = match &self.file_url {
            Some(url) => format!("file={}", js_encode(url)),
            None => format!("sample={}", self.sample),
        };
        let mut query = format!(
            "?{opened}&solver={}&time={}&seed={}&step={}&objective={}",
            self.solver, self.time_limit_s, self.seed, self.step_mm, self.objective
        );
        if self.sheet > 0 {
            query.push_str(&format!("&sheet={}", self.sheet + 1));
        }
        let defaults = MachineParameters::default();
        for (key, get, _) in MACHINE_KEYS {
            if get(&self.machine) != get(&defaults) {
                query.push_str(&format!("&{key}={}", get(&self.machine)));
            }
        }
        // The full route only when it is on: idealised links stay as they were.
        let k = &self.kerf;
        if !k.is_idealised() {
            for (key, get, _) in KERF_KEYS {
                query.push_str(&format!("&{key}={}", get(k)));
            }
            query.push_str(&format!(
                "&lead_in={}&lead_out={}&tabs={}:{}",
                shape_name(k.lead_in.shape),
                shape_name(k.lead_out.shape),
                k.tabs.count,
                k.tabs.width
            ));
            if k.edge_pierce {
                query.push_str("&edge_pierce=1");
            }
            if k.kerf_pierce {
                query.push_str("&kerf_pierce=1");
            }
        }
        let t = &self.thermal;
        if *t != ThermalSettings::default() {
            let rules = [
                ("part", t.rules.part),
                ("sheet", t.rules.sheet),
                ("islands", t.rules.islands),
            ]
            .into_iter()
            .filter(|(_, on)| *on)
            .map(|(name, _)| name)
            .collect::<Vec<_>>()
            .join(",");
            query.push_str(&format!(
                "&sigma={}&tau={}&heat_weight={}&rules={rules}&hard={}",
                t.sigma_mm,
                t.tau_s,
                t.weight,
                u8::from(t.hard)
            ));
        }
        query
    }

    /// The remembered settings (defaults when nothing or something unreadable is stored).
    pub fn load() -> Self {
        storage()
            .and_then(|s| s.get_item(STORAGE_KEY).ok().flatten())
            .and_then(|text| serde_json::from_str(&text).ok())
            .unwrap_or_default()
    }

    /// Remember these settings.
    pub fn save(&self) {
        if let (Some(storage), Ok(text)) = (storage(), serde_json::to_string(self)) {
            let _ = storage.set_item(STORAGE_KEY, &text);
        }
    }
}

/// The objective with the given short name (`Objective::name`).
pub fn objective_from_name(name: &str) -> Option<Objective> {
    [Objective::Time, Objective::Cost]
        .into_iter()
        .find(|o| o.name() == name)
}

fn positive(value: &str) -> Option<f64> {
    value
        .parse::<f64>()
        .ok()
        .filter(|v| *v > 0.0 && v.is_finite())
}

/// Percent-decoding of a query value (sample names are plain ASCII; this keeps `%2E` and `+`
/// working when a link was escaped by some other tool).
fn js_decode(value: &str) -> String {
    #[cfg(target_arch = "wasm32")]
    {
        js_sys::decode_uri_component(&value.replace('+', " "))
            .ok()
            .and_then(|s| s.as_string())
            .unwrap_or_else(|| value.to_string())
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        // The same decoding natively, for the tests.
        let bytes = value.replace('+', " ").into_bytes();
        let mut out = Vec::with_capacity(bytes.len());
        let mut i = 0;
        while i < bytes.len() {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            match (bytes[i], hex) {
                (b'%', Some(b)) => {
                    out.push(b);
                    i += 3;
                }
                (b, _) => {
                    out.push(b);
                    i += 1;
                }
            }
        }
        String::from_utf8(out).unwrap_or_else(|_| value.to_string())
    }
}

/// Percent-encoding of a query value (a URL inside a URL).
fn js_encode(value: &str) -> String {
    #[cfg(target_arch = "wasm32")]
    {
        String::from(js_sys::encode_uri_component(value))
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        value
            .bytes()
            .map(|b| match b {
                b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => {
                    (b as char).to_string()
                }
                _ => format!("%{b:02X}"),
            })
            .collect()
    }
}

fn storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok()?
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_sets_sample_and_solver_and_ignores_nonsense() {
        let s =
            Settings::default().with_query("?sample=test1.dbs.json&solver=ccp&time=3&step=-1&x=y");
        assert_eq!(s.sample, "test1.dbs.json");
        assert_eq!(s.solver, "ccp");
        assert_eq!(s.time_limit_s, 3.0);
        assert_eq!(
            s.step_mm,
            Settings::default().step_mm,
            "negative step ignored"
        );
        let unknown = Settings::default().with_query("sample=../../etc/passwd&solver=magic");
        assert_eq!(unknown, Settings::default());
    }

    #[test]
    fn the_link_round_trips() {
        let s = Settings {
            sample: "seven.dbs".into(),
            solver: "exact".into(),
            time_limit_s: 7.5,
            seed: 9,
            step_mm: 20.0,
            objective: "cost".into(),
            ..Settings::default()
        };
        assert_eq!(Settings::default().with_query(&s.query()), s);
        assert_eq!(Settings::default().objective, "time");
        let nonsense = Settings::default().with_query("?objective=speed");
        assert_eq!(nonsense.objective, "time", "unknown objectives are ignored");
        assert_eq!(objective_from_name("cost"), Some(Objective::Cost));
    }

    #[test]
    fn the_full_route_rides_the_link_and_old_links_stay_idealised() {
        let s = Settings {
            sample: "nested.dbs".into(),
            solver: "ccp".into(),
            kerf: KerfSettings {
                kerf: 2.0,
                pierce_clearance: 5.0,
                switch_off_clearance: 1.0,
                lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
                lead_out: LeadSpec::new(LeadShape::LineArc, 2.5),
                overcut: 0.5,
                tabs: TabSpec {
                    count: 3,
                    width: 1.5,
                },
                edge_pierce: true,
                kerf_pierce: true,
            },
            ..Settings::default()
        };
        let query = s.query();
        assert!(query.contains("&kerf=2&d1=5&d2=1"), "{query}");
        assert!(
            query.contains("&lead_in=arc&lead_out=line-arc&tabs=3:1.5"),
            "{query}"
        );
        assert_eq!(Settings::default().with_query(&query), s);
        assert!(!Settings::default().query().contains("kerf"));
        let old = Settings::default().with_query("?sample=seven.dbs&solver=ccp&time=3");
        assert!(old.kerf.is_idealised());
        let nonsense = Settings::default().with_query("?kerf=-1&lead_in=spiral&tabs=two:1");
        assert_eq!(nonsense.kerf, Settings::default().kerf);
    }

    #[test]
    fn thermal_settings_ride_the_link_and_old_links_leave_them_off() {
        let s = Settings {
            sample: "seven.dbs".into(),
            solver: "ccp".into(),
            thermal: ThermalSettings {
                sigma_mm: 40.0,
                tau_s: 90.0,
                weight: 100.0,
                rules: RuleSet {
                    part: true,
                    sheet: false,
                    islands: true,
                },
                hard: true,
            },
            ..Settings::default()
        };
        assert_eq!(Settings::default().with_query(&s.query()), s);
        assert!(!Settings::default().query().contains("sigma"));
        let old = Settings::default().with_query("?sample=seven.dbs&solver=ccp&time=3");
        assert_eq!(old.thermal, ThermalSettings::default());
        let stored: Settings = serde_json::from_str(r#"{"solver":"ccp"}"#).unwrap();
        assert_eq!(stored.thermal, ThermalSettings::default());
        let nonsense = Settings::default().with_query("?sigma=-3&heat_weight=x&rules=heat");
        assert_eq!(nonsense.thermal, ThermalSettings::default());
    }

    #[test]
    fn machine_and_file_ride_the_link_and_layers_are_read() {
        let s = Settings {
            solver: "ccp".into(),
            file_url: Some("https://example.org/nests/a b.dbs".into()),
            machine: MachineParameters {
                cut_speed: 25.0,
                pierce_price: 0.0,
                ..MachineParameters::default()
            },
            ..Settings::default()
        };
        let query = s.query();
        assert!(!query.contains("sample="), "{query}");
        assert!(!query.contains("idle_speed"), "defaults stay out: {query}");
        let back = Settings::default().with_query(&query);
        assert_eq!(back.file_url, s.file_url);
        assert_eq!(back.machine, s.machine);
        assert_eq!(back.solver, "ccp");
        let hidden = Settings::default().with_query("?hide=order,hatch,nonsense");
        assert_eq!(hidden.hidden_layers, vec![Layer::Order, Layer::Hatch]);
        assert!(!hidden.query().contains("hide="));
        let nonsense = Settings::default().with_query("?cut_speed=0&pierce_time=-1&idle_price=x");
        assert_eq!(nonsense.machine, MachineParameters::default());
        let sheet = Settings {
            file_url: Some("p.tfnesting".into()),
            sheet: 1,
            ..Settings::default()
        };
        assert!(sheet.query().contains("&sheet=2"), "{}", sheet.query());
        assert_eq!(Settings::default().with_query(&sheet.query()).sheet, 1);
        assert_eq!(Settings::default().with_query("?sheet=0").sheet, 0);
        let sample = Settings::default().with_query("?file=x.dbs&sample=seven.dbs");
        assert_eq!(sample.file_url, None, "the later of file and sample wins");
    }

    #[test]
    fn a_reload_keeps_the_local_file_reminder_and_another_sample_forgets_it() {
        let stored = Settings {
            sample: "test1.dbs.json".into(),
            last_file: Some("nested.dbs".into()),
            ..Settings::default()
        };
        let reloaded = stored.clone().with_query(&stored.query());
        assert_eq!(reloaded.last_file.as_deref(), Some("nested.dbs"));
        let other = stored.with_query("?sample=seven.dbs");
        assert_eq!(other.last_file, None);
    }
}
