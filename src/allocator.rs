//! The program's allocator: mimalloc instead of the system's, told to keep what is freed.
//!
//! A fit allocates a record-long vector (about 1 MB at 150 001 samples) for nearly every
//! evaluation — residuals, a part's contribution, a difference column — and frees it soon
//! after. glibc's malloc serves blocks that large from fresh mappings or trims them back to
//! the system, so every evaluation touched new pages: a force-level discovery of the paper's
//! sweep with one hidden effect took 368 000–438 000 page faults and 11.0–11.2 CPU-seconds.
//! mimalloc keeps freed pages for the next block: 14 000–22 000 page faults, 10.5 CPU-seconds,
//! wall 5.89–6.07 → 5.69–5.74 s (two runs each, alternating). glibc's own tunables
//! (`mmap_threshold` 32 MB, `trim_threshold` at its maximum, set by the environment for the
//! measurement) did as well, 53 000 page faults and 5.68 s, but only on glibc and through an
//! `unsafe` call to `mallopt`; mimalloc is the same on every platform.
//!
//! mimalloc still hands memory unused for a while back to the system ("purges" it), and the
//! kernel clears each page taken again: 4–5 % of that discovery's samples. The program never
//! purges ([`keep_freed_memory`]): 470 page faults instead of 13 000–15 000, 8.56–8.73
//! CPU-seconds against 8.74–9.07, wall 4.62–4.73 s against 4.74–4.90 s (three runs each,
//! alternating), peak memory 205 MB against 191 MB. What a run has freed stays the process's
//! until it ends. The library crates leave the allocator to whoever links them (the Python
//! module keeps Python's).

/// The global allocator of the `stf-lab` program.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// mimalloc's `mi_option_purge_delay`: its place in the C header's `mi_option_e` (the same in
/// mimalloc 2 and 3; libmimalloc-sys names the options around it, 14 and 16, but not it).
const PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Tell mimalloc never to purge: freed memory is kept for the next allocation instead of
/// being returned to the system and taken again (cleared by the kernel) later.
pub fn keep_freed_memory() {
    // SAFETY: `mi_option_set` stores a value in mimalloc's option table, which it reads
    // atomically; any option below `_mi_option_last` may be set at any time, and -1 is the
    // purge delay's documented "never".
    unsafe { libmimalloc_sys::mi_option_set(PURGE_DELAY, -1) }
}
