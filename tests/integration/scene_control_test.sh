#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain on loopback: run-time session control.
# A probe holds the liver pressed in while another process (an instructor) doubles Young's
# modulus, lowers the physics rate, asks for scenes that do not exist or do not read, and loads
# the 12k-tet liver. Checks against theory: the GPS's forces scale exactly with E at a fixed
# configuration, so with the contact penalty in series the held force grows by
#   (1/k_pen + 1/k_t) / (1/k_pen + 1/(2 k_t))  (< 2),
# k_t the tissue's stiffness, here from the server's own condensed stiffness (local model).
# Usage: scene_control_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
trap 'kill "$server" "$presser" "$watcher" 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
presser=; watcher=
hc="$build/tools/haptic-client/haptic-client"
ctl="$build/tools/viscera-control/viscera-control"
# The scene directory: the liver, its 12k refinement, and a scene with a bad field.
scenes="$tmp/scenes"; mkdir -p "$scenes"
cp "$scene" "$scenes/liver.json"
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$src/data/meshes/#; s#\"../materials/#\"$src/data/materials/#" \
  "$src/data/scenes/liver-12k.json" > "$scenes/liver-12k.json"
sed 's/"contact_stiffness_n_per_m": [0-9]*/"contact_stiffness_n_per_m": -5/' "$scenes/liver.json" > "$scenes/broken.json"
# Press 2 cm below the top of the organ's bounds at its centre in 1 s, then hold.
printf 'time_s,x_m,y_m,z_m\n0,0,0,0.02\n1,0,0,-0.02\n16,0,0,-0.02\n' > "$tmp/hold.csv"

"$build/server/runtime/viscera-server" --scene "$scenes/liver.json" > "$tmp/server.log" 2>&1 &
server=$!
"$ctl" events --domain "$domain" --client-id 902 --duration 60 > "$tmp/events.log" 2>&1 &
watcher=$!
for _ in $(seq 100); do grep -q "following the events" "$tmp/events.log" && break; sleep 0.05; done
"$hc" --domain "$domain" --client-id 31 --instrument 1 --trajectory "$tmp/hold.csv" --frame organ-top --quiet \
  --report "$tmp/hold.json" > "$tmp/hold.log" 2>&1 &
presser=$!
for _ in $(seq 100); do grep -q "claimed" "$tmp/hold.log" && break; sleep 0.05; done
sleep 5
"$ctl" show --domain "$domain" > "$tmp/show0.log" 2>&1
t_material=$(date +%s.%N)
"$ctl" material --youngs-modulus-pa 10000 --domain "$domain" > "$tmp/material.log" 2>&1; rc_material=$?
t_material_done=$(date +%s.%N)
sleep 3.5
"$ctl" rate 250 --domain "$domain" > "$tmp/rate.log" 2>&1; rc_rate=$?
sleep 2.5
"$ctl" load nope --domain "$domain" > "$tmp/nope.log" 2>&1; rc_nope=$?
"$ctl" load broken --domain "$domain" > "$tmp/broken.log" 2>&1; rc_broken=$?
"$ctl" load liver-12k --domain "$domain" > "$tmp/load.log" 2>&1; rc_load=$?
# A client of the new scene: claims its probe, presses, watches the new surface.
"$hc" --domain "$domain" --client-id 41 --instrument 2 --duration 2 --depth 0.01 --watch-mesh --quiet \
  --report "$tmp/after.json" > "$tmp/after.log" 2>&1; rc_after=$?
"$ctl" show --domain "$domain" > "$tmp/show1.log" 2>&1
wait "$presser"; rc_presser=$?
sleep 0.3; kill "$watcher"; wait "$watcher" 2>/dev/null
kill -INT "$server"; wait "$server"; rc_server=$?
cat "$tmp/show0.log" "$tmp/material.log" "$tmp/rate.log" "$tmp/nope.log" "$tmp/broken.log" "$tmp/load.log" "$tmp/show1.log" \
  "$tmp/hold.log" "$tmp/after.log" "$tmp/events.log"
grep -v "Hz physics" "$tmp/server.log"

check "the scene state lists the loadable scenes, not the broken one" "grep -q 'scenes to load: liver liver-12k\$' '$tmp/show0.log'"
check "material change accepted (rc $rc_material)" "[ $rc_material -eq 0 ] && grep -q 'changed to material youngs_modulus_pa 10000' '$tmp/material.log'"
check "the scene state shows the new modulus" "grep -q 'E 10000 Pa' '$tmp/material.log'"
check "physics rate change accepted (rc $rc_rate)" "[ $rc_rate -eq 0 ] && grep -q 'physics rate 250 Hz (was 1000 Hz)' '$tmp/rate.log'"
# The rate took effect: a one-second window of about 250 ticks, not 1000 (a busy two-core machine
# misses a few of the 4 ms slots: 233-246 Hz seen beside the clients on the project's machine).
# Only the windows between the rate change and the request for the 12k scene count.
check "the server holds the new rate" "sed -n '/set_physics_rate/,/asked for scene liver-12k/p' '$tmp/server.log' | grep -Eq ': 2([0-4][0-9]|5[0-5]) Hz physics'"
check "unknown scene refused, naming what exists (rc $rc_nope)" "[ $rc_nope -eq 1 ] && grep -q \"no scene 'nope'.*available: liver, liver-12k\" '$tmp/nope.log'"
check "broken scene refused, naming file and field (rc $rc_broken)" "[ $rc_broken -eq 1 ] && grep -q 'broken.json.*contact_stiffness_n_per_m' '$tmp/broken.log'"
check "12k scene loaded (rc $rc_load)" "[ $rc_load -eq 0 ] && grep -q 'loaded scene liver-12k' '$tmp/load.log'"
check "the scene state shows the new scene, generation 2" "grep -q 'scene liver-12k' '$tmp/show1.log' && grep -q 'generation 2' '$tmp/show1.log'"
check "the holding client claimed its probe again in the new scene" "grep -q 'loaded scene liver-12k: instrument 1 claimed again' '$tmp/hold.log'"
check "a client of the new scene ran (rc $rc_after $rc_presser)" "[ $rc_after -eq 0 ] && [ $rc_presser -eq 0 ]"
check "server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"
pycheck "$tmp/events.log" <<'PY'
import sys
lines = [l.split() for l in open(sys.argv[1]) if l.startswith("event ")]
kinds = [l[1] for l in lines]
text = open(sys.argv[1]).read()
order = ["material_changed", "physics_rate_changed", "request_refused", "request_refused", "instrument_released", "scene_loaded"]
at, i = [], 0
for k in order:
    i = kinds.index(k, i) if k in kinds[i:] else -1
    assert i >= 0, f"no {k} in order {order} among {kinds}"
    at.append(i); i += 1
assert "the scene was replaced by liver-12k" in text, "the released owner was not told why"
print(f"[ figure ] control events seen by a console, in order: {', '.join(order)}")
PY
pycheck "$tmp/hold.json" "$t_material" "$t_material_done" "$tmp/after.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
t0 = float(sys.argv[2]) - r["start_epoch_s"]   # client time of the request
t1 = float(sys.argv[3]) - r["start_epoch_s"]   # client time the outcome arrived
s = [x for x in r["samples"] if x["in_contact"]]
def window(a, b):
    w = [x for x in s if a <= x["t_s"] <= b]
    assert len(w) > 200, f"{len(w)} samples in contact in [{a:.2f}, {b:.2f}] s"
    return w
before, after = window(t0 - 1.2, t0 - 0.1), window(t1 + 1.2, t1 + 2.4)
mean = lambda w, f: sum(f(x) for x in w) / len(w)
f0, f1 = mean(before, lambda x: x["force_n"][2]), mean(after, lambda x: x["force_n"][2])
k_local = mean(before, lambda x: x["normal_stiffness_n_per_m"])   # 1 / (1/k_pen + 1/k_t)
k_pen = 1000.0                                                      # the scene's contact stiffness
k_t = 1.0 / (1.0 / k_local - 1.0 / k_pen)
predicted = (1 / k_pen + 1 / k_t) / (1 / k_pen + 1 / (2 * k_t))
ratio = f1 / f0
print(f"[ figure ] Young's modulus 5 -> 10 kPa at a held 2 cm press: force {f0:.3f} -> {f1:.3f} N, ratio {ratio:.2f}; "
      f"predicted {predicted:.2f} (tissue {k_t:.0f} N/m in series with the 1000 N/m penalty), request to outcome {t1 - t0:.2f} s")
assert f0 > 0.05, f"the probe held no force before the change ({f0:.3f} N)"
# Constant-Q relaxation between the windows (about 2 s apart, t^-0.07) lowers the ratio a little.
assert 0.8 * predicted < ratio < 2.0, f"force ratio {ratio:.2f}, predicted {predicted:.2f}"
a = json.load(open(sys.argv[4]))
frames = [m for m in a["mesh"]["samples"] if m["mesh_id"] == 2]
assert a["scene"] == "liver-12k" and len(frames) > 30, f"{a['scene']}: {len(frames)} frames of the new surface"
assert len(a["samples"]) / a["duration_s"] > 800, "forces in the new scene below 800/s"
print(f"[ figure ] after loading liver-12k: a new client received {len(frames)} frames of the new surface and "
      f"{len(a['samples']) / a['duration_s']:.0f} forces/s")
PY
finish
