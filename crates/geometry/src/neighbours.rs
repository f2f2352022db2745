//! The nearest groups of points: neighbour lists for the local searches over many objects
//! (segments with one or two representative points), by an R-tree instead of all pairs.

use rstar::primitives::GeomWithData;
use rstar::RTree;

use crate::Point;

/// For every group of `groups`, the `k` other groups nearest to it, nearest first, where the
/// distance between two groups is the least distance between a point of one and a point of the
/// other (among groups at the same distance, which come first is deterministic but not
/// specified). Groups without points have no neighbours and are no one's.
///
/// Each group's own points ask the R-tree for their nearest points until `k` other groups are
/// seen: a group nearer than the `k`-th is seen by the point of this group that is nearest to
/// it, so the union holds the `k` nearest (`O(n·k·log n)` for `n` groups of a few points,
/// where comparing all pairs took seconds on 10,000 segments).
///
/// ```
/// use cutroute_geometry::{nearest_groups, Point};
/// let groups = vec![
///     vec![Point::new(0.0, 0.0)],
///     vec![Point::new(10.0, 0.0), Point::new(1.0, 0.0)],
///     vec![Point::new(3.0, 0.0)],
/// ];
/// assert_eq!(nearest_groups(&groups, 1), vec![vec![1], vec![0], vec![1]]);
/// ```
pub fn nearest_groups(groups: &[Vec<Point>], k: usize) -> Vec<Vec<usize>> {
    let tree = RTree::bulk_load(
        groups
            .iter()
            .enumerate()
            .flat_map(|(g, points)| points.iter().map(move |p| GeomWithData::new([p.x, p.y], g)))
            .collect(),
    );
    let distance = |a: usize, b: usize| {
        groups[a]
            .iter()
            .flat_map(|p| groups[b].iter().map(move |q| p.distance(*q)))
            .fold(f64::INFINITY, f64::min)
    };
    (0..groups.len())
        .map(|a| {
            let mut candidates: Vec<usize> = Vec::new();
            for p in &groups[a] {
                let mut from_here: Vec<usize> = Vec::with_capacity(k);
                for item in tree.nearest_neighbor_iter(&[p.x, p.y]) {
                    if from_here.len() >= k {
                        break;
                    }
                    let b = item.data;
                    if b != a && !from_here.contains(&b) {
                        from_here.push(b);
                    }
                }
                for b in from_here {
                    if !candidates.contains(&b) {
                        candidates.push(b);
                    }
                }
            }
            let mut ranked: Vec<(f64, usize)> = candidates
                .into_iter()
                .map(|b| (distance(a, b), b))
                .collect();
            ranked.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            ranked.truncate(k);
            ranked.into_iter().map(|(_, b)| b).collect()
        })
        .collect()
}
