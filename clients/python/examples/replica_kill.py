"""A replica dies in the middle of a load run: three `kinplan serve`
processes behind one client (round robin, UNAVAILABLE retried on another
replica), `threads` callers doing FK and warm IK, and at half time one
replica is SIGKILLed. Prints calls, errors, and latency before, around
(±0.5 s) and after the kill.

    KINPLAN_BIN=target/release/kinplan python replica_kill.py [seconds] [threads]
"""
import sys
import threading
import time

import numpy as np

import kinplan


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    servers = [kinplan.LocalServer(args=["--cpu-threads", "1"]).start() for _ in range(3)]
    client = kinplan.Client([s.address for s in servers], timeout=5, wait_for_ready=True)
    ur5 = client.robot("ur5")
    rng = np.random.default_rng(0)
    qs = rng.uniform(-2.5, 2.5, size=(64, 6))
    targets = [ur5.fk(q) for q in qs]
    records = []  # (start time, latency s, error name or "")
    lock = threading.Lock()
    t_start = time.perf_counter()
    stop_at = t_start + seconds

    def caller(k: int) -> None:
        local = []
        i = k
        while time.perf_counter() < stop_at:
            t0 = time.perf_counter()
            err = ""
            try:
                if i % 2:
                    ur5.fk(qs[i % 64])
                else:
                    ur5.ik(targets[i % 64], seed=qs[i % 64] + 0.03)
            except kinplan.KinplanError as e:
                err = e.code_name
            local.append((t0 - t_start, time.perf_counter() - t0, err))
            i += 1
        with lock:
            records.extend(local)

    workers = [threading.Thread(target=caller, args=(k,)) for k in range(threads)]
    for w in workers:
        w.start()
    time.sleep(seconds / 2)
    kill_at = time.perf_counter() - t_start
    servers[0].kill()
    for w in workers:
        w.join()
    client.close()
    for s in servers[1:]:
        s.stop()

    r = np.array([(t, lat) for t, lat, _ in records])
    errors = [e for _, _, e in records if e]
    print(f"{len(records)} calls in {seconds:.0f} s with {threads} threads over 3 replicas; "
          f"replica 1 SIGKILLed at {kill_at:.2f} s")
    print(f"errors: {len(errors)} {sorted(set(errors))}")
    for label, mask in [
        ("before", r[:, 0] < kill_at - 0.5),
        ("around", np.abs(r[:, 0] - kill_at) <= 0.5),
        ("after", r[:, 0] > kill_at + 0.5),
    ]:
        lat = r[mask, 1] * 1e3
        if len(lat):
            print(f"  {label:6s}: {len(lat):6d} calls, p50 {np.percentile(lat, 50):.2f} ms, "
                  f"p99 {np.percentile(lat, 99):.2f} ms, max {lat.max():.2f} ms")


if __name__ == "__main__":
    main()
