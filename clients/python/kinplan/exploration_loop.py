"""The values of the exploration loop run end to end on the server
(ExplorationService.Explore; S0 §4-5) and of its reference cells:
``for step in client.explore(robot, start=..., scene=..., region=...)`` yields
one :class:`ExploreStep` per iteration and finally an :class:`ExploreSummary`
holding the totals and the final octree."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, List, Optional, Tuple

import numpy as np

from ._display import html_table
from ._convert import pose_to_matrix
from .octree import Octree
from .v1 import common_pb2, exploration_pb2


SCENES = {
    "s0_open_cell": exploration_pb2.REFERENCE_SCENE_NAME_S0_OPEN_CELL,
    "s0_walled_cell": exploration_pb2.REFERENCE_SCENE_NAME_S0_WALLED_CELL,
}


@dataclass
class ReferenceScene:
    """One of kinplan's seeded reference cells: the robot's name, the
    obstacles (CollisionObject messages, usable as ``scene=``), the region
    (min xyz, max xyz) and the start joints. Pass it as ``scene=`` to
    :meth:`kinplan.Client.explore` and the region, start and robot follow."""

    name: str
    robot: str
    obstacles: List[common_pb2.CollisionObject]
    region: Tuple[np.ndarray, np.ndarray]
    start: np.ndarray

    def __repr__(self) -> str:
        lo, hi = self.region
        return f"ReferenceScene({self.name!r}, {len(self.obstacles)} obstacles, region {lo.tolist()} - {hi.tolist()})"


@dataclass
class ExploreStep:
    """One iteration: the view moved to (4x4 camera pose in the world, or
    None when every tried view failed) with its utility terms, the executed
    trajectory (waypoints x dof, rad) and its S0 criteria (CD m, JD rad, OC
    rad, CPC, RDM m, ...), the views that failed and why, the known ratio
    after the scan, and the seconds spent per stage."""

    iteration: int
    known_ratio: float
    view: Optional[np.ndarray]
    terms: Dict[str, float]
    trajectory: np.ndarray
    times_from_start: np.ndarray
    criteria: Dict[str, float]
    failures: List[Tuple[Tuple[float, float, float], str]]
    hits_scene: bool
    joints: np.ndarray
    times: Dict[str, float]

    def __repr__(self) -> str:
        moved = "no motion" if self.view is None else f"{len(self.trajectory)} waypoints"
        return (
            f"ExploreStep({self.iteration}: known {self.known_ratio:.3f}, {moved}, "
            f"{len(self.failures)} failed views, {self.times.get('total', 0.0):.3f} s)"
        )


@dataclass
class ExploreSummary:
    """How the run ended (status "EXPLORED", "ITERATION_CAP",
    "CONSECUTIVE_FAILURES", "NO_CANDIDATES", "OBSERVABLE_EXHAUSTED",
    "TIMEOUT" or "CANCELLED"), the known ratio before the first iteration
    and at the end, the S0 criteria summed over every trajectory (S0 Tab.
    5.3) and the final tree. ``wasted_moves`` counts views reached whose
    scan added nothing; ``best_predicted_cells`` is the last visibility
    check's largest lower bound of the cells a view would reveal (None
    without the check)."""

    status: str
    iterations: int
    initial_known_ratio: float
    known_ratio: float
    observable_cells: int
    totals: Dict[str, float]
    failures: int
    scene_hits: int
    final_joints: np.ndarray
    octree: Octree
    scans: int
    elapsed: float
    wasted_moves: int = 0
    best_predicted_cells: Optional[int] = None

    def _repr_html_(self) -> str:
        rows = [("status", self.status), ("iterations", self.iterations),
                ("known ratio", f"{self.initial_known_ratio:.3f} -> {self.known_ratio:.3f}"),
                ("observable cells", self.observable_cells), ("failed views", self.failures),
                ("wasted moves", self.wasted_moves),
                ("trajectories hitting the scene", self.scene_hits), ("elapsed (s)", self.elapsed)]
        rows += [(f"{k} (sum)", v) for k, v in self.totals.items()]
        return html_table("ExploreSummary", rows, "CD, RDM in m; JD, OC in rad; sums over every executed trajectory (S0 Tab. 5.3)")

    def __repr__(self) -> str:
        return (
            f"ExploreSummary({self.status} after {self.iterations} iterations, known "
            f"{self.initial_known_ratio:.3f} -> {self.known_ratio:.3f}, {self.failures} failed views, "
            f"{self.wasted_moves} wasted moves, {self.elapsed:.2f} s)"
        )


def _step(m: exploration_pb2.ExploreIteration) -> ExploreStep:
    pts = m.trajectory.points
    v = m.view if m.HasField("view") else None
    return ExploreStep(
        iteration=m.iteration,
        known_ratio=m.known_ratio,
        view=pose_to_matrix(v.pose) if v is not None else None,
        terms={} if v is None else {
            "distance": v.distance_score,
            "rotation": v.rotation_score,
            "information_gain": v.information_gain,
            "utility": v.utility,
            "rank": float(m.view_rank),
        },
        trajectory=np.array([list(p.positions) for p in pts], dtype=float).reshape(len(pts), -1),
        times_from_start=np.array([p.time_from_start for p in pts], dtype=float),
        criteria=dict(m.criteria),
        failures=[((f.position.x, f.position.y, f.position.z), f.reason) for f in m.failures],
        hits_scene=m.hits_scene,
        joints=np.array(m.joints, dtype=float),
        times={f.name: getattr(m.times, f.name) for f in m.times.DESCRIPTOR.fields},
    )


def _summary(s: exploration_pb2.ExploreSummary) -> ExploreSummary:
    t = s.totals
    return ExploreSummary(
        status=exploration_pb2.ExploreStatus.Name(s.status).removeprefix("EXPLORE_STATUS_"),
        iterations=s.iterations,
        initial_known_ratio=s.initial_known_ratio,
        known_ratio=s.known_ratio,
        observable_cells=s.observable_cells,
        totals={"JD": t.jd, "CPC": t.cpc, "CD": t.cd, "OC": t.oc, "RDM": t.rdm, "trajectories": float(t.trajectories)},
        failures=s.failures,
        scene_hits=s.scene_hits,
        final_joints=np.array(s.final_joints, dtype=float),
        octree=Octree.from_proto(s.octree),
        scans=s.scans,
        elapsed=s.elapsed,
        wasted_moves=s.wasted_moves,
        best_predicted_cells=s.best_predicted_cells if s.HasField("best_predicted_cells") else None,
    )


__all__ = ["SCENES", "ExploreStep", "ExploreSummary", "ReferenceScene"]
