//! The heat penalty of issue #19: off, it changes nothing; on, it lowers H.

use std::time::Duration;

use cutroute_ccp::{solve, CcpOptions, HeatPenalty};
use cutroute_geometry::{generate_nest, MachineParameters, Objective, Point};
use cutroute_thermal::HeatModel;

fn options(heat: Option<HeatPenalty>) -> CcpOptions {
    CcpOptions {
        start: Point::new(0.0, 0.0),
        time_limit: Duration::from_secs(8),
        max_non_improving_shakes: 30,
        restarts: 0,
        heat,
        ..CcpOptions::default()
    }
}

fn penalty(weight: f64) -> Option<HeatPenalty> {
    Some(HeatPenalty {
        model: HeatModel::default(),
        weight,
        objective: Objective::Time,
    })
}

#[test]
fn weight_zero_is_plain_ccp() {
    let nest = generate_nest(120, 9);
    let plain = solve(&nest, options(None), &mut |_| {}).unwrap();
    let zero = solve(&nest, options(penalty(0.0)), &mut |_| {}).unwrap();
    assert_eq!(plain.route, zero.route);
    assert_eq!(plain.progress.evaluations, zero.progress.evaluations);
}

#[test]
fn the_penalty_lowers_the_heat_load() {
    let nest = generate_nest(120, 9);
    let machine = MachineParameters::default();
    let model = HeatModel::default();
    let plain = solve(&nest, options(None), &mut |_| {}).unwrap();
    let heated = solve(&nest, options(penalty(100.0)), &mut |_| {}).unwrap();
    heated.route.validate(&nest, 1e-6).unwrap();
    let h_plain = model.route_load(&plain.route, &nest, &machine).unwrap();
    let h_heated = model.route_load(&heated.route, &nest, &machine).unwrap();
    assert!(
        h_heated < 0.8 * h_plain,
        "H {h_heated} with the penalty vs {h_plain} without"
    );
    // It costs idle travel, not the other way round.
    assert!(heated.metrics.idle_length >= plain.metrics.idle_length - 1e-6);
}

#[test]
fn bad_heat_options_are_refused() {
    let nest = generate_nest(10, 1);
    let bad = HeatPenalty {
        model: HeatModel {
            sigma_mm: -1.0,
            tau_s: 60.0,
        },
        weight: 1.0,
        objective: Objective::Time,
    };
    assert!(cutroute_ccp::CcpSolver::new(&nest, options(Some(bad))).is_err());
    let nan = penalty(f64::NAN);
    assert!(cutroute_ccp::CcpSolver::new(&nest, options(nan)).is_err());
}
