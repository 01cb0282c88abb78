//! Rerun recordings (.rrd): the only module that imports rerun.
//!
//! Layout of a recording, on the `sim_time` timeline (seconds of simulated time):
//! - `world/terrain/<geom>`: terrain shapes, static;
//! - `world/robot/<body>`: one transform per body over time, its geoms static beneath it;
//! - `world/stability/com` (CoM projected on the ground), `world/stability/support_polygon`;
//! - `plots/stability_margin_m`: the margin as a time series;
//! - `world/plan/...` and `maps/...`: plans and cost layers, where a job logs them.
//!
//! The per-frame series (bodies, stability overlay, trajectory, plots) are buffered
//! ([`Pending`]) and sent as columns; they carry the `sim_time` timeline only (no
//! `log_tick` or `log_time`: a `log` call per sample was a quarter of a run's wall time).

use crate::geometry::Pose2;
use crate::monitor::StabilitySample;
use crate::path::{ManoeuvreKind, PathElement};
use crate::render::RgbImage;
use crate::robot::Leg;
use crate::sim::{BodyPose, GeomKind, GeomShape};
use crate::terrain::HeightMap;
use std::path::{Path, PathBuf};

/// Name of the timeline of simulated time.
pub const SIM_TIME: &str = "sim_time";

/// A recording could not be written.
#[derive(Debug, thiserror::Error)]
pub enum VizError {
    /// Opening or writing the file failed.
    #[error("cannot write recording {path}: {message}")]
    Write {
        /// The .rrd file.
        path: PathBuf,
        /// Rerun's message.
        message: String,
    },
}

/// An open .rrd recording.
pub struct Recorder {
    rec: rerun::RecordingStream,
    path: PathBuf,
    body_names: Vec<String>,
    /// Time series not yet sent (see [`Pending`]).
    pending: Pending,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder").field("path", &self.path).finish_non_exhaustive()
    }
}

fn rgba_u8(c: [f32; 4]) -> rerun::Color {
    let [r, g, b, a] = albedo(c);
    rerun::Color::from_unmultiplied_rgba(r, g, b, a)
}

fn albedo(c: [f32; 4]) -> [u8; 4] {
    c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

fn v3(p: [f64; 3]) -> [f32; 3] {
    [p[0] as f32, p[1] as f32, p[2] as f32]
}

fn quat(q: [f64; 4]) -> rerun::Quaternion {
    // MuJoCo stores (w, x, y, z); rerun takes (x, y, z, w).
    rerun::Quaternion::from_xyzw([q[1] as f32, q[2] as f32, q[3] as f32, q[0] as f32])
}

impl Recorder {
    /// Creates the file `path` for application `app`.
    ///
    /// # Errors
    /// [`VizError::Write`] if the file cannot be created.
    pub fn create(path: &Path, app: &'static str) -> Result<Self, VizError> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| VizError::Write { path: path.to_owned(), message: e.to_string() })?;
        }
        let rec = rerun::RecordingStreamBuilder::new(app)
            .save(path)
            .map_err(|e| VizError::Write { path: path.to_owned(), message: e.to_string() })?;
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())
            .map_err(|e| VizError::Write { path: path.to_owned(), message: e.to_string() })?;
        Ok(Self { rec, path: path.to_owned(), body_names: Vec::new(), pending: Pending::default() })
    }

    fn err(&self, e: impl std::fmt::Display) -> VizError {
        VizError::Write { path: self.path.clone(), message: e.to_string() }
    }

    /// Logs the world's shapes once: terrain geoms under `world/terrain`, robot geoms under
    /// their bodies. `bodies` names the bodies in model order (body 0 is the world).
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_world(&mut self, shapes: &[GeomShape], bodies: &[BodyPose]) -> Result<(), VizError> {
        self.body_names = std::iter::once("world".to_owned())
            .chain(bodies.iter().map(|b| b.name.clone()))
            .collect();
        for (i, g) in shapes.iter().enumerate() {
            let name = if g.name.is_empty() { format!("geom_{i}") } else { g.name.clone() };
            let entity = if g.body == 0 {
                format!("world/terrain/{name}")
            } else {
                let body = self
                    .body_names
                    .get(g.body)
                    .cloned()
                    .unwrap_or_else(|| format!("body_{}", g.body));
                format!("world/robot/{body}/{name}")
            };
            let color = rgba_u8(g.rgba);
            let s = g.size;
            let pose = rerun::Transform3D::from_translation_rotation(
                v3(g.local_position),
                quat(g.local_quaternion),
            );
            self.rec.log_static(entity.as_str(), &pose).map_err(|e| self.err(e))?;
            let logged = match g.kind {
                GeomKind::Box => self.rec.log_static(
                    entity.as_str(),
                    &rerun::Boxes3D::from_half_sizes([v3(s)])
                        .with_colors([color])
                        .with_fill_mode(rerun::FillMode::Solid),
                ),
                GeomKind::Plane => self.rec.log_static(
                    entity.as_str(),
                    &rerun::Boxes3D::from_centers_and_half_sizes(
                        [[0.0, 0.0, -0.001]],
                        [[s[0] as f32, s[1] as f32, 0.001]],
                    )
                    .with_colors([rerun::Color::from_rgb(200, 200, 190)])
                    .with_fill_mode(rerun::FillMode::Solid),
                ),
                GeomKind::Sphere => self.rec.log_static(
                    entity.as_str(),
                    &rerun::Ellipsoids3D::from_radii([s[0] as f32])
                        .with_colors([color])
                        .with_fill_mode(rerun::FillMode::Solid),
                ),
                GeomKind::Capsule => self.rec.log_static(
                    entity.as_str(),
                    &rerun::Capsules3D::from_endpoints_and_radii(
                        [[0.0, 0.0, -s[1] as f32]],
                        [[0.0, 0.0, s[1] as f32]],
                        [s[0] as f32],
                    )
                    .with_colors([color]),
                ),
                GeomKind::Cylinder => self.rec.log_static(
                    entity.as_str(),
                    &rerun::Cylinders3D::from_lengths_and_radii([2.0 * s[1] as f32], [s[0] as f32])
                        .with_colors([color])
                        .with_fill_mode(rerun::FillMode::Solid),
                ),
                GeomKind::Mesh => {
                    let vertices: Vec<[f32; 3]> =
                        g.triangles.iter().flat_map(|t| t.map(v3)).collect();
                    let indices: Vec<[u32; 3]> = (0..g.triangles.len() as u32)
                        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                        .collect();
                    self.rec.log_static(
                        entity.as_str(),
                        &rerun::Mesh3D::new(vertices)
                            .with_triangle_indices(indices)
                            .with_albedo_factor(albedo(g.rgba)),
                    )
                }
            };
            logged.map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// Logs the bodies' poses at simulated time `time` (buffered, see [`Pending`]).
    ///
    /// # Errors
    /// [`VizError`] if writing a full buffer fails.
    pub fn log_bodies(&mut self, time: f64, bodies: &[BodyPose]) -> Result<(), VizError> {
        for (k, b) in bodies.iter().enumerate() {
            let column = Column::find(&mut self.pending.bodies, k, &b.name);
            column.push(time, (v3(b.position), b.quaternion));
        }
        self.rows_logged(bodies.len())
    }

    /// Logs a stability sample: the CoM's ground projection, the support polygon and the
    /// margin time series (buffered, see [`Pending`]).
    ///
    /// # Errors
    /// [`VizError`] if writing a full buffer fails.
    pub fn log_stability(&mut self, s: &StabilitySample, ground_z: f64) -> Result<(), VizError> {
        let z = ground_z as f32 + 0.005;
        let stable = s.margin > 0.0;
        let com = [[s.com[0] as f32, s.com[1] as f32, z], v3(s.com)];
        self.pending.com.push(s.time, (com, stable));
        let mut ring: Vec<[f32; 3]> =
            s.support_polygon.iter().map(|p| [p[0] as f32, p[1] as f32, z]).collect();
        if let Some(first) = ring.first().copied() {
            ring.push(first);
        }
        self.pending.support.push(s.time, (ring, stable));
        if s.margin.is_finite() {
            Column::find(&mut self.pending.scalars, 0, "stability_margin_m").push(s.time, s.margin);
        }
        self.rows_logged(3)
    }

    /// Logs the load on each leg's wheel pair (N) as time series under
    /// `plots/wheel_load_n/<leg>`: a pair at zero has left the ground, and the load-sharing
    /// controllers (`control::load_sharing`) keep the diagonals near their share.
    ///
    /// # Errors
    /// [`VizError`] if writing a full buffer fails.
    pub fn log_wheel_loads(&mut self, time: f64, loads: &[f64; 4]) -> Result<(), VizError> {
        for (leg, load) in Leg::ALL.iter().zip(loads) {
            self.log_scalar(time, &format!("wheel_load_n/{}", leg.prefix()), *load)?;
        }
        Ok(())
    }

    /// Logs a scalar time series value under `plots/<name>` (buffered, see [`Pending`]).
    ///
    /// # Errors
    /// [`VizError`] if writing a full buffer fails.
    pub fn log_scalar(&mut self, time: f64, name: &str, value: f64) -> Result<(), VizError> {
        Column::find(&mut self.pending.scalars, 0, name).push(time, value);
        self.rows_logged(1)
    }

    /// Logs the known cells of a height map as a static point cloud under
    /// `world/height_map`, coloured from low (blue) to high (orange).
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_height_map(&self, map: &HeightMap) -> Result<(), VizError> {
        let (nx, ny) = map.dims();
        let mut points = Vec::new();
        let mut heights = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                if let Some(h) = map.get(i, j) {
                    let c = map.cell_center(i, j);
                    points.push([c[0] as f32, c[1] as f32, h as f32]);
                    heights.push(h);
                }
            }
        }
        let (lo, hi) = heights
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &h| (a.min(h), b.max(h)));
        let span = if hi > lo { hi - lo } else { 1.0 };
        let colors: Vec<rerun::Color> = heights
            .iter()
            .map(|h| {
                let t = ((h - lo) / span) as f32;
                rerun::Color::from_rgb(
                    (40.0 + 200.0 * t) as u8,
                    (90.0 + 60.0 * t) as u8,
                    (200.0 - 170.0 * t) as u8,
                )
            })
            .collect();
        let radius = (map.resolution() / 2.0) as f32;
        self.rec
            .log_static(
                "world/height_map",
                &rerun::Points3D::new(points).with_colors(colors).with_radii([radius]),
            )
            .map_err(|e| self.err(e))
    }

    /// Logs a rendered map layer as a static image under `maps/<name>` (+y up, one pixel per
    /// cell; `origin` and `resolution` are recorded as text beside it).
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_layer_image(
        &self,
        name: &str,
        image: &RgbImage,
        origin: [f64; 2],
        resolution: f64,
    ) -> Result<(), VizError> {
        self.rec
            .log_static(
                format!("maps/{name}"),
                &rerun::Image::from_rgb24(image.pixels.clone(), [image.width, image.height]),
            )
            .map_err(|e| self.err(e))?;
        let text = format!(
            "{name}: {} x {} cells of {resolution} m, cell (0, 0) at ({}, {}), +y up",
            image.width, image.height, origin[0], origin[1]
        );
        self.rec
            .log_static(format!("maps/{name}/info"), &rerun::TextDocument::new(text))
            .map_err(|e| self.err(e))
    }

    /// Logs a planned driving path as a static line strip (base positions, 2 cm above the
    /// ground) with heading arrows every tenth pose, under `world/plan`.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_plan(&self, poses: &[Pose2]) -> Result<(), VizError> {
        let line: Vec<[f32; 3]> = poses.iter().map(|p| [p.x as f32, p.y as f32, 0.02]).collect();
        self.rec
            .log_static(
                "world/plan/path",
                &rerun::LineStrips3D::new([line])
                    .with_colors([rerun::Color::from_rgb(40, 90, 230)]),
            )
            .map_err(|e| self.err(e))?;
        let (origins, vectors): (Vec<[f32; 3]>, Vec<[f32; 3]>) = poses
            .iter()
            .step_by(10)
            .map(|p| {
                (
                    [p.x as f32, p.y as f32, 0.02],
                    [0.1 * p.theta.cos() as f32, 0.1 * p.theta.sin() as f32, 0.0],
                )
            })
            .unzip();
        self.rec
            .log_static(
                "world/plan/headings",
                &rerun::Arrows3D::from_vectors(vectors).with_origins(origins),
            )
            .map_err(|e| self.err(e))
    }

    /// Logs abstract steps as static lines from the old foot position to the foothold, front
    /// steps red and rear steps green (paper Fig. 11), under `world/plan/steps`.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_steps(&self, steps: &[([f64; 3], [f64; 3], bool)]) -> Result<(), VizError> {
        let lines: Vec<Vec<[f32; 3]>> =
            steps.iter().map(|(a, b, _)| vec![v3(*a), v3(*b)]).collect();
        let colors: Vec<rerun::Color> = steps
            .iter()
            .map(|(_, _, front)| {
                if *front {
                    rerun::Color::from_rgb(220, 40, 40)
                } else {
                    rerun::Color::from_rgb(40, 180, 60)
                }
            })
            .collect();
        self.rec
            .log_static("world/plan/steps", &rerun::LineStrips3D::new(lines).with_colors(colors))
            .map_err(|e| self.err(e))
    }

    /// Appends the base position to the executed trajectory (`world/trajectory`,
    /// buffered, see [`Pending`]).
    ///
    /// # Errors
    /// [`VizError`] if writing a full buffer fails.
    pub fn log_trajectory_point(&mut self, time: f64, position: [f64; 3]) -> Result<(), VizError> {
        self.pending.trajectory.push(time, v3(position));
        self.rows_logged(1)
    }

    /// Writes the buffered time series and flushes and closes the file.
    ///
    /// # Errors
    /// [`VizError`] if the final write fails.
    pub fn finish(mut self) -> Result<(), VizError> {
        self.send_pending()?;
        self.rec.flush_blocking().map_err(|e| self.err(e))
    }

    /// Counts `n` buffered rows; sends the buffers once they hold [`FLUSH_ROWS`].
    fn rows_logged(&mut self, n: usize) -> Result<(), VizError> {
        self.pending.rows += n;
        if self.pending.rows >= FLUSH_ROWS { self.send_pending() } else { Ok(()) }
    }

    /// Sends every buffered time series as columns, one `send_columns` per entity, and
    /// empties the buffers.
    fn send_pending(&mut self) -> Result<(), VizError> {
        let pending = std::mem::take(&mut self.pending);
        for c in pending.bodies {
            let (translations, rotations): (Vec<[f32; 3]>, Vec<rerun::Quaternion>) =
                c.values.iter().map(|&(t, q)| (t, quat(q))).unzip();
            let columns = rerun::Transform3D::update_fields()
                .with_many_translation(translations)
                .with_many_quaternion(rotations)
                .columns_of_unit_batches();
            self.send(&format!("world/robot/{}", c.entity), &c.times, columns)?;
        }
        for c in pending.scalars {
            let columns = rerun::Scalars::update_fields()
                .with_scalars(c.values.iter().copied())
                .columns_of_unit_batches();
            self.send(&format!("plots/{}", c.entity), &c.times, columns)?;
        }
        let com = &pending.com;
        // Two points a row (on the ground, at the CoM) sharing one radius and colour, as
        // `log` writes them: the positions partitioned by two, the rest by one.
        let n = com.values.len();
        let columns = rerun::Points3D::update_fields()
            .with_positions(com.values.iter().flat_map(|(p, _)| *p))
            .columns(std::iter::repeat_n(2, n))
            .and_then(|points| {
                let style = rerun::Points3D::update_fields()
                    .with_radii(std::iter::repeat_n(0.025f32, n))
                    .with_colors(com.values.iter().map(|&(_, stable)| margin_color(stable)))
                    .columns_of_unit_batches()?;
                Ok(points.chain(style))
            });
        self.send("world/stability/com", &com.times, columns)?;
        let support = &pending.support;
        let columns = rerun::LineStrips3D::update_fields()
            .with_strips(support.values.iter().map(|(ring, _)| ring.clone()))
            .with_colors(support.values.iter().map(|&(_, stable)| margin_color(stable)))
            .columns_of_unit_batches();
        self.send("world/stability/support_polygon", &support.times, columns)?;
        let trajectory = &pending.trajectory;
        let n = trajectory.values.len();
        let columns = rerun::Points3D::update_fields()
            .with_positions(trajectory.values.iter().copied())
            .with_radii(std::iter::repeat_n(0.01f32, n))
            .with_colors(std::iter::repeat_n(rerun::Color::from_rgb(230, 120, 20), n))
            .columns_of_unit_batches();
        self.send("world/trajectory", &trajectory.times, columns)
    }

    /// One `send_columns` of `columns` at `times` on the sim-time timeline (nothing for
    /// no rows).
    fn send<C>(
        &self,
        entity: &str,
        times: &[f64],
        columns: Result<C, rerun::SerializationError>,
    ) -> Result<(), VizError>
    where
        C: IntoIterator<Item = rerun::SerializedComponentColumn>,
    {
        if times.is_empty() {
            return Ok(());
        }
        let index = rerun::TimeColumn::new_duration_secs(SIM_TIME, times.iter().copied());
        let columns = columns.map_err(|e| self.err(e))?;
        self.rec.send_columns(entity, [index], columns).map_err(|e| self.err(e))
    }
}

impl Drop for Recorder {
    /// Sends what is still buffered, so that a job that stops on an error (without
    /// [`Recorder::finish`]) keeps its time series; a write error here has no one to go to.
    fn drop(&mut self) {
        let _ = self.send_pending();
    }
}

/// The colour of the stability overlay: green with a positive margin, else red.
fn margin_color(stable: bool) -> rerun::Color {
    if stable { rerun::Color::from_rgb(40, 200, 60) } else { rerun::Color::from_rgb(230, 40, 40) }
}

/// Samples buffered before they are sent: a frame of a run logged some 40 rows (a
/// transform per body, the stability overlay, the plots), and a `log` call costs about
/// 10 µs of the simulation thread plus the batcher's work on the other core; the
/// platform's run took 7.2 s with a recording and 5.8 s without. Sent as columns
/// (`send_columns`, a chunk per entity) every [`FLUSH_ROWS`] samples and at the end.
#[derive(Debug, Default)]
struct Pending {
    /// Per body, in the order the simulation lists them, by body name.
    bodies: Vec<Column<([f32; 3], [f64; 4])>>,
    /// Per series, by name under `plots/`.
    scalars: Vec<Column<f64>>,
    /// The CoM on the ground and in space, and whether the margin was positive.
    com: Column<([[f32; 3]; 2], bool)>,
    /// The closed support polygon, and whether the margin was positive.
    support: Column<(Vec<[f32; 3]>, bool)>,
    /// The base positions.
    trajectory: Column<[f32; 3]>,
    /// Rows buffered since the last send.
    rows: usize,
}

/// Rows buffered before a send: about 1,000 frames of a run (some 40 rows each), 40 s of
/// simulated time at its recording rate of 25 Hz; a few MB.
const FLUSH_ROWS: usize = 40_000;

/// One entity's buffered samples: times (s) and values.
#[derive(Debug)]
struct Column<T> {
    entity: String,
    times: Vec<f64>,
    values: Vec<T>,
}

impl<T> Default for Column<T> {
    fn default() -> Self {
        Self { entity: String::new(), times: Vec::new(), values: Vec::new() }
    }
}

impl<T> Column<T> {
    /// The column of `entity` in `columns`, tried at index `hint` first (the bodies come
    /// in the same order every frame), added at the end if there is none.
    fn find<'a>(columns: &'a mut Vec<Column<T>>, hint: usize, entity: &str) -> &'a mut Self {
        let k = if columns.get(hint).is_some_and(|c| c.entity == entity) {
            hint
        } else if let Some(k) = columns.iter().position(|c| c.entity == entity) {
            k
        } else {
            columns.push(Column { entity: entity.to_owned(), ..Column::default() });
            columns.len() - 1
        };
        &mut columns[k]
    }

    fn push(&mut self, time: f64, value: T) {
        self.times.push(time);
        self.values.push(value);
    }
}

impl Recorder {
    /// Logs the keyframes of a detailed path (step motion generation) on the `sim_time`
    /// timeline at their times: the base origin under `world/keyframes/base`, the feet
    /// (in contact green, lifted red) under `world/keyframes/feet`, the support polygon and
    /// the CoM's ground projection under `world/keyframes/support` and `…/com`, the expected
    /// margin under `plots/keyframe_margin_m`, and the phase name as a text log.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_keyframes(&self, keyframes: &[crate::motion::Keyframe]) -> Result<(), VizError> {
        for k in keyframes {
            self.rec.set_duration_secs(SIM_TIME, k.time_s);
            self.rec
                .log(
                    "world/keyframes/base",
                    &rerun::Points3D::new([v3(k.base_position)])
                        .with_radii([0.03])
                        .with_colors([rerun::Color::from_rgb(230, 120, 20)]),
                )
                .map_err(|e| self.err(e))?;
            let colors: Vec<rerun::Color> = k
                .contact
                .iter()
                .map(|&c| {
                    if c {
                        rerun::Color::from_rgb(40, 200, 60)
                    } else {
                        rerun::Color::from_rgb(230, 40, 40)
                    }
                })
                .collect();
            self.rec
                .log(
                    "world/keyframes/feet",
                    &rerun::Points3D::new(k.feet.iter().map(|f| v3(*f)))
                        .with_radii([0.04])
                        .with_colors(colors),
                )
                .map_err(|e| self.err(e))?;
            let ground = k
                .feet
                .iter()
                .zip(k.contact)
                .filter(|(_, c)| *c)
                .map(|(f, _)| f[2])
                .fold(f64::INFINITY, f64::min);
            let z = if ground.is_finite() { ground as f32 + 0.01 } else { 0.01 };
            let support: Vec<[f64; 2]> = k
                .feet
                .iter()
                .zip(k.contact)
                .filter(|(_, c)| *c)
                .map(|(f, _)| [f[0], f[1]])
                .collect();
            let mut ring: Vec<[f32; 3]> = crate::support::convex_hull(&support)
                .iter()
                .map(|p| [p[0] as f32, p[1] as f32, z])
                .collect();
            if let Some(first) = ring.first().copied() {
                ring.push(first);
            }
            self.rec
                .log("world/keyframes/support", &rerun::LineStrips3D::new([ring]))
                .map_err(|e| self.err(e))?;
            self.rec
                .log(
                    "world/keyframes/com",
                    &rerun::Points3D::new([[k.com[0] as f32, k.com[1] as f32, z], v3(k.com)])
                        .with_radii([0.02]),
                )
                .map_err(|e| self.err(e))?;
            if k.margin_m.is_finite() {
                self.rec
                    .log("plots/keyframe_margin_m", &rerun::Scalars::single(k.margin_m))
                    .map_err(|e| self.err(e))?;
            }
            self.rec
                .log("world/keyframes/phase", &rerun::TextLog::new(k.phase.name()))
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }
}

/// Each step of `path` as a line from the old foot position to its foothold, 2 cm
/// above the ground, and whether a front leg steps (red) or a rear one (green).
pub fn step_lines(path: &[PathElement]) -> Vec<([f64; 3], [f64; 3], bool)> {
    let mut steps = Vec::new();
    for pair in path.windows(2) {
        let (before, after) = (&pair[0], &pair[1]);
        if after.kind == ManoeuvreKind::Step
            && let Some(leg) = after.leg
        {
            let i = leg.index();
            let z = |h: Option<f64>| h.unwrap_or(0.0) + 0.02;
            steps.push((
                [before.feet[i][0], before.feet[i][1], z(before.foot_heights[i])],
                [after.feet[i][0], after.feet[i][1], z(after.foot_heights[i])],
                leg.is_front(),
            ));
        }
    }
    steps
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A recorder writing to memory instead of a file.
    fn in_memory() -> (Recorder, rerun::sink::MemorySinkStorage) {
        let (rec, storage) =
            rerun::RecordingStreamBuilder::new("momaro test").memory().expect("memory sink");
        let r = Recorder {
            rec,
            path: PathBuf::from("memory"),
            body_names: Vec::new(),
            pending: Pending::default(),
        };
        (r, storage)
    }

    /// Rows per entity of everything the stream wrote.
    fn rows(storage: &rerun::sink::MemorySinkStorage) -> BTreeMap<String, usize> {
        let mut rows = BTreeMap::new();
        for msg in storage.take() {
            if let rerun::log::LogMsg::ArrowMsg(_, arrow) = msg {
                let chunk = rerun::log::Chunk::from_arrow_msg(&arrow).expect("chunk");
                *rows.entry(chunk.entity_path().to_string()).or_default() += chunk.num_rows();
            }
        }
        rows
    }

    fn body(name: &str, x: f64) -> BodyPose {
        BodyPose {
            name: name.to_owned(),
            position: [x, 0.0, 0.5],
            quaternion: [1.0, 0.0, 0.0, 0.0],
        }
    }

    fn sample(time: f64, margin: f64) -> StabilitySample {
        StabilitySample {
            time,
            com: [0.0, 0.0, 0.6],
            contacts: Vec::new(),
            support_polygon: vec![[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]],
            margin,
            roll_pitch: [0.0; 2],
            vertical_speed: 0.0,
            body_collisions: Vec::new(),
        }
    }

    #[test]
    fn every_buffered_frame_is_written_when_the_recording_finishes() {
        let (mut r, storage) = in_memory();
        for k in 0..30 {
            let t = f64::from(k) * 0.04;
            r.log_bodies(t, &[body("base", t), body("fl_wheel_l", t)]).expect("bodies");
            r.log_stability(&sample(t, if k == 3 { f64::NEG_INFINITY } else { 0.1 }), 0.0)
                .expect("stability");
            r.log_trajectory_point(t, [t, 0.0, 0.5]).expect("trajectory");
            r.log_wheel_loads(t, &[100.0; 4]).expect("loads");
        }
        r.finish().expect("finish");
        let rows = rows(&storage);
        for entity in [
            "/world/robot/base",
            "/world/robot/fl_wheel_l",
            "/world/stability/com",
            "/world/stability/support_polygon",
            "/world/trajectory",
            "/plots/wheel_load_n/fl",
            "/plots/wheel_load_n/rr",
        ] {
            assert_eq!(rows.get(entity), Some(&30), "{entity}: {rows:?}");
        }
        // No margin where no wheel supports the robot (−∞).
        assert_eq!(rows.get("/plots/stability_margin_m"), Some(&29), "{rows:?}");
    }

    #[test]
    fn a_recording_dropped_without_finish_keeps_what_it_buffered_past_a_flush() {
        let (mut r, storage) = in_memory();
        // Two bodies a frame: the buffers are sent once on the way (FLUSH_ROWS) and the
        // rest when the recorder is dropped, as a job that stops on an error drops it.
        let frames = FLUSH_ROWS / 2 + 7;
        for k in 0..frames {
            let t = k as f64 * 0.04;
            r.log_bodies(t, &[body("base", t), body("fl_thigh", t)]).expect("bodies");
        }
        drop(r);
        let rows = rows(&storage);
        assert_eq!(rows.get("/world/robot/base"), Some(&frames), "{rows:?}");
        assert_eq!(rows.get("/world/robot/fl_thigh"), Some(&frames), "{rows:?}");
    }
}
