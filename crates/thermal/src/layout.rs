//! What the rules need to know about a nest once: the sheet, its long axis, and the *units* of
//! cutting — a part's outer contour (a root of the containment forest) with everything inside
//! it. Cutting a unit's root frees the part: from that step on its area is cut out of the sheet.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{BoundingBox, ContainmentForest, Contour, ContourRef, Nest, Point, Route};

/// A root contour and its subtree.
#[derive(Clone, Debug)]
pub(crate) struct Unit {
    /// The root (the part's outer contour).
    pub root: ContourRef,
    /// The root's bounding box.
    pub bbox: BoundingBox,
    /// Total perimeter of the unit's contours, mm: the cut length, hence the heat, it releases.
    pub perimeter: f64,
}

/// The sheet and the units of a nest.
pub(crate) struct Layout<'a> {
    pub nest: &'a Nest,
    pub forest: ContainmentForest,
    /// The sheet's outer contour, when the file has a sheet.
    pub sheet_contour: Option<&'a Contour>,
    /// The sheet's box (the parts' box when the file has no sheet).
    pub sheet_box: BoundingBox,
    pub units: Vec<Unit>,
    /// Per forest index: the index of the unit the contour belongs to.
    pub unit_of: Vec<usize>,
}

impl<'a> Layout<'a> {
    pub fn new(nest: &'a Nest) -> Layout<'a> {
        // Within the check tolerance: a part touching the hole it sits in belongs to the
        // hole's unit (it drops with the hole's slug), so a repair that moves whole units
        // never cuts it after the hole.
        let forest = ContainmentForest::with_tolerance(nest, nest.check_tolerance());
        let sheet_contour = nest
            .sheet
            .as_ref()
            .and_then(|s| s.contours.first())
            .filter(|c| !c.vertices.is_empty());
        let sheet_box = match sheet_contour {
            Some(c) => c.bounding_box(),
            None => nest.bounding_box(),
        };
        let mut units: Vec<Unit> = forest
            .roots()
            .iter()
            .map(|&root| Unit {
                root,
                bbox: nest
                    .contour(root)
                    .map_or(BoundingBox::from_points([]), Contour::bounding_box),
                perimeter: 0.0,
            })
            .collect();
        let mut unit_of = vec![usize::MAX; forest.len()];
        for (u, unit) in units.iter().enumerate() {
            if let Some(i) = forest.index_of(unit.root) {
                unit_of[i] = u;
            }
        }
        for r in nest.contour_refs() {
            let Some(i) = forest.index_of(r) else {
                continue;
            };
            let root = forest.ancestors(r).last().unwrap_or(r);
            let u = forest.index_of(root).map_or(usize::MAX, |ri| unit_of[ri]);
            unit_of[i] = u;
            if let (Some(unit), Some(c)) = (units.get_mut(u), nest.contour(r)) {
                unit.perimeter += c.perimeter();
            }
        }
        Layout {
            nest,
            forest,
            sheet_contour,
            sheet_box,
            units,
            unit_of,
        }
    }

    /// Per unit, the step at which its root is cut (`None` when the route does not cut it).
    pub fn root_steps(&self, route: &Route) -> Vec<Option<usize>> {
        let mut steps = vec![None; self.units.len()];
        for (s, step) in route.steps.iter().enumerate() {
            if let Some(i) = self.forest.index_of(step.contour) {
                let u = self.unit_of[i];
                if u < steps.len() && self.units[u].root == step.contour && steps[u].is_none() {
                    steps[u] = Some(s);
                }
            }
        }
        steps
    }

    /// Distance from `p` to the sheet's border (to the box's sides without a sheet contour).
    pub fn border_distance(&self, p: Point) -> f64 {
        match self.sheet_contour {
            Some(c) => c.distance_to(p),
            None => {
                let b = &self.sheet_box;
                (p.x - b.min.x)
                    .min(b.max.x - p.x)
                    .min(p.y - b.min.y)
                    .min(b.max.y - p.y)
                    .max(0.0)
            }
        }
    }

    /// 0 when the sheet's long axis is x, 1 when it is y.
    pub fn long_axis(&self) -> usize {
        usize::from(self.sheet_box.height() > self.sheet_box.width())
    }
}

/// Coordinate `axis` (0 = x, 1 = y) of a point.
pub(crate) fn along(p: Point, axis: usize) -> f64 {
    if axis == 0 {
        p.x
    } else {
        p.y
    }
}

/// Distance from `p` to a box (0 inside).
pub(crate) fn box_distance(b: &BoundingBox, p: Point) -> f64 {
    let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
    let dy = (b.min.y - p.y).max(p.y - b.max.y).max(0.0);
    dx.hypot_libm(dy)
}

/// Candidate points of a contour: every ≤ 5 mm of arc length (at least 16, at most 400) and its
/// vertices.
pub(crate) fn samples(contour: &Contour) -> Vec<Point> {
    let perimeter = contour.perimeter();
    let n = ((perimeter / 5.0).ceil() as usize).clamp(16, 400);
    let mut points: Vec<Point> = (0..n)
        .filter_map(|k| contour.point_at_length(perimeter * k as f64 / n as f64))
        .collect();
    points.extend(contour.vertices.iter().map(|v| v.point));
    points
}
