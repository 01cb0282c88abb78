//! What one manoeuvre unit is ([`Unit`]): its planner side (`planner::graph::Manoeuvre`,
//! made fresh per graph) and its expansion into keyframes, and the way every unit's
//! planner side runs the motion generator's own check ([`generator_check`]).

use crate::motion::expander::{Expander, MotionError};
use crate::path::{ManoeuvreKind, PathElement};
use crate::planner::core::{Feet, GraphCore};
use crate::planner::graph::Manoeuvre;
use crate::planner::lattice::LatticeState;
use crate::posture::standing::EstimatedCom;

/// One manoeuvre of the robot, whole: how the planner offers it and how the motion
/// generator expands it. A new manoeuvre is a new implementation of this trait and one
/// entry in `registry::MANOEUVRES`.
pub trait Unit: Sync {
    /// The path kinds this unit's edges carry (and it expands).
    fn kinds(&self) -> &'static [ManoeuvreKind];

    /// Its planner side, fresh for one graph (empty memo tables).
    fn planner(&self) -> Box<dyn Manoeuvre>;

    /// Expands element `k` of `path` (one of this unit's kinds) from the expander's
    /// current posture, appending its keyframes.
    ///
    /// # Errors
    /// [`MotionError`] naming the element when no stable, reachable motion holds.
    fn expand(
        &self,
        ex: &mut Expander<'_>,
        path: &[PathElement],
        k: usize,
    ) -> Result<(), MotionError>;
}

/// Runs one of the generator's own checks (`check`, on an [`Expander::for_check`]) from
/// the shared rule's standing posture at `s`'s pose on feet `feet`, with the planner's
/// CoM estimate ([`EstimatedCom`]) and margins (`HybridConfig::motion`); whether it
/// holds.
pub fn generator_check(
    core: &GraphCore<'_>,
    s: LatticeState,
    feet: &Feet,
    check: impl FnOnce(&mut Expander<'_>) -> Result<(), MotionError>,
) -> bool {
    generator_outcome(core, s, feet, check).is_ok()
}

/// [`generator_check`]'s outcome: the check's error, or `None` where the rule found no
/// standing posture to start from.
pub fn generator_outcome(
    core: &GraphCore<'_>,
    s: LatticeState,
    feet: &Feet,
    check: impl FnOnce(&mut Expander<'_>) -> Result<(), MotionError>,
) -> Result<(), Option<MotionError>> {
    let pose = core.lattice().pose(s);
    let robot = core.robot();
    let options = &core.config().motion;
    let world = GraphCore::feet_xyz(feet);
    let xy = [pose.x, pose.y];
    let Ok((pre, _)) =
        options.standing.stand(robot, core.maps().leg_terrain(), world, xy, pose.theta)
    else {
        return Err(None);
    };
    let mut model = EstimatedCom { robot };
    let mut ex = Expander::for_check(robot, core.maps(), &mut model, options, pre);
    check(&mut ex).map_err(Some)
}
