//! One feasibility model for the planner and the step motion generator: what the robot
//! can do where, asked cheaply by the planner and exactly by the generator, from the same
//! functions, so that a path the planner returns is a path the generator can expand.
//! (Nav2 keeps its collision checker apart from its planners in the same way.)
//!
//! **Driving** ([`DrivingCheck`]): the driving posture of Sec. VI-B at a pose
//! ([`kinematics::driving_posture`]: the feet in the neutral footprint on the height map,
//! the base pitched by 70 % of the slope and set by the highest foot) must be reachable by
//! every leg with the standing rule's reach margin (sagittal IK within the joint limits),
//! keep every thigh and shin clear of the terrain ([`StandingRule::legs_clear`] on the
//! height map dilated by the legs' width), and keep the lumped CoM estimate
//! ([`standing::com_estimate`]) inside the support polygon by the required margin.
//!
//! The generator checks this at every keyframe and at points 1 cm / 0.02 rad apart between
//! them; the planner checks it once per lattice pose (memoised with the pose cost) against
//! terrain dilated by [`crate::cost::SWEEP_CELLS`] more cells, which covers every point of the legs
//! between two neighbouring lattice poses: a move of the 20-neighbourhood (at most
//! √5 cells, 5.6 cm) or a turn of 2π/64 (4.6 cm at the farthest leg point, 0.47 m from the
//! centre) brings no leg point farther than 2.8 cm from where it stood at one of the two
//! ends.
//!
//! Stepping uses the standing rule of `posture::standing` (its step heights are what the
//! planner's reach check and the generator's step candidates share), and the planner runs
//! the generator's own step check (`motion::manoeuvres::step::check`) on the steps it admits,
//! and its own wheel-move and base-shift expansions (`wheel_move::check`,
//! `base_shift`) on the moves and shifts it admits; a wheel move between two
//! cells whose postures both clear the swept leg terrain needs none, by the argument
//! above.

use crate::cost::CostMaps;
use crate::geometry::Pose2;
use crate::params::{Params, StepModel};
use crate::posture::kinematics::{self, Posture, PostureError, solve_chains};
use crate::posture::standing::{self, StandingRule};
use crate::robot::RobotDescription;
use crate::support::stability_margin;
use crate::terrain::HeightMap;

/// Clearance the base's underside keeps above the terrain under its circles, m.
pub const BODY_CLEARANCE_M: f64 = 0.02;

/// Why a pose is infeasible.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Infeasible {
    /// A foot stands where the height map knows no ground.
    #[error("no terrain height at ({x:.3}, {y:.3})")]
    UnknownTerrain {
        /// World x, m.
        x: f64,
        /// World y, m.
        y: f64,
    },
    /// A leg cannot reach its foot, passes a joint limit or touches the terrain.
    #[error(transparent)]
    Posture(#[from] PostureError),
    /// The base's underside would not clear the terrain under its two circles (the
    /// paper's body model, Sec. IV); `clearance` is negative when the terrain reaches
    /// into the body.
    #[error("base {clearance_m:.3} m above the terrain under it")]
    BodyCollision {
        /// Underside above the highest terrain under a circle, m.
        clearance_m: f64,
    },
    /// The CoM lies too close to the edge of the support polygon.
    #[error("stability margin {margin_m:.3} m, {required_m} m required")]
    Margin {
        /// The margin, m.
        margin_m: f64,
        /// The required margin, m.
        required_m: f64,
    },
}

/// The driving-posture feasibility check (see the module docs).
#[derive(Debug, Clone)]
pub struct DrivingCheck {
    robot: RobotDescription,
    rule: StandingRule,
    leg_height_m: f64,
    min_margin_m: f64,
    circle_radius_m: f64,
}

impl DrivingCheck {
    /// The check with the paper's driving leg height and pitch fraction from `params`.
    pub fn new(robot: &RobotDescription, params: &Params) -> Self {
        Self::from_parts(
            robot,
            StandingRule::from_params(params),
            params.driving_leg_height_m,
            params.min_stability_margin_m,
            params.base_circle_radius_m,
        )
    }

    /// The check from its parts: the standing rule (reach margin, leg clearance, pitch
    /// fraction), the driving leg height, the required stability margin and the base
    /// circles' radius, m.
    pub fn from_parts(
        robot: &RobotDescription,
        rule: StandingRule,
        leg_height_m: f64,
        min_margin_m: f64,
        circle_radius_m: f64,
    ) -> Self {
        Self { robot: robot.clone(), rule, leg_height_m, min_margin_m, circle_radius_m }
    }

    /// The driving posture at `pose` on `heights`.
    ///
    /// # Errors
    /// [`Infeasible::UnknownTerrain`] where a foot has no ground.
    pub fn posture(&self, pose: &Pose2, heights: &HeightMap) -> Result<Posture, Infeasible> {
        kinematics::driving_posture(
            &self.robot,
            pose,
            self.leg_height_m,
            self.rule.pitch_fraction,
            |x, y| heights.height_at_cell(x, y),
        )
        .map_err(|[x, y]| Infeasible::UnknownTerrain { x, y })
    }

    /// Whether posture `p` is reachable (reach margin, joint limits), keeps every thigh
    /// and shin clear of `leg_terrain` and the base clear of the terrain under it
    /// ([`Self::body_clear`]), and keeps the CoM estimate `min_margin_m` inside the feet
    /// in contact; the joint angles if so.
    ///
    /// # Errors
    /// The first [`Infeasible`] found.
    pub fn posture_ok(
        &self,
        p: &Posture,
        maps: &CostMaps,
        leg_terrain: &HeightMap,
    ) -> Result<[[f64; 3]; 4], Infeasible> {
        let legs = solve_chains(&self.robot, p, self.rule.reach_margin_m)?;
        self.rule.legs_clear(&self.robot, leg_terrain, &legs)?;
        self.body_clear_in(p, &legs.frame.rotation, maps)?;
        let com = standing::solved_com_estimate(&self.robot, p, &legs);
        let support: Vec<[f64; 2]> =
            (0..4).filter(|&i| p.contact[i]).map(|i| [p.feet[i][0], p.feet[i][1]]).collect();
        let margin_m = stability_margin(&support, com);
        if margin_m < self.min_margin_m {
            return Err(Infeasible::Margin { margin_m, required_m: self.min_margin_m });
        }
        Ok(legs.joints())
    }

    /// Whether the base's underside (at hip level, `RobotDescription::base_bottom_z`)
    /// stays [`BODY_CLEARANCE_M`] above the highest terrain under each of the paper's two
    /// base circles (the cost client's disc maxima, `cost::body`): eq. 3 charges for
    /// lifting the body over an obstacle, and this is where lifting no longer helps.
    ///
    /// # Errors
    /// [`Infeasible::BodyCollision`], or unknown terrain under a circle.
    pub fn body_clear(&self, p: &Posture, maps: &CostMaps) -> Result<(), Infeasible> {
        self.body_clear_in(p, &kinematics::rotation(p.base_rpy), maps)
    }

    /// [`Self::body_clear`] with the base rotation `r` of `p` given.
    fn body_clear_in(
        &self,
        p: &Posture,
        r: &[[f64; 3]; 3],
        maps: &CostMaps,
    ) -> Result<(), Infeasible> {
        let z_under = self.robot.hips[0][2] + self.robot.base_bottom_z;
        let hm = maps.heights();
        for cx in self.robot.base_circle_centres_x(self.circle_radius_m) {
            let w = kinematics::apply(r, p.base_position, [cx, 0.0, z_under]);
            let Some((i, j)) = hm.cell_of(w[0], w[1]) else {
                return Err(Infeasible::UnknownTerrain { x: w[0], y: w[1] });
            };
            let Some(top) = maps.disc_max_layer().get(i, j) else {
                return Err(Infeasible::UnknownTerrain { x: w[0], y: w[1] });
            };
            if w[2] - top < BODY_CLEARANCE_M {
                return Err(Infeasible::BodyCollision { clearance_m: w[2] - top });
            }
        }
        Ok(())
    }

    /// The standing posture of the standing rule ([`StandingRule::stand`]) in the neutral
    /// footprint at `pose`, checked as [`Self::posture_ok`] does.
    ///
    /// # Errors
    /// The first [`Infeasible`] found.
    pub fn standing(
        &self,
        pose: &Pose2,
        maps: &CostMaps,
        leg_terrain: &HeightMap,
    ) -> Result<Posture, Infeasible> {
        let feet = self.posture(pose, maps.heights())?.feet;
        let (p, _) =
            self.rule.stand(&self.robot, leg_terrain, feet, [pose.x, pose.y], pose.theta)?;
        self.posture_ok(&p, maps, leg_terrain)?;
        Ok(p)
    }

    /// The planner's check of a neutral-footprint lattice pose: the robot can be there
    /// in its driving posture or, failing that, standing tall in the neutral footprint
    /// (the generator drives standing between close manoeuvres, and stands up where the
    /// driving posture does not fit: see `motion::expand`), checked against the swept
    /// leg terrain ([`CostMaps::swept_leg_terrain`]) so that every posture the generator
    /// samples between this pose and a neighbour is feasible too.
    ///
    /// # Errors
    /// The driving posture's [`Infeasible`] if neither fits.
    pub fn lattice_pose(&self, maps: &CostMaps, pose: &Pose2) -> Result<(), Infeasible> {
        let p = self.posture(pose, maps.heights())?;
        match self.posture_ok(&p, maps, maps.swept_leg_terrain()) {
            Ok(_) => Ok(()),
            Err(e) => {
                self.standing(pose, maps, maps.swept_leg_terrain()).map(|_| ()).map_err(|_| e)
            }
        }
    }
}

/// Constants of the motion generator (Sec. VI) that the planner checks its manoeuvres
/// with: the margins and the standing rule of this feasibility model, and the
/// generator's own limits, sampling and speeds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionOptions {
    /// Minimum static stability margin at every keyframe and interpolated point, m.
    pub min_margin_m: f64,
    /// Minimum margin of a posture with three feet in contact, m: the executor's lift
    /// threshold, `Params::min_lift_margin_m` + `Params::lift_margin_reserve_m` (5 cm),
    /// where it exceeds `min_margin_m`. The CoM estimate leaves out the sag of the
    /// compliant support legs toward an unloaded foot; a step whose lifted phase held only
    /// `min_margin_m` was one the executor's guard refused to lift.
    pub min_three_contact_margin_m: f64,
    /// With [`StepModel::Stairs`] the partner wheel stops where its leg leaves reach
    /// (a shorter move, the rest to roll and shift); with the paper's model a candidate
    /// whose wheel move leaves reach fails, as before (the shorter move admitted steps
    /// with less margin to the executor's lift guard on three generated courses).
    pub step_model: StepModel,
    /// The standing leg-height rule (Sec. VI-B), the one the planner checks reach with.
    pub standing: StandingRule,
    /// Driving leg height (Sec. VI-B), m.
    pub driving_leg_height_m: f64,
    /// Radius of the base's two circles (Sec. IV), m.
    pub base_circle_radius_m: f64,
    /// Largest base roll, rad.
    pub max_roll_rad: f64,
    /// Largest stabilising base shift, m.
    pub max_base_shift_m: f64,
    /// Largest wheel-to-centre displacement, m.
    pub max_wheel_to_centre_m: f64,
    /// Smallest longitudinal gap between the displaced wheel pair and the stepping foot, m.
    pub wheel_gap_m: f64,
    /// Driving distance to the next manoeuvre from which the robot lowers in between, m.
    pub stay_standing_m: f64,
    /// Interpolation sample spacing, m.
    pub sample_m: f64,
    /// Interpolation sample spacing, rad.
    pub sample_rad: f64,
    /// Base and wheel speed for timing, m/s.
    pub wheel_speed: f64,
    /// Swing foot speed for timing, m/s.
    pub foot_speed: f64,
    /// Roll, pitch and yaw rate for timing, rad/s.
    pub angular_speed: f64,
    /// Largest shift of the zero-moment point from the CoM's ground projection that a
    /// standing segment's own acceleration may cause where its margin has none to spare,
    /// m; elsewhere the margin beyond the required one (see `motion::Expander::duration`).
    pub zmp_shift_m: f64,
}

impl MotionOptions {
    /// The paper's values from `params`, conservative speeds (0.1 m/s, 0.2 rad/s).
    pub fn from_params(params: &Params) -> Self {
        Self {
            min_margin_m: params.min_stability_margin_m,
            min_three_contact_margin_m: params.min_lift_margin_m + params.lift_margin_reserve_m,
            step_model: params.step_model,
            standing: StandingRule::from_params(params),
            driving_leg_height_m: params.driving_leg_height_m,
            base_circle_radius_m: params.base_circle_radius_m,
            max_roll_rad: 0.2,
            max_base_shift_m: 0.2,
            max_wheel_to_centre_m: params.max_wheel_to_centre_m,
            wheel_gap_m: params.wheel_gap_m,
            stay_standing_m: 1.0,
            sample_m: 0.01,
            sample_rad: 0.02,
            wheel_speed: 0.1,
            foot_speed: 0.1,
            angular_speed: 0.2,
            zmp_shift_m: ZMP_SHIFT_M,
        }
    }

    /// The least margin posture `p` must hold: [`Self::min_margin_m`], and with three feet
    /// in contact at least [`Self::min_three_contact_margin_m`].
    pub fn required_margin(&self, p: &Posture) -> f64 {
        if p.contact.iter().filter(|&&c| c).count() == 3 {
            self.min_margin_m.max(self.min_three_contact_margin_m)
        } else {
            self.min_margin_m
        }
    }
}

impl Default for MotionOptions {
    fn default() -> Self {
        Self::from_params(&Params::default())
    }
}

/// Default of [`MotionOptions::zmp_shift_m`]: where a segment has no margin to spare, a
/// third of the 3 cm the checks ask on four feet, so that braking at its ends keeps its
/// zero-moment point at least 2 cm inside the support (`Expander::duration`).
pub const ZMP_SHIFT_M: f64 = 0.01;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_posture_on_three_feet_needs_the_lift_threshold() {
        // The paper's 3 cm for every posture; on three feet the executor's lift threshold,
        // 2 cm + 3 cm of sag reserve = 5 cm; a threshold below 3 cm does not lower it.
        let o = MotionOptions::default();
        let mut p = Posture {
            base_position: [0.0, 0.0, 0.5],
            base_rpy: [0.0; 3],
            feet: [[0.0; 3]; 4],
            contact: [true; 4],
        };
        assert!((o.required_margin(&p) - 0.03).abs() < 1e-12);
        p.contact[2] = false;
        assert!((o.required_margin(&p) - 0.05).abs() < 1e-12);
        let low = MotionOptions { min_three_contact_margin_m: 0.01, ..o };
        assert!((low.required_margin(&p) - 0.03).abs() < 1e-12);
    }

    fn maps(f: impl Fn(f64, f64) -> f64) -> CostMaps {
        let hm = HeightMap::from_fn([-2.0, -2.0], 0.025, 160, 160, |i, j| {
            f(-2.0 + (i as f64 + 0.5) * 0.025, -2.0 + (j as f64 + 0.5) * 0.025)
        })
        .unwrap();
        CostMaps::build(&hm, &RobotDescription::reference(), &Params::default()).unwrap()
    }

    #[test]
    fn flat_ground_is_feasible_everywhere_inside() {
        let m = maps(|_, _| 0.0);
        let c = DrivingCheck::new(&RobotDescription::reference(), &Params::default());
        for k in 0..16 {
            let pose = Pose2::new(0.1, -0.2, f64::from(k) * 0.4);
            c.lattice_pose(&m, &pose).unwrap();
        }
    }

    #[test]
    fn a_doorway_passed_at_an_angle_is_a_leg_collision_the_foot_cost_misses() {
        // A 1.02 m doorway in a 1 m wall (x ∈ [1.7, 1.9]). Turned 34° in it, every wheel
        // pair keeps r_F = 0.12 m from the wall (finite foot cost, the paper's planner
        // admits the pose), but the right rear leg's knee, bent toward the body centre,
        // reaches over the wall: the pose a planned path once drove through and the
        // motion generator rejected.
        let robot = RobotDescription::reference();
        let wall = |y: f64| {
            crate::scenario::Primitive::Box(crate::scenario::terrain::Block {
                center: [1.8, y],
                size: [0.2, 1.5],
                height: 1.0,
                yaw_deg: 0.0,
            })
        };
        let hm =
            crate::terrain::rasterise(&[wall(1.26), wall(-1.26)], [0.0, -2.0], [3.5, 4.0], 0.025)
                .unwrap();
        let m = CostMaps::build(&hm, &robot, &Params::default()).unwrap();
        let c = DrivingCheck::new(&robot, &Params::default());
        let angled = Pose2::new(1.5625, -0.1875, 33.75f64.to_radians());
        assert!(m.driving_pose_cost(&angled).finite().is_some());
        match c.lattice_pose(&m, &angled) {
            Err(Infeasible::Posture(PostureError::LegCollision { .. })) => {}
            other => panic!("expected a leg collision, got {other:?}"),
        }
        // Square to the doorway, in its middle: through.
        c.lattice_pose(&m, &Pose2::new(1.8, 0.0, 0.0)).unwrap();
    }

    #[test]
    fn unknown_ground_under_a_foot_is_named() {
        let m = maps(|x, _| if x > 0.0 { f64::NAN } else { 0.0 });
        let c = DrivingCheck::new(&RobotDescription::reference(), &Params::default());
        match c.lattice_pose(&m, &Pose2::new(0.0, 0.0, 0.0)) {
            Err(Infeasible::UnknownTerrain { x, .. }) => assert!(x > 0.0),
            other => panic!("expected unknown terrain, got {other:?}"),
        }
    }
}
