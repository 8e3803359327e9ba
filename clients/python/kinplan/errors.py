"""Server errors as Python exceptions."""
from __future__ import annotations

from typing import Any, List, Tuple

import grpc


class KinplanError(Exception):
    """A call failed. `code` is the gRPC status code, `message` the server's
    text, `field_violations` the (field, description) pairs it named.

    Each status code has its subclass, which also derives from the matching
    builtin, so plain Python handlers work: :class:`InvalidArgument` is a
    ``ValueError``, :class:`DeadlineExceeded` a ``TimeoutError``,
    :class:`Unavailable` a ``ConnectionError``, :class:`NotFound` a
    ``LookupError``. Errors pickle (multiprocessing, joblib)."""

    def __init__(self, code: grpc.StatusCode, message: str, field_violations: List[Tuple[str, str]]):
        super().__init__(f"{code.name}: {message}")
        self.code = code
        self.message = message
        self.field_violations = field_violations

    def __reduce__(self) -> Tuple[Any, Tuple[str, str, List[Tuple[str, str]]]]:
        return (_rebuild, (self.code.name, self.message, self.field_violations))

    def __str__(self) -> str:
        return f"{self.code.name}: {self.message}"

    @property
    def code_name(self) -> str:
        return str(self.code.name)

    @classmethod
    def from_rpc_error(cls, err: grpc.RpcError) -> "KinplanError":
        code = err.code() if hasattr(err, "code") else grpc.StatusCode.UNKNOWN
        message = err.details() if hasattr(err, "details") else str(err)
        return error_for(code, message or "", _field_violations(err))


class InvalidArgument(KinplanError, ValueError):
    """INVALID_ARGUMENT: the request named a bad field (see field_violations)."""


class DeadlineExceeded(KinplanError, TimeoutError):
    """DEADLINE_EXCEEDED: the call's timeout passed."""


class Unavailable(KinplanError, ConnectionError):
    """UNAVAILABLE: no server answered at the address."""

    def __str__(self) -> str:
        return (
            f"{self.code.name}: {self.message} (is `kinplan serve` running at that address? "
            "kinplan.LocalServer() starts one)"
        )


class NotFound(KinplanError, LookupError):
    """NOT_FOUND: e.g. an unknown built-in robot name."""


class ResourceExhausted(KinplanError, RuntimeError):
    """RESOURCE_EXHAUSTED: the server shed the call (overload) or the request is too large."""


class Cancelled(KinplanError):
    """CANCELLED: the call was cancelled."""


class Internal(KinplanError, RuntimeError):
    """INTERNAL: a server bug; the message says what."""


class JointLimitWarning(UserWarning):
    """Joint values outside the robot's limits were sent: kinplan takes
    radians, and degrees are the usual cause (``np.radians(...)``)."""


_BY_CODE = {
    grpc.StatusCode.INVALID_ARGUMENT: InvalidArgument,
    grpc.StatusCode.DEADLINE_EXCEEDED: DeadlineExceeded,
    grpc.StatusCode.UNAVAILABLE: Unavailable,
    grpc.StatusCode.NOT_FOUND: NotFound,
    grpc.StatusCode.RESOURCE_EXHAUSTED: ResourceExhausted,
    grpc.StatusCode.CANCELLED: Cancelled,
    grpc.StatusCode.INTERNAL: Internal,
}


def error_for(code: grpc.StatusCode, message: str, field_violations: List[Tuple[str, str]]) -> KinplanError:
    """The exception of the subclass that matches `code`."""
    return _BY_CODE.get(code, KinplanError)(code, message, field_violations)


def invalid_argument(field: str, message: str) -> InvalidArgument:
    """A locally detected bad argument, as the server would report it."""
    return InvalidArgument(grpc.StatusCode.INVALID_ARGUMENT, f"{field}: {message}", [(field, message)])


def _rebuild(code_name: str, message: str, field_violations: List[Tuple[str, str]]) -> KinplanError:
    return error_for(grpc.StatusCode[code_name], message, field_violations)


def _field_violations(err: grpc.RpcError) -> List[Tuple[str, str]]:
    """Reads google.rpc.BadRequest from the status details, when present."""
    try:
        from google.protobuf import any_pb2  # noqa: F401
        from grpc_status import rpc_status
    except ImportError:
        rpc_status = None
    if rpc_status is not None:
        try:
            status = rpc_status.from_call(err)
        except Exception:
            status = None
        if status is not None:
            return _violations_from_status(status)
    return []


def _violations_from_status(status: Any) -> List[Tuple[str, str]]:
    from google.rpc import error_details_pb2  # type: ignore

    out: List[Tuple[str, str]] = []
    for detail in status.details:
        if detail.Is(error_details_pb2.BadRequest.DESCRIPTOR):
            bad = error_details_pb2.BadRequest()
            detail.Unpack(bad)
            out.extend((v.field, v.description) for v in bad.field_violations)
    return out
