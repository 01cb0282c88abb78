//! Step motion generation (Klamt & Behnke 2017, Sec. VI): the abstract path of the hybrid
//! planner expanded into a timed sequence of statically stable, kinematically feasible
//! keyframes — the contract the step executor consumes.
//!
//! - [`roll`]: the base roll of eqs. 6–8 (lateral CoM alignment), a pure function.
//! - [`kinematics`]: a whole-robot posture (base pose, feet, contacts) → leg IK, leg
//!   heights, CoM (through [`CenterOfMassModel`]) and the static stability margin.
//! - [`standing`]: the Sec. VI-B leg-height rule for standing manoeuvres, shared with the
//!   planner's reach checks so planner and generator agree on what a footprint can reach.
//! - [`keyframe`]: [`Keyframe`], [`Phase`], [`DetailedPath`] (serialisable).
//! - [`expand`]: [`expand_path`], the expansion itself (see its docs for every manoeuvre).
//!
//! The module does not import MuJoCo: the CoM comes from a [`CenterOfMassModel`], which
//! `sim::Simulation` implements with MuJoCo's own kinematics (so planner and simulator
//! agree by construction) and [`LumpedMassModel`] implements analytically for unit tests.

pub mod expand;
pub mod keyframe;
pub mod kinematics;
pub mod roll;
pub mod standing;

pub use expand::{MotionError, MotionOptions, ZMP_SHIFT_M, expand_path};
pub use keyframe::{DetailedPath, Keyframe, Phase};
pub use kinematics::{Evaluation, Posture, rotation};
pub use roll::{RollError, RollSolution, roll_for_lateral_com};
pub use standing::StandingRule;

use crate::robot::RobotDescription;
use crate::robot::ik::{knee_and_ankle, leg_fk};

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
