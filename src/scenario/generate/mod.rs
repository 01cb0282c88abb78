//! Seeded random scenarios, the pure half of `momaro generate`: eight classes of course,
//! each drawn from a seed into a scenario file.
//!
//! A case is a class and a seed; its file is a function of those two and of how many
//! draws of the seed's stream were rejected before it, nothing else (the crate's own
//! generator [`crate::rng::Rng`], no clock, no hash-map order), so a case is reproducible
//! from its seed alone. Every draw is checked here to parse as a
//! [`Scenario`](super::Scenario) and to keep
//! its map within [`MAX_MAP_M`]; whether the robot can stand at its start and goal needs
//! the robot, so `jobs::generate` checks that (`planner::prepare`) and asks for the
//! next draw of the same stream ([`Draws::next_case`]) when it fails.
//!
//! **A class is a unit.** Each class is one file (`stairs.rs`, `step_down.rs`, ...)
//! holding its parameter ranges, its drawing function and the models its files name, as a
//! `ClassUnit`; `REGISTRY` registers them, once, in `momaro generate`'s order. Adding a
//! class is one new file, a variant of [`Class`] and its row in `REGISTRY`. The
//! drawing helpers the classes share are `course` (numbers, the course frame, the
//! builder of primitives in it) and `layout` (walls, corridors, clutter, the edge
//! course); a case and its file are `case` (TOML written by serde from the scenario
//! format's own types).
//!
//! Courses are laid out in a local *course frame* (the robot travels along +x, y left)
//! and turned into the world: by a quarter turn for the classes whose obstacles must cut
//! the whole map (no detour), by any yaw for stairs. Obstacles meant to block (a platform
//! edge, a block across the path, a wall with a doorway) reach 1 m beyond the map on
//! every side, so no way around them exists in the simulated world either.
//!
//! The parameter ranges and where they come from are documented in the "Generated
//! scenarios" section of `scenarios/README.md`; the constants of the class files (and of
//! `layout` for the ranges classes share), all exported here, are the single source of
//! the numbers.

mod case;
mod clutter;
mod course;
mod headings;
mod impossible;
mod layout;
mod mixed;
mod narrow;
mod stairs;
mod step_down;
mod up_and_over;

pub use case::{GeneratedCase, Placed};
pub use clutter::BUMP_HEIGHT_M;
pub use course::Span;
pub use headings::{LATTICE_STEP_DEG, MIN_OFF_LATTICE_DEG, off_lattice_deg};
pub use impossible::{ENCLOSURE_HEIGHT_M, HIGH_WALL_HEIGHT_M, TIGHT_DOOR_WIDTH_M};
pub use layout::{CLUTTER_HEIGHT_M, EDGE_YAW_DEG, WALL_HEIGHT_M, WALL_YAW_DEG};
pub use narrow::DOOR_WIDTH_M;
pub use stairs::{
    STAIR_LANDING_M, STAIR_MID_LANDING_M, STAIR_RISE_M, STAIR_STEPS, STAIR_TREAD_M, STAIR_WIDTH_M,
};
pub use step_down::STEP_DOWN_HEIGHT_M;
pub use up_and_over::{UP_AND_OVER_DEPTH_M, UP_AND_OVER_HEIGHT_M};

use super::Outcome;
use crate::params::{FootModel, StepModel};
use crate::rng::Rng;
use course::{Course, Reject};
use serde::Serialize;
use std::path::Path;

/// A class of generated course.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Class {
    /// A flight of stairs, climbed or descended.
    Stairs,
    /// Start on a platform, get down its edge.
    StepDown,
    /// A block across the path: step up, drive across, step down.
    UpAndOver,
    /// Random boxes and poles with low bumps, a way left free.
    Clutter,
    /// A wall across the map with a doorway, sometimes a corridor.
    Narrow,
    /// Flat ground, start and goal headings off the planner's lattice.
    Headings,
    /// Clutter, a climb (block or stairs) and a step down on one course.
    Mixed,
    /// No way exists: the planner must answer "no path".
    Impossible,
}

/// One class of course, as its file defines it.
#[derive(Debug)]
struct ClassUnit {
    /// The class.
    class: Class,
    /// Its name, as written in files and on the command line.
    name: &'static str,
    /// Draws one course from the stream.
    draw: fn(&mut Rng) -> Result<Course, Reject>,
    /// The step and foot models its files name in `[params]`, if any.
    models: Option<(StepModel, FootModel)>,
}

/// The classes, registered once, in the order `momaro generate` cycles through them
/// (which is also the order of [`Class`]'s variants).
const REGISTRY: [&ClassUnit; 8] = [
    &stairs::UNIT,
    &step_down::UNIT,
    &up_and_over::UNIT,
    &clutter::UNIT,
    &narrow::UNIT,
    &headings::UNIT,
    &mixed::UNIT,
    &impossible::UNIT,
];

impl Class {
    /// Every class, in the order `momaro generate` cycles through them.
    pub const ALL: [Class; REGISTRY.len()] = {
        let mut all = [Class::Stairs; REGISTRY.len()];
        let mut k = 0;
        while k < all.len() {
            all[k] = REGISTRY[k].class;
            k += 1;
        }
        all
    };

    /// The names of [`Class::ALL`], as written in files and on the command line.
    pub const NAMES: [&'static str; REGISTRY.len()] = {
        let mut names = [""; REGISTRY.len()];
        let mut k = 0;
        while k < names.len() {
            names[k] = REGISTRY[k].name;
            k += 1;
        }
        names
    };

    /// The class's unit (its file's [`ClassUnit`]).
    fn unit(self) -> &'static ClassUnit {
        // The registry lists the classes in the order of the variants (a test checks).
        REGISTRY[self as usize]
    }

    /// The class's name (`step_down`, ...).
    pub fn name(self) -> &'static str {
        self.unit().name
    }

    /// The class named `name`, if any.
    pub fn from_name(name: &str) -> Option<Class> {
        Self::NAMES.iter().position(|&n| n == name).map(|k| Self::ALL[k])
    }

    /// The class of case `i` of a run without `--class`: `i mod 8` in [`Class::ALL`]'s order.
    pub fn of_case(i: u64) -> Class {
        Self::ALL[(i % Self::ALL.len() as u64) as usize]
    }

    /// The step and foot models the class's files name in `[params]`, if any (only
    /// stairs do: see `stairs.rs`). The other classes name none and the planner chooses
    /// them from the course's heights (`planner::terrain_models`): mixed courses whose
    /// climb is 2–3 steps get the wheel pair, the rest the paper's models.
    pub fn models(self) -> Option<(StepModel, FootModel)> {
        self.unit().models
    }
}

impl std::fmt::Display for Class {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Class {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Class::from_name(s)
            .ok_or_else(|| format!("unknown class `{s}` (one of {})", Class::NAMES.join(", ")))
    }
}

/// A class is written as its name.
impl Serialize for Class {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Largest map, m: the longer side at most 10 m, the shorter at most 6 m.
pub const MAX_MAP_M: [f64; 2] = [10.0, 6.0];

/// Draws of one `next_case` call before giving up (rejections of the map size etc.).
pub const MAX_DRAWS: u32 = 200;

/// Why no case could be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerateError {
    /// Every draw was rejected.
    #[error("class {class}, seed {seed}: no valid course in {draws} draws; the last: {reason}")]
    NoValidDraw {
        /// The class.
        class: Class,
        /// The seed.
        seed: u64,
        /// Draws tried.
        draws: u32,
        /// Why the last draw was rejected.
        reason: String,
    },
    /// A case could not be serialised as TOML (a generator bug).
    #[error("case {name}: cannot write its TOML: {reason}")]
    Toml {
        /// The case's name.
        name: String,
        /// The serialiser's message.
        reason: String,
    },
    /// A case's file does not load as a scenario: the loader's message, which names the
    /// file and the field.
    #[error("{reason}")]
    Scenario {
        /// The loader's message.
        reason: String,
    },
}

/// The stream of candidate cases of one class and seed: each call to
/// [`Draws::next_case`] continues the same random stream, so the n-th candidate is
/// always the same.
#[derive(Debug, Clone)]
pub struct Draws {
    class: Class,
    seed: u64,
    rng: Rng,
    draws: u32,
}

impl Draws {
    /// The stream of `class` from `seed`.
    pub fn new(class: Class, seed: u64) -> Self {
        Self { class, seed, rng: Rng::seeded(seed), draws: 0 }
    }

    /// The next draw that parses as a scenario and fits the map limit.
    ///
    /// # Errors
    /// [`GenerateError::NoValidDraw`] after [`MAX_DRAWS`] rejected draws in a row.
    pub fn next_case(&mut self) -> Result<GeneratedCase, GenerateError> {
        let mut reason = String::new();
        for _ in 0..MAX_DRAWS {
            let draw = self.draws;
            self.draws += 1;
            match draw_case(self.class, self.seed, draw, &mut self.rng) {
                Ok(case) => match case.scenario(Path::new("")) {
                    Ok(_) => return Ok(case),
                    Err(e) => reason = e.to_string(),
                },
                Err(Reject(r)) => reason = r,
            }
        }
        Err(GenerateError::NoValidDraw {
            class: self.class,
            seed: self.seed,
            draws: MAX_DRAWS,
            reason,
        })
    }
}

/// The first valid draw of `class` from `seed` (without the robot's standability check,
/// which `jobs::generate` adds).
///
/// # Errors
/// [`GenerateError::NoValidDraw`].
pub fn generate(class: Class, seed: u64) -> Result<GeneratedCase, GenerateError> {
    Draws::new(class, seed).next_case()
}

/// Draws one course of `class` and makes it a case: the map limit, the timeout.
fn draw_case(class: Class, seed: u64, draw: u32, rng: &mut Rng) -> Result<GeneratedCase, Reject> {
    let course = (class.unit().draw)(rng)?;
    let map = course.map;
    let (long, short) = {
        let (a, b) = (map.x_max - map.x_min, map.y_max - map.y_min);
        (a.max(b), a.min(b))
    };
    if long > MAX_MAP_M[0] + 1e-9 || short > MAX_MAP_M[1] + 1e-9 {
        return Err(Reject(format!(
            "map {long:.1} m x {short:.1} m exceeds {} m x {} m",
            MAX_MAP_M[0], MAX_MAP_M[1]
        )));
    }
    let timeout_s = match course.outcome {
        Outcome::Reach => {
            // 60 s, 40 s per planned step (four per height edge, one per leg; the
            // platform's 4 steps take 146 s of keyframes) and 10 s per metre of course;
            // rounded up to whole 10 s.
            let t = 60.0 + 4.0 * 40.0 * f64::from(course.edges) + 10.0 * course.length_m;
            (t / 10.0).ceil() * 10.0
        }
        Outcome::NoPath => 60.0,
    };
    Ok(GeneratedCase {
        class,
        seed,
        draw,
        name: format!("{}_{seed:06}", class.name()),
        description: course.description,
        map,
        start: course.start,
        goal: course.goal,
        terrain: course.terrain,
        outcome: course.outcome,
        timeout_s,
        parameters: course.parameters,
    })
}

/// What the class files' tests share.
#[cfg(test)]
pub(super) mod test_support {
    use super::*;
    use crate::scenario::Scenario;

    /// The seeds every class is tested with.
    pub(crate) const SEEDS: std::ops::Range<u64> = 1..51;

    /// The first valid draw of `class` from `seed`.
    pub(crate) fn case(class: Class, seed: u64) -> GeneratedCase {
        generate(class, seed).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The case's file loaded.
    pub(crate) fn loaded(c: &GeneratedCase) -> Scenario {
        c.scenario(Path::new("")).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Heights over a 5 cm grid of the map, with each point's coordinate along the
    /// normal of the edges (world angle `heading + edge_yaw`) through the world origin.
    pub(crate) fn over_map(s: &Scenario, normal_deg: f64) -> Vec<(f64, f64)> {
        let (sn, cs) = normal_deg.to_radians().sin_cos();
        let m = s.map;
        let (nx, ny) = (((m.x_max - m.x_min) / 0.05) as i32, ((m.y_max - m.y_min) / 0.05) as i32);
        let mut v = Vec::new();
        for i in 0..=nx {
            for j in 0..=ny {
                let (x, y) = (m.x_min + f64::from(i) * 0.05, m.y_min + f64::from(j) * 0.05);
                v.push((x * cs + y * sn, s.terrain_height(x, y)));
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::{SEEDS, case};
    use super::*;

    #[test]
    fn the_registry_follows_the_variants() {
        for (k, unit) in REGISTRY.iter().enumerate() {
            assert_eq!(unit.class as usize, k, "{}", unit.name);
            assert_eq!(unit.class.unit().name, unit.name);
        }
        assert_eq!(Class::ALL.len(), 8);
        assert_eq!(
            Class::NAMES,
            [
                "stairs",
                "step_down",
                "up_and_over",
                "clutter",
                "narrow",
                "headings",
                "mixed",
                "impossible"
            ]
        );
        assert_eq!(serde_json::to_string(&Class::UpAndOver).unwrap(), "\"up_and_over\"");
    }

    #[test]
    fn class_names_round_trip_and_cases_cycle() {
        for (k, c) in Class::ALL.iter().enumerate() {
            assert_eq!(Class::from_name(c.name()), Some(*c));
            assert_eq!(c.name().parse::<Class>(), Ok(*c));
            assert_eq!(Class::of_case(k as u64), *c);
            assert_eq!(Class::of_case(k as u64 + 8), *c);
        }
        assert!("stair".parse::<Class>().is_err());
    }

    #[test]
    fn same_seed_same_text_other_seed_other_text() {
        for class in Class::ALL {
            let a = case(class, 7).to_toml().unwrap();
            assert_eq!(a, case(class, 7).to_toml().unwrap(), "{class}");
            assert_ne!(a, case(class, 8).to_toml().unwrap(), "{class}");
        }
    }

    #[test]
    fn draws_continue_one_stream() {
        let mut d = Draws::new(Class::Clutter, 3);
        let first = d.next_case().unwrap();
        let second = d.next_case().unwrap();
        assert_ne!(first.to_toml().unwrap(), second.to_toml().unwrap());
        assert!(second.draw > first.draw);
        let mut again = Draws::new(Class::Clutter, 3);
        assert_eq!(again.next_case().unwrap(), first);
        assert_eq!(again.next_case().unwrap(), second);
    }

    #[test]
    fn every_class_parses_with_its_class_name_and_small_map() {
        for class in Class::ALL {
            for seed in SEEDS {
                let c = case(class, seed);
                let s = c.scenario(Path::new("generated")).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(s.class.as_deref(), Some(class.name()));
                assert_eq!(s.name, format!("{class}_{seed:06}"));
                assert_eq!(c.file_name(), format!("{class}_{seed:06}.toml"));
                assert!(!s.description.is_empty());
                let (a, b) = (s.map.x_max - s.map.x_min, s.map.y_max - s.map.y_min);
                assert!(a.max(b) <= 10.0 + 1e-9 && a.min(b) <= 6.0 + 1e-9, "{}: {a} x {b}", s.name);
                assert_eq!(s.expect.outcome, c.outcome);
                assert!(s.expect.timeout_s >= 60.0);
                if c.outcome == Outcome::Reach {
                    assert_eq!(s.expect.goal_tolerance_m, 0.1);
                    assert_eq!(s.expect.goal_tolerance_deg, 10.0);
                    assert_eq!(s.expect.min_stability_margin_m, 0.02);
                }
                assert!(s.map.contains(s.start.x, s.start.y) && s.map.contains(s.goal.x, s.goal.y));
                // Stairs name the models that climb treads shorter than the robot; the
                // other classes name none, and the planner chooses from their heights.
                match class.models() {
                    Some((step, foot)) => {
                        assert_eq!((s.params.step_model, s.params.foot_model), (step, foot));
                        assert!(s.named_models.foot && s.named_models.step, "{}", s.name);
                    }
                    None => assert_eq!(s.named_models, Default::default(), "{}", s.name),
                }
                assert_eq!(class == Class::Stairs, s.params.step_model == StepModel::Stairs);
            }
        }
    }

    #[test]
    fn only_impossible_cases_expect_no_path() {
        for class in Class::ALL {
            for seed in SEEDS {
                let c = case(class, seed);
                let want =
                    if class == Class::Impossible { Outcome::NoPath } else { Outcome::Reach };
                assert_eq!(c.outcome, want, "{}", c.name);
            }
        }
    }
}
