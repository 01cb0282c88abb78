//! Pose cost C (paper eq. 4): foot costs at the four feet and the body cost, combined.
//!
//! `C = k4 · max_j C_F(f_j) + k5 · Σ_j C_F(f_j) + k6 · C_B`. With the paper's weights
//! (0.1, 0.1, 0.5) it is exactly 1 on flat ground, half from the feet and half from the
//! body. The max term makes one very difficult foothold worse than four slightly
//! difficult ones (Sec. IV).
//!
//! Infinite and unknown parts: any infinite foot cost makes the pose infinite (a known
//! obstacle); otherwise any unknown part makes it unknown. The planner treats both as
//! untraversable; they are kept apart so that maps and images can tell them apart.

use super::Cost;

/// The weights of eq. 4.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseWeights {
    /// Weight on the largest foot cost.
    pub k4: f64,
    /// Weight on the sum of the foot costs.
    pub k5: f64,
    /// Weight on the body cost.
    pub k6: f64,
}

/// A pose cost with its parts, for the step motion generator and for debugging.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseCost {
    /// C (eq. 4).
    pub total: Cost,
    /// C_F at each foot, FL, FR, RL, RR (eq. 1).
    pub feet: [Cost; 4],
    /// C_B (eq. 3).
    pub body: Cost,
}

/// Eq. 4 from the four foot costs and the body cost.
#[inline]
pub fn combine(feet: &[Cost; 4], body: Cost, w: &PoseWeights) -> Cost {
    let mut max = f64::NEG_INFINITY;
    let mut sum = 0.0;
    let mut unknown = false;
    for c in feet {
        match *c {
            Cost::Finite(v) => {
                max = max.max(v);
                sum += v;
            }
            Cost::Infinite => return Cost::Infinite,
            Cost::Unknown => unknown = true,
        }
    }
    match body {
        Cost::Infinite => Cost::Infinite,
        Cost::Unknown => Cost::Unknown,
        _ if unknown => Cost::Unknown,
        Cost::Finite(b) => Cost::Finite(w.k4 * max + w.k5 * sum + w.k6 * b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

    fn weights() -> PoseWeights {
        let p = Params::default();
        PoseWeights { k4: p.k4, k5: p.k5, k6: p.k6 }
    }

    #[test]
    fn flat_is_exactly_one() {
        assert_eq!(
            combine(&[Cost::Finite(1.0); 4], Cost::Finite(1.0), &weights()),
            Cost::Finite(1.0)
        );
    }

    #[test]
    fn hand_computed_mix() {
        // 0.1 · 5 + 0.1 · (1 + 2 + 3 + 5) + 0.5 · 2 = 0.5 + 1.1 + 1.0 = 2.6.
        let feet = [Cost::Finite(1.0), Cost::Finite(2.0), Cost::Finite(3.0), Cost::Finite(5.0)];
        let Cost::Finite(c) = combine(&feet, Cost::Finite(2.0), &weights()) else { panic!() };
        assert!((c - 2.6).abs() < 1e-12);
    }

    #[test]
    fn one_bad_foot_costs_more_than_four_mediocre_ones() {
        let w = weights();
        let one_bad = [Cost::Finite(1.0), Cost::Finite(1.0), Cost::Finite(1.0), Cost::Finite(5.0)];
        let four = [Cost::Finite(2.0); 4];
        let (a, b) =
            (combine(&one_bad, Cost::Finite(1.0), &w), combine(&four, Cost::Finite(1.0), &w));
        // 0.1·5 + 0.1·8 + 0.5 = 1.8 against 0.1·2 + 0.1·8 + 0.5 = 1.5.
        assert!(a.finite().unwrap() > b.finite().unwrap(), "{a:?} {b:?}");
    }

    #[test]
    fn infinite_beats_unknown_beats_finite() {
        let w = weights();
        let mut feet = [Cost::Finite(1.0); 4];
        feet[1] = Cost::Unknown;
        assert_eq!(combine(&feet, Cost::Finite(1.0), &w), Cost::Unknown);
        feet[3] = Cost::Infinite;
        assert_eq!(combine(&feet, Cost::Finite(1.0), &w), Cost::Infinite);
        assert_eq!(combine(&[Cost::Finite(1.0); 4], Cost::Unknown, &w), Cost::Unknown);
    }
}
