#!/usr/bin/env bash
# One measurement session: ours (ik_bench, which also writes the targets), then the
# anchors on those targets, then ours again; load average and the busiest processes
# are logged before every step.
#
#   benches/anchors/run_session.sh [N] [OUT_DIR]
#
# Needs the venv of README.md (PY, default /tmp/anchor-venv/bin/python).
set -euo pipefail
cd "$(dirname "$0")/../.."
N=${1:-10000}
OUT=${2:-/tmp/anchor-session}
PY=${PY:-/tmp/anchor-venv/bin/python}
TARGETS=$OUT/targets
ARMS=kuka_kr210_r2700_extra,abb_irb4600_60_205,ur5,franka_panda,kuka_lbr_iiwa14_r820
mkdir -p "$OUT"
LOG=$OUT/session.log

state() {
  {
    echo "== $1  $(date -u +%FT%TZ)  loadavg: $(cut -d' ' -f1-3 /proc/loadavg)"
    # second frame of top = CPU use over the last second; processes above 5 %
    top -bn2 -d 1 | awk '/^top -/{n++} n==2 && $1 ~ /^[0-9]+$/ && $9+0 > 5 {print "   busy:", $9 "%", $12}'
  } | tee -a "$LOG"
}

# Runs ik_bench "$@" > $OUTFILE and logs the CPU used by it and by everything else.
busy() { awk '/^cpu /{print $2+$3+$4+$7+$8, $9}' /proc/stat; }
ours() {
  local out=$1; shift
  local b0 b1 e u s
  b0=$(busy)
  /usr/bin/time -f "%e %U %S" -o "$out.time" "$@" > "$out"
  b1=$(busy)
  cat "$out"
  read -r e u s < "$out.time"
  # fields: busy0 steal0 busy1 steal1 wall user sys hz
  echo "$b0 $b1 $e $u $s $(getconf CLK_TCK)" | awk '{wall=$5; own=$6+$7; hz=$8;
    printf "   ik_bench: wall %.2f s, CPU used by ik_bench %.2f cores, by other processes %.2f cores, stolen %.2f cores\n",
      wall, own/wall, (($3-$1)/hz - own)/wall, ($4-$2)/hz/wall}' | tee -a "$LOG"
}

# Waits (up to WAIT_IDLE seconds, default 600) until no other process uses > 20 % CPU in
# two consecutive 1-second samples of top; goes on anyway after that and says so.
wait_idle() {
  local max=${WAIT_IDLE:-600} start=$SECONDS ok=0 busy=""
  while (( SECONDS - start < max )); do
    busy=$(top -bn2 -d 1 | awk '/^top -/{n++} n==2 && $1 ~ /^[0-9]+$/ && $9+0 > 20 {print $12}' | head -3 | tr '\n' ' ')
    if [[ -z "$busy" ]]; then ok=$((ok + 1)); else ok=0; fi
    if (( ok >= 2 )); then echo "machine idle after $((SECONDS - start)) s of waiting"; return; fi
  done
  echo "WARNING: still busy after $max s ($busy); measuring anyway"
}
wait_idle | tee "$OUT/wait_idle.log"

{
  echo "date: $(date -u)"
  echo "host: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-)"
  echo "kinplan HEAD: $(git rev-parse HEAD)"
  echo "working tree (uncommitted changes are part of what 'ours' measures):"
  git status --short | sed 's/^/   /'
  echo "sha256 of 'git diff HEAD -- src': $(git diff HEAD -- src | sha256sum | cut -c1-16)"
} | tee "$LOG"
git diff HEAD -- src > "$OUT/src.diff"

cargo build --release --example ik_bench 2>&1 | tail -1 | tee -a "$LOG"
BIN=target/release/examples/ik_bench

state "ours, run 1 (writes the targets)"
DUMP_TARGETS=$TARGETS ours "$OUT/ours_1.md" $BIN "$N" $ARMS lm-svd

state "anchors: TRAC-IK"
$PY benches/anchors/run_anchors.py --targets "$TARGETS" --arms $ARMS \
  --anchors tracik,tracik-strict > "$OUT/anchors_tracik.md" 2> "$OUT/anchors_tracik.log"
cat "$OUT/anchors_tracik.md"

state "anchors: KDL"
$PY benches/anchors/run_anchors.py --targets "$TARGETS" --arms $ARMS \
  --anchors kdl,kdl-strict,kdl-5ms,kdl-lma > "$OUT/anchors_kdl.md" 2> "$OUT/anchors_kdl.log"
cat "$OUT/anchors_kdl.md"

state "ours, run 2 (targets written again and compared)"
DUMP_TARGETS=$OUT/targets_2 ours "$OUT/ours_2.md" $BIN "$N" $ARMS lm-svd
for f in "$TARGETS"/*; do cmp "$f" "$OUT/targets_2/$(basename "$f")"; done && echo "targets identical in both runs" | tee -a "$LOG"
rm -rf "$OUT/targets_2"

state "end"
