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

    /// A copy of the erosion state, to undo a tentative cut.
    pub fn save(&self) -> Vec<bool> {
        self.weak.clone()
    }

    /// Undoes the cuts made since `save`.
    pub fn restore(&mut self, saved: Vec<bool>) {
        self.weak = saved;
    }
}
