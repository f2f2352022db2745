//! Nest-level queries and the containment forest: which contour lies inside which.
//!
//! The cutting rule "a contour must be cut before every contour that contains it" (holes
//! before their part, parts in a hole before the hole) is read off this forest.

use rstar::{RTree, RTreeObject, AABB};

use crate::{BoundingBox, Contour, ContourRef, Nest, Point};

impl Nest {
    /// Number of contours of the parts (the sheet excluded).
    pub fn contour_count(&self) -> usize {
        self.parts.iter().map(|p| p.contours.len()).sum()
    }

    /// Number of arc spans over the parts' contours (the sheet excluded).
    pub fn arc_count(&self) -> usize {
        self.parts
            .iter()
            .flat_map(|p| &p.contours)
            .map(Contour::arc_count)
            .sum()
    }

    /// Bounding box of the parts (the sheet excluded).
    pub fn bounding_box(&self) -> BoundingBox {
        self.parts
            .iter()
            .fold(BoundingBox::EMPTY, |b, p| b.union(p.bounding_box()))
    }

    /// The nest's size for tolerances: width plus height of the parts' box, at least 1 mm.
    pub fn scale(&self) -> f64 {
        let b = self.bounding_box();
        ((b.max.x - b.min.x).abs() + (b.max.y - b.min.y).abs()).max(1.0)
    }

    /// The distance under which solvers and checkers take two points of this nest as one:
    /// 10⁻⁶ of its [`scale`](Nest::scale), so rounding in files and arc maths never reads as a
    /// gap, and any real gap does.
    pub fn check_tolerance(&self) -> f64 {
        1e-6 * self.scale()
    }

    /// Orients every part contour by its depth in the nest's containment forest: even depth
    /// (outer contours, parts placed in holes) clockwise, odd depth (holes) counter-clockwise,
    /// as the DBS convention "material on the right" requires. The sheet is left alone.
    /// Returns how many contours were reversed.
    pub fn normalize_orientation(&mut self) -> usize {
        let forest = self.containment_forest();
        let depths: Vec<usize> = self
            .contour_refs()
            .map(|r| forest.depth(r).unwrap_or(0))
            .collect();
        crate::contour::orient_by_depth(
            self.parts
                .iter_mut()
                .flat_map(|p| p.contours.iter_mut())
                .zip(depths),
        )
    }

    /// The contour a reference points at, if it exists.
    pub fn contour(&self, r: ContourRef) -> Option<&Contour> {
        self.parts.get(r.part)?.contours.get(r.contour)
    }

    /// References to every contour of the parts, part by part, in file order.
    pub fn contour_refs(&self) -> impl Iterator<Item = ContourRef> + '_ {
        self.parts.iter().enumerate().flat_map(|(part, p)| {
            (0..p.contours.len()).map(move |contour| ContourRef { part, contour })
        })
    }

    /// The containment forest of the parts' contours (see [`ContainmentForest::new`]).
    pub fn containment_forest(&self) -> ContainmentForest {
        ContainmentForest::new(self)
    }
}

/// For every contour of a nest (sheet excluded): the smallest contour containing it (its
/// parent), the contours it directly contains (children) and its depth (0 for top level).
///
/// Contours are numbered by a flat *index* in [`Nest::contour_refs`] order; the methods take
/// and return [`ContourRef`]s.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContainmentForest {
    refs: Vec<ContourRef>,
    part_offsets: Vec<usize>,
    parent: Vec<Option<usize>>,
    children: Vec<Vec<ContourRef>>,
    depth: Vec<usize>,
    roots: Vec<ContourRef>,
}

/// What is known of a contour before building the forest.
struct ContourSummary {
    bbox: BoundingBox,
    area: f64,
    probe: Option<Point>,
}

/// R-tree entry: a contour's bounding box and flat index.
struct BoxEntry {
    envelope: AABB<[f64; 2]>,
    index: usize,
}

impl RTreeObject for BoxEntry {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

fn summarize(contour: &Contour) -> ContourSummary {
    let bbox = contour.bounding_box();
    let signed_area = contour.signed_area();
    let area = signed_area.abs();
    let probe = interior_probe(contour, signed_area).filter(|p| p.is_finite());
    let usable = probe.is_some()
        && area.is_finite()
        && !bbox.is_empty()
        && bbox.min.is_finite()
        && bbox.max.is_finite();
    ContourSummary {
        bbox,
        area: if usable { area } else { f64::NAN },
        probe: if usable { probe } else { None },
    }
}

/// The point that stands for `contour` in point-in-contour tests: just inside it, off the
/// middle of its longest span, so it lies on no other contour of a nest whose contours do not
/// cross. A span's own middle is not enough: a part fitted into another's notch, or placed in
/// a hole, shares spans with it, and a point on a shared span reads as inside either way.
/// The offset shrinks until the point is inside (a thin contour); a contour with no inside
/// (zero area) gets its first span's middle. `signed_area` is the contour's.
fn interior_probe(contour: &Contour, signed_area: f64) -> Option<Point> {
    let middle = || contour.span(0).map(|s| s.point_at(0.5));
    // The longest chord: no trigonometry, and an arc's tangent at its middle is its chord's
    // direction.
    let longest = contour.spans().max_by(|a, b| {
        a.chord()
            .norm_squared()
            .total_cmp(&b.chord().norm_squared())
    })?;
    let length = longest.chord().norm();
    if !(signed_area != 0.0 && length > 0.0 && length.is_finite()) {
        return middle();
    }
    let tangent = longest.chord() * (1.0 / length);
    // The inside is to the left of a counter-clockwise contour's direction of travel.
    let side = signed_area.signum();
    let inward = Point::new(-tangent.y, tangent.x) * side;
    let on = longest.point_at(0.5);
    let mut offset = 1e-3 * length;
    for _ in 0..6 {
        let probe = on + inward * offset;
        if contour.contains(probe) {
            return Some(probe);
        }
        offset *= 0.25;
    }
    middle()
}

/// Does contour `outer` contain contour `inner`? Strictly larger area (which keeps the
/// relation acyclic), box containment within `tolerance`, then the exact arc-aware point test
/// on inner's probe.
///
/// With a tolerance, boxes are compared within it because a part placed in a hole often
/// touches it: its edge lies on the hole's edge, and after the placement's rotation and
/// translation a rounding error may put it a hair outside (Nest02: part 119 sticks 2·10⁻⁵ mm
/// out of the hole of part 20 along the edge it shares). Compared exactly, such a part is a
/// top-level part.
fn contains(
    outer: &Contour,
    o: &ContourSummary,
    inner: &Contour,
    i: &ContourSummary,
    tolerance: f64,
) -> bool {
    let Some(probe) = i.probe else {
        return false;
    };
    if !(o.area > i.area && box_holds(&o.bbox, &i.bbox, tolerance)) {
        return false;
    }
    if tolerance > 0.0 {
        // The probe may lie on the shared edge, a rounding error outside: the first span
        // middle clear of the outer boundary decides (the contours do not cross).
        if let Some(p) = inner
            .spans()
            .map(|s| s.point_at(0.5))
            .find(|&p| p.is_finite() && outer.distance_to(p) > tolerance)
        {
            return outer.contains(p);
        }
    }
    outer.contains(probe)
}

/// Whether box `outer` contains box `inner` within `tolerance`.
fn box_holds(outer: &BoundingBox, inner: &BoundingBox, tolerance: f64) -> bool {
    outer.expanded(tolerance).contains_box(inner)
}

impl ContainmentForest {
    /// Builds the forest for the nest's parts (the sheet is ignored).
    ///
    /// Contours are assumed not to cross one another (as in any valid nest), so one point of
    /// a contour decides whether it lies inside another. Candidates come from an R-tree of
    /// bounding boxes, and are tried from the smallest area up; the first that contains the
    /// contour is its parent. Contours with non-finite data become roots.
    pub fn new(nest: &Nest) -> Self {
        Self::with_tolerance(nest, 0.0)
    }

    /// [`ContainmentForest::new`] with the contours' boxes compared within `tolerance` (see
    /// [`contains`]): a part placed in a hole and touching it, its shared edge a rounding error
    /// outside the hole's, is inside the hole. The thermal rules group parts into units by
    /// this forest (`cutroute-thermal`'s layout, with the nest's check tolerance), so their
    /// repair never moves such a part after the hole that drops it. The solvers' forest
    /// ([`ContainmentForest::new`]) stays exact: the segment plan takes a part sharing an edge
    /// with its parent hole for no common edge (SCCP/GSCCP lost their gains on Nest02/Nest03).
    pub fn with_tolerance(nest: &Nest, tolerance: f64) -> Self {
        let refs: Vec<ContourRef> = nest.contour_refs().collect();
        let contours: Vec<&Contour> = nest.parts.iter().flat_map(|p| &p.contours).collect();
        let summaries: Vec<ContourSummary> = contours.iter().map(|c| summarize(c)).collect();
        let entries: Vec<BoxEntry> = summaries
            .iter()
            .enumerate()
            .filter(|(_, s)| s.probe.is_some())
            .map(|(index, s)| BoxEntry {
                envelope: AABB::from_corners(
                    [s.bbox.min.x, s.bbox.min.y],
                    [s.bbox.max.x, s.bbox.max.y],
                ),
                index,
            })
            .collect();
        let tree = RTree::bulk_load(entries);
        let mut candidates: Vec<usize> = Vec::new();
        let parent: Vec<Option<usize>> = summaries
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let p = s.probe?;
                candidates.clear();
                candidates.extend(
                    tree.locate_in_envelope_intersecting(&AABB::from_corners(
                        [p.x - tolerance, p.y - tolerance],
                        [p.x + tolerance, p.y + tolerance],
                    ))
                    .map(|e| e.index)
                    .filter(|&j| {
                        j != i
                            && summaries[j].area > s.area
                            && box_holds(&summaries[j].bbox, &s.bbox, tolerance)
                    }),
                );
                candidates.sort_by(|&a, &b| {
                    summaries[a]
                        .area
                        .total_cmp(&summaries[b].area)
                        .then(a.cmp(&b))
                });
                candidates
                    .iter()
                    .copied()
                    .find(|&j| contains(contours[j], &summaries[j], contours[i], s, tolerance))
            })
            .collect();
        Self::from_parents(nest, refs, parent)
    }

    /// The same forest computed by testing every pair: O(n²), for checking [`Self::new`].
    pub fn brute_force(nest: &Nest) -> Self {
        Self::brute_force_with_tolerance(nest, 0.0)
    }

    /// [`ContainmentForest::brute_force`] for [`ContainmentForest::with_tolerance`].
    pub fn brute_force_with_tolerance(nest: &Nest, tolerance: f64) -> Self {
        let refs: Vec<ContourRef> = nest.contour_refs().collect();
        let contours: Vec<&Contour> = nest.parts.iter().flat_map(|p| &p.contours).collect();
        let summaries: Vec<ContourSummary> = contours.iter().map(|c| summarize(c)).collect();
        let parent = (0..contours.len())
            .map(|i| {
                (0..contours.len())
                    .filter(|&j| {
                        j != i
                            && contains(
                                contours[j],
                                &summaries[j],
                                contours[i],
                                &summaries[i],
                                tolerance,
                            )
                    })
                    .min_by(|&a, &b| {
                        summaries[a]
                            .area
                            .total_cmp(&summaries[b].area)
                            .then(a.cmp(&b))
                    })
            })
            .collect();
        Self::from_parents(nest, refs, parent)
    }

    fn from_parents(nest: &Nest, refs: Vec<ContourRef>, parent: Vec<Option<usize>>) -> Self {
        let mut part_offsets = Vec::with_capacity(nest.parts.len() + 1);
        let mut offset = 0;
        for p in &nest.parts {
            part_offsets.push(offset);
            offset += p.contours.len();
        }
        part_offsets.push(offset);
        let n = refs.len();
        let mut children = vec![Vec::new(); n];
        let mut roots = Vec::new();
        for (i, p) in parent.iter().enumerate() {
            match p {
                Some(p) => children[*p].push(refs[i]),
                None => roots.push(refs[i]),
            }
        }
        // Depth by walking up; parents have strictly larger area, so the walk ends.
        let mut depth = vec![usize::MAX; n];
        let mut chain = Vec::new();
        for start in 0..n {
            let mut i = start;
            let base = loop {
                if depth[i] != usize::MAX {
                    break depth[i] + 1;
                }
                chain.push(i);
                match parent[i] {
                    Some(p) => i = p,
                    None => break 0,
                }
            };
            // The chain runs from `start` up to the topmost node of unknown depth.
            let mut d = base;
            while let Some(j) = chain.pop() {
                depth[j] = d;
                d += 1;
            }
        }
        ContainmentForest {
            refs,
            part_offsets,
            parent,
            children,
            depth,
            roots,
        }
    }

    /// Number of contours in the forest.
    pub fn len(&self) -> usize {
        self.refs.len()
    }

    /// True when the nest has no contours.
    pub fn is_empty(&self) -> bool {
        self.refs.is_empty()
    }

    /// The flat index of a contour, if it belongs to the nest.
    pub fn index_of(&self, r: ContourRef) -> Option<usize> {
        let start = *self.part_offsets.get(r.part)?;
        let end = *self.part_offsets.get(r.part + 1)?;
        (start + r.contour < end).then_some(start + r.contour)
    }

    /// The contour with a flat index.
    pub fn contour_ref(&self, index: usize) -> Option<ContourRef> {
        self.refs.get(index).copied()
    }

    /// The smallest contour containing `r`, if any.
    pub fn parent(&self, r: ContourRef) -> Option<ContourRef> {
        self.parent[self.index_of(r)?].map(|p| self.refs[p])
    }

    /// The contours directly inside `r` (empty for unknown references).
    pub fn children(&self, r: ContourRef) -> &[ContourRef] {
        self.index_of(r).map_or(&[], |i| &self.children[i])
    }

    /// Nesting depth of `r`: 0 for a contour inside no other, 1 for a hole of such a part, …
    pub fn depth(&self, r: ContourRef) -> Option<usize> {
        self.index_of(r).map(|i| self.depth[i])
    }

    /// The greatest depth in the nest (0 for a nest without nesting or without contours).
    pub fn max_depth(&self) -> usize {
        self.depth.iter().copied().max().unwrap_or(0)
    }

    /// The contours inside no other.
    pub fn roots(&self) -> &[ContourRef] {
        &self.roots
    }

    /// The contours containing no other (the innermost ones, which CCP keeps in its step 1).
    pub fn leaves(&self) -> Vec<ContourRef> {
        (0..self.len())
            .filter(|&i| self.children[i].is_empty())
            .map(|i| self.refs[i])
            .collect()
    }

    /// Every contour containing `r`, from its parent outwards.
    pub fn ancestors(&self, r: ContourRef) -> impl Iterator<Item = ContourRef> + '_ {
        let mut current = self.index_of(r).and_then(|i| self.parent[i]);
        std::iter::from_fn(move || {
            let i = current?;
            current = self.parent[i];
            Some(self.refs[i])
        })
    }

    /// True when `outer` contains `inner` (at any depth), i.e. `inner` must be cut first.
    pub fn must_precede(&self, inner: ContourRef, outer: ContourRef) -> bool {
        self.ancestors(inner).any(|a| a == outer)
    }

    /// `(inner, parent)` pairs: each contour must be cut before its parent. Together with
    /// transitivity these imply every precedence constraint.
    pub fn precedence_pairs(&self) -> Vec<(ContourRef, ContourRef)> {
        (0..self.len())
            .filter_map(|i| self.parent[i].map(|p| (self.refs[i], self.refs[p])))
            .collect()
    }

    /// `(inner, ancestor)` pairs for every ancestor: the transitive closure of
    /// [`Self::precedence_pairs`].
    pub fn all_precedence_pairs(&self) -> Vec<(ContourRef, ContourRef)> {
        self.refs
            .iter()
            .flat_map(|&r| self.ancestors(r).map(move |a| (r, a)))
            .collect()
    }
}
