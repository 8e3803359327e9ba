"""Octree.leaves / Octree.boxes (the client's own decoding of .bt node
bytes, which kinplan.viz draws) against the server's octree_info."""
import numpy as np
import pytest

import kinplan


@pytest.fixture(scope="module")
def tree(server_address):
    rng = np.random.default_rng(7)
    wall = np.column_stack([np.full(2000, 2.0), rng.uniform(-1, 1, (2000, 2))])
    with kinplan.Client(server_address, timeout=30) as c:
        t = c.insert_scan(None, wall, origin=[0, 0, 0], resolution=0.1)
        return t, c.octree_info(t)


def test_the_leaves_are_the_trees_leaves(tree):
    t, info = tree
    mins, edges, occupied = t.leaves()
    assert len(mins) == info["leaves"] and int(occupied.sum()) == info["occupied_leaves"]
    assert edges.min() > 0 and edges.max() > 0.1 + 1e-9  # pruned free leaves are bigger cubes
    centres = mins[occupied] + edges[occupied, None] / 2
    np.testing.assert_allclose(np.sort(centres, axis=0), np.sort(t.occupied_cells(), axis=0))
    assert (edges[occupied, None] ** 3).sum() == pytest.approx(info["occupied_volume"])
    assert (edges[~occupied, None] ** 3).sum() == pytest.approx(info["free_volume"])


def test_boxes_partition_a_region_by_state(tree):
    t, info = tree
    region = (np.array([0.05, -1.23, -0.77]), np.array([2.61, 1.4, 0.9]))  # not cell-aligned
    boxes = t.boxes(region)
    volume = 0.0
    for state, (a, b) in boxes.items():
        assert np.all(a >= region[0] - 1e-12) and np.all(b <= region[1] + 1e-12) and np.all(b > a)
        volume += np.prod(b - a, axis=1).sum()
    assert volume == pytest.approx(np.prod(region[1] - region[0]))
    whole = t.boxes()
    lo, hi = info["bounds"]
    assert len(whole["occupied"][0]) == info["occupied_leaves"] and len(whole["free"][0]) == info["free_leaves"]
    assert sum(np.prod(b - a, axis=1).sum() for a, b in whole.values()) == pytest.approx(np.prod(hi - lo))
    with pytest.raises(ValueError, match="max_cells"):
        t.boxes(([-100, -100, -100], [100, 100, 100]))
