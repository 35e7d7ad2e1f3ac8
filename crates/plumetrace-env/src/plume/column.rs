//! One column of the filaments' state (the plume stores them as parallel columns), whose front
//! can be dropped without moving what follows it.
//!
//! Filaments leave the plume mostly from the front of the columns: they are kept in release
//! order, and the oldest are the ones that reach the domain's edge or the downflow sink. Dropping
//! a few of them used to move every filament behind them; a column instead moves only the kept
//! filaments before the last one dropped, toward the back, and starts later. The dropped front is
//! reclaimed when it outgrows the live filaments, so each filament is moved a bounded number of
//! times on average.

use std::ops::{Deref, DerefMut};

/// A growable column whose live part starts at `head`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Column<T> {
    buf: Vec<T>,
    head: usize,
}

/// A dropped front is reclaimed (the live part moved to the start) once it is at least this long
/// and at least as long as the live part.
const RECLAIM_AT: usize = 4096;

impl<T: Copy> Column<T> {
    /// An empty column.
    pub(crate) const fn new() -> Self {
        Column {
            buf: Vec::new(),
            head: 0,
        }
    }

    /// Appends `v` at the back.
    #[inline]
    pub(crate) fn push(&mut self, v: T) {
        self.buf.push(v);
    }

    /// Copies live value `from` to live position `to`.
    #[inline]
    pub(crate) fn copy(&mut self, from: usize, to: usize) {
        self.buf[self.head + to] = self.buf[self.head + from];
    }

    /// Drops the first `n` live values.
    pub(crate) fn drop_front(&mut self, n: usize) {
        self.head = self.head.saturating_add(n).min(self.buf.len());
        let live = self.buf.len() - self.head;
        if self.head >= RECLAIM_AT && self.head >= live {
            self.buf.drain(..self.head);
            self.head = 0;
        }
    }

    /// A copy of the live values in a column of their own.
    pub(crate) fn copy_live(&self) -> Self {
        Column {
            buf: self.buf[self.head..].to_vec(),
            head: 0,
        }
    }
}

impl<T> Deref for Column<T> {
    type Target = [T];
    #[inline]
    fn deref(&self) -> &[T] {
        &self.buf[self.head..]
    }
}

impl<T> DerefMut for Column<T> {
    #[inline]
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.buf[self.head..]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_drops_its_front_keeps_its_order_and_reclaims_the_room() {
        let mut c = Column::new();
        for v in 0..10_000u32 {
            c.push(v);
        }
        // Drop 3, 4 and 5 and keep 0, 1 and 2: move them back over the gap, as the plume does,
        // and start three later.
        for k in (0..3).rev() {
            c.copy(k, k + 3);
        }
        c.drop_front(3);
        assert_eq!(&c[..4], &[0, 1, 2, 6]);
        assert_eq!(c.len(), 9_997);
        assert_eq!(c[c.len() - 1], 9_999);
        c.push(42);
        assert_eq!(c[c.len() - 1], 42);
        // A long dropped front is reclaimed once it outgrows the live part; the values stay.
        let mut mirror: Vec<u32> = c.to_vec();
        for v in 0..5_000u32 {
            c.push(v);
            mirror.push(v);
        }
        c.drop_front(4_100);
        assert_eq!(c.head, 4_103, "a front shorter than the live part stays");
        assert_eq!(&c[..], &mirror[4_100..]);
        c.drop_front(7_900);
        assert_eq!(c.head, 0, "the dropped front was reclaimed");
        assert_eq!(&c[..], &mirror[12_000..]);
        assert_eq!(&c.copy_live()[..], &mirror[12_000..]);
        c.drop_front(usize::MAX);
        assert!(c.is_empty());
    }
}
