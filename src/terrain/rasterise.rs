//! The rasterised height-map source: a [`HeightMap`] computed exactly from a scenario's
//! terrain primitives, the "ground truth" the sensed map is compared against.
//!
//! **Cell value.** Each cell holds the *highest terrain surface over the cell's area*:
//! the supremum of [`terrain_height`](crate::scenario::terrain::terrain_height) over the
//! half-open cell square, i.e. the maximum of the ground plane (z = 0) and the top of every
//! primitive whose footprint overlaps the cell in a set of positive area. This is
//! conservative for a planner (an edge of a box claims every cell it cuts) and is computed
//! exactly, not by sampling, from the [`Solid`]s each primitive is made of (this module
//! knows those shapes, not the primitive kinds):
//!
//! - boxes (`box` primitives, stair steps; flat tops): a separating-axis test of the (rotated)
//!   footprint rectangle against the cell square;
//! - cylinders (poles): the distance from the axis to the cell square against the radius;
//! - wedges (ramps; linear tops): the cell square is clipped to the wedge's footprint in
//!   its frame; the highest point is at a vertex of the clipped polygon.
//!
//! Overlaps thinner than [`OVERLAP_EPS_M`] are ignored, so a footprint edge that lies on a
//! cell boundary (up to rounding of a rotation) does not bleed into the neighbouring cell.
//!
//! **Speed.** Each primitive visits only the cells its `footprint_bounds()` touches, so the
//! cost is the sum of the primitives' footprint areas in cells, not cells × primitives.

use super::heightmap::{HeightMap, HeightMapError};
use crate::scenario::terrain::{Primitive, Solid, terrain_height};

/// Overlaps between a footprint and a cell thinner than this are ignored (m): rounding
/// noise from rotations, far below any physical size.
pub const OVERLAP_EPS_M: f64 = 1e-9;

/// Why a rasterised height map could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RasteriseError {
    /// The map geometry is invalid.
    #[error(transparent)]
    Map(#[from] HeightMapError),
    /// The requested extent is not finite and positive.
    #[error("rasterised map size must be finite and > 0 m, got {x} x {y}")]
    BadSize {
        /// Size along x, m.
        x: f64,
        /// Size along y, m.
        y: f64,
    },
    /// A primitive has a non-finite or negative dimension.
    #[error("terrain primitive #{index} ({kind}) has a non-finite or negative dimension")]
    BadPrimitive {
        /// Index in the slice passed in.
        index: usize,
        /// Its kind, as in scenario files.
        kind: &'static str,
    },
}

/// Rasterises `primitives` onto a map whose cell (0, 0) has its corner at `origin`,
/// covering at least `size` (x, y) metres: `ceil(size / resolution)` cells per axis.
///
/// # Errors
/// Invalid geometry (see [`HeightMapError`]) or a malformed primitive.
pub fn rasterise(
    primitives: &[Primitive],
    origin: [f64; 2],
    size: [f64; 2],
    resolution: f64,
) -> Result<HeightMap, RasteriseError> {
    if !(size[0].is_finite() && size[1].is_finite() && size[0] > 0.0 && size[1] > 0.0) {
        return Err(RasteriseError::BadSize { x: size[0], y: size[1] });
    }
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(HeightMapError::BadResolution(resolution).into());
    }
    // The small slack keeps 20 m / 0.025 m at 800 cells despite rounding.
    let nx = (size[0] / resolution - 1e-9).ceil().max(1.0) as usize;
    let ny = (size[1] / resolution - 1e-9).ceil().max(1.0) as usize;
    let mut map = HeightMap::filled(origin, resolution, nx, ny, 0.0)?;
    rasterise_into(primitives, &mut map)?;
    Ok(map)
}

/// Raises every cell of `map` to the highest primitive surface over it (cells keep their
/// value where it is higher; unknown cells that a primitive overlaps become known).
///
/// # Errors
/// A malformed primitive.
pub fn rasterise_into(primitives: &[Primitive], map: &mut HeightMap) -> Result<(), RasteriseError> {
    for (index, p) in primitives.iter().enumerate() {
        check_primitive(index, p)?;
    }
    let res = map.resolution();
    let origin = map.origin();
    let (nx, ny) = map.dims();
    let mut data = map.as_slice().to_vec();
    for p in primitives {
        let b = p.footprint_bounds();
        let Some((i_range, j_range)) = cell_range(b, origin, res, nx, ny) else { continue };
        let mut visit = |cell_max: &dyn Fn([f64; 4]) -> Option<f64>| {
            for j in j_range.clone() {
                let y0 = origin[1] + j as f64 * res;
                for i in i_range.clone() {
                    let x0 = origin[0] + i as f64 * res;
                    if let Some(h) = cell_max([x0, y0, x0 + res, y0 + res]) {
                        let v = &mut data[j * nx + i];
                        // NaN (unknown) loses to any surface: f64::max returns the other.
                        *v = v.max(h);
                    }
                }
            }
        };
        for solid in p.solids() {
            match solid {
                Solid::Box { center, half_size, height, yaw } => {
                    let rect = Rect::new(center, half_size, yaw);
                    visit(&|cell| rect.overlaps_cell(cell).then_some(height));
                }
                Solid::Wedge { center, half_size, height, yaw } => {
                    let rect = Rect::new(center, half_size, yaw);
                    // The rise over the whole run, 2·half_size[0] (exact in binary).
                    let run = 2.0 * half_size[0];
                    visit(&|cell| {
                        rect.max_local_x_in_cell(cell).map(|lx| height * (lx / run + 0.5))
                    });
                }
                Solid::Cylinder { center, radius, height } => {
                    visit(&|cell| disc_overlaps_cell(center, radius, cell).then_some(height));
                }
            }
        }
    }
    *map = HeightMap::new(origin, res, nx, ny, data)?;
    Ok(())
}

fn check_primitive(index: usize, p: &Primitive) -> Result<(), RasteriseError> {
    if p.well_formed() {
        Ok(())
    } else {
        Err(RasteriseError::BadPrimitive { index, kind: p.kind() })
    }
}

/// The index ranges of cells that the bounds `[x_min, y_min, x_max, y_max]` touch.
fn cell_range(
    b: [f64; 4],
    origin: [f64; 2],
    res: f64,
    nx: usize,
    ny: usize,
) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
    let lo = |v: f64, o: f64| ((v - o) / res).floor().max(0.0);
    let hi = |v: f64, o: f64, n: usize| ((v - o) / res).floor().min(n as f64 - 1.0);
    let (i0, i1) = (lo(b[0], origin[0]), hi(b[2], origin[0], nx));
    let (j0, j1) = (lo(b[1], origin[1]), hi(b[3], origin[1], ny));
    (i0 <= i1 && j0 <= j1).then(|| (i0 as usize..i1 as usize + 1, j0 as usize..j1 as usize + 1))
}

/// A rectangle rotated by `yaw` about its centre.
struct Rect {
    center: [f64; 2],
    half: [f64; 2],
    /// Local x and y axes in world coordinates.
    axes: [[f64; 2]; 2],
}

impl Rect {
    fn new(center: [f64; 2], half: [f64; 2], yaw: f64) -> Self {
        let (s, c) = yaw.sin_cos();
        Self { center, half, axes: [[c, s], [-s, c]] }
    }

    /// Whether the rectangle and the cell `[x0, y0, x1, y1]` share an area: no separating
    /// axis among the four edge normals (world x, y and the local axes) with more than
    /// `OVERLAP_EPS_M` of overlap on each.
    fn overlaps_cell(&self, cell: [f64; 4]) -> bool {
        // Half-extents of the rectangle projected on world x and y.
        let ex = self.half[0] * self.axes[0][0].abs() + self.half[1] * self.axes[1][0].abs();
        let ey = self.half[0] * self.axes[0][1].abs() + self.half[1] * self.axes[1][1].abs();
        let overlap = |a0: f64, a1: f64, b0: f64, b1: f64| a1.min(b1) - a0.max(b0) > OVERLAP_EPS_M;
        if !overlap(self.center[0] - ex, self.center[0] + ex, cell[0], cell[2])
            || !overlap(self.center[1] - ey, self.center[1] + ey, cell[1], cell[3])
        {
            return false;
        }
        let (cx, cy) = ((cell[0] + cell[2]) / 2.0, (cell[1] + cell[3]) / 2.0);
        let (hw, hh) = ((cell[2] - cell[0]) / 2.0, (cell[3] - cell[1]) / 2.0);
        for (k, axis) in self.axes.iter().enumerate() {
            let c = (cx - self.center[0]) * axis[0] + (cy - self.center[1]) * axis[1];
            let r = hw * axis[0].abs() + hh * axis[1].abs();
            if !overlap(-self.half[k], self.half[k], c - r, c + r) {
                return false;
            }
        }
        true
    }

    /// The largest local x over the part of the cell inside the rectangle, if that part
    /// has an area: the cell is clipped to the rectangle in the local frame
    /// (Sutherland–Hodgman), and a linear function peaks at a vertex.
    fn max_local_x_in_cell(&self, cell: [f64; 4]) -> Option<f64> {
        if !self.overlaps_cell(cell) {
            return None;
        }
        let to_local = |x: f64, y: f64| {
            let (dx, dy) = (x - self.center[0], y - self.center[1]);
            [
                dx * self.axes[0][0] + dy * self.axes[0][1],
                dx * self.axes[1][0] + dy * self.axes[1][1],
            ]
        };
        let mut poly: Vec<[f64; 2]> = vec![
            to_local(cell[0], cell[1]),
            to_local(cell[2], cell[1]),
            to_local(cell[2], cell[3]),
            to_local(cell[0], cell[3]),
        ];
        // Keep the half-planes s·p[axis] <= half[axis].
        for (axis, sign) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)] {
            let limit = self.half[axis];
            let inside = |p: &[f64; 2]| sign * p[axis] <= limit;
            let mut out = Vec::with_capacity(poly.len() + 2);
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                match (inside(&a), inside(&b)) {
                    (true, true) => out.push(b),
                    (true, false) => out.push(cut(a, b, axis, sign * limit)),
                    (false, true) => {
                        out.push(cut(a, b, axis, sign * limit));
                        out.push(b);
                    }
                    (false, false) => {}
                }
            }
            poly = out;
            if poly.is_empty() {
                return None;
            }
        }
        poly.iter().map(|p| p[0].clamp(-self.half[0], self.half[0])).reduce(f64::max)
    }
}

/// The point on segment a–b where coordinate `axis` equals `value`.
fn cut(a: [f64; 2], b: [f64; 2], axis: usize, value: f64) -> [f64; 2] {
    let t = (value - a[axis]) / (b[axis] - a[axis]);
    let mut p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    p[axis] = value;
    p
}

/// Whether a disc and the cell `[x0, y0, x1, y1]` share an area: the closest point of the
/// cell to the centre is nearer than the radius (by more than `OVERLAP_EPS_M`).
fn disc_overlaps_cell(center: [f64; 2], radius: f64, cell: [f64; 4]) -> bool {
    let dx = center[0] - center[0].clamp(cell[0], cell[2]);
    let dy = center[1] - center[1].clamp(cell[1], cell[3]);
    let r = radius - OVERLAP_EPS_M;
    r > 0.0 && dx * dx + dy * dy < r * r
}

/// Lowest and highest terrain surface over cell (i, j) of `map`, sampled on an 11 × 11
/// grid that includes points a hair inside each edge. The minimum, with the rasterised value
/// (the exact highest surface), bounds what a sensor may legitimately report for the cell;
/// the maximum is a sampled lower bound of that rasterised value.
pub fn sampled_height_range(
    primitives: &[Primitive],
    map: &HeightMap,
    i: usize,
    j: usize,
) -> [f64; 2] {
    let o = map.origin();
    let res = map.resolution();
    let fr = |k: usize| match k {
        0 => 1e-7,
        10 => 1.0 - 1e-7,
        _ => k as f64 / 10.0,
    };
    let mut range = [f64::INFINITY, f64::NEG_INFINITY];
    for a in 0..=10 {
        for b in 0..=10 {
            let x = o[0] + (i as f64 + fr(a)) * res;
            let y = o[1] + (j as f64 + fr(b)) * res;
            let h = terrain_height(primitives, x, y);
            range = [range[0].min(h), range[1].max(h)];
        }
    }
    range
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::terrain::{Block, Pole, Ramp, Stairs};

    const RES: f64 = 0.025;

    #[test]
    fn axis_aligned_box_on_cell_boundaries_claims_exactly_its_cells() {
        // Box from x = 0.5 to 1.0 and y = -0.25 to 0.25: edges on cell boundaries.
        let b = Primitive::Box(Block {
            center: [0.75, 0.0],
            size: [0.5, 0.5],
            height: 0.2,
            yaw_deg: 0.0,
        });
        let m = rasterise(&[b], [0.0, -1.0], [2.0, 2.0], RES).unwrap();
        assert_eq!(m.dims(), (80, 80));
        // Cells 20..40 in x, 30..50 in y are on the box; their neighbours are ground.
        for j in 0..80 {
            for i in 0..80 {
                let inside = (20..40).contains(&i) && (30..50).contains(&j);
                assert_eq!(m.get(i, j), Some(if inside { 0.2 } else { 0.0 }), "({i},{j})");
            }
        }
    }

    #[test]
    fn box_edge_inside_a_cell_raises_the_whole_cell() {
        // Box from x = 0.51 (inside cell 20 = [0.5, 0.525)).
        let b = Primitive::Box(Block {
            center: [0.755, 0.0],
            size: [0.49, 0.5],
            height: 0.2,
            yaw_deg: 0.0,
        });
        let m = rasterise(&[b], [0.0, -1.0], [2.0, 2.0], RES).unwrap();
        assert_eq!(m.get(19, 40), Some(0.0));
        assert_eq!(m.get(20, 40), Some(0.2));
    }

    #[test]
    fn ramp_cell_holds_its_highest_point() {
        // Ramp from x = 0 (h 0) to x = 2 (h 0.2), axis-aligned: slope 0.1.
        let r = Primitive::Ramp(Ramp {
            center: [1.0, 0.0],
            size: [2.0, 1.0],
            height: 0.2,
            yaw_deg: 0.0,
        });
        let m = rasterise(&[r], [0.0, -1.0], [3.0, 2.0], RES).unwrap();
        // Cell i covers [i·0.025, (i+1)·0.025): max at its right edge, 0.1·(i+1)·0.025.
        for i in [0usize, 7, 79] {
            let h = m.get(i, 40).unwrap();
            assert!((h - 0.1 * (i + 1) as f64 * RES).abs() < 1e-12, "cell {i}: {h}");
        }
        assert_eq!(m.get(80, 40), Some(0.0), "past the high end is ground");
    }

    #[test]
    fn pole_is_a_disc_of_cells() {
        // Pole of radius 0.05 centred on a cell corner: exactly the 4 x 4 cells around.
        let p = Primitive::Pole(Pole { center: [0.5, 0.5], radius: 0.05, height: 0.4 });
        let m = rasterise(&[p], [0.0, 0.0], [1.0, 1.0], RES).unwrap();
        let raised: Vec<(usize, usize)> = (0..40)
            .flat_map(|j| (0..40).map(move |i| (i, j)))
            .filter(|&(i, j)| m.get(i, j) == Some(0.4))
            .collect();
        // Cells 18..22 in both axes: even the corner cells' nearest points are only
        // √2 · 0.025 ≈ 0.035 m from the axis. Cell 17 touches the disc at one point
        // (x = 0.45, distance exactly r): no area, not raised.
        assert_eq!(raised.len(), 16, "{raised:?}");
        assert!(
            raised.contains(&(18, 18))
                && !raised.contains(&(17, 19))
                && !raised.contains(&(22, 20))
        );
    }

    #[test]
    fn rotated_primitives_match_dense_sampling() {
        let ps = [
            Primitive::Box(Block {
                center: [0.7, 0.6],
                size: [0.6, 0.3],
                height: 0.15,
                yaw_deg: 27.0,
            }),
            Primitive::Ramp(Ramp {
                center: [1.6, 1.2],
                size: [1.0, 0.6],
                height: 0.3,
                yaw_deg: -40.0,
            }),
            Primitive::Stairs(Stairs {
                start: [0.3, 1.4],
                width: 0.5,
                steps: 3,
                step_depth: 0.2,
                step_height: 0.1,
                landing_depth: 0.1,
                yaw_deg: 100.0,
            }),
            Primitive::Pole(Pole { center: [1.5, 0.3], radius: 0.07, height: 0.5 }),
        ];
        let m = rasterise(&ps, [0.0, 0.0], [2.5, 2.5], RES).unwrap();
        let mut raised = 0;
        for j in 0..m.ny() {
            for i in 0..m.nx() {
                let exact = m.get(i, j).unwrap();
                let [_, sampled] = sampled_height_range(&ps, &m, i, j);
                // Sampling can only miss a sliver: never above the exact value, and within
                // a ramp's rise over a tenth of a cell diagonal of it for most cells.
                assert!(sampled <= exact + 1e-9, "({i},{j}) sampled {sampled} > {exact}");
                if exact > 0.0 {
                    raised += 1;
                }
                if (exact - sampled).abs() > 0.005 {
                    // A flat top overlapping the cell by less than a tenth of a cell.
                    let c = m.cell_center(i, j);
                    let near_edge = ps.iter().any(|p| {
                        let b = p.footprint_bounds();
                        c[0] > b[0] - RES
                            && c[0] < b[2] + RES
                            && c[1] > b[1] - RES
                            && c[1] < b[3] + RES
                    });
                    assert!(near_edge, "({i},{j}) exact {exact} sampled {sampled}");
                }
            }
        }
        assert!(raised > 500, "primitives were rasterised: {raised}");
    }

    #[test]
    fn unknown_cells_become_known_under_primitives() {
        let mut m = HeightMap::unknown([0.0, 0.0], RES, 10, 10).unwrap();
        let b = Primitive::Box(Block {
            center: [0.05, 0.05],
            size: [0.05, 0.05],
            height: 0.1,
            yaw_deg: 0.0,
        });
        rasterise_into(&[b], &mut m).unwrap();
        assert_eq!(m.get(1, 1), Some(0.1));
        assert_eq!(m.get(5, 5), None);
    }

    #[test]
    fn bad_input_is_rejected() {
        let b = Primitive::Box(Block {
            center: [f64::NAN, 0.0],
            size: [1.0, 1.0],
            height: 0.1,
            yaw_deg: 0.0,
        });
        assert_eq!(
            rasterise(&[b], [0.0, 0.0], [1.0, 1.0], RES),
            Err(RasteriseError::BadPrimitive { index: 0, kind: "box" })
        );
        assert!(matches!(
            rasterise(&[], [0.0, 0.0], [0.0, 1.0], RES),
            Err(RasteriseError::BadSize { .. })
        ));
        assert!(matches!(
            rasterise(&[], [0.0, 0.0], [1.0, 1.0], 0.0),
            Err(RasteriseError::Map(HeightMapError::BadResolution(_)))
        ));
    }

    #[test]
    fn twenty_metre_map_has_800_cells_a_side() {
        let m = rasterise(&[], [-10.0, -10.0], [20.0, 20.0], RES).unwrap();
        assert_eq!(m.dims(), (800, 800));
    }
}
