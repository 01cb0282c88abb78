//! Drive runs: consecutive drive keyframes are handed to the B-spline path follower
//! (Sec. IX) and the omnidirectional wheel kinematics, while the legs hold the keyframes'
//! posture interpolated at the robot's progress along the run. The follower's end of the
//! run hands over to the next keyframe; too large a cross-track error fails.

use super::{Command, ExecFailure, Mode, Observation, StepExecutor};
use crate::control::path_follower::{FollowerStatus, PathFollower};
use crate::geometry::wrap_angle;
use crate::motion::kinematics::{Posture, contacts_in_base, interpolate};

/// How far a drive run moves a foot from its keyframe height to where its wheels rest,
/// m: the foot cost's largest height difference within r_F (eq. 2), the most a wheel
/// meets while driving.
const WHEEL_REST_RANGE_M: f64 = 0.05;

impl StepExecutor {
    /// `p` with each foot at the height where its wheel pair rests on the height map
    /// (the higher of its two wheels, [`crate::terrain::HeightMap::wheel_rest_height`], with the pair
    /// turned by its measured steering), within [`WHEEL_REST_RANGE_M`] of the keyframes'
    /// height: legs lengthen and shorten with the ground under the wheels, so every
    /// wheel keeps the ground over bumps the foot cost lets the robot drive on, rather
    /// than the stiff legs lifting a diagonal off it. The base rises with the highest
    /// foot's rise (as `motion::kinematics::driving_posture` sets it by the highest
    /// foot): the driving height folds the knees nearly to their limit, so no leg may get
    /// shorter than planned.
    fn on_wheel_rest_heights(&self, mut p: Posture, obs: &Observation) -> Posture {
        let mut rise = 0.0_f64;
        let r = self.robot.wheel_radius;
        let half_track = self.robot.wheel_track / 2.0;
        for (i, f) in p.feet.iter_mut().enumerate() {
            let (s, c) = (p.base_rpy[2] + obs.steering[i]).sin_cos();
            let top = f[2] + WHEEL_REST_RANGE_M;
            let rest = [-1.0, 1.0]
                .iter()
                .filter_map(|side| {
                    let (x, y) = (f[0] - side * half_track * s, f[1] + side * half_track * c);
                    self.ground.wheel_rest_height(x, y, r, top)
                })
                .fold(None, |a: Option<f64>, z| Some(a.map_or(z, |a| a.max(z))));
            if let Some(z) = rest {
                let z = z.clamp(f[2] - WHEEL_REST_RANGE_M, top);
                rise = rise.max(z - f[2]);
                f[2] = z;
            }
        }
        p.base_position[2] += rise;
        p
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
            self.cmd = self.on_wheel_rest_heights(self.keys[last].posture(), obs);
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
        // The keyframe posture at the robot's progress along the run.
        let path = follower.path();
        let k = out.progress_index.min(path.len() - 1);
        let a_idx = first - 1 + k;
        let p = if k + 1 < path.len() {
            let (a, b) = (path[k], path[k + 1]);
            let (dx, dy) = (b.x - a.x, b.y - a.y);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 1e-8 {
                ((obs.base.x - a.x) * dx + (obs.base.y - a.y) * dy) / len2
            } else {
                let dth = wrap_angle(b.theta - a.theta);
                if dth.abs() > 1e-6 { wrap_angle(obs.base.theta - a.theta) / dth } else { 1.0 }
            };
            interpolate(
                &self.keys[a_idx].posture(),
                &self.keys[a_idx + 1].posture(),
                t.clamp(0.0, 1.0),
            )
        } else {
            self.keys[a_idx].posture()
        };
        let p = self.on_wheel_rest_heights(p, obs);
        self.cmd = p;
        self.wheel_hold = [None; 4];
        self.mode = Mode::Drive { follower, first, last };
        let Some(legs) = self.legs_for(&p, time) else { return self.hold() };
        let local = contacts_in_base(&self.robot, &p);
        let feet: [[f64; 2]; 4] = std::array::from_fn(|i| {
            [local[i][0] + self.robot.hips[i][0], local[i][1] + self.robot.hips[i][1]]
        });
        let wheels = self.config.wheels.commands(&self.robot, out.twist, &feet, &obs.steering);
        Command { legs, wheels: self.with_steer_rate(wheels, obs) }
    }
}
