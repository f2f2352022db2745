//! Parsing of SVG attribute text: path data, transforms, number lists and lengths, into
//! subpaths in the element's own user space.

use cutroute_geometry::float::Libm;
use cutroute_geometry::{Point, Span, Transform};

use crate::curves::EllipticArc;

use super::{MAX_COORDINATE, MM_PER_PX};

/// One piece of a subpath in the element's own user space.
#[derive(Clone, Debug)]
pub(super) enum Segment {
    /// A straight piece (`L`, `H`, `V`, `Z`, polyline edges): geometry's span with bulge 0.
    Line(Span),
    /// A Bézier curve by its control points (3 for quadratic, 4 for cubic).
    Bezier(Vec<Point>),
    /// An elliptic arc `center + u·cos t + v·sin t`, `t` from `t0` to `t1`.
    Elliptic(EllipticArc),
}

/// A subpath: its segments, and whether `Z` (or the shape itself) closes it.
#[derive(Clone, Debug, Default)]
pub(super) struct Subpath {
    pub segments: Vec<Segment>,
    pub closed: bool,
}

pub(super) fn polyline(points: &[Point]) -> Subpath {
    Subpath {
        segments: points
            .windows(2)
            .map(|w| Segment::Line(Span::line(w[0], w[1])))
            .collect(),
        closed: false,
    }
}

/// Closes a subpath with a line back to its start when it does not end there.
pub(super) fn close(subpath: &mut Subpath, start: Option<Point>) {
    let Some(start) = start else { return };
    let end = subpath.segments.last().map(segment_end);
    if let Some(end) = end {
        if end != start {
            subpath.segments.push(Segment::Line(Span::line(end, start)));
        }
    }
    subpath.closed = true;
}

pub(super) fn segment_end(s: &Segment) -> Point {
    match s {
        Segment::Line(line) => line.end,
        Segment::Bezier(c) => c[c.len() - 1],
        Segment::Elliptic(arc) => arc.point_at(arc.t1),
    }
}

/// A rectangle, its corners rounded by quarter ellipses of radii `rx`, `ry` when positive.
pub(super) fn rounded_rect(x: f64, y: f64, w: f64, h: f64, rx: f64, ry: f64) -> Subpath {
    use std::f64::consts::{FRAC_PI_2, PI};
    if rx <= 0.0 || ry <= 0.0 {
        let corners = [
            Point::new(x, y),
            Point::new(x + w, y),
            Point::new(x + w, y + h),
            Point::new(x, y + h),
            Point::new(x, y),
        ];
        let mut s = polyline(&corners);
        s.closed = true;
        return s;
    }
    let corner = |cx: f64, cy: f64, t0: f64| {
        Segment::Elliptic(EllipticArc {
            center: Point::new(cx, cy),
            u: Point::new(rx, 0.0),
            v: Point::new(0.0, ry),
            t0,
            t1: t0 + FRAC_PI_2,
        })
    };
    let mut segments = Vec::new();
    let line = |a: Point, b: Point, segments: &mut Vec<Segment>| {
        if a != b {
            segments.push(Segment::Line(Span::line(a, b)));
        }
    };
    // Clockwise on screen (y down): top edge, top-right corner, right edge, …
    line(
        Point::new(x + rx, y),
        Point::new(x + w - rx, y),
        &mut segments,
    );
    segments.push(corner(x + w - rx, y + ry, -FRAC_PI_2));
    line(
        Point::new(x + w, y + ry),
        Point::new(x + w, y + h - ry),
        &mut segments,
    );
    segments.push(corner(x + w - rx, y + h - ry, 0.0));
    line(
        Point::new(x + w - rx, y + h),
        Point::new(x + rx, y + h),
        &mut segments,
    );
    segments.push(corner(x + rx, y + h - ry, FRAC_PI_2));
    line(
        Point::new(x, y + h - ry),
        Point::new(x, y + ry),
        &mut segments,
    );
    segments.push(corner(x + rx, y + ry, PI));
    Subpath {
        segments,
        closed: true,
    }
}

/// Splits `"12.5mm"` into `(12.5, "mm")`; `None` when no finite number leads.
pub(super) fn split_length(text: &str) -> Option<(f64, &str)> {
    let text = text.trim();
    let mut scanner = Scanner::new(text);
    let value = scanner.number().ok()?;
    Some((value, text[scanner.at..].trim()))
}

/// Millimetres per unit of an absolute CSS length unit ("" and "px" are pixels).
pub(super) fn absolute_unit_mm(unit: &str) -> Option<f64> {
    Some(match unit {
        "" | "px" => MM_PER_PX,
        "mm" => 1.0,
        "cm" => 10.0,
        "in" => 25.4,
        "pt" => 25.4 / 72.0,
        "pc" => 25.4 / 6.0,
        _ => return None,
    })
}

/// Numbers separated by white space and/or commas; `None` on anything else.
pub(super) fn parse_number_list(text: &str) -> Option<Vec<f64>> {
    let mut scanner = Scanner::new(text);
    let mut out = Vec::new();
    loop {
        scanner.separators();
        if scanner.done() {
            return Some(out);
        }
        out.push(scanner.number().ok()?);
    }
}

/// Parses a `transform` attribute into the map from the element's space to its parent's.
pub(super) fn parse_transform(text: &str) -> Result<Transform, String> {
    let mut scanner = Scanner::new(text);
    let mut total = Transform::IDENTITY;
    loop {
        scanner.separators();
        if scanner.done() {
            return Ok(total);
        }
        let start = scanner.at;
        while scanner.peek().is_some_and(|c| c.is_ascii_alphabetic()) {
            scanner.at += 1;
        }
        let name = &text[start..scanner.at];
        scanner.whitespace();
        if scanner.peek() != Some(b'(') {
            return Err(format!(
                "expected '(' after {name:?} at character {}",
                scanner.at
            ));
        }
        scanner.at += 1;
        let mut args = Vec::new();
        loop {
            scanner.separators();
            if scanner.peek() == Some(b')') {
                scanner.at += 1;
                break;
            }
            if scanner.done() || args.len() >= 6 {
                return Err(format!("unterminated {name}(…)"));
            }
            args.push(scanner.number().map_err(|(_, reason)| reason)?);
        }
        if args.iter().any(|v| v.abs() > MAX_COORDINATE) {
            return Err(format!("{name}(…) argument out of range (|value| > 1e9)"));
        }
        let step = match (name, args.as_slice()) {
            ("matrix", &[a, b, c, d, e, f]) => Transform {
                matrix: [[a, c], [b, d]],
                offset: Point::new(e, f),
            },
            ("translate", &[tx]) => Transform::translation(tx, 0.0),
            ("translate", &[tx, ty]) => Transform::translation(tx, ty),
            ("scale", &[s]) => Transform::scaling(s),
            ("scale", &[sx, sy]) => Transform {
                matrix: [[sx, 0.0], [0.0, sy]],
                offset: Point::ORIGIN,
            },
            // SVG's positive angles turn x towards y, which is what `rotation` does.
            ("rotate", &[a]) => Transform::rotation(a.to_radians()),
            ("rotate", &[a, cx, cy]) => Transform::translation(-cx, -cy)
                .then(&Transform::rotation(a.to_radians()))
                .then(&Transform::translation(cx, cy)),
            ("skewX", &[a]) => Transform {
                matrix: [[1.0, a.to_radians().tan_libm()], [0.0, 1.0]],
                offset: Point::ORIGIN,
            },
            ("skewY", &[a]) => Transform {
                matrix: [[1.0, 0.0], [a.to_radians().tan_libm(), 1.0]],
                offset: Point::ORIGIN,
            },
            _ => {
                return Err(format!(
                    "unknown transform {name}({} arguments)",
                    args.len()
                ))
            }
        };
        // "A B" maps a point by B first, then A.
        total = step.then(&total);
    }
}

/// A cursor over attribute text: numbers, separators, command letters.
pub(super) struct Scanner<'t> {
    text: &'t [u8],
    pub at: usize,
}

impl<'t> Scanner<'t> {
    pub fn new(text: &'t str) -> Self {
        Self {
            text: text.as_bytes(),
            at: 0,
        }
    }

    pub fn peek(&self) -> Option<u8> {
        self.text.get(self.at).copied()
    }

    pub fn done(&self) -> bool {
        self.at >= self.text.len()
    }

    pub fn whitespace(&mut self) {
        while self.peek().is_some_and(|c| c.is_ascii_whitespace()) {
            self.at += 1;
        }
    }

    /// White space with at most one comma.
    pub fn separators(&mut self) {
        self.whitespace();
        if self.peek() == Some(b',') {
            self.at += 1;
            self.whitespace();
        }
    }

    /// A finite number (`-1.5e3`, `.5`, `5.`); errors carry the offset.
    pub fn number(&mut self) -> Result<f64, (usize, String)> {
        let start = self.at;
        if matches!(self.peek(), Some(b'+' | b'-')) {
            self.at += 1;
        }
        let mut digits = 0;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.at += 1;
            digits += 1;
        }
        if self.peek() == Some(b'.') {
            self.at += 1;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.at += 1;
                digits += 1;
            }
        }
        if digits == 0 {
            self.at = start;
            return Err((start, "number expected".into()));
        }
        if matches!(self.peek(), Some(b'e' | b'E')) {
            let mark = self.at;
            self.at += 1;
            if matches!(self.peek(), Some(b'+' | b'-')) {
                self.at += 1;
            }
            let exp_start = self.at;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.at += 1;
            }
            if self.at == exp_start {
                // Not an exponent after all (`1em`): the number ends before the `e`.
                self.at = mark;
            }
        }
        // The slice is ASCII by construction.
        let slice = std::str::from_utf8(&self.text[start..self.at]).unwrap_or("");
        match slice.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err((start, format!("{slice:?} is not a finite number"))),
        }
    }

    /// An arc flag: `0` or `1`, which may stand without a separator before the next number.
    pub fn flag(&mut self) -> Result<bool, (usize, String)> {
        match self.peek() {
            Some(b'0') => {
                self.at += 1;
                Ok(false)
            }
            Some(b'1') => {
                self.at += 1;
                Ok(true)
            }
            _ => Err((self.at, "arc flag (0 or 1) expected".into())),
        }
    }
}

/// Parses path data into subpaths in user space; errors are `(offset, reason)`.
pub(super) fn parse_path(d: &str) -> Result<Vec<Subpath>, (usize, String)> {
    let mut s = Scanner::new(d);
    let mut subpaths: Vec<Subpath> = Vec::new();
    let mut current = Subpath::default();
    let mut start = Point::ORIGIN;
    let mut pen = Point::ORIGIN;
    // The control point to reflect for S/T, with the kind of curve that left it.
    let mut last_cubic: Option<Point> = None;
    let mut last_quad: Option<Point> = None;
    let mut command: Option<u8> = None;
    fn finish(current: &mut Subpath, subpaths: &mut Vec<Subpath>) {
        let done = std::mem::take(current);
        if !done.segments.is_empty() {
            subpaths.push(done);
        }
    }
    loop {
        s.separators();
        if s.done() {
            break;
        }
        let c = s.peek().unwrap_or(b' ');
        if c.is_ascii_alphabetic() && c != b'e' && c != b'E' {
            if command.is_none() && c != b'M' && c != b'm' {
                return Err((s.at, "path data must begin with a move-to (M or m)".into()));
            }
            s.at += 1;
            command = Some(c);
        } else if command.is_none() {
            return Err((s.at, "path data must begin with a move-to (M or m)".into()));
        } else if matches!(command, Some(b'Z' | b'z')) {
            return Err((s.at, "a number cannot follow Z".into()));
        }
        let cmd = command.unwrap_or(b'M');
        let relative = cmd.is_ascii_lowercase();
        let base = if relative { pen } else { Point::ORIGIN };
        let at = |s: &mut Scanner<'_>, base: Point| -> Result<Point, (usize, String)> {
            s.separators();
            let x = s.number()?;
            s.separators();
            let y = s.number()?;
            check_range(s.at, x)?;
            check_range(s.at, y)?;
            Ok(Point::new(base.x + x, base.y + y))
        };
        let mut next_cubic = None;
        let mut next_quad = None;
        match cmd.to_ascii_uppercase() {
            b'M' => {
                finish(&mut current, &mut subpaths);
                pen = at(&mut s, base)?;
                start = pen;
                // Further pairs after a move-to are line-tos.
                command = Some(if relative { b'l' } else { b'L' });
            }
            b'Z' => {
                if !current.segments.is_empty() {
                    close(&mut current, Some(start));
                }
                finish(&mut current, &mut subpaths);
                pen = start;
            }
            b'L' => {
                let p = at(&mut s, base)?;
                current.segments.push(Segment::Line(Span::line(pen, p)));
                pen = p;
            }
            b'H' | b'V' => {
                s.separators();
                let v = s.number()?;
                check_range(s.at, v)?;
                let p = if cmd.eq_ignore_ascii_case(&b'H') {
                    Point::new(if relative { pen.x + v } else { v }, pen.y)
                } else {
                    Point::new(pen.x, if relative { pen.y + v } else { v })
                };
                current.segments.push(Segment::Line(Span::line(pen, p)));
                pen = p;
            }
            b'C' | b'S' => {
                let c1 = if cmd.eq_ignore_ascii_case(&b'C') {
                    at(&mut s, base)?
                } else {
                    last_cubic.map_or(pen, |c| Point::new(2.0 * pen.x - c.x, 2.0 * pen.y - c.y))
                };
                let c2 = at(&mut s, base)?;
                let p = at(&mut s, base)?;
                current.segments.push(Segment::Bezier(vec![pen, c1, c2, p]));
                next_cubic = Some(c2);
                pen = p;
            }
            b'Q' | b'T' => {
                let c1 = if cmd.eq_ignore_ascii_case(&b'Q') {
                    at(&mut s, base)?
                } else {
                    last_quad.map_or(pen, |c| Point::new(2.0 * pen.x - c.x, 2.0 * pen.y - c.y))
                };
                let p = at(&mut s, base)?;
                current.segments.push(Segment::Bezier(vec![pen, c1, p]));
                next_quad = Some(c1);
                pen = p;
            }
            b'A' => {
                s.separators();
                let rx = s.number()?.abs();
                s.separators();
                let ry = s.number()?.abs();
                s.separators();
                let rotation = s.number()?;
                s.separators();
                let large = s.flag()?;
                s.separators();
                let sweep = s.flag()?;
                let p = at(&mut s, base)?;
                check_range(s.at, rx)?;
                check_range(s.at, ry)?;
                current
                    .segments
                    .push(endpoint_arc(pen, rx, ry, rotation, large, sweep, p));
                pen = p;
            }
            other => {
                return Err((
                    s.at - 1,
                    format!("unknown path command {:?}", other as char),
                ));
            }
        }
        last_cubic = next_cubic;
        last_quad = next_quad;
    }
    finish(&mut current, &mut subpaths);
    Ok(subpaths)
}

pub(super) fn check_range(at: usize, v: f64) -> Result<(), (usize, String)> {
    if v.abs() > MAX_COORDINATE {
        Err((at, format!("{v} is out of range (|value| > 1e9)")))
    } else {
        Ok(())
    }
}

/// SVG's endpoint arc as a centre-parameterised elliptic arc (SVG 1.1, appendix F.6.5–F.6.6:
/// radii too small for the chord are scaled up; a zero radius makes a straight line).
pub(super) fn endpoint_arc(
    from: Point,
    rx: f64,
    ry: f64,
    rotation_deg: f64,
    large: bool,
    sweep: bool,
    to: Point,
) -> Segment {
    if from == to {
        return Segment::Line(Span::line(from, to));
    }
    if rx == 0.0 || ry == 0.0 {
        return Segment::Line(Span::line(from, to));
    }
    let (sin, cos) = rotation_deg.to_radians().sin_cos_libm();
    let dx = (from.x - to.x) / 2.0;
    let dy = (from.y - to.y) / 2.0;
    let x1 = cos * dx + sin * dy;
    let y1 = -sin * dx + cos * dy;
    let (mut rx, mut ry) = (rx, ry);
    let lambda = (x1 * x1) / (rx * rx) + (y1 * y1) / (ry * ry);
    if lambda > 1.0 {
        let k = lambda.sqrt();
        rx *= k;
        ry *= k;
    }
    let numerator = (rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1).max(0.0);
    let denominator = rx * rx * y1 * y1 + ry * ry * x1 * x1;
    let mut k = if denominator > 0.0 {
        (numerator / denominator).sqrt()
    } else {
        0.0
    };
    if large == sweep {
        k = -k;
    }
    if !(rx.is_finite() && ry.is_finite() && k.is_finite()) {
        // Radii far below the chord (1e-300) overflow the scaling: the arc is the chord.
        return Segment::Line(Span::line(from, to));
    }
    let cx1 = k * rx * y1 / ry;
    let cy1 = -k * ry * x1 / rx;
    let center = Point::new(
        cos * cx1 - sin * cy1 + (from.x + to.x) / 2.0,
        sin * cx1 + cos * cy1 + (from.y + to.y) / 2.0,
    );
    let angle = |ux: f64, uy: f64| uy.atan2_libm(ux);
    let t0 = angle((x1 - cx1) / rx, (y1 - cy1) / ry);
    let t_end = angle((-x1 - cx1) / rx, (-y1 - cy1) / ry);
    let mut delta = t_end - t0;
    // sweep = 1 runs in the direction of increasing angle.
    if sweep && delta < 0.0 {
        delta += std::f64::consts::TAU;
    } else if !sweep && delta > 0.0 {
        delta -= std::f64::consts::TAU;
    }
    if !delta.is_finite() || !center.x.is_finite() || !center.y.is_finite() {
        return Segment::Line(Span::line(from, to));
    }
    Segment::Elliptic(EllipticArc {
        center,
        u: Point::new(rx * cos, rx * sin),
        v: Point::new(-ry * sin, ry * cos),
        t0,
        t1: t0 + delta,
    })
}
