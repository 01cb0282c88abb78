//! The model: kinematics read from MJCF agree with MuJoCo's forward kinematics, and the
//! URDF agrees with the MJCF.

mod common;

use momaro::robot::Leg;
use momaro::robot::ik::{leg_fk, leg_ik};
use momaro::scenario::terrain::Solid;
use momaro::sim::Simulation;

#[test]
fn model_derived_kinematics_match_mujoco_forward_kinematics() {
    let mut sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let robot = sim.robot().clone();
    let configs: [[f64; 3]; 4] =
        [[0.0, 0.0, 0.0], [1.3, -2.5, 1.2], [-0.4, 0.9, -0.5], [0.7, -1.4, 0.7]];
    for q in configs {
        sim.place_robot([0.0, 0.0, 1.5], 0.0, &[q; 4]);
        let base = sim.base().position;
        let centres = sim.wheel_pair_centres();
        for leg in Leg::ALL {
            let hip = robot.hips[leg.index()];
            // leg_fk gives the contact point r below the axle (level base); the axle itself
            // is independent of that assumption.
            let contact = leg_fk(&robot, q, 0.0);
            let axle = [contact[0], contact[1] + robot.wheel_radius];
            let got = centres[leg.index()];
            let expected = [base[0] + hip[0] + axle[0], base[2] + hip[2] + axle[1]];
            assert!(
                (got[0] - expected[0]).abs() < 1e-3,
                "{leg:?} {q:?}: x {} vs {}",
                got[0],
                expected[0]
            );
            assert!(
                (got[2] - expected[1]).abs() < 1e-3,
                "{leg:?} {q:?}: z {} vs {}",
                got[2],
                expected[1]
            );
            assert!((got[1] - (base[1] + hip[1])).abs() < 1e-3, "{leg:?}: y");
        }
    }
}

#[test]
fn ik_then_mujoco_forward_kinematics_returns_the_foot() {
    let mut sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let robot = sim.robot().clone();
    for &(x, z) in &[(0.0, -0.27), (0.12, -0.45), (-0.1, -0.6), (0.2, -0.35)] {
        let q: [[f64; 3]; 4] =
            Leg::ALL.map(|leg| leg_ik(&robot, leg, [x, z], 0.0).expect("reachable"));
        sim.place_robot([0.0, 0.0, 1.5], 0.0, &q);
        let base = sim.base().position;
        for leg in Leg::ALL {
            let hip = robot.hips[leg.index()];
            let axle = sim.wheel_pair_centres()[leg.index()];
            let contact =
                [axle[0] - base[0] - hip[0], axle[2] - robot.wheel_radius - base[2] - hip[2]];
            assert!(
                (contact[0] - x).abs() < 1e-3 && (contact[1] - z).abs() < 1e-3,
                "{leg:?}: {contact:?} vs ({x}, {z})"
            );
        }
    }
}

#[test]
fn description_is_read_from_the_model() {
    let sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let r = sim.robot();
    assert!((r.total_mass - 58.0).abs() < 1.0, "total mass {}", r.total_mass);
    assert!(r.max_leg_length() > 0.45 + 0.2, "legs must reach past the manoeuvre height");
    let fp = r.neutral_footprint();
    assert!((fp[0][0] - fp[2][0]).abs() > 0.5, "feet on a side must be > 0.5 m apart");
}

#[test]
fn urdf_is_in_sync_with_the_mjcf() {
    let sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let generated = momaro::urdf_export::momaro_urdf_string(&sim.urdf_inputs().unwrap()).unwrap();
    let path = common::root().join("models/momaro.urdf");
    let on_disk = std::fs::read_to_string(&path)
        .expect("models/momaro.urdf exists (run `momaro urdf -o models/momaro.urdf`)");
    assert_eq!(
        generated, on_disk,
        "models/momaro.urdf is stale: regenerate with `cargo run -- urdf -o models/momaro.urdf`"
    );

    let urdf = urdf_rs::read_file(&path).expect("URDF parses");
    let r = sim.robot();
    assert_eq!(urdf.joints.len(), 4 * 6);
    for leg in Leg::ALL {
        let p = leg.prefix();
        let j = |name: &str| {
            urdf.joints.iter().find(|j| j.name == format!("{p}_{name}")).expect("joint present")
        };
        let hip = j("hip");
        for k in 0..3 {
            assert!((hip.origin.xyz[k] - r.hips[leg.index()][k]).abs() < 1e-9);
        }
        assert!((j("knee").origin.xyz[2] + r.thigh_length).abs() < 1e-9);
        assert!((j("ankle").origin.xyz[2] + r.shin_length).abs() < 1e-9);
        assert!((j("steer").origin.xyz[2] + r.foot_length).abs() < 1e-9);
        assert!((hip.limit.lower - r.joint_ranges[0].min).abs() < 1e-9);
        assert!(
            (j("wheel_l").origin.xyz[1] - j("wheel_r").origin.xyz[1] - r.wheel_track).abs() < 1e-9
        );
    }
}

#[test]
fn scratch_com_matches_the_simulated_com_and_leaves_the_simulation_alone() {
    let mut sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let q = [[0.9, -1.8, 0.9], [0.9, -1.8, 0.9], [-0.9, 1.8, -0.9], [-0.9, 1.8, -0.9]];
    sim.place_robot([0.3, -0.2, 0.6], 0.4, &q);
    let simulated = sim.center_of_mass();
    let before = sim.base().position;
    let scratch = sim.com_of_configuration([0.3, -0.2, 0.6], [0.0, 0.0, 0.4], &q);
    for k in 0..3 {
        assert!((scratch[k] - simulated[k]).abs() < 1e-9, "{scratch:?} vs {simulated:?}");
    }
    assert_eq!(sim.base().position, before);
    // Rotating only the base rotates the CoM rigidly about the base origin: pitch by −0.2
    // rad (nose up) about the base's y axis, after the yaw of 0.4 rad.
    let pitched = sim.com_of_configuration([0.3, -0.2, 0.6], [0.0, -0.2, 0.4], &q);
    let rel = |c: [f64; 3]| [c[0] - 0.3, c[1] + 0.2, c[2] - 0.6];
    let (sy, cy) = 0.4f64.sin_cos();
    let to_base = |v: [f64; 3]| [cy * v[0] + sy * v[1], -sy * v[0] + cy * v[1], v[2]];
    let level = to_base(rel(scratch));
    let (sp, cp) = (-0.2f64).sin_cos();
    let expected = [cp * level[0] + sp * level[2], level[1], -sp * level[0] + cp * level[2]];
    let got = to_base(rel(pitched));
    for k in 0..3 {
        assert!((got[k] - expected[k]).abs() < 1e-9, "{got:?} vs {expected:?}");
    }
}

#[test]
fn reference_description_for_unit_tests_equals_the_model() {
    let sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let got = sim.robot();
    let reference = momaro::robot::RobotDescription::reference();
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    for i in 0..4 {
        for k in 0..3 {
            assert!(close(got.hips[i][k], reference.hips[i][k]), "hips");
        }
        assert!(close(got.neutral_foot_offset_x[i], reference.neutral_foot_offset_x[i]));
    }
    for (a, b) in [
        (got.thigh_length, reference.thigh_length),
        (got.shin_length, reference.shin_length),
        (got.foot_length, reference.foot_length),
        (got.wheel_radius, reference.wheel_radius),
        (got.wheel_track, reference.wheel_track),
        (got.base_bottom_z, reference.base_bottom_z),
        (got.total_mass, reference.total_mass),
        (got.body_mass, reference.body_mass),
        (got.body_com[0], reference.body_com[0]),
        (got.body_com[1], reference.body_com[1]),
        (got.body_com[2], reference.body_com[2]),
        (got.leg_segment_masses[0], reference.leg_segment_masses[0]),
        (got.leg_segment_masses[1], reference.leg_segment_masses[1]),
        (got.leg_segment_masses[2], reference.leg_segment_masses[2]),
    ] {
        assert!(close(a, b), "{a} vs {b}: update RobotDescription::reference()");
    }
    for k in 0..3 {
        assert!(close(got.base_half_extents[k], reference.base_half_extents[k]));
        assert!(close(got.joint_ranges[k].min, reference.joint_ranges[k].min));
        assert!(close(got.joint_ranges[k].max, reference.joint_ranges[k].max));
    }
}

#[test]
fn planner_com_estimate_equals_mujocos_in_the_horizontal() {
    // The planner's lumped CoM (posture::standing::com_estimate) against MuJoCo's for
    // standing postures like those of a rear step up: pitched base, a rear foot stretched
    // back, front feet forward. Thigh and shin are symmetric about their midpoints and the
    // foot hangs vertically under the ankle, so the horizontal CoM is exact.
    use momaro::posture::kinematics::{Posture, solve_legs};
    use momaro::posture::standing::com_estimate;
    let mut sim = Simulation::robot_only(&common::model()).expect("model compiles");
    let robot = sim.robot().clone();
    let mut checked = 0;
    for (pitch, rear_dx, front_dx) in
        [(0.0, 0.0, 0.0), (-0.12, -0.3, 0.1), (-0.2, -0.1, 0.3), (0.1, 0.2, -0.2)]
    {
        let base = [1.0, 0.5, 0.55];
        let mut feet = robot.hips.map(|h| [base[0] + h[0], base[1] + h[1], 0.0]);
        feet[2][0] += rear_dx;
        feet[0][0] += front_dx;
        let p =
            Posture { base_position: base, base_rpy: [0.0, pitch, 0.0], feet, contact: [true; 4] };
        let q = solve_legs(&robot, &p, 0.0).expect("reachable");
        let truth = sim.com_of_configuration(base, p.base_rpy, &q);
        let est = com_estimate(&robot, &p).expect("reachable");
        let err = (est[0] - truth[0]).hypot(est[1] - truth[1]);
        assert!(err < 1e-6, "pitch {pitch}: estimate {est:?}, MuJoCo {truth:?}");
        checked += 1;
    }
    assert_eq!(checked, 4);
}

#[test]
fn terrain_solids_in_bodies_of_their_own_are_drawn_and_found_as_before() {
    // Every solid of a world is a static body of its own (MuJoCo's broadphase passes over
    // the far ones; `sim::world`). The robot's bodies are still the recordings' bodies,
    // the same as with no terrain at all, and every block's geom is reported as the
    // world's, where the scenario puts it.
    let sc = common::scenario("staircase");
    let sim = Simulation::new(&sc, &common::model()).expect("world compiles");
    let alone = Simulation::robot_only(&common::model()).expect("model compiles");
    let names = |s: &Simulation| s.body_poses().into_iter().map(|b| b.name).collect::<Vec<_>>();
    assert_eq!(names(&sim), names(&alone));
    assert!(names(&sim).iter().all(|n| !n.starts_with("terrain_")), "{:?}", names(&sim));
    let shapes = sim.geom_shapes();
    let mut blocks = 0;
    for (i, prim) in sc.terrain.iter().enumerate() {
        for (k, solid) in prim.solids().iter().enumerate() {
            let Solid::Box { center, height, .. } = *solid else { continue };
            let name = format!("terrain_{i}_{k}");
            let g = shapes.iter().find(|g| g.name == name).expect("a geom per block");
            assert_eq!(g.body, 0, "{name}");
            let expected = [center[0], center[1], height / 2.0];
            let off = (0..3).map(|c| (g.local_position[c] - expected[c]).abs()).fold(0.0, f64::max);
            assert!(off < 1e-9, "{name}: {g:?}");
            blocks += 1;
        }
    }
    assert!(blocks > 5, "{blocks} blocks");
}
