//! Terrain primitives of a scenario: boxes, ramps, stairs and poles on a ground plane.
//!
//! One description serves two consumers, so they agree by construction: the world
//! builder (`sim`) turns each primitive into MuJoCo geoms, and the height-map rasteriser
//! (`terrain`) asks each primitive for its surface height. Every primitive stands on the
//! ground plane z = 0 and is a 2.5D solid: its top surface is a function of (x, y) over
//! its footprint, and it is solid from that surface down to the ground.
//!
//! Frame: world x forward, y left, z up; yaw counter-clockwise from +x (see `geometry`).

use serde::{Deserialize, Serialize};

/// One terrain primitive, as written in a scenario's `[[terrain]]` array.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Primitive {
    /// A block with a flat top at `height`.
    Box {
        /// Centre of the footprint (x, y), m.
        center: [f64; 2],
        /// Footprint (length along local x, width along local y), m.
        size: [f64; 2],
        /// Top surface height, m.
        height: f64,
        /// Rotation about z, degrees.
        #[serde(default)]
        yaw_deg: f64,
    },
    /// A wedge rising linearly along its local +x from 0 to `height`.
    Ramp {
        /// Centre of the footprint (x, y), m.
        center: [f64; 2],
        /// Footprint (run along local x, width along local y), m.
        size: [f64; 2],
        /// Height at the high (local +x) end, m.
        height: f64,
        /// Rotation about z, degrees.
        #[serde(default)]
        yaw_deg: f64,
    },
    /// A flight of `steps` steps going up along local +x, starting at `start` (centre of
    /// the first riser), each `step_depth` deep and `step_height` high, followed by a
    /// landing `landing_depth` deep at the top.
    Stairs {
        /// Centre of the bottom edge of the first step (x, y), m.
        start: [f64; 2],
        /// Width along local y, m.
        width: f64,
        /// Number of steps (at least 1).
        steps: u32,
        /// Tread depth, m.
        step_depth: f64,
        /// Riser height, m.
        step_height: f64,
        /// Depth of the top landing, m (0 for none).
        #[serde(default)]
        landing_depth: f64,
        /// Rotation about z, degrees.
        #[serde(default)]
        yaw_deg: f64,
    },
    /// A vertical cylinder.
    Pole {
        /// Axis position (x, y), m.
        center: [f64; 2],
        /// Radius, m.
        radius: f64,
        /// Top height, m.
        height: f64,
    },
}

/// An axis-aligned box in a primitive's local frame, as the world builder places it:
/// the solids that make up a primitive (a flight of stairs is several).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalBlock {
    /// Footprint centre in world coordinates (x, y), m.
    pub center: [f64; 2],
    /// Half extents along local x and y, m.
    pub half_size: [f64; 2],
    /// Top height, m (the block reaches down to z = 0).
    pub height: f64,
    /// Rotation about z, rad.
    pub yaw: f64,
}

impl Primitive {
    /// Short name of the primitive's kind, as written in scenario files.
    pub fn kind(&self) -> &'static str {
        match self {
            Primitive::Box { .. } => "box",
            Primitive::Ramp { .. } => "ramp",
            Primitive::Stairs { .. } => "stairs",
            Primitive::Pole { .. } => "pole",
        }
    }

    /// Height of the primitive's top surface at (x, y), or `None` outside its footprint.
    ///
    /// Footprints are half-open on their far sides so that two touching primitives never
    /// both claim a boundary point with different heights by accident of rounding.
    pub fn surface_height(&self, x: f64, y: f64) -> Option<f64> {
        match *self {
            Primitive::Box { center, size, height, yaw_deg } => {
                let (lx, ly) = to_local(center, yaw_deg.to_radians(), x, y);
                inside_centered(lx, ly, size).then_some(height)
            }
            Primitive::Ramp { center, size, height, yaw_deg } => {
                let (lx, ly) = to_local(center, yaw_deg.to_radians(), x, y);
                inside_centered(lx, ly, size).then(|| height * (lx / size[0] + 0.5))
            }
            Primitive::Stairs {
                start,
                width,
                steps,
                step_depth,
                step_height,
                landing_depth,
                yaw_deg,
            } => {
                let (lx, ly) = to_local(start, yaw_deg.to_radians(), x, y);
                let run = f64::from(steps) * step_depth + landing_depth;
                if !(lx >= 0.0 && lx < run && ly >= -width / 2.0 && ly < width / 2.0) {
                    return None;
                }
                let step = ((lx / step_depth).floor() as u32 + 1).min(steps);
                Some(f64::from(step) * step_height)
            }
            Primitive::Pole { center, radius, height } => {
                let (dx, dy) = (x - center[0], y - center[1]);
                (dx * dx + dy * dy <= radius * radius).then_some(height)
            }
        }
    }

    /// Highest point of the primitive, m.
    pub fn max_height(&self) -> f64 {
        match *self {
            Primitive::Box { height, .. }
            | Primitive::Ramp { height, .. }
            | Primitive::Pole { height, .. } => height,
            Primitive::Stairs { steps, step_height, .. } => f64::from(steps) * step_height,
        }
    }

    /// Axis-aligned bounding box of the footprint: `[x_min, y_min, x_max, y_max]`.
    pub fn footprint_bounds(&self) -> [f64; 4] {
        let corners: Vec<[f64; 2]> = match *self {
            Primitive::Box { center, size, yaw_deg, .. }
            | Primitive::Ramp { center, size, yaw_deg, .. } => {
                let (hx, hy) = (size[0] / 2.0, size[1] / 2.0);
                [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
                    .iter()
                    .map(|&(lx, ly)| to_world(center, yaw_deg.to_radians(), lx, ly))
                    .collect()
            }
            Primitive::Stairs {
                start, width, steps, step_depth, landing_depth, yaw_deg, ..
            } => {
                let run = f64::from(steps) * step_depth + landing_depth;
                let hy = width / 2.0;
                [(0.0, -hy), (run, -hy), (run, hy), (0.0, hy)]
                    .iter()
                    .map(|&(lx, ly)| to_world(start, yaw_deg.to_radians(), lx, ly))
                    .collect()
            }
            Primitive::Pole { center, radius, .. } => vec![
                [center[0] - radius, center[1] - radius],
                [center[0] + radius, center[1] + radius],
            ],
        };
        let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for [cx, cy] in corners {
            b = [b[0].min(cx), b[1].min(cy), b[2].max(cx), b[3].max(cy)];
        }
        b
    }

    /// The rectangular blocks of a box or a flight of stairs (one per step, plus the
    /// landing), for the world builder. Ramps and poles are not blocks and return none.
    pub fn blocks(&self) -> Vec<LocalBlock> {
        match *self {
            Primitive::Box { center, size, height, yaw_deg } => vec![LocalBlock {
                center,
                half_size: [size[0] / 2.0, size[1] / 2.0],
                height,
                yaw: yaw_deg.to_radians(),
            }],
            Primitive::Stairs {
                start,
                width,
                steps,
                step_depth,
                step_height,
                landing_depth,
                yaw_deg,
            } => {
                let yaw = yaw_deg.to_radians();
                (1..=steps)
                    .map(|k| {
                        let depth =
                            if k == steps { step_depth + landing_depth } else { step_depth };
                        let lx = f64::from(k - 1) * step_depth + depth / 2.0;
                        LocalBlock {
                            center: to_world(start, yaw, lx, 0.0),
                            half_size: [depth / 2.0, width / 2.0],
                            height: f64::from(k) * step_height,
                            yaw,
                        }
                    })
                    .collect()
            }
            Primitive::Ramp { .. } | Primitive::Pole { .. } => Vec::new(),
        }
    }
}

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

/// Height of the terrain (ground plane and all primitives) at (x, y): the highest surface.
pub fn terrain_height(primitives: &[Primitive], x: f64, y: f64) -> f64 {
    primitives.iter().filter_map(|p| p.surface_height(x, y)).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_height_inside_and_outside() {
        let b = Primitive::Box { center: [1.0, 0.0], size: [1.0, 2.0], height: 0.2, yaw_deg: 0.0 };
        assert_eq!(b.surface_height(1.2, 0.9), Some(0.2));
        assert_eq!(b.surface_height(1.6, 0.0), None);
        assert_eq!(terrain_height(&[b], 0.0, 0.0), 0.0);
    }

    #[test]
    fn rotated_box_uses_local_frame() {
        let b = Primitive::Box { center: [0.0, 0.0], size: [2.0, 0.2], height: 0.3, yaw_deg: 90.0 };
        assert_eq!(b.surface_height(0.0, 0.9), Some(0.3));
        assert_eq!(b.surface_height(0.9, 0.0), None);
    }

    #[test]
    fn ramp_rises_linearly() {
        let r = Primitive::Ramp { center: [1.0, 0.0], size: [2.0, 1.0], height: 0.2, yaw_deg: 0.0 };
        let h = r.surface_height(1.5, 0.0).unwrap();
        assert!((h - 0.15).abs() < 1e-12);
        let h0 = r.surface_height(0.0, 0.0).unwrap();
        assert!(h0.abs() < 1e-12);
    }

    #[test]
    fn stairs_step_up_and_blocks_match_surface() {
        let s = Primitive::Stairs {
            start: [0.0, 0.0],
            width: 1.0,
            steps: 3,
            step_depth: 0.3,
            step_height: 0.15,
            landing_depth: 0.5,
            yaw_deg: 0.0,
        };
        assert_eq!(s.surface_height(0.1, 0.0), Some(0.15));
        assert_eq!(s.surface_height(0.4, 0.0), Some(0.30));
        assert!((s.surface_height(1.2, 0.0).unwrap() - 0.45).abs() < 1e-12);
        assert_eq!(s.surface_height(1.5, 0.0), None);
        let blocks = s.blocks();
        assert_eq!(blocks.len(), 3);
        let last = blocks[2];
        assert!((last.center[0] - (0.6 + 0.4)).abs() < 1e-12);
        assert!((last.half_size[0] - 0.4).abs() < 1e-12);
        assert!((s.max_height() - 0.45).abs() < 1e-12);
    }

    #[test]
    fn pole_is_a_disc() {
        let p = Primitive::Pole { center: [1.0, 1.0], radius: 0.05, height: 0.5 };
        assert_eq!(p.surface_height(1.03, 1.03), Some(0.5));
        assert_eq!(p.surface_height(1.04, 1.04), None);
    }
}
