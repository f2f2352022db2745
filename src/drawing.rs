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
    let n = contour.vertices.len();
    if n == 0 {
        return;
    }
    let first = contour.vertices[0].point;
    let _ = write!(out, "M{:.3} {:.3}", first.x, first.y);
    for i in 0..n {
        let from = contour.vertices[i];
        let to = contour.vertices[(i + 1) % n].point;
        if from.bulge == 0.0 || !from.bulge.is_finite() {
            let _ = write!(out, "L{:.3} {:.3}", to.x, to.y);
            continue;
        }
        let pieces = if from.bulge.abs() > 1.0 { 2 } else { 1 };
        // Halving an arc: the bulge of each half is tan(φ/8) = b / (1 + sqrt(1 + b²)).
        let bulge = if pieces == 2 {
            from.bulge / (1.0 + (1.0 + from.bulge * from.bulge).sqrt())
        } else {
            from.bulge
        };
        let mid = arc_midpoint(from.point, to, from.bulge);
        let targets = if pieces == 2 { vec![mid, to] } else { vec![to] };
        let mut start = from.point;
        for target in targets {
            let chord = (target.x - start.x).hypot(target.y - start.y);
            let radius = chord * (1.0 + bulge * bulge) / (4.0 * bulge.abs());
            let sweep = u8::from(bulge > 0.0);
            let _ = write!(
                out,
                "A{radius:.3} {radius:.3} 0 0 {sweep} {:.3} {:.3}",
                target.x, target.y
            );
            start = target;
        }
    }
    out.push('Z');
}

/// The point halfway along the arc from `a` to `b` with the given bulge.
fn arc_midpoint(a: Point, b: Point, bulge: f64) -> Point {
    // The sagitta is bulge × half-chord, on the right of the chord for counter-clockwise arcs.
    let (cx, cy) = (b.x - a.x, b.y - a.y);
    Point::new(
        (a.x + b.x) / 2.0 + cy * bulge / 2.0,
        (a.y + b.y) / 2.0 - cx * bulge / 2.0,
    )
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
