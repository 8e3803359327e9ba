#!/usr/bin/env bash
# Builds the kinplan image with podman on a machine without a Docker engine or
# a registry (Debian: apt-get install -y podman runc). From a clean clone:
#   bash deploy/image/build.sh            # image kinplan:latest
# Prints the image size (uncompressed and gzip-compressed).
set -euo pipefail
cd "$(dirname "$0")/../.."
command -v podman >/dev/null || { echo "needs podman (apt-get install -y podman runc)" >&2; exit 1; }
tag=${1:-kinplan:latest}
cargo build --release --locked --bin kinplan
ctx=$(mktemp -d)
trap 'rm -rf "$ctx"' EXIT
deploy/image/rootfs.sh target/release/kinplan "$ctx/rootfs"
cp deploy/image/Containerfile "$ctx/"
podman build --quiet -t "$tag" -f "$ctx/Containerfile" "$ctx" >/dev/null
raw=$(podman image inspect "$tag" --format '{{.Size}}')
gz=$(podman save "$tag" 2>/dev/null | gzip -9 | wc -c)
echo "image $tag: $((raw / 1024 / 1024)) MiB uncompressed, $((gz / 1024 / 1024)).$(( (gz % (1024*1024)) * 10 / 1024 / 1024 )) MiB gzip-compressed"
