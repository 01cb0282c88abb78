//! A clamped uniform cubic B-spline over planar poses (x, y, θ): the curve the driving
//! controller aims along (Sec. IX: "We obtain w = (v_x', v_y', ω) by computing a B-spline
//! through the next five driving poses and aim towards a pose p = (p_x, p_y, p_θ) on this
//! B-spline in front of the robot").
//!
//! [`PoseSpline`] treats each pose as a 3-D control point (x, y, θ). The headings are
//! unwrapped first (each differs from its predecessor by at most π), so the spline never
//! turns the long way round across ±π. The knot vector is *clamped* (end knots repeated
//! degree + 1 times) and uniform inside, so the curve starts exactly at the first pose,
//! ends exactly at the last one and approximates (smooths) the ones in between, as the
//! paper's spline must to cut the lattice path's corners. The degree is
//! min(3, poses − 1): one pose gives a point, two a straight segment, three a parabola.
//!
//! Length along the spline is measured in a *pose metric*
//! ds² = dx² + dy² + (ρ·dθ)², with ρ the rotation radius given at construction. With
//! ρ = 0 it is the ordinary arc length; with ρ > 0 a turn on the spot (position constant,
//! θ changing) still has a length, so "a lookahead ahead along the spline" and "the
//! closest point to the robot" stay meaningful while the robot turns in place — the
//! [`path_follower`](super::path_follower) relies on this. Lengths come from a dense
//! lookup table ([`SAMPLES_PER_SPAN`] chords per knot span), good to far below a
//! millimetre for the half-metre splines the controller builds.
//!
//! Everything is deterministic and total: no input makes it panic or return NaN once the
//! constructor has accepted the poses (finite values only).

use crate::geometry::{Pose2, wrap_angle};

/// Chords per knot span in the length table. A 0.5 m cubic span with 128 chords has chord
/// errors of order h²κ²·L/24 ≈ 10⁻⁸ m for curvatures κ ≤ 10 m⁻¹, far below the required
/// millimetre; the table also seeds the closest-point search.
pub const SAMPLES_PER_SPAN: usize = 128;

/// Golden-section iterations refining a closest point: the bracket (two table intervals)
/// shrinks by 0.618⁴⁰ ≈ 4·10⁻⁹, i.e. to 10⁻¹¹ in the parameter.
const REFINE_ITERATIONS: usize = 40;

/// Why a spline could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplineError {
    /// No poses were given.
    #[error("a B-spline needs at least one pose")]
    Empty,
    /// A pose has a NaN or infinite component.
    #[error("pose {index} is not finite")]
    NonFinite {
        /// Index of the offending pose.
        index: usize,
    },
    /// The rotation radius of the pose metric is negative or not finite.
    #[error("rotation radius {0} must be a finite number >= 0")]
    InvalidRotationRadius(f64),
}

/// A B-spline curve in (x, y, θ) with its knot vector; also used for the derivative curve.
#[derive(Debug, Clone, PartialEq)]
struct Curve {
    degree: usize,
    knots: Vec<f64>,
    ctrl: Vec<[f64; 3]>,
}

impl Curve {
    /// Index of the knot span [U_k, U_{k+1}) holding `u` (NURBS Book A2.1); `u` at the upper
    /// end belongs to the last non-empty span.
    fn span(&self, u: f64) -> usize {
        let n = self.ctrl.len() - 1;
        let p = self.degree;
        if u >= self.knots[n + 1] {
            return n;
        }
        if u <= self.knots[p] {
            return p;
        }
        let (mut lo, mut hi) = (p, n + 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if u < self.knots[mid] { hi = mid } else { lo = mid }
        }
        lo
    }

    /// The degree + 1 non-zero basis functions at `u`, N_{span−p..=span} (NURBS Book A2.2).
    /// Denominators are knot differences around a non-empty span of a clamped knot vector
    /// with distinct interior knots, so they are never zero.
    fn basis_at(&self, u: f64) -> (usize, [f64; 4]) {
        let p = self.degree;
        let span = self.span(u);
        let mut n = [0.0; 4];
        let mut left = [0.0; 4];
        let mut right = [0.0; 4];
        n[0] = 1.0;
        for j in 1..=p {
            left[j] = u - self.knots[span + 1 - j];
            right[j] = self.knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                let temp = n[r] / (right[r + 1] + left[j - r]);
                n[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            n[j] = saved;
        }
        (span, n)
    }

    fn eval(&self, u: f64) -> [f64; 3] {
        let (span, n) = self.basis_at(u);
        let p = self.degree;
        let mut out = [0.0; 3];
        for (r, w) in n.iter().enumerate().take(p + 1) {
            let c = self.ctrl[span - p + r];
            for k in 0..3 {
                out[k] += w * c[k];
            }
        }
        out
    }

    /// The derivative curve d/du: degree p − 1 with control points
    /// Q_i = p·(P_{i+1} − P_i)/(U_{i+p+1} − U_{i+1}) on the knots without their ends.
    fn derivative(&self) -> Curve {
        let p = self.degree;
        if p == 0 {
            return Curve { degree: 0, knots: vec![0.0, 1.0], ctrl: vec![[0.0; 3]] };
        }
        let ctrl = self
            .ctrl
            .windows(2)
            .enumerate()
            .map(|(i, w)| {
                let f = p as f64 / (self.knots[i + p + 1] - self.knots[i + 1]);
                [f * (w[1][0] - w[0][0]), f * (w[1][1] - w[0][1]), f * (w[1][2] - w[0][2])]
            })
            .collect();
        Curve { degree: p - 1, knots: self.knots[1..self.knots.len() - 1].to_vec(), ctrl }
    }
}

/// One entry of the length table.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Sample {
    u: f64,
    s: f64,
    point: [f64; 3],
}

/// The closest point of a spline to a query pose ([`PoseSpline::project`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Spline parameter, in [0, 1].
    pub u: f64,
    /// Length along the spline from its start to the closest point (pose metric), m.
    pub s: f64,
    /// The spline's pose there (θ wrapped to (−π, π]).
    pub pose: Pose2,
    /// Distance √(dx² + dy² + (ρ·Δθ)²) from the query in the projection's metric, m.
    pub distance: f64,
    /// Plain Euclidean distance between the positions, m.
    pub position_distance: f64,
}

/// A clamped uniform B-spline (cubic when there are at least four poses) through a short
/// sequence of poses, with a length table in the pose metric (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PoseSpline {
    curve: Curve,
    deriv: Curve,
    rotation_radius: f64,
    table: Vec<Sample>,
}

impl PoseSpline {
    /// The spline of `poses` (first and last interpolated, the others approximated), with
    /// lengths in the pose metric of rotation radius `rotation_radius_m` (0: arc length).
    ///
    /// # Errors
    /// [`SplineError`] for no poses, a non-finite pose, or an invalid rotation radius.
    pub fn new(poses: &[Pose2], rotation_radius_m: f64) -> Result<Self, SplineError> {
        if poses.is_empty() {
            return Err(SplineError::Empty);
        }
        if !(rotation_radius_m.is_finite() && rotation_radius_m >= 0.0) {
            return Err(SplineError::InvalidRotationRadius(rotation_radius_m));
        }
        if let Some(index) =
            poses.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()))
        {
            return Err(SplineError::NonFinite { index });
        }
        // Unwrap θ so consecutive control headings differ by at most π: the spline then
        // turns the short way, e.g. from 179° to −179° through 180°, not through 0°.
        let mut ctrl: Vec<[f64; 3]> = Vec::with_capacity(poses.len());
        for p in poses {
            let theta = match ctrl.last() {
                Some(prev) => prev[2] + wrap_angle(p.theta - prev[2]),
                None => p.theta,
            };
            ctrl.push([p.x, p.y, theta]);
        }
        let n = ctrl.len();
        let degree = (n - 1).min(3);
        let spans = n - degree;
        // Clamped uniform knots: degree + 1 zeros, spans − 1 evenly spaced interior knots,
        // degree + 1 ones.
        let mut knots = vec![0.0; degree + 1];
        knots.extend((1..spans).map(|j| j as f64 / spans as f64));
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        let curve = Curve { degree, knots, ctrl };
        let deriv = curve.derivative();
        let mut spline =
            Self { curve, deriv, rotation_radius: rotation_radius_m, table: Vec::new() };
        spline.build_table(spans);
        Ok(spline)
    }

    fn build_table(&mut self, spans: usize) {
        let count = spans * SAMPLES_PER_SPAN;
        let mut table = Vec::with_capacity(count + 1);
        let mut s = 0.0;
        let mut prev: Option<[f64; 3]> = None;
        for j in 0..=count {
            let u = j as f64 / count as f64;
            let point = self.curve.eval(u);
            if let Some(q) = prev {
                s += self.metric(point, q);
            }
            table.push(Sample { u, s, point });
            prev = Some(point);
        }
        self.table = table;
    }

    /// Pose-metric distance between two (x, y, unwrapped θ) points.
    fn metric(&self, a: [f64; 3], b: [f64; 3]) -> f64 {
        let dt = self.rotation_radius * (a[2] - b[2]);
        (a[0] - b[0]).hypot(a[1] - b[1]).hypot(dt)
    }

    /// Polynomial degree: min(3, number of poses − 1).
    pub fn degree(&self) -> usize {
        self.curve.degree
    }

    /// The control points (x, y, θ unwrapped), one per input pose.
    pub fn control_points(&self) -> &[[f64; 3]] {
        &self.curve.ctrl
    }

    /// Rotation radius ρ of the pose metric, m.
    pub fn rotation_radius(&self) -> f64 {
        self.rotation_radius
    }

    /// All basis functions N_i(u), one per control point (mostly zeros). They are ≥ 0 and
    /// sum to one; at u = 0 only the first is non-zero, at u = 1 only the last.
    pub fn basis(&self, u: f64) -> Vec<f64> {
        let u = clamp_param(u);
        let (span, n) = self.curve.basis_at(u);
        let p = self.curve.degree;
        let mut out = vec![0.0; self.curve.ctrl.len()];
        for r in 0..=p {
            out[span - p + r] = n[r];
        }
        out
    }

    /// The spline point (x, y, θ unwrapped) at parameter `u` (clamped to [0, 1]).
    pub fn point(&self, u: f64) -> [f64; 3] {
        self.curve.eval(clamp_param(u))
    }

    /// The spline pose at `u`, θ wrapped to (−π, π].
    pub fn pose(&self, u: f64) -> Pose2 {
        let [x, y, theta] = self.point(u);
        Pose2::new(x, y, wrap_angle(theta))
    }

    /// The derivative d(x, y, θ)/du at `u`. Zero everywhere for a single pose.
    pub fn derivative(&self, u: f64) -> [f64; 3] {
        self.deriv.eval(clamp_param(u))
    }

    /// Direction of motion atan2(dy/du, dx/du) at `u`, or `None` where the position does
    /// not move (a single pose, or a turn on the spot). This is the path tangent, not the
    /// robot's heading θ: an omnidirectional robot may drive sideways or backwards.
    pub fn tangent_direction(&self, u: f64) -> Option<f64> {
        let d = self.derivative(u);
        let speed = d[0].hypot(d[1]);
        // 1e-9 m per unit parameter: far below any real motion on a spline of poses.
        (speed > 1e-9).then(|| d[1].atan2(d[0]))
    }

    /// Total length in the pose metric, m.
    pub fn length(&self) -> f64 {
        self.table.last().map_or(0.0, |s| s.s)
    }

    /// Length from the start to parameter `u` (pose metric), m.
    pub fn length_at(&self, u: f64) -> f64 {
        let u = clamp_param(u);
        let last = self.table.len().saturating_sub(1);
        if last == 0 {
            return 0.0;
        }
        // Samples are uniform in u: the interval is found by index, then interpolated.
        let i = ((u * last as f64).floor() as usize).min(last - 1);
        let (a, b) = (self.table[i], self.table[i + 1]);
        let f = ((u - a.u) / (b.u - a.u)).clamp(0.0, 1.0);
        a.s + f * (b.s - a.s)
    }

    /// The parameter at length `s` from the start (pose metric), clamped to the spline.
    /// Where the spline does not move in the metric (repeated poses, or a pure turn with
    /// ρ = 0) the first parameter reaching `s` is returned; `s` at or past the end gives 1.
    pub fn param_at_length(&self, s: f64) -> f64 {
        let total = self.length();
        if s.is_nan() || s >= total {
            // NaN too: the end of the spline is the safe answer.
            return 1.0;
        }
        if s <= 0.0 {
            return 0.0;
        }
        // First sample with length ≥ s (the table is non-decreasing).
        let j = self.table.partition_point(|e| e.s < s);
        if j == 0 {
            return 0.0;
        }
        let (a, b) = (self.table[j - 1], self.table[j]);
        let ds = b.s - a.s;
        if ds <= 0.0 {
            return b.u;
        }
        a.u + (s - a.s) / ds * (b.u - a.u)
    }

    /// Squared pose-metric distance from the spline at `u` to `q`; the heading difference
    /// is wrapped, so the query's θ may be given in any branch.
    fn dist2(&self, u: f64, q: &Pose2, rho: f64) -> f64 {
        let c = self.curve.eval(u);
        dist2_point(c, q, rho)
    }

    /// The point of the spline closest to `query` in the pose metric of rotation radius
    /// `rotation_radius_m` (0: simply the closest position; it need not be the radius the
    /// lengths are measured with — a small one lets positions decide and headings only
    /// tell apart the points of a turn on the spot). Robust and deterministic: the best
    /// table sample (first one on ties) is refined by a golden-section search over its two
    /// neighbouring intervals. A negative or non-finite radius counts as 0.
    pub fn project(&self, query: &Pose2, rotation_radius_m: f64) -> Projection {
        let rho = if rotation_radius_m.is_finite() { rotation_radius_m.max(0.0) } else { 0.0 };
        let mut best = 0;
        let mut best_d = f64::INFINITY;
        for (j, e) in self.table.iter().enumerate() {
            let d = dist2_point(e.point, query, rho);
            if d < best_d {
                best_d = d;
                best = j;
            }
        }
        let last = self.table.len() - 1;
        let mut lo = self.table[best.saturating_sub(1)].u;
        let mut hi = self.table[(best + 1).min(last)].u;
        let mut u_best = self.table[best].u;
        if hi > lo {
            let g = (5f64.sqrt() - 1.0) / 2.0;
            let mut a = hi - g * (hi - lo);
            let mut b = lo + g * (hi - lo);
            let (mut fa, mut fb) = (self.dist2(a, query, rho), self.dist2(b, query, rho));
            for _ in 0..REFINE_ITERATIONS {
                if fa <= fb {
                    hi = b;
                    b = a;
                    fb = fa;
                    a = hi - g * (hi - lo);
                    fa = self.dist2(a, query, rho);
                } else {
                    lo = a;
                    a = b;
                    fa = fb;
                    b = lo + g * (hi - lo);
                    fb = self.dist2(b, query, rho);
                }
            }
            let u = 0.5 * (lo + hi);
            let d = self.dist2(u, query, rho);
            // Keep the sample if refinement did not improve on it (flat or kinked metric).
            if d < best_d {
                best_d = d;
                u_best = u;
            }
        }
        let c = self.curve.eval(u_best);
        Projection {
            u: u_best,
            s: self.length_at(u_best),
            pose: Pose2::new(c[0], c[1], wrap_angle(c[2])),
            distance: best_d.max(0.0).sqrt(),
            position_distance: (c[0] - query.x).hypot(c[1] - query.y),
        }
    }
}

/// Squared pose-metric distance from a spline point (θ unwrapped) to `q`.
fn dist2_point(c: [f64; 3], q: &Pose2, rho: f64) -> f64 {
    let dt = rho * wrap_angle(c[2] - q.theta);
    (c[0] - q.x).powi(2) + (c[1] - q.y).powi(2) + dt * dt
}

/// Clamps a parameter to [0, 1]; NaN maps to 0 so evaluation stays total.
fn clamp_param(u: f64) -> f64 {
    if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn line5() -> PoseSpline {
        let poses: Vec<Pose2> = (0..5).map(|i| Pose2::new(0.25 * f64::from(i), 0.0, 0.0)).collect();
        PoseSpline::new(&poses, 0.0).unwrap()
    }

    fn curved() -> PoseSpline {
        let poses = [
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(0.15, 0.0, 0.1),
            Pose2::new(0.3, 0.05, 0.4),
            Pose2::new(0.4, 0.17, 0.9),
            Pose2::new(0.45, 0.32, 1.4),
        ];
        PoseSpline::new(&poses, 0.0).unwrap()
    }

    #[test]
    fn basis_sums_to_one_and_is_non_negative() {
        for s in [line5(), curved()] {
            for j in 0..=100 {
                let b = s.basis(f64::from(j) / 100.0);
                assert!(b.iter().all(|&v| v >= -1e-15), "{b:?}");
                assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{b:?}");
            }
        }
    }

    #[test]
    fn basis_at_interior_knot_is_hand_computed() {
        // Knots 0,0,0,0,½,1,1,1,1; Cox–de Boor at u = ½ gives N = (0, ¼, ½, ¼, 0).
        let b = line5().basis(0.5);
        let expect = [0.0, 0.25, 0.5, 0.25, 0.0];
        for (v, e) in b.iter().zip(expect) {
            assert!((v - e).abs() < 1e-12, "{b:?}");
        }
    }

    #[test]
    fn endpoints_are_clamped() {
        let s = curved();
        assert_eq!(s.basis(0.0), vec![1.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(s.basis(1.0), vec![0.0, 0.0, 0.0, 0.0, 1.0]);
        let (a, b) = (s.pose(0.0), s.pose(1.0));
        assert!(a.x.abs() < 1e-12 && a.y.abs() < 1e-12 && a.theta.abs() < 1e-12);
        assert!(
            (b.x - 0.45).abs() < 1e-12
                && (b.y - 0.32).abs() < 1e-12
                && (b.theta - 1.4).abs() < 1e-12
        );
        // Clamped cubic: the end tangent points at the neighbouring control point,
        // C'(0) = 3·(P1 − P0)/(U4 − U1) = 3·(0.15, 0)/0.5 = (0.9, 0).
        let d = s.derivative(0.0);
        assert!((d[0] - 0.9).abs() < 1e-12 && d[1].abs() < 1e-12, "{d:?}");
    }

    #[test]
    fn straight_line_spline_is_that_line() {
        let s = line5();
        assert_eq!(s.degree(), 3);
        for j in 0..=50 {
            let p = s.pose(f64::from(j) / 50.0);
            assert!(p.y.abs() < 1e-15 && p.theta.abs() < 1e-15);
            assert!((-1e-12..=1.0 + 1e-12).contains(&p.x));
        }
        // Uniformly spaced control points on a clamped uniform cubic: C(½) = ¼·0.25 + ½·0.5
        // + ¼·0.75 = 0.5.
        assert!((s.pose(0.5).x - 0.5).abs() < 1e-12);
        assert!((s.length() - 1.0).abs() < 1e-9, "{}", s.length());
        // Arc-length lookup: the point 0.3 m along is at x = 0.3.
        let u = s.param_at_length(0.3);
        assert!((s.pose(u).x - 0.3).abs() < 1e-4, "{}", s.pose(u).x);
        assert!((s.length_at(u) - 0.3).abs() < 1e-9);
    }

    #[test]
    fn arc_length_lookup_is_good_to_a_millimetre() {
        let s = curved();
        // Reference: 200 000 chords.
        let n = 200_000;
        let mut reference = vec![0.0; n + 1];
        let mut prev = s.point(0.0);
        for j in 1..=n {
            let p = s.point(j as f64 / n as f64);
            reference[j] = reference[j - 1] + (p[0] - prev[0]).hypot(p[1] - prev[1]);
            prev = p;
        }
        assert!((s.length() - reference[n]).abs() < 1e-4);
        for k in 1..10 {
            let target = reference[n] * f64::from(k) / 10.0;
            let u = s.param_at_length(target);
            let r = reference[(u * n as f64).round() as usize];
            assert!((r - target).abs() < 1e-3, "at {target}: {r}");
            assert!((s.length_at(u) - target).abs() < 1e-6);
        }
    }

    #[test]
    fn closest_point_on_a_straight_segment() {
        let s = line5();
        let pr = s.project(&Pose2::new(0.3, 0.2, 0.0), 0.0);
        assert!((pr.pose.x - 0.3).abs() < 1e-6 && pr.pose.y.abs() < 1e-12, "{pr:?}");
        assert!((pr.distance - 0.2).abs() < 1e-9 && (pr.position_distance - 0.2).abs() < 1e-9);
        // Lengths interpolate the table linearly in u: good to ~10⁻⁵ m here.
        assert!((pr.s - 0.3).abs() < 1e-5, "{}", pr.s);
        // Beyond either end: the end points.
        let before = s.project(&Pose2::new(-0.5, -0.1, 0.0), 0.0);
        assert!(before.u == 0.0 && before.pose.x.abs() < 1e-12);
        let after = s.project(&Pose2::new(1.7, 0.3, 0.0), 0.0);
        assert!((after.u - 1.0).abs() < 1e-9 && (after.pose.x - 1.0).abs() < 1e-9);
    }

    #[test]
    fn closest_point_on_a_curve_beats_dense_sampling() {
        let s = curved();
        let q = Pose2::new(0.2, 0.2, 0.0);
        let pr = s.project(&q, 0.0);
        let brute = (0..=100_000)
            .map(|j| {
                let p = s.point(f64::from(j) / 100_000.0);
                (p[0] - q.x).hypot(p[1] - q.y)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(pr.distance <= brute + 1e-12, "{} vs {brute}", pr.distance);
    }

    #[test]
    fn theta_is_unwrapped_across_pi() {
        // 3.0 rad to −3.0 rad is a 0.28 rad turn through π, not a 6 rad turn through 0.
        let s =
            PoseSpline::new(&[Pose2::new(0.0, 0.0, 3.0), Pose2::new(1.0, 0.0, -3.0)], 0.0).unwrap();
        assert!((s.control_points()[1][2] - (2.0 * PI - 3.0)).abs() < 1e-12);
        let mid = s.pose(0.5);
        assert!(wrap_angle(mid.theta - PI).abs() < 1e-12, "{}", mid.theta);
        for j in 0..=20 {
            let t = s.point(f64::from(j) / 20.0)[2];
            assert!((3.0 - 1e-12..=2.0 * PI - 3.0 + 1e-12).contains(&t), "{t}");
        }
    }

    #[test]
    fn one_pose_is_a_point() {
        let p = Pose2::new(1.0, -2.0, 0.5);
        let s = PoseSpline::new(&[p], 0.4).unwrap();
        assert_eq!(s.degree(), 0);
        for u in [0.0, 0.3, 1.0, f64::NAN, -3.0] {
            assert_eq!(s.pose(u), p);
            assert_eq!(s.derivative(u), [0.0; 3]);
        }
        assert_eq!(s.length(), 0.0);
        assert_eq!(s.param_at_length(0.1), 1.0);
        assert_eq!(s.tangent_direction(0.5), None);
        let pr = s.project(&Pose2::new(1.3, -1.6, 0.5), 0.4);
        assert!((pr.distance - 0.5).abs() < 1e-12 && pr.u == 0.0);
    }

    #[test]
    fn two_poses_are_a_segment() {
        let s = PoseSpline::new(&[Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.0, 2.0, FRAC_PI_2)], 0.0)
            .unwrap();
        assert_eq!(s.degree(), 1);
        let p = s.pose(0.25);
        assert!(
            p.x.abs() < 1e-12
                && (p.y - 0.5).abs() < 1e-12
                && (p.theta - FRAC_PI_2 / 4.0).abs() < 1e-12
        );
        assert_eq!(s.derivative(0.7), [0.0, 2.0, FRAC_PI_2]);
        assert!((s.tangent_direction(0.1).unwrap() - FRAC_PI_2).abs() < 1e-12);
        assert!((s.length() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn turn_on_the_spot_has_length_in_the_pose_metric() {
        let poses: Vec<Pose2> =
            (0..5).map(|i| Pose2::new(1.0, 1.0, FRAC_PI_2 * f64::from(i) / 4.0)).collect();
        let s = PoseSpline::new(&poses, 0.4).unwrap();
        // Monotone θ from 0 to π/2 at a fixed position: length ρ·π/2.
        assert!((s.length() - 0.4 * FRAC_PI_2).abs() < 1e-9, "{}", s.length());
        assert_eq!(s.tangent_direction(0.5), None);
        // Lookahead along it changes θ, not the position.
        let p = s.pose(s.param_at_length(0.2));
        assert!((p.x - 1.0).abs() < 1e-15 && (p.y - 1.0).abs() < 1e-15);
        assert!((p.theta - 0.5).abs() < 1e-4, "{}", p.theta);
        // A robot there at θ = 1.0 projects to θ = 1.0.
        let pr = s.project(&Pose2::new(1.0, 1.0, 1.0), 0.05);
        assert!((pr.pose.theta - 1.0).abs() < 1e-6 && pr.distance < 1e-6, "{pr:?}");
        // With ρ = 0 the same spline has no length but stays finite.
        let z = PoseSpline::new(&poses, 0.0).unwrap();
        assert_eq!(z.length(), 0.0);
        assert_eq!(z.param_at_length(0.0), 1.0);
        let pr = z.project(&Pose2::new(2.0, 1.0, 0.0), 0.0);
        assert!(pr.u.is_finite() && (pr.distance - 1.0).abs() < 1e-12);
    }

    #[test]
    fn repeated_poses_stay_finite() {
        let p = Pose2::new(0.5, 0.5, -1.0);
        let s = PoseSpline::new(&[p, p, p, p, p], 0.4).unwrap();
        for j in 0..=10 {
            let u = f64::from(j) / 10.0;
            let q = s.pose(u);
            assert!(
                (q.x - p.x).abs() < 1e-12
                    && (q.y - p.y).abs() < 1e-12
                    && (q.theta - p.theta).abs() < 1e-12
            );
            assert!(s.derivative(u).iter().all(|v| v.abs() < 1e-12));
        }
        assert!(s.length() < 1e-12);
        let pr = s.project(&Pose2::new(0.0, 0.0, 3.0), f64::NAN);
        assert!(pr.distance.is_finite() && pr.s < 1e-12);
        assert_eq!(s.param_at_length(f64::NAN), 1.0);
    }

    #[test]
    fn invalid_input_is_an_error() {
        assert_eq!(PoseSpline::new(&[], 0.0), Err(SplineError::Empty));
        let bad = [Pose2::new(0.0, 0.0, 0.0), Pose2::new(f64::NAN, 0.0, 0.0)];
        assert_eq!(PoseSpline::new(&bad, 0.0), Err(SplineError::NonFinite { index: 1 }));
        assert_eq!(
            PoseSpline::new(&[Pose2::default()], -1.0),
            Err(SplineError::InvalidRotationRadius(-1.0))
        );
    }
}
