"""Trajectory scoring: the S0 criteria, the PTP cycle time and set comparison.

``robot.score(q)`` returns a :class:`Scores` mapping keyed by the
criteria's names ("CD", "JD", "OC", "OC_geodesic", "CPC", "RDM", "JJ", "CJ",
"JMJ", "CMJ", "JJP", "CJP", "cycle_time"); ``robot.compare({...})``
returns a :class:`Comparison` table (mean, variance, sum per set and criterion,
the form of S0 Tab. 5.3-5.5) that turns into a pandas DataFrame when pandas is
installed. Units: metres, radians, seconds (see proto/kinplan/v1/scoring.proto).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Union

import numpy as np

from ._codec import trajectory_message
from .v1 import common_pb2, scoring_pb2

#: Robot-point choices for RDM, by name.
ROBOT_POINTS = {
    None: scoring_pb2.ROBOT_POINTS_UNSPECIFIED,
    "link_origins": scoring_pb2.ROBOT_POINTS_LINK_ORIGINS,
    "collision_vertices": scoring_pb2.ROBOT_POINTS_COLLISION_VERTICES,
    "none": scoring_pb2.ROBOT_POINTS_NONE,
}

#: Statistics of one criterion over one set, in this order.
STATS = ("count", "mean", "variance", "population_variance", "sum", "min", "max")

Trajectory = Union[np.ndarray, Sequence[Sequence[float]], common_pb2.JointTrajectory]


@dataclass
class Peak:
    """A pseudo-jerk peak counted in JJP or CJP: waypoint index, height (rad
    or m) and predicted slowdown (dimensionless)."""

    index: int
    height: float
    slowdown: float


@dataclass
class Series:
    """Per-waypoint terms (length n). Step terms at i belong to the step
    i-1 -> i (entry 0 is 0); jerk terms at i are the third difference ending
    at i (entries 0-2 are 0)."""

    cd: np.ndarray
    jd: np.ndarray
    oc: np.ndarray
    cpc: np.ndarray
    rdm: Optional[np.ndarray]
    joint_jerk: np.ndarray
    cartesian_jerk: np.ndarray
    joint_peaks: List[Peak]
    cartesian_peaks: List[Peak]
    joint_jerk_rate: Optional[np.ndarray] = None
    cartesian_jerk_rate: Optional[np.ndarray] = None

    @classmethod
    def from_proto(cls, s: scoring_pb2.ScoreSeries) -> "Series":
        def arr(v: Any) -> np.ndarray:
            return np.asarray(v, dtype=float)

        def opt(v: Any) -> Optional[np.ndarray]:
            return arr(v) if len(v) else None

        def peaks(ps: Any) -> List[Peak]:
            return [Peak(p.index, p.height, p.slowdown) for p in ps]

        return cls(
            cd=arr(s.cd),
            jd=arr(s.jd),
            oc=arr(s.oc),
            cpc=arr(s.cpc),
            rdm=opt(s.rdm),
            joint_jerk=arr(s.joint_jerk),
            cartesian_jerk=arr(s.cartesian_jerk),
            joint_peaks=peaks(s.joint_peaks),
            cartesian_peaks=peaks(s.cartesian_peaks),
            joint_jerk_rate=opt(s.joint_jerk_rate),
            cartesian_jerk_rate=opt(s.cartesian_jerk_rate),
        )


@dataclass
class TimePotential:
    """Waypoint ``index``: seconds ``via`` it and ``direct`` past it; ``gain``
    = via - direct; ``has_potential`` when the gain exceeds the tolerance."""

    index: int
    via: float
    direct: float
    gain: float
    has_potential: bool


@dataclass
class CycleTime:
    """Synchronized PTP cycle time (S2 §3.3): ``total`` seconds, one duration
    and limiting joint (-1: none moves) per segment, one potential per
    intermediate waypoint."""

    total: float
    segments: np.ndarray
    limiting_joints: np.ndarray
    potentials: List[TimePotential]

    @property
    def with_potential(self) -> List[TimePotential]:
        """The waypoints whose removal alone would save time."""
        return [p for p in self.potentials if p.has_potential]

    @classmethod
    def from_proto(cls, c: scoring_pb2.CycleTime) -> "CycleTime":
        return cls(
            total=c.total,
            segments=np.array([s.duration for s in c.segments], dtype=float),
            limiting_joints=np.array([s.limiting_joint for s in c.segments], dtype=int),
            potentials=[TimePotential(p.index, p.via, p.direct, p.gain, p.has_potential) for p in c.potentials],
        )


class Scores(Dict[str, float]):
    """The criteria of one trajectory, ``{name: value}``, plus details:
    ``waypoints``, ``joint_peak_count``, ``cartesian_peak_count``,
    ``robot_points`` (points per waypoint behind RDM), ``cycle_time``
    (:class:`CycleTime` or None) with ``cycle_time_unavailable`` saying why it
    is missing, ``time_scaled`` (dict of JJ/CJ/JMJ/CMJ in rad/s³, m/s³, or
    None for untimed input) and ``series`` (:class:`Series` when requested)."""

    waypoints: int = 0
    joint_peak_count: int = 0
    cartesian_peak_count: int = 0
    robot_points: int = 0
    cycle_time: Optional[CycleTime] = None
    cycle_time_unavailable: str = ""
    time_scaled: Optional[Dict[str, float]] = None
    series: Optional[Series] = None

    @classmethod
    def from_proto(cls, r: scoring_pb2.ScoreTrajectoryResponse) -> "Scores":
        out = cls(_ordered(r.criteria))
        out.waypoints = r.waypoints
        out.joint_peak_count = r.joint_peak_count
        out.cartesian_peak_count = r.cartesian_peak_count
        out.robot_points = r.robot_points
        out.cycle_time = CycleTime.from_proto(r.cycle_time) if r.HasField("cycle_time") else None
        out.cycle_time_unavailable = r.cycle_time_unavailable
        if r.HasField("time_scaled"):
            t = r.time_scaled
            out.time_scaled = {"JJ": t.jj, "CJ": t.cj, "JMJ": t.jmj, "CMJ": t.cmj}
        out.series = Series.from_proto(r.series) if r.HasField("series") else None
        return out


#: Canonical criterion order (S0 §2, then the cycle time).
CRITERIA = ("CD", "JD", "OC", "OC_geodesic", "CPC", "RDM", "JJ", "CJ", "JMJ", "CMJ", "JJP", "CJP", "cycle_time")


def _ordered(criteria: Mapping[str, float]) -> Dict[str, float]:
    known = [k for k in CRITERIA if k in criteria]
    return {k: float(criteria[k]) for k in known + sorted(set(criteria) - set(known))}


class Comparison:
    """Per-set, per-criterion statistics of :meth:`kinplan.Robot.compare`.

    ``c["rrt"]["OC"]["mean"]``; ``c.labels``, ``c.criteria``;
    ``c.scores["rrt"]`` is each trajectory's criteria; ``c.rows()`` the long
    form (one dict per set and criterion); ``c.to_pandas()`` a DataFrame
    indexed by (set, criterion) with the columns of :data:`STATS`, or with
    ``criterion="OC"`` one row per set (S0 Tab. 5.4/5.5).
    ``variance`` is the sample variance (None for a single trajectory).
    """

    def __init__(self, reply: scoring_pb2.CompareTrajectoriesResponse):
        self.labels: List[str] = [s.label for s in reply.sets]
        self.criteria: List[str] = list(reply.criteria)
        self.cycle_time_unavailable: str = reply.cycle_time_unavailable
        self.stats: Dict[str, Dict[str, Dict[str, Any]]] = {}
        self.scores: Dict[str, List[Dict[str, float]]] = {}
        for s in reply.sets:
            self.stats[s.label] = {
                name: {
                    "count": st.count,
                    "mean": st.mean,
                    "variance": st.variance if st.HasField("variance") else None,
                    "population_variance": st.population_variance,
                    "sum": st.sum,
                    "min": st.min,
                    "max": st.max,
                }
                for name, st in sorted(s.criteria.items(), key=lambda kv: _rank(kv[0]))
            }
            self.scores[s.label] = [_ordered(t.criteria) for t in s.scores]

    def __getitem__(self, label: str) -> Dict[str, Dict[str, Any]]:
        return self.stats[label]

    def __iter__(self) -> Iterator[str]:
        return iter(self.labels)

    def __len__(self) -> int:
        return len(self.labels)

    def rows(self, criterion: Optional[str] = None) -> List[Dict[str, Any]]:
        """One dict per (set, criterion): ``{"set", "criterion", *STATS}``."""
        out = []
        for label in self.labels:
            for name, st in self.stats[label].items():
                if criterion is None or name == criterion:
                    out.append({"set": label, "criterion": name, **st})
        return out

    def to_dict(self) -> Dict[str, Dict[str, Dict[str, Any]]]:
        return {label: {k: dict(v) for k, v in crit.items()} for label, crit in self.stats.items()}

    def to_pandas(self, criterion: Optional[str] = None) -> Any:
        """A pandas DataFrame (needs pandas: ``pip install kinplan[table]``)."""
        try:
            import pandas as pd
        except ImportError as err:  # pragma: no cover - depends on the environment
            raise ImportError("to_pandas() needs pandas: pip install pandas") from err
        rows = self.rows(criterion)
        if criterion is not None:
            df = pd.DataFrame(rows, columns=["set", "criterion", *STATS]).set_index("set")
            return df.drop(columns="criterion")
        return pd.DataFrame(rows, columns=["set", "criterion", *STATS]).set_index(["set", "criterion"])

    to_dataframe = to_pandas

    def __repr__(self) -> str:
        lines = [f"Comparison({len(self.labels)} sets, criteria {self.criteria})"]
        for label in self.labels:
            means = ", ".join(f"{k}={v['mean']:.6g}" for k, v in self.stats[label].items())
            lines.append(f"  {label} (n={len(self.scores[label])}): {means}")
        return "\n".join(lines)


def _rank(name: str) -> int:
    return CRITERIA.index(name) if name in CRITERIA else len(CRITERIA)


def _encode_rows(arr: np.ndarray, ts: Optional[np.ndarray]) -> common_pb2.JointTrajectory:
    """A JointTrajectory of an (n x m) float array (see :func:`kinplan._codec.trajectory_message`)."""
    return trajectory_message(arr, ts)


def _check_trajectory_limits(check: Any, q: Any) -> None:
    """The joint-limit (degrees) guard `check(states, field)` on a rectangular trajectory."""
    if isinstance(q, common_pb2.JointTrajectory):
        return
    try:
        arr = np.asarray(q, dtype=float)
    except ValueError:  # ragged rows: the server names the bad one
        return
    if arr.ndim == 2 and arr.size:
        check(arr, "q")


def trajectory_to_proto(q: Trajectory, timestamps: Optional[Iterable[float]] = None) -> common_pb2.JointTrajectory:
    """A JointTrajectory from an (n x joints) array or a list of waypoints.
    Ragged lists are sent as they are, so that the server names the bad row.
    ``timestamps`` (seconds, one per waypoint) set ``time_from_start``."""
    ts = None if timestamps is None else np.asarray(list(timestamps), dtype=float)
    if isinstance(q, common_pb2.JointTrajectory):
        traj = common_pb2.JointTrajectory()
        traj.CopyFrom(q)
    else:
        try:
            arr = np.asarray(q, dtype=float)
        except ValueError:  # ragged rows
            rows = [np.asarray(row, dtype=float).ravel().tolist() for row in q]
        else:
            if arr.size == 0:
                rows = []
            elif arr.ndim != 2:
                raise ValueError(f"q must be (waypoints x joints), got shape {arr.shape}")
            else:
                if ts is not None and ts.shape != (arr.shape[0],):
                    raise ValueError(f"timestamps must have one entry per waypoint ({arr.shape[0]}), got {ts.shape}")
                return _encode_rows(arr, ts)
        traj = common_pb2.JointTrajectory(points=[common_pb2.JointPoint(positions=r) for r in rows])
    if ts is not None:
        if ts.shape != (len(traj.points),):
            raise ValueError(f"timestamps must have one entry per waypoint ({len(traj.points)}), got {ts.shape}")
        for point, t in zip(traj.points, ts.tolist()):
            point.time_from_start = t
    return traj


def score_options(
    weights: Optional[Iterable[float]] = None,
    series: bool = False,
    robot_points: Optional[str] = None,
    max_velocity: Optional[Iterable[float]] = None,
    max_acceleration: Optional[Iterable[float]] = None,
    jerk_peaks: Optional[Mapping[str, Any]] = None,
    potential_tolerance: Optional[float] = None,
) -> scoring_pb2.ScoreOptions:
    """ScoreOptions from Python values; unset means the documented default."""
    if robot_points not in ROBOT_POINTS:
        raise ValueError(f"robot_points must be one of {[k for k in ROBOT_POINTS if k]}, got {robot_points!r}")
    o = scoring_pb2.ScoreOptions(series=series, robot_points=ROBOT_POINTS[robot_points])
    for name, values in (("joint_weights", weights), ("max_velocity", max_velocity), ("max_acceleration", max_acceleration)):
        if values is not None:
            getattr(o, name).extend(np.asarray(values, dtype=float).ravel().tolist())
    if jerk_peaks:
        o.jerk_peaks.CopyFrom(scoring_pb2.JerkPeakOptions(**dict(jerk_peaks)))
    if potential_tolerance is not None:
        o.potential_tolerance = float(potential_tolerance)
    return o


__all__ = [
    "CRITERIA",
    "Comparison",
    "CycleTime",
    "Peak",
    "Scores",
    "Series",
    "TimePotential",
    "score_options",
    "trajectory_to_proto",
]


def __getattr__(name: str) -> Any:
    """The client mixins of earlier releases: the classes that now hold their methods."""
    if name == "ScoringMixin":
        from .client import Client

        return Client
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
