//! Deterministic synthetic nests for tests and benchmarks.
//!
//! Parts are drawn from a small catalogue (rounded rectangles, rings, flanges with bolt holes,
//! rotated L-shapes, frames whose large hole holds another part) and placed one per cell of a
//! square grid of 100 mm cells, so they never overlap. Outer contours run clockwise, holes
//! counter-clockwise, as in real files.

use crate::float::Libm;
use std::f64::consts::{FRAC_PI_8, PI, TAU};

use crate::{Contour, Nest, Part, Point, SplitMix64, Transform, Vertex};

/// Side of the square grid cell each part is placed in, mm.
const CELL: f64 = 100.0;

/// A rectangle centred at the origin with rounded corners (radius `r`, quarter arcs of bulge
/// `tan(π/8)`), counter-clockwise, starting on the bottom edge.
fn rounded_rectangle(width: f64, height: f64, r: f64) -> Contour {
    let (x0, y0, x1, y1) = (-width / 2.0, -height / 2.0, width / 2.0, height / 2.0);
    if r <= 0.0 {
        return Contour::new(vec![
            Vertex::line(x0, y0),
            Vertex::line(x1, y0),
            Vertex::line(x1, y1),
            Vertex::line(x0, y1),
        ]);
    }
    let q = FRAC_PI_8.tan_libm();
    Contour::new(vec![
        Vertex::line(x0 + r, y0),
        Vertex::arc(x1 - r, y0, q),
        Vertex::line(x1, y0 + r),
        Vertex::arc(x1, y1 - r, q),
        Vertex::line(x1 - r, y1),
        Vertex::arc(x0 + r, y1, q),
        Vertex::line(x0, y1 - r),
        Vertex::arc(x0, y0 + r, q),
    ])
}

fn clockwise(c: Contour) -> Contour {
    if c.is_clockwise() {
        c
    } else {
        c.reversed()
    }
}

fn counter_clockwise(c: Contour) -> Contour {
    if c.is_clockwise() {
        c.reversed()
    } else {
        c
    }
}

/// A part centred at the origin, fitting in a disc of radius 45 mm (so in one cell), using at
/// most `budget` contours (at least 1).
fn random_part(rng: &mut SplitMix64, budget: usize, serial: usize) -> Vec<Part> {
    let kind = rng.below(5);
    let part = |name: &str, contours: Vec<Contour>| Part {
        name: format!("{name}-{serial}"),
        contours,
    };
    match kind {
        // Flange: outer disc, centre hole, 3–8 bolt holes.
        0 if budget >= 5 => {
            let r_outer = rng.range(35.0, 45.0);
            let r_centre = rng.range(0.2, 0.4) * r_outer;
            let bolts = (3 + rng.below(6) as usize).min(budget - 2);
            let pitch = 0.5 * (r_outer + r_centre);
            let max_bolt = (0.5 * (r_outer - r_centre) - 1.0)
                .min(pitch * (PI / bolts as f64).sin_libm() - 1.0);
            let r_bolt = rng.range(0.4, 0.9) * max_bolt;
            let phase = rng.range(0.0, TAU);
            let mut contours = vec![
                Contour::circle(Point::ORIGIN, r_outer, true),
                Contour::circle(Point::ORIGIN, r_centre, false),
            ];
            contours.extend((0..bolts).map(|k| {
                let a = phase + TAU * k as f64 / bolts as f64;
                Contour::circle(
                    Point::new(pitch * a.cos_libm(), pitch * a.sin_libm()),
                    r_bolt,
                    false,
                )
            }));
            vec![part("flange", contours)]
        }
        // Frame: a rounded square with a large rounded hole holding a disc (maybe a ring).
        1 if budget >= 3 => {
            let side = rng.range(80.0, 88.0);
            let wall = rng.range(5.0, 10.0);
            let hole = side - 2.0 * wall;
            let frame = part(
                "frame",
                vec![
                    clockwise(rounded_rectangle(side, side, rng.range(2.0, 8.0))),
                    counter_clockwise(rounded_rectangle(hole, hole, rng.range(2.0, 10.0))),
                ],
            );
            let r = rng.range(0.2, 0.4) * hole;
            let centre = Point::new(rng.range(-0.05, 0.05) * hole, rng.range(-0.05, 0.05) * hole);
            let mut inner = vec![Contour::circle(centre, r, true)];
            if budget >= 4 {
                inner.push(Contour::circle(centre, rng.range(0.3, 0.7) * r, false));
            }
            vec![frame, part("inlay", inner)]
        }
        // Ring.
        2 if budget >= 2 => {
            let r = rng.range(20.0, 45.0);
            let centre = Point::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let outer = Contour::circle(centre, r.min(44.0 - centre.norm()), true);
            vec![part(
                "ring",
                vec![
                    outer,
                    Contour::circle(centre, rng.range(0.3, 0.8) * r, false),
                ],
            )]
        }
        // L-shape, rotated by a random angle.
        3 => {
            let (a, b) = (rng.range(35.0, 60.0), rng.range(35.0, 60.0));
            let t = rng.range(10.0, 0.6 * a.min(b));
            let l = Contour::new(vec![
                Vertex::line(0.0, 0.0),
                Vertex::line(a, 0.0),
                Vertex::line(a, t),
                Vertex::line(t, t),
                Vertex::line(t, b),
                Vertex::line(0.0, b),
            ]);
            let placement = Transform::translation(-a / 2.0, -b / 2.0)
                .then(&Transform::rotation(rng.range(0.0, TAU)));
            vec![part("angle", vec![clockwise(l.transformed(&placement))])]
        }
        // Rounded rectangle, with a round hole when the budget allows.
        _ => {
            let (w, h) = (rng.range(40.0, 62.0), rng.range(40.0, 62.0));
            let r = rng.range(0.0, 0.25 * w.min(h));
            let mut contours = vec![clockwise(rounded_rectangle(w, h, r))];
            if budget >= 2 && rng.below(2) == 0 {
                contours.push(Contour::circle(
                    Point::ORIGIN,
                    rng.range(0.1, 0.3) * w.min(h),
                    false,
                ));
            }
            vec![part("plate", contours)]
        }
    }
}

/// A nest of exactly `contour_count` contours of mixed parts, the same for the same seed.
///
/// The sheet is the smallest square grid of 100 mm cells holding every part group (a frame
/// and the part inside its hole share a cell); parts never overlap.
///
/// ```
/// let nest = cutroute_geometry::generate_nest(500, 7);
/// assert_eq!(nest.contour_count(), 500);
/// assert!(nest.parts.iter().all(|p| p.contours[0].is_clockwise()));
/// ```
pub fn generate_nest(contour_count: usize, seed: u64) -> Nest {
    let mut rng = SplitMix64::new(seed);
    let mut groups: Vec<Vec<Part>> = Vec::new();
    let mut remaining = contour_count;
    while remaining > 0 {
        let group = random_part(&mut rng, remaining, groups.len());
        remaining -= group.iter().map(|p| p.contours.len()).sum::<usize>();
        groups.push(group);
    }
    let columns = (groups.len() as f64).sqrt().ceil().max(1.0) as usize;
    let rows = groups.len().div_ceil(columns).max(1);
    let mut parts = Vec::with_capacity(groups.len() + groups.len() / 5);
    for (k, group) in groups.into_iter().enumerate() {
        let centre = Point::new(
            ((k % columns) as f64 + 0.5) * CELL,
            ((k / columns) as f64 + 0.5) * CELL,
        );
        let to_cell = Transform::translation(centre.x, centre.y);
        parts.extend(group.iter().map(|p| p.transformed(&to_cell)));
    }
    let (width, height) = (columns as f64 * CELL, rows as f64 * CELL);
    let sheet = Part {
        name: "sheet".to_string(),
        contours: vec![Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, height),
            Vertex::line(width, height),
            Vertex::line(width, 0.0),
        ])],
    };
    Nest {
        sheet: Some(sheet),
        parts,
    }
}
