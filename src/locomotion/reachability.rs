//! Where the base can be at all, and which of those cells connect: a relaxation of the
//! hybrid graph that proves "no path" at once when the goal lies where the robot's body
//! and legs cannot pass (a closed room, a doorway narrower than the robot, a wall too
//! tall to straddle), instead of searching every pose before giving up.
//!
//! **Base cells.** A cell is *admissible* when, for some orientation of the lattice, the
//! robot's base centred there could satisfy the two tests every state of the hybrid
//! graph passes (`feasibility`, `motion::standing`):
//! - the underside of the base clears the terrain under its two circles
//!   (`DrivingCheck::body_clear`): here, the highest terrain within
//!   [`BODY_DISC_M`] of each circle centre (less than the 0.25 m the check uses, for the
//!   base's offset from its cell centre during a base shift) is at most
//!   `H_loc + `[`BODY_RISE_M`];
//! - the first quarter of every thigh clears the (dilated) leg terrain by 4 cm
//!   (`StandingRule::legs_clear`): here, somewhere in a band of the hip's sagittal plane
//!   around its nominal position (where that point lies, whatever the hip angle, pitch
//!   or offset of the base: 12.5 cm along, 2.5 cm across) the leg terrain is at most
//!   `H_loc + `[`HIP_RISE_M`].
//!
//! `H_loc` is the highest ground of finite foot cost within [`FEET_REACH_M`] of the cell:
//! every foot stands on such ground within that distance of the base. The standing rule
//! puts the hip over the highest foot at most 0.45 m above it, and the pitch (70 % of
//! the slope between the front and rear feet) raises another hip by at most
//! 0.7 m · sin 0.4 ≈ 0.27 m; so no hip, thigh point or base underside is more than
//! 0.72 m above `H_loc`, and the rises below leave 0.1 m to spare.
//!
//! **Regions.** The test is made per cell *and orientation*. Admissible (cell,
//! orientation) pairs at most [`LINK_CELLS`] apart along each axis in the same
//! orientation are linked (a driving move shifts the base by up to 2 cells; a base shift
//! passes through cells every cell's width, each checked by the standing rule), and so
//! are neighbouring orientations of one cell (a turn on the spot); steps and foot moves
//! leave the base where it is. A flood from the goal cell marks what can reach it; a
//! state whose cell no admissible orientation of which was reached cannot reach the goal:
//! its heuristic is infinite (consistent: both ends of every edge are linked, and the
//! goal's cell is where the flood starts). Per orientation, a leg's band is only 25 cm
//! long, so a 20 cm wall cuts a narrow doorway's passage for every heading that would
//! put a hip over the wall; taken over all orientations at once, a hip could hop it.
//! When the goal's own cell is not admissible the relaxation says nothing (every cell
//! counts as reachable), and a cell that is not admissible itself (only ever a start
//! the robot was put in) counts as reachable: the search from it goes on as before.

use super::lattice::Lattice;
use crate::cost::{CostMaps, DiscMaxLayer};
use crate::robot::RobotDescription;
use crate::terrain::HeightMap;

/// Radius around each base circle centre whose terrain the base must clear, m.
pub const BODY_DISC_M: f64 = 0.2;
/// Longitudinal offsets (base frame x', toward the base centre positive) from each hip
/// at which its thigh's first checked point may lie, m: the knees point toward the
/// centre (`robot::ik`), so the point lies up to a quarter thigh (6.25 cm) inward; 5 cm
/// of pitch and the base's 1.8 cm off its cell centre either way; one cell apart.
const HIP_BAND_X: [f64; 8] = [0.0, 0.025, 0.05, 0.075, 0.1, -0.025, -0.05, 0.125];
/// Lateral offsets (base frame y') of that point, m: the thigh stays in its leg's plane
/// (the roll of a step moves it under 1 cm); one cell either way for the base's offset.
const HIP_BAND_Y: [f64; 3] = [0.0, -0.025, 0.025];
/// Highest terrain under the base circles above `H_loc`, m.
pub const BODY_RISE_M: f64 = 0.85;
/// Highest leg terrain at a hip's thigh point above `H_loc`, m.
pub const HIP_RISE_M: f64 = 0.85;
/// Farthest a foot stands from the base centre, m (the neutral foot 0.47 m out, plus
/// the largest foot offset).
pub const FEET_REACH_M: f64 = 1.0;
/// Link radius between admissible cells, cells.
pub const LINK_CELLS: isize = 2;

/// A fixed-size bit set: one bit per (cell, orientation), 32 MB at the 4 M-cell map
/// limit with 64 orientations.
struct Bits(Vec<u64>);

impl Bits {
    fn new(n: usize) -> Self {
        Self(vec![0; n.div_ceil(64)])
    }

    #[inline]
    fn get(&self, k: usize) -> bool {
        self.0[k / 64] >> (k % 64) & 1 == 1
    }

    #[inline]
    fn set(&mut self, k: usize) {
        self.0[k / 64] |= 1 << (k % 64);
    }
}

/// "Not admissible".
const NONE: u32 = u32::MAX;

/// Regions of admissible base cells and the goal's region.
#[derive(Debug, Clone)]
pub struct BaseRegions {
    nx: usize,
    region: Vec<u32>,
    /// `None`: the relaxation is off (every cell reachable).
    goal_region: Option<u32>,
    regions: usize,
}

impl BaseRegions {
    /// A relaxation that admits every cell.
    pub fn off() -> Self {
        Self { nx: 0, region: Vec::new(), goal_region: None, regions: 0 }
    }

    /// Builds the regions on `maps` for a lattice `lattice` and the goal cell.
    pub fn build(
        maps: &CostMaps,
        robot: &RobotDescription,
        lattice: &Lattice,
        circle_radius_m: f64,
        goal: (i16, i16),
    ) -> Self {
        let hm = maps.heights();
        let (nx, ny) = hm.dims();
        let res = hm.resolution();
        // Highest standable ground near each cell (a square window holding the disc of
        // FEET_REACH_M: a larger window only weakens the test); not standable = unknown.
        let standable: Vec<f64> = (0..nx * ny)
            .map(|k| match (maps.foot_cost_cell(k % nx, k / nx).finite(), hm.as_slice()[k]) {
                (Some(_), h) if h.is_finite() => h,
                _ => f64::NAN,
            })
            .collect();
        let Ok(standable) = HeightMap::new(hm.origin(), res, nx, ny, standable) else {
            return Self::off();
        };
        let h_loc = standable.dilated_max((FEET_REACH_M / res).ceil() as usize);
        let h_loc = h_loc.as_slice();
        let body = DiscMaxLayer::compute(hm, BODY_DISC_M);
        let legs = maps.leg_terrain();
        let circles = robot.base_circle_centres_x(circle_radius_m);
        let trig: Vec<(f64, f64)> =
            (0..lattice.orientations).map(|k| lattice.yaw(k as u8).sin_cos()).collect();
        let cell = |x: f64, y: f64| hm.cell_of(x, y);
        let no = usize::from(lattice.orientations);
        let admissible = |k: usize, o: usize| -> bool {
            let (i, j) = (k % nx, k / nx);
            let top = h_loc[k];
            if !top.is_finite() {
                return false;
            }
            let (x, y) =
                (hm.origin()[0] + (i as f64 + 0.5) * res, hm.origin()[1] + (j as f64 + 0.5) * res);
            let (s, c) = trig[o];
            let body_ok = circles.iter().all(|&cx| {
                cell(x + c * cx, y + s * cx)
                    .and_then(|(a, b)| body.get(a, b))
                    .is_some_and(|h| h <= top + BODY_RISE_M)
            });
            body_ok
                && robot.hips.iter().all(|hp| {
                    // Somewhere in the hip's sagittal band (see `HIP_BAND_*`).
                    HIP_BAND_X.iter().any(|dx| {
                        HIP_BAND_Y.iter().any(|dy| {
                            let (bx, by) = (hp[0] - hp[0].signum() * dx, hp[1] + dy);
                            // Unknown or off the map: `legs_clear` lets it pass too.
                            legs.height_at_cell(x + c * bx - s * by, y + s * bx + c * by)
                                .is_none_or(|h| h <= top + HIP_RISE_M)
                        })
                    })
                })
        };
        let mut ok = Bits::new(nx * ny * no);
        for n in 0..nx * ny * no {
            if admissible(n / no, n % no) {
                ok.set(n);
            }
        }
        let Some(g) = (|| {
            let (i, j) = (usize::try_from(goal.0).ok()?, usize::try_from(goal.1).ok()?);
            (i < nx && j < ny).then_some(j * nx + i)
        })() else {
            return Self::off();
        };
        // Flood from the goal cell's admissible orientations: linked are the same
        // orientation at most LINK_CELLS away along each axis, and the neighbouring
        // orientations in the same cell (a turn on the spot).
        let mut seen = Bits::new(nx * ny * no);
        let mut queue: Vec<usize> = (0..no).map(|o| g * no + o).filter(|&n| ok.get(n)).collect();
        if queue.is_empty() {
            return Self::off();
        }
        for &n in &queue {
            seen.set(n);
        }
        while let Some(n) = queue.pop() {
            let (k, o) = (n / no, n % no);
            let (i, j) = ((k % nx) as isize, (k / nx) as isize);
            for o2 in [(o + 1) % no, (o + no - 1) % no] {
                let m = k * no + o2;
                if ok.get(m) && !seen.get(m) {
                    seen.set(m);
                    queue.push(m);
                }
            }
            for b in (j - LINK_CELLS).max(0)..=(j + LINK_CELLS).min(ny as isize - 1) {
                for a in (i - LINK_CELLS).max(0)..=(i + LINK_CELLS).min(nx as isize - 1) {
                    let m = (b as usize * nx + a as usize) * no + o;
                    if ok.get(m) && !seen.get(m) {
                        seen.set(m);
                        queue.push(m);
                    }
                }
            }
        }
        // Per cell: reaches the goal with some orientation, cannot, or not admissible.
        let region: Vec<u32> = (0..nx * ny)
            .map(|k| {
                if (0..no).any(|o| ok.get(k * no + o)) {
                    u32::from(!(0..no).any(|o| seen.get(k * no + o)))
                } else {
                    NONE
                }
            })
            .collect();
        let regions = 1 + usize::from(region.contains(&1));
        Self { nx, goal_region: Some(0), region, regions }
    }

    /// Whether a base in cell (i, j) may still reach the goal.
    #[inline]
    pub fn reachable(&self, i: i16, j: i16) -> bool {
        let Some(goal) = self.goal_region else { return true };
        let (Ok(i), Ok(j)) = (usize::try_from(i), usize::try_from(j)) else { return false };
        self.region.get(j * self.nx + i).is_none_or(|&r| r == goal || r == NONE)
    }

    /// Number of regions (0 when the relaxation is off).
    pub fn regions(&self) -> usize {
        self.regions
    }

    /// Whether the relaxation is on.
    pub fn is_on(&self) -> bool {
        self.goal_region.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::scenario::Primitive;
    use crate::terrain::rasterise;

    fn regions(prims: &[Primitive], goal: [f64; 2]) -> (BaseRegions, Lattice) {
        let robot = RobotDescription::reference();
        let hm = rasterise(prims, [-1.0, -2.0], [6.0, 4.0], 0.025).unwrap();
        let maps = CostMaps::build(&hm, &robot, &Params::default()).unwrap();
        let lattice = Lattice::for_map(maps.heights(), 64).unwrap();
        let cell = |p: [f64; 2]| {
            let s = lattice.state(&crate::geometry::Pose2::new(p[0], p[1], 0.0)).unwrap();
            (s.i, s.j)
        };
        let r = BaseRegions::build(&maps, &robot, &lattice, 0.25, cell(goal));
        (r, lattice)
    }

    fn wall(center: [f64; 2], size: [f64; 2]) -> Primitive {
        Primitive::Box { center, size, height: 1.2, yaw_deg: 0.0 }
    }

    fn goal_reachable(r: &BaseRegions, l: &Lattice, p: [f64; 2]) -> bool {
        let s = l.state(&crate::geometry::Pose2::new(p[0], p[1], 0.0)).unwrap();
        r.reachable(s.i, s.j)
    }

    #[test]
    fn a_closed_room_cuts_the_start_off_the_goal() {
        // A 2.2 m × 2.2 m room of 1.2 m walls around the goal at (3.5, 0).
        let room = [
            wall([3.5, 1.1], [2.4, 0.2]),
            wall([3.5, -1.1], [2.4, 0.2]),
            wall([2.4, 0.0], [0.2, 2.4]),
            wall([4.6, 0.0], [0.2, 2.4]),
        ];
        let (r, l) = regions(&room, [3.5, 0.0]);
        assert!(r.is_on() && r.regions() >= 2);
        assert!(!goal_reachable(&r, &l, [0.0, 0.0]));
        assert!(goal_reachable(&r, &l, [3.3, 0.2]));
    }

    #[test]
    fn a_doorway_narrower_than_the_robot_is_closed_and_a_wide_one_open() {
        let door = |gap: f64| {
            let w = (4.0 - gap) / 2.0;
            [
                wall([2.0, gap / 2.0 + w / 2.0], [0.2, w]),
                wall([2.0, -gap / 2.0 - w / 2.0], [0.2, w]),
            ]
        };
        // Narrower than the base's circles (0.4 m across the disc the test uses): closed.
        // (Between that and the legs' width the relaxation lets a hip hop the wall by
        // turning; the search proves those.)
        let (r, l) = regions(&door(0.38), [4.0, 0.0]);
        assert!(r.is_on());
        assert!(!goal_reachable(&r, &l, [0.0, 0.0]), "0.38 m door");
        let (r, l) = regions(&door(1.1), [4.0, 0.0]);
        assert!(goal_reachable(&r, &l, [0.0, 0.0]), "1.1 m door");
    }

    #[test]
    fn a_platform_or_a_low_bar_stays_open() {
        // Steps and straddling are possible over a 0.3 m platform and a 0.5 m bar.
        let prims = [
            Primitive::Box { center: [2.0, 0.0], size: [1.0, 4.0], height: 0.3, yaw_deg: 0.0 },
            Primitive::Box { center: [3.6, 0.0], size: [0.1, 4.0], height: 0.5, yaw_deg: 0.0 },
        ];
        let (r, l) = regions(&prims, [4.5, 0.0]);
        assert!(goal_reachable(&r, &l, [0.0, 0.0]));
    }
}
