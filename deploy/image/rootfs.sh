#!/usr/bin/env bash
# Lays out the root filesystem of the kinplan image: the stripped binary, the
# shared libraries `ldd` names for it (and nothing else), and passwd/group
# entries for the unprivileged user 10001. Used by build.sh (podman) and by
# the multi-stage Dockerfile, so both produce the same image.
#   usage: rootfs.sh BINARY OUT_DIR
set -euo pipefail
bin=${1:?usage: rootfs.sh BINARY OUT_DIR}
out=${2:?usage: rootfs.sh BINARY OUT_DIR}
rm -rf "$out"
mkdir -p "$out/usr/local/bin" "$out/etc" "$out/tmp"
install -m 0755 "$bin" "$out/usr/local/bin/kinplan"
strip --strip-debug "$out/usr/local/bin/kinplan"
# Every library the dynamic loader resolves, plus the loader itself, at the
# paths the binary expects.
ldd "$bin" | awk '/=> \// { print $3 } /^[ \t]*\/[^ ]*ld-linux/ { print $1 }' | sort -u |
  while read -r lib; do
    mkdir -p "$out$(dirname "$lib")"
    cp -L "$lib" "$out$lib"
  done
echo 'kinplan:x:10001:10001:kinplan:/nonexistent:/sbin/nologin' > "$out/etc/passwd"
echo 'kinplan:x:10001:' > "$out/etc/group"
chmod 1777 "$out/tmp"
