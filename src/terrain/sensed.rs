//! The sensed height-map source: a height map built from laser returns, like the paper's
//! continuously rotating 3D laser scanner at Momaro's head (Sec. III–IV).
//!
//! The module knows nothing of MuJoCo: rays are cast through the [`RayCaster`] trait
//! (the simulator implements it with `mj_multiRay`, excluding the robot's own geoms; the
//! tests implement it analytically against the terrain primitives).
//!
//! **Scan pattern.** [`LaserScanner`] casts rays from `origin` on a regular
//! azimuth × elevation grid (azimuth counter-clockwise from +x, elevation up from the
//! horizontal), in a fixed order, so a scan is deterministic. The defaults (0.3° azimuth,
//! 0.1° elevation, elevations −85° to −10°, 6 m range) hit every 2.5 cm cell of flat
//! ground between 0.3 m and 3 m from a head 1.1 m up (see the tests).
//!
//! **Cell value.** A return at distance `d` along unit direction `u` is the point
//! `p = origin + d·u`; it belongs to the cell containing `(p.x, p.y)`.
//! - Returns on *up-facing* surfaces (unit normal z ≥ `min_up_normal_z`, default
//!   cos 45°) are heights: a cell holds the **maximum** of its up-facing return heights
//!   (and of what it held before, so several scans accumulate). The max matches the
//!   rasterised map's "highest surface over the cell".
//! - Returns on *steep* surfaces (walls, pole sides, risers) are not heights: their z is
//!   only a lower bound of the obstacle's top, and the return point lies on the boundary
//!   between two cells. They are counted in [`ScanStats::steep_hits`] and otherwise
//!   ignored; a cell that only steep returns reach stays unknown (`NaN`), which the cost
//!   maps treat as untraversable.
//! - Returns beyond `max_range_m`, outside the map, or with a non-finite distance are
//!   dropped (counted in [`ScanStats`]). Cells that no ray reaches stay unknown.

use super::heightmap::{HeightMap, HeightMapError};
use super::rasterise::sampled_height_range;
use crate::scenario::terrain::Primitive;

/// A ray's first intersection with the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Distance from the ray origin along the unit direction, m.
    pub distance: f64,
    /// Unit surface normal at the hit, world frame, pointing out of the surface (towards
    /// the ray origin's side).
    pub normal: [f64; 3],
}

/// Something that can cast rays into the world, e.g. MuJoCo's `mj_multiRay`.
pub trait RayCaster {
    /// Casts one ray per unit vector in `directions` from `origin` (world frame, m).
    /// Implementations clear `hits` and push exactly one entry per direction, in order:
    /// `None` when the ray hits nothing (within whatever cut-off the caster uses).
    fn cast_rays(
        &mut self,
        origin: [f64; 3],
        directions: &[[f64; 3]],
        hits: &mut Vec<Option<RayHit>>,
    );
}

/// Why a scan could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SensedError {
    /// A scanner setting is invalid.
    #[error("laser scanner setting `{name}` = {value} is invalid: {reason}")]
    BadScanner {
        /// Field name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// What a valid value looks like.
        reason: &'static str,
    },
    /// The ray caster broke its contract.
    #[error("ray caster returned {got} hits for {expected} rays")]
    HitCountMismatch {
        /// Rays cast.
        expected: usize,
        /// Hits returned.
        got: usize,
    },
    /// The target map is invalid.
    #[error(transparent)]
    Map(#[from] HeightMapError),
}

/// Configuration of the simulated rotating laser scanner.
#[derive(Debug, Clone, PartialEq)]
pub struct LaserScanner {
    /// Sensor position (world frame, m): the robot's head.
    pub origin: [f64; 3],
    /// First azimuth, rad, counter-clockwise from +x.
    pub azimuth_min_rad: f64,
    /// Azimuth span, rad (2π for a full turn; the end is then excluded).
    pub azimuth_span_rad: f64,
    /// Azimuth step, rad.
    pub azimuth_step_rad: f64,
    /// Lowest elevation, rad (negative looks down).
    pub elevation_min_rad: f64,
    /// Highest elevation, rad (inclusive).
    pub elevation_max_rad: f64,
    /// Elevation step, rad.
    pub elevation_step_rad: f64,
    /// Returns farther than this are dropped, m.
    pub max_range_m: f64,
    /// Returns whose normal has a z component below this are steep (not heights).
    pub min_up_normal_z: f64,
    /// Rays per call to the caster (bounds the direction buffer).
    pub batch_size: usize,
}

impl LaserScanner {
    /// A scanner at `origin` with the default pattern (see the module doc).
    pub fn at(origin: [f64; 3]) -> Self {
        Self {
            origin,
            azimuth_min_rad: 0.0,
            azimuth_span_rad: std::f64::consts::TAU,
            azimuth_step_rad: 0.3_f64.to_radians(),
            elevation_min_rad: (-85.0_f64).to_radians(),
            elevation_max_rad: (-10.0_f64).to_radians(),
            elevation_step_rad: 0.1_f64.to_radians(),
            max_range_m: 6.0,
            min_up_normal_z: std::f64::consts::FRAC_1_SQRT_2,
            batch_size: 1 << 16,
        }
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// The first invalid setting, by name.
    pub fn validate(&self) -> Result<(), SensedError> {
        let bad = |name, value, reason| Err(SensedError::BadScanner { name, value, reason });
        for (name, v) in [
            ("origin[0]", self.origin[0]),
            ("origin[1]", self.origin[1]),
            ("origin[2]", self.origin[2]),
        ] {
            if !v.is_finite() {
                return bad(name, v, "must be finite");
            }
        }
        if !self.azimuth_min_rad.is_finite() {
            return bad("azimuth_min_rad", self.azimuth_min_rad, "must be finite");
        }
        if !(self.azimuth_span_rad > 0.0 && self.azimuth_span_rad <= std::f64::consts::TAU) {
            return bad("azimuth_span_rad", self.azimuth_span_rad, "must lie in (0, 2π]");
        }
        for (name, v) in [
            ("azimuth_step_rad", self.azimuth_step_rad),
            ("elevation_step_rad", self.elevation_step_rad),
            ("max_range_m", self.max_range_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "must be a finite number > 0");
            }
        }
        let half_pi = std::f64::consts::FRAC_PI_2;
        if !(self.elevation_min_rad >= -half_pi && self.elevation_min_rad <= self.elevation_max_rad)
        {
            return bad(
                "elevation_min_rad",
                self.elevation_min_rad,
                "must lie in [-π/2, elevation_max_rad]",
            );
        }
        if self.elevation_max_rad > half_pi {
            return bad("elevation_max_rad", self.elevation_max_rad, "must be <= π/2");
        }
        if !(self.min_up_normal_z > 0.0 && self.min_up_normal_z <= 1.0) {
            return bad("min_up_normal_z", self.min_up_normal_z, "must lie in (0, 1]");
        }
        if self.batch_size == 0 {
            return bad("batch_size", 0.0, "must be >= 1");
        }
        if self.ray_count() > 50_000_000 {
            return bad("azimuth_step_rad", self.azimuth_step_rad, "pattern exceeds 5e7 rays");
        }
        Ok(())
    }

    fn azimuth_count(&self) -> usize {
        let n = (self.azimuth_span_rad / self.azimuth_step_rad).ceil();
        // A full turn excludes its end (it is the start again).
        let full = self.azimuth_span_rad >= std::f64::consts::TAU - 1e-12;
        let extra = if full || (n * self.azimuth_step_rad - self.azimuth_span_rad).abs() > 1e-12 {
            0.0
        } else {
            1.0
        };
        (n + extra).clamp(1.0, 1e9) as usize
    }

    fn elevation_count(&self) -> usize {
        let span = self.elevation_max_rad - self.elevation_min_rad;
        ((span / self.elevation_step_rad + 1e-9).floor() + 1.0).clamp(1.0, 1e9) as usize
    }

    /// Number of rays in one scan.
    pub fn ray_count(&self) -> usize {
        self.azimuth_count().saturating_mul(self.elevation_count())
    }

    /// Unit direction of ray `k` (elevation-major: all azimuths of the lowest elevation
    /// first).
    fn direction(&self, k: usize) -> [f64; 3] {
        let na = self.azimuth_count();
        let (e, a) = (k / na, k % na);
        let az = self.azimuth_min_rad + a as f64 * self.azimuth_step_rad;
        let el = self.elevation_min_rad + e as f64 * self.elevation_step_rad;
        let (sa, ca) = az.sin_cos();
        let (se, ce) = el.sin_cos();
        [ce * ca, ce * sa, se]
    }

    /// All ray directions of one scan, in the order they are cast.
    ///
    /// # Errors
    /// Invalid settings.
    pub fn directions(&self) -> Result<Vec<[f64; 3]>, SensedError> {
        self.validate()?;
        Ok((0..self.ray_count()).map(|k| self.direction(k)).collect())
    }

    /// Scans into `map`: each cell becomes the max of its value and the heights of the
    /// up-facing returns in it (see the module doc).
    ///
    /// # Errors
    /// Invalid settings, or a caster that returns the wrong number of hits.
    pub fn scan_into(
        &self,
        caster: &mut impl RayCaster,
        map: &mut HeightMap,
    ) -> Result<ScanStats, SensedError> {
        self.validate()?;
        let total = self.ray_count();
        let mut stats = ScanStats { rays: total, ..ScanStats::default() };
        let mut dirs = Vec::with_capacity(self.batch_size.min(total));
        let mut hits = Vec::with_capacity(self.batch_size.min(total));
        let mut start = 0;
        while start < total {
            let end = (start + self.batch_size).min(total);
            dirs.clear();
            dirs.extend((start..end).map(|k| self.direction(k)));
            caster.cast_rays(self.origin, &dirs, &mut hits);
            if hits.len() != dirs.len() {
                return Err(SensedError::HitCountMismatch {
                    expected: dirs.len(),
                    got: hits.len(),
                });
            }
            for (u, hit) in dirs.iter().zip(&hits) {
                self.record(u, hit, map, &mut stats)?;
            }
            start = end;
        }
        Ok(stats)
    }

    fn record(
        &self,
        u: &[f64; 3],
        hit: &Option<RayHit>,
        map: &mut HeightMap,
        stats: &mut ScanStats,
    ) -> Result<(), SensedError> {
        let Some(hit) = hit else {
            stats.misses += 1;
            return Ok(());
        };
        if !(hit.distance.is_finite() && hit.distance >= 0.0) || hit.distance > self.max_range_m {
            stats.out_of_range += 1;
            return Ok(());
        }
        let p = [0, 1, 2].map(|k| self.origin[k] + hit.distance * u[k]);
        let Some((i, j)) = map.cell_of(p[0], p[1]) else {
            stats.outside_map += 1;
            return Ok(());
        };
        // A NaN normal counts as steep.
        if hit.normal[2].is_nan() || hit.normal[2] < self.min_up_normal_z {
            stats.steep_hits += 1;
            return Ok(());
        }
        stats.height_hits += 1;
        let old = map.raw(i, j);
        // NaN (unknown) loses to any return: f64::max returns the other operand.
        map.set(i, j, old.max(p[2]))?;
        Ok(())
    }

    /// Scans onto a fresh all-unknown map with the given geometry.
    ///
    /// # Errors
    /// As [`LaserScanner::scan_into`], or invalid map geometry.
    pub fn scan(
        &self,
        caster: &mut impl RayCaster,
        origin: [f64; 2],
        resolution: f64,
        nx: usize,
        ny: usize,
    ) -> Result<(HeightMap, ScanStats), SensedError> {
        let mut map = HeightMap::unknown(origin, resolution, nx, ny)?;
        let stats = self.scan_into(caster, &mut map)?;
        Ok((map, stats))
    }
}

/// What happened to the rays of a scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ScanStats {
    /// Rays cast.
    pub rays: usize,
    /// Returns used as heights (up-facing, in range, in the map).
    pub height_hits: usize,
    /// Returns on steep surfaces, not used as heights.
    pub steep_hits: usize,
    /// Rays that hit nothing.
    pub misses: usize,
    /// Returns beyond `max_range_m` (or with an invalid distance).
    pub out_of_range: usize,
    /// Returns outside the map.
    pub outside_map: usize,
}

/// How a sensed map compares with the rasterised map of the same terrain and grid.
///
/// A cell is *seen* if it received at least one up-facing return. Seen cells are of two
/// kinds: *uniform* cells, where the terrain over the cell varies by at most `tolerance`
/// (ground, box tops, ramp faces), must agree within `tolerance`; *edge* cells, cut by a
/// vertical face, where the raster holds the highest surface but the sensor may see only
/// the lower part, must lie within [lowest surface − tolerance, highest + tolerance].
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct SensedAgreement {
    /// Uniform cells seen.
    pub uniform_seen: usize,
    /// Uniform cells seen whose value is raised above the ground (> 5 cm).
    pub raised_seen: usize,
    /// Edge cells seen.
    pub edge_seen: usize,
    /// Edge cells in the map.
    pub edge_total: usize,
    /// Largest |sensed − rasterised| over uniform seen cells, m.
    pub max_uniform_error_m: f64,
    /// Seen cells outside their bounds (uniform: error > tolerance; edge: outside range).
    pub violations: usize,
}

/// Compares `sensed` with `raster` (same grid) cell by cell; see [`SensedAgreement`].
pub fn agreement(
    primitives: &[Primitive],
    raster: &HeightMap,
    sensed: &HeightMap,
    tolerance: f64,
) -> SensedAgreement {
    let mut a = SensedAgreement::default();
    for j in 0..raster.ny().min(sensed.ny()) {
        for i in 0..raster.nx().min(sensed.nx()) {
            let Some(hi) = raster.get(i, j) else { continue };
            let [lo, _] = sampled_height_range(primitives, raster, i, j);
            let edge = hi - lo > tolerance;
            a.edge_total += usize::from(edge);
            let Some(s) = sensed.get(i, j) else { continue };
            if edge {
                a.edge_seen += 1;
                a.violations += usize::from(!(s >= lo - tolerance && s <= hi + tolerance));
            } else {
                a.uniform_seen += 1;
                a.raised_seen += usize::from(hi > 0.05);
                let err = (s - hi).abs();
                a.max_uniform_error_m = a.max_uniform_error_m.max(err);
                a.violations += usize::from(err > tolerance);
            }
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::terrain::{Block, Pole, Primitive, Ramp, Solid, Stairs};
    use crate::terrain::rasterise::rasterise;

    const RES: f64 = 0.025;

    /// A convex solid as half-spaces `n·p <= d` (outward unit normals).
    struct Polytope {
        planes: Vec<([f64; 3], f64)>,
    }

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    impl Polytope {
        /// An oriented prism over a rectangle (centre, half sizes, yaw) from z = 0 up to
        /// the top plane z = h0 + slope·lx (local x).
        fn prism(center: [f64; 2], half: [f64; 2], yaw: f64, h0: f64, slope: f64) -> Self {
            let (s, c) = yaw.sin_cos();
            let ax = [c, s, 0.0];
            let ay = [-s, c, 0.0];
            let o = [center[0], center[1], 0.0];
            let mut planes = Vec::new();
            for (axis, h) in [(ax, half[0]), (ay, half[1])] {
                planes.push((axis, dot(axis, o) + h));
                let neg = [-axis[0], -axis[1], 0.0];
                planes.push((neg, dot(neg, o) + h));
            }
            planes.push(([0.0, 0.0, -1.0], 0.0));
            // Top: z - slope·(ax·(p - o)) <= h0.
            let raw = [-slope * ax[0], -slope * ax[1], 1.0];
            let norm = dot(raw, raw).sqrt();
            let n = [raw[0] / norm, raw[1] / norm, raw[2] / norm];
            planes.push((n, (h0 + dot(raw, o)) / norm));
            Self { planes }
        }

        /// Cyrus–Beck clipping: entry distance and normal of the entry face.
        fn intersect(&self, o: [f64; 3], u: [f64; 3]) -> Option<(f64, [f64; 3])> {
            let (mut t0, mut t1) = (0.0_f64, f64::INFINITY);
            let mut normal = None;
            for &(n, d) in &self.planes {
                let denom = dot(n, u);
                let num = d - dot(n, o);
                if denom.abs() < 1e-15 {
                    if num < 0.0 {
                        return None;
                    }
                } else {
                    let t = num / denom;
                    if denom < 0.0 {
                        if t > t0 {
                            t0 = t;
                            normal = Some(n);
                        }
                    } else if t < t1 {
                        t1 = t;
                    }
                }
                if t0 > t1 {
                    return None;
                }
            }
            normal.map(|n| (t0, n))
        }
    }

    /// Exact ray caster against the 2.5D terrain: ground plane, prisms and cylinders.
    struct AnalyticCaster {
        solids: Vec<Polytope>,
        poles: Vec<([f64; 2], f64, f64)>,
    }

    impl AnalyticCaster {
        fn new(ps: &[Primitive]) -> Self {
            let mut solids = Vec::new();
            let mut poles = Vec::new();
            for solid in ps.iter().flat_map(Primitive::solids) {
                match solid {
                    Solid::Box { center, half_size, height, yaw } => {
                        solids.push(Polytope::prism(center, half_size, yaw, height, 0.0));
                    }
                    Solid::Wedge { center, half_size, height, yaw } => {
                        // Top z = height·(lx/L + 1/2): h0 = height/2 at the centre.
                        let slope = height / (2.0 * half_size[0]);
                        solids.push(Polytope::prism(center, half_size, yaw, height / 2.0, slope));
                    }
                    Solid::Cylinder { center, radius, height } => {
                        poles.push((center, radius, height))
                    }
                }
            }
            Self { solids, poles }
        }

        fn cast(&self, o: [f64; 3], u: [f64; 3]) -> Option<RayHit> {
            let mut best: Option<(f64, [f64; 3])> = None;
            let mut offer = |t: f64, n: [f64; 3]| {
                if t >= 0.0 && best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, n));
                }
            };
            if u[2] < 0.0 {
                offer(-o[2] / u[2], [0.0, 0.0, 1.0]);
            }
            for s in &self.solids {
                if let Some((t, n)) = s.intersect(o, u) {
                    offer(t, n);
                }
            }
            for &(c, r, h) in &self.poles {
                // Top cap.
                if u[2] != 0.0 {
                    let t = (h - o[2]) / u[2];
                    let (x, y) = (o[0] + t * u[0] - c[0], o[1] + t * u[1] - c[1]);
                    if x * x + y * y <= r * r {
                        offer(t, [0.0, 0.0, 1.0]);
                    }
                }
                // Side.
                let (dx, dy) = (o[0] - c[0], o[1] - c[1]);
                let a = u[0] * u[0] + u[1] * u[1];
                let b = 2.0 * (dx * u[0] + dy * u[1]);
                let cc = dx * dx + dy * dy - r * r;
                let disc = b * b - 4.0 * a * cc;
                if a > 0.0 && disc >= 0.0 {
                    let t = (-b - disc.sqrt()) / (2.0 * a);
                    let z = o[2] + t * u[2];
                    if (0.0..=h).contains(&z) {
                        let (x, y) = (dx + t * u[0], dy + t * u[1]);
                        offer(t, [x / r, y / r, 0.0]);
                    }
                }
            }
            best.map(|(distance, normal)| RayHit { distance, normal })
        }
    }

    impl RayCaster for AnalyticCaster {
        fn cast_rays(
            &mut self,
            origin: [f64; 3],
            dirs: &[[f64; 3]],
            hits: &mut Vec<Option<RayHit>>,
        ) {
            hits.clear();
            hits.extend(dirs.iter().map(|&u| self.cast(origin, u)));
        }
    }

    fn scene() -> Vec<Primitive> {
        vec![
            Primitive::Box(Block {
                center: [1.5, 0.6],
                size: [0.6, 0.8],
                height: 0.2,
                yaw_deg: 0.0,
            }),
            Primitive::Box(Block {
                center: [-0.2, -1.6],
                size: [0.7, 0.4],
                height: 0.12,
                yaw_deg: 25.0,
            }),
            Primitive::Ramp(Ramp {
                center: [-1.6, 0.3],
                size: [1.5, 1.0],
                height: 0.2,
                yaw_deg: 30.0,
            }),
            Primitive::Pole(Pole { center: [0.8, -1.0], radius: 0.05, height: 0.6 }),
            Primitive::Pole(Pole { center: [-0.7, 1.2], radius: 0.1, height: 0.15 }),
            Primitive::Stairs(Stairs {
                start: [0.3, 1.5],
                width: 0.8,
                steps: 3,
                step_depth: 0.3,
                step_height: 0.15,
                landing_depth: 0.4,
                yaw_deg: 80.0,
            }),
        ]
    }

    /// The sensed map agrees with the rasterised map on every cell the sensor sees.
    ///
    /// "Sees": the cell received at least one up-facing return. Cells are of two kinds:
    /// - *uniform* cells, where the terrain over the cell varies by at most 1 cm (ground,
    ///   box tops, ramp faces): the sensed height must be within 1 cm of the rasterised
    ///   one;
    /// - *edge* cells, cut by a vertical face (box, step, pole side), where the rasterised
    ///   value is the highest surface and the sensor may only see the lower part: the
    ///   sensed height must lie within [lowest surface − 1 cm, highest surface + 1 cm] of
    ///   the cell. Edge cells are counted and bounded so they cannot hide a disagreement.
    #[test]
    fn sensed_agrees_with_rasterised_where_seen() {
        let ps = scene();
        let (origin, size) = ([-3.0, -3.0], [6.0, 6.0]);
        let raster = rasterise(&ps, origin, size, RES).unwrap();
        let scanner = LaserScanner::at([0.0, 0.0, 1.1]);
        let mut caster = AnalyticCaster::new(&ps);
        let (sensed, stats) =
            scanner.scan(&mut caster, origin, RES, raster.nx(), raster.ny()).unwrap();
        assert!(stats.steep_hits > 0 && stats.height_hits > 100_000, "{stats:?}");

        let a = agreement(&ps, &raster, &sensed, 0.01);
        eprintln!("{a:?}");
        assert_eq!(a.violations, 0, "{a:?}");
        let SensedAgreement { uniform_seen, raised_seen, edge_seen, edge_total, .. } = a;
        // Non-vacuous: most of the 240 x 240 cells seen, many raised ones, few edges.
        assert!(uniform_seen > 40_000, "{uniform_seen}");
        assert!(raised_seen > 1_500, "{raised_seen}");
        assert!(edge_total < 2_000 && edge_seen <= edge_total, "{edge_seen}/{edge_total}");
    }

    #[test]
    fn default_scanner_covers_flat_ground_within_three_metres() {
        let scanner = LaserScanner::at([0.013, -0.007, 1.1]);
        let mut caster = AnalyticCaster::new(&[]);
        let (m, stats) = scanner.scan(&mut caster, [-3.5, -3.5], RES, 280, 280).unwrap();
        assert_eq!(stats.steep_hits, 0);
        let mut missed = Vec::new();
        for j in 0..m.ny() {
            for i in 0..m.nx() {
                let c = m.cell_center(i, j);
                let r = (c[0] - 0.013).hypot(c[1] + 0.007);
                if (0.3..=3.0).contains(&r) {
                    match m.get(i, j) {
                        Some(h) => assert!(h.abs() < 1e-9),
                        None => missed.push((i, j)),
                    }
                }
            }
        }
        assert!(missed.is_empty(), "{} cells unseen, e.g. {:?}", missed.len(), missed.first());
    }

    #[test]
    fn steep_returns_are_not_heights_and_unseen_cells_stay_unknown() {
        struct Wall;
        impl RayCaster for Wall {
            fn cast_rays(&mut self, _: [f64; 3], d: &[[f64; 3]], hits: &mut Vec<Option<RayHit>>) {
                hits.clear();
                hits.extend(
                    d.iter().map(|_| Some(RayHit { distance: 1.0, normal: [-1.0, 0.0, 0.0] })),
                );
            }
        }
        let scanner = LaserScanner {
            elevation_min_rad: -0.5,
            elevation_max_rad: -0.5,
            ..LaserScanner::at([0.0; 3])
        };
        let (m, stats) = scanner.scan(&mut Wall, [-2.0, -2.0], RES, 160, 160).unwrap();
        assert_eq!(m.known_count(), 0);
        assert_eq!(stats.steep_hits, stats.rays);
    }

    #[test]
    fn returns_are_max_accumulated_and_out_of_range_dropped() {
        // Straight down from 1 m: distance 1 → z = 0; 0.7 → z = 0.3; 9 → beyond range.
        struct Seq(Vec<f64>);
        impl RayCaster for Seq {
            fn cast_rays(&mut self, _: [f64; 3], d: &[[f64; 3]], hits: &mut Vec<Option<RayHit>>) {
                hits.clear();
                let dist = self.0.pop();
                hits.extend(
                    d.iter()
                        .map(|_| dist.map(|distance| RayHit { distance, normal: [0.0, 0.0, 1.0] })),
                );
            }
        }
        let down = LaserScanner {
            azimuth_span_rad: 0.1,
            azimuth_step_rad: 1.0,
            elevation_min_rad: -std::f64::consts::FRAC_PI_2,
            elevation_max_rad: -std::f64::consts::FRAC_PI_2,
            ..LaserScanner::at([0.01, 0.01, 1.0])
        };
        assert_eq!(down.ray_count(), 1);
        let mut m = HeightMap::unknown([0.0, 0.0], RES, 2, 2).unwrap();
        let mut caster = Seq(vec![9.0, 1.0, 0.7]);
        down.scan_into(&mut caster, &mut m).unwrap();
        assert!((m.get(0, 0).unwrap() - 0.3).abs() < 1e-12);
        down.scan_into(&mut caster, &mut m).unwrap();
        assert!((m.get(0, 0).unwrap() - 0.3).abs() < 1e-12, "max is kept");
        let s = down.scan_into(&mut caster, &mut m).unwrap();
        assert_eq!(s.out_of_range, 1);
        assert_eq!(m.known_count(), 1);
    }

    #[test]
    fn pattern_is_deterministic_and_validated() {
        let s = LaserScanner::at([0.0, 0.0, 1.0]);
        assert_eq!(s.ray_count(), 1200 * 751);
        let d1 = s.directions().unwrap();
        assert_eq!(d1, s.directions().unwrap());
        assert!(d1.iter().all(|u| (dot(*u, *u) - 1.0).abs() < 1e-12 && u[2] < 0.0));
        let bad = LaserScanner { azimuth_step_rad: 0.0, ..s.clone() };
        assert!(matches!(
            bad.validate(),
            Err(SensedError::BadScanner { name: "azimuth_step_rad", .. })
        ));
        let bad = LaserScanner { origin: [f64::NAN, 0.0, 0.0], ..s };
        assert!(bad.validate().is_err());
    }

    #[test]
    fn caster_contract_is_checked() {
        struct Short;
        impl RayCaster for Short {
            fn cast_rays(&mut self, _: [f64; 3], _: &[[f64; 3]], hits: &mut Vec<Option<RayHit>>) {
                hits.clear();
            }
        }
        let s = LaserScanner::at([0.0, 0.0, 1.0]);
        let r = s.scan(&mut Short, [0.0, 0.0], RES, 4, 4);
        assert!(matches!(r, Err(SensedError::HitCountMismatch { .. })));
    }
}
