//! The `box` primitive: a block with a flat top over a rectangle rotated about its
//! centre. It is one [`Solid::Box`], a static body of its own in the simulated world.

use super::{PrimitiveKind, Rectangle, Solid};
use crate::scenario::field::FieldError;
use serde::{Deserialize, Serialize};

/// A block with a flat top at `height` (`kind = "box"`; `Box` is Rust's own).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Block {
    /// Centre of the footprint (x, y), m.
    pub center: [f64; 2],
    /// Footprint (length along local x, width along local y), m.
    pub size: [f64; 2],
    /// Top surface height, m.
    pub height: f64,
    /// Rotation about z, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
}

impl PrimitiveKind for Block {
    fn name(&self) -> &'static str {
        "box"
    }

    fn validate(&self, at: &str) -> Result<(), FieldError> {
        self.rectangle().validate(at)
    }

    fn well_formed(&self) -> bool {
        self.rectangle().well_formed()
    }

    fn surface_height(&self, x: f64, y: f64) -> Option<f64> {
        let inside = self.rectangle().local_inside(x, y);
        inside.map(|_| self.height)
    }

    fn max_height(&self) -> f64 {
        self.height
    }

    fn footprint_bounds(&self) -> [f64; 4] {
        self.rectangle().bounds()
    }

    fn solids(&self) -> Vec<Solid> {
        vec![Solid::Box {
            center: self.center,
            half_size: self.rectangle().half_size(),
            height: self.height,
            yaw: self.yaw_deg.to_radians(),
        }]
    }
}

impl Block {
    fn rectangle(&self) -> Rectangle {
        Rectangle {
            center: self.center,
            size: self.size,
            height: self.height,
            yaw_deg: self.yaw_deg,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn height_inside_and_outside() {
        let b = Block { center: [1.0, 0.0], size: [1.0, 2.0], height: 0.2, yaw_deg: 0.0 };
        assert_eq!(b.surface_height(1.2, 0.9), Some(0.2));
        // Half-open: the near edges belong to the box, the far ones do not.
        assert_eq!(b.surface_height(0.5, -1.0), Some(0.2));
        assert_eq!(b.surface_height(1.5, 0.0), None);
        assert_eq!(b.surface_height(1.6, 0.0), None);
        assert_eq!(b.footprint_bounds(), [0.5, -1.0, 1.5, 1.0]);
    }

    #[test]
    fn rotated_box_uses_local_frame() {
        let b = Block { center: [0.0, 0.0], size: [2.0, 0.2], height: 0.3, yaw_deg: 90.0 };
        assert_eq!(b.surface_height(0.0, 0.9), Some(0.3));
        assert_eq!(b.surface_height(0.9, 0.0), None);
        let [x0, y0, x1, y1] = b.footprint_bounds();
        assert!((x0 + 0.1).abs() < 1e-12 && (x1 - 0.1).abs() < 1e-12);
        assert!((y0 + 1.0).abs() < 1e-12 && (y1 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn one_block_solid() {
        let b = Block { center: [1.0, 2.0], size: [1.0, 0.5], height: 0.2, yaw_deg: 90.0 };
        assert_eq!(
            b.solids(),
            [Solid::Box {
                center: [1.0, 2.0],
                half_size: [0.5, 0.25],
                height: 0.2,
                yaw: std::f64::consts::FRAC_PI_2
            }]
        );
    }

    #[test]
    fn validation_names_the_field() {
        let b = Block { center: [1.0, 2.0], size: [1.0, 0.5], height: 0.2, yaw_deg: 0.0 };
        assert_eq!(b.validate("terrain[3]"), Ok(()));
        let bad = Block { size: [1.0, -0.5], ..b };
        assert_eq!(
            bad.validate("terrain[3]"),
            Err(("terrain[3].size".into(), "-0.5 must be a finite number > 0".into()))
        );
        assert!(!bad.well_formed());
        let bad = Block { yaw_deg: f64::NAN, ..b };
        assert_eq!(bad.validate("t").map_err(|e| e.0), Err("t.yaw_deg".into()));
        // A flat box passes the rasteriser's check, not the file's.
        let flat = Block { size: [0.0, 1.0], ..b };
        assert!(flat.well_formed() && flat.validate("t").is_err());
    }
}
