"""Operations: Prometheus metrics, JSON logs and graceful SIGTERM, on a
separate server process."""
import json
import signal
import subprocess
import urllib.request

import grpc
import pytest

import kinplan
from conftest import _binary, _free_port


def test_metrics_logs_and_sigterm():
    address = f"127.0.0.1:{_free_port()}"
    metrics = f"127.0.0.1:{_free_port()}"
    proc = subprocess.Popen(
        [_binary(), "serve", "--listen", address, "--metrics-listen", metrics, "--log-format", "json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    try:
        channel = grpc.insecure_channel(address)
        grpc.channel_ready_future(channel).result(timeout=30)
        channel.close()
        with kinplan.Client(address, timeout=5) as c:
            robot = c.robot("ur5")
            for _ in range(3):
                robot.fk([0.0] * 6)
            with pytest.raises(kinplan.KinplanError):
                robot.fk([0.0] * 2)
        text = urllib.request.urlopen(f"http://{metrics}/metrics", timeout=5).read().decode()
        ok = 'grpc_server_handled_total{grpc_service="kinplan.v1.RobotService",grpc_method="ForwardKinematics",grpc_code="OK"} 3'
        bad = 'grpc_server_handled_total{grpc_service="kinplan.v1.RobotService",grpc_method="ForwardKinematics",grpc_code="INVALID_ARGUMENT"} 1'
        assert ok in text and bad in text, text
        assert 'grpc_server_handling_seconds_bucket{grpc_service="kinplan.v1.RobotService"' in text
    finally:
        proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=15)
    assert proc.returncode == 0
    lines = [json.loads(line) for line in out.decode().splitlines() if line.startswith("{")]
    messages = [line["fields"]["message"] for line in lines]
    assert any("NOT_SERVING" in m for m in messages), messages
