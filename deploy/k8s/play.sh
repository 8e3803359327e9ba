#!/usr/bin/env bash
# Runs deploy/k8s/kinplan.yaml's Deployment with `podman kube play`, balances
# the Python and the Rust client over its replicas and kills one replica under
# load, then tears everything down. Hand-run (root, podman 4.x with runc and
# iptables; see deploy/README.md "Running the manifest with podman"):
#   bash deploy/k8s/play.sh
# Exits 0 when no request was lost, 1 when one was, 77 when podman cannot run
# containers here (skipped, with the reason).
#
# Per round (one client each): load for DURATION s at RATE calls/s; at KILL_AT
# s one replica's server process gets SIGKILL (a crash, no drain; KILL=pod
# kills its whole pod); at RESTART_AT s its pod is started again (`podman pod
# start`: the restart the kubelet does, which podman does not here) and
# rejoins once SERVING. KILL=term sends SIGTERM instead: the server drains
# and exits 0, and podman restarts it itself (restartPolicy Always). A lost
# request is a call that failed after the client's own retries.
#
# Networking stays off the host: every podman command runs in a network
# namespace made here (`ip netns add`; nsenter --net only, so podman's mounts
# stay in the host's mount namespace), which holds podman's bridge, its
# iptables rules and the pods; the clients run there too. The pods' network
# (podman network `kinplan-play`, $SUBNET.0/24, removed at the end) has its
# bridge only inside it.
set -euo pipefail
cd "$(dirname "$0")/../.."
RATE=${RATE:-400}           # calls/s per client; 0: back to back (closed loop)
DURATION=${DURATION:-20}    # s per round
KILL_AT=${KILL_AT:-5}       # s into the round
RESTART_AT=${RESTART_AT:-10}
CONCURRENCY=${CONCURRENCY:-8}
KILL=${KILL:-container}     # container: SIGKILL the server process; pod: SIGKILL the whole
                            # pod; term: SIGTERM the server (its drain, as on a rollout)
NETNS=${KINPLAN_PLAY_NETNS:-kinplan-play}
SUBNET=${KINPLAN_PLAY_SUBNET:-10.89.7}   # /24 of the pods' network (inside the namespace)
PY=${PYTHON:-target/py-venv/bin/python}
bin=${KINPLAN_BIN:-target/release/kinplan}
CLIENTS=${CLIENTS:-python rust}   # one round each, in this order

skip() { echo "SKIP: $*" >&2; exit 77; }
[ "$(id -u)" = 0 ] || skip "needs root (network namespace, rootful podman)"
command -v podman >/dev/null || skip "no podman (apt-get install -y podman runc iptables)"
command -v runc >/dev/null || skip "no runc (crun fails on this host's hybrid cgroups; apt-get install -y runc)"
command -v iptables >/dev/null || skip "no iptables (netavark needs it for the pods' bridge)"
command -v curl >/dev/null || skip "no curl (reads the replicas' metrics)"
"$PY" -c 'import kinplan, yaml' 2>/dev/null || skip "$PY lacks the kinplan client or pyyaml (pip install ./clients/python pyyaml)"
# (the Rust client's load: target/release/examples/balanced_load, built below)

work=$(mktemp -d)
# runc: crun 1.8 refuses this host's cgroup layout ("cgroups in hybrid mode
# not supported"); ulimits: without CAP_SYS_RESOURCE podman's default
# nofile=1048576 cannot be set (EPERM), so the limits stay under the hard ones.
cat > "$work/containers.conf" <<'EOF'
[containers]
default_ulimits = ["nofile=1024:1024", "nproc=4096:4096"]
[engine]
runtime = "runc"
EOF
export CONTAINERS_CONF=$work/containers.conf
made_netns=0
if ! ip netns list | grep -qw "^$NETNS"; then
  ip netns add "$NETNS"
  ip -n "$NETNS" link set lo up
  made_netns=1
fi
in_ns() { nsenter --net="/run/netns/$NETNS" "$@"; }
manifest=$work/kinplan.podman.yaml
made_net=0
cleanup() {
  in_ns podman kube down "$manifest" >/dev/null 2>&1 || true
  [ "$made_net" = 1 ] && podman network rm kinplan-play >/dev/null 2>&1 || true
  [ "$made_netns" = 1 ] && ip netns del "$NETNS" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

now() { date +%s.%N; }
since() { python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$1" "$2"; }

echo "== image"
if [ -z "${SKIP_BUILD:-}" ]; then
  bash deploy/image/build.sh
  cargo build --release --locked -p kinplan-client --example balanced_load
fi
podman image exists kinplan:latest || skip "no image kinplan:latest (deploy/image/build.sh)"
# can a container run here at all?
if ! err=$(in_ns podman run --rm --network none kinplan:latest --version 2>&1); then
  skip "podman cannot run a container here: $err"
fi

echo "== podman kube play (rendered from deploy/k8s/kinplan.yaml by podman_render.py)"
"$PY" deploy/k8s/podman_render.py deploy/k8s/kinplan.yaml > "$manifest"
replicas=$("$PY" -c 'import sys, yaml; print(next(d for d in yaml.safe_load_all(open(sys.argv[1])) if d["kind"] == "Deployment")["spec"]["replicas"])' deploy/k8s/kinplan.yaml)
# Static pod IPs and MACs: a Kubernetes pod keeps its sandbox (IP, MAC) when
# its container restarts; a kube-play pod stops whole when its container dies
# (exit policy "stop") and would come back on a new IP, which the clients'
# address list (the headless Service's answer, resolved once) does not follow,
# or on the same IP with a new MAC, unreachable until the namespace's ARP entry
# for it goes stale (20-45 s seen).
if ! podman network exists kinplan-play; then
  podman network create --subnet "$SUBNET.0/24" kinplan-play >/dev/null
  made_net=1
fi
ip_args=()
for i in $(seq "$replicas"); do
  ip_args+=(--ip "$SUBNET.$((10 + i))" --mac-address "$(printf '02:6b:70:00:00:%02x' "$((10 + i))")")
done
t0=$(now)
in_ns podman kube play --network kinplan-play "${ip_args[@]}" "$manifest" 2> >(grep -v -e syslog -e 'static macs' >&2) | grep -c '^Pod:' | sed 's/^/pods created: /'
mapfile -t pods < <(in_ns podman pod ps --filter label=app=kinplan --format '{{.Name}}' | sort)
[ "${#pods[@]}" = "$replicas" ] || { echo "FAIL: ${#pods[@]} pods for $replicas replicas"; exit 1; }
pod_ip() {
  local infra
  infra=$(in_ns podman pod inspect "$1" --format '{{.InfraContainerID}}')
  in_ns podman inspect "$infra" --format '{{range .NetworkSettings.Networks}}{{.IPAddress}}{{end}}'
}
declare -A ip
for p in "${pods[@]}"; do ip[$p]=$(pod_ip "$p"); done
# the headless Service's job: every ready replica's address
wait_ready() { # pod: polls grpc.health.v1 on the pod's IP (the readiness probe), up to 30 s
  for _ in $(seq 300); do
    [ "$(in_ns "$bin" health --target "${ip[$1]}:50051" --timeout 0.5 2>/dev/null)" = SERVING ] && return 0
    sleep 0.1
  done
  echo "FAIL: $1 (${ip[$1]}) not SERVING after 30 s"; exit 1
}
for p in "${pods[@]}"; do wait_ready "$p"; done
echo "$replicas replicas SERVING $(since "$t0" "$(now)") s after kube play: $(for p in "${pods[@]}"; do printf '%s=%s ' "$p" "${ip[$p]}"; done)"
targets=$(for p in "${pods[@]}"; do printf '%s:50051,' "${ip[$p]}"; done)
targets=${targets%,}

fk_count() { # ForwardKinematics calls a replica answered since it started (its metrics)
  in_ns curl -sf --max-time 1 "http://${ip[$1]}:9090/metrics" |
    awk '/^grpc_server_handled_total/ && /grpc_method="ForwardKinematics"/ { n += $NF } END { print n + 0 }'
}

lost_total=0
round() { # client victim
  local client=$1 victim=$2 calls=$work/calls-$1.txt events=$work/events-$1.txt
  local flags=""
  [ "$client" = rust ] && [ -n "${RUST_RETRY_TRANSPORT:-}" ] && flags=" (+ --retry-transport-errors)"
  echo "== $client client$flags over $targets: ${RATE}/s for ${DURATION} s; kill $victim ($KILL) at ${KILL_AT} s, $([ "$KILL" = term ] && echo "podman restarts it after its drain" || echo "restart at ${RESTART_AT} s")"
  declare -A before
  for p in "${pods[@]}"; do before[$p]=$(fk_count "$p"); done
  local driver
  if [ "$client" = python ]; then
    driver=("$PY" deploy/k8s/balanced_load.py)
  else
    driver=(target/release/examples/balanced_load)
    # the client does not retry a call whose connection broke (see balanced_load.rs)
    [ -n "${RUST_RETRY_TRANSPORT:-}" ] && driver+=(--retry-transport-errors)
  fi
  in_ns "${driver[@]}" --targets "$targets" --concurrency "$CONCURRENCY" --rate "$RATE" \
    --duration "$DURATION" --total "${TOTAL:-1000000}" --out "$calls" &
  local load=$!
  sleep "$KILL_AT"
  epoch_of() { # a time field of the victim's container, as epoch seconds
    in_ns podman inspect "$victim-kinplan" --format "{{.State.$1.UnixNano}}" |
      awk '{ printf "%d.%09d\n", $1 / 1e9, $1 % 1e9 }'
  }
  local victim_before started0
  started0=$(epoch_of StartedAt)
  victim_before=$(fk_count "$victim")
  echo "kill_sent $(now)" > "$events"
  if [ "$KILL" = pod ]; then
    in_ns podman pod kill "$victim" >/dev/null
  elif [ "$KILL" = term ]; then
    in_ns podman kill --signal TERM "$victim-kinplan" >/dev/null
  else
    in_ns podman kill "$victim-kinplan" >/dev/null
  fi
  echo "kill $(now)" >> "$events" # the process is gone by now (SIGKILL)
  if [ "$KILL" = term ]; then
    # the server exits 0 after its drain, and podman's restartPolicy Always
    # (the pod's, as the kubelet's) restarts it at once, in the same pod
    for _ in $(seq 400); do
      [ "$(epoch_of StartedAt)" != "$started0" ] && break
      sleep 0.1
    done
    echo "exited $(epoch_of FinishedAt)" >> "$events"
    echo "restart $(epoch_of StartedAt)" >> "$events"
    echo "restarted_by podman" >> "$events"
  else
    # SIGKILL: podman restarts nothing (the pod's exit policy stops it); start
    # the pod again at RESTART_AT, as the kubelet would restart the container
    sleep "$(python3 -c "print(max(0.0, $RESTART_AT - $KILL_AT))")"
    for _ in $(seq 100); do
      [ "$(in_ns podman pod inspect "$victim" --format '{{.State}}')" = Exited ] && break
      sleep 0.1
    done
    echo "restart $(now)" >> "$events"
    in_ns podman pod start "$victim" 2> >(grep -v "static macs" >&2) >/dev/null
  fi
  local new_ip
  new_ip=$(pod_ip "$victim")
  [ "$new_ip" = "${ip[$victim]}" ] || echo "note: $victim came back on $new_ip (was ${ip[$victim]}); the clients' address list does not follow"
  ip[$victim]=$new_ip
  wait_ready "$victim"
  echo "ready $(now)" >> "$events"
  for _ in $(seq 200); do # first call answered by the restarted replica
    [ "$(fk_count "$victim")" -gt 0 ] && { echo "first_call $(now)" >> "$events"; break; }
    sleep 0.05
  done
  wait "$load"
  local answered=""
  for p in "${pods[@]}"; do
    [ "$p" = "$victim" ] && continue
    answered+="$p=$(($(fk_count "$p") - ${before[$p]})) "
  done
  answered+="$victim:after_restart=$(fk_count "$victim") $victim:before_kill_seen=$((victim_before - ${before[$victim]}))"
  "$PY" deploy/k8s/play_report.py "$client" "$calls" "$events" $answered || lost_total=$((lost_total + 1))
}

n=0
for client in $CLIENTS; do # each round kills another replica
  n=$((n + 1))
  round "$client" "${pods[$((n % ${#pods[@]}))]}"
done

echo "== teardown"
in_ns podman kube down "$manifest" >/dev/null 2>&1 || true
[ -z "$(in_ns podman pod ps -q --filter label=app=kinplan)" ] && echo "pods removed"
[ "$lost_total" = 0 ] && echo "PASS: no request lost" || { echo "FAIL: requests lost in $lost_total round(s)"; exit 1; }
