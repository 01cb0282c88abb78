//! The command line: clap definitions and the dispatch to `jobs`. Errors surface here as
//! `anyhow` with context; `main` maps them to exit codes.

use crate::control::wheels::Twist;
use crate::jobs;
use crate::scenario::generate::Class;
use crate::scenario::{Scenario, ScenarioError};
use anyhow::Context as _;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// Prints a line to stdout; a closed pipe (`momaro ... | head`) is not an error worth a
/// panic, so write errors are ignored.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// Closed-loop simulator of hybrid driving-stepping locomotion for Momaro (Klamt & Behnke, IROS 2017).
#[derive(Debug, Parser)]
#[command(name = "momaro", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Options every command that loads the robot shares.
#[derive(Debug, Args)]
pub struct ModelArgs {
    /// Robot model (MJCF).
    #[arg(long, value_name = "FILE", default_value_os_t = crate::sim::default_model_path())]
    pub model: PathBuf,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scenario's world headless with the robot standing, or driving a constant twist.
    Sim {
        /// Scenario file (scenarios/*.toml).
        scenario: PathBuf,
        /// Simulated duration, s.
        #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
        duration: f64,
        /// Constant body velocity command in the robot frame: vx,vy,wz (m/s, m/s, rad/s).
        #[arg(long, value_name = "VX,VY,WZ", value_parser = parse_twist, allow_hyphen_values = true)]
        drive: Option<Twist>,
        /// Write a Rerun recording.
        #[arg(long, value_name = "FILE.rrd")]
        rerun: Option<PathBuf>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Build the height map and the paper's cost layers (foot, body, pose cost) of a scenario.
    Costmap {
        /// Scenario file.
        scenario: PathBuf,
        /// Write PNG images of the layers into this directory.
        #[arg(long, value_name = "DIR")]
        png: Option<PathBuf>,
        /// Use the height map the robot's laser senses in MuJoCo, not the rasterised one.
        #[arg(long)]
        sensed: bool,
        /// Write a Rerun recording.
        #[arg(long, value_name = "FILE.rrd")]
        rerun: Option<PathBuf>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Measure speed (medians over repeats; never asserted in tests).
    #[command(subcommand)]
    Bench(BenchCommand),
    /// What the robot can do, swept in closed loop.
    #[command(subcommand)]
    Envelope(EnvelopeCommand),
    /// Plan a hybrid driving-stepping path for a scenario (A* or anytime ARA*).
    Plan {
        /// Scenario file.
        scenario: PathBuf,
        #[command(flatten)]
        planner: PlannerArgs,
        /// Write a Rerun recording of the maps and the path.
        #[arg(long, value_name = "FILE.rrd")]
        rerun: Option<PathBuf>,
        /// Write a PNG of where the search went: expansions per base cell over the height
        /// map (log scale, dark blue to magenta), also when it finds no path.
        #[arg(long, value_name = "FILE.png")]
        expansions: Option<PathBuf>,
        /// Print the result as JSON.
        #[arg(long)]
        json: bool,
        /// Expand the path into stable keyframes (step motion generation, Sec. VI).
        #[arg(long)]
        detailed: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Plan, then execute the plan in closed loop in MuJoCo; exit 0 only if the scenario's
    /// expectations hold.
    Run {
        /// Scenario file.
        scenario: PathBuf,
        #[command(flatten)]
        planner: PlannerArgs,
        /// Noise on the measured base pose: position std (m), yaw std (degrees), seed.
        #[arg(long, value_name = "POS_M,YAW_DEG,SEED", value_parser = parse_noise)]
        noise: Option<crate::closed_loop::PoseNoise>,
        /// Write a Rerun recording.
        #[arg(long, value_name = "FILE.rrd")]
        rerun: Option<PathBuf>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Run a suite of scenarios in closed loop on worker threads and print a table of
    /// results with totals per class; exit 0 if all pass, 1 if any fails, 2 if any is
    /// invalid.
    Check {
        /// Scenario files or directories (every *.toml below them, recursively); sorted
        /// and de-duplicated. Default: every scenarios/*.toml of the repository.
        #[arg(value_name = "PATH")]
        paths: Vec<PathBuf>,
        #[command(flatten)]
        planner: PlannerArgs,
        /// Worker threads, each running whole scenarios (default: the available
        /// parallelism). Results do not depend on it.
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
        /// Run only shard K of N: the files whose 0-based index i in the sorted suite has
        /// i mod N = K-1 (like cargo-nextest's --partition count:K/N). N jobs of a CI
        /// matrix or a cluster job array, K = 1..N, run every file exactly once.
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
        /// What fails the command: `all` (any scenario that does not pass) or `safety`
        /// (only a fall, a static violation past its bound, an impossible course not
        /// refused, or an error; goals not reached and plans the motion generator
        /// rejects, which stop the run before the robot moves, are reported, not failed:
        /// for suites of generated courses).
        #[arg(long, value_enum, default_value_t = FailOn::All)]
        fail_on: FailOn,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Write seeded random scenarios (eight classes of course) into a directory; each is
    /// checked to load and to let the robot stand at its start and goal.
    Generate {
        /// Seed of the first case; case i uses SEED + i, so each file is reproducible alone.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Number of cases; without --class they cycle through the classes.
        #[arg(long, default_value_t = 8)]
        count: usize,
        /// Directory to write into (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Only this class of course.
        #[arg(long, value_name = "CLASS", value_parser = class_parser())]
        class: Option<Class>,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Write the URDF of the robot, generated from the MJCF model.
    Urdf {
        /// Output file (default: standard output).
        #[arg(long, short)]
        output: Option<PathBuf>,
        #[command(flatten)]
        model: ModelArgs,
    },
}

/// What fails `momaro check`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FailOn {
    /// Any scenario that does not pass.
    All,
    /// Only safety failures (see `check --help`).
    Safety,
}

/// Search algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AlgorithmArg {
    /// Optimal A*.
    Astar,
    /// Anytime Repairing A* (Likhachev et al. 2003).
    Arastar,
}

/// Planner options shared by `plan`, `run` and `check`.
#[derive(Debug, Args)]
pub struct PlannerArgs {
    /// Search algorithm.
    #[arg(long, value_enum, default_value_t = AlgorithmArg::Arastar)]
    pub algorithm: AlgorithmArg,
    /// Planning time limit, s (always held).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub time_limit: f64,
    /// ARA*'s initial heuristic weight (default: the scenario's, 3.0).
    #[arg(long, allow_negative_numbers = true)]
    pub initial_epsilon: Option<f64>,
    /// ARA* stops at a solution with this ε (default 1, the optimum); set it to the
    /// initial ε to take the first solution, the same on any machine.
    #[arg(long, allow_negative_numbers = true)]
    pub final_epsilon: Option<f64>,
    /// ε of ARA*'s greedy probe, searched before the schedule and kept as the answer if
    /// a limit stops the schedule (default: the scenario's, 50); at most the initial ε
    /// turns it off (the paper's ARA*).
    #[arg(long, allow_negative_numbers = true)]
    pub probe_epsilon: Option<f64>,
    /// Order the probe by the admissible heuristic alone, as before its guidance (by
    /// default every other expansion of the probe follows the heuristic without its
    /// base-pose cost-to-go, which misleads beside open-sided stairs, and after 20,000
    /// expansions without a path every third follows that guidance alone, greedily, with
    /// each foot's offset from neutral weighed at a quarter of a metre of the base's way;
    /// for comparisons).
    #[arg(long)]
    pub unguided_probe: bool,
    /// Expansions ARA*'s schedule may spend once the probe has found a path, after which
    /// the probe's path is the answer (default: none for `plan`; 1000000 for `run`,
    /// `check` and `envelope`, so that their plans do not depend on the machine's speed).
    #[arg(long)]
    pub schedule_expansions: Option<u64>,
    /// Orientation cost factor k12 (default: the scenario's, 2.0).
    #[arg(long, allow_negative_numbers = true)]
    pub k12: Option<f64>,
    /// Step-related cost factor (default: the scenario's, 10.75, calibrated on
    /// ramp_detour and ramp_far).
    #[arg(long, allow_negative_numbers = true)]
    pub step_cost_factor: Option<f64>,
    /// Foot model of the foot cost (default: the scenario's `[params] foot_model`; where
    /// it names none, `wheel_pair` on terrain with stairs, else `paper`): `paper`, the
    /// paper's disc of radius r_F (eq. 2), or `wheel_pair`, the wheel pair's contact
    /// footprint at the foot's heading.
    #[arg(long, value_enum)]
    pub foot_model: Option<FootModelArg>,
    /// Which manoeuvres prepare steps (default: the scenario's `[params] step_model`, or
    /// where it names none `stairs` on a flight of four steps or more, else `paper`):
    /// `paper`, the paper's manoeuvres, or `stairs`, which add those a flight longer than
    /// the robot needs.
    #[arg(long, value_enum)]
    pub step_model: Option<StepModelArg>,
}

/// `--foot-model` values (`Params::foot_model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FootModelArg {
    /// The paper's r_F disc (eq. 2).
    Paper,
    /// The wheel pair's footprint at the foot's heading.
    #[value(name = "wheel_pair", alias = "wheel-pair")]
    WheelPair,
}

/// `--step-model` values (`Params::step_model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StepModelArg {
    /// The paper's manoeuvres (Sec. V).
    Paper,
    /// The paper's and those a flight longer than the robot needs.
    Stairs,
}

impl PlannerArgs {
    fn options(&self) -> crate::planner::PlanOptions {
        crate::planner::PlanOptions {
            algorithm: match self.algorithm {
                AlgorithmArg::Astar => crate::search::Algorithm::AStar,
                AlgorithmArg::Arastar => crate::search::Algorithm::AraStar,
            },
            time_limit_s: self.time_limit,
            initial_epsilon: self.initial_epsilon,
            probe_epsilon: self.probe_epsilon,
            probe_guidance: !self.unguided_probe,
            schedule_expansions: self.schedule_expansions,
            final_epsilon: self.final_epsilon,
            overrides: crate::planner::ParamOverrides {
                k12: self.k12,
                step_cost_factor: self.step_cost_factor,
                foot_model: self.foot_model.map(|m| match m {
                    FootModelArg::Paper => crate::params::FootModel::Paper,
                    FootModelArg::WheelPair => crate::params::FootModel::WheelPair,
                }),
                step_model: self.step_model.map(|m| match m {
                    StepModelArg::Paper => crate::params::StepModel::Paper,
                    StepModelArg::Stairs => crate::params::StepModel::Stairs,
                }),
            },
            ..crate::planner::PlanOptions::default()
        }
    }
}

/// What `bench plan` and `bench probe` share.
#[derive(Debug, Args)]
pub struct BenchRunArgs {
    /// Runs of each search (`bench plan`) or file (`bench probe`); times are their medians.
    #[arg(long, default_value_t = 1)]
    repeats: usize,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    model: ModelArgs,
}

/// The benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Planner speed: time to first solution, cost over the optimum, cost after 1 s and 10 s,
    /// time to the optimum, for A* and ARA*.
    Plan {
        /// Scenario file.
        scenario: PathBuf,
        /// ARA* time budget, s.
        #[arg(long, default_value_t = 10.0)]
        arastar_limit: f64,
        /// Time budget of the A* run that finds the optimum, s.
        #[arg(long, default_value_t = 120.0)]
        optimum_limit: f64,
        #[command(flatten)]
        run: BenchRunArgs,
    },
    /// Cold first-path time of `plan` (the guided probe, `--schedule-expansions 0`) over a
    /// suite of scenarios, one run at a time: per file the median of the repeats, then
    /// the suite's median, mean and largest.
    Probe {
        /// Scenario files or directories (every *.toml below them, recursively); sorted
        /// and de-duplicated. Default: every scenarios/*.toml of the repository.
        paths: Vec<PathBuf>,
        /// Planning time limit of each run, s.
        #[arg(long, default_value_t = 10.0)]
        time_limit: f64,
        #[command(flatten)]
        run: BenchRunArgs,
    },
    /// Real-time factor of `momaro sim` against a bare mj_step loop on the same world.
    Sim {
        /// Scenario file.
        scenario: PathBuf,
        /// Simulated duration of each run, s.
        #[arg(long, default_value_t = 60.0)]
        duration: f64,
        /// Repeats (the median is reported).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Print the result as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
}

/// The envelopes.
#[derive(Debug, Subcommand)]
pub enum EnvelopeCommand {
    /// Straight flights over rise × tread, up and down, each in closed loop (`check`'s
    /// workers): a table (or JSON) on stdout, the cells' scenarios, `envelope.json` and
    /// the heat map `envelope.png` in OUT. Exit 0 if no cell lost its stability.
    Stairs {
        /// Rises, m, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [0.10, 0.12, 0.14, 0.16, 0.18, 0.20, 0.22])]
        rises: Vec<f64>,
        /// Treads, m, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [0.25, 0.27, 0.30, 0.35, 0.40])]
        treads: Vec<f64>,
        /// Steps per flight.
        #[arg(long, default_value_t = 3)]
        steps: u32,
        /// Which way: up, down or both.
        #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
        direction: DirectionArg,
        /// Output directory.
        #[arg(long, value_name = "DIR", default_value = "out/envelope")]
        out: PathBuf,
        #[command(flatten)]
        planner: PlannerArgs,
        /// Worker threads (default: the available parallelism). Results do not depend on
        /// it.
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
}

/// `envelope stairs --direction`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DirectionArg {
    /// Climb.
    Up,
    /// Descend.
    Down,
    /// Both.
    Both,
}

/// `--class`: one of the generator's class names (listed by `--help`).
fn class_parser() -> impl clap::builder::TypedValueParser<Value = Class> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(Class::NAMES).try_map(|s| s.parse::<Class>())
}

fn parse_noise(s: &str) -> Result<crate::closed_loop::PoseNoise, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected POS_M,YAW_DEG,SEED, got `{s}`"));
    }
    let num = |p: &str| -> Result<f64, String> {
        p.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| format!("`{p}` is not a finite number >= 0"))
    };
    Ok(crate::closed_loop::PoseNoise {
        position_std_m: num(parts[0])?,
        yaw_std_rad: num(parts[1])?.to_radians(),
        seed: parts[2].parse().map_err(|e| format!("seed `{}`: {e}", parts[2]))?,
    })
}

fn parse_twist(s: &str) -> Result<Twist, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three comma-separated numbers vx,vy,wz, got `{s}`"));
    }
    let mut v = [0.0; 3];
    for (k, p) in parts.iter().enumerate() {
        v[k] = p.parse::<f64>().map_err(|e| format!("`{p}` is not a number: {e}"))?;
        if !v[k].is_finite() {
            return Err(format!("`{p}` is not a finite number"));
        }
    }
    Ok(Twist { vx: v[0], vy: v[1], wz: v[2] })
}

/// Failure classes, for exit codes.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

fn plan_error(e: crate::planner::PlanError) -> anyhow::Error {
    use crate::planner::PlanError as E;
    match e {
        E::BadOption { .. } | E::Params { .. } | E::OffMap { .. } | E::Untraversable { .. } => {
            anyhow::Error::new(BadInput(e.to_string()))
        }
        other => anyhow::Error::new(other),
    }
}

fn run_error(e: crate::closed_loop::RunError) -> anyhow::Error {
    match e {
        crate::closed_loop::RunError::Plan(p) => plan_error(p),
        other => anyhow::Error::new(other),
    }
}

/// The JSON of a run that ended in an error rather than a summary: `run --json` always
/// prints one object, with the failure's kind (`invalid_input` or `error`).
fn error_summary(scenario: &std::path::Path, e: &anyhow::Error) -> serde_json::Value {
    let mut v = failure_object(scenario, e, input_or_error(e));
    if let Some(obj) = v.as_object_mut() {
        obj.insert("passed".into(), false.into());
        obj.insert("reached_goal".into(), false.into());
    }
    v
}

/// `invalid_input` for bad input (exit code 2), else `error`.
fn input_or_error(e: &anyhow::Error) -> &'static str {
    if e.chain().any(|c| c.is::<BadInput>()) { "invalid_input" } else { "error" }
}

/// The scenario, its path, the failure's kind and its message.
fn failure_object(scenario: &std::path::Path, e: &anyhow::Error, kind: &str) -> serde_json::Value {
    serde_json::json!({
        "scenario": scenario.file_stem().map(|s| s.to_string_lossy().into_owned()),
        "path": scenario.display().to_string(),
        "failure_kind": kind,
        "failure": format!("{e:#}"),
    })
}

/// With `--json`, the object `plan` prints when it ends without a plan (stdout stays
/// one JSON object whatever happens, as for `run`): `failure_kind` `no_path`,
/// `planning_time_limit`, `motion_generation` (`--detailed`), `invalid_input` or `error`,
/// and the message in `failure`. The exit code is the error's.
fn print_plan_failure(json: bool, scenario: &std::path::Path, e: &anyhow::Error) {
    if !json {
        return;
    }
    let kind = e.chain().find_map(|c| {
        if let Some(crate::planner::PlanError::NoPath { termination, .. }) = c.downcast_ref() {
            Some(match termination {
                crate::search::Termination::NoPath => "no_path",
                _ => "planning_time_limit",
            })
        } else if let Some(jobs::detailed::DetailedJobError::Motion { .. }) = c.downcast_ref() {
            Some("motion_generation")
        } else {
            None
        }
    });
    let v = failure_object(scenario, e, kind.unwrap_or_else(|| input_or_error(e)));
    // Printing can fail only on a closed stdout, where nobody reads the object.
    let _ = print_json(&v);
}

fn robot(model: &std::path::Path) -> anyhow::Result<crate::robot::RobotDescription> {
    Ok(crate::sim::Simulation::robot_only(model)?.robot().clone())
}

fn check_error(e: jobs::check::CheckError) -> anyhow::Error {
    use jobs::check::CheckError as E;
    match e {
        E::BadShard { .. } | E::NoWorkers | E::Io { .. } | E::EmptyDirectory { .. } => {
            anyhow::Error::new(BadInput(e.to_string()))
        }
        E::Spawn(_) => anyhow::Error::new(e),
    }
}

/// The scenario files of a suite (`check`, `bench probe`): those below `paths`, sorted
/// and de-duplicated, or every scenarios/*.toml of the repository if none is given.
fn suite_files(paths: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    if paths.is_empty() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
        jobs::check::repository_scenarios(&dir)
    } else {
        jobs::check::discover(paths)
    }
    .map_err(check_error)
}

/// `momaro check`: the suite's rows on stderr as they finish, then the table (or JSON) in
/// the suite's order on stdout.
fn check(
    paths: &[PathBuf],
    planner: &PlannerArgs,
    jobs: Option<usize>,
    shard: Option<&str>,
    fail_on: FailOn,
    json: bool,
    model: PathBuf,
) -> anyhow::Result<bool> {
    use jobs::check;
    let shard = shard.map(str::parse::<check::Shard>).transpose().map_err(check_error)?;
    let jobs = workers_or_all(jobs);
    let files = suite_files(paths)?;
    let opts = check::CheckOptions {
        run: crate::closed_loop::RunOptions::new(planner.options(), model),
        jobs,
        shard,
    };
    let width = files.len().to_string().len();
    let report = check::run(&files, &opts, &mut |f| {
        use std::io::Write as _;
        let line = format!(
            "[{:>width$}/{}] {:<24} {:<7} {:>7.1} s  {}",
            f.done,
            f.total,
            f.row.scenario,
            f.row.verdict().to_string(),
            f.row.wall_time_s,
            f.row.failure_kind().unwrap_or("")
        );
        let _ = writeln!(std::io::stderr(), "{}", line.trim_end());
    })
    .map_err(check_error)?;
    if json {
        print_json(&report)?;
    } else {
        print_check_table(&report);
    }
    if report.any_invalid() {
        return Err(anyhow::Error::new(BadInput(format!(
            "{} of {} scenarios are invalid input",
            report.total.invalid, report.total.cases
        ))));
    }
    Ok(match fail_on {
        FailOn::All => report.all_passed(),
        FailOn::Safety => report.safe(),
    })
}

/// `--jobs`, or one worker per available core.
fn workers_or_all(jobs: Option<usize>) -> usize {
    jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// `momaro envelope stairs`: the cells' rows on stderr as they finish, then the table (or
/// JSON) on stdout; `envelope.json` beside the heat map.
fn envelope_stairs(opts: jobs::envelope::EnvelopeOptions, json: bool) -> anyhow::Result<bool> {
    use jobs::envelope::{self, EnvelopeError};
    let report = envelope::run(&opts, &mut |f| {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "[{}/{}] {:<28} {}",
            f.done,
            f.total,
            f.row.scenario,
            envelope::CellVerdict::of(f.row).name()
        );
    })
    .map_err(|e| match e {
        EnvelopeError::BadOption { .. } => anyhow::Error::new(BadInput(e.to_string())),
        EnvelopeError::Check(c) => check_error(c),
        e => anyhow::Error::new(e),
    })?;
    let json_path = opts.out_dir.join("envelope.json");
    std::fs::write(&json_path, serde_json::to_string_pretty(&report)?)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", json_path.display()))?;
    if json {
        print_json(&report)?;
    } else {
        say!("{}", envelope::table(&report));
        say!(
            "heat map: {} (green climbs, grey no path, blue planner limit, orange other",
            report.png.display()
        );
        say!("failure, red unstable; rises bottom to top, treads left to right, one panel per");
        say!("direction); JSON: {}", json_path.display());
    }
    Ok(report.stable_everywhere())
}

fn print_check_table(report: &jobs::check::CheckReport) {
    use jobs::check::RowOutcome;
    let name_w = report.rows.iter().map(|r| r.scenario.len()).max().unwrap_or(0).max(8);
    let class_w = report.classes.keys().map(String::len).max().unwrap_or(0).max(5);
    say!(
        "{:<name_w$}  {:<class_w$}  {:<7}  {:<19}  {:>10}  {:>8}  {:>8}  {:<6}  {:>7}  {:>6}  {:>7}",
        "scenario",
        "class",
        "result",
        "failure",
        "goal err m",
        "margin m",
        "static s",
        "tipped",
        "steps",
        "sim s",
        "wall s"
    );
    for row in &report.rows {
        let head = format!(
            "{:<name_w$}  {:<class_w$}  {:<7}",
            row.scenario,
            row.class_key(),
            row.verdict().to_string()
        );
        match &row.outcome {
            RowOutcome::Ran { summary: s, .. } => {
                let kind = row.failure_kind().unwrap_or("-");
                let margin = if s.min_stability_margin_m.is_finite() {
                    format!("{:.3}", s.min_stability_margin_m)
                } else {
                    "-".to_owned()
                };
                say!(
                    "{head}  {:<19}  {:>10.3}  {:>8}  {:>8.3}  {:<6}  {:>7}  {:>6.1}  {:>7.1}",
                    kind,
                    s.goal_position_error_m,
                    margin,
                    s.static_violation_s,
                    if s.tipped { "yes" } else { "no" },
                    format!("{}/{}", s.steps_executed, s.steps_planned),
                    s.sim_time_s,
                    row.wall_time_s
                );
            }
            RowOutcome::Error { message } | RowOutcome::Invalid { message } => {
                say!("{head}  {message}");
            }
        }
    }
    say!("");
    say!(
        "{:<class_w$}  {:>5}  {:>6}  {:>6}  {:>6}  {:>7}  {:>7}  {:>7}  {:>10}  {:>6}  {:>12}  {:>18}",
        "class",
        "cases",
        "passed",
        "failed",
        "errors",
        "invalid",
        "reached",
        "no path",
        "motion gen",
        "tipped",
        "static > max",
        "impossible planned"
    );
    let line = |name: &str, t: &jobs::check::Totals| {
        say!(
            "{:<class_w$}  {:>5}  {:>6}  {:>6}  {:>6}  {:>7}  {:>7}  {:>7}  {:>10}  {:>6}  {:>12}  {:>18}",
            name,
            t.cases,
            t.passed,
            t.failed,
            t.errors,
            t.invalid,
            t.reached_goal,
            t.no_path,
            t.motion_generation,
            t.tipped,
            t.static_violation_exceeded,
            t.impossible_not_refused
        );
    };
    for (class, t) in &report.classes {
        line(class, t);
    }
    line("total", &report.total);
    say!(
        "{} scenario{}{} on {} worker{} in {:.1} s wall",
        report.total.cases,
        if report.total.cases == 1 { "" } else { "s" },
        report.shard.map_or(String::new(), |s| format!(" (shard {s})")),
        report.jobs,
        if report.jobs == 1 { "" } else { "s" },
        report.wall_time_s
    );
}

fn load(path: &std::path::Path) -> anyhow::Result<Scenario> {
    Scenario::load(path).map_err(|e: ScenarioError| anyhow::Error::new(BadInput(e.to_string())))
}

fn print_json<T: serde::Serialize>(value: &T) -> anyhow::Result<()> {
    say!("{}", serde_json::to_string_pretty(value).context("serialising the summary")?);
    Ok(())
}

/// Runs the parsed command line; returns whether the job's own checks passed.
///
/// # Errors
/// Any failure, with context; a [`BadInput`] in the chain marks invalid input.
pub fn run(cli: Cli) -> anyhow::Result<bool> {
    match cli.command {
        Command::Sim { scenario, duration, drive, rerun, json, model } => {
            let sc = load(&scenario)?;
            let opts = jobs::sim::SimOptions {
                duration_s: duration,
                drive,
                model_path: model.model,
                rerun,
                progress: !json,
            };
            let summary = jobs::sim::run(&sc, &opts).map_err(|e| match e {
                jobs::sim::SimJobError::BadOption { .. } => {
                    anyhow::Error::new(BadInput(e.to_string()))
                }
                other => anyhow::Error::new(other).context(format!("sim {}", scenario.display())),
            })?;
            if json {
                print_json(&summary)?;
            } else {
                let s = &summary;
                say!("scenario            {}", s.scenario);
                say!(
                    "sim time            {:.2} s in {:.2} s wall (x{:.1} real time)",
                    s.sim_time_s,
                    s.wall_time_s,
                    s.real_time_factor
                );
                say!(
                    "base start          x {:.3}  y {:.3}  z {:.3}  yaw {:.1}°",
                    s.base_start[0],
                    s.base_start[1],
                    s.base_start[2],
                    s.base_start[3].to_degrees()
                );
                say!(
                    "base end            x {:.3}  y {:.3}  z {:.3}  yaw {:.1}°",
                    s.base_end[0],
                    s.base_end[1],
                    s.base_end[2],
                    s.base_end[3].to_degrees()
                );
                say!("wheels in contact   min {}", s.min_wheels_in_contact);
                say!("stability margin    min {:.3} m", s.min_stability_margin_m);
                say!("upright             {}", s.upright);
                if !s.body_collisions.is_empty() {
                    say!("body collisions     {}", s.body_collisions.join(", "));
                }
            }
            Ok(summary.upright && summary.body_collisions.is_empty())
        }
        Command::Costmap { scenario, png, sensed, rerun, json, model } => {
            let sc = load(&scenario)?;
            let opts = jobs::costmap::CostmapOptions {
                sensed,
                png_dir: png,
                rerun,
                model_path: model.model,
            };
            let s = jobs::costmap::run(&sc, &opts)
                .with_context(|| format!("costmap {}", scenario.display()))?;
            if json {
                print_json(&s)?;
            } else {
                say!("scenario            {} ({} height map)", s.scenario, s.source);
                say!(
                    "map                 {} x {} cells of {} m from ({}, {})",
                    s.cells[0],
                    s.cells[1],
                    s.resolution_m,
                    s.origin[0],
                    s.origin[1]
                );
                say!(
                    "build time          height map {:.1} ms, cost layers {:.1} ms",
                    s.height_map_time_s * 1e3,
                    s.cost_maps_time_s * 1e3
                );
                say!(
                    "foot cost cells     {} infinite, {} unknown",
                    s.infinite_foot_cells,
                    s.unknown_foot_cells
                );
                if let Some(sensed) = &s.sensed {
                    say!(
                        "laser               {} rays, {} cells seen, max error on flat cells {:.4} m, {} violations",
                        sensed.rays,
                        sensed.seen_cells,
                        sensed.agreement.max_uniform_error_m,
                        sensed.agreement.violations
                    );
                }
                for img in &s.images {
                    say!("wrote               {}", img.display());
                }
            }
            Ok(true)
        }
        Command::Plan { scenario, planner, rerun, expansions, json, detailed: true, model } => {
            let opts = planner.options();
            let d = load(&scenario)
                .and_then(|sc| {
                    let mut sim = crate::sim::Simulation::robot_only(&model.model)?;
                    let image = expansions.as_deref();
                    let d =
                        jobs::detailed::run(&sc, &mut sim, &opts, image).map_err(|e| match e {
                            jobs::detailed::DetailedJobError::Plan(p) => plan_error(p),
                            other => anyhow::Error::new(other),
                        })?;
                    Ok((sc, d))
                })
                .inspect_err(|e| print_plan_failure(json, &scenario, e));
            let (sc, d) = d?;
            if let Some(path) = rerun {
                jobs::detailed::record(&sc, &d, &path)
                    .with_context(|| format!("recording {}", path.display()))?;
            }
            if json {
                print_json(&d)?;
            } else {
                let k = &d.detailed;
                say!("scenario            {} ({})", d.plan.scenario, d.plan.algorithm);
                say!("path                {} poses, {} steps", d.plan.path.len(), d.plan.steps);
                say!("keyframes           {} over {:.1} s", k.keyframes.len(), k.duration_s);
                say!(
                    "min margin          {:.3} m (keyframes {:.3} m, three contacts {:.3} m)",
                    k.min_margin_m,
                    k.min_keyframe_margin_m,
                    k.min_three_contact_margin_m
                );
                say!("postures checked    {}", k.samples_checked);
            }
            Ok(true)
        }
        Command::Plan { scenario, planner, rerun, expansions, json, detailed: false, model } => {
            let opts = planner.options();
            let planned = load(&scenario)
                .and_then(|sc| {
                    let robot = robot(&model.model)?;
                    let image = expansions.as_deref();
                    let summary =
                        jobs::plan::run(&sc, &robot, &opts, image).map_err(|e| match e {
                            jobs::plan::PlanJobError::Plan(p) => plan_error(p),
                            other => anyhow::Error::new(other),
                        })?;
                    Ok((sc, robot, summary))
                })
                .inspect_err(|e| print_plan_failure(json, &scenario, e));
            let (sc, robot, summary) = planned?;
            if let Some(path) = rerun {
                jobs::plan_recording::record(&sc, &robot, &summary, &path)
                    .with_context(|| format!("recording {}", path.display()))?;
            }
            if json {
                print_json(&summary)?;
            } else {
                say!("scenario            {} ({})", summary.scenario, summary.algorithm);
                for s in &summary.solutions {
                    say!(
                        "solution            ε {:.3}  cost {:.3}  {:.1} ms  {} expansions",
                        s.epsilon,
                        s.cost,
                        s.time_s * 1e3,
                        s.expansions
                    );
                }
                say!(
                    "path                {} poses, {} steps, cost {:.3}",
                    summary.path.len(),
                    summary.steps,
                    summary.cost
                );
                say!(
                    "planning            {:.1} ms ({})",
                    summary.planning_time_s * 1e3,
                    summary.termination
                );
            }
            Ok(true)
        }
        Command::Run { scenario, planner, noise, rerun, json, model } => {
            let opts = crate::closed_loop::RunOptions {
                rerun,
                progress: !json,
                noise,
                ..crate::closed_loop::RunOptions::new(planner.options(), model.model)
            };
            let s = match load(&scenario)
                .and_then(|sc| jobs::run::run(&sc, &opts).map_err(run_error))
            {
                Ok(s) => s,
                Err(e) => {
                    if json {
                        print_json(&error_summary(&scenario, &e))?;
                    }
                    return Err(e);
                }
            };
            if json {
                print_json(&s)?;
            } else {
                say!("scenario            {}", s.scenario);
                say!("result              {}", if s.passed { "PASS" } else { "FAIL" });
                say!(
                    "plan                cost {:.3}, {} steps, {:.1} ms",
                    s.plan_cost,
                    s.plan_steps,
                    s.planning_time_s * 1e3
                );
                say!(
                    "goal error          {:.3} m, {:.1}°",
                    s.goal_position_error_m,
                    s.goal_heading_error_rad.to_degrees()
                );
                say!("stability margin    min {:.3} m", s.min_stability_margin_m);
                say!(
                    "steps               {} of {} executed, {} aborted, {} replans",
                    s.steps_executed,
                    s.steps_planned,
                    s.steps_aborted,
                    s.replans
                );
                if let Some(f) = &s.failure {
                    say!("stopped             {f}");
                }
                if s.static_violation_s > 0.0 {
                    say!(
                        "static violations   {:.3} s, worst {:.3} m",
                        s.static_violation_s,
                        s.worst_static_violation_m
                    );
                }
                say!(
                    "tracking error      max {:.3} m, mean {:.3} m",
                    s.max_tracking_error_m,
                    s.mean_tracking_error_m
                );
                say!(
                    "sim time            {:.1} s in {:.1} s wall (x{:.1} real time)",
                    s.sim_time_s,
                    s.wall_time_s,
                    s.real_time_factor
                );
                for e in &s.expectations {
                    say!(
                        "  {} {:<22} {}",
                        if e.passed { "ok  " } else { "FAIL" },
                        e.name,
                        e.detail
                    );
                }
            }
            Ok(s.passed)
        }
        Command::Check { paths, planner, jobs, shard, fail_on, json, model } => {
            check(&paths, &planner, jobs, shard.as_deref(), fail_on, json, model.model)
        }
        Command::Envelope(EnvelopeCommand::Stairs {
            rises,
            treads,
            steps,
            direction,
            out,
            planner,
            jobs,
            json,
            model,
        }) => {
            use jobs::envelope::{Direction, EnvelopeOptions};
            let directions = match direction {
                DirectionArg::Up => vec![Direction::Up],
                DirectionArg::Down => vec![Direction::Down],
                DirectionArg::Both => vec![Direction::Up, Direction::Down],
            };
            let workers = workers_or_all(jobs);
            // ARA*'s first solution unless asked otherwise: the same plan on any machine.
            let mut plan = planner.options();
            plan.final_epsilon = plan.final_epsilon.or(plan.initial_epsilon).or(Some(3.0));
            let opts = EnvelopeOptions {
                rises_m: rises,
                treads_m: treads,
                steps,
                directions,
                out_dir: out,
                check: jobs::check::CheckOptions {
                    run: crate::closed_loop::RunOptions::new(plan, model.model),
                    jobs: workers,
                    shard: None,
                },
            };
            envelope_stairs(opts, json)
        }
        Command::Bench(BenchCommand::Plan {
            scenario,
            arastar_limit,
            optimum_limit,
            run: BenchRunArgs { repeats, json, model },
        }) => {
            let sc = load(&scenario)?;
            let opts = jobs::bench::BenchOptions {
                arastar_time_limit_s: arastar_limit,
                optimum_time_limit_s: optimum_limit,
                repeats,
                ..Default::default()
            };
            let report =
                jobs::bench::bench(&sc, &robot(&model.model)?, &opts).map_err(plan_error)?;
            if json {
                print_json(&report)?;
            } else {
                let pct = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.1} %"));
                let ms =
                    |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{:.1} ms", v * 1e3));
                let c = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.3}"));
                say!(
                    "scenario {} (setup {:.1} ms; times are medians of {})",
                    report.scenario,
                    report.setup_time_s * 1e3,
                    opts.repeats
                );
                say!(
                    "{:<13} {:<5} {:>10} {:>12} {:>10} {:>10} {:>7} {:>10} {:>10} {:>12} {:>10} {:>10}",
                    "algo",
                    "nbhd",
                    "optimum",
                    "first",
                    "warm first",
                    "over opt",
                    "bound",
                    "cost@1s",
                    "cost@10s",
                    "to optimum",
                    "first exp",
                    "h setup"
                );
                for r in &report.rows {
                    say!(
                        "{:<13} {:<5} {:>10} {:>12} {:>10} {:>10} {:>7} {:>10} {:>10} {:>12} {:>10} {:>10}",
                        r.algorithm,
                        r.neighbourhood,
                        c(r.optimum),
                        ms(r.first_solution_s),
                        ms(r.first_solution_warm_s),
                        pct(r.first_over_optimum_pct),
                        r.first_bound.map_or("-".to_owned(), |b| format!("{b:.2}")),
                        c(r.cost_at_1s),
                        c(r.cost_at_10s),
                        ms(r.time_to_optimum_s),
                        r.first_expansions.map_or("-".to_owned(), |e| e.to_string()),
                        ms(Some(r.heuristic_setup_s))
                    );
                }
            }
            Ok(true)
        }
        Command::Bench(BenchCommand::Probe {
            paths,
            time_limit,
            run: BenchRunArgs { repeats, json, model },
        }) => {
            let scenarios =
                suite_files(&paths)?.iter().map(|f| load(f)).collect::<anyhow::Result<Vec<_>>>()?;
            let opts = jobs::bench::ProbeBenchOptions { time_limit_s: time_limit, repeats };
            let (total, width) = (scenarios.len(), scenarios.len().to_string().len());
            let b = jobs::bench::probe_bench(
                &scenarios,
                &robot(&model.model)?,
                &opts,
                &mut |done, r| {
                    use std::io::Write as _;
                    let _ = writeln!(
                        std::io::stderr(),
                        "[{done:>width$}/{total}] {:<24} {:<10} {:>8.1} ms",
                        r.scenario,
                        r.outcome,
                        r.time_s * 1e3
                    );
                },
            )
            .map_err(plan_error)?;
            if json {
                print_json(&b)?;
            } else {
                let ms = |v: Option<f64>| v.map_or("-".to_owned(), |t| format!("{:.1}", t * 1e3));
                say!(
                    "{:<28} {:<10} {:>10} {:>10} {:>11} {:>12}",
                    "scenario",
                    "outcome",
                    "wall ms",
                    "search ms",
                    "expansions",
                    "cost"
                );
                for r in &b.rows {
                    say!(
                        "{:<28} {:<10} {:>10.1} {:>10} {:>11} {:>12}",
                        r.scenario,
                        r.outcome,
                        r.time_s * 1e3,
                        ms(r.search_s),
                        r.expansions.map_or("-".to_owned(), |e| e.to_string()),
                        r.cost.map_or("-".to_owned(), |c| format!("{c:.3}"))
                    );
                }
                say!(
                    "{} files, {} with a path (median of {} runs each): wall median {:.1} ms, mean {:.1} ms, largest {:.1} ms; search median {} ms",
                    b.rows.len(),
                    b.paths,
                    b.repeats,
                    b.median_s * 1e3,
                    b.mean_s * 1e3,
                    b.max_s * 1e3,
                    ms(b.median_search_s)
                );
            }
            Ok(true)
        }
        Command::Bench(BenchCommand::Sim { scenario, duration, repeats, json, model }) => {
            let sc = load(&scenario)?;
            let opts = jobs::sim::SimOptions {
                duration_s: duration,
                drive: None,
                model_path: model.model,
                rerun: None,
                progress: false,
            };
            let b = jobs::bench::sim_bench(&sc, &opts, repeats)
                .with_context(|| format!("bench sim {}", scenario.display()))?;
            if json {
                print_json(&b)?;
            } else {
                say!(
                    "scenario            {} ({} s simulated, {} steps, median of {})",
                    b.scenario,
                    b.sim_time_s,
                    b.steps,
                    b.repeats
                );
                say!(
                    "bare mj_step loop   x{:.1} real time ({:.2} µs/step)",
                    b.bare_real_time_factor,
                    b.bare_step_us
                );
                say!(
                    "momaro sim          x{:.1} real time ({:.2} µs/step)",
                    b.controlled_real_time_factor,
                    b.controlled_step_us
                );
                say!("controller+monitor  {:.1} % of a step", b.overhead_fraction * 100.0);
            }
            Ok(true)
        }
        Command::Generate { seed, count, out, class, json, model } => {
            let opts = jobs::generate::GenerateOptions { seed, count, out_dir: out, class };
            if count == 0 {
                // Before the model loads: bad input is reported as such even without it.
                return Err(anyhow::Error::new(BadInput(
                    "invalid option `count`: must be at least 1".into(),
                )));
            }
            let summary =
                jobs::generate::run(&opts, &robot(&model.model)?).map_err(|e| match e {
                    jobs::generate::GenerateJobError::BadOption { .. } => {
                        anyhow::Error::new(BadInput(e.to_string()))
                    }
                    other => anyhow::Error::new(other).context("generate"),
                })?;
            if json {
                print_json(&summary)?;
            } else {
                for f in &summary.files {
                    say!("wrote {}  {}", f.path.display(), f.description);
                }
                let counts: Vec<String> =
                    summary.per_class.iter().map(|c| format!("{} {}", c.class, c.count)).collect();
                say!(
                    "{} files in {} ({})",
                    summary.files.len(),
                    summary.out_dir.display(),
                    counts.join(", ")
                );
            }
            Ok(true)
        }
        Command::Urdf { output, model } => {
            let sim = crate::sim::Simulation::robot_only(&model.model)?;
            let text = crate::urdf_export::momaro_urdf_string(&sim.urdf_inputs()?)?;
            match output {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("writing {}", path.display()))?,
                None => print!("{text}"),
            }
            Ok(true)
        }
    }
}
