//! Driving and turning on the spot (Sec. V, VII-A, Fig. 4) as one unit: the neutral
//! footprint's moves of the lattice (`planner::driving`: the 16- or 20-neighbourhood and
//! the turn to the next orientation, at the pose costs of eq. 4 times k_Δθ), their
//! expansion into keyframes, and the heuristic terms that bound them (the Euclidean
//! distance plus turn and the cost-to-go's driving edges, `Relaxation::Driving`).
//!
//! The lattice admits a driving pose where the shared feasibility model fits the robot in
//! its driving posture, or failing that, standing (`feasibility::DrivingCheck`). The
//! expansion keeps one keyframe per path pose, the feet in the neutral footprint on the
//! height map: at driving height (0.27 m) the mean hip stands that high above the mean
//! ground under the feet (`posture::kinematics::driving_posture`, which the closed loop
//! uses too); while standing (between close manoeuvres) the leg-height rule applies. The
//! robot lowers to driving height when the footprint is neutral and the next manoeuvre
//! is at least `MotionOptions::stay_standing_m` of driving away (or none), where the
//! driving posture fits; where it does not (a knee over a wall, a wheel folded past its
//! limit), it drives standing, as the planner's feasibility check allowed.

use super::unit::Unit;
use crate::geometry::Pose2;
use crate::motion::expander::{Expander, MotionError};
use crate::motion::keyframe::Phase;
use crate::path::{EdgeLabel, ManoeuvreKind, PathElement};
use crate::planner::core::{GraphCore, Stance};
use crate::planner::graph::{Manoeuvre, Successors};
use crate::planner::heuristic::Relaxation;
use crate::planner::lattice::{LatticeState, NEUTRAL_FOOTPRINT};

/// Driving and turning on the spot, one unit (see the module docs).
pub struct Drive;

/// The drive's planner side: the driving graph's moves, which keep no memo of their own.
struct DrivePlanner;

impl Unit for Drive {
    fn kinds(&self) -> &'static [ManoeuvreKind] {
        &[ManoeuvreKind::Drive, ManoeuvreKind::Turn]
    }

    fn planner(&self) -> Box<dyn Manoeuvre> {
        Box::new(DrivePlanner)
    }

    /// A keyframe at the element's pose, driving or standing (see the module docs).
    fn expand(
        &self,
        ex: &mut Expander<'_>,
        path: &[PathElement],
        k: usize,
    ) -> Result<(), MotionError> {
        let el = &path[k];
        let check = ex.driving_check();
        let (maps, stay_standing_m) = (ex.maps, ex.o.stay_standing_m);
        if ex.standing {
            // Lower if the next manoeuvre is far (or there is none).
            let mut dist = 0.0;
            let mut prev = path[k - 1].pose;
            let mut next_special = false;
            for e2 in &path[k..] {
                if e2.kind.is_step_related() {
                    next_special = true;
                    break;
                }
                dist += prev.distance(&e2.pose);
                prev = e2.pose;
            }
            if !next_special || dist >= stay_standing_m {
                let pose = Pose2 {
                    x: ex.cur.base_position[0],
                    y: ex.cur.base_position[1],
                    theta: ex.cur.base_rpy[2],
                };
                let p = ex.driving(&pose)?;
                // Lower only where the driving posture fits (`feasibility`).
                if check.posture_ok(&p, maps, maps.leg_terrain()).is_ok() {
                    ex.push(el.kind, &[(Phase::Lower, None, p)])?;
                    ex.standing = false;
                }
            }
        }
        // Where the driving posture does not fit (a knee over a wall, a wheel folded past
        // its limit), drive standing, as the planner's feasibility check allowed
        // (`feasibility::DrivingCheck::lattice_pose`).
        if !ex.standing
            && check.posture_ok(&ex.driving(&el.pose)?, maps, maps.leg_terrain()).is_err()
        {
            ex.stand_up(el.kind)?;
            ex.standing = true;
        }
        let target = if ex.standing {
            let feet = ex.neutral_feet(&el.pose)?;
            ex.stand_for(el.kind, feet, [el.pose.x, el.pose.y], el.pose.theta)?
        } else {
            ex.driving(&el.pose)?
        };
        ex.push(el.kind, &[(Phase::Drive, None, target)])
    }
}

impl Manoeuvre for DrivePlanner {
    fn relaxation(&self) -> Relaxation {
        Relaxation::Driving
    }

    /// The driving graph's moves and turns from a neutral state, labelled a turn where the
    /// cell stays and a drive elsewhere.
    fn successors(
        &mut self,
        core: &mut GraphCore<'_>,
        s: LatticeState,
        _stance: Option<&Stance>,
        _lazy: bool,
        out: &mut Successors<'_>,
    ) {
        if s.footprint != NEUTRAL_FOOTPRINT {
            return;
        }
        let first = out.edges().len();
        core.driving_successors(s, out.edges());
        if !out.wants_labels() {
            return;
        }
        let lattice = core.lattice();
        let a = lattice.pose(s);
        let turn_m = core.driving().config().turn_radius_m * lattice.orientation_step();
        let added: Vec<(LatticeState, crate::search::Cost)> = out.edges()[first..].to_vec();
        for (t, c) in added {
            let (kind, length_m) = if (t.i, t.j) == (s.i, s.j) {
                (ManoeuvreKind::Turn, turn_m)
            } else {
                (ManoeuvreKind::Drive, a.distance(&lattice.pose(t)))
            };
            out.label(EdgeLabel { kind, leg: None, length_m, cost: c.to_f64(), step: None });
        }
    }
}
