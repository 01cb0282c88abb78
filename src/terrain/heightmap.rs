//! The 2.5D height map: a regular grid of terrain heights, `NaN` where unknown.
//!
//! This is the one place that defines the grid convention used by every layer built on
//! it (foot cost, body cost, images):
//!
//! - Cell `(i, j)` covers `[origin_x + i·res, origin_x + (i+1)·res)` in x and
//!   `[origin_y + j·res, origin_y + (j+1)·res)` in y (half-open, so every point belongs to
//!   exactly one cell). `i` runs along +x (`0..nx`), `j` along +y (`0..ny`).
//! - Storage is row-major with rows of constant y: the value of cell `(i, j)` lives at
//!   index `j·nx + i`, so x is the contiguous direction.
//! - A cell's value is a terrain height in metres (z up, world frame) or `NaN` for
//!   "unknown" (never observed). Infinite values are rejected: a height is finite or
//!   unknown.
//! - The cell *centre* `(origin_x + (i+½)·res, origin_y + (j+½)·res)` is the point a cell
//!   stands for in distance computations (foot and body costs).
//!
//! What a cell's height means depends on the source: see `rasterise` (highest surface
//! over the cell's area) and `sensed` (highest up-facing laser return in the cell).

use std::sync::OnceLock;

/// Why a height map (or a view of one) could not be made or changed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HeightMapError {
    /// The cell size is not a finite number > 0.
    #[error("height map resolution must be a finite number > 0 m, got {0}")]
    BadResolution(f64),
    /// A dimension is zero (or the cell count overflows).
    #[error("height map must have at least one cell, got {nx} x {ny}")]
    Empty {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
    },
    /// The origin is not finite.
    #[error("height map origin must be finite, got ({x}, {y})")]
    BadOrigin {
        /// Origin x, m.
        x: f64,
        /// Origin y, m.
        y: f64,
    },
    /// The data vector does not hold `nx · ny` values.
    #[error("height map data holds {got} values, expected {nx} x {ny} = {}", nx * ny)]
    SizeMismatch {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
        /// Values supplied.
        got: usize,
    },
    /// A height is ±∞ (unknown must be written as NaN).
    #[error("cell ({i}, {j}) holds {value}: a height must be finite, or NaN for unknown")]
    InfiniteHeight {
        /// Cell index along x.
        i: usize,
        /// Cell index along y.
        j: usize,
        /// The offending value.
        value: f64,
    },
    /// A cell index or a view lies (partly) outside the map.
    #[error("cells [{i0}, {i0}+{ni}) x [{j0}, {j0}+{nj}) are not inside the {nx} x {ny} map")]
    OutOfBounds {
        /// First index along x.
        i0: usize,
        /// First index along y.
        j0: usize,
        /// Count along x.
        ni: usize,
        /// Count along y.
        nj: usize,
        /// Map cells along x.
        nx: usize,
        /// Map cells along y.
        ny: usize,
    },
}

/// A regular grid of terrain heights (m), `NaN` = unknown. See the module doc for the
/// frame convention.
#[derive(Debug, Clone)]
pub struct HeightMap {
    origin: [f64; 2],
    resolution: f64,
    nx: usize,
    ny: usize,
    data: Vec<f64>,
    /// The blocks' highest heights, made by the first [`HeightMap::max_known_in_grid_box`]
    /// and dropped by every change to `data`.
    blocks: OnceLock<BlockMax>,
}

impl PartialEq for HeightMap {
    /// The same grid and heights (the block cache does not count).
    fn eq(&self, other: &Self) -> bool {
        self.origin == other.origin
            && self.resolution == other.resolution
            && (self.nx, self.ny) == (other.nx, other.ny)
            && self.data == other.data
    }
}

/// Cells along each side of a block of [`BlockMax`]: 20 cm at the planner's 2.5 cm, about
/// the reach of a leg segment.
const BLOCK: usize = 8;

/// The highest known height of each block of [`BLOCK`] × [`BLOCK`] cells (−∞ where
/// none is known), row-major like the cells.
#[derive(Debug, Clone)]
struct BlockMax {
    bx: usize,
    max: Vec<f64>,
}

impl BlockMax {
    fn build(map: &HeightMap) -> Self {
        let bx = map.nx.div_ceil(BLOCK);
        let by = map.ny.div_ceil(BLOCK);
        let mut max = vec![f64::NEG_INFINITY; bx * by];
        for j in 0..map.ny {
            let row = &map.data[j * map.nx..(j + 1) * map.nx];
            let out = &mut max[(j / BLOCK) * bx..(j / BLOCK + 1) * bx];
            for (b, cells) in row.chunks(BLOCK).enumerate() {
                // `f64::max` passes over NaN: unknown cells never count.
                out[b] = cells.iter().copied().fold(out[b], f64::max);
            }
        }
        Self { bx, max }
    }
}

fn check_geometry(
    origin: [f64; 2],
    resolution: f64,
    nx: usize,
    ny: usize,
) -> Result<(), HeightMapError> {
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(HeightMapError::BadResolution(resolution));
    }
    if !(origin[0].is_finite() && origin[1].is_finite()) {
        return Err(HeightMapError::BadOrigin { x: origin[0], y: origin[1] });
    }
    if nx == 0 || ny == 0 || nx.checked_mul(ny).is_none() {
        return Err(HeightMapError::Empty { nx, ny });
    }
    Ok(())
}

impl HeightMap {
    /// A map from row-major data (`data[j·nx + i]` is cell `(i, j)`).
    ///
    /// # Errors
    /// Bad resolution or origin, zero cells, a data length other than `nx · ny`, or an
    /// infinite height.
    pub fn new(
        origin: [f64; 2],
        resolution: f64,
        nx: usize,
        ny: usize,
        data: Vec<f64>,
    ) -> Result<Self, HeightMapError> {
        check_geometry(origin, resolution, nx, ny)?;
        if data.len() != nx * ny {
            return Err(HeightMapError::SizeMismatch { nx, ny, got: data.len() });
        }
        if let Some(k) = data.iter().position(|v| v.is_infinite()) {
            return Err(HeightMapError::InfiniteHeight { i: k % nx, j: k / nx, value: data[k] });
        }
        Ok(Self { origin, resolution, nx, ny, data, blocks: OnceLock::new() })
    }

    /// A map with every cell at `value` (`NaN` for an all-unknown map).
    ///
    /// # Errors
    /// As [`HeightMap::new`].
    pub fn filled(
        origin: [f64; 2],
        resolution: f64,
        nx: usize,
        ny: usize,
        value: f64,
    ) -> Result<Self, HeightMapError> {
        check_geometry(origin, resolution, nx, ny)?;
        if value.is_infinite() {
            return Err(HeightMapError::InfiniteHeight { i: 0, j: 0, value });
        }
        let data = vec![value; nx * ny];
        Ok(Self { origin, resolution, nx, ny, data, blocks: OnceLock::new() })
    }

    /// A map with every cell unknown.
    ///
    /// # Errors
    /// As [`HeightMap::new`].
    pub fn unknown(
        origin: [f64; 2],
        resolution: f64,
        nx: usize,
        ny: usize,
    ) -> Result<Self, HeightMapError> {
        Self::filled(origin, resolution, nx, ny, f64::NAN)
    }

    /// A map whose cell `(i, j)` holds `f(i, j)`.
    ///
    /// # Errors
    /// As [`HeightMap::new`].
    pub fn from_fn(
        origin: [f64; 2],
        resolution: f64,
        nx: usize,
        ny: usize,
        mut f: impl FnMut(usize, usize) -> f64,
    ) -> Result<Self, HeightMapError> {
        check_geometry(origin, resolution, nx, ny)?;
        let mut data = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                data.push(f(i, j));
            }
        }
        Self::new(origin, resolution, nx, ny, data)
    }

    /// `(nx, ny)`: cells along x and along y.
    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Cells along x.
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Cells along y.
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Total number of cells.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// Always false: a map has at least one cell.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// World position (x, y) of the corner of cell (0, 0), m.
    pub fn origin(&self) -> [f64; 2] {
        self.origin
    }

    /// Cell edge length, m.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// World extent `[x_min, y_min, x_max, y_max]` covered by the cells, m.
    pub fn bounds(&self) -> [f64; 4] {
        [
            self.origin[0],
            self.origin[1],
            self.origin[0] + self.nx as f64 * self.resolution,
            self.origin[1] + self.ny as f64 * self.resolution,
        ]
    }

    /// The cell containing world point (x, y), or `None` outside the map (or for NaN).
    #[inline]
    pub fn cell_of(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        self.cell_at_grid(self.grid_coords(x, y))
    }

    /// World point (x, y) in grid units: cell (i, j) spans `[i, i + 1) × [j, j + 1)`.
    /// Points along a straight line in the world lie along one here too, so a caller
    /// sampling a segment converts its ends and interpolates, instead of dividing at
    /// every sample ([`Self::height_at_grid`]).
    #[inline]
    pub fn grid_coords(&self, x: f64, y: f64) -> [f64; 2] {
        [(x - self.origin[0]) / self.resolution, (y - self.origin[1]) / self.resolution]
    }

    /// The cell at grid coordinates `g` ([`Self::grid_coords`]), or `None` outside the
    /// map (or for NaN).
    #[inline]
    fn cell_at_grid(&self, [fx, fy]: [f64; 2]) -> Option<(usize, usize)> {
        // The comparisons are false for NaN, so NaN input yields None. On [0, n) the
        // truncating cast is floor (and cheaper: no libm call on baseline x86-64).
        if fx >= 0.0 && fy >= 0.0 && fx < self.nx as f64 && fy < self.ny as f64 {
            Some((fx as usize, fy as usize))
        } else {
            None
        }
    }

    /// Height of the cell at grid coordinates `g` ([`Self::grid_coords`]): `None` if
    /// unknown or outside the map.
    #[inline]
    pub fn height_at_grid(&self, g: [f64; 2]) -> Option<f64> {
        let (i, j) = self.cell_at_grid(g)?;
        self.get(i, j)
    }

    /// An upper bound on the known heights of the cells holding a point of the box from
    /// `lo` to `hi` in grid coordinates ([`Self::grid_coords`]) that lies on the map: the
    /// highest height of the blocks of 8 × 8 cells the box touches (−∞ where none is
    /// known or the box is off the map; +∞, no bound, for a NaN corner). One look-up per
    /// block, where asking every point costs one per point: a body part that keeps its
    /// clearance above this bound keeps it above every cell it passes.
    #[inline]
    pub fn max_known_in_grid_box(&self, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
            return f64::INFINITY;
        }
        let (nx, ny) = (self.nx as f64, self.ny as f64);
        if hi[0] < 0.0 || hi[1] < 0.0 || lo[0] >= nx || lo[1] >= ny {
            return f64::NEG_INFINITY;
        }
        // On [0, n) the truncating cast is floor; the box is clipped to the map.
        let cell = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        let (i0, i1) = (cell(lo[0], self.nx) / BLOCK, cell(hi[0], self.nx) / BLOCK);
        let (j0, j1) = (cell(lo[1], self.ny) / BLOCK, cell(hi[1], self.ny) / BLOCK);
        let blocks = self.blocks.get_or_init(|| BlockMax::build(self));
        let mut best = f64::NEG_INFINITY;
        for bj in j0..=j1 {
            let row = &blocks.max[bj * blocks.bx..];
            best = row[i0..=i1].iter().copied().fold(best, f64::max);
        }
        best
    }

    /// World position of the centre of cell (i, j), m. Defined for any index, also
    /// outside the map.
    #[inline]
    pub fn cell_center(&self, i: usize, j: usize) -> [f64; 2] {
        [
            self.origin[0] + (i as f64 + 0.5) * self.resolution,
            self.origin[1] + (j as f64 + 0.5) * self.resolution,
        ]
    }

    /// Row-major index of cell (i, j), or `None` outside the map.
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> Option<usize> {
        (i < self.nx && j < self.ny).then(|| j * self.nx + i)
    }

    /// Known height of cell (i, j); `None` if the cell is unknown or outside the map.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> Option<f64> {
        let v = self.raw(i, j);
        (!v.is_nan()).then_some(v)
    }

    /// Stored value of cell (i, j): the height, or `NaN` if unknown or outside the map.
    #[inline]
    pub fn raw(&self, i: usize, j: usize) -> f64 {
        match self.index(i, j) {
            Some(k) => self.data[k],
            None => f64::NAN,
        }
    }

    /// Whether cell (i, j) lies in the map and has a known height.
    pub fn is_known(&self, i: usize, j: usize) -> bool {
        self.get(i, j).is_some()
    }

    /// Sets cell (i, j) to `value` (a finite height, or `NaN` to mark it unknown).
    ///
    /// # Errors
    /// The cell is outside the map, or `value` is infinite.
    pub fn set(&mut self, i: usize, j: usize, value: f64) -> Result<(), HeightMapError> {
        if value.is_infinite() {
            return Err(HeightMapError::InfiniteHeight { i, j, value });
        }
        let k = self.index(i, j).ok_or(HeightMapError::OutOfBounds {
            i0: i,
            j0: j,
            ni: 1,
            nj: 1,
            nx: self.nx,
            ny: self.ny,
        })?;
        self.data[k] = value;
        self.blocks = OnceLock::new();
        Ok(())
    }

    /// Height of the cell containing (x, y): `None` if unknown or outside the map.
    #[inline]
    pub fn height_at_cell(&self, x: f64, y: f64) -> Option<f64> {
        let (i, j) = self.cell_of(x, y)?;
        self.get(i, j)
    }

    /// The map whose cell (i, j) holds the highest known height of the (2r + 1)² cells
    /// around (i, j) here (NaN where none is known): what a body part of up to r cells'
    /// reach over a cell must clear, answered by one look-up.
    pub fn dilated_max(&self, r: usize) -> HeightMap {
        // [`square_window_max`], O(1) a cell whatever r (the reachable regions dilate by
        // 28 cells, which took a twentieth of a cold plan's time at O(r) a cell). Unknown
        // cells count as −∞, so they drop out; a window with none known stays −∞ and
        // becomes NaN. The max is exact in any order: the values are the direct block
        // maximum's.
        let known: Vec<f64> =
            self.data.iter().map(|&v| if v.is_nan() { f64::NEG_INFINITY } else { v }).collect();
        let data = square_window_max(&known, self.nx, r)
            .into_iter()
            .map(|m| if m.is_finite() { m } else { f64::NAN })
            .collect();
        HeightMap { data, blocks: OnceLock::new(), ..*self }
    }

    /// Highest known height over the (2r + 1)² cells around the cell containing (x, y),
    /// `None` if none is known (or the point is off the map).
    #[inline]
    pub fn max_around(&self, x: f64, y: f64, r: usize) -> Option<f64> {
        self.fold_around(x, y, r, f64::max)
    }

    /// Lowest known height over the (2r + 1)² cells around the cell containing (x, y),
    /// `None` if none is known (or the point is off the map).
    pub fn min_around(&self, x: f64, y: f64, r: usize) -> Option<f64> {
        self.fold_around(x, y, r, f64::min)
    }

    #[inline]
    fn fold_around(&self, x: f64, y: f64, r: usize, pick: fn(f64, f64) -> f64) -> Option<f64> {
        let (i, j) = self.cell_of(x, y)?;
        let mut best: Option<f64> = None;
        for jj in j.saturating_sub(r)..=(j + r).min(self.ny - 1) {
            for ii in i.saturating_sub(r)..=(i + r).min(self.nx - 1) {
                if let Some(h) = self.get(ii, jj) {
                    best = Some(best.map_or(h, |b| pick(b, h)));
                }
            }
        }
        best
    }

    /// Where a sphere of radius `r` (a wheel) lowered onto the terrain at (x, y) comes to
    /// rest: the height of its lowest point, m. Each cell (flat-topped at its height, a
    /// square) holds the sphere up by `h + √(r² − d²) − r`, d the horizontal distance from
    /// the sphere's centre to the cell's nearest point; the highest of these. A wheel
    /// rolling over a box edge rises along the arc this traces, not in a step. Cells above
    /// `max_top` are walls the wheel presses against, not tops it can roll onto: they are
    /// left out. `None` if no cell under the sphere is known.
    pub fn wheel_rest_height(&self, x: f64, y: f64, r: f64, max_top: f64) -> Option<f64> {
        self.wheel_rest_height_on(x, y, r, |_, _, h| h <= max_top)
    }

    /// [`Self::wheel_rest_height`] on the known cells that `keep` (column, row, height)
    /// accepts.
    pub fn wheel_rest_height_on(
        &self,
        x: f64,
        y: f64,
        r: f64,
        keep: impl Fn(usize, usize, f64) -> bool,
    ) -> Option<f64> {
        let res = self.resolution;
        let span = |v: f64, o: f64, n: usize| {
            let lo = (((v - r - o) / res).floor().max(0.0)) as usize;
            let hi = (((v + r - o) / res).floor() as i64).min(n as i64 - 1);
            (lo, hi)
        };
        let (i0, i1) = span(x, self.origin[0], self.nx);
        let (j0, j1) = span(y, self.origin[1], self.ny);
        let mut best: Option<f64> = None;
        for j in j0..=usize::try_from(j1).ok()? {
            for i in i0..=usize::try_from(i1).ok()? {
                let d2 = self.cell_distance2(i, j, x, y);
                if d2 > r * r {
                    continue;
                }
                if let Some(h) = self.get(i, j).filter(|&h| keep(i, j, h)) {
                    let z = h + (r * r - d2).sqrt() - r;
                    best = Some(best.map_or(z, |b: f64| b.max(z)));
                }
            }
        }
        best
    }

    /// Whether cell (i, j), a square, comes within `r` of (x, y): the cells a sphere of
    /// radius `r` centred above (x, y) may rest on ([`Self::wheel_rest_height`]).
    pub fn cell_within(&self, i: usize, j: usize, x: f64, y: f64, r: f64) -> bool {
        self.cell_distance2(i, j, x, y) <= r * r
    }

    /// Squared horizontal distance from (x, y) to the nearest point of cell (i, j), a
    /// square, m².
    fn cell_distance2(&self, i: usize, j: usize, x: f64, y: f64) -> f64 {
        let res = self.resolution;
        let (x0, y0) = (self.origin[0] + i as f64 * res, self.origin[1] + j as f64 * res);
        let dx = (x0 - x).max(0.0).max(x - (x0 + res));
        let dy = (y0 - y).max(0.0).max(y - (y0 + res));
        dx * dx + dy * dy
    }

    /// Highest known terrain over the cells whose centres lie within `radius` of the
    /// segment from `a` to `b` (x, y; the ends' z count too), m: what a foot carried along
    /// the segment must clear.
    ///
    /// The set within `radius` of a segment is convex (a segment dilated by a disc), so
    /// each row of cell centres meets it in one interval: the union of the intervals of
    /// the two end discs and of the band between them. Each row is then a contiguous
    /// slice (the step check calls this for every candidate foothold).
    pub fn max_height_near_segment(&self, a: [f64; 3], b: [f64; 3], radius: f64) -> f64 {
        let mut best = a[2].max(b[2]);
        if radius.is_nan() || radius < 0.0 || self.nx == 0 {
            return best;
        }
        let res = self.resolution;
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let reach = radius * len2.sqrt();
        let first_row = ((a[1].min(b[1]) - radius - self.origin[1]) / res - 0.5).ceil().max(0.0);
        let last_row = ((a[1].max(b[1]) + radius - self.origin[1]) / res - 0.5).floor();
        let last_row = last_row.min(self.ny as f64 - 1.0);
        // NaN ends compare false: nothing to scan.
        if first_row.partial_cmp(&last_row).is_none_or(|o| o.is_gt()) {
            return best;
        }
        for j in first_row as usize..=last_row as usize {
            let cy = self.origin[1] + (j as f64 + 0.5) * res;
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for end in [a, b] {
                let h2 = radius * radius - (cy - end[1]) * (cy - end[1]);
                if h2 >= 0.0 {
                    let w = h2.sqrt();
                    lo = lo.min(end[0] - w);
                    hi = hi.max(end[0] + w);
                }
            }
            if len2 > 0.0 {
                // Projection onto the segment in [0, len²], perpendicular offset within
                // radius · |b − a|: two conditions linear in x.
                let ey = cy - a[1];
                let along = solve_linear(dx, -ey * dy, len2 - ey * dy);
                let across = solve_linear(dy, ey * dx - reach, ey * dx + reach);
                if let (Some((l1, h1)), Some((l2, h2))) = (along, across) {
                    let (l, h) = (l1.max(l2), h1.min(h2));
                    if l <= h {
                        lo = lo.min(a[0] + l);
                        hi = hi.max(a[0] + h);
                    }
                }
            }
            let i0 = ((lo - self.origin[0]) / res - 0.5).ceil().max(0.0);
            let i1 = ((hi - self.origin[0]) / res - 0.5).floor().min(self.nx as f64 - 1.0);
            if i0.partial_cmp(&i1).is_none_or(|o| o.is_gt()) {
                continue;
            }
            let row = j * self.nx;
            // NaN (unknown) never wins a `max`.
            best = self.data[row + i0 as usize..=row + i1 as usize]
                .iter()
                .fold(best, |m, &h| m.max(h));
        }
        best
    }

    /// Bilinear interpolation between the four cell centres around (x, y).
    ///
    /// `None` if a needed corner is unknown or outside the map; a corner whose weight is
    /// exactly zero is not needed (so sampling exactly at a border cell's centre works).
    pub fn bilinear(&self, x: f64, y: f64) -> Option<f64> {
        let fx = (x - self.origin[0]) / self.resolution - 0.5;
        let fy = (y - self.origin[1]) / self.resolution - 0.5;
        if !(fx.is_finite() && fy.is_finite()) {
            return None;
        }
        let (i0, j0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - i0, fy - j0);
        let mut sum = 0.0;
        for (di, wx) in [(0.0, 1.0 - tx), (1.0, tx)] {
            for (dj, wy) in [(0.0, 1.0 - ty), (1.0, ty)] {
                let w = wx * wy;
                if w == 0.0 {
                    continue;
                }
                let (ci, cj) = (i0 + di, j0 + dj);
                if ci < 0.0 || cj < 0.0 {
                    return None;
                }
                sum += w * self.get(ci as usize, cj as usize)?;
            }
        }
        Some(sum)
    }

    /// The raw row-major values (`NaN` = unknown), `j·nx + i` for cell (i, j).
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// Number of cells with a known height.
    pub fn known_count(&self) -> usize {
        self.data.iter().filter(|v| !v.is_nan()).count()
    }

    /// A borrowed view of the `ni × nj` cells starting at cell `(i0, j0)`.
    ///
    /// # Errors
    /// The view is empty or reaches outside the map.
    pub fn view(
        &self,
        i0: usize,
        j0: usize,
        ni: usize,
        nj: usize,
    ) -> Result<HeightMapView<'_>, HeightMapError> {
        let fits = ni > 0
            && nj > 0
            && i0.checked_add(ni).is_some_and(|e| e <= self.nx)
            && j0.checked_add(nj).is_some_and(|e| e <= self.ny);
        if !fits {
            return Err(HeightMapError::OutOfBounds { i0, j0, ni, nj, nx: self.nx, ny: self.ny });
        }
        Ok(HeightMapView { map: self, i0, j0, ni, nj })
    }
}

/// A rectangular window onto a [`HeightMap`]; local cell `(0, 0)` is the map's
/// `(i0, j0)`. World coordinates are unchanged.
#[derive(Debug, Clone, Copy)]
pub struct HeightMapView<'a> {
    map: &'a HeightMap,
    i0: usize,
    j0: usize,
    ni: usize,
    nj: usize,
}

impl<'a> HeightMapView<'a> {
    /// `(ni, nj)`: cells along x and y.
    pub fn dims(&self) -> (usize, usize) {
        (self.ni, self.nj)
    }

    /// The map cell that local cell (0, 0) is.
    pub fn offset(&self) -> (usize, usize) {
        (self.i0, self.j0)
    }

    /// World position of the corner of local cell (0, 0), m.
    pub fn origin(&self) -> [f64; 2] {
        let o = self.map.origin();
        let r = self.map.resolution();
        [o[0] + self.i0 as f64 * r, o[1] + self.j0 as f64 * r]
    }

    /// Cell edge length, m.
    pub fn resolution(&self) -> f64 {
        self.map.resolution()
    }

    /// Known height of local cell (i, j); `None` if unknown or outside the view.
    pub fn get(&self, i: usize, j: usize) -> Option<f64> {
        if i < self.ni && j < self.nj { self.map.get(self.i0 + i, self.j0 + j) } else { None }
    }

    /// Local row `j` as a slice of raw values (`NaN` = unknown), or `None` past the view.
    pub fn row(&self, j: usize) -> Option<&'a [f64]> {
        if j >= self.nj {
            return None;
        }
        let start = (self.j0 + j) * self.map.nx() + self.i0;
        self.map.as_slice().get(start..start + self.ni)
    }

    /// The map this view borrows from.
    pub fn map(&self) -> &'a HeightMap {
        self.map
    }
}

/// The `u` with `k · u` in `[lo, hi]`, as an interval: all of ℝ (infinite ends) when
/// `k = 0` and `0` lies in `[lo, hi]`, `None` when it is empty.
fn solve_linear(k: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if k > 0.0 {
        Some((lo / k, hi / k))
    } else if k < 0.0 {
        Some((hi / k, lo / k))
    } else if lo <= 0.0 && 0.0 <= hi {
        Some((f64::NEG_INFINITY, f64::INFINITY))
    } else {
        None
    }
}

/// Per cell of a row-major grid `nx` cells wide, the largest of `values` over the
/// (2r + 1)² cells around it, clipped to the grid (−∞ where the grid holds none; NaN
/// values are the caller's to map first: `f64::max` skips them). Separable: the max over
/// the row window, then over the column window of those, each by van Herk and
/// Gil-Werman's running maxima, three comparisons a cell whatever r.
pub fn square_window_max(values: &[f64], nx: usize, r: usize) -> Vec<f64> {
    let ny = values.len().checked_div(nx).unwrap_or(0);
    let mut scratch = WindowMax::default();
    let mut rows = vec![f64::NEG_INFINITY; nx * ny];
    for j in 0..ny {
        let row = j * nx..(j + 1) * nx;
        scratch.run(values[row.clone()].iter().copied(), r, &mut rows[row]);
    }
    let mut out = vec![f64::NEG_INFINITY; nx * ny];
    let mut column = vec![f64::NEG_INFINITY; ny];
    for i in 0..nx {
        scratch.run((0..ny).map(|j| rows[j * nx + i]), r, &mut column);
        for (j, &m) in column.iter().enumerate() {
            out[j * nx + i] = m;
        }
    }
    out
}

/// Van Herk and Gil-Werman's sliding-window maximum, its buffers kept between runs.
#[derive(Debug, Default)]
struct WindowMax {
    /// The values, padded with r times −∞ at either end.
    padded: Vec<f64>,
    /// Running maxima from each block's start, and to each block's end (blocks of
    /// 2r + 1 padded values).
    from_start: Vec<f64>,
    to_end: Vec<f64>,
}

impl WindowMax {
    /// `out[i]` = the max of `values[i − r ..= i + r]` (clamped to the values; −∞ where
    /// none): a window spans the end of one block and the start of the next, or exactly
    /// one block, so it is the larger of two running maxima.
    fn run(&mut self, values: impl Iterator<Item = f64>, r: usize, out: &mut [f64]) {
        // A window reaching past every value is the same as one reaching just past them
        // (and no huge r pads a huge buffer).
        let r = r.min(out.len());
        let w = 2 * r + 1;
        self.padded.clear();
        self.padded.resize(r, f64::NEG_INFINITY);
        self.padded.extend(values);
        let n = self.padded.len() - r;
        self.padded.resize(n + 2 * r, f64::NEG_INFINITY);
        let m = self.padded.len();
        self.from_start.clear();
        self.from_start.extend_from_slice(&self.padded);
        for k in 1..m {
            if k % w != 0 {
                self.from_start[k] = self.from_start[k].max(self.from_start[k - 1]);
            }
        }
        self.to_end.clear();
        self.to_end.extend_from_slice(&self.padded);
        for k in (0..m.saturating_sub(1)).rev() {
            if k % w != w - 1 {
                self.to_end[k] = self.to_end[k].max(self.to_end[k + 1]);
            }
        }
        for (i, o) in out.iter_mut().enumerate().take(n) {
            *o = self.to_end[i].max(self.from_start[i + 2 * r]);
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn max_around_a_cell_by_hand() {
        let hm = HeightMap::from_fn([0.0, 0.0], 0.1, 4, 4, |i, j| (i + 10 * j) as f64).unwrap();
        // Around cell (1, 1): cells 0..=2 in both directions, highest (2, 2) = 22.
        assert_eq!(hm.max_around(0.15, 0.15, 1), Some(22.0));
        // At the corner the block is clipped to the map.
        assert_eq!(hm.max_around(0.05, 0.05, 1), Some(11.0));
        assert_eq!(hm.max_around(0.35, 0.35, 0), Some(33.0));
        assert_eq!(hm.max_around(-1.0, 0.0, 1), None);
    }

    #[test]
    fn a_wheel_rests_on_a_box_edge_along_its_arc() {
        // Floor at 0, a 0.04 m box from x = 1.0 on; wheel radius 0.08.
        let hm = HeightMap::from_fn([0.0, 0.0], 0.025, 80, 20, |i, _| {
            if (i as f64) * 0.025 >= 1.0 { 0.04 } else { 0.0 }
        })
        .unwrap();
        let r = 0.08;
        // Far from the edge: on the floor; on top: at the box height.
        assert!((hm.wheel_rest_height(0.5, 0.25, r, 1.0).unwrap()).abs() < 1e-12);
        assert!((hm.wheel_rest_height(1.5, 0.25, r, 1.0).unwrap() - 0.04).abs() < 1e-12);
        // Centre 0.05 m before the edge: the edge holds it at 0.04 + √(0.08² − 0.05²) − 0.08.
        let z = hm.wheel_rest_height(0.95, 0.25, r, 1.0).unwrap();
        assert!((z - (0.04 + (0.0064f64 - 0.0025).sqrt() - 0.08)).abs() < 1e-12, "{z}");
        // A wall (above `max_top`) is pressed against, not climbed.
        assert!(hm.wheel_rest_height(0.95, 0.25, r, 0.03).unwrap().abs() < 1e-12);
        // Beyond the radius the edge does not touch it.
        assert!(hm.wheel_rest_height(0.91, 0.25, r, 1.0).unwrap().abs() < 1e-12);
    }

    #[test]
    fn dilated_max_by_hand() {
        let hm = HeightMap::from_fn([0.0, 0.0], 0.1, 4, 4, |i, j| (i + 10 * j) as f64).unwrap();
        let d = hm.dilated_max(1);
        assert_eq!(d.get(0, 0), Some(11.0));
        assert_eq!(d.get(1, 2), Some(32.0));
        assert_eq!(d.get(3, 3), Some(33.0));
        assert_eq!(hm.dilated_max(0), hm);
        // (0.25, 0.15) lies in cell (2, 1): its 3 × 3 block holds 1..3, 11..13, 21..23.
        assert_eq!(hm.max_around(0.25, 0.15, 1), Some(23.0));
        assert_eq!(hm.min_around(0.25, 0.15, 1), Some(1.0));
        assert_eq!(hm.min_around(0.05, 0.05, 0), Some(0.0));
        assert_eq!(hm.min_around(5.0, 5.0, 1), None);
    }

    #[test]
    fn dilated_max_is_the_max_around_every_cell_unknown_cells_left_out() {
        // The separable passes against the direct (2r + 1)² block, with unknown cells
        // and a corner where none is known.
        let mut hm = HeightMap::from_fn([0.0, 0.0], 0.1, 13, 9, |i, j| {
            ((i * 37 + j * 11) % 17) as f64 * 0.01
        })
        .unwrap();
        for (i, j) in [(4, 4), (5, 4), (0, 0), (1, 0), (0, 1), (1, 1), (12, 8)] {
            hm.set(i, j, f64::NAN).unwrap();
        }
        // Windows within, across and wider than the map (van Herk's blocks and padding).
        for r in [0, 1, 2, 3, 4, 5, 8, 12, 20] {
            if r == 20 {
                // Any window wider than the map is the whole map's.
                assert_eq!(hm.dilated_max(usize::MAX / 4), hm.dilated_max(r));
            }
            let d = hm.dilated_max(r);
            for j in 0..9 {
                for i in 0..13 {
                    let [x, y] = hm.cell_center(i, j);
                    assert_eq!(d.get(i, j), hm.max_around(x, y, r), "r {r} ({i}, {j})");
                }
            }
        }
        assert_eq!(hm.dilated_max(0).get(0, 0), None);
    }

    #[test]
    fn max_height_near_a_segment_by_hand() {
        // 10 × 10 cells of 0.1 m from (0, 0); a 0.3 m wall at x ∈ [0.6, 0.7) and a 0.5 m
        // post at cell (2, 8).
        let hm = HeightMap::from_fn([0.0, 0.0], 0.1, 10, 10, |i, j| {
            if i == 6 {
                0.3
            } else if (i, j) == (2, 8) {
                0.5
            } else {
                0.0
            }
        })
        .unwrap();
        // Along y = 0.25 from x = 0.1 to 0.45: the wall's centres (x = 0.65) lie 0.2 away.
        let seg =
            |bx: f64, r: f64| hm.max_height_near_segment([0.1, 0.25, 0.0], [bx, 0.25, 0.0], r);
        assert_eq!(seg(0.45, 0.15), 0.0);
        assert_eq!(seg(0.45, 0.21), 0.3);
        // Through the wall.
        assert_eq!(seg(0.9, 0.01), 0.3);
        // The post at (0.25, 0.85) is 0.6 from the segment: only a wide radius sees it.
        assert_eq!(seg(0.45, 0.59), 0.3);
        assert_eq!(seg(0.45, 0.61), 0.5);
        // The ends' own heights count; off the map nothing is seen.
        assert_eq!(hm.max_height_near_segment([5.0, 5.0, 0.1], [6.0, 5.0, 0.2], 0.3), 0.2);
    }

    /// The definition, cell by cell: every cell centre's distance to the segment.
    fn max_near_segment_per_cell(hm: &HeightMap, a: [f64; 3], b: [f64; 3], r: f64) -> f64 {
        let mut best = a[2].max(b[2]);
        let (nx, ny) = hm.dims();
        for j in 0..ny {
            for i in 0..nx {
                let c = hm.cell_center(i, j);
                let d = crate::geometry::segment_distance(c, [a[0], a[1]], [b[0], b[1]]);
                if d <= r
                    && let Some(h) = hm.get(i, j)
                {
                    best = best.max(h);
                }
            }
        }
        best
    }

    proptest::proptest! {
        /// Row intervals find what the per-cell definition finds (cells closer than 1 µm
        /// to the radius may go either way), on a map of distinct random heights with
        /// unknown cells, for segments of any direction and length, partly off the map.
        #[test]
        fn max_height_near_segment_is_the_per_cell_maximum(
            a in proptest::array::uniform2(-0.3f64..1.3),
            b in proptest::array::uniform2(-0.3f64..1.3),
            r in 0.0f64..0.4,
            seed in 0u64..1000,
        ) {
            let hm = HeightMap::from_fn([0.0, 0.0], 0.05, 20, 20, |i, j| {
                let v = ((i * 31 + j * 17) as u64 * 2654435761 + seed) % 1000;
                if v < 50 { f64::NAN } else { v as f64 * 1e-3 }
            })
            .unwrap();
            let (a, b) = ([a[0], a[1], -1.0], [b[0], b[1], -1.0]);
            let got = hm.max_height_near_segment(a, b, r);
            let inner = max_near_segment_per_cell(&hm, a, b, (r - 1e-6).max(0.0));
            let outer = max_near_segment_per_cell(&hm, a, b, r + 1e-6);
            proptest::prop_assert!(inner <= got && got <= outer, "{inner} {got} {outer}");
        }
    }

    use super::*;

    fn ramp_map() -> HeightMap {
        // 4 x 3 cells of 0.5 m from (-1, 2); h = i + 10 j.
        HeightMap::from_fn([-1.0, 2.0], 0.5, 4, 3, |i, j| i as f64 + 10.0 * j as f64).unwrap()
    }

    #[test]
    fn construction_errors() {
        assert_eq!(
            HeightMap::filled([0.0, 0.0], 0.0, 2, 2, 0.0),
            Err(HeightMapError::BadResolution(0.0))
        );
        assert!(matches!(
            HeightMap::filled([0.0, 0.0], -0.1, 2, 2, 0.0),
            Err(HeightMapError::BadResolution(_))
        ));
        assert!(matches!(
            HeightMap::filled([0.0, 0.0], f64::NAN, 2, 2, 0.0),
            Err(HeightMapError::BadResolution(_))
        ));
        assert_eq!(
            HeightMap::filled([0.0, 0.0], 0.1, 0, 2, 0.0),
            Err(HeightMapError::Empty { nx: 0, ny: 2 })
        );
        assert!(matches!(
            HeightMap::filled([f64::NAN, 0.0], 0.1, 2, 2, 0.0),
            Err(HeightMapError::BadOrigin { .. })
        ));
        assert_eq!(
            HeightMap::new([0.0, 0.0], 0.1, 2, 2, vec![0.0; 3]),
            Err(HeightMapError::SizeMismatch { nx: 2, ny: 2, got: 3 })
        );
        assert_eq!(
            HeightMap::new([0.0, 0.0], 0.1, 2, 2, vec![0.0, 0.0, f64::INFINITY, 0.0]),
            Err(HeightMapError::InfiniteHeight { i: 0, j: 1, value: f64::INFINITY })
        );
        assert!(HeightMap::unknown([0.0, 0.0], 0.1, 2, 2).is_ok());
    }

    #[test]
    fn cell_convention_is_half_open_and_row_major() {
        let m = ramp_map();
        assert_eq!(m.dims(), (4, 3));
        assert_eq!(m.cell_of(-1.0, 2.0), Some((0, 0)));
        assert_eq!(m.cell_of(-0.5, 2.0), Some((1, 0)), "right edge belongs to the next cell");
        assert_eq!(m.cell_of(-0.500001, 2.49), Some((0, 0)));
        assert_eq!(m.cell_of(0.99, 3.49), Some((3, 2)));
        assert_eq!(m.cell_of(1.0, 3.0), None, "x_max is outside");
        assert_eq!(m.cell_of(-1.0, 3.5), None, "y_max is outside");
        assert_eq!(m.cell_of(-1.0001, 2.0), None);
        assert_eq!(m.cell_of(f64::NAN, 2.0), None);
        assert_eq!(m.cell_center(2, 1), [0.25, 2.75]);
        assert_eq!(m.as_slice()[4 + 2], 12.0, "cell (2, 1) at j*nx + i");
        assert_eq!(m.get(2, 1), Some(12.0));
        assert_eq!(m.get(4, 0), None);
        assert_eq!(m.height_at_cell(0.3, 3.2), Some(22.0));
        assert_eq!(m.bounds(), [-1.0, 2.0, 1.0, 3.5]);
        // Grid units: origin (-1, 2), 0.5 m cells; (0.3, 3.2) is 2.6 and 2.4 cells in.
        let g = m.grid_coords(0.3, 3.2);
        assert!((g[0] - 2.6).abs() < 1e-12 && (g[1] - 2.4).abs() < 1e-12, "{g:?}");
        assert_eq!(m.height_at_grid(g), Some(22.0));
        assert_eq!(m.height_at_grid([2.0, 0.0]), Some(2.0), "a cell's corner is its own");
        assert_eq!(m.height_at_grid([4.0, 0.0]), None, "nx is outside");
        assert_eq!(m.height_at_grid([-1e-9, 0.0]), None);
        assert_eq!(m.height_at_grid([f64::NAN, 0.0]), None);
    }

    #[test]
    fn unknown_cells_and_set() {
        let mut m = ramp_map();
        m.set(1, 1, f64::NAN).unwrap();
        assert_eq!(m.get(1, 1), None);
        assert!(m.raw(1, 1).is_nan());
        assert!(!m.is_known(1, 1));
        assert_eq!(m.known_count(), 11);
        assert!(matches!(m.set(9, 0, 1.0), Err(HeightMapError::OutOfBounds { .. })));
        assert!(matches!(
            m.set(0, 0, f64::NEG_INFINITY),
            Err(HeightMapError::InfiniteHeight { .. })
        ));
    }

    #[test]
    fn bilinear_interpolates_and_respects_unknown() {
        let mut m = ramp_map();
        // Halfway between centres of (0,0) [-0.75, 2.25] and (1,1) [-0.25, 2.75].
        let v = m.bilinear(-0.5, 2.5).unwrap();
        assert!((v - (0.5 + 5.0)).abs() < 1e-12, "{v}");
        // Exactly at a border cell centre: only that corner is needed.
        assert_eq!(m.bilinear(-0.75, 2.25), Some(0.0));
        assert_eq!(m.bilinear(0.75, 3.25), Some(23.0));
        // Beyond the outermost centres: a needed corner is outside.
        assert_eq!(m.bilinear(-0.9, 2.5), None);
        m.set(1, 1, f64::NAN).unwrap();
        assert_eq!(m.bilinear(-0.5, 2.5), None);
        // Unknown corner with zero weight is not needed.
        assert_eq!(m.bilinear(-0.75, 2.5), Some(5.0));
    }

    #[test]
    fn view_borrows_a_window() {
        let m = ramp_map();
        let v = m.view(1, 1, 3, 2).unwrap();
        assert_eq!(v.dims(), (3, 2));
        assert_eq!(v.get(0, 0), Some(11.0));
        assert_eq!(v.get(2, 1), Some(23.0));
        assert_eq!(v.get(3, 0), None);
        assert_eq!(v.row(1), Some(&[21.0, 22.0, 23.0][..]));
        assert_eq!(v.origin(), [-0.5, 2.5]);
        assert!(m.view(2, 0, 3, 1).is_err());
        assert!(m.view(0, 0, 0, 1).is_err());
        assert!(m.view(usize::MAX, 0, 2, 1).is_err());
    }

    /// The highest known height of the cells holding a point of the grid box, one by one.
    fn max_known_per_cell(hm: &HeightMap, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        let (nx, ny) = hm.dims();
        let mut best = f64::NEG_INFINITY;
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (i as f64, j as f64);
                let touched = x + 1.0 > lo[0] && x <= hi[0] && y + 1.0 > lo[1] && y <= hi[1];
                if touched && let Some(h) = hm.get(i, j) {
                    best = best.max(h);
                }
            }
        }
        best
    }

    #[test]
    fn max_known_in_grid_box_takes_the_blocks_the_box_touches() {
        // 20 x 10 cells: blocks of 8 x 8 are x 0-7, 8-15, 16-19 and y 0-7, 8-9.
        let mut hm = HeightMap::filled([0.0, 0.0], 0.1, 20, 10, 0.0).unwrap();
        hm.set(9, 2, 0.5).unwrap(); // block (1, 0)
        hm.set(18, 9, 0.7).unwrap(); // block (2, 1)
        hm.set(3, 3, f64::NAN).unwrap(); // unknown: never counts
        // Within block (0, 0): its cells are 0 (the NaN passed over).
        assert_eq!(hm.max_known_in_grid_box([0.5, 0.5], [7.9, 7.9]), 0.0);
        // Touching x = 8 reaches block (1, 0) and its 0.5, though the cell is at x = 9:
        // an upper bound, not the cells' maximum.
        assert_eq!(hm.max_known_in_grid_box([7.5, 0.5], [8.0, 1.0]), 0.5);
        // Clipped to the map: past its far corner, block (2, 1).
        assert_eq!(hm.max_known_in_grid_box([17.0, 8.5], [40.0, 30.0]), 0.7);
        // Off the map: nothing known; a NaN corner: no bound.
        assert_eq!(hm.max_known_in_grid_box([-5.0, -5.0], [-0.1, 3.0]), f64::NEG_INFINITY);
        assert_eq!(hm.max_known_in_grid_box([20.0, 0.0], [25.0, 3.0]), f64::NEG_INFINITY);
        assert_eq!(hm.max_known_in_grid_box([f64::NAN, 0.0], [1.0, 1.0]), f64::INFINITY);
        // A change after a query is seen (the blocks are made again), in a dilated map
        // too (its blocks are its own, not a copy of the source's).
        hm.set(7, 5, 0.6).unwrap();
        assert_eq!(hm.max_known_in_grid_box([0.5, 0.5], [1.0, 1.0]), 0.6);
        assert_eq!(hm.max_known_in_grid_box([10.0, 0.0], [10.5, 0.5]), 0.5);
        // Dilated by a cell, the 0.6 at x = 7 reaches x = 8, into block (1, 0).
        let wide = hm.dilated_max(1);
        assert_eq!(wide.max_known_in_grid_box([10.0, 0.0], [10.5, 0.5]), 0.6);
    }

    proptest::proptest! {
        /// The block bound is never below a known cell the box touches, and never above
        /// the highest known height of the blocks around it (a box within one block
        /// gets that block's maximum exactly).
        #[test]
        fn max_known_in_grid_box_bounds_every_touched_cell(
            lo in proptest::array::uniform2(-3.0f64..23.0),
            size in proptest::array::uniform2(0.0f64..12.0),
            seed in 0u64..1000,
        ) {
            let hm = HeightMap::from_fn([0.0, 0.0], 0.05, 20, 20, |i, j| {
                let v = ((i * 31 + j * 17) as u64 * 2654435761 + seed) % 1000;
                if v < 50 { f64::NAN } else { v as f64 * 1e-3 }
            })
            .unwrap();
            let hi = [lo[0] + size[0], lo[1] + size[1]];
            let got = hm.max_known_in_grid_box(lo, hi);
            proptest::prop_assert!(got >= max_known_per_cell(&hm, lo, hi));
            let block = |v: f64| (v.clamp(0.0, 19.0) as usize / BLOCK * BLOCK) as f64;
            let (blo, bhi) = ([block(lo[0]), block(lo[1])], [block(hi[0]) + 7.5, block(hi[1]) + 7.5]);
            if hi[0] >= 0.0 && hi[1] >= 0.0 && lo[0] < 20.0 && lo[1] < 20.0 {
                proptest::prop_assert_eq!(got, max_known_per_cell(&hm, blo, bhi));
            } else {
                proptest::prop_assert_eq!(got, f64::NEG_INFINITY);
            }
        }
    }
}
