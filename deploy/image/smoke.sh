#!/usr/bin/env bash
# Runs the kinplan image with podman and smoke-tests it: time until health
# SERVING, FK calls answered, the unprivileged user and read-only root, and a
# SIGTERM drain (health NOT_SERVING first, then exit 0). Run after build.sh:
#   bash deploy/image/smoke.sh [kinplan:latest]
# Loopback only (--network host with the listener on 127.0.0.1).
set -euo pipefail
cd "$(dirname "$0")/../.."
tag=${1:-kinplan:latest}
port=${KINPLAN_SMOKE_PORT:-50071}
bin=target/release/kinplan
loadtest=target/release/kinplan-loadtest
name=kinplan-smoke-$$
now() { date +%s.%N; }
ms() { python3 -c "print(f'{($2 - $1) * 1000:.0f} ms')"; }

t0=$(now)
podman run -d --name "$name" --runtime runc \
  --ulimit nofile=1024:1024 --ulimit nproc=1000:1000 \
  --network host --read-only \
  -e KINPLAN_LISTEN="127.0.0.1:$port" -e KINPLAN_METRICS_LISTEN="127.0.0.1:$((port + 1))" \
  -e KINPLAN_DRAIN_DELAY_SECS=1 \
  "$tag" >/dev/null
trap 'podman rm -f "$name" >/dev/null 2>&1 || true' EXIT
for _ in $(seq 500); do
  "$bin" health --target "127.0.0.1:$port" --timeout 0.2 >/dev/null 2>&1 && break
  sleep 0.01
done
t1=$(now)
[ "$("$bin" health --target "127.0.0.1:$port")" = SERVING ] || { echo "FAIL: not SERVING"; exit 1; }
echo "ready (health SERVING) $(ms "$t0" "$t1") after 'podman run'"

echo "user: $(podman inspect "$name" --format '{{.Config.User}}'), read-only root: $(podman inspect "$name" --format '{{.HostConfig.ReadonlyRootfs}}')"
[ -x "$loadtest" ] || cargo build --release --locked -p kinplan-loadtest
"$loadtest" --target "127.0.0.1:$port" --rpc fk --total 500 --concurrency 4 --connections 1 --warmup 5 | sed 's/^/  /'
curl -sf "http://127.0.0.1:$((port + 1))/metrics" | grep -c '^grpc_server_handled_total' | sed 's/^/  metric series grpc_server_handled_total: /' || echo "  (curl missing: metrics not checked)"

# Drain: SIGTERM turns health NOT_SERVING for the drain delay (1 s), then the
# process exits 0.
podman kill --signal TERM "$name" >/dev/null
t2=$(now)
sleep 0.2
echo "health 0.2 s after SIGTERM: $("$bin" health --target "127.0.0.1:$port" 2>&1 || true)"
code=$(podman wait "$name")
t3=$(now)
echo "exited with $code $(ms "$t2" "$t3") after SIGTERM"
[ "$code" = 0 ] || { echo "FAIL: exit code $code"; exit 1; }
echo "smoke test passed"
