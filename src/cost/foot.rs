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
//!
//! **The wheel-pair foot model** (`Params::foot_model = wheel_pair`, [`FootCostLayer::wheel_pair`]).
//! The paper's r_F disc stands for a foot of unknown heading; Momaro's foot is a pair of
//! wheels side by side, and a tread between two risers fits it lengthwise long before it
//! fits the disc (a 0.29 m tread keeps 2 cells for the disc, 4 for the wheel pair along
//! the fall line). Case 1 above becomes, per foot heading φ:
//! - *Infinite at φ* if a known cell with `ΔH > max_foot_height_diff_m` lies under a wheel:
//!   its centre closer than the wheel radius r_w to one of the two wheel centres, which
//!   sit at `±track/2` along the axle `(−sin φ, cos φ)` (the model's wheels are spheres:
//!   a sphere within r_w of a step edge rests on the edge, not on the tread);
//! - else *unknown at φ* if such a cell is unknown or off the map;
//! - else the paper's sum (case 3, r_N unchanged: the same neighbourhood pays for nearby
//!   edges, so a foot placed close to a riser costs more than one mid-tread).
//!
//! The footprint is symmetric under a half turn, so φ is binned into
//! `min(orientations / 2, 64)` bins over [0, π): with the paper's 64 orientations every
//! lattice heading has its own bin. A foot's heading is the base heading: the wheels stand
//! straight while stepping and driving forward (see `CostMaps::pose_cost` for what the
//! planner assumes). ΔH marks both sides of an edge, so a wheel keeps at least one cell
//! (2.5 cm) plus the rest of its radius from the edge itself: a margin for the foot's
//! placement, not a tuned number.
//!
//! [`FootCostLayer::get`] of a wheel-pair layer is the foot cost at the cell's most
//! favourable heading (finite if any heading fits): a lower bound of every heading's, for
//! relaxations (heuristic, reachability) and images. Poses use [`FootCostLayer::get_at`].

use super::Cost;
use crate::params::Params;
use crate::terrain::HeightMap;

/// The two wheels of a foot, as the model gives them (`RobotDescription::wheel_radius`
/// and `wheel_track`): what the wheel-pair foot model rests on the terrain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelPair {
    /// Wheel radius r_w, m.
    pub radius: f64,
    /// Distance between the two wheel centres along the axle, m.
    pub track: f64,
}

/// A foot heading's bin in a [`FootCostLayer`] (see [`FootCostLayer::heading_bin`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeadingBin(usize);

impl HeadingBin {
    /// The bin's index (0 for every heading in the paper's model).
    pub fn index(self) -> usize {
        self.0
    }
}

/// Most heading bins a wheel-pair layer keeps (one bit each per cell).
const MAX_BINS: usize = 64;

/// The wheel-pair model's per-heading flags (see the module doc).
#[derive(Debug, Clone, PartialEq)]
struct HeadingFlags {
    /// Number of bins over [0, π).
    bins: usize,
    /// Per cell, bit `b`: a too-high cell lies under a wheel at heading bin `b`.
    infinite: Vec<u64>,
    /// Per cell, bit `b`: an unknown or off-map cell lies under a wheel at bin `b`.
    unknown: Vec<u64>,
    /// Per cell, the paper's finite value `1 + k1 · Σ` (eq. 1, eq. 2 second case), used
    /// at the headings whose bits are clear.
    finite: Vec<f64>,
}

/// The precomputed foot cost C_F of every cell of a height map (same grid).
#[derive(Debug, Clone, PartialEq)]
pub struct FootCostLayer {
    nx: usize,
    ny: usize,
    /// Finite cost, `+∞` for infinite, `NaN` for unknown (internal only: read through
    /// [`FootCostLayer::get`], which returns a [`Cost`]). For the wheel-pair model, the
    /// value at the most favourable heading.
    values: Vec<f64>,
    infinite: usize,
    unknown: usize,
    /// Per-heading flags of the wheel-pair model; `None` for the paper's model, whose
    /// cost does not depend on the heading.
    headings: Option<HeadingFlags>,
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
        let (dist_high, dist_unknown) = row_obstacle_distances(&dh, nx, ny, params);

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
        Self { nx, ny, values, infinite, unknown, headings: None }
    }

    /// C_F for every cell of `map` with the wheel-pair foot model (eq. 1–2 with the
    /// wheels' footprint at each heading in place of the r_F disc; see the module doc).
    /// `params.r_f_m` is not used; `params.orientations` sets the heading bins.
    pub fn wheel_pair(map: &HeightMap, params: &Params, wheels: WheelPair) -> Self {
        let (nx, ny) = map.dims();
        let res = map.resolution();
        let dh = height_differences(map);
        let near = DiscRows::new(params.r_n_m, res);
        let weights = near.weights(params.r_n_m, res);
        let mut sums = vec![0.0; nx * ny];
        par_bands(&mut sums, nx, ny, |y0, band| {
            let y1 = y0 + band.len() / nx;
            scatter_weighted(&dh, nx, ny, &near, &weights, y0, y1, band);
            for v in band.iter_mut() {
                *v = 1.0 + params.k1 * *v;
            }
        });

        let bins = usize::try_from(params.orientations / 2).unwrap_or(MAX_BINS).clamp(1, MAX_BINS);
        let shapes: Vec<Footprint> =
            (0..bins).map(|b| Footprint::new(wheels, bin_angle(b, bins), res)).collect();
        // Which cells need the per-heading test at all: those whose bounding disc (every
        // heading's footprint lies inside it) holds a too-high or unknown cell.
        let bound = DiscRows::new(wheels.track / 2.0 + wheels.radius, res);
        let (dist_high, dist_unknown) = row_obstacle_distances(&dh, nx, ny, params);
        // Per row, prefix counts of too-high and of unknown cells: a footprint row's
        // interval is then tested in O(1).
        let prefix = |pred: &dyn Fn(f64) -> bool| -> Vec<u32> {
            let mut p = vec![0u32; ny * (nx + 1)];
            for y in 0..ny {
                let row = &mut p[y * (nx + 1)..(y + 1) * (nx + 1)];
                for x in 0..nx {
                    row[x + 1] = row[x] + u32::from(pred(dh[y * nx + x]));
                }
            }
            p
        };
        let pre_high = prefix(&|v: f64| v > params.max_foot_height_diff_m);
        let pre_unknown = prefix(&|v: f64| v.is_nan());

        // Flags per cell: (infinite bits, unknown bits).
        let mut flags = vec![(0u64, 0u64); nx * ny];
        par_bands(&mut flags, nx, ny, |y0, band| {
            let y1 = y0 + band.len() / nx;
            let (mut high, mut unknown) = (vec![false; nx], vec![false; nx]);
            for (y, row) in (y0..y1).zip(band.chunks_mut(nx)) {
                foot_disc_flags(
                    &dist_high,
                    &dist_unknown,
                    nx,
                    ny,
                    &bound,
                    y,
                    &mut high,
                    &mut unknown,
                );
                for (x, f) in row.iter_mut().enumerate() {
                    if !(high[x] || unknown[x]) {
                        continue;
                    }
                    for (b, shape) in shapes.iter().enumerate() {
                        let (h, u) = shape.test(&pre_high, &pre_unknown, nx, ny, x, y);
                        f.0 |= u64::from(h) << b;
                        f.1 |= u64::from(u) << b;
                    }
                }
            }
        });

        let all = if bins == 64 { u64::MAX } else { (1u64 << bins) - 1 };
        // The most favourable heading: finite if one is, else unknown if one is not
        // infinite (a known obstacle under the foot at every heading is infinite).
        let values: Vec<f64> = flags
            .iter()
            .zip(&sums)
            .map(|(&(inf, unk), &sum)| {
                if (inf | unk) & all != all {
                    sum
                } else if inf & all != all {
                    f64::NAN
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        let infinite_bits = flags.iter().map(|f| f.0).collect();
        let unknown_bits = flags.iter().map(|f| f.1).collect();
        let infinite = values.iter().filter(|v| v.is_infinite()).count();
        let unknown = values.iter().filter(|v| v.is_nan()).count();
        Self {
            nx,
            ny,
            values,
            infinite,
            unknown,
            headings: Some(HeadingFlags {
                bins,
                infinite: infinite_bits,
                unknown: unknown_bits,
                finite: sums,
            }),
        }
    }

    /// C_F of cell (i, j); `Unknown` outside the layer. For the wheel-pair model, the
    /// cost at the cell's most favourable heading (a lower bound of [`Self::get_at`]).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> Cost {
        if i < self.nx && j < self.ny {
            Cost::from_raw(self.values[j * self.nx + i])
        } else {
            Cost::Unknown
        }
    }

    /// The bin of foot heading `theta` (rad): the nearest of the layer's headings. Every
    /// heading shares bin 0 in the paper's model.
    #[inline]
    pub fn heading_bin(&self, theta: f64) -> HeadingBin {
        match &self.headings {
            Some(h) if theta.is_finite() => {
                let step = std::f64::consts::PI / h.bins as f64;
                // `bins` ≤ 64, so the rounded quotient fits i64 for any finite angle that
                // matters; rem_euclid folds it into [0, bins).
                let k = (theta / step).round().rem_euclid(h.bins as f64);
                HeadingBin((k as usize).min(h.bins - 1))
            }
            _ => HeadingBin(0),
        }
    }

    /// C_F of cell (i, j) for a foot at heading bin `bin`; `Unknown` outside the layer.
    /// The same as [`Self::get`] for the paper's model.
    #[inline]
    pub fn get_at(&self, i: usize, j: usize, bin: HeadingBin) -> Cost {
        if i < self.nx && j < self.ny {
            Cost::from_raw(self.raw_at(j * self.nx + i, bin))
        } else {
            Cost::Unknown
        }
    }

    /// Raw row-major value at heading bin `bin` (`+∞` infinite, `NaN` unknown).
    #[inline]
    pub(crate) fn raw_at(&self, k: usize, bin: HeadingBin) -> f64 {
        match &self.headings {
            None => self.values[k],
            Some(h) => {
                let bit = 1u64 << bin.0;
                if h.infinite[k] & bit != 0 {
                    f64::INFINITY
                } else if h.unknown[k] & bit != 0 {
                    f64::NAN
                } else {
                    h.finite[k]
                }
            }
        }
    }

    /// Everything the layer holds for cell `k` (row-major), as bits: the value, and the
    /// wheel-pair model's flags and finite value (zero for the paper's model).
    pub(crate) fn cell_bits(&self, k: usize) -> [u64; 4] {
        let value = self.values.get(k).map_or(u64::MAX, |v| v.to_bits());
        match &self.headings {
            None => [value, 0, 0, 0],
            Some(h) => [
                value,
                h.infinite.get(k).copied().unwrap_or(u64::MAX),
                h.unknown.get(k).copied().unwrap_or(u64::MAX),
                h.finite.get(k).map_or(u64::MAX, |v| v.to_bits()),
            ],
        }
    }

    /// The heading bins at which cell `k` (row-major) has a finite C_F, as bits (every
    /// bit or none for the paper's model).
    #[inline]
    pub(crate) fn finite_bins(&self, k: usize) -> u64 {
        match &self.headings {
            None if self.values[k].is_finite() => u64::MAX,
            None => 0,
            Some(h) => !(h.infinite[k] | h.unknown[k]),
        }
    }

    /// Whether cell `k` (row-major) has infinite C_F at some heading: for the paper's
    /// model, whether it is infinite.
    #[inline]
    pub(crate) fn infinite_at_some_heading(&self, k: usize) -> bool {
        match &self.headings {
            None => self.values[k].is_infinite(),
            Some(h) => h.infinite[k] != 0,
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

/// The centre angle of heading bin `b` of `bins` over [0, π), rad.
fn bin_angle(b: usize, bins: usize) -> f64 {
    b as f64 * std::f64::consts::PI / bins as f64
}

/// The cells under a wheel pair at one heading, as row intervals of cell offsets.
#[derive(Debug, Clone)]
struct Footprint {
    /// `(dy, lo, hi)`: offsets `(dx, dy)` with `lo <= dx <= hi` lie under a wheel.
    runs: Vec<(isize, isize, isize)>,
}

impl Footprint {
    /// The cells whose centre lies closer than `wheels.radius` to one of the two wheel
    /// centres, at `±track/2` along the axle of a foot heading `phi`.
    fn new(wheels: WheelPair, phi: f64, res: f64) -> Self {
        let (s, c) = phi.sin_cos();
        let half = wheels.track / 2.0;
        let centres = [[-s * half, c * half], [s * half, -c * half]];
        let under = |dx: isize, dy: isize| {
            let (x, y) = (dx as f64 * res, dy as f64 * res);
            centres.iter().any(|w| (x - w[0]).hypot(y - w[1]) < wheels.radius)
        };
        // Bounded like DiscRows: a wheel pair wider than 10⁴ cells is not a foot.
        let reach =
            (((half + wheels.radius) / res).ceil() as usize).saturating_add(1).min(10_000) as isize;
        let mut runs = Vec::new();
        for dy in -reach..=reach {
            let mut start = None;
            for dx in -reach..=reach + 1 {
                match (under(dx, dy) && dx <= reach, start) {
                    (true, None) => start = Some(dx),
                    (false, Some(lo)) => {
                        runs.push((dy, lo, dx - 1));
                        start = None;
                    }
                    _ => {}
                }
            }
        }
        Self { runs }
    }

    /// For a foot on cell (x, y): whether a too-high cell lies under a wheel, and
    /// whether an unknown or off-map cell does (prefix counts per row, `nx + 1` each).
    #[allow(clippy::too_many_arguments)]
    fn test(
        &self,
        pre_high: &[u32],
        pre_unknown: &[u32],
        nx: usize,
        ny: usize,
        x: usize,
        y: usize,
    ) -> (bool, bool) {
        let (mut high, mut unknown) = (false, false);
        for &(dy, lo, hi) in &self.runs {
            let yy = y as isize + dy;
            if yy < 0 || yy >= ny as isize {
                unknown = true;
                continue;
            }
            let (x0, x1) = (x as isize + lo, x as isize + hi);
            if x0 < 0 || x1 >= nx as isize {
                unknown = true;
            }
            let (a, b) = (x0.max(0) as usize, (x1 + 1).min(nx as isize).max(0) as usize);
            if a >= b {
                continue;
            }
            let row = yy as usize * (nx + 1);
            high |= pre_high[row + b] > pre_high[row + a];
            unknown |= pre_unknown[row + b] > pre_unknown[row + a];
            if high {
                break;
            }
        }
        (high, unknown)
    }
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
/// Per cell, the distance in cells along its row to the nearest cell whose height
/// difference `dh` is above `max_foot_height_diff_m`, and to the nearest unknown cell
/// (outside the map counting as unknown): what both foot models test discs and
/// footprints against.
fn row_obstacle_distances(
    dh: &[f64],
    nx: usize,
    ny: usize,
    params: &Params,
) -> (Vec<u32>, Vec<u32>) {
    let too_high = |v: f64| v > params.max_foot_height_diff_m;
    let mut dist_high = vec![0u32; nx * ny];
    let mut dist_unknown = vec![0u32; nx * ny];
    par_rows(&mut dist_high, nx, |y, row| {
        row_distances(&dh[y * nx..(y + 1) * nx], too_high, false, row)
    });
    par_rows(&mut dist_unknown, nx, |y, row| {
        row_distances(&dh[y * nx..(y + 1) * nx], f64::is_nan, true, row)
    });
    (dist_high, dist_unknown)
}

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

    /// The model's wheel pair (`RobotDescription::reference`, which `tests/model.rs`
    /// checks against the model file): radius 0.08 m, wheel centres 0.12 m apart.
    fn wheels() -> WheelPair {
        let r = crate::robot::RobotDescription::reference();
        WheelPair { radius: r.wheel_radius, track: r.wheel_track }
    }

    /// The wheel-pair model cell by cell, per heading bin, with no tricks: the reference
    /// the fast layer must match. `Cost`s per bin, row-major per cell.
    fn naive_wheel_pair(map: &HeightMap, p: &Params, w: WheelPair) -> Vec<Vec<Cost>> {
        let (nx, ny) = map.dims();
        let res = map.resolution();
        let dh = height_differences(map);
        let paper = naive_foot_cost(map, &Params { r_f_m: 1e-6, ..p.clone() });
        let bins = (p.orientations / 2).min(64) as usize;
        let reach = ((w.track / 2.0 + w.radius) / res).ceil() as isize + 1;
        let mut out = Vec::with_capacity(nx * ny);
        for y in 0..ny as isize {
            for x in 0..nx as isize {
                let mut per_bin = Vec::with_capacity(bins);
                for b in 0..bins {
                    let phi = b as f64 * std::f64::consts::PI / bins as f64;
                    let axle = [-phi.sin() * w.track / 2.0, phi.cos() * w.track / 2.0];
                    let (mut high, mut unknown) = (false, false);
                    for iy in y - reach..=y + reach {
                        for ix in x - reach..=x + reach {
                            let (ox, oy) = ((ix - x) as f64 * res, (iy - y) as f64 * res);
                            let under = (ox - axle[0]).hypot(oy - axle[1]) < w.radius
                                || (ox + axle[0]).hypot(oy + axle[1]) < w.radius;
                            if !under {
                                continue;
                            }
                            let inside = ix >= 0 && iy >= 0 && ix < nx as isize && iy < ny as isize;
                            let v =
                                if inside { dh[iy as usize * nx + ix as usize] } else { f64::NAN };
                            high |= v > p.max_foot_height_diff_m;
                            unknown |= v.is_nan();
                        }
                    }
                    // The finite value is the paper's sum (eq. 1): the paper's layer with
                    // a vanishing r_F gives it wherever the cell itself is known.
                    let k = y as usize * nx + x as usize;
                    per_bin.push(if high {
                        Cost::Infinite
                    } else if unknown {
                        Cost::Unknown
                    } else {
                        paper[k]
                    });
                }
                out.push(per_bin);
            }
        }
        out
    }

    /// Stairs rising along +x from x = 1.0 m: 0.17 m risers, 0.29 m treads (typical
    /// indoor stairs), heights by cell centre. Tread 1 holds the cells whose centres lie
    /// in [1.0, 1.29): i = 40 (1.0125) ..= 51 (1.2875), twelve cells.
    fn stairs_map() -> HeightMap {
        flat_with(100, 40, |i, _| {
            let x = (i as f64 + 0.5) * RES;
            if x < 1.0 { 0.0 } else { 0.17 * (((x - 1.0) / 0.29).floor() + 1.0) }
        })
    }

    /// Columns of row 20 on tread 1 whose C_F is finite, by `cost(i)`.
    fn finite_tread_cells(cost: impl Fn(usize) -> Cost) -> Vec<usize> {
        (40..=51).filter(|&i| cost(i).is_finite()).collect()
    }

    #[test]
    fn wheel_pair_on_a_typical_tread_by_hand() {
        let m = stairs_map();
        let p = Params::default();
        let wp = FootCostLayer::wheel_pair(&m, &p, wheels());
        let paper = FootCostLayer::compute(&m, &p);
        // ΔH > 0.05 m marks columns 39 and 40 (the first riser) and 51 and 52 (the
        // second). Paper: a marked column within r_F = 0.12 m (4.8 cells, so |dx| <= 4)
        // is infinite: 45 and 46 remain, 0.05 m of the tread.
        assert_eq!(finite_tread_cells(|i| paper.get(i, 20)), vec![45, 46]);
        // Heading 0 (climbing straight up): wheel centres at (0, ±0.06 m). The cell
        // (dx, dy) = (3, 2) lies 0.025·√(9 + 0.16) ≈ 0.0757 m < 0.08 m from the wheel
        // at dy = 2.4 cells; (4, dy) lies at least 0.1 m from both. So |dx| <= 3 counts:
        // 44..=47 remain, 0.1 m of the tread, twice the paper's.
        let at = |deg: f64| wp.heading_bin(deg.to_radians());
        assert_eq!(finite_tread_cells(|i| wp.get_at(i, 20, at(0.0))), vec![44, 45, 46, 47]);
        assert_eq!(finite_tread_cells(|i| wp.get_at(i, 20, at(180.0))), vec![44, 45, 46, 47]);
        // Heading 90° (along the tread): wheel centres at (∓0.06 m, 0), so the wheels
        // cover |x| < 0.14 m: |dx| <= 5 (0.125 m) counts and no cell of the 12 is free.
        assert!(finite_tread_cells(|i| wp.get_at(i, 20, at(90.0))).is_empty());
        assert!(finite_tread_cells(|i| wp.get_at(i, 20, at(-90.0))).is_empty());
        // Heading 45°: wheel centres at (∓0.0424, ±0.0424) m. (−4, 1) lies
        // √(0.0576² + 0.0174²) ≈ 0.060 m from one; (−5, dy) at least 0.0826 m from
        // both. So |dx| <= 4 counts, as for the paper's disc: 45 and 46.
        assert_eq!(finite_tread_cells(|i| wp.get_at(i, 20, at(45.0))), vec![45, 46]);
        // The heading-free value is the most favourable heading's.
        assert_eq!(finite_tread_cells(|i| wp.get(i, 20)), vec![44, 45, 46, 47]);
        // Where both models are finite they agree: the same r_N sum (eq. 1).
        assert_eq!(wp.get_at(45, 20, at(0.0)), paper.get(45, 20));
        assert!(wp.get_at(44, 20, at(0.0)).finite().is_some_and(|c| c > 1.0));
        // On the riser's edge cells every heading is infinite.
        for b in 0..32 {
            assert_eq!(wp.get_at(40, 20, HeadingBin(b)), Cost::Infinite);
        }
        assert_eq!(wp.get(40, 20), Cost::Infinite);
    }

    #[test]
    fn heading_bins_fold_half_turns() {
        let m = stairs_map();
        let wp = FootCostLayer::wheel_pair(&m, &Params::default(), wheels());
        let step = std::f64::consts::PI / 32.0;
        for k in 0..64 {
            let theta = k as f64 * step;
            assert_eq!(wp.heading_bin(theta), HeadingBin(k % 32), "lattice heading {k}");
            assert_eq!(wp.heading_bin(theta - std::f64::consts::TAU), HeadingBin(k % 32));
        }
        assert_eq!(wp.heading_bin(0.49 * step), HeadingBin(0));
        assert_eq!(wp.heading_bin(-0.51 * step), HeadingBin(31));
        assert_eq!(wp.heading_bin(f64::NAN), HeadingBin(0));
        // The paper's layer has one bin for every heading.
        let paper = FootCostLayer::compute(&m, &Params::default());
        assert_eq!(paper.heading_bin(1.0), HeadingBin(0));
    }

    #[test]
    fn paper_layer_is_the_same_at_every_heading() {
        let m = stairs_map();
        let p = Params::default();
        let l = FootCostLayer::compute(&m, &p);
        let naive = naive_foot_cost(&m, &p);
        for (k, c) in naive.iter().enumerate() {
            for theta in [0.0, 0.7, 1.6, -2.2] {
                let b = l.heading_bin(theta);
                assert_eq!(l.get_at(k % 100, k / 100, b), *c);
                assert_eq!(l.raw_at(k, b).to_bits(), l.raw(k).to_bits());
            }
            assert_eq!(l.infinite_at_some_heading(k), *c == Cost::Infinite);
        }
    }

    #[test]
    fn wheel_pair_layer_matches_naive_on_a_varied_map() {
        let mut m = flat_with(50, 44, |i, j| {
            let (x, y) = (i as f64, j as f64);
            if i > 32 {
                0.25
            } else if (j as f64 - 0.4 * x).abs() < 2.0 {
                0.1
            } else {
                0.01 * ((x * 0.7).sin() + (y * 0.3).cos())
            }
        });
        for k in 0..12 {
            m.set((k * 37) % 50, (k * 11) % 44, f64::NAN).unwrap();
        }
        for orientations in [64, 8] {
            let p = Params { orientations, ..Params::default() };
            let fast = FootCostLayer::wheel_pair(&m, &p, wheels());
            let naive = naive_wheel_pair(&m, &p, wheels());
            let (mut finite, mut infinite, mut unknown) = (0, 0, 0);
            for (k, per_bin) in naive.iter().enumerate() {
                let (i, j) = (k % 50, k / 50);
                for (b, c) in per_bin.iter().enumerate() {
                    let f = fast.get_at(i, j, HeadingBin(b));
                    match (f, *c) {
                        (Cost::Finite(a), Cost::Finite(e)) => {
                            finite += 1;
                            assert!((a - e).abs() <= 1e-9, "({i},{j}) bin {b}: {a} vs {e}");
                        }
                        _ => assert_eq!(f, *c, "({i},{j}) bin {b}"),
                    }
                    infinite += usize::from(*c == Cost::Infinite);
                    unknown += usize::from(*c == Cost::Unknown);
                }
                let best = per_bin
                    .iter()
                    .find(|c| c.is_finite())
                    .or_else(|| per_bin.iter().find(|c| **c == Cost::Unknown))
                    .copied()
                    .unwrap_or(Cost::Infinite);
                match (fast.get(i, j), best) {
                    (Cost::Finite(a), Cost::Finite(e)) => assert!((a - e).abs() <= 1e-9),
                    (a, e) => assert_eq!(a, e, "({i},{j}) best heading"),
                }
                let any = per_bin.contains(&Cost::Infinite);
                assert_eq!(fast.infinite_at_some_heading(k), any, "({i},{j})");
            }
            assert!(
                finite > 1000 && infinite > 1000 && unknown > 1000,
                "{finite} {infinite} {unknown}"
            );
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
