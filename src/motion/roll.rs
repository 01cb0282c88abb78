//! Base roll for lateral CoM alignment (Klamt & Behnke 2017, Sec. VI-B, eqs. 6–8).
//!
//! Seen from behind (the robot's y'–z' plane, Fig. 12), the base rolls about a centre of
//! rotation R(y'_rot, z'_rot) between the left and right wheels on the ground. With the CoM
//! at C(y'_CoM, z'_CoM):
//!
//! - eq. 6: α = atan((y'_rot − y'_CoM) / (z'_CoM − z'_rot)), the angle between RC and the
//!   vertical;
//! - eq. 7: α_des = asin((y'_rot − y'_CoM,des) / ‖RC‖), the same for the desired lateral CoM
//!   (‖RC_des‖ = ‖RC‖: a roll moves C on a circle about R);
//! - eq. 8: Δh_leg = b · tan(α − α_des), with b the footprint width.
//!
//! **Sign.** y' points left. α > 0 when the CoM lies right of R. Δh_leg is the length by
//! which the *right* legs grow relative to the left ones (negative: the left legs grow):
//! with the CoM centred and a desired position to the right (y'_CoM,des < y'_rot),
//! α_des > 0 and Δh_leg < 0, so the left side rises and the base rolls right, which moves
//! the CoM right. The corresponding base roll angle (MuJoCo sign, positive = left side up)
//! is φ = −atan(Δh_leg / b) = α_des − α.

use serde::Serialize;

/// The quantities of eqs. 6–8 for one roll.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RollSolution {
    /// α (eq. 6), rad.
    pub alpha: f64,
    /// α_des (eq. 7), rad.
    pub alpha_des: f64,
    /// ‖RC‖, m.
    pub rc_length: f64,
    /// Δh_leg (eq. 8), m: growth of the right legs relative to the left ones.
    pub delta_h_leg: f64,
    /// Base roll φ = −atan(Δh_leg / b), rad (positive: left side up).
    pub roll: f64,
}

/// Why a roll cannot be computed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum RollError {
    /// Non-finite input, a CoM not above R, or a non-positive footprint width.
    #[error("roll (eqs. 6–8): degenerate input (CoM not above the centre of rotation, or b ≤ 0)")]
    Degenerate,
    /// |y'_rot − y'_CoM,des| exceeds ‖RC‖: no roll puts the CoM there.
    #[error("roll (eqs. 6–8): desired lateral CoM {offset:.3} m from R is beyond ‖RC‖ = {rc:.3} m")]
    Unreachable {
        /// |y'_rot − y'_CoM,des|, m.
        offset: f64,
        /// ‖RC‖, m.
        rc: f64,
    },
}

/// Eqs. 6–8: the leg height difference that moves the CoM laterally from `com` = (y', z')
/// to `y_com_des`, rolling about `rot` = (y'_rot, z'_rot), for footprint width `b`.
///
/// # Errors
/// [`RollError`] for degenerate input or an unreachable target.
pub fn roll_for_lateral_com(
    rot: [f64; 2],
    com: [f64; 2],
    y_com_des: f64,
    b: f64,
) -> Result<RollSolution, RollError> {
    let finite = rot.iter().chain(com.iter()).all(|v| v.is_finite()) && y_com_des.is_finite();
    let height = com[1] - rot[1];
    if !finite || b.is_nan() || b <= 0.0 || height.is_nan() || height <= 0.0 {
        return Err(RollError::Degenerate);
    }
    // eq. 6
    let alpha = ((rot[0] - com[0]) / height).atan();
    let rc = (rot[0] - com[0]).hypot(height);
    let offset = rot[0] - y_com_des;
    if offset.abs() > rc {
        return Err(RollError::Unreachable { offset: offset.abs(), rc });
    }
    // eq. 7
    let alpha_des = (offset / rc).asin();
    // eq. 8
    let delta_h_leg = b * (alpha - alpha_des).tan();
    Ok(RollSolution {
        alpha,
        alpha_des,
        rc_length: rc,
        delta_h_leg,
        roll: -(delta_h_leg / b).atan(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centred_com_shifted_right_hand_computed() {
        // R at the origin, C 0.6 m above it, desired 0.1 m to the right, b = 0.64 m:
        // α = 0, α_des = asin(0.1 / 0.6) = 0.167448 rad, Δh = 0.64 · tan(−0.167448)
        // = −0.108180 m: the left legs grow by 10.8 cm; roll φ = +0.167448 rad.
        let s = roll_for_lateral_com([0.0, 0.0], [0.0, 0.6], -0.1, 0.64).unwrap();
        assert!(s.alpha.abs() < 1e-12);
        assert!((s.alpha_des - 0.167_448_079_6).abs() < 1e-9, "{s:?}");
        assert!((s.delta_h_leg + 0.108_179_7).abs() < 1e-6, "{s:?}");
        assert!((s.roll - 0.167_448_079_6).abs() < 1e-9, "{s:?}");
    }

    #[test]
    fn offset_com_hand_computed() {
        // R (0.02, 0.1), C (0.05, 0.5): α = atan(−0.03 / 0.4) = −0.074859 rad,
        // ‖RC‖ = 0.401123; desired y = −0.05: α_des = asin(0.07 / 0.401123) = 0.175408 rad;
        // Δh = 0.6 · tan(−0.250268) = −0.153376 m.
        let s = roll_for_lateral_com([0.02, 0.1], [0.05, 0.5], -0.05, 0.6).unwrap();
        assert!((s.alpha + 0.074_859_8).abs() < 1e-6, "{s:?}");
        assert!((s.rc_length - 0.401_123_4).abs() < 1e-6, "{s:?}");
        assert!((s.alpha_des - 0.175_408_0).abs() < 1e-6, "{s:?}");
        assert!((s.delta_h_leg + 0.153_376).abs() < 1e-5, "{s:?}");
    }

    #[test]
    fn already_aligned_needs_no_roll_and_degenerate_is_an_error() {
        let s = roll_for_lateral_com([0.0, 0.0], [0.03, 0.5], 0.03, 0.64).unwrap();
        assert!(s.delta_h_leg.abs() < 1e-12 && s.roll.abs() < 1e-12);
        assert_eq!(
            roll_for_lateral_com([0.0, 0.5], [0.0, 0.4], 0.0, 0.64),
            Err(RollError::Degenerate)
        );
        assert!(matches!(
            roll_for_lateral_com([0.0, 0.0], [0.0, 0.3], -0.5, 0.64),
            Err(RollError::Unreachable { .. })
        ));
    }
}
