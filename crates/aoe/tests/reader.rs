//! The edge-list reader: located errors, round trips, and no panic on garbage.

mod common;

use common::{read, FIG4_ANTIPRISM, FIG5A};
use cutroute_aoe::edge_list::{self, ReadError, WriteError};
use cutroute_aoe::random::{random_four_regular, random_plane_multigraph};
use cutroute_aoe::{Embedding, PlaneGraph};
use cutroute_geometry::SplitMix64;
use proptest::prelude::*;

#[test]
fn fixtures_round_trip() {
    for text in [FIG4_ANTIPRISM, FIG5A] {
        let embedding = read(text);
        let written = edge_list::write(&embedding).unwrap();
        let again = edge_list::read(&written).unwrap();
        assert_eq!(again.graph(), embedding.graph());
        assert_eq!(edge_list::write(&again).unwrap(), written);
    }
}

#[test]
fn random_graphs_round_trip_or_refuse_loops() {
    let mut rng = SplitMix64::new(8);
    let (mut written, mut refused) = (0, 0);
    for round in 0..600 {
        let embedding = if round % 2 == 0 {
            random_four_regular(3 + round % 20, &mut rng).unwrap()
        } else {
            let g = random_plane_multigraph(1 + round % 30, &mut rng);
            let outer = rng.below(g.faces().count() as u64) as usize;
            Embedding::new(g, outer).unwrap()
        };
        match edge_list::write(&embedding) {
            Ok(text) => {
                let again = edge_list::read(&text).unwrap();
                assert_eq!(again.graph(), embedding.graph());
                assert_eq!(again.outer_face(), embedding.outer_face());
                written += 1;
            }
            Err(WriteError::Loop { edge }) => {
                let (a, b) = embedding.graph().ends(edge - 1);
                assert_eq!(a, b);
                refused += 1;
            }
        }
    }
    assert!(
        written > 20 && refused > 50,
        "{written} written, {refused} refused"
    );
}

fn with_line(text: &str, line: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[line - 1] = new;
    lines.join("\n")
}

#[test]
fn errors_are_located() {
    assert_eq!(edge_list::read(""), Err(ReadError::Empty));
    assert!(matches!(
        edge_list::read("x\n"),
        Err(ReadError::BadEdgeCount { line: 1, .. })
    ));
    assert!(matches!(
        edge_list::read("0\n"),
        Err(ReadError::BadEdgeCount { line: 1, .. })
    ));
    let t = FIG5A;
    assert_eq!(
        edge_list::read(&with_line(t, 3, "1 2 1 4 3 1 2 1")),
        Err(ReadError::FieldCount { line: 3, found: 8 })
    );
    assert!(matches!(
        edge_list::read(&with_line(t, 3, "1 2 1 4 3 -1 2 1 2")),
        Err(ReadError::BadNumber {
            line: 3,
            field: "r2",
            ..
        })
    ));
    assert_eq!(
        edge_list::read(&with_line(t, 3, "7: 1 2 1 4 3 1 2 1 2")),
        Err(ReadError::WrongLabel {
            line: 3,
            found: 7,
            expected: 2
        })
    );
    assert_eq!(
        edge_list::read(&with_line(t, 3, "0 2 1 4 3 1 2 1 2")),
        Err(ReadError::VertexZero {
            line: 3,
            field: "v1"
        })
    );
    assert_eq!(
        edge_list::read(&with_line(t, 3, "1 2 11 4 3 1 2 1 2")),
        Err(ReadError::NoSuchEdge {
            line: 3,
            field: "l1",
            edge: 11
        })
    );
    assert_eq!(
        edge_list::read(&with_line(t, 3, "1 2 7 4 3 1 2 1 2")),
        Err(ReadError::NotIncident {
            line: 3,
            field: "l1",
            edge: 7,
            vertex: 1
        })
    );
    let r = edge_list::read(&with_line(t, 3, "1 2 9 4 3 1 2 1 2"));
    assert!(
        matches!(r, Err(ReadError::LeftRightMismatch { line: 3, .. })),
        "{r:?}"
    );
    assert!(matches!(
        edge_list::read(&with_line(t, 3, "1 2 1 4 3 1 2 7 2")),
        Err(ReadError::FaceMismatch { .. })
    ));
    assert_eq!(
        edge_list::read(&with_line(t, 3, "1 2 1 4 3 1 2 1 3")),
        Err(ReadError::RankMismatch {
            line: 3,
            found: 3,
            computed: 2
        })
    );
    assert_eq!(
        edge_list::read(&format!("{t}1 2 1 1 1 1 0 0 1\n")),
        Err(ReadError::ExtraLine {
            line: 12,
            expected: 10
        })
    );
    let short: String = t.lines().take(10).collect::<Vec<_>>().join("\n");
    assert_eq!(
        edge_list::read(&short),
        Err(ReadError::MissingEdges {
            expected: 10,
            found: 9
        })
    );
    assert_eq!(
        edge_list::read("1\n1 1 1 1 1 1 0 1 1\n"),
        Err(ReadError::Loop {
            line: 2,
            field: "v2",
            edge: 1
        })
    );
    assert_eq!(
        edge_list::read("2\n1 3 2 2 2 2 1 0 1\n1 3 1 1 1 1 0 1 1\n"),
        Err(ReadError::IsolatedVertex {
            vertex: 2,
            vertex_count: 3
        })
    );
    assert_eq!(
        edge_list::read("1\n1 99999999999 1 1 1 1 0 0 1\n"),
        Err(ReadError::VertexOutOfRange {
            line: 2,
            field: "v2",
            vertex: 99999999999,
            limit: 2
        })
    );
    // Faces renumbered without a 0.
    let no_outer = "1\n1 2 1 1 1 1 5 5 1\n";
    assert_eq!(edge_list::read(no_outer), Err(ReadError::NoOuterFace));
    let figure_eight =
        PlaneGraph::from_rotations(1, &[(0, 0), (0, 0)], &[vec![0, 1, 2, 3]]).unwrap();
    let e = Embedding::with_outer_dart(figure_eight, 1).unwrap();
    assert_eq!(edge_list::write(&e), Err(WriteError::Loop { edge: 1 }));
}

#[test]
fn one_bridge_reads() {
    let e = edge_list::read("1\n1 2 1 1 1 1 0 0 1\n").unwrap();
    assert_eq!(e.graph().edge_count(), 1);
    assert_eq!(e.edge_rank(0), 1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn garbage_never_panics(text in "[0-9 :\\n-]{0,200}") {
        let _ = edge_list::read(&text);
    }

    #[test]
    fn mutated_fixtures_never_panic(position in 0usize..400, byte in 0u8..128, count in 0usize..10) {
        let mut bytes = FIG4_ANTIPRISM.as_bytes().to_vec();
        let at = position % bytes.len();
        let end = (at + count).min(bytes.len());
        bytes.splice(at..end, std::iter::once(byte));
        let text = String::from_utf8_lossy(&bytes);
        let _ = edge_list::read(&text);
    }

    #[test]
    fn number_soup_never_panics(numbers in proptest::collection::vec(0usize..12, 0..60)) {
        let mut text = String::from("5\n");
        for chunk in numbers.chunks(9) {
            text += &chunk.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" ");
            text.push('\n');
        }
        let _ = edge_list::read(&text);
    }
}
