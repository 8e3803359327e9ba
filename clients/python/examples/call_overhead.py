"""Python-side cost of the client over the raw generated stub, same server,
same calls, one run:

    python call_overhead.py [host:port] [calls]

For FK and warm IK on the UR5: the mean time of `robot.fk(q)` / `robot.ik(T,
seed=...)` against the generated stub called with a request built once, and
the difference (the client's own overhead per call), then the same from
the medians. Calls alternate, so drift in the machine's speed hits both
alike. Rows:

- ForwardKinematics: `robot.fk(q)`, the 4x4 array returned;
- SolveIk (warm, seed built per call): `robot.ik(T, seed=q + 0.02)`, the
  seed's numpy addition inside the timed call (the first version of this
  script; the stub's request holds the seed already);
- SolveIk (warm): the same seed array made once, as the stub's request is;
- SolveIk (warm) read: both sides also read the answer -- `.success` and
  `.q` of the client's result, `.success` and the first solution's joints
  as a numpy array (through a list) from the stub's reply.
"""
from typing import Any, List

import statistics
import sys
import time

import numpy as np

import kinplan
from kinplan.kinematics import ik_options, target_to_pose
from kinplan.v1 import kinematics_pb2, robot_pb2


def interleaved_us(a: Any, b: Any, n: int) -> Any:
    """Mean and median µs of `a` and of `b`, called alternately so that
    drift in the machine's speed hits both alike (the medians shrug off the
    calls another process on the machine delays)."""
    for _ in range(50):
        a()
        b()
    ta: List[float] = []
    tb: List[float] = []
    for _ in range(n):
        t0 = time.perf_counter()
        a()
        t1 = time.perf_counter()
        b()
        t2 = time.perf_counter()
        ta.append(t1 - t0)
        tb.append(t2 - t1)
    return (sum(ta) / n * 1e6, sum(tb) / n * 1e6, statistics.median(ta) * 1e6, statistics.median(tb) * 1e6)


def main() -> None:
    address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 3000
    with kinplan.Client(address, timeout=10) as c:
        ur5 = c.robot("ur5")
        q = np.array([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
        T = ur5.fk(q)
        ref = ur5._ref()
        fk_req = robot_pb2.ForwardKinematicsRequest(robot=ref, joint_positions=q.tolist())
        ik_req = kinematics_pb2.SolveIkRequest(
            robot=ref, target=target_to_pose(T), seed=(q + 0.02).tolist(), options=ik_options("lm", "svd")
        )
        rows = []
        times = interleaved_us(lambda: c._robots.ForwardKinematics(fk_req, timeout=10), lambda: ur5.fk(q), n)
        rows.append(("ForwardKinematics", *times))
        times = interleaved_us(
            lambda: c._kinematics.SolveIk(ik_req, timeout=10), lambda: ur5.ik(T, seed=q + 0.02), n
        )
        rows.append(("SolveIk (warm, seed built per call)", *times))
        seed = q + 0.02
        times = interleaved_us(lambda: c._kinematics.SolveIk(ik_req, timeout=10), lambda: ur5.ik(T, seed=seed), n)
        rows.append(("SolveIk (warm)", *times))

        def raw_read() -> Any:
            r = c._kinematics.SolveIk(ik_req, timeout=10)
            return r.success, np.array(r.solutions[0].joints[:])  # through a list: the fastest way

        def ours_read() -> Any:
            r = ur5.ik(T, seed=seed)
            return r.success, r.q

        times = interleaved_us(raw_read, ours_read, n)
        rows.append(("SolveIk (warm) read", *times))
        for name, raw, ours, raw_median, ours_median in rows:
            print(f"{name:36s} raw stub {raw:7.1f} us   client {ours:7.1f} us   overhead {ours - raw:6.1f} us "
                  f"({ours / raw:.2f}x)   medians {raw_median:6.1f} / {ours_median:6.1f} us: "
                  f"{ours_median - raw_median:5.1f} us")

if __name__ == "__main__":
    main()
