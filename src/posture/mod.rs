//! How the robot stands on terrain: a whole-robot posture (base pose, feet, contacts)
//! solved by leg IK, its centre of mass and static stability margin, and the standing
//! rule of Sec. VI-B that planner, motion generator and executor share.
//!
//! - [`kinematics`]: posture → leg IK, leg heights, CoM (through [`CenterOfMassModel`]) and
//!   the margin over the wheels each pair stands on; the driving posture; base heights.
//! - [`standing`]: the Sec. VI-B leg-height rule for standing manoeuvres (pitch 70 % of the
//!   slope, base set by the highest foot, 0.45 m lowered until every leg reaches), shared
//!   by the planner's reach checks and the generator, and the planner's lumped CoM
//!   estimate ([`standing::EstimatedCom`]).
//!
//! The module does not import MuJoCo: the CoM comes from a [`CenterOfMassModel`], which
//! `sim::Simulation` implements with MuJoCo's own kinematics (so planner and simulator
//! agree by construction) and [`LumpedMassModel`] implements analytically for unit tests.

pub mod kinematics;
pub mod standing;

pub use kinematics::{Evaluation, Posture, rotation};
pub use standing::StandingRule;

use crate::robot::ik::{IkError, knee_and_ankle, leg_fk, leg_ik};
use crate::robot::{Leg, RobotDescription};

/// The whole robot's centre of mass (world frame, m) for a commanded configuration: base
/// position, base roll/pitch/yaw (ZYX, MuJoCo's signs) and per-leg (hip, knee, ankle)
/// joint angles, FL, FR, RL, RR.
pub trait CenterOfMassModel {
    /// The CoM of the configuration.
    fn com(
        &mut self,
        base_position: [f64; 3],
        base_rpy: [f64; 3],
        legs: &[[f64; 3]; 4],
    ) -> [f64; 3];

    /// The CoM of a posture whose legs [`kinematics::solve_chains`] has solved: what
    /// [`Self::com`] gives for its base and joint angles. A model that can use the solved
    /// chain (the planner's lumped estimate) overrides it and saves recomputing it.
    fn com_of_solved(&mut self, legs: &kinematics::SolvedLegs) -> [f64; 3] {
        self.com(legs.base_position, legs.frame.rpy, &legs.joints())
    }
}

/// An analytic CoM model for tests and quick estimates: a body point mass fixed in the base
/// frame plus, per leg, a point mass at the middle of the thigh–shin chain and one at the
/// wheel axle.
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedMassModel {
    /// The robot's kinematics.
    pub robot: RobotDescription,
    /// Body (base, torso, head) mass, kg.
    pub body_mass: f64,
    /// Body CoM in the base frame, m.
    pub body_com: [f64; 3],
    /// Mass per leg at the knee, kg.
    pub knee_mass: f64,
    /// Mass per leg at the wheel axle, kg.
    pub wheel_mass: f64,
}

impl LumpedMassModel {
    /// Momaro-like masses: 34 kg body 0.15 m above the base origin, 3.3 kg at each knee,
    /// 2.7 kg at each wheel axle.
    pub fn momaro_like(robot: &RobotDescription) -> Self {
        Self {
            robot: robot.clone(),
            body_mass: 34.0,
            body_com: [0.0, 0.0, 0.15],
            knee_mass: 3.3,
            wheel_mass: 2.7,
        }
    }
}

impl CenterOfMassModel for LumpedMassModel {
    fn com(
        &mut self,
        base_position: [f64; 3],
        base_rpy: [f64; 3],
        legs: &[[f64; 3]; 4],
    ) -> [f64; 3] {
        let r = rotation(base_rpy);
        let world = |p: [f64; 3]| kinematics::apply(&r, base_position, p);
        let mut sum = [0.0; 3];
        let mut mass = 0.0;
        let mut add = |p: [f64; 3], m: f64| {
            for k in 0..3 {
                sum[k] += m * p[k];
            }
            mass += m;
        };
        add(world(self.body_com), self.body_mass);
        let rb = &self.robot;
        for (i, q) in legs.iter().enumerate() {
            let h = rb.hips[i];
            let [knee, _] = knee_and_ankle(rb, *q);
            add(world([h[0] + knee[0], h[1], h[2] + knee[1]]), self.knee_mass);
            let c = leg_fk(rb, *q, base_rpy[1]);
            let axle = [h[0] + c[0], h[1], h[2] + c[1] + rb.wheel_radius];
            add(world(axle), self.wheel_mass);
        }
        if mass > 0.0 { sum.map(|v| v / mass) } else { base_position }
    }
}

/// Joint targets (hip, knee, ankle per leg) for the neutral footprint with every wheel's
/// ground contact `leg_height` below its hip and the base level.
///
/// # Errors
/// [`IkError`] if the height is out of the legs' reach.
pub fn neutral_posture(
    robot: &RobotDescription,
    leg_height: f64,
) -> Result<[[f64; 3]; 4], IkError> {
    let mut q = [[0.0; 3]; 4];
    for leg in Leg::ALL {
        let i = leg.index();
        q[i] = leg_ik(robot, leg, [robot.neutral_foot_offset_x[i], -leg_height], 0.0)?;
    }
    Ok(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn com_of_solved_defaults_to_the_angles() {
        // A model that knows only joint angles gives, for solved legs, its CoM of their
        // angles: by hand, level base and feet under the hips 0.45 m down, the knees
        // mirror each other front to rear and the body's 0.15 m lifts the CoM to
        // 34 · 0.15 / 58 above the knee and axle masses' mean height.
        let robot = RobotDescription::reference();
        let feet = robot.hips.map(|h| [h[0], h[1], h[2] - 0.45]);
        let p = Posture { base_position: [0.0; 3], base_rpy: [0.0; 3], feet, contact: [true; 4] };
        let legs = kinematics::solve_chains(&robot, &p, 0.0).unwrap();
        let mut model = LumpedMassModel::momaro_like(&robot);
        let c = model.com_of_solved(&legs);
        assert_eq!(c, model.com([0.0; 3], [0.0; 3], &legs.joints()));
        // Knees at z' = −0.05 − 0.135, axles at −0.05 − 0.45 + 0.08.
        let z = (34.0 * 0.15 + 4.0 * 3.3 * -0.185 + 4.0 * 2.7 * -0.42) / 58.0;
        assert!(c[0].abs() < 1e-12 && c[1].abs() < 1e-12 && (c[2] - z).abs() < 1e-12, "{c:?}");
    }
}
