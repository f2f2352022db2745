//! Each rule on small hand-built nests with known violation counts.

use cutroute_geometry::{Contour, ContourRef, CutStep, Nest, Part, Point, Route, Vertex};
use cutroute_thermal::{
    admissible_pierce_points, check_rules, enforce_rules, RuleParams, RuleSet, Side, ThermalError,
    Violation,
};

/// A clockwise rectangle.
fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Contour {
    Contour::new(vec![
        Vertex::line(x0, y0),
        Vertex::line(x0, y1),
        Vertex::line(x1, y1),
        Vertex::line(x1, y0),
    ])
}

fn part(contour: Contour) -> Part {
    Part {
        name: String::new(),
        contours: vec![contour],
    }
}

fn sheet(w: f64, h: f64, parts: Vec<Part>) -> Nest {
    Nest {
        sheet: Some(part(rect(0.0, 0.0, w, h))),
        parts,
    }
}

/// Cuts the parts' outer contours in `order`, each pierced at `pierce(part index)`.
fn route(nest: &Nest, order: &[usize], pierce: impl Fn(usize) -> Point) -> Route {
    let route = Route {
        start: Point::new(0.0, 0.0),
        steps: order
            .iter()
            .map(|&p| {
                CutStep::pierced(
                    ContourRef {
                        part: p,
                        contour: 0,
                    },
                    pierce(p),
                )
            })
            .collect(),
        finish: None,
    };
    assert!(route.validate(nest, 1e-9).is_ok());
    route
}

fn only(part: bool, sheet: bool, islands: bool) -> RuleSet {
    RuleSet {
        part,
        sheet,
        islands,
    }
}

#[test]
fn part_rigidity_counts_pierce_points_far_from_the_free_edge() {
    // A 30 mm wide part 2 mm from the left border of a 200 × 200 sheet, and a second one right
    // of it, 5 mm apart.
    let nest = sheet(
        200.0,
        200.0,
        vec![
            part(rect(2.0, 80.0, 32.0, 120.0)),
            part(rect(37.0, 80.0, 67.0, 120.0)),
        ],
    );
    let params = RuleParams::default();
    let rules = only(true, false, false);
    // Both pierced on their left sides: the first faces the border (2 mm), the second faces
    // the first, already cut (5 mm): no violation.
    let left = |p: usize| Point::new(if p == 0 { 2.0 } else { 37.0 }, 100.0);
    let report = check_rules(&nest, &route(&nest, &[0, 1], left), rules, &params).unwrap();
    assert_eq!(report.counts().part, Some(0));
    // Pierced on their right sides: the first 32 mm from the border (> 2 + 10), the second
    // 30 mm from the first (> 5 + 10): two violations.
    let right = |p: usize| Point::new(if p == 0 { 32.0 } else { 67.0 }, 100.0);
    let report = check_rules(&nest, &route(&nest, &[0, 1], right), rules, &params).unwrap();
    assert_eq!(report.counts().part, Some(2));
    match &report.violations[0] {
        Violation::PartRigidity {
            step, excess_mm, ..
        } => {
            assert_eq!(*step, 0);
            assert!((excess_mm - 20.0).abs() < 1e-6, "{excess_mm}");
        }
        other => panic!("{other:?}"),
    }
    // Cut in the other order, the second part (cut first) has only the border as free edge:
    // its right side is 133 mm from the sheet's right border, its left 37 mm from the left
    // one: pierced on its left it is fine; the first part, cut second, pierced left: fine.
    let report = check_rules(&nest, &route(&nest, &[1, 0], left), rules, &params).unwrap();
    assert_eq!(report.counts().part, Some(0));
    // The admissible pierce points of the first part face the border: within 2 + 10 mm of it.
    let admissible =
        admissible_pierce_points(&nest, &route(&nest, &[0, 1], right), &params).unwrap();
    let first = admissible[0].as_ref().expect("the rule constrains part 0");
    assert!(!first.is_empty() && first.iter().all(|p| p.x <= 12.0 + 1e-9));
    // The repair moves both pierce points and leaves a valid route.
    let fixed = enforce_rules(&nest, &route(&nest, &[0, 1], right), rules, &params).unwrap();
    assert_eq!(fixed.report.counts().part, Some(0));
    assert!(fixed.route.validate(&nest, 1e-9).is_ok());
}

#[test]
fn sheet_rule_1_wants_long_parts_near_a_narrow_border_first() {
    // A 400 × 20 strip 10 mm from the bottom edge of a 1000 × 500 sheet, squares spread over
    // the sheet (no large scrap, balanced halves).
    let mut parts = vec![part(rect(300.0, 10.0, 700.0, 30.0))];
    for x in [100.0, 300.0, 600.0, 800.0] {
        parts.push(part(rect(x, 200.0, x + 50.0, 250.0)));
    }
    parts.push(part(rect(20.0, 400.0, 70.0, 450.0)));
    parts.push(part(rect(930.0, 400.0, 980.0, 450.0)));
    let nest = sheet(1000.0, 500.0, parts);
    // Rule 3 off (any imbalance tolerated): this test is about rule 1 alone.
    let params = RuleParams {
        heat_balance: 1.0,
        ..RuleParams::default()
    };
    let rules = only(false, true, false);
    let corner = |p: usize| nest.parts[p].contours[0].vertices[0].point;
    let first = route(&nest, &[0, 1, 2, 3, 4, 5, 6], corner);
    assert_eq!(
        check_rules(&nest, &first, rules, &params)
            .unwrap()
            .counts()
            .sheet,
        Some(0)
    );
    let late = route(&nest, &[1, 2, 0, 3, 4, 5, 6], corner);
    let report = check_rules(&nest, &late, rules, &params).unwrap();
    assert_eq!(report.counts().sheet, Some(1));
    assert!(matches!(
        report.violations[0],
        Violation::LongPartLate { step: 2, .. }
    ));
    // The same strip 100 mm from the edge is not near a narrow border.
    let mut far = nest.clone();
    far.parts[0] = part(rect(300.0, 100.0, 700.0, 120.0));
    assert_eq!(
        check_rules(&far, &late, rules, &params)
            .unwrap()
            .counts()
            .sheet,
        Some(0)
    );
    // Repaired: the strip goes first.
    let fixed = enforce_rules(&nest, &late, rules, &params).unwrap();
    assert_eq!(fixed.report.counts().sheet, Some(0));
    assert_eq!(fixed.route.steps[0].contour.part, 0);
}

#[test]
fn sheet_rules_2_and_3_choose_the_start_side() {
    let params = RuleParams::default();
    let rules = only(false, true, false);
    // Rule 2: parts only on the left half of a 1000 × 500 sheet (500 mm of scrap on the right):
    // start on the left (low) side of the parts' extent [0, 500].
    let parts: Vec<Part> = [10.0, 110.0, 210.0, 310.0, 410.0]
        .iter()
        .map(|&x| part(rect(x, 100.0, x + 80.0, 180.0)))
        .collect();
    let nest = sheet(1000.0, 500.0, parts);
    let corner = |p: usize| nest.parts[p].contours[0].vertices[0].point;
    let good = route(&nest, &[0, 1, 2, 3, 4], corner);
    assert_eq!(
        check_rules(&nest, &good, rules, &params)
            .unwrap()
            .counts()
            .sheet,
        Some(0)
    );
    let bad = route(&nest, &[4, 3, 2, 1, 0], corner);
    let report = check_rules(&nest, &bad, rules, &params).unwrap();
    assert_eq!(report.counts().sheet, Some(1));
    assert!(matches!(
        report.violations[0],
        Violation::WrongStartSide {
            required: Side::Low,
            rule: 2,
            ..
        }
    ));
    let fixed = enforce_rules(&nest, &bad, rules, &params).unwrap();
    assert_eq!(fixed.report.counts().sheet, Some(0));
    // Rule 3: parts over the whole sheet, many small ones on the right: start on the right.
    let mut parts = vec![part(rect(20.0, 20.0, 220.0, 220.0))];
    for i in 0..6 {
        let x = 600.0 + 60.0 * i as f64;
        parts.push(part(rect(x, 20.0, x + 40.0, 60.0)));
        parts.push(part(rect(x, 300.0, x + 40.0, 340.0)));
    }
    let nest = sheet(1000.0, 500.0, parts);
    let corner = |p: usize| nest.parts[p].contours[0].vertices[0].point;
    let order: Vec<usize> = (0..13).collect();
    let left_first = route(&nest, &order, corner);
    let report = check_rules(&nest, &left_first, rules, &params).unwrap();
    assert_eq!(report.counts().sheet, Some(1));
    assert!(matches!(
        report.violations[0],
        Violation::WrongStartSide {
            required: Side::High,
            rule: 3,
            ..
        }
    ));
    let reversed: Vec<usize> = (0..13).rev().collect();
    let right_first = route(&nest, &reversed, corner);
    assert_eq!(
        check_rules(&nest, &right_first, rules, &params)
            .unwrap()
            .counts()
            .sheet,
        Some(0)
    );
}

/// A 3 × 3 grid of 20 mm squares 5 mm apart, 40 mm from the edges of a 150 × 150 sheet;
/// part 4 is the centre, 0–3 the corners, 5–8 the sides.
fn grid_nest() -> Nest {
    let mut parts = Vec::new();
    let at = [40.0, 65.0, 90.0];
    let cells = [
        (0, 0),
        (2, 0),
        (0, 2),
        (2, 2),
        (1, 1),
        (1, 0),
        (0, 1),
        (2, 1),
        (1, 2),
    ];
    for (i, j) in cells {
        parts.push(part(rect(at[i], at[j], at[i] + 20.0, at[j] + 20.0)));
    }
    sheet(150.0, 150.0, parts)
}

#[test]
fn islands_count_parts_cut_off_by_the_cuts_around_them() {
    let nest = grid_nest();
    let params = RuleParams::default();
    let rules = only(false, false, true);
    let corner = |p: usize| nest.parts[p].contours[0].vertices[0].point;
    // Ring first (corners, then sides), centre last: the last side cut isolates the centre.
    let ring_first = route(&nest, &[0, 1, 2, 3, 5, 6, 7, 8, 4], corner);
    let report = check_rules(&nest, &ring_first, rules, &params).unwrap();
    assert_eq!(report.counts().islands, Some(1));
    assert_eq!(
        report.violations[0],
        Violation::Island {
            step: 7,
            part: ContourRef {
                part: 4,
                contour: 0
            }
        }
    );
    // Centre first: nothing is ever cut off (every ring part has 40 mm of sheet outside it).
    let centre_first = route(&nest, &[4, 0, 1, 2, 3, 5, 6, 7, 8], corner);
    assert_eq!(
        check_rules(&nest, &centre_first, rules, &params)
            .unwrap()
            .counts()
            .islands,
        Some(0)
    );
    // Strips: with a 4 mm strip width, the 5 mm webs hold the centre.
    let thin = RuleParams {
        strip_width_mm: 4.0,
        ..params
    };
    assert_eq!(
        check_rules(&nest, &ring_first, rules, &thin)
            .unwrap()
            .counts()
            .islands,
        Some(0)
    );
    // The repair cuts the centre before it is isolated, and the route stays valid.
    let fixed = enforce_rules(&nest, &ring_first, rules, &params).unwrap();
    assert_eq!(fixed.report.counts().islands, Some(0));
    assert!(fixed.route.validate(&nest, 1e-9).is_ok());
}

#[test]
fn all_rules_together_and_typed_errors() {
    let nest = grid_nest();
    let corner = |p: usize| nest.parts[p].contours[0].vertices[0].point;
    let ring_first = route(&nest, &[0, 1, 2, 3, 5, 6, 7, 8, 4], corner);
    let fixed = enforce_rules(&nest, &ring_first, RuleSet::ALL, &RuleParams::default()).unwrap();
    assert_eq!(fixed.report.counts().total(), 0, "{:?}", fixed.report);
    assert!(fixed.route.validate(&nest, 1e-9).is_ok());
    assert_eq!(
        RuleSet::parse("part,islands").unwrap(),
        only(true, false, true)
    );
    assert!(matches!(
        RuleSet::parse("part,heat"),
        Err(ThermalError::UnknownRule(name)) if name == "heat"
    ));
    let bad = RuleParams {
        strip_width_mm: -1.0,
        ..RuleParams::default()
    };
    assert!(matches!(
        check_rules(&nest, &ring_first, RuleSet::ALL, &bad),
        Err(ThermalError::InvalidParameter {
            name: "strip_width",
            ..
        })
    ));
}

/// The check in pieces finds exactly what the check in one call finds, whatever the budget.
#[test]
fn the_check_in_pieces_equals_the_check_in_one_call() {
    use cutroute_geometry::{generate_nest, SplitMix64};
    use cutroute_thermal::RuleCheck;
    use std::time::Duration;
    // Part rigidity and islands are the pieces that split; sheet rigidity is one piece (its
    // violations are tested on the hand-built nests above).
    let mut kinds_seen = [false; 2];
    for seed in 1..=4u64 {
        let nest = generate_nest(2_500 + 500 * seed as usize, seed);
        let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
        // Deepest contours first keeps inner before outer; a shuffle within each depth makes
        // part, sheet and island violations.
        let forest = nest.containment_forest();
        let mut rng = SplitMix64::new(seed);
        for i in (1..refs.len()).rev() {
            refs.swap(i, rng.below(i as u64 + 1) as usize);
        }
        refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r).unwrap_or(0)));
        let route = Route {
            start: Point::new(0.0, 0.0),
            steps: refs
                .iter()
                .map(|&r| CutStep::pierced(r, nest.contour(r).unwrap().vertices[0].point))
                .collect(),
            finish: None,
        };
        let whole = check_rules(&nest, &route, RuleSet::ALL, &RuleParams::default()).unwrap();
        for budget in [Duration::ZERO, Duration::from_millis(5)] {
            let mut check = RuleCheck::new(RuleSet::ALL, RuleParams::default()).unwrap();
            let mut calls = 0;
            let report = loop {
                calls += 1;
                if let Some(report) = check.advance(&nest, &route, budget).unwrap() {
                    break report;
                }
            };
            assert_eq!(report, whole, "seed {seed}, budget {budget:?}");
            if budget.is_zero() {
                assert!(calls > 4, "{calls} pieces");
            }
        }
        for v in &whole.violations {
            match v {
                Violation::PartRigidity { .. } => kinds_seen[0] = true,
                Violation::LongPartLate { .. } | Violation::WrongStartSide { .. } => {}
                Violation::Island { .. } => kinds_seen[1] = true,
            }
        }
    }
    assert_eq!(kinds_seen, [true, true], "both split rules are exercised");
}

/// The repair in pieces (a unit of the island replay, a range of the part rule, a piece of the
/// final check at a time) returns exactly what the one-call repair returns, whatever the budget,
/// and refuses to go on once it has.
#[test]
fn the_repair_in_pieces_equals_the_repair_in_one_call() {
    use cutroute_geometry::{generate_nest, SplitMix64};
    use cutroute_thermal::RuleRepair;
    use std::time::Duration;
    let mut changed = 0;
    for seed in 1..=3u64 {
        let nest = generate_nest(300 * seed as usize, seed);
        let forest = nest.containment_forest();
        let mut refs: Vec<ContourRef> = nest.contour_refs().collect();
        let mut rng = SplitMix64::new(seed);
        for i in (1..refs.len()).rev() {
            refs.swap(i, rng.below(i as u64 + 1) as usize);
        }
        refs.sort_by_key(|&r| std::cmp::Reverse(forest.depth(r).unwrap_or(0)));
        let route = Route {
            start: Point::new(0.0, 0.0),
            steps: refs
                .iter()
                .map(|&r| CutStep::pierced(r, nest.contour(r).unwrap().vertices[0].point))
                .collect(),
            finish: None,
        };
        let params = RuleParams::default();
        for rules in [
            RuleSet::ALL,
            only(true, false, false),
            only(false, true, true),
        ] {
            let whole = enforce_rules(&nest, &route, rules, &params).unwrap();
            changed += usize::from(whole.route != route);
            for budget in [Duration::ZERO, Duration::from_millis(3)] {
                let mut repair = RuleRepair::new(&route, rules, params).unwrap();
                let mut calls = 0;
                let pieced = loop {
                    calls += 1;
                    if let Some(enforced) = repair.advance(&nest, budget).unwrap() {
                        break enforced;
                    }
                };
                assert_eq!(pieced, whole, "seed {seed}, {rules:?}, budget {budget:?}");
                if budget.is_zero() && rules.islands {
                    // One piece per unit placed on the island raster at least.
                    assert!(calls > forest.roots().len(), "{calls} pieces");
                }
                assert!(matches!(
                    repair.advance(&nest, budget),
                    Err(ThermalError::RepairFinished)
                ));
            }
        }
    }
    // Most repairs move something: the equality is not that of untouched routes.
    assert!(changed >= 6, "{changed} of 9 repairs changed the route");
}

/// A part touching the hole it sits in (its shared edge 2·10⁻⁵ mm outside the hole's, as T-FLEX
/// placements leave it) is outside the hole for the solvers' exact forest, so a valid route may
/// cut it after the hole; the repair cuts it before the hole that drops it (Nest02/03's AOE
/// routes were refused by the path checker for this).
#[test]
fn the_repair_cuts_a_part_touching_its_hole_before_the_hole() {
    let hole = |x0: f64, y0: f64, x1: f64, y1: f64| rect(x0, y0, x1, y1).reversed();
    let plate = Part {
        name: "plate".into(),
        contours: vec![
            rect(0.0, 0.0, 400.0, 400.0),
            hole(100.0, 100.0, 300.0, 300.0),
        ],
    };
    let touching = part(rect(100.0 - 2e-5, 150.0, 180.0, 230.0));
    let nest = sheet(500.0, 500.0, vec![plate, touching]);
    let r = |part, contour| ContourRef { part, contour };
    // Hole, then the touching part, then the plate: valid under the exact forest, where the
    // part lies inside the plate's outer contour but not inside its hole.
    let route = Route {
        start: Point::new(0.0, 0.0),
        steps: vec![
            CutStep::pierced(r(0, 1), Point::new(300.0, 200.0)),
            CutStep::pierced(r(1, 0), Point::new(180.0, 200.0)),
            CutStep::pierced(r(0, 0), Point::new(0.0, 200.0)),
        ],
        finish: None,
    };
    let valid = route.validate(&nest, nest.check_tolerance());
    assert!(valid.is_ok(), "{valid:?}");
    for rules in [RuleSet::ALL, only(false, true, false)] {
        let fixed = enforce_rules(&nest, &route, rules, &RuleParams::default()).unwrap();
        let at = |c: ContourRef| fixed.route.steps.iter().position(|s| s.contour == c);
        assert!(
            at(r(1, 0)) < at(r(0, 1)),
            "{rules:?}: {:?}",
            fixed.route.steps
        );
        assert!(at(r(0, 1)) < at(r(0, 0)));
        assert!(fixed.route.validate(&nest, nest.check_tolerance()).is_ok());
    }
}
