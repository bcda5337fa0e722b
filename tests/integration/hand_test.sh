#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain on loopback: a hand is never struck
# (docs/FAULTS.md, "The force on the hand"). A real server and a real haptic client whose report
# holds the force it commanded its device, one sample a millisecond; in each scenario an event
# comes under a pressing probe, and the force on the hand must
#  - change by at most the slew limit (1 N/ms, the default) from one 1 ms sample to the next, and
#  - never exceed the larger of 1.5x the force just before the event and that force plus 1 N.
# Scenarios: the organ reset under a 2 cm press; the 12k liver loaded under a probe holding 0.5 N
# (the client claims again in the new scene, its tip still deep); the organ paused under a press
# that goes on deeper (the frozen organ must not let the tip through: the force never falls to
# zero while the tip is in it); a scalpel's cut button released with the blade 2 cm in the tissue
# (it leaves the cut touching nothing); the stiffest material the server takes pressed 3 cm (no
# physics reset), a stiffer one refused.
# Usage: hand_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
server=""
trap 'kill -KILL $server 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
bin_server="$build/server/runtime/viscera-server"
hc="$build/tools/haptic-client/haptic-client"
ctl="$build/tools/viscera-control/viscera-control"
now() { date +%s.%N; }
# The 1.5k liver, with the 12k liver and a deeper-pressed 1.5k liver beside it to load.
mkdir -p "$tmp/scenes"
cp "$scene" "$tmp/scenes/liver.json"
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$src/data/meshes/#; s#\"../materials/#\"$src/data/materials/#" \
  "$src/data/scenes/liver-12k.json" > "$tmp/scenes/liver-12k.json"
# The 1.5k liver stating a deeper strain for the stiff material's press (below).
sed 's/"volume_term": 0.5,/"volume_term": 0.5, "largest_edge_strain": 0.5,/; s/"name": "liver"/"name": "liver-deep"/' \
  "$tmp/scenes/liver.json" > "$tmp/scenes/liver-deep.json"
start_server() {  # log; waits for its first status line
  "$bin_server" --scene "$tmp/scenes/liver.json" > "$1" 2>&1 &
  server=$!
  wait_for "physics" "$1" 200
}
stop_server() { kill -INT "$server"; wait "$server"; }
# The force on the hand around an event at epoch time EVENT: the two bounds above; NAME for the
# figure line.
hand_check() {  # REPORT EVENT NAME
  pycheck "$1" "$2" "$3" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
event, name = float(sys.argv[2]) - r["start_epoch_s"], sys.argv[3]
slew = r["slew_limit"]["n_per_ms"]
s = r["samples"]
mag = lambda x: math.sqrt(sum(c * c for c in x["rendered_force_n"]))
before = [mag(x) for x in s if event - 0.05 <= x["t_s"] <= event]
assert before, f"{name}: no samples in the 50 ms before the event at t = {event:.3f} s"
f0 = sum(before) / len(before)
assert f0 > 0.2, f"{name}: the probe was not pressing before the event ({f0:.3f} N)"
bound = max(1.5 * f0, f0 + 1.0)
after = [x for x in s if x["t_s"] > event]
assert len(after) > 500, f"{name}: only {len(after)} samples after the event"
peak = max(mag(x) for x in after)
# Consecutive periods (a period the loop only rendered, or waited through, leaves no sample).
steps = [(abs(mag(b) - mag(a)), b["t_s"]) for a, b in zip(s, s[1:]) if b["t_s"] - a["t_s"] <= 1.05e-3]
worst, at = max(steps)
print(f"[ figure ] {name}: force before {f0:.3f} N, largest after {peak:.3f} N (bound {bound:.3f} N); largest 1 ms change "
      f"{worst:.3f} N at t = {at:.3f} s (limit {slew} N/ms; the renderer asked for at most {r['slew_limit']['largest_step_asked_n']:.3f} N)")
assert worst <= slew + 1e-9, f"{name}: the force changed by {worst:.3f} N in one sample"
assert peak <= bound, f"{name}: the force reached {peak:.3f} N after the event, above {bound:.3f} N"
PY
}

# under_probe NAME DELAY EVENT CLIENT-ARGS...: a haptic client (its report NAME.json, its log
# hc-NAME.log), and DELAY s after its claim the shell function EVENT; sets event_at, rc_client.
under_probe() {
  local name="$1" delay="$2" event="$3"; shift 3
  "$hc" --domain "$domain" --client-id 1 --instrument 1 --quiet --report "$tmp/$name.json" "$@" > "$tmp/hc-$name.log" 2>&1 &
  local client=$!
  wait_for "claimed" "$tmp/hc-$name.log"
  sleep "$delay"
  event_at=$(now)
  "$event" > "$tmp/ctl-$name.log" 2>&1
  wait "$client"; rc_client=$?
  cat "$tmp/hc-$name.log"
}

start_server "$tmp/server.log"

# --- The organ reset under a 2 cm press (the press is deepest at 3 s). ---
reset_organ() { "$ctl" reset --domain "$domain"; }
under_probe reset 3.2 reset_organ --script press --depth 0.02 --duration 6
check "reset: the client ran to its end (rc $rc_client)" "[ $rc_client -eq 0 ]"
check "reset: the client saw the organ jump and ramped its force" "grep -q 'the organ was reset, reloaded' '$tmp/hc-reset.log'"
check "reset: no physics reset on the server" "! grep -q 'physics: ' '$tmp/server.log'"
hand_check "$tmp/reset.json" "$event_at" "reset under a 2 cm press"

# --- The 12k liver loaded under a probe holding 0.5 N: the client claims again, its tip deep. ---
load_12k() { "$ctl" load liver-12k --domain "$domain"; }
under_probe load 3 load_12k --script hold --force 0.5 --duration 9
check "load: the client claimed again in the new scene (rc $rc_client)" "[ $rc_client -eq 0 ] && grep -q 'the server loaded scene liver-12k: instrument 1 claimed again' '$tmp/hc-load.log'"
hand_check "$tmp/load.json" "$event_at" "scene loaded under a 0.5 N hold"

# --- The organ paused under a press that goes on deeper, then resumed. ---
pause_a_while() { "$ctl" pause --domain "$domain"; sleep 1.5; "$ctl" resume --domain "$domain"; }
under_probe pause 2 pause_a_while --script press --depth 0.04 --duration 8
pause_at=$event_at
check "pause: the client ran to its end (rc $rc_client)" "[ $rc_client -eq 0 ]"
# The bound on the peak does not hold for a frozen organ pressed 1.5 s deeper (it is a wall, up to
# the device's 15 N): the slew and the floor are asked here.
pycheck "$tmp/pause.json" "$pause_at" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
pause = float(sys.argv[2]) - r["start_epoch_s"]
s = r["samples"]
mag = lambda x: math.sqrt(sum(c * c for c in x["rendered_force_n"]))
slew = r["slew_limit"]["n_per_ms"]
worst = max(abs(mag(b) - mag(a)) for a, b in zip(s, s[1:]) if b["t_s"] - a["t_s"] <= 1.05e-3)
at_pause = [x for x in s if x["t_s"] <= pause][-1]
z0, f0 = at_pause["tip_z_m"], mag(at_pause)
frozen = [x for x in s if pause + 0.3 < x["t_s"] < pause + 1.4 and x["tip_z_m"] < z0 - 0.002]
assert f0 > 0.2 and frozen, f"the probe was not pressing at the pause ({f0:.3f} N) or never went deeper"
low = min(mag(x) for x in frozen)
depth = 1e3 * (z0 - min(x["tip_z_m"] for x in frozen))
print(f"[ figure ] paused organ: {f0:.3f} N at the pause; with the tip up to {depth:.1f} mm deeper the force stayed >= {low:.3f} N; "
      f"largest 1 ms change {worst:.3f} N")
assert worst <= slew + 1e-9, f"the force changed by {worst:.3f} N in one sample"
assert low >= 0.5 * f0, f"the tip went through the paused organ: the force fell to {low:.3f} N"
PY

# --- A scalpel's cut button released with the blade 2 cm in the tissue; it stays there 1.5 s. ---
cat > "$tmp/release.csv" <<'CSV'
time_s,x_m,y_m,z_m,jaw_rad,buttons
0.0,0.0,0.0,0.02,0.5,1
0.8,0.0,0.0,-0.02,0.5,1
2.3,0.005,0.0,-0.02,0.5,1
2.301,0.005,0.0,-0.02,0.5,0
3.8,0.005,0.0,-0.02,0.5,0
4.6,0.005,0.0,0.02,0.5,0
CSV
"$hc" --domain "$domain" --client-id 1 --instrument 4 --trajectory "$tmp/release.csv" --frame organ-top --duration 4.8 --quiet \
  --report "$tmp/release.json" > "$tmp/hc-release.log" 2>&1
rc_client=$?
rc_release=$rc_client
cat "$tmp/hc-release.log"
resets_before_stiff=$(grep -c 'physics: ' "$tmp/server.log")

# --- The stiffest stiffening the server takes, pressed 3 cm into the 1.5k liver; a stiffer one is
# refused with its reason (server/runtime/stiffening_limit.hpp). The scene states the deepest edge
# strain it must run at, 0.5: a 3 cm press reaches 0.35-0.43, more when the machine is loaded and
# the commands come in bursts (0.403 measured with two busy cores, past the default 0.4 the rule
# assumes). At 0.5 the rule takes B up to 15.07 in this form. ---
"$ctl" load liver-deep --domain "$domain" > "$tmp/ctl-stiff.log" 2>&1
stiff() {  # B: a material file of the liver's elasticity with Fung's exponential in the energy form
  printf '{"name": "stiff liver %s", "density_kg_m3": 1060, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 5000, "poisson_ratio": 0.45},
 "viscoelasticity": {"model": "constant_q", "shear_q": 4.8, "bulk_q": 4.8, "band_hz": [0.01, 10], "mechanisms": 3,
 "reference_frequency_hz": 2, "qlv_stiffening": %s, "qlv_form": "energy"}}' "$1" "$1" > "$tmp/stiff-$1.json"
}
stiff 18.7; stiff 15
"$ctl" material --file "$tmp/stiff-18.7.json" --domain "$domain" >> "$tmp/ctl-stiff.log" 2>&1; rc_refused=$?
"$ctl" material --file "$tmp/stiff-15.json" --domain "$domain" >> "$tmp/ctl-stiff.log" 2>&1; rc_taken=$?
cat "$tmp/ctl-stiff.log"
check "stiff: B = 18.7 refused naming the field and the largest B (rc $rc_refused)" \
  "[ $rc_refused -eq 1 ] && grep -q 'viscoelasticity.qlv_stiffening' '$tmp/ctl-stiff.log' && grep -q 'B up to 15 in' '$tmp/ctl-stiff.log'"
check "stiff: B = 15 taken (rc $rc_taken)" "[ $rc_taken -eq 0 ] && grep -q 'material stiff liver 15' '$tmp/ctl-stiff.log'"
"$hc" --domain "$domain" --client-id 1 --instrument 1 --script press --depth 0.03 --duration 6 --quiet --report "$tmp/stiff.json" \
  > "$tmp/hc-stiff.log" 2>&1
rc_client=$?
stop_server
cat "$tmp/hc-stiff.log"
check "stiff: the 3 cm press ran to its end (rc $rc_client)" "[ $rc_client -eq 0 ]"
grep 'physics: ' "$tmp/server.log"
check "stiff: no physics reset on the server" "[ \$(grep -c 'physics: ' '$tmp/server.log') -eq $resets_before_stiff ]"
pycheck "$tmp/stiff.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
s = r["samples"]
mag = lambda x: math.sqrt(sum(c * c for c in x["rendered_force_n"]))
worst = max(abs(mag(b) - mag(a)) for a, b in zip(s, s[1:]) if b["t_s"] - a["t_s"] <= 1.05e-3)
print(f"[ figure ] stiffest accepted material pressed 3 cm: peak {max(mag(x) for x in s):.3f} N, largest 1 ms change {worst:.3f} N")
assert max(mag(x) for x in s) > 0.5, "the probe never pressed"
assert worst <= r["slew_limit"]["n_per_ms"] + 1e-9, f"the force changed by {worst:.3f} N in one sample"
PY
check "scalpel: the client ran to its end (rc $rc_release)" "[ $rc_release -eq 0 ]"
check "scalpel: no physics reset on the server" "[ $resets_before_stiff -eq 0 ]"
pycheck "$tmp/release.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
s = r["samples"]
mag = lambda x: math.sqrt(sum(c * c for c in x["rendered_force_n"]))
slew = r["slew_limit"]["n_per_ms"]
held = [mag(x) for x in s if 2.1 <= x["t_s"] <= 2.3]
after = [mag(x) for x in s if 2.3 < x["t_s"] < 3.8]
worst = max(abs(mag(b) - mag(a)) for a, b in zip(s, s[1:]) if b["t_s"] - a["t_s"] <= 1.05e-3)
f0 = sum(held) / len(held)
bound = max(1.5 * f0, f0 + 1.0)
print(f"[ figure ] scalpel released 2 cm deep: {f0:.3f} N while cutting, at most {max(after):.3f} N after (bound {bound:.3f} N), "
      f"asked for at most {r['slew_limit']['largest_step_asked_n']:.3f} N in one sample; largest 1 ms change {worst:.3f} N")
assert worst <= slew + 1e-9, f"the force changed by {worst:.3f} N in one sample"
assert max(after) <= bound, f"releasing the button in the tissue gave {max(after):.3f} N, above {bound:.3f} N"
PY

finish
