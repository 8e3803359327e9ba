//! Admission control and the CPU pool. Every request takes an admission
//! permit (or is shed with RESOURCE_EXHAUSTED); long computations run on a
//! dedicated rayon pool, never on the async runtime, and see the request's
//! deadline and cancellation through a [`Budget`] (its
//! [`Budget::deadline`] is what the domain polls).

use std::future::Future;
use std::panic::AssertUnwindSafe;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use tokio::sync::{OwnedSemaphorePermit, Semaphore, oneshot};
use tonic::Status;

pub use super::deadline::Budget;
use super::deadline::{RequestDeadline, call_deadline, grpc_timeout};

/// Raises the cancellation flag if the request's future is dropped (caller
/// gone, deadline) before the work's answer arrived; disarmed on completion so
/// the budget stays usable for the request's next computation.
struct CancelOnDrop {
    flag: Arc<AtomicBool>,
    armed: bool,
}

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if self.armed {
            self.flag.store(true, Ordering::Relaxed);
        }
    }
}

/// Stack of each CPU-pool thread, bytes.
pub const CPU_STACK_BYTES: usize = 8 * 1024 * 1024;

/// The server's CPU pool and admission limit.
pub struct Compute {
    pool: rayon::ThreadPool,
    admitted: Arc<Semaphore>,
    limit: usize,
    default_timeout: Option<Duration>,
    /// Open `StreamIk` streams (each message's work is admitted separately).
    streams: Arc<Semaphore>,
    /// How long a stream may stay silent.
    pub stream_idle_timeout: Duration,
    /// Jobs running on the pool now (tests read it to see work stop).
    running: Arc<AtomicUsize>,
    /// Run work on the calling thread, not the pool (`ServerConfig::inline_compute`).
    pub inline: bool,
}

/// Counts a job while it runs.
struct Running(Arc<AtomicUsize>);

impl Running {
    fn start(counter: &Arc<AtomicUsize>) -> Self {
        counter.fetch_add(1, Ordering::SeqCst);
        Self(counter.clone())
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The answer to a call shed because every admission slot is taken.
pub fn shed_status() -> Status {
    Status::resource_exhausted("server busy: every request slot is taken; retry with backoff")
}

impl Compute {
    /// `threads` workers (0: one per core) at nice [`super::priority::CPU_POOL_NICE`],
    /// at most `concurrency` requests in the server at once, `default_timeout`
    /// for requests without a deadline.
    pub fn new(threads: usize, concurrency: usize, default_timeout: Option<Duration>) -> Self {
        Self::with_nice(
            threads,
            concurrency,
            default_timeout,
            super::priority::CPU_POOL_NICE,
        )
    }

    /// Like [`Compute::new`], the pool's threads at nice value `nice` (0–19).
    pub fn with_nice(
        threads: usize,
        concurrency: usize,
        default_timeout: Option<Duration>,
        nice: i32,
    ) -> Self {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("kinplan-cpu-{i}"))
            // Explicit, so recursion depth never depends on the platform default.
            .stack_size(CPU_STACK_BYTES)
            // below the runtime's threads: admission and health stay prompt when every core computes
            .start_handler(move |_| super::priority::lower_this_thread(nice))
            .build()
            .expect("the CPU pool starts");
        let limit = concurrency.max(1);
        Self {
            pool,
            admitted: Arc::new(Semaphore::new(limit)),
            limit,
            default_timeout,
            streams: Arc::new(Semaphore::new(limit)),
            stream_idle_timeout: Duration::from_secs(60),
            running: Arc::new(AtomicUsize::new(0)),
            inline: false,
        }
    }

    /// Counts running jobs in `counter` (shared with whoever watches it).
    pub fn with_running_counter(mut self, counter: Arc<AtomicUsize>) -> Self {
        self.running = counter;
        self
    }

    /// Jobs running on the CPU pool now.
    pub fn running_jobs(&self) -> usize {
        self.running.load(Ordering::SeqCst)
    }

    /// Admits a new stream (at most the concurrency limit open at once); its
    /// messages' work is admitted one by one with [`Compute::admit_work`].
    pub fn admit_stream(&self) -> Result<OwnedSemaphorePermit, Status> {
        self.streams.clone().try_acquire_owned().map_err(|_| {
            metrics::counter!("kinplan_requests_shed_total").increment(1);
            Status::resource_exhausted(format!(
                "server busy: {} streams open; retry with backoff",
                self.limit
            ))
        })
    }

    /// Admits one piece of work (a stream message) or sheds it.
    pub fn admit_work(&self) -> Result<OwnedSemaphorePermit, Status> {
        self.admitted.clone().try_acquire_owned().map_err(|_| {
            metrics::counter!("kinplan_requests_shed_total").increment(1);
            shed_status()
        })
    }

    /// True while every admission permit is taken: a new call would be shed.
    pub fn saturated(&self) -> bool {
        self.admitted.available_permits() == 0
    }

    /// Admits a request or sheds it; the permit is held until the reply.
    /// An admitted request's numbers are range-checked
    /// ([`super::request_numbers`]) before any work.
    pub fn admit<T: prost::Message>(
        &self,
        request: &tonic::Request<T>,
    ) -> Result<(OwnedSemaphorePermit, Budget), Status> {
        let permit = self.admit_work()?;
        super::request_numbers::check_request(request.get_ref())?;
        Ok((permit, Budget::new(self.deadline_of(request))))
    }

    /// The request's deadline: the one the guard layer set, or (outside a
    /// server) the shorter of `grpc-timeout` and the default, from now. Never
    /// overflows: a timeout too large for `Instant` means no deadline.
    pub fn deadline_of<T>(&self, request: &tonic::Request<T>) -> Option<Instant> {
        if let Some(RequestDeadline(deadline)) = request.extensions().get::<RequestDeadline>() {
            return *deadline;
        }
        let header = grpc_timeout(request.metadata().as_ref());
        call_deadline(header, self.default_timeout)
    }

    /// Runs `work` on the CPU pool. Answers DEADLINE_EXCEEDED when the
    /// deadline passes first (the work polls [`Budget::deadline`] and ends early)
    /// and INTERNAL if the work panics.
    pub async fn run<T, F>(&self, budget: &Budget, work: F) -> Result<T, Status>
    where
        T: Send + 'static,
        F: FnOnce(&Budget) -> T + Send + 'static,
    {
        if budget.expired() {
            return Err(deadline_exceeded());
        }
        if self.inline {
            let _running = Running::start(&self.running);
            // outside the runtime's context, so work that feeds a stream
            // with blocking sends may run here too
            let out =
                tokio::task::block_in_place(|| std::panic::catch_unwind(AssertUnwindSafe(|| work(budget))));
            return out.map_err(|_panic| {
                tracing::error!("a computation panicked");
                Status::internal("the computation failed unexpectedly")
            });
        }
        let mut cancel_on_drop = CancelOnDrop {
            flag: budget.cancel_flag().clone(),
            armed: true,
        };
        let (tx, rx) = oneshot::channel();
        let inner = budget.clone();
        let running = self.running.clone();
        self.pool.spawn(move || {
            if inner.expired() {
                return;
            }
            let _running = Running::start(&running);
            let out = std::panic::catch_unwind(AssertUnwindSafe(|| work(&inner)));
            let _ = tx.send(out);
        });
        let received = match budget.call_deadline() {
            Some(deadline) => tokio::time::timeout_at(deadline.into(), rx)
                .await
                .map_err(|_| deadline_exceeded())?,
            None => rx.await,
        };
        cancel_on_drop.armed = false;
        match received {
            Ok(Ok(value)) => Ok(value),
            Ok(Err(_panic)) => {
                tracing::error!("a computation panicked");
                Err(Status::internal("the computation failed unexpectedly"))
            }
            Err(_dropped) => Err(deadline_exceeded()),
        }
    }
}

fn deadline_exceeded() -> Status {
    Status::deadline_exceeded("the request's deadline passed before the work finished")
}

/// `future`, with a panic while polling it returned as `Err`.
pub fn catch_unwind<F: Future>(
    future: F,
) -> impl Future<Output = Result<F::Output, Box<dyn std::any::Any + Send>>> {
    CatchUnwind(Box::pin(future))
}

/// Polls a future inside `catch_unwind`.
struct CatchUnwind<F>(Pin<Box<F>>);

impl<F: Future> Future for CatchUnwind<F> {
    type Output = Result<F::Output, Box<dyn std::any::Any + Send>>;
    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let inner = self.0.as_mut();
        match std::panic::catch_unwind(AssertUnwindSafe(|| inner.poll(cx))) {
            Ok(Poll::Pending) => Poll::Pending,
            Ok(Poll::Ready(v)) => Poll::Ready(Ok(v)),
            Err(panic) => Poll::Ready(Err(panic)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: the legal-looking maximum `grpc-timeout` overflowed
    /// `Instant` arithmetic; it means no deadline, unless the server has a default.
    #[test]
    fn a_timeout_too_large_for_instant_is_no_deadline() {
        let compute = Compute::new(1, 1, None);
        let mut req = tonic::Request::new(());
        req.metadata_mut()
            .insert("grpc-timeout", "18446744073709551615S".parse().unwrap());
        assert_eq!(compute.deadline_of(&req), None);
        let compute = Compute::new(1, 1, Some(Duration::from_secs(1)));
        assert!(compute.deadline_of(&req).is_some());
    }

    #[cfg(target_os = "linux")]
    #[tokio::test]
    async fn pool_threads_run_at_the_nice_value_given() {
        let nice_of_this_thread =
            || unsafe { libc::getpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t) };
        // Pool threads start at this thread's nice; from 0 every value is a lowering.
        if nice_of_this_thread() != 0 {
            return;
        }
        for nice in [0, 3, 10, 19] {
            let compute = Compute::with_nice(1, 1, None, nice);
            let seen = compute
                .run(&Budget::new(None), move |_| nice_of_this_thread())
                .await
                .unwrap();
            assert_eq!(seen, nice);
        }
        let clamped = Compute::with_nice(1, 1, None, 40);
        let seen = clamped
            .run(&Budget::new(None), move |_| nice_of_this_thread())
            .await
            .unwrap();
        assert_eq!(seen, 19);
    }

    #[tokio::test]
    async fn shed_when_full_and_deadline_stops_work() {
        let compute = Compute::new(1, 1, None);
        let req = tonic::Request::new(());
        let (permit, _) = compute.admit(&req).unwrap();
        let err = compute.admit(&req).unwrap_err();
        assert_eq!(err.code(), tonic::Code::ResourceExhausted);
        drop(permit);
        let budget = Budget::new(Some(Instant::now() + Duration::from_millis(50)));
        let started = Instant::now();
        let result = compute
            .run(&budget, |b| {
                while !b.deadline().expired() {
                    std::hint::spin_loop();
                }
                1
            })
            .await;
        // Either the work saw the deadline and returned, or the timer fired.
        assert!(result.is_ok() || result.unwrap_err().code() == tonic::Code::DeadlineExceeded);
        assert!(started.elapsed() < Duration::from_secs(2));
        // A finished run leaves the budget usable for the next one.
        let reused = Budget::new(None);
        assert_eq!(compute.run(&reused, |_| 1).await.unwrap(), 1);
        assert!(!reused.expired());
        assert_eq!(compute.run(&reused, |_| 2).await.unwrap(), 2);
        let panicking = compute
            .run(&Budget::new(None), |_| -> i32 { panic!("boom") })
            .await;
        assert_eq!(panicking.unwrap_err().code(), tonic::Code::Internal);
    }
}
