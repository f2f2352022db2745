//! Property tests: span and contour maths against dense polyline approximations.

use proptest::prelude::*;

use cutroute_geometry::{Contour, Part, Point, Span, Transform, Vertex};

fn point() -> impl Strategy<Value = Point> {
    (-100.0..100.0f64, -100.0..100.0f64).prop_map(|(x, y)| Point::new(x, y))
}

fn bulge() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -3.0..3.0f64,
        1 => Just(0.0),
        1 => Just(1.0),
        1 => Just(-1.0),
        1 => -1e-6..1e-6f64,
        1 => prop_oneof![Just(1e-12), Just(-1e-9), Just(5.0), Just(-20.0)],
    ]
}

fn span() -> impl Strategy<Value = Span> {
    (point(), point(), bulge())
        .prop_filter("non-degenerate chord", |(a, z, _)| a.distance(*z) > 0.1)
        .prop_map(|(a, z, b)| Span::new(a, z, b))
}

/// A star-shaped polygon around the origin with arcs of moderate bulge; may self-intersect
/// (area and winding number do not need simplicity).
fn contour() -> impl Strategy<Value = Contour> {
    prop::collection::vec((0.0..1.0f64, 5.0..50.0f64, -0.6..0.6f64), 3..12).prop_map(|mut raw| {
        raw.sort_by(|a, b| a.0.total_cmp(&b.0));
        let n = raw.len() as f64;
        let vertices = raw
            .iter()
            .enumerate()
            // Spread the angles so no two vertices coincide.
            .map(|(i, &(a, r, b))| {
                let angle = std::f64::consts::TAU * (i as f64 + 0.8 * a) / n;
                Vertex::arc(r * angle.cos(), r * angle.sin(), b)
            })
            .collect();
        Contour::new(vertices)
    })
}

fn samples(s: &Span, n: usize) -> Vec<Point> {
    (0..=n).map(|k| s.point_at(k as f64 / n as f64)).collect()
}

fn polyline_length(points: &[Point]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// Dense closed polygon of a contour (closing point not repeated).
fn dense(c: &Contour, per_span: usize) -> Vec<Point> {
    c.spans()
        .flat_map(|s| (0..per_span).map(move |k| s.point_at(k as f64 / per_span as f64)))
        .collect()
}

fn shoelace(poly: &[Point]) -> f64 {
    let o = poly[0];
    (0..poly.len())
        .map(|i| 0.5 * (poly[i] - o).cross(poly[(i + 1) % poly.len()] - o))
        .sum()
}

fn polygon_winding(poly: &[Point], p: Point) -> i32 {
    let mut w = 0;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if a.y <= p.y {
            if b.y > p.y && (b - a).cross(p - a) > 0.0 {
                w += 1;
            }
        } else if b.y <= p.y && (b - a).cross(p - a) < 0.0 {
            w -= 1;
        }
    }
    w
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn span_length_matches_dense_polyline(s in span()) {
        let poly = polyline_length(&samples(&s, 4000));
        let l = s.length();
        prop_assert!(poly <= l * (1.0 + 1e-12) + 1e-12);
        prop_assert!((l - poly).abs() <= 1e-5 * l.max(1.0), "{} vs {}", l, poly);
        // Samples are equally spaced along the arc (arc-length parameter).
        let a = s.point_at(0.25).distance(s.point_at(0.0));
        let b = s.point_at(0.5).distance(s.point_at(0.25));
        prop_assert!((a - b).abs() <= 1e-9 * l.max(1.0));
    }

    #[test]
    fn span_points_and_tangents_agree(s in span(), t in 0.0..1.0f64) {
        let h = 1e-6;
        let (t0, t1) = ((t - h).max(0.0), (t + h).min(1.0));
        let numeric = (s.point_at(t1) - s.point_at(t0)).normalized();
        prop_assert!(numeric.distance(s.tangent_at(t)) < 1e-4);
        if let Some(c) = s.centre() {
            if s.radius() < 1e6 {
                prop_assert!((s.point_at(t).distance(c) - s.radius()).abs() < 1e-9 * s.radius().max(1.0));
            }
        }
        prop_assert!((s.parameter_of(s.point_at(t)) - t).abs() < 1e-7);
    }

    #[test]
    fn detour_minimum_is_the_least_detour_over_the_span(
        s in span(),
        ax in -300.0..300.0f64, ay in -300.0..300.0f64,
        bx in -300.0..300.0f64, by in -300.0..300.0f64,
        open in any::<bool>(),
    ) {
        let (a, b) = (Point::new(ax, ay), Point::new(bx, by));
        let b = (!open).then_some(b);
        let f = |t: f64| {
            let m = s.point_at(t);
            a.distance(m) + b.map_or(0.0, |b| m.distance(b))
        };
        let (t, value) = s.detour_minimum(a, b);
        prop_assert!((0.0..=1.0).contains(&t));
        prop_assert!((f(t) - value).abs() <= 1e-9 * (1.0 + value));
        let sampled = (0..=4000).map(|k| f(k as f64 / 4000.0)).fold(f64::INFINITY, f64::min);
        prop_assert!(value <= sampled + 1e-7 * (1.0 + sampled), "{} vs sampled {}", value, sampled);
    }

    #[test]
    fn distance_between_spans_is_the_least_over_samples(
        s in span(),
        o in span(),
        shift in prop_oneof![Just(Point::new(0.0, 0.0)), point(), point().prop_map(|p| p * 3.0)],
    ) {
        let o = Span::new(o.start + shift, o.end + shift, o.bulge);
        let d = s.distance_to_span(&o);
        prop_assert!((d - o.distance_to_span(&s)).abs() <= 1e-7 * (1.0 + d));
        // Never above any sampled pair (it is a true distance between points of the spans) …
        let (ps, po) = (samples(&s, 600), samples(&o, 600));
        let sampled = ps
            .iter()
            .map(|p| o.distance_to(*p))
            .chain(po.iter().map(|p| s.distance_to(*p)))
            .fold(f64::INFINITY, f64::min);
        prop_assert!(d <= sampled + 1e-7 * (1.0 + sampled), "{} above sampled {}", d, sampled);
        // … and never below the sampled minimum by more than the sampling step allows.
        let step = s.length().max(o.length()) / 600.0;
        prop_assert!(d >= sampled - step - 1e-7, "{} far below sampled {}", d, sampled);
    }

    #[test]
    fn nearest_point_to_a_span_attains_the_set_distance(
        s in span(),
        o in span(),
        shift in prop_oneof![Just(Point::new(0.0, 0.0)), point(), point().prop_map(|p| p * 3.0)],
    ) {
        let o = Span::new(o.start + shift, o.end + shift, o.bulge);
        let n = s.nearest_point_to_span(&o);
        // A point of this span at its parameter, whose distance to the other is the one given …
        prop_assert!((0.0..=1.0).contains(&n.t));
        let tol = 1e-7 * (1.0 + s.length() + o.length() + n.distance);
        prop_assert!(s.point_at(n.t).distance(n.point) <= tol);
        prop_assert!((o.distance_to(n.point) - n.distance).abs() <= tol);
        // … and that is the set distance, so no sampled point of this span is nearer.
        prop_assert!((n.distance - s.distance_to_span(&o)).abs() <= tol,
            "{} vs set distance {}", n.distance, s.distance_to_span(&o));
        let sampled = samples(&s, 600)
            .iter()
            .map(|p| o.distance_to(*p))
            .fold(f64::INFINITY, f64::min);
        prop_assert!(n.distance <= sampled + tol, "{} above sampled {}", n.distance, sampled);
    }

    #[test]
    fn span_bounding_box_is_exact(s in prop_oneof![
        4 => span(),
        // Either side of the bulges where the arc's box changes method.
        1 => (point(), point(), prop_oneof![5e-5..2e-4f64, -2e-4..-5e-5f64, 5e3..2e4f64, -2e4..-5e3f64])
            .prop_map(|(a, z, b)| Span::new(a, z, b)),
    ]) {
        let b = s.bounding_box();
        let pts = samples(&s, 4000);
        let eps = 1e-9 * (1.0 + s.length());
        prop_assert!(pts.iter().all(|p| b.expanded(eps).contains_point(*p)));
        let sampled = cutroute_geometry::BoundingBox::from_points(pts);
        let slack = 1e-5 * s.length().max(1.0);
        prop_assert!((sampled.min.x - b.min.x).abs() < slack && (sampled.max.x - b.max.x).abs() < slack);
        prop_assert!((sampled.min.y - b.min.y).abs() < slack && (sampled.max.y - b.max.y).abs() < slack);
    }

    #[test]
    fn box_distance_to_a_point_is_the_clamped_distance_and_bounds_the_span(s in span(), q in point()) {
        let b = s.bounding_box();
        let clamped = Point::new(q.x.clamp(b.min.x, b.max.x), q.y.clamp(b.min.y, b.max.y));
        let d = b.distance_to_point(q);
        prop_assert!((d - q.distance(clamped)).abs() <= 1e-12 * (1.0 + d));
        let eps = 1e-9 * (1.0 + s.length());
        prop_assert!(samples(&s, 64).iter().all(|p| d <= q.distance(*p) + eps));
        prop_assert_eq!(b.distance_to_point(b.centre()), 0.0);
        prop_assert!(cutroute_geometry::BoundingBox::EMPTY.distance_to_point(q).is_infinite());
    }

    #[test]
    fn fast_norms_agree_with_the_hypot_ones(p in point(), q in point()) {
        let v = q - p;
        prop_assert!((v.fast_norm() - v.norm()).abs() <= 4.0 * f64::EPSILON * v.norm());
        prop_assert_eq!(p.fast_distance(q), v.fast_norm());
        prop_assert_eq!(p.fast_distance(q), q.fast_distance(p));
        let u = v.fast_unit();
        if v.fast_norm() > 0.0 {
            prop_assert!((u.fast_norm() - 1.0).abs() <= 1e-15);
            prop_assert!(u.cross(v).abs() <= 1e-12 * v.fast_norm() && u.dot(v) > 0.0);
        } else {
            prop_assert_eq!(u, Point::ORIGIN);
        }
    }

    #[test]
    fn box_gaps_are_the_box_distances(s in span(), o in span(), q in point()) {
        let (a, b) = (s.bounding_box(), o.bounding_box());
        prop_assert_eq!(a.gap_to_point(q).norm(), a.distance_to_point(q));
        prop_assert_eq!(a.gap_to_box(&b).norm(), a.distance_to_box(&b));
        prop_assert_eq!(a.gap_to_box(&b), b.gap_to_box(&a));
        let scale = 1e-12 * (1.0 + a.distance_to_box(&b));
        prop_assert!((a.gap_to_box(&b).fast_norm() - a.distance_to_box(&b)).abs() <= scale);
        // The gap to the box of a point is the gap to the point.
        let point_box = cutroute_geometry::BoundingBox::from_corners(q, q);
        prop_assert_eq!(a.gap_to_box(&point_box), a.gap_to_point(q));
    }

    #[test]
    fn split_then_merge_is_identity(s in span(), t in 0.01..0.99f64) {
        let (a, b) = s.split_at(t);
        prop_assert!((a.length() + b.length() - s.length()).abs() < 1e-9 * s.length().max(1.0));
        prop_assert!(a.end.distance(s.point_at(t)) < 1e-12 * (1.0 + s.length()));
        prop_assert!(a.point_at(0.5).distance(s.point_at(0.5 * t)) < 1e-9 * s.length().max(1.0));
        let merged = a.joined(&b, 1e-7 * s.length().max(1.0));
        prop_assert!(merged.is_some(), "{:?} {:?}", a, b);
        let m = merged.unwrap();
        prop_assert_eq!(m.start, s.start);
        prop_assert_eq!(m.end, s.end);
        prop_assert!((m.bulge - s.bulge).abs() <= 1e-9 * (1.0 + s.bulge.abs() * s.bulge.abs()));
    }

    #[test]
    fn halves_are_the_split_at_the_middle(s in span()) {
        let (a, b) = s.halved();
        let (x, y) = s.split_at(0.5);
        let scale = s.length().max(1.0);
        prop_assert_eq!(a.start, s.start);
        prop_assert_eq!(b.end, s.end);
        prop_assert_eq!(a.end, b.start);
        prop_assert!(a.end.distance(x.end) < 1e-9 * scale);
        prop_assert!((a.bulge - x.bulge).abs() <= 1e-12 * (1.0 + x.bulge.abs()));
        prop_assert!((b.bulge - y.bulge).abs() <= 1e-12 * (1.0 + y.bulge.abs()));
        prop_assert!((a.length() - 0.5 * s.length()).abs() < 1e-9 * scale);
        prop_assert!((b.length() - 0.5 * s.length()).abs() < 1e-9 * scale);
        // Each half turns less than half a circle, whatever the span turns.
        prop_assert!(a.bulge.abs() < 1.0 && b.bulge.abs() < 1.0);
    }

    #[test]
    fn arc_through_its_own_point(s in span(), t in 0.05..0.95f64) {
        let via = s.point_at(t);
        if let Some(r) = Span::through_points(s.start, via, s.end) {
            prop_assert!((r.sweep() - s.sweep()).abs() < 1e-6, "{:?} vs {:?}", r, s);
        } else {
            prop_assert!(false, "no arc through {:?}", via);
        }
    }

    #[test]
    fn nearest_point_beats_samples(s in span(), q in point()) {
        let n = s.nearest_point(q);
        prop_assert!((0.0..=1.0).contains(&n.t));
        prop_assert!((s.point_at(n.t).distance(q) - n.distance).abs() < 1e-9 * (1.0 + n.distance));
        let best_sample = samples(&s, 2000).into_iter().map(|p| p.distance(q)).fold(f64::INFINITY, f64::min);
        prop_assert!(n.distance <= best_sample + 1e-9 * (1.0 + best_sample), "{} > {}", n.distance, best_sample);
    }

    #[test]
    fn intersections_are_on_both_and_complete(s in span(), o in span()) {
        let found = s.intersections(&o);
        for x in &found {
            prop_assert!(s.point_at(x.t_self).distance(x.point) < 1e-6);
            prop_assert!(o.point_at(x.t_other).distance(x.point) < 1e-6);
        }
        // Every transversal crossing of the dense polylines is near a reported intersection,
        // unless all possible intersections were found already. Near-tangent crossings are left
        // out: there the chords of two arcs can cross where the arcs themselves pass each other
        // at a tiny gap (bulges −20 and 5 did), or a true crossing's polyline image drifts far.
        let most = if s.is_line() && o.is_line() { 1 } else { 2 };
        prop_assume!(found.len() < most);
        let (ps, po) = (samples(&s, 600), samples(&o, 600));
        // A chord strays from its arc by at most the sagitta R·(1 − cos(θ/2)), θ = sweep/600,
        // and two chords crossing at angle α place their crossing up to (e₁ + e₂)/sin α away
        // from the arcs' crossing (−20-bulge arcs of radius 895 and 470 crossing at 14° put
        // it 0.053 away).
        let sagitta = |s: &Span| if s.is_line() { 0.0 } else {
            s.radius() * (1.0 - (s.sweep().abs() / 1200.0).cos())
        };
        let stray = sagitta(&s) + sagitta(&o);
        let mut misses = 0;
        for a in ps.windows(2) {
            for b in po.windows(2) {
                let (r, q) = (a[1] - a[0], b[1] - b[0]);
                let den = r.cross(q);
                if den.abs() < 1e-12 || den.abs() < 0.05 * r.norm() * q.norm() { continue; }
                let w = b[0] - a[0];
                let (t, u) = (w.cross(q) / den, w.cross(r) / den);
                if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                    let hit = a[0] + r * t;
                    let reach = 0.05f64.max(2.0 * stray * r.norm() * q.norm() / den.abs());
                    if !found.iter().any(|x| x.point.distance(hit) < reach) { misses += 1; }
                }
            }
        }
        prop_assert_eq!(misses, 0, "{:?}", found);
    }

    #[test]
    fn contour_area_and_perimeter_match_dense_polygon(c in contour()) {
        let poly = dense(&c, 800);
        let area = shoelace(&poly);
        // The inscribed polygon misses n·R²(θ − sin θ)/2 ≤ n·R²·θ³/12 per arc, θ = |φ|/n.
        let missed: f64 = c
            .spans()
            .filter(|s| !s.is_line())
            .map(|s| {
                let theta = s.sweep().abs() / 800.0;
                800.0 * s.radius() * s.radius() * theta.powi(3) / 12.0
            })
            .sum();
        let tolerance = 1.01 * missed + 1e-9 * c.perimeter() * c.perimeter();
        prop_assert!((c.signed_area() - area).abs() <= tolerance, "{} vs {} (tol {})", c.signed_area(), area, tolerance);
        let mut closed = poly.clone();
        closed.push(poly[0]);
        let per = polyline_length(&closed);
        prop_assert!((c.perimeter() - per).abs() <= 1e-5 * per);
        prop_assert_eq!(c.is_clockwise(), area < 0.0);
    }

    #[test]
    fn part_area_is_material_whatever_the_hole_orientation(c in contour(), hole_reversed: bool) {
        // The outer contour twice the size of the hole; both star-shaped about the origin.
        let outer = c.transformed(&Transform::scaling(2.0));
        let hole = if hole_reversed { c.reversed() } else { c.clone() };
        let part = Part { name: "P".into(), contours: vec![outer.clone(), hole.clone()] };
        let (outer_poly, hole_poly) = (dense(&outer, 800), dense(&hole, 800));
        let material = shoelace(&outer_poly).abs() - shoelace(&hole_poly).abs();
        let tolerance = 1e-3 * outer.perimeter() * outer.perimeter() / 800.0;
        prop_assert!((part.area() - material).abs() <= tolerance, "{} vs {}", part.area(), material);
        let mut cut = 0.0;
        for poly in [outer_poly, hole_poly] {
            let mut closed = poly.clone();
            closed.push(poly[0]);
            cut += polyline_length(&closed);
        }
        prop_assert!((part.perimeter() - cut).abs() <= 1e-5 * cut);
        prop_assert_eq!(Part::default().area(), 0.0);
    }

    #[test]
    fn point_in_contour_matches_dense_winding(c in contour(), q in (-60.0..60.0f64, -60.0..60.0f64)) {
        let q = Point::new(q.0, q.1);
        prop_assume!(c.distance_to(q) > 1e-2);
        let poly: Vec<Point> = c.flatten(1e-5);
        prop_assert_eq!(c.winding_number(q), polygon_winding(&poly, q));
    }

    #[test]
    fn point_in_contour_on_grid_points(
        raw in prop::collection::vec((-20i32..20, -20i32..20, prop_oneof![Just(0.0), Just(1.0), Just(-1.0), Just(0.5), Just(-0.25), Just(2.0)]), 2..7),
        qx in -40i32..40, qy in -40i32..40,
    ) {
        // Vertices and query points on a grid: the query often sits exactly on a chord's line
        // or at a vertex's height, the degenerate cases of ray casting.
        let c = Contour::new(raw.iter().map(|&(x, y, b)| Vertex::arc(x as f64, y as f64, b)).collect());
        let q = Point::new(qx as f64 * 0.5, qy as f64 * 0.5);
        prop_assume!(c.distance_to(q) > 1e-3);
        let poly: Vec<Point> = c.flatten(1e-6);
        prop_assert_eq!(c.winding_number(q), polygon_winding(&poly, q));
    }

    #[test]
    fn reverse_twice_is_identity(c in contour()) {
        let r = c.reversed();
        prop_assert_eq!(r.reversed(), c.clone());
        prop_assert!((r.signed_area() + c.signed_area()).abs() < 1e-9 * c.area().max(1.0));
        prop_assert!((r.perimeter() - c.perimeter()).abs() < 1e-9 * c.perimeter());
        // The same point set: reversed contour's samples lie on the original.
        for p in dense(&r, 5) {
            prop_assert!(c.distance_to(p) < 1e-9);
        }
    }

    #[test]
    fn similarities_are_recognised(
        angle in -7.0..7.0f64, scale in 0.01..100.0f64, mirror: bool, dx in -1e3..1e3f64,
        stretch in 1.001..10.0f64, c in contour(),
    ) {
        let mut t = Transform::rotation(angle).then(&Transform::scaling(scale));
        if mirror { t = t.then(&Transform::mirror_x()); }
        let t = t.then(&Transform::translation(dx, -dx));
        prop_assert!(t.is_similarity());
        // A similarity maps an arc onto the arc of the mapped ends and bulge: the image of the
        // span's midpoint is the mapped span's midpoint.
        for s in c.spans() {
            let image = s.transformed(&t);
            let expected = t.apply(s.point_at(0.5));
            prop_assert!(image.point_at(0.5).distance(expected) < 1e-9 * scale * 100.0);
        }
        let uneven = Transform { matrix: [[stretch, 0.0], [0.0, 1.0]], offset: Point::ORIGIN };
        prop_assert!(!uneven.then(&t).is_similarity());
        prop_assert!(!t.then(&uneven).is_similarity());
        let sheared = Transform { matrix: [[1.0, stretch - 1.0], [0.0, 1.0]], offset: Point::ORIGIN };
        prop_assert!(!sheared.then(&t).is_similarity());
        let singular = Transform { matrix: [[0.0; 2]; 2], offset: Point::ORIGIN };
        prop_assert!(!singular.is_similarity());
    }

    #[test]
    fn transform_then_inverse_is_identity(
        c in contour(), angle in -7.0..7.0f64, scale in 0.5..2.0f64, mirror: bool, dx in -1e3..1e3f64, dy in -1e3..1e3f64
    ) {
        let mut t = Transform::rotation(angle).then(&Transform::scaling(scale));
        if mirror { t = t.then(&Transform::mirror_y()); }
        let t = t.then(&Transform::translation(dx, dy));
        let image = c.transformed(&t);
        prop_assert!((image.signed_area() - c.signed_area() * t.determinant()).abs() < 1e-6 * c.area().max(1.0) * scale * scale);
        let inverse = t.inverse().unwrap();
        let back = image.transformed(&inverse);
        for (a, b) in back.vertices.iter().zip(&c.vertices) {
            prop_assert!(a.point.distance(b.point) < 1e-9 * 1e3);
            prop_assert_eq!(a.bulge, b.bulge);
        }
    }

    #[test]
    fn contour_nearest_and_length_parameterisation(c in contour(), q in point(), s in 0.0..1.0f64) {
        let n = c.nearest_point(q).unwrap();
        let best_sample = dense(&c, 300).into_iter().map(|p| p.distance(q)).fold(f64::INFINITY, f64::min);
        prop_assert!(n.distance <= best_sample + 1e-9);
        let length = s * c.perimeter();
        let pos = c.position_at_length(length).unwrap();
        prop_assert!((c.length_at(pos) - length).abs() < 1e-9 * c.perimeter());
        prop_assert!(c.point_at_length(length).unwrap().distance(c.point_at(pos).unwrap()) < 1e-12);
    }
}

proptest! {
    /// Candidate pierce points lie on the contour, walk it in order (their arc lengths never
    /// decrease), are `step` apart where no vertex falls between, and number exactly the points
    /// of the grid plus the vertices that are not on it.
    #[test]
    fn candidate_points_walk_the_contour_every_step(c in contour(), step in 0.5f64..40.0) {
        let perimeter = c.perimeter();
        prop_assume!(perimeter > 1e-3);
        let without = c.candidate_points(step, false);
        let with = c.candidate_points(step, true);
        for p in with.iter() {
            prop_assert!(c.distance_to(*p) < 1e-6 * (1.0 + perimeter), "{p:?} off the contour");
        }
        // The grid alone: points at 0, step, 2 step, … up to the perimeter (the last one may
        // fall on vertex 0 again at exactly the perimeter).
        let grid = (perimeter / step).floor() as usize + 1;
        prop_assert!(without.len() == grid || without.len() + 1 == grid,
            "{} grid points for {grid}", without.len());
        for (k, p) in without.iter().enumerate() {
            let expected = c.point_at_length(k as f64 * step).unwrap();
            prop_assert!(p.distance(expected) < 1e-6 * (1.0 + perimeter));
        }
        // With the vertices: each vertex is among the points (once).
        for v in &c.vertices {
            prop_assert!(with.iter().any(|p| p.distance(v.point) < 1e-6 * (1.0 + perimeter)));
        }
        prop_assert!(with.len() <= without.len() + c.vertices.len());
        prop_assert!(with.len() >= without.len());
    }
}

/// `nearest_groups` by comparing all pairs: the `k` nearest other groups by their least
/// point-to-point distance, nearest first, ties by index.
fn nearest_groups_by_all_pairs(groups: &[Vec<Point>], k: usize) -> Vec<Vec<usize>> {
    (0..groups.len())
        .map(|a| {
            let mut d: Vec<(f64, usize)> = (0..groups.len())
                .filter(|&b| b != a && !groups[b].is_empty())
                .map(|b| {
                    let d = groups[a]
                        .iter()
                        .flat_map(|p| groups[b].iter().map(move |q| p.distance(*q)))
                        .fold(f64::INFINITY, f64::min);
                    (d, b)
                })
                .filter(|(d, _)| d.is_finite())
                .collect();
            d.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            d.truncate(k);
            d.into_iter().map(|(_, b)| b).collect()
        })
        .collect()
}

proptest! {
    /// The R-tree's neighbour lists are the all-pairs ones (random real coordinates, so no
    /// ties), for groups of one or two points and any k.
    #[test]
    fn nearest_groups_are_those_of_all_pairs(
        groups in prop::collection::vec(
            prop::collection::vec((-100.0f64..100.0, -100.0f64..100.0), 1..3),
            0..40,
        ),
        k in 0usize..8,
    ) {
        let groups: Vec<Vec<Point>> = groups
            .into_iter()
            .map(|g| g.into_iter().map(|(x, y)| Point::new(x, y)).collect())
            .collect();
        prop_assert_eq!(
            cutroute_geometry::nearest_groups(&groups, k),
            nearest_groups_by_all_pairs(&groups, k)
        );
    }
}
