//! glibc's malloc tuned once at the start of the program (the CLI's and the benchmarks' `main`
//! only: the library, its C API and the FMU leave the allocator to their host). The set-up's
//! transient buffers (the CalculiX text, Lanczos blocks of n × 4, faer's scratch) are megabytes:
//! by default glibc maps each with mmap and returns it on free (or trims the heap top), so every
//! stage touches fresh pages again; page faults were 0.5–1.7 s of system CPU per set-up of the
//! real blade (validation/RECORD.md "Real-blade benchmark", set-up round 3). Keeping freed memory in the heap
//! costs peak RSS (≈ 320 → 460 MB there) and saves those faults.

/// Serves every allocation below 2 GiB from the heap and never trims it (mallopt(3):
/// M_TRIM_THRESHOLD = −1, M_MMAP_THRESHOLD = −3). Returns whether glibc accepted both.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn keep_freed_memory() -> bool {
    unsafe extern "C" {
        fn mallopt(param: i32, value: i32) -> i32;
    }
    const M_TRIM_THRESHOLD: i32 = -1;
    const M_MMAP_THRESHOLD: i32 = -3;
    // SAFETY: mallopt only changes glibc's allocation thresholds; called before any thread starts.
    unsafe { mallopt(M_MMAP_THRESHOLD, i32::MAX) == 1 && mallopt(M_TRIM_THRESHOLD, i32::MAX) == 1 }
}

/// Other platforms keep their allocator's defaults.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn keep_freed_memory() -> bool {
    false
}
