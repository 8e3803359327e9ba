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


OCTOMAP_OT = __import__("pathlib").Path(__file__).resolve().parents[3] / "crates/kinplan-core/src/octree/fixtures/scans_octomap.ot"


def test_the_bt_size_line_counts_the_nodes_octomap_builds():
    # A root with 8 known leaves (0x66: children 10 01 10 01 in each byte): 9 nodes.
    tree = kinplan.Octree(data=b"\x66\x66", resolution=0.1)
    assert b"\nsize 9\n" in tree.to_bt()
    # A root whose child 0 is inner (bits 11) with two occupied leaves: 1 + 1 + 2 nodes.
    tree = kinplan.Octree(data=b"\x03\x00\x0a\x00", resolution=0.1)
    assert b"\nsize 4\n" in tree.to_bt()


def test_the_bt_size_line_agrees_with_the_server_count(client):
    tree = client.insert_scan(None, wall(), origin=[0, 0, 0], resolution=0.1)
    size = int(tree.to_bt().split(b"\nsize ")[1].split(b"\n")[0])
    assert size == client.octree_info(tree)["nodes"]


def test_every_octree_argument_form_is_taken(client, tmp_path):
    import io

    tree = client.insert_scan(None, wall(), origin=[0, 0, 0], resolution=0.1)
    bt = tree.to_bt()
    path = tmp_path / "wall.bt"
    path.write_bytes(bt)
    expected = client.octree_info(tree)["nodes"]
    forms = (lambda: tree, lambda: bt, lambda: bytearray(bt), lambda: memoryview(bt), lambda: io.BytesIO(bt),
             lambda: path, lambda: str(path))
    for form in forms:
        assert client.octree_info(form())["nodes"] == expected
        grown = client.insert_scan(form(), wall() + [0.5, 0, 0], origin=[0, 0, 0])
        assert client.octree_info(grown)["occupied_leaves"] == 72
        assert len(client.next_best_view(form(), camera_pose=np.eye(4), max_results=2)) > 0
    # An OctoMap-written .ot file (full nodes): its own header says how many nodes it holds.
    ot = OCTOMAP_OT.read_bytes()
    header_size = int(ot.split(b"\nsize ")[1].split(b"\n")[0])
    assert client.octree_info(OCTOMAP_OT)["nodes"] == header_size
    assert not kinplan.Octree.read(io.BytesIO(ot)).binary
    with pytest.raises(TypeError, match="binary mode"):
        client.octree_info(io.StringIO("# Octomap OcTree binary file\n"))
    with pytest.raises(ValueError, match="not an OctoMap file"):
        client.octree_info(b"hello")
    with pytest.raises(TypeError, match="octree must be"):
        client.insert_scan(42, wall())


def test_nbv_takes_a_region_and_names_an_unknown_option(client):
    tree = client.insert_scan(None, wall(), origin=np.eye(4), resolution=0.1)
    everywhere = client.next_best_view(tree, camera_pose=np.eye(4), max_results=50)
    # Frontier cells only in the half-space y > 0: every candidate's frontier lies there.
    region = ([-5.0, 0.0, -5.0], [5.0, 5.0, 5.0])
    half = client.next_best_view(tree, camera_pose=np.eye(4), max_results=50, region=region)
    assert 0 < half.stages["frontier_cells"] < everywhere.stages["frontier_cells"]
    frontiers = half.frontier[~np.isnan(half.frontier[:, 0])]
    assert len(frontiers) and np.all(frontiers[:, 1] >= -1e-9)
    with pytest.raises(TypeError, match="NbvOptions has no field 'pose'"):
        client.next_best_view(tree, camera_pose=np.eye(4), pose=np.eye(4))
    with pytest.raises(ValueError, match="region must be"):
        client.next_best_view(tree, camera_pose=np.eye(4), region=[1, 2])


def test_a_depth_image_inserts_like_its_hand_back_projected_points(client):
    # a 6 x 4 image of a plane 2 m ahead, fx = fy = 4 px, cx = 2.5, cy = 1.5:
    # pixel (u, v) is the point ((u - 2.5) / 2, (v - 1.5) / 2, 2) in the optical frame
    pose = np.eye(4)
    pose[:3, 3] = [0.02, 0.03, 0.01]
    u, v = np.meshgrid(np.arange(6), np.arange(4))
    pts = np.column_stack([(u.ravel() - 2.5) / 2, (v.ravel() - 1.5) / 2, np.full(24, 2.0)]) + pose[:3, 3]
    by_points = client.insert_scan(None, pts, origin=pose, resolution=0.1)
    k = (4.0, 4.0, 2.5, 1.5)
    metres = client.insert_scan(None, origin=pose, depth=np.full((4, 6), 2.0), intrinsics=k, resolution=0.1)
    mm = client.insert_scan(None, origin=pose, depth=np.full((4, 6), 2000, dtype=np.uint16), intrinsics=k,
                            resolution=0.1)
    assert metres.data == by_points.data and mm.data == by_points.data
    # a pixel without a return (0 mm) adds no end point
    holes = np.full((4, 6), 2000, dtype=np.uint16)
    holes[0, 0] = 0
    fewer = client.insert_scan(None, origin=pose, depth=holes, intrinsics=k, resolution=0.1)
    assert client.octree_info(fewer)["occupied_leaves"] == client.octree_info(mm)["occupied_leaves"] - 1
    with pytest.raises(ValueError):
        client.insert_scan(None, origin=pose, depth=np.full((4, 6), 2000, dtype=np.int32), intrinsics=k)
    with pytest.raises(kinplan.KinplanError) as e:
        client.insert_scan(None, origin=pose, depth=np.full((4, 6), 2.0), camera={"width": 5, "height": 4})
    assert "depth_image.camera.width" in str(e.value)


def test_a_shared_near_field_keeps_the_end_points_and_refuses_bad_spacings(client):
    # 48 x 36 pixels of a plane tilted from 2 m to 4 m, f = 30 px
    pose = np.eye(4)
    depth = np.tile(2.0 + 2.0 * np.arange(48) / 48, (36, 1))
    k = (30.0, 30.0, 23.5, 17.5)
    exact = client.insert_scan(None, origin=pose, depth=depth, intrinsics=k, resolution=0.1)
    fast = client.insert_scan(None, origin=pose, depth=depth, intrinsics=k, resolution=0.1, near_ray_spacing=0.7)
    ie, fa = client.octree_info(exact), client.octree_info(fast)
    # every end point is occupied in both; the near field leaves out at most a few free cells
    np.testing.assert_array_equal(np.sort(exact.occupied_cells(), axis=0), np.sort(fast.occupied_cells(), axis=0))
    assert ie["occupied_leaves"] == fa["occupied_leaves"]
    assert fa["free_volume"] <= ie["free_volume"] + 1e-9
    assert fa["free_volume"] >= 0.99 * ie["free_volume"]
    for bad in (1.5, -0.5):
        with pytest.raises(kinplan.KinplanError) as e:
            client.insert_scan(None, origin=pose, depth=depth, intrinsics=k, near_ray_spacing=bad)
        assert "near_ray_spacing" in str(e.value)
