//! Tests of the hybrid graph with the robot's manoeuvres (steps, base shifts, foot
//! moves) on rasterised maps with Momaro's dimensions (as the model gives them).

use super::ALL;
use super::base_shift::base_shift_cost;
use super::step::step_cost;
use super::wheel_move::{WheelMovePlanner, foot_move_cost};
use crate::cost::CostMaps;
use crate::geometry::Pose2;
use crate::params::Params;
use crate::path::{EdgeLabel, ManoeuvreKind};
use crate::planner::*;
use crate::robot::{Leg, RobotDescription};
use crate::scenario::terrain::{Block, Primitive, Stairs};
use crate::search::{Cost, SearchGraph, SearchParams, Termination, arastar, astar};
use crate::terrain::rasterise;

fn robot() -> RobotDescription {
    RobotDescription::reference()
}

/// A 4 m × 2 m map from (−1, −1) with a platform of `height` from x = 1 m on.
fn platform_maps(height: f64) -> CostMaps {
    let prims =
        [Primitive::Box(Block { center: [2.0, 0.0], size: [2.0, 2.0], height, yaw_deg: 0.0 })];
    let m = rasterise(&prims, [-1.0, -1.0], [4.0, 2.0], 0.025).expect("map");
    CostMaps::build(&m, &robot(), &Params::default()).expect("cost maps")
}

fn graph<'c>(maps: &'c CostMaps, goal: LatticeState) -> HybridGraph<'c> {
    let cfg = HybridConfig::new(&Params::default(), &robot(), Neighbourhood::N16);
    HybridGraph::new(maps, &robot(), 64, cfg, DrivingGoal::at(goal), &ALL).expect("graph")
}

fn state_at(g: &HybridGraph<'_>, x: f64, y: f64) -> LatticeState {
    g.lattice().state(&Pose2::new(x, y, 0.0)).expect("on the map")
}

/// The lattice state at pose (x, y, yaw) of any graph on `maps` (64 orientations, as
/// `graph` builds them), without building one.
fn state_on(maps: &CostMaps, x: f64, y: f64, yaw: f64) -> LatticeState {
    let lattice = Lattice::for_map(maps.heights(), 64).expect("lattice");
    lattice.state(&Pose2::new(x, y, yaw)).expect("on the map")
}

fn config() -> HybridConfig {
    HybridConfig::new(&Params::default(), &robot(), Neighbourhood::N16)
}

#[test]
fn a_doorway_in_a_wall_whose_top_no_foot_reaches_is_closed_at_once() {
    // `impossible_005111` (generated), square to the map: a 0.31 m doorway in a wall
    // 0.98 m high and 0.29 m thick. The middle of its top lies more than r_F from its
    // edges, so a foot's cost there is finite, and the reachable regions counted it
    // as ground a foot might stand on: every pose near the wall could then stand
    // 0.98 m up, and the regions let the base over it (the search took 958 k
    // expansions, 15 s, to prove no path). No foot climbs 0.98 m, so the step bound
    // is infinite there, and such ground now does not count.
    let prims = crate::planner::heuristic::reachability::tests::doorway(0.31, 0.29, 0.98);
    let m = rasterise(&prims, [-1.0, -2.0], [6.0, 4.0], 0.025).expect("map");
    let maps = CostMaps::build(&m, &robot(), &Params::default()).expect("cost maps");
    let (i, j) = maps.heights().cell_of(2.0, 1.0).expect("on the map");
    assert!(maps.foot_cost_cell(i, j).finite().is_some(), "the wall's top is standable");
    let g = graph(&maps, state_on(&maps, 4.0, 0.0, 0.0));
    assert!(g.heuristic_parts(state_at(&g, 0.0, 0.0)).reachable.is_infinite());
    assert!(!g.heuristic_parts(state_at(&g, 3.5, 0.5)).reachable.is_infinite());
}

/// Runs one of the generator's own checks (`check`) as the planner does, from posture
/// `pre`: the CoM estimate, the planner's margins (`options`).
fn with_generator<T>(
    robot: &RobotDescription,
    maps: &CostMaps,
    options: &crate::feasibility::MotionOptions,
    pre: crate::posture::Posture,
    check: impl FnOnce(&mut crate::motion::Expander<'_>) -> T,
) -> T {
    let mut model = crate::posture::standing::EstimatedCom { robot };
    check(&mut crate::motion::Expander::for_check(robot, maps, &mut model, options, pre))
}

/// The abstract steps among `s`'s successors, in the graph's order.
fn step_edges(g: &mut HybridGraph<'_>, s: LatticeState) -> Vec<(LatticeState, Cost, EdgeLabel)> {
    let mut all = g.labelled_successors(s);
    all.retain(|(_, _, m)| m.kind == ManoeuvreKind::Step);
    all
}

#[test]
fn a_graph_asked_only_for_edges_builds_no_heuristic() {
    // `jobs::plan` prices a path on a second graph (k12 = 1) through `edge` alone;
    // it built the step bound and the regions for nothing (~70 ms on the platform).
    let maps = platform_maps(0.2);
    let goal = state_on(&maps, 2.0, 0.0, 0.0);
    let mut g = graph(&maps, goal);
    let s = state_at(&g, 0.0, 0.0);
    let t = g.labelled_successors(s).first().expect("a successor").0;
    assert!(g.edge(s, t).is_some());
    assert!(!g.heuristic_built());
    assert!(g.heuristic(s) > Cost::ZERO);
    assert!(g.heuristic_built());
}

#[test]
fn graphs_sharing_a_heuristic_cache_build_the_tables_once() {
    let maps = platform_maps(0.2);
    let goal = state_on(&maps, 2.0, 0.0, 0.0);
    let cache = HeuristicCache::default();
    let first = graph(&maps, goal).with_heuristic_cache(&cache);
    let s = state_at(&first, -0.5, 0.0);
    let h = first.heuristic(s);
    assert!(!first.heuristic_reused());
    assert!(first.heuristic_setup_time() > std::time::Duration::ZERO);
    let nodes = first.cost_to_go_nodes();
    assert!(nodes > 0);
    // Same map, robot, configuration and goal: taken over, with the nodes settled.
    let second = graph(&maps, goal).with_heuristic_cache(&cache);
    assert!(second.heuristic_reused());
    assert_eq!(second.heuristic_setup_time(), std::time::Duration::ZERO);
    assert_eq!(second.cost_to_go_nodes(), nodes);
    assert_eq!(second.heuristic(s), h);
    // The same values as tables of its own, also where the first never asked.
    let fresh = graph(&maps, goal);
    for (x, y) in [(-0.9, -0.8), (0.3, 0.7), (1.5, 0.0), (2.9, 0.9)] {
        let t = state_at(&fresh, x, y);
        assert_eq!(second.heuristic(t), fresh.heuristic(t), "at ({x}, {y})");
    }
    // Another goal, configuration or map: tables of its own.
    let elsewhere = graph(&maps, state_on(&maps, 2.5, 0.5, 0.0)).with_heuristic_cache(&cache);
    assert!(!elsewhere.heuristic_reused());
    let plain = Params { k12: 1.0, ..Params::default() };
    let cfg = HybridConfig::new(&plain, &robot(), Neighbourhood::N16);
    let priced = HybridGraph::new(&maps, &robot(), 64, cfg, DrivingGoal::at(goal), &ALL)
        .expect("graph")
        .with_heuristic_cache(&cache);
    assert!(!priced.heuristic_reused());
    let copy = platform_maps(0.2);
    assert!(!graph(&copy, goal).with_heuristic_cache(&cache).heuristic_reused());
}

#[test]
fn a_later_search_thaws_the_cost_to_go_an_earlier_deadline_froze() {
    let maps = platform_maps(0.2);
    let goal = state_on(&maps, 2.0, 0.0, 0.0);
    let cache = HeuristicCache::default();
    let first = graph(&maps, goal).with_heuristic_cache(&cache);
    // A deadline already past: the first query freezes the cost-to-go at once.
    first.set_heuristic_deadline(Some(std::time::Instant::now()));
    let s = state_at(&first, -0.5, 0.0);
    let frozen = first.heuristic(s);
    assert!(first.heuristic_frozen());
    let second = graph(&maps, goal).with_heuristic_cache(&cache);
    let fresh = graph(&maps, goal);
    assert_eq!(second.heuristic(s), fresh.heuristic(s));
    assert!(!second.heuristic_frozen());
    assert!(second.heuristic(s) > frozen, "{:?} {frozen:?}", second.heuristic(s));
}

#[test]
fn manoeuvre_costs_by_hand() {
    let c = config();
    // eq. 5: 0.5 · 0.45 + 0.1 · (3 − 1) + 2.3 · 0.2 = 0.225 + 0.2 + 0.46.
    assert!((step_cost(&c, 0.45, 3.0, 0.2) - 0.885).abs() < 1e-12);
    // C_BS = 0.5 · 0.4 · 1.1.
    assert!((base_shift_cost(&c, 0.4, 1.1) - 0.22).abs() < 1e-12);
    // eq. 6: 0.125 · 0.1 · 2.
    assert!((foot_move_cost(&c, 0.1, 2.0) - 0.025).abs() < 1e-12);
    assert_eq!(c.step_cost_factor, Params::default().step_cost_factor);
}

#[test]
fn reach_comes_from_the_leg_ik() {
    let maps = platform_maps(0.2);
    let g = graph(&maps, LatticeState::new(0, 0, 0));
    // The widest range over all manoeuvre leg heights (0.45 m down by the largest
    // step, 0.3 m): with the ankle level with the hip (leg 0.18 m) thigh and shin
    // reach 0.5 m = 20 cells. At 0.45 m the ankle is 0.27 m below the hip:
    // √(0.5² − 0.27²) = 0.42 m, 16 cells (the base shift test below relies on it).
    for leg in 0..4 {
        assert_eq!(g.reach()[leg], [-20, 20], "leg {leg}");
    }
}

#[test]
fn no_steps_far_from_obstacles() {
    let maps = platform_maps(0.2);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 0.0, 0.0);
    let succ = g.labelled_successors(s);
    assert_eq!(succ.len(), 18, "16 moves and 2 turns");
    assert!(succ.iter().all(|(_, _, m)| !m.kind.is_step_related()));
}

#[test]
fn front_steps_onto_a_platform_cost_eq_5() {
    let maps = platform_maps(0.2);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    // Front feet at x = 0.5125 + 0.35 = 0.8625, 0.1375 m before the edge: within
    // 0.1 m of the infinite band (0.12 m around the edge cells at 0.9875 / 1.0125).
    let s = state_at(&g, 0.505, 0.0);
    let steps = step_edges(&mut g, s);
    let legs: Vec<_> = steps.iter().map(|(_, _, m)| m.leg).collect();
    assert_eq!(legs, vec![Some(Leg::FrontLeft), Some(Leg::FrontRight)]);
    for (t, c, m) in &steps {
        let st = m.step.expect("step details");
        // The cheapest foothold: flat (C_F = 1) platform, 0.45 m ahead (18 cells,
        // the reach of a leg 0.2 m shorter with 2 cm to spare), ΔH = 0.2.
        assert!((st.length_m - 0.45).abs() < 1e-9, "{st:?}");
        assert_eq!(st.foothold_cost, 1.0);
        assert!((st.height_m - 0.2).abs() < 1e-12);
        let c_s = 0.5 * 0.45 + 2.3 * 0.2;
        assert!((st.c_s - c_s).abs() < 1e-12);
        let f = Params::default().step_cost_factor;
        assert_eq!(*c, Cost::from_f64_ceil(f * c_s * (1.0 - 1e-12)));
        assert_eq!((t.i, t.j, t.theta), (s.i, s.j, s.theta), "the base stays");
        let o = g.offsets(*t).expect("interned");
        assert_eq!(o.iter().filter(|&&v| v == 18).count(), 1);
    }
}

#[test]
fn step_height_and_support_criteria() {
    // Criterion 3: a 0.35 m platform cannot be stepped onto.
    let maps = platform_maps(0.35);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 0.48, 0.0);
    assert!(g.labelled_successors(s).iter().all(|(_, _, m)| m.kind != ManoeuvreKind::Step));
    // Criterion 4: once the front left foot has stepped 19 cells, the rear left foot
    // is close to nothing, but the rear feet's support sides are fine; a rear step is
    // only offered where a rear foot is near the edge. After both front steps, no
    // further front step exists (the feet are on the flat platform, far from it).
    let maps = platform_maps(0.2);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 0.48, 0.0);
    let fl = g
        .labelled_successors(s)
        .into_iter()
        .find(|(_, _, m)| m.leg == Some(Leg::FrontLeft))
        .expect("front left step")
        .0;
    let after: Vec<_> = g.labelled_successors(fl);
    assert!(
        after
            .iter()
            .any(|(_, _, m)| m.leg == Some(Leg::FrontRight) && m.kind == ManoeuvreKind::Step)
    );
    assert!(
        after
            .iter()
            .all(|(_, _, m)| !(m.leg == Some(Leg::FrontLeft) && m.kind == ManoeuvreKind::Step))
    );
}

#[test]
fn rear_steps_the_generator_expands_are_offered() {
    // The paper's platform (0.2 m), neutral footprint, front feet on it, rear feet
    // 0.16 m before its edge (`scenarios/platform.toml` at x = 4.1875). Every rear
    // foothold needs the generator's alignment (partner wheel, roll, base shift): at
    // the unaligned stance the CoM lies within 5.5 cm of the support triangle's edge.
    // The planner's CoM-in-triangle pre-check turned all of them away, though the
    // generator expands them, and offered no rear step here.
    let maps = platform_maps(0.2);
    let robot = robot();
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 1.1875, 0.0);
    let steps = step_edges(&mut g, s);
    let legs: Vec<_> = steps.iter().filter_map(|(_, _, m)| m.leg).collect();
    assert!(legs.contains(&Leg::RearLeft) && legs.contains(&Leg::RearRight), "{legs:?}");
    // Each offered step is one the generator expands from the rule's stance.
    let motion = g.config().motion;
    let rule = motion.standing;
    let pose = g.lattice().pose(s);
    let ground = |f: [f64; 2]| [f[0], f[1], maps.height_at(f[0], f[1]).expect("ground")];
    let world = g.feet(s).expect("feet").map(ground);
    let xy = [pose.x, pose.y];
    let (pre, _) = rule.stand(&robot, maps.leg_terrain(), world, xy, pose.theta).expect("stands");
    for (t, _, m) in &steps {
        let leg = m.leg.expect("a step's leg");
        let post = ground(g.feet(*t).expect("feet")[leg.index()]);
        let heights = rule.step_heights(
            &robot,
            maps.heights(),
            maps.leg_terrain(),
            world,
            leg.index(),
            post,
            xy,
            pose.theta,
        );
        let r = with_generator(&robot, &maps, &motion, pre, |ex| {
            super::step::check(ex, leg, post, heights)
        });
        assert!(r.is_ok(), "{leg:?} to {post:?}: {r:?}");
    }
}

#[test]
fn front_steps_onto_a_block_taller_than_the_two_tallest_stances_allow() {
    // A front foot onto 0.24 m: at the two tallest leg heights of the shared rule
    // (0.35 and 0.34 m for this step) the stance rolled toward the support triangle
    // leaves the stretched rear leg on that side no reach; from 0.31 m down it holds.
    // The planner once tried only those two heights and refused every block above
    // ~0.21 m (generated up-and-over courses of 0.22–0.25 m: "no path").
    let maps = platform_maps(0.24);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 0.5, 0.0);
    let legs: Vec<_> = step_edges(&mut g, s)
        .into_iter()
        .map(|(_, _, m)| (m.leg, m.step.expect("step details").height_m))
        .collect();
    assert_eq!(legs.len(), 2, "{legs:?}");
    for (leg, height) in legs {
        assert!(matches!(leg, Some(Leg::FrontLeft | Leg::FrontRight)));
        assert!((height - 0.24).abs() < 1e-9, "{height}");
    }
}

#[test]
fn the_roll_finds_the_front_foot_move_that_trying_the_longest_first_finds() {
    // The longest feasible front-foot-forward move is found by rolling the foot cell
    // by cell up to the first cell or segment that fails; trying every move longest
    // first (as before) must pick the same. Poses before, on and across a platform's
    // edge, at several headings, with feet behind and ahead of neutral, so that the
    // longest move, a shorter one and none at all are each chosen.
    let maps = platform_maps(0.2);
    let goal = LatticeState::new(0, 0, 0);
    let (mut rolled, mut tried) = (graph(&maps, goal), graph(&maps, goal));
    let footprints: [FootOffsets; 5] =
        [[0, 0, 0, 0], [0, 0, -8, -8], [6, 0, -4, 0], [0, 10, 0, -12], [12, 12, -16, -16]];
    let (mut longest, mut shorter, mut none) = (0, 0, 0);
    for x in [0.2, 0.45, 0.6, 0.8, 1.05, 1.3] {
        for y in [-0.2, 0.0, 0.25] {
            for yaw in [0.0, 0.3, -0.6, 1.2] {
                let at = state_on(&maps, x, y, yaw);
                for o in footprints {
                    let (Some(a), Some(b)) =
                        (rolled.with_offsets(at, o), tried.with_offsets(at, o))
                    else {
                        continue;
                    };
                    for k in [0, 1] {
                        let (by_roll, end) =
                            WheelMovePlanner::default().forward_move(&mut rolled, a, k, false);
                        let (by_trying, _) =
                            WheelMovePlanner::default().forward_move(&mut tried, b, k, true);
                        assert_eq!(by_roll, by_trying, "({x}, {y}, {yaw}) {o:?} leg {k}");
                        match (by_roll, end) {
                            (None, Some(_)) => none += 1,
                            (Some(to), Some(end)) if to[k] == end => longest += 1,
                            (Some(_), _) => shorter += 1,
                            (None, None) => {}
                        }
                    }
                }
            }
        }
    }
    assert!(longest > 0 && shorter > 0 && none > 0, "{longest} {shorter} {none}");
}

#[test]
fn base_shift_after_both_front_steps_costs_c_bs() {
    let maps = platform_maps(0.2);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 0.505, 0.0);
    let fl = g
        .labelled_successors(s)
        .into_iter()
        .find(|(_, _, m)| m.leg == Some(Leg::FrontLeft))
        .expect("front left step")
        .0;
    let both = g
        .labelled_successors(fl)
        .into_iter()
        .find(|(_, _, m)| m.kind == ManoeuvreKind::Step)
        .expect("front right step")
        .0;
    assert_eq!(g.offsets(both), Some([18, 18, 0, 0]));
    let (t, c, m) = g
        .labelled_successors(both)
        .into_iter()
        .find(|(_, _, m)| m.kind == ManoeuvreKind::BaseShift)
        .expect("base shift");
    // Until the rear legs, stretched back over the floor, are at the end of their reach
    // by the standing rule (Sec. VI-B: base pitched 70 % of the slope, its height set
    // by the front feet on the platform): the robot can stand at the shift's end and
    // not one cell further.
    let o = g.offsets(t).expect("interned");
    let l = i32::from(o[0]) - 18;
    assert!(l < 0 && o == [o[0], o[0], l as i8, l as i8], "{o:?}");
    assert_eq!(i32::from(t.i - s.i), -l);
    assert!((m.length_m - f64::from(-l) * 0.025).abs() < 1e-9);
    let robot = RobotDescription::reference();
    let rule = crate::posture::StandingRule::from_params(&Params::default());
    let stands = |cells: i32| {
        let base = 0.505 + f64::from(s.i - state_at(&g, 0.505, 0.0).i) * 0.025;
        let x = base + f64::from(cells) * 0.025;
        let feet = [
            [base + 0.35 + 0.45, 0.32, 0.2],
            [base + 0.35 + 0.45, -0.32, 0.2],
            [base - 0.35, 0.32, 0.0],
            [base - 0.35, -0.32, 0.0],
        ];
        rule.stand(&robot, maps.heights(), feet, [x, 0.0], 0.0).is_ok()
    };
    assert!(stands(-l) && !stands(-l + 1), "shift of {} cells", -l);
    // C_B,avg = 1 + k3 · 0.2 = 1.1 (front feet 0.2 m higher; the legs are long
    // enough that the base clears everything): C_BS = 0.5 · L · 1.1.
    let f = Params::default().step_cost_factor;
    let c_bs = 0.5 * m.length_m * 1.1;
    assert!((m.cost - f * c_bs).abs() < 1e-9, "{m:?}");
    assert_eq!(c, Cost::from_f64_ceil(f * c_bs * (1.0 - 1e-12)));
}

#[test]
fn a_base_shift_toward_the_goal_leaves_the_greedy_lists_estimate_level() {
    // The base 0.3 m nearer the goal straight ahead, all four feet where they stood
    // (0.3 m behind neutral): the straight line drops by 0.3, the offsets' share of
    // the greedy list's estimate rises by 4 × 0.25 × 0.3. At the heuristic's own
    // weight (c = f · k11 · C_F,min = 10.75 · 0.125 = 1.34 per metre) the guidance
    // rises by 4c · 0.3 − 0.3 = 1.3125, a hill the greedy list, ordered by it, crossed
    // only after every state below it.
    let maps = platform_maps(0.2);
    let mut g = graph(&maps, state_on(&maps, 2.5, 0.0, 0.0));
    let s = state_at(&g, -0.5, 0.0);
    let t = state_at(&g, -0.2, 0.0);
    assert_eq!(t.i - s.i, 12);
    let t = g.with_offsets(t, [-12; 4]).expect("interned");
    let (before, after) = (g.heuristic_parts(s), g.heuristic_parts(t));
    assert_eq!(before.steps, after.steps, "the feet stand where they stood");
    let drop = before.driving.0 as i64 - after.driving.0 as i64;
    assert!((drop - Cost::from_f64(0.3).0 as i64).abs() <= 2, "{drop}");
    let rise = after.greedy_guidance().0 as i64 - before.greedy_guidance().0 as i64;
    assert!(rise.abs() <= 2, "the greedy estimate moved by {rise} micro-units");
    let hill = after.guidance().to_f64() - before.guidance().to_f64();
    assert!((hill - 1.3125).abs() < 1e-4, "{hill}");
    // The heuristic itself keeps Φ at c (its cost-to-go pays for the rise), per cell
    // rounded down to the micro-unit.
    let c = Params::default().step_cost_factor * Params::default().k11;
    assert!((after.behind.to_f64() - 4.0 * c * 0.3).abs() < 1e-4, "{:?}", after.behind);
}

#[test]
fn feet_back_to_neutral_one_at_a_time_cost_eq_6() {
    let maps = platform_maps(0.2);
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = state_at(&g, 0.0, 0.0);
    let t = g.with_offsets(s, [0, 0, -8, -4]).expect("interned");
    let fms: Vec<_> = g
        .labelled_successors(t)
        .into_iter()
        .filter(|(_, _, m)| m.kind == ManoeuvreKind::FootNeutral)
        .collect();
    // Only the first movable foot (RL) is offered; flat ground: C_F,avg = 1.
    assert_eq!(fms.len(), 1);
    let (u, _, m) = fms[0];
    assert_eq!(m.leg, Some(Leg::RearLeft));
    assert_eq!(g.offsets(u), Some([0, 0, 0, -4]));
    let f = Params::default().step_cost_factor;
    assert!((m.cost - f * 0.125 * 0.2 * 1.0).abs() < 1e-12);
    assert!(g.driving_pose_cost(s).is_some());
}

#[test]
fn a_foot_short_of_an_edge_rolls_up_to_it_cost_eq_6() {
    // Both front feet 0.4 m behind neutral, their neutral spots on the 0.2 m platform
    // (x ≥ 1 m): the way to neutral climbs the edge, and FL is too far from it to
    // step. Before, no move reached the edge and a rear foot short of a stair's riser
    // stayed there (flights of four steps had no path). Stairs step model only.
    let maps = platform_maps(0.2);
    let params = Params { step_model: crate::params::StepModel::Stairs, ..Params::default() };
    let c = HybridConfig::new(&params, &robot(), Neighbourhood::N16);
    let goal = DrivingGoal::at(LatticeState::new(0, 0, 0));
    let mut g = HybridGraph::new(&maps, &robot(), 64, c, goal, &ALL).expect("graph");
    let nfx = robot().neutral_footprint()[0][0];
    let s = state_at(&g, 1.1 - nfx, 0.0);
    let t = g.with_offsets(s, [-16, -16, 0, 0]).expect("interned");
    let fms: Vec<_> = g
        .labelled_successors(t)
        .into_iter()
        .filter(|(_, _, m)| m.kind == ManoeuvreKind::FootNeutral)
        .collect();
    assert_eq!(fms.len(), 1, "{fms:?}");
    let (u, _, m) = fms[0];
    assert_eq!(m.leg, Some(Leg::FrontLeft));
    let to = g.offsets(u).expect("footprint")[0];
    assert!((-15..0).contains(&to), "rolled to offset {to}");
    // It stops at the last cell a wheel pair can drive on: one more cell is the edge's
    // untraversable band.
    let feet = g.feet(u).expect("feet");
    let res = g.lattice().resolution;
    let cf = |x: f64| maps.foot_cost_at_heading(x, feet[0][1], 0.0);
    assert!(cf(feet[0][0]).is_finite());
    assert!(!cf(feet[0][0] + res).is_finite());
    // eq. 6 over the cells rolled, both ends included, times the step-related factor.
    let from = g.feet(t).expect("feet")[0][0];
    let cells = i32::from(to) + 16;
    let avg =
        (0..=cells).map(|k| cf(from + f64::from(k) * res).finite().expect("drivable")).sum::<f64>()
            / f64::from(cells + 1);
    let expected = c.step_cost_factor * foot_move_cost(&c, f64::from(cells) * res, avg);
    assert!((m.cost - expected).abs() < 1e-9, "{} vs {expected}", m.cost);
}

#[test]
fn every_wheel_move_offered_past_a_block_edge_is_one_the_generator_expands() {
    // Generated up_and_over seed 3: coming down a 0.229 m block at 174.4°, front feet
    // on the floor, rear feet on the block. The front-left pair's roll forward stands
    // at every cell (the planner's check before), but between two cells the knee
    // passes 3.7 cm over the block's edge, within the legs' 4 cm clearance: the
    // generator rejected the planned path ("wheel_move: at 33 % of the segment").
    let robot = robot();
    let block = |center: [f64; 2], size: [f64; 2], height: f64, yaw_deg: f64| {
        Primitive::Box(Block { center, size, height, yaw_deg })
    };
    let prims = [
        block([-0.57, 0.002], [1.14, 5.581], 0.229, 178.2),
        block([-0.5, -1.315], [7.8, 0.15], 0.8, -180.0),
        block([-0.5, 1.315], [7.8, 0.15], 0.8, -180.0),
    ];
    let m = rasterise(&prims, [-3.4, -1.7], [5.8, 3.4], 0.025).expect("map");
    let maps = CostMaps::build(&m, &robot, &Params::default()).expect("cost maps");
    let mut g = graph(&maps, LatticeState::new(0, 0, 0));
    let s = g.lattice().state(&Pose2::new(-1.0125, -0.3625, 3.0434)).expect("on the map");
    let motion = g.config().motion;
    let rule = motion.standing;
    let mut checked = 0;
    for fl in 0..=4 {
        let o = [fl, 16, 0, -18];
        let t = g.with_offsets(s, o).expect("interned");
        let pose = g.lattice().pose(t);
        let feet = g.feet(t).expect("feet");
        let world = feet.map(|f| [f[0], f[1], maps.height_at(f[0], f[1]).expect("ground")]);
        let Ok((pre, _)) =
            rule.stand(&robot, maps.leg_terrain(), world, [pose.x, pose.y], pose.theta)
        else {
            continue;
        };
        for (u, _, man) in g.labelled_successors(t) {
            let Some(leg) = man.leg else { continue };
            if !matches!(man.kind, ManoeuvreKind::FootForward | ManoeuvreKind::FootNeutral) {
                continue;
            }
            let to = g.feet(u).expect("feet")[leg.index()];
            let r = with_generator(&robot, &maps, &motion, pre, |ex| {
                super::wheel_move::check(ex, leg, to)
            });
            assert!(r.is_ok(), "{o:?}: {leg:?} to {:?}: {r:?}", g.offsets(u));
            checked += 1;
        }
    }
    assert!(checked > 0, "no wheel move offered");
}

#[test]
fn steps_down_0_3_m_between_walls_with_the_descent_shift() {
    // A 0.3 m platform ending at x = 1.0, between walls 1.3 m apart, the robot on it
    // facing the edge. From hips over its feet no front step down holds: lifted over
    // the edge the leg folds past the knee's limit at every height at which it still
    // reaches the floor beyond the untraversable band. Every drop of 0.24-0.30 m
    // answered "no path" after searching the whole map; with the descent shift (the
    // hip over the middle of the step first) the robot steps down head-on.
    let wall = |y: f64| {
        Primitive::Box(Block { center: [1.5, y], size: [6.0, 0.2], height: 1.0, yaw_deg: 0.0 })
    };
    let prims = [
        Primitive::Box(Block { center: [-0.25, 0.0], size: [2.5, 3.0], height: 0.3, yaw_deg: 0.0 }),
        wall(0.75),
        wall(-0.75),
    ];
    let m = rasterise(&prims, [-1.5, -1.5], [6.0, 3.0], 0.025).expect("map");
    let maps = CostMaps::build(&m, &robot(), &Params::default()).expect("cost maps");
    let (start, goal) = (state_on(&maps, 0.0, 0.0, 0.0), state_on(&maps, 3.4, 0.0, 0.0));
    let mut g = graph(&maps, goal);
    let search =
        SearchParams { initial_epsilon: 3.0, final_epsilon: 3.0, ..SearchParams::default() };
    let r = arastar(&mut g, start, &search).expect("valid params");
    let best = r.best().unwrap_or_else(|| panic!("no path: {:?}", r.termination));
    let labels: Vec<EdgeLabel> =
        best.path.windows(2).filter_map(|w| g.edge(w[0], w[1]).map(|(_, m)| m)).collect();
    let steps = labels.iter().filter(|m| m.kind == ManoeuvreKind::Step).count();
    assert_eq!(steps, 4, "every foot steps down once");
    // A base shift leaves both front feet behind neutral before the first step.
    let first_step = best
        .path
        .windows(2)
        .position(|w| g.edge(w[0], w[1]).is_some_and(|(_, m)| m.kind == ManoeuvreKind::Step))
        .expect("a step");
    assert!(
        best.path[..=first_step]
            .iter()
            .any(|&t| g.offsets(t).is_some_and(|o| o[0] < 0 && o[1] < 0)),
        "no descent shift before the first step"
    );
}

#[test]
fn translated_step_failures_turn_away_only_steps_that_fail() {
    // A straight drop, 0.3 m (the step-down scenario's) for y < 0 and 0.2 m beyond,
    // and a 0.2 m strip across the floor further on: from stances along the drop,
    // before and after the descent shift, and before the strip, at two headings, the
    // steps offered with failed checks taken over from other cells are those the
    // checks give alone; some are taken over, each where the check fails. Front steps
    // down 0.3 m fail from stances that step down 0.2 m: without the terrain's print
    // in the key, the first would turn the second away.
    let prims = [
        Primitive::Box(Block {
            center: [-0.25, -1.5],
            size: [2.5, 3.0],
            height: 0.3,
            yaw_deg: 0.0,
        }),
        Primitive::Box(Block { center: [-0.25, 1.5], size: [2.5, 3.0], height: 0.2, yaw_deg: 0.0 }),
        Primitive::Box(Block { center: [2.6, 0.0], size: [0.4, 6.0], height: 0.2, yaw_deg: 0.0 }),
    ];
    let m = rasterise(&prims, [-1.5, -3.0], [6.0, 6.0], 0.025).expect("map");
    let maps = CostMaps::build(&m, &robot(), &Params::default()).expect("cost maps");
    let goal = state_on(&maps, 3.4, 0.0, 0.0);
    let new_graph = |reuse: bool| {
        let cfg = HybridConfig { reuse_translated_step_failures: reuse, ..config() };
        HybridGraph::new(&maps, &robot(), 64, cfg, DrivingGoal::at(goal), &ALL).expect("graph")
    };
    let (mut reusing, mut checking) = (new_graph(true), new_graph(false));
    let mut steps = 0;
    for (x, yaw) in [(0.45, 0.0), (0.45, 0.4), (1.9, 0.0)] {
        for k in -20..=12 {
            let s = state_on(&maps, x, f64::from(k) * 0.1, yaw);
            let mut from = vec![s];
            from.extend(
                checking
                    .labelled_successors(s)
                    .into_iter()
                    .filter(|(_, _, m)| m.kind == ManoeuvreKind::BaseShift)
                    .map(|(t, _, _)| t),
            );
            for t in from {
                let want = step_edges(&mut checking, t);
                assert_eq!(step_edges(&mut reusing, t), want, "from {t:?}");
                steps += want.len();
            }
        }
    }
    let (reused, checked) = (reusing.stats(), checking.stats());
    assert_eq!(checked.step_failures_translated, 0);
    assert!(reused.step_failures_translated > 10, "{reused:?}");
    assert!(steps > 0, "no step offered at all");
    assert_eq!(reused.step_checks_passed, checked.step_checks_passed);
    let failed = |c: ManoeuvreStats| {
        c.front_steps_unstable
            + c.rear_steps_unstable
            + c.steps_without_leg_height
            + c.steps_failed_otherwise
    };
    assert_eq!(failed(reused) + reused.step_failures_translated, failed(checked));
}

#[test]
fn descends_a_flight_with_the_descent_shift_mid_flight() {
    // Three 0.20 m rises on 0.25 m treads, walked down head-on (stairs step model,
    // wheel-pair feet, as `momaro envelope stairs` plans them). Stop 27 restricted
    // the descent shift to a platform's edge (rear feet on the stepping foot's
    // ground) after a mid-flight shift tipped the robot over; with the executor's
    // stance compliance that shift is safe, and without it a front foot on a middle
    // tread cannot step down: this flight had no path.
    let stairs = Primitive::Stairs(Stairs {
        start: [0.0, 0.0],
        width: 1.8,
        steps: 3,
        step_depth: 0.25,
        step_height: 0.2,
        landing_depth: 3.0,
        yaw_deg: 0.0,
    });
    let m = rasterise(&[stairs], [-2.0, -1.5], [6.05, 3.0], 0.025).expect("map");
    let params = Params {
        step_model: crate::params::StepModel::Stairs,
        foot_model: crate::params::FootModel::WheelPair,
        ..Params::default()
    };
    let maps = CostMaps::build(&m, &robot(), &params).expect("cost maps");
    let down = std::f64::consts::PI;
    let (start, goal) = (state_on(&maps, 2.15, 0.0, down), state_on(&maps, -1.0, 0.0, down));
    let cfg = HybridConfig::new(&params, &robot(), Neighbourhood::N16);
    let mut g =
        HybridGraph::new(&maps, &robot(), 64, cfg, DrivingGoal::at(goal), &ALL).expect("graph");
    let search =
        SearchParams { initial_epsilon: 3.0, final_epsilon: 3.0, ..SearchParams::default() };
    let r = arastar(&mut g, start, &search).expect("valid params");
    let best = r.best().unwrap_or_else(|| panic!("no path: {:?}", r.termination));
    // A base shift past the front feet's neutral before a front foot steps down from a
    // tread below the rear feet.
    let ground = |g: &HybridGraph<'_>, s: LatticeState| -> [f64; 4] {
        let f = g.feet(s).expect("feet");
        f.map(|p| g.height_at(p[0], p[1]).expect("on the map"))
    };
    let labels: Vec<EdgeLabel> =
        best.path.windows(2).filter_map(|w| g.edge(w[0], w[1]).map(|(_, m)| m)).collect();
    let mid_flight_shift = (0..labels.len()).any(|i| {
        let next_step = (i + 1..labels.len()).find(|&k| labels[k].kind == ManoeuvreKind::Step);
        let Some(k) = next_step else { return false };
        let Some(f) = labels[k].leg.map(Leg::index).filter(|&f| f < 2) else { return false };
        let (before, after) = (ground(&g, best.path[i]), ground(&g, best.path[k + 1]));
        labels[i].kind == ManoeuvreKind::BaseShift
            && g.offsets(best.path[i + 1]).is_some_and(|o| o[0] < 0 && o[1] < 0)
            && before[2].min(before[3]) > before[f] + 0.1
            && after[f] < before[f] - 0.1
    });
    assert!(mid_flight_shift, "no descent shift mid-flight (cost {})", best.cost);
}

/// The plain driving heuristic (Euclidean distance plus turn) of `s` in `g`.
fn driving_heuristic(g: &HybridGraph<'_>, s: LatticeState) -> Cost {
    let l = *g.lattice();
    let cfg = g.config().driving;
    let goal = DrivingGoal::at(LatticeState::new(120, 40, 0));
    DrivingGraph::new(&|_: &Pose2| Some(1.0), l, cfg, goal).heuristic(s)
}

#[test]
fn a_thin_wall_a_step_cannot_cross_makes_the_bound_infinite() {
    // A 0.1 m thick wall across the whole map at x = 1.5. Floor on both sides, so the
    // components' heights do not tell it apart; what does is that every cell a step
    // passes stays within 0.3 m of the foot's ground (criterion 3).
    let wall = |h: f64| {
        let prims = [Primitive::Box(Block {
            center: [1.5, 0.0],
            size: [0.1, 2.4],
            height: h,
            yaw_deg: 0.0,
        })];
        let m = rasterise(&prims, [-1.0, -1.0], [4.0, 2.0], 0.025).expect("map");
        CostMaps::build(&m, &robot(), &Params::default()).expect("cost maps")
    };
    let high = wall(0.5);
    let goal_high = state_on(&high, 2.5, 0.0, 0.0);
    let g = graph(&high, goal_high);
    assert!(g.heuristic(state_at(&g, 0.0, 0.0)).is_infinite(), "0.5 m wall");
    assert!(!g.heuristic(state_at(&g, 2.4, 0.0)).is_infinite(), "the goal's side");
    // A 0.25 m bar can be stepped over: the bound stays finite.
    let low = wall(0.25);
    let goal_low = state_on(&low, 2.5, 0.0, 0.0);
    let g = graph(&low, goal_low);
    assert!(!g.heuristic(state_at(&g, 0.0, 0.0)).is_infinite(), "0.25 m bar");
}

#[test]
fn step_bound_is_one_platform_step_per_foot() {
    // Floor and platform top are two foot components 0.2 m apart in height. C_F is
    // infinite within r_F = 0.12 m of the edge cells (centres 0.9875 and 1.0125), so
    // the last finite floor cell is centred at 0.8625 and the first platform one at
    // 1.1375: 11 cells apart, a step at least 11 / 1.0824 − √2 cells long (octile
    // over Euclidean distance, feet within half a cell diagonal of their centres).
    // The offset potential takes c = f · k11 · C_F,min per metre of offset, paid by
    // the share λ = c / (f · k7) of eq. 5's k7 term. Per foot
    // f · ((1 − λ) · k7 · L + k9 · 0.2), with C_F = 1 on the flat platform.
    let maps = platform_maps(0.2);
    let goal = LatticeState::new(120, 40, 0);
    let g = graph(&maps, goal);
    assert!(g.step_bound_components() >= 2, "{}", g.step_bound_components());
    let p = Params::default();
    let f = p.step_cost_factor;
    let octile = (1.0 + (std::f64::consts::SQRT_2 - 1.0).powi(2)).sqrt();
    let l = (11.0 / octile - std::f64::consts::SQRT_2) * 0.025 * (1.0 - 1e-9);
    let c = f * p.k11;
    let lambda = c / (f * p.k7);
    let per_foot =
        Cost::from_f64_floor(f * ((1.0 - lambda) * p.k7 * l + p.k9 * 0.2) * (1.0 - 1e-9));
    // By hand with f = 10.75: L = 0.21871 m, c = 1.34375, λ = 0.25, so
    // 10.75 · (0.375 · 0.21871 + 2.3 · 0.2) = 5.8267.
    assert!((per_foot.to_f64() - 5.8267).abs() < 1e-3, "{per_foot}");
    let s = state_at(&g, 0.0, 0.0);
    let parts = g.heuristic_parts(s);
    assert_eq!(parts.driving, driving_heuristic(&g, s));
    assert_eq!(parts.steps, Cost(4 * per_foot.0));
    assert_eq!(g.heuristic(s), parts.driving.max(parts.to_go).saturating_add(parts.steps));
    // The cost-to-go knows the platform edge costs more than a metre per metre.
    assert!(parts.to_go > parts.driving, "{parts:?}");
    // Offsets (cells): c per cell behind neutral added, per cell ahead subtracted.
    let mut g = g;
    let t = g.with_offsets(s, [4, 0, -2, 0]).expect("interned");
    let cell = Cost::from_f64_floor(c * 0.025 * (1.0 - 1e-9));
    let pt = g.heuristic_parts(t);
    assert_eq!((pt.behind, pt.ahead), (Cost(2 * cell.0), Cost(4 * cell.0)));
    assert_eq!(
        g.heuristic(t),
        pt.driving
            .max(pt.to_go)
            .saturating_add(pt.steps)
            .saturating_add(pt.behind)
            .saturating_sub(pt.ahead)
    );
    // On the platform, with the goal there: no step left.
    let on = state_at(&g, 2.2, 0.0);
    assert_eq!(g.heuristic_parts(on).steps, Cost::ZERO);
    assert_eq!(g.heuristic(goal), Cost::ZERO);
    // Flat ground: no obstacle, no step, no bound, and the cost-to-go is the
    // distance (pose cost 1, k_Δθ = 1 straight ahead) up to the 20-neighbourhood's
    // grid path.
    let flat = platform_maps(0.0);
    let g = graph(&flat, goal);
    let pf = g.heuristic_parts(s);
    assert_eq!(pf.steps, Cost::ZERO);
    assert!(pf.to_go.to_f64() >= pf.driving.to_f64() - 1e-4, "{pf:?}");
}

#[test]
fn a_step_longer_than_the_legs_reach_is_no_step_edge() {
    // Floor, a 0.25 m platform 1.5 m deep (edges on cell boundaries at x = 1.15 and
    // 2.65, as the platform test's at 1.0), floor again with the goal. Every cell a
    // foot would pass going straight across stays within 0.3 m of the floor, and both
    // floors are 0 m high: a single "step" floor to floor would cost only k7 · L.
    // No step is longer than a leg's range of offsets (1 m), so each foot pays the
    // step up and the step down, each as in `step_bound_is_one_platform_step_per_foot`.
    let prims = [Primitive::Box(Block {
        center: [1.9, 0.0],
        size: [1.5, 2.0],
        height: 0.25,
        yaw_deg: 0.0,
    })];
    let m = rasterise(&prims, [-1.0, -1.0], [5.0, 2.0], 0.025).expect("map");
    let maps = CostMaps::build(&m, &robot(), &Params::default()).expect("cost maps");
    let goal = state_on(&maps, 3.5, 0.0, 0.0);
    let g = graph(&maps, goal);
    let p = Params::default();
    let f = p.step_cost_factor;
    let octile = (1.0 + (std::f64::consts::SQRT_2 - 1.0).powi(2)).sqrt();
    let l = (11.0 / octile - std::f64::consts::SQRT_2) * 0.025 * (1.0 - 1e-9);
    let lambda = p.k11 / p.k7;
    let edge = Cost::from_f64_floor(f * ((1.0 - lambda) * p.k7 * l + p.k9 * 0.25) * (1.0 - 1e-9));
    let steps = g.heuristic_parts(state_at(&g, 0.0, 0.0)).steps;
    assert_eq!(steps, Cost(8 * edge.0), "{steps} against {edge} per step");
}

#[test]
fn a_platform_three_0_1_m_rises_high_is_within_the_step_height() {
    // 0.1 + 0.1 + 0.1 = 0.30000000000000004 m: the paper's largest step, a few ulps
    // over. The step bound found no step edge onto it and the step scan stopped at
    // its edge: four generated mixed courses descending such a plateau searched the
    // whole map (120 s) for a path the criterion forbade. Such a platform is now the
    // 0.3 m platform: the same bound, the same steps from every pose before it.
    let exact = platform_maps(0.3);
    let sum = platform_maps(0.1 + 0.1 + 0.1);
    let goal = LatticeState::new(120, 40, 0);
    let (mut a, mut b) = (graph(&exact, goal), graph(&sum, goal));
    let s = state_at(&a, 0.0, 0.0);
    assert!(!b.heuristic(s).is_infinite());
    assert_eq!(a.heuristic_parts(s).steps, b.heuristic_parts(s).steps);
    let mut steps = 0;
    for k in 0..40 {
        for o in [0, 2, 4, 6, 8, 10, 12, 14, 16] {
            let base = state_at(&a, 0.025 * f64::from(k), 0.0);
            let of = |g: &mut HybridGraph<'_>| -> Vec<_> {
                let s = g.with_offsets(base, [o, o, 0, 0]).expect("interned");
                step_edges(g, s).into_iter().map(|(t, c, m)| (g.offsets(t), c, m.leg)).collect()
            };
            let (sa, sb) = (of(&mut a), of(&mut b));
            steps += sa.len();
            assert_eq!(sa, sb, "base at x = {}, front offsets {o}", 0.025 * f64::from(k));
        }
    }
    assert!(steps > 0, "no step up from the poses tried");
}

/// Checks `h(s) ≤ c(s, t) + h(t)` on every labelled successor of `s` and on every
/// edge the search itself takes out of `s` and out of the lazy steps' intermediate
/// nodes it reaches (`motion::manoeuvres::step`, "Lazy step checks"); returns the labelled
/// successors.
fn check_consistent(
    g: &mut HybridGraph<'_>,
    s: LatticeState,
) -> Vec<(LatticeState, Cost, EdgeLabel)> {
    let succ = g.labelled_successors(s);
    for &(t, c, m) in &succ {
        let (hs, ht) = (g.heuristic(s), g.heuristic(t));
        assert!(hs <= c.saturating_add(ht), "h = {hs} > {c} + {ht}: {m:?} from {s:?} to {t:?}");
    }
    let mut search_edges = Vec::new();
    g.successors(s, &mut search_edges);
    for (p, c) in search_edges {
        let (hs, hp) = (g.heuristic(s), g.heuristic(p));
        assert!(hs <= c.saturating_add(hp), "h = {hs} > {c} + {hp}: from {s:?} to {p:?}");
        if g.is_intermediate(p) {
            let mut rest = Vec::new();
            g.successors(p, &mut rest);
            for (t, c2) in rest {
                let ht = g.heuristic(t);
                assert!(hp <= c2.saturating_add(ht), "h = {hp} > {c2} + {ht}: {p:?} to {t:?}");
                // The two parts add up to the step the labelled successors give.
                let full = succ.iter().find(|(u, _, _)| *u == t).map(|&(_, c, _)| c);
                assert_eq!(full, Some(c.saturating_add(c2)), "{s:?} to {t:?} via {p:?}");
            }
        }
    }
    succ
}

#[test]
fn steps_are_checked_lazily_and_paths_leave_their_intermediate_nodes_out() {
    // The step onto the platform reaches an intermediate node at the cheapest
    // foothold's cost; the node's successor is the checked step, and the two parts
    // cost what the step does. A* returns poses only, at the same cost.
    let maps = platform_maps(0.2);
    let goal = LatticeState::new(120, 40, 0);
    let mut g = graph(&maps, goal);
    let s = state_at(&g, 0.48, 0.0);
    let mut out = Vec::new();
    g.successors(s, &mut out);
    let pending: Vec<_> = out.iter().filter(|(p, _)| g.is_intermediate(*p)).collect();
    assert_eq!(pending.len(), 2, "a step node per front leg: {out:?}");
    for &&(p, _) in &pending {
        assert_eq!((p.i, p.j, p.theta, p.footprint), (s.i, s.j, s.theta, s.footprint));
        assert!(!g.is_goal(p));
    }
    let before = g.stats().steps;
    check_consistent(&mut g, s);
    assert!(g.stats().steps > before, "expanding a node checks its step");
    // ...and counts how its checks ended: the step onto the platform holds.
    let st = g.stats();
    assert!(st.step_checks_passed > 0, "{st:?}");
    let start = state_at(&g, 0.0, 0.0);
    let r = astar(&mut g, start, &SearchParams::default());
    let best = r.best().expect("a path onto the platform");
    assert!(best.path.iter().all(|&t| !g.is_intermediate(t)));
    let edges: Cost = best
        .path
        .windows(2)
        .map(|w| g.edge(w[0], w[1]).expect("consecutive poses are joined").0)
        .sum();
    assert_eq!(edges, best.cost);
}

#[test]
fn heuristic_is_consistent_on_every_manoeuvre() {
    let maps = platform_maps(0.2);
    let goal = LatticeState::new(120, 40, 0);
    let mut g = graph(&maps, goal);
    // Front feet before the edge; rear feet before it with the front ones on the
    // platform (front foot forward, rear steps).
    let mut frontier = vec![
        state_at(&g, 0.48, 0.0),
        state_at(&g, 0.3, 0.1),
        state_at(&g, 1.2, 0.0),
        state_at(&g, 1.16, -0.05),
    ];
    let mut checked = 0;
    let mut kinds = std::collections::BTreeSet::new();
    let mut stepped = 0;
    for _ in 0..8 {
        let mut next = Vec::new();
        for s in frontier {
            for (t, _, m) in check_consistent(&mut g, s) {
                checked += 1;
                kinds.insert(m.kind);
                if m.kind == ManoeuvreKind::Step && g.heuristic(t) < g.heuristic(s) {
                    stepped += 1;
                }
                if m.kind.is_step_related() && next.len() < 400 {
                    next.push(t);
                }
            }
        }
        frontier = next;
    }
    assert!(checked > 30, "{checked}");
    assert_eq!(kinds.len(), 6, "every manoeuvre kind was checked: {kinds:?}");
    // Steps onto the platform lower the step bound: the tight case was checked.
    assert!(stepped > 0);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

    /// States near the platform edge (base 0.2–1.3 m, the edge at 1 m) with random
    /// orientations and footprints: every edge out of them keeps h consistent.
    #[test]
    fn heuristic_is_consistent_near_the_platform_edge(
        x in 0.2f64..1.3, y in -0.3f64..0.3, theta in 0u8..64,
        o in proptest::array::uniform4(-16i8..=19),
        neutral in proptest::prelude::any::<bool>(),
    ) {
        let maps = platform_maps(0.2);
        let mut g = graph(&maps, LatticeState::new(120, 40, 0));
        let s = g.lattice().state(&Pose2::new(x, y, 0.0)).expect("on the map");
        let s = LatticeState { theta, ..s };
        let s = if neutral { s } else { g.with_offsets(s, o).expect("interned") };
        for (t, _, _) in check_consistent(&mut g, s) {
            check_consistent(&mut g, t);
        }
    }
}

/// A random small map: 3.2 m × 1.6 m from (−0.8, −0.8), with up to three boxes
/// (bumps, platforms, bars) between the start at (0, 0) and x = 2 m.
fn random_maps(boxes: &[(f64, f64, f64, f64, f64, f64)]) -> CostMaps {
    let prims: Vec<Primitive> = boxes
        .iter()
        .map(|&(x, y, w, d, h, yaw)| {
            Primitive::Box(Block { center: [x, y], size: [w, d], height: h, yaw_deg: yaw })
        })
        .collect();
    let m = rasterise(&prims, [-0.8, -0.8], [3.2, 1.6], 0.025).expect("map");
    CostMaps::build(&m, &robot(), &Params::default()).expect("maps")
}

fn random_box() -> impl proptest::strategy::Strategy<Value = (f64, f64, f64, f64, f64, f64)> {
    (0.3f64..1.8, -0.5f64..0.5, 0.05f64..1.2, 0.1f64..1.6, 0.02f64..0.35, 0.0f64..90.0)
}

/// The hybrid graph with the heuristic before the cost-to-go (issue 15): the
/// Euclidean-plus-turn part and the step bound (consistent on their own, see the
/// `motion::manoeuvres`). A reference for the optimum. It searches the graph's
/// checked edges (`labelled_successors`), without the intermediate nodes of lazy
/// step checks: on such a node this heuristic, its pose's, is not consistent (the
/// edge into the node has paid the step's least cost already), and A* with it
/// returned a path 3 % above the optimum on a random map.
struct Baseline<'a, 'c>(&'a mut HybridGraph<'c>);

impl SearchGraph for Baseline<'_, '_> {
    type State = LatticeState;
    fn successors(&mut self, s: LatticeState, out: &mut Vec<(LatticeState, Cost)>) {
        out.extend(self.0.labelled_successors(s).into_iter().map(|(t, c, _)| (t, c)));
    }
    fn heuristic(&self, s: LatticeState) -> Cost {
        let p = self.0.heuristic_parts(s);
        p.reachable.saturating_add(p.driving).saturating_add(p.steps)
    }
    fn is_goal(&self, s: LatticeState) -> bool {
        self.0.is_goal(s)
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    /// Random edges of random small maps: from a random state (any orientation,
    /// neutral or a random footprint), a random walk of four edges, checking
    /// `h(s) ≤ c(s, t) + h(t)` on every successor on the way; with the cost-to-go in
    /// 64, 16, 8 (the default), 2 or one orientation group, the goal's orientation
    /// fixed or free.
    #[test]
    fn heuristic_is_consistent_on_random_maps(
        boxes in proptest::collection::vec(random_box(), 1..=3),
        x in -0.3f64..2.0, y in -0.4f64..0.4, theta in 0u8..64,
        o in proptest::array::uniform4(-12i8..=16),
        neutral in proptest::prelude::any::<bool>(),
        walk in proptest::collection::vec(0usize..1000, 4),
        groups in proptest::sample::select(vec![64usize, 16, 8, 2, 1]),
        free_goal_theta in proptest::prelude::any::<bool>(),
    ) {
        let maps = random_maps(&boxes);
        let goal = state_on(&maps, 2.0, 0.0, 0.0);
        let cfg = HybridConfig { cost_to_go_groups: groups, ..config() };
        let target = DrivingGoal {
            theta: if free_goal_theta { None } else { Some(goal.theta) },
            ..DrivingGoal::at(goal)
        };
        let mut g = HybridGraph::new(&maps, &robot(), 64, cfg, target, &ALL).expect("graph");
        let s = g.lattice().state(&Pose2::new(x, y, 0.0)).expect("on the map");
        let s = LatticeState { theta, ..s };
        let mut s = if neutral { s } else { g.with_offsets(s, o).expect("interned") };
        for k in walk {
            let succ = check_consistent(&mut g, s);
            if succ.is_empty() {
                break;
            }
            s = succ[k % succ.len()].0;
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(6))]

    /// A*'s optimum (ε = 1) on random small maps is the same with the cost-to-go as
    /// with the heuristic before it (both searches that finish agree, "no path"
    /// included).
    #[test]
    fn astar_optimum_is_unchanged_by_the_cost_to_go(
        boxes in proptest::collection::vec(random_box(), 1..=2),
    ) {
        let maps = random_maps(&boxes);
        let goal = state_at(&graph(&maps, LatticeState::new(0, 0, 0)), 1.6, 0.0);
        let start = state_at(&graph(&maps, goal), 0.0, 0.0);
        let params = SearchParams { max_expansions: Some(400_000), ..SearchParams::default() };
        let mut g = graph(&maps, goal);
        let new = astar(&mut g, start, &params);
        let mut g = graph(&maps, goal);
        let old = astar(&mut Baseline(&mut g), start, &params);
        let finished =
            |t: Termination| matches!(t, Termination::OptimalProven | Termination::NoPath);
        if finished(old.termination) && finished(new.termination) {
            proptest::prop_assert_eq!(old.best().map(|s| s.cost), new.best().map(|s| s.cost));
        }
    }
}

#[test]
fn a_flight_longer_than_the_robot_has_a_path() {
    // Six steps of 0.17 m on 0.29 m treads (1.74 m of flight, the robot's feet span
    // 0.8 m): with a rear foot short of a riser unable to roll up to it, and no base
    // shift past the front feet's neutral while they stand on a tread, flights of
    // four or more steps were searched exhaustively without a path.
    let prims = [Primitive::Stairs(Stairs {
        start: [0.0, 0.0],
        width: 1.8,
        steps: 6,
        step_depth: 0.29,
        step_height: 0.17,
        landing_depth: 1.5,
        yaw_deg: 0.0,
    })];
    let m = rasterise(&prims, [-1.6, -1.2], [5.0, 2.4], 0.025).expect("map");
    let params = Params {
        step_model: crate::params::StepModel::Stairs,
        foot_model: crate::params::FootModel::WheelPair,
        ..Params::default()
    };
    let maps = CostMaps::build(&m, &robot(), &params).expect("maps");
    let cfg = HybridConfig::new(&params, &robot(), Neighbourhood::N20);
    let at = |x: f64| LatticeState::new(((x + 1.6) / 0.025) as i16, 48, 0);
    let goal = DrivingGoal::at(at(2.6));
    let mut g = HybridGraph::new(&maps, &robot(), 64, cfg, goal, &ALL).expect("graph");
    let search =
        SearchParams { initial_epsilon: 3.0, final_epsilon: 3.0, ..SearchParams::default() };
    let r = arastar(&mut g, at(-1.0), &search).expect("valid params");
    let best = r.best().unwrap_or_else(|| panic!("no path: {:?}", r.termination));
    let steps = best
        .path
        .windows(2)
        .filter(|w| g.edge(w[0], w[1]).is_some_and(|(_, m)| m.kind == ManoeuvreKind::Step))
        .count();
    // Every foot climbs every riser (six each; the top one onto the landing).
    assert_eq!(steps, 24);
}

#[test]
fn climbs_a_small_platform_and_ara_ends_at_the_astar_cost() {
    // 3.2 m × 1.6 m: small enough for an exhaustive search.
    let prims =
        [Primitive::Box(Block { center: [1.8, 0.0], size: [2.0, 2.0], height: 0.2, yaw_deg: 0.0 })];
    let m = rasterise(&prims, [-0.8, -0.8], [3.2, 1.6], 0.025).expect("map");
    let maps = CostMaps::build(&m, &robot(), &Params::default()).expect("maps");
    let (start, goal) = (state_on(&maps, 0.0, 0.0, 0.0), state_on(&maps, 1.5, 0.0, 0.0));
    let cfg = config();
    let mut g = HybridGraph::new(&maps, &robot(), 64, cfg, DrivingGoal::at(goal), &ALL).expect("g");
    let h0 = g.heuristic(start);
    let a = astar(&mut g, start, &SearchParams::default());
    assert_eq!(a.termination, Termination::OptimalProven);
    let best = a.best().expect("a path up");
    // Admissible, and informed: the four steps' bound is most of the heuristic.
    assert!(h0 <= best.cost, "h = {h0} > {}", best.cost);
    assert!(h0.to_f64() > 1.5 + 4.0 * 4.0, "h = {h0}");
    let kinds: Vec<_> =
        best.path.windows(2).filter_map(|w| g.edge(w[0], w[1]).map(|(_, m)| m.kind)).collect();
    assert_eq!(kinds.len(), best.path.len() - 1, "every edge is labelled");
    assert_eq!(kinds.iter().filter(|k| **k == ManoeuvreKind::Step).count(), 4);
    assert!(kinds.contains(&ManoeuvreKind::BaseShift));
    let mut g2 =
        HybridGraph::new(&maps, &robot(), 64, cfg, DrivingGoal::at(goal), &ALL).expect("g");
    let r = arastar(&mut g2, start, &SearchParams::default()).expect("valid params");
    assert_eq!(r.termination, Termination::OptimalProven);
    let costs: Vec<_> = r.solutions.iter().map(|s| s.cost).collect();
    assert!(costs.windows(2).all(|w| w[1] <= w[0]), "{costs:?}");
    for s in &r.solutions {
        assert!(s.cost.to_f64() <= s.epsilon * best.cost.to_f64() + 1e-6);
    }
    assert_eq!(r.best().map(|s| s.cost), Some(best.cost));
}
