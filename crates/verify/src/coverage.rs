//! Which samples some triangle covers: one bit per grid sample.

/// A fixed-size set of sample indices, one bit each (a 20k x 20k grid takes 50 MB).
#[derive(Debug, Clone)]
pub(crate) struct Coverage {
    words: Vec<u64>,
}

impl Coverage {
    /// An empty set able to hold indices `0..len`.
    pub(crate) fn new(len: usize) -> Self {
        Self {
            words: vec![0; len.div_ceil(64)],
        }
    }

    /// Adds sample index `i`.
    ///
    /// # Panics
    /// If `i` is not below the `len` given to [`Coverage::new`] (rounded up to 64).
    pub(crate) fn insert(&mut self, i: usize) {
        self.words[i / 64] |= 1 << (i % 64);
    }

    /// Whether sample index `i` was added.
    pub(crate) fn contains(&self, i: usize) -> bool {
        self.words[i / 64] & (1 << (i % 64)) != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn insert_and_contains() {
        let mut set = Coverage::new(130);
        for i in [0, 63, 64, 129] {
            assert!(!set.contains(i));
            set.insert(i);
            assert!(set.contains(i));
        }
        let count = (0..130).filter(|&i| set.contains(i)).count();
        assert_eq!(count, 4);
        set.insert(64);
        assert_eq!((0..130).filter(|&i| set.contains(i)).count(), 4);
    }

    #[test]
    fn empty_set() {
        let set = Coverage::new(0);
        assert!(set.words.is_empty());
    }
}
