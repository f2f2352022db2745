//! Multi-sheet T-FLEX projects: every sheet can be opened, and the document lists them.

use std::path::PathBuf;

use cutroute_engine::{open_document, open_sheet, OpenError};
use cutroute_protocol::Problem;

fn data(relative: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn part_count(problem: &Problem) -> usize {
    match problem {
        Problem::Nest { nest, .. } => nest.parts.len(),
        other => panic!("not a nest: {other:?}"),
    }
}

#[test]
fn each_sheet_of_a_project_opens() {
    let bytes = data("nests/tflex-multi/two-sheets.tfnesting");
    let first = open_document("two-sheets.tfnesting", &bytes).unwrap();
    assert_eq!(first.sheets.len(), 2);
    assert_eq!(first.sheet, 0);
    assert_eq!(part_count(&first.problem), 5);
    let second = open_sheet("two-sheets.tfnesting", &bytes, 1).unwrap();
    assert_eq!(second.sheet, 1);
    assert_eq!(second.sheets, first.sheets);
    assert_eq!(part_count(&second.problem), 1);
    assert!(second
        .warnings
        .iter()
        .any(|w| w.kind == cutroute_geometry::WarningKind::Sheets
            && w.message.contains("showing sheet 2")));
    assert!(matches!(
        open_sheet("two-sheets.tfnesting", &bytes, 2),
        Err(OpenError::NoSuchSheet {
            sheet: 3,
            count: 2,
            ..
        })
    ));
}

#[test]
fn files_of_one_sheet_have_only_sheet_one() {
    let bytes = data("nests/dbs/nested.dbs");
    let document = open_sheet("nested.dbs", &bytes, 0).unwrap();
    assert!(document.sheets.is_empty());
    let e = open_sheet("nested.dbs", &bytes, 1).unwrap_err();
    assert!(e.to_string().contains("no sheet 2"), "{e}");
    let single = data("nests/tflex/Nest01.tfnesting");
    assert!(open_document("Nest01.tfnesting", &single)
        .unwrap()
        .sheets
        .is_empty());
}
