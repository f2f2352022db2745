//! Turning the model into SVG path data (y axis up: the view flips it with a transform).

use std::fmt::Write;

use cutroute_geometry::{Contour, Nest, Point, Route, Span, ToolMove, Toolpath};

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

/// The whole toolpath as one continuous subpath (idle and cut moves in machine order), with the
/// distance along it at which each move starts (one more entry for the end). The animation
/// reveals it with a dash of that length: a single attribute per frame, whatever the nest size.
pub fn travel_path(toolpath: &Toolpath) -> (String, Vec<f64>) {
    let mut out = String::new();
    let _ = write!(out, "M{:.3} {:.3}", toolpath.start.x, toolpath.start.y);
    let mut starts = Vec::with_capacity(toolpath.moves.len() + 1);
    let mut walked = 0.0;
    for m in &toolpath.moves {
        starts.push(walked);
        match m {
            ToolMove::Idle { to, .. } => {
                let _ = write!(out, "L{:.3} {:.3}", to.x, to.y);
            }
            ToolMove::Pierce { .. } => {}
            ToolMove::Cut { span, .. } => push_span(span, &mut out),
        }
        walked += m.length();
    }
    starts.push(walked);
    (out, starts)
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

    #[test]
    fn travel_path_measures_every_move() {
        let (nest, route) = square_nest();
        let toolpath = Toolpath::new(&route, &nest).unwrap();
        let (d, starts) = travel_path(&toolpath);
        assert!(d.starts_with("M-10.000 0.000"));
        assert_eq!(
            d.matches('M').count(),
            1,
            "one subpath: the dash must not restart"
        );
        assert_eq!(starts.len(), toolpath.moves.len() + 1);
        // 10 idle in, 40 around the square, 10 idle back.
        assert!((starts.last().unwrap() - 60.0).abs() < 1e-9);
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
