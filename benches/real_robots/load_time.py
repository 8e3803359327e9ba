"""Time to load example-robot-data's Panda with its meshes in kinplan: the
client reading the files, the first call (URDF and meshes sent, parsed), the
first collision call (meshes read, hulls and fitted polytopes, the pair
tables, the sampled allowed-collision matrix), and the same again through the
server's caches; then the server's resident memory and how much of it is in
transparent huge pages (Linux).

    KINPLAN_BIN=target/release/kinplan python benches/real_robots/load_time.py

Needs example-robot-data (pip) in the running Python's site-packages.
"""
import pathlib
import time
import kinplan
import sys
share = next(pathlib.Path(p) / "cmeel.prefix" / "share" for p in sys.path if (pathlib.Path(p) / "cmeel.prefix" / "share").is_dir())
urdf = share / "example-robot-data/robots/panda_description/urdf/panda.urdf"
with kinplan.LocalServer() as s:
    c = s.client()
    for run in range(2):
        t0 = time.perf_counter()
        robot = c.robot(urdf=urdf, package_dirs=[share], tip_link="panda_hand")
        t1 = time.perf_counter()
        robot.describe()
        t2 = time.perf_counter()
        robot.check([[0, -0.5, 0, -2, 0, 1.5, 0.8]], [kinplan.Sphere(0.05, [2, 2, 2])])
        t3 = time.perf_counter()
        robot.check([[0, -0.5, 0, -2, 0, 1.5, 0.8]], [kinplan.Sphere(0.05, [2, 2, 2])])
        t4 = time.perf_counter()
        print(f"run {run}: read files {1e3*(t1-t0):.0f} ms, first call (send URDF+{len(robot.mesh_files)} meshes, parse) {1e3*(t2-t1):.0f} ms, "
              f"first check (meshes, hulls, ACM sampling) {1e3*(t3-t2):.0f} ms, next check {1e3*(t4-t3):.1f} ms")
    smaps = pathlib.Path(f"/proc/{s.pid}/smaps_rollup") if s.pid is not None else None
    if smaps is not None and smaps.exists():
        kb = {l.split(":")[0]: int(l.split()[1]) for l in smaps.read_text().splitlines()[1:] if l.split()[-1] == "kB"}
        print(f"server resident {kb['Rss'] / 1024:.1f} MiB, of it in transparent huge pages {kb['AnonHugePages'] / 1024:.1f} MiB")
