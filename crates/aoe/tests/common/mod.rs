//! Fixtures shared by the integration tests: the graphs the digest reconstructs from the paper.
#![allow(dead_code)]

use cutroute_aoe::{edge_list, Embedding};
use cutroute_geometry::{Contour, Nest, Part, Vertex};
use std::path::PathBuf;

/// An axis-parallel rectangle, clockwise as outer contours run.
pub fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x0, y0),
        Vertex::line(x0, y1),
        Vertex::line(x1, y1),
        Vertex::line(x1, y0),
    ])
}

/// An axis-parallel rectangle, counter-clockwise as holes run.
pub fn hole(x0: f64, y0: f64, x1: f64, y1: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x0, y0),
        Vertex::line(x1, y0),
        Vertex::line(x1, y1),
        Vertex::line(x0, y1),
    ])
}

/// A nameless part.
pub fn part(contours: Vec<Contour>) -> Part {
    Part {
        name: String::new(),
        contours,
    }
}

/// A nest of `data/nests` by its path there; panics loudly when the file is missing.
pub fn load_nest(relative: &str) -> Nest {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/nests")
        .join(relative);
    let bytes = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("required test data {} is missing: {e}", path.display()));
    if relative.ends_with(".tfnesting") {
        cutroute_cad::tflex::read_tfnesting(&bytes)
            .unwrap()
            .remove(0)
    } else {
        cutroute_formats::read_nest(&bytes).unwrap()
    }
}

/// Every real nest the plan-graph tests use.
pub const REAL_NESTS: [&str; 8] = [
    "dbs/nested.dbs",
    "dbs/seven.dbs",
    "dbs/test0.json.dbs",
    "dbs-json/E1X_6_01.dbs.json",
    "dbs-json/test1.dbs.json",
    "tflex/Nest01.tfnesting",
    "tflex/Nest02.tfnesting",
    "tflex/Nest03.tfnesting",
];

/// Fig. 4 of the paper, rebuilt by the digest (§6.1): the square antiprism.
pub const FIG4_ANTIPRISM: &str = "16
1:  1 2  4 12  2 10  1 0  1
2:  1 5  1 13  3 12  2 1  2
3:  8 1  5  2 13  4  2 3  2
4:  4 1  7  3  5  1  3 0  1
5:  4 8  4 14  6  3  4 3  2
6:  7 4  8  5 14  7  4 5  2
7:  3 4 10  6  8  4  5 0  1
8:  3 7  7 15  9  6  6 5  2
9:  6 3 11  8 15 10  6 7  2
10: 2 3  1  9 11  7  7 0  1
11: 2 6 10 16 12  9  8 7  2
12: 5 2  2 11 16  1  8 1  2
13: 8 5  3 16 14  2  9 2  3
14: 7 8  6 13 15  5  9 4  3
15: 6 7  9 14 16  8  9 6  3
16: 5 6 12 15 13 11  9 8  3
";

/// Fig. 5a of the paper, rebuilt by the digest (§6.2), in the orientation that reproduces
/// Table 2. Vertex 5 is a rank-2 cut point whose two outer corners are different faces.
pub const FIG5A: &str = "10
1:  2 1  2  9  6  2  0 1  1
2:  1 2  1  4  3  1  2 1  2
3:  5 1  8  2  4  9  2 3  2
4:  2 5  6  3  2  5  2 4  2
5:  5 3  4  7  8  6  5 4  2
6:  3 2  5  1 10  4  0 4  1
7:  3 4 10  8  5 10  5 6  2
8:  4 5  9  5  7  3  5 3  2
9:  1 4  3 10  1  8  0 3  1
10: 4 3  7  6  9  7  0 6  1
";

pub fn read(text: &str) -> Embedding {
    edge_list::read(text).unwrap_or_else(|e| panic!("fixture does not read: {e}"))
}

/// Parses a table row "2 - 13 - 14" into 0-based edge numbers.
pub fn row(text: &str) -> Vec<usize> {
    text.split('-')
        .map(|t| t.trim().parse::<usize>().expect("edge number") - 1)
        .collect()
}
