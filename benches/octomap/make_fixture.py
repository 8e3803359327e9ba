"""Writes the OctoMap insertPointCloud fixture the Rust test compares against.

Run from the repository root with the OctoMap Python binding installed
(`pip install octomap-python numpy`):

    python benches/octomap/make_fixture.py

It writes crates/kinplan-core/src/octree/fixtures/scans.bin (little-endian: u32 scan
count; per scan: f32 origin[3], f32 max_range, u32 n, f32 points[n][3]) and
scans_octomap.ot, OctoMap's tree after inserting the scans in order at 0.1 m.
"""
import struct
import sys
from pathlib import Path

import numpy as np
import octomap

sys.path.insert(0, str(Path(__file__).parent))
from scene import beams  # noqa: E402

OUT = Path("crates/kinplan-core/src/octree/fixtures")
SCANS = [((0.1, 0.2, 1.3), 0.3, 24, 18, -1.0, 0.01, 1),
         ((-0.7, -0.4, 1.0), 2.2, 24, 18, 2.5, 0.01, 2),
         ((0.1, 0.2, 1.3), 0.3, 24, 18, -1.0, 0.0, 3)]


def main():
    tree = octomap.OcTree(0.1)
    blob = bytearray(struct.pack("<I", len(SCANS)))
    for origin, yaw, w, h, max_range, noise, seed in SCANS:
        pts = beams(origin, yaw, w, h, noise=noise, seed=seed)
        o = np.array(origin, dtype=np.float32)
        tree.insertPointCloud(pts.astype(np.float64), o.astype(np.float64), maxrange=max_range)
        blob += struct.pack("<3ffI", *o.tolist(), max_range, len(pts))
        blob += pts.astype("<f4").tobytes()
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "scans.bin").write_bytes(bytes(blob))
    tree.write(str(OUT / "scans_octomap.ot"))
    print("nodes", tree.size(), "leaves", tree.getNumLeafNodes())


if __name__ == "__main__":
    main()
