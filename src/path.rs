//! The abstract path: what the hybrid planner hands the motion generator (Sec. V–VI).
//!
//! A path is a list of [`PathElement`]s: each a lattice pose, the four feet, and the
//! [`ManoeuvreKind`] that reached it (the first element's kind is
//! [`ManoeuvreKind::Start`]). [`EdgeLabel`] says what one edge of the planner's graph
//! does; [`StepCost`] holds the parts of a step's cost C_S (eq. 5). These types sit
//! below both the planner, which produces them, and the motion generator, which expands
//! them, so neither imports the other for them.

use crate::geometry::Pose2;
use crate::robot::Leg;
use serde::Serialize;

/// What a manoeuvre does: the one kind shared by the planner's edges, the path's
/// elements and the motion generator's expansions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ManoeuvreKind {
    /// The path's start pose: reached by no manoeuvre.
    Start,
    /// A straight driving move in the neutral footprint (Fig. 4 left).
    Drive,
    /// A turn on the spot to the next orientation (Fig. 4 right).
    Turn,
    /// An abstract step of one foot (Fig. 6a).
    Step,
    /// A longitudinal base shift (Fig. 6b).
    BaseShift,
    /// A front wheel pair driven forward to prepare a rear step (Fig. 6c).
    FootForward,
    /// A wheel pair driven back to its neutral position (Fig. 6d).
    FootNeutral,
}

impl ManoeuvreKind {
    /// Whether the manoeuvre is step-related (its cost carries the step-related factor).
    pub fn is_step_related(self) -> bool {
        !matches!(self, Self::Start | Self::Drive | Self::Turn)
    }

    /// The snake-case name (as serialised).
    pub fn name(self) -> &'static str {
        match self {
            Self::Start => "start",
            Self::Drive => "drive",
            Self::Turn => "turn",
            Self::Step => "step",
            Self::BaseShift => "base_shift",
            Self::FootForward => "foot_forward",
            Self::FootNeutral => "foot_neutral",
        }
    }
}

/// The parts of a step's cost C_S (eq. 5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepCost {
    /// L_step, m.
    pub length_m: f64,
    /// C_F(c_h), the foot cost of the foothold (eq. 1).
    pub foothold_cost: f64,
    /// ΔH_step, m: the largest height difference the foot overcomes.
    pub height_m: f64,
    /// C_S (eq. 5), before the step-related factor.
    pub c_s: f64,
}

/// What one edge of the planner's graph does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeLabel {
    /// What it does.
    pub kind: ManoeuvreKind,
    /// The leg that moves (steps and foot moves).
    pub leg: Option<Leg>,
    /// Distance: base travel (drive, base shift), wheel travel (turn, foot moves) or the
    /// step length, m.
    pub length_m: f64,
    /// The edge cost as searched, in cost units (before fixed-point rounding).
    pub cost: f64,
    /// The parts of C_S, for steps.
    pub step: Option<StepCost>,
}

/// One pose of the planned path and the manoeuvre that reached it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathElement {
    /// The manoeuvre ([`ManoeuvreKind::Start`] for the first element).
    pub kind: ManoeuvreKind,
    /// The leg that moved (steps and foot moves).
    pub leg: Option<Leg>,
    /// Base pose after the manoeuvre (lattice cell centre and orientation).
    pub pose: Pose2,
    /// World (x, y) of the feet, FL, FR, RL, RR.
    pub feet: [[f64; 2]; 4],
    /// Ground height under each foot, m (`null` where unknown).
    pub foot_heights: [Option<f64>; 4],
    /// Foot offsets from the neutral footprint along the base's x', m.
    pub foot_offsets_m: [f64; 4],
    /// Plain A* cost of the manoeuvre (k12 = 1).
    pub cost: f64,
    /// The parts of C_S (eq. 5), for steps.
    pub step: Option<StepCost>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_serialise_by_their_names() {
        let all = [
            ManoeuvreKind::Start,
            ManoeuvreKind::Drive,
            ManoeuvreKind::Turn,
            ManoeuvreKind::Step,
            ManoeuvreKind::BaseShift,
            ManoeuvreKind::FootForward,
            ManoeuvreKind::FootNeutral,
        ];
        for k in all {
            assert_eq!(serde_json::to_string(&k).unwrap(), format!("\"{}\"", k.name()));
        }
        let related: Vec<_> = all.iter().filter(|k| k.is_step_related()).collect();
        assert_eq!(related.len(), 4);
    }
}
