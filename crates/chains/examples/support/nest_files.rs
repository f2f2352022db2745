//! Helpers shared by the benchmark examples of `cutroute-chains` and `cutroute-segments`
//! (included by path: examples cannot share a module otherwise): the real nests of
//! `data/nests`, opened as the app and the CLI open them.

use cutroute_geometry::{Nest, Point};
use cutroute_protocol::Problem;

/// Every nest file of the shared data: DBS, geometry JSON and T-FLEX projects.
pub fn nest_files() -> Vec<String> {
    let root = format!("{}/../../data/nests", env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["dbs-json", "dbs", "tflex"] {
        let entries = std::fs::read_dir(format!("{root}/{dir}"))
            .unwrap_or_else(|e| panic!("missing data folder {root}/{dir}: {e}"));
        let mut names: Vec<String> = entries
            .map(|e| {
                e.expect("readable folder")
                    .file_name()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect();
        names.sort();
        files.extend(names.into_iter().map(|n| format!("{root}/{dir}/{n}")));
    }
    files
}

/// The nest, start and finish of a file as the app and CLI open it (orientation normalised).
pub fn read_nest(path: &str) -> (Nest, Point, Option<Point>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("missing file {path}: {e}"));
    let document = cutroute_engine::open_document(path, &bytes)
        .unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
    match document.problem {
        Problem::Nest {
            nest,
            start,
            finish,
        } => (nest, start, finish),
        Problem::PcgtspText { .. } => panic!("{path} is not a nest"),
    }
}
