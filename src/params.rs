//! The paper's constants, in one place.
//!
//! Every number that Klamt & Behnke (IROS 2017) give lives here with the paper's value as
//! its default and a doc comment naming the equation or section it comes from. Scenarios
//! may override any of them (`[params]` table in a scenario file); robot dimensions do not
//! live here: they are read from the model (see `robot`).

use serde::{Deserialize, Serialize};

/// All tunable constants of the planner, cost client and step motion generator.
///
/// Field names follow the paper's symbols. `Default` gives the paper's values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Height-map cell size (m). Sec. IV: 2.5 cm.
    pub grid_resolution_m: f64,
    /// Number of discrete base orientations. Sec. IV: 64.
    pub orientations: u32,

    /// Foot cost weight k1 (eq. 1).
    pub k1: f64,
    /// Foot radius r_F (eq. 2): a height difference above `max_foot_height_diff_m` closer
    /// than this makes the foot cost infinite. Used by `foot_model = "paper"` only; the
    /// wheel-pair model takes the wheels' footprint from the robot model instead.
    pub r_f_m: f64,
    /// Neighbourhood radius r_N (eq. 2) over which height differences are accumulated.
    pub r_n_m: f64,
    /// Untraversable height difference for a wheel (eq. 2): 0.05 m.
    pub max_foot_height_diff_m: f64,
    /// Which ground a foot must find free of height differences above
    /// `max_foot_height_diff_m` (eq. 2, first case): the paper's disc of radius `r_f_m`
    /// (the default) or the wheel pair's own contact footprint at the foot's heading
    /// (see [`FootModel`] and `cost::foot`).
    pub foot_model: FootModel,
    /// Which manoeuvres prepare steps (see [`StepModel`]): `paper` (the default) or
    /// `stairs`.
    pub step_model: StepModel,

    /// Body cost weight k2 on missing clearance under the base (eq. 3).
    pub k2: f64,
    /// Body cost weight k3 on the height difference between lowest and highest foot (eq. 3).
    pub k3: f64,
    /// Radius of the two circles approximating the base (Sec. IV): 0.25 m.
    pub base_circle_radius_m: f64,

    /// Pose cost weight k4 on the maximum foot cost (eq. 4).
    pub k4: f64,
    /// Pose cost weight k5 on the sum of foot costs (eq. 4).
    pub k5: f64,
    /// Pose cost weight k6 on the body cost (eq. 4).
    pub k6: f64,

    /// Step criterion (Sec. V): a foot closer than this to an infinite-cost cell may step.
    pub step_obstacle_distance_m: f64,
    /// Step criterion (Sec. V): maximum absolute height difference of a step.
    pub max_step_height_m: f64,
    /// Step criterion (Sec. V): minimum distance between the two feet on the
    /// non-stepping side.
    pub min_support_side_length_m: f64,
    /// Step cost weight k7 on the step length (eq. 5).
    pub k7: f64,
    /// Step cost weight k8 on the foothold's foot cost minus one (eq. 5).
    pub k8: f64,
    /// Step cost weight k9 on the step height (eq. 5).
    pub k9: f64,
    /// Base shift cost weight k10 (eq. C_BS = k10 · L_BS · C_B,avg, Sec. V).
    pub k10: f64,
    /// Single foot move cost weight k11 (eq. 6, C_FM = k11 · L_FM · C_F,avg).
    pub k11: f64,
    /// Factor on all step-related manoeuvre costs (C_S, C_BS, C_FM; Sec. V, Fig. 7). The
    /// paper gives no number, only the rule: before a 0.2 m platform, a 1.5 m ramp detour
    /// just wins over stepping.
    ///
    /// Calibrated on `scenarios/ramp_detour.toml` (0.2 m platform 2 m ahead, a ramp whose
    /// straight-segment detour is 1.55 m longer than the direct route; the planned detour
    /// drives 2.3 m more) with the optimal planner (ARA* run to ε = 1, k12 = 2) and the
    /// standing rule that planner and step generator share (Sec. VI-B). The optimal
    /// four-step plan costs 12.56 + 3.519 · f (driving plus step-related terms), the
    /// detour 49.56, so the plan switches at f = 10.51: `momaro plan` finds the four steps
    /// at 10.5 and the detour at 10.55. 10.75 makes the detour just win (by 1.7 %), while
    /// on `scenarios/ramp_far.toml` (detour 3.8 m longer, cost 53.0) stepping (50.39)
    /// wins; stepping would lose there above f = 11.49. Both are asserted by
    /// `tests/planner_scenarios.rs`. The number is large because the cost client prices a
    /// 0.2 m ramp of any length at about 37 units of pose cost above flat driving
    /// (C_F ≈ 1 + 375 · slope on a plane; eq. 1).
    pub step_cost_factor: f64,

    /// Maximum orientation cost factor k12 (Sec. VII-A, Fig. 8).
    pub k12: f64,
    /// Orientation difference below which the orientation factor is 1 (Fig. 8): 2π/60.
    pub orientation_free_band_rad: f64,

    /// Leg height while driving with the neutral footprint (Sec. VI-B): 0.27 m.
    pub driving_leg_height_m: f64,
    /// Soft minimum leg height for manoeuvres other than driving (Sec. VI-B): 0.45 m.
    pub manoeuvre_leg_height_m: f64,
    /// Base pitch as a fraction of the ground slope (Sec. VI-B): 70 %.
    pub base_pitch_slope_fraction: f64,
    /// Minimum static stability margin accepted for a keyframe (m).
    pub min_stability_margin_m: f64,
    /// Support margin measured in the simulation (CoM over the wheel contacts of the three
    /// support legs) required before a foot is lifted, m (the executor's closed loop on
    /// stability, issue 7): 2 cm, the smallest margin the paper's scenarios expect during
    /// execution.
    pub min_lift_margin_m: f64,
    /// Margin a step's three support legs need on top of `min_lift_margin_m` while a foot
    /// is lifted, m: when the foot unloads, the compliant support legs let the CoM sag
    /// toward it (measured in MuJoCo: 2.5–3 cm on the platform's and the staircase's front
    /// steps up), which the CoM estimate of a posture leaves out. The executor asks this
    /// much more before it lifts a foot; the motion generator (and with it the planner's
    /// step check) asks it of every posture with three feet in contact, so that a planned
    /// step is one the executor lifts. Ours: 0.03 m.
    pub lift_margin_reserve_m: f64,
    /// Longest wheel-to-centre move of the stepping side's other wheel pair (Sec. VI-A,
    /// Fig. 12a), m. Ours: 0.45 m.
    pub max_wheel_to_centre_m: f64,
    /// Smallest longitudinal gap the displaced wheel pair keeps to the stepping foot, m.
    /// Ours: 0.3 m (two wheel pairs' length with room to spare).
    pub wheel_gap_m: f64,

    /// ARA*: initial heuristic weight (Sec. VIII): 3.0.
    pub arastar_initial_epsilon: f64,
    /// ARA*: factor by which ε − 1 shrinks after each solution (exponential decay).
    pub arastar_epsilon_decay: f64,
    /// ARA*: ε of a greedy probe searched before the paper's schedule (`search::arastar`),
    /// whose solution is kept, with its certified bound, for when a limit stops the
    /// schedule. Not in the paper; at most `arastar_initial_epsilon` turns it off. 50:
    /// on seed 1's 13 generated up-and-over courses it finds a path in 0.2–1.5 s each,
    /// where ε = 3 found 6 within 30 s (and ε = 20 needed up to 18 s).
    pub arastar_probe_epsilon: f64,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            grid_resolution_m: 0.025,
            orientations: 64,
            k1: 100.0,
            r_f_m: 0.12,
            r_n_m: 0.3,
            max_foot_height_diff_m: 0.05,
            foot_model: FootModel::Paper,
            step_model: StepModel::Paper,
            k2: 1.0,
            k3: 0.5,
            base_circle_radius_m: 0.25,
            k4: 0.1,
            k5: 0.1,
            k6: 0.5,
            step_obstacle_distance_m: 0.1,
            max_step_height_m: 0.3,
            min_support_side_length_m: 0.5,
            k7: 0.5,
            k8: 0.1,
            k9: 2.3,
            k10: 0.5,
            k11: 0.125,
            step_cost_factor: 10.75,
            k12: 2.0,
            orientation_free_band_rad: std::f64::consts::TAU / 60.0,
            driving_leg_height_m: 0.27,
            manoeuvre_leg_height_m: 0.45,
            base_pitch_slope_fraction: 0.7,
            min_stability_margin_m: 0.03,
            min_lift_margin_m: 0.02,
            lift_margin_reserve_m: 0.03,
            max_wheel_to_centre_m: 0.45,
            wheel_gap_m: 0.3,
            arastar_initial_epsilon: 3.0,
            arastar_epsilon_decay: 0.5,
            arastar_probe_epsilon: 50.0,
        }
    }
}

/// The foot model of the foot cost's infinite case (eq. 2, first case), written
/// `foot_model = "paper"` or `foot_model = "wheel_pair"` in a scenario's `[params]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FootModel {
    /// The paper's (eq. 2): infinite when a height difference above the limit lies
    /// closer than r_F to the cell, whatever the foot's heading.
    #[default]
    Paper,
    /// The wheel pair's contact footprint: the two wheels of the model (radius and
    /// spacing read from the model file), side by side across the foot's heading, which
    /// is the base heading. Infinite when a height difference above the limit lies under
    /// a wheel at that heading; the r_N sum (eq. 1) is the paper's.
    WheelPair,
}

impl FootModel {
    /// The name used in scenario files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FootModel::Paper => "paper",
            FootModel::WheelPair => "wheel_pair",
        }
    }
}

/// Which manoeuvres prepare a step, written `step_model = "paper"` or
/// `step_model = "stairs"` in a scenario's `[params]`. With either, a step is planned
/// only where the motion generator's own check expands it (`motion::manoeuvres`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StepModel {
    /// The paper's manoeuvres (Sec. V), the front feet never behind neutral. Fast on the
    /// paper's scenarios; it climbs three building-code steps but finds no path up a
    /// flight longer than the robot's feet span (four or more).
    #[default]
    Paper,
    /// Adds the rear-step approach (a base shift past the front feet's neutral, where
    /// their way ahead is blocked, so a rear foot reaches a riser while the front feet
    /// stand on a short tread), the climb shift (on a flight longer than the robot, the
    /// base forward past the front feet's neutral so a rear foot can step and the front
    /// legs reach the next tread), and the generator's partner wheel stops short of
    /// where its leg leaves reach before a step (with `paper` such a step fails).
    /// Climbs and descends building-code stairs; plans the paper's staircase slower, as
    /// more manoeuvres are open.
    Stairs,
}

impl StepModel {
    /// The name used in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            StepModel::Paper => "paper",
            StepModel::Stairs => "stairs",
        }
    }
}

/// A parameter that fails validation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("parameter `{name}` = {value} is invalid: {reason}")]
pub struct InvalidParam {
    /// Field name as written in a scenario's `[params]` table.
    pub name: &'static str,
    /// Offending value.
    pub value: f64,
    /// What a valid value looks like.
    pub reason: &'static str,
}

impl Params {
    /// Checks every field for finiteness and sign.
    ///
    /// # Errors
    /// The first invalid field, by name.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        let positive: [(&'static str, f64); 16] = [
            ("grid_resolution_m", self.grid_resolution_m),
            ("r_f_m", self.r_f_m),
            ("r_n_m", self.r_n_m),
            ("max_foot_height_diff_m", self.max_foot_height_diff_m),
            ("base_circle_radius_m", self.base_circle_radius_m),
            ("step_obstacle_distance_m", self.step_obstacle_distance_m),
            ("max_step_height_m", self.max_step_height_m),
            ("min_support_side_length_m", self.min_support_side_length_m),
            ("step_cost_factor", self.step_cost_factor),
            ("k12", self.k12),
            ("orientation_free_band_rad", self.orientation_free_band_rad),
            ("driving_leg_height_m", self.driving_leg_height_m),
            ("manoeuvre_leg_height_m", self.manoeuvre_leg_height_m),
            ("arastar_initial_epsilon", self.arastar_initial_epsilon),
            ("max_wheel_to_centre_m", self.max_wheel_to_centre_m),
            ("wheel_gap_m", self.wheel_gap_m),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(InvalidParam { name, value, reason: "must be a finite number > 0" });
            }
        }
        let non_negative: [(&'static str, f64); 15] = [
            ("k1", self.k1),
            ("k2", self.k2),
            ("k3", self.k3),
            ("k4", self.k4),
            ("k5", self.k5),
            ("k6", self.k6),
            ("k7", self.k7),
            ("k8", self.k8),
            ("k9", self.k9),
            ("k10", self.k10),
            ("k11", self.k11),
            ("base_pitch_slope_fraction", self.base_pitch_slope_fraction),
            ("min_stability_margin_m", self.min_stability_margin_m),
            ("min_lift_margin_m", self.min_lift_margin_m),
            ("lift_margin_reserve_m", self.lift_margin_reserve_m),
        ];
        for (name, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(InvalidParam { name, value, reason: "must be a finite number >= 0" });
            }
        }
        if self.orientations < 4 || !self.orientations.is_multiple_of(4) {
            return Err(InvalidParam {
                name: "orientations",
                value: f64::from(self.orientations),
                reason: "must be a multiple of 4, at least 4",
            });
        }
        if self.k12 < 1.0 {
            return Err(InvalidParam { name: "k12", value: self.k12, reason: "must be >= 1" });
        }
        if self.arastar_initial_epsilon < 1.0 {
            return Err(InvalidParam {
                name: "arastar_initial_epsilon",
                value: self.arastar_initial_epsilon,
                reason: "must be >= 1",
            });
        }
        if !(self.arastar_probe_epsilon.is_finite() && self.arastar_probe_epsilon >= 1.0) {
            return Err(InvalidParam {
                name: "arastar_probe_epsilon",
                value: self.arastar_probe_epsilon,
                reason: "must be a finite number >= 1",
            });
        }
        if !(self.arastar_epsilon_decay > 0.0 && self.arastar_epsilon_decay < 1.0) {
            return Err(InvalidParam {
                name: "arastar_epsilon_decay",
                value: self.arastar_epsilon_decay,
                reason: "must lie in (0, 1)",
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers_and_valid() {
        let p = Params::default();
        assert_eq!(p.k1, 100.0);
        assert_eq!(p.k9, 2.3);
        assert_eq!(p.orientations, 64);
        assert!((p.k4 + p.k5 * 4.0 + p.k6 - 1.0).abs() < 1e-12, "pose cost is 1 on flat ground");
        p.validate().unwrap();
    }

    #[test]
    fn nan_is_rejected_by_name() {
        let p = Params { k3: f64::NAN, ..Params::default() };
        let e = p.validate().unwrap_err();
        assert_eq!(e.name, "k3");
    }
}
