//! Zeros written into fresh memory on all threads.

use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Grows `values` to `len` with zeros written on all threads, so each new page is mapped by
/// one write fault on whichever core writes it. Zeros left to the allocator are mapped later
/// by their first use, in its critical path (and a first `+=` reads the shared zero page
/// first: two faults and a TLB shootdown per page). Does nothing when `values` is as long.
pub fn extend_with_zeros_par(values: &mut Vec<f64>, len: usize) {
    let done = values.len();
    if len <= done {
        return;
    }
    values.reserve_exact(len - done);
    values.spare_capacity_mut()[..len - done]
        .par_chunks_mut(1 << 15)
        .for_each(|chunk| chunk.fill(MaybeUninit::new(0.0)));
    // SAFETY: the `len - done` elements of the capacity after the first `done` were all
    // written just above.
    unsafe { values.set_len(len) };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// From empty, from a prefix of other values and past several chunks: the prefix kept,
    /// the rest zeros; a shorter length leaves the vector as it is.
    #[test]
    fn the_vector_grows_by_zeros_and_keeps_its_prefix() {
        let mut v = Vec::new();
        extend_with_zeros_par(&mut v, 5);
        assert_eq!(v, [0.0; 5]);
        let mut v = vec![1.0, 2.0];
        extend_with_zeros_par(&mut v, 3 * (1 << 15) + 7);
        assert_eq!(v.len(), 3 * (1 << 15) + 7);
        assert_eq!(&v[..2], &[1.0, 2.0]);
        assert!(v[2..].iter().all(|&x| x == 0.0));
        extend_with_zeros_par(&mut v, 1);
        assert_eq!(v.len(), 3 * (1 << 15) + 7);
    }
}
