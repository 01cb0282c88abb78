//! Foot cost C_F (paper eq. 1–2): how hard the terrain around a cell is for a wheel pair.
//!
//! **ΔH.** The local unsigned height difference of a known cell is the largest absolute
//! height difference to its known 8-neighbours: `ΔH(c) = max_n |H(c) − H(n)|`. Unknown
//! neighbours and neighbours outside the map do not contribute (a cell with none known has
//! ΔH = 0); an unknown cell has no ΔH. The 8-neighbourhood catches diagonal steps and
//! single-cell spikes; on a plane of slope g it gives g·res (along the fall line) to
//! g·res·√2 (diagonal).
//!
//! **C_F of cell j** (distances `d` between cell centres):
//! 1. *Infinite* if a known cell with `d < r_F` has `ΔH > max_foot_height_diff_m` (eq. 2,
//!    first case). A known obstacle wins over unknown cells.
//! 2. else *Unknown* if a cell with `d < r_F` is unknown or outside the map: the foot's
//!    own footprint is not observed, so it could hide an obstacle.
//! 3. else `1 + k1 · Σ_{d < r_N} ΔH(c_i) · (1 − d / r_N)` (eq. 1 with eq. 2, second
//!    case), summing over known cells in the map; unknown cells beyond r_F add nothing.
//!
//! **Computation.** The whole layer is precomputed once, exactly:
//! - the r_F tests are disc dilations of the masks "ΔH > limit" and "unknown", done with
//!   per-row distances to the nearest masked cell, then one check per disc row;
//! - the weighted sum is accumulated per source row: in a row with few cells of ΔH > 0,
//!   each of them *scatters* `ΔH · w` onto the output rows its disc covers (contiguous
//!   slices); in a row with many, the whole row is convolved with each kernel row, one
//!   long shifted slice per weight (vectorises). Flat ground (typically most of a map)
//!   costs nothing. Either way the contributions reach each output cell in source
//!   row-major order, the order of the naive per-cell sum, so the result is bitwise
//!   identical to it (tested).
//!
//! Rows are split into bands computed on separate threads; each output cell's value does
//! not depend on the split, so results are deterministic.

use super::Cost;
use crate::params::Params;
use crate::terrain::HeightMap;

/// The precomputed foot cost C_F of every cell of a height map (same grid).
#[derive(Debug, Clone, PartialEq)]
pub struct FootCostLayer {
    nx: usize,
    ny: usize,
    /// Finite cost, `+∞` for infinite, `NaN` for unknown (internal only: read through
    /// [`FootCostLayer::get`], which returns a [`Cost`]).
    values: Vec<f64>,
    infinite: usize,
    unknown: usize,
}

impl FootCostLayer {
    /// Computes C_F for every cell of `map` (eq. 1–2, see the module doc).
    pub fn compute(map: &HeightMap, params: &Params) -> Self {
        let (nx, ny) = map.dims();
        let res = map.resolution();
        let dh = height_differences(map);
        let foot_disc = DiscRows::new(params.r_f_m, res);
        let near = DiscRows::new(params.r_n_m, res);
        let weights = near.weights(params.r_n_m, res);

        // Per row: distance (in cells) to the nearest "too high" and "unknown" cell.
        let too_high = |v: f64| v > params.max_foot_height_diff_m;
        let mut dist_high = vec![0u32; nx * ny];
        let mut dist_unknown = vec![0u32; nx * ny];
        par_rows(&mut dist_high, nx, |y, row| {
            row_distances(&dh[y * nx..(y + 1) * nx], too_high, false, row)
        });
        par_rows(&mut dist_unknown, nx, |y, row| {
            row_distances(&dh[y * nx..(y + 1) * nx], f64::is_nan, true, row)
        });

        let mut values = vec![0.0; nx * ny];
        par_bands(&mut values, nx, ny, |y0, band| {
            let y1 = y0 + band.len() / nx;
            scatter_weighted(&dh, nx, ny, &near, &weights, y0, y1, band);
            let (mut high, mut unknown) = (vec![false; nx], vec![false; nx]);
            for (y, row) in (y0..y1).zip(band.chunks_mut(nx)) {
                foot_disc_flags(
                    &dist_high,
                    &dist_unknown,
                    nx,
                    ny,
                    &foot_disc,
                    y,
                    &mut high,
                    &mut unknown,
                );
                for ((v, &h), &u) in row.iter_mut().zip(&high).zip(&unknown) {
                    *v = if h {
                        f64::INFINITY
                    } else if u {
                        f64::NAN
                    } else {
                        1.0 + params.k1 * *v
                    };
                }
            }
        });
        let infinite = values.iter().filter(|v| v.is_infinite()).count();
        let unknown = values.iter().filter(|v| v.is_nan()).count();
        Self { nx, ny, values, infinite, unknown }
    }

    /// C_F of cell (i, j); `Unknown` outside the layer.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> Cost {
        if i < self.nx && j < self.ny {
            Cost::from_raw(self.values[j * self.nx + i])
        } else {
            Cost::Unknown
        }
    }

    /// `(nx, ny)`, as the height map.
    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Number of cells with infinite C_F.
    pub fn infinite_count(&self) -> usize {
        self.infinite
    }

    /// Number of cells with unknown C_F.
    pub fn unknown_count(&self) -> usize {
        self.unknown
    }

    /// Raw row-major value, `+∞` infinite, `NaN` unknown (crate-internal fast path).
    #[inline]
    pub(crate) fn raw(&self, k: usize) -> f64 {
        self.values[k]
    }
}

/// ΔH of every cell, row-major (`NaN` for unknown cells): the largest absolute height
/// difference to the known 8-neighbours (0 when none is known).
pub fn height_differences(map: &HeightMap) -> Vec<f64> {
    let (nx, ny) = map.dims();
    let h = map.as_slice();
    let mut out = vec![0.0; nx * ny];
    // Whole-row slices, shifted by one for the left and right neighbours, so the loops
    // vectorise. `f64::max` ignores the NaN difference to an unknown neighbour.
    par_rows(&mut out, nx, |y, row| {
        let c = &h[y * nx..(y + 1) * nx];
        for yy in y.saturating_sub(1)..(y + 2).min(ny) {
            let n = &h[yy * nx..(yy + 1) * nx];
            max_abs_diff(row, c, n);
            if nx > 1 {
                max_abs_diff(&mut row[1..], &c[1..], &n[..nx - 1]);
                max_abs_diff(&mut row[..nx - 1], &c[..nx - 1], &n[1..]);
            }
        }
        for (o, &cv) in row.iter_mut().zip(c) {
            if cv.is_nan() {
                *o = f64::NAN;
            }
        }
    });
    out
}

/// `out[x] = max(out[x], |a[x] − b[x]|)`, NaN differences ignored.
fn max_abs_diff(out: &mut [f64], a: &[f64], b: &[f64]) {
    for ((o, &x), &y) in out.iter_mut().zip(a).zip(b) {
        *o = o.max((x - y).abs());
    }
}

/// The rows of a disc of cells: for each row offset `dy`, the half-width `hw` such that
/// offsets `(dx, dy)` with `|dx| <= hw` have centre distance `res·√(dx²+dy²) < r`.
#[derive(Debug, Clone)]
pub(crate) struct DiscRows {
    /// `(dy, hw)` for every row that holds at least one cell, `dy` ascending.
    pub(crate) rows: Vec<(isize, usize)>,
    /// Largest `|dy|`.
    pub(crate) reach: usize,
}

/// Distance between the centres of cells `(dx, dy)` apart, m: the one expression used by
/// every disc test in this module (and by the reference implementation in the tests).
#[inline]
pub(crate) fn cell_distance(dx: isize, dy: isize, res: f64) -> f64 {
    res * ((dx * dx + dy * dy) as f64).sqrt()
}

impl DiscRows {
    /// Cells at centre distance `< r` (strict, as in eq. 2).
    pub(crate) fn new(r: f64, res: f64) -> Self {
        Self::with_test(res, r, |d| d < r)
    }

    /// Cells at centre distance `<= r` (plus 1 nm against rounding).
    pub(crate) fn closed(r: f64, res: f64) -> Self {
        Self::with_test(res, r, |d| d <= r + 1e-9)
    }

    fn with_test(res: f64, r: f64, inside: impl Fn(f64) -> bool) -> Self {
        // Bound the search: r is validated finite, and a disc wider than 10⁴ cells is
        // not a foot or a base.
        let max = ((r / res).ceil() as usize).saturating_add(1).min(10_000) as isize;
        let mut rows = Vec::new();
        for dy in -max..=max {
            let mut hw = None;
            for dx in 0..=max {
                if inside(cell_distance(dx, dy, res)) {
                    hw = Some(dx as usize);
                } else {
                    break;
                }
            }
            if let Some(hw) = hw {
                rows.push((dy, hw));
            }
        }
        let reach = rows.iter().map(|&(dy, _)| dy.unsigned_abs()).max().unwrap_or(0);
        Self { rows, reach }
    }

    /// Cone weights `1 − d/r` for each row, indexed by `dx + hw` (eq. 2, second case).
    fn weights(&self, r: f64, res: f64) -> Vec<Vec<f64>> {
        self.rows
            .iter()
            .map(|&(dy, hw)| {
                let hw = hw as isize;
                (-hw..=hw).map(|dx| 1.0 - cell_distance(dx, dy, res) / r).collect()
            })
            .collect()
    }
}

/// Per-row distance (in cells, capped) from each cell to the nearest cell whose ΔH
/// satisfies `pred`; with `outside_counts`, the cells just past both row ends count too.
fn row_distances(dh: &[f64], pred: impl Fn(f64) -> bool, outside_counts: bool, out: &mut [u32]) {
    const FAR: u32 = u32::MAX / 2;
    let n = dh.len();
    // The cell just past the row end is at distance 1 from the end cell.
    let mut last = if outside_counts { 0 } else { FAR };
    for x in 0..n {
        last = if pred(dh[x]) { 0 } else { last.saturating_add(1) };
        out[x] = last;
    }
    let mut last = if outside_counts { 0 } else { FAR };
    for x in (0..n).rev() {
        last = if pred(dh[x]) { 0 } else { last.saturating_add(1) };
        out[x] = out[x].min(last);
    }
}

/// For every cell of row `y`: whether its r_F disc holds a too-high cell (`high`) and
/// whether it holds an unknown or off-map cell (`unknown`). Row-wise, so it vectorises.
#[allow(clippy::too_many_arguments)]
fn foot_disc_flags(
    dist_high: &[u32],
    dist_unknown: &[u32],
    nx: usize,
    ny: usize,
    disc: &DiscRows,
    y: usize,
    high: &mut [bool],
    unknown: &mut [bool],
) {
    high.fill(false);
    unknown.fill(false);
    for &(dy, hw) in &disc.rows {
        let yy = y as isize + dy;
        if yy < 0 || yy >= ny as isize {
            unknown.fill(true);
            continue;
        }
        let hw = u32::try_from(hw).unwrap_or(u32::MAX);
        let k = yy as usize * nx;
        for (f, &d) in high.iter_mut().zip(&dist_high[k..k + nx]) {
            *f |= d <= hw;
        }
        for (f, &d) in unknown.iter_mut().zip(&dist_unknown[k..k + nx]) {
            *f |= d <= hw;
        }
    }
}

/// Adds `Σ ΔH(i)·w(i)` over the r_N disc into the band of output rows `[y0, y1)`
/// (`band` starts zeroed).
///
/// Per source row: when few cells have ΔH > 0, each of them scatters its weighted disc
/// (cost ∝ non-zero cells); when many do, the row is convolved densely with each kernel
/// row, one long shifted slice at a time. Both add the contributions to an output cell
/// in ascending source column order (zero sources add exactly +0), so both give the
/// same bits as the naive sum.
#[allow(clippy::too_many_arguments)]
fn scatter_weighted(
    dh: &[f64],
    nx: usize,
    ny: usize,
    disc: &DiscRows,
    weights: &[Vec<f64>],
    y0: usize,
    y1: usize,
    band: &mut [f64],
) {
    let reach = disc.reach;
    let sy_end = (y1 + reach).min(ny);
    // Unknown (NaN) and flat cells add nothing: a cleaned copy of the source row.
    let mut src = vec![0.0; nx];
    let mut nonzero = Vec::with_capacity(nx);
    for sy in y0.saturating_sub(reach)..sy_end {
        nonzero.clear();
        for (sx, (s, &v)) in src.iter_mut().zip(&dh[sy * nx..(sy + 1) * nx]).enumerate() {
            *s = if v > 0.0 { v } else { 0.0 };
            if v > 0.0 {
                nonzero.push(sx);
            }
        }
        if nonzero.is_empty() {
            continue;
        }
        let dense = nonzero.len() * 4 > nx;
        for (&(dy, hw), w) in disc.rows.iter().zip(weights) {
            let oy = sy as isize + dy;
            if oy < y0 as isize || oy >= y1 as isize {
                continue;
            }
            let out = &mut band[(oy as usize - y0) * nx..(oy as usize - y0 + 1) * nx];
            if dense {
                convolve_row(out, &src, w, hw);
            } else {
                scatter_row(out, &src, &nonzero, w, hw);
            }
        }
    }
}

/// `out[x] += Σ_dx src[x + dx] · w[dx + hw]`, dx ascending, clipped to the row.
fn convolve_row(out: &mut [f64], src: &[f64], w: &[f64], hw: usize) {
    let n = out.len();
    for (k, &wk) in w.iter().enumerate() {
        if k >= hw {
            let dx = k - hw;
            if dx >= n {
                continue;
            }
            for (o, &s) in out[..n - dx].iter_mut().zip(&src[dx..]) {
                *o += s * wk;
            }
        } else {
            let dx = hw - k;
            if dx >= n {
                continue;
            }
            for (o, &s) in out[dx..].iter_mut().zip(&src[..n - dx]) {
                *o += s * wk;
            }
        }
    }
}

/// Each non-zero `src[sx]` (`sx` in `nonzero`, ascending) adds `src[sx] · w` to
/// `out[sx − hw ..= sx + hw]`, clipped.
fn scatter_row(out: &mut [f64], src: &[f64], nonzero: &[usize], w: &[f64], hw: usize) {
    let n = out.len();
    for &sx in nonzero {
        let v = src[sx];
        let lo = sx.saturating_sub(hw);
        let hi = (sx + hw + 1).min(n);
        let w0 = lo + hw - sx;
        for (o, &wk) in out[lo..hi].iter_mut().zip(&w[w0..w0 + (hi - lo)]) {
            *o += v * wk;
        }
    }
}

/// Number of worker threads for layer builds (results do not depend on it).
pub(crate) fn worker_count() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, 8)
}

/// Runs `f(y0, band)` on bands of whole rows of `out` (row length `nx`), in parallel.
pub(crate) fn par_bands<T: Send>(
    out: &mut [T],
    nx: usize,
    ny: usize,
    f: impl Fn(usize, &mut [T]) + Sync,
) {
    let workers = worker_count().min(ny.max(1));
    let rows_per = ny.div_ceil(workers).max(1);
    if workers <= 1 || ny * nx < 4096 {
        f(0, out);
        return;
    }
    std::thread::scope(|s| {
        for (b, band) in out.chunks_mut(rows_per * nx).enumerate() {
            let f = &f;
            s.spawn(move || f(b * rows_per, band));
        }
    });
}

/// Runs `f(y, row)` for every row of `out`, rows spread over threads.
pub(crate) fn par_rows<T: Send>(out: &mut [T], nx: usize, f: impl Fn(usize, &mut [T]) + Sync) {
    let ny = out.len() / nx.max(1);
    par_bands(out, nx, ny, |y0, band| {
        for (k, row) in band.chunks_mut(nx).enumerate() {
            f(y0 + k, row);
        }
    });
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use proptest::prelude::*;

    const RES: f64 = 0.025;

    /// The paper's definition, cell by cell, with no tricks: the reference the fast
    /// layer must match.
    pub(crate) fn naive_foot_cost(map: &HeightMap, p: &Params) -> Vec<Cost> {
        let (nx, ny) = map.dims();
        let res = map.resolution();
        let dh = height_differences(map);
        let reach = (p.r_n_m.max(p.r_f_m) / res).ceil() as isize + 1;
        let mut out = Vec::with_capacity(nx * ny);
        for y in 0..ny as isize {
            for x in 0..nx as isize {
                let (mut high, mut unknown, mut sum) = (false, false, 0.0);
                for iy in y - reach..=y + reach {
                    for ix in x - reach..=x + reach {
                        let d = cell_distance(ix - x, iy - y, res);
                        let inside = ix >= 0 && iy >= 0 && ix < nx as isize && iy < ny as isize;
                        let v = if inside { dh[iy as usize * nx + ix as usize] } else { f64::NAN };
                        if d < p.r_f_m {
                            high |= v > p.max_foot_height_diff_m;
                            unknown |= v.is_nan();
                        }
                        if d < p.r_n_m && !v.is_nan() {
                            sum += v * (1.0 - d / p.r_n_m);
                        }
                    }
                }
                out.push(if high {
                    Cost::Infinite
                } else if unknown {
                    Cost::Unknown
                } else {
                    Cost::Finite(1.0 + p.k1 * sum)
                });
            }
        }
        out
    }

    fn layer(map: &HeightMap) -> FootCostLayer {
        FootCostLayer::compute(map, &Params::default())
    }

    fn flat_with(nx: usize, ny: usize, f: impl Fn(usize, usize) -> f64) -> HeightMap {
        HeightMap::from_fn([0.0, 0.0], RES, nx, ny, f).unwrap()
    }

    #[test]
    fn disc_rows_match_the_definition() {
        let d = DiscRows::new(0.12, RES);
        // 0.12 / 0.025 = 4.8 cells: rows -4..=4; row 0 half-width 4; row ±4: dx² < 23.04 - 16.
        assert_eq!(d.reach, 4);
        assert_eq!(d.rows.iter().find(|r| r.0 == 0), Some(&(0, 4)));
        assert_eq!(d.rows.iter().find(|r| r.0 == 4), Some(&(4, 2)));
        assert_eq!(d.rows.iter().find(|r| r.0 == 3), Some(&(3, 3)));
        let n = DiscRows::new(0.3, RES);
        // d < 0.3 m = 12 cells: (12, 0) is excluded, (11, 4) is in (137 < 144).
        assert_eq!(n.reach, 11);
        assert_eq!(n.rows.iter().find(|r| r.0 == 0), Some(&(0, 11)));
        assert_eq!(n.rows.iter().find(|r| r.0 == 4), Some(&(4, 11)));
    }

    #[test]
    fn delta_h_is_max_abs_difference_to_known_eight_neighbours() {
        let mut m = flat_with(4, 4, |_, _| 0.0);
        m.set(1, 1, 0.3).unwrap();
        m.set(3, 3, -0.1).unwrap();
        m.set(3, 0, f64::NAN).unwrap();
        let dh = height_differences(&m);
        let at = |i: usize, j: usize| dh[j * 4 + i];
        assert_eq!(at(1, 1), 0.3);
        assert_eq!(at(0, 0), 0.3, "diagonal neighbour counts");
        assert_eq!(at(2, 2), 0.3, "max over both raised neighbours");
        assert_eq!(at(3, 2), 0.1);
        assert!(at(3, 0).is_nan(), "unknown cell has no ΔH");
        assert_eq!(at(2, 0), 0.3, "unknown neighbour (3,0) ignored");
        assert_eq!(at(3, 1), 0.0, "no difference to its known neighbours");
    }

    #[test]
    fn flat_ground_costs_exactly_one() {
        let m = flat_with(60, 50, |_, _| 0.37);
        let l = layer(&m);
        // Cells within r_F of the border see off-map cells: unknown. 0.12 m = 4.8 cells,
        // so cells 0..=3 from each side are unknown (4 cells away: d = 0.125 >= r_F).
        assert_eq!(l.get(30, 25), Cost::Finite(1.0));
        assert_eq!(l.get(4, 4), Cost::Finite(1.0));
        assert_eq!(l.get(3, 25), Cost::Unknown);
        assert_eq!(l.get(30, 46), Cost::Unknown);
        assert_eq!(l.get(30, 45), Cost::Finite(1.0));
        assert_eq!(l.unknown_count(), 60 * 50 - 52 * 42);
        assert_eq!(l.infinite_count(), 0);
    }

    /// A straight step of height `h` along x = 1.0 m (cells i >= 40 raised).
    fn step_map(h: f64) -> HeightMap {
        flat_with(80, 60, |i, _| if i >= 40 { h } else { 0.0 })
    }

    #[test]
    fn edge_over_the_limit_within_r_f_is_infinite() {
        let l = layer(&step_map(0.06));
        // ΔH = 0.06 in columns 39 and 40. Column 35: nearest is 4 cells = 0.1 m < 0.12.
        assert_eq!(l.get(35, 30), Cost::Infinite);
        assert_eq!(l.get(44, 30), Cost::Infinite);
        // Column 34: 5 cells = 0.125 m >= r_F: finite.
        assert!(matches!(l.get(34, 30), Cost::Finite(_)));
        assert!(matches!(l.get(45, 30), Cost::Finite(_)));
    }

    #[test]
    fn edge_below_the_limit_gives_the_hand_computed_weighted_sum() {
        let l = layer(&step_map(0.04));
        assert!(matches!(l.get(39, 30), Cost::Finite(_)), "0.04 <= 0.05 is traversable");
        // Cell (34, 30): the edge cells (ΔH = 0.04) are columns 39 (dx = 5) and 40
        // (dx = 6). Within r_N = 12 cells: column 39 rows dy with 25 + dy² < 144, i.e.
        // |dy| <= 10; column 40 with 36 + dy² < 144, |dy| <= 10.
        // C_F = 1 + 100 · 0.04 · Σ (1 − 0.025·√(dx² + dy²) / 0.3).
        let mut s = 0.0;
        for dx in [5.0_f64, 6.0] {
            for dy in -10..=10 {
                let d = 0.025 * (dx * dx + f64::from(dy * dy)).sqrt();
                s += 1.0 - d / 0.3;
            }
        }
        let expected = 1.0 + 100.0 * 0.04 * s;
        // Σ_dy (1 − √(25+dy²)/12) ≈ 7.565 and Σ_dy (1 − √(36+dy²)/12) ≈ 6.613, so
        // s ≈ 14.178 and C_F ≈ 1 + 4 · 14.178 = 57.712.
        assert!((s - 14.17798).abs() < 1e-5, "hand sum {s}");
        assert!((expected - 57.71193).abs() < 1e-4, "{expected}");
        match l.get(34, 30) {
            Cost::Finite(c) => assert!((c - expected).abs() < 1e-9, "{c} vs {expected}"),
            other => panic!("{other:?}"),
        }
        // Right on the edge, all 0.04 cells within r_N add up: still finite.
        assert!(matches!(l.get(40, 30), Cost::Finite(c) if c > expected));
        // 13 columns away (> r_N): back to exactly 1.
        assert_eq!(l.get(26, 30), Cost::Finite(1.0));
    }

    #[test]
    fn unknown_near_the_foot_is_unknown_but_a_known_obstacle_wins() {
        let mut m = flat_with(60, 60, |_, _| 0.0);
        m.set(30, 30, f64::NAN).unwrap();
        let l = layer(&m);
        assert_eq!(l.get(30, 30), Cost::Unknown);
        assert_eq!(l.get(34, 30), Cost::Unknown, "4 cells = 0.1 m < r_F");
        assert_eq!(l.get(35, 30), Cost::Finite(1.0), "unknown beyond r_F adds nothing");
        m.set(32, 30, 0.2).unwrap();
        let l = layer(&m);
        assert_eq!(l.get(30, 30), Cost::Infinite);
        assert_eq!(l.get(34, 30), Cost::Infinite);
    }

    #[test]
    fn fast_layer_matches_naive_on_a_varied_map() {
        let mut m = flat_with(70, 55, |i, j| {
            let (x, y) = (i as f64, j as f64);
            if i > 45 {
                0.3
            } else if j > 40 {
                0.002 * x
            } else {
                0.01 * ((x * 0.7).sin() + (y * 0.3).cos())
            }
        });
        for k in 0..30 {
            m.set((k * 37) % 70, (k * 11) % 55, f64::NAN).unwrap();
        }
        let p = Params::default();
        let fast = FootCostLayer::compute(&m, &p);
        let naive = naive_foot_cost(&m, &p);
        let mut finite = 0;
        for j in 0..55 {
            for i in 0..70 {
                let (a, b) = (fast.get(i, j), naive[j * 70 + i]);
                match (a, b) {
                    (Cost::Finite(x), Cost::Finite(y)) => {
                        finite += 1;
                        assert!((x - y).abs() <= 1e-9, "({i},{j}) {x} vs {y}");
                        assert_eq!(x.to_bits(), y.to_bits(), "same summation order");
                    }
                    _ => assert_eq!(a, b, "({i},{j})"),
                }
            }
        }
        assert!(finite > 500 && fast.infinite_count() > 100 && fast.unknown_count() > 100);
    }

    #[test]
    fn result_does_not_depend_on_banding() {
        // A map big enough to be split across threads equals one computed row by row.
        let m = flat_with(100, 90, |i, j| 0.01 * ((i * 7 + j * 13) % 11) as f64);
        let p = Params::default();
        let fast = FootCostLayer::compute(&m, &p);
        let naive = naive_foot_cost(&m, &p);
        for (k, c) in naive.iter().enumerate() {
            assert_eq!(fast.get(k % 100, k / 100), *c);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn fast_equals_naive_on_random_maps(
            nx in 1usize..40,
            ny in 1usize..40,
            seed in any::<u64>(),
            r_f in 0.03f64..0.2,
            r_n in 0.03f64..0.35,
        ) {
            let mut s = seed | 1;
            let mut next = move || { s ^= s << 13; s ^= s >> 7; s ^= s << 17; s };
            let m = HeightMap::from_fn([0.3, -0.2], RES, nx, ny, |_, _| {
                let r = next();
                match r % 10 {
                    0 => f64::NAN,
                    1..=4 => 0.0,
                    _ => (r >> 20) as f64 / (1u64 << 44) as f64 * 0.08,
                }
            }).unwrap();
            let p = Params { r_f_m: r_f, r_n_m: r_n, ..Params::default() };
            let fast = FootCostLayer::compute(&m, &p);
            let naive = naive_foot_cost(&m, &p);
            for (k, c) in naive.iter().enumerate() {
                let f = fast.get(k % nx, k / nx);
                match (f, *c) {
                    (Cost::Finite(a), Cost::Finite(b)) => prop_assert!((a - b).abs() <= 1e-9),
                    _ => prop_assert_eq!(f, *c),
                }
            }
        }
    }
}
