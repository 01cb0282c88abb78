//! The pose lattice: discrete robot poses `(cell i, cell j, orientation index, footprint)`
//! on the height map's grid (Sec. IV: 2.5 cm cells, 64 orientations), and the driving
//! moves between them (Sec. V, Fig. 4; Sec. VII-B, Fig. 9).
//!
//! A lattice state stands for the robot base centre at the *centre* of cell `(i, j)` (the
//! height map's convention, see `terrain::heightmap`) with yaw `θ = k · 2π / n`.

use crate::geometry::{Pose2, wrap_angle};
use crate::terrain::HeightMap;
use std::f64::consts::TAU;

/// Footprint id of the neutral footprint (Sec. V): the driving configuration. Other ids
/// are reserved for the footprints that stepping manoeuvres create.
pub const NEUTRAL_FOOTPRINT: u16 = 0;

/// A discrete robot pose: 8 bytes, `Ord` for deterministic tie-breaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LatticeState {
    /// Cell index along x.
    pub i: i16,
    /// Cell index along y.
    pub j: i16,
    /// Orientation index, `0..orientations`; yaw `θ = theta · 2π / orientations`.
    pub theta: u8,
    /// Footprint id ([`NEUTRAL_FOOTPRINT`] for driving).
    pub footprint: u16,
    /// 0 for a pose; otherwise the intermediate node of a lazily checked edge from this
    /// pose, tagged by the manoeuvre that offered it (`graph` module docs, "Lazy edges"):
    /// the search reaches it at the edge's least possible cost, and the manoeuvre checks
    /// the edge only if the search expands it. Steps tag leg `k`'s as `k + 1`.
    pub pending: u8,
}

impl LatticeState {
    /// A neutral-footprint state.
    pub const fn new(i: i16, j: i16, theta: u8) -> Self {
        Self { i, j, theta, footprint: NEUTRAL_FOOTPRINT, pending: 0 }
    }
}

/// Grid geometry of the lattice: the height map's grid plus the orientation count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// World position of the corner of cell (0, 0), m.
    pub origin: [f64; 2],
    /// Cell size, m.
    pub resolution: f64,
    /// Cells along x.
    pub nx: u16,
    /// Cells along y.
    pub ny: u16,
    /// Orientations per cell (64 in the paper; at most 256).
    pub orientations: u16,
}

/// Why a lattice cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LatticeError {
    /// The map has more cells along an axis than a state's `i16` index can hold.
    #[error("map of {nx} x {ny} cells exceeds the lattice's {max} cells per axis")]
    TooLarge {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
        /// Limit per axis.
        max: usize,
    },
    /// Orientation count outside 1..=256.
    #[error("{0} orientations: must be in 1..=256")]
    Orientations(u32),
}

impl Lattice {
    /// The lattice over `map`'s grid with `orientations` orientations per cell.
    ///
    /// # Errors
    /// A map larger than 32767 cells per axis, or an orientation count outside 1..=256.
    pub fn for_map(map: &HeightMap, orientations: u32) -> Result<Self, LatticeError> {
        let (nx, ny) = map.dims();
        let max = i16::MAX as usize;
        if nx > max || ny > max {
            return Err(LatticeError::TooLarge { nx, ny, max });
        }
        if !(1..=256).contains(&orientations) {
            return Err(LatticeError::Orientations(orientations));
        }
        Ok(Self {
            origin: map.origin(),
            resolution: map.resolution(),
            nx: nx as u16,
            ny: ny as u16,
            orientations: orientations as u16,
        })
    }

    /// Angle of one orientation step, rad.
    pub fn orientation_step(&self) -> f64 {
        TAU / f64::from(self.orientations)
    }

    /// Yaw of orientation index `k`, in (−π, π].
    pub fn yaw(&self, k: u8) -> f64 {
        wrap_angle(f64::from(k) * self.orientation_step())
    }

    /// Whether the cell lies on the map.
    pub fn contains(&self, i: i32, j: i32) -> bool {
        i >= 0 && j >= 0 && i < i32::from(self.nx) && j < i32::from(self.ny)
    }

    /// The continuous pose a state stands for (cell centre, orientation yaw).
    pub fn pose(&self, s: LatticeState) -> Pose2 {
        Pose2::new(
            self.origin[0] + (f64::from(s.i) + 0.5) * self.resolution,
            self.origin[1] + (f64::from(s.j) + 0.5) * self.resolution,
            self.yaw(s.theta),
        )
    }

    /// The neutral-footprint state whose cell contains `pose` and whose orientation is
    /// nearest its yaw; `None` off the map or for non-finite poses.
    pub fn state(&self, pose: &Pose2) -> Option<LatticeState> {
        if !(pose.x.is_finite() && pose.y.is_finite() && pose.theta.is_finite()) {
            return None;
        }
        let i = ((pose.x - self.origin[0]) / self.resolution).floor();
        let j = ((pose.y - self.origin[1]) / self.resolution).floor();
        if !(0.0..f64::from(self.nx)).contains(&i) || !(0.0..f64::from(self.ny)).contains(&j) {
            return None;
        }
        let k = (pose.theta.rem_euclid(TAU) / self.orientation_step()).round() as u32
            % u32::from(self.orientations);
        Some(LatticeState::new(i as i16, j as i16, k as u8))
    }

    /// Smallest number of orientation steps between indices `a` and `b`.
    pub fn orientation_steps_between(&self, a: u8, b: u8) -> u32 {
        let n = u32::from(self.orientations);
        let d = (u32::from(a) + n - u32::from(b) % n) % n;
        d.min(n - d)
    }
}

/// A driving move: a cell offset with the orientation kept (omnidirectional driving).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Cell offset along x.
    pub di: i8,
    /// Cell offset along y.
    pub dj: i8,
    /// Length in cells.
    pub cells: f64,
    /// World direction of the move, rad, in (−π, π].
    pub direction: f64,
}

/// Which driving moves a state has (Sec. V; Sec. VII-B, Fig. 9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Neighbourhood {
    /// The 16-neighbourhood of A* (Fig. 4): the 8 adjacent cells and the 8 "knight"
    /// cells (two along one axis, one along the other).
    #[default]
    N16,
    /// The 20-neighbourhood used with ARA* (Fig. 9): [`Neighbourhood::N16`] plus the four
    /// straight two-cell moves (±2, 0) and (0, ±2).
    ///
    /// Why these four: the paper adds them because a highly weighted heuristic favours
    /// the moves that gain the most distance per expansion, so a straight drive becomes a
    /// zig-zag of knight moves (Fig. 9a). A knight move (length √5) gains about 2 cells
    /// towards a goal straight ahead; the straight two-cell move gains the same 2 cells
    /// for less cost and wins, giving the straight line of Fig. 9b. The figure's text
    /// does not name the four moves; these are the four cells of the 5 × 5 ring on the
    /// axes, the only ring cells along which the 16-neighbourhood has no move.
    N20,
}

const N16: [(i8, i8); 16] = [
    (1, 0),
    (2, 1),
    (1, 1),
    (1, 2),
    (0, 1),
    (-1, 2),
    (-1, 1),
    (-2, 1),
    (-1, 0),
    (-2, -1),
    (-1, -1),
    (-1, -2),
    (0, -1),
    (1, -2),
    (1, -1),
    (2, -1),
];

/// The four moves [`Neighbourhood::N20`] adds.
pub const N20_EXTRA: [(i8, i8); 4] = [(2, 0), (0, 2), (-2, 0), (0, -2)];

impl Neighbourhood {
    /// The moves, in a fixed order (counter-clockwise from +x, extras last).
    pub fn moves(self) -> Vec<Move> {
        let extra: &[(i8, i8)] = match self {
            Neighbourhood::N16 => &[],
            Neighbourhood::N20 => &N20_EXTRA,
        };
        N16.iter()
            .chain(extra)
            .map(|&(di, dj)| {
                let (x, y) = (f64::from(di), f64::from(dj));
                Move { di, dj, cells: x.hypot(y), direction: y.atan2(x) }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn lattice() -> Lattice {
        Lattice { origin: [-1.0, 2.0], resolution: 0.025, nx: 100, ny: 80, orientations: 64 }
    }

    #[test]
    fn neighbourhoods_are_distinct_and_symmetric() {
        for (n, len) in [(Neighbourhood::N16, 16), (Neighbourhood::N20, 20)] {
            let m = n.moves();
            assert_eq!(m.len(), len);
            let mut set: Vec<(i8, i8)> = m.iter().map(|m| (m.di, m.dj)).collect();
            set.sort();
            set.dedup();
            assert_eq!(set.len(), len, "duplicate moves");
            for &(a, b) in &set {
                assert!(set.contains(&(-a, -b)), "({a},{b}) has no opposite");
                assert!(a.abs().max(b.abs()) <= 2 && (a, b) != (0, 0));
            }
        }
        let extra: Vec<_> = Neighbourhood::N20.moves()[16..].iter().map(|m| m.cells).collect();
        assert_eq!(extra, vec![2.0; 4]);
    }

    #[test]
    fn pose_state_round_trip() {
        let l = lattice();
        let s = LatticeState::new(17, 33, 48);
        let p = l.pose(s);
        assert!((p.x - (-1.0 + 17.5 * 0.025)).abs() < 1e-12);
        assert!((p.theta + PI / 2.0).abs() < 1e-12);
        assert_eq!(l.state(&p), Some(s));
        assert_eq!(l.state(&Pose2::new(-1.01, 2.1, 0.0)), None);
        assert_eq!(l.state(&Pose2::new(f64::NAN, 2.1, 0.0)), None);
        // Nearest orientation, wrapping.
        let near_zero = Pose2::new(p.x, p.y, -0.01);
        assert_eq!(l.state(&near_zero).map(|s| s.theta), Some(0));
        assert_eq!(l.orientation_steps_between(1, 63), 2);
        assert_eq!(l.orientation_steps_between(0, 32), 32);
    }
}
