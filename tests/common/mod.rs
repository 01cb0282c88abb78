//! Helpers shared by the integration tests.
#![allow(dead_code)]

use momaro::planner::PlanOptions;
use momaro::scenario::Scenario;
use std::path::PathBuf;

/// ARA*'s first solution (ε = 3), whatever the machine's speed: the same plan everywhere
/// (a time limit would cut the anytime search wherever the CPU happens to be).
pub fn first_solution() -> PlanOptions {
    PlanOptions { time_limit_s: 600.0, final_epsilon: Some(3.0), ..PlanOptions::default() }
}

/// ARA*'s probe's path, as `plan --schedule-expansions 0` finds it: the same plan on any
/// machine, where the schedule to ε = 3 costs a search the test does not need (the
/// paper's staircase: 1.5 M expansions, more than `run`'s `RUN_SCHEDULE_EXPANSIONS`, so
/// this is what `momaro run` executes there).
pub fn probe_path() -> PlanOptions {
    PlanOptions { schedule_expansions: Some(0), ..first_solution() }
}

/// Repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Loads `scenarios/<name>.toml`.
pub fn scenario(name: &str) -> Scenario {
    Scenario::load(&root().join("scenarios").join(format!("{name}.toml"))).expect("scenario loads")
}

/// The robot model file.
pub fn model() -> PathBuf {
    momaro::sim::default_model_path()
}

/// A fresh temporary directory under the target dir.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Case `seed` of `class` as `momaro generate --class C --seed S --count 1` writes it, in
/// a fresh temporary directory named after both, loaded.
pub fn generated(class: momaro::scenario::generate::Class, seed: u64) -> Scenario {
    let robot = momaro::sim::Simulation::robot_only(&model()).expect("model").robot().clone();
    let dir = temp_dir(&format!("generated_{class:?}_{seed}"));
    let (case, _) =
        momaro::jobs::generate::checked_case(class, seed, &dir, &robot, false).expect("generated");
    case.scenario(&dir).expect("scenario")
}
