//! Fixed-point path costs.
//!
//! Every cost the search sees — edge costs, `g` values, heuristics — is a [`Cost`]: an
//! unsigned 64-bit count of **micro-units** ([`Cost::SCALE`] = 10⁶ per unit of cost).
//! With integers, sums are exact and associative, ties are real ties, and the weighted
//! key `g + ε·h` of ARA* is computed exactly (ε is itself fixed point, see
//! [`crate::search::arastar`]), so a search gives the same result bit for bit on any
//! machine. Arithmetic saturates at [`Cost::INFINITY`] (`u64::MAX`), which also stands
//! for "impassable": the search never follows an edge of infinite cost.
//!
//! Range: `u64::MAX` micro-units is about 1.8·10¹³ units. Internally the search multiplies
//! `g` by 1000 (the ε scale) and still has 1.8·10¹⁰ units of head-room, far beyond any path
//! on a map (a 10 m drive on flat ground costs about 10 units in the hybrid planner).

use std::fmt;
use std::iter::Sum;
use std::ops::{Add, AddAssign};

/// A non-negative path cost in micro-units (fixed point, [`Cost::SCALE`] per unit).
///
/// Addition saturates at [`Cost::INFINITY`]. Ordering is the integer ordering.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Cost(pub u64);

impl Cost {
    /// Micro-units per unit of cost.
    pub const SCALE: u64 = 1_000_000;
    /// Zero cost.
    pub const ZERO: Cost = Cost(0);
    /// One unit of cost (10⁶ micro-units).
    pub const ONE: Cost = Cost(Self::SCALE);
    /// Impassable / unknown. Edges of this cost are never followed.
    pub const INFINITY: Cost = Cost(u64::MAX);

    /// Converts a cost in units to fixed point, rounding to the nearest micro-unit.
    ///
    /// `NaN` and `+∞` map to [`Cost::INFINITY`] (unknown means impassable); negative
    /// values clamp to [`Cost::ZERO`] (the search needs non-negative edges); values too
    /// large for the range saturate to [`Cost::INFINITY`].
    pub fn from_f64(units: f64) -> Cost {
        Self::from_f64_rounded(units, f64::round)
    }

    /// As [`Cost::from_f64`], rounding *up* to the next micro-unit. Use it for edge costs
    /// and [`Cost::from_f64_floor`] for heuristics, so a heuristic consistent in real
    /// numbers stays consistent in fixed point.
    pub fn from_f64_ceil(units: f64) -> Cost {
        Self::from_f64_rounded(units, f64::ceil)
    }

    /// As [`Cost::from_f64`], rounding *down* (see [`Cost::from_f64_ceil`]).
    pub fn from_f64_floor(units: f64) -> Cost {
        // On positive values the truncating cast is floor, without libm's call (x86-64's
        // baseline has no rounding instruction): the heuristic's Dijkstra converts every
        // edge it relaxes.
        Self::from_f64_rounded(units, |micro| micro)
    }

    fn from_f64_rounded(units: f64, round: fn(f64) -> f64) -> Cost {
        if units.is_nan() {
            return Cost::INFINITY;
        }
        if units <= 0.0 {
            return Cost::ZERO;
        }
        // `units > 0` here, so `micro as u64` truncates toward zero, i.e. floors.
        let micro = round(units * Self::SCALE as f64);
        if micro >= u64::MAX as f64 { Cost::INFINITY } else { Cost(micro as u64) }
    }

    /// The cost in units (`+∞` for [`Cost::INFINITY`]).
    pub fn to_f64(self) -> f64 {
        if self.is_infinite() { f64::INFINITY } else { self.0 as f64 / Self::SCALE as f64 }
    }

    /// Whether this is [`Cost::INFINITY`].
    pub const fn is_infinite(self) -> bool {
        self.0 == u64::MAX
    }

    /// Saturating sum.
    pub const fn saturating_add(self, other: Cost) -> Cost {
        Cost(self.0.saturating_add(other.0))
    }

    /// Saturating difference (clamps at zero).
    pub const fn saturating_sub(self, other: Cost) -> Cost {
        Cost(self.0.saturating_sub(other.0))
    }
}

impl Add for Cost {
    type Output = Cost;
    /// Saturating addition.
    fn add(self, rhs: Cost) -> Cost {
        self.saturating_add(rhs)
    }
}

impl AddAssign for Cost {
    fn add_assign(&mut self, rhs: Cost) {
        *self = self.saturating_add(rhs);
    }
}

impl Sum for Cost {
    fn sum<I: Iterator<Item = Cost>>(iter: I) -> Cost {
        iter.fold(Cost::ZERO, Add::add)
    }
}

impl fmt::Debug for Cost {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_infinite() {
            write!(f, "Cost(inf)")
        } else {
            write!(f, "Cost({}.{:06})", self.0 / Self::SCALE, self.0 % Self::SCALE)
        }
    }
}

impl fmt::Display for Cost {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_infinite() {
            write!(f, "inf")
        } else {
            write!(f, "{}.{:06}", self.0 / Self::SCALE, self.0 % Self::SCALE)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_round_and_clamp() {
        assert_eq!(Cost::from_f64(1.0), Cost::ONE);
        assert_eq!(Cost::from_f64(0.025), Cost(25_000));
        assert_eq!(Cost::from_f64(1.4999995), Cost(1_500_000));
        assert_eq!(Cost::from_f64(-3.0), Cost::ZERO);
        assert_eq!(Cost::from_f64(f64::NAN), Cost::INFINITY);
        assert_eq!(Cost::from_f64(f64::INFINITY), Cost::INFINITY);
        assert_eq!(Cost::from_f64(1e300), Cost::INFINITY);
        assert_eq!(Cost(2_500_000).to_f64(), 2.5);
        assert_eq!(Cost::from_f64_ceil(0.0000011), Cost(2));
        assert_eq!(Cost::from_f64_floor(0.0000019), Cost(1));
        assert_eq!(Cost::from_f64_floor(2.9999999), Cost(2_999_999));
        assert_eq!(Cost::from_f64_floor(-0.5), Cost::ZERO);
        assert_eq!(Cost::from_f64_floor(1e300), Cost::INFINITY);
        assert_eq!(Cost::from_f64_floor(f64::INFINITY), Cost::INFINITY);
        assert_eq!(Cost::from_f64_ceil(f64::NAN), Cost::INFINITY);
        assert!(Cost::INFINITY.to_f64().is_infinite());
    }

    #[test]
    fn addition_saturates() {
        assert_eq!(Cost::INFINITY + Cost::ONE, Cost::INFINITY);
        assert_eq!(Cost(u64::MAX - 1) + Cost(5), Cost::INFINITY);
        assert_eq!([Cost(1), Cost(2), Cost(3)].into_iter().sum::<Cost>(), Cost(6));
        assert_eq!(Cost(3).saturating_sub(Cost(5)), Cost::ZERO);
    }

    #[test]
    fn formatting() {
        assert_eq!(Cost(1_250_000).to_string(), "1.250000");
        assert_eq!(format!("{:?}", Cost::INFINITY), "Cost(inf)");
    }
}
