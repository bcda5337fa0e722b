#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain: a scalpel's incision through the liver
# (haptic-client --script incise on instrument 4) while viscera-record records; the surface seen
# by the cutting client and by a client that joins after the cut (transient local: it gets the
# current cut surface, not the one loaded); the cut's events in the recording; and the recorded
# session re-simulated in lockstep bit for bit (positions, forces, events, the surface's
# topology generation at every frame); the organ's energy at each change of the mesh, live.
# Usage: cutting_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
hc="$build/tools/haptic-client/haptic-client"
"$build/server/runtime/viscera-server" --scene "$scene" > "$tmp/server.log" 2>&1 & server=$!; pids+=($server)
"$build/tools/viscera-record/viscera-record" --out "$tmp/cut.mcap" --domain "$domain" --compression none > "$tmp/rec.log" 2>&1 & recorder=$!; pids+=($recorder)
wait_for "recording DDS domain" "$tmp/rec.log"; wait_for "DDS domain" "$tmp/server.log"
sleep 1  # discovery
"$hc" --domain "$domain" --client-id 21 --instrument 4 --script incise --depth 0.015 --length 0.06 --duration 3 --watch-mesh --quiet \
  --report "$tmp/incise.json" > "$tmp/incise.log" 2>&1; rc_incise=$?
# A client that joins after the cut: the topology it gets is the current one.
"$hc" --domain "$domain" --client-id 22 --instrument 2 --duration 0.5 --depth 0 --watch-mesh --quiet --report "$tmp/late.json" > "$tmp/late.log" 2>&1; rc_late=$?
sleep 0.3
kill -INT "$recorder"; wait "$recorder"; rc_rec=$?
kill -INT "$server"; wait "$server"; rc_server=$?
cat "$tmp/incise.log" "$tmp/late.log"; tail -2 "$tmp/server.log"
check "the incision ran (client $rc_incise, late client $rc_late, recorder $rc_rec, server $rc_server)" \
  "[ $rc_incise -eq 0 ] && [ $rc_late -eq 0 ] && [ $rc_rec -eq 0 ] && [ $rc_server -eq 0 ]"
check "the organ's kinetic plus elastic energy never rose at a change of the mesh by the live cut" \
  "grep 'stopped after' '$tmp/server.log' | grep -qE ' [1-9][0-9]* changes of the mesh by cuts, kinetic plus elastic energy rose at 0 '"
pycheck "$tmp/incise.json" "$tmp/late.json" <<'PY'
import json, sys
cut, late = (json.load(open(p))["mesh"] for p in sys.argv[1:3])
print(f"cutting client: surface generation {cut['topology_generation']}, {cut['surface_vertices']} vertices, {cut['frames']} frames; "
      f"late client: generation {late['topology_generation']}, {late['surface_vertices']} vertices, {late['frames']} frames")
# The bundled 1.5k liver's surface has 432 vertices before any cut.
assert cut["topology_generation"] >= 5, "the surface did not change as the blade cut"
assert cut["surface_vertices"] > 432, "the cut added no surface vertices"
assert late["topology_generation"] == cut["topology_generation"] and late["surface_vertices"] == cut["surface_vertices"], \
    "a client joining after the cut does not get the cut surface"
assert late["frames"] > 10, "the late client's frames were not of the surface it got"
PY
# The stroke's events, in the recording (uncompressed: the event's text is there as written).
check "the recording holds the stroke's cut_started and cut_ended events" \
  "grep -aq 'stroke 0' '$tmp/cut.mcap' && grep -aq 'tetrahedra cut' '$tmp/cut.mcap'"
"$build/tools/viscera-replay/viscera-replay" resimulate "$tmp/cut.mcap" --report "$tmp/resim.json" > "$tmp/resim.log" 2>&1; rc_resim=$?
cat "$tmp/resim.log"
check "the session with its cut re-simulates bit for bit (rc $rc_resim)" "[ $rc_resim -eq 0 ] && grep -q 'bit-identical' '$tmp/resim.log'"
pycheck "$tmp/resim.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print("re-simulation:", json.dumps(r.get("frames")), json.dumps(r.get("events")))
assert r["frames"]["compared"] > 100 and r["frames"]["identical"] == r["frames"]["recorded"], r["frames"]
PY
# The recording played back from its last half second, after the cut (schema 16: the newest
# surface message before that point is a patch of the one before): a client of the replay's
# station gets the whole surface as it stood there, the cutting client's, and frames of it.
span=$("$build/tools/viscera-record/viscera-record" info "$tmp/cut.mcap" | grep -o "over [0-9.]* s" | grep -o "[0-9.]*")
from=$(python3 -c "print(max(0.0, ${span:-0} - 0.5))")
"$build/tools/viscera-replay/viscera-replay" play "$tmp/cut.mcap" --from "$from" --loop --station replay-cut --domain "$domain" --no-keys --quiet \
  > "$tmp/play.log" 2>&1 & player=$!; pids+=($player)
PYTHONPATH="$build/python" /usr/bin/python3 - "$tmp/incise.json" "$domain" <<'PY'; rc_replay=$?
import json, sys, time
from viscera.session import Client
cut = json.load(open(sys.argv[1]))["mesh"]
c = Client(int(sys.argv[2]), 31, "replay-cut")
surface, frames, end = None, 0, time.time() + 15
while time.time() < end and frames < 10:
    surface = c.surface()
    f = c.poll_mesh_frame()
    if f is not None and surface is not None and f.topology_generation == surface.topology_generation:
        frames += 1
    time.sleep(0.01)
got = (surface.topology_generation, surface.vertex_count) if surface else None
print(f"replay from its last half second: surface {got}, {frames} frames; the cutting client's: "
      f"generation {cut['topology_generation']}, {cut['surface_vertices']} vertices")
sys.exit(0 if got == (cut["topology_generation"], cut["surface_vertices"]) and frames >= 10 else 1)
PY
kill -INT "$player" 2>/dev/null; wait "$player" 2>/dev/null
check "a replay from after the cut gives a new client the cut surface whole, and its frames (rc $rc_replay)" "[ $rc_replay -eq 0 ]"
finish
