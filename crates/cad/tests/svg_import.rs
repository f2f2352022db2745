//! SVG import as the app's own export writes it: a part is one `<path>` with its outer contour
//! and holes as subpaths.

use cutroute_cad::svg::{read_svg, SvgOptions};

/// Holes of equal area keep their file order. Before the importers took areas from
/// `cutroute-geometry` (about the contour's first vertex), the area about (0, 0) differed in
/// the last bits between equal circles at different places, and sorting by it shuffled them:
/// this very part came back as the holes at x = 72, 197, 322.
#[test]
fn equal_holes_keep_their_file_order() {
    let circle = |x: f64, y: f64| {
        format!(
            "M{x},{y} A63,63,0,0,1,{},{} A63,63,0,0,1,{},{y} A63,63,0,0,1,{},{} A63,63,0,0,1,{x},{y} z",
            x + 63.0,
            y - 63.0,
            x + 126.0,
            x + 63.0,
            y + 63.0
        )
    };
    let d = format!(
        "M510,575 V10 H10 V575 H510 z {} {} {}",
        circle(322.0, 470.0),
        circle(72.0, 470.0),
        circle(197.0, 210.0)
    );
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 600 600"><path d="{d}"/></svg>"#
    );
    let options = SvgOptions {
        user_unit_mm: Some(1.0),
        ..SvgOptions::default()
    };
    let import = read_svg(svg.as_bytes(), &options).unwrap();
    assert_eq!(import.nest.parts.len(), 1);
    let centres: Vec<f64> = import.nest.parts[0].contours[1..]
        .iter()
        .map(|c| c.bounding_box().centre().x)
        .collect();
    assert_eq!(centres.len(), 3);
    for (got, want) in centres.iter().zip([385.0, 135.0, 260.0]) {
        assert!((got - want).abs() < 1e-9, "hole centres {centres:?}");
    }
}
