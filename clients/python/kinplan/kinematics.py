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

from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Literal, Mapping, Optional, Tuple

import numpy as np

from ._display import html_table
from ._codec import IK_OPTIONS, length_delimited
from ._convert import matrix_to_pose, pose_bytes, pose_to_matrix
from .v1 import common_pb2, kinematics_pb2

#: IK methods by name (``None``: the server default, Levenberg-Marquardt).
#: IK method names (aliases: "levenberg_marquardt", "ji").
IkMethodName = Literal["lm", "levenberg_marquardt", "jacobian_inverse", "ji", "newton", "ccd", "fabrik",
                       "length_relaxation", "analytic"]
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
    "analytic": kinematics_pb2.IK_METHOD_ANALYTIC,
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
    hold_configuration: Optional[bool] = None,
    nearest_turn_only: bool = False,
    redundant_joint: Optional[int] = None,
    analytic_start: bool = False,
    search_redundant: bool = False,
    redundant_samples: Optional[int] = None,
    search_samples: Optional[int] = None,
) -> kinematics_pb2.IkOptions:
    """IkOptions from Python values; ``None`` means the server's documented
    default. Values are checked by the server, which names a bad field.
    Built once per distinct set of arguments (a request copies the message)."""
    key: Any = (method, linear_solver, position_tolerance, orientation_tolerance, position_only, max_iterations,
           damping, max_restarts, num_solutions, rng_seed, joint_limits, time_budget, adaptive_damping,
           max_step, distinct_tolerance, rlxa_max_iterations, history, hold_configuration, nearest_turn_only,
           redundant_joint, analytic_start, search_redundant, redundant_samples, search_samples)
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
                          time_budget, adaptive_damping, max_step, distinct_tolerance, rlxa_max_iterations, history,
                          hold_configuration, nearest_turn_only, redundant_joint, analytic_start,
                          search_redundant, redundant_samples, search_samples)
    if key is not None and len(_IK_OPTIONS_CACHE) < 256:
        _IK_OPTIONS_CACHE[key] = kinematics_pb2.IkOptions()
        _IK_OPTIONS_CACHE[key].CopyFrom(o)
    return o


_IK_OPTIONS_CACHE: Dict[Any, kinematics_pb2.IkOptions] = {}


def _build_ik_options(method: Any, linear_solver: Any, position_tolerance: Any, orientation_tolerance: Any,
                      position_only: Any, max_iterations: Any, damping: Any, max_restarts: Any,
                      num_solutions: Any, rng_seed: Any, joint_limits: Any, time_budget: Any,
                      adaptive_damping: Any, max_step: Any, distinct_tolerance: Any, rlxa_max_iterations: Any,
                      history: Any, hold_configuration: Any = None, nearest_turn_only: Any = False,
                      redundant_joint: Any = None, analytic_start: Any = False, search_redundant: Any = False,
                      redundant_samples: Any = None, search_samples: Any = None) -> kinematics_pb2.IkOptions:
    o = kinematics_pb2.IkOptions(
        method=_choice(METHODS, method, "method"),
        linear_solver=_choice(LINEAR_SOLVERS, linear_solver, "linear_solver"),
        position_only=bool(position_only),
        max_iterations=int(max_iterations or 0),
        num_solutions=int(num_solutions or 0),
        rng_seed=int(rng_seed),
        joint_limits=_choice(JOINT_LIMITS, joint_limits, "joint_limits"),
        return_history=bool(history),
        nearest_turn_only=bool(nearest_turn_only),
        analytic_start=bool(analytic_start),
        search_redundant=bool(search_redundant),
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
        ("hold_configuration", hold_configuration, bool),
        ("redundant_joint", redundant_joint, int),
        ("redundant_samples", redundant_samples, int),
        ("search_samples", search_samples, int),
    ):
        if value is not None:
            setattr(o, name, kind(value))
    return o


#: The IkOptions fields in the order :func:`ik_options` takes them (its last
#: keyword, ``history``, is the proto's ``return_history``).
IK_OPTION_FIELDS = ("method", "linear_solver", "position_tolerance", "orientation_tolerance", "position_only",
                    "max_iterations", "damping", "max_restarts", "num_solutions", "rng_seed", "joint_limits",
                    "time_budget", "adaptive_damping", "max_step", "distinct_tolerance", "rlxa_max_iterations",
                    "return_history", "hold_configuration", "nearest_turn_only", "redundant_joint", "analytic_start",
                    "search_redundant", "redundant_samples", "search_samples")
#: The keyword shortcuts of ``robot.ik`` and friends, in the same order.
IK_SHORTCUTS = tuple("history" if f == "return_history" else f for f in IK_OPTION_FIELDS)


@dataclass(frozen=True)
class IkOptions:
    """The options of an IK request, field for field the proto's
    ``kinplan.v1.IkOptions`` (and the Rust client's ``IkOptions``);
    ``None`` means the server's documented default.

    ``method``: "lm" (Levenberg-Marquardt), "jacobian_inverse", "newton",
    "ccd", "fabrik", "length_relaxation", "analytic" (closed form: every
    solution, 6- and 7-joint arms of the families ``RobotDescription.analytic_family``
    names); ``linear_solver`` (Jacobian
    methods): "svd", "angle_relaxation", "angle_relaxation_safeguarded";
    tolerances in m and rad; ``max_restarts`` random restarts drawn from
    ``rng_seed``; ``num_solutions`` distinct solutions (two differ when a
    joint differs by more than ``distinct_tolerance``); ``joint_limits``
    "clamp" or "ignore"; ``time_budget`` in s; ``adaptive_damping``,
    ``damping`` and ``max_step`` steer the Jacobian step;
    ``rlxa_max_iterations`` caps the angle-relaxation solve;
    ``return_history`` returns each solution's per-iteration errors;
    ``hold_configuration``, ``nearest_turn_only`` and ``redundant_joint``
    steer ``method="analytic"`` (the seed's configuration first; one
    whole-turn variant per joint; the joint of a 7-joint arm held at the
    seed's value); ``search_redundant`` searches that joint's value (within
    its limits, ``redundant_samples`` samples then a refinement) for the
    solution nearest the seed instead; ``search_samples`` (8 to 4096,
    default 128) is how densely ``method="analytic"`` samples the searched
    wrist joint of an offset-wrist arm (family ``searched_6r``: two solutions
    of one branch closer than 2π/search_samples rad in that joint can be
    missed); ``analytic_start`` starts the
    iterative methods from the closed-form solution nearest the seed.

    Pass it as ``robot.ik(T, options=IkOptions(...))`` (also ``ik_batch``,
    ``track``, ``stream_ik``); a keyword shortcut given beside it
    (``robot.ik(T, options=o, max_restarts=0)``) replaces that field when it
    is not the keyword's default. Frozen: ``dataclasses.replace(o, ...)``
    makes a variant."""

    method: Optional[IkMethodName] = "lm"
    linear_solver: Optional[LinearSolverName] = "svd"
    position_tolerance: Optional[float] = None
    orientation_tolerance: Optional[float] = None
    position_only: bool = False
    max_iterations: Optional[int] = None
    damping: Optional[float] = None
    max_restarts: Optional[int] = None
    num_solutions: Optional[int] = None
    rng_seed: int = 0
    joint_limits: Optional[Literal["clamp", "ignore"]] = None
    time_budget: Optional[float] = None
    adaptive_damping: Optional[bool] = None
    max_step: Optional[float] = None
    distinct_tolerance: Optional[float] = None
    rlxa_max_iterations: Optional[int] = None
    return_history: bool = False
    hold_configuration: Optional[bool] = None
    nearest_turn_only: bool = False
    redundant_joint: Optional[int] = None
    analytic_start: bool = False
    search_redundant: bool = False
    redundant_samples: Optional[int] = None
    search_samples: Optional[int] = None

    def __post_init__(self) -> None:
        _choice(METHODS, self.method, "method")
        _choice(LINEAR_SOLVERS, self.linear_solver, "linear_solver")
        _choice(JOINT_LIMITS, self.joint_limits, "joint_limits")

    def args(self) -> Tuple[Any, ...]:
        """The fields in :data:`IK_OPTION_FIELDS` order (:func:`ik_options`'s arguments)."""
        return tuple(getattr(self, name) for name in IK_OPTION_FIELDS)

    def to_proto(self) -> kinematics_pb2.IkOptions:
        return ik_options_of_args(self.args())


#: The shortcuts' defaults: a shortcut at its default leaves the field of ``options`` as it is.
_SHORTCUT_DEFAULTS = IkOptions().args()


def resolve_ik_args(options: Optional[IkOptions], args: Tuple[Any, ...]) -> Tuple[Any, ...]:
    """The options of a call: `args` (the shortcuts, in :data:`IK_SHORTCUTS`
    order) over `options`; a shortcut at its default keeps the field of `options`."""
    if options is None:
        return args
    if not isinstance(options, IkOptions):
        raise TypeError(f"options must be a kinplan.IkOptions, got {type(options).__name__}")
    return tuple(o if (a is d or a == d) else a for a, d, o in zip(args, _SHORTCUT_DEFAULTS, options.args()))


def ik_args(method: Any, linear_solver: Any, shortcuts: Mapping[str, Any]) -> Tuple[Any, ...]:
    """The arguments of :func:`ik_options` from a method, a linear solver and
    keyword shortcuts (``TypeError`` naming an unknown one)."""
    unknown = set(shortcuts) - set(IK_SHORTCUTS[2:])
    if unknown:
        raise TypeError(f"unknown IK options: {sorted(unknown)}")
    defaults = dict(zip(IK_SHORTCUTS, _SHORTCUT_DEFAULTS))
    return (method, linear_solver) + tuple(shortcuts.get(k, defaults[k]) for k in IK_SHORTCUTS[2:])


def ik_options_of_args(args: Tuple[Any, ...]) -> kinematics_pb2.IkOptions:
    """:func:`ik_options` of arguments in :data:`IK_SHORTCUTS` order."""
    return ik_options(args[0], args[1], **dict(zip(IK_SHORTCUTS[2:], args[2:])))


@dataclass(frozen=True)
class ConfigFlags:
    """How a controller names an arm configuration (``method="analytic"``):
    each flag is the side of a singularity the arm is on.
    ``shoulder_back``: the wrist lies behind axis 1 (KUKA Status bit 0);
    ``elbow_down``: joint 3 is below its stretched-arm angle (sin(q3 - q3s) < 0);
    ``wrist_flipped``: joint 5 is on the negative side of its wrist-singular
    angle (sin(q5 - q5s) < 0). See docs/inverse-kinematics.md#analytic for
    the KUKA / ABB / UR names."""

    shoulder_back: bool
    elbow_down: bool
    wrist_flipped: bool


@dataclass
class IkSolution:
    """One answer: joints ``q`` (rad, m for prismatic joints), errors of its
    true FK (m, rad), iterations of its attempt, µs since the request began,
    the attempt's status and index (0 = from the seed). With ``history=True``
    in the request, ``history`` is an (iterations + 1) x 2 array of the
    (position m, orientation rad) error at the start of every iteration.
    With ``method="analytic"``: ``config`` holds the solution's
    :class:`ConfigFlags` and ``singular`` says a free joint of a singular pose
    took the seed's value (``config`` is None for the iterative methods)."""

    q: np.ndarray
    position_error: float
    orientation_error: float
    iterations: int
    elapsed_us: int
    status: str
    attempt: int
    history: Optional[np.ndarray] = None
    config: Optional[ConfigFlags] = None
    singular: bool = False

    @classmethod
    def from_proto(cls, s: kinematics_pb2.IkSolution) -> "IkSolution":
        # positional, in field order: the hot path of every IK answer
        return cls(
            np.array(s.joints[:], dtype=float),  # a list first: cheaper than asarray for a few values
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
            (
                ConfigFlags(s.config.shoulder_back, s.config.elbow_down, s.config.wrist_flipped)
                if s.HasField("config")
                else None
            ),
            s.singular,
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
                d["q"] = np.array(s.joints[:])  # float64 from a list of floats (cheaper than asarray here)
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


def __getattr__(name: str) -> Any:
    """``IkStream`` moved to :mod:`kinplan.robot` with the rest of the blocking robot."""
    if name == "IkStream":
        from .robot import IkStream

        return IkStream
    if name == "KinematicsMixin":  # the client mixins of earlier releases: the classes that now hold their methods
        from .client import Client

        return Client
    if name == "RobotKinematicsMixin":  # the client mixins of earlier releases: the classes that now hold their methods
        from .robot import Robot

        return Robot
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "IK_OPTION_FIELDS",
    "IkBatchResult",
    "IkOptions",
    "IkResult",
    "IkSolution",
    "JOINT_LIMITS",
    "LINEAR_SOLVERS",
    "LinearSolution",
    "METHODS",
    "TrackResult",
    "ik_options",
    "target_to_pose",
]
