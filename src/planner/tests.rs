//! Tests of the driving graph: straight drives, obstacles, orientation preference, the
//! 20-neighbourhood's effect on ARA*, heuristic consistency, and the `CostMaps` adapter.

use super::*;
use crate::geometry::Pose2;
use crate::params::Params;
use crate::search::{Algorithm, Cost, SearchGraph, SearchParams, Termination, arastar, astar};
use proptest::prelude::*;
use std::f64::consts::FRAC_PI_2;

fn lattice(n: u16, orientations: u16) -> Lattice {
    Lattice { origin: [0.0, 0.0], resolution: 0.025, nx: n, ny: n, orientations }
}

/// A neutral footprint of ±0.4 m × ±0.3 m: turn radius 0.5 m.
fn config(neighbourhood: Neighbourhood) -> DrivingConfig {
    let fp = [[0.4, 0.3], [0.4, -0.3], [-0.4, 0.3], [-0.4, -0.3]];
    DrivingConfig::new(&Params::default(), &fp, neighbourhood)
}

fn flat(_: &Pose2) -> Option<f64> {
    Some(1.0)
}

fn goal(i: i16, j: i16, theta: u8) -> DrivingGoal {
    DrivingGoal { i, j, theta: Some(theta) }
}

#[test]
fn config_turn_radius_from_footprint() {
    assert!((config(Neighbourhood::N16).turn_radius_m - 0.5).abs() < 1e-12);
}

#[test]
fn straight_drive_on_flat_ground_is_exact() {
    let mut g =
        DrivingGraph::new(&flat, lattice(60, 64), config(Neighbourhood::N16), goal(30, 10, 0));
    let r = astar(&mut g, LatticeState::new(10, 10, 0), &SearchParams::default());
    let best = r.best().expect("a path on flat ground");
    assert_eq!(best.cost, Cost::from_f64(0.5)); // 20 cells of 2.5 cm, C = 1, k = 1
    assert!(best.path.iter().all(|s| s.j == 10 && s.theta == 0));
    assert_eq!(best.path.len(), 21);
}

#[test]
fn turning_on_the_spot_costs_wheel_travel() {
    let mut g =
        DrivingGraph::new(&flat, lattice(20, 64), config(Neighbourhood::N16), goal(5, 5, 16));
    let r = astar(&mut g, LatticeState::new(5, 5, 0), &SearchParams::default());
    let best = r.best().expect("path");
    // 16 steps of 2π/64 at 0.5 m: π/4 m of wheel travel.
    let expected = 16.0 * Cost::from_f64_ceil(0.5 * std::f64::consts::TAU / 64.0).to_f64();
    assert!((best.cost.to_f64() - expected).abs() < 1e-9, "{}", best.cost);
    assert!(best.path.iter().all(|s| (s.i, s.j) == (5, 5)));
}

#[test]
fn long_sideways_goal_turns_instead_of_crabbing() {
    // 3 m to the left, heading +x at start and goal: crabbing costs 3 · k12 = 6, turning
    // twice by 90° costs 2 · π/4 and driving forward 3.
    let l = lattice(150, 64);
    let mut g = DrivingGraph::new(&flat, l, config(Neighbourhood::N16), goal(10, 130, 0));
    let r = astar(&mut g, LatticeState::new(10, 10, 0), &SearchParams::default());
    let best = r.best().expect("path");
    assert!(best.cost.to_f64() < 3.0 + FRAC_PI_2 + 0.01, "{}", best.cost);
    let l = g.lattice();
    let max_turn = best.path.iter().map(|s| l.orientation_steps_between(s.theta, 0)).max();
    assert!(max_turn >= Some(8), "turned at most {max_turn:?} steps: crabbed");
}

#[test]
fn backwards_beats_sideways_for_a_short_reverse() {
    // 0.5 m straight behind: reversing costs 0.5 · 1.5 = 0.75; turning around costs π/2
    // and crabbing is worse. The path must keep orientation 0 and drive -x.
    let mut g =
        DrivingGraph::new(&flat, lattice(60, 64), config(Neighbourhood::N16), goal(10, 30, 0));
    let r = astar(&mut g, LatticeState::new(30, 30, 0), &SearchParams::default());
    let best = r.best().expect("path");
    assert!(best.path.iter().all(|s| s.theta == 0 && s.j == 30));
    assert_eq!(best.cost, Cost::from_f64(0.75));
}

/// A wall at i ∈ [29, 31] with a gap at j ∈ [40, 45), untraversable; elsewhere cost 1.
/// (Three cells thick: two-cell moves hop one-cell walls; see `driving`.)
fn walled(p: &Pose2) -> Option<f64> {
    let i = (p.x / 0.025).floor() as i32;
    let j = (p.y / 0.025).floor() as i32;
    if (29..=31).contains(&i) && !(40..45).contains(&j) { None } else { Some(1.0) }
}

#[test]
fn obstacles_are_avoided() {
    let mut g =
        DrivingGraph::new(&walled, lattice(60, 16), config(Neighbourhood::N16), goal(50, 10, 0));
    let r = astar(&mut g, LatticeState::new(10, 10, 0), &SearchParams::default());
    let best = r.best().expect("a path through the gap");
    let mut g2 =
        DrivingGraph::new(&walled, lattice(60, 16), config(Neighbourhood::N16), goal(50, 10, 0));
    for s in &best.path {
        assert!(g2.pose_cost(*s).is_some(), "{s:?} is untraversable");
    }
    assert!(best.path.iter().any(|s| s.i == 30 && (40..45).contains(&s.j)));
    // Closing the gap leaves no path.
    let closed = |p: &Pose2| {
        let i = (p.x / 0.025).floor() as i32;
        if (29..=31).contains(&i) { None } else { Some(1.0) }
    };
    let mut g =
        DrivingGraph::new(&closed, lattice(60, 16), config(Neighbourhood::N16), goal(50, 10, 0));
    let r = astar(&mut g, LatticeState::new(10, 10, 0), &SearchParams::default());
    assert_eq!(r.termination, Termination::NoPath);
}

fn knight_moves(path: &[LatticeState]) -> usize {
    path.windows(2)
        .filter(|w| {
            let (di, dj) = ((w[1].i - w[0].i).abs(), (w[1].j - w[0].j).abs());
            (di, dj) == (2, 1) || (di, dj) == (1, 2)
        })
        .count()
}

#[test]
fn twenty_neighbourhood_straightens_weighted_search() {
    // Fig. 9: at ε = 3, N16 zig-zags with knight moves on a straight drive; N20 does not.
    let p = SearchParams { initial_epsilon: 3.0, final_epsilon: 3.0, ..SearchParams::default() };
    let run = |n: Neighbourhood| {
        let mut g = DrivingGraph::new(&flat, lattice(120, 64), config(n), goal(100, 20, 0));
        let r = arastar(&mut g, LatticeState::new(10, 13, 0), &p).expect("valid");
        r.best().expect("path").path.clone()
    };
    let n16 = run(Neighbourhood::N16);
    let n20 = run(Neighbourhood::N20);
    assert!(knight_moves(&n16) > 0, "N16 path has no knight moves");
    assert!(knight_moves(&n20) < knight_moves(&n16), "N20: {} knight moves", knight_moves(&n20));
}

/// A deterministic rough cost field: 1 to 3, untraversable on ~10 % of the poses
/// (depending on position and orientation, as the body cost does).
fn rough(p: &Pose2) -> Option<f64> {
    let i = (p.x / 0.025).floor() as i64;
    let j = (p.y / 0.025).floor() as i64;
    let k = (p.theta * 100.0).round() as i64;
    let mut h = (i.wrapping_mul(73_856_093)
        ^ j.wrapping_mul(19_349_663)
        ^ k.wrapping_mul(83_492_791)) as u64;
    h ^= h >> 29;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 32;
    if h.is_multiple_of(10) { None } else { Some(1.0 + (h % 1000) as f64 / 500.0) }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn heuristic_is_consistent(
        si in 0i16..40, sj in 0i16..40, st in 0u8..16,
        gi in 0i16..40, gj in 0i16..40, gt in proptest::option::of(0u8..16),
        n20 in any::<bool>(),
    ) {
        let n = if n20 { Neighbourhood::N20 } else { Neighbourhood::N16 };
        let goal = DrivingGoal { i: gi, j: gj, theta: gt };
        let mut g = DrivingGraph::new(&rough, lattice(40, 16), config(n), goal);
        let s = LatticeState::new(si, sj, st);
        let mut out = Vec::new();
        g.successors(s, &mut out);
        let hs = g.heuristic(s);
        for &(t, c) in &out {
            prop_assert!(hs <= c + g.heuristic(t), "h({s:?}) = {hs} > {c} + h({t:?})");
        }
        prop_assert_eq!(g.heuristic(LatticeState::new(gi, gj, gt.unwrap_or(st))), Cost::ZERO);
    }

    #[test]
    fn arastar_ends_at_astar_cost(
        si in 0i16..30, sj in 0i16..30, gi in 0i16..30, gj in 0i16..30, gt in 0u8..8,
    ) {
        let l = lattice(30, 8);
        let start = LatticeState::new(si, sj, 0);
        let goal = goal(gi, gj, gt);
        let mut a = DrivingGraph::new(&rough, l, config(Neighbourhood::N20), goal);
        let exact = astar(&mut a, start, &SearchParams::default());
        let mut b = DrivingGraph::new(&rough, l, config(Neighbourhood::N20), goal);
        let any = arastar(&mut b, start, &SearchParams::default()).expect("valid");
        prop_assert_eq!(exact.best().map(|s| s.cost), any.best().map(|s| s.cost));
        if let (Some(first), Some(opt)) = (any.first(), exact.best()) {
            prop_assert!(first.cost.0 as f64 <= 3.0 * opt.cost.0 as f64);
        }
    }
}

#[test]
fn plan_driving_snaps_poses_and_reports_off_map() {
    let l = lattice(60, 64);
    let cfg = config(Neighbourhood::N20);
    let r = plan_driving(
        flat,
        l,
        cfg,
        &Pose2::new(0.26, 0.26, 0.0),
        &Pose2::new(1.01, 0.26, 0.0),
        Algorithm::AraStar,
        &SearchParams::default(),
        Default::default(),
    )
    .expect("on the map");
    assert_eq!(r.termination, Termination::OptimalProven);
    assert_eq!(r.best().map(|s| s.cost), Some(Cost::from_f64(0.75)));
    let off = plan_driving(
        flat,
        l,
        cfg,
        &Pose2::new(-0.5, 0.26, 0.0),
        &Pose2::new(1.0, 0.26, 0.0),
        Algorithm::AStar,
        &SearchParams::default(),
        Default::default(),
    );
    assert!(matches!(off, Err(DrivingPlanError::StartOffMap(_))));
}

#[test]
fn cost_maps_adapter_gives_one_on_flat_ground() {
    use crate::cost::CostMaps;
    use crate::robot::RobotDescription;
    use crate::terrain::HeightMap;
    let robot = RobotDescription::reference();
    let map = HeightMap::filled([0.0, 0.0], 0.025, 120, 120, 0.0).expect("map");
    let costs = CostMaps::build(&map, &robot, &Params::default()).expect("cost maps");
    let l = Lattice::for_map(&map, 64).expect("lattice");
    let centre = l.pose(LatticeState::new(60, 60, 5));
    let c = (&costs).driving_cost(&centre).expect("flat ground is traversable");
    assert!((c - 1.0).abs() < 1e-9, "{c}");
    // Off the map: no cost.
    assert_eq!((&costs).driving_cost(&Pose2::new(-1.0, 0.0, 0.0)), None);
    // A drive across the middle of the flat map costs its length.
    let cfg =
        DrivingConfig::new(&Params::default(), &robot.neutral_footprint(), Neighbourhood::N16);
    let mut g = DrivingGraph::new(&costs, l, cfg, goal(80, 60, 0));
    let r = astar(&mut g, LatticeState::new(40, 60, 0), &SearchParams::default());
    assert_eq!(r.best().map(|s| s.cost), Some(Cost::from_f64(1.0)));
}

#[test]
fn the_probes_guidance_drops_the_cost_to_go_and_its_greedy_one_counts_the_feet_way() {
    // h = max(2, 15) + 30 + 1 − 0.5 = 45.5; guidance = 2 + 30 + 1 − 0.5 = 32.5; the
    // greedy list's = 2 + 30 + 0.25 − 0.125 = 32.125 (the offsets at its own weight).
    let u = |v: f64| Cost::from_f64(v);
    let p = HeuristicParts {
        reachable: Cost::ZERO,
        driving: u(2.0),
        to_go: u(15.0),
        steps: u(30.0),
        behind: u(1.0),
        ahead: u(0.5),
        greedy_behind: u(0.25),
        greedy_ahead: u(0.125),
        way: u(1.5),
    };
    assert_eq!(p.total(), u(45.5));
    assert_eq!((p.guidance(), p.greedy_guidance()), (u(32.5), u(32.125)));
    // The feet's way over climbable terrain replaces the straight line where it is longer,
    // in the greedy list only (9 + 30 + 0.25 − 0.125), and leaves the heuristic and the
    // weighted guidance alone.
    let around = HeuristicParts { way: u(9.0), ..p };
    assert_eq!(around.total(), u(45.5));
    assert_eq!((around.guidance(), around.greedy_guidance()), (u(32.5), u(39.125)));
    // Clamped at zero; infinite where the base cannot reach.
    let ahead = HeuristicParts { ahead: u(40.0), greedy_ahead: u(40.0), ..p };
    assert_eq!((ahead.total(), ahead.guidance()), (u(6.0), Cost::ZERO));
    assert_eq!(ahead.greedy_guidance(), Cost::ZERO);
    let unreachable = HeuristicParts { reachable: Cost::INFINITY, ..p };
    assert!(unreachable.guidance().is_infinite() && unreachable.greedy_guidance().is_infinite());
}
