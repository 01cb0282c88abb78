//! The OPEN list: a 4-ary min-heap of `(key, h, node)` with lazy deletion.
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

/// Min-heap of [`Entry`] with lazy deletion (validity is judged by the caller).
///
/// A 4-ary implicit heap: half the levels of a binary heap, and a node's four children
/// share one or two cache lines, so a pop touches about half as many lines on the large
/// OPEN lists of a pose lattice (a binary heap's pop was a quarter of the search time).
/// Entries are totally ordered (the node id breaks every tie), so the pop order — and
/// hence the search — is the same as with any other correct priority queue.
#[derive(Debug, Default)]
pub(crate) struct OpenList {
    heap: Vec<Entry>,
}

/// Children per heap node.
const ARITY: usize = 4;

/// `a` pops before `b`.
#[inline]
fn before(a: &Entry, b: &Entry) -> bool {
    (a.key, a.h, a.node) < (b.key, b.h, b.node)
}

impl OpenList {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn push(&mut self, entry: Entry) {
        self.heap.push(entry);
        self.sift_up(self.heap.len() - 1);
    }

    fn sift_up(&mut self, mut i: usize) {
        let e = self.heap[i];
        while i > 0 {
            let parent = (i - 1) / ARITY;
            if !before(&e, &self.heap[parent]) {
                break;
            }
            self.heap[i] = self.heap[parent];
            i = parent;
        }
        self.heap[i] = e;
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.heap.len();
        let e = self.heap[i];
        loop {
            let first = i * ARITY + 1;
            if first >= n {
                break;
            }
            let mut best = first;
            for c in first + 1..(first + ARITY).min(n) {
                if before(&self.heap[c], &self.heap[best]) {
                    best = c;
                }
            }
            if !before(&self.heap[best], &e) {
                break;
            }
            self.heap[i] = self.heap[best];
            i = best;
        }
        self.heap[i] = e;
    }

    /// Removes and returns the smallest entry.
    fn pop(&mut self) -> Option<Entry> {
        let last = self.heap.pop()?;
        if self.heap.is_empty() {
            return Some(last);
        }
        let top = std::mem::replace(&mut self.heap[0], last);
        self.sift_down(0);
        Some(top)
    }

    /// Pops entries until `valid` accepts one, which is returned (and removed).
    pub fn pop_valid(&mut self, mut valid: impl FnMut(&Entry) -> bool) -> Option<Entry> {
        while let Some(e) = self.pop() {
            if valid(&e) {
                return Some(e);
            }
        }
        None
    }

    /// Discards stale entries at the top; returns the smallest valid entry, leaving it in
    /// the heap.
    pub fn peek_valid(&mut self, mut valid: impl FnMut(&Entry) -> bool) -> Option<Entry> {
        while let Some(&e) = self.heap.first() {
            if valid(&e) {
                return Some(e);
            }
            self.pop();
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
        std::mem::take(&mut self.heap)
    }

    /// Replaces the contents with `entries`, heapified in O(n).
    pub fn rebuild(&mut self, entries: Vec<Entry>) {
        self.heap = entries;
        let n = self.heap.len();
        if n > 1 {
            for i in (0..=(n - 2) / ARITY).rev() {
                self.sift_down(i);
            }
        }
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
    fn pops_in_sorted_order_after_pushes_and_rebuilds() {
        // A deterministic pseudo-random mix of pushes, pops and a rebuild against a
        // sorted reference.
        let mut o = OpenList::new();
        let mut reference: Vec<(u64, u64, u32)> = Vec::new();
        let mut x = 12345_u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for round in 0..2000 {
            let r = next();
            if r % 3 == 0 && !reference.is_empty() {
                reference.sort_unstable();
                let want = reference.remove(0);
                let got = o.pop_valid(|_| true).map(|e| (e.key, e.h, e.node));
                assert_eq!(got, Some(want));
            } else {
                let e = Entry { key: r % 50, h: (r >> 8) % 5, node: round };
                reference.push((e.key, e.h, e.node));
                o.push(e);
            }
            if round == 1000 {
                let entries = o.take_entries();
                o.rebuild(entries);
            }
        }
        reference.sort_unstable();
        let rest: Vec<_> =
            std::iter::from_fn(|| o.pop_valid(|_| true)).map(|e| (e.key, e.h, e.node)).collect();
        assert_eq!(rest, reference);
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
