"""A kinplan server for this Python process: ``with kinplan.LocalServer() as
server: client = server.client()`` starts ``kinplan serve`` on a free
loopback port, waits until it answers, and stops it on exit. Without a
``kinplan`` binary it runs the same server on a thread of this process
through the native extension (``pip install kinplan-native``): no cargo."""
from __future__ import annotations

import os
import shutil
import socket
import subprocess
import tempfile
import time
from typing import Any, List, Optional

from .client import Client
from .errors import error_for

import grpc


def find_binary(binary: Optional[str] = None) -> str:
    """`binary`, else $KINPLAN_BIN, else `kinplan` on the PATH."""
    path = binary or os.environ.get("KINPLAN_BIN") or shutil.which("kinplan")
    if not path or not os.path.exists(path):
        raise FileNotFoundError(
            "no kinplan server binary: pass binary=, set KINPLAN_BIN, or put `kinplan` on the PATH "
            "(cargo install --path crates/kinplan-server)"
        )
    return path


def _native_available() -> bool:
    from .inprocess import native

    try:
        native()
        return True
    except ImportError:
        return False


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class LocalServer:
    """``kinplan serve`` as a child process on 127.0.0.1 (a free port unless
    `port` is given). `args` are extra ``serve`` options, e.g.
    ``["--cpu-threads", "2"]``. `startup_timeout` bounds the wait for the
    first answer (s).

    `in_thread`: run the server on a thread of this process through the
    native extension instead of a child process (default: only when no
    ``kinplan`` binary is found). `args` do not apply there; `kill` is `stop`."""

    def __init__(self, *, binary: Optional[str] = None, port: Optional[int] = None,
                 args: Optional[List[str]] = None, startup_timeout: float = 30.0,
                 in_thread: Optional[bool] = None):
        if in_thread is None:
            try:
                self.binary = find_binary(binary)
                in_thread = False
            except FileNotFoundError:
                in_thread = _native_available()
                if not in_thread:
                    raise FileNotFoundError(
                        "no kinplan server: pip install kinplan-native (a server in this process), "
                        "or pass binary=, set KINPLAN_BIN, or put `kinplan` on the PATH"
                    ) from None
        elif not in_thread:
            self.binary = find_binary(binary)
        self.in_thread = in_thread
        self.address = f"127.0.0.1:{port or _free_port()}"
        self.args = list(args or [])
        self.startup_timeout = startup_timeout
        self._proc: Optional["subprocess.Popen[bytes]"] = None
        self._thread_server: Any = None
        self._log: Any = None

    def start(self) -> "LocalServer":
        if self._proc is not None or self._thread_server is not None:
            return self
        if self.in_thread:
            from .inprocess import native

            self._thread_server = native().serve_in_thread(self.address)
            return self
        # a file, not a pipe: a chatty server must never block on a full pipe
        self._log = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(
            [self.binary, "serve", "--listen", self.address, *self.args],
            stdout=subprocess.DEVNULL,
            stderr=self._log,
        )
        # Ready when the port accepts connections (TLS or not, tokens or not).
        host, port = self.address.rsplit(":", 1)
        deadline = time.monotonic() + self.startup_timeout
        while True:
            if self._proc.poll() is not None:
                self._log.seek(0)
                err = self._log.read().decode(errors="replace")
                self._proc = None
                raise error_for(grpc.StatusCode.UNAVAILABLE, f"kinplan serve exited: {err.strip()[-500:]}", [])
            try:
                with socket.create_connection((host, int(port)), timeout=0.2):
                    return self
            except OSError:
                if time.monotonic() > deadline:
                    self.stop()
                    raise error_for(
                        grpc.StatusCode.UNAVAILABLE, f"kinplan serve did not start at {self.address}", []
                    ) from None
                time.sleep(0.02)

    def client(self, **kwargs: Any) -> Client:
        """A client of this server (keyword arguments as for :class:`Client`)."""
        return Client(self.address, **kwargs)

    def stop(self, timeout: float = 10.0) -> None:
        """SIGTERM (the server drains its calls), then SIGKILL after `timeout` s."""
        server, self._thread_server = self._thread_server, None
        if server is not None:
            server.stop()
        proc, self._proc = self._proc, None
        if proc is None:
            return
        proc.terminate()
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        self._log.close()

    def kill(self) -> None:
        """SIGKILL: the server dies with its calls (a crash, for failover tests)."""
        if self._thread_server is not None:
            self.stop()
        proc, self._proc = self._proc, None
        if proc is not None:
            proc.kill()
            proc.wait()
            self._log.close()

    @property
    def running(self) -> bool:
        if self._thread_server is not None:
            return bool(self._thread_server.running())
        return self._proc is not None and self._proc.poll() is None

    @property
    def pid(self) -> Optional[int]:
        """The server process's id (for its memory or CPU figures); ``None``
        when it runs in a thread of this process or is not running."""
        return self._proc.pid if self._proc is not None else None

    def __enter__(self) -> "LocalServer":
        return self.start()

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    def __repr__(self) -> str:
        return f"LocalServer({self.address!r}, running={self.running})"
