"""Inverse kinematics and the linear solvers behind it (KinematicsService).

``robot.ik(T, seed=q0, method="lm")`` returns an :class:`IkResult` with
``.q`` (numpy), ``.success``, ``.position_error``, ``.orientation_error``,
``.iterations``, ``.solutions`` and ``.status``; ``robot.ik_batch(Ts)`` solves
many targets in parallel on the server; ``robot.track(poses | line= | circle=)``
follows a Cartesian path warm-started step to step; ``robot.stream_ik()`` opens
a bidirectional stream for a controller; ``client.solve_linear(A, b)`` solves
``A x = b`` with the SVD pseudoinverse or angle relaxation (RLXA).

A target ``T`` is a 4x4 homogeneous matrix or a ``(position, quaternion)``
pair with the quaternion in the order (x, y, z, w). Units: metres, radians
(metres for prismatic joints), seconds; the robot's base frame (see
proto/kinplan/v1/kinematics.proto).
"""
from __future__ import annotations

import queue
import threading
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Iterable, Iterator, List, Literal, Mapping, Optional, Sequence, Union

import grpc
import numpy as np
import numpy.typing as npt

from ._display import html_table
from ._codec import IK_OPTIONS, IK_SEED, IK_TARGET, joints, joints_field, length_delimited, target_field
from ._convert import matrix_to_pose, matrix_to_proto, pose_bytes, pose_to_matrix
from .errors import KinplanError
from .v1 import common_pb2, kinematics_pb2, kinematics_pb2_grpc

#: IK methods by name (``None``: the server default, Levenberg-Marquardt).
#: IK method names (aliases: "levenberg_marquardt", "ji").
IkMethodName = Literal["lm", "levenberg_marquardt", "jacobian_inverse", "ji", "newton", "ccd", "fabrik",
                       "length_relaxation"]
#: Linear solver names of the Jacobian methods (aliases: "pinv", "rlxa", "rlxa_safeguarded").
LinearSolverName = Literal["svd", "pinv", "angle_relaxation", "rlxa", "angle_relaxation_safeguarded",
                           "rlxa_safeguarded"]

METHODS = {
    None: kinematics_pb2.IK_METHOD_UNSPECIFIED,
    "lm": kinematics_pb2.IK_METHOD_LEVENBERG_MARQUARDT,
    "levenberg_marquardt": kinematics_pb2.IK_METHOD_LEVENBERG_MARQUARDT,
    "jacobian_inverse": kinematics_pb2.IK_METHOD_JACOBIAN_INVERSE,
    "ji": kinematics_pb2.IK_METHOD_JACOBIAN_INVERSE,
    "newton": kinematics_pb2.IK_METHOD_NEWTON,
    "ccd": kinematics_pb2.IK_METHOD_CCD,
    "fabrik": kinematics_pb2.IK_METHOD_FABRIK,
    "length_relaxation": kinematics_pb2.IK_METHOD_LENGTH_RELAXATION,
    "lr": kinematics_pb2.IK_METHOD_LENGTH_RELAXATION,
}

#: Linear solvers by name (``None``: SVD pseudoinverse).
LINEAR_SOLVERS = {
    None: kinematics_pb2.LINEAR_SOLVER_UNSPECIFIED,
    "svd": kinematics_pb2.LINEAR_SOLVER_SVD_PSEUDOINVERSE,
    "pinv": kinematics_pb2.LINEAR_SOLVER_SVD_PSEUDOINVERSE,
    "angle_relaxation": kinematics_pb2.LINEAR_SOLVER_ANGLE_RELAXATION,
    "rlxa": kinematics_pb2.LINEAR_SOLVER_ANGLE_RELAXATION,
    "angle_relaxation_safeguarded": kinematics_pb2.LINEAR_SOLVER_ANGLE_RELAXATION_SAFEGUARDED,
    "rlxa_safeguarded": kinematics_pb2.LINEAR_SOLVER_ANGLE_RELAXATION_SAFEGUARDED,
}

#: Joint-limit handling by name (``None``: clamp).
JOINT_LIMITS = {
    None: kinematics_pb2.JOINT_LIMIT_MODE_UNSPECIFIED,
    "clamp": kinematics_pb2.JOINT_LIMIT_MODE_CLAMP,
    "ignore": kinematics_pb2.JOINT_LIMIT_MODE_IGNORE,
}


def _choice(table: Mapping[Any, int], value: Any, what: str) -> Any:
    """The proto enum value `table` maps `value` to (an int; Any to the
    stubs, whose enum parameters take their own wrapper type)."""
    if value not in table:
        raise ValueError(f"{what} must be one of {[k for k in table if k]}, got {value!r}")
    return table[value]


_IK_STATUS = {v: kinematics_pb2.IkStatus.Name(v).removeprefix("IK_STATUS_").lower() for v in kinematics_pb2.IkStatus.values()}


def _ik_status(value: int) -> str:
    """``"converged"``, ``"max_iterations"``, ``"stalled"``, ``"time_budget"``, ``"cancelled"``."""
    return _IK_STATUS.get(value) or kinematics_pb2.IkStatus.Name(value).removeprefix("IK_STATUS_").lower()


def _is_position(T: Any) -> bool:
    """True for a bare 3-vector (array or sequence of three numbers)."""
    if isinstance(T, np.ndarray):
        return bool(T.shape == (3,))
    return isinstance(T, (list, tuple)) and len(T) == 3 and all(isinstance(v, (int, float)) for v in T)


def target_to_pose(T: Any) -> common_pb2.Pose:
    """A proto Pose from a 4x4 matrix, a (position, quaternion x-y-z-w) pair,
    or a pinocchio / spatialmath SE3 (quaternion objects by their named
    parts: spatialmath's scalar-first ``UnitQuaternion`` is read right)."""
    if isinstance(T, common_pb2.Pose):
        return T
    if isinstance(T, (tuple, list)) and len(T) == 2 and np.asarray(T[0]).shape == (3,):
        return matrix_to_pose((np.asarray(T[0], dtype=float), T[1]))  # type: ignore[arg-type]
    return matrix_to_pose(T)


_SOLVE_IK = "/kinplan.v1.KinematicsService/SolveIk"


def _target_wire(T: Any) -> bytes:
    """The encoded Pose of an IK target (any form :func:`target_to_pose` takes)."""
    if isinstance(T, np.ndarray) and T.shape == (4, 4):
        return pose_bytes(T)
    out: bytes = target_to_pose(T).SerializeToString()
    return out
_IK_OPTIONS_FIELD: Dict[Any, bytes] = {}


def _ik_options_field(*args: Any) -> bytes:
    """The IkOptions of ``ik_options(*args)`` (all its parameters, in order)
    encoded as field 4 of a SolveIkRequest: the same message, cached per
    distinct set of arguments."""
    try:
        cached = _IK_OPTIONS_FIELD.get(args)
    except TypeError:  # an unhashable argument: no cache
        return length_delimited(IK_OPTIONS, _build_ik_options(*args).SerializeToString())
    if cached is None:
        cached = length_delimited(IK_OPTIONS, _build_ik_options(*args).SerializeToString())
        if len(_IK_OPTIONS_FIELD) < 256:
            _IK_OPTIONS_FIELD[args] = cached
    return cached


def _targets(Ts: Any) -> List[common_pb2.Pose]:
    if isinstance(Ts, np.ndarray) and Ts.ndim == 3:
        return [target_to_pose(t) for t in Ts]
    return [target_to_pose(t) for t in Ts]


def ik_options(
    method: Optional[str] = "lm",
    linear_solver: Optional[str] = "svd",
    *,
    position_tolerance: Optional[float] = None,
    orientation_tolerance: Optional[float] = None,
    position_only: bool = False,
    max_iterations: Optional[int] = None,
    damping: Optional[float] = None,
    max_restarts: Optional[int] = None,
    num_solutions: Optional[int] = None,
    rng_seed: int = 0,
    joint_limits: Optional[str] = None,
    time_budget: Optional[float] = None,
    adaptive_damping: Optional[bool] = None,
    max_step: Optional[float] = None,
    distinct_tolerance: Optional[float] = None,
    rlxa_max_iterations: Optional[int] = None,
    history: bool = False,
) -> kinematics_pb2.IkOptions:
    """IkOptions from Python values; ``None`` means the server's documented
    default. Values are checked by the server, which names a bad field.
    Built once per distinct set of arguments (a request copies the message)."""
    key: Any = (method, linear_solver, position_tolerance, orientation_tolerance, position_only, max_iterations,
           damping, max_restarts, num_solutions, rng_seed, joint_limits, time_budget, adaptive_damping,
           max_step, distinct_tolerance, rlxa_max_iterations, history)
    try:
        cached = _IK_OPTIONS_CACHE.get(key)
    except TypeError:  # an unhashable argument: build without the cache
        key, cached = None, None
    if cached is not None:
        out = kinematics_pb2.IkOptions()
        out.CopyFrom(cached)  # callers may change theirs
        return out
    o = _build_ik_options(method, linear_solver, position_tolerance, orientation_tolerance, position_only,
                          max_iterations, damping, max_restarts, num_solutions, rng_seed, joint_limits,
                          time_budget, adaptive_damping, max_step, distinct_tolerance, rlxa_max_iterations, history)
    if key is not None and len(_IK_OPTIONS_CACHE) < 256:
        _IK_OPTIONS_CACHE[key] = kinematics_pb2.IkOptions()
        _IK_OPTIONS_CACHE[key].CopyFrom(o)
    return o


_IK_OPTIONS_CACHE: Dict[Any, kinematics_pb2.IkOptions] = {}


def _build_ik_options(method: Any, linear_solver: Any, position_tolerance: Any, orientation_tolerance: Any,
                      position_only: Any, max_iterations: Any, damping: Any, max_restarts: Any,
                      num_solutions: Any, rng_seed: Any, joint_limits: Any, time_budget: Any,
                      adaptive_damping: Any, max_step: Any, distinct_tolerance: Any, rlxa_max_iterations: Any,
                      history: Any) -> kinematics_pb2.IkOptions:
    o = kinematics_pb2.IkOptions(
        method=_choice(METHODS, method, "method"),
        linear_solver=_choice(LINEAR_SOLVERS, linear_solver, "linear_solver"),
        position_only=bool(position_only),
        max_iterations=int(max_iterations or 0),
        num_solutions=int(num_solutions or 0),
        rng_seed=int(rng_seed),
        joint_limits=_choice(JOINT_LIMITS, joint_limits, "joint_limits"),
        return_history=bool(history),
    )
    for name, value, kind in (
        ("position_tolerance", position_tolerance, float),
        ("orientation_tolerance", orientation_tolerance, float),
        ("damping", damping, float),
        ("max_restarts", max_restarts, int),
        ("time_budget", time_budget, float),
        ("adaptive_damping", adaptive_damping, bool),
        ("max_step", max_step, float),
        ("distinct_tolerance", distinct_tolerance, float),
        ("rlxa_max_iterations", rlxa_max_iterations, int),
    ):
        if value is not None:
            setattr(o, name, kind(value))
    return o


@dataclass
class IkSolution:
    """One answer: joints ``q`` (rad, m for prismatic joints), errors of its
    true FK (m, rad), iterations of its attempt, µs since the request began,
    the attempt's status and index (0 = from the seed). With ``history=True``
    in the request, ``history`` is an (iterations + 1) x 2 array of the
    (position m, orientation rad) error at the start of every iteration."""

    q: np.ndarray
    position_error: float
    orientation_error: float
    iterations: int
    elapsed_us: int
    status: str
    attempt: int
    history: Optional[np.ndarray] = None

    @classmethod
    def from_proto(cls, s: kinematics_pb2.IkSolution) -> "IkSolution":
        # positional, in field order: the hot path of every IK answer
        return cls(
            np.array(s.joints[:], dtype=float),  # a list first: ~3x faster than asarray for a few values
            s.position_error,
            s.orientation_error,
            s.iterations,
            s.elapsed_us,
            _IK_STATUS.get(s.status) or _ik_status(s.status),
            s.attempt,
            (
                np.column_stack([s.position_error_history, s.orientation_error_history])
                if len(s.position_error_history)
                else None
            ),
        )


@dataclass
class IkResult:
    """The answer to one target.

    ``success``: at least one solution converged. ``q`` and the errors are
    those of the first solution (nearest to the seed) -- or, when nothing
    converged, of ``best_attempt``, which is **not** a solution: check
    ``success``. ``status`` is why the search stopped ("converged",
    "max_iterations", "time_budget", "cancelled")."""

    success: bool
    q: Optional[np.ndarray]
    position_error: float
    orientation_error: float
    iterations: int
    status: str
    solutions: List[IkSolution]
    best_attempt: Optional[IkSolution]
    attempts: int
    total_iterations: int
    elapsed_us: int
    #: The request's sequence number (StreamIk answers only).
    sequence: Optional[int] = None
    raw: Any = field(default=None, repr=False)

    def _repr_html_(self) -> str:
        return html_table("IkResult", [
            ("success", self.success), ("status", self.status),
            ("position error (m)", self.position_error), ("orientation error (rad)", self.orientation_error),
            ("solutions", len(self.solutions)), ("attempts", self.attempts), ("elapsed (us)", self.elapsed_us),
        ])

    def __repr__(self) -> str:
        return (
            f"IkResult(success={self.success}, status={self.status!r}, position_error={self.position_error:.2e} m, "
            f"orientation_error={self.orientation_error:.2e} rad, solutions={len(self.solutions)}, "
            f"attempts={self.attempts}, {self.elapsed_us} us)"
        )

    @classmethod
    def from_proto(cls, r: kinematics_pb2.SolveIkResponse) -> "IkResult":
        """The result of a SolveIkResponse. Only ``success`` and ``raw`` are
        read at once; every other field is built from ``raw`` when first
        read (then kept, see :class:`_LazyIkField`), so a caller pays for
        what it reads: an answer is most often read for ``success`` and
        ``q`` alone. The values are those the eager build gave (``q`` is
        ``solutions[0].q``, the same array, else ``best_attempt.q``)."""
        out = cls.__new__(cls)
        out.success = r.success
        out.raw = r
        return out

    def __bool__(self) -> bool:
        return self.success


class _LazyIkField:
    """A field of :class:`IkResult` built from ``raw`` on first read.

    A non-data descriptor set on the class after the dataclass is made (so
    ``__init__`` and ``dataclasses.fields`` are unchanged): an instance's own
    value always wins, so it only runs for a field an answer from
    ``IkResult.from_proto`` has not built yet, stores the value in the
    instance and is not called again for it. The head fields (``q``, the two
    errors, ``iterations``) are built together, from the first solution or,
    when there is none, from ``best_attempt``."""

    def __init__(self, name: str):
        self.name = name

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        d = obj.__dict__
        r = d.get("raw")
        if r is None:  # not from from_proto: the field was never set
            raise AttributeError(f"'IkResult' object has no attribute {self.name!r}")
        name = self.name
        if name in _IK_HEAD_FIELDS:
            solutions = d.get("solutions")
            if solutions is None and len(r.solutions):
                s = r.solutions[0]
                d["q"] = np.array(s.joints[:])  # float64 from a list of floats; a list first: ~3x faster than asarray
                d["position_error"], d["orientation_error"], d["iterations"] = (
                    s.position_error, s.orientation_error, s.iterations)
            else:
                head = solutions[0] if solutions else obj.best_attempt
                if head is None:
                    d["q"], d["position_error"], d["orientation_error"], d["iterations"] = (
                        None, float("nan"), float("nan"), 0)
                else:
                    d["q"], d["position_error"], d["orientation_error"], d["iterations"] = (
                        head.q, head.position_error, head.orientation_error, head.iterations)
        elif name == "solutions":
            solutions = [IkSolution.from_proto(s) for s in r.solutions]
            q = d.get("q")
            if solutions and q is not None:
                solutions[0].q = q  # the head's array, shared as in the eager build
            d["solutions"] = solutions
        elif name == "best_attempt":
            # (with no solutions the head fields are read from it, so it is built before them)
            d["best_attempt"] = IkSolution.from_proto(r.best_attempt) if r.HasField("best_attempt") else None
        elif name == "status":
            d["status"] = _IK_STATUS.get(r.status) or _ik_status(r.status)
        else:  # attempts, total_iterations, elapsed_us
            d[name] = getattr(r, name)
        return d[name]


#: The fields of the first solution (or of the best attempt) that IkResult repeats.
_IK_HEAD_FIELDS = frozenset(("q", "position_error", "orientation_error", "iterations"))
for _name in sorted(_IK_HEAD_FIELDS | {"status", "solutions", "best_attempt", "attempts", "total_iterations",
                                       "elapsed_us"}):
    setattr(IkResult, _name, _LazyIkField(_name))
del _name


@dataclass
class IkBatchResult:
    """``results[i]`` answers target i. ``q`` stacks each result's ``q``
    (n x dof; rows of targets that did not converge hold the best attempt),
    ``success`` is a boolean array."""

    results: List[IkResult]
    succeeded: int
    elapsed_us: int

    def __repr__(self) -> str:
        return f"IkBatchResult({self.succeeded}/{len(self.results)} solved, {self.elapsed_us} us)"

    @property
    def q(self) -> np.ndarray:
        return np.stack([r.q for r in self.results if r.q is not None])

    @property
    def success(self) -> np.ndarray:
        return np.array([r.success for r in self.results], dtype=bool)

    @property
    def position_error(self) -> np.ndarray:
        return np.array([r.position_error for r in self.results])

    @property
    def orientation_error(self) -> np.ndarray:
        return np.array([r.orientation_error for r in self.results])

    def __len__(self) -> int:
        return len(self.results)

    def __getitem__(self, i: int) -> IkResult:
        return self.results[i]

    def __iter__(self) -> Iterator[IkResult]:
        return iter(self.results)


@dataclass
class TrackResult:
    """A tracked Cartesian path, one row per step: ``q`` (n x dof joint path),
    ``targets`` (n x 4 x 4 poses aimed at), ``position_error`` (m),
    ``orientation_error`` (rad), ``iterations``, ``elapsed_us``, ``status``
    and ``joint_step`` (largest |Δq| from the previous step, rad; the first
    against the seed). ``max_joint_step`` is the largest over the path."""

    q: np.ndarray
    targets: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    iterations: np.ndarray
    elapsed_us: np.ndarray
    status: List[str]
    joint_step: np.ndarray
    max_joint_step: float
    all_converged: bool
    stop_reason: str
    total_elapsed_us: int
    raw: Any = field(default=None, repr=False)

    def __repr__(self) -> str:
        worst = float(np.max(self.position_error)) if len(self.position_error) else 0.0
        return (
            f"TrackResult({len(self.q)} targets, all_converged={self.all_converged}, "
            f"max position error {worst:.2e} m, max joint step {self.max_joint_step:.3f} rad, "
            f"stop_reason={self.stop_reason!r}, {self.total_elapsed_us} us)"
        )

    @classmethod
    def from_proto(cls, r: kinematics_pb2.TrackPathResponse) -> "TrackResult":
        steps = r.steps
        dof = len(steps[0].joints) if len(steps) else 0
        return cls(
            q=np.array([s.joints for s in steps], dtype=float).reshape(len(steps), dof),
            targets=np.array([pose_to_matrix(s.target) for s in steps]).reshape(len(steps), 4, 4),
            position_error=np.array([s.position_error for s in steps]),
            orientation_error=np.array([s.orientation_error for s in steps]),
            iterations=np.array([s.iterations for s in steps], dtype=int),
            elapsed_us=np.array([s.elapsed_us for s in steps], dtype=int),
            status=[_ik_status(s.status) for s in steps],
            joint_step=np.array([s.max_joint_step for s in steps]),
            max_joint_step=r.max_joint_step,
            all_converged=r.all_converged,
            stop_reason=_ik_status(r.status),
            total_elapsed_us=r.elapsed_us,
            raw=r,
        )

    @property
    def success(self) -> bool:
        return self.all_converged

    def __len__(self) -> int:
        return len(self.q)


@dataclass
class LinearSolution:
    """``x`` of ``A x = b``, ``residual_norm`` = |b - A x|, iterations (1 for
    the SVD), ``status`` ("converged" or "iteration_cap"), and the residual
    after every iteration when asked for (``history``)."""

    x: np.ndarray
    residual_norm: float
    iterations: int
    status: str
    history: np.ndarray
    elapsed_us: int

    @property
    def converged(self) -> bool:
        return self.status == "converged"


def _track_request(poses: Any, seed: Optional[npt.ArrayLike], line: Optional[Mapping[str, Any]],
                   circle: Optional[Mapping[str, Any]], method: Optional[str], linear_solver: Optional[str],
                   stop_on_failure: bool, options: Dict[str, Any],
                   ) -> Callable[[common_pb2.RobotRef], kinematics_pb2.TrackPathRequest]:
    """The TrackPathRequest of :meth:`RobotKinematicsMixin.track`'s arguments
    for a robot reference (shared by the blocking and asyncio clients)."""
    o = ik_options(method, linear_solver, **options)
    seed_list = [] if seed is None else joints(seed, "seed")
    kwargs: Dict[str, Any] = {}
    if poses is not None:
        kwargs["poses"] = _targets(poses)
    if line is not None:
        spec = dict(line)
        lp = kinematics_pb2.LinePath(steps=int(spec.pop("steps", 0)))
        if spec.get("start") is not None:
            lp.start.CopyFrom(target_to_pose(spec["start"]))
        spec.pop("start", None)
        if spec.get("end") is not None:
            lp.end.CopyFrom(target_to_pose(spec["end"]))
        spec.pop("end", None)
        if spec:
            raise ValueError(f"unknown line keys {sorted(spec)}")
        kwargs["line"] = lp
    if circle is not None:
        spec = dict(circle)
        cp = kinematics_pb2.CirclePath(angle_step=float(spec.pop("angle_step", 0.0)), steps=int(spec.pop("steps", 0)))
        if spec.get("start") is not None:
            cp.start.CopyFrom(target_to_pose(spec["start"]))
        spec.pop("start", None)
        for key in ("centre", "normal"):
            value = spec.pop(key, spec.pop("center", None) if key == "centre" else None)
            if value is not None:
                v = np.asarray(value, dtype=float).ravel()
                getattr(cp, key).CopyFrom(common_pb2.Vec3(x=v[0], y=v[1], z=v[2]))
        if spec:
            raise ValueError(f"unknown circle keys {sorted(spec)}")
        kwargs["circle"] = cp

    def build(ref: common_pb2.RobotRef) -> kinematics_pb2.TrackPathRequest:
        return kinematics_pb2.TrackPathRequest(
            robot=ref, seed=seed_list, options=o, stop_on_failure=stop_on_failure, **kwargs
        )

    return build


def _solve_linear_request(A: Any, b: Any, method: Optional[str], max_iterations: Optional[int],
                          tolerance: Optional[float], relative_tolerance: Optional[float], rng_seed: int,
                          history: bool, singular_value_tolerance: Optional[float],
                          ) -> kinematics_pb2.SolveLinearSystemRequest:
    """The SolveLinearSystemRequest of :meth:`KinematicsMixin.solve_linear`'s arguments."""
    a = np.asarray(A, dtype=float)
    if a.ndim != 2:
        raise ValueError(f"A must be two-dimensional, got shape {a.shape}")
    rhs = np.asarray(b, dtype=float).ravel()
    request = kinematics_pb2.SolveLinearSystemRequest(
        a=matrix_to_proto(a),
        b=rhs.tolist(),
        method=_choice(LINEAR_SOLVERS, method, "method"),
        max_iterations=int(max_iterations or 0),
        rng_seed=int(rng_seed),
        record_history=bool(history),
    )
    if tolerance is not None:
        request.tolerance = float(tolerance)
    if relative_tolerance is not None:
        request.relative_tolerance = float(relative_tolerance)
    if singular_value_tolerance is not None:
        request.singular_value_tolerance = float(singular_value_tolerance)
    return request


def _linear_solution(reply: kinematics_pb2.SolveLinearSystemResponse) -> LinearSolution:
    """The :class:`LinearSolution` of a SolveLinearSystem reply."""
    return LinearSolution(
        x=np.asarray(reply.x, dtype=float),
        residual_norm=reply.residual_norm,
        iterations=reply.iterations,
        status=kinematics_pb2.LinearSolveStatus.Name(reply.status).removeprefix("LINEAR_SOLVE_STATUS_").lower(),
        history=np.asarray(reply.residual_history, dtype=float),
        elapsed_us=reply.elapsed_us,
    )


class IkStream:
    """A ``StreamIk`` call: send targets, read answers in order, each
    warm-started from the previous answer. Use as a context manager::

        with robot.stream_ik(time_budget=0.004) as s:
            for T in targets:
                r = s.solve(T)            # send + wait: one controller cycle
            s.send(T1); s.send(T2)        # or pipeline...
            a1, a2 = next(s), next(s)     # ...and read the answers in order

    Each answer is an :class:`IkResult` with ``sequence`` set. A bad target
    ends the stream: the next read raises :class:`KinplanError` naming the
    field and the message's sequence number.
    """

    _END = object()

    def __init__(self, robot: Any, options: kinematics_pb2.IkOptions, seed: Optional[npt.ArrayLike], timeout: Optional[float]):
        self._robot = robot
        self._options = options
        self._seed = None if seed is None else joints(seed, "seed")
        self._queue: "queue.Queue[Any]" = queue.Queue()
        self._sequence = 0
        self._first = True
        self._lock = threading.Lock()
        self._closed = False
        stub = robot.client._kinematics
        self._call = stub.StreamIk(self._requests(), timeout=timeout)

    def _requests(self) -> Iterator[kinematics_pb2.StreamIkRequest]:
        while True:
            item = self._queue.get()
            if item is IkStream._END:
                return
            yield item

    def send(self, T: Any, seed: Optional[npt.ArrayLike] = None) -> int:
        """Queues a target; returns its sequence number."""
        if self._closed:
            raise RuntimeError("the stream is closed")
        with self._lock:
            self._sequence += 1
            msg = kinematics_pb2.StreamIkRequest(sequence=self._sequence, target=target_to_pose(T))
            if self._first:
                msg.robot.CopyFrom(self._robot._ref(inline=self._robot.urdf_text is not None))
                msg.options.CopyFrom(self._options)
                if self._seed is not None and seed is None:
                    seed = self._seed
                self._first = False
            if seed is not None:
                msg.seed.extend(joints(seed, "seed"))
            self._queue.put(msg)
            return self._sequence

    def __next__(self) -> IkResult:
        try:
            reply = next(self._call)
        except grpc.RpcError as err:
            raise KinplanError.from_rpc_error(err) from None
        out = IkResult.from_proto(reply.result)
        out.sequence = reply.sequence
        return out

    def __iter__(self) -> "IkStream":
        return self

    def solve(self, T: Any, seed: Optional[npt.ArrayLike] = None) -> IkResult:
        """Sends one target and waits for its answer."""
        self.send(T, seed)
        return next(self)

    def close(self) -> None:
        """Ends the request side; the server then ends the stream."""
        if not self._closed:
            self._closed = True
            self._queue.put(IkStream._END)

    def cancel(self) -> None:
        self.close()
        self._call.cancel()

    def __enter__(self) -> "IkStream":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
        # drain what is left so that the call ends cleanly
        try:
            for _ in self._call:
                pass
        except grpc.RpcError:
            pass


class RobotKinematicsMixin:
    """Adds :meth:`ik`, :meth:`ik_batch`, :meth:`track` and :meth:`stream_ik`
    to :class:`kinplan.Robot`."""

    def ik(
        self,
        T: Any,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[IkMethodName] = "lm",
        linear_solver: Optional[LinearSolverName] = "svd",
        *,
        max_restarts: Optional[int] = None,
        num_solutions: Optional[int] = None,
        position_tolerance: Optional[float] = None,
        orientation_tolerance: Optional[float] = None,
        position_only: bool = False,
        max_iterations: Optional[int] = None,
        damping: Optional[float] = None,
        rng_seed: int = 0,
        joint_limits: Optional[Literal["clamp", "ignore"]] = None,
        time_budget: Optional[float] = None,
        adaptive_damping: Optional[bool] = None,
        max_step: Optional[float] = None,
        distinct_tolerance: Optional[float] = None,
        rlxa_max_iterations: Optional[int] = None,
        history: bool = False,
        timeout: Optional[float] = None,
    ) -> IkResult:
        """Joints that put the tool at ``T`` (4x4, or (position, quaternion
        xyzw), or a bare position 3-vector, which means ``position_only``),
        base frame. ``method``: "lm" (default), "jacobian_inverse",
        "newton", "ccd", "fabrik", "length_relaxation"; ``linear_solver``
        (Jacobian methods): "svd" (default), "angle_relaxation",
        "angle_relaxation_safeguarded". Tolerances in m and rad (default
        1e-5); ``max_restarts`` (default 200) random restarts from
        ``rng_seed``; ``num_solutions`` distinct solutions ranked by distance
        to ``seed``. Further options: ``max_iterations``, ``damping``,
        ``rng_seed``, ``joint_limits`` ("clamp"/"ignore"), ``time_budget``
        (s; default: the call's deadline), ``adaptive_damping``,
        ``max_step``, ``distinct_tolerance``, ``rlxa_max_iterations``,
        ``history`` (True: each solution carries its per-iteration errors).

        Which combinations converge (1,000 random reachable targets per arm,
        5 ms budget, ``benches/IK_RESULTS.md`` §0.5): "lm", "jacobian_inverse"
        and "newton" with "svd" solve 100 % on all six built-in arms in
        ~20-30 us median; with "angle_relaxation" 84-96 % (slower); "ccd"
        20-58 % on 6-axis arms; "newton" + "angle_relaxation" solves 0 %,
        as S2 predicts (the relaxation's inexact solve is not accurate enough
        for Newton's fixed-point step): do not use it. "fabrik" and
        "length_relaxation" take position targets only."""
        matrix = isinstance(T, np.ndarray) and T.shape == (4, 4)  # the usual target: packed in one step
        # a bare 3-vector is a position: solve for it alone
        if not matrix and _is_position(T):
            T = (np.asarray(T, dtype=float), np.array([0.0, 0.0, 0.0, 1.0]))
            position_only = True
        key = (method, linear_solver, position_tolerance, orientation_tolerance, position_only, max_iterations,
               damping, max_restarts, num_solutions, rng_seed, joint_limits, time_budget, adaptive_damping,
               max_step, distinct_tolerance, rlxa_max_iterations, history)
        try:
            options_field = _IK_OPTIONS_FIELD[key]
        except (KeyError, TypeError):  # first use of these arguments, or an unhashable one
            options_field = _ik_options_field(*key)
        # the request goes out as bytes built field by field: no message objects
        target = target_field(T) if matrix else length_delimited(IK_TARGET, _target_wire(T))
        body = target + (b"" if seed is None else joints_field(IK_SEED, seed, "seed")) + options_field
        reply = self._send(_SOLVE_IK, kinematics_pb2.SolveIkResponse, body, timeout)  # type: ignore[attr-defined]
        return IkResult.from_proto(reply)

    def ik_batch(
        self,
        Ts: Any,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[str] = "lm",
        linear_solver: Optional[str] = "svd",
        *,
        timeout: Optional[float] = None,
        **options: Any,
    ) -> IkBatchResult:
        """Solves every target of ``Ts`` (n x 4 x 4 array, or a list of 4x4
        matrices / (position, quaternion) pairs) in parallel on the server,
        each from ``seed``: one joint vector for all targets, or an (n x dof)
        array with one seed per target. Options as :meth:`ik`; ``time_budget`` is per
        target, the call's deadline bounds the batch."""
        o = ik_options(method, linear_solver, **options)
        targets = _targets(Ts)
        seed_arr = None if seed is None else np.asarray(seed, dtype=np.float64)
        per_target = None
        seed_list: List[float] = []
        if seed_arr is not None and seed_arr.ndim == 2:
            per_target = matrix_to_proto(seed_arr)
        elif seed is not None:
            seed_list = joints(seed, "seed")
        reply = self._call(  # type: ignore[attr-defined]
            self.client._kinematics.SolveIkBatch,  # type: ignore[attr-defined]
            lambda ref: kinematics_pb2.SolveIkBatchRequest(
                robot=ref, targets=targets, seed=seed_list, options=o, seeds=per_target
            ),
            timeout,
        )
        return IkBatchResult(
            results=[IkResult.from_proto(r) for r in reply.results],
            succeeded=reply.succeeded,
            elapsed_us=reply.elapsed_us,
        )

    def track(
        self,
        poses: Any = None,
        seed: Optional[npt.ArrayLike] = None,
        *,
        line: Optional[Mapping[str, Any]] = None,
        circle: Optional[Mapping[str, Any]] = None,
        method: Optional[str] = "lm",
        linear_solver: Optional[str] = "svd",
        stop_on_failure: bool = False,
        timeout: Optional[float] = None,
        **options: Any,
    ) -> TrackResult:
        """Follows a Cartesian path step by step, each step warm-started from
        the previous one (no restarts unless ``max_restarts`` is given).
        Give exactly one of ``poses`` (n x 4 x 4, or a list of targets),
        ``line={"end": T, "steps": 20, "start": T0}`` or ``circle={"centre":
        (x, y, z), "normal": (0, 0, 1), "angle_step": pi/50, "steps": 100,
        "start": T0}`` (``start`` defaults to the tool pose at ``seed``).
        ``seed`` defaults to the middle of the joint limits. Options as
        :meth:`ik`; ``time_budget`` bounds the whole path."""
        build = _track_request(poses, seed, line, circle, method, linear_solver, stop_on_failure, options)
        reply = self._call(self.client._kinematics.TrackPath, build, timeout)  # type: ignore[attr-defined]
        return TrackResult.from_proto(reply)

    def stream_ik(
        self,
        seed: Optional[npt.ArrayLike] = None,
        method: Optional[str] = "lm",
        linear_solver: Optional[str] = "svd",
        *,
        timeout: Optional[float] = None,
        **options: Any,
    ) -> IkStream:
        """Opens a ``StreamIk`` call (see :class:`IkStream`). The first
        target starts from ``seed`` (default: middle of the limits), every
        later one from the previous answer. Options as :meth:`ik` (default
        ``max_restarts`` 0; ``time_budget`` per target). ``timeout`` bounds
        the whole stream (default: none -- a controller's stream lasts as
        long as the controller runs)."""
        o = ik_options(method, linear_solver, **options)
        return IkStream(self, o, seed, timeout)


class KinematicsMixin:
    """Adds :meth:`solve_linear` (and the stub the robots' IK calls use) to
    :class:`kinplan.Client`."""

    @property
    def _kinematics(self) -> kinematics_pb2_grpc.KinematicsServiceStub:
        stub = self.__dict__.get("_kinematics_stub")
        if stub is None:
            stub = kinematics_pb2_grpc.KinematicsServiceStub(self._channel)  # type: ignore[attr-defined]
            self.__dict__["_kinematics_stub"] = stub
        return stub

    def solve_linear(
        self,
        A: Any,
        b: Any,
        method: Optional[str] = "svd",
        *,
        max_iterations: Optional[int] = None,
        tolerance: Optional[float] = None,
        relative_tolerance: Optional[float] = None,
        rng_seed: int = 0,
        history: bool = False,
        singular_value_tolerance: Optional[float] = None,
        timeout: Optional[float] = None,
    ) -> LinearSolution:
        """Solves ``A x = b`` for any m x n ``A``: ``method="svd"`` (least
        squares, minimum norm) or ``"angle_relaxation"`` /
        ``"angle_relaxation_safeguarded"`` (RLXA: ``max_iterations``, default
        20,000; ``tolerance`` on |b - A x|, default 0.01; ``rng_seed``;
        ``history=True`` returns the residual after every iteration)."""
        request = _solve_linear_request(A, b, method, max_iterations, tolerance, relative_tolerance, rng_seed,
                                        history, singular_value_tolerance)
        reply = self._call(self._kinematics.SolveLinearSystem, request, timeout)  # type: ignore[attr-defined]
        return _linear_solution(reply)


__all__ = [
    "IkBatchResult",
    "IkResult",
    "IkSolution",
    "IkStream",
    "JOINT_LIMITS",
    "KinematicsMixin",
    "LINEAR_SOLVERS",
    "LinearSolution",
    "METHODS",
    "RobotKinematicsMixin",
    "TrackResult",
    "ik_options",
    "target_to_pose",
]
