//! The `pole` primitive: a vertical cylinder. It is one [`Solid::Cylinder`], a static
//! body of its own in the simulated world.

use super::{PrimitiveKind, Solid, all_finite, all_non_negative, bounds};
use crate::scenario::field::{FieldError, finite, positive};
use serde::{Deserialize, Serialize};

/// A vertical cylinder.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pole {
    /// Axis position (x, y), m.
    pub center: [f64; 2],
    /// Radius, m.
    pub radius: f64,
    /// Top height, m.
    pub height: f64,
}

impl PrimitiveKind for Pole {
    fn name(&self) -> &'static str {
        "pole"
    }

    fn validate(&self, at: &str) -> Result<(), FieldError> {
        finite(&format!("{at}.center"), self.center[0])?;
        finite(&format!("{at}.center"), self.center[1])?;
        positive(&format!("{at}.radius"), self.radius)?;
        positive(&format!("{at}.height"), self.height)
    }

    fn well_formed(&self) -> bool {
        all_finite(&[self.center[0], self.center[1], self.height])
            && all_non_negative(&[self.radius])
    }

    fn surface_height(&self, x: f64, y: f64) -> Option<f64> {
        let (dx, dy) = (x - self.center[0], y - self.center[1]);
        (dx * dx + dy * dy <= self.radius * self.radius).then_some(self.height)
    }

    fn max_height(&self) -> f64 {
        self.height
    }

    fn footprint_bounds(&self) -> [f64; 4] {
        let ([cx, cy], r) = (self.center, self.radius);
        bounds([[cx - r, cy - r], [cx + r, cy + r]])
    }

    fn solids(&self) -> Vec<Solid> {
        vec![Solid::Cylinder { center: self.center, radius: self.radius, height: self.height }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_a_disc() {
        let p = Pole { center: [1.0, 1.0], radius: 0.05, height: 0.5 };
        assert_eq!(p.surface_height(1.03, 1.03), Some(0.5));
        assert_eq!(p.surface_height(1.04, 1.04), None);
        // The rim belongs to the pole (a radius and a point exact in binary).
        let wide = Pole { center: [0.0, 0.0], radius: 0.5, height: 0.5 };
        assert_eq!(wide.surface_height(0.0, 0.5), Some(0.5));
        assert_eq!(wide.surface_height(0.0, 0.5 + 1e-12), None);
        let b = p.footprint_bounds();
        for (v, want) in b.iter().zip([0.95, 0.95, 1.05, 1.05]) {
            assert!((v - want).abs() < 1e-12, "{b:?}");
        }
        assert_eq!(p.solids(), [Solid::Cylinder { center: [1.0, 1.0], radius: 0.05, height: 0.5 }]);
    }

    #[test]
    fn validation_names_the_field() {
        let p = Pole { center: [1.0, 1.0], radius: 0.05, height: 0.5 };
        assert_eq!(p.validate("terrain[2]"), Ok(()));
        assert_eq!(
            Pole { radius: 0.0, ..p }.validate("terrain[2]"),
            Err(("terrain[2].radius".into(), "0 must be a finite number > 0".into()))
        );
        assert!(!Pole { radius: -0.1, ..p }.well_formed());
    }
}
