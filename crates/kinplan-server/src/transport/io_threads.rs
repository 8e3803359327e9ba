//! Thread-per-core serving. The listener is accepted on the caller's runtime
//! and each connection is handed, round robin, to one of several I/O threads;
//! each I/O thread runs its own single-threaded tokio runtime with its own copy
//! of the tonic server, and every stream of a connection is handled there.
//!
//! Why not one multi-threaded runtime: hyper runs each call as its own task and
//! wakes the connection's task to write the reply. The multi-threaded scheduler
//! runs a task woken by the running one next (its "LIFO slot"), so every reply
//! was written by its own `writev` even when several calls of the connection
//! finished together; on loopback each `writev` also pays the receiver's TCP
//! processing. A single-threaded runtime queues the woken connection task behind
//! the calls already queued, so the replies of one read are written together:
//! one `writev` per read instead of one per call (the server CPU per call
//! before and after is in `benches/RESULTS.md`). The CPU pool is unchanged:
//! work that is not tiny still runs there and never on these threads.

use std::future::Future;
use std::pin::Pin;

use tokio::sync::{mpsc, oneshot, watch};
use tokio_stream::StreamExt;
use tokio_stream::wrappers::UnboundedReceiverStream;

type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// The connections one I/O thread serves, registered with its runtime as they
/// are taken from the queue.
pub(crate) type Connections = tokio_stream::adapters::Map<
    UnboundedReceiverStream<std::net::TcpStream>,
    fn(std::net::TcpStream) -> std::io::Result<tokio::net::TcpStream>,
>;

/// Resolves when the I/O threads must stop accepting and drain.
pub(crate) type StopSignal = Pin<Box<dyn Future<Output = ()> + Send>>;

/// Serves one thread's connections until the stop signal, then drains them
/// (a tonic server's `serve_with_incoming_shutdown`).
pub(crate) type ServeFn = dyn Fn(Connections, StopSignal) -> Pin<Box<dyn Future<Output = Result<(), tonic::transport::Error>>>>
    + Send
    + Sync;

/// The running I/O threads. Dropping this (e.g. when `serve`'s future is
/// dropped) ends every thread at once, connections included.
pub(crate) struct IoThreads {
    queues: Vec<mpsc::UnboundedSender<std::net::TcpStream>>,
    next: usize,
    stop: watch::Sender<bool>,
    results: mpsc::UnboundedReceiver<Result<(), BoxError>>,
    running: usize,
    /// Dropped with `self`: each thread's runtime then returns and is dropped.
    _kill: Vec<oneshot::Sender<()>>,
}

/// I/O threads to start for `requested` (0: one per core).
pub(crate) fn thread_count(requested: usize) -> usize {
    if requested > 0 {
        requested
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }
}

impl IoThreads {
    /// Starts `threads` I/O threads, each serving with `serve`.
    pub(crate) fn start(threads: usize, serve: std::sync::Arc<ServeFn>) -> Result<IoThreads, BoxError> {
        let (stop, _) = watch::channel(false);
        let (results_tx, results) = mpsc::unbounded_channel();
        let mut queues = Vec::with_capacity(threads);
        let mut kill = Vec::with_capacity(threads);
        for i in 0..threads.max(1) {
            // Built here, so a runtime that cannot start fails `serve` at once.
            let runtime = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()?;
            let (queue, receiver) = mpsc::unbounded_channel::<std::net::TcpStream>();
            let (kill_tx, kill_rx) = oneshot::channel::<()>();
            let mut stop_rx = stop.subscribe();
            let serve = serve.clone();
            let results_tx = results_tx.clone();
            std::thread::Builder::new()
                .name(format!("kinplan-io-{i}"))
                .spawn(move || {
                    let register: fn(std::net::TcpStream) -> std::io::Result<tokio::net::TcpStream> =
                        tokio::net::TcpStream::from_std;
                    let connections = UnboundedReceiverStream::new(receiver).map(register);
                    let signal: StopSignal = Box::pin(async move {
                        // An error: `IoThreads` is gone, so stop as well.
                        let _ = stop_rx.wait_for(|stop| *stop).await;
                    });
                    let result = runtime.block_on(async move {
                        tokio::select! {
                            served = serve(connections, signal) => served.map_err(BoxError::from),
                            _ = kill_rx => Ok(()),
                        }
                    });
                    drop(runtime);
                    let _ = results_tx.send(result);
                })?;
            queues.push(queue);
            kill.push(kill_tx);
        }
        Ok(IoThreads {
            running: queues.len(),
            queues,
            next: 0,
            stop,
            results,
            _kill: kill,
        })
    }

    /// Hands an accepted connection to the next thread (round robin).
    pub(crate) fn dispatch(&mut self, connection: tokio::net::TcpStream) {
        // Deregistered from this runtime; the I/O thread registers it with its own.
        let Ok(connection) = connection.into_std() else {
            tracing::debug!("an accepted connection could not be handed over; dropped");
            return;
        };
        let i = self.next % self.queues.len();
        self.next = self.next.wrapping_add(1);
        if self.queues[i].send(connection).is_err() {
            tracing::warn!(thread = i, "an I/O thread has stopped; connection dropped");
        }
    }

    /// Tells every thread to stop accepting and to drain its connections.
    pub(crate) fn stop(&self) {
        let _ = self.stop.send(true);
    }

    /// Resolves with the first error of a thread, or `Ok` once all have finished.
    pub(crate) async fn finished(&mut self) -> Result<(), BoxError> {
        while self.running > 0 {
            match self.results.recv().await {
                Some(Ok(())) => self.running -= 1,
                Some(Err(e)) => return Err(e),
                None => return Err("an I/O thread ended without a result".into()),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{Arc, Mutex};

    /// Counts the server futures dropped.
    struct CountDrop(Arc<AtomicUsize>);

    impl Drop for CountDrop {
        fn drop(&mut self) {
            self.0.fetch_add(1, Ordering::SeqCst);
        }
    }

    /// A stand-in server: records which thread each connection reached, ends
    /// Ok at the stop signal, and counts its futures dropped.
    fn recording(seen: Arc<Mutex<Vec<String>>>, dropped: Arc<AtomicUsize>) -> Arc<ServeFn> {
        Arc::new(move |mut connections: Connections, stop: StopSignal| {
            let seen = seen.clone();
            let guard = CountDrop(dropped.clone());
            Box::pin(async move {
                let _guard = guard;
                tokio::pin!(stop);
                loop {
                    tokio::select! {
                        () = &mut stop => return Ok(()),
                        next = connections.next() => match next {
                            Some(Ok(_)) => seen.lock().unwrap().push(
                                std::thread::current().name().unwrap_or("?").to_string(),
                            ),
                            _ => return Ok(()),
                        },
                    }
                }
            })
        })
    }

    async fn connection(listener: &tokio::net::TcpListener) -> tokio::net::TcpStream {
        let addr = listener.local_addr().unwrap();
        let (_client, accepted) = tokio::join!(tokio::net::TcpStream::connect(addr), listener.accept());
        accepted.unwrap().0
    }

    #[tokio::test]
    async fn connections_go_round_robin_and_stop_ends_every_thread() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let dropped = Arc::new(AtomicUsize::new(0));
        let mut threads = IoThreads::start(2, recording(seen.clone(), dropped.clone())).unwrap();
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
        for _ in 0..4 {
            threads.dispatch(connection(&listener).await);
        }
        let started = std::time::Instant::now();
        while seen.lock().unwrap().len() < 4 && started.elapsed().as_secs() < 10 {
            tokio::time::sleep(std::time::Duration::from_millis(5)).await;
        }
        let mut names = seen.lock().unwrap().clone();
        names.sort();
        assert_eq!(
            names,
            ["kinplan-io-0", "kinplan-io-0", "kinplan-io-1", "kinplan-io-1"]
        );
        threads.stop();
        threads.finished().await.unwrap();
        assert_eq!(dropped.load(Ordering::SeqCst), 2);
    }

    #[tokio::test]
    async fn dropping_the_threads_ends_servers_that_never_stop() {
        let dropped = Arc::new(AtomicUsize::new(0));
        let never: Arc<ServeFn> = {
            let dropped = dropped.clone();
            Arc::new(move |_connections: Connections, _stop: StopSignal| {
                let guard = CountDrop(dropped.clone());
                Box::pin(async move {
                    let _guard = guard;
                    std::future::pending::<()>().await;
                    Ok(())
                })
            })
        };
        let threads = IoThreads::start(3, never).unwrap();
        drop(threads);
        let started = std::time::Instant::now();
        while dropped.load(Ordering::SeqCst) < 3 && started.elapsed().as_secs() < 10 {
            tokio::time::sleep(std::time::Duration::from_millis(5)).await;
        }
        assert_eq!(dropped.load(Ordering::SeqCst), 3);
    }
}
