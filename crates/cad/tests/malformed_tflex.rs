//! Hostile and broken T-FLEX projects: typed errors with element paths and positions.

use cutroute_cad::tflex::{read_tfnesting, read_tfnesting_project, TflexError};

const LINE: &str = r#"<ContourObject xsi:type="ContourLine"><Begin><X>{x0}</X><Y>{y0}</Y></Begin><End><X>{x1}</X><Y>{y1}</Y></End></ContourObject>"#;

fn line(x0: f64, y0: f64, x1: f64, y1: f64) -> String {
    LINE.replace("{x0}", &x0.to_string())
        .replace("{y0}", &y0.to_string())
        .replace("{x1}", &x1.to_string())
        .replace("{y1}", &y1.to_string())
}

fn square_objects() -> String {
    [
        line(0.0, 0.0, 0.0, 10.0),
        line(0.0, 10.0, 10.0, 10.0),
        line(10.0, 10.0, 10.0, 0.0),
        line(10.0, 0.0, 0.0, 0.0),
    ]
    .concat()
}

/// A project with one part (given contour XML), one 100 × 100 sheet and the given placements.
fn project(contour: &str, placements: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<Project xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
  <Parts><PartDefinition><PartProfile><Contours>{contour}</Contours></PartProfile><Name>P</Name><ID>7</ID></PartDefinition></Parts>
  <Sheets><SheetDefinition xsi:type="RectangularSheet"><ID>1</ID><Name>S</Name><Width>100</Width><Length>100</Length></SheetDefinition></Sheets>
  <Results><NestingResult><Layouts><SheetLayout><SheetID>1</SheetID><SheetIndex>0</SheetIndex><PartPositions>{placements}</PartPositions></SheetLayout></Layouts></NestingResult></Results>
</Project>"#
    )
}

fn figure(objects: &str) -> String {
    format!(
        r#"<Contour xsi:type="FigureContour"><Orientation>Positive</Orientation><Objects>{objects}</Objects></Contour>"#
    )
}

fn placement(part: i64, x: &str) -> String {
    format!("<PartPosition><AngleDeg>90</AngleDeg><Inverted>true</Inverted><Position><X>{x}</X><Y>5</Y></Position><PartID>{part}</PartID></PartPosition>")
}

#[test]
fn a_minimal_project_reads() {
    let text = project(&figure(&square_objects()), &placement(7, "50"));
    let p = read_tfnesting_project(text.as_bytes()).unwrap();
    assert_eq!(p.layouts.len(), 1);
    let nest = &p.layouts[0].nest;
    assert_eq!(nest.parts.len(), 1);
    // Mirrored (x ↦ −x) then turned 90° CCW: (x, y) ↦ (−y, −x), then moved to (50, 5).
    let xs: Vec<f64> = nest.parts[0].contours[0]
        .vertices
        .iter()
        .map(|v| v.point.x)
        .collect();
    let ys: Vec<f64> = nest.parts[0].contours[0]
        .vertices
        .iter()
        .map(|v| v.point.y)
        .collect();
    assert!(
        xs.iter().all(|&x| (40.0 - 1e-9..=50.0 + 1e-9).contains(&x)),
        "{xs:?}"
    );
    assert!(
        ys.iter().all(|&y| (-5.0 - 1e-9..=5.0 + 1e-9).contains(&y)),
        "{ys:?}"
    );
}

#[test]
fn encoding_and_xml_errors_are_located() {
    assert_eq!(
        read_tfnesting(b"<Project>\xff</Project>"),
        Err(TflexError::NotUtf8 { byte: 9 })
    );
    let text = project(&figure(&square_objects()), &placement(7, "50"));
    let truncated = &text[..text.len() / 2];
    let err = read_tfnesting(truncated.as_bytes()).unwrap_err();
    assert!(
        matches!(err, TflexError::Xml { line, .. } if line >= 3),
        "{err}"
    );
    assert!(
        matches!(read_tfnesting(b"<Nest/>"), Err(TflexError::NotAProject { ref found }) if found == "Nest")
    );
    let err = read_tfnesting(b"<Project><Sheets/></Project>").unwrap_err();
    assert_eq!(
        err,
        TflexError::MissingElement {
            path: "/Project".into(),
            element: "Parts",
            line: 1,
            column: 1
        }
    );
}

#[test]
fn bad_numbers_name_their_element() {
    for bad in ["abc", "NaN", "inf", "1e300"] {
        let text = project(&figure(&square_objects()), &placement(7, bad));
        let err = read_tfnesting(text.as_bytes()).unwrap_err();
        let TflexError::BadValue { path, line, .. } = &err else {
            panic!("{err}")
        };
        assert_eq!(path, "/Project/Results/NestingResult/Layouts/SheetLayout/PartPositions/PartPosition/Position/X");
        assert_eq!(*line, 5);
    }
    let text = project(
        &figure(&square_objects()),
        &placement(7, "5").replace("true", "maybe"),
    );
    assert!(matches!(
        read_tfnesting(text.as_bytes()),
        Err(TflexError::BadValue {
            expected: "true or false",
            ..
        })
    ));
}

#[test]
fn missing_references() {
    let text = project(&figure(&square_objects()), &placement(99, "5"));
    let err = read_tfnesting(text.as_bytes()).unwrap_err();
    assert!(
        matches!(
            err,
            TflexError::UnknownReference {
                what: "part",
                id: 99,
                ..
            }
        ),
        "{err}"
    );
    let text = project(&figure(&square_objects()), "")
        .replace("<SheetID>1</SheetID>", "<SheetID>3</SheetID>");
    assert!(matches!(
        read_tfnesting(text.as_bytes()),
        Err(TflexError::UnknownReference {
            what: "sheet",
            id: 3,
            ..
        })
    ));
}

#[test]
fn broken_geometry() {
    // Unknown contour type.
    let text = project(r#"<Contour xsi:type="Spiral"/>"#, "");
    assert!(
        matches!(read_tfnesting(text.as_bytes()), Err(TflexError::UnknownType { ref found, .. }) if found == "Spiral")
    );
    // Zero-radius circle.
    let circle = r#"<Contour xsi:type="CircleContour"><Center><X>0</X><Y>0</Y></Center><Radius>0</Radius></Contour>"#;
    assert!(matches!(
        read_tfnesting(project(circle, "").as_bytes()),
        Err(TflexError::InvalidGeometry { .. })
    ));
    // A gap between two objects.
    let gap = [
        line(0.0, 0.0, 0.0, 10.0),
        line(0.0, 11.0, 10.0, 10.0),
        line(10.0, 10.0, 0.0, 0.0),
    ]
    .concat();
    let err = read_tfnesting(project(&figure(&gap), "").as_bytes()).unwrap_err();
    let TflexError::InvalidGeometry { path, reason, .. } = &err else {
        panic!("{err}")
    };
    assert!(path.ends_with("Objects/ContourObject[2]"), "{path}");
    assert!(reason.contains("1.0000 mm away"), "{reason}");
    // An arc of zero sweep.
    let arc = r#"<ContourObject xsi:type="ContourArc"><Begin><X>10</X><Y>0</Y></Begin><End><X>0</X><Y>0</Y></End><Center><X>5</X><Y>0</Y></Center><Radius>5</Radius><Angle>0</Angle><Ccw>true</Ccw></ContourObject>"#;
    let objects = format!("{}{arc}", line(0.0, 0.0, 10.0, 0.0));
    assert!(matches!(
        read_tfnesting(project(&figure(&objects), "").as_bytes()),
        Err(TflexError::InvalidGeometry { .. })
    ));
    // An empty contour.
    assert!(matches!(
        read_tfnesting(project(&figure(""), "").as_bytes()),
        Err(TflexError::InvalidGeometry { .. })
    ));
}

#[test]
fn entity_expansion_bombs_are_refused() {
    let bomb = r#"<?xml version="1.0"?><!DOCTYPE p [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;"><!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;"><!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;"><!ENTITY g "&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;"><!ENTITY h "&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;">]><Project><Name>&h;</Name></Project>"#;
    assert!(matches!(
        read_tfnesting(bomb.as_bytes()),
        Err(TflexError::Xml { .. })
    ));
}

#[test]
fn placements_cannot_multiply_without_bound() {
    // 2 000 vertices placed 2 501 times: over the 5 million vertex limit.
    let objects: String = (0..2000)
        .map(|k| {
            let (a, b) = (
                k as f64 / 2000.0 * std::f64::consts::TAU,
                (k + 1) as f64 / 2000.0 * std::f64::consts::TAU,
            );
            line(a.cos(), a.sin(), b.cos(), b.sin())
        })
        .collect();
    let placements: String = (0..2_501).map(|_| placement(7, "5")).collect();
    let text = project(&figure(&objects), &placements);
    assert_eq!(
        read_tfnesting(text.as_bytes()),
        Err(TflexError::TooLarge { limit: 5_000_000 })
    );
}

#[test]
fn deep_nesting_does_not_overflow_the_stack() {
    let depth = 100_000;
    let text = format!(
        "<Project>{}{}</Project>",
        "<a>".repeat(depth),
        "</a>".repeat(depth)
    );
    // Either the XML parser refuses the depth or the project lacks its parts: no crash.
    assert!(read_tfnesting(text.as_bytes()).is_err());
}
