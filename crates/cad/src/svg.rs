//! SVG import: nests drawn as SVG (what DeepNest and SVGnest write, and cutroute's own export)
//! → a [`Nest`](cutroute_geometry::Nest) of closed parts plus a report.
//!
//! What becomes geometry: `<path>` (every command of SVG 1.1, `M L H V C S Q T A Z`, absolute
//! and relative), `<polyline>`, `<polygon>`, `<rect>` (rounded corners too), `<circle>`,
//! `<ellipse>` and `<line>`, inside any depth of `<g>` (and nested `<svg>`) with `transform`
//! (`matrix`, `translate`, `scale`, `rotate`, `skewX`, `skewY`). Bézier curves and elliptic arcs
//! are approximated by circular arcs within [`SvgOptions::approximation_tolerance`], by the same
//! code as DXF splines and ellipses; circular arcs under a similarity map stay exact arcs.
//! Non-rendered content (`<defs>`, `<symbol>`, `<clipPath>`, `<mask>`, `<marker>`, `<pattern>`,
//! text, images, `display="none"`) is skipped, and so is the route layer of cutroute's own
//! export (`<g class="route">`). `<use>` is not expanded (a warning says so).
//!
//! Each closed subpath (ended by `Z`, or whose ends meet within
//! [`SvgOptions::join_tolerance`]) is a contour; open subpaths and lines are joined end to end
//! like loose DXF entities. Contours are grouped into parts by containment, exactly as for DXF
//! (a contour inside a part is its hole, a contour inside a hole starts a new part). An element
//! whose `class` lists `sheet` or `bin` (cutroute's export; the bin of SVGnest and DeepNest
//! when so marked) is the sheet, not a part.
//!
//! **Coordinates.** SVG's y axis points down, the model's up: a user-space point `(x, y)` of the
//! root `<svg>` becomes `(s·x, −s·y)` mm, where `s` is the size of one user unit. The origin
//! stays where it is (the `viewBox` does not move it), so cutroute's export, which draws the
//! model inside `scale(1,-1)`, reads back at its own coordinates. `s` comes from
//! [`SvgOptions::user_unit_mm`] when set; otherwise from the root's `width`/`height` in absolute
//! units (`mm`, `cm`, `in`, `pt`, `pc`, `px` = 1/96 in) divided by its `viewBox` (or, without a
//! `viewBox`, from the unit of `width`); a drawing with neither is taken to be in millimetres,
//! since cutting nests are drawn in millimetres (CSS pixels would shrink them 3.78 times).
//!
//! ```
//! use cutroute_cad::svg::{read_svg, SvgOptions};
//!
//! // A 40 × 20 plate with a Ø10 hole, drawn in millimetres (y down).
//! let drawing = r#"<svg xmlns="http://www.w3.org/2000/svg" width="50mm" height="30mm"
//!     viewBox="0 0 50 30">
//!   <g transform="translate(5 5)">
//!     <path d="M0 0 H40 V20 H0 Z"/>
//!     <circle cx="20" cy="10" r="5"/>
//!   </g>
//! </svg>"#;
//! let import = read_svg(drawing.as_bytes(), &SvgOptions::default()).unwrap();
//! assert_eq!(import.nest.parts.len(), 1);
//! let part = &import.nest.parts[0];
//! assert_eq!(part.contours.len(), 2); // the outline, then the hole
//! let area = part.contours[0].area() - part.contours[1].area();
//! assert!((area - (800.0 - 25.0 * std::f64::consts::PI)).abs() < 1e-6);
//! // y is flipped: the plate lies below the x axis.
//! assert!(part.contours[0].bounding_box().max.y <= -5.0 + 1e-9);
//! ```

use cutroute_geometry::float::Libm;
use cutroute_geometry::{Point, Span, Transform};
use roxmltree::{Document, Node};

use crate::assemble::{
    assemble, finish_import, is_bounded, AssembleLimits, DrawingImport, EntityRef, Piece,
};
use crate::curves::{approximate, elliptic_spans, ApproxFailure, EllipticArc, Nurbs};

/// Deepest nesting of elements followed; deeper content is refused (hostile input).
const MAX_DEPTH: usize = 256;
/// Largest absolute coordinate or length accepted, in user units.
const MAX_COORDINATE: f64 = 1e9;
/// The SVG namespace; elements of other namespaces (editor metadata) are ignored.
const SVG_NS: &str = "http://www.w3.org/2000/svg";
/// Millimetres per CSS pixel.
const MM_PER_PX: f64 = 25.4 / 96.0;

/// Settings of an SVG import.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgOptions {
    /// Largest distance (mm) allowed between a Bézier curve or elliptic arc and the arcs that
    /// replace it.
    pub approximation_tolerance: f64,
    /// Largest gap (mm) between two end points that are still joined into one contour.
    pub join_tolerance: f64,
    /// Most spans the import may produce before it gives up with [`SvgError::TooComplex`].
    pub max_spans: usize,
    /// Millimetres per user unit of the root `<svg>`, overriding what its `width`, `height`
    /// and `viewBox` say (`None`: derive it, see the module docs).
    pub user_unit_mm: Option<f64>,
}

impl Default for SvgOptions {
    fn default() -> Self {
        Self {
            approximation_tolerance: 0.01,
            join_tolerance: 0.05,
            max_spans: 500_000,
            user_unit_mm: None,
        }
    }
}

/// Something the reader skipped or changed without failing, with where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgWarning {
    /// 1-based line of the element concerned; 0 when the warning concerns the whole drawing.
    pub line: u32,
    /// 1-based column of the element concerned.
    pub column: u32,
    /// What happened, for people.
    pub message: String,
}

impl std::fmt::Display for SvgWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: {}", self.line, self.column, self.message)
        } else {
            f.write_str(&self.message)
        }
    }
}

/// The result of an SVG import: the closed parts and the sheet when an element is marked as
/// one, the open chains of subpaths, and the warnings.
pub type SvgImport = DrawingImport<SvgWarning>;

/// Why an SVG file could not be imported: the CAD readers' shared [`CadError`](crate::CadError),
/// whose shared and `SVG:` variants this reader returns. `line`/`column` are 1-based positions
/// in the file.
pub type SvgError = crate::CadError;

/// Reads an SVG drawing into closed parts (and the sheet, when one is marked), reporting open
/// chains and skipped elements.
///
/// Fails with a located [`SvgError`] on malformed input; never panics. Succeeds as long as at
/// least one closed contour results.
pub fn read_svg(bytes: &[u8], options: &SvgOptions) -> Result<SvgImport, SvgError> {
    check_options(options)?;
    let text = crate::error::xml_text(bytes)?;
    let parsing = roxmltree::ParsingOptions {
        // Illustrator and Inkscape write a DOCTYPE; roxmltree bounds entity expansion.
        allow_dtd: true,
        ..Default::default()
    };
    let doc = crate::error::xml_document(text, parsing)?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(SvgError::NotSvg {
            found: root.tag_name().name().to_owned(),
        });
    }
    let mut reader = Reader {
        doc: &doc,
        options,
        budget: options.max_spans,
        parts: Vec::new(),
        sheet: Vec::new(),
        warnings: Vec::new(),
    };
    let unit = match options.user_unit_mm {
        Some(mm) => mm,
        None => reader.root_unit(root)?,
    };
    // User space of the root → model: scale to millimetres and turn y up.
    let to_model = Transform {
        matrix: [[unit, 0.0], [0.0, -unit]],
        offset: Point::ORIGIN,
    };
    reader.walk(root, &to_model, "svg", false, 0)?;

    let limits = AssembleLimits {
        join_tolerance: options.join_tolerance,
        flatten_tolerance: options.approximation_tolerance,
    };
    let Reader {
        parts: part_pieces,
        sheet: sheet_pieces,
        mut warnings,
        ..
    } = reader;
    let sheet = if sheet_pieces.is_empty() {
        None
    } else {
        let assembled = assemble(sheet_pieces, &limits);
        let mut sheets = assembled.parts.into_iter();
        let sheet = sheets.next();
        if sheets.next().is_some() {
            warnings.push(SvgWarning {
                line: 0,
                column: 0,
                message:
                    "more than one sheet outline; the first is the sheet, the others are ignored"
                        .into(),
            });
        }
        sheet
    };
    let dropped = |d: crate::assemble::Dropped| SvgWarning {
        line: u32::try_from(d.line).unwrap_or(u32::MAX),
        column: 0,
        message: d.message,
    };
    let nothing_drawn = |_: &[SvgWarning]| "nothing drawn".to_owned();
    finish_import(
        part_pieces,
        sheet,
        &limits,
        warnings,
        dropped,
        nothing_drawn,
    )
}

fn check_options(options: &SvgOptions) -> Result<(), SvgError> {
    crate::assemble::check_curve_options(
        options.approximation_tolerance,
        options.join_tolerance,
        options.max_spans,
    )
    .map_err(SvgError::InvalidOptions)?;
    if let Some(mm) = options.user_unit_mm {
        if !(mm.is_finite() && mm > 0.0) || mm > 1e6 {
            return Err(SvgError::InvalidOptions(format!(
                "user unit {mm} mm must be positive and at most 1e6"
            )));
        }
    }
    Ok(())
}

/// One piece of a subpath in the element's own user space.
#[derive(Clone, Debug)]
enum Segment {
    /// A straight piece (`L`, `H`, `V`, `Z`, polyline edges): geometry's span with bulge 0.
    Line(Span),
    /// A Bézier curve by its control points (3 for quadratic, 4 for cubic).
    Bezier(Vec<Point>),
    /// An elliptic arc `center + u·cos t + v·sin t`, `t` from `t0` to `t1`.
    Elliptic(EllipticArc),
}

/// A subpath: its segments, and whether `Z` (or the shape itself) closes it.
#[derive(Clone, Debug, Default)]
struct Subpath {
    segments: Vec<Segment>,
    closed: bool,
}

struct Reader<'a, 'input, 'o> {
    doc: &'a Document<'input>,
    options: &'o SvgOptions,
    budget: usize,
    parts: Vec<Piece>,
    sheet: Vec<Piece>,
    warnings: Vec<SvgWarning>,
}

impl<'a, 'input> Reader<'a, 'input, '_> {
    fn position(&self, node: Node<'_, '_>) -> (u32, u32) {
        let p = self.doc.text_pos_at(node.range().start);
        (p.row, p.col)
    }

    fn warn(&mut self, node: Node<'_, '_>, message: impl Into<String>) {
        let (line, column) = self.position(node);
        self.warnings.push(SvgWarning {
            line,
            column,
            message: message.into(),
        });
    }

    fn bad_attribute(&self, node: Node<'_, '_>, attribute: &str, reason: &str) -> SvgError {
        let (line, column) = self.position(node);
        let value: String = node
            .attribute(attribute)
            .unwrap_or("")
            .chars()
            .take(80)
            .collect();
        SvgError::BadAttribute {
            element: node.tag_name().name().to_owned(),
            attribute: attribute.to_owned(),
            value,
            reason: reason.to_owned(),
            line,
            column,
        }
    }

    /// Millimetres per user unit of the root element.
    fn root_unit(&self, root: Node<'_, '_>) -> Result<f64, SvgError> {
        let view_box = match root.attribute("viewBox") {
            None => None,
            Some(text) => {
                let numbers = parse_number_list(text)
                    .ok_or_else(|| self.bad_attribute(root, "viewBox", "not a list of numbers"))?;
                match numbers[..] {
                    [_, _, w, h] if w > 0.0 && h > 0.0 => Some((w, h)),
                    [_, _, _, _] => None, // SVG: a non-positive size disables the viewBox.
                    _ => return Err(self.bad_attribute(root, "viewBox", "expected four numbers")),
                }
            }
        };
        let mut scales = Vec::new();
        for (attribute, index) in [("width", 0), ("height", 1)] {
            let Some(text) = root.attribute(attribute) else {
                continue;
            };
            let Some((value, unit)) = split_length(text) else {
                return Err(self.bad_attribute(root, attribute, "not a length"));
            };
            let Some(mm_per_unit) = absolute_unit_mm(unit) else {
                continue; // % or em: relative to nothing we know.
            };
            let unit_given = !unit.is_empty();
            match view_box {
                Some(vb) if value > 0.0 => {
                    let size = if index == 0 { vb.0 } else { vb.1 };
                    if unit_given {
                        scales.push(value * mm_per_unit / size);
                    }
                }
                None if unit_given => scales.push(mm_per_unit),
                _ => {}
            }
        }
        // preserveAspectRatio's default ("meet") scales uniformly by the smaller factor.
        let unit = scales.into_iter().fold(f64::INFINITY, f64::min);
        Ok(if unit.is_finite() && unit > 0.0 {
            unit
        } else {
            1.0
        })
    }

    fn walk(
        &mut self,
        node: Node<'a, 'input>,
        parent: &Transform,
        layer: &str,
        in_sheet: bool,
        depth: usize,
    ) -> Result<(), SvgError> {
        if depth > MAX_DEPTH {
            let (line, column) = self.position(node);
            return Err(SvgError::TooDeep {
                limit: MAX_DEPTH,
                line,
                column,
            });
        }
        if !node.is_element() {
            return Ok(());
        }
        let namespace = node.tag_name().namespace();
        if namespace.is_some_and(|ns| ns != SVG_NS) {
            return Ok(());
        }
        if node.attribute("display") == Some("none") {
            return Ok(());
        }
        let name = node.tag_name().name();
        let classes: Vec<&str> = node
            .attribute("class")
            .map(|c| c.split_ascii_whitespace().collect())
            .unwrap_or_default();
        let in_sheet = in_sheet || classes.iter().any(|&c| c == "sheet" || c == "bin");
        let transform = match node.attribute("transform") {
            None => *parent,
            Some(text) => {
                let local = parse_transform(text)
                    .map_err(|reason| self.bad_attribute(node, "transform", &reason))?;
                local.then(parent)
            }
        };
        if !is_bounded(&transform) {
            return Err(self.bad_attribute(
                node,
                "transform",
                "the accumulated transform scales beyond 1e6 or moves beyond 1e12",
            ));
        }
        match name {
            "svg" | "g" | "a" | "switch" => {
                if name == "g" && classes.contains(&"route") {
                    return Ok(()); // cutroute's export draws the route here: not geometry.
                }
                let layer = node
                    .attribute("id")
                    .or_else(|| {
                        node.attribute(("http://www.inkscape.org/namespaces/inkscape", "label"))
                    })
                    .unwrap_or(layer)
                    .to_owned();
                // A nested <svg> establishes its own viewport at (x, y).
                let transform = if name == "svg" && depth > 0 {
                    let x = self.length_or_zero(node, "x")?;
                    let y = self.length_or_zero(node, "y")?;
                    Transform::translation(x, y).then(&transform)
                } else {
                    transform
                };
                for child in node.children() {
                    self.walk(child, &transform, &layer, in_sheet, depth + 1)?;
                }
                Ok(())
            }
            "path" | "polyline" | "polygon" | "rect" | "circle" | "ellipse" | "line" => {
                let subpaths = self.shape(node)?;
                let (line, _) = self.position(node);
                let source = EntityRef {
                    entity: name.to_owned(),
                    line: line as usize,
                    layer: layer.to_owned(),
                };
                for subpath in subpaths {
                    self.push(subpath, &transform, source.clone(), in_sheet)?;
                }
                Ok(())
            }
            "use" => {
                self.warn(
                    node,
                    "<use> is not expanded; the referenced shape is drawn once",
                );
                Ok(())
            }
            // Not rendered, or not geometry: defs, symbol, clipPath, mask, marker, pattern,
            // style, title, desc, metadata, text, image, foreignObject, gradients, filters.
            _ => Ok(()),
        }
    }

    fn length_or_zero(&self, node: Node<'_, '_>, attribute: &str) -> Result<f64, SvgError> {
        match node.attribute(attribute) {
            None => Ok(0.0),
            Some(_) => self.length(node, attribute),
        }
    }

    /// A coordinate or length attribute in user units (absolute units at 96 px per inch).
    fn length(&self, node: Node<'_, '_>, attribute: &str) -> Result<f64, SvgError> {
        let text = node.attribute(attribute).unwrap_or("");
        let (value, unit) = split_length(text)
            .ok_or_else(|| self.bad_attribute(node, attribute, "not a length"))?;
        let per_unit = if unit.is_empty() {
            1.0
        } else {
            absolute_unit_mm(unit).ok_or_else(|| {
                self.bad_attribute(node, attribute, "relative units are not supported")
            })? / MM_PER_PX
        };
        let value = value * per_unit;
        if value.abs() > MAX_COORDINATE {
            return Err(self.bad_attribute(node, attribute, "out of range (|value| > 1e9)"));
        }
        Ok(value)
    }

    /// The element's geometry as subpaths in its own user space.
    fn shape(&mut self, node: Node<'_, '_>) -> Result<Vec<Subpath>, SvgError> {
        let name = node.tag_name().name();
        match name {
            "path" => {
                let d = node.attribute("d").unwrap_or("");
                parse_path(d).map_err(|(offset, reason)| {
                    let (line, column) = self.position(node);
                    SvgError::BadPathData {
                        offset,
                        reason,
                        line,
                        column,
                    }
                })
            }
            "polyline" | "polygon" => {
                let text = node.attribute("points").unwrap_or("");
                let numbers = parse_number_list(text)
                    .ok_or_else(|| self.bad_attribute(node, "points", "not a list of numbers"))?;
                if numbers.iter().any(|v| v.abs() > MAX_COORDINATE) {
                    return Err(self.bad_attribute(node, "points", "out of range (|value| > 1e9)"));
                }
                if numbers.len() % 2 == 1 {
                    self.warn(node, "odd number of coordinates; the last one is ignored");
                }
                let points: Vec<Point> = numbers
                    .chunks_exact(2)
                    .map(|c| Point::new(c[0], c[1]))
                    .collect();
                let mut subpath = polyline(&points);
                subpath.closed = name == "polygon";
                if subpath.closed {
                    close(&mut subpath, points.first().copied());
                }
                Ok(vec![subpath])
            }
            "line" => {
                let a = Point::new(
                    self.length_or_zero(node, "x1")?,
                    self.length_or_zero(node, "y1")?,
                );
                let b = Point::new(
                    self.length_or_zero(node, "x2")?,
                    self.length_or_zero(node, "y2")?,
                );
                Ok(vec![polyline(&[a, b])])
            }
            "circle" | "ellipse" => {
                let cx = self.length_or_zero(node, "cx")?;
                let cy = self.length_or_zero(node, "cy")?;
                let (rx, ry) = if name == "circle" {
                    let r = self.length_or_zero(node, "r")?;
                    (r, r)
                } else {
                    (
                        self.length_or_zero(node, "rx")?,
                        self.length_or_zero(node, "ry")?,
                    )
                };
                if rx <= 0.0 || ry <= 0.0 {
                    self.warn(
                        node,
                        format!("<{name}> with a radius of zero or less is not drawn"),
                    );
                    return Ok(Vec::new());
                }
                Ok(vec![Subpath {
                    segments: vec![Segment::Elliptic(EllipticArc {
                        center: Point::new(cx, cy),
                        u: Point::new(rx, 0.0),
                        v: Point::new(0.0, ry),
                        t0: 0.0,
                        t1: std::f64::consts::TAU,
                    })],
                    closed: true,
                }])
            }
            "rect" => {
                let x = self.length_or_zero(node, "x")?;
                let y = self.length_or_zero(node, "y")?;
                let w = self.length_or_zero(node, "width")?;
                let h = self.length_or_zero(node, "height")?;
                if w <= 0.0 || h <= 0.0 {
                    self.warn(node, "<rect> with a size of zero or less is not drawn");
                    return Ok(Vec::new());
                }
                // SVG: a missing rx takes ry's value and vice versa; both are clamped to half
                // the side.
                let rx_given = node
                    .attribute("rx")
                    .map(|_| self.length(node, "rx"))
                    .transpose()?;
                let ry_given = node
                    .attribute("ry")
                    .map(|_| self.length(node, "ry"))
                    .transpose()?;
                let rx = rx_given.or(ry_given).unwrap_or(0.0).max(0.0).min(w / 2.0);
                let ry = ry_given.or(rx_given).unwrap_or(0.0).max(0.0).min(h / 2.0);
                Ok(vec![rounded_rect(x, y, w, h, rx, ry)])
            }
            _ => Ok(Vec::new()),
        }
    }

    /// Maps a subpath to the model and stores it as a piece.
    fn push(
        &mut self,
        subpath: Subpath,
        to_model: &Transform,
        source: EntityRef,
        in_sheet: bool,
    ) -> Result<(), SvgError> {
        let tolerance = self.options.approximation_tolerance;
        let too_complex = SvgError::TooComplex {
            limit: self.options.max_spans,
        };
        let mut spans: Vec<Span> = Vec::new();
        for segment in subpath.segments {
            match segment {
                Segment::Line(line) => {
                    let (a, b) = (to_model.apply(line.start), to_model.apply(line.end));
                    if a != b {
                        self.budget = self.budget.checked_sub(1).ok_or(too_complex.clone())?;
                        spans.push(Span::line(a, b));
                    }
                }
                Segment::Bezier(control) => {
                    let world: Vec<Point> = control.iter().map(|&p| to_model.apply(p)).collect();
                    // A Bézier curve is the NURBS of its control points on a clamped knot
                    // vector, so the spline approximation applies as it is.
                    let degree = world.len() - 1;
                    let knots: Vec<f64> = std::iter::repeat_n(0.0, degree + 1)
                        .chain(std::iter::repeat_n(1.0, degree + 1))
                        .collect();
                    let Ok(curve) = Nurbs::new(degree, knots, &world, &[]) else {
                        continue;
                    };
                    if world.iter().all(|&p| p == world[0]) {
                        continue;
                    }
                    let pieces = approximate(
                        &|t| curve.point_at(t),
                        0.0,
                        1.0,
                        &[0.5],
                        tolerance,
                        &mut self.budget,
                    )
                    .map_err(|ApproxFailure::BudgetExceeded| too_complex.clone())?;
                    spans.extend(pieces);
                }
                Segment::Elliptic(arc) => {
                    let world = EllipticArc {
                        center: to_model.apply(arc.center),
                        u: to_model.apply_vector(arc.u),
                        v: to_model.apply_vector(arc.v),
                        t0: arc.t0,
                        t1: arc.t1,
                    };
                    let before = self.budget;
                    let pieces = elliptic_spans(&world, tolerance, &mut self.budget)
                        .map_err(|ApproxFailure::BudgetExceeded| too_complex.clone())?;
                    if self.budget == before {
                        // Exact circular spans: the approximation did not count them.
                        self.budget = self
                            .budget
                            .checked_sub(pieces.len())
                            .ok_or(too_complex.clone())?;
                    }
                    spans.extend(pieces);
                }
            }
        }
        if spans.is_empty() {
            return Ok(());
        }
        let piece = Piece {
            spans,
            closed: subpath.closed,
            source,
        };
        if in_sheet {
            self.sheet.push(piece);
        } else {
            self.parts.push(piece);
        }
        Ok(())
    }
}

fn polyline(points: &[Point]) -> Subpath {
    Subpath {
        segments: points
            .windows(2)
            .map(|w| Segment::Line(Span::line(w[0], w[1])))
            .collect(),
        closed: false,
    }
}

/// Closes a subpath with a line back to its start when it does not end there.
fn close(subpath: &mut Subpath, start: Option<Point>) {
    let Some(start) = start else { return };
    let end = subpath.segments.last().map(segment_end);
    if let Some(end) = end {
        if end != start {
            subpath.segments.push(Segment::Line(Span::line(end, start)));
        }
    }
    subpath.closed = true;
}

fn segment_end(s: &Segment) -> Point {
    match s {
        Segment::Line(line) => line.end,
        Segment::Bezier(c) => c[c.len() - 1],
        Segment::Elliptic(arc) => arc.point_at(arc.t1),
    }
}

/// A rectangle, its corners rounded by quarter ellipses of radii `rx`, `ry` when positive.
fn rounded_rect(x: f64, y: f64, w: f64, h: f64, rx: f64, ry: f64) -> Subpath {
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
fn split_length(text: &str) -> Option<(f64, &str)> {
    let text = text.trim();
    let mut scanner = Scanner::new(text);
    let value = scanner.number().ok()?;
    Some((value, text[scanner.at..].trim()))
}

/// Millimetres per unit of an absolute CSS length unit ("" and "px" are pixels).
fn absolute_unit_mm(unit: &str) -> Option<f64> {
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
fn parse_number_list(text: &str) -> Option<Vec<f64>> {
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
fn parse_transform(text: &str) -> Result<Transform, String> {
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
struct Scanner<'t> {
    text: &'t [u8],
    at: usize,
}

impl<'t> Scanner<'t> {
    fn new(text: &'t str) -> Self {
        Self {
            text: text.as_bytes(),
            at: 0,
        }
    }

    fn peek(&self) -> Option<u8> {
        self.text.get(self.at).copied()
    }

    fn done(&self) -> bool {
        self.at >= self.text.len()
    }

    fn whitespace(&mut self) {
        while self.peek().is_some_and(|c| c.is_ascii_whitespace()) {
            self.at += 1;
        }
    }

    /// White space with at most one comma.
    fn separators(&mut self) {
        self.whitespace();
        if self.peek() == Some(b',') {
            self.at += 1;
            self.whitespace();
        }
    }

    /// A finite number (`-1.5e3`, `.5`, `5.`); errors carry the offset.
    fn number(&mut self) -> Result<f64, (usize, String)> {
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
    fn flag(&mut self) -> Result<bool, (usize, String)> {
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
fn parse_path(d: &str) -> Result<Vec<Subpath>, (usize, String)> {
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

fn check_range(at: usize, v: f64) -> Result<(), (usize, String)> {
    if v.abs() > MAX_COORDINATE {
        Err((at, format!("{v} is out of range (|value| > 1e9)")))
    } else {
        Ok(())
    }
}

/// SVG's endpoint arc as a centre-parameterised elliptic arc (SVG 1.1, appendix F.6.5–F.6.6:
/// radii too small for the chord are scaled up; a zero radius makes a straight line).
fn endpoint_arc(
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

#[cfg(test)]
mod tests {
    use super::*;

    fn read(svg: &str) -> SvgImport {
        read_svg(svg.as_bytes(), &SvgOptions::default()).unwrap()
    }

    fn wrap(body: &str) -> String {
        format!(r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 500 500">{body}</svg>"#)
    }

    #[test]
    fn numbers_without_separators_parse() {
        let subpaths = parse_path("M.5.5l10-1e1,0,10.5Z").unwrap();
        assert_eq!(subpaths.len(), 1);
        assert!(subpaths[0].closed);
        assert_eq!(subpaths[0].segments.len(), 3);
        let arcs = parse_path("M0 0a5 5 0 1110 0z").unwrap();
        assert!(matches!(arcs[0].segments[0], Segment::Elliptic(_)));
    }

    #[test]
    fn transforms_compose_right_to_left() {
        let t = parse_transform("translate(10,0) scale(2)").unwrap();
        assert_eq!(t.apply(Point::new(1.0, 1.0)), Point::new(12.0, 2.0));
        let r = parse_transform("rotate(90 1 1)").unwrap();
        let p = r.apply(Point::new(2.0, 1.0));
        assert!((p.x - 1.0).abs() < 1e-12 && (p.y - 2.0).abs() < 1e-12);
        let m = parse_transform("matrix(1 0 0 1 3 4)").unwrap();
        assert_eq!(m.apply(Point::ORIGIN), Point::new(3.0, 4.0));
        assert!(parse_transform("shear(1)").is_err());
        assert!(parse_transform("scale(1").is_err());
    }

    #[test]
    fn every_shape_gives_its_area() {
        use std::f64::consts::PI;
        let cases = [
            (r#"<rect x="0" y="0" width="30" height="20"/>"#, 600.0),
            (
                r#"<rect x="0" y="0" width="30" height="20" rx="5"/>"#,
                600.0 - (4.0 - PI) * 25.0,
            ),
            (r#"<circle cx="50" cy="50" r="10"/>"#, PI * 100.0),
            (r#"<ellipse cx="50" cy="50" rx="20" ry="10"/>"#, PI * 200.0),
            (r#"<polygon points="0,0 10,0 10,10"/>"#, 50.0),
            (r#"<polyline points="0,0 10,0 10,10 0,0"/>"#, 50.0),
            (r#"<path d="M0 0 h10 v10 h-10 z"/>"#, 100.0),
            // A quarter-disc pie by an arc command.
            (r#"<path d="M0 0 L10 0 A10 10 0 0 1 0 10 Z"/>"#, PI * 25.0),
            // A cubic that closes on a line: area of the parabola-like lens, ∫ = 3/10·w·h·…
            (r#"<path d="M0 0 Q5 10 10 0 Z"/>"#, 2.0 / 3.0 * 10.0 * 5.0),
            (
                r#"<path d="M0 0 L10 0 L10 10 L0 10 Z" transform="scale(2 3)"/>"#,
                600.0,
            ),
            (
                r#"<rect width="10" height="10" transform="skewX(45)"/>"#,
                100.0,
            ),
        ];
        for (body, area) in cases {
            let import = read(&wrap(body));
            let contour = &import.nest.parts[0].contours[0];
            assert!(
                (contour.area() - area).abs() < 0.05,
                "{body}: area {} expected {area}",
                contour.area()
            );
            assert!(
                contour.is_clockwise(),
                "{body}: outer contours run clockwise"
            );
        }
    }

    #[test]
    fn lines_join_into_a_contour() {
        let import = read(&wrap(
            r#"<line x1="0" y1="0" x2="10" y2="0"/><line x1="10" y1="0" x2="0" y2="10"/>
               <line x1="0" y1="10" x2="0" y2="0"/>"#,
        ));
        assert_eq!(import.nest.parts.len(), 1);
        assert!((import.nest.parts[0].contours[0].area() - 50.0).abs() < 1e-9);
    }

    #[test]
    fn bad_input_is_located() {
        let bad = [
            (wrap(r#"<path d="M0 0 L10"/>"#), "1:"),
            (wrap(r#"<path d="L0 0"/>"#), "move-to"),
            (
                wrap(r#"<g transform="wobble(3)"><rect width="1" height="1"/></g>"#),
                "wobble",
            ),
            ("<svg><rect".to_owned(), "malformed"),
            ("<html/>".to_owned(), "expected <svg>"),
            (wrap(r#"<path d="M0 0 L 1e300 0"/>"#), "out of range"),
        ];
        for (text, expected) in bad {
            let e = read_svg(text.as_bytes(), &SvgOptions::default()).unwrap_err();
            assert!(e.to_string().contains(expected), "{text}: {e}");
        }
        let deep = format!("<svg>{}{}</svg>", "<g>".repeat(300), "</g>".repeat(300));
        assert!(matches!(
            read_svg(deep.as_bytes(), &SvgOptions::default()),
            Err(SvgError::TooDeep { .. })
        ));
    }

    #[test]
    fn hostile_input_fails_cleanly() {
        let cases = [
            wrap(r#"<path d="M0 0 A1e-300 1e-300 0 0 1 1e8 0 Z"/>"#),
            wrap(r#"<g transform="scale(1e6)"><g transform="scale(1e6)"><rect width="1" height="1"/></g></g>"#),
            wrap(r#"<rect width="1" height="1" transform="skewX(90)"/>"#),
            wrap(r#"<path d="M0 0 C 1e9 1e9 -1e9 1e9 0 0 Z"/>"#),
            wrap(r#"<polygon points="0,0"/>"#),
            wrap(r#"<path d="M0 0 1"/>"#),
            wrap(r#"<path d="M0,0 L1,0 Z 5"/>"#),
            wrap(r#"<circle r="-1"/>"#),
            wrap(r#"<path d="M0 0 a 5 5 0 2 0 10 0"/>"#),
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="1e300mm" viewBox="0 0 1e-300 1"><rect width="1" height="1"/></svg>"#.to_owned(),
            r#"<!DOCTYPE svg [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]><svg>&c;</svg>"#.to_owned(),
        ];
        let options = SvgOptions {
            max_spans: 10_000,
            ..SvgOptions::default()
        };
        for text in cases {
            // Either outcome is fine; what matters is no panic and no hang.
            let _ = read_svg(text.as_bytes(), &options);
        }
    }

    #[test]
    fn units_come_from_width_and_view_box() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10cm" height="10cm"
            viewBox="0 0 10 10"><rect width="1" height="1"/></svg>"#;
        let import = read(svg);
        assert!((import.nest.parts[0].contours[0].area() - 100.0).abs() < 1e-9);
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="96px" height="96px">
            <rect width="96" height="96"/></svg>"#;
        let import = read(svg);
        assert!((import.nest.parts[0].contours[0].area() - 25.4 * 25.4).abs() < 1e-9);
    }
}
