//! Drive runs: consecutive drive keyframes are handed to the B-spline path follower
//! (Sec. IX) and the omnidirectional wheel kinematics, while the legs hold the keyframes'
//! posture interpolated where the robot is along the run (on the path segment it is on,
//! [`segment_at`]). The follower's end of the run hands over to the next keyframe; too
//! large a cross-track error fails.
//!
//! **Load sharing.** The legs are position-controlled, and four stiff legs on ground the
//! height map knows only to a cell rest on three of them: the fourth pair hangs a few
//! millimetres up, and the CoM sits next to the diagonal of the other three
//! (`control::load_sharing`). The legs of the diagonal that carries less than its share of
//! the weight (MuJoCo's wheel loads against the balancing loads whose smallest is largest)
//! are lengthened, and the other diagonal's shortened back to their planned length, at
//! `load_sharing_gain_mps` per unit of the error (at most `max_leg_extension_m`); what all
//! four share is given back at `leg_release_speed_mps`, so the extension does not outlive
//! the bump. The gain is a third of where the loop starts to ring: at 0.8 m/s the warp
//! flipped sign every 10 ms tick on flat ground, at 0.6 it settled (generated clutter seed
//! 335). It replaced lengthening only a leg whose wheels touch nothing, at 5 cm/s: that
//! came after the load had gone, and over a 3 cm bump the chassis rocked from one diagonal
//! to the other, a pair 4 mm up for 0.1 s with the CoM 0.85 cm inside the others' diagonal.
//!
//! **The base follows the ground slowly.** The feet follow the height map under the
//! wheels, and the base rises with the highest foot; the commanded base moves up or down
//! no faster than `base_rise_speed_mps`, whether the ground or the plan moves it: a base
//! thrown up faster leaves the ground with all its wheels when the rise stops.

use super::actuation::pairs_in_base;
use super::interface::STANDARD_GRAVITY;
use super::{Command, ExecFailure, Mode, Observation, StepExecutor, planar};
use crate::control::load_sharing::{WARP_SIGN, measured_warp, target_warp};
use crate::control::path_follower::{FollowerStatus, PathFollower};
use crate::geometry::{Pose2, wrap_angle};
use crate::posture::kinematics::{Posture, hips_in_world, interpolate};

/// How far a drive run moves a foot from its keyframe height to where its wheels rest,
/// m: the foot cost's largest height difference within r_F (eq. 2), the most a wheel
/// meets while driving.
pub(super) const WHEEL_REST_RANGE_M: f64 = 0.05;

impl StepExecutor {
    /// `p` with each foot at the height where its wheel pair rests on the height map (the
    /// higher of its two wheels, [`crate::terrain::HeightMap::wheel_rest_height`], with the
    /// pair turned by its measured steering), within [`WHEEL_REST_RANGE_M`] of the
    /// keyframes' height: legs lengthen and shorten with the ground under the wheels, so
    /// every wheel keeps the ground over bumps the foot cost lets the robot drive on,
    /// rather than the stiff legs lifting a diagonal off it. The base rises where a foot
    /// would otherwise stand closer under its hip than the driving leg height (the knees
    /// fold nearly to their limit there): by the most any foot rises beyond its leg's
    /// [`Self::leg_slack`]. A driving posture sets the base by its highest foot
    /// (`posture::kinematics::driving_posture`), so only that leg is at the driving height;
    /// a wheel resting on the edge of a bump the plan has it already off is taken up by its
    /// longer leg. (The base rose by each foot's whole rise before: a front pair rolling
    /// off a 4.3 cm box, its wheels still on the edge where the map had its foot on the
    /// floor, raised the base 3.5 cm while its partner stood on the box, and the rise and
    /// the load sharing's push threw every wheel off the ground: generated clutter seed
    /// 12067, the CoM 2.7 cm outside the support of the first wheels down.)
    fn on_wheel_rest_heights(&self, mut p: Posture, obs: &Observation) -> Posture {
        let mut rise = 0.0_f64;
        let r = self.robot.wheel_radius;
        let half_track = self.robot.wheel_track / 2.0;
        let planned = planar(&p);
        let slack = self.leg_slack(&p);
        for (i, f) in p.feet.iter_mut().enumerate() {
            // Where the wheels are: the foot's place under the base as measured, not under
            // the keyframes' pose, which the robot follows only within the follower's
            // tolerance (a start off the lattice's headings stands up to 2.8° from it).
            let [fx, fy] = obs.base.transform(planned.inverse_transform([f[0], f[1]]));
            let (s, c) = (obs.base.theta + obs.steering[i]).sin_cos();
            let top = f[2] + WHEEL_REST_RANGE_M;
            let rest = [-1.0, 1.0]
                .iter()
                .filter_map(|side| {
                    let (x, y) = (fx - side * half_track * s, fy + side * half_track * c);
                    self.ground.wheel_rest_height(x, y, r, top)
                })
                .fold(None, |a: Option<f64>, z| Some(a.map_or(z, |a| a.max(z))));
            if let Some(z) = rest {
                let z = z.clamp(f[2] - WHEEL_REST_RANGE_M, top);
                rise = rise.max(z - f[2] - slack[i]);
                f[2] = z;
            }
        }
        p.base_position[2] += rise;
        p
    }

    /// How much longer than the driving leg height each leg of `p` is (hip over foot, m,
    /// at least zero): how far its foot may rise under an unmoved base.
    fn leg_slack(&self, p: &Posture) -> [f64; 4] {
        let hips = hips_in_world(&self.robot, p);
        std::array::from_fn(|i| {
            (hips[i][2] - p.feet[i][2] - self.config.driving_leg_height_m).max(0.0)
        })
    }

    /// `rest` (`planned` on the wheels' rest heights, [`Self::on_wheel_rest_heights`])
    /// with the base's rise moved toward its rise there by at most
    /// `base_rise_speed_mps · dt` since the last tick, the base commanded no more than
    /// that above or below its last command, and each foot no higher than the driving leg
    /// height allows under that base ([`Self::leg_slack`]: no leg shorter than the knees
    /// fold to). Followed at once, a wheel pair driven onto a 3.7 cm box edge at 0.45 m/s
    /// raised the base at 0.5 m/s, and when the rise stopped the robot flew on: every
    /// wheel off the ground for 60 ms, the CoM 0.25 m outside the support of the wheels
    /// that first came down. A wheel that climbs faster than the base may rise presses
    /// into its bump instead, which lifts that side as it would a rigid cart.
    fn with_limited_rise(&mut self, planned: &Posture, mut rest: Posture, dt: f64) -> Posture {
        let target = rest.base_position[2] - planned.base_position[2];
        let step = self.config.base_rise_speed_mps * dt;
        self.drive_rise += (target - self.drive_rise).clamp(-step, step);
        // Nor does the commanded base come down faster: where the plan's base drops
        // between two poses while a wheel still rests on the edge it leaves, the rise
        // takes the drop up only at its rate, and the base commanded 3.3 cm lower in one
        // tick left three pairs hanging (generated clutter seed 12067, ε = 3: the CoM
        // outside the one pair down for 30 ms). Legs that shorten no faster than the
        // robot falls in a millimetre keep their wheels loaded.
        // Nor does it rise faster where the plan's base rises between two poses: where
        // a blended turn on the spot puts a foot onto a bump, the keyframes' base rose
        // 3 cm from one pose to the next, and the legs, following at once, threw the
        // robot off all its wheels for 50 ms (generated clutter: the CoM 0.34 m outside
        // the pair that came down first).
        let mut z = planned.base_position[2] + self.drive_rise;
        if let Some(last) = self.drive_base_z {
            z = z.clamp(last - step, last + step);
        }
        self.drive_rise = z - planned.base_position[2];
        self.drive_base_z = Some(z);
        rest.base_position[2] = z;
        let slack = self.leg_slack(planned);
        for ((f, q), s) in rest.feet.iter_mut().zip(&planned.feet).zip(slack) {
            f[2] = f[2].min(q[2] + s + self.drive_rise);
        }
        rest
    }

    /// `p` with each leg extended by its compliance (see the module docs), updated for a
    /// tick of `dt` from the wheel loads in `obs` ([`Self::share_load`]); what all four
    /// legs share is given back at `leg_release_speed_mps`.
    fn complied(&mut self, mut p: Posture, obs: &Observation, dt: f64) -> Posture {
        let mut extension = self.drive_extension;
        if self.share_load(&p, obs, &mut extension, dt) {
            let shared = extension.iter().copied().fold(f64::INFINITY, f64::min);
            let back = shared.min(self.config.leg_release_speed_mps * dt);
            for e in &mut extension {
                *e -= back;
            }
            self.drive_extension = extension;
        }
        for (f, e) in p.feet.iter_mut().zip(self.drive_extension) {
            f[2] -= e;
        }
        p
    }

    /// One tick of load sharing on four feet (`control::load_sharing`): the legs of the
    /// diagonal that carries less than its share lengthen, the others' shorten, each
    /// `extension` (below `p`'s feet, m) moved by `load_sharing_gain_mps` × the warp error ×
    /// `dt`, never below zero nor lengthened beyond `max_leg_extension_m`. The warp error
    /// is the measured warp ([`measured_warp`]) less the target warp of `p`'s feet and the
    /// measured CoM, both in the base's frame ([`target_warp`]). Drive runs and the
    /// standing manoeuvres on four feet (`contact`) share it. False, and nothing
    /// changed, while the wheels carry less than a quarter of the weight (a bounce: loads
    /// say nothing of the warp then) or the feet stand on one line.
    pub(super) fn share_load(
        &self,
        p: &Posture,
        obs: &Observation,
        extension: &mut [f64; 4],
        dt: f64,
    ) -> bool {
        let c = &self.config;
        let planned = planar(p);
        let feet = p.feet.map(|f| planned.inverse_transform([f[0], f[1]]));
        let com = obs.base.inverse_transform([obs.com[0], obs.com[1]]);
        let carried =
            obs.wheel_loads.iter().sum::<f64>() >= 0.25 * self.robot.total_mass * STANDARD_GRAVITY;
        let (true, Some(warp), Some(target)) =
            (carried, measured_warp(&obs.wheel_loads), target_warp(&feet, com))
        else {
            return false;
        };
        let rate = c.load_sharing_gain_mps * (warp - target);
        for (e, s) in extension.iter_mut().zip(WARP_SIGN) {
            let next = *e - s * rate * dt;
            *e = if next > *e { next.min(c.max_leg_extension_m.max(*e)) } else { next.max(0.0) };
        }
        true
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn drive_tick(
        &mut self,
        obs: &Observation,
        dt: f64,
        mut follower: Box<PathFollower>,
        first: usize,
        last: usize,
    ) -> Command {
        let time = obs.time;
        let out = follower.update(obs.base, dt);
        if out.status == FollowerStatus::Finished {
            // Where the wheels rest, as during the run: no jump into the next segment.
            let planned = self.keys[last].posture();
            let p = self.on_wheel_rest_heights(planned, obs);
            let p = self.with_limited_rise(&planned, p, dt);
            self.cmd = self.complied(p, obs, dt);
            self.advance(last + 1, time);
            return self.hold();
        }
        if out.cross_track_m.abs() > self.config.drift_tolerance_m {
            self.cmd = self.keys[(first - 1 + out.progress_index).min(last)].posture();
            self.fail(
                ExecFailure::Drift {
                    distance_m: out.cross_track_m.abs(),
                    heading_rad: out.heading_error_rad,
                },
                time,
            );
            return self.hold();
        }
        // The keyframe posture where the robot is along the run.
        let path = follower.path();
        let (k, t) = segment_at(path, out.progress_index.min(path.len() - 1), obs.base);
        let a_idx = first - 1 + k;
        let p = if k + 1 < path.len() {
            interpolate(&self.keys[a_idx].posture(), &self.keys[a_idx + 1].posture(), t)
        } else {
            self.keys[a_idx].posture()
        };
        let rest = self.on_wheel_rest_heights(p, obs);
        let p = self.with_limited_rise(&p, rest, dt);
        let p = self.complied(p, obs, dt);
        self.cmd = p;
        self.mode = Mode::Drive { follower, first, last };
        let Some(legs) = self.legs_for(&p, time) else { return self.hold() };
        let feet = pairs_in_base(&self.robot, &p);
        let wheels = self.config.wheels.commands(&self.robot, out.twist, &feet, &obs.steering);
        Command { legs, wheels: self.with_steer_rate(wheels, obs) }
    }
}

/// Where `base` lies along the run's `path`: the path segment it is on, as the index of
/// its first pose, and the fraction of the segment it has covered (its projection onto the
/// segment, or for a turn on the spot its share of the turn), in [0, 1]. `progress` is the
/// follower's progress index, the path pose *closest* to the robot: the robot is on the
/// segment that pose begins, or, where it has not reached that pose yet, on the one
/// before it. (Interpolating from the closest pose alone jumped half a segment where the
/// closest pose changed, halfway along: on generated clutter the plan's base rose 6 cm
/// from one pose to the next, the commanded base 3.1 cm in one tick, and the legs threw
/// the robot off all its wheels for 60 ms.)
fn segment_at(path: &[Pose2], progress: usize, base: Pose2) -> (usize, f64) {
    let fraction = |a: Pose2, b: Pose2| {
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let len2 = dx * dx + dy * dy;
        if len2 > 1e-8 {
            ((base.x - a.x) * dx + (base.y - a.y) * dy) / len2
        } else {
            let dth = wrap_angle(b.theta - a.theta);
            if dth.abs() > 1e-6 { wrap_angle(base.theta - a.theta) / dth } else { 1.0 }
        }
    };
    let ahead = (progress + 1 < path.len()).then(|| fraction(path[progress], path[progress + 1]));
    match ahead {
        Some(t) if t >= 0.0 || progress == 0 => (progress, t.clamp(0.0, 1.0)),
        _ if progress > 0 => {
            let t = fraction(path[progress - 1], path[progress]);
            if t < 1.0 { (progress - 1, t.max(0.0)) } else { (progress, 0.0) }
        }
        _ => (progress, 0.0),
    }
}

#[cfg(test)]
mod tests {
    use crate::control::step_executor::StepExecutor;
    use crate::control::step_executor::test_support::{
        config, ground, obs, robot, standing, step_path,
    };
    use crate::geometry::Pose2;
    use crate::posture::kinematics::Posture;
    use crate::terrain::HeightMap;

    /// A 4 cm bump under the front-left foot's keyframe position (hip at (0.35, 0.32),
    /// the bump covering x ∈ [0.25, 0.45], y ∈ [0.2, 0.45]).
    fn front_left_bump() -> HeightMap {
        bump(0.2..0.45, 0.04)
    }

    /// A box `height` high under both front pairs (x ∈ [0.25, 0.45], y ∈ [−0.45, 0.45]).
    fn front_box(height: f64) -> HeightMap {
        bump(-0.45..0.45, height)
    }

    /// A box `height` high over x ∈ [0.25, 0.45] and `across` in y.
    fn bump(across: std::ops::Range<f64>, height: f64) -> HeightMap {
        HeightMap::from_fn([-2.0, -2.0], 0.025, 160, 160, |i, j| {
            let (x, y) = (-2.0 + (i as f64 + 0.5) * 0.025, -2.0 + (j as f64 + 0.5) * 0.025);
            if (0.25..0.45).contains(&x) && across.contains(&y) { height } else { 0.0 }
        })
        .unwrap()
    }

    /// The reference robot at the driving height on flat ground: level, every hip the
    /// driving leg height over its foot (the knees folded nearly to their limit).
    fn driving() -> Posture {
        let mut p = standing();
        p.base_position[2] = config().driving_leg_height_m - robot().hips[0][2];
        p
    }

    #[test]
    fn a_leg_longer_than_the_driving_height_takes_up_a_wheel_on_an_edge() {
        // A 4.3 cm box under both front pairs; the plan has the front-left foot on it (the
        // base set by it, the leg at the driving height) and the front-right still on the
        // floor, its leg 4.3 cm longer. The front-right wheels rest on the box: its leg
        // takes that up, and the base does not rise (it rose 4.3 cm when any foot's rise
        // counted whole, which threw the robot off its wheels on generated clutter).
        let ex = StepExecutor::new(&robot(), config(), step_path(), front_box(0.043));
        let mut p = driving();
        p.feet[0][2] = 0.043;
        p.base_position[2] += 0.043;
        let o = obs(0.0, &ex, &[], [0.0; 3]);
        let q = ex.on_wheel_rest_heights(p, &o);
        assert!((q.base_position[2] - p.base_position[2]).abs() < 1e-12, "{q:?}");
        assert!((q.feet[1][2] - 0.043).abs() < 1e-12, "{q:?}");
        // Nor does the limited rise hold the front-right foot down at its planned height.
        let mut ex = ex;
        let r = ex.with_limited_rise(&p, q, 0.01);
        assert!((r.base_position[2] - q.base_position[2]).abs() < 1e-12, "{r:?}");
        assert!((0..4).all(|i| (r.feet[i][2] - q.feet[i][2]).abs() < 1e-12), "{r:?}");
        // Both front feet planned on the floor: the front pair at the driving height on
        // its 4.3 cm rises the base by that.
        let q = ex.on_wheel_rest_heights(driving(), &o);
        assert!((q.base_position[2] - driving().base_position[2] - 0.043).abs() < 1e-12);
    }

    #[test]
    fn wheels_rest_on_the_ground_under_the_measured_base_not_the_keyframes() {
        // The front-left bump. With the base measured where the keyframes put it, the
        // front-left wheels rest on the bump and the base rises 4 cm; with the base
        // measured 0.3 m behind, the wheels stand on the floor and nothing rises.
        let ex = StepExecutor::new(&robot(), config(), step_path(), front_left_bump());
        let p = driving();
        let mut o = obs(0.0, &ex, &[], [0.0; 3]);
        let rise = |o: &crate::control::step_executor::Observation| {
            ex.on_wheel_rest_heights(p, o).base_position[2] - p.base_position[2]
        };
        assert!((rise(&o) - 0.04).abs() < 1e-9, "{}", rise(&o));
        o.base = Pose2::new(-0.3, 0.0, 0.0);
        assert!(rise(&o).abs() < 1e-9, "{}", rise(&o));
    }

    #[test]
    fn the_base_rises_onto_a_bump_no_faster_than_its_rise_speed() {
        // The 4 cm bump of the test above under the front-left wheels, the robot at the
        // driving height: the rest heights raise the base 4 cm at once; the command rises
        // √(2 g · 1 mm) = 0.140 m/s, so 1.40 mm per 10 ms tick, the front-left foot held
        // at its planned leg length (1.40 mm up, not 4 cm); 29 ticks reach the 4 cm, and
        // off the bump it comes down as slowly.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), front_left_bump());
        let p = driving();
        let on = obs(0.0, &ex, &[], [0.0; 3]);
        let mut off = obs(0.0, &ex, &[], [0.0; 3]);
        off.base = Pose2::new(-0.3, 0.0, 0.0);
        let v = (2.0 * 9.81 * 0.001f64).sqrt();
        assert!((ex.config.base_rise_speed_mps - v).abs() < 1e-12);
        let tick = |ex: &mut StepExecutor, o| {
            let rest = ex.on_wheel_rest_heights(p, o);
            ex.with_limited_rise(&p, rest, 0.01)
        };
        let q = tick(&mut ex, &on);
        assert!((q.base_position[2] - p.base_position[2] - v * 0.01).abs() < 1e-12);
        assert!((q.feet[0][2] - p.feet[0][2] - v * 0.01).abs() < 1e-12);
        assert!((1..4).all(|i| q.feet[i][2] == p.feet[i][2]));
        for _ in 1..27 {
            tick(&mut ex, &on);
        }
        let q = tick(&mut ex, &on);
        assert!((q.base_position[2] - p.base_position[2] - 28.0 * v * 0.01).abs() < 1e-12);
        let q = tick(&mut ex, &on);
        assert!((q.base_position[2] - p.base_position[2] - 0.04).abs() < 1e-12);
        assert!((q.feet[0][2] - p.feet[0][2] - 0.04).abs() < 1e-12);
        let q = tick(&mut ex, &off);
        assert!((q.base_position[2] - p.base_position[2] - (0.04 - v * 0.01)).abs() < 1e-12);
        assert!((0..4).all(|i| q.feet[i][2] == p.feet[i][2]));
    }

    #[test]
    fn the_base_comes_down_no_faster_than_it_may_rise() {
        // Flat ground, the robot at the driving height. The plan's base drops 3.3 cm
        // from one tick to the next while the wheels' rest heights keep it where it was
        // (a wheel still on the edge of the box the plan has it off): the command comes
        // down one tick's 1.40 mm, not 3.3 cm less the rise's 1.40 mm. Where the rest
        // heights drop with the plan, it comes down 1.40 mm a tick until it is there.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let step = ex.config.base_rise_speed_mps * 0.01;
        let p = driving();
        let z = p.base_position[2];
        let q = ex.with_limited_rise(&p, p, 0.01);
        assert!((q.base_position[2] - z).abs() < 1e-12);
        let mut lower = p;
        lower.base_position[2] -= 0.033;
        let q = ex.with_limited_rise(&lower, p, 0.01);
        assert!((q.base_position[2] - (z - step)).abs() < 1e-12, "{q:?}");
        let mut last = q.base_position[2];
        for _ in 0..40 {
            let q = ex.with_limited_rise(&lower, lower, 0.01);
            let dz = last - q.base_position[2];
            assert!((-1e-12..=step + 1e-12).contains(&dz), "{dz}");
            last = q.base_position[2];
        }
        assert!((last - (z - 0.033)).abs() < 1e-12, "{last}");
    }

    #[test]
    fn the_light_diagonal_lengthens_until_the_loads_balance() {
        // The reference stance is a rectangle of feet, the CoM at its centre: target warp
        // zero. All the
        // weight on front-right + rear-left is a warp of −1: front-left and rear-right
        // lengthen at 0.25 m/s × 1 = 2.5 mm per 10 ms tick (the others stay at their
        // planned length), 1 cm after 4 ticks. Balanced loads hold it; the weight on the
        // other diagonal hands it over in 4 ticks; a bounce (a tenth of the weight on the
        // wheels) changes nothing; and nothing lengthens beyond 3 cm.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let p = standing();
        let weight = robot().total_mass * 9.81;
        let mut o = obs(0.0, &ex, &[], [0.0; 3]);
        let mut tick = |ex: &mut StepExecutor, loads: [f64; 4]| {
            o.wheel_loads = loads.map(|f| f * weight);
            let q = ex.complied(p, &o, 0.01);
            std::array::from_fn::<f64, 4, _>(|i| p.feet[i][2] - q.feet[i][2])
        };
        let close = |a: [f64; 4], b: [f64; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!((ex.config.load_sharing_gain_mps - 0.25).abs() < 1e-12);
        let mut lowered = [0.0; 4];
        for _ in 0..4 {
            lowered = tick(&mut ex, [0.0, 0.5, 0.5, 0.0]);
        }
        assert!(close(lowered, [0.01, 0.0, 0.0, 0.01]), "{lowered:?}");
        for _ in 0..10 {
            lowered = tick(&mut ex, [0.25; 4]);
        }
        assert!(close(lowered, [0.01, 0.0, 0.0, 0.01]), "{lowered:?}");
        // Handing over, all four legs are extended for three ticks, and the part they
        // share goes back at 0.01 m/s: 0.1 mm a tick, 0.3 mm in all.
        for _ in 0..4 {
            lowered = tick(&mut ex, [0.5, 0.0, 0.0, 0.5]);
        }
        assert!(close(lowered, [0.0, 0.0097, 0.0097, 0.0]), "{lowered:?}");
        lowered = tick(&mut ex, [0.1, 0.0, 0.0, 0.0]);
        assert!(close(lowered, [0.0, 0.0097, 0.0097, 0.0]), "{lowered:?}");
        for _ in 0..100 {
            lowered = tick(&mut ex, [0.5, 0.0, 0.0, 0.5]);
        }
        assert!(close(lowered, [0.0, 0.03, 0.03, 0.0]), "{lowered:?}");
    }

    #[test]
    fn what_all_four_legs_share_is_given_back_slowly() {
        // Every leg 1 cm long (a stance compliance's extension carried into the run), the
        // loads balanced: the warp needs nothing, and the shared centimetre goes back at
        // 0.01 m/s, 0.1 mm per tick, keeping the legs equal.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        ex.drive_extension = [0.01; 4];
        let p = standing();
        let mut o = obs(0.0, &ex, &[], [0.0; 3]);
        o.wheel_loads = [0.25 * robot().total_mass * 9.81; 4];
        let mut q = p;
        for _ in 0..50 {
            q = ex.complied(p, &o, 0.01);
        }
        for i in 0..4 {
            assert!((p.feet[i][2] - q.feet[i][2] - 0.005).abs() < 1e-9, "{i}: {q:?}");
        }
    }

    #[test]
    fn the_base_rises_with_the_plan_no_faster_than_its_rise_speed() {
        // Flat ground, the robot at the driving height. The plan's base rises 3 cm from one
        // tick to the next (a blended turn on the spot that puts a foot on a bump), the
        // rest heights with it: the command rises one tick's 1.40 mm, not 3 cm, and gets
        // there 1.40 mm a tick.
        let mut ex = StepExecutor::new(&robot(), config(), step_path(), ground());
        let step = ex.config.base_rise_speed_mps * 0.01;
        let p = driving();
        let z = p.base_position[2];
        ex.with_limited_rise(&p, p, 0.01);
        let mut higher = p;
        higher.base_position[2] += 0.03;
        let q = ex.with_limited_rise(&higher, higher, 0.01);
        assert!((q.base_position[2] - (z + step)).abs() < 1e-12, "{q:?}");
        let mut last = q.base_position[2];
        for _ in 0..25 {
            let q = ex.with_limited_rise(&higher, higher, 0.01);
            let dz = q.base_position[2] - last;
            assert!((-1e-12..=step + 1e-12).contains(&dz), "{dz}");
            last = q.base_position[2];
        }
        assert!((last - (z + 0.03)).abs() < 1e-12, "{last}");
    }

    #[test]
    fn the_run_is_interpolated_on_the_segment_the_robot_is_on() {
        use super::segment_at;
        // Poses 5 cm apart along x, then a turn on the spot at the end.
        let path = [
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(0.05, 0.0, 0.0),
            Pose2::new(0.10, 0.0, 0.0),
            Pose2::new(0.10, 0.0, 0.2),
        ];
        let close = |(k, t): (usize, f64), (k2, t2): (usize, f64)| k == k2 && (t - t2).abs() < 1e-9;
        // 3 cm along: pose 1 is the closest, but the robot is 60 % along the first segment.
        assert!(close(segment_at(&path, 1, Pose2::new(0.03, 0.0, 0.0)), (0, 0.6)));
        assert!(close(segment_at(&path, 0, Pose2::new(0.03, 0.0, 0.0)), (0, 0.6)));
        // 7 cm along, 1 cm aside: 40 % along the second.
        assert!(close(segment_at(&path, 1, Pose2::new(0.07, 0.01, 0.0)), (1, 0.4)));
        // Halfway through the turn on the spot, with the last pose the closest.
        assert!(close(segment_at(&path, 3, Pose2::new(0.10, 0.0, 0.1)), (2, 0.5)));
        // Past the last pose, and behind the first.
        assert!(close(segment_at(&path, 3, Pose2::new(0.10, 0.0, 0.3)), (3, 0.0)));
        assert!(close(segment_at(&path, 0, Pose2::new(-0.02, 0.0, 0.0)), (0, 0.0)));
        // Either side of the switch of the closest pose, halfway, the same place: the
        // posture does not jump there.
        let before = segment_at(&path, 0, Pose2::new(0.0249, 0.0, 0.0));
        let after = segment_at(&path, 1, Pose2::new(0.0251, 0.0, 0.0));
        assert_eq!(before.0, after.0);
        assert!((after.1 - before.1).abs() < 0.01, "{before:?} {after:?}");
    }
}
