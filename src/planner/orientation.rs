//! The robot orientation cost factor k_Δθ (Sec. VII-A, Fig. 8).
//!
//! Driving edges are multiplied by k_Δθ, a function of the angle Δθ ∈ [0, π] between the
//! robot's heading and its driving direction. The paper fixes: 1 within 2π/60 of
//! forward, rising to k12 (= 2); straight backwards preferred over diagonal backwards.
//! It shows the curve only as a figure. The curve chosen here (piecewise linear,
//! continuous, with b = `free_band_rad` and k_back = (1 + k12)/2 by default):
//!
//! ```text
//!   Δθ ∈ [0, b]            1                          forward
//!   Δθ ∈ [b, π/2]          1 → k12 linearly            forward-diagonal to sideways
//!   Δθ ∈ [π/2, π − b]      k12 → k_back linearly       sideways to straight backwards
//!   Δθ ∈ [π − b, π]        k_back                      straight backwards
//! ```
//!
//! So sideways driving (widest clearance needed) is the worst, diagonal backwards
//! (3π/4: (k12 + k_back)/2 = 1.75) costs more than straight backwards (1.5), and forward
//! is free. The minimum is 1, which the heuristic relies on.

use std::f64::consts::{FRAC_PI_2, PI};

/// The k_Δθ curve's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientationFactor {
    /// Half-width of the band around forward (and around backward) where the factor is
    /// flat, rad. Paper: 2π/60.
    pub free_band_rad: f64,
    /// Maximum factor k12 (sideways). Paper: 2.
    pub k12: f64,
    /// Factor for straight backwards driving, in [1, k12]. Default (1 + k12)/2.
    pub backward: f64,
}

impl OrientationFactor {
    /// The paper's curve for a given k12 and band, with k_back = (1 + k12)/2.
    pub fn new(k12: f64, free_band_rad: f64) -> Self {
        Self { free_band_rad, k12, backward: 0.5 * (1.0 + k12) }
    }

    /// k_Δθ for an angle `dtheta` between heading and driving direction (any value; it
    /// is folded to [0, π]). Never below 1 for valid parameters (k12 ≥ backward ≥ 1).
    pub fn factor(&self, dtheta: f64) -> f64 {
        let d = crate::geometry::wrap_angle(dtheta).abs();
        let b = self.free_band_rad.clamp(0.0, FRAC_PI_2 - 1e-9);
        let k = if d <= b {
            1.0
        } else if d <= FRAC_PI_2 {
            1.0 + (self.k12 - 1.0) * (d - b) / (FRAC_PI_2 - b)
        } else if d < PI - b {
            self.k12 + (self.backward - self.k12) * (d - FRAC_PI_2) / (FRAC_PI_2 - b)
        } else {
            self.backward
        };
        k.max(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_4, TAU};

    fn paper() -> OrientationFactor {
        OrientationFactor::new(2.0, TAU / 60.0)
    }

    #[test]
    fn shape_matches_the_paper() {
        let k = paper();
        assert_eq!(k.factor(0.0), 1.0);
        assert_eq!(k.factor(TAU / 60.0 - 1e-6), 1.0);
        assert!(k.factor(TAU / 60.0 + 0.05) > 1.0);
        assert!((k.factor(FRAC_PI_2) - 2.0).abs() < 1e-12);
        assert!((k.factor(PI) - 1.5).abs() < 1e-12);
        // straight backwards beats diagonal backwards, which beats sideways
        assert!(k.factor(PI) < k.factor(3.0 * FRAC_PI_4));
        assert!(k.factor(3.0 * FRAC_PI_4) < k.factor(FRAC_PI_2));
        // forward diagonal is cheaper than sideways
        assert!(k.factor(FRAC_PI_4) < k.factor(FRAC_PI_2));
    }

    #[test]
    fn symmetric_continuous_and_at_least_one() {
        let k = paper();
        let mut prev = k.factor(-PI);
        for n in 0..=20_000 {
            let a = -PI + TAU * f64::from(n) / 20_000.0;
            let f = k.factor(a);
            assert!((1.0..=2.0).contains(&f));
            assert!((f - k.factor(-a)).abs() < 1e-9, "asymmetric at {a}");
            assert!((f - prev).abs() < 0.01, "jump at {a}");
            prev = f;
        }
    }
}
