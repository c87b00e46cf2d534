//! `release_free_memory` returns what the allocator kept of freed heap blocks (its own process:
//! no other test allocates meanwhile).

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn resident_kib() -> usize {
    let status = std::fs::read_to_string("/proc/self/status").expect("procfs");
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("VmRSS in /proc/self/status")
}

/// 256 MiB in 64 KiB blocks (below glibc's mmap threshold, so on the heap), written, each
/// followed by a small block that stays: freed, the large ones are holes between live blocks
/// (as a parse leaves them), which glibc keeps resident — its automatic trim returns only the
/// heap's top — until the call, which must give back at least half.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[test]
fn freed_heap_blocks_go_back_to_the_system() {
    const BLOCK: usize = 64 << 10;
    const BLOCKS: usize = 4096;
    let (mut blocks, keep): (Vec<Vec<u8>>, Vec<Vec<u8>>) = (0..BLOCKS)
        .map(|i| (vec![(i % 251) as u8 + 1; BLOCK], vec![7u8; 64]))
        .unzip();
    let checksum: usize = blocks.iter().map(|b| b[BLOCK / 2] as usize).sum();
    assert!(checksum > BLOCKS);
    blocks.clear();
    blocks.shrink_to_fit();
    let before = resident_kib();
    fibercell::free_memory::release_free_memory();
    let after = resident_kib();
    assert!(keep.iter().all(|k| k[63] == 7));
    let freed = (BLOCKS * BLOCK) >> 10;
    assert!(
        before >= after + freed / 2,
        "resident {before} KiB before, {after} KiB after; {freed} KiB were freed"
    );
}
