"""Times each hand-written encoding of kinplan._codec against the generated
protobuf classes doing the same work (no server needed), and prints the
ratio: a hand-written path is kept only where it pays.

    python examples/codec_benchmark.py
"""
from __future__ import annotations

import timeit
from typing import Any, Callable, List, Tuple

import numpy as np

from kinplan import _codec
from kinplan._rotation import pose_values_to_matrix, quat_of_rows, quat_to_matrix
from kinplan.kinematics import ik_options
from kinplan.v1 import common_pb2, kinematics_pb2, robot_pb2


def best(f: Callable[[], Any], number: int) -> float:
    """Seconds per call: the best of five runs of `number` calls."""
    return min(timeit.repeat(f, number=number, repeat=5)) / number


def cases() -> List[Tuple[str, Callable[[], Any], Callable[[], Any], int]]:
    rng = np.random.default_rng(0)
    q = rng.normal(size=6)
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(0.1, 0.2, 0.3, float(np.sqrt(1 - 0.14)))
    T[:3, 3] = (0.4, 0.5, 0.6)
    ref = common_pb2.RobotRef(name="ur5")
    options = ik_options("lm", "svd")
    options_field = _codec.length_delimited(_codec.IK_OPTIONS, options.SerializeToString())
    ref_field = _codec.length_delimited(_codec.ROBOT_REF, ref.SerializeToString())
    x, y, z, w = quat_of_rows(T.tolist())
    reply = robot_pb2.ForwardKinematicsResponse(tool_pose=common_pb2.Pose(
        position=common_pb2.Vec3(x=0.4, y=0.5, z=0.6), orientation=common_pb2.Quaternion(x=x, y=y, z=z, w=w)))
    reply_wire = reply.SerializeToString()
    batch = rng.normal(size=(10_000, 6))
    trajectory = rng.normal(size=(1000, 6))
    times = np.linspace(0.0, 10.0, 1000)

    def fk_request_generated() -> bytes:
        out: bytes = robot_pb2.ForwardKinematicsRequest(robot=ref, joint_positions=q.tolist()).SerializeToString()
        return out

    def fk_reply_generated() -> np.ndarray:
        p = robot_pb2.ForwardKinematicsResponse.FromString(reply_wire).tool_pose
        return pose_values_to_matrix(p.position.x, p.position.y, p.position.z, p.orientation.x, p.orientation.y,
                                     p.orientation.z, p.orientation.w)

    def ik_request_generated() -> bytes:
        a, b, c, d = quat_of_rows(T.tolist())
        pose = common_pb2.Pose(position=common_pb2.Vec3(x=T[0, 3], y=T[1, 3], z=T[2, 3]),
                               orientation=common_pb2.Quaternion(x=a, y=b, z=c, w=d))
        out: bytes = kinematics_pb2.SolveIkRequest(robot=ref, target=pose, seed=q.tolist(),
                                                   options=options).SerializeToString()
        return out

    return [
        ("FK request (ref + 6 joints)", lambda: ref_field + _codec.joints_field(_codec.FK_JOINTS, q, "q"),
         fk_request_generated, 20_000),
        ("FK reply (tool pose -> 4x4)", lambda: _codec.read_fk_reply(reply_wire), fk_reply_generated, 20_000),
        ("IK request (ref + 4x4 target + seed + options)",
         lambda: ref_field + _codec.target_field(T) + _codec.joints_field(_codec.IK_SEED, q, "seed") + options_field,
         ik_request_generated, 20_000),
        ("Matrix 10,000 x 6", lambda: _codec.matrix_message(batch),
         lambda: common_pb2.Matrix(rows=10_000, cols=6, data=batch.ravel().tolist()), 20),
        ("JointTrajectory 1,000 x 6, timed", lambda: _codec.trajectory_message(trajectory, times),
         lambda: common_pb2.JointTrajectory(points=[
             common_pb2.JointPoint(positions=row, time_from_start=t)
             for row, t in zip(trajectory.tolist(), times.tolist())]), 20),
    ]


def main() -> None:
    print(f"{'path':48s} {'by hand':>10s} {'generated':>10s} {'ratio':>7s}")
    for name, hand, generated, number in cases():
        a, b = best(hand, number), best(generated, number)
        print(f"{name:48s} {a * 1e6:8.2f}us {b * 1e6:8.2f}us {b / a:6.1f}x")


if __name__ == "__main__":
    main()
