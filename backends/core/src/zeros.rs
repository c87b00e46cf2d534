//! Zeros written into fresh memory, on all threads or on the calling one.

use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Values per task of [`extend_with_zeros_par`] (256 KiB).
const CHUNK: usize = 1 << 15;

/// Grows `values` to `len` with zeros written on all threads, so each new page is mapped by
/// one write fault on whichever core writes it. Zeros left to the allocator are mapped later
/// by their first use, in its critical path (and a first `+=` reads the shared zero page
/// first: two faults and a TLB shootdown per page). Does nothing when `values` is as long.
pub fn extend_with_zeros_par(values: &mut Vec<f64>, len: usize) {
    // SAFETY (of `extend`'s contract): every chunk of the new elements is written.
    unsafe {
        extend(values, len, |new| {
            new.par_chunks_mut(CHUNK).for_each(write_zeros)
        })
    }
}

/// [`extend_with_zeros_par`] on the calling thread alone (for a helper that must not take
/// the pool's threads).
pub fn extend_with_zeros(values: &mut Vec<f64>, len: usize) {
    // SAFETY: as above.
    unsafe {
        extend(values, len, |new| {
            new.chunks_mut(CHUNK).for_each(write_zeros)
        })
    }
}

/// Grows `values` to `len` (when longer) by elements that `write` initializes.
///
/// # Safety
/// `write` writes every element of the slice it is given.
unsafe fn extend(values: &mut Vec<f64>, len: usize, write: impl FnOnce(&mut [MaybeUninit<f64>])) {
    let done = values.len();
    if len <= done {
        return;
    }
    values.reserve_exact(len - done);
    write(&mut values.spare_capacity_mut()[..len - done]);
    // SAFETY: the `len - done` elements of the capacity after the first `done` were all
    // written by `write` (the caller's contract).
    unsafe { values.set_len(len) };
}

/// Maps the pages of `values` for writing, one request per 256 KiB on all threads, leaving
/// every value as it is: for an array fresh from the allocator (`vec![0; n]`, whose zeros
/// the allocator maps lazily) that is about to be written all over on the threads, so that
/// the writes fault no more. Only a cost where the pages are mapped already.
pub fn populate_par<T: Send>(values: &mut [T]) {
    let chunk = (256 << 10) / std::mem::size_of::<T>().max(1);
    values
        .par_chunks_mut(chunk.max(1))
        .for_each(|c| populate_for_write(c));
}

/// Zeros into `chunk`, its whole pages first mapped for writing in one request to the kernel
/// (Linux's `MADV_POPULATE_WRITE`, 5.14 on; elsewhere, or refused, the writes fault page by
/// page as before). One request per 256 KiB instead of a fault per 4 KiB page: 512 MB of
/// fresh memory zeroed in 0.13–0.16 instead of 0.23–0.24 s on one core of the Intel VM
/// (`benches/fresh_pages.c`, its last two lines).
fn write_zeros(chunk: &mut [MaybeUninit<f64>]) {
    populate_for_write(chunk);
    chunk.fill(MaybeUninit::new(0.0));
}

#[cfg(target_os = "linux")]
fn populate_for_write<T>(chunk: &mut [T]) {
    const PAGE: usize = 4096;
    let start = chunk.as_mut_ptr() as usize;
    let end = start + std::mem::size_of_val(chunk);
    let (first, last) = (start.next_multiple_of(PAGE), end / PAGE * PAGE);
    if last > first {
        // SAFETY: [first, last) lies within `chunk`, memory this thread borrows exclusively;
        // the request maps its pages and changes no byte of it. The result is ignored: a
        // refusal (an older kernel) leaves the pages to fault at the writes that follow.
        unsafe {
            libc::madvise(
                first as *mut libc::c_void,
                last - first,
                libc::MADV_POPULATE_WRITE,
            );
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn populate_for_write<T>(_chunk: &mut [T]) {}

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
        // The same on the calling thread.
        let mut w = vec![1.0, 2.0];
        extend_with_zeros(&mut w, 3 * CHUNK + 7);
        assert_eq!(w, v);
    }

    /// Mapping the pages changes no value: written values over several chunks (page-aligned
    /// and not) stay, and fresh zeros stay zeros.
    #[test]
    fn populating_keeps_every_value() {
        let n = 5 * CHUNK + 3;
        let mut v: Vec<u64> = (0..n as u64).map(|i| i.wrapping_mul(0x9E37_79B9)).collect();
        let expected = v.clone();
        populate_par(&mut v);
        populate_par(&mut v[7..]);
        assert_eq!(v, expected);
        let mut z = vec![0usize; n];
        populate_par(&mut z);
        assert!(z.iter().all(|&x| x == 0));
    }
}
