//! The CPU pool's threads run at a lower scheduling priority than the async
//! runtime's: when every core is busy computing, the threads that accept
//! connections, shed excess calls with RESOURCE_EXHAUSTED and answer health
//! checks still get a core at once instead of waiting for a pool thread's time
//! slice. Throughput is unchanged
//! when the runtime is idle: a nice value only matters under contention.
//!
//! The same nice value also weighs the pool against other processes at nice
//! 0 on the host: with nice 10 they get about 9× a pool thread's share, which
//! lengthens computed calls' tails on a host shared with other work (not in a
//! container, whose threads compete among themselves). `--cpu-nice 0` trades
//! the prompt admission for that (both are measured in `benches/RESULTS.md`).

/// Default nice value of the pool threads (0 is the default, 19 the lowest priority).
pub const CPU_POOL_NICE: i32 = 10;

/// Sets the calling thread's nice value to `nice` (clamped to 0–19). Linux
/// keeps a nice value per thread, so the rest of the process is untouched;
/// elsewhere (and if the call fails) the thread keeps its priority.
pub fn lower_this_thread(nice: i32) {
    #[cfg(not(target_os = "linux"))]
    let _ = nice;
    #[cfg(target_os = "linux")]
    {
        // SAFETY: gettid and setpriority take and return plain integers and
        // touch no memory of ours; who = this thread's id (Linux: per-thread nice).
        let result = unsafe {
            let tid = libc::gettid();
            libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, nice.clamp(0, 19))
        };
        if result != 0 {
            tracing::debug!("could not lower a CPU pool thread's priority");
        }
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn only_the_calling_thread_is_lowered() {
        let nice_of = |tid: libc::pid_t| unsafe { libc::getpriority(libc::PRIO_PROCESS, tid as libc::id_t) };
        let main_tid = unsafe { libc::gettid() };
        let before = nice_of(main_tid);
        let lowered = std::thread::spawn(|| {
            lower_this_thread(CPU_POOL_NICE);
            unsafe { libc::getpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t) }
        })
        .join()
        .unwrap();
        assert_eq!(
            lowered,
            CPU_POOL_NICE.max(before),
            "the pool thread runs at nice {CPU_POOL_NICE}"
        );
        assert_eq!(nice_of(main_tid), before, "the other threads keep theirs");
    }
}
