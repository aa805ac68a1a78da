//! The contact memory: what the contacts of the last step remember, by key.
//!
//! Rebuilt at every committed step from the step's contacts and looked up by every
//! vertex-edge candidate of the next detection, so its layout is a matter of speed on a
//! large wall (wall:31: ~7 000 contacts a step): the memories sit in a vector in the
//! order they were written — the order the next detection asks for them — and a hash
//! table maps a compact key to a position. A table of the memories themselves (96-byte buckets) took
//! a cache miss at nearly every write. The keys are kept in the same order too, so a
//! caller that knows where a memory was ([`ContactMemories::get_near`]: the detection's
//! next position, a contact's slot) finds it by one comparison instead of a hash.

use std::collections::hash_map::Entry;

use rustc_hash::FxHashMap;

use super::contact::{ContactKey, ContactMemory};

/// A contact key as four 32-bit numbers (the table's key: 16 bytes instead of 32).
/// Block and vertex counts are bounded far below 2³² by `crate::limits` (`MAX_BLOCKS`,
/// `MAX_SCENE_VERTICES`), so the narrowing loses nothing.
type CompactKey = [u32; 4];

fn compact(key: &ContactKey) -> CompactKey {
    [
        key.vertex_block as u32,
        key.vertex as u32,
        key.edge_block as u32,
        key.edge as u32,
    ]
}

/// What the contacts of the last step remember, by key (a map with the few operations the
/// solver needs).
#[derive(Debug, Clone, Default)]
pub struct ContactMemories {
    /// Position of each key's memory in `entries`.
    index: FxHashMap<CompactKey, u32>,
    /// The memories, in the order they were first written.
    entries: Vec<ContactMemory>,
    /// The key of each memory in `entries`, at the same position.
    keys: Vec<CompactKey>,
}

impl ContactMemories {
    /// The memory of `key`, if it has one.
    pub fn get(&self, key: &ContactKey) -> Option<&ContactMemory> {
        Some(&self.entries[self.position(&compact(key))?])
    }

    /// The memory of `key` and its position, looked for first at position `hint` (where
    /// the caller expects it: any value is safe, a wrong one costs the table's lookup).
    pub fn get_near(&self, key: &ContactKey, hint: usize) -> Option<(usize, &ContactMemory)> {
        let key = compact(key);
        let at = if self.keys.get(hint) == Some(&key) {
            hint
        } else {
            self.position(&key)?
        };
        Some((at, &self.entries[at]))
    }

    /// True if `key` has a memory.
    pub fn contains_key(&self, key: &ContactKey) -> bool {
        self.position(&compact(key)).is_some()
    }

    /// The memory of `key` to change, if it has one.
    pub fn get_mut(&mut self, key: &ContactKey) -> Option<&mut ContactMemory> {
        let at = self.position(&compact(key))?;
        Some(&mut self.entries[at])
    }

    /// Where the memory of `key` is, by the table.
    fn position(&self, key: &CompactKey) -> Option<usize> {
        self.index.get(key).map(|&at| at as usize)
    }

    /// Sets the memory of `key` (replacing any it had); returns its position (a hint for
    /// [`ContactMemories::get_near`]).
    pub fn insert(&mut self, key: ContactKey, memory: ContactMemory) -> usize {
        let (at, added) = self.position_or_push(key, memory);
        if !added {
            self.entries[at] = memory;
        }
        at
    }

    /// The memory of `key` to change, first set to `memory` if it had none.
    pub fn get_or_insert(&mut self, key: ContactKey, memory: ContactMemory) -> &mut ContactMemory {
        let (at, _) = self.position_or_push(key, memory);
        &mut self.entries[at]
    }

    /// Where the memory of `key` is, and whether it was just added there as `memory`
    /// (one lookup of the table either way).
    fn position_or_push(&mut self, key: ContactKey, memory: ContactMemory) -> (usize, bool) {
        match self.index.entry(compact(&key)) {
            Entry::Occupied(at) => (*at.get() as usize, false),
            Entry::Vacant(slot) => {
                self.keys.push(*slot.key());
                slot.insert(self.entries.len() as u32);
                self.entries.push(memory);
                (self.entries.len() - 1, true)
            }
        }
    }

    /// Forgets every memory (keeping the storage for the next step's).
    pub fn clear(&mut self) {
        self.index.clear();
        self.entries.clear();
        self.keys.clear();
    }

    /// Every memory, to change (in no particular order).
    pub fn values_mut(&mut self) -> impl Iterator<Item = &mut ContactMemory> {
        self.entries.iter_mut()
    }

    /// How many contacts have a memory.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True if no contact has a memory.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn memory(gap: f64) -> ContactMemory {
        ContactMemory::stuck_for_test(gap)
    }

    fn key(vertex_block: usize, vertex: usize, edge_block: usize, edge: usize) -> ContactKey {
        ContactKey {
            vertex_block,
            vertex,
            edge_block,
            edge,
        }
    }

    /// Keys that differ in any one field are different contacts; a second write replaces
    /// the first; `get_or_insert` keeps an existing memory; `clear` forgets all.
    #[test]
    fn the_memory_is_a_map_by_the_whole_key() {
        let mut m = ContactMemories::default();
        let keys = [
            key(1, 2, 3, 4),
            key(0, 2, 3, 4),
            key(1, 0, 3, 4),
            key(1, 2, 0, 4),
            key(1, 2, 3, 0),
        ];
        for (i, k) in keys.iter().enumerate() {
            m.insert(*k, memory(i as f64));
        }
        assert_eq!(m.len(), keys.len());
        for (i, k) in keys.iter().enumerate() {
            assert_eq!(m.get(k).map(|c| c.gap), Some(i as f64), "{k:?}");
        }
        m.insert(keys[2], memory(-1.0));
        assert_eq!(m.len(), keys.len());
        assert_eq!(m.get(&keys[2]).map(|c| c.gap), Some(-1.0));
        assert_eq!(m.get_or_insert(keys[3], memory(9.0)).gap, 3.0);
        m.get_mut(&keys[4]).unwrap().gap = 7.0;
        assert_eq!(m.get(&keys[4]).map(|c| c.gap), Some(7.0));
        assert_eq!(m.get(&key(5, 5, 5, 5)), None);
        assert!(m.contains_key(&keys[1]) && !m.contains_key(&key(5, 5, 5, 5)));
        assert_eq!(m.values_mut().count(), keys.len());
        m.clear();
        assert!(m.is_empty());
        assert_eq!(m.get(&keys[0]), None);
        assert_eq!(m.get_or_insert(keys[0], memory(2.0)).gap, 2.0);
        assert_eq!(m.len(), 1);
    }

    /// A hint is only a place to look first: the right one, a wrong one and one past
    /// the end all find the key's memory (and its position, which `insert` returned);
    /// a key without a memory is not found at any hint.
    #[test]
    fn a_hint_never_changes_what_is_found() {
        let mut m = ContactMemories::default();
        let keys = [key(1, 2, 3, 4), key(4, 3, 2, 1), key(0, 0, 1, 1)];
        let slots: Vec<usize> = (0..keys.len())
            .map(|i| m.insert(keys[i], memory(i as f64)))
            .collect();
        assert_eq!(slots, [0, 1, 2]);
        assert_eq!(
            m.insert(keys[1], memory(5.0)),
            1,
            "a rewrite keeps its position"
        );
        for (i, k) in keys.iter().enumerate() {
            let gap = if i == 1 { 5.0 } else { i as f64 };
            for hint in [slots[i], (slots[i] + 1) % keys.len(), usize::MAX] {
                let (at, found) = m.get_near(k, hint).expect("a memory");
                assert_eq!((at, found.gap), (slots[i], gap), "{k:?} at hint {hint}");
            }
        }
        for hint in [0, 1, 2, usize::MAX] {
            assert!(m.get_near(&key(9, 9, 9, 9), hint).is_none());
        }
        m.clear();
        assert!(
            m.get_near(&keys[0], 0).is_none(),
            "cleared: the old positions are gone"
        );
    }
}
