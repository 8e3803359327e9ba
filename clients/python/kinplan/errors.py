"""Server errors as Python exceptions."""
from __future__ import annotations

from typing import List, Tuple

import grpc


class KinplanError(Exception):
    """A call failed. `code` is the gRPC status code, `message` the server's
    text, `field_violations` the (field, description) pairs it named."""

    def __init__(self, code: grpc.StatusCode, message: str, field_violations: List[Tuple[str, str]]):
        super().__init__(f"{code.name}: {message}")
        self.code = code
        self.message = message
        self.field_violations = field_violations

    @property
    def code_name(self) -> str:
        return self.code.name

    @classmethod
    def from_rpc_error(cls, err: grpc.RpcError) -> "KinplanError":
        code = err.code() if hasattr(err, "code") else grpc.StatusCode.UNKNOWN
        message = err.details() if hasattr(err, "details") else str(err)
        return cls(code, message or "", _field_violations(err))


def _field_violations(err: grpc.RpcError) -> List[Tuple[str, str]]:
    """Reads google.rpc.BadRequest from the status details, when present."""
    try:
        from google.protobuf import any_pb2  # noqa: F401
        from grpc_status import rpc_status  # type: ignore
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


def _violations_from_status(status) -> List[Tuple[str, str]]:
    from google.rpc import error_details_pb2  # type: ignore

    out: List[Tuple[str, str]] = []
    for detail in status.details:
        if detail.Is(error_details_pb2.BadRequest.DESCRIPTOR):
            bad = error_details_pb2.BadRequest()
            detail.Unpack(bad)
            out.extend((v.field, v.description) for v in bad.field_violations)
    return out
