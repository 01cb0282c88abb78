//! What the planner and controllers know of the robot: its kinematic description, read
//! once from the compiled MuJoCo model by `sim::model` and never typed a second time.
//!
//! Legs are indexed FL, FR, RL, RR (see [`Leg`]). Each leg has three pitch joints (hip,
//! knee, ankle) moving the foot in the leg's sagittal plane (the base x'–z' plane at the
//! hip's y'), a steering (yaw) joint, and a pair of driven wheels. A *foot* position is the
//! ground contact point under the centre of the wheel pair.

pub mod ik;

use serde::Serialize;

/// A leg of the robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Leg {
    /// Front left.
    FrontLeft = 0,
    /// Front right.
    FrontRight = 1,
    /// Rear left.
    RearLeft = 2,
    /// Rear right.
    RearRight = 3,
}

impl Leg {
    /// All legs in index order.
    pub const ALL: [Leg; 4] = [Leg::FrontLeft, Leg::FrontRight, Leg::RearLeft, Leg::RearRight];

    /// Index 0..4.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Short name used in the model's element names: `fl`, `fr`, `rl`, `rr`.
    pub const fn prefix(self) -> &'static str {
        match self {
            Leg::FrontLeft => "fl",
            Leg::FrontRight => "fr",
            Leg::RearLeft => "rl",
            Leg::RearRight => "rr",
        }
    }

    /// Whether the leg is a front leg.
    pub const fn is_front(self) -> bool {
        matches!(self, Leg::FrontLeft | Leg::FrontRight)
    }

    /// Whether the leg is on the left side.
    pub const fn is_left(self) -> bool {
        matches!(self, Leg::FrontLeft | Leg::RearLeft)
    }

    /// The leg's sign on the diagonals: +1 on front-left/rear-right, −1 on the other.
    /// A pattern of four values (loads, lateral offsets) weighted by it sums what one
    /// diagonal has beyond the other, the *warp* of a four-foot stance; no rigid motion
    /// of the base in the plane and no equal change of the legs of one side adds to it.
    pub const fn diagonal_sign(self) -> f64 {
        match self {
            Leg::FrontLeft | Leg::RearRight => 1.0,
            Leg::FrontRight | Leg::RearLeft => -1.0,
        }
    }

    /// The other leg on the same side.
    pub const fn same_side_partner(self) -> Leg {
        match self {
            Leg::FrontLeft => Leg::RearLeft,
            Leg::FrontRight => Leg::RearRight,
            Leg::RearLeft => Leg::FrontLeft,
            Leg::RearRight => Leg::FrontRight,
        }
    }
}

/// A closed interval `[min, max]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Range {
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
}

impl Range {
    /// Whether `v` lies in the interval.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// Kinematic and inertial description of Momaro, as compiled by MuJoCo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobotDescription {
    /// Hip pitch axis position in the base frame (x', y', z'), m, per leg.
    pub hips: [[f64; 3]; 4],
    /// Hip-to-knee length, m.
    pub thigh_length: f64,
    /// Knee-to-ankle length, m.
    pub shin_length: f64,
    /// Ankle-to-wheel-axle length, m (the foot segment, vertical when the wheel is level).
    pub foot_length: f64,
    /// Wheel radius, m.
    pub wheel_radius: f64,
    /// Lateral distance between the two wheels of a pair, m.
    pub wheel_track: f64,
    /// Hip, knee and ankle joint ranges, rad (same for all legs).
    pub joint_ranges: [Range; 3],
    /// Foot x' offset from the hip in the neutral driving footprint, m, per leg.
    pub neutral_foot_offset_x: [f64; 4],
    /// Half extents of the base box (x', y', z'), m.
    pub base_half_extents: [f64; 3],
    /// Height of the base's underside above the hip axes, m (negative: below).
    pub base_bottom_z: f64,
    /// Total mass, kg.
    pub total_mass: f64,
    /// Mass of the base body alone (base, torso, arms, head: everything but the legs), kg.
    pub body_mass: f64,
    /// The base body's own CoM in the base frame, m.
    pub body_com: [f64; 3],
    /// Per leg: thigh, shin, and foot with steering and wheels (the foot's subtree), kg.
    pub leg_segment_masses: [f64; 3],
}

impl RobotDescription {
    /// Momaro as `models/momaro.xml` compiles, written out for unit tests and benchmarks
    /// that run without MuJoCo. Library code never uses it: it reads the model. The test
    /// `tests/model.rs` checks it equals what the model gives, so it cannot drift.
    pub fn reference() -> Self {
        let joint = Range { min: -2.9, max: 2.9 };
        Self {
            hips: [
                [0.35, 0.32, -0.05],
                [0.35, -0.32, -0.05],
                [-0.35, 0.32, -0.05],
                [-0.35, -0.32, -0.05],
            ],
            thigh_length: 0.25,
            shin_length: 0.25,
            foot_length: 0.10,
            wheel_radius: 0.08,
            wheel_track: 0.12,
            joint_ranges: [joint; 3],
            neutral_foot_offset_x: [0.0; 4],
            base_half_extents: [0.45, 0.25, 0.05],
            base_bottom_z: 0.0,
            total_mass: 58.0,
            // Base box 15 kg at 0, torso 17 kg at z' = 0.30, head 2 kg at (0.02, 0, 0.63).
            body_mass: 34.0,
            body_com: [0.04 / 34.0, 0.0, 6.36 / 34.0],
            leg_segment_masses: [1.8, 1.5, 2.7],
        }
    }

    /// Neutral foot positions (x', y') in the base frame, per leg.
    pub fn neutral_footprint(&self) -> [[f64; 2]; 4] {
        std::array::from_fn(|i| [self.hips[i][0] + self.neutral_foot_offset_x[i], self.hips[i][1]])
    }

    /// Longest hip-to-ground distance with a straight leg and level wheel, m.
    pub fn max_leg_length(&self) -> f64 {
        self.thigh_length + self.shin_length + self.foot_length + self.wheel_radius
    }

    /// Radius around a foot that covers its wheel pair in every direction (half the
    /// track plus a wheel radius), m.
    pub fn wheel_pair_radius(&self) -> f64 {
        self.wheel_track / 2.0 + self.wheel_radius
    }

    /// x' offsets of the centres of the two circles that approximate the base (Sec. IV),
    /// for circles of radius `radius` inscribed at the two ends of the base box.
    pub fn base_circle_centres_x(&self, radius: f64) -> [f64; 2] {
        let d = (self.base_half_extents[0] - radius).max(0.0);
        [d, -d]
    }
}
