//! The foundation on flat ground: standing, driving forward, sideways, turning on the spot.

mod common;

use momaro::control::wheels::Twist;
use momaro::jobs::sim::{SimOptions, SimSummary, run};

fn sim(duration_s: f64, drive: Option<Twist>) -> SimSummary {
    let sc = common::scenario("flat");
    let opts =
        SimOptions { duration_s, drive, model_path: common::model(), rerun: None, progress: false };
    run(&sc, &opts).expect("sim runs")
}

#[test]
fn stands_on_all_eight_wheels_at_nominal_height_for_ten_seconds() {
    let s = sim(10.0, None);
    assert_eq!(s.min_wheels_in_contact, 8, "{s:#?}");
    let height_error = s.base_end[2] - s.nominal_base_height_m;
    assert!(
        height_error.abs() < 0.02,
        "base height {} vs nominal {}",
        s.base_end[2],
        s.nominal_base_height_m
    );
    assert!(s.upright && s.body_collisions.is_empty(), "{s:#?}");
    assert!(s.min_stability_margin_m > 0.2, "{s:#?}");
    // The wheels carry the weight (MuJoCo's contact forces), each pair its share.
    let weight = s.total_mass_kg * 9.81;
    let carried: f64 = s.wheel_loads_end_n.iter().sum();
    assert!((carried / weight - 1.0).abs() < 0.02, "{carried} N carried of {weight} N");
    assert!(s.wheel_loads_end_n.iter().all(|f| *f > 0.15 * weight), "{s:#?}");
    // Standing still means standing still.
    let drift = (s.base_end[0] - s.base_start[0]).hypot(s.base_end[1] - s.base_start[1]);
    assert!(drift < 0.01, "drifted {drift} m");
}

#[test]
fn drives_forward_two_metres_in_four_seconds() {
    let s = sim(4.0, Some(Twist { vx: 0.5, vy: 0.0, wz: 0.0 }));
    let dx = s.base_end[0] - s.base_start[0];
    let dy = s.base_end[1] - s.base_start[1];
    assert!((dx - 2.0).abs() < 0.2, "moved {dx} m forward");
    assert!(dy.abs() < 0.1, "moved {dy} m sideways");
    let drift = (s.base_end[3] - s.base_start[3]).to_degrees();
    assert!(drift.abs() < 5.0, "heading drift {drift}°");
    assert!(s.upright && s.min_wheels_in_contact == 8, "{s:#?}");
}

#[test]
fn drives_sideways() {
    let s = sim(4.0, Some(Twist { vx: 0.0, vy: 0.3, wz: 0.0 }));
    let dx = s.base_end[0] - s.base_start[0];
    let dy = s.base_end[1] - s.base_start[1];
    assert!(dy > 0.8, "moved only {dy} m sideways");
    assert!(dx.abs() < 0.1, "moved {dx} m forward");
    assert!((s.base_end[3] - s.base_start[3]).to_degrees().abs() < 5.0);
    assert!(s.upright, "{s:#?}");
}

#[test]
fn turns_on_the_spot() {
    let s = sim(4.0, Some(Twist { vx: 0.0, vy: 0.0, wz: 0.5 }));
    let drift = (s.base_end[0] - s.base_start[0]).hypot(s.base_end[1] - s.base_start[1]);
    assert!(drift < 0.05, "base drifted {drift} m while turning");
    let turned = momaro::geometry::wrap_angle(s.base_end[3] - s.base_start[3]);
    assert!(turned > 1.2, "turned only {turned} rad");
    assert!(s.upright, "{s:#?}");
}
