//! State storage shared by A* and ARA*: a hash map from state to a dense `u32` id and a
//! `Vec` of compact node records, a deterministic Fx-style hasher, the limit checks
//! (time, cancel, expansions) and path reconstruction.
//!
//! A node record is the state plus 40 bytes (`g`, cached `h` and two guidances, parent id, and
//! a packed word holding the CLOSED iteration and the OPEN / INCONS / goal flags), so ARA*'s
//! "CLOSED = ∅" at the start of each iteration is O(1): a state is closed only if it was
//! closed *in the current iteration*.

use super::{Cost, SearchGraph, Termination};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Dense index of a generated state.
pub(crate) type NodeId = u32;
/// "No parent" (the start).
pub(crate) const NO_NODE: NodeId = u32::MAX;

/// Fx-style hasher (as in rustc: rotate, xor, multiply per word) with a final avalanche
/// step so that the low bits used for bucket selection depend on every input bit.
/// Deterministic: no random seed, the same on every run and machine.
#[derive(Debug, Default, Clone, Copy)]
pub struct FxHasher {
    hash: u64,
}

const FX_SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl FxHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.hash = (self.hash.rotate_left(5) ^ word).wrapping_mul(FX_SEED);
    }
}

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.add(u64::from_le_bytes(w));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut w = [0u8; 8];
            w[..rest.len()].copy_from_slice(rest);
            self.add(u64::from_le_bytes(w));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u16(&mut self, i: u16) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }
    #[inline]
    fn write_i8(&mut self, i: i8) {
        self.add(i as u8 as u64);
    }
    #[inline]
    fn write_i16(&mut self, i: i16) {
        self.add(i as u16 as u64);
    }
    #[inline]
    fn write_i32(&mut self, i: i32) {
        self.add(i as u32 as u64);
    }
    #[inline]
    fn write_i64(&mut self, i: i64) {
        self.add(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        // murmur3 fmix64 tail: cheap, and mixes high bits into the low ones.
        let mut h = self.hash;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h
    }
}

/// A `BuildHasher` for [`FxHasher`]: `HashMap<K, V, FxBuild>` is a fast, deterministic map
/// for small integer keys (graphs may use it for their own caches).
pub type FxBuild = BuildHasherDefault<FxHasher>;

const CLOSED_MASK: u32 = (1 << 29) - 1;
const GOAL: u32 = 1 << 29;
const OPEN: u32 = 1 << 30;
const INCONS: u32 = 1 << 31;

/// One generated state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Node<S> {
    pub state: S,
    /// Best known cost from the start.
    pub g: Cost,
    /// Cached heuristic.
    pub h: Cost,
    /// Cached guidance ([`SearchGraph::heuristic_and_guidance`]) in a guided store, else
    /// equal to `h`.
    pub guidance: Cost,
    /// Cached guidance of the greedy list (`SearchGraph::heuristic_and_guidances`).
    pub greedy: Cost,
    /// Predecessor on the best known path.
    pub parent: NodeId,
    /// Bits 0–28: iteration + 1 in which the node was last closed (0: never);
    /// bit 29: goal; bit 30: in OPEN; bit 31: in INCONS.
    meta: u32,
}

impl<S> Node<S> {
    #[inline]
    pub fn is_goal(&self) -> bool {
        self.meta & GOAL != 0
    }
    #[inline]
    pub fn in_open(&self) -> bool {
        self.meta & OPEN != 0
    }
    #[inline]
    pub fn set_open(&mut self, on: bool) {
        if on {
            self.meta |= OPEN;
        } else {
            self.meta &= !OPEN;
        }
    }
    #[inline]
    pub fn in_incons(&self) -> bool {
        self.meta & INCONS != 0
    }
    #[inline]
    pub fn set_incons(&mut self, on: bool) {
        if on {
            self.meta |= INCONS;
        } else {
            self.meta &= !INCONS;
        }
    }
    /// Closed in iteration `iter` (CLOSED of earlier iterations counts as empty).
    #[inline]
    pub fn closed_in(&self, iter: u32) -> bool {
        self.meta & CLOSED_MASK == (iter & CLOSED_MASK) + 1
    }
    #[inline]
    pub fn close(&mut self, iter: u32) {
        self.meta = (self.meta & !CLOSED_MASK) | ((iter & CLOSED_MASK) + 1);
    }
    /// Marks the node as never closed (A*'s re-opening).
    #[inline]
    pub fn unclose(&mut self) {
        self.meta &= !CLOSED_MASK;
    }
}

/// The weighted key `g·EPS_SCALE + ε_milli·h`, saturating.
#[inline]
pub(crate) fn weighted_key(g: Cost, h: Cost, eps_milli: u64) -> u64 {
    g.0.saturating_mul(super::params::EPS_SCALE).saturating_add(h.0.saturating_mul(eps_milli))
}

/// All generated states.
pub(crate) struct NodeStore<S> {
    /// States without a dense index (or all, for graphs without one).
    index: HashMap<S, NodeId, FxBuild>,
    /// Node id + 1 by dense index (0: not generated), for graphs that provide one
    /// ([`SearchGraph::dense_len`]). Zero-initialised, so the allocation is lazy.
    dense: Vec<u32>,
    pub nodes: Vec<Node<S>>,
    limit: usize,
    /// Whether new nodes ask the graph for their guidance (a guided probe runs).
    pub guided: bool,
}

impl<S: Copy + Eq + std::hash::Hash> NodeStore<S> {
    /// An empty store; `dense_len` is the graph's [`SearchGraph::dense_len`].
    pub fn new(max_states: Option<usize>, dense_len: usize) -> Self {
        let cap = (NO_NODE - 1) as usize;
        Self {
            index: HashMap::default(),
            dense: vec![0; dense_len],
            nodes: Vec::new(),
            limit: max_states.map_or(cap, |m| m.min(cap)),
            guided: false,
        }
    }

    /// Forgets every state (its limit kept), for a search that starts over.
    pub fn clear(&mut self) {
        self.index.clear();
        // A fresh zeroed vector, not a fill: its pages are mapped lazily, as in `new`.
        self.dense = vec![0; self.dense.len()];
        self.nodes.clear();
    }

    /// Appends a new node for `state` (g = ∞, h and goal flag from `graph`); `None` when
    /// the store is full.
    #[inline]
    fn push_new<G: SearchGraph<State = S>>(&mut self, graph: &G, state: S) -> Option<NodeId> {
        if self.nodes.len() >= self.limit {
            return None;
        }
        let id = self.nodes.len() as NodeId;
        let meta = if graph.is_goal(state) { GOAL } else { 0 };
        let (h, guidance, greedy) = if self.guided {
            graph.heuristic_and_guidances(state)
        } else {
            let h = graph.heuristic(state);
            (h, h, h)
        };
        self.nodes.push(Node {
            state,
            g: Cost::INFINITY,
            h,
            guidance,
            greedy,
            parent: NO_NODE,
            meta,
        });
        Some(id)
    }

    /// The id of `state`, generating it (g = ∞, h and goal flag from `graph`) if new.
    /// `None` when the state is new and the store is full.
    #[inline]
    pub fn get_or_insert<G: SearchGraph<State = S>>(
        &mut self,
        graph: &G,
        state: S,
    ) -> Option<NodeId> {
        if let Some(k) = graph.dense_index(state).filter(|&k| k < self.dense.len()) {
            let slot = self.dense[k];
            if slot != 0 {
                return Some(slot - 1);
            }
            let id = self.push_new(graph, state)?;
            self.dense[k] = id + 1;
            return Some(id);
        }
        if let Some(&id) = self.index.get(&state) {
            return Some(id);
        }
        let id = self.push_new(graph, state)?;
        self.index.insert(state, id);
        Some(id)
    }

    #[inline]
    pub fn get(&self, id: NodeId) -> &Node<S> {
        &self.nodes[id as usize]
    }

    #[inline]
    pub fn get_mut(&mut self, id: NodeId) -> &mut Node<S> {
        &mut self.nodes[id as usize]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// The node ids from the start to `goal` along parent pointers.
    pub fn trace(&self, goal: NodeId) -> Vec<NodeId> {
        let mut ids = Vec::new();
        let mut cur = goal;
        // Parent pointers form a tree (a parent is only set on a strict improvement of g
        // with non-negative edges, which cannot close a cycle), but bound the walk anyway.
        while cur != NO_NODE && ids.len() <= self.nodes.len() {
            ids.push(cur);
            cur = self.get(cur).parent;
        }
        ids.reverse();
        ids
    }
}

/// The cost of `path` as the graph reports it: for each step, the cheapest edge from one
/// state to the next. If the graph no longer offers an edge (a graph whose successors
/// change while searched), `fallback` (the difference of `g` values) is used for it.
pub(crate) fn path_cost<G: SearchGraph>(
    graph: &mut G,
    path: &[G::State],
    buf: &mut Vec<(G::State, Cost)>,
    mut fallback: impl FnMut(usize) -> Cost,
) -> Cost {
    let mut total = Cost::ZERO;
    for (i, w) in path.windows(2).enumerate() {
        buf.clear();
        graph.successors(w[0], buf);
        let edge = buf
            .iter()
            .filter(|(s, _)| *s == w[1])
            .map(|&(_, c)| c)
            .min()
            .unwrap_or_else(|| fallback(i));
        total += edge;
    }
    total
}

/// Time, cancel and expansion limits, checked before each expansion.
pub(crate) struct Limits<'a> {
    pub start: Instant,
    deadline: Option<Instant>,
    max_expansions: Option<u64>,
    cancel: Option<&'a AtomicBool>,
    tick: u32,
}

/// Read the clock every this many expansions (and at every iteration boundary).
const CLOCK_INTERVAL: u32 = 8;

impl<'a> Limits<'a> {
    pub fn new(
        time_limit: Option<Duration>,
        max_expansions: Option<u64>,
        cancel: Option<&'a AtomicBool>,
    ) -> Self {
        let start = Instant::now();
        Self {
            start,
            deadline: time_limit.and_then(|t| start.checked_add(t)),
            max_expansions,
            cancel,
            tick: 0,
        }
    }

    /// Lowers the expansion cap to `at` (expansions counted from the search's start).
    pub fn cap_expansions(&mut self, at: u64) {
        self.max_expansions = Some(self.max_expansions.map_or(at, |m| m.min(at)));
    }

    /// Whether the search must stop before the next expansion (`expansions` done so far).
    #[inline]
    pub fn check(&mut self, expansions: u64) -> Option<Termination> {
        if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Some(Termination::Cancelled);
        }
        if self.max_expansions.is_some_and(|m| expansions >= m) {
            return Some(Termination::ExpansionLimit);
        }
        self.tick = self.tick.wrapping_add(1);
        if self.tick.is_multiple_of(CLOCK_INTERVAL) {
            return self.check_clock();
        }
        None
    }

    /// Cancel flag and clock only, unconditionally.
    pub fn check_now(&self) -> Option<Termination> {
        if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Some(Termination::Cancelled);
        }
        self.check_clock()
    }

    #[inline]
    fn check_clock(&self) -> Option<Termination> {
        match self.deadline {
            Some(d) if Instant::now() >= d => Some(Termination::TimeLimit),
            _ => None,
        }
    }

    pub fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::{BuildHasher, Hash};

    #[test]
    fn fx_hash_is_deterministic_and_spreads_low_bits() {
        let b = FxBuild::default();
        assert_eq!(b.hash_one((1i32, 2i32)), b.hash_one((1i32, 2i32)));
        // Neighbouring grid cells must land in different buckets of a small table.
        let mut buckets = std::collections::BTreeSet::new();
        for x in 0..16i32 {
            for y in 0..16i32 {
                buckets.insert(b.hash_one((x, y)) & 1023);
            }
        }
        assert!(buckets.len() > 200, "only {} distinct buckets", buckets.len());
        let mut h = FxHasher::default();
        [1u8, 2, 3, 4, 5, 6, 7, 8, 9].hash(&mut h);
        assert_ne!(h.finish(), 0);
    }

    #[test]
    fn meta_bits_are_independent() {
        let mut n = Node {
            state: (),
            g: Cost::ZERO,
            h: Cost::ZERO,
            guidance: Cost::ZERO,
            greedy: Cost::ZERO,
            parent: NO_NODE,
            meta: GOAL,
        };
        n.set_open(true);
        n.close(7);
        n.set_incons(true);
        assert!(n.is_goal() && n.in_open() && n.in_incons() && n.closed_in(7));
        assert!(!n.closed_in(6) && !n.closed_in(8));
        n.set_open(false);
        n.unclose();
        assert!(n.is_goal() && !n.in_open() && n.in_incons() && !n.closed_in(7));
    }
}
