//! Lead-ins and lead-outs: how the tool gets from its pierce point M onto the equidistant, and
//! off it again to the switch-off point M* (dissertation §2.3, constraints (1.5)–(1.6)).
//!
//! A lead lies on the scrap side of its contour (outside an outer contour, inside a hole),
//! which after orientation is always the left of the cut direction. Shapes ([`LeadShape`]):
//! a straight line at an angle to the normal, an arc tangent to the equidistant at the entry,
//! or a straight line followed by that arc.
//!
//! [`LeadFitter`] fits leads automatically: where the asked lead would come closer than kerf/2
//! to a contour, leave the scrap, or put M closer than d₁ (M* closer than d₂) to a part, it
//! shortens the lead, turns a line, falls back from an arc to a line, moves the entry along
//! the contour, and in a hole tries a pierce at the hole's centre. A contour where nothing fits
//! is reported ([`LeadError::NoFit`]), never dropped.
//!
//! ```
//! use cutroute_geometry::{Contour, ContourRef, KerfSettings, LeadFitter, LeadShape, LeadSpec,
//!     Nest, Part, Point};
//! let square = Contour::new(vec![
//!     cutroute_geometry::Vertex::line(0.0, 0.0),
//!     cutroute_geometry::Vertex::line(0.0, 50.0),
//!     cutroute_geometry::Vertex::line(50.0, 50.0),
//!     cutroute_geometry::Vertex::line(50.0, 0.0),
//! ]);
//! let nest = Nest { sheet: None, parts: vec![Part { name: "p".into(), contours: vec![square] }] };
//! let settings = KerfSettings {
//!     kerf: 2.0,
//!     pierce_clearance: 5.0,
//!     switch_off_clearance: 1.0,
//!     lead_in: LeadSpec::new(LeadShape::Arc, 10.0),
//!     lead_out: LeadSpec::new(LeadShape::Line, 3.0),
//!     overcut: 0.0,
//!     tabs: Default::default(),
//!     edge_pierce: false,
//!     kerf_pierce: false,
//! };
//! let fitter = LeadFitter::new(&nest, settings);
//! let r = ContourRef { part: 0, contour: 0 };
//! let leads = fitter.fit(r, Point::new(-20.0, 25.0)).unwrap();
//! // The entry lies on the equidistant at kerf/2 = 1 from the square, M at least d₁ = 5 from it.
//! assert!((nest.contour(r).unwrap().distance_to(leads.entry) - 1.0).abs() < 1e-9);
//! assert!(nest.contour(r).unwrap().distance_to(leads.pierce) >= 5.0);
//! assert!(fitter.problems(r, &leads).is_empty());
//! ```

use crate::float::Libm;
use std::borrow::Cow;

use rstar::primitives::{GeomWithData, Rectangle};
use rstar::RTree;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::kerf::{equidistant, OffsetError};
use crate::{
    BoundingBox, ContainmentForest, Contour, ContourRef, CutStep, MachineParameters, Nest, Point,
    Route, Span, Vertex,
};

/// The shape of a lead-in or lead-out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LeadShape {
    /// No lead: the tool pierces (or switches off) on the equidistant.
    #[default]
    None,
    /// A straight line, at [`LeadSpec::angle`] from the contour's normal.
    Line,
    /// A circular arc tangent to the equidistant at the entry (exit).
    Arc,
    /// A straight line of [`LeadSpec::length`] continuing the tangent arc of
    /// [`LeadSpec::radius`].
    LineArc,
}

/// The asked shape and size of a lead; the fitter may shrink or turn it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LeadSpec {
    /// The shape.
    pub shape: LeadShape,
    /// Length of the lead (of its straight part for [`LeadShape::LineArc`]), mm.
    pub length: f64,
    /// Angle between a straight lead and the contour's normal, degrees: 0 is perpendicular,
    /// positive leans the lead back along the contour.
    pub angle: f64,
    /// Radius of the arc, mm; 0 means a quarter circle of the lead's length (radius 2L/π).
    pub radius: f64,
}

impl LeadSpec {
    /// A lead of this shape and length, perpendicular for lines, a quarter circle for arcs.
    pub fn new(shape: LeadShape, length: f64) -> LeadSpec {
        LeadSpec {
            shape,
            length,
            angle: 0.0,
            radius: 0.0,
        }
    }

    /// This lead scaled by `factor` (lengths and radius).
    fn scaled(self, factor: f64) -> LeadSpec {
        LeadSpec {
            length: self.length * factor,
            radius: self.radius * factor,
            ..self
        }
    }

    /// How far the lead takes its free end from the equidistant, along the normal, mm.
    pub fn reach(self) -> f64 {
        let (radius, sweep) = self.arc();
        match self.shape {
            LeadShape::None => 0.0,
            LeadShape::Line => self.length * self.angle.to_radians().cos_libm().max(0.0),
            LeadShape::Arc => radius * (1.0 - sweep.cos_libm()),
            LeadShape::LineArc => radius + self.length,
        }
    }

    /// How far behind the entry (against the cut direction) the lead-in's pierce point lies,
    /// mm: the entry for a pierce point over arc length s lies at s + this.
    pub fn lag(self) -> f64 {
        let (radius, sweep) = self.arc();
        match self.shape {
            LeadShape::None => 0.0,
            LeadShape::Line => self.length * self.angle.to_radians().sin_libm(),
            LeadShape::Arc => radius * sweep.sin_libm(),
            LeadShape::LineArc => radius,
        }
    }

    /// The longest path the fitter may lay for this lead (the asked one; its variants are
    /// shorter, or lines of the same length turned): the straight part plus the arc, mm.
    pub fn longest_chain(self) -> f64 {
        let (radius, sweep) = self.arc();
        match self.shape {
            LeadShape::None => 0.0,
            LeadShape::Line => self.length,
            LeadShape::Arc => (radius * sweep).max(self.length),
            LeadShape::LineArc => self.length + radius * sweep,
        }
    }

    /// The arc's radius and sweep (radians).
    fn arc(self) -> (f64, f64) {
        let quarter = std::f64::consts::FRAC_PI_2;
        match self.shape {
            LeadShape::Arc if self.radius > 0.0 => (
                self.radius,
                (self.length / self.radius).min(std::f64::consts::PI),
            ),
            LeadShape::Arc => (self.length / quarter, quarter),
            LeadShape::LineArc if self.radius > 0.0 => (self.radius, quarter),
            LeadShape::LineArc => (self.length / 2.0, quarter),
            _ => (0.0, 0.0),
        }
    }
}

/// Micro-joints (tabs, bridges): `count` uncut gaps of `width` mm in the outer contour of every
/// part, which hold the part in the sheet until it is broken out. The torch switches off at
/// each gap, crosses it and pierces again after it. Holes get none: they fall out as scrap.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TabSpec {
    /// Gaps per part (0: none).
    pub count: usize,
    /// Width of each gap along the cut, mm.
    pub width: f64,
}

/// One micro-joint of a step: the cut stops at arc length `start` of the step's cut (measured
/// from the entry round the equidistant) and starts again at `end`; the head crosses the gap
/// from `from` to `to` with the torch off and pierces at `to`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tab {
    /// Where the gap begins, mm of the cut from the entry.
    pub start: f64,
    /// Where it ends, mm of the cut from the entry.
    pub end: f64,
    /// The point of the equidistant at `start`: the torch switches off here.
    pub from: Point,
    /// The point at `end`: the torch pierces again here.
    pub to: Point,
}

impl Tab {
    /// Width of the gap along the cut, mm.
    pub fn width(&self) -> f64 {
        self.end - self.start
    }
}

/// A corner of an equidistant: where its direction turns by more than this, degrees. A tab over
/// a corner would leave a notch where the part breaks out badly.
const CORNER_DEG: f64 = 20.0;

/// Places `spec.count` tabs on `eq`, the equidistant at `offset` from its contour, for a cut
/// that starts at arc length `entry` of `eq` and runs on `overcut` past it: spread evenly round
/// the cut, each at least its width (and 1 mm) away from every corner and from the cut's start
/// and end (where the lead-in, overcut and lead-out are). A corner is a turn of more than 20°
/// between spans, or an arc of radius at most `offset` (how an outward offset rounds a corner
/// of its contour). A tab that finds no such place within half the spacing of its even
/// position is left out; the step then has fewer tabs.
pub fn place_tabs(eq: &Contour, offset: f64, entry: f64, overcut: f64, spec: TabSpec) -> Vec<Tab> {
    let perimeter = eq.perimeter();
    let width = spec.width;
    if spec.count == 0 || !(width > 0.0) || !(perimeter > 0.0) || !width.is_finite() {
        return Vec::new();
    }
    let margin = width.max(1.0);
    let corners = corner_intervals(eq, offset, entry);
    // No more gaps than the cut has room for (each takes its width and a margin), however
    // many are asked: the count is the caller's, the room is the contour's.
    let room = (perimeter / (width + margin)).floor();
    let count = if room < spec.count as f64 {
        room as usize
    } else {
        spec.count
    };
    let mut tabs: Vec<Tab> = Vec::with_capacity(count);
    let fits = |a: f64, tabs: &[Tab]| {
        a >= overcut + margin
            && a + width <= perimeter - margin
            && corners
                .iter()
                .all(|&(c0, c1)| c1 < a - margin || c0 > a + width + margin)
            && tabs
                .iter()
                .all(|t| a + width + margin < t.start || a > t.end + margin)
    };
    if count == 0 {
        return Vec::new();
    }
    let spacing = perimeter / count as f64;
    const TRIES: usize = 200;
    for k in 0..count {
        let even = spacing * (k as f64 + 0.5) - width / 2.0;
        let found = (0..=TRIES)
            .flat_map(|j| {
                let d = 0.5 * spacing * j as f64 / TRIES as f64;
                [even + d, even - d]
            })
            .find(|&a| fits(a, &tabs));
        if let Some(a) = found {
            let at = |s: f64| frame_at(eq, (entry + s).rem_euclid(perimeter)).0;
            tabs.push(Tab {
                start: a,
                end: a + width,
                from: at(a),
                to: at(a + width),
            });
        }
    }
    tabs.sort_by(|a, b| a.start.total_cmp(&b.start));
    tabs
}

/// The corners of `eq` (see [`place_tabs`]) as arc-length intervals measured from `entry` in
/// the cut direction; a sharp turn is an interval of no length. An interval that wraps past
/// the entry is split in two.
fn corner_intervals(eq: &Contour, offset: f64, entry: f64) -> Vec<(f64, f64)> {
    let perimeter = eq.perimeter();
    let spans: Vec<Span> = eq.spans().collect();
    let n = spans.len();
    let mut at = 0.0;
    let mut out = Vec::new();
    let mut push = |from: f64, to: f64| {
        let a = (from - entry).rem_euclid(perimeter);
        let b = a + (to - from);
        if b > perimeter {
            out.push((a, perimeter));
            out.push((0.0, b - perimeter));
        } else {
            out.push((a, b));
        }
    };
    for k in 0..n {
        let before = spans[(k + n - 1) % n].tangent_at(1.0);
        let after = spans[k].tangent_at(0.0);
        let turn = before.cross(after).atan2_libm(before.dot(after)).abs();
        if turn > CORNER_DEG.to_radians() {
            push(at, at);
        }
        let length = spans[k].length();
        if !spans[k].is_line() && spans[k].radius() <= offset * (1.0 + 1e-9) + 1e-12 {
            push(at, at + length);
        }
        at += length;
    }
    out
}

/// Machine and material settings of the full cutting route. The default is the idealised
/// model (kerf 0, no leads, no clearances, no overcut), under which a route is cut on the
/// contours themselves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct KerfSettings {
    /// Kerf width, mm: the tool centre runs at kerf/2 from the contour.
    pub kerf: f64,
    /// d₁: least distance from every contour to a pierce point, mm.
    pub pierce_clearance: f64,
    /// d₂: least distance from every contour to a switch-off point, mm.
    pub switch_off_clearance: f64,
    /// The lead-in, from M to the entry on the equidistant.
    pub lead_in: LeadSpec,
    /// The lead-out, from the exit to M*.
    pub lead_out: LeadSpec,
    /// How far the cut runs on past the entry before the lead-out, mm.
    pub overcut: f64,
    /// Micro-joints in the outer contour of every part.
    #[serde(default)]
    pub tabs: TabSpec,
    /// Edge piercing: a part's outer contour that lies in the sheet's own scrap (not in a
    /// hole) may be pierced at the sheet's border, where piercing is quicker and deforms
    /// less. Where the border is within [`KerfSettings::edge_reach`] of an entry, the lead-in
    /// is a straight line from the border's nearest point to the entry, used when it keeps
    /// kerf/2 from every contour; its pierce is priced at the machine's edge-pierce time.
    /// Needs a nest with a sheet. Off by default (the idealised and published runs).
    #[serde(default)]
    pub edge_pierce: bool,
    /// Kerf piercing, where the technology allows it: a step may be pierced in the open kerf
    /// of a contour cut earlier in the route, as at an edge ([`LeadFitter::pierce_into_kerfs`];
    /// needs a kerf; priced at the machine's edge-pierce time). Off by default.
    #[serde(default)]
    pub kerf_pierce: bool,
}

impl KerfSettings {
    /// Whether these settings are the idealised model: cut on the contour, pierce on it.
    pub fn is_idealised(&self) -> bool {
        self.kerf == 0.0
            && self.pierce_clearance == 0.0
            && self.switch_off_clearance == 0.0
            && self.lead_in.shape == LeadShape::None
            && self.lead_out.shape == LeadShape::None
            && self.overcut == 0.0
            && self.tabs.count == 0
            && !self.edge_pierce
            && !self.kerf_pierce
    }

    /// Issue #17's plasma settings, the reference of its benchmarks and tests: kerf 2, d₁ 5,
    /// d₂ 1, an 8 mm arc lead-in, a 2 mm line lead-out, nothing else.
    pub fn plasma_reference() -> KerfSettings {
        KerfSettings {
            kerf: 2.0,
            pierce_clearance: 5.0,
            switch_off_clearance: 1.0,
            lead_in: LeadSpec::new(LeadShape::Arc, 8.0),
            lead_out: LeadSpec::new(LeadShape::Line, 2.0),
            ..KerfSettings::default()
        }
    }

    /// Every setting in its range ([`KerfField`]): kerf, overcut, radii and tab widths 0 or
    /// from [`MIN_KERF_LENGTH`], clearances and lengths at most [`MAX_KERF_LENGTH`], a lead
    /// of any shape but none at least [`MIN_KERF_LENGTH`] long, angles within ±89°, at most
    /// [`MAX_TABS`] tabs. NaN and infinities are outside every range. The first setting out
    /// of range is named.
    pub fn check(&self) -> Result<(), KerfRangeError> {
        use KerfField as F;
        let length = |field, zero| KerfRange {
            field,
            zero,
            min: MIN_KERF_LENGTH,
            max: MAX_KERF_LENGTH,
            unit: "mm",
        };
        let upto = |field| KerfRange {
            field,
            zero: true,
            min: 0.0,
            max: MAX_KERF_LENGTH,
            unit: "mm",
        };
        let angle = |field| KerfRange {
            field,
            zero: true,
            min: -89.0,
            max: 89.0,
            unit: "degrees",
        };
        let lead = |spec: LeadSpec, l, a, r| {
            let shaped = spec.shape != LeadShape::None;
            [
                (length(l, !shaped), spec.length),
                (angle(a), spec.angle),
                (length(r, true), spec.radius),
            ]
        };
        let mut table = vec![
            (length(F::Kerf, true), self.kerf),
            (upto(F::PierceClearance), self.pierce_clearance),
            (upto(F::SwitchOffClearance), self.switch_off_clearance),
            (upto(F::Overcut), self.overcut),
        ];
        table.extend(lead(
            self.lead_in,
            F::LeadInLength,
            F::LeadInAngle,
            F::LeadInRadius,
        ));
        table.extend(lead(
            self.lead_out,
            F::LeadOutLength,
            F::LeadOutAngle,
            F::LeadOutRadius,
        ));
        if self.tabs.count > 0 {
            table.push((length(F::TabWidth, false), self.tabs.width));
        }
        for (range, value) in table {
            if !range.holds(value) {
                let zero_refused =
                    matches!(range.field, F::LeadInLength | F::LeadOutLength) && value == 0.0;
                return Err(KerfRangeError {
                    field: range.field,
                    value,
                    range: range.words(),
                    note: if zero_refused {
                        " for a lead (a lead of no length is lead shape none)"
                    } else {
                        ""
                    },
                });
            }
        }
        if self.tabs.count > MAX_TABS {
            return Err(KerfRangeError {
                field: F::TabCount,
                value: self.tabs.count as f64,
                range: format!("from 0 to {MAX_TABS}"),
                note: " per part",
            });
        }
        Ok(())
    }

    /// The longest edge lead-in, mm: the asked lead-in's longest chain plus d₁, as far as the
    /// asked lead and its pierce region would reach from the entry anyway.
    pub fn edge_reach(&self) -> f64 {
        self.lead_in.longest_chain() + self.pierce_clearance
    }
}

/// A setting of [`KerfSettings`] held to a range by [`KerfSettings::check`]: the one table of
/// ranges that the command line's flags, machine profiles and the engine's requests share.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum KerfField {
    /// [`KerfSettings::kerf`].
    Kerf,
    /// [`KerfSettings::pierce_clearance`].
    PierceClearance,
    /// [`KerfSettings::switch_off_clearance`].
    SwitchOffClearance,
    /// The lead-in's [`LeadSpec::length`].
    LeadInLength,
    /// The lead-in's [`LeadSpec::angle`].
    LeadInAngle,
    /// The lead-in's [`LeadSpec::radius`].
    LeadInRadius,
    /// The lead-out's [`LeadSpec::length`].
    LeadOutLength,
    /// The lead-out's [`LeadSpec::angle`].
    LeadOutAngle,
    /// The lead-out's [`LeadSpec::radius`].
    LeadOutRadius,
    /// [`KerfSettings::overcut`].
    Overcut,
    /// [`TabSpec::count`].
    TabCount,
    /// [`TabSpec::width`].
    TabWidth,
}

impl KerfField {
    /// The setting in words, as messages name it.
    pub fn words(self) -> &'static str {
        match self {
            Self::Kerf => "kerf",
            Self::PierceClearance => "pierce clearance",
            Self::SwitchOffClearance => "switch-off clearance",
            Self::LeadInLength => "lead-in length",
            Self::LeadInAngle => "lead-in angle",
            Self::LeadInRadius => "lead-in radius",
            Self::LeadOutLength => "lead-out length",
            Self::LeadOutAngle => "lead-out angle",
            Self::LeadOutRadius => "lead-out radius",
            Self::Overcut => "overcut",
            Self::TabCount => "tab count",
            Self::TabWidth => "tab width",
        }
    }

    /// The command-line flag that sets it (`None`: only a profile does).
    pub fn flag(self) -> Option<&'static str> {
        match self {
            Self::Kerf => Some("--kerf"),
            Self::PierceClearance => Some("--pierce-clearance"),
            Self::SwitchOffClearance => Some("--switch-off-clearance"),
            Self::LeadInLength => Some("--lead-in-length"),
            Self::LeadOutLength => Some("--lead-out-length"),
            Self::Overcut => Some("--overcut"),
            Self::TabCount | Self::TabWidth => Some("--tabs"),
            Self::LeadInAngle | Self::LeadInRadius | Self::LeadOutAngle | Self::LeadOutRadius => {
                None
            }
        }
    }

    /// Its key in a machine profile's JSON.
    pub fn profile_key(self) -> &'static str {
        match self {
            Self::Kerf => "kerf.kerf",
            Self::PierceClearance => "kerf.pierce_clearance",
            Self::SwitchOffClearance => "kerf.switch_off_clearance",
            Self::LeadInLength => "kerf.lead_in.length",
            Self::LeadInAngle => "kerf.lead_in.angle",
            Self::LeadInRadius => "kerf.lead_in.radius",
            Self::LeadOutLength => "kerf.lead_out.length",
            Self::LeadOutAngle => "kerf.lead_out.angle",
            Self::LeadOutRadius => "kerf.lead_out.radius",
            Self::Overcut => "kerf.overcut",
            Self::TabCount => "kerf.tabs.count",
            Self::TabWidth => "kerf.tabs.width",
        }
    }
}

/// The range of one setting: `zero` (off) or from `min` to `max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KerfRange {
    /// The setting.
    pub field: KerfField,
    /// Whether 0 (the setting off) is allowed below `min`.
    pub zero: bool,
    /// The least value other than 0.
    pub min: f64,
    /// The largest value.
    pub max: f64,
    /// The unit the message gives.
    pub unit: &'static str,
}

impl KerfRange {
    /// Whether `value` is in the range.
    pub fn holds(&self, value: f64) -> bool {
        (self.zero && value == 0.0) || (value >= self.min && value <= self.max)
    }

    /// The range in words: "0 or from 0.001 to 100 mm".
    pub fn words(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        if self.zero {
            format!("0 or from {} to {}{unit}", self.min, self.max)
        } else {
            format!("from {} to {}{unit}", self.min, self.max)
        }
    }
}

/// Smallest kerf, lead, radius and tab width other than 0, mm: below it the offsets and leads
/// are below the checkers' tolerances (a kerf of 10⁻³⁰⁰ mm is no kerf, and a route built with
/// it fails its own checks). No machine cuts with less.
pub const MIN_KERF_LENGTH: f64 = 1e-3;

/// Largest length of any kerf setting, mm (a lead or clearance of a metre is a typing error).
pub const MAX_KERF_LENGTH: f64 = 1000.0;

/// Largest number of tabs per part.
pub const MAX_TABS: usize = 1000;

/// Why [`KerfSettings::check`] refuses the settings: one setting outside its range.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("{} {}: must be {range}{}", field.words(), number(*value), note)]
pub struct KerfRangeError {
    /// The setting.
    pub field: KerfField,
    /// Its value.
    pub value: f64,
    /// Its range in words.
    pub range: String,
    /// What else the message says (why 0 is not allowed here), or empty.
    pub note: &'static str,
}

impl KerfRangeError {
    /// The message naming the command-line flag (or the profile key when no flag sets it).
    pub fn for_flag(&self) -> String {
        let name = match self.field {
            KerfField::TabCount => "--tabs count".to_string(),
            KerfField::TabWidth => "--tabs width".to_string(),
            f => f.flag().unwrap_or(f.profile_key()).to_string(),
        };
        self.message(&name)
    }

    /// The message naming the profile key.
    pub fn in_profile(&self) -> String {
        self.message(self.field.profile_key())
    }

    fn message(&self, name: &str) -> String {
        format!(
            "{name} {}: must be {}{}",
            number(self.value),
            self.range,
            self.note
        )
    }
}

/// A value as a message gives it: plain, or in exponent form where plain would run to hundreds
/// of digits (10⁻³⁰⁰, 4·10¹⁸).
fn number(value: f64) -> String {
    let size = value.abs();
    if value != 0.0 && size.is_finite() && !(1e-4..1e9).contains(&size) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// The full-route elements of one step: M, the lead-in, the entry on the equidistant, the
/// cut round the equidistant (and the overcut), the lead-out, M*.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepLeads {
    /// Pierce point M.
    pub pierce: Point,
    /// Where the lead-in meets the equidistant; the cut starts here.
    pub entry: Point,
    /// Lead-in spans as vertices `[x, y, bulge]` from M to the entry (the last vertex is the
    /// entry, bulge 0); just `[entry]` without a lead.
    #[serde(with = "vertex_triples")]
    pub lead_in: Vec<Vertex>,
    /// Lead-out spans from the exit (entry + overcut along the equidistant) to M*.
    #[serde(with = "vertex_triples")]
    pub lead_out: Vec<Vertex>,
    /// Switch-off point M*.
    pub switch_off: Point,
    /// Half the kerf: the distance of the equidistant from the contour, mm.
    pub offset: f64,
    /// How far the cut runs on past the entry, mm.
    #[serde(default)]
    pub overcut: f64,
    /// d₁ the pierce point was placed under (the checker holds the step to it), mm.
    #[serde(default)]
    pub pierce_clearance: f64,
    /// d₂ the switch-off point was placed under, mm.
    #[serde(default)]
    pub switch_off_clearance: f64,
    /// Micro-joints of the cut, in cut order.
    #[serde(default)]
    pub tabs: Vec<Tab>,
    /// M lies on the sheet's border (an edge pierce, see [`KerfSettings::edge_pierce`]): the
    /// checker holds it to the border instead of G_M.
    #[serde(default)]
    pub edge_pierce: bool,
    /// M lies in the open kerf of this contour, cut earlier in the route (a kerf pierce, see
    /// [`LeadFitter::pierce_into_kerfs`]): the checker holds it to that contour's cut
    /// equidistant, outside its tabs, instead of G_M. Priced like an edge pierce.
    #[serde(default)]
    pub kerf_pierce: Option<ContourRef>,
}

/// Spans of a vertex chain (each vertex's bulge shapes the span to the next; the last vertex
/// only ends the chain).
pub fn chain_spans(chain: &[Vertex]) -> impl Iterator<Item = Span> + '_ {
    chain
        .windows(2)
        .map(|w| Span::new(w[0].point, w[1].point, w[0].bulge))
}

impl StepLeads {
    /// The rules these leads were built under (kerf, d₁, d₂; shapes are not rules), which
    /// the route checker holds them to.
    pub fn rules(&self) -> KerfSettings {
        KerfSettings {
            kerf: 2.0 * self.offset,
            pierce_clearance: self.pierce_clearance,
            switch_off_clearance: self.switch_off_clearance,
            overcut: self.overcut,
            ..KerfSettings::default()
        }
    }

    /// Length of the tool-on path of the step: lead-in, the equidistant's perimeter, the
    /// overcut and the lead-out, less the gaps of the tabs, mm.
    pub fn cut_length(&self, equidistant: &Contour) -> f64 {
        self.lead_in_length() + equidistant.perimeter() + self.overcut + self.lead_out_length()
            - self.tab_width()
    }

    /// Total width of the tabs' gaps, mm.
    pub fn tab_width(&self) -> f64 {
        self.tabs.iter().map(Tab::width).sum()
    }

    /// The cut of `equidistant` ([`StepLeads::equidistant_cut`]) split at the tabs: the pieces
    /// the torch cuts between the entry, the gaps and the exit, in order (one piece without
    /// tabs). Pieces shorter than `min_piece` are dropped.
    pub fn equidistant_pieces(&self, equidistant: &Contour, min_piece: f64) -> Vec<Vec<Span>> {
        split_at_tabs(
            self.equidistant_cut(equidistant, 0.0),
            &self.tabs,
            min_piece,
        )
    }

    /// Length of the lead-in, mm.
    pub fn lead_in_length(&self) -> f64 {
        chain_spans(&self.lead_in).map(|s| s.length()).sum()
    }

    /// Length of the lead-out, mm.
    pub fn lead_out_length(&self) -> f64 {
        chain_spans(&self.lead_out).map(|s| s.length()).sum()
    }

    /// The exit point: where the lead-out leaves the equidistant.
    pub fn exit(&self) -> Point {
        self.lead_out.first().map_or(self.entry, |v| v.point)
    }

    /// The cut of `equidistant` for this step: from the entry round to the entry, then the
    /// overcut. Pieces shorter than `min_piece` are dropped.
    pub fn equidistant_cut(&self, equidistant: &Contour, min_piece: f64) -> Vec<Span> {
        let mut cut = opened_at(equidistant, self.entry, min_piece);
        let mut left = self.overcut;
        let round = cut.clone();
        for span in round {
            if !(left > min_piece) {
                break;
            }
            let l = span.length();
            if l <= left {
                cut.push(span);
                left -= l;
            } else {
                cut.push(span.sub_span(0.0, left / l));
                left = 0.0;
            }
        }
        cut
    }
}

/// `cut` (spans from the entry, in cut order) split at `tabs` (arc lengths from the entry):
/// the pieces the torch cuts between the entry, the gaps and the end, in order (one piece
/// without tabs). Pieces shorter than `min_piece` are dropped.
pub(crate) fn split_at_tabs(cut: Vec<Span>, tabs: &[Tab], min_piece: f64) -> Vec<Vec<Span>> {
    let mut pieces = vec![Vec::new()];
    // Cut intervals [from, to] of arc length between the tabs.
    let mut bounds = vec![0.0];
    for tab in tabs {
        bounds.push(tab.start);
        bounds.push(tab.end);
    }
    bounds.push(f64::INFINITY);
    let intervals: Vec<(f64, f64)> = bounds.chunks(2).map(|w| (w[0], w[1])).collect();
    let mut at = 0.0;
    let mut current = 0;
    for span in cut {
        let length = span.length();
        let (begin, end) = (at, at + length);
        at = end;
        while current < intervals.len() {
            let (from, to) = intervals[current];
            let (a, b) = (begin.max(from), end.min(to));
            if b > a && length > 0.0 {
                let piece = span.sub_span((a - begin) / length, (b - begin) / length);
                if piece.length() > min_piece {
                    pieces[current].push(piece);
                }
            }
            if to <= end {
                current += 1;
                pieces.push(Vec::new());
            } else {
                break;
            }
        }
    }
    pieces.truncate(intervals.len());
    pieces
}

/// The spans of `contour` opened at the point nearest to `at`: the rest of that span, the
/// spans after it round the cycle, then the part of that span before `at`.
pub fn opened_at(contour: &Contour, at: Point, min_piece: f64) -> Vec<Span> {
    let Some(entry) = contour.nearest_point(at) else {
        return Vec::new();
    };
    let spans: Vec<Span> = contour.spans().collect();
    let (i, t) = (entry.position.span, entry.position.t);
    let mut out = Vec::with_capacity(spans.len() + 1);
    out.push(spans[i].sub_span(t, 1.0));
    for k in 1..spans.len() {
        out.push(spans[(i + k) % spans.len()]);
    }
    out.push(spans[i].sub_span(0.0, t));
    out.retain(|s| s.length() > min_piece);
    out
}

pub(crate) mod vertex_triples {
    //! Lead vertices as `[x, y, bulge]` triples, the issue's JSON form.
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use crate::Vertex;

    pub fn serialize<S: Serializer>(v: &[Vertex], s: S) -> Result<S::Ok, S::Error> {
        v.iter()
            .map(|v| [v.point.x, v.point.y, v.bulge])
            .collect::<Vec<_>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vertex>, D::Error> {
        let triples = Vec::<[f64; 3]>::deserialize(d)?;
        Ok(triples
            .into_iter()
            .map(|[x, y, b]| Vertex::arc(x, y, b))
            .collect())
    }
}

/// Why the full-route elements of a contour could not be built.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum LeadError {
    /// The nest has no such contour.
    #[error("the nest has no {contour}")]
    UnknownContour {
        /// The reference.
        contour: ContourRef,
    },
    /// The contour has no single equidistant at kerf/2.
    #[error("{contour} has no equidistant: {source}")]
    Offset {
        /// The contour.
        contour: ContourRef,
        /// Why.
        source: OffsetError,
    },
    /// No lead-in/lead-out pair fits anywhere on the contour.
    #[error("no lead fits {contour}: {reason}")]
    NoFit {
        /// The contour.
        contour: ContourRef,
        /// What failed at the last position tried.
        reason: LeadProblem,
    },
}

/// One way the full-route elements of a step break the model's rules.
#[derive(Clone, Copy, Debug, PartialEq, Error)]
pub enum LeadProblem {
    /// M is not in G_M: closer than d₁ to a contour, or not in the contour's scrap region.
    #[error("pierce point ({x}, {y}) is not in the pierce region G_M")]
    PierceOutsideRegion {
        /// M, x.
        x: f64,
        /// M, y.
        y: f64,
    },
    /// M lies off the sheet, or closer than d₁ to the sheet's edge: the torch would pierce
    /// beside the plate (or at its crumbling edge), where there is no scrap to pierce.
    #[error("pierce point ({x}, {y}) is off the sheet or closer than d₁ to its edge")]
    PierceOffSheet {
        /// M, x.
        x: f64,
        /// M, y.
        y: f64,
    },
    /// M* lies off the sheet, or closer than d₂ to its edge.
    #[error("switch-off point ({x}, {y}) is off the sheet or closer than d₂ to its edge")]
    SwitchOffOffSheet {
        /// M*, x.
        x: f64,
        /// M*, y.
        y: f64,
    },
    /// A lead's corner (between its straight part and its arc) lies off the sheet.
    #[error("a lead runs off the sheet at ({x}, {y})")]
    LeadOffSheet {
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
    },
    /// M* is not in G_M*.
    #[error("switch-off point ({x}, {y}) is not in the switch-off region G_M*")]
    SwitchOffOutsideRegion {
        /// M*, x.
        x: f64,
        /// M*, y.
        y: f64,
    },
    /// A lead comes closer than kerf/2 to a contour or crosses it.
    #[error("a lead comes {distance} mm from a contour near ({x}, {y}), closer than kerf/2")]
    LeadTooClose {
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
        /// Its distance to the nearest contour.
        distance: f64,
    },
    /// An edge pierce whose M is not on the sheet's border, or whose contour is not a part's
    /// outer contour in the sheet's scrap (or the nest has no sheet).
    #[error("edge pierce point ({x}, {y}) is not on the sheet's border")]
    EdgePierceOffBorder {
        /// M, x.
        x: f64,
        /// M, y.
        y: f64,
    },
    /// A kerf pierce whose M is not in the open kerf of the contour it names: off that
    /// contour's equidistant, in one of its tabs, or with no kerf at all.
    #[error("kerf pierce point ({x}, {y}) is not in the open kerf of the contour it names")]
    KerfPierceOffKerf {
        /// M, x.
        x: f64,
        /// M, y.
        y: f64,
    },
    /// The entry (or exit) is not on the equidistant.
    #[error("the entry ({x}, {y}) is {distance} mm off the equidistant")]
    EntryOffEquidistant {
        /// Entry, x.
        x: f64,
        /// Entry, y.
        y: f64,
        /// Its distance from the equidistant.
        distance: f64,
    },
    /// The lead chain does not run from M to the entry, or from the exit to M*.
    #[error("a lead does not join its end points")]
    Disjoint,
    /// A path's overcut is negative or not finite, runs on past the start of an open path
    /// (one that does not end where it starts), or is longer than the path.
    #[error("an overcut of {length} mm on an open path, or longer than its path")]
    OvercutMisplaced {
        /// The overcut, mm.
        length: f64,
    },
    /// A tab lies outside the cut, out of order, off the equidistant, over a corner, in a
    /// hole (holes get no tabs), or ends off the sheet.
    #[error("the tab at ({x}, {y}) is misplaced")]
    TabMisplaced {
        /// Where its gap begins, x.
        x: f64,
        /// Where its gap begins, y.
        y: f64,
    },
}

/// Relative tolerance of the checks, times the nest's scale (1 mm).
const TOLERANCE: f64 = 1e-6;

/// Builds equidistants and fits leads for the contours of one nest under one set of
/// [`KerfSettings`]; also checks given leads (the route checker's geometric part).
pub struct LeadFitter<'a> {
    nest: &'a Nest,
    forest: Cow<'a, ContainmentForest>,
    settings: KerfSettings,
    /// The contours' boxes by part and contour, built on first use: a box is a pass over
    /// the contour's spans, and the fitter tests thousands of points.
    boxes: std::cell::OnceCell<Vec<Vec<BoundingBox>>>,
    /// The same boxes in an R-tree, built on first use: clearance tests ask for the contours
    /// near a point, and scanning every box made that O(n) per test (20,000 contours).
    box_index: std::cell::OnceCell<RTree<GeomWithData<Rectangle<[f64; 2]>, ContourRef>>>,
}

impl<'a> LeadFitter<'a> {
    /// A fitter for `nest`; builds the containment forest once.
    pub fn new(nest: &'a Nest, settings: KerfSettings) -> LeadFitter<'a> {
        LeadFitter {
            nest,
            forest: Cow::Owned(nest.containment_forest()),
            settings,
            boxes: Default::default(),
            box_index: Default::default(),
        }
    }

    /// A fitter for `nest` that reuses its containment forest.
    pub fn with_forest(
        nest: &'a Nest,
        forest: &'a ContainmentForest,
        settings: KerfSettings,
    ) -> LeadFitter<'a> {
        LeadFitter {
            nest,
            forest: Cow::Borrowed(forest),
            settings,
            boxes: Default::default(),
            box_index: Default::default(),
        }
    }

    /// The contours whose boxes meet `area`, in the nest's order (part, then contour), so a
    /// search that stops at its first find finds what a scan in that order would.
    fn contours_meeting(&self, area: &BoundingBox) -> Vec<ContourRef> {
        let index = self.box_index.get_or_init(|| {
            RTree::bulk_load(
                self.nest
                    .contour_refs()
                    .filter_map(|r| {
                        let b = self.box_of(r)?;
                        Some(GeomWithData::new(
                            Rectangle::from_corners([b.min.x, b.min.y], [b.max.x, b.max.y]),
                            r,
                        ))
                    })
                    .collect(),
            )
        });
        let query = rstar::AABB::from_corners([area.min.x, area.min.y], [area.max.x, area.max.y]);
        let mut found: Vec<ContourRef> = index
            .locate_in_envelope_intersecting(&query)
            .map(|g| g.data)
            // The index's own test is the same closed-box test; this keeps it exactly ours.
            .filter(|&r| self.box_of(r).is_some_and(|b| b.intersects(area)))
            .collect();
        found.sort_unstable();
        found
    }

    pub(crate) fn box_of(&self, r: ContourRef) -> Option<&BoundingBox> {
        let boxes = self.boxes.get_or_init(|| {
            self.nest
                .parts
                .iter()
                .map(|p| p.contours.iter().map(Contour::bounding_box).collect())
                .collect()
        });
        boxes.get(r.part)?.get(r.contour)
    }

    /// [`crate::clearance`] with the boxes built once.
    fn clearance(&self, p: Point, limit: f64) -> f64 {
        let around = BoundingBox::from_corners(p, p).expanded(limit);
        self.contours_meeting(&around)
            .into_iter()
            .filter(|&r| {
                self.box_of(r)
                    .is_some_and(|b| b.expanded(limit).contains_point(p))
            })
            .filter_map(|r| self.nest.contour(r))
            .map(|c| c.distance_to(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// The least distance from a point of `span` to any contour whose box comes within
    /// `limit` of the span's box (`f64::INFINITY` when none does): exact, from
    /// [`Span::distance_to_span`] against each of those contours' spans.
    fn span_clearance(&self, span: &Span, limit: f64) -> f64 {
        let reach = span.bounding_box().expanded(limit);
        self.contours_meeting(&reach)
            .into_iter()
            .filter_map(|r| self.nest.contour(r))
            .flat_map(|c| c.spans())
            .filter(|s| s.bounding_box().intersects(&reach))
            .map(|s| span.distance_to_span(&s))
            .fold(f64::INFINITY, f64::min)
    }

    /// [`crate::in_clear_scrap`] with the boxes built once: a contour contains no point outside its
    /// box.
    fn in_clear_scrap(&self, r: ContourRef, p: Point, distance: f64) -> bool {
        if self.nest.contour(r).is_none() {
            return false;
        }
        let region = if self.is_hole(r) {
            Some(r)
        } else {
            self.forest.parent(r)
        };
        let contains = |c: ContourRef| {
            self.box_of(c).is_some_and(|b| b.contains_point(p))
                && self.nest.contour(c).is_some_and(|c| c.contains(p))
        };
        let inside_region = region.is_none_or(contains);
        let children = match region {
            None => self.forest.roots(),
            Some(c) => self.forest.children(c),
        };
        p.is_finite()
            && inside_region
            && !children.iter().any(|&c| contains(c))
            && !(self.clearance(p, distance) < distance)
    }

    /// Whether `p` lies on the nest's sheet at least `distance` inside its border (its first
    /// contour, as for edge piercing); every point is on a nest without a sheet. A pierce or
    /// switch-off point must be: off the plate there is nothing to pierce, and at its very
    /// edge the plate crumbles like the part's own edge would.
    pub fn on_sheet(&self, p: Point, distance: f64) -> bool {
        on_sheet(self.nest, p, distance)
    }

    /// The settings.
    pub fn settings(&self) -> &KerfSettings {
        &self.settings
    }

    /// The nest the fitter fits leads in.
    pub fn nest(&self) -> &'a Nest {
        self.nest
    }

    /// The nest's containment forest.
    pub(crate) fn forest(&self) -> &ContainmentForest {
        &self.forest
    }

    /// The equidistant of contour `r` at kerf/2 on its scrap side.
    pub fn equidistant(&self, r: ContourRef) -> Result<Contour, LeadError> {
        let contour = self
            .nest
            .contour(r)
            .ok_or(LeadError::UnknownContour { contour: r })?;
        equidistant(contour, self.settings.kerf / 2.0)
            .map_err(|source| LeadError::Offset { contour: r, source })
    }

    /// Leads for contour `r` with the pierce point M as near as the rules allow to `near` (a
    /// point the tool comes from, or a wanted pierce point). Tries the asked leads at the nearest entry, then
    /// shorter and turned ones, then entries further along the equidistant, then (in a hole)
    /// a pierce at the hole's centre.
    pub fn fit(&self, r: ContourRef, near: Point) -> Result<StepLeads, LeadError> {
        let eq = self.equidistant(r)?;
        self.fit_on(r, &eq, near)
    }

    /// [`LeadFitter::fit`] with the equidistant already built.
    pub fn fit_on(&self, r: ContourRef, eq: &Contour, near: Point) -> Result<StepLeads, LeadError> {
        let perimeter = eq.perimeter();
        // The entry that puts the asked lead-in's M over `near`.
        let s0 = eq
            .nearest_point(near)
            .map_or(0.0, |p| eq.length_at(p.position))
            + self.settings.lead_in.lag();
        const POSITIONS: usize = 24;
        let mut reason = LeadProblem::Disjoint;
        for k in 0..POSITIONS {
            // 0, +1, −1, +2, −2, … steps of perimeter/POSITIONS round the equidistant.
            let step = (k as f64 / 2.0).ceil() * if k % 2 == 1 { 1.0 } else { -1.0 };
            let s = (s0 + step * perimeter / POSITIONS as f64).rem_euclid(perimeter.max(1e-12));
            match self.fit_at(r, eq, s) {
                Ok(leads) => return Ok(leads),
                Err(problem) => reason = problem,
            }
        }
        if self.is_hole(r) {
            if let Some(leads) = self.centre_pierce(r, eq) {
                return Ok(leads);
            }
        }
        Err(LeadError::NoFit { contour: r, reason })
    }

    pub(crate) fn is_hole(&self, r: ContourRef) -> bool {
        self.forest.depth(r).is_some_and(|d| d % 2 == 1)
    }

    /// Leads with the entry at arc length `s` of `eq` (contour `r`'s equidistant), trying the
    /// variants of each lead in order; the rule the last variant broke when none fits. The
    /// full-route discretisation places its candidates with it (one entry per position).
    pub fn fit_at(&self, r: ContourRef, eq: &Contour, s: f64) -> Result<StepLeads, LeadProblem> {
        self.fit_at_linked(r, eq, s, false, false)
            .map_err(|(_, problem)| problem)
    }

    /// [`LeadFitter::fit_at`] for a step of a chain: entered by a tool-on link (`linked_in`:
    /// no lead-in, the link ends at the entry) or left by one (`linked_out`: no overcut and no
    /// lead-out, the link starts where the cut ends). The error says which lead found no room
    /// (`true`: the lead-in) and why.
    pub(crate) fn fit_at_linked(
        &self,
        r: ContourRef,
        eq: &Contour,
        s: f64,
        linked_in: bool,
        linked_out: bool,
    ) -> Result<StepLeads, (bool, LeadProblem)> {
        let (entry, tangent) = frame_at(eq, s);
        let perimeter = eq.perimeter();
        let overcut = if linked_out {
            0.0
        } else {
            self.settings.overcut
        };
        let (exit, exit_tangent) = frame_at(eq, (s + overcut).rem_euclid(perimeter));
        let edge_lead = if linked_in {
            None
        } else {
            self.edge_lead_in(r, entry)
        };
        let edge_pierce = edge_lead.is_some();
        let lead_in = if linked_in {
            vec![vertex(entry)]
        } else if let Some(chain) = edge_lead {
            chain
        } else {
            self.first_fitting(
                r,
                true,
                self.variants(self.settings.lead_in)
                    .map(|spec| lead_in_chain(spec, entry, tangent)),
            )
            .map_err(|problem| (true, problem))?
        };
        let lead_out = if linked_out {
            vec![vertex(exit)]
        } else {
            self.first_fitting(
                r,
                false,
                self.variants(self.settings.lead_out)
                    .map(|spec| lead_out_chain(spec, exit, exit_tangent)),
            )
            .map_err(|problem| (false, problem))?
        };
        let mut tabs = if self.is_hole(r) {
            Vec::new()
        } else {
            place_tabs(eq, self.settings.kerf / 2.0, s, overcut, self.settings.tabs)
        };
        // The torch pierces again at a tab's end: where the equidistant runs off the sheet (a
        // part at its edge) there is neither material to hold nor scrap to pierce.
        tabs.retain(|t| self.on_sheet(t.from, 0.0) && self.on_sheet(t.to, 0.0));
        Ok(StepLeads {
            pierce: lead_in[0].point,
            entry,
            switch_off: lead_out.last().map_or(exit, |v| v.point),
            lead_in,
            lead_out,
            offset: self.settings.kerf / 2.0,
            overcut,
            pierce_clearance: self.settings.pierce_clearance,
            switch_off_clearance: self.settings.switch_off_clearance,
            tabs,
            edge_pierce,
            kerf_pierce: None,
        })
    }

    /// The border of the sheet when contour `r` may be pierced at it: edge piercing on, `r` a
    /// part's outer contour in the sheet's own scrap (a root of the containment forest).
    fn edge_border(&self, r: ContourRef) -> Option<&'a Contour> {
        if self.forest.parent(r).is_some() || self.is_hole(r) {
            return None;
        }
        self.nest.sheet.as_ref()?.contours.first()
    }

    /// An edge lead-in to `entry` of contour `r`: the straight line from the nearest point of
    /// the sheet's border, when edge piercing is on, `r` may be pierced at the border, the line
    /// is no longer than [`KerfSettings::edge_reach`] and it keeps kerf/2 from every contour.
    pub(crate) fn edge_lead_in(&self, r: ContourRef, entry: Point) -> Option<Vec<Vertex>> {
        if !self.settings.edge_pierce {
            return None;
        }
        let at = self.edge_border(r)?.nearest_point(entry)?.point;
        if !(at.distance(entry) <= self.settings.edge_reach()) {
            return None;
        }
        let chain = vec![vertex(at), vertex(entry)];
        // Linked: M is held to the border, not to G_M; the line to every contour's kerf.
        self.chain_problem_linked(r, &chain, true, true)
            .is_none()
            .then_some(chain)
    }

    /// The first chain that breaks no rule, else the problem of the last one tried.
    fn first_fitting(
        &self,
        r: ContourRef,
        lead_in: bool,
        chains: impl Iterator<Item = Vec<Vertex>>,
    ) -> Result<Vec<Vertex>, LeadProblem> {
        let mut last = LeadProblem::Disjoint;
        for chain in chains {
            match self.chain_problem(r, &chain, lead_in) {
                None => return Ok(chain),
                Some(problem) => last = problem,
            }
        }
        Err(last)
    }

    /// The asked lead, then shorter ones, then (lines) turned ones, then a line for an arc.
    pub(crate) fn variants(&self, spec: LeadSpec) -> impl Iterator<Item = LeadSpec> {
        let mut out = vec![spec];
        if spec.shape != LeadShape::None {
            out.extend([0.75, 0.5].map(|f| spec.scaled(f)));
            let line = LeadSpec {
                shape: LeadShape::Line,
                ..spec
            };
            for angle in [30.0, -30.0, 60.0, -60.0] {
                out.push(LeadSpec { angle, ..line });
            }
            if spec.shape != LeadShape::Line {
                out.push(LeadSpec { angle: 0.0, ..line });
            }
        }
        out.into_iter()
    }

    /// A lead-in from the hole's centre (the centre of its equidistant's box) straight to the
    /// nearest point of the equidistant, and a lead-out back towards the centre.
    fn centre_pierce(&self, r: ContourRef, eq: &Contour) -> Option<StepLeads> {
        let centre = eq.bounding_box().centre();
        let entry = eq.nearest_point(centre)?.point;
        let lead_in = vec![Vertex::arc(centre.x, centre.y, 0.0), vertex(entry)];
        self.chain_problem(r, &lead_in, true)
            .is_none()
            .then_some(())?;
        let to_centre = centre - entry;
        let reach = self.settings.lead_out.length.min(to_centre.norm());
        let switch_off = entry + to_centre.normalized() * reach;
        let lead_out = if reach > 0.0 {
            vec![vertex(entry), vertex(switch_off)]
        } else {
            vec![vertex(entry)]
        };
        self.chain_problem(r, &lead_out, false)
            .is_none()
            .then_some(())?;
        Some(StepLeads {
            pierce: centre,
            entry,
            lead_in,
            lead_out,
            switch_off,
            offset: self.settings.kerf / 2.0,
            overcut: 0.0,
            pierce_clearance: self.settings.pierce_clearance,
            switch_off_clearance: self.settings.switch_off_clearance,
            tabs: Vec::new(),
            edge_pierce: false,
            kerf_pierce: None,
        })
    }

    /// The first rule a lead chain breaks: its free end (M for a lead-in, M* for a lead-out)
    /// must lie in the region, and every span must keep kerf/2 from every contour.
    pub(crate) fn chain_problem(
        &self,
        r: ContourRef,
        chain: &[Vertex],
        lead_in: bool,
    ) -> Option<LeadProblem> {
        self.chain_problem_linked(r, chain, lead_in, false)
    }

    /// [`LeadFitter::chain_problem`]; with `linked` the free end is where a tool-on link of a
    /// chain joins (no pierce or switch-off there), so it need not lie in G_M (G_M*).
    fn chain_problem_linked(
        &self,
        r: ContourRef,
        chain: &[Vertex],
        lead_in: bool,
        linked: bool,
    ) -> Option<LeadProblem> {
        let (free, distance) = if lead_in {
            (chain.first()?.point, self.settings.pierce_clearance)
        } else {
            (chain.last()?.point, self.settings.switch_off_clearance)
        };
        if !linked && !self.on_sheet(free, distance - TOLERANCE) {
            return Some(if lead_in {
                LeadProblem::PierceOffSheet {
                    x: free.x,
                    y: free.y,
                }
            } else {
                LeadProblem::SwitchOffOffSheet {
                    x: free.x,
                    y: free.y,
                }
            });
        }
        // The lead's inner vertices (a line-arc's corner) stay on the sheet too; its end on
        // the equidistant may not (a part at the sheet's edge is cut round off the plate).
        let inner = chain
            .get(1..chain.len().saturating_sub(1))
            .unwrap_or_default();
        if let Some(v) = inner.iter().find(|v| !self.on_sheet(v.point, -TOLERANCE)) {
            return Some(LeadProblem::LeadOffSheet {
                x: v.point.x,
                y: v.point.y,
            });
        }
        if !linked && !self.in_clear_scrap(r, free, distance - TOLERANCE) {
            return Some(if lead_in {
                LeadProblem::PierceOutsideRegion {
                    x: free.x,
                    y: free.y,
                }
            } else {
                LeadProblem::SwitchOffOutsideRegion {
                    x: free.x,
                    y: free.y,
                }
            });
        }
        let half = self.settings.kerf / 2.0;
        for span in chain_spans(chain) {
            // Exact, not sampled: a lead can dip between samples (0.99973 from a hole where
            // kerf/2 = 1 was required, between samples 0.25 mm apart).
            let d = self.span_clearance(&span, half + 1.0);
            if d < half - TOLERANCE {
                // Where: the nearest of dense samples (the distance reported is the exact one).
                let p = (0..=256)
                    .map(|i| span.point_at(i as f64 / 256.0))
                    .min_by(|a, b| {
                        self.clearance(*a, half + 1.0)
                            .total_cmp(&self.clearance(*b, half + 1.0))
                    })
                    .unwrap_or(span.start);
                return Some(LeadProblem::LeadTooClose {
                    x: p.x,
                    y: p.y,
                    distance: d,
                });
            }
            // With no kerf, sampling cannot see a crossing: test it exactly, away from the
            // lead's end on its own contour.
            if half <= TOLERANCE {
                if let Some(p) = self.crossing(r, &span, lead_in) {
                    return Some(LeadProblem::LeadTooClose {
                        x: p.x,
                        y: p.y,
                        distance: 0.0,
                    });
                }
            }
        }
        None
    }

    /// A point where `span` crosses a contour, other than the lead's end on contour `r`
    /// (the end at t = 1 of a lead-in, t = 0 of a lead-out).
    fn crossing(&self, r: ContourRef, span: &Span, lead_in: bool) -> Option<Point> {
        let bbox = span.bounding_box();
        for other in self.contours_meeting(&bbox) {
            let c = self.nest.contour(other)?;
            for s in c.spans() {
                for x in span.intersections(&s) {
                    let at_own_end = other == r
                        && if lead_in {
                            x.t_self > 1.0 - 1e-9
                        } else {
                            x.t_self < 1e-9
                        };
                    if !at_own_end {
                        return Some(x.point);
                    }
                }
            }
        }
        None
    }

    /// The nest of *pierce curves*: every contour replaced by its offset at kerf/2 plus the
    /// lead-in's reach (at least d₁), on the scrap side — where the pierce points M of
    /// unobstructed leads lie. A solver of idealised routes run on it places M and orders the
    /// contours with the leads' idle legs priced; [`LeadFitter::project`] and
    /// [`LeadFitter::attach`] then bring its route back to this nest. Contours whose curve
    /// does not exist, or would change which contour holds which, keep their own shape, so
    /// the precedence of the curve nest is that of the nest.
    pub fn pierce_curve_nest(&self) -> Nest {
        let reach = (self.settings.kerf / 2.0 + self.settings.lead_in.reach())
            .max(self.settings.pierce_clearance);
        self.offset_nest(reach)
    }

    /// Every contour offset by `reach` on its scrap side; contours whose offset does not exist,
    /// or would change which contour holds which, keep their own shape.
    pub(crate) fn offset_nest(&self, reach: f64) -> Nest {
        let mut curves = self.nest.clone();
        for part in &mut curves.parts {
            for contour in &mut part.contours {
                if let Ok(curve) = equidistant(contour, reach) {
                    *contour = curve;
                }
            }
        }
        // Undo the curves that change the containment forest (a part near the wall of the
        // hole it sits in), until none does.
        loop {
            let forest = curves.containment_forest();
            let changed: Vec<ContourRef> = self
                .nest
                .contour_refs()
                .filter(|&r| forest.parent(r) != self.forest.parent(r))
                .collect();
            if changed.is_empty() {
                return curves;
            }
            let mut undone = 0;
            for r in changed {
                for c in [Some(r), self.forest.parent(r)].into_iter().flatten() {
                    let original = &self.nest.parts[c.part].contours[c.contour];
                    let slot = &mut curves.parts[c.part].contours[c.contour];
                    if slot != original {
                        *slot = original.clone();
                        undone += 1;
                    }
                }
            }
            if undone == 0 {
                return self.nest.clone();
            }
        }
    }

    /// `route` (over [`LeadFitter::pierce_curve_nest`] or any nest of the same contours) with
    /// every pierce point moved to the nearest point of its own contour in this nest.
    pub fn project(&self, route: &Route) -> Route {
        let mut projected = route.clone();
        for step in &mut projected.steps {
            if let Some(p) = self
                .nest
                .contour(step.contour)
                .and_then(|c| c.nearest_point(step.pierce_point))
            {
                step.pierce_point = p.point;
            }
        }
        projected
    }

    /// The leads of one step: fitted with the entry as near as the rules allow to the step's
    /// pierce point, which then moves to the contour point under the entry.
    pub fn attach_to_step(&self, step: &CutStep) -> Result<CutStep, LeadError> {
        let leads = self.fit(step.contour, step.pierce_point)?;
        let contour = self
            .nest
            .contour(step.contour)
            .ok_or(LeadError::UnknownContour {
                contour: step.contour,
            })?;
        let on_contour = contour
            .nearest_point(leads.entry)
            .map_or(step.pierce_point, |p| p.point);
        Ok(CutStep {
            pierce_point: on_contour,
            leads: Some(leads),
            ..step.clone()
        })
    }

    /// `route` with leads attached to every pierced step ("solve, then attach leads"); steps
    /// entered by a tool-on link keep none. Every contour where no lead fits is reported.
    pub fn attach(&self, route: &Route) -> Result<Route, Vec<LeadError>> {
        let mut errors = Vec::new();
        let mut steps = Vec::with_capacity(route.steps.len());
        for step in &route.steps {
            if !step.is_pierced() {
                steps.push(step.clone());
                continue;
            }
            match self.attach_to_step(step) {
                Ok(s) => steps.push(s),
                Err(e) => errors.push(e),
            }
        }
        if errors.is_empty() {
            Ok(Route {
                steps,
                ..route.clone()
            })
        } else {
            Err(errors)
        }
    }

    /// Moves the leads of every pierced step of `route` (a route with leads) along its
    /// equidistant to shorten the idle legs around it, `passes` sweeps over the route: each
    /// step tries `positions` entries evenly spread round its equidistant, keeping the one
    /// with the least |previous M* → M| + |M* → next M| among those whose leads fit. The
    /// order is kept; leads stay valid.
    pub fn relax(&self, route: &Route, passes: usize, positions: usize) -> Route {
        let mut route = route.clone();
        for _ in 0..passes {
            for i in 0..route.steps.len() {
                self.relax_step(&mut route, i, positions);
            }
        }
        route
    }

    /// One step of [`LeadFitter::relax`]: the leads of step `i` moved to the best of
    /// `positions` entries round its equidistant (if one shortens its idle legs). Returns
    /// whether they moved. Callers that work in time slices relax step by step.
    pub fn relax_step(&self, route: &mut Route, i: usize, positions: usize) -> bool {
        let Some(step) = route.steps.get(i) else {
            return false;
        };
        let (Some(current), true) = (&step.leads, step.is_pierced()) else {
            return false;
        };
        // A step whose cut goes on into a chain's link keeps its exit where the link starts.
        if route
            .steps
            .get(i + 1)
            .is_some_and(|next| !next.is_pierced())
        {
            return false;
        }
        let Ok(eq) = self.equidistant(step.contour) else {
            return false;
        };
        let before = if i == 0 {
            route.start
        } else {
            route.steps[i - 1].switch_off_point()
        };
        let after = match route.steps.get(i + 1) {
            Some(next) if next.is_pierced() => Some(next.switch_on_point()),
            Some(_) => None,
            None => route.finish,
        };
        let legs = |l: &StepLeads| {
            before.distance(l.pierce) + after.map_or(0.0, |a| l.switch_off.distance(a))
        };
        // Every lead the fitter makes at an entry P is at most this long (shorter and turned
        // variants included), so M lies within `lead_in` of P and M* within `lead_out` of it:
        // an entry whose legs cannot beat the best even so is not fitted (the result is the
        // same, the fits are the cost).
        let lead_in = if self.settings.edge_pierce {
            self.settings
                .lead_in
                .longest_chain()
                .max(self.settings.edge_reach())
        } else {
            self.settings.lead_in.longest_chain()
        };
        let lead_out = self.settings.lead_out.longest_chain() + self.settings.overcut;
        let perimeter = eq.perimeter();
        let mut best = (legs(current), None);
        for k in 0..positions {
            let s = perimeter * k as f64 / positions as f64;
            let (entry, _) = frame_at(&eq, s);
            let least = (before.distance(entry) - lead_in).max(0.0)
                + after.map_or(0.0, |a| (a.distance(entry) - lead_out).max(0.0));
            if least >= best.0 - 1e-9 {
                continue;
            }
            if let Ok(leads) = self.fit_at(step.contour, &eq, s) {
                let value = legs(&leads);
                if value < best.0 - 1e-9 {
                    best = (value, Some(leads));
                }
            }
        }
        let Some(leads) = best.1 else {
            return false;
        };
        let contour = self.nest.contour(step.contour).expect("fitted contour");
        let step = &mut route.steps[i];
        if let Some(p) = contour.nearest_point(leads.entry) {
            step.pierce_point = p.point;
        }
        step.leads = Some(leads);
        true
    }

    /// Every rule that `leads` breaks as the leads of contour `r` (the checker used by
    /// [`crate::Route::problems`]): M ∈ G_M, M* ∈ G_M*, the leads clear of every contour by
    /// kerf/2, the entry and exit on the equidistant, the chains joined to their points.
    pub fn problems(&self, r: ContourRef, leads: &StepLeads) -> Vec<LeadProblem> {
        self.problems_linked(r, leads, false, false)
    }

    /// [`LeadFitter::problems`] for a step of a chain: entered by a tool-on link
    /// (`linked_in`: its pierce point is where the link ends, not a pierce, so not held to
    /// G_M) or left by one (`linked_out`: its switch-off point is where the link starts, not
    /// held to G_M*). The leads themselves are held to every other rule.
    pub fn problems_linked(
        &self,
        r: ContourRef,
        leads: &StepLeads,
        linked_in: bool,
        linked_out: bool,
    ) -> Vec<LeadProblem> {
        let mut problems = Vec::new();
        let joined = leads.lead_in.first().map(|v| v.point) == Some(leads.pierce)
            && leads.lead_in.last().map(|v| v.point) == Some(leads.entry)
            && leads.lead_out.last().map(|v| v.point) == Some(leads.switch_off);
        if !joined {
            problems.push(LeadProblem::Disjoint);
        }
        match self.equidistant(r) {
            Ok(eq) => {
                for p in [leads.entry, leads.exit()] {
                    let distance = eq.distance_to(p);
                    if !(distance <= 1e-6) {
                        problems.push(LeadProblem::EntryOffEquidistant {
                            x: p.x,
                            y: p.y,
                            distance,
                        });
                    }
                }
            }
            Err(_) => problems.push(LeadProblem::EntryOffEquidistant {
                x: leads.entry.x,
                y: leads.entry.y,
                distance: f64::NAN,
            }),
        }
        // An edge pierce's M is on the sheet's border, a kerf pierce's in a cut kerf (checked
        // by the route, which knows what was cut before): both outside G_M; their leads are
        // held to the kerf like every other.
        let edge = leads.edge_pierce && !linked_in;
        let quick = (leads.edge_pierce || leads.kerf_pierce.is_some()) && !linked_in;
        if edge {
            let on_border = self
                .edge_border(r)
                .is_some_and(|border| border.distance_to(leads.pierce) <= 1e-6);
            if !on_border {
                problems.push(LeadProblem::EdgePierceOffBorder {
                    x: leads.pierce.x,
                    y: leads.pierce.y,
                });
            }
        }
        problems.extend(self.chain_problem_linked(r, &leads.lead_in, true, linked_in || quick));
        problems.extend(self.chain_problem_linked(r, &leads.lead_out, false, linked_out));
        if !leads.tabs.is_empty() {
            problems.extend(self.tab_problems(r, leads));
        }
        problems
    }

    /// The tabs of `leads` on contour `r`: only in a part's outer contour, in cut order within
    /// the cut, their ends on the equidistant where their arc lengths say, and no corner inside
    /// a gap.
    fn tab_problems(&self, r: ContourRef, leads: &StepLeads) -> Vec<LeadProblem> {
        let misplaced = |p: Point| LeadProblem::TabMisplaced { x: p.x, y: p.y };
        if self.is_hole(r) {
            return leads.tabs.iter().map(|t| misplaced(t.from)).collect();
        }
        let Ok(eq) = self.equidistant(r) else {
            return Vec::new(); // reported as the entry off the equidistant
        };
        let perimeter = eq.perimeter();
        let entry = eq
            .nearest_point(leads.entry)
            .map_or(0.0, |p| eq.length_at(p.position));
        let corners = corner_intervals(&eq, leads.offset, entry);
        let tolerance = 1e-6;
        let mut problems = Vec::new();
        let mut previous_end = 0.0;
        for tab in &leads.tabs {
            let at = |s: f64| frame_at(&eq, (entry + s).rem_euclid(perimeter)).0;
            let ordered = previous_end <= tab.start && tab.start < tab.end && tab.end <= perimeter;
            let on_equidistant = at(tab.start).distance(tab.from) <= tolerance
                && at(tab.end).distance(tab.to) <= tolerance;
            let clear = corners
                .iter()
                .all(|&(c0, c1)| c1 <= tab.start || c0 >= tab.end);
            let on_sheet = self.on_sheet(tab.to, -tolerance);
            if !(ordered && on_equidistant && clear && on_sheet) {
                problems.push(misplaced(tab.from));
            }
            previous_end = tab.end;
        }
        problems
    }
}

impl LeadFitter<'_> {
    /// Kerf piercing ([`KerfSettings::kerf_pierce`], with a kerf): each pierced step of `route` (a route
    /// with leads) whose entry lies within [`KerfSettings::edge_reach`] of the equidistant of
    /// a contour cut earlier is pierced there instead, in that contour's open kerf (no
    /// material to burn through, like the sheet's edge), by a straight lead-in from the
    /// kerf's nearest point that keeps kerf/2 from every contour. A step moves only when that
    /// saves time under `machine`: the edge-pierce time against the pierce time, plus the
    /// change in its idle leg. Steps already pierced at the border, and points in a tab's
    /// gap, are left alone. The order and every other element stay. Returns how many steps
    /// moved.
    pub fn pierce_into_kerfs(&self, route: &mut Route, machine: &MachineParameters) -> usize {
        if !self.settings.kerf_pierce || self.settings.kerf <= 0.0 {
            return 0;
        }
        // As far as the lead and its pierce region would reach from the entry anyway.
        let reach = self.settings.edge_reach();
        let half = self.settings.kerf / 2.0;
        let mut equidistants: std::collections::HashMap<ContourRef, Option<Contour>> =
            Default::default();
        // The boxes (grown by kerf/2 and the reach) of the contours the steps cut, by step: a
        // step finds the cuts near its entry in logarithmic time, not by testing every earlier
        // step (2·10⁸ box tests at 20,000 contours).
        let reach_of = |r: ContourRef| {
            self.box_of(r)
                .map(|b| b.expanded(half + reach))
                .filter(|b| !b.is_empty())
        };
        let cuts: RTree<GeomWithData<Rectangle<[f64; 2]>, usize>> = RTree::bulk_load(
            route
                .steps
                .iter()
                .enumerate()
                .filter(|(_, s)| s.leads.is_some())
                .filter_map(|(j, s)| {
                    let b = reach_of(s.contour)?;
                    let corners = ([b.min.x, b.min.y], [b.max.x, b.max.y]);
                    Some(GeomWithData::new(
                        Rectangle::from_corners(corners.0, corners.1),
                        j,
                    ))
                })
                .collect(),
        );
        let mut moved = 0;
        for i in 0..route.steps.len() {
            let step = &route.steps[i];
            let Some(leads) = step.leads.as_ref().filter(|_| step.is_pierced()) else {
                continue;
            };
            if leads.edge_pierce || leads.kerf_pierce.is_some() {
                continue;
            }
            let before = if i == 0 {
                route.start
            } else {
                route.steps[i - 1].switch_off_point()
            };
            let seconds = |m: Point, pierce: f64| before.distance(m) / machine.idle_speed + pierce;
            let mut best = (seconds(leads.pierce, machine.pierce_time), None);
            // The earlier cuts near the entry, in route order (a tie in time goes to the
            // earliest cut).
            let mut near: Vec<usize> = cuts
                .locate_all_at_point(&[leads.entry.x, leads.entry.y])
                .map(|e| e.data)
                .filter(|&j| j < i)
                .collect();
            near.sort_unstable();
            for earlier in near.into_iter().map(|j| &route.steps[j]) {
                let (kerf_of, Some(cut)) = (earlier.contour, earlier.leads.as_ref()) else {
                    continue;
                };
                let near = reach_of(kerf_of).is_some_and(|b| b.contains_point(leads.entry));
                if kerf_of == step.contour || !near {
                    continue;
                }
                let eq = equidistants
                    .entry(kerf_of)
                    .or_insert_with(|| self.equidistant(kerf_of).ok());
                let Some(at) = eq.as_ref().and_then(|eq| eq.nearest_point(leads.entry)) else {
                    continue;
                };
                let at = at.point;
                let time = seconds(at, machine.edge_pierce_seconds());
                if !(at.distance(leads.entry) <= reach) || time >= best.0 - 1e-9 {
                    continue;
                }
                let chain = vec![vertex(at), vertex(leads.entry)];
                let open = eq
                    .as_ref()
                    .is_some_and(|eq| in_open_kerf(eq, cut, at, half))
                    && self.on_sheet(at, 0.0);
                if open
                    && self
                        .chain_problem_linked(step.contour, &chain, true, true)
                        .is_none()
                {
                    best = (time, Some((kerf_of, chain)));
                }
            }
            if let (_, Some((kerf_of, chain))) = best {
                let leads = route.steps[i].leads.as_mut().expect("checked above");
                leads.pierce = chain[0].point;
                leads.lead_in = chain;
                leads.kerf_pierce = Some(kerf_of);
                moved += 1;
            }
        }
        moved
    }

    /// Whether `pierce` lies in the open kerf that the cut `cut` of contour `kerf_of` leaves:
    /// on its equidistant, outside its tabs' gaps (the route checker's test of a kerf pierce).
    pub fn kerf_pierce_problem(
        &self,
        kerf_of: ContourRef,
        cut: &StepLeads,
        pierce: Point,
    ) -> Option<LeadProblem> {
        let off = LeadProblem::KerfPierceOffKerf {
            x: pierce.x,
            y: pierce.y,
        };
        let half = self.settings.kerf / 2.0;
        if !(half > 0.0) {
            return Some(off);
        }
        let Ok(eq) = self.equidistant(kerf_of) else {
            return Some(off);
        };
        // A kerf that runs off the sheet (a part at its edge) is no place to pierce.
        let on = eq.distance_to(pierce) <= 1e-6
            && in_open_kerf(&eq, cut, pierce, half)
            && self.on_sheet(pierce, -TOLERANCE);
        (!on).then_some(off)
    }
}

/// Whether `at` (on `eq`, the equidistant that the cut `cut` runs on) lies outside every tab
/// gap of that cut, with `half` (kerf/2) to spare: a tab is material left standing.
fn in_open_kerf(eq: &Contour, cut: &StepLeads, at: Point, half: f64) -> bool {
    if cut.tabs.is_empty() {
        return true;
    }
    let position = |p: Point| eq.nearest_point(p).map(|n| eq.length_at(n.position));
    let (Some(s), Some(entry)) = (position(at), position(cut.entry)) else {
        return false;
    };
    let along = (s - entry).rem_euclid(eq.perimeter().max(1e-12));
    cut.tabs
        .iter()
        .all(|t| along <= t.start - half || along >= t.end + half)
}

/// Whether `p` lies inside the border of `nest`'s sheet (its first contour) and at least
/// `distance` from it (see [`LeadFitter::on_sheet`]); true without a sheet.
pub(crate) fn on_sheet(nest: &Nest, p: Point, distance: f64) -> bool {
    let Some(border) = nest.sheet.as_ref().and_then(|s| s.contours.first()) else {
        return true;
    };
    if border.vertices.len() < 2 {
        return true;
    }
    p.is_finite() && border.contains(p) && !(border.distance_to(p) < distance)
        || (distance <= 0.0 && border.distance_to(p) <= -distance)
}

pub(crate) fn vertex(p: Point) -> Vertex {
    Vertex::arc(p.x, p.y, 0.0)
}

/// The point at arc length `s` of `eq` and the unit tangent there (cut direction).
fn frame_at(eq: &Contour, s: f64) -> (Point, Point) {
    let Some(position) = eq.position_at_length(s) else {
        return (Point::new(f64::NAN, f64::NAN), Point::new(1.0, 0.0));
    };
    let span = eq.span(position.span).expect("position on the contour");
    (span.point_at(position.t), span.tangent_at(position.t))
}

/// The lead-in chain from M to `entry`, where the cut leaves in direction `tangent`; the
/// scrap side is the left of the tangent.
pub(crate) fn lead_in_chain(spec: LeadSpec, entry: Point, tangent: Point) -> Vec<Vertex> {
    let normal = tangent.rotated_quarter();
    match spec.shape {
        LeadShape::None => vec![vertex(entry)],
        LeadShape::Line => {
            let a = spec.angle.to_radians();
            let m = entry + (normal * a.cos_libm() - tangent * a.sin_libm()) * spec.length;
            vec![vertex(m), vertex(entry)]
        }
        LeadShape::Arc | LeadShape::LineArc => {
            // The arc ends at the entry moving along the tangent, its centre on the scrap side,
            // so it turns counter-clockwise; it starts `sweep` before the entry.
            let (radius, sweep) = spec.arc();
            let centre = entry + normal * radius;
            let start = centre + (entry - centre).rotated(-sweep);
            let bulge = (sweep / 4.0).tan_libm();
            let mut chain = vec![Vertex::arc(start.x, start.y, bulge), vertex(entry)];
            if spec.shape == LeadShape::LineArc && spec.length > 0.0 {
                // The line runs into the arc along the arc's tangent at its start.
                let arc_tangent = (start - centre).rotated_quarter().normalized();
                let m = start - arc_tangent * spec.length;
                chain.insert(0, vertex(m));
            }
            chain
        }
    }
}

/// The lead-out chain from `exit`, where the cut arrives in direction `tangent`, to M*.
pub(crate) fn lead_out_chain(spec: LeadSpec, exit: Point, tangent: Point) -> Vec<Vertex> {
    let normal = tangent.rotated_quarter();
    match spec.shape {
        LeadShape::None => vec![vertex(exit)],
        LeadShape::Line => {
            let a = spec.angle.to_radians();
            let m = exit + (normal * a.cos_libm() + tangent * a.sin_libm()) * spec.length;
            vec![vertex(exit), vertex(m)]
        }
        LeadShape::Arc | LeadShape::LineArc => {
            let (radius, sweep) = spec.arc();
            let centre = exit + normal * radius;
            let end = centre + (exit - centre).rotated(sweep);
            let bulge = (sweep / 4.0).tan_libm();
            let mut chain = vec![Vertex::arc(exit.x, exit.y, bulge), vertex(end)];
            if spec.shape == LeadShape::LineArc && spec.length > 0.0 {
                let arc_tangent = (end - centre).rotated_quarter().normalized();
                chain.push(vertex(end + arc_tangent * spec.length));
            }
            chain
        }
    }
}
