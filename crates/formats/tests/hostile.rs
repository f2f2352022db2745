//! Issue #15: the numeric domain every reader shares, CP866 part names, and nests without a
//! sheet through geometry JSON.

use cutroute_formats::{
    read_dbs, read_geometry_json, write_dbs, write_dbs_with, write_geometry_json, DbsWriteOptions,
};
use cutroute_geometry::{Contour, Nest, Part, Vertex};

fn square(x: f64, side: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x, 0.0),
        Vertex::line(x, side),
        Vertex::line(x + side, side),
        Vertex::line(x + side, 0.0),
    ])
}

fn one_part(name: &str) -> Nest {
    Nest {
        sheet: Some(Part {
            name: "LIST".into(),
            contours: vec![square(-10.0, 100.0)],
        }),
        parts: vec![Part {
            name: name.into(),
            contours: vec![square(0.0, 10.0)],
        }],
    }
}

#[test]
fn cyrillic_names_are_written_in_cp866_and_read_back() {
    let bytes = write_dbs(&one_part("КОНУС#1")).unwrap();
    // «КО» «НУ» «С#» «1 » pair-swapped: К = 0x8A, О = 0x8E in CP866.
    assert!(bytes.windows(2).any(|w| w == [0x8E, 0x8A]));
    let read = read_dbs(&bytes).unwrap().nest;
    assert_eq!(read.parts[0].name, "КОНУС#1");
    assert_eq!(read.sheet.unwrap().name, "LIST");
}

#[test]
fn long_or_foreign_names_are_refused_or_cut_to_eight_cp866_characters() {
    assert!(write_dbs(&one_part("ЗАГОТОВКА-1")).is_err());
    assert!(write_dbs(&one_part("箱")).is_err());
    let cut = DbsWriteOptions {
        truncate_long_names: true,
    };
    let read = |name: &str| {
        read_dbs(&write_dbs_with(&one_part(name), &cut).unwrap())
            .unwrap()
            .nest
            .parts[0]
            .name
            .clone()
    };
    assert_eq!(read("ЗАГОТОВКА-1"), "ЗАГОТОВК");
    assert_eq!(read("箱 ёЁ"), "? ёЁ");
}

#[test]
fn a_nest_without_a_sheet_keeps_its_only_part_through_geometry_json() {
    let nest = Nest {
        sheet: None,
        parts: vec![Part {
            name: "RECTANGL".into(),
            contours: vec![square(0.0, 10.0)],
        }],
    };
    let text = write_geometry_json(&nest).unwrap();
    assert_eq!(read_geometry_json(text.as_bytes()).unwrap(), nest);
    // Files with a sheet first read as before.
    let with_sheet = one_part("A");
    let text = write_geometry_json(&with_sheet).unwrap();
    assert_eq!(read_geometry_json(text.as_bytes()).unwrap(), with_sheet);
}

#[test]
fn geometry_json_refuses_values_outside_the_shared_domain_with_a_json_path() {
    let file = |point: &str| {
        format!(
            r#"[{{"partid":"S","paths":[[[0,0],[0,100],[100,100],[100,0],[0,0]]]}},
               {{"partid":"P","paths":[[{point},[1,2],[2,2],[2,1],[1,1]]]}}]"#
        )
    };
    let ok = read_geometry_json(file("[1,1]").as_bytes());
    assert!(ok.is_ok(), "{ok:?}");
    for (point, what) in [
        ("[1e200,1]", "coordinate"),
        ("[1,1,1e300]", "bulge"),
        ("[-1e308,1]", "coordinate"),
    ] {
        let error = read_geometry_json(file(point).as_bytes())
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("[1].paths[0]") && error.contains(what),
            "{error}"
        );
    }
    // All points the same: a point, not a contour.
    let dot = r#"[{"partid":"S","paths":[[[0,0],[0,100],[100,100],[100,0],[0,0]]]},
                  {"partid":"P","paths":[[[5,5],[5,5],[5,5],[5,5]]]}]"#;
    let error = read_geometry_json(dot.as_bytes()).unwrap_err().to_string();
    assert!(
        error.contains("[1].paths[0]") && error.contains("0.05 mm"),
        "{error}"
    );
}
