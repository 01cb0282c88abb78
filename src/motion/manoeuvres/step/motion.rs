//! The step's motion (Sec. VI-A, Fig. 12, 13c–g): `roll` (eqs. 6–8 toward the support
//! triangle centroid's lateral coordinate, iterated with the CoM model because the base
//! actually turns about the lower side's hips rather than about R, and capped at
//! `MotionOptions::max_roll_rad`), `wheel_to_centre` (the other wheel pair on the
//! stepping side driven toward the centre until the STC's longitudinal coordinate meets
//! the CoM's, stopping before cells of infinite foot cost, height changes, and
//! `MotionOptions::wheel_gap_m` from the stepping foot), `base_shift` (only if a
//! longitudinal error of more than 2 cm remains: the wheel was blocked), `lift` (the
//! foot rises vertically to `StandingRule::swing_clearance_m` above the highest terrain
//! within a wheel's reach of its straight path), `swing`, `place`, then `shift_back`,
//! `wheel_back`, `roll_back` (to the post-step pitch).
//!
//! **Alternatives before failing**: a step is tried at the leg heights of the shared
//! standing rule at which it stays within reach (`StandingRule::step_heights`, the same
//! check the planner made), tallest first, then at 0.50 and 0.55 m; for each, full
//! wheel-to-centre alignment, half, none, and as far as the wheel may go (a diagonal
//! support edge may need it further in than alignment asks); full, half, then no roll; a
//! base shift taking what the wheel leaves (all, half, none). Then, as a second pass,
//! fixed base shifts of ±2.5 to ±20 cm with every wheel and roll choice. The first
//! candidate whose every point holds is taken; otherwise [`MotionError::Step`] names the
//! step, the leg and the best margin reached.
//!
//! **The planner runs the same check** ([`check`], [`StepSearch::Planner`]): every height
//! with full wheel alignment and every roll and shift fraction, a subset of the
//! generator's candidates, from the shared rule's standing posture at the planned pose
//! (`StandingRule::stand`). Heights are taken lazily, the next only when every candidate
//! at the ones before failed, so a step that holds tall costs no more. Tall steps hold
//! only lower down: a front foot onto 0.24 m holds first at 0.31 m of leg height, where
//! the rolled stance leaves the stretched rear leg on the same side its reach (when the
//! planner tried only the two tallest heights, it called every block above ~0.21 m
//! impassable). The generator settles into that posture before every step and wheel move
//! (a `stand_up` keyframe where the manoeuvre before left the base elsewhere), so a step
//! the planner admits meets a candidate here that holds; only the CoM model differs (the
//! planner's estimate, MuJoCo's here), and the planner keeps 3 mm of margin for that.

use crate::feasibility::Infeasible;
use crate::motion::expander::{Expander, MotionError, Planned, SegmentFailure, StepChecks};
use crate::motion::keyframe::Phase;
use crate::motion::roll::{RollError, roll_for_lateral_com};
use crate::params::StepModel;
use crate::posture::kinematics::{Posture, PostureError, solve_chains};
use crate::posture::standing::StepStance;
use crate::robot::Leg;

/// The planner's check of a step ([`StepSearch::Planner`]) of `leg` from the expander's
/// posture (the shared rule's standing posture) to `post_foot`: whether the expansion
/// finds a stable motion among the planner's candidates. `heights` are the shared rule's
/// step heights for this step (`StandingRule::step_heights`, which the planner has begun
/// to draw on): the generator computes the same from the posture.
///
/// # Errors
/// The expansion's [`MotionError::Step`] when no candidate holds.
pub fn check(
    ex: &mut Expander<'_>,
    leg: Leg,
    post_foot: [f64; 3],
    heights: impl Iterator<Item = f64>,
) -> Result<(), MotionError> {
    ex.expand_step_at(leg, post_foot, StepSearch::Planner, heights)
}

impl Expander<'_> {
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
    pub(crate) fn expand_step(&mut self, leg: Leg, post_foot: [f64; 3]) -> Result<(), MotionError> {
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
    pub(crate) fn expand_step_at(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cost::CostMaps;
    use crate::feasibility::MotionOptions;
    use crate::geometry::Pose2;
    use crate::params::Params;
    use crate::robot::RobotDescription;

    #[test]
    fn remembered_step_checks_find_what_unremembered_ones_find() {
        // A step's candidate search remembers its posture and segment checks
        // (`StepChecks`): the outcome, the reported failure and the keyframes committed
        // are those of the search without. Steps of every leg, from stances before the
        // paper's 0.2 m platform and on it, onto footholds on the floor, at the edge and
        // on top, forward and back; both candidate sets.
        use crate::scenario::terrain::{Block, Primitive};
        use crate::terrain::rasterise::rasterise;
        let robot = RobotDescription::reference();
        let params = Params::default();
        let prims = [Primitive::Box(Block {
            center: [2.0, 0.0],
            size: [2.0, 2.0],
            height: 0.2,
            yaw_deg: 0.0,
        })];
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
