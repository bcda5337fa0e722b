#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain: a patient's liver from the bundled CT
# label map (viscera-mesh, docs/MESHING.md) run by the server as any scene is: it loads with its
# gallbladder as a region of its own material and held where the mesher said; a haptic client
# presses it and feels the organ push back, with no step on the hand and no physics reset; the
# session is recorded, and re-simulated in lockstep bit for bit from the recording alone.
# Usage: patient_organ_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
mesh="$build/tools/viscera-mesh/viscera-mesh"
rec="$build/tools/viscera-record/viscera-record"
replay="$build/tools/viscera-replay/viscera-replay"
hc="$build/tools/haptic-client/haptic-client"
ctl="$build/tools/viscera-control/viscera-control"

start=$(date +%s.%N)
"$mesh" "$src/data/label-maps/abdomen-totalsegmentator/example_seg.nii.gz" --organ 5 --organ-name liver \
  --region "4:gallbladder:$src/data/materials/gallbladder.json" --material "$src/data/materials/liver-viscoelastic.json" \
  --hold-touching 63 --hold-crop --tets 12000 --out "$tmp/patient" --name patient-liver > "$tmp/mesh.log" 2>&1; rc_mesh=$?
seconds=$(python3 -c "print(f'{$(date +%s.%N) - $start:.1f}')")
cat "$tmp/mesh.log"
check "viscera-mesh made the patient's liver in $seconds s (rc $rc_mesh; target 60 s)" "[ $rc_mesh -eq 0 ] && python3 -c 'import sys; sys.exit($seconds > 60)'"

"$build/server/runtime/viscera-server" --scene "$tmp/patient/patient-liver.json" --domain "$domain" > "$tmp/server.log" 2>&1 & server=$!; pids+=($server)
"$rec" --out "$tmp/session.mcap" --domain "$domain" --quiet > "$tmp/rec.log" 2>&1 & recorder=$!; pids+=($recorder)
wait_for "recording DDS domain" "$tmp/rec.log"
sleep 1
"$ctl" show --domain "$domain" > "$tmp/show.log" 2>&1; rc_show=$?
cat "$tmp/show.log"
check "the server runs the patient's liver with its gallbladder as a region (rc $rc_show)" \
  "[ $rc_show -eq 0 ] && grep -q 'patient-liver' '$tmp/show.log' && grep -q 'gallbladder' '$tmp/show.log'"
"$hc" --domain "$domain" --client-id 31 --instrument 2 --script press --depth 0.015 --duration 4 --report "$tmp/press.json" --quiet > "$tmp/press.log" 2>&1
rc_press=$?
cat "$tmp/press.log"
sleep 0.3
kill -INT "$recorder"; wait "$recorder"; rc_rec=$?
kill -INT "$server"; wait "$server"; rc_server=$?
grep -E "scene patient-liver|stopped after" "$tmp/server.log"
check "the press ran and the server stopped cleanly (press $rc_press, recorder $rc_rec, server $rc_server)" \
  "[ $rc_press -eq 0 ] && [ $rc_rec -eq 0 ] && [ $rc_server -eq 0 ]"
check "no physics reset" "grep -q 'stopped after .* 0 physics resets' '$tmp/server.log'"
pycheck "$tmp/press.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
samples = r["samples"] if isinstance(r, dict) else r
f = [math.dist(s["rendered_force_n"], (0, 0, 0)) for s in samples]
peak = max(f)
step = max(abs(b - a) for a, b in zip(f, f[1:]))
print(f"press on the patient's liver: peak {peak:.2f} N, largest 1 ms step of the rendered force {step:.3f} N, {len(f)} samples")
sys.exit(0 if 0.2 < peak < 15 and step < 0.5 else 1)
PY
"$replay" resimulate "$tmp/session.mcap" --domain "$domain" --quiet > "$tmp/resim.log" 2>&1; rc_resim=$?
cat "$tmp/resim.log"
check "the recorded session re-simulates bit for bit from the recording (rc $rc_resim)" "[ $rc_resim -eq 0 ] && grep -q 'bit-identical' '$tmp/resim.log'"
finish
