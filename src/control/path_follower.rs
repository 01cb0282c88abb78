//! The driving controller of Sec. IX: it follows a planned driving path by "computing a
//! B-spline through the next five driving poses" and aiming "towards a pose p = (p_x, p_y,
//! p_θ) on this B-spline in front of the robot", producing the omnidirectional velocity
//! command w = (v_x', v_y', ω) in the robot frame.
//!
//! **How it fits.** The closed-loop run creates one [`PathFollower`] per driving path (a
//! `Vec<Pose2>` densified to about 2.5 cm, with turns on the spot as runs of poses sharing
//! one position) and calls [`PathFollower::update`] every 10 ms control tick with the
//! measured base pose. The returned [`Twist`] goes to the wheel kinematics
//! ([`super::wheels`]); the tracking errors in [`FollowerOutput`] are for logging.
//!
//! **One tick.**
//! 1. *Progress.* The index of the path pose closest to the robot in the metric
//!    √(dx² + dy² + (ρ_p·Δθ)²), ρ_p = `projection_rotation_radius_m` (small: positions
//!    decide, headings tell apart the poses of a turn on the spot), is searched from the
//!    current index forward, inside a window (`progress_window_m` of pose-metric length,
//!    see [`super::bspline`]) that ends before the next *stop* (see below) until the robot
//!    has reached that stop. The index only grows, so the robot never skips unreached
//!    parts of the path.
//! 2. *Spline.* Five poses from the path: the reached pose and the first poses at least
//!    1, 2, 3, 4 × `spline_span_m`/4 further along (pose metric), cut at the next stop.
//!    The paper's "next five driving poses" are lattice poses; at our 2.5 cm spacing five
//!    consecutive poses would span only 10 cm, less than the lookahead, so they are spread
//!    over `spline_span_m` (default twice the lookahead: the aim point then lies in the
//!    middle of the spline, away from its clamped ends). See [`super::bspline`].
//! 3. *Aim.* The robot is projected onto the spline; the aim pose p lies `lookahead_m`
//!    further along (pose metric, so while turning on the spot the aim runs ahead in θ).
//! 4. *Command.* The linear velocity points from the robot towards p's position — more
//!    exactly along (p − c) + g·(c − robot), c the projection, g = `cross_track_gain`:
//!    g = 1 is plain aiming at p, g > 1 pulls harder towards the spline so that arcs are
//!    not cut by the chord to p. It is expressed in the robot frame: the robot drives
//!    omnidirectionally and its heading follows the poses' θ, not the direction of travel
//!    (a path behind the robot with poses facing forward is driven backwards). Its
//!    magnitude is the least of v_max, a braking profile to the speed allowed further on
//!    (zero at stops, lower at corners and where the path turns fast), a proportional term
//!    near the aim point, and a reduction for large heading errors. ω follows the heading
//!    error to p with a braking profile. Finally both are rate limited against the
//!    previous command (a_max, α_max).
//!
//! **Stops** are the goal, sharp corners (the direction of travel changes by at least
//! `corner_stop_min_rad`, cusps included) and the start and end of a turn on the spot of
//! at least `turn_in_place_min_rad`. The robot brakes to a standstill at a stop, and only
//! once it is there (within half the goal tolerances, or within them for `goal_dwell_s`)
//! does the next stretch begin: at the start of a turn it turns in place to the end's
//! heading, then drives on. Progress windows and splines end at the next stop, so the
//! robot neither turns early nor cuts a stop. Smaller turns on the spot (the lattice
//! planner emits single 2π/64 turns between moves) and corners are blended into the drive
//! by the spline, at a speed capped for them.
//!
//! **Goal.** The goal is the last stop: once it is reached the command ramps down to zero
//! ([`FollowerStatus::Settling`]) and the follower then reports
//! [`FollowerStatus::Finished`]; pushed out to twice the tolerances, it resumes. Aiming at
//! half the tolerance leaves room inside it for braking and measurement noise.
//!
//! Everything is deterministic: no clocks, no randomness, no hashing.

use super::bspline::PoseSpline;
use super::wheels::Twist;
use crate::geometry::{Pose2, wrap_angle};
use serde::{Deserialize, Serialize};

/// Poses in the spline of each tick (Sec. IX: "the next five driving poses").
pub const SPLINE_POSES: usize = 5;

/// Consecutive poses closer than this (m) share a position: the step is a turn on the spot.
const STATIONARY_EPS_M: f64 = 1e-4;

/// Share of ω_max the speed caps plan for following the path's own turning; the rest is
/// left for correcting heading errors.
const ROTATION_SPEED_SHARE: f64 = 0.8;

/// Tuning of the path follower. `Default` gives the documented values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FollowerConfig {
    /// Maximum linear speed |(v_x', v_y')|, m/s. Default 0.5.
    pub v_max: f64,
    /// Maximum yaw rate |ω|, rad/s. Default 0.8.
    pub omega_max: f64,
    /// Maximum linear acceleration (norm of the change of (v_x', v_y') per second), m/s².
    /// Default 0.5.
    pub a_max: f64,
    /// Maximum angular acceleration, rad/s². Default 1.0.
    pub alpha_max: f64,
    /// Distance from the robot's projection to the aim pose along the spline (pose
    /// metric), m. Default 0.25.
    pub lookahead_m: f64,
    /// Pose-metric length of path the five spline poses cover, m. Default 0.5 (twice the
    /// lookahead, so the aim is mid-spline).
    pub spline_span_m: f64,
    /// Rotation radius ρ of the pose metric: turning by 1 rad counts as driving ρ metres.
    /// Default 0.4 m, about the distance of the wheel pairs from the base centre, so a turn
    /// counts as far as the wheels roll.
    pub rotation_radius_m: f64,
    /// Rotation radius of the metric for the closest path pose and the closest spline
    /// point, m. Default 0.05: small, so positions decide and headings only tell apart
    /// the poses of a turn on the spot (with ρ a robot whose heading leads the path's
    /// would be projected ahead of where it is).
    pub projection_rotation_radius_m: f64,
    /// How far ahead of the current progress index (pose metric) the closest path pose is
    /// searched, m. Default 0.5.
    pub progress_window_m: f64,
    /// A turn on the spot of at least this angle is a stop: the robot halts, turns in
    /// place, then drives on. Smaller ones are blended into the drive. Default 0.35 rad
    /// (20°: the planner's single 2π/64 turns and runs of up to three blend).
    pub turn_in_place_min_rad: f64,
    /// A change of the direction of travel of at least this angle between consecutive
    /// moves (cusps included) is a stop: the robot halts at the corner instead of cutting
    /// it. Smaller corners are rounded by the spline at a reduced speed. Default π/3 (60°:
    /// neighbouring move directions of the 16-neighbourhood lattice differ by 18°–27°, so
    /// a path bends this much only where it really turns a corner).
    pub corner_stop_min_rad: f64,
    /// Proportional gain from the remaining distance (to the next stop, or to the aim
    /// point) to the linear speed, 1/s. Default 3.0.
    pub position_gain: f64,
    /// Proportional gain from the heading error to ω, 1/s. Default 3.0.
    pub heading_gain: f64,
    /// Weight g of the pull back onto the spline in the direction of travel
    /// (p − c) + g·(c − robot) (dimensionless; 1 = aim straight at p). Pure aiming cuts an
    /// arc of radius R by about L²/(2R); g divides that. Default 3.0.
    pub cross_track_gain: f64,
    /// Share of a_max and α_max the braking profiles plan with. Default 0.5: then the
    /// proportional tails (decelerating at gain × speed ≤ 2·share·limit) also respect the
    /// limits, and the rest is margin for the rate limiter.
    pub brake_fraction: f64,
    /// Heading error (to the path pose at the robot's projection) above which the linear
    /// speed is reduced, rad. Default 0.15.
    pub heading_slowdown_start_rad: f64,
    /// Heading error at which the linear speed reaches zero (turn first), rad. Default 0.6.
    pub heading_slowdown_stop_rad: f64,
    /// Goal position tolerance, m; half of it is aimed at, at the goal and at every stop.
    /// Default 0.02.
    pub goal_position_tolerance_m: f64,
    /// Goal heading tolerance, rad. Default 2°.
    pub goal_heading_tolerance_rad: f64,
    /// Time within the goal tolerances of a stop or the goal (but not half of them) after
    /// which it counts as reached anyway, s. Default 1.0.
    pub goal_dwell_s: f64,
}

impl Default for FollowerConfig {
    fn default() -> Self {
        Self {
            v_max: 0.5,
            omega_max: 0.8,
            a_max: 0.5,
            alpha_max: 1.0,
            lookahead_m: 0.25,
            spline_span_m: 0.5,
            rotation_radius_m: 0.4,
            projection_rotation_radius_m: 0.05,
            progress_window_m: 0.5,
            turn_in_place_min_rad: 0.35,
            corner_stop_min_rad: std::f64::consts::FRAC_PI_3,
            position_gain: 3.0,
            heading_gain: 3.0,
            cross_track_gain: 3.0,
            brake_fraction: 0.5,
            heading_slowdown_start_rad: 0.15,
            heading_slowdown_stop_rad: 0.6,
            goal_position_tolerance_m: 0.02,
            goal_heading_tolerance_rad: 2f64.to_radians(),
            goal_dwell_s: 1.0,
        }
    }
}

impl FollowerConfig {
    /// Checks that every value is finite and positive (ρ may be zero) and the two
    /// heading-slowdown angles are ordered.
    ///
    /// # Errors
    /// [`FollowerError::InvalidConfig`] naming the first bad field.
    pub fn validate(&self) -> Result<(), FollowerError> {
        let positive = [
            ("v_max", self.v_max),
            ("omega_max", self.omega_max),
            ("a_max", self.a_max),
            ("alpha_max", self.alpha_max),
            ("lookahead_m", self.lookahead_m),
            ("spline_span_m", self.spline_span_m),
            ("progress_window_m", self.progress_window_m),
            ("turn_in_place_min_rad", self.turn_in_place_min_rad),
            ("corner_stop_min_rad", self.corner_stop_min_rad),
            ("position_gain", self.position_gain),
            ("heading_gain", self.heading_gain),
            ("cross_track_gain", self.cross_track_gain),
            ("brake_fraction", self.brake_fraction),
            ("heading_slowdown_stop_rad", self.heading_slowdown_stop_rad),
            ("goal_position_tolerance_m", self.goal_position_tolerance_m),
            ("goal_heading_tolerance_rad", self.goal_heading_tolerance_rad),
            ("goal_dwell_s", self.goal_dwell_s),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(FollowerError::InvalidConfig {
                    name,
                    value,
                    reason: "must be a finite number > 0",
                });
            }
        }
        let non_negative = [
            ("rotation_radius_m", self.rotation_radius_m),
            ("projection_rotation_radius_m", self.projection_rotation_radius_m),
            ("heading_slowdown_start_rad", self.heading_slowdown_start_rad),
        ];
        for (name, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(FollowerError::InvalidConfig {
                    name,
                    value,
                    reason: "must be a finite number >= 0",
                });
            }
        }
        if self.corner_stop_min_rad > std::f64::consts::PI {
            return Err(FollowerError::InvalidConfig {
                name: "corner_stop_min_rad",
                value: self.corner_stop_min_rad,
                reason: "must be <= π",
            });
        }
        if self.brake_fraction > 1.0 {
            return Err(FollowerError::InvalidConfig {
                name: "brake_fraction",
                value: self.brake_fraction,
                reason: "must be <= 1",
            });
        }
        if self.heading_slowdown_start_rad >= self.heading_slowdown_stop_rad {
            return Err(FollowerError::InvalidConfig {
                name: "heading_slowdown_start_rad",
                value: self.heading_slowdown_start_rad,
                reason: "must be < heading_slowdown_stop_rad",
            });
        }
        Ok(())
    }
}

/// Why a follower could not be created.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FollowerError {
    /// The path has no poses.
    #[error("the driving path is empty")]
    EmptyPath,
    /// A path pose has a NaN or infinite component.
    #[error("driving path pose {index} is not finite")]
    NonFinitePose {
        /// Index of the offending pose.
        index: usize,
    },
    /// A configuration value is out of range.
    #[error("follower parameter `{name}` = {value} is invalid: {reason}")]
    InvalidConfig {
        /// Field name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// What a valid value looks like.
        reason: &'static str,
    },
}

/// What the follower is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FollowerStatus {
    /// Following the path.
    #[default]
    Tracking,
    /// Inside the goal tolerances, ramping the command down to zero.
    Settling,
    /// Standing still inside the goal tolerances.
    Finished,
    /// The measured pose or the time step was not finite (or dt ≤ 0): the command ramps
    /// down to zero (or, without a usable dt, is repeated) and progress is unchanged.
    InvalidInput,
}

/// The result of one control tick.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct FollowerOutput {
    /// Velocity command in the robot frame, after the speed and acceleration limits.
    pub twist: Twist,
    /// What the follower is doing.
    pub status: FollowerStatus,
    /// Signed distance of the robot from the spline, m; positive when the robot is left of
    /// the direction of travel (left of the path pose's heading during a turn on the spot).
    pub cross_track_m: f64,
    /// Heading error wrap(θ_path − θ_robot) at the robot's projection onto the spline, rad.
    pub heading_error_rad: f64,
    /// Index of the path pose reached so far (monotone).
    pub progress_index: usize,
    /// The robot's projection onto the spline.
    pub closest: Pose2,
    /// The aim pose p on the spline.
    pub aim: Pose2,
    /// Linear speed allowed this tick before the rate limiter, m/s.
    pub speed_limit: f64,
    /// Euclidean distance from the robot to the goal pose, m.
    pub distance_to_goal_m: f64,
    /// wrap(θ_goal − θ_robot), rad.
    pub goal_heading_error_rad: f64,
}

/// Follows one driving path (see the module docs).
#[derive(Debug, Clone)]
pub struct PathFollower {
    config: FollowerConfig,
    path: Vec<Pose2>,
    /// Cumulative pose-metric length along the path, m.
    cum_metric: Vec<f64>,
    /// Stop indices (goal, sharp corners, starts and ends of big turns on the spot), ascending;
    /// always ends with the last index.
    stops: Vec<usize>,
    /// Linear speed allowed on reaching each pose (braking already propagated back), m/s.
    allowed: Vec<f64>,
    progress: usize,
    arrived: bool,
    /// Time spent within the goal tolerances of the next stop, s.
    in_tolerance_s: f64,
    last: FollowerOutput,
    spline: Option<PoseSpline>,
}

impl PathFollower {
    /// A follower for `path` (at least one pose; the first is normally the robot's start
    /// pose). The path is analysed once here: stops, corner and turning speed caps, and
    /// the braking profile between them.
    ///
    /// # Errors
    /// [`FollowerError`] for an empty path, a non-finite pose or an invalid config.
    pub fn new(path: Vec<Pose2>, config: FollowerConfig) -> Result<Self, FollowerError> {
        config.validate()?;
        if path.is_empty() {
            return Err(FollowerError::EmptyPath);
        }
        if let Some(index) =
            path.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()))
        {
            return Err(FollowerError::NonFinitePose { index });
        }
        let n = path.len();
        let rho = config.rotation_radius_m;
        let mut cum_len = vec![0.0; n];
        let mut cum_metric = vec![0.0; n];
        // θ unwrapped along the path, for net turning over a stretch.
        let mut theta = vec![path[0].theta; n];
        for i in 1..n {
            let (a, b) = (path[i - 1], path[i]);
            let dth = wrap_angle(b.theta - a.theta);
            let d = a.distance(&b);
            cum_len[i] = cum_len[i - 1] + d;
            cum_metric[i] = cum_metric[i - 1] + d.hypot(rho * dth);
            theta[i] = theta[i - 1] + dth;
        }
        let moving = |i: usize| path[i].distance(&path[i + 1]) >= STATIONARY_EPS_M;

        let mut cap = vec![config.v_max; n];
        let mut stops = Vec::new();
        // Turns on the spot: maximal runs of stationary steps.
        let mut i = 0;
        while i + 1 < n {
            if moving(i) {
                i += 1;
                continue;
            }
            let start = i;
            while i + 1 < n && !moving(i) {
                i += 1;
            }
            // Poses start..=i share a position.
            if (theta[i] - theta[start]).abs() >= config.turn_in_place_min_rad {
                // Stop where the turn starts and where it ends: the spline of the turn then
                // ends at the turn's final heading, so the robot turns fully in place and
                // only then aims along the next stretch.
                stops.extend([start, i]);
                cap[start..=i].fill(0.0);
            }
        }
        // Sharp corners and cusps: consecutive moving steps (across any turn on the spot
        // between them) whose directions differ by at least `corner_stop_min_rad`: the robot
        // stops where the first ends and sets off along the second, instead of cutting the
        // corner.
        let cos_stop = config.corner_stop_min_rad.cos();
        let mut prev: Option<([f64; 2], usize)> = None;
        for i in 0..n.saturating_sub(1) {
            if !moving(i) {
                continue;
            }
            let d = path[i].distance(&path[i + 1]);
            let dir = [(path[i + 1].x - path[i].x) / d, (path[i + 1].y - path[i].y) / d];
            if let Some((pd, end)) = prev
                && pd[0] * dir[0] + pd[1] * dir[1] <= cos_stop
            {
                stops.push(end);
                cap[end..=i].fill(0.0);
            }
            prev = Some((dir, i + 1));
        }
        stops.push(n - 1);
        stops.sort_unstable();
        stops.dedup();
        cap[n - 1] = 0.0;

        // Corner and turning caps over a window of one spline spacing either side (the
        // spline smooths the lattice path's zig-zags over about that distance), not
        // reaching past a stop: what lies beyond one is handled by stopping there.
        let spacing = config.spline_span_m / (SPLINE_POSES - 1) as f64;
        for i in 0..n {
            let lo = stops.partition_point(|&t| t <= i).checked_sub(1).map_or(0, |j| stops[j]);
            let hi = stops[stops.partition_point(|&t| t < i).min(stops.len() - 1)];
            let mut back = i;
            while back > lo && cum_len[i] - cum_len[back] < spacing {
                back -= 1;
            }
            let mut fwd = i;
            while fwd < hi && cum_len[fwd] - cum_len[i] < spacing {
                fwd += 1;
            }
            let (b, p, f) = (path[back], path[i], path[fwd]);
            let din = [p.x - b.x, p.y - b.y];
            let dout = [f.x - p.x, f.y - p.y];
            let (lin, lout) = (din[0].hypot(din[1]), dout[0].hypot(dout[1]));
            if lin > STATIONARY_EPS_M && lout > STATIONARY_EPS_M {
                let cos = ((din[0] * dout[0] + din[1] * dout[1]) / (lin * lout)).clamp(-1.0, 1.0);
                let half_sin = (0.5 * (1.0 - cos)).sqrt(); // sin(Δφ/2)
                if half_sin > 1e-9 {
                    // Turning the velocity vector by Δφ at speed v changes it by 2v·sin(Δφ/2)
                    // within about one spacing of travel: that takes a ≤ a_max when
                    // v² ≤ a_max·spacing / (2·sin(Δφ/2)).
                    cap[i] = cap[i].min((config.a_max * spacing / (2.0 * half_sin)).sqrt());
                }
            }
            let turn = (theta[fwd] - theta[back]).abs();
            if turn > 1e-9 {
                let travel = cum_len[fwd] - cum_len[back];
                cap[i] = cap[i].min(ROTATION_SPEED_SHARE * config.omega_max * travel / turn);
            }
        }
        // Backward pass: from every pose the robot can still brake to every later cap.
        let brake = config.brake_fraction * config.a_max;
        let mut allowed = cap;
        for i in (0..n.saturating_sub(1)).rev() {
            let reach =
                (allowed[i + 1].powi(2) + 2.0 * brake * (cum_len[i + 1] - cum_len[i])).sqrt();
            allowed[i] = allowed[i].min(reach);
        }
        let last = FollowerOutput { closest: path[0], aim: path[0], ..FollowerOutput::default() };
        Ok(Self {
            config,
            path,
            cum_metric,
            stops,
            allowed,
            progress: 0,
            arrived: false,
            in_tolerance_s: 0.0,
            last,
            spline: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &FollowerConfig {
        &self.config
    }

    /// The path being followed.
    pub fn path(&self) -> &[Pose2] {
        &self.path
    }

    /// Index of the path pose reached so far.
    pub fn progress_index(&self) -> usize {
        self.progress
    }

    /// Indices of the stops (goal, sharp corners, starts and ends of big turns on the spot),
    /// ascending.
    pub fn stops(&self) -> &[usize] {
        &self.stops
    }

    /// The spline of the last tick (for visualisation), if any.
    pub fn spline(&self) -> Option<&PoseSpline> {
        self.spline.as_ref()
    }

    /// The output of the last tick (zeros before the first).
    pub fn last_output(&self) -> &FollowerOutput {
        &self.last
    }

    /// The linear speed allowed on reaching path pose `i` (0 at stops), m/s; `None` out
    /// of range.
    pub fn allowed_speed(&self, i: usize) -> Option<f64> {
        self.allowed.get(i).copied()
    }

    /// Squared distance from a path pose to the robot in the projection metric.
    fn metric2(&self, p: &Pose2, q: &Pose2) -> f64 {
        let dt = self.config.projection_rotation_radius_m * wrap_angle(p.theta - q.theta);
        (p.x - q.x).powi(2) + (p.y - q.y).powi(2) + dt * dt
    }

    /// The first stop strictly after `k`, or the last index.
    fn next_stop(&self, k: usize) -> usize {
        let last = self.path.len() - 1;
        let j = self.stops.partition_point(|&s| s <= k);
        self.stops.get(j).copied().unwrap_or(last)
    }

    /// Advances the progress index to the closest pose in the window ahead. A stop (and so
    /// the goal) counts as reached only once the robot is within half the goal tolerances
    /// of it, or within the tolerances for `goal_dwell_s`: until then the window ends just
    /// before it, so the robot keeps being brought to it and never cuts it.
    fn advance(&mut self, measured: &Pose2, dt: f64) {
        let cfg = &self.config;
        let k = self.progress;
        let limit = self.cum_metric[k] + cfg.progress_window_m;
        let by_window = self.cum_metric.partition_point(|&c| c <= limit).saturating_sub(1);
        let stop = self.next_stop(k);
        let target = self.path[stop];
        let (dp, dth) =
            (measured.distance(&target), wrap_angle(target.theta - measured.theta).abs());
        let within = |f: f64| {
            dp <= f * cfg.goal_position_tolerance_m && dth <= f * cfg.goal_heading_tolerance_rad
        };
        // Only a stop inside the window may be reached: a path ending where it starts is
        // not finished at the start.
        let in_window = stop <= by_window;
        self.in_tolerance_s = if in_window && within(1.0) { self.in_tolerance_s + dt } else { 0.0 };
        let reached = in_window && (within(0.5) || self.in_tolerance_s >= cfg.goal_dwell_s);
        if reached {
            if stop == self.path.len() - 1 {
                self.arrived = true;
            }
            if stop != k {
                self.progress = stop;
                self.in_tolerance_s = 0.0;
            }
            return;
        }
        let end = by_window.min(stop.saturating_sub(1)).max(k);
        let mut best = (k, f64::INFINITY);
        for j in k..=end {
            let d = self.metric2(&self.path[j], measured);
            if d < best.1 {
                best = (j, d);
            }
        }
        self.progress = best.0;
    }

    /// The five (or fewer, near a stop) spline poses from the progress index.
    fn spline_poses(&self) -> Vec<Pose2> {
        let k = self.progress;
        let seg_end = self.next_stop(k);
        let spacing = self.config.spline_span_m / (SPLINE_POSES - 1) as f64;
        let mut idx = vec![k];
        for i in 1..SPLINE_POSES {
            let target = self.cum_metric[k] + i as f64 * spacing;
            let j = self.cum_metric.partition_point(|&c| c < target).min(seg_end);
            if idx.last().is_some_and(|&l| j > l) {
                idx.push(j);
            }
            if j >= seg_end {
                break;
            }
        }
        idx.into_iter().map(|i| self.path[i]).collect()
    }

    /// One control tick: `measured` is the base pose (world frame), `dt` the time since the
    /// previous tick (s). Returns the velocity command and the tracking errors.
    pub fn update(&mut self, measured: Pose2, dt: f64) -> FollowerOutput {
        if !(dt.is_finite() && dt > 0.0) {
            // No usable time step: the rate limits cannot be applied, so the last command
            // is repeated unchanged.
            self.last.status = FollowerStatus::InvalidInput;
            return self.last;
        }
        if !(measured.x.is_finite() && measured.y.is_finite() && measured.theta.is_finite()) {
            let twist = self.rate_limit(Twist::default(), dt);
            self.last.twist = twist;
            self.last.status = FollowerStatus::InvalidInput;
            return self.last;
        }
        self.advance(&measured, dt);
        let cfg = self.config.clone();
        let k = self.progress;
        let last_index = self.path.len() - 1;
        let goal = self.path[last_index];

        let poses = self.spline_poses();
        // The poses are finite (checked in `new`) and non-empty, so this cannot fail; if it
        // did, aiming at the reached pose itself is the safe fallback.
        let spline = PoseSpline::new(&poses, cfg.rotation_radius_m).ok();
        let (closest, aim, tangent) = match &spline {
            Some(s) => {
                let pr = s.project(&measured, cfg.projection_rotation_radius_m);
                let u_aim = s.param_at_length(pr.s + cfg.lookahead_m);
                (pr.pose, s.pose(u_aim), s.tangent_direction(pr.u))
            }
            None => (self.path[k], self.path[k], None),
        };
        self.spline = spline;

        // Tracking errors at the projection.
        let along = tangent.unwrap_or(closest.theta);
        let (sa, ca) = along.sin_cos();
        let cross_track = -sa * (measured.x - closest.x) + ca * (measured.y - closest.y);
        let heading_error = wrap_angle(closest.theta - measured.theta);

        // Linear speed: brake towards the speed allowed at the next pose (zero at stops).
        let (allow_next, r_next) = if k < last_index {
            (self.allowed[k + 1], measured.distance(&self.path[k + 1]))
        } else {
            (0.0, measured.distance(&goal))
        };
        let brake = cfg.brake_fraction * cfg.a_max;
        let to_aim = [aim.x - measured.x, aim.y - measured.y];
        let d_aim = to_aim[0].hypot(to_aim[1]);
        let slowdown = ((cfg.heading_slowdown_stop_rad - heading_error.abs())
            / (cfg.heading_slowdown_stop_rad - cfg.heading_slowdown_start_rad))
            .clamp(0.0, 1.0);
        let speed_limit = cfg
            .v_max
            .min((allow_next * allow_next + 2.0 * brake * r_next).sqrt())
            .min(allow_next + cfg.position_gain * r_next)
            .min(cfg.position_gain * d_aim)
            * slowdown;
        // Direction: the chord from the projection to p, plus the pull back onto the spline.
        let g = cfg.cross_track_gain;
        let dir = [
            aim.x - closest.x + g * (closest.x - measured.x),
            aim.y - closest.y + g * (closest.y - measured.y),
        ];
        let dir_norm = dir[0].hypot(dir[1]);
        let (v_wx, v_wy) = if dir_norm > 1e-9 {
            (speed_limit * dir[0] / dir_norm, speed_limit * dir[1] / dir_norm)
        } else {
            (0.0, 0.0)
        };
        // World → robot frame.
        let (st, ct) = measured.theta.sin_cos();
        let vx = ct * v_wx + st * v_wy;
        let vy = -st * v_wx + ct * v_wy;

        // Yaw rate: towards the aim pose's heading, braking so as to stop at it.
        let e_aim = wrap_angle(aim.theta - measured.theta);
        let brake_rot = cfg.brake_fraction * cfg.alpha_max;
        let w_mag = cfg
            .omega_max
            .min((2.0 * brake_rot * e_aim.abs()).sqrt())
            .min(cfg.heading_gain * e_aim.abs());
        let wz = w_mag.copysign(e_aim);

        // Goal: reached in `advance`; released when pushed out to twice the tolerances.
        let distance_to_goal = measured.distance(&goal);
        let goal_heading_error = wrap_angle(goal.theta - measured.theta);
        if self.arrived
            && (distance_to_goal > 2.0 * cfg.goal_position_tolerance_m
                || goal_heading_error.abs() > 2.0 * cfg.goal_heading_tolerance_rad)
        {
            self.arrived = false;
        }
        let desired = if self.arrived { Twist::default() } else { Twist { vx, vy, wz } };
        let twist = self.rate_limit(desired, dt);
        let status = match (self.arrived, twist == Twist::default()) {
            (false, _) => FollowerStatus::Tracking,
            (true, false) => FollowerStatus::Settling,
            (true, true) => FollowerStatus::Finished,
        };
        self.last = FollowerOutput {
            twist,
            status,
            cross_track_m: cross_track,
            heading_error_rad: heading_error,
            progress_index: k,
            closest,
            aim,
            speed_limit,
            distance_to_goal_m: distance_to_goal,
            goal_heading_error_rad: goal_heading_error,
        };
        self.last
    }

    /// Limits the change from the last command: the linear part as a vector (its norm
    /// changes by at most a_max·dt), ω by at most α_max·dt.
    fn rate_limit(&self, desired: Twist, dt: f64) -> Twist {
        let prev = self.last.twist;
        let (dvx, dvy) = (desired.vx - prev.vx, desired.vy - prev.vy);
        let dv = dvx.hypot(dvy);
        let max_dv = self.config.a_max * dt;
        let (vx, vy) = if dv > max_dv {
            let f = max_dv / dv;
            (prev.vx + f * dvx, prev.vy + f * dvy)
        } else {
            (desired.vx, desired.vy)
        };
        let max_dw = self.config.alpha_max * dt;
        let dw = desired.wz - prev.wz;
        // Exact assignment when within the limit, so a stop is exactly zero.
        let wz = if dw.abs() <= max_dw { desired.wz } else { prev.wz + max_dw.copysign(dw) };
        Twist { vx, vy, wz }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    const DT: f64 = 0.01;
    const STEP: f64 = 0.025;

    /// Poses from `a` to `b` (both included) at about `STEP` spacing, all at heading `theta`.
    fn line(a: [f64; 2], b: [f64; 2], theta: f64) -> Vec<Pose2> {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = (len / STEP).round().max(1.0) as usize;
        (0..=n)
            .map(|i| {
                let f = i as f64 / n as f64;
                Pose2::new(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), theta)
            })
            .collect()
    }

    /// A turn on the spot at `at` from `from` to `to` in 2π/64 steps, excluding `from`.
    fn turn(at: [f64; 2], from: f64, to: f64) -> Vec<Pose2> {
        let steps = ((to - from).abs() / (TAU / 64.0)).round().max(1.0) as usize;
        (1..=steps)
            .map(|i| Pose2::new(at[0], at[1], from + (to - from) * i as f64 / steps as f64))
            .collect()
    }

    /// Straight along +x to (1, 0), turn on the spot to 90°, straight along +y to (1, 1).
    fn l_path() -> Vec<Pose2> {
        let mut p = line([0.0, 0.0], [1.0, 0.0], 0.0);
        p.extend(turn([1.0, 0.0], 0.0, FRAC_PI_2));
        p.extend(line([1.0, 0.0], [1.0, 1.0], FRAC_PI_2).into_iter().skip(1));
        p
    }

    /// A tiny deterministic PRNG (xorshift64*) with Box–Muller normals.
    struct Rng(u64);

    impl Rng {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
            // 53 random bits in (0, 1).
            ((r >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }

        fn normal(&mut self) -> f64 {
            let (u1, u2) = (self.uniform(), self.uniform());
            (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
        }
    }

    struct Run {
        /// True pose before each tick.
        poses: Vec<Pose2>,
        outputs: Vec<FollowerOutput>,
    }

    impl Run {
        fn end(&self) -> Pose2 {
            self.poses[self.poses.len() - 1]
        }

        fn finished(&self) -> bool {
            self.outputs.last().is_some_and(|o| o.status == FollowerStatus::Finished)
        }
    }

    /// A perfect kinematic robot: integrates the commanded robot-frame twist in the world
    /// frame until the follower reports `Finished` (or `max_s` passes). With `noise`
    /// (σ_position m, σ_heading rad, rng) the follower sees a noisy measurement.
    fn simulate(
        f: &mut PathFollower,
        start: Pose2,
        max_s: f64,
        mut noise: Option<(f64, f64, &mut Rng)>,
    ) -> Run {
        let mut pose = start;
        let mut run = Run { poses: Vec::new(), outputs: Vec::new() };
        for _ in 0..(max_s / DT) as usize {
            let measured = match noise.as_mut() {
                Some((sp, sa, rng)) => Pose2::new(
                    pose.x + *sp * rng.normal(),
                    pose.y + *sp * rng.normal(),
                    wrap_angle(pose.theta + *sa * rng.normal()),
                ),
                None => pose,
            };
            run.poses.push(pose);
            let out = f.update(measured, DT);
            run.outputs.push(out);
            if out.status == FollowerStatus::Finished {
                break;
            }
            let (s, c) = pose.theta.sin_cos();
            let t = out.twist;
            pose = Pose2::new(
                pose.x + (c * t.vx - s * t.vy) * DT,
                pose.y + (s * t.vx + c * t.vy) * DT,
                wrap_angle(pose.theta + t.wz * DT),
            );
        }
        run.poses.push(pose);
        run
    }

    fn follower(path: Vec<Pose2>) -> PathFollower {
        PathFollower::new(path, FollowerConfig::default()).unwrap()
    }

    fn assert_at_goal(run: &Run, goal: Pose2, tol_m: f64, tol_rad: f64) {
        assert!(run.finished(), "not finished after {} ticks", run.outputs.len());
        let end = run.end();
        assert!(end.distance(&goal) <= tol_m, "end {end:?}, goal {goal:?}");
        assert!(wrap_angle(end.theta - goal.theta).abs() <= tol_rad, "end {end:?}, goal {goal:?}");
    }

    /// Every command within the speed limits and every change within the acceleration
    /// limits (starting from standstill).
    fn assert_limits(run: &Run, cfg: &FollowerConfig) {
        let mut prev = Twist::default();
        for (i, o) in run.outputs.iter().enumerate() {
            let t = o.twist;
            assert!(t.vx.hypot(t.vy) <= cfg.v_max + 1e-12, "tick {i}: {t:?}");
            assert!(t.wz.abs() <= cfg.omega_max + 1e-12, "tick {i}: {t:?}");
            let dv = (t.vx - prev.vx).hypot(t.vy - prev.vy);
            assert!(dv <= cfg.a_max * DT * (1.0 + 1e-9), "tick {i}: |Δv| = {dv}");
            assert!(
                (t.wz - prev.wz).abs() <= cfg.alpha_max * DT * (1.0 + 1e-9),
                "tick {i}: {t:?} after {prev:?}"
            );
            prev = t;
        }
    }

    #[test]
    fn straight_path_cruises_at_v_max_and_stops_at_the_end() {
        let path = line([0.0, 0.0], [2.0, 0.0], 0.0);
        let goal = path[path.len() - 1];
        let mut f = follower(path);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
        for (i, o) in run.outputs.iter().enumerate() {
            let t = i as f64 * DT;
            // Ramp: at most a_max·t after t seconds.
            assert!(o.twist.vx <= 0.5 * (t + DT) + 1e-9, "t = {t}: {:?}", o.twist);
            assert!(
                o.twist.vx >= 0.0 && o.twist.vy.abs() < 1e-12 && o.twist.wz.abs() < 1e-12,
                "{:?}",
                o.twist
            );
            assert!(o.cross_track_m.abs() < 1e-12 && o.heading_error_rad.abs() < 1e-12);
        }
        // Hand computation: the ramp to 0.5 m/s takes 1 s (0.25 m); braking at 0.25 m/s²
        // starts 0.5 m before the goal, i.e. at x = 1.5 m, t ≈ 1 + 1.25/0.5 = 3.5 s.
        for o in &run.outputs[105..340] {
            assert!((o.twist.vx - 0.5).abs() < 1e-12, "{:?}", o.twist);
        }
        assert!(run.outputs.len() < 700, "took {} ticks", run.outputs.len());
    }

    #[test]
    fn sideways_path_drives_left_without_turning() {
        // Heading 0, path along +y: pure v_y'.
        let path = line([0.0, 0.0], [0.0, 1.0], 0.0);
        let goal = path[path.len() - 1];
        let mut f = follower(path);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        let mut max_vy: f64 = 0.0;
        for o in &run.outputs {
            assert!(o.twist.vx.abs() < 1e-12 && o.twist.wz.abs() < 1e-12, "{:?}", o.twist);
            assert!(o.twist.vy >= 0.0);
            max_vy = max_vy.max(o.twist.vy);
        }
        assert!((max_vy - 0.5).abs() < 1e-12);
    }

    #[test]
    fn path_behind_with_forward_poses_is_driven_backwards() {
        // The poses face +x but lead to −x: the robot reverses instead of turning round.
        let path = line([0.0, 0.0], [-1.0, 0.0], 0.0);
        let goal = path[path.len() - 1];
        let mut f = follower(path);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert!(run.poses.iter().all(|p| p.theta.abs() < 1e-12));
        for o in &run.outputs {
            assert!(
                o.twist.vx <= 0.0 && o.twist.vy.abs() < 1e-12 && o.twist.wz.abs() < 1e-12,
                "{:?}",
                o.twist
            );
        }
        assert!(run.outputs.iter().any(|o| (o.twist.vx + 0.5).abs() < 1e-12));
    }

    #[test]
    fn l_path_turns_on_the_spot_and_continues() {
        let path = l_path();
        let corner = 40; // Index of (1, 0) at heading 0: 1 m / 2.5 cm.
        assert_eq!(path[corner], Pose2::new(1.0, 0.0, 0.0));
        let goal = path[path.len() - 1];
        let mut f = follower(path.clone());
        assert_eq!(f.stops(), &[corner, corner + 16, path.len() - 1]);
        assert_eq!(f.allowed_speed(corner), Some(0.0));
        let run = simulate(&mut f, Pose2::default(), 30.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
        let mut turning_ticks = 0;
        for (p, o) in run.poses.iter().zip(&run.outputs) {
            let deg = p.theta.to_degrees();
            // No turning before the corner: the heading stays 0 until the robot is there.
            if p.x < 0.98 {
                assert!(p.theta.abs() < 1e-12, "turned early at {p:?}");
            }
            if (5.0..85.0).contains(&deg) {
                // Turning in place: at the corner, (almost) no linear motion (the last few
                // millimetres of the approach creep in at ≤ 2 cm/s).
                turning_ticks += 1;
                assert!(p.distance(&Pose2::new(1.0, 0.0, 0.0)) < 0.01, "{p:?}");
                assert!(o.twist.vx.hypot(o.twist.vy) < 0.02, "{p:?}: {:?}", o.twist);
            }
        }
        // 80° at ≤ 0.8 rad/s takes at least 1.75 s.
        assert!(turning_ticks >= 175, "{turning_ticks}");
        // Then it drives on forwards (+x' is +y in the world at 90°) at full speed.
        let after = run.poses.iter().zip(&run.outputs).filter(|(p, _)| p.y > 0.3 && p.y < 0.5);
        for (p, o) in after {
            assert!(o.twist.vx > 0.3 && o.twist.vy.abs() < 0.02, "{p:?}: {:?}", o.twist);
            assert!((p.x - 1.0).abs() < 0.02);
        }
        // Progress is monotone.
        assert!(run.outputs.windows(2).all(|w| w[0].progress_index <= w[1].progress_index));
    }

    #[test]
    fn path_starting_with_a_turn_turns_first() {
        // The planner's path often starts by turning to the driving orientation.
        let mut path = vec![Pose2::default()];
        path.extend(turn([0.0, 0.0], 0.0, -FRAC_PI_2));
        path.extend(line([0.0, 0.0], [0.0, -0.6], -FRAC_PI_2).into_iter().skip(1));
        let goal = path[path.len() - 1];
        let mut f = follower(path.clone());
        assert_eq!(f.stops(), &[0, 16, path.len() - 1]);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
        for (p, o) in run.poses.iter().zip(&run.outputs) {
            if p.theta > -85f64.to_radians() {
                assert!(p.x.hypot(p.y) < 0.005, "drove before turning: {p:?}");
            }
            assert!(o.twist.wz <= 1e-12, "turns the short way (right): {o:?}");
        }
    }

    #[test]
    fn small_lattice_turns_are_blended_without_stopping() {
        // The lattice planner's arc: four 2.5 cm moves, one 2π/64 turn, sixteen times (90°).
        let mut path = vec![Pose2::default()];
        for j in 0..16 {
            let th = f64::from(j) * TAU / 64.0;
            for _ in 0..4 {
                let p = path[path.len() - 1];
                path.push(Pose2::new(p.x + STEP * th.cos(), p.y + STEP * th.sin(), th));
            }
            let p = path[path.len() - 1];
            path.push(Pose2::new(p.x, p.y, th + TAU / 64.0));
        }
        let goal = path[path.len() - 1];
        let mut f = follower(path.clone());
        assert_eq!(f.stops(), &[path.len() - 1], "single turns are no stops");
        let run = simulate(&mut f, Pose2::default(), 30.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
        let n = path.len();
        for (p, o) in run.poses.iter().zip(&run.outputs) {
            if o.progress_index > n / 5 && o.progress_index < 3 * n / 5 {
                assert!(o.twist.vx.hypot(o.twist.vy) > 0.2, "slowed at {p:?}: {:?}", o.twist);
            }
            assert!(o.cross_track_m.abs() < 0.02, "{p:?}: {o:?}");
            assert!(o.heading_error_rad.abs() < 0.15, "{p:?}: {o:?}");
        }
    }

    #[test]
    fn cusp_is_reached_before_reversing() {
        let mut path = line([0.0, 0.0], [0.5, 0.0], 0.0);
        path.extend(line([0.5, 0.0], [0.0, 0.0], 0.0).into_iter().skip(1));
        let cusp = 20;
        let goal = path[path.len() - 1];
        let mut f = follower(path.clone());
        assert_eq!(f.stops(), &[cusp, path.len() - 1]);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
        let max_x = run.poses.iter().map(|p| p.x).fold(f64::MIN, f64::max);
        assert!((max_x - 0.5).abs() < 0.015, "{max_x}");
    }

    #[test]
    fn sharp_corner_at_fixed_heading_is_a_stop() {
        // 90° corner driven omnidirectionally (heading 0 throughout): stop, then sideways.
        let mut path = line([0.0, 0.0], [1.0, 0.0], 0.0);
        path.extend(line([1.0, 0.0], [1.0, 1.0], 0.0).into_iter().skip(1));
        let goal = path[path.len() - 1];
        let mut f = follower(path.clone());
        assert_eq!(f.stops(), &[40, path.len() - 1]);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
        // The corner counts as reached within half the goal tolerance (1 cm), so the robot
        // is never more than about that off the L.
        for o in &run.outputs {
            assert!(o.cross_track_m.abs() < 0.011, "{o:?}");
        }
        for p in &run.poses {
            assert!(p.y.abs() < 0.011 || (p.x - 1.0).abs() < 0.011, "{p:?}");
        }
        assert!(run.poses.iter().any(|p| p.x > 0.99 && p.y.abs() < 0.001), "reached the corner");
        // A 45° corner is rounded without stopping.
        let mut path = line([0.0, 0.0], [1.0, 0.0], 0.0);
        path.extend(line([1.0, 0.0], [1.5, 0.5], 0.0).into_iter().skip(1));
        let f = follower(path.clone());
        assert_eq!(f.stops(), &[path.len() - 1]);
        assert!(f.allowed_speed(40).unwrap() > 0.2);
    }

    #[test]
    fn acceleration_limits_are_never_exceeded() {
        // Sideways, turn on the spot by +135° across ±π, then a diagonal, with pose noise.
        let mut path = line([0.0, 0.0], [0.0, 0.6], 3.0);
        path.extend(
            turn([0.0, 0.6], 3.0, 3.0 + 0.75 * PI)
                .into_iter()
                .map(|p| Pose2 { theta: wrap_angle(p.theta), ..p }),
        );
        let th = wrap_angle(3.0 + 0.75 * PI);
        path.extend(line([0.0, 0.6], [0.8, 0.9], th).into_iter().skip(1));
        let cfg = FollowerConfig::default();
        let mut f = PathFollower::new(path.clone(), cfg.clone()).unwrap();
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let run = simulate(&mut f, path[0], 40.0, Some((0.01, 1f64.to_radians(), &mut rng)));
        assert_at_goal(&run, path[path.len() - 1], 0.05, 5f64.to_radians());
        assert_limits(&run, &cfg);
    }

    #[test]
    fn noisy_measurements_still_reach_the_goal() {
        for seed in [1u64, 42, 0xDEAD_BEEF] {
            let path = l_path();
            let goal = path[path.len() - 1];
            let mut f = follower(path);
            let mut rng = Rng(seed);
            let run =
                simulate(&mut f, Pose2::default(), 40.0, Some((0.01, 1f64.to_radians(), &mut rng)));
            assert_at_goal(&run, goal, 0.05, 5f64.to_radians());
            assert_limits(&run, f.config());
            assert!(run.outputs.windows(2).all(|w| w[0].progress_index <= w[1].progress_index));
        }
    }

    #[test]
    fn runs_are_deterministic() {
        let go = || {
            let mut f = follower(l_path());
            let mut rng = Rng(7);
            simulate(&mut f, Pose2::new(0.02, -0.03, 0.05), 40.0, Some((0.01, 0.02, &mut rng)))
                .outputs
        };
        assert_eq!(go(), go());
    }

    #[test]
    fn progress_does_not_skip_ahead_beyond_the_window() {
        let path = line([0.0, 0.0], [3.0, 0.0], 0.0);
        let mut f = follower(path);
        // Measured 2 m along: the closest pose is index 80, but only the window (0.5 m =
        // 20 poses) ahead of index 0 may be reached.
        let o = f.update(Pose2::new(2.0, 0.0, 0.0), DT);
        assert_eq!(o.progress_index, 20);
        // And progress never goes back.
        let o = f.update(Pose2::new(0.0, 0.0, 0.0), DT);
        assert_eq!(o.progress_index, 20);
    }

    #[test]
    fn tracking_errors_are_signed() {
        let mut f = follower(line([0.0, 0.0], [2.0, 0.0], 0.0));
        let o = f.update(Pose2::new(0.5, 0.1, 0.2), DT);
        // Left of the path by 0.1 m, heading 0.2 rad to the left of the path's.
        assert!((o.cross_track_m - 0.1).abs() < 1e-6, "{o:?}");
        assert!((o.heading_error_rad + 0.2).abs() < 1e-9, "{o:?}");
        assert_eq!(o.progress_index, 20);
        // Steering back: velocity to the right of the robot's heading, turning right.
        assert!(o.twist.vy < 0.0 && o.twist.wz < 0.0, "{o:?}");
    }

    #[test]
    fn single_pose_path_drives_to_that_pose() {
        let goal = Pose2::new(0.3, 0.1, 0.2);
        let mut f = follower(vec![goal]);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        assert_at_goal(&run, goal, 0.02, 2f64.to_radians());
        assert_limits(&run, f.config());
    }

    #[test]
    fn invalid_inputs_do_not_panic() {
        let mut f = follower(line([0.0, 0.0], [1.0, 0.0], 0.0));
        for _ in 0..50 {
            f.update(Pose2::default(), DT);
        }
        let moving = f.last_output().twist;
        assert!(moving.vx > 0.2);
        let o = f.update(Pose2::new(f64::NAN, 0.0, 0.0), DT);
        assert_eq!(o.status, FollowerStatus::InvalidInput);
        assert!((o.twist.vx - (moving.vx - 0.5 * DT)).abs() < 1e-12, "brakes: {o:?}");
        let p = f.update(Pose2::default(), 0.0);
        assert_eq!((p.status, p.twist), (FollowerStatus::InvalidInput, o.twist));
        let q = f.update(Pose2::default(), f64::INFINITY);
        assert_eq!(q.twist, o.twist);
        let r = f.update(Pose2::default(), DT);
        assert_eq!(r.status, FollowerStatus::Tracking);
    }

    #[test]
    fn bad_paths_and_configs_are_errors() {
        let cfg = FollowerConfig::default();
        assert!(matches!(
            PathFollower::new(Vec::new(), cfg.clone()),
            Err(FollowerError::EmptyPath)
        ));
        let bad = vec![Pose2::default(), Pose2::new(0.0, f64::INFINITY, 0.0)];
        assert!(matches!(
            PathFollower::new(bad, cfg.clone()),
            Err(FollowerError::NonFinitePose { index: 1 })
        ));
        let zero = FollowerConfig { v_max: 0.0, ..cfg.clone() };
        assert!(matches!(zero.validate(), Err(FollowerError::InvalidConfig { name: "v_max", .. })));
        let order = FollowerConfig { heading_slowdown_start_rad: 0.7, ..cfg.clone() };
        assert!(order.validate().is_err());
        assert!(cfg.validate().is_ok());
    }

    #[test]
    fn settles_then_finishes_and_resumes_when_pushed() {
        let path = line([0.0, 0.0], [0.5, 0.0], 0.0);
        let goal = path[path.len() - 1];
        let mut f = follower(path);
        let run = simulate(&mut f, Pose2::default(), 20.0, None);
        // Aiming at half the tolerance: the robot stops well inside it.
        assert_at_goal(&run, goal, 0.012, 1.2f64.to_radians());
        assert!(run.outputs.iter().any(|o| o.status == FollowerStatus::Settling));
        // Still finished when measured at the goal again; tracking when pushed 10 cm off.
        assert_eq!(f.update(run.end(), DT).status, FollowerStatus::Finished);
        let o = f.update(Pose2::new(0.5, 0.1, 0.0), DT);
        assert_eq!(o.status, FollowerStatus::Tracking);
        assert!(o.twist.vy < 0.0);
    }
}
