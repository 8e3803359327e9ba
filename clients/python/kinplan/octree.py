"""OctoMap trees (:class:`Octree`) and the ranked next-best views of one
(:class:`Views`): the values of ``Client.insert_scan``, ``octree_info`` and
``next_best_view`` (proto/kinplan/v1/exploration.proto; S0 §4).

Trees travel as :class:`Octree` values: the node bytes of an OctoMap ``.bt``
(or ``.ot``) file without its text header, as ROS ``octomap_msgs/Octomap``
carries them. ``Octree.from_bt(open("map.bt", "rb").read())`` reads a file's
bytes; the server never opens a file.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from .v1 import common_pb2, exploration_pb2

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
        tree_id, resolution, data = _split_header(content)
        return cls(data=data, resolution=resolution, binary=True, tree_id=tree_id)

    @classmethod
    def from_file_bytes(cls, content: bytes) -> "Octree":
        """A whole OctoMap file's bytes: ``.bt`` (binary) or ``.ot`` (full,
        OcTree or ColorOcTree), told apart by the first header line."""
        first = bytes(content[:64]).split(b"\n", 1)[0].strip()
        if first == _BT_MAGIC:
            return cls.from_bt(content)
        if first == _OT_MAGIC:
            tree_id, resolution, data = _split_header(content)
            return cls(data=data, resolution=resolution, binary=False, tree_id=tree_id)
        raise ValueError(
            "not an OctoMap file: the first line must be "
            f"{_BT_MAGIC.decode()!r} (.bt) or {_OT_MAGIC.decode()!r} (.ot)"
        )

    @classmethod
    def read(cls, source: "OctreeSource", name: str = "octree") -> "Octree":
        """An :class:`Octree` from any of the forms the client's calls take:
        an ``Octree``; a ``.bt``/``.ot`` file's bytes; an open binary file
        (anything with ``read()``); or a path, read here on the client (the
        server never opens a file). ``name`` is the argument named in errors."""
        if isinstance(source, Octree):
            return source
        if isinstance(source, (bytes, bytearray, memoryview)):
            return cls.from_file_bytes(bytes(source))
        if hasattr(source, "read"):
            content = source.read()
            if not isinstance(content, (bytes, bytearray)):
                raise TypeError(f"{name}: the file must be opened in binary mode ('rb')")
            return cls.from_file_bytes(bytes(content))
        if isinstance(source, (str, os.PathLike)):
            with open(source, "rb") as f:
                return cls.from_file_bytes(f.read())
        raise TypeError(
            f"{name} must be an Octree, a .bt/.ot file's bytes, a binary file object or a path, "
            f"got {type(source).__name__}"
        )

    def to_bt(self) -> bytes:
        """The tree as a ``.bt`` file OctoMap reads (binary trees only)."""
        if not self.binary:
            raise ValueError("only a binary tree can be written as .bt")
        # OctoMap checks `size` against the nodes it built while reading.
        return (
            f"{_BT_MAGIC.decode()}\nid {self.tree_id}\nsize {_count_binary_nodes(self.data)}\n"
            f"res {self.resolution}\ndata\n"
        ).encode() + self.data

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

    def leaves(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every leaf of a binary tree as a cube: its lowest corner (n x 3,
        m, world frame), its edge (n, m; a pruned leaf at depth d is 2^(16-d)
        cells a side) and whether it is occupied (n, bool; else free), in
        the order of the node stream. ``occupied_cells()`` are the centres
        of the occupied ones."""
        if not self.binary:
            raise ValueError("only a binary tree's nodes are decoded")
        data = self.data
        inner_lo, inner_hi = _inner_children()
        # one record per inner node (2 bytes, stream order): the node's lowest corner key and half edge; only
        # the inner children are walked here, the leaves are read from the bytes with numpy below
        nodes: List[Tuple[int, int, int, int]] = []
        stack = [(0, 0, 0, 0)] if data else []  # key of the node's lowest corner, depth
        i = 0
        while stack:
            kx, ky, kz, depth = stack.pop()
            half = 1 << (15 - depth)
            nodes.append((kx, ky, kz, half))
            inner = inner_lo[data[i]] + inner_hi[data[i + 1]]
            i += 2
            if inner:  # depth first, children in order 0..7
                stack.extend([(kx + half * (c & 1), ky + half * ((c >> 1) & 1), kz + half * (c >> 2), depth + 1)
                              for c in reversed(inner)])
        if not nodes:
            return np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=bool)
        rec = np.array(nodes, dtype=np.int64)
        bits = np.frombuffer(data[:i], dtype="<u2").astype(np.int64)
        kinds = (bits[:, None] >> (2 * np.arange(8))) & 3
        r, c = np.nonzero((kinds == 1) | (kinds == 2))
        offsets = np.array([[k & 1, (k >> 1) & 1, k >> 2] for k in range(8)], dtype=np.int64)
        half = rec[r, 3]
        keys = rec[r, :3] + half[:, None] * offsets[c]
        mins = (keys - 32768) * self.resolution
        return mins.astype(float), half * self.resolution, kinds[r, c] == 2

    def boxes(self, region: Optional[Tuple[Sequence[float], Sequence[float]]] = None,
              max_cells: int = 1 << 23) -> Dict[str, Tuple[np.ndarray, np.ndarray]]:
        """The space of ``region`` = (min xyz, max xyz) by state, as
        axis-aligned boxes (min corners n x 3, max corners n x 3, m):
        ``"occupied"`` and ``"free"`` leaves and ``"unknown"`` cells (the
        finest cells no leaf covers), each clipped to the region, so that
        their volumes add up to ``octree_info(tree, box=region)``'s. Without
        a region: the whole leaves, and the unknown cells inside the bounds
        of the known ones. Raises ValueError when the region holds more than
        ``max_cells`` finest cells."""
        mins, edges, occupied = self.leaves()
        maxs = mins + edges[:, None]
        res = self.resolution
        if region is None:
            if not len(mins):
                empty = np.zeros((0, 3))
                return {"occupied": (empty, empty), "free": (empty, empty), "unknown": (empty, empty)}
            lo, hi = mins.min(axis=0), maxs.max(axis=0)
        else:
            lo, hi = (np.asarray(b, dtype=float).reshape(3) for b in region)
            if np.any(hi < lo):
                raise ValueError(f"region min {lo.tolist()} exceeds max {hi.tolist()}")
        out: Dict[str, Tuple[np.ndarray, np.ndarray]] = {}
        for name, pick in (("occupied", occupied), ("free", ~occupied)):
            a, b = mins[pick], maxs[pick]
            if region is not None:
                a, b = np.maximum(a, lo), np.minimum(b, hi)
                keep = np.all(b > a, axis=1)
                a, b = a[keep], b[keep]
            out[name] = (a, b)
        # the finest cells of the region, minus those the leaves cover
        k0 = np.floor(lo / res + 1e-9).astype(np.int64)
        k1 = np.maximum(np.ceil(hi / res - 1e-9).astype(np.int64), k0)
        shape = tuple(int(v) for v in k1 - k0)
        if int(np.prod(shape, dtype=np.int64)) > max_cells:
            raise ValueError(f"the region holds {int(np.prod(shape, dtype=np.int64))} cells of {res} m, more than "
                             f"max_cells={max_cells}: give a smaller region")
        known = np.zeros(shape, dtype=bool)
        if known.size:
            kmin = np.rint(mins / res).astype(np.int64) - k0
            kmax = kmin + np.rint(edges / res).astype(np.int64)[:, None]
            kmin = np.clip(kmin, 0, shape)
            kmax = np.clip(kmax, 0, shape)
            inside = np.all(kmax > kmin, axis=1)
            single = inside & np.all(kmax - kmin == 1, axis=1)
            known[tuple(kmin[single].T)] = True
            big = inside & ~single
            for (x0, y0, z0), (x1, y1, z1) in zip(kmin[big].tolist(), kmax[big].tolist()):
                known[x0:x1, y0:y1, z0:z1] = True
        cells = np.argwhere(~known)
        a = (cells + k0) * res
        b = a + res
        a, b = np.maximum(a, lo), np.minimum(b, hi)
        keep = np.all(b > a, axis=1)
        out["unknown"] = (a[keep], b[keep])
        return out

    def to_proto(self) -> common_pb2.Octree:
        return common_pb2.Octree(id=self.tree_id, resolution=self.resolution, binary=self.binary, data=self.data)

    @classmethod
    def from_proto(cls, o: common_pb2.Octree) -> "Octree":
        return cls(data=o.data, resolution=o.resolution, binary=o.binary, tree_id=o.id)

    def __repr__(self) -> str:
        kind = "binary" if self.binary else "full"
        return f"Octree({kind}, resolution={self.resolution} m, {len(self.data)} bytes)"


_INNER: List[Tuple[Tuple[int, ...], ...]] = []


def _inner_children() -> List[Tuple[Tuple[int, ...], ...]]:
    """Per byte of a .bt node: its inner children (bits 11), for the low
    byte (children 0-3) and for the high byte (children 4-7)."""
    if not _INNER:
        _INNER.append(tuple(tuple(c for c in range(4) if (b >> (2 * c)) & 3 == 3) for b in range(256)))
        _INNER.append(tuple(tuple(c + 4 for c in range(4) if (b >> (2 * c)) & 3 == 3) for b in range(256)))
    return _INNER


_BT_MAGIC = b"# Octomap OcTree binary file"
_OT_MAGIC = b"# Octomap OcTree file"

#: What the client's octree arguments take (see :meth:`Octree.read`).
OctreeSource = Union["Octree", bytes, bytearray, memoryview, str, "os.PathLike[str]", Any]


def _split_header(content: bytes) -> Tuple[str, float, bytes]:
    """(id, resolution, node bytes) of an OctoMap file: text lines up to ``data``."""
    tree_id, resolution, offset = "OcTree", None, 0
    while True:
        end = content.find(b"\n", offset)
        if end < 0:
            raise ValueError("the OctoMap header has no 'data' line")
        line = content[offset:end].decode("ascii", "replace").strip()
        offset = end + 1
        if line.startswith("id "):
            tree_id = line[3:].strip()
        elif line.startswith("res "):
            resolution = float(line[4:])
        elif line == "data":
            break
    if resolution is None:
        raise ValueError("the OctoMap header has no 'res' line")
    return tree_id, resolution, content[offset:]


def _count_binary_nodes(data: bytes) -> int:
    """The nodes OctoMap builds from a .bt node stream (what its ``size``
    header line must say): the root and every known child. Each inner node
    is 2 bytes, 2 bits per child (00 unknown: no node; 01 free and 10
    occupied leaves: a node; 11: a node whose own 2 bytes follow, depth
    first)."""
    count, pending, i = 1, 1, 0
    while pending:
        if i + 2 > len(data):
            raise ValueError("truncated binary octree")
        pending -= 1
        bits = data[i] | (data[i + 1] << 8)
        i += 2
        children = [(bits >> (2 * c)) & 3 for c in range(8)]
        count += sum(1 for b in children if b)
        pending += sum(1 for b in children if b == 3)
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


__all__ = ["GAINS", "Octree", "Views"]
