//! The hybrid graph's configuration ([`HybridConfig`]: the paper's manoeuvre constants and
//! the motion generator's, which the manoeuvres check with) and the counters of what a
//! search generated ([`ManoeuvreStats`]).

use super::driving::DrivingConfig;
use super::heuristic::cost_to_go;
use super::lattice::Neighbourhood;
use crate::feasibility::MotionOptions;
use crate::params::Params;
use crate::robot::RobotDescription;
use serde::Serialize;

/// Configuration of the hybrid graph: the driving part and the manoeuvre constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HybridConfig {
    /// Driving moves, k_Δθ, turn radius.
    pub driving: DrivingConfig,
    /// Step cost weight on L_step (eq. 5).
    pub k7: f64,
    /// Step cost weight on C_F(c_h) − 1 (eq. 5).
    pub k8: f64,
    /// Step cost weight on ΔH_step (eq. 5).
    pub k9: f64,
    /// Base shift weight (C_BS).
    pub k10: f64,
    /// Single foot move weight (eq. 6).
    pub k11: f64,
    /// Factor on every step-related manoeuvre cost (Sec. V, Fig. 7).
    pub step_cost_factor: f64,
    /// Criterion 1: an infinite-cost cell closer than this to the foot, m.
    pub step_obstacle_distance_m: f64,
    /// Criterion 3: largest |ΔH| of a step, m.
    pub max_step_height_m: f64,
    /// Largest height difference a wheel drives over (eq. 2), m.
    pub max_foot_height_diff_m: f64,
    /// Criterion 4: the feet on the non-stepping side must be farther apart, m.
    pub min_support_side_length_m: f64,
    /// Shortest "front foot forward" move, m (each such move drives as far as it can).
    pub foot_move_increment_m: f64,
    /// Cap on distinct footprints (graph size guard).
    pub max_footprints: usize,
    /// Orientation groups of the heuristic's cost-to-go, one layer of nodes each (a
    /// divisor of the lattice's orientations; see `cost_to_go`).
    pub cost_to_go_groups: usize,
    /// Most (cell, group) nodes for which the heuristic's cost-to-go keeps
    /// `cost_to_go_groups` layers (`cost_to_go::MAX_ORIENTED_NODES`); above, one layer.
    pub max_oriented_nodes: usize,
    /// Smallest stability margin of a posture, m (the generator's requirement).
    pub min_stability_margin_m: f64,
    /// Whether a step check that failed answers the same check on the same terrain at
    /// another cell (module docs, "Translated step failures").
    pub reuse_translated_step_failures: bool,
    /// The motion generator's constants: the leg-height rule for standing manoeuvres
    /// (reach and leg clearance, Sec. VI-B), the driving leg height, the base circles'
    /// radius, the wheel-to-centre move and gap of a step; with them steps are checked
    /// (the manoeuvres' checks, `motion::manoeuvres`), whose margin is the generator's plus
    /// [`PLANNER_MARGIN_SLACK_M`].
    pub motion: MotionOptions,
}

/// Margin the planner's step check requires beyond the generator's, m: the planner's CoM
/// estimate (`posture::standing::EstimatedCom`) is MuJoCo's to a micrometre with the wheels
/// level, but the roll of eqs. 6–8 is iterated to 3 mm of its target with either model, so
/// the generator's roll may differ slightly from the planner's.
pub const PLANNER_MARGIN_SLACK_M: f64 = 0.003;

impl HybridConfig {
    /// From the paper's constants and the robot's neutral footprint; the shortest foot
    /// move is 0.1 m and up to 65 536 footprints (all `u16` ids) are allowed.
    pub fn new(params: &Params, robot: &RobotDescription, neighbourhood: Neighbourhood) -> Self {
        Self {
            driving: DrivingConfig::new(params, &robot.neutral_footprint(), neighbourhood),
            k7: params.k7,
            k8: params.k8,
            k9: params.k9,
            k10: params.k10,
            k11: params.k11,
            step_cost_factor: params.step_cost_factor,
            step_obstacle_distance_m: params.step_obstacle_distance_m,
            max_step_height_m: params.max_step_height_m,
            max_foot_height_diff_m: params.max_foot_height_diff_m,
            min_support_side_length_m: params.min_support_side_length_m,
            foot_move_increment_m: 0.1,
            max_footprints: 65_536,
            cost_to_go_groups: cost_to_go::ORIENTATION_GROUPS,
            max_oriented_nodes: cost_to_go::MAX_ORIENTED_NODES,
            min_stability_margin_m: params.min_stability_margin_m,
            reuse_translated_step_failures: true,
            motion: {
                let mut m = MotionOptions::from_params(params);
                m.min_margin_m += PLANNER_MARGIN_SLACK_M;
                m.min_three_contact_margin_m += PLANNER_MARGIN_SLACK_M;
                m
            },
        }
    }
}

/// Counters of the manoeuvres generated, for reports and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ManoeuvreStats {
    /// Steps generated (edges, counted per expansion).
    pub steps: u64,
    /// Base shifts generated.
    pub base_shifts: u64,
    /// Front-foot-forward moves generated.
    pub foot_forward: u64,
    /// Foot-to-neutral moves generated.
    pub foot_neutral: u64,
    /// Manoeuvres dropped because the footprint table was full.
    pub footprint_table_full: u64,
    /// Step checks the motion generator passed (the checks run: each step of a state is
    /// checked once, `step_checks` memoises it).
    pub step_checks_passed: u64,
    /// Step checks that found no leg height within reach (the standing rule's
    /// `step_heights`): the generator was not asked.
    pub steps_without_leg_height: u64,
    /// Step checks of a front leg the generator turned down: no candidate motion kept
    /// the robot stable and within reach.
    pub front_steps_unstable: u64,
    /// The same for a rear leg.
    pub rear_steps_unstable: u64,
    /// Step checks that failed otherwise (no standing posture before the step, unknown
    /// terrain).
    pub steps_failed_otherwise: u64,
    /// Steps turned away, without a check, by a failed check of the same step on the
    /// same terrain at another cell (module docs, "Translated step failures").
    pub step_failures_translated: u64,
}

impl ManoeuvreStats {
    /// Step checks that failed, for any reason.
    pub fn steps_failed(&self) -> u64 {
        self.steps_without_leg_height
            + self.front_steps_unstable
            + self.rear_steps_unstable
            + self.steps_failed_otherwise
    }
}
