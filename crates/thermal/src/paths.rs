//! The rules on routes of tool-on paths (segment cutting, common-edge routes): such a route
//! cuts a contour in pieces, possibly from several pierces, and a common edge once for two
//! contours, so it has no step per contour. Its *contour route* gives it one: each contour is
//! done when the last piece of it is cut (whole units are freed in that order, which is what
//! sheet rigidity and islands are about), and its cut *starts* where the first piece of it is
//! cut — the point the part rule asks to lie next to the free edge. A route of whole closed
//! contours (standard cutting) is its own contour route.

use cutroute_geometry::{ContourRef, CutStep, Nest, PathRoute, Point, Route};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

/// Where and when each contour is cut by a path route: per contour, (last path, first path,
/// first point), in contour order; `None` for a contour no span lies on.
type Touches = Vec<Option<(usize, usize, Point)>>;

/// The contour route of `route` (see the module documentation): steps ordered by the path that
/// finishes each contour (then the one that starts it), each step's pierce point where the
/// contour's first piece starts; a span lies on a contour when its midpoint is within
/// `tolerance` mm of it. Contours no span lies on are left out (the path route's own checker
/// reports them).
pub fn contour_route_of_paths(nest: &Nest, route: &PathRoute, tolerance: f64) -> Route {
    let refs: Vec<ContourRef> = nest.contour_refs().collect();
    let tree: RTree<GeomWithData<Rectangle<[f64; 2]>, usize>> = RTree::bulk_load(
        refs.iter()
            .enumerate()
            .filter_map(|(i, &r)| {
                let b = nest.contour(r)?.bounding_box();
                (b.min.is_finite() && b.max.is_finite()).then(|| {
                    GeomWithData::new(
                        Rectangle::from_corners(
                            [b.min.x - tolerance, b.min.y - tolerance],
                            [b.max.x + tolerance, b.max.y + tolerance],
                        ),
                        i,
                    )
                })
            })
            .collect(),
    );
    let mut touches: Touches = vec![None; refs.len()];
    for (k, path) in route.paths.iter().enumerate() {
        for span in &path.spans {
            let m = span.midpoint();
            let at = AABB::from_point([m.x, m.y]);
            for hit in tree.locate_in_envelope_intersecting(&at) {
                let i = hit.data;
                if nest
                    .contour(refs[i])
                    .is_some_and(|c| c.distance_to(m) <= tolerance)
                {
                    let t = touches[i].get_or_insert((k, k, span.start));
                    t.0 = k;
                }
            }
        }
    }
    let mut steps: Vec<(usize, usize, usize, Point)> = touches
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.map(|(last, first, point)| (last, first, i, point)))
        .collect();
    steps.sort_by_key(|&(last, first, i, _)| (last, first, i));
    Route {
        start: route.start,
        steps: steps
            .into_iter()
            .map(|(_, _, i, point)| CutStep::pierced(refs[i], point))
            .collect(),
        finish: route.finish,
    }
}
