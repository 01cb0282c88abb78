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
        let opts = GenerateOptions {
            seed: 100,
            count: 12,
            out_dir: dir.clone(),
            class: Some(class),
            stairs_as_boxes: false,
        };
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
    let opts = GenerateOptions {
        seed: 40,
        count: 10,
        out_dir: dir.clone(),
        class: None,
        stairs_as_boxes: false,
    };
    let summary = run(&opts, &robot).unwrap_or_else(|e| panic!("{e}"));
    // Case 9 is seed 49, class 9 mod 8 = step_down.
    let f = &summary.files[9];
    assert_eq!((f.seed, f.class), (49, Class::StepDown));
    let (_, text) = checked_case(Class::StepDown, 49, &dir, &robot, false).unwrap();
    assert_eq!(std::fs::read_to_string(&f.path).unwrap(), text);
}

/// `--stairs-as boxes`: every flight of a stairs course written as a box per step, the
/// same heights cell for cell as its labelled version (and the same files otherwise).
#[test]
fn flights_written_as_boxes_rasterise_as_the_labelled_flights() {
    let robot = robot();
    let (dir_a, dir_b) =
        (common::temp_dir("generate_stairs_labelled"), common::temp_dir("generate_stairs_boxes"));
    for (as_boxes, dir) in [(false, &dir_a), (true, &dir_b)] {
        let opts = GenerateOptions {
            seed: 7,
            count: 4,
            out_dir: dir.clone(),
            class: Some(Class::Stairs),
            stairs_as_boxes: as_boxes,
        };
        run(&opts, &robot).unwrap_or_else(|e| panic!("{e}"));
    }
    for seed in 7..11 {
        let file = format!("stairs_{seed:06}.toml");
        let a = Scenario::load(&dir_a.join(&file)).expect("labelled loads");
        let b = Scenario::load(&dir_b.join(&file)).expect("boxes load");
        assert!(a.terrain.iter().any(|p| p.kind() == "stairs"));
        assert!(b.terrain.iter().all(|p| p.kind() != "stairs"), "{file}: no stairs left");
        let ha = momaro::terrain::scenario_map(&a).expect("map");
        let hb = momaro::terrain::scenario_map(&b).expect("map");
        assert_eq!(ha.dims(), hb.dims());
        let (nx, ny) = ha.dims();
        for j in 0..ny {
            for i in 0..nx {
                assert_eq!(
                    ha.get(i, j).map(f64::to_bits),
                    hb.get(i, j).map(f64::to_bits),
                    "{file} ({i}, {j})"
                );
            }
        }
        assert_eq!((a.start, a.goal), (b.start, b.goal));
    }
}
