//! The monitor is right both ways, in MuJoCo: a robot pushed over counts as tipped; a
//! level drive over low clutter does not, and keeps its CoM over the supporting wheels.

mod common;

use momaro::closed_loop::stand_at_start;
use momaro::closed_loop::{RunOptions, run};
use momaro::monitor::{MonitorEvent, MonitorLimits, StabilityMonitor, TipCause};
use momaro::planner::PlanOptions;
use momaro::robot::Leg;
use momaro::sim::Simulation;

#[test]
fn a_robot_pushed_over_counts_as_tipped() {
    let sc = common::scenario("flat");
    let mut sim = Simulation::new(&sc, &common::model()).expect("world compiles");
    let (posture, _) = stand_at_start(&mut sim, &sc).expect("stands");
    let mut monitor = StabilityMonitor::new(MonitorLimits { settle_s: 0.3, ..Default::default() });
    let mut upright_after_settling = true;
    for tick in 0..400 {
        for leg in Leg::ALL {
            sim.set_leg_joint_targets(leg, posture[leg.index()]);
        }
        // From 1 s on, 0.4 s of a strong sideways shove at the base, up and to the left.
        let t = sim.time();
        sim.push_base(if (1.0..1.4).contains(&t) { [0.0, 1500.0, 900.0] } else { [0.0; 3] });
        sim.step(5).expect("steps");
        let s = monitor.observe(&sim);
        if tick == 90 {
            upright_after_settling = !monitor.tipped() && s.margin > 0.2;
        }
    }
    monitor.finish();
    assert!(upright_after_settling, "stood before the push: {:?}", monitor.events);
    assert!(monitor.tipped(), "pushed over, yet not tipped: {:?}", monitor.events);
    let cause = monitor.events.iter().find_map(|e| match e {
        MonitorEvent::TipOver { cause, .. } => Some(*cause),
        _ => None,
    });
    assert!(matches!(cause, Some(TipCause::Tilt | TipCause::TrunkContact | TipCause::Fall)));
    assert!(monitor.max_tilt.to_degrees() > 35.0, "tilt {}", monitor.max_tilt.to_degrees());
}

#[test]
fn a_level_drive_over_low_clutter_is_no_tip_over() {
    let sc = common::scenario("low_clutter");
    let plan = PlanOptions { final_epsilon: Some(3.0), time_limit_s: 300.0, ..Default::default() };
    let s = run(&sc, &RunOptions::new(plan, common::model())).expect("runs");
    assert!(s.reached_goal, "{s:#?}");
    assert_eq!(s.plan_steps, 0, "driven, not stepped");
    assert!(!s.tipped, "{:?}", s.events);
    assert!(s.max_tilt_deg < 10.0, "tilt {}", s.max_tilt_deg);
    assert!(
        s.static_violation_s <= sc.expect.max_static_violation_s,
        "{} s outside the support, worst {} m",
        s.static_violation_s,
        s.worst_static_violation_m
    );
    assert!(s.min_stability_margin_m >= 0.02, "margin {}", s.min_stability_margin_m);
    assert!(s.passed, "{:?}", s.expectations);
}

#[test]
fn a_closed_room_is_no_path_at_once() {
    let sc = common::scenario("closed_room");
    let plan = PlanOptions { final_epsilon: Some(3.0), time_limit_s: 30.0, ..Default::default() };
    let s = run(&sc, &RunOptions::new(plan, common::model())).expect("runs");
    assert_eq!(s.failure_kind, Some(momaro::closed_loop::FailureKind::NoPath), "{:?}", s.failure);
    assert!(s.passed, "{:?}", s.expectations);
    assert_eq!(s.sim_time_s, 0.0);
}
