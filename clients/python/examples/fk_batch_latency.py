"""Batch FK against one FK call per state, same server, same states:

    python fk_batch_latency.py [host:port] [n]

Prints the round trip of `robot.fk_batch` for n states (median of 20) and
of n single `robot.fk` calls, and the ratio.
"""
import sys
import time

import numpy as np

import kinplan


def main() -> None:
    address = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 10_000
    with kinplan.Client(address, timeout=30) as c:
        ur5 = c.robot("ur5")
        qs = np.random.default_rng(0).uniform(-2.5, 2.5, size=(n, 6))
        ur5.fk_batch(qs[:10])  # warm the model cache and the connection
        times = []
        for _ in range(20):
            t0 = time.perf_counter()
            T = ur5.fk_batch(qs)
            times.append(time.perf_counter() - t0)
        batch = float(np.median(times))
        t0 = time.perf_counter()
        for q in qs[: min(n, 2000)]:
            ur5.fk(q)
        single = (time.perf_counter() - t0) / min(n, 2000) * n
        assert T.shape == (n, 4, 4)
        print(f"{n} states: fk_batch median {batch * 1e3:.2f} ms ({batch / n * 1e6:.2f} us/state); "
              f"single fk calls {single * 1e3:.0f} ms ({single / n * 1e6:.1f} us/state, "
              f"extrapolated from {min(n, 2000)}); batch {single / batch:.0f}x faster")


if __name__ == "__main__":
    main()
