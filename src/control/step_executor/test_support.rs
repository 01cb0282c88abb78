//! Fixtures shared by the step executor's unit tests: the reference robot standing on
//! flat ground, keyframes of one front-left step, observations and the default config.

use super::{ExecutorConfig, Observation, StepExecutor};
use crate::control::path_follower::FollowerConfig;
use crate::geometry::Pose2;
use crate::motion::{Keyframe, Phase};
use crate::params::Params;
use crate::posture::kinematics::{Posture, leg_joint_targets};
use crate::robot::{Leg, RobotDescription};
use crate::terrain::HeightMap;

pub(super) fn robot() -> RobotDescription {
    RobotDescription::reference()
}

/// Level base 0.5 m up at the origin, feet under the hips on flat ground.
pub(super) fn standing() -> Posture {
    let r = robot();
    Posture {
        base_position: [0.0, 0.0, 0.5],
        base_rpy: [0.0, 0.0, 0.0],
        feet: std::array::from_fn(|i| [r.hips[i][0], r.hips[i][1], 0.0]),
        contact: [true; 4],
    }
}

pub(super) fn key(time_s: f64, phase: Phase, leg: Option<Leg>, p: &Posture) -> Keyframe {
    Keyframe {
        time_s,
        phase,
        path_index: 0,
        leg,
        base_position: p.base_position,
        base_rpy: p.base_rpy,
        feet: p.feet,
        contact: p.contact,
        leg_heights: [0.45; 4],
        joints: leg_joint_targets(&robot(), p).unwrap(),
        com: [0.0; 3],
        margin_m: 0.1,
        segment_min_margin_m: 0.1,
        centroid_distance_m: 0.0,
    }
}

pub(super) fn obs(
    time: f64,
    ex: &StepExecutor,
    contacts: &[(Leg, [f64; 2])],
    com: [f64; 3],
) -> Observation {
    Observation {
        time,
        base: Pose2::new(0.0, 0.0, 0.0),
        base_z: None,
        joints: ex.last_legs,
        steering: [0.0; 4],
        steering_rate: [0.0; 4],
        com,
        wheel_contacts: contacts.to_vec(),
        support_contacts: contacts.to_vec(),
        wheel_loads: [0.0; 4],
    }
}

pub(super) fn config() -> ExecutorConfig {
    ExecutorConfig::from_params(&Params::default(), FollowerConfig::default())
}

/// Start, lift, swing and place of the front-left foot 0.1 m forward on flat ground.
pub(super) fn step_path() -> Vec<Keyframe> {
    let a = standing();
    let mut lift = a;
    lift.feet[0][2] = 0.05;
    lift.contact[0] = false;
    let mut swing = lift;
    swing.feet[0][0] += 0.1;
    let mut place = swing;
    place.feet[0][2] = 0.0;
    place.contact[0] = true;
    vec![
        key(0.0, Phase::Start, None, &a),
        key(0.5, Phase::Lift, Some(Leg::FrontLeft), &lift),
        key(1.5, Phase::Swing, Some(Leg::FrontLeft), &swing),
        key(2.0, Phase::Place, Some(Leg::FrontLeft), &place),
    ]
}

pub(super) fn all_contacts(feet: &[[f64; 3]; 4]) -> Vec<(Leg, [f64; 2])> {
    Leg::ALL.iter().map(|&l| (l, [feet[l.index()][0], feet[l.index()][1]])).collect()
}

/// [`all_contacts`] but those of `lifted`.
pub(super) fn contacts_without(feet: &[[f64; 3]; 4], lifted: Leg) -> Vec<(Leg, [f64; 2])> {
    all_contacts(feet).into_iter().filter(|(l, _)| *l != lifted).collect()
}

pub(super) fn ground() -> HeightMap {
    HeightMap::filled([-2.0, -2.0], 0.025, 160, 160, 0.0).unwrap()
}
