//! The expansion of an abstract path into keyframes (Sec. VI): [`expand_path`] walks the
//! path's elements and hands each to the unit of its manoeuvre (`manoeuvres`), which
//! appends its keyframes to one [`Expander`] holding the robot's actual posture.
//!
//! - **Start**: the driving posture at the first pose.
//! - **Stand up / lower** (Fig. 13b, n): before the first manoeuvre that is not a drive
//!   or turn the robot stands up (the manoeuvre's unit asks,
//!   [`Expander::stand_if_driving`]); a drive lowers it again where the next such
//!   manoeuvre is far (`manoeuvres::drive`), and the path ends in the driving posture
//!   where it fits.
//! - **Leg heights while standing** (Sec. VI-B): the base height is set by the highest
//!   foot, whose leg gets the manoeuvre height (0.45 m, a soft constraint); the others are
//!   longer. When a leg would then exceed its reach (hard constraint), the leg height is
//!   lowered in 1 cm steps (down to the driving height). Before each step, wheel move and
//!   planned base shift the base settles into the shared rule's standing posture at the
//!   planned pose ([`Expander::settle`]), the posture the planner checked it from.

use super::expander::{Expander, MotionError};
use super::keyframe::{DetailedPath, Keyframe, Phase};
use super::manoeuvres::unit_for;
use crate::cost::CostMaps;
use crate::feasibility::MotionOptions;
use crate::geometry::Pose2;
use crate::path::{ManoeuvreKind, PathElement};
use crate::posture::CenterOfMassModel;
use crate::posture::kinematics::{Posture, evaluate};
use crate::robot::RobotDescription;

/// Expands an abstract path (`planner::PlanSummary::path`) into a detailed path of
/// stable keyframes (see the module docs).
///
/// # Errors
/// [`MotionError`] naming the path element (and for steps the leg and best margin) when no
/// stable, reachable motion is found, or a foot stands on unknown terrain.
pub fn expand_path(
    path: &[PathElement],
    robot: &RobotDescription,
    maps: &CostMaps,
    model: &mut dyn CenterOfMassModel,
    options: &MotionOptions,
) -> Result<DetailedPath, MotionError> {
    let first = path.first().ok_or(MotionError::EmptyPath)?;
    let placeholder = Posture {
        base_position: [first.pose.x, first.pose.y, 0.0],
        base_rpy: [0.0, 0.0, first.pose.theta],
        feet: [[0.0; 3]; 4],
        contact: [true; 4],
    };
    let mut ex = Expander::at(robot, maps, model, options, placeholder);
    let start = ex.driving(&first.pose)?;
    ex.cur = start;
    let e = evaluate(robot, ex.model, &start, options.standing.reach_margin_m)
        .map_err(|e| MotionError::Manoeuvre { index: 0, kind: "start", reason: e.to_string() })?;
    ex.min_margin = e.margin;
    ex.samples = 1;
    ex.keys.push(Keyframe {
        time_s: 0.0,
        phase: Phase::Start,
        path_index: 0,
        leg: None,
        base_position: start.base_position,
        base_rpy: start.base_rpy,
        feet: start.feet,
        contact: start.contact,
        leg_heights: e.leg_heights,
        joints: e.joints,
        com: e.com,
        margin_m: e.margin,
        segment_min_margin_m: e.margin,
        centroid_distance_m: e.centroid_distance,
    });
    for (k, el) in path.iter().enumerate().skip(1) {
        ex.index = k;
        if let Some(unit) = unit_for(el.kind) {
            unit.expand(&mut ex, path, k)?;
        }
    }
    if ex.standing {
        ex.index = path.len() - 1;
        let pose = Pose2 {
            x: ex.cur.base_position[0],
            y: ex.cur.base_position[1],
            theta: ex.cur.base_rpy[2],
        };
        let p = ex.driving(&pose)?;
        // Where the driving posture does not fit (the planner admitted the goal standing),
        // the robot finishes standing.
        if ex.driving_check().posture_ok(&p, maps, maps.leg_terrain()).is_ok() {
            ex.push(ManoeuvreKind::Drive, &[(Phase::Lower, None, p)])?;
        }
    }
    let min_keyframe = ex.keys.iter().map(|k| k.margin_m).fold(f64::INFINITY, f64::min);
    Ok(DetailedPath {
        duration_s: ex.time,
        min_keyframe_margin_m: min_keyframe,
        min_margin_m: ex.min_margin,
        min_three_contact_margin_m: ex.min_three,
        samples_checked: ex.samples,
        steps: ex.steps,
        keyframes: ex.keys,
    })
}
