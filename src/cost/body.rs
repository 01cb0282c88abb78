//! Body cost C_B (paper eq. 3): clearance under the base and the slope between the feet.
//!
//! The base is approximated by two circles of radius `base_circle_radius_m` at
//! `RobotDescription::base_circle_centres_x` (Sec. IV).
//!
//! - **H_max,uB** for a circle: the highest cell whose centre lies within the circle's
//!   radius of the centre of the cell that holds the circle's centre. The maximum depends
//!   only on that cell, so one precomputed [`DiscMaxLayer`] serves every orientation and a
//!   query is a look-up per circle. The circle centre is thus quantised to its cell (at
//!   most res/√2 ≈ 1.8 cm off); cell heights are already the highest surface over each
//!   cell, so this errs on the safe side at edges. Any unknown (or off-map) cell in the
//!   disc makes the circle's maximum unknown.
//! - **H_B**, the height of the base's underside: each hip is at the ground height under
//!   its foot (the foot's cell) plus its leg height (hip-axis-to-ground distance). The
//!   underside is the line through the mean front-hip height (at the front hips' mean
//!   x') and the mean rear-hip height (at the rear hips' x'), lowered by
//!   `-base_bottom_z`, evaluated at each circle centre's x'. On level ground with equal
//!   leg heights this is `mean foot ground height + leg height + base_bottom_z`; when the
//!   legs pitch the base, each circle is compared with the underside above it.
//! - **ΔH_max,F**: highest minus lowest foot ground height.
//!
//! `C_B = 1 + k2 · max_circles(max(H_max,uB − H_B, 0)) + k3 · ΔH_max,F` (eq. 3). It is
//! never infinite; it is unknown when a foot's cell or a circle's disc is unknown.

use super::Cost;
use super::foot::{DiscRows, par_bands};
use crate::terrain::HeightMap;

/// For every cell, the highest terrain height among the cells whose centres lie within
/// a radius of its centre (`+∞` when any of them is unknown or off the map).
#[derive(Debug, Clone, PartialEq)]
pub struct DiscMaxLayer {
    nx: usize,
    ny: usize,
    radius: f64,
    values: Vec<f64>,
}

impl DiscMaxLayer {
    /// Computes the max over a disc of `radius` (closed) around every cell.
    ///
    /// Per row offset `dy` of the disc, a half-width `hw(dy)`. Sliding maxima of growing
    /// width are built incrementally per row (`m_w(x) = max(m_{w−1}(x), h(x−w), h(x+w))`),
    /// and each disc row takes its width's maximum from the row `dy` away: about
    /// `2·(R+1) + (2R+1)` comparisons per cell for a disc of R cells, exact.
    pub fn compute(map: &HeightMap, radius: f64) -> Self {
        let (nx, ny) = map.dims();
        let disc = DiscRows::closed(radius, map.resolution());
        let h = map.as_slice();
        let reach = disc.reach;
        let max_w = disc.rows.iter().map(|r| r.1).max().unwrap_or(0);
        let mut values = vec![f64::NEG_INFINITY; nx * ny];
        par_bands(&mut values, nx, ny, |y0, band| {
            let y1 = y0 + band.len() / nx;
            // Source rows this band needs, unknown as +∞, padded with +∞ (off the map)
            // by `max_w` on both sides so the sliding maxima need no bounds checks.
            let (s0, s1) = (y0.saturating_sub(reach), (y1 + reach).min(ny));
            let width = nx + 2 * max_w;
            let mut src = vec![f64::INFINITY; (s1 - s0) * width];
            for (prow, hrow) in src.chunks_mut(width).zip(h[s0 * nx..s1 * nx].chunks(nx)) {
                for (p, &v) in prow[max_w..max_w + nx].iter_mut().zip(hrow) {
                    *p = if v.is_nan() { f64::INFINITY } else { v };
                }
            }
            let mut m: Vec<f64> =
                src.chunks(width).flat_map(|r| r[max_w..max_w + nx].iter().copied()).collect();
            for w in 0..=max_w {
                if w > 0 {
                    for (mrow, prow) in m.chunks_mut(nx).zip(src.chunks(width)) {
                        let left = &prow[max_w - w..max_w - w + nx];
                        let right = &prow[max_w + w..max_w + w + nx];
                        for ((mv, &l), &r) in mrow.iter_mut().zip(left).zip(right) {
                            *mv = mv.max(l).max(r);
                        }
                    }
                }
                for &(dy, _) in disc.rows.iter().filter(|r| r.1 == w) {
                    for (y, out) in (y0..y1).zip(band.chunks_mut(nx)) {
                        let sy = y as isize + dy;
                        if sy < 0 || sy >= ny as isize {
                            out.fill(f64::INFINITY);
                            continue;
                        }
                        let k = sy as usize - s0;
                        for (o, &mv) in out.iter_mut().zip(&m[k * nx..(k + 1) * nx]) {
                            *o = o.max(mv);
                        }
                    }
                }
            }
        });
        Self { nx, ny, radius, values }
    }

    /// The maximum height around cell (i, j); `None` if unknown or off the layer.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> Option<f64> {
        if i < self.nx && j < self.ny {
            let v = self.values[j * self.nx + i];
            v.is_finite().then_some(v)
        } else {
            None
        }
    }

    /// The disc radius, m.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// `(nx, ny)`, as the height map.
    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }
}

/// Robot geometry and weights the body cost needs, read once from the model and params.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyGeometry {
    /// x' of the two base circles (front first), m.
    pub circle_x: [f64; 2],
    /// Mean x' of the front hips and of the rear hips, m.
    pub hip_x: [f64; 2],
    /// Height of the base's underside above the hip axes, m (negative: below).
    pub base_bottom_z: f64,
    /// Weight k2 (eq. 3).
    pub k2: f64,
    /// Weight k3 (eq. 3).
    pub k3: f64,
}

impl BodyGeometry {
    /// Underside height at x' given the front and rear mean hip heights (see module doc).
    #[inline]
    pub fn underside_at(&self, x: f64, front_hip_z: f64, rear_hip_z: f64) -> f64 {
        let span = self.hip_x[0] - self.hip_x[1];
        let hip_z = if span.abs() > 1e-9 {
            rear_hip_z + (front_hip_z - rear_hip_z) * (x - self.hip_x[1]) / span
        } else {
            0.5 * (front_hip_z + rear_hip_z)
        };
        hip_z + self.base_bottom_z
    }

    /// Eq. 3 from its inputs: the ground heights under the four feet (FL, FR, RL, RR),
    /// the leg heights, and the terrain maximum under each circle (front, rear).
    #[inline]
    pub fn cost(&self, ground: [f64; 4], leg_heights: &[f64; 4], under_circle: [f64; 2]) -> Cost {
        // Non-finite leg heights are a caller error; `f64::max` would hide a NaN, so
        // refuse them explicitly rather than let them into a cost.
        if !leg_heights.iter().all(|h| h.is_finite()) {
            return Cost::Unknown;
        }
        let hip = [0, 1, 2, 3].map(|k| ground[k] + leg_heights[k]);
        let front = 0.5 * (hip[0] + hip[1]);
        let rear = 0.5 * (hip[2] + hip[3]);
        let mut deficit = 0.0_f64;
        for (x, h_max) in self.circle_x.iter().zip(under_circle) {
            deficit = deficit.max(h_max - self.underside_at(*x, front, rear));
        }
        let (lo, hi) = ground
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &g| (lo.min(g), hi.max(g)));
        let c = 1.0 + self.k2 * deficit + self.k3 * (hi - lo);
        if c.is_finite() { Cost::Finite(c) } else { Cost::Unknown }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RES: f64 = 0.025;

    fn naive_disc_max(m: &HeightMap, r: f64, i: usize, j: usize) -> Option<f64> {
        let reach = (r / RES).ceil() as isize + 1;
        let mut best = f64::NEG_INFINITY;
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                if RES * ((dx * dx + dy * dy) as f64).sqrt() > r + 1e-9 {
                    continue;
                }
                let (x, y) = (i as isize + dx, j as isize + dy);
                if x < 0 || y < 0 {
                    return None;
                }
                best = best.max(m.get(x as usize, y as usize)?);
            }
        }
        Some(best)
    }

    #[test]
    fn disc_max_matches_naive() {
        let mut m = HeightMap::from_fn([0.0, 0.0], RES, 57, 43, |i, j| {
            ((i * 31 + j * 17) % 23) as f64 * 0.01
        })
        .unwrap();
        m.set(30, 20, f64::NAN).unwrap();
        for r in [0.0, 0.05, 0.1, 0.25] {
            let l = DiscMaxLayer::compute(&m, r);
            for j in 0..43 {
                for i in 0..57 {
                    assert_eq!(l.get(i, j), naive_disc_max(&m, r, i, j), "r {r} ({i},{j})");
                }
            }
        }
    }

    #[test]
    fn disc_max_of_a_spike_is_a_disc() {
        let mut m = HeightMap::filled([0.0, 0.0], RES, 50, 50, 0.0).unwrap();
        m.set(20, 20, 0.5).unwrap();
        let l = DiscMaxLayer::compute(&m, 0.25);
        // 0.25 m = 10 cells: (10, 0) and (6, 8) are in, (8, 7) (√113 > 10) is out.
        assert_eq!(l.get(30, 20), Some(0.5));
        assert_eq!(l.get(26, 28), Some(0.5));
        assert_eq!(l.get(28, 27), Some(0.0));
        assert_eq!(l.get(9, 20), None, "disc reaches off the map");
        assert_eq!(l.get(10, 20), Some(0.5));
    }

    #[test]
    fn underside_follows_the_hips() {
        let g = BodyGeometry {
            circle_x: [0.2, -0.2],
            hip_x: [0.3, -0.3],
            base_bottom_z: -0.05,
            k2: 1.0,
            k3: 0.5,
        };
        assert!((g.underside_at(0.0, 0.3, 0.3) - 0.25).abs() < 1e-12);
        // Front hips 0.2 m higher: at x' = 0.2 the line has risen 0.2 · (0.5/0.6).
        assert!((g.underside_at(0.2, 0.5, 0.3) - (0.3 + 0.2 * 0.5 / 0.6 - 0.05)).abs() < 1e-12);
        assert_eq!(g.cost([0.0; 4], &[f64::NAN; 4], [0.0, 0.0]), Cost::Unknown);
    }
}
