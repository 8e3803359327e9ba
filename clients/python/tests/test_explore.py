"""c.explore against a real server: the IRB 4600 explores a box behind a
shelf; the stream is checked against independent facts (the known ratio
never falls, each trajectory starts where the previous ended, the totals
are the sums of the steps' criteria, the final tree parses)."""
import numpy as np
import pytest

import kinplan

START = [0.0, -0.2, 0.3, 0.0, 0.75, 0.0]


def scene():
    return [
        kinplan.Box(size=(8, 8, 0.1), pose=[1.0, 0.0, -0.4], id="floor"),
        kinplan.Box(size=(0.2, 8, 2.8), pose=[3.6, 0.0, 1.0], id="back wall"),
        kinplan.Box(size=(0.5, 0.5, 0.6), pose=[2.3, 0.3, -0.05], id="crate"),
        kinplan.Box(size=(0.3, 0.8, 1.1), pose=[2.0, -0.6, 0.2], id="shelf"),
    ]


def explore(client, **kw):
    irb = "abb_irb4600_60_205"  # a name works as well as client.robot(name)
    args = dict(
        start=START, scene=scene(), region=([1.4, -1.2, -0.29], [3.2, 1.2, 1.0]),
        resolution=0.2, pixel_stride=8, known_ratio=1.0, max_iterations=3, seed=5,
    )
    args.update(kw)
    return list(client.explore(irb, **args))


def test_an_exploration_yields_steps_then_a_summary(client):
    out = explore(client)
    *steps, summary = out
    assert isinstance(summary, kinplan.ExploreSummary)
    assert all(isinstance(s, kinplan.ExploreStep) for s in steps)
    assert summary.iterations == len(steps) >= 1
    ratios = [summary.initial_known_ratio] + [s.known_ratio for s in steps]
    assert np.all(np.diff(ratios) >= 0)
    q = np.array(START)
    cd = 0.0
    for s in steps:
        if len(s.trajectory):
            np.testing.assert_allclose(s.trajectory[0], q, atol=1e-9)
            q = s.trajectory[-1]
            cd += s.criteria["CD"]
            assert np.all(np.diff(s.times_from_start) > 0)
        np.testing.assert_allclose(s.joints, q, atol=1e-12)
    assert summary.totals["CD"] == pytest.approx(cd)
    info = client.octree_info(summary.octree)
    assert info["resolution"] == pytest.approx(0.2) and info["occupied_leaves"] > 0
    assert "known" in repr(summary) and len(repr(steps[0])) < 200
    # wasted moves are the views reached whose scan added nothing ("no_gain"):
    # with the visibility check (on by default) there are none
    no_gain = sum(1 for s in steps for _, why in s.failures if why == "no_gain")
    assert summary.wasted_moves == no_gain == 0
    assert summary.best_predicted_cells is not None


def test_bad_exploration_input_raises_naming_the_field(client):
    with pytest.raises(kinplan.KinplanError, match="known_ratio"):
        explore(client, known_ratio=1.5)
    with pytest.raises(kinplan.KinplanError, match="start"):
        explore(client, start=[0.0] * 5)
    with pytest.raises(ValueError, match="planner"):
        explore(client, planner="rrt")


def test_a_reference_cell_comes_with_its_region_and_a_collision_free_start(client):
    ref = kinplan.scenes.s0_walled_cell(client)
    assert ref.robot == "abb_irb4600_60_205" and len(ref.start) == 6
    lo, hi = ref.region
    assert np.all(lo < hi)
    names = [o.id for o in ref.obstacles]
    assert {"front wall", "far wall", "floor"} <= set(names)
    irb = client.robot(ref.robot)
    checks = client.check_states(irb, ref.start, ref.obstacles)
    assert bool(checks.valid[0])
    # the same seed gives the same cell, another seed moves the clutter
    again = client.reference_scene("s0_walled_cell", seed=1)
    assert [o.SerializeToString() for o in again.obstacles] == [o.SerializeToString() for o in ref.obstacles]
    other = client.reference_scene("s0_walled_cell", seed=2)
    assert [o.SerializeToString() for o in other.obstacles] != [o.SerializeToString() for o in ref.obstacles]
    # and it can be explored as it is (robot, start and region from the scene)
    *steps, summary = client.explore(scene=ref, resolution=0.2, pixel_stride=8, max_iterations=1)
    assert summary.initial_known_ratio < 0.5
    assert kinplan.scenes.s0_open_cell(client).name == "s0_open_cell"
    assert summary.iterations == len(steps) <= 1
