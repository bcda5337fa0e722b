#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Live surface frames in Python copy nothing: viscera-server on a scene (default the 96k liver), a
# Python client takes frames and measures with tracemalloc what taking their positions allocates,
# against what a copy allocates. Prints one line per scene.
# Usage: [SCENES="liver-96k"] bench/python_frame.sh
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
python="$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$root/build/CMakeCache.txt")"
for scene in ${SCENES:-liver-96k}; do
  domain=$(( (RANDOM % 200) + 1 ))
  sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
    "$root/data/scenes/$scene.json" > "$tmp/$scene.json"
  "$root/build/server/runtime/viscera-server" --scene "$tmp/$scene.json" > "$tmp/server.log" 2>&1 &
  server=$!
  PYTHONPATH="$root/build/python" "$python" - "$domain" "$scene" <<'PY'
import sys, time, tracemalloc
import viscera
domain, scene = int(sys.argv[1]), sys.argv[2]
c = viscera.session.Client(domain, 81)
assert c.wait_for_scene(120.0) is not None, "no server"
frame = None
deadline = time.monotonic() + 120
while frame is None and time.monotonic() < deadline:
    c.surface()
    frame = c.poll_mesh_frame()
    time.sleep(0.05)
assert frame is not None, "no frame"
tracemalloc.start()
start = tracemalloc.get_traced_memory()[0]
positions = frame.positions
view = tracemalloc.get_traced_memory()[0] - start
copy = positions.copy()
copied = tracemalloc.get_traced_memory()[0] - start - view
tracemalloc.stop()
print(f"{scene}: a frame of {positions.shape[0]} vertices ({positions.nbytes} bytes): taking its positions allocated {view} bytes; "
      f"a copy would allocate {copied} bytes")
PY
  kill -INT "$server"; wait "$server" || true
done
