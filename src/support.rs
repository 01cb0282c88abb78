//! Static stability: the support polygon of the ground contacts and the margin of the
//! horizontal CoM projection inside it (Sec. VI-A).
//!
//! The margin is the signed distance from the CoM projection to the polygon's boundary:
//! positive inside, negative outside. With fewer than three non-collinear contacts there is
//! no area to stand on and the margin is minus the distance to the contacts' hull (a point
//! or segment), so it is never positive.

use crate::geometry::{norm2, segment_distance};

/// Most points whose hull [`with_hull`] computes on the stack: a robot's contacts (four
/// wheel pairs), which the planner's checks evaluate millions of times.
const STACK_POINTS: usize = 8;

/// Convex hull of points in the plane, counter-clockwise, without collinear points
/// (Andrew's monotone chain). Deterministic for equal inputs.
pub fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    with_hull(points, <[[f64; 2]]>::to_vec)
}

/// `f` of the [`convex_hull`] of `points`, the hull kept on the stack for up to
/// [`STACK_POINTS`] points.
pub fn with_hull<R>(points: &[[f64; 2]], f: impl FnOnce(&[[f64; 2]]) -> R) -> R {
    if points.len() <= STACK_POINTS {
        let mut sorted = [[0.0; 2]; STACK_POINTS];
        let mut hull = [[0.0; 2]; 2 * STACK_POINTS];
        let n = hull_into(points, &mut sorted, &mut hull);
        f(&hull[..n])
    } else {
        let mut sorted = vec![[0.0; 2]; points.len()];
        let mut hull = vec![[0.0; 2]; 2 * points.len()];
        let n = hull_into(points, &mut sorted, &mut hull);
        f(&hull[..n])
    }
}

/// The monotone chain over the finite `points`, sorted and deduplicated into `sorted`
/// (room for all of them), the hull written to `hull` (room for twice as many); returns
/// the hull's length.
fn hull_into(points: &[[f64; 2]], sorted: &mut [[f64; 2]], hull: &mut [[f64; 2]]) -> usize {
    let mut m = 0;
    for q in points.iter().filter(|q| q[0].is_finite() && q[1].is_finite()) {
        sorted[m] = *q;
        m += 1;
    }
    let p = &mut sorted[..m];
    p.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    // Equal neighbours (by `==`, as `Vec::dedup`) once.
    let mut k = 0;
    for i in 0..m {
        if k == 0 || p[i] != p[k - 1] {
            p[k] = p[i];
            k += 1;
        }
    }
    if k < 3 {
        hull[..k].copy_from_slice(&p[..k]);
        return k;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut len = 0;
    for pass in 0..2 {
        let start = len;
        for idx in 0..k {
            let q = if pass == 0 { p[idx] } else { p[k - 1 - idx] };
            while len >= start + 2 && cross(hull[len - 2], hull[len - 1], q) <= 1e-12 {
                len -= 1;
            }
            hull[len] = q;
            len += 1;
        }
        len -= 1;
    }
    len
}

/// Signed distance of `com` (horizontal projection) to the boundary of the convex hull of
/// `contacts`: positive inside. `-inf` without contacts.
pub fn stability_margin(contacts: &[[f64; 2]], com: [f64; 2]) -> f64 {
    with_hull(contacts, |hull| margin_in(hull, com))
}

/// [`stability_margin`] of `com` in the hull `hull`.
fn margin_in(hull: &[[f64; 2]], com: [f64; 2]) -> f64 {
    match hull.len() {
        0 => f64::NEG_INFINITY,
        1 => -norm2(com[0] - hull[0][0], com[1] - hull[0][1]),
        2 => -segment_distance(com, hull[0], hull[1]),
        n => {
            let mut inside = true;
            let mut nearest = f64::INFINITY;
            for i in 0..n {
                let (a, b) = (hull[i], hull[(i + 1) % n]);
                let cross = (b[0] - a[0]) * (com[1] - a[1]) - (b[1] - a[1]) * (com[0] - a[0]);
                if cross < 0.0 {
                    inside = false;
                }
                nearest = nearest.min(segment_distance(com, a, b));
            }
            if inside { nearest } else { -nearest }
        }
    }
}

/// Limits the monitor checks against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonitorLimits {
    /// Roll or pitch beyond this is a tip-over, rad: steps pitch the base by at most about
    /// 15°, so 35° is a robot falling, not climbing.
    pub max_tilt_rad: f64,
    /// A base sinking faster than this for [`Self::fall_duration_s`] is falling, m/s:
    /// the controllers lower it at about 0.1 m/s.
    pub fall_speed_m_s: f64,
    /// How long the base must sink that fast to count as a fall, s: a wheel rolling off
    /// a 5 cm bump drops the base at that speed for under 0.1 s; a robot tipping over or
    /// off a step keeps falling.
    pub fall_duration_s: f64,
    /// A wheel whose contact MuJoCo lists this close to the terrain supports the robot,
    /// m (the foam compresses by more than that under load; with the model's margin of
    /// 0, MuJoCo lists a wheel's contacts only once it touches).
    pub support_gap_m: f64,
    /// A wheel that touched the terrain this recently still supports the robot, s.
    pub support_memory_s: f64,
    /// Wheels expected to support the robot (8 while driving).
    pub expected_wheels: usize,
    /// Samples before this time only update the wheel memory (the robot settles), s.
    pub settle_s: f64,
    /// A margin counts toward the run's minimum when held this long, s: longer than a
    /// wheel's bounce off a bump edge (the support memory), short against any lean.
    pub margin_hold_s: f64,
}

impl Default for MonitorLimits {
    fn default() -> Self {
        Self {
            max_tilt_rad: 35f64.to_radians(),
            fall_speed_m_s: 0.5,
            fall_duration_s: 0.15,
            support_gap_m: 0.004,
            support_memory_s: 0.03,
            expected_wheels: 8,
            settle_s: 0.0,
            margin_hold_s: 0.05,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_margin_is_distance_to_nearest_edge() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
        assert_eq!(convex_hull(&sq).len(), 4);
        assert!((stability_margin(&sq, [0.5, 0.5]) - 0.5).abs() < 1e-12);
        assert!((stability_margin(&sq, [0.2, 0.6]) - 0.2).abs() < 1e-12);
        assert!((stability_margin(&sq, [1.3, 0.5]) + 0.3).abs() < 1e-12);
    }

    #[test]
    fn triangle_margin_hand_computed() {
        // Right triangle (0,0) (2,0) (0,2): the point (0.5, 0.5) is 0.5 from two legs and
        // |0.5 + 0.5 − 2|/√2 = 1/√2 from the hypotenuse.
        let tri = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        assert!((stability_margin(&tri, [0.5, 0.5]) - 0.5).abs() < 1e-12);
        assert!((stability_margin(&tri, [0.9, 0.9]) - 0.2 / 2f64.sqrt()).abs() < 1e-12);
    }

    proptest::proptest! {
        /// The hull on the stack (up to 8 points) and on the heap (more) is the convex
        /// hull: counter-clockwise, no collinear vertex, every point on or left of every
        /// edge, every vertex one of the points; and a point set's hull does not depend
        /// on which path computed it (the first 8 points again, padded with copies of
        /// them past the stack's size).
        #[test]
        fn the_hull_holds_every_point_on_either_path(
            pts in proptest::collection::vec((-2i32..=2, -2i32..=2), 1..14)
        ) {
            let pts: Vec<[f64; 2]> =
                pts.iter().map(|&(x, y)| [f64::from(x) * 0.3, f64::from(y) * 0.2]).collect();
            let hull = convex_hull(&pts);
            let n = hull.len();
            for v in &hull {
                proptest::prop_assert!(pts.contains(v));
            }
            if n >= 3 {
                for i in 0..n {
                    let (a, b, c) = (hull[i], hull[(i + 1) % n], hull[(i + 2) % n]);
                    let turn = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
                    proptest::prop_assert!(turn > 0.0, "{hull:?}");
                    for p in &pts {
                        let side = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
                        proptest::prop_assert!(side >= -1e-12, "{p:?} right of {a:?}→{b:?}");
                    }
                }
            }
            let first: Vec<[f64; 2]> = pts.iter().copied().take(8).collect();
            let padded: Vec<[f64; 2]> = first.iter().cycle().copied().take(12).collect();
            proptest::prop_assert_eq!(convex_hull(&first), convex_hull(&padded));
        }
    }

    #[test]
    fn degenerate_support_is_never_positive() {
        assert!(stability_margin(&[[0.0, 0.0], [1.0, 0.0]], [0.5, 0.0]) <= 0.0);
        assert!((stability_margin(&[[0.0, 0.0], [1.0, 0.0]], [0.5, 0.2]) + 0.2).abs() < 1e-12);
        assert_eq!(stability_margin(&[], [0.0, 0.0]), f64::NEG_INFINITY);
    }
}
