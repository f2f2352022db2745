//! Containment forest on hand-made and generated nests, checked against brute force.

use std::time::Instant;

use cutroute_geometry::{
    generate_nest, ContainmentForest, Contour, ContourRef, Nest, Part, Point, Vertex,
};

fn square(x0: f64, y0: f64, side: f64, clockwise: bool) -> Contour {
    let c = Contour::new(vec![
        Vertex::line(x0, y0),
        Vertex::line(x0 + side, y0),
        Vertex::line(x0 + side, y0 + side),
        Vertex::line(x0, y0 + side),
    ]);
    if clockwise {
        c.reversed()
    } else {
        c
    }
}

fn r(part: usize, contour: usize) -> ContourRef {
    ContourRef { part, contour }
}

/// Part 0: a plate with two holes; part 1 sits in hole 1 and has a hole of its own, holding
/// part 2; part 3 stands apart; part 4 is a disc whose bulging arc reaches over part 5's box.
fn hand_made() -> Nest {
    let plate = Part {
        name: "plate".into(),
        contours: vec![
            square(0.0, 0.0, 100.0, true),
            square(10.0, 10.0, 50.0, false),
            square(70.0, 70.0, 10.0, false),
        ],
    };
    let inlay = Part {
        name: "inlay".into(),
        contours: vec![
            square(20.0, 20.0, 30.0, true),
            square(30.0, 30.0, 10.0, false),
        ],
    };
    let pin = Part {
        name: "pin".into(),
        contours: vec![Contour::circle(Point::new(35.0, 35.0), 3.0, true)],
    };
    let apart = Part {
        name: "apart".into(),
        contours: vec![square(200.0, 0.0, 10.0, true)],
    };
    let disc = Part {
        name: "disc".into(),
        contours: vec![Contour::circle(Point::new(300.0, 0.0), 20.0, true)],
    };
    // A small square inside the disc's box but outside the disc (near the box corner).
    let corner = Part {
        name: "corner".into(),
        contours: vec![square(281.0, 16.0, 2.0, true)],
    };
    Nest {
        sheet: Some(Part {
            name: "sheet".into(),
            contours: vec![square(-10.0, -30.0, 400.0, true)],
        }),
        parts: vec![plate, inlay, pin, apart, disc, corner],
    }
}

#[test]
fn hand_made_forest() {
    let nest = hand_made();
    let f = nest.containment_forest();
    assert_eq!(f.len(), 9);
    assert_eq!(f.parent(r(0, 0)), None);
    assert_eq!(f.parent(r(0, 1)), Some(r(0, 0)));
    assert_eq!(f.parent(r(0, 2)), Some(r(0, 0)));
    assert_eq!(f.parent(r(1, 0)), Some(r(0, 1)));
    assert_eq!(f.parent(r(1, 1)), Some(r(1, 0)));
    assert_eq!(f.parent(r(2, 0)), Some(r(1, 1)));
    assert_eq!(f.parent(r(3, 0)), None);
    assert_eq!(f.parent(r(4, 0)), None);
    assert_eq!(
        f.parent(r(5, 0)),
        None,
        "outside the disc though inside its box"
    );
    assert_eq!(f.depth(r(2, 0)), Some(4));
    assert_eq!(f.max_depth(), 4);
    assert_eq!(f.children(r(0, 0)), &[r(0, 1), r(0, 2)]);
    assert_eq!(f.roots(), &[r(0, 0), r(3, 0), r(4, 0), r(5, 0)]);
    let ancestors: Vec<_> = f.ancestors(r(2, 0)).collect();
    assert_eq!(ancestors, vec![r(1, 1), r(1, 0), r(0, 1), r(0, 0)]);
    assert!(f.must_precede(r(2, 0), r(0, 0)));
    assert!(!f.must_precede(r(0, 0), r(2, 0)));
    assert_eq!(f.precedence_pairs().len(), 5);
    assert_eq!(f.all_precedence_pairs().len(), 1 + 1 + 2 + 3 + 4);
    let mut leaves = f.leaves();
    leaves.sort();
    assert_eq!(leaves, vec![r(0, 2), r(2, 0), r(3, 0), r(4, 0), r(5, 0)]);
    assert_eq!(f, ContainmentForest::brute_force(&nest));
}

#[test]
fn generated_forest_matches_brute_force() {
    for seed in 0..3 {
        let nest = generate_nest(500, seed);
        assert_eq!(nest.contour_count(), 500);
        let fast = nest.containment_forest();
        let slow = ContainmentForest::brute_force(&nest);
        assert_eq!(fast, slow, "seed {seed}");
        // Every hole of a part has that part's outer contour as parent.
        for (pi, part) in nest.parts.iter().enumerate() {
            for ci in 1..part.contours.len() {
                assert_eq!(fast.parent(r(pi, ci)), Some(r(pi, 0)));
            }
        }
        assert!(fast.max_depth() >= 2, "frames hold inlays");
    }
}

#[test]
fn twenty_thousand_contours_fast() {
    let t0 = Instant::now();
    let nest = generate_nest(20_000, 42);
    let generated = t0.elapsed();
    assert_eq!(nest.contour_count(), 20_000);
    let t1 = Instant::now();
    let forest = nest.containment_forest();
    let built = t1.elapsed();
    assert_eq!(forest.len(), 20_000);
    // Generous bounds: debug-ish builds on a shared, busy machine.
    assert!(
        generated.as_secs_f64() < 5.0,
        "generation took {generated:?}"
    );
    assert!(built.as_secs_f64() < 10.0, "forest took {built:?}");
    let holes: usize = nest.parts.iter().map(|p| p.contours.len() - 1).sum();
    let inlays = nest
        .parts
        .iter()
        .filter(|p| p.name.starts_with("inlay"))
        .count();
    assert_eq!(forest.precedence_pairs().len(), holes + inlays);
    eprintln!("generate {generated:?}, forest {built:?}");
}

#[test]
fn generated_nests_follow_the_conventions() {
    let a = generate_nest(2_000, 9);
    assert_eq!(a, generate_nest(2_000, 9), "deterministic");
    assert_ne!(a, generate_nest(2_000, 10));
    let forest = a.containment_forest();
    let sheet = a.sheet.as_ref().unwrap().contours[0].clone();
    assert!(sheet.bounding_box().contains_box(&a.bounding_box()));
    let mut kinds = std::collections::BTreeSet::new();
    for (pi, part) in a.parts.iter().enumerate() {
        kinds.insert(part.name.split('-').next().unwrap().to_string());
        for (ci, c) in part.contours.iter().enumerate() {
            let r = r(pi, ci);
            assert_eq!(c.validate(), Ok(()), "{r:?}");
            assert_eq!(
                c.is_clockwise(),
                ci == 0,
                "outer clockwise, holes counter-clockwise"
            );
            let depth = forest.depth(r).unwrap();
            assert_eq!(depth.is_multiple_of(2), ci == 0, "{r:?}");
            if ci == 0 {
                // A part is either free or sits in a hole of another part.
                if let Some(parent) = forest.parent(r) {
                    assert_ne!(parent.part, pi);
                    assert_ne!(parent.contour, 0, "parts never overlap");
                }
            }
        }
    }
    // No two parts' contours touch: check every pair whose boxes meet.
    let boxes: Vec<_> = a.parts.iter().map(|p| p.bounding_box()).collect();
    for i in 0..a.parts.len() {
        for j in i + 1..a.parts.len() {
            if !boxes[i].intersects(&boxes[j]) {
                continue;
            }
            for ci in &a.parts[i].contours {
                for cj in &a.parts[j].contours {
                    for si in ci.spans() {
                        assert!(
                            cj.spans().all(|sj| si.intersections(&sj).is_empty()),
                            "parts {i} and {j} touch"
                        );
                    }
                }
            }
        }
    }
    assert_eq!(a.clone().normalize_orientation(), 0);
    assert!(a.arc_count() > 0);
    for kind in ["flange", "frame", "inlay", "ring", "angle", "plate"] {
        assert!(kinds.contains(kind), "{kind} missing");
    }
    for n in [0, 1, 2, 3, 4, 5, 7] {
        assert_eq!(generate_nest(n, 1).contour_count(), n);
    }
}

/// A part placed in a hole touching it, its shared edge a rounding error outside the hole's
/// (as T-FLEX placements leave it: Nest02's part 119 sticks out of its hole by 2·10⁻⁵ mm), is
/// inside the hole in the forest with the check tolerance (the thermal rules' units): a repair
/// must cut it before the hole that drops it. A part merely touching the plate from outside
/// stays a root. The exact forest keeps the touching part a root.
#[test]
fn a_part_touching_the_hole_it_sits_in_is_inside_it_within_the_tolerance() {
    let plate = Part {
        name: "plate".into(),
        contours: vec![
            square(0.0, 0.0, 400.0, true),
            square(100.0, 100.0, 200.0, false),
        ],
    };
    // Its left edge on the hole's left edge, 2·10⁻⁵ mm out; its other sides well inside.
    let touching = Part {
        name: "touching".into(),
        contours: vec![square(100.0 - 2e-5, 150.0, 80.0, true)],
    };
    // Beside the plate, sharing its right edge.
    let beside = Part {
        name: "beside".into(),
        contours: vec![square(400.0 + 2e-5, 0.0, 80.0, true)],
    };
    let nest = Nest {
        parts: vec![plate, touching, beside],
        ..Nest::default()
    };
    let tolerance = nest.check_tolerance();
    assert!(2e-5 < tolerance);
    for forest in [
        ContainmentForest::with_tolerance(&nest, tolerance),
        ContainmentForest::brute_force_with_tolerance(&nest, tolerance),
    ] {
        assert_eq!(forest.parent(r(1, 0)), Some(r(0, 1)));
        assert_eq!(forest.depth(r(1, 0)), Some(2));
        assert_eq!(forest.parent(r(2, 0)), None);
        assert!(forest
            .all_precedence_pairs()
            .into_iter()
            .any(|(inner, outer)| inner == r(1, 0) && outer == r(0, 1)));
    }
    for forest in [
        ContainmentForest::new(&nest),
        ContainmentForest::brute_force(&nest),
    ] {
        assert_eq!(forest.parent(r(1, 0)), Some(r(0, 0)));
    }
}

/// A part fitted into another part's notch shares three sides with it (its first span among
/// them), and its fourth closes the notch: it lies beside the other part, not inside it,
/// in every forest. The same part fitted into a hole of that shape, sharing the same three
/// sides, lies inside the hole.
#[test]
fn a_part_sharing_its_first_spans_with_a_neighbour_is_inside_it_only_when_it_is() {
    // A U open at the top: its notch is x 10..20, y 10..30.
    let u = Contour::new(
        [
            (0.0, 0.0),
            (30.0, 0.0),
            (30.0, 30.0),
            (20.0, 30.0),
            (20.0, 10.0),
            (10.0, 10.0),
            (10.0, 30.0),
            (0.0, 30.0),
        ]
        .map(|(x, y)| Vertex::line(x, y))
        .to_vec(),
    );
    // The notch's filler, starting on the notch's bottom edge, its longest spans on the
    // notch's sides, an arc closing it at the top.
    let filler = |bulge: f64, first: usize| {
        let mut vertices = vec![
            Vertex::line(10.0, 10.0),
            Vertex::line(20.0, 10.0),
            Vertex::arc(20.0, 30.0, bulge),
            Vertex::line(10.0, 30.0),
        ];
        vertices.rotate_left(first);
        Contour::new(vertices)
    };
    // A plate with a hole the filler fits in, its sides along the hole's, y 10..40.
    let hole = Contour::new(
        [(10.0, 10.0), (20.0, 10.0), (20.0, 40.0), (10.0, 40.0)]
            .map(|(x, y)| Vertex::line(x, y))
            .to_vec(),
    );
    let plate = Part {
        name: "plate".into(),
        contours: vec![square(-100.0, -100.0, 300.0, true), hole],
    };
    for (bulge, first, reversed) in (0..4)
        .flat_map(|first| [(0.0, first), (0.5, first), (-0.5, first)])
        .flat_map(|(bulge, first)| [(bulge, first, false), (bulge, first, true)])
    {
        let filler = |bulge: f64| match reversed {
            false => filler(bulge, first),
            true => filler(bulge, first).reversed(),
        };
        let case = format!("bulge {bulge}, first vertex {first}, reversed {reversed}");
        let nest = Nest {
            parts: vec![
                Part {
                    name: "u".into(),
                    contours: vec![u.clone()],
                },
                Part {
                    name: "filler".into(),
                    contours: vec![filler(bulge)],
                },
            ],
            ..Nest::default()
        };
        let tolerance = nest.check_tolerance();
        for forest in [
            ContainmentForest::new(&nest),
            ContainmentForest::brute_force(&nest),
            ContainmentForest::with_tolerance(&nest, tolerance),
            ContainmentForest::brute_force_with_tolerance(&nest, tolerance),
        ] {
            assert_eq!(forest.parent(r(1, 0)), None, "{case}");
            assert_eq!(forest.parent(r(0, 0)), None, "{case}");
        }
        let nest = Nest {
            parts: vec![
                plate.clone(),
                Part {
                    name: "filler".into(),
                    contours: vec![filler(bulge)],
                },
            ],
            ..Nest::default()
        };
        for forest in [
            ContainmentForest::new(&nest),
            ContainmentForest::brute_force(&nest),
        ] {
            assert_eq!(forest.parent(r(1, 0)), Some(r(0, 1)), "{case}");
        }
    }
}
