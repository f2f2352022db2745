//! A standalone HTML page of a routed nest: open it from disk in any browser, no server and no
//! network needed.
//!
//! Everything is inline: the SVG drawing (sheet, parts with holes, cut moves, idle moves,
//! pierce points, start and finish), the CSS, the route's numbers (idle and cut length, pierces,
//! machine time) and a small script that plays the tool head along the route in machine time
//! (play/pause, scrub, speed) and pans/zooms by rewriting the `viewBox` (wheel around the
//! cursor, drag, `+`/`-`/`0` keys, a Fit button). The page is also well-formed XML (scripts and
//! styles sit in CDATA sections), so XML tools can read its drawing.

use std::fmt::Write as _;

use crate::path_data::PathData;
use cutroute_geometry::{
    BoundingBox, MachineParameters, Nest, Point, Route, RouteError, ToolClock, ToolMove, Toolpath,
};
use svg::node::element::{Circle, Group, Path, Title};
use svg::Document;

use crate::svg_export::span_data;

/// Options of [`route_html`].
#[derive(Clone, Debug, PartialEq)]
pub struct HtmlOptions {
    /// Title of the page (e.g. the nest's file name).
    pub title: String,
    /// Speeds and pierce time for the machine-time clock and the statistics.
    pub machine: MachineParameters,
    /// Real seconds the animation takes for the whole route at speed ×1 (the page offers
    /// faster speeds).
    pub playback_s: f64,
    /// Margin around the drawing as a fraction of its larger side.
    pub margin: f64,
    /// Radius of the pierce/start/finish markers as a fraction of the drawing's larger side.
    pub marker_radius: f64,
}

impl Default for HtmlOptions {
    fn default() -> Self {
        HtmlOptions {
            title: "cutroute route".into(),
            machine: MachineParameters::default(),
            playback_s: 30.0,
            margin: 0.02,
            marker_radius: 0.003,
        }
    }
}

/// Why a page could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HtmlExportError {
    /// The route does not fit the nest (a step names a contour the nest lacks).
    #[error("the route does not fit the nest: {0}")]
    Route(#[from] RouteError),
}

const STYLE: &str = "\
body{margin:0;font:14px system-ui,sans-serif;background:#fafafa;color:#222;display:flex;flex-direction:column;height:100vh}\
header{padding:.5em 1em;display:flex;flex-wrap:wrap;gap:1em;align-items:center;border-bottom:1px solid #ccc}\
h1{font-size:1.1em;margin:0}\
dl{display:flex;gap:1em;margin:0}dt{font-weight:bold}dd{margin:0 0 0 .3em}\
dl div{display:flex}\
#view{flex:1;width:100%;background:#fff;cursor:grab;touch-action:none}\
path{fill-rule:evenodd;stroke-linejoin:round;vector-effect:non-scaling-stroke;stroke-width:1px}\
path.sheet{fill:#eee;stroke:#555}\
path.part{fill:#9ecae1;fill-opacity:.5;stroke:#08306b}\
path.cut{fill:none;stroke:#d55e00;stroke-width:2px}\
path.idle{fill:none;stroke:#0072b2;stroke-dasharray:4 3}\
circle{vector-effect:non-scaling-stroke;stroke-width:1px}\
circle.pierce{fill:#009e73;stroke:#000}\
circle.start,circle.finish{fill:#f0e442;stroke:#000}\
circle#tool-head{fill:#cc79a7;stroke:#000;stroke-width:2px}\
button{font:inherit}";

/// Animates the head along the sampled route (`R` = [machine time, x, y] rows) and pans/zooms.
const SCRIPT: &str = r#"
(function () {
  var R = JSON.parse(document.getElementById('route-data').textContent);
  var svg = document.getElementById('view');
  var head = document.getElementById('tool-head');
  var clock = document.getElementById('clock');
  var play = document.getElementById('anim-play');
  var scrub = document.getElementById('anim-scrub');
  var speedBox = document.getElementById('anim-speed');
  var total = R.length ? R[R.length - 1][0] : 0;
  var playback = Number(svg.getAttribute('data-playback-s')) || 30;
  var t = 0, playing = false, last = null;
  function at(time) {
    var lo = 0, hi = R.length - 1;
    if (hi < 0) return [0, 0];
    while (hi - lo > 1) { var mid = (lo + hi) >> 1; if (R[mid][0] > time) hi = mid; else lo = mid; }
    var a = R[lo], b = R[hi], span = b[0] - a[0];
    var f = span > 0 ? Math.min(1, Math.max(0, (time - a[0]) / span)) : 1;
    return [a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f];
  }
  function show() {
    var p = at(t);
    head.setAttribute('cx', p[0]); head.setAttribute('cy', p[1]);
    head.setAttribute('data-machine-time', t.toFixed(3));
    clock.textContent = t.toFixed(1) + ' s / ' + total.toFixed(1) + ' s';
    scrub.value = total > 0 ? Math.round(1000 * t / total) : 0;
  }
  function frame(now) {
    if (!playing) return;
    if (last !== null) t = Math.min(total, t + (now - last) / 1000 * total / playback * Number(speedBox.value));
    last = now;
    show();
    if (t >= total) { playing = false; play.textContent = 'Play'; return; }
    requestAnimationFrame(frame);
  }
  play.addEventListener('click', function () {
    playing = !playing; last = null;
    if (playing && t >= total) t = 0;
    play.textContent = playing ? 'Pause' : 'Play';
    if (playing) requestAnimationFrame(frame);
  });
  scrub.addEventListener('input', function () { t = total * Number(scrub.value) / 1000; show(); });
  var home = svg.getAttribute('viewBox').split(' ').map(Number), box = home.slice();
  function setBox(b) { box = b; svg.setAttribute('viewBox', b.join(' ')); }
  function toView(e) {
    var r = svg.getBoundingClientRect();
    var s = Math.max(box[2] / r.width, box[3] / r.height);
    var ox = box[0] + box[2] / 2 - s * r.width / 2, oy = box[1] + box[3] / 2 - s * r.height / 2;
    return [ox + (e.clientX - r.left) * s, oy + (e.clientY - r.top) * s, s];
  }
  function zoom(k, cx, cy) {
    setBox([cx - (cx - box[0]) * k, cy - (cy - box[1]) * k, box[2] * k, box[3] * k]);
  }
  svg.addEventListener('wheel', function (e) {
    e.preventDefault();
    var p = toView(e);
    zoom(Math.pow(1.0015, e.deltaY), p[0], p[1]);
  }, { passive: false });
  var drag = null;
  svg.addEventListener('pointerdown', function (e) { drag = toView(e); svg.setPointerCapture(e.pointerId); });
  svg.addEventListener('pointermove', function (e) {
    if (!drag) return;
    var p = toView(e);
    setBox([box[0] - (p[0] - drag[0]), box[1] - (p[1] - drag[1]), box[2], box[3]]);
  });
  svg.addEventListener('pointerup', function () { drag = null; });
  document.getElementById('fit').addEventListener('click', function () { setBox(home.slice()); });
  document.addEventListener('keydown', function (e) {
    var cx = box[0] + box[2] / 2, cy = box[1] + box[3] / 2;
    if (e.key === '+' || e.key === '=') zoom(0.8, cx, cy);
    else if (e.key === '-') zoom(1.25, cx, cy);
    else if (e.key === '0') setBox(home.slice());
  });
  show();
})();
"#;

/// The route over `nest` as a standalone HTML page.
pub fn route_html(
    nest: &Nest,
    route: &Route,
    options: &HtmlOptions,
) -> Result<String, HtmlExportError> {
    let toolpath = Toolpath::new(route, nest)?;
    let labels: Vec<String> = route
        .steps
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let name = nest
                .parts
                .get(s.contour.part)
                .map_or("?", |p| p.name.as_str());
            format!("Step {}: {} ({name})", k + 1, s.contour)
        })
        .collect();
    Ok(toolpath_html(nest, &toolpath, &labels, options))
}

/// `toolpath` over `nest` as a standalone HTML page; `step_labels[k]` (when present) is shown
/// as the tooltip of step `k`'s pierce point.
pub fn toolpath_html(
    nest: &Nest,
    toolpath: &Toolpath,
    step_labels: &[String],
    options: &HtmlOptions,
) -> String {
    let machine = &options.machine;
    let clock = ToolClock::new(toolpath, machine);
    let BoundingBox { min: lo, max: hi } = extent(nest, toolpath);
    let side = (hi.x - lo.x).max(hi.y - lo.y).max(1e-9);
    let margin = side * options.margin.max(0.0);
    let marker = side * options.marker_radius.max(0.0);
    // The drawing sits in a y-flipped group, so the view box spans −max.y … −min.y.
    let view_box = format!(
        "{} {} {} {}",
        num(lo.x - margin),
        num(-(hi.y + margin)),
        num(hi.x - lo.x + 2.0 * margin),
        num(hi.y - lo.y + 2.0 * margin)
    );
    let title = escape(&options.title);
    let mut out = String::with_capacity(4096 + 200 * toolpath.moves.len());
    out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n");
    let _ = writeln!(out, "<title>{title}</title>");
    let _ = writeln!(
        out,
        "<style>/*<![CDATA[*/{STYLE}/*]]>*/</style>\n</head>\n<body>"
    );
    let _ = writeln!(out, "<header>\n<h1>{title}</h1>\n<dl id=\"stats\">");
    let stats = [
        (
            "idle-length",
            "Idle",
            format!("{:.1} mm", toolpath.idle_length()),
        ),
        (
            "cut-length",
            "Cut",
            format!("{:.1} mm", toolpath.cut_length()),
        ),
        ("pierces", "Pierces", toolpath.pierce_count().to_string()),
        ("machine-time", "Time", format!("{:.1} s", clock.total())),
    ];
    for (id, name, value) in stats {
        let _ = writeln!(
            out,
            "<div><dt>{name}</dt><dd id=\"{id}\">{value}</dd></div>"
        );
    }
    out.push_str("</dl>\n<div id=\"controls\">\n");
    out.push_str("<button id=\"anim-play\" type=\"button\">Play</button>\n");
    out.push_str("<label>Time <input id=\"anim-scrub\" type=\"range\" min=\"0\" max=\"1000\" value=\"0\"/></label>\n");
    out.push_str("<label>Speed <select id=\"anim-speed\">");
    for speed in [1, 2, 5, 10, 20, 50, 100] {
        let _ = write!(out, "<option value=\"{speed}\">×{speed}</option>");
    }
    out.push_str("</select></label>\n<span id=\"clock\"></span>\n");
    out.push_str("<button id=\"fit\" type=\"button\">Fit</button>\n</div>\n</header>\n");
    let _ = writeln!(
        out,
        "{}",
        drawing(nest, toolpath, step_labels, options, view_box, marker)
    );
    let _ = writeln!(
        out,
        "<script type=\"application/json\" id=\"route-data\">{}</script>",
        samples_json(toolpath, &clock)
    );
    let _ = writeln!(
        out,
        "<script>//<![CDATA[{SCRIPT}//]]></script>\n</body>\n</html>"
    );
    out
}

/// The SVG drawing of the page (built with the `svg` crate, like every SVG the project writes):
/// the nest, then the route in a y-flipped group, with the head the script moves.
fn drawing(
    nest: &Nest,
    toolpath: &Toolpath,
    step_labels: &[String],
    options: &HtmlOptions,
    view_box: String,
    marker: f64,
) -> Document {
    let mut doc = Document::new()
        .set("id", "view")
        .set("viewBox", view_box)
        .set("data-playback-s", rounded(options.playback_s.max(0.1)))
        .set("role", "img")
        .set("aria-label", options.title.as_str());
    // Inline SVG in HTML needs no namespace, and the page names no URL at all.
    doc.get_attributes_mut().remove("xmlns");
    let mut parts = Group::new().set("class", "nest");
    for (part, class) in nest
        .sheet
        .iter()
        .map(|p| (p, "sheet"))
        .chain(nest.parts.iter().map(|p| (p, "part")))
    {
        let mut data = PathData::new();
        for contour in &part.contours {
            let mut spans = contour.spans().peekable();
            if let Some(first) = spans.peek() {
                data = data.move_to(xy(first.start));
            }
            for span in spans {
                data = span_data(data, at(span.start), at(span.end), span.bulge);
            }
            data = data.close();
        }
        parts = parts.add(
            Path::new()
                .set("class", class)
                .set("d", data)
                .add(Title::new(part.name.as_str())),
        );
    }
    let mut route = route_paths(Group::new().set("class", "route"), toolpath);
    let circle = |class: &str, p: Point, r: f64| {
        Circle::new()
            .set("class", class)
            .set("cx", rounded(p.x))
            .set("cy", rounded(p.y))
            .set("r", rounded(r))
    };
    for m in &toolpath.moves {
        if let ToolMove::Pierce { at, step } = m {
            let label = step_labels
                .get(*step)
                .cloned()
                .unwrap_or_else(|| format!("Step {}", step + 1));
            route = route.add(
                circle("pierce", *at, marker)
                    .set("data-step", step + 1)
                    .add(Title::new(label)),
            );
        }
    }
    let start = toolpath.start;
    route = route.add(circle("start", start, 1.5 * marker).add(Title::new("Start")));
    if matches!(toolpath.moves.last(), Some(ToolMove::Idle { .. })) {
        route = route.add(circle("finish", toolpath.end(), 1.5 * marker).add(Title::new("Finish")));
    }
    let head = Circle::new()
        .set("id", "tool-head")
        .set("cx", rounded(start.x))
        .set("cy", rounded(start.y))
        .set("r", rounded(2.0 * marker))
        .set("data-machine-time", 0);
    doc.add(
        Group::new()
            .set("transform", "scale(1,-1)")
            .add(parts)
            .add(route.add(head)),
    )
}

/// Consecutive moves of one kind form one `<path>`, so a contour's cut is a single element.
fn route_paths(mut group: Group, toolpath: &Toolpath) -> Group {
    let mut idle = PathData::new();
    let mut cut: Option<(usize, PathData)> = None;
    let finish = |group: Group, cut: Option<(usize, PathData)>| match cut {
        Some((step, data)) => group.add(
            Path::new()
                .set("class", "cut")
                .set("data-step", step + 1)
                .set("d", data),
        ),
        None => group,
    };
    for m in &toolpath.moves {
        match *m {
            ToolMove::Idle { from, to } => idle = idle.move_to(xy(from)).line_to(xy(to)),
            ToolMove::Pierce { .. } => {}
            ToolMove::Cut { step, span, .. } => {
                let data = match cut.take() {
                    Some((s, data)) if s == step => data,
                    other => {
                        group = finish(group, other);
                        PathData::new().move_to(xy(span.start))
                    }
                };
                cut = Some((
                    step,
                    span_data(data, at(span.start), at(span.end), span.bulge),
                ));
            }
        }
    }
    group = finish(group, cut);
    if !idle.is_empty() {
        group = group.add(Path::new().set("class", "idle").set("d", idle));
    }
    group
}

/// A coordinate to a micrometre, as the page draws it (its text stays small); non-finite values
/// (never in a valid nest) as 0 so the document stays well-formed.
fn rounded(v: f64) -> f64 {
    if !v.is_finite() {
        return 0.0;
    }
    let r = (v * 1000.0).round() / 1000.0;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

fn at(p: Point) -> Point {
    Point::new(rounded(p.x), rounded(p.y))
}

fn xy(p: Point) -> (f64, f64) {
    (rounded(p.x), rounded(p.y))
}

/// The head's positions over machine time as `[[t, x, y], …]`: move ends, with arcs sampled
/// every 1/16 of a half turn so the head follows the curve.
fn samples_json(toolpath: &Toolpath, clock: &ToolClock) -> String {
    let mut out = String::from("[");
    let mut push = |t: f64, p: Point| {
        if out.len() > 1 {
            out.push(',');
        }
        let _ = write!(out, "[{},{},{}]", num(t), num(p.x), num(p.y));
    };
    push(0.0, toolpath.start);
    for (i, m) in toolpath.moves.iter().enumerate() {
        let (Some(begin), Some(end)) = (clock.start_of(i), clock.start_of(i + 1)) else {
            continue;
        };
        let pieces = match m {
            ToolMove::Cut { span, .. } if !span.is_line() => {
                ((span.sweep().abs() / (std::f64::consts::PI / 16.0)).ceil() as usize).clamp(1, 64)
            }
            _ => 1,
        };
        for k in 1..=pieces {
            let f = k as f64 / pieces as f64;
            push(begin + (end - begin) * f, m.point_at(f));
        }
    }
    out.push(']');
    out
}

fn extent(nest: &Nest, toolpath: &Toolpath) -> BoundingBox {
    crate::svg_export::drawing_extent(
        nest,
        std::iter::once(toolpath.start).chain(toolpath.moves.iter().map(ToolMove::end)),
    )
}

/// A coordinate with at most three decimals; non-finite values (never in a valid nest) as 0 so
/// the document stays well-formed.
fn num(v: f64) -> String {
    if !v.is_finite() {
        return "0".into();
    }
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// Text and attribute escaping for HTML and XML alike.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c if c.is_control() && c != '\n' && c != '\t' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, ContourRef, CutStep, Part, Vertex};

    /// A plate with a round hole; the hole is cut first, then the outline.
    fn plate() -> (Nest, Route) {
        let square = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, 100.0),
            Vertex::line(100.0, 100.0),
            Vertex::line(100.0, 0.0),
        ]);
        let hole = Contour::circle(Point::new(50.0, 50.0), 20.0, false);
        let nest = Nest {
            sheet: None,
            parts: vec![Part {
                name: "plate <A&B>".into(),
                contours: vec![square, hole],
            }],
        };
        let step = |contour: usize, x: f64, y: f64| {
            CutStep::pierced(ContourRef { part: 0, contour }, Point::new(x, y))
        };
        let route = Route {
            start: Point::new(-10.0, -10.0),
            steps: vec![step(1, 70.0, 50.0), step(0, 100.0, 50.0)],
            finish: Some(Point::new(-10.0, -10.0)),
        };
        (nest, route)
    }

    #[test]
    fn the_page_is_well_formed_standalone_and_holds_the_route() {
        let (nest, route) = plate();
        let html = route_html(&nest, &route, &HtmlOptions::default()).unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"));
        // Nothing external: no URL, no src attribute, no link element.
        for needle in ["http", "src=", "<link", "url("] {
            assert!(!html.contains(needle), "{needle} in the page");
        }
        let options = roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        };
        let doc = roxmltree::Document::parse_with_options(&html, options)
            .unwrap_or_else(|e| panic!("not well-formed: {e}"));
        let by_id = |id: &str| {
            doc.descendants()
                .find(|n| n.attribute("id") == Some(id))
                .unwrap_or_else(|| panic!("no #{id}"))
        };
        // Both contours are cut (two cut paths), with one idle path and two pierce markers.
        let class = |c: &str| {
            doc.descendants()
                .filter(|n| n.attribute("class") == Some(c))
                .count()
        };
        assert_eq!(class("cut"), 2);
        assert_eq!(class("idle"), 1);
        assert_eq!(class("pierce"), 2);
        assert_eq!(class("part"), 1);
        let pierce = doc
            .descendants()
            .find(|n| n.attribute("class") == Some("pierce"))
            .unwrap();
        assert_eq!(pierce.attribute("cx"), Some("70"));
        // The part name is escaped and survives.
        assert!(doc.descendants().any(|n| n.text() == Some("plate <A&B>")));
        // The numbers: idle = |start→(70,50)| + |(70,50)→(100,50)| + |(100,50)→start|.
        let idle = 80f64.hypot(60.0) + 30.0 + 110f64.hypot(60.0);
        assert_eq!(
            by_id("idle-length").text(),
            Some(format!("{idle:.1} mm").as_str())
        );
        let cut = 400.0 + 40.0 * std::f64::consts::PI;
        assert_eq!(
            by_id("cut-length").text(),
            Some(format!("{cut:.1} mm").as_str())
        );
        assert_eq!(by_id("pierces").text(), Some("2"));
        let machine = MachineParameters::default();
        let time = machine.time(cut, idle, 2);
        assert_eq!(
            by_id("machine-time").text(),
            Some(format!("{time:.1} s").as_str())
        );
        // The animation data ends at the finish at the total machine time.
        let samples: Vec<[f64; 3]> = by_id("route-data")
            .text()
            .unwrap()
            .trim_matches(|c| c == '[' || c == ']')
            .split("],[")
            .map(|row| {
                let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        let last = samples.last().unwrap();
        assert!((last[0] - time).abs() < 1e-3 && last[1] == -10.0 && last[2] == -10.0);
        assert!(
            samples.windows(2).all(|w| w[1][0] >= w[0][0]),
            "time runs forward"
        );
        // The animation controls of the app's contract.
        for id in ["anim-play", "anim-scrub", "anim-speed", "tool-head", "view"] {
            by_id(id);
        }
    }

    #[test]
    fn routes_that_do_not_fit_are_refused() {
        let (nest, mut route) = plate();
        route.steps[1].contour.contour = 9;
        assert!(matches!(
            route_html(&nest, &route, &HtmlOptions::default()),
            Err(HtmlExportError::Route(RouteError::UnknownContour {
                step: 1,
                ..
            }))
        ));
    }
}
