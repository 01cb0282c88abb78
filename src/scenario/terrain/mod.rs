//! Terrain primitives of a scenario: boxes, ramps, stairs and poles on a ground plane.
//!
//! **A kind is a unit.** Each kind of primitive is one file of this module holding all
//! there is to know of it: its struct as written in a scenario's `[[terrain]]` table
//! (serde), the validation of its values, its surface height and footprint, and the
//! [`Solid`]s it is made of. The kinds answer through one trait, `PrimitiveKind`, and
//! [`Primitive`] registers them: a variant per kind (serde's `kind` tag) and one dispatch,
//! `Primitive::unit`. Adding a kind is one new file implementing the trait, plus its
//! registration here: its variant, its arm of `unit` (and the file's `mod` line).
//!
//! One description serves every consumer, so they agree by construction: the scenario's
//! validation and the start and goal checks (`scenario`), the height-map rasteriser
//! (`terrain`, from the footprints and the solids) and the world builder (`sim::world`,
//! which turns the solids into MuJoCo geoms). None of them knows the kinds: they know the
//! three neutral shapes of [`Solid`] (box, wedge, cylinder). Every primitive stands on the
//! ground plane z = 0 and is a 2.5D solid: its top surface is a function of (x, y) over its
//! footprint, and it is solid from that surface down to the ground.
//!
//! Frame: world x forward, y left, z up; yaw counter-clockwise from +x (see `geometry`).

mod block;
mod pole;
mod ramp;
mod stairs;

pub use block::Block;
pub use pole::Pole;
pub use ramp::Ramp;
pub use stairs::Stairs;

use super::field::{FieldError, finite, positive};
use serde::{Deserialize, Serialize};

/// One terrain primitive, as written in a scenario's `[[terrain]]` array: the
/// registration of the kinds. The tag `kind` names the variant (`box`, `ramp`, ...); the
/// variant's struct reads the rest of the table, refusing unknown keys.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Primitive {
    /// A block with a flat top.
    Box(Block),
    /// A wedge rising linearly along its local +x.
    Ramp(Ramp),
    /// A flight of steps with a landing at the top.
    Stairs(Stairs),
    /// A vertical cylinder.
    Pole(Pole),
}

/// What every kind of primitive answers: the one interface between a kind's file and the
/// rest of the crate.
pub(crate) trait PrimitiveKind {
    /// The kind's name, as written in scenario files (serde's tag of its variant).
    fn name(&self) -> &'static str;

    /// Checks the values a scenario file gave, naming the field below `at` (the
    /// primitive's own path, `terrain[2]`) that is out of range.
    fn validate(&self, at: &str) -> Result<(), FieldError>;

    /// Whether the geometry can be built at all: finite numbers, no negative dimension.
    /// Laxer than [`PrimitiveKind::validate`]; the rasteriser checks primitives made in
    /// code with it.
    fn well_formed(&self) -> bool;

    /// Height of the top surface at (x, y), or `None` outside the footprint.
    fn surface_height(&self, x: f64, y: f64) -> Option<f64>;

    /// Highest point, m.
    fn max_height(&self) -> f64;

    /// Axis-aligned bounding box of the footprint: `[x_min, y_min, x_max, y_max]`.
    fn footprint_bounds(&self) -> [f64; 4];

    /// The solids the primitive is made of, in world coordinates.
    fn solids(&self) -> Vec<Solid>;

    /// The same terrain written as boxes, where the kind is made of boxes alone and is
    /// not one: the same solids, so the same heights cell for cell and the same world
    /// (`momaro generate --stairs-as boxes`). `None` for the other kinds.
    fn as_blocks(&self) -> Option<Vec<Block>> {
        None
    }
}

/// A solid standing on the ground plane (it reaches down to z = 0), in world
/// coordinates: the neutral shapes primitives are made of, which the rasteriser
/// (`terrain::rasterise`) and the world builder (`sim::world`) know instead of the kinds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    /// A box with a flat top over a rectangle rotated about its centre.
    Box {
        /// Footprint centre (x, y), m.
        center: [f64; 2],
        /// Half extents along the local x and y, m.
        half_size: [f64; 2],
        /// Top height, m.
        height: f64,
        /// Rotation about z, rad.
        yaw: f64,
    },
    /// A wedge (a triangular prism lying on a side) over a rectangle rotated about its
    /// centre: its top rises linearly along the local +x from 0 at the low edge (local
    /// x = −`half_size[0]`) to `height` at the high edge, where a vertical face drops.
    Wedge {
        /// Footprint centre (x, y), m.
        center: [f64; 2],
        /// Half extents along the local x (the rise) and y, m.
        half_size: [f64; 2],
        /// Height of the high edge, m.
        height: f64,
        /// Rotation about z, rad.
        yaw: f64,
    },
    /// A vertical cylinder.
    Cylinder {
        /// Axis position (x, y), m.
        center: [f64; 2],
        /// Radius, m.
        radius: f64,
        /// Top height, m.
        height: f64,
    },
}

impl Primitive {
    /// The one dispatch from a primitive to its kind's unit.
    pub(crate) fn unit(&self) -> &dyn PrimitiveKind {
        match self {
            Primitive::Box(p) => p,
            Primitive::Ramp(p) => p,
            Primitive::Stairs(p) => p,
            Primitive::Pole(p) => p,
        }
    }

    /// Short name of the primitive's kind, as written in scenario files.
    pub fn kind(&self) -> &'static str {
        self.unit().name()
    }

    /// Checks the values a scenario file gave; `at` is the primitive's path
    /// (`terrain[2]`), the error names the field below it.
    pub(crate) fn validate(&self, at: &str) -> Result<(), FieldError> {
        self.unit().validate(at)
    }

    /// Whether the geometry can be built at all (finite numbers, no negative dimension).
    pub fn well_formed(&self) -> bool {
        self.unit().well_formed()
    }

    /// Height of the primitive's top surface at (x, y), or `None` outside its footprint.
    ///
    /// Footprints are half-open on their far sides so that two touching primitives never
    /// both claim a boundary point with different heights by accident of rounding.
    pub fn surface_height(&self, x: f64, y: f64) -> Option<f64> {
        self.unit().surface_height(x, y)
    }

    /// Highest point of the primitive, m.
    pub fn max_height(&self) -> f64 {
        self.unit().max_height()
    }

    /// Axis-aligned bounding box of the footprint: `[x_min, y_min, x_max, y_max]`.
    pub fn footprint_bounds(&self) -> [f64; 4] {
        self.unit().footprint_bounds()
    }

    /// The solids the primitive is made of: a box's box, a ramp's wedge, a box per
    /// step of a flight (the last one with the landing), a pole's cylinder.
    pub fn solids(&self) -> Vec<Solid> {
        self.unit().solids()
    }

    /// The primitive written as boxes where it is made of boxes but is not one (a flight
    /// of stairs: a box per step), with the same solids; itself otherwise.
    pub fn as_boxes(&self) -> Vec<Primitive> {
        match self.unit().as_blocks() {
            Some(blocks) => blocks.into_iter().map(Primitive::Box).collect(),
            None => vec![self.clone()],
        }
    }
}

/// Whether a local point lies in a footprint of `size` centred on the local origin
/// (half-open on the far sides).
fn inside_centered(lx: f64, ly: f64, size: [f64; 2]) -> bool {
    lx >= -size[0] / 2.0 && lx < size[0] / 2.0 && ly >= -size[1] / 2.0 && ly < size[1] / 2.0
}

/// World point into a frame at `origin` rotated by `yaw`.
fn to_local(origin: [f64; 2], yaw: f64, x: f64, y: f64) -> (f64, f64) {
    let (s, c) = yaw.sin_cos();
    let (dx, dy) = (x - origin[0], y - origin[1]);
    (c * dx + s * dy, -s * dx + c * dy)
}

/// Local point of a frame at `origin` rotated by `yaw` into world coordinates.
fn to_world(origin: [f64; 2], yaw: f64, lx: f64, ly: f64) -> [f64; 2] {
    let (s, c) = yaw.sin_cos();
    [origin[0] + c * lx - s * ly, origin[1] + s * lx + c * ly]
}

/// A rectangle footprint rotated about its centre, with a height: what the `box` and
/// `ramp` primitives share (their fields' checks, their local frame, their bounds).
struct Rectangle {
    center: [f64; 2],
    size: [f64; 2],
    height: f64,
    yaw_deg: f64,
}

impl Rectangle {
    /// The fields' checks, each error naming `at`'s field.
    fn validate(&self, at: &str) -> Result<(), FieldError> {
        finite(&format!("{at}.center"), self.center[0])?;
        finite(&format!("{at}.center"), self.center[1])?;
        positive(&format!("{at}.size"), self.size[0])?;
        positive(&format!("{at}.size"), self.size[1])?;
        positive(&format!("{at}.height"), self.height)?;
        finite(&format!("{at}.yaw_deg"), self.yaw_deg)
    }

    fn well_formed(&self) -> bool {
        all_finite(&[self.center[0], self.center[1], self.height, self.yaw_deg])
            && all_non_negative(&self.size)
    }

    /// The local coordinates (x along the rectangle's length from its centre) of a world
    /// point inside it.
    fn local_inside(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let (lx, ly) = to_local(self.center, self.yaw_deg.to_radians(), x, y);
        inside_centered(lx, ly, self.size).then_some((lx, ly))
    }

    fn half_size(&self) -> [f64; 2] {
        [self.size[0] / 2.0, self.size[1] / 2.0]
    }

    fn bounds(&self) -> [f64; 4] {
        let [hx, hy] = self.half_size();
        rotated_bounds(
            self.center,
            self.yaw_deg.to_radians(),
            [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)],
        )
    }
}

/// The bounding box `[x_min, y_min, x_max, y_max]` of the local points `corners` of a
/// frame at `origin` rotated by `yaw`.
fn rotated_bounds(origin: [f64; 2], yaw: f64, corners: [(f64, f64); 4]) -> [f64; 4] {
    bounds(corners.map(|(lx, ly)| to_world(origin, yaw, lx, ly)))
}

/// The bounding box `[x_min, y_min, x_max, y_max]` of world points.
fn bounds<const N: usize>(points: [[f64; 2]; N]) -> [f64; 4] {
    let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    for [cx, cy] in points {
        b = [b[0].min(cx), b[1].min(cy), b[2].max(cx), b[3].max(cy)];
    }
    b
}

/// Whether every value is finite.
fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Whether every value is finite and not negative.
fn all_non_negative(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite() && *x >= 0.0)
}

/// Height of the terrain (ground plane and all primitives) at (x, y): the highest surface.
pub fn terrain_height(primitives: &[Primitive], x: f64, y: f64) -> f64 {
    primitives.iter().filter_map(|p| p.surface_height(x, y)).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One primitive of every kind.
    fn one_of_each() -> [Primitive; 4] {
        [
            Primitive::Box(Block {
                center: [1.0, 0.5],
                size: [1.0, 2.0],
                height: 0.2,
                yaw_deg: 30.0,
            }),
            Primitive::Ramp(Ramp {
                center: [3.0, 0.0],
                size: [2.0, 1.0],
                height: 0.3,
                yaw_deg: -45.0,
            }),
            Primitive::Stairs(Stairs {
                start: [0.0, -2.0],
                width: 1.0,
                steps: 3,
                step_depth: 0.3,
                step_height: 0.15,
                landing_depth: 0.5,
                yaw_deg: 90.0,
            }),
            Primitive::Pole(Pole { center: [1.0, 1.0], radius: 0.05, height: 0.5 }),
        ]
    }

    #[test]
    fn every_kind_round_trips_through_toml_under_its_own_name() {
        #[derive(Debug, PartialEq, Serialize, Deserialize)]
        struct File {
            terrain: Vec<Primitive>,
        }
        let file = File { terrain: one_of_each().to_vec() };
        let text = toml::to_string(&file).unwrap();
        let back: File = toml::from_str(&text).unwrap();
        assert_eq!(back, file);
        // The tag serde writes is the kind's own name.
        let kinds: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("kind = "))
            .map(|k| k.trim_matches('"'))
            .collect();
        let names: Vec<&str> = file.terrain.iter().map(Primitive::kind).collect();
        assert_eq!(kinds, names);
        assert_eq!(names, ["box", "ramp", "stairs", "pole"]);
    }

    #[test]
    fn defaults_and_unknown_keys() {
        let p: Primitive =
            toml::from_str("kind = \"box\"\ncenter = [1.0, 2.0]\nsize = [1.0, 1.0]\nheight = 0.2")
                .unwrap();
        assert_eq!(
            p,
            Primitive::Box(Block {
                center: [1.0, 2.0],
                size: [1.0, 1.0],
                height: 0.2,
                yaw_deg: 0.0
            })
        );
        let e = toml::from_str::<Primitive>(
            "kind = \"pole\"\ncenter = [1.0, 2.0]\nradius = 0.1\nheight = 0.2\nyaw_deg = 3.0",
        )
        .unwrap_err();
        assert!(e.to_string().contains("unknown field `yaw_deg`"), "{e}");
    }

    #[test]
    fn terrain_height_is_the_highest_surface() {
        let ps = one_of_each();
        assert_eq!(terrain_height(&ps, -5.0, -5.0), 0.0);
        // The pole (0.5 m) stands inside the box (0.2 m).
        assert_eq!(terrain_height(&ps, 1.0, 1.0), 0.5);
        assert_eq!(terrain_height(&ps, 1.0, 0.5), 0.2);
    }

    #[test]
    fn solids_lie_within_the_footprint_and_reach_the_top() {
        for p in one_of_each() {
            let b = p.footprint_bounds();
            let mut top = 0.0f64;
            for s in p.solids() {
                let (c, h) = match s {
                    Solid::Box { center, height, .. }
                    | Solid::Wedge { center, height, .. }
                    | Solid::Cylinder { center, height, .. } => (center, height),
                };
                assert!(c[0] >= b[0] && c[0] <= b[2] && c[1] >= b[1] && c[1] <= b[3], "{p:?}");
                top = top.max(h);
            }
            assert!((top - p.max_height()).abs() < 1e-12, "{p:?}");
            assert!(p.well_formed());
            assert_eq!(p.validate("terrain[0]"), Ok(()));
        }
    }
}
