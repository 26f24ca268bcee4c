//! The program's allocator: mimalloc instead of the system's.
//!
//! A fit allocates a record-long vector (about 1 MB at 150 001 samples) for nearly every
//! evaluation — residuals, a part's contribution, a difference column — and frees it soon
//! after. glibc's malloc serves blocks that large from fresh mappings or trims them back to
//! the system, so every evaluation touched new pages: a force-level discovery of the paper's
//! sweep with one hidden effect took 368 000–438 000 page faults and 11.0–11.2 CPU-seconds.
//! mimalloc keeps freed pages for the next block: 14 000–15 000 page faults, 10.5 CPU-seconds,
//! wall 5.89–6.07 → 5.69–5.74 s (two runs each, alternating). glibc's own tunables
//! (`mmap_threshold` 32 MB, `trim_threshold` at its maximum, set by the environment for the
//! measurement) did as well, 53 000 page faults and 5.68 s, but only on glibc and through an
//! `unsafe` call to `mallopt`; mimalloc is the same on every platform. The library crates
//! leave the allocator to whoever links them (the Python module keeps Python's).

/// The global allocator of the `stf-lab` program.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;
