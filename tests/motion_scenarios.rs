//! Step motion generation (Klamt & Behnke 2017, Sec. VI) on the scenarios: the abstract
//! plan expanded into keyframes whose every keyframe and interpolated point is statically
//! stable by MuJoCo's CoM (`Simulation` as the `CenterOfMassModel`) and within the legs'
//! reach and joint limits.
//!
//! Status: the expansion does not yet succeed on whole plans (see the ignored tests): the
//! staircase fails at the first rear-right step, the platform at the first rear step onto
//! the platform (the rear leg stretched 0.4 m behind its hip cannot take the roll or base
//! shift that stability needs). The passing tests cover the path up to those steps.

use momaro::jobs::plan::{self, PathElement, PathKind, PlanOptions, PlanSummary};
use momaro::locomotion::Algorithm;
use momaro::motion::{DetailedPath, MotionError, MotionOptions, Phase, expand_path};
use momaro::robot::Leg;
use momaro::scenario::Scenario;
use momaro::sim::{Simulation, default_model_path};
use std::path::Path;

fn scenario(name: &str) -> Scenario {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(format!("{name}.toml"));
    Scenario::load(&p).expect("scenario loads")
}

fn sim() -> Simulation {
    Simulation::robot_only(&default_model_path()).expect("model compiles")
}

fn planned(s: &Scenario, sim: &Simulation) -> PlanSummary {
    let opts =
        PlanOptions { algorithm: Algorithm::AraStar, time_limit_s: 60.0, ..PlanOptions::default() };
    plan::run(s, sim.robot(), &opts).expect("plan")
}

fn expand(
    s: &Scenario,
    sim: &mut Simulation,
    path: &[PathElement],
) -> Result<DetailedPath, MotionError> {
    let robot = sim.robot().clone();
    let prep = plan::prepare(s, &robot, None, None).expect("maps");
    let options = MotionOptions::from_params(&prep.params);
    expand_path(path, &robot, &prep.maps, sim, &options)
}

/// Every keyframe: margin ≥ 3 cm, joints within their ranges, contacts on the ground.
fn check(d: &DetailedPath, sim: &Simulation) {
    let robot = sim.robot();
    assert!(d.min_margin_m >= 0.03, "min margin {:.3}", d.min_margin_m);
    assert!(d.min_keyframe_margin_m >= 0.03);
    let mut t = -1.0;
    for k in &d.keyframes {
        assert!(k.time_s > t || k.phase == Phase::Start, "time order");
        t = k.time_s;
        assert!(k.segment_min_margin_m >= 0.03, "{:?} at {}", k.phase, k.path_index);
        for leg in Leg::ALL {
            for (j, q) in k.joints[leg.index()].iter().enumerate() {
                assert!(robot.joint_ranges[j].contains(*q), "{leg:?} joint {j} = {q}");
            }
            assert!(k.leg_heights[leg.index()] < robot.max_leg_length());
        }
        assert!(k.contact.iter().filter(|&&c| c).count() >= 3);
    }
}

fn phases(d: &DetailedPath) -> Vec<Phase> {
    d.keyframes.iter().map(|k| k.phase).collect()
}

/// The prefix of the path before the `n`-th (0-based) step of a rear leg onto higher ground.
fn before_rear_step_up(p: &PlanSummary, n: usize) -> usize {
    p.path
        .iter()
        .enumerate()
        .filter(|(_, e)| {
            e.kind == PathKind::Step
                && e.leg.is_some_and(|l| !l.is_front())
                && e.step.is_some_and(|s| s.height_m > 0.05)
        })
        .map(|(i, _)| i)
        .nth(n)
        .unwrap_or(p.path.len())
}

/// Prints the expansion's figures (seen with `cargo test -- --nocapture`).
fn report(s: &Scenario, end: usize, total: usize, d: &DetailedPath) {
    println!(
        "{}: {end} of {total} elements, {} steps, {} keyframes, {} postures, min margin {:.3} m (keyframes {:.3}, three contacts {:.3})",
        s.name,
        d.steps,
        d.keyframes.len(),
        d.samples_checked,
        d.min_margin_m,
        d.min_keyframe_margin_m,
        d.min_three_contact_margin_m
    );
}

#[test]
fn staircase_front_steps_and_first_rear_step_are_stable() {
    let s = scenario("staircase");
    let mut sim = sim();
    let p = planned(&s, &sim);
    // Up to (excluding) the second rear step up: the front steps onto the first two treads
    // and the first rear-left step.
    let end = before_rear_step_up(&p, 1);
    let d = expand(&s, &mut sim, &p.path[..end]).expect("expansion");
    report(&s, end, p.path.len(), &d);
    check(&d, &sim);
    let ph = phases(&d);
    for want in [
        Phase::StandUp,
        Phase::Roll,
        Phase::WheelToCentre,
        Phase::Lift,
        Phase::Swing,
        Phase::Place,
        Phase::WheelBack,
        Phase::RollBack,
        Phase::PlannedBaseShift,
        Phase::WheelMove,
    ] {
        assert!(ph.contains(&want), "{want:?} missing");
    }
    let stepped: Vec<Leg> =
        d.keyframes.iter().filter(|k| k.phase == Phase::Place).filter_map(|k| k.leg).collect();
    assert!(stepped.iter().any(|l| l.is_front()) && stepped.iter().any(|l| !l.is_front()));
    // Three contacts while the foot is in the air, with the margin kept.
    assert!(d.min_three_contact_margin_m >= 0.03 && d.min_three_contact_margin_m.is_finite());
}

#[test]
fn platform_path_up_to_the_rear_steps_onto_the_platform_is_stable() {
    let s = scenario("platform");
    let mut sim = sim();
    let p = planned(&s, &sim);
    let end = before_rear_step_up(&p, 0);
    let d = expand(&s, &mut sim, &p.path[..end]).expect("expansion");
    report(&s, end, p.path.len(), &d);
    check(&d, &sim);
    assert!(d.steps >= 2, "front steps onto the platform: {}", d.steps);
    let ph = phases(&d);
    assert!(ph.contains(&Phase::Roll) && ph.contains(&Phase::Lower) && ph.contains(&Phase::Drive));
}

#[test]
fn failure_names_the_step_and_leg() {
    let s = scenario("staircase");
    let mut sim = sim();
    let p = planned(&s, &sim);
    let end = before_rear_step_up(&p, 1);
    match expand(&s, &mut sim, &p.path) {
        Ok(_) => {}
        Err(MotionError::Step { index, best_margin_m, required_m, .. }) => {
            assert!(index >= end);
            assert!(best_margin_m < required_m);
        }
        Err(e) => panic!("unexpected error {e}"),
    }
}

#[test]
#[ignore = "issue 5 unfinished: rear steps up with the rear leg 0.4 m behind its hip"]
fn staircase_whole_path_is_stable() {
    let s = scenario("staircase");
    let mut sim = sim();
    let p = planned(&s, &sim);
    let d = expand(&s, &mut sim, &p.path).expect("expansion");
    check(&d, &sim);
}

#[test]
#[ignore = "issue 5 unfinished: rear steps up with the rear leg 0.4 m behind its hip"]
fn platform_whole_path_is_stable() {
    let s = scenario("platform");
    let mut sim = sim();
    let p = planned(&s, &sim);
    let d = expand(&s, &mut sim, &p.path).expect("expansion");
    check(&d, &sim);
}
