//! The suite commands: `momaro check` (a suite of scenarios in closed loop on worker
//! threads, a table with totals per class) and `momaro envelope stairs` (what the robot
//! climbs).

use super::args::*;
use super::report::*;
use crate::jobs;
use std::path::PathBuf;

/// The repository's scenarios/ directory (the commands' default files).
pub fn repository_scenarios_dir() -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

/// The scenario files of a suite (`check`, `bench probe`): those below `paths`, sorted
/// and de-duplicated, or every scenarios/*.toml of the repository if none is given.
pub fn suite_files(paths: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    if paths.is_empty() {
        jobs::check::repository_scenarios(&repository_scenarios_dir())
    } else {
        jobs::check::discover(paths)
    }
    .map_err(check_error)
}

/// `momaro check`: the suite's rows on stderr as they finish, then the table (or JSON) in
/// the suite's order on stdout.
pub fn check(
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
pub fn workers_or_all(jobs: Option<usize>) -> usize {
    jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// `momaro envelope stairs`: the cells' rows on stderr as they finish, then the table (or
/// JSON) on stdout; `envelope.json` beside the heat map.
pub fn envelope_stairs(opts: jobs::envelope::EnvelopeOptions, json: bool) -> anyhow::Result<bool> {
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

pub fn print_check_table(report: &jobs::check::CheckReport) {
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

/// `momaro check`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn check_cmd(args: CheckArgs) -> anyhow::Result<bool> {
    let CheckArgs { paths, planner, jobs, shard, fail_on, json, model } = args;
    check(&paths, &planner, jobs, shard.as_deref(), fail_on, json, model.model)
}

/// `momaro envelope stairs`.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn envelope_stairs_cmd(args: EnvelopeStairsArgs) -> anyhow::Result<bool> {
    let EnvelopeStairsArgs { rises, treads, steps, direction, out, planner, jobs, json, model } =
        args;
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
