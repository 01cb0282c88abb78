//! The leg-height rule for standing manoeuvres (Sec. VI-B), shared by the planner's
//! reach checks (`motion::manoeuvres`) and the step motion generator (`motion::expander`),
//! so every footprint the planner admits is one the generator can stand in.
//!
//! Sec. VI-B: for manoeuvres other than driving, "the base height is determined by the
//! highest foot. A soft constraint is applied that the leg height should be at least
//! 0.45 m. At the same time, a hard constraint […] is that none of the legs exceeds its
//! maximum leg length", and "the robot base pitching angle is set to be 70 % of the ground
//! slope". Here:
//!
//! - the pitch is `pitch_fraction` of the slope between the mean front and mean rear foot
//!   ([`super::kinematics::pitch_from_feet`]); during a step, the mean of the pitch before
//!   and after it;
//! - the base origin is raised until the leg over the highest ground is `height` long (the
//!   others are longer);
//! - `height` starts at the soft constraint (0.45 m) and drops in 1 cm steps, down to the
//!   driving height, until every leg reaches its foot with the reach margin to spare
//!   (sagittal IK within the joint limits, [`super::kinematics::solve_legs`]);
//! - during a step, the stepping leg counts the higher of its two grounds (the foot must
//!   clear it), and its foot must also be reachable at the swing height above both ends.

use super::CenterOfMassModel;
use super::kinematics::{
    BaseFrame, Posture, PostureError, SolvedLegs, apply, base_z_in, contacts_in, pitch_from_feet,
    rotation, solve_chains, solve_chains_in,
};
use crate::geometry::norm2;
use crate::params::Params;
use crate::robot::RobotDescription;
use crate::robot::ik::{LegChain, knee_and_ankle, leg_fk};
use crate::terrain::HeightMap;

/// Pad of a leg chain's bounding box in [`StandingRule::legs_clear`]'s block test, in
/// grid cells and metres: far above the rounding of a sample interpolated between two of
/// the chain's points (about 10⁻¹⁵), far below anything a cell or a clearance resolves.
const CHAIN_BOX_PAD: f64 = 1e-9;

/// The parameters of the rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandingRule {
    /// Soft minimum leg height of the highest foot (0.45 m, Sec. VI-B), m.
    pub leg_height_m: f64,
    /// Lowest leg height tried (the driving height, 0.27 m), m.
    pub min_leg_height_m: f64,
    /// Decrement between tried heights, m.
    pub height_step_m: f64,
    /// Base pitch as a fraction of the ground slope (0.7, Sec. VI-B).
    pub pitch_fraction: f64,
    /// Spare reach every leg keeps (hip-to-ankle below thigh + shin by this much), m: 2 cm,
    /// what the executor's holds take. The legs are position servos: under the robot's
    /// weight they give, the base sinks 1–2 cm and lags a shift, and the executor's height
    /// and position holds (`control::step_executor`) make that up by commanding the legs
    /// longer than the keyframes. A leg planned at full reach has nothing to give them:
    /// with 2 mm to spare a partner pair driven toward the centre on a stair descent
    /// (0.14 m × 0.35 m) stopped 2.3 cm short, the base stood 2 cm behind its keyframe,
    /// and the rear step's lift margin measured 1.4 cm under the plan's (aborted); on a
    /// long flight (generated stairs, seed 6) a rear-loaded stance on stretched legs
    /// pitched nose up by 6° and tipped over backward. Both pass with 2 cm.
    pub reach_margin_m: f64,
    /// Swing foot clearance above the terrain near its path, m.
    pub swing_clearance_m: f64,
    /// Smallest height of a thigh or shin axis point above the terrain under it (the
    /// dilated `CostMaps::leg_terrain`), m: the capsule radius (2.5 cm) and 1.5 cm to
    /// spare.
    pub leg_clearance_m: f64,
}

impl StandingRule {
    /// The paper's values from `params`, 1 cm height steps, 2 cm spare reach, 5 cm swing
    /// clearance.
    pub fn from_params(params: &Params) -> Self {
        Self {
            leg_height_m: params.manoeuvre_leg_height_m,
            min_leg_height_m: params.driving_leg_height_m,
            height_step_m: 0.01,
            pitch_fraction: params.base_pitch_slope_fraction,
            reach_margin_m: 0.02,
            swing_clearance_m: 0.05,
            leg_clearance_m: 0.04,
        }
    }

    /// Swing height of a foot carried from `a` to `b` under heading `yaw`:
    /// `swing_clearance_m` above the highest terrain within a wheel radius (plus
    /// [`SWING_SCAN_PAD_M`]) of either wheel's straight path. The wheels are the model's
    /// spheres at ±track/2 along the axle, which is across the foot's heading (the base
    /// heading), so the swept volume reaches a wheel radius ahead and behind but
    /// track/2 + a wheel radius to the sides: a foot set down close before a stair's next
    /// riser does not have to be carried over that riser.
    pub fn swing_z(
        &self,
        robot: &RobotDescription,
        heights: &HeightMap,
        a: [f64; 3],
        b: [f64; 3],
        yaw: f64,
    ) -> f64 {
        let radius = robot.wheel_radius + SWING_SCAN_PAD_M;
        let (s, c) = yaw.sin_cos();
        let half = robot.wheel_track / 2.0;
        let top = [-1.0, 1.0]
            .map(|side| {
                let (ox, oy) = (-s * half * side, c * half * side);
                let end = |p: [f64; 3]| [p[0] + ox, p[1] + oy, p[2]];
                heights.max_height_near_segment(end(a), end(b), radius)
            })
            .into_iter()
            .fold(f64::NEG_INFINITY, f64::max);
        top + self.swing_clearance_m
    }

    /// The heights tried, soft constraint first.
    pub fn heights(&self) -> impl Iterator<Item = f64> + use<> {
        let (top, low, step) = (self.leg_height_m, self.min_leg_height_m, self.height_step_m);
        let n =
            if step > 0.0 && top >= low { ((top - low) / step + 1e-9).floor() as usize } else { 0 };
        (0..=n).map(move |k| top - k as f64 * step)
    }

    /// Whether every thigh and shin of a posture (its legs solved, `legs`) keeps
    /// `leg_clearance_m` above `terrain` (heights dilated by the legs' width, see
    /// `CostMaps::leg_terrain`) at points a quarter segment (6.25 cm) apart along it: a
    /// lowered base must not fold a knee onto a step.
    ///
    /// # Errors
    /// [`PostureError::LegCollision`] naming the leg and its clearance.
    pub fn legs_clear(
        &self,
        robot: &RobotDescription,
        terrain: &HeightMap,
        legs: &SolvedLegs,
    ) -> Result<(), PostureError> {
        let r = &legs.frame.rotation;
        for leg in crate::robot::Leg::ALL {
            let i = leg.index();
            let h = robot.hips[i];
            let LegChain { knee, ankle, .. } = legs.chains[i];
            // The chain's points in the terrain's grid units (x, y; z in metres): the base
            // transform and the grid's are affine, so the samples between the points are
            // their interpolation (three transforms and divisions a leg, not eight; this
            // check was a fifth of the platform's A* time, its optimum 1-5 % sooner).
            let chain = [
                [h[0], h[1], h[2]],
                [h[0] + knee[0], h[1], h[2] + knee[1]],
                [h[0] + ankle[0], h[1], h[2] + ankle[1]],
            ]
            .map(|b| {
                let w = apply(r, legs.base_position, b);
                let [gx, gy] = terrain.grid_coords(w[0], w[1]);
                [gx, gy, w[2]]
            });
            // Every sample lies in the chain's bounding box and no lower than its lowest
            // point (the segments are straight): a leg whose lowest point keeps the
            // clearance above the box's highest block keeps it at every sample, and is
            // clear without them (a few block look-ups where the samples take 8; the
            // result is the same, the pads cover the interpolation's rounding).
            let (lo, hi) =
                chain.iter().fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), p| {
                    (
                        std::array::from_fn(|c| lo[c].min(p[c])),
                        std::array::from_fn(|c| hi[c].max(p[c])),
                    )
                });
            let pad = CHAIN_BOX_PAD;
            let top = terrain
                .max_known_in_grid_box([lo[0] - pad, lo[1] - pad], [hi[0] + pad, hi[1] + pad]);
            if lo[2] - pad - top >= self.leg_clearance_m {
                continue;
            }
            for seg in chain.windows(2) {
                // A quarter segment apart, far end included (the hip never dips).
                for k in 1..=4 {
                    let t = f64::from(k) / 4.0;
                    let w: [f64; 3] =
                        std::array::from_fn(|c| seg[0][c] + (seg[1][c] - seg[0][c]) * t);
                    let Some(top) = terrain.height_at_grid([w[0], w[1]]) else { continue };
                    if w[2] - top < self.leg_clearance_m {
                        return Err(PostureError::LegCollision { leg, clearance: w[2] - top });
                    }
                }
            }
        }
        Ok(())
    }

    /// Pitch for feet `feet` under heading `yaw`.
    pub fn pitch(&self, feet: &[[f64; 3]; 4], yaw: f64) -> f64 {
        pitch_from_feet(feet, yaw, self.pitch_fraction)
    }

    /// Pitch during a step from feet `pre` to feet `post`: the mean of both.
    pub fn step_pitch(&self, pre: &[[f64; 3]; 4], post: &[[f64; 3]; 4], yaw: f64) -> f64 {
        (self.pitch(pre, yaw) + self.pitch(post, yaw)) / 2.0
    }

    /// The stance a step of leg `leg` from feet `pre` to `post_foot` is made in, under
    /// heading `yaw`: the step's pitch ([`Self::step_pitch`]) and the ground under each
    /// leg, the stepping leg counting the higher of its two grounds (the foot must clear
    /// it). Planner and generator both stand a step this way.
    pub fn step_stance(
        &self,
        pre: &[[f64; 3]; 4],
        leg: usize,
        post_foot: [f64; 3],
        yaw: f64,
    ) -> StepStance {
        let mut post = *pre;
        post[leg] = post_foot;
        let mut ground = pre.map(|f| f[2]);
        ground[leg] = pre[leg][2].max(post_foot[2]);
        StepStance { post, pitch: self.step_pitch(pre, &post, yaw), ground }
    }

    /// The first height of [`Self::heights`] at which all four feet (in contact, on their
    /// legs' planes) are reached and no thigh or shin touches `terrain`
    /// ([`Self::legs_clear`]), with the posture.
    ///
    /// # Errors
    /// The last height's [`PostureError`] if none reaches.
    pub fn stand(
        &self,
        robot: &RobotDescription,
        terrain: &HeightMap,
        feet: [[f64; 3]; 4],
        xy: [f64; 2],
        yaw: f64,
    ) -> Result<(Posture, f64), PostureError> {
        self.stand_within(robot, (terrain, None), feet, xy, yaw).map(|(p, h, _)| (p, h))
    }

    /// [`Self::stand`] on `terrain`, and whether the posture's legs also clear `wider`
    /// ([`Self::legs_clear`]): heights at least `terrain`'s wherever `terrain` knows one
    /// (a wider dilation of the same map, as `CostMaps::swept_leg_terrain` is of
    /// `CostMaps::leg_terrain`). `wider` is checked first at each height: legs clear
    /// of it are clear of `terrain` at the same points, so the common case costs one
    /// clearance check instead of two, and the answer is the same.
    ///
    /// # Errors
    /// As [`Self::stand`].
    pub fn stand_clear_of(
        &self,
        robot: &RobotDescription,
        terrain: &HeightMap,
        wider: &HeightMap,
        feet: [[f64; 3]; 4],
        xy: [f64; 2],
        yaw: f64,
    ) -> Result<(Posture, f64, bool), PostureError> {
        self.stand_within(robot, (terrain, Some(wider)), feet, xy, yaw)
    }

    /// [`Self::stand_clear_of`], `wider` optional (none: `false`).
    fn stand_within(
        &self,
        robot: &RobotDescription,
        (terrain, wider): (&HeightMap, Option<&HeightMap>),
        feet: [[f64; 3]; 4],
        xy: [f64; 2],
        yaw: f64,
    ) -> Result<(Posture, f64, bool), PostureError> {
        let pitch = self.pitch(&feet, yaw);
        let ground = feet.map(|f| f[2]);
        let frame = BaseFrame::new([0.0, pitch, yaw]);
        let probe = ReachProbe::new(robot, &feet, [true; 4], xy, &frame, &ground, self);
        let mut last = None;
        for h in self.heights() {
            if let Err(e) = probe.distances_ok(h) {
                last = Some(e);
                continue;
            }
            let p = level_posture_in(robot, feet, [true; 4], xy, &frame, h, ground);
            let legs = match solve_chains_in(robot, &frame, &p, self.reach_margin_m) {
                Ok(legs) => legs,
                Err(e) => {
                    last = Some(e);
                    continue;
                }
            };
            if wider.is_some_and(|w| self.legs_clear(robot, w, &legs).is_ok()) {
                return Ok((p, h, true));
            }
            match self.legs_clear(robot, terrain, &legs) {
                Ok(()) => return Ok((p, h, false)),
                Err(e) => last = Some(e),
            }
        }
        Err(last.unwrap_or(PostureError::NoHeight))
    }

    /// The heights of [`Self::heights`], tallest first and computed lazily, at which a
    /// step of leg `leg` from feet `pre` to `post_foot` keeps every leg within reach: the
    /// three support feet and the stepping foot on the ground at both ends and at the
    /// swing height ([`Self::swing_z`] over `heights`) along its straight path (every
    /// 5 cm, ends included: a folded leg cannot pass under its hip), with the step's pitch
    /// and the stepping leg counting the higher ground; thighs and shins clear
    /// `leg_terrain`.
    #[allow(clippy::too_many_arguments)]
    pub fn step_heights<'a>(
        &'a self,
        robot: &'a RobotDescription,
        heights: &HeightMap,
        leg_terrain: &'a HeightMap,
        pre: [[f64; 3]; 4],
        leg: usize,
        post_foot: [f64; 3],
        xy: [f64; 2],
        yaw: f64,
    ) -> impl Iterator<Item = f64> + use<'a> {
        let StepStance { post, pitch, ground } = self.step_stance(&pre, leg, post_foot, yaw);
        let frame = BaseFrame::new([0.0, pitch, yaw]);
        let probe = |feet: &[[f64; 3]; 4]| {
            ReachProbe::new(robot, feet, [true; 4], xy, &frame, &ground, self)
        };
        let mut variants = vec![pre, post];
        let mut probes: Vec<ReachProbe> = variants.iter().map(probe).collect();
        // The swing height scans the terrain around the path, the dearest part: only
        // when both ground stances pass the distance check at some height (a quarter of
        // the planner's candidate footholds on the platform end here).
        let window = |probes: &[ReachProbe]| {
            probes
                .iter()
                .map(ReachProbe::height_window)
                .fold((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi), (l, h)| (lo.max(l), hi.min(h)))
        };
        let (lo, hi) = window(&probes);
        let grounded = self
            .heights()
            .any(|h| (lo..=hi).contains(&h) && probes.iter().all(|p| p.distances_ok(h).is_ok()));
        if grounded {
            let swing_z = self.swing_z(robot, heights, pre[leg], post_foot, yaw);
            // The swing at most 5 cm apart, ends included, and where the foot passes
            // closest under its hip (1 cm either side, the generator's spacing): the
            // hip-to-ankle distance is convex along the straight swing, so the knee
            // folds furthest there, between two 5 cm samples.
            let (a, b) = (pre[leg], post_foot);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let n = (len / SWING_SAMPLE_M).ceil().max(1.0) as usize;
            let hip = {
                let h = robot.hips[leg];
                let (s, c) = yaw.sin_cos();
                [xy[0] + c * h[0] - s * h[1], xy[1] + s * h[0] + c * h[1]]
            };
            let closest = if len > 1e-9 {
                ((hip[0] - a[0]) * (b[0] - a[0]) + (hip[1] - a[1]) * (b[1] - a[1])) / (len * len)
            } else {
                0.0
            };
            let fine = SWING_FINE_M / len.max(1e-9);
            let mut ts: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
            ts.extend([closest - fine, closest, closest + fine].map(|t| t.clamp(0.0, 1.0)));
            for t in ts {
                let mut feet = pre;
                feet[leg] = [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, swing_z];
                probes.push(probe(&feet));
                variants.push(feet);
            }
            // The lifted foot first: its stances fail most often.
            variants.rotate_left(2);
        }
        // Lazy: the planner needs only the first (tallest) height, and each costs up to
        // one IK and one clearance check per variant. The variant that failed is tried
        // first at the next height: mostly the same one fails (the foot lifted at one end
        // of its swing folds the leg past a joint limit), so a rejected height costs one
        // IK instead of several.
        let (lo, hi) = window(&probes);
        let tried = if grounded { Some(self.heights()) } else { None };
        tried.into_iter().flatten().filter(move |&h| {
            if !(lo..=hi).contains(&h) || !probes.iter().all(|p| p.distances_ok(h).is_ok()) {
                return false;
            }
            let failed = variants.iter().position(|feet| {
                let p = level_posture_in(robot, *feet, [true; 4], xy, &frame, h, ground);
                solve_chains_in(robot, &frame, &p, self.reach_margin_m)
                    .and_then(|legs| self.legs_clear(robot, leg_terrain, &legs))
                    .is_err()
            });
            if let Some(k) = failed {
                variants.swap(0, k);
            }
            failed.is_none()
        })
    }
}

/// How a step is stood ([`StandingRule::step_stance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepStance {
    /// The feet after the step.
    pub post: [[f64; 3]; 4],
    /// Base pitch during the step, rad.
    pub pitch: f64,
    /// Ground height under each leg, the stepping leg's the higher of its two, m.
    pub ground: [f64; 4],
}

/// What the swing scan adds to the wheel radius around each wheel's path, m: the
/// tracking error a swinging foot is allowed.
pub const SWING_SCAN_PAD_M: f64 = 0.02;

/// Spacing of the swing points [`StandingRule::step_heights`] checks, m.
const SWING_SAMPLE_M: f64 = 0.05;

/// Spacing of the extra swing points around the foot's closest pass under its hip, m:
/// the motion generator's sample spacing (`motion::expand`).
const SWING_FINE_M: f64 = 0.01;

/// The cheap part of [`super::kinematics::solve_legs`] for one set of feet at every
/// height of the rule: the rotation and the feet in the base frame are computed once;
/// lowering the base by δ moves every foot by δ·Rᵀe_z in the base frame, so each height
/// costs four distance checks. The joint-limit part stays with `solve_legs`.
struct ReachProbe {
    /// Feet relative to their hips in the base frame at `h0`.
    local0: [[f64; 3]; 4],
    /// Rᵀ·e_z: world up in the base frame.
    up: [f64; 3],
    h0: f64,
    /// From the contact point to the ankle in the base frame (x', z'), as
    /// [`crate::robot::ik::ankle_of_contact`] adds it.
    ankle: [f64; 2],
    limit: f64,
    reach_margin: f64,
    contact: [bool; 4],
    /// The stance twist's verdict ([`super::kinematics::check_stance_twist`]): the base
    /// moves along its own axis, so it is the same at every height.
    twist: Result<(), PostureError>,
}

impl ReachProbe {
    fn new(
        robot: &RobotDescription,
        feet: &[[f64; 3]; 4],
        contact: [bool; 4],
        xy: [f64; 2],
        frame: &BaseFrame,
        ground: &[f64; 4],
        rule: &StandingRule,
    ) -> Self {
        let h0 = rule.leg_height_m;
        let p = level_posture_in(robot, *feet, contact, xy, frame, h0, *ground);
        let (r, down) = (&frame.rotation, frame.down);
        let below = robot.foot_length + robot.wheel_radius;
        let local0 = contacts_in(robot, r, &p);
        Self {
            twist: super::kinematics::check_stance_twist(contact, &local0),
            local0,
            up: [r[2][0], r[2][1], r[2][2]],
            h0,
            ankle: [-below * down[0], -below * down[1]],
            limit: robot.thigh_length + robot.shin_length - rule.reach_margin_m,
            reach_margin: rule.reach_margin_m,
            contact,
        }
    }

    /// The leg heights `[lo, hi]` outside which [`Self::distances_ok`] fails (empty when
    /// `lo > hi`), widened by 1 µm so that rounding never drops a height that passes:
    /// at leg height `h = h0 − d` each foot sits at `c + d·u` in the base frame, so the
    /// lateral test is linear in `d` and the reach test `|p + d·u| ≤ limit` quadratic,
    /// each true on one interval of `d`. The check of every height against every stance
    /// of a step's swing then costs one interval per stance instead of one test per
    /// height.
    fn height_window(&self) -> (f64, f64) {
        const WIDEN: f64 = 1e-6;
        let (mut d_lo, mut d_hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for i in 0..4 {
            let c = self.local0[i];
            if self.contact[i] {
                // |c₁ + d·u₁| ≤ M.
                let m = super::kinematics::MAX_LATERAL_MISMATCH_M;
                if self.up[1] == 0.0 {
                    if c[1].abs() > m {
                        return (f64::INFINITY, f64::NEG_INFINITY);
                    }
                } else {
                    let (a, b) = ((-m - c[1]) / self.up[1], (m - c[1]) / self.up[1]);
                    d_lo = d_lo.max(a.min(b));
                    d_hi = d_hi.min(a.max(b));
                }
            }
            // |p + d·u|² ≤ limit²: (u·u) d² + 2 (p·u) d + p·p − limit² ≤ 0.
            let p = [c[0] + self.ankle[0], c[2] + self.ankle[1]];
            let u = [self.up[0], self.up[2]];
            let (qa, qb) = (u[0] * u[0] + u[1] * u[1], p[0] * u[0] + p[1] * u[1]);
            let qc = p[0] * p[0] + p[1] * p[1] - self.limit * self.limit;
            if qa <= 0.0 {
                if qc > 0.0 {
                    return (f64::INFINITY, f64::NEG_INFINITY);
                }
                continue;
            }
            let disc = qb * qb - qa * qc;
            if disc < 0.0 {
                return (f64::INFINITY, f64::NEG_INFINITY);
            }
            let w = disc.sqrt();
            d_lo = d_lo.max((-qb - w) / qa);
            d_hi = d_hi.min((-qb + w) / qa);
        }
        (self.h0 - d_hi - WIDEN, self.h0 - d_lo + WIDEN)
    }

    /// Whether every leg's hip-to-ankle distance at leg height `h` leaves the reach
    /// margin, and every foot in contact lies on its leg plane (as
    /// [`super::kinematics::solve_legs`]), the stance twist within its bound.
    fn distances_ok(&self, h: f64) -> Result<(), PostureError> {
        self.twist.clone()?;
        let d = self.h0 - h;
        for leg in crate::robot::Leg::ALL {
            let i = leg.index();
            let c = [
                self.local0[i][0] + d * self.up[0],
                self.local0[i][1] + d * self.up[1],
                self.local0[i][2] + d * self.up[2],
            ];
            if self.contact[i] && c[1].abs() > super::kinematics::MAX_LATERAL_MISMATCH_M {
                return Err(PostureError::Lateral { leg, offset: c[1] });
            }
            let distance = norm2(c[0] + self.ankle[0], c[2] + self.ankle[1]);
            if distance > self.limit {
                return Err(PostureError::ReachMargin { leg, distance, margin: self.reach_margin });
            }
        }
        Ok(())
    }
}

/// Horizontal CoM estimate of posture `p` for the planner, which has no MuJoCo: the base
/// body (everything but the legs) at its own CoM; per leg the thigh and shin at their
/// midpoints (joint angles from the sagittal IK) and the foot with steering and wheels at
/// the foot. Masses and CoM come from the model. With symmetric segments and the foot
/// hanging vertically (wheel level) this is MuJoCo's CoM in the horizontal plane
/// (`tests/model.rs` checks it to 1 µm). It sees what the base centre misses: the upper
/// body leaning back with a pitched base, and heavy feet stretched behind.
///
/// # Errors
/// [`PostureError`] if a leg cannot reach its foot.
pub fn com_estimate(robot: &RobotDescription, p: &Posture) -> Result<[f64; 2], PostureError> {
    Ok(solved_com_estimate(robot, p, &solve_chains(robot, p, 0.0)?))
}

/// [`com_estimate`] of posture `p` with its legs solved (`legs`, [`solve_chains`] with
/// any reach margin: the chains do not depend on it).
pub fn solved_com_estimate(robot: &RobotDescription, p: &Posture, legs: &SolvedLegs) -> [f64; 2] {
    let c = lumped_com(robot, legs.base_position, &legs.frame.rotation, &legs.chains, &p.feet);
    [c[0], c[1]]
}

/// [`com_estimate`]'s lumped masses as a [`CenterOfMassModel`]: the motion generator's
/// checks, run by the planner without MuJoCo (`motion::manoeuvres`' step and wheel-move
/// checks). The foot mass sits at the wheel axle, which the leg's forward kinematics
/// gives; its height (which only the roll of eqs. 6–8 uses) is the axle's.
#[derive(Debug, Clone, Copy)]
pub struct EstimatedCom<'r> {
    /// The robot's kinematics and masses.
    pub robot: &'r RobotDescription,
}

impl CenterOfMassModel for EstimatedCom<'_> {
    fn com(
        &mut self,
        base_position: [f64; 3],
        base_rpy: [f64; 3],
        legs: &[[f64; 3]; 4],
    ) -> [f64; 3] {
        let r = rotation(base_rpy);
        let rb = self.robot;
        let axles: [[f64; 3]; 4] = std::array::from_fn(|i| {
            let h = rb.hips[i];
            let c = leg_fk(rb, legs[i], base_rpy[1]);
            let contact = apply(&r, base_position, [h[0] + c[0], h[1], h[2] + c[1]]);
            [contact[0], contact[1], contact[2] + rb.wheel_radius]
        });
        let chains = legs.map(|q| {
            let [knee, ankle] = knee_and_ankle(rb, q);
            LegChain { joints: q, knee, ankle }
        });
        lumped_com(rb, base_position, &r, &chains, &axles)
    }

    /// [`Self::com`] from the solved chains: the knees and ankles the IK solved for, and
    /// the axles straight above the contacts it solved them for (where the forward
    /// kinematics of the angles puts them, to rounding).
    fn com_of_solved(&mut self, legs: &SolvedLegs) -> [f64; 3] {
        let rb = self.robot;
        let r = &legs.frame.rotation;
        let axles: [[f64; 3]; 4] = std::array::from_fn(|i| {
            let (h, c) = (rb.hips[i], legs.contacts[i]);
            let contact = apply(r, legs.base_position, [h[0] + c[0], h[1], h[2] + c[2]]);
            [contact[0], contact[1], contact[2] + rb.wheel_radius]
        });
        lumped_com(rb, legs.base_position, r, &legs.chains, &axles)
    }
}

/// The lumped-mass CoM (world, m) of a base at `base_position` rotated by `r`: the body
/// at its CoM, thighs and shins at the midpoints of `chains`, each foot's mass at `feet`.
fn lumped_com(
    robot: &RobotDescription,
    base_position: [f64; 3],
    r: &[[f64; 3]; 3],
    chains: &[LegChain; 4],
    feet: &[[f64; 3]; 4],
) -> [f64; 3] {
    let world = |b: [f64; 3]| apply(r, base_position, b);
    let body = world(robot.body_com);
    let [m_thigh, m_shin, m_foot] = robot.leg_segment_masses;
    let mut c = body.map(|v| robot.body_mass * v);
    let mut total = robot.body_mass;
    for (i, chain) in chains.iter().enumerate() {
        let h = robot.hips[i];
        let LegChain { knee, ankle, .. } = *chain;
        let thigh = world([h[0] + knee[0] / 2.0, h[1], h[2] + knee[1] / 2.0]);
        let shin =
            world([h[0] + (knee[0] + ankle[0]) / 2.0, h[1], h[2] + (knee[1] + ankle[1]) / 2.0]);
        for (m, x) in [(m_thigh, thigh), (m_shin, shin), (m_foot, feet[i])] {
            for k in 0..3 {
                c[k] += m * x[k];
            }
            total += m;
        }
    }
    if total <= 0.0 {
        return base_position;
    }
    c.map(|v| v / total)
}

/// The posture with the base at `xy`, `rpy` and the height of [`base_z`]; feet not in
/// `contact` are moved onto their legs' planes (same base-frame x' and z').
pub fn level_posture(
    robot: &RobotDescription,
    feet: [[f64; 3]; 4],
    contact: [bool; 4],
    xy: [f64; 2],
    rpy: [f64; 3],
    height: f64,
    ground: [f64; 4],
) -> Posture {
    level_posture_in(robot, feet, contact, xy, &BaseFrame::new(rpy), height, ground)
}

/// [`level_posture`] with the base frame given.
fn level_posture_in(
    robot: &RobotDescription,
    feet: [[f64; 3]; 4],
    contact: [bool; 4],
    xy: [f64; 2],
    frame: &BaseFrame,
    height: f64,
    ground: [f64; 4],
) -> Posture {
    let r = &frame.rotation;
    let z = base_z_in(robot, &ground, r, height);
    let mut p = Posture { base_position: [xy[0], xy[1], z], base_rpy: frame.rpy, feet, contact };
    if contact.iter().any(|c| !c) {
        let local = contacts_in(robot, r, &p);
        for i in 0..4 {
            if !contact[i] {
                let h = robot.hips[i];
                p.feet[i] =
                    apply(r, p.base_position, [local[i][0] + h[0], h[1], local[i][2] + h[2]]);
            }
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::posture::kinematics::{base_z, solve_legs};
    use std::f64::consts::FRAC_PI_2;

    fn rule() -> StandingRule {
        StandingRule::from_params(&Params::default())
    }

    /// A 0.2 m platform from x = 0.2 m on, 2.5 cm cells over [−2, 2]².
    fn platform() -> HeightMap {
        HeightMap::from_fn([-2.0, -2.0], 0.025, 160, 160, |i, _| {
            if -2.0 + (i as f64 + 0.5) * 0.025 >= 0.2 { 0.2 } else { 0.0 }
        })
        .unwrap()
    }

    #[test]
    fn a_swing_clears_what_the_wheels_pass_not_a_disc_around_the_foot() {
        // A tread at 0.17 m from x = 0 to 0.29, the next at 0.34 m beyond; a 0.40 m post
        // at y from 0.125 to 0.15, x from −0.6 to −0.5. A foot carried along +x from (−0.16, 0) to
        // (0.1625, 0) onto the tread: its wheels (spheres of 0.08 m at y = ±0.06) swept
        // with 2 cm to spare reach x = 0.2625, short of the next riser (0.29), so the
        // swing is 0.17 + 0.05. The disc of the pair's radius (0.16 m) reached 0.3225 and
        // carried the foot over the next step (0.39), out of reach for the leg.
        let robot = RobotDescription::reference();
        let map = HeightMap::from_fn([-1.0, -1.0], 0.025, 80, 80, |i, j| {
            let (x, y) = (-1.0 + (i as f64 + 0.5) * 0.025, -1.0 + (j as f64 + 0.5) * 0.025);
            if (0.125..0.15).contains(&y) && (-0.6..-0.5).contains(&x) {
                0.4
            } else if x >= 0.29 {
                0.34
            } else if x >= 0.0 {
                0.17
            } else {
                0.0
            }
        })
        .unwrap();
        let rule = rule();
        let (a, b) = ([-0.16, 0.0, 0.0], [0.1625, 0.0, 0.17]);
        assert!((rule.swing_z(&robot, &map, a, b, 0.0) - 0.22).abs() < 1e-9);
        // Heading along y, the same path passes the wheels sideways: the riser, 0.1275 m
        // from the foothold, is under a wheel's 0.10 m reach (0.06 + 0.10 across).
        assert!((rule.swing_z(&robot, &map, a, b, FRAC_PI_2) - 0.39).abs() < 1e-9);
        // Past the post: its cells' centres (y = 0.1375) lie 0.0775 m from the
        // left wheel's path (y = 0.06), inside 0.10: carried over it.
        let (a, b) = ([-0.8, 0.0, 0.0], [-0.3, 0.0, 0.0]);
        assert!((rule.swing_z(&robot, &map, a, b, 0.0) - 0.45).abs() < 1e-9);
    }

    #[test]
    fn heights_run_from_the_soft_constraint_to_driving_height() {
        let h: Vec<f64> = rule().heights().collect();
        assert_eq!(h.len(), 19);
        assert!((h[0] - 0.45).abs() < 1e-12 && (h[18] - 0.27).abs() < 1e-9);
    }

    #[test]
    fn base_height_follows_the_highest_foot_by_hand() {
        // Level base, feet on 0 except FL on 0.2: the FL hip (0.05 m below the origin)
        // stands 0.45 above 0.2, so the origin is at 0.2 + 0.45 + 0.05.
        let robot = RobotDescription::reference();
        let z = base_z(&robot, &[0.2, 0.0, 0.0, 0.0], [0.0; 3], 0.45);
        assert!((z - 0.7).abs() < 1e-12);
        // Pitched nose up by a (negative pitch): the front hips rise by 0.35·sin a, so the
        // highest ground's hip needs less origin height.
        let a = 0.1f64;
        let z = base_z(&robot, &[0.2, 0.2, 0.0, 0.0], [0.0, -a, 0.0], 0.45);
        let front_hip_dz = -(-a).sin() * 0.35 + (-a).cos() * -0.05;
        assert!((z - (0.65 - front_hip_dz)).abs() < 1e-12);
    }

    #[test]
    fn stand_lowers_until_the_long_leg_reaches() {
        // Front feet 0.2 m up, rear feet 0.36 m behind their hips: at 0.45 the rear legs
        // (about 0.57 m) cannot reach 0.36 m back; a lower height can.
        let robot = RobotDescription::reference();
        let feet = [[0.35, 0.32, 0.2], [0.35, -0.32, 0.2], [-0.71, 0.32, 0.0], [-0.71, -0.32, 0.0]];
        let (p, h) = rule().stand(&robot, &platform(), feet, [0.0, 0.0], 0.0).unwrap();
        assert!(h < 0.45 - 1e-9, "height {h}");
        let spare = rule().reach_margin_m;
        assert!(solve_legs(&robot, &p, spare).is_ok());
        // The leg height one step above fails.
        let above = level_posture(
            &robot,
            feet,
            [true; 4],
            [0.0, 0.0],
            p.base_rpy,
            h + 0.01,
            feet.map(|f| f[2]),
        );
        assert!(solve_legs(&robot, &above, spare).is_err());
        // Far out of reach: a clear error.
        let far = [[0.35, 0.32, 0.0], [0.35, -0.32, 0.0], [-1.2, 0.32, 0.0], [-0.35, -0.32, 0.0]];
        assert!(rule().stand(&robot, &platform(), far, [0.0, 0.0], 0.0).is_err());
    }

    #[test]
    fn a_rear_step_up_counts_the_higher_ground() {
        let robot = RobotDescription::reference();
        let r = rule();
        // Front feet on a 0.2 m platform, rear feet under their hips on the floor; the
        // rear-left foot steps 0.3 m forward onto the platform.
        let pre = [[0.35, 0.32, 0.2], [0.35, -0.32, 0.2], [-0.35, 0.32, 0.0], [-0.35, -0.32, 0.0]];
        let map = platform();
        let heights_for = |feet| {
            r.step_heights(&robot, &map, &map, feet, 2, [-0.05, 0.32, 0.2], [0.0, 0.0], 0.0)
                .collect::<Vec<_>>()
        };
        let hs = heights_for(pre);
        assert!(!hs.is_empty());
        // Every height listed really reaches with the stepping leg over 0.2 m…
        let mut post = pre;
        post[2] = [-0.05, 0.32, 0.2];
        let pitch = r.step_pitch(&pre, &post, 0.0);
        for &h in &hs {
            let p = level_posture(
                &robot,
                pre,
                [true; 4],
                [0.0, 0.0],
                [0.0, pitch, 0.0],
                h,
                [0.2, 0.2, 0.2, 0.0],
            );
            assert!(solve_legs(&robot, &p, 0.002).is_ok());
        }
        // …and with the other rear foot 0.4 m behind its hip no height does.
        let mut stretched = pre;
        stretched[3][0] = -0.75;
        let hs = heights_for(stretched);
        assert!(hs.is_empty(), "{hs:?}");
    }

    #[test]
    fn the_reach_probe_agrees_with_the_leg_solver() {
        // Over a grid of rear-foot offsets, platform heights and leg heights, the cheap
        // distance check fails exactly when solve_legs reports a reach or lateral error.
        let robot = RobotDescription::reference();
        let r = rule();
        let (mut checked, mut unreachable) = (0, 0);
        for rear_dx in [-0.45, -0.3, -0.1, 0.0, 0.2] {
            for up in [0.0, 0.1, 0.2, 0.3] {
                let feet = [
                    [0.4, 0.32, up],
                    [0.35, -0.32, up],
                    [-0.35 + rear_dx, 0.32, 0.0],
                    [-0.35, -0.32, 0.0],
                ];
                let ground = feet.map(|f| f[2]);
                let rpy = [0.0, r.pitch(&feet, 0.3), 0.3];
                let frame = BaseFrame::new(rpy);
                let (s3, c3) = 0.3f64.sin_cos();
                let world = feet.map(|f| [c3 * f[0] - s3 * f[1], s3 * f[0] + c3 * f[1], f[2]]);
                let probe =
                    ReachProbe::new(&robot, &world, [true; 4], [0.0, 0.0], &frame, &ground, &r);
                // The analytic window holds every height that passes (checked on a
                // 1 mm grid, through and past the rule's heights) and nothing 2 µm
                // inside its ends fails.
                let (lo, hi) = probe.height_window();
                for k in 0..=700 {
                    let h = f64::from(k) * 1e-3;
                    if probe.distances_ok(h).is_ok() {
                        assert!((lo..=hi).contains(&h), "{rear_dx} {up} {h}: [{lo}, {hi}]");
                    } else {
                        assert!(!(lo + 2e-6..=hi - 2e-6).contains(&h), "{rear_dx} {up} {h}");
                    }
                }
                for h in r.heights() {
                    let p = level_posture(&robot, world, [true; 4], [0.0, 0.0], rpy, h, ground);
                    let full = solve_legs(&robot, &p, r.reach_margin_m);
                    let geometric = matches!(
                        full,
                        Err(PostureError::ReachMargin { .. }
                            | PostureError::Lateral { .. }
                            | PostureError::Twist { .. })
                    );
                    assert_eq!(probe.distances_ok(h).is_err(), geometric, "{rear_dx} {up} {h}");
                    checked += 1;
                    unreachable += usize::from(geometric);
                }
            }
        }
        assert_eq!(checked, 5 * 4 * 19);
        assert!(unreachable > 20 && unreachable < checked - 20, "{unreachable} of {checked}");
    }

    #[test]
    fn com_estimate_matches_mujoco_lumped_by_hand() {
        // Level base, feet under the hips 0.45 m down: every leg's chain is symmetric
        // front to rear (knees toward the centre), so only the body's x' = 0.04/34 and
        // the legs' mirror images remain: CoM x = 34 · (0.04/34) / 58.
        let robot = RobotDescription::reference();
        let feet = robot.hips.map(|h| [h[0], h[1], h[2] - 0.45]);
        let p = Posture { base_position: [0.0; 3], base_rpy: [0.0; 3], feet, contact: [true; 4] };
        let c = com_estimate(&robot, &p).unwrap();
        assert!((c[0] - 0.04 / 58.0).abs() < 1e-12 && c[1].abs() < 1e-12, "{c:?}");
        // A rear foot 0.2 m further back moves its 2.7 kg foot by 0.2 m, and its thigh and
        // shin somewhere between: the CoM moves back by more than 2.7 · 0.2 / 58.
        let mut q = p;
        q.feet[2][0] -= 0.2;
        let back = c[0] - com_estimate(&robot, &q).unwrap()[0];
        assert!(back > 2.7 * 0.2 / 58.0 && back < 6.0 * 0.2 / 58.0, "{back}");
        // Out of reach: an error, not a guess.
        q.feet[2][0] -= 1.0;
        assert!(com_estimate(&robot, &q).is_err());
    }

    #[test]
    fn the_estimate_from_solved_legs_is_the_estimate_from_angles() {
        // Level base, feet under the hips 0.45 m down: by hand (as above) the lumped CoM
        // lies at x = 0.04/58, whether from the solved chains or the angles.
        let robot = RobotDescription::reference();
        let feet = robot.hips.map(|h| [h[0], h[1], h[2] - 0.45]);
        let p = Posture { base_position: [0.0; 3], base_rpy: [0.0; 3], feet, contact: [true; 4] };
        let legs = solve_chains(&robot, &p, 0.002).unwrap();
        let c = solved_com_estimate(&robot, &p, &legs);
        assert!((c[0] - 0.04 / 58.0).abs() < 1e-12 && c[1].abs() < 1e-12, "{c:?}");
        // Over pitched, rolled, turned postures with a foot stretched back: the model's
        // CoM from the chains is the one from the angles (knees, ankles and axles by the
        // forward kinematics) to rounding.
        let mut model = EstimatedCom { robot: &robot };
        for (k, rpy) in [[0.0, 0.0, 0.0], [0.03, -0.2, 0.5], [-0.05, 0.25, -2.0]].iter().enumerate()
        {
            let mut q = p;
            q.base_position = [0.4, -0.3, 0.2];
            q.base_rpy = *rpy;
            let r = rotation(*rpy);
            let local = robot.hips.map(|h| [h[0] - 0.05 * k as f64, h[1], h[2] - 0.4]);
            q.feet = local.map(|b| apply(&r, q.base_position, b));
            q.feet[2] = apply(&r, q.base_position, [-0.6, 0.32, -0.4]);
            let legs = solve_chains(&robot, &q, 0.002).unwrap();
            let from_chains = model.com_of_solved(&legs);
            let from_angles = model.com(q.base_position, q.base_rpy, &legs.joints());
            for i in 0..3 {
                assert!((from_chains[i] - from_angles[i]).abs() < 1e-12, "{from_chains:?}");
            }
            let c = solved_com_estimate(&robot, &q, &legs);
            assert_eq!(c, com_estimate(&robot, &q).unwrap());
        }
    }

    #[test]
    fn base_z_in_a_given_frame() {
        // Pitched nose down by 0.1: the front hips (0.35 m ahead, 0.05 m below the
        // origin) sink by 0.35·sin 0.1, so over ground 0 everywhere they set the height.
        let robot = RobotDescription::reference();
        let rpy = [0.0, 0.1, 0.0];
        let z = base_z_in(&robot, &[0.0; 4], &rotation(rpy), 0.45);
        let front = 0.35 * -(0.1f64.sin()) - 0.05 * 0.1f64.cos();
        assert!((z - (0.45 - front)).abs() < 1e-12, "{z}");
        assert_eq!(z, base_z(&robot, &[0.0; 4], rpy, 0.45));
    }

    #[test]
    fn standing_clear_of_wider_terrain_is_standing_then_checking_it() {
        // Blocks of 0.05–0.3 m on a 2.5 cm grid; feet on the ground under a neutral
        // footprint stretched by up to ±0.15 m, over a grid of poses and yaws: the
        // posture, height and verdict are those of `stand` followed by `legs_clear` on the
        // wider terrain, errors included.
        let robot = RobotDescription::reference();
        let r = rule();
        let heights = HeightMap::from_fn([-1.5, -1.5], 0.025, 120, 120, |i, j| {
            let (bi, bj) = (i / 10, j / 10);
            match (bi * 7 + bj * 13) % 5 {
                0 => 0.05 * ((bi + bj) % 6) as f64,
                _ => 0.0,
            }
        })
        .unwrap();
        let plain = heights.dilated_max(crate::cost::LEG_TERRAIN_CELLS);
        let wider = heights.dilated_max(crate::cost::LEG_TERRAIN_CELLS + crate::cost::SWEEP_CELLS);
        let neutral = robot.neutral_footprint();
        let mut seen = [0usize; 3];
        for n in 0..600 {
            let (x, y) = (-0.5 + 0.1 * (n % 11) as f64, -0.5 + 0.1 * ((n / 11) % 11) as f64);
            let yaw = 0.7 * (n % 9) as f64;
            let stretch = 0.05 * ((n % 7) as f64 - 3.0);
            let (sn, cs) = yaw.sin_cos();
            let feet: [[f64; 3]; 4] = std::array::from_fn(|k| {
                let (fx, fy) = (neutral[k][0] + if k < 2 { stretch } else { 0.0 }, neutral[k][1]);
                let (wx, wy) = (x + cs * fx - sn * fy, y + sn * fx + cs * fy);
                [wx, wy, heights.height_at_cell(wx, wy).unwrap()]
            });
            let both = r.stand_clear_of(&robot, &plain, &wider, feet, [x, y], yaw);
            let apart = r.stand(&robot, &plain, feet, [x, y], yaw).map(|(p, h)| {
                let legs = solve_chains(&robot, &p, r.reach_margin_m).unwrap();
                (p, h, r.legs_clear(&robot, &wider, &legs).is_ok())
            });
            match (both, apart) {
                (Ok((p, h, clear)), Ok((q, g, also))) => {
                    assert_eq!((p, h, clear), (q, g, also), "case {n}");
                    seen[usize::from(clear)] += 1;
                }
                (Err(e), Err(f)) => {
                    assert_eq!(e, f, "case {n}");
                    seen[2] += 1;
                }
                (a, b) => panic!("case {n}: {a:?} against {b:?}"),
            }
        }
        // Every branch was taken.
        assert!(seen.iter().all(|&c| c > 0), "{seen:?}");
    }

    #[test]
    fn a_knee_in_the_platform_is_a_collision() {
        // Rear legs on the floor with the platform edge 0.1 m ahead of the rear hips: the
        // rear knees point forward, over the platform. Standing tall they clear it; with
        // the base low (hips 0.27 m up) the knees dip below 0.2 + 0.04 m.
        let robot = RobotDescription::reference();
        let r = rule();
        let hm = HeightMap::from_fn([-2.0, -2.0], 0.025, 160, 160, |i, _| {
            if -2.0 + (i as f64 + 0.5) * 0.025 >= -0.25 { 0.2 } else { 0.0 }
        })
        .unwrap();
        let feet = [[0.35, 0.32, 0.2], [0.35, -0.32, 0.2], [-0.35, 0.32, 0.0], [-0.35, -0.32, 0.0]];
        let ground = feet.map(|f| f[2]);
        let pose =
            |h: f64| level_posture(&robot, feet, [true; 4], [0.0, 0.0], [0.0, 0.0, 0.0], h, ground);
        let low = pose(0.27);
        let legs = solve_chains(&robot, &low, 0.0).unwrap();
        let hm = hm.dilated_max(crate::cost::LEG_TERRAIN_CELLS);
        match r.legs_clear(&robot, &hm, &legs) {
            Err(PostureError::LegCollision { leg, clearance }) => {
                assert!(!leg.is_front() && clearance < 0.04, "{leg:?} {clearance}");
            }
            other => panic!("expected a collision, got {other:?}"),
        }
        let tall = pose(0.45);
        let legs = solve_chains(&robot, &tall, 0.0).unwrap();
        assert!(r.legs_clear(&robot, &hm, &legs).is_ok());
    }
}
