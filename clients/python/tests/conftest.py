"""Starts a real `kinplan serve` process on a free loopback port."""
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


@pytest.fixture()
def client(server_address):
    with kinplan.Client(server_address, timeout=10) as c:
        yield c
