//! `momaro generate` against the robot: every class's start and goal pass the planner's
//! own check (`jobs::plan::prepare`: the driving footprint on finite foot costs) for
//! many seeds, and a case reproduces from its class and seed alone.

mod common;

use momaro::jobs::generate::{GenerateOptions, checked_case, run};
use momaro::motion::manoeuvres::ALL;
use momaro::planner::prepare;
use momaro::robot::RobotDescription;
use momaro::scenario::Scenario;
use momaro::scenario::generate::Class;

fn robot() -> RobotDescription {
    momaro::sim::Simulation::robot_only(&common::model()).expect("model compiles").robot().clone()
}

#[test]
fn every_class_passes_prepare_for_many_seeds() {
    let robot = robot();
    for class in Class::ALL {
        let dir = common::temp_dir(&format!("generate_{class}"));
        let opts =
            GenerateOptions { seed: 100, count: 12, out_dir: dir.clone(), class: Some(class) };
        let summary = run(&opts, &robot).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(summary.files.len(), 12);
        assert_eq!(summary.per_class.len(), 1);
        for f in &summary.files {
            let s = Scenario::load(&f.path).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(s.class.as_deref(), Some(class.name()));
            prepare(&s, &robot, Default::default(), &ALL)
                .unwrap_or_else(|e| panic!("{}: {e}", f.path.display()));
        }
    }
}

#[test]
fn a_case_of_a_mixed_run_reproduces_alone() {
    let robot = robot();
    let dir = common::temp_dir("generate_mixed_run");
    let opts = GenerateOptions { seed: 40, count: 10, out_dir: dir.clone(), class: None };
    let summary = run(&opts, &robot).unwrap_or_else(|e| panic!("{e}"));
    // Case 9 is seed 49, class 9 mod 8 = step_down.
    let f = &summary.files[9];
    assert_eq!((f.seed, f.class), (49, Class::StepDown));
    let (_, text) = checked_case(Class::StepDown, 49, &dir, &robot).unwrap();
    assert_eq!(std::fs::read_to_string(&f.path).unwrap(), text);
}
