//! The URDF of Momaro, generated from the compiled MJCF (through `sim`) with urdf-rs, for
//! Rerun and ROS users. `models/momaro.urdf` is this output, checked in sync by a test.
//!
//! Links and joints mirror the MJCF's bodies and joints one to one, with the same names:
//! `base` → `<leg>_thigh` (hip) → `<leg>_shin` (knee) → `<leg>_foot` (ankle) →
//! `<leg>_steer` (steer) → `<leg>_wheel_l` / `<leg>_wheel_r`.

use crate::robot::{Leg, RobotDescription};
use urdf_rs::{
    Axis, Geometry, Inertia, Inertial, Joint, JointLimit, JointType, Link, LinkName, Mass, Pose,
    Robot, Vec3, Visual,
};

/// What the URDF needs beyond the kinematic description: per-body masses and the actuators'
/// limits, read from the compiled model.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfInputs {
    /// Kinematics.
    pub robot: RobotDescription,
    /// Mass of each body by name, kg.
    pub body_masses: Vec<(String, f64)>,
    /// Force or torque limit of each joint's actuator by joint name, N·m.
    pub effort_limits: Vec<(String, f64)>,
    /// Velocity limit of each joint by name (wheel control range; 0 where none), rad/s.
    pub velocity_limits: Vec<(String, f64)>,
    /// Steering joint range, rad.
    pub steer_range: [f64; 2],
}

fn lookup(v: &[(String, f64)], name: &str) -> f64 {
    v.iter().find(|(n, _)| n == name).map_or(0.0, |(_, m)| *m)
}

fn link(name: &str, mass: f64, visual: Option<(Geometry, [f64; 3])>) -> Link {
    // A small diagonal inertia keeps ROS tools happy; dynamics live in the MJCF.
    let i = (mass * 1e-3).max(1e-6);
    Link {
        name: name.to_owned(),
        inertial: Inertial {
            origin: Pose::default(),
            mass: Mass { value: mass },
            inertia: Inertia { ixx: i, ixy: 0.0, ixz: 0.0, iyy: i, iyz: 0.0, izz: i },
        },
        visual: visual
            .map(|(geometry, xyz)| Visual {
                name: None,
                origin: Pose { xyz: Vec3(xyz), rpy: Vec3([0.0; 3]) },
                geometry,
                material: None,
            })
            .into_iter()
            .collect(),
        collision: Vec::new(),
    }
}

fn joint(
    name: &str,
    kind: JointType,
    parent: &str,
    child: &str,
    xyz: [f64; 3],
    axis: [f64; 3],
    limit: JointLimit,
) -> Joint {
    Joint {
        name: name.to_owned(),
        joint_type: kind,
        origin: Pose { xyz: Vec3(xyz), rpy: Vec3([0.0; 3]) },
        parent: LinkName { link: parent.to_owned() },
        child: LinkName { link: child.to_owned() },
        axis: Axis { xyz: Vec3(axis) },
        limit,
        calibration: None,
        dynamics: None,
        mimic: None,
        safety_controller: None,
    }
}

/// The URDF robot.
pub fn momaro_urdf(inp: &UrdfInputs) -> Robot {
    let r = &inp.robot;
    let base_mass = inp.body_masses.iter().find(|(n, _)| n == "base").map_or(0.0, |(_, m)| *m);
    let h = r.base_half_extents;
    let mut links = vec![link(
        "base",
        base_mass,
        Some((Geometry::Box { size: Vec3([2.0 * h[0], 2.0 * h[1], 2.0 * h[2]]) }, [0.0; 3])),
    )];
    let mut joints = Vec::new();
    let y = [0.0, 1.0, 0.0];
    for leg in Leg::ALL {
        let p = leg.prefix();
        let names =
            [format!("{p}_thigh"), format!("{p}_shin"), format!("{p}_foot"), format!("{p}_steer")];
        let lengths = [r.thigh_length, r.shin_length, r.foot_length];
        for (k, len) in lengths.iter().enumerate() {
            links.push(link(
                &names[k],
                lookup(&inp.body_masses, &names[k]),
                Some((Geometry::Cylinder { radius: 0.025, length: *len }, [0.0, 0.0, -len / 2.0])),
            ));
        }
        links.push(link(&names[3], lookup(&inp.body_masses, &names[3]), None));
        let parents = ["base".to_owned(), names[0].clone(), names[1].clone(), names[2].clone()];
        let origins = [
            r.hips[leg.index()],
            [0.0, 0.0, -r.thigh_length],
            [0.0, 0.0, -r.shin_length],
            [0.0, 0.0, -r.foot_length],
        ];
        for (k, jn) in ["hip", "knee", "ankle"].iter().enumerate() {
            let name = format!("{p}_{jn}");
            let range = r.joint_ranges[k];
            let limit = JointLimit {
                lower: range.min,
                upper: range.max,
                effort: lookup(&inp.effort_limits, &name),
                velocity: lookup(&inp.velocity_limits, &name),
            };
            joints.push(joint(
                &name,
                JointType::Revolute,
                &parents[k],
                &names[k],
                origins[k],
                y,
                limit,
            ));
        }
        let steer = format!("{p}_steer");
        let limit = JointLimit {
            lower: inp.steer_range[0],
            upper: inp.steer_range[1],
            effort: lookup(&inp.effort_limits, &steer),
            velocity: lookup(&inp.velocity_limits, &steer),
        };
        joints.push(joint(
            &steer,
            JointType::Revolute,
            &parents[3],
            &names[3],
            origins[3],
            [0.0, 0.0, 1.0],
            limit,
        ));
        for (side, sign) in [("l", 1.0), ("r", -1.0)] {
            let wheel = format!("{p}_wheel_{side}");
            links.push(link(
                &wheel,
                lookup(&inp.body_masses, &wheel),
                Some((Geometry::Sphere { radius: r.wheel_radius }, [0.0; 3])),
            ));
            let limit = JointLimit {
                lower: 0.0,
                upper: 0.0,
                effort: lookup(&inp.effort_limits, &wheel),
                velocity: lookup(&inp.velocity_limits, &wheel),
            };
            joints.push(joint(
                &wheel,
                JointType::Continuous,
                &names[3],
                &wheel,
                [0.0, sign * r.wheel_track / 2.0, 0.0],
                y,
                limit,
            ));
        }
    }
    Robot { name: "momaro".to_owned(), links, joints, materials: Vec::new() }
}

/// The URDF as XML text.
///
/// # Errors
/// urdf-rs's serialisation error.
pub fn momaro_urdf_string(inp: &UrdfInputs) -> Result<String, urdf_rs::UrdfError> {
    urdf_rs::write_to_string(&momaro_urdf(inp))
}
