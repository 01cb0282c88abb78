//! The abstract step (Sec. V, Fig. 5, 6a) as one unit: the lattice's steps, their checks
//! by the motion generator, their expansion into keyframes (`motion`, Sec. VI-A) and the
//! heuristic term that bounds them (the step bound, `Relaxation::Step`).
//!
//! **Successors.** A foot moves from its pre-step to its after-step position, forward in
//! its sagittal plane, the base staying put. Added only when all four criteria hold:
//! criterion 1 (the foot close to an obstacle) and 4 (the two feet on the other side
//! carry the robot: farther apart than `min_support_side_length_m`) here, 2 and 3 in the
//! scan (`scan`); its cost is C_S (eq. 5) of the cheapest end position that passes every
//! check ([`StepPlanner::best_step`]), the only one returned.
//!
//! **Choices where the paper is silent** (each tested):
//! - *Reach.* A step must stay within reach while the foot is carried: the stepping leg
//!   counting the higher of its grounds, the foot at its swing height above both ends
//!   (`StandingRule::step_heights`).
//! - *Support for a step.* The paper leaves static stability to the step motion
//!   generator. A plan whose step no alignment can stabilise is useless to it, so a step
//!   must pass the generator's own check ([`check`]: roll, wheel to centre, base shift,
//!   lift, swing, place and back, every centimetre, with the CoM estimate
//!   `posture::standing::EstimatedCom` and 3 mm of margin to spare): a planned step is one
//!   the generator expands, and no cheaper test turns away a step that check admits (a
//!   CoM-in-triangle pre-check once came first and turned away steps the generator
//!   expands, see [`step_feasible`]).
//! - *Which footholds count as a step.* A step must carry the foot *over* untraversable
//!   terrain: its straight sagittal line crosses at least one cell of infinite foot cost.
//!   A foothold reachable over finite cells only is a wheel drive (front foot forward /
//!   foot to neutral), not a step — otherwise the cheapest "step" would always be one
//!   cell long.
//! - *ΔH_step* (eq. 5) is the largest |H(c) − H(f_j)| over the cells the foot passes,
//!   end included; the paper's third criterion bounds |H(f_j) − H(c_h)| by 0.3 m, and
//!   Fig. 5c's "the height difference to overcome" bounds ΔH_step as well (a leg cannot
//!   lift a foot over a 0.5 m bar even if the far side is level).
//!
//! **Lazy step checks** (issue 15). A step's checks after the scan (the standing rule's
//! IK for the after-step state, the generator's own step check) cost about a quarter of a
//! millisecond when they pass, and most steps the search generates are never expanded.
//! So the search's edge for a step goes to an intermediate node (`planner::graph`, "Lazy
//! edges") tagged `k + 1` for leg `k`, at the cost of the cheapest foothold the scan
//! found, a lower bound of the step's. Expanding the node runs the checks and gives the
//! step itself at the rest of its cost, or nothing. The node's heuristic is
//! `min_c (c_c + h(t_c)) − c_lb` over the scan's footholds `c` (edge cost `c_c`,
//! after-step state `t_c`, `c_lb` the least `c_c`): consistent into the node because the
//! heuristic is consistent on every step from the pose, and out of it because the step
//! taken is one of the `c`.
//!
//! **Translated step failures** (issue 15). A step check that failed is remembered by
//! the terrain it read, its stance and its step, not by where it stood: the
//! orientation, footprint, leg and new offset, and the print of every map layer over a
//! window that holds everything the check reads (`cost::prints`; the window below). A
//! check from another cell with the same key fails without being run. Along a straight
//! edge, a stair's riser or a wall the terrain repeats cell by cell, and a search whose
//! heuristic cannot tell the cells apart tries the same failing step at each: on the
//! 0.3 m step-down scenario 31 k of its 31 k step checks failed, most of them copies.
//! Only failures are taken over. A check reads the maps at points computed from its
//! absolute pose, so where one lands within rounding of a cell boundary a translated
//! copy may read the neighbouring cell: a remembered failure can turn away a step the
//! exact check would pass there (a lost option, never a plan the generator cannot
//! expand), and a remembered success could admit one it would fail. The window is the
//! box of the feet before and after the step, widened by the foot link, half the wheel
//! track, the wheel radius and a margin, and of the base's corners and hips, widened by
//! the largest base shift of a step candidate, the thigh and the margin: every leg
//! point lies within a thigh of its hip or between its knee and its foot, every foot
//! the check moves stays between the stance's feet, and the base moves only by the
//! candidates' shift (`HybridConfig::reuse_translated_step_failures`).

mod motion;
mod scan;

pub use motion::{StepSearch, check};
pub use scan::{StepCandidate, step_candidates, step_cost, step_reaches};

use super::unit::{Unit, generator_outcome};
use crate::motion::expander::{Expander, MotionError};
use crate::path::{EdgeLabel, ManoeuvreKind, PathElement, StepCost};
use crate::planner::core::{Feet, GraphCore, PoseKey, Stance};
use crate::planner::driving::edge_cost;
use crate::planner::footprint::FootOffsets;
use crate::planner::graph::{Manoeuvre, Successors};
use crate::planner::heuristic::Relaxation;
use crate::planner::lattice::LatticeState;
use crate::robot::Leg;
use crate::search::{Cost, FxBuild};
use std::collections::{HashMap, HashSet};

/// The abstract step, one unit (see the module docs).
pub struct Step;

/// A step check by what it reads and does ([`translated_step`]): the print of its window,
/// the window's cells relative to the state's, the orientation, the footprint's offsets,
/// the leg and its new offset.
type TranslatedStep = (u128, [i16; 4], u8, FootOffsets, u8, i8);

/// Margin of a translated step's window beyond the reach it bounds, m (with two cells
/// more): the base's pitch and roll move the hips a few centimetres, and bilinear
/// reads take the next cell.
const TRANSLATION_WINDOW_MARGIN_M: f64 = 0.05;

/// The step's planner side for one graph, with its memo tables.
#[derive(Default)]
pub struct StepPlanner {
    /// [`step_feasible`] by the state a step starts from, the leg and its new offset:
    /// ARA* expands a state again in each iteration.
    step_checks: HashMap<(PoseKey, u8, i8), bool, FxBuild>,
    /// The failed step checks by what they read and did, wherever they stood (module
    /// docs, "Translated step failures").
    translated_failures: HashSet<TranslatedStep, FxBuild>,
}

impl Unit for Step {
    fn kinds(&self) -> &'static [ManoeuvreKind] {
        &[ManoeuvreKind::Step]
    }

    fn planner(&self) -> Box<dyn Manoeuvre> {
        Box::new(StepPlanner::default())
    }

    /// The generator's step from the planned stance to the planned foothold
    /// ([`StepSearch::Full`]), from the shared rule's standing posture at the pose
    /// before it.
    fn expand(
        &self,
        ex: &mut Expander<'_>,
        path: &[PathElement],
        k: usize,
    ) -> Result<(), MotionError> {
        let el = &path[k];
        let leg = ex.leg_of(el)?;
        ex.stand_before(path, k)?;
        let f = el.feet[leg.index()];
        let post_foot = [f[0], f[1], ex.ground(f[0], f[1])?];
        ex.expand_step(leg, post_foot)?;
        ex.steps += 1;
        Ok(())
    }
}

impl Manoeuvre for StepPlanner {
    fn relaxation(&self) -> Relaxation {
        Relaxation::Step
    }

    fn pending_tags(&self) -> u8 {
        4
    }

    fn successors(
        &mut self,
        core: &mut GraphCore<'_>,
        _s: LatticeState,
        stance: Option<&Stance>,
        lazy: bool,
        out: &mut Successors<'_>,
    ) {
        let Some(&Stance { s, o, feet, near, .. }) = stance else {
            return;
        };
        // Criteria 1 and 4 here, 2 and 3 in the scan and `best_step`.
        for leg in Leg::ALL {
            let k = leg.index();
            if !near[k] {
                continue;
            }
            // Criterion 4: the two feet on the other side carry the robot while it steps.
            if core.side_length(&o, !leg.is_left()) <= core.config().min_support_side_length_m {
                continue;
            }
            let candidates = step_candidates(core, s, &o, &feet, k);
            if lazy {
                // The cheapest foothold by the scan: a lower bound of the step's cost.
                if let Some(&(_, _, step, _)) = candidates.first() {
                    let (cost, m) = step_edge(core, k, step);
                    out.pending(s, k as u8 + 1, cost, || m);
                }
                continue;
            }
            if let Some((t, cost, m)) = self.checked_step(core, s, &o, &feet, k, candidates) {
                out.push(t, cost, || m);
            }
        }
    }

    fn pending_successor(
        &mut self,
        core: &mut GraphCore<'_>,
        p: LatticeState,
        tag: u8,
    ) -> Option<(LatticeState, Cost, EdgeLabel)> {
        self.pending_step(core, LatticeState { pending: tag, ..p })
    }

    fn pending_heuristic(
        &self,
        core: &GraphCore<'_>,
        p: LatticeState,
        tag: u8,
    ) -> Option<(Cost, Cost, Cost)> {
        pending_heuristic(core, LatticeState { pending: tag, ..p })
    }
}

impl StepPlanner {
    /// The cheapest abstract step of `leg` from state `s` (offsets `o`, feet `feet`),
    /// given that criteria 1 (close to an obstacle) and 4 (support side) hold: of the
    /// footholds of the scan ([`step_candidates`], criteria 2 and 3, cheapest
    /// first), the first whose after-step state may be entered and whose step passes
    /// [`step_feasible`], with its new offsets.
    pub fn best_step(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        leg: usize,
        candidates: Vec<StepCandidate>,
    ) -> Option<(FootOffsets, StepCost)> {
        candidates.into_iter().find_map(|(_, d, cost, foothold)| {
            let mut o2 = *o;
            o2[leg] = (i32::from(o[leg]) + d) as i8;
            let key = ((s.i, s.j, s.theta, *o), leg as u8, o2[leg]);
            let known = self.step_checks.get(&key).copied();
            if !core.target_ok(s, &o2) {
                return None;
            }
            let ok = known.unwrap_or_else(|| {
                let translated = translated_step(core, s, o, feet, leg, o2[leg], foothold);
                let ok = if translated.is_some_and(|t| self.translated_failures.contains(&t)) {
                    core.count(|c| &mut c.step_failures_translated);
                    false
                } else {
                    let ok = step_feasible(core, s, feet, leg, foothold);
                    if let (false, Some(t)) = (ok, translated) {
                        self.translated_failures.insert(t);
                    }
                    ok
                };
                self.step_checks.insert(key, ok);
                ok
            });
            ok.then_some((o2, cost))
        })
    }

    /// The step of leg `k` from state `s` (offsets `o`, feet `feet`) to the cheapest of
    /// the scan's `candidates` that passes every check (`best_step`), labelled, at its
    /// full cost.
    fn checked_step(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        k: usize,
        candidates: Vec<StepCandidate>,
    ) -> Option<(LatticeState, Cost, EdgeLabel)> {
        let (o2, step) = self.best_step(core, s, o, feet, k, candidates)?;
        let t = core.with_footprint(s, o2)?;
        core.count(|c| &mut c.steps);
        let (cost, m) = step_edge(core, k, step);
        Some((t, cost, m))
    }

    /// The successor of an intermediate node `p` (see "Lazy step checks" in the module
    /// docs): its step, checked now, at the rest of its cost (the full cost less what
    /// the edge into `p` charged). `None` when no foothold passes the checks.
    fn pending_step(
        &mut self,
        core: &mut GraphCore<'_>,
        p: LatticeState,
    ) -> Option<(LatticeState, Cost, EdgeLabel)> {
        let k = usize::from(p.pending.checked_sub(1)?);
        let s = LatticeState { pending: 0, ..p };
        let o = core.offsets(s)?;
        let feet = core.feet_of(s, &o)?;
        let candidates = step_candidates(core, s, &o, &feet, k);
        let &(_, _, cheapest, _) = candidates.first()?;
        let (charged, _) = step_edge(core, k, cheapest);
        let (t, cost, m) = self.checked_step(core, s, &o, &feet, k, candidates)?;
        Some((t, cost.saturating_sub(charged), m))
    }
}

/// The key of the step of `leg` from `s` (offsets `o`, feet `feet`) to `foothold`
/// (new offset `to`) among the translated failures: the print of the window the
/// check reads, relative to `s`'s cell, with the stance and the step (module docs,
/// "Translated step failures"). `None` where the window leaves the prints' padding,
/// or with the reuse turned off.
pub(crate) fn translated_step(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    leg: usize,
    to: i8,
    foothold: [f64; 3],
) -> Option<TranslatedStep> {
    if !core.config().reuse_translated_step_failures {
        return None;
    }
    let r = core.robot();
    let res = core.lattice().resolution;
    let margin = TRANSLATION_WINDOW_MARGIN_M + 2.0 * res;
    // The prints' padding: the farthest a window reaches from its base cell.
    let reach = r.max_leg_length() + r.hips.iter().map(|h| h[0].hypot(h[1])).fold(0.0, f64::max);
    let far = reach + core.config().motion.max_base_shift_m + r.wheel_track + margin;
    let prints = core.maps().prints((far / res).ceil() as usize + 2);
    let pose = core.lattice().pose(s);
    let [hx, hy, _] = r.base_half_extents;
    let body = [[hx, hy], [hx, -hy], [-hx, hy], [-hx, -hy]]
        .into_iter()
        .chain(r.hips.iter().map(|h| [h[0], h[1]]))
        .map(|p| pose.transform(p));
    let r_body = core.config().motion.max_base_shift_m + r.thigh_length + margin;
    let r_foot = r.foot_length + r.wheel_track / 2.0 + r.wheel_radius + margin;
    let feet_xy = feet.pos.into_iter().chain([[foothold[0], foothold[1]]]);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (p, grow) in feet_xy.map(|p| (p, r_foot)).chain(body.map(|p| (p, r_body))) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k] - grow);
            hi[k] = hi[k].max(p[k] + grow);
        }
    }
    let cell = |[x, y]: [f64; 2]| core.maps().heights().grid_coords(x, y).map(|g| g.floor() as i64);
    let ([i0, j0], [i1, j1]) = (cell(lo), cell(hi));
    let print = prints.print([i0, i1], [j0, j1])?;
    let (si, sj) = (i64::from(s.i), i64::from(s.j));
    let rel = [i0 - si, i1 - si, j0 - sj, j1 - sj].map(|d| d as i16);
    Some((print, rel, s.theta, *o, leg as u8, to))
}

/// Whether the step of leg `leg` from feet `feet` (state `s`) to the foot at `post`
/// (x, y, ground z) is one the motion generator expands:
/// - it stays within reach while the foot is carried at some height of the standing
///   rule ((`StandingRule::step_heights`), drawn lazily, tallest first), and
/// - the generator's own check ([`check`]) from the standing posture of
///   the shared rule finds a stable motion at those heights, at every sample, with the
///   CoM estimate (`EstimatedCom`) and `PLANNER_MARGIN_SLACK_M` to spare.
///
/// No support pre-check comes first: the CoM-in-triangle filters this planner had
/// (the paper model's at the unaligned stance, the stairs model's through the lift's
/// alignments) turned away 1–6 % of the steps checked on generated flights and 40–98 %
/// on the paper's staircase and generated mixed courses, and the generator expands
/// much of what they turned away (on the staircase 5,545 of 7,575): the planner
/// missed steps, and paths, it could take.
pub(crate) fn step_feasible(
    core: &GraphCore<'_>,
    s: LatticeState,
    feet: &Feet,
    leg: usize,
    post: [f64; 3],
) -> bool {
    let pose = core.lattice().pose(s);
    let (robot, maps, rule) = (core.robot(), core.maps(), &core.config().motion.standing);
    let pre_feet = GraphCore::feet_xyz(feet);
    let xy = [pose.x, pose.y];
    let mut heights = rule
        .step_heights(
            robot,
            maps.heights(),
            maps.leg_terrain(),
            pre_feet,
            leg,
            post,
            xy,
            pose.theta,
        )
        .peekable();
    if heights.peek().is_none() {
        core.count(|c| &mut c.steps_without_leg_height);
        return false;
    }
    let outcome = generator_outcome(core, s, feet, |ex| check(ex, Leg::ALL[leg], post, heights));
    core.count(|c| match outcome {
        Ok(()) => &mut c.step_checks_passed,
        Err(Some(MotionError::Step { .. })) if Leg::ALL[leg].is_front() => {
            &mut c.front_steps_unstable
        }
        Err(Some(MotionError::Step { .. })) => &mut c.rear_steps_unstable,
        Err(_) => &mut c.steps_failed_otherwise,
    });
    outcome.is_ok()
}

/// A step of leg `k` with cost terms `step`: its edge cost (C_S times the
/// step-related factor) and label.
pub(crate) fn step_edge(core: &GraphCore<'_>, k: usize, step: StepCost) -> (Cost, EdgeLabel) {
    let cost = core.config().step_cost_factor * step.c_s;
    let m = EdgeLabel {
        kind: ManoeuvreKind::Step,
        leg: Some(Leg::ALL[k]),
        length_m: step.length_m,
        cost,
        step: Some(step),
    };
    (edge_cost(cost), m)
}

/// The heuristic and the guidance (`HeuristicParts::guidance`) of an intermediate
/// node `p` (see "Lazy edges" in `planner::graph`); `None` if its pose has
/// no footprint or feet on finite cells, or the scan no foothold (the node then has
/// no successor).
pub(crate) fn pending_heuristic(
    core: &GraphCore<'_>,
    p: LatticeState,
) -> Option<(Cost, Cost, Cost)> {
    let k = usize::from(p.pending.checked_sub(1)?);
    let s = LatticeState { pending: 0, ..p };
    let o = core.offsets(s)?;
    let feet = core.feet_of(s, &o)?;
    let f = core.config().step_cost_factor;
    let candidates = step_candidates(core, s, &o, &feet, k);
    let charged = edge_cost(f * candidates.first()?.0);
    let (mut best, mut guided, mut greedy) = (Cost::INFINITY, Cost::INFINITY, Cost::INFINITY);
    for &(c_s, d, _, _) in &candidates {
        let mut o2 = o;
        o2[k] = (i32::from(o[k]) + d) as i8;
        // The after-step state's own heuristic: its feet as `feet_pos` places them.
        let parts = core.parts_with(s, Some((&o2, &core.feet_pos(s, &o2))));
        let c = edge_cost(f * c_s);
        best = best.min(c.saturating_add(parts.total()));
        guided = guided.min(c.saturating_add(parts.guidance()));
        greedy = greedy.min(c.saturating_add(parts.greedy_guidance()));
    }
    Some((
        best.saturating_sub(charged),
        guided.saturating_sub(charged),
        greedy.saturating_sub(charged),
    ))
}
