"""MobileService against a real server, checked against hand-derived values:
OMR-III (r 0.1 m, R 0.3 m, wheel 0 at 90 deg, rim <= 0.5 m/s), MOBIL-II
(L 0.6 m, t 0.62 m, r 0.1 m), the Jackal-like differential base (r 0.098 m,
b 0.37559 m) and the Lyapunov run of S1 (S = (-1, 1, 3pi/4) -> G = (0, 0, 0))."""
import math

import grpc
import numpy as np
import pytest

import kinplan
from kinplan.mobile import MobileRun, StepResult


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def test_omni_pure_rotation_wheel_speeds_are_R_omega_over_r(client):
    w = client.mobile.wheels("omni", (0.0, 0.0, 1.0))
    assert w.wheels["speeds"] == pytest.approx([3.0, 3.0, 3.0], abs=1e-12)  # R*w/r = 0.3/0.1
    assert w.saturation == {"speed_scale": 1.0, "steering_clamped": False, "lateral_dropped": False}
    # Forward 0.2 m/s: u_i = -sin(phi_i) * vx / r with phi = 90, 210, 330 deg.
    w = client.mobile.wheels("omni", (0.2, 0.0, 0.0))
    assert w.wheels["speeds"] == pytest.approx([-2.0, 1.0, 1.0], abs=1e-12)
    # 2 rad/s needs a 0.6 m/s rim: scaled by 0.5/0.6.
    w = client.mobile.wheels("omni", (0.0, 0.0, 2.0))
    assert w.saturation["speed_scale"] == pytest.approx(0.5 / 0.6)
    assert w.twist == pytest.approx([0.0, 0.0, 2.0 * 0.5 / 0.6])
    # A smaller wheel turns faster: r = 0.05 m -> 6 rad/s.
    w = client.mobile.wheels("omni", (0.0, 0.0, 1.0), chassis_params={"wheel_radius": 0.05})
    assert w.wheels["speeds"] == pytest.approx([6.0, 6.0, 6.0], abs=1e-12)


def test_car_and_differential_by_hand_and_round_trips(client):
    w = client.mobile.wheels("car", (0.5, 0.0, 0.5)).wheels  # 1 m radius
    assert w["rear_left"] == pytest.approx(3.45, abs=1e-12)  # (v - w t/2) / r
    assert w["rear_right"] == pytest.approx(6.55, abs=1e-12)
    assert w["steer_left"] == pytest.approx(math.atan(0.3 / 0.345), abs=1e-12)
    assert w["steer_right"] == pytest.approx(math.atan(0.3 / 0.655), abs=1e-12)
    w = client.mobile.wheels("differential", (0.98, 0.0, 0.0)).wheels
    assert (w["left"], w["right"]) == pytest.approx((10.0, 10.0), abs=1e-12)
    for chassis, twist in [
        ("omni", (0.2, -0.1, 0.4)),
        ("car", (0.4, 0.0, -0.3)),
        ("tricycle", (-0.2, 0.0, 0.25)),
        ("differential", (0.7, 0.0, 1.3)),
    ]:
        inv = client.mobile.wheels(chassis, twist)
        fwd = client.mobile.wheels(chassis, wheels=inv.wheels)
        assert fwd.twist == pytest.approx(inv.twist, abs=1e-9), chassis


def test_lyapunov_run_converges_and_V_never_increases(client):
    run = client.mobile.follow(
        chassis="differential",
        start=(-1.0, 1.0, 3 * math.pi / 4),
        path=[(0.0, 0.0, 0.0)],
        controller="lyapunov",
        gains={"gamma": 0.5, "k": 0.3, "h": 0.5, "lambda": 0.55, "goal_tolerance": 0.005},
        dt=0.01,
        max_time=200.0,
    )
    assert isinstance(run, MobileRun)
    assert run.outcome == "REACHED"
    assert run.states.shape == (run.steps + 1, 3)
    assert run.commands.shape == (run.steps, 3)
    x, y, th = run.states[-1]
    assert math.hypot(x, y) < 0.01
    assert abs(wrap(th)) < math.radians(1)
    x, y, th = run.states.T
    e = np.hypot(x, y)
    theta = np.arctan2(-y, -x)
    alpha = wrap(theta - th)
    V = 0.5 * (0.55 * e**2 + alpha**2 + 0.5 * theta**2)
    assert np.all(np.diff(V) <= 1e-9)
    assert run.time == pytest.approx(run.steps * 0.01)
    assert run.path_length > math.sqrt(2)
    assert run.min_clearance is None


def test_step_token_round_trip(client):
    free = client.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=[2.0] * 8)
    assert isinstance(free, StepResult)
    assert free.command == pytest.approx([0.5, 0.0, 0.0], abs=1e-12)
    assert free.mode == "R"
    blocked = [0.1] + [2.0] * 7
    first = client.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked)
    second = client.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked, token=first)
    fresh = client.mobile.step((0, 0, 0), controller="vector_distance", goal=(5, 0), readings=blocked)
    assert second.mode == "L"
    assert fresh.token == first.token and np.array_equal(fresh.command, first.command)
    assert second.token != first.token
    # Pure pursuit: node 0 is inside the 0.3 m switching distance at the origin.
    path = [(0.1, 0.0), (2.0, 0.0)]
    a = client.mobile.step((0, 0, 0), controller="pure_pursuit", path=path)
    assert a.target_node == 1
    assert client.mobile.step((-1, 0, 0), controller="pure_pursuit", path=path, token=a).target_node == 1
    assert client.mobile.step((-1, 0, 0), controller="pure_pursuit", path=path).target_node == 0


def test_navigate_reaches_around_obstacles_and_reports_no_path(client):
    world = [{"circle": (2.0, 0.0, 0.5)}, {"polygon": [(2.7, -1.5), (3.3, -1.5), (3.3, -0.9), (2.7, -0.9)]}]
    run = client.mobile.navigate(chassis="differential", start=(0, 0, 0), goal=(4, 0), world=world, robot_radius=0.22)
    assert run.outcome == "REACHED"
    assert math.hypot(run.states[-1, 0] - 4, run.states[-1, 1]) <= 0.1
    assert run.min_clearance >= 0 and run.path_length > 4.0
    assert len(run.modes) == run.steps and set(run.modes) - {"R"}
    ring = [
        {"circle": (6 + 1.3 * math.cos(a), 1.3 * math.sin(a), 0.16)}
        for a in np.linspace(0, 2 * math.pi, 28, endpoint=False)
    ]
    run = client.mobile.navigate(start=(0, 0, 0), goal=(6, 0), world=ring, robot_radius=0.22, max_time=300)
    assert run.outcome == "NO_PATH"
    assert run.hit_points.shape[1] == 2 and len(run.hit_points) >= 1
    assert run.no_path_reason in ("RETURNED_TO_HIT", "NO_PROGRESS")
    grid = client.mobile.navigate(start=(0, 0, 0), goal=(6, 0), world=ring, navigator="grid_astar")
    assert grid.outcome == "NO_PATH" and grid.no_path_reason == "NO_GRID_PATH"


def test_collision_is_reported(client):
    run = client.mobile.follow(
        "omni", (0, 0, 0), [(4, 0)], "pure_pursuit", world=[(2.0, 0.0, 0.5)], robot_radius=0.22
    )
    assert run.outcome == "COLLISION" and run.collided_with == 0
    assert math.hypot(run.states[-1, 0] - 2, run.states[-1, 1]) < 0.72
    assert run.min_clearance < 0


@pytest.mark.parametrize(
    "call, field",
    [
        (lambda m: m.step((math.nan, 0, 0), controller="vector_distance", goal=(1, 0), readings=[2.0] * 8), "state.x"),
        (lambda m: m.wheels("omni", (0.1, 0, 0), chassis_params={"wheel_radius": 0.0}), "chassis.omni.wheel_radius"),
        (lambda m: m.follow("omni", (0, 0, 0), [(1, 0)], dt=-0.05), "sim.dt"),
        (lambda m: m.follow("omni", (0, 0, 0), []), "path"),
        (lambda m: m.step((0, 0, 0), controller="vector_distance", goal=(1, 0), readings=[2.0] * 8, token=b"x"), "state_token"),
        (lambda m: m.navigate(goal=(1, 0), world=[(5, 5, 0.1)] * 10001), "world"),
    ],
)
def test_bad_input_is_invalid_argument_naming_the_field(client, call, field):
    with pytest.raises(kinplan.KinplanError) as err:
        call(client.mobile)
    assert err.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert err.value.field_violations[0][0] == field
    assert client.mobile.wheels("omni", (0, 0, 1)).wheels["speeds"] == pytest.approx([3, 3, 3])


def test_client_side_errors(client):
    with pytest.raises(ValueError):
        client.mobile.follow(chassis="hovercraft", path=[(1, 0)])
    with pytest.raises(ValueError):
        client.mobile.follow(path=[(1, 0)], controller="teleport")
