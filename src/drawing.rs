//! Turning the model into SVG path data (y axis up: the view flips it with a transform).

use std::fmt::Write;

use cutroute_geometry::{
    BoundingBox, Contour, Nest, PathRoute, Point, Route, Span, ToolMove, Toolpath,
};

/// The box of everything worth showing: every finite vertex of the sheet and the parts (`None`
/// when there is none).
pub fn nest_bounds(nest: &Nest) -> Option<BoundingBox> {
    let bounds = BoundingBox::from_points(
        nest.sheet
            .iter()
            .chain(nest.parts.iter())
            .flat_map(|p| p.contours.iter())
            .flat_map(|c| c.vertices.iter())
            .map(|v| v.point)
            .filter(|p| p.x.is_finite() && p.y.is_finite()),
    );
    (!bounds.is_empty()).then_some(bounds)
}

/// Appends the drawing command of one span (the pen is at its start); arcs are split so no
/// single `A` command sweeps more than 180° (large sweeps are numerically fragile in SVG
/// renderers).
pub fn push_span(span: &Span, out: &mut String) {
    if span.is_line() || !span.bulge.is_finite() {
        let _ = write!(out, "L{:.3} {:.3}", span.end.x, span.end.y);
        return;
    }
    let (a, b) = span.split_at(0.5);
    let pieces = if span.bulge.abs() > 1.0 {
        vec![a, b]
    } else {
        vec![*span]
    };
    for piece in pieces {
        let radius = piece.radius();
        let sweep = u8::from(piece.bulge > 0.0);
        let _ = write!(
            out,
            "A{radius:.3} {radius:.3} 0 0 {sweep} {:.3} {:.3}",
            piece.end.x, piece.end.y
        );
    }
}

/// SVG path data of a closed contour.
pub fn contour_path(contour: &Contour, out: &mut String) {
    let Some(first) = contour.vertices.first() else {
        return;
    };
    let _ = write!(out, "M{:.3} {:.3}", first.point.x, first.point.y);
    for span in contour.spans() {
        push_span(&span, out);
    }
    out.push('Z');
}

/// Path data of the idle (tool-off) moves of a route: start → pierce → … → finish.
/// With leads, each idle move runs from a switch-off point M* to the next pierce point M.
pub fn idle_path(route: &Route) -> String {
    let mut out = String::new();
    let _ = write!(out, "M{:.3} {:.3}", route.start.x, route.start.y);
    for step in &route.steps {
        let (on, off) = step
            .leads
            .as_ref()
            .map_or((step.pierce_point, step.pierce_point), |l| {
                (l.pierce, l.switch_off)
            });
        let _ = write!(out, "L{:.3} {:.3}", on.x, on.y);
        if off != on {
            let _ = write!(out, "M{:.3} {:.3}", off.x, off.y);
        }
    }
    if let Some(finish) = route.finish {
        let _ = write!(out, "L{:.3} {:.3}", finish.x, finish.y);
    }
    out
}

/// Path data of the idle moves of a path route: start → first pierce, each path's end → the
/// next pierce, last end → finish.
pub fn path_route_idle_path(route: &PathRoute) -> String {
    let mut out = String::new();
    let mut pen: Option<Point> = None;
    for (from, to) in route.idle_moves() {
        if pen != Some(from) {
            let _ = write!(out, "M{:.3} {:.3}", from.x, from.y);
        }
        let _ = write!(out, "L{:.3} {:.3}", to.x, to.y);
        pen = Some(to);
    }
    out
}

/// Path data of the cut (tool-on) moves of a toolpath that `keep` accepts, a new subpath
/// wherever the pen would jump.
fn cuts_where(toolpath: &Toolpath, keep: impl Fn(usize, bool) -> bool) -> String {
    let mut out = String::new();
    let mut pen: Option<Point> = None;
    for m in &toolpath.moves {
        if let ToolMove::Cut { span, step, link } = m {
            if !keep(*step, *link) {
                continue;
            }
            if pen != Some(span.start) {
                let _ = write!(out, "M{:.3} {:.3}", span.start.x, span.start.y);
            }
            push_span(span, &mut out);
            pen = Some(span.end);
        }
    }
    out
}

/// Path data of the cut moves along contours (links left out), one subpath per contour.
pub fn cut_path(toolpath: &Toolpath) -> String {
    cuts_where(toolpath, |_, link| !link)
}

/// Path data of the tool-on links (chain links, a path's pieces through scrap).
pub fn link_path(toolpath: &Toolpath) -> String {
    cuts_where(toolpath, |_, link| link)
}

/// Path data of the cut moves along contours, one string per step of the toolpath (per
/// tool-on path of a path route), so each can be drawn apart. Steps without such moves give
/// an empty string.
pub fn cut_paths_by_step(toolpath: &Toolpath) -> Vec<String> {
    let steps = toolpath
        .moves
        .iter()
        .filter_map(ToolMove::step)
        .max()
        .map_or(0, |s| s + 1);
    let mut out = vec![String::new(); steps];
    let mut pen: Option<(usize, Point)> = None;
    for m in &toolpath.moves {
        if let ToolMove::Cut {
            span,
            step,
            link: false,
        } = m
        {
            let d = &mut out[*step];
            if pen != Some((*step, span.start)) {
                let _ = write!(d, "M{:.3} {:.3}", span.start.x, span.start.y);
            }
            push_span(span, d);
            pen = Some((*step, span.end));
        }
    }
    out
}

/// Distance (mm) within which a tool-on span counts as following a contour. Spans of a path
/// route on a contour are pieces of that contour's spans (off by rounding only); a piece
/// through scrap crosses no contour, so its midpoint is well away from all of them.
pub const ON_CONTOUR_TOLERANCE_MM: f64 = 1e-3;

/// The contours' spans of a nest bucketed on a uniform grid, to ask quickly whether a point
/// lies on some contour.
struct ContourGrid {
    spans: Vec<Span>,
    min: Point,
    cell: f64,
    columns: usize,
    rows: usize,
    cells: Vec<Vec<u32>>,
}

/// Most cells along one side of the grid.
const MAX_GRID_SIDE: usize = 512;

impl ContourGrid {
    fn new(nest: &Nest, tolerance: f64) -> Option<ContourGrid> {
        let spans: Vec<Span> = nest
            .sheet
            .iter()
            .chain(nest.parts.iter())
            .flat_map(|p| p.contours.iter())
            .flat_map(|c| c.spans())
            .collect();
        let boxes: Vec<BoundingBox> = spans
            .iter()
            .map(|s| s.bounding_box().expanded(tolerance))
            .collect();
        let all = boxes.iter().copied().reduce(BoundingBox::union)?;
        let side = all.width().max(all.height()).max(tolerance);
        let per_side = ((spans.len() as f64).sqrt().ceil() as usize).clamp(1, MAX_GRID_SIDE);
        let cell = side / per_side as f64;
        let columns = (all.width() / cell).floor() as usize + 1;
        let rows = (all.height() / cell).floor() as usize + 1;
        let mut grid = ContourGrid {
            spans,
            min: all.min,
            cell,
            columns,
            rows,
            cells: vec![Vec::new(); columns * rows],
        };
        for (i, b) in boxes.iter().enumerate() {
            let (c0, r0) = grid.cell_of(b.min);
            let (c1, r1) = grid.cell_of(b.max);
            for r in r0..=r1 {
                for c in c0..=c1 {
                    grid.cells[r * columns + c].push(i as u32);
                }
            }
        }
        Some(grid)
    }

    fn cell_of(&self, p: Point) -> (usize, usize) {
        let index = |v: f64, n: usize| {
            if v.is_finite() && v > 0.0 {
                ((v / self.cell) as usize).min(n - 1)
            } else {
                0
            }
        };
        (
            index(p.x - self.min.x, self.columns),
            index(p.y - self.min.y, self.rows),
        )
    }

    fn on_contour(&self, p: Point, tolerance: f64) -> bool {
        let (c, r) = self.cell_of(p);
        self.cells[r * self.columns + c]
            .iter()
            .any(|&i| self.spans[i as usize].distance_to(p) <= tolerance)
    }
}

/// The toolpath of a path route over `nest`, with the tool-on pieces that follow no contour
/// (links between parts through scrap) marked as links, as chain cutting's links are, so the
/// drawing, the animation and the exports show them apart.
///
/// With kerf and leads (the paths carry [`cutroute_geometry::PathLeads`]) the paths run on the
/// equidistants: those are the contours a piece follows, and the leads are no links (as a
/// contour route's leads are not).
pub fn path_route_toolpath(route: &PathRoute, nest: &Nest) -> Toolpath {
    let mut toolpath = Toolpath::from_path_route(route);
    let kerf_nest = route
        .paths
        .iter()
        .find_map(|p| p.leads.as_ref())
        .map(|l| cutroute_geometry::LeadFitter::new(nest, l.rules()).kerf_nest());
    let Some(grid) = ContourGrid::new(kerf_nest.as_ref().unwrap_or(nest), ON_CONTOUR_TOLERANCE_MM)
    else {
        return toolpath;
    };
    let is_lead = |step: usize, span: &Span| {
        route
            .paths
            .get(step)
            .and_then(|p| p.leads.as_ref())
            .is_some_and(|l| {
                cutroute_geometry::chain_spans(&l.lead_in)
                    .chain(cutroute_geometry::chain_spans(&l.lead_out))
                    .any(|s| s.start == span.start && s.end == span.end)
            })
    };
    for m in &mut toolpath.moves {
        if let ToolMove::Cut { span, link, step } = m {
            *link = !is_lead(*step, span)
                && !grid.on_contour(span.point_at(0.5), ON_CONTOUR_TOLERANCE_MM);
        }
    }
    toolpath
}

/// Box `[min_x, min_y, max_x, max_y]` of everything a toolpath draws (`None` if empty).
pub fn toolpath_bounds(toolpath: &Toolpath) -> Option<BoundingBox> {
    let mut bounds = BoundingBox::from_corners(toolpath.start, toolpath.start);
    for m in &toolpath.moves {
        bounds = bounds.union(move_box(m));
    }
    (!toolpath.moves.is_empty()).then_some(bounds)
}

/// Consecutive moves of a toolpath drawn as one path element: the animation shows the
/// travelled route piece by piece, so a frame redraws one small path instead of the whole
/// route (a dash on one path of every move made Chromium lay out, paint and raster the entire
/// view each frame).
#[derive(Clone, Debug, PartialEq)]
pub struct TravelChunk {
    /// Path data: one continuous subpath (a dash over it must not restart).
    pub d: String,
    /// The moves drawn, as indices into the toolpath's moves.
    pub moves: std::ops::Range<usize>,
    /// Distance along the whole route at which the chunk starts.
    pub start: f64,
    /// Length of the chunk's path.
    pub length: f64,
}

/// How the travelled route is cut into chunks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChunkLimits {
    /// Most moves in one chunk (a pierce counts as a move).
    pub max_moves: usize,
    /// Largest width or height of a chunk's bounding box, in drawing units: the area a frame
    /// repaints is the box of the chunk under the head. A single move larger than this is a
    /// chunk of its own.
    pub max_side: f64,
}

impl Default for ChunkLimits {
    fn default() -> Self {
        Self {
            max_moves: 64,
            max_side: f64::INFINITY,
        }
    }
}

/// The whole toolpath (idle and cut moves in machine order) as path data, whole and in chunks,
/// with the distance along it at which each move starts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Travel {
    /// The whole route as one continuous subpath (a dash over it must not restart).
    pub d: String,
    /// The chunks in machine order; together they hold every move once.
    pub chunks: Vec<TravelChunk>,
    /// `move_starts[i]` = distance along the route at which move `i` starts; one more entry
    /// for the end.
    pub move_starts: Vec<f64>,
}

impl Travel {
    /// Length of the whole route, idle and cut moves.
    pub fn length(&self) -> f64 {
        self.move_starts.last().copied().unwrap_or(0.0)
    }

    /// Index of the chunk that draws move `index` (the last chunk past the end).
    pub fn chunk_of_move(&self, index: usize) -> Option<usize> {
        if self.chunks.is_empty() {
            return None;
        }
        let after = self.chunks.partition_point(|c| c.moves.end <= index);
        Some(after.min(self.chunks.len() - 1))
    }
}

/// Bounding box of what a move draws.
fn move_box(m: &ToolMove) -> BoundingBox {
    match m {
        ToolMove::Idle { from, to } => BoundingBox::from_corners(*from, *to),
        ToolMove::Pierce { at, .. } => BoundingBox::from_corners(*at, *at),
        ToolMove::Cut { span, .. } => span.bounding_box(),
    }
}

/// The toolpath as chunks within `limits`.
pub fn travel_chunks(toolpath: &Toolpath, limits: ChunkLimits) -> Travel {
    let max_moves = limits.max_moves.max(1);
    let mut chunks = Vec::new();
    let mut move_starts = Vec::with_capacity(toolpath.moves.len() + 1);
    let mut walked = 0.0;
    let mut pen = toolpath.start;
    let mut current: Option<(TravelChunk, BoundingBox)> = None;
    let mut whole = String::new();
    let _ = write!(whole, "M{:.3} {:.3}", pen.x, pen.y);
    for (i, m) in toolpath.moves.iter().enumerate() {
        move_starts.push(walked);
        let bounds = move_box(m);
        if let Some((chunk, chunk_box)) = current.take() {
            let grown = chunk_box.union(bounds);
            // Moves of no length (a pierce after a long idle move) stay with what follows.
            let too_big = chunk.length > 0.0
                && (grown.width() > limits.max_side || grown.height() > limits.max_side);
            if chunk.moves.len() >= max_moves || too_big {
                chunks.push(chunk);
            } else {
                current = Some((chunk, grown));
            }
        }
        let (chunk, _) = current.get_or_insert_with(|| {
            let mut d = String::new();
            let _ = write!(d, "M{:.3} {:.3}", pen.x, pen.y);
            (
                TravelChunk {
                    d,
                    moves: i..i,
                    start: walked,
                    length: 0.0,
                },
                bounds,
            )
        });
        let drawn = chunk.d.len();
        match m {
            ToolMove::Idle { to, .. } => {
                let _ = write!(chunk.d, "L{:.3} {:.3}", to.x, to.y);
            }
            ToolMove::Pierce { .. } => {}
            ToolMove::Cut { span, .. } => push_span(span, &mut chunk.d),
        }
        whole.push_str(&chunk.d[drawn..]);
        chunk.moves.end = i + 1;
        chunk.length += m.length();
        walked += m.length();
        pen = m.end();
    }
    chunks.extend(current.map(|(chunk, _)| chunk));
    move_starts.push(walked);
    Travel {
        d: whole,
        chunks,
        move_starts,
    }
}

/// Chevrons showing each contour's cutting direction, `size` drawing units long, placed a
/// quarter of the way round from the first vertex.
pub fn direction_arrows(nest: &Nest, size: f64) -> String {
    let mut out = String::new();
    for contour in nest.parts.iter().flat_map(|p| p.contours.iter()) {
        let perimeter = contour.perimeter();
        if !(perimeter > 0.0 && perimeter.is_finite()) {
            continue;
        }
        let Some(position) = contour.position_at_length(perimeter * 0.25) else {
            continue;
        };
        let Some(span) = contour.span(position.span) else {
            continue;
        };
        let p = span.point_at(position.t);
        let d = span.tangent_at(position.t);
        // Small contours get small arrows, so the chevron never hides the contour.
        let h = (size.min(perimeter / 6.0)) / 2.0;
        let n = Point::new(-d.y, d.x);
        let tip = p + d * h;
        let left = p - d * h + n * h;
        let right = p - d * h - n * h;
        let _ = write!(
            out,
            "M{:.3} {:.3}L{:.3} {:.3}L{:.3} {:.3}",
            left.x, left.y, tip.x, tip.y, right.x, right.y
        );
    }
    out
}

/// Candidate pierce points of the discrete solvers (`Contour::candidate_points` with the
/// vertices, as the engine's discretisation takes them). Drawn as zero-length subpaths with
/// round caps (dots that keep their size when zooming).
pub fn candidate_dots(nest: &Nest, step: f64) -> String {
    let mut out = String::new();
    if !(step > 0.0 && step.is_finite()) {
        return out;
    }
    for contour in nest.parts.iter().flat_map(|p| p.contours.iter()) {
        for p in contour.candidate_points(step, true) {
            let _ = write!(out, "M{:.3} {:.3}l0 0", p.x, p.y);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{ContourRef, CutStep, Part, ToolOnPath, Vertex};

    fn square_nest() -> (Nest, Route) {
        let square = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(10.0, 0.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(0.0, 10.0),
        ]);
        let nest = Nest {
            sheet: None,
            parts: vec![Part {
                name: "square".into(),
                contours: vec![square],
            }],
        };
        let route = Route {
            start: Point::new(-10.0, 0.0),
            steps: vec![CutStep::pierced(
                ContourRef {
                    part: 0,
                    contour: 0,
                },
                Point::new(0.0, 0.0),
            )],
            finish: Some(Point::new(-10.0, 0.0)),
        };
        (nest, route)
    }

    /// Checks that `travel` draws every move of `toolpath` once, in order, each chunk one
    /// continuous subpath starting where the previous one ended.
    fn check_chunks(toolpath: &Toolpath, travel: &Travel) {
        assert_eq!(travel.move_starts.len(), toolpath.moves.len() + 1);
        let mut next_move = 0;
        let mut pen = toolpath.start;
        let mut walked = 0.0;
        for chunk in &travel.chunks {
            assert_eq!(chunk.moves.start, next_move, "chunks are contiguous");
            assert!(chunk.moves.end > chunk.moves.start, "no empty chunk");
            assert_eq!(
                chunk.d.matches('M').count(),
                1,
                "one subpath: the dash must not restart"
            );
            assert!(chunk.d.starts_with(&format!("M{:.3} {:.3}", pen.x, pen.y)));
            assert!((chunk.start - travel.move_starts[chunk.moves.start]).abs() < 1e-9);
            assert!((chunk.start - walked).abs() < 1e-9);
            let length: f64 = toolpath.moves[chunk.moves.clone()]
                .iter()
                .map(ToolMove::length)
                .sum();
            assert!((chunk.length - length).abs() < 1e-9);
            walked += length;
            next_move = chunk.moves.end;
            pen = toolpath.moves[chunk.moves.end - 1].end();
        }
        assert_eq!(next_move, toolpath.moves.len(), "every move drawn");
        // The whole route is the chunks joined, each one's `M` dropped but the first.
        let joined: String = travel
            .chunks
            .iter()
            .enumerate()
            .map(|(k, c)| {
                if k == 0 {
                    c.d.clone()
                } else {
                    c.d[c.d.find(['L', 'A']).unwrap_or(c.d.len())..].to_string()
                }
            })
            .collect();
        assert_eq!(travel.d, joined);
        assert_eq!(
            travel.d.matches('M').count(),
            1,
            "one subpath: the dash must not restart"
        );
        assert!((travel.length() - walked).abs() < 1e-9);
    }

    #[test]
    fn travel_chunks_draw_every_move_once() {
        let (nest, route) = square_nest();
        let toolpath = Toolpath::new(&route, &nest).unwrap();
        // Idle in, pierce, four sides, idle back.
        assert_eq!(toolpath.moves.len(), 7);
        let whole = travel_chunks(&toolpath, ChunkLimits::default());
        check_chunks(&toolpath, &whole);
        assert_eq!(whole.chunks.len(), 1);
        assert!(whole.chunks[0].d.starts_with("M-10.000 0.000"));
        // 10 idle in, 40 around the square, 10 idle back.
        assert!((whole.length() - 60.0).abs() < 1e-9);
        for max_moves in 1..=7 {
            let limits = ChunkLimits {
                max_moves,
                ..ChunkLimits::default()
            };
            let travel = travel_chunks(&toolpath, limits);
            check_chunks(&toolpath, &travel);
            assert_eq!(travel.chunks.len(), 7usize.div_ceil(max_moves));
            assert!(travel.chunks.iter().all(|c| c.moves.len() <= max_moves));
        }
        assert_eq!(
            travel_chunks(&Toolpath::default(), ChunkLimits::default()).chunks,
            vec![]
        );
    }

    #[test]
    fn travel_chunks_stay_small_on_the_drawing() {
        let (nest, route) = square_nest();
        let toolpath = Toolpath::new(&route, &nest).unwrap();
        let limits = ChunkLimits {
            max_moves: 100,
            max_side: 12.0,
        };
        let travel = travel_chunks(&toolpath, limits);
        check_chunks(&toolpath, &travel);
        // The idle move in with the pierce (the first side would widen the box to 20 mm),
        // the four sides (10 × 10 mm), the idle move out.
        for chunk in &travel.chunks {
            let bounds = toolpath.moves[chunk.moves.clone()]
                .iter()
                .map(move_box)
                .fold(BoundingBox::EMPTY, BoundingBox::union);
            assert!(
                chunk.moves.len() == 1 || bounds.width().max(bounds.height()) <= 12.0,
                "chunk {:?} spans {bounds:?}",
                chunk.moves
            );
        }
        let moves: Vec<_> = travel.chunks.iter().map(|c| c.moves.clone()).collect();
        assert_eq!(moves, vec![0..2, 2..6, 6..7]);
        // Look-up from a move to its chunk.
        for (k, chunk) in travel.chunks.iter().enumerate() {
            for i in chunk.moves.clone() {
                assert_eq!(travel.chunk_of_move(i), Some(k));
            }
        }
        assert_eq!(travel.chunk_of_move(99), Some(travel.chunks.len() - 1));
    }

    #[test]
    fn candidates_every_step_and_at_vertices() {
        let (nest, _) = square_nest();
        // Round a 40 mm square: every 5 mm gives 8 points, its vertices among them (drawn once).
        assert_eq!(candidate_dots(&nest, 5.0).matches('M').count(), 8);
        // Every 3 mm gives 14 points (0 to 39 mm); the vertices at 10 and 20 mm fall between them.
        assert_eq!(candidate_dots(&nest, 3.0).matches('M').count(), 16);
        assert!(candidate_dots(&nest, 0.0).is_empty());
    }

    #[test]
    fn one_arrow_per_contour() {
        let (nest, _) = square_nest();
        let arrows = direction_arrows(&nest, 2.0);
        assert_eq!(arrows.matches('M').count(), 1);
        // A quarter of the way round a counter-clockwise square (from (0,0) along +x) is the
        // corner (10, 0): the tip points along the first edge's direction at that place.
        assert!(arrows.contains("L11.000 0.000") || arrows.contains("L10.000 1.000"));
    }

    #[test]
    fn path_route_leads_and_cuts_on_the_equidistants_are_no_links() {
        let (nest, _) = common_edge_route();
        // Parts A and C only (apart): their paths over the kerf nest, with leads.
        let nest = Nest {
            sheet: None,
            parts: vec![nest.parts[0].clone(), nest.parts[2].clone()],
        };
        let settings = cutroute_geometry::KerfSettings {
            kerf: 0.2,
            pierce_clearance: 1.0,
            switch_off_clearance: 0.5,
            lead_in: cutroute_geometry::LeadSpec::new(cutroute_geometry::LeadShape::Arc, 2.0),
            lead_out: cutroute_geometry::LeadSpec::new(cutroute_geometry::LeadShape::Line, 1.0),
            ..Default::default()
        };
        let fitter = cutroute_geometry::LeadFitter::new(&nest, settings);
        let kerf_nest = fitter.kerf_nest();
        let route = Route::innermost_first(&kerf_nest, Point::new(-5.0, -5.0), None);
        let paths = PathRoute::from_route(&route, &kerf_nest).unwrap();
        let paths = fitter.attach_paths(&paths).unwrap();
        let toolpath = path_route_toolpath(&paths, &nest);
        assert!(toolpath
            .moves
            .iter()
            .all(|m| !matches!(m, ToolMove::Cut { link: true, .. })));
        // The leads are in the drawing's lead layer and the animation's toolpath.
        assert_eq!(crate::kerf::path_lead_paths(&paths).len(), 2);
        let leads: f64 = paths.paths.iter().map(|p| p.leads_length()).sum();
        assert!((toolpath.cut_length() - paths.cut_length()).abs() < 1e-9 && leads > 0.0);
    }

    /// Parts A = [0,10]², B = [10,20]×[0,10] sharing the edge x = 10, C = [30,40]×[0,10] apart;
    /// a path route cutting A∪B's outline, then the common edge, a link through scrap over to C
    /// and C's outline.
    fn common_edge_route() -> (Nest, PathRoute) {
        let square = |x0: f64, x1: f64| {
            Contour::new(vec![
                Vertex::line(x0, 0.0),
                Vertex::line(x0, 10.0),
                Vertex::line(x1, 10.0),
                Vertex::line(x1, 0.0),
            ])
        };
        let part = |name: &str, contour| Part {
            name: name.into(),
            contours: vec![contour],
        };
        let nest = Nest {
            sheet: None,
            parts: vec![
                part("a", square(0.0, 10.0)),
                part("b", square(10.0, 20.0)),
                part("c", square(30.0, 40.0)),
            ],
        };
        let p = Point::new;
        let walk = |points: &[Point]| -> Vec<Span> {
            points.windows(2).map(|w| Span::line(w[0], w[1])).collect()
        };
        let outline = ToolOnPath {
            pierce: p(0.0, 0.0),
            spans: walk(&[
                p(0.0, 0.0),
                p(0.0, 10.0),
                p(10.0, 10.0),
                p(20.0, 10.0),
                p(20.0, 0.0),
                p(10.0, 0.0),
                p(0.0, 0.0),
            ]),
            leads: None,
        };
        let edge_then_c = ToolOnPath {
            pierce: p(10.0, 0.0),
            spans: walk(&[
                p(10.0, 0.0),
                p(10.0, 10.0),
                // Link: up into scrap, across, down onto C's top edge.
                p(10.0, 20.0),
                p(35.0, 20.0),
                p(35.0, 10.0),
                // C's outline from there.
                p(30.0, 10.0),
                p(30.0, 0.0),
                p(40.0, 0.0),
                p(40.0, 10.0),
                p(35.0, 10.0),
            ]),
            leads: None,
        };
        let route = PathRoute {
            start: p(0.0, -10.0),
            paths: vec![outline, edge_then_c],
            finish: Some(p(0.0, -10.0)),
        };
        (nest, route)
    }

    #[test]
    fn path_route_pieces_through_scrap_become_links() {
        let (nest, route) = common_edge_route();
        // The hand-made route is valid for the independent checker.
        assert_eq!(route.problems(&nest, 1e-6), vec![]);
        let toolpath = path_route_toolpath(&route, &nest);
        let links: Vec<Span> = toolpath
            .moves
            .iter()
            .filter_map(|m| match m {
                ToolMove::Cut {
                    span, link: true, ..
                } => Some(*span),
                _ => None,
            })
            .collect();
        assert_eq!(links.len(), 3, "{links:?}");
        assert!((toolpath.link_length() - 45.0).abs() < 1e-9);
        // Links still count as cut length; nothing else changes.
        assert!((toolpath.cut_length() - route.cut_length()).abs() < 1e-9);
        assert!((toolpath.idle_length() - route.idle_length()).abs() < 1e-9);
        assert_eq!(toolpath.pierce_count(), 2);
        // Drawn apart: the links in their own path, each tool-on path in its own.
        assert_eq!(link_path(&toolpath).matches('M').count(), 1);
        assert_eq!(link_path(&toolpath).matches('L').count(), 3);
        let by_step = cut_paths_by_step(&toolpath);
        assert_eq!(by_step.len(), 2);
        assert_eq!(by_step[0].matches('L').count(), 6);
        // Path 2: the common edge, then (after the link) C's outline: two subpaths.
        assert_eq!(by_step[1].matches('M').count(), 2);
        assert_eq!(by_step[1].matches('L').count(), 1 + 5);
        assert!(
            !cut_path(&toolpath).contains("L10.000 20.000"),
            "links are not cuts"
        );
    }

    #[test]
    fn path_route_idle_moves_join_the_paths() {
        let (_, route) = common_edge_route();
        let d = path_route_idle_path(&route);
        // start → pierce 1 (0,0) = end of path 1 → pierce 2 (10,0) in one stroke; then end of
        // path 2 (35,10) → finish.
        assert_eq!(d.matches('M').count(), 2, "{d}");
        assert!(d.contains("L0.000 0.000L10.000 0.000M"), "{d}");
        assert!(d.starts_with("M0.000 -10.000L0.000 0.000"), "{d}");
        assert!(d.ends_with("M35.000 10.000L0.000 -10.000"), "{d}");
    }

    #[test]
    fn a_nest_with_nothing_to_draw_is_fitted_to_the_toolpath() {
        let (_, route) = common_edge_route();
        let toolpath = Toolpath::from_path_route(&route);
        assert_eq!(
            toolpath_bounds(&toolpath),
            Some(BoundingBox::from_corners(
                Point::new(0.0, -10.0),
                Point::new(40.0, 20.0)
            ))
        );
        // With no contours there is nothing to follow: no move is called a link.
        let bare = path_route_toolpath(&route, &Nest::default());
        assert_eq!(bare.link_length(), 0.0);
        assert_eq!(toolpath_bounds(&Toolpath::default()), None);
    }
}

/// The heat map's colour scale: a cell whose temperature is at least `HEAT_LEVELS[k]` (and
/// below the next level) is drawn in class `heat-k`, whose colour each theme defines; cooler
/// cells are not drawn. Temperatures are in units of H: 1 is one source at its own point the
/// moment it switches on, so the scale means the same on every nest and at every time.
pub const HEAT_LEVELS: [f64; 8] = [0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0];

/// One frame of the heat map: per colour level, the path data of its cells and their number,
/// and what the frame shows in numbers (the tests' handle on the drawn temperatures).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HeatFrame {
    /// `(level, path data, cells)` for every level with at least one cell.
    pub levels: Vec<(usize, String, usize)>,
    /// The hottest cell's temperature.
    pub max: f64,
    /// The sum of every cell's temperature.
    pub sum: f64,
}

/// The temperature field of `sources` (in time order) at machine time `t`, sampled at the
/// centres of square cells over `bounds`, `cells_across` along
/// its longer side.
pub fn heat_frame(
    model: &cutroute_thermal::HeatModel,
    sources: &[cutroute_thermal::Pierce],
    bounds: BoundingBox,
    t: f64,
    cells_across: usize,
) -> HeatFrame {
    let (Point { x: x0, y: y0 }, Point { x: x1, y: y1 }) = (bounds.min, bounds.max);
    let side = (x1 - x0).max(y1 - y0) / cells_across.max(1) as f64;
    if !(side > 0.0 && side.is_finite()) {
        return HeatFrame::default();
    }
    let (nx, ny) = (
        ((x1 - x0) / side).ceil().max(1.0) as usize,
        ((y1 - y0) / side).ceil().max(1.0) as usize,
    );
    let mut paths = vec![(String::new(), 0_usize); HEAT_LEVELS.len()];
    let mut frame = HeatFrame::default();
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = (x0 + i as f64 * side, y0 + j as f64 * side);
            let centre = Point::new(x + side / 2.0, y + side / 2.0);
            let temperature = model.temperature_at(sources, centre, t);
            frame.sum += temperature;
            frame.max = frame.max.max(temperature);
            let Some(level) = HEAT_LEVELS.iter().rposition(|l| temperature >= *l) else {
                continue;
            };
            let (d, count) = &mut paths[level];
            let _ = write!(d, "M{x:.2} {y:.2}h{side:.2}v{side:.2}h{:.2}z", -side);
            *count += 1;
        }
    }
    frame.levels = paths
        .into_iter()
        .enumerate()
        .filter(|(_, (_, count))| *count > 0)
        .map(|(level, (d, count))| (level, d, count))
        .collect();
    frame
}

#[cfg(test)]
mod heat_tests {
    use super::*;
    use cutroute_thermal::{HeatModel, Pierce};

    #[test]
    fn the_heat_map_warms_where_and_when_the_torch_went_on_and_cools_after() {
        let model = HeatModel::new(10.0, 60.0).unwrap();
        let sources = [Pierce {
            point: Point::new(5.0, 5.0),
            time: 10.0,
        }];
        let bounds = BoundingBox::from_corners(Point::new(0.0, 0.0), Point::new(100.0, 50.0));
        let before = heat_frame(&model, &sources, bounds, 5.0, 20);
        assert_eq!(before.sum, 0.0, "nothing switched on yet");
        assert!(before.levels.is_empty());
        let at = heat_frame(&model, &sources, bounds, 10.0, 20);
        let later = heat_frame(&model, &sources, bounds, 70.0, 20);
        // The cell centred on (2.5, 2.5) is 3.54 mm from the source: exp(−12.5/200) ≈ 0.939.
        assert!((at.max - (-12.5f64 / 200.0).exp()).abs() < 1e-12);
        assert!(
            (later.max - at.max * (-1.0f64).exp()).abs() < 1e-12,
            "one τ later"
        );
        assert!(later.sum < at.sum);
        let hottest = at.levels.last().unwrap();
        assert_eq!(hottest.0, 6, "0.939 is in the level from 0.7");
        let cells: usize = at.levels.iter().map(|l| l.2).sum();
        assert!(cells > 0 && cells < 20 * 10);
    }
}
