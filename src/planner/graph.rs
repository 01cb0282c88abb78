//! The hybrid driving-stepping graph (Klamt & Behnke 2017, Sec. V): driving in the
//! neutral footprint plus the stepping manoeuvres of Fig. 5 and Fig. 6, as one
//! [`SearchGraph`] over [`LatticeState`]s `(i, j, θ, footprint)`.
//!
//! **States.** The base pose is a lattice pose (`lattice`); the footprint id names four
//! longitudinal foot offsets in a `FootprintTable` (`footprint`). A foot stands at its
//! neutral position (x', y') in the base frame moved by its offset along x'.
//!
//! **Manoeuvres.** The graph knows no manoeuvre itself: each is a [`Manoeuvre`], one unit
//! per manoeuvre in `motion::manoeuvres` (drive and turn, abstract step, base shift,
//! wheel moves), which offers its successors of a state, checked by the motion
//! generator's own expansion, and says which term of the heuristic bounds it
//! ([`Relaxation`]). A [`ManoeuvreSet`] makes them fresh for each graph, in the order
//! their successors are offered; the state they share (maps, lattice, footprints,
//! stances, the heuristic's tables, counters) is the [`GraphCore`]. All manoeuvre costs
//! but driving and turning are multiplied by the step-related factor
//! (`HybridConfig::step_cost_factor`, Sec. V, Fig. 7: the calibration is documented on
//! `Params::step_cost_factor`).
//!
//! **Lazy edges** (issue 15). A manoeuvre whose exact check is expensive (the step: the
//! standing rule's IK for the after-step state, the generator's own step check, about a
//! quarter of a millisecond when they pass, and most steps the search generates are
//! never expanded) may offer an *intermediate node* instead: the same pose with
//! [`LatticeState::pending`] set to one of the manoeuvre's tags, at a lower bound of the
//! edge's cost. Expanding the node asks the manoeuvre for the edge itself at the rest of
//! its cost, or nothing ([`Manoeuvre::pending_successor`]). The graph is the same (paths
//! and costs are those of checking every edge at once), and the search's paths leave the
//! nodes out ([`SearchGraph::is_intermediate`]). The node's heuristic comes from the
//! manoeuvre ([`Manoeuvre::pending_heuristic`]), consistent on both of its edges.
//! [`HybridGraph::labelled_successors`] and [`HybridGraph::edge`] give the checked edges
//! directly. Each manoeuvre's tags are numbered after those of the manoeuvres before it
//! in the set, from 1.
//!
//! **Heuristic**: see `heuristic`; built from the manoeuvres' relaxations at its first
//! query.

use super::config::HybridConfig;
use super::core::{GraphCore, PoseKey, Stance};
use super::driving::DrivingGoal;
use super::heuristic::Relaxation;
use super::lattice::{LatticeError, LatticeState, NEUTRAL_FOOTPRINT};
use crate::cost::CostMaps;
use crate::path::EdgeLabel;
use crate::robot::RobotDescription;
use crate::search::{Cost, SearchGraph};
use std::ops::{Deref, DerefMut};

/// One manoeuvre of the hybrid graph, as the planner sees it: its successors of a state,
/// checked, with their costs and labels, and which term of the heuristic bounds its
/// edges. Made fresh for each graph by a [`ManoeuvreSet`], so the memo tables of its
/// checks live with it.
pub trait Manoeuvre {
    /// Which term of the heuristic bounds this manoeuvre's edges (the proofs are in
    /// `heuristic`).
    fn relaxation(&self) -> Relaxation;

    /// Appends the successors of state `s` (not an intermediate node) by this manoeuvre
    /// to `out`. `stance` is where `s`'s feet stand, `None` where no manoeuvre that
    /// leaves or changes the footprint may start ([`GraphCore::stance`]). With `lazy`, a
    /// manoeuvre may offer intermediate nodes ([`Successors::pending`]) for the search;
    /// without, the checked edges themselves.
    fn successors(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        stance: Option<&Stance>,
        lazy: bool,
        out: &mut Successors<'_>,
    );

    /// How many tags of [`LatticeState::pending`] this manoeuvre's intermediate nodes use
    /// (none: it offers none).
    fn pending_tags(&self) -> u8 {
        0
    }

    /// The edge out of intermediate node `p` with this manoeuvre's tag `tag` (from 1):
    /// checked now, at the rest of its cost (its full cost less what the edge into `p`
    /// charged); `None` when the check fails.
    fn pending_successor(
        &mut self,
        _core: &mut GraphCore<'_>,
        _p: LatticeState,
        _tag: u8,
    ) -> Option<(LatticeState, Cost, EdgeLabel)> {
        None
    }

    /// The heuristic, the probe's guidance and its greedy estimate of intermediate node
    /// `p` with this manoeuvre's tag `tag`; `None` where the node has no successor.
    fn pending_heuristic(
        &self,
        _core: &GraphCore<'_>,
        _p: LatticeState,
        _tag: u8,
    ) -> Option<(Cost, Cost, Cost)> {
        None
    }
}

/// The manoeuvres a robot can make, made fresh for each graph (in the order their
/// successors are offered).
pub trait ManoeuvreSet: Sync {
    /// A fresh instance of every manoeuvre, with empty memo tables.
    fn instantiate(&self) -> Vec<Box<dyn Manoeuvre>>;
}

/// Where a manoeuvre's successors go: the search's `(state, cost)` list and, when asked
/// for, their labels.
pub struct Successors<'o> {
    edges: &'o mut Vec<(LatticeState, Cost)>,
    labels: Option<&'o mut Vec<EdgeLabel>>,
    /// The pending tag before the current manoeuvre's first.
    tag_base: u8,
}

impl<'o> Successors<'o> {
    /// Successors appended to `edges`, labelled into `labels` where given (for tests and
    /// callers that run a manoeuvre outside a graph).
    pub fn new(
        edges: &'o mut Vec<(LatticeState, Cost)>,
        labels: Option<&'o mut Vec<EdgeLabel>>,
    ) -> Self {
        Self { edges, labels, tag_base: 0 }
    }

    /// Offers the edge to `t` at cost `c`, labelled `label` (built only when labels are
    /// wanted).
    pub fn push(&mut self, t: LatticeState, c: Cost, label: impl FnOnce() -> EdgeLabel) {
        self.edges.push((t, c));
        if let Some(labels) = &mut self.labels {
            labels.push(label());
        }
    }

    /// Offers the intermediate node of `s` with this manoeuvre's tag `tag` (from 1) at cost
    /// `c` (see "Lazy edges" in the module docs).
    pub fn pending(
        &mut self,
        s: LatticeState,
        tag: u8,
        c: Cost,
        label: impl FnOnce() -> EdgeLabel,
    ) {
        let p = LatticeState { pending: self.tag_base + tag, ..s };
        self.push(p, c, label);
    }

    /// The edges offered so far (by every manoeuvre), for appending unlabelled ones.
    pub fn edges(&mut self) -> &mut Vec<(LatticeState, Cost)> {
        self.edges
    }

    /// Whether labels are wanted; a manoeuvre that appends to [`Self::edges`] directly
    /// labels them with [`Self::label`].
    pub fn wants_labels(&self) -> bool {
        self.labels.is_some()
    }

    /// Labels the next edge appended directly to [`Self::edges`].
    pub fn label(&mut self, label: EdgeLabel) {
        if let Some(labels) = &mut self.labels {
            labels.push(label);
        }
    }
}

/// The hybrid graph over one cost map: its [`GraphCore`] and its manoeuvres.
pub struct HybridGraph<'c> {
    core: GraphCore<'c>,
    manoeuvres: Vec<Box<dyn Manoeuvre>>,
    /// Per manoeuvre, the pending tag before its first.
    tag_bases: Vec<u8>,
    /// Edges the motion generator rejected in an earlier plan (`closed_loop`): left out.
    forbidden: Vec<(PoseKey, PoseKey)>,
    /// Scratch buffers for labelled successors.
    labels: Vec<EdgeLabel>,
    edges: Vec<(LatticeState, Cost)>,
}

impl<'c> Deref for HybridGraph<'c> {
    type Target = GraphCore<'c>;

    fn deref(&self) -> &GraphCore<'c> {
        &self.core
    }
}

impl DerefMut for HybridGraph<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.core
    }
}

impl<'c> HybridGraph<'c> {
    /// The hybrid graph on `maps` (lattice over its height map with `orientations`
    /// orientations) searching for `goal`, with the manoeuvres of `set`.
    ///
    /// # Errors
    /// A map too large for the lattice or an invalid orientation count.
    pub fn new(
        maps: &'c CostMaps,
        robot: &RobotDescription,
        orientations: u32,
        config: HybridConfig,
        goal: DrivingGoal,
        set: &dyn ManoeuvreSet,
    ) -> Result<Self, LatticeError> {
        let manoeuvres = set.instantiate();
        let relaxations = manoeuvres.iter().map(|m| m.relaxation()).collect();
        let mut tag_bases = Vec::with_capacity(manoeuvres.len());
        let mut next = 0u8;
        for m in &manoeuvres {
            tag_bases.push(next);
            next = next.saturating_add(m.pending_tags());
        }
        Ok(Self {
            core: GraphCore::new(maps, robot, orientations, config, goal, relaxations)?,
            manoeuvres,
            tag_bases,
            forbidden: Vec::new(),
            labels: Vec::new(),
            edges: Vec::new(),
        })
    }

    /// This graph with the heuristic tables of `cache` (see
    /// [`super::heuristic::HeuristicCache`]).
    #[must_use]
    pub fn with_heuristic_cache(self, cache: &'c super::heuristic::HeuristicCache) -> Self {
        Self { core: self.core.with_heuristic_cache(cache), ..self }
    }

    /// Leaves out the edges between these states from now on (the motion generator could
    /// not expand them: see `closed_loop`'s mission planning).
    pub fn forbid(&mut self, edges: &[(PoseKey, PoseKey)]) {
        self.forbidden.extend_from_slice(edges);
    }

    /// The manoeuvre that owns intermediate node `p`, and its tag for it.
    fn owner(&self, p: LatticeState) -> Option<(usize, u8)> {
        let k = self.tag_bases.iter().rposition(|&b| b < p.pending)?;
        let tag = p.pending - self.tag_bases[k];
        (tag <= self.manoeuvres[k].pending_tags()).then_some((k, tag))
    }

    /// Appends every successor of pose state `s` (not an intermediate node) to `edges`,
    /// and with `labels` their labels, in the manoeuvres' order.
    fn pose_successors(
        &mut self,
        s: LatticeState,
        lazy: bool,
        edges: &mut Vec<(LatticeState, Cost)>,
        labels: Option<&mut Vec<EdgeLabel>>,
    ) {
        let stance = self.core.stance(s);
        let mut out = Successors { edges, labels, tag_base: 0 };
        for (m, &base) in self.manoeuvres.iter_mut().zip(&self.tag_bases) {
            out.tag_base = base;
            m.successors(&mut self.core, s, stance.as_ref(), lazy, &mut out);
        }
    }

    /// The checked edge out of intermediate node `p` (see "Lazy edges").
    fn pending_successor(&mut self, p: LatticeState) -> Option<(LatticeState, Cost, EdgeLabel)> {
        let (k, tag) = self.owner(p)?;
        self.manoeuvres[k].pending_successor(&mut self.core, p, tag)
    }

    /// Every successor of `s` with its cost and label, in the search's order.
    pub fn labelled_successors(&mut self, s: LatticeState) -> Vec<(LatticeState, Cost, EdgeLabel)> {
        if s.pending != 0 {
            return self.pending_successor(s).into_iter().collect();
        }
        let (mut edges, mut labels) =
            (std::mem::take(&mut self.edges), std::mem::take(&mut self.labels));
        edges.clear();
        labels.clear();
        self.pose_successors(s, false, &mut edges, Some(&mut labels));
        let out = edges.iter().zip(&labels).map(|(&(t, c), &m)| (t, c, m)).collect();
        (self.edges, self.labels) = (edges, labels);
        out
    }

    /// The cheapest edge from `s` to `t`, labelled; `None` if there is none.
    pub fn edge(&mut self, s: LatticeState, t: LatticeState) -> Option<(Cost, EdgeLabel)> {
        self.labelled_successors(s)
            .into_iter()
            .filter(|(u, _, _)| *u == t)
            .map(|(_, c, m)| (c, m))
            .min_by_key(|(c, _)| *c)
    }
}

impl SearchGraph for HybridGraph<'_> {
    type State = LatticeState;

    fn successors(&mut self, s: LatticeState, out: &mut Vec<(LatticeState, Cost)>) {
        let first = out.len();
        if s.pending != 0 {
            out.extend(self.pending_successor(s).map(|(t, c, _)| (t, c)));
        } else {
            self.pose_successors(s, true, out, None);
        }
        if !self.forbidden.is_empty()
            && let Some(from) = self.key(s)
        {
            let mut k = first;
            while k < out.len() {
                let to = self.key(out[k].0);
                if to.is_some_and(|to| self.forbidden.contains(&(from, to))) {
                    out.remove(k);
                } else {
                    k += 1;
                }
            }
        }
    }

    /// The larger of the driving heuristic (Euclidean distance plus turn,
    /// `DrivingGraph`) and the base-cell cost-to-go (`cost_to_go`), plus the step
    /// bound Σ_k S_k of the four feet and the foot-offset potential Φ (`step_bound`),
    /// clamped at zero: consistent on every manoeuvre (see the `heuristic` module docs).
    /// An intermediate node gets its manoeuvre's [`Manoeuvre::pending_heuristic`].
    fn heuristic(&self, s: LatticeState) -> Cost {
        if s.pending == 0 {
            return self.heuristic_parts(s).total();
        }
        self.owner(s)
            .and_then(|(k, tag)| self.manoeuvres[k].pending_heuristic(&self.core, s, tag))
            .map_or(Cost::INFINITY, |(h, _, _)| h)
    }

    /// The heuristic and, as guidance for ARA*'s probe, the same without the cost-to-go
    /// (`HeuristicParts::guidance`).
    fn heuristic_and_guidance(&self, s: LatticeState) -> (Cost, Cost) {
        let (h, g, _) = self.heuristic_and_guidances(s);
        (h, g)
    }

    /// The heuristic, the guidance and, for the probe's greedy list, the guidance with
    /// the feet's offsets weighed as the straight line weighs the base's way and the
    /// feet's way over climbable terrain where it is longer than the straight line
    /// (`HeuristicParts::greedy_guidance`).
    fn heuristic_and_guidances(&self, s: LatticeState) -> (Cost, Cost, Cost) {
        if s.pending == 0 {
            let parts = self.heuristic_parts(s);
            return (parts.total(), parts.guidance(), parts.greedy_guidance());
        }
        self.owner(s)
            .and_then(|(k, tag)| self.manoeuvres[k].pending_heuristic(&self.core, s, tag))
            .unwrap_or((Cost::INFINITY, Cost::INFINITY, Cost::INFINITY))
    }

    fn is_goal(&self, s: LatticeState) -> bool {
        s.pending == 0 && self.driving().is_goal(s)
    }

    fn is_intermediate(&self, s: LatticeState) -> bool {
        s.pending != 0
    }

    fn dense_len(&self) -> usize {
        let l = self.lattice();
        usize::from(l.nx) * usize::from(l.ny) * usize::from(l.orientations)
    }

    /// Neutral states only: `(j·nx + i)·orientations + θ`, the layout of the driving
    /// pose-cost cache, so a cell's orientations share cache lines.
    #[inline]
    fn dense_index(&self, s: LatticeState) -> Option<usize> {
        let l = self.lattice();
        if s.footprint != NEUTRAL_FOOTPRINT
            || s.pending != 0
            || !l.contains(i32::from(s.i), i32::from(s.j))
        {
            return None;
        }
        let cell = s.j as usize * usize::from(l.nx) + s.i as usize;
        Some(cell * usize::from(l.orientations) + usize::from(s.theta))
    }
}
