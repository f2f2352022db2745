//! Turning the model into SVG path data (y axis up: the view flips it with a transform).

use cutroute_geometry::{Contour, Nest, Point, Route};

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

/// SVG path data of a closed contour; arcs are split so no single `A` command sweeps more
/// than 180° (large sweeps are numerically fragile in SVG renderers).
pub fn contour_path(contour: &Contour, out: &mut String) {
    use std::fmt::Write;
    let Some(first) = contour.vertices.first() else {
        return;
    };
    let _ = write!(out, "M{:.3} {:.3}", first.point.x, first.point.y);
    for span in contour.spans() {
        if span.is_line() || !span.bulge.is_finite() {
            let _ = write!(out, "L{:.3} {:.3}", span.end.x, span.end.y);
            continue;
        }
        let (a, b) = span.split_at(0.5);
        let pieces = if span.bulge.abs() > 1.0 {
            vec![a, b]
        } else {
            vec![span]
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
    out.push('Z');
}

/// Path data of the idle (tool-off) moves of a route: start → pierce → … → finish.
pub fn idle_path(route: &Route) -> String {
    use std::fmt::Write;
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
