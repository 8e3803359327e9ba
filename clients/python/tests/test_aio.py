"""kinplan.aio against a real server: the same answers as the blocking
client, concurrent calls on one channel, a StreamIk session, typed errors."""
import asyncio
import math
import socket

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


def test_retime_a_line_from_rest_to_rest(server_address):
    start = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
    line = np.array([start, start + [1.0, 0, 0, 0, 0, 0]])
    v, a = [1.0] * 6, [2.0] * 6

    async def main():
        async with kinplan.aio.Client(server_address, timeout=20) as c:
            ur5 = c.robot("ur5")
            optimal = await ur5.retime(line, max_velocity=v, max_acceleration=a)
            smooth = await ur5.retime(line, method="jerk_limited", max_velocity=v, max_acceleration=a,
                                      max_jerk=[10.0] * 6)
            return optimal, smooth

    optimal, smooth = run(main())
    # trapezoid 1/1 + 1/2 s; S-curve with T_j = 0.2, T_a = 0.3 and 0.3 s of cruise: 1.7 s
    assert abs(optimal.duration - 1.5) < 2e-3 and abs(smooth.duration - 1.7) < 1e-9
    assert smooth.qd.shape == smooth.q.shape and np.all(np.abs(smooth.qdd) <= 2.0 + 1e-9)


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


# --- the calls beyond IK, planning and scoring: each against the blocking
# client's answer on the same inputs, plus a fact computed independently


def test_track_solve_linear_and_compare_match_the_blocking_client(server_address):
    sync = kinplan.Client(server_address, timeout=20)
    robot_sync = sync.robot(KR210)
    end = robot_sync.fk(Q0)
    end[:3, 3] += [0.0, 0.05, -0.05]
    A = np.array([[2.0, 1.0], [1.0, 3.0], [0.0, 1.0]])
    b = np.array([3.0, 5.0, 1.0])
    sets = {"a": [np.column_stack([0.1 * np.arange(5), np.zeros(5)])],
            "b": [np.column_stack([0.1 * np.arange(3), np.zeros(3)]), np.column_stack([0.1 * np.arange(2), np.zeros(2)])]}

    async def main():
        async with kinplan.aio.Client(server_address, timeout=20) as c:
            robot = c.robot(KR210)
            line = await robot.track(seed=Q0, line={"end": end, "steps": 10})
            again = await robot.track(line.targets, seed=Q0, max_iterations=200)
            x = await c.solve_linear(A, b)
            relaxed = await c.solve_linear(A[:2], b[:2], "angle_relaxation", tolerance=1e-10, max_iterations=100_000,
                                           history=True)
            table = await c.compare(sets, robot="planar_2")
            reached = await asyncio.gather(*(robot.fk(q) for q in line.q))
            return line, again, x, relaxed, table, reached

    line, again, x, relaxed, table, reached = run(main())
    expect = robot_sync.track(seed=Q0, line={"end": end, "steps": 10})
    assert line.all_converged and len(line) == len(expect) == 11  # the start, then 10 steps
    assert np.array_equal(line.q, expect.q) and np.array_equal(line.targets, expect.targets)
    assert line.status == expect.status and line.stop_reason == expect.stop_reason
    np.testing.assert_allclose(line.targets[-1], end, atol=1e-9)  # the line ends where it was told to
    np.testing.assert_allclose(line.targets[5, :3, 3], (line.targets[0, :3, 3] + end[:3, 3]) / 2, atol=1e-12)
    for T, R in zip(line.targets, reached):
        assert np.linalg.norm(T[:3, 3] - R[:3, 3]) <= 1e-5
    assert np.array_equal(again.q, robot_sync.track(expect.targets, seed=Q0, max_iterations=200).q)

    x_sync = sync.solve_linear(A, b)
    assert np.array_equal(x.x, x_sync.x) and x.status == x_sync.status == "converged"
    np.testing.assert_allclose(x.x, np.linalg.lstsq(A, b, rcond=None)[0], atol=1e-12)  # least squares
    relaxed_sync = sync.solve_linear(A[:2], b[:2], "angle_relaxation", tolerance=1e-10, max_iterations=100_000,
                                     history=True)
    assert np.array_equal(relaxed.x, relaxed_sync.x) and np.array_equal(relaxed.history, relaxed_sync.history)
    np.testing.assert_allclose(relaxed.x, np.linalg.solve(A[:2], b[:2]), atol=1e-8)

    assert table.to_dict() == sync.compare(sets, robot="planar_2").to_dict()
    # JD sums joint travel (S0 §2): 0.4 rad for "a"; 0.2 and 0.1 rad in "b"
    assert table["a"]["JD"]["mean"] == pytest.approx(0.4, abs=1e-12)
    assert table["b"]["JD"]["sum"] == pytest.approx(0.3, abs=1e-12)
    assert table["b"]["JD"]["variance"] == pytest.approx(0.005, abs=1e-12)
    sync.close()


def test_mobile_calls_match_the_blocking_client(server_address):
    sync = kinplan.Client(server_address, timeout=20)
    world = [{"circle": (2, 0, 0.5)}, {"polygon": [(3, -1.5), (3.5, -1.5), (3.5, -1)]}]
    blocked = [2.0] * 8
    blocked[0] = 0.1

    async def main():
        async with kinplan.aio.Client(server_address, timeout=20) as c:
            omni = await c.mobile.wheels("omni", (0.0, 0.0, 1.0))
            back = await c.mobile.wheels("differential", wheels={"left": 2.0, "right": 4.0})
            first = await c.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked)
            second = await c.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked,
                                         token=first)
            follow = await c.mobile.follow(chassis="differential", start=(-1, 1, 2.36), path=[(0, 0, 0)],
                                           controller="lyapunov")
            nav = await c.mobile.navigate(chassis="differential", start=(0, 0, 0), goal=(4, 0), world=world,
                                          robot_radius=0.22)
            return omni, back, first, second, follow, nav

    omni, back, first, second, follow, nav = run(main())
    # OMR-III: three wheels at R from the centre, radius r: each turns R ω / r = 3 rad/s for ω = 1
    assert omni.wheels["speeds"] == pytest.approx([3, 3, 3])
    back_sync = sync.mobile.wheels("differential", wheels={"left": 2.0, "right": 4.0})
    assert np.array_equal(back.twist, back_sync.twist) and back.twist[0] > 0 and back.twist[2] > 0
    s1 = sync.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked)
    s2 = sync.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked, token=s1)
    assert first.token == s1.token and second.token == s2.token
    assert np.array_equal(second.command, s2.command) and second.mode == s2.mode
    follow_sync = sync.mobile.follow(chassis="differential", start=(-1, 1, 2.36), path=[(0, 0, 0)],
                                     controller="lyapunov")
    assert follow.reached and np.array_equal(follow.states, follow_sync.states)
    assert np.linalg.norm(follow.states[-1][:2]) <= 0.1  # it ended at the path's node
    nav_sync = sync.mobile.navigate(chassis="differential", start=(0, 0, 0), goal=(4, 0), world=world,
                                    robot_radius=0.22)
    assert nav.outcome == nav_sync.outcome == "REACHED" and np.array_equal(nav.states, nav_sync.states)
    assert nav.min_clearance == nav_sync.min_clearance and nav.min_clearance > 0
    sync.close()


def wall():
    """Points at the centres of a 6 x 6 wall of 0.1 m cells at x in [2.0, 2.1)."""
    ys, zs = np.meshgrid((np.arange(-3, 3) + 0.5) * 0.1, (np.arange(-3, 3) + 0.5) * 0.1)
    return np.column_stack([np.full(36, 2.05), ys.ravel(), zs.ravel()])


def test_exploration_calls_match_the_blocking_client(server_address):
    sync = kinplan.Client(server_address, timeout=60)

    async def main():
        async with kinplan.aio.Client(server_address, timeout=60) as c:
            tree = await c.insert_scan(None, wall(), origin=[0, 0, 0], resolution=0.1)
            info, views = await asyncio.gather(
                c.octree_info(tree, box=([1.9, -0.4, -0.4], [2.2, 0.4, 0.4])),
                c.next_best_view(tree, camera_pose=np.eye(4), weights=(1.0, 0.5, 0.25), max_results=5),
            )
            ref = await c.reference_scene("s0_walled_cell", seed=1)
            run_ = [m async for m in c.explore(scene=ref, resolution=0.2, pixel_stride=8, max_iterations=1)]
            return tree, info, views, ref, run_

    tree, info, views, ref, explored = run(main())
    tree_sync = sync.insert_scan(None, wall(), origin=[0, 0, 0], resolution=0.1)
    assert tree.data == tree_sync.data and tree.resolution == 0.1
    info_sync = sync.octree_info(tree_sync, box=([1.9, -0.4, -0.4], [2.2, 0.4, 0.4]))
    assert info["occupied_leaves"] == info_sync["occupied_leaves"] == 36  # the wall's cells, counted by hand
    assert info["occupied_volume"] == pytest.approx(36 * 0.1 ** 3)
    assert info["unknown_volume"] == info_sync["unknown_volume"]
    views_sync = sync.next_best_view(tree_sync, camera_pose=np.eye(4), weights=(1.0, 0.5, 0.25), max_results=5)
    assert 0 < len(views) == len(views_sync) and np.array_equal(views.poses, views_sync.poses)
    assert np.array_equal(views.utility, views_sync.utility)
    np.testing.assert_allclose(views.utility, views.gain + 0.5 * views.distance + 0.25 * views.rotation, atol=1e-9)

    ref_sync = sync.reference_scene("s0_walled_cell", seed=1)
    assert ref.robot == ref_sync.robot and np.array_equal(ref.start, ref_sync.start)
    assert [o.SerializeToString() for o in ref.obstacles] == [o.SerializeToString() for o in ref_sync.obstacles]
    *steps, summary = explored
    *steps_sync, summary_sync = list(sync.explore(scene=ref_sync, resolution=0.2, pixel_stride=8, max_iterations=1))
    assert isinstance(summary, kinplan.ExploreSummary) and all(isinstance(s, kinplan.ExploreStep) for s in steps)
    assert summary.iterations == len(steps) == len(steps_sync) == 1
    assert (summary.status, summary.known_ratio) == (summary_sync.status, summary_sync.known_ratio)
    assert summary.octree.data == summary_sync.octree.data
    for s, t in zip(steps, steps_sync):
        assert s.known_ratio == t.known_ratio and np.array_equal(s.trajectory, t.trajectory)
    sync.close()


def test_plan_stream_is_an_async_iterator_with_the_blocking_frames(server_address):
    start, goal = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0]), np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
    sync = kinplan.Client(server_address, timeout=30)
    ur5_sync = sync.robot("ur5")
    scene = [kinplan.Sphere(0.12, ur5_sync.fk((start + goal) / 2)[:3, 3], id="ball")]

    async def main():
        async with kinplan.aio.Client(server_address, timeout=30) as c:
            ur5 = c.robot("ur5")
            frames = [f async for f in c.plan_stream(ur5, start=start, goal=goal, scene=scene, seed=2)]
            # leaving the loop early ends the call; the channel serves the next one
            async for first in c.plan_stream("ur5", start=start, goal=goal, scene=scene, seed=2):
                break
            return frames, first, await c.ping()

    frames, first, _ = run(main())
    expect = list(sync.plan_stream(ur5_sync, start=start, goal=goal, scene=scene, seed=2))
    *iterations, final = frames
    assert isinstance(final, kinplan.Plan) and final.success and len(frames) == len(expect)
    assert iterations and all(f.shape == (40, 6) for f in iterations)
    for f, g in zip(iterations, expect[:-1]):
        assert np.array_equal(f, g)
    assert np.array_equal(first, expect[0])
    assert np.array_equal(final.q, expect[-1].q)
    # the final trajectory starts and ends where it was asked to
    np.testing.assert_array_equal(final.q[0], start)
    np.testing.assert_array_equal(final.q[-1], goal)
    sync.close()


def test_errors_of_the_new_calls_are_the_blocking_clients(server_address):
    sync = kinplan.Client(server_address, timeout=10)

    def blocking_error(call):
        with pytest.raises(kinplan.KinplanError) as e:
            result = call()
            if hasattr(result, "__next__"):
                list(result)
        return e.value

    async def main():
        async with kinplan.aio.Client(server_address, timeout=10) as c:
            out = []
            with pytest.raises(kinplan.InvalidArgument) as e:
                await c.solve_linear(np.eye(2), [1.0])  # b has one entry for two rows
            out.append(e.value)
            with pytest.raises(kinplan.InvalidArgument) as e:
                await c.robot(KR210).track(seed=np.zeros(6), circle={"centre": (0, 0, 0), "normal": (0, 0, 0),
                                                                     "angle_step": 0.1, "steps": 5})
            out.append(e.value)
            with pytest.raises(kinplan.InvalidArgument) as e:
                await c.mobile.wheels("omni", (0.0, 0.0, 1.0), chassis_params={"wheel_radius": -1.0})
            out.append(e.value)
            with pytest.raises(kinplan.InvalidArgument) as e:
                await c.insert_scan(None, wall(), resolution=-1.0)
            out.append(e.value)
            with pytest.raises(kinplan.InvalidArgument) as e:  # raised by the stream, after the call began
                [m async for m in c.plan_stream("ur5", start=[0.0] * 5, goal=[0.0] * 6)]
            out.append(e.value)
            with pytest.raises(ValueError, match="planner"):  # the shared builder's own check
                [m async for m in c.explore("ur5", scene=[], start=[0.0] * 6, region=([0, 0, 0], [1, 1, 1]),
                                            planner="rrt")]
            return out

    errors = run(main())
    expected = [
        blocking_error(lambda: sync.solve_linear(np.eye(2), [1.0])),
        blocking_error(lambda: sync.robot(KR210).track(seed=np.zeros(6), circle={
            "centre": (0, 0, 0), "normal": (0, 0, 0), "angle_step": 0.1, "steps": 5})),
        blocking_error(lambda: sync.mobile.wheels("omni", (0.0, 0.0, 1.0), chassis_params={"wheel_radius": -1.0})),
        blocking_error(lambda: sync.insert_scan(None, wall(), resolution=-1.0)),
        blocking_error(lambda: sync.plan_stream(sync.robot("ur5"), start=[0.0] * 5, goal=[0.0] * 6)),
    ]
    for got, want in zip(errors, expected):
        assert type(got) is type(want) and got.code == want.code
        assert got.field_violations == want.field_violations and got.field_violations
    assert "b" in errors[0].field_violations[0][0] and "circle.normal" in errors[1].field_violations[0][0]
    sync.close()


def test_the_asyncio_methods_take_the_blocking_methods_parameters():
    """Names, kinds and defaults of every public method's parameters, class by
    class; the blocking-only methods are listed (not yet in kinplan.aio)."""
    import inspect

    from kinplan._aio_mobile import AsyncMobile
    from kinplan.mobile import Mobile

    not_yet = {"limits_key"}  # a cache key
    checked = []
    for sync_cls, aio_cls in ((kinplan.Client, kinplan.aio.Client), (kinplan.Robot, kinplan.aio.AsyncRobot),
                              (Mobile, AsyncMobile)):
        for name, method in inspect.getmembers(sync_cls, callable):
            if name.startswith("_") or name in not_yet:
                continue
            other = getattr(aio_cls, name)
            assert inspect.iscoroutinefunction(other) or inspect.isasyncgenfunction(other) or name in (
                "robot", "stream_ik", "local"), name
            params = [(p.name, p.kind, p.default) for p in inspect.signature(method).parameters.values()]
            assert params == [(p.name, p.kind, p.default) for p in inspect.signature(other).parameters.values()], name
            checked.append(name)
    assert {"ik", "track", "solve_linear", "compare", "plan_stream", "explore", "navigate", "step", "urdf",
            "wait_for_ready"} <= set(checked)

    async def mobile_of_a_client():
        async with kinplan.aio.Client("127.0.0.1:1") as c:  # no call: no server needed
            return type(c.mobile)

    assert run(mobile_of_a_client()) is AsyncMobile


def test_urdf_wait_for_ready_and_robot_arguments_as_the_blocking_client(server_address):
    sync = kinplan.Client(server_address, timeout=10)
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        nobody = f"127.0.0.1:{s.getsockname()[1]}"

    async def main():
        async with kinplan.aio.Client(server_address, timeout=10) as c:
            await c.wait_for_ready()
            text = await c.robot("ur5").urdf()
            kept = await c.robot("ur5").urdf(keep_capsules=True)
            inline = await c.robot(urdf=text).urdf()
            with pytest.raises(kinplan.InvalidArgument, match="file path"):
                c.robot(urdf="arm.urdf")
        async with kinplan.aio.Client(nobody, timeout=10) as c:
            with pytest.raises(kinplan.Unavailable, match="within 0.3 s"):
                await c.wait_for_ready(0.3)
        return text, kept, inline

    text, kept, inline = run(main())
    assert text == sync.robot("ur5").urdf() and kept == sync.robot("ur5").urdf(keep_capsules=True)
    assert inline == text and text.lstrip().startswith("<") and "<robot" in text
    with pytest.raises(kinplan.InvalidArgument, match="file path"):
        sync.robot(urdf="arm.urdf")
    with pytest.raises(kinplan.Unavailable, match="within 0.3 s"):
        kinplan.Client(nobody, timeout=10).wait_for_ready(0.3)
    sync.close()


def test_ik_keywords_give_the_blocking_answers(server_address):
    sync = kinplan.Client(server_address, timeout=10)
    robot_sync = sync.robot(KR210)
    T = robot_sync.fk(Q0)
    kw = dict(num_solutions=3, max_restarts=50, rng_seed=4, position_tolerance=1e-7, history=True)

    async def main():
        async with kinplan.aio.Client(server_address, timeout=10) as c:
            robot = c.robot(KR210)
            return await robot.ik(T, seed=np.zeros(6), **kw), await robot.ik(T[:3, 3], seed=Q0)

    full, position = run(main())
    expect = robot_sync.ik(T, seed=np.zeros(6), **kw)
    assert full.success and len(full.solutions) == len(expect.solutions) >= 1
    for a, b in zip(full.solutions, expect.solutions):
        assert np.array_equal(a.q, b.q) and np.array_equal(a.history, b.history)
        assert np.linalg.norm(robot_sync.fk(a.q)[:3, 3] - T[:3, 3]) <= 1e-7
    # a bare 3-vector is a position-only target in both clients
    assert position.success and np.array_equal(position.q, robot_sync.ik(T[:3, 3], seed=Q0).q)
    sync.close()


@pytest.mark.skipif("local" not in __import__("conftest").BACKENDS, reason="the native extension is not built")
def test_the_in_process_asyncio_client_answers_as_the_blocking_one(local_client):
    """kinplan.aio.Client.local(): unary calls, a server stream, a StreamIk
    session and typed errors, against the blocking in-process client."""
    robot_sync = local_client.robot("ur5")
    start = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
    goal = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])

    async def main():
        async with kinplan.aio.Client.local(timeout=10, acm_samples=1000) as c:
            await c.wait_for_ready()
            robot = c.robot("ur5")
            T = await robot.fk(start)
            # several calls at once on one in-process channel
            Ts = await asyncio.gather(*(robot.fk(start + 0.01 * k) for k in range(4)))
            ik = await robot.ik(T, seed=start + 0.05)
            frames = [f async for f in c.plan_stream(robot, start=start, goal=goal, algorithm="stomp", seed=2,
                                                      stomp={"timesteps": 10, "max_iterations": 5})]
            async with robot.stream_ik(seed=start) as s:
                tracked = [await s.solve(T), await s.solve(T)]
            errors = []
            for bad in (lambda: c.robot("no_such_robot").fk(start), lambda: robot.fk([math.nan] * 6)):
                try:
                    await bad()
                except kinplan.KinplanError as e:
                    errors.append(e)
            return T, Ts, ik, frames, tracked, errors

    T, Ts, ik, frames, tracked, errors = run(main())
    np.testing.assert_array_equal(T, robot_sync.fk(start))
    for k, Tk in enumerate(Ts):
        np.testing.assert_array_equal(Tk, robot_sync.fk(start + 0.01 * k))
    assert ik.success and np.allclose(robot_sync.fk(ik.q), T, atol=1e-5)
    assert isinstance(frames[-1], kinplan.Plan) and len(frames) >= 2
    assert all(isinstance(f, np.ndarray) for f in frames[:-1])
    np.testing.assert_array_equal(frames[-1].q[0], start)
    assert all(r.success for r in tracked)
    assert isinstance(errors[0], kinplan.NotFound) and isinstance(errors[1], kinplan.InvalidArgument)
    assert errors[1].field_violations and "joint_positions" in errors[1].field_violations[0][0]
