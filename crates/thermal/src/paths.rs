//! The rules on routes of tool-on paths (segment cutting, common-edge routes): such a route
//! cuts a contour in pieces, possibly from several pierces, and a common edge once for two
//! contours, so it has no step per contour. Its *contour route* gives it one: each contour is
//! done when the last piece of it is cut (whole units are freed in that order, which is what
//! sheet rigidity and islands are about), and its cut *starts* where the first piece of it is
//! cut — the point the part rule asks to lie next to the free edge (the piece's midpoint stands
//! for it, off the junctions). A route of whole closed contours (standard cutting) is its own
//! contour route.

use cutroute_geometry::{ContourRef, CutStep, Nest, PathRoute, Point, Route, Span};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

/// Where and when each contour is cut by a path route: per contour, (last path, first path,
/// first point), in contour order; `None` for a contour no span lies on.
type Touches = Vec<Option<(usize, usize, Point)>>;

/// A contour span (with its contour's index) by its box widened by the tolerance.
type SpanBox = GeomWithData<Rectangle<[f64; 2]>, (usize, Span)>;

/// The contour route of `route` (see the module documentation): steps ordered by the path that
/// finishes each contour (then the deeper contour first, then the path that starts it), each
/// step's pierce point the pierce of
/// a whole contour's path, or else the midpoint of the contour's first piece cut (on the
/// contour, off the junctions); a span lies on a
/// contour when its midpoint is within `tolerance` mm of it, and a closed path as long as one
/// contour it lies on is that contour's alone. Contours no span lies on are left out (the path
/// route's own checker reports them).
pub fn contour_route_of_paths(nest: &Nest, route: &PathRoute, tolerance: f64) -> Route {
    let refs: Vec<ContourRef> = nest.contour_refs().collect();
    // Every contour span by its box: a point's contours are found in time logarithmic in the
    // nest's spans (measured against whole contours, a 20,000-vertex circle took a minute).
    let tree: RTree<SpanBox> = RTree::bulk_load(
        refs.iter()
            .enumerate()
            .filter_map(|(i, &r)| Some((i, nest.contour(r)?)))
            .flat_map(|(i, c)| c.spans().map(move |span| (i, span)))
            .filter_map(|(i, span)| {
                let b = span.bounding_box();
                (b.min.is_finite() && b.max.is_finite()).then(|| {
                    GeomWithData::new(
                        Rectangle::from_corners(
                            [b.min.x - tolerance, b.min.y - tolerance],
                            [b.max.x + tolerance, b.max.y + tolerance],
                        ),
                        (i, span),
                    )
                })
            })
            .collect(),
    );
    let mut touches: Touches = vec![None; refs.len()];
    // The contours within `tolerance` of `p` (a contour's distance is its nearest span's).
    let lying_on = |p: Point| -> Vec<usize> {
        let at = AABB::from_point([p.x, p.y]);
        let mut on: Vec<usize> = tree
            .locate_in_envelope_intersecting(&at)
            .filter(|hit| hit.data.1.distance_to(p) <= tolerance)
            .map(|hit| hit.data.0)
            .collect();
        on.sort_unstable();
        on.dedup();
        on
    };
    for (k, path) in route.paths.iter().enumerate() {
        let spans: Vec<Vec<usize>> = path.spans.iter().map(|s| lying_on(s.midpoint())).collect();
        // A closed path round one whole contour is that contour's cut alone, even where the
        // contour shares an edge with a neighbour (standard cutting cuts the edge again for
        // the neighbour): a route of whole contours is its own contour route. Coincident
        // contours (test0 has two) are all that path's.
        let length: f64 = path.spans.iter().map(|s| s.length()).sum();
        let closed = path.end().distance(path.pierce) <= tolerance;
        let whole: Vec<usize> = match spans.first() {
            Some(first) if closed => first
                .iter()
                .copied()
                .filter(|&i| {
                    spans.iter().all(|on| on.contains(&i))
                        && nest.contour(refs[i]).is_some_and(|c| {
                            (c.perimeter() - length).abs() <= tolerance * (1 + spans.len()) as f64
                        })
                })
                .collect(),
            _ => Vec::new(),
        };
        for (span, on) in path.spans.iter().zip(&spans) {
            // A whole contour starts at its pierce; a piece at its span's midpoint (on the
            // contour, and off the junctions where pieces meet, where a pierce would touch a
            // neighbour).
            let point = if whole.is_empty() {
                span.midpoint()
            } else {
                path.pierce
            };
            for &i in on.iter().filter(|i| whole.is_empty() || whole.contains(i)) {
                let t = touches[i].get_or_insert((k, k, point));
                t.0 = k;
            }
        }
    }
    let mut steps: Vec<(usize, usize, usize, Point)> = touches
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.map(|(last, first, point)| (last, first, i, point)))
        .collect();
    // Contours finished by one path: the inner ones first, as a contour route must cut them.
    let forest = nest.containment_forest();
    let depth = |i: usize| forest.depth(refs[i]).unwrap_or(0);
    steps.sort_by_key(|&(last, first, i, _)| (last, std::cmp::Reverse(depth(i)), first, i));
    Route {
        start: route.start,
        steps: steps
            .into_iter()
            .map(|(_, _, i, point)| {
                // On the contour itself: a merged common edge may lie a tolerance off it.
                let point = nest
                    .contour(refs[i])
                    .and_then(|c| c.nearest_point(point))
                    .map_or(point, |n| n.point);
                CutStep::pierced(refs[i], point)
            })
            .collect(),
        finish: route.finish,
    }
}
