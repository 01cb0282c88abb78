//! The paper's "cost client" (Sec. IV): foot cost C_F (eq. 1–2), body cost C_B (eq. 3)
//! and pose cost C (eq. 4), computed from a [`HeightMap`].
//!
//! [`CostMaps::build`] precomputes everything that does not depend on the pose, once per
//! map: the foot-cost layer ([`foot`]) and the "highest terrain within the base-circle
//! radius" layer ([`body`]). After that every query (foot, body, pose cost) is a handful
//! of look-ups and arithmetic: no allocation, no search, well under a microsecond. The
//! planner and the step motion generator call it for every pose they consider.
//!
//! Costs are [`Cost`] values: finite (≥ 1 on known terrain), `Infinite` (a known
//! untraversable height difference under a foot), or `Unknown` (unobserved terrain under
//! a foot or the base, or a position off the map). Both non-finite kinds are
//! untraversable for the planner; they are distinct so images can show them apart
//! (paper Fig. 3: yellow = not traversable, olive = unknown).
//!
//! Leg heights are hip-axis-to-ground distances per leg (FL, FR, RL, RR), m: the paper's
//! "vertical position of a foot relative to the robot base" (Sec. VI-B).

pub mod body;
pub mod foot;
pub mod pose;
pub mod prints;

pub use body::{BodyGeometry, DiscMaxLayer};
pub use foot::{FootCostLayer, HeadingBin, WheelPair, height_differences};
pub use pose::{PoseCost, PoseWeights, combine};

use crate::geometry::Pose2;
use crate::params::{FootModel, InvalidParam, Params};
use crate::robot::RobotDescription;
use crate::terrain::HeightMap;

/// A cost value: finite, infinite (known untraversable) or unknown (unobserved).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cost {
    /// A finite cost (≥ 1 for the paper's costs).
    Finite(f64),
    /// Known to be untraversable.
    Infinite,
    /// Depends on terrain that is not known.
    Unknown,
}

impl Cost {
    /// The finite value, if any.
    #[inline]
    pub fn finite(self) -> Option<f64> {
        match self {
            Cost::Finite(v) => Some(v),
            _ => None,
        }
    }

    /// Whether the cost is finite (the planner may use the pose).
    #[inline]
    pub fn is_finite(self) -> bool {
        matches!(self, Cost::Finite(_))
    }

    /// Internal layer encoding: `NaN` → unknown, `±∞` → infinite.
    #[inline]
    pub(crate) fn from_raw(v: f64) -> Self {
        if v.is_nan() {
            Cost::Unknown
        } else if v.is_infinite() {
            Cost::Infinite
        } else {
            Cost::Finite(v)
        }
    }
}

/// Why the cost maps could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CostError {
    /// A parameter is invalid.
    #[error(transparent)]
    Params(#[from] InvalidParam),
    /// A robot dimension the costs need is not finite.
    #[error("robot description field `{field}` = {value} is not finite")]
    BadRobot {
        /// Field name in `RobotDescription`.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
}

/// Cells by which [`CostMaps::leg_terrain`] dilates the heights: 2 (5 cm at 2.5 cm cells,
/// the leg capsule's 2.5 cm radius and the half cell a point may sit off its cell centre).
pub const LEG_TERRAIN_CELLS: usize = 2;

/// Extra cells by which the planner's leg terrain ([`CostMaps::swept_leg_terrain`]) is
/// dilated beyond the generator's: two cells (5 cm) ≥ the 2.8 cm a leg point moves away
/// from both ends of a lattice edge (see `feasibility`'s module docs).
pub const SWEEP_CELLS: usize = 2;

/// Cell offsets of a driving pose's look-ups for one yaw ([`CostMaps::driving_stencil`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrivingStencil {
    /// Each foot's cell (FL, FR, RL, RR), `[di, dj]` from the base's.
    feet: [[isize; 2]; 4],
    /// Each base circle's cell.
    circles: [[isize; 2]; 2],
    /// The feet's heading bin (the base's yaw).
    bin: HeadingBin,
}

/// Height map, precomputed cost layers, weights and robot geometry: everything needed to
/// answer cost queries for any pose on one map.
#[derive(Debug, Clone)]
pub struct CostMaps {
    heights: HeightMap,
    foot: FootCostLayer,
    /// Per cell `[C_F raw, height raw]` (`NaN` unknown, `+∞` infinite C_F): a foot's two
    /// look-ups share one cache line, which matters for scattered queries.
    foot_cells: Vec<[f64; 2]>,
    /// Whether C_F depends on the foot heading (the wheel-pair foot model).
    foot_oriented: bool,
    disc_max: DiscMaxLayer,
    /// Heights dilated by two cells (5 cm): the terrain a leg point must clear.
    leg_terrain: HeightMap,
    /// Heights dilated by `SWEEP_CELLS` more: what the planner's lattice poses check.
    swept_leg_terrain: HeightMap,
    body: BodyGeometry,
    weights: PoseWeights,
    neutral_footprint: [[f64; 2]; 4],
    driving_leg_height: f64,
    unknown_heights: usize,
    /// The translation-invariant prints of these layers ([`Self::prints`]), built at the
    /// first request and shared by every graph on the map (a replan's graph too).
    prints: std::sync::OnceLock<prints::TerrainPrints>,
}

impl CostMaps {
    /// Precomputes the foot-cost and disc-max layers for `map`. Cell distances use the
    /// map's own resolution (`Params::grid_resolution_m` is for building maps).
    ///
    /// # Errors
    /// Invalid parameters, or a non-finite robot dimension.
    pub fn build(
        map: &HeightMap,
        robot: &RobotDescription,
        params: &Params,
    ) -> Result<Self, CostError> {
        params.validate()?;
        let check = |field: &'static str, value: f64| {
            if value.is_finite() { Ok(value) } else { Err(CostError::BadRobot { field, value }) }
        };
        for (k, hip) in robot.hips.iter().enumerate() {
            check("hips", hip[0])?;
            check("hips", hip[1])?;
            check("neutral_foot_offset_x", robot.neutral_foot_offset_x[k])?;
        }
        check("base_half_extents", robot.base_half_extents[0])?;
        let base_bottom_z = check("base_bottom_z", robot.base_bottom_z)?;
        let circle_x = robot.base_circle_centres_x(params.base_circle_radius_m);
        let hips = robot.hips;
        let body = BodyGeometry {
            circle_x,
            hip_x: [0.5 * (hips[0][0] + hips[1][0]), 0.5 * (hips[2][0] + hips[3][0])],
            base_bottom_z,
            k2: params.k2,
            k3: params.k3,
        };
        let foot = match params.foot_model {
            FootModel::Paper => FootCostLayer::compute(map, params),
            FootModel::WheelPair => {
                let positive = |field: &'static str, value: f64| {
                    if value.is_finite() && value > 0.0 {
                        Ok(value)
                    } else {
                        Err(CostError::BadRobot { field, value })
                    }
                };
                let wheels = WheelPair {
                    radius: positive("wheel_radius", robot.wheel_radius)?,
                    track: check("wheel_track", robot.wheel_track)?.abs(),
                };
                FootCostLayer::wheel_pair(map, params, wheels)
            }
        };
        let foot_cells =
            map.as_slice().iter().enumerate().map(|(k, &h)| [foot.raw(k), h]).collect();
        Ok(Self {
            heights: map.clone(),
            foot_oriented: params.foot_model != FootModel::Paper,
            foot,
            foot_cells,
            disc_max: DiscMaxLayer::compute(map, params.base_circle_radius_m),
            leg_terrain: map.dilated_max(LEG_TERRAIN_CELLS),
            swept_leg_terrain: map.dilated_max(LEG_TERRAIN_CELLS + SWEEP_CELLS),
            body,
            weights: PoseWeights { k4: params.k4, k5: params.k5, k6: params.k6 },
            neutral_footprint: robot.neutral_footprint(),
            driving_leg_height: params.driving_leg_height_m,
            unknown_heights: map.len() - map.known_count(),
            prints: std::sync::OnceLock::new(),
        })
    }

    /// The layers' translation-invariant prints ([`prints::TerrainPrints`]), padded by
    /// `pad` cells at the first request. A later request gets the same prints: any padding
    /// is correct (a rectangle beyond it has no print), only smaller windows fit.
    pub fn prints(&self, pad: usize) -> &prints::TerrainPrints {
        self.prints.get_or_init(|| prints::TerrainPrints::new(self, pad))
    }

    /// A signature of everything the layers hold at cell (i, j) of the map (heights, leg
    /// terrains, the body's disc maximum, the foot cost at every heading): equal
    /// signatures, equal cells (up to a hash collision). For [`prints::TerrainPrints`].
    pub fn cell_signature(&self, i: usize, j: usize) -> u64 {
        let foot = self.foot.cell_bits(j * self.heights.nx() + i);
        let disc = self.disc_max.get(i, j).map_or(u64::MAX, f64::to_bits);
        prints::signature(
            [
                self.heights.raw(i, j).to_bits(),
                self.leg_terrain.raw(i, j).to_bits(),
                self.swept_leg_terrain.raw(i, j).to_bits(),
                disc,
            ]
            .into_iter()
            .chain(foot),
        )
    }

    /// The height map the costs were computed from.
    pub fn heights(&self) -> &HeightMap {
        &self.heights
    }

    /// The heights dilated by [`LEG_TERRAIN_CELLS`] cells: per cell the highest terrain a
    /// leg segment (capsule radius 2.5 cm) over it could touch (`posture::standing`).
    pub fn leg_terrain(&self) -> &HeightMap {
        &self.leg_terrain
    }

    /// The heights dilated by [`SWEEP_CELLS`] more cells than
    /// [`Self::leg_terrain`]: the planner checks lattice poses against it, so that the
    /// legs clear the terrain everywhere between two neighbouring poses
    /// (`feasibility`).
    pub fn swept_leg_terrain(&self) -> &HeightMap {
        &self.swept_leg_terrain
    }

    /// The foot-cost layer.
    pub fn foot_layer(&self) -> &FootCostLayer {
        &self.foot
    }

    /// The "highest terrain within the base-circle radius" layer.
    pub fn disc_max_layer(&self) -> &DiscMaxLayer {
        &self.disc_max
    }

    /// Known terrain height of the cell containing (x, y), m.
    #[inline]
    pub fn height_at(&self, x: f64, y: f64) -> Option<f64> {
        self.heights.height_at_cell(x, y)
    }

    /// C_F (eq. 1) of the cell containing (x, y); `Unknown` off the map. With the
    /// wheel-pair foot model, at the most favourable heading (see
    /// [`Self::foot_cost_cell`]); a foot of known heading uses
    /// [`Self::foot_cost_at_heading`].
    #[inline]
    pub fn foot_cost_at(&self, x: f64, y: f64) -> Cost {
        match self.heights.cell_of(x, y) {
            Some((i, j)) => self.foot.get(i, j),
            None => Cost::Unknown,
        }
    }

    /// C_F (eq. 1–2) of the cell containing (x, y) for a foot facing `theta` (rad; a
    /// foot faces its base's heading); `Unknown` off the map. Equal to
    /// [`Self::foot_cost_at`] with the paper's foot model.
    #[inline]
    pub fn foot_cost_at_heading(&self, x: f64, y: f64, theta: f64) -> Cost {
        match self.heights.cell_of(x, y) {
            Some((i, j)) => self.foot.get_at(i, j, self.foot.heading_bin(theta)),
            None => Cost::Unknown,
        }
    }

    /// C_F (eq. 1) of cell (i, j); `Unknown` off the map. With the wheel-pair foot model
    /// (`Params::foot_model`), the cost at the cell's most favourable foot heading: a
    /// lower bound for relaxations and images; poses use [`Self::foot_cost_cell_at`].
    #[inline]
    pub fn foot_cost_cell(&self, i: usize, j: usize) -> Cost {
        self.foot.get(i, j)
    }

    /// The foot-cost layer's bin for a foot heading `theta` (rad); a foot's heading is
    /// its base's (the wheels stand straight while stepping and driving forward).
    #[inline]
    pub fn foot_heading_bin(&self, theta: f64) -> HeadingBin {
        self.foot.heading_bin(theta)
    }

    /// C_F (eq. 1–2) of cell (i, j) for a foot at heading bin `bin`; `Unknown` off the
    /// map. Equal to [`Self::foot_cost_cell`] with the paper's foot model.
    #[inline]
    pub fn foot_cost_cell_at(&self, i: usize, j: usize, bin: HeadingBin) -> Cost {
        self.foot.get_at(i, j, bin)
    }

    /// Whether cell (i, j) has infinite C_F at some foot heading (with the paper's
    /// model: whether it is infinite); `false` off the map. A superset of every
    /// heading's infinite cells, for pre-filters.
    #[inline]
    pub fn foot_cost_infinite_at_some_heading(&self, i: usize, j: usize) -> bool {
        let (nx, ny) = self.heights.dims();
        i < nx && j < ny && self.foot.infinite_at_some_heading(j * nx + i)
    }

    /// Whether any cell whose centre is closer than `radius` to (x, y) has infinite C_F:
    /// the paper's first step criterion (Sec. V, "close to an obstacle"). Scans the disc
    /// (about 50 cells for 0.1 m); no allocation.
    pub fn infinite_foot_cost_within(&self, x: f64, y: f64, radius: f64) -> bool {
        self.infinite_foot_cost_within_at(x, y, radius, None)
    }

    /// As [`Self::infinite_foot_cost_within`], with C_F at heading bin `bin` (the most
    /// favourable heading's for `None`).
    pub fn infinite_foot_cost_within_at(
        &self,
        x: f64,
        y: f64,
        radius: f64,
        bin: Option<HeadingBin>,
    ) -> bool {
        let res = self.heights.resolution();
        let o = self.heights.origin();
        let (nx, ny) = self.heights.dims();
        if !(radius.is_finite() && radius >= 0.0 && x.is_finite() && y.is_finite()) {
            return false;
        }
        let lo = |v: f64, o: f64| ((v - radius - o) / res - 0.5).ceil().max(0.0);
        let hi =
            |v: f64, o: f64, n: usize| ((v + radius - o) / res - 0.5).floor().min(n as f64 - 1.0);
        let (i0, i1) = (lo(x, o[0]), hi(x, o[0], nx));
        let (j0, j1) = (lo(y, o[1]), hi(y, o[1], ny));
        if i0 > i1 || j0 > j1 {
            return false;
        }
        for j in j0 as usize..=j1 as usize {
            for i in i0 as usize..=i1 as usize {
                let c = self.heights.cell_center(i, j);
                let k = j * nx + i;
                let v = match bin {
                    Some(b) => self.foot.raw_at(k, b),
                    None => self.foot.raw(k),
                };
                if (c[0] - x).hypot(c[1] - y) < radius && v.is_infinite() {
                    return true;
                }
            }
        }
        false
    }

    /// Whether every neutral foot at `pose` has a finite C_F with its wheel pair steered
    /// for a drive: to the world direction `direction` of a straight move, or, for `None`
    /// (turning on the spot), across the line to the base centre (the steering of
    /// `control::wheels`, whose pair rolls along the foot's velocity). Always true with
    /// the paper's foot model, whose cost does not depend on the heading: the wheel-pair
    /// model's pose costs assume straight wheels, and a drive steers them.
    pub fn steered_feet_fit(&self, pose: &Pose2, direction: Option<f64>) -> bool {
        self.steered_feet_fit_mask(pose, &[direction]) & 1 == 1
    }

    /// [`Self::steered_feet_fit`] for several steerings at once: bit k for
    /// `directions[k]` (at most 32; all ones with the paper's model). One look-up per
    /// foot serves every direction.
    pub fn steered_feet_fit_mask(&self, pose: &Pose2, directions: &[Option<f64>]) -> u32 {
        if !self.foot_oriented {
            return u32::MAX;
        }
        let feet = self.neutral_feet(pose);
        // Per foot, the heading bins at which it has a finite C_F (none off the map).
        let fits = feet.map(|f| {
            self.heights
                .cell_of(f[0], f[1])
                .and_then(|(i, j)| self.heights.index(i, j))
                .map_or(0, |k| self.foot.finite_bins(k))
        });
        let mut mask = 0;
        for (bit, d) in directions.iter().enumerate().take(32) {
            let ok = fits.iter().zip(&self.neutral_footprint).all(|(&fit, n)| {
                let heading = d.unwrap_or_else(|| pose.theta + n[0].atan2(-n[1]));
                fit >> self.foot.heading_bin(heading).index() & 1 == 1
            });
            mask |= u32::from(ok) << bit;
        }
        mask
    }

    /// Whether C_F depends on the foot heading (the wheel-pair foot model).
    pub fn foot_heading_dependent(&self) -> bool {
        self.foot_oriented
    }

    /// World positions of the neutral footprint's feet (FL, FR, RL, RR) at `pose`.
    #[inline]
    pub fn neutral_feet(&self, pose: &Pose2) -> [[f64; 2]; 4] {
        let (s, c) = pose.theta.sin_cos();
        self.neutral_footprint.map(|[fx, fy]| [pose.x + c * fx - s * fy, pose.y + s * fx + c * fy])
    }

    /// The neutral footprint in the base frame (x', y'), FL, FR, RL, RR.
    pub fn neutral_footprint(&self) -> [[f64; 2]; 4] {
        self.neutral_footprint
    }

    /// C_B (eq. 3) for the base at `pose` with feet at `feet` (world x, y; FL, FR, RL, RR)
    /// and per-leg `leg_heights` (hip axis above the ground under the foot, m).
    ///
    /// `Unknown` when a foot's cell or a base circle's disc is unknown or off the map, or
    /// when the pose or leg heights are not finite.
    #[inline]
    pub fn body_cost(&self, pose: &Pose2, feet: &[[f64; 2]; 4], leg_heights: &[f64; 4]) -> Cost {
        let mut ground = [0.0; 4];
        for (g, f) in ground.iter_mut().zip(feet) {
            match self.heights.height_at_cell(f[0], f[1]) {
                Some(h) => *g = h,
                None => return Cost::Unknown,
            }
        }
        self.body_cost_under(self.circle_cells(pose, pose.theta.sin_cos()), ground, leg_heights)
    }

    /// The cells holding the two base circles' centres at `pose` (`(s, c)` the sine and
    /// cosine of its yaw); `None` off the map.
    #[inline]
    fn circle_cells(&self, pose: &Pose2, (s, c): (f64, f64)) -> [Option<(usize, usize)>; 2] {
        self.body.circle_x.map(|cx| self.heights.cell_of(pose.x + c * cx, pose.y + s * cx))
    }

    /// Eq. 3 once the feet's ground heights are known (all finite), with the base
    /// circles' centres in `circles`.
    #[inline]
    fn body_cost_under(
        &self,
        circles: [Option<(usize, usize)>; 2],
        ground: [f64; 4],
        leg_heights: &[f64; 4],
    ) -> Cost {
        let mut under = [0.0; 2];
        for (u, cell) in under.iter_mut().zip(circles) {
            match cell.and_then(|(i, j)| self.disc_max.get(i, j)) {
                Some(h) => *u = h,
                None => return Cost::Unknown,
            }
        }
        self.body.cost(ground, leg_heights, under)
    }

    /// C (eq. 4) for the base at `pose`, feet at `feet` (world; FL, FR, RL, RR) and
    /// per-leg `leg_heights`. Allocation-free.
    #[inline]
    pub fn pose_cost(&self, pose: &Pose2, feet: &[[f64; 2]; 4], leg_heights: &[f64; 4]) -> Cost {
        self.pose_cost_detail(pose, feet, leg_heights).total
    }

    /// As [`CostMaps::pose_cost`], with the foot and body costs that make it up.
    #[inline]
    pub fn pose_cost_detail(
        &self,
        pose: &Pose2,
        feet: &[[f64; 2]; 4],
        leg_heights: &[f64; 4],
    ) -> PoseCost {
        self.pose_cost_sc(pose, pose.theta.sin_cos(), feet, leg_heights)
    }

    #[inline]
    fn pose_cost_sc(
        &self,
        pose: &Pose2,
        sc: (f64, f64),
        feet: &[[f64; 2]; 4],
        leg_heights: &[f64; 4],
    ) -> PoseCost {
        let cells = feet
            .map(|[x, y]| self.heights.cell_of(x, y).and_then(|(i, j)| self.heights.index(i, j)));
        // The feet's heading is the base's: the neutral footprint and the step stances
        // stand with straight wheels.
        let bin = self.foot.heading_bin(pose.theta);
        self.pose_cost_of_cells(cells, bin, || self.circle_cells(pose, sc), leg_heights, false)
    }

    /// Eq. 4 from the feet's cells (`None` off the map), the feet's heading bin and the
    /// base circles' cells (asked for only where every foot's ground is known). With
    /// `total_only`, a foot of infinite C_F ends it before the body cost, which cannot
    /// change the total then ([`pose::combine`]); `body` is then left unknown. The
    /// cost-to-go asks this of a million poses on a cold plan, a fifth of them next to an
    /// edge.
    #[inline]
    fn pose_cost_of_cells(
        &self,
        cells: [Option<usize>; 4],
        bin: HeadingBin,
        circles: impl FnOnce() -> [Option<(usize, usize)>; 2],
        leg_heights: &[f64; 4],
        total_only: bool,
    ) -> PoseCost {
        // One cell look-up per foot serves both its C_F and its ground height.
        let mut feet_cost = [Cost::Unknown; 4];
        let mut ground = [0.0; 4];
        let mut ground_known = true;
        for k in 0..4 {
            match cells[k] {
                Some(idx) => {
                    let [cf, h] = self.foot_cells[idx];
                    let cf = if self.foot_oriented { self.foot.raw_at(idx, bin) } else { cf };
                    feet_cost[k] = Cost::from_raw(cf);
                    if h.is_nan() {
                        ground_known = false;
                    } else {
                        ground[k] = h;
                    }
                }
                None => ground_known = false,
            }
        }
        let skip = total_only && feet_cost.contains(&Cost::Infinite);
        let body = if ground_known && !skip {
            self.body_cost_under(circles(), ground, leg_heights)
        } else {
            Cost::Unknown
        };
        PoseCost { total: combine(&feet_cost, body, &self.weights), feet: feet_cost, body }
    }

    /// C (eq. 4) for driving: neutral footprint at `pose`, all legs at the driving leg
    /// height (`Params::driving_leg_height_m`).
    #[inline]
    pub fn driving_pose_cost(&self, pose: &Pose2) -> Cost {
        self.driving_pose_cost_sc(pose, pose.theta.sin_cos())
    }

    /// As [`CostMaps::driving_pose_cost`], with the sine and cosine of the pose's yaw
    /// given (the same result, bit for bit, for `pose.theta.sin_cos()`): for callers that
    /// evaluate many poses of a few orientations.
    #[inline]
    pub fn driving_pose_cost_sc(&self, pose: &Pose2, (s, c): (f64, f64)) -> Cost {
        let feet = self
            .neutral_footprint
            .map(|[fx, fy]| [pose.x + c * fx - s * fy, pose.y + s * fx + c * fy]);
        self.pose_cost_sc(pose, (s, c), &feet, &[self.driving_leg_height; 4]).total
    }

    /// Where the look-ups of [`CostMaps::driving_pose_cost`] fall, in whole cells from
    /// the base's cell, for a pose at a cell centre with yaw `theta`: a point `d` from a
    /// cell's centre lies `⌊1/2 + d / res⌋` cells away, the same for every cell. `None`
    /// where a look-up point lies within 10⁻⁶ of a cell border (float rounding could
    /// then put it in either cell: ask `driving_pose_cost` instead).
    pub fn driving_stencil(&self, theta: f64) -> Option<DrivingStencil> {
        let (s, c) = theta.sin_cos();
        let res = self.heights.resolution();
        let shift = |d: f64| -> Option<isize> {
            let q = 0.5 + d / res;
            let k = q.floor();
            (q - k > 1e-6 && k + 1.0 - q > 1e-6).then_some(k as isize)
        };
        let cell = |dx: f64, dy: f64| Some([shift(dx)?, shift(dy)?]);
        let mut feet = [[0; 2]; 4];
        for (f, &[fx, fy]) in feet.iter_mut().zip(&self.neutral_footprint) {
            *f = cell(c * fx - s * fy, s * fx + c * fy)?;
        }
        let mut circles = [[0; 2]; 2];
        for (o, &cx) in circles.iter_mut().zip(&self.body.circle_x) {
            *o = cell(c * cx, s * cx)?;
        }
        Some(DrivingStencil { feet, circles, bin: self.foot.heading_bin(theta) })
    }

    /// [`CostMaps::driving_pose_cost`] of the pose at the centre of cell (i, j) with the
    /// yaw `stencil` was made for: the same value, from integer look-ups.
    #[inline]
    pub fn driving_pose_cost_at(&self, i: usize, j: usize, stencil: &DrivingStencil) -> Cost {
        let (nx, ny) = self.heights.dims();
        let at = |[di, dj]: [isize; 2]| {
            let (a, b) = (i.wrapping_add_signed(di), j.wrapping_add_signed(dj));
            (a < nx && b < ny).then_some((a, b))
        };
        let cells = stencil.feet.map(|d| at(d).map(|(a, b)| b * nx + a));
        let circles = || stencil.circles.map(at);
        let legs = [self.driving_leg_height; 4];
        self.pose_cost_of_cells(cells, stencil.bin, circles, &legs, true).total
    }

    /// Number of cells with infinite foot cost.
    pub fn infinite_foot_cells(&self) -> usize {
        self.foot.infinite_count()
    }

    /// Number of cells with unknown foot cost.
    pub fn unknown_foot_cells(&self) -> usize {
        self.foot.unknown_count()
    }

    /// Number of height-map cells with unknown height.
    pub fn unknown_height_cells(&self) -> usize {
        self.unknown_heights
    }

    /// C_B at every cell centre for orientation `theta`, neutral footprint, all legs at
    /// `leg_height` (row-major like the height map). For images and debugging.
    pub fn body_cost_layer(&self, theta: f64, leg_height: f64) -> Vec<Cost> {
        self.layer(theta, |pose| {
            let feet = self.neutral_feet(pose);
            self.body_cost(pose, &feet, &[leg_height; 4])
        })
    }

    /// C (eq. 4) at every cell centre for orientation `theta`, neutral footprint, all legs
    /// at `leg_height` (row-major like the height map). For images and debugging.
    pub fn pose_cost_layer(&self, theta: f64, leg_height: f64) -> Vec<Cost> {
        self.layer(theta, |pose| {
            let feet = self.neutral_feet(pose);
            self.pose_cost(pose, &feet, &[leg_height; 4])
        })
    }

    fn layer(&self, theta: f64, f: impl Fn(&Pose2) -> Cost) -> Vec<Cost> {
        let (nx, ny) = self.heights.dims();
        let mut out = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let [x, y] = self.heights.cell_center(i, j);
                out.push(f(&Pose2::new(x, y, theta)));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::Range;
    use crate::scenario::terrain::{Block, Pole, Primitive};
    use crate::terrain::rasterise;

    const RES: f64 = 0.025;

    /// A test robot: hips at x' = ±0.3, y' = ±0.2; neutral feet 0.15 m further out in
    /// x' (at ±0.45, ±0.2); base 0.9 m long, so the 0.25 m circles sit at x' = ±0.2;
    /// underside 0.05 m below the hips. Driving (0.27 m legs) leaves 0.22 m of clearance.
    fn robot() -> RobotDescription {
        RobotDescription {
            hips: [[0.3, 0.2, 0.0], [0.3, -0.2, 0.0], [-0.3, 0.2, 0.0], [-0.3, -0.2, 0.0]],
            thigh_length: 0.3,
            shin_length: 0.3,
            foot_length: 0.1,
            wheel_radius: 0.08,
            wheel_track: 0.1,
            joint_ranges: [Range { min: -2.0, max: 2.0 }; 3],
            neutral_foot_offset_x: [0.15, 0.15, -0.15, -0.15],
            base_half_extents: [0.45, 0.25, 0.1],
            base_bottom_z: -0.05,
            total_mass: 50.0,
            body_mass: 30.0,
            body_com: [0.0, 0.0, 0.2],
            leg_segment_masses: [2.0, 1.5, 1.5],
        }
    }

    #[test]
    fn a_driving_stencil_holds_the_cells_a_point_d_from_a_centre_falls_in() {
        let maps = maps_of(&[]);
        // Feet at x' = ±0.45 m (18.5 → 18, −17.5 → −18 cells), y' = ±0.2 m (8.5 → 8,
        // −7.5 → −8); circles at x' = ±0.2 m (8, −8).
        let s = maps.driving_stencil(0.0).expect("no point on a border");
        assert_eq!(s.feet, [[18, 8], [18, -8], [-18, 8], [-18, -8]]);
        assert_eq!(s.circles, [[8, 0], [-8, 0]]);
        // Facing +y: x = −y', y = x'.
        let s = maps.driving_stencil(std::f64::consts::FRAC_PI_2).expect("no border");
        assert_eq!(s.feet, [[-8, 18], [8, 18], [-8, -18], [8, -18]]);
        // Feet at x' = ±0.4375 m lie 17.5 cells out: on a border, so no stencil.
        let mut r = robot();
        r.neutral_foot_offset_x = [0.1375, 0.1375, -0.1375, -0.1375];
        let m = rasterise(&[], [0.0, 0.0], [5.0, 5.0], RES).unwrap();
        let maps = CostMaps::build(&m, &r, &Params::default()).unwrap();
        assert_eq!(maps.driving_stencil(0.0), None);
    }

    #[test]
    fn a_driving_stencil_gives_the_driving_pose_cost_bit_for_bit() {
        let prims = [
            Primitive::Box(Block {
                center: [1.2, 0.9],
                size: [0.6, 0.5],
                height: 0.2,
                yaw_deg: 17.0,
            }),
            Primitive::Box(Block {
                center: [2.3, 0.5],
                size: [0.3, 0.3],
                height: 0.06,
                yaw_deg: 0.0,
            }),
            Primitive::Pole(Pole { center: [0.7, 1.4], radius: 0.05, height: 0.12 }),
        ];
        let m = rasterise(&prims, [0.0, 0.0], [3.0, 2.0], RES).unwrap();
        let robot = RobotDescription::reference();
        for foot_model in [FootModel::Paper, FootModel::WheelPair] {
            let maps =
                CostMaps::build(&m, &robot, &Params { foot_model, ..Params::default() }).unwrap();
            let (nx, ny) = m.dims();
            let (mut stencils, mut infinite) = (0, 0);
            for k in 0..64 {
                let theta =
                    crate::geometry::wrap_angle(f64::from(k) * std::f64::consts::TAU / 64.0);
                let Some(stencil) = maps.driving_stencil(theta) else { continue };
                stencils += 1;
                for j in 0..ny {
                    for i in 0..nx {
                        let [x, y] = m.cell_center(i, j);
                        let exact = maps.driving_pose_cost(&Pose2::new(x, y, theta));
                        let fast = maps.driving_pose_cost_at(i, j, &stencil);
                        assert_eq!(fast, exact, "{foot_model:?} ({i}, {j}) at {k}");
                        // Where a foot's C_F is infinite the stencil skips the body cost.
                        infinite += usize::from(exact == Cost::Infinite);
                    }
                }
            }
            // The map's edges put feet off it (unknown); the test is not vacuous.
            assert!(stencils >= 60, "{stencils} of 64 yaws have a stencil");
            assert!(infinite > 1000, "{infinite} infinite poses");
        }
    }

    /// A 5 m x 5 m map from (0, 0); cell centres at odd multiples of 0.0125 m.
    fn maps_of(primitives: &[Primitive]) -> CostMaps {
        let m = rasterise(primitives, [0.0, 0.0], [5.0, 5.0], RES).unwrap();
        CostMaps::build(&m, &robot(), &Params::default()).unwrap()
    }

    /// The pose at the centre of cell (100, 100), facing +x.
    const CENTRE: Pose2 = Pose2::new(2.5125, 2.5125, 0.0);

    fn finite(c: Cost) -> f64 {
        c.finite().unwrap_or_else(|| panic!("expected a finite cost, got {c:?}"))
    }

    #[test]
    fn flat_ground_costs_exactly_one_everywhere_inside() {
        let maps = maps_of(&[]);
        for theta in [0.0, 0.3, 1.9, -2.7] {
            let pose = Pose2 { theta, ..CENTRE };
            let d = maps.pose_cost_detail(&pose, &maps.neutral_feet(&pose), &[0.27; 4]);
            assert_eq!(d.feet, [Cost::Finite(1.0); 4]);
            assert_eq!(d.body, Cost::Finite(1.0));
            assert_eq!(d.total, Cost::Finite(1.0));
            assert_eq!(maps.driving_pose_cost(&pose), Cost::Finite(1.0));
        }
        assert_eq!(maps.infinite_foot_cells(), 0);
        assert_eq!(maps.unknown_height_cells(), 0);
        // Only the 4-cell border ring (within r_F of the map edge) is unknown.
        assert_eq!(maps.unknown_foot_cells(), 200 * 200 - 192 * 192);
        assert_eq!(maps.height_at(1.0, 1.0), Some(0.0));
    }

    #[test]
    fn low_pole_between_the_legs_costs_nothing() {
        // 0.15 m < 0.22 m clearance; 0.49 m from every foot (> r_N), so no foot cost.
        let maps =
            maps_of(&[Primitive::Pole(Pole { center: [2.5, 2.5], radius: 0.05, height: 0.15 })]);
        let d = maps.pose_cost_detail(&CENTRE, &maps.neutral_feet(&CENTRE), &[0.27; 4]);
        assert_eq!(d.feet, [Cost::Finite(1.0); 4]);
        assert_eq!(d.body, Cost::Finite(1.0));
        assert_eq!(d.total, Cost::Finite(1.0));
        // But a wheel on it is another matter.
        assert_eq!(maps.foot_cost_at(2.5, 2.5), Cost::Infinite);
    }

    #[test]
    fn tall_pole_under_the_base_costs_k2_times_missing_clearance() {
        let maps =
            maps_of(&[Primitive::Pole(Pole { center: [2.5, 2.5], radius: 0.05, height: 0.4 })]);
        let d = maps.pose_cost_detail(&CENTRE, &maps.neutral_feet(&CENTRE), &[0.27; 4]);
        // C_B = 1 + k2 · (0.4 − (0 + 0.27 − 0.05)) = 1.18.
        assert!((finite(d.body) - 1.18).abs() < 1e-12, "{d:?}");
        // C = 0.1 · 1 + 0.1 · 4 + 0.5 · 1.18 = 1.09.
        assert!((finite(d.total) - 1.09).abs() < 1e-12, "{d:?}");
        // Standing taller (0.45 m legs, underside at 0.4 m) clears it exactly.
        let tall = maps.pose_cost(&CENTRE, &maps.neutral_feet(&CENTRE), &[0.45; 4]);
        assert_eq!(tall, Cost::Finite(1.0));
        // Turned by 90°, the circles still cover the pole; 1 m away, nothing.
        let turned = Pose2 { theta: std::f64::consts::FRAC_PI_2, ..CENTRE };
        assert!(
            (finite(maps.body_cost(&turned, &maps.neutral_feet(&turned), &[0.27; 4])) - 1.18).abs()
                < 1e-12
        );
        let away = Pose2 { x: 3.5125, ..CENTRE };
        assert_eq!(maps.driving_pose_cost(&away), Cost::Finite(1.0));
    }

    #[test]
    fn slope_adds_k3_times_foot_height_difference() {
        // A plane rising 0.1 m per m along x: cell (i, j) at 0.1 · its centre's x.
        let m = HeightMap::from_fn([0.0, 0.0], RES, 200, 200, |i, _| 0.1 * (i as f64 + 0.5) * RES)
            .unwrap();
        let maps = CostMaps::build(&m, &robot(), &Params::default()).unwrap();
        let feet = maps.neutral_feet(&CENTRE);
        let d = maps.pose_cost_detail(&CENTRE, &feet, &[0.27; 4]);
        // Feet at x = 2.9625 and 2.0625 (cell centres): ΔH_max,F = 0.1 · 0.9 = 0.09.
        // Clearance: the underside rises with the hips and stays well above the slope.
        // C_B = 1 + 0.5 · 0.09 = 1.045.
        assert!((finite(d.body) - 1.045).abs() < 1e-9, "{d:?}");
        // Every cell's ΔH is the 0.0025 m step to its x-neighbours (the diagonal ones
        // differ by the same). C_F = 1 + 100 · 0.0025 · Σ_{d < r_N} (1 − d / r_N).
        let mut w = 0.0;
        for dy in -12_i32..=12 {
            for dx in -12_i32..=12 {
                let dist = RES * f64::from(dx * dx + dy * dy).sqrt();
                if dist < 0.3 {
                    w += 1.0 - dist / 0.3;
                }
            }
        }
        // The cone over a disc of 12 cells holds about π·12²/3 ≈ 151 cells' weight.
        assert!((w - 150.0).abs() < 3.0, "{w}");
        let cf = 1.0 + 100.0 * 0.0025 * w;
        for f in d.feet {
            assert!((finite(f) - cf).abs() < 1e-9, "{f:?} vs {cf}");
        }
        // C = 0.1 · C_F + 0.1 · 4 C_F + 0.5 · C_B.
        assert!((finite(d.total) - (0.5 * cf + 0.5 * 1.045)).abs() < 1e-9);
    }

    #[test]
    fn pitched_base_clearance_follows_the_legs() {
        // A 0.3 m platform from x = 2.7125 on: the front feet (x = 2.9625) stand on it,
        // the rear feet (2.0625) do not, and the front circle's disc (centre 2.7125,
        // radius 0.25) reaches onto it.
        let maps = maps_of(&[Primitive::Box(Block {
            center: [3.85, 2.5],
            size: [2.3, 5.0],
            height: 0.3,
            yaw_deg: 0.0,
        })]);
        let feet = maps.neutral_feet(&CENTRE);
        // Hips: front 0.3 + 0.27, rear 0.27; underside at the front circle (x' = 0.2):
        // 0.27 + 0.3 · (0.5 / 0.6) − 0.05 = 0.47 > 0.3: no clearance cost.
        // ΔH_max,F = 0.3: C_B = 1 + 0.5 · 0.3 = 1.15.
        assert!((finite(maps.body_cost(&CENTRE, &feet, &[0.27; 4])) - 1.15).abs() < 1e-12);
        // Front legs short (0.05 m): front hips at 0.35 m, the underside at the front
        // circle is 0.27 + 0.08 · (5/6) − 0.05 ≈ 0.287 < 0.3: a k2 cost of ≈ 0.013.
        let legs = [0.05, 0.05, 0.27, 0.27];
        let under = 0.27 + (0.35 - 0.27) * (0.5 / 0.6) - 0.05;
        let expected = 1.0 + (0.3 - under) + 0.5 * 0.3;
        assert!((finite(maps.body_cost(&CENTRE, &feet, &legs)) - expected).abs() < 1e-12);
    }

    #[test]
    fn edges_at_the_feet_are_infinite_or_finite_by_height() {
        // An edge at x = 3.05, 0.0875 m in front of the front feet (x = 2.9625).
        let edge = |h: f64| {
            maps_of(&[Primitive::Box(Block {
                center: [4.0, 2.5],
                size: [1.9, 5.0],
                height: h,
                yaw_deg: 0.0,
            })])
        };
        let feet = |m: &CostMaps| m.pose_cost_detail(&CENTRE, &m.neutral_feet(&CENTRE), &[0.27; 4]);
        let high = edge(0.06);
        let d = feet(&high);
        assert_eq!(d.feet[0], Cost::Infinite);
        assert_eq!(d.total, Cost::Infinite);
        assert!(high.infinite_foot_cost_within(2.9625, 2.5125, 0.1));
        assert!(!high.infinite_foot_cost_within(2.0625, 2.5125, 0.1));
        let low = edge(0.04);
        let d = feet(&low);
        assert!(finite(d.feet[0]) > 1.0 && d.feet[2] == Cost::Finite(1.0), "{d:?}");
        assert!(finite(d.total) > 1.0);
        assert!(!low.infinite_foot_cost_within(2.9625, 2.5125, 0.3));
    }

    #[test]
    fn wheel_pair_fits_a_foot_facing_an_edge_the_paper_disc_does_not() {
        // A 0.17 m step whose edge lies at x = 3.075: ΔH marks cells 122 (centre
        // 3.0625) and 123. The front feet stand on cell 118 (centre 2.9625), 4 cells =
        // 0.1 m from the nearest marked cell.
        let prims = [Primitive::Box(Block {
            center: [4.025, 2.5],
            size: [1.9, 5.0],
            height: 0.17,
            yaw_deg: 0.0,
        })];
        let m = rasterise(&prims, [0.0, 0.0], [5.0, 5.0], RES).unwrap();
        let paper = CostMaps::build(&m, &robot(), &Params::default()).unwrap();
        let wp_params = Params { foot_model: FootModel::WheelPair, ..Params::default() };
        let wp = CostMaps::build(&m, &robot(), &wp_params).unwrap();
        let (x, y) = (2.9625, 2.5125);
        // Paper: 0.1 m < r_F = 0.12 m, infinite at any heading.
        assert_eq!(paper.foot_cost_at(x, y), Cost::Infinite);
        assert_eq!(paper.foot_cost_at_heading(x, y, 0.0), Cost::Infinite);
        // Wheel pair (radius 0.08 m, wheel centres 0.1 m apart): facing the edge, each
        // wheel is 0.1 m from the marked cells, clear. Facing along it, the wheel
        // centres sit at x ± 0.05 m: the front one 0.05 m < 0.08 m from them.
        assert!(wp.foot_cost_at_heading(x, y, 0.0).is_finite());
        assert!(wp.foot_cost_at_heading(x, y, std::f64::consts::PI).is_finite());
        assert_eq!(wp.foot_cost_at_heading(x, y, std::f64::consts::FRAC_PI_2), Cost::Infinite);
        assert!(wp.foot_cost_at(x, y).is_finite(), "the most favourable heading");
        // The pose facing the edge stands; the same pose driving sideways or turning on
        // the spot would steer the front pairs across the edge.
        let d = wp.pose_cost_detail(&CENTRE, &wp.neutral_feet(&CENTRE), &[0.27; 4]);
        assert!(d.feet[0].is_finite() && d.feet[1].is_finite(), "{d:?}");
        assert_eq!(paper.driving_pose_cost(&CENTRE), Cost::Infinite);
        assert!(wp.steered_feet_fit(&CENTRE, Some(0.0)));
        assert!(wp.steered_feet_fit(&CENTRE, Some(std::f64::consts::PI)));
        assert!(!wp.steered_feet_fit(&CENTRE, Some(std::f64::consts::FRAC_PI_2)));
        assert!(!wp.steered_feet_fit(&CENTRE, None), "front-left tangent at 114°");
        // All at once, as the driving graph memoises them: bit k for direction k.
        let dirs = [Some(0.0), Some(std::f64::consts::FRAC_PI_2), None, Some(-3.0)];
        assert_eq!(wp.steered_feet_fit_mask(&CENTRE, &dirs), 0b1001);
        assert_eq!(paper.steered_feet_fit_mask(&CENTRE, &dirs), u32::MAX);
        // The paper's model does not depend on the steering.
        assert!(paper.steered_feet_fit(&CENTRE, Some(std::f64::consts::FRAC_PI_2)));
        assert!(paper.steered_feet_fit(&CENTRE, None));
    }

    #[test]
    fn unknown_terrain_and_off_map_poses_are_unknown() {
        let mut m = HeightMap::filled([0.0, 0.0], RES, 200, 200, 0.0).unwrap();
        m.set(100, 100, f64::NAN).unwrap(); // under the base, between the legs
        let maps = CostMaps::build(&m, &robot(), &Params::default()).unwrap();
        let d = maps.pose_cost_detail(&CENTRE, &maps.neutral_feet(&CENTRE), &[0.27; 4]);
        assert_eq!(d.feet, [Cost::Finite(1.0); 4]);
        assert_eq!(d.body, Cost::Unknown);
        assert_eq!(d.total, Cost::Unknown);
        assert_eq!(maps.driving_pose_cost(&Pose2::new(-1.0, 2.0, 0.0)), Cost::Unknown);
        assert_eq!(
            maps.driving_pose_cost(&Pose2::new(0.2, 2.0, 0.0)),
            Cost::Unknown,
            "feet off the map"
        );
        assert_eq!(maps.driving_pose_cost(&Pose2::new(f64::NAN, 2.0, 0.0)), Cost::Unknown);
        assert_eq!(maps.foot_cost_at(9.0, 9.0), Cost::Unknown);
        assert_eq!(maps.unknown_height_cells(), 1);
    }

    #[test]
    fn layers_cover_the_map() {
        let maps =
            maps_of(&[Primitive::Pole(Pole { center: [2.5, 2.5], radius: 0.05, height: 0.4 })]);
        let body = maps.body_cost_layer(0.0, 0.27);
        let pose = maps.pose_cost_layer(0.0, 0.27);
        assert_eq!(body.len(), 200 * 200);
        assert_eq!(pose[100 * 200 + 100], maps.driving_pose_cost(&CENTRE));
        assert!((finite(body[100 * 200 + 100]) - 1.18).abs() < 1e-12);
    }

    #[test]
    fn build_rejects_bad_input() {
        let m = HeightMap::filled([0.0, 0.0], RES, 10, 10, 0.0).unwrap();
        let p = Params { k1: -1.0, ..Params::default() };
        assert!(matches!(CostMaps::build(&m, &robot(), &p), Err(CostError::Params(_))));
        let r = RobotDescription { base_bottom_z: f64::NAN, ..robot() };
        assert!(matches!(
            CostMaps::build(&m, &r, &Params::default()),
            Err(CostError::BadRobot { field: "base_bottom_z", .. })
        ));
    }
}
