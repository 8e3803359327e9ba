//! CPU time of this process's threads, for benchmarks run on a shared machine.

/// CPU time on a core and time waiting in the run queue (ns), summed over the threads
/// of this process (Linux `/proc/self/task/*/schedstat`); `None` elsewhere. The wait
/// shows how much of a wall time the machine's other load took.
pub fn sched_ns() -> Option<(u64, u64)> {
    let mut on = 0u64;
    let mut wait = 0u64;
    for t in std::fs::read_dir("/proc/self/task").ok()? {
        let s = std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok()?;
        let mut f = s.split_whitespace().map(|v| v.parse::<u64>().unwrap_or(0));
        on += f.next()?;
        wait += f.next()?;
    }
    Some((on, wait))
}
