//! How a four-wheel support shares the robot's weight, and how far that is from how it
//! should: the controllers' measure of a rocking chassis.
//!
//! Four stiff legs on ground known to a cell carry the weight on three of them: the
//! weight on four supports is statically indeterminate, and the one distribution the
//! three equilibrium equations (total load, two moments) leave free is the *warp*, the
//! load the front-left/rear-right diagonal carries beyond the other one. A symmetric
//! robot's CoM lies on both diagonals, so when the warp takes all the weight onto one
//! diagonal, the wheels of the other carry nothing and the CoM stands on the edge of the
//! three-wheel support that remains (generated clutter: a pair 4 mm off a 3 cm bump for
//! 0.1 s, the CoM 0.85 cm inside the diagonal of the other three). Lengthening the legs of
//! the light diagonal moves load onto it; nothing else a leg can do changes the warp.
//!
//! The reference is the warp of the balancing loads whose smallest is largest
//! ([`target_warp`]): the distribution farthest from losing a wheel. MuJoCo's contact
//! forces give the measured warp ([`measured_warp`]); the step executor lengthens the legs
//! of the diagonal that carries less than that (`control::step_executor`: `drive` in drive
//! runs, `contact` on four feet while standing).

use crate::robot::Leg;
use nalgebra::{Matrix3, Vector3};

/// Each leg's sign in the warp, in `Leg` order (front-left, front-right, rear-left,
/// rear-right): [`Leg::diagonal_sign`], +1 on the front-left/rear-right diagonal.
pub const WARP_SIGN: [f64; 4] = [
    Leg::FrontLeft.diagonal_sign(),
    Leg::FrontRight.diagonal_sign(),
    Leg::RearLeft.diagonal_sign(),
    Leg::RearRight.diagonal_sign(),
];

/// The warp of measured wheel loads (N, in `Leg` order): `Σ s_i F_i / Σ F_i` with
/// `s` = [`WARP_SIGN`], in [−1, 1]; `None` when the wheels carry nothing.
pub fn measured_warp(loads: &[f64; 4]) -> Option<f64> {
    let total: f64 = loads.iter().sum();
    (total > 0.0).then(|| loads.iter().zip(WARP_SIGN).map(|(f, s)| s * f).sum::<f64>() / total)
}

/// The warp that loads the least loaded wheel most: of the loads on four supports at
/// `feet` (horizontal, `Leg` order) that balance a weight whose CoM projects to `com`, the
/// one whose smallest load is largest, as a fraction of the weight; `None` for feet on
/// one line (their moments cannot balance).
///
/// Balancing loads `F` (fractions of the weight) solve `A F = (1, c_x, c_y)` with `A`'s
/// rows `1`, `x_i`, `y_i`: the least-norm one `F₀ = Aᵀ (A Aᵀ)⁻¹ (1, c_x, c_y)` (what four
/// equally stiff supports under a rigid body on flat ground carry: their deflections are
/// affine in the positions) plus `t n`, `n` the warp pattern [`WARP_SIGN`] less its part
/// in `A`'s row space. The smallest of the four lines `F₀ᵢ + t nᵢ` is largest where a
/// rising one crosses a falling one, so the candidates are those crossings. For a
/// rectangle of feet with the CoM on an axis through its centre this is `F₀`, warp zero;
/// with the CoM toward a corner it takes load off that corner's diagonal, which the least-
/// norm loads would leave carrying the least (on a stair, a rear shift left a front foot
/// at no load with `F₀`'s warp matched).
pub fn target_warp(feet: &[[f64; 2]; 4], com: [f64; 2]) -> Option<f64> {
    // Centred on the feet's mean, for conditioning (the loads do not change with it).
    let mx = feet.iter().map(|f| f[0]).sum::<f64>() / 4.0;
    let my = feet.iter().map(|f| f[1]).sum::<f64>() / 4.0;
    let rows: [Vector3<f64>; 4] = feet.map(|f| Vector3::new(1.0, f[0] - mx, f[1] - my));
    let aat: Matrix3<f64> = rows.iter().map(|r| r * r.transpose()).sum();
    if aat.determinant().abs() < 1e-12 {
        return None;
    }
    let inv = aat.try_inverse()?;
    let least_norm = |b: Vector3<f64>| {
        let lambda = inv * b;
        rows.map(|r| r.dot(&lambda))
    };
    let f0 = least_norm(Vector3::new(1.0, com[0] - mx, com[1] - my));
    let in_rows = least_norm(rows.iter().zip(WARP_SIGN).map(|(r, s)| r * s).sum());
    let n: [f64; 4] = std::array::from_fn(|i| WARP_SIGN[i] - in_rows[i]);
    let smallest = |t: f64| (0..4).map(|i| f0[i] + t * n[i]).fold(f64::INFINITY, f64::min);
    let mut best = (smallest(0.0), 0.0);
    for i in (0..4).filter(|&i| n[i] > 1e-9) {
        for j in (0..4).filter(|&j| n[j] < -1e-9) {
            let t = (f0[j] - f0[i]) / (n[i] - n[j]);
            let value = smallest(t);
            if value > best.0 {
                best = (value, t);
            }
        }
    }
    Some((0..4).map(|i| WARP_SIGN[i] * (f0[i] + best.1 * n[i])).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn measured_warp_is_the_diagonals_difference_over_the_weight() {
        // The clutter run's rocking: 336 N on front-left + rear-right against 0.
        assert_eq!(measured_warp(&[55.0, 0.0, 0.0, 281.0]), Some(1.0));
        // (200 − 80 − 70 + 220) / 570 = 270 / 570.
        assert!(close(measured_warp(&[200.0, 80.0, 70.0, 220.0]).unwrap(), 270.0 / 570.0));
        assert_eq!(measured_warp(&[140.0; 4]), Some(0.0));
        assert_eq!(measured_warp(&[0.0; 4]), None);
    }

    #[test]
    fn a_rectangle_of_feet_with_the_com_on_an_axis_shares_without_warp() {
        let feet = [[0.4, 0.3], [0.4, -0.3], [-0.4, 0.3], [-0.4, -0.3]];
        for com in [[0.0, 0.0], [0.3, 0.0], [0.0, -0.25]] {
            assert!(close(target_warp(&feet, com).unwrap(), 0.0), "{com:?}");
        }
        // Shifted and turned: still a rectangle, the CoM on its long axis.
        let (s, c) = 0.7f64.sin_cos();
        let moved = feet.map(|[x, y]| [2.0 + c * x - s * y, -1.0 + s * x + c * y]);
        assert!(close(target_warp(&moved, [2.0 + c * 0.1, -1.0 + s * 0.1]).unwrap(), 0.0));
    }

    #[test]
    fn a_com_toward_a_corner_loads_the_opposite_corner_more() {
        // Feet (±0.4, ±0.3), CoM (0.1, 0.075). By hand: A Aᵀ = diag(4, 0.64, 0.36), so
        // F₀ᵢ = 1/4 + xᵢ c_x / 0.64 + yᵢ c_y / 0.36 = 1/4 ± 1/16 ± 1/16: front-left 0.375,
        // front-right 0.25, rear-left 0.25, rear-right 0.125 (warp 0.25). The warp pattern
        // is orthogonal to A's rows, n = (1, −1, −1, 1): the smallest line is largest
        // where 0.125 + t = 0.25 − t, t = 1/16: loads (0.4375, 0.1875, 0.1875, 0.1875),
        // warp 0.4375 − 0.1875 − 0.1875 + 0.1875 = 0.25.
        let feet = [[0.4, 0.3], [0.4, -0.3], [-0.4, 0.3], [-0.4, -0.3]];
        let w = target_warp(&feet, [0.1, 0.075]).unwrap();
        assert!(close(w, 0.25), "{w}");
    }

    #[test]
    fn a_front_left_foot_set_forward_takes_less_of_the_weight() {
        // Feet (0.6, 0.3), (0.4, −0.3), (−0.4, 0.3), (−0.4, −0.3), CoM at the origin. By
        // hand, centred on the mean (0.05, 0): rows (1, 0.55, 0.3), (1, 0.35, −0.3),
        // (1, −0.45, 0.3), (1, −0.45, −0.3); A Aᵀ = [[4, 0, 0], [0, 0.83, 0.06],
        // [0, 0.06, 0.36]]. F₀ = rows · (A Aᵀ)⁻¹ (1, −0.05, 0): λ = (0.25, λx, λy) with
        // 0.83 λx + 0.06 λy = −0.05, 0.06 λx + 0.36 λy = 0, so λy = −λx / 6 and
        // λx = −0.05 / 0.82; F₀ = (0.25 + 0.55 λx + 0.3 λy, 0.25 + 0.35 λx − 0.3 λy,
        // 0.25 − 0.45 λx + 0.3 λy, 0.25 − 0.45 λx − 0.3 λy) = (0.2195, 0.2378, 0.2805,
        // 0.2622) to four places, warp 0.2 λx = −0.0122: the least loaded is the
        // front-left foot, set forward. Every other balancing set of loads is F₀ plus a
        // multiple of A's null vector; the largest smallest load along that line is found
        // below by brute force and must give the same warp, more than F₀'s.
        let feet = [[0.6, 0.3], [0.4, -0.3], [-0.4, 0.3], [-0.4, -0.3]];
        let w = target_warp(&feet, [0.0, 0.0]).unwrap();
        let lambda_x = -0.05 / 0.82;
        let lambda_y = -lambda_x / 6.0;
        let centred = [[0.55, 0.3], [0.35, -0.3], [-0.45, 0.3], [-0.45, -0.3]];
        let f0 = centred.map(|[x, y]| 0.25 + x * lambda_x + y * lambda_y);
        let w0: f64 = f0.iter().zip(WARP_SIGN).map(|(f, s)| s * f).sum();
        assert!(close(w0, 0.2 * lambda_x), "{w0}");
        let null = {
            // A n = 0 with n_FL = 1.
            let m = nalgebra::Matrix3::new(1.0, 1.0, 1.0, 0.35, -0.45, -0.45, -0.3, 0.3, -0.3);
            let rest = m.try_inverse().unwrap() * nalgebra::Vector3::new(-1.0, -0.55, -0.3);
            [1.0, rest[0], rest[1], rest[2]]
        };
        let best = (0..=200_000)
            .map(|k| -0.5 + k as f64 * 5e-6)
            .map(|t| {
                let loads: Vec<f64> = (0..4).map(|i| f0[i] + t * null[i]).collect();
                (loads.iter().copied().fold(f64::INFINITY, f64::min), loads)
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap();
        let brute: f64 = best.1.iter().zip(WARP_SIGN).map(|(f, s)| s * f).sum();
        assert!((w - brute).abs() < 1e-4, "{w} vs {brute}");
        assert!(w > w0, "the front-left diagonal gets more than the least-norm loads give");
    }

    #[test]
    fn feet_on_one_line_have_no_target_warp() {
        let feet = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]];
        assert_eq!(target_warp(&feet, [1.5, 0.0]), None);
    }
}
