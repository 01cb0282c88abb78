//! Tests of A* and ARA* on hand-made graphs, random grids (proptest, against a plain
//! Dijkstra), an unbounded grid (time limit, cancel), and for determinism.

use super::*;
use proptest::prelude::*;
use std::collections::{BinaryHeap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

// ---------------------------------------------------------------- hand-made graphs

/// A graph given as an edge list with an explicit heuristic table.
#[derive(Debug, Clone)]
struct Table {
    edges: Vec<(u8, u8, u64)>,
    h: Vec<u64>,
    goal: u8,
    /// Guidance per state (`SearchGraph::heuristic_and_guidance`); none: the heuristic.
    guidance: Option<Vec<u64>>,
    /// The greedy list's guidance per state (`SearchGraph::heuristic_and_guidances`);
    /// none: the guidance.
    greedy: Option<Vec<u64>>,
}

impl SearchGraph for Table {
    type State = u8;
    fn successors(&mut self, s: u8, out: &mut Vec<(u8, Cost)>) {
        for &(a, b, c) in &self.edges {
            if a == s {
                out.push((b, Cost(c * Cost::SCALE)));
            }
        }
    }
    fn heuristic(&self, s: u8) -> Cost {
        Cost(self.h[s as usize] * Cost::SCALE)
    }
    fn is_goal(&self, s: u8) -> bool {
        s == self.goal
    }
    fn heuristic_and_guidance(&self, s: u8) -> (Cost, Cost) {
        let h = self.heuristic(s);
        (h, self.guidance.as_ref().map_or(h, |g| Cost(g[s as usize] * Cost::SCALE)))
    }
    fn heuristic_and_guidances(&self, s: u8) -> (Cost, Cost, Cost) {
        let (h, guidance) = self.heuristic_and_guidance(s);
        (h, guidance, self.greedy.as_ref().map_or(guidance, |g| Cost(g[s as usize] * Cost::SCALE)))
    }
}

const S: u8 = 0;
const A: u8 = 1;
const B: u8 = 2;
const G: u8 = 3;

/// S→A→G costs 6, S→B→G costs 4. h is consistent but badly underestimates at A, so
/// weighted A* (ε = 3) takes the route through A; ARA* must then improve it.
fn trap() -> Table {
    Table {
        edges: vec![(S, A, 1), (A, G, 5), (S, B, 3), (B, G, 1)],
        h: vec![1, 0, 1, 0],
        goal: G,
        guidance: None,
        greedy: None,
    }
}

fn units(c: u64) -> Cost {
    Cost(c * Cost::SCALE)
}

#[test]
fn astar_finds_optimal_on_trap() {
    let r = astar(&mut trap(), S, &SearchParams::default());
    assert_eq!(r.termination, Termination::OptimalProven);
    let best = r.best().expect("solution");
    assert_eq!(best.path, vec![S, B, G]);
    assert_eq!(best.cost, units(4));
    assert_eq!(r.solutions.len(), 1);
}

#[test]
fn weighted_astar_is_suboptimal_on_trap() {
    let p = SearchParams { initial_epsilon: 3.0, final_epsilon: 3.0, ..SearchParams::default() };
    let r = arastar(&mut trap(), S, &p).expect("valid params");
    assert_eq!(r.termination, Termination::FinalEpsilonReached);
    let best = r.best().expect("solution");
    assert_eq!(best.path, vec![S, A, G]);
    assert_eq!(best.cost, units(6));
    assert_eq!(best.epsilon, 3.0);
    // ε′ = 6 / min(g + h over OPEN) = 6 / (3 + 1).
    assert!((best.suboptimality_bound - 1.5).abs() < 1e-12);
}

#[test]
fn a_probe_publishes_first_and_the_schedule_still_finds_the_optimum() {
    // The probe (ε = 10) takes the trap's route through A; the schedule, from scratch at
    // ε = 1, the optimum through B.
    let p =
        SearchParams { probe_epsilon: Some(10.0), initial_epsilon: 1.0, ..SearchParams::default() };
    let r = arastar(&mut trap(), S, &p).expect("valid params");
    assert_eq!(r.termination, Termination::OptimalProven);
    let got: Vec<(f64, Cost)> = r.solutions.iter().map(|s| (s.epsilon, s.cost)).collect();
    assert_eq!(got, vec![(10.0, units(6)), (1.0, units(4))]);
    assert_eq!(r.best().expect("solution").path, vec![S, B, G]);
    // ε′ of the probe's path: 6 / min(g + h over OPEN) = 6 / (3 + 1).
    assert!((r.solutions[0].suboptimality_bound - 1.5).abs() < 1e-12);
}

#[test]
fn a_guided_probe_takes_the_route_its_guidance_shows() {
    // Guidance that knows A is a detour: the probe expands S from the heuristic's list,
    // then B from the guidance's (key 3 + 10·0 against A's 1 + 10·100), and stops at G
    // (guidance key 4, the guidance list's smallest). Its bound comes from the admissible
    // heuristic: ε′ = 4 / min(g + h over OPEN) = 4 / (1 + 0), A being still open.
    let mut guided = trap();
    guided.guidance = Some(vec![1, 100, 0, 0]);
    let p = SearchParams {
        probe_epsilon: Some(10.0),
        initial_epsilon: 3.0,
        final_epsilon: 3.0,
        schedule_max_expansions: Some(0),
        ..SearchParams::default()
    };
    let r = arastar(&mut guided, S, &p).expect("valid params");
    let probe = &r.solutions[0];
    assert_eq!((probe.path.clone(), probe.cost, probe.epsilon), (vec![S, B, G], units(4), 10.0));
    assert!((probe.suboptimality_bound - 4.0).abs() < 1e-12, "{}", probe.suboptimality_bound);
    // Unguided, the probe falls into the trap (S, A, G: cost 6).
    let r = arastar(&mut guided, S, &SearchParams { probe_guidance: false, ..p.clone() })
        .expect("valid params");
    assert_eq!((r.solutions[0].path.clone(), r.solutions[0].cost), (vec![S, A, G], units(6)));
    // Guidance equal to the heuristic (the default) searches as the unguided probe does.
    let r = arastar(&mut trap(), S, &p).expect("valid params");
    assert_eq!((r.solutions[0].path.clone(), r.solutions[0].cost), (vec![S, A, G], units(6)));
}

/// S → A costs 100 and A → G 1 (the only way to the goal); S → P1 → … → P40 is a
/// dead-end plateau of unit edges. h: 2 on S and the plateau, 1 on A, 0 on G
/// (consistent). At ε = 10 the plateau's keys (k + 20) are all below A's (110).
fn dear_edge() -> Table {
    let mut edges = vec![(S, A, 100), (A, G, 1), (S, 4, 1)];
    edges.extend((4..43).map(|p| (p, p + 1, 1)));
    let mut h = vec![2; 44];
    h[A as usize] = 1;
    h[G as usize] = 0;
    h[B as usize] = 2;
    Table { edges, h, goal: G, guidance: None, greedy: None }
}

/// A guided probe (ε = 10) whose greedy list joins from the start, and no schedule after
/// it.
fn greedy_probe() -> SearchParams {
    SearchParams {
        probe_epsilon: Some(10.0),
        initial_epsilon: 3.0,
        final_epsilon: 3.0,
        schedule_max_expansions: Some(0),
        probe_greedy_after: Some(0),
        ..SearchParams::default()
    }
}

#[test]
fn a_guided_probes_greedy_list_crosses_a_dear_edge_and_reports_its_true_bound() {
    let p = greedy_probe();
    // Guided: S from OPEN, P1 from the guidance's list (key 1 + 10·2 against A's 110),
    // A from the greedy list (guidance 1 against P2's 2), which reaches G: three
    // expansions. ε′ = 101 / min(g + h over OPEN) = 101 / (P2: 2 + 2), above ε = 10,
    // which this search does not guarantee.
    let r = arastar(&mut dear_edge(), S, &p).expect("valid params");
    let probe = &r.solutions[0];
    assert_eq!((probe.path.clone(), probe.cost, probe.expansions), (vec![S, A, G], units(101), 3));
    assert!((probe.suboptimality_bound - 25.25).abs() < 1e-12, "{}", probe.suboptimality_bound);
    // The greedy list joining after 10 expansions (S, P1…P9 by the weighted lists): P10
    // from OPEN, P11 from the guidance's list, A from the greedy list: 13 expansions,
    // ε′ = 101 / (P12: 12 + 2).
    let later = SearchParams { probe_greedy_after: Some(10), ..p.clone() };
    let r = arastar(&mut dear_edge(), S, &later).expect("valid params");
    let probe = &r.solutions[0];
    assert_eq!((probe.path.clone(), probe.expansions), (vec![S, A, G], 13));
    assert!((probe.suboptimality_bound - 101.0 / 14.0).abs() < 1e-12);
    // Unguided, the weighted search expands the whole plateau first (S, P1…P40, A) and
    // its path carries ε (ε′ = 101 / 101 here: the goal alone is left in OPEN).
    let r = arastar(&mut dear_edge(), S, &SearchParams { probe_guidance: false, ..p })
        .expect("valid params");
    let probe = &r.solutions[0];
    assert_eq!((probe.cost, probe.expansions), (units(101), 42));
    assert!((probe.suboptimality_bound - 1.0).abs() < 1e-12, "{}", probe.suboptimality_bound);
}

#[test]
fn a_guided_probes_greedy_list_follows_its_own_estimate() {
    // The dear edge's probe with its greedy list from the start (3 expansions above),
    // the greedy list ordered by an estimate of its own: where it puts A behind the
    // plateau (50 against 2), every list expands the plateau first (S, P1…P40, A: 42);
    // where the guidance does so and the greedy estimate is the heuristic, the greedy
    // list takes A third as before.
    let p = greedy_probe();
    let behind = |t: &Table| {
        let mut v = t.h.clone();
        v[A as usize] = 50;
        Some(v)
    };
    let mut g = dear_edge();
    g.greedy = behind(&g);
    let r = arastar(&mut g, S, &p).expect("valid params");
    assert_eq!((r.solutions[0].cost, r.solutions[0].expansions), (units(101), 42));
    let mut g = dear_edge();
    (g.guidance, g.greedy) = (behind(&g), Some(g.h.clone()));
    let r = arastar(&mut g, S, &p).expect("valid params");
    assert_eq!((r.solutions[0].path.clone(), r.solutions[0].expansions), (vec![S, A, G], 3));
}

#[test]
fn a_limit_on_the_schedule_leaves_the_probes_path() {
    // The probe expands S and A (2); the schedule may spend one expansion after it.
    let p = SearchParams {
        probe_epsilon: Some(10.0),
        initial_epsilon: 1.0,
        schedule_max_expansions: Some(1),
        ..SearchParams::default()
    };
    let r = arastar(&mut trap(), S, &p).expect("valid params");
    assert_eq!(r.termination, Termination::ExpansionLimit);
    let best = r.best().expect("the probe's solution");
    assert_eq!((best.path.clone(), best.cost), (vec![S, A, G], units(6)));
    assert_eq!(best.epsilon, 10.0);
    assert_eq!(r.expansions, 3);
    // Without a probe there is no probe's path to keep: the cap does not apply.
    let p = SearchParams { schedule_max_expansions: Some(0), ..SearchParams::default() };
    let r = arastar(&mut trap(), S, &p).expect("valid params");
    assert_eq!(r.termination, Termination::OptimalProven);
}

#[test]
fn a_certified_bound_at_the_final_epsilon_ends_the_schedule() {
    // ε = 3 finds the route through A with ε′ = 1.5: what a search at the final ε = 1.5
    // would prove, so none runs.
    let p = SearchParams { initial_epsilon: 3.0, final_epsilon: 1.5, ..SearchParams::default() };
    let r = arastar(&mut trap(), S, &p).expect("valid params");
    assert_eq!(r.termination, Termination::FinalEpsilonReached);
    assert_eq!(r.solutions.len(), 1);
    assert!((r.solutions[0].suboptimality_bound - 1.5).abs() < 1e-12);
}

#[test]
fn a_probe_below_the_initial_epsilon_is_rejected() {
    let p = SearchParams { probe_epsilon: Some(2.0), ..SearchParams::default() };
    assert!(matches!(
        arastar(&mut trap(), S, &p),
        Err(SearchError::Params(ParamsError::ProbeOrder { .. }))
    ));
    let same = SearchParams { probe_epsilon: Some(3.0), ..SearchParams::default() };
    let r = arastar(&mut trap(), S, &same).expect("a probe at the initial ε is none");
    assert_eq!(r.solutions[0].epsilon, 3.0);
}

#[test]
fn arastar_improves_the_trap_solution() {
    let r = arastar(&mut trap(), S, &SearchParams::default()).expect("valid params");
    assert_eq!(r.termination, Termination::OptimalProven);
    let costs: Vec<Cost> = r.solutions.iter().map(|s| s.cost).collect();
    assert_eq!(costs, vec![units(6), units(4)]);
    assert_eq!(r.solutions[0].epsilon, 3.0);
    assert_eq!(r.solutions[1].path, vec![S, B, G]);
    assert_eq!(r.solutions[1].suboptimality_bound, 1.0);
    // The second search reused the first: B was already in OPEN, only it was expanded.
    assert_eq!(r.expansions, 3);
}

#[test]
fn astar_reopens_for_inconsistent_admissible_heuristic() {
    // S→A 6, S→B 2, B→A 2, A→G 10, S→C 15, C→G 0. h(A) = h(C) = 0 and h(B) = 12
    // (exact) are admissible but not consistent: A is expanded via S (g 6) before B
    // improves it to 4. Without re-opening A, the search would settle for S→C→G (15).
    const C: u8 = 4;
    let mut g = Table {
        edges: vec![(S, A, 6), (S, B, 2), (B, A, 2), (A, G, 10), (S, C, 15), (C, G, 0)],
        h: vec![0, 0, 12, 0, 0],
        goal: G,
        guidance: None,
        greedy: None,
    };
    let r = astar(&mut g, S, &SearchParams::default());
    let best = r.best().expect("solution");
    assert_eq!(best.path, vec![S, B, A, G]);
    assert_eq!(best.cost, units(14));
}

#[test]
fn start_is_goal() {
    let mut g = trap();
    let r = astar(&mut g, G, &SearchParams::default());
    assert_eq!(r.best().map(|s| (s.path.clone(), s.cost)), Some((vec![G], Cost::ZERO)));
    let r = arastar(&mut g, G, &SearchParams::default()).expect("valid");
    assert_eq!(r.termination, Termination::OptimalProven);
    assert_eq!(r.solutions.len(), 1);
    assert_eq!(r.best().map(|s| s.cost), Some(Cost::ZERO));
}

#[test]
fn unreachable_goal_reports_no_path() {
    let mut g = Table {
        edges: vec![(S, A, 1), (A, S, 1), (B, G, 1)],
        h: vec![0; 4],
        goal: G,
        guidance: None,
        greedy: None,
    };
    let r = astar(&mut g, S, &SearchParams::default());
    assert_eq!(r.termination, Termination::NoPath);
    assert!(r.solutions.is_empty());
    let r = arastar(&mut g, S, &SearchParams::default()).expect("valid");
    assert_eq!(r.termination, Termination::NoPath);
    assert!(r.solutions.is_empty());
    assert_eq!(r.expansions, 2);
}

/// Edges as in [`Table`], where a cost of `u64::MAX` means [`Cost::INFINITY`].
struct WithInfinite(Vec<(u8, u8, u64)>);

impl SearchGraph for WithInfinite {
    type State = u8;
    fn successors(&mut self, s: u8, out: &mut Vec<(u8, Cost)>) {
        for &(a, b, c) in &self.0 {
            if a == s {
                let cost = if c == u64::MAX { Cost::INFINITY } else { units(c) };
                out.push((b, cost));
            }
        }
    }
    fn heuristic(&self, _: u8) -> Cost {
        Cost::ZERO
    }
    fn is_goal(&self, s: u8) -> bool {
        s == G
    }
}

#[test]
fn infinite_edges_are_not_followed() {
    let mut g = WithInfinite(vec![(S, G, u64::MAX), (S, A, 2), (A, G, 2)]);
    let r = astar(&mut g, S, &SearchParams::default());
    assert_eq!(r.best().map(|s| (s.path.clone(), s.cost)), Some((vec![S, A, G], units(4))));
    let mut g = WithInfinite(vec![(S, G, u64::MAX)]);
    let r = arastar(&mut g, S, &SearchParams::default()).expect("valid");
    assert_eq!(r.termination, Termination::NoPath);
}

#[test]
fn invalid_params_are_an_error() {
    let p = SearchParams { initial_epsilon: 0.9, ..SearchParams::default() };
    assert!(matches!(
        arastar(&mut trap(), S, &p),
        Err(SearchError::Params(ParamsError::Epsilon { .. }))
    ));
}

#[test]
fn expansion_and_state_limits() {
    let mut g = Unbounded;
    let p = SearchParams { max_expansions: Some(100), ..SearchParams::default() };
    let r = astar(&mut g, (5, 0), &p);
    assert_eq!(r.termination, Termination::ExpansionLimit);
    assert_eq!(r.expansions, 100);
    let p = SearchParams { max_states: Some(50), ..SearchParams::default() };
    let r = arastar(&mut g, (5, 0), &p).expect("valid");
    assert_eq!(r.termination, Termination::StateLimit);
    assert!(r.states <= 50);
    let p = SearchParams { max_states: Some(0), ..SearchParams::default() };
    assert_eq!(astar(&mut g, (5, 0), &p).termination, Termination::StateLimit);
}

#[test]
fn hooks_see_every_expansion_and_solution() {
    let mut expanded = Vec::new();
    let mut log = |e: &Expansion<u8>| expanded.push((e.state, e.iteration));
    let mut found = Vec::new();
    let mut on_sol = |s: &Solution<u8>| found.push(s.cost);
    let hooks = Hooks { cancel: None, on_expand: Some(&mut log), on_solution: Some(&mut on_sol) };
    let r = arastar_with_hooks(&mut trap(), S, &SearchParams::default(), hooks).expect("valid");
    assert_eq!(expanded, vec![(S, 0), (A, 0), (B, 1)]);
    assert_eq!(found, r.solutions.iter().map(|s| s.cost).collect::<Vec<_>>());
}

// ---------------------------------------------------------------- grids

/// A bounded 8-connected grid; `None` cells are blocked. Moving between cells costs the
/// move length (1 or √2, in integer micro-units) times the mean of the two cell costs.
/// The heuristic is the octile distance with the same integer lengths, the exact cost on
/// an all-ones grid, hence consistent.
#[derive(Debug, Clone)]
struct Grid {
    w: i32,
    h: i32,
    cells: Vec<Option<u8>>,
    goal: (i32, i32),
}

const STRAIGHT: u64 = Cost::SCALE;
const DIAGONAL: u64 = 1_414_214; // round(√2 · 10⁶)
const DIRS8: [(i32, i32); 8] =
    [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)];

fn octile(a: (i64, i64), b: (i64, i64)) -> Cost {
    let (dx, dy) = ((a.0 - b.0).unsigned_abs(), (a.1 - b.1).unsigned_abs());
    let (lo, hi) = (dx.min(dy), dx.max(dy));
    Cost((hi - lo) * STRAIGHT + lo * DIAGONAL)
}

impl Grid {
    fn cell(&self, x: i32, y: i32) -> Option<u8> {
        if x < 0 || y < 0 || x >= self.w || y >= self.h {
            return None;
        }
        self.cells[(y * self.w + x) as usize]
    }
}

impl SearchGraph for Grid {
    type State = (i32, i32);
    fn successors(&mut self, (x, y): (i32, i32), out: &mut Vec<((i32, i32), Cost)>) {
        let Some(here) = self.cell(x, y) else { return };
        for (dx, dy) in DIRS8 {
            if let Some(there) = self.cell(x + dx, y + dy) {
                let len = if dx != 0 && dy != 0 { DIAGONAL } else { STRAIGHT };
                let c = len * (u64::from(here) + u64::from(there)) / 2;
                out.push(((x + dx, y + dy), Cost(c)));
            }
        }
    }
    fn heuristic(&self, (x, y): (i32, i32)) -> Cost {
        octile((x.into(), y.into()), (self.goal.0.into(), self.goal.1.into()))
    }
    fn is_goal(&self, s: (i32, i32)) -> bool {
        s == self.goal
    }
}

/// Plain Dijkstra over the graph's successors: the reference optimal cost.
fn dijkstra<G: SearchGraph>(g: &mut G, start: G::State) -> Option<Cost>
where
    G::State: Ord,
{
    let mut dist: HashMap<G::State, Cost> = HashMap::new();
    let mut heap = BinaryHeap::new();
    dist.insert(start, Cost::ZERO);
    heap.push(std::cmp::Reverse((Cost::ZERO, start)));
    let mut out = Vec::new();
    while let Some(std::cmp::Reverse((d, s))) = heap.pop() {
        if dist.get(&s).is_some_and(|&best| d > best) {
            continue;
        }
        if g.is_goal(s) {
            return Some(d);
        }
        out.clear();
        g.successors(s, &mut out);
        for &(t, c) in &out {
            let nd = d + c;
            if dist.get(&t).is_none_or(|&best| nd < best) {
                dist.insert(t, nd);
                heap.push(std::cmp::Reverse((nd, t)));
            }
        }
    }
    None
}

/// Checks that consecutive states are joined by edges and the edge costs sum to `cost`.
fn assert_valid_path<G: SearchGraph>(g: &mut G, start: G::State, sol: &Solution<G::State>)
where
    G::State: std::fmt::Debug,
{
    assert_eq!(sol.path.first(), Some(&start));
    assert!(sol.path.last().is_some_and(|&s| g.is_goal(s)));
    let mut total = Cost::ZERO;
    let mut out = Vec::new();
    for w in sol.path.windows(2) {
        out.clear();
        g.successors(w[0], &mut out);
        let edge = out.iter().filter(|(s, _)| *s == w[1]).map(|&(_, c)| c).min();
        assert!(edge.is_some(), "{:?} -> {:?} is not an edge", w[0], w[1]);
        total += edge.unwrap_or(Cost::INFINITY);
    }
    assert_eq!(total, sol.cost);
}

fn grid_strategy() -> impl Strategy<Value = (Grid, (i32, i32))> {
    (1i32..=14, 1i32..=14)
        .prop_flat_map(|(w, h)| {
            let n = (w * h) as usize;
            (
                Just((w, h)),
                proptest::collection::vec(
                    prop_oneof![1 => Just(None), 3 => (1u8..=9).prop_map(Some)],
                    n,
                ),
                0..n,
                0..n,
            )
        })
        .prop_map(|((w, h), mut cells, s, g)| {
            cells[s] = cells[s].or(Some(1));
            cells[g] = cells[g].or(Some(1));
            let at = |i: usize| (i as i32 % w, i as i32 / w);
            let grid = Grid { w, h, cells, goal: at(g) };
            (grid, at(s))
        })
}

/// A [`Grid`] with an arbitrary guidance per cell (row-major, in cells of `STRAIGHT`).
#[derive(Debug, Clone)]
struct Guided {
    grid: Grid,
    guidance: Vec<u64>,
}

impl SearchGraph for Guided {
    type State = (i32, i32);
    fn successors(&mut self, s: (i32, i32), out: &mut Vec<((i32, i32), Cost)>) {
        self.grid.successors(s, out);
    }
    fn heuristic(&self, s: (i32, i32)) -> Cost {
        self.grid.heuristic(s)
    }
    fn is_goal(&self, s: (i32, i32)) -> bool {
        self.grid.is_goal(s)
    }
    fn heuristic_and_guidance(&self, s: (i32, i32)) -> (Cost, Cost) {
        let k = (s.1 * self.grid.w + s.0) as usize % self.guidance.len();
        (self.grid.heuristic(s), Cost(self.guidance[k] * STRAIGHT))
    }
}

fn eps_params(initial: f64, decay: f64) -> SearchParams {
    SearchParams { initial_epsilon: initial, epsilon_decay: decay, ..SearchParams::default() }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn astar_matches_dijkstra((grid, start) in grid_strategy()) {
        let optimal = dijkstra(&mut grid.clone(), start);
        let mut g = grid.clone();
        let r = astar(&mut g, start, &SearchParams::default());
        match optimal {
            None => {
                prop_assert_eq!(r.termination, Termination::NoPath);
                prop_assert!(r.solutions.is_empty());
            }
            Some(opt) => {
                prop_assert_eq!(r.termination, Termination::OptimalProven);
                let best = r.best().expect("solution");
                prop_assert_eq!(best.cost, opt);
                assert_valid_path(&mut g, start, best);
            }
        }
    }

    #[test]
    fn arastar_bounds_and_monotone(
        (grid, start) in grid_strategy(),
        initial in 1.0f64..5.0,
        decay in 0.2f64..0.9,
    ) {
        let optimal = dijkstra(&mut grid.clone(), start);
        let mut g = grid.clone();
        let r = arastar(&mut g, start, &eps_params(initial, decay)).expect("valid");
        let Some(opt) = optimal else {
            prop_assert_eq!(r.termination, Termination::NoPath);
            prop_assert!(r.solutions.is_empty());
            return Ok(());
        };
        prop_assert_eq!(r.termination, Termination::OptimalProven);
        prop_assert!(!r.solutions.is_empty());
        let mut prev: Option<&Solution<(i32, i32)>> = None;
        for sol in &r.solutions {
            assert_valid_path(&mut g, start, sol);
            // cost ≤ ε · optimal (exact in integers: ε is in thousandths)
            let eps_milli = (sol.epsilon * 1000.0).round() as u128;
            prop_assert!(u128::from(sol.cost.0) * 1000 <= eps_milli * u128::from(opt.0),
                "cost {} > ε {} × optimal {}", sol.cost, sol.epsilon, opt);
            prop_assert!(sol.cost.to_f64() <= sol.suboptimality_bound * opt.to_f64() * (1.0 + 1e-9));
            prop_assert!(sol.suboptimality_bound >= 1.0 && sol.suboptimality_bound <= sol.epsilon);
            if let Some(p) = prev {
                prop_assert!(sol.cost <= p.cost);
                prop_assert!(sol.epsilon < p.epsilon);
                prop_assert!(sol.expansions >= p.expansions);
            }
            prev = Some(sol);
        }
        let last = r.best().expect("solution");
        prop_assert_eq!(last.cost, opt);
        let astar_cost = astar(&mut grid.clone(), start, &SearchParams::default())
            .best()
            .map(|s| s.cost);
        prop_assert_eq!(Some(last.cost), astar_cost);
    }

    #[test]
    fn a_guided_probe_keeps_arastars_bounds_whatever_its_guidance(
        (grid, start) in grid_strategy(),
        guidance in proptest::collection::vec(0u64..40, 196),
        probe in 3.5f64..60.0,
        greedy_after in proptest::option::of(0u64..30),
    ) {
        // Guidance of any size, unrelated to the costs: the probe's order changes, its
        // bound ε′ (from the admissible heuristic) still holds, the schedule's paths keep
        // their ε, and the schedule still ends at the optimum. (The probe's greedy list,
        // when it joins, stops it at its first goal: its path's bound is ε′ alone.)
        let optimal = dijkstra(&mut grid.clone(), start);
        let mut g = Guided { grid: grid.clone(), guidance };
        let p = SearchParams {
            probe_epsilon: Some(probe),
            probe_greedy_after: greedy_after,
            ..eps_params(3.0, 0.5)
        };
        let r = arastar(&mut g, start, &p).expect("valid");
        let Some(opt) = optimal else {
            prop_assert_eq!(r.termination, Termination::NoPath);
            return Ok(());
        };
        prop_assert_eq!(r.termination, Termination::OptimalProven);
        for (i, sol) in r.solutions.iter().enumerate() {
            assert_valid_path(&mut g.grid, start, sol);
            prop_assert!(sol.cost.to_f64() <= sol.suboptimality_bound * opt.to_f64() * (1.0 + 1e-9));
            prop_assert!(sol.suboptimality_bound >= 1.0);
            if i > 0 {
                let eps_milli = (sol.epsilon * 1000.0).round() as u128;
                prop_assert!(u128::from(sol.cost.0) * 1000 <= eps_milli * u128::from(opt.0));
                prop_assert!(sol.suboptimality_bound <= sol.epsilon);
            }
        }
        prop_assert_eq!(r.best().map(|s| s.cost), Some(opt));
    }

    #[test]
    fn weighted_astar_within_bound((grid, start) in grid_strategy(), eps in 1.0f64..4.0) {
        let p = SearchParams { initial_epsilon: eps, final_epsilon: eps, ..SearchParams::default() };
        let mut g = grid.clone();
        let r = arastar(&mut g, start, &p).expect("valid");
        if let Some(opt) = dijkstra(&mut grid.clone(), start) {
            let sol = r.best().expect("solution");
            prop_assert_eq!(r.solutions.len(), 1);
            let eps_milli = (sol.epsilon * 1000.0).round() as u128;
            prop_assert!(u128::from(sol.cost.0) * 1000 <= eps_milli * u128::from(opt.0));
            assert_valid_path(&mut g, start, sol);
        } else {
            prop_assert_eq!(r.termination, Termination::NoPath);
        }
    }
}

/// A deterministic pseudo-random 60 × 60 grid with obstacles.
fn fixed_grid() -> Grid {
    let (w, h) = (60, 60);
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let cells = (0..w * h)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            if x.is_multiple_of(5) { None } else { Some((x % 7 + 1) as u8) }
        })
        .collect::<Vec<_>>();
    let mut grid = Grid { w, h, cells, goal: (w - 1, h - 1) };
    grid.cells[0] = Some(1);
    let last = grid.cells.len() - 1;
    grid.cells[last] = Some(1);
    grid
}

#[test]
fn same_graph_same_paths() {
    let run = || {
        let mut g = fixed_grid();
        let r = arastar(&mut g, (0, 0), &SearchParams::default()).expect("valid");
        let a = astar(&mut g, (0, 0), &SearchParams::default());
        let sols: Vec<_> =
            r.solutions.into_iter().map(|s| (s.path, s.cost, s.epsilon, s.expansions)).collect();
        (sols, a.best().map(|s| s.path.clone()), r.expansions, a.expansions)
    };
    let first = run();
    assert!(!first.0.is_empty(), "fixed grid must be solvable");
    assert!(first.0.len() > 1, "ARA* should improve at least once on the fixed grid");
    assert_eq!(first, run());
}

// ---------------------------------------------------------------- unbounded graph

/// An unbounded 4-connected grid of unit cost whose goal (0, 0) is walled in by the
/// ring of cells at Chebyshev distance 1: the search can never finish on its own.
struct Unbounded;

impl SearchGraph for Unbounded {
    type State = (i64, i64);
    fn successors(&mut self, (x, y): (i64, i64), out: &mut Vec<((i64, i64), Cost)>) {
        for (dx, dy) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            let (nx, ny) = (x + dx, y + dy);
            if nx.abs().max(ny.abs()) != 1 {
                out.push(((nx, ny), Cost::ONE));
            }
        }
    }
    fn heuristic(&self, (x, y): (i64, i64)) -> Cost {
        Cost((x.unsigned_abs() + y.unsigned_abs()) * Cost::SCALE)
    }
    fn is_goal(&self, s: (i64, i64)) -> bool {
        s == (0, 0)
    }
}

#[test]
fn time_limit_holds_on_unbounded_graph() {
    let limit = Duration::from_millis(200);
    let p = SearchParams {
        time_limit: Some(limit),
        max_states: Some(20_000_000), // a backstop should the limit fail
        ..SearchParams::default()
    };
    let t = Instant::now();
    let r = arastar(&mut Unbounded, (5, 3), &p).expect("valid");
    let took = t.elapsed();
    assert_eq!(r.termination, Termination::TimeLimit);
    assert!(r.solutions.is_empty());
    assert!(took < 5 * limit, "took {took:?}");
    assert!(took >= limit);

    let t = Instant::now();
    let r = astar(&mut Unbounded, (5, 3), &p);
    assert_eq!(r.termination, Termination::TimeLimit);
    assert!(t.elapsed() < 5 * limit, "took {:?}", t.elapsed());
}

#[test]
fn cancel_flag_stops_search() {
    let flag = AtomicBool::new(false);
    let p = SearchParams {
        max_states: Some(20_000_000), // a backstop should the flag be ignored
        ..SearchParams::default()
    };
    let t = Instant::now();
    let r = std::thread::scope(|scope| {
        scope.spawn(|| {
            std::thread::sleep(Duration::from_millis(100));
            flag.store(true, Ordering::Relaxed);
        });
        let hooks = Hooks { cancel: Some(&flag), ..Hooks::default() };
        arastar_with_hooks(&mut Unbounded, (5, 3), &p, hooks).expect("valid")
    });
    assert_eq!(r.termination, Termination::Cancelled);
    assert!(r.expansions > 0);
    assert!(t.elapsed() < Duration::from_secs(2), "took {:?}", t.elapsed());

    // Already raised: stops before the first expansion.
    let hooks = Hooks { cancel: Some(&flag), ..Hooks::default() };
    let r = astar_with_hooks(&mut Unbounded, (5, 3), &p, hooks);
    assert_eq!(r.termination, Termination::Cancelled);
    assert_eq!(r.expansions, 0);
}

#[test]
fn time_limit_keeps_anytime_solutions() {
    // A limit that ends ARA* somewhere in its iterations still returns what it found,
    // with non-increasing costs, and the termination is the limit or optimality.
    let mut g = fixed_grid();
    let p = SearchParams { time_limit: Some(Duration::from_millis(5)), ..SearchParams::default() };
    let r = arastar(&mut g, (0, 0), &p).expect("valid");
    assert!(matches!(r.termination, Termination::TimeLimit | Termination::OptimalProven));
    assert!(r.solutions.windows(2).all(|w| w[1].cost <= w[0].cost));
}

/// A graph that offers dense indices for half of its states must give exactly the same
/// search as without them (the index is only a faster look-up).
mod dense_index {
    use crate::search::{Cost, SearchGraph, SearchParams, arastar, astar};

    struct Grid {
        n: i32,
        dense: bool,
    }

    impl SearchGraph for Grid {
        type State = (i32, i32);
        fn successors(&mut self, (x, y): (i32, i32), out: &mut Vec<((i32, i32), Cost)>) {
            for (dx, dy) in [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, -1)] {
                let (a, b) = (x + dx, y + dy);
                if a >= 0 && b >= 0 && a < self.n && b < self.n && (a * 7 + b * 3) % 11 != 0 {
                    let w = 1 + ((a * 13 + b * 5) % 4) as u64;
                    out.push(((a, b), Cost(w * Cost::SCALE)));
                }
            }
        }
        fn heuristic(&self, (x, y): (i32, i32)) -> Cost {
            let d = (self.n - 1 - x).max(self.n - 1 - y).max(0) as u64;
            Cost(d * Cost::SCALE)
        }
        fn is_goal(&self, s: (i32, i32)) -> bool {
            s == (self.n - 1, self.n - 1)
        }
        fn dense_len(&self) -> usize {
            if self.dense { (self.n * self.n) as usize } else { 0 }
        }
        fn dense_index(&self, (x, y): (i32, i32)) -> Option<usize> {
            // Only even rows are indexed: the rest go through the hash map.
            (self.dense && y % 2 == 0).then_some((y * self.n + x) as usize)
        }
    }

    #[test]
    fn dense_and_hashed_searches_agree() {
        for n in [5, 17, 40] {
            let a = astar(&mut Grid { n, dense: true }, (0, 0), &SearchParams::default());
            let b = astar(&mut Grid { n, dense: false }, (0, 0), &SearchParams::default());
            assert_eq!(
                a.solutions,
                b.solutions
                    .iter()
                    .map(|s| crate::search::Solution { time: a.solutions[0].time, ..s.clone() })
                    .collect::<Vec<_>>()
            );
            assert_eq!((a.expansions, a.states), (b.expansions, b.states));
            let p = SearchParams::default();
            let c = arastar(&mut Grid { n, dense: true }, (0, 0), &p).expect("params");
            let d = arastar(&mut Grid { n, dense: false }, (0, 0), &p).expect("params");
            let costs = |r: &crate::search::SearchResult<(i32, i32)>| {
                r.solutions.iter().map(|s| (s.cost, s.path.clone())).collect::<Vec<_>>()
            };
            assert_eq!(costs(&c), costs(&d));
        }
    }
}
