"""Figures of one deploy/k8s/play.sh round from the client's call log
(balanced_load.py / balanced_load.rs: start µs, latency µs, gRPC code), the
round's events (epochs of kill, restart, ready, first_call) and the replicas'
answered counts (their metrics). Exits 1 when a call failed (a lost request).

    python deploy/k8s/play_report.py CLIENT CALLS EVENTS [replica=count ...]
"""
from __future__ import annotations

import sys
from collections import Counter

CODES = ["OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED", "NOT_FOUND", "ALREADY_EXISTS",
         "PERMISSION_DENIED", "RESOURCE_EXHAUSTED", "FAILED_PRECONDITION", "ABORTED", "OUT_OF_RANGE",
         "UNIMPLEMENTED", "INTERNAL", "UNAVAILABLE", "DATA_LOSS", "UNAUTHENTICATED"]


def main() -> int:
    client, calls_path, events_path, *answered = sys.argv[1:]
    with open(calls_path) as f:
        epoch = float(f.readline().split()[-1])
        calls = [tuple(int(x) for x in line.split()) for line in f if line.strip()]
    events = {}
    with open(events_path) as f:
        for line in f:
            name, t = line.split()
            if name == "restarted_by":
                continue
            events[name] = (float(t) - epoch) * 1e6  # µs into the round
    by_podman = "restarted_by podman" in open(events_path).read()
    # the kill happened between these two (podman's start-up, ~0.1 s)
    kill_sent, kill, restart = events["kill_sent"], events["kill"], events["restart"]
    ok = [c for c in calls if c[2] == 0]
    failed = Counter(CODES[c[2]] if c[2] < len(CODES) else str(c[2]) for c in calls if c[2] != 0)
    steady = sorted(c[1] for c in ok if c[0] + c[1] < kill)
    p50 = steady[len(steady) // 2] if steady else 0
    p99 = steady[int(len(steady) * 0.99)] if steady else 0
    slow = max(3 * p99, 20_000)
    in_flight = [c for c in calls if c[0] <= kill and c[0] + c[1] >= kill_sent]
    after = [c for c in calls if c[0] + c[1] >= kill_sent and c[0] < restart]
    slow_after = [c for c in after if c[1] > slow]
    recover = max((c[0] + c[1] - kill for c in slow_after), default=0.0) / 1e6
    failed_at = [round((c[0] - kill) / 1e6, 3) for c in calls if c[2] != 0]
    duration = (calls[-1][0] + calls[-1][1]) / 1e6 if calls else 0.0

    def rate(t0: float, t1: float) -> float:
        return sum(1 for c in ok if t0 <= c[0] + c[1] < t1) / ((t1 - t0) / 1e6)

    print(f"{client} client: {len(calls)} calls sent in {duration:.1f} s, {len(ok)} answered, "
          f"{sum(failed.values())} lost (failed after the client's retries){': ' + dict(failed).__repr__() if failed else ''}")
    counts = dict(a.split("=") for a in answered)
    survivors = sum(int(v) for k, v in counts.items() if ":" not in k)
    after_restart = sum(int(v) for k, v in counts.items() if k.endswith(":after_restart"))
    victim = next((k.split(":")[0] for k in counts if ":" in k), "?")
    print(f"  answered per replica (their metrics): {' '.join(answered)}; so {victim} answered "
          f"{len(ok) - survivors - after_restart} before the kill ({len(ok)} answered - the others' counts)")
    if failed_at:
        print(f"  the failed calls started at {failed_at} s after the kill")
    print(f"  latency before the kill: p50 {p50 / 1e3:.2f} ms, p99 {p99 / 1e3:.2f} ms; "
          f"{len(in_flight)} calls in flight during `podman kill` ({(kill - kill_sent) / 1e3:.0f} ms), slowest "
          f"{max((c[1] for c in in_flight), default=0) / 1e3:.1f} ms")
    early = [c for c in slow_after if c[0] + c[1] - kill <= 1e6]
    late = [c for c in slow_after if c[0] + c[1] - kill > 1e6]
    print(f"  after the kill: {len(early)} calls slower than {slow / 1e3:.0f} ms (3 x p99) ended within 1 s, "
          f"the last {max(0.0, max((c[0] + c[1] - kill for c in early), default=0.0)) / 1e6:.3f} s after the kill; "
          f"{len(late)} later before the restart{f' (the last {recover:.2f} s after the kill)' if late else ''}; "
          f"answered/s 1 s before {rate(kill - 1e6, kill):.0f}, 1 s after {rate(kill, kill + 1e6):.0f}")
    if "exited" in events:
        print(f"  the replica's server exited {(events['exited'] - kill_sent) / 1e6:.2f} s after SIGTERM was sent "
              f"(its drain), restarted {(restart - events['exited']) / 1e6:.2f} s later")
    if "ready" in events:
        first = f", first call answered by it {(events['first_call'] - restart) / 1e6:.2f} s after" if "first_call" in events else ", no call reached it"
        how = "podman restarted it (restartPolicy Always)" if by_podman else "`podman pod start`"
        print(f"  restarted replica SERVING {(events['ready'] - restart) / 1e6:.2f} s after {how}{first}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
