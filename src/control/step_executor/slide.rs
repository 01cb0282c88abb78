//! The stance slide: before a step, the whole robot rolls on its four wheel pairs, legs
//! held, until its feet stand on the plan's footholds again, turned as the plan has them.
//!
//! Why it is needed: the legs move only in their sagittal planes, so nothing else can
//! move or turn the stance, yet the plan asks for it. A planned base shift ends on the
//! lattice cell nearest its length along the heading, and its footprint moves with the
//! base (`motion::expand`: "the wheels roll that far"); off the grid's axes that is up to
//! half a cell sideways per shift. Stance wheels also creep under the legs' push (velocity
//! servos). Measured on a generated flight stepped at 22.5° (stairs seed 27), the feet
//! stood 5 cm from their footholds after 12 steps, the base 13 cm to the side of the plan
//! after 24, and the run was stranded by drift; the position hold
//! (`StepExecutor::hold_base`) saturated at its 4 cm trying to carry the base back over
//! feet that were themselves off. And the stance turns: a base rolled (eqs. 6–8) while
//! it is pitched less than the line through its front and rear feet (70 % of the slope,
//! Sec. VI-B) cannot roll about its own x' axis with every foot on its leg's plane; the
//! rigid robot rolls about the feet's line instead, which turns it (measured on a flight
//! of 0.156 m rises, rolled 0.2 rad at 0.35 rad of pitch: 0.03–0.04 rad), and rolled back
//! after a step the feet's line has changed, so the turn stays. A stance 0.03 rad off its
//! heading carries its base sideways by 0.03 m per metre of base shift; on generated
//! stairs the stance drifted 5 cm sideways and 0.05 rad before a stretched leg lost its
//! tread and the robot fell.
//!
//! How: at the first keyframe of a path element that lifts a foot
//! ([`StepExecutor::starts_a_step`]), the stance's error is measured from the wheel
//! contacts MuJoCo reports ([`stance_error`]: each leg whose two wheels touch stands at
//! their midpoint; the shift and turn that best take the footholds onto them). Where a
//! foot stands more than [`ExecutorConfig::slide_threshold_m`] (half a cell) from its
//! foothold, every pair steers to its own way back and rolls: each roll is made along one
//! arc (the constant body twist from where it starts to where it ends, so each pair keeps
//! one steering angle, at most 90° from straight, the one checked on the height map), at a
//! speed set by how much of the arc the measured base has left (closed loop along the arc,
//! pairs at most [`ExecutorConfig::slide_speed_mps`], given up after
//! [`ExecutorConfig::max_slide_s`]); then the pairs steer straight again before the step's
//! first segment. The legs keep their targets (the holds are frozen), so the relative
//! geometry of base and feet does not change.
//!
//! A pair steered across its tread puts a wheel over the nosing or against the riser
//! (measured: steering regardless, 4 of 30 generated flights aborted a step, 13 cm of
//! margin gone to 3 cm). So each roll is checked on the height map first
//! ([`StepExecutor::steering_keeps_the_ground`]: every steered pair must rest as the
//! straight one does, where it starts and where it ends), both from where the rigid fit
//! puts the feet and from where each pair was measured: the fit leaves every foot its own
//! residual, 2–4 cm late in a descent of a flight at 45° to the map, where a roll checked
//! at the fitted feet alone steered a rear pair against the riser its wheels stood 1.5 cm
//! clear of; checked at the measured feet alone, rolls the fit refuses went ahead (a
//! contact midpoint is not always the foot), and a generated flight that climbed was
//! stranded. Where the whole way back fails,
//! the turn goes first on its own: on the spot (each pair 40–50° from the heading), or
//! where that fails in two arcs of half the turn about centres to either side (0.6–2 m
//! away, steering 45–11°; one arc forward and one backward, like a three-point turn);
//! then the shift: straight back; or its sideways part in two rolls at a smaller angle
//! (forward and backward at ±60° … ±20°, their parts along the heading cancelling); or
//! only its part along the heading, straight, over footholds the plan checked. Where
//! nothing can be rolled, the step goes ahead from where the stance is, and the run's
//! events say so (`SlideRefused`, with the sideways part and the turn). On generated
//! flights of 0.284 m treads the arcs turn the stance back where nothing else could
//! (30 generated flights: the one fall is gone, see the README's "Stance slide").

use super::actuation::pairs_in_base;
use super::{Command, ExecEventKind, ExecutorConfig, Mode, Observation, StepExecutor};
use crate::control::wheels::Twist;
use crate::geometry::{Pose2, wrap_angle};
use crate::motion::Phase;
use crate::posture::kinematics::Posture;
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

/// The radii (m, smallest first) of the two arcs by which a slide turns the stance where
/// the pairs cannot steer to a turn on the spot: at 0.6 m a pair steers up to about 45°
/// from the heading, at 2 m about 11°, and the stance rolls turn · radius / 2 along it.
const TURN_ARC_RADII: [f64; 4] = [0.6, 1.0, 1.5, 2.0];

/// How far a steered pair's wheels may rest from where the straight pair's do, m.
const STEER_REST_TOLERANCE_M: f64 = 0.005;

/// Where the stance stands against the plan, measured from the wheel contacts: the planar
/// rigid motion (least squares) that takes the plan's footholds to the measured feet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceError {
    /// The planned feet's centroid (world x, y, m), the centre of [`StanceError::yaw`].
    pub centre: [f64; 2],
    /// How far the measured feet's centroid stands from it (world x, y, m).
    pub offset: [f64; 2],
    /// How far the stance is turned from the plan about its centre (counter-clockwise,
    /// rad); zero when only two legs are measured (one wheel's bounce would turn it).
    pub yaw: f64,
    /// The largest distance of a measured foot from its foothold, m.
    pub worst_m: f64,
    /// Where each measured leg stands (world x, y, m; `Leg` order), `None` for a leg not
    /// measured: the rigid fit leaves each foot its own residual.
    pub feet: [Option<[f64; 2]>; 4],
}

impl StanceError {
    /// The roll that takes the measured stance back onto the plan's footholds.
    fn back(&self) -> Roll {
        let at = [self.centre[0] + self.offset[0], self.centre[1] + self.offset[1]];
        Roll { centre: at, turn: -self.yaw, shift: [-self.offset[0], -self.offset[1]] }
    }

    /// The roll that takes the plan's footholds to where the stance is measured.
    fn forward(&self) -> Roll {
        Roll { centre: self.centre, turn: self.yaw, shift: self.offset }
    }
}

/// The stance's error against posture `planned`, measured over the legs `planned` has in
/// contact whose two wheels both touch: each such leg stands at the midpoint of its two
/// wheel contacts (the two points of the leg farthest apart, which must lie between half
/// and one and a half wheel tracks apart). `None` when fewer than two legs can be
/// measured (a single contact lies half a track to one side of its foot, and which side
/// is not known).
pub fn stance_error(
    robot: &RobotDescription,
    planned: &Posture,
    contacts: &[(Leg, [f64; 2])],
) -> Option<StanceError> {
    let track = robot.wheel_track;
    let mut pairs: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(4);
    let mut feet = [None; 4];
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
        let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        feet[leg.index()] = Some(m);
        pairs.push(([f[0], f[1]], m));
    }
    if pairs.len() < 2 {
        return None;
    }
    let n = pairs.len() as f64;
    let (mut centre, mut measured) = ([0.0; 2], [0.0; 2]);
    for (p, m) in &pairs {
        for k in 0..2 {
            centre[k] += p[k] / n;
            measured[k] += m[k] / n;
        }
    }
    // The turn that best maps the planned feet about their centroid onto the measured
    // ones about theirs (2-D Procrustes).
    let (mut cross, mut dot) = (0.0, 0.0);
    for (p, m) in &pairs {
        let (a, b) =
            ([p[0] - centre[0], p[1] - centre[1]], [m[0] - measured[0], m[1] - measured[1]]);
        cross += a[0] * b[1] - a[1] * b[0];
        dot += a[0] * b[0] + a[1] * b[1];
    }
    let yaw = if pairs.len() >= 3 { cross.atan2(dot) } else { 0.0 };
    let worst_m = pairs.iter().map(|(p, m)| (m[0] - p[0]).hypot(m[1] - p[1])).fold(0.0, f64::max);
    Some(StanceError {
        centre,
        offset: [measured[0] - centre[0], measured[1] - centre[1]],
        yaw,
        worst_m,
        feet,
    })
}

/// A rigid planar motion of the whole robot on its wheels, legs held: a turn by `turn`
/// (rad, counter-clockwise) about `centre` (world x, y, m), then a shift by `shift`
/// (world, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Roll {
    centre: [f64; 2],
    turn: f64,
    shift: [f64; 2],
}

impl Roll {
    /// A shift with no turn.
    fn straight(shift: [f64; 2]) -> Self {
        Self { centre: [0.0; 2], turn: 0.0, shift }
    }

    /// Where the roll takes the world point `x`.
    fn apply(&self, x: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.turn.sin_cos();
        let d = [x[0] - self.centre[0], x[1] - self.centre[1]];
        [
            c * d[0] - s * d[1] + self.centre[0] + self.shift[0],
            s * d[0] + c * d[1] + self.centre[1] + self.shift[1],
        ]
    }

    /// Where the roll takes the base pose `b`.
    fn apply_pose(&self, b: Pose2) -> Pose2 {
        let [x, y] = self.apply([b.x, b.y]);
        Pose2::new(x, y, b.theta + self.turn)
    }
}

/// `p` with the whole robot (feet, base) moved by `roll`.
fn rolled(p: &Posture, roll: &Roll) -> Posture {
    let mut q = *p;
    for f in q.feet.iter_mut() {
        let [x, y] = roll.apply([f[0], f[1]]);
        f[0] = x;
        f[1] = y;
    }
    let b = roll.apply_pose(Pose2::new(p.base_position[0], p.base_position[1], p.base_rpy[2]));
    q.base_position[0] = b.x;
    q.base_position[1] = b.y;
    q.base_rpy[2] = b.theta;
    q
}

/// The constant twist (robot frame of `from`, per unit time) that carries pose `from` to
/// pose `to`: the SE(2) logarithm, a circular arc (a straight line where the two poses
/// have one heading). In the robot's frame every wheel pair moves in one direction along
/// it, so a roll made along its arc keeps each pair at one steering angle.
fn arc_twist(from: Pose2, to: Pose2) -> Twist {
    let turn = wrap_angle(to.theta - from.theta);
    let d = from.inverse_transform([to.x, to.y]);
    // d = V · v with V = [[a, −b], [b, a]], a = sin θ / θ, b = (1 − cos θ) / θ.
    let (a, b) =
        if turn.abs() < 1e-9 { (1.0, 0.0) } else { (turn.sin() / turn, (1.0 - turn.cos()) / turn) };
    let n = a * a + b * b;
    Twist { vx: (a * d[0] + b * d[1]) / n, vy: (-b * d[0] + a * d[1]) / n, wz: turn }
}

/// The velocity of a wheel pair at `foot` (robot frame, m) under `twist`.
fn pair_velocity(twist: Twist, foot: [f64; 2]) -> [f64; 2] {
    [twist.vx - twist.wz * foot[1], twist.vy + twist.wz * foot[0]]
}

/// The twist that continues a roll along its arc `arc` ([`arc_twist`] from the roll's
/// start to its end) from pose `at` toward its end pose `target`, the pairs at `feet`
/// (robot frame): `arc` scaled by `SLIDE_GAIN` times the part of it left (the least-squares
/// fraction over the pairs' displacements, negative past the end), capped so that no pair
/// rolls faster than `max_speed`; and the farthest pair's distance left along the arc (m).
///
/// The direction stays the arc's: the pairs keep the steering the roll was checked with
/// on the height map (`StepExecutor::steering_keeps_the_ground`), and a pair rolls back
/// past the end without steering round. A slide that instead pointed every tick at the
/// whole error left steered its pairs after the error's direction, which turns as the
/// robot nears the target; on an 8-step descent (generated, stairs seed 12072) four
/// loaded pairs swung through 90° within 0.1 s, their steering torques turned the robot
/// 7° on its wheels, and it fell down the flight. What the arc cannot take out (the
/// steering's own reaction turning the robot a little) is measured again before the next
/// step.
fn along_the_arc(
    at: Pose2,
    target: Pose2,
    arc: Twist,
    feet: &[[f64; 2]; 4],
    max_speed: f64,
) -> (Twist, f64) {
    let left = arc_twist(at, target);
    let (mut along, mut norm, mut span) = (0.0, 0.0, 0.0f64);
    for f in feet {
        let (u, v) = (pair_velocity(arc, *f), pair_velocity(left, *f));
        along += u[0] * v[0] + u[1] * v[1];
        norm += u[0] * u[0] + u[1] * u[1];
        span = span.max(u[0].hypot(u[1]));
    }
    if span < 1e-9 {
        return (Twist::default(), 0.0);
    }
    let fraction = along / norm;
    let k = (SLIDE_GAIN * fraction).clamp(-max_speed / span, max_speed / span);
    (Twist { vx: k * arc.vx, vy: k * arc.vy, wz: k * arc.wz }, fraction.abs() * span)
}

impl StepExecutor {
    /// Whether every wheel pair of posture `p` in contact, where it stands and where
    /// `roll` takes it, rests on the height map with its wheels across the direction it
    /// rolls in (world yaw) as it does steered straight, within
    /// [`STEER_REST_TOLERANCE_M`]: on a tread, a pair steered across the heading can put a
    /// wheel over the nosing or against the riser the straight pair keeps clear of. A pair
    /// the roll moves by less than a millimetre keeps its steering.
    fn steering_keeps_the_ground(&self, p: &Posture, roll: &Roll) -> bool {
        let (r, h) = (self.robot.wheel_radius, self.robot.wheel_track / 2.0);
        let rest = |x: f64, y: f64, yaw: f64, top: f64| {
            let (s, c) = yaw.sin_cos();
            let a = self.ground.wheel_rest_height(x - h * s, y + h * c, r, top)?;
            let b = self.ground.wheel_rest_height(x + h * s, y - h * c, r, top)?;
            Some([a, b])
        };
        let yaw = p.base_rpy[2];
        let end_yaw = yaw + roll.turn;
        (0..4).filter(|&i| p.contact[i]).all(|i| {
            let f = p.feet[i];
            let to = roll.apply([f[0], f[1]]);
            let d = [to[0] - f[0], to[1] - f[1]];
            if d[0].hypot(d[1]) < 1e-3 {
                return true;
            }
            let psi = d[1].atan2(d[0]);
            // Anything up to a metre above the foot holds a wheel up (a riser included).
            let top = f[2] + 1.0;
            [([f[0], f[1]], yaw), (to, end_yaw)].iter().all(|(q, straight)| {
                match (rest(q[0], q[1], *straight, top), rest(q[0], q[1], psi, top)) {
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

    /// Whether the rolls, one after the other from each of the stances `from` (the same
    /// robot with its feet by each estimate), each keep the ground
    /// ([`Self::steering_keeps_the_ground`]).
    fn rolls_keep_the_ground(&self, from: &[Posture], rolls: &[Roll]) -> bool {
        from.iter().all(|p| {
            let mut at = *p;
            rolls.iter().all(|r| {
                let ok = self.steering_keeps_the_ground(&at, r);
                at = rolled(&at, r);
                ok
            })
        })
    }

    /// The rolls a stance slide makes for the stance error `err`, each checked with
    /// [`Self::steering_keeps_the_ground`] from where it starts: all of the error back in
    /// one roll (turn and shift) if the pairs can steer to it; else, where the turn moves
    /// a foot by more than [`SLIDE_DONE_M`], the turn as [`Self::turn_rolls`] finds it (on
    /// the spot or in two arcs), then the shift as [`Self::shift_rolls`] finds it; else
    /// the shift alone. `None` if no foot stands more than the threshold from its foothold,
    /// or nothing can be rolled.
    fn slide_rolls(&self, err: &StanceError) -> Option<Vec<Roll>> {
        if err.worst_m <= self.config.slide_threshold_m {
            return None;
        }
        let p = self.with_offsets(&self.cmd);
        // The feet stand where the error puts the planned footholds (the rigid fit), or
        // each measured one where it was measured: a roll is made only if it keeps the
        // ground from both.
        let fitted = rolled(&p, &err.forward());
        let mut measured = fitted;
        for (f, m) in measured.feet.iter_mut().zip(err.feet) {
            if let Some(m) = m {
                f[0] = m[0];
                f[1] = m[1];
            }
        }
        let now = [fitted, measured];
        let back = err.back();
        if self.rolls_keep_the_ground(&now, &[back]) {
            return Some(vec![back]);
        }
        let reach = (0..4)
            .map(|i| (fitted.feet[i][0] - back.centre[0]).hypot(fitted.feet[i][1] - back.centre[1]))
            .fold(0.0, f64::max);
        let mut rolls = Vec::with_capacity(4);
        if err.yaw.abs() * reach > SLIDE_DONE_M {
            rolls = self.turn_rolls(&now, back.centre, -err.yaw);
        }
        let from = now.map(|p| rolls.iter().fold(p, |q, r| rolled(&q, r)));
        // The turns keep the stance's centre where it was, up to the arcs' second order.
        let centre = rolls.iter().fold(back.centre, |c, r| r.apply(c));
        let target = [err.centre[0] - centre[0], err.centre[1] - centre[1]];
        rolls.extend(self.shift_rolls(&from, target));
        (!rolls.is_empty()).then_some(rolls)
    }

    /// The rolls that turn the stance `from` (fitted and measured feet, one base) by
    /// `turn` (rad) about `centre`: the turn on the spot if the pairs can steer to it
    /// (each pair across its radius, 40–50° from the heading); else two arcs of half the
    /// turn each, about centres [`TURN_ARC_RADII`] to either side (the first arc forward
    /// and the second backward, or the other way, like a three-point turn), with the
    /// smallest radius whose steering keeps the ground: at radius R a pair steers about
    /// atan(0.35 / (R − 0.32)) from the heading and the stance rolls turn · R / 2 along it
    /// and back. None where nothing keeps the ground.
    fn turn_rolls(&self, from: &[Posture; 2], centre: [f64; 2], turn: f64) -> Vec<Roll> {
        let on_the_spot = Roll { centre, turn, shift: [0.0; 2] };
        if self.rolls_keep_the_ground(from, &[on_the_spot]) {
            return vec![on_the_spot];
        }
        let half = 0.5 * turn;
        // The unit vectors to the robot's left before the turn and half way through it.
        let left = |yaw: f64| [-yaw.sin(), yaw.cos()];
        let yaw = from[0].base_rpy[2];
        let (n, n1) = (left(yaw), left(yaw + half));
        for radius in TURN_ARC_RADII {
            for side in [1.0, -1.0] {
                // The first arc's centre `radius` to the left (side 1) or right of the
                // stance centre; the second's as far to the other side of where the first
                // leaves it.
                let first = Roll {
                    centre: [centre[0] + side * radius * n[0], centre[1] + side * radius * n[1]],
                    turn: half,
                    shift: [0.0; 2],
                };
                let c1 = first.apply(centre);
                let second = Roll {
                    centre: [c1[0] - side * radius * n1[0], c1[1] - side * radius * n1[1]],
                    turn: half,
                    shift: [0.0; 2],
                };
                if self.rolls_keep_the_ground(from, &[first, second]) {
                    return vec![first, second];
                }
            }
        }
        Vec::new()
    }

    /// The rolls that shift the stance `from` (fitted and measured feet, one base) by
    /// `back` (world, m): all of it in one roll if the pairs can steer to it; else its
    /// sideways part in two rolls at the largest of [`ZIGZAG_ANGLES`] from the heading
    /// that the pairs can steer to (one forward, one backward, their parts along the
    /// heading adding up to the shift's, in the order that keeps the ground); else its
    /// part along the heading (rolled straight, over footholds the plan checked) if that
    /// is more than the threshold; else none.
    fn shift_rolls(&self, from: &[Posture; 2], back: [f64; 2]) -> Vec<Roll> {
        let threshold = self.config.slide_threshold_m;
        if back[0].hypot(back[1]) <= threshold {
            return Vec::new();
        }
        let whole = Roll::straight(back);
        if self.rolls_keep_the_ground(from, &[whole]) {
            return vec![whole];
        }
        let (sy, cy) = from[0].base_rpy[2].sin_cos();
        let world = |a: f64, l: f64| Roll::straight([a * cy - l * sy, a * sy + l * cy]);
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
                    if self.rolls_keep_the_ground(from, &rolls) {
                        return rolls.to_vec();
                    }
                }
            }
        }
        if along.abs() > threshold { vec![world(along, 0.0)] } else { Vec::new() }
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
    /// a foot stands more than the threshold from the plan's foothold (see the module
    /// docs), then the keyframe's own work.
    pub(super) fn check_stance(&mut self, index: usize, obs: &Observation) {
        let err = stance_error(&self.robot, &self.cmd, &obs.wheel_contacts);
        match err.and_then(|e| self.slide_rolls(&e).map(|r| (e, r))) {
            Some((e, rolls)) => {
                let start = obs.base;
                let end = rolls.iter().fold(start, |b, r| r.apply_pose(b));
                self.event(
                    obs.time,
                    ExecEventKind::Slide {
                        offset_m: e.offset[0].hypot(e.offset[1]),
                        yaw_rad: e.yaw,
                        slid_m: (end.x - start.x).hypot(end.y - start.y),
                        turned_rad: wrap_angle(end.theta - start.theta),
                        rolls: rolls.len(),
                    },
                );
                self.mode =
                    Mode::Slide { index, start, rolls, roll: 0, elapsed: 0.0, rolling: true };
            }
            None => {
                // Off by more than the threshold with no roll that keeps the ground: said,
                // so a drift that builds up step by step on narrow treads is not silent.
                if let Some(e) = err
                    && e.worst_m > self.config.slide_threshold_m
                {
                    let (s, c) = self.cmd.base_rpy[2].sin_cos();
                    self.event(
                        obs.time,
                        ExecEventKind::SlideRefused {
                            offset_m: e.offset[0].hypot(e.offset[1]),
                            lateral_m: -e.offset[0] * s + e.offset[1] * c,
                            yaw_rad: e.yaw,
                        },
                    );
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
    /// contact rolling the robot through `rolls` (from `start`, the base pose when the
    /// slide began; `roll` the one under way), then (`rolling` false) the pairs steered
    /// straight again before the keyframe's work measures the support they stand on.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn slide_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        index: usize,
        start: Pose2,
        rolls: Vec<Roll>,
        mut roll: usize,
        elapsed: f64,
        mut rolling: bool,
    ) -> Command {
        let p = self.with_offsets(&self.cmd);
        let Some(legs) = self.legs_for(&p, obs.time) else { return self.hold() };
        let c: &ExecutorConfig = &self.config;
        let out_of_time = elapsed >= c.max_slide_s;
        let feet = pairs_in_base(&self.robot, &p);
        let max_speed = c.slide_speed_mps;
        // The base pose at the end of roll `k`, and the arc it is made along.
        let target = |k: usize| rolls[..=k].iter().fold(start, |b, r| r.apply_pose(b));
        let arc = |k: usize| arc_twist(if k == 0 { start } else { target(k - 1) }, target(k));
        let toward = |k: usize| along_the_arc(obs.base, target(k), arc(k), &feet, max_speed);
        // The roll under way and what it commands; a roll with less than `SLIDE_DONE_M`
        // of its arc left is done.
        let (mut twist, mut left) = toward(roll);
        while rolling && roll + 1 < rolls.len() && left < SLIDE_DONE_M {
            roll += 1;
            (twist, left) = toward(roll);
        }
        if rolling && (left < SLIDE_DONE_M || out_of_time) {
            rolling = false;
        }
        if !rolling {
            let straight = obs.steering.iter().all(|s| s.abs() <= STRAIGHT_RAD);
            if straight || elapsed >= c.max_slide_s + STRAIGHTEN_S {
                self.proceed(index);
            } else {
                self.mode =
                    Mode::Slide { index, start, rolls, roll, elapsed: elapsed + dt, rolling };
            }
            return Command { legs, wheels: self.rolling(&p, &[[0.0; 2]; 4], obs) };
        }
        let wheels = c.wheels.commands(&self.robot, twist, &feet, &obs.steering);
        self.mode = Mode::Slide { index, start, rolls, roll, elapsed: elapsed + dt, rolling };
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

    /// The stance error of a stance shifted by `offset` and not turned (the standing
    /// feet's centroid is the origin).
    fn shifted(offset: [f64; 2]) -> StanceError {
        StanceError {
            centre: [0.0; 2],
            offset,
            yaw: 0.0,
            worst_m: offset[0].hypot(offset[1]),
            feet: [None; 4],
        }
    }

    #[test]
    fn the_stance_error_fits_a_shift_and_a_turn_to_the_wheel_midpoints() {
        let r = robot();
        let p = standing();
        let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // Shifted by (0.01, −0.03): every foot √(0.01² + 0.03²) = 0.031623 m off.
        let e = stance_error(&r, &p, &two_wheel_contacts(&p, [0.01, -0.03])).unwrap();
        assert!(near(e.offset[0], 0.01) && near(e.offset[1], -0.03) && near(e.yaw, 0.0), "{e:?}");
        assert!(near(e.centre[0], 0.0) && near(e.centre[1], 0.0));
        assert!((e.worst_m - 0.031623).abs() < 1e-6, "{e:?}");
        // Each leg where its two wheels' midpoint is.
        let fr = p.feet[Leg::FrontRight.index()];
        assert_eq!(e.feet[Leg::FrontRight.index()], Some([fr[0] + 0.01, fr[1] - 0.03]));
        // Turned by 0.02 rad about the centroid (the origin) and shifted 1 cm along y:
        // the feet at 0.4749 m from it move 0.4749 · 0.02 = 9.5 mm around it.
        let turn = Roll { centre: [0.0; 2], turn: 0.02, shift: [0.0, 0.01] };
        let e = stance_error(&r, &p, &two_wheel_contacts(&rolled(&p, &turn), [0.0; 2])).unwrap();
        assert!(near(e.yaw, 0.02) && near(e.offset[0], 0.0) && near(e.offset[1], 0.01), "{e:?}");
        // Front-left 4 cm further ahead than the others: the centroid moves 1 cm, and the
        // turn that fits best is atan2(Σ a × b, Σ a · b) over the feet about their
        // centroids: Σ a × b = −(0.32 · 0.03 + 3 · 0.32 · 0.01) = −0.0128 and
        // Σ a · b = 4 · (0.35² + 0.32²) + 0.35 · 0.03 + 0.35 · 0.01 = 0.9136: −0.014010 rad.
        let mut c = two_wheel_contacts(&p, [0.0; 2]);
        for (l, q) in c.iter_mut() {
            if *l == Leg::FrontLeft {
                q[0] += 0.04;
            }
        }
        let e = stance_error(&r, &p, &c).unwrap();
        assert!(near(e.offset[0], 0.01) && near(e.offset[1], 0.0), "{e:?}");
        assert!((e.yaw + 0.014010).abs() < 1e-6 && near(e.worst_m, 0.04), "{e:?}");
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
        // Two legs measured: their shift, and no turn (one wheel's bounce would make one).
        let e = stance_error(&r, &p, &c).unwrap();
        assert!((e.offset[0] - 0.02).abs() < 1e-12 && e.offset[1].abs() < 1e-12, "{e:?}");
        assert_eq!(e.yaw, 0.0);
        // Only front-right left: one leg is not a measurement.
        let c: Vec<_> = c.into_iter().filter(|(l, _)| *l != Leg::FrontLeft).collect();
        assert_eq!(stance_error(&r, &p, &c), None);
        // Contacts 0.3 m apart are not one pair's two wheels.
        let far: Vec<_> = Leg::ALL
            .iter()
            .flat_map(|&l| {
                let f = standing().feet[l.index()];
                [(l, [f[0], f[1] - 0.15]), (l, [f[0], f[1] + 0.15])]
            })
            .collect();
        assert_eq!(stance_error(&r, &standing(), &far), None);
    }

    #[test]
    fn the_arc_twist_is_the_constant_body_twist_between_two_poses() {
        use std::f64::consts::FRAC_PI_2;
        let near = |t: Twist, e: [f64; 3]| {
            (t.vx - e[0]).abs() < 1e-12
                && (t.vy - e[1]).abs() < 1e-12
                && (t.wz - e[2]).abs() < 1e-12
        };
        // 1 cm along −x in the world at heading 90°: the robot's +y' (its left is −x).
        let t = arc_twist(Pose2::new(0.0, 0.0, FRAC_PI_2), Pose2::new(-0.01, 0.0, FRAC_PI_2));
        assert!(near(t, [0.0, 0.01, 0.0]), "{t:?}");
        // A quarter circle of radius 1 to the left, (0, 0, 0) to (1, 1, 90°): forward at
        // π/2 per unit time, turning at π/2 (a = b = 2/π, so v = (a + b) / (a² + b²) = π/2).
        let t = arc_twist(Pose2::new(0.0, 0.0, 0.0), Pose2::new(1.0, 1.0, FRAC_PI_2));
        assert!(near(t, [FRAC_PI_2, 0.0, FRAC_PI_2]), "{t:?}");
        // A turn on the spot.
        let t = arc_twist(Pose2::new(0.5, 0.5, 0.3), Pose2::new(0.5, 0.5, 0.28));
        assert!(near(t, [0.0, 0.0, -0.02]), "{t:?}");
    }

    #[test]
    fn a_roll_goes_along_its_arc_at_a_speed_set_by_what_is_left_of_it() {
        let feet = pairs_in_base(&robot(), &standing());
        let near = |t: Twist, e: [f64; 3]| {
            (t.vx - e[0]).abs() < 1e-12
                && (t.vy - e[1]).abs() < 1e-12
                && (t.wz - e[2]).abs() < 1e-12
        };
        // 3 cm to the right (−y), from the origin.
        let arc = arc_twist(Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.0, -0.03, 0.0));
        let target = Pose2::new(0.0, -0.03, 0.0);
        // At the start: 2/s · 0.03 m = 0.06 m/s, capped at 0.03 m/s; 3 cm left.
        let (t, left) = along_the_arc(Pose2::new(0.0, 0.0, 0.0), target, arc, &feet, 0.03);
        assert!(near(t, [0.0, -0.03, 0.0]) && (left - 0.03).abs() < 1e-12, "{t:?} {left}");
        // 1 cm left: 2/s · 0.01 m along −y; with the base also 1 cm ahead of the arc, only
        // the part along the arc counts (the pairs keep their steering): the same.
        let (t, left) = along_the_arc(Pose2::new(0.0, -0.02, 0.0), target, arc, &feet, 0.03);
        assert!(near(t, [0.0, -0.02, 0.0]) && (left - 0.01).abs() < 1e-12, "{t:?} {left}");
        let at = Pose2::new(0.01, -0.02, 0.0);
        let (t, _) = along_the_arc(at, target, arc, &feet, 0.03);
        assert!(near(t, [0.0, -0.02, 0.0]), "{t:?}");
        // Half a centimetre past the end: back along the arc at 0.01 m/s.
        let (t, left) = along_the_arc(Pose2::new(0.0, -0.035, 0.0), target, arc, &feet, 0.03);
        assert!(near(t, [0.0, 0.01, 0.0]) && (left - 0.005).abs() < 1e-12, "{t:?} {left}");
        // A turn of 0.02 rad on the spot: the farthest pair, √(0.35² + 0.32²) = 0.474 m out,
        // has 9.5 mm to go, at 2/s: 0.04 rad/s.
        let arc = arc_twist(Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.0, 0.0, 0.02));
        let (t, left) =
            along_the_arc(Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.0, 0.0, 0.02), arc, &feet, 0.03);
        assert!(near(t, [0.0, 0.0, 0.04]), "{t:?}");
        assert!((left - 0.02 * 0.35f64.hypot(0.32)).abs() < 1e-12, "{left}");
        // No arc: nothing to do.
        let none = Twist::default();
        assert_eq!(along_the_arc(at, at, none, &feet, 0.03), (Twist::default(), 0.0));
    }

    #[test]
    fn a_sliding_pair_keeps_the_steering_its_roll_was_checked_with() {
        // Sliding 3 cm to the right (pairs steered to −90°); 2 cm done, the robot 1 cm
        // ahead of its way and turned 0.01 rad by the steering's reaction. Pointing at the
        // whole error left steered each pair elsewhere (−90° − 45° and more, each its own
        // way with the turn): on a stair descent, four loaded pairs chasing the error's
        // direction swung through 90° in 0.1 s and the robot fell (stairs seed 12072).
        let (mut ex, mut o) = slide_started_3_cm_left();
        o.steering = [-std::f64::consts::FRAC_PI_2; 4];
        o.base = Pose2::new(0.01, 0.01, 0.01);
        let (cmd, _) = ex.tick(&o, 0.01);
        for w in cmd.wheels {
            assert!((w.steer + std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{w:?}");
            // Rolling on, toward −y (forward along the steering), all pairs alike.
            assert!(w.wheel_speeds[0] > 0.0, "{w:?}");
            assert!((w.wheel_speeds[0] - cmd.wheels[0].wheel_speeds[0]).abs() < 1e-12);
        }
        assert!(matches!(ex.mode, Mode::Slide { .. }), "{:?}", ex.mode);
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
                .any(|e| matches!(e.event, ExecEventKind::Slide { offset_m, slid_m, rolls: 1, turned_rad, .. } if (offset_m - 0.03).abs() < 1e-9 && (slid_m - 0.03).abs() < 1e-9 && turned_rad.abs() < 1e-12))
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
        assert_eq!(shifts(&ex, [0.0, 0.03]), None);
        // 3 cm behind and 3 cm to the left: the 3 cm along the heading.
        let r = shifts(&ex, [-0.03, 0.03]).unwrap();
        assert!(r.len() == 1 && close(r[0], [0.03, 0.0]), "{r:?}");
        // 1 cm behind and 3 cm to the left: the 1 cm along is within the threshold (half
        // a cell, 1.25 cm): no slide.
        assert_eq!(shifts(&ex, [-0.01, 0.03]), None);
        // On open ground the whole offset in one roll.
        let ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let r = shifts(&ex, [-0.02, 0.03]).unwrap();
        assert!(r.len() == 1 && close(r[0], [0.02, -0.03]), "{r:?}");
        // Within half a cell (1.25 cm) nothing; 2 cm ahead and 1 cm to the left, which a
        // threshold of a cell let be, rolled back.
        assert_eq!(shifts(&ex, [0.01, 0.005]), None);
        let r = shifts(&ex, [0.02, 0.01]).unwrap();
        assert!(r.len() == 1 && close(r[0], [-0.02, -0.01]), "{r:?}");
    }

    /// The shifts of the rolls a slide makes for a stance shifted by `offset`, none of
    /// which turns.
    fn shifts(ex: &StepExecutor, offset: [f64; 2]) -> Option<Vec<[f64; 2]>> {
        let rolls = ex.slide_rolls(&shifted(offset))?;
        assert!(rolls.iter().all(|r| r.turn == 0.0), "{rolls:?}");
        Some(rolls.iter().map(|r| r.shift).collect())
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
        let r = shifts(&ex, [0.0, -0.03]).unwrap();
        assert!(r.len() == 2 && close(r[0], [-0.015, 0.015]) && close(r[1], [0.015, 0.015]));
    }

    #[test]
    fn a_roll_is_checked_where_each_pair_was_measured_not_where_the_fit_puts_it() {
        // The stance measured 3 cm to the left (+y), the front pairs 5 cm ahead of their
        // footholds as well (x = 0.40 m, the rear ones at −0.35 m): the rigid fit moves
        // every foothold by (0.025, 0.03) and turns none, which puts the front feet at
        // x = 0.375 m, 2.5 cm behind where their wheels touch. All of it back in one roll
        // steers every pair to roll along (−0.025, −0.03), its axle along (0.768, −0.640):
        // a front wheel 0.06 · 0.768 = 0.0461 m ahead of its foot. With a riser from
        // x = 0.5136 m, a sphere of 8 cm there reaches 0.375 + 0.0461 + 0.08 = 0.5011 m
        // from the fitted foot (clear by 1.25 cm) but 0.5261 m from the measured one
        // (1.25 cm into the riser), which steered straight reaches 0.48 m. On a diagonal
        // stair descent the fit's residuals grew to 2-4 cm, and a roll checked at the fit
        // steered a rear pair against the riser: the chassis rocked, the CoM 1.7 cm
        // outside the wheels that touched.
        // Columns from i = 100: x ≥ −1.9864 + 100 · 0.025 = 0.5136 m.
        let height = |i: usize, _: usize| if i >= 100 { 0.17 } else { 0.0 };
        let riser = HeightMap::from_fn([-1.9864, -2.0], 0.025, 160, 160, height).unwrap();
        let ex = StepExecutor::new(&robot(), config(), step_path(), riser);
        let p = standing();
        let contacts: Vec<(Leg, [f64; 2])> = two_wheel_contacts(&p, [0.0, 0.03])
            .into_iter()
            .map(|(l, c)| (l, if l.is_front() { [c[0] + 0.05, c[1]] } else { c }))
            .collect();
        let err = stance_error(&robot(), &p, &contacts).unwrap();
        let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(near(err.offset[0], 0.025) && near(err.offset[1], 0.03) && near(err.yaw, 0.0));
        let fl = err.feet[Leg::FrontLeft.index()].unwrap();
        assert!(near(fl[0], 0.40) && near(fl[1], 0.35), "{fl:?}");
        // Checked at the fit alone, the one roll back would keep the ground; where the
        // pairs stand, it does not, and the slide takes another way.
        let fitted = rolled(&p, &err.forward());
        assert!(ex.rolls_keep_the_ground(&[fitted], &[err.back()]));
        let rolls = ex.slide_rolls(&err).unwrap();
        assert_ne!(rolls, vec![err.back()]);
        assert!(rolls.len() == 2 && rolls.iter().all(|r| r.turn == 0.0), "{rolls:?}");
    }

    /// The stance of [`standing`] turned by `yaw` (rad) about its centre (the origin),
    /// measured on every wheel.
    fn turned_contacts(yaw: f64) -> Vec<(Leg, [f64; 2])> {
        let turn = Roll { centre: [0.0; 2], turn: yaw, shift: [0.0; 2] };
        two_wheel_contacts(&rolled(&standing(), &turn), [0.0; 2])
    }

    #[test]
    fn a_turned_stance_is_turned_back_on_the_spot_on_open_ground() {
        // Turned 0.06 rad: the feet, 0.4749 m from the centre, stand 2.85 cm from their
        // footholds (more than a cell). On open ground one roll turns it back, every pair
        // steered across its radius: front-left at (0.35, 0.32) moves along
        // (0.32, −0.35) for a turn to the right, −47.6° from the heading.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let mut o = obs(0.0, &ex, &turned_contacts(0.06), [0.0; 3]);
        o.base.theta = 0.06;
        ex.check_stance(1, &o);
        let Mode::Slide { ref rolls, .. } = ex.mode else { panic!("{:?}", ex.mode) };
        assert_eq!(rolls.len(), 1);
        assert!((rolls[0].turn + 0.06).abs() < 1e-9 && close(rolls[0].shift, [0.0; 2]));
        assert!(ex.events.iter().any(|e| matches!(e.event,
            ExecEventKind::Slide { yaw_rad, turned_rad, rolls: 1, .. }
                if (yaw_rad - 0.06).abs() < 1e-9 && (turned_rad + 0.06).abs() < 1e-9)));
        o.steering = [0.0; 4];
        let (cmd, _) = ex.tick(&o, 0.01);
        let fl = cmd.wheels[Leg::FrontLeft.index()].steer;
        assert!((fl - (-0.35f64).atan2(0.32)).abs() < 0.01, "{fl}");
        // Turned back (the pairs straight again, as
        // `after_the_roll_the_pairs_are_steered_straight_before_the_guard` has them): the
        // guard.
        o.base.theta = 0.0;
        ex.tick(&o, 0.01);
        assert!(matches!(ex.mode, Mode::Guard { index: 1, .. }), "{:?}", ex.mode);
    }

    #[test]
    fn near_a_riser_a_turn_goes_in_two_arcs_like_a_three_point_turn() {
        // The riser 0.12 m ahead of the front feet (x = 0.47 m): a front pair steered
        // 47.6° to turn on the spot reaches 0.35 + 0.08 + 0.06 · sin 47.6° = 0.474 m,
        // against it; on arcs of a larger radius the pairs steer less.
        let ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.47));
        let err = stance_error(&robot(), &standing(), &turned_contacts(0.06)).unwrap();
        let now = rolled(&standing(), &err.forward());
        let on_the_spot = Roll { shift: [0.0; 2], ..err.back() };
        assert!(!ex.rolls_keep_the_ground(&[now], &[on_the_spot]));
        let rolls = ex.slide_rolls(&err).unwrap();
        assert_eq!(rolls.len(), 2, "{rolls:?}");
        // Each arc half the turn, about centres on either side of the stance, at least
        // the smallest radius away, the same distance.
        let d: Vec<f64> = rolls.iter().map(|r| r.centre[0].hypot(r.centre[1])).collect();
        for r in &rolls {
            assert!((r.turn + 0.03).abs() < 1e-9 && r.shift == [0.0; 2], "{r:?}");
        }
        assert!(d[0] >= TURN_ARC_RADII[0] - 1e-9 && (d[0] - d[1]).abs() < 0.02, "{d:?}");
        assert!(rolls[0].centre[1] * rolls[1].centre[1] < 0.0, "{rolls:?}");
        // Together: turned back, the stance's centre where it was within a few mm.
        let end = rolls.iter().fold(Pose2::new(0.0, 0.0, 0.06), |b, r| r.apply_pose(b));
        assert!(end.theta.abs() < 1e-9 && end.x.hypot(end.y) < 0.005, "{end:?}");
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
                ExecEventKind::SlideRefused { offset_m, lateral_m, .. } => {
                    Some((offset_m, lateral_m))
                }
                _ => None,
            })
            .collect();
        assert_eq!(refused.len(), 1, "{:?}", ex.events);
        assert!((refused[0].0 - 0.03).abs() < 1e-9 && (refused[0].1 - 0.03).abs() < 1e-9);
        // Within the threshold: nothing to report.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), riser_from(0.45));
        let o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.01, 0.005]), [0.0; 3]);
        ex.check_stance(1, &o);
        assert!(ex.events.is_empty(), "{:?}", ex.events);
    }

    #[test]
    fn feet_within_the_threshold_go_straight_to_the_guard() {
        // Half a cell.
        assert!((config().slide_threshold_m - 0.0125).abs() < 1e-12);
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let o = obs(0.0, &ex, &two_wheel_contacts(&standing(), [0.01, 0.005]), [0.0; 3]);
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
