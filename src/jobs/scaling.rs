//! `momaro bench scaling`: how the planner's cold first path grows with the map's area
//! and with the course's length (issue 67's benchmark).
//!
//! Two sweeps of one course, each plan cold (maps and heuristic tables built for it) and
//! timed whole, as a user of `plan` waits for it:
//!
//! - **area**: the scenario's own course (start, goal, terrain) on square maps of the
//!   given sides, centred on the midpoint of start and goal. A planner whose work follows
//!   the course keeps the same time on every map.
//! - **length**: on one square map centred on the start, the goal straight ahead of the
//!   start at each of the given distances, facing the start's way.
//!
//! Each row reports the medians over the repeats of the whole wall time and of its parts
//! (maps, heuristic set-up, search), and what the plan did (its cost-to-go's settled
//! nodes, expansions, cost). Then, on the same world, a *warm replan*: the first path
//! again from the path's middle pose to the same goal, with the heuristic tables the cold
//! plan left (`HeuristicCache`), as the closed loop replans from where the robot stands.
//! Times are measurements on a noisy machine, never asserted.

use super::bench::{failed_outcome, first_path_options, median};
use crate::geometry::Pose2;
use crate::motion::manoeuvres::ALL;
use crate::planner::options::bad;
use crate::planner::{self, PlanError, PlanOptions, PlanSummary, Prepared};
use crate::robot::RobotDescription;
use crate::scenario::{MapExtent, Scenario};
use serde::Serialize;
use std::time::Instant;

/// How far start and goal must stay inside a map's border, m: the robot's half length
/// and its cost maps' border band, with room to spare.
pub const BORDER_M: f64 = 1.0;

/// Options of `bench scaling`.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalingOptions {
    /// Sides of the square maps of the area sweep, m.
    pub map_sizes_m: Vec<f64>,
    /// Goal distances of the length sweep, m.
    pub lengths_m: Vec<f64>,
    /// Side of the square map of the length sweep, m.
    pub length_map_m: f64,
    /// Planning time limit of each run, s.
    pub time_limit_s: f64,
    /// Runs of each course; its times are their medians.
    pub repeats: usize,
}

impl Default for ScalingOptions {
    fn default() -> Self {
        Self {
            map_sizes_m: vec![6.0, 12.0, 24.0, 48.0],
            lengths_m: vec![1.0, 2.0, 4.0, 8.0, 16.0],
            length_map_m: 48.0,
            time_limit_s: 60.0,
            repeats: 3,
        }
    }
}

/// One course of `bench scaling`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingRow {
    /// `area` or `length`.
    pub sweep: &'static str,
    /// Side of the square map, m.
    pub map_m: f64,
    /// Cells of the map.
    pub cells: usize,
    /// Straight-line distance from start to goal, m.
    pub length_m: f64,
    /// `path`, `no_path` or `time_limit` (of the last repeat).
    pub outcome: &'static str,
    /// Median wall time of the whole plan, s.
    pub time_s: f64,
    /// Median time of the height and cost maps, s.
    pub maps_s: f64,
    /// Median time of the heuristic's tables (step bound, regions, way), s.
    pub heuristic_setup_s: f64,
    /// Median time of the search (with the lazy cost-to-go it drives), s.
    pub search_s: f64,
    /// (Cell, orientation) nodes the cost-to-go settled (last repeat).
    pub cost_to_go_nodes: usize,
    /// Expansions of the search (last repeat).
    pub expansions: u64,
    /// The path's cost, when one was found.
    pub cost: Option<f64>,
    /// Median search time of the warm replan from the path's middle pose, s (`None`
    /// without a path, or where that pose cannot start a plan).
    pub warm_replan_s: Option<f64>,
    /// Expansions of the warm replan (last repeat).
    pub warm_replan_expansions: Option<u64>,
}

/// Result of `bench scaling`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingBench {
    /// The course's scenario.
    pub scenario: String,
    /// Runs of each course.
    pub repeats: usize,
    /// The area sweep's rows, smallest map first, then the length sweep's, shortest
    /// course first.
    pub rows: Vec<ScalingRow>,
    /// Time on the largest map over time on the smallest (`None` with fewer than two).
    pub area_ratio: Option<f64>,
    /// Time of the longest course over time of the shortest (`None` with fewer than two).
    pub length_ratio: Option<f64>,
}

/// The scenario's course on a square map of side `side` centred on the midpoint of its
/// start and goal.
///
/// # Errors
/// `map_sizes` when start or goal would lie within [`BORDER_M`] of the border.
pub fn on_square_map(base: &Scenario, side: f64) -> Result<Scenario, PlanError> {
    let centre = [(base.start.x + base.goal.x) / 2.0, (base.start.y + base.goal.y) / 2.0];
    let mut sc = base.clone();
    sc.map = square(centre, side);
    sc.name = format!("{}_map{side}m", base.name);
    inside("map_sizes", &sc, side)?;
    Ok(sc)
}

/// The scenario on a square map of side `side` centred on its start, the goal `length`
/// straight ahead of the start, facing the start's way.
///
/// # Errors
/// `lengths` when the goal would lie within [`BORDER_M`] of the border.
pub fn straight_course(base: &Scenario, side: f64, length: f64) -> Result<Scenario, PlanError> {
    let s = base.start;
    let mut sc = base.clone();
    sc.map = square([s.x, s.y], side);
    sc.goal =
        Pose2 { x: s.x + length * s.theta.cos(), y: s.y + length * s.theta.sin(), theta: s.theta };
    sc.name = format!("{}_straight{length}m", base.name);
    inside("lengths", &sc, side)?;
    Ok(sc)
}

fn square(centre: [f64; 2], side: f64) -> MapExtent {
    let h = side / 2.0;
    MapExtent {
        x_min: centre[0] - h,
        x_max: centre[0] + h,
        y_min: centre[1] - h,
        y_max: centre[1] + h,
    }
}

fn inside(option: &'static str, sc: &Scenario, side: f64) -> Result<(), PlanError> {
    let m = &sc.map;
    let shrunk = MapExtent {
        x_min: m.x_min + BORDER_M,
        x_max: m.x_max - BORDER_M,
        y_min: m.y_min + BORDER_M,
        y_max: m.y_max - BORDER_M,
    };
    for (what, p) in [("start", sc.start), ("goal", sc.goal)] {
        if !(side.is_finite() && shrunk.contains(p.x, p.y)) {
            return Err(bad(
                option,
                format!(
                    "on a {side} m map the {what} ({:.2}, {:.2}) lies within {BORDER_M} m of the border",
                    p.x, p.y
                ),
            ));
        }
    }
    Ok(())
}

/// Runs both sweeps of `base`'s course, `opts.repeats` times each course, one run at a
/// time; `on_row` hears of each row as it is done, with how many are and how many
/// there will be.
///
/// # Errors
/// `opts` out of range (no repeats, a map too small for its course), or a plan that
/// fails for another reason than finding no path.
pub fn scaling_bench(
    base: &Scenario,
    robot: &RobotDescription,
    opts: &ScalingOptions,
    on_row: &mut dyn FnMut(usize, usize, &ScalingRow),
) -> Result<ScalingBench, PlanError> {
    if opts.repeats == 0 {
        return Err(bad("repeats", "0 must be at least 1"));
    }
    let mut courses = Vec::new();
    for &side in &opts.map_sizes_m {
        courses.push(("area", side, on_square_map(base, side)?));
    }
    for &length in &opts.lengths_m {
        if !(length.is_finite() && length > 0.0) {
            return Err(bad("lengths", format!("{length} must be a positive distance")));
        }
        courses.push((
            "length",
            opts.length_map_m,
            straight_course(base, opts.length_map_m, length)?,
        ));
    }
    let plan_opts = first_path_options(opts.time_limit_s);
    let total = courses.len();
    let mut rows = Vec::with_capacity(total);
    for (sweep, side, sc) in courses {
        let mut times = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        let mut warm_times = Vec::new();
        let (mut last, mut last_warm) = (None, None);
        let mut outcome = "path";
        for _ in 0..opts.repeats {
            let t = Instant::now();
            let prepared = planner::prepare_for(&sc, robot, &plan_opts, &ALL);
            let result = prepared
                .and_then(|prep| Ok((planner::run_on(&prep, &sc, robot, &plan_opts)?, prep)));
            let wall = t.elapsed().as_secs_f64();
            match result {
                Ok((s, mut prep)) => {
                    let parts = [wall, s.setup_time_s, s.heuristic.setup_time_s, s.planning_time_s];
                    for (v, p) in times.iter_mut().zip(parts) {
                        v.push(p);
                    }
                    last_warm = warm_replan(&mut prep, &sc, robot, &plan_opts, &s);
                    if let Some(w) = &last_warm {
                        warm_times.push(w.planning_time_s);
                    }
                    outcome = "path";
                    last = Some(s);
                }
                Err(e) => {
                    outcome = failed_outcome(e)?;
                    times[0].push(wall);
                    last = None;
                }
            }
        }
        let med = |k: usize| if times[k].is_empty() { 0.0 } else { median(times[k].clone()) };
        let cells = last.as_ref().map_or(0, |s| s.map.nx * s.map.ny);
        rows.push(ScalingRow {
            sweep,
            map_m: side,
            cells,
            length_m: (sc.goal.x - sc.start.x).hypot(sc.goal.y - sc.start.y),
            outcome,
            time_s: med(0),
            maps_s: med(1),
            heuristic_setup_s: med(2),
            search_s: med(3),
            cost_to_go_nodes: last.as_ref().map_or(0, |s| s.heuristic.cost_to_go_nodes),
            expansions: last.as_ref().map_or(0, |s| s.expansions),
            cost: last.as_ref().map(|s| s.cost),
            warm_replan_s: (!warm_times.is_empty()).then(|| median(warm_times)),
            warm_replan_expansions: last_warm.as_ref().map(|w| w.expansions),
        });
        if let Some(r) = rows.last() {
            on_row(rows.len(), total, r);
        }
    }
    let ratio = |sweep: &str| {
        let times: Vec<f64> = rows.iter().filter(|r| r.sweep == sweep).map(|r| r.time_s).collect();
        match (times.first(), times.last()) {
            (Some(a), Some(b)) if times.len() > 1 && *a > 0.0 => Some(b / a),
            _ => None,
        }
    };
    Ok(ScalingBench {
        scenario: base.name.clone(),
        repeats: opts.repeats,
        area_ratio: ratio("area"),
        length_ratio: ratio("length"),
        rows,
    })
}

/// The warm replan of a row: `prep`'s start moved to the middle pose of `cold`'s path
/// and the first path planned again, on the tables `cold` left. `None` where that pose
/// cannot start a plan or the replan fails (the row then reports no replan).
fn warm_replan(
    prep: &mut Prepared,
    sc: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    cold: &PlanSummary,
) -> Option<PlanSummary> {
    let middle = cold.path.get(cold.path.len() / 2)?.pose;
    prep.set_start(sc, robot, middle).ok()?;
    planner::run_on(prep, sc, robot, opts).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat() -> Scenario {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/flat.toml");
        Scenario::load(&path).expect("flat loads")
    }

    #[test]
    fn a_square_map_is_centred_on_the_course() {
        // flat: start (0, 0), goal (-1.5, 1.2): the midpoint (-0.75, 0.6).
        let sc = on_square_map(&flat(), 12.0).expect("fits");
        let m = sc.map;
        assert_eq!([m.x_min, m.x_max, m.y_min, m.y_max], [-6.75, 5.25, -5.4, 6.6]);
        assert_eq!((sc.start, sc.goal), (flat().start, flat().goal));
        // 4 m: the goal 1.2 - 0.6 = 0.6 m from the midpoint, 2 - 0.6 = 1.4 m from the
        // border; 3 m leaves 0.9 m, inside the 1 m border band.
        assert!(on_square_map(&flat(), 4.0).is_ok());
        let e = on_square_map(&flat(), 3.0).expect_err("too small");
        assert!(e.to_string().contains("map_sizes"), "{e}");
    }

    #[test]
    fn a_straight_course_runs_ahead_of_the_start() {
        let mut base = flat();
        base.start.theta = std::f64::consts::FRAC_PI_2;
        let sc = straight_course(&base, 10.0, 3.0).expect("fits");
        assert!((sc.goal.x - 0.0).abs() < 1e-12 && (sc.goal.y - 3.0).abs() < 1e-12);
        assert_eq!(sc.goal.theta, base.start.theta);
        assert_eq!([sc.map.x_min, sc.map.y_max], [-5.0, 5.0]);
        // 4.5 m ahead on a 10 m map: 0.5 m from the border.
        assert!(straight_course(&base, 10.0, 4.5).is_err());
    }

    #[test]
    fn bad_options_are_named() {
        let robot = RobotDescription::reference();
        let none = ScalingOptions { repeats: 0, ..ScalingOptions::default() };
        let e = scaling_bench(&flat(), &robot, &none, &mut |_, _, _| {}).expect_err("repeats");
        assert!(e.to_string().contains("repeats"), "{e}");
        let nan = ScalingOptions { map_sizes_m: vec![f64::NAN], ..ScalingOptions::default() };
        let e = scaling_bench(&flat(), &robot, &nan, &mut |_, _, _| {}).expect_err("NaN");
        assert!(e.to_string().contains("map_sizes"), "{e}");
        let back = ScalingOptions {
            map_sizes_m: vec![],
            lengths_m: vec![-1.0],
            ..ScalingOptions::default()
        };
        let e = scaling_bench(&flat(), &robot, &back, &mut |_, _, _| {}).expect_err("negative");
        assert!(e.to_string().contains("lengths"), "{e}");
    }
}
