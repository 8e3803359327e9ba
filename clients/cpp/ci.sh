#!/usr/bin/env bash
# Builds the C++ client (clients/cpp) into target/cpp-build and runs its tests
# against a real `kinplan serve` on a free loopback port.
#
#   clients/cpp/ci.sh            # from anywhere; KINPLAN_BIN overrides the server
#
# Debian packages: when some are missing and this runs as root with apt-get
# (the CI container), they are installed: the C++ client is part of the
# product and a CI run that silently skipped it would let it rot. Otherwise
# (a developer machine without root) the build is skipped with a message and
# exit status 0, unless KINPLAN_CPP_REQUIRED=1 makes that a failure.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
build="$root/target/cpp-build"
server="${KINPLAN_BIN:-$root/target/debug/kinplan}"

packages=(cmake g++ pkg-config libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev libeigen3-dev)
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]})); then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "== installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null ||
      { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; }
  else
    echo "== SKIPPED the C++ client: missing Debian packages ${missing[*]}"
    echo "   (install them with: sudo apt-get install ${missing[*]})"
    [ "${KINPLAN_CPP_REQUIRED:-0}" = 1 ] && exit 1
    exit 0
  fi
fi

if [ ! -x "$server" ]; then
  echo "kinplan binary not found at $server: run \`cargo build -p kinplan-server\` or set KINPLAN_BIN" >&2
  exit 1
fi

echo "== cmake build (target/cpp-build)"
cmake -S clients/cpp -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log="$build/server.log"
# --model-cache 1: two URDF robots used in turn evict each other, so the tests
# exercise the client's NOT_FOUND -> resend-the-URDF rule.
"$server" serve --listen "127.0.0.1:$port" --model-cache 1 >"$log" 2>&1 &
pid=$!
trap 'kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null || true' EXIT

echo "== C++ client tests against $server on 127.0.0.1:$port"
# the tests wait up to 30 s for the server to accept connections
if ! "$build/client_tests" "127.0.0.1:$port" "$root"; then
  echo "-- server log:" >&2
  tail -n 50 "$log" >&2
  exit 1
fi
