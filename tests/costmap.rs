//! Height maps and cost layers of real scenarios: the laser in MuJoCo agrees with the
//! rasterised map, and `momaro costmap` writes what it promises.

mod common;

use momaro::jobs::costmap::{CostmapOptions, rasterised_map, run, sensed_map};

#[test]
fn mujoco_laser_agrees_with_the_rasterised_map_on_every_seen_cell() {
    // Poles are a few cells across: only their tops can be seen raised.
    for (name, min_raised) in
        [("platform", 100), ("staircase", 100), ("ramp_detour", 100), ("poles", 2)]
    {
        let sc = common::scenario(name);
        let raster = rasterised_map(&sc).unwrap();
        let (sensed, summary) = sensed_map(&sc, &common::model(), &raster).unwrap();
        let a = summary.agreement;
        assert_eq!(a.violations, 0, "{name}: {a:?}");
        assert!(a.max_uniform_error_m <= 0.01, "{name}: {a:?}");
        // Non-vacuous: the laser sees thousands of cells, raised ones among them, and
        // leaves unseen cells unknown.
        assert!(a.uniform_seen > 5_000 && a.raised_seen >= min_raised, "{name}: {a:?}");
        assert!(sensed.known_count() < raster.known_count(), "{name}: everything seen?");
    }
}

#[test]
fn costmap_writes_pngs_and_counts_cells() {
    let sc = common::scenario("platform");
    let dir = common::temp_dir("costmap_png");
    let rrd = dir.join("platform_costmap.rrd");
    let opts = CostmapOptions {
        sensed: false,
        png_dir: Some(dir.clone()),
        rerun: Some(rrd.clone()),
        model_path: common::model(),
    };
    let s = run(&sc, &opts).unwrap();
    assert_eq!(s.images.len(), 4);
    for img in &s.images {
        assert!(img.is_file(), "{} missing", img.display());
    }
    assert!(
        s.infinite_foot_cells > 1000,
        "walls, platform edge and clutter are untraversable: {s:?}"
    );
    // The unknown ring lies in the margin outside the scenario's map only.
    assert!(s.unknown_foot_cells > 0 && s.unknown_height_cells == 0, "{s:?}");
    assert!(rrd.metadata().map(|m| m.len() > 1000).unwrap_or(false));
    // One riser (the platform's edge) is no flight: the paper's models.
    assert_eq!(s.flight_risers, 1);
    assert_eq!((s.foot_model.name(), s.step_model.name()), ("paper", "paper"));
}

#[test]
fn costmap_reports_the_models_the_heights_call_for() {
    // Six stacked boxes, no label, no models named: a flight of six risers, so the
    // wheel pair's footprint and the stairs manoeuvres.
    let opts =
        CostmapOptions { sensed: false, png_dir: None, rerun: None, model_path: common::model() };
    let s = run(&common::scenario("stairs_long_boxes"), &opts).unwrap();
    assert_eq!(s.flight_risers, 6);
    assert!((s.flight_rise_m - 1.02).abs() < 1e-9, "{s:?}");
    assert_eq!((s.foot_model.name(), s.step_model.name()), ("wheel_pair", "stairs"));
}

#[test]
fn flat_scenario_has_unit_costs_everywhere_inside_the_map() {
    let sc = common::scenario("flat");
    let robot = momaro::sim::Simulation::robot_only(&common::model()).unwrap().robot().clone();
    let maps =
        momaro::cost::CostMaps::build(&rasterised_map(&sc).unwrap(), &robot, &sc.params).unwrap();
    for &(x, y, th) in &[(0.0, 0.0, 0.0), (1.0, -1.0, 0.7), (-1.5, 1.2, 1.57)] {
        let pose = momaro::geometry::Pose2::new(x, y, th);
        assert_eq!(maps.driving_pose_cost(&pose).finite(), Some(1.0));
    }
}
