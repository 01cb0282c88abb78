//! Every manoeuvre the robot can make, registered once: the order here is the order in
//! which the planner offers their successors (and numbers their intermediate nodes'
//! tags), and each path kind's expansion is looked up here.

use super::base_shift::BaseShift;
use super::drive::Drive;
use super::step::Step;
use super::unit::Unit;
use super::wheel_move::WheelMove;
use crate::path::ManoeuvreKind;
use crate::planner::graph::{Manoeuvre, ManoeuvreSet};

/// The robot's manoeuvres: drive and turn, abstract step, base shift, wheel moves.
pub static MANOEUVRES: [&dyn Unit; 4] = [&Drive, &Step, &BaseShift, &WheelMove];

/// [`MANOEUVRES`] as the planner takes them.
#[derive(Debug, Clone, Copy, Default)]
pub struct Manoeuvres;

/// The robot's manoeuvres, for `planner::prepare`.
pub static ALL: Manoeuvres = Manoeuvres;

impl ManoeuvreSet for Manoeuvres {
    fn instantiate(&self) -> Vec<Box<dyn Manoeuvre>> {
        MANOEUVRES.iter().map(|u| u.planner()).collect()
    }
}

/// The unit whose edges carry `kind` (none for `start`).
pub fn unit_for(kind: ManoeuvreKind) -> Option<&'static dyn Unit> {
    MANOEUVRES.iter().copied().find(|u| u.kinds().contains(&kind))
}
