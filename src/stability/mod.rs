//! Static stability: the support polygon of the ground contacts and the margin of the
//! horizontal CoM projection inside it (Sec. VI-A).
//!
//! The margin is the signed distance from the CoM projection to the polygon's boundary:
//! positive inside, negative outside. With fewer than three non-collinear contacts there is
//! no area to stand on and the margin is minus the distance to the contacts' hull (a point
//! or segment), so it is never positive.

use crate::geometry::norm2;

/// Convex hull of points in the plane, counter-clockwise, without collinear points
/// (Andrew's monotone chain). Deterministic for equal inputs.
pub fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> =
        points.iter().copied().filter(|q| q[0].is_finite() && q[1].is_finite()).collect();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(p.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> =
            if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 1e-12
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Distance from `p` to the segment from `a` to `b` in the plane.
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm2(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)
}

/// Signed distance of `com` (horizontal projection) to the boundary of the convex hull of
/// `contacts`: positive inside. `-inf` without contacts.
pub fn stability_margin(contacts: &[[f64; 2]], com: [f64; 2]) -> f64 {
    let hull = convex_hull(contacts);
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

    #[test]
    fn degenerate_support_is_never_positive() {
        assert!(stability_margin(&[[0.0, 0.0], [1.0, 0.0]], [0.5, 0.0]) <= 0.0);
        assert!((stability_margin(&[[0.0, 0.0], [1.0, 0.0]], [0.5, 0.2]) + 0.2).abs() < 1e-12);
        assert_eq!(stability_margin(&[], [0.0, 0.0]), f64::NEG_INFINITY);
    }
}
