//! SVG export of a nest and, optionally, a tool path (thesis §4.2).
//!
//! One `<path>` per part (all its contours in one `d`, holes shown by `fill-rule: evenodd`),
//! everything inside `<g transform="scale(1,-1)">` so CAD's y-up coordinates display upright,
//! arcs as `A` commands split at their zenith when they reach 180° (so the large-arc flag is
//! always 0). Styling is by CSS class, so the app's themes restyle it: `sheet`, `part`, `idle`,
//! `cut`, `link` (chain cutting's tool-on links between contours), `lead` (lead-in/out),
//! `pierce`, `start`, `finish`.

use crate::path_data::PathData;
use cutroute_geometry::{BoundingBox, Contour, Nest, Part, Point, Span};
use svg::node::element::{Circle, Group, Path, Style, Title};
use svg::Document;

use crate::result_json::{MoveKind, ToolMove};

/// The default theme embedded when [`SvgOptions::embed_style`] is on.
pub const DEFAULT_STYLE: &str = "\
path{fill-rule:evenodd;stroke-linejoin:round;vector-effect:non-scaling-stroke;stroke-width:1px}\
path.sheet{fill:none;stroke:#555}\
path.part{fill:#cdff00;fill-opacity:.6;stroke:black}\
path.cut{fill:none;stroke:#d00;stroke-width:2px}\
path.lead{fill:none;stroke:#f80;stroke-width:2px}\
path.idle{fill:none;stroke:#06c;stroke-dasharray:4 3}\
path.link{fill:none;stroke:#d55e00;stroke-width:2px;stroke-dasharray:1 2}\
circle.pierce{fill:#0f0;stroke:navy;vector-effect:non-scaling-stroke}\
circle.start,circle.finish{fill:#fc0;stroke:black;vector-effect:non-scaling-stroke}";

/// Options of [`nest_svg`].
#[derive(Clone, Debug, PartialEq)]
pub struct SvgOptions {
    /// Margin around the drawing as a fraction of its larger side.
    pub margin: f64,
    /// Embed [`DEFAULT_STYLE`]; switch off when the page supplies its own theme.
    pub embed_style: bool,
    /// Radius of pierce/start/finish markers as a fraction of the drawing's larger side.
    pub marker_radius: f64,
}

impl Default for SvgOptions {
    fn default() -> Self {
        Self {
            margin: 0.01,
            embed_style: true,
            marker_radius: 0.002,
        }
    }
}

/// Renders a nest, and the tool moves when given, as a standalone SVG document.
pub fn nest_svg(nest: &Nest, moves: Option<&[ToolMove]>, options: &SvgOptions) -> String {
    let BoundingBox { min, max } = drawing_extent(
        nest,
        moves.unwrap_or(&[]).iter().flat_map(|m| [m.from, m.to]),
    );
    let side = (max.x - min.x).max(max.y - min.y).max(1e-9);
    let margin = side * options.margin;
    let mut doc = Document::new().set("class", "cutroute-nest").set(
        "viewBox",
        (
            min.x - margin,
            -(max.y + margin),
            max.x - min.x + 2.0 * margin,
            max.y - min.y + 2.0 * margin,
        ),
    );
    if options.embed_style {
        doc = doc.add(Style::new(DEFAULT_STYLE));
    }
    let mut flipped = Group::new().set("transform", "scale(1,-1)");
    let mut parts = Group::new().set("class", "nest");
    if let Some(sheet) = &nest.sheet {
        parts = parts.add(part_path(sheet, "sheet"));
    }
    for part in &nest.parts {
        parts = parts.add(part_path(part, "part"));
    }
    flipped = flipped.add(parts);
    if let Some(moves) = moves {
        flipped = flipped.add(route_group(moves, side * options.marker_radius));
    }
    doc.add(flipped).to_string()
}

fn part_path(part: &Part, class: &str) -> Path {
    let mut data = PathData::new();
    for contour in &part.contours {
        data = contour_data(data, contour);
    }
    Path::new()
        .set("class", class)
        // Holes must show as holes even when the page supplies no style sheet.
        .set("fill-rule", "evenodd")
        .set("data-partid", part.name.as_str())
        .set("d", data)
        .add(Title::new(format!(
            "Part: {} / Contours: {}",
            part.name,
            part.contours.len()
        )))
}

fn contour_data(mut data: PathData, contour: &Contour) -> PathData {
    let Some(first) = contour.vertices.first() else {
        return data;
    };
    data = data.move_to((first.point.x, first.point.y));
    for s in contour.spans() {
        data = span_data(data, s.start, s.end, s.bulge);
    }
    data.close()
}

/// Appends one span; `V`/`H`/`L` for straight spans, one or two `A` for arcs.
pub(crate) fn span_data(data: PathData, a: Point, z: Point, b: f64) -> PathData {
    // An arc whose radius lies beyond the coordinate domain is straight to within
    // chord² / (8 · 1e9) mm, and its radius is a number no reader of the domain accepts
    // (a bulge of 1e-13 gives a radius of 1e13 chords): it is written as the line it is.
    let radius = Span::new(a, z, b).radius();
    let too_flat = b != 0.0 && (radius.is_nan() || radius > cutroute_geometry::MAX_COORDINATE);
    if b == 0.0 || a == z || too_flat {
        return if a.x == z.x {
            data.vertical_line_to(z.y)
        } else if a.y == z.y {
            data.horizontal_line_to(z.x)
        } else {
            data.line_to((z.x, z.y))
        };
    }
    if b.abs() > 0.5 {
        // Over about 106°: halved (again if need be) at the middle. An SVG arc is given by its
        // radius, and near a semicircle the radius is about half the chord, where the rounding
        // of the written numbers decides which side the centre lies on: a reader then draws
        // the other half of the circle.
        let (first, second) = Span::new(a, z, b).halved();
        return span_data(
            span_data(data, a, first.end, first.bulge),
            first.end,
            z,
            second.bulge,
        );
    }
    arc(data, a, z, b)
}

fn arc(data: PathData, a: Point, z: Point, b: f64) -> PathData {
    let r = Span::new(a, z, b).radius();
    // Inside the y-flipped group a counter-clockwise arc (b > 0) has sweep flag 1.
    data.arc_to(r, b > 0.0, (z.x, z.y))
}

fn route_group(moves: &[ToolMove], marker: f64) -> Group {
    let mut group = Group::new().set("class", "route");
    let mut i = 0;
    // Consecutive moves of one class form one path, so a contour cut is a single element.
    let class_of = |m: &ToolMove| match (m.kind, m.contour) {
        (MoveKind::Air, _) => "idle",
        (MoveKind::Cut, Some(_)) => "cut",
        (MoveKind::Cut, None) => "link",
        (MoveKind::CutIn | MoveKind::CutOut, _) => "lead",
    };
    while i < moves.len() {
        let class = class_of(&moves[i]);
        let mut data = PathData::new().move_to((moves[i].from.x, moves[i].from.y));
        let mut j = i;
        while j < moves.len()
            && class_of(&moves[j]) == class
            && (j == i || moves[j].from == moves[j - 1].to)
        {
            let m = &moves[j];
            data = span_data(data, m.from, m.to, m.bulge);
            j += 1;
        }
        group = group.add(Path::new().set("class", class).set("d", data));
        i = j;
    }
    let circle = |p: Point, class: &str| {
        Circle::new()
            .set("class", class)
            .set("cx", p.x)
            .set("cy", p.y)
            .set("r", marker)
    };
    for (k, m) in moves.iter().enumerate() {
        let after_idle = k == 0 || moves[k - 1].kind == MoveKind::Air;
        if m.kind != MoveKind::Air && after_idle {
            let title = Title::new(format!("Pierce ({:.3}, {:.3})", m.from.x, m.from.y));
            group = group.add(circle(m.from, "pierce").add(title));
        }
    }
    if let (Some(first), Some(last)) = (moves.first(), moves.last()) {
        group = group.add(circle(first.from, "start"));
        if last.kind == MoveKind::Air {
            group = group.add(circle(last.to, "finish"));
        }
    }
    group
}

/// Bounding box of everything drawn: the nest's contours (arc zeniths included) and `points`
/// (the route's); a unit box when nothing finite is drawn.
pub(crate) fn drawing_extent(nest: &Nest, points: impl IntoIterator<Item = Point>) -> BoundingBox {
    let corners = nest
        .sheet
        .iter()
        .chain(&nest.parts)
        .flat_map(|p| &p.contours)
        .map(Contour::bounding_box)
        .filter(|b| !b.is_empty())
        .flat_map(|b| [b.min, b.max]);
    let extent = BoundingBox::from_points(
        corners
            .chain(points)
            .filter(|p| p.x.is_finite() && p.y.is_finite()),
    );
    if extent.is_empty() {
        return BoundingBox::from_corners(Point::default(), Point::new(1.0, 1.0));
    }
    extent
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::Vertex;

    /// Listing 4.1/4.2 of the thesis: a 700 × 500 sheet and a ring of radii 200 and 100.
    fn listing_4_1() -> Nest {
        let rect = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, 500.0),
            Vertex::line(700.0, 500.0),
            Vertex::line(700.0, 0.0),
        ]);
        let outer = Contour::new(vec![
            Vertex::arc(205.0, 405.0, -1.0),
            Vertex::arc(205.0, 5.0, -1.0),
        ]);
        let hole = Contour::new(vec![
            Vertex::arc(205.0, 305.0, 1.0),
            Vertex::arc(205.0, 105.0, 1.0),
        ]);
        Nest {
            sheet: Some(Part {
                name: "LIST".into(),
                contours: vec![rect],
            }),
            parts: vec![Part {
                name: "RING".into(),
                contours: vec![outer, hole],
            }],
        }
    }

    #[test]
    fn listing_4_2_half_circles_become_quarter_arcs() {
        let svg = nest_svg(
            &listing_4_1(),
            None,
            &SvgOptions {
                embed_style: false,
                margin: 0.0,
                ..Default::default()
            },
        );
        // The sheet: V/H commands only, as in the listing.
        assert!(svg.contains("M0,0 V500 H700 V0 H0 z"), "{svg}");
        // Each half circle is drawn as two quarter arcs: 4 arcs of radius 200 (clockwise,
        // sweep 0) and 4 of radius 100 (counter-clockwise, sweep 1).
        assert_eq!(svg.matches("A200,200,0,0,0,").count(), 4, "{svg}");
        assert_eq!(svg.matches("A100,100,0,0,1,").count(), 4, "{svg}");
        assert!(svg.contains("viewBox=\"0 -500 700 500\""), "{svg}");
        assert!(svg.contains("transform=\"scale(1,-1)\""));
    }
}
