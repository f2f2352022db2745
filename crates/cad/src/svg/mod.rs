//! SVG import: nests drawn as SVG (what DeepNest, SVGnest, Inkscape, Illustrator, Boxes.py and
//! cutroute's own export write) → a [`Nest`](cutroute_geometry::Nest) of closed parts plus a
//! report.
//!
//! What becomes geometry: `<path>` (every command of SVG 1.1, `M L H V C S Q T A Z`, absolute
//! and relative), `<polyline>`, `<polygon>`, `<rect>` (rounded corners too), `<circle>`,
//! `<ellipse>` and `<line>`, inside any depth of `<g>`, `<a>` and nested `<svg>` viewports
//! (with their own `x`, `y`, `width`, `height`, `viewBox` and `preserveAspectRatio`), with
//! `transform` (`matrix`, `translate`, `scale`, `rotate`, `skewX`, `skewY`), and `<use>`
//! (`href` or `xlink:href`, its `x`/`y` and transform, of any element or of a `<symbol>` with
//! its own viewBox). Bézier curves and elliptic arcs are approximated by circular arcs within
//! [`SvgOptions::approximation_tolerance`], by the same code as DXF splines and ellipses;
//! circular arcs under a similarity map stay exact arcs.
//!
//! What is not cut: the content of `<defs>`, `<symbol>` (unless used), `<clipPath>`, `<mask>`,
//! `<marker>` and `<pattern>`; the route layer of cutroute's own export (`<g class="route">`);
//! text and images (a warning counts them); and hidden geometry — `display: none` (which hides
//! the subtree) and `visibility: hidden` (inherited; a child may set `visible`), given as
//! presentation attributes, in `style="…"` or by `<style>` rules with simple selectors (type,
//! `.class`, `#id`), with CSS precedence. Hidden geometry is left out with a
//! [`WarningKind::Hidden`] warning that carries it. A style rule this reader does not follow
//! that sets `display` or `visibility` is a warning, never a silent change.
//!
//! Each closed subpath (ended by `Z`, or whose ends meet within
//! [`SvgOptions::join_tolerance`]) is a contour; open subpaths and lines are joined end to end
//! like loose DXF entities. Contours are grouped into parts by containment, exactly as for DXF
//! (a contour inside a part is its hole, a contour inside a hole starts a new part). An element
//! whose `class` lists `sheet` or `bin` (cutroute's export; the bin of SVGnest and DeepNest
//! when so marked) is the sheet, not a part.
//!
//! **Coordinates.** SVG's y axis points down, the model's up: a user-space point `(x, y)` of the
//! root `<svg>` becomes `(sx·x, −sy·y)` mm, where `sx`, `sy` are the size of one user unit.
//! The origin stays where it is (the root's `viewBox` does not move it), so cutroute's export,
//! which draws the model inside `scale(1,-1)`, reads back at its own coordinates. The size of a
//! user unit comes from [`SvgOptions::user_unit_mm`] when set; otherwise from the root's
//! `width`/`height` in absolute units (`mm`, `cm`, `in`, `pt`, `pc`, `px` = 1/96 in) divided by
//! its `viewBox`, as its `preserveAspectRatio` says (uniform by default). Without a `viewBox`,
//! a user unit is a CSS pixel (1/96 in), as SVG says. Without an absolute size (no
//! `width`/`height`, a percentage, or bare numbers) a user unit is taken as a CSS pixel too,
//! with a [`WarningKind::Units`] warning, since the writer's unit is then a guess. Cutroute's
//! own export (root class `cutroute-nest`) is drawn in millimetres. Inside the drawing, lengths
//! take `mm`, `cm`, `in`, `pt`, `pc`, `px`, `em`/`ex` (of the inherited `font-size`) and `%`
//! (of the nearest viewport).
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

mod parse;
mod style;

use std::collections::HashMap;

use cutroute_geometry::{Point, ReadWarning, Span, Transform, WarningKind};
use roxmltree::{Node, NodeId};

use crate::assemble::{
    assemble, finish_import, is_bounded, AssembleLimits, DrawingImport, EntityRef, Piece,
};
use crate::curves::{approximate, elliptic_spans, ApproxFailure, EllipticArc, Nurbs};
use parse::{
    absolute_unit_mm, close, parse_number_list, parse_path, parse_transform, polyline,
    rounded_rect, split_length, Segment, Subpath,
};
use style::StyleSheet;

/// Deepest nesting of elements followed (`<use>` expansions count); deeper content is refused
/// (hostile input).
const MAX_DEPTH: usize = 256;
/// Largest absolute coordinate or length accepted, in user units.
const MAX_COORDINATE: f64 = 1e9;
/// The SVG namespace; elements of other namespaces (editor metadata) are ignored.
const SVG_NS: &str = "http://www.w3.org/2000/svg";
/// The XLink namespace of SVG 1.1's `xlink:href`.
const XLINK_NS: &str = "http://www.w3.org/1999/xlink";
/// Inkscape's namespace (layer labels, the writer's version).
const INKSCAPE_NS: &str = "http://www.inkscape.org/namespaces/inkscape";
/// Millimetres per CSS pixel.
const MM_PER_PX: f64 = 25.4 / 96.0;
/// CSS's initial `font-size`, in pixels (for `em` lengths).
const INITIAL_FONT_PX: f64 = 16.0;
/// The approximation tolerance of a Bézier curve as a fraction of its extent, where that is
/// finer than the options' tolerance.
const SMALL_CURVE_TOLERANCE: f64 = 1e-2;
/// Elements visited per allowed span: bounds the walk of `<use>` trees that draw nothing.
const VISITS_PER_SPAN: usize = 4;

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

/// Something the reader left out or changed without failing, with where it is: the one
/// warning type of every reader.
pub type SvgWarning = ReadWarning;

/// The result of an SVG import: the closed parts and the sheet when an element is marked as
/// one, the open chains of subpaths, and the warnings.
pub type SvgImport = DrawingImport<SvgWarning>;

/// Why an SVG file could not be imported: the CAD readers' shared [`CadError`](crate::CadError),
/// whose shared and `SVG:` variants this reader returns. `line`/`column` are 1-based positions
/// in the file.
pub type SvgError = crate::CadError;

/// Reads an SVG drawing into closed parts (and the sheet, when one is marked), reporting open
/// chains, and what was left out as warnings.
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
        lines: LineIndex::new(doc.input_text()),
        options,
        budget: options.max_spans,
        visits: options.max_spans.saturating_mul(VISITS_PER_SPAN),
        sheet_css: StyleSheet::default(),
        ids: HashMap::new(),
        using: Vec::new(),
        parts: Vec::new(),
        sheet: Vec::new(),
        warnings: Vec::new(),
        hidden: Vec::new(),
        skipped: Vec::new(),
        clipped: None,
    };
    reader.index(root);
    let (sx, sy, viewport) = reader.root_scale(root)?;
    // User space of the root → model: scale to millimetres and turn y up.
    let context = Context {
        transform: Transform {
            matrix: [[sx, 0.0], [0.0, -sy]],
            offset: Point::ORIGIN,
        },
        layer: "svg".to_owned(),
        in_sheet: false,
        viewport,
        font: INITIAL_FONT_PX,
        display_hidden: None,
        visibility_hidden: None,
    };
    reader.walk(root, &context, 0)?;
    let warnings = reader.take_warnings();

    let limits = AssembleLimits {
        join_tolerance: options.join_tolerance,
        flatten_tolerance: options.approximation_tolerance,
    };
    let Reader {
        parts: part_pieces,
        sheet: sheet_pieces,
        ..
    } = reader;
    let mut warnings = warnings;
    let sheet = if sheet_pieces.is_empty() {
        None
    } else {
        let assembled = assemble(sheet_pieces, &limits);
        let mut sheets = assembled.parts.into_iter();
        let sheet = sheets.next();
        if sheets.next().is_some() {
            warnings.push(ReadWarning::new(
                WarningKind::Sheets,
                "more than one sheet outline; the first is the sheet, the others are ignored",
            ));
        }
        sheet
    };
    let dropped = ReadWarning::from;
    let nothing_drawn = |warnings: &[SvgWarning]| match warnings
        .iter()
        .find(|w| matches!(w.kind, WarningKind::Hidden | WarningKind::Skipped))
    {
        Some(first) => format!("nothing drawn that is cut ({first})"),
        None => "nothing drawn".to_owned(),
    };
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

/// What an element inherits from where it is drawn.
#[derive(Clone, Debug)]
struct Context {
    /// The element's parent user space → model millimetres.
    transform: Transform,
    /// The layer named in the pieces' sources (the nearest group's id or Inkscape label).
    layer: String,
    /// Inside an element marked as the sheet.
    in_sheet: bool,
    /// Size of the nearest viewport in its user units, for percentages (`None`: unknown).
    viewport: Option<(f64, f64)>,
    /// The inherited `font-size` in user units, for `em` and `ex`.
    font: f64,
    /// The hidden group that `display: none` (or an empty viewport) of an ancestor opened.
    display_hidden: Option<usize>,
    /// The hidden group of the inherited `visibility: hidden`.
    visibility_hidden: Option<usize>,
}

impl Context {
    fn hidden(&self) -> Option<usize> {
        self.display_hidden.or(self.visibility_hidden)
    }
}

/// Geometry left out because an element hides it, gathered for one warning.
struct Hidden {
    warning: ReadWarning,
    shapes: usize,
    left_out: Vec<Vec<Point>>,
}

/// Millimetres per root user unit along x and y, and the root viewport's size in user units.
type RootScale = (f64, f64, Option<(f64, f64)>);

/// The map from a viewport's content to its parent's user space, and its size in its own
/// user units.
type Viewport = (Transform, (f64, f64));

/// Which axis a percentage refers to.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Axis {
    X,
    Y,
    /// Radii and other lengths: the viewport's normalised diagonal.
    Other,
}

struct Reader<'a, 'input, 'o> {
    lines: LineIndex<'input>,
    options: &'o SvgOptions,
    budget: usize,
    visits: usize,
    sheet_css: StyleSheet,
    ids: HashMap<&'a str, Node<'a, 'input>>,
    /// The `<use>` targets being expanded, innermost last (a target among them is a cycle).
    using: Vec<NodeId>,
    parts: Vec<Piece>,
    sheet: Vec<Piece>,
    warnings: Vec<SvgWarning>,
    hidden: Vec<Hidden>,
    /// Elements skipped as not cutting geometry, by name: count and first place.
    skipped: Vec<(String, usize, u32, u32)>,
    /// Elements with a `clip-path` that is not applied: count and first place.
    clipped: Option<(usize, u32, u32)>,
}

impl<'a, 'input> Reader<'a, 'input, '_> {
    fn position(&self, node: Node<'_, '_>) -> (u32, u32) {
        self.lines.position(node.range().start)
    }

    fn warn(&mut self, node: Node<'_, '_>, kind: WarningKind, message: impl Into<String>) {
        let warning = self.warning_at(node, kind, message);
        self.warnings.push(warning);
    }

    fn warning_at(
        &self,
        node: Node<'_, '_>,
        kind: WarningKind,
        message: impl Into<String>,
    ) -> ReadWarning {
        let (line, column) = self.position(node);
        ReadWarning::new(kind, message).at_line(line as usize, Some(column as usize))
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

    /// Collects the ids for `<use>` (the first of equal ids wins, as in browsers) and the
    /// `<style>` sheets, which apply to the whole drawing wherever they stand.
    fn index(&mut self, root: Node<'a, 'input>) {
        for node in root.descendants().filter(|n| n.is_element()) {
            if let Some(id) = node.attribute("id") {
                self.ids.entry(id).or_insert(node);
            }
            if node.tag_name().name() != "style"
                || node.tag_name().namespace().is_some_and(|ns| ns != SVG_NS)
            {
                continue;
            }
            let kind = node.attribute("type").unwrap_or("text/css").trim();
            if !kind.is_empty() && !kind.eq_ignore_ascii_case("text/css") {
                self.warn(
                    node,
                    WarningKind::Skipped,
                    format!("a <style> of type {kind:?} is not read; only CSS is"),
                );
                continue;
            }
            let css: String = node.children().filter_map(|c| c.text()).collect();
            for problem in self.sheet_css.add(&css) {
                self.warn(
                    node,
                    WarningKind::Other,
                    format!(
                        "the style rule \"{}\" sets display, visibility, font-size, transform \
                         or clip-path in a way this reader does not follow (or beyond its first {} rules); \
                         it is not applied",
                        problem.what,
                        style::MAX_RULES
                    ),
                );
            }
        }
    }

    /// The size of a root user unit in millimetres along x and y, and the root viewport's size
    /// in user units (for percentages).
    fn root_scale(&mut self, root: Node<'_, '_>) -> Result<RootScale, SvgError> {
        let view_box = self.view_box(root)?;
        let mut sizes = [None, None];
        let mut bare = false;
        for (k, attribute) in ["width", "height"].into_iter().enumerate() {
            let Some(text) = root.attribute(attribute) else {
                continue;
            };
            let Some((value, unit)) = split_length(text) else {
                return Err(self.bad_attribute(root, attribute, "not a length"));
            };
            if let Some(mm) = absolute_unit_mm(unit) {
                if value > 0.0 && value * mm <= 1e12 {
                    sizes[k] = Some(value * mm);
                    bare |= unit.is_empty();
                }
            }
        }
        let viewport = match view_box {
            Some([_, _, w, h]) => Some((w, h)),
            None => match sizes {
                [Some(w), Some(h)] => Some((w / MM_PER_PX, h / MM_PER_PX)),
                _ => None,
            },
        };
        if let Some(mm) = self.options.user_unit_mm {
            return Ok((mm, mm, viewport));
        }
        let class = root.attribute("class").unwrap_or("");
        if class.split_ascii_whitespace().any(|c| c == "cutroute-nest") {
            return Ok((1.0, 1.0, viewport));
        }
        let scale = match (view_box, sizes) {
            (Some([_, _, w, h]), [Some(width), Some(height)]) => {
                let (sx, sy) = (width / w, height / h);
                match self.aspect(root) {
                    Aspect { none: true, .. } => Some((sx, sy)),
                    Aspect { slice: true, .. } => Some((sx.max(sy), sx.max(sy))),
                    _ => Some((sx.min(sy), sx.min(sy))),
                }
            }
            (Some([_, _, w, _]), [Some(width), None]) => Some((width / w, width / w)),
            (Some([_, _, _, h]), [None, Some(height)]) => Some((height / h, height / h)),
            (Some(_), [None, None]) => None,
            // Without a viewBox a user unit is a CSS pixel, whatever the size's unit; but
            // Inkscape before 0.92 drew 90 of its pixels to the inch, and its files say which
            // version wrote them (Inkscape itself reads them so when it opens them).
            (None, [Some(_), _] | [_, Some(_)]) => match legacy_inkscape(root) {
                Some(version) => {
                    self.warn(
                        root,
                        WarningKind::Units,
                        format!(
                            "written by Inkscape {version}, which drew 90 user units to the \
                             inch (not CSS's 96): one user unit is {:.6} mm",
                            25.4 / 90.0
                        ),
                    );
                    Some((25.4 / 90.0, 25.4 / 90.0))
                }
                None => Some((MM_PER_PX, MM_PER_PX)),
            },
            (None, [None, None]) => None,
        };
        let scale = scale.filter(|&(sx, sy)| {
            sx.is_finite() && sy.is_finite() && sx > 0.0 && sy > 0.0 && sx <= 1e6 && sy <= 1e6
        });
        match scale {
            Some((sx, sy)) => {
                if bare {
                    self.warn(
                        root,
                        WarningKind::Units,
                        format!(
                            "the drawing's width or height has no unit, so it is taken in CSS \
                             pixels (1/96 in): one user unit is {:.6} mm",
                            sx
                        ),
                    );
                }
                Ok((sx, sy, viewport))
            }
            None => {
                self.warn(
                    root,
                    WarningKind::Units,
                    "the drawing gives no absolute size (width and height in mm, cm, in, pt or \
                     px, with a viewBox), so one user unit is taken as one CSS pixel \
                     (0.264583 mm); set the size in the drawing if it is meant otherwise",
                );
                Ok((MM_PER_PX, MM_PER_PX, viewport))
            }
        }
    }

    /// The `viewBox` of an element; `None` when absent or of a non-positive size (which SVG
    /// says disables it).
    fn view_box(&self, node: Node<'_, '_>) -> Result<Option<[f64; 4]>, SvgError> {
        let Some(text) = node.attribute("viewBox") else {
            return Ok(None);
        };
        let numbers = parse_number_list(text)
            .ok_or_else(|| self.bad_attribute(node, "viewBox", "not a list of numbers"))?;
        match numbers[..] {
            [x, y, w, h] if w > 0.0 && h > 0.0 => {
                if [x, y, w, h].iter().any(|v| v.abs() > MAX_COORDINATE) {
                    return Err(self.bad_attribute(
                        node,
                        "viewBox",
                        "out of range (|value| > 1e9)",
                    ));
                }
                Ok(Some([x, y, w, h]))
            }
            [_, _, _, _] => Ok(None),
            _ => Err(self.bad_attribute(node, "viewBox", "expected four numbers")),
        }
    }

    /// `preserveAspectRatio` (SVG 1.1 §7.8); an unknown value is SVG's default.
    fn aspect(&mut self, node: Node<'_, '_>) -> Aspect {
        let text = node.attribute("preserveAspectRatio").unwrap_or("");
        let mut words = text.split_ascii_whitespace();
        let mut align = words.next().unwrap_or("xMidYMid");
        if align == "defer" {
            align = words.next().unwrap_or("xMidYMid");
        }
        let fit = words.next().unwrap_or("meet");
        let mut aspect = Aspect {
            none: align == "none",
            slice: fit == "slice",
            x: 0.5,
            y: 0.5,
        };
        if !aspect.none {
            let part = |s: &str| match s {
                "Min" => Some(0.0),
                "Mid" => Some(0.5),
                "Max" => Some(1.0),
                _ => None,
            };
            let parsed = align
                .strip_prefix('x')
                .filter(|a| a.len() == 7)
                .and_then(|a| {
                    let (x, y) = a.split_at(3);
                    Some((part(x)?, part(y.strip_prefix('Y')?)?))
                });
            match parsed {
                Some((x, y)) => {
                    aspect.x = x;
                    aspect.y = y;
                }
                None => self.warn(
                    node,
                    WarningKind::Other,
                    format!(
                        "preserveAspectRatio {text:?} is not understood; xMidYMid meet is used"
                    ),
                ),
            }
            if !matches!(fit, "meet" | "slice") {
                self.warn(
                    node,
                    WarningKind::Other,
                    format!("preserveAspectRatio {text:?} is not understood; meet is used"),
                );
            }
        }
        aspect
    }

    /// The map from a viewport element's (nested `<svg>`, used `<symbol>`) content to its
    /// parent's user space, and its viewport size; `None` when its size is zero, which SVG
    /// says draws nothing.
    fn viewport(
        &mut self,
        node: Node<'_, '_>,
        context: &Context,
        place: Option<Node<'_, '_>>,
    ) -> Result<Option<Viewport>, SvgError> {
        // A used symbol takes its size from the <use> (x and y are already applied there).
        let sized = place.unwrap_or(node);
        let (x, y) = if place.is_some() {
            (0.0, 0.0)
        } else {
            (
                self.length_or(node, "x", Axis::X, context, 0.0)?,
                self.length_or(node, "y", Axis::Y, context, 0.0)?,
            )
        };
        let view_box = self.view_box(node)?;
        let full = |axis: usize| -> Option<f64> {
            context
                .viewport
                .map(|v| if axis == 0 { v.0 } else { v.1 })
                .or_else(|| view_box.map(|b| b[2 + axis]))
        };
        let mut size = [0.0; 2];
        for (k, (attribute, axis)) in [("width", Axis::X), ("height", Axis::Y)]
            .into_iter()
            .enumerate()
        {
            size[k] = match sized.attribute(attribute) {
                Some(_) => self.length(sized, attribute, axis, context)?,
                // 100 % of the parent's viewport (or, unknown, the viewBox at scale 1).
                None => match full(k) {
                    Some(v) => v,
                    None => {
                        return Err(self.bad_attribute(
                            sized,
                            attribute,
                            "missing, and the enclosing viewport's size is unknown",
                        ))
                    }
                },
            };
        }
        let [w, h] = size;
        if w <= 0.0 || h <= 0.0 {
            return Ok(None);
        }
        let Some([bx, by, bw, bh]) = view_box else {
            return Ok(Some((Transform::translation(x, y), (w, h))));
        };
        let aspect = self.aspect(node);
        let (sx, sy) = (w / bw, h / bh);
        let (sx, sy) = if aspect.none {
            (sx, sy)
        } else if aspect.slice {
            (sx.max(sy), sx.max(sy))
        } else {
            (sx.min(sy), sx.min(sy))
        };
        let tx = x + aspect.x * (w - bw * sx) - bx * sx;
        let ty = y + aspect.y * (h - bh * sy) - by * sy;
        let map = Transform {
            matrix: [[sx, 0.0], [0.0, sy]],
            offset: Point::new(tx, ty),
        };
        Ok(Some((map, (bw, bh))))
    }

    /// Opens a hidden group for the geometry under `node`.
    fn hide(&mut self, node: Node<'_, '_>, why: &str) -> usize {
        let id = node
            .attribute("id")
            .map(|id| format!(" id=\"{id}\""))
            .unwrap_or_default();
        let warning = self.warning_at(
            node,
            WarningKind::Hidden,
            format!("<{}{id}> is {why}", node.tag_name().name()),
        );
        self.hidden.push(Hidden {
            warning,
            shapes: 0,
            left_out: Vec::new(),
        });
        self.hidden.len() - 1
    }

    fn skip(&mut self, node: Node<'_, '_>) {
        let name = node.tag_name().name();
        let (line, column) = self.position(node);
        match self.skipped.iter_mut().find(|s| s.0 == name) {
            Some(entry) => entry.1 += 1,
            None => self.skipped.push((name.to_owned(), 1, line, column)),
        }
    }

    /// The warnings in file order of their kinds: the walk's, then what was hidden, skipped
    /// and not clipped.
    fn take_warnings(&mut self) -> Vec<SvgWarning> {
        let mut warnings = std::mem::take(&mut self.warnings);
        for group in std::mem::take(&mut self.hidden) {
            if group.shapes == 0 {
                continue; // It hid text or nothing at all: no geometry was left out.
            }
            let what = if group.shapes == 1 {
                "1 shape".to_owned()
            } else {
                format!("{} shapes", group.shapes)
            };
            let mut warning = group.warning;
            warning.message = format!("{}: {what} left out", warning.message);
            warnings.push(warning.leaving_out(group.left_out));
        }
        for (name, count, line, column) in std::mem::take(&mut self.skipped) {
            let what = if count == 1 {
                format!("1 <{name}> element is")
            } else {
                format!("{count} <{name}> elements are")
            };
            let why = match name.as_str() {
                "text" | "flowRoot" => "convert text to paths to cut it",
                "image" => "images are not cutting geometry",
                _ => "not cutting geometry this reader knows",
            };
            warnings.push(
                ReadWarning::new(
                    WarningKind::Skipped,
                    format!("{what} not cut (the first here); {why}"),
                )
                .at_line(line as usize, Some(column as usize)),
            );
        }
        if let Some((count, line, column)) = self.clipped.take() {
            warnings.push(
                ReadWarning::new(
                    WarningKind::Other,
                    format!(
                        "{count} element(s) with a clip-path (the first here): clipping is not \
                         applied, the shapes are cut whole"
                    ),
                )
                .at_line(line as usize, Some(column as usize)),
            );
        }
        warnings
    }

    fn walk(
        &mut self,
        node: Node<'a, 'input>,
        parent: &Context,
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
        self.visits = self.visits.checked_sub(1).ok_or(SvgError::TooComplex {
            limit: self.options.max_spans,
        })?;
        let namespace = node.tag_name().namespace();
        if namespace.is_some_and(|ns| ns != SVG_NS) {
            return Ok(());
        }
        let name = node.tag_name().name();
        match name {
            "svg" | "g" | "a" | "switch" | "use" | "path" | "polyline" | "polygon" | "rect"
            | "circle" | "ellipse" | "line" | "symbol" => {}
            "text" | "flowRoot" | "image" | "foreignObject" => {
                if parent.hidden().is_none() && self.shown(node) {
                    self.skip(node);
                }
                return Ok(());
            }
            // Not rendered, or not geometry: defs, clipPath, mask, marker, pattern, style,
            // title, desc, metadata, gradients, filters, scripts, animation.
            _ => return Ok(()),
        }
        let mut context = parent.clone();
        if context.display_hidden.is_none() && !self.shown(node) {
            context.display_hidden = Some(self.hide(node, "not displayed (display: none)"));
        }
        match self.sheet_css.value(node, "visibility").as_deref() {
            Some("hidden" | "collapse") if context.visibility_hidden.is_none() => {
                context.visibility_hidden = Some(self.hide(node, "hidden (visibility: hidden)"));
            }
            Some("visible") => context.visibility_hidden = None,
            _ => {}
        }
        if let Some(size) = self.sheet_css.value(node, "font-size") {
            if let Some((value, unit)) = split_length(&size) {
                let px = match unit {
                    "em" => Some(value * parent.font),
                    "ex" => Some(value * parent.font / 2.0),
                    "%" => Some(value * parent.font / 100.0),
                    _ => absolute_unit_mm(unit).map(|mm| value * mm / MM_PER_PX),
                };
                if let Some(px) = px.filter(|v| v.is_finite() && *v > 0.0 && *v <= MAX_COORDINATE) {
                    context.font = px;
                }
            }
        }
        if self.sheet_css.declared(node, "transform") {
            self.warn(
                node,
                WarningKind::Other,
                "a transform given as a CSS property is not applied; only the transform \
                 attribute is",
            );
        }
        if context.hidden().is_none()
            && (node.attribute("clip-path").is_some() || self.sheet_css.declared(node, "clip-path"))
        {
            let (line, column) = self.position(node);
            let entry = self.clipped.get_or_insert((0, line, column));
            entry.0 += 1;
        }
        let classes: Vec<&str> = node
            .attribute("class")
            .map(|c| c.split_ascii_whitespace().collect())
            .unwrap_or_default();
        context.in_sheet |= classes.iter().any(|&c| c == "sheet" || c == "bin");
        if let Some(text) = node.attribute("transform") {
            let local = parse_transform(text)
                .map_err(|reason| self.bad_attribute(node, "transform", &reason))?;
            context.transform = local.then(&parent.transform);
        }
        self.check_bounded(node, &context.transform)?;
        match name {
            "svg" | "g" | "a" | "switch" | "symbol" => {
                if name == "g" && classes.contains(&"route") {
                    return Ok(()); // cutroute's export draws the route here: not geometry.
                }
                if name == "symbol" {
                    return Ok(()); // Drawn only where a <use> places it.
                }
                if let Some(layer) = node
                    .attribute("id")
                    .or_else(|| node.attribute((INKSCAPE_NS, "label")))
                {
                    layer.clone_into(&mut context.layer);
                }
                if name == "svg" && depth > 0 {
                    self.enter_viewport(node, &mut context, None)?;
                }
                if name == "switch" {
                    // SVG draws the first child whose conditions hold; this reader supports no
                    // extensions (Illustrator puts its private data first behind one).
                    let first = node.children().find(|c| {
                        c.is_element()
                            && c.tag_name().namespace().is_none_or(|ns| ns == SVG_NS)
                            && !c.has_attribute("requiredExtensions")
                    });
                    return match first {
                        Some(child) => self.walk(child, &context, depth + 1),
                        None => Ok(()),
                    };
                }
                self.walk_children(node, &context, depth)
            }
            "use" => self.expand_use(node, context, depth),
            _ => {
                let subpaths = self.shape(node, &context)?;
                let (line, _) = self.position(node);
                let source = EntityRef {
                    entity: name.to_owned(),
                    line: line as usize,
                    layer: context.layer.clone(),
                };
                if let Some(group) = context.hidden() {
                    if !subpaths.is_empty() {
                        self.hidden[group].shapes += 1;
                    }
                }
                for subpath in subpaths {
                    self.push(subpath, &context, source.clone())?;
                }
                Ok(())
            }
        }
    }

    fn walk_children(
        &mut self,
        node: Node<'a, 'input>,
        context: &Context,
        depth: usize,
    ) -> Result<(), SvgError> {
        for child in node.children() {
            self.walk(child, context, depth + 1)?;
        }
        Ok(())
    }

    /// Whether `display` lets the element be drawn (`display` is not inherited, but `none`
    /// hides the whole subtree).
    fn shown(&self, node: Node<'_, '_>) -> bool {
        self.sheet_css.value(node, "display").as_deref() != Some("none")
    }

    fn check_bounded(&self, node: Node<'_, '_>, transform: &Transform) -> Result<(), SvgError> {
        if is_bounded(transform) {
            Ok(())
        } else {
            Err(self.bad_attribute(
                node,
                "transform",
                "the accumulated transform scales beyond 1e6 or moves beyond 1e12",
            ))
        }
    }

    /// Moves `context` into the viewport that `node` (a nested `<svg>`, or a `<symbol>`
    /// placed by the `<use>` `place`) establishes.
    fn enter_viewport(
        &mut self,
        node: Node<'_, '_>,
        context: &mut Context,
        place: Option<Node<'_, '_>>,
    ) -> Result<(), SvgError> {
        match self.viewport(node, context, place)? {
            Some((map, size)) => {
                context.transform = map.then(&context.transform);
                context.viewport = Some(size);
                self.check_bounded(node, &context.transform)
            }
            None => {
                if context.display_hidden.is_none() {
                    context.display_hidden = Some(self.hide(
                        place.unwrap_or(node),
                        "a viewport of zero width or height, which draws nothing",
                    ));
                }
                Ok(())
            }
        }
    }

    /// Draws what a `<use>` refers to, at its `x`/`y` under its transform (already in
    /// `context`), with the `<use>`'s inherited properties.
    fn expand_use(
        &mut self,
        node: Node<'a, 'input>,
        mut context: Context,
        depth: usize,
    ) -> Result<(), SvgError> {
        let href = node
            .attribute((XLINK_NS, "href"))
            .or_else(|| node.attribute("href"))
            .map(str::trim);
        let target = href
            .and_then(|h| h.strip_prefix('#'))
            .and_then(|id| self.ids.get(id).copied());
        let Some(target) = target else {
            let what = match href {
                Some(h) => format!("refers to {h:?}, which is not an element of this file"),
                None => "has no href".to_owned(),
            };
            if context.hidden().is_none() {
                self.warn(
                    node,
                    WarningKind::Skipped,
                    format!("<use> {what}; nothing is drawn for it"),
                );
            }
            return Ok(());
        };
        if node.ancestors().any(|a| a == target) || self.using.contains(&target.id()) {
            let attribute = if node.has_attribute((XLINK_NS, "href")) {
                "xlink:href"
            } else {
                "href"
            };
            let (line, column) = self.position(node);
            return Err(SvgError::BadAttribute {
                element: "use".to_owned(),
                attribute: attribute.to_owned(),
                value: href.unwrap_or("").chars().take(80).collect(),
                reason: "it refers to an element that contains this <use> (a cycle)".to_owned(),
                line,
                column,
            });
        }
        let x = self.length_or(node, "x", Axis::X, &context, 0.0)?;
        let y = self.length_or(node, "y", Axis::Y, &context, 0.0)?;
        context.transform = Transform::translation(x, y).then(&context.transform);
        self.check_bounded(node, &context.transform)?;
        self.using.push(target.id());
        let result = if target.tag_name().name() == "symbol"
            && target.tag_name().namespace().is_none_or(|ns| ns == SVG_NS)
        {
            self.use_symbol(node, target, context, depth)
        } else {
            self.walk(target, &context, depth + 1)
        };
        self.using.pop();
        result
    }

    /// A `<symbol>` drawn by a `<use>`: its own viewBox in the viewport the `<use>` sizes.
    fn use_symbol(
        &mut self,
        place: Node<'a, 'input>,
        symbol: Node<'a, 'input>,
        mut context: Context,
        depth: usize,
    ) -> Result<(), SvgError> {
        if context.display_hidden.is_none() && !self.shown(symbol) {
            context.display_hidden = Some(self.hide(symbol, "not displayed (display: none)"));
        }
        if let Some(text) = symbol.attribute("transform") {
            let local = parse_transform(text)
                .map_err(|reason| self.bad_attribute(symbol, "transform", &reason))?;
            context.transform = local.then(&context.transform);
        }
        self.enter_viewport(symbol, &mut context, Some(place))?;
        self.walk_children(symbol, &context, depth + 1)
    }

    fn length_or(
        &self,
        node: Node<'_, '_>,
        attribute: &str,
        axis: Axis,
        context: &Context,
        default: f64,
    ) -> Result<f64, SvgError> {
        match node.attribute(attribute) {
            None => Ok(default),
            Some(_) => self.length(node, attribute, axis, context),
        }
    }

    /// A coordinate or length attribute in user units: absolute units at 96 px per inch,
    /// `em`/`ex` of the font size, `%` of the nearest viewport.
    fn length(
        &self,
        node: Node<'_, '_>,
        attribute: &str,
        axis: Axis,
        context: &Context,
    ) -> Result<f64, SvgError> {
        let text = node.attribute(attribute).unwrap_or("");
        let (value, unit) = split_length(text)
            .ok_or_else(|| self.bad_attribute(node, attribute, "not a length"))?;
        let value = match unit {
            "em" => value * context.font,
            "ex" => value * context.font / 2.0,
            "%" => {
                let (w, h) = context.viewport.ok_or_else(|| {
                    self.bad_attribute(
                        node,
                        attribute,
                        "a percentage of a viewport whose size the drawing does not give",
                    )
                })?;
                let whole = match axis {
                    Axis::X => w,
                    Axis::Y => h,
                    Axis::Other => ((w * w + h * h) / 2.0).sqrt(),
                };
                value * whole / 100.0
            }
            _ => {
                value
                    * (absolute_unit_mm(unit)
                        .ok_or_else(|| self.bad_attribute(node, attribute, "unknown unit"))?
                        / MM_PER_PX)
            }
        };
        if !value.is_finite() || value.abs() > MAX_COORDINATE {
            return Err(self.bad_attribute(node, attribute, "out of range (|value| > 1e9)"));
        }
        Ok(value)
    }
    /// The element's geometry as subpaths in its own user space.
    fn shape(&mut self, node: Node<'_, '_>, c: &Context) -> Result<Vec<Subpath>, SvgError> {
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
                    self.warn(
                        node,
                        WarningKind::Other,
                        "odd number of coordinates; the last one is ignored",
                    );
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
                    self.length_or(node, "x1", Axis::X, c, 0.0)?,
                    self.length_or(node, "y1", Axis::Y, c, 0.0)?,
                );
                let b = Point::new(
                    self.length_or(node, "x2", Axis::X, c, 0.0)?,
                    self.length_or(node, "y2", Axis::Y, c, 0.0)?,
                );
                Ok(vec![polyline(&[a, b])])
            }
            "circle" | "ellipse" => {
                let cx = self.length_or(node, "cx", Axis::X, c, 0.0)?;
                let cy = self.length_or(node, "cy", Axis::Y, c, 0.0)?;
                let (rx, ry) = if name == "circle" {
                    let r = self.length_or(node, "r", Axis::Other, c, 0.0)?;
                    (r, r)
                } else {
                    (
                        self.length_or(node, "rx", Axis::X, c, 0.0)?,
                        self.length_or(node, "ry", Axis::Y, c, 0.0)?,
                    )
                };
                if rx <= 0.0 || ry <= 0.0 {
                    if c.hidden().is_none() {
                        self.warn(
                            node,
                            WarningKind::ZeroArea,
                            format!("<{name}> with a radius of zero or less is not drawn"),
                        );
                    }
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
                let x = self.length_or(node, "x", Axis::X, c, 0.0)?;
                let y = self.length_or(node, "y", Axis::Y, c, 0.0)?;
                let w = self.length_or(node, "width", Axis::X, c, 0.0)?;
                let h = self.length_or(node, "height", Axis::Y, c, 0.0)?;
                if w <= 0.0 || h <= 0.0 {
                    if c.hidden().is_none() {
                        self.warn(
                            node,
                            WarningKind::ZeroArea,
                            "<rect> with a size of zero or less is not drawn",
                        );
                    }
                    return Ok(Vec::new());
                }
                // SVG: a missing rx takes ry's value and vice versa; both are clamped to half
                // the side.
                let rx_given = node
                    .attribute("rx")
                    .map(|_| self.length(node, "rx", Axis::X, c))
                    .transpose()?;
                let ry_given = node
                    .attribute("ry")
                    .map(|_| self.length(node, "ry", Axis::Y, c))
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
        context: &Context,
        source: EntityRef,
    ) -> Result<(), SvgError> {
        let to_model = &context.transform;
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
                    // A curve far smaller than the tolerance (the rounded corners Boxes.py
                    // draws, 0.1 mm across) would be replaced by arcs of a visibly different
                    // length: its tolerance shrinks with its size.
                    let extent = world
                        .iter()
                        .map(|p| p.distance(world[0]))
                        .fold(0.0, f64::max);
                    let pieces = approximate(
                        &|t| curve.point_at(t),
                        0.0,
                        1.0,
                        &[0.5],
                        tolerance.min(extent * SMALL_CURVE_TOLERANCE),
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
        if let Some(group) = context.hidden() {
            self.hidden[group].left_out.push(flattened(&piece.spans));
        } else if context.in_sheet {
            self.sheet.push(piece);
        } else {
            self.parts.push(piece);
        }
        Ok(())
    }
}

/// Lines and columns of byte offsets in time linear in the file: roxmltree's `text_pos_at`
/// counts from the start of the text at every call, which made every element's position cost
/// the length of the file before it.
struct LineIndex<'t> {
    text: &'t str,
    /// Byte offset of the start of each line.
    starts: Vec<usize>,
    /// The last position asked for, `(offset, column)`: positions are mostly asked in file
    /// order, so the column is counted on from there along one line (minified files have one).
    last: std::cell::Cell<(usize, u32)>,
}

impl<'t> LineIndex<'t> {
    fn new(text: &'t str) -> Self {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(k, _)| k + 1))
            .collect();
        Self {
            text,
            starts,
            last: std::cell::Cell::new((0, 1)),
        }
    }

    /// The 1-based line and column (in characters) of a byte offset.
    fn position(&self, offset: usize) -> (u32, u32) {
        let offset = offset.min(self.text.len());
        let line = self.starts.partition_point(|&s| s <= offset).max(1);
        let start = self.starts[line - 1];
        let (last, last_column) = self.last.get();
        let (from, column) = if last >= start && last <= offset {
            (last, last_column)
        } else {
            (start, 1)
        };
        let between = self.text.get(from..offset).map_or(0, |t| t.chars().count());
        let column = column.saturating_add(u32::try_from(between).unwrap_or(u32::MAX));
        self.last.set((offset, column));
        (u32::try_from(line).unwrap_or(u32::MAX), column)
    }
}

/// A `preserveAspectRatio`: no uniform scaling (`none`), or uniform by the larger factor
/// (`slice`) or the smaller (`meet`), aligned at the fractions `x`, `y` of the viewport.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Aspect {
    none: bool,
    slice: bool,
    x: f64,
    y: f64,
}

/// The version of Inkscape before 0.92 that wrote the drawing, if one did.
fn legacy_inkscape<'n>(root: Node<'n, '_>) -> Option<&'n str> {
    let version = root.attribute((INKSCAPE_NS, "version"))?;
    let mut numbers = version
        .split(|c: char| !c.is_ascii_digit())
        .map(|n| n.parse::<u32>().ok());
    match (numbers.next()??, numbers.next()??) {
        (0, minor) if minor < 92 => Some(version.trim()),
        _ => None,
    }
}

/// Spans as one polyline, arcs cut into chords of at most 1/32 turn, for drawing what was
/// left out.
fn flattened(spans: &[Span]) -> Vec<Point> {
    let mut points = Vec::with_capacity(spans.len() + 1);
    if let Some(first) = spans.first() {
        points.push(first.start);
    }
    for span in spans {
        if !span.is_line() {
            let steps = (span.sweep().abs() / (std::f64::consts::TAU / 32.0)).ceil();
            let steps = steps.clamp(1.0, 32.0) as usize;
            for k in 1..steps {
                points.push(span.point_at(k as f64 / steps as f64));
            }
        }
        points.push(span.end);
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(svg: &str) -> SvgImport {
        read_svg(svg.as_bytes(), &SvgOptions::default()).unwrap()
    }

    fn wrap(body: &str) -> String {
        let root = r#"<svg xmlns="http://www.w3.org/2000/svg" width="500mm" height="500mm" viewBox="0 0 500 500">"#;
        format!("{root}{body}</svg>")
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

    #[test]
    fn line_index_agrees_with_the_xml_parser_in_any_order() {
        let text = "<svg>\n  <g id=\"é\">  <rect/>\n\n<path d=\"M0 0\"/>ü<line/></g></svg>";
        let doc = roxmltree::Document::parse(text).unwrap();
        let lines = LineIndex::new(text);
        let mut offsets: Vec<usize> = doc.descendants().map(|n| n.range().start).collect();
        offsets.push(text.len());
        let reversed: Vec<usize> = offsets.iter().rev().copied().collect();
        for offset in offsets.into_iter().chain(reversed) {
            let p = doc.text_pos_at(offset);
            assert_eq!(lines.position(offset), (p.row, p.col), "offset {offset}");
        }
    }
}
