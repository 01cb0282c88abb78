//! ARA*, Anytime Repairing A* (Likhachev, Gordon & Thrun, "ARA*: Anytime A* with
//! Provable Bounds on Sub-Optimality", NIPS 2003), as used by Klamt & Behnke 2017,
//! Sec. VII-B.
//!
//! A series of weighted-A* searches with `fvalue(s) = g(s) + ε·h(s)` and decreasing ε.
//! Each search (`ImprovePath`, in `engine`) expands every state at most once; a state
//! whose `g` improves after it was expanded goes into INCONS. Between searches ε
//! decreases (exponentially, see [`SearchParams`]), INCONS moves into OPEN, OPEN is
//! re-keyed and CLOSED emptied — so each search reuses all `g` values of the previous
//! ones instead of starting over.
//!
//! Each finished search publishes a [`super::Solution`] whose cost is at most ε times the
//! optimal cost (for a consistent heuristic; Likhachev et al. 2003, Theorem 1), together
//! with the tighter bound ε′ = min(ε, cost / min_{OPEN ∪ INCONS}(g + h)). Published costs
//! never increase: a solution always carries the best path known so far. The search
//! ends when a search at `final_epsilon` finishes, when ε′ reaches `final_epsilon` (1
//! included), or at a limit (time, cancel, expansions, states), returning what it has.
//!
//! **Probe** (`SearchParams::probe_epsilon`, not in the paper): an optional first search
//! at an ε far above the schedule's. Weighted A* at ε = 3 floods the plateaus of a hybrid
//! lattice whose heuristic misses most of the cost near edges (the foot costs), where a
//! greedier search runs straight through: on seed 1's generated up-and-over courses, ε =
//! 50 finds a path within 0.2–1.5 s on every one, ε = 3 on 6 of 13 within 30 s. The
//! probe's solution is published with its certified ε′ and kept as the best so far;
//! then the schedule runs from scratch (same limits, the graph's memos kept), so where
//! it finishes it finds what the paper's ARA* finds, and where a limit stops it the
//! probe's path is the answer. (On the probe's `g` values the schedule's first search
//! would stop at once wherever the probe's poorer path already meets its bound.)
//!
//! **Guided probe** (`SearchParams::probe_guidance`, not in the paper): the probe takes
//! every other expansion from a second OPEN list ordered by `g + ε·guidance`, an estimate
//! the graph may offer beside its admissible heuristic
//! (`SearchGraph::heuristic_and_guidance`; `engine` module docs). A consistent heuristic
//! that is informed in one place can mislead in another: the hybrid lattice's base-pose
//! cost-to-go lets a relaxed base shift over any edge, so beside a flight of stairs with
//! open sides it is lower than in front of it, and a probe ordered by it alone searched
//! the whole floor at every heading (1.6 M expansions) before it stepped onto a two-step
//! flight its guidance (the same heuristic without that term) climbs in 140. Where the
//! heuristic alone was the better guide, alternating costs expansions (a generated mixed
//! course: 170 → 1,041). A probe that has reached no goal after
//! `SearchParams::probe_greedy_after` expansions (20,000) adds a third list, ordered by
//! a guidance alone (greedy best-first; the graph may offer it a guidance of its own,
//! `SearchGraph::heuristic_and_guidances`): where one edge costs more than ε times the
//! heuristic's drop over it, both weighted lists expand every state keyed below its far
//! side first. On a generated two-step flight whose every tread foothold lies near an
//! edge (a step onto the first tread about 440, the heuristic's bound for it about 10),
//! the two-list probe found its path after 930 k expansions (52 s); with the greedy list
//! from its 20,000th expansion it has one at 20,267. Probes that reach a goal sooner
//! are the two-list probe, unchanged. The greedy list ends the probe at the first goal
//! reached, so that probe's path carries its certified ε′ alone, which may exceed ε
//! (`Solution::suboptimality_bound`). ε′ is certified from the admissible heuristic over
//! OPEN and INCONS, which holds whatever order the states were expanded in.
//!
//! Fixed point: ε is held in thousandths, and keys are `g·1000 + ε_milli·h`
//! ([`super::Cost`] micro-units × 1000), so weighting is exact integer arithmetic.

use super::engine::{ClosedPolicy, EPS_ONE, Engine, certified_bound, suboptimality_bound};
use super::params::eps_to_f64;
use super::{Hooks, SearchError, SearchGraph, SearchParams, SearchResult, Termination};

/// Runs ARA* from `start` with the ε schedule and limits of `params`.
///
/// # Errors
/// [`SearchError::Params`] if the ε fields of `params` are invalid.
pub fn arastar<G: SearchGraph>(
    graph: &mut G,
    start: G::State,
    params: &SearchParams,
) -> Result<SearchResult<G::State>, SearchError> {
    arastar_with_hooks(graph, start, params, Hooks::default())
}

/// [`arastar`] with a cancel flag, an expansion log and a solution callback (called as
/// each solution is found, for anytime use).
///
/// # Errors
/// [`SearchError::Params`] if the ε fields of `params` are invalid.
pub fn arastar_with_hooks<G: SearchGraph>(
    graph: &mut G,
    start: G::State,
    params: &SearchParams,
    hooks: Hooks<'_, G::State>,
) -> Result<SearchResult<G::State>, SearchError> {
    let schedule = params.schedule()?;
    // Fig. 3, lines 01'–02': g(start) = 0, OPEN = {start}, ε = ε₀.
    let mut engine =
        Engine::new(graph, start, params, hooks, schedule.first(), ClosedPolicy::Incons);
    if !engine.started() {
        return Ok(engine.finish(Termination::StateLimit));
    }
    let mut best: Option<(Vec<G::State>, super::Cost)> = None;
    if let Some(probe) = schedule.probe {
        // The probe: one search at its ε, its solution published and kept as the best so
        // far; then the schedule from scratch, so that it finds what the paper's ARA*
        // finds (a search on the probe's g values would stop at once wherever the probe's
        // path already meets the bound, with the probe's poorer path).
        if params.probe_guidance {
            engine.restart_with(start, probe, true);
        }
        if let Err(stop) = engine.improve_path() {
            return Ok(engine.finish(stop));
        }
        // A guided probe's greedy list, once it joined, ends it at the first goal it
        // reaches, so its path carries the certified ε′ alone (engine module docs).
        let certified = if engine.greedy_joined() { Bound::Certified } else { Bound::Epsilon };
        if publish_best(&mut engine, &mut best, certified).is_none() {
            return Ok(engine.finish(Termination::NoPath));
        }
        if let Some(stop) = engine.limits.check_now() {
            return Ok(engine.finish(stop));
        }
        engine.restart(start, schedule.initial);
        if let Some(n) = params.schedule_max_expansions {
            let at = engine.expansions.saturating_add(n);
            engine.limits.cap_expansions(at);
        }
    }
    let termination = loop {
        // line 03' / 09': ImprovePath()
        if let Err(stop) = engine.improve_path() {
            break stop;
        }
        // lines 04' / 10': ε′ and publish the current ε′-suboptimal solution
        let Some(bound) = publish_best(&mut engine, &mut best, Bound::Epsilon) else {
            break Termination::NoPath; // OPEN ran empty without reaching a goal
        };
        // line 05': while ε′ > 1
        if bound <= 1.0 {
            break Termination::OptimalProven;
        }
        // ε′ ≤ final ε proves what a search at the final ε would (a probe's solution can).
        if engine.eps <= schedule.final_ || bound <= eps_to_f64(schedule.final_) {
            break if schedule.final_ == EPS_ONE {
                Termination::OptimalProven
            } else {
                Termination::FinalEpsilonReached
            };
        }
        if let Some(stop) = engine.limits.check_now() {
            break stop;
        }
        // lines 06'–08': decrease ε, move INCONS into OPEN, re-key OPEN, CLOSED = ∅
        engine.next_iteration(schedule.next(engine.eps));
    };
    Ok(engine.finish(termination))
}

/// What bounds a search's solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bound {
    /// The weighted search's ε, or the certified ε′ if smaller (Likhachev et al. 2003).
    Epsilon,
    /// The certified ε′ alone: a search that may stop before its ε holds.
    Certified,
}

/// After an `ImprovePath`: the path to the engine's goal becomes `best` unless `best` is
/// cheaper, and `best` is published with its bound ε′ (Likhachev et al. 2003, Fig. 3,
/// lines 04' and 10'), which is returned; `None` if no goal was reached.
fn publish_best<G: SearchGraph>(
    engine: &mut Engine<'_, '_, G>,
    best: &mut Option<(Vec<G::State>, super::Cost)>,
    kind: Bound,
) -> Option<f64> {
    let goal = engine.goal?;
    let lower = engine.lower_bound();
    let (path, cost) = engine.path_to(goal);
    if best.as_ref().is_none_or(|(_, c)| cost <= *c) {
        *best = Some((path, cost));
    }
    let (path, cost) = best.clone()?;
    let bound = match kind {
        Bound::Epsilon => suboptimality_bound(engine.eps, cost, lower),
        Bound::Certified => certified_bound(cost, lower),
    };
    engine.publish(path, cost, bound);
    Some(bound)
}
