"""c.insert_scan / c.octree_info / c.next_best_view against a real server:
a hand-placed wall whose cells are counted by hand, the .bt round trip, and
candidates checked against the utility formula."""
import numpy as np
import pytest

import kinplan


def wall():
    """Points at the centres of a 6 x 6 wall of 0.1 m cells at x in [2.0, 2.1)."""
    ys, zs = np.meshgrid((np.arange(-3, 3) + 0.5) * 0.1, (np.arange(-3, 3) + 0.5) * 0.1)
    return np.column_stack([np.full(36, 2.05), ys.ravel(), zs.ravel()])


def test_a_scanned_wall_counts_its_cells_and_round_trips_as_bt(client):
    tree = client.insert_scan(None, wall(), origin=[0, 0, 0], resolution=0.1)
    info = client.octree_info(tree)
    assert info["occupied_leaves"] == 36
    assert info["occupied_volume"] == pytest.approx(36 * 0.1**3)
    lo, hi = info["bounds"]
    assert hi[0] == pytest.approx(2.1) and lo[0] <= 0.0
    # Through a .bt file's bytes and back: the same tree.
    again = kinplan.Octree.from_bt(tree.to_bt())
    assert again.data == tree.data and again.resolution == 0.1
    assert client.octree_info(again)["free_leaves"] == info["free_leaves"]
    # the decoded occupied cells are the wall's 36 cell centres
    cells = tree.occupied_cells()
    np.testing.assert_allclose(cells[np.lexsort(cells.T[::-1])], wall()[np.lexsort(wall().T[::-1])], atol=1e-9)


def test_views_follow_the_utility_formula(client):
    tree = client.insert_scan(None, wall(), origin=np.eye(4), resolution=0.1)
    views = client.next_best_view(tree, camera_pose=np.eye(4), weights=(1.0, 0.5, 0.25), max_results=5)
    assert 0 < len(views) <= 5 and views.status == "COMPLETE"
    np.testing.assert_allclose(views.utility, views.gain + 0.5 * views.distance + 0.25 * views.rotation, atol=1e-9)
    assert np.all(np.diff(views.utility) <= 0)
    np.testing.assert_allclose(views.poses[:, :3, :3] @ views.poses[:, :3, :3].transpose(0, 2, 1), np.tile(np.eye(3), (len(views), 1, 1)), atol=1e-9)
    assert views.stages["frontier_cells"] > 0
    assert all(r is None for r in views.reachable)


def test_a_robot_named_by_its_built_in_name_checks_reach_as_the_robot_object(client):
    tree = client.insert_scan(None, wall(), origin=np.eye(4), resolution=0.1)
    by_name = client.next_best_view(tree, camera_pose=np.eye(4), robot="abb_irb4600_60_205", max_results=3)
    by_robot = client.next_best_view(tree, camera_pose=np.eye(4), robot=client.robot("abb_irb4600_60_205"),
                                     max_results=3)
    assert list(by_name.reachable) == list(by_robot.reachable)
    assert all(r is not None for r in by_name.reachable)
    np.testing.assert_array_equal(by_name.poses, by_robot.poses)


def test_bad_scans_are_refused(client):
    with pytest.raises(ValueError):
        client.insert_scan(None, np.zeros((4, 2)))
    with pytest.raises(kinplan.KinplanError) as e:
        client.insert_scan(None, wall(), resolution=-1.0)
    assert "resolution" in str(e.value)
