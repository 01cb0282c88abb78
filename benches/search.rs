//! Search core benchmark: A* and ARA* on a 400 × 400 8-connected grid with obstacles
//! and varying cell costs, corner to corner. Asserts the costs it times (ARA* at ε = 1
//! equals A*; the first ARA* solution is within ε = 3 of it), in the style of the
//! `pathfinding` crate's benchmarks.
//!
//! Run: `cargo bench --bench search`.

use criterion::{Criterion, criterion_group, criterion_main};
use momaro::search::{Cost, SearchGraph, SearchParams, arastar, astar};
use std::hint::black_box;

const N: i32 = 400;
const STRAIGHT: u64 = Cost::SCALE;
const DIAGONAL: u64 = 1_414_214;

/// Cells cost 1–4 (0 = blocked); moves cost length × mean cell cost.
struct Grid {
    cells: Vec<u8>,
    goal: (i32, i32),
}

impl Grid {
    /// Deterministic: ~20 % scattered blocked cells plus long walls with gaps.
    fn new() -> Self {
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut cells: Vec<u8> = (0..N * N)
            .map(|_| {
                let r = next();
                if r % 5 == 0 { 0 } else { (r % 4 + 1) as u8 }
            })
            .collect();
        for wall in 1..8 {
            let col = wall * N / 8;
            let gap = (next() % (N as u64 - 20)) as i32;
            for y in 0..N {
                if !(gap..gap + 12).contains(&y) {
                    cells[(y * N + col) as usize] = 0;
                }
            }
        }
        cells[0] = 1;
        cells[(N * N - 1) as usize] = 1;
        Grid { cells, goal: (N - 1, N - 1) }
    }

    fn cell(&self, x: i32, y: i32) -> u8 {
        if x < 0 || y < 0 || x >= N || y >= N { 0 } else { self.cells[(y * N + x) as usize] }
    }
}

impl SearchGraph for Grid {
    type State = (i32, i32);
    fn successors(&mut self, (x, y): (i32, i32), out: &mut Vec<((i32, i32), Cost)>) {
        let here = u64::from(self.cell(x, y));
        for (dx, dy) in [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)] {
            let there = u64::from(self.cell(x + dx, y + dy));
            if there > 0 {
                let len = if dx != 0 && dy != 0 { DIAGONAL } else { STRAIGHT };
                out.push(((x + dx, y + dy), Cost(len * (here + there) / 2)));
            }
        }
    }
    fn heuristic(&self, (x, y): (i32, i32)) -> Cost {
        let dx = u64::from((x - self.goal.0).unsigned_abs());
        let dy = u64::from((y - self.goal.1).unsigned_abs());
        Cost((dx.max(dy) - dx.min(dy)) * STRAIGHT + dx.min(dy) * DIAGONAL)
    }
    fn is_goal(&self, s: (i32, i32)) -> bool {
        s == self.goal
    }
}

fn bench(c: &mut Criterion) {
    let mut grid = Grid::new();
    let exact = astar(&mut grid, (0, 0), &SearchParams::default());
    let opt = exact.best().map(|s| s.cost).expect("the benchmark grid is solvable");
    let first_params =
        SearchParams { initial_epsilon: 3.0, final_epsilon: 3.0, ..SearchParams::default() };
    let full = arastar(&mut grid, (0, 0), &SearchParams::default()).expect("valid params");
    assert_eq!(full.best().map(|s| s.cost), Some(opt));
    let first = full.first().expect("first solution");
    assert!(first.cost.0 <= 3 * opt.0);
    eprintln!(
        "grid {N}x{N}: optimal {opt}, A* {} expansions; ARA* first {} (ε {}, {} expansions), \
         {} solutions, {} expansions, {} states",
        exact.expansions,
        first.cost,
        first.epsilon,
        first.expansions,
        full.solutions.len(),
        full.expansions,
        full.states
    );

    let mut g = c.benchmark_group("search_400x400");
    g.sample_size(20);
    g.bench_function("astar", |b| {
        b.iter(|| {
            let r = astar(&mut grid, black_box((0, 0)), &SearchParams::default());
            assert_eq!(r.best().map(|s| s.cost), Some(opt));
        })
    });
    g.bench_function("arastar_first_solution_eps3", |b| {
        b.iter(|| {
            let r = arastar(&mut grid, black_box((0, 0)), &first_params).expect("valid");
            assert!(r.best().is_some_and(|s| s.cost.0 <= 3 * opt.0));
        })
    });
    g.bench_function("arastar_to_eps1", |b| {
        b.iter(|| {
            let r = arastar(&mut grid, black_box((0, 0)), &SearchParams::default()).expect("valid");
            assert_eq!(r.best().map(|s| s.cost), Some(opt));
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
