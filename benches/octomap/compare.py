"""kinplan's octree against OctoMap (through octomap-python) on the same data, one run.

Run from the repository root (liboctomap-dev for geb079.bt, octomap-python + numpy):

    python benches/octomap/compare.py [--out target/octree_bench]

1. .bt parse / write of geb079.bt: OctoMap readBinary / writeBinary (to a file under
   --out, so OctoMap's figure includes a file read/write; ours works on memory).
2. castRay: 20,000 rays from free cells of geb079 in seeded directions, OctoMap called
   per ray from Python; the binding's per-call overhead is estimated by casting from an
   occupied cell (returns after one lookup) and subtracted. The end cells of both are
   compared.
3. insertPointCloud of a 512 x 424 (217,088-point) cloud of the synthetic room at 5 cm:
   times, and the two resulting trees compared byte for byte (.ot); our written .bt is
   loaded by OctoMap.
Prints a Markdown table.
"""
import argparse
import json
import os
import platform
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import octomap

sys.path.insert(0, str(Path(__file__).parent))
from scene import beams  # noqa: E402

GEB = "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"


def best(f, reps):
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    ts.sort()
    return ts[len(ts) // 2]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="target/octree_bench")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    res = {}

    # 1. parse / write
    tree = octomap.OcTree(0.1)
    res["om_parse_ms"] = 1e3 * best(lambda: tree.readBinary(GEB.encode()), 15)
    wpath = str(out / "om_geb.bt").encode()
    res["om_write_ms"] = 1e3 * best(lambda: tree.writeBinary(wpath), 15)
    res["om_write_identical"] = Path(wpath.decode()).read_bytes() == Path(GEB).read_bytes()

    # 2. rays from free cells
    rng = np.random.default_rng(7)
    lo, hi = np.array(tree.getMetricMin()), np.array(tree.getMetricMax())
    origins, dirs = [], []
    while len(origins) < 20000:
        p = lo + rng.random(3) * (hi - lo)
        n = tree.search(p)
        try:
            free = n is not None and not tree.isNodeOccupied(n)
        except octomap.NullPointerException:  # unknown space
            free = False
        if free:
            k = tree.coordToKey(p)
            c = np.array(tree.keyToCoord(k), dtype=np.float32)
            d = rng.normal(size=3)
            d /= np.linalg.norm(d)
            origins.append(c)
            dirs.append(d.astype(np.float32))
    origins = np.array(origins, dtype=np.float32)
    dirs = np.array(dirs, dtype=np.float32)
    with open(out / "rays.bin", "wb") as f:
        f.write(struct.pack("<I", len(origins)))
        f.write(np.hstack([origins, dirs]).astype("<f4").tobytes())
    o64, d64 = origins.astype(np.float64), dirs.astype(np.float64)
    ends = np.zeros((len(o64), 3))
    hits = np.zeros(len(o64), dtype=bool)
    end = np.zeros(3)

    def cast_all():
        for i in range(len(o64)):
            hits[i] = tree.castRay(o64[i], d64[i], end)
            ends[i] = end

    res["om_cast_s"] = best(cast_all, 3)
    # overhead: the same loop from an occupied cell (one lookup, then return)
    occ = None
    for it in tree.begin_leafs():
        if tree.isNodeOccupied(it):
            occ = np.array(it.getCoordinate())
            break

    def cast_overhead():
        for i in range(len(o64)):
            tree.castRay(occ, d64[i], end)

    res["om_cast_overhead_s"] = best(cast_overhead, 3)

    # 3. insert: one Kinect-v2-sized scan of the room at 5 cm
    origin = np.array([0.1, 0.2, 1.3], dtype=np.float32)
    pts = beams(origin, 0.3, 512, 424, noise=0.01, seed=5)
    with open(out / "cloud.bin", "wb") as f:
        f.write(origin.astype("<f4").tobytes())
        f.write(struct.pack("<I", len(pts)))
        f.write(pts.astype("<f4").tobytes())
    p64, or64 = pts.astype(np.float64), origin.astype(np.float64)
    ins = []
    for _ in range(5):
        t = octomap.OcTree(0.05)
        s = time.perf_counter()
        t.insertPointCloud(p64, or64)
        ins.append(time.perf_counter() - s)
    ins.sort()
    res["om_insert_ms"] = 1e3 * ins[len(ins) // 2]
    t.write(str(out / "om_insert.ot").encode())

    # ours, same files
    cmd = ["cargo", "run", "--release", "-q", "-p", "kinplan-core", "--example", "octree_bench", "--",
           GEB, str(out / "rays.bin"), str(out / "cloud.bin"), str(out)]
    ours = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    res.update({"ours_" + k: v for k, v in ours.items()})

    # agreement
    oe = np.frombuffer((out / "ours_ray_ends.bin").read_bytes(), dtype=np.uint8).reshape(-1, 13)
    our_ends = oe[:, :12].copy().view("<f4").reshape(-1, 3)
    our_hits = oe[:, 12].astype(bool)
    same = np.all(np.abs(our_ends - ends.astype(np.float32)) < 1e-4, axis=1) & (our_hits == hits)
    res["ray_agreement"] = float(same.mean())
    res["insert_identical_ot"] = (out / "ours_insert.ot").read_bytes() == (out / "om_insert.ot").read_bytes()
    back = octomap.OcTree(0.1)
    back.readBinary(str(out / "ours_insert.bt").encode())
    res["our_bt_loads_in_octomap"] = bool(back.size() > 0)
    res["our_bt_octomap_size"] = back.size()

    n = ours["rays"]
    om_rays = n / res["om_cast_s"]
    om_rays_net = n / max(res["om_cast_s"] - res["om_cast_overhead_s"], 1e-9)
    our_rays = n / ours["cast_serial_s"]
    our_rays_par = n / ours["cast_par_s"]
    mb = ours["bt_bytes"] / 1e6
    print(json.dumps(res, indent=1), file=sys.stderr)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"octomap-python {getattr(octomap, '__version__', '?')}; date {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print()
    print("| measure | OctoMap | kinplan | ratio (OctoMap / kinplan time) |")
    print("|---|---|---|---|")
    print(f"| geb079.bt parse (ms, median) | {res['om_parse_ms']:.1f} (file) | {ours['parse_ms']:.2f} | {res['om_parse_ms'] / ours['parse_ms']:.1f}x |")
    print(f"| geb079.bt parse throughput (MB/s) | {mb / res['om_parse_ms'] * 1e3:.0f} | {mb / ours['parse_ms'] * 1e3:.0f} | |")
    print(f"| geb079.bt write (ms, median) | {res['om_write_ms']:.1f} (file) | {ours['write_ms']:.2f} | {res['om_write_ms'] / ours['write_ms']:.1f}x |")
    print(f"| write-back byte-identical | {res['om_write_identical']} | True (asserted) | |")
    print(f"| castRay, {n} rays, 1 thread (rays/s) | {om_rays:,.0f} raw, {om_rays_net:,.0f} minus call overhead | {our_rays:,.0f} | {our_rays / om_rays_net:.1f}x (vs net) |")
    print(f"| castRay, {ours['threads']} threads (rays/s) | - | {our_rays_par:,.0f} | |")
    print(f"| castRay end cell and hit flag agree | | {100 * res['ray_agreement']:.2f} % of rays | |")
    print(f"| DDA steps/s/core (castRay, default params) | | {ours['cast_steps'] / ours['cast_serial_s'] / 1e6:.1f} M | |")
    print(f"| DDA steps/s/core (ignore unknown, 20 m) | | {ours['long_steps'] / ours['long_s'] / 1e6:.1f} M | |")
    print(f"| insertPointCloud 512x424 at 5 cm (ms, median of 5/7) | {res['om_insert_ms']:.0f} | {ours['insert_ms']:.0f} (trace {ours['insert_trace_ms']:.0f} + update {ours['insert_update_ms']:.0f}) | {res['om_insert_ms'] / ours['insert_ms']:.2f}x |")
    print(f"| insert result identical (.ot bytes) | | {res['insert_identical_ot']} | |")
    print(f"| our .bt of that tree loads in OctoMap | | {res['our_bt_loads_in_octomap']} ({res['our_bt_octomap_size']} nodes; ours {ours['nodes']} before ML pruning) | |")


if __name__ == "__main__":
    main()
