//! A mission: the plan the hybrid planner finds with the robot's manoeuvres
//! (`motion::manoeuvres`), expanded into keyframes by the motion generator with MuJoCo's
//! CoM. Where the generator rejects a manoeuvre the planner admitted (it checks every
//! centimetre of a manoeuvre the planner checks at its stances), that edge is left out and
//! the planner searches again, a bounded number of times.

use super::summary::RunError;
use crate::feasibility::MotionOptions;
use crate::motion::manoeuvres::ALL;
use crate::motion::{DetailedPath, MotionError, expand_path};
use crate::planner::{self, ParamOverrides, PlanOptions, PlanSummary, Prepared};
use crate::scenario::Scenario;
use crate::sim::Simulation;

/// A plan and its expansion into keyframes.
#[derive(Debug, Clone)]
pub struct Mission {
    /// The abstract plan.
    pub plan: PlanSummary,
    /// Its keyframes.
    pub detailed: DetailedPath,
}

/// Plans `scenario` on the world `prep` (`planner::prepare_for` with `opts`) from its start
/// and expands the path with `sim`'s CoM model.
///
/// # Errors
/// Planning or the expansion failed.
pub fn plan_mission(
    prep: &Prepared,
    scenario: &Scenario,
    sim: &mut Simulation,
    opts: &PlanOptions,
) -> Result<Mission, RunError> {
    let robot = sim.robot().clone();
    let mut plan = planner::run_on(prep, scenario, &robot, opts)?;
    let mut planning_time_s = plan.planning_time_s;
    // The planner and the generator share one feasibility model, but the generator
    // checks every centimetre of a manoeuvre the planner checks at its stances: what it
    // rejects is left out and the search runs again (ARA*'s first solution, each with
    // the full time limit, so the outcome does not depend on the machine's speed). If
    // no retry expands, the first rejection is the run's failure.
    let mut retry = PlanOptions {
        final_epsilon: opts.initial_epsilon.or(Some(scenario.params.arastar_initial_epsilon)),
        ..opts.clone()
    };
    let mut first: Option<RunError> = None;
    loop {
        let source = match expand_mission_on(prep, sim, &plan, plan.path.len()) {
            Ok(detailed) => {
                plan.planning_time_s = planning_time_s;
                return Ok(Mission { plan, detailed });
            }
            Err(source) => source,
        };
        let name = scenario.name.clone();
        let edge = source
            .index()
            .and_then(|k| Some((*plan.keys.get(k.checked_sub(1)?)?, *plan.keys.get(k)?)));
        let original = first.take().unwrap_or(RunError::Motion { scenario: name, source });
        let Some(e) = edge.filter(|e| {
            retry.forbidden.len() < MAX_REJECTED_MANOEUVRES && !retry.forbidden.contains(e)
        }) else {
            return Err(original);
        };
        retry.forbidden.push(e);
        match planner::run_on(prep, scenario, &robot, &retry) {
            Ok(p) => {
                planning_time_s += p.planning_time_s;
                plan = p;
                first = Some(original);
            }
            Err(_) => return Err(original),
        }
    }
}

/// How far from where the robot stopped a replan may start when no plan can start there
/// (a wheel next to an edge after an aborted manoeuvre), m: a little more than the paper's
/// foot radius r_F (0.12 m), within which an edge makes a wheel's cell untraversable.
pub const REPLAN_START_RADIUS_M: f64 = 0.15;

/// Manoeuvres the generator may reject in one planning before the run gives up with a
/// motion-generation failure.
pub const MAX_REJECTED_MANOEUVRES: usize = 8;

/// Expands the first `end` elements of `plan`'s path (the whole path for its length), on
/// the maps the plan was made on (its k12, step cost factor and models).
///
/// # Errors
/// [`RunError`] if the maps cannot be built or the expansion fails.
pub fn expand_mission(
    scenario: &Scenario,
    sim: &mut Simulation,
    plan: &PlanSummary,
    end: usize,
) -> Result<DetailedPath, RunError> {
    let prep = planner::prepare(scenario, sim.robot(), ParamOverrides::of_plan(plan), &ALL)?;
    expand_mission_on(&prep, sim, plan, end)
        .map_err(|source| RunError::Motion { scenario: scenario.name.clone(), source })
}

/// [`expand_mission`] on the world `prep` the plan was made on (`planner::run_on`), with
/// `sim`'s CoM (MuJoCo's).
///
/// # Errors
/// [`MotionError`] if the expansion fails.
pub fn expand_mission_on(
    prep: &Prepared,
    sim: &mut Simulation,
    plan: &PlanSummary,
    end: usize,
) -> Result<DetailedPath, MotionError> {
    let robot = sim.robot().clone();
    let options = MotionOptions::from_params(&prep.params);
    let end = end.min(plan.path.len());
    expand_path(&plan.path[..end], &robot, &prep.maps, sim, &options)
}
