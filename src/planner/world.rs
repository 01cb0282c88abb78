//! The world a plan is searched on, built once per job: the scenario's height map
//! rasterised (2.5 cm), the cost maps (Sec. IV), the lattice over them, the start and goal
//! states checked (on the map, and poses the robot can stand at), and the heuristic tables
//! of the job's searches toward its goal ([`HeuristicCache`]). A run's plans (the first,
//! the generator's retries, the replans from where the robot stopped) share one
//! [`Prepared`] world.

use super::graph::ManoeuvreSet;
use super::options::{ParamOverrides, PlanError, PlanOptions};
use super::{
    DrivingGoal, HeuristicCache, HybridConfig, HybridGraph, Lattice, LatticeError, LatticeState,
    Neighbourhood,
};
use crate::cost::{Cost as CostValue, CostMaps};
use crate::geometry::Pose2;
use crate::params::{FootModel, Params, StepModel};
use crate::robot::RobotDescription;
use crate::scenario::Scenario;
use crate::terrain::{FlightRule, Flights, HeightMap, flights, rasterise};
use serde::Serialize;
use std::time::Instant;

/// Grid of the plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapInfo {
    /// World position of the corner of cell (0, 0), m.
    pub origin: [f64; 2],
    /// Cell size, m.
    pub resolution: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Orientations per cell.
    pub orientations: u32,
}

/// Cost maps, lattice states of start and goal and the parameters of one scenario, and
/// the heuristic tables the job's searches built: what every search of a job shares.
pub struct Prepared {
    /// The parameters with the options' overrides.
    pub params: Params,
    /// The flights of steps the height map shows ([`terrain_flights`]), which chose the
    /// models the scenario does not name.
    pub flights: Flights,
    /// The cost client.
    pub maps: CostMaps,
    /// The lattice over the maps.
    pub lattice: Lattice,
    /// Start state (neutral footprint).
    pub start: LatticeState,
    /// Goal state (neutral footprint).
    pub goal: LatticeState,
    /// Time spent building, s.
    pub setup_time_s: f64,
    /// The heuristic tables of the searches on these maps ([`super::run_on`]'s graphs).
    pub heuristics: HeuristicCache,
    /// The manoeuvres the robot plans with (`motion::manoeuvres::ALL`).
    pub manoeuvres: &'static dyn ManoeuvreSet,
}

impl Prepared {
    /// Moves the start to `start` (a replan from where the robot stands), checked as
    /// [`prepare`] checks `scenario`'s.
    ///
    /// # Errors
    /// [`PlanError::OffMap`] or [`PlanError::Untraversable`] naming `scenario`.
    pub fn set_start(
        &mut self,
        scenario: &Scenario,
        robot: &RobotDescription,
        start: Pose2,
    ) -> Result<(), PlanError> {
        let world = (&self.maps, &self.lattice);
        self.start = endpoint(scenario, robot, &self.params, world, "start", start)?;
        Ok(())
    }

    /// The hybrid graph for this scenario with `neighbourhood` and k12 = `k12`.
    ///
    /// # Errors
    /// A map too large for the lattice.
    pub fn graph(
        &self,
        robot: &RobotDescription,
        neighbourhood: Neighbourhood,
        k12: f64,
    ) -> Result<HybridGraph<'_>, LatticeError> {
        let params = Params { k12, ..self.params.clone() };
        let config = HybridConfig::new(&params, robot, neighbourhood);
        HybridGraph::new(
            &self.maps,
            robot,
            self.params.orientations,
            config,
            DrivingGoal::at(self.goal),
            self.manoeuvres,
        )
    }

    /// The map grid.
    pub fn map_info(&self) -> MapInfo {
        let hm = self.maps.heights();
        let (nx, ny) = hm.dims();
        MapInfo {
            origin: hm.origin(),
            resolution: hm.resolution(),
            nx,
            ny,
            orientations: self.params.orientations,
        }
    }
}

/// Builds the height map and cost maps of `scenario` and checks its start and goal; the
/// robot plans on it with `manoeuvres`.
///
/// # Errors
/// Invalid parameters, an unbuildable map, or a start / goal off the map or on
/// untraversable terrain.
pub fn prepare(
    scenario: &Scenario,
    robot: &RobotDescription,
    overrides: ParamOverrides,
    manoeuvres: &'static dyn ManoeuvreSet,
) -> Result<Prepared, PlanError> {
    let t0 = Instant::now();
    let heights = scenario_heights(scenario)?;
    let flights = terrain_flights(&heights, robot, &scenario.params);
    let params = params_for(scenario, &flights, overrides)?;
    let (maps, lattice) = build_maps(scenario, robot, &params, &heights)?;
    let endpoint = |which, pose| endpoint(scenario, robot, &params, (&maps, &lattice), which, pose);
    let start = endpoint("start", scenario.start)?;
    let goal = endpoint("goal", scenario.goal)?;
    Ok(Prepared {
        start,
        goal,
        params,
        flights,
        maps,
        lattice,
        setup_time_s: t0.elapsed().as_secs_f64(),
        heuristics: HeuristicCache::default(),
        manoeuvres,
    })
}

/// [`prepare`] with the overrides of `opts` (as [`run`] prepares).
///
/// # Errors
/// As [`prepare`].
pub fn prepare_for(
    scenario: &Scenario,
    robot: &RobotDescription,
    opts: &PlanOptions,
    manoeuvres: &'static dyn ManoeuvreSet,
) -> Result<Prepared, PlanError> {
    prepare(scenario, robot, opts.overrides, manoeuvres)
}

/// The lattice state of `scenario`'s `which` pose `pose`, checked: on the map, and one
/// the robot can stand at ([`unfit`]).
pub(crate) fn endpoint(
    scenario: &Scenario,
    robot: &RobotDescription,
    params: &Params,
    (maps, lattice): (&CostMaps, &Lattice),
    which: &'static str,
    pose: Pose2,
) -> Result<LatticeState, PlanError> {
    let file = || scenario.path.clone();
    let Some(s) = lattice.state(&pose) else {
        return Err(PlanError::OffMap {
            scenario: file(),
            which,
            pose,
            bounds: maps.heights().bounds(),
        });
    };
    if let Some(reason) = unfit(robot, params, maps, &lattice.pose(s)) {
        return Err(PlanError::Untraversable { scenario: file(), which, pose, reason });
    }
    Ok(s)
}

/// Flights of this many steps or more have no path with the paper's step model: its
/// front feet never stand behind neutral, so the feet of one side stay a hip spacing
/// (0.7 m) apart, and on a flight longer than the robot's 0.8 m feet span no footprint
/// lets a rear foot step while the front feet stand on a tread (`docs/models.md`). Where
/// the height map has such a flight (or one taller than a step), the stairs manoeuvres
/// are chosen ([`terrain_models`]).
pub const PAPER_MODEL_FLIGHT_STEPS: u32 = 4;

/// How much a flight's summed risers may exceed the step limit and still count as within
/// it, m: the float noise of adding rises (0.1 + 0.1 + 0.1 > 0.3), far below a height
/// that matters to a foot.
const RISE_TOLERANCE_M: f64 = 1e-6;

/// What a flight is for `robot` under `params` (`terrain::flights`): a riser is a height
/// change a wheel cannot drive over (ΔH_max, eq. 2) up to what a step overcomes (Sec. V);
/// changes closer than a wheel radius are one riser (no wheel stands between them); a
/// tread is too short for the whole robot when it is shorter than the wheels of the
/// neutral footprint from front to back (so the feet stand on different levels), and a
/// flight is at least as wide as those wheels from side to side (a narrower one the robot
/// cannot climb, and two small blocks stacked are clutter).
pub fn flight_rule(robot: &RobotDescription, params: &Params) -> FlightRule {
    let feet = robot.neutral_footprint();
    let extent = |axis: usize| {
        let v = feet.map(|f| f[axis]);
        v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - v.iter().copied().fold(f64::INFINITY, f64::min)
    };
    FlightRule {
        min_rise_m: params.max_foot_height_diff_m,
        max_rise_m: params.max_step_height_m,
        min_tread_m: robot.wheel_radius,
        max_tread_m: extent(0) + 2.0 * robot.wheel_radius,
        min_width_m: extent(1) + robot.wheel_track,
    }
}

/// The flights of steps of `heights` for `robot` under `params` ([`flight_rule`]): what
/// [`terrain_models`] chooses from.
pub fn terrain_flights(heights: &HeightMap, robot: &RobotDescription, params: &Params) -> Flights {
    flights(heights, &flight_rule(robot, params))
}

/// The planner's models for a terrain whose flights of steps are `f`
/// ([`terrain_flights`], issue 63), chosen from heights and the robot alone: on a flight
/// the wheel pair's contact footprint (the paper's r_F disc leaves 5 cm of foothold on a
/// 0.29 m tread, less than the robot's 16 cm wheels stand on), and the stairs manoeuvres
/// where the flight has [`PAPER_MODEL_FLIGHT_STEPS`] risers or more, or climbs more than
/// one step of the paper may (`max_step_height_m`, 0.3 m: then the front and rear feet
/// stand further apart in height than a step takes, and with the paper's manoeuvres three
/// steep steps had no path); elsewhere the paper's models (beside walls the wheel pair
/// needs 2 cm more than the disc, and doorways that the robot drove through it stepped
/// through).
pub fn terrain_models(f: &Flights, params: &Params) -> (FootModel, StepModel) {
    if f.risers < 2 {
        return (FootModel::Paper, StepModel::Paper);
    }
    // (A flight that climbs the step limit exactly is summed with float noise.)
    let taller = f.rise_m > params.max_step_height_m + RISE_TOLERANCE_M;
    let stairs = f.risers >= PAPER_MODEL_FLIGHT_STEPS || taller;
    (FootModel::WheelPair, if stairs { StepModel::Stairs } else { StepModel::Paper })
}

/// The scenario's parameters on a terrain whose flights are `flights`: the models its
/// file does not name chosen from them ([`terrain_models`]).
pub fn scenario_params(scenario: &Scenario, flights: &Flights) -> Params {
    let mut params = scenario.params.clone();
    let named = scenario.named_models;
    let (foot, step) = terrain_models(flights, &params);
    if !named.foot {
        params.foot_model = foot;
    }
    if !named.step {
        params.step_model = step;
    }
    params
}

/// [`scenario_params`] with the options' overrides, validated.
///
/// # Errors
/// [`PlanError::Params`] naming the scenario.
pub fn params_for(
    scenario: &Scenario,
    flights: &Flights,
    overrides: ParamOverrides,
) -> Result<Params, PlanError> {
    let params = overrides.apply(scenario_params(scenario, flights));
    params
        .validate()
        .map_err(|source| PlanError::Params { scenario: scenario.path.clone(), source })?;
    Ok(params)
}

/// The height map of `scenario`, rasterised at its grid resolution.
///
/// # Errors
/// [`PlanError::Map`] naming the scenario.
pub fn scenario_heights(scenario: &Scenario) -> Result<HeightMap, PlanError> {
    let m = &scenario.map;
    rasterise(
        &scenario.terrain,
        [m.x_min, m.y_min],
        [m.x_max - m.x_min, m.y_max - m.y_min],
        scenario.params.grid_resolution_m,
    )
    .map_err(|source| PlanError::Map { scenario: scenario.path.clone(), source })
}

/// The cost maps of `scenario`'s `heights` with `params`, and the lattice over them.
fn build_maps(
    scenario: &Scenario,
    robot: &RobotDescription,
    params: &Params,
    heights: &HeightMap,
) -> Result<(CostMaps, crate::planner::Lattice), PlanError> {
    let file = || scenario.path.clone();
    let maps = CostMaps::build(heights, robot, params)
        .map_err(|source| PlanError::Cost { scenario: file(), source })?;
    let lattice = crate::planner::Lattice::for_map(maps.heights(), params.orientations)
        .map_err(|source| PlanError::Lattice { scenario: file(), source })?;
    Ok((maps, lattice))
}

/// Why the robot cannot start or end at lattice pose `pose`, if it cannot: the driving
/// pose cost must be finite and the feasibility model must fit the robot there.
pub(crate) fn unfit(
    robot: &RobotDescription,
    params: &Params,
    maps: &CostMaps,
    pose: &Pose2,
) -> Option<&'static str> {
    match maps.driving_pose_cost(pose) {
        CostValue::Finite(_)
            if crate::feasibility::DrivingCheck::new(robot, params)
                .lattice_pose(maps, pose)
                .is_ok() =>
        {
            None
        }
        CostValue::Finite(_) => Some(
            "the legs or the body do not fit there, driving or standing (the feasibility model the planner and the motion generator share)",
        ),
        CostValue::Infinite => Some(
            "a wheel stands on or next to an untraversable height difference (infinite foot cost)",
        ),
        CostValue::Unknown => Some("the robot stands on unknown terrain or reaches off the map"),
    }
}

/// The pose a replan starts from: `start` if the planner can start there, else the
/// nearest lattice pose within `radius_m` and two orientation steps of it that it can (the
/// nearest first, then the smaller turn), else `start` (whose planning then fails with
/// [`PlanError::Untraversable`], [`Prepared::set_start`]). A robot that stopped
/// mid-manoeuvre may stand with a wheel next to an edge, where no plan may start; the path
/// follower takes it from where it stands to the new path's first pose.
pub fn nearest_start(
    prep: &Prepared,
    robot: &RobotDescription,
    start: Pose2,
    radius_m: f64,
) -> Pose2 {
    let (params, maps, lattice) = (&prep.params, &prep.maps, &prep.lattice);
    let Some(s) = lattice.state(&start) else {
        return start;
    };
    if unfit(robot, params, maps, &lattice.pose(s)).is_none() {
        return start;
    }
    let r = (radius_m / lattice.resolution).ceil() as i32;
    let n = i32::from(lattice.orientations);
    let mut candidates = Vec::new();
    for di in -r..=r {
        for dj in -r..=r {
            let d = f64::from(di).hypot(f64::from(dj)) * lattice.resolution;
            if d > radius_m {
                continue;
            }
            for dt in [0_i32, 1, -1, 2, -2] {
                candidates.push((d, dt.abs(), di, dj, dt));
            }
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (_, _, di, dj, dt) in candidates {
        let (i, j) = (i32::from(s.i) + di, i32::from(s.j) + dj);
        let (Ok(i), Ok(j)) = (i16::try_from(i), i16::try_from(j)) else { continue };
        if i < 0
            || j < 0
            || i32::from(i) >= i32::from(lattice.nx)
            || i32::from(j) >= i32::from(lattice.ny)
        {
            continue;
        }
        let theta = (i32::from(s.theta) + dt).rem_euclid(n) as u8;
        let pose = lattice.pose(LatticeState::new(i, j, theta));
        if unfit(robot, params, maps, &pose).is_none() {
            return pose;
        }
    }
    start
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::terrain::{Primitive, Stairs};

    fn models_of(steps: u32, rise: f64, tread: f64) -> (FootModel, StepModel) {
        let flight = Primitive::Stairs(Stairs {
            start: [0.0, 0.0],
            width: 1.2,
            steps,
            step_depth: tread,
            step_height: rise,
            landing_depth: 2.0,
            yaw_deg: 25.0,
        });
        let heights = rasterise(&[flight], [-2.0, -3.0], [7.0, 6.0], 0.025).expect("map");
        let params = Params::default();
        let flights = terrain_flights(&heights, &RobotDescription::reference(), &params);
        terrain_models(&flights, &params)
    }

    #[test]
    fn the_heights_choose_the_models() {
        let (paper, wheels) = (FootModel::Paper, FootModel::WheelPair);
        let (paper_steps, stairs) = (StepModel::Paper, StepModel::Stairs);
        // One step is no flight; flat ground neither.
        assert_eq!(models_of(1, 0.2, 0.3), (paper, paper_steps));
        // Two low steps, 0.24 m in all: the wheel pair, the paper's steps.
        assert_eq!(models_of(2, 0.12, 0.3), (wheels, paper_steps));
        // Three steps of 0.1 m climb exactly the 0.3 m step limit: still the paper's.
        assert_eq!(models_of(3, 0.1, 0.35), (wheels, paper_steps));
        // Three steps of 0.17 m climb more than a step may: the stairs manoeuvres.
        assert_eq!(models_of(3, 0.17, 0.29), (wheels, stairs));
        // Four low steps: longer than the robot, the stairs manoeuvres.
        assert_eq!(models_of(4, 0.06, 0.29), (wheels, stairs));
    }
}
