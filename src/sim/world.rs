//! Builds the MJCF of a scenario's world: the robot model file, included, plus the ground
//! plane and one geom per terrain solid, boxes, treads and poles each in a static body of
//! their own. The solids are the primitives' own ([`Solid`]: boxes, wedges, cylinders);
//! this module turns those shapes into geoms and knows no primitive kind.
//!
//! The text is generated deterministically from the scenario, so two runs of a scenario
//! simulate the same world bit for bit. Wedges (ramps) are convex triangular-prism meshes;
//! boxes (`box` primitives, stair treads) are boxes; cylinders (poles) are cylinders.
//! Terrain geoms carry contype 1 / conaffinity 2 and group 0 (see `models/momaro.xml` for
//! the robot's side of that contract). A solid's geom and body are named after its
//! primitive's index `i` in the scenario: `terrain_{i}_{k}` for the k-th box (a `box`'s
//! one, a flight's treads) and for the solids of a primitive of several, `terrain_{i}`
//! for a primitive's only wedge or cylinder.
//!
//! **A body per solid.** MuJoCo's broadphase sorts bodies by their bounding boxes; the
//! geoms of one body go through its midphase, a tree of their boxes. With every solid a
//! geom of the world body, whose tree holds the infinite plane, every robot body met
//! every solid's box at every step: that tree walk was 23 % of a step's instructions on
//! the platform (callgrind, `bench sim`). In bodies of their own, the solids far from a
//! robot body are passed over by the sort, and the same geom pairs reach the narrowphase.
//! The bodies have no joint (they are welded to the world, and MuJoCo collides no two
//! such bodies) and sit at the world's origin unrotated, so a solid's geom has its world
//! pose in its body (`sim::Simulation::geom_shapes` reports them as the world's). Wedges
//! (ramps) stay in the world body: in a body of its own a ramp's mesh was missed by MuJoCo's ray
//! casting (`mj_multiRay`, the laser; on `ramp_detour` 76 seen cells disagreed with the
//! map), and a course has few of them.

use crate::scenario::terrain::Solid;
use crate::scenario::{MapExtent, Primitive};
use std::fmt::Write as _;

/// File name under which the robot model is placed in MuJoCo's virtual file system.
pub const ROBOT_FILE: &str = "momaro.xml";

/// Prefix of every terrain geom's name; the floor is `terrain_floor`.
pub const TERRAIN_PREFIX: &str = "terrain_";

const TERRAIN_GEOM: &str =
    r#"contype="1" conaffinity="2" group="0" friction="1.0 0.02 0.001" rgba="0.62 0.6 0.55 1""#;

/// The world MJCF for a map extent and terrain, including `ROBOT_FILE`.
pub fn world_xml(name: &str, map: &MapExtent, terrain: &[Primitive]) -> String {
    let mut assets = String::new();
    let mut geoms = String::new();
    let (cx, cy) = ((map.x_min + map.x_max) / 2.0, (map.y_min + map.y_max) / 2.0);
    let (hx, hy) = ((map.x_max - map.x_min) / 2.0 + 2.0, (map.y_max - map.y_min) / 2.0 + 2.0);
    // The plane is infinite for collision; `size` only bounds its drawing.
    let _ = writeln!(
        geoms,
        r#"    <geom name="{TERRAIN_PREFIX}floor" type="plane" pos="{cx} {cy} 0" size="{hx} {hy} 0.1" {TERRAIN_GEOM}/>"#
    );
    for (i, prim) in terrain.iter().enumerate() {
        let solids = prim.solids();
        for (k, solid) in solids.iter().enumerate() {
            // The names of the module docs.
            let id = if solids.len() == 1 && !matches!(solid, Solid::Box { .. }) {
                format!("{i}")
            } else {
                format!("{i}_{k}")
            };
            match *solid {
                Solid::Box { center, half_size, height, yaw } => {
                    let _ = writeln!(
                        geoms,
                        r#"    <body name="{TERRAIN_PREFIX}{id}"><geom name="{TERRAIN_PREFIX}{id}" type="box" pos="{} {} {}" size="{} {} {}" euler="0 0 {yaw}" {TERRAIN_GEOM}/></body>"#,
                        center[0],
                        center[1],
                        height / 2.0,
                        half_size[0],
                        half_size[1],
                        height / 2.0,
                    );
                }
                Solid::Wedge { center, half_size: [hx, hy], height, yaw } => {
                    // Triangular prism: low edge at local x = -hx on the ground, high edge
                    // at +hx. In the world body (module docs: the laser's rays).
                    let _ = writeln!(
                        assets,
                        r#"    <mesh name="{TERRAIN_PREFIX}ramp_{id}" vertex="{mx} {my} 0  {mx} {hy} 0  {hx} {my} 0  {hx} {hy} 0  {hx} {my} {height}  {hx} {hy} {height}"/>"#,
                        mx = -hx,
                        my = -hy,
                    );
                    let _ = writeln!(
                        geoms,
                        r#"    <geom name="{TERRAIN_PREFIX}{id}" type="mesh" mesh="{TERRAIN_PREFIX}ramp_{id}" pos="{} {} 0" euler="0 0 {yaw}" {TERRAIN_GEOM}/>"#,
                        center[0], center[1],
                    );
                }
                Solid::Cylinder { center, radius, height } => {
                    let _ = writeln!(
                        geoms,
                        r#"    <body name="{TERRAIN_PREFIX}{id}"><geom name="{TERRAIN_PREFIX}{id}" type="cylinder" pos="{} {} {}" size="{radius} {}" {TERRAIN_GEOM}/></body>"#,
                        center[0],
                        center[1],
                        height / 2.0,
                        height / 2.0
                    );
                }
            }
        }
    }
    format!(
        r#"<mujoco model="momaro_{name}">
  <include file="{ROBOT_FILE}"/>
  <visual><global offwidth="1280" offheight="720"/></visual>
  <asset>
{assets}  </asset>
  <worldbody>
    <light pos="0 0 5" dir="0 0 -1" directional="true"/>
{geoms}  </worldbody>
</mujoco>
"#
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::terrain::{Block, Pole, Ramp, Stairs};

    #[test]
    fn one_geom_per_solid_and_deterministic() {
        let map = MapExtent { x_min: 0.0, x_max: 4.0, y_min: -1.0, y_max: 1.0 };
        let terrain = vec![
            Primitive::Box(Block {
                center: [1.0, 0.0],
                size: [0.5, 0.5],
                height: 0.2,
                yaw_deg: 0.0,
            }),
            Primitive::Ramp(Ramp {
                center: [2.0, 0.0],
                size: [1.0, 1.0],
                height: 0.2,
                yaw_deg: 90.0,
            }),
            Primitive::Stairs(Stairs {
                start: [3.0, 0.0],
                width: 1.0,
                steps: 2,
                step_depth: 0.3,
                step_height: 0.15,
                landing_depth: 0.0,
                yaw_deg: 0.0,
            }),
            Primitive::Pole(Pole { center: [0.5, 0.5], radius: 0.05, height: 0.6 }),
        ];
        let xml = world_xml("t", &map, &terrain);
        assert_eq!(xml.matches("<geom ").count(), 1 + 1 + 1 + 2 + 1);
        // Every solid but the plane and the ramp in a body of its own, at the origin,
        // unrotated.
        assert_eq!(xml.matches(&format!("<body name=\"{TERRAIN_PREFIX}")).count(), 1 + 2 + 1);
        assert_eq!(xml.matches("<body ").count(), xml.matches("</body>").count());
        assert!(!xml.contains("<body name=\"terrain_floor"));
        assert!(!xml.contains("<body name=\"terrain_1\""), "the ramp is the world's");
        assert!(xml.lines().filter(|l| l.contains("<body ")).all(|l| {
            !l.split("<geom").next().is_some_and(|b| b.contains("pos=") || b.contains("euler="))
        }));
        assert_eq!(xml.matches("<mesh ").count(), 1);
        assert_eq!(xml, world_xml("t", &map, &terrain));
    }
}
