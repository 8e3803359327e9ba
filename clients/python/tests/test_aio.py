"""kinplan.aio against a real server: the same answers as the blocking
client, concurrent calls on one channel, a StreamIk session, typed errors."""
import asyncio
import math

import numpy as np
import pytest

import kinplan
import kinplan.aio

KR210 = "kuka_kr210_r2700_extra"
Q0 = [0.2, -1.6, 1.7, 0.3, 0.8, -0.2]


def run(coro):
    return asyncio.run(coro)


def test_answers_match_the_blocking_client(server_address):
    sync = kinplan.Client(server_address, timeout=10)
    robot_sync = sync.robot(KR210)

    async def main():
        async with kinplan.aio.Client(server_address, timeout=10) as c:
            robot = c.robot(KR210)
            d = await robot.describe()
            T = await robot.fk(Q0)
            J = await robot.jacobian(Q0)
            Ts, Js = await robot.fk_batch(np.array([Q0, Q0]), jacobians=True)
            q = np.linspace(np.array(Q0), np.array(Q0) + 0.2, 20)
            scores = await c.score(robot, q)
            return d, T, J, Ts, Js, scores

    d, T, J, Ts, Js, scores = run(main())
    assert d.joint_names == robot_sync.describe().joint_names
    assert np.array_equal(T, robot_sync.fk(Q0))
    assert np.array_equal(J, robot_sync.jacobian(Q0))
    assert np.array_equal(Ts[1], T) and np.array_equal(Js[0], J)
    assert scores["JD"] == pytest.approx(sync.score(robot_sync, np.linspace(np.array(Q0), np.array(Q0) + 0.2, 20))["JD"])
    # JD (S0 §2) sums every joint's absolute travel: 6 joints x 0.2 rad
    assert scores["JD"] == pytest.approx(6 * 0.2, rel=1e-9)
    sync.close()


def test_many_concurrent_ik_calls_on_one_channel_round_trip_through_fk(server_address):
    rng = np.random.default_rng(7)

    async def main():
        async with kinplan.aio.Client(server_address, timeout=20) as c:
            robot = c.robot(KR210)
            d = await robot.describe()
            qs = rng.uniform(d.lower, d.upper, size=(40, d.dof))
            targets = await asyncio.gather(*(robot.fk(q) for q in qs))
            answers = await asyncio.gather(*(robot.ik(T) for T in targets))
            reached = await asyncio.gather(*(robot.fk(a.q) for a in answers))
            batch = await robot.ik_batch(np.stack(targets), seed=qs + 0.01)
            return targets, answers, reached, batch

    targets, answers, reached, batch = run(main())
    assert all(a.success for a in answers)
    for T, R in zip(targets, reached):
        assert np.linalg.norm(T[:3, 3] - R[:3, 3]) <= 1e-5
    assert batch.succeeded == len(targets)


def test_a_stream_session_tracks_a_circle(server_address):
    async def main():
        async with kinplan.aio.Client(server_address, timeout=10) as c:
            robot = c.robot(KR210)
            start = await robot.fk(Q0)
            centre = start[:3, 3] - [0.01, 0, 0]
            results = []
            async with robot.stream_ik(seed=Q0) as s:
                for k in range(30):
                    a = 2 * math.pi * k / 30
                    T = start.copy()
                    T[:3, 3] = centre + 0.01 * np.array([math.cos(a), math.sin(a), 0])
                    results.append((T, await s.solve(T)))
            return robot, results

    robot, results = run(main())
    assert [r.sequence for _, r in results] == list(range(1, 31))
    for T, r in results:
        assert r.success and r.position_error <= 1e-5


def test_plans_and_state_checks(server_address):
    start, goal = [-1.2, -1.3, 1.4, -1.6, -1.57, 0.0], [1.2, -1.3, 1.4, -1.6, -1.57, 0.0]

    async def main():
        async with kinplan.aio.Client(server_address, timeout=20) as c:
            ur5 = c.robot("ur5")
            mid = await ur5.fk((np.array(start) + goal) / 2)
            scene = [kinplan.Sphere(0.12, mid[:3, 3])]
            plan = await c.plan(ur5, start=start, goal=goal, scene=scene, seed=3)
            checks = await c.check_states(ur5, plan.q, scene)
            blocked = await c.check_states(ur5, (np.array(start) + goal) / 2, scene)
            return plan, checks, blocked

    plan, checks, blocked = run(main())
    assert plan.success and np.allclose(plan.q[0], start) and np.allclose(plan.q[-1], goal)
    assert checks.valid.all() and not blocked.valid[0]


def test_errors_are_the_blocking_clients(server_address):
    async def main():
        async with kinplan.aio.Client(server_address, timeout=10) as c:
            robot = c.robot(KR210)
            with pytest.raises(kinplan.InvalidArgument) as bad:
                await robot.fk([float("nan")] * 6)
            assert bad.value.field_violations and "joint_positions" in bad.value.field_violations[0][0]
            with pytest.raises(kinplan.NotFound):
                await c.robot("no_such_robot").describe()
            with pytest.warns(kinplan.JointLimitWarning):
                await robot.fk([0, -90, 90, 0, 45, 0])
            with pytest.raises(kinplan.InvalidArgument):
                await c.robot(KR210, strict=True).fk([0, -90, 90, 0, 45, 0])
            # an unreachable pose under a short deadline: the best attempt, flagged, not an error
            far = np.eye(4)
            far[:3, 3] = [9.0, 0.0, 1.0]
            answer = await robot.ik(far, max_restarts=10 ** 6, timeout=0.5)
            assert not answer.success and answer.status == "time_budget"

    run(main())
