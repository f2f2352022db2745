//! The kerf keeps off every contour: a tool-on span of the full cutting route (a piece of an
//! equidistant, a path's span) may come no closer than kerf/2 to any contour, or the kerf it
//! burns eats into that contour's part. One index and one test serve both route checkers
//! ([`crate::Route::problems`] on each step's cut, [`crate::PathRoute::problems`] on every
//! tool-on span) and the kerf job's refusal of nests whose parts sit closer than the kerf
//! ([`kerf_overlaps`]). A step's cut is held off every *other* contour (its own is the offset's
//! business, tested by the offset's properties); a path's span names no contour, so it is held
//! off every contour.
//!
//! A cut that keeps kerf/2 (less the tolerance) from every contour also never runs through
//! material: every point of an equidistant lies kerf/2 from its own contour on the scrap side,
//! so a contour between the two would come closer than kerf/2 to the cut.
//!
//! ```
//! use cutroute_geometry::{kerf_overlaps, Contour, Nest, Part, Vertex};
//! // Two 10 mm squares side by side, 1 mm apart: a 2 mm kerf round one eats into the other.
//! let square = |x: f64| Contour::new(vec![
//!     Vertex::line(x, 0.0),
//!     Vertex::line(x, 10.0),
//!     Vertex::line(x + 10.0, 10.0),
//!     Vertex::line(x + 10.0, 0.0),
//! ]);
//! let part = |x: f64| Part { name: "p".into(), contours: vec![square(x)] };
//! let close = Nest { sheet: None, parts: vec![part(0.0), part(11.0)] };
//! let pairs = kerf_overlaps(&close, 1.0, 1e-6);
//! assert_eq!(pairs.len(), 1);
//! assert!((pairs[0].gap - 1.0).abs() < 1e-9);
//! // 3 mm apart they leave room for the 2 mm kerf of both.
//! let apart = Nest { sheet: None, parts: vec![part(0.0), part(13.0)] };
//! assert!(kerf_overlaps(&apart, 1.0, 1e-6).is_empty());
//! ```

use std::collections::BTreeMap;

use rstar::{RTree, RTreeObject, AABB};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::{equidistant, BoundingBox, ContourRef, Nest, Point, Span};

/// R-tree entry: the box of one span of a contour.
struct SpanBox {
    envelope: AABB<[f64; 2]>,
    contour: usize,
    span: usize,
}

impl RTreeObject for SpanBox {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

fn aabb(b: &BoundingBox) -> AABB<[f64; 2]> {
    AABB::from_corners([b.min.x, b.min.y], [b.max.x, b.max.y])
}

/// Where a tool-on span comes too close to a contour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooClose {
    /// The contour it comes too close to.
    pub contour: ContourRef,
    /// The least distance between the span and that contour span, mm.
    pub distance: f64,
    /// A point of the tool-on span near where it comes closest.
    pub at: Point,
}

/// The spans of every contour of a nest in an R-tree: which contours a tool-on span comes
/// too close to, in time logarithmic in the nest's size.
pub struct ContourSpans {
    refs: Vec<ContourRef>,
    spans: Vec<Vec<Span>>,
    tree: RTree<SpanBox>,
}

impl ContourSpans {
    /// The index of `nest`'s contours.
    pub fn new(nest: &Nest) -> ContourSpans {
        let refs: Vec<ContourRef> = nest.contour_refs().collect();
        let spans: Vec<Vec<Span>> = refs
            .iter()
            .map(|&r| nest.contour(r).map_or(Vec::new(), |c| c.spans().collect()))
            .collect();
        let mut entries = Vec::new();
        for (c, contour) in spans.iter().enumerate() {
            for (s, span) in contour.iter().enumerate() {
                entries.push(SpanBox {
                    envelope: aabb(&span.bounding_box()),
                    contour: c,
                    span: s,
                });
            }
        }
        ContourSpans {
            refs,
            spans,
            tree: RTree::bulk_load(entries),
        }
    }

    /// Every contour span that `span` comes closer to than `clearance − tolerance` (kerf/2
    /// for the full cutting route), one item per contour span, in no particular order.
    pub fn too_close<'s>(
        &'s self,
        span: &'s Span,
        clearance: f64,
        tolerance: f64,
    ) -> impl Iterator<Item = TooClose> + 's {
        let reach = aabb(&span.bounding_box().expanded(clearance));
        self.tree
            .locate_in_envelope_intersecting(&reach)
            .filter_map(move |e| {
                let other = &self.spans[e.contour][e.span];
                let distance = span.distance_to_span(other);
                (distance < clearance - tolerance).then(|| TooClose {
                    contour: self.refs[e.contour],
                    distance,
                    at: span
                        .nearest_point(other.nearest_point(span.point_at(0.5)).point)
                        .point,
                })
            })
    }

    /// The least distance between contours `a` and `b`, searched within `limit` mm (infinity
    /// when they are further apart, or either is unknown).
    pub fn gap(&self, a: ContourRef, b: ContourRef, limit: f64) -> f64 {
        // `refs` are in `Nest::contour_refs` order, which is sorted.
        let (Ok(ia), Ok(ib)) = (self.refs.binary_search(&a), self.refs.binary_search(&b)) else {
            return f64::INFINITY;
        };
        let mut best = f64::INFINITY;
        for span in &self.spans[ia] {
            let reach = aabb(&span.bounding_box().expanded(limit));
            for e in self.tree.locate_in_envelope_intersecting(&reach) {
                if e.contour == ib {
                    best = best.min(span.distance_to_span(&self.spans[ib][e.span]));
                }
            }
        }
        best
    }

    /// Whether contour `a` lies wholly on contour `b`: the middle of each of its spans is
    /// within `reach` of `b` (a part in a hole of its own shape, stacked identical parts, however
    /// each is split into spans). Contours that merely touch, at a point or along a stretch,
    /// have a span whose middle is off the other. False when either is unknown.
    pub fn lies_on(&self, a: ContourRef, b: ContourRef, reach: f64) -> bool {
        let (Ok(ia), Ok(ib)) = (self.refs.binary_search(&a), self.refs.binary_search(&b)) else {
            return false;
        };
        let near_b = |p: Point| {
            let around = AABB::from_corners([p.x - reach, p.y - reach], [p.x + reach, p.y + reach]);
            self.tree.locate_in_envelope_intersecting(&around).any(|e| {
                e.contour == ib
                    && self.spans[ib][e.span].nearest_point(p).point.distance(p) <= reach
            })
        };
        let mut spans = self.spans[ia]
            .iter()
            .filter(|s| s.length() > 0.0)
            .peekable();
        spans.peek().is_some() && spans.all(|s| near_b(s.point_at(0.5)))
    }
}

/// The cut of `contour` on its equidistant at kerf/2 comes closer than kerf/2 to `other`: the
/// kerf eats into `other` (the two sit closer than the kerf, `gap` < kerf).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KerfOverlap {
    /// The contour whose cut comes too close.
    pub contour: ContourRef,
    /// The contour it comes too close to.
    pub other: ContourRef,
    /// The least distance from the cut to `other`, mm; for contours that touch or coincide
    /// (where the cut may keep kerf/2 from `other` by running on its far side), the contours'
    /// own distance.
    pub distance: f64,
    /// The least it may be: kerf/2, mm.
    pub required: f64,
    /// The gap between the two contours themselves, mm (less than the kerf).
    pub gap: f64,
    /// A point of the cut near where it comes closest to `other`.
    pub at: Point,
    /// The two contours lie on one another (see [`contours_on_one_another`]): the cut round
    /// each keeps kerf/2 from the other on its far side, yet one of them comes out a kerf off
    /// its line.
    #[serde(default)]
    pub on_one_another: bool,
}

/// The contours each cut of `cuts` (contour, its tool-on spans) comes closer than
/// `half − tolerance` to, as [`KerfOverlap`]s with the least distance per pair. Each unordered
/// pair of contours is reported once, in the direction first found. Pairs in `seen` are skipped
/// (a caller marks `(contour, contour)` to leave the contour's own out), and the reported ones
/// added to it.
pub(crate) fn cut_overlaps<'a>(
    index: &ContourSpans,
    contour: ContourRef,
    spans: impl IntoIterator<Item = &'a Span>,
    half: f64,
    tolerance: f64,
    seen: &mut std::collections::BTreeSet<(ContourRef, ContourRef)>,
) -> Vec<KerfOverlap> {
    let mut nearest: BTreeMap<ContourRef, TooClose> = BTreeMap::new();
    for span in spans {
        for hit in index.too_close(span, half, tolerance) {
            let key = (contour.min(hit.contour), contour.max(hit.contour));
            if seen.contains(&key) {
                continue;
            }
            let best = nearest.entry(hit.contour).or_insert(hit);
            if hit.distance < best.distance {
                *best = hit;
            }
        }
    }
    nearest
        .into_values()
        .map(|hit| {
            seen.insert((contour.min(hit.contour), contour.max(hit.contour)));
            KerfOverlap {
                contour,
                other: hit.contour,
                distance: hit.distance,
                required: half,
                // Every point of the cut is kerf/2 from its contour, so the two contours are
                // within distance + kerf/2 of each other.
                gap: index.gap(contour, hit.contour, hit.distance + half + tolerance),
                at: hit.at,
                on_one_another: false,
            }
        })
        .collect()
}

/// Every pair of distinct contours of `nest` where the cut of one on its equidistant at `half`
/// (kerf/2) comes closer than `half − tolerance` to the other: parts that sit closer than the
/// kerf, where no full cutting route exists (the kerf of one eats into its neighbour). Each
/// pair once; contours without an equidistant at `half` have no cut and are skipped (they have
/// no room, which the lead fitter reports). Empty for `half` 0. Contours that lie exactly on
/// one another escape this test ([`contours_on_one_another`] finds them; [`PartsTooClose::of`]
/// holds a nest to both).
pub fn kerf_overlaps(nest: &Nest, half: f64, tolerance: f64) -> Vec<KerfOverlap> {
    if !(half > 0.0) {
        return Vec::new();
    }
    let index = ContourSpans::new(nest);
    kerf_overlaps_in(&index, nest, half, tolerance, &mut Default::default())
}

fn kerf_overlaps_in(
    index: &ContourSpans,
    nest: &Nest,
    half: f64,
    tolerance: f64,
    seen: &mut std::collections::BTreeSet<(ContourRef, ContourRef)>,
) -> Vec<KerfOverlap> {
    let mut overlaps = Vec::new();
    for r in nest.contour_refs() {
        let Some(eq) = nest.contour(r).and_then(|c| equidistant(c, half).ok()) else {
            continue;
        };
        // Its own contour is no neighbour: mark it seen.
        seen.insert((r, r));
        let spans: Vec<Span> = eq.spans().collect();
        overlaps.extend(cut_overlaps(index, r, &spans, half, tolerance, seen));
    }
    overlaps
}

/// Every pair of distinct contours of `nest` that touch or lie on one another (closer than
/// `tolerance`), as [`KerfOverlap`]s with gap and distance their own distance and `required`
/// `half` (kerf/2), each pair once; [`KerfOverlap::on_one_another`] tells those lying wholly on
/// one another from those that touch. Where one contour lies exactly on another (a part in a
/// hole of its own shape, two identical parts stacked) the cut round one runs exactly kerf/2
/// from the other, on its far side, so [`kerf_overlaps`] sees no overlap; yet with a kerf the
/// slug of the hole *is* the part, and either the hole or the part is cut a kerf too large.
/// Without kerf a line shared by two contours is cut once per contour, which leaves both their
/// shape (the part in a hole of its shape is cut as the hole's slug and again as itself: one
/// more pierce and cut, nothing cut wrong).
pub fn contours_on_one_another(nest: &Nest, half: f64, tolerance: f64) -> Vec<KerfOverlap> {
    let index = ContourSpans::new(nest);
    let mut seen = std::collections::BTreeSet::new();
    let mut overlaps = Vec::new();
    for r in nest.contour_refs() {
        let Some(contour) = nest.contour(r) else {
            continue;
        };
        let spans: Vec<Span> = contour.spans().collect();
        overlaps.extend(touching(&index, r, &spans, half, tolerance, &mut seen));
    }
    overlaps
}

/// The contours that `contour` (its `spans`) touches or lies on, as [`contours_on_one_another`]
/// reports them; pairs in `seen` are skipped and the reported ones added to it.
pub(crate) fn touching(
    index: &ContourSpans,
    contour: ContourRef,
    spans: &[Span],
    half: f64,
    tolerance: f64,
    seen: &mut std::collections::BTreeSet<(ContourRef, ContourRef)>,
) -> Vec<KerfOverlap> {
    seen.insert((contour, contour));
    cut_overlaps(index, contour, spans, 2.0 * tolerance, tolerance, seen)
        .into_iter()
        .map(|touch| KerfOverlap {
            required: half,
            gap: touch.distance,
            on_one_another: index.lies_on(touch.contour, touch.other, 2.0 * tolerance)
                || index.lies_on(touch.other, touch.contour, 2.0 * tolerance),
            ..touch
        })
        .collect()
}

/// Parts that sit closer than the kerf: no cut on the equidistants keeps kerf/2 off the
/// neighbours, so the model has no route (the kerf job refuses such a nest up front).
#[derive(Clone, Debug, PartialEq, Error, Serialize, Deserialize)]
pub struct PartsTooClose {
    /// The kerf asked for, mm.
    pub kerf: f64,
    /// The pairs of contours closer than it (see [`kerf_overlaps`]).
    pub pairs: Vec<KerfOverlap>,
}

impl PartsTooClose {
    /// The refusal of `nest` under a kerf of `kerf`: the pairs of contours closer than the kerf
    /// ([`kerf_overlaps`]), then those that touch or lie on one another and escape that test
    /// ([`contours_on_one_another`]: a part in a hole of its own shape, stacked parts), each
    /// pair once. `None` when there are none, or for kerf 0 (without a kerf a shared line is
    /// cut once per contour, each part keeping its shape).
    pub fn of(nest: &Nest, kerf: f64, tolerance: f64) -> Option<PartsTooClose> {
        let half = kerf / 2.0;
        if !(half > 0.0) {
            return None;
        }
        let index = ContourSpans::new(nest);
        let mut seen = std::collections::BTreeSet::new();
        let mut pairs = kerf_overlaps_in(&index, nest, half, tolerance, &mut seen);
        // Contours lying on one another are found by the touching test below, unless the
        // offset's precision let the kerf's own test see them first.
        for p in pairs.iter_mut().filter(|p| p.gap < 2.0 * tolerance) {
            p.on_one_another = index.lies_on(p.contour, p.other, 2.0 * tolerance)
                || index.lies_on(p.other, p.contour, 2.0 * tolerance);
        }
        for r in nest.contour_refs() {
            let Some(contour) = nest.contour(r) else {
                continue;
            };
            let spans: Vec<Span> = contour.spans().collect();
            pairs.extend(touching(&index, r, &spans, half, tolerance, &mut seen));
        }
        (!pairs.is_empty()).then_some(PartsTooClose { kerf, pairs })
    }
}

/// How many pairs [`PartsTooClose`]'s message names before it counts the rest.
const PAIRS_NAMED: usize = 8;

impl std::fmt::Display for PartsTooClose {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "parts closer than the kerf of {} mm: no cut on the equidistants keeps kerf/2 off \
             its neighbour; {} pair(s) of contours: ",
            self.kerf,
            self.pairs.len()
        )?;
        for (i, p) in self.pairs.iter().take(PAIRS_NAMED).enumerate() {
            if i > 0 {
                write!(f, "; ")?;
            }
            write!(f, "{} and {} ", p.contour, p.other)?;
            // Touching parts are the common case (nests packed without spacing); parts lying
            // on one another (in a hole of their own shape, or stacked) are told apart.
            if p.on_one_another {
                write!(f, "lie on one another")?;
            } else if p.gap < 5e-4 {
                write!(f, "touch")?;
            } else {
                write!(f, "{:.3} mm apart", p.gap)?;
            }
            write!(f, " near ({:.3}, {:.3})", p.at.x, p.at.y)?;
        }
        if self.pairs.len() > PAIRS_NAMED {
            write!(f, "; and {} more", self.pairs.len() - PAIRS_NAMED)?;
        }
        Ok(())
    }
}
