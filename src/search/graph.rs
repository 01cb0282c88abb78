//! The one interface between the search and a problem: [`SearchGraph`].
//!
//! As in SBPL, the search knows states only as opaque values; the graph (the paper's
//! "neighbour client", the hybrid pose lattice in `planner`) owns coordinates,
//! successors, costs and the heuristic. Nothing here knows about robots.

use super::Cost;
use std::hash::Hash;

/// A directed graph with non-negative edge costs, a goal test and a heuristic.
///
/// # Contract
/// - [`successors`](Self::successors) *appends* `(state, edge cost)` pairs to `out`
///   (the search clears `out` before each call and reuses it, so no allocation happens
///   per expansion). Edges of cost [`Cost::INFINITY`] are ignored. The order of the
///   successors must be deterministic: the search breaks ties by discovery order, so the
///   same graph gives the same path bit for bit.
/// - [`heuristic`](Self::heuristic) must be **admissible** (never above the true
///   cost-to-go) for A* to return optimal paths, and **consistent**
///   (`h(s) ≤ c(s, s') + h(s')` for every edge, `h(goal) = 0`) for ARA*'s
///   ε-suboptimality bounds (Likhachev, Gordon & Thrun 2003, Theorem 1). A consistent
///   heuristic is admissible. The search calls it once per state and caches the value.
/// - [`is_goal`](Self::is_goal) may accept many states (e.g. any orientation at the goal
///   cell). It is called once per state, when the state is first generated.
///
/// `successors` takes `&mut self` so a graph can cache lazily computed data (cost maps,
/// step feasibility) while it is searched.
pub trait SearchGraph {
    /// A node of the graph. Small and `Copy`: the search stores one per generated state.
    type State: Copy + Eq + Hash;

    /// Appends every successor of `state` with the cost of the edge to it.
    fn successors(&mut self, state: Self::State, out: &mut Vec<(Self::State, Cost)>);

    /// A lower bound on the cost from `state` to the nearest goal (see the contract).
    fn heuristic(&self, state: Self::State) -> Cost;

    /// Whether `state` is a goal.
    fn is_goal(&self, state: Self::State) -> bool;

    /// Optional: the admissible [`heuristic`](Self::heuristic) of `state` together with a
    /// *guidance* estimate that orders the second OPEN list of ARA*'s greedy probe
    /// (`arastar` module docs, "Guided probe"). Guidance need be neither admissible nor
    /// consistent: it only chooses which state the probe expands next, and the bound the
    /// probe certifies comes from the admissible heuristic alone. It should be zero at a
    /// goal. The default is the heuristic itself (the second list then repeats the first).
    fn heuristic_and_guidance(&self, state: Self::State) -> (Cost, Cost) {
        let h = self.heuristic(state);
        (h, h)
    }

    /// Optional: [`heuristic_and_guidance`](Self::heuristic_and_guidance) and a second
    /// guidance for the probe's greedy list (`engine` module docs). The default is the
    /// one guidance for both lists.
    fn heuristic_and_guidances(&self, state: Self::State) -> (Cost, Cost, Cost) {
        let (h, guidance) = self.heuristic_and_guidance(state);
        (h, guidance, guidance)
    }

    /// Optional: whether `state` is the intermediate node of a lazily evaluated edge
    /// (default: none is). A graph may split an edge whose validity is expensive to check
    /// into a cheap edge, at a lower bound of its cost, to an intermediate node, and the
    /// rest of the cost from that node on, checking the edge only when the search expands
    /// the node (as in Lazy Weighted A*, Cohen, Phillips & Likhachev 2014). Returned paths
    /// leave intermediate nodes out; their cost is the sum of both parts. The heuristic
    /// must stay consistent on both parts.
    fn is_intermediate(&self, state: Self::State) -> bool {
        let _ = state;
        false
    }

    /// Optional: the size of a dense index space, `0` (the default) if the graph has none.
    ///
    /// A graph whose states (or most of them, e.g. the cells × orientations of a lattice)
    /// map to small integers can return their count here and the index from
    /// [`dense_index`](Self::dense_index). The search then finds a state's record with one
    /// array read instead of a hash look-up — on a pose lattice the hash look-up is most of
    /// the cost of an expansion, because neighbouring states scatter over the table. States
    /// without a dense index still go through the hash map, so a graph may index only the
    /// common kind of state. The search allocates 4 bytes per index (zeroed memory, so
    /// untouched pages cost nothing).
    fn dense_len(&self) -> usize {
        0
    }

    /// Optional: the dense index of `state`, in `0..dense_len()`, or `None` for a state
    /// that has none (see [`dense_len`](Self::dense_len)). Must be injective: two
    /// different states never share an index. An index `>= dense_len()` is treated as
    /// `None`.
    fn dense_index(&self, state: Self::State) -> Option<usize> {
        let _ = state;
        None
    }
}

impl<G: SearchGraph + ?Sized> SearchGraph for &mut G {
    type State = G::State;

    fn successors(&mut self, state: Self::State, out: &mut Vec<(Self::State, Cost)>) {
        (**self).successors(state, out);
    }

    fn heuristic(&self, state: Self::State) -> Cost {
        (**self).heuristic(state)
    }

    fn is_goal(&self, state: Self::State) -> bool {
        (**self).is_goal(state)
    }

    fn heuristic_and_guidance(&self, state: Self::State) -> (Cost, Cost) {
        (**self).heuristic_and_guidance(state)
    }

    fn heuristic_and_guidances(&self, state: Self::State) -> (Cost, Cost, Cost) {
        (**self).heuristic_and_guidances(state)
    }

    fn is_intermediate(&self, state: Self::State) -> bool {
        (**self).is_intermediate(state)
    }

    fn dense_len(&self) -> usize {
        (**self).dense_len()
    }

    fn dense_index(&self, state: Self::State) -> Option<usize> {
        (**self).dense_index(state)
    }
}
