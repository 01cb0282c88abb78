//! A whole-robot posture and what it implies: per-leg IK, leg heights, CoM and static
//! stability (Sec. VI-A).
//!
//! A [`Posture`] is the base pose (position, roll/pitch/yaw) and the four wheel contact
//! points in the world. Each leg's contact point is expressed in the base frame and solved
//! with the sagittal leg IK (`robot::ik::leg_ik`, wheel level for the base pitch). A rolled
//! base tilts the legs' sagittal planes; the contact's lateral offset from the hip plane
//! (a few millimetres for the rolls used) is taken up by the compliant legs and foam wheels
//! (Sec. VI-A) and is bounded by [`MAX_LATERAL_MISMATCH_M`] for feet in contact.
//!
//! On four feet the offsets' diagonal part, the *stance twist* ([`stance_twist`]), is
//! bounded apart ([`MAX_STANCE_TWIST_M`]): a roll over feet on different levels asks the
//! front and rear pairs for different lateral shifts, which no placement of the rigid base
//! gives and the compliance takes only so far.

use super::CenterOfMassModel;
use crate::geometry::{Pose2, norm2};
use crate::robot::ik::{IkError, LegChain, leg_chain, leg_ik, world_down};
use crate::robot::{Leg, RobotDescription};
use crate::support::{stability_margin, with_hull};
use serde::Serialize;

/// Largest lateral offset of a contact point from its hip's sagittal plane accepted for a
/// foot in contact, m.
pub const MAX_LATERAL_MISMATCH_M: f64 = 0.03;

/// Largest stance twist ([`stance_twist`]) accepted on four feet in contact, m.
///
/// The legs bend only in their own planes, so a base rolled by φ asks each foot for a
/// lateral shift of its depth below the hip times tan φ. Feet on one level, or on two
/// levels front and rear (a platform, a flight head-on), ask every leg of a pair the same,
/// and the base's lateral place and yaw take it up: no twist. One foot on another level
/// than the other three (a front foot stepped down at an angle to an edge, then its
/// partner rolled away from it) asks for a twist of a quarter of the level difference times
/// tan φ: 1.5 cm at 0.3 m and 0.2 rad. In closed loop the base then does not roll (0.05 of
/// 0.2 rad commanded), pitches over the front wheels instead and unloads the rear ones: six
/// of 25 generated mixed courses (`generate --seed 1 --count 200`, planned with the wheel
/// pair's footprint and every manoeuvre) tipped so at 1.4 cm, and passed with rolls held
/// to 1 cm (1.5 and 2 cm left all six tipping). Steps that need more roll over such a
/// stance shift the CoM by the other means the generator has (a wheel toward the centre,
/// a base shift), or are not offered.
pub const MAX_STANCE_TWIST_M: f64 = 0.01;

/// The stance twist of contact points `local` (each relative to its hip, base frame, `Leg`
/// order): `Σ s_i y'_i / 4` with `s` = [`Leg::diagonal_sign`], the part of the feet's
/// lateral offsets from their leg planes that neither the base's lateral place, nor its
/// yaw, nor an equal change of the two sides' track can remove. Height-free: moving the
/// base along its own axes shifts every offset alike.
pub fn stance_twist(local: &[[f64; 3]; 4]) -> f64 {
    Leg::ALL.iter().map(|l| l.diagonal_sign() * local[l.index()][1]).sum::<f64>() / 4.0
}

/// Rotation matrix of roll, pitch, yaw (ZYX: R = Rz(yaw)·Ry(pitch)·Rx(roll)), row-major.
pub fn rotation(rpy: [f64; 3]) -> [[f64; 3]; 3] {
    let [(sr, cr), (sp, cp), (sy, cy)] = rpy.map(sin_cos);
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// `a.sin_cos()`, without libm's call at zero (the same values, ±0 and 1): the standing
/// rule rotates a base without roll, and without pitch on level ground, for every
/// footprint the planner stands.
#[inline]
fn sin_cos(a: f64) -> (f64, f64) {
    if a == 0.0 { (a, 1.0) } else { a.sin_cos() }
}

/// `position + r · p`.
pub(crate) fn apply(r: &[[f64; 3]; 3], position: [f64; 3], p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| position[i] + r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])
}

/// `rᵀ · (w − position)`.
pub(crate) fn apply_inverse(r: &[[f64; 3]; 3], position: [f64; 3], w: [f64; 3]) -> [f64; 3] {
    let d = [w[0] - position[0], w[1] - position[1], w[2] - position[2]];
    std::array::from_fn(|i| r[0][i] * d[0] + r[1][i] * d[1] + r[2][i] * d[2])
}

/// Base pose, foot positions and contacts of the whole robot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Posture {
    /// Base origin in the world, m.
    pub base_position: [f64; 3],
    /// Base roll, pitch, yaw (ZYX; pitch positive nose down, roll positive left side up), rad.
    pub base_rpy: [f64; 3],
    /// Wheel contact points in the world, FL, FR, RL, RR, m.
    pub feet: [[f64; 3]; 4],
    /// Which feet bear weight.
    pub contact: [bool; 4],
}

/// Why a posture is not feasible.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PostureError {
    /// Leg IK failed (reach or joint limits).
    #[error(transparent)]
    Ik(#[from] IkError),
    /// A leg would be straighter than the reach margin allows.
    #[error("leg {leg:?}: hip-to-ankle {distance:.3} m leaves less than {margin} m of reach")]
    ReachMargin {
        /// The leg.
        leg: Leg,
        /// Hip-to-ankle distance, m.
        distance: f64,
        /// Required spare reach, m.
        margin: f64,
    },
    /// A thigh or shin would touch the terrain.
    #[error("leg {leg:?}: thigh or shin {clearance:.3} m above the terrain")]
    LegCollision {
        /// The leg.
        leg: Leg,
        /// Clearance of its lowest point, m.
        clearance: f64,
    },
    /// The standing rule has no leg height to try.
    #[error("no leg height to try")]
    NoHeight,
    /// Four feet in contact ask the rigid base for more twist than the legs give.
    #[error("stance twist {twist:.3} m (at most {MAX_STANCE_TWIST_M} m)")]
    Twist {
        /// The stance twist, m ([`stance_twist`]).
        twist: f64,
    },
    /// A foot in contact lies too far from its leg's sagittal plane.
    #[error("leg {leg:?}: contact {offset:.3} m off the leg plane")]
    Lateral {
        /// The leg.
        leg: Leg,
        /// Lateral offset, m.
        offset: f64,
    },
}

/// What a feasible posture implies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Evaluation {
    /// Joint targets (hip, knee, ankle) per leg, rad.
    pub joints: [[f64; 3]; 4],
    /// Leg heights: hip axis above the foot's contact point, world vertical, m.
    pub leg_heights: [f64; 4],
    /// CoM (world), m.
    pub com: [f64; 3],
    /// Signed distance of the horizontal CoM projection to the support polygon's edge, m.
    pub margin: f64,
    /// Horizontal distance of the CoM projection to the support polygon's centroid (the
    /// support triangle centroid, STC, with three contacts), m.
    pub centroid_distance: f64,
}

/// Vertex mean of the convex hull of `points` (the triangle centroid for three points).
pub fn support_centroid(points: &[[f64; 2]]) -> Option<[f64; 2]> {
    with_hull(points, |hull| {
        if hull.is_empty() {
            return None;
        }
        let n = hull.len() as f64;
        Some([
            hull.iter().map(|p| p[0]).sum::<f64>() / n,
            hull.iter().map(|p| p[1]).sum::<f64>() / n,
        ])
    })
}

/// The trigonometry of a base orientation, computed once for every check of a posture
/// (or of postures sharing the orientation, as the heights the standing rule tries).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseFrame {
    /// Base roll, pitch, yaw, rad.
    pub rpy: [f64; 3],
    /// [`rotation`]`(rpy)`.
    pub rotation: [[f64; 3]; 3],
    /// World down in the legs' sagittal planes, [`world_down`]`(pitch)`.
    pub down: [f64; 2],
}

impl BaseFrame {
    /// The frame of a base at `rpy`.
    pub fn new(rpy: [f64; 3]) -> Self {
        Self { rpy, rotation: rotation(rpy), down: world_down(rpy[1]) }
    }
}

/// The legs of a posture solved ([`solve_chains`]), with what the checks after the IK
/// reuse: the base frame, the contacts in it and each leg's chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolvedLegs {
    /// Base origin in the world, m.
    pub base_position: [f64; 3],
    /// The base frame.
    pub frame: BaseFrame,
    /// Per leg: the contact point (x', y', z') relative to the hip in the base frame, m.
    pub contacts: [[f64; 3]; 4],
    /// Per leg: joint angles, knee and ankle.
    pub chains: [LegChain; 4],
}

impl SolvedLegs {
    /// Joint angles (hip, knee, ankle) per leg, rad.
    pub fn joints(&self) -> [[f64; 3]; 4] {
        self.chains.map(|c| c.joints)
    }
}

/// Per leg: the contact point (x', y', z') relative to the hip in the base frame.
pub fn contacts_in_base(robot: &RobotDescription, p: &Posture) -> [[f64; 3]; 4] {
    contacts_in(robot, &rotation(p.base_rpy), p)
}

/// [`contacts_in_base`] with the base rotation `r` of `p` given.
pub(crate) fn contacts_in(
    robot: &RobotDescription,
    r: &[[f64; 3]; 3],
    p: &Posture,
) -> [[f64; 3]; 4] {
    std::array::from_fn(|i| {
        let b = apply_inverse(r, p.base_position, p.feet[i]);
        let h = robot.hips[i];
        [b[0] - h[0], b[1] - h[1], b[2] - h[2]]
    })
}

/// World position of each hip axis.
pub fn hips_in_world(robot: &RobotDescription, p: &Posture) -> [[f64; 3]; 4] {
    let r = rotation(p.base_rpy);
    std::array::from_fn(|i| apply(&r, p.base_position, robot.hips[i]))
}

/// [`PostureError::Twist`] when all four feet are in contact and their
/// [`stance_twist`] passes [`MAX_STANCE_TWIST_M`].
pub(crate) fn check_stance_twist(
    contact: [bool; 4],
    local: &[[f64; 3]; 4],
) -> Result<(), PostureError> {
    if contact.iter().all(|&c| c) {
        let twist = stance_twist(local);
        if twist.abs() > MAX_STANCE_TWIST_M {
            return Err(PostureError::Twist { twist });
        }
    }
    Ok(())
}

/// Solves the legs of `p`: joint targets (hip, knee, ankle) per leg.
///
/// # Errors
/// [`PostureError`] if a leg cannot reach its foot with `reach_margin` m to spare, a joint
/// limit is passed, or a foot in contact lies off its leg plane.
pub fn solve_legs(
    robot: &RobotDescription,
    p: &Posture,
    reach_margin: f64,
) -> Result<[[f64; 3]; 4], PostureError> {
    solve_chains(robot, p, reach_margin).map(|s| s.joints())
}

/// [`solve_legs`] with the base frame, contacts and chains it solves through, so that
/// the checks after it compute none of them again.
///
/// # Errors
/// [`PostureError`] as [`solve_legs`].
pub fn solve_chains(
    robot: &RobotDescription,
    p: &Posture,
    reach_margin: f64,
) -> Result<SolvedLegs, PostureError> {
    solve_chains_in(robot, &BaseFrame::new(p.base_rpy), p, reach_margin)
}

/// [`solve_chains`] with the base frame of `p` given (`BaseFrame::new(p.base_rpy)`,
/// shared by postures of one orientation).
///
/// # Errors
/// [`PostureError`] as [`solve_legs`].
pub fn solve_chains_in(
    robot: &RobotDescription,
    frame: &BaseFrame,
    p: &Posture,
    reach_margin: f64,
) -> Result<SolvedLegs, PostureError> {
    debug_assert!(
        frame.rpy.map(f64::to_bits) == p.base_rpy.map(f64::to_bits),
        "frame {:?} for a base at {:?}",
        frame.rpy,
        p.base_rpy
    );
    let local = contacts_in(robot, &frame.rotation, p);
    check_stance_twist(p.contact, &local)?;
    let pitch = frame.rpy[1];
    let below = robot.foot_length + robot.wheel_radius;
    let reach = robot.thigh_length + robot.shin_length;
    let mut chains = [LegChain { joints: [0.0; 3], knee: [0.0; 2], ankle: [0.0; 2] }; 4];
    for leg in Leg::ALL {
        let i = leg.index();
        let c = local[i];
        if p.contact[i] && c[1].abs() > MAX_LATERAL_MISMATCH_M {
            return Err(PostureError::Lateral { leg, offset: c[1] });
        }
        let ankle = [c[0] - below * frame.down[0], c[2] - below * frame.down[1]];
        let distance = norm2(ankle[0], ankle[1]);
        if distance > reach - reach_margin {
            return Err(PostureError::ReachMargin { leg, distance, margin: reach_margin });
        }
        chains[i] = leg_chain(robot, leg, [c[0], c[2]], pitch, frame.down)?;
    }
    Ok(SolvedLegs { base_position: p.base_position, frame: *frame, contacts: local, chains })
}

/// Solves the legs of `p` ([`solve_legs`]), computes the CoM with `model` and the
/// stability margin of the feet in contact.
///
/// # Errors
/// [`PostureError`] as [`solve_legs`].
pub fn evaluate(
    robot: &RobotDescription,
    model: &mut dyn CenterOfMassModel,
    p: &Posture,
    reach_margin: f64,
) -> Result<Evaluation, PostureError> {
    Ok(evaluate_legs(robot, model, p, &solve_chains(robot, p, reach_margin)?))
}

/// [`evaluate`] of posture `p` with its legs solved (`legs`, [`solve_chains`]).
pub fn evaluate_legs(
    robot: &RobotDescription,
    model: &mut dyn CenterOfMassModel,
    p: &Posture,
    legs: &SolvedLegs,
) -> Evaluation {
    let joints = legs.joints();
    let r = &legs.frame.rotation;
    let leg_heights =
        std::array::from_fn(|i| apply(r, p.base_position, robot.hips[i])[2] - p.feet[i][2]);
    let com = model.com_of_solved(legs);
    let support = wheel_support(robot, r, p);
    let margin = stability_margin(&support, [com[0], com[1]]);
    let centroid_distance =
        support_centroid(&support).map_or(f64::INFINITY, |c| norm2(c[0] - com[0], c[1] - com[1]));
    Evaluation { joints, leg_heights, com, margin, centroid_distance }
}

/// Height difference between the two wheels of a pair up to which both bear weight, m:
/// about what the soft wheel contacts give under the robot's weight.
pub const WHEEL_PAIR_LEVEL_TOLERANCE_M: f64 = 0.002;

/// The ground points of posture `p`'s supporting wheels (base rotation `r`): a foot in
/// contact stands on its two wheels, half the track either side of its point along the
/// pair's axle (the base's y' with the wheels steered straight, as they are while
/// stepping), or, where a rolled base tilts the axle so that one wheel stands more than
/// [`WHEEL_PAIR_LEVEL_TOLERANCE_M`] above the other, on the lower wheel alone. The legs
/// only pitch, so a base roll tilts every pair with it: rolled 5° to move the CoM over
/// three feet, each pair stands on the wheel on the lower side, 6 cm from its foot point,
/// and the support triangle moves with them (measured in MuJoCo on indoor stairs: a rear
/// step planned with 9 cm of margin measured 1.6 cm).
pub fn wheel_support(robot: &RobotDescription, r: &[[f64; 3]; 3], p: &Posture) -> Vec<[f64; 2]> {
    let half = robot.wheel_track / 2.0;
    let axle = [r[0][1] * half, r[1][1] * half];
    // How much higher the left wheel (+y') stands than the right one.
    let rise = robot.wheel_track * r[2][1];
    let mut points = Vec::with_capacity(8);
    for i in (0..4).filter(|&i| p.contact[i]) {
        let f = p.feet[i];
        let left = [f[0] + axle[0], f[1] + axle[1]];
        let right = [f[0] - axle[0], f[1] - axle[1]];
        if rise.abs() <= WHEEL_PAIR_LEVEL_TOLERANCE_M {
            points.extend([left, right]);
        } else if rise > 0.0 {
            points.push(right);
        } else {
            points.push(left);
        }
    }
    points
}

/// Base pitch for feet `feet` under a base heading `yaw` (Sec. VI-B): `pitch_fraction` of
/// the ground slope between the mean front and mean rear foot, with MuJoCo's sign (nose up
/// on an upward slope is negative).
pub fn pitch_from_feet(feet: &[[f64; 3]; 4], yaw: f64, pitch_fraction: f64) -> f64 {
    let (s, c) = yaw.sin_cos();
    let along = |f: [f64; 3]| c * f[0] + s * f[1];
    let dx = (along(feet[0]) + along(feet[1]) - along(feet[2]) - along(feet[3])) / 2.0;
    let dz = (feet[0][2] + feet[1][2] - feet[2][2] - feet[3][2]) / 2.0;
    // (atan(±0) is ±0: level feet need no libm call.)
    let slope = if dx.abs() <= 1e-6 {
        0.0
    } else if dz == 0.0 {
        dz / dx
    } else {
        (dz / dx).atan()
    };
    -pitch_fraction * slope
}

/// The driving posture at `pose` (Sec. VI-B): the feet in the neutral footprint on the
/// ground that `ground(x, y)` gives, the base pitched by `pitch_fraction` of the slope and
/// raised so that the hip over the highest ground stands `leg_height` above it (the other
/// legs stretch down to their lower ground), as Sec. VI-B sets the base for standing
/// manoeuvres. The driving height folds the knees nearly to their limit (hip to ankle
/// 9 cm of the 6 cm the knee allows), so a base set by the *mean* ground would fold the
/// knee of a wheel on a 4 cm bump past its limit; set by the highest foot every wheel
/// keeps the ground over whatever the foot cost lets it drive on (ΔH ≤ 5 cm).
///
/// # Errors
/// The (x, y) of a foot where `ground` knows no height.
pub fn driving_posture(
    robot: &RobotDescription,
    pose: &Pose2,
    leg_height: f64,
    pitch_fraction: f64,
    ground: impl Fn(f64, f64) -> Option<f64>,
) -> Result<Posture, [f64; 2]> {
    let neutral = robot.neutral_footprint();
    let mut feet = [[0.0; 3]; 4];
    for (f, n) in feet.iter_mut().zip(neutral) {
        let [x, y] = pose.transform(n);
        *f = [x, y, ground(x, y).ok_or([x, y])?];
    }
    let pitch = pitch_from_feet(&feet, pose.theta, pitch_fraction);
    let r = rotation([0.0, pitch, pose.theta]);
    let z = base_z_in(robot, &feet.map(|f| f[2]), &r, leg_height);
    Ok(Posture {
        base_position: [pose.x, pose.y, z],
        base_rpy: [0.0, pitch, pose.theta],
        feet,
        contact: [true; 4],
    })
}

/// Joint targets (hip, knee, ankle) that put each leg's wheel on its foot of `p`.
///
/// # Errors
/// [`IkError`] if a foot is out of reach or a joint limit would be passed.
pub fn leg_joint_targets(robot: &RobotDescription, p: &Posture) -> Result<[[f64; 3]; 4], IkError> {
    let local = contacts_in_base(robot, p);
    let mut joints = [[0.0; 3]; 4];
    for leg in Leg::ALL {
        let c = local[leg.index()];
        joints[leg.index()] = leg_ik(robot, leg, [c[0], c[2]], p.base_rpy[1])?;
    }
    Ok(joints)
}

/// Linear interpolation of two postures at `t` ∈ [0, 1] (base pose and feet; yaw along the
/// shorter way). Contacts: a foot bears weight only if it does at both ends.
pub fn interpolate(a: &Posture, b: &Posture, t: f64) -> Posture {
    let lerp = |x: f64, y: f64| x + (y - x) * t;
    let dyaw = crate::geometry::wrap_angle(b.base_rpy[2] - a.base_rpy[2]);
    Posture {
        base_position: std::array::from_fn(|k| lerp(a.base_position[k], b.base_position[k])),
        base_rpy: [
            lerp(a.base_rpy[0], b.base_rpy[0]),
            lerp(a.base_rpy[1], b.base_rpy[1]),
            a.base_rpy[2] + dyaw * t,
        ],
        feet: std::array::from_fn(|i| std::array::from_fn(|k| lerp(a.feet[i][k], b.feet[i][k]))),
        contact: std::array::from_fn(|i| a.contact[i] && b.contact[i]),
    }
}

/// Base origin height for the base at `rpy` such that the hip over the highest of `ground`
/// (per leg, m) stands `height` above it and no hip stands lower above its ground.
pub fn base_z(robot: &RobotDescription, ground: &[f64; 4], rpy: [f64; 3], height: f64) -> f64 {
    base_z_in(robot, ground, &rotation(rpy), height)
}

/// [`base_z`] with the base rotation `r` given.
pub(crate) fn base_z_in(
    robot: &RobotDescription,
    ground: &[f64; 4],
    r: &[[f64; 3]; 3],
    height: f64,
) -> f64 {
    (0..4)
        .map(|i| {
            let h = robot.hips[i];
            ground[i] + height - (r[2][0] * h[0] + r[2][1] * h[1] + r[2][2] * h[2])
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_shortcuts_give_libms_bits() {
        // `sin_cos` skips libm at ±0 only, with its values to the bit.
        for a in [0.0, -0.0, 1e-300, -0.3, 2.0] {
            let (s, c) = sin_cos(a);
            let (ls, lc) = a.sin_cos();
            assert_eq!((s.to_bits(), c.to_bits()), (ls.to_bits(), lc.to_bits()), "{a}");
        }
        // Level feet: the pitch of the arctangent of a zero slope, its sign included.
        let feet = [[0.3, 0.2, 0.1], [0.3, -0.2, 0.1], [-0.4, 0.2, 0.1], [-0.4, -0.2, 0.1]];
        for yaw in [0.0_f64, 3.0] {
            let dx = yaw.cos() * 0.7;
            let want = -0.7 * (0.0_f64 / dx).atan();
            assert_eq!(pitch_from_feet(&feet, yaw, 0.7).to_bits(), want.to_bits(), "{yaw}");
        }
        // A slope still takes the arctangent.
        let mut up = feet;
        up[0][2] = 0.2;
        up[1][2] = 0.2;
        assert!((pitch_from_feet(&up, 0.0, 0.7) + 0.7 * (0.1f64 / 0.7).atan()).abs() < 1e-15);
    }

    #[test]
    fn a_level_pair_stands_on_both_wheels_a_rolled_one_on_its_lower_wheel() {
        // Track 0.12 m: level, each foot in contact gives its two wheels 0.06 m either side
        // along y' (yaw 0: world y); FR lifted gives none.
        let robot = RobotDescription::reference();
        let mut p = Posture {
            base_position: [0.0, 0.0, 0.5],
            base_rpy: [0.0; 3],
            feet: [[0.35, 0.3, 0.0], [0.35, -0.3, 0.0], [-0.35, 0.3, 0.0], [-0.35, -0.3, 0.0]],
            contact: [true, false, true, true],
        };
        let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-12;
        let level = wheel_support(&robot, &rotation(p.base_rpy), &p);
        assert_eq!(level.len(), 6);
        assert!(near(level[0], [0.35, 0.36]) && near(level[1], [0.35, 0.24]), "{level:?}");
        // Rolled 5° left side up: the left wheel stands 0.12 · sin 5° = 10 mm higher (more
        // than the 2 mm tolerance), so each pair stands on its right wheel, 0.06 · cos 5°
        // to the right of its foot.
        p.base_rpy[0] = 5f64.to_radians();
        let rolled = wheel_support(&robot, &rotation(p.base_rpy), &p);
        let d = 0.06 * 5f64.to_radians().cos();
        assert_eq!(rolled.len(), 3);
        assert!(near(rolled[0], [0.35, 0.3 - d]) && near(rolled[2], [-0.35, -0.3 - d]));
        // Turned to yaw 90° and rolled the other way: the left (+y' = world −x) wheel.
        p.base_rpy = [-5f64.to_radians(), 0.0, std::f64::consts::FRAC_PI_2];
        let turned = wheel_support(&robot, &rotation(p.base_rpy), &p);
        assert!(near(turned[0], [0.35 - d, 0.3]), "{turned:?}");
        // 0.9° of roll lifts a wheel 1.9 mm: both still bear weight.
        p.base_rpy[0] = 0.9f64.to_radians();
        assert_eq!(wheel_support(&robot, &rotation(p.base_rpy), &p).len(), 6);
    }

    #[test]
    fn driving_posture_on_a_slope_by_hand() {
        // Ground rising 0.1 per metre along +x; the feet at x = ±0.35 m see ±0.035 m, so the
        // slope between front and rear is atan(0.1) and the pitch −0.7·atan(0.1). The front
        // hips (x' = 0.35, 0.05 m below the origin) stand over the highest ground, 0.035 m:
        // z = 0.035 + 0.27 − (0.35·(−sin pitch) − 0.05·cos pitch); the front hips rise
        // by 0.35·sin|pitch| < 0.035 m, so the rear ones stand higher above their ground.
        let robot = RobotDescription::reference();
        let p =
            driving_posture(&robot, &Pose2::new(0.0, 0.0, 0.0), 0.27, 0.7, |x, _| Some(0.1 * x))
                .unwrap();
        let pitch = -0.7 * 0.1f64.atan();
        assert!((p.base_rpy[1] - pitch).abs() < 1e-12);
        let z = 0.035 + 0.27 - (0.35 * -pitch.sin() - 0.05 * pitch.cos());
        assert!((p.base_position[2] - z).abs() < 1e-12, "{} {z}", p.base_position[2]);
        assert!((p.feet[0][2] - 0.035).abs() < 1e-12 && (p.feet[2][2] + 0.035).abs() < 1e-12);
        // The joint targets put each wheel back on its foot.
        let q = leg_joint_targets(&robot, &p).unwrap();
        let local = contacts_in_base(&robot, &p);
        for leg in Leg::ALL {
            let f = crate::robot::ik::leg_fk(&robot, q[leg.index()], p.base_rpy[1]);
            assert!(
                (f[0] - local[leg.index()][0]).abs() < 1e-9
                    && (f[1] - local[leg.index()][2]).abs() < 1e-9
            );
        }
        // Unknown ground names where.
        let e = driving_posture(&robot, &Pose2::new(0.0, 0.0, 0.0), 0.27, 0.7, |x, _| {
            (x < 0.0).then_some(0.0)
        });
        assert_eq!(e.unwrap_err(), [0.35, 0.32]);
    }

    #[test]
    fn a_wheel_on_a_bump_keeps_its_knee_within_limits() {
        // Flat ground with a 4 cm bump under the front-left wheel only. The hip over the
        // bump stands 0.27 m above it; by the mean ground it would stand 3 cm lower, its
        // hip-to-ankle 6 cm, the knee folded past 2.9 rad.
        let robot = RobotDescription::reference();
        let bump = |x: f64, y: f64| Some(if x > 0.2 && y > 0.2 { 0.04 } else { 0.0 });
        let p = driving_posture(&robot, &Pose2::new(0.0, 0.0, 0.0), 0.27, 0.7, bump).unwrap();
        leg_joint_targets(&robot, &p).unwrap();
        let mut mean = p;
        mean.base_position[2] -= 0.03;
        assert!(leg_joint_targets(&robot, &mean).is_err());
    }

    #[test]
    fn rotation_matches_zyx_convention() {
        // Pitch +0.3 (nose down): the base x axis points down.
        let r = rotation([0.0, 0.3, 0.0]);
        assert!((r[2][0] + 0.3f64.sin()).abs() < 1e-12);
        // Roll +0.2: the base y axis (left) points up.
        let r = rotation([0.2, 0.0, 0.0]);
        assert!((r[2][1] - 0.2f64.sin()).abs() < 1e-12);
        let r = rotation([0.1, -0.2, 0.7]);
        let p = [0.3, -0.1, 0.4];
        let w = apply(&r, [1.0, 2.0, 3.0], p);
        let back = apply_inverse(&r, [1.0, 2.0, 3.0], w);
        for k in 0..3 {
            assert!((back[k] - p[k]).abs() < 1e-12);
        }
    }

    #[test]
    fn solved_chains_by_hand() {
        // Level base, every foot 0.45 m under its hip: the contacts straight down, the
        // ankles 0.27 m below the hips, the knees halfway down and √(0.25² − 0.135²) to
        // the body centre's side (front knees back, rear knees forward).
        let robot = RobotDescription::reference();
        let feet = robot.hips.map(|h| [h[0], h[1], h[2] - 0.45]);
        let p = Posture { base_position: [0.0; 3], base_rpy: [0.0; 3], feet, contact: [true; 4] };
        let legs = solve_chains(&robot, &p, 0.002).unwrap();
        assert_eq!(legs.frame, BaseFrame::new([0.0; 3]));
        assert_eq!(legs.frame.down, [0.0, -1.0]);
        assert_eq!(legs.joints(), solve_legs(&robot, &p, 0.002).unwrap());
        let side = (0.25f64 * 0.25 - 0.135 * 0.135).sqrt();
        for leg in Leg::ALL {
            let (i, c) = (leg.index(), legs.chains[leg.index()]);
            assert!(
                legs.contacts[i].iter().zip([0.0, 0.0, -0.45]).all(|(a, b)| (a - b).abs() < 1e-12)
            );
            assert!(c.ankle[0].abs() < 1e-12 && (c.ankle[1] + 0.27).abs() < 1e-12, "{c:?}");
            let x = if leg.is_front() { -side } else { side };
            assert!((c.knee[0] - x).abs() < 1e-12 && (c.knee[1] + 0.135).abs() < 1e-12, "{c:?}");
        }
        // The frame of a rolled, pitched, turned base is the rotation and the sagittal down:
        // nose up by 0.2, world down points back in the base frame, (−sin 0.2, −cos 0.2).
        let f = BaseFrame::new([0.1, -0.2, 0.7]);
        assert_eq!(f.rotation, rotation([0.1, -0.2, 0.7]));
        assert!(
            (f.down[0] + 0.2f64.sin()).abs() < 1e-15 && (f.down[1] + 0.2f64.cos()).abs() < 1e-15
        );
        // The same errors as solve_legs: a foot out of reach.
        let mut far = p;
        far.feet[3][0] -= 1.0;
        assert!(matches!(
            solve_chains(&robot, &far, 0.002),
            Err(PostureError::ReachMargin { leg: Leg::RearRight, .. })
        ));
    }

    #[test]
    fn stance_twist_is_the_diagonal_part_of_the_lateral_offsets() {
        // Offsets (m) by hand: a base shifted sideways (all alike), turned (front against
        // rear) or with its track changed (left against right) has no twist; the offsets
        // of the six tipped mixed courses' rolls, +1.4/−2.9/−0.5/+0.7 cm, have
        // (1.4 + 2.9 + 0.5 + 0.7) / 4 = 1.375 cm.
        let at = |y: [f64; 4]| y.map(|y| [0.0, y, -0.5]);
        for rigid in [[0.02; 4], [0.01, 0.01, -0.01, -0.01], [0.02, -0.02, 0.02, -0.02]] {
            assert_eq!(stance_twist(&at(rigid)), 0.0, "{rigid:?}");
        }
        let tipped = stance_twist(&at([0.014, -0.029, -0.005, 0.007]));
        assert!((tipped - 0.01375).abs() < 1e-15, "{tipped}");
        assert!((stance_twist(&at([-0.01, 0.01, 0.01, -0.01])) + 0.01).abs() < 1e-15);
    }

    #[test]
    fn four_feet_in_contact_take_a_bounded_twist_three_any() {
        // Level base, feet 0.45 m under their hips and moved sideways (world y is y'):
        // front-left out and front-right in by 2.5 cm, each within the 3 cm a single foot
        // may lie off its leg plane, is a twist of (2.5 + 2.5) / 4 = 1.25 cm: refused on
        // four feet, accepted with front-right lifted (three feet have no twist), and at
        // 1.5 cm each (a twist of 0.75 cm) accepted on four.
        let robot = RobotDescription::reference();
        let feet = |e: f64| {
            let mut f = robot.hips.map(|h| [h[0], h[1], h[2] - 0.45]);
            f[0][1] += e;
            f[1][1] -= e;
            f
        };
        let p = Posture {
            base_position: [0.0; 3],
            base_rpy: [0.0; 3],
            feet: feet(0.025),
            contact: [true; 4],
        };
        match solve_legs(&robot, &p, 0.002) {
            Err(PostureError::Twist { twist }) => {
                assert!((twist - 0.0125).abs() < 1e-12, "{twist}")
            }
            other => panic!("{other:?}"),
        }
        let lifted = Posture { contact: [true, false, true, true], ..p };
        assert!(solve_legs(&robot, &lifted, 0.002).is_ok());
        let small = Posture { feet: feet(0.015), ..p };
        assert!(solve_legs(&robot, &small, 0.002).is_ok());
    }

    #[test]
    fn evaluate_legs_is_evaluate() {
        // A pitched, rolled posture with one foot lifted: the evaluation from the solved
        // legs is the one evaluate gives, leg heights the hips above the feet.
        let robot = RobotDescription::reference();
        let mut p =
            driving_posture(&robot, &Pose2::new(0.3, -0.2, 0.4), 0.35, 0.7, |x, _| Some(0.1 * x))
                .unwrap();
        p.base_rpy[0] = 0.02;
        p.contact[1] = false;
        let mut model = crate::posture::LumpedMassModel::momaro_like(&robot);
        let legs = solve_chains(&robot, &p, 0.002).unwrap();
        let e = evaluate_legs(&robot, &mut model, &p, &legs);
        assert_eq!(e, evaluate(&robot, &mut model, &p, 0.002).unwrap());
        let hips = hips_in_world(&robot, &p);
        for (i, hip) in hips.iter().enumerate() {
            assert_eq!(e.leg_heights[i], hip[2] - p.feet[i][2]);
        }
        assert_eq!(contacts_in(&robot, &rotation(p.base_rpy), &p), contacts_in_base(&robot, &p));
    }

    #[test]
    fn triangle_centroid() {
        let c = support_centroid(&[[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]]).unwrap();
        assert!((c[0] - 1.0).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12);
    }
}
