//! Reads the robot's description from the compiled MuJoCo model: segment lengths, hip
//! positions, wheel geometry, joint ranges, the neutral footprint and the mass. This is the
//! one place robot numbers enter the program (`models/momaro.xml` is their source).

use super::SimError;
use crate::robot::{Leg, Range, RobotDescription};
use mujoco_rs::prelude::*;

/// Element names of one leg in the model.
pub(crate) struct LegNames {
    pub thigh: String,
    pub shin: String,
    pub foot: String,
    pub steer: String,
    pub wheels: [String; 2],
}

impl LegNames {
    pub(crate) fn of(leg: Leg) -> Self {
        let p = leg.prefix();
        Self {
            thigh: format!("{p}_thigh"),
            shin: format!("{p}_shin"),
            foot: format!("{p}_foot"),
            steer: format!("{p}_steer"),
            wheels: [format!("{p}_wheel_l"), format!("{p}_wheel_r")],
        }
    }
}

pub(crate) fn id(model: &MjModel, kind: MjtObjBase, name: &str) -> Result<usize, SimError> {
    model.name_to_id(kind, name).ok_or_else(|| SimError::MissingElement {
        kind: format!("{kind:?}").trim_start_matches("mjOBJ_").to_lowercase(),
        name: name.to_owned(),
    })
}

fn body_pos(model: &MjModel, name: &str) -> Result<[f64; 3], SimError> {
    Ok(model.body_pos()[id(model, MjtObjBase::mjOBJ_BODY, name)?])
}

/// Extracts the robot description.
///
/// # Errors
/// [`SimError::MissingElement`] if the model lacks a body, joint, geom or custom numeric the
/// description needs; [`SimError::BadModel`] if a number is inconsistent (legs differ, a
/// segment is not vertical in the zero configuration).
pub(crate) fn describe(model: &MjModel) -> Result<RobotDescription, SimError> {
    let bad = |what: String| SimError::BadModel(what);
    let fl = LegNames::of(Leg::FrontLeft);
    let thigh_length = -body_pos(model, &fl.shin)?[2];
    let shin_length = -body_pos(model, &fl.foot)?[2];
    let foot_length = -body_pos(model, &fl.steer)?[2];
    let wheel_geom = id(model, MjtObjBase::mjOBJ_GEOM, &fl.wheels[0])?;
    let wheel_radius = model.geom_size()[wheel_geom][0];
    let wheel_track = body_pos(model, &fl.wheels[0])?[1] - body_pos(model, &fl.wheels[1])?[1];

    let mut hips = [[0.0; 3]; 4];
    for leg in Leg::ALL {
        let n = LegNames::of(leg);
        hips[leg.index()] = body_pos(model, &n.thigh)?;
        // Every leg must share the front-left leg's segment lengths: the description has one set.
        let lengths = [
            -body_pos(model, &n.shin)?[2],
            -body_pos(model, &n.foot)?[2],
            -body_pos(model, &n.steer)?[2],
        ];
        if (lengths[0] - thigh_length).abs() > 1e-9
            || (lengths[1] - shin_length).abs() > 1e-9
            || (lengths[2] - foot_length).abs() > 1e-9
        {
            return Err(bad(format!("leg {} has different segment lengths from fl", leg.prefix())));
        }
        for child in [&n.shin, &n.foot, &n.steer] {
            let p = body_pos(model, child)?;
            if p[0].abs() > 1e-9 || p[1].abs() > 1e-9 {
                return Err(bad(format!("body {child} is not straight below its parent")));
            }
        }
    }
    if !(thigh_length > 0.0 && shin_length > 0.0 && foot_length > 0.0 && wheel_radius > 0.0) {
        return Err(bad("segment lengths and wheel radius must be positive".into()));
    }

    let joint_ranges = ["fl_hip", "fl_knee", "fl_ankle"].map(|name| {
        id(model, MjtObjBase::mjOBJ_JOINT, name).map(|j| {
            let r = model.jnt_range()[j];
            Range { min: r[0], max: r[1] }
        })
    });
    let [hip_range, knee_range, ankle_range] = joint_ranges;

    let numeric = id(model, MjtObjBase::mjOBJ_NUMERIC, "momaro/neutral_foot_offset_x")?;
    let adr =
        usize::try_from(model.numeric_adr()[numeric]).map_err(|_| bad("numeric address".into()))?;
    let size = usize::try_from(model.numeric_size()[numeric]).unwrap_or(0);
    if size != 4 {
        return Err(bad(format!("momaro/neutral_foot_offset_x has {size} values, expected 4")));
    }
    let offsets = &model.numeric_data()[adr..adr + 4];
    let neutral_foot_offset_x = [offsets[0], offsets[1], offsets[2], offsets[3]];

    let base = id(model, MjtObjBase::mjOBJ_BODY, "base")?;
    let base_box = id(model, MjtObjBase::mjOBJ_GEOM, "base_box")?;
    let base_half_extents = model.geom_size()[base_box];
    let base_box_pos = model.geom_pos()[base_box];
    let base_bottom_z = base_box_pos[2] - base_half_extents[2] - hips[0][2];

    Ok(RobotDescription {
        hips,
        thigh_length,
        shin_length,
        foot_length,
        wheel_radius,
        wheel_track,
        joint_ranges: [hip_range?, knee_range?, ankle_range?],
        neutral_foot_offset_x,
        base_half_extents,
        base_bottom_z,
        total_mass: model.body_subtreemass()[base],
        body_mass: model.body_mass()[base],
        body_com: model.body_ipos()[base],
    })
}

/// Masses and actuator limits for the URDF export.
///
/// # Errors
/// As [`describe`], and [`SimError::MissingElement`] for a missing steering joint.
pub(crate) fn urdf_inputs(model: &MjModel) -> Result<crate::urdf_export::UrdfInputs, SimError> {
    let robot = describe(model)?;
    let nbody = model.ffi().nbody as usize;
    let body_masses = (1..nbody)
        .filter_map(|b| {
            model
                .id_to_name(MjtObjBase::mjOBJ_BODY, b)
                .map(|n| (n.to_owned(), model.body_mass()[b]))
        })
        .collect();
    let mut effort_limits = Vec::new();
    let mut velocity_limits = Vec::new();
    for a in 0..model.ffi().nu as usize {
        let Some(name) = model.id_to_name(MjtObjBase::mjOBJ_ACTUATOR, a) else { continue };
        let force = model.actuator_forcerange()[a];
        effort_limits.push((name.to_owned(), force[0].abs().max(force[1].abs())));
        // Velocity servos (the wheels) have a velocity control range; position servos none.
        let is_velocity = model.actuator_biastype()[a] == MjtBias::mjBIAS_AFFINE
            && model.actuator_biasprm()[a][1] == 0.0;
        let ctrl = model.actuator_ctrlrange()[a];
        velocity_limits.push((name.to_owned(), if is_velocity { ctrl[1].abs() } else { 0.0 }));
    }
    let steer = model.jnt_range()[id(model, MjtObjBase::mjOBJ_JOINT, "fl_steer")?];
    Ok(crate::urdf_export::UrdfInputs {
        robot,
        body_masses,
        effort_limits,
        velocity_limits,
        steer_range: steer,
    })
}
