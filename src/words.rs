//! The page's words for what the engine reports as data: a job's phase, the solvers' names, the
//! reader's errors. The engine's `Display` texts are the English words (the CLI prints them);
//! the Russian ones are built here from the same typed values.

use cutroute_protocol::{
    CcpStage, Ensemble, KerfNote, KerfSource, OpenError, OpenErrorKind, Phase, SolverKind,
    SourceLocation, ThermalNote,
};

use crate::i18n::Lang;

/// A job's phase in the page's language.
pub fn phase_text(lang: Lang, phase: &Phase) -> String {
    match lang {
        Lang::En => phase.to_string(),
        Lang::Ru => phase_ru(phase),
    }
}

fn ccp_stage_ru(stage: CcpStage) -> &'static str {
    match stage {
        CcpStage::Start => "начало",
        CcpStage::Relaxing => "релаксация точек врезки",
        CcpStage::LocalSearch => "локальный поиск",
        CcpStage::Shaking => "встряска (VNS)",
        CcpStage::Done => "готово",
    }
}

fn ensemble_ru(ensemble: Ensemble) -> &'static str {
    match ensemble {
        Ensemble::Standard => "стандартный",
        Ensemble::Chains => "цепочки",
        Ensemble::Junctions => "стыки",
    }
}

fn phase_ru(phase: &Phase) -> String {
    match phase {
        Phase::Starting => "запуск".into(),
        Phase::Done => "готово".into(),
        Phase::Cancelled => "отменено".into(),
        Phase::Bound => "нижняя оценка".into(),
        Phase::Ccp(stage) => ccp_stage_ru(*stage).into(),
        Phase::ChainCcp(stage) => format!("CCP-Relax: {}", ccp_stage_ru(*stage)),
        Phase::ChainJoining => "резка цепочками: соединение близких контуров".into(),
        Phase::Chained {
            saved,
            pierces,
            chains,
            cost_before,
            cost_after,
        } => format!(
            "цепочки: сэкономлено {saved} из {pierces} врезок, цепочек {chains}, стоимость \
             {cost_before:.2} → {cost_after:.2}"
        ),
        Phase::ChainFailed { error } => {
            format!("резка цепочками не удалась: {error}; оставлен маршрут CCP")
        }
        Phase::BuildingMatrix { rows_done, rows } => {
            format!("построение модели: {rows_done} из {rows} строк матрицы стоимостей")
        }
        Phase::BuildingHeuristic => "построение модели: эвристика".into(),
        Phase::BuildingExact => "построение модели: точный поиск".into(),
        Phase::Alns { iterations } => format!("ALNS · итераций {iterations}"),
        Phase::ExactLayer { layer, states } => format!("слой {layer} · состояний {states}"),
        Phase::ProvenOptimal => "оптимальность доказана".into(),
        Phase::BuildTimedOut => {
            "остановлено: лимит времени истёк во время построения модели".into()
        }
        Phase::Stopped { reason: None } => "остановлено".into(),
        Phase::Stopped {
            reason: Some(reason),
        } => format!("остановлено: {reason}"),
        Phase::SegmentsCcp => "резка сегментами: CCP-Relax задаёт порядки".into(),
        Phase::SegmentsBuilding {
            ensemble: Some(ensemble),
        } => format!(
            "резка сегментами: построение ансамбля «{}»",
            ensemble_ru(*ensemble)
        ),
        Phase::SegmentsBuilding { ensemble: None } => {
            "резка сегментами: построение ансамблей".into()
        }
        Phase::SegmentsSearch {
            ensemble,
            segments,
            shakes,
        } => format!(
            "резка сегментами: ансамбль «{}» (сегментов {segments}, встрясок {shakes})",
            ensemble_ru(*ensemble)
        ),
        Phase::SegmentsDone { best } => format!(
            "резка сегментами: готово, лучший — {}",
            best.map_or("CCP", ensemble_ru)
        ),
        Phase::SegmentsFailed { error } => format!("резка сегментами не удалась: {error}"),
        Phase::SegmentsNoRoute => {
            "резка сегментами: ни один ансамбль не дал допустимого маршрута".into()
        }
        Phase::CommonEdgeGraph => "совмещённые резы: построение графа раскроя".into(),
        Phase::CommonEdgeOrdering => "совмещённые резы: упорядочение компонент".into(),
        Phase::CommonEdgeBound => "совмещённые резы: нижняя оценка по раскрою".into(),
        Phase::CommonEdgeDone { chains, components } => {
            format!("совмещённые резы: цепочек {chains} в компонентах: {components}")
        }
        Phase::CommonEdgeFailed { error } => format!("совмещённые резы не удались: {error}"),
        Phase::Thermal { base, note } => match note {
            ThermalNote::RulesEnforced => {
                format!("{} · тепловые правила соблюдены", phase_ru(base))
            }
            ThermalNote::Relaxed => format!(
                "{} · точки врезки уточнены по холостому ходу + W·H",
                phase_ru(base)
            ),
            ThermalNote::RepairFailed { error } => format!(
                "{} · исправить нарушения правил не удалось ({error}); маршрут оставлен",
                phase_ru(base)
            ),
            ThermalNote::RulesEnforcedOnWholeContours => format!(
                "{} · правила соблюдены резкой целых контуров (стандартная резка)",
                phase_ru(base)
            ),
            ThermalNote::RulesNotChecked => format!(
                "{} · правила не проверены: проверка не уложилась бы в лимит времени",
                phase_ru(base)
            ),
        },
        Phase::Kerf { base, note } => match note {
            KerfNote::Leads {
                source: KerfSource::PierceCurves,
            } => format!(
                "{} · подводы оптимизированы по кривым врезки",
                phase_ru(base)
            ),
            KerfNote::Leads {
                source: KerfSource::FullRoute,
            } => format!(
                "{} · подводы выбраны среди кандидатов модели полного маршрута",
                phase_ru(base)
            ),
            KerfNote::Leads {
                source: KerfSource::Idealised,
            } => format!(
                "{} · подводы добавлены к идеализированному порядку",
                phase_ru(base)
            ),
            KerfNote::Leads {
                source: KerfSource::Chains { links_broken },
            } => format!(
                "{} · подводы на концах цепочек, перемычек заменено врезками: {links_broken}",
                phase_ru(base)
            ),
            KerfNote::Leads {
                source: KerfSource::Paths,
            } => format!(
                "{} · подводы на концах путей, резка по эквидистантам",
                phase_ru(base)
            ),
            // The contours by number, not the engine's English reasons.
            KerfNote::NoRoom { contours, .. } => format!(
                "{} · нет места для подводов у контуров ({}): {}",
                phase_ru(base),
                contours.len(),
                contours
                    .iter()
                    .map(|(part, contour)| format!("деталь {} контур {contour}", part + 1))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        },
    }
}

/// A solver's name in the page's language.
pub fn solver_label(lang: Lang, kind: SolverKind) -> &'static str {
    match lang {
        Lang::En => kind.label(),
        Lang::Ru => match kind {
            SolverKind::NearestNeighbour => "Ближайший сосед (базовый)",
            SolverKind::Ccp => "Непрерывная задача: CCP-Relax",
            SolverKind::Heuristic => "Дискретная задача: эвристика (ALNS)",
            SolverKind::Exact => "Дискретная задача: точно, с нижней оценкой",
            SolverKind::Chain => "Резка цепочками (CCP-Relax + цепочки)",
            SolverKind::Sccp => "Резка сегментами (SCCP, общие кромки один раз)",
            SolverKind::Gsccp => "Обобщённая резка сегментами (GSCCP)",
            SolverKind::Aoe => "Совмещённые резы: AOE-цепочки",
        },
    }
}

/// Why a job failed, kept as data so the label follows the language.
#[derive(Clone, Debug, PartialEq)]
pub enum JobFailure {
    /// The exact PCGTSP search proved that no tour exists.
    NoTourExists { solver: &'static str },
    /// The PCGTSP solver found no tour within its time.
    NoTourFound { solver: &'static str, seconds: f64 },
    /// The worker died during the job.
    WorkerStopped,
    /// The engine refused the job (its English words).
    Engine(String),
    /// Kerf and leads are on, and the nest's parts sit closer than the kerf (the pairs).
    PartsTooClose(cutroute_geometry::PartsTooClose),
    /// Kerf and leads are on, and the solver has no full-route model.
    NoKerfModel { solver: &'static str },
}

/// How many pairs the page names before it counts the rest (as the engine's message does).
const PAIRS_NAMED: usize = 8;

/// The refusal of a nest whose parts sit closer than the kerf, in Russian: each pair by part
/// (from 1) and contour, as the phase names contours without room.
fn parts_too_close_ru(refusal: &cutroute_geometry::PartsTooClose) -> String {
    let named =
        |r: cutroute_geometry::ContourRef| format!("деталь {} контур {}", r.part + 1, r.contour);
    let mut pairs: Vec<String> = refusal
        .pairs
        .iter()
        .take(PAIRS_NAMED)
        .map(|p| {
            let gap = if p.on_one_another {
                "совпадают".to_string()
            } else if p.gap < 5e-4 {
                "касаются".to_string()
            } else {
                format!("в {:.3} мм друг от друга", p.gap)
            };
            format!(
                "{} и {} {gap} около ({:.3}, {:.3})",
                named(p.contour),
                named(p.other),
                p.at.x,
                p.at.y
            )
        })
        .collect();
    if refusal.pairs.len() > PAIRS_NAMED {
        pairs.push(format!("и ещё {}", refusal.pairs.len() - PAIRS_NAMED));
    }
    format!(
        "детали ближе друг к другу, чем ширина реза {} мм: рез по эквидистанте задел бы соседнюю \
         деталь; пар контуров: {}: {}",
        refusal.kerf,
        refusal.pairs.len(),
        pairs.join("; ")
    )
}

impl JobFailure {
    /// The failure in the page's language.
    pub fn text(&self, lang: Lang) -> String {
        match (self, lang) {
            (JobFailure::NoKerfModel { solver }, Lang::En) => format!(
                "the {solver} solver does not cut with kerf and leads yet (nearest, ccp, \
                 heuristic and chain do): choose one of those, or set the kerf and leads to none"
            ),
            (JobFailure::NoKerfModel { solver }, Lang::Ru) => format!(
                "решатель {solver} пока не строит маршрут с шириной реза и подводами (это \
                 умеют nearest, ccp, heuristic и chain): выберите один из них или отключите \
                 ширину реза и подводы"
            ),
            (JobFailure::NoTourExists { solver }, Lang::En) => {
                format!("the {solver} solver proved that the instance has no feasible tour")
            }
            (JobFailure::NoTourExists { solver }, Lang::Ru) => {
                format!("решатель {solver} доказал, что допустимого обхода нет")
            }
            (JobFailure::NoTourFound { solver, seconds }, Lang::En) => format!(
                "the {solver} solver found no feasible tour in {seconds:.1} s (not a proof that \
                 none exists)"
            ),
            (JobFailure::NoTourFound { solver, seconds }, Lang::Ru) => format!(
                "решатель {solver} не нашёл допустимого обхода за {seconds:.1} с (это не \
                 доказательство, что его нет)"
            ),
            (JobFailure::WorkerStopped, Lang::En) => "the solver stopped unexpectedly".into(),
            (JobFailure::WorkerStopped, Lang::Ru) => "решатель неожиданно остановился".into(),
            (JobFailure::PartsTooClose(refusal), Lang::En) => refusal.to_string(),
            (JobFailure::PartsTooClose(refusal), Lang::Ru) => parts_too_close_ru(refusal),
            (JobFailure::Engine(message), Lang::En) => message.clone(),
            (JobFailure::Engine(message), Lang::Ru) => format!("задача не запущена: {message}"),
        }
    }
}

/// An error the page shows over the drawing: a file the engine could not open, or one the page
/// could not fetch or read, or an open lost with a worker that died.
#[derive(Clone, Debug, PartialEq)]
pub enum PageError {
    /// The engine's located error.
    Open(OpenError),
    /// A bundled sample could not be fetched.
    Fetch { url: String, message: String },
    /// A local file could not be read.
    Read { file_name: String, message: String },
    /// The worker died while opening these files.
    WorkerDiedOpening {
        files: String,
        reason: crate::worker_client::DeathReason,
    },
}

impl PageError {
    /// The error in the page's language.
    pub fn text(&self, lang: Lang) -> String {
        match (self, lang) {
            (PageError::Open(error), Lang::En) => error.message.clone(),
            (PageError::Open(error), Lang::Ru) => open_error_ru(error),
            (PageError::Fetch { url, message }, Lang::En) => format!("{url}: {message}"),
            (PageError::Fetch { url, message }, Lang::Ru) => {
                format!("{url}: не удалось загрузить ({message})")
            }
            (PageError::Read { file_name, message }, Lang::En) => {
                format!("{file_name}: {message}")
            }
            (PageError::Read { file_name, message }, Lang::Ru) => {
                format!("{file_name}: не удалось прочитать файл ({message})")
            }
            (PageError::WorkerDiedOpening { files, reason }, Lang::En) => format!(
                "{files}: the solver stopped unexpectedly while opening this ({}); it was \
                 restarted and the document shown before is still open",
                reason.text(lang)
            ),
            (PageError::WorkerDiedOpening { files, reason }, Lang::Ru) => format!(
                "{files}: решатель неожиданно остановился при открытии ({}); он \
                 перезапущен, прежний документ остаётся открытым",
                reason.text(lang)
            ),
        }
    }
}

/// A place in a file, in Russian.
pub fn location_ru(location: &SourceLocation) -> String {
    match location {
        SourceLocation::Line { line, column: None } => format!("строка {line}"),
        SourceLocation::Line {
            line,
            column: Some(column),
        } => format!("строка {line}, столбец {column}"),
        SourceLocation::Byte { offset } => format!("байт {offset}"),
        SourceLocation::JsonPath { path } => format!("элемент JSON {path}"),
    }
}

/// The name of a format (as the engine names it) in the page's language.
pub fn format_text(lang: Lang, format: &str) -> &str {
    match lang {
        Lang::En => format,
        Lang::Ru => format_ru(format),
    }
}

/// The name of a format or a kind of file, in Russian.
fn format_ru(format: &str) -> &str {
    match format {
        "DBS binary" => "DBS, двоичный",
        "geometry JSON" => "JSON геометрии",
        "task JSON" => "JSON задания",
        "result JSON" => "JSON результата",
        "T-FLEX nesting" => "раскрой T-FLEX",
        "PCGTSP instance" => "задача PCGTSP",
        "PCGLNS result" => "результат PCGLNS",
        "G-code" => "G-код",
        "nests" => "раскрои",
        "task files" => "задания на резку",
        "PCGTSP instances" => "задачи PCGTSP",
        "PCGLNS results" => "результаты PCGLNS",
        other => other,
    }
}

/// A reader's located error in Russian: what happened and where are worded here; the reader's
/// own finding (`detail`) follows in its English words, as the CLI prints it.
fn open_error_ru(error: &OpenError) -> String {
    let f = &error.file_name;
    let place = error
        .location
        .as_ref()
        .map(|l| format!("{}: ", location_ru(l)))
        .unwrap_or_default();
    let detail = &error.detail;
    match &error.kind {
        OpenErrorKind::Unreadable { format } => format!(
            "{f} ({}): файл не читается: {place}{detail}",
            format_ru(format)
        ),
        OpenErrorKind::TaskWithoutGeometry => format!(
            "{f}: в задании на резку нет геометрии; сначала откройте его раскрой (JSON \
             геометрии или DBS)"
        ),
        OpenErrorKind::UnknownFormat => format!(
            "{f}: формат не распознан с байта 0 (ожидались DBS, JSON геометрии, задания или \
             результата, DXF, SVG, T-FLEX, задача или результат PCGLNS/PCGTSPLIB, G-код)"
        ),
        OpenErrorKind::MalformedJson => {
            format!("{f} (JSON): ошибка в JSON: {place}{detail}")
        }
        OpenErrorKind::NothingToCut => {
            format!("{f}: в файле нет замкнутых контуров для резки")
        }
        OpenErrorKind::Gcode => format!("{f} (G-код): программа не читается: {place}{detail}"),
        OpenErrorKind::GcodeCutsNothing => {
            format!("{f} (G-код): программа не вырезает ни одного замкнутого контура")
        }
        OpenErrorKind::TourAlone => format!(
            "{f}: в результате PCGLNS только обход; откройте его вместе с задачей \
             (.pcglns/.pcgtsp) или с раскроем и JSON задания"
        ),
        OpenErrorKind::TwoOfAKind { kind, second } => format!(
            "{f} и {second} — оба «{}»: открывайте по одному такому файлу",
            format_ru(kind)
        ),
        OpenErrorKind::NotCombinable => format!(
            "{f}: не сочетается с остальными файлами (ожидались раскрой, JSON задания, задача \
             PCGTSP или результат PCGLNS)"
        ),
        OpenErrorKind::InfeasibleTour { against } => {
            format!("{f}: обход недопустим для {against}: {detail} (узлы и кластеры считаются с 0)")
        }
        OpenErrorKind::CostMismatch {
            against,
            reported,
            checked,
        } => format!(
            "{f}: в файле стоимость {reported}, а проверка обхода на {against} даёт {checked:.3}"
        ),
        OpenErrorKind::InstanceNotOfTask {
            nodes,
            task,
            points,
        } => format!(
            "{f}: {nodes} узлов, а в {task} {points} точек врезки и старт: файлы не \
             соответствуют друг другу"
        ),
        OpenErrorKind::TaskNotOnNest { index, x, y, nest } => format!(
            "{f}: контур {index} (точка врезки ({x:.3}, {y:.3})) не лежит ни на одном контуре \
             {nest}: файлы не соответствуют друг другу"
        ),
        OpenErrorKind::InvalidRoute { nest } => {
            format!("{f}: как маршрут резки раскроя {nest} обход недопустим: {detail}")
        }
        OpenErrorKind::NoSuchSheet { sheet, count } => {
            format!("{f}: листа {sheet} нет (листов в файле: {count}; листы считаются с 1)")
        }
        OpenErrorKind::TaskWithoutNest => format!(
            "{f}: в задании на резку нет геометрии; откройте его вместе с раскроем (JSON \
             геометрии или DBS)"
        ),
    }
}

/// A post-processor preset as the picker shows it: in English its id and the library's
/// description, in Russian what it is for.
pub fn preset_text(lang: Lang, preset: cutroute_gcode::GcodePreset) -> String {
    use cutroute_gcode::GcodePreset::*;
    match lang {
        Lang::En => format!("{} — {}", preset.name(), preset.description()),
        Lang::Ru => match preset {
            Generic => "Общий: M03/M05, G04 P в секундах, дуги I/J (по умолчанию в cutroute)",
            GrblLaser => "GRBL 1.1, лазерный режим: M04 S1000 (мощность по скорости), G04 P в секундах",
            QtPlasmac => "LinuxCNC QtPlasmaC: M03 $0 S1 / M05 $0",
            Mach3Plasma => "Mach3, плазма: M03/M05, G91.1, номера строк",
            Fanuc => "В стиле Fanuc: G04 P в миллисекундах, номера строк N10",
            Kometa2p32m => {
                "Газовая резка «Комета», ЧПУ 2П32М: G91, M71/M74 T1, без выдержки (мм, см. документацию)"
            }
        }
        .to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{ContourRef, KerfOverlap, PartsTooClose, Point};

    fn refusal(pairs: usize) -> PartsTooClose {
        PartsTooClose {
            kerf: 2.0,
            pairs: (0..pairs)
                .map(|i| KerfOverlap {
                    contour: ContourRef {
                        part: i,
                        contour: 0,
                    },
                    other: ContourRef {
                        part: i + 1,
                        contour: 0,
                    },
                    distance: 0.0,
                    required: 1.0,
                    gap: if i == 0 { 0.0 } else { 0.25 },
                    at: Point::new(501.0, 0.0),
                    on_one_another: false,
                })
                .collect(),
        }
    }

    /// The refusal of parts closer than the kerf names every pair by part and contour in
    /// Russian, with no English word; in English it is the engine's message.
    #[test]
    fn parts_too_close_is_worded_in_each_language() {
        let failure = JobFailure::PartsTooClose(refusal(10));
        assert_eq!(failure.text(Lang::En), refusal(10).to_string());
        let ru = failure.text(Lang::Ru);
        assert!(
            ru.contains("ширина реза 2 мм") && ru.contains("пар контуров: 10"),
            "{ru}"
        );
        assert!(
            ru.contains("деталь 1 контур 0 и деталь 2 контур 0 касаются около (501.000, 0.000)"),
            "{ru}"
        );
        assert!(
            ru.contains("деталь 2 контур 0 и деталь 3 контур 0 в 0.250 мм"),
            "{ru}"
        );
        assert!(ru.ends_with("и ещё 2"), "{ru}");
        assert!(!ru.chars().any(|c| c.is_ascii_alphabetic()), "{ru}");
    }

    /// Contours lying on one another (a part in a hole of its own shape) are said to coincide,
    /// not to touch, in each language.
    #[test]
    fn contours_on_one_another_are_said_to_coincide() {
        let mut coincident = refusal(1);
        coincident.pairs[0].on_one_another = true;
        let failure = JobFailure::PartsTooClose(coincident);
        let en = failure.text(Lang::En);
        assert!(
            en.contains("part 1 contour 0 and part 2 contour 0 lie on one another near (501.000"),
            "{en}"
        );
        let ru = failure.text(Lang::Ru);
        assert!(
            ru.contains("деталь 1 контур 0 и деталь 2 контур 0 совпадают около (501.000, 0.000)"),
            "{ru}"
        );
        assert!(!ru.contains("касаются"), "{ru}");
    }
}
