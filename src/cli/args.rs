//! The command line's arguments: clap's definitions of every command and its options
//! (the help text users read is here), and the parsers of their compound values.

use crate::control::wheels::Twist;
use crate::scenario::generate::Class;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// Closed-loop simulator of hybrid driving-stepping locomotion for Momaro (Klamt & Behnke,
/// IROS 2017).
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
    Sim(SimArgs),
    /// Build the height map and the paper's cost layers (foot, body, pose cost) of a scenario.
    Costmap(CostmapArgs),
    /// Measure speed (medians over repeats; never asserted in tests).
    #[command(subcommand)]
    Bench(BenchCommand),
    /// What the robot can do, swept in closed loop.
    #[command(subcommand)]
    Envelope(EnvelopeCommand),
    /// Plan a hybrid driving-stepping path for a scenario (A* or anytime ARA*).
    Plan(PlanArgs),
    /// Plan, then execute the plan in closed loop in MuJoCo; exit 0 only if the scenario's
    /// expectations hold.
    Run(RunArgs),
    /// Run a suite of scenarios in closed loop on worker threads and print a table of
    /// results with totals per class; exit 0 if all pass, 1 if any fails, 2 if any is
    /// invalid.
    Check(CheckArgs),
    /// Write seeded random scenarios (eight classes of course) into a directory; each is
    /// checked to load and to let the robot stand at its start and goal.
    Generate(GenerateArgs),
    /// Write the URDF of the robot, generated from the MJCF model.
    Urdf(UrdfArgs),
}

/// The arguments of `momaro sim`.
#[derive(Debug, Args)]
pub struct SimArgs {
    /// Scenario file (scenarios/*.toml).
    pub scenario: PathBuf,
    /// Simulated duration, s.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub duration: f64,
    /// Constant body velocity command in the robot frame: vx,vy,wz (m/s, m/s, rad/s).
    #[arg(long, value_name = "VX,VY,WZ", value_parser = parse_twist, allow_hyphen_values = true)]
    pub drive: Option<Twist>,
    /// Write a Rerun recording.
    #[arg(long, value_name = "FILE.rrd")]
    pub rerun: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The arguments of `momaro costmap`.
#[derive(Debug, Args)]
pub struct CostmapArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Write PNG images of the layers into this directory.
    #[arg(long, value_name = "DIR")]
    pub png: Option<PathBuf>,
    /// Use the height map the robot's laser senses in MuJoCo, not the rasterised one.
    #[arg(long)]
    pub sensed: bool,
    /// Write a Rerun recording.
    #[arg(long, value_name = "FILE.rrd")]
    pub rerun: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The arguments of `momaro plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    #[command(flatten)]
    pub planner: PlannerArgs,
    /// Write a Rerun recording of the maps and the path.
    #[arg(long, value_name = "FILE.rrd")]
    pub rerun: Option<PathBuf>,
    /// Write a PNG of where the search went: expansions per base cell over the height
    /// map (log scale, dark blue to magenta), also when it finds no path.
    #[arg(long, value_name = "FILE.png")]
    pub expansions: Option<PathBuf>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    /// Expand the path into stable keyframes (step motion generation, Sec. VI).
    #[arg(long)]
    pub detailed: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The arguments of `momaro run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    #[command(flatten)]
    pub planner: PlannerArgs,
    /// Noise on the measured base pose: position std (m), yaw std (degrees), seed.
    #[arg(long, value_name = "POS_M,YAW_DEG,SEED", value_parser = parse_noise)]
    pub noise: Option<crate::closed_loop::PoseNoise>,
    /// Write a Rerun recording.
    #[arg(long, value_name = "FILE.rrd")]
    pub rerun: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The arguments of `momaro check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scenario files or directories (every *.toml below them, recursively); sorted
    /// and de-duplicated. Default: every scenarios/*.toml of the repository.
    #[arg(value_name = "PATH")]
    pub paths: Vec<PathBuf>,
    #[command(flatten)]
    pub planner: PlannerArgs,
    /// Worker threads, each running whole scenarios (default: the available
    /// parallelism). Results do not depend on it.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Run only shard K of N: the files whose 0-based index i in the sorted suite has
    /// i mod N = K-1 (like cargo-nextest's --partition count:K/N). N jobs of a CI
    /// matrix or a cluster job array, K = 1..N, run every file exactly once.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// What fails the command: `all` (any scenario that does not pass) or `safety`
    /// (only a fall, a static violation past its bound, an impossible course not
    /// refused, or an error; goals not reached and plans the motion generator
    /// rejects, which stop the run before the robot moves, are reported, not failed:
    /// for suites of generated courses).
    #[arg(long, value_enum, default_value_t = FailOn::All)]
    pub fail_on: FailOn,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The arguments of `momaro generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Seed of the first case; case i uses SEED + i, so each file is reproducible alone.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Number of cases; without --class they cycle through the classes.
    #[arg(long, default_value_t = 8)]
    pub count: usize,
    /// Directory to write into (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Only this class of course.
    #[arg(long, value_name = "CLASS", value_parser = class_parser())]
    pub class: Option<Class>,
    /// How flights of stairs are written: as `stairs` primitives, or as stacked boxes, a
    /// box per step (the same heights cell for cell, without the label).
    #[arg(long, value_enum, default_value_t = StairsAsArg::Stairs)]
    pub stairs_as: StairsAsArg,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// `generate --stairs-as` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StairsAsArg {
    /// A `stairs` primitive per flight.
    Stairs,
    /// A `box` primitive per step.
    Boxes,
}

/// The arguments of `momaro urdf`.
#[derive(Debug, Args)]
pub struct UrdfArgs {
    /// Output file (default: standard output).
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Planner speed: time to first solution, cost over the optimum, cost after 1 s and 10 s,
    /// time to the optimum, for A* and ARA*.
    Plan(BenchPlanArgs),
    /// Cold first-path time of `plan` (the guided probe, `--schedule-expansions 0`) over a
    /// suite of scenarios, one run at a time: per file the median of the repeats, then
    /// the suite's median, mean and largest.
    Probe(BenchProbeArgs),
    /// Real-time factor of `momaro sim` against a bare mj_step loop on the same world.
    Sim(BenchSimArgs),
    /// Cold first-path time against the map's area (one course on square maps of growing
    /// side) and against the course's length (a straight drive of growing length on one
    /// map): medians of the whole plan and of its parts.
    Scaling(BenchScalingArgs),
}

/// The arguments of `momaro bench scaling`.
#[derive(Debug, Args)]
pub struct BenchScalingArgs {
    /// The course's scenario (its start, goal and terrain). Default: scenarios/flat.toml
    /// of the repository.
    pub scenario: Option<PathBuf>,
    /// Sides of the area sweep's square maps, m, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [6.0, 12.0, 24.0, 48.0])]
    pub map_sizes: Vec<f64>,
    /// Goal distances of the length sweep, m, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 2.0, 4.0, 8.0, 16.0])]
    pub lengths: Vec<f64>,
    /// Side of the length sweep's square map (centred on the start), m.
    #[arg(long, default_value_t = 48.0)]
    pub length_map: f64,
    /// Planning time limit of each run, s.
    #[arg(long, default_value_t = 60.0)]
    pub time_limit: f64,
    #[command(flatten)]
    pub run: BenchRunArgs,
}

/// The arguments of `momaro bench plan`.
#[derive(Debug, Args)]
pub struct BenchPlanArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    /// ARA* time budget, s.
    #[arg(long, default_value_t = 10.0)]
    pub arastar_limit: f64,
    /// Time budget of the A* run that finds the optimum, s.
    #[arg(long, default_value_t = 120.0)]
    pub optimum_limit: f64,
    #[command(flatten)]
    pub run: BenchRunArgs,
}

/// The arguments of `momaro bench probe`.
#[derive(Debug, Args)]
pub struct BenchProbeArgs {
    /// Scenario files or directories (every *.toml below them, recursively); sorted
    /// and de-duplicated. Default: every scenarios/*.toml of the repository.
    pub paths: Vec<PathBuf>,
    /// Planning time limit of each run, s.
    #[arg(long, default_value_t = 10.0)]
    pub time_limit: f64,
    #[command(flatten)]
    pub run: BenchRunArgs,
}

/// The arguments of `momaro bench sim`.
#[derive(Debug, Args)]
pub struct BenchSimArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Simulated duration of each run, s.
    #[arg(long, default_value_t = 60.0)]
    pub duration: f64,
    /// Repeats (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
}

/// The envelopes.
#[derive(Debug, Subcommand)]
pub enum EnvelopeCommand {
    /// Straight flights over rise × tread, up and down, each in closed loop (`check`'s
    /// workers): a table (or JSON) on stdout, the cells' scenarios, `envelope.json` and
    /// the heat map `envelope.png` in OUT. Exit 0 if no cell lost its stability.
    Stairs(EnvelopeStairsArgs),
}

/// The arguments of `momaro envelope stairs`.
#[derive(Debug, Args)]
pub struct EnvelopeStairsArgs {
    /// Rises, m, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [0.10, 0.12, 0.14, 0.16, 0.18, 0.20, 0.22])]
    pub rises: Vec<f64>,
    /// Treads, m, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [0.25, 0.27, 0.30, 0.35, 0.40])]
    pub treads: Vec<f64>,
    /// Steps per flight.
    #[arg(long, default_value_t = 3)]
    pub steps: u32,
    /// Which way: up, down or both.
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "out/envelope")]
    pub out: PathBuf,
    #[command(flatten)]
    pub planner: PlannerArgs,
    /// Worker threads (default: the available parallelism). Results do not depend on
    /// it.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
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
    /// Expansion budget of each plan (replans included): the search stops after N
    /// expansions, reported as the time limit is. With a time limit that never binds it
    /// makes a plan, and a suite's verdicts, independent of the machine and its load.
    #[arg(long, value_name = "N")]
    pub max_expansions: Option<u64>,
    /// Orientation cost factor k12 (default: the scenario's, 2.0).
    #[arg(long, allow_negative_numbers = true)]
    pub k12: Option<f64>,
    /// Step-related cost factor (default: the scenario's, 10.75, calibrated on
    /// ramp_detour and ramp_far).
    #[arg(long, allow_negative_numbers = true)]
    pub step_cost_factor: Option<f64>,
    /// Foot model of the foot cost, for experiments (default: the scenario's `[params]
    /// foot_model`, else chosen from the height map: `wheel_pair`, the wheel pair's
    /// contact footprint at the foot's heading, where it has a flight of steps, and
    /// `paper`, the paper's disc of radius r_F (eq. 2), elsewhere;
    /// `planner::terrain_models`).
    #[arg(long, value_enum)]
    pub foot_model: Option<FootModelArg>,
    /// Which manoeuvres prepare steps, for experiments (default: the scenario's `[params]
    /// step_model`, else chosen from the height map: `stairs`, every manoeuvre where the
    /// terrain calls for it, where it has a flight of four or more steps or one that climbs
    /// more than 0.3 m, and `paper`, the paper's manoeuvres alone, elsewhere;
    /// `planner::terrain_models`).
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
    pub fn options(&self) -> crate::planner::PlanOptions {
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
            max_expansions: self.max_expansions,
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
    /// Runs of each search (`bench plan`), file (`bench probe`) or course (`bench
    /// scaling`); times are their medians.
    #[arg(long, default_value_t = 1)]
    pub repeats: usize,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub model: ModelArgs,
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
