//! DXF as CAD programs write it: comment groups anywhere, bytes after `0 EOF`, units the
//! reader does not know, geometry only in a paper-space layout block, planes tilted out of XY.

use cutroute_cad::dxf::{read_dxf, DxfImport, DxfOptions};
use cutroute_geometry::{BoundingBox, WarningKind};

fn read(text: &str) -> DxfImport {
    read_dxf(text.as_bytes(), &DxfOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn bbox(import: &DxfImport) -> BoundingBox {
    import
        .nest
        .parts
        .iter()
        .flat_map(|p| &p.contours)
        .fold(BoundingBox::EMPTY, |b, c| b.union(c.bounding_box()))
}

const CIRCLE: &str = "0\r\nCIRCLE\r\n8\r\n0\r\n10\r\n5\r\n20\r\n5\r\n40\r\n2\r\n";

#[test]
fn comments_anywhere_and_bytes_after_eof_are_no_part_of_the_drawing() {
    let text = format!(
        "999\r\ndxflib 2.0.4.8\r\n0\r\nSECTION\r\n999\r\n\r\n2\r\nENTITIES\r\n{CIRCLE}\
         999\r\na comment between entities\r\n0\r\nENDSEC\r\n0\r\nEOF\r\n\x1a trailing text"
    );
    let import = read(&text);
    assert_eq!(import.nest.parts.len(), 1);
    let b = bbox(&import);
    assert!((b.width() - 4.0).abs() < 1e-9 && (b.min.x - 3.0).abs() < 1e-9);
}

#[test]
fn unknown_and_missing_units_are_millimetres_with_a_warning() {
    for (header, said) in [
        ("9\n$INSUNITS\n70\n99\n", "$INSUNITS = 99"),
        ("9\n$INSUNITS\n70\n0\n", "no units"),
        ("9\n$ACADVER\n1\nAC1015\n", "no units"),
    ] {
        let text = format!(
            "0\nSECTION\n2\nHEADER\n{header}0\nENDSEC\n0\nSECTION\n2\nENTITIES\n{CIRCLE}0\nENDSEC\n0\nEOF\n"
        );
        let import = read(&text);
        assert!((bbox(&import).width() - 4.0).abs() < 1e-9);
        let units: Vec<_> = import
            .warnings
            .iter()
            .filter(|w| w.kind == WarningKind::Units)
            .collect();
        assert_eq!(units.len(), 1, "{header}: {:?}", import.warnings);
        assert!(units[0].message.contains(said), "{}", units[0]);
        assert!(
            units[0].message.contains("millimetres assumed"),
            "{}",
            units[0]
        );
    }
}

#[test]
fn a_layout_block_is_read_only_when_model_space_draws_nothing() {
    let blocks = format!(
        "0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n2\n*Paper_Space0\n10\n0\n20\n0\n{CIRCLE}0\nENDBLK\n0\nENDSEC\n"
    );
    let text =
        |entities: &str| format!("{blocks}0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n");
    let paper = read(&text("0\nTEXT\n8\n0\n10\n0\n20\n0\n1\nnote\n"));
    assert_eq!(paper.nest.parts.len(), 1);
    assert!(paper
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::PaperSpace && w.message.contains("paper-space")));
    // With a square in model space, the layout's circle is not read.
    let square = "0\nLWPOLYLINE\n8\n0\n70\n1\n10\n20\n20\n0\n10\n30\n20\n0\n10\n30\n20\n10\n10\n20\n20\n10\n";
    let model = read(&text(square));
    assert_eq!(model.nest.parts.len(), 1);
    assert!((bbox(&model).min.x - 20.0).abs() < 1e-9);
    assert!(model
        .warnings
        .iter()
        .all(|w| w.kind != WarningKind::PaperSpace));
}

#[test]
fn a_circle_in_a_tilted_plane_is_read_as_seen_from_above() {
    // Normal (0, 0.6, 0.8): the plane is tilted about the x axis, so a circle of radius 2 shows
    // as an ellipse 4 wide and 4 · 0.8 high.
    let text = "0\nSECTION\n2\nENTITIES\n0\nCIRCLE\n8\n0\n10\n0\n20\n0\n40\n2\n210\n0\n220\n0.6\n230\n0.8\n0\nENDSEC\n0\nEOF\n";
    let import = read(text);
    let b = bbox(&import);
    let tolerance = DxfOptions::default().approximation_tolerance;
    assert!((b.width() - 4.0).abs() <= 2.0 * tolerance, "{b:?}");
    assert!((b.height() - 3.2).abs() <= 2.0 * tolerance, "{b:?}");
}
