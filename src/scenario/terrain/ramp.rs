//! The `ramp` primitive: a wedge over a rectangle rotated about its centre, rising
//! linearly along its local +x. It is one [`Solid::Wedge`], a convex mesh that stays in
//! the simulated world's own body (see `sim::world`).

use super::{PrimitiveKind, Rectangle, Solid};
use crate::scenario::field::FieldError;
use serde::{Deserialize, Serialize};

/// A wedge rising linearly along its local +x from 0 to `height`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ramp {
    /// Centre of the footprint (x, y), m.
    pub center: [f64; 2],
    /// Footprint (run along local x, width along local y), m.
    pub size: [f64; 2],
    /// Height at the high (local +x) end, m.
    pub height: f64,
    /// Rotation about z, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
}

impl PrimitiveKind for Ramp {
    fn name(&self) -> &'static str {
        "ramp"
    }

    fn validate(&self, at: &str) -> Result<(), FieldError> {
        self.rectangle().validate(at)
    }

    fn well_formed(&self) -> bool {
        self.rectangle().well_formed()
    }

    fn surface_height(&self, x: f64, y: f64) -> Option<f64> {
        let inside = self.rectangle().local_inside(x, y);
        inside.map(|(lx, _)| self.height * (lx / self.size[0] + 0.5))
    }

    fn max_height(&self) -> f64 {
        self.height
    }

    fn footprint_bounds(&self) -> [f64; 4] {
        self.rectangle().bounds()
    }

    fn solids(&self) -> Vec<Solid> {
        vec![Solid::Wedge {
            center: self.center,
            half_size: self.rectangle().half_size(),
            height: self.height,
            yaw: self.yaw_deg.to_radians(),
        }]
    }
}

impl Ramp {
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
    fn rises_linearly() {
        let r = Ramp { center: [1.0, 0.0], size: [2.0, 1.0], height: 0.2, yaw_deg: 0.0 };
        let h = r.surface_height(1.5, 0.0).unwrap();
        assert!((h - 0.15).abs() < 1e-12);
        let h0 = r.surface_height(0.0, 0.0).unwrap();
        assert!(h0.abs() < 1e-12);
        assert_eq!(r.surface_height(2.0, 0.0), None, "the high edge is the far side");
        assert_eq!(r.max_height(), 0.2);
    }

    #[test]
    fn rotated_ramp_rises_along_its_own_x() {
        // Turned a quarter: it rises along world +y.
        let r = Ramp { center: [0.0, 0.0], size: [2.0, 1.0], height: 0.4, yaw_deg: 90.0 };
        let h = r.surface_height(0.0, 0.5).unwrap();
        assert!((h - 0.3).abs() < 1e-12, "{h}");
        assert_eq!(r.surface_height(0.6, 0.0), None);
    }

    #[test]
    fn one_wedge_solid_and_validation() {
        let r = Ramp { center: [1.0, 2.0], size: [2.0, 1.0], height: 0.2, yaw_deg: 0.0 };
        assert_eq!(
            r.solids(),
            [Solid::Wedge { center: [1.0, 2.0], half_size: [1.0, 0.5], height: 0.2, yaw: 0.0 }]
        );
        assert_eq!(r.validate("terrain[1]"), Ok(()));
        assert_eq!(
            Ramp { height: 0.0, ..r }.validate("terrain[1]"),
            Err(("terrain[1].height".into(), "0 must be a finite number > 0".into()))
        );
    }
}
