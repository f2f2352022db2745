//! Step 1 and the spatial structures: the flattened contour list of a nest, its containment
//! forest, the kept (innermost) and removed (outer) contours, a uniform grid, k-nearest
//! candidate lists and the nearest-neighbour construction.

use cutroute_geometry::{BoundingBox, ContourRef, Nest, Point, SplitMix64};

use crate::geom::Shape;

/// A uniform grid of boxes: each cell lists the items whose box overlaps it.
pub(crate) struct Grid {
    min: Point,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    /// A grid over `bounds` with about `per_cell` items per cell for `n` items.
    pub fn new(bounds: BoundingBox, n: usize, per_cell: f64) -> Grid {
        let w = (bounds.max.x - bounds.min.x).max(1e-6);
        let h = (bounds.max.y - bounds.min.y).max(1e-6);
        let cells_wanted = (n as f64 / per_cell).clamp(1.0, 4.0e6);
        let cell = (w * h / cells_wanted).sqrt().max(1e-6);
        let nx = ((w / cell).ceil() as usize).clamp(1, 4096);
        let ny = ((h / cell).ceil() as usize).clamp(1, 4096);
        let cell = (w / nx as f64).max(h / ny as f64);
        Grid {
            min: bounds.min,
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        }
    }
    fn ix(&self, x: f64) -> usize {
        (((x - self.min.x) / self.cell).floor().max(0.0) as usize).min(self.nx - 1)
    }
    fn iy(&self, y: f64) -> usize {
        (((y - self.min.y) / self.cell).floor().max(0.0) as usize).min(self.ny - 1)
    }
    fn range(&self, b: &BoundingBox) -> (usize, usize, usize, usize) {
        (
            self.ix(b.min.x),
            self.iy(b.min.y),
            self.ix(b.max.x),
            self.iy(b.max.y),
        )
    }
    pub fn insert(&mut self, id: u32, b: &BoundingBox) {
        let (x0, y0, x1, y1) = self.range(b);
        for y in y0..=y1 {
            for x in x0..=x1 {
                self.cells[y * self.nx + x].push(id);
            }
        }
    }
    /// Visits every cell overlapping `b`.
    pub fn cells_in(&self, b: &BoundingBox, mut f: impl FnMut(&[u32])) {
        let (x0, y0, x1, y1) = self.range(b);
        for y in y0..=y1 {
            for x in x0..=x1 {
                f(&self.cells[y * self.nx + x]);
            }
        }
    }

    /// Visits the cells of ring `r` around the cell range of `b` (ring 0 = the range itself);
    /// returns false when the ring lies wholly outside the grid.
    pub fn ring(&self, b: &BoundingBox, r: usize, mut f: impl FnMut(&[u32])) -> bool {
        let (bx0, by0, bx1, by1) = self.range(b);
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let r = r as isize;
        let (x0, y0, x1, y1) = (
            bx0 as isize - r,
            by0 as isize - r,
            bx1 as isize + r,
            by1 as isize + r,
        );
        // Ring r is wholly outside when ring r − 1 already covered the grid.
        if r > 0 && x0 < 0 && y0 < 0 && x1 >= nx && y1 >= ny {
            return false;
        }
        for y in y0.max(0)..=y1.min(ny - 1) {
            let row = y as usize * self.nx;
            if r == 0 || y == y0 || y == y1 {
                for x in x0.max(0)..=x1.min(nx - 1) {
                    f(&self.cells[row + x as usize]);
                }
            } else {
                if x0 >= 0 {
                    f(&self.cells[row + x0 as usize]);
                }
                if x1 < nx {
                    f(&self.cells[row + x1 as usize]);
                }
            }
        }
        true
    }
    /// Width of a cell.
    pub fn cell(&self) -> f64 {
        self.cell
    }
}

/// The contours of a nest prepared for CCP-Relax.
pub(crate) struct Problem {
    /// Every contour of the nest's parts (the sheet excluded), flattened.
    pub refs: Vec<ContourRef>,
    pub shapes: Vec<Shape>,
    /// The smallest contour containing each contour (the containment forest).
    pub parent: Vec<Option<usize>>,
    /// Flat ids of the innermost contours (step 1 keeps these).
    pub kept: Vec<usize>,
    /// Flat ids of the outer contours (restored in step 4).
    pub removed: Vec<usize>,
    /// Bounds of all contours, the start and the finish.
    pub bounds: BoundingBox,
}

impl Problem {
    pub fn new(nest: &Nest, start: Point, finish: Option<Point>) -> Problem {
        let mut refs = Vec::new();
        let mut shapes = Vec::new();
        for (pi, part) in nest.parts.iter().enumerate() {
            for (ci, c) in part.contours.iter().enumerate() {
                if c.vertices.is_empty() {
                    continue;
                }
                refs.push(ContourRef {
                    part: pi,
                    contour: ci,
                });
                shapes.push(Shape::new(c));
            }
        }
        let mut bounds = BoundingBox::EMPTY;
        for s in &shapes {
            bounds = bounds.union(s.bbox);
        }
        bounds = bounds.including(start);
        if let Some(f) = finish {
            bounds = bounds.including(f);
        }
        let parent = containment_parents(nest, &refs);
        let mut has_child = vec![false; shapes.len()];
        for p in parent.iter().flatten() {
            has_child[*p] = true;
        }
        let kept = (0..shapes.len()).filter(|&i| !has_child[i]).collect();
        let removed = (0..shapes.len()).filter(|&i| has_child[i]).collect();
        Problem {
            refs,
            shapes,
            parent,
            kept,
            removed,
            bounds,
        }
    }

    /// All containment pairs `(inner, outer)` of the forest (transitively closed).
    pub fn precedence_pairs(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for i in 0..self.shapes.len() {
            let mut p = self.parent[i];
            while let Some(a) = p {
                out.push((i, a));
                p = self.parent[a];
            }
        }
        out
    }
}

/// For each contour of `refs`, the smallest contour whose region contains it: the geometry
/// crate's containment forest (exact arc-aware point test), in `refs` numbering.
fn containment_parents(nest: &Nest, refs: &[ContourRef]) -> Vec<Option<usize>> {
    let forest = nest.containment_forest();
    // `refs` skips contours without vertices, so the forest's flat numbering can differ.
    let mut part_offsets = Vec::with_capacity(nest.parts.len());
    let mut offset = 0;
    for part in &nest.parts {
        part_offsets.push(offset);
        offset += part.contours.len();
    }
    let mut index = vec![usize::MAX; offset];
    for (i, r) in refs.iter().enumerate() {
        index[part_offsets[r.part] + r.contour] = i;
    }
    refs.iter()
        .map(|&r| {
            forest
                .parent(r)
                .map(|p| index[part_offsets[p.part] + p.contour])
                .filter(|&p| p != usize::MAX)
        })
        .collect()
}

/// For each item, up to `k` others nearest by box gap (ties by centre distance).
pub(crate) fn nearest_lists(boxes: &[BoundingBox], bounds: BoundingBox, k: usize) -> Vec<Vec<u32>> {
    let n = boxes.len();
    let mut grid = Grid::new(bounds, n, 2.0);
    for (i, b) in boxes.iter().enumerate() {
        grid.insert(i as u32, b);
    }
    let mut stamp = vec![usize::MAX; n];
    let mut out = Vec::with_capacity(n);
    let mut cand: Vec<(f64, f64, u32)> = Vec::new();
    for (i, bi) in boxes.iter().enumerate() {
        cand.clear();
        stamp[i] = i;
        let mut r = 0;
        loop {
            let alive = grid.ring(bi, r, |cell| {
                for &j in cell {
                    if stamp[j as usize] != i {
                        stamp[j as usize] = i;
                        let bj = &boxes[j as usize];
                        cand.push((
                            bi.gap_to_box(bj).fast_norm(),
                            bi.centre().fast_distance(bj.centre()),
                            j,
                        ));
                    }
                }
            });
            // Items first seen in later rings have a gap of at least r·cell.
            let bound = r as f64 * grid.cell();
            let enough = cand.iter().filter(|c| c.0 <= bound).count() >= k;
            if !alive || enough || cand.len() >= n - 1 {
                break;
            }
            r += 1;
        }
        cand.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        out.push(cand.iter().take(k).map(|c| c.2).collect());
    }
    out
}

/// Nearest-neighbour order of the shapes from `start` (grid-accelerated): each step goes to the
/// unvisited contour nearest to the current point and pierces it at its nearest point.
/// `rng` (when given) sometimes takes the second nearest, for restarts.
pub(crate) fn nearest_neighbour_order(
    shapes: &[&Shape],
    bounds: BoundingBox,
    start: Point,
    mut rng: Option<&mut SplitMix64>,
) -> (Vec<u32>, Vec<Point>) {
    let n = shapes.len();
    let mut grid = Grid::new(bounds, n, 2.0);
    for (i, s) in shapes.iter().enumerate() {
        grid.insert(i as u32, &s.bbox);
    }
    let mut visited = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut points = vec![Point::ORIGIN; n];
    let mut cur = start;
    let mut stamp = vec![usize::MAX; n];
    for step in 0..n {
        let qb = BoundingBox { min: cur, max: cur };
        let mut best = (f64::INFINITY, usize::MAX, Point::ORIGIN);
        let mut second = best;
        let mut r = 0;
        loop {
            let alive = grid.ring(&qb, r, |cell| {
                for &j in cell {
                    let j = j as usize;
                    if visited[j] || stamp[j] == step {
                        continue;
                    }
                    stamp[j] = step;
                    if shapes[j].bbox.gap_to_point(cur).fast_norm() >= second.0 {
                        continue;
                    }
                    let x = shapes[j].nearest(cur);
                    let d = x.fast_distance(cur);
                    if d < best.0 {
                        second = best;
                        best = (d, j, x);
                    } else if d < second.0 {
                        second = (d, j, x);
                    }
                }
            });
            let bound = r as f64 * grid.cell();
            if !alive || (second.0 <= bound) || (best.0 <= bound && rng.is_none()) {
                break;
            }
            r += 1;
        }
        let take_second =
            second.1 != usize::MAX && rng.as_deref_mut().is_some_and(|g| g.index_below(4) == 0);
        let pick = if take_second { second } else { best };
        visited[pick.1] = true;
        order.push(pick.1 as u32);
        points[pick.1] = pick.2;
        cur = pick.2;
    }
    (order, points)
}
