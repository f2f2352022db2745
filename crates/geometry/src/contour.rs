//! Whole-contour geometry: orientation, area, perimeter, point-in-contour with true arcs,
//! nearest point, length parameterisation, self-intersection and flattening.

use crate::float::Libm;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::{BoundingBox, Contour, Part, Point, Span, SpanProjection, Transform, Vertex};

/// Why raw file points do not make a closed contour.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ClosureError {
    /// Fewer than two distinct vertices remain once the closing point is dropped.
    #[error("a contour needs at least 2 distinct vertices after dropping the closing point, got {count}")]
    TooFewPoints {
        /// Vertices that remained.
        count: usize,
    },
    /// A coordinate or bulge is NaN or infinite.
    #[error("point {index} has a non-finite coordinate or bulge")]
    NonFinite {
        /// Index of the offending raw point.
        index: usize,
    },
    /// The last point does not come back to the first.
    #[error("contour is open: its last point ({last_x}, {last_y}) is {gap} mm from its first ({first_x}, {first_y}), tolerance {tolerance} mm")]
    Open {
        /// Distance between the first and the last point.
        gap: f64,
        /// The tolerance that was exceeded.
        tolerance: f64,
        /// First point, x.
        first_x: f64,
        /// First point, y.
        first_y: f64,
        /// Last point, x.
        last_x: f64,
        /// Last point, y.
        last_y: f64,
    },
}

/// Why a contour is not a valid simple closed curve.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ContourError {
    /// Fewer than two vertices.
    #[error("a contour needs at least 2 vertices, got {count}")]
    TooFewVertices {
        /// Number of vertices.
        count: usize,
    },
    /// A coordinate or bulge is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate or bulge")]
    NonFinite {
        /// Index of the offending vertex.
        index: usize,
    },
    /// A span has zero length (two consecutive vertices coincide).
    #[error("span {span} has zero length")]
    ZeroLengthSpan {
        /// Index of the span (= its start vertex).
        span: usize,
    },
    /// Two spans cross or touch away from their shared vertex.
    #[error("spans {first_span} and {second_span} intersect at ({x}, {y})")]
    SelfIntersecting {
        /// The lower span index.
        first_span: usize,
        /// The higher span index.
        second_span: usize,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
    },
}

/// Why a contour is not one a machine can cut: the one meaning of a contour that every reader
/// applies ([`Contour::check_cuttable`]).
///
/// A cuttable contour is
/// - **closed** with at least 2 vertices and finite values (the type closes it implicitly);
/// - **not a slit**: two straight spans are a line drawn out and back, never a region, so a
///   contour needs 3 spans or an arc among its spans;
/// - **not self-intersecting**: no two spans cross or touch farther than the tolerance from the
///   vertex they share ([`Contour::first_self_intersection_within`]), since inside and outside, and so the side the kerf
///   goes to and which contour holds which, are undefined otherwise;
/// - **not a sliver**: its enclosed area is at least `tolerance × perimeter / 2`, i.e. the region
///   is on average at least one tolerance wide. A strip of width w and length L has area wL and
///   perimeter about 2L, so this refuses exactly the strips whose two sides lie within the
///   tolerance of each other: lines drawn twice that a join closed into a loop, a circle of
///   radius below the tolerance. The tolerance is the reader's (the join tolerance of a drawing,
///   the closure tolerance of a nest).
///
/// Readers of CAD drawings (DXF, SVG) and of G-code loops first remove the sub-loops too small
/// to cut where an outline touches or crosses itself ([`Contour::without_small_loops`], with a
/// warning), then leave a contour that still fails out with a
/// [`ReadWarning`](crate::ReadWarning) of the matching kind, since drawings commonly carry
/// them; readers of nest formats (geometry JSON, result JSON, DBS, T-FLEX, G-code) refuse the
/// file with the contour's location, since a nesting program never writes one on purpose.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ContourFault {
    /// Fewer than two vertices.
    #[error("a contour needs at least 2 vertices, got {count}")]
    TooFewVertices {
        /// Number of vertices.
        count: usize,
    },
    /// A coordinate or bulge is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate or bulge")]
    NonFinite {
        /// Index of the offending vertex.
        index: usize,
    },
    /// Two straight spans: a slit drawn out and back, enclosing nothing.
    #[error("the contour is a slit (two straight spans out and back) and encloses no area")]
    Slit,
    /// Two spans cross or touch away from their shared vertex.
    #[error(
        "the contour intersects itself: spans {first_span} and {second_span} meet at ({x}, {y})"
    )]
    SelfIntersecting {
        /// The lower span index (span i runs from vertex i to vertex i + 1).
        first_span: usize,
        /// The higher span index.
        second_span: usize,
        /// Where they meet, x.
        x: f64,
        /// Where they meet, y.
        y: f64,
    },
    /// The enclosed area is below `tolerance × perimeter / 2`: a sliver or a point.
    #[error("the contour encloses {area:.3e} mm², less than the {minimum:.3e} mm² of a region one tolerance wide along its {perimeter:.3} mm perimeter")]
    TooThin {
        /// The enclosed area, mm².
        area: f64,
        /// The least area allowed, mm².
        minimum: f64,
        /// The perimeter, mm.
        perimeter: f64,
    },
}

impl ContourFault {
    /// Whether the fault is that the contour encloses (next to) no area: a slit or a sliver,
    /// which CAD drawings carry as lines drawn twice.
    pub fn is_zero_area(&self) -> bool {
        matches!(self, Self::Slit | Self::TooThin { .. })
    }
}

/// A place on a contour: span index and arc-length parameter on that span.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContourPosition {
    /// Index of the span (= index of its start vertex).
    pub span: usize,
    /// Arc-length fraction along that span, in `[0, 1]`.
    pub t: f64,
}

/// The point of a contour nearest to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContourProjection {
    /// Where on the contour.
    pub position: ContourPosition,
    /// The nearest point.
    pub point: Point,
    /// Its distance to the query point.
    pub distance: f64,
}

/// A point where a straight segment meets a contour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContourCrossing {
    /// Where on the contour.
    pub position: ContourPosition,
    /// The common point.
    pub point: Point,
    /// Its parameter along the segment (0 at its start, 1 at its end).
    pub segment_t: f64,
}

/// The first pair of spans (in index order) found crossing each other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfIntersection {
    /// The lower span index.
    pub first_span: usize,
    /// The higher span index.
    pub second_span: usize,
    /// A common point.
    pub point: Point,
}

impl Contour {
    /// Builds a contour from raw file points whose last point repeats the first (as DBS and
    /// geometry JSON store them): the closing point is dropped (its bulge is meaningless).
    ///
    /// The contour is closed when the last point is within `tolerance` of the first (DBS
    /// readers often compare bitwise: pass 0). Otherwise [`ClosureError::Open`] tells by how
    /// much it is open.
    pub fn close_points(points: &[Vertex], tolerance: f64) -> Result<Contour, ClosureError> {
        if let Some(index) = points
            .iter()
            .position(|v| !v.point.is_finite() || !v.bulge.is_finite())
        {
            // The closing point's bulge is ignored, so a garbage value there is harmless.
            if !(index + 1 == points.len() && points[index].point.is_finite()) {
                return Err(ClosureError::NonFinite { index });
            }
        }
        let (Some(first), Some(last)) = (points.first(), points.last()) else {
            return Err(ClosureError::TooFewPoints { count: 0 });
        };
        let gap = first.point.distance(last.point);
        if points.len() < 2 || !(gap <= tolerance) {
            if points.len() < 2 {
                return Err(ClosureError::TooFewPoints {
                    count: points.len(),
                });
            }
            return Err(ClosureError::Open {
                gap,
                tolerance,
                first_x: first.point.x,
                first_y: first.point.y,
                last_x: last.point.x,
                last_y: last.point.y,
            });
        }
        let vertices = points[..points.len() - 1].to_vec();
        if vertices.len() < 2 {
            return Err(ClosureError::TooFewPoints {
                count: vertices.len(),
            });
        }
        Ok(Contour { vertices })
    }

    /// Builds a contour from vertices already known to be closed (say a DXF polyline with its
    /// "closed" flag), which may or may not repeat the first point at the end. Every vertex
    /// within `tolerance` of the next one (cyclically) is dropped, as its span has no length:
    /// that removes a repeated closing point and doubled points alike.
    pub fn from_closed_vertices(
        vertices: &[Vertex],
        tolerance: f64,
    ) -> Result<Contour, ClosureError> {
        if let Some(index) = vertices
            .iter()
            .position(|v| !v.point.is_finite() || !v.bulge.is_finite())
        {
            return Err(ClosureError::NonFinite { index });
        }
        let mut kept: Vec<Vertex> = Vec::with_capacity(vertices.len());
        for v in vertices {
            match kept.last_mut() {
                // The earlier vertex's span would have no length: the later one takes its place.
                Some(last) if last.point.distance(v.point) <= tolerance => *last = *v,
                _ => kept.push(*v),
            }
        }
        while kept.len() > 1 && kept[kept.len() - 1].point.distance(kept[0].point) <= tolerance {
            kept.pop();
        }
        if kept.len() < 2 {
            return Err(ClosureError::TooFewPoints { count: kept.len() });
        }
        Ok(Contour { vertices: kept })
    }

    /// A circle of the given radius as two semicircular spans (β = ±1), starting at the
    /// rightmost point; `clockwise` as outer contours run.
    pub fn circle(centre: Point, radius: f64, clockwise: bool) -> Contour {
        let bulge = if clockwise { -1.0 } else { 1.0 };
        Contour::new(vec![
            Vertex {
                point: Point::new(centre.x + radius, centre.y),
                bulge,
            },
            Vertex {
                point: Point::new(centre.x - radius, centre.y),
                bulge,
            },
        ])
    }

    /// Number of spans (equal to the number of vertices: the closing span is implicit).
    pub fn span_count(&self) -> usize {
        self.vertices.len()
    }

    /// The `i`-th span: from vertex `i` to vertex `i + 1` (wrapping to vertex 0).
    pub fn span(&self, i: usize) -> Option<Span> {
        let n = self.vertices.len();
        let v = self.vertices.get(i)?;
        let next = self.vertices[(i + 1) % n];
        Some(Span::new(v.point, next.point, v.bulge))
    }

    /// All spans in order, the closing one last.
    pub fn spans(&self) -> impl ExactSizeIterator<Item = Span> + '_ {
        let n = self.vertices.len();
        (0..n).map(move |i| {
            let v = self.vertices[i];
            Span::new(v.point, self.vertices[(i + 1) % n].point, v.bulge)
        })
    }

    /// Number of arc spans (non-zero bulge).
    pub fn arc_count(&self) -> usize {
        self.vertices.iter().filter(|v| v.bulge != 0.0).count()
    }

    /// Total length of the contour.
    pub fn perimeter(&self) -> f64 {
        self.spans().map(|s| s.length()).sum()
    }

    /// Signed enclosed area: positive for counter-clockwise contours (holes), negative for
    /// clockwise ones (outer contours). Note the DBS/Appendix Б convention is the opposite.
    pub fn signed_area(&self) -> f64 {
        let Some(origin) = self.vertices.first().map(|v| v.point) else {
            return 0.0;
        };
        self.spans().map(|s| s.area_term(origin)).sum()
    }

    /// Enclosed area, regardless of orientation.
    pub fn area(&self) -> f64 {
        self.signed_area().abs()
    }

    /// True when the contour runs clockwise (negative signed area), as outer contours do.
    pub fn is_clockwise(&self) -> bool {
        self.signed_area() < 0.0
    }

    /// Exact bounding box (arcs included with their axis extremes).
    pub fn bounding_box(&self) -> BoundingBox {
        self.spans()
            .fold(BoundingBox::EMPTY, |b, s| b.union(s.bounding_box()))
    }

    /// The same closed curve traversed the other way, by the DBS reversal rule: points in
    /// reverse order, and each new point's bulge is minus the bulge of the point that preceded
    /// it originally (here cyclically, since the closing span is implicit). The vertex that was
    /// last becomes first.
    pub fn reversed(&self) -> Contour {
        let n = self.vertices.len();
        let vertices = (0..n)
            .map(|k| {
                let old = n - 1 - k;
                let preceding = (old + n - 1) % n;
                Vertex {
                    point: self.vertices[old].point,
                    bulge: -self.vertices[preceding].bulge,
                }
            })
            .collect();
        Contour { vertices }
    }

    /// The contour mapped by `transform`; a reflection (negative determinant) negates every
    /// bulge, and so also flips the orientation.
    pub fn transformed(&self, transform: &Transform) -> Contour {
        let flip = transform.is_reflection();
        let vertices = self
            .vertices
            .iter()
            .map(|v| Vertex {
                point: transform.apply(v.point),
                bulge: if flip { -v.bulge } else { v.bulge },
            })
            .collect();
        Contour { vertices }
    }

    /// Winding number of the contour around `p` (+1 inside a counter-clockwise contour, −1
    /// inside a clockwise one, 0 outside), with true arcs.
    ///
    /// Counts signed crossings of the ray from `p` towards +x, with the half-open rule of
    /// Sunday's algorithm (an upward piece counts when it starts at or below `p` and ends above
    /// it). Arcs are first cut into pieces monotone in y; whether a piece passes east of `p` is
    /// decided from the piece's chord and the β-multiplied circle equation, so nearly straight
    /// arcs are exact too and no centre is needed. Points on the boundary get either value;
    /// NaN gives 0.
    pub fn winding_number(&self, p: Point) -> i32 {
        self.spans().map(|s| span_crossings(&s, p)).sum()
    }

    /// `p` lies inside the region the contour bounds (either orientation).
    pub fn contains(&self, p: Point) -> bool {
        self.winding_number(p) != 0
    }

    /// The point of the contour nearest to `p`. `None` for a contour without vertices.
    pub fn nearest_point(&self, p: Point) -> Option<ContourProjection> {
        let mut best: Option<ContourProjection> = None;
        for (i, s) in self.spans().enumerate() {
            let SpanProjection { t, point, distance } = s.nearest_point(p);
            if best.is_none_or(|b| distance < b.distance) {
                best = Some(ContourProjection {
                    position: ContourPosition { span: i, t },
                    point,
                    distance,
                });
            }
        }
        best
    }

    /// Distance from `p` to the contour (infinite for an empty contour).
    pub fn distance_to(&self, p: Point) -> f64 {
        self.nearest_point(p).map_or(f64::INFINITY, |n| n.distance)
    }

    /// The point at a position.
    pub fn point_at(&self, position: ContourPosition) -> Option<Point> {
        self.span(position.span).map(|s| s.point_at(position.t))
    }

    /// Arc length from vertex 0 along the contour to `position`.
    pub fn length_at(&self, position: ContourPosition) -> f64 {
        let before: f64 = self.spans().take(position.span).map(|s| s.length()).sum();
        before
            + self
                .span(position.span)
                .map_or(0.0, |s| s.length() * position.t)
    }

    /// The position at arc length `s` from vertex 0 in the contour's direction; `s` is taken
    /// modulo the perimeter, so negative values walk backwards. `None` for an empty contour.
    pub fn position_at_length(&self, s: f64) -> Option<ContourPosition> {
        if self.vertices.is_empty() {
            return None;
        }
        let perimeter = self.perimeter();
        if !(perimeter > 0.0) || !s.is_finite() || !perimeter.is_finite() {
            return Some(ContourPosition { span: 0, t: 0.0 });
        }
        let mut rest = s.rem_euclid(perimeter);
        let n = self.vertices.len();
        for (i, span) in self.spans().enumerate() {
            let l = span.length();
            if rest <= l || i + 1 == n {
                let t = if l > 0.0 {
                    (rest / l).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                return Some(ContourPosition { span: i, t });
            }
            rest -= l;
        }
        Some(ContourPosition { span: 0, t: 0.0 })
    }

    /// The point at arc length `s` from vertex 0 (modulo the perimeter). `None` for an empty
    /// contour.
    pub fn point_at_length(&self, s: f64) -> Option<Point> {
        self.position_at_length(s).and_then(|p| self.point_at(p))
    }

    /// The candidate pierce points of the discrete solvers: a point every `step` of arc length
    /// from vertex 0 in the contour's direction, and (with `with_vertices`) every vertex, in the
    /// order met; a point within 1e-9 of the one before (or, for the last, of the first) is not
    /// repeated. Never empty for a contour with vertices (vertex 0 at least). The discretisation
    /// (`cutroute-ccp`), the view's candidate dots and `cutroute inspect --step` all count these
    /// same points.
    pub fn candidate_points(&self, step: f64, with_vertices: bool) -> Vec<Point> {
        let mut out: Vec<Point> = Vec::new();
        let Some(first) = self.vertices.first() else {
            return out;
        };
        let push = |p: Point, out: &mut Vec<Point>| {
            if !out.last().is_some_and(|q| q.distance(p) < 1e-9) {
                out.push(p);
            }
        };
        if step > 0.0 && step.is_finite() {
            let mut next_at = 0.0;
            let mut walked = 0.0;
            for span in self.spans() {
                let length = span.length();
                if with_vertices {
                    push(span.start, &mut out);
                }
                while length > 0.0 && next_at <= walked + length {
                    push(span.point_at((next_at - walked) / length), &mut out);
                    next_at += step;
                }
                walked += length;
            }
            // The grid point at exactly the perimeter is vertex 0 again.
            if out.len() > 1 && out[0].distance(out[out.len() - 1]) < 1e-9 {
                out.pop();
            }
        }
        if out.is_empty() {
            out.push(first.point);
        }
        out
    }

    /// Every point where the segment `a → b` meets the contour, ordered along the segment
    /// (CCP step 4 takes the last one). A meeting at a vertex is reported once.
    pub fn segment_crossings(&self, a: Point, b: Point) -> Vec<ContourCrossing> {
        let segment = Span::line(a, b);
        let reach = BoundingBox::from_corners(a, b);
        let mut found: Vec<ContourCrossing> = Vec::new();
        for (span, s) in self.spans().enumerate() {
            if !s
                .bounding_box()
                .intersects(&reach.expanded(1e-9 * (1.0 + segment.length())))
            {
                continue;
            }
            for x in s.intersections(&segment) {
                found.push(ContourCrossing {
                    position: ContourPosition { span, t: x.t_self },
                    point: x.point,
                    segment_t: x.t_other,
                });
            }
        }
        found.sort_by(|p, q| p.segment_t.total_cmp(&q.segment_t));
        let tolerance = 1e-9 * (1.0 + segment.length() + a.x.abs().max(a.y.abs()));
        found.dedup_by(|later, earlier| later.point.distance(earlier.point) <= tolerance);
        found
    }

    /// The first crossing of two spans (lowest span pair in lexicographic order), ignoring the
    /// vertex that adjacent spans share. Spans are swept in order of their boxes' left edge,
    /// so a simple contour of n spans costs about O(n log n).
    pub fn first_self_intersection(&self) -> Option<SelfIntersection> {
        self.first_self_intersection_within(0.0)
    }

    /// [`Contour::first_self_intersection`], with meetings within `tolerance` (mm) of the vertex
    /// two spans share counted as that vertex: a file that rounds its numbers (an SVG's 32-bit
    /// floats, a DBS file's) moves a line tangent to an arc enough to cut the circle again
    /// √(2·R·rounding) from their vertex, which is no crossing at the reader's tolerance.
    pub fn first_self_intersection_within(&self, tolerance: f64) -> Option<SelfIntersection> {
        let spans: Vec<Span> = self.spans().collect();
        let n = spans.len();
        if n < 2 {
            return None;
        }
        let boxes: Vec<BoundingBox> = spans.iter().map(|s| s.bounding_box()).collect();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| boxes[a].min.x.total_cmp(&boxes[b].min.x));
        let mut best: Option<SelfIntersection> = None;
        for (k, &i) in order.iter().enumerate() {
            for &j in &order[k + 1..] {
                if !(boxes[j].min.x <= boxes[i].max.x) {
                    break;
                }
                if !boxes[i].intersects(&boxes[j]) {
                    continue;
                }
                let (lo, hi) = if i < j { (i, j) } else { (j, i) };
                if best.is_some_and(|b| (b.first_span, b.second_span) <= (lo, hi)) {
                    continue;
                }
                // Adjacent spans share a vertex (the end of one is the start of the other).
                // Meeting points next to it are rounding, e.g. of a line tangent to an arc.
                // A contour of two spans shares both its vertices between them.
                let shared = [
                    (hi == lo + 1).then_some(spans[hi].start),
                    (lo == 0 && hi == n - 1).then_some(spans[lo].start),
                ];
                // A line tangent to an arc at the shared vertex, once rounded, cuts the circle
                // again about √(2·R·rounding) away: that far is still "at the vertex".
                let lengths = spans[lo].length() + spans[hi].length();
                let magnitude = spans[lo].start.x.abs().max(spans[lo].start.y.abs());
                let near =
                    (1e-5 * lengths + (1e-14 * (1.0 + magnitude) * lengths).sqrt()).max(tolerance);
                for x in spans[lo].intersections(&spans[hi]) {
                    if !shared.iter().flatten().any(|v| v.distance(x.point) <= near) {
                        best = Some(SelfIntersection {
                            first_span: lo,
                            second_span: hi,
                            point: x.point,
                        });
                        break;
                    }
                }
            }
        }
        best
    }

    /// Checks the one meaning of a contour every reader applies (see [`ContourFault`]), with
    /// the reader's `tolerance` (mm) for how thin a region may be.
    ///
    /// ```
    /// use cutroute_geometry::{Contour, ContourFault, Vertex};
    /// assert!(Contour::rectangle(0.0, 0.0, 10.0, 10.0).check_cuttable(1e-3).is_ok());
    /// let slit = Contour::new(vec![Vertex::line(0.0, 0.0), Vertex::line(10.0, 0.0)]);
    /// assert_eq!(slit.check_cuttable(1e-3), Err(ContourFault::Slit));
    /// let bow_tie = Contour::new(vec![
    ///     Vertex::line(0.0, 0.0),
    ///     Vertex::line(10.0, 10.0),
    ///     Vertex::line(10.0, 0.0),
    ///     Vertex::line(0.0, 10.0),
    /// ]);
    /// assert!(matches!(bow_tie.check_cuttable(1e-3), Err(ContourFault::SelfIntersecting { .. })));
    /// ```
    pub fn check_cuttable(&self, tolerance: f64) -> Result<(), ContourFault> {
        let n = self.vertices.len();
        if n < 2 {
            return Err(ContourFault::TooFewVertices { count: n });
        }
        if let Some(index) = self
            .vertices
            .iter()
            .position(|v| !v.point.is_finite() || !v.bulge.is_finite())
        {
            return Err(ContourFault::NonFinite { index });
        }
        if n == 2 && self.vertices.iter().all(|v| v.bulge == 0.0) {
            return Err(ContourFault::Slit);
        }
        if let Some(x) = self.first_self_intersection_within(tolerance.max(0.0)) {
            return Err(ContourFault::SelfIntersecting {
                first_span: x.first_span,
                second_span: x.second_span,
                x: x.point.x,
                y: x.point.y,
            });
        }
        let area = self.area();
        let perimeter = self.perimeter();
        let minimum = tolerance.max(0.0) * perimeter / 2.0;
        // `!(a >= b)` also refuses a NaN area.
        if !(area >= minimum) || area == 0.0 {
            return Err(ContourFault::TooThin {
                area,
                minimum,
                perimeter,
            });
        }
        Ok(())
    }

    /// Checks that the contour is a usable simple closed curve: at least 2 vertices, finite
    /// values, no zero-length span, no self-intersection.
    pub fn validate(&self) -> Result<(), ContourError> {
        let n = self.vertices.len();
        if n < 2 {
            return Err(ContourError::TooFewVertices { count: n });
        }
        if let Some(index) = self
            .vertices
            .iter()
            .position(|v| !v.point.is_finite() || !v.bulge.is_finite())
        {
            return Err(ContourError::NonFinite { index });
        }
        if let Some(span) = self.spans().position(|s| s.chord().norm_squared() == 0.0) {
            return Err(ContourError::ZeroLengthSpan { span });
        }
        match self.first_self_intersection() {
            Some(x) => Err(ContourError::SelfIntersecting {
                first_span: x.first_span,
                second_span: x.second_span,
                x: x.point.x,
                y: x.point.y,
            }),
            None => Ok(()),
        }
    }

    /// The contour as a closed polyline (closing point not repeated) whose chords stay within
    /// `chord_tolerance` of every arc. Each arc is cut into at most 1024 pieces; a
    /// non-positive or NaN tolerance gives 1024 pieces per arc.
    pub fn flatten(&self, chord_tolerance: f64) -> Vec<Point> {
        let mut out = Vec::with_capacity(self.vertices.len());
        for s in self.spans() {
            out.push(s.start);
            if s.is_line() {
                continue;
            }
            let pieces = arc_pieces(&s, chord_tolerance);
            out.extend((1..pieces).map(|k| s.point_at(k as f64 / pieces as f64)));
        }
        out
    }
}

/// An open chain of spans as a polyline (its first point, then every span's end) whose chords
/// stay within `chord_tolerance` of every arc, as [`Contour::flatten`] cuts them.
pub fn flatten_spans(spans: &[Span], chord_tolerance: f64) -> Vec<Point> {
    let mut out = Vec::with_capacity(spans.len() + 1);
    let Some(first) = spans.first() else {
        return out;
    };
    out.push(first.start);
    for s in spans {
        if !s.is_line() {
            let pieces = arc_pieces(s, chord_tolerance);
            out.extend((1..pieces).map(|k| s.point_at(k as f64 / pieces as f64)));
        }
        out.push(s.end);
    }
    out
}

/// Signed crossings of the ray from `p` towards +x with one span (see
/// [`Contour::winding_number`]).
fn span_crossings(s: &Span, p: Point) -> i32 {
    if s.is_line() {
        return piece_crossing(s.start, s.end, p, None);
    }
    let bbox = s.bounding_box();
    if !(p.y >= bbox.min.y && p.y <= bbox.max.y && p.x <= bbox.max.x) {
        return 0;
    }
    // Inside the circle ⇔ β·(power of p) < 0, with the power taken in the robust form
    // β·(|q|² − L²/4) − ((1 − β²)/2)·cross(d, q), q = p − chord midpoint.
    let d = s.chord();
    let q = p - s.start.midpoint(s.end);
    let b = s.bulge;
    let power_times_beta =
        b * (q.norm_squared() - 0.25 * d.norm_squared()) - 0.5 * (1.0 - b * b) * d.cross(q);
    let inside_circle = power_times_beta * b < 0.0;
    let curve = Some((b > 0.0, inside_circle));
    // Cut at the points with a horizontal tangent: θ_d − φ/2 + tφ ≡ 0 (mod π).
    let phi = s.sweep();
    let theta = d.y.atan2_libm(d.x);
    let pi = std::f64::consts::PI;
    let mut cuts = [0.0f64; 5];
    let mut count = 1;
    let r = (0.5 * phi - theta).rem_euclid(pi);
    for k in 0..3 {
        let t = if phi > 0.0 {
            (r + k as f64 * pi) / phi
        } else {
            (r - pi - k as f64 * pi) / phi
        };
        if t > 0.0 && t < 1.0 {
            cuts[count] = t;
            count += 1;
        }
    }
    cuts[count] = 1.0;
    count += 1;
    cuts[1..count - 1].sort_by(f64::total_cmp);
    let mut total = 0;
    let mut previous = s.start;
    for &t in &cuts[1..count] {
        let next = if t == 1.0 { s.end } else { s.point_at(t) };
        total += piece_crossing(previous, next, p, curve);
        previous = next;
    }
    total
}

/// Crossing of the ray from `p` towards +x with a piece from `a` to `b`, monotone in y: a
/// segment (`curve == None`) or a circular arc given by (turns counter-clockwise, `p` strictly
/// inside its circle).
fn piece_crossing(a: Point, b: Point, p: Point, curve: Option<(bool, bool)>) -> i32 {
    let upward = a.y <= p.y && p.y < b.y;
    let downward = b.y <= p.y && p.y < a.y;
    if !upward && !downward {
        return 0;
    }
    let side = (b - a).cross(p - a);
    // `p` strictly west of the chord (the chord crosses the ray east of p).
    let west = if upward { side > 0.0 } else { side < 0.0 };
    let east_crossing = match curve {
        None => west,
        Some((ccw, inside_circle)) => {
            // A counter-clockwise arc bulges to the right of its chord: east when going up.
            let bulges_east = ccw == upward;
            if bulges_east {
                west || side == 0.0 || inside_circle
            } else {
                west && !inside_circle
            }
        }
    };
    match (east_crossing, upward) {
        (false, _) => 0,
        (true, true) => 1,
        (true, false) => -1,
    }
}

/// Reverses each contour whose orientation does not match its depth's parity (even depth
/// clockwise); returns how many were reversed.
pub(crate) fn orient_by_depth<'a>(
    contours: impl Iterator<Item = (&'a mut Contour, usize)>,
) -> usize {
    let mut reversed = 0;
    for (c, depth) in contours {
        let area = c.signed_area();
        let wrong = if depth.is_multiple_of(2) {
            area > 0.0
        } else {
            area < 0.0
        };
        if wrong {
            *c = c.reversed();
            reversed += 1;
        }
    }
    reversed
}

/// How many equal pieces keep the sagitta `R·(1 − cos(φ/2n))` within `tolerance`.
fn arc_pieces(s: &Span, tolerance: f64) -> usize {
    const MAX_PIECES: usize = 1024;
    let radius = s.radius();
    let phi = s.sweep().abs();
    if !(tolerance > 0.0) {
        return MAX_PIECES;
    }
    if !(radius > tolerance) {
        // A tiny arc: its sagitta (≤ R) is already within tolerance, but keep its shape.
        return if phi > std::f64::consts::PI { 2 } else { 1 };
    }
    let max_half_angle = (1.0 - tolerance / radius).acos_libm();
    let pieces = (phi / (2.0 * max_half_angle)).ceil();
    if pieces.is_nan() {
        return 1;
    }
    (pieces as usize).clamp(1, MAX_PIECES)
}

impl Part {
    /// Material area (mm²): the outer contour's enclosed area minus each hole's, whatever
    /// their stored orientation (real files store holes clockwise too). The contours after the
    /// first are taken as holes of it, as the model defines a part; 0 for a part without
    /// contours.
    pub fn area(&self) -> f64 {
        let mut contours = self.contours.iter();
        let outer = contours.next().map_or(0.0, Contour::area);
        outer - contours.map(Contour::area).sum::<f64>()
    }

    /// Total cut length (mm): the sum of every contour's perimeter.
    pub fn perimeter(&self) -> f64 {
        self.contours.iter().map(Contour::perimeter).sum()
    }

    /// Bounding box of the part (its outer contour's, plus any stray hole).
    pub fn bounding_box(&self) -> BoundingBox {
        self.contours
            .iter()
            .fold(BoundingBox::EMPTY, |b, c| b.union(c.bounding_box()))
    }

    /// Reverses the contours that break the DBS convention (material on the right): a contour
    /// inside an even number of the part's other contours (the outer one, an island in a hole)
    /// runs clockwise, one inside an odd number (a hole) counter-clockwise. Returns how many
    /// were reversed. Real files do break the convention (`test0`/`test1` of the shared data
    /// store every hole clockwise).
    pub fn normalize_orientation(&mut self) -> usize {
        let single = crate::Nest {
            sheet: None,
            parts: vec![self.clone()],
        };
        let forest = crate::ContainmentForest::brute_force(&single);
        let depths: Vec<usize> = (0..self.contours.len())
            .map(|contour| {
                forest
                    .depth(crate::ContourRef { part: 0, contour })
                    .unwrap_or(0)
            })
            .collect();
        orient_by_depth(self.contours.iter_mut().zip(depths))
    }

    /// The part mapped by `transform` (see [`Contour::transformed`]).
    pub fn transformed(&self, transform: &Transform) -> Part {
        Part {
            name: self.name.clone(),
            contours: self
                .contours
                .iter()
                .map(|c| c.transformed(transform))
                .collect(),
        }
    }
}
