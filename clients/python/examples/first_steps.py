"""First steps with kinplan: list robots, forward kinematics, a Jacobian.

Start a server first (`cargo run --release -- serve`), then:
    python clients/python/examples/first_steps.py [address]
"""
import sys

import numpy as np

import kinplan

address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
with kinplan.Client(address, timeout=5) as c:
    for r in c.list_robots():
        print(f"{r['name']:<26} {r['dof']} joints")
    robot = c.robot("kuka_kr210_r2700_extra")
    home = np.radians([0, -90, 90, 0, 0, 0])
    T = robot.fk(home)
    np.set_printoptions(precision=4, suppress=True)
    print("KR 210 home pose (tool0 in base frame, metres):\n", T)
    J = robot.jacobian(home)
    print("Jacobian singular values:", np.linalg.svd(J, compute_uv=False))
