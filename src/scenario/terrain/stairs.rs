//! The `stairs` primitive: a flight of steps going up along its local +x, with a landing
//! at the top. It is a [`Solid::Box`] per step, reaching from the ground to the step's
//! tread (the last one carries the landing), each a static body of its own in the
//! simulated world.

use super::{
    Block, PrimitiveKind, Solid, all_finite, all_non_negative, rotated_bounds, to_local, to_world,
};
use crate::scenario::field::{FieldError, finite, non_negative, positive};
use serde::{Deserialize, Serialize};

/// A flight of `steps` steps going up along local +x, starting at `start` (centre of the
/// first riser), each `step_depth` deep and `step_height` high, followed by a landing
/// `landing_depth` deep at the top.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stairs {
    /// Centre of the bottom edge of the first step (x, y), m.
    pub start: [f64; 2],
    /// Width along local y, m.
    pub width: f64,
    /// Number of steps (at least 1).
    pub steps: u32,
    /// Tread depth, m.
    pub step_depth: f64,
    /// Riser height, m.
    pub step_height: f64,
    /// Depth of the top landing, m (0 for none).
    #[serde(default)]
    pub landing_depth: f64,
    /// Rotation about z, degrees.
    #[serde(default)]
    pub yaw_deg: f64,
}

impl Stairs {
    /// The depth of step `k`'s box (1-based): the step's, the last one's with the landing.
    fn tread_of(&self, k: u32) -> f64 {
        if k == self.steps { self.step_depth + self.landing_depth } else { self.step_depth }
    }

    /// Length of the flight along its local x, the landing included, m.
    fn run(&self) -> f64 {
        f64::from(self.steps) * self.step_depth + self.landing_depth
    }
}

impl PrimitiveKind for Stairs {
    fn name(&self) -> &'static str {
        "stairs"
    }

    fn validate(&self, at: &str) -> Result<(), FieldError> {
        finite(&format!("{at}.start"), self.start[0])?;
        finite(&format!("{at}.start"), self.start[1])?;
        positive(&format!("{at}.width"), self.width)?;
        if self.steps == 0 {
            return Err((format!("{at}.steps"), "must be at least 1".into()));
        }
        positive(&format!("{at}.step_depth"), self.step_depth)?;
        positive(&format!("{at}.step_height"), self.step_height)?;
        non_negative(&format!("{at}.landing_depth"), self.landing_depth)?;
        finite(&format!("{at}.yaw_deg"), self.yaw_deg)
    }

    fn well_formed(&self) -> bool {
        all_finite(&[self.start[0], self.start[1], self.step_height, self.yaw_deg])
            && all_non_negative(&[self.width, self.step_depth, self.landing_depth])
    }

    fn surface_height(&self, x: f64, y: f64) -> Option<f64> {
        let (lx, ly) = to_local(self.start, self.yaw_deg.to_radians(), x, y);
        let run = self.run();
        if !(lx >= 0.0 && lx < run && ly >= -self.width / 2.0 && ly < self.width / 2.0) {
            return None;
        }
        let step = ((lx / self.step_depth).floor() as u32 + 1).min(self.steps);
        Some(f64::from(step) * self.step_height)
    }

    fn max_height(&self) -> f64 {
        f64::from(self.steps) * self.step_height
    }

    fn footprint_bounds(&self) -> [f64; 4] {
        let run = self.run();
        let hy = self.width / 2.0;
        rotated_bounds(
            self.start,
            self.yaw_deg.to_radians(),
            [(0.0, -hy), (run, -hy), (run, hy), (0.0, hy)],
        )
    }

    fn solids(&self) -> Vec<Solid> {
        let yaw = self.yaw_deg.to_radians();
        (1..=self.steps)
            .map(|k| {
                let depth = self.tread_of(k);
                let lx = f64::from(k - 1) * self.step_depth + depth / 2.0;
                Solid::Box {
                    center: to_world(self.start, yaw, lx, 0.0),
                    half_size: [depth / 2.0, self.width / 2.0],
                    height: f64::from(k) * self.step_height,
                    yaw,
                }
            })
            .collect()
    }

    /// A box per step from the ground to its tread, the last with the landing: the
    /// flight's own solids ([`Self::solids`]), written as `box` primitives (the yaw kept in
    /// degrees as given, so the boxes' solids are the flight's bit for bit).
    fn as_blocks(&self) -> Option<Vec<Block>> {
        let yaw = self.yaw_deg.to_radians();
        let blocks = (1..=self.steps)
            .map(|k| {
                let depth = self.tread_of(k);
                let lx = f64::from(k - 1) * self.step_depth + depth / 2.0;
                Block {
                    center: to_world(self.start, yaw, lx, 0.0),
                    size: [depth, self.width],
                    height: f64::from(k) * self.step_height,
                    yaw_deg: self.yaw_deg,
                }
            })
            .collect();
        Some(blocks)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::terrain::Primitive;

    const FLIGHT: Stairs = Stairs {
        start: [0.0, 0.0],
        width: 1.0,
        steps: 3,
        step_depth: 0.3,
        step_height: 0.15,
        landing_depth: 0.5,
        yaw_deg: 0.0,
    };

    #[test]
    fn steps_up_and_blocks_match_surface() {
        let s = FLIGHT;
        assert_eq!(s.surface_height(0.1, 0.0), Some(0.15));
        assert_eq!(s.surface_height(0.4, 0.0), Some(0.30));
        assert!((s.surface_height(1.2, 0.0).unwrap() - 0.45).abs() < 1e-12);
        assert_eq!(s.surface_height(1.5, 0.0), None);
        assert_eq!(s.surface_height(-0.01, 0.0), None);
        let blocks = s.solids();
        assert_eq!(blocks.len(), 3);
        let Solid::Box { center, half_size, height, .. } = blocks[2] else { panic!("{blocks:?}") };
        assert!((center[0] - (0.6 + 0.4)).abs() < 1e-12);
        assert!((half_size[0] - 0.4).abs() < 1e-12);
        assert!((height - 0.45).abs() < 1e-12);
        assert!((s.max_height() - 0.45).abs() < 1e-12);
    }

    #[test]
    fn a_flight_as_boxes_is_the_same_solids_bit_for_bit() {
        // At odd headings too, where the boxes' centres come out of sin and cos: each box
        // is the flight's solid for its step, and its top the step's height.
        for yaw_deg in [0.0, 17.3, -56.5, 180.0] {
            let s = Stairs { yaw_deg, start: [1.3, -0.7], ..FLIGHT };
            let flight = Primitive::Stairs(s);
            let boxes = flight.as_boxes();
            assert_eq!(boxes.len(), 3);
            let solids: Vec<Solid> = boxes.iter().flat_map(Primitive::solids).collect();
            assert_eq!(solids, flight.solids(), "yaw {yaw_deg}");
            assert!(boxes.iter().all(|b| b.kind() == "box"));
        }
        // Other kinds are themselves.
        let pole = Primitive::Pole(crate::scenario::terrain::Pole {
            center: [0.0, 0.0],
            radius: 0.1,
            height: 0.2,
        });
        assert_eq!(pole.as_boxes(), vec![pole.clone()]);
    }

    #[test]
    fn every_block_top_is_the_surface_over_it() {
        let s = Stairs { yaw_deg: 35.0, start: [1.0, -2.0], ..FLIGHT };
        for b in s.solids() {
            let Solid::Box { center, height, .. } = b else { panic!("{b:?}") };
            assert_eq!(s.surface_height(center[0], center[1]), Some(height));
        }
    }

    #[test]
    fn validation_names_the_field() {
        assert_eq!(FLIGHT.validate("terrain[0]"), Ok(()));
        assert_eq!(
            Stairs { steps: 0, ..FLIGHT }.validate("terrain[0]"),
            Err(("terrain[0].steps".into(), "must be at least 1".into()))
        );
        assert_eq!(
            Stairs { landing_depth: -1.0, ..FLIGHT }.validate("terrain[0]"),
            Err(("terrain[0].landing_depth".into(), "-1 must be a finite number >= 0".into()))
        );
        assert!(!Stairs { width: f64::INFINITY, ..FLIGHT }.well_formed());
    }
}
