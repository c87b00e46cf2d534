//! A slice that parallel tasks write to at disjoint indices: the colored fills, where no two
//! elements (or contacts) of one color touch the same entry.

use std::marker::PhantomData;

/// Shared mutable access to a slice for writes at disjoint indices.
pub(crate) struct SharedMut<'a, T> {
    ptr: *mut T,
    len: usize,
    _slice: PhantomData<&'a mut [T]>,
}

// SAFETY: the only access is `get`, whose contract excludes concurrent access to one index.
unsafe impl<T: Send> Sync for SharedMut<'_, T> {}
unsafe impl<T: Send> Send for SharedMut<'_, T> {}

impl<'a, T> SharedMut<'a, T> {
    /// Borrows `slice` for the lifetime of the shared view.
    pub(crate) fn new(slice: &'a mut [T]) -> Self {
        SharedMut {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _slice: PhantomData,
        }
    }

    /// The entry at `i`.
    ///
    /// # Safety
    /// No other task may access index `i` while the returned reference lives. `i` is bounds
    /// checked (a panic, not undefined behaviour, when it is out of range).
    #[allow(clippy::mut_from_ref)]
    pub(crate) unsafe fn get(&self, i: usize) -> &mut T {
        assert!(i < self.len, "index {i} out of {}", self.len);
        // SAFETY: in bounds; exclusivity is the caller's contract.
        unsafe { &mut *self.ptr.add(i) }
    }

    /// The `N` entries from `start` on.
    ///
    /// # Safety
    /// As [`SharedMut::get`], for every index of the run. The run is bounds checked.
    #[allow(clippy::mut_from_ref)]
    pub(crate) unsafe fn run<const N: usize>(&self, start: usize) -> &mut [T; N] {
        assert!(start + N <= self.len, "run {start}+{N} out of {}", self.len);
        // SAFETY: in bounds; exclusivity is the caller's contract.
        unsafe { &mut *self.ptr.add(start).cast::<[T; N]>() }
    }
}
