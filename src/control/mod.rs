//! Controllers that turn plans and commands into actuator targets: wheel kinematics for
//! omnidirectional driving and the standing posture.

pub mod stand;
pub mod wheels;
