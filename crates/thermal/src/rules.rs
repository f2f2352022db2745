//! The shop rules of Krotov and Gurtovenko as checks with counted violations, and a repair that
//! makes a route obey them (hard-rule mode).
//!
//! The dissertation states the rules in words; these are the precise definitions used here,
//! each with its reason.
//!
//! **Units.** A *unit* is a root of the containment forest (a part's outer contour) with every
//! contour inside it. Cutting the root frees the part: from that step on its area is cut out
//! of the sheet. Holes are not free edges for their own part: a hole is cut while the part is
//! still held by the sheet, and the rule is about what holds the part.
//!
//! **Part rigidity** (one check per outer contour of a part, i.e. per even-depth contour). The
//! *free edge* at a step is the sheet border (the sheet's outer contour, or the parts' box
//! when the file has no sheet) together with every sibling outer contour cut before it (for a
//! part inside a hole: the earlier-cut siblings only, the hole is cut later). The rule asks to
//! cut the sections nearest the free edge first and to finish on the section bordering rigid
//! material. A contour cut whole from one pierce point starts and finishes at that point and
//! runs one way round, so the two clauses are one choice: the pierce point. It is a violation
//! when the pierce point is more than `part_margin_mm` farther from the free edge than the
//! contour's nearest point to it (the contour is sampled every ≤ 5 mm and at its vertices).
//! Then the cut starts next to the free edge and ends there too, having gone round through the
//! material that is still rigid. The margin (10 mm) absorbs sampling and makes "closest"
//! tolerant of equal-distance sides (a part parallel to the border).
//!
//! **Sheet rigidity.** The sheet's long axis is the longer side of its box.
//! 1. A unit is *long* when its box's longer side is at least `long_ratio` (10, as the
//!    dissertation says) times its shorter side; it is *near a narrow border* when the strip of
//!    sheet between its box and the nearest sheet side is at most `border_band_mm` wide (50 mm:
//!    a strip of that width is what bends most, and "narrow border" reads as the narrow strip
//!    of material along the edge). Each such unit cut after a unit that is not one counts one
//!    violation.
//! 2. The sheet has a *large scrap* when the part-free margin at one end of its long axis is at
//!    least `large_scrap_fraction` (25 %) of the sheet's length: a quarter of the sheet left
//!    whole is a rigid remainder worth ending at. The start must then lie in the half of the
//!    parts' extent away from that end.
//! 3. Otherwise, the start must lie in the half of the parts' extent (along the long axis)
//!    whose units have the larger total perimeter (cut length is heat released, and more small
//!    parts mean more perimeter), unless the halves differ by less than `heat_balance` (10 %)
//!    of the total, when either side will do.
//!
//!    The *start* is the first unit cut that is not a rule-1 unit (rule 1 decides what comes
//!    before it); it lies in a half when its box's centre does. A wrong start is one violation.
//! 4. Rule 4 (no narrow strips or islands) is the islands rule below, counted there.
//!
//! **Islands and strips.** After each cut of a unit, an uncut unit is on an island when no
//! material at least `strip_width_mm` (20 mm) wide joins it to the sheet's edge: see the
//! module `islands` for the raster definition. Each unit counts once, at the step that first
//! cuts it off; units smaller than a raster cell are never counted.

use std::collections::HashMap;
use std::ops::Range;

use cutroute_geometry::{Contour, ContourRef, Entry, Nest, Point, Route};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{PointDistance, RTree};
use serde::{Deserialize, Serialize};

use crate::islands::IslandGrid;
use crate::layout::{along, box_distance, samples, Layout};

/// A cut contour's box, with its index in the cut list.
type CutBox = GeomWithData<Rectangle<[f64; 2]>, usize>;
use crate::ThermalError;

/// The parameters of the rules (see the module documentation for what each one means).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RuleParams {
    /// Part rigidity: how much farther from the free edge than the contour's nearest point a
    /// pierce point may be, mm.
    pub part_margin_mm: f64,
    /// Sheet rule 1: the aspect ratio from which a part is long.
    pub long_ratio: f64,
    /// Sheet rule 1: the widest strip between a part and the sheet edge that counts as a narrow
    /// border, mm.
    pub border_band_mm: f64,
    /// Sheet rule 2: the part-free end margin, as a fraction of the sheet's length, from which
    /// the scrap is large.
    pub large_scrap_fraction: f64,
    /// Sheet rule 3: the smallest difference between the halves' perimeters, as a fraction of
    /// the total, that makes one side the required start.
    pub heat_balance: f64,
    /// Islands: the narrowest material that still holds a part, mm.
    pub strip_width_mm: f64,
    /// Islands: the largest number of raster cells (the cell grows beyond w/4 to respect it).
    pub max_grid_cells: usize,
}

impl Default for RuleParams {
    fn default() -> Self {
        RuleParams {
            part_margin_mm: 10.0,
            long_ratio: 10.0,
            border_band_mm: 50.0,
            large_scrap_fraction: 0.25,
            heat_balance: 0.1,
            strip_width_mm: 20.0,
            max_grid_cells: 250_000,
        }
    }
}

impl RuleParams {
    /// Checks that every parameter is finite and in range.
    pub fn validate(&self) -> Result<(), ThermalError> {
        let checks = [
            (
                "part_margin",
                self.part_margin_mm,
                self.part_margin_mm >= 0.0,
            ),
            ("long_ratio", self.long_ratio, self.long_ratio >= 1.0),
            (
                "border_band",
                self.border_band_mm,
                self.border_band_mm >= 0.0,
            ),
            (
                "large_scrap_fraction",
                self.large_scrap_fraction,
                self.large_scrap_fraction > 0.0 && self.large_scrap_fraction <= 1.0,
            ),
            (
                "heat_balance",
                self.heat_balance,
                (0.0..=1.0).contains(&self.heat_balance),
            ),
            (
                "strip_width",
                self.strip_width_mm,
                self.strip_width_mm > 0.0,
            ),
        ];
        for (name, value, ok) in checks {
            if !(ok && value.is_finite()) {
                return Err(ThermalError::InvalidParameter {
                    name,
                    value,
                    expected: "see RuleParams",
                });
            }
        }
        Ok(())
    }
}

/// Which rules to check or enforce.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RuleSet {
    /// Part rigidity.
    pub part: bool,
    /// Sheet rigidity 1–3.
    pub sheet: bool,
    /// Islands and strips (sheet rule 4).
    pub islands: bool,
}

impl RuleSet {
    /// No rule.
    pub const NONE: RuleSet = RuleSet {
        part: false,
        sheet: false,
        islands: false,
    };

    /// Whether any rule is selected.
    pub fn any(&self) -> bool {
        self.part || self.sheet || self.islands
    }

    /// Every rule.
    pub const ALL: RuleSet = RuleSet {
        part: true,
        sheet: true,
        islands: true,
    };

    /// Parses a comma-separated list of `part`, `sheet`, `islands` (the CLI's `--rules`).
    pub fn parse(text: &str) -> Result<RuleSet, ThermalError> {
        let mut set = RuleSet::NONE;
        for name in text.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            match name {
                "part" => set.part = true,
                "sheet" => set.sheet = true,
                "islands" => set.islands = true,
                other => return Err(ThermalError::UnknownRule(other.to_string())),
            }
        }
        Ok(set)
    }
}

/// The half of the parts' extent along the sheet's long axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Side {
    /// Towards smaller coordinates.
    Low,
    /// Towards larger coordinates.
    High,
}

/// One broken rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Violation {
    /// Part rigidity: the pierce point is `excess_mm` farther from the free edge than the
    /// contour's nearest point (beyond the margin), which is `best`.
    PartRigidity {
        /// The step.
        step: usize,
        /// Its contour.
        contour: ContourRef,
        /// How much farther than allowed, mm.
        excess_mm: f64,
        /// The contour's point nearest the free edge.
        best: Point,
    },
    /// Sheet rule 1: a long part near a narrow border is cut after another part.
    LongPartLate {
        /// The step cutting its outer contour.
        step: usize,
        /// Its outer contour.
        part: ContourRef,
    },
    /// Sheet rule 2 or 3: the route starts on the wrong side.
    WrongStartSide {
        /// The step cutting the start unit's outer contour.
        step: usize,
        /// Its outer contour.
        part: ContourRef,
        /// Where the start should be.
        required: Side,
        /// Rule 2 (large scrap) or 3 (heat release).
        rule: u8,
    },
    /// Islands: an uncut part is cut off from the sheet's edge by the cut at `step`.
    Island {
        /// The step whose cut isolates it.
        step: usize,
        /// The isolated part's outer contour.
        part: ContourRef,
    },
}

/// Violation counts per rule group (`None` for a group not checked).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RuleCounts {
    /// Part rigidity.
    pub part: Option<usize>,
    /// Sheet rigidity 1–3.
    pub sheet: Option<usize>,
    /// Islands and strips.
    pub islands: Option<usize>,
}

impl RuleCounts {
    /// Violations of the checked rules together.
    pub fn total(&self) -> usize {
        self.part.unwrap_or(0) + self.sheet.unwrap_or(0) + self.islands.unwrap_or(0)
    }
}

/// The outcome of a check.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RuleReport {
    /// Which rules were checked.
    pub rules: RuleSet,
    /// Every violation found, by rule group then step.
    pub violations: Vec<Violation>,
}

impl RuleReport {
    /// The counts per checked group.
    pub fn counts(&self) -> RuleCounts {
        let count = |f: fn(&Violation) -> bool| self.violations.iter().filter(|v| f(v)).count();
        RuleCounts {
            part: self
                .rules
                .part
                .then(|| count(|v| matches!(v, Violation::PartRigidity { .. }))),
            sheet: self.rules.sheet.then(|| {
                count(|v| {
                    matches!(
                        v,
                        Violation::LongPartLate { .. } | Violation::WrongStartSide { .. }
                    )
                })
            }),
            islands: self
                .rules
                .islands
                .then(|| count(|v| matches!(v, Violation::Island { .. }))),
        }
    }
}

/// Checks `route` over `nest` against the selected rules. The route should be valid
/// (`Route::problems` empty); contours it does not cut are treated as never cut.
pub fn check_rules(
    nest: &Nest,
    route: &Route,
    rules: RuleSet,
    params: &RuleParams,
) -> Result<RuleReport, ThermalError> {
    params.validate()?;
    check_steps(route, nest)?;
    if !rules.any() {
        // Nothing to check: the layout's boxes and rasters alone took 0.4 s on 100,000
        // contours, in the CLI's report after the time limit.
        return Ok(RuleReport {
            rules,
            violations: Vec::new(),
        });
    }
    let layout = Layout::new(nest);
    let mut violations = Vec::new();
    if rules.part {
        violations.extend(part_rigidity(&layout, route, params));
    }
    if rules.sheet {
        violations.extend(sheet_rigidity(&layout, route, params));
    }
    if rules.islands {
        violations.extend(islands(&layout, route, params));
    }
    Ok(RuleReport { rules, violations })
}

/// Steps of the part rule per piece of a [`RuleCheck`] (about 70 ms on a generated
/// 30,000-contour nest, release build).
const PART_STEPS_PER_PIECE: usize = 2_000;

/// [`check_rules`] in pieces, for a job that must answer Stop between slices: part rigidity a
/// range of steps at a time, sheet rigidity, the island raster's build, then its sweep. Call
/// [`RuleCheck::advance`] with the same nest and route until it returns the report, which is
/// [`check_rules`]'s.
#[derive(Clone)]
pub struct RuleCheck {
    rules: RuleSet,
    params: RuleParams,
    stage: CheckStage,
    violations: Vec<Violation>,
}

#[derive(Clone)]
enum CheckStage {
    Start,
    Part(usize),
    Sheet,
    IslandGrid,
    Islands(Box<IslandGrid>),
    Done,
}

impl RuleCheck {
    /// A check of `rules` with `params` (refused when a parameter is out of range).
    pub fn new(rules: RuleSet, params: RuleParams) -> Result<RuleCheck, ThermalError> {
        params.validate()?;
        Ok(RuleCheck {
            rules,
            params,
            stage: CheckStage::Start,
            violations: Vec::new(),
        })
    }

    /// Works on the check for about `budget` (a piece at least, a piece's length at most
    /// beyond it); `Some(report)` once done.
    pub fn advance(
        &mut self,
        nest: &Nest,
        route: &Route,
        budget: web_time::Duration,
    ) -> Result<Option<RuleReport>, ThermalError> {
        let started = web_time::Instant::now();
        let layout = Layout::new(nest);
        loop {
            self.stage = match std::mem::replace(&mut self.stage, CheckStage::Done) {
                CheckStage::Start => {
                    check_steps(route, nest)?;
                    CheckStage::Part(0)
                }
                CheckStage::Part(from) if self.rules.part && from < route.steps.len() => {
                    let to = (from + PART_STEPS_PER_PIECE).min(route.steps.len());
                    self.violations.extend(part_rigidity_range(
                        &layout,
                        route,
                        &self.params,
                        from..to,
                    ));
                    CheckStage::Part(to)
                }
                CheckStage::Part(_) => CheckStage::Sheet,
                CheckStage::Sheet => {
                    if self.rules.sheet {
                        self.violations
                            .extend(sheet_rigidity(&layout, route, &self.params));
                    }
                    CheckStage::IslandGrid
                }
                CheckStage::IslandGrid if self.rules.islands => {
                    CheckStage::Islands(Box::new(IslandGrid::new(
                        &layout,
                        self.params.strip_width_mm,
                        self.params.max_grid_cells,
                    )))
                }
                CheckStage::IslandGrid => CheckStage::Done,
                CheckStage::Islands(grid) => {
                    self.violations
                        .extend(island_violations(&layout, route, &grid));
                    CheckStage::Done
                }
                CheckStage::Done => {
                    return Ok(Some(RuleReport {
                        rules: self.rules,
                        violations: std::mem::take(&mut self.violations),
                    }))
                }
            };
            if !matches!(self.stage, CheckStage::Done) && started.elapsed() >= budget {
                return Ok(None);
            }
        }
    }
}

fn check_steps(route: &Route, nest: &Nest) -> Result<(), ThermalError> {
    for (step, s) in route.steps.iter().enumerate() {
        if nest.contour(s.contour).is_none() {
            return Err(ThermalError::Route(Box::new(
                cutroute_geometry::RouteError::UnknownContour {
                    step,
                    contour: s.contour,
                },
            )));
        }
    }
    Ok(())
}

/// What the part rule sees at one step: the contour's sample points with their distance to the
/// free edge, the least of them, and the pierce point's distance.
struct Rigidity {
    step: usize,
    contour: ContourRef,
    points: Vec<(Point, f64)>,
    best: (Point, f64),
    here: f64,
}

/// The steps the part rule constrains (even-depth contours with a free edge), in order. The
/// free edges depend on the order only, never on pierce points.
fn rigidity(layout: &Layout, route: &Route) -> Vec<Rigidity> {
    rigidity_range(layout, route, 0..route.steps.len())
}

/// The part rule's contours at steps in `range`: the free edges of the steps before it are
/// bulk-loaded first, so a long route is checked in pieces that each cost O(n log n) at most.
fn rigidity_range(layout: &Layout, route: &Route, range: Range<usize>) -> Vec<Rigidity> {
    let forest = &layout.forest;
    // The contours already cut, one R-tree of their boxes per scrap region (children of the
    // sheet, or of one hole): the free edge near a point is found among the nearest boxes, so
    // a 10,000-part sheet takes O(n log n), not a scan of every earlier part per sample point.
    // A box's data is the step that cut its contour.
    let constrained = |step: usize| {
        let s = &route.steps[step];
        let depth = forest.depth(s.contour)?;
        let contour = layout.nest.contour(s.contour)?;
        (depth % 2 == 0).then_some((s.contour, contour))
    };
    let box_of = |contour: &Contour, step: usize| {
        let b = contour.bounding_box();
        (b.min.is_finite() && b.max.is_finite()).then(|| {
            CutBox::new(
                Rectangle::from_corners([b.min.x, b.min.y], [b.max.x, b.max.y]),
                step,
            )
        })
    };
    let mut earlier_boxes: HashMap<Option<ContourRef>, Vec<CutBox>> = HashMap::new();
    for step in 0..range.start.min(route.steps.len()) {
        if let Some((r, contour)) = constrained(step) {
            let region = earlier_boxes.entry(forest.parent(r)).or_default();
            region.extend(box_of(contour, step));
        }
    }
    let mut regions: HashMap<Option<ContourRef>, RTree<CutBox>> = earlier_boxes
        .into_iter()
        .map(|(region, boxes)| (region, RTree::bulk_load(boxes)))
        .collect();
    let mut out = Vec::new();
    for step in range {
        let Some((r, contour)) = constrained(step) else {
            continue;
        };
        let s = &route.steps[step];
        let parent = forest.parent(r);
        let earlier = regions.entry(parent).or_default();
        let no_free_edge = parent.is_some() && earlier.size() == 0;
        let own_box = box_of(contour, step);
        if no_free_edge {
            // A part in a hole with no free edge yet: the rule says nothing.
            if let Some(own) = own_box {
                earlier.insert(own);
            }
            continue;
        }
        let earlier: &RTree<CutBox> = earlier;
        let free = |q: Point| {
            let mut best = if parent.is_none() {
                layout.border_distance(q)
            } else {
                f64::INFINITY
            };
            for near in earlier.nearest_neighbor_iter(&[q.x, q.y]) {
                if near.geom().distance_2(&[q.x, q.y]).sqrt() >= best {
                    break;
                }
                if let Some(cut) = layout.nest.contour(route.steps[near.data].contour) {
                    best = best.min(cut.distance_to(q));
                }
            }
            best
        };
        let points: Vec<(Point, f64)> =
            samples(contour).into_iter().map(|q| (q, free(q))).collect();
        let best = points
            .iter()
            .copied()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((s.pierce_point, 0.0));
        out.push(Rigidity {
            step,
            contour: s.contour,
            points,
            best,
            here: free(s.pierce_point),
        });
        if let Some(own) = own_box {
            regions.entry(parent).or_default().insert(own);
        }
    }
    out
}

fn part_rigidity(layout: &Layout, route: &Route, params: &RuleParams) -> Vec<Violation> {
    part_rigidity_range(layout, route, params, 0..route.steps.len())
}

fn part_rigidity_range(
    layout: &Layout,
    route: &Route,
    params: &RuleParams,
    range: Range<usize>,
) -> Vec<Violation> {
    rigidity_range(layout, route, range)
        .into_iter()
        .filter(|r| r.here > r.best.1 + params.part_margin_mm)
        .map(|r| Violation::PartRigidity {
            step: r.step,
            contour: r.contour,
            excess_mm: r.here - r.best.1 - params.part_margin_mm,
            best: r.best.0,
        })
        .collect()
}

/// Per step of `route`, the pierce points the part rule admits for the route's order (sample
/// points of the contour, every ≤ 5 mm, within the margin of the free edge's nearest); `None`
/// where the rule does not constrain the step. Heat-aware relaxation under hard rules picks
/// among these: the forbidden pierce points of the dissertation's formalisation.
pub fn admissible_pierce_points(
    nest: &Nest,
    route: &Route,
    params: &RuleParams,
) -> Result<Vec<Option<Vec<Point>>>, ThermalError> {
    params.validate()?;
    check_steps(route, nest)?;
    let layout = Layout::new(nest);
    let mut out = vec![None; route.steps.len()];
    for r in rigidity(&layout, route) {
        let limit = r.best.1 + params.part_margin_mm;
        out[r.step] = Some(
            r.points
                .into_iter()
                .filter(|p| p.1 <= limit)
                .map(|p| p.0)
                .collect(),
        );
    }
    Ok(out)
}

/// Per unit: long and near a narrow border (rule 1).
fn rule1_units(layout: &Layout, params: &RuleParams) -> Vec<bool> {
    let s = layout.sheet_box;
    layout
        .units
        .iter()
        .map(|u| {
            let b = u.bbox;
            let (long_side, short_side) = (b.width().max(b.height()), b.width().min(b.height()));
            let long = long_side > 0.0 && long_side >= params.long_ratio * short_side;
            let gap = (b.min.x - s.min.x)
                .min(s.max.x - b.max.x)
                .min(b.min.y - s.min.y)
                .min(s.max.y - b.max.y);
            long && gap <= params.border_band_mm
        })
        .collect()
}

/// The start side rules 2 and 3 require, and which rule requires it.
fn required_side(layout: &Layout, params: &RuleParams) -> Option<(Side, u8, f64)> {
    let axis = layout.long_axis();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for u in &layout.units {
        lo = lo.min(along(u.bbox.min, axis));
        hi = hi.max(along(u.bbox.max, axis));
    }
    if !(lo < hi) {
        return None;
    }
    let mid = 0.5 * (lo + hi);
    let (s_lo, s_hi) = (
        along(layout.sheet_box.min, axis),
        along(layout.sheet_box.max, axis),
    );
    let length = s_hi - s_lo;
    let (gap_lo, gap_hi) = (lo - s_lo, s_hi - hi);
    if length > 0.0 && gap_lo.max(gap_hi) >= params.large_scrap_fraction * length {
        let side = if gap_hi >= gap_lo {
            Side::Low
        } else {
            Side::High
        };
        return Some((side, 2, mid));
    }
    let (mut p_lo, mut p_hi) = (0.0, 0.0);
    for u in &layout.units {
        if along(u.bbox.centre(), axis) < mid {
            p_lo += u.perimeter;
        } else {
            p_hi += u.perimeter;
        }
    }
    if (p_lo - p_hi).abs() <= params.heat_balance * (p_lo + p_hi) {
        return None;
    }
    Some((if p_lo > p_hi { Side::Low } else { Side::High }, 3, mid))
}

fn side_of(layout: &Layout, u: usize, mid: f64) -> Side {
    if along(layout.units[u].bbox.centre(), layout.long_axis()) < mid {
        Side::Low
    } else {
        Side::High
    }
}

fn sheet_rigidity(layout: &Layout, route: &Route, params: &RuleParams) -> Vec<Violation> {
    let steps = layout.root_steps(route);
    let long = rule1_units(layout, params);
    let mut violations = Vec::new();
    let first_other = (0..layout.units.len())
        .filter(|&u| !long[u])
        .filter_map(|u| steps[u].map(|s| (s, u)))
        .min();
    for (u, &is_long) in long.iter().enumerate() {
        if let (true, Some(step), Some((other, _))) = (is_long, steps[u], first_other) {
            if other < step {
                violations.push(Violation::LongPartLate {
                    step,
                    part: layout.units[u].root,
                });
            }
        }
    }
    if let (Some((required, rule, mid)), Some((step, u))) =
        (required_side(layout, params), first_other)
    {
        if side_of(layout, u, mid) != required {
            violations.push(Violation::WrongStartSide {
                step,
                part: layout.units[u].root,
                required,
                rule,
            });
        }
    }
    violations.sort_by_key(|v| match v {
        Violation::LongPartLate { step, .. } | Violation::WrongStartSide { step, .. } => *step,
        _ => 0,
    });
    violations
}

fn islands(layout: &Layout, route: &Route, params: &RuleParams) -> Vec<Violation> {
    let grid = IslandGrid::new(layout, params.strip_width_mm, params.max_grid_cells);
    island_violations(layout, route, &grid)
}

fn island_violations(layout: &Layout, route: &Route, grid: &IslandGrid) -> Vec<Violation> {
    let steps = layout.root_steps(route);
    let mut order: Vec<(usize, usize)> = steps
        .iter()
        .enumerate()
        .filter_map(|(u, s)| s.map(|s| (s, u)))
        .collect();
    order.sort();
    let units: Vec<usize> = order.iter().map(|&(_, u)| u).collect();
    // Each unit counts once, at the cut that first isolates it (by step, then unit).
    let mut isolated: Vec<(usize, usize)> = grid
        .first_islanded(&units)
        .into_iter()
        .enumerate()
        .filter_map(|(v, at)| at.map(|i| (order[i].0, v)))
        .collect();
    isolated.sort();
    isolated
        .into_iter()
        .map(|(step, v)| Violation::Island {
            step,
            part: layout.units[v].root,
        })
        .collect()
}

/// What [`enforce_rules`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct Enforced {
    /// The repaired route (a valid route stays valid: whole units move, pierce points stay on
    /// their contours).
    pub route: Route,
    /// Violations left (the repair is greedy; see [`enforce_rules`]).
    pub report: RuleReport,
}

/// Hard-rule mode as a repair of a finished route:
/// 1. sheet rule 1: the long parts near a narrow border move to the front (whole units, in
///    their order); rules 2/3: if the start is on the wrong side, the unit on the required side
///    nearest the route's start point moves to just after them;
/// 2. islands: units are replayed in order on the raster; when the next unit's cut would cut
///    off uncut units, those move before it (their cut cannot isolate anything the cut of the
///    unit would not), repeatedly; if the units isolate each other, the one isolating the
///    fewest goes first;
/// 3. part rigidity: each violating pierce point moves to the contour's point nearest the
///    free edge.
///
/// Moving whole units keeps "inner before outer". A step entered by a tool-on link whose
/// predecessor changes is entered by a pierce instead, and so is a linked step whose entry
/// point breaks part rigidity (with the link out of it: it left from the old point). The
/// violations left are reported, not hidden.
pub fn enforce_rules(
    nest: &Nest,
    route: &Route,
    rules: RuleSet,
    params: &RuleParams,
) -> Result<Enforced, ThermalError> {
    let mut repair = RuleRepair::new(route, rules, *params)?;
    loop {
        if let Some(enforced) = repair.advance(nest, web_time::Duration::MAX)? {
            return Ok(enforced);
        }
    }
}

/// [`enforce_rules`] in pieces, for a job that must answer Stop between slices (on Nest02/03
/// the repair took about a second in one piece): the sheet rule's reorder, the island raster's
/// build, the island replay a unit at a time, the part rule a range of steps at a time, then
/// the check of the repaired route as a [`RuleCheck`]. Call [`RuleRepair::advance`] with the
/// same nest until it returns the result, which is [`enforce_rules`]'s.
#[derive(Clone)]
pub struct RuleRepair {
    rules: RuleSet,
    params: RuleParams,
    route: Route,
    stage: RepairStage,
}

#[derive(Clone)]
enum RepairStage {
    Start,
    IslandGrid(Vec<usize>),
    Islands(Box<IslandReplay>),
    Reorder(Vec<usize>),
    Part {
        repaired: Route,
        from: usize,
        violations: Vec<Violation>,
    },
    Check(Route, RuleCheck),
    Done,
}

/// The island repair under way: the raster, the units still uncut, those to place (in order)
/// and those placed.
#[derive(Clone)]
struct IslandReplay {
    grid: IslandGrid,
    uncut: Vec<bool>,
    pending: Vec<usize>,
    done: Vec<usize>,
}

impl RuleRepair {
    /// A repair of `route` under `rules` with `params` (refused when a parameter is out of
    /// range).
    pub fn new(
        route: &Route,
        rules: RuleSet,
        params: RuleParams,
    ) -> Result<RuleRepair, ThermalError> {
        params.validate()?;
        Ok(RuleRepair {
            rules,
            params,
            route: route.clone(),
            stage: RepairStage::Start,
        })
    }

    /// Works on the repair for about `budget` (a piece at least); `Some` once done.
    pub fn advance(
        &mut self,
        nest: &Nest,
        budget: web_time::Duration,
    ) -> Result<Option<Enforced>, ThermalError> {
        let started = web_time::Instant::now();
        let layout = Layout::new(nest);
        let params = &self.params;
        let route = &self.route;
        loop {
            self.stage = match std::mem::replace(&mut self.stage, RepairStage::Done) {
                RepairStage::Start => {
                    check_steps(route, nest)?;
                    let units = sheet_order(&layout, route, self.rules, params);
                    if self.rules.islands {
                        RepairStage::IslandGrid(units)
                    } else {
                        RepairStage::Reorder(units)
                    }
                }
                RepairStage::IslandGrid(units) => RepairStage::Islands(Box::new(IslandReplay {
                    grid: IslandGrid::new(&layout, params.strip_width_mm, params.max_grid_cells),
                    uncut: vec![true; layout.units.len()],
                    pending: units,
                    done: Vec::new(),
                })),
                RepairStage::Islands(mut replay) => {
                    if replay.pending.is_empty() {
                        RepairStage::Reorder(replay.done)
                    } else {
                        replay.place_next();
                        RepairStage::Islands(replay)
                    }
                }
                RepairStage::Reorder(units) => RepairStage::Part {
                    repaired: reorder(&layout, route, &units),
                    from: 0,
                    violations: Vec::new(),
                },
                RepairStage::Part {
                    repaired,
                    from,
                    mut violations,
                } if self.rules.part && from < repaired.steps.len() => {
                    // The free edges depend on the order only, so the violations of the
                    // reordered route are found a range of steps at a time before any pierce
                    // point moves.
                    let to = (from + PART_STEPS_PER_PIECE).min(repaired.steps.len());
                    violations.extend(part_rigidity_range(&layout, &repaired, params, from..to));
                    RepairStage::Part {
                        repaired,
                        from: to,
                        violations,
                    }
                }
                RepairStage::Part {
                    mut repaired,
                    violations,
                    ..
                } => {
                    move_pierce_points(&mut repaired, violations);
                    RepairStage::Check(repaired, RuleCheck::new(self.rules, *params)?)
                }
                RepairStage::Check(repaired, mut check) => {
                    let left = budget.saturating_sub(started.elapsed());
                    match check.advance(nest, &repaired, left)? {
                        Some(report) => {
                            return Ok(Some(Enforced {
                                route: repaired,
                                report,
                            }))
                        }
                        None => RepairStage::Check(repaired, check),
                    }
                }
                RepairStage::Done => return Err(ThermalError::RepairFinished),
            };
            if started.elapsed() >= budget {
                return Ok(None);
            }
        }
    }
}

/// Step 1 of [`enforce_rules`]: the units in route order (by their root's step; units never
/// cut go last), with sheet rule 1's units first and rules 2/3's start moved.
fn sheet_order(layout: &Layout, route: &Route, rules: RuleSet, params: &RuleParams) -> Vec<usize> {
    let steps = layout.root_steps(route);
    let mut units: Vec<usize> = (0..layout.units.len()).collect();
    units.sort_by_key(|&u| (steps[u].unwrap_or(usize::MAX), u));
    if rules.sheet {
        let long = rule1_units(layout, params);
        let (mut order, rest): (Vec<usize>, Vec<usize>) = units.iter().partition(|&&u| long[u]);
        let mut rest = rest;
        if let (Some((required, _, mid)), Some(&first)) =
            (required_side(layout, params), rest.first())
        {
            if side_of(layout, first, mid) != required {
                let start = route.start;
                if let Some(pick) = rest
                    .iter()
                    .position(|&u| side_of(layout, u, mid) == required)
                    .map(|_| {
                        (0..rest.len())
                            .filter(|&i| side_of(layout, rest[i], mid) == required)
                            .min_by(|&a, &b| {
                                box_distance(&layout.units[rest[a]].bbox, start)
                                    .total_cmp(&box_distance(&layout.units[rest[b]].bbox, start))
                            })
                            .unwrap_or(0)
                    })
                {
                    let u = rest.remove(pick);
                    rest.insert(0, u);
                }
            }
        }
        order.extend(rest);
        units = order;
    }
    units
}

/// Step 3 of [`enforce_rules`]: each violating pierce point moves to the contour's point
/// nearest the free edge.
fn move_pierce_points(repaired: &mut Route, violations: Vec<Violation>) {
    for v in violations {
        let Violation::PartRigidity { step, best, .. } = v else {
            continue;
        };
        // A linked step starts where its link ends and the next link leaves from that
        // point (a chain leaves a contour where it entered it), so the chain chose the
        // point for the link's length, not for the rule. Under hard rules such a link is a
        // forbidden move: the contour is pierced at its rigid point instead, and the link
        // that left from the old point becomes a pierce where it ended.
        repaired.steps[step].entry = Entry::Pierce;
        repaired.steps[step].pierce_point = best;
        if let Some(next) = repaired.steps.get_mut(step + 1) {
            if matches!(next.entry, Entry::Link(_)) {
                next.entry = Entry::Pierce;
            }
        }
    }
}

impl IslandReplay {
    /// Places the next unit: the first pending one whose cut isolates nothing, after moving
    /// the units it would isolate to the front (repeatedly); if the units isolate each other,
    /// the one isolating the fewest.
    fn place_next(&mut self) {
        let IslandReplay {
            grid,
            uncut,
            pending,
            done,
        } = self;
        let mut tried: Vec<(usize, usize)> = Vec::new(); // (unit, islands it makes)
        let choice = loop {
            let u = pending[0];
            let saved = grid.save();
            grid.cut(u);
            uncut[u] = false;
            let isolated = grid.islanded(uncut);
            grid.restore(saved);
            uncut[u] = true;
            if isolated.is_empty() {
                break 0;
            }
            tried.push((u, isolated.len()));
            let fresh: Vec<usize> = isolated
                .iter()
                .copied()
                .filter(|v| !tried.iter().any(|t| t.0 == *v))
                .collect();
            if fresh.is_empty() || tried.len() > 8 {
                // They isolate each other: the least harmful first.
                let (best, _) = tried.iter().min_by_key(|t| t.1).copied().unwrap_or((u, 0));
                break pending.iter().position(|&p| p == best).unwrap_or(0);
            }
            // The isolated units go first, in their current order.
            let (mut front, back): (Vec<usize>, Vec<usize>) =
                pending.iter().partition(|p| fresh.contains(p));
            front.extend(back);
            *pending = front;
        };
        let u = pending.remove(choice);
        grid.cut(u);
        uncut[u] = false;
        done.push(u);
    }
}

/// The step indices of `indexed` ((unit rank, step) sorted) with every contour after the
/// contours inside it in the layout's forest: a step is held back until the steps of the
/// contours inside it are out, the rest keep their order. The route is valid under the
/// solvers' exact forest; the layout's forest (within the check tolerance) may also put a part
/// touching the hole it sits in inside that hole, and a route may have cut it after the hole.
fn inner_first(layout: &Layout, route: &Route, indexed: &[(usize, usize)]) -> Vec<usize> {
    let forest = &layout.forest;
    // Per forest index: how many steps of contours inside it are still to come.
    let mut waiting = vec![0usize; forest.len()];
    for &(_, i) in indexed {
        for a in forest.ancestors(route.steps[i].contour) {
            if let Some(k) = forest.index_of(a) {
                waiting[k] += 1;
            }
        }
    }
    let ready = |waiting: &[usize], i: usize| {
        forest
            .index_of(route.steps[i].contour)
            .is_none_or(|k| waiting[k] == 0)
    };
    let mut order = Vec::with_capacity(indexed.len());
    let mut held: Vec<usize> = Vec::new();
    let emit = |i: usize, waiting: &mut [usize], order: &mut Vec<usize>| {
        order.push(i);
        for a in forest.ancestors(route.steps[i].contour) {
            if let Some(k) = forest.index_of(a) {
                waiting[k] -= 1;
            }
        }
    };
    for &(_, i) in indexed {
        if !ready(&waiting, i) {
            held.push(i);
            continue;
        }
        emit(i, &mut waiting, &mut order);
        // Steps held back may be ready now (an outer contour once its last inner one is out).
        while let Some(pos) = held.iter().position(|&h| ready(&waiting, h)) {
            let h = held.remove(pos);
            emit(h, &mut waiting, &mut order);
        }
    }
    // Contours the forest cannot order (never the case for a route of its nest) keep theirs.
    order.extend(held);
    order
}

/// The route with its steps grouped by unit in `units` order (each unit's steps in their
/// original order); links whose predecessor changed become pierces.
fn reorder(layout: &Layout, route: &Route, units: &[usize]) -> Route {
    let mut rank = vec![usize::MAX; layout.units.len()];
    for (i, &u) in units.iter().enumerate() {
        rank[u] = i;
    }
    let unit_rank = |r: ContourRef| {
        layout
            .forest
            .index_of(r)
            .and_then(|i| rank.get(layout.unit_of[i]).copied())
            .unwrap_or(usize::MAX)
    };
    let mut indexed: Vec<(usize, usize)> = route
        .steps
        .iter()
        .enumerate()
        .map(|(i, s)| (unit_rank(s.contour), i))
        .collect();
    indexed.sort();
    let order = inner_first(layout, route, &indexed);
    let mut steps = Vec::with_capacity(route.steps.len());
    let mut previous: Option<usize> = None;
    for &i in &order {
        let mut s = route.steps[i].clone();
        if matches!(s.entry, Entry::Link(_)) && previous != Some(i.wrapping_sub(1)) {
            s.entry = Entry::Pierce;
        }
        previous = Some(i);
        steps.push(s);
    }
    Route {
        start: route.start,
        steps,
        finish: route.finish,
    }
}
