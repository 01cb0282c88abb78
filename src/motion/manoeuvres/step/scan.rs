//! The step's scan (criteria 2 and 3 of Sec. V): the footholds along a foot's sagittal
//! line by the cost maps alone, cheapest first, and C_S (eq. 5). The base shifts read it
//! too, to shift where a foot can still step.

use crate::cost::Cost as CostValue;
use crate::path::StepCost;
use crate::planner::config::HybridConfig;
use crate::planner::core::{Feet, GraphCore};
use crate::planner::footprint::FootOffsets;
use crate::planner::heuristic::step_bound::STEP_HEIGHT_TOLERANCE_M;
use crate::planner::lattice::LatticeState;

/// A foothold of a step by the scan ([`step_candidates`]): C_S, the offset
/// change in cells, the cost terms and the foothold (x, y, ground z).
pub type StepCandidate = (f64, i32, StepCost, [f64; 3]);

/// C_S = k7 · L_step + k8 · (C_F(c_h) − 1) + k9 · ΔH_step (eq. 5), before the
/// step-related factor.
pub fn step_cost(params: &HybridConfig, length_m: f64, foothold_cost: f64, height_m: f64) -> f64 {
    params.k7 * length_m + params.k8 * (foothold_cost - 1.0) + params.k9 * height_m
}

/// The footholds of `leg`'s step by the scan alone (C_S, offset change, cost terms,
/// foothold x, y, z), cheapest first (ties: the shorter step): the foot's sagittal
/// line forward to the end of the leg's reach, footholds that
///
/// - have finite foot cost C_F (criterion 2) and lie beyond at least one cell of
///   infinite C_F (the foot is carried over the obstacle, see the module docs),
/// - differ in height from the foot by at most `max_step_height_m` (criterion 3),
///   as does every cell passed on the way.
///
/// The checks that need the IK are left to `StepPlanner::best_step`.
pub fn step_candidates(
    core: &GraphCore<'_>,
    s: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    leg: usize,
) -> Vec<StepCandidate> {
    let res = core.lattice().resolution;
    let (hx, hy) = core.heading(s.theta);
    let bin = core.bin(s.theta);
    let [x0, y0] = feet.pos[leg];
    let h0 = feet.h[leg];
    let max_d = i32::from(core.reach()[leg][1]) - i32::from(o[leg]);
    let mut crossed = false;
    let mut dh_max = 0.0_f64;
    // Footholds by the scan: (C_S, offset, cost terms, foothold). The checks that
    // need the IK run afterwards in order of C_S, and stop at the first that holds.
    let mut candidates: Vec<StepCandidate> = Vec::new();
    for d in 1..=max_d {
        let l = f64::from(d) * res;
        let (x, y) = (x0 + hx * l, y0 + hy * l);
        let hm = core.maps().heights();
        let Some((i, j)) = hm.cell_of(x, y) else {
            break;
        };
        // Unknown terrain cannot be stepped over: the leg could hit anything.
        let Some(h) = hm.get(i, j) else { break };
        dh_max = dh_max.max((h - h0).abs());
        if dh_max > core.config().max_step_height_m + STEP_HEIGHT_TOLERANCE_M {
            break;
        }
        let cf = match core.maps().foot_cost_cell_at(i, j, bin) {
            CostValue::Finite(c) => c,
            CostValue::Infinite => {
                crossed = true;
                continue;
            }
            CostValue::Unknown => break,
        };
        if !crossed {
            continue;
        }
        let c_s = step_cost(core.config(), l, cf, dh_max);
        let cost = StepCost { length_m: l, foothold_cost: cf, height_m: dh_max, c_s };
        candidates.push((c_s, d, cost, [x, y, h]));
    }
    // Cheapest first; ties: the shorter step (the scan order, kept by a stable sort).
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    candidates
}

/// Whether leg `r` at state `t` (offsets `o`, feet `feet`) keeps every leg in reach
/// through a step to its cheapest foothold by the scan.
pub fn step_reaches(
    core: &GraphCore<'_>,
    t: LatticeState,
    o: &FootOffsets,
    feet: &Feet,
    r: usize,
) -> bool {
    let Some(&(_, _, _, post)) = step_candidates(core, t, o, feet, r).first() else {
        return false;
    };
    let pose = core.lattice().pose(t);
    core.config()
        .motion
        .standing
        .step_heights(
            core.robot(),
            core.maps().heights(),
            core.maps().leg_terrain(),
            GraphCore::feet_xyz(feet),
            r,
            post,
            [pose.x, pose.y],
            pose.theta,
        )
        .next()
        .is_some()
}
