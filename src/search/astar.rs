//! A* (Hart, Nilsson & Raphael 1968) with re-opening: optimal for any admissible
//! heuristic, and never re-opens anything when the heuristic is consistent.
//!
//! The search stops when the cheapest goal's `f = g` is at most every key in OPEN —
//! the moment A* would pop it. Ties in `f` go to the smaller `h`, then to the state
//! discovered first (see `open_list`). `SearchParams`' ε fields are ignored; for
//! weighted A*, run [`super::arastar`] with `initial_epsilon == final_epsilon`.

use super::engine::{ClosedPolicy, EPS_ONE, Engine};
use super::{Hooks, SearchGraph, SearchParams, SearchResult, Termination};

/// Optimal A* from `start` to the nearest state accepted by [`SearchGraph::is_goal`].
///
/// Honours `time_limit`, `max_expansions` and `max_states` of `params`. The result holds
/// at most one solution; its termination is [`Termination::OptimalProven`] when one was
/// found.
pub fn astar<G: SearchGraph>(
    graph: &mut G,
    start: G::State,
    params: &SearchParams,
) -> SearchResult<G::State> {
    astar_with_hooks(graph, start, params, Hooks::default())
}

/// [`astar`] with a cancel flag, an expansion log and a solution callback.
pub fn astar_with_hooks<G: SearchGraph>(
    graph: &mut G,
    start: G::State,
    params: &SearchParams,
    hooks: Hooks<'_, G::State>,
) -> SearchResult<G::State> {
    let mut engine = Engine::new(graph, start, params, hooks, EPS_ONE, ClosedPolicy::Reopen);
    if !engine.started() {
        return engine.finish(Termination::StateLimit);
    }
    if let Err(stop) = engine.improve_path() {
        return engine.finish(stop);
    }
    let Some(goal) = engine.goal else {
        return engine.finish(Termination::NoPath);
    };
    let (path, cost) = engine.path_to(goal);
    engine.publish(path, cost, 1.0);
    engine.finish(Termination::OptimalProven)
}
