//! The wheel moves (Sec. V, Fig. 6c, d) as one unit: a wheel pair rolled along the ground
//! to a new footprint, the lattice's moves, their checks by the motion generator, their
//! expansion into keyframes and the heuristic term that bounds them (the foot-offset
//! potential Φ, `Relaxation::WheelMove`).
//!
//! - **front foot forward** (Fig. 6c): when a rear foot is close to an obstacle, a front
//!   wheel pair drives forward (keeping ground contact), preparing a rear step — as far
//!   as its leg reaches and the terrain is drivable, in one move. Cost C_FM (eq. 6).
//! - **foot to neutral** (Fig. 6d): in a non-neutral footprint, one wheel pair drives
//!   back to its neutral position. Cost C_FM (eq. 6). With `step_model = "stairs"`,
//!   where the way to neutral is not drivable and the foot is not close to an obstacle,
//!   it drives up to the last drivable cell before the obstacle instead (then it is
//!   close to it, and may step). (With the paper's model it would also apply, but it
//!   slowed generated `up_and_over` searches by a fifth for no new path.)
//!
//! A move is offered where its footprint can stand at every cell of the way (the
//! generator rolls the foot through the same cells) and, between two cells whose
//! postures do not both clear the swept leg terrain, where the generator's own one-cell
//! move holds ([`check`], memoised per pose, footprint, leg and offset). Its expansion
//! rolls the foot through every cell of the way, the base re-stood by the shared rule
//! at each.

use super::unit::{Unit, generator_check};
use crate::motion::expander::{Expander, MotionError};
use crate::motion::keyframe::Phase;
use crate::params::StepModel;
use crate::path::{EdgeLabel, ManoeuvreKind, PathElement};
use crate::planner::config::HybridConfig;
use crate::planner::core::{Feet, GraphCore, PoseKey, Stance, Stand};
use crate::planner::driving::edge_cost;
use crate::planner::footprint::FootOffsets;
use crate::planner::graph::{Manoeuvre, Successors};
use crate::planner::heuristic::Relaxation;
use crate::planner::lattice::LatticeState;
use crate::robot::Leg;
use crate::search::FxBuild;
use std::collections::HashMap;

/// The wheel moves, one unit (see the module docs).
pub struct WheelMove;

/// The wheel moves' planner side for one graph, with its memo table.
#[derive(Default)]
pub struct WheelMovePlanner {
    /// [`Self::wheel_segment_ok`] by the pose and footprint a one-cell wheel move starts
    /// from, the leg and its new offset.
    wheel_move_checks: HashMap<(PoseKey, u8, i8), bool, FxBuild>,
}

impl Unit for WheelMove {
    fn kinds(&self) -> &'static [ManoeuvreKind] {
        &[ManoeuvreKind::FootForward, ManoeuvreKind::FootNeutral]
    }

    fn planner(&self) -> Box<dyn Manoeuvre> {
        Box::new(WheelMovePlanner::default())
    }

    /// The wheel move of the planned leg to its planned foot, from the shared rule's
    /// standing posture at the pose before it.
    fn expand(
        &self,
        ex: &mut Expander<'_>,
        path: &[PathElement],
        k: usize,
    ) -> Result<(), MotionError> {
        let el = &path[k];
        let leg = ex.leg_of(el)?;
        ex.stand_before(path, k)?;
        ex.expand_wheel_move(el.kind, leg, el.feet[leg.index()])
    }
}

impl Manoeuvre for WheelMovePlanner {
    fn relaxation(&self) -> Relaxation {
        Relaxation::WheelMove
    }

    fn successors(
        &mut self,
        core: &mut GraphCore<'_>,
        _s: LatticeState,
        stance: Option<&Stance>,
        _lazy: bool,
        out: &mut Successors<'_>,
    ) {
        let Some(&Stance { s, o, neutral, feet, near, .. }) = stance else {
            return;
        };
        // Front wheel pairs forward, preparing a rear step: when a rear foot is close to
        // an obstacle (Sec. V). One move per foot, as far as the leg reaches and the
        // wheels can drive (at least `foot_move_increment_m`): shorter moves would only
        // multiply footprints, and a later base shift uses the whole lead.
        if near[2] || near[3] {
            for k in [Leg::FrontLeft.index(), Leg::FrontRight.index()] {
                let moves = foot_forward_moves(core, s, &o, &feet, k);
                self.push_longest_feasible_move(core, s, &o, &moves, out);
            }
        }
        // A wheel pair back to neutral. Moves of different feet commute, so only the
        // first foot (in FL, FR, RL, RR order) that can move is offered: the same
        // footprints stay reachable, through a chain instead of every subset of feet
        // (2^4 intermediate footprints per pose become 4).
        if !neutral {
            let moves = foot_neutral_moves(core, s, &o, &feet, near);
            self.push_first_feasible_move(core, s, &o, &moves, out);
        }
    }
}

/// The planner's check of a wheel move of `leg`'s pair to `foot` (x, y) from the
/// expander's posture: a keyframe per cell of the way, each stood by the rule, and every
/// point 1 cm apart between them. The rule's postures at the cells alone let a knee pass
/// within the legs' clearance of a block's edge between two of them.
///
/// # Errors
/// The expansion's [`MotionError::Manoeuvre`] (or [`MotionError::UnknownTerrain`]).
pub fn check(ex: &mut Expander<'_>, leg: Leg, foot: [f64; 2]) -> Result<(), MotionError> {
    ex.expand_wheel_move(ManoeuvreKind::FootForward, leg, foot)
}

impl WheelMovePlanner {
    /// The front-foot-forward move of leg index `k` from `s` that the successors
    /// offers ([`Self::push_longest_feasible_move`]), or with `longest_first` the one
    /// trying the moves longest first finds ([`Self::push_first_feasible_move`]): its
    /// footprint, and the leg's offset at the end of the longest move it chose from
    /// (`None`: there was none). For tests.
    #[cfg(test)]
    pub(crate) fn forward_move(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        k: usize,
        longest_first: bool,
    ) -> (Option<FootOffsets>, Option<i8>) {
        let Some((o, feet)) = core.offsets(s).and_then(|o| Some((o, core.feet_of(s, &o)?))) else {
            return (None, None);
        };
        let moves = foot_forward_moves(core, s, &o, &feet, k);
        let (mut edges, mut labels) = (Vec::new(), Vec::new());
        let mut out = Successors::new(&mut edges, Some(&mut labels));
        if longest_first {
            self.push_first_feasible_move(core, s, &o, &moves, &mut out);
        } else {
            self.push_longest_feasible_move(core, s, &o, &moves, &mut out);
        }
        let to = edges.first().and_then(|&(t, _)| core.offsets(t));
        (to, moves.first().map(|m| m.to[k]))
    }

    /// Offers the first of `moves` (from `s`, offsets `o`) whose way the robot can
    /// stand on ([`Self::wheel_move_feasible`]).
    fn push_first_feasible_move(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        moves: &[FootMove],
        out: &mut Successors<'_>,
    ) {
        if let Some(m) = moves.iter().find(|m| self.wheel_move_feasible(core, s, o, m)).copied() {
            self.push_move(core, s, &m, out);
        }
    }

    /// Offers wheel move `m` from `s`, checked.
    fn push_move(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        m: &FootMove,
        out: &mut Successors<'_>,
    ) {
        let Some(t) = core.with_footprint(s, m.to) else {
            return;
        };
        match m.kind {
            ManoeuvreKind::FootForward => core.count(|c| &mut c.foot_forward),
            _ => core.count(|c| &mut c.foot_neutral),
        }
        out.push(t, edge_cost(m.cost), || m.manoeuvre());
    }

    /// Offers the longest of `moves` (one leg's wheel moves from `s`, offsets `o`, all
    /// the same way, longest first) whose way the robot can stand on: the move
    /// [`Self::push_first_feasible_move`] offers, found by [`Self::feasible_roll`] with
    /// one look at each cell up to the first that fails, where trying the moves longest
    /// first stood the robot at every cell beyond the first failure too (on the
    /// platform's A*, 5.23 M standing checks became 5.01 M).
    fn push_longest_feasible_move(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        moves: &[FootMove],
        out: &mut Successors<'_>,
    ) {
        let Some(longest) = moves.first() else {
            return;
        };
        let k = longest.leg.index();
        let shortest = moves.last().map_or(longest.to[k], |m| m.to[k]);
        let rolled = self.feasible_roll(core, s, o, longest.leg, longest.to[k], shortest);
        let reach = (i32::from(rolled) - i32::from(o[k])).abs();
        let chosen = moves.iter().find(|m| {
            debug_assert!(m.leg == longest.leg, "one leg's moves");
            (i32::from(m.to[k]) - i32::from(o[k])).abs() <= reach
        });
        if let Some(m) = chosen {
            debug_assert!(self.wheel_move_feasible(core, s, o, m), "the longest feasible move");
            self.push_move(core, s, m, out);
        }
    }

    /// How far `leg`'s wheel pair rolls from footprint `o` at `s` toward offset `to`:
    /// the last offset of the longest way from `o` whose every cell can stand
    /// (`GraphCore::target_ok`) and every one-cell segment passes (the checks
    /// [`Self::wheel_move_feasible`] describes, and makes by this roll). A move is
    /// feasible exactly when its end lies on that way: both conditions hold for a way when
    /// they hold for a longer one, so the cells are looked at nearest first, each once, up
    /// to the first that fails, and the segments only up to there, and only where that
    /// reaches `at_least` (the offset of the shortest move wanted; short of it, the cells'
    /// reach is returned).
    fn feasible_roll(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        leg: Leg,
        to: i8,
        at_least: i8,
    ) -> i8 {
        let k = leg.index();
        let dir: i8 = if to >= o[k] { 1 } else { -1 };
        let mut way = *o;
        // The cells: every one up to the first that cannot stand.
        while way[k] != to {
            let mut next = way;
            next[k] += dir;
            if !core.target_ok(s, &next) {
                break;
            }
            way = next;
        }
        if (i32::from(way[k]) - i32::from(at_least)) * i32::from(dir) < 0 {
            return way[k];
        }
        // The segments between them, up to the first that fails.
        let mut a = *o;
        let mut a_clear = a[k] != way[k] && core.stand(s, &a) == Stand::SweptClear;
        while a[k] != way[k] {
            let mut b = a;
            b[k] += dir;
            let b_clear = core.stand(s, &b) == Stand::SweptClear;
            let swept = a_clear && b_clear;
            if !swept && !self.wheel_segment_ok(core, s, &a, leg, &b) {
                break;
            }
            (a, a_clear) = (b, b_clear);
        }
        a[k]
    }

    /// Whether the robot at `s` (offsets `o`) can roll the wheel pair of move `m` its
    /// whole way, as the generator moves it (`expand`'s wheel move: a keyframe per cell of
    /// the way, the base stood by the shared rule at each, every point 1 cm apart between
    /// two checked):
    /// - the footprint with that foot at every cell of the way, the last one included,
    ///   can stand ([`Self::target_ok`], memoised);
    /// - between two cells whose postures both clear the swept leg terrain
    ///   ([`Stand::SweptClear`]) no leg point comes within the legs' clearance of the
    ///   terrain (the argument of `feasibility` for neighbouring lattice poses: a leg point
    ///   moves less than the sweep's two cells between them);
    /// - between any other two, near an edge, the generator's own expansion of that cell's
    ///   move decides ([`check`], memoised by pose, footprint, leg and
    ///   new offset, so moves through the same cells share it).
    ///
    /// Checking the two ends alone let a knee dip below the legs' clearance on the way;
    /// checking the cells alone let a knee pass within it over a block's edge between two.
    fn wheel_move_feasible(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        o: &FootOffsets,
        m: &FootMove,
    ) -> bool {
        // The end first: where it cannot stand, the way needs no look.
        let to = m.to[m.leg.index()];
        core.target_ok(s, &m.to) && self.feasible_roll(core, s, o, m.leg, to, to) == to
    }

    /// The generator's one-cell wheel move of `leg`'s pair from footprint `a` to `b` at
    /// `s`'s pose ([`check`] from the rule's standing posture on `a`),
    /// with the CoM estimate and [`PLANNER_MARGIN_SLACK_M`] to spare; memoised.
    fn wheel_segment_ok(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        a: &FootOffsets,
        leg: Leg,
        b: &FootOffsets,
    ) -> bool {
        let k = leg.index();
        let key = ((s.i, s.j, s.theta, *a), k as u8, b[k]);
        if let Some(&ok) = self.wheel_move_checks.get(&key) {
            return ok;
        }
        let ok = wheel_segment_motion(core, s, a, leg, b);
        self.wheel_move_checks.insert(key, ok);
        ok
    }
}

/// A wheel move the lattice offers: the leg whose pair rolls, the footprint after it, its
/// cost (C_FM times the step-related factor) and length.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FootMove {
    kind: ManoeuvreKind,
    leg: Leg,
    to: FootOffsets,
    cost: f64,
    length_m: f64,
}

impl FootMove {
    fn manoeuvre(&self) -> EdgeLabel {
        EdgeLabel {
            kind: self.kind,
            leg: Some(self.leg),
            length_m: self.length_m,
            cost: self.cost,
            step: None,
        }
    }
}

/// C_FM = k11 · L_FM · C_F,avg (eq. 6), before the step-related factor.
pub fn foot_move_cost(params: &HybridConfig, length_m: f64, foot_cost_avg: f64) -> f64 {
    params.k11 * length_m * foot_cost_avg
}

/// The wheel move of `kind` of `leg`'s pair to footprint `to`, `length_m` long over
/// cells of mean foot cost `avg`, at its cost C_FM (eq. 6) times the step-related
/// factor.
fn foot_move(
    core: &GraphCore<'_>,
    kind: ManoeuvreKind,
    leg: Leg,
    to: FootOffsets,
    length_m: f64,
    avg: f64,
) -> FootMove {
    let cost = core.config().step_cost_factor * foot_move_cost(core.config(), length_m, avg);
    FootMove { kind, leg, to, cost, length_m }
}

/// The wheel pairs back toward neutral from `s` (offsets `o`, feet `feet`, criterion
/// 1 per foot `near`), in FL, FR, RL, RR order (of which the successors take
/// the first that passes its checks): to neutral where the way is drivable; with
/// `step_model = "stairs"`, a foot not close to an obstacle whose way is not, up to
/// the last drivable cell before the obstacle, where it is close to it. Without
/// that, a rear foot behind neutral short of a stair's riser could neither step (it
/// is not close to the riser) nor roll to neutral (the way climbs the riser), and no
/// base shift brings it closer while the front feet stand behind neutral on a tread:
/// flights of four or more steps had no path.
fn foot_neutral_moves(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    near: [bool; 4],
) -> Vec<FootMove> {
    let res = core.lattice().resolution;
    let heading = core.heading(s.theta);
    let bin = core.bin(s.theta);
    let partial = core.config().motion.step_model == StepModel::Stairs;
    let mut moves = Vec::new();
    for leg in Leg::ALL {
        let k = leg.index();
        if o[k] == 0 {
            continue;
        }
        let back = if o[k] > 0 { (-heading.0, -heading.1) } else { heading };
        let all = i32::from(o[k]).abs();
        let (cells, avg) = match core.drivable_prefix(feet.pos[k], back, all, bin) {
            Some((cells, avg)) if cells == all || (partial && cells > 0 && !near[k]) => {
                (cells, avg)
            }
            _ => continue,
        };
        let mut to = *o;
        to[k] = if o[k] > 0 { o[k] - cells as i8 } else { o[k] + cells as i8 };
        let length_m = f64::from(cells) * res;
        moves.push(foot_move(core, ManoeuvreKind::FootNeutral, leg, to, length_m, avg));
    }
    moves
}

/// The "front foot forward" moves of leg index `k` (see the successors), longest
/// first: as far as the leg reaches and the wheels can drive, at least
/// `foot_move_increment_m`.
fn foot_forward_moves(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    k: usize,
) -> Vec<FootMove> {
    let res = core.lattice().resolution;
    let (hx, hy) = core.heading(s.theta);
    let bin = core.bin(s.theta);
    let [x0, y0] = feet.pos[k];
    let max_d = i32::from(core.reach()[k][1]) - i32::from(o[k]);
    // Prefix sums of C_F along the drivable part of the line.
    let mut sums = [0.0_f64; 128];
    sums[0] = feet.cf[k];
    let mut last = 0;
    for d in 1..=max_d.min(127) {
        let l = f64::from(d) * res;
        match core.cell(x0 + hx * l, y0 + hy * l, bin) {
            Ok((c, _)) => {
                sums[d as usize] = sums[d as usize - 1] + c;
                last = d;
            }
            Err(_) => break,
        }
    }
    let min_d = i32::from(core.foot_move_cells());
    let leg = Leg::ALL[k];
    (min_d..=last)
        .rev()
        .map(|d| {
            let mut to = *o;
            to[k] = (i32::from(o[k]) + d) as i8;
            let avg = sums[d as usize] / f64::from(d + 1);
            let length_m = f64::from(d) * res;
            foot_move(core, ManoeuvreKind::FootForward, leg, to, length_m, avg)
        })
        .collect()
}

/// [`Self::wheel_segment_ok`] unmemoised.
fn wheel_segment_motion(
    core: &GraphCore<'_>,
    s: LatticeState,
    a: &FootOffsets,
    leg: Leg,
    b: &FootOffsets,
) -> bool {
    let (Some(feet), Some(after)) = (core.feet_of(s, a), core.feet_of(s, b)) else {
        return false;
    };
    let foot = after.pos[leg.index()];
    generator_check(core, s, &feet, |ex| check(ex, leg, foot))
}

impl Expander<'_> {
    /// The wheel move of one foot to `foot` (x, y on the ground), the base standing by the
    /// shared rule at its current place: through every cell of the way (a keyframe per
    /// height-map cell the foot rolls over), the base re-stood by the rule at each, as the
    /// planner checked the move (every footprint of the way can stand). A single keyframe
    /// at the end let the interpolation between the two ends dip a knee below the legs'
    /// clearance that both ends kept.
    pub(crate) fn expand_wheel_move(
        &mut self,
        kind: ManoeuvreKind,
        leg: Leg,
        foot: [f64; 2],
    ) -> Result<(), MotionError> {
        let i = leg.index();
        let from = self.cur.feet[i];
        let (dx, dy) = (foot[0] - from[0], foot[1] - from[1]);
        let res = self.maps.heights().resolution();
        let n = ((dx.hypot(dy) / res).round() as usize).max(1);
        let (xy, yaw) = (self.xy(), self.cur.base_rpy[2]);
        let mut feet = self.cur.feet;
        let mut seq = Vec::with_capacity(n);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let (x, y) = (from[0] + dx * t, from[1] + dy * t);
            feet[i] = [x, y, self.ground(x, y)?];
            let p = self.stand_for(kind, feet, xy, yaw)?;
            seq.push((Phase::WheelMove, Some(leg), p));
        }
        self.push(kind, &seq)
    }
}
