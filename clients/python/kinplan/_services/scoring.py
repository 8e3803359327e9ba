"""ScoringService: one trajectory's criteria and labelled sets compared —
requests built and replies read for both clients."""
from __future__ import annotations

from typing import Any, Iterable, Mapping, Optional, Sequence

from ..scoring import Comparison, Scores, Trajectory, score_options, trajectory_to_proto
from ..v1 import common_pb2, scoring_pb2
from . import Call


def score(q: Trajectory, timestamps: Optional[Iterable[float]], weights: Optional[Iterable[float]], series: bool,
          robot_points: Optional[str], max_velocity: Optional[Iterable[float]],
          max_acceleration: Optional[Iterable[float]], jerk_peaks: Optional[Mapping[str, Any]],
          potential_tolerance: Optional[float]) -> Call[Scores]:
    """ScoreTrajectory: the criteria of one joint trajectory."""
    traj = trajectory_to_proto(q, timestamps)
    options = score_options(weights, series, robot_points, max_velocity, max_acceleration, jerk_peaks,
                            potential_tolerance)
    return Call("scoring", "ScoreTrajectory", Scores.from_proto,
                build=lambda ref: scoring_pb2.ScoreTrajectoryRequest(robot=ref, trajectory=traj, options=options))


def compare(sets: Mapping[str, Sequence[Trajectory]], weights: Optional[Iterable[float]],
            robot_points: Optional[str], max_velocity: Optional[Iterable[float]],
            max_acceleration: Optional[Iterable[float]], jerk_peaks: Optional[Mapping[str, Any]],
            potential_tolerance: Optional[float]) -> Call[Comparison]:
    """CompareTrajectories: per set and criterion, the statistics of every trajectory's criteria."""
    request_sets = [
        scoring_pb2.TrajectorySet(label=label, trajectories=[trajectory_to_proto(q) for q in trajectories])
        for label, trajectories in sets.items()
    ]
    options = score_options(weights, False, robot_points, max_velocity, max_acceleration, jerk_peaks,
                            potential_tolerance)

    def build(ref: common_pb2.RobotRef) -> scoring_pb2.CompareTrajectoriesRequest:
        return scoring_pb2.CompareTrajectoriesRequest(robot=ref, sets=request_sets, options=options)

    return Call("scoring", "CompareTrajectories", Comparison, build=build)
