//! Controllers that turn plans and commands into actuator targets: wheel kinematics for
//! omnidirectional driving, the path follower, and the step
//! executor with its foot contact confirmation and the four-wheel support's load sharing.

pub mod bspline;
pub mod foot_contact;
pub mod load_sharing;
pub mod path_follower;
pub mod step_executor;
pub mod wheels;
