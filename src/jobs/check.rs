//! `momaro check`: a suite of scenarios, each run in closed loop by [`super::run::run`],
//! on a pool of worker threads, with a verdict per scenario and totals per class.
//!
//! The suite is the scenario files named on the command line, directories searched
//! recursively for `*.toml` ([`discover`]), or the repository's `scenarios/*.toml`
//! ([`repository_scenarios`]); de-duplicated and sorted by path. A [`Shard`] `K/N` keeps
//! the files whose 0-based index `i` in that order has `i mod N = K − 1`, like
//! cargo-nextest's `--partition count:K/N`, so a CI matrix or a cluster job array of `N`
//! jobs runs every file exactly once.
//!
//! [`run()`] hands whole scenarios to `jobs` worker threads: each takes the next index from
//! an atomic counter, loads the file and runs it (the worker builds its own
//! `Simulation`, maps and planner; nothing is shared but the options), and sends the row
//! back over a channel. Rows are reported as they finish (for progress) and returned in
//! the input order; a run is deterministic given the planner options (ARA*'s first
//! solution, `final_epsilon` = the initial ε, or else the probe's path where the
//! schedule's cap `run::RUN_SCHEDULE_EXPANSIONS` stops it), so the rows do not depend
//! on the worker count, only their wall-clock fields do, as long as the time limit does
//! not stop a search first.
//!
//! A file that does not load, or that the planner rejects as input (start off the map or
//! on untraversable terrain, invalid options or parameters), is an
//! [`Verdict::Invalid`] row with the message naming the file and field; any other error
//! of a run (or a panic) is a [`Verdict::Error`] row with the error chain. The rest of the
//! suite runs either way.

use super::run;
use crate::closed_loop::{FailureKind, RunError, RunOptions, RunSummary};
use crate::planner::PlanError;
use crate::scenario::Scenario;
use serde::{Serialize, Serializer};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

/// The key of scenarios without a class in [`CheckReport::classes`] (class names are
/// words of `a-z`, `0-9` and `_`, so it cannot clash with one).
pub const NO_CLASS: &str = "-";

/// Why a suite could not be assembled or run.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// A shard specification is malformed or out of range.
    #[error("--shard `{spec}`: {reason}")]
    BadShard {
        /// What was given.
        spec: String,
        /// What is wrong with it.
        reason: String,
    },
    /// Zero worker threads were asked for.
    #[error("--jobs: must be at least 1")]
    NoWorkers,
    /// A directory could not be listed.
    #[error("cannot list scenario directory {path}: {source}")]
    Io {
        /// The directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A directory named as a suite holds no scenario file.
    #[error("no *.toml scenario files below {path}")]
    EmptyDirectory {
        /// The directory.
        path: PathBuf,
    },
    /// A worker thread could not be started.
    #[error("cannot start a worker thread: {0}")]
    Spawn(std::io::Error),
}

/// One of `count` shards of a suite: shard `index` (1-based) takes the files whose 0-based
/// index `i` in the sorted suite satisfies `i mod count = index − 1`. Written `K/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// K, 1-based: 1 ≤ K ≤ N.
    pub index: usize,
    /// N ≥ 1.
    pub count: usize,
}

impl Shard {
    /// Whether the file at 0-based position `i` of the sorted suite belongs to this shard.
    pub fn contains(&self, i: usize) -> bool {
        i % self.count == self.index - 1
    }

    /// The items of the sorted suite `all` that belong to this shard, in order.
    pub fn select<T: Clone>(&self, all: &[T]) -> Vec<T> {
        all.iter().enumerate().filter(|(i, _)| self.contains(*i)).map(|(_, t)| t.clone()).collect()
    }
}

impl FromStr for Shard {
    type Err = CheckError;

    fn from_str(s: &str) -> Result<Self, CheckError> {
        let bad = |reason: &str| CheckError::BadShard { spec: s.to_owned(), reason: reason.into() };
        let (k, n) = s.split_once('/').ok_or_else(|| bad("expected K/N, e.g. 1/4"))?;
        let k: usize = k.trim().parse().map_err(|_| bad("K is not a whole number"))?;
        let n: usize = n.trim().parse().map_err(|_| bad("N is not a whole number"))?;
        if n == 0 {
            return Err(bad("N must be at least 1"));
        }
        if k == 0 || k > n {
            return Err(bad(&format!("K must lie in 1..={n}")));
        }
        Ok(Self { index: k, count: n })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Serialize for Shard {
    /// As `[K, N]`.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        [self.index, self.count].serialize(s)
    }
}

fn is_toml(path: &Path) -> bool {
    path.extension().is_some_and(|x| x == "toml")
}

/// Every `*.toml` file below `dir` (recursively; symbolic links to files are followed,
/// to directories not, so a link cannot make a cycle), appended to `out`.
fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), CheckError> {
    let io = |source| CheckError::Io { path: dir.to_owned(), source };
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let entry = entry.map_err(io)?;
        let path = entry.path();
        let kind = entry.file_type().map_err(io)?;
        if kind.is_dir() {
            walk(&path, out)?;
        } else if is_toml(&path) && (kind.is_file() || path.is_file()) {
            out.push(path);
        }
    }
    Ok(())
}

/// The suite named by `paths`: each a scenario file (taken as given, even if it does not
/// exist or is not `*.toml`: loading it then reports why) or a directory (every `*.toml`
/// below it, recursively). De-duplicated (two spellings of one file count once) and
/// sorted by path.
///
/// # Errors
/// [`CheckError::Io`] if a directory cannot be listed, [`CheckError::EmptyDirectory`] if
/// one holds no `*.toml` file.
pub fn discover(paths: &[PathBuf]) -> Result<Vec<PathBuf>, CheckError> {
    let mut files = Vec::new();
    for p in paths {
        if p.is_dir() {
            let before = files.len();
            walk(p, &mut files)?;
            if files.len() == before {
                return Err(CheckError::EmptyDirectory { path: p.clone() });
            }
        } else {
            files.push(p.clone());
        }
    }
    files.sort();
    let mut seen = BTreeSet::new();
    files.retain(|p| seen.insert(std::fs::canonicalize(p).unwrap_or_else(|_| p.clone())));
    Ok(files)
}

/// The `*.toml` files directly in `dir` (not below it), sorted: the default suite, the
/// repository's `scenarios/`.
///
/// # Errors
/// [`CheckError::Io`] if `dir` cannot be listed.
pub fn repository_scenarios(dir: &Path) -> Result<Vec<PathBuf>, CheckError> {
    let io = |source| CheckError::Io { path: dir.to_owned(), source };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if is_toml(&path) && path.is_file() {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

/// The verdict on one scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The run met every expectation.
    Pass,
    /// The run ended, but an expectation failed.
    Fail,
    /// The run could not be carried out (simulation diverged, a map failed, a panic).
    Error,
    /// The scenario file or its combination with the options is invalid input.
    Invalid,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Pass => "PASS",
            Self::Fail => "FAIL",
            Self::Error => "ERROR",
            Self::Invalid => "INVALID",
        })
    }
}

/// What came of one scenario.
#[derive(Debug, Clone)]
pub enum RowOutcome {
    /// The run ended with a summary (passed or not).
    Ran {
        /// The run's summary.
        summary: Box<RunSummary>,
        /// The scenario's bound on the time of static-stability violations, s
        /// (`expect.max_static_violation_s`).
        max_static_violation_s: f64,
    },
    /// The run failed with an error.
    Error {
        /// The error and its causes, joined by ": ".
        message: String,
    },
    /// The input is invalid.
    Invalid {
        /// The message, naming the file and field.
        message: String,
    },
}

/// One scenario of the suite and its result. Serialised as the run's summary (`run
/// --json`) plus `path`, `class`, `result` and `max_static_violation_s`; or, for an
/// error or invalid input, `scenario`, `path`, `class`, `result`, `passed` (false),
/// `reached_goal` (false), `failure_kind` (`error` or `invalid_input`), `failure` (the
/// message) and `wall_time_s`.
#[derive(Debug, Clone)]
pub struct CheckRow {
    /// The scenario file.
    pub path: PathBuf,
    /// The scenario's name (the file stem if the file did not load).
    pub scenario: String,
    /// The scenario's class, if it has one (and loaded).
    pub class: Option<String>,
    /// Wall time of loading and running the scenario, s.
    pub wall_time_s: f64,
    /// What came of it.
    pub outcome: RowOutcome,
}

impl CheckRow {
    /// The verdict.
    pub fn verdict(&self) -> Verdict {
        match &self.outcome {
            RowOutcome::Ran { summary, .. } if summary.passed => Verdict::Pass,
            RowOutcome::Ran { .. } => Verdict::Fail,
            RowOutcome::Error { .. } => Verdict::Error,
            RowOutcome::Invalid { .. } => Verdict::Invalid,
        }
    }

    /// The run's summary, if it ran.
    pub fn summary(&self) -> Option<&RunSummary> {
        match &self.outcome {
            RowOutcome::Ran { summary, .. } => Some(summary),
            _ => None,
        }
    }

    /// Why the run stopped short, as in its JSON (`no_path`, `motion_generation`,
    /// `timeout`, ...): `None` for a run without a failure and for error or invalid rows.
    pub fn failure_kind(&self) -> Option<&'static str> {
        self.summary().and_then(|s| s.failure_kind).map(failure_kind_name)
    }

    /// The class, or [`NO_CLASS`].
    pub fn class_key(&self) -> &str {
        self.class.as_deref().unwrap_or(NO_CLASS)
    }
}

impl Serialize for CheckRow {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Ran<'a> {
            path: String,
            class: Option<&'a str>,
            result: Verdict,
            max_static_violation_s: f64,
            #[serde(flatten)]
            summary: &'a RunSummary,
        }
        #[derive(Serialize)]
        struct Failed<'a> {
            scenario: &'a str,
            path: String,
            class: Option<&'a str>,
            result: Verdict,
            passed: bool,
            reached_goal: bool,
            failure_kind: &'static str,
            failure: &'a str,
            wall_time_s: f64,
        }
        let path = self.path.to_string_lossy().into_owned();
        let class = self.class.as_deref();
        let result = self.verdict();
        let failed = |kind, message| Failed {
            scenario: &self.scenario,
            path: path.clone(),
            class,
            result,
            passed: false,
            reached_goal: false,
            failure_kind: kind,
            failure: message,
            wall_time_s: self.wall_time_s,
        };
        match &self.outcome {
            RowOutcome::Ran { summary, max_static_violation_s } => Ran {
                path,
                class,
                result,
                max_static_violation_s: *max_static_violation_s,
                summary,
            }
            .serialize(s),
            RowOutcome::Error { message } => failed("error", message).serialize(s),
            RowOutcome::Invalid { message } => failed("invalid_input", message).serialize(s),
        }
    }
}

/// The name of a failure kind, as serialised.
pub fn failure_kind_name(kind: FailureKind) -> &'static str {
    match kind {
        FailureKind::NoPath => "no_path",
        FailureKind::PlanningTimeLimit => "planning_time_limit",
        FailureKind::MotionGeneration => "motion_generation",
        FailureKind::Replanning => "replanning",
        FailureKind::Stranded => "stranded",
        FailureKind::Timeout => "timeout",
    }
}

/// Counts over a set of rows.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Totals {
    /// Scenarios.
    pub cases: usize,
    /// Verdict PASS.
    pub passed: usize,
    /// Verdict FAIL.
    pub failed: usize,
    /// Verdict ERROR.
    pub errors: usize,
    /// Verdict INVALID.
    pub invalid: usize,
    /// Runs that ended within the goal tolerances.
    pub reached_goal: usize,
    /// Runs the planner answered with a proof of "no path" ([`FailureKind::NoPath`]).
    pub no_path: usize,
    /// Runs whose plan the motion generator could not expand
    /// ([`FailureKind::MotionGeneration`]).
    pub motion_generation: usize,
    /// Runs in which the robot fell over.
    pub tipped: usize,
    /// Runs whose static-stability violations lasted longer than the scenario allows.
    pub static_violation_exceeded: usize,
    /// Impossible courses (`expect.outcome = "no_path"`) that were not answered "no path".
    pub impossible_not_refused: usize,
}

impl Totals {
    /// Runs that broke what must hold on any terrain: a fall, a static violation past
    /// the bound, or an impossible course not refused. A plan the motion generator
    /// rejects is a failure (counted in `motion_generation`) but not a safety one: the
    /// run stops cleanly before the robot moves; nor is a goal not reached.
    pub fn unsafe_runs(&self) -> usize {
        self.tipped + self.static_violation_exceeded + self.impossible_not_refused
    }
}

impl Totals {
    /// Counts `row` in.
    pub fn add(&mut self, row: &CheckRow) {
        self.cases += 1;
        match row.verdict() {
            Verdict::Pass => self.passed += 1,
            Verdict::Fail => self.failed += 1,
            Verdict::Error => self.errors += 1,
            Verdict::Invalid => self.invalid += 1,
        }
        if let RowOutcome::Ran { summary: s, max_static_violation_s } = &row.outcome {
            self.reached_goal += usize::from(s.reached_goal);
            self.no_path += usize::from(s.failure_kind == Some(FailureKind::NoPath));
            self.motion_generation +=
                usize::from(s.failure_kind == Some(FailureKind::MotionGeneration));
            self.tipped += usize::from(s.tipped);
            self.static_violation_exceeded +=
                usize::from(s.static_violation_s > *max_static_violation_s);
            self.impossible_not_refused +=
                usize::from(s.expectations.iter().any(|e| e.name == "outcome" && !e.passed));
        }
    }
}

/// Totals per class (scenarios without one under [`NO_CLASS`]) and over all rows.
pub fn aggregate(rows: &[CheckRow]) -> (BTreeMap<String, Totals>, Totals) {
    let mut classes: BTreeMap<String, Totals> = BTreeMap::new();
    let mut total = Totals::default();
    for row in rows {
        classes.entry(row.class_key().to_owned()).or_default().add(row);
        total.add(row);
    }
    (classes, total)
}

/// The result of a suite, as printed by `check --json`.
#[derive(Debug, Clone, Serialize)]
pub struct CheckReport {
    /// Worker threads used: `--jobs`, but at most one per scenario.
    pub jobs: usize,
    /// The shard run, as `[K, N]`; `null` for the whole suite.
    pub shard: Option<Shard>,
    /// Wall time of the whole suite, s.
    pub wall_time_s: f64,
    /// One row per scenario, in the suite's (sorted) order.
    pub rows: Vec<CheckRow>,
    /// Totals per class.
    pub classes: BTreeMap<String, Totals>,
    /// Totals over every row.
    pub total: Totals,
}

impl CheckReport {
    /// Whether every scenario passed.
    pub fn all_passed(&self) -> bool {
        self.total.passed == self.total.cases
    }

    /// Whether no run broke a safety property ([`Totals::unsafe_runs`]) and none
    /// ended in an error.
    pub fn safe(&self) -> bool {
        self.total.unsafe_runs() == 0 && self.total.errors == 0
    }

    /// Whether some scenario was invalid input.
    pub fn any_invalid(&self) -> bool {
        self.total.invalid > 0
    }
}

/// Options of a suite.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Options of every run (planner options and model; a progress bar is never drawn).
    pub run: RunOptions,
    /// Worker threads, ≥ 1.
    pub jobs: usize,
    /// Run only this shard of the suite.
    pub shard: Option<Shard>,
}

/// A scenario just finished, reported in completion order.
#[derive(Debug, Clone, Copy)]
pub struct Finished<'a> {
    /// Scenarios finished so far, this one included.
    pub done: usize,
    /// Scenarios in the (sharded) suite.
    pub total: usize,
    /// Its row.
    pub row: &'a CheckRow,
}

/// An error and its sources, joined by ": "; a source whose text the message already
/// ends with (errors that print their cause) is not repeated.
fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        let text = c.to_string();
        if !s.ends_with(&text) {
            s.push_str(": ");
            s.push_str(&text);
        }
        cur = c.source();
    }
    s
}

/// Whether a run error is the input's fault (what `momaro run` exits 2 for).
fn is_input_error(e: &RunError) -> bool {
    matches!(
        e,
        RunError::Plan(
            PlanError::BadOption { .. }
                | PlanError::Params { .. }
                | PlanError::OffMap { .. }
                | PlanError::Untraversable { .. }
        )
    )
}

/// The text of a panic's payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_owned())
}

/// Loads and runs one scenario; never fails: failures are rows.
fn run_one(path: &Path, opts: &RunOptions) -> CheckRow {
    let t0 = Instant::now();
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let (scenario, class, outcome) = match Scenario::load(path) {
        Err(e) => (stem, None, RowOutcome::Invalid { message: e.to_string() }),
        Ok(sc) => {
            let result =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run::run(&sc, opts)));
            let outcome = match result {
                Ok(Ok(summary)) => RowOutcome::Ran {
                    summary: Box::new(summary),
                    max_static_violation_s: sc.expect.max_static_violation_s,
                },
                Ok(Err(e)) if is_input_error(&e) => RowOutcome::Invalid { message: chain(&e) },
                Ok(Err(e)) => RowOutcome::Error { message: chain(&e) },
                Err(payload) => RowOutcome::Error {
                    message: format!("panicked: {}", panic_message(payload.as_ref())),
                },
            };
            (sc.name, sc.class, outcome)
        }
    };
    CheckRow {
        path: path.to_owned(),
        scenario,
        class,
        wall_time_s: t0.elapsed().as_secs_f64(),
        outcome,
    }
}

/// Runs the suite `files` (sorted, as [`discover`] returns it), or the shard of it that
/// `opts` names, on `opts.jobs` worker threads; calls `on_finished` on the calling thread
/// as each scenario finishes. Rows come back in `files`' order whatever the worker count.
///
/// # Errors
/// [`CheckError::NoWorkers`] for zero jobs, [`CheckError::Spawn`] if no worker thread
/// could be started. A scenario that fails, errs or is invalid is a row, not an error.
pub fn run(
    files: &[PathBuf],
    opts: &CheckOptions,
    on_finished: &mut dyn FnMut(Finished<'_>),
) -> Result<CheckReport, CheckError> {
    if opts.jobs == 0 {
        return Err(CheckError::NoWorkers);
    }
    let t0 = Instant::now();
    let files = match opts.shard {
        Some(shard) => shard.select(files),
        None => files.to_vec(),
    };
    let run_opts = RunOptions { progress: false, ..opts.run.clone() };
    let workers = opts.jobs.min(files.len());
    let next = AtomicUsize::new(0);
    let mut slots: Vec<Option<CheckRow>> = vec![None; files.len()];
    std::thread::scope(|scope| -> Result<(), CheckError> {
        let (tx, rx) = mpsc::channel::<(usize, CheckRow)>();
        for w in 0..workers {
            let tx = tx.clone();
            let (files, next, run_opts) = (&files, &next, &run_opts);
            std::thread::Builder::new()
                .name(format!("check-{w}"))
                .spawn_scoped(scope, move || {
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(path) = files.get(i) else { break };
                        if tx.send((i, run_one(path, run_opts))).is_err() {
                            break;
                        }
                    }
                })
                .map_err(CheckError::Spawn)?;
        }
        // Only the workers' senders remain: the loop ends when the last worker does.
        drop(tx);
        for (done, (i, row)) in rx.iter().enumerate() {
            on_finished(Finished { done: done + 1, total: files.len(), row: &row });
            if let Some(slot) = slots.get_mut(i) {
                *slot = Some(row);
            }
        }
        Ok(())
    })?;
    // Every index was sent unless a worker died outside `run_one`'s panic guard.
    let rows: Vec<CheckRow> = slots
        .into_iter()
        .zip(&files)
        .map(|(slot, path)| {
            slot.unwrap_or_else(|| CheckRow {
                path: path.clone(),
                scenario: path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                class: None,
                wall_time_s: 0.0,
                outcome: RowOutcome::Error { message: "its worker thread stopped".into() },
            })
        })
        .collect();
    let (classes, total) = aggregate(&rows);
    Ok(CheckReport {
        jobs: workers,
        shard: opts.shard,
        wall_time_s: t0.elapsed().as_secs_f64(),
        rows,
        classes,
        total,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_parses_k_of_n_and_rejects_bad_specs() {
        assert_eq!("2/5".parse::<Shard>().unwrap(), Shard { index: 2, count: 5 });
        assert_eq!("1/1".parse::<Shard>().unwrap(), Shard { index: 1, count: 1 });
        for bad in ["0/2", "3/2", "1/0", "0/0", "2", "a/2", "1/b", "-1/2", "1/2/3", ""] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(matches!(e, CheckError::BadShard { .. }), "{bad}: {e}");
            assert!(e.to_string().starts_with("--shard"), "{bad}: {e}");
        }
        assert_eq!(Shard { index: 3, count: 4 }.to_string(), "3/4");
        assert_eq!(serde_json::to_string(&Shard { index: 3, count: 4 }).unwrap(), "[3,4]");
    }

    #[test]
    fn every_file_is_in_exactly_one_shard() {
        for len in [0usize, 1, 4, 7, 12] {
            let files: Vec<usize> = (0..len).collect();
            for n in 1..=5 {
                let mut seen = vec![0usize; len];
                for k in 1..=n {
                    let part = Shard { index: k, count: n }.select(&files);
                    // In order, and shard k starts at index k - 1, every n-th.
                    assert!(part.windows(2).all(|w| w[1] == w[0] + n), "{k}/{n}: {part:?}");
                    assert_eq!(part.first().copied(), (k - 1 < len).then_some(k - 1));
                    for f in part {
                        seen[f] += 1;
                    }
                }
                assert!(seen.iter().all(|&c| c == 1), "len {len}, N {n}: {seen:?}");
            }
        }
        // The nextest example: 10 files in 3 shards.
        let files: Vec<usize> = (0..10).collect();
        assert_eq!(Shard { index: 1, count: 3 }.select(&files), vec![0, 3, 6, 9]);
        assert_eq!(Shard { index: 2, count: 3 }.select(&files), vec![1, 4, 7]);
        assert_eq!(Shard { index: 3, count: 3 }.select(&files), vec![2, 5, 8]);
    }

    /// A fresh directory under the system's temporary directory, removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> Self {
            let dir =
                std::env::temp_dir().join(format!("momaro_check_{name}_{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn directories_are_searched_recursively_for_toml_files() {
        let tmp = TempDir::new("discover");
        let d = &tmp.0;
        for dir in ["suite/a/deep", "suite/b", "other", "empty"] {
            std::fs::create_dir_all(d.join(dir)).unwrap();
        }
        for f in [
            "suite/z.toml",
            "suite/a/x.toml",
            "suite/a/deep/y.toml",
            "suite/b/w.toml",
            "suite/b/notes.txt",
            "suite/b/toml",
            "other/v.toml",
        ] {
            std::fs::write(d.join(f), "").unwrap();
        }
        // A directory whose name ends in .toml is searched, not taken as a file.
        std::fs::create_dir_all(d.join("suite/c.toml")).unwrap();
        std::fs::write(d.join("suite/c.toml/u.toml"), "").unwrap();

        let found = discover(&[d.join("suite")]).unwrap();
        let rel: Vec<String> = found
            .iter()
            .map(|p| p.strip_prefix(d).unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            rel,
            [
                "suite/a/deep/y.toml",
                "suite/a/x.toml",
                "suite/b/w.toml",
                "suite/c.toml/u.toml",
                "suite/z.toml"
            ]
        );

        // Files and directories mixed, overlapping and in any order: sorted, each once
        // (also under another spelling); a missing file is kept for loading to report.
        let found = discover(&[
            d.join("suite/b/w.toml"),
            d.join("other"),
            d.join("suite/b"),
            d.join("suite/./b/w.toml"),
            d.join("missing.toml"),
        ])
        .unwrap();
        let rel: Vec<String> = found
            .iter()
            .map(|p| p.strip_prefix(d).unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(rel, ["missing.toml", "other/v.toml", "suite/b/w.toml"]);

        assert!(matches!(discover(&[d.join("empty")]), Err(CheckError::EmptyDirectory { .. })));
        // The default suite is not recursive.
        let top = repository_scenarios(&d.join("suite")).unwrap();
        assert_eq!(top, [d.join("suite/z.toml")]);
    }

    fn summary(
        passed: bool,
        reached_goal: bool,
        failure_kind: Option<FailureKind>,
        tipped: bool,
        static_violation_s: f64,
    ) -> RunSummary {
        RunSummary {
            passed,
            reached_goal,
            sim_time_s: 1.0,
            wall_time_s: 1.0,
            real_time_factor: 1.0,
            planning_time_s: 0.1,
            plan_cost: 1.0,
            failure: failure_kind.map(|_| "why".into()),
            failure_kind,
            min_stability_margin_m: 0.1,
            min_instant_margin_m: 0.1,
            static_violation_s,
            tipped,
            ..RunSummary::not_run("s")
        }
    }

    fn row(class: Option<&str>, outcome: RowOutcome) -> CheckRow {
        CheckRow {
            path: PathBuf::from("x.toml"),
            scenario: "x".into(),
            class: class.map(str::to_owned),
            wall_time_s: 1.0,
            outcome,
        }
    }

    fn ran(class: Option<&str>, s: RunSummary, bound_s: f64) -> CheckRow {
        row(class, RowOutcome::Ran { summary: Box::new(s), max_static_violation_s: bound_s })
    }

    #[test]
    fn totals_per_class_and_overall() {
        use FailureKind::*;
        let rows = vec![
            // stairs: a pass, a tip-over that also leaned too long, a motion failure.
            ran(Some("stairs"), summary(true, true, None, false, 0.05), 0.1),
            ran(Some("stairs"), summary(false, false, Some(Timeout), true, 0.5), 0.1),
            ran(Some("stairs"), summary(false, false, Some(MotionGeneration), false, 0.0), 0.1),
            // gaps: a correct "no path", a wrong one, a violation exactly at the bound.
            ran(Some("gaps"), summary(true, false, Some(NoPath), false, 0.0), 0.1),
            ran(Some("gaps"), summary(false, false, Some(NoPath), false, 0.0), 0.1),
            ran(Some("gaps"), summary(true, true, None, false, 0.2), 0.2),
            row(Some("gaps"), RowOutcome::Error { message: "diverged".into() }),
            // no class: a pass beyond a loose bound, an invalid file.
            ran(None, summary(true, true, None, false, 0.3), 1.0),
            row(None, RowOutcome::Invalid { message: "bad".into() }),
        ];
        let (classes, total) = aggregate(&rows);
        assert_eq!(classes.keys().collect::<Vec<_>>(), ["-", "gaps", "stairs"]);
        assert_eq!(
            classes["stairs"],
            Totals {
                cases: 3,
                passed: 1,
                failed: 2,
                errors: 0,
                invalid: 0,
                reached_goal: 1,
                no_path: 0,
                motion_generation: 1,
                tipped: 1,
                static_violation_exceeded: 1,
                impossible_not_refused: 0,
            }
        );
        assert_eq!(
            classes["gaps"],
            Totals {
                cases: 4,
                passed: 2,
                failed: 1,
                errors: 1,
                invalid: 0,
                reached_goal: 1,
                no_path: 2,
                motion_generation: 0,
                tipped: 0,
                static_violation_exceeded: 0,
                impossible_not_refused: 0,
            }
        );
        assert_eq!(
            classes[NO_CLASS],
            Totals { cases: 2, passed: 1, invalid: 1, reached_goal: 1, ..Totals::default() }
        );
        assert_eq!(
            total,
            Totals {
                cases: 9,
                passed: 4,
                failed: 3,
                errors: 1,
                invalid: 1,
                reached_goal: 3,
                no_path: 2,
                motion_generation: 1,
                tipped: 1,
                static_violation_exceeded: 1,
                impossible_not_refused: 0,
            }
        );
        // Safety: the fall, also over its static bound (the motion failure stopped
        // cleanly: a failure, not a safety one).
        assert_eq!(total.unsafe_runs(), 2);
    }

    #[test]
    fn an_impossible_course_that_gets_a_plan_is_unsafe_and_an_unreached_goal_is_not() {
        let mut planned = summary(false, true, None, false, 0.0);
        planned.expectations.push(crate::closed_loop::ExpectationResult {
            name: "outcome",
            passed: false,
            detail: "a plan".into(),
        });
        let unreached = summary(false, false, Some(FailureKind::PlanningTimeLimit), false, 0.0);
        let rows = vec![ran(Some("impossible"), planned, 0.1), ran(Some("stairs"), unreached, 0.1)];
        let (classes, total) = aggregate(&rows);
        assert_eq!(classes["impossible"].impossible_not_refused, 1);
        assert_eq!(classes["stairs"].unsafe_runs(), 0);
        assert_eq!(total.unsafe_runs(), 1);
        let report = CheckReport {
            jobs: 1,
            shard: None,
            wall_time_s: 0.0,
            rows: rows.clone(),
            classes,
            total,
        };
        assert!(!report.safe() && !report.all_passed());
    }

    #[test]
    fn error_chains_name_each_cause_once() {
        #[derive(Debug, thiserror::Error)]
        enum E {
            #[error("outer: {0}")]
            Prints(#[source] std::io::Error),
            #[error("outer")]
            Hides(#[source] std::io::Error),
        }
        let io = || std::io::Error::other("inner");
        assert_eq!(chain(&E::Prints(io())), "outer: inner");
        assert_eq!(chain(&E::Hides(io())), "outer: inner");
    }

    #[test]
    fn failure_kind_names_are_the_serialised_ones() {
        use FailureKind::*;
        for k in [NoPath, PlanningTimeLimit, MotionGeneration, Replanning, Stranded, Timeout] {
            assert_eq!(serde_json::to_value(k).unwrap(), failure_kind_name(k), "{k:?}");
        }
        let r = ran(None, summary(false, false, Some(Timeout), false, 0.0), 0.1);
        assert_eq!(r.failure_kind(), Some("timeout"));
        assert_eq!(row(None, RowOutcome::Error { message: "e".into() }).failure_kind(), None);
    }

    #[test]
    fn rows_serialise_as_the_run_summary_plus_path_and_class_or_an_error_object() {
        let r = ran(Some("stairs"), summary(true, true, None, false, 0.0), 0.1);
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["path"], "x.toml");
        assert_eq!(v["class"], "stairs");
        assert_eq!(v["result"], "pass");
        assert_eq!(v["scenario"], "s");
        assert_eq!(v["passed"], true);
        assert_eq!(v["max_static_violation_s"], 0.1);
        assert!(v.get("goal_position_error_m").is_some() && v.get("expectations").is_some());

        let r = row(
            None,
            RowOutcome::Invalid { message: "invalid scenario x.toml: field `goal`".into() },
        );
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["scenario"], "x");
        assert_eq!(v["class"], serde_json::Value::Null);
        assert_eq!(v["result"], "invalid");
        assert_eq!(v["failure_kind"], "invalid_input");
        assert_eq!(v["passed"], false);
        assert!(v["failure"].as_str().unwrap().contains("field `goal`"));
        let v = serde_json::to_value(row(None, RowOutcome::Error { message: "e".into() })).unwrap();
        assert_eq!(
            (v["result"].as_str(), v["failure_kind"].as_str()),
            (Some("error"), Some("error"))
        );
    }

    #[test]
    fn a_suite_of_files_that_do_not_load_runs_to_the_end_in_order() {
        let tmp = TempDir::new("invalid_suite");
        let files: Vec<PathBuf> =
            ["a.toml", "b.toml", "c.toml"].iter().map(|f| tmp.0.join(f)).collect();
        std::fs::write(&files[0], "[map\n").unwrap();
        std::fs::write(&files[2], "name = 3\n").unwrap();
        let opts = CheckOptions {
            run: RunOptions::new(Default::default(), PathBuf::from("/no/model.xml")),
            jobs: 2,
            shard: None,
        };
        let mut finished = Vec::new();
        let report = run(&files, &opts, &mut |f| finished.push((f.done, f.total))).unwrap();
        assert_eq!(finished, [(1, 3), (2, 3), (3, 3)]);
        assert_eq!(
            report.rows.iter().map(|r| r.scenario.as_str()).collect::<Vec<_>>(),
            ["a", "b", "c"]
        );
        assert!(report.rows.iter().all(|r| r.verdict() == Verdict::Invalid));
        assert!(report.any_invalid() && !report.all_passed());
        assert_eq!(report.jobs, 2);
        let RowOutcome::Invalid { message } = &report.rows[1].outcome else { unreachable!() };
        assert!(message.contains("b.toml"), "{message}");

        let one = CheckOptions { shard: Some(Shard { index: 2, count: 2 }), ..opts };
        let report = run(&files, &one, &mut |_| {}).unwrap();
        assert_eq!(report.rows.len(), 1);
        assert_eq!(report.rows[0].scenario, "b");
        assert_eq!(report.jobs, 1);
        assert!(matches!(
            run(&files, &CheckOptions { jobs: 0, ..one }, &mut |_| {}),
            Err(CheckError::NoWorkers)
        ));
    }
}
