//! Cost-map benchmarks: rasterising a 20 m × 20 m scenario, building the foot-cost layer
//! and the full `CostMaps` for its 800 × 800 cells, and pose-cost queries.
//!
//! The scenario is deterministic: a platform, ramps, stairs and scattered poles and
//! boxes (40 primitives), like the paper's test arenas. A second, worst-case map has
//! ΔH > 0 in every cell (rough terrain everywhere), so no cell can be skipped.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use momaro::cost::{CostMaps, FootCostLayer};
use momaro::geometry::Pose2;
use momaro::params::Params;
use momaro::robot::RobotDescription;
use momaro::scenario::terrain::{Block, Pole, Primitive, Ramp, Stairs};
use momaro::terrain::{HeightMap, rasterise};

/// Test robot with Momaro-like proportions (the real numbers come from the model).
fn robot() -> RobotDescription {
    RobotDescription::reference()
}

/// xorshift64: a fixed pseudo-random sequence, so the scene is the same every run.
struct Rng(u64);
impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

fn scene() -> Vec<Primitive> {
    let mut ps = vec![
        Primitive::Box(Block { center: [4.0, 0.0], size: [3.0, 4.0], height: 0.2, yaw_deg: 0.0 }),
        Primitive::Ramp(Ramp { center: [1.75, 3.0], size: [1.5, 2.0], height: 0.2, yaw_deg: 0.0 }),
        Primitive::Ramp(Ramp {
            center: [-5.0, -5.0],
            size: [2.0, 1.5],
            height: 0.3,
            yaw_deg: 35.0,
        }),
        Primitive::Stairs(Stairs {
            start: [-3.0, 5.0],
            width: 1.2,
            steps: 4,
            step_depth: 0.3,
            step_height: 0.15,
            landing_depth: 1.0,
            yaw_deg: 90.0,
        }),
    ];
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for k in 0..36 {
        let c = [rng.range(-9.0, 9.0), rng.range(-9.0, 9.0)];
        ps.push(if k % 2 == 0 {
            Primitive::Pole(Pole {
                center: c,
                radius: rng.range(0.03, 0.1),
                height: rng.range(0.1, 0.8),
            })
        } else {
            Primitive::Box(Block {
                center: c,
                size: [rng.range(0.2, 1.0), rng.range(0.2, 1.0)],
                height: rng.range(0.03, 0.4),
                yaw_deg: rng.range(0.0, 90.0),
            })
        });
    }
    ps
}

fn bench(c: &mut Criterion) {
    let params = Params::default();
    let robot = robot();
    let ps = scene();
    let map = rasterise(&ps, [-10.0, -10.0], [20.0, 20.0], params.grid_resolution_m).unwrap();
    assert_eq!(map.dims(), (800, 800));
    let mut rough_rng = Rng(7);
    let rough =
        HeightMap::from_fn([-10.0, -10.0], 0.025, 800, 800, |_, _| rough_rng.range(0.0, 0.04))
            .unwrap();

    let mut g = c.benchmark_group("costmap");
    g.sample_size(20);
    g.bench_function("rasterise_20m_40_primitives", |b| {
        b.iter(|| rasterise(black_box(&ps), [-10.0, -10.0], [20.0, 20.0], 0.025).unwrap())
    });
    g.bench_function("foot_cost_800x800_scene", |b| {
        b.iter(|| FootCostLayer::compute(black_box(&map), &params))
    });
    g.bench_function("foot_cost_800x800_rough_worst_case", |b| {
        b.iter(|| FootCostLayer::compute(black_box(&rough), &params))
    });
    g.bench_function("cost_maps_build_800x800_scene", |b| {
        b.iter(|| CostMaps::build(black_box(&map), &robot, &params).unwrap())
    });
    g.finish();

    let maps = CostMaps::build(&map, &robot, &params).unwrap();
    // 4096 poses over the map and all 64 orientations; a query is one pose.
    let mut rng = Rng(42);
    let poses: Vec<Pose2> = (0..4096)
        .map(|k| {
            let theta = (k % 64) as f64 * std::f64::consts::TAU / 64.0;
            Pose2::new(rng.range(-9.0, 9.0), rng.range(-9.0, 9.0), theta)
        })
        .collect();
    // Spatially coherent queries, as a search makes them: every cell of a 64 x 64 cell
    // (1.6 m) patch in row order, 64 orientations each (262 144 poses).
    let coherent: Vec<Pose2> = (0..64 * 64 * 64)
        .map(|k| {
            let (cell, o) = (k / 64, k % 64);
            let (i, j) = (cell % 64, cell / 64);
            let theta = o as f64 * std::f64::consts::TAU / 64.0;
            Pose2::new(2.0 + i as f64 * 0.025, -1.0 + j as f64 * 0.025, theta)
        })
        .collect();
    let legs = [params.driving_leg_height_m; 4];
    let mut g = c.benchmark_group("pose_cost");
    g.throughput(criterion::Throughput::Elements(poses.len() as u64));
    g.bench_function("driving_pose_cost_random_x4096", |b| {
        b.iter(|| {
            let mut finite = 0usize;
            for p in &poses {
                finite += usize::from(maps.driving_pose_cost(black_box(p)).is_finite());
            }
            finite
        })
    });
    g.throughput(criterion::Throughput::Elements(coherent.len() as u64));
    g.bench_function("driving_pose_cost_coherent_x262144", |b| {
        b.iter(|| {
            let mut finite = 0usize;
            for p in &coherent {
                finite += usize::from(maps.driving_pose_cost(black_box(p)).is_finite());
            }
            finite
        })
    });
    g.throughput(criterion::Throughput::Elements(poses.len() as u64));
    g.bench_function("pose_cost_explicit_feet_x4096", |b| {
        b.iter(|| {
            let mut finite = 0usize;
            for p in &poses {
                let feet = maps.neutral_feet(p);
                finite += usize::from(maps.pose_cost(black_box(p), &feet, &legs).is_finite());
            }
            finite
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
