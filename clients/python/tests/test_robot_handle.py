"""The robot as the handle of every call about it (robot.plan, .plan_stream,
.check, .score, .compare, in both clients), the client's per-robot calls kept
as aliases that warn, IkOptions, and the old module paths."""
import asyncio
import dataclasses
import importlib
import warnings

import numpy as np
import pytest

import kinplan
import kinplan.aio
from kinplan.kinematics import ik_options
from kinplan.v1 import kinematics_pb2

START = np.array([-1.2, -1.3, 1.4, -1.6, -1.57, 0.0])
GOAL = np.array([1.2, -1.3, 1.4, -1.6, -1.57, 0.0])


def ball(ur5):
    return kinplan.Sphere(0.12, ur5.fk((START + GOAL) / 2)[:3, 3], id="ball")


def no_warnings(f, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return f(*args, **kwargs)


def test_robot_calls_answer_as_the_client_aliases_and_the_aliases_warn(client):
    ur5 = client.robot("ur5")
    scene = [ball(ur5)]
    plan = no_warnings(ur5.plan, START, GOAL, algorithm="rrt_connect", scene=scene, seed=3)
    with pytest.warns(DeprecationWarning, match=r"robot\.plan"):
        old = client.plan(ur5, start=START, goal=GOAL, algorithm="rrt_connect", scene=scene, seed=3)
    assert plan.success and np.array_equal(plan.q, old.q) and np.array_equal(plan.t, old.t)

    checks = no_warnings(ur5.check, [START, (START + GOAL) / 2, GOAL], scene)
    with pytest.warns(DeprecationWarning, match=r"robot\.check"):
        old_checks = client.check_states("ur5", [START, (START + GOAL) / 2, GOAL], scene)
    assert list(checks.valid) == list(old_checks.valid) == [True, False, True]
    np.testing.assert_array_equal(checks.clearance, old_checks.clearance)

    q = np.linspace(START, GOAL, 30)
    scores = no_warnings(ur5.score, q)
    with pytest.warns(DeprecationWarning, match=r"robot\.score"):
        assert client.score(ur5, q) == scores
    assert scores["JD"] > 0

    table = no_warnings(ur5.compare, {"a": [q], "b": [q[::-1], q]})
    with pytest.warns(DeprecationWarning, match=r"robot\.compare"):
        assert client.compare({"a": [q], "b": [q[::-1], q]}, robot="ur5").to_dict() == table.to_dict()

    frames = no_warnings(lambda: list(ur5.plan_stream(START, GOAL, scene=scene, seed=2)))
    with pytest.warns(DeprecationWarning, match=r"robot\.plan_stream"):
        old_frames = list(client.plan_stream(ur5, start=START, goal=GOAL, scene=scene, seed=2))
    assert isinstance(frames[-1], kinplan.Plan) and len(frames) == len(old_frames)
    np.testing.assert_array_equal(frames[-1].q, old_frames[-1].q)


def test_the_robot_handle_keeps_the_joint_limit_guard_and_the_errors(client):
    kr210 = client.robot("kuka_kr210_r2700_extra")
    with pytest.warns(kinplan.JointLimitWarning):
        kr210.score(np.linspace(np.zeros(6), [10, -90, 90, 0, 45, 0], 10))
    with pytest.raises(kinplan.InvalidArgument, match="radians"):
        client.robot("kuka_kr210_r2700_extra", strict=True).score(np.linspace(np.zeros(6), [10, -90, 90, 0, 45, 0], 10))
    with pytest.raises(ValueError, match="exactly one of goal"):
        kr210.plan(np.zeros(6))
    with pytest.raises(kinplan.InvalidArgument):
        client.robot("ur5").check(np.zeros((2, 5)))


def test_ik_options_are_the_proto_fields_and_the_keywords_are_shortcuts(client):
    proto_fields = [f.name for f in kinematics_pb2.IkOptions.DESCRIPTOR.fields]
    assert [f.name for f in dataclasses.fields(kinplan.IkOptions)] == proto_fields
    o = kinplan.IkOptions(max_restarts=3, num_solutions=2, rng_seed=7, position_tolerance=1e-7,
                          return_history=True, joint_limits="ignore")
    assert o.to_proto() == ik_options("lm", "svd", max_restarts=3, num_solutions=2, rng_seed=7,
                                      position_tolerance=1e-7, history=True, joint_limits="ignore")
    with pytest.raises(ValueError, match="method"):
        kinplan.IkOptions(method="lmm")
    ur5 = client.robot("ur5")
    T = ur5.fk([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])
    by_options = ur5.ik(T, options=o)
    by_keywords = ur5.ik(T, max_restarts=3, num_solutions=2, rng_seed=7, position_tolerance=1e-7, history=True,
                         joint_limits="ignore")
    assert by_options.success and len(by_options.solutions) == len(by_keywords.solutions) == 2
    for a, b in zip(by_options.solutions, by_keywords.solutions):
        assert np.array_equal(a.q, b.q) and np.array_equal(a.history, b.history)
    # a shortcut beside options replaces its field; one at its default leaves it
    one = ur5.ik(T, options=o, num_solutions=1, history=False)
    assert len(one.solutions) == 1 and one.solutions[0].history is not None
    assert ur5.ik(T[:3, 3], options=o).success  # a bare position still means position_only
    batch = ur5.ik_batch([T, T], options=o, num_solutions=1)
    assert batch.succeeded == 2 and all(len(r.solutions) == 1 for r in batch)
    track = ur5.track(seed=by_options.q, line={"end": T, "steps": 3}, options=dataclasses.replace(o, max_restarts=0))
    assert track.all_converged
    with ur5.stream_ik(seed=by_options.q, options=o) as stream:
        assert stream.solve(T).success
    with pytest.raises(TypeError, match="IkOptions"):
        ur5.ik(T, options={"max_restarts": 3})
    with pytest.raises(TypeError, match="unknown IK options"):
        ur5.ik_batch([T], max_restart=3)


def test_the_asyncio_robot_has_the_same_calls(server_address):
    sync = kinplan.Client(server_address, timeout=30)
    ur5_sync = sync.robot("ur5")
    scene = [ball(ur5_sync)]
    q = np.linspace(START, GOAL, 20)
    o = kinplan.IkOptions(num_solutions=2, rng_seed=1)
    T = ur5_sync.fk(START)

    async def main():
        async with kinplan.aio.Client(server_address, timeout=30) as c:
            ur5 = c.robot("ur5")
            plan = await ur5.plan(START, GOAL, scene=scene, seed=3)
            checks = await ur5.check([START, GOAL], scene)
            scores = await ur5.score(q)
            table = await ur5.compare({"a": [q]})
            frames = [f async for f in ur5.plan_stream(START, GOAL, scene=scene, seed=2)]
            answer = await ur5.ik(T, options=o)
            with pytest.warns(DeprecationWarning):
                await c.score("ur5", q)
            return plan, checks, scores, table, frames, answer

    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        plan, checks, scores, table, frames, answer = asyncio.run(main())
    assert np.array_equal(plan.q, ur5_sync.plan(START, GOAL, scene=scene, seed=3).q)
    assert list(checks.valid) == list(ur5_sync.check([START, GOAL], scene).valid)
    assert scores == ur5_sync.score(q) and table.to_dict() == ur5_sync.compare({"a": [q]}).to_dict()
    assert np.array_equal(frames[-1].q, list(ur5_sync.plan_stream(START, GOAL, scene=scene, seed=2))[-1].q)
    expect = ur5_sync.ik(T, options=o)
    assert [s.q.tolist() for s in answer.solutions] == [s.q.tolist() for s in expect.solutions]
    sync.close()


@pytest.mark.parametrize("old, new, names", [
    ("kinplan.exploration", "kinplan.octree", ["Octree", "Views", "GAINS"]),
    ("kinplan.explore", "kinplan.exploration_loop", ["ExploreStep", "ExploreSummary", "ReferenceScene", "SCENES"]),
    ("kinplan.local", "kinplan.local_server", ["LocalServer", "find_binary"]),
    ("kinplan._aio_mobile", "kinplan.aio", ["AsyncMobile"]),
    ("kinplan.kinematics", "kinplan.robot", ["IkStream"]),
    ("kinplan.client", "kinplan.robot", ["Robot"]),
    ("kinplan.client", "kinplan.description", ["RobotDescription", "JointLimits"]),
    ("kinplan.mobile", "kinplan.client", ["Mobile"]),
    ("kinplan.kinematics", "kinplan.client", ["KinematicsMixin"]),  # the mixins: the classes holding their methods
    ("kinplan.planning", "kinplan.client", ["PlanningMixin"]),
    ("kinplan.scoring", "kinplan.client", ["ScoringMixin"]),
    ("kinplan.exploration", "kinplan.client", ["ExplorationMixin"]),
    ("kinplan.explore", "kinplan.client", ["ExploreMixin"]),
    ("kinplan.mobile", "kinplan.client", ["MobileMixin"]),
])
def test_old_module_paths_still_import_the_same_objects(old, new, names):
    for name in names:
        if name.endswith("Mixin"):
            assert getattr(importlib.import_module(old), name) is kinplan.Client or name == "RobotKinematicsMixin"
            continue
        assert getattr(importlib.import_module(old), name) is getattr(importlib.import_module(new), name)


def test_ik_options_and_the_robot_calls_type_check(tmp_path):
    pytest.importorskip("mypy.api")
    from test_typing import check

    out = check(tmp_path, """
        import numpy as np
        import kinplan

        def use(c: kinplan.Client) -> float:
            robot = c.robot("ur5")
            o = kinplan.IkOptions(method="newton", max_restarts=5, return_history=True)
            answer = robot.ik(np.eye(4), options=o, max_restarts=0)
            plan = robot.plan(np.zeros(6), np.ones(6), scene=[kinplan.Sphere(0.1, [0.5, 0.0, 0.3])])
            checks = robot.check(plan.q)
            return robot.score(plan.q)["JD"] + float(checks.clearance.min()) + answer.position_error

        def wrong() -> None:
            kinplan.IkOptions(method="lmm")
            kinplan.IkOptions(max_restart=3)
    """)
    assert "Literal['lmm']" in out, out
    assert 'Unexpected keyword argument "max_restart"' in out, out
    assert out.count("error:") == 2, out
