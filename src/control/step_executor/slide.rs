//! The stance slide: before a step, the whole robot rolls on its four wheel pairs, legs
//! held, until its feet stand on the plan's footholds again.
//!
//! Why it is needed: the legs move only in their sagittal planes, so nothing else can
//! move the stance sideways, yet the plan asks for it. A planned base shift ends on the
//! lattice cell nearest its length along the heading, and its footprint moves with the
//! base (`motion::expand`: "the wheels roll that far"); off the grid's axes that is up to
//! half a cell sideways per shift. Stance wheels also creep under the legs' push (velocity
//! servos). Measured on a generated flight stepped at 22.5° (stairs seed 27), the feet
//! stood 5 cm from their footholds after 12 steps, the base 13 cm to the side of the plan
//! after 24, and the run was stranded by drift; the position hold
//! (`StepExecutor::hold_base`) saturated at its 4 cm trying to carry the base back over
//! feet that were themselves off.
//!
//! How: at the first keyframe of a path element that lifts a foot
//! ([`StepExecutor::starts_a_step`]), the stance's offset from the plan is measured from
//! the wheel contacts MuJoCo reports ([`stance_offset`]: each leg whose two wheels touch
//! stands at their midpoint). Beyond [`ExecutorConfig::slide_threshold_m`] (a cell) every
//! pair steers to the way back (the wheel kinematics' shortest way, at most 90°) and
//! rolls at the same velocity, a pure translation, until the measured base has moved by
//! the offset (closed loop on the base, at most [`ExecutorConfig::slide_speed_mps`],
//! given up after [`ExecutorConfig::max_slide_s`]); then the pairs steer straight again
//! before the step's first segment. The legs keep their targets (the holds are frozen),
//! so the relative geometry of base and feet does not change.
//!
//! A pair steered across its tread puts a wheel over the nosing or against the riser
//! (measured: steering regardless, 4 of 30 generated flights aborted a step, 13 cm of
//! margin gone to 3 cm). So each roll is checked on the height map first
//! ([`StepExecutor::steering_keeps_the_ground`]: the steered pair must rest as the
//! straight one does); where the way straight back fails, the sideways part goes in two
//! rolls at a smaller angle (forward and backward at ±60° … ±20°, their parts along the
//! heading cancelling), and where those fail too, only the part along the heading is
//! rolled, straight, over footholds the plan checked. Where that part is within a cell,
//! nothing rolls: the step goes ahead from where the stance is, and the run's events say
//! so (`SlideRefused`, with the sideways part). On narrow treads every step can end here:
//! a generated flight of 0.284 m treads drifted 5 cm sideways over eight such refusals
//! before a stretched leg lost its tread.

use super::actuation::pairs_in_base;
use super::{Command, ExecEventKind, ExecutorConfig, Mode, Observation, StepExecutor};
use crate::control::wheels::Twist;
use crate::motion::Phase;
use crate::motion::kinematics::Posture;
use crate::robot::{Leg, RobotDescription};

/// Slide speed per metre of remaining offset, 1/s: the speed falls off over the last
/// centimetre, so the pairs do not overshoot into the next manoeuvre.
const SLIDE_GAIN: f64 = 2.0;

/// Remaining offset at which a slide is done, m.
const SLIDE_DONE_M: f64 = 0.002;

/// Steering angle within which a pair counts as straight again after a slide, rad.
const STRAIGHT_RAD: f64 = 0.05;

/// Longest wait for the pairs to steer straight after a slide that ran out of time, s.
const STRAIGHTEN_S: f64 = 2.0;

/// The angles from the heading (degrees, largest first) at which a slide may roll the
/// stance sideways in two rolls where the pairs cannot steer straight across.
const ZIGZAG_ANGLES: [f64; 4] = [60.0, 45.0, 30.0, 20.0];

/// How far a steered pair's wheels may rest from where the straight pair's do, m.
const STEER_REST_TOLERANCE_M: f64 = 0.005;

/// The planar offset (world x, y, m) of the stance from the plan: the mean, over the legs
/// the posture `planned` has in contact and whose two wheels both touch, of the midpoint
/// of the two wheel contacts (the two points of the leg farthest apart, which must lie
/// between half and one and a half wheel tracks apart) less the planned foot. `None` when
/// fewer than two legs can be measured (a single contact lies half a track to one side of
/// its foot, and which side is not known).
pub fn stance_offset(
    robot: &RobotDescription,
    planned: &Posture,
    contacts: &[(Leg, [f64; 2])],
) -> Option<[f64; 2]> {
    let track = robot.wheel_track;
    let mut sum = [0.0; 2];
    let mut n = 0usize;
    for leg in Leg::ALL.into_iter().filter(|l| planned.contact[l.index()]) {
        let pts: Vec<[f64; 2]> =
            contacts.iter().filter(|(l, _)| *l == leg).map(|(_, p)| *p).collect();
        let mut widest: Option<(f64, [f64; 2], [f64; 2])> = None;
        for (k, a) in pts.iter().enumerate() {
            for b in &pts[k + 1..] {
                let d = (a[0] - b[0]).hypot(a[1] - b[1]);
                if widest.is_none_or(|w| d > w.0) {
                    widest = Some((d, *a, *b));
                }
            }
        }
        let Some((d, a, b)) = widest else { continue };
        if !(0.5 * track..=1.5 * track).contains(&d) {
            continue;
        }
        let f = planned.feet[leg.index()];
        sum[0] += 0.5 * (a[0] + b[0]) - f[0];
        sum[1] += 0.5 * (a[1] + b[1]) - f[1];
        n += 1;
    }
    (n >= 2).then(|| sum.map(|s| s / n as f64))
}

/// `p` with every foot moved by `by` (world x, y, m).
fn feet_moved(p: &Posture, by: [f64; 2]) -> Posture {
    let mut q = *p;
    for f in q.feet.iter_mut() {
        f[0] += by[0];
        f[1] += by[1];
    }
    q
}

/// The twist (robot frame) that moves a robot at heading `yaw` toward a remaining world
/// displacement `remaining`: along it at `SLIDE_GAIN` per metre left, at most `max_speed`.
fn slide_twist(remaining: [f64; 2], yaw: f64, max_speed: f64) -> Twist {
    let d = remaining[0].hypot(remaining[1]);
    if d < 1e-12 {
        return Twist::default();
    }
    let v = (SLIDE_GAIN * d).min(max_speed) / d;
    let (s, c) = yaw.sin_cos();
    let (wx, wy) = (remaining[0] * v, remaining[1] * v);
    Twist { vx: c * wx + s * wy, vy: -s * wx + c * wy, wz: 0.0 }
}

impl StepExecutor {
    /// Whether every wheel pair of posture `p` in contact, at its foot and at its foot
    /// moved by `by` (world, m), rests on the height map with its wheels across the
    /// rolling direction `psi` (world yaw, rad) as it does steered straight, within
    /// [`STEER_REST_TOLERANCE_M`]: on a tread, a pair steered across the heading can put a
    /// wheel over the nosing or against the riser the straight pair keeps clear of.
    fn steering_keeps_the_ground(&self, p: &Posture, by: [f64; 2], psi: f64) -> bool {
        let (r, h) = (self.robot.wheel_radius, self.robot.wheel_track / 2.0);
        let rest = |x: f64, y: f64, yaw: f64, top: f64| {
            let (s, c) = yaw.sin_cos();
            let a = self.ground.wheel_rest_height(x - h * s, y + h * c, r, top)?;
            let b = self.ground.wheel_rest_height(x + h * s, y - h * c, r, top)?;
            Some([a, b])
        };
        let yaw = p.base_rpy[2];
        (0..4).filter(|&i| p.contact[i]).all(|i| {
            let f = p.feet[i];
            // Anything up to a metre above the foot holds a wheel up (a riser included).
            let top = f[2] + 1.0;
            [[f[0], f[1]], [f[0] + by[0], f[1] + by[1]]].iter().all(|q| {
                match (rest(q[0], q[1], yaw, top), rest(q[0], q[1], psi, top)) {
                    (Some(a), Some(b)) => {
                        (0..2).all(|k| (a[k] - b[k]).abs() <= STEER_REST_TOLERANCE_M)
                            || (a[0] - b[1]).abs() <= STEER_REST_TOLERANCE_M
                                && (a[1] - b[0]).abs() <= STEER_REST_TOLERANCE_M
                    }
                    _ => false,
                }
            })
        })
    }

    /// The rolls (world displacements, the second zero for one) a stance slide makes for
    /// a stance offset `offset`, each checked with [`Self::steering_keeps_the_ground`]
    /// from where it starts: all of the offset back in one roll if the pairs can steer to
    /// it; else its sideways part in two rolls at the largest of [`ZIGZAG_ANGLES`] from
    /// the heading that the pairs can steer to (one forward, one backward, their parts
    /// along the heading adding up to the offset's, in the order that keeps the ground);
    /// else its part along the heading (rolled straight, over footholds the plan
    /// checked). `None` if what is left is within the threshold.
    fn slide_rolls(&self, offset: [f64; 2]) -> Option<[[f64; 2]; 2]> {
        let back = [-offset[0], -offset[1]];
        let threshold = self.config.slide_threshold_m;
        if back[0].hypot(back[1]) <= threshold {
            return None;
        }
        let p = self.with_offsets(&self.cmd);
        // The feet stand at the planned footholds plus the offset now.
        let now = feet_moved(&p, offset);
        let safe = |rolls: &[[f64; 2]]| {
            let mut at = now;
            rolls.iter().all(|r| {
                let ok = self.steering_keeps_the_ground(&at, *r, r[1].atan2(r[0]));
                at = feet_moved(&at, *r);
                ok
            })
        };
        if safe(&[back]) {
            return Some([back, [0.0; 2]]);
        }
        let (sy, cy) = p.base_rpy[2].sin_cos();
        let world = |a: f64, l: f64| [a * cy - l * sy, a * sy + l * cy];
        let along = back[0] * cy + back[1] * sy;
        let lateral = -back[0] * sy + back[1] * cy;
        if lateral.abs() > threshold {
            for phi in ZIGZAG_ANGLES.map(f64::to_radians) {
                // Forward l1 and backward l2 at ±phi: (l1 − l2) cos phi along the heading,
                // (l1 + l2) sin phi across it.
                let (s, c) = phi.sin_cos();
                let (sum, diff) = (lateral.abs() / s, along / c);
                let (l1, l2) = (0.5 * (sum + diff), 0.5 * (sum - diff));
                if l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let side = lateral.signum();
                let forward = world(l1 * c, side * l1 * s);
                let backward = world(-l2 * c, side * l2 * s);
                for rolls in [[forward, backward], [backward, forward]] {
                    if safe(&rolls) {
                        return Some(rolls);
                    }
                }
            }
        }
        (along.abs() > threshold).then(|| [world(along, 0.0), [0.0; 2]])
    }

    /// Whether keyframe `i` is the first of a path element that lifts a foot (a step's
    /// manoeuvre, from its first alignment to its lift and beyond), the standing robot
    /// having finished the element before.
    pub(super) fn starts_a_step(&self, i: usize) -> bool {
        let Some(k) = self.keys.get(i) else { return false };
        i > 0
            && self.keys[i - 1].path_index != k.path_index
            && self.keys[i..]
                .iter()
                .take_while(|q| q.path_index == k.path_index)
                .any(|q| q.phase == Phase::Lift)
    }

    /// Starts work toward keyframe `index`, the first of a step: a stance slide first if
    /// the feet stand more than the threshold from the plan's footholds (see the module
    /// docs), then the keyframe's own work.
    pub(super) fn check_stance(&mut self, index: usize, obs: &Observation) {
        let offset = stance_offset(&self.robot, &self.cmd, &obs.wheel_contacts);
        match offset.and_then(|o| self.slide_rolls(o).map(|r| (o, r))) {
            Some((o, rolls)) => {
                let net = [rolls[0][0] + rolls[1][0], rolls[0][1] + rolls[1][1]];
                self.event(
                    obs.time,
                    ExecEventKind::Slide {
                        offset_m: o[0].hypot(o[1]),
                        slid_m: net[0].hypot(net[1]),
                        rolls: 1 + usize::from(rolls[1] != [0.0; 2]),
                    },
                );
                self.mode = Mode::Slide {
                    index,
                    start: [obs.base.x, obs.base.y],
                    rolls,
                    roll: 0,
                    elapsed: 0.0,
                    rolling: true,
                };
            }
            None => {
                // Off by more than a cell with no roll that keeps the ground: said, so a
                // drift that builds up step by step on narrow treads is not silent.
                if let Some(o) = offset {
                    let offset_m = o[0].hypot(o[1]);
                    if offset_m > self.config.slide_threshold_m {
                        let (s, c) = self.cmd.base_rpy[2].sin_cos();
                        let lateral_m = -o[0] * s + o[1] * c;
                        self.event(obs.time, ExecEventKind::SlideRefused { offset_m, lateral_m });
                    }
                }
                self.proceed(index)
            }
        }
    }

    /// The work toward keyframe `index` once the stance stands on its footholds: the
    /// lift guard for a lift, else the segment.
    fn proceed(&mut self, index: usize) {
        if self.keys[index].phase == Phase::Lift {
            self.start_guard(index);
        } else {
            self.start_segment(index);
        }
    }

    /// One tick of a stance slide before keyframe `index`: legs held, every pair in
    /// contact rolling the robot through `rolls` (world displacements from `start`, where
    /// the base stood when the slide began; `roll` the one under way), then (`rolling`
    /// false) the pairs steered straight again before the keyframe's work measures the
    /// support they stand on.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn slide_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        index: usize,
        start: [f64; 2],
        rolls: [[f64; 2]; 2],
        mut roll: usize,
        elapsed: f64,
        mut rolling: bool,
    ) -> Command {
        let p = self.with_offsets(&self.cmd);
        let Some(legs) = self.legs_for(&p, obs.time) else { return self.hold() };
        let c: &ExecutorConfig = &self.config;
        let out_of_time = elapsed >= c.max_slide_s;
        let remaining = |roll: usize| {
            let (t0, t1) = if roll == 0 {
                (rolls[0][0], rolls[0][1])
            } else {
                (rolls[0][0] + rolls[1][0], rolls[0][1] + rolls[1][1])
            };
            [t0 - (obs.base.x - start[0]), t1 - (obs.base.y - start[1])]
        };
        let done = |r: [f64; 2]| r[0].hypot(r[1]) < SLIDE_DONE_M;
        if rolling && roll == 0 && done(remaining(0)) && rolls[1] != [0.0; 2] {
            roll = 1;
        }
        if rolling && (done(remaining(roll)) || out_of_time) {
            rolling = false;
        }
        let next = |elapsed| Mode::Slide { index, start, rolls, roll, elapsed, rolling };
        if !rolling {
            let straight = obs.steering.iter().all(|s| s.abs() <= STRAIGHT_RAD);
            if straight || elapsed >= c.max_slide_s + STRAIGHTEN_S {
                self.proceed(index);
            } else {
                self.mode = next(elapsed + dt);
            }
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        let twist = slide_twist(remaining(roll), obs.base.theta, c.slide_speed_mps);
        let feet = pairs_in_base(&self.robot, &p);
        let wheels = c.wheels.commands(&self.robot, twist, &feet, &obs.steering);
        self.mode = next(elapsed + dt);
        Command { legs, wheels: self.with_steer_rate(wheels, obs) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::step_executor::test_support::{
        config, ground, key, obs, robot, standing, step_path,
    };
    use crate::motion::Keyframe;
    use crate::terrain::HeightMap;
    use std::f64::consts::FRAC_PI_4;

    /// Both wheels of every leg touching, the pair across the heading (track 0.12 m),
    /// every foot moved by `by`.
    fn two_wheel_contacts(p: &Posture, by: [f64; 2]) -> Vec<(Leg, [f64; 2])> {
        let h = robot().wheel_track / 2.0;
        Leg::ALL
            .iter()
            .flat_map(|&l| {
                let f = p.feet[l.index()];
                [-h, h].map(|dy| (l, [f[0] + by[0], f[1] + by[1] + dy]))
            })
            .collect()
    }

    /// The step path on flat ground, its stance measured 3 cm to the left of the plan
    /// (the base too) before the lift keyframe: the executor and that observation.
    fn slide_started_3_cm_left() -> (StepExecutor, Observation) {
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let mut o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.0, 0.03]), [0.0; 3]);
        o.base.y = 0.03;
        ex.check_stance(1, &o);
        (ex, o)
    }

    #[test]
    fn the_stance_offset_is_the_mean_of_the_wheel_midpoints_less_the_feet() {
        let r = robot();
        let p = standing();
        let c = two_wheel_contacts(&p, [0.01, -0.03]);
        let o = stance_offset(&r, &p, &c).unwrap();
        assert!((o[0] - 0.01).abs() < 1e-12 && (o[1] + 0.03).abs() < 1e-12, "{o:?}");
        // Front-left 4 cm further ahead than the others: the mean moves by 1 cm.
        let mut c = c;
        for (l, q) in c.iter_mut() {
            if *l == Leg::FrontLeft {
                q[0] += 0.04;
            }
        }
        let o = stance_offset(&r, &p, &c).unwrap();
        assert!((o[0] - 0.02).abs() < 1e-12 && (o[1] + 0.03).abs() < 1e-12, "{o:?}");
    }

    #[test]
    fn legs_with_one_wheel_or_a_lifted_foot_are_not_measured() {
        let r = robot();
        let mut p = standing();
        let mut c = two_wheel_contacts(&p, [0.02, 0.0]);
        // Rear-right touches with one wheel only: half a track to its side, left out.
        let i = c.iter().position(|(l, _)| *l == Leg::RearRight).unwrap();
        c.remove(i);
        // Rear-left is planned in the air (its contacts, wherever they are, left out).
        p.contact[Leg::RearLeft.index()] = false;
        for (l, q) in c.iter_mut() {
            if *l == Leg::RearLeft {
                q[0] += 0.3;
            }
        }
        let o = stance_offset(&r, &p, &c).unwrap();
        assert!((o[0] - 0.02).abs() < 1e-12 && o[1].abs() < 1e-12, "{o:?}");
        // Only front-right left: one leg is not a measurement.
        let c: Vec<_> = c.into_iter().filter(|(l, _)| *l != Leg::FrontLeft).collect();
        assert_eq!(stance_offset(&r, &p, &c), None);
        // Contacts 0.3 m apart are not one pair's two wheels.
        let far: Vec<_> = Leg::ALL
            .iter()
            .flat_map(|&l| {
                let f = standing().feet[l.index()];
                [(l, [f[0], f[1] - 0.15]), (l, [f[0], f[1] + 0.15])]
            })
            .collect();
        assert_eq!(stance_offset(&r, &standing(), &far), None);
    }

    #[test]
    fn the_slide_twist_points_at_the_remaining_offset_in_the_robot_frame() {
        // 1 cm left in the world at heading 90°: the robot's −x' (it rolls backward),
        // at 2/s · 0.01 m = 0.02 m/s; 10 cm left: capped at 0.03 m/s.
        let t = slide_twist([-0.01, 0.0], std::f64::consts::FRAC_PI_2, 0.03);
        assert!((t.vx + 0.0).abs() < 1e-12 && (t.vy - 0.02).abs() < 1e-12, "{t:?}");
        let t = slide_twist([0.0, 0.1], 0.0, 0.03);
        assert!(t.vx.abs() < 1e-12 && (t.vy - 0.03).abs() < 1e-12, "{t:?}");
        assert_eq!(slide_twist([0.0, 0.0], 1.0, 0.03), Twist::default());
    }

    #[test]
    fn feet_off_their_footholds_are_slid_back_before_the_lift_then_the_guard_runs() {
        // The stance stands 3 cm to the left of the plan (+y): the executor slides 3 cm to
        // the right (every pair steered to −90°, rolling), legs held, and once the base
        // has moved by that the lift guard starts.
        let (mut ex, mut o) = slide_started_3_cm_left();
        assert!(matches!(ex.mode, Mode::Slide { .. }), "{:?}", ex.mode);
        assert!(
            ex.events
                .iter()
                .any(|e| matches!(e.event, ExecEventKind::Slide { offset_m, slid_m, rolls: 1 } if (offset_m - 0.03).abs() < 1e-9 && (slid_m - 0.03).abs() < 1e-9))
        );
        let legs_before = ex.last_legs;
        let (cmd, _) = ex.tick(&o, 0.01);
        for w in cmd.wheels {
            // The shortest way to −90° from straight: steer to −π/2 forward.
            assert!((w.steer + std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{w:?}");
        }
        assert_eq!(cmd.legs, legs_before);
        // Half way: still sliding; there: the guard.
        o.base.y = 0.015;
        ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Slide { .. }));
        o.base.y = 0.0005;
        ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
    }

    /// Flat ground with a riser 0.17 m high from `x0` (m) on: ahead of the front feet
    /// (x = 0.35 m) by more than a straight pair's 0.08 m wheel radius.
    fn riser_from(x0: f64) -> HeightMap {
        HeightMap::from_fn([-2.0, -2.0], 0.025, 160, 160, |i, _| {
            if -2.0 + i as f64 * 0.025 >= x0 - 1e-9 { 0.17 } else { 0.0 }
        })
        .unwrap()
    }

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9
    }

    #[test]
    fn a_pair_that_cannot_steer_near_a_riser_slides_only_along_the_heading() {
        // The riser 0.10 m ahead of the front feet: a pair steered by as little as 20°
        // puts a wheel 0.06 · sin 20° = 2 cm forward, against it (a sphere of 8 cm).
        let ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.45));
        // 3 cm to the left: only a sideways roll takes it out: no slide.
        assert_eq!(ex.slide_rolls([0.0, 0.03]), None);
        // 3 cm behind and 3 cm to the left: the 3 cm along the heading.
        let r = ex.slide_rolls([-0.03, 0.03]).unwrap();
        assert!(close(r[0], [0.03, 0.0]) && r[1] == [0.0; 2], "{r:?}");
        // 2 cm behind and 3 cm to the left: the 2 cm along are within a cell: no slide.
        assert_eq!(ex.slide_rolls([-0.02, 0.03]), None);
        // On open ground the whole offset in one roll.
        let ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let r = ex.slide_rolls([-0.02, 0.03]).unwrap();
        assert!(close(r[0], [0.02, -0.03]) && r[1] == [0.0; 2], "{r:?}");
        // Within a cell (2.5 cm) nothing.
        assert_eq!(ex.slide_rolls([0.02, 0.01]), None);
    }

    #[test]
    fn a_pair_that_can_steer_part_way_slides_sideways_in_two_rolls() {
        // The riser 0.125 m ahead of the front feet (x = 0.475 m). Steered straight across
        // (90°) or at 60° a front wheel comes within 8 cm of it (0.35 + 0.06 · sin 60° =
        // 0.402 m); at 45° it stays 0.083 m away. The stance stands 3 cm to the right
        // (−y): two rolls at 45° of 0.03 / (2 sin 45°) = 0.02121 m each, the backward one
        // first (forward first carries the wheel 1.5 cm nearer the riser):
        // (−0.015, +0.015), then (+0.015, +0.015).
        let ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.475));
        let r = ex.slide_rolls([0.0, -0.03]).unwrap();
        assert!(close(r[0], [-0.015, 0.015]) && close(r[1], [0.015, 0.015]), "{r:?}");
    }

    #[test]
    fn a_two_roll_slide_rolls_one_then_the_other() {
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.475));
        let mut o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.0, -0.03]), [0.0; 3]);
        o.base.y = -0.03;
        ex.check_stance(1, &o);
        assert!(matches!(ex.mode, Mode::Slide { roll: 0, .. }), "{:?}", ex.mode);
        // The first roll: backward and to the left, at 45° (reversing the wheels: the
        // pairs steer to −45°, not 135°).
        let (cmd, _) = ex.tick(&o, 0.01);
        assert!(cmd.wheels.iter().all(|w| (w.steer + FRAC_PI_4).abs() < 1e-9), "{cmd:?}");
        // At the end of the first roll the second starts: forward and to the left.
        o.base.x = -0.015;
        o.base.y = -0.015;
        let (cmd, _) = ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Slide { roll: 1, rolling: true, .. }), "{:?}", ex.mode);
        assert!(cmd.wheels.iter().all(|w| (w.steer - FRAC_PI_4).abs() < 1e-9), "{cmd:?}");
        o.base.x = 0.0;
        o.base.y = 0.0;
        ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
    }

    #[test]
    fn after_the_roll_the_pairs_are_steered_straight_before_the_guard() {
        let (mut ex, mut o) = slide_started_3_cm_left();
        // There, but the pairs still stand at −80°: the slide steers them back.
        o.base.y = 0.0;
        o.steering = [-1.4; 4];
        let (cmd, _) = ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Slide { rolling: false, .. }), "{:?}", ex.mode);
        assert!(cmd.wheels.iter().all(|w| w.steer == 0.0), "{:?}", cmd.wheels);
        o.steering = [0.02; 4];
        ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
    }

    #[test]
    fn a_step_starts_at_the_first_keyframe_of_an_element_that_lifts_a_foot() {
        // Elements: 0 the start, 1 a wheel move, 2 a step (wheel to centre, lift, swing,
        // place), 3 a base shift.
        let p = standing();
        let phases = [
            (0, Phase::Start),
            (1, Phase::WheelMove),
            (1, Phase::WheelMove),
            (2, Phase::WheelToCentre),
            (2, Phase::Lift),
            (2, Phase::Swing),
            (2, Phase::Place),
            (3, Phase::PlannedBaseShift),
        ];
        let keys = phases
            .iter()
            .map(|&(e, ph)| Keyframe { path_index: e, ..key(0.0, ph, None, &p) })
            .collect();
        let ex = StepExecutor::new(&robot(), config(), keys, ground());
        let starts: Vec<usize> = (0..9).filter(|&i| ex.starts_a_step(i)).collect();
        assert_eq!(starts, vec![3]);
    }

    #[test]
    fn a_slide_no_pair_can_roll_is_reported_and_the_step_goes_ahead() {
        // 3 cm to the left with a riser 0.10 m ahead of the front feet: no roll keeps the
        // ground (`a_pair_that_cannot_steer_near_a_riser_slides_only_along_the_heading`),
        // so the guard starts, and the refusal is an event with the offset's sideways
        // part (generated stairs drifted 5 cm sideways over eight such silent refusals).
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.45));
        let o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.0, 0.03]), [0.0; 3]);
        ex.check_stance(1, &o);
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
        let refused: Vec<_> = ex
            .events
            .iter()
            .filter_map(|e| match e.event {
                ExecEventKind::SlideRefused { offset_m, lateral_m } => Some((offset_m, lateral_m)),
                _ => None,
            })
            .collect();
        assert_eq!(refused.len(), 1, "{:?}", ex.events);
        assert!((refused[0].0 - 0.03).abs() < 1e-9 && (refused[0].1 - 0.03).abs() < 1e-9);
        // Within a cell: nothing to report.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.45));
        let o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.02, 0.01]), [0.0; 3]);
        ex.check_stance(1, &o);
        assert!(ex.events.is_empty(), "{:?}", ex.events);
    }

    #[test]
    fn feet_within_the_threshold_go_straight_to_the_guard() {
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.02, 0.01]), [0.0; 3]);
        ex.check_stance(1, &o);
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
    }

    #[test]
    fn a_slide_that_does_not_get_there_gives_up_after_its_time() {
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.05, 0.0]), [0.0; 3]);
        ex.check_stance(1, &o);
        // The base never moves: after max_slide_s (500 ticks of 10 ms) the guard runs.
        let ticks = (config().max_slide_s / 0.01).round() as usize;
        for _ in 0..ticks - 1 {
            ex.tick(&o, 0.01);
        }
        assert!(matches!(ex.mode, Mode::Slide { .. }), "{:?}", ex.mode);
        for _ in 0..3 {
            ex.tick(&o, 0.01);
        }
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
    }
}
