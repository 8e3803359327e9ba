"""IK from Python, one run, same targets: kinplan's in-process backend
(`kinplan.Client.local()`), kinplan over gRPC (the client and the raw
generated stub), and roboticstoolbox-python's in-process C++ `ik_LM`:

    python ik_vs_rtb.py [host:port] [targets]

Targets follow the TRAC-IK protocol on the KUKA KR 210 R2700 extra: joints
drawn uniformly within the limits (seeded), their FK pose the target, every
solver started from the middle of the limits. roboticstoolbox reads the same
robot from `robot.urdf()` (its FK is checked against ours first). Success is
judged the same way for every solver, by kinplan's FK of the returned joints:
position within 1e-5 m and rotation within 1e-5 rad. roboticstoolbox runs
twice: at its defaults (tol 1e-6 on E = ½ eᵀe, i.e. |e| up to ~1.4e-3) and at
a tolerance matched to ours (E ≤ 5e-11, |e| ≤ 1e-5), both with joint limits
and its default 100 searches.
Needs `pip install roboticstoolbox-python kinplan-native`.
"""
import sys
import tempfile
import time
from typing import Any, Callable, Dict, List

import numpy as np

import kinplan
from kinplan.kinematics import ik_options, target_to_pose
from kinplan.v1 import kinematics_pb2

ROBOT = "kuka_kr210_r2700_extra"


def stats(label: str, times_s: List[float], ok: List[bool]) -> float:
    us = np.array(times_s) * 1e6
    print(f"{label:<46} mean {us.mean():7.1f} µs  median {np.median(us):7.1f} µs  "
          f"p95 {np.percentile(us, 95):8.1f} µs  solved {100 * np.mean(ok):5.1f} %")
    return float(us.mean())


def main() -> None:
    address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 500
    import roboticstoolbox as rtb

    local = kinplan.Client.local()
    remote = kinplan.Client(address, timeout=10, wait_for_ready=True)
    robot_local, robot_remote = local.robot(ROBOT), remote.robot(ROBOT)
    d = robot_local.describe()
    rng = np.random.default_rng(2026)
    qs = rng.uniform(d.lower, d.upper, size=(n, d.dof))
    targets = [robot_local.fk(q) for q in qs]
    mid = (d.lower + d.upper) / 2

    with tempfile.NamedTemporaryFile("w", suffix=".urdf") as f:
        f.write(robot_local.urdf())
        f.flush()
        r = rtb.Robot.URDF(f.name)
    for q, T in zip(qs[:20], targets[:20]):
        assert np.allclose(r.fkine(q).A, T, atol=1e-12), "roboticstoolbox reads another robot"

    def solved(q: Any, target: Any) -> bool:
        T = robot_local.fk(q)
        dp = np.linalg.norm(T[:3, 3] - target[:3, 3])
        c = (np.trace(T[:3, :3].T @ target[:3, :3]) - 1) / 2
        return bool(dp <= 1e-5 and np.arccos(np.clip(c, -1, 1)) <= 1e-5)

    stub = remote._kinematics
    options = ik_options("lm", "svd")
    runs: Dict[str, Callable[[Any], Any]] = {
        "kinplan in-process  robot.ik (Client.local())": lambda T: robot_local.ik(T).q,
        "kinplan over gRPC   robot.ik": lambda T: robot_remote.ik(T).q,
        "kinplan over gRPC   raw generated stub": lambda T: np.array(
            stub.SolveIk(kinematics_pb2.SolveIkRequest(
                robot=robot_remote._ref(), target=target_to_pose(T), options=options), timeout=10).solutions[0].joints
            or [np.nan] * 6),
        "roboticstoolbox ik_LM, defaults": lambda T: r.ik_LM(T, q0=mid, joint_limits=True)[0],
        "roboticstoolbox ik_LM, tol 5e-11 (|e| ≤ 1e-5)": lambda T: r.ik_LM(T, q0=mid, tol=5e-11, joint_limits=True)[0],
    }
    print(f"{n} KR 210 targets (TRAC-IK protocol), {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    means = {}
    for label, solve in runs.items():
        for target in targets[:20]:
            solve(target)
        times: List[float] = []
        ok: List[bool] = []
        for target in targets:
            t0 = time.perf_counter()
            q = solve(target)
            times.append(time.perf_counter() - t0)
            ok.append(bool(np.all(np.isfinite(q))) and solved(q, target))
        means[label] = stats(label, times, ok)
    labels = list(runs)
    print(f"ratio in-process / rtb defaults: {means[labels[0]] / means[labels[3]]:.2f}; "
          f"/ rtb matched tolerance: {means[labels[0]] / means[labels[4]]:.2f}; "
          f"gRPC client / raw stub: {means[labels[1]] / means[labels[2]]:.2f}")


if __name__ == "__main__":
    main()
