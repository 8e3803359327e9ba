"""The connection layer both clients share: gRPC targets as people type
them, channel options for replicas, TLS files and the bearer token."""
from __future__ import annotations

import json
import socket
from typing import Any, List, Optional, Sequence, Union

import grpc

from .errors import KinplanError, error_for, invalid_argument

DEFAULT_TIMEOUT = 30.0


DEFAULT_PORT = 50051


# Round robin over the resolved addresses; UNAVAILABLE (replica gone or not
# yet up) is retried up to three attempts with a short backoff.
_REPLICA_SERVICE_CONFIG = json.dumps(
    {
        "loadBalancingConfig": [{"round_robin": {}}],
        "methodConfig": [
            {
                "name": [{}],
                "retryPolicy": {
                    "maxAttempts": 3,
                    "initialBackoff": "0.01s",
                    "maxBackoff": "0.2s",
                    "backoffMultiplier": 2,
                    "retryableStatusCodes": ["UNAVAILABLE"],
                },
            }
        ],
    }
)


def normalize_target(target: Union[str, Sequence[str]]) -> str:
    """A gRPC target from what people type: "host" gets port 50051,
    "http://host:port" loses its scheme, several addresses become one
    "ipv4:a:p,b:p" target; "dns:///..." and other gRPC targets pass."""
    if not isinstance(target, str):
        parts = [str(t) for t in target]
    else:
        if target.startswith(("dns:", "ipv4:", "ipv6:", "unix:")):
            return target
        if target.startswith("https://"):
            raise invalid_argument("target", "TLS is not supported by this client; give host:port")
        parts = [p.strip() for p in target.split(",") if p.strip()]
    if not parts:
        raise invalid_argument("target", "no address given")
    out = []
    for p in parts:
        p = p.removeprefix("http://").rstrip("/")
        if "/" in p:
            raise invalid_argument("target", f"{p!r} is not host[:port]")
        bracketed = p.startswith("[")
        has_port = (bracketed and "]:" in p) or (not bracketed and p.count(":") == 1)
        if p.count(":") > 1 and not bracketed:
            p = f"[{p}]"  # a bare IPv6 address
        out.append(p if has_port else f"{p}:{DEFAULT_PORT}")
    if len(out) == 1:
        return out[0]
    # gRPC's ipv4:/ipv6: targets take literal addresses: resolve host names once
    resolved = []
    for o in out:
        host, port = o.rsplit(":", 1)
        if not host.startswith("["):
            try:
                socket.inet_aton(host)
            except OSError:
                host = socket.gethostbyname(host)
        resolved.append(f"{host}:{port}")
    scheme = "ipv6" if any(o.startswith("[") for o in resolved) else "ipv4"
    return f"{scheme}:{','.join(resolved)}"


def _channel_options(target: str, max_message_bytes: int) -> List[Any]:
    """grpc channel options for a normalized target (blocking and asyncio clients)."""
    options: List[Any] = [
        ("grpc.max_send_message_length", max_message_bytes),
        ("grpc.max_receive_message_length", max_message_bytes),
    ]
    if target.startswith(("dns:", "ipv4:", "ipv6:")):
        # Replicas are identical and every call is stateless, so a call
        # that finds its replica gone is retried on another.
        options.append(("grpc.service_config", _REPLICA_SERVICE_CONFIG))
        options.append(("grpc.enable_retries", 1))
    if target.startswith(("ipv4:", "ipv6:")):
        # the default :authority would be the whole address list, which
        # HTTP/2 servers refuse (RST_STREAM PROTOCOL_ERROR)
        options.append(("grpc.default_authority", "kinplan"))
    return options


def _pem(v: Union[str, bytes]) -> bytes:
    """PEM bytes, or the content of the file a string names."""
    if isinstance(v, bytes):
        return v
    with open(v, "rb") as f:
        return f.read()


class _BearerToken(
    grpc.UnaryUnaryClientInterceptor,
    grpc.UnaryStreamClientInterceptor,
    grpc.StreamUnaryClientInterceptor,
    grpc.StreamStreamClientInterceptor,
):
    """Adds ``authorization: Bearer <token>`` to every call."""

    def __init__(self, token: str):
        if not token or any(c in token for c in "\r\n"):
            raise invalid_argument("token", "must be a non-empty single line")
        self._header = ("authorization", f"Bearer {token}")

    def _details(self, d: Any) -> Any:
        metadata = list(d.metadata or []) + [self._header]
        return _CallDetails(d.method, d.timeout, metadata, d.credentials, d.wait_for_ready, d.compression)

    def intercept_unary_unary(self, continuation, details, request):  # type: ignore[no-untyped-def]
        return continuation(self._details(details), request)

    def intercept_unary_stream(self, continuation, details, request):  # type: ignore[no-untyped-def]
        return continuation(self._details(details), request)

    def intercept_stream_unary(self, continuation, details, requests):  # type: ignore[no-untyped-def]
        return continuation(self._details(details), requests)

    def intercept_stream_stream(self, continuation, details, requests):  # type: ignore[no-untyped-def]
        return continuation(self._details(details), requests)


class _CallDetails(grpc.ClientCallDetails):
    def __init__(self, method: Any, timeout: Any, metadata: Any, credentials: Any, wait_for_ready: Any,
                 compression: Any) -> None:
        self.method = method
        self.timeout = timeout
        self.metadata = metadata
        self.credentials = credentials
        self.wait_for_ready = wait_for_ready
        self.compression = compression



def _no_server(target: str, timeout: Optional[float]) -> KinplanError:
    """The :class:`kinplan.errors.Unavailable` of a ``wait_for_ready`` that timed out."""
    return error_for(grpc.StatusCode.UNAVAILABLE, f"no server at {target} within {timeout} s", [])
