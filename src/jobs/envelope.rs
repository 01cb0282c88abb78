//! `momaro envelope stairs`: what this robot climbs. A sweep of straight flights over rise
//! × tread (at a fixed step count), up and down, each run in closed loop by `check`'s
//! worker pool ([`super::check::run`]), with one verdict per cell: a table, JSON and a PNG
//! heat map.
//!
//! Each cell is a scenario file written to `OUT/scenarios/` (so any cell can be re-run
//! or replayed alone with `momaro run`): a flight of `steps` steps, 1.8 m wide, head-on,
//! from 1 m before the first riser to 1.4 m onto a 3 m landing (up), or the reverse
//! (down), with the stairs models (`[params] step_model = "stairs"`, `foot_model =
//! "wheel_pair"`, as the repository's stairs scenarios and `generate --class stairs`)
//! and the monitor's expectations: goal within 0.1 m and 10°, margin ≥ 2 cm, no fall.
//!
//! Verdicts ([`CellVerdict`]), from the run's summary:
//! - `climbs`: every expectation held;
//! - `unstable`: the robot fell, or its static stability margin went below the bound
//!   (2 cm), or a static violation outlasted its bound: what must be nowhere;
//! - `no_path`: the planner proved that no path exists;
//! - `limit`: the planner found no path within its limits (not a proof);
//! - `fails`: anything else (a plan the generator could not expand, replans used up, the
//!   simulated-time budget, an error).

use super::check::{self, CheckError, CheckOptions, CheckRow, Finished};
use crate::closed_loop::FailureKind;
use crate::render::{ImageError, RgbImage, write_png};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Which way the flights are taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// From the floor up onto the landing.
    Up,
    /// From the landing down to the floor.
    Down,
}

impl Direction {
    /// The name used in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::Up => "up",
            Self::Down => "down",
        }
    }
}

/// The sweep.
#[derive(Debug, Clone)]
pub struct EnvelopeOptions {
    /// Step rises, m.
    pub rises_m: Vec<f64>,
    /// Tread depths, m.
    pub treads_m: Vec<f64>,
    /// Steps per flight.
    pub steps: u32,
    /// Directions swept.
    pub directions: Vec<Direction>,
    /// Output directory: `scenarios/`, `envelope.json`, `envelope.png`.
    pub out_dir: PathBuf,
    /// How every cell runs (planner options, workers).
    pub check: CheckOptions,
}

/// Why a sweep could not run.
#[derive(Debug, thiserror::Error)]
pub enum EnvelopeError {
    /// A rise, tread or step count outside what a staircase can be.
    #[error("{field} = {value}: {reason}")]
    BadOption {
        /// The option.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// Writing a file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The suite could not run.
    #[error(transparent)]
    Check(#[from] CheckError),
    /// The heat map could not be written.
    #[error(transparent)]
    Image(#[from] ImageError),
}

/// One cell's verdict (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CellVerdict {
    /// Every expectation held.
    Climbs,
    /// A fall, or the stability margin below its bound.
    Unstable,
    /// No path exists (proved by the planner).
    NoPath,
    /// No path within the planner's limits.
    Limit,
    /// Anything else.
    Fails,
}

impl CellVerdict {
    /// The table's word.
    pub fn name(self) -> &'static str {
        match self {
            Self::Climbs => "climbs",
            Self::Unstable => "UNSTABLE",
            Self::NoPath => "no path",
            Self::Limit => "limit",
            Self::Fails => "fails",
        }
    }

    /// The heat map's colour.
    fn rgb(self) -> [u8; 3] {
        match self {
            Self::Climbs => [40, 160, 70],
            Self::Unstable => [210, 30, 30],
            Self::NoPath => [150, 150, 150],
            Self::Limit => [90, 110, 200],
            Self::Fails => [240, 150, 30],
        }
    }

    /// The verdict of one run.
    pub fn of(row: &CheckRow) -> Self {
        let check::RowOutcome::Ran { summary: s, max_static_violation_s } = &row.outcome else {
            return Self::Fails;
        };
        if s.tipped || s.static_violation_s > *max_static_violation_s {
            return Self::Unstable;
        }
        match s.failure_kind {
            // Never executed: no margin to judge.
            Some(FailureKind::NoPath) => return Self::NoPath,
            Some(FailureKind::PlanningTimeLimit) => return Self::Limit,
            _ => {}
        }
        if s.min_stability_margin_m < MIN_MARGIN_M {
            Self::Unstable
        } else if s.passed {
            Self::Climbs
        } else {
            Self::Fails
        }
    }
}

/// One cell of the sweep.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    /// Way taken.
    pub direction: Direction,
    /// Rise, m.
    pub rise_m: f64,
    /// Tread, m.
    pub tread_m: f64,
    /// Steps of the flight.
    pub steps: u32,
    /// The verdict.
    pub verdict: CellVerdict,
    /// The run's smallest static stability margin, m (`None` if it never executed).
    pub min_stability_margin_m: Option<f64>,
    /// Steps executed.
    pub steps_executed: Option<usize>,
    /// Planning time, s.
    pub planning_time_s: Option<f64>,
    /// The cell's scenario file.
    pub scenario: PathBuf,
}

/// The sweep's result.
#[derive(Debug, Clone, Serialize)]
pub struct EnvelopeReport {
    /// Directions swept, in the order of `cells`.
    pub directions: Vec<Direction>,
    /// Rises swept, m (rows of the table and the map, lowest first).
    pub rises_m: Vec<f64>,
    /// Treads swept, m (columns, shortest first).
    pub treads_m: Vec<f64>,
    /// Steps per flight.
    pub steps: u32,
    /// Every cell, direction by direction, rise by rise, tread by tread.
    pub cells: Vec<Cell>,
    /// Wall time of the sweep, s.
    pub wall_time_s: f64,
    /// The heat map.
    pub png: PathBuf,
}

impl EnvelopeReport {
    /// The cell at (direction, rise index, tread index).
    pub fn cell(&self, d: Direction, r: usize, t: usize) -> Option<&Cell> {
        let (nr, nt) = (self.rises_m.len(), self.treads_m.len());
        let p = self.directions.iter().position(|&x| x == d)?;
        (r < nr && t < nt).then(|| self.cells.get((p * nr + r) * nt + t)).flatten()
    }

    /// Whether no cell lost its stability.
    pub fn stable_everywhere(&self) -> bool {
        self.cells.iter().all(|c| c.verdict != CellVerdict::Unstable)
    }
}

/// The margin every cell must keep (its `expect.min_stability_margin_m`), m.
const MIN_MARGIN_M: f64 = 0.02;
/// Landing depth of every flight, m.
const LANDING_M: f64 = 3.0;
/// Start (up) before the first riser, and goal (up) onto the landing, m.
const APPROACH_M: f64 = 1.0;
const ONTO_LANDING_M: f64 = 1.4;

/// The scenario text of one cell.
pub fn cell_toml(direction: Direction, rise: f64, tread: f64, steps: u32) -> String {
    let top = f64::from(steps) * tread;
    let (bottom_x, top_x) = (-APPROACH_M, top + ONTO_LANDING_M);
    let (sx, gx, yaw) = match direction {
        Direction::Up => (bottom_x, top_x, 0.0),
        Direction::Down => (top_x, bottom_x, 180.0),
    };
    let name = cell_name(direction, rise, tread, steps);
    format!(
        "# Written by `momaro envelope stairs`: {steps} steps of {rise:.3} m on {tread:.3} m, {dir}.\n\
         name = \"{name}\"\n\
         description = \"Envelope cell: {steps} steps of {rise:.3} m rise on {tread:.3} m treads, {dir}.\"\n\
         \n[map]\nx_min = -2.0\nx_max = {xmax:.3}\ny_min = -1.5\ny_max = 1.5\n\
         \n[start]\nx = {sx:.3}\ny = 0.0\nyaw_deg = {yaw:.1}\n\
         \n[goal]\nx = {gx:.3}\ny = 0.0\nyaw_deg = {yaw:.1}\n\
         \n[[terrain]]\nkind = \"stairs\"\nstart = [0.0, 0.0]\nwidth = 1.8\nsteps = {steps}\n\
         step_depth = {tread}\nstep_height = {rise}\nlanding_depth = {LANDING_M:.1}\n\
         \n[params]\nstep_model = \"stairs\"\nfoot_model = \"wheel_pair\"\n\
         \n[expect]\noutcome = \"reach\"\ngoal_tolerance_m = 0.1\ngoal_tolerance_deg = 10.0\n\
         stepping = \"required\"\nmin_stability_margin_m = {MIN_MARGIN_M}\ntimeout_s = {timeout:.1}\n",
        dir = direction.name(),
        xmax = top + LANDING_M + 0.3,
        timeout = 300.0 + 150.0 * f64::from(steps),
    )
}

/// The scenario name of one cell: `stairs_up_r170_t290_n3`.
pub fn cell_name(direction: Direction, rise: f64, tread: f64, steps: u32) -> String {
    let mm = |v: f64| (v * 1000.0).round() as i64;
    format!("stairs_{}_r{}_t{}_n{steps}", direction.name(), mm(rise), mm(tread))
}

fn check_options(opts: &EnvelopeOptions) -> Result<(), EnvelopeError> {
    let bad = |field, value, reason| Err(EnvelopeError::BadOption { field, value, reason });
    for &r in &opts.rises_m {
        if !(r.is_finite() && r > 0.0 && r <= 0.5) {
            return bad("rise", r, "must lie in (0, 0.5] m");
        }
    }
    for &t in &opts.treads_m {
        if !(t.is_finite() && (0.1..=2.0).contains(&t)) {
            return bad("tread", t, "must lie in [0.1, 2] m");
        }
    }
    if !(1..=20).contains(&opts.steps) {
        return bad("steps", f64::from(opts.steps), "must be 1 to 20");
    }
    if opts.rises_m.is_empty() || opts.treads_m.is_empty() || opts.directions.is_empty() {
        return bad("rises/treads/directions", 0.0, "need at least one value each");
    }
    Ok(())
}

/// Writes the cells' scenarios to `OUT/scenarios/`, runs them, writes the heat map
/// `OUT/envelope.png` and returns the report (which the command writes as
/// `OUT/envelope.json`); `on_finished` sees each run as it ends.
///
/// # Errors
/// [`EnvelopeError`]: a bad option, a file that cannot be written, a suite that cannot run.
pub fn run(
    opts: &EnvelopeOptions,
    on_finished: &mut dyn FnMut(Finished<'_>),
) -> Result<EnvelopeReport, EnvelopeError> {
    check_options(opts)?;
    let dir = opts.out_dir.join("scenarios");
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| EnvelopeError::Io { path, source }
    };
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    let mut files = Vec::new();
    let mut keys = Vec::new();
    for &d in &opts.directions {
        for &r in &opts.rises_m {
            for &t in &opts.treads_m {
                let path = dir.join(format!("{}.toml", cell_name(d, r, t, opts.steps)));
                std::fs::write(&path, cell_toml(d, r, t, opts.steps)).map_err(io(&path))?;
                files.push(path);
                keys.push((d, r, t));
            }
        }
    }
    let t0 = std::time::Instant::now();
    let report = check::run(&files, &opts.check, on_finished)?;
    let cells: Vec<Cell> = report
        .rows
        .iter()
        .zip(&keys)
        .map(|(row, &(direction, rise_m, tread_m))| {
            let s = row.summary();
            Cell {
                direction,
                rise_m,
                tread_m,
                steps: opts.steps,
                verdict: CellVerdict::of(row),
                min_stability_margin_m: s
                    .filter(|s| s.steps_executed > 0 || s.reached_goal)
                    .map(|s| s.min_stability_margin_m),
                steps_executed: s.map(|s| s.steps_executed),
                planning_time_s: s.map(|s| s.planning_time_s),
                scenario: row.path.clone(),
            }
        })
        .collect();
    let png = opts.out_dir.join("envelope.png");
    let out = EnvelopeReport {
        directions: opts.directions.clone(),
        rises_m: opts.rises_m.clone(),
        treads_m: opts.treads_m.clone(),
        steps: opts.steps,
        cells,
        wall_time_s: t0.elapsed().as_secs_f64(),
        png: png.clone(),
    };
    write_png(&heat_map(&out), &png)?;
    Ok(out)
}

/// Pixels per cell of the heat map, and between panels.
const CELL_PX: usize = 32;
const GAP_PX: usize = 16;

/// The heat map: one panel per direction (left to right, in the order swept), treads
/// left to right (shortest first), rises bottom to top (lowest at the bottom), each cell
/// coloured by its verdict (green climbs, grey no path, blue planner limit, orange other
/// failure, red unstable), with a 1 px white grid.
pub fn heat_map(report: &EnvelopeReport) -> RgbImage {
    let (nr, nt) = (report.rises_m.len(), report.treads_m.len());
    let directions = &report.directions;
    let panels = directions.len().max(1);
    let width = panels * nt * CELL_PX + (panels + 1) * GAP_PX;
    let height = nr * CELL_PX + 2 * GAP_PX;
    let mut pixels = vec![255u8; width * height * 3];
    for (p, &d) in directions.iter().enumerate() {
        let x0 = GAP_PX + p * (nt * CELL_PX + GAP_PX);
        for r in 0..nr {
            for t in 0..nt {
                let rgb = report.cell(d, r, t).map_or([255, 255, 255], |c| c.verdict.rgb());
                let top = GAP_PX + (nr - 1 - r) * CELL_PX;
                for y in top + 1..top + CELL_PX {
                    for x in x0 + t * CELL_PX + 1..x0 + (t + 1) * CELL_PX {
                        let k = (y * width + x) * 3;
                        pixels[k..k + 3].copy_from_slice(&rgb);
                    }
                }
            }
        }
    }
    RgbImage { width: width as u32, height: height as u32, pixels }
}

/// The table: per direction, one row per rise, one column per tread.
pub fn table(report: &EnvelopeReport) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    for &d in &report.directions {
        let _ = writeln!(
            s,
            "{} ({} steps; rise down, tread across; margin in cm)",
            d.name(),
            report.steps
        );
        let _ = write!(s, "{:>12}", "rise \\ tread");
        for t in &report.treads_m {
            let _ = write!(s, " {:>16}", format!("{t:.3} m"));
        }
        let _ = writeln!(s);
        for (r, rise) in report.rises_m.iter().enumerate() {
            let _ = write!(s, "{:>12}", format!("{rise:.3} m"));
            for t in 0..report.treads_m.len() {
                let text = report.cell(d, r, t).map_or("-".to_owned(), |c| {
                    match (c.verdict, c.min_stability_margin_m) {
                        (CellVerdict::Climbs | CellVerdict::Unstable, Some(m)) => {
                            format!("{} {:.1}", c.verdict.name(), m * 100.0)
                        }
                        (v, _) => v.name().to_owned(),
                    }
                });
                let _ = write!(s, " {text:>16}");
            }
            let _ = writeln!(s);
        }
        let _ = writeln!(s);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    #[test]
    fn a_cell_is_a_valid_scenario_both_ways() {
        for d in [Direction::Up, Direction::Down] {
            let text = cell_toml(d, 0.17, 0.29, 3);
            let s = Scenario::parse(&text, Path::new("cell.toml")).expect("parses");
            assert_eq!(s.name, cell_name(d, 0.17, 0.29, 3));
            // 3 × 0.29 = 0.87 m of flight: up from x = −1 to 2.27, down the reverse.
            let (a, b) = if d == Direction::Up { (-1.0, 2.27) } else { (2.27, -1.0) };
            assert!((s.start.x - a).abs() < 1e-9 && (s.goal.x - b).abs() < 1e-9, "{d:?}");
        }
        assert_eq!(cell_name(Direction::Down, 0.17, 0.29, 3), "stairs_down_r170_t290_n3");
    }

    fn report(verdicts: &[CellVerdict]) -> EnvelopeReport {
        // Up then down; 2 rises × 3 treads each.
        let (rises, treads) = (vec![0.1, 0.2], vec![0.25, 0.3, 0.4]);
        let mut cells = Vec::new();
        let mut k = 0;
        for direction in [Direction::Up, Direction::Down] {
            for &rise_m in &rises {
                for &tread_m in &treads {
                    cells.push(Cell {
                        direction,
                        rise_m,
                        tread_m,
                        steps: 3,
                        verdict: verdicts[k],
                        min_stability_margin_m: Some(0.05),
                        steps_executed: Some(12),
                        planning_time_s: Some(1.0),
                        scenario: PathBuf::new(),
                    });
                    k += 1;
                }
            }
        }
        EnvelopeReport {
            directions: vec![Direction::Up, Direction::Down],
            rises_m: rises,
            treads_m: treads,
            steps: 3,
            cells,
            wall_time_s: 0.0,
            png: PathBuf::new(),
        }
    }

    #[test]
    fn the_heat_map_puts_each_cell_where_its_axes_say() {
        use CellVerdict::*;
        let mut v = [Climbs; 12];
        v[5] = NoPath; // up, rise 0.2 (index 1), tread 0.4 (index 2)
        v[6] = Unstable; // down, rise 0.1, tread 0.25
        let r = report(&v);
        assert_eq!(r.cell(Direction::Up, 1, 2).map(|c| c.verdict), Some(NoPath));
        assert_eq!(r.cell(Direction::Down, 0, 0).map(|c| c.verdict), Some(Unstable));
        assert!(r.cell(Direction::Up, 2, 0).is_none());
        assert!(!r.stable_everywhere());
        let img = heat_map(&r);
        // Two panels of 3 × 32 px plus three 16 px gaps; two rows plus two gaps.
        assert_eq!((img.width, img.height), (3 * 16 + 6 * 32, 2 * 32 + 2 * 16));
        let px = |x: usize, y: usize| {
            let k = (y * img.width as usize + x) * 3;
            [img.pixels[k], img.pixels[k + 1], img.pixels[k + 2]]
        };
        // Rise 0.2 is the top row; tread 0.4 the third column of the first panel.
        assert_eq!(px(16 + 2 * 32 + 16, 16 + 16), NoPath.rgb());
        assert_eq!(px(16 + 16, 16 + 16), Climbs.rgb());
        // Rise 0.1, tread 0.25 of the second panel: bottom left.
        assert_eq!(px(16 + 3 * 32 + 16 + 16, 16 + 32 + 16), Unstable.rgb());
        let t = table(&r);
        assert!(
            t.contains("no path") && t.contains("UNSTABLE 5.0") && t.contains("climbs 5.0"),
            "{t}"
        );
    }

    #[test]
    fn bad_sweeps_name_the_option() {
        let opts = |rise: f64, steps: u32| EnvelopeOptions {
            rises_m: vec![rise],
            treads_m: vec![0.3],
            steps,
            directions: vec![Direction::Up],
            out_dir: PathBuf::from("/nonexistent"),
            check: CheckOptions {
                run: crate::closed_loop::RunOptions::new(
                    crate::planner::PlanOptions::default(),
                    PathBuf::from("m.xml"),
                ),
                jobs: 1,
                shard: None,
            },
        };
        let err = |o| run(&o, &mut |_| {}).expect_err("rejected").to_string();
        assert!(err(opts(f64::NAN, 3)).starts_with("rise = NaN"));
        assert!(err(opts(0.17, 0)).starts_with("steps = 0"));
    }
}
