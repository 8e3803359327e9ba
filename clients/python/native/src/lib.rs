//! `kinplan_native`: the kinplan services for Python without a network hop.
//!
//! - `Backend`: the services in this process (`kinplan_server::InProcess`):
//!   encoded protobuf request in, encoded response out, streams included. The
//!   `kinplan` package wraps it as a gRPC channel, so `kinplan.Client.local()`
//!   has the whole client API.
//! - `serve`: a real gRPC server (the one `kinplan serve` runs) on a thread of
//!   this process, so a notebook gets a server from `pip install` alone.
//!
//! A failed call raises `CallError(code, message, details)`: the gRPC status
//! code as an int, its message, and the encoded `google.rpc.Status` details.

use std::net::TcpListener;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use bytes::Bytes;
use kinplan_server::{InProcess, ResponseStream, ServerConfig, serve};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use tokio::runtime::Runtime;
use tokio::sync::mpsc;

create_exception!(
    kinplan_native,
    CallError,
    PyException,
    "A call's non-OK gRPC status: (code, message, details)."
);

fn call_error(status: tonic::Status) -> PyErr {
    CallError::new_err((
        status.code() as i32,
        status.message().to_owned(),
        status.details().to_vec(),
    ))
}

/// A finite, positive timeout in seconds.
fn timeout(seconds: Option<f64>) -> PyResult<Option<Duration>> {
    seconds
        .map(|s| {
            Duration::try_from_secs_f64(s)
                .ok()
                .filter(|d| !d.is_zero())
                .ok_or_else(|| {
                    PyValueError::new_err(format!("timeout: {s} is not a finite number of seconds > 0"))
                })
        })
        .transpose()
}

fn config(cpu_threads: usize, acm_samples: usize) -> ServerConfig {
    ServerConfig {
        cpu_threads,
        acm_samples,
        ..ServerConfig::default()
    }
}

/// The in-process backend's: each computation runs on the calling Python
/// thread (which waits for it with the GIL released) instead of handing it
/// to the CPU pool and back.
fn inline_config(cpu_threads: usize, acm_samples: usize) -> ServerConfig {
    ServerConfig {
        inline_compute: true,
        ..config(cpu_threads, acm_samples)
    }
}

/// The kinplan services in this process.
#[pyclass(frozen)]
struct Backend {
    runtime: Arc<Runtime>,
    services: Arc<InProcess>,
}

#[pymethods]
impl Backend {
    /// `cpu_threads`: the CPU pool (0: one per core); `acm_samples`: random
    /// states per robot for its allowed-collision matrix (MoveIt's 10,000).
    #[new]
    #[pyo3(signature = (cpu_threads = 0, acm_samples = 10_000))]
    fn new(cpu_threads: usize, acm_samples: usize) -> PyResult<Self> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .thread_name("kinplan-local")
            .enable_all()
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("tokio runtime: {e}")))?;
        let services = {
            let _inside = runtime.enter();
            InProcess::new(&inline_config(cpu_threads, acm_samples))
        };
        Ok(Backend {
            runtime: Arc::new(runtime),
            services: Arc::new(services),
        })
    }

    /// A unary call: `path` "/kinplan.v1.RobotService/ForwardKinematics",
    /// `request` the encoded message; returns the encoded answer.
    #[pyo3(signature = (path, request, timeout = None))]
    fn unary<'py>(
        &self,
        py: Python<'py>,
        path: &str,
        request: &[u8],
        timeout: Option<f64>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let timeout = self::timeout(timeout)?;
        let answer = py.detach(|| self.runtime.block_on(self.services.unary(path, request, timeout)));
        answer.map(|bytes| PyBytes::new(py, &bytes)).map_err(call_error)
    }

    /// Starts a bidirectional (or client-streamed) call; send requests and
    /// read answers on the result.
    #[pyo3(signature = (path, timeout = None))]
    fn stream(&self, path: &str, timeout: Option<f64>) -> PyResult<Stream> {
        let timeout = self::timeout(timeout)?;
        let (sender, answers) = {
            let _inside = self.runtime.enter();
            self.services.stream(path, timeout)
        };
        Ok(Stream {
            runtime: self.runtime.clone(),
            sender: Mutex::new(Some(sender)),
            answers: Arc::new(tokio::sync::Mutex::new(answers)),
        })
    }

    /// Starts a server-streamed call with its one request; read the answers
    /// on the result.
    #[pyo3(signature = (path, request, timeout = None))]
    fn server_stream(
        &self,
        py: Python<'_>,
        path: &str,
        request: &[u8],
        timeout: Option<f64>,
    ) -> PyResult<Stream> {
        let timeout = self::timeout(timeout)?;
        let started = py.detach(|| {
            self.runtime
                .block_on(self.services.server_stream(path, request, timeout))
        });
        Ok(Stream {
            runtime: self.runtime.clone(),
            sender: Mutex::new(None),
            answers: Arc::new(tokio::sync::Mutex::new(started.map_err(call_error)?)),
        })
    }
}

/// An open streaming call.
#[pyclass(frozen)]
struct Stream {
    runtime: Arc<Runtime>,
    sender: Mutex<Option<mpsc::Sender<Bytes>>>,
    answers: Arc<tokio::sync::Mutex<ResponseStream>>,
}

#[pymethods]
impl Stream {
    /// Sends one encoded request; false when the call has already ended.
    fn send(&self, py: Python<'_>, request: &[u8]) -> bool {
        let sender = self.sender.lock().ok().and_then(|s| s.clone());
        let Some(sender) = sender else { return false };
        let message = Bytes::copy_from_slice(request);
        py.detach(|| sender.blocking_send(message).is_ok())
    }

    /// Ends the request side (the server then ends the call).
    fn close(&self) {
        if let Ok(mut sender) = self.sender.lock() {
            sender.take();
        }
    }

    /// The next encoded answer, or None after the last one.
    fn recv<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyBytes>>> {
        let answers = self.answers.clone();
        let next = py.detach(|| {
            self.runtime
                .block_on(async move { answers.lock().await.next().await })
        });
        match next {
            None => Ok(None),
            Some(Ok(bytes)) => Ok(Some(PyBytes::new(py, &bytes))),
            Some(Err(status)) => Err(call_error(status)),
        }
    }
}

/// A kinplan gRPC server running on a thread of this process.
#[pyclass(frozen)]
struct Server {
    #[pyo3(get)]
    address: String,
    stop: Mutex<Option<tokio::sync::oneshot::Sender<()>>>,
    thread: Mutex<Option<JoinHandle<()>>>,
}

#[pymethods]
impl Server {
    /// Stops accepting, finishes the calls in flight and joins the thread.
    fn stop(&self, py: Python<'_>) {
        if let Some(stop) = self.stop.lock().ok().and_then(|mut s| s.take()) {
            let _ = stop.send(());
        }
        if let Some(thread) = self.thread.lock().ok().and_then(|mut t| t.take()) {
            py.detach(|| {
                let _ = thread.join();
            });
        }
    }

    /// True until the server has stopped.
    fn running(&self) -> bool {
        self.thread
            .lock()
            .map(|t| t.as_ref().is_some_and(|t| !t.is_finished()))
            .unwrap_or(false)
    }
}

/// Serves the kinplan API on `address` ("127.0.0.1:0" picks a free port;
/// the bound address is `Server.address`) from a thread of this process.
#[pyfunction]
#[pyo3(signature = (address = "127.0.0.1:0", cpu_threads = 0, acm_samples = 10_000))]
fn serve_in_thread(address: &str, cpu_threads: usize, acm_samples: usize) -> PyResult<Server> {
    let listener =
        TcpListener::bind(address).map_err(|e| PyRuntimeError::new_err(format!("bind {address}: {e}")))?;
    listener
        .set_nonblocking(true)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let bound = listener
        .local_addr()
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("kinplan-serve")
        .enable_all()
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("tokio runtime: {e}")))?;
    let listener = {
        let _inside = runtime.enter();
        tokio::net::TcpListener::from_std(listener).map_err(|e| PyRuntimeError::new_err(e.to_string()))?
    };
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let config = config(cpu_threads, acm_samples);
    let thread = std::thread::Builder::new()
        .name("kinplan-server".into())
        .spawn(move || {
            let served = runtime.block_on(serve(config, listener, async {
                let _ = stopped.await;
            }));
            if let Err(e) = served {
                eprintln!("kinplan server stopped with an error: {e}");
            }
        })
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(Server {
        address: bound.to_string(),
        stop: Mutex::new(Some(stop)),
        thread: Mutex::new(Some(thread)),
    })
}

#[pymodule]
fn kinplan_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Backend>()?;
    m.add_class::<Stream>()?;
    m.add_class::<Server>()?;
    m.add_function(wrap_pyfunction!(serve_in_thread, m)?)?;
    m.add("CallError", m.py().get_type::<CallError>())?;
    Ok(())
}
