"""A robot's own URDF file and mesh files: read on the client (pinocchio's
package_dirs rules), sent with the model, colliding as the meshes do."""

import struct

import numpy as np
import pytest

import kinplan
from kinplan._model_files import collision_mesh_uris, load_model

# a one-joint arm: base -> arm (revolute about z); the arm's collision is a
# 0.1 m cube mesh centred 0.25 m up (a unit-cube STL scaled by the URDF), and
# a gripper fixed 0.5 m up carries an OBJ cube of 0.1 m (its file next to the URDF)
URDF = """<robot name="meshy">
  <link name="base"/>
  <link name="arm"><collision><origin xyz="0 0 0.25"/>
    <geometry><mesh filename="package://arm_pkg/meshes/link.stl" scale="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="gripper"><collision><geometry><mesh filename="../meshes/gripper.obj"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="arm"/><child link="gripper"/><origin xyz="0 0 0.5"/></joint>
</robot>"""

CORNERS = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
QUADS = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def binary_stl(scale=1.0):
    triangles = [t for q in QUADS for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]
    out = b"\0" * 80 + struct.pack("<I", len(triangles))
    for t in triangles:
        out += struct.pack("<3f", 0, 0, 0)
        for i in t:
            out += struct.pack("<3f", *(c * scale for c in CORNERS[i]))
        out += b"\0\0"
    return out


def obj(scale):
    lines = [f"v {x * scale} {y * scale} {z * scale}" for x, y, z in CORNERS]
    lines += ["f " + " ".join(str(i + 1) for i in q) for q in QUADS]
    return ("\n".join(lines) + "\n").encode()


@pytest.fixture
def package(tmp_path):
    """tmp/arm_pkg/{urdf/arm.urdf, meshes/link.stl, meshes/gripper.obj}"""
    root = tmp_path / "arm_pkg"
    (root / "urdf").mkdir(parents=True)
    (root / "meshes").mkdir()
    (root / "urdf" / "arm.urdf").write_text(URDF)
    (root / "meshes" / "link.stl").write_bytes(binary_stl())
    (root / "meshes" / "gripper.obj").write_bytes(obj(0.1))
    return tmp_path


def ball(x, z, r=0.02):
    return [kinplan.Sphere(r, [x, 0.0, z])]


def test_the_urdf_file_and_its_meshes_are_sent_and_collide_as_the_meshes(client, package):
    robot = client.robot(urdf=package / "arm_pkg" / "urdf" / "arm.urdf", package_dirs=[package])
    assert sorted(robot.mesh_files) == ["../meshes/gripper.obj", "package://arm_pkg/meshes/link.stl"]
    q = [[0.0]]
    # the arm cube's face at x = 0.05 (z 0.2-0.3), the gripper cube's at x = 0.05 (z 0.45-0.55)
    for z in (0.25, 0.5):
        assert not robot.check(q, ball(0.06, z)).valid[0], z
        clear = robot.check(q, ball(0.08, z))
        assert clear.valid[0] and abs(clear.clearance[0] - 0.01) < 1e-6, (z, clear.clearance)
    # the tool is the tree's end link, the gripper 0.5 m up the turning joint
    np.testing.assert_allclose(robot.fk([np.pi / 2])[:3, 3], [0, 0, 0.5], atol=1e-12)


def test_mesh_bytes_can_be_given_by_uri(client):
    files = {"package://arm_pkg/meshes/link.stl": binary_stl(), "../meshes/gripper.obj": obj(0.1)}
    robot = client.robot(urdf=URDF, meshes=files)
    assert not robot.check([[0.0]], ball(0.06, 0.5)).valid[0]
    # without them, FK still works and a collision call names the missing file
    bare = client.robot(urdf=URDF)
    assert bare.mesh_files == {}
    bare.fk([0.0])
    with pytest.raises(kinplan.InvalidArgument, match="link.stl"):
        bare.check([[0.0]], ball(0.5, 0.5))


def test_a_mesh_that_cannot_be_found_names_its_uri_and_every_place_looked(package, tmp_path):
    (package / "arm_pkg" / "meshes" / "link.stl").unlink()
    with pytest.raises(FileNotFoundError) as err:
        load_model(package / "arm_pkg" / "urdf" / "arm.urdf", package_dirs=[package])
    text = str(err.value)
    assert "package://arm_pkg/meshes/link.stl" in text
    assert str(package / "arm_pkg" / "meshes" / "link.stl") in text
    with pytest.raises(kinplan.InvalidArgument, match="no such file"):
        load_model(tmp_path / "nowhere.urdf")


def test_only_collision_meshes_are_named():
    urdf = URDF.replace("<link name=\"base\"/>",
                        "<link name=\"base\"><visual><geometry><mesh filename=\"seen.dae\"/></geometry></visual></link>")
    assert collision_mesh_uris(urdf) == ["package://arm_pkg/meshes/link.stl", "../meshes/gripper.obj"]


FOLDING = """<robot name="folding">
  <link name="base"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="l1"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry></collision></link>
  <link name="l2"><collision><origin xyz="0 0 0.3"/><geometry><box size="0.05 0.05 0.6"/></geometry></collision></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="t" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0 0 0.6"/></joint>
</robot>"""

SRDF = """<robot name="folding">
  <group name="arm"><chain base_link="base" tip_link="tool"/></group>
  <group name="upper"><chain base_link="base" tip_link="l1"/></group>
  <group_state name="folded" group="arm"><joint name="j1" value="0"/><joint name="j2" value="3"/></group_state>
  <disable_collisions link1="base" link2="l2" reason="Never"/>
</robot>"""


def test_an_srdf_disables_pairs_names_groups_and_states(client, tmp_path):
    (tmp_path / "folding.srdf").write_text(SRDF)
    plain = client.robot(urdf=FOLDING)
    robot = client.robot(urdf=FOLDING, srdf=tmp_path / "folding.srdf")
    folded = robot.describe().named_state("folded")
    np.testing.assert_array_equal(folded, [0.0, 3.0])
    # folded back, the second link reaches into the base: a pair the SRDF disables
    assert not plain.check([folded]).valid[0]
    assert robot.check([folded]).valid[0]
    upper = client.robot(urdf=FOLDING, srdf=SRDF, group="upper")
    assert upper.describe().tip_link == "l1" and upper.describe().dof == 1
    # a state for a longer chain gives this chain's joints; an unknown name lists the known ones
    np.testing.assert_array_equal(upper.describe().named_state("folded"), [0.0])
    with pytest.raises(KeyError, match="folded"):
        upper.describe().named_state("ready")


def test_held_joints_put_the_fingers_where_asked(client):
    q = [0.0, 0.3, 0.0, -2.0, 0.0, 2.3, 0.785]
    tool = client.robot("franka_panda_hand").fk(q)[:3, 3]
    ball = [kinplan.Sphere(0.005, tool)]
    closed = client.robot("franka_panda_hand")
    opened = client.robot("franka_panda_hand", held_joints={"panda_finger_joint1": 0.04, "panda_finger_joint2": 0.04})
    assert not closed.check([q], ball).valid[0]
    assert opened.check([q], ball).valid[0]
