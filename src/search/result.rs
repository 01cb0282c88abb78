//! What a search returns ([`SearchResult`], [`Solution`], [`Termination`]) and the
//! optional hooks a caller passes in ([`Hooks`]: cancel flag, expansion log, solution
//! stream).

use super::Cost;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// One path found by a search.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution<S> {
    /// States from the start to a goal, inclusive.
    pub path: Vec<S>,
    /// The path's cost: the sum of its edge costs as the graph reports them.
    pub cost: Cost,
    /// The heuristic weight ε of the search that produced it (1.0 for A*). The cost is
    /// at most ε times the optimal cost (for a consistent heuristic), except for ARA*'s
    /// guided probe, which may stop sooner (`search::engine`, "Guided search").
    pub epsilon: f64,
    /// The bound it carries, `min(ε, ε′)` with `ε′ = cost / min_{s ∈ OPEN ∪ INCONS}(g(s) +
    /// h(s))` (Likhachev et al. 2003, Sec. 4), or ε′ alone for a guided probe's path (then
    /// it may exceed ε): cost ≤ `suboptimality_bound` · optimal. 1.0 means proven optimal.
    pub suboptimality_bound: f64,
    /// Wall-clock time from the start of the search to this solution.
    pub time: Duration,
    /// Expansions from the start of the search to this solution (cumulative).
    pub expansions: u64,
}

/// Why a search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Termination {
    /// The last solution is optimal (search at ε = 1 finished, or ε′ reached 1).
    OptimalProven,
    /// ARA* finished its search at `final_epsilon` > 1.
    FinalEpsilonReached,
    /// The time limit ran out.
    TimeLimit,
    /// The cancel flag was raised.
    Cancelled,
    /// The graph has no path from the start to a goal (OPEN ran empty).
    NoPath,
    /// `max_expansions` was reached.
    ExpansionLimit,
    /// `max_states` (or the index range) was reached.
    StateLimit,
}

/// The outcome of a search: every solution in the order found, and why it stopped.
///
/// Solution costs never increase along `solutions`; the last is the best.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchResult<S> {
    /// Solutions in the order found. ARA* reports one per completed iteration (the best
    /// path known at that point, with that iteration's ε); A* at most one.
    pub solutions: Vec<Solution<S>>,
    /// Why the search stopped.
    pub termination: Termination,
    /// Total expansions.
    pub expansions: u64,
    /// Total states generated (stored).
    pub states: usize,
    /// Total wall-clock time.
    pub elapsed: Duration,
}

impl<S> SearchResult<S> {
    /// The best (last) solution, if any.
    pub fn best(&self) -> Option<&Solution<S>> {
        self.solutions.last()
    }

    /// The first solution, if any.
    pub fn first(&self) -> Option<&Solution<S>> {
        self.solutions.first()
    }
}

/// One expansion, as shown to [`Hooks::on_expand`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Expansion<S> {
    /// The expanded state.
    pub state: S,
    /// Its cost from the start.
    pub g: Cost,
    /// Its heuristic.
    pub h: Cost,
    /// The ε of the current search.
    pub epsilon: f64,
    /// ARA* iteration (0-based; always 0 for A*).
    pub iteration: u32,
    /// Expansions so far, this one included.
    pub expansions: u64,
}

/// A callback for each expansion.
pub type ExpandHook<'a, S> = &'a mut dyn FnMut(&Expansion<S>);
/// A callback for each solution.
pub type SolutionHook<'a, S> = &'a mut dyn FnMut(&Solution<S>);

/// Optional hooks into a running search. `Hooks::default()` has none.
///
/// In the style of Nav2's smac planner: a cancel check and an expansion log for
/// debugging, plus a stream of solutions for anytime use.
pub struct Hooks<'a, S> {
    /// When this flag reads `true`, the search stops with [`Termination::Cancelled`]
    /// and returns the solutions found so far. Read with relaxed ordering every
    /// expansion and between iterations.
    pub cancel: Option<&'a AtomicBool>,
    /// Called for every expansion (costly; for debugging and visualisation).
    pub on_expand: Option<ExpandHook<'a, S>>,
    /// Called with each solution as soon as it is found.
    pub on_solution: Option<SolutionHook<'a, S>>,
}

impl<S> Default for Hooks<'_, S> {
    fn default() -> Self {
        Self { cancel: None, on_expand: None, on_solution: None }
    }
}

/// A search that could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SearchError {
    /// Invalid parameters.
    #[error("invalid search parameters: {0}")]
    Params(#[from] super::ParamsError),
}
