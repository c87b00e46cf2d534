//! Handing freed heap memory back to the operating system after a phase that allocates much
//! and keeps little (a model file's parse, an analysis).
//!
//! glibc's allocator keeps freed small and medium blocks in its arenas, resident, for later
//! allocations; the large structures of a run (factor values, the low-rank correction's S)
//! are allocated by `mmap` instead and never reuse them, so what a parse or an ordering
//! freed can stay in the process's peak to its end. `malloc_trim` returns those pages: after
//! reading the L non-woven's 16 MB TOML file 224 MB are resident of which 21 MB are live, and
//! with a trim there and after the analysis its curve's base is 43,412 KiB lower (2,629,728
//! against 2,673,140 KiB at increment 8: later allocations reuse most of the rest).
//!
//! Called by [`crate::io::load_model`] and after a stick/slip run's analysis; a program that
//! embeds the library may call it after its own set-up.

/// Returns the allocator's free pages to the operating system (glibc's `malloc_trim`; nothing
/// on other C libraries). Costs a walk of the free lists: milliseconds.
pub fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns unused pages of the allocator's own arenas; it reads
    // no caller memory and is thread-safe (it takes each arena's lock).
    unsafe {
        libc::malloc_trim(0);
    }
}
