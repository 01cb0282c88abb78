//! Rerun recordings (.rrd): the only module that imports rerun.
//!
//! Layout of a recording, on the `sim_time` timeline (seconds of simulated time):
//! - `world/terrain/<geom>`: terrain shapes, static;
//! - `world/robot/<body>`: one transform per body over time, its geoms static beneath it;
//! - `world/stability/com` (CoM projected on the ground), `world/stability/support_polygon`;
//! - `plots/stability_margin_m`: the margin as a time series;
//! - `world/plan/...` and `maps/...`: plans and cost layers, where a job logs them.

use crate::cost_image::RgbImage;
use crate::geometry::Pose2;
use crate::monitor::StabilitySample;
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
        Ok(Self { rec, path: path.to_owned(), body_names: Vec::new() })
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

    /// Logs the bodies' poses at simulated time `time`.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_bodies(&self, time: f64, bodies: &[BodyPose]) -> Result<(), VizError> {
        self.rec.set_duration_secs(SIM_TIME, time);
        for b in bodies {
            let t =
                rerun::Transform3D::from_translation_rotation(v3(b.position), quat(b.quaternion));
            self.rec.log(format!("world/robot/{}", b.name), &t).map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// Logs a stability sample: the CoM's ground projection, the support polygon and the
    /// margin time series.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_stability(&self, s: &StabilitySample, ground_z: f64) -> Result<(), VizError> {
        self.rec.set_duration_secs(SIM_TIME, s.time);
        let z = ground_z as f32 + 0.005;
        let color = if s.margin > 0.0 {
            rerun::Color::from_rgb(40, 200, 60)
        } else {
            rerun::Color::from_rgb(230, 40, 40)
        };
        self.rec
            .log(
                "world/stability/com",
                &rerun::Points3D::new([[s.com[0] as f32, s.com[1] as f32, z], v3(s.com)])
                    .with_radii([0.025])
                    .with_colors([color]),
            )
            .map_err(|e| self.err(e))?;
        let mut ring: Vec<[f32; 3]> =
            s.support_polygon.iter().map(|p| [p[0] as f32, p[1] as f32, z]).collect();
        if let Some(first) = ring.first().copied() {
            ring.push(first);
        }
        self.rec
            .log(
                "world/stability/support_polygon",
                &rerun::LineStrips3D::new([ring]).with_colors([color]),
            )
            .map_err(|e| self.err(e))?;
        if s.margin.is_finite() {
            self.rec
                .log("plots/stability_margin_m", &rerun::Scalars::single(s.margin))
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }

    /// Logs the load on each leg's wheel pair (N) as time series under
    /// `plots/wheel_load_n/<leg>`: a pair at zero has left the ground, and the load-sharing
    /// controllers (`control::load_sharing`) keep the diagonals near their share.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_wheel_loads(&self, time: f64, loads: &[f64; 4]) -> Result<(), VizError> {
        for (leg, load) in Leg::ALL.iter().zip(loads) {
            self.log_scalar(time, &format!("wheel_load_n/{}", leg.prefix()), *load)?;
        }
        Ok(())
    }

    /// Logs a scalar time series value under `plots/<name>`.
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_scalar(&self, time: f64, name: &str, value: f64) -> Result<(), VizError> {
        self.rec.set_duration_secs(SIM_TIME, time);
        self.rec
            .log(format!("plots/{name}"), &rerun::Scalars::single(value))
            .map_err(|e| self.err(e))
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

    /// Appends the base position to the executed trajectory (`world/trajectory`).
    ///
    /// # Errors
    /// [`VizError`] if writing fails.
    pub fn log_trajectory_point(&self, time: f64, position: [f64; 3]) -> Result<(), VizError> {
        self.rec.set_duration_secs(SIM_TIME, time);
        self.rec
            .log(
                "world/trajectory",
                &rerun::Points3D::new([v3(position)])
                    .with_radii([0.01])
                    .with_colors([rerun::Color::from_rgb(230, 120, 20)]),
            )
            .map_err(|e| self.err(e))
    }

    /// Flushes and closes the file.
    ///
    /// # Errors
    /// [`VizError`] if the final write fails.
    pub fn finish(self) -> Result<(), VizError> {
        self.rec.flush_blocking().map_err(|e| self.err(e))
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
            let mut ring: Vec<[f32; 3]> = crate::stability::convex_hull(&support)
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
