//! The step executor in closed loop (issue 7): detailed plans executed in MuJoCo — drive
//! runs with the path follower, steps by tracking the keyframes, the margin checked before
//! each lift and contact confirmed before weight goes back onto a placed foot.
//!
//! Until the motion generator expands rear steps up (issue 5), the platform plan is
//! executed up to its first rear step up: the front feet climb onto the platform.

mod common;

use momaro::control::step_executor::{ExecEventKind, ExecFailure};
use momaro::jobs::plan::{self, PathKind, PlanOptions, PlanSummary};
use momaro::jobs::run::{self, Mission, Push, PushWhen, RunOptions, RunSummary};
use momaro::motion::{DetailedPath, Phase};
use momaro::robot::Leg;
use momaro::scenario::Scenario;
use momaro::sim::Simulation;
use std::time::Instant;

fn plan_options() -> PlanOptions {
    PlanOptions { time_limit_s: 60.0, ..PlanOptions::default() }
}

/// The prefix of the path before the `n`-th (0-based) step of a rear leg onto higher
/// ground.
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

/// The keyframes of `d` without those of the base shift that prepares the rear step up
/// (path element `end − 1`) and after it. That shift stretches the rear legs back over the
/// platform's edge, and the generator, which checks reach, joint limits and stability but
/// not leg–terrain collisions, lets the rear shins hit the edge (seen in MuJoCo: `rl_shin`
/// and `rr_shin` touch the platform, the base stops, the executor reports the drift).
fn without_rear_step_preparation(p: &PlanSummary, end: usize, d: &mut DetailedPath) {
    if end > 0 && p.path[end - 1].kind == PathKind::BaseShift {
        d.keyframes.retain(|k| k.path_index < end - 1);
    }
}

/// Plans `sc`, expands the prefix before the first rear step up, and executes it without
/// replanning (a replan would plan the whole path again).
fn execute_prefix(sc: &Scenario, rear_steps_up: usize, push: Option<Push>) -> RunSummary {
    let wall = Instant::now();
    let mut sim = Simulation::new(sc, &common::model()).expect("world compiles");
    let robot = sim.robot().clone();
    let plan = plan::run(sc, &robot, &plan_options()).expect("plan");
    let end = before_rear_step_up(&plan, rear_steps_up);
    assert!(end < plan.path.len(), "the plan has a rear step up");
    let mut detailed = run::expand_mission(sc, &mut sim, &plan, end).expect("prefix expands");
    without_rear_step_preparation(&plan, end, &mut detailed);
    momaro::jobs::stand_at_start(&mut sim, sc).expect("stands");
    let opts =
        RunOptions { max_replans: 0, push, ..RunOptions::new(plan_options(), common::model()) };
    let s = run::execute(sc, &mut sim, Mission { plan, detailed }, &opts, wall).expect("runs");
    println!(
        "{}: {} of {} steps, {} aborted, min margin {:.3} m, steps {:?}, sim {:.1} s, wall {:.1} s, RTF {:.1}, failure {:?}",
        sc.name,
        s.steps_executed,
        s.steps_planned,
        s.steps_aborted,
        s.min_stability_margin_m,
        s.step_margins
            .iter()
            .map(|m| (m.leg, (m.min_margin_m * 1000.0).round() / 1000.0))
            .collect::<Vec<_>>(),
        s.sim_time_s,
        s.wall_time_s,
        s.real_time_factor,
        s.failure
    );
    s
}

#[test]
fn platform_prefix_front_feet_climb_onto_the_platform() {
    let sc = common::scenario("platform");
    let s = execute_prefix(&sc, 0, None);
    assert!(s.failure.is_none(), "{:#?}", s);
    assert!(s.steps_planned >= 2, "front steps up in the prefix: {}", s.steps_planned);
    assert_eq!(s.steps_executed, s.steps_planned, "{:#?}", s.executor_events);
    assert_eq!(s.steps_aborted, 0);
    assert_eq!(s.step_margins.len(), s.steps_planned);
    for m in &s.step_margins {
        assert!(
            m.min_margin_m >= 0.02,
            "step {} ({:?}): margin {:.3} m",
            m.step,
            m.leg,
            m.min_margin_m
        );
    }
    assert!(s.min_stability_margin_m >= 0.02, "{}", s.min_stability_margin_m);
    assert!(!s.tipped, "{:?}", s.events);
    assert!(s.body_collisions.is_empty(), "{:?}", s.body_collisions);
}

#[test]
fn staircase_prefix_front_steps_and_first_rear_step_up() {
    let sc = common::scenario("staircase");
    let s = execute_prefix(&sc, 1, None);
    assert!(s.failure.is_none(), "{:#?}", s);
    assert!(s.steps_planned >= 3, "{}", s.steps_planned);
    assert_eq!(s.steps_executed, s.steps_planned, "{:#?}", s.executor_events);
    for m in &s.step_margins {
        assert!(m.min_margin_m >= 0.02, "step {} ({:?}): {:.3} m", m.step, m.leg, m.min_margin_m);
    }
    assert!(!s.tipped, "{:?}", s.events);
    assert!(s.body_collisions.is_empty(), "{:?}", s.body_collisions);
}

#[test]
fn lateral_push_on_three_legs_puts_the_foot_down_and_the_step_is_retried() {
    // Step 2 of the platform prefix is the front-left step up, the one with the smallest
    // margin (4–7 cm on three legs): 1 s into its swing, the base is pushed to the left,
    // toward the lifted foot, with 100 N for 0.3 s. The robot is stiff, so the static
    // margin hardly changes until the push lifts a support wheel (right rear): then the
    // measured support shrinks and the margin falls below zero. The executor must see it,
    // put the foot down at once, and retry the step once the margin is back.
    let sc = common::scenario("platform");
    let push = Push {
        when: PushWhen::Step { step: 2, phase: Phase::Swing, delay_s: 1.0 },
        force: [0.0, 100.0, 0.0],
        duration_s: 0.3,
    };
    let s = execute_prefix(&sc, 0, Some(push));
    let r = s.push.expect("the push was applied");
    println!("push: {r:?}, max tilt {:.1}°", s.max_tilt_deg);
    // The monitor saw the margin fall (by more than 5 cm, below zero).
    assert!(
        r.min_margin_after_m < r.margin_before_m - 0.05 && r.min_margin_after_m < 0.0,
        "margin {:.3} → {:.3} m",
        r.margin_before_m,
        r.min_margin_after_m
    );
    // The executor put the foot down within 0.2 s of the push start …
    let put_down = s
        .executor_events
        .iter()
        .find_map(|e| match e.event {
            ExecEventKind::FootPutDown { leg, .. } => Some((e.time_s, leg)),
            _ => None,
        })
        .expect("the foot was put down");
    assert_eq!(put_down.1, Leg::FrontLeft);
    assert!(put_down.0 >= r.start_s && put_down.0 <= r.start_s + 0.2, "{put_down:?} {r:?}");
    // … the support wheel came back within 0.6 s and the robot stayed upright …
    assert!(r.negative_margin_s <= 0.6, "{r:?}");
    // (Tilt includes the commanded roll and the retry's larger stabilising roll; the
    // monitor counts a tilt of 35° as tipping.)
    assert!(r.max_tilt_deg < 15.0, "{r:?}");
    assert!(s.max_tilt_deg < 15.0, "{}", s.max_tilt_deg);
    assert!(s.body_collisions.is_empty(), "{:?}", s.body_collisions);
    // … and the retried step and the rest were executed.
    assert!(s.failure.is_none(), "{:?}", s.failure);
    assert_eq!(s.steps_executed, s.steps_planned);
    assert_eq!(s.steps_aborted, 0);
}

/// The whole mission (`momaro run`): plan, expand, execute with replanning.
fn run_whole(name: &str) -> RunSummary {
    let sc = common::scenario(name);
    let s = run::run(&sc, &RunOptions::new(plan_options(), common::model())).expect("run");
    println!(
        "{name}: goal {:.3} m / {:.1}°, {} of {} steps, min margin {:.3} m, max pitch {:.1}°, wall {:.1} s, RTF {:.1}",
        s.goal_position_error_m,
        s.goal_heading_error_rad.to_degrees(),
        s.steps_executed,
        s.steps_planned,
        s.min_stability_margin_m,
        s.max_pitch_deg,
        s.wall_time_s,
        s.real_time_factor
    );
    assert!(s.goal_position_error_m <= 0.1, "{s:#?}");
    assert!(s.goal_heading_error_rad.abs() <= 10f64.to_radians(), "{s:#?}");
    assert!(s.steps_planned > 0 && s.steps_executed == s.steps_planned, "{s:#?}");
    for m in &s.step_margins {
        assert!(m.min_margin_m >= 0.02, "step {} ({:?}): {:.3} m", m.step, m.leg, m.min_margin_m);
    }
    assert!(!s.tipped && s.body_collisions.is_empty(), "{s:#?}");
    assert!(s.passed, "{s:#?}");
    s
}

#[test]
#[ignore = "issue 5: expand_path fails at the first rear step up (platform element 124, \
            rear leg 0.4 m behind its hip); and the base shift preparing it (element 123) \
            makes the rear shins hit the platform edge in MuJoCo"]
fn platform_whole_mission_in_closed_loop() {
    run_whole("platform");
}

#[test]
#[ignore = "issue 5: expand_path fails at the second rear step up of the staircase \
            (no stable motion for the rear-right step)"]
fn staircase_whole_mission_in_closed_loop_pitches_with_the_stairs() {
    let s = run_whole("staircase");
    // Stairs of 0.12 m per 0.7 m: the base pitches by 70 % of their slope (Sec. VI-B).
    let expected = 0.7 * (0.12f64 / 0.7).atan().to_degrees();
    assert!(
        (s.max_pitch_deg - expected).abs() < 1.5,
        "max pitch {} vs {expected}",
        s.max_pitch_deg
    );
}

#[test]
fn an_aborted_step_returns_to_the_driving_posture_and_replans() {
    // A lift threshold no posture can meet (30 cm): the first step is aborted without
    // lifting, the robot returns to the driving posture where it stands, and the job
    // replans from there (once). Until the motion generator expands the staircase's rear
    // steps up (issue 5) the replan's expansion fails; after that, the replanned first
    // step is aborted again and no replan is left. Either way the run stops, reported.
    let mut sc = common::scenario("staircase");
    sc.params.min_lift_margin_m = 0.3;
    let opts = RunOptions {
        max_replans: 1,
        replan_time_limit_s: 30.0,
        ..RunOptions::new(plan_options(), common::model())
    };
    let wall = Instant::now();
    let mut sim = Simulation::new(&sc, &common::model()).expect("world compiles");
    let robot = sim.robot().clone();
    let plan = plan::run(&sc, &robot, &plan_options()).expect("plan");
    let end = before_rear_step_up(&plan, 1);
    let detailed = run::expand_mission(&sc, &mut sim, &plan, end).expect("prefix expands");
    momaro::jobs::stand_at_start(&mut sim, &sc).expect("stands");
    let s = run::execute(&sc, &mut sim, Mission { plan, detailed }, &opts, wall).expect("runs");
    println!("abort: {:?} / {:?}", s.failure, s.executor_events);
    assert!(s.steps_aborted >= 1 && s.steps_executed == 0, "{s:#?}");
    assert!(
        !s.executor_events.iter().any(|e| matches!(e.event, ExecEventKind::Lift { .. })),
        "a foot was lifted: {:?}",
        s.executor_events
    );
    assert!(s.executor_events.iter().any(|e| matches!(
        e.event,
        ExecEventKind::Failure { failure: ExecFailure::StepAborted { .. } }
    )));
    assert_eq!(s.replans, 1);
    let f = s.failure.clone().expect("the run stopped");
    assert!(f.contains("replan") || f.contains("no replans left"), "{f}");
    // Back at driving height: the base 0.32 m above the ground it stands on (first
    // tread or floor), all eight wheels down, upright.
    let base = sim.base();
    let ground = sc.terrain_height(base.position[0], base.position[1]);
    assert!((base.position[2] - ground - 0.32).abs() < 0.03, "{:?} over {ground}", base.position);
    assert_eq!(sim.wheel_contacts().len(), 8);
    assert!(!s.tipped && s.body_collisions.is_empty(), "{s:#?}");
}
