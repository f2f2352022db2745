//! Cutter compensation as LinuxCNC's interpreter computes it (`interp_convert.cc`): the
//! stretch from `G41`/`G42` to the move after `G40`, gathered whole, becomes the tool centre's
//! path.
//!
//! - The start-up move (straight, from where the head stands to the programmed point `P`) ends
//!   at `P` offset by the radius perpendicular to the move itself, to the compensation side; a
//!   start-up move not longer than the radius is refused.
//! - Every later programmed line or arc is offset by the radius (an arc's radius grows or
//!   shrinks; an arc that would vanish is refused).
//! - At a corner where the tool is outside the turn (convex), an arc about the programmed
//!   corner joins the two offsets; where it is inside (concave), both offsets end at their
//!   intersection, and a corner the tool cannot reach without cutting into the previous move
//!   is refused, as LinuxCNC refuses it. A move shorter than its concave corner's retreat then
//!   runs backwards; LinuxCNC refuses that only where the next corner needs the move's end
//!   again (a concave corner, or a convex one sharper than its tolerance).
//! - The move after `G40` is straight and uncompensated: from where the tool stands to the
//!   programmed point, with no corner.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{Point, Span};
use std::f64::consts::{PI, TAU};

/// Which side of the programmed path the controller keeps the tool on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Side {
    Left,
    Right,
}

/// Below this (mm, or radians of turn) two directions or points are the same.
const EPS: f64 = 1e-9;
/// A convex turn up to this (radians) gets no corner arc from LinuxCNC, and the move before
/// it is not checked again (its `TOLERANCE_CONCAVE_CORNER`).
const CONVEX_CORNER_TOLERANCE: f64 = 0.05;
const GOUGE: &str = "a concave corner the tool cannot reach without gouging";

/// One piece of the tool centre's path.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line {
        a: Point,
        b: Point,
    },
    /// From `a` to `b` about `centre` (radius `|a − centre|`), counter-clockwise when `ccw`.
    Arc {
        centre: Point,
        a: Point,
        b: Point,
        ccw: bool,
        /// A whole turn (`a` = `b`).
        full: bool,
    },
}

impl Piece {
    fn start(&self) -> Point {
        match *self {
            Piece::Line { a, .. } | Piece::Arc { a, .. } => a,
        }
    }

    fn end(&self) -> Point {
        match *self {
            Piece::Line { b, .. } | Piece::Arc { b, .. } => b,
        }
    }

    fn set_end(&mut self, p: Point) {
        match self {
            Piece::Line { b, .. } => *b = p,
            Piece::Arc { b, full, .. } => {
                *b = p;
                *full = false;
            }
        }
    }

    fn set_start(&mut self, p: Point) {
        match self {
            Piece::Line { a, .. } => *a = p,
            Piece::Arc { a, full, .. } => {
                *a = p;
                *full = false;
            }
        }
    }

    /// Sweep of an arc, signed (counter-clockwise positive).
    fn sweep(centre: Point, a: Point, b: Point, ccw: bool, full: bool) -> f64 {
        let (u, v) = (a - centre, b - centre);
        let turn = v.y.atan2_libm(v.x) - u.y.atan2_libm(u.x);
        let mut s = if ccw {
            turn.rem_euclid(TAU)
        } else {
            (-turn).rem_euclid(TAU)
        };
        if full || (s < EPS && a.distance(b) < EPS) {
            s = TAU;
        }
        if ccw {
            s
        } else {
            -s
        }
    }

    /// The piece as spans of at most half a turn each.
    fn spans(&self) -> Vec<Span> {
        match *self {
            Piece::Line { a, b } => vec![Span::line(a, b)],
            Piece::Arc {
                centre,
                a,
                b,
                ccw,
                full,
            } => {
                let sweep = Piece::sweep(centre, a, b, ccw, full);
                if sweep.abs() <= PI {
                    return vec![Span::new(a, b, (sweep / 4.0).tan_libm())];
                }
                let middle = centre + (a - centre).rotated(0.5 * sweep);
                let half = (sweep / 8.0).tan_libm();
                vec![Span::new(a, middle, half), Span::new(middle, b, half)]
            }
        }
    }

    /// Whether `p` (on the piece's line or circle) lies before the piece's end, so that the
    /// piece from `p` on keeps its direction.
    fn runs_on_from(&self, p: Point) -> bool {
        match *self {
            Piece::Line { a, b } => {
                let d = b - a;
                let l2 = d.x * d.x + d.y * d.y;
                l2 > EPS * EPS && ((b - p).x * d.x + (b - p).y * d.y) / l2 > 1e-9
            }
            Piece::Arc {
                centre,
                a,
                b,
                ccw,
                full,
            } => {
                if full {
                    return true;
                }
                let whole = Piece::sweep(centre, a, b, ccw, false).abs();
                let to_p = Piece::sweep(centre, a, p, ccw, false).abs();
                // Past the start (trimmed) and short of the end, or behind the start.
                to_p < whole - 1e-9 || to_p > PI + 0.5 * whole
            }
        }
    }

    /// Whether `p` (on the piece's line or circle) lies on the piece past its start, within
    /// a small tolerance of its end.
    fn reaches(&self, p: Point) -> bool {
        match *self {
            Piece::Line { a, b } => {
                let d = b - a;
                let l2 = d.x * d.x + d.y * d.y;
                if l2 <= EPS * EPS {
                    return false;
                }
                let t = ((p - a).x * d.x + (p - a).y * d.y) / l2;
                t > 1e-9 && t <= 1.0 + 1e-6
            }
            Piece::Arc {
                centre,
                a,
                b,
                ccw,
                full,
            } => {
                let whole = Piece::sweep(centre, a, b, ccw, full).abs();
                let part = Piece::sweep(centre, a, p, ccw, false).abs();
                part > 1e-9 && part <= whole + 1e-6
            }
        }
    }
}

/// Unit tangent of a programmed span at its start (`t` = 0) or end (`t` = 1).
fn tangent(span: &Span, t: f64) -> Point {
    span.tangent_at(t)
}

fn unit(p: Point) -> Option<Point> {
    let l = (p.x * p.x + p.y * p.y).sqrt();
    (l > EPS).then(|| Point::new(p.x / l, p.y / l))
}

fn cross(a: Point, b: Point) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The problem LinuxCNC names, and the line of the move it stops on.
pub(super) type Refusal = (&'static str, usize);

/// The tool centre's path of a compensated stretch: from `start` (where the head stood) by the
/// start-up move to the programmed `entry`, along the programmed `spans` (each with its line),
/// and by the cancel move to `to`.
pub(super) fn tool_path(
    side: Side,
    radius: f64,
    start: Point,
    entry: Point,
    spans: &[(Span, usize)],
    to: Point,
    lines: (usize, usize),
) -> Result<Vec<(Span, usize)>, Refusal> {
    let normal = |t: Point| match side {
        Side::Left => t.rotated_quarter(),
        Side::Right => -t.rotated_quarter(),
    };
    let d0 = unit(entry - start).ok_or(("the start-up move has no length", lines.0))?;
    if start.distance(entry) <= radius {
        return Err((
            "the start-up move is not longer than the tool radius",
            lines.0,
        ));
    }
    let mut pieces: Vec<(Piece, usize)> = vec![(
        Piece::Line {
            a: start,
            b: entry + normal(d0) * radius,
        },
        lines.0,
    )];
    // The last piece that offsets a programmed move (a corner arc is never trimmed).
    let mut last = 0;
    // That piece runs backwards from its trimmed start.
    let mut next_backwards = false;
    let mut direction = d0;
    for &(span, line) in spans {
        if span.length() <= EPS {
            continue;
        }
        let (t0, t1) = (tangent(&span, 0.0), tangent(&span, 1.0));
        let mut piece = if span.bulge == 0.0 {
            Piece::Line {
                a: span.start + normal(t0) * radius,
                b: span.end + normal(t1) * radius,
            }
        } else {
            let centre = span.centre().ok_or(("an arc without a centre", line))?;
            let ccw = span.bulge > 0.0;
            let r = span.start.distance(centre);
            // The tool is inside the arc when the arc turns toward the compensation side.
            let inside = ccw == (side == Side::Left);
            let tool_r = if inside { r - radius } else { r + radius };
            if tool_r <= EPS {
                return Err(("the tool radius is not less than an arc's radius", line));
            }
            let on = |p: Point| centre + unit(p - centre).unwrap_or(Point::new(1.0, 0.0)) * tool_r;
            Piece::Arc {
                centre,
                a: on(span.start),
                b: on(span.end),
                ccw,
                full: false,
            }
        };
        let corner = span.start;
        let backwards = std::mem::replace(&mut next_backwards, false);
        let turn = cross(direction, t0);
        let dot = direction.x * t0.x + direction.y * t0.y;
        let concave = match side {
            Side::Left => turn > EPS,
            Side::Right => turn < -EPS,
        };
        // The start-up move's offset is the line through its end along the move (its tool
        // path runs from where the head stood, not along that line).
        let previous = if last == 0 {
            let end = pieces[0].0.end();
            Piece::Line {
                a: end - d0 * start.distance(entry),
                b: end,
            }
        } else {
            pieces[last].0
        };
        if turn.abs() <= EPS && dot > 0.0 {
            // Tangent: the offsets meet.
            piece.set_start(previous.end());
        } else if concave {
            let x = intersection(&previous, &piece, corner).ok_or((GOUGE, line))?;
            if !previous.reaches(x) || backwards {
                return Err((GOUGE, line));
            }
            // A move shorter than the corner's retreat now runs backwards; LinuxCNC lets it
            // (the tool backs up a little) unless the next corner needs its end again.
            next_backwards = !piece.runs_on_from(x);
            pieces[last].0.set_end(x);
            piece.set_start(x);
        } else {
            // A convex corner sharper than LinuxCNC's tolerance flushes the previous move
            // with its end checked: one that runs backwards is refused.
            if backwards && turn.atan2_libm(dot).abs() > CONVEX_CORNER_TOLERANCE {
                return Err((GOUGE, line));
            }
            pieces.push((
                Piece::Arc {
                    centre: corner,
                    a: previous.end(),
                    b: piece.start(),
                    ccw: side == Side::Right,
                    full: false,
                },
                line,
            ));
        }
        pieces.push((piece, line));
        last = pieces.len() - 1;
        direction = t1;
    }
    let end = pieces[last].0.end();
    pieces.push((Piece::Line { a: end, b: to }, lines.1));
    Ok(pieces
        .iter()
        .flat_map(|(piece, line)| piece.spans().into_iter().map(move |s| (s, *line)))
        .filter(|(s, _)| s.length() > EPS)
        .collect())
}

/// The intersection of two pieces' lines or circles nearest `near`.
fn intersection(p: &Piece, q: &Piece, near: Point) -> Option<Point> {
    let candidates = match (*p, *q) {
        (Piece::Line { a, b }, Piece::Line { a: c, b: d }) => {
            let (u, v) = (b - a, d - c);
            let den = cross(u, v);
            if den.abs() <= EPS {
                return None;
            }
            let t = cross(c - a, v) / den;
            vec![a + u * t]
        }
        (Piece::Line { a, b }, Piece::Arc { centre, a: s, .. })
        | (Piece::Arc { centre, a: s, .. }, Piece::Line { a, b }) => {
            line_circle(a, b, centre, s.distance(centre))
        }
        (
            Piece::Arc {
                centre: c1, a: s1, ..
            },
            Piece::Arc {
                centre: c2, a: s2, ..
            },
        ) => circle_circle(c1, s1.distance(c1), c2, s2.distance(c2)),
    };
    candidates.into_iter().min_by(|x, y| {
        x.distance(near)
            .partial_cmp(&y.distance(near))
            .unwrap_or(std::cmp::Ordering::Equal)
    })
}

fn line_circle(a: Point, b: Point, c: Point, r: f64) -> Vec<Point> {
    let d = b - a;
    let f = a - c;
    let (qa, qb, qc) = (
        d.x * d.x + d.y * d.y,
        2.0 * (f.x * d.x + f.y * d.y),
        f.x * f.x + f.y * f.y - r * r,
    );
    if qa <= EPS * EPS {
        return Vec::new();
    }
    let disc = qb * qb - 4.0 * qa * qc;
    if disc < 0.0 {
        return Vec::new();
    }
    let root = disc.sqrt();
    [(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)]
        .iter()
        .map(|&t| a + d * t)
        .collect()
}

fn circle_circle(c1: Point, r1: f64, c2: Point, r2: f64) -> Vec<Point> {
    let d = c1.distance(c2);
    if d <= EPS || d > r1 + r2 || d < (r1 - r2).abs() {
        return Vec::new();
    }
    let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h = (r1 * r1 - a * a).max(0.0).sqrt();
    let u = (c2 - c1) * (1.0 / d);
    let m = c1 + u * a;
    let n = u.rotated_quarter();
    vec![m + n * h, m - n * h]
}
