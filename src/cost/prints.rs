//! Fingerprints of the cost maps' rectangles that a translation by whole cells leaves
//! unchanged: two rectangles of the same size get the same print exactly when (up to a
//! collision, see below) every layer of [`CostMaps`] holds the same values in both, cell
//! by cell. The planner uses them to answer a step check from an earlier one at the same
//! stance on the same terrain elsewhere (`motion::manoeuvres::step`, "Translated step
//! failures"): a straight edge, a stair's riser or a wall is the same terrain along its
//! whole length.
//!
//! **How.** Each cell gets a 61-bit signature of all its layers (heights, the leg
//! terrains, the body's disc maximum, the foot cost at every heading; off the map a
//! constant of its own). A rectangle's print is the polynomial sum
//! `Σ v(i, j) · a^(i − i0) · b^(j − j0)` modulo the Mersenne prime `p = 2^61 − 1`, for two
//! independent base pairs (a, b). Prefix sums of `v · a^i · b^j` over the map, padded on
//! every side with off-map cells, give any rectangle's sum in four look-ups, and the
//! inverse powers of its corner move it to the origin: a print costs a few
//! multiplications, whatever its size.
//!
//! **Collisions.** For two different rectangles of `w × h` cells the two lanes agree with
//! probability at most `((w + h) / p)²` over the bases (two independent polynomial
//! identity tests), about 10⁻³² for the planner's windows: far below any other
//! uncertainty in the plan. Deterministic: the bases are constants.

use super::CostMaps;

/// The Mersenne prime 2^61 − 1.
const P: u64 = (1 << 61) - 1;

/// The bases (a, b) of the two lanes, arbitrary residues below `P`.
const BASES: [[u64; 2]; 2] = [
    [0x0a3b_195d_4c3f_8e21, 0x1c2e_7b55_9d04_6f13],
    [0x05f1_4d27_e83a_b6c9, 0x1367_0f8d_2a9b_51e5],
];

/// The signature of an off-map cell.
const OFF_MAP: u64 = 0x0f0f_1e2d_3c4b_5a69 % P;

fn mul(a: u64, b: u64) -> u64 {
    let z = u128::from(a) * u128::from(b);
    // 2^61 ≡ 1 (mod p): the high and low 61 bits add up to z modulo p.
    let s = (z as u64 & P) + (z >> 61) as u64;
    if s >= P { s - P } else { s }
}

fn add(a: u64, b: u64) -> u64 {
    let s = a + b;
    if s >= P { s - P } else { s }
}

fn sub(a: u64, b: u64) -> u64 {
    if a >= b { a - b } else { a + P - b }
}

fn pow(mut base: u64, mut e: u64) -> u64 {
    let mut r = 1;
    while e > 0 {
        if e & 1 == 1 {
            r = mul(r, base);
        }
        base = mul(base, base);
        e >>= 1;
    }
    r
}

/// A 64-bit mix (SplitMix64's finaliser) of one layer's bits into a running signature.
fn mix(h: u64, bits: u64) -> u64 {
    let mut z = (h ^ bits).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// One lane: prefix sums and the inverse powers of its bases.
#[derive(Clone)]
struct Lane {
    /// `(w + 1) × (h + 1)` row-major: the sum over cells `[0, i) × [0, j)` (padded
    /// coordinates) of `v · a^i · b^j`.
    prefix: Vec<u64>,
    inv_a: Vec<u64>,
    inv_b: Vec<u64>,
}

/// Translation-invariant rectangle prints of one [`CostMaps`] (module docs).
#[derive(Clone)]
pub struct TerrainPrints {
    /// Off-map cells kept on every side, cells.
    pad: usize,
    /// Padded width and height, cells.
    w: usize,
    h: usize,
    lanes: [Lane; 2],
}

impl std::fmt::Debug for TerrainPrints {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TerrainPrints").field("pad", &self.pad).field("w", &self.w).finish()
    }
}

impl TerrainPrints {
    /// The prints of `maps`, with `pad` cells of off-map terrain on every side (a
    /// rectangle reaching further out has no print).
    pub fn new(maps: &CostMaps, pad: usize) -> Self {
        let (nx, ny) = maps.heights().dims();
        let (w, h) = (nx + 2 * pad, ny + 2 * pad);
        let signature = |pi: usize, pj: usize| {
            let (i, j) = (pi.wrapping_sub(pad), pj.wrapping_sub(pad));
            if i < nx && j < ny { maps.cell_signature(i, j) % P } else { OFF_MAP }
        };
        let lanes = BASES.map(|[a, b]| {
            let mut prefix = vec![0u64; (w + 1) * (h + 1)];
            let mut b_pow = 1;
            for pj in 0..h {
                let mut row = 0;
                let mut a_pow = 1;
                for pi in 0..w {
                    row = add(row, mul(signature(pi, pj), mul(a_pow, b_pow)));
                    let above = prefix[pj * (w + 1) + pi + 1];
                    prefix[(pj + 1) * (w + 1) + pi + 1] = add(above, row);
                    a_pow = mul(a_pow, a);
                }
                b_pow = mul(b_pow, b);
            }
            let powers = |base: u64, n: usize| {
                let inv = pow(base, P - 2);
                std::iter::successors(Some(1), |&x| Some(mul(x, inv))).take(n).collect()
            };
            Lane { prefix, inv_a: powers(a, w), inv_b: powers(b, h) }
        });
        Self { pad, w, h, lanes }
    }

    /// The print of the map cells `i0..=i1` × `j0..=j1` (indices may lie off the map,
    /// within the padding), or `None` for an empty rectangle or one beyond the padding.
    pub fn print(&self, [i0, i1]: [i64; 2], [j0, j1]: [i64; 2]) -> Option<u128> {
        let pad = i64::try_from(self.pad).ok()?;
        let (x0, x1) = (usize::try_from(i0 + pad).ok()?, usize::try_from(i1 + pad).ok()?);
        let (y0, y1) = (usize::try_from(j0 + pad).ok()?, usize::try_from(j1 + pad).ok()?);
        if x0 > x1 || y0 > y1 || x1 >= self.w || y1 >= self.h {
            return None;
        }
        let lane = |l: &Lane| {
            let s = |x: usize, y: usize| l.prefix[y * (self.w + 1) + x];
            let sum = sub(add(s(x1 + 1, y1 + 1), s(x0, y0)), add(s(x0, y1 + 1), s(x1 + 1, y0)));
            mul(sum, mul(l.inv_a[x0], l.inv_b[y0]))
        };
        Some((u128::from(lane(&self.lanes[0])) << 64) | u128::from(lane(&self.lanes[1])))
    }
}

/// A cell's signature of the given layers' bits, for [`CostMaps::cell_signature`].
pub(super) fn signature(bits: impl IntoIterator<Item = u64>) -> u64 {
    bits.into_iter().fold(0, mix)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::robot::RobotDescription;
    use crate::scenario::terrain::{Block, Primitive};
    use crate::terrain::rasterise::rasterise;

    fn maps(prims: &[Primitive]) -> CostMaps {
        let map = rasterise(prims, [0.0, 0.0], [3.0, 2.0], 0.025).expect("map");
        CostMaps::build(&map, &RobotDescription::reference(), &Params::default()).expect("maps")
    }

    fn block(x: f64, y: f64) -> Primitive {
        Primitive::Box(Block { center: [x, y], size: [0.2, 0.3], height: 0.15, yaw_deg: 0.0 })
    }

    #[test]
    fn arithmetic_modulo_the_mersenne_prime() {
        assert_eq!(mul(P - 1, P - 1), 1, "(−1)² = 1");
        assert_eq!(mul(1 << 60, 4), 2, "2^62 = 2 · 2^61 ≡ 2");
        assert_eq!(add(P - 1, 1), 0);
        assert_eq!(sub(0, 1), P - 1);
        let a = BASES[0][0];
        assert_eq!(mul(a, pow(a, P - 2)), 1, "Fermat's inverse");
    }

    #[test]
    fn a_print_is_the_normalised_polynomial_of_its_cells() {
        // Against the sum written out for a 3 × 2 rectangle at (7, 11).
        let m = maps(&[block(0.3, 0.3)]);
        let prints = TerrainPrints::new(&m, 4);
        let [a, b] = BASES[0];
        let mut want = 0;
        for dj in 0..2u64 {
            for di in 0..3u64 {
                let v = m.cell_signature(7 + di as usize, 11 + dj as usize) % P;
                want = add(want, mul(v, mul(pow(a, di), pow(b, dj))));
            }
        }
        let got = prints.print([7, 9], [11, 12]).expect("inside");
        assert_eq!((got >> 64) as u64, want);
    }

    #[test]
    fn the_same_terrain_elsewhere_has_the_same_print_and_other_terrain_another() {
        // Two blocks 1.0 m (40 cells) apart along x and 0.5 m (20 cells) along y.
        let m = maps(&[block(0.7, 0.6), block(1.7, 1.1)]);
        let prints = TerrainPrints::new(&m, 10);
        let window = |i: i64, j: i64| prints.print([i - 8, i + 8], [j - 9, j + 9]);
        let (i, j) = ((0.7 / 0.025) as i64, (0.6 / 0.025) as i64);
        assert_eq!(window(i, j), window(i + 40, j + 20));
        assert_ne!(window(i, j), window(i + 41, j + 20), "shifted by a cell");
        assert_ne!(window(i, j), window(i + 40, j + 19), "shifted by a cell");
        // A window of other terrain, and one of the same size on flat ground.
        assert_ne!(window(i, j), window(i + 20, j));
        // Off the map: the padding's own signature, unlike flat ground at zero.
        assert_ne!(prints.print([-5, 3], [30, 40]), prints.print([60, 68], [30, 40]));
        assert!(prints.print([-10, 0], [0, 0]).is_some());
        assert_eq!(prints.print([-11, 0], [0, 0]), None, "beyond the padding");
        assert_eq!(prints.print([3, 2], [0, 0]), None, "empty");
    }

    #[test]
    fn prints_see_a_change_in_any_layer_of_a_cell() {
        // A 1 cm change of one cell's height changes its heights, foot cost and leg
        // terrain: the print of every window holding it changes, others do not.
        let low = maps(&[block(1.0, 1.0)]);
        let high = maps(&[
            block(1.0, 1.0),
            Primitive::Box(Block {
                center: [2.0125, 0.5125],
                size: [0.025, 0.025],
                height: 0.01,
                yaw_deg: 0.0,
            }),
        ]);
        let (pl, ph) = (TerrainPrints::new(&low, 0), TerrainPrints::new(&high, 0));
        assert_ne!(pl.print([70, 90], [10, 30]), ph.print([70, 90], [10, 30]));
        assert_eq!(pl.print([20, 60], [40, 70]), ph.print([20, 60], [40, 70]));
    }
}
