"""Load from the Python client balanced over several replicas: one
``kinplan.Client`` given every address (gRPC round_robin over them, and the
client's retry policy: UNAVAILABLE retried up to 3 attempts in all, 10 ms
backoff doubling to 200 ms), ``ForwardKinematics`` calls from `--concurrency`
threads, bounded by `--total` calls and `--duration` seconds, optionally paced
to `--rate` calls/s. A call that fails here failed after the client's retries:
a lost request. Used by deploy/k8s/play.sh while a replica is killed.

    python deploy/k8s/balanced_load.py --targets 10.89.0.2:50051,10.89.0.3:50051 --out calls.txt

Writes one line per call to `--out` (the format of balanced_load.rs): start
(µs after the first line's epoch), latency (µs), gRPC code (0 = OK). Prints a
summary and each distinct error.
"""
from __future__ import annotations

import argparse
import threading
import time
from collections import Counter

import numpy as np

import kinplan
from kinplan.errors import KinplanError


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--targets", required=True, help="host:port[,host:port...]")
    ap.add_argument("--concurrency", type=int, default=4)
    ap.add_argument("--total", type=int, default=20_000)
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--rate", type=float, default=0.0, help="calls/s over all threads; 0: back to back")
    ap.add_argument("--timeout", type=float, default=5.0)
    ap.add_argument("--out", default="balanced_load_python.txt")
    a = ap.parse_args()

    client = kinplan.Client(a.targets.split(","), timeout=a.timeout)
    robot = client.robot("kuka_kr210_r2700_extra")
    epoch = time.time()
    start = time.perf_counter()
    stop = start + a.duration
    lock = threading.Lock()
    sent = [0]
    results: list[list[tuple[int, int, int]]] = [[] for _ in range(a.concurrency)]
    errors: Counter[str] = Counter()
    interval = a.concurrency / a.rate if a.rate > 0 else 0.0

    def worker(w: int) -> None:
        calls = results[w]
        nxt = start + interval * w / a.concurrency
        i = 0
        while True:
            if interval:
                delay = nxt - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                nxt += interval
            t0 = time.perf_counter()
            with lock:
                if t0 >= stop or sent[0] >= a.total:
                    return
                sent[0] += 1
            i += 1
            q = np.array([0.1 + (i % 100) * 1e-3, -1.5, 1.4, 0.2, 0.3, 0.4])
            try:
                robot.fk(q)
                code = 0
            except KinplanError as err:
                code = err.code.value[0]
                with lock:
                    errors[str(err)] += 1
            calls.append((int((t0 - start) * 1e6), int((time.perf_counter() - t0) * 1e6), code))

    threads = [threading.Thread(target=worker, args=(w,)) for w in range(a.concurrency)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    elapsed = time.perf_counter() - start
    client.close()
    calls = sorted(c for r in results for c in r)
    with open(a.out, "w") as f:
        f.write(f"# start_epoch {epoch:.6f}\n")
        f.writelines(f"{t} {lat} {code}\n" for t, lat, code in calls)
    failed = sum(1 for c in calls if c[2] != 0)
    for message, n in errors.items():
        print(f"  {n} x {message}")
    print(f"python client: {len(calls)} calls in {elapsed:.1f} s, {len(calls) - failed} answered, "
          f"{failed} failed after retries")


if __name__ == "__main__":
    main()
