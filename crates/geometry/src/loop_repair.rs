//! The one repair of a contour that crosses or touches itself, applied by every reader that
//! leaves contours out (DXF, SVG, G-code loops) before [`Contour::check_cuttable`] decides.
//!
//! A path that returns to a point it already passed (a zero-chord curve, or a crossing) splits
//! there into two closed sub-loops. When one of them is no region worth a cut, by the same
//! measures as the one meaning of a contour, it is removed and the rest of the outline kept:
//! - its **extent is within the tolerance**: every point of it lies within the tolerance of the
//!   point where it leaves the outline, so cutting the outline without it moves the cut by no
//!   more than the reader already allows a join to move it; or
//! - it is a **sliver**: it does not cross itself and encloses less than
//!   `tolerance × perimeter / 2` (the area rule of [`Contour::check_cuttable`]), i.e. it is on
//!   average narrower than the tolerance — a spike or slit drawn out and back.
//!
//! Both are what CAD programs write on purpose or by rounding: a box generator's corner "burn"
//! curve at zero burn is a teardrop a twentieth of a millimetre across that touches the outline
//! at the corner; a kerf-compensated corner drawn by hand crosses itself in a tiny bow. A CAM
//! engineer cuts the outline and lets the kerf round the corner.
//!
//! Larger crossings (a figure-8, a bow-tie, two real lobes) are not repaired: which side of
//! each lobe is material is a question only the drawing's author can answer, so the contour is
//! left out with its crossing, as before. Splitting them into simple loops would invent
//! contours (the two lobes of a bow-tie cut as two parts) that nobody drew.
//!
//! Nest formats (geometry JSON, DBS, result JSON) do not repair: a nesting program never writes
//! such a contour, so they refuse it with its location.

use crate::{Contour, ContourFault, Point, Span, Vertex, WarningKind};

/// A sub-loop removed from a contour by [`Contour::without_small_loops`].
#[derive(Clone, Debug, PartialEq)]
pub struct RemovedLoop {
    /// Where the loop leaves the rest of the outline and comes back to it.
    pub at: Point,
    /// The loop's spans, from `at` back to `at`.
    pub spans: Vec<Span>,
    /// Its length, mm.
    pub length: f64,
    /// The area it encloses (unsigned), mm².
    pub area: f64,
    /// Why it was removed.
    pub reason: LoopReason,
}

/// Why a sub-loop was no region worth a cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopReason {
    /// Every point of it lies within the tolerance of where it leaves the outline.
    WithinTolerance,
    /// It encloses less than `tolerance × perimeter / 2`: narrower than the tolerance.
    Sliver,
}

/// A contour that passed [`Contour::check_cuttable`], possibly after small sub-loops were
/// removed.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopRepair {
    /// The cuttable contour.
    pub contour: Contour,
    /// What was removed, in the order it was found (empty: the contour was cuttable as drawn).
    pub removed: Vec<RemovedLoop>,
}

impl LoopRepair {
    /// The kind of a reader's warning for the removal: [`WarningKind::ZeroArea`] when every
    /// removed loop was a sliver (a spike or slit drawn out and back), otherwise
    /// [`WarningKind::SelfIntersecting`] (repaired, as its message says).
    pub fn warning_kind(&self) -> WarningKind {
        if !self.removed.is_empty() && self.removed.iter().all(|l| l.reason == LoopReason::Sliver) {
            WarningKind::ZeroArea
        } else {
            WarningKind::SelfIntersecting
        }
    }

    /// Total length (mm) of the removed loops.
    pub fn removed_length(&self) -> f64 {
        self.removed.iter().map(|l| l.length).sum()
    }

    /// What was removed and where, as a sentence for a reader's warning (without the place in
    /// the file); `None` when nothing was removed. Up to three loops are placed, then counted.
    pub fn describe(&self) -> Option<String> {
        let n = self.removed.len();
        if n == 0 {
            return None;
        }
        let length = self.removed_length();
        let mut out = format!(
            "{n} loop{} too small to cut ({length:.3} mm in all) removed where the outline \
             touches or crosses itself: ",
            if n == 1 { "" } else { "s" }
        );
        for (k, l) in self.removed.iter().take(3).enumerate() {
            if k > 0 {
                out.push_str(", ");
            }
            let why = match l.reason {
                LoopReason::WithinTolerance => "within the tolerance",
                LoopReason::Sliver => "narrower than the tolerance",
            };
            out.push_str(&format!(
                "at ({:.4}, {:.4}), {:.3} mm long, {why}",
                l.at.x, l.at.y, l.length
            ));
        }
        if n > 3 {
            out.push_str(&format!(" and {} more", n - 3));
        }
        out.push_str("; the rest of the outline is kept");
        Some(out)
    }

    /// The removed loops as closed polylines (arcs within `chord_tolerance`, and within
    /// 1/2000 of the loop's length, so that a loop far smaller than the tolerance keeps its
    /// shape and its length), for a warning's `left_out`.
    pub fn left_out(&self, chord_tolerance: f64) -> Vec<Vec<Point>> {
        self.removed
            .iter()
            .map(|l| crate::flatten_spans(&l.spans, chord_tolerance.min(l.length / 2000.0)))
            .collect()
    }
}

/// Most span visits (spans × crossing searches) one repair may spend: a real outline has at most
/// a few hundred small loops on a few thousand spans; a hostile contour of a million crossings
/// is left out instead of searched for minutes.
const REPAIR_WORK: usize = 1 << 23;

impl Contour {
    /// The contour made cuttable by removing the sub-loops that are no region worth a cut (see
    /// the module's rule, [`RemovedLoop`]), or the fault of [`Contour::check_cuttable`] when the
    /// contour as drawn fails for another reason or a crossing remains that is no such loop.
    ///
    /// ```
    /// use cutroute_geometry::{Contour, ContourFault, Vertex};
    /// // A 10 × 10 square whose corner (10, 10) carries a tiny loop out and back there.
    /// let square = Contour::new(vec![
    ///     Vertex::line(0.0, 0.0),
    ///     Vertex::line(10.0, 0.0),
    ///     Vertex::line(10.0, 10.0),
    ///     Vertex::line(10.02, 10.03),
    ///     Vertex::line(10.03, 10.0),
    ///     Vertex::line(10.0, 10.0),
    ///     Vertex::line(0.0, 10.0),
    /// ]);
    /// assert!(matches!(square.check_cuttable(0.05), Err(ContourFault::SelfIntersecting { .. })));
    /// let repaired = square.without_small_loops(0.05).unwrap();
    /// assert_eq!(repaired.removed.len(), 1);
    /// assert!((repaired.contour.area() - 100.0).abs() < 1e-9);
    /// ```
    pub fn without_small_loops(&self, tolerance: f64) -> Result<LoopRepair, ContourFault> {
        let fault = match self.check_cuttable(tolerance) {
            Ok(()) => {
                return Ok(LoopRepair {
                    contour: self.clone(),
                    removed: Vec::new(),
                })
            }
            Err(fault @ ContourFault::SelfIntersecting { .. }) => fault,
            Err(fault) => return Err(fault),
        };
        let tolerance = tolerance.max(0.0);
        let mut removed = Vec::new();
        let mut spans = without_touching_loops(self.spans().collect(), tolerance, &mut removed);
        let mut work = 0usize;
        loop {
            work += spans.len();
            if work > REPAIR_WORK {
                return Err(fault);
            }
            let contour = contour_of(&spans);
            let (first, second, at) = match contour.check_cuttable(tolerance) {
                Ok(()) => return Ok(LoopRepair { contour, removed }),
                Err(ContourFault::SelfIntersecting {
                    first_span,
                    second_span,
                    x,
                    y,
                }) => (first_span, second_span, Point::new(x, y)),
                Err(_) => return Err(fault),
            };
            let (inner, outer) = split_at(&spans, first, second, at);
            // The shorter loop is the one to remove when it can be; otherwise the longer one
            // (a sliver tail whose "rest" is the small real region), never both.
            let (short, long) = if perimeter(&inner) <= perimeter(&outer) {
                (inner, outer)
            } else {
                (outer, inner)
            };
            let (gone, rest, reason) = if let Some(reason) = removable(&short, at, tolerance) {
                (short, long, reason)
            } else if let Some(reason) = removable(&long, at, tolerance) {
                (long, short, reason)
            } else {
                return Err(fault);
            };
            if rest.len() < 2 {
                return Err(fault);
            }
            removed.push(removed_loop(gone, at, reason));
            spans = rest;
        }
    }
}

fn removed_loop(spans: Vec<Span>, at: Point, reason: LoopReason) -> RemovedLoop {
    RemovedLoop {
        at,
        length: perimeter(&spans),
        area: contour_of(&spans).area(),
        spans,
        reason,
    }
}

/// Two vertices this close (mm) are one point the path passes twice.
const SAME_POINT_MM: f64 = 1e-6;

/// The spans without the removable loops that leave and rejoin the outline at a vertex (the
/// path comes back to a vertex it already passed), found in one pass: each vertex is looked up
/// among the earlier ones still kept, so a contour of n spans costs O(n) here instead of a
/// crossing search per loop. Crossings away from vertices are left to that search.
fn without_touching_loops(
    spans: Vec<Span>,
    tolerance: f64,
    removed: &mut Vec<RemovedLoop>,
) -> Vec<Span> {
    let key = |p: Point| {
        (
            (p.x / SAME_POINT_MM).round() as i64,
            (p.y / SAME_POINT_MM).round() as i64,
        )
    };
    let Some(first) = spans.first().map(|s| s.start) else {
        return spans;
    };
    let mut kept: Vec<Span> = Vec::with_capacity(spans.len());
    // Where each point was last seen as a kept span's start.
    let mut seen: std::collections::HashMap<(i64, i64), usize> =
        std::collections::HashMap::with_capacity(spans.len());
    // The loop `kept[k..]` back to `p`, when `p` was passed at `kept[k]` and the loop may go.
    let mut close = |kept: &mut Vec<Span>,
                     seen: &std::collections::HashMap<(i64, i64), usize>,
                     p: Point,
                     least: usize| {
        let Some(&k) = seen.get(&key(p)) else { return };
        if k < least || k >= kept.len() || !(kept[k].start.distance(p) <= SAME_POINT_MM) {
            return;
        }
        let mut lp: Vec<Span> = kept[k..].to_vec();
        if let Some(last) = lp.last_mut() {
            last.end = kept[k].start;
        }
        if perimeter(&lp) <= SAME_POINT_MM {
            // No length: nothing drawn there.
            kept.truncate(k);
            return;
        }
        if let Some(reason) = removable(&lp, kept[k].start, tolerance) {
            let at = kept[k].start;
            kept.truncate(k);
            removed.push(removed_loop(lp, at, reason));
        }
    };
    for s in spans {
        close(&mut kept, &seen, s.start, 0);
        seen.insert(key(s.start), kept.len());
        kept.push(s);
    }
    // The closing return to the first vertex; the loop from it (k = 0) is the whole contour.
    close(&mut kept, &seen, first, 1);
    kept
}

fn perimeter(spans: &[Span]) -> f64 {
    spans.iter().map(Span::length).sum()
}

/// The closed contour through the spans' starts, without spans of no length.
fn contour_of(spans: &[Span]) -> Contour {
    Contour::new(
        spans
            .iter()
            .map(|s| Vertex {
                point: s.start,
                bulge: s.bulge,
            })
            .collect(),
    )
}

/// Whether a piece is rounding, not geometry: pieces cut off at a crossing that lies on a
/// span's end.
fn no_length(s: &Span) -> bool {
    let magnitude = s.start.x.abs().max(s.start.y.abs()).max(1.0);
    s.chord_length() <= 1e-12 * magnitude && s.length() <= 1e-12 * magnitude
}

/// The two closed loops into which spans `i < j` meeting at `at` split the contour: the one
/// through the spans between them, and the rest. Both start and end exactly at `at`; pieces of
/// no length (a crossing at a span's end) are dropped.
fn split_at(spans: &[Span], i: usize, j: usize, at: Point) -> (Vec<Span>, Vec<Span>) {
    let ti = spans[i].nearest_point(at).t;
    let tj = spans[j].nearest_point(at).t;
    let closed = |mut pieces: Vec<Span>| {
        if let Some(first) = pieces.first_mut() {
            first.start = at;
        }
        if let Some(last) = pieces.last_mut() {
            last.end = at;
        }
        pieces.retain(|s| !no_length(s));
        if let (Some(first), Some(last)) = (pieces.first().copied(), pieces.last_mut()) {
            last.end = first.start;
        }
        pieces
    };
    let mut inner = Vec::with_capacity(j - i + 1);
    inner.push(spans[i].sub_span(ti, 1.0));
    inner.extend_from_slice(&spans[i + 1..j]);
    inner.push(spans[j].sub_span(0.0, tj));
    let mut outer = Vec::with_capacity(spans.len() - (j - i) + 1);
    outer.push(spans[j].sub_span(tj, 1.0));
    outer.extend_from_slice(&spans[j + 1..]);
    outer.extend_from_slice(&spans[..i]);
    outer.push(spans[i].sub_span(0.0, ti));
    (closed(inner), closed(outer))
}

/// Why `spans` (a closed loop leaving the outline at `at`) may be removed, if it may.
fn removable(spans: &[Span], at: Point, tolerance: f64) -> Option<LoopReason> {
    if spans.is_empty() {
        return None;
    }
    if spans.iter().all(|s| farthest_on(s, at) <= tolerance) {
        return Some(LoopReason::WithinTolerance);
    }
    let lp = contour_of(spans);
    // A loop that crosses itself has a signed area that lobes cancel: no measure of width.
    if lp.area() < tolerance * perimeter(spans) / 2.0
        && lp.first_self_intersection_within(0.0).is_none()
    {
        return Some(LoopReason::Sliver);
    }
    None
}

/// The greatest distance from `p` to a point of the span: at an end, or for an arc at the point
/// of its circle opposite `p` when the arc passes there.
fn farthest_on(s: &Span, p: Point) -> f64 {
    let ends = s.start.distance(p).max(s.end.distance(p));
    if s.is_line() {
        return ends;
    }
    let Some(c) = s.centre() else { return ends };
    let v = c - p;
    let n = v.norm();
    let radius = s.radius();
    if !(n > 0.0) {
        return ends.max(radius);
    }
    let opposite = c + v * (radius / n);
    if s.nearest_point(opposite).distance <= 1e-9 * (1.0 + radius) {
        ends.max(n + radius)
    } else {
        ends
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOLERANCE: f64 = 0.05;

    fn line(x: f64, y: f64) -> Vertex {
        Vertex::line(x, y)
    }

    fn arc(x: f64, y: f64, bulge: f64) -> Vertex {
        Vertex {
            point: Point::new(x, y),
            bulge,
        }
    }

    /// The 10 × 10 square, counter-clockwise from the origin, with `corner` (the vertices of a
    /// loop from (10, 10) back to it) inserted at its corner (10, 10).
    fn square_with(corner: &[Vertex]) -> Contour {
        let mut v = vec![line(0.0, 0.0), line(10.0, 0.0)];
        v.extend_from_slice(corner);
        v.push(line(0.0, 10.0));
        Contour::new(v)
    }

    fn is_crossing(c: &Contour) -> bool {
        matches!(
            c.check_cuttable(TOLERANCE),
            Err(ContourFault::SelfIntersecting { .. })
        )
    }

    #[test]
    fn a_teardrop_touching_a_corner_is_removed_and_the_square_kept() {
        // Two arcs out to (10.03, 10.03) and back: a loop 0.042 mm across that touches the
        // outline only at the corner, as a box generator's corner curve at zero burn does.
        let teardrop = [
            arc(10.0, 10.0, 0.6),
            arc(10.03, 10.03, 0.6),
            line(10.0, 10.0),
        ];
        let contour = square_with(&teardrop);
        assert!(is_crossing(&contour));
        let repair = contour.without_small_loops(TOLERANCE).unwrap();
        assert_eq!(repair.removed.len(), 1);
        let gone = &repair.removed[0];
        assert_eq!(gone.reason, LoopReason::WithinTolerance);
        assert!(
            gone.at.distance(Point::new(10.0, 10.0)) < 1e-9,
            "{:?}",
            gone.at
        );
        assert_eq!(repair.contour.check_cuttable(TOLERANCE), Ok(()));
        assert!((repair.contour.area() - 100.0).abs() < 1e-9);
        assert!((repair.contour.perimeter() - 40.0).abs() < 1e-9);
        assert!((contour.perimeter() - 40.0 - gone.length).abs() < 1e-9);
        assert!(gone.area > 0.0 && gone.spans.len() == 2);
        // The warning's text places it, and its geometry keeps its length though the loop is
        // far smaller than a reader's flattening tolerance.
        let text = repair.describe().unwrap();
        assert!(text.starts_with("1 loop too small to cut"), "{text}");
        assert!(text.contains("at (10.0000, 10.0000)"), "{text}");
        let drawn = repair.left_out(0.01);
        assert_eq!(drawn.len(), 1);
        let length: f64 = drawn[0].windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!(
            (length - gone.length).abs() < 1e-3 * gone.length,
            "{length}"
        );
        assert!(drawn[0].first() == drawn[0].last());
    }

    #[test]
    fn a_teardrop_where_the_contour_starts_is_removed_too() {
        // The same loop, but the contour's first vertex lies on it: the loop wraps around the
        // closing span.
        let contour = Contour::new(vec![
            arc(10.03, 10.03, 0.6),
            line(10.0, 10.0),
            line(0.0, 10.0),
            line(0.0, 0.0),
            line(10.0, 0.0),
            arc(10.0, 10.0, 0.6),
        ]);
        assert!(is_crossing(&contour));
        let repair = contour.without_small_loops(TOLERANCE).unwrap();
        assert_eq!(repair.removed.len(), 1);
        assert!((repair.contour.area() - 100.0).abs() < 1e-9);
        assert!((repair.contour.perimeter() - 40.0).abs() < 1e-9);
    }

    #[test]
    fn a_tiny_crossing_bow_at_a_corner_is_removed_at_the_crossing() {
        // Up past the corner, across, and back along the top edge: the top edge crosses the
        // right one at (10, 10), 0.03 mm before their vertices.
        let bow = [line(10.0, 10.03), line(10.03, 10.0)];
        let contour = square_with(&bow);
        assert!(is_crossing(&contour));
        let repair = contour.without_small_loops(TOLERANCE).unwrap();
        assert_eq!(repair.removed.len(), 1);
        assert!(repair.removed[0].at.distance(Point::new(10.0, 10.0)) < 1e-9);
        assert_eq!(repair.contour.vertices.len(), 4);
        assert!((repair.contour.area() - 100.0).abs() < 1e-9);
    }

    #[test]
    fn a_spike_narrower_than_the_tolerance_is_removed_as_a_sliver() {
        // 5 mm out from the corner and back, 0.02 mm apart: far from the corner, but on
        // average narrower than the tolerance.
        let spike = [line(10.0, 10.0), line(15.0, 15.0), line(15.0, 14.98)];
        let contour = square_with(&[spike[0], spike[1], spike[2], line(10.0, 10.0)]);
        assert!(is_crossing(&contour));
        let repair = contour.without_small_loops(TOLERANCE).unwrap();
        assert_eq!(repair.removed.len(), 1);
        assert_eq!(repair.removed[0].reason, LoopReason::Sliver);
        assert!((repair.contour.area() - 100.0).abs() < 1e-9);
    }

    #[test]
    fn a_figure_eight_stays_left_out() {
        let bow_tie = Contour::new(vec![
            line(0.0, 0.0),
            line(10.0, 10.0),
            line(10.0, 0.0),
            line(0.0, 10.0),
        ]);
        let fault = bow_tie.check_cuttable(TOLERANCE).unwrap_err();
        assert_eq!(bow_tie.without_small_loops(TOLERANCE), Err(fault));
        // Unequal lobes, one of them small but no sliver and larger than the tolerance.
        let lopsided = Contour::new(vec![
            line(0.0, 0.0),
            line(10.0, 1.0),
            line(10.0, 0.0),
            line(0.0, 1.0),
        ]);
        assert!(is_crossing(&lopsided));
        assert!(lopsided.without_small_loops(TOLERANCE).is_err());
    }

    #[test]
    fn a_loop_larger_than_the_tolerance_is_not_removed() {
        // The same teardrop as above, 1 mm long: a region a cutter can cut, so the outline is
        // a real self-touching contour.
        let teardrop = [arc(10.0, 10.0, 0.6), arc(10.7, 10.7, 0.6), line(10.0, 10.0)];
        let contour = square_with(&teardrop);
        let fault = contour.check_cuttable(TOLERANCE).unwrap_err();
        assert!(matches!(fault, ContourFault::SelfIntersecting { .. }));
        assert_eq!(contour.without_small_loops(TOLERANCE), Err(fault));
    }

    #[test]
    fn cuttable_contours_and_other_faults_are_left_as_they_are() {
        let square = Contour::rectangle(0.0, 0.0, 10.0, 10.0);
        let repair = square.without_small_loops(TOLERANCE).unwrap();
        assert_eq!(repair.contour, square);
        assert!(repair.removed.is_empty());
        let slit = Contour::new(vec![line(0.0, 0.0), line(10.0, 0.0)]);
        assert_eq!(slit.without_small_loops(TOLERANCE), Err(ContourFault::Slit));
    }

    #[test]
    fn many_small_loops_on_one_outline_are_all_removed() {
        // A teardrop at every corner but the origin, each found in turn.
        let drop_at = |x: f64, y: f64, dx: f64, dy: f64| {
            [arc(x, y, 0.6), arc(x + dx, y + dy, 0.6), line(x, y)]
        };
        let mut v = vec![line(0.0, 0.0)];
        v.extend(drop_at(10.0, 0.0, 0.03, -0.03));
        v.extend(drop_at(10.0, 10.0, 0.03, 0.03));
        v.extend(drop_at(0.0, 10.0, -0.03, 0.03));
        let contour = Contour::new(v);
        let repair = contour.without_small_loops(TOLERANCE).unwrap();
        assert_eq!(repair.removed.len(), 3);
        assert!((repair.contour.area() - 100.0).abs() < 1e-9);
        assert!((repair.contour.perimeter() - 40.0).abs() < 1e-9);
    }
}
