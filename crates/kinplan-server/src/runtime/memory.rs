//! The process's memory settings.
//!
//! The allocator (mimalloc) asks the kernel for transparent huge pages on
//! its arenas (`madvise(MADV_HUGEPAGE)`). Where the host allows them on
//! request (`/sys/kernel/mm/transparent_hugepage/enabled` = `madvise`, a
//! common default), the first touch of each 2 MiB page zeroes all of it,
//! and may compact memory first (`defrag` = `madvise`), inside whichever
//! call touched it, such as a robot's first collision check, which fills
//! fresh memory (measured in `benches/RESULTS.md`). The server turns them
//! off for itself unless told otherwise.

/// Turns transparent huge pages off for this process (Linux
/// `PR_SET_THP_DISABLE`: every later page fault gets a base page, whatever
/// the allocator advised). Returns whether they are now off; elsewhere, and
/// if the call fails, nothing changes.
pub fn disable_transparent_huge_pages() -> bool {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: prctl with PR_SET_THP_DISABLE takes plain integers and
        // touches no memory of ours.
        let result = unsafe { libc::prctl(libc::PR_SET_THP_DISABLE, 1, 0, 0, 0) };
        if result != 0 {
            tracing::debug!("could not turn transparent huge pages off");
        }
        result == 0
    }
    #[cfg(not(target_os = "linux"))]
    false
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_reports_huge_pages_off_after_the_call() {
        assert!(disable_transparent_huge_pages());
        // SAFETY: as above; PR_GET_THP_DISABLE returns the flag.
        let flag = unsafe { libc::prctl(libc::PR_GET_THP_DISABLE, 0, 0, 0, 0) };
        assert_eq!(flag, 1);
    }
}
