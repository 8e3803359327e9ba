"""Starts a real `kinplan serve` process on a free loopback port; the
`client` fixture runs each test against it and, when the native extension is
available (installed, or $KINPLAN_NATIVE names a built libkinplan_native.so),
again against the in-process backend (`kinplan.Client.local()`)."""
import os
import pathlib
import socket
import subprocess
import time

import grpc
import pytest

import kinplan

ROOT = pathlib.Path(__file__).resolve().parents[3]


def _binary() -> str:
    path = os.environ.get("KINPLAN_BIN") or str(ROOT / "target" / "debug" / "kinplan")
    if not os.path.exists(path):
        pytest.exit(f"kinplan binary not found at {path}: run `cargo build` or set KINPLAN_BIN", 2)
    return path


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="session")
def server_address():
    port = _free_port()
    address = f"127.0.0.1:{port}"
    proc = subprocess.Popen(
        [_binary(), "serve", "--listen", address],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    channel = grpc.insecure_channel(address)
    try:
        grpc.channel_ready_future(channel).result(timeout=30)
    except grpc.FutureTimeoutError:
        proc.kill()
        raise RuntimeError(proc.stderr.read().decode())
    finally:
        channel.close()
    yield address
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()


def _native_available() -> bool:
    try:
        from kinplan.inprocess import native

        native()
        return True
    except ImportError:
        return False


BACKENDS = ["remote", "local"] if _native_available() else ["remote"]


@pytest.fixture(scope="session")
def local_client():
    # one in-process backend (one CPU pool) for the whole session
    return kinplan.Client.local(timeout=10, acm_samples=1000)


@pytest.fixture(params=BACKENDS)
def client(request, server_address):
    if request.param == "local":
        yield request.getfixturevalue("local_client")
        return
    with kinplan.Client(server_address, timeout=10) as c:
        yield c
