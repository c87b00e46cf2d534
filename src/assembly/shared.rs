//! A slice that parallel tasks write to at disjoint indices: the colored fills, where no two
//! elements of one color touch the same entry, and the node-owned contact fill, where each task
//! writes its own node's columns.

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

    /// Hints the CPU to bring entry `i` into the cache (no effect when `i` is out of range).
    #[inline]
    pub(crate) fn prefetch(&self, i: usize) {
        if i < self.len {
            // SAFETY: the address is inside the slice.
            prefetch(unsafe { self.ptr.add(i) });
        }
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

/// Hints the CPU to bring the cache line at `p` into the cache (nothing off x86-64). A prefetch
/// never faults, whatever the address.
#[inline]
pub(crate) fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch has no architectural effect and never faults.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(p.cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
