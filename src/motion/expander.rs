//! The motion generator's engine (Sec. VI): an [`Expander`] keeps the robot's posture
//! (base pose and the four feet) while manoeuvres append keyframes to it, and checks
//! every keyframe and interpolated point it is given.
//!
//! **Stability** (Sec. VI-A): every keyframe and interpolated point (every 1 cm of base or
//! foot motion and every 0.02 rad) is solved with the leg IK (reach with
//! `StandingRule::reach_margin_m` to spare, joint limits) and its CoM computed with the
//! [`CenterOfMassModel`]; its margin in the support polygon of the feet in contact must be
//! at least `MotionOptions::min_margin_m` (default 3 cm), and with a foot lifted the
//! executor's lift threshold, `MotionOptions::min_three_contact_margin_m` (5 cm: the
//! estimate leaves out the support legs' sag toward the unloaded foot).
//!
//! **Timing**: each standing segment is timed at the base, foot and angular speeds and
//! slow enough that the smoothstep's braking moves the zero-moment point from the CoM's
//! ground projection no further than the segment's margin beyond the required one, or
//! 1 cm where it has none to spare, `T ≥ √(6 d h / (g δ))` ([`Expander::duration`]).
//!
//! The same engine runs the planner's checks of a manoeuvre ([`Expander::for_check`]:
//! the planner's CoM estimate and margins, no keyframes kept, no braking), so a path's
//! manoeuvre that passes there is one the generator expands.

use super::keyframe::{Keyframe, Phase};
use crate::cost::CostMaps;
use crate::feasibility::{DrivingCheck, Infeasible, MotionOptions};
use crate::geometry::{Pose2, wrap_angle};
use crate::path::{ManoeuvreKind, PathElement};
use crate::posture::CenterOfMassModel;
use crate::posture::kinematics::base_z_in;
use crate::posture::kinematics::{
    self, Evaluation, Posture, PostureError, contacts_in, evaluate_legs, interpolate, rotation,
    solve_chains,
};
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

/// A segment that passed: its end evaluation, smallest margins and sample count.
#[derive(Debug, Clone)]
struct SegmentCheck {
    end: Evaluation,
    min_margin: f64,
    min_three: f64,
    samples: usize,
}

/// The robot's posture while a path (or one manoeuvre, for the planner's checks) is
/// expanded, and the keyframes appended so far.
pub struct Expander<'a> {
    /// The robot.
    pub(crate) robot: &'a RobotDescription,
    /// The maps the postures are checked against.
    pub(crate) maps: &'a CostMaps,
    /// The CoM model (MuJoCo's, or the planner's estimate in its checks).
    pub(crate) model: &'a mut dyn CenterOfMassModel,
    /// The generator's constants.
    pub(crate) o: &'a MotionOptions,
    /// The keyframes committed so far.
    pub(crate) keys: Vec<Keyframe>,
    /// The current posture.
    pub(crate) cur: Posture,
    /// Whether keyframes are timed for braking ([`Expander::duration`]): not for the
    /// planner's checks ([`Expander::for_check`]), which keep no keyframes.
    pub(crate) braking: bool,
    /// Time of the last keyframe, s.
    pub(crate) time: f64,
    /// Postures checked.
    pub(crate) samples: usize,
    /// Smallest margin of any posture checked, m.
    pub(crate) min_margin: f64,
    /// Smallest margin of any posture on three feet, m.
    pub(crate) min_three: f64,
    /// Index of the path element being expanded.
    pub(crate) index: usize,
    /// Whether the robot stands (after a manoeuvre) rather than drives.
    pub(crate) standing: bool,
    /// Steps expanded.
    pub(crate) steps: usize,
    /// The checks of the step being searched ([`StepChecks`]); `None` outside a step's
    /// candidate search.
    pub(crate) checked: Option<StepChecks>,
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
pub(crate) struct StepChecks {
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
pub(crate) type Planned = (Phase, Option<Leg>, Posture);

impl<'a> Expander<'a> {
    /// An expander standing in posture `cur`, nothing expanded yet.
    pub fn at(
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
            standing: false,
            steps: 0,
            checked: None,
        }
    }

    /// An expander for the planner's check of one manoeuvre from posture `pre` (the
    /// shared rule's standing posture), with the planner's CoM model and margins: it keeps
    /// no keyframes' timing (no braking).
    pub fn for_check(
        robot: &'a RobotDescription,
        maps: &'a CostMaps,
        model: &'a mut dyn CenterOfMassModel,
        o: &'a MotionOptions,
        pre: Posture,
    ) -> Self {
        Self { braking: false, ..Self::at(robot, maps, model, o, pre) }
    }

    /// The shared feasibility model's driving check with the generator's margins: where
    /// the driving posture fits.
    pub(crate) fn driving_check(&self) -> DrivingCheck {
        let o = self.o;
        DrivingCheck::from_parts(
            self.robot,
            o.standing,
            o.driving_leg_height_m,
            o.min_margin_m,
            o.base_circle_radius_m,
        )
    }

    /// Stands up before a manoeuvre of `kind` (anything but a drive or turn) if the
    /// robot is in its driving posture.
    ///
    /// # Errors
    /// [`MotionError::Manoeuvre`] where no standing posture holds.
    pub(crate) fn stand_if_driving(&mut self, kind: ManoeuvreKind) -> Result<(), MotionError> {
        if !self.standing {
            self.stand_up(kind)?;
            self.standing = true;
        }
        Ok(())
    }

    /// The leg a path element of a one-leg manoeuvre names.
    ///
    /// # Errors
    /// [`MotionError::Manoeuvre`] where it names none.
    pub(crate) fn leg_of(&self, el: &PathElement) -> Result<Leg, MotionError> {
        el.leg.ok_or_else(|| MotionError::Manoeuvre {
            index: self.index,
            kind: el.kind.name(),
            reason: "no leg named".to_owned(),
        })
    }

    /// Before path element `k`, a manoeuvre standing on its feet: stands up if driving
    /// ([`Self::stand_if_driving`]), then settles at the pose before it ([`Self::settle`]).
    ///
    /// # Errors
    /// [`MotionError::Manoeuvre`] where no standing posture holds.
    pub(crate) fn stand_before(
        &mut self,
        path: &[PathElement],
        k: usize,
    ) -> Result<(), MotionError> {
        let kind = path[k].kind;
        self.stand_if_driving(kind)?;
        self.settle(kind, &path[k - 1].pose)
    }

    pub(crate) fn ground(&self, x: f64, y: f64) -> Result<f64, MotionError> {
        self.maps.height_at(x, y).ok_or(MotionError::UnknownTerrain { index: self.index, x, y })
    }

    pub(crate) fn neutral_feet(&self, pose: &Pose2) -> Result<[[f64; 3]; 4], MotionError> {
        let xy = self.maps.neutral_feet(pose);
        let mut f = [[0.0; 3]; 4];
        for i in 0..4 {
            f[i] = [xy[i][0], xy[i][1], self.ground(xy[i][0], xy[i][1])?];
        }
        Ok(f)
    }

    /// Base pitch: `pitch_fraction` of the slope between the front and rear feet.
    pub(crate) fn pitch_for(&self, feet: &[[f64; 3]; 4], yaw: f64) -> f64 {
        self.o.standing.pitch(feet, yaw)
    }

    /// Driving posture at `pose` (Sec. VI-B, [`kinematics::driving_posture`]).
    pub(crate) fn driving(&self, pose: &Pose2) -> Result<Posture, MotionError> {
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
    pub(crate) fn standing(
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
    pub(crate) fn standing_fallback(
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

    pub(crate) fn com_of(&mut self, p: &Posture) -> Result<[f64; 3], PostureError> {
        solve_chains(self.robot, p, self.o.standing.reach_margin_m)
            .map(|legs| self.model.com_of_solved(&legs))
    }

    /// Checks one posture: the leg IK with the reach margin, thighs and shins clear of the
    /// terrain, and the stability margin. Within a step's candidate search, remembered
    /// ([`StepChecks`]).
    pub(crate) fn check_posture(&mut self, p: &Posture) -> Result<Evaluation, Infeasible> {
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
    pub(crate) fn evaluate_posture(&mut self, p: &Posture) -> Result<Evaluation, Infeasible> {
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
    pub(crate) fn duration(
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
    pub(crate) fn trial(
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

    pub(crate) fn commit(&mut self, keys: Vec<Keyframe>, mm: f64, m3: f64, samples: usize) {
        if let Some(k) = keys.last() {
            self.cur = k.posture();
            self.time = k.time_s;
        }
        self.min_margin = self.min_margin.min(mm);
        self.min_three = self.min_three.min(m3);
        self.samples += samples;
        self.keys.extend(keys);
    }

    pub(crate) fn push(&mut self, kind: ManoeuvreKind, seq: &[Planned]) -> Result<(), MotionError> {
        let (k, mm, m3, s) = self.trial(seq).map_err(|f| MotionError::Manoeuvre {
            index: self.index,
            kind: kind.name(),
            reason: f.to_string(),
        })?;
        self.commit(k, mm, m3, s);
        Ok(())
    }

    pub(crate) fn stand_up(&mut self, kind: ManoeuvreKind) -> Result<(), MotionError> {
        let (feet, xy, yaw) = (self.cur.feet, self.xy(), self.cur.base_rpy[2]);
        let p = self.stand_for(kind, feet, xy, yaw)?;
        self.push(kind, &[(Phase::StandUp, None, p)])
    }

    /// [`Self::standing_fallback`] within a manoeuvre of `kind`: its failure names the
    /// manoeuvre.
    pub(crate) fn stand_for(
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

    pub(crate) fn xy(&self) -> [f64; 2] {
        [self.cur.base_position[0], self.cur.base_position[1]]
    }

    /// Moves the base, all feet down, to the shared rule's standing posture over the
    /// current feet at `pose` ([`StandingRule::stand`]) if it is not there: every step,
    /// wheel move and planned base shift starts from that posture, the one the planner
    /// checks it from ([`Expander::for_check`]), whatever the manoeuvre before left (a roll-back
    /// at another leg height, a base re-centred on its feet).
    pub(crate) fn settle(&mut self, kind: ManoeuvreKind, pose: &Pose2) -> Result<(), MotionError> {
        let p = self.stand_for(kind, self.cur.feet, [pose.x, pose.y], pose.theta)?;
        if p != self.cur {
            self.push(kind, &[(Phase::StandUp, None, p)])?;
        }
        Ok(())
    }
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
}
