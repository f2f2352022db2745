//! Thin helpers over `cutroute-geometry`'s span maths that the formats need: arc angles for
//! result JSON, part area/perimeter as DBS record 27 defines them, splitting a contour at a
//! pierce point, and halving arcs for SVG.

use cutroute_geometry::{Contour, Part, Point, Span, Vertex};

/// Euclidean distance between two points.
pub(crate) fn dist(a: Point, b: Point) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// Arc angle in degrees (signed, CCW positive) of a span with bulge `b`; result JSON stores this.
pub(crate) fn bulge_to_degrees(b: f64) -> f64 {
    4.0 * b.atan().to_degrees()
}

/// Bulge of a span whose swept angle is `deg` degrees.
pub(crate) fn degrees_to_bulge(deg: f64) -> f64 {
    (deg.to_radians() / 4.0).tan()
}

/// The span from `a` to `z` with bulge `b`.
pub(crate) fn span(a: Point, z: Point, b: f64) -> Span {
    Span {
        start: a,
        end: z,
        bulge: b,
    }
}

/// Material area of a part (mm²): outer contour minus its holes, whatever their stored
/// orientation.
pub(crate) fn part_area(part: &Part) -> f64 {
    let mut contours = part.contours.iter();
    let outer = contours.next().map_or(0.0, Contour::area);
    outer - contours.map(Contour::area).sum::<f64>()
}

/// Total cut length of a part (mm): every contour's perimeter.
pub(crate) fn part_perimeter(part: &Part) -> f64 {
    part.contours.iter().map(Contour::perimeter).sum()
}

/// Bulge of each half when a span is halved at its zenith (`β / (1 + √(1+β²))`, App. Б).
pub(crate) fn half_bulge(b: f64) -> f64 {
    b / (1.0 + (1.0 + b * b).sqrt())
}

/// Splits a closed contour at the point nearest to `pierce` and returns the vertices of the
/// full cut from there back to it: the first vertex is the pierce point and the list repeats it
/// at the end with bulge 0. `None` for a contour without vertices.
pub(crate) fn cut_from(contour: &Contour, pierce: Point) -> Option<Vec<Vertex>> {
    let hit = contour.nearest_point(pierce)?;
    let n = contour.vertices.len();
    let best = hit.position.span;
    let (before, after) = contour.span(best)?.split_at(hit.position.t);
    let start = after.start;
    let mut out = Vec::with_capacity(n + 2);
    out.push(Vertex {
        point: start,
        bulge: after.bulge,
    });
    for k in 1..=n {
        let i = (best + k) % n;
        let bulge = if k == n {
            before.bulge
        } else {
            contour.vertices[i].bulge
        };
        out.push(Vertex {
            point: contour.vertices[i].point,
            bulge,
        });
    }
    out.push(Vertex {
        point: start,
        bulge: 0.0,
    });
    // A pierce point on a vertex leaves a zero-length piece: merge it into its neighbour,
    // keeping the bulge of the piece that has length.
    out.dedup_by(|later, earlier| {
        if later.point != earlier.point {
            return false;
        }
        if earlier.bulge == 0.0 {
            earlier.bulge = later.bulge;
        }
        true
    });
    if out.len() == 1 {
        out.push(Vertex {
            point: start,
            bulge: 0.0,
        });
    }
    if let Some(last) = out.last_mut() {
        last.bulge = 0.0;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(r: f64, bulge: f64) -> Contour {
        Contour::new(vec![
            Vertex::arc(0.0, r, bulge),
            Vertex::arc(0.0, -r, bulge),
        ])
    }

    #[test]
    fn part_area_subtracts_holes_in_either_orientation() {
        let ring = |hole_bulge| Part {
            name: "R".into(),
            contours: vec![circle(2.0, -1.0), circle(1.0, hole_bulge)],
        };
        let expected = std::f64::consts::PI * 3.0;
        assert!((part_area(&ring(1.0)) - expected).abs() < 1e-9);
        assert!((part_area(&ring(-1.0)) - expected).abs() < 1e-9);
        assert!((part_perimeter(&ring(1.0)) - 6.0 * std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn angle_conversion_round_trips() {
        assert!((bulge_to_degrees(1.0) - 180.0).abs() < 1e-12);
        assert!((degrees_to_bulge(90.0) - (2f64.sqrt() - 1.0)).abs() < 1e-12);
        assert!((degrees_to_bulge(bulge_to_degrees(-0.3)) + 0.3).abs() < 1e-12);
    }

    #[test]
    fn half_bulges_recombine() {
        let b = 0.7;
        let h = half_bulge(b);
        assert!((2.0 * h / (1.0 - h * h) - b).abs() < 1e-12);
    }

    fn cut_length(cut: &[Vertex]) -> f64 {
        cut.windows(2)
            .map(|w| span(w[0].point, w[1].point, w[0].bulge).length())
            .sum()
    }

    #[test]
    fn cut_from_mid_arc_keeps_the_length() {
        let c = circle(5.0, -1.0);
        let pierce = Point::new(5.0, 0.0);
        let cut = cut_from(&c, pierce).unwrap();
        assert_eq!(cut.first().unwrap().point, cut.last().unwrap().point);
        assert!(dist(cut[0].point, pierce) < 1e-9);
        assert_eq!(cut.len(), 4);
        assert!((cut_length(&cut) - c.perimeter()).abs() < 1e-9);
    }

    #[test]
    fn cut_from_a_vertex_adds_no_sliver() {
        let square = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, 10.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(10.0, 0.0),
        ]);
        let cut = cut_from(&square, Point::new(10.0, 10.0)).unwrap();
        let points: Vec<Point> = cut.iter().map(|v| v.point).collect();
        assert_eq!(
            points,
            [
                (10.0, 10.0),
                (10.0, 0.0),
                (0.0, 0.0),
                (0.0, 10.0),
                (10.0, 10.0)
            ]
            .map(|(x, y)| Point::new(x, y))
        );
        assert!((cut_length(&cut) - 40.0).abs() < 1e-12);
    }
}
