//! Turning the model into SVG path data (y axis up: the view flips it with a transform).

use std::fmt::Write;

use cutroute_geometry::{BoundingBox, Contour, Nest, Point, Route, Span, ToolMove, Toolpath};

/// Axis-aligned box `[min_x, min_y, max_x, max_y]` of everything worth showing.
pub fn nest_bounds(nest: &Nest) -> Option<[f64; 4]> {
    let mut bounds: Option<[f64; 4]> = None;
    let parts = nest.sheet.iter().chain(nest.parts.iter());
    for vertex in parts
        .flat_map(|p| p.contours.iter())
        .flat_map(|c| c.vertices.iter())
    {
        let Point { x, y } = vertex.point;
        if !(x.is_finite() && y.is_finite()) {
            continue;
        }
        bounds = Some(match bounds {
            None => [x, y, x, y],
            Some([a, b, c, d]) => [a.min(x), b.min(y), c.max(x), d.max(y)],
        });
    }
    bounds
}

/// Appends the drawing command of one span (the pen is at its start); arcs are split so no
/// single `A` command sweeps more than 180° (large sweeps are numerically fragile in SVG
/// renderers).
fn push_span(span: &Span, out: &mut String) {
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
pub fn idle_path(route: &Route) -> String {
    let mut out = String::new();
    let _ = write!(out, "M{:.3} {:.3}", route.start.x, route.start.y);
    for step in &route.steps {
        let _ = write!(
            out,
            "L{:.3} {:.3}",
            step.pierce_point.x, step.pierce_point.y
        );
    }
    if let Some(finish) = route.finish {
        let _ = write!(out, "L{:.3} {:.3}", finish.x, finish.y);
    }
    out
}

/// Path data of the cut (tool-on) moves of a toolpath, one subpath per contour.
pub fn cut_path(toolpath: &Toolpath) -> String {
    let mut out = String::new();
    let mut pen: Option<Point> = None;
    for m in &toolpath.moves {
        if let ToolMove::Cut { span, .. } = m {
            if pen != Some(span.start) {
                let _ = write!(out, "M{:.3} {:.3}", span.start.x, span.start.y);
            }
            push_span(span, &mut out);
            pen = Some(span.end);
        }
    }
    out
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

/// Candidate pierce points of the discrete solvers: every `step` mm of arc length along each
/// contour from its first vertex, and the vertices. Drawn as zero-length subpaths with round
/// caps (dots that keep their size when zooming).
pub fn candidate_dots(nest: &Nest, step: f64) -> String {
    let mut out = String::new();
    if !(step > 0.0 && step.is_finite()) {
        return out;
    }
    let mut dot = |p: Point| {
        let _ = write!(out, "M{:.3} {:.3}l0 0", p.x, p.y);
    };
    for contour in nest.parts.iter().flat_map(|p| p.contours.iter()) {
        contour.vertices.iter().for_each(|v| dot(v.point));
        let perimeter = contour.perimeter();
        if !(perimeter.is_finite()) {
            continue;
        }
        let mut s = 0.0;
        while s < perimeter {
            if let Some(p) = contour.point_at_length(s) {
                dot(p);
            }
            s += step;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{ContourRef, CutStep, Part, Vertex};

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
        let dots = candidate_dots(&nest, 5.0);
        // 4 vertices + 8 points every 5 mm round a 40 mm perimeter.
        assert_eq!(dots.matches('M').count(), 12);
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
}
