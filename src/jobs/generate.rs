//! `momaro generate`: writes seeded random scenarios (`scenario::generate`) into a
//! directory, each checked to load and to let the robot stand at its start and goal.
//!
//! Case i of a run uses seed S + i alone and, without a class, class i mod 8; so any one
//! file is reproducible with `--class C --seed S --count 1`. A draw whose start or goal
//! the planner would refuse (`planner::prepare`: the driving footprint on an infinite or
//! unknown foot cost) is replaced by the next draw of the same seed's stream, up to
//! [`MAX_TRIES`] draws. Every case is generated and checked before any file is written.

use crate::planner;
use crate::robot::RobotDescription;
use crate::scenario::generate::{Class, Draws, GenerateError, GeneratedCase};
use crate::scenario::{Outcome, Scenario};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Draws of one case tried against the standability check before giving up.
pub const MAX_TRIES: u32 = 50;

/// What to generate.
#[derive(Debug, Clone)]
pub struct GenerateOptions {
    /// Seed of the first case; case i uses `seed + i`.
    pub seed: u64,
    /// Number of cases (at least 1).
    pub count: usize,
    /// Directory to write into (created if missing).
    pub out_dir: PathBuf,
    /// Only this class (default: the classes in turn).
    pub class: Option<Class>,
    /// Write every flight of stairs as stacked boxes, a box per step
    /// (`GeneratedCase::with_stairs_as_boxes`), instead of a `stairs` primitive.
    pub stairs_as_boxes: bool,
}

/// Why generation failed.
#[derive(Debug, thiserror::Error)]
pub enum GenerateJobError {
    /// An option is out of range.
    #[error("invalid option `{option}`: {reason}")]
    BadOption {
        /// The option.
        option: &'static str,
        /// Why.
        reason: String,
    },
    /// The generator found no valid course.
    #[error(transparent)]
    Generate(#[from] GenerateError),
    /// No draw of a case let the robot stand at its start and goal.
    #[error(
        "class {class}, seed {seed}: no draw in {tries} had a start and goal the robot can stand on; the last: {reason}"
    )]
    NotStandable {
        /// The class.
        class: Class,
        /// The seed.
        seed: u64,
        /// Draws tried.
        tries: u32,
        /// The last draw's failure.
        reason: String,
    },
    /// A file or the directory could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// One file written.
#[derive(Debug, Clone, Serialize)]
pub struct GeneratedFile {
    /// Its path.
    pub path: PathBuf,
    /// The class.
    pub class: Class,
    /// The seed.
    pub seed: u64,
    /// The draw of the seed's stream that passed the checks (0: the first).
    pub draw: u32,
    /// The right answer to the course.
    pub outcome: Outcome,
    /// The scenario's description (the drawn parameters).
    pub description: String,
}

/// How many files of a class were written.
#[derive(Debug, Clone, Serialize)]
pub struct ClassCount {
    /// The class.
    pub class: Class,
    /// Files written.
    pub count: usize,
}

/// What `generate` did.
#[derive(Debug, Clone, Serialize)]
pub struct GenerateSummary {
    /// The directory written into.
    pub out_dir: PathBuf,
    /// The first seed.
    pub seed: u64,
    /// The class asked for, if one was.
    pub class: Option<Class>,
    /// The files, in case order.
    pub files: Vec<GeneratedFile>,
    /// Files per class, in the classes' order; classes without files left out.
    pub per_class: Vec<ClassCount>,
}

/// The first draw of `class` from `seed` that loads as a scenario at `dir` and passes
/// the planner's start and goal check, with its text; with `stairs_as_boxes`, its flights
/// written as boxes.
///
/// # Errors
/// [`GenerateJobError::Generate`] if the generator fails,
/// [`GenerateJobError::NotStandable`] after [`MAX_TRIES`] draws that fail the check.
pub fn checked_case(
    class: Class,
    seed: u64,
    dir: &Path,
    robot: &RobotDescription,
    stairs_as_boxes: bool,
) -> Result<(GeneratedCase, String), GenerateJobError> {
    let mut draws = Draws::new(class, seed);
    let mut reason = String::new();
    for _ in 0..MAX_TRIES {
        let case = draws.next_case()?;
        let case = if stairs_as_boxes { case.with_stairs_as_boxes() } else { case };
        let text = case.to_toml()?;
        let path = dir.join(case.file_name());
        match Scenario::parse(&text, &path) {
            Ok(scenario) => {
                match planner::prepare(
                    &scenario,
                    robot,
                    planner::ParamOverrides::default(),
                    &crate::motion::manoeuvres::ALL,
                ) {
                    Ok(_) => return Ok((case, text)),
                    Err(e) => reason = format!("draw {}: {e}", case.draw),
                }
            }
            Err(e) => reason = format!("draw {}: {e}", case.draw),
        }
    }
    Err(GenerateJobError::NotStandable { class, seed, tries: MAX_TRIES, reason })
}

/// Generates, checks and writes the cases of `opts`.
///
/// # Errors
/// [`GenerateJobError`]: a bad option (`count` 0, seeds past `u64::MAX`), a case that
/// cannot be generated, or a write failure. Nothing is written unless every case passes.
pub fn run(
    opts: &GenerateOptions,
    robot: &RobotDescription,
) -> Result<GenerateSummary, GenerateJobError> {
    if opts.count == 0 {
        return Err(GenerateJobError::BadOption {
            option: "count",
            reason: "must be at least 1".into(),
        });
    }
    let last = u64::try_from(opts.count - 1).ok().and_then(|n| opts.seed.checked_add(n));
    if last.is_none() {
        return Err(GenerateJobError::BadOption {
            option: "seed",
            reason: format!("{} + {} cases runs past {}", opts.seed, opts.count, u64::MAX),
        });
    }
    let mut cases = Vec::with_capacity(opts.count);
    for i in 0..opts.count as u64 {
        let seed = opts.seed + i;
        let class = opts.class.unwrap_or_else(|| Class::of_case(i));
        cases.push(checked_case(class, seed, &opts.out_dir, robot, opts.stairs_as_boxes)?);
    }
    std::fs::create_dir_all(&opts.out_dir)
        .map_err(|source| GenerateJobError::Io { path: opts.out_dir.clone(), source })?;
    let mut files = Vec::with_capacity(cases.len());
    for (case, text) in cases {
        let path = opts.out_dir.join(case.file_name());
        std::fs::write(&path, text)
            .map_err(|source| GenerateJobError::Io { path: path.clone(), source })?;
        files.push(GeneratedFile {
            path,
            class: case.class,
            seed: case.seed,
            draw: case.draw,
            outcome: case.outcome,
            description: case.description,
        });
    }
    let per_class = Class::ALL
        .iter()
        .map(|&class| ClassCount {
            class,
            count: files.iter().filter(|f| f.class == class).count(),
        })
        .filter(|c| c.count > 0)
        .collect();
    Ok(GenerateSummary {
        out_dir: opts.out_dir.clone(),
        seed: opts.seed,
        class: opts.class,
        files,
        per_class,
    })
}
