//! The expansion of an abstract path into keyframes (Sec. VI).
//!
//! Walking the abstract path (`jobs::plan::PathElement`s), the expander keeps the robot's
//! actual posture (base pose and the four feet) and appends keyframes:
//!
//! - **Driving** (drive / turn elements): one keyframe per path pose, feet in the neutral
//!   footprint on the height map. At driving height (0.27 m) the mean hip stands that high
//!   above the mean ground under the feet (`kinematics::driving_posture`, which the closed loop
//!   uses too); while
//!   standing (between close manoeuvres) the manoeuvre leg-height rule below applies. The
//!   base pitch is 70 % of the ground slope between front and rear feet (Sec. VI-B).
//! - **Stand up / lower** (Fig. 13b, n): before the first non-driving manoeuvre the robot
//!   stands up; it lowers to driving height when the footprint is neutral and the next
//!   manoeuvre is at least [`MotionOptions::stay_standing_m`] of driving away (or none).
//! - **Leg heights while standing** (Sec. VI-B): the base height is set by the highest
//!   foot, whose leg gets the manoeuvre height (0.45 m, a soft constraint); the others are
//!   longer. When a leg would then exceed its reach (hard constraint), the leg height is
//!   lowered in 1 cm steps (down to the driving height).
//! - **Planned base shifts and wheel moves** (Sec. V, Fig. 6b–d): one keyframe each, all
//!   feet in contact.
//! - **Abstract steps** (Sec. VI-A, Fig. 12, 13c–g): `roll` (eqs. 6–8 toward the support
//!   triangle centroid's lateral coordinate, iterated with the CoM model because the base
//!   actually turns about the lower side's hips rather than about R, and capped at
//!   [`MotionOptions::max_roll_rad`]), `wheel_to_centre` (the other wheel pair on the
//!   stepping side driven toward the centre until the STC's longitudinal coordinate meets
//!   the CoM's, stopping before cells of infinite foot cost, height changes, and
//!   [`MotionOptions::wheel_gap_m`] from the stepping foot), `base_shift` (only if a
//!   longitudinal error of more than 2 cm remains: the wheel was blocked), `lift` (the
//!   foot rises vertically to `StandingRule::swing_clearance_m` above the highest
//!   terrain within a wheel's reach of its straight path), `swing`, `place`, then
//!   `shift_back`, `wheel_back`, `roll_back` (to the post-step pitch).
//!
//! **Stability** (Sec. VI-A): every keyframe and interpolated point (every 1 cm of base or
//! foot motion and every 0.02 rad) is solved with the leg IK (reach with
//! `StandingRule::reach_margin_m` to spare, joint limits) and its CoM computed with the
//! [`CenterOfMassModel`]; its margin in the support polygon of the feet in contact must be
//! at least [`MotionOptions::min_margin_m`] (default 3 cm), and with a foot lifted the
//! executor's lift threshold, [`MotionOptions::min_three_contact_margin_m`] (5 cm: the
//! estimate leaves out the support legs' sag toward the unloaded foot).
//!
//! **Alternatives before failing**: a step is tried at the leg heights of the shared
//! standing rule at which it stays within reach (`StandingRule::step_heights`, the same
//! check the planner made), tallest first, then at 0.50 and 0.55 m; for each, full
//! wheel-to-centre alignment, half, none, and as far as the wheel may go (a diagonal
//! support edge may need it further in than alignment asks); full, half, then no roll; a
//! base shift taking what
//! the wheel leaves (all, half, none). Then, as a second pass, fixed base shifts of
//! ±2.5 to ±20 cm with every wheel and roll choice. The first candidate whose every point
//! holds is taken; otherwise [`MotionError::Step`] names the step, the leg and the best
//! margin reached.
//!
//! **The planner runs the same check** ([`ManoeuvreCheck::step`], [`StepSearch::Planner`]):
//! every height with full wheel alignment and every roll and shift fraction, a subset of
//! the generator's candidates, from the shared rule's standing posture at the planned pose
//! ([`StandingRule::stand`]). Heights are taken lazily, the next only when every candidate
//! at the ones before failed, so a step that holds tall costs no more. Tall steps hold
//! only lower down: a front foot onto 0.24 m holds first at 0.31 m of leg height, where
//! the rolled stance leaves the stretched rear leg on the same side its reach (when the
//! planner tried only the two tallest heights, it called every block above ~0.21 m
//! impassable). The generator settles into that posture before every step and wheel move
//! (a `stand_up` keyframe where the manoeuvre before left the base elsewhere), so a step
//! the planner admits meets a candidate here that holds; only the CoM model differs (the
//! planner's estimate, MuJoCo's here), and the planner keeps 3 mm of margin for that.

use super::keyframe::{DetailedPath, Keyframe, Phase};
use super::roll::{RollError, roll_for_lateral_com};
use crate::cost::CostMaps;
use crate::feasibility::{DrivingCheck, Infeasible, MotionOptions};
use crate::geometry::{Pose2, wrap_angle};
use crate::params::StepModel;
use crate::path::{ManoeuvreKind, PathElement};
use crate::posture::CenterOfMassModel;
use crate::posture::kinematics;
use crate::posture::kinematics::PostureError;
use crate::posture::kinematics::base_z_in;
use crate::posture::kinematics::{
    Evaluation, Posture, contacts_in, evaluate, evaluate_legs, interpolate, rotation, solve_chains,
};
use crate::posture::standing::StepStance;
use crate::robot::{Leg, RobotDescription};
use crate::search::FxBuild;
use std::collections::HashMap;

/// Why a path cannot be expanded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    /// No candidate motion for a step keeps the robot stable and within reach.
    #[error(
        "path element {index}: step of leg {leg:?} has no stable motion (best margin {best_margin_m:.3} m, {required_m} m required): {reason}"
    )]
    Step {
        /// Index of the step in the abstract path.
        index: usize,
        /// The stepping leg.
        leg: Leg,
        /// Best smallest margin over a candidate's points, m (−inf if none was feasible).
        best_margin_m: f64,
        /// The required margin, m.
        required_m: f64,
        /// Why the best candidate failed.
        reason: String,
    },
    /// Another manoeuvre is infeasible or unstable.
    #[error("path element {index} ({kind}): {reason}")]
    Manoeuvre {
        /// Index in the abstract path.
        index: usize,
        /// The manoeuvre.
        kind: &'static str,
        /// Why.
        reason: String,
    },
    /// A foot stands on unknown terrain or off the map.
    #[error("path element {index}: no terrain height at ({x:.3}, {y:.3})")]
    UnknownTerrain {
        /// Index in the abstract path.
        index: usize,
        /// World x, m.
        x: f64,
        /// World y, m.
        y: f64,
    },
    /// The path is empty or does not start with its start pose.
    #[error("the abstract path is empty")]
    EmptyPath,
}

impl MotionError {
    /// The index of the path element that could not be expanded.
    pub fn index(&self) -> Option<usize> {
        match self {
            Self::Step { index, .. }
            | Self::Manoeuvre { index, .. }
            | Self::UnknownTerrain { index, .. } => Some(*index),
            Self::EmptyPath => None,
        }
    }
}

/// Why a step candidate's alignment could not be built: its stance's CoM has no solved
/// legs, or the roll (eqs. 6–8) has no solution. Kept as it is and put into words only if
/// the whole step fails: most candidates the planner asks about do, and most of their
/// alignments are fine.
#[derive(Debug, Clone, thiserror::Error)]
enum AlignmentError {
    #[error(transparent)]
    Posture(#[from] PostureError),
    #[error(transparent)]
    Roll(#[from] RollError),
}

/// A segment that passed: its end evaluation, smallest margins and sample count.
#[derive(Debug, Clone)]
struct SegmentCheck {
    end: Evaluation,
    min_margin: f64,
    min_three: f64,
    samples: usize,
}

struct Expander<'a> {
    robot: &'a RobotDescription,
    maps: &'a CostMaps,
    model: &'a mut dyn CenterOfMassModel,
    o: &'a MotionOptions,
    keys: Vec<Keyframe>,
    cur: Posture,
    /// Whether keyframes are timed for braking ([`Expander::duration`]): not for the
    /// planner's checks ([`ManoeuvreCheck`]), which keep no keyframes.
    braking: bool,
    time: f64,
    samples: usize,
    min_margin: f64,
    min_three: f64,
    index: usize,
    /// The checks of the step being searched ([`StepChecks`]); `None` outside a step's
    /// candidate search.
    checked: Option<StepChecks>,
}

/// The outcomes of the posture and segment checks within one step's candidate search
/// ([`Expander::expand_step_at`]), by the postures' exact bits. A step's candidates share
/// keyframes and whole segments (those differing only in their base shift share the
/// wheel move and the roll; every trial re-checks the lift its early check passed, and
/// every segment walk ends on a keyframe the trial checked first): on a generated mixed
/// course (seed 20002) 27 % of the 6.6 M postures the planner's step checks evaluated
/// had been evaluated in the same step before. Both checks are pure functions of their
/// postures (the robot, maps, CoM model and options are fixed), so a remembered outcome
/// is the outcome. Interpolated samples are not remembered one by one (their segment
/// is): hashing each cost more than the few repeats saved.
#[derive(Default)]
struct StepChecks {
    postures: HashMap<PostureBits, Result<Evaluation, Infeasible>, FxBuild>,
    segments: HashMap<(PostureBits, PostureBits, bool), SegmentOutcome, FxBuild>,
}

/// What [`Expander::check_segment`] finds: the segment's check, or where along it (0–1)
/// and why it failed.
type SegmentOutcome = Result<SegmentCheck, (f64, Infeasible)>;

/// A posture's exact bits: base position and roll, pitch, yaw, the four feet, and the
/// contact flags.
type PostureBits = ([u64; 18], u8);

fn posture_bits(p: &Posture) -> PostureBits {
    let mut bits = [0u64; 18];
    let values = p.base_position.iter().chain(&p.base_rpy).chain(p.feet.iter().flatten());
    for (b, v) in bits.iter_mut().zip(values) {
        *b = v.to_bits();
    }
    let contact = p.contact.iter().enumerate().fold(0u8, |m, (k, &c)| m | (u8::from(c) << k));
    (bits, contact)
}

/// A planned keyframe before checking.
type Planned = (Phase, Option<Leg>, Posture);

impl<'a> Expander<'a> {
    /// An expander standing in posture `cur`, nothing expanded yet.
    fn at(
        robot: &'a RobotDescription,
        maps: &'a CostMaps,
        model: &'a mut dyn CenterOfMassModel,
        o: &'a MotionOptions,
        cur: Posture,
    ) -> Self {
        Self {
            robot,
            maps,
            model,
            o,
            keys: Vec::new(),
            cur,
            braking: true,
            time: 0.0,
            samples: 0,
            min_margin: f64::INFINITY,
            min_three: f64::INFINITY,
            index: 0,
            checked: None,
        }
    }

    fn ground(&self, x: f64, y: f64) -> Result<f64, MotionError> {
        self.maps.height_at(x, y).ok_or(MotionError::UnknownTerrain { index: self.index, x, y })
    }

    fn neutral_feet(&self, pose: &Pose2) -> Result<[[f64; 3]; 4], MotionError> {
        let xy = self.maps.neutral_feet(pose);
        let mut f = [[0.0; 3]; 4];
        for i in 0..4 {
            f[i] = [xy[i][0], xy[i][1], self.ground(xy[i][0], xy[i][1])?];
        }
        Ok(f)
    }

    /// Base pitch: `pitch_fraction` of the slope between the front and rear feet.
    fn pitch_for(&self, feet: &[[f64; 3]; 4], yaw: f64) -> f64 {
        self.o.standing.pitch(feet, yaw)
    }

    /// Driving posture at `pose` (Sec. VI-B, [`kinematics::driving_posture`]).
    fn driving(&self, pose: &Pose2) -> Result<Posture, MotionError> {
        kinematics::driving_posture(
            self.robot,
            pose,
            self.o.driving_leg_height_m,
            self.o.standing.pitch_fraction,
            |x, y| self.maps.height_at(x, y),
        )
        .map_err(|[x, y]| MotionError::UnknownTerrain { index: self.index, x, y })
    }

    /// Standing posture: base height from the highest relevant ground (`ground`, per leg)
    /// so the shortest leg is `height`; base moved laterally so the feet in contact lie on
    /// their legs' planes on average; feet not in contact put on their leg planes.
    #[allow(clippy::too_many_arguments)]
    fn standing(
        &self,
        feet: [[f64; 3]; 4],
        contact: [bool; 4],
        xy: [f64; 2],
        yaw: f64,
        pitch: f64,
        roll: f64,
        height: f64,
        ground: [f64; 4],
    ) -> Posture {
        let rpy = [roll, pitch, yaw];
        let r = rotation(rpy);
        let mut p = Posture { base_position: [xy[0], xy[1], 0.0], base_rpy: rpy, feet, contact };
        for _ in 0..3 {
            p.base_position[2] = base_z_in(self.robot, &ground, &r, height);
            let local = contacts_in(self.robot, &r, &p);
            let n = contact.iter().filter(|&&c| c).count().max(1) as f64;
            let m = (0..4).filter(|&i| contact[i]).map(|i| local[i][1]).sum::<f64>() / n;
            for (b, row) in p.base_position.iter_mut().zip(&r) {
                *b += row[1] * m;
            }
        }
        let local = contacts_in(self.robot, &r, &p);
        for i in 0..4 {
            if !contact[i] {
                let h = self.robot.hips[i];
                let b = [local[i][0] + h[0], h[1], local[i][2] + h[2]];
                p.feet[i] = kinematics::apply(&r, p.base_position, b);
            }
        }
        p
    }

    /// The standing posture of the shared rule ([`StandingRule::stand`]) for all four
    /// feet in contact.
    fn standing_fallback(
        &mut self,
        feet: [[f64; 3]; 4],
        xy: [f64; 2],
        yaw: f64,
    ) -> Result<Posture, String> {
        self.o
            .standing
            .stand(self.robot, self.maps.leg_terrain(), feet, xy, yaw)
            .map(|(p, _)| p)
            .map_err(|e| format!("no standing leg height reaches every foot: {e}"))
    }

    fn com_of(&mut self, p: &Posture) -> Result<[f64; 3], PostureError> {
        solve_chains(self.robot, p, self.o.standing.reach_margin_m)
            .map(|legs| self.model.com_of_solved(&legs))
    }

    /// Checks one posture: the leg IK with the reach margin, thighs and shins clear of the
    /// terrain, and the stability margin. Within a step's candidate search, remembered
    /// ([`StepChecks`]).
    fn check_posture(&mut self, p: &Posture) -> Result<Evaluation, Infeasible> {
        if self.checked.is_none() {
            return self.evaluate_posture(p);
        }
        let key = posture_bits(p);
        if let Some(known) = self.checked.as_ref().and_then(|c| c.postures.get(&key)) {
            return known.clone();
        }
        let outcome = self.evaluate_posture(p);
        if let Some(c) = self.checked.as_mut() {
            c.postures.insert(key, outcome.clone());
        }
        outcome
    }

    /// [`Self::check_posture`] unremembered.
    fn evaluate_posture(&mut self, p: &Posture) -> Result<Evaluation, Infeasible> {
        let o = self.o;
        // The clearance before the CoM: a posture it rejects needs none.
        let legs = solve_chains(self.robot, p, o.standing.reach_margin_m)?;
        o.standing.legs_clear(self.robot, self.maps.leg_terrain(), &legs)?;
        let e = evaluate_legs(self.robot, self.model, p, &legs);
        let required = o.required_margin(p);
        if e.margin < required {
            return Err(Infeasible::Margin { margin_m: e.margin, required_m: required });
        }
        Ok(e)
    }

    /// Checks the segment from `a` to `b` (interpolated points and `b`); `drive` keeps the
    /// feet in the neutral footprint under the moving base. Within a step's candidate
    /// search, remembered ([`StepChecks`]).
    fn check_segment(&mut self, a: &Posture, b: &Posture, drive: bool) -> SegmentOutcome {
        if self.checked.is_none() {
            return self.walk_segment(a, b, drive);
        }
        let key = (posture_bits(a), posture_bits(b), drive);
        if let Some(known) = self.checked.as_ref().and_then(|c| c.segments.get(&key)) {
            return known.clone();
        }
        let outcome = self.walk_segment(a, b, drive);
        if let Some(c) = self.checked.as_mut() {
            c.segments.insert(key, outcome.clone());
        }
        outcome
    }

    /// [`Self::check_segment`] unremembered: every sample evaluated, the end (a
    /// keyframe) by [`Self::check_posture`].
    fn walk_segment(&mut self, a: &Posture, b: &Posture, drive: bool) -> SegmentOutcome {
        let o = self.o;
        let dist = |p: [f64; 3], q: [f64; 3]| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let lin = (0..4)
            .map(|i| dist(a.feet[i], b.feet[i]))
            .fold(dist(a.base_position, b.base_position), f64::max);
        let ang =
            (0..3).map(|k| wrap_angle(b.base_rpy[k] - a.base_rpy[k]).abs()).fold(0.0, f64::max);
        let n = ((lin / o.sample_m).ceil().max((ang / o.sample_rad).ceil()) as usize).max(1);
        let mut min_margin = f64::INFINITY;
        let mut min_three = f64::INFINITY;
        let mut end = None;
        for j in 1..=n {
            let t = j as f64 / n as f64;
            let mut p = if j == n { *b } else { interpolate(a, b, t) };
            if drive && j < n {
                let pose =
                    Pose2 { x: p.base_position[0], y: p.base_position[1], theta: p.base_rpy[2] };
                let xy = self.maps.neutral_feet(&pose);
                // The feet on the ground under them, the base raised with the highest
                // foot's rise over the interpolation (as the executor's drive runs do):
                // a foot crossing a strip of bump between two lattice poses shortens no
                // leg below its planned height.
                let mut rise = 0.0_f64;
                for (f, w) in p.feet.iter_mut().zip(xy) {
                    let z = self.maps.height_at(w[0], w[1]).unwrap_or(f[2]);
                    rise = rise.max(z - f[2]);
                    *f = [w[0], w[1], z];
                }
                p.base_position[2] += rise;
            }
            let e = if j == n { self.check_posture(&p) } else { self.evaluate_posture(&p) };
            let e = e.map_err(|cause| (t, cause))?;
            min_margin = min_margin.min(e.margin);
            if p.contact.iter().filter(|&&c| c).count() == 3 {
                min_three = min_three.min(e.margin);
            }
            end = Some(e);
        }
        let end = end.ok_or((0.0, Infeasible::Posture(PostureError::NoHeight)))?;
        Ok(SegmentCheck { end, min_margin, min_three, samples: n })
    }

    /// How long the executor takes from `a` to `b`, whose CoM estimates are `coms`: the
    /// base and feet at their speeds, the base's angles at theirs, and slow enough for
    /// the CoM's own acceleration (not for a drive, which the path follower times, nor in
    /// the planner's checks, which keep no keyframes). `spare` is how far the segment's
    /// smallest margin exceeds what its end posture must keep.
    ///
    /// The executor moves along a smoothstep (`control::step_executor::smoothstep`), so
    /// a CoM moved by `d` in time `T` accelerates at up to `6 d / T²` at both ends, and its
    /// zero-moment point then lies `a · h / g` from its ground projection (`h` its height
    /// over the feet in contact): the static margin the checks ask is not what holds while
    /// it brakes. At the wheel speed a 4 cm shift of a CoM 0.5 m up took 0.4 s and moved
    /// the zero-moment point 8 cm; braking the descent shift on a generated flight
    /// (stairs seed 20008, 3-7 cm of static margin over the lower front pairs) unloaded
    /// both rear pairs at every keyframe. `T ≥ √(6 d h / (g δ))` keeps the shift within
    /// `δ`: the margin to spare, and never less than `MotionOptions::zmp_shift_m`, which
    /// the required margin then pays.
    fn duration(
        &self,
        (a, b): (&Posture, &Posture),
        coms: [[f64; 3]; 2],
        spare: f64,
        drive: bool,
    ) -> f64 {
        let o = self.o;
        let d2 = |p: [f64; 3], q: [f64; 3]| (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2]);
        let base = d2(a.base_position, b.base_position) / o.wheel_speed;
        let feet = (0..4).map(|i| d2(a.feet[i], b.feet[i])).fold(0.0, f64::max) / o.foot_speed;
        let ang =
            (0..3).map(|k| wrap_angle(b.base_rpy[k] - a.base_rpy[k]).abs()).fold(0.0, f64::max)
                / o.angular_speed;
        let braking = if drive || !self.braking {
            0.0
        } else {
            zmp_duration(b, coms, spare.max(o.zmp_shift_m))
        };
        base.max(feet).max(ang).max(braking).max(0.1)
    }

    /// Checks a sequence from the current posture without committing it; returns the
    /// keyframes and the sequence's smallest margin.
    fn trial(
        &mut self,
        seq: &[Planned],
    ) -> Result<(Vec<Keyframe>, f64, f64, usize), SegmentFailure> {
        // The keyframes first: a candidate that fails mostly fails at one of them, and
        // each costs one sample where its segment costs one per centimetre. The verdict
        // is the same: every keyframe is its segment's last sample.
        for &(phase, _, p) in seq {
            self.check_posture(&p).map_err(|cause| SegmentFailure {
                phase: phase.name(),
                percent: 100.0,
                cause,
            })?;
        }
        let mut from = self.cur;
        // The CoM the first segment starts from: the last keyframe's, the posture stood in
        // (from the start keyframe on); none where keyframes are not timed.
        let mut from_com = match self.keys.last() {
            Some(k) if self.braking => k.com,
            _ => [f64::NAN; 3],
        };
        let mut t = self.time;
        let mut out = Vec::with_capacity(seq.len());
        let (mut mm, mut m3, mut samples) = (f64::INFINITY, f64::INFINITY, 0);
        for &(phase, leg, p) in seq {
            let drive = phase == Phase::Drive;
            let c = self.check_segment(&from, &p, drive).map_err(|(t, cause)| SegmentFailure {
                phase: phase.name(),
                percent: t * 100.0,
                cause,
            })?;
            let spare = c.min_margin - self.o.required_margin(&p);
            t += self.duration((&from, &p), [from_com, c.end.com], spare, drive);
            from_com = c.end.com;
            mm = mm.min(c.min_margin);
            m3 = m3.min(c.min_three);
            samples += c.samples;
            out.push(Keyframe {
                time_s: t,
                phase,
                path_index: self.index,
                leg,
                base_position: p.base_position,
                base_rpy: p.base_rpy,
                feet: p.feet,
                contact: p.contact,
                leg_heights: c.end.leg_heights,
                joints: c.end.joints,
                com: c.end.com,
                margin_m: c.end.margin,
                segment_min_margin_m: c.min_margin,
                centroid_distance_m: c.end.centroid_distance,
            });
            from = p;
        }
        Ok((out, mm, m3, samples))
    }

    fn commit(&mut self, keys: Vec<Keyframe>, mm: f64, m3: f64, samples: usize) {
        if let Some(k) = keys.last() {
            self.cur = k.posture();
            self.time = k.time_s;
        }
        self.min_margin = self.min_margin.min(mm);
        self.min_three = self.min_three.min(m3);
        self.samples += samples;
        self.keys.extend(keys);
    }

    fn push(&mut self, kind: ManoeuvreKind, seq: &[Planned]) -> Result<(), MotionError> {
        let (k, mm, m3, s) = self.trial(seq).map_err(|f| MotionError::Manoeuvre {
            index: self.index,
            kind: kind.name(),
            reason: f.to_string(),
        })?;
        self.commit(k, mm, m3, s);
        Ok(())
    }

    fn stand_up(&mut self, kind: ManoeuvreKind) -> Result<(), MotionError> {
        let (feet, xy, yaw) = (self.cur.feet, self.xy(), self.cur.base_rpy[2]);
        let p = self.stand_for(kind, feet, xy, yaw)?;
        self.push(kind, &[(Phase::StandUp, None, p)])
    }

    /// [`Self::standing_fallback`] within a manoeuvre of `kind`: its failure names the
    /// manoeuvre.
    fn stand_for(
        &mut self,
        kind: ManoeuvreKind,
        feet: [[f64; 3]; 4],
        xy: [f64; 2],
        yaw: f64,
    ) -> Result<Posture, MotionError> {
        let index = self.index;
        self.standing_fallback(feet, xy, yaw).map_err(|reason| MotionError::Manoeuvre {
            index,
            kind: kind.name(),
            reason,
        })
    }

    fn xy(&self) -> [f64; 2] {
        [self.cur.base_position[0], self.cur.base_position[1]]
    }

    /// The longitudinal part of a step candidate's alignment: the partner wheel toward
    /// the centre (`wheel_fraction` of the way) at leg height `height`, and the support
    /// it leaves for the roll ([`Self::roll_alignment`]). Candidates that differ only in
    /// their roll or shift share it.
    fn wheel_alignment(
        &mut self,
        leg: Leg,
        post_foot: [f64; 3],
        height: f64,
        wheel_fraction: f64,
    ) -> Result<WheelAlignment, AlignmentError> {
        let o = *self.o;
        let i = leg.index();
        let j = leg.same_side_partner().index();
        let yaw = self.cur.base_rpy[2];
        let (s, c) = yaw.sin_cos();
        let along = |f: [f64; 3]| c * f[0] + s * f[1];
        let lateral = |f: [f64; 3]| -s * f[0] + c * f[1];
        let pre = self.cur.feet;
        let stance = self.o.standing.step_stance(&pre, i, post_foot, yaw);
        let StepStance { pitch, ground, .. } = stance;
        let xy = self.xy();
        let all = [true; 4];

        // Longitudinal alignment: the partner wheel toward the centre (Fig. 12a).
        let p0 = self.standing(pre, all, xy, yaw, pitch, 0.0, height, ground);
        let c0 = self.com_of(&p0)?;
        let others: Vec<usize> = (0..4).filter(|&k| k != i && k != j).collect();
        let x_des = 3.0 * along(c0) - others.iter().map(|&k| along(pre[k])).sum::<f64>();
        let sign = if Leg::ALL[j].is_front() { -1.0 } else { 1.0 };
        let wanted = ((x_des - along(pre[j])) * sign).clamp(0.0, o.max_wheel_to_centre_m);
        let gap_limit = if sign > 0.0 {
            along(pre[i]).min(along(post_foot)) - o.wheel_gap_m - along(pre[j])
        } else {
            along(pre[j]) - (along(pre[i]).max(along(post_foot)) + o.wheel_gap_m)
        };
        // `wheel_fraction` of the aligning move, or (infinite) as far as allowed: a
        // diagonal support edge may need the wheel further in than longitudinal
        // alignment asks.
        let target = if wheel_fraction.is_infinite() {
            o.max_wheel_to_centre_m
        } else {
            wanted * wheel_fraction
        }
        .min(gap_limit.max(0.0));
        let mut d = 0.0;
        let step = 0.01;
        while d + step <= target + 1e-9 {
            let e = d + step;
            let (x, y) = (pre[j][0] + sign * e * c, pre[j][1] + sign * e * s);
            // The wheel pair rolls along the base heading: its foot cost at that heading.
            let ok = self.maps.foot_cost_at_heading(x, y, yaw).is_finite()
                && self.maps.height_at(x, y).is_some_and(|h| (h - pre[j][2]).abs() < 0.02);
            if !ok {
                break;
            }
            d = e;
        }
        // ... and, with the stairs step model, as far as the partner's leg reaches at this
        // stance: a wheel driven past it would fail the step, where a shorter move leaves
        // the rest to the roll and the base shift.
        let moved_by = |d: f64| {
            let mut moved = pre;
            if d > 0.0 {
                let (x, y) = (pre[j][0] + sign * d * c, pre[j][1] + sign * d * s);
                moved[j] = [x, y, self.maps.height_at(x, y).unwrap_or(pre[j][2])];
            }
            moved
        };
        let mut moved = moved_by(d);
        while d > 0.0 && self.o.step_model == StepModel::Stairs {
            let p = self.standing(moved, all, xy, yaw, pitch, 0.0, height, ground);
            if solve_chains(self.robot, &p, self.o.standing.reach_margin_m).is_ok() {
                break;
            }
            d = (d - step).max(0.0);
            moved = moved_by(d);
        }

        // Lateral alignment: roll (eqs. 6–8), iterated with the CoM model.
        let support: Vec<[f64; 3]> = (0..4).filter(|&k| k != i).map(|k| moved[k]).collect();
        let stc = [
            support.iter().map(|f| f[0]).sum::<f64>() / 3.0,
            support.iter().map(|f| f[1]).sum::<f64>() / 3.0,
            0.0,
        ];
        let y_rot = moved.iter().map(|&f| lateral(f)).sum::<f64>() / 4.0;
        let z_rot = support.iter().map(|f| f[2]).sum::<f64>() / 3.0;
        let left = (lateral(moved[0]) + lateral(moved[2])) / 2.0;
        let right = (lateral(moved[1]) + lateral(moved[3])) / 2.0;
        let width = (left - right).abs();
        let p1 = self.standing(moved, all, xy, yaw, pitch, 0.0, height, ground);
        let com = self.com_of(&p1)?;
        Ok(WheelAlignment {
            height,
            stance,
            d,
            wanted,
            moved,
            stc,
            rot: [y_rot, z_rot],
            width,
            com,
        })
    }

    /// A step candidate's alignment before its base shift: `wheel`'s
    /// ([`Self::wheel_alignment`]), then the roll that takes the CoM `roll_fraction` of
    /// the way sideways to the support centroid (eqs. 6–8, iterated with the CoM model).
    fn roll_alignment(
        &mut self,
        wheel: &WheelAlignment,
        roll_fraction: f64,
    ) -> Result<Alignment, AlignmentError> {
        let o = *self.o;
        let yaw = self.cur.base_rpy[2];
        let (s, c) = yaw.sin_cos();
        let along = |f: [f64; 3]| c * f[0] + s * f[1];
        let lateral = |f: [f64; 3]| -s * f[0] + c * f[1];
        let xy = self.xy();
        let all = [true; 4];
        let WheelAlignment { height, stance, d, wanted, moved, stc, rot, width: b, mut com } =
            *wheel;
        let StepStance { pitch, ground, .. } = stance;
        let [y_rot, z_rot] = rot;
        let y_target = lateral(com) + roll_fraction * (lateral(stc) - lateral(com));
        let mut roll = 0.0;
        for _ in 0..5 {
            if (lateral(com) - y_target).abs() < 0.003 {
                break;
            }
            let sol = roll_for_lateral_com([y_rot, z_rot], [lateral(com), com[2]], y_target, b)?;
            // A roll that takes a stretched leg out of reach is halved (up to three
            // times) rather than dropping the candidate: part of the alignment still helps.
            let mut step = sol.roll;
            let mut next = None;
            for _ in 0..4 {
                let r = (roll + step).clamp(-o.max_roll_rad, o.max_roll_rad);
                let p = self.standing(moved, all, xy, yaw, pitch, r, height, ground);
                if let Ok(c) = self.com_of(&p) {
                    next = Some((r, c));
                    break;
                }
                step /= 2.0;
            }
            let Some((r, c)) = next else { break };
            (roll, com) = (r, c);
        }

        // What a base shift would have to take along (Fig. 12b).
        let rest = along(stc) - along(com);
        Ok(Alignment { height, stance, d, wanted, moved, roll, rest })
    }

    /// A step candidate's early keyframes (see [`EarlyKeyframes`]): its base shift of
    /// `shift` (Fig. 12b: the longitudinal remainder of its alignment, only where the
    /// partner wheel could not go as far as alignment wanted, blocked or a candidate with
    /// a shorter wheel move), the foot lifted to `swing_z` over where it stood, and the
    /// stance after the shift.
    fn early_keyframes(
        &self,
        leg: Leg,
        swing_z: f64,
        aligned: &Alignment,
        shift: Shift,
    ) -> EarlyKeyframes {
        let max_shift = self.o.max_base_shift_m;
        let hindered = aligned.d + 1e-3 < aligned.wanted;
        let shift = match shift {
            Shift::Remainder(fraction) => {
                if hindered && aligned.rest.abs() > 0.02 {
                    fraction * aligned.rest.clamp(-max_shift, max_shift)
                } else {
                    0.0
                }
            }
            Shift::Fixed(m) => m.clamp(-max_shift, max_shift),
        };
        let i = leg.index();
        let (yaw, xy, pre) = (self.cur.base_rpy[2], self.xy(), self.cur.feet);
        let (s, c) = yaw.sin_cos();
        let xy_shift = [xy[0] + shift * c, xy[1] + shift * s];
        let Alignment { height, stance, moved, roll, .. } = *aligned;
        let StepStance { pitch, ground, .. } = stance;
        let mut lift_feet = moved;
        lift_feet[i] = [pre[i][0], pre[i][1], swing_z];
        let mut lifted = [true; 4];
        lifted[i] = false;
        let st = |feet, contact| {
            self.standing(feet, contact, xy_shift, yaw, pitch, roll, height, ground)
        };
        EarlyKeyframes {
            shift,
            xy_shift,
            lift: st(lift_feet, lifted),
            shifted: (shift != 0.0).then(|| st(moved, [true; 4])),
        }
    }

    /// Builds the keyframes of one step candidate from its alignment, the foot carried
    /// at `swing_z`.
    fn step_candidate(
        &self,
        leg: Leg,
        swing_z: f64,
        aligned: &Alignment,
        early: &EarlyKeyframes,
    ) -> Vec<Planned> {
        let Alignment { height, stance, d, moved, roll, .. } = *aligned;
        let StepStance { post, pitch, ground } = stance;
        let (i, j) = (leg.index(), leg.same_side_partner().index());
        let post_foot = post[i];
        let yaw = self.cur.base_rpy[2];
        let pitch_post = self.pitch_for(&post, yaw);
        let pre = self.cur.feet;
        let xy = self.xy();
        let all = [true; 4];
        let mut lifted = all;
        lifted[i] = false;
        let EarlyKeyframes { shift, xy_shift, lift, shifted } = *early;
        let mut swing_feet = moved;
        swing_feet[i] = [post_foot[0], post_foot[1], swing_z];
        let mut placed = moved;
        placed[i] = post_foot;

        let st = |feet, contact, xy, roll, pitch| {
            self.standing(feet, contact, xy, yaw, pitch, roll, height, ground)
        };
        let mut seq: Vec<Planned> = Vec::new();
        seq.push((Phase::Roll, None, st(pre, all, xy, roll, pitch)));
        if d > 0.0 {
            seq.push((Phase::WheelToCentre, Some(Leg::ALL[j]), st(moved, all, xy, roll, pitch)));
        }
        if let Some(p) = shifted {
            seq.push((Phase::BaseShift, None, p));
        }
        seq.push((Phase::Lift, Some(leg), lift));
        seq.push((Phase::Swing, Some(leg), st(swing_feet, lifted, xy_shift, roll, pitch)));
        seq.push((Phase::Place, Some(leg), st(placed, all, xy_shift, roll, pitch)));
        if shift != 0.0 {
            seq.push((Phase::ShiftBack, None, st(placed, all, xy, roll, pitch)));
        }
        let mut back = placed;
        back[j] = pre[j];
        if d > 0.0 {
            seq.push((Phase::WheelBack, Some(Leg::ALL[j]), st(back, all, xy, roll, pitch)));
        }
        let mut post_ground = back.map(|f| f[2]);
        post_ground[i] = ground[i];
        seq.push((
            Phase::RollBack,
            None,
            self.standing(back, all, xy, yaw, pitch_post, 0.0, height, post_ground),
        ));
        seq
    }

    /// Expands a step of `leg` to `post_foot` from the current posture with the
    /// generator's candidates ([`StepSearch::Full`]), committing the first that holds.
    fn expand_step(&mut self, leg: Leg, post_foot: [f64; 3]) -> Result<(), MotionError> {
        // The heights of the shared rule at which the step is within reach (what the
        // planner checked), then two taller stances (the soft constraint is a minimum).
        let rule = self.o.standing;
        let (pre, xy, yaw) = (self.cur.feet, self.xy(), self.cur.base_rpy[2]);
        let heights = rule
            .step_heights(
                self.robot,
                self.maps.heights(),
                self.maps.leg_terrain(),
                pre,
                leg.index(),
                post_foot,
                xy,
                yaw,
            )
            .chain([rule.leg_height_m + 0.05, rule.leg_height_m + 0.1]);
        self.expand_step_at(leg, post_foot, StepSearch::Full, heights)
    }

    /// [`Self::expand_step`] at the leg heights `heights` (lazily: the planner's check
    /// takes the next height only when every candidate at the ones before failed), its
    /// posture checks remembered while the candidates are searched ([`StepChecks`]).
    fn expand_step_at(
        &mut self,
        leg: Leg,
        post_foot: [f64; 3],
        search: StepSearch,
        heights: impl Iterator<Item = f64>,
    ) -> Result<(), MotionError> {
        self.checked = Some(StepChecks::default());
        let outcome = self.search_step_candidates(leg, post_foot, search, heights);
        self.checked = None;
        outcome
    }

    /// [`Self::expand_step_at`]'s search.
    fn search_step_candidates(
        &mut self,
        leg: Leg,
        post_foot: [f64; 3],
        search: StepSearch,
        heights: impl Iterator<Item = f64>,
    ) -> Result<(), MotionError> {
        let i = leg.index();
        let pre = self.cur.feet;
        let rule = self.o.standing;
        // The same for every candidate (what `step_heights` checked the swing at).
        let swing_z =
            rule.swing_z(self.robot, self.maps.heights(), pre[i], post_foot, self.cur.base_rpy[2]);
        // The best failure so far (the largest margin short of the requirement), put
        // into words only if the step fails: most candidates the planner asks about do.
        let mut best: (f64, f64, Option<Result<SegmentFailure, AlignmentError>>) =
            (f64::NEG_INFINITY, self.o.min_margin_m, None);
        let candidates: Box<dyn Iterator<Item = (f64, f64, f64, Shift)>> = match search {
            StepSearch::Planner => {
                Box::new(heights.flat_map(|h| {
                    PLANNER_ALIGNMENTS.map(|(rf, f)| (h, 1.0, rf, Shift::Remainder(f)))
                }))
            }
            StepSearch::Full => Box::new(full_candidates(&heights.collect::<Vec<_>>()).into_iter()),
        };
        // Candidates that differ only in their shift share their alignment, those that
        // differ only in their roll too its wheel move, and those whose sequences come out
        // the same (no shift where the wheel was not hindered) are checked once.
        let mut wheels: Vec<((f64, f64), Result<WheelAlignment, AlignmentError>)> = Vec::new();
        let mut alignments: Vec<(AlignmentKey, Result<Alignment, AlignmentError>)> = Vec::new();
        let mut tried: Vec<Vec<Planned>> = Vec::new();
        // Early keyframes that failed (candidates can share them).
        let mut failed_early: Vec<Posture> = Vec::new();
        let min_margin = self.o.min_margin_m;
        let note = |best: &mut (f64, f64, Option<Result<SegmentFailure, AlignmentError>>),
                    f: SegmentFailure| {
            let (m, r) = match f.cause {
                Infeasible::Margin { margin_m, required_m } => (margin_m, required_m),
                _ => (f64::NEG_INFINITY, min_margin),
            };
            if m > best.0 || best.0 == f64::NEG_INFINITY {
                *best = (m, r, Some(Ok(f)));
            }
        };
        'candidates: for (h, wf, rf, shift) in candidates {
            let key = (h, wf, rf);
            let aligned = match alignments.iter().find(|(k, _)| *k == key) {
                Some((_, a)) => a.clone(),
                None => {
                    let wheel = match wheels.iter().find(|(k, _)| *k == (h, wf)) {
                        Some((_, w)) => w.clone(),
                        None => {
                            let w = self.wheel_alignment(leg, post_foot, h, wf);
                            wheels.push(((h, wf), w.clone()));
                            w
                        }
                    };
                    let a = wheel.and_then(|w| self.roll_alignment(&w, rf));
                    alignments.push((key, a.clone()));
                    a
                }
            };
            let aligned = match aligned {
                Ok(a) => a,
                Err(e) => {
                    if best.0 == f64::NEG_INFINITY {
                        best.2 = Some(Err(e));
                    }
                    continue;
                }
            };
            // The lift keyframe first, then the shifted stance where the base shifts:
            // most candidates that fail, fail at one of them (the CoM over the support
            // triangle of three feet; the stepping leg stretched by the shift), and each
            // is one posture where the whole sequence is up to nine and their segments.
            // The verdict is the same: the trial checks every keyframe.
            let early = self.early_keyframes(leg, swing_z, &aligned, shift);
            let checks =
                [Some((Phase::Lift, early.lift)), early.shifted.map(|p| (Phase::BaseShift, p))];
            let checks = checks.iter().flatten();
            if checks.clone().any(|(_, p)| failed_early.contains(p)) {
                continue;
            }
            for &(phase, p) in checks {
                if let Err(cause) = self.check_posture(&p) {
                    note(&mut best, SegmentFailure { phase: phase.name(), percent: 100.0, cause });
                    failed_early.push(p);
                    continue 'candidates;
                }
            }
            let seq = self.step_candidate(leg, swing_z, &aligned, &early);
            if tried.contains(&seq) {
                continue;
            }
            match self.trial(&seq) {
                Ok((k, mm, m3, s)) => {
                    self.commit(k, mm, m3, s);
                    return Ok(());
                }
                Err(f) => note(&mut best, f),
            }
            tried.push(seq);
        }
        Err(MotionError::Step {
            index: self.index,
            leg,
            best_margin_m: best.0,
            required_m: best.1,
            reason: match best.2 {
                Some(Ok(f)) => f.to_string(),
                Some(Err(e)) => e.to_string(),
                None => "no candidate".to_owned(),
            },
        })
    }

    /// Moves the base, all feet down, to the shared rule's standing posture over the
    /// current feet at `pose` ([`StandingRule::stand`]) if it is not there: every step,
    /// wheel move and planned base shift starts from that posture, the one the planner
    /// checks it from ([`ManoeuvreCheck`]), whatever the manoeuvre before left (a roll-back
    /// at another leg height, a base re-centred on its feet).
    fn settle(&mut self, kind: ManoeuvreKind, pose: &Pose2) -> Result<(), MotionError> {
        let p = self.stand_for(kind, self.cur.feet, [pose.x, pose.y], pose.theta)?;
        if p != self.cur {
            self.push(kind, &[(Phase::StandUp, None, p)])?;
        }
        Ok(())
    }

    /// The wheel move of one foot to `foot` (x, y on the ground), the base standing by the
    /// shared rule at its current place: through every cell of the way (a keyframe per
    /// height-map cell the foot rolls over), the base re-stood by the rule at each, as the
    /// planner checked the move (`locomotion::hybrid`: every footprint of the way can
    /// stand). A single keyframe at the end let the interpolation between the two ends
    /// dip a knee below the legs' clearance that both ends kept.
    fn expand_wheel_move(
        &mut self,
        kind: ManoeuvreKind,
        leg: Leg,
        foot: [f64; 2],
    ) -> Result<(), MotionError> {
        let i = leg.index();
        let from = self.cur.feet[i];
        let (dx, dy) = (foot[0] - from[0], foot[1] - from[1]);
        let res = self.maps.heights().resolution();
        let n = ((dx.hypot(dy) / res).round() as usize).max(1);
        let (xy, yaw) = (self.xy(), self.cur.base_rpy[2]);
        let mut feet = self.cur.feet;
        let mut seq = Vec::with_capacity(n);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let (x, y) = (from[0] + dx * t, from[1] + dy * t);
            feet[i] = [x, y, self.ground(x, y)?];
            let p = self.stand_for(kind, feet, xy, yaw)?;
            seq.push((Phase::WheelMove, Some(leg), p));
        }
        self.push(kind, &seq)
    }

    /// A planned base shift to `to`, the feet at `feet` (x, y on the ground): through
    /// every cell of the way, the base stood by the shared rule at each, as the planner
    /// checks it ([`ManoeuvreCheck::base_shift`]). The planner's shift ends on a lattice cell, so
    /// its feet stand up to half a cell from where they were: the shift takes its
    /// footprint (the wheels roll that far), so both agree on every later reach.
    fn expand_base_shift(
        &mut self,
        kind: ManoeuvreKind,
        feet: [[f64; 2]; 4],
        to: &Pose2,
    ) -> Result<(), MotionError> {
        let mut on_ground = self.cur.feet;
        for (f, p) in on_ground.iter_mut().zip(feet) {
            *f = [p[0], p[1], self.ground(p[0], p[1])?];
        }
        let (from, to_xy) = (self.xy(), [to.x, to.y]);
        let res = self.maps.heights().resolution();
        let dist = (to_xy[0] - from[0]).hypot(to_xy[1] - from[1]);
        let n = (dist / res).ceil().max(1.0) as usize;
        let mut seq = Vec::with_capacity(n);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let xy = [from[0] + (to_xy[0] - from[0]) * t, from[1] + (to_xy[1] - from[1]) * t];
            let p = self.stand_for(kind, on_ground, xy, to.theta)?;
            seq.push((Phase::PlannedBaseShift, None, p));
        }
        self.push(kind, &seq)
    }
}

/// Which step candidates the expansion tries (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepSearch {
    /// The planner's: every height of the shared rule, tallest first, with the
    /// partner wheel's full alignment, no, full or half roll, and none, all or half of
    /// the remaining base shift. Every one of them is also a [`StepSearch::Full`]
    /// candidate, so a step the planner admits is one the generator expands.
    Planner,
    /// The generator's: every height of the rule and two taller, every alignment, then
    /// fixed base shifts.
    Full,
}

/// The generator's candidates (leg height, wheel fraction, roll fraction, shift) at
/// `heights`, in the order tried (see the module docs).
fn full_candidates(heights: &[f64]) -> Vec<(f64, f64, f64, Shift)> {
    let mut out = Vec::new();
    for pass in 0..2 {
        for &h in heights {
            for wf in [1.0, 0.5, 0.0, f64::INFINITY] {
                for rf in [1.0, 0.5, 0.0] {
                    if pass == 0 {
                        for f in [1.0, 0.5, 0.0] {
                            out.push((h, wf, rf, Shift::Remainder(f)));
                        }
                    } else {
                        for m in [0.025, 0.05, 0.1, 0.15, 0.2, -0.025, -0.05, -0.1, -0.15, -0.2] {
                            out.push((h, wf, rf, Shift::Fixed(m)));
                        }
                    }
                }
            }
        }
    }
    out
}

/// The planner's (roll fraction, base-shift fraction) pairs, in order: every pair of the
/// generator's first pass with the partner wheel fully aligned.
const PLANNER_ALIGNMENTS: [(f64, f64); 9] = [
    (0.0, 0.0),
    (0.0, 1.0),
    (1.0, 0.0),
    (1.0, 1.0),
    (0.5, 0.0),
    (0.5, 1.0),
    (0.0, 0.5),
    (1.0, 0.5),
    (0.5, 0.5),
];

/// The generator's own expansions as the planner asks them (`locomotion::hybrid`), each
/// from posture `pre` (the shared rule's standing posture, [`StandingRule::stand`]) with
/// the CoM of `model` and the margins of `options`: what a path's manoeuvre needs to pass
/// here is what the generator later expands.
pub struct ManoeuvreCheck<'a> {
    /// The robot.
    pub robot: &'a RobotDescription,
    /// The maps the generator checks against.
    pub maps: &'a CostMaps,
    /// The CoM model (the planner's estimate).
    pub model: &'a mut dyn CenterOfMassModel,
    /// The generator's options, with the planner's margins.
    pub options: &'a MotionOptions,
}

impl ManoeuvreCheck<'_> {
    fn expander(&mut self, pre: Posture) -> Expander<'_> {
        let e = Expander::at(self.robot, self.maps, &mut *self.model, self.options, pre);
        Expander { braking: false, ..e }
    }

    /// A step: whether the expansion finds a stable motion among the
    /// [`StepSearch::Planner`] candidates for a step of `leg` from `pre` to `post_foot`.
    /// `heights` are the shared rule's step heights for this step
    /// ([`StandingRule::step_heights`], which the planner has begun to draw on): the
    /// generator computes the same from `pre`.
    ///
    /// # Errors
    /// The expansion's [`MotionError::Step`] when no candidate holds.
    pub fn step(
        &mut self,
        pre: Posture,
        leg: Leg,
        post_foot: [f64; 3],
        heights: impl Iterator<Item = f64>,
    ) -> Result<(), MotionError> {
        self.expander(pre).expand_step_at(leg, post_foot, StepSearch::Planner, heights)
    }

    /// A wheel move of `leg`'s pair to `foot` (x, y): a keyframe per cell of the way, each
    /// stood by the rule, and every point 1 cm apart between them. The rule's postures at
    /// the cells alone let a knee pass within the legs' clearance of a block's edge
    /// between two of them.
    ///
    /// # Errors
    /// The expansion's [`MotionError::Manoeuvre`] (or [`MotionError::UnknownTerrain`]).
    pub fn wheel_move(
        &mut self,
        pre: Posture,
        leg: Leg,
        foot: [f64; 2],
    ) -> Result<(), MotionError> {
        self.expander(pre).expand_wheel_move(ManoeuvreKind::FootForward, leg, foot)
    }

    /// A planned base shift to pose `to` over feet `feet` (x, y: the footprint at the
    /// shift's end): the base stood by the rule at every cell of the way.
    ///
    /// # Errors
    /// The expansion's [`MotionError::Manoeuvre`] (or [`MotionError::UnknownTerrain`]).
    pub fn base_shift(
        &mut self,
        pre: Posture,
        feet: [[f64; 2]; 4],
        to: &Pose2,
    ) -> Result<(), MotionError> {
        self.expander(pre).expand_base_shift(ManoeuvreKind::BaseShift, feet, to)
    }
}

/// The keyframes of a step candidate that most candidates fail at, built before the rest
/// of its sequence ([`Expander::early_keyframes`]).
#[derive(Debug, Clone, Copy)]
struct EarlyKeyframes {
    /// The base shift along the heading, m (0: none).
    shift: f64,
    /// The base's x, y after the shift.
    xy_shift: [f64; 2],
    /// The foot lifted to the swing height over where it stood, the base rolled and
    /// shifted.
    lift: Posture,
    /// All feet down after the shift, where the base shifts.
    shifted: Option<Posture>,
}

/// What a step candidate's alignment depends on: leg height, wheel and roll fractions.
type AlignmentKey = (f64, f64, f64);

/// The longitudinal part of a step candidate's alignment ([`Expander::wheel_alignment`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct WheelAlignment {
    /// Leg height of the standing rule, m.
    height: f64,
    /// How the step is stood ([`crate::posture::standing::StandingRule::step_stance`]).
    stance: StepStance,
    /// How far the partner wheel moves toward the centre, m.
    d: f64,
    /// How far longitudinal alignment wanted it to move, m.
    wanted: f64,
    /// The feet with the partner moved.
    moved: [[f64; 3]; 4],
    /// The support triangle's centroid (x, y, 0).
    stc: [f64; 3],
    /// The centre of rotation of the roll (y'_rot, z'_rot) (eq. 6).
    rot: [f64; 2],
    /// The footprint's width b (eq. 8), m.
    width: f64,
    /// The CoM standing with the partner moved, unrolled.
    com: [f64; 3],
}

/// A step candidate's alignment before its base shift ([`Expander::roll_alignment`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Alignment {
    /// Leg height of the standing rule, m.
    height: f64,
    /// How the step is stood ([`crate::posture::standing::StandingRule::step_stance`]).
    stance: StepStance,
    /// How far the partner wheel moves toward the centre, m.
    d: f64,
    /// How far longitudinal alignment wanted it to move, m.
    wanted: f64,
    /// The feet with the partner moved.
    moved: [[f64; 3]; 4],
    /// Base roll, rad.
    roll: f64,
    /// From the CoM after the roll to the support triangle's centroid along the
    /// heading, m: what a base shift would take up.
    rest: f64,
}

/// The longitudinal base shift of a step candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shift {
    /// This fraction of the CoM–STC remainder, only when the wheel was hindered (Sec. VI-A).
    Remainder(f64),
    /// A fixed shift, m (forward positive).
    Fixed(f64),
}

/// Where a checked sequence failed: the phase, how far into its segment, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{phase}: at {percent:.0} % of the segment: {cause}")]
pub struct SegmentFailure {
    /// The keyframe phase whose segment failed.
    pub phase: &'static str,
    /// Position along the segment, %.
    pub percent: f64,
    /// The cause.
    pub cause: Infeasible,
}

/// Expands an abstract path (`jobs::plan::PlanSummary::path`) into a detailed path of
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
    let check = DrivingCheck::from_parts(
        robot,
        options.standing,
        options.driving_leg_height_m,
        options.min_margin_m,
        options.base_circle_radius_m,
    );
    let special = |k: ManoeuvreKind| {
        !matches!(k, ManoeuvreKind::Start | ManoeuvreKind::Drive | ManoeuvreKind::Turn)
    };
    let mut standing = false;
    let mut steps = 0;
    for (k, el) in path.iter().enumerate().skip(1) {
        ex.index = k;
        match el.kind {
            ManoeuvreKind::Start => {}
            ManoeuvreKind::Drive | ManoeuvreKind::Turn => {
                if standing {
                    // Lower if the next manoeuvre is far (or there is none).
                    let mut dist = 0.0;
                    let mut prev = path[k - 1].pose;
                    let mut next_special = false;
                    for e2 in &path[k..] {
                        if special(e2.kind) {
                            next_special = true;
                            break;
                        }
                        dist += prev.distance(&e2.pose);
                        prev = e2.pose;
                    }
                    if !next_special || dist >= options.stay_standing_m {
                        let pose = Pose2 {
                            x: ex.cur.base_position[0],
                            y: ex.cur.base_position[1],
                            theta: ex.cur.base_rpy[2],
                        };
                        let p = ex.driving(&pose)?;
                        // Lower only where the driving posture fits (`feasibility`).
                        if check.posture_ok(&p, maps, maps.leg_terrain()).is_ok() {
                            ex.push(el.kind, &[(Phase::Lower, None, p)])?;
                            standing = false;
                        }
                    }
                }
                // Where the driving posture does not fit (a knee over a wall, a wheel
                // folded past its limit), drive standing, as the planner's feasibility
                // check allowed (`feasibility::DrivingCheck::lattice_pose`).
                if !standing
                    && check.posture_ok(&ex.driving(&el.pose)?, maps, maps.leg_terrain()).is_err()
                {
                    ex.stand_up(el.kind)?;
                    standing = true;
                }
                let target = if standing {
                    let feet = ex.neutral_feet(&el.pose)?;
                    ex.stand_for(el.kind, feet, [el.pose.x, el.pose.y], el.pose.theta)?
                } else {
                    ex.driving(&el.pose)?
                };
                ex.push(el.kind, &[(Phase::Drive, None, target)])?;
            }
            ManoeuvreKind::Step
            | ManoeuvreKind::BaseShift
            | ManoeuvreKind::FootForward
            | ManoeuvreKind::FootNeutral => {
                if !standing {
                    ex.stand_up(el.kind)?;
                    standing = true;
                }
                let bad = |reason: String| MotionError::Manoeuvre {
                    index: k,
                    kind: el.kind.name(),
                    reason,
                };
                match (el.kind, el.leg) {
                    (ManoeuvreKind::Step, Some(leg)) => {
                        ex.settle(el.kind, &path[k - 1].pose)?;
                        let f = el.feet[leg.index()];
                        let post_foot = [f[0], f[1], ex.ground(f[0], f[1])?];
                        ex.expand_step(leg, post_foot)?;
                        steps += 1;
                    }
                    (ManoeuvreKind::BaseShift, _) => {
                        ex.settle(el.kind, &path[k - 1].pose)?;
                        ex.expand_base_shift(el.kind, el.feet, &el.pose)?;
                    }
                    (_, Some(leg)) => {
                        ex.settle(el.kind, &path[k - 1].pose)?;
                        ex.expand_wheel_move(el.kind, leg, el.feet[leg.index()])?;
                    }
                    (_, None) => return Err(bad("no leg named".to_owned())),
                }
            }
        }
    }
    if standing {
        ex.index = path.len() - 1;
        let pose = Pose2 {
            x: ex.cur.base_position[0],
            y: ex.cur.base_position[1],
            theta: ex.cur.base_rpy[2],
        };
        let p = ex.driving(&pose)?;
        // Where the driving posture does not fit (the planner admitted the goal standing),
        // the robot finishes standing.
        if check.posture_ok(&p, maps, maps.leg_terrain()).is_ok() {
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
        steps,
        keyframes: ex.keys,
    })
}

/// Standard gravity, m/s².
const GRAVITY: f64 = 9.81;

/// The shortest smoothstep time for a CoM moving from `coms[0]` to `coms[1]` whose
/// zero-moment point stays within `shift` of its ground projection: `√(6 d h / (g δ))`
/// with `d` the CoM's horizontal travel and `h` its height over the mean of the feet `b`
/// has in contact (`Expander::duration`). Zero where a CoM is unknown.
fn zmp_duration(b: &Posture, coms: [[f64; 3]; 2], shift: f64) -> f64 {
    let [c0, c1] = coms;
    let d = (c1[0] - c0[0]).hypot(c1[1] - c0[1]);
    let (sum, n) =
        (0..4).filter(|&i| b.contact[i]).fold((0.0, 0.0), |(s, n), i| (s + b.feet[i][2], n + 1.0));
    let h = if n > 0.0 { c1[2] - sum / n } else { 0.0 };
    let t = (6.0 * d * h.max(0.0) / (GRAVITY * shift)).sqrt();
    if t.is_finite() { t } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

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

    #[test]
    fn a_segment_is_slow_enough_for_its_zero_moment_point() {
        // A CoM 0.5 m over the feet moved 5 cm (3 cm, 4 cm): 6 · 0.05 · 0.5 / (9.81 · 0.01)
        // = 1.529052 s², T = 1.236548 s; the smoothstep's peak acceleration 6 d / T² then
        // moves the zero-moment point a · h / g = 1 cm.
        let mut b = Posture {
            base_position: [0.0, 0.0, 0.6],
            base_rpy: [0.0; 3],
            feet: [[0.0, 0.0, 0.1]; 4],
            contact: [true; 4],
        };
        let coms = [[0.0, 0.0, 0.6], [0.03, 0.04, 0.6]];
        let t = zmp_duration(&b, coms, 0.01);
        assert!((t - 1.236_548).abs() < 1e-6, "{t}");
        assert!((6.0 * 0.05 / (t * t) * 0.5 / GRAVITY - 0.01).abs() < 1e-9);
        // Four times the shift (a segment with 4 cm of margin to spare): half the time.
        assert!((zmp_duration(&b, coms, 0.04) - t / 2.0).abs() < 1e-12);
        // The height counts over the feet in contact only; a CoM that does not move, or an
        // unknown one, asks nothing.
        b.feet[3][2] = 0.5;
        b.contact[3] = false;
        assert!((zmp_duration(&b, coms, 0.01) - t).abs() < 1e-12);
        assert_eq!(zmp_duration(&b, [coms[1]; 2], 0.01), 0.0);
        assert_eq!(zmp_duration(&b, [[f64::NAN; 3], coms[1]], 0.01), 0.0);
    }

    #[test]
    fn remembered_step_checks_find_what_unremembered_ones_find() {
        // A step's candidate search remembers its posture and segment checks
        // (`StepChecks`): the outcome, the reported failure and the keyframes committed
        // are those of the search without. Steps of every leg, from stances before the
        // paper's 0.2 m platform and on it, onto footholds on the floor, at the edge and
        // on top, forward and back; both candidate sets.
        use crate::scenario::terrain::Primitive;
        use crate::terrain::rasterise::rasterise;
        let robot = RobotDescription::reference();
        let params = Params::default();
        let prims =
            [Primitive::Box { center: [2.0, 0.0], size: [2.0, 2.0], height: 0.2, yaw_deg: 0.0 }];
        let map = rasterise(&prims, [-1.0, -1.0], [4.0, 2.0], 0.025).expect("map");
        let maps = CostMaps::build(&map, &robot, &params).expect("cost maps");
        let options = MotionOptions::from_params(&params);
        let rule = options.standing;
        let ground = |x: f64, y: f64| [x, y, maps.height_at(x, y).expect("ground")];
        let (mut held, mut failed) = (0, 0);
        for x in [0.45, 0.5, 0.6, 1.1875, 1.6] {
            let pose = Pose2::new(x, 0.0, 0.0);
            let feet = maps.neutral_feet(&pose).map(|[fx, fy]| ground(fx, fy));
            // Where a knee would touch the edge there is no stance to step from.
            let Ok((pre, _)) = rule.stand(&robot, maps.leg_terrain(), feet, [x, 0.0], 0.0) else {
                continue;
            };
            for leg in Leg::ALL {
                let f = feet[leg.index()];
                for d in [-0.2, 0.1, 0.2, 0.3, 0.45] {
                    let post = ground(f[0] + d, f[1]);
                    for search in [StepSearch::Planner, StepSearch::Full] {
                        let run = |remember: bool| {
                            let heights = rule.step_heights(
                                &robot,
                                maps.heights(),
                                maps.leg_terrain(),
                                feet,
                                leg.index(),
                                post,
                                [x, 0.0],
                                0.0,
                            );
                            let mut model =
                                crate::posture::standing::EstimatedCom { robot: &robot };
                            let mut e = Expander::at(&robot, &maps, &mut model, &options, pre);
                            let r = if remember {
                                e.expand_step_at(leg, post, search, heights)
                            } else {
                                e.search_step_candidates(leg, post, search, heights)
                            };
                            (r, e.keys)
                        };
                        let remembered = run(true);
                        assert_eq!(remembered, run(false), "{leg:?} from x = {x} by {d} m");
                        if remembered.0.is_ok() {
                            held += 1;
                        } else {
                            failed += 1;
                        }
                    }
                }
            }
        }
        assert!(held > 10 && failed > 10, "{held} held, {failed} failed");
    }
}
