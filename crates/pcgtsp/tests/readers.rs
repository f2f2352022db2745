//! Readers and writers on the real files, and on malformed input.

mod common;

use common::{read_data, references};
use cutroute_pcgtsp::{check_tour, Instance, ParseError, PcglnsResult};

#[test]
fn every_reference_instance_parses_and_its_pcglns_tour_checks() {
    let refs = references();
    assert_eq!(refs.len(), 59, "reference.csv rows");
    for r in &refs {
        let instance = r.load();
        assert_eq!(instance.node_count, r.nodes, "{}", r.instance);
        assert_eq!(instance.clusters.len(), r.clusters, "{}", r.instance);
        assert_eq!(instance.depot, 0, "{}", r.instance);
        let cost =
            check_tour(&instance, &r.pcglns_tour).unwrap_or_else(|e| panic!("{}: {e}", r.instance));
        assert_eq!(cost, r.pcglns_cost, "{}", r.instance);
    }
}

#[test]
fn pcglns_round_trip_is_exact() {
    for name in ["pcgtsplib/ESC07", "pcgtsplib/br17.12", "industrial/e1x_6"] {
        let instance = Instance::parse(&read_data(&format!("pcgtsp/{name}.pcglns"))).unwrap();
        let again = Instance::parse(&instance.to_pcglns()).unwrap();
        assert_eq!(again, instance, "{name}");
    }
}

#[test]
fn pcgtsplib_variant_with_real_weights_and_result_file() {
    let instance = Instance::parse(&read_data("nests/pcgtsp/E1X_6_01.pcgtsp")).unwrap();
    assert_eq!(instance.node_count, 181);
    assert_eq!(instance.clusters.len(), 17);
    assert!(instance
        .cost
        .iter()
        .any(|c| c.is_finite() && c.fract() != 0.0));
    let result =
        PcglnsResult::parse(&read_data("nests/pcgtsp/E1X_6_01.pcglns.result.txt")).unwrap();
    assert_eq!(result.cost, 1514.0);
    assert_eq!(result.tour.len(), 17);
    assert_eq!(result.instance_name.as_deref(), Some("e1x_6.pcglns"));
    // The result was computed on the integer-rounded twin e1x_6.pcglns.
    let rounded = Instance::parse(&read_data("pcgtsp/industrial/e1x_6.pcglns")).unwrap();
    assert_eq!(check_tour(&rounded, &result.tour).unwrap(), 1514.0);
    let real = check_tour(&instance, &result.tour).unwrap();
    assert!((real - 1514.0).abs() < 17.0, "real-valued cost {real}");
    // Real weights survive the PCGLNS writer.
    assert_eq!(Instance::parse(&instance.to_pcglns()).unwrap(), instance);
    let test1 = PcglnsResult::parse(&read_data("nests/pcgtsp/test1.pcglns.result.txt")).unwrap();
    assert_eq!(test1.cost, 4662.0);
    assert_eq!(test1.tour[0], 0);
}

#[test]
fn node_weights_are_folded_into_entering_arcs() {
    let text = "NAME: w\nTYPE: PCGTSP\nDIMENSION: 3\nGROUPS: 2\nEDGE_WEIGHT_TYPE: EXPLICIT\n\
                EDGE_WEIGHT_FORMAT: FULL_MATRIX\nNODE_WEIGHT_SECTION:\n0 1.5 2\nEDGE_WEIGHT_SECTION\n\
                0 10 -1\n3 0 4\n5 6 0\nNODE_GROUP_SECTION\n1 1 -1\n2 2 3 -1\nSTART_GROUP_SECTION\n1\nEOF\n";
    let instance = Instance::parse(text).unwrap();
    assert_eq!(instance.arc_cost(0, 1), 11.5);
    assert_eq!(instance.arc_cost(0, 2), f64::INFINITY);
    assert_eq!(instance.arc_cost(1, 0), 3.0);
    assert_eq!(instance.arc_cost(2, 1), 7.5);
    assert!(instance.precedence.is_empty());
}

/// A valid 4-node, 3-cluster instance whose pieces the malformed tests replace.
fn tiny(dimension: &str, matrix: &str, sets: &str, ordering: &str) -> String {
    format!(
        "NAME : tiny\nTYPE : PCGLNS\nDIMENSION : {dimension}\nGTSP_SETS : 3\nEDGE_WEIGHT_TYPE : EXPLICIT\n\
         EDGE_WEIGHT_FORMAT : FULL_MATRIX\nEDGE_WEIGHT_SECTION\n{matrix}GTSP_SET_SECTION\n{sets}\
         GTSP_SET_ORDERING\n{ordering}START_GROUP_SECTION\n1\nEOF\n"
    )
}

const MATRIX: &str = "0 1 2 3\n1 0 4 5\n2 4 0 6\n3 5 6 0\n";
const SETS: &str = "1 1 -1\n2 2 3 -1\n3 4 -1\n";

fn parse_err(text: &str) -> ParseError {
    Instance::parse(text).expect_err("must be rejected")
}

#[test]
fn tiny_instance_is_valid() {
    let instance = Instance::parse(&tiny("4", MATRIX, SETS, "2 3 -1\n")).unwrap();
    assert_eq!(instance.precedence, vec![(1, 2)]);
    assert_eq!(instance.clusters, vec![vec![0], vec![1, 2], vec![3]]);
}

#[test]
fn malformed_inputs_give_typed_errors_with_lines() {
    assert_eq!(parse_err(""), ParseError::Empty);
    assert!(matches!(
        parse_err(&tiny("1000000000000", MATRIX, SETS, "")),
        ParseError::DimensionOutOfRange {
            line: 3,
            value: 1_000_000_000_000,
            ..
        }
    ));
    assert!(matches!(
        parse_err(&tiny("-4", MATRIX, SETS, "")),
        ParseError::InvalidNumber { line: 3, .. }
    ));
    // Truncated matrix: detected where the next section starts.
    assert!(matches!(
        parse_err(&tiny("4", "0 1 2 3\n1 0 4 5\n", SETS, "")),
        ParseError::Truncated {
            line: 10,
            found: 8,
            expected: 16,
            ..
        }
    ));
    assert!(matches!(
        parse_err(&tiny(
            "4",
            "0 1 2 3\n1 0 4 5\n2 4 0 6\n3 5 6 0 9\n",
            SETS,
            ""
        )),
        ParseError::TooManyValues { line: 11, .. }
    ));
    assert!(matches!(
        parse_err(&tiny(
            "4",
            "0 1 2 3\n1 0 NaN 5\n2 4 0 6\n3 5 6 0\n",
            SETS,
            ""
        )),
        ParseError::InvalidNumber { line: 9, .. }
    ));
    assert!(matches!(
        parse_err(&tiny(
            "4",
            "NaN 1 2 3\n1 0 4 5\n2 4 0 6\n3 5 6 0\n",
            SETS,
            ""
        )),
        ParseError::InvalidNumber { line: 8, .. }
    ));
    assert!(matches!(
        parse_err(&tiny(
            "4",
            "0 1 2 3\n1 0 4 5\n2 4 0 inf\n3 5 6 0\n",
            SETS,
            ""
        )),
        ParseError::InvalidNumber { line: 10, .. }
    ));
    assert!(matches!(
        parse_err(&tiny(
            "4",
            "0 1 2 3\n1 0 -4 5\n2 4 0 6\n3 5 6 0\n",
            SETS,
            ""
        )),
        ParseError::NegativeWeight { line: 9, .. }
    ));
    assert_eq!(
        parse_err(&tiny("4", MATRIX, "1 1 -1\n2 2 3 -1\n3 3 4 -1\n", "")),
        ParseError::NodeInTwoClusters {
            line: 15,
            node: 3,
            first: 2,
            second: 3
        }
    );
    assert!(matches!(
        parse_err(&tiny("4", MATRIX, "1 1 -1\n2 2 -1\n3 4 -1\n", "")),
        ParseError::NodeInNoCluster { node: 3, .. }
    ));
    assert!(matches!(
        parse_err(&tiny("4", MATRIX, "1 1 -1\n2 2 3 -1\n3 9 -1\n", "")),
        ParseError::NodeOutOfRange {
            line: 15,
            node: 9,
            ..
        }
    ));
    assert!(matches!(
        parse_err(&tiny("4", MATRIX, "1 1 -1\n2 2 3 -1\n", "")),
        ParseError::EmptyCluster { cluster: 3, .. }
    ));
    assert!(matches!(
        parse_err(&tiny("4", MATRIX, "1 1 -1\n2 2 3 -1\n2 4 -1\n", "")),
        ParseError::ClusterDefinedTwice {
            line: 15,
            cluster: 2
        }
    ));
    assert!(matches!(
        parse_err(&tiny("4", MATRIX, "1 1 -1\n2 2 3 -1\n3 4\n", "")),
        ParseError::Unterminated { line: 16, .. }
    ));
    assert_eq!(
        parse_err(&tiny("4", MATRIX, SETS, "2 3 -1\n3 2 -1\n")),
        ParseError::CyclicPrecedence {
            line: 18,
            cycle: vec![2, 3, 2]
        }
    );
    assert_eq!(
        parse_err(&tiny("4", MATRIX, SETS, "2 2 -1\n")),
        ParseError::SelfPrecedence {
            line: 17,
            cluster: 2
        }
    );
    assert_eq!(
        parse_err(&tiny("4", MATRIX, SETS, "3 1 -1\n")),
        ParseError::PrecedenceBeforeDepot {
            line: 17,
            before: 3,
            depot: 1
        }
    );
    assert!(matches!(
        parse_err(&tiny("4", MATRIX, SETS, "2 7 -1\n")),
        ParseError::ClusterOutOfRange {
            line: 17,
            cluster: 7,
            ..
        }
    ));
    assert!(matches!(
        parse_err("FOO : 1\n"),
        ParseError::UnknownKeyword { line: 1, .. }
    ));
    assert!(matches!(
        parse_err("NAME : x\nEDGE_WEIGHT_SECTION\n0\n"),
        ParseError::Missing {
            line: 2,
            what: "DIMENSION"
        }
    ));
    assert!(matches!(
        parse_err("NAME : x\nTYPE : TSP\n"),
        ParseError::Unsupported {
            line: 2,
            key: "TYPE",
            ..
        }
    ));
    assert!(matches!(
        parse_err("NAME : x\nDIMENSION : 2\nGTSP_SETS : 3\n"),
        ParseError::ClusterCountOutOfRange { line: 3, .. }
    ));
    // The whole text cut short in the matrix.
    let full = tiny("4", MATRIX, SETS, "2 3 -1\n");
    let cut = &full[..full.find("2 4 0 6").unwrap()];
    assert!(matches!(
        parse_err(cut),
        ParseError::Truncated { found: 8, .. }
    ));
    // Messages are human-readable and carry the line.
    assert_eq!(
        parse_err(&tiny("4", MATRIX, SETS, "2 3 -1\n3 2 -1\n")).to_string(),
        "line 18: cyclic precedence 2 -> 3 -> 2"
    );
}

#[test]
fn malformed_result_files() {
    assert!(matches!(
        PcglnsResult::parse("Cost : 12\n"),
        Err(ParseError::Missing {
            what: "Tour Ordering",
            ..
        })
    ));
    assert!(matches!(
        PcglnsResult::parse("Cost : x\nTour Ordering : [1, 2]\n"),
        Err(ParseError::InvalidNumber { line: 1, .. })
    ));
    assert!(matches!(
        PcglnsResult::parse("Cost : 3\nTour Ordering : [1, 0]\n"),
        Err(ParseError::NodeOutOfRange {
            line: 2,
            node: 0,
            ..
        })
    ));
    let ok = PcglnsResult::parse("Cost : 3\nTour Ordering : [1, 3, 2]\n").unwrap();
    assert_eq!(ok.tour, vec![0, 2, 1]);
}
