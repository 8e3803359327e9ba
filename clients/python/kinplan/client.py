"""The kinplan client: a channel, robots, and numpy conversions."""
from __future__ import annotations

from dataclasses import dataclass, field
import json
import operator
import socket
import time
import warnings
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import grpc
import numpy as np
import numpy.typing as npt

from ._codec import FK_JOINTS, ROBOT_REF, joints, joints_and_field, length_delimited, read_fk_reply
from ._convert import matrix_from_proto, matrix_to_proto, pose_to_matrix
from ._rotation import poses_to_matrices
from .errors import JointLimitWarning, KinplanError, error_for, invalid_argument
from .kinematics import KinematicsMixin, RobotKinematicsMixin
from .mobile import MobileMixin
from .explore import ExploreMixin
from .exploration import ExplorationMixin
from .planning import PlanningMixin
from .scoring import ScoringMixin
from .v1 import common_pb2, robot_pb2, robot_pb2_grpc

DEFAULT_TIMEOUT = 30.0


DEFAULT_PORT = 50051

_FORWARD_KINEMATICS = "/kinplan.v1.RobotService/ForwardKinematics"

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


class Client(ExploreMixin, ExplorationMixin, PlanningMixin, ScoringMixin, MobileMixin, KinematicsMixin):
    """A connection to a kinplan server.

    `timeout` (seconds) is the default deadline of every call; each method
    also takes its own `timeout=`. Use as a context manager, or call close().
    """

    def __init__(
        self,
        target: Union[str, Sequence[str]] = "127.0.0.1:50051",
        *,
        timeout: Optional[float] = DEFAULT_TIMEOUT,
        max_message_bytes: int = 16 * 1024 * 1024,
        channel: Optional[grpc.Channel] = None,
        wait_for_ready: bool = False,
        token: Optional[str] = None,
        tls_ca: Union[None, str, bytes] = None,
        tls_cert: Union[None, str, bytes] = None,
        tls_key: Union[None, str, bytes] = None,
    ):
        """`target`: "host", "host:port" (port 50051 when left out),
        "dns:///name:port" (every address the name resolves to, round robin),
        or several "host:port" (a list or one comma-separated string; calls
        spread round robin over identical replicas). With `wait_for_ready`,
        the constructor waits up to `timeout` for the server and raises
        :class:`kinplan.errors.Unavailable` if none answers.

        Security (both off by default, as on the server): `token` is sent as
        ``authorization: Bearer <token>`` on every call; `tls_ca` (a PEM
        file path or bytes) turns on TLS, trusting that CA; `tls_cert` and
        `tls_key` add a client certificate for mutual TLS."""
        self.target = normalize_target(target)
        self.timeout = timeout
        options = _channel_options(self.target, max_message_bytes)
        if channel is None:
            if tls_ca is not None:
                creds = grpc.ssl_channel_credentials(
                    root_certificates=_pem(tls_ca),
                    private_key=_pem(tls_key) if tls_key is not None else None,
                    certificate_chain=_pem(tls_cert) if tls_cert is not None else None,
                )
                channel = grpc.secure_channel(self.target, creds, options=options)
            elif tls_cert is not None or tls_key is not None:
                raise invalid_argument("tls_ca", "a client certificate needs TLS: give tls_ca too")
            else:
                channel = grpc.insecure_channel(self.target, options=options)
            if token is not None:
                channel = grpc.intercept_channel(channel, _BearerToken(token))
        self._channel = channel
        self._robots = robot_pb2_grpc.RobotServiceStub(self._channel)
        if wait_for_ready:
            self.wait_for_ready(timeout)

    @classmethod
    def local(cls, *, timeout: Optional[float] = DEFAULT_TIMEOUT, cpu_threads: int = 0,
              acm_samples: int = 10_000) -> "Client":
        """A client whose calls run in this process: kinplan's services through
        the native extension (``pip install kinplan-native``), with the same
        API, validation and errors as a server, and no network hop — for
        latency-critical loops. `cpu_threads` sizes its CPU pool (0: one per
        core); `acm_samples` is the random states sampled per robot for its
        allowed-collision matrix (planning)."""
        from .inprocess import LocalChannel

        client = cls(timeout=timeout, channel=LocalChannel(cpu_threads, acm_samples))
        client.target = "in-process"
        return client

    def wait_for_ready(self, timeout: Optional[float] = None) -> None:
        """Blocks until the channel connects (at most `timeout` s, default the
        client's); raises :class:`kinplan.errors.Unavailable` otherwise."""
        if self.target == "in-process":
            return
        t = self.timeout if timeout is None else timeout
        try:
            grpc.channel_ready_future(self._channel).result(timeout=t)
        except grpc.FutureTimeoutError:
            raise _no_server(self.target, t) from None

    def ping(self, *, timeout: Optional[float] = None) -> float:
        """Round-trip time (s) of the cheapest call (ListRobots); raises
        :class:`kinplan.errors.Unavailable` when no server answers."""
        t0 = time.perf_counter()
        self._call(self._robots.ListRobots, robot_pb2.ListRobotsRequest(), timeout)
        return time.perf_counter() - t0

    def __repr__(self) -> str:
        return f"kinplan.Client({self.target!r}, timeout={self.timeout})"

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        self._channel.close()

    def _raw_unary(self, path: str, response: Any) -> Any:
        """A unary method that sends an already-encoded request (bytes) and
        decodes the answer as `response` (``None``: the answer's bytes): the
        fast path of hot calls."""
        try:
            return self.__dict__["_raw_methods"][(path, response)]
        except KeyError:
            cache = self.__dict__.setdefault("_raw_methods", {})
            # registered as the generated stubs register theirs (the core
            # interns the method's path once, not per call)
            method = cache[(path, response)] = self._channel.unary_unary(
                path, request_serializer=None, response_deserializer=None if response is None else response.FromString,
                _registered_method=True,
            )
            return method

    def _call(self, method: Callable[..., Any], request: Any, timeout: Optional[float]) -> Any:
        try:
            return method(request, timeout=self.timeout if timeout is None else timeout)
        except grpc.RpcError as err:
            raise KinplanError.from_rpc_error(err) from None

    def list_robots(self, *, timeout: Optional[float] = None) -> List[Dict[str, Any]]:
        """The built-in robots: name, dof, description, base and tip links."""
        reply = self._call(self._robots.ListRobots, robot_pb2.ListRobotsRequest(), timeout)
        return [
            {
                "name": r.name,
                "dof": r.dof,
                "description": r.description,
                "base_link": r.base_link,
                "tip_link": r.tip_link,
            }
            for r in reply.robots
        ]

    def robot(
        self,
        name: Optional[str] = None,
        *,
        urdf: Optional[str] = None,
        base_link: str = "",
        tip_link: str = "",
        strict: bool = False,
    ) -> "Robot":
        """A built-in robot by `name`, or a model sent as `urdf` text.

        Joint values outside the robot's limits (usually degrees given where
        radians are meant) raise a :class:`kinplan.JointLimitWarning` in
        ``fk``, ``fk_batch``, ``jacobian`` and ``Client.score``; with
        `strict=True` they raise :class:`kinplan.InvalidArgument` instead."""
        _check_robot_args(name, urdf)
        return Robot(self, name=name, urdf=urdf, base_link=base_link, tip_link=tip_link, strict=strict)


@dataclass
class RobotDescription:
    """A robot's chain as the server sees it. Limits in rad (m for prismatic
    joints); infinite for unlimited joints; max_velocity 0 when unknown."""

    name: str
    base_link: str
    tip_link: str
    joint_names: List[str]
    joint_types: List[str]
    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    link_names: List[str]
    model_id: bytes = b""
    raw: Any = field(default=None, repr=False)

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    @classmethod
    def from_proto(cls, r: robot_pb2.DescribeRobotResponse) -> "RobotDescription":
        return cls(
            name=r.name,
            base_link=r.base_link,
            tip_link=r.tip_link,
            joint_names=[j.name for j in r.joints],
            joint_types=[robot_pb2.JointType.Name(j.type).removeprefix("JOINT_TYPE_").lower() for j in r.joints],
            lower=np.array([j.lower for j in r.joints]),
            upper=np.array([j.upper for j in r.joints]),
            max_velocity=np.array([j.max_velocity for j in r.joints]),
            link_names=[link.name for link in r.links],
            model_id=r.model_id,
            raw=r,
        )


class JointLimits:
    """A chain's joint limits for the client-side guard against degrees: a
    value outside [lower, upper] (1e-9 of slack) warns, or raises when strict."""

    def __init__(self, d: RobotDescription):
        self.lower = d.lower - 1e-9
        self.upper = d.upper + 1e-9
        self.names = d.joint_names
        self._lower_list: List[float] = self.lower.tolist()
        self._upper_list: List[float] = self.upper.tolist()

    def check(self, q: Any, field_name: str, strict: bool) -> None:
        if isinstance(q, list) and len(q) == len(self._lower_list):
            # one state as floats (fk, jacobian): comparisons mapped in C are the cheapest test
            if all(map(operator.le, self._lower_list, q)) and all(map(operator.le, q, self._upper_list)):
                return
        arr = np.asarray(q, dtype=float)
        if arr.ndim == 0 or arr.shape[-1] != len(self.lower):
            return  # the server names a wrong length
        outside = (arr < self.lower) | (arr > self.upper)
        if not outside.any():
            return
        where = np.argwhere(outside)[0]
        j = int(where[-1])
        value = float(arr[tuple(where)])
        message = (
            f"{int(outside.sum())} joint value(s) outside the limits, e.g. {self.names[j]} = {value:.6g} not in "
            f"[{self.lower[j] + 1e-9:.6g}, {self.upper[j] - 1e-9:.6g}]; kinplan takes radians (m for prismatic "
            "joints): degrees? use np.radians(...)"
        )
        if strict:
            raise invalid_argument(field_name, message)
        warnings.warn(f"{field_name}: {message}", JointLimitWarning, stacklevel=4)


def _check_robot_args(name: Optional[str], urdf: Optional[str]) -> None:
    """`Client.robot`'s checks (blocking and asyncio): one of a name or a URDF
    text, and a URDF that is not a file's path."""
    if (name is None) == (urdf is None):
        raise invalid_argument("name", "give exactly one of name or urdf=")
    if urdf is not None and "<" not in urdf and urdf.strip().lower().endswith((".urdf", ".xml")):
        raise invalid_argument(
            "urdf",
            f"{urdf!r} looks like a file path; urdf= takes the document's text: urdf=open(path).read()",
        )


def _urdf_request(keep_capsules: bool) -> Callable[[common_pb2.RobotRef], robot_pb2.DescribeRobotRequest]:
    """The DescribeRobotRequest of :meth:`Robot.urdf` for a robot reference
    (shared by the blocking and asyncio clients)."""
    def build(ref: common_pb2.RobotRef) -> robot_pb2.DescribeRobotRequest:
        return robot_pb2.DescribeRobotRequest(robot=ref, include_urdf=True, keep_capsules=keep_capsules)

    return build


def _no_server(target: str, timeout: Optional[float]) -> KinplanError:
    """The :class:`kinplan.errors.Unavailable` of a ``wait_for_ready`` that timed out."""
    return error_for(grpc.StatusCode.UNAVAILABLE, f"no server at {target} within {timeout} s", [])


class RobotRefs:
    """How a robot names itself in requests (shared by :class:`Robot` and
    :class:`kinplan.aio.AsyncRobot`): by name, by model id once the server
    has given one, else (or when resending) the URDF text."""

    name: Optional[str]
    urdf_text: Optional[str]
    base_link: str
    tip_link: str
    model_id: bytes

    def _ref(self, inline: bool = False) -> common_pb2.RobotRef:
        """The RobotRef of this robot's next request: by name, by model id once
        the server has given one, else (or with `inline`) the URDF text.
        Cached while the model id stays the same; callers copy it, never change it."""
        key = (inline, self.model_id)
        cached = self.__dict__.get("_ref_cache")
        if cached is not None and cached[0] == key:
            ref: common_pb2.RobotRef = cached[1]
            return ref
        ref = self._new_ref(inline)
        self.__dict__["_ref_cache"] = (key, ref, length_delimited(ROBOT_REF, ref.SerializeToString()))
        return ref

    def _ref_field(self, ref: common_pb2.RobotRef) -> bytes:
        """`ref` (from :meth:`_ref`) encoded as field 1 of a request, cached with it."""
        cached = self.__dict__.get("_ref_cache")
        if cached is not None and cached[1] is ref:
            encoded: bytes = cached[2]
            return encoded
        return length_delimited(ROBOT_REF, ref.SerializeToString())

    def _new_ref(self, inline: bool) -> common_pb2.RobotRef:
        ref = common_pb2.RobotRef(base_link=self.base_link, tip_link=self.tip_link)
        if self.name is not None:
            ref.name = self.name
        elif self.model_id and not inline:
            ref.model_id = self.model_id
        else:
            ref.urdf = self.urdf_text or ""
        return ref


class Robot(RobotRefs, RobotKinematicsMixin):
    """A robot on a server. Inline URDFs are sent once, then referred to by
    the content hash the server returns; if a replica does not hold it
    (NOT_FOUND), the URDF is sent again by itself."""

    def __init__(self, client: Client, *, name: Optional[str], urdf: Optional[str], base_link: str, tip_link: str,
                 strict: bool = False):
        self.client = client
        self.name = name
        self.urdf_text = urdf
        self.base_link = base_link
        self.tip_link = tip_link
        self.strict = strict
        self.model_id: bytes = b""

    def _limits(self) -> "JointLimits":
        """The chain's joint limits, fetched once per model and chain per client."""
        key = self.limits_key()
        try:
            limits: JointLimits = self.client.__dict__["_limits_cache"][key]
        except KeyError:
            limits = self.client.__dict__.setdefault("_limits_cache", {})[key] = JointLimits(self.describe())
        return limits

    def limits_key(self) -> Any:
        """What identifies this robot's chain in a client's cache."""
        return (self.name, None if self.urdf_text is None else hash(self.urdf_text), self.base_link, self.tip_link)

    def check_limits(self, q: Any, field_name: str = "q") -> None:
        """Warns with :class:`kinplan.JointLimitWarning` (raises
        :class:`kinplan.InvalidArgument` when the robot is strict) if a joint
        value of `q` (one state or rows of states) lies outside the limits:
        kinplan takes radians, and degrees are the usual cause."""
        self._limits().check(q, field_name, self.strict)

    def _send(self, path: str, response: Any, body: bytes, timeout: Optional[float]) -> Any:
        """:meth:`_call` for a request sent as bytes: this robot's reference
        (field 1) and then `body`, the request's other fields already
        encoded; the answer is parsed as `response` (``None``: its bytes are
        returned, and a model id in them is the caller's to read). The same
        retry as :meth:`_call` when a replica does not hold the model id."""
        client = self.client
        cached = self.__dict__.get("_ref_cache")
        if cached is not None and cached[0] == (False, self.model_id):
            ref_field: bytes = cached[2]
        else:
            ref_field = self._ref_field(self._ref())
        method = client._raw_unary(path, response)
        try:
            reply = method(ref_field + body, timeout=client.timeout if timeout is None else timeout)
        except grpc.RpcError as err:
            if not (err.code() == grpc.StatusCode.NOT_FOUND and self.model_id and self.urdf_text):
                raise KinplanError.from_rpc_error(err) from None
            self.model_id = b""
            reply = client._call(method, self._ref_field(self._ref(inline=True)) + body, timeout)
        if response is not None and self.urdf_text is not None and reply.model_id:
            self.model_id = reply.model_id
        return reply

    def _call(self, method: Callable[..., Any], build: Callable[[common_pb2.RobotRef], Any], timeout: Optional[float]) -> Any:
        try:
            reply = self.client._call(method, build(self._ref()), timeout)
        except KinplanError as err:
            if not (err.code == grpc.StatusCode.NOT_FOUND and self.model_id and self.urdf_text):
                raise
            self.model_id = b""
            reply = self.client._call(method, build(self._ref(inline=True)), timeout)
        model_id = getattr(reply, "model_id", b"")
        if model_id and self.urdf_text is not None:
            self.model_id = model_id
        return reply

    def describe(self, *, timeout: Optional[float] = None) -> RobotDescription:
        r = self._call(
            self.client._robots.DescribeRobot,
            lambda ref: robot_pb2.DescribeRobotRequest(robot=ref),
            timeout,
        )
        return RobotDescription.from_proto(r)

    def urdf(self, *, keep_capsules: bool = False, timeout: Optional[float] = None) -> str:
        """The robot's URDF text: a built-in's from the server, in standard URDF
        (each ``<capsule>``, a ROS extension urdfdom and pinocchio refuse,
        written as a cylinder and two end spheres) unless `keep_capsules`;
        an inline model's own text as given."""
        if self.urdf_text is not None:
            return self.urdf_text
        return str(self._call(self.client._robots.DescribeRobot, _urdf_request(keep_capsules), timeout).urdf)

    @overload
    def fk(self, q: npt.ArrayLike, *, links: Literal[False] = False,
           timeout: Optional[float] = None) -> npt.NDArray[np.float64]: ...

    @overload
    def fk(self, q: npt.ArrayLike, *, links: Literal[True],
           timeout: Optional[float] = None) -> Tuple[npt.NDArray[np.float64], Dict[str, npt.NDArray[np.float64]]]: ...

    def fk(self, q: npt.ArrayLike, *, links: bool = False, timeout: Optional[float] = None) -> Any:
        """Tool pose (4x4, base frame, metres) for joint vector `q`; with
        `links=True`, also a dict of every link's 4x4 pose."""
        if links:
            positions = joints(q)
            self.check_limits(positions)
            r = self._call(
                self.client._robots.ForwardKinematics,
                lambda ref: robot_pb2.ForwardKinematicsRequest(
                    robot=ref, joint_positions=positions, include_links=links
                ),
                timeout,
            )
            return pose_to_matrix(r.tool_pose), {link.name: pose_to_matrix(link.pose) for link in r.links}
        # the hot path: the request as bytes (reference, packed joints), the
        # answer read from its bytes when it has the usual layout
        positions, body = joints_and_field(FK_JOINTS, q, "q")
        limits = self._limits()
        lower, upper = limits._lower_list, limits._upper_list
        if not (len(positions) == len(lower) and all(map(operator.le, lower, positions))
                and all(map(operator.le, positions, upper))):
            self.check_limits(positions)  # the whole check: it warns, or raises, naming the joint
        tool, model_id = read_fk_reply(self._send(_FORWARD_KINEMATICS, None, body, timeout))
        if model_id and self.urdf_text is not None:
            self.model_id = model_id
        return tool

    def fk_batch(self, qs: Any, *, jacobians: bool = False, timeout: Optional[float] = None) -> Any:
        """Tool poses of every row of `qs` (n x dof, rad) in one call: an
        (n, 4, 4) array; with `jacobians=True` also the (n, 6, dof)
        Jacobians (rows 0-2 linear, 3-5 angular, base frame)."""
        arr = np.ascontiguousarray(qs, dtype=np.float64)
        if arr.ndim == 1:
            arr = arr[None, :]
        if arr.ndim != 2 or arr.shape[0] == 0:
            raise invalid_argument("qs", f"must be n x dof with n >= 1, got shape {arr.shape}")
        self.check_limits(arr, "qs")
        matrix = matrix_to_proto(arr)
        r = self._call(
            self.client._robots.ForwardKinematicsBatch,
            lambda ref: robot_pb2.ForwardKinematicsBatchRequest(
                robot=ref, joint_positions=matrix, include_jacobians=jacobians
            ),
            timeout,
        )
        return self._batch_reply(r, arr.shape[1], jacobians)

    @staticmethod
    def _batch_reply(r: Any, dof: int, jacobians: bool) -> Any:
        """The (n, 4, 4) poses (and (n, 6, dof) Jacobians) of a batch FK reply."""
        T = poses_to_matrices(np.asarray(r.tool_poses.data, dtype=np.float64))
        if jacobians:
            J = np.asarray(r.jacobians.data, dtype=np.float64).reshape(len(T), 6, dof)
            return T, J
        return T

    def jacobian(self, q: npt.ArrayLike, *, timeout: Optional[float] = None) -> np.ndarray:
        """6 x n geometric Jacobian in the base frame (rows: vx, vy, vz, wx, wy, wz)."""
        positions = joints(q)
        self.check_limits(positions)
        r = self._call(
            self.client._robots.Jacobian,
            lambda ref: robot_pb2.JacobianRequest(robot=ref, joint_positions=positions),
            timeout,
        )
        return matrix_from_proto(r.jacobian)
