//! Cutter compensation as LinuxCNC's interpreter computes it (`interp_convert.cc`): the
//! stretch from `G41`/`G42` to `G40` (or the program's end), gathered whole, becomes the tool
//! centre's path, and the tool stays at its end.
//!
//! - A straight start-up move (feed or rapid, from where the head stands to the programmed
//!   point `P`) ends at `P` offset by the radius perpendicular to the move itself, to the
//!   compensation side; one not longer than the radius is refused. An arc start-up move ends
//!   at `P` offset along the arc's radius, on an arc whose centre lies on that radius, as far
//!   from its end as from where the head stood.
//! - Every later programmed line or arc is offset by the radius (an arc's radius grows or
//!   shrinks; an arc that would vanish is refused); rapids as lines. A move without motion in
//!   the plane leaves the tool where it is.
//! - A turn within LinuxCNC's tolerance, to either side, is no corner: the next move runs on
//!   from where the last one ended. At a sharper corner where the tool is outside the turn
//!   (convex), an arc about the programmed corner joins the two offsets (a straight traverse
//!   before a rapid), also round a spike back; where it is inside (concave), or about a half
//!   turn back onto an arc the tool runs outside of (atop an "m" or an "h"), both offsets end
//!   at their intersection, and a corner the tool cannot reach without cutting into the
//!   previous move is refused, as LinuxCNC refuses it. A move shorter than its concave
//!   corner's retreat then runs backwards; LinuxCNC refuses that where its end is checked
//!   again (at a concave corner, a convex one before a straight move, or the end of
//!   compensation).

use cutroute_geometry::float::Libm;
use cutroute_geometry::{Point, Span};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Which side of the programmed path the controller keeps the tool on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Side {
    Left,
    Right,
}

/// Below this (mm, or radians of turn) two directions or points are the same.
const EPS: f64 = 1e-9;
/// A turn up to this (radians), convex or concave, is no corner to LinuxCNC: no corner arc,
/// no intersection, and the move before it is not checked again (its
/// `TOLERANCE_CONCAVE_CORNER`).
const CORNER_TOLERANCE: f64 = 0.05;
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

/// A programmed move of a compensated stretch (a move of more than half a turn comes as two
/// spans of one line).
#[derive(Clone, Copy, Debug)]
pub(super) struct Step {
    pub span: Span,
    pub line: usize,
    /// `G0`: offset as a straight feed is, but a convex corner before it is a straight
    /// traverse (there is no rapid arc).
    pub rapid: bool,
}

/// A span of the tool centre's path, with the index of the programmed step it runs for (a
/// corner before a step is that step's).
#[derive(Clone, Copy, Debug)]
pub(super) struct ToolSpan {
    pub span: Span,
    pub line: usize,
    pub rapid: bool,
    pub step: usize,
}

/// The tool centre's path of a compensated stretch, as far as LinuxCNC has run it when
/// compensation ends (`G40` or the program's end, on `end_line`): from `start` (where the head
/// stands) by the start-up move (its first `startup` steps; `origin` is the programmed point
/// the interpreter reckons from, which differs from `start` only right after a `G40`) and
/// along the later steps, each offset by the radius. The tool stays at the last offset end.
pub(super) fn tool_path(
    side: Side,
    radius: f64,
    (origin, start): (Point, Point),
    steps: &[Step],
    startup: usize,
    end_line: usize,
) -> Result<Vec<ToolSpan>, Refusal> {
    let normal = |t: Point| match side {
        Side::Left => t.rotated_quarter(),
        Side::Right => -t.rotated_quarter(),
    };
    let first = steps
        .first()
        .ok_or(("the start-up move has no length", end_line))?;
    let startup = startup.clamp(1, steps.len());
    let last_startup = steps[startup - 1];
    let entry = last_startup.span.end;
    let straight_startup = first.span.bulge == 0.0;
    let d0 = unit(entry - origin).ok_or(("the start-up move has no length", first.line))?;
    if origin.distance(entry) <= radius {
        return Err((
            "the start-up move is not longer than the tool radius",
            first.line,
        ));
    }
    let startup_piece = if straight_startup {
        Piece::Line {
            a: start,
            b: entry + normal(d0) * radius,
        }
    } else {
        startup_arc(side, radius, origin, start, &steps[..startup])?
    };
    let mut pieces: Vec<(Piece, usize, bool, usize)> =
        vec![(startup_piece, first.line, first.rapid, 0)];
    // The last piece that offsets a programmed move (a corner piece is never trimmed).
    let mut last = 0;
    // That piece runs backwards from its trimmed start.
    let mut next_backwards = false;
    let mut direction = if straight_startup {
        d0
    } else {
        tangent(&last_startup.span, 1.0)
    };
    for (index, step) in steps.iter().enumerate().skip(startup) {
        let (span, line) = (step.span, step.line);
        // A move without motion in the plane (a Z move, or a move to where it is) leaves the
        // tool where it stands.
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
        // LinuxCNC's β: the turn as the tool sees it, convex positive, from −90° to 270°.
        let angle = turn.atan2_libm(dot);
        let beta = match side {
            Side::Left => -angle,
            Side::Right => angle,
        };
        let beta = if beta < -FRAC_PI_2 { beta + TAU } else { beta };
        let tool_outside =
            |p: &Piece| matches!(*p, Piece::Arc { ccw, .. } if ccw == (side == Side::Right));
        // About a half turn back, LinuxCNC keeps the tool on its side of an arc the tool runs
        // outside of (atop an "m" or an "h"): there the corner is concave.
        let concave = !(-CORNER_TOLERANCE..=PI + CORNER_TOLERANCE).contains(&beta)
            || if span.bulge == 0.0 {
                beta > PI - CORNER_TOLERANCE && tool_outside(&pieces[last].0)
            } else {
                (beta - PI).abs() < CORNER_TOLERANCE && tool_outside(&piece)
            };
        // The straight start-up move's offset is the line through its end along the move (its
        // tool path runs from where the head stood, not along that line).
        let previous = if last == 0 && straight_startup {
            let end = pieces[0].0.end();
            Piece::Line {
                a: end - d0 * origin.distance(entry),
                b: end,
            }
        } else {
            pieces[last].0
        };
        if concave {
            let x = intersection(&previous, &piece, corner).ok_or((GOUGE, line))?;
            if !previous.reaches(x) || backwards {
                return Err((GOUGE, line));
            }
            // A move shorter than the corner's retreat now runs backwards; LinuxCNC lets it
            // (the tool backs up a little) unless the next corner needs its end again.
            next_backwards = !piece.runs_on_from(x);
            pieces[last].0.set_end(x);
            piece.set_start(x);
        } else if beta <= CORNER_TOLERANCE {
            // A turn within LinuxCNC's tolerance, to either side, is no corner: the move runs
            // on from where the previous one ends, which keeps its end unchecked.
            piece.set_start(previous.end());
        } else {
            // A convex corner before a straight move flushes the previous move with its end
            // checked: one that runs backwards is refused (before an arc it is not checked).
            if backwards && span.bulge == 0.0 {
                return Err((GOUGE, line));
            }
            // There is no rapid arc: before a rapid the corner is a straight traverse.
            let corner_piece = if step.rapid {
                Piece::Line {
                    a: previous.end(),
                    b: piece.start(),
                }
            } else {
                Piece::Arc {
                    centre: corner,
                    a: previous.end(),
                    b: piece.start(),
                    ccw: side == Side::Right,
                    full: false,
                }
            };
            pieces.push((corner_piece, line, step.rapid, index));
        }
        pieces.push((piece, line, step.rapid, index));
        last = pieces.len() - 1;
        direction = t1;
    }
    // Ending compensation flushes the last move with its end checked, as a corner would.
    if next_backwards {
        return Err((GOUGE, end_line));
    }
    Ok(pieces
        .iter()
        .flat_map(|&(piece, line, rapid, step)| {
            piece.spans().into_iter().map(move |span| ToolSpan {
                span,
                line,
                rapid,
                step,
            })
        })
        .filter(|s| s.span.length() > EPS)
        .collect())
}

/// The tool's arc of an arc start-up move (LinuxCNC's `convert_arc_comp1`): it ends at the
/// programmed end offset along the arc's radius, and its centre lies on that radius, as far
/// from the end as from where the head stands.
fn startup_arc(
    side: Side,
    radius: f64,
    origin: Point,
    start: Point,
    spans: &[Step],
) -> Result<Piece, Refusal> {
    let (first, line) = (spans[0].span, spans[0].line);
    let end = spans[spans.len() - 1].span.end;
    // The interpreter reckons the arc from the programmed point: from anywhere else its arc
    // would not be circular.
    if origin.distance(start) > 1e-9 {
        return Err((
            "an arc start-up move where the tool does not stand at the programmed point",
            line,
        ));
    }
    let centre = first.centre().ok_or(("an arc without a centre", line))?;
    let ccw = first.bulge > 0.0;
    let inside = ccw == (side == Side::Left);
    if inside && origin.distance(centre) <= radius {
        return Err(("the tool radius is not less than an arc's radius", line));
    }
    let out = unit(end - centre).ok_or(("an arc without a centre", line))?;
    let tool_end = if inside {
        end - out * radius
    } else {
        end + out * radius
    };
    let (along, back) = (unit(centre - tool_end), unit(start - tool_end));
    let cos = match (along, back) {
        (Some(u), Some(v)) => u.x * v.x + u.y * v.y,
        _ => 0.0,
    };
    // LinuxCNC's TOLERANCE_EQUAL: a radius through the end perpendicular to the chord has no
    // centre equidistant from both ends.
    if cos.abs() < 1e-4 {
        return Err(("the tool radius is not less than an arc's radius", line));
    }
    let along = along.unwrap_or(Point::new(1.0, 0.0));
    let tool_centre = tool_end + along * (0.5 * start.distance(tool_end) / cos);
    Ok(Piece::Arc {
        centre: tool_centre,
        a: start,
        b: tool_end,
        ccw,
        full: false,
    })
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
