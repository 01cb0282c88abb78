//! The simulated robot in MuJoCo: the only module that imports mujoco-rs.
//!
//! [`Simulation`] compiles a scenario's world (`world`), reads the robot's description
//! from the compiled model (`model`), and offers what controllers and monitors need in the
//! project's own types: base pose, joint positions, the whole-robot CoM as MuJoCo computes
//! it, which wheels touch the terrain and where, the load on each wheel pair, actuator
//! targets, external pushes, ray casts for the sensed height map, and body poses for
//! recordings.

pub mod model;
pub mod world;

use crate::robot::{Leg, RobotDescription};
use crate::scenario::Scenario;
use crate::terrain::sensed::{RayCaster, RayHit};
use mujoco_rs::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What can go wrong building or querying the simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The robot model file is missing or unreadable.
    #[error("cannot read robot model {path}: {source}")]
    ModelFile {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// MuJoCo rejected the world.
    #[error("MuJoCo could not compile the world of {scenario}: {message}")]
    Compile {
        /// Scenario name.
        scenario: String,
        /// MuJoCo's message.
        message: String,
    },
    /// The model lacks an element the program relies on.
    #[error("robot model has no {kind} named `{name}`")]
    MissingElement {
        /// Element kind (body, joint, ...).
        kind: String,
        /// Its expected name.
        name: String,
    },
    /// The model's numbers are inconsistent.
    #[error("robot model is inconsistent: {0}")]
    BadModel(String),
    /// The simulation diverged (NaN or a MuJoCo warning that invalidates the state).
    #[error("simulation diverged at t = {time:.3} s: {what}")]
    Diverged {
        /// Simulated time.
        time: f64,
        /// What was seen.
        what: String,
    },
}

/// Actuator and state indices of one leg.
#[derive(Debug, Clone, Copy)]
struct LegIds {
    /// Actuators: hip, knee, ankle, steer, wheel left, wheel right.
    actuators: [usize; 6],
    /// qpos addresses: hip, knee, ankle, steer.
    qpos: [usize; 4],
    /// qvel addresses of the two wheels.
    wheel_qvel: [usize; 2],
    /// qvel address of the steering joint.
    steer_qvel: usize,
    /// Geoms of the two wheels.
    wheel_geoms: [usize; 2],
    /// Body of the wheel pair's steering carrier.
    steer_body: usize,
}

/// A wheel near or touching the terrain, from MuJoCo's contact list.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelContact {
    /// The leg.
    pub leg: Leg,
    /// 0 = left wheel of the pair, 1 = right.
    pub wheel: usize,
    /// Contact position in the world, m (the mean of the wheel's nearest contacts).
    pub position: [f64; 3],
    /// Signed distance of the wheel from the terrain, m (negative = the foam is pressed
    /// in): the smallest of its contacts.
    pub distance: f64,
}

impl WheelContact {
    /// Whether the wheel touches the terrain ([`TOUCHING_M`]).
    pub fn touching(&self) -> bool {
        self.distance <= TOUCHING_M
    }
}

/// A wheel closer to the terrain than this touches it, m: the controllers' idea of
/// contact (foot placement, the lift guard).
pub const TOUCHING_M: f64 = 1e-3;

/// Pose of the robot's base in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseState {
    /// Position of the base frame origin, m.
    pub position: [f64; 3],
    /// Orientation quaternion (w, x, y, z).
    pub quaternion: [f64; 4],
    /// Roll, pitch, yaw (ZYX convention), rad.
    pub rpy: [f64; 3],
    /// Linear velocity in the world frame, m/s.
    pub linear_velocity: [f64; 3],
}

/// A rigid body's name and world pose, for recordings.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPose {
    /// Body name.
    pub name: String,
    /// Position, m.
    pub position: [f64; 3],
    /// Quaternion (w, x, y, z).
    pub quaternion: [f64; 4],
}

/// A geom's shape for drawing: boxes, spheres, capsules, cylinders, and meshes as boxes of
/// their bounding size.
#[derive(Debug, Clone, PartialEq)]
pub struct GeomShape {
    /// Geom name ("" if unnamed).
    pub name: String,
    /// Body the geom belongs to (0 = world).
    pub body: usize,
    /// Kind.
    pub kind: GeomKind,
    /// MuJoCo size parameters.
    pub size: [f64; 3],
    /// RGBA colour, 0..1.
    pub rgba: [f32; 4],
    /// Position in its body's frame, m.
    pub local_position: [f64; 3],
    /// Orientation in its body's frame (w, x, y, z).
    pub local_quaternion: [f64; 4],
    /// For meshes: triangles in the geom's frame.
    pub triangles: Vec<[[f64; 3]; 3]>,
}

/// Geom kinds the recorder draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeomKind {
    /// Half extents in `size`.
    Box,
    /// Radius in `size[0]`.
    Sphere,
    /// Radius, half length.
    Capsule,
    /// Radius, half height.
    Cylinder,
    /// Infinite plane, drawn over `size[0..2]` half extents.
    Plane,
    /// Convex mesh (terrain ramps): drawn from its vertices by the recorder.
    Mesh,
}

/// A running MuJoCo simulation of a scenario's world.
pub struct Simulation {
    model: Arc<MjModel>,
    data: MjData<Arc<MjModel>>,
    robot: RobotDescription,
    legs: [LegIds; 4],
    base_body: usize,
    base_qpos: usize,
    base_qvel: usize,
    terrain_geoms: Vec<bool>,
    /// Scratch data for kinematic queries that must not disturb the simulation.
    scratch: Option<MjData<Arc<MjModel>>>,
}

impl std::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulation").field("time", &self.time()).finish_non_exhaustive()
    }
}

/// Default location of the robot model, relative to the repository root.
pub fn default_model_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models").join("momaro.xml")
}

impl Simulation {
    /// Compiles the world of `scenario` around the robot model at `model_path`.
    ///
    /// # Errors
    /// [`SimError`] if the model file is missing, MuJoCo rejects the world, or the model
    /// lacks an element the program needs.
    pub fn new(scenario: &Scenario, model_path: &Path) -> Result<Self, SimError> {
        let xml = world::world_xml(&scenario.name, &scenario.map, &scenario.terrain);
        Self::compile(&scenario.name, &xml, model_path)
    }

    /// The robot alone on flat ground (for exports and kinematic checks).
    ///
    /// # Errors
    /// As [`Simulation::new`].
    pub fn robot_only(model_path: &Path) -> Result<Self, SimError> {
        let map = crate::scenario::MapExtent { x_min: -5.0, x_max: 5.0, y_min: -5.0, y_max: 5.0 };
        Self::compile("robot", &world::world_xml("robot", &map, &[]), model_path)
    }

    fn compile(name: &str, xml: &str, model_path: &Path) -> Result<Self, SimError> {
        let robot_xml = std::fs::read(model_path)
            .map_err(|source| SimError::ModelFile { path: model_path.to_owned(), source })?;
        let compile_err =
            |message: String| SimError::Compile { scenario: name.to_owned(), message };
        let mut vfs = mujoco_rs::wrappers::mj_auxiliary::MjVfs::new();
        vfs.add_from_buffer(world::ROBOT_FILE, &robot_xml)
            .map_err(|e| compile_err(e.to_string()))?;
        vfs.add_from_buffer("world.xml", xml.as_bytes()).map_err(|e| compile_err(e.to_string()))?;
        let model =
            MjModel::from_xml_vfs("world.xml", &vfs).map_err(|e| compile_err(e.to_string()))?;
        Self::from_model(Arc::new(model))
    }

    fn from_model(model: Arc<MjModel>) -> Result<Self, SimError> {
        let robot = model::describe(&model)?;
        let joint_adr = |name: &str| -> Result<(usize, usize), SimError> {
            let j = model::id(&model, MjtObjBase::mjOBJ_JOINT, name)?;
            let q = usize::try_from(model.jnt_qposadr()[j])
                .map_err(|_| SimError::BadModel(name.into()))?;
            let v = usize::try_from(model.jnt_dofadr()[j])
                .map_err(|_| SimError::BadModel(name.into()))?;
            Ok((q, v))
        };
        let mut legs = Vec::with_capacity(4);
        for leg in Leg::ALL {
            let p = leg.prefix();
            let names = model::LegNames::of(leg);
            let act = |suffix: &str| {
                model::id(&model, MjtObjBase::mjOBJ_ACTUATOR, &format!("{p}_{suffix}"))
            };
            let actuators = [
                act("hip")?,
                act("knee")?,
                act("ankle")?,
                act("steer")?,
                act("wheel_l")?,
                act("wheel_r")?,
            ];
            let qpos = [
                joint_adr(&format!("{p}_hip"))?.0,
                joint_adr(&format!("{p}_knee"))?.0,
                joint_adr(&format!("{p}_ankle"))?.0,
                joint_adr(&format!("{p}_steer"))?.0,
            ];
            let (w0, w1) = (joint_adr(&names.wheels[0])?, joint_adr(&names.wheels[1])?);
            let wheel_qvel = [w0.1, w1.1];
            let steer_qvel = joint_adr(&format!("{p}_steer"))?.1;
            let wheel_geoms = [
                model::id(&model, MjtObjBase::mjOBJ_GEOM, &names.wheels[0])?,
                model::id(&model, MjtObjBase::mjOBJ_GEOM, &names.wheels[1])?,
            ];
            let steer_body = model::id(&model, MjtObjBase::mjOBJ_BODY, &names.steer)?;
            legs.push(LegIds { actuators, qpos, wheel_qvel, steer_qvel, wheel_geoms, steer_body });
        }
        let legs: [LegIds; 4] =
            legs.try_into().map_err(|_| SimError::BadModel("leg count".into()))?;
        let base_body = model::id(&model, MjtObjBase::mjOBJ_BODY, "base")?;
        let (base_qpos, base_qvel) = joint_adr("root")?;
        let terrain_geoms = (0..model.ffi().ngeom as usize)
            .map(|g| {
                model
                    .id_to_name(MjtObjBase::mjOBJ_GEOM, g)
                    .is_some_and(|n| n.starts_with(world::TERRAIN_PREFIX))
            })
            .collect();
        let data = MjData::new(model.clone());
        Ok(Self {
            model,
            data,
            robot,
            legs,
            base_body,
            base_qpos,
            base_qvel,
            terrain_geoms,
            scratch: None,
        })
    }

    /// The robot's description, read from the compiled model.
    pub fn robot(&self) -> &RobotDescription {
        &self.robot
    }

    /// Physics time step, s.
    pub fn timestep(&self) -> f64 {
        self.model.opt().timestep
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.data.time()
    }

    /// Places the robot: base at `position` with yaw `yaw`, level, at rest, leg joints at
    /// `leg_joints` (hip, knee, ankle per leg), steering straight; actuator targets set to
    /// hold that configuration. Recomputes kinematics.
    pub fn place_robot(&mut self, position: [f64; 3], yaw: f64, leg_joints: &[[f64; 3]; 4]) {
        self.data.reset();
        let (s, c) = (yaw / 2.0).sin_cos();
        let (bq, legs) = (self.base_qpos, self.legs);
        let qpos = self.data.qpos_mut();
        qpos[bq..bq + 7].copy_from_slice(&[position[0], position[1], position[2], c, 0.0, 0.0, s]);
        for (ids, q) in legs.iter().zip(leg_joints) {
            for k in 0..3 {
                qpos[ids.qpos[k]] = q[k];
            }
            qpos[ids.qpos[3]] = 0.0;
        }
        for (leg, q) in Leg::ALL.iter().zip(leg_joints) {
            self.set_leg_joint_targets(*leg, *q);
            self.set_steering_target(*leg, 0.0);
            self.set_wheel_speeds(*leg, [0.0, 0.0]);
        }
        self.data.forward();
    }

    /// Advances the physics by `n` time steps.
    ///
    /// # Errors
    /// [`SimError::Diverged`] if the state becomes non-finite.
    pub fn step(&mut self, n: usize) -> Result<(), SimError> {
        for _ in 0..n {
            self.data.step();
        }
        let bq = self.base_qpos;
        if self.data.qpos()[bq..bq + 7].iter().any(|v| !v.is_finite()) {
            return Err(SimError::Diverged {
                time: self.time(),
                what: "base pose is not finite".into(),
            });
        }
        Ok(())
    }

    /// Hip, knee and ankle position targets, rad.
    pub fn set_leg_joint_targets(&mut self, leg: Leg, q: [f64; 3]) {
        let a = self.legs[leg.index()].actuators;
        let ctrl = self.data.ctrl_mut();
        for k in 0..3 {
            ctrl[a[k]] = q[k];
        }
    }

    /// Steering position target, rad.
    pub fn set_steering_target(&mut self, leg: Leg, angle: f64) {
        let a = self.legs[leg.index()].actuators[3];
        self.data.ctrl_mut()[a] = angle;
    }

    /// Wheel angular speed targets (left, right), rad/s.
    pub fn set_wheel_speeds(&mut self, leg: Leg, speeds: [f64; 2]) {
        let a = self.legs[leg.index()].actuators;
        let ctrl = self.data.ctrl_mut();
        ctrl[a[4]] = speeds[0];
        ctrl[a[5]] = speeds[1];
    }

    /// Measured hip, knee and ankle angles, rad.
    pub fn leg_joints(&self, leg: Leg) -> [f64; 3] {
        let ids = self.legs[leg.index()];
        let qpos = self.data.qpos();
        [qpos[ids.qpos[0]], qpos[ids.qpos[1]], qpos[ids.qpos[2]]]
    }

    /// Measured steering angle, rad.
    pub fn steering_angle(&self, leg: Leg) -> f64 {
        self.data.qpos()[self.legs[leg.index()].qpos[3]]
    }

    /// Measured steering rate, rad/s.
    pub fn steering_rate(&self, leg: Leg) -> f64 {
        self.data.qvel()[self.legs[leg.index()].steer_qvel]
    }

    /// Measured wheel speeds (left, right), rad/s.
    pub fn wheel_speeds(&self, leg: Leg) -> [f64; 2] {
        let ids = self.legs[leg.index()];
        let qvel = self.data.qvel();
        [qvel[ids.wheel_qvel[0]], qvel[ids.wheel_qvel[1]]]
    }

    /// The base's pose and velocity.
    pub fn base(&self) -> BaseState {
        let (bq, bv) = (self.base_qpos, self.base_qvel);
        let qpos = self.data.qpos();
        let qvel = self.data.qvel();
        let position = [qpos[bq], qpos[bq + 1], qpos[bq + 2]];
        let quaternion = [qpos[bq + 3], qpos[bq + 4], qpos[bq + 5], qpos[bq + 6]];
        BaseState {
            position,
            quaternion,
            rpy: quaternion_to_rpy(quaternion),
            linear_velocity: [qvel[bv], qvel[bv + 1], qvel[bv + 2]],
        }
    }

    /// The whole robot's centre of mass as MuJoCo computes it (subtree CoM of the base).
    pub fn center_of_mass(&self) -> [f64; 3] {
        self.data.subtree_com()[self.base_body]
    }

    /// World position of the centre of each leg's wheel pair (the steering carrier's origin,
    /// on the wheel axle).
    pub fn wheel_pair_centres(&self) -> [[f64; 3]; 4] {
        let xpos = self.data.xpos();
        std::array::from_fn(|i| xpos[self.legs[i].steer_body])
    }

    /// The robot's geom in a contact between the robot and the terrain; `None` for any
    /// other contact (robot with robot, terrain with terrain).
    fn robot_geom_on_terrain(
        &self,
        c: &mujoco_rs::wrappers::mj_auxiliary::MjContact,
    ) -> Option<usize> {
        let (g1, g2) = (usize::try_from(c.geom1).ok()?, usize::try_from(c.geom2).ok()?);
        match (self.terrain_geoms[g1], self.terrain_geoms[g2]) {
            (true, false) => Some(g2),
            (false, true) => Some(g1),
            _ => None,
        }
    }

    /// The leg index and the wheel (0 = left, 1 = right) of a wheel geom; `None` for any
    /// other geom.
    fn wheel_of(&self, geom: usize) -> Option<(usize, usize)> {
        self.legs.iter().enumerate().find_map(|(leg, ids)| {
            ids.wheel_geoms.iter().position(|&g| g == geom).map(|wheel| (leg, wheel))
        })
    }

    /// The wheels MuJoCo reports near the terrain now (within the wheels' contact `gap`,
    /// 4 mm: see `models/momaro.xml`), one entry per wheel in leg order, with the wheel's
    /// smallest distance. [`WheelContact::touching`] tells those in contact.
    pub fn wheel_contacts(&self) -> Vec<WheelContact> {
        // Per wheel: smallest distance, and the sum and count of contact points within
        // 1 mm of it (a wheel on a box edge has two contacts; both carry it).
        let mut best = [[(f64::INFINITY, [0.0; 3], 0u32); 2]; 4];
        for c in self.data.contact() {
            let Some((leg, wheel)) = self.robot_geom_on_terrain(c).and_then(|g| self.wheel_of(g))
            else {
                continue;
            };
            let (dist, sum, n) = &mut best[leg][wheel];
            if c.dist < *dist - TOUCHING_M {
                // A clearly nearer contact replaces the ones seen so far.
                (*dist, *sum, *n) = (c.dist, c.pos, 1);
            } else if c.dist <= *dist + TOUCHING_M {
                for (acc, p) in sum.iter_mut().zip(c.pos) {
                    *acc += p;
                }
                *n += 1;
                *dist = dist.min(c.dist);
            }
        }
        let mut out = Vec::with_capacity(8);
        for leg in Leg::ALL {
            for (w, (dist, sum, n)) in best[leg.index()].iter().enumerate() {
                if *n > 0 {
                    let k = f64::from(*n);
                    out.push(WheelContact {
                        leg,
                        wheel: w,
                        position: [sum[0] / k, sum[1] / k, sum[2] / k],
                        distance: *dist,
                    });
                }
            }
        }
        out
    }

    /// The load on each leg's wheel pair, N: the normal forces of the contacts between its
    /// wheels and the terrain (MuJoCo's constraint forces, `mj_contactForce`), summed.
    pub fn wheel_loads(&self) -> [f64; 4] {
        let mut loads = [0.0; 4];
        for (k, c) in self.data.contact().iter().enumerate() {
            let Some((leg, _)) = self.robot_geom_on_terrain(c).and_then(|g| self.wheel_of(g))
            else {
                continue;
            };
            if let Ok(f) = self.data.try_contact_force(k) {
                loads[leg] += f[0].max(0.0);
            }
        }
        loads
    }

    /// Names of robot geoms other than wheels that touch terrain now: body-terrain collisions.
    pub fn body_terrain_collisions(&self) -> Vec<String> {
        let mut names = Vec::new();
        for c in self.data.contact() {
            if c.dist > TOUCHING_M {
                continue;
            }
            let Some(robot_geom) = self.robot_geom_on_terrain(c) else { continue };
            if self.wheel_of(robot_geom).is_some() {
                continue;
            }
            let body = self.model.geom_bodyid()[robot_geom];
            let name = usize::try_from(body)
                .ok()
                .and_then(|b| self.model.id_to_name(MjtObjBase::mjOBJ_BODY, b))
                .unwrap_or("?")
                .to_owned();
            if !names.contains(&name) {
                names.push(name);
            }
        }
        names.sort();
        names
    }

    /// Applies an external force (N) at the base's CoM, in world coordinates, until changed.
    pub fn push_base(&mut self, force: [f64; 3]) {
        let b = self.base_body;
        self.data.xfrc_applied_mut()[b] = [force[0], force[1], force[2], 0.0, 0.0, 0.0];
    }

    /// Whether body `b` is part of the robot (its root, the world's child it hangs from,
    /// is the base's), not a terrain solid's static body (`world`).
    fn is_robot_body(&self, b: usize) -> bool {
        let root = self.model.body_rootid();
        b > 0 && root.get(b) == root.get(self.base_body)
    }

    /// World pose of every robot body, in model order: bodies 1 to N, the robot's file
    /// being included before the terrain (`world`).
    pub fn body_poses(&self) -> Vec<BodyPose> {
        let (xpos, xquat) = (self.data.xpos(), self.data.xquat());
        (1..self.model.ffi().nbody as usize)
            .filter(|&b| self.is_robot_body(b))
            .map(|b| BodyPose {
                name: self.model.id_to_name(MjtObjBase::mjOBJ_BODY, b).unwrap_or("").to_owned(),
                position: xpos[b],
                quaternion: xquat[b],
            })
            .collect()
    }

    /// Shapes of all geoms (terrain and robot), each in its body's frame; a terrain
    /// solid's geom as the world's (body 0: its static body sits at the world's origin
    /// unrotated, see `world`).
    pub fn geom_shapes(&self) -> Vec<GeomShape> {
        let m = &self.model;
        (0..m.ffi().ngeom as usize)
            .filter_map(|g| {
                let kind = match m.geom_type()[g] {
                    MjtGeomBase::mjGEOM_BOX => GeomKind::Box,
                    MjtGeomBase::mjGEOM_SPHERE => GeomKind::Sphere,
                    MjtGeomBase::mjGEOM_CAPSULE => GeomKind::Capsule,
                    MjtGeomBase::mjGEOM_CYLINDER => GeomKind::Cylinder,
                    MjtGeomBase::mjGEOM_PLANE => GeomKind::Plane,
                    MjtGeomBase::mjGEOM_MESH => GeomKind::Mesh,
                    _ => return None,
                };
                Some(GeomShape {
                    name: m.id_to_name(MjtObjBase::mjOBJ_GEOM, g).unwrap_or("").to_owned(),
                    body: usize::try_from(m.geom_bodyid()[g])
                        .ok()
                        .filter(|&b| self.is_robot_body(b))
                        .unwrap_or(0),
                    kind,
                    size: m.geom_size()[g],
                    rgba: m.geom_rgba()[g],
                    local_position: m.geom_pos()[g],
                    local_quaternion: m.geom_quat()[g],
                    triangles: if kind == GeomKind::Mesh {
                        self.mesh_triangles(g)
                    } else {
                        Vec::new()
                    },
                })
            })
            .collect()
    }

    fn mesh_triangles(&self, geom: usize) -> Vec<[[f64; 3]; 3]> {
        let m = &self.model;
        let Ok(mesh) = usize::try_from(m.geom_dataid()[geom]) else { return Vec::new() };
        let (Ok(va), Ok(fa), Ok(fnum)) = (
            usize::try_from(m.mesh_vertadr()[mesh]),
            usize::try_from(m.mesh_faceadr()[mesh]),
            usize::try_from(m.mesh_facenum()[mesh]),
        ) else {
            return Vec::new();
        };
        let verts = m.mesh_vert();
        m.mesh_face()[fa..fa + fnum]
            .iter()
            .filter_map(|f| {
                let v = |k: usize| -> Option<[f64; 3]> {
                    let p = verts.get(va + usize::try_from(f[k]).ok()?)?;
                    Some([f64::from(p[0]), f64::from(p[1]), f64::from(p[2])])
                };
                Some([v(0)?, v(1)?, v(2)?])
            })
            .collect()
    }

    /// World position of a site of the robot (e.g. `laser`, `imu`).
    ///
    /// # Errors
    /// [`SimError::MissingElement`] if there is no such site.
    pub fn site_position(&self, name: &str) -> Result<[f64; 3], SimError> {
        let s = model::id(&self.model, MjtObjBase::mjOBJ_SITE, name)?;
        Ok(self.data.site_xpos()[s])
    }
}

/// Roll, pitch, yaw (ZYX: R = Rz(yaw)·Ry(pitch)·Rx(roll)) of a unit quaternion (w, x, y, z).
pub fn quaternion_to_rpy(q: [f64; 4]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    [roll, pitch, yaw]
}

impl Simulation {
    /// What the URDF export needs from the compiled model.
    ///
    /// # Errors
    /// [`SimError::MissingElement`] if the model lacks an element the export names.
    pub fn urdf_inputs(&self) -> Result<crate::urdf_export::UrdfInputs, SimError> {
        model::urdf_inputs(&self.model)
    }
}

impl Simulation {
    /// The whole robot's CoM (world frame, m) for a commanded configuration, computed by
    /// MuJoCo's own kinematics (`mj_kinematics`, `mj_comPos`, subtree CoM of the base) on a
    /// scratch copy of the data, so planned and simulated CoM agree by construction. The
    /// running simulation is not touched. Base orientation from roll, pitch, yaw (ZYX);
    /// steering and wheel angles at zero (they do not move the CoM of a symmetric pair).
    pub fn com_of_configuration(
        &mut self,
        base_position: [f64; 3],
        base_rpy: [f64; 3],
        leg_joints: &[[f64; 3]; 4],
    ) -> [f64; 3] {
        let scratch = self.scratch.get_or_insert_with(|| MjData::new(self.model.clone()));
        let q = rpy_to_quaternion(base_rpy);
        let bq = self.base_qpos;
        let legs = self.legs;
        let qpos = scratch.qpos_mut();
        qpos.fill(0.0);
        qpos[bq..bq + 7].copy_from_slice(&[
            base_position[0],
            base_position[1],
            base_position[2],
            q[0],
            q[1],
            q[2],
            q[3],
        ]);
        for (ids, joints) in legs.iter().zip(leg_joints) {
            for k in 0..3 {
                qpos[ids.qpos[k]] = joints[k];
            }
        }
        scratch.kinematics();
        scratch.com_pos();
        scratch.subtree_com()[self.base_body]
    }
}

/// Unit quaternion (w, x, y, z) of roll, pitch, yaw (ZYX: R = Rz(yaw)·Ry(pitch)·Rx(roll)).
pub fn rpy_to_quaternion(rpy: [f64; 3]) -> [f64; 4] {
    let (sr, cr) = (rpy[0] / 2.0).sin_cos();
    let (sp, cp) = (rpy[1] / 2.0).sin_cos();
    let (sy, cy) = (rpy[2] / 2.0).sin_cos();
    [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]
}

/// Range beyond which the laser reports nothing, m (MuJoCo's ray cut-off).
const LASER_CUTOFF_M: f64 = 30.0;

/// The simulated laser: MuJoCo's `mj_multiRay` against terrain geoms only (group 0), so
/// the robot never sees itself.
impl RayCaster for Simulation {
    fn cast_rays(
        &mut self,
        origin: [f64; 3],
        directions: &[[f64; 3]],
        hits: &mut Vec<Option<RayHit>>,
    ) {
        hits.clear();
        let mut groups = [0u8; mujoco_rs::mujoco_c::mjNGROUP as usize];
        groups[0] = 1;
        let mut normals = vec![[0.0; 3]; directions.len()];
        match self.data.try_multi_ray(
            &origin,
            directions,
            Some(&groups),
            true,
            None,
            LASER_CUTOFF_M,
            Some(&mut normals),
        ) {
            Ok((ids, dist)) => {
                hits.extend(ids.iter().zip(dist).zip(normals).map(|((id, distance), normal)| {
                    (id.is_some() && distance >= 0.0).then_some(RayHit { distance, normal })
                }))
            }
            Err(_) => hits.extend(std::iter::repeat_n(None, directions.len())),
        }
    }
}

/// The step motion generator's CoM model: MuJoCo's own kinematics on a scratch copy of the
/// data ([`Simulation::com_of_configuration`]), so planned and simulated CoM agree.
impl crate::posture::CenterOfMassModel for Simulation {
    fn com(
        &mut self,
        base_position: [f64; 3],
        base_rpy: [f64; 3],
        legs: &[[f64; 3]; 4],
    ) -> [f64; 3] {
        self.com_of_configuration(base_position, base_rpy, legs)
    }
}
