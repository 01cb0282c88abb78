//! The OPEN list: a binary min-heap of `(key, h, node)` with lazy deletion.
//!
//! When a state's `g` improves it is pushed again; the old entry stays in the heap and is
//! recognised as stale when popped (its key no longer matches the state's current key,
//! or the state is no longer marked open). This is cheaper than an indexed heap's
//! decrease-key for the sparse improvements of grid-like graphs, and ARA*'s re-keying
//! rebuilds the heap in O(n) anyway.
//!
//! Order: smallest key first; among equal keys the smaller `h` (the deeper state,
//! which drives towards the goal), then the smaller node id (earlier discovery). Node ids
//! are assigned in discovery order, so ties are broken deterministically.

use super::nodes::NodeId;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// One heap entry (24 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Entry {
    /// Priority: `g·1000 + ε_milli·h` (ARA*'s `fvalue`, scaled by 1000).
    pub key: u64,
    /// The state's heuristic (micro-units), the first tie-break.
    pub h: u64,
    /// The state.
    pub node: NodeId,
}

impl Ord for Entry {
    /// Reversed, so that `BinaryHeap` (a max-heap) pops the smallest key.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .key
            .cmp(&self.key)
            .then_with(|| other.h.cmp(&self.h))
            .then_with(|| other.node.cmp(&self.node))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Min-heap of [`Entry`] with lazy deletion (validity is judged by the caller).
#[derive(Debug, Default)]
pub(crate) struct OpenList {
    heap: BinaryHeap<Entry>,
}

impl OpenList {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn push(&mut self, entry: Entry) {
        self.heap.push(entry);
    }

    /// Pops entries until `valid` accepts one, which is returned (and removed).
    pub fn pop_valid(&mut self, mut valid: impl FnMut(&Entry) -> bool) -> Option<Entry> {
        while let Some(e) = self.heap.pop() {
            if valid(&e) {
                return Some(e);
            }
        }
        None
    }

    /// Discards stale entries at the top; returns the smallest valid entry, leaving it in
    /// the heap.
    pub fn peek_valid(&mut self, mut valid: impl FnMut(&Entry) -> bool) -> Option<Entry> {
        while let Some(&e) = self.heap.peek() {
            if valid(&e) {
                return Some(e);
            }
            self.heap.pop();
        }
        None
    }

    /// All entries (valid or stale) in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = &Entry> {
        self.heap.iter()
    }

    /// Empties the heap, returning its entries (valid or stale) and keeping the
    /// allocation for [`OpenList::rebuild`].
    pub fn take_entries(&mut self) -> Vec<Entry> {
        std::mem::take(&mut self.heap).into_vec()
    }

    /// Replaces the contents with `entries`, heapified in O(n).
    pub fn rebuild(&mut self, entries: Vec<Entry>) {
        self.heap = BinaryHeap::from(entries);
    }

    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.heap.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_by_key_then_h_then_node() {
        let mut o = OpenList::new();
        for (key, h, node) in [(5, 0, 1), (3, 2, 7), (3, 1, 9), (3, 1, 4), (9, 0, 0)] {
            o.push(Entry { key, h, node });
        }
        let order: Vec<_> =
            std::iter::from_fn(|| o.pop_valid(|_| true)).map(|e| (e.key, e.h, e.node)).collect();
        assert_eq!(order, vec![(3, 1, 4), (3, 1, 9), (3, 2, 7), (5, 0, 1), (9, 0, 0)]);
    }

    #[test]
    fn lazy_deletion_skips_stale() {
        let mut o = OpenList::new();
        o.push(Entry { key: 1, h: 0, node: 0 });
        o.push(Entry { key: 2, h: 0, node: 1 });
        assert_eq!(o.peek_valid(|e| e.node != 0).map(|e| e.node), Some(1));
        assert_eq!(o.len(), 1);
        assert_eq!(o.pop_valid(|e| e.node != 1), None);
    }
}
