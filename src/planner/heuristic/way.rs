//! How far the feet still have to go over terrain they could climb: a guide for the
//! probe's greedy list, not a bound.
//!
//! The probe's greedy list (`HeuristicParts::greedy_guidance`, joining a probe that has
//! found no path in 20,000 expansions) counted the base's way to the goal as the straight
//! line. Beside an open-sided flight of stairs the straight line is shortest on the floor
//! next to its top, where no foot can get up: the flight's side there is many risers high.
//! A probe stuck at the flight's foot (its first steps found, the next ones failing at
//! that heading) then expanded the floor beside the flight at every heading and footprint
//! before the one pose at the foot from which the climb goes through (`stairs_000009` of
//! `generate --seed 1`: 396 k expansions, all but 431 of them on the floor; 93 k with the
//! way).
//!
//! [`WayField`] is the length of the shortest 8-connected way from each cell to the goal's
//! feet over cells of known height whose neighbours along the way differ by at most the
//! largest step height (criterion 3 of a step; a diagonal move's two side cells too): the
//! feet climb nothing higher, so each foot passes along such a way. A state's way is the
//! mean over its four feet, in metres, weighed like the straight line (one per metre),
//! plus the driving part's turn; the greedy list takes the larger of the two.
//!
//! It is not a bound, nor meant to be one (the way is counted per cell, and not every
//! manoeuvre that shortens it pays one per metre), so it orders only that list; the
//! heuristic, and with it ε′, is untouched, and probes that find a path before the greedy
//! list joins are as before. In the weighted guided list as well it found that flight's
//! path in 22 k expansions, but it changed the paths of probes that needed no help (the
//! paper's staircase among them). The octile way exceeds the straight line by up to 8 %
//! on open ground; divided by that excess, so that it would take over only where it goes
//! around or up to something, it no longer helped `stairs_000009` (388 k expansions): the
//! floor beside the flight's first treads, from which the field lets feet climb the first
//! tread sideways, is then level with the flight's foot. What the way settles is the floor
//! farther along the flight; the field knows nothing of headings.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::terrain::HeightMap;

/// A neighbour step's length in the field's fixed point: 1000 per cell along an axis.
const AXIS: u32 = 1000;
/// A diagonal neighbour step, √2 · [`AXIS`] rounded.
const DIAGONAL: u32 = 1414;
/// No way to the goal.
const NONE: u32 = u32::MAX;

/// Per cell, the length of the shortest way to the goal's feet over terrain without a
/// rise or drop beyond a step (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct WayField {
    /// Row-major as the height map, in thousandths of a cell; [`NONE`] where no way
    /// leads to the goal.
    way: Vec<u32>,
    nx: usize,
    resolution: f64,
}

impl WayField {
    /// The field on `map` toward `goals` (world points, each a source at way zero; those
    /// off the map or on unknown cells are left out), moving between 8-neighbours whose
    /// heights differ by at most `max_rise_m`.
    pub fn build(map: &HeightMap, goals: &[[f64; 2]], max_rise_m: f64) -> Self {
        let (nx, ny) = map.dims();
        let heights = map.as_slice();
        let mut way = vec![NONE; nx * ny];
        let mut queue = BinaryHeap::new();
        for &[x, y] in goals {
            if let Some((i, j)) = map.cell_of(x, y) {
                let c = j * nx + i;
                if !heights[c].is_nan() && way[c] != 0 {
                    way[c] = 0;
                    queue.push(Reverse((0u32, c)));
                }
            }
        }
        while let Some(Reverse((d, c))) = queue.pop() {
            if d > way[c] {
                continue;
            }
            let (i, j) = ((c % nx) as isize, (c / nx) as isize);
            let h = heights[c];
            for (di, dj) in NEIGHBOURS {
                let (a, b) = (i + di, j + dj);
                if a < 0 || b < 0 || a >= nx as isize || b >= ny as isize {
                    continue;
                }
                let n = b as usize * nx + a as usize;
                let passable = |n: usize| {
                    let rise = (heights[n] - h).abs();
                    // Unknown (NaN) cells have no way through them.
                    !rise.is_nan() && rise <= max_rise_m
                };
                // A diagonal move passes between its two side cells: both must be
                // passable too, or it would slip through a wall one cell thick.
                let diagonal = di != 0 && dj != 0;
                let (row, col) = (j as usize * nx + a as usize, b as usize * nx + i as usize);
                let sides = || passable(row) && passable(col);
                if !passable(n) || (diagonal && !sides()) {
                    continue;
                }
                let step = if diagonal { DIAGONAL } else { AXIS };
                let dn = d.saturating_add(step);
                if dn < way[n] {
                    way[n] = dn;
                    queue.push(Reverse((dn, n)));
                }
            }
        }
        Self { way, nx, resolution: map.resolution() }
    }

    /// The way from cell `(i, j)` of the map the field was built on, m; `None` where no
    /// way leads to the goal (or off the map).
    pub fn at_cell(&self, (i, j): (usize, usize)) -> Option<f64> {
        if i >= self.nx {
            return None;
        }
        let w = *self.way.get(j.checked_mul(self.nx)?.checked_add(i)?)?;
        (w != NONE).then(|| f64::from(w) / f64::from(AXIS) * self.resolution)
    }

    /// The mean way of four feet (world points on `map`, the map the field was built
    /// on), m; `None` if any has none.
    pub fn mean_of(&self, map: &HeightMap, feet: &[[f64; 2]; 4]) -> Option<f64> {
        let mut sum = 0.0;
        for &[x, y] in feet {
            sum += self.at_cell(map.cell_of(x, y)?)?;
        }
        Some(0.25 * sum)
    }
}

/// The eight neighbours of a cell.
const NEIGHBOURS: [(isize, isize); 8] =
    [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)];

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 × 6 map at 0.1 m: floor at 0, with `heights` written over it.
    fn map(heights: &[(usize, usize, f64)]) -> HeightMap {
        let mut m = HeightMap::new([0.0, 0.0], 0.1, 10, 6, vec![0.0; 60]).expect("map");
        for &(i, j, h) in heights {
            m.set(i, j, h).expect("cell");
        }
        m
    }

    /// A way of `cells` cells along an axis and `diagonals` diagonal cells, at 0.1 m a
    /// cell.
    fn way(cells: f64, diagonals: f64) -> f64 {
        cells * 0.1 + diagonals * 0.1414
    }

    #[test]
    fn open_floor_gives_the_octile_distance() {
        let f = WayField::build(&map(&[]), &[[0.05, 0.05]], 0.3);
        // Cell (0, 0) is the source; (3, 0) three cells along x; (2, 2) two diagonals.
        assert_eq!(f.at_cell((0, 0)), Some(0.0));
        assert!((f.at_cell((3, 0)).expect("way") - way(3.0, 0.0)).abs() < 1e-12);
        assert!((f.at_cell((2, 2)).expect("way") - way(0.0, 2.0)).abs() < 1e-12);
        // (5, 1): one diagonal and four along x.
        assert!((f.at_cell((5, 1)).expect("way") - way(4.0, 1.0)).abs() < 1e-12);
        assert_eq!((f.at_cell((10, 0)), f.at_cell((0, 6))), (None, None));
        assert_eq!(f.at_cell((0, usize::MAX)), None);
    }

    #[test]
    fn a_wall_higher_than_a_step_is_walked_around_and_a_low_one_crossed() {
        // A wall along i = 4 for j = 0..5, open at j = 5; the goal beyond it at (8, 0).
        let tall: Vec<_> = (0..5).map(|j| (4, j, 0.5)).collect();
        let f = WayField::build(&map(&tall), &[[0.85, 0.05]], 0.3);
        // From (0, 0) around the wall's open end: no diagonal passes the wall's end cell
        // (4, 4), so the gap (4, 5) is entered and left along x, from (3, 5) to (5, 5);
        // three diagonals and two cells along y to (3, 5), as many from (5, 5) to (8, 0).
        let around = f.at_cell((0, 0)).expect("way");
        assert!((around - way(6.0, 6.0)).abs() < 1e-12, "{around}");
        // The wall's top is 0.5 above every neighbour on the floor: no way leads onto it.
        assert_eq!(f.at_cell((4, 0)), None);
        let low: Vec<_> = (0..5).map(|j| (4, j, 0.2)).collect();
        let f = WayField::build(&map(&low), &[[0.85, 0.05]], 0.3);
        assert!((f.at_cell((0, 0)).expect("way") - way(8.0, 0.0)).abs() < 1e-12);
    }

    #[test]
    fn a_diagonal_wall_one_cell_thick_is_not_slipped_through() {
        // A 0.5 m wall on the cells (k, k), k = 0..5, from the map's corner to its far
        // edge: the cells above it (i < j) are closed off from a goal at (9, 0), though
        // a diagonal move from (1, 0) to (0, 1) joins two floor cells.
        let wall: Vec<_> = (0..6).map(|k| (k, k, 0.5)).collect();
        let f = WayField::build(&map(&wall), &[[0.95, 0.05]], 0.3);
        assert!(f.at_cell((1, 0)).is_some());
        assert_eq!(f.at_cell((0, 1)), None);
        assert_eq!(f.at_cell((2, 5)), None);
    }

    #[test]
    fn unknown_cells_and_unreachable_goals_give_no_way() {
        let mut m = map(&[]);
        for j in 0..6 {
            m.set(5, j, f64::NAN).expect("cell");
        }
        let f = WayField::build(&m, &[[0.85, 0.05]], 0.3);
        assert_eq!(f.at_cell((0, 0)), None);
        assert!(f.at_cell((9, 5)).is_some());
        let feet = [[0.85, 0.05], [0.95, 0.05], [0.85, 0.15], [0.05, 0.05]];
        assert_eq!(f.mean_of(&m, &feet), None);
        let off_map = [[0.85, 0.05], [0.95, 0.05], [0.85, 0.15], [1.05, 0.05]];
        assert_eq!(f.mean_of(&m, &off_map), None);
        let feet = [[0.85, 0.05], [0.95, 0.05], [0.85, 0.15], [0.95, 0.15]];
        let mean = f.mean_of(&m, &feet).expect("way");
        assert!((mean - way(2.0, 1.0) / 4.0).abs() < 1e-12);
        // A goal off the map is no source.
        let f = WayField::build(&m, &[[5.0, 5.0]], 0.3);
        assert_eq!(f.at_cell((8, 0)), None);
    }
}
