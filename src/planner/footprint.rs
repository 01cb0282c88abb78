//! Footprints: where the four feet stand relative to the base (Sec. V).
//!
//! Momaro's legs move their feet only in their sagittal planes (the base's x'–z' plane at
//! each hip), so a footprint is four longitudinal offsets, one per leg (FL, FR, RL, RR),
//! from the foot's position in the *neutral footprint* (Sec. V, Fig. 6a: the driving
//! configuration). Offsets are whole grid cells along x' (2.5 cm), so footprints are
//! exact, hashable and few.
//!
//! A lattice state carries a footprint as a small id ([`LatticeState::footprint`]) into a
//! [`FootprintTable`], which interns each offset tuple the first time a manoeuvre creates
//! it. Id 0 is always the neutral footprint ([`NEUTRAL_FOOTPRINT`]). Ids are handed out
//! in the order footprints are first met, which the deterministic search fixes, so the
//! same plan gives the same ids. The table is bounded: the per-leg offset range is the
//! leg's reach (a few dozen cells) and the table refuses new entries beyond a cap, so the
//! graph stays finite whatever the terrain.
//!
//! [`LatticeState::footprint`]: super::LatticeState::footprint

use super::lattice::NEUTRAL_FOOTPRINT;
use crate::search::FxBuild;
use std::collections::HashMap;

/// Per-leg longitudinal foot offsets from the neutral footprint, in grid cells along the
/// base's x' axis (positive: forward), indexed FL, FR, RL, RR.
pub type FootOffsets = [i8; 4];

/// The neutral footprint's offsets.
pub const NEUTRAL_OFFSETS: FootOffsets = [0; 4];

/// Interned footprints: a `Vec` of offsets by id and a deterministic hash map back.
#[derive(Debug, Clone)]
pub struct FootprintTable {
    offsets: Vec<FootOffsets>,
    ids: HashMap<FootOffsets, u16, FxBuild>,
    max: usize,
}

impl FootprintTable {
    /// A table holding only the neutral footprint (id 0), accepting at most `max`
    /// footprints in all (at least 1, at most 65 536: ids are `u16`).
    pub fn new(max: usize) -> Self {
        let mut ids = HashMap::default();
        ids.insert(NEUTRAL_OFFSETS, NEUTRAL_FOOTPRINT);
        Self { offsets: vec![NEUTRAL_OFFSETS], ids, max: max.clamp(1, usize::from(u16::MAX) + 1) }
    }

    /// The offsets of footprint `id`, `None` for an id never handed out.
    #[inline]
    pub fn get(&self, id: u16) -> Option<FootOffsets> {
        self.offsets.get(usize::from(id)).copied()
    }

    /// The id of `offsets`, interning them if new; `None` when the table is full.
    pub fn intern(&mut self, offsets: FootOffsets) -> Option<u16> {
        if let Some(&id) = self.ids.get(&offsets) {
            return Some(id);
        }
        if self.offsets.len() >= self.max {
            return None;
        }
        let id = u16::try_from(self.offsets.len()).ok()?;
        self.offsets.push(offsets);
        self.ids.insert(offsets, id);
        Some(id)
    }

    /// Number of footprints interned (the neutral one included).
    pub fn len(&self) -> usize {
        self.offsets.len()
    }

    /// Always false: the neutral footprint is always there.
    pub fn is_empty(&self) -> bool {
        self.offsets.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neutral_is_zero_and_ids_are_stable() {
        let mut t = FootprintTable::new(4);
        assert_eq!(t.get(0), Some(NEUTRAL_OFFSETS));
        assert_eq!(t.intern(NEUTRAL_OFFSETS), Some(0));
        assert_eq!(t.intern([3, 0, 0, 0]), Some(1));
        assert_eq!(t.intern([3, 4, 0, 0]), Some(2));
        assert_eq!(t.intern([3, 0, 0, 0]), Some(1));
        assert_eq!(t.get(2), Some([3, 4, 0, 0]));
        assert_eq!(t.intern([0, 0, 0, -2]), Some(3));
        // Full: known footprints still resolve, new ones are refused.
        assert_eq!(t.intern([1, 1, 1, 1]), None);
        assert_eq!(t.intern([3, 4, 0, 0]), Some(2));
        assert_eq!(t.len(), 4);
        assert_eq!(t.get(9), None);
    }
}
