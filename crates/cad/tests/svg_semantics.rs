//! What the SVG reader makes of viewports, styles, `<use>` and units, on small drawings whose
//! geometry is known: nested `<svg>` viewports with viewBox and preserveAspectRatio,
//! `display`/`visibility` from attributes, `style` and `<style>`, `<use>` of elements and
//! symbols, and the units of the root.

use cutroute_cad::svg::{read_svg, SvgImport, SvgOptions};
use cutroute_geometry::{BoundingBox, WarningKind};

fn read(svg: &str) -> SvgImport {
    read_svg(svg.as_bytes(), &SvgOptions::default()).unwrap_or_else(|e| panic!("{e}\n{svg}"))
}

/// A drawing of `size` mm square whose user unit is the millimetre.
fn mm(size: f64, body: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
            width="{size}mm" height="{size}mm" viewBox="0 0 {size} {size}">{body}</svg>"#
    )
}

/// The boxes of the outer contours, in file order, as (x0, y0, x1, y1) in SVG's y-down frame.
fn boxes(import: &SvgImport) -> Vec<[f64; 4]> {
    import
        .nest
        .parts
        .iter()
        .map(|p| {
            let BoundingBox { min, max } = p.contours[0].bounding_box();
            [min.x, -max.y, max.x, -min.y]
        })
        .collect()
}

fn assert_box(got: [f64; 4], want: [f64; 4]) {
    assert!(
        got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-6),
        "box {got:?}, expected {want:?}"
    );
}

#[test]
fn a_part_in_a_nested_view_box_keeps_its_size() {
    // 100 × 100 mm drawn in a nested viewport whose viewBox is in tenths of a millimetre.
    let import = read(&mm(
        300.0,
        r#"<svg x="50" y="20" width="100" height="100" viewBox="0 0 1000 1000">
             <rect x="0" y="0" width="1000" height="1000"/></svg>"#,
    ));
    assert_eq!(import.nest.parts.len(), 1);
    assert_box(boxes(&import)[0], [50.0, 20.0, 150.0, 120.0]);
    // A viewBox that does not start at 0 moves the content by its origin.
    let import = read(&mm(
        300.0,
        r#"<svg x="10" y="10" width="40" height="40" viewBox="100 100 20 20">
             <rect x="100" y="105" width="20" height="10"/></svg>"#,
    ));
    assert_box(boxes(&import)[0], [10.0, 20.0, 50.0, 40.0]);
}

#[test]
fn preserve_aspect_ratio_aligns_meets_slices_and_stretches() {
    // A 200 × 100 viewport showing a 10 × 10 viewBox filled by a square.
    let case = |aspect: &str| {
        let import = read(&mm(
            400.0,
            &format!(
                r#"<svg width="200" height="100" viewBox="0 0 10 10" preserveAspectRatio="{aspect}">
                     <rect width="10" height="10"/></svg>"#
            ),
        ));
        boxes(&import)[0]
    };
    assert_box(case("xMidYMid meet"), [50.0, 0.0, 150.0, 100.0]);
    assert_box(case(""), [50.0, 0.0, 150.0, 100.0]); // the default
    assert_box(case("xMinYMin"), [0.0, 0.0, 100.0, 100.0]);
    assert_box(case("xMaxYMax meet"), [100.0, 0.0, 200.0, 100.0]);
    assert_box(case("xMidYMid slice"), [0.0, -50.0, 200.0, 150.0]);
    assert_box(case("xMinYMax slice"), [0.0, -100.0, 200.0, 100.0]);
    assert_box(case("none"), [0.0, 0.0, 200.0, 100.0]);
}

#[test]
fn a_viewport_of_zero_size_draws_nothing_and_says_so() {
    let import = read(&mm(
        100.0,
        r#"<rect width="10" height="10"/>
           <svg width="0" height="50" viewBox="0 0 1 1"><rect width="1" height="1"/></svg>"#,
    ));
    assert_eq!(import.nest.parts.len(), 1);
    assert!(import
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::Hidden && w.message.contains("zero width")));
}

#[test]
fn display_none_hides_as_attribute_style_and_style_sheet_with_a_warning_that_carries_it() {
    let import = read(&mm(
        200.0,
        r##"<style>.off { display: none } #gone { display: none } rect.keep { display: inline }</style>
           <rect x="0" width="10" height="10"/>
           <rect x="20" width="10" height="10" display="none"/>
           <rect x="40" width="10" height="10" style="display:none"/>
           <rect x="60" width="10" height="10" style="fill: red; display : none ;"/>
           <rect x="80" width="10" height="10" class="off"/>
           <rect x="100" width="10" height="10" id="gone"/>
           <rect x="120" width="10" height="10" display="none" style="display: inline"/>
           <rect x="140" width="10" height="10" class="off keep"/>
           <g style="display:none"><rect x="160" width="10" height="10" style="display:inline"/></g>"##,
    ));
    let xs: Vec<f64> = boxes(&import).iter().map(|b| b[0]).collect();
    assert_eq!(xs, [0.0, 120.0, 140.0]);
    let hidden: Vec<_> = import
        .warnings
        .iter()
        .filter(|w| w.kind == WarningKind::Hidden)
        .collect();
    assert_eq!(hidden.len(), 6, "{hidden:#?}");
    for w in hidden {
        assert!(w.place.is_some(), "{w}");
        assert_eq!(w.left_out.len(), 1, "{w}");
        assert!((w.length_mm.unwrap() - 40.0).abs() < 1e-9, "{w}");
    }
}

#[test]
fn visibility_is_inherited_and_a_child_may_be_visible_again() {
    let import = read(&mm(
        200.0,
        r#"<g visibility="hidden">
             <rect x="0" width="10" height="10"/>
             <rect x="20" width="10" height="10" style="visibility: visible"/>
             <g><rect x="40" width="10" height="10"/></g>
           </g>
           <rect x="60" width="10" height="10" style="visibility:collapse"/>"#,
    ));
    let xs: Vec<f64> = boxes(&import).iter().map(|b| b[0]).collect();
    assert_eq!(xs, [20.0]);
    let hidden: Vec<_> = import
        .warnings
        .iter()
        .filter(|w| w.kind == WarningKind::Hidden)
        .collect();
    assert_eq!(hidden.len(), 2);
    assert!(hidden[0].message.contains("2 shapes"), "{}", hidden[0]);
}

#[test]
fn a_style_rule_that_is_not_understood_is_a_warning() {
    let import = read(&mm(
        100.0,
        r#"<style>g > rect { display: none } .a { fill: none }</style>
           <g><rect width="10" height="10" class="a"/></g>"#,
    ));
    assert_eq!(import.nest.parts.len(), 1);
    assert!(import
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::Other && w.message.contains("g > rect")));
}

#[test]
fn use_draws_its_element_at_x_y_under_its_transform() {
    let import = read(&mm(
        200.0,
        r##"<defs><rect id="r" width="10" height="5"/></defs>
           <use href="#r" x="20" y="30"/>
           <use xlink:href="#r" x="5" transform="translate(100 0) scale(2)"/>"##,
    ));
    let mut b = boxes(&import);
    b.sort_by(|p, q| p[0].total_cmp(&q[0]));
    assert_eq!(b.len(), 2);
    assert_box(b[0], [20.0, 30.0, 30.0, 35.0]);
    assert_box(b[1], [110.0, 0.0, 130.0, 10.0]);
}

#[test]
fn use_of_a_symbol_fits_its_view_box_into_the_use_size() {
    let import = read(&mm(
        200.0,
        r##"<symbol id="s" viewBox="0 0 1 1"><circle cx="0.5" cy="0.5" r="0.5"/></symbol>
           <use href="#s" x="10" y="10" width="40" height="40"/>"##,
    ));
    let b = boxes(&import);
    assert_eq!(b.len(), 1, "the symbol itself is not drawn");
    assert_box(b[0], [10.0, 10.0, 50.0, 50.0]);
}

#[test]
fn use_cycles_and_missing_targets_are_reported() {
    let cycle = mm(
        100.0,
        r##"<g id="a"><rect width="1" height="1"/><use href="#a"/></g>"##,
    );
    let e = read_svg(cycle.as_bytes(), &SvgOptions::default()).unwrap_err();
    assert!(e.to_string().contains("cycle"), "{e}");
    let missing = read(&mm(
        100.0,
        r##"<rect width="1" height="1"/><use href="#nowhere"/><use href="other.svg#x"/>"##,
    ));
    let skipped = missing
        .warnings
        .iter()
        .filter(|w| w.kind == WarningKind::Skipped)
        .count();
    assert_eq!(skipped, 2);
    // A tree of uses that doubles at each level stays bounded (and draws nothing).
    let mut body = String::from(r#"<defs><g id="l0"><line x2="1"/></g>"#);
    for k in 1..40 {
        let j = k - 1;
        body.push_str(&format!(
            r##"<g id="l{k}"><use href="#l{j}"/><use href="#l{j}"/></g>"##
        ));
    }
    body.push_str(r##"</defs><use href="#l39"/><rect width="1" height="1"/>"##);
    let options = SvgOptions {
        max_spans: 10_000,
        ..SvgOptions::default()
    };
    assert!(read_svg(mm(100.0, &body).as_bytes(), &options).is_err());
}

#[test]
fn units_of_lengths_and_of_the_root() {
    // Lengths inside the drawing: absolute units at 96 px per inch, % of the viewport.
    let import = read(&mm(
        200.0,
        r#"<rect width="1in" height="10mm"/><rect x="50%" width="10%" height="2.54cm"/>
           <circle cx="100" cy="150" r="1em" style="font-size: 5px"/>"#,
    ));
    let b = boxes(&import);
    assert_box(b[0], [0.0, 0.0, 96.0, 10.0 * 96.0 / 25.4]);
    assert_box(b[1], [100.0, 0.0, 120.0, 96.0]);
    assert_box(b[2], [95.0, 145.0, 105.0, 155.0]);
    // Root sizes: width/height over the viewBox, the smaller factor by default.
    let root = |attributes: &str| {
        read(&format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" {attributes}><rect width="10" height="10"/></svg>"#
        ))
    };
    let side = |import: &SvgImport| {
        let b = boxes(import)[0];
        (b[2] - b[0], b[3] - b[1])
    };
    let px = 25.4 / 96.0;
    let cases = [
        (
            r#"width="20mm" height="20mm" viewBox="0 0 10 10""#,
            (20.0, 20.0),
            false,
        ),
        (
            r#"width="2cm" height="4cm" viewBox="0 0 10 10""#,
            (20.0, 20.0),
            false,
        ),
        (
            r#"width="2cm" height="4cm" viewBox="0 0 10 10" preserveAspectRatio="none""#,
            (20.0, 40.0),
            false,
        ),
        (r#"width="72pt" viewBox="0 0 10 10""#, (25.4, 25.4), false),
        (
            r#"width="100mm" height="50mm""#,
            (10.0 * px, 10.0 * px),
            false,
        ),
        (r#"viewBox="0 0 10 10""#, (10.0 * px, 10.0 * px), true),
        (
            r#"width="100%" height="100%" viewBox="0 0 10 10""#,
            (10.0 * px, 10.0 * px),
            true,
        ),
        (
            r#"width="40" height="40" viewBox="0 0 10 10""#,
            (40.0 * px, 40.0 * px),
            true,
        ),
        ("", (10.0 * px, 10.0 * px), true),
    ];
    for (attributes, (w, h), warned) in cases {
        let import = root(attributes);
        let (gw, gh) = side(&import);
        assert!(
            (gw - w).abs() < 1e-9 && (gh - h).abs() < 1e-9,
            "{attributes}: {gw} × {gh}, expected {w} × {h}"
        );
        let units = import.warnings.iter().any(|w| w.kind == WarningKind::Units);
        assert_eq!(units, warned, "{attributes}: {:?}", import.warnings);
    }
    // Inkscape before 0.92 drew 90 pixels to the inch; later versions 96.
    let inkscape = |version: &str| {
        read(&format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
                inkscape:version="{version}" width="210mm" height="297mm"><rect width="90" height="90"/></svg>"#
        ))
    };
    let legacy = inkscape("0.48.3.1 r9886");
    assert!((side(&legacy).0 - 25.4).abs() < 1e-9);
    assert!(legacy.warnings.iter().any(|w| w.kind == WarningKind::Units));
    assert!((side(&inkscape("1.0 (4035a4f, 2020-05-01)")).0 - 90.0 * px).abs() < 1e-9);
    // Cutroute's own export is drawn in millimetres.
    let own = root(r#"class="cutroute-nest" viewBox="0 -20 20 20""#);
    assert_eq!(side(&own), (10.0, 10.0));
    assert!(own.warnings.is_empty());
}

#[test]
fn text_and_clipping_are_told() {
    let import = read(&mm(
        100.0,
        r#"<text x="1" y="1">A</text><text>B</text>
           <rect width="10" height="10" clip-path="url(#c)"/>"#,
    ));
    let skipped: Vec<_> = import
        .warnings
        .iter()
        .filter(|w| w.kind == WarningKind::Skipped)
        .collect();
    assert_eq!(skipped.len(), 1);
    assert!(
        skipped[0].message.starts_with("2 <text> elements"),
        "{}",
        skipped[0]
    );
    assert!(import
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::Other && w.message.contains("clip-path")));
}

#[test]
fn switch_draws_its_first_child_that_applies() {
    let import = read(&mm(
        100.0,
        r#"<switch>
             <foreignObject requiredExtensions="http://ns.adobe.com/AdobeIllustrator/10.0/"/>
             <g><rect width="10" height="10"/></g>
             <rect x="50" width="10" height="10"/>
           </switch>"#,
    ));
    assert_eq!(boxes(&import).len(), 1);
    assert_box(boxes(&import)[0], [0.0, 0.0, 10.0, 10.0]);
}
