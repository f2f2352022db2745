//! The island and strip rule on a raster of the sheet.
//!
//! The sheet is rasterised into square cells (side h ≤ strip width / 4, coarser only to keep
//! the grid under `max_grid_cells`). A cell is *void* once the unit whose root contour contains
//! its centre has been cut (the part falls out). Material is *rigid* where it is at least half a
//! strip width from every void cell: eroding by w/2 removes exactly the strips narrower than w.
//! Cells outside the sheet (a ring around it, and the sheet box outside a non-rectangular sheet)
//! are the *anchor*: the stock beyond the sheet edge and the clamps, rigid by definition. An
//! uncut part is on an island when none of its rigid cells is connected (4-neighbours) to the
//! anchor through rigid cells — whatever holds it is narrower than the strip width.

use std::collections::VecDeque;

use cutroute_geometry::Point;

use crate::layout::Layout;

#[derive(Clone)]
pub(crate) struct IslandGrid {
    nx: usize,
    ny: usize,
    anchor: Vec<bool>,
    /// Void or within w/2 of a void cell: not rigid.
    weak: Vec<bool>,
    /// Per unit, its cells (centres inside the root contour).
    unit_cells: Vec<Vec<u32>>,
    /// Cell offsets within w/2 of a cell (the erosion disc).
    disc: Vec<(isize, isize)>,
}

impl IslandGrid {
    pub fn new(layout: &Layout, strip_width: f64, max_cells: usize) -> IslandGrid {
        let sheet = layout.sheet_box;
        let area = sheet.width().max(1e-9) * sheet.height().max(1e-9);
        let h = (strip_width / 4.0)
            .max((area / max_cells.max(16) as f64).sqrt())
            .max(1e-6);
        let nx = (sheet.width() / h).ceil() as usize + 4;
        let ny = (sheet.height() / h).ceil() as usize + 4;
        let origin = Point::new(sheet.min.x - 2.0 * h, sheet.min.y - 2.0 * h);
        let centre = |ix: usize, iy: usize| {
            Point::new(
                origin.x + (ix as f64 + 0.5) * h,
                origin.y + (iy as f64 + 0.5) * h,
            )
        };
        let mut anchor = vec![false; nx * ny];
        for iy in 0..ny {
            for ix in 0..nx {
                let p = centre(ix, iy);
                anchor[iy * nx + ix] = !sheet.contains_point(p)
                    || layout.sheet_contour.is_some_and(|c| !c.contains(p));
            }
        }
        let unit_cells = layout
            .units
            .iter()
            .map(|unit| {
                let Some(contour) = layout.nest.contour(unit.root) else {
                    return Vec::new();
                };
                let b = unit.bbox;
                let cell =
                    |v: f64, o: f64, n: usize| (((v - o) / h).floor().max(0.0) as usize).min(n - 1);
                let (x0, x1) = (cell(b.min.x, origin.x, nx), cell(b.max.x, origin.x, nx));
                let (y0, y1) = (cell(b.min.y, origin.y, ny), cell(b.max.y, origin.y, ny));
                let mut cells = Vec::new();
                for iy in y0..=y1 {
                    for ix in x0..=x1 {
                        let i = iy * nx + ix;
                        if !anchor[i] && contour.contains(centre(ix, iy)) {
                            cells.push(i as u32);
                        }
                    }
                }
                cells
            })
            .collect();
        let r = strip_width / 2.0 / h;
        let reach = r.floor() as isize;
        let mut disc = Vec::new();
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                if ((dx * dx + dy * dy) as f64) <= r * r {
                    disc.push((dx, dy));
                }
            }
        }
        IslandGrid {
            nx,
            ny,
            weak: vec![false; nx * ny],
            anchor,
            unit_cells,
            disc,
        }
    }

    /// Marks unit `u` as cut: its cells void, everything within w/2 of them weak.
    pub fn cut(&mut self, u: usize) {
        let cells = std::mem::take(&mut self.unit_cells[u]);
        for &c in &cells {
            let (cx, cy) = (
                (c as usize % self.nx) as isize,
                (c as usize / self.nx) as isize,
            );
            for &(dx, dy) in &self.disc {
                let (x, y) = (cx + dx, cy + dy);
                if x >= 0 && y >= 0 && (x as usize) < self.nx && (y as usize) < self.ny {
                    let i = y as usize * self.nx + x as usize;
                    if !self.anchor[i] {
                        self.weak[i] = true;
                    }
                }
            }
        }
        self.unit_cells[u] = cells;
    }

    /// The uncut units (`uncut[u]`) with cells none of which is rigid and connected to the
    /// anchor. Units too small to hold a cell are never islands (the grid cannot tell).
    pub fn islanded(&self, uncut: &[bool]) -> Vec<usize> {
        let mut reached = vec![false; self.nx * self.ny];
        let mut queue: VecDeque<usize> = VecDeque::new();
        for (i, &a) in self.anchor.iter().enumerate() {
            if a {
                reached[i] = true;
                queue.push_back(i);
            }
        }
        while let Some(i) = queue.pop_front() {
            let (x, y) = (i % self.nx, i / self.nx);
            let mut visit = |j: usize| {
                if !reached[j] && !self.weak[j] {
                    reached[j] = true;
                    queue.push_back(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < self.nx {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - self.nx);
            }
            if y + 1 < self.ny {
                visit(i + self.nx);
            }
        }
        (0..self.unit_cells.len())
            .filter(|&u| {
                uncut[u]
                    && !self.unit_cells[u].is_empty()
                    && !self.unit_cells[u].iter().any(|&c| reached[c as usize])
            })
            .collect()
    }

    /// For units cut in `order`, per unit the index in `order` of the first cut after which
    /// it is uncut and on an island (`None`: never) — what replaying the cuts one by one and
    /// asking [`IslandGrid::islanded`] after each finds, in one pass over the grid instead of
    /// one flood fill per cut.
    ///
    /// Why it is the same: a cell turns weak at the first cut whose erosion disc covers it
    /// (`weak_at`), and stays weak. After cut i a cell is reached when some path of cells from
    /// the anchor has every cell still rigid, i.e. `weak_at > i` along it; so it is reached
    /// exactly while i < `reach`, the path's largest smallest `weak_at` (a widest-path
    /// problem, solved by a Dijkstra-like sweep from the anchor in decreasing order). A unit
    /// is on an island after cut i when none of its cells is reached: from i = max `reach`
    /// over its cells on, and it counts while it is still uncut.
    pub fn first_islanded(&self, order: &[usize]) -> Vec<Option<usize>> {
        const NEVER: u32 = u32::MAX;
        let cells = self.nx * self.ny;
        let mut weak_at = vec![NEVER; cells];
        let mut cut_at = vec![NEVER; self.unit_cells.len()];
        for (i, &u) in order.iter().enumerate() {
            let i = i as u32;
            if cut_at[u] != NEVER {
                continue;
            }
            cut_at[u] = i;
            for &c in &self.unit_cells[u] {
                let (cx, cy) = (
                    (c as usize % self.nx) as isize,
                    (c as usize / self.nx) as isize,
                );
                for &(dx, dy) in &self.disc {
                    let (x, y) = (cx + dx, cy + dy);
                    if x >= 0 && y >= 0 && (x as usize) < self.nx && (y as usize) < self.ny {
                        let j = y as usize * self.nx + x as usize;
                        if !self.anchor[j] && weak_at[j] > i {
                            weak_at[j] = i;
                        }
                    }
                }
            }
        }
        // Widest path from the anchor: `reach[c]` = the largest bottleneck `weak_at` of a
        // path to c (anchor cells never weaken). `None` until settled from a neighbour.
        let mut reach: Vec<Option<u32>> = vec![None; cells];
        let mut heap: std::collections::BinaryHeap<(u32, u32)> =
            std::collections::BinaryHeap::new();
        for (i, &a) in self.anchor.iter().enumerate() {
            if a {
                reach[i] = Some(NEVER);
                heap.push((NEVER, i as u32));
            }
        }
        let mut settled = vec![false; cells];
        while let Some((value, i)) = heap.pop() {
            let i = i as usize;
            if settled[i] {
                continue;
            }
            settled[i] = true;
            let (x, y) = (i % self.nx, i / self.nx);
            let mut relax = |j: usize| {
                if settled[j] {
                    return;
                }
                let through = value.min(weak_at[j]);
                if reach[j].is_none_or(|r| through > r) {
                    reach[j] = Some(through);
                    heap.push((through, j as u32));
                }
            };
            if x > 0 {
                relax(i - 1);
            }
            if x + 1 < self.nx {
                relax(i + 1);
            }
            if y > 0 {
                relax(i - self.nx);
            }
            if y + 1 < self.ny {
                relax(i + self.nx);
            }
        }
        self.unit_cells
            .iter()
            .zip(&cut_at)
            .map(|(unit_cells, &cut)| {
                // After cut i a cell is reached while i < reach; the unit is isolated from
                // the last of its cells' reach on.
                let isolated_from = unit_cells
                    .iter()
                    .map(|&c| reach[c as usize].unwrap_or(0))
                    .max()?;
                (isolated_from < cut && (isolated_from as usize) < order.len())
                    .then_some(isolated_from as usize)
            })
            .collect()
    }

    /// A copy of the erosion state, to undo a tentative cut.
    pub fn save(&self) -> Vec<bool> {
        self.weak.clone()
    }

    /// Undoes the cuts made since `save`.
    pub fn restore(&mut self, saved: Vec<bool>) {
        self.weak = saved;
    }
}

#[cfg(test)]
mod tests {
    use cutroute_geometry::{generate_nest, SplitMix64};

    use super::IslandGrid;
    use crate::layout::Layout;

    /// The definition: cut units one by one and flood-fill after each cut.
    fn replay(grid: &mut IslandGrid, order: &[usize]) -> Vec<Option<usize>> {
        let units = grid.unit_cells.len();
        let mut uncut = vec![true; units];
        let mut first = vec![None; units];
        for (i, &u) in order.iter().enumerate() {
            grid.cut(u);
            uncut[u] = false;
            for v in grid.islanded(&uncut) {
                first[v].get_or_insert(i);
            }
        }
        first
    }

    #[test]
    fn one_widest_path_sweep_finds_what_the_replay_finds() {
        let mut islands_seen = 0;
        for seed in 1..=12u64 {
            let nest = generate_nest(40 + 10 * seed as usize, seed);
            let layout = Layout::new(&nest);
            let units = layout.units.len();
            let mut rng = SplitMix64::new(seed);
            let mut order: Vec<usize> = (0..units).collect();
            // Random orders isolate parts; a few units left uncut test the never-cut case.
            for i in (1..units).rev() {
                order.swap(i, rng.below(i as u64 + 1) as usize);
            }
            order.truncate(units - units / 8);
            for strip in [4.0, 20.0, 60.0] {
                let grid = IslandGrid::new(&layout, strip, 40_000);
                let swept = grid.first_islanded(&order);
                let mut replayed = IslandGrid::new(&layout, strip, 40_000);
                assert_eq!(
                    swept,
                    replay(&mut replayed, &order),
                    "seed {seed}, strip {strip}"
                );
                islands_seen += swept.iter().flatten().count();
            }
        }
        assert!(islands_seen > 0, "the orders isolate some parts");
    }
}
