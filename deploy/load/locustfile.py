"""Locust load test of a kinplan server through the Python client: a mix of
what notebook and controller users call (FK, warm IK, scoring, navigation,
planning). Headless, from a fresh venv with `pip install locust ./clients/python`:

    locust -f deploy/load/locustfile.py --headless -u 16 -r 16 -t 60s \\
        --host 127.0.0.1:50051 --csv target/locust

Locust's master/worker mode (`--master`, `--worker`) spreads the users over
many machines. Each call is reported as request type "grpc" named by its
RPC; errors carry the gRPC status (e.g. RESOURCE_EXHAUSTED when the server
sheds load).
"""
import time

import numpy as np
from locust import User, between, events, task

import kinplan

Q_UR5 = np.array([0.3, -1.2, 1.4, -0.6, 1.2, 0.1])


class KinplanUser(User):
    """One client connection per simulated user, like a notebook or a
    controller process."""

    wait_time = between(0.0, 0.002)

    def on_start(self):
        self.client = kinplan.Client(self.host or "127.0.0.1:50051", timeout=10)
        self.ur5 = self.client.robot("ur5")
        self.rng = np.random.default_rng()
        # reachable targets: FK of random joint states
        qs = self.rng.uniform(-2.5, 2.5, size=(64, 6))
        self.targets = [self.ur5.fk(q) for q in qs]
        self.seeds = qs + self.rng.normal(0, 0.05, size=qs.shape)
        self.trajectory = np.linspace(Q_UR5, -Q_UR5, 40)

    def on_stop(self):
        self.client.close()

    def _timed(self, name, call):
        t0 = time.perf_counter()
        exception = None
        try:
            call()
        except kinplan.KinplanError as err:
            exception = err
        events.request.fire(
            request_type="grpc",
            name=name,
            response_time=(time.perf_counter() - t0) * 1000.0,
            response_length=0,
            exception=exception,
            context={},
        )

    @task(40)
    def forward_kinematics(self):
        q = self.rng.uniform(-2.5, 2.5, 6)
        self._timed("ForwardKinematics", lambda: self.ur5.fk(q))

    @task(30)
    def warm_ik(self):
        k = int(self.rng.integers(len(self.targets)))
        self._timed("SolveIk (warm)", lambda: self.ur5.ik(self.targets[k], seed=self.seeds[k]))

    @task(15)
    def score(self):
        self._timed("ScoreTrajectory", lambda: self.client.score(self.ur5, self.trajectory))

    @task(10)
    def navigate(self):
        world = [{"circle": (2.0, 0.1, 0.4)}]
        self._timed(
            "Navigate",
            lambda: self.client.mobile.navigate(start=(0, 0, 0), goal=(4, 0), world=world, robot_radius=0.22),
        )

    @task(5)
    def plan(self):
        self._timed(
            "Plan (RRT-Connect)",
            lambda: self.client.plan(self.ur5, start=Q_UR5, goal=-Q_UR5, algorithm="rrt_connect"),
        )
