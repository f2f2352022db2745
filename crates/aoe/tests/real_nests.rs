//! Plane graphs of the real nests in `data/nests`: every component is plane, and the
//! edges account for every contour's perimeter exactly once per contour they belong to.

use cutroute_aoe::{PlanGraph, PlanOptions};
mod common;

use common::{load_nest as load, REAL_NESTS};

#[test]
fn real_nests_give_plane_graphs_that_account_for_every_contour() {
    let options = PlanOptions::default();
    let mut total_common = 0;
    for name in REAL_NESTS {
        let nest = load(name);
        let plan = PlanGraph::from_nest(&nest, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
        let components = plan.components().unwrap_or_else(|e| panic!("{name}: {e}"));
        let g = plan.graph();
        assert_eq!(
            components.iter().map(|c| c.edges.len()).sum::<usize>(),
            g.edge_count()
        );
        let perimeters: f64 = nest
            .parts
            .iter()
            .flat_map(|p| &p.contours)
            .map(|c| c.perimeter())
            .sum();
        let covered: f64 = (0..g.edge_count())
            .map(|e| {
                let length: f64 = plan.edge_spans(e).iter().map(|s| s.length()).sum();
                length * plan.edge_contours(e).len() as f64
            })
            .sum();
        let slack = 1e-7 * perimeters + 10.0 * options.tolerance * nest.contour_count() as f64;
        assert!(
            (covered - perimeters).abs() <= slack,
            "{name}: {covered} vs {perimeters}"
        );
        let chains = plan.route().unwrap_or_else(|e| panic!("{name}: {e}"));
        plan.check_route(&chains)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        total_common += (0..g.edge_count())
            .filter(|&e| plan.edge_contours(e).len() > 1)
            .count();
        if name == "tflex/Nest01.tfnesting" {
            // Five parts in a row touching along y = 0: one connected cluster.
            assert_eq!(components.len(), 1);
            assert!((0..g.vertex_count()).all(|v| g.degree(v) == 3));
        }
    }
    assert!(total_common > 0);
}
