"""The in-process backend: kinplan's services inside this Python process,
through the native extension ``kinplan_native`` (``pip install
kinplan-native``, or a build of ``clients/python/native``).

:meth:`kinplan.Client.local` gives a client with the whole API whose calls
never leave the process: no socket, no HTTP/2, no grpcio call set-up — the
same handlers, validation and errors as ``kinplan serve``. Use it for
latency-critical loops; use a server for sharing and scale-out.
"""
from __future__ import annotations

import asyncio
import importlib.machinery
import importlib.util
import os
import threading
from types import ModuleType
from typing import Any, AsyncIterator, Callable, Iterable, Iterator, List, Optional, Tuple

import grpc

_native: Optional[ModuleType] = None


def native() -> ModuleType:
    """The ``kinplan_native`` extension: the installed module, else the file
    $KINPLAN_NATIVE names (a cargo build's ``libkinplan_native.so``)."""
    global _native
    if _native is not None:
        return _native
    try:
        import kinplan_native

        _native = kinplan_native
    except ImportError:
        path = os.environ.get("KINPLAN_NATIVE")
        if not path:
            raise ImportError(
                "the in-process backend needs the native extension: pip install kinplan-native "
                "(a wheel built by `maturin build -m clients/python/native/Cargo.toml`), "
                "or set KINPLAN_NATIVE to a built libkinplan_native.so"
            ) from None
        loader = importlib.machinery.ExtensionFileLoader("kinplan_native", path)
        spec = importlib.util.spec_from_file_location("kinplan_native", path, loader=loader)
        assert spec is not None
        module = importlib.util.module_from_spec(spec)
        loader.exec_module(module)
        _native = module
    return _native


class LocalRpcError(grpc.RpcError):
    """A failed in-process call, shaped like grpcio's error (code, details,
    trailing metadata with the rich status) so the client maps it the same way."""

    def __init__(self, code: int, message: str, details: bytes):
        super().__init__(message)
        self._code = _CODES.get(code, grpc.StatusCode.UNKNOWN)
        self._message = message
        self._details = details

    def code(self) -> grpc.StatusCode:
        return self._code

    def details(self) -> str:
        return self._message

    def trailing_metadata(self) -> List[Tuple[str, bytes]]:
        return [("grpc-status-details-bin", self._details)] if self._details else []

    def __str__(self) -> str:
        return f"{self._code.name}: {self._message}"


_CODES = {c.value[0]: c for c in grpc.StatusCode}


def _rpc_error(err: Exception) -> LocalRpcError:
    code, message, details = err.args
    return LocalRpcError(code, message, details)


class _Unary:
    def __init__(self, backend: Any, path: str, serialize: Callable[..., Any], deserialize: Callable[..., Any]):
        self._backend, self._path = backend, path
        self._serialize, self._deserialize = serialize, deserialize
        self._error = native().CallError

    def __call__(self, request: Any, timeout: Optional[float] = None, **_: Any) -> Any:
        try:
            wire = request if self._serialize is None else self._serialize(request)
            answer = self._backend.unary(self._path, wire, timeout)
        except self._error as err:
            raise _rpc_error(err) from None
        return answer if self._deserialize is None else self._deserialize(answer)


class _Answers(Iterator[Any]):
    """The answers of a streaming call, as grpcio's response iterator."""

    def __init__(self, stream: Any, deserialize: Callable[..., Any], feeder: Optional[threading.Thread]):
        self._stream, self._deserialize, self._feeder = stream, deserialize, feeder
        self._error = native().CallError

    def __next__(self) -> Any:
        try:
            answer = self._stream.recv()
        except self._error as err:
            raise _rpc_error(err) from None
        if answer is None:
            raise StopIteration
        return self._deserialize(answer)

    def cancel(self) -> bool:
        self._stream.close()
        return True


class _Streaming:
    def __init__(self, backend: Any, path: str, serialize: Callable[..., Any], deserialize: Callable[..., Any], client_streams: bool):
        self._backend, self._path = backend, path
        self._serialize, self._deserialize = serialize, deserialize
        self._client_streams = client_streams
        self._error = native().CallError

    def __call__(self, requests: Any, timeout: Optional[float] = None, **_: Any) -> _Answers:
        try:
            if not self._client_streams:
                stream = self._backend.server_stream(self._path, self._serialize(requests), timeout)
                return _Answers(stream, self._deserialize, None)
            stream = self._backend.stream(self._path, timeout)
        except self._error as err:
            raise _rpc_error(err) from None
        feeder = threading.Thread(target=self._feed, args=(stream, requests), daemon=True)
        feeder.start()
        return _Answers(stream, self._deserialize, feeder)

    def _feed(self, stream: Any, requests: Iterable[Any]) -> None:
        try:
            for request in requests:
                if not stream.send(self._serialize(request)):
                    return
        finally:
            stream.close()


class LocalChannel:
    """A stand-in for ``grpc.Channel`` whose calls run in this process; the
    generated stubs (and so the whole client) work on it unchanged."""

    def __init__(self, cpu_threads: int = 0, acm_samples: int = 10_000):
        self._backend = native().Backend(cpu_threads, acm_samples)

    def unary_unary(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> _Unary:
        return _Unary(self._backend, method, request_serializer, response_deserializer)

    def unary_stream(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> _Streaming:
        return _Streaming(self._backend, method, request_serializer, response_deserializer, False)

    def stream_stream(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> _Streaming:
        return _Streaming(self._backend, method, request_serializer, response_deserializer, True)

    def stream_unary(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> Any:
        streaming = _Streaming(self._backend, method, request_serializer, response_deserializer, True)

        def call(requests: Any, timeout: Optional[float] = None, **kw: Any) -> Any:
            return next(streaming(requests, timeout, **kw))

        return call

    def subscribe(self, *_: Any, **__: Any) -> None:
        pass

    def unsubscribe(self, *_: Any, **__: Any) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self) -> "LocalChannel":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _aio_error(err: Exception) -> grpc.aio.AioRpcError:
    """A native call error as grpc.aio's error (code, details, rich status)."""
    code, message, details = err.args
    trailing = grpc.aio.Metadata(("grpc-status-details-bin", details)) if details else grpc.aio.Metadata()
    return grpc.aio.AioRpcError(_CODES.get(code, grpc.StatusCode.UNKNOWN), grpc.aio.Metadata(), trailing, details=message)


class _AioUnary:
    """An awaitable unary call: the native call runs on a worker thread (it
    releases the GIL), so the event loop keeps running."""

    def __init__(self, backend: Any, path: str, serialize: Callable[..., Any], deserialize: Callable[..., Any]):
        self._backend, self._path = backend, path
        self._serialize, self._deserialize = serialize, deserialize
        self._error = native().CallError

    async def __call__(self, request: Any, timeout: Optional[float] = None, **_: Any) -> Any:
        wire = request if self._serialize is None else self._serialize(request)
        try:
            answer = await asyncio.to_thread(self._backend.unary, self._path, wire, timeout)
        except self._error as err:
            raise _aio_error(err) from None
        return self._deserialize(answer)


class _AioCall:
    """A streaming call as grpc.aio's: ``async for`` over the answers,
    ``read()`` (``grpc.aio.EOF`` at the end), ``write()``, ``done_writing()``
    and ``cancel()``."""

    def __init__(self, stream: Any, serialize: Callable[..., Any], deserialize: Callable[..., Any]):
        self._stream, self._serialize, self._deserialize = stream, serialize, deserialize
        self._error = native().CallError

    async def read(self) -> Any:
        try:
            answer = await asyncio.to_thread(self._stream.recv)
        except self._error as err:
            raise _aio_error(err) from None
        return grpc.aio.EOF if answer is None else self._deserialize(answer)

    def __aiter__(self) -> AsyncIterator[Any]:
        return self._answers()

    async def _answers(self) -> AsyncIterator[Any]:
        while True:
            answer = await self.read()
            if answer is grpc.aio.EOF:
                return
            yield answer

    async def write(self, request: Any) -> None:
        if not await asyncio.to_thread(self._stream.send, self._serialize(request)):
            raise _aio_error(native().CallError(1, "the call has ended", b""))

    async def done_writing(self) -> None:
        self._stream.close()

    def cancel(self) -> bool:
        self._stream.close()
        return True


class _AioStreaming:
    def __init__(self, backend: Any, path: str, serialize: Callable[..., Any], deserialize: Callable[..., Any], client_streams: bool):
        self._backend, self._path = backend, path
        self._serialize, self._deserialize = serialize, deserialize
        self._client_streams = client_streams
        self._error = native().CallError

    def __call__(self, request: Any = None, timeout: Optional[float] = None, **_: Any) -> _AioCall:
        try:
            if self._client_streams:
                stream = self._backend.stream(self._path, timeout)
            else:
                stream = self._backend.server_stream(self._path, self._serialize(request), timeout)
        except self._error as err:
            raise _aio_error(err) from None
        return _AioCall(stream, self._serialize, self._deserialize)


class AioLocalChannel:
    """A stand-in for ``grpc.aio.Channel`` whose calls run in this process
    (:meth:`kinplan.aio.Client.local`); the generated stubs work on it unchanged."""

    def __init__(self, cpu_threads: int = 0, acm_samples: int = 10_000):
        self._backend = native().Backend(cpu_threads, acm_samples)

    def unary_unary(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> _AioUnary:
        return _AioUnary(self._backend, method, request_serializer, response_deserializer)

    def unary_stream(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> _AioStreaming:
        return _AioStreaming(self._backend, method, request_serializer, response_deserializer, False)

    def stream_stream(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> _AioStreaming:
        return _AioStreaming(self._backend, method, request_serializer, response_deserializer, True)

    def stream_unary(self, method: str, request_serializer: Callable[..., Any], response_deserializer: Callable[..., Any], **_: Any) -> Any:
        raise NotImplementedError("kinplan has no client-streaming calls")

    async def channel_ready(self) -> None:
        return None

    async def close(self) -> None:
        return None
