//! Flights of steps read from a height map alone: how many risers follow each other,
//! all up or all down, with treads between them too short for the whole robot to stand
//! on one (the feet then stand on different levels, as on stairs), and how high they
//! climb in all.
//!
//! The planner chooses the models a scenario does not name from these flights
//! (`planner::world::terrain_models`), so a flight written as a `stairs` primitive, as
//! stacked boxes, or seen by the laser is the same terrain to it: only heights count.
//!
//! The map is scanned along straight lines in [`SCAN_DIRECTIONS`] directions over a half
//! turn (every flight is crossed within 11.25° of its axis, so a tread reads at most 2 %
//! long), one line every [`LANE_CELLS`] cells across: a flight as narrow as the robot is
//! crossed by several lines. Along a line, a *riser* is a height change between adjacent
//! samples of at least [`FlightRule::min_rise_m`] (what a wheel cannot drive over) and at
//! most [`FlightRule::max_rise_m`] (what a step overcomes; a higher change is a wall and
//! ends the flight). Risers closer than [`FlightRule::min_tread_m`] are one riser (the
//! corner of a rotated step can read as two); risers of one sense at most
//! [`FlightRule::max_tread_m`] apart are one flight. Unknown cells end a flight. A flight
//! counts where the lines that read it span [`FlightRule::min_width_m`] across: where two
//! small blocks stand on each other, or two edges meet at a corner, a line crossing both
//! reads two risers, but no flight as wide as the robot.

use super::HeightMap;

/// Directions scanned over a half turn (each line is read both ways).
pub const SCAN_DIRECTIONS: usize = 8;

/// Spacing of the scan lines across their direction, cells.
pub const LANE_CELLS: usize = 4;

/// What counts as a riser and as a flight, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightRule {
    /// Smallest height change that is a riser.
    pub min_rise_m: f64,
    /// Largest height change that is a riser (higher: a wall).
    pub max_rise_m: f64,
    /// Height changes closer than this are one riser.
    pub min_tread_m: f64,
    /// Longest tread between two risers of one flight.
    pub max_tread_m: f64,
    /// Narrowest flight.
    pub min_width_m: f64,
}

/// The longest and the tallest flight of a map.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Flights {
    /// The most risers of any flight (0 on terrain without risers).
    pub risers: u32,
    /// The largest height that any flight climbs, its risers summed, m.
    pub rise_m: f64,
}

/// The longest and the tallest flight of `map` under `rule`.
pub fn flights(map: &HeightMap, rule: &FlightRule) -> Flights {
    if !has_riser(map, rule) {
        return Flights::default();
    }
    let res = map.resolution();
    let (nx, ny) = map.dims();
    let (w, h) = (nx as f64, ny as f64);
    let min_tread = rule.min_tread_m / res;
    let max_tread = rule.max_tread_m / res;
    // Lanes side by side that a flight must cover.
    let lanes = ((rule.min_width_m / (res * LANE_CELLS as f64)).ceil() as usize).max(1);
    let mut best = Flights::default();
    for k in 0..SCAN_DIRECTIONS {
        let angle = std::f64::consts::PI * k as f64 / SCAN_DIRECTIONS as f64;
        let u = [angle.cos(), angle.sin()];
        let n = [-u[1], u[0]];
        // The map's corners (in cell units) projected on the line and across it.
        let corners = [[0.0, 0.0], [w, 0.0], [0.0, h], [w, h]];
        let span = |d: [f64; 2]| {
            corners.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                let p = c[0] * d[0] + c[1] * d[1];
                (lo.min(p), hi.max(p))
            })
        };
        let (t0, t1) = span(u);
        let (o0, o1) = span(n);
        // The longest and the tallest flight each lane reads.
        let mut per_lane = Vec::new();
        let mut o = o0 + 0.5;
        while o < o1 {
            let mut line = Line::default();
            let mut lane_best = Flights::default();
            let mut t = t0;
            while t <= t1 {
                let x = o * n[0] + t * u[0];
                let y = o * n[1] + t * u[1];
                let height = (x >= 0.0 && y >= 0.0 && x < w && y < h)
                    .then(|| map.get(x as usize, y as usize))
                    .flatten();
                line.sample(t, height, rule, min_tread, max_tread);
                lane_best.risers = lane_best.risers.max(line.count);
                lane_best.rise_m = lane_best.rise_m.max(line.rise_m);
                t += 1.0;
            }
            per_lane.push(lane_best);
            o += LANE_CELLS as f64;
        }
        // The longest and the tallest flight that `lanes` neighbouring lanes all read.
        for window in per_lane.windows(lanes.min(per_lane.len())) {
            let risers = window.iter().map(|f| f.risers).min().unwrap_or(0);
            let rise = window.iter().map(|f| f.rise_m).fold(f64::INFINITY, f64::min);
            best.risers = best.risers.max(risers);
            best.rise_m = best.rise_m.max(rise);
        }
    }
    best
}

/// Whether any two neighbouring cells (along x, y or a diagonal) differ by a riser:
/// where none do (open floors, ramps, low clutter), no line needs scanning. Consecutive
/// samples of a scan line lie in one cell or in neighbouring ones, so a line reads a
/// riser only where this finds one.
fn has_riser(map: &HeightMap, rule: &FlightRule) -> bool {
    let (nx, ny) = map.dims();
    let is_riser = |a: &f64, b: &f64| {
        let d = (a - b).abs();
        d >= rule.min_rise_m && d <= rule.max_rise_m
    };
    let row = |j: usize| &map.as_slice()[j * nx..(j + 1) * nx];
    (0..ny).any(|j| {
        let r = row(j);
        if r.windows(2).any(|w| is_riser(&w[0], &w[1])) {
            return true;
        }
        if j + 1 == ny {
            return false;
        }
        let up = row(j + 1);
        r.iter().zip(up).any(|(a, b)| is_riser(a, b))
            || r.iter().zip(&up[1..]).any(|(a, b)| is_riser(a, b))
            || r[1..].iter().zip(up).any(|(a, b)| is_riser(a, b))
    })
}

/// The flight being read along one scan line.
#[derive(Debug, Default)]
struct Line {
    /// Height of the previous sample, if known.
    previous: Option<f64>,
    /// Sense (+1 up, −1 down) and position of the last riser, cells.
    last: Option<(f64, f64)>,
    /// Risers of the current flight.
    count: u32,
    /// The height the current flight climbs (or descends), m.
    rise_m: f64,
}

impl Line {
    fn sample(
        &mut self,
        t: f64,
        height: Option<f64>,
        rule: &FlightRule,
        min_tread: f64,
        max_tread: f64,
    ) {
        let (Some(h), Some(p)) = (height, self.previous) else {
            // An unknown sample (or the line's first): no flight continues across it.
            self.previous = height;
            self.end_flight();
            return;
        };
        self.previous = Some(h);
        let rise = h - p;
        if rise.abs() < rule.min_rise_m {
            return;
        }
        if rise.abs() > rule.max_rise_m {
            self.end_flight();
            return;
        }
        let sense = rise.signum();
        match self.last {
            Some((s, at)) if s == sense && t - at < min_tread => self.rise_m += rise.abs(),
            Some((s, at)) if s == sense && t - at <= max_tread => {
                self.count += 1;
                self.rise_m += rise.abs();
            }
            _ => {
                self.count = 1;
                self.rise_m = rise.abs();
            }
        }
        self.last = Some((sense, t));
    }

    /// No flight goes on past here: the next riser starts a new one.
    fn end_flight(&mut self) {
        self.last = None;
        self.count = 0;
        self.rise_m = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::terrain::{Block, Primitive, Stairs};
    use crate::terrain::rasterise;

    /// The planner's rule for Momaro: a wheel's 5 cm, a step's 0.3 m, a wheel radius, the
    /// 0.86 m from the front of the front wheels to the back of the rear ones, the 0.76 m
    /// across the outer wheels.
    const RULE: FlightRule = FlightRule {
        min_rise_m: 0.05,
        max_rise_m: 0.3,
        min_tread_m: 0.08,
        max_tread_m: 0.86,
        min_width_m: 0.76,
    };

    fn flight(steps: u32, rise: f64, tread: f64, yaw_deg: f64) -> Primitive {
        Primitive::Stairs(Stairs {
            start: [0.0, 0.0],
            width: 1.2,
            steps,
            step_depth: tread,
            step_height: rise,
            landing_depth: 0.0,
            yaw_deg,
        })
    }

    fn count(prims: &[Primitive]) -> u32 {
        let map = rasterise(prims, [-3.0, -3.0], [8.0, 6.0], 0.025).expect("map");
        flights(&map, &RULE).risers
    }

    #[test]
    fn a_flight_counts_its_risers_at_any_heading() {
        for yaw in [0.0, 17.0, 45.0, 94.0, 200.0] {
            for steps in [2, 3, 5] {
                assert_eq!(count(&[flight(steps, 0.18, 0.3, yaw)]), steps, "{steps} at {yaw}°");
            }
        }
    }

    #[test]
    fn a_flight_narrower_than_the_robot_is_no_flight() {
        let narrow = |width| {
            Primitive::Stairs(Stairs {
                start: [0.0, 0.0],
                width,
                steps: 4,
                step_depth: 0.3,
                step_height: 0.15,
                landing_depth: 0.0,
                yaw_deg: 30.0,
            })
        };
        assert_eq!(count(&[narrow(0.9)]), 4);
        assert!(count(&[narrow(0.5)]) < 2);
    }

    #[test]
    fn a_flight_climbs_its_risers_summed() {
        let map =
            |prims: &[Primitive]| rasterise(prims, [-3.0, -3.0], [8.0, 6.0], 0.025).expect("map");
        let f = flights(&map(&[flight(3, 0.18, 0.3, 30.0)]), &RULE);
        assert_eq!(f.risers, 3);
        assert!((f.rise_m - 0.54).abs() < 1e-9, "{f:?}");
        // A landing longer than the robot splits a flight: the taller part counts.
        let lower = flight(3, 0.17, 0.29, 0.0);
        let upper = Primitive::Stairs(Stairs {
            start: [0.87 + 1.2, 0.0],
            width: 1.2,
            steps: 2,
            step_depth: 0.29,
            step_height: 0.17,
            landing_depth: 0.0,
            yaw_deg: 0.0,
        });
        let mut prims = lower.as_boxes();
        // The landing: 1.2 m at the top of the lower flight.
        prims.push(Primitive::Box(Block {
            center: [0.87 + 0.6, 0.0],
            size: [1.2, 1.2],
            height: 0.51,
            yaw_deg: 0.0,
        }));
        // The upper flight stands on the landing: its boxes raised by it.
        for b in upper.as_boxes() {
            if let Primitive::Box(b) = b {
                prims.push(Primitive::Box(Block { height: b.height + 0.51, ..b }));
            }
        }
        let f = flights(&map(&prims), &RULE);
        assert_eq!(f.risers, 3, "{f:?}");
        assert!((f.rise_m - 0.51).abs() < 1e-9, "{f:?}");
        // No risers: nothing climbed.
        assert_eq!(flights(&map(&[]), &RULE), Flights::default());
    }

    #[test]
    fn a_flight_as_boxes_is_the_same_flight() {
        let stairs = flight(4, 0.17, 0.28, 30.0);
        assert_eq!(count(&stairs.as_boxes()), 4);
        assert_eq!(count(&[stairs]), 4);
    }

    #[test]
    fn flat_ground_ramps_lone_steps_and_walls_are_no_flight() {
        assert_eq!(count(&[]), 0);
        let wide = |x: f64, depth: f64, width: f64, height: f64| {
            Primitive::Box(Block { center: [x, 0.0], size: [depth, width], height, yaw_deg: 0.0 })
        };
        let block = |x: f64, depth: f64, height: f64| wide(x, depth, 2.0, height);
        // A platform: one riser.
        assert_eq!(count(&[block(1.5, 2.0, 0.2)]), 1);
        // A block crossed up and down: two risers of opposite sense.
        assert_eq!(count(&[block(1.0, 0.4, 0.2)]), 1);
        // Two rises with a tread the whole robot stands on: two flights of one (the lower
        // level reaches 1 m beyond the upper one on every side: where two edges meet
        // within the robot's length, as at a corner of a two-level block, a line crossing
        // both rightly reads a flight of two).
        let lower = wide(2.5, 4.0, 4.0, 0.15);
        assert_eq!(count(&[lower.clone(), block(2.5, 2.0, 0.3)]), 1);
        // The same with a 0.5 m tread: one flight of two.
        assert_eq!(count(&[lower, block(2.25, 2.5, 0.3)]), 2);
        // Two blocks stacked, narrower than the robot: no flight of two.
        assert_eq!(count(&[wide(1.0, 1.0, 0.5, 0.1), wide(1.2, 0.6, 0.5, 0.2)]), 1);
        // A wall is not a riser, and a 4 cm kerb is driven over.
        assert_eq!(count(&[block(1.0, 0.2, 1.0)]), 0);
        assert_eq!(count(&[block(1.0, 0.3, 0.04)]), 0);
    }

    #[test]
    fn unknown_cells_end_a_flight() {
        let mut map =
            rasterise(&[flight(4, 0.18, 0.3, 0.0)], [-1.0, -1.0], [3.0, 2.0], 0.025).expect("map");
        assert_eq!(flights(&map, &RULE).risers, 4);
        // Unknown across the second tread (x in 0.33..0.57 m): flights of 2 and 2 remain.
        let (nx, ny) = map.dims();
        for j in 0..ny {
            for i in 0..nx {
                let x = map.cell_center(i, j)[0];
                if (0.4..0.5).contains(&x) {
                    map.set(i, j, f64::NAN).expect("in the map");
                }
            }
        }
        assert_eq!(flights(&map, &RULE).risers, 2);
    }
}
