//! The longitudinal base shift (Sec. V, Fig. 6b) as one unit: the lattice's shifts,
//! their checks by the motion generator, their expansion into keyframes and the heuristic
//! term that bounds them (the cost-to-go's base-shift links, `Relaxation::BaseShift`).
//!
//! A base shift moves the base forward over the standing feet. Cost C_BS = k10 · L_BS ·
//! C_B,avg. Shifts end on the lattice cell containing the exact shifted position (the
//! feet then stand up to half a cell from where they were; the paper's grid has the same
//! issue). The edge cost is `max(C_BS · factor, distance moved)`, which keeps the
//! heuristic consistent even for factors below 2. Every shift is checked by the
//! generator's own expansion ([`check`]: the base stood by the shared rule at every cell
//! of the way, memoised by state and length), and expands so. Four kinds are offered:
//!
//! - **The paper's shift**: when both front feet stand ahead of neutral, forward until
//!   one front foot is neutral or a rear leg reaches its reach limit. A rear leg at its
//!   limit can stand but not step (the step's stance pitches the base less), so where a
//!   rear foot close to an obstacle could not step after the full shift, the shift ends
//!   at the longest length from which it can ([`rear_step_ready_shift`]); otherwise a
//!   square approach to a 0.186 m block left both rear feet stranded and the plan
//!   climbed diagonally at ten times the cost.
//! - *The rear-step approach* (`step_model = "stairs"` only): where the front feet stand
//!   on other ground than the rear ones, a rear foot is not close to an obstacle and a
//!   front foot's way ahead is blocked, a base shift past the front feet's neutral (their
//!   legs reach back) to the first length at which a rear foot, rolled forward to
//!   neutral, comes close to one. Without it the feet of one side stay a hip spacing
//!   (0.7 m) apart, and on treads shorter than that no footprint puts a rear foot at a
//!   riser while the front feet stand on a tread.
//! - *The climb shift* (`step_model = "stairs"` only): a climb is under way (a front
//!   foot stands higher than a rear foot), a rear foot is close to an obstacle and the
//!   front feet do not both stand ahead of neutral. On a flight longer than the robot
//!   the front feet stand on a tread they cannot roll along, at or behind neutral; no
//!   longitudinal shift applies, a rear foot lifted there leaves the CoM behind the
//!   other three, and the front legs cannot reach the next tread from so far back. The
//!   base shifts forward past the front feet's neutral as far as every leg reaches,
//!   shortened to where a rear foot close to an obstacle can still step (as the
//!   longitudinal shift is). Not offered on descents, where it stretched the lower front
//!   legs to their reach limit (a planned descent with it tipped over in closed loop).
//! - *The descent shift* (both step models): a front foot close to an obstacle steps
//!   down (its cheapest foothold lies lower than the foot by more than a wheel drives
//!   down) and the front feet do not both stand ahead of neutral. The base shifts
//!   forward past the front feet's neutral until that front hip stands over the middle
//!   of the step, or the length nearest to it at which every leg stands on the way and
//!   the foot can still step. It mirrors what a climb gets from the longitudinal shift
//!   before its rear steps (the rear hip over the riser, the rear foot behind it): with
//!   the hip over its foot, a front leg lifted over an edge folds past the knee's limit
//!   at every height from which it still reaches a floor 0.24 m or more below, beyond the
//!   edge's untraversable band, and every such drop had no path. Offered mid-flight as
//!   at a platform's edge: the one flight on which a mid-flight shift tipped the robot
//!   over lost a stance pair to the base's pitch, an executor defect its stance
//!   compliance fixed (`control::step_executor`).
//!
//! *Flights longer than the robot* (four or more building-code steps) need the last two
//! and the partial foot to neutral (`wheel_move`): without them a rear foot short of a
//! riser could neither step nor roll up to it, and every reachable pose was searched
//! without a path.
//!
//! Every kind is a base shift like the others (same cost, same heuristic terms), so the
//! heuristic stays consistent.

use super::step::{step_candidates, step_reaches};
use super::unit::{Unit, generator_check};
use crate::cost::HeadingBin;
use crate::geometry::Pose2;
use crate::motion::expander::{Expander, MotionError};
use crate::motion::keyframe::Phase;
use crate::params::StepModel;
use crate::path::{EdgeLabel, ManoeuvreKind, PathElement};
use crate::planner::config::HybridConfig;
use crate::planner::core::{Feet, GraphCore, Stance};
use crate::planner::driving::edge_cost;
use crate::planner::footprint::FootOffsets;
use crate::planner::graph::{Manoeuvre, Successors};
use crate::planner::heuristic::Relaxation;
use crate::planner::lattice::LatticeState;
use crate::search::FxBuild;
use std::collections::HashMap;

/// The base shift, one unit (see the module docs).
pub struct BaseShift;

/// The base shift's planner side for one graph, with its memo table.
#[derive(Default)]
pub struct BaseShiftPlanner {
    /// [`Self::base_shift_feasible`] by the state a shift starts from (cell, orientation,
    /// footprint id) and the cell it ends on.
    base_shift_checks: HashMap<(i16, i16, u8, u16, i16, i16), bool, FxBuild>,
}

impl Unit for BaseShift {
    fn kinds(&self) -> &'static [ManoeuvreKind] {
        &[ManoeuvreKind::BaseShift]
    }

    fn planner(&self) -> Box<dyn Manoeuvre> {
        Box::new(BaseShiftPlanner::default())
    }

    /// The shift to the planned pose over the planned footprint, from the shared rule's
    /// standing posture at the pose before it.
    fn expand(
        &self,
        ex: &mut Expander<'_>,
        path: &[PathElement],
        k: usize,
    ) -> Result<(), MotionError> {
        let el = &path[k];
        ex.stand_before(path, k)?;
        ex.expand_base_shift(el.kind, el.feet, &el.pose)
    }
}

impl Manoeuvre for BaseShiftPlanner {
    fn relaxation(&self) -> Relaxation {
        Relaxation::BaseShift
    }

    fn successors(
        &mut self,
        core: &mut GraphCore<'_>,
        _s: LatticeState,
        stance: Option<&Stance>,
        _lazy: bool,
        out: &mut Successors<'_>,
    ) {
        let Some(&Stance { s, o, feet, near, heading, bin, .. }) = stance else {
            return;
        };
        // Longitudinal base shift: both front feet ahead of neutral; forward until a
        // front foot is neutral or a rear leg is at the end of its reach.
        if o[0] > 0 && o[1] > 0 {
            // Every cell of the way must stand by the rule (the generator moves the base
            // through them), so the shift ends before the first that cannot.
            let mut l = longest_shift_in_reach(core, s, &feet, o[0].min(o[1]));
            // The paper's shift ends where a rear leg reaches its full length. A rear leg
            // at full length cannot also lift its foot over an edge (its step stance
            // pitches the base less), so where a rear foot close to an obstacle could not
            // step from there, the shift ends earlier, where it can.
            if let Some(ready) = rear_step_ready_shift(core, s, &o, near, l) {
                l = ready;
            }
            if l > 0 {
                self.push_base_shift(core, s, &o, &feet, l, out);
            }
        }

        // Rear-step approach (see the module docs): the front feet stand on other ground
        // than the rear feet (a climb or descent is under way), a rear foot is not close
        // to an obstacle, and the base shifts past the front feet's neutral (their legs
        // reach back) to the first length at which a rear wheel pair, rolled forward to
        // its neutral again (foot to neutral), comes close to one. This is how the rear
        // feet reach a stair's first riser while the front feet stand on a tread too
        // short to drive along.
        let far_rear = [2, 3].map(|r| !near[r]);
        let max_diff = core.config().max_foot_height_diff_m;
        let split = [0, 1]
            .iter()
            .any(|&f| [2, 3].iter().any(|&r| (feet.h[f] - feet.h[r]).abs() > max_diff));
        let stairs = core.config().motion.step_model == StepModel::Stairs;
        // (A shift the longitudinal base shift above already offers is left out.)
        if stairs
            && split
            && far_rear.iter().any(|&f| f)
            && let Some(l) = rear_approach_shift(core, s, &o, &feet, far_rear, heading, bin)
            && !(o[0] > 0 && o[1] > 0 && l <= o[0].min(o[1]))
        {
            self.push_base_shift(core, s, &o, &feet, l, out);
        }

        // Climb shift (see the module docs): on a climb, with a rear foot close to an
        // obstacle and the front feet not both ahead of neutral, as far past their
        // neutral as every leg reaches, shortened to where a rear foot can still step.
        let climbing =
            [0, 1].iter().any(|&f| [2, 3].iter().any(|&r| feet.h[f] - feet.h[r] > max_diff));
        if stairs && climbing && (near[2] || near[3]) && !(o[0] > 0 && o[1] > 0) {
            let l = longest_shift_in_reach(core, s, &feet, shift_room(core, &o));
            if let Some(l) = rear_step_ready_shift(core, s, &o, near, l) {
                self.push_base_shift(core, s, &o, &feet, l, out);
            }
        }

        // Descent shift (see the module docs): before a front foot steps down.
        if let Some(l) = descent_shift(core, s, &o, &feet, near) {
            self.push_base_shift(core, s, &o, &feet, l, out);
        }
    }
}

/// The planner's check of a base shift from the expander's posture to pose `to` over
/// feet `feet` (x, y: the footprint at the shift's end): the base stood by the rule at
/// every cell of the way.
///
/// # Errors
/// The expansion's [`MotionError::Manoeuvre`] (or [`MotionError::UnknownTerrain`]).
pub fn check(ex: &mut Expander<'_>, feet: [[f64; 2]; 4], to: &Pose2) -> Result<(), MotionError> {
    ex.expand_base_shift(ManoeuvreKind::BaseShift, feet, to)
}

impl BaseShiftPlanner {
    /// A base shift by `l` cells over the standing feet (see the module docs).
    fn push_base_shift(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        feet: &Feet,
        l: i8,
        out: &mut Successors<'_>,
    ) {
        let res = core.lattice().resolution;
        let (hx, hy) = core.heading(s.theta);
        let p = core.lattice().pose(s);
        let Some((legs, _)) = core.standing_legs(s, feet) else {
            return;
        };
        // C_B,avg: the body cost at every cell-length of the shift, feet fixed in the world.
        let mut sum = 0.0;
        for k in 0..=l {
            let d = f64::from(k) * res;
            let pk = Pose2::new(p.x + hx * d, p.y + hy * d, p.theta);
            match core.maps().body_cost(&pk, &feet.pos, &legs).finite() {
                Some(c) => sum += c,
                None => return,
            }
        }
        let cb_avg = sum / f64::from(l + 1);
        let length = f64::from(l) * res;
        let Some((t, o2)) = shifted(core, s, o, l) else {
            return;
        };
        let moved = core.lattice().pose(t).distance(&p);
        if !core.target_ok(t, &o2) {
            return;
        }
        let Some(t) = core.with_footprint(t, o2) else {
            return;
        };
        if !self.base_shift_feasible(core, s, feet, t) {
            return;
        }
        let cost = (core.config().step_cost_factor
            * base_shift_cost(core.config(), length, cb_avg))
        .max(moved);
        core.count(|c| &mut c.base_shifts);
        out.push(t, edge_cost(cost), || EdgeLabel {
            kind: ManoeuvreKind::BaseShift,
            leg: None,
            length_m: moved,
            cost,
            step: None,
        });
    }

    /// Whether the generator expands the base shift from `s` (feet `feet`) to `t`: its
    /// own expansion ([`check`]: the base stood by the shared rule at
    /// every cell of the way, every point between checked) from the rule's standing
    /// posture, with the CoM estimate and [`PLANNER_MARGIN_SLACK_M`] to spare; memoised
    /// by state and length. The end alone let a path through whose shift could not
    /// stand on the way.
    fn base_shift_feasible(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        feet: &Feet,
        t: LatticeState,
    ) -> bool {
        let key = (s.i, s.j, s.theta, s.footprint, t.i, t.j);
        if let Some(&ok) = self.base_shift_checks.get(&key) {
            return ok;
        }
        let to = core.lattice().pose(t);
        let ok = core
            .feet(t)
            .is_some_and(|after| generator_check(core, s, feet, |ex| check(ex, after, &to)));
        self.base_shift_checks.insert(key, ok);
        ok
    }
}

/// C_BS = k10 · L_BS · C_B,avg (Sec. V), before the step-related factor.
pub fn base_shift_cost(params: &HybridConfig, length_m: f64, body_cost_avg: f64) -> f64 {
    params.k10 * length_m * body_cost_avg
}

/// The longest shift of at most `max` cells from `s` (feet `feet`) whose every cell
/// of the way stands by the rule ([`shift_in_reach`]): the generator moves the
/// base through them.
fn longest_shift_in_reach(core: &GraphCore<'_>, s: LatticeState, feet: &Feet, max: i8) -> i8 {
    let mut l = 0;
    while l < max && shift_in_reach(core, s, feet, l + 1) {
        l += 1;
    }
    l
}

/// The most cells the base can shift forward over feet with offsets `o`: every
/// offset drops by the shift, and the leg with the least room behind it bounds it.
fn shift_room(core: &GraphCore<'_>, o: &FootOffsets) -> i8 {
    let room = (0..4).map(|k| i32::from(o[k]) - i32::from(core.reach()[k][0])).min();
    room.map_or(0, |m| m.clamp(0, i32::from(i8::MAX)) as i8)
}

/// Whether the robot can stand by the rule with its base `l` cells ahead of state
/// `s`'s pose, over the same feet.
fn shift_in_reach(core: &GraphCore<'_>, s: LatticeState, feet: &Feet, l: i8) -> bool {
    let p = core.lattice().pose(s);
    let (hx, hy) = core.heading(s.theta);
    let d = f64::from(l) * core.lattice().resolution;
    let xy = [p.x + hx * d, p.y + hy * d];
    core.config()
        .motion
        .standing
        .stand(core.robot(), core.maps().leg_terrain(), GraphCore::feet_xyz(feet), xy, p.theta)
        .is_ok()
}

/// The state a base shift of `l` cells from state `s` (offsets `o`) ends in: the base
/// on the lattice cell holding the exact shifted position, the same orientation and
/// footprint id as `s`, and every foot offset lowered by `l` (the feet stay put).
/// `None` off the lattice.
fn shifted(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    l: i8,
) -> Option<(LatticeState, FootOffsets)> {
    let (hx, hy) = core.heading(s.theta);
    let p = core.lattice().pose(s);
    let d = f64::from(l) * core.lattice().resolution;
    let cell = core.lattice().state(&Pose2::new(p.x + hx * d, p.y + hy * d, p.theta))?;
    Some((LatticeState { i: cell.i, j: cell.j, ..s }, o.map(|v| v - l)))
}

/// The longest base shift of at most `max` cells from state `s` (offsets `o`) after
/// which a rear leg close to an obstacle (`near`, criterion 1; the feet stay where
/// they stand, so it holds before and after) keeps every leg in reach while it steps
/// to its cheapest foothold (`StandingRule::step_heights` yields a height): `None`
/// when no rear foot is close to an obstacle or no such shift exists. The shift's
/// other checks (stability, the generator's) stay with the step itself.
fn rear_step_ready_shift(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    near: [bool; 4],
    max: i8,
) -> Option<i8> {
    if !near[2] && !near[3] {
        return None;
    }
    (1..=max).rev().find(|&l| {
        let Some((t, o2)) = shifted(core, s, o, l) else {
            return false;
        };
        let Some(feet) = core.feet_of(t, &o2) else {
            return false;
        };
        [2, 3].into_iter().filter(|&r| near[r]).any(|r| step_reaches(core, t, &o2, &feet, r))
    })
}

/// The rear-step approach's shift (see the successors): the fewest cells `l`
/// the base can shift forward over the standing feet (every cell of the way standing
/// by the rule, every leg within its offset reach afterwards) after which a rear foot
/// of `far` (RL, RR) rolled forward by `l` cells over drivable cells is close to an
/// obstacle (criterion 1).
fn rear_approach_shift(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    far: [bool; 2],
    heading: (f64, f64),
    bin: HeadingBin,
) -> Option<i8> {
    let res = core.lattice().resolution;
    for l in 1..=shift_room(core, o) {
        if !shift_in_reach(core, s, feet, l) {
            return None;
        }
        let d = f64::from(l) * res;
        let close = [2, 3].into_iter().filter(|&r| far[r - 2]).any(|r| {
            let p = feet.pos[r];
            let q = [p[0] + heading.0 * d, p[1] + heading.1 * d];
            core.near_obstacle(q, bin)
                && core.drive_line_cost(p, heading, i32::from(l), bin).is_some()
        });
        if close {
            // Where the front wheel pairs could roll as far, driving does the same:
            // the shift is offered only where a front foot's way ahead is blocked.
            let blocked = [0, 1]
                .into_iter()
                .any(|f| core.drive_line_cost(feet.pos[f], heading, i32::from(l), bin).is_none());
            return blocked.then_some(l);
        }
    }
    None
}

/// The descent shift of state `s` (offsets `o`, feet `feet`, criterion 1 per foot
/// `near`), in cells: where a front foot close to an obstacle steps down (its
/// cheapest foothold by the scan lies lower than the foot by more than a wheel drives
/// down, `max_foot_height_diff_m`) and the front feet do not both stand ahead of
/// neutral (the longitudinal shift's case), the base forward until that front hip
/// stands over the middle of its step, or the length nearest to it at which every
/// leg stands on the way ([`shift_in_reach`]) and the front foot can still step
/// ([`step_reaches`]). `None` when no front foot steps down, its hip is at or
/// past the middle already, or no length holds.
fn descent_shift(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    near: [bool; 4],
) -> Option<i8> {
    if o[0] > 0 && o[1] > 0 {
        return None;
    }
    let down = |f: usize| -> Option<i32> {
        if !near[f] {
            return None;
        }
        let c = *step_candidates(core, s, o, feet, f).first()?;
        (c.3[2] < feet.h[f] - core.config().max_foot_height_diff_m).then_some(c.1)
    };
    // The hip over the middle of the step: the foot's offset plus half the step.
    let (leg, target) = [0, 1]
        .into_iter()
        .filter_map(|f| down(f).map(|d| (f, i32::from(o[f]) + d / 2)))
        .min_by_key(|&(_, t)| t)?;
    if target <= 0 {
        return None;
    }
    let longest = longest_shift_in_reach(core, s, feet, shift_room(core, o));
    let mut lengths: Vec<i8> = (1..=longest).collect();
    lengths.sort_by_key(|&l| (i32::from(l) - target).abs());
    lengths.into_iter().find(|&l| {
        shifted(core, s, o, l)
            .and_then(|(t, o2)| Some((t, o2, core.feet_of(t, &o2)?)))
            .is_some_and(|(t, o2, f)| step_reaches(core, t, &o2, &f, leg))
    })
}

impl Expander<'_> {
    /// A planned base shift to `to`, the feet at `feet` (x, y on the ground): through
    /// every cell of the way, the base stood by the shared rule at each, as the planner
    /// checks it ([`check`]). The planner's shift ends on a lattice cell, so
    /// its feet stand up to half a cell from where they were: the shift takes its
    /// footprint (the wheels roll that far), so both agree on every later reach.
    pub(crate) fn expand_base_shift(
        &mut self,
        kind: ManoeuvreKind,
        feet: [[f64; 2]; 4],
        to: &Pose2,
    ) -> Result<(), MotionError> {
        let mut on_ground = self.cur.feet;
        for (f, p) in on_ground.iter_mut().zip(feet) {
            *f = [p[0], p[1], self.ground(p[0], p[1])?];
        }
        let (from, to_xy) = (self.xy(), [to.x, to.y]);
        let res = self.maps.heights().resolution();
        let dist = (to_xy[0] - from[0]).hypot(to_xy[1] - from[1]);
        let n = (dist / res).ceil().max(1.0) as usize;
        let mut seq = Vec::with_capacity(n);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let xy = [from[0] + (to_xy[0] - from[0]) * t, from[1] + (to_xy[1] - from[1]) * t];
            let p = self.stand_for(kind, on_ground, xy, to.theta)?;
            seq.push((Phase::PlannedBaseShift, None, p));
        }
        self.push(kind, &seq)
    }
}
