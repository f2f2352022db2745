//! A scrap region as an obstacle field: the contours a link inside it must not cross, and the
//! shortest link between two points of its boundary that crosses none of them.

use cutroute_geometry::float::Libm;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

use cutroute_geometry::{BoundingBox, Contour, ContourRef, Nest, Point, Span};

/// One contour bounding the region, with its box for quick rejection.
struct Obstacle<'a> {
    contour: &'a Contour,
    bbox: BoundingBox,
    /// The contour's spans with their boxes, so a link piece is tested only against spans
    /// near it.
    spans: Vec<(Span, BoundingBox)>,
    /// The region lies inside this contour (the hole the siblings sit in), not outside it.
    encloses_region: bool,
}

/// The contours bounding one scrap region: the siblings (the region lies outside them) and, for
/// a hole, the hole itself (the region lies inside it).
pub(crate) struct Region<'a> {
    obstacles: Vec<Obstacle<'a>>,
    /// Links keep this far (mm) from contours at their corners.
    clearance: f64,
    /// Tolerance (mm) for "this crossing is the link's own end point".
    end_tolerance: f64,
}

impl<'a> Obstacle<'a> {
    fn new(contour: &'a Contour, encloses_region: bool) -> Obstacle<'a> {
        Obstacle {
            contour,
            bbox: contour.bounding_box(),
            spans: contour.spans().map(|s| (s, s.bounding_box())).collect(),
            encloses_region,
        }
    }
}

impl<'a> Region<'a> {
    /// The region of `parent` (`None` = the sheet) whose children are `siblings`.
    pub(crate) fn new(
        nest: &'a Nest,
        parent: Option<ContourRef>,
        siblings: &[ContourRef],
        clearance: f64,
        end_tolerance: f64,
    ) -> Region<'a> {
        let mut obstacles: Vec<Obstacle<'a>> = siblings
            .iter()
            .filter_map(|&r| nest.contour(r))
            .map(|contour| Obstacle::new(contour, false))
            .collect();
        if let Some(contour) = parent.and_then(|p| nest.contour(p)) {
            obstacles.push(Obstacle::new(contour, true));
        }
        Region {
            obstacles,
            clearance,
            end_tolerance,
        }
    }

    /// `p` lies in the open region (inside the enclosing hole, outside every sibling).
    fn contains(local: &[&Obstacle], p: Point) -> bool {
        local.iter().all(|o| {
            let inside = o.bbox.contains_point(p) && o.contour.contains(p);
            inside == o.encloses_region
        })
    }

    /// The straight piece `a → b` stays in the region: it crosses no contour except at the
    /// link's own end points `ends`, and its middle lies in the region.
    fn sees(&self, local: &[&Obstacle], a: Point, b: Point, ends: [Point; 2]) -> bool {
        let reach = BoundingBox::from_corners(a, b).expanded(self.end_tolerance);
        let at_an_end = |x: Point| ends.iter().any(|e| e.distance(x) <= self.end_tolerance);
        for o in local {
            if !o.bbox.intersects(&reach) {
                continue;
            }
            let piece = Span::line(a, b);
            for (span, bbox) in &o.spans {
                if bbox.intersects(&reach)
                    && span
                        .intersections(&piece)
                        .iter()
                        .any(|x| !at_an_end(x.point))
                {
                    return false;
                }
            }
        }
        Self::contains(local, a.midpoint(b))
    }

    /// Corner points a shortest link may bend at, within the ellipse `|x−p| + |x−q| ≤ reach`:
    /// every vertex of every obstacle pushed `clearance` into the region, and points round every
    /// arc (at most 30° apart) far enough out that the chords between them clear the arc.
    fn corners(&self, local: &[&Obstacle], p: Point, q: Point, reach: f64) -> Vec<Point> {
        let ellipse = BoundingBox::from_corners(p, q).expanded(reach / 2.0);
        let mut corners = Vec::new();
        let in_ellipse = |x: Point| x.distance(p) + x.distance(q) <= reach;
        for o in local {
            if !o.bbox.intersects(&ellipse) {
                continue;
            }
            let spans: Vec<_> = o.contour.spans().collect();
            let n = spans.len();
            for i in 0..n {
                let (before, span) = (spans[(i + n - 1) % n], spans[i]);
                let v = span.start;
                // Shortest paths bend only round corners that stick out into the region: skip
                // vertices where the obstacle is locally flat or hollow as seen from it.
                let step = (before.length().min(span.length()) * 0.25).max(1e-9);
                let chord_middle = (v - before.tangent_at(1.0).normalized() * step)
                    .midpoint(v + span.tangent_at(0.0).normalized() * step);
                let sticks_out = o.contour.contains(chord_middle) != o.encloses_region
                    && o.contour.distance_to(chord_middle) > 1e-9 * (1.0 + step);
                if ellipse.contains_point(v) && sticks_out {
                    let normal = (before.tangent_at(1.0) + span.tangent_at(0.0))
                        .rotated_quarter()
                        .normalized();
                    let normal = if normal.is_finite() && normal.norm() > 0.5 {
                        normal
                    } else {
                        span.tangent_at(0.0).rotated_quarter().normalized()
                    };
                    for side in [1.0, -1.0] {
                        let x = v + normal * (side * self.clearance);
                        if in_ellipse(x) && Self::contains(local, x) {
                            corners.push(x);
                            break;
                        }
                    }
                }
                if span.is_line() {
                    continue;
                }
                let Some(centre) = span.centre() else {
                    continue;
                };
                let sweep = span.sweep().abs();
                let pieces = (sweep / (std::f64::consts::PI / 6.0)).ceil().max(1.0) as usize;
                let half = sweep / pieces as f64 / 2.0;
                let radius = span.radius();
                for k in 0..=pieces {
                    let on_arc = span.point_at(k as f64 / pieces as f64);
                    let out = (on_arc - centre).normalized();
                    // Outside the circle, the tangent polygon's corners at radius
                    // (r + c)/cos(half step) keep every chord clear; inside, the arc bows away.
                    for x in [
                        centre + out * ((radius + self.clearance) / half.cos_libm()),
                        centre + out * (radius - self.clearance).max(0.0),
                    ] {
                        if in_ellipse(x) && Self::contains(local, x) {
                            corners.push(x);
                        }
                    }
                }
            }
        }
        corners
    }

    /// The shortest polyline from `p` to `q` inside the region bending only at [`corners`], no
    /// longer than `reach`: its corners (without `p` and `q`) and length. `None` if there is
    /// none that short.
    pub(crate) fn shortest_link(
        &self,
        p: Point,
        q: Point,
        reach: f64,
    ) -> Option<(Vec<Point>, f64)> {
        let ends = [p, q];
        let direct = p.distance(q);
        if direct > reach {
            return None;
        }
        // Every point of a path no longer than `reach` lies in this box: only obstacles
        // meeting it matter (a sibling outside it cannot contain such a point either).
        let area = BoundingBox::from_corners(p, q).expanded(reach / 2.0 + self.end_tolerance);
        let local: Vec<&Obstacle> = self
            .obstacles
            .iter()
            .filter(|o| o.bbox.intersects(&area))
            .collect();
        if self.sees(&local, p, q, ends) {
            return Some((Vec::new(), direct));
        }
        let mut nodes = vec![p, q];
        nodes.extend(self.corners(&local, p, q, reach));
        // A* over the visibility graph, edges tested lazily when a node is settled.
        let n = nodes.len();
        let mut best = vec![f64::INFINITY; n];
        let mut from = vec![usize::MAX; n];
        let mut settled = vec![false; n];
        let mut heap = BinaryHeap::new();
        best[0] = 0.0;
        heap.push(Queued {
            estimate: direct,
            node: 0,
        });
        while let Some(Queued { estimate, node }) = heap.pop() {
            if settled[node] {
                continue;
            }
            settled[node] = true;
            if node == 1 {
                let mut corners = Vec::new();
                let mut at = from[1];
                while at != 0 {
                    corners.push(nodes[at]);
                    at = from[at];
                }
                corners.reverse();
                return Some((corners, best[1]));
            }
            if estimate > reach {
                return None;
            }
            for next in 1..n {
                if settled[next] {
                    continue;
                }
                let length = best[node] + nodes[node].distance(nodes[next]);
                let estimate = length + nodes[next].distance(q);
                if length >= best[next] || estimate > reach {
                    continue;
                }
                if !self.sees(&local, nodes[node], nodes[next], ends) {
                    continue;
                }
                best[next] = length;
                from[next] = node;
                heap.push(Queued {
                    estimate,
                    node: next,
                });
            }
        }
        None
    }
}

/// A node waiting in the A* queue, smallest estimate first.
struct Queued {
    estimate: f64,
    node: usize,
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Queued {}
impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        other.estimate.total_cmp(&self.estimate)
    }
}
