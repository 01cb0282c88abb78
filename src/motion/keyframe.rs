//! The detailed path: timed keyframes, the contract between step motion generation
//! (Sec. VI) and the executor. Serialisable to JSON (`momaro plan --detailed --json`).
//!
//! Between consecutive keyframes the motion is linear in base pose (position, roll, pitch,
//! yaw the shorter way) and in each foot's world position, except for [`Phase::Drive`]
//! segments, where the feet stay in the neutral footprint under the moving base (wheels
//! roll). A foot bears weight along a segment only if it does at both of its keyframes.

use crate::posture::kinematics::Posture;
use crate::robot::Leg;
use serde::Serialize;

/// What a keyframe's segment does (the segment from the previous keyframe to this one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// The start posture (driving height).
    Start,
    /// Driving or turning in the neutral footprint.
    Drive,
    /// Standing up from driving height to the manoeuvre leg height (Sec. VI-B, Fig. 13b).
    StandUp,
    /// Base roll for lateral CoM alignment (eqs. 6–8, Fig. 13c).
    Roll,
    /// The other wheel pair on the stepping side driven toward the centre (Fig. 12a, 13d).
    WheelToCentre,
    /// Longitudinal base shift for alignment when the wheel is blocked (Fig. 12b).
    BaseShift,
    /// Foot lifted off the ground to the swing height.
    Lift,
    /// Foot moved at the swing height above the foothold.
    Swing,
    /// Foot lowered onto the foothold (Fig. 13e).
    Place,
    /// The stabilising base shift reversed.
    ShiftBack,
    /// The displaced wheel pair driven back (Fig. 13f).
    WheelBack,
    /// The roll reversed (Fig. 13g).
    RollBack,
    /// A planned longitudinal base shift (Sec. V, Fig. 6b; Fig. 13j).
    PlannedBaseShift,
    /// A planned single wheel-pair move: front foot forward or foot to neutral (Fig. 6c, d).
    WheelMove,
    /// Lowering to driving height (Fig. 13n).
    Lower,
}

impl Phase {
    /// Snake-case name (as in JSON).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Start => "start",
            Phase::Drive => "drive",
            Phase::StandUp => "stand_up",
            Phase::Roll => "roll",
            Phase::WheelToCentre => "wheel_to_centre",
            Phase::BaseShift => "base_shift",
            Phase::Lift => "lift",
            Phase::Swing => "swing",
            Phase::Place => "place",
            Phase::ShiftBack => "shift_back",
            Phase::WheelBack => "wheel_back",
            Phase::RollBack => "roll_back",
            Phase::PlannedBaseShift => "planned_base_shift",
            Phase::WheelMove => "wheel_move",
            Phase::Lower => "lower",
        }
    }
}

/// One keyframe of the detailed path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Keyframe {
    /// Time from the path start at which the keyframe is reached, s.
    pub time_s: f64,
    /// What the segment ending here does.
    pub phase: Phase,
    /// Index of the abstract path element this keyframe belongs to.
    pub path_index: usize,
    /// The leg concerned (stepping leg, displaced wheel, moved wheel), if any.
    pub leg: Option<Leg>,
    /// Base position (world), m.
    pub base_position: [f64; 3],
    /// Base roll, pitch, yaw (ZYX; pitch positive nose down, roll positive left side up), rad.
    pub base_rpy: [f64; 3],
    /// Wheel contact points (world), FL, FR, RL, RR, m.
    pub feet: [[f64; 3]; 4],
    /// Which feet bear weight.
    pub contact: [bool; 4],
    /// Leg heights: hip axis above the foot's contact point, m (Sec. VI-B).
    pub leg_heights: [f64; 4],
    /// Joint targets (hip, knee, ankle) per leg from the sagittal IK, rad.
    pub joints: [[f64; 3]; 4],
    /// Expected CoM (world) from the CoM model, m.
    pub com: [f64; 3],
    /// Static stability margin at the keyframe, m (signed distance of the horizontal CoM
    /// projection to the support polygon's edge).
    pub margin_m: f64,
    /// Smallest margin over the keyframe and the interpolated points of the segment
    /// ending here, m.
    pub segment_min_margin_m: f64,
    /// Distance of the CoM projection to the support polygon's centroid (STC with three
    /// contacts), m.
    pub centroid_distance_m: f64,
}

impl Keyframe {
    /// The keyframe's posture.
    pub fn posture(&self) -> Posture {
        Posture {
            base_position: self.base_position,
            base_rpy: self.base_rpy,
            feet: self.feet,
            contact: self.contact,
        }
    }
}

/// The expanded path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DetailedPath {
    /// The keyframes, in time order.
    pub keyframes: Vec<Keyframe>,
    /// Total duration, s.
    pub duration_s: f64,
    /// Smallest margin over all keyframes, m.
    pub min_keyframe_margin_m: f64,
    /// Smallest margin over all keyframes and interpolated points, m.
    pub min_margin_m: f64,
    /// Smallest margin over the keyframes and interpolated points with three contacts, m.
    pub min_three_contact_margin_m: f64,
    /// Postures checked (keyframes and interpolated points).
    pub samples_checked: usize,
    /// Abstract steps expanded.
    pub steps: usize,
}
