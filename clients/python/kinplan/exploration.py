"""Next-best-view selection on OctoMap trees, scan integration and tree
statistics (proto/kinplan/v1/exploration.proto; S0 §4).

Trees travel as :class:`Octree` values: the node bytes of an OctoMap ``.bt``
(or ``.ot``) file without its text header, as ROS ``octomap_msgs/Octomap``
carries them. ``Octree.from_bt(open("map.bt", "rb").read())`` reads a file's
bytes; the server never opens a file.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence

import numpy as np

from ._convert import pose_to_matrix
from .planning import _pose
from .v1 import common_pb2, exploration_pb2, exploration_pb2_grpc

GAINS = {
    "intersection": exploration_pb2.GAIN_METHOD_INTERSECTION,
    "rays": exploration_pb2.GAIN_METHOD_RAYS,
    "occlusion_aware": exploration_pb2.GAIN_METHOD_OCCLUSION_AWARE,
    "unobserved_voxels": exploration_pb2.GAIN_METHOD_UNOBSERVED_VOXELS,
}


@dataclass
class Octree:
    """An OctoMap tree: node bytes, resolution (m), binary (.bt) or full (.ot)."""

    data: bytes
    resolution: float
    binary: bool = True
    tree_id: str = "OcTree"

    @classmethod
    def from_bt(cls, content: bytes) -> "Octree":
        """A whole ``.bt`` file's bytes (header lines ``id``, ``res``, ``data``)."""
        from .planning import OctreeObstacle

        o = OctreeObstacle.from_bt_file_bytes(content)
        return cls(data=o.data, resolution=o.resolution, binary=True, tree_id=o.tree_id)

    def to_bt(self) -> bytes:
        """The tree as a ``.bt`` file OctoMap reads (binary trees only)."""
        if not self.binary:
            raise ValueError("only a binary tree can be written as .bt")
        header = (
            f"# Octomap OcTree binary file\nid {self.tree_id}\nsize 0\nres {self.resolution}\ndata\n"
        )
        # OctoMap reads `size` but recounts the nodes; 0 would be refused by
        # kinplan's own reader, so count the nodes (2 bytes each).
        header = header.replace("size 0", f"size {_count_binary_nodes(self.data)}")
        return header.encode() + self.data

    def occupied_cells(self) -> np.ndarray:
        """Centres (n x 3, m, world frame) of the occupied leaves of a binary
        tree, any depth (a pruned leaf at depth d stands for 2^(16-d) cells a
        side), decoded from the .bt node bytes: 2 bits per child, 01 free
        leaf, 10 occupied leaf, 11 inner node; child i at depth d from bit
        15 - d of the keys, i = x + 2y + 4z."""
        if not self.binary:
            raise ValueError("only a binary tree's nodes are decoded")
        data, out, i = self.data, [], 0
        stack = [((0, 0, 0), 0)] if data else []  # (key of the node's lowest corner, depth)
        while stack:
            (kx, ky, kz), depth = stack.pop()
            bits = data[i] | (data[i + 1] << 8)
            i += 2
            half = 1 << (15 - depth)
            children = []
            for c in range(8):
                kind = (bits >> (2 * c)) & 3
                key = (kx + half * (c & 1), ky + half * ((c >> 1) & 1), kz + half * ((c >> 2) & 1))
                if kind == 2:
                    size = half * self.resolution
                    out.append((np.array(key) - 32768) * self.resolution + size / 2)
                elif kind == 3:
                    children.append((key, depth + 1))
            stack.extend(reversed(children))  # depth first, children in order 0..7
        return np.array(out, dtype=float).reshape(-1, 3)

    def to_proto(self) -> common_pb2.Octree:
        return common_pb2.Octree(id=self.tree_id, resolution=self.resolution, binary=self.binary, data=self.data)

    @classmethod
    def from_proto(cls, o: common_pb2.Octree) -> "Octree":
        return cls(data=o.data, resolution=o.resolution, binary=o.binary, tree_id=o.id)

    def __repr__(self) -> str:
        kind = "binary" if self.binary else "full"
        return f"Octree({kind}, resolution={self.resolution} m, {len(self.data)} bytes)"


def _count_binary_nodes(data: bytes) -> int:
    """Nodes of a .bt node stream: each node is 2 bytes, children with
    children (bits 11) follow depth first."""
    count, pending, i = 0, 1, 0
    while pending:
        if i + 2 > len(data):
            raise ValueError("truncated binary octree")
        pending -= 1
        count += 1
        bits = data[i] | (data[i + 1] << 8)
        i += 2
        pending += sum(1 for c in range(8) if (bits >> (2 * c)) & 3 == 3)
    return count


@dataclass
class Views:
    """Ranked candidate views. ``poses`` is k x 4 x 4 (camera optical frame in
    the world; +z looks), ``utility`` f = w_d D + w_r R + w_i Ig, ``gain`` Ig,
    ``distance`` D, ``rotation`` R, ``reachable`` True/False/None (not
    checked), ``joints`` the IK solutions (None where not reachable)."""

    poses: np.ndarray
    utility: np.ndarray
    gain: np.ndarray
    distance: np.ndarray
    rotation: np.ndarray
    unknown_cells: np.ndarray
    frontier: np.ndarray
    reachable: List[Optional[bool]]
    joints: List[Optional[np.ndarray]]
    stages: Dict[str, float]
    status: str
    weights: Dict[str, float]
    raw: Any = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.utility)

    def __repr__(self) -> str:
        best = f", best f={self.utility[0]:.3f}" if len(self) else ""
        return f"Views({len(self)} candidates{best}, status={self.status})"

    def to_pandas(self) -> Any:
        import pandas as pd

        return pd.DataFrame(
            {
                "x": self.poses[:, 0, 3] if len(self) else [],
                "y": self.poses[:, 1, 3] if len(self) else [],
                "z": self.poses[:, 2, 3] if len(self) else [],
                "utility": self.utility,
                "Ig": self.gain,
                "D": self.distance,
                "R": self.rotation,
                "unknown_cells": self.unknown_cells,
                "reachable": self.reachable,
            }
        )


_REACH = {0: None, 1: True, 2: False}


def _nbv_request(octree: Any, camera_pose: Any, camera_mount: Any, candidate_poses: Sequence[Any],
                 weights: Optional[Sequence[float]], gain: str, ray_fraction: Optional[float], max_results: int,
                 camera: Optional[Dict[str, Any]], options: Dict[str, Any]) -> exploration_pb2.NextBestViewRequest:
    """The NextBestViewRequest of :meth:`ExplorationMixin.next_best_view`'s
    arguments, without a robot (shared by the blocking and asyncio clients)."""
    tree = octree if isinstance(octree, Octree) else Octree.from_bt(bytes(octree))
    if gain not in GAINS:
        raise ValueError(f"gain must be one of {sorted(GAINS)}, got {gain!r}")
    opts = exploration_pb2.NbvOptions(gain=GAINS[gain], max_results=int(max_results), **options)
    if ray_fraction is not None:
        opts.ray_fraction = float(ray_fraction)
    if weights is not None:
        w_i, w_d, w_r = (float(v) for v in weights)
        opts.weights.CopyFrom(exploration_pb2.UtilityWeights(information_gain=w_i, distance=w_d, rotation=w_r))
    req = exploration_pb2.NextBestViewRequest(
        octree=tree.to_proto(),
        camera=exploration_pb2.CameraModel(**(camera or {})),
        camera_pose=_pose(camera_pose),
        candidate_poses=[_pose(p) for p in candidate_poses],
        options=opts,
    )
    if camera_mount is not None:
        req.camera_mount.CopyFrom(_pose(camera_mount))
    return req


def _with_robot(req: exploration_pb2.NextBestViewRequest,
                ) -> Callable[[common_pb2.RobotRef], exploration_pb2.NextBestViewRequest]:
    """`req` with a robot reference (for a robot's ``_call``)."""
    def build(ref: common_pb2.RobotRef) -> exploration_pb2.NextBestViewRequest:
        r = exploration_pb2.NextBestViewRequest()
        r.CopyFrom(req)
        r.robot.CopyFrom(ref)
        return r

    return build


def _views(reply: exploration_pb2.NextBestViewResponse) -> Views:
    """The :class:`Views` of a NextBestView reply."""
    c = reply.candidates
    s = reply.stages
    return Views(
        poses=np.array([pose_to_matrix(v.pose) for v in c]).reshape(-1, 4, 4),
        utility=np.array([v.utility for v in c]),
        gain=np.array([v.information_gain for v in c]),
        distance=np.array([v.distance_score for v in c]),
        rotation=np.array([v.rotation_score for v in c]),
        unknown_cells=np.array([v.unknown_cells for v in c]),
        frontier=np.array(
            [[v.frontier.x, v.frontier.y, v.frontier.z] if v.HasField("frontier") else [np.nan] * 3 for v in c]
        ).reshape(-1, 3),
        reachable=[_REACH[v.reachability] for v in c],
        joints=[np.array(v.joints) if len(v.joints) else None for v in c],
        stages={f.name: getattr(s, f.name) for f in s.DESCRIPTOR.fields},
        status=exploration_pb2.NbvStatus.Name(reply.status).removeprefix("NBV_STATUS_"),
        weights={
            "information_gain": reply.weights.information_gain,
            "distance": reply.weights.distance,
            "rotation": reply.weights.rotation,
        },
        raw=reply,
    )


def _insert_scan_request(octree: Optional[Octree], points: Any, origin: Any, resolution: float,
                         max_range: Optional[float], discretize: bool) -> exploration_pb2.InsertScanRequest:
    """The InsertScanRequest of :meth:`ExplorationMixin.insert_scan`'s arguments
    (the reply's tree reads as :meth:`Octree.from_proto`)."""
    pts = np.asarray(points, dtype=np.float32)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must be n x 3, got shape {pts.shape}")
    req = exploration_pb2.InsertScanRequest(
        resolution=float(resolution),
        sensor_pose=_pose(origin),
        points=exploration_pb2.PointCloud(xyz=pts.ravel().tolist()),
        discretize=discretize,
    )
    if octree is not None:
        req.octree.CopyFrom(octree.to_proto())
    if max_range is not None:
        req.max_range = float(max_range)
    return req


def _octree_info_request(octree: Any, box: Any) -> exploration_pb2.OctreeInfoRequest:
    """The OctreeInfoRequest of :meth:`ExplorationMixin.octree_info`'s arguments."""
    tree = octree if isinstance(octree, Octree) else Octree.from_bt(bytes(octree))
    req = exploration_pb2.OctreeInfoRequest(octree=tree.to_proto())
    if box is not None:
        lo, hi = (np.asarray(b, dtype=float) for b in box)
        req.box.min.CopyFrom(common_pb2.Vec3(x=lo[0], y=lo[1], z=lo[2]))
        req.box.max.CopyFrom(common_pb2.Vec3(x=hi[0], y=hi[1], z=hi[2]))
    return req


def _octree_info(r: exploration_pb2.OctreeInfoResponse) -> Dict[str, Any]:
    """The dict of an OctreeInfo reply."""
    s = r.stats
    return {
        "resolution": s.resolution,
        "nodes": s.nodes,
        "leaves": s.leaves,
        "occupied_leaves": s.occupied_leaves,
        "free_leaves": s.free_leaves,
        "bounds": (
            np.array([s.bounds.min.x, s.bounds.min.y, s.bounds.min.z]),
            np.array([s.bounds.max.x, s.bounds.max.y, s.bounds.max.z]),
        ),
        "occupied_volume": r.occupied_volume,
        "free_volume": r.free_volume,
        "unknown_volume": r.unknown_volume,
    }


class ExplorationMixin:
    """``Client.next_best_view``, ``Client.insert_scan``, ``Client.octree_info``."""

    def _exploration(self) -> exploration_pb2_grpc.ExplorationServiceStub:
        stub = getattr(self, "_exploration_stub", None)
        if stub is None:
            stub = exploration_pb2_grpc.ExplorationServiceStub(self._channel)  # type: ignore[attr-defined]
            self._exploration_stub = stub
        return stub

    def next_best_view(
        self,
        octree: Any,
        *,
        camera_pose: Any = None,
        robot: Any = None,
        camera_mount: Any = None,
        candidate_poses: Sequence[Any] = (),
        weights: Optional[Sequence[float]] = None,
        gain: str = "intersection",
        ray_fraction: Optional[float] = None,
        max_results: int = 10,
        camera: Optional[Dict[str, Any]] = None,
        timeout: Optional[float] = None,
        **options: Any,
    ) -> Views:
        """Ranked next views of the unknown space in ``octree`` (an
        :class:`Octree` or a ``.bt`` file's bytes). ``weights`` = (w_i, w_d,
        w_r); ``gain`` one of "intersection", "rays", "occlusion_aware",
        "unobserved_voxels"; ``robot`` (optional, a robot or a built-in's name) adds the reach filter and IK
        checks of the best candidates; further ``options`` are the fields of
        ``NbvOptions`` (e.g. ``frontier_unknown_ratio=0.3``)."""
        req = _nbv_request(octree, camera_pose, camera_mount, candidate_poses, weights, gain, ray_fraction,
                           max_results, camera, options)
        if isinstance(robot, str):
            robot = self.robot(robot)  # type: ignore[attr-defined]
        if robot is not None:
            reply = robot._call(self._exploration().NextBestView, _with_robot(req), timeout)
        else:
            reply = self._call(self._exploration().NextBestView, req, timeout)  # type: ignore[attr-defined]
        return _views(reply)

    def insert_scan(
        self,
        octree: Optional[Octree],
        points: Any,
        origin: Any = None,
        *,
        resolution: float = 0.05,
        max_range: Optional[float] = None,
        discretize: bool = False,
        timeout: Optional[float] = None,
    ) -> Octree:
        """Inserts ``points`` (n x 3, world frame, metres) seen from ``origin``
        (3-vector or 4x4 sensor pose) with OctoMap's sensor model; a new tree at
        ``resolution`` when ``octree`` is None. Returns the updated tree."""
        req = _insert_scan_request(octree, points, origin, resolution, max_range, discretize)
        reply = self._call(self._exploration().InsertScan, req, timeout)  # type: ignore[attr-defined]
        return Octree.from_proto(reply.octree)

    def octree_info(self, octree: Any, *, box: Any = None, timeout: Optional[float] = None) -> Dict[str, Any]:
        """Resolution, node and leaf counts, bounds, and free / occupied /
        unknown volume (m^3) inside ``box`` = (min xyz, max xyz) or the bounds."""
        req = _octree_info_request(octree, box)
        return _octree_info(self._call(self._exploration().OctreeInfo, req, timeout))  # type: ignore[attr-defined]
