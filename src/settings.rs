//! What survives a reload (local storage) and what a link can set (`?sample=…&solver=…&time=…`):
//! the chosen sample or file name, solver settings (objective included) and drawing layers. The theme keeps its own
//! key (see `theme`).

use cutroute_geometry::Objective;
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
}

impl Layer {
    /// Every layer, in the order the panel lists them.
    pub const ALL: [Layer; 11] = [
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
}

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
        }
    }
}

impl Settings {
    /// Applies the query of a link: `sample`, `solver`, `time`, `seed`, `step`, `objective`; unknown or
    /// malformed values are ignored.
    pub fn with_query(mut self, query: &str) -> Self {
        for pair in query.trim_start_matches('?').split('&') {
            let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
            let value = js_decode(value);
            match key {
                "sample" if crate::app::SAMPLES.iter().any(|(f, ..)| *f == value) => {
                    self.sample = value;
                    self.last_file = None;
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

    /// The query of a link that reopens this sample with these solver settings; the thermal
    /// ones only when they differ from the defaults (old links stay short and the same).
    pub fn query(&self) -> String {
        let mut query = format!(
            "?sample={}&solver={}&time={}&seed={}&step={}&objective={}",
            self.sample, self.solver, self.time_limit_s, self.seed, self.step_mm, self.objective
        );
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
        value.to_string()
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
}
