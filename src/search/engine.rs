//! The best-first engine shared by A* and ARA*: ARA*'s `ImprovePath` (Likhachev, Gordon
//! & Thrun 2003, Fig. 3) over the node store and the OPEN list, with the CLOSED set kept
//! per iteration and the INCONS list.
//!
//! A* is the same loop at ε = 1 where an improved CLOSED state is re-opened instead of
//! being parked in INCONS (A* with re-opening, optimal for any admissible heuristic).
//! The drivers in `astar` and `arastar` own the outer loop.
//!
//! **Guided search** (ARA*'s probe, `arastar` module docs): beside OPEN (ordered by
//! `g + ε·h`) a second list of the same states ordered by `g + ε·guidance`
//! ([`SearchGraph::heuristic_and_guidance`]), and, once the search has made
//! `SearchParams::probe_greedy_after` expansions without reaching a goal, a third,
//! *greedy* one, ordered by a guidance alone (ties: the smaller `g`), its own if the graph
//! offers one ([`SearchGraph::heuristic_and_guidances`]); expansions are
//! taken from the lists in turn (the alternation of Röger & Helmert, "The More, the
//! Merrier: Combining Heuristic Estimators for Satisficing Planning", ICAPS 2010). Every
//! OPEN state is in every list and a state is closed whichever list it leaves by, so it
//! is still expanded at most once per search; `g`, CLOSED, INCONS and the bound ε′ are
//! the unguided search's, computed with the admissible heuristic. The greedy list crosses
//! an edge dearer than ε times the heuristic's drop over it (a step onto a tread whose
//! every foothold lies near an edge), where the weighted lists first expand every state
//! keyed below its far side. It also ends the search as soon as a goal is reached (a
//! goal's guidance is its list's smallest key), so the path of a search it joined is
//! bounded by its ε′ alone, not by ε.

use super::nodes::{Limits, NodeId, NodeStore, path_cost, weighted_key};
use super::open_list::{Entry, OpenList};
use super::params::{EPS_SCALE, eps_to_f64};
use super::result::{ExpandHook, SolutionHook};
use super::{
    Cost, Expansion, Hooks, SearchGraph, SearchParams, SearchResult, Solution, Termination,
};

/// What happens when a CLOSED state's `g` improves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ClosedPolicy {
    /// A*: put it back into OPEN.
    Reopen,
    /// ARA*: park it in INCONS until the next iteration.
    Incons,
}

/// The state of one search (all iterations).
pub(crate) struct Engine<'g, 'h, G: SearchGraph> {
    pub graph: &'g mut G,
    pub store: NodeStore<G::State>,
    pub open: OpenList,
    /// The guidance-ordered OPEN list of a guided search (see the module docs).
    guide: Option<OpenList>,
    /// The greedy list of a guided search: by its guidance alone, ties by `g` (module
    /// docs).
    greedy: Option<OpenList>,
    /// Which list the next expansion comes from (0: OPEN, 1: `guide`, 2: `greedy`).
    turn: u8,
    /// Expansions after which a guided search without a goal adds `greedy`.
    greedy_after: Option<u64>,
    /// ARA*'s INCONS: states whose `g` improved after they were closed this iteration.
    pub incons: Vec<NodeId>,
    succ: Vec<(G::State, Cost)>,
    pub limits: Limits<'h>,
    on_expand: Option<ExpandHook<'h, G::State>>,
    on_solution: Option<SolutionHook<'h, G::State>>,
    pub solutions: Vec<Solution<G::State>>,
    pub expansions: u64,
    /// ε in milli-units.
    pub eps: u64,
    /// Iteration number: a state is in CLOSED iff it was closed in this iteration.
    pub iter: u32,
    /// The goal state with the smallest `g` generated so far.
    pub goal: Option<NodeId>,
    policy: ClosedPolicy,
}

impl<'g, 'h, G: SearchGraph> Engine<'g, 'h, G> {
    /// Sets up a search from `start` (`g(start) = 0`, OPEN = {start}, CLOSED = INCONS = ∅;
    /// Likhachev et al. 2003, Fig. 3, lines 01'–02'). If not even the start can be
    /// stored (`max_states` = 0), [`Engine::started`] is false.
    pub fn new(
        graph: &'g mut G,
        start: G::State,
        params: &SearchParams,
        hooks: Hooks<'h, G::State>,
        eps: u64,
        policy: ClosedPolicy,
    ) -> Self {
        let dense_len = graph.dense_len();
        let mut engine = Self {
            graph,
            store: NodeStore::new(params.max_states, dense_len),
            open: OpenList::new(),
            guide: None,
            greedy: None,
            turn: 0,
            greedy_after: params.probe_greedy_after,
            incons: Vec::new(),
            succ: Vec::with_capacity(32),
            limits: Limits::new(params.time_limit, params.max_expansions, hooks.cancel),
            on_expand: hooks.on_expand,
            on_solution: hooks.on_solution,
            solutions: Vec::new(),
            expansions: 0,
            eps,
            iter: 0,
            goal: None,
            policy,
        };
        engine.seed(start);
        engine
    }

    /// `g(start) = 0`, OPEN = {start} at the current ε.
    fn seed(&mut self, start: G::State) {
        let eps = self.eps;
        if let Some(id) = self.store.get_or_insert(&*self.graph, start) {
            let n = self.store.get_mut(id);
            n.g = Cost::ZERO;
            let (h, goal) = (n.h, n.is_goal());
            if goal {
                self.goal = Some(id);
            }
            // An infinite heuristic proves that no path leaves the start: OPEN stays
            // empty and the search ends at once with no path.
            if goal || !h.is_infinite() {
                n.set_open(true);
                let guidance = (n.guidance, n.greedy);
                let lists = OpenLists::of(&mut self.open, &mut self.guide, &mut self.greedy);
                lists.push(id, Cost::ZERO, h, guidance, eps);
            }
        }
    }

    /// Starts over from `start` at ε = `eps` with no state known (a fresh search), keeping
    /// the limits, the expansion count, the hooks and the published solutions: ARA*'s
    /// schedule after its probe.
    pub fn restart(&mut self, start: G::State, eps: u64) {
        self.restart_with(start, eps, false);
    }

    /// [`Engine::restart`] as a guided search (module docs) if `guided`: nodes then cache
    /// the graph's guidance and OPEN has its guidance-ordered list (and its greedy one
    /// from `SearchParams::probe_greedy_after` expansions on).
    pub fn restart_with(&mut self, start: G::State, eps: u64, guided: bool) {
        self.store.clear();
        self.store.guided = guided;
        self.guide = guided.then(OpenList::new);
        self.greedy = (guided && self.greedy_after == Some(0)).then(OpenList::new);
        self.turn = 0;
        self.open = OpenList::new();
        self.incons.clear();
        self.goal = None;
        self.eps = eps;
        self.iter += 1;
        self.seed(start);
    }

    /// Whether an OPEN entry is current: its state is still in OPEN with this key at `eps`.
    #[inline]
    fn is_valid(store: &NodeStore<G::State>, e: &Entry, eps: u64) -> bool {
        let n = store.get(e.node);
        n.in_open() && weighted_key(n.g, n.h, eps) == e.key
    }

    /// Whether a guide-list entry is current: its state is still in OPEN with this
    /// guidance key at `eps`.
    #[inline]
    fn is_valid_guide(store: &NodeStore<G::State>, e: &Entry, eps: u64) -> bool {
        let n = store.get(e.node);
        n.in_open() && weighted_key(n.g, n.guidance, eps) == e.key
    }

    /// Whether this search's greedy list has joined it (its path is then bounded by ε′
    /// alone).
    pub fn greedy_joined(&self) -> bool {
        self.greedy.is_some()
    }

    /// Adds the greedy list to a guided search under way: every OPEN state, keyed by its
    /// guidance.
    fn start_greedy(&mut self) {
        let mut greedy = OpenList::new();
        for e in self.open.iter() {
            if Self::is_valid(&self.store, e, self.eps) {
                let n = self.store.get(e.node);
                greedy.push(greedy_entry(e.node, n.g, n.greedy));
            }
        }
        self.greedy = Some(greedy);
    }

    /// Whether a greedy-list entry is current: its state is still in OPEN with this `g`
    /// (its guidance never changes).
    #[inline]
    fn is_valid_greedy(store: &NodeStore<G::State>, e: &Entry) -> bool {
        let n = store.get(e.node);
        n.in_open() && greedy_entry(e.node, n.g, n.greedy) == *e
    }

    /// `ImprovePath()`: expand states in key order until the best goal's key is at most
    /// the smallest key in OPEN (Likhachev et al. 2003, Fig. 3, line 02), or OPEN is
    /// empty. `Err` with the reason when a limit stops it first. A guided search takes
    /// its states from OPEN, the guidance-ordered and the greedy list in turn and also
    /// stops when the goal's key in either of those is at most that list's smallest (for
    /// the greedy list: once a goal is reached).
    pub fn improve_path(&mut self) -> Result<(), Termination> {
        let eps = self.eps;
        let iter = self.iter;
        loop {
            if self.guide.is_some()
                && self.greedy.is_none()
                && self.goal.is_none()
                && self.greedy_after.is_some_and(|n| self.expansions >= n)
            {
                self.start_greedy();
            }
            let store = &self.store;
            let Some(top) = self.open.peek_valid(|e| Self::is_valid(store, e, eps)) else {
                return Ok(()); // OPEN = ∅
            };
            let guided_top = self
                .guide
                .as_mut()
                .and_then(|g| g.peek_valid(|e| Self::is_valid_guide(store, e, eps)));
            let greedy_top = self
                .greedy
                .as_mut()
                .and_then(|g| g.peek_valid(|e| Self::is_valid_greedy(store, e)));
            if let Some(goal) = self.goal {
                let gn = self.store.get(goal);
                // while fvalue(s_goal) > min_{s ∈ OPEN} fvalue(s)
                if weighted_key(gn.g, gn.h, eps) <= top.key
                    || guided_top.is_some_and(|t| weighted_key(gn.g, gn.guidance, eps) <= t.key)
                    || greedy_top.is_some_and(|t| gn.greedy.0 <= t.key)
                {
                    return Ok(());
                }
            }
            if let Some(t) = self.limits.check(self.expansions) {
                return Err(t);
            }
            // line 03: remove s with the smallest fvalue from OPEN; CLOSED = CLOSED ∪ {s}
            // (a guided search: from each list in turn)
            let turn = self.turn;
            let lists = 1 + u8::from(self.guide.is_some()) + u8::from(self.greedy.is_some());
            self.turn = (turn + 1) % lists;
            let id = match (turn, guided_top, greedy_top, &mut self.guide, &mut self.greedy) {
                (1, Some(t), _, Some(list), _) | (2, _, Some(t), _, Some(list)) => {
                    list.pop_valid(|_| true);
                    t.node
                }
                _ => {
                    self.open.pop_valid(|_| true);
                    top.node
                }
            };
            let node = self.store.get_mut(id);
            node.set_open(false);
            node.close(iter);
            let (state, g, h) = (node.state, node.g, node.h);
            self.expansions += 1;
            if let Some(log) = self.on_expand.as_deref_mut() {
                log(&Expansion {
                    state,
                    g,
                    h,
                    epsilon: eps_to_f64(eps),
                    iteration: iter,
                    expansions: self.expansions,
                });
            }
            // line 04: for each successor s' of s
            self.succ.clear();
            self.graph.successors(state, &mut self.succ);
            for &(t, c) in &self.succ {
                if c.is_infinite() {
                    continue;
                }
                let ng = g.saturating_add(c);
                if ng.is_infinite() {
                    continue;
                }
                // lines 05–06: a state never visited before has g = ∞
                let Some(tid) = self.store.get_or_insert(&*self.graph, t) else {
                    return Err(Termination::StateLimit);
                };
                let best_goal_g = self.goal.map_or(Cost::INFINITY, |b| self.store.get(b).g);
                let tn = self.store.get_mut(tid);
                // An infinite (admissible) heuristic: the goal cannot be reached from t.
                if tn.h.is_infinite() {
                    continue;
                }
                // line 07: if g(s') > g(s) + c(s, s')
                if ng >= tn.g {
                    continue;
                }
                tn.g = ng;
                tn.parent = id;
                if tn.is_goal() && ng < best_goal_g {
                    self.goal = Some(tid);
                }
                if tn.closed_in(iter) {
                    match self.policy {
                        // line 11: else insert s' into INCONS
                        ClosedPolicy::Incons => {
                            if !tn.in_incons() {
                                tn.set_incons(true);
                                self.incons.push(tid);
                            }
                            continue;
                        }
                        ClosedPolicy::Reopen => tn.unclose(),
                    }
                }
                // lines 09–10: if s' ∉ CLOSED, insert/update s' in OPEN with fvalue(s')
                tn.set_open(true);
                let (h, guidance) = (tn.h, (tn.guidance, tn.greedy));
                let lists = OpenLists::of(&mut self.open, &mut self.guide, &mut self.greedy);
                lists.push(tid, ng, h, guidance, eps);
            }
        }
    }

    /// `min_{s ∈ OPEN ∪ INCONS} (g(s) + h(s))`, a lower bound on the optimal cost for a
    /// consistent heuristic (Likhachev et al. 2003, Sec. 4, ε′). ∞ if both are empty.
    pub fn lower_bound(&self) -> Cost {
        let open =
            self.open.iter().filter(|e| Self::is_valid(&self.store, e, self.eps)).map(|e| e.node);
        open.chain(self.incons.iter().copied())
            .map(|id| {
                let n = self.store.get(id);
                n.g.saturating_add(n.h)
            })
            .min()
            .unwrap_or(Cost::INFINITY)
    }

    /// The path to `goal` and its cost as the graph reports its edges.
    pub fn path_to(&mut self, goal: NodeId) -> (Vec<G::State>, Cost) {
        let ids = self.store.trace(goal);
        let path: Vec<G::State> = ids.iter().map(|&i| self.store.get(i).state).collect();
        let store = &self.store;
        let cost = path_cost(&mut *self.graph, &path, &mut self.succ, |i| {
            store.get(ids[i + 1]).g.saturating_sub(store.get(ids[i]).g)
        });
        let graph = &*self.graph;
        let path = path.into_iter().filter(|&s| !graph.is_intermediate(s)).collect();
        (path, cost)
    }

    /// Records a solution (and streams it to the hook).
    pub fn publish(&mut self, path: Vec<G::State>, cost: Cost, bound: f64) {
        let sol = Solution {
            path,
            cost,
            epsilon: eps_to_f64(self.eps),
            suboptimality_bound: bound,
            time: self.limits.elapsed(),
            expansions: self.expansions,
        };
        if let Some(f) = self.on_solution.as_deref_mut() {
            f(&sol);
        }
        self.solutions.push(sol);
    }

    /// ARA*, Fig. 3 lines 10'–12': move INCONS into OPEN, re-key OPEN with the new ε,
    /// and start a new iteration (CLOSED = ∅). O(|OPEN| + |INCONS|).
    pub fn next_iteration(&mut self, new_eps: u64) {
        // Guidance orders one search (the probe); later iterations are the paper's.
        self.guide = None;
        self.greedy = None;
        self.turn = 0;
        self.store.guided = false;
        let old = self.eps;
        let mut entries = self.open.take_entries();
        let store = &self.store;
        entries.retain_mut(|e| {
            if Self::is_valid(store, e, old) {
                let n = store.get(e.node);
                e.key = weighted_key(n.g, n.h, new_eps);
                true
            } else {
                false
            }
        });
        for id in self.incons.drain(..) {
            let n = self.store.get_mut(id);
            n.set_incons(false);
            if !n.in_open() {
                n.set_open(true);
                entries.push(Entry { key: weighted_key(n.g, n.h, new_eps), h: n.h.0, node: id });
            }
        }
        self.open.rebuild(entries);
        self.eps = new_eps;
        self.iter += 1;
    }

    /// The final result.
    pub fn finish(self, termination: Termination) -> SearchResult<G::State> {
        SearchResult {
            solutions: self.solutions,
            termination,
            expansions: self.expansions,
            states: self.store.len(),
            elapsed: self.limits.elapsed(),
        }
    }

    /// Whether the start could be stored at all.
    pub fn started(&self) -> bool {
        self.store.len() > 0
    }
}

/// OPEN and, in a guided search, its guidance-ordered and greedy lists.
struct OpenLists<'a> {
    open: &'a mut OpenList,
    guide: Option<&'a mut OpenList>,
    greedy: Option<&'a mut OpenList>,
}

impl<'a> OpenLists<'a> {
    fn of(
        open: &'a mut OpenList,
        guide: &'a mut Option<OpenList>,
        greedy: &'a mut Option<OpenList>,
    ) -> Self {
        Self { open, guide: guide.as_mut(), greedy: greedy.as_mut() }
    }

    /// Inserts node `id` (cost `g`, heuristic `h`, the guidance of the guidance-ordered
    /// list and of the greedy one `(guide, greedy)`) into every list at ε `eps`.
    #[inline]
    fn push(self, id: NodeId, g: Cost, h: Cost, (guide_h, greedy_h): (Cost, Cost), eps: u64) {
        self.open.push(Entry { key: weighted_key(g, h, eps), h: h.0, node: id });
        if let Some(guide) = self.guide {
            guide.push(Entry { key: weighted_key(g, guide_h, eps), h: guide_h.0, node: id });
        }
        if let Some(greedy) = self.greedy {
            greedy.push(greedy_entry(id, g, greedy_h));
        }
    }
}

/// A greedy-list entry: keyed by the guidance alone, ties broken by `g` (the entry's
/// second field) and then by discovery.
#[inline]
fn greedy_entry(id: NodeId, g: Cost, guidance: Cost) -> Entry {
    Entry { key: guidance.0, h: g.0, node: id }
}

/// `cost / lower_bound`, at least 1 (∞ for a lower bound of 0): the ε′ a path carries
/// whatever order the search expanded in (for a consistent heuristic).
pub(crate) fn certified_bound(cost: Cost, lower_bound: Cost) -> f64 {
    if lower_bound >= cost {
        return 1.0;
    }
    if lower_bound == Cost::ZERO {
        return f64::INFINITY;
    }
    (cost.0 as f64 / lower_bound.0 as f64).max(1.0)
}

/// `min(ε, cost / lower_bound)`, at least 1.
pub(crate) fn suboptimality_bound(eps: u64, cost: Cost, lower_bound: Cost) -> f64 {
    certified_bound(cost, lower_bound).min(eps_to_f64(eps))
}

/// ε = 1 in milli-units.
pub(crate) const EPS_ONE: u64 = EPS_SCALE;
