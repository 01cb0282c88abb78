//! Controllers that turn plans and commands into actuator targets: wheel kinematics for
//! omnidirectional driving and the standing posture.

pub mod bspline;
pub mod path_follower;
pub mod stand;
pub mod wheels;
